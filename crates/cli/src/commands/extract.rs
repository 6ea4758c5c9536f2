#[derive(clap::Args)]
pub struct Args {
    /// Input file.
    pub input: std::path::PathBuf,
}

pub fn main(args: Args) -> anyhow::Result<()> {
    anyhow::bail!("`stickslip extract` is not available yet (input {})", args.input.display())
}
