//! `stickslip nlmode STUDY.toml --out DIR`: the backbone of the study's `[nonlinear_mode]`
//! (extended periodic motion concept): `backbone.csv` and plots of frequency and damping ratio
//! against the modal amplitude.
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use indicatif::{ProgressBar, ProgressStyle};
use stickslip_core::continuation::Point;
use stickslip_core::model::NonlinearModel;
use stickslip_io::analysis::{backbone_ending, run_nonlinear_mode};
use stickslip_io::backbone::{
    single_mode_frfs, singular_kind_name, write_backbone_csv, write_backbone_singular_csv, write_single_mode_csv,
};
use stickslip_io::output::LevelResult;
use stickslip_io::study::{OutputSpec, PlotFormat, Study};

#[derive(clap::Args)]
pub struct Args {
    /// The study file (TOML, with a [nonlinear_mode] section; see docs/nonlinear-modes.md).
    pub study: PathBuf,
    /// Output directory (created if needed).
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// No progress messages.
    #[arg(long)]
    pub quiet: bool,
    /// Do not draw plots.
    #[arg(long)]
    pub no_plots: bool,
}

pub fn main(args: Args) -> anyhow::Result<()> {
    let study = Study::load(&args.study)?;
    if study.nonlinear_mode.is_none() {
        anyhow::bail!(
            "{}: the study has no [nonlinear_mode] section (keys: mode, amplitude_start, amplitude_end; see docs/nonlinear-modes.md)",
            args.study.display()
        );
    }
    std::fs::create_dir_all(&args.out).with_context(|| format!("cannot create {}", args.out.display()))?;
    let (model, _, outputs) = study.build_model()?;
    let plots = (!args.no_plots).then_some(study.output_options.plot_format);
    compute_and_write(&study, &model, &outputs, &args.out, plots, args.quiet, None)?;
    Ok(())
}

/// Compute the backbone of `study`'s `[nonlinear_mode]` (nothing without one) and write
/// `backbone.csv` and, with `plots`, its two plots into `out`. With `forced` (the excitation
/// pattern and the levels the harmonic balance computed), also the forced responses
/// synthesised from the mode alone, `single_mode_frf.csv`, and per output their plot beside
/// the harmonic balance's. Returns the files written.
pub fn compute_and_write(
    study: &Study,
    model: &NonlinearModel,
    outputs: &[OutputSpec],
    out: &Path,
    plots: Option<PlotFormat>,
    quiet: bool,
    forced: Option<(&[f64], &[LevelResult])>,
) -> anyhow::Result<Vec<PathBuf>> {
    let started = Instant::now();
    let Some(spec) = &study.nonlinear_mode else { return Ok(Vec::new()) };
    // A bar over the amplitude range (in log a, as the branch is continued), as the sweeps'.
    let bar = if quiet { ProgressBar::hidden() } else { ProgressBar::new(1000) };
    bar.set_style(
        ProgressStyle::with_template("{prefix:>10} [{bar:30}] {percent:>3}% {msg}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar.set_prefix(format!("mode {}", spec.mode));
    let mut observer = |p: &Point, done: f64| {
        bar.set_position((done * 1000.0) as u64);
        bar.set_message(format!("modal amplitude {:.3e} m·√kg", 10f64.powf(p.lambda)));
    };
    let Some(result) = run_nonlinear_mode(study, model, outputs, &mut observer) else { return Ok(Vec::new()) };
    bar.finish_and_clear();
    let (backbone, names) = result.context("nonlinear mode")?;
    for note in &backbone.notes {
        eprintln!("nonlinear mode: {note}");
    }
    let joints: Vec<String> = model.elements.iter().map(|e| e.name.clone()).collect();
    let csv = out.join("backbone.csv");
    write_backbone_csv(&csv, &backbone, &joints, &names, study.hbm.harmonics)?;
    let singular = out.join("backbone_bifurcations.csv");
    write_backbone_singular_csv(&singular, &backbone)?;
    let mut files = vec![csv, singular];
    for s in &backbone.singular_points {
        eprintln!(
            "nonlinear mode: {} at modal amplitude {:.4e} m·√kg, {:.4} Hz, damping ratio {:.4e}{}",
            singular_kind_name(s.kind),
            s.amplitude,
            s.omega / (2.0 * std::f64::consts::PI),
            s.damping_ratio(),
            if s.located { "" } else { " (not located: the point after it)" }
        );
    }
    if let Some(format) = plots {
        files.extend(stickslip_io::plot::plot_backbone(out, &backbone, format)?);
    }
    if let Some((load, levels)) = forced {
        let levels_n: Vec<f64> = levels.iter().map(|l| l.level_n).collect();
        let frfs = single_mode_frfs(&backbone, load, &levels_n);
        let csv = out.join("single_mode_frf.csv");
        write_single_mode_csv(&csv, &frfs, &names)?;
        files.push(csv);
        if let Some(format) = plots {
            for (o, name) in names.iter().enumerate() {
                let path = out.join(format!("frf_single_mode_{name}.{}", format.extension()));
                stickslip_io::plot::plot_single_mode(&path, levels, name, &frfs, o)?;
                files.push(path);
            }
        }
    }
    let (first, last) = (backbone.points.first(), backbone.points.last());
    if let (Some(first), Some(last)) = (first, last) {
        eprintln!(
            "nonlinear mode {}: {} points, modal amplitude {:.3e}-{:.3e} m·√kg, {:.4}-{:.4} Hz, damping ratio {:.4e}-{:.4e}, {} in {:.3} s; wrote backbone.csv{}",
            backbone.mode + 1,
            backbone.points.len(),
            first.amplitude,
            last.amplitude,
            first.frequency_hz(),
            last.frequency_hz(),
            first.damping_ratio(),
            last.damping_ratio(),
            backbone_ending(&backbone),
            started.elapsed().as_secs_f64(),
            if plots.is_some() { ", backbone_frequency and backbone_damping plots" } else { "" }
        );
    }
    if !backbone.complete() {
        anyhow::bail!("nonlinear mode: the branch {} (its points are written)", backbone_ending(&backbone));
    }
    Ok(files)
}
