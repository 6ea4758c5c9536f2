//! Result files of a frequency sweep: the FRF table `frf.csv` (one row per converged point, all
//! levels), the per-point time data `points/level<i>_point<j>.csv`, and `frf.npz` (the same
//! columns as NumPy arrays).
//!
//! The solver converts its branches into the plain records below ([`LevelResult`],
//! [`PointRecord`], ...); the writers only format them. Numbers are written in the shortest
//! round-trip exponent form (`{:e}`'s form, `ryu`'s digits in the tables: `csv::push_number`),
//! so reading a file back gives the same `f64` bit for bit.

pub(crate) mod csv;
mod manifest;
mod npz;

use std::path::PathBuf;

#[cfg(feature = "plot")]
use crate::study::PlotFormat;
#[cfg(feature = "plot")]
use std::path::Path;

pub use csv::{
    frf_columns, frf_row, time_data_files, write_bifurcations_csv, write_frf_csv, write_peaks_csv, write_point_csv,
    write_snapshot_csv, write_time_data,
};
pub use manifest::{manifest_path, replace_previous_run};
pub use npz::write_frf_npz;
pub(crate) use npz::NpzFile;

/// All converged points of one force level.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LevelResult {
    /// Excitation level (N).
    pub level_n: f64,
    pub points: Vec<PointRecord>,
    /// Per output, the resonance peak located along the branch (empty when not located).
    pub peaks: Vec<Peak>,
    /// Bifurcations along the branch: folds and branch points always, period doublings and
    /// Neimark-Sacker bifurcations when stability is computed.
    pub bifurcations: Vec<BifurcationRecord>,
}

/// The largest displacement FRF of one output at one level.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Peak {
    /// Force level (N).
    pub level_n: f64,
    pub output: String,
    /// Frequency of the largest amplitude (Hz).
    pub frequency_hz: f64,
    /// |X₁| / F there (m/N).
    pub disp_frf: f64,
    /// Ω² |X₁| / F there (m s⁻² / N).
    pub accel_frf: f64,
    /// Located between the sampled points (`stickslip_core::continuation::maximise_along`),
    /// or, when false, the largest sampled point (a peak at an end of the band).
    pub located: bool,
}

/// One converged point of a branch.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PointRecord {
    /// Excitation frequency Ω / 2π (Hz).
    pub frequency_hz: f64,
    /// Newton iterations of the corrector.
    pub iterations: usize,
    /// Final residual norm relative to the excitation norm.
    pub residual: f64,
    pub outputs: Vec<OutputRecord>,
    pub elements: Vec<ElementRecord>,
    /// Work of the excitation per cycle (J): the energy the force puts in, which the joints
    /// (`ElementRecord::energy_j`) and the viscous damping dissipate at a periodic solution.
    pub input_energy_j: f64,
    /// Energy dissipated per cycle by the viscous damping (J).
    pub viscous_energy_j: f64,
    /// Stability by Hill's method, when the study asks for it (`stability = true`).
    pub stability: Option<PointStability>,
}

/// Stability of a periodic solution: its leading Floquet exponent (the one with the largest
/// real part; a perturbation grows or decays as `e^{st}`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointStability {
    pub stable: bool,
    /// Real part of the leading exponent (1/s): negative when stable.
    pub exponent_re: f64,
    /// Its imaginary part (rad/s): 0 for a real exponent, the frequency of the perturbation's
    /// oscillation otherwise.
    pub exponent_im: f64,
}

/// A bifurcation of the branch of one level (see `stickslip_core::hbm::bifurcation`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BifurcationRecord {
    /// Force level (N).
    pub level_n: f64,
    /// "fold", "branch point", "period doubling" or "Neimark-Sacker".
    pub kind: String,
    pub frequency_hz: f64,
    /// The harmonics at each output there, in the outputs' order: element k of each list is
    /// `(A_k, φ_k)`, amplitude (m) and phase (rad), k = 0..=N, as [`OutputRecord::harmonics`].
    pub harmonics: Vec<(String, Vec<(f64, f64)>)>,
    /// Imaginary part of the crossing Floquet exponent (rad/s): 0 at a fold or a branch point
    /// (a real exponent crosses zero there).
    pub exponent_im: f64,
    /// False when it could not be located between its two points (then it is the second).
    pub located: bool,
}

impl BifurcationRecord {
    /// |X₁| at each output there (m), in the outputs' order.
    pub fn amplitudes(&self) -> impl Iterator<Item = (&str, f64)> {
        self.harmonics.iter().map(|(name, h)| (name.as_str(), h.get(1).map_or(0.0, |h| h.0)))
    }
}

/// Response of one output at one point.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OutputRecord {
    pub name: String,
    /// |X₁| / F: amplitude of the first harmonic over the force level (m/N).
    pub disp_frf: f64,
    /// Ω² |X₁| / F (m s⁻² / N).
    pub accel_frf: f64,
    /// max |x(t)| over the period (m).
    pub peak: f64,
    /// `(A_k, φ_k)` for k = 0..=N with `x(t) = A_0 + Σ A_k cos(kΩt + φ_k)`: amplitude (m) and
    /// phase (rad); `A_0` is the mean (signed) and `φ_0 = 0`. See [`harmonics_from_coefficients`].
    pub harmonics: Vec<(f64, f64)>,
    /// Displacement over one period at `θ_j = 2π j / n_t` (m); empty when not kept.
    pub disp: Vec<f64>,
    /// Velocity over one period (m/s); empty when not kept.
    pub vel: Vec<f64>,
}

/// State of one element at one point.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ElementRecord {
    pub name: String,
    /// Energy dissipated per cycle ∮ g du (J).
    pub energy_j: f64,
    /// Fraction of the period spent stuck (0..1).
    pub stick_fraction: f64,
    /// Element displacement `u = Vᵀ U` over one period (m); empty when not kept.
    pub loop_u: Vec<f64>,
    /// Element force over one period (N), the hysteresis loop against `loop_u`.
    pub loop_force: Vec<f64>,
    /// Slider velocity v_P over one period (m/s, paper Eq. 33).
    pub slider_velocity: Vec<f64>,
}

/// The periodic response at one fixed frequency and force level (a `[[snapshot]]`), with its
/// time signals.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SnapshotResult {
    /// Force level (N).
    pub level_n: f64,
    pub point: PointRecord,
    pub sides: Vec<JointSides>,
}

/// The velocities over one period of the two sides of a joint placed between DOFs A and B
/// (paper Figs. 22-23: the blade top P and its envelope contact B).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct JointSides {
    pub joint: String,
    pub dof_a: String,
    pub dof_b: String,
    /// Velocity of A: B's plus the slider velocity (Eq. 33), m/s.
    pub velocity_a: Vec<f64>,
    /// Velocity of B (m/s).
    pub velocity_b: Vec<f64>,
}

impl PointRecord {
    /// Does this point carry time data?
    pub fn has_time_data(&self) -> bool {
        self.outputs.iter().any(|o| !o.disp.is_empty()) || self.elements.iter().any(|e| !e.loop_u.is_empty())
    }
}

/// `(amplitude, phase)` pairs, k = 0..=N, from Fourier coefficients `[c0, c1, s1, ..., cN, sN]`
/// (the convention of `stickslip_core::hbm::fourier`): `c_k cos kθ + s_k sin kθ = A_k cos(kθ + φ_k)`
/// with `A_k = √(c_k² + s_k²)` and `φ_k = atan2(−s_k, c_k)`.
pub fn harmonics_from_coefficients(coefficients: &[f64]) -> Vec<(f64, f64)> {
    assert!(coefficients.len() % 2 == 1, "expected 2N+1 coefficients, got {}", coefficients.len());
    let n = coefficients.len() / 2;
    std::iter::once((coefficients[0], 0.0))
        .chain((1..=n).map(|k| {
            let (c, s) = (coefficients[2 * k - 1], coefficients[2 * k]);
            (c.hypot(s), (-s).atan2(c))
        }))
        .collect()
}

/// Write everything a run produces into `dir` (created if needed): `frf.csv`, `frf.npz`,
/// `peaks.csv` (see [`write_peaks_csv`]), `bifurcations.csv` (see [`write_bifurcations_csv`]), the
/// time data of the points that carry it (`points/`), and per output an FRF plot
/// (`frf_<out>.<png|svg>`) and a phase plot (`frf_phase_<out>.<png|svg>`) and the plots of [`crate::plot::plot_level_details`], unless `plots`
/// is `None` (batch runs). Returns the paths of the FRF table, the NPZ file and the plots.
#[cfg(feature = "plot")]
pub fn write_results(
    dir: &std::path::Path,
    levels: &[LevelResult],
    plots: Option<PlotFormat>,
) -> Result<Vec<PathBuf>, OutputError> {
    std::fs::create_dir_all(dir).map_err(|source| OutputError::Io { path: dir.to_path_buf(), source })?;
    // The plots take longer than the tables: they are drawn meanwhile, on the other threads.
    let (tables, plotted) = rayon::join(
        || write_tables(dir, levels),
        || plots.map_or(Ok(Vec::new()), |format| crate::plot::plot_results(dir, levels, format)),
    );
    let mut files = tables?;
    files.extend(plotted?);
    Ok(files)
}

/// The tables of [`write_results`]; returns their files.
#[cfg(feature = "plot")]
fn write_tables(dir: &std::path::Path, levels: &[LevelResult]) -> Result<Vec<PathBuf>, OutputError> {
    let (csv, npz) = (dir.join("frf.csv"), dir.join("frf.npz"));
    write_frf_csv(&csv, levels)?;
    write_frf_npz(&npz, levels)?;
    let peaks = dir.join("peaks.csv");
    write_peaks_csv(&peaks, &crate::report::peaks(levels))?;
    let bifurcations = dir.join("bifurcations.csv");
    write_bifurcations_csv(&bifurcations, levels)?;
    let files = vec![csv, npz, peaks, bifurcations];
    write_time_data(dir, levels)?;
    Ok(files)
}

/// Write each snapshot's time signals, `snapshot<i>.csv` (i from 0, in the study's order), and
/// per joint with both sides known the plot of their velocities, `snapshot<i>_<joint>.<ext>`
/// (unless `plots` is `None`). Returns the files written.
#[cfg(feature = "plot")]
pub fn write_snapshots(
    dir: &Path,
    snapshots: &[SnapshotResult],
    plots: Option<PlotFormat>,
) -> Result<Vec<PathBuf>, OutputError> {
    let mut files = Vec::new();
    for (i, s) in snapshots.iter().enumerate() {
        let csv = dir.join(format!("snapshot{i}.csv"));
        write_snapshot_csv(&csv, s)?;
        files.push(csv);
        let Some(format) = plots else { continue };
        for sides in &s.sides {
            let path = dir.join(format!("snapshot{i}_{}.{}", sides.joint, format.extension()));
            crate::plot::plot_joint_sides(&path, s, sides)?;
            files.push(path);
        }
    }
    Ok(files)
}

/// What went wrong writing results.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// Points of one file must share outputs, elements and the number of harmonics.
    #[error("level {level_n} N, point at {frequency_hz} Hz: {message}")]
    Inconsistent { level_n: f64, frequency_hz: f64, message: String },
    /// The time series of one point must have the same number of samples.
    #[error("{}: {message}", path.display())]
    TimeData { path: PathBuf, message: String },
    /// A NaN or infinity among the results: written, it would read back as no number.
    #[error("{}: {quantity} is {value} at {location}: refusing to write a value that is not finite", path.display())]
    NotFinite { path: PathBuf, quantity: String, location: String, value: f64 },
    #[error("{0}")]
    Plot(String),
}
