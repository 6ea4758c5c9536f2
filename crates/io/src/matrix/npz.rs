//! Reduced (or any) models to NumPy `.npz`: `numpy.load("model.npz")` gives `M`, `K` (and `D`
//! for a damping matrix) as dense 2-D float64 arrays, optionally the basis `T`, and the DOF
//! map as `dof_node` / `dof_direction` (int64, -1 for DOFs without a node, e.g. modal
//! coordinates) and `retained_index` (0-based index in the full model of each retained DOF).
//! The DOF names go to a CSV next to it (see [`write_dof_csv`]).
use std::io::Write;
use std::path::Path;

use faer::Mat;
use stickslip_core::model::{Damping, LinearModel};

use super::MatrixFileError;
use crate::output::NpzFile;

/// What goes in the archive besides M, K, D.
pub struct NpzExtras<'a> {
    /// The reduction basis `T` (full DOFs × reduced DOFs).
    pub basis: Option<&'a Mat<f64>>,
    /// Full-model indices of the retained DOFs.
    pub retained: &'a [usize],
}

/// Write `M`, `K`, `D` (if a damping matrix), the DOF map and the extras.
pub fn write(path: &Path, model: &LinearModel, extras: &NpzExtras<'_>) -> Result<(), MatrixFileError> {
    let io = |e: std::io::Error| MatrixFileError::io(path, e);
    // Checked before the file is created, so that nothing is left half written.
    super::refuse_non_finite(path, "M", &model.mass)?;
    super::refuse_non_finite(path, "K", &model.stiffness)?;
    if let Damping::Matrix(d) = &model.damping {
        super::refuse_non_finite(path, "D", d)?;
    }
    if let Some(t) = extras.basis {
        super::refuse_non_finite_dense(path, "T", t.as_ref())?;
    }
    let mut npz = NpzFile::create(path).map_err(io)?;
    let mut dense = |name: &str, m: &Mat<f64>| {
        let shape = [m.nrows() as u64, m.ncols() as u64];
        // C order: row by row.
        npz.add(name, &shape, (0..m.nrows()).flat_map(|i| (0..m.ncols()).map(move |j| m[(i, j)])))
    };
    dense("M", &model.mass.to_dense()).map_err(io)?;
    dense("K", &model.stiffness.to_dense()).map_err(io)?;
    if let Damping::Matrix(d) = &model.damping {
        dense("D", &d.to_dense()).map_err(io)?;
    }
    if let Some(t) = extras.basis {
        dense("T", t).map_err(io)?;
    }
    let nodes: Vec<i64> = model.dofs.iter().map(|d| d.node.map(|n| n as i64).unwrap_or(-1)).collect();
    let dirs: Vec<i64> = model.dofs.iter().map(|d| d.direction.map(|n| n as i64).unwrap_or(-1)).collect();
    let retained: Vec<i64> = extras.retained.iter().map(|&i| i as i64).collect();
    for (name, ints) in [("dof_node", nodes), ("dof_direction", dirs), ("retained_index", retained)] {
        npz.add(name, &[ints.len() as u64], ints).map_err(io)?;
    }
    npz.finish().map_err(io)
}

/// The DOF map as CSV: `index,name,node,direction,full_index` (node and direction empty for
/// modal coordinates; `full_index` is the retained DOF's index in the full model).
pub fn write_dof_csv(path: &Path, model: &LinearModel, retained: &[usize]) -> Result<(), MatrixFileError> {
    let io = |e: std::io::Error| MatrixFileError::io(path, e);
    let mut w = std::io::BufWriter::new(std::fs::File::create(path).map_err(io)?);
    writeln!(w, "index,name,node,direction,full_index").map_err(io)?;
    for (i, d) in model.dofs.iter().enumerate() {
        let opt = |v: Option<String>| v.unwrap_or_default();
        writeln!(
            w,
            "{i},{},{},{},{}",
            d.name,
            opt(d.node.map(|n| n.to_string())),
            opt(d.direction.map(|n| n.to_string())),
            opt(retained.get(i).map(|n| n.to_string()))
        )
        .map_err(io)?;
    }
    w.flush().map_err(io)
}
