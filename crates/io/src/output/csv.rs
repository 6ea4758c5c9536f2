//! CSV writers: `frf.csv` and the per-point time data.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};

use super::{LevelResult, OutputError, Peak, PointRecord, SnapshotResult};

/// Column names of `frf.csv` for points shaped like `template` (units in every name).
pub fn frf_columns(template: &PointRecord) -> Vec<String> {
    let mut cols: Vec<String> =
        ["level_N", "frequency_Hz", "newton_iterations", "residual_rel"].iter().map(|s| s.to_string()).collect();
    for o in &template.outputs {
        let n = &o.name;
        cols.extend([format!("{n}_disp_frf_m_per_N"), format!("{n}_accel_frf_m_s2_per_N"), format!("{n}_peak_m")]);
        for k in 0..o.harmonics.len() {
            cols.extend([format!("{n}_h{k}_amp_m"), format!("{n}_h{k}_phase_rad")]);
        }
    }
    for e in &template.elements {
        cols.extend([format!("{}_energy_J", e.name), format!("{}_stick_fraction", e.name)]);
    }
    cols.extend(["input_energy_J", "viscous_energy_J"].map(String::from));
    if template.stability.is_some() {
        cols.extend(["stable", "floquet_re_per_s", "floquet_im_rad_per_s"].map(String::from));
    }
    cols
}

/// The numbers of one row of `frf.csv`, in the order of [`frf_columns`].
pub fn frf_row(level_n: f64, p: &PointRecord) -> Vec<f64> {
    let mut row = vec![level_n, p.frequency_hz, p.iterations as f64, p.residual];
    for o in &p.outputs {
        row.extend([o.disp_frf, o.accel_frf, o.peak]);
        for &(a, ph) in &o.harmonics {
            row.extend([a, ph]);
        }
    }
    for e in &p.elements {
        row.extend([e.energy_j, e.stick_fraction]);
    }
    row.extend([p.input_energy_j, p.viscous_energy_j]);
    if let Some(s) = &p.stability {
        row.extend([f64::from(u8::from(s.stable)), s.exponent_re, s.exponent_im]);
    }
    row
}

/// The first point of all levels (it fixes the columns), after checking that every point has
/// the same outputs, elements and number of harmonics.
pub(crate) fn template(levels: &[LevelResult]) -> Result<Option<&PointRecord>, OutputError> {
    let Some(first) = levels.iter().flat_map(|l| l.points.first()).next() else { return Ok(None) };
    let shape = |p: &PointRecord| {
        (
            p.outputs.iter().map(|o| (o.name.clone(), o.harmonics.len())).collect::<Vec<_>>(),
            p.elements.iter().map(|e| e.name.clone()).collect::<Vec<_>>(),
            p.stability.is_some(),
        )
    };
    let expected = shape(first);
    for l in levels {
        for p in &l.points {
            if shape(p) != expected {
                return Err(OutputError::Inconsistent {
                    level_n: l.level_n,
                    frequency_hz: p.frequency_hz,
                    message: format!(
                        "outputs/harmonics {:?}, elements {:?} and stability ({}) differ from the first point's {:?}, {:?} and ({})",
                        shape(p).0,
                        shape(p).1,
                        shape(p).2,
                        expected.0,
                        expected.1,
                        expected.2
                    ),
                });
            }
        }
    }
    Ok(Some(first))
}

/// Refuse results holding a value that is not finite, naming its column, level and point.
pub(crate) fn check_finite(path: &Path, levels: &[LevelResult], columns: &[String]) -> Result<(), OutputError> {
    for l in levels {
        for p in &l.points {
            for (c, v) in frf_row(l.level_n, p).into_iter().enumerate() {
                if !v.is_finite() {
                    return Err(OutputError::NotFinite {
                        path: path.to_path_buf(),
                        quantity: format!("column `{}`", columns[c]),
                        location: format!("level {} N, point at {} Hz", l.level_n, p.frequency_hz),
                        value: v,
                    });
                }
            }
        }
    }
    Ok(())
}

fn write_file(path: &Path, text: &str) -> Result<(), OutputError> {
    let io = |source| OutputError::Io { path: path.to_path_buf(), source };
    let mut f = std::io::BufWriter::new(std::fs::File::create(path).map_err(io)?);
    f.write_all(text.as_bytes()).map_err(io)?;
    f.flush().map_err(io)
}

fn push_row(out: &mut String, values: &[f64]) {
    let mut digits = ryu::Buffer::new();
    for (i, &v) in values.iter().enumerate() {
        if i > 0 {
            out.push(',');
        }
        push_number(out, v, &mut digits);
    }
    out.push('\n');
}

/// Append `v` exactly as `format!("{v:e}")` writes it: the shortest digits that read back to
/// the same f64, in exponent form (`2.0572874308247228e2`, `-1e-7`, `0e0`). The digits come
/// from `ryu` (the same shortest, closest digits as the standard library's formatter, ~3x
/// faster: the result tables are a tenth of a fast run); ryu writes `1000.0` or `0.001`, so its
/// text is rewritten into exponent form here. Non-finite values go through `{:e}`.
pub(crate) fn push_number(out: &mut String, v: f64, digits: &mut ryu::Buffer) {
    if !v.is_finite() {
        write!(out, "{v:e}").expect("writing to a String cannot fail");
        return;
    }
    let text = digits.format_finite(v);
    let (text, negative) = match text.strip_prefix('-') {
        Some(rest) => (rest, true),
        None => (text, false),
    };
    let (mantissa, exponent) = match text.split_once('e') {
        Some((m, e)) => (m, e.parse::<i32>().expect("ryu writes an integer exponent")),
        None => (text, 0),
    };
    let (int_part, frac_part) = mantissa.split_once('.').unwrap_or((mantissa, ""));
    // value = (int_part frac_part as an integer) × 10^(exponent − frac_part.len())
    let all = int_part.bytes().chain(frac_part.bytes());
    let mut significant = [0u8; 32];
    let mut len = 0;
    for b in all.skip_while(|&b| b == b'0') {
        if len == significant.len() {
            // Not ryu's output (at most 17 digits and the zeros of its plain form).
            write!(out, "{v:e}").expect("writing to a String cannot fail");
            return;
        }
        significant[len] = b;
        len += 1;
    }
    if negative {
        out.push('-');
    }
    let trailing_zeros = significant[..len].iter().rev().take_while(|&&b| b == b'0').count();
    if len == trailing_zeros {
        out.push_str("0e0");
        return;
    }
    let kept = &significant[..len - trailing_zeros];
    let scientific = exponent - frac_part.len() as i32 + len as i32 - 1;
    out.push(kept[0] as char);
    if kept.len() > 1 {
        out.push('.');
        out.push_str(std::str::from_utf8(&kept[1..]).expect("ASCII digits"));
    }
    out.push('e');
    if scientific < 0 {
        out.push('-');
    }
    // |exponent| ≤ 324: at most three digits.
    let e = scientific.unsigned_abs();
    if e >= 100 {
        out.push(char::from(b'0' + (e / 100) as u8));
    }
    if e >= 10 {
        out.push(char::from(b'0' + (e / 10 % 10) as u8));
    }
    out.push(char::from(b'0' + (e % 10) as u8));
}

/// Write `frf.csv`: a header with units, then one row per converged point of every level, in
/// level order then branch order. Iteration counts are written as integers.
pub fn write_frf_csv(path: &Path, levels: &[LevelResult]) -> Result<(), OutputError> {
    let mut text = String::new();
    let Some(first) = template(levels)? else {
        return write_file(path, &(frf_columns(&PointRecord::default()).join(",") + "\n"));
    };
    let columns = frf_columns(first);
    check_finite(path, levels, &columns)?;
    text.push_str(&columns.join(","));
    text.push('\n');
    let mut digits = ryu::Buffer::new();
    for l in levels {
        for p in &l.points {
            // The iteration count as an integer, every other number in round-trip form.
            let row = frf_row(l.level_n, p);
            for (i, &v) in row.iter().enumerate() {
                if i > 0 {
                    text.push(',');
                }
                if i == 2 {
                    write!(text, "{}", p.iterations).expect("String write");
                } else {
                    push_number(&mut text, v, &mut digits);
                }
            }
            text.push('\n');
        }
    }
    write_file(path, &text)
}

/// Write the time data of one point: `theta_rad`, `time_s`, then per output `<out>_disp_m`,
/// `<out>_vel_m_s`, per element `<el>_u_m`, `<el>_force_N`, `<el>_slider_vel_m_s`; one row
/// per sample `θ_j = 2π j / n_t`. Series that were not kept are left out.
pub fn write_point_csv(path: &Path, p: &PointRecord) -> Result<(), OutputError> {
    write_signals(path, p.frequency_hz, point_columns(p))
}

/// Write a snapshot's time signals: those of [`write_point_csv`], then per joint with both
/// sides known `<joint>_<A>_vel_m_s` and `<joint>_<B>_vel_m_s`.
pub fn write_snapshot_csv(path: &Path, s: &SnapshotResult) -> Result<(), OutputError> {
    let mut columns = point_columns(&s.point);
    for j in &s.sides {
        columns.push((format!("{}_{}_vel_m_s", j.joint, j.dof_a), &j.velocity_a));
        columns.push((format!("{}_{}_vel_m_s", j.joint, j.dof_b), &j.velocity_b));
    }
    write_signals(path, s.point.frequency_hz, columns)
}

fn point_columns(p: &PointRecord) -> Vec<(String, &[f64])> {
    let mut columns: Vec<(String, &[f64])> = Vec::new();
    for o in &p.outputs {
        columns.push((format!("{}_disp_m", o.name), &o.disp));
        columns.push((format!("{}_vel_m_s", o.name), &o.vel));
    }
    for e in &p.elements {
        columns.push((format!("{}_u_m", e.name), &e.loop_u));
        columns.push((format!("{}_force_N", e.name), &e.loop_force));
        columns.push((format!("{}_slider_vel_m_s", e.name), &e.slider_velocity));
    }
    columns
}

/// Signals over one period at `frequency_hz`, one column each (empty ones left out).
fn write_signals(path: &Path, frequency_hz: f64, mut columns: Vec<(String, &[f64])>) -> Result<(), OutputError> {
    columns.retain(|(_, v)| !v.is_empty());
    let n_t = columns.iter().map(|(_, v)| v.len()).max().unwrap_or(0);
    if let Some((name, v)) = columns.iter().find(|(_, v)| v.len() != n_t) {
        return Err(OutputError::TimeData {
            path: path.to_path_buf(),
            message: format!("series {name} has {} samples, others {n_t}", v.len()),
        });
    }
    let mut text = String::from("theta_rad,time_s");
    for (name, _) in &columns {
        text.push(',');
        text.push_str(name);
    }
    text.push('\n');
    let omega = 2.0 * std::f64::consts::PI * frequency_hz;
    if n_t > 0 && !(omega.is_finite() && omega > 0.0) {
        return Err(OutputError::NotFinite {
            path: path.to_path_buf(),
            quantity: "the period (time_s column)".into(),
            location: format!("the point at {frequency_hz} Hz"),
            value: 1.0 / frequency_hz,
        });
    }
    for (name, v) in &columns {
        if let Some(j) = v.iter().position(|x| !x.is_finite()) {
            return Err(OutputError::NotFinite {
                path: path.to_path_buf(),
                quantity: format!("series `{name}`"),
                location: format!("sample {j} of the point at {frequency_hz} Hz"),
                value: v[j],
            });
        }
    }
    let mut row = Vec::with_capacity(columns.len() + 2);
    for j in 0..n_t {
        let theta = 2.0 * std::f64::consts::PI * j as f64 / n_t as f64;
        row.clear();
        row.extend([theta, theta / omega]);
        row.extend(columns.iter().map(|(_, v)| v[j]));
        push_row(&mut text, &row);
    }
    write_file(path, &text)
}

/// Write `dir/points/level<i>_point<j>.csv` (i, j from 0, in level and branch order) for every
/// point that carries time data. Returns the number of files written.
pub fn write_time_data(dir: &Path, levels: &[LevelResult]) -> Result<usize, OutputError> {
    let points_dir = dir.join("points");
    let mut written = 0;
    for (i, l) in levels.iter().enumerate() {
        for (j, p) in l.points.iter().enumerate().filter(|(_, p)| p.has_time_data()) {
            if written == 0 {
                std::fs::create_dir_all(&points_dir)
                    .map_err(|source| OutputError::Io { path: points_dir.clone(), source })?;
            }
            write_point_csv(&point_file(dir, i, j), p)?;
            written += 1;
        }
    }
    Ok(written)
}

/// The time data file of point `j` of level `i`.
fn point_file(dir: &Path, i: usize, j: usize) -> PathBuf {
    dir.join("points").join(format!("level{i}_point{j}.csv"))
}

/// The files [`write_time_data`] writes for `levels`.
pub fn time_data_files(dir: &Path, levels: &[LevelResult]) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for (i, l) in levels.iter().enumerate() {
        files
            .extend(l.points.iter().enumerate().filter(|(_, p)| p.has_time_data()).map(|(j, _)| point_file(dir, i, j)));
    }
    files
}

/// Write `peaks.csv`: per level and output, the FRF peak (`level_N,output,frequency_Hz,
/// disp_frf_m_per_N,accel_frf_m_s2_per_N,located`; `located` is 1 for a peak located between
/// the sampled points, 0 for the largest sampled point, at an end of the band).
pub fn write_peaks_csv(path: &Path, peaks: &[Peak]) -> Result<(), OutputError> {
    let mut text = String::from("level_N,output,frequency_Hz,disp_frf_m_per_N,accel_frf_m_s2_per_N,located\n");
    for p in peaks {
        for (quantity, value) in
            [("frequency", p.frequency_hz), ("displacement FRF", p.disp_frf), ("acceleration FRF", p.accel_frf)]
        {
            if !value.is_finite() {
                return Err(OutputError::NotFinite {
                    path: path.to_path_buf(),
                    quantity: format!("the peak {quantity}"),
                    location: format!("output {} at {} N", p.output, p.level_n),
                    value,
                });
            }
        }
        let _ = writeln!(
            text,
            "{:e},{},{:e},{:e},{:e},{}",
            p.level_n,
            p.output,
            p.frequency_hz,
            p.disp_frf,
            p.accel_frf,
            u8::from(p.located)
        );
    }
    write_file(path, &text)
}

/// Write `bifurcations.csv`: per level, each bifurcation of the branch (`level_N,kind,
/// frequency_Hz,located,floquet_im_rad_per_s`, then `<output>_amp_m`, the first harmonic's
/// amplitude at each output there). A header alone when none was found.
pub fn write_bifurcations_csv(path: &Path, levels: &[LevelResult]) -> Result<(), OutputError> {
    let outputs: Vec<String> = levels
        .iter()
        .flat_map(|l| l.points.first())
        .next()
        .map(|p| p.outputs.iter().map(|o| o.name.clone()).collect())
        .unwrap_or_default();
    let mut text = String::from("level_N,kind,frequency_Hz,located,floquet_im_rad_per_s");
    for o in &outputs {
        let _ = write!(text, ",{o}_amp_m");
    }
    text.push('\n');
    for b in levels.iter().flat_map(|l| &l.bifurcations) {
        let values = [b.frequency_hz, b.exponent_im].into_iter().chain(b.amplitudes().map(|a| a.1));
        for value in values {
            if !value.is_finite() {
                return Err(OutputError::NotFinite {
                    path: path.to_path_buf(),
                    quantity: format!("a value of the {}", b.kind),
                    location: format!("{} N, near {} Hz", b.level_n, b.frequency_hz),
                    value,
                });
            }
        }
        let _ =
            write!(text, "{:e},{},{:e},{},{:e}", b.level_n, b.kind, b.frequency_hz, u8::from(b.located), b.exponent_im);
        for (_, a) in b.amplitudes() {
            let _ = write!(text, ",{a:e}");
        }
        text.push('\n');
    }
    write_file(path, &text)
}

#[cfg(test)]
mod tests {
    use super::push_number;
    use rand::{Rng, SeedableRng};

    /// Our text against the standard `{:e}` text: the same f64 when read back, the same
    /// number of digits (both shortest) and the same form; true when the texts are identical.
    /// They may differ in the last digit where the f64 lies exactly halfway between two
    /// shortest digit strings (`-563077405529510.25`: ryu writes ...510.2 as Python does, the
    /// standard formatter ...510.3); both read back to the same f64.
    fn check(v: f64, digits: &mut ryu::Buffer) -> bool {
        let mut ours = String::new();
        push_number(&mut ours, v, digits);
        let std = format!("{v:e}");
        if !v.is_finite() {
            return ours == std;
        }
        let back: f64 = ours.parse().unwrap_or_else(|_| panic!("{ours} does not parse"));
        assert_eq!(back.to_bits(), v.to_bits(), "{ours} reads back as {back:e}, not {std}");
        let shape = |t: &str| {
            let (m, e) = t.split_once('e').expect("exponent form");
            (m.len(), e.to_owned(), m.starts_with('-'))
        };
        assert_eq!(shape(&ours), shape(&std), "{ours} against {std}");
        ours == std
    }

    /// Every number of a result table reads back to the same f64, written in the standard
    /// exponent form with its shortest digits: checked on the values whose form differs in
    /// ryu's output (integers, plain decimals, exponents of either sign, subnormals, extremes,
    /// signed zeros) and on a million random bit patterns and a million values of the tables'
    /// magnitudes. The ties above are ~0.1 % of random bit patterns; more than 1 % would be a
    /// fault of the rewriting.
    #[test]
    fn numbers_read_back_exactly_in_the_standard_exponent_form() {
        let mut digits = ryu::Buffer::new();
        let special = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            10.0,
            1000.0,
            1e15,
            1e16,
            1e17,
            123456789012345680.0,
            0.001,
            0.0001,
            1e-5,
            1e-7,
            2.0572874308247228e2,
            3.574255186398001e-7,
            f64::MIN_POSITIVE,
            5e-324,
            -5e-324,
            f64::MAX,
            f64::MIN,
            f64::EPSILON,
            0.1 + 0.2,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        for v in special {
            assert!(check(v, &mut digits), "{v:?} written otherwise than by {{:e}}");
        }
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        let mut differ = 0;
        let n = 1_000_000;
        for _ in 0..n {
            let v = f64::from_bits(rng.random::<u64>());
            let w = rng.random_range(-1.0..1.0) * 10f64.powi(rng.random_range(-25..25));
            differ += usize::from(!check(v, &mut digits)) + usize::from(!check(w, &mut digits));
        }
        println!("{differ} of {} numbers differ from {{:e}} in their last digit", 2 * n);
        assert!(differ * 100 <= 2 * n, "{differ} of {} differ", 2 * n);
    }
}
