//! `backbone.csv`: the damped nonlinear mode of a study's `[nonlinear_mode]` section, one row
//! per point of the branch (see docs/nonlinear-modes.md for the columns).

use std::fmt::Write as _;
use std::path::Path;

use stickslip_core::continuation::SingularKind;
use stickslip_core::hbm::Backbone;

use crate::output::OutputError;

/// Column names of `backbone.csv` (units in every name), for `joints` and `outputs` named as
/// in the study and `harmonics` harmonics.
pub fn backbone_columns(joints: &[String], outputs: &[String], harmonics: usize) -> Vec<String> {
    let mut cols: Vec<String> =
        ["modal_amplitude_m_sqrtkg", "frequency_Hz", "damping_ratio", "energy_per_cycle_J"].map(String::from).to_vec();
    for j in joints {
        cols.extend([format!("{j}_stick_fraction"), format!("{j}_energy_J")]);
    }
    for o in outputs {
        cols.push(format!("{o}_h0_mean_m"));
        cols.extend((1..=harmonics).map(|k| format!("{o}_h{k}_amp_m")));
    }
    cols
}

/// The numbers of every row, in the order of [`backbone_columns`].
pub fn backbone_rows(backbone: &Backbone, n_joints: usize, harmonics: usize) -> Vec<Vec<f64>> {
    backbone
        .points
        .iter()
        .map(|p| {
            let mut row = vec![p.amplitude, p.frequency_hz(), p.damping_ratio(), p.energy_per_cycle];
            for j in 0..n_joints {
                // A model without joints has none to report (the linear mode).
                row.extend([
                    p.stick_fraction.get(j).copied().unwrap_or(1.0),
                    p.joint_energy.get(j).copied().unwrap_or(0.0),
                ]);
            }
            for (o, c) in p.outputs.iter().enumerate() {
                row.push(c[0]);
                row.extend((1..=harmonics).map(|k| p.output_amplitude(o, k)));
            }
            row
        })
        .collect()
}

/// Write `backbone.csv` at `path`; a value that is not finite is refused, naming its column.
pub fn write_backbone_csv(
    path: &Path,
    backbone: &Backbone,
    joints: &[String],
    outputs: &[String],
    harmonics: usize,
) -> Result<(), OutputError> {
    let columns = backbone_columns(joints, outputs, harmonics);
    let mut text = columns.join(",");
    text.push('\n');
    // Shortest round-trip digits, as frf.csv: the file reads back to the same doubles.
    let mut digits = ryu::Buffer::new();
    for (i, row) in backbone_rows(backbone, joints.len(), harmonics).iter().enumerate() {
        for (c, v) in row.iter().enumerate() {
            if !v.is_finite() {
                return Err(OutputError::NotFinite {
                    path: path.to_path_buf(),
                    quantity: format!("column `{}`", columns[c]),
                    location: format!("backbone point {}", i + 1),
                    value: *v,
                });
            }
            if c > 0 {
                text.push(',');
            }
            crate::output::csv::push_number(&mut text, *v, &mut digits);
        }
        text.push('\n');
    }
    std::fs::write(path, text).map_err(|source| OutputError::Io { path: path.to_path_buf(), source })
}

/// Write `backbone_bifurcations.csv` at `path`: one row per fold in amplitude or branch point
/// of the backbone (`kind`, `modal_amplitude_m_sqrtkg`, `frequency_Hz`, `damping_ratio`,
/// `located`), the header alone when there is none.
pub fn write_backbone_singular_csv(path: &Path, backbone: &Backbone) -> Result<(), OutputError> {
    let mut text = String::from("kind,modal_amplitude_m_sqrtkg,frequency_Hz,damping_ratio,located\n");
    let mut digits = ryu::Buffer::new();
    for s in &backbone.singular_points {
        let values = [s.amplitude, s.omega / (2.0 * std::f64::consts::PI), s.damping_ratio()];
        if let Some(v) = values.iter().find(|v| !v.is_finite()) {
            return Err(OutputError::NotFinite {
                path: path.to_path_buf(),
                quantity: "a backbone fold or branch point".into(),
                location: format!("after backbone point {}", s.after_point + 1),
                value: *v,
            });
        }
        text.push_str(singular_kind_name(s.kind));
        for v in values {
            text.push(',');
            crate::output::csv::push_number(&mut text, v, &mut digits);
        }
        let _ = writeln!(text, ",{}", s.located);
    }
    std::fs::write(path, text).map_err(|source| OutputError::Io { path: path.to_path_buf(), source })
}

/// The name of a backbone's singular point in files and messages.
pub fn singular_kind_name(kind: SingularKind) -> &'static str {
    match kind {
        SingularKind::Fold => "fold in amplitude",
        SingularKind::BranchPoint => "branch point",
    }
}

/// The forced response of one level synthesised from a backbone.
#[derive(Clone, Debug, PartialEq)]
pub struct SingleModeFrf {
    /// Force level (N).
    pub level_n: f64,
    /// `(frequency (Hz), |X₁|/F (m/N) at each output)` along the curve.
    pub points: Vec<(f64, Vec<f64>)>,
}

/// The forced response of each level synthesised from the backbone alone (single nonlinear
/// mode theory, [`Backbone::single_mode_response`]).
pub fn single_mode_frfs(backbone: &Backbone, load: &[f64], levels_n: &[f64]) -> Vec<SingleModeFrf> {
    let two_pi = 2.0 * std::f64::consts::PI;
    levels_n
        .iter()
        .map(|&level| {
            let curve = backbone
                .single_mode_response(load, level)
                .iter()
                .map(|s| {
                    let p = &backbone.points[s.point];
                    let frfs = (0..p.outputs.len()).map(|o| p.output_amplitude(o, 1) / level).collect();
                    (s.omega / two_pi, frfs)
                })
                .collect();
            SingleModeFrf { level_n: level, points: curve }
        })
        .collect()
}

/// Write `single_mode_frf.csv`: `level_N,frequency_Hz` and `<output>_disp_frf_m_per_N` per
/// output, the forced responses of [`single_mode_frfs`], one row per point of each curve.
pub fn write_single_mode_csv(path: &Path, frfs: &[SingleModeFrf], outputs: &[String]) -> Result<(), OutputError> {
    let mut text = String::from("level_N,frequency_Hz");
    for o in outputs {
        let _ = write!(text, ",{o}_disp_frf_m_per_N");
    }
    text.push('\n');
    for SingleModeFrf { level_n: level, points } in frfs {
        for (f, values) in points {
            for v in std::iter::once(f).chain(values) {
                if !v.is_finite() {
                    return Err(OutputError::NotFinite {
                        path: path.to_path_buf(),
                        quantity: "the synthesised response".into(),
                        location: format!("{level} N near {f} Hz"),
                        value: *v,
                    });
                }
            }
            let _ = write!(text, "{level:e},{f:.10e}");
            for v in values {
                let _ = write!(text, ",{v:.10e}");
            }
            text.push('\n');
        }
    }
    std::fs::write(path, text).map_err(|source| OutputError::Io { path: path.to_path_buf(), source })
}
