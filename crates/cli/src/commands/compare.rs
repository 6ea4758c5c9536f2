//! `stickslip compare`: measured against simulated FRFs (paper Section 5.1), per force level an
//! overlay plot of the amplitudes and a table of the resonance peaks (frequency, amplitude and
//! their errors), on stdout and as CSV.
//!
//! Measured FRFs: CSV (`[level_N,]frequency_Hz,<name>_amp_<unit>[,<name>_phase_rad]`) or UFF 58
//! (function type 4). A curve in `m_s2_per_N` is compared with the simulated
//! `<name>_accel_frf_m_s2_per_N`, one in `m_per_N` with `<name>_disp_frf_m_per_N`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use plotters::prelude::*;
use stickslip_core::signal::peaks::{peaks, Peak};
use stickslip_io::plot;
use stickslip_io::records::{self, FrfSet};
use stickslip_io::uff;

#[derive(Clone, Copy, clap::ValueEnum)]
pub enum PlotFormat {
    Svg,
    Png,
}

#[derive(clap::Args)]
pub struct Args {
    /// Measured FRF files (CSV or UFF 58), one or several force levels each.
    #[arg(long, required = true, num_args = 1..)]
    pub measured: Vec<PathBuf>,
    /// Simulated FRF table written by `stickslip run` (DIR/frf.csv, or DIR).
    #[arg(long)]
    pub simulated: PathBuf,
    /// Output directory.
    #[arg(long, default_value = "compare")]
    pub out: PathBuf,
    /// Simulated output to compare with (default: the measured curve's name).
    #[arg(long)]
    pub output: Option<String>,
    /// Force level in N of measured files without a `level_N` column.
    #[arg(long)]
    pub level: Option<f64>,
    /// Minimum prominence of a peak, as a fraction of the curve's maximum.
    #[arg(long, default_value_t = 0.1)]
    pub prominence: f64,
    /// Plot file format (PNG needs a system font).
    #[arg(long, value_enum, default_value = "svg")]
    pub plot_format: PlotFormat,
}

/// Relative tolerance when matching a measured level to a simulated one: levels identified by
/// Eq. 1 are quoted to a few newtons in the paper (70, 1070, 1875, 2910 N).
const LEVEL_MATCH: f64 = 0.02;

fn load_measured(path: &Path) -> Result<Vec<FrfSet>> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    if ext == "uff" || ext == "unv" {
        let file = uff::read(path)?;
        for w in &file.warnings {
            eprintln!("warning: {}: {w}", path.display());
        }
        let sets = records::frf_sets_from_uff(&file.datasets, &path.display().to_string());
        if sets.is_empty() {
            bail!("{}: no FRF dataset 58 (function type 4)", path.display());
        }
        Ok(sets)
    } else {
        Ok(records::read_frf_csv(path)?)
    }
}

/// Simulated column of an FRF in `unit`, for output `name`.
fn simulated_column(name: &str, unit: &str) -> Result<String> {
    match unit {
        "m_s2_per_N" => Ok(format!("{name}_accel_frf_m_s2_per_N")),
        "m_per_N" => Ok(format!("{name}_disp_frf_m_per_N")),
        other => bail!(
            "measured FRF unit `{other}` cannot be compared: use m_s2_per_N (accelerance) or m_per_N (receptance)"
        ),
    }
}

/// Curves of one overlay plot.
struct Group {
    level_index: usize,
    level_n: f64,
    output: String,
    unit: String,
    simulated: (Vec<f64>, Vec<f64>),
    /// (label, frequency, amplitude) of each measured curve.
    measured: Vec<(String, Vec<f64>, Vec<f64>)>,
}

/// One compared peak.
struct PeakRow {
    level_n: f64,
    output: String,
    unit: String,
    /// Measured file (stem).
    source: String,
    measured: Peak,
    simulated: Option<Peak>,
}

pub fn main(args: Args) -> Result<()> {
    let sim_path = if args.simulated.is_dir() { args.simulated.join("frf.csv") } else { args.simulated.clone() };
    let sim = records::read_table(&sim_path)?;
    let (sim_level, sim_freq) = match (sim.column("level_N"), sim.column("frequency_Hz")) {
        (Some(l), Some(f)) => (l.to_vec(), f.to_vec()),
        _ => bail!("{}: not a simulated FRF table (no `level_N` and `frequency_Hz` columns)", sim_path.display()),
    };
    let mut levels: Vec<f64> = Vec::new();
    for &l in &sim_level {
        if !levels.contains(&l) {
            levels.push(l);
        }
    }
    std::fs::create_dir_all(&args.out).with_context(|| format!("creating {}", args.out.display()))?;
    let ext = match args.plot_format {
        PlotFormat::Svg => "svg",
        PlotFormat::Png => "png",
    };
    let mut rows = Vec::new();
    // Per (level, output): the measured curves (label, frequency, amplitude) and the simulated one.
    let mut groups: Vec<Group> = Vec::new();
    for path in &args.measured {
        let stem = path.file_stem().map_or_else(|| "measured".into(), |s| s.to_string_lossy().into_owned());
        for set in load_measured(path)? {
            let level = match set.level_n.or(args.level) {
                Some(l) => l,
                None if levels.len() == 1 => levels[0],
                None => bail!(
                    "{}: no force level (`level_N` column in CSV, id2 `level <F> N` in UFF); add one or pass --level (simulated levels: {levels:?} N)",
                    path.display()
                ),
            };
            let Some(level_index) = levels.iter().position(|&l| (l - level).abs() <= LEVEL_MATCH * level.abs()) else {
                bail!(
                    "{}: level {level} N has no simulated counterpart within 2 % (simulated levels: {levels:?} N)",
                    path.display()
                );
            };
            let sim_l = levels[level_index];
            let sim_rows: Vec<usize> = (0..sim_level.len()).filter(|&r| sim_level[r] == sim_l).collect();
            for curve in &set.curves {
                let output = args.output.clone().unwrap_or_else(|| curve.name.clone());
                let column = simulated_column(&output, &curve.unit)?;
                let sim_amp = sim.column(&column).ok_or_else(|| {
                    let outputs: Vec<&str> =
                        sim.columns.iter().filter_map(|c| c.strip_suffix("_disp_frf_m_per_N")).collect();
                    anyhow::anyhow!(
                        "{}: no column `{column}` for measured curve `{}`; simulated outputs are {outputs:?} (use --output)",
                        sim_path.display(),
                        curve.name
                    )
                })?;
                let sim_f: Vec<f64> = sim_rows.iter().map(|&r| sim_freq[r]).collect();
                let sim_a: Vec<f64> = sim_rows.iter().map(|&r| sim_amp[r].abs()).collect();
                let meas_a: Vec<f64> = curve.values.iter().map(|v| v.norm()).collect();
                let sim_peaks = peaks(&sim_f, &sim_a, args.prominence);
                for m in peaks(&set.frequency_hz, &meas_a, args.prominence) {
                    let nearest = sim_peaks
                        .iter()
                        .min_by(|a, b| {
                            (a.frequency_hz - m.frequency_hz).abs().total_cmp(&(b.frequency_hz - m.frequency_hz).abs())
                        })
                        .copied();
                    rows.push(PeakRow {
                        level_n: sim_l,
                        output: output.clone(),
                        unit: curve.unit.clone(),
                        source: stem.clone(),
                        measured: m,
                        simulated: nearest,
                    });
                }
                let group = match groups.iter().position(|g| g.level_index == level_index && g.output == output) {
                    Some(g) => g,
                    None => {
                        groups.push(Group {
                            level_index,
                            level_n: sim_l,
                            output: output.clone(),
                            unit: curve.unit.clone(),
                            simulated: (sim_f, sim_a),
                            measured: Vec::new(),
                        });
                        groups.len() - 1
                    }
                };
                groups[group].measured.push((stem.clone(), set.frequency_hz.clone(), meas_a));
            }
        }
    }
    for g in &groups {
        let plot = args.out.join(format!("compare_level{}_{}.{ext}", g.level_index, g.output));
        overlay(&plot, g).with_context(|| format!("plotting {}", plot.display()))?;
        println!("wrote {}", plot.display());
    }
    let (table, csv) = peak_table(&rows);
    print!("{table}");
    let csv_path = args.out.join("peaks.csv");
    std::fs::write(&csv_path, csv).with_context(|| format!("writing {}", csv_path.display()))?;
    println!("wrote {}", csv_path.display());
    Ok(())
}

/// Text table and CSV of the compared peaks; errors are simulated − measured, relative to measured.
fn peak_table(rows: &[PeakRow]) -> (String, String) {
    let mut text = format!(
        "{:>10} {:<14} {:<16} {:>12} {:>12} {:>9} {:>12} {:>12} {:>9}\n",
        "level_N", "output", "measured", "f_meas_Hz", "f_sim_Hz", "df_%", "amp_meas", "amp_sim", "damp_%"
    );
    let mut csv = String::from(
        "level_N,output,unit,measured_file,measured_frequency_Hz,simulated_frequency_Hz,frequency_error_Hz,frequency_error_pct,measured_amplitude,simulated_amplitude,amplitude_error_pct\n",
    );
    for r in rows {
        let m = r.measured;
        let (sf, sa) = r.simulated.map_or((f64::NAN, f64::NAN), |s| (s.frequency_hz, s.amplitude));
        let df = sf - m.frequency_hz;
        let df_pct = 100.0 * df / m.frequency_hz;
        let da_pct = 100.0 * (sa - m.amplitude) / m.amplitude;
        let _ = writeln!(
            text,
            "{:>10.1} {:<14} {:<16} {:>12.3} {:>12.3} {:>9.2} {:>12.4e} {:>12.4e} {:>9.2}",
            r.level_n, r.output, r.source, m.frequency_hz, sf, df_pct, m.amplitude, sa, da_pct
        );
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{},{},{},{},{},{}",
            r.level_n, r.output, r.unit, r.source, m.frequency_hz, sf, df, df_pct, m.amplitude, sa, da_pct
        );
    }
    (text, csv)
}

/// Measured (points) and simulated (line) FRF amplitudes on a log axis, SVG or PNG by extension.
fn overlay(path: &Path, g: &Group) -> Result<()> {
    match path.extension().and_then(|e| e.to_str()) {
        Some("png") => draw(BitMapBackend::new(path, (1000, 650)).into_drawing_area(), g),
        _ => draw(SVGBackend::new(path, (1000, 650)).into_drawing_area(), g),
    }
}

fn draw<DB: DrawingBackend>(root: DrawingArea<DB, plotters::coord::Shift>, g: &Group) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let e = |err: DrawingAreaErrorKind<DB::ErrorType>| anyhow::anyhow!("{err}");
    // Log axis: only positive finite amplitudes are drawn.
    let points = |f: &[f64], a: &[f64]| -> Vec<(f64, f64)> {
        f.iter().zip(a).map(|(&x, &y)| (x, y)).filter(|(x, y)| x.is_finite() && y.is_finite() && *y > 0.0).collect()
    };
    let sim = points(&g.simulated.0, &g.simulated.1);
    let meas: Vec<(String, Vec<(f64, f64)>)> = g.measured.iter().map(|(l, f, a)| (l.clone(), points(f, a))).collect();
    let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
    for &(x, y) in sim.iter().chain(meas.iter().flat_map(|m| m.1.iter())) {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    if !x0.is_finite() {
        bail!("no positive amplitude to plot");
    }
    if x1 <= x0 {
        (x0, x1) = (x0 - 1.0, x1 + 1.0);
    }
    // Finite axis ends whatever the data (an amplitude of 1e308 once made the log axis end at
    // infinity, where plotting never finished).
    let (x, y) = (plot::linear_axis(x0, x1), plot::log_axis(y0, y1));
    root.fill(&WHITE).map_err(e)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(format!("{} at {} N: measured and simulated", g.output, g.level_n), ("sans-serif", 22))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(85)
        .build_cartesian_2d(x, y.log_scale())
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc("frequency (Hz)")
        .y_desc(format!("|FRF| ({})", g.unit.replace('_', " ")))
        .y_label_formatter(&|y| format!("{y:.0e}"))
        .draw()
        .map_err(e)?;
    for (i, (label, pts)) in meas.iter().enumerate() {
        let color = Palette99::pick(i + 1).to_rgba();
        chart
            .draw_series(pts.iter().map(|&p| Circle::new(p, 2, color.filled())))
            .map_err(e)?
            .label(format!("measured {label}"))
            .legend(move |(x, y)| Circle::new((x + 10, y), 3, color.filled()));
    }
    chart
        .draw_series(LineSeries::new(sim.iter().copied(), BLACK.stroke_width(2)))
        .map_err(e)?
        .label("simulated")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(2)));
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(e)?;
    root.present().map_err(e)?;
    Ok(())
}
