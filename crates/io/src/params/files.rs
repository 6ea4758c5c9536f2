//! The tables of a parameter study on disk, for batch schedulers: each job runs one shard of
//! the samples and writes `shard-I-of-N.csv`; [`merge`] checks that the shards belong to one
//! study and one design, that none is missing, and writes `samples.csv`.
//!
//! A table's first line is a comment naming the study and its design
//! (`# study=<id> design=<id> shard=I/N samples=<total>`), then a header and one row per
//! sample and force level: `sample`, the varied keys, then [`SUMMARY_COLUMNS`]. A sample that
//! failed has one row with its error and empty summary cells. Numbers are written in the
//! shortest form that reads back to the same `f64`. Read it with pandas as
//! `pandas.read_csv(path, skiprows=1)`.

use std::fmt::Write as _;
use std::ops::Range;
use std::path::{Path, PathBuf};

use super::{fnv1a, ParamError, ParamStudy, SampleOutcome};

/// Summary columns after `sample` and the varied keys (units in the names, Hz for frequencies).
pub const SUMMARY_COLUMNS: [&str; 8] =
    ["level_N", "peak_frequency_Hz", "peak_amplitude_m", "peak_energy_J", "points", "complete", "ending", "error"];

/// Shard `index` (from 1) of `count`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl Shard {
    /// Parse `I/N` with 1 <= I <= N.
    pub fn parse(text: &str) -> Result<Shard, ParamError> {
        let bad = || ParamError::Design(format!("--shard {text}: expected I/N with 1 <= I <= N, e.g. 3/10"));
        let (i, n) = text.split_once('/').ok_or_else(bad)?;
        let (index, count) =
            (i.trim().parse::<usize>().map_err(|_| bad())?, n.trim().parse::<usize>().map_err(|_| bad())?);
        if index == 0 || index > count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }

    /// The samples of this shard among `total`: contiguous, sizes differing by at most one.
    pub fn range(&self, total: usize) -> Range<usize> {
        (self.index - 1) * total / self.count..self.index * total / self.count
    }

    /// `shard-I-of-N.csv`, zero-padded so that the files list in order.
    pub fn file_name(&self) -> String {
        let w = self.count.to_string().len();
        format!("shard-{:0w$}-of-{}.csv", self.index, self.count)
    }
}

/// An identifier of the design: the keys and every sample's values.
pub fn design_id(study: &ParamStudy) -> String {
    let mut text = study.keys.iter().map(|k| k.to_string()).collect::<Vec<_>>().join(",");
    for row in &study.samples {
        for v in row {
            write!(text, ",{:016x}", v.to_bits()).expect("String write");
        }
    }
    format!("{:016x}", fnv1a(text.as_bytes()))
}

/// The header line of the tables of `study`.
pub fn header(study: &ParamStudy) -> String {
    let mut cols = vec!["sample".to_string()];
    cols.extend(study.keys.iter().map(|k| k.to_string()));
    cols.extend(SUMMARY_COLUMNS.iter().map(|c| c.to_string()));
    cols.join(",")
}

/// The rows of one sample, each ending with a newline.
pub fn rows(outcome: &SampleOutcome) -> String {
    let mut out = String::new();
    let start = |out: &mut String| {
        write!(out, "{}", outcome.index).expect("String write");
        for v in &outcome.values {
            write!(out, ",{v:e}").expect("String write");
        }
    };
    // A level without points has no peak: its fields are left empty (as a failed sample's are),
    // with `points` 0 and the ending saying why, rather than written as NaN.
    let number = |v: f64| if v.is_finite() { format!("{v:e}") } else { String::new() };
    for r in &outcome.rows {
        start(&mut out);
        writeln!(
            out,
            ",{:e},{},{},{},{},{},{},",
            r.level_n,
            number(r.peak_frequency_hz),
            number(r.peak_amplitude_m),
            number(r.peak_energy_j),
            r.points,
            r.complete,
            quote(&r.ending)
        )
        .expect("String write");
    }
    if let Some(e) = &outcome.error {
        start(&mut out);
        writeln!(out, ",,,,,0,false,,{}", quote(e)).expect("String write");
    }
    out
}

/// A CSV field: quoted, inner quotes doubled, line breaks kept inside the quotes.
fn quote(s: &str) -> String {
    format!("\"{}\"", s.replace('"', "\"\""))
}

/// The comment line of a table.
fn comment(study: &ParamStudy, shard: Option<Shard>) -> String {
    let shard = shard.map(|s| format!(" shard={}/{}", s.index, s.count)).unwrap_or_default();
    format!("# study={} design={}{shard} samples={}", study.study_id(), design_id(study), study.samples.len())
}

/// Write the table of one shard (its outcomes in sample order) into `dir`.
pub fn write_shard(
    dir: &Path,
    study: &ParamStudy,
    shard: Shard,
    outcomes: &[SampleOutcome],
) -> Result<PathBuf, ParamError> {
    let mut text = comment(study, Some(shard));
    text.push('\n');
    text.push_str(&header(study));
    text.push('\n');
    for o in outcomes {
        text.push_str(&rows(o));
    }
    let path = dir.join(shard.file_name());
    write(&path, &text)?;
    Ok(path)
}

/// The full curves of a sample, as `frf.csv` of a run: `curves/sample-<index>.csv`.
pub fn write_curves(dir: &Path, outcome: &SampleOutcome) -> Result<Option<PathBuf>, ParamError> {
    let Some(levels) = &outcome.levels else { return Ok(None) };
    let folder = dir.join("curves");
    std::fs::create_dir_all(&folder)
        .map_err(|e| ParamError::File { path: folder.clone(), message: format!("cannot create: {e}") })?;
    let path = folder.join(format!("sample-{}.csv", outcome.index));
    crate::output::write_frf_csv(&path, levels)
        .map_err(|e| ParamError::File { path: path.clone(), message: e.to_string() })?;
    Ok(Some(path))
}

fn write(path: &Path, text: &str) -> Result<(), ParamError> {
    std::fs::write(path, text)
        .map_err(|e| ParamError::File { path: path.to_path_buf(), message: format!("cannot write: {e}") })
}

/// One shard file read back.
struct ShardFile {
    path: PathBuf,
    study: String,
    design: String,
    shard: Shard,
    samples: usize,
    header: String,
    /// `(sample, row)` with the row's newline.
    rows: Vec<(usize, String)>,
}

/// Merge the shard tables of `dir` into `dir/samples.csv`, in sample order. Refuses shards of
/// different studies or designs, and a missing shard (named). Returns the path and the number
/// of samples.
pub fn merge(dir: &Path) -> Result<(PathBuf, usize), ParamError> {
    let listing = std::fs::read_dir(dir)
        .map_err(|e| ParamError::File { path: dir.to_path_buf(), message: format!("cannot list: {e}") })?;
    let mut shards = Vec::new();
    for entry in listing.flatten() {
        let name = entry.file_name().to_string_lossy().to_string();
        if name.starts_with("shard-") && name.ends_with(".csv") {
            shards.push(read_shard(&entry.path())?);
        }
    }
    let Some(first) = shards.first() else {
        return Err(ParamError::File { path: dir.to_path_buf(), message: "no shard-*.csv table to merge".into() });
    };
    let (study, design, count, samples, header) =
        (first.study.clone(), first.design.clone(), first.shard.count, first.samples, first.header.clone());
    let mut present = vec![false; count];
    for s in &shards {
        if s.study != study || s.design != design || s.shard.count != count || s.header != header {
            return Err(ParamError::File {
                path: s.path.clone(),
                message: format!(
                    "belongs to another parameter study (study {}, design {}, {} shards) than {} (study {study}, design {design}, {count} shards): refusing to mix them",
                    s.study,
                    s.design,
                    s.shard.count,
                    first.path.display()
                ),
            });
        }
        present[s.shard.index - 1] = true;
    }
    let missing: Vec<String> =
        (1..=count).filter(|i| !present[i - 1]).map(|i| Shard { index: i, count }.file_name()).collect();
    if !missing.is_empty() {
        return Err(ParamError::File {
            path: dir.to_path_buf(),
            message: format!("{} of {count} shard(s) missing: {}", missing.len(), missing.join(", ")),
        });
    }
    let mut rows: Vec<(usize, String)> = shards.into_iter().flat_map(|s| s.rows).collect();
    // Stable: the rows of one sample (one per level) keep their order.
    rows.sort_by_key(|(i, _)| *i);
    let mut seen: Vec<usize> = rows.iter().map(|(i, _)| *i).collect();
    seen.dedup();
    if seen.len() != samples || seen.iter().enumerate().any(|(k, i)| k != *i) {
        return Err(ParamError::File {
            path: dir.to_path_buf(),
            message: format!("the shards hold {} distinct samples, expected 0..{samples}", seen.len()),
        });
    }
    let mut text = format!("# study={study} design={design} samples={samples}\n{header}\n");
    for (_, r) in rows {
        text.push_str(&r);
    }
    let path = dir.join("samples.csv");
    write(&path, &text)?;
    Ok((path, samples))
}

fn read_shard(path: &Path) -> Result<ShardFile, ParamError> {
    let bad = |message: String| ParamError::File { path: path.to_path_buf(), message };
    let text = std::fs::read_to_string(path).map_err(|e| bad(format!("cannot read: {e}")))?;
    let mut lines = text.split_inclusive('\n');
    let first = lines.next().unwrap_or("").trim_end();
    let field = |name: &str| {
        first
            .split_whitespace()
            .find_map(|w| w.strip_prefix(name).and_then(|w| w.strip_prefix('=')))
            .map(str::to_string)
            .ok_or_else(|| {
                bad(format!("the first line must be `# study=... design=... shard=I/N samples=...`, got {first:?}"))
            })
    };
    let (study, design) = (field("study")?, field("design")?);
    let shard = Shard::parse(&field("shard")?)?;
    let samples: usize = field("samples")?.parse().map_err(|_| bad("samples= is not an integer".into()))?;
    let header = lines.next().unwrap_or("").trim_end().to_string();
    let mut rows = Vec::new();
    let mut pending = String::new();
    for line in lines {
        pending.push_str(line);
        // A quoted field may hold a line break: a row ends where its quotes are balanced.
        if pending.matches('"').count() % 2 == 1 {
            continue;
        }
        let sample = pending
            .split(',')
            .next()
            .and_then(|s| s.parse::<usize>().ok())
            .ok_or_else(|| bad(format!("a row does not start with a sample number: {:?}", pending.trim_end())))?;
        if sample >= samples {
            return Err(bad(format!("sample {sample} is beyond the {samples} samples of the study")));
        }
        rows.push((sample, std::mem::take(&mut pending)));
    }
    if !pending.is_empty() {
        return Err(bad("the file ends inside a quoted field".into()));
    }
    Ok(ShardFile { path: path.to_path_buf(), study, design, shard, samples, header, rows })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::SummaryRow;

    #[test]
    fn a_level_without_a_peak_leaves_its_fields_empty_rather_than_nan() {
        let row = |f: f64| SummaryRow {
            level_n: 10.0,
            peak_frequency_hz: f,
            peak_amplitude_m: if f.is_nan() { f64::NAN } else { 1e-3 },
            peak_energy_j: if f.is_nan() { f64::NAN } else { 0.5 },
            points: if f.is_nan() { 0 } else { 40 },
            complete: !f.is_nan(),
            ending: "ended".into(),
        };
        let outcome = SampleOutcome {
            index: 3,
            values: vec![0.25],
            rows: vec![row(120.0), row(f64::NAN)],
            levels: None,
            error: None,
        };
        let text = rows(&outcome);
        assert!(!text.to_lowercase().contains("nan"), "{text}");
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], "3,2.5e-1,1e1,1.2e2,1e-3,5e-1,40,true,\"ended\",");
        assert_eq!(lines[1], "3,2.5e-1,1e1,,,,0,false,\"ended\",");
    }
}
