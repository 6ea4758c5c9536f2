//! Universal File Format dataset 58 ("function at nodal DOF"): time records, spectra and FRFs as
//! test software exchanges them, ASCII and binary (58b), real or complex ordinates, even or
//! uneven abscissa, single or double precision.
//!
//! # Layout of one dataset
//!
//! ```text
//!     -1                              delimiter
//!     58      (or 58b + binary description: byte order, float format, 11, byte count)
//! records 1-5   80-character id lines (id1..id5)
//! record 6      function type, id, version, load case, response entity/node/direction,
//!               reference entity/node/direction            (2(I5,I10),2(1X,10A1,I10,I4))
//! record 7      ordinate type (2 real single, 4 real double, 5 complex single, 6 complex
//!               double), number of points, spacing (1 even, 0 uneven), x min, x increment,
//!               z value                                     (3I10,3E13.5)
//! records 8-11  abscissa, ordinate numerator, ordinate denominator, z axis: data type,
//!               length/force/temperature exponents, label, units  (I10,3I5,2(1X,20A1))
//! record 12     values: x (uneven only), then the real or (re, im) ordinate, per point.
//!               ASCII single 6E13.5; double even 4E20.12; double uneven real 2(E13.5,E20.12);
//!               double uneven complex E13.5,2E20.12. Binary: IEEE floats of the same sequence.
//!     -1                              delimiter
//! ```
//!
//! Reading follows pyuff 2.5.8 (the reference implementation the tests compare with): fixed-width
//! fields, blank trailing fields ignored, text decoded as UTF-8 with replacement, the number of
//! values found wins over a disagreeing point count (reported as a [`UffWarning`]). Datasets of
//! other types are skipped and listed; a file with none of type 58 is an error.
//!
//! Hand-written: no maintained Rust crate reads or writes UFF.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use num_complex::Complex64;

/// Floating-point precision of the stored ordinate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Precision {
    Single,
    Double,
}

/// Abscissa of a dataset: evenly spaced (time records, FRFs on a grid) or listed.
#[derive(Debug, Clone, PartialEq)]
pub enum Abscissa {
    Even { min: f64, increment: f64 },
    Uneven(Vec<f64>),
}

/// Ordinate values.
#[derive(Debug, Clone, PartialEq)]
pub enum Ordinate {
    Real(Vec<f64>),
    Complex(Vec<Complex64>),
}

impl Ordinate {
    pub fn len(&self) -> usize {
        match self {
            Ordinate::Real(v) => v.len(),
            Ordinate::Complex(v) => v.len(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// One axis description (records 8-11).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct AxisSpec {
    /// Specific data type: 0 unknown, 1 general, 8 displacement, 11 velocity, 12 acceleration,
    /// 13 excitation force, 17 time, 18 frequency, ...
    pub data_type: i32,
    pub length_exponent: i32,
    pub force_exponent: i32,
    pub temperature_exponent: i32,
    pub label: String,
    pub units: String,
}

impl AxisSpec {
    pub fn new(data_type: i32, label: &str, units: &str) -> Self {
        AxisSpec { data_type, label: label.to_string(), units: units.to_string(), ..Default::default() }
    }

    fn none() -> Self {
        AxisSpec::new(0, "NONE", "NONE")
    }
}

/// Function types of record 6 used by stickslip.
pub mod function_type {
    pub const GENERAL: i32 = 0;
    pub const TIME_RESPONSE: i32 = 1;
    pub const AUTO_SPECTRUM: i32 = 2;
    pub const FRF: i32 = 4;
}

/// One dataset 58.
#[derive(Debug, Clone, PartialEq)]
pub struct Dataset58 {
    /// Records 1-5 (id1 is usually the function's name, id3 the date).
    pub ids: [String; 5],
    pub function_type: i32,
    pub function_id: i32,
    pub version: i32,
    pub load_case: i32,
    pub response_entity: String,
    pub response_node: i64,
    pub response_direction: i32,
    pub reference_entity: String,
    pub reference_node: i64,
    pub reference_direction: i32,
    pub precision: Precision,
    pub abscissa: Abscissa,
    pub z_value: f64,
    pub abscissa_axis: AxisSpec,
    pub ordinate_axis: AxisSpec,
    pub denominator_axis: AxisSpec,
    pub z_axis: AxisSpec,
    pub ordinate: Ordinate,
}

impl Dataset58 {
    /// A time record of `samples` at interval `dt_s` from t = 0 (function type 1), the ordinate
    /// labelled `name` in `units`, written in double precision.
    pub fn time_record(name: &str, units: &str, dt_s: f64, samples: Vec<f64>) -> Self {
        Dataset58 {
            ids: [name.to_string(), "NONE".into(), "NONE".into(), "NONE".into(), "NONE".into()],
            function_type: function_type::TIME_RESPONSE,
            function_id: 0,
            version: 0,
            load_case: 0,
            response_entity: name.chars().take(10).collect(),
            response_node: 0,
            response_direction: 0,
            reference_entity: "NONE".into(),
            reference_node: 0,
            reference_direction: 0,
            precision: Precision::Double,
            abscissa: Abscissa::Even { min: 0.0, increment: dt_s },
            z_value: 0.0,
            abscissa_axis: AxisSpec::new(17, "Time", "s"),
            ordinate_axis: AxisSpec::new(1, name, units),
            denominator_axis: AxisSpec::none(),
            z_axis: AxisSpec::none(),
            ordinate: Ordinate::Real(samples),
        }
    }

    /// An FRF (function type 4) of `name` in `units`, on listed frequencies in Hz.
    pub fn frf(name: &str, units: &str, frequencies_hz: Vec<f64>, values: Vec<Complex64>) -> Self {
        Dataset58 {
            function_type: function_type::FRF,
            abscissa: Abscissa::Uneven(frequencies_hz),
            abscissa_axis: AxisSpec::new(18, "Frequency", "Hz"),
            ordinate: Ordinate::Complex(values),
            ..Dataset58::time_record(name, units, 1.0, Vec::new())
        }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.ordinate.len()
    }

    pub fn is_empty(&self) -> bool {
        self.ordinate.is_empty()
    }

    /// Abscissa values, one per point.
    pub fn x(&self) -> Vec<f64> {
        match &self.abscissa {
            Abscissa::Even { min, increment } => (0..self.len()).map(|i| min + i as f64 * increment).collect(),
            Abscissa::Uneven(x) => x.clone(),
        }
    }

    fn ordinate_code(&self) -> i32 {
        match (&self.ordinate, self.precision) {
            (Ordinate::Real(_), Precision::Single) => 2,
            (Ordinate::Real(_), Precision::Double) => 4,
            (Ordinate::Complex(_), Precision::Single) => 5,
            (Ordinate::Complex(_), Precision::Double) => 6,
        }
    }
}

/// A dataset of another type, skipped.
#[derive(Debug, Clone, PartialEq)]
pub struct SkippedDataset {
    pub dataset_type: u32,
    /// 1-based line of its opening `-1`.
    pub line: usize,
}

/// Something read but suspicious.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum UffWarning {
    #[error("dataset 58 at line {line} declares {declared} points but holds {found}: the {found} values present were read (the file may be truncated)")]
    PointCount { line: usize, declared: usize, found: usize },
}

/// The datasets 58 of a file, and what was skipped.
#[derive(Debug, Clone, PartialEq)]
pub struct UffFile {
    pub datasets: Vec<Dataset58>,
    pub skipped: Vec<SkippedDataset>,
    pub warnings: Vec<UffWarning>,
}

/// ASCII or binary (58b) data records.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Encoding {
    Ascii,
    Binary,
}

/// Errors reading or writing UFF files.
#[derive(Debug, thiserror::Error)]
pub enum UffError {
    #[error("{path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    #[error("{file}: holds UFF datasets {found:?} but no dataset 58 (function at nodal DOF): export the time records or FRFs as dataset 58")]
    NoDataset58 { file: String, found: Vec<u32> },
    #[error("{file}: no UFF dataset found (a dataset opens with a line `    -1`)")]
    Empty { file: String },
    #[error("{file}:{line}: {what}")]
    Malformed { file: String, line: usize, what: String },
    #[error("{file}:{line}: ordinate data type {code} is not one of 2 (real single), 4 (real double), 5 (complex single), 6 (complex double)")]
    OrdinateType { file: String, line: usize, code: i64 },
    #[error("{file}:{line}: binary dataset 58b uses {what}; only IEEE 754 floats (format 2) are supported: convert the file to IEEE or ASCII")]
    BinaryFormat { file: String, line: usize, what: String },
    #[error("dataset `{name}`: {what}")]
    Invalid { name: String, what: String },
}

/// Read every dataset 58 of a UFF file.
pub fn read(path: &Path) -> Result<UffFile, UffError> {
    let bytes = std::fs::read(path).map_err(|source| UffError::Io { path: path.to_path_buf(), source })?;
    parse(&bytes, &path.display().to_string())
}

/// Line-oriented cursor over the raw bytes (binary data sits between ASCII lines).
struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
    line: usize,
}

impl<'a> Cursor<'a> {
    /// The next line without its terminator (LF, CRLF or CR), or None at the end.
    fn next_line(&mut self) -> Option<&'a [u8]> {
        if self.pos >= self.bytes.len() {
            return None;
        }
        let rest = &self.bytes[self.pos..];
        let end = rest.iter().position(|&b| b == b'\n' || b == b'\r').unwrap_or(rest.len());
        let mut next = self.pos + end;
        if next < self.bytes.len() && self.bytes[next] == b'\r' {
            next += 1;
        }
        if next < self.bytes.len() && self.bytes[next] == b'\n' {
            next += 1;
        }
        self.pos = next;
        self.line += 1;
        Some(&rest[..end])
    }
}

fn is_delimiter(line: &[u8]) -> bool {
    String::from_utf8_lossy(line).trim() == "-1"
}

/// Fixed-width field `[start, start+width)` of a line, clipped to the line.
fn field(line: &str, start: usize, width: usize) -> &str {
    if line.is_ascii() {
        return &line[start.min(line.len())..(start + width).min(line.len())];
    }
    let chars: Vec<(usize, char)> = line.char_indices().collect();
    let at = |i: usize| chars.get(i).map(|&(b, _)| b).unwrap_or(line.len());
    &line[at(start)..at(start + width)]
}

/// A Fortran real (E or D exponent).
fn parse_real(text: &str) -> Option<f64> {
    let t = text.trim();
    t.parse::<f64>().ok().or_else(|| t.replace(['D', 'd'], "E").parse().ok())
}

struct Context<'a> {
    file: &'a str,
}

impl Context<'_> {
    fn malformed(&self, line: usize, what: impl Into<String>) -> UffError {
        UffError::Malformed { file: self.file.to_string(), line, what: what.into() }
    }

    fn int(&self, text: &str, line: usize, name: &str) -> Result<i64, UffError> {
        let t = text.trim();
        if t.is_empty() {
            return Ok(0);
        }
        t.parse().map_err(|_| self.malformed(line, format!("{name} `{t}` is not an integer")))
    }

    fn real(&self, text: &str, line: usize, name: &str) -> Result<f64, UffError> {
        let t = text.trim();
        if t.is_empty() {
            return Ok(0.0);
        }
        match parse_real(t) {
            Some(x) if x.is_finite() => Ok(x),
            Some(_) => Err(self.malformed(line, format!("{name} `{t}` is not a finite number"))),
            None => Err(self.malformed(line, format!("{name} `{t}` is not a number"))),
        }
    }

    fn axis(&self, text: &str, line: usize) -> Result<AxisSpec, UffError> {
        Ok(AxisSpec {
            data_type: self.int(field(text, 0, 10), line, "specific data type")? as i32,
            length_exponent: self.int(field(text, 10, 5), line, "length units exponent")? as i32,
            force_exponent: self.int(field(text, 15, 5), line, "force units exponent")? as i32,
            temperature_exponent: self.int(field(text, 20, 5), line, "temperature units exponent")? as i32,
            label: field(text, 26, 20).trim().to_string(),
            units: field(text, 47, 20).trim().to_string(),
        })
    }
}

/// Parse the bytes of a UFF file named `file` (for messages).
pub fn parse(bytes: &[u8], file: &str) -> Result<UffFile, UffError> {
    let ctx = Context { file };
    let mut cur = Cursor { bytes, pos: 0, line: 0 };
    let mut out = UffFile { datasets: Vec::new(), skipped: Vec::new(), warnings: Vec::new() };
    loop {
        // Opening delimiter (blank lines between datasets are tolerated).
        let open = loop {
            match cur.next_line() {
                None => break None,
                Some(l) if String::from_utf8_lossy(l).trim().is_empty() => continue,
                Some(l) if is_delimiter(l) => break Some(cur.line),
                Some(l) => {
                    return Err(ctx.malformed(
                        cur.line,
                        format!(
                            "expected the delimiter `    -1` opening a dataset, found `{}`",
                            String::from_utf8_lossy(l).trim()
                        ),
                    ));
                }
            }
        };
        let Some(open_line) = open else { break };
        let Some(head) = cur.next_line() else {
            return Err(ctx.malformed(open_line, "the file ends after a `-1` delimiter"));
        };
        let head = String::from_utf8_lossy(head).into_owned();
        let number_text = field(&head, 0, 6).trim().to_string();
        let number: u32 = number_text.trim_end_matches(['b', 'B']).parse().map_err(|_| {
            ctx.malformed(cur.line, format!("`{}` is not a dataset number (expected e.g. `    58`)", head.trim()))
        })?;
        let binary =
            head.chars().nth(6).is_some_and(|c| c.eq_ignore_ascii_case(&'b')) || number_text.ends_with(['b', 'B']);
        if number != 58 {
            out.skipped.push(SkippedDataset { dataset_type: number, line: open_line });
            loop {
                match cur.next_line() {
                    None => return Err(ctx.malformed(open_line, format!("dataset {number} is not closed by `-1`"))),
                    Some(l) if is_delimiter(l) => break,
                    Some(_) => {}
                }
            }
            continue;
        }
        let (dataset, warning) = parse_58(&ctx, &mut cur, &head, binary, open_line)?;
        out.datasets.push(dataset);
        out.warnings.extend(warning);
    }
    if out.datasets.is_empty() {
        if out.skipped.is_empty() {
            return Err(UffError::Empty { file: file.to_string() });
        }
        return Err(UffError::NoDataset58 {
            file: file.to_string(),
            found: out.skipped.iter().map(|s| s.dataset_type).collect(),
        });
    }
    Ok(out)
}

fn parse_58(
    ctx: &Context,
    cur: &mut Cursor,
    head: &str,
    binary: bool,
    open_line: usize,
) -> Result<(Dataset58, Option<UffWarning>), UffError> {
    let head_line = cur.line;
    let mut little_endian = true;
    if binary {
        // `    58b` then byte ordering (1 little, 2 big), floating-point format (2 IEEE).
        little_endian = ctx.int(field(head, 7, 6), head_line, "byte ordering")? != 2;
        let format = ctx.int(field(head, 13, 6), head_line, "floating-point format")?;
        if format != 2 && format != 0 {
            let what = if format == 1 { "DEC VMS floats (format 1)" } else { "IBM 370 floats (format 3)" };
            return Err(UffError::BinaryFormat { file: ctx.file.to_string(), line: head_line, what: what.into() });
        }
    }
    let mut records = Vec::with_capacity(11);
    for _ in 0..11 {
        let l =
            cur.next_line().ok_or_else(|| ctx.malformed(cur.line, "the file ends inside the header of dataset 58"))?;
        if is_delimiter(l) {
            return Err(ctx.malformed(cur.line, "dataset 58 ends before its 11 header records"));
        }
        records.push((String::from_utf8_lossy(l).into_owned(), cur.line));
    }
    let id = |i: usize| records[i].0.trim_end().to_string();
    let (r6, l6) = (&records[5].0, records[5].1);
    let (r7, l7) = (&records[6].0, records[6].1);
    // Record 7: fixed width (3I10,3E13.5), whitespace-separated as a fallback.
    let fixed: Option<Vec<&str>> = Some(vec![
        field(r7, 0, 10),
        field(r7, 10, 10),
        field(r7, 20, 10),
        field(r7, 30, 13),
        field(r7, 43, 13),
        field(r7, 56, 13),
    ])
    .filter(|f| {
        f[0..3].iter().all(|t| t.trim().parse::<i64>().is_ok())
            && f[3..].iter().all(|t| t.trim().is_empty() || parse_real(t).is_some())
    });
    let split: Vec<&str> = r7.split_whitespace().collect();
    let r7f = fixed.unwrap_or(split);
    let get = |i: usize| r7f.get(i).copied().unwrap_or("");
    let code = ctx.int(get(0), l7, "ordinate data type")?;
    let declared = ctx.int(get(1), l7, "number of points")?;
    let even = ctx.int(get(2), l7, "abscissa spacing")? == 1;
    let x_min = ctx.real(get(3), l7, "abscissa minimum")?;
    let x_inc = ctx.real(get(4), l7, "abscissa increment")?;
    let z_value = ctx.real(get(5), l7, "z-axis value")?;
    let (complex, precision) = match code {
        2 => (false, Precision::Single),
        4 => (false, Precision::Double),
        5 => (true, Precision::Single),
        6 => (true, Precision::Double),
        _ => return Err(UffError::OrdinateType { file: ctx.file.to_string(), line: l7, code }),
    };
    let per_point = usize::from(!even) + if complex { 2 } else { 1 };

    let data_line = cur.line + 1;
    // Line of each value (ASCII), for the errors on values checked after reading.
    let mut value_lines: Vec<usize> = Vec::new();
    let values: Vec<f64> = if binary {
        let size = if precision == Precision::Single { 4 } else { 8 };
        // Checked: a damaged point count must not overflow or reserve beyond the file.
        let left = cur.bytes.len() - cur.pos;
        let n_bytes = usize::try_from(declared.max(0)).ok().and_then(|d| d.checked_mul(per_point * size));
        let Some(n_bytes) = n_bytes.filter(|&n| n <= left) else {
            return Err(ctx.malformed(
                data_line,
                format!("binary data of {declared} points needs more bytes than the file has left ({left})"),
            ));
        };
        let end = cur.pos + n_bytes;
        if end > cur.bytes.len() {
            return Err(ctx.malformed(
                data_line,
                format!(
                    "binary data of {declared} points needs {n_bytes} bytes but the file has {} left",
                    cur.bytes.len() - cur.pos
                ),
            ));
        }
        let raw = &cur.bytes[cur.pos..end];
        cur.pos = end;
        let values = raw
            .chunks_exact(size)
            .map(|c| match (size, little_endian) {
                (4, true) => f32::from_le_bytes(c.try_into().unwrap()) as f64,
                (4, false) => f32::from_be_bytes(c.try_into().unwrap()) as f64,
                (_, true) => f64::from_le_bytes(c.try_into().unwrap()),
                (_, false) => f64::from_be_bytes(c.try_into().unwrap()),
            })
            .collect();
        // The closing delimiter follows the data, possibly after a line break.
        while cur.pos < cur.bytes.len() && matches!(cur.bytes[cur.pos], b'\r' | b'\n') {
            cur.pos += 1;
        }
        match cur.next_line() {
            Some(l) if is_delimiter(l) => {}
            _ => {
                return Err(ctx.malformed(
                    data_line,
                    format!("binary data of {declared} points is not followed by `-1`: the point count or ordinate type of record 7 (line {l7}) disagrees with the data"),
                ));
            }
        }
        values
    } else {
        // Field widths as in record 12 (see the module documentation).
        let widths: &[usize] = match (precision, even, complex) {
            (Precision::Single, _, _) => &[13],
            (Precision::Double, true, _) => &[20],
            (Precision::Double, false, false) => &[13, 20],
            (Precision::Double, false, true) => &[13, 20, 20],
        };
        // Reserve no more than the rest of the file can hold (a value takes 13 characters at
        // least): the declared count comes from the file and may be damaged.
        let left = (cur.bytes.len() - cur.pos) / 13;
        let mut values = Vec::with_capacity((declared.max(0) as usize).saturating_mul(per_point).min(left));
        loop {
            let l = cur.next_line().ok_or_else(|| ctx.malformed(open_line, "dataset 58 is not closed by `-1`"))?;
            if is_delimiter(l) {
                break;
            }
            let text = String::from_utf8_lossy(l);
            let mut start = 0;
            let mut w = 0;
            while start < text.len() {
                let width = widths[w % widths.len()];
                let f = field(&text, start, width);
                if !f.trim().is_empty() {
                    let v = parse_real(f).ok_or_else(|| {
                        ctx.malformed(
                            cur.line,
                            format!("`{}` (columns {}-{}) is not a number", f.trim(), start + 1, start + width),
                        )
                    })?;
                    if !v.is_finite() {
                        return Err(ctx.malformed(
                            cur.line,
                            format!("`{}` (columns {}-{}) is not a finite number", f.trim(), start + 1, start + width),
                        ));
                    }
                    values.push(v);
                    value_lines.push(cur.line);
                }
                start += width;
                w += 1;
            }
        }
        values
    };
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        // Binary data (ASCII values are checked as they are read).
        return Err(ctx.malformed(
            data_line,
            format!(
                "value {} of the binary data (point {}) is {}, not a finite number",
                i + 1,
                i / per_point + 1,
                values[i]
            ),
        ));
    }
    if !values.len().is_multiple_of(per_point) {
        return Err(ctx.malformed(
            head_line + 12,
            format!("{} values do not make whole points of {per_point} values each", values.len()),
        ));
    }
    let found = values.len() / per_point;
    let warning = (found != declared.max(0) as usize).then_some(UffWarning::PointCount {
        line: open_line,
        declared: declared.max(0) as usize,
        found,
    });
    let offset = usize::from(!even);
    // Time and frequency increase: a listed abscissa out of order, or an even one that does not
    // advance, would make a record or FRF the analyses cannot use.
    if even && found > 1 && x_inc <= 0.0 {
        return Err(ctx.malformed(l7, format!("abscissa increment {x_inc} of {found} points: it must be > 0")));
    }
    if even && found > 1 {
        // In f64 the points must still increase and stay finite (an increment below the
        // resolution of the minimum, or a last point beyond 1.8e308, does not).
        let x = |i: usize| x_min + i as f64 * x_inc;
        if let Some(i) = (1..found).find(|&i| !(x(i).is_finite() && x(i) > x(i - 1))) {
            return Err(ctx.malformed(
                l7,
                format!(
                    "abscissa minimum {x_min} and increment {x_inc}: point {} is at {}, not above point {i}",
                    i + 1,
                    x(i)
                ),
            ));
        }
    }
    if !even {
        for p in 1..found {
            let (a, b) = (values[(p - 1) * per_point], values[p * per_point]);
            if b <= a {
                let line = value_lines.get(p * per_point).copied().unwrap_or(data_line);
                return Err(ctx.malformed(
                    line,
                    format!("abscissa value {b} of point {} does not increase on {a}: the points must be in increasing abscissa order", p + 1),
                ));
            }
        }
    }
    let abscissa = if even {
        Abscissa::Even { min: x_min, increment: x_inc }
    } else {
        Abscissa::Uneven(values.chunks_exact(per_point).map(|p| p[0]).collect())
    };
    let ordinate = if complex {
        Ordinate::Complex(values.chunks_exact(per_point).map(|p| Complex64::new(p[offset], p[offset + 1])).collect())
    } else {
        Ordinate::Real(values.chunks_exact(per_point).map(|p| p[offset]).collect())
    };
    let dataset = Dataset58 {
        ids: [id(0), id(1), id(2), id(3), id(4)],
        function_type: ctx.int(field(r6, 0, 5), l6, "function type")? as i32,
        function_id: ctx.int(field(r6, 5, 10), l6, "function id")? as i32,
        version: ctx.int(field(r6, 15, 5), l6, "version number")? as i32,
        load_case: ctx.int(field(r6, 20, 10), l6, "load case")? as i32,
        response_entity: field(r6, 31, 10).trim().to_string(),
        response_node: ctx.int(field(r6, 41, 10), l6, "response node")?,
        response_direction: ctx.int(field(r6, 51, 4), l6, "response direction")? as i32,
        reference_entity: field(r6, 56, 10).trim().to_string(),
        reference_node: ctx.int(field(r6, 66, 10), l6, "reference node")?,
        reference_direction: ctx.int(field(r6, 76, 4), l6, "reference direction")? as i32,
        precision,
        abscissa,
        z_value,
        abscissa_axis: ctx.axis(&records[7].0, records[7].1)?,
        ordinate_axis: ctx.axis(&records[8].0, records[8].1)?,
        denominator_axis: ctx.axis(&records[9].0, records[9].1)?,
        z_axis: ctx.axis(&records[10].0, records[10].1)?,
        ordinate,
    };
    Ok((dataset, warning))
}

/// Fortran `Ew.d`: d digits after the point, exponent with sign and at least two digits, right
/// aligned in w characters.
fn fortran_e(x: f64, width: usize, digits: usize) -> String {
    let s = format!("{x:.digits$e}");
    let (mantissa, exponent) = s.split_once('e').unwrap_or((&s, "0"));
    let e: i32 = exponent.parse().unwrap_or(0);
    let sign = if e < 0 { '-' } else { '+' };
    format!("{:>width$}", format!("{mantissa}E{sign}{:02}", e.abs()))
}

/// Text fields must fit their columns and stay on one line.
fn text_field(s: &str, width: usize) -> String {
    let clean: String = s.chars().map(|c| if c.is_control() { ' ' } else { c }).take(width).collect();
    format!("{clean:<width$}")
}

fn check(dataset: &Dataset58) -> Result<(), UffError> {
    let invalid = |what: String| UffError::Invalid { name: dataset.ids[0].clone(), what };
    if dataset.is_empty() {
        return Err(invalid("no points to write".into()));
    }
    if let Abscissa::Uneven(x) = &dataset.abscissa {
        if x.len() != dataset.len() {
            return Err(invalid(format!("{} abscissa values for {} ordinate values", x.len(), dataset.len())));
        }
    }
    // A NaN written as text reads back as a malformed field (or as NaN in other tools).
    let not_finite = |quantity: &str, v: &dyn std::fmt::Display| {
        invalid(format!("{quantity} is {v}: refusing to write a value that is not finite"))
    };
    match &dataset.abscissa {
        Abscissa::Even { min, increment } => {
            for (q, v) in [("abscissa minimum", *min), ("abscissa increment", *increment)] {
                if !v.is_finite() {
                    return Err(not_finite(q, &v));
                }
            }
        }
        Abscissa::Uneven(x) => {
            if let Some(i) = x.iter().position(|v| !v.is_finite()) {
                return Err(not_finite(&format!("abscissa value of point {}", i + 1), &x[i]));
            }
        }
    }
    if !dataset.z_value.is_finite() {
        return Err(not_finite("z-axis value", &dataset.z_value));
    }
    match &dataset.ordinate {
        Ordinate::Real(v) => {
            if let Some(i) = v.iter().position(|v| !v.is_finite()) {
                return Err(not_finite(&format!("ordinate of point {}", i + 1), &v[i]));
            }
        }
        Ordinate::Complex(v) => {
            if let Some(i) = v.iter().position(|v| !(v.re.is_finite() && v.im.is_finite())) {
                return Err(not_finite(&format!("ordinate of point {}", i + 1), &v[i]));
            }
        }
    }
    Ok(())
}

/// The data sequence of record 12: per point, x (uneven only) then the real or (re, im) ordinate.
fn data_values(dataset: &Dataset58) -> Vec<f64> {
    let x = match &dataset.abscissa {
        Abscissa::Uneven(x) => Some(x),
        Abscissa::Even { .. } => None,
    };
    let mut out = Vec::new();
    for i in 0..dataset.len() {
        if let Some(x) = x {
            out.push(x[i]);
        }
        match &dataset.ordinate {
            Ordinate::Real(v) => out.push(v[i]),
            Ordinate::Complex(v) => {
                out.push(v[i].re);
                out.push(v[i].im);
            }
        }
    }
    out
}

/// The bytes of a UFF file holding `datasets`, all ASCII or all binary (58b, little endian, IEEE).
pub fn to_bytes(datasets: &[Dataset58], encoding: Encoding) -> Result<Vec<u8>, UffError> {
    let mut out = Vec::new();
    for d in datasets {
        check(d)?;
        let values = data_values(d);
        let size = if d.precision == Precision::Single { 4 } else { 8 };
        let mut h = String::new();
        let _ = writeln!(h, "{:>6}", -1);
        match encoding {
            Encoding::Ascii => {
                let _ = writeln!(h, "{:>6}", 58);
            }
            Encoding::Binary => {
                let _ = writeln!(
                    h,
                    "{:>6}b{:>6}{:>6}{:>12}{:>12}{:>6}{:>6}{:>12}{:>12}",
                    58,
                    1,
                    2,
                    11,
                    values.len() * size,
                    0,
                    0,
                    0,
                    0
                );
            }
        }
        for id in &d.ids {
            let _ = writeln!(h, "{}", text_field(if id.is_empty() { "NONE" } else { id }, 80).trim_end());
        }
        let _ = writeln!(
            h,
            "{:>5}{:>10}{:>5}{:>10} {}{:>10}{:>4} {}{:>10}{:>4}",
            d.function_type,
            d.function_id,
            d.version,
            d.load_case,
            text_field(&d.response_entity, 10),
            d.response_node,
            d.response_direction,
            text_field(&d.reference_entity, 10),
            d.reference_node,
            d.reference_direction
        );
        let (even, min, inc) = match d.abscissa {
            Abscissa::Even { min, increment } => (1, min, increment),
            Abscissa::Uneven(_) => (0, 0.0, 0.0),
        };
        let _ = writeln!(
            h,
            "{:>10}{:>10}{:>10}{}{}{}",
            d.ordinate_code(),
            d.len(),
            even,
            fortran_e(min, 13, 5),
            fortran_e(inc, 13, 5),
            fortran_e(d.z_value, 13, 5)
        );
        for a in [&d.abscissa_axis, &d.ordinate_axis, &d.denominator_axis, &d.z_axis] {
            let _ = writeln!(
                h,
                "{:>10}{:>5}{:>5}{:>5} {} {}",
                a.data_type,
                a.length_exponent,
                a.force_exponent,
                a.temperature_exponent,
                text_field(&a.label, 20),
                text_field(&a.units, 20)
            );
        }
        out.extend_from_slice(h.as_bytes());
        match encoding {
            Encoding::Binary => {
                for v in &values {
                    match d.precision {
                        Precision::Single => out.extend_from_slice(&(*v as f32).to_le_bytes()),
                        Precision::Double => out.extend_from_slice(&v.to_le_bytes()),
                    }
                }
            }
            Encoding::Ascii => {
                let even = matches!(d.abscissa, Abscissa::Even { .. });
                let complex = matches!(d.ordinate, Ordinate::Complex(_));
                // (width, digits) per field, cycled, and fields per line.
                let (fields, per_line): (&[(usize, usize)], usize) = match (d.precision, even, complex) {
                    (Precision::Single, _, _) => (&[(13, 5)], 6),
                    (Precision::Double, true, _) => (&[(20, 12)], 4),
                    (Precision::Double, false, false) => (&[(13, 5), (20, 12)], 4),
                    (Precision::Double, false, true) => (&[(13, 5), (20, 12), (20, 12)], 3),
                };
                let mut line = String::new();
                for (i, v) in values.iter().enumerate() {
                    let (w, p) = fields[i % fields.len()];
                    line.push_str(&fortran_e(*v, w, p));
                    if (i + 1) % per_line == 0 || i + 1 == values.len() {
                        line.push('\n');
                        out.extend_from_slice(line.as_bytes());
                        line.clear();
                    }
                }
            }
        }
        out.extend_from_slice(format!("{:>6}\n", -1).as_bytes());
    }
    Ok(out)
}

/// Write `datasets` to a UFF file.
pub fn write(path: &Path, datasets: &[Dataset58], encoding: Encoding) -> Result<(), UffError> {
    let bytes = to_bytes(datasets, encoding)?;
    std::fs::write(path, bytes).map_err(|source| UffError::Io { path: path.to_path_buf(), source })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fortran_exponent_format() {
        assert_eq!(fortran_e(1.52588e-5, 13, 5), "  1.52588E-05");
        assert_eq!(fortran_e(-3.81956, 13, 5), " -3.81956E+00");
        assert_eq!(fortran_e(0.0, 13, 5), "  0.00000E+00");
        assert_eq!(fortran_e(-1.0e-100, 13, 5), "-1.00000E-100");
        assert_eq!(fortran_e(std::f64::consts::PI, 20, 12), "  3.141592653590E+00");
        assert_eq!(parse_real("0.00000E+000"), Some(0.0));
        assert_eq!(parse_real(" 1.5D+02"), Some(150.0));
    }
}
