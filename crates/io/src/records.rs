//! Time records, measured FRFs and period frames as CSV, and their exchange with UFF 58.
//!
//! Column names carry the unit (SI, frequencies in Hz):
//! - time records: `time_s,<name>_<unit>,...`, e.g. `time_s,force_N,top_m_s2`; sampling must be
//!   uniform (the time column is checked);
//! - measured FRFs: `[level_N,]frequency_Hz,<name>_amp_<unit>[,<name>_phase_rad],...`, e.g.
//!   `level_N,frequency_Hz,top_amp_m_s2_per_N,top_phase_rad`; rows of several force levels may
//!   share one file, told apart by `level_N`. When several curves share a name (the
//!   displacement, velocity and acceleration FRFs of one output), each phase column carries its
//!   curve's unit, `<name>_<unit>_phase_rad` (e.g. `tip_m_per_N_phase_rad`), so that no two
//!   columns are named alike;
//! - period frames: `frame_<j>.csv` with `point,phase_rad,<quantity>_<unit>`.
//!
//! Lines starting with `#` are comments. The tables are purely numeric with a one-line header, so
//! a split on commas is the whole parser; errors name the file, line and column.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use num_complex::Complex64;

use crate::uff::{function_type, Abscissa, Dataset58, Ordinate};

/// Units recognised at the end of column names, longest first.
const UNITS: [&str; 14] =
    ["m_s2_per_N", "m_s_per_N", "m_per_N", "m_s2", "m_s", "rad", "N", "m", "V", "Pa", "g", "Hz", "s", "1"];

/// Errors reading or writing records.
#[derive(Debug, thiserror::Error)]
pub enum RecordsError {
    #[error("{path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    #[error("{file}:{line}: {what}")]
    Parse { file: String, line: usize, what: String },
    #[error("{file}: {what}")]
    Header { file: String, what: String },
    #[error("{file}:{line}: time {time_s} s breaks the uniform sampling (expected {expected_s} s, interval {dt_s} s): resample the record at a constant rate")]
    NonUniform { file: String, line: usize, time_s: f64, expected_s: f64, dt_s: f64 },
    #[error("{file}: channel `{channel}` {what}: all channels of a record set must share one clock (same sample rate and length)")]
    Mismatch { file: String, channel: String, what: String },
    #[error("no channel `{channel}` in {file}: available channels are {available:?}")]
    MissingChannel { file: String, channel: String, available: Vec<String> },
    #[error("{file}: {quantity} is {value} at {location}: refusing to write a value that is not finite")]
    NotFinite { file: String, quantity: String, location: String, value: f64 },
    #[error("{0}")]
    Invalid(String),
}

/// Refuse to write a non-finite `value` of `quantity` at `location` (a NaN in a result file
/// reads back as a number the next tool cannot use, or not at all).
fn finite(file: &Path, quantity: &str, location: impl FnOnce() -> String, value: f64) -> Result<(), RecordsError> {
    if value.is_finite() {
        return Ok(());
    }
    Err(RecordsError::NotFinite {
        file: file.display().to_string(),
        quantity: quantity.to_string(),
        location: location(),
        value,
    })
}

/// Refuse a column (time, frequency) whose values do not strictly increase, naming the line.
fn check_increasing(table: &Table, column: usize, rows: &[usize]) -> Result<(), RecordsError> {
    let values = &table.data[column];
    for w in rows.windows(2) {
        let (a, b) = (values[w[0]], values[w[1]]);
        if b <= a {
            return Err(RecordsError::Parse {
                file: table.file.clone(),
                line: table.lines[w[1]],
                what: format!(
                    "column {} (`{}`): {b} does not increase on {a} (line {}); the rows must be in increasing order",
                    column + 1,
                    table.columns[column],
                    table.lines[w[0]]
                ),
            });
        }
    }
    Ok(())
}

/// One sampled channel.
#[derive(Debug, Clone, PartialEq)]
pub struct Channel {
    pub name: String,
    /// Unit as written in column names (`m_s2`, `N`, ...); empty if none was recognised.
    pub unit: String,
    pub values: Vec<f64>,
}

impl Channel {
    /// Column name `<name>_<unit>`.
    pub fn column(&self) -> String {
        if self.unit.is_empty() {
            self.name.clone()
        } else {
            format!("{}_{}", self.name, self.unit)
        }
    }
}

/// Channels sampled together at a uniform rate.
#[derive(Debug, Clone, PartialEq)]
pub struct TimeRecords {
    /// Where they came from (for messages).
    pub source: String,
    pub start_s: f64,
    pub sample_rate_hz: f64,
    pub channels: Vec<Channel>,
}

impl TimeRecords {
    /// The channel called `name` (with or without its unit suffix).
    pub fn channel(&self, name: &str) -> Result<&Channel, RecordsError> {
        self.channels.iter().find(|c| c.name == name || c.column() == name).ok_or_else(|| {
            RecordsError::MissingChannel {
                file: self.source.clone(),
                channel: name.to_string(),
                available: self.channels.iter().map(Channel::column).collect(),
            }
        })
    }

    /// Number of samples per channel.
    pub fn len(&self) -> usize {
        self.channels.first().map_or(0, |c| c.values.len())
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Split a column name into (name, unit) at a recognised unit suffix.
pub fn split_unit(column: &str) -> (String, String) {
    for unit in UNITS {
        if let Some(name) = column.strip_suffix(unit).and_then(|n| n.strip_suffix('_')) {
            if !name.is_empty() {
                return (name.to_string(), unit.to_string());
            }
        }
    }
    (column.to_string(), String::new())
}

/// A numeric CSV table: header names and columns.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    pub file: String,
    pub columns: Vec<String>,
    /// `data[c][r]`: column-major.
    pub data: Vec<Vec<f64>>,
    /// 1-based file line of each row.
    pub lines: Vec<usize>,
}

impl Table {
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.columns.iter().position(|c| c == name).map(|i| self.data[i].as_slice())
    }
}

fn io_err(path: &Path) -> impl FnOnce(std::io::Error) -> RecordsError + '_ {
    move |source| RecordsError::Io { path: path.to_path_buf(), source }
}

/// Read a numeric CSV with a header row.
pub fn read_table(path: &Path) -> Result<Table, RecordsError> {
    let text = std::fs::read_to_string(path).map_err(io_err(path))?;
    parse_table(&text, &path.display().to_string())
}

/// Parse the text of a numeric CSV named `file`.
pub fn parse_table(text: &str, file: &str) -> Result<Table, RecordsError> {
    let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let (_, header) =
        lines.next().ok_or_else(|| RecordsError::Header { file: file.into(), what: "the file is empty".into() })?;
    let columns: Vec<String> = header.split(',').map(|c| c.trim().to_string()).collect();
    let mut data = vec![Vec::new(); columns.len()];
    let mut rows = Vec::new();
    for (i, line) in lines {
        let fields: Vec<&str> = line.split(',').collect();
        if fields.len() != columns.len() {
            return Err(RecordsError::Parse {
                file: file.into(),
                line: i + 1,
                what: format!("{} fields, the header has {} columns", fields.len(), columns.len()),
            });
        }
        for (c, f) in fields.iter().enumerate() {
            let v: f64 = f.trim().parse().map_err(|_| RecordsError::Parse {
                file: file.into(),
                line: i + 1,
                what: format!("column {} (`{}`): `{}` is not a number", c + 1, columns[c], f.trim()),
            })?;
            // `nan`, `inf` and overflowing literals parse as f64 but are no sample.
            if !v.is_finite() {
                return Err(RecordsError::Parse {
                    file: file.into(),
                    line: i + 1,
                    what: format!("column {} (`{}`): `{}` is not a finite number", c + 1, columns[c], f.trim()),
                });
            }
            data[c].push(v);
        }
        rows.push(i + 1);
    }
    Ok(Table { file: file.into(), columns, data, lines: rows })
}

/// Write a numeric CSV: a header row of `columns`, then one line per row.
pub fn write_table(path: &Path, columns: &[String], rows: &[Vec<f64>]) -> Result<(), RecordsError> {
    let mut s = columns.join(",");
    s.push('\n');
    for row in rows {
        if row.len() != columns.len() {
            return Err(RecordsError::Header {
                file: path.display().to_string(),
                what: format!("a row of {} values for {} columns", row.len(), columns.len()),
            });
        }
        for (c, &v) in row.iter().enumerate() {
            finite(path, &format!("column `{}`", columns[c]), || format!("data row {}", s.lines().count()), v)?;
        }
        let cells: Vec<String> = row.iter().map(|v| num(*v)).collect();
        s.push_str(&cells.join(","));
        s.push('\n');
    }
    std::fs::write(path, s).map_err(io_err(path))
}

/// Sample rate of a time column, checking that it is uniform: every time within 1 % of an
/// interval of `t0 + j dt` (CSV files print times with finite digits).
fn uniform_rate(time: &[f64], lines: &[usize], file: &str) -> Result<f64, RecordsError> {
    if time.len() < 2 {
        return Err(RecordsError::Header { file: file.into(), what: "a time record needs at least 2 samples".into() });
    }
    let dt = (time[time.len() - 1] - time[0]) / (time.len() - 1) as f64;
    if !(dt > 0.0 && dt.is_finite() && (1.0 / dt).is_finite()) {
        return Err(RecordsError::Header { file: file.into(), what: "time must increase".into() });
    }
    for (j, (&t, &line)) in time.iter().zip(lines).enumerate() {
        let expected = time[0] + j as f64 * dt;
        if (t - expected).abs() > 0.01 * dt {
            return Err(RecordsError::NonUniform {
                file: file.into(),
                line,
                time_s: t,
                expected_s: expected,
                dt_s: dt,
            });
        }
    }
    Ok(1.0 / dt)
}

/// Read time records from a CSV whose first column is `time_s`.
pub fn read_time_csv(path: &Path) -> Result<TimeRecords, RecordsError> {
    let table = read_table(path)?;
    time_records_from_table(table)
}

fn time_records_from_table(table: Table) -> Result<TimeRecords, RecordsError> {
    if table.columns.first().map(String::as_str) != Some("time_s") {
        return Err(RecordsError::Header {
            file: table.file.clone(),
            what: format!(
                "the first column must be `time_s` (time in seconds), found `{}`",
                table.columns.first().cloned().unwrap_or_default()
            ),
        });
    }
    check_increasing(&table, 0, &(0..table.lines.len()).collect::<Vec<_>>())?;
    let rate = uniform_rate(&table.data[0], &table.lines, &table.file)?;
    let start_s = table.data[0][0];
    let channels = table
        .columns
        .iter()
        .zip(table.data)
        .skip(1)
        .map(|(column, values)| {
            let (name, unit) = split_unit(column);
            Channel { name, unit, values }
        })
        .collect();
    Ok(TimeRecords { source: table.file, start_s, sample_rate_hz: rate, channels })
}

/// Shortest text that reads back to the same f64.
fn num(x: f64) -> String {
    format!("{x:e}")
}

/// Write time records as CSV (`time_s` then one column per channel).
pub fn write_time_csv(path: &Path, records: &TimeRecords) -> Result<(), RecordsError> {
    finite(path, "the start time", || "the time column".into(), records.start_s)?;
    let rate = records.sample_rate_hz;
    if !(rate.is_finite() && rate > 0.0) {
        return Err(RecordsError::Invalid(format!(
            "{}: the sample rate is {rate} Hz, expected a finite rate > 0: refusing to write the time column",
            path.display()
        )));
    }
    for c in &records.channels {
        for (j, &v) in c.values.iter().enumerate() {
            finite(path, &format!("channel `{}`", c.column()), || format!("sample {}", j + 1), v)?;
        }
    }
    let mut s = String::from("time_s");
    for c in &records.channels {
        s.push(',');
        s.push_str(&c.column());
    }
    s.push('\n');
    for j in 0..records.len() {
        s.push_str(&num(records.start_s + j as f64 / records.sample_rate_hz));
        for c in &records.channels {
            s.push(',');
            s.push_str(&num(c.values[j]));
        }
        s.push('\n');
    }
    std::fs::write(path, s).map_err(io_err(path))
}

/// Time records from the time-response datasets (function type 1) of a UFF file; other function
/// types are ignored. All must share one sampling.
pub fn time_records_from_uff(datasets: &[Dataset58], file: &str) -> Result<TimeRecords, RecordsError> {
    let mut channels = Vec::new();
    let mut clock: Option<(f64, f64, usize, String)> = None;
    for d in datasets.iter().filter(|d| d.function_type == function_type::TIME_RESPONSE) {
        let name = if d.ids[0].trim().is_empty() || d.ids[0].trim() == "NONE" {
            format!("channel{}", channels.len() + 1)
        } else {
            d.ids[0].trim().replace([' ', ',', ':'], "_")
        };
        let (start, dt) = match &d.abscissa {
            Abscissa::Even { min, increment } => {
                // The rate 1/dt must be finite too (a subnormal increment gives an infinite one).
                if !(increment.is_finite() && *increment > 0.0 && (1.0 / increment).is_finite()) {
                    return Err(RecordsError::Mismatch {
                        file: file.into(),
                        channel: name,
                        what: format!(
                            "has a time increment of {increment} s: time must increase at a finite sample rate"
                        ),
                    });
                }
                (*min, *increment)
            }
            Abscissa::Uneven(x) => {
                let lines: Vec<usize> = (1..=x.len()).collect();
                let rate = uniform_rate(x, &lines, &format!("{file} (dataset `{name}`, point numbers as lines)"))?;
                (x[0], 1.0 / rate)
            }
        };
        let values = match &d.ordinate {
            Ordinate::Real(v) => v.clone(),
            Ordinate::Complex(_) => {
                return Err(RecordsError::Mismatch {
                    file: file.into(),
                    channel: name,
                    what: "is complex, a time record must be real".into(),
                });
            }
        };
        match &clock {
            None => clock = Some((start, dt, values.len(), name.clone())),
            Some((_, dt0, len0, first)) => {
                if (dt - dt0).abs() > 1e-9 * dt0.abs() {
                    return Err(RecordsError::Mismatch {
                        file: file.into(),
                        channel: name,
                        what: format!("is sampled every {dt} s, `{first}` every {dt0} s"),
                    });
                }
                if values.len() != *len0 {
                    return Err(RecordsError::Mismatch {
                        file: file.into(),
                        channel: name,
                        what: format!("has {} samples, `{first}` has {len0}", values.len()),
                    });
                }
            }
        }
        let unit = unit_from_label(&d.ordinate_axis.units);
        channels.push(Channel { name, unit, values });
    }
    let Some((start_s, dt, _, _)) = clock else {
        return Err(RecordsError::Header {
            file: file.into(),
            what: "no time-response dataset 58 (function type 1) in the file".into(),
        });
    };
    Ok(TimeRecords { source: file.into(), start_s, sample_rate_hz: 1.0 / dt, channels })
}

/// Our unit spellings and their UFF labels.
const UNIT_LABELS: [(&str, &str); 10] = [
    ("m_s2", "m/s^2"),
    ("m_s", "m/s"),
    ("m", "m"),
    ("N", "N"),
    ("m_s2_per_N", "(m/s^2)/N"),
    ("m_s_per_N", "(m/s)/N"),
    ("m_per_N", "m/N"),
    ("Pa", "Pa"),
    ("V", "V"),
    ("g", "g"),
];

/// Our unit spelling of a UFF units label (`m/s^2` → `m_s2`); unknown labels keep their letters
/// and digits, other characters become `_`.
fn unit_from_label(label: &str) -> String {
    let l = label.trim().replace(' ', "");
    if l.is_empty() || l == "NONE" {
        return String::new();
    }
    if let Some((unit, _)) = UNIT_LABELS.iter().find(|(_, lab)| *lab == l) {
        return unit.to_string();
    }
    match l.as_str() {
        "m/s2" | "m/s²" => "m_s2".into(),
        other => other.chars().map(|c| if c.is_ascii_alphanumeric() { c } else { '_' }).collect(),
    }
}

/// Our unit spelling in UFF label form (`m_s2` → `m/s^2`).
pub fn unit_label(unit: &str) -> String {
    if unit.is_empty() {
        return "NONE".into();
    }
    UNIT_LABELS.iter().find(|(u, _)| *u == unit).map_or_else(|| unit.to_string(), |(_, lab)| lab.to_string())
}

/// Add white Gaussian noise of standard deviation `rms` to `values`, drawn from a generator
/// seeded with `seed`: the sensor noise of a virtual test, the same from run to run.
pub fn add_white_noise(values: &mut [f64], rms: f64, seed: u64) -> Result<(), RecordsError> {
    use rand::SeedableRng;
    use rand_distr::Distribution;
    if !(rms.is_finite() && rms >= 0.0) {
        return Err(RecordsError::Invalid(format!("a noise level is a finite standard deviation >= 0, got {rms}")));
    }
    let normal = rand_distr::Normal::new(0.0, rms).map_err(|e| RecordsError::Invalid(e.to_string()))?;
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    for v in values {
        *v += normal.sample(&mut rng);
    }
    Ok(())
}

/// UFF datasets of time records (one time-response dataset per channel).
pub fn time_records_to_uff(records: &TimeRecords) -> Vec<Dataset58> {
    records
        .channels
        .iter()
        .map(|c| {
            let mut d =
                Dataset58::time_record(&c.name, &unit_label(&c.unit), 1.0 / records.sample_rate_hz, c.values.clone());
            d.abscissa = Abscissa::Even { min: records.start_s, increment: 1.0 / records.sample_rate_hz };
            d
        })
        .collect()
}

/// One measured FRF curve.
#[derive(Debug, Clone, PartialEq)]
pub struct FrfCurve {
    pub name: String,
    /// Unit of the FRF, e.g. `m_s2_per_N`.
    pub unit: String,
    pub values: Vec<Complex64>,
    /// False when the file gave amplitudes only (values are then real, phase 0).
    pub has_phase: bool,
}

/// FRF curves on one frequency grid, at one force level if known.
#[derive(Debug, Clone, PartialEq)]
pub struct FrfSet {
    pub source: String,
    pub level_n: Option<f64>,
    pub frequency_hz: Vec<f64>,
    pub curves: Vec<FrfCurve>,
}

/// Read measured FRFs from a CSV file: one [`FrfSet`] per force level (in order of appearance).
pub fn read_frf_csv(path: &Path) -> Result<Vec<FrfSet>, RecordsError> {
    let table = read_table(path)?;
    let file = table.file.clone();
    let freq = table.column("frequency_Hz").ok_or_else(|| RecordsError::Header {
        file: file.clone(),
        what: format!("no `frequency_Hz` column (found {:?})", table.columns),
    })?;
    let level = table.column("level_N");
    let amplitude_columns: Vec<(usize, &str, &str)> =
        table.columns.iter().enumerate().filter_map(|(i, c)| c.split_once("_amp_").map(|(n, u)| (i, n, u))).collect();
    let mut curves: Vec<(String, String, usize, Option<usize>)> = Vec::new();
    for &(i, name, unit) in &amplitude_columns {
        let position = |column: &str| table.columns.iter().position(|p| p == column);
        // The phase of this very curve, or the name's only phase when the name is not shared.
        let shared = amplitude_columns.iter().filter(|(_, n, _)| *n == name).count() > 1;
        let phase = match position(&format!("{name}_{unit}_phase_rad")) {
            Some(p) => Some(p),
            None if shared && position(&format!("{name}_phase_rad")).is_some() => {
                return Err(RecordsError::Header {
                    file,
                    what: format!(
                        "`{name}_phase_rad` is ambiguous: several amplitude columns are named `{name}_amp_<unit>`; name each phase `{name}_<unit>_phase_rad` (e.g. `{name}_{unit}_phase_rad`)"
                    ),
                });
            }
            None => position(&format!("{name}_phase_rad")),
        };
        curves.push((name.to_string(), unit.to_string(), i, phase));
    }
    if curves.is_empty() {
        return Err(RecordsError::Header {
            file,
            what: "no FRF amplitude column `<name>_amp_<unit>` (e.g. `top_amp_m_s2_per_N`)".into(),
        });
    }
    // Group rows by level, keeping the order of first appearance.
    let mut order: Vec<Option<f64>> = Vec::new();
    let mut rows: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for r in 0..freq.len() {
        let l = level.map(|l| l[r]);
        let g = match order.iter().position(|o| *o == l) {
            Some(g) => g,
            None => {
                order.push(l);
                order.len() - 1
            }
        };
        rows.entry(g).or_default().push(r);
    }
    let freq_column = table.columns.iter().position(|c| c == "frequency_Hz").expect("found above");
    for rs in rows.values() {
        check_increasing(&table, freq_column, rs)?;
    }
    Ok(rows
        .into_iter()
        .map(|(g, rs)| FrfSet {
            source: file.clone(),
            level_n: order[g],
            frequency_hz: rs.iter().map(|&r| freq[r]).collect(),
            curves: curves
                .iter()
                .map(|(name, unit, a, p)| FrfCurve {
                    name: name.clone(),
                    unit: unit.clone(),
                    values: rs
                        .iter()
                        .map(|&r| Complex64::from_polar(table.data[*a][r], p.map_or(0.0, |p| table.data[p][r])))
                        .collect(),
                    has_phase: p.is_some(),
                })
                .collect(),
        })
        .collect())
}

/// Write FRF sets as CSV (`level_N` column when any set has a level).
pub fn write_frf_csv(path: &Path, sets: &[FrfSet]) -> Result<(), RecordsError> {
    let with_level = sets.iter().any(|s| s.level_n.is_some());
    let first = sets
        .first()
        .ok_or_else(|| RecordsError::Header { file: path.display().to_string(), what: "no FRF to write".into() })?;
    let mut s = String::new();
    if with_level {
        s.push_str("level_N,");
    }
    s.push_str("frequency_Hz");
    for (i, c) in first.curves.iter().enumerate() {
        let shared = first.curves.iter().filter(|o| o.name == c.name).count() > 1;
        if first.curves[..i].iter().any(|o| o.name == c.name && o.unit == c.unit) {
            return Err(RecordsError::Header {
                file: path.display().to_string(),
                what: format!("two FRF curves named `{}` in {}: their columns would be named alike", c.name, c.unit),
            });
        }
        // A shared name: each phase column says which curve it belongs to (see the module).
        if shared {
            let _ = write!(s, ",{0}_amp_{1},{0}_{1}_phase_rad", c.name, c.unit);
        } else {
            let _ = write!(s, ",{0}_amp_{1},{0}_phase_rad", c.name, c.unit);
        }
    }
    s.push('\n');
    for set in sets {
        let names: Vec<&str> = set.curves.iter().map(|c| c.name.as_str()).collect();
        let first_names: Vec<&str> = first.curves.iter().map(|c| c.name.as_str()).collect();
        if names != first_names || set.curves.iter().any(|c| c.values.len() != set.frequency_hz.len()) {
            return Err(RecordsError::Mismatch {
                file: path.display().to_string(),
                channel: names.join(","),
                what: "differs in curves or length from the first FRF set".into(),
            });
        }
        let level = set.level_n.map_or_else(String::new, |l| format!("level {l} N, "));
        if let Some(l) = set.level_n {
            finite(path, "the force level", || format!("FRF set {}", set.source), l)?;
        }
        for (r, f) in set.frequency_hz.iter().enumerate() {
            finite(path, "the frequency", || format!("{level}row {}", r + 1), *f)?;
            for c in &set.curves {
                let v = c.values[r];
                let at = || format!("{level}{f} Hz");
                finite(path, &format!("the real part of FRF `{}`", c.name), at, v.re)?;
                finite(path, &format!("the imaginary part of FRF `{}`", c.name), at, v.im)?;
            }
            if with_level {
                let _ = write!(s, "{},", num(set.level_n.unwrap_or(f64::NAN)));
            }
            s.push_str(&num(*f));
            for c in &set.curves {
                let _ = write!(s, ",{},{}", num(c.values[r].norm()), num(c.values[r].arg()));
            }
            s.push('\n');
        }
    }
    std::fs::write(path, s).map_err(io_err(path))
}

/// FRF sets from the FRF datasets (function type 4) of a UFF file, one set per dataset.
pub fn frf_sets_from_uff(datasets: &[Dataset58], file: &str) -> Vec<FrfSet> {
    datasets
        .iter()
        .filter(|d| d.function_type == function_type::FRF)
        .map(|d| {
            let values = match &d.ordinate {
                Ordinate::Real(v) => v.iter().map(|&x| Complex64::new(x, 0.0)).collect(),
                Ordinate::Complex(v) => v.clone(),
            };
            let unit = match (unit_from_label(&d.ordinate_axis.units), unit_from_label(&d.denominator_axis.units)) {
                (n, d) if d.is_empty() => n,
                (n, d) => format!("{n}_per_{d}"),
            };
            FrfSet {
                source: file.into(),
                // Written by `frf_set_to_uff` as id2 = "level <F> N".
                level_n: d.ids[1]
                    .trim()
                    .strip_prefix("level ")
                    .and_then(|l| l.strip_suffix(" N"))
                    .and_then(|l| l.parse::<f64>().ok())
                    // `level NaN N` is no level: left unknown, as an id2 without one.
                    .filter(|l| l.is_finite()),
                frequency_hz: d.x(),
                curves: vec![FrfCurve {
                    name: d.ids[0].trim().replace([' ', ','], "_"),
                    unit,
                    values,
                    has_phase: matches!(d.ordinate, Ordinate::Complex(_)),
                }],
            }
        })
        .collect()
}

/// UFF FRF datasets (function type 4, complex, listed frequencies) of an FRF set.
pub fn frf_set_to_uff(set: &FrfSet) -> Vec<Dataset58> {
    set.curves
        .iter()
        .map(|c| {
            let mut d = Dataset58::frf(&c.name, &unit_label(&c.unit), set.frequency_hz.clone(), c.values.clone());
            if let Some(l) = set.level_n {
                d.ids[1] = format!("level {l} N");
            }
            d
        })
        .collect()
}

/// Write period frames `frames[j][i]` (point i at phase 2πj/n) as `dir/frame_<j>.csv`, columns
/// `point,phase_rad,<quantity>`; returns the files written.
pub fn write_frames(
    dir: &Path,
    point_names: &[String],
    quantity_column: &str,
    frames: &[Vec<f64>],
) -> Result<Vec<PathBuf>, RecordsError> {
    std::fs::create_dir_all(dir).map_err(io_err(dir))?;
    // Checked before any file is written, so that a refused frame leaves no partial set.
    for (j, frame) in frames.iter().enumerate() {
        for (name, v) in point_names.iter().zip(frame) {
            finite(dir, quantity_column, || format!("point `{name}` of frame {j}"), *v)?;
        }
    }
    let digits = frames.len().saturating_sub(1).to_string().len().max(3);
    let mut written = Vec::with_capacity(frames.len());
    for (j, frame) in frames.iter().enumerate() {
        let phase = 2.0 * std::f64::consts::PI * j as f64 / frames.len() as f64;
        let mut s = format!("point,phase_rad,{quantity_column}\n");
        for (name, v) in point_names.iter().zip(frame) {
            let _ = writeln!(s, "{name},{},{}", num(phase), num(*v));
        }
        let path = dir.join(format!("frame_{j:0digits$}.csv"));
        std::fs::write(&path, s).map_err(io_err(&path))?;
        written.push(path);
    }
    Ok(written)
}
