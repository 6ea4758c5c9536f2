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
    /// Worker threads of every parallel stage (default: RAYON_NUM_THREADS if set, otherwise one
    /// per core left idle by the rest of the machine: the cores less the 1-minute load average,
    /// rounded, or less the other tasks running now if fewer, at least one). Results do not
    /// depend on it beyond round-off.
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

/// The cores not busy with other work: one worker per core oversubscribes a loaded machine
/// (measured: 15-40 s of system time added at 306k DOFs on a loaded 2-core machine, the
/// workers preempting each other in the factor's solves). `None` where the load cannot be read
/// (rayon's default, one per core, then applies).
fn idle_cores() -> Option<usize> {
    let cores = std::thread::available_parallelism().ok()?.get();
    let loadavg = std::fs::read_to_string("/proc/loadavg").ok()?;
    let mut fields = loadavg.split_whitespace();
    let load: f64 = fields.next()?.parse().ok()?;
    // The fourth field, "running/total": the tasks runnable now, this process included.
    let running = fields.nth(2).and_then(|f| f.split('/').next()?.parse::<usize>().ok());
    Some(default_threads(cores, load, running))
}

/// `max(1, cores − busy)`, at most `cores`, where `busy` is the rounded 1-minute load average,
/// or fewer if fewer other tasks are runnable now (`running` counts this process): the average
/// still counts a run that has just finished for a minute after it, which would give the next
/// command of a workflow one thread on an idle machine.
fn default_threads(cores: usize, load: f64, running: Option<usize>) -> usize {
    let average = if load.is_finite() && load > 0.0 { load.round() as usize } else { 0 };
    let busy = running.map_or(average, |r| average.min(r.saturating_sub(1)));
    cores.saturating_sub(busy).clamp(1, cores.max(1))
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    if cli.threads == Some(0) {
        eprintln!("error: --threads must be at least 1");
        return ExitCode::FAILURE;
    }
    let by_load =
        if cli.threads.is_none() && std::env::var_os("RAYON_NUM_THREADS").is_none() { idle_cores() } else { None };
    let threads = cli.threads.or(by_load);
    if let Some(n) = threads {
        if let Err(e) = rayon::ThreadPoolBuilder::new().num_threads(n).build_global() {
            eprintln!("error: cannot start {n} worker threads: {e}");
            return ExitCode::FAILURE;
        }
    }
    // Notes of the solvers (the factor's size before factorising) go with the stage timings.
    if !matches!(&cli.command, Command::Run(a) if a.quiet) {
        stickslip_fe::memory::set_notes(|text| eprintln!("{text}"));
        // The thread count changes the round-off, which can move a friction branch's points:
        // when the load chose fewer threads than cores, say how to repeat this run exactly.
        let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
        if let Some(n) = by_load.filter(|&n| n < cores) {
            eprintln!("worker threads: {n} of {cores} cores, the others busy (load average); --threads {n} repeats this run's round-off");
        }
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

#[cfg(test)]
mod tests {
    use super::default_threads;

    #[test]
    fn the_default_thread_count_leaves_the_busy_cores_alone() {
        assert_eq!(default_threads(2, 0.1, None), 2);
        assert_eq!(default_threads(2, 0.6, None), 1);
        assert_eq!(default_threads(2, 5.3, None), 1);
        assert_eq!(default_threads(8, 2.4, None), 6);
        assert_eq!(default_threads(4, f64::NAN, None), 4);
        // A run that has just finished: the average is still high, only this process runs.
        assert_eq!(default_threads(2, 0.9, Some(1)), 2);
        // Others running now and on average: the fewer of the two.
        assert_eq!(default_threads(2, 0.9, Some(3)), 1);
        assert_eq!(default_threads(8, 2.4, Some(2)), 7);
        assert_eq!(default_threads(8, 2.4, Some(6)), 6);
    }
}
