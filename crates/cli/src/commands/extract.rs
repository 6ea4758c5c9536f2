//! `stickslip extract`: harmonics and FRFs from time records (CSV or UFF 58).
//!
//! Swept-sine records give one harmonics/FRF row per block of cycles, the frequency of each from
//! the reference channel. With `--stepped`, each record is one stationary excitation (a stepped-
//! sine frequency, or one point scanned by the vibrometer): one row per record, and `--frames`
//! reconstructs one period of every response of every record on the common excitation phase.
//! The FRFs are plotted per unit, amplitude and phase (`<stem>_amp_<unit>`, `<stem>_phase_<unit>`).
//! A steady state written by `stickslip timesim` is such a stationary record (several periods).

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use stickslip_core::hbm::fourier::amplitude_phase;
use stickslip_core::signal::frf::{frf_from_blocks, identify_force, interpolate_at, Normalization};
use stickslip_core::signal::harmonics::{extract, Block, SyncOptions};
use stickslip_core::signal::period;
use stickslip_io::records::{self, FrfCurve, FrfSet, TimeRecords};
use stickslip_io::uff;

#[derive(Clone, Copy, clap::ValueEnum)]
pub enum UffEncoding {
    Ascii,
    Binary,
}

#[derive(Clone, Copy, clap::ValueEnum)]
pub enum PlotFormat {
    Svg,
    Png,
}

#[derive(clap::Args)]
pub struct Args {
    /// Time-record files: CSV (`time_s,<name>_<unit>,...`) or UFF 58 (`.uff`, `.unv`).
    #[arg(required = true)]
    pub records: Vec<PathBuf>,
    /// Excitation reference channel: it gives the phase and frequency of every cycle.
    #[arg(long)]
    pub reference: String,
    /// Highest harmonic extracted.
    #[arg(long, default_value_t = 7)]
    pub harmonics: usize,
    /// Output directory.
    #[arg(long, default_value = "extract")]
    pub out: PathBuf,
    /// Response channels, comma-separated (default: every channel but the reference and a
    /// frequency channel in Hz).
    #[arg(long, value_delimiter = ',')]
    pub channels: Vec<String>,
    /// Each record is one stationary excitation (stepped sine, or one scanned point): fit every
    /// cycle after --skip-cycles at once.
    #[arg(long)]
    pub stepped: bool,
    /// Cycles per block of a swept record (more: less noise, coarser in frequency).
    #[arg(long, default_value_t = 1)]
    pub cycles_per_block: usize,
    /// Cycles dropped at the start of each record (transient).
    #[arg(long, default_value_t = 0)]
    pub skip_cycles: usize,
    /// Excitation force amplitude in N (e.g. identified by Eq. 1): FRFs are the response divided
    /// by it. Default: divided by the reference channel's fundamental.
    #[arg(long, conflicts_with = "calibration")]
    pub force_level: Option<f64>,
    /// Identify the force level by paper Eq. 1 against a calibration: a harmonics table written by
    /// `stickslip extract` for a record at a known level (--calibration-level), compared at an
    /// off-resonance frequency (--identify-at) where the structure is linear.
    #[arg(long, requires_all = ["calibration_level", "identify_at"])]
    pub calibration: Option<PathBuf>,
    /// Force level (N) of the calibration record (70 N in the paper).
    #[arg(long)]
    pub calibration_level: Option<f64>,
    /// Frequency (Hz) of the identification, inside both records' ranges (100 Hz in the paper).
    #[arg(long)]
    pub identify_at: Option<f64>,
    /// Response channel used for the identification (default: the first response).
    #[arg(long)]
    pub identify_channel: Option<String>,
    /// Also write the FRFs as UFF 58.
    #[arg(long, value_enum)]
    pub uff: Option<UffEncoding>,
    /// With --stepped: frames of one period of every response of every record (the vibrometer
    /// "video"), written to OUT/frames/.
    #[arg(long)]
    pub frames: Option<usize>,
    /// Plot file format of the FRF plots (amplitude and phase per unit; PNG needs a system font).
    #[arg(long, value_enum, default_value = "svg")]
    pub plot_format: PlotFormat,
    /// Do not plot the FRFs.
    #[arg(long)]
    pub no_plots: bool,
    /// Frames of the time integral of the responses (vibrometer velocities → displacements, as
    /// in the paper's Fig. 22); the mean is set to zero.
    #[arg(long, requires = "frames")]
    pub integrate: bool,
}

/// Read time records from CSV or UFF (by extension), reporting what UFF reading skipped.
fn load(path: &Path) -> Result<TimeRecords> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    if ext == "uff" || ext == "unv" {
        let file = uff::read(path)?;
        for s in &file.skipped {
            eprintln!(
                "warning: {}:{}: UFF dataset {} skipped (only dataset 58 holds records)",
                path.display(),
                s.line,
                s.dataset_type
            );
        }
        for w in &file.warnings {
            eprintln!("warning: {}: {w}", path.display());
        }
        Ok(records::time_records_from_uff(&file.datasets, &path.display().to_string())?)
    } else {
        Ok(records::read_time_csv(path)?)
    }
}

/// One record's reference and response channels.
struct Selected<'a> {
    reference: &'a records::Channel,
    responses: Vec<&'a records::Channel>,
}

fn select<'a>(r: &'a TimeRecords, args: &Args) -> Result<Selected<'a>> {
    let reference = r.channel(&args.reference)?;
    let responses = if args.channels.is_empty() {
        // A channel in Hz is the excitation's frequency (a swept record written by `timesim`
        // carries one), not a response to it.
        r.channels.iter().filter(|c| !std::ptr::eq(*c, reference) && c.unit != "Hz").collect()
    } else {
        args.channels.iter().map(|c| r.channel(c)).collect::<Result<Vec<_>, _>>()?
    };
    if responses.is_empty() {
        bail!("{}: no response channel besides the reference `{}`", r.source, args.reference);
    }
    Ok(Selected { reference, responses })
}

fn blocks_of(r: &TimeRecords, s: &Selected, options: &SyncOptions) -> Result<Vec<Block>> {
    let inputs: Vec<(&str, &[f64])> = s.responses.iter().map(|c| (c.name.as_str(), c.values.as_slice())).collect();
    extract(&s.reference.values, &inputs, r.sample_rate_hz, options).with_context(|| format!("in {}", r.source))
}

/// Columns and rows of a harmonics table: time, frequency, reference amplitude, then amplitude and
/// phase of harmonics 0..N of each response (h0: amplitude = mean, phase 0, as in `frf.csv`):
/// `<name>_h<k>_amp_<unit>`, `<name>_h<k>_phase_rad` (`<name>_<unit>_h<k>_phase_rad` when
/// several responses share the name).
fn harmonics_table(s: &Selected, blocks: &[(f64, &Block)], n: usize) -> (Vec<String>, Vec<Vec<f64>>) {
    let mut columns =
        vec!["time_s".to_string(), "frequency_Hz".into(), format!("{}_h1_amp_{}", s.reference.name, s.reference.unit)];
    for c in &s.responses {
        // Channels sharing a name (a `timesim` record's displacement, velocity and acceleration
        // of one output) each get their own phase columns, named with their unit as in the FRF
        // table (`records` module).
        let shared = s.responses.iter().filter(|o| o.name == c.name).count() > 1;
        let phase_of = if shared { format!("{}_{}", c.name, c.unit) } else { c.name.clone() };
        for k in 0..=n {
            columns.push(format!("{}_h{k}_amp_{}", c.name, c.unit));
            columns.push(format!("{phase_of}_h{k}_phase_rad"));
        }
    }
    let rows = blocks
        .iter()
        .map(|(t, b)| {
            let mut row = vec![*t, b.frequency_hz, b.reference[1]];
            for coeffs in &b.responses {
                row.extend([coeffs[0], 0.0]);
                for k in 1..=n {
                    let (a, p) = amplitude_phase(coeffs, k);
                    row.extend([a, p]);
                }
            }
            row
        })
        .collect();
    (columns, rows)
}

/// Amplitude of harmonic 1 at `frequency_hz` of a curve sampled in any order (a sweep may go down).
fn amplitude_at(frequency_hz: &[f64], amplitude: &[f64], at_hz: f64) -> Result<f64> {
    let mut pairs: Vec<(f64, f64)> = frequency_hz.iter().copied().zip(amplitude.iter().copied()).collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (f, a): (Vec<f64>, Vec<f64>) = pairs.into_iter().unzip();
    Ok(interpolate_at(&f, &a, at_hz)?)
}

/// Force level of `blocks` by paper Eq. 1, when a calibration is given.
fn identified_level(s: &Selected, blocks: &[Block], args: &Args) -> Result<Option<f64>> {
    let (Some(cal), Some(cal_level), Some(at)) = (&args.calibration, args.calibration_level, args.identify_at) else {
        return Ok(None);
    };
    let r = match &args.identify_channel {
        Some(name) => s
            .responses
            .iter()
            .position(|c| c.name == *name || c.column() == *name)
            .with_context(|| format!("--identify-channel `{name}` is not a response channel"))?,
        None => 0,
    };
    let c = s.responses[r];
    let f: Vec<f64> = blocks.iter().map(|b| b.frequency_hz).collect();
    let a: Vec<f64> = blocks.iter().map(|b| b.harmonic(r, 1).norm()).collect();
    let response = amplitude_at(&f, &a, at).with_context(|| format!("response `{}` at {at} Hz", c.name))?;
    let table = records::read_table(cal)?;
    let column = format!("{}_h1_amp_{}", c.name, c.unit);
    let (Some(cf), Some(ca)) = (table.column("frequency_Hz"), table.column(&column)) else {
        bail!(
            "{}: no `frequency_Hz` and `{column}` columns (a harmonics table written by `stickslip extract`)",
            cal.display()
        );
    };
    let reference = amplitude_at(cf, ca, at).with_context(|| format!("calibration {} at {at} Hz", cal.display()))?;
    let level = identify_force(cal_level, reference, response)?;
    println!(
        "force level {level:.4} N (Eq. 1: {cal_level} N x {response:.6e} / {reference:.6e} {} of `{}` at {at} Hz)",
        c.unit, c.name
    );
    Ok(Some(level))
}

/// FRFs of every response over `blocks`, with the level and unit of the normalisation.
fn frf_set(s: &Selected, blocks: &[Block], args: &Args, source: &str) -> Result<FrfSet> {
    let (normalization, per, level_n) = match args.force_level.or(identified_level(s, blocks, args)?) {
        Some(f) => (Normalization::Force { amplitude_n: f }, "N".to_string(), Some(f)),
        None => {
            // The reference's fundamental; as a force, its median amplitude is the level.
            let mut amps: Vec<f64> = blocks.iter().map(|b| b.reference[1]).collect();
            amps.sort_by(f64::total_cmp);
            let level = (s.reference.unit == "N").then(|| amps[amps.len() / 2]);
            let per = if s.reference.unit.is_empty() { "ref".to_string() } else { s.reference.unit.clone() };
            (Normalization::ReferenceChannel, per, level)
        }
    };
    let mut curves = Vec::new();
    let mut frequency_hz = Vec::new();
    for (r, c) in s.responses.iter().enumerate() {
        let points = frf_from_blocks(blocks, r, normalization)?;
        frequency_hz = points.iter().map(|p| p.frequency_hz).collect();
        curves.push(FrfCurve {
            name: c.name.clone(),
            unit: format!("{}_per_{per}", if c.unit.is_empty() { "1" } else { &c.unit }),
            values: points.iter().map(|p| p.value).collect(),
            has_phase: true,
        });
    }
    Ok(FrfSet { source: source.to_string(), level_n, frequency_hz, curves })
}

fn write_frfs(dir: &Path, stem: &str, set: &FrfSet, args: &Args) -> Result<Vec<PathBuf>> {
    let mut written = vec![dir.join(format!("{stem}.csv"))];
    records::write_frf_csv(&written[0], std::slice::from_ref(set))?;
    if let Some(enc) = args.uff {
        let path = dir.join(format!("{stem}.uff"));
        let enc = match enc {
            UffEncoding::Ascii => uff::Encoding::Ascii,
            UffEncoding::Binary => uff::Encoding::Binary,
        };
        uff::write(&path, &records::frf_set_to_uff(set), enc)?;
        written.push(path);
    }
    if !args.no_plots {
        let format = match args.plot_format {
            PlotFormat::Svg => stickslip_io::study::PlotFormat::Svg,
            PlotFormat::Png => stickslip_io::study::PlotFormat::Png,
        };
        written.extend(stickslip_io::plot::plot_frf_set(dir, stem, set, format)?);
    }
    Ok(written)
}

fn stem(path: &Path) -> String {
    path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "record".into())
}

pub fn main(args: Args) -> Result<()> {
    if args.frames.is_some() && !args.stepped {
        bail!("--frames needs --stepped: frames are built from stationary records, one per point");
    }
    std::fs::create_dir_all(&args.out).with_context(|| format!("creating {}", args.out.display()))?;
    let loaded: Vec<TimeRecords> = args.records.iter().map(|p| load(p)).collect::<Result<_>>()?;
    let mut written = Vec::new();
    let mut frame_files = Vec::new();
    if !args.stepped {
        let options = SyncOptions {
            n_harmonics: args.harmonics,
            cycles_per_block: args.cycles_per_block,
            skip_cycles: args.skip_cycles,
        };
        for (path, r) in args.records.iter().zip(&loaded) {
            let s = select(r, &args)?;
            let blocks = blocks_of(r, &s, &options)?;
            let timed: Vec<(f64, &Block)> =
                blocks.iter().map(|b| (r.start_s + 0.5 * (b.start_s + b.end_s), b)).collect();
            let (columns, rows) = harmonics_table(&s, &timed, args.harmonics);
            let h = args.out.join(format!("{}_harmonics.csv", stem(path)));
            records::write_table(&h, &columns, &rows)?;
            written.push(h);
            let set = frf_set(&s, &blocks, &args, &r.source)?;
            written.extend(write_frfs(&args.out, &format!("{}_frf", stem(path)), &set, &args)?);
            println!(
                "{}: {} blocks, {:.3} to {:.3} Hz",
                path.display(),
                blocks.len(),
                first_f(&blocks),
                last_f(&blocks)
            );
        }
    } else {
        let options = SyncOptions::whole_record(args.harmonics, args.skip_cycles);
        let mut all: Vec<(f64, Block)> = Vec::new();
        let mut names: Option<Vec<String>> = None;
        let mut point_names = Vec::new();
        let mut coeffs = Vec::new();
        for (path, r) in args.records.iter().zip(&loaded) {
            let s = select(r, &args)?;
            let these: Vec<String> = s.responses.iter().map(|c| c.column()).collect();
            match &names {
                None => names = Some(these.clone()),
                Some(n) if *n != these => {
                    bail!(
                        "{}: response channels {these:?} differ from the first record's {n:?}: give --channels",
                        path.display()
                    )
                }
                _ => {}
            }
            let block = blocks_of(r, &s, &options)?.remove(0);
            let omega = 2.0 * std::f64::consts::PI * block.frequency_hz;
            for (c, x) in s.responses.iter().zip(&block.responses) {
                point_names.push(format!("{}.{}", stem(path), c.name));
                coeffs.push(if args.integrate { period::integrate(x, omega)? } else { x.clone() });
            }
            all.push((r.start_s + 0.5 * (block.start_s + block.end_s), block));
        }
        let s = select(&loaded[0], &args)?;
        let mut order: Vec<usize> = (0..all.len()).collect();
        order.sort_by(|&a, &b| all[a].1.frequency_hz.total_cmp(&all[b].1.frequency_hz));
        let timed: Vec<(f64, &Block)> = order.iter().map(|&i| (all[i].0, &all[i].1)).collect();
        let (columns, rows) = harmonics_table(&s, &timed, args.harmonics);
        let h = args.out.join("harmonics.csv");
        records::write_table(&h, &columns, &rows)?;
        written.push(h);
        let sorted: Vec<Block> = order.iter().map(|&i| all[i].1.clone()).collect();
        let set = frf_set(&s, &sorted, &args, "stepped sine")?;
        written.extend(write_frfs(&args.out, "frf", &set, &args)?);
        if let Some(n_frames) = args.frames {
            let frames = period::frames(&coeffs, n_frames)?;
            let unit = match (args.integrate, s.responses[0].unit.as_str()) {
                (false, u) => u.to_string(),
                (true, "m_s2") => "m_s".into(),
                (true, "m_s") => "m".into(),
                (true, u) => format!("{u}_s"),
            };
            let files =
                records::write_frames(&args.out.join("frames"), &point_names, &format!("value_{unit}"), &frames)?;
            println!("{} frames of {} points in {}", files.len(), point_names.len(), args.out.join("frames").display());
            frame_files = files;
        }
        println!("{} stepped-sine records, {:.3} to {:.3} Hz", sorted.len(), first_f(&sorted), last_f(&sorted));
    }
    for w in &written {
        println!("wrote {}", w.display());
    }
    written.extend(frame_files);
    for old in stickslip_io::output::replace_previous_run(&args.out, "extract", &written)? {
        println!("removed {} (written by the previous extract, not by this one)", old.display());
    }
    Ok(())
}

fn first_f(blocks: &[Block]) -> f64 {
    blocks.first().map_or(f64::NAN, |b| b.frequency_hz)
}

fn last_f(blocks: &[Block]) -> f64 {
    blocks.last().map_or(f64::NAN, |b| b.frequency_hz)
}
