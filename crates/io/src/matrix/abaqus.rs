//! Abaqus `*MATRIX GENERATE` / `*MATRIX OUTPUT, FORMAT=MATRIX INPUT` text output
//! (`job_STIF1.mtx`, `job_MASS1.mtx`): one entry per line as
//! `row node, row DOF, column node, column DOF, value`, one triangle of the symmetric matrix.
//! Lines starting with `*` (keywords, `**` comments) are skipped.
use std::path::Path;

use super::{parse_real, read_text, LabelledMatrix, MatrixFileError, SymmetricTriplets};

/// Read one Abaqus matrix file. DOFs are ordered by node, then direction.
pub fn read(path: &Path) -> Result<LabelledMatrix, MatrixFileError> {
    let text = read_text(path)?;
    let mut entries = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.is_empty() || t.starts_with('*') {
            continue;
        }
        let f: Vec<&str> = t.split(',').map(str::trim).filter(|s| !s.is_empty()).collect();
        if f.len() != 5 {
            return Err(MatrixFileError::parse(
                path,
                i + 1,
                format!("expected `node, dof, node, dof, value`, got {} field(s): {t:?}", f.len()),
            ));
        }
        let node = |s: &str, what: &str| {
            s.parse::<u64>().map_err(|_| {
                MatrixFileError::parse(path, i + 1, format!("expected a node number for {what}, got {s:?}"))
            })
        };
        let dof = |s: &str, what: &str| match s.parse::<u8>() {
            Ok(d) if (1..=6).contains(&d) => Ok(d),
            _ => Err(MatrixFileError::parse(path, i + 1, format!("expected a DOF 1..=6 for {what}, got {s:?}"))),
        };
        let a = (node(f[0], "the row node")?, dof(f[1], "the row DOF")?);
        let b = (node(f[2], "the column node")?, dof(f[3], "the column DOF")?);
        let v = parse_real(path, i + 1, f[4], "the value")?;
        entries.push((i + 1, a, b, v));
    }
    if entries.is_empty() {
        return Err(MatrixFileError::invalid(path, "no matrix entry found"));
    }
    let mut keys: Vec<(u64, u8)> = entries.iter().flat_map(|e| [e.1, e.2]).collect();
    keys.sort_unstable();
    keys.dedup();
    let index = |k: &(u64, u8)| keys.binary_search(k).expect("every key is listed");
    let mut t = SymmetricTriplets::default();
    for (line, a, b, v) in &entries {
        t.push(path, *line, index(a), index(b), *v)?;
    }
    let matrix = t.build(path, keys.len())?;
    Ok(LabelledMatrix::nodal(keys, matrix))
}
