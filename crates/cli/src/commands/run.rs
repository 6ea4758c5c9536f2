//! `stickslip run STUDY.toml --out DIR`: the FRF of every force level of a study.
use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use indicatif::{MultiProgress, ProgressBar, ProgressStyle};
use rayon::prelude::*;
use stickslip_core::continuation::Point;
use stickslip_io::analysis::{describe_termination, run_grid, run_snapshot, LevelRun, LevelSweeper};
use stickslip_io::output::{replace_previous_run, time_data_files, write_frf_csv, write_results, write_snapshots};
use stickslip_io::report::write_report;
use stickslip_io::study::Study;

#[derive(clap::Args)]
pub struct Args {
    /// The study file (TOML; see docs/study-file.md).
    pub study: PathBuf,
    /// Output directory (created if needed).
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// No progress bars.
    #[arg(long)]
    pub quiet: bool,
    /// Do not write the HTML report (report.html).
    #[arg(long)]
    pub no_report: bool,
    /// Do not draw plots (batch runs: the tables and time data only).
    #[arg(long)]
    pub no_plots: bool,
}

pub fn main(args: Args) -> anyhow::Result<()> {
    let study = Study::load(&args.study)?;
    std::fs::create_dir_all(&args.out).with_context(|| format!("cannot create {}", args.out.display()))?;
    // Every file this run writes, listed for the next run (see `replace_previous_run`).
    let mut own_files = Vec::new();
    if let Some(mesh) = study.generated_mesh()? {
        // A generated geometry is written for CalculiX/Abaqus and Gmsh users to open, check or
        // reuse (the deck carries the couplings, connectors, shaker mass and spring), before
        // the solve, so that it is there even if the solve stops.
        let started = std::time::Instant::now();
        stickslip_fe::mesh::inp_writer::write(&mesh, args.out.join("model.inp"))?;
        stickslip_fe::mesh::gmsh_writer::write(&mesh, args.out.join("model.msh"))?;
        own_files.extend([args.out.join("model.inp"), args.out.join("model.msh")]);
        if !args.quiet {
            eprintln!("mesh files (model.inp, model.msh): {:.2} s", started.elapsed().as_secs_f64());
        }
    }
    let mut timings = Vec::new();
    let (model, excitation, outputs) = study.build_model_timed(&mut timings)?;
    if !args.quiet {
        for (stage, secs) in &timings {
            eprintln!("{stage}: {secs:.2} s");
        }
    }

    let bars = MultiProgress::new();
    if args.quiet {
        bars.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    let style = ProgressStyle::with_template("{prefix:>10} [{bar:30}] {percent:>3}% {msg}")
        .expect("valid template")
        .progress_chars("=> ");
    let (start_hz, end_hz) = (study.sweep.start_hz, study.sweep.end_hz);
    let started = Instant::now();
    // The model's linear part (its modes) once, shared by the levels.
    let sweeper =
        LevelSweeper::new(&study, &model, &excitation, &outputs).context("setting up the harmonic balance")?;
    let runs: Vec<anyhow::Result<(LevelRun, f64)>> = excitation
        .levels_n
        .par_iter()
        .map(|&level| {
            let level_started = Instant::now();
            let bar = bars.add(ProgressBar::new(1000));
            bar.set_style(style.clone());
            bar.set_prefix(format!("{level} N"));
            let mut observer = |p: &Point, done: f64| {
                bar.set_position((done * 1000.0) as u64);
                bar.set_message(format!("{:.2} Hz", p.lambda / (2.0 * std::f64::consts::PI)));
            };
            let run = sweeper.run(level, &mut observer).with_context(|| format!("level {level} N"))?;
            let secs = level_started.elapsed().as_secs_f64();
            if let Some(note) = &run.note {
                bars.suspend(|| eprintln!("level {level} N: {note}"));
            }
            bar.finish_with_message(format!(
                "{} points, {}, {secs:.2} s (of which the located peaks {:.3} s)",
                run.result.points.len(),
                describe_termination(&run.termination),
                run.seconds.peaks
            ));
            Ok((run, secs))
        })
        .collect();
    let runs: Vec<(LevelRun, f64)> = runs.into_iter().collect::<anyhow::Result<_>>()?;
    let elapsed = started.elapsed();
    for (run, secs) in &runs {
        timings.push((format!("level {} N", run.result.level_n), *secs));
        // Indented: parts of the level above.
        let stages = &run.seconds;
        timings.push(("  sweep".into(), stages.sweep));
        timings.push(("  located peaks".into(), stages.peaks));
        timings.push(("  located bifurcations".into(), stages.bifurcations));
    }
    timings.push(("all levels (wall clock)".into(), elapsed.as_secs_f64()));
    let runs: Vec<LevelRun> = runs.into_iter().map(|(run, _)| run).collect();

    let levels: Vec<_> = runs.iter().map(|r| r.result.clone()).collect();
    let plots = (!args.no_plots).then_some(study.output_options.plot_format);
    // The sweeps' result files and plots on one side; on the other, what is left to solve: the
    // snapshots, the grid and the [nonlinear_mode] backbone. Neither needs the other. A failed
    // snapshot, grid level or backbone does not keep the sweeps' results from being written:
    // it is reported at the end with the incomplete levels.
    let after_sweeps = Instant::now();
    let (results, (snapshots, grid, snapshots_secs, backbone)) = rayon::join(
        || -> anyhow::Result<(Vec<PathBuf>, f64)> {
            let started = Instant::now();
            let files = write_results(&args.out, &levels, plots)?;
            Ok((files, started.elapsed().as_secs_f64()))
        },
        || {
            let started = Instant::now();
            let snapshots: (Vec<_>, Vec<_>) = study
                .snapshots
                .par_iter()
                .map(|s| run_snapshot(&study, &model, &excitation, &outputs, s))
                .partition(Result::is_ok);
            // The [grid] frequencies, at every level.
            let grid: (Vec<_>, Vec<_>) = if study.grid_hz.is_empty() {
                (Vec::new(), Vec::new())
            } else {
                excitation
                    .levels_n
                    .par_iter()
                    .map(|&level| run_grid(&study, &model, &excitation, &outputs, level))
                    .partition(Result::is_ok)
            };
            let snapshots_secs = started.elapsed().as_secs_f64();
            let started = Instant::now();
            let backbone = study.nonlinear_mode.as_ref().map(|_| {
                let forced = Some((excitation.pattern.as_slice(), levels.as_slice()));
                super::nlmode::compute_and_write(&study, &model, &outputs, &args.out, plots, args.quiet, forced)
                    .map(|files| (files, started.elapsed().as_secs_f64()))
            });
            (snapshots, grid, snapshots_secs, backbone)
        },
    );
    let (mut files, results_secs) = results?;
    let (snapshots, failed_snapshots) = snapshots;
    let snapshots: Vec<_> = snapshots.into_iter().filter_map(Result::ok).collect();
    let (grid, failed_grid) = grid;
    let grid: Vec<_> = grid.into_iter().filter_map(Result::ok).collect();
    files.extend(write_snapshots(&args.out, &snapshots, plots)?);
    if !grid.is_empty() {
        let path = args.out.join("grid.csv");
        write_frf_csv(&path, &grid)?;
        files.push(path);
    }
    if let Some(Ok((written, _))) = &backbone {
        files.extend(written.iter().cloned());
    }
    // Stages side by side: their wall clock counts once in the total, each is a part of it.
    let solved_meanwhile = !study.snapshots.is_empty() || !study.grid_hz.is_empty();
    let backbone_secs = match &backbone {
        Some(Ok((_, secs))) => Some(*secs),
        _ => None,
    };
    if solved_meanwhile || backbone_secs.is_some() {
        timings.push(("after the sweeps (wall clock)".into(), after_sweeps.elapsed().as_secs_f64()));
        timings.push(("  result files and plots".into(), results_secs));
        if solved_meanwhile {
            timings.push(("  snapshots and grid".into(), snapshots_secs));
        }
        if let Some(secs) = backbone_secs {
            timings.push(("  nonlinear mode".into(), secs));
        }
    } else {
        timings.push(("result files and plots".into(), results_secs));
    }
    let backbone = backbone.map(|b| b.map(|(files, _)| files));
    let points: usize = levels.iter().map(|l| l.points.len()).sum();
    eprintln!(
        "{points} points over {} level(s), {start_hz}-{end_hz} Hz, in {:.3} s; wrote {} files to {} (frf.csv, frf.npz, peaks.csv, bifurcations.csv{}, points/)",
        levels.len(),
        elapsed.as_secs_f64(),
        files.len(),
        args.out.display(),
        if args.no_plots { "" } else { ", plots" }
    );
    if !args.no_report {
        let data = stickslip_io::analysis::report_data(&study, &model, &excitation, &runs, &files, timings.clone());
        let report = write_report(&args.out, &data).context("cannot write the report")?;
        eprintln!("report: {}", report.display());
        own_files.push(report);
    }
    own_files.extend(files);
    own_files.extend(time_data_files(&args.out, &levels));
    for old in replace_previous_run(&args.out, "run", &own_files)? {
        if !args.quiet {
            eprintln!("removed {} (written by the previous run, not by this one)", old.display());
        }
    }
    if !args.quiet {
        eprintln!(
            "total: {:.2} s",
            // Levels run in parallel (their wall clock is a stage of its own) and indented
            // sub-stages are parts of the stage above them.
            timings
                .iter()
                .filter(|(s, _)| !s.starts_with("level ") && !s.starts_with(' '))
                .map(|(_, t)| t)
                .sum::<f64>()
        );
    }
    let incomplete: Vec<String> = runs
        .iter()
        .filter(|r| !r.is_complete())
        .map(|r| format!("level {} N {}", r.result.level_n, r.ending()))
        .collect();
    let failed: Vec<String> = failed_snapshots
        .into_iter()
        .filter_map(Result::err)
        .chain(failed_grid.into_iter().filter_map(Result::err))
        .map(|e| e.to_string())
        .chain(backbone.and_then(Result::err).map(|e| format!("{e:#}")))
        .collect();
    if !incomplete.is_empty() || !failed.is_empty() {
        let mut what = Vec::new();
        if !incomplete.is_empty() {
            what.push(format!("{} level(s) did not cross the band (their points are written)", incomplete.len()));
        }
        if !failed.is_empty() {
            what.push(format!("{} snapshot(s), grid level(s) or nonlinear mode failed", failed.len()));
        }
        anyhow::bail!(
            "{}:\n  {}",
            what.join(" and "),
            incomplete.iter().chain(&failed).cloned().collect::<Vec<_>>().join("\n  ")
        );
    }
    Ok(())
}
