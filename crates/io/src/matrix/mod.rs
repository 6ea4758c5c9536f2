//! Matrix files in and out: Matrix Market ([`mtx`]), CalculiX `.sti`/`.mas`/`.dof`
//! ([`calculix`]), Abaqus `*MATRIX GENERATE` text output ([`abaqus`]), Nastran DMIG punch
//! ([`dmig`]) and NumPy `.npz` ([`npz`]).
//!
//! Every reader reports the file and the 1-based line of what it could not use.
use std::path::{Path, PathBuf};

use faer::sparse::{SparseColMat, Triplet};
use faer::MatRef;
use stickslip_core::model::{Damping, DofLabel, LinearModel, Matrix, ModelError};

pub mod abaqus;
pub mod calculix;
pub mod dmig;
pub mod mtx;
pub mod npz;

/// What went wrong reading or writing a matrix file.
#[derive(Debug, thiserror::Error)]
pub enum MatrixFileError {
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{}:{line}: {message}", path.display())]
    Parse { path: PathBuf, line: usize, message: String },
    #[error("{}: {message}", path.display())]
    Invalid { path: PathBuf, message: String },
}

/// Refuse to write `matrix` (named `name` in the message) to `path` if an entry is not finite,
/// naming the first such entry (1-based row and column, as Matrix Market counts): a file that
/// holds NaN or inf reads back as nothing any solver can use, and every reader here refuses it.
pub(crate) fn refuse_non_finite(path: &Path, name: &str, matrix: &Matrix) -> Result<(), MatrixFileError> {
    let first = match matrix {
        Matrix::Dense(m) => first_non_finite(m.as_ref()),
        Matrix::Sparse(m) => {
            let m = m.as_ref();
            (0..m.ncols())
                .flat_map(|j| {
                    m.symbolic().row_idx_of_col_raw(j).iter().zip(m.val_of_col(j)).map(move |(&i, &v)| (i, j, v))
                })
                .find(|e| !e.2.is_finite())
        }
    };
    refuse_entry(path, name, first)
}

/// [`refuse_non_finite`] for a dense matrix (a reduction basis, which is not copied to check it).
pub(crate) fn refuse_non_finite_dense(path: &Path, name: &str, m: MatRef<'_, f64>) -> Result<(), MatrixFileError> {
    refuse_entry(path, name, first_non_finite(m))
}

fn first_non_finite(m: MatRef<'_, f64>) -> Option<(usize, usize, f64)> {
    (0..m.ncols()).flat_map(|j| (0..m.nrows()).map(move |i| (i, j, m[(i, j)]))).find(|e| !e.2.is_finite())
}

fn refuse_entry(path: &Path, name: &str, entry: Option<(usize, usize, f64)>) -> Result<(), MatrixFileError> {
    match entry {
        Some((i, j, v)) => Err(MatrixFileError::invalid(
            path,
            format!(
                "{name} holds {v} at row {}, column {}: refusing to write a value that is not finite",
                i + 1,
                j + 1
            ),
        )),
        None => Ok(()),
    }
}

impl MatrixFileError {
    pub(crate) fn io(path: &Path, source: std::io::Error) -> Self {
        MatrixFileError::Io { path: path.to_path_buf(), source }
    }

    pub(crate) fn parse(path: &Path, line: usize, message: impl Into<String>) -> Self {
        MatrixFileError::Parse { path: path.to_path_buf(), line, message: message.into() }
    }

    pub(crate) fn invalid(path: &Path, message: impl Into<String>) -> Self {
        MatrixFileError::Invalid { path: path.to_path_buf(), message: message.into() }
    }
}

/// Largest matrix dimension a file may declare: 10 million DOFs, 30 times the largest model
/// of the benchmarks. A sparse matrix allocates a column pointer per column whatever its
/// entries, so a damaged size line would otherwise abort on a huge allocation.
pub(crate) const MAX_DIMENSION: usize = 10_000_000;

/// Read a whole text file, the error naming it.
pub(crate) fn read_text(path: &Path) -> Result<String, MatrixFileError> {
    std::fs::read_to_string(path).map_err(|e| MatrixFileError::io(path, e))
}

/// Parse one number of a text matrix file; Fortran `D` exponents (`1.5D+03`) are accepted.
pub(crate) fn parse_f64(path: &Path, line: usize, token: &str, what: &str) -> Result<f64, MatrixFileError> {
    let parsed = token.parse::<f64>().or_else(|_| token.replace(['D', 'd'], "e").parse::<f64>());
    match parsed {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(MatrixFileError::parse(path, line, format!("{what} {token:?} is not finite"))),
        Err(_) => Err(MatrixFileError::parse(path, line, format!("expected a number for {what}, got {token:?}"))),
    }
}

/// Parse a 1-based index no larger than `max`, returned 0-based.
pub(crate) fn parse_index(
    path: &Path,
    line: usize,
    token: &str,
    what: &str,
    max: usize,
) -> Result<usize, MatrixFileError> {
    let i: usize = token.parse().map_err(|_| {
        MatrixFileError::parse(path, line, format!("expected a positive integer for {what}, got {token:?}"))
    })?;
    if i == 0 || i > max {
        return Err(MatrixFileError::parse(path, line, format!("{what} {i} is out of range 1..={max}")));
    }
    Ok(i - 1)
}

/// Entries of a symmetric matrix given by one triangle (either one, not both: both would
/// double the off-diagonal terms), mirrored; duplicates are summed.
#[derive(Default)]
pub(crate) struct SymmetricTriplets {
    triplets: Vec<Triplet<usize, usize, f64>>,
    lower: bool,
    upper: bool,
}

impl SymmetricTriplets {
    pub(crate) fn push(&mut self, path: &Path, line: usize, i: usize, j: usize, v: f64) -> Result<(), MatrixFileError> {
        self.triplets.push(Triplet::new(i, j, v));
        if i != j {
            self.lower |= i > j;
            self.upper |= i < j;
            if self.lower && self.upper {
                return Err(MatrixFileError::parse(
                    path,
                    line,
                    "entries on both sides of the diagonal: a symmetric matrix file must list one triangle",
                ));
            }
            self.triplets.push(Triplet::new(j, i, v));
        }
        Ok(())
    }

    pub(crate) fn build(self, path: &Path, n: usize) -> Result<SparseColMat<usize, f64>, MatrixFileError> {
        let m = SparseColMat::try_new_from_triplets(n, n, &self.triplets)
            .map_err(|e| MatrixFileError::invalid(path, format!("cannot build the sparse matrix: {e:?}")))?;
        finite_sums(path, m)
    }
}

/// Duplicate entries are summed: finite values can sum to infinity (1e308 + 1e308).
pub(crate) fn finite_sums(
    path: &Path,
    m: SparseColMat<usize, f64>,
) -> Result<SparseColMat<usize, f64>, MatrixFileError> {
    let a = m.as_ref();
    for j in 0..a.ncols() {
        if let Some(p) = a.val_of_col(j).iter().position(|v| !v.is_finite()) {
            let i = a.symbolic().row_idx_of_col_raw(j)[p];
            return Err(MatrixFileError::invalid(
                path,
                format!(
                    "the entries at row {}, column {} sum to {}, which is not finite",
                    i + 1,
                    j + 1,
                    a.val_of_col(j)[p]
                ),
            ));
        }
    }
    Ok(m)
}

/// Parse a Nastran/Fortran real: `1.5`, `1.5E+3`, `1.5D+3`, and Nastran's implicit exponent
/// `1.5+3` / `-2.-4`.
pub(crate) fn parse_real(path: &Path, line: usize, token: &str, what: &str) -> Result<f64, MatrixFileError> {
    let t = token.trim();
    let mut s = t.replace(['D', 'd'], "E");
    if !s.contains(['E', 'e']) {
        // A sign after the first character starts the exponent (char indices: the token may
        // start with a multi-byte character, or be empty).
        if let Some((p, _)) = s.char_indices().skip(1).find(|(_, c)| matches!(c, '+' | '-')) {
            s.insert(p, 'E');
        }
    }
    parse_f64(path, line, &s, what)
        .map_err(|_| MatrixFileError::parse(path, line, format!("expected a number for {what}, got {t:?}")))
}

/// A sparse symmetric matrix over named DOFs (imports that carry their own DOF list).
#[derive(Clone, Debug)]
pub struct LabelledMatrix {
    pub dofs: Vec<DofLabel>,
    pub matrix: SparseColMat<usize, f64>,
}

impl LabelledMatrix {
    pub(crate) fn nodal(keys: Vec<(u64, u8)>, matrix: SparseColMat<usize, f64>) -> Self {
        LabelledMatrix { dofs: keys.into_iter().map(|(n, d)| DofLabel::nodal(n, d)).collect(), matrix }
    }
}

/// An undamped model from a stiffness and a mass over possibly different DOF lists (a DOF
/// with no mass entry, say): the model's DOFs are the union, in the stiffness's order then
/// the mass's extra DOFs.
///
/// Each matrix must be square over its DOF list, and the model passes the checks of
/// [`LinearModel::new`] (a rectangular mass once came out of the eigensolver as f = 0 with a
/// NaN residual).
pub fn model_from_pair(stiffness: LabelledMatrix, mass: LabelledMatrix) -> Result<LinearModel, ModelError> {
    for (what, m) in [("K (stiffness)", &stiffness), ("M (mass)", &mass)] {
        let (rows, cols, n) = (m.matrix.nrows(), m.matrix.ncols(), m.dofs.len());
        if rows != n || cols != n {
            return Err(ModelError::WrongSize { what: what.into(), rows, cols, expected: n });
        }
    }
    let mut dofs = stiffness.dofs.clone();
    let mut index: std::collections::HashMap<String, usize> =
        dofs.iter().enumerate().map(|(i, d)| (d.name.clone(), i)).collect();
    for d in &mass.dofs {
        if !index.contains_key(&d.name) {
            index.insert(d.name.clone(), dofs.len());
            dofs.push(d.clone());
        }
    }
    let n = dofs.len();
    let remap = |m: &LabelledMatrix| {
        let map: Vec<usize> = m.dofs.iter().map(|d| index[&d.name]).collect();
        let a = m.matrix.as_ref();
        let mut t = Vec::new();
        for j in 0..a.ncols() {
            for (&i, &v) in a.symbolic().row_idx_of_col_raw(j).iter().zip(a.val_of_col(j)) {
                t.push(Triplet::new(map[i], map[j], v));
            }
        }
        SparseColMat::try_new_from_triplets(n, n, &t).expect("indices are in range")
    };
    LinearModel::new(Matrix::Sparse(remap(&mass)), Matrix::Sparse(remap(&stiffness)), Damping::None, dofs, vec![])
}
