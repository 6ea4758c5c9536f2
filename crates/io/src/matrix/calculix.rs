//! CalculiX 2.20 matrix export (`*FREQUENCY, SOLVER=MATRIXSTORAGE`): `job.sti` (stiffness)
//! and `job.mas` (mass) list the upper triangle as `row column value`, 1-based, in the order
//! of `job.dof`, whose line `i` names DOF `i` as `node.direction`; constrained DOFs are absent.
use std::path::{Path, PathBuf};

use faer::sparse::SparseColMat;
use stickslip_core::model::{Damping, DofLabel, LinearModel, Matrix};

use super::{parse_f64, parse_index, read_text, MatrixFileError, SymmetricTriplets};

/// `job.sti`, `job.mas`, `job.dof` for a prefix given as `job` or as any of the three files.
pub fn job_files(prefix: &Path) -> (PathBuf, PathBuf, PathBuf) {
    let base = match prefix.extension().and_then(|e| e.to_str()) {
        Some("sti" | "mas" | "dof" | "inp") => prefix.with_extension(""),
        _ => prefix.to_path_buf(),
    };
    let with = |ext: &str| {
        let mut p = base.clone().into_os_string();
        p.push(".");
        p.push(ext);
        PathBuf::from(p)
    };
    (with("sti"), with("mas"), with("dof"))
}

/// Read the three files of a CalculiX job into an undamped model with nodal DOF labels.
pub fn read_job(prefix: &Path) -> Result<LinearModel, MatrixFileError> {
    let (sti, mas, dof) = job_files(prefix);
    let dofs = read_dof(&dof)?;
    let n = dofs.len();
    let k = read_triangle(&sti, n, &dof)?;
    let m = read_triangle(&mas, n, &dof)?;
    // Built directly: both matrices are symmetric by construction (one triangle mirrored).
    Ok(LinearModel {
        mass: Matrix::Sparse(m),
        stiffness: Matrix::Sparse(k),
        damping: Damping::None,
        dofs,
        loads: vec![],
    })
}

/// A `.dof` file: one `node.direction` per line.
pub fn read_dof(path: &Path) -> Result<Vec<DofLabel>, MatrixFileError> {
    let text = read_text(path)?;
    let mut dofs = Vec::new();
    let mut seen = std::collections::HashSet::new();
    for (i, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.is_empty() {
            continue;
        }
        let bad = || MatrixFileError::parse(path, i + 1, format!("expected `node.direction` (e.g. 12.3), got {t:?}"));
        let (node, dir) = t.split_once('.').ok_or_else(bad)?;
        let node: u64 = node.parse().map_err(|_| bad())?;
        let dir: u8 = dir.parse().map_err(|_| bad())?;
        if !(1..=6).contains(&dir) {
            return Err(MatrixFileError::parse(path, i + 1, format!("direction {dir} of node {node} is not in 1..=6")));
        }
        if !seen.insert((node, dir)) {
            return Err(MatrixFileError::parse(path, i + 1, format!("DOF {node}.{dir} is listed twice")));
        }
        dofs.push(DofLabel::nodal(node, dir));
    }
    if dofs.is_empty() {
        return Err(MatrixFileError::invalid(path, "no DOF listed"));
    }
    Ok(dofs)
}

/// One triangle of a symmetric `n × n` matrix as `row column value` lines (1-based).
fn read_triangle(path: &Path, n: usize, dof: &Path) -> Result<SparseColMat<usize, f64>, MatrixFileError> {
    let text = read_text(path)?;
    let mut t = SymmetricTriplets::default();
    for (i, line) in text.lines().enumerate() {
        let tokens: Vec<&str> = line.split_whitespace().collect();
        if tokens.is_empty() {
            continue;
        }
        if tokens.len() != 3 {
            return Err(MatrixFileError::parse(path, i + 1, format!("expected `row column value`, got {line:?}")));
        }
        let index = |token: &str, what: &str| {
            parse_index(path, i + 1, token, what, n).map_err(|e| match e {
                MatrixFileError::Parse { path, line, message } => MatrixFileError::Parse {
                    path,
                    line,
                    message: format!("{message}: {} lists {n} DOFs (is a DOF missing from it?)", dof.display()),
                },
                other => other,
            })
        };
        let r = index(tokens[0], "row")?;
        let c = index(tokens[1], "column")?;
        let v = parse_f64(path, i + 1, tokens[2], "value")?;
        t.push(path, i + 1, r, c, v)?;
    }
    t.build(path, n)
}
