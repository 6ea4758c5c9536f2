//! Matrix Market files (NIST format, <https://math.nist.gov/MatrixMarket/formats.html>):
//! `coordinate` (sparse) and `array` (dense) storage of real matrices, `general` or
//! `symmetric` (only one triangle stored).
use std::io::Write;
use std::path::Path;

use faer::sparse::{SparseColMat, Triplet};
use faer::Mat;
use stickslip_core::model::Matrix;

use super::{finite_sums, parse_f64, parse_index, read_text, MatrixFileError, MAX_DIMENSION};

#[derive(Clone, Copy, PartialEq)]
enum Storage {
    Coordinate,
    Array,
}

/// Read a Matrix Market file: `coordinate` files give a sparse matrix, `array` files a dense
/// one. Field `real`, `double` or `integer`; symmetry `general` or `symmetric` (the stored
/// triangle is mirrored). Duplicate coordinate entries are summed, as the format allows.
pub fn read(path: &Path) -> Result<Matrix, MatrixFileError> {
    let text = read_text(path)?;
    let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l));
    let (_, header) = lines.next().ok_or_else(|| MatrixFileError::parse(path, 1, "empty file"))?;
    let (storage, symmetric) = parse_header(path, header)?;
    let mut data = lines.filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('%'));
    let (size_line, size) =
        data.next().ok_or_else(|| MatrixFileError::parse(path, 2, "missing the size line (rows columns [entries])"))?;
    let dims: Vec<&str> = size.split_whitespace().collect();
    let expected_len = if storage == Storage::Coordinate { 3 } else { 2 };
    if dims.len() != expected_len {
        let what = if storage == Storage::Coordinate { "rows columns entries" } else { "rows columns" };
        return Err(MatrixFileError::parse(path, size_line, format!("expected the size line `{what}`, got {size:?}")));
    }
    let count = |t: &str, what: &str| {
        t.parse::<usize>()
            .map_err(|_| MatrixFileError::parse(path, size_line, format!("expected an integer {what}, got {t:?}")))
    };
    let nrows = count(dims[0], "number of rows")?;
    let ncols = count(dims[1], "number of columns")?;
    if nrows.max(ncols) > MAX_DIMENSION {
        return Err(MatrixFileError::parse(
            path,
            size_line,
            format!(
                "a {nrows}x{ncols} matrix is larger than stickslip reads (at most {MAX_DIMENSION} rows and columns)"
            ),
        ));
    }
    // Every entry (coordinate) or value (array) takes two bytes at least, a digit and a
    // separator: counts the file cannot hold are refused before anything is reserved.
    let room = text.len() / 2;
    if symmetric && nrows != ncols {
        return Err(MatrixFileError::parse(
            path,
            size_line,
            format!("a symmetric matrix must be square, got {nrows}x{ncols}"),
        ));
    }
    match storage {
        Storage::Coordinate => {
            let nnz = count(dims[2], "number of entries")?;
            if nnz > room {
                return Err(MatrixFileError::parse(
                    path,
                    size_line,
                    format!(
                        "the size line announces {nnz} entries, more than the file ({} bytes) can hold",
                        text.len()
                    ),
                ));
            }
            read_coordinate(path, &mut data, nrows, ncols, nnz, symmetric, size_line)
        }
        Storage::Array => {
            let values = if symmetric { nrows.checked_mul(nrows + 1).map(|v| v / 2) } else { nrows.checked_mul(ncols) };
            if values.is_none_or(|v| v > room) {
                return Err(MatrixFileError::parse(
                    path,
                    size_line,
                    format!("a {nrows}x{ncols} array needs more values than the file ({} bytes) can hold", text.len()),
                ));
            }
            read_array(path, &mut data, nrows, ncols, symmetric, size_line)
        }
    }
}

fn parse_header(path: &Path, header: &str) -> Result<(Storage, bool), MatrixFileError> {
    let words: Vec<String> = header.split_whitespace().map(|w| w.to_ascii_lowercase()).collect();
    if words.len() != 5 || words[0] != "%%matrixmarket" || words[1] != "matrix" {
        return Err(MatrixFileError::parse(
            path,
            1,
            format!(
                "expected the header `%%MatrixMarket matrix coordinate|array real general|symmetric`, got {header:?}"
            ),
        ));
    }
    let storage = match words[2].as_str() {
        "coordinate" => Storage::Coordinate,
        "array" => Storage::Array,
        other => {
            return Err(MatrixFileError::parse(
                path,
                1,
                format!("storage {other:?} not supported (coordinate or array)"),
            ))
        }
    };
    if !matches!(words[3].as_str(), "real" | "double" | "integer") {
        return Err(MatrixFileError::parse(
            path,
            1,
            format!("field {:?} not supported: stickslip reads real matrices (real, double or integer)", words[3]),
        ));
    }
    let symmetric = match words[4].as_str() {
        "general" => false,
        "symmetric" => true,
        other => {
            return Err(MatrixFileError::parse(
                path,
                1,
                format!("symmetry {other:?} not supported (general or symmetric)"),
            ))
        }
    };
    Ok((storage, symmetric))
}

fn read_coordinate<'a>(
    path: &Path,
    data: &mut impl Iterator<Item = (usize, &'a str)>,
    nrows: usize,
    ncols: usize,
    nnz: usize,
    symmetric: bool,
    size_line: usize,
) -> Result<Matrix, MatrixFileError> {
    let mut triplets = Vec::with_capacity(if symmetric { 2 * nnz } else { nnz });
    // A symmetric file stores one triangle; both at once would double the off-diagonal terms.
    let (mut lower, mut upper) = (false, false);
    let mut last_line = size_line;
    for k in 0..nnz {
        let (line, text) = data.next().ok_or_else(|| {
            MatrixFileError::parse(path, last_line, format!("the size line announces {nnz} entries, found only {k}"))
        })?;
        last_line = line;
        let t: Vec<&str> = text.split_whitespace().collect();
        if t.len() != 3 {
            return Err(MatrixFileError::parse(path, line, format!("expected `row column value`, got {text:?}")));
        }
        let i = parse_index(path, line, t[0], "row", nrows)?;
        let j = parse_index(path, line, t[1], "column", ncols)?;
        let v = parse_f64(path, line, t[2], "value")?;
        triplets.push(Triplet::new(i, j, v));
        if symmetric && i != j {
            lower |= i > j;
            upper |= i < j;
            if lower && upper {
                return Err(MatrixFileError::parse(
                    path,
                    line,
                    "a symmetric file must store one triangle only, found entries above and below the diagonal",
                ));
            }
            triplets.push(Triplet::new(j, i, v));
        }
    }
    if let Some((line, text)) = data.next() {
        return Err(MatrixFileError::parse(path, line, format!("more entries than the {nnz} announced: {text:?}")));
    }
    let m = SparseColMat::try_new_from_triplets(nrows, ncols, &triplets)
        .map_err(|e| MatrixFileError::invalid(path, format!("cannot build the sparse matrix: {e:?}")))?;
    Ok(Matrix::Sparse(finite_sums(path, m)?))
}

fn read_array<'a>(
    path: &Path,
    data: &mut impl Iterator<Item = (usize, &'a str)>,
    nrows: usize,
    ncols: usize,
    symmetric: bool,
    size_line: usize,
) -> Result<Matrix, MatrixFileError> {
    // Column-major order; a symmetric matrix lists the lower triangle column by column.
    let positions: Vec<(usize, usize)> = if symmetric {
        (0..ncols).flat_map(|j| (j..nrows).map(move |i| (i, j))).collect()
    } else {
        (0..ncols).flat_map(|j| (0..nrows).map(move |i| (i, j))).collect()
    };
    let mut m = Mat::<f64>::zeros(nrows, ncols);
    let mut values = data.flat_map(|(line, text)| text.split_whitespace().map(move |t| (line, t)));
    let mut last_line = size_line;
    for (k, &(i, j)) in positions.iter().enumerate() {
        let (line, token) = values.next().ok_or_else(|| {
            MatrixFileError::parse(
                path,
                last_line,
                format!("a {nrows}x{ncols} array needs {} values, found only {k}", positions.len()),
            )
        })?;
        last_line = line;
        let v = parse_f64(path, line, token, "value")?;
        m[(i, j)] = v;
        if symmetric {
            m[(j, i)] = v;
        }
    }
    if let Some((line, token)) = values.next() {
        return Err(MatrixFileError::parse(
            path,
            line,
            format!("more values than a {nrows}x{ncols} array holds: {token:?}"),
        ));
    }
    Ok(Matrix::Dense(m))
}

/// Write a matrix as Matrix Market: sparse as `coordinate`, dense as `array`; `symmetric`
/// (lower triangle only) when the matrix is exactly symmetric, else `general`. Values are
/// written with the shortest decimal form that reads back to the same `f64`.
pub fn write(path: &Path, matrix: &Matrix) -> Result<(), MatrixFileError> {
    super::refuse_non_finite(path, "the matrix", matrix)?;
    let file = std::fs::File::create(path).map_err(|e| MatrixFileError::io(path, e))?;
    let mut w = std::io::BufWriter::new(file);
    write_to(&mut w, matrix).and_then(|_| w.flush()).map_err(|e| MatrixFileError::io(path, e))
}

fn write_to(w: &mut impl Write, matrix: &Matrix) -> std::io::Result<()> {
    match matrix {
        Matrix::Sparse(m) => {
            let symmetric = is_exactly_symmetric(m);
            let keep = |i: usize, j: usize| !symmetric || i >= j;
            let m = m.as_ref();
            let mut nnz = 0;
            for j in 0..m.ncols() {
                nnz += m.symbolic().row_idx_of_col_raw(j).iter().filter(|&&i| keep(i, j)).count();
            }
            let kind = if symmetric { "symmetric" } else { "general" };
            writeln!(w, "%%MatrixMarket matrix coordinate real {kind}")?;
            writeln!(w, "{} {} {}", m.nrows(), m.ncols(), nnz)?;
            for j in 0..m.ncols() {
                for (&i, &v) in m.symbolic().row_idx_of_col_raw(j).iter().zip(m.val_of_col(j)) {
                    if keep(i, j) {
                        writeln!(w, "{} {} {:e}", i + 1, j + 1, v)?;
                    }
                }
            }
        }
        Matrix::Dense(m) => {
            let symmetric =
                m.nrows() == m.ncols() && (0..m.ncols()).all(|j| (j + 1..m.nrows()).all(|i| m[(i, j)] == m[(j, i)]));
            let kind = if symmetric { "symmetric" } else { "general" };
            writeln!(w, "%%MatrixMarket matrix array real {kind}")?;
            writeln!(w, "{} {}", m.nrows(), m.ncols())?;
            for j in 0..m.ncols() {
                let first = if symmetric { j } else { 0 };
                for i in first..m.nrows() {
                    writeln!(w, "{:e}", m[(i, j)])?;
                }
            }
        }
    }
    Ok(())
}

/// Same pattern and values as the transpose, bit for bit (explicit zeros count as entries).
fn is_exactly_symmetric(m: &SparseColMat<usize, f64>) -> bool {
    if m.nrows() != m.ncols() {
        return false;
    }
    let Ok(t) = m.as_ref().transpose().to_col_major() else {
        return false;
    };
    let (a, b) = (m.as_ref(), t.as_ref());
    (0..a.ncols()).all(|j| {
        a.symbolic().row_idx_of_col_raw(j) == b.symbolic().row_idx_of_col_raw(j) && a.val_of_col(j) == b.val_of_col(j)
    })
}
