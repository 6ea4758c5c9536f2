//! `stickslip timesim STUDY.toml --out DIR (--frequency HZ | --sweep-rate HZ_PER_S)`: direct time
//! integration of a study (paper Eq. 12) at every force level: the periodic steady state at one
//! frequency, or a swept sine over the study's `[sweep]` band.
//!
//! Files (SI units in the column names, frequencies in Hz):
//! - `timesim_<level>N_<f>Hz.csv`: one steady period, `time_s, force_N`, per output
//!   `<out>_m, <out>_m_s, <out>_m_s2`, per joint `<joint>_restoring_force_N` (the element's `g`
//!   of Eq. 12; for a paper-form Jenkins joint `f − k_J u`) and `<joint>_slider_velocity_m_s`
//!   (Eq. 33: 0 while stuck);
//! - `timesim_summary.csv`: per level, the periods needed, the periodicity reached, the energy
//!   input and dissipated per cycle (viscous, each joint) and the harmonic amplitudes of each output;
//! - `sweep_<level>N.csv`: the same channels plus `frequency_Hz`, every `--record-every` steps;
//! - `sweep_<level>N_cycles.csv`: per excitation cycle, first-harmonic amplitude and phase of
//!   each output against the excitation.
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context};
use stickslip_core::model::NonlinearModel;
use stickslip_core::timesim::{
    steady_state, swept_sine, Records, Scheme, SteadyState, SteadyStateOptions, SweepOptions,
};
use stickslip_io::records::{write_table, write_time_csv, Channel, TimeRecords};
use stickslip_io::study::{OutputSpec, Study};

#[derive(clap::Args)]
pub struct Args {
    /// The study file (TOML; see docs/study-file.md): model, joints, load, levels, outputs.
    pub study: PathBuf,
    /// Output directory (created if needed).
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Steady state at this excitation frequency (Hz).
    #[arg(long, conflicts_with = "sweep_rate")]
    pub frequency: Option<f64>,
    /// Swept sine over the study's [sweep] band at this rate (Hz/s), up or down as the band goes.
    #[arg(long)]
    pub sweep_rate: Option<f64>,
    /// Time steps per period (at the highest frequency for a sweep).
    #[arg(long, default_value_t = 256)]
    pub steps_per_period: usize,
    /// HHT-α parameter in [-1/3, 0]; 0 is Newmark's average acceleration.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub alpha: f64,
    /// Periodicity tolerance of the steady state (max |x(t+T) − x(t)| / max |x|, two periods in a row).
    #[arg(long, default_value_t = 1e-6)]
    pub tolerance: f64,
    /// Give up the steady state after this many periods.
    #[arg(long, default_value_t = 5000)]
    pub max_periods: usize,
    /// Harmonics reported for a steady state (default: the study's [hbm] harmonics).
    #[arg(long)]
    pub harmonics: Option<usize>,
    /// For a sweep, write every k-th time step (the per-cycle harmonics use every step).
    #[arg(long, default_value_t = 10)]
    pub record_every: usize,
}

pub fn main(args: Args) -> anyhow::Result<()> {
    let study = Study::load(&args.study)?;
    let (model, excitation, outputs) = study.build_model()?;
    std::fs::create_dir_all(&args.out).with_context(|| format!("cannot create {}", args.out.display()))?;
    let scheme = if args.alpha == 0.0 { Scheme::AverageAcceleration } else { Scheme::Hht { alpha: args.alpha } };
    // Record only the DOFs the outputs combine.
    let dofs: Vec<usize> = (0..model.linear.n_dofs()).filter(|&i| outputs.iter().any(|o| o.vector[i] != 0.0)).collect();
    let harmonics = args.harmonics.unwrap_or(study.hbm.harmonics);
    let started = Instant::now();
    let mut written = Vec::new();
    match (args.frequency, args.sweep_rate) {
        (Some(f), None) => {
            let mut summary = Vec::new();
            let mut columns = Vec::new();
            for &level in &excitation.levels_n {
                let mut o = SteadyStateOptions::new(f, excitation.pattern.iter().map(|p| p * level).collect());
                o.scheme = scheme;
                o.steps_per_period = args.steps_per_period;
                o.harmonics = harmonics;
                o.tolerance = args.tolerance;
                o.max_periods = args.max_periods;
                o.record_dofs = dofs.clone();
                let s = steady_state(&model, &o).with_context(|| format!("level {level} N at {f} Hz"))?;
                let path = args.out.join(format!("timesim_{level}N_{f}Hz.csv"));
                let force: Vec<f64> =
                    s.records.time.iter().map(|t| level * (2.0 * std::f64::consts::PI * f * t).cos()).collect();
                write_records(&path, &outputs, &s.records, Some(force), None)?;
                written.push(path);
                let (cols, row) = summary_row(&model, &outputs, &s, level, harmonics)?;
                columns = cols;
                summary.push(row);
                eprintln!(
                    "{level} N at {f} Hz: periodic after {} periods (periodicity {:.1e}); input {:.4e} J/cycle, dissipated {:.4e} J/cycle",
                    s.periods,
                    s.periodicity,
                    s.energy.input,
                    s.energy.dissipated()
                );
            }
            let path = args.out.join("timesim_summary.csv");
            write_table(&path, &columns, &summary)?;
            written.push(path);
        }
        (None, Some(rate)) => {
            for &level in &excitation.levels_n {
                let (f0, f1) = (study.sweep.start_hz, study.sweep.end_hz);
                let mut o = SweepOptions::new(f0, f1, rate, excitation.pattern.iter().map(|p| p * level).collect());
                o.scheme = scheme;
                o.steps_per_period = args.steps_per_period;
                o.record_dofs = dofs.clone();
                o.record_every = args.record_every;
                o.settle = Some((args.tolerance, args.max_periods));
                let sweep = swept_sine(&model, &o).with_context(|| format!("level {level} N, sweep {f0}-{f1} Hz"))?;
                let path = args.out.join(format!("sweep_{level}N.csv"));
                let two_pi = 2.0 * std::f64::consts::PI;
                let r = rate * (f1 - f0).signum();
                let force: Vec<f64> =
                    sweep.records.time.iter().map(|t| level * (two_pi * (f0 * t + 0.5 * r * t * t)).cos()).collect();
                write_records(&path, &outputs, &sweep.records, Some(force), Some(sweep.frequency_hz.clone()))?;
                written.push(path);
                // Per-cycle first harmonic of every output against the excitation phase.
                let mut columns = vec!["frequency_Hz".to_string()];
                for o in &outputs {
                    columns.push(format!("{}_amp_m", o.name));
                    columns.push(format!("{}_phase_rad", o.name));
                }
                let rows: Vec<Vec<f64>> = sweep
                    .cycles
                    .iter()
                    .map(|c| {
                        let mut row = vec![c.frequency_hz];
                        for o in &outputs {
                            let (mut re, mut im) = (0.0, 0.0);
                            for (k, &i) in dofs.iter().enumerate() {
                                re += o.vector[i] * c.harmonic1[k].0;
                                im -= o.vector[i] * c.harmonic1[k].1;
                            }
                            row.push(re.hypot(im));
                            row.push(im.atan2(re));
                        }
                        row
                    })
                    .collect();
                let path = args.out.join(format!("sweep_{level}N_cycles.csv"));
                write_table(&path, &columns, &rows)?;
                written.push(path);
                eprintln!("{level} N: swept {f0}-{f1} Hz at {rate} Hz/s, {} cycles", sweep.cycles.len());
            }
        }
        _ => bail!("give either --frequency HZ (steady state) or --sweep-rate HZ_PER_S (swept sine over the study's [sweep] band)"),
    }
    let names: Vec<String> = written.iter().map(|p| p.display().to_string()).collect();
    eprintln!("done in {:.2} s; wrote {}", started.elapsed().as_secs_f64(), names.join(", "));
    Ok(())
}

/// Time records of the outputs (displacement, velocity, acceleration), the force and the
/// joints (restoring force and slider velocity, Eq. 33) as CSV.
fn write_records(
    path: &Path,
    outputs: &[OutputSpec],
    records: &Records,
    force: Option<Vec<f64>>,
    frequency: Option<Vec<f64>>,
) -> anyhow::Result<()> {
    if records.len() < 2 {
        bail!("fewer than 2 samples recorded for {}: lower --record-every", path.display());
    }
    let mut channels = Vec::new();
    if let Some(f) = frequency {
        channels.push(Channel { name: "frequency".into(), unit: "Hz".into(), values: f });
    }
    if let Some(f) = force {
        channels.push(Channel { name: "force".into(), unit: "N".into(), values: f });
    }
    for o in outputs {
        for (series, unit) in
            [(&records.displacement, "m"), (&records.velocity, "m_s"), (&records.acceleration, "m_s2")]
        {
            let values = (0..records.len())
                .map(|j| records.dofs.iter().enumerate().map(|(k, &i)| o.vector[i] * series[k][j]).sum())
                .collect();
            channels.push(Channel { name: o.name.clone(), unit: unit.into(), values });
        }
    }
    let e = &records.elements;
    for (a, name) in e.names.iter().enumerate() {
        channels.push(Channel {
            name: format!("{name}_restoring_force"),
            unit: "N".into(),
            values: e.force[a].clone(),
        });
        channels.push(Channel {
            name: format!("{name}_slider_velocity"),
            unit: "m_s".into(),
            values: e.slider_velocity[a].clone(),
        });
    }
    let dt = records.time[1] - records.time[0];
    let recs = TimeRecords {
        source: path.display().to_string(),
        start_s: records.time[0],
        sample_rate_hz: 1.0 / dt,
        channels,
    };
    write_time_csv(path, &recs)?;
    Ok(())
}

/// One summary row: level, frequency, periods, periodicity, energies, harmonic amplitudes.
fn summary_row(
    model: &NonlinearModel,
    outputs: &[OutputSpec],
    s: &SteadyState,
    level: f64,
    harmonics: usize,
) -> anyhow::Result<(Vec<String>, Vec<f64>)> {
    let mut columns: Vec<String> =
        ["level_N", "frequency_Hz", "periods", "periodicity", "input_J", "viscous_J"].map(String::from).to_vec();
    let mut row = vec![level, s.frequency_hz, s.periods as f64, s.periodicity, s.energy.input, s.energy.viscous];
    for (e, site) in model.elements.iter().enumerate() {
        columns.push(format!("{}_dissipated_J", site.name));
        row.push(s.energy.elements[e]);
    }
    for o in outputs {
        let x: Vec<f64> = (0..s.records.len())
            .map(|j| s.records.dofs.iter().enumerate().map(|(k, &i)| o.vector[i] * s.records.displacement[k][j]).sum())
            .collect();
        let c = SteadyState::harmonics(&x, harmonics)?;
        for k in 1..=harmonics {
            columns.push(format!("{}_h{k}_amp_m", o.name));
            row.push(c[2 * k - 1].hypot(c[2 * k]));
        }
    }
    Ok((columns, row))
}
