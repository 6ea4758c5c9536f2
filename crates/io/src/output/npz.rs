//! `frf.npz`: the columns of `frf.csv` as NumPy arrays (`numpy.load("frf.npz")`).

use std::path::Path;

use npyz::WriterBuilder;

use super::csv::{check_finite, frf_columns, frf_row, template};
use super::{LevelResult, OutputError};

/// Write `frf.npz`: one 1-D float64 array per column of `frf.csv`, same names and row order,
/// plus per output `<out>_harmonics_amp_m` and `<out>_harmonics_phase_rad`, 2-D (points × N+1).
pub fn write_frf_npz(path: &Path, levels: &[LevelResult]) -> Result<(), OutputError> {
    let io = |source| OutputError::Io { path: path.to_path_buf(), source };
    let Some(first) = template(levels)? else {
        return npyz::npz::NpzWriter::create(path).map(drop).map_err(io);
    };
    let columns = frf_columns(first);
    check_finite(path, levels, &columns)?;
    let rows: Vec<Vec<f64>> = levels.iter().flat_map(|l| l.points.iter().map(move |p| frf_row(l.level_n, p))).collect();
    let n_rows = rows.len() as u64;
    let mut npz = npyz::npz::NpzWriter::create(path).map_err(io)?;
    let mut write = |name: &str, shape: &[u64], values: &mut dyn Iterator<Item = f64>| -> std::io::Result<()> {
        let mut w = npz.array::<f64>(name, Default::default())?.default_dtype().shape(shape).begin_nd()?;
        w.extend(values)?;
        w.finish()
    };
    for (c, name) in columns.iter().enumerate() {
        write(name, &[n_rows], &mut rows.iter().map(|r| r[c])).map_err(io)?;
    }
    for (o, out) in first.outputs.iter().enumerate() {
        let n_h = out.harmonics.len() as u64;
        let points = || levels.iter().flat_map(|l| l.points.iter());
        let mut amps = points().flat_map(|p| p.outputs[o].harmonics.iter().map(|h| h.0));
        write(&format!("{}_harmonics_amp_m", out.name), &[n_rows, n_h], &mut amps).map_err(io)?;
        let mut phases = points().flat_map(|p| p.outputs[o].harmonics.iter().map(|h| h.1));
        write(&format!("{}_harmonics_phase_rad", out.name), &[n_rows, n_h], &mut phases).map_err(io)?;
    }
    // Finish explicitly (writes the zip directory) so that errors are reported, not dropped.
    let mut file = npz.zip_writer().finish().map_err(|e| io(std::io::Error::other(e)))?;
    std::io::Write::flush(&mut file).map_err(io)
}
