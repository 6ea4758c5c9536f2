//! `stickslip timesim STUDY.toml --out DIR (--frequency HZ[,HZ...] | --sweep-rate HZ_PER_S)`: direct time
//! integration of a study (paper Eq. 12) at every force level: the periodic steady state at one
//! frequency, or a swept sine over the study's `[sweep]` band.
//!
//! Files (SI units in the column names, frequencies in Hz):
//! - `timesim_<level>N_<f>Hz.csv`: the steady state over `--write-periods` periods (the
//!   converged period repeated), `time_s, force_N`, per output
//!   `<out>_m, <out>_m_s, <out>_m_s2`, per joint `<joint>_restoring_force_N` (the element's `g`
//!   of Eq. 12; for a paper-form Jenkins joint `f − k_J u`) and `<joint>_slider_velocity_m_s`
//!   (Eq. 33: 0 while stuck);
//! - `timesim_summary.csv`: per level, the periods needed, the periodicity reached, the energy
//!   input and dissipated per cycle (viscous, each joint) and the harmonic amplitudes of each output;
//! - `sweep_<level>N.csv`: the same channels plus `frequency_Hz`, every `--record-every` steps;
//! - `timesim_<level>N_<f>Hz.<png|svg>`, `sweep_<level>N.<png|svg>`: the outputs' displacements
//!   against time (not with `--no-plots`);
//! - `sweep_<level>N_cycles.csv`: per excitation cycle, first-harmonic amplitude and phase of
//!   each output against the excitation;
//! - with `--uff`, `sweep_<level>N.uff` instead of `sweep_<level>N.csv`: what the paper's
//!   shaker test records (Section 2.4), the shaker's drive signal (V, proportional to the
//!   force: the test piloted the tension, not the force) and the acceleration of every output
//!   as UFF 58 time records, with white sensor noise (`--accel-noise`), ready for
//!   `stickslip extract` and its force identification by Eq. 1.
//!
//! Reduced (dense) models are integrated in the coordinates of their modes (M = I,
//! K = diag ω², D diagonal for Rayleigh or modal damping): the same Newmark solution to
//! round-off of the eigensolution, at O(n q) per step instead of O(n²).
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context};
use rayon::prelude::*;
use stickslip_core::model::NonlinearModel;
use stickslip_core::model::{Damping, Modes};
use stickslip_core::timesim::{
    steady_state, swept_sine, Records, Scheme, SlowBand, SteadyState, SteadyStateOptions, SweepOptions, SweepRecord,
};
use stickslip_io::plot::plot_time_records;
use stickslip_io::records::{add_white_noise, time_records_to_uff, write_table, write_time_csv, Channel, TimeRecords};
use stickslip_io::study::{OutputSpec, Study};
use stickslip_io::uff;

#[derive(clap::Args)]
pub struct Args {
    /// The study file (TOML; see docs/study-file.md): model, joints, load, levels, outputs.
    pub study: PathBuf,
    /// Output directory (created if needed).
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Steady state at these excitation frequencies (Hz, comma-separated).
    #[arg(long, value_delimiter = ',', conflicts_with = "sweep_rate")]
    pub frequency: Option<Vec<f64>>,
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
    /// Judge the periodicity on the outputs' DOFs only, not on every DOF (stiff joints that
    /// stick for less than a step: with --min-periods and a looser --tolerance, see docs/cli.md).
    #[arg(long)]
    pub periodic_on_outputs: bool,
    /// Integrate at least this many periods before judging the periodicity.
    #[arg(long, default_value_t = 0)]
    pub min_periods: usize,
    /// Give up the steady state after this many periods.
    #[arg(long, default_value_t = 5000)]
    pub max_periods: usize,
    /// Periods of a steady state written to its time record: the converged period repeated,
    /// a stationary record as a test takes one, which `stickslip extract --stepped` reads
    /// (it fits the complete cycles between the excitation's zero crossings, and one period
    /// starting at the force's peak holds none).
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u64).range(1..=1000))]
    pub write_periods: u64,
    /// Harmonics reported for a steady state (default: the study's [hbm] harmonics).
    #[arg(long)]
    pub harmonics: Option<usize>,
    /// For a sweep, write every k-th time step (the per-cycle harmonics use every step).
    #[arg(long, default_value_t = 10)]
    pub record_every: usize,
    /// A band swept at --slow-rate instead (Hz, two values: LOW,HIGH), e.g. the friction range.
    #[arg(long, value_delimiter = ',', requires = "slow_rate")]
    pub slow_band: Option<Vec<f64>>,
    /// Sweep rate inside --slow-band (Hz/s).
    #[arg(long, requires = "slow_band")]
    pub slow_rate: Option<f64>,
    /// Coordinates of the integration: `modal` (dense models with Rayleigh, modal or no
    /// damping: O(n q) per step), `physical`, or `auto` (modal where it applies).
    #[arg(long, value_enum, default_value_t = Coordinates::Auto)]
    pub coordinates: Coordinates,
    /// Force levels (N, comma-separated) instead of the study's [excitation] levels.
    #[arg(long, value_delimiter = ',')]
    pub levels: Option<Vec<f64>>,
    /// Sweep this band (Hz, START,END) instead of the study's [sweep] band, e.g. down to
    /// 100 Hz where Eq. 1 identifies the force.
    #[arg(long, value_delimiter = ',')]
    pub band: Option<Vec<f64>>,
    /// For a sweep, write what a shaker test records instead of the full time table: the
    /// drive signal (V) and the accelerations of the outputs as UFF 58 (`sweep_<level>N.uff`).
    #[arg(long)]
    pub uff: bool,
    /// White noise added to the UFF accelerations (m/s² RMS), the sensors' noise floor.
    #[arg(long, default_value_t = 0.0, requires = "uff")]
    pub accel_noise: f64,
    /// Seed of the noise (the same seed gives the same records).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Do not draw the outputs' displacements against time (in the study's plot format).
    #[arg(long)]
    pub no_plots: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, clap::ValueEnum)]
pub enum Coordinates {
    Auto,
    Modal,
    Physical,
}

pub fn main(args: Args) -> anyhow::Result<()> {
    let study = Study::load(&args.study)?;
    study.require_penalty_contacts("the time integration")?;
    let (model, excitation, outputs) = study.build_model()?;
    std::fs::create_dir_all(&args.out).with_context(|| format!("cannot create {}", args.out.display()))?;
    let scheme = if args.alpha == 0.0 { Scheme::AverageAcceleration } else { Scheme::Hht { alpha: args.alpha } };
    // Record only the DOFs the outputs combine.
    let dofs: Vec<usize> = (0..model.linear.n_dofs()).filter(|&i| outputs.iter().any(|o| o.vector[i] != 0.0)).collect();
    let (model, modes) = in_coordinates(model, args.coordinates)?;
    // The load pattern in the integration's coordinates (Φᵀ p in modal coordinates).
    let pattern: Vec<f64> = match &modes {
        Some(m) => (0..m.omega.len())
            .map(|r| excitation.pattern.iter().enumerate().map(|(i, p)| m.shapes[(i, r)] * p).sum())
            .collect(),
        None => excitation.pattern.clone(),
    };
    let shapes = modes.map(|m| m.shapes);
    let levels = match &args.levels {
        Some(l) if l.iter().all(|x| x.is_finite() && *x > 0.0) => l.clone(),
        Some(l) => bail!("--levels takes force amplitudes > 0 in N, got {l:?}"),
        None => excitation.levels_n.clone(),
    };
    let harmonics = args.harmonics.unwrap_or(study.hbm.harmonics);
    let plots = (!args.no_plots).then_some(study.output_options.plot_format);
    let started = Instant::now();
    let mut written = Vec::new();
    // Levels (and frequencies) are independent runs: solved in parallel on the thread pool,
    // written in order.
    match (&args.frequency, args.sweep_rate) {
        (Some(frequencies), None) => {
            if let Some(f) = frequencies.iter().find(|f| !(f.is_finite() && **f > 0.0)) {
                bail!("--frequency takes frequencies > 0 in Hz, got {f}");
            }
            let runs: Vec<(f64, f64)> =
                levels.iter().flat_map(|&l| frequencies.iter().map(move |&f| (l, f))).collect();
            let solved: Vec<anyhow::Result<SteadyState>> = runs
                .par_iter()
                .map(|&(level, f)| {
                    let mut o = SteadyStateOptions::new(f, pattern.iter().map(|p| p * level).collect());
                    o.mode_shapes = shapes.clone();
                    o.scheme = scheme;
                    o.steps_per_period = args.steps_per_period;
                    o.harmonics = harmonics;
                    o.tolerance = args.tolerance;
                    o.max_periods = args.max_periods;
                    o.record_dofs = dofs.clone();
                    o.periodic_on_recorded = args.periodic_on_outputs;
                    o.min_periods = args.min_periods;
                    steady_state(&model, &o).with_context(|| format!("level {level} N at {f} Hz"))
                })
                .collect();
            let mut summary = Vec::new();
            let mut columns = Vec::new();
            for (&(level, f), s) in runs.iter().zip(solved) {
                let s = s?;
                let path = args.out.join(format!("timesim_{level}N_{f}Hz.csv"));
                let force: Vec<f64> = s.records.excitation.iter().map(|e| level * e).collect();
                let one_period = time_records(&path, &outputs, &s.records, Some(&force), None)?;
                let records = repeated(one_period, args.write_periods as usize);
                write_time_csv(&path, &records)?;
                written.push(path);
                if let Some(format) = plots {
                    let plot = args.out.join(format!("timesim_{level}N_{f}Hz.{}", format.extension()));
                    let title = format!("Steady state at {f} Hz, {level} N: displacements");
                    plot_time_records(&plot, &title, &records, "m")?;
                    written.push(plot);
                }
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
            let (f0, f1) = match &args.band {
                None => (study.sweep.start_hz, study.sweep.end_hz),
                Some(b) if b.len() == 2 => (b[0], b[1]),
                Some(b) => bail!("--band takes two frequencies START,END in Hz, got {b:?}"),
            };
            let slow_band = match (&args.slow_band, args.slow_rate) {
                (Some(band), Some(slow)) if band.len() == 2 => {
                    Some(SlowBand { low_hz: band[0], high_hz: band[1], rate_hz_per_s: slow })
                }
                (Some(band), _) => bail!("--slow-band takes two frequencies LOW,HIGH in Hz, got {band:?}"),
                _ => None,
            };
            let options = |level: f64| {
                let mut o = SweepOptions::new(f0, f1, rate, pattern.iter().map(|p| p * level).collect());
                o.mode_shapes = shapes.clone();
                o.slow_band = slow_band;
                o.scheme = scheme;
                o.steps_per_period = args.steps_per_period;
                o.record_dofs = dofs.clone();
                o.record_every = args.record_every;
                o.settle = Some((args.tolerance, args.max_periods));
                if args.uff {
                    // What a test system samples: low-passed below 0.4 of the sample rate.
                    o.anti_alias_hz = Some(ANTI_ALIAS_FRACTION / (o.step().0 * args.record_every as f64));
                }
                o
            };
            let schedule = options(1.0).schedule().context("the sweep")?;
            let solved: Vec<anyhow::Result<(SweepRecord, f64)>> = levels
                .par_iter()
                .map(|&level| {
                    let level_started = Instant::now();
                    let sweep = swept_sine(&model, &options(level))
                        .with_context(|| format!("level {level} N, sweep {f0}-{f1} Hz"))?;
                    Ok((sweep, level_started.elapsed().as_secs_f64()))
                })
                .collect();
            for (&level, result) in levels.iter().zip(solved) {
                let (sweep, solve_s) = result?;
                let force: Vec<f64> = sweep.records.excitation.iter().map(|e| level * e).collect();
                let path = args.out.join(format!("sweep_{level}N.{}", if args.uff { "uff" } else { "csv" }));
                let records = time_records(&path, &outputs, &sweep.records, Some(&force), Some(&sweep.frequency_hz))?;
                if args.uff {
                    write_measured(&path, &records, args.accel_noise, args.seed)?;
                } else {
                    write_time_csv(&path, &records)?;
                }
                written.push(path);
                if let Some(format) = plots {
                    let plot = args.out.join(format!("sweep_{level}N.{}", format.extension()));
                    let title = format!("Swept sine {f0}-{f1} Hz at {rate} Hz/s, {level} N: displacements");
                    plot_time_records(&plot, &title, &records, "m")?;
                    written.push(plot);
                }
                let path = args.out.join(format!("sweep_{level}N_cycles.csv"));
                write_cycles(&path, &outputs, &dofs, &sweep)?;
                written.push(path);
                let steps = (schedule.duration() / sweep.step).ceil();
                eprintln!(
                    "{level} N: swept {f0}-{f1} Hz in {:.1} s of signal, {} cycles, {steps:.0} steps in {solve_s:.1} s ({:.2} µs per step)",
                    schedule.duration(),
                    sweep.cycles.len(),
                    1e6 * solve_s / steps
                );
            }
        }
        _ => bail!("give either --frequency HZ[,HZ...] (steady states) or --sweep-rate HZ_PER_S (swept sine over the study's [sweep] band)"),
    }
    for old in stickslip_io::output::replace_previous_run(&args.out, "timesim", &written)? {
        eprintln!("removed {} (written by the previous timesim, not by this one)", old.display());
    }
    let names: Vec<String> = written.iter().map(|p| p.display().to_string()).collect();
    eprintln!("done in {:.2} s; wrote {}", started.elapsed().as_secs_f64(), names.join(", "));
    Ok(())
}

/// Per excitation cycle, the first harmonic of every output against the excitation phase.
fn write_cycles(path: &Path, outputs: &[OutputSpec], dofs: &[usize], sweep: &SweepRecord) -> anyhow::Result<()> {
    let mut columns = vec!["frequency_Hz".to_string()];
    for o in outputs {
        columns.push(format!("{}_amp_m", o.name));
        columns.push(format!("{}_phase_rad", o.name));
    }
    let rows: Vec<Vec<f64>> = sweep
        .cycles
        .iter()
        .map(|c| {
            let mut row = vec![c.frequency_hz];
            for o in outputs {
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
    write_table(path, &columns, &rows)?;
    Ok(())
}

/// The model in the coordinates asked for, and its modes when they are modal.
fn in_coordinates(model: NonlinearModel, asked: Coordinates) -> anyhow::Result<(NonlinearModel, Option<Modes>)> {
    let dense = matches!(model.linear.mass, stickslip_core::model::Matrix::Dense(_));
    let diagonal_damping = !matches!(model.linear.damping, Damping::Matrix(_));
    match asked {
        Coordinates::Physical => Ok((model, None)),
        Coordinates::Auto if !(dense && diagonal_damping) => Ok((model, None)),
        Coordinates::Auto | Coordinates::Modal => {
            let modes = match model.linear.dense_modes() {
                Ok(m) => m,
                // A model with a rigid-body motion has no modal form; physical coordinates
                // integrate it all the same.
                Err(_) if asked == Coordinates::Auto => return Ok((model, None)),
                Err(e) => return Err(e).context("--coordinates modal needs the modes of the model"),
            };
            let modal = model.into_modal(&modes)?;
            Ok((modal, Some(modes)))
        }
    }
}

/// Cutoff of the anti-aliasing filter of `--uff` records as a fraction of their sample rate
/// (with the 8th-order Butterworth of `stickslip_core::signal::antialias`, what would fold
/// below 0.2 of the sample rate is attenuated by 46 dB or more).
const ANTI_ALIAS_FRACTION: f64 = 0.4;

/// Drive signal per newton of force: the paper's shaker gave 70 N for a 20 mV tension
/// amplitude (Section 2.4). The shaker is modelled as a force source, so the drive is the
/// force scaled; Eq. 1 recovers the force from the responses at 100 Hz.
const DRIVE_V_PER_N: f64 = 0.020 / 70.0;

/// What a shaker test records, as UFF 58: the drive signal and the accelerations of the
/// outputs with white sensor noise.
fn write_measured(path: &Path, records: &TimeRecords, accel_noise: f64, seed: u64) -> anyhow::Result<()> {
    let mut measured = TimeRecords { channels: Vec::new(), ..records.clone() };
    for (k, c) in records.channels.iter().enumerate() {
        if c.name == "force" {
            let values = c.values.iter().map(|f| f * DRIVE_V_PER_N).collect();
            measured.channels.push(Channel { name: "drive".into(), unit: "V".into(), values });
        } else if c.unit == "m_s2" {
            let mut c = c.clone();
            // One stream per channel: independent sensors.
            add_white_noise(&mut c.values, accel_noise, seed.wrapping_mul(1000).wrapping_add(k as u64))
                .with_context(|| format!("--accel-noise on channel {}", c.name))?;
            measured.channels.push(c);
        }
    }
    uff::write(path, &time_records_to_uff(&measured), uff::Encoding::Binary)?;
    Ok(())
}

/// Time records of the outputs (displacement, velocity, acceleration), the force and the
/// joints (restoring force and slider velocity, Eq. 33).
fn time_records(
    path: &Path,
    outputs: &[OutputSpec],
    records: &Records,
    force: Option<&[f64]>,
    frequency: Option<&[f64]>,
) -> anyhow::Result<TimeRecords> {
    if records.len() < 2 {
        bail!("fewer than 2 samples recorded for {}: lower --record-every", path.display());
    }
    let mut channels = Vec::new();
    if let Some(f) = frequency {
        channels.push(Channel { name: "frequency".into(), unit: "Hz".into(), values: f.to_vec() });
    }
    if let Some(f) = force {
        channels.push(Channel { name: "force".into(), unit: "N".into(), values: f.to_vec() });
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
    Ok(TimeRecords { source: path.display().to_string(), start_s: records.time[0], sample_rate_hz: 1.0 / dt, channels })
}

/// `periods` copies of one steady period end to end. The steady state is periodic to the
/// tolerance of its check, so the copies join as the integration would have continued; the
/// record holds the period without its end point, so no sample is written twice.
fn repeated(mut one_period: TimeRecords, periods: usize) -> TimeRecords {
    for c in &mut one_period.channels {
        c.values = c.values.repeat(periods);
    }
    one_period
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
