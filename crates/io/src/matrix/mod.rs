//! Matrix files in and out: Matrix Market ([`mtx`]), CalculiX `.sti`/`.mas`/`.dof`
//! ([`calculix`]), Abaqus `*MATRIX GENERATE` text output ([`abaqus`]), Nastran DMIG punch
//! ([`dmig`]) and NumPy `.npz` ([`npz`]).
//!
//! Every reader reports the file and the 1-based line of what it could not use.
use std::path::{Path, PathBuf};

pub mod mtx;

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
