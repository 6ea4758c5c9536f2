//! `backbone.csv`: the damped nonlinear mode of a study's `[nonlinear_mode]` section, one row
//! per point of the branch (see docs/nonlinear-modes.md for the columns).

use std::fmt::Write as _;
use std::path::Path;

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
            let _ = write!(text, "{v:.10e}");
        }
        text.push('\n');
    }
    std::fs::write(path, text).map_err(|source| OutputError::Io { path: path.to_path_buf(), source })
}
