//! `stickslip params STUDY.toml --vary KEY=SPEC ... [--shard I/N] --out DIR` and
//! `stickslip merge DIR`: parameter studies for batch schedulers (a Slurm array job runs one
//! shard per task, then one merge), on the library's `stickslip_io::params`.
use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use rayon::prelude::*;
use stickslip_io::params::files::{merge, write_curves, write_shard, Shard};
use stickslip_io::params::{ParamStudy, SampleOutcome, SampleRunner, Vary};

#[derive(clap::Args)]
pub struct Args {
    /// The study file (TOML; see docs/study-file.md).
    pub study: PathBuf,
    /// A varied value: KEY=LO:HI (a Latin hypercube range), KEY=LO:HI:N (N grid values) or
    /// KEY=a,b,c; KEY is a dotted path such as joint.blade1.threshold, damping.alpha or
    /// excitation.levels[0]. Repeat for several keys.
    #[arg(long, required = true)]
    pub vary: Vec<String>,
    /// Number of Latin hypercube samples (ranges only; a grid has its own number).
    #[arg(long)]
    pub samples: Option<usize>,
    /// Seed of the Latin hypercube: the same seed gives the same samples on every machine.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Run only shard I of N (from 1), e.g. 3/10; the samples are cut in N contiguous parts.
    #[arg(long, default_value = "1/1")]
    pub shard: String,
    /// Output directory: shard-I-of-N.csv (and samples.csv when there is one shard).
    #[arg(long, default_value = "out/params")]
    pub out: PathBuf,
    /// The output whose peak is summarised (default: the first [[output]]).
    #[arg(long)]
    pub output: Option<String>,
    /// Also write every sample's curves (curves/sample-<i>.csv, the columns of frf.csv).
    #[arg(long)]
    pub curves: bool,
    /// No progress lines.
    #[arg(long)]
    pub quiet: bool,
}

pub fn main(args: Args) -> anyhow::Result<()> {
    let varies = args.vary.iter().map(|v| Vary::parse(v)).collect::<Result<Vec<_>, _>>()?;
    let shard = Shard::parse(&args.shard)?;
    let study = ParamStudy::load(&args.study, &varies, args.samples, args.seed)?;
    std::fs::create_dir_all(&args.out).with_context(|| format!("cannot create {}", args.out.display()))?;
    let range = shard.range(study.samples.len());
    let started = Instant::now();
    let done = std::sync::atomic::AtomicUsize::new(0);
    let total = range.len();
    let outcomes: Vec<SampleOutcome> = range
        .into_par_iter()
        // A runner per rayon job keeps the linear model (and its reduction) of its samples.
        .map_init(
            || SampleRunner::new(&study),
            |runner, i| {
                let o = runner.run(i, args.output.as_deref(), args.curves);
                let n = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                if !args.quiet {
                    match &o.error {
                        None => eprintln!("[{n}/{total}] sample {i} done"),
                        Some(e) => eprintln!("[{n}/{total}] sample {i} failed: {e}"),
                    }
                }
                o
            },
        )
        .collect();
    let mut written = Vec::new();
    for o in &outcomes {
        written.extend(write_curves(&args.out, o)?);
    }
    let path = write_shard(&args.out, &study, shard, &outcomes)?;
    written.push(path.clone());
    // One file list per shard: the shards of an array job share the folder.
    let list = format!("params-shard-{}-of-{}", shard.index, shard.count);
    for old in stickslip_io::output::replace_previous_run(&args.out, &list, &written)? {
        eprintln!("removed {} (written by the previous run)", old.display());
    }
    let failed = outcomes.iter().filter(|o| o.error.is_some()).count();
    eprintln!(
        "{total} sample(s) of {} ({}), {failed} failed, in {:.2} s: {}",
        study.samples.len(),
        study.method,
        started.elapsed().as_secs_f64(),
        path.display()
    );
    if shard.count == 1 {
        let (merged, _) = merge(&args.out)?;
        stickslip_io::output::replace_previous_run(&args.out, "merge", std::slice::from_ref(&merged))?;
        eprintln!("table: {}", merged.display());
    }
    Ok(())
}

#[derive(clap::Args)]
pub struct MergeArgs {
    /// The directory of the shard tables (shard-I-of-N.csv).
    pub dir: PathBuf,
}

pub fn merge_main(args: MergeArgs) -> anyhow::Result<()> {
    let (path, samples) = merge(&args.dir)?;
    stickslip_io::output::replace_previous_run(&args.dir, "merge", std::slice::from_ref(&path))?;
    eprintln!("{samples} samples: {}", path.display());
    Ok(())
}
