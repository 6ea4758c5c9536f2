//! Nastran DMIG bulk entries as written to the punch file (`.pch`) by `EXTSEOUT(DMIGPCH)` or
//! `PARAM,EXTOUT`: small field (8-character fields), large field (`DMIG*`, 16-character
//! fields, `*` continuations) and free field (commas).
//!
//! A header entry `DMIG NAME 0 IFO TIN TOUT POLAR _ NCOL` opens matrix NAME (IFO 6 symmetric,
//! 1 square; TIN 1 or 2 real), then one entry per column `DMIG NAME GJ CJ _ G1 C1 A1 _ G2 C2
//! A2 _ ...`: the terms `A_i` at rows `(G_i, C_i)` of column `(GJ, CJ)` (grid, component).
//! A symmetric matrix lists one triangle.
use std::collections::BTreeMap;
use std::path::Path;

use stickslip_core::model::LinearModel;

use super::{model_from_pair, parse_real, read_text, LabelledMatrix, MatrixFileError, SymmetricTriplets};

/// One DMIG matrix.
#[derive(Clone, Debug)]
pub struct DmigMatrix {
    pub name: String,
    /// IFO 6 (symmetric, one triangle stored and mirrored) rather than 1 (square).
    pub symmetric: bool,
    /// DOFs (`grid.component`) ordered by grid then component.
    pub matrix: LabelledMatrix,
}

/// A field and the line it came from.
type Field = (usize, String);

struct Card {
    fields: Vec<Field>,
}

/// Split a card image into its data fields (the first, name/continuation field dropped).
fn fields(line: &str, number: usize) -> Vec<Field> {
    if line.contains(',') {
        return line.split(',').skip(1).map(|f| (number, f.trim().to_string())).collect();
    }
    let chars: Vec<char> = line.chars().collect();
    let slice = |a: usize, b: usize| -> String {
        chars.get(a.min(chars.len())..b.min(chars.len())).map(|s| s.iter().collect::<String>()).unwrap_or_default()
    };
    let large = slice(0, 8).trim().ends_with('*');
    let (width, count) = if large { (16, 4) } else { (8, 8) };
    (0..count).map(|k| (number, slice(8 + k * width, 8 + (k + 1) * width).trim().to_string())).collect()
}

fn cards(text: &str) -> Vec<Card> {
    let mut out: Vec<Card> = Vec::new();
    let mut open = false;
    for (i, line) in text.lines().enumerate() {
        let number = i + 1;
        let head = line.split(',').next().unwrap_or("");
        let head = head.get(..head.len().min(8)).unwrap_or(head).trim().to_ascii_uppercase();
        if line.trim().is_empty() || line.starts_with('$') {
            continue;
        }
        if head == "DMIG" || head == "DMIG*" {
            out.push(Card { fields: fields(line, number) });
            open = true;
        } else if open && (head.is_empty() || head.starts_with('+') || head.starts_with('*')) {
            let card = out.last_mut().expect("a card is open");
            card.fields.extend(fields(line, number));
        } else {
            open = false;
        }
    }
    out
}

/// A DOF as (grid, component).
type Dof = (u64, u8);

/// A term: source line, row DOF, column DOF, value.
type Term = (usize, Dof, Dof, f64);

struct Pending {
    symmetric: bool,
    entries: Vec<Term>,
}

/// Read every DMIG matrix of a punch or bulk data file.
pub fn read(path: &Path) -> Result<Vec<DmigMatrix>, MatrixFileError> {
    let text = read_text(path)?;
    let mut matrices: BTreeMap<String, Pending> = BTreeMap::new();
    let mut order = Vec::new();
    for card in cards(&text) {
        let f = &card.fields;
        let get = |k: usize| f.get(k).map(|x| x.1.as_str()).unwrap_or("");
        let line_of = |k: usize| f.get(k).or(f.last()).map(|x| x.0).unwrap_or(0);
        let int = |k: usize, what: &str| -> Result<u64, MatrixFileError> {
            get(k).parse::<u64>().map_err(|_| {
                MatrixFileError::parse(path, line_of(k), format!("expected an integer {what}, got {:?}", get(k)))
            })
        };
        // Components are 0 (scalar point) to 6; a larger one would wrap onto another DOF as u8.
        let component = |k: usize, what: &str| -> Result<u8, MatrixFileError> {
            match int(k, what)? {
                c @ 0..=6 => Ok(c as u8),
                c => Err(MatrixFileError::parse(path, line_of(k), format!("{what} {c} is not a component 0..=6"))),
            }
        };
        let name = get(0).to_string();
        if name.is_empty() {
            return Err(MatrixFileError::parse(path, line_of(0), "DMIG entry without a matrix name"));
        }
        let gj = int(1, "column grid (GJ, 0 for the header)")?;
        if gj == 0 {
            let ifo = int(2, "form IFO")?;
            let tin = int(3, "type TIN")?;
            let symmetric = match ifo {
                6 => true,
                1 => false,
                other => {
                    return Err(MatrixFileError::parse(
                        path,
                        line_of(2),
                        format!("matrix {name}: form IFO = {other} not supported (6 symmetric or 1 square)"),
                    ))
                }
            };
            if tin != 1 && tin != 2 {
                return Err(MatrixFileError::parse(
                    path,
                    line_of(3),
                    format!("matrix {name}: type TIN = {tin} not supported (1 or 2: real)"),
                ));
            }
            if matrices.insert(name.clone(), Pending { symmetric, entries: vec![] }).is_some() {
                return Err(MatrixFileError::parse(path, line_of(0), format!("matrix {name} is defined twice")));
            }
            order.push(name);
            continue;
        }
        let pending = matrices.get_mut(&name).ok_or_else(|| {
            MatrixFileError::parse(
                path,
                line_of(0),
                format!("column of matrix {name} before its header entry (GJ = 0)"),
            )
        })?;
        let cj = component(2, "column component (CJ)")?;
        // Terms in groups of four fields (G, C, A, B), the first group after field 4.
        let mut k = 4;
        while k < f.len() {
            if get(k).is_empty() && get(k + 1).is_empty() && get(k + 2).is_empty() {
                k += 4;
                continue;
            }
            let g = int(k, "row grid (G)")?;
            let c = component(k + 1, "row component (C)")?;
            if get(k + 2).is_empty() {
                return Err(MatrixFileError::parse(
                    path,
                    line_of(k + 1),
                    format!("matrix {name}: term at row {g}.{c} has no value"),
                ));
            }
            let a = parse_real(path, line_of(k + 2), get(k + 2), "the term value (A)")?;
            pending.entries.push((line_of(k + 2), (g, c), (gj, cj), a));
            k += 4;
        }
    }
    let mut out = Vec::new();
    for name in order {
        let p = matrices.remove(&name).expect("listed");
        let mut keys: Vec<Dof> = p.entries.iter().flat_map(|e| [e.1, e.2]).collect();
        keys.sort_unstable();
        keys.dedup();
        let index = |k: &Dof| keys.binary_search(k).expect("every key is listed");
        let n = keys.len();
        let matrix = if p.symmetric {
            let mut t = SymmetricTriplets::default();
            for (line, r, c, v) in &p.entries {
                t.push(path, *line, index(r), index(c), *v)?;
            }
            t.build(path, n)?
        } else {
            let t: Vec<_> =
                p.entries.iter().map(|(_, r, c, v)| faer::sparse::Triplet::new(index(r), index(c), *v)).collect();
            let m = faer::sparse::SparseColMat::try_new_from_triplets(n, n, &t)
                .map_err(|e| MatrixFileError::invalid(path, format!("matrix {name}: {e:?}")))?;
            super::finite_sums(path, m)?
        };
        out.push(DmigMatrix { name, symmetric: p.symmetric, matrix: LabelledMatrix::nodal(keys, matrix) });
    }
    Ok(out)
}

/// An undamped model from the DMIG stiffness and mass matrices named `stiffness` and `mass`
/// (e.g. `KAAX` and `MAAX`).
pub fn read_model(path: &Path, stiffness: &str, mass: &str) -> Result<LinearModel, MatrixFileError> {
    let mut all = read(path)?;
    let known = all.iter().map(|m| m.name.clone()).collect::<Vec<_>>().join(", ");
    let mut take = |name: &str| {
        all.iter()
            .position(|m| m.name.eq_ignore_ascii_case(name))
            .map(|p| all.remove(p).matrix)
            .ok_or_else(|| MatrixFileError::invalid(path, format!("no DMIG matrix named {name} (found: {known})")))
    };
    let k = take(stiffness)?;
    let m = take(mass)?;
    model_from_pair(k, m).map_err(|e| MatrixFileError::invalid(path, format!("{stiffness} and {mass}: {e}")))
}
