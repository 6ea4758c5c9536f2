//! `stickslip compare`: measured against simulated FRFs (paper Section 5.1), per force level,
//! output and quantity an overlay plot of the amplitudes (`compare_level<i>_<out>_<disp|vel|accel>`)
//! and a table of the resonance peaks (frequency, amplitude and their errors), on stdout and as
//! `peaks.csv`; the same, with the plots, as the "Test comparison" section of the run's
//! `report.html` (`--no-report`: not).
//!
//! Measured FRFs: CSV (`[level_N,]frequency_Hz,<name>_amp_<unit>[,<name>_phase_rad]`, as
//! `stickslip extract` writes them) or UFF 58 (function type 4). A curve in `m_s2_per_N` is
//! compared with the simulated `<name>_accel_frf_m_s2_per_N`, one in `m_per_N` with
//! `<name>_disp_frf_m_per_N`, one in `m_s_per_N` with the latter times Ω (the first harmonic's
//! velocity). Curves in other units (a joint's force, for instance) are skipped and said so;
//! `--curves` picks the curves to compare. Each quantity gets its own plot: a displacement and an
//! acceleration FRF span different decades and do not share an axis.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use stickslip_core::signal::peaks::peaks;
use stickslip_io::plot::{self, MeasuredCurve};
use stickslip_io::records::{self, FrfCurve, FrfSet};
use stickslip_io::report;
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
    /// Measured curves to compare, comma-separated: a curve's name (`tip`, all its units) or
    /// its amplitude column (`tip_amp_m_s2_per_N`). Default: every curve in a comparable unit.
    #[arg(long, value_delimiter = ',')]
    pub curves: Vec<String>,
    /// Force level in N of measured files without a `level_N` column.
    #[arg(long)]
    pub level: Option<f64>,
    /// Minimum prominence of a peak, as a fraction of the curve's maximum.
    #[arg(long, default_value_t = 0.1)]
    pub prominence: f64,
    /// Plot file format (PNG needs a system font).
    #[arg(long, value_enum, default_value = "svg")]
    pub plot_format: PlotFormat,
    /// Leave the run's report alone (by default the comparison becomes the "Test comparison"
    /// section of `report.html` beside the simulated table, when there is one).
    #[arg(long)]
    pub no_report: bool,
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

/// The simulated quantity an FRF in `unit` is compared with: its short name (in plot file
/// names), the column of `frf.csv` it is read from, and the power of Ω that turns that column
/// into the unit (the velocity FRF is Ω times the displacement FRF, for the first harmonic).
fn simulated_quantity(name: &str, unit: &str) -> Option<(&'static str, String, i32)> {
    match unit {
        "m_per_N" => Some(("disp", format!("{name}_disp_frf_m_per_N"), 0)),
        "m_s_per_N" => Some(("vel", format!("{name}_disp_frf_m_per_N"), 1)),
        "m_s2_per_N" => Some(("accel", format!("{name}_accel_frf_m_s2_per_N"), 0)),
        _ => None,
    }
}

/// Is `curve` among those asked by `--curves` (all when none is asked)?
fn is_asked(curve: &FrfCurve, asked: &[String]) -> bool {
    asked.is_empty() || asked.iter().any(|a| *a == curve.name || *a == format!("{}_amp_{}", curve.name, curve.unit))
}

/// Curves of one overlay plot.
struct Group {
    level_index: usize,
    level_n: f64,
    output: String,
    unit: String,
    /// `disp`, `vel` or `accel`.
    quantity: &'static str,
    simulated: (Vec<f64>, Vec<f64>),
    measured: Vec<MeasuredCurve>,
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
    // Per (level, output, quantity): the measured curves and the simulated one.
    let mut groups: Vec<Group> = Vec::new();
    let mut compared = 0;
    let mut available: Vec<String> = Vec::new();
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
            available.extend(set.curves.iter().map(|c| format!("{}_amp_{}", c.name, c.unit)));
            for curve in set.curves.iter().filter(|c| is_asked(c, &args.curves)) {
                let output = args.output.clone().unwrap_or_else(|| curve.name.clone());
                let Some((quantity, column, omega_power)) = simulated_quantity(&output, &curve.unit) else {
                    if !args.curves.is_empty() {
                        bail!(
                            "{}: curve `{}_amp_{}` cannot be compared: use m_s2_per_N (accelerance), m_s_per_N (mobility) or m_per_N (receptance)",
                            path.display(),
                            curve.name,
                            curve.unit
                        );
                    }
                    eprintln!(
                        "note: {}: curve `{}_amp_{}` skipped (not a displacement, velocity or acceleration per newton)",
                        path.display(),
                        curve.name,
                        curve.unit
                    );
                    continue;
                };
                let Some(sim_amp) = sim.column(&column) else {
                    let outputs: Vec<&str> =
                        sim.columns.iter().filter_map(|c| c.strip_suffix("_disp_frf_m_per_N")).collect();
                    let message = format!(
                        "{}: no column `{column}` for measured curve `{}_amp_{}`; simulated outputs are {outputs:?}",
                        sim_path.display(),
                        curve.name,
                        curve.unit
                    );
                    // A curve the user picked must be compared; among all the curves of a file
                    // (a joint's channels extracted beside the outputs), one without a
                    // simulated output is passed over.
                    if !args.curves.is_empty() || args.output.is_some() {
                        bail!("{message} (use --output)");
                    }
                    eprintln!("note: {message}: skipped");
                    continue;
                };
                compared += 1;
                let sim_f: Vec<f64> = sim_rows.iter().map(|&r| sim_freq[r]).collect();
                let omega = |f: f64| (2.0 * std::f64::consts::PI * f).powi(omega_power);
                let sim_a: Vec<f64> = sim_rows.iter().map(|&r| sim_amp[r].abs() * omega(sim_freq[r])).collect();
                let meas_a: Vec<f64> = curve.values.iter().map(|v| v.norm()).collect();
                let sim_peaks = peaks(&sim_f, &sim_a, args.prominence);
                for m in peaks(&set.frequency_hz, &meas_a, args.prominence) {
                    let nearest = sim_peaks
                        .iter()
                        .min_by(|a, b| {
                            (a.frequency_hz - m.frequency_hz).abs().total_cmp(&(b.frequency_hz - m.frequency_hz).abs())
                        })
                        .copied();
                    rows.push(report::ComparedPeak {
                        level_n: sim_l,
                        output: output.clone(),
                        unit: curve.unit.clone(),
                        source: stem.clone(),
                        measured_frequency_hz: m.frequency_hz,
                        measured_amplitude: m.amplitude,
                        simulated_frequency_hz: nearest.map_or(f64::NAN, |p| p.frequency_hz),
                        simulated_amplitude: nearest.map_or(f64::NAN, |p| p.amplitude),
                    });
                }
                let same = |g: &Group| g.level_index == level_index && g.output == output && g.quantity == quantity;
                let group = match groups.iter().position(same) {
                    Some(g) => g,
                    None => {
                        groups.push(Group {
                            level_index,
                            level_n: sim_l,
                            output: output.clone(),
                            unit: curve.unit.clone(),
                            quantity,
                            simulated: (sim_f, sim_a),
                            measured: Vec::new(),
                        });
                        groups.len() - 1
                    }
                };
                groups[group].measured.push(MeasuredCurve {
                    label: stem.clone(),
                    frequency_hz: set.frequency_hz.clone(),
                    amplitude: meas_a,
                });
            }
        }
    }
    for asked in &args.curves {
        if !available.iter().any(|a| a == asked || a.split_once("_amp_").is_some_and(|(n, _)| n == asked)) {
            bail!("--curves: no measured curve `{asked}`; the measured files have {available:?}");
        }
    }
    if compared == 0 {
        bail!(
            "no measured curve to compare{}: curves in m_per_N, m_s_per_N or m_s2_per_N are compared",
            if args.curves.is_empty() { String::new() } else { format!(" among --curves {:?}", args.curves) }
        );
    }
    let mut written = Vec::new();
    // The plots with their captions in the run's report.
    let mut figures = Vec::new();
    for g in &groups {
        let plot = args.out.join(format!("compare_level{}_{}_{}.{ext}", g.level_index, g.output, g.quantity));
        let title = format!("{} at {} N: measured and simulated", g.output, g.level_n);
        plot::plot_comparison(&plot, &title, &g.unit, &g.simulated, &g.measured)?;
        println!("wrote {}", plot.display());
        let quantity = match g.quantity {
            "disp" => "displacement",
            "vel" => "velocity",
            _ => "acceleration",
        };
        figures.push((
            plot.clone(),
            format!("{} at {} N, {quantity} FRF: measured (markers) and simulated", g.output, g.level_n),
        ));
        written.push(plot);
    }
    let (table, csv) = peak_table(&rows);
    print!("{table}");
    let csv_path = args.out.join("peaks.csv");
    std::fs::write(&csv_path, csv).with_context(|| format!("writing {}", csv_path.display()))?;
    println!("wrote {}", csv_path.display());
    written.push(csv_path);
    for old in stickslip_io::output::replace_previous_run(&args.out, "compare", &written)? {
        println!("removed {} (written by the previous compare, not by this one)", old.display());
    }
    let report = sim_path.with_file_name(report::REPORT_FILE);
    if !args.no_report && report.is_file() {
        let comparison = report::Comparison {
            measured: args.measured.iter().map(|m| m.display().to_string()).collect(),
            figures,
            peaks: rows,
        };
        let page = std::fs::read_to_string(&report).with_context(|| format!("reading {}", report.display()))?;
        let page = report::with_comparison(&page, &comparison)?;
        std::fs::write(&report, page).with_context(|| format!("writing {}", report.display()))?;
        println!("report: {} (its test comparison section)", report.display());
    }
    Ok(())
}

/// Text table and CSV of the compared peaks; errors are simulated − measured, relative to measured.
fn peak_table(rows: &[report::ComparedPeak]) -> (String, String) {
    let mut text = format!(
        "{:>10} {:<14} {:<16} {:>12} {:>12} {:>9} {:>12} {:>12} {:>9}\n",
        "level_N", "output", "measured", "f_meas_Hz", "f_sim_Hz", "df_%", "amp_meas", "amp_sim", "amp_err_%"
    );
    let mut csv = String::from(
        "level_N,output,unit,measured_file,measured_frequency_Hz,simulated_frequency_Hz,frequency_error_Hz,frequency_error_pct,measured_amplitude,simulated_amplitude,amplitude_error_pct\n",
    );
    for r in rows {
        let (mf, sf, ma, sa) =
            (r.measured_frequency_hz, r.simulated_frequency_hz, r.measured_amplitude, r.simulated_amplitude);
        let (df_pct, da_pct) = (r.frequency_error_pct(), r.amplitude_error_pct());
        let _ = writeln!(
            text,
            "{:>10.1} {:<14} {:<16} {:>12.3} {:>12.3} {:>9.2} {:>12.4e} {:>12.4e} {:>9.2}",
            r.level_n, r.output, r.source, mf, sf, df_pct, ma, sa, da_pct
        );
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{},{},{},{},{},{}",
            r.level_n,
            r.output,
            r.unit,
            r.source,
            cell(mf),
            cell(sf),
            cell(sf - mf),
            cell(df_pct),
            cell(ma),
            cell(sa),
            cell(da_pct)
        );
    }
    (text, csv)
}

/// A number of `peaks.csv`: empty where there is none (no simulated peak, or an error relative
/// to a measured amplitude of zero), as CSV readers take a missing value, rather than NaN or
/// inf; the table printed beside it shows them as such.
fn cell(v: f64) -> String {
    if v.is_finite() {
        v.to_string()
    } else {
        String::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_simulated_peak_leaves_its_fields_empty_in_the_csv() {
        let peak = |simulated: f64| report::ComparedPeak {
            level_n: 2.0,
            output: "tip".into(),
            unit: "m_per_N".into(),
            source: "test".into(),
            measured_frequency_hz: 100.0,
            measured_amplitude: 1e-3,
            simulated_frequency_hz: simulated,
            simulated_amplitude: simulated * 1e-5,
        };
        let (_, csv) = peak_table(&[peak(101.0), peak(f64::NAN)]);
        let lines: Vec<&str> = csv.lines().collect();
        assert!(!csv.to_lowercase().contains("nan") && !csv.contains("inf"), "{csv}");
        assert!(lines[1].starts_with("2,tip,m_per_N,test,100,101,1,1,0.001,0.00101,1.0000000000"), "{}", lines[1]);
        assert_eq!(lines[2], "2,tip,m_per_N,test,100,,,,0.001,,");
    }
}
