//! The `stickslip` command: argument parsing and progress only; the libraries do the work.
use std::process::ExitCode;

use clap::{Parser, Subcommand};

mod commands;

#[derive(Parser)]
#[command(
    name = "stickslip",
    version,
    about = "Nonlinear vibration of assemblies with friction joints: harmonic balance, condensation, continuation"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Worker threads of every parallel stage (default: one per core, or RAYON_NUM_THREADS)
    #[arg(long, global = true)]
    threads: Option<usize>,
}

#[derive(Subcommand)]
enum Command {
    /// Frequency response of a study at every force level (harmonic balance + continuation).
    Run(commands::run::Args),
    /// Backbone of a study's [nonlinear_mode]: frequency and damping ratio of a damped nonlinear mode against amplitude.
    Nlmode(commands::nlmode::Args),
    /// Lowest modes of a model (mesh, CalculiX deck or matrices).
    Modes(commands::modes::Args),
    /// Reduce a model (Craig-Bampton, free-mode variant, slipped-joint enrichment).
    Reduce(commands::reduce::Args),
    /// Direct time integration of a study: steady states at given frequencies, or a swept sine.
    Timesim(commands::timesim::Args),
    /// Harmonics and FRFs from time records (CSV or UFF 58).
    Extract(commands::extract::Args),
    /// Measured against simulated FRFs: overlay plots, peak frequencies and amplitudes.
    Compare(commands::compare::Args),
    /// A parameter study (grid or Latin hypercube over study values), whole or one shard.
    Params(commands::params::Args),
    /// Merge the shard tables of a parameter study into samples.csv.
    Merge(commands::params::MergeArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    if let Some(n) = cli.threads {
        if n == 0 {
            eprintln!("error: --threads must be at least 1");
            return ExitCode::FAILURE;
        }
        if let Err(e) = rayon::ThreadPoolBuilder::new().num_threads(n).build_global() {
            eprintln!("error: cannot start {n} worker threads: {e}");
            return ExitCode::FAILURE;
        }
    }
    // Notes of the solvers (the factor's size before factorising) go with the stage timings.
    if !matches!(&cli.command, Command::Run(a) if a.quiet) {
        stickslip_fe::memory::set_notes(|text| eprintln!("{text}"));
    }
    let result = match cli.command {
        Command::Run(a) => commands::run::main(a),
        Command::Nlmode(a) => commands::nlmode::main(a),
        Command::Modes(a) => commands::modes::main(a),
        Command::Reduce(a) => commands::reduce::main(a),
        Command::Timesim(a) => commands::timesim::main(a),
        Command::Extract(a) => commands::extract::main(a),
        Command::Compare(a) => commands::compare::main(a),
        Command::Params(a) => commands::params::main(a),
        Command::Merge(a) => commands::params::merge_main(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
