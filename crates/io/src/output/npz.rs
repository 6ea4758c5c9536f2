//! `frf.npz`: the columns of `frf.csv` as NumPy arrays (`numpy.load("frf.npz")`).

use std::fs::File;
use std::io::{BufWriter, Write as _};
use std::path::Path;

use npyz::zip::write::FileOptions;
use npyz::zip::{CompressionMethod, ZipWriter};
use npyz::WriterBuilder;

use super::csv::{check_finite, frf_columns, frf_row, template};
use super::{LevelResult, OutputError};

/// Write `frf.npz`: one 1-D float64 array per column of `frf.csv`, same names and row order,
/// plus per output `<out>_harmonics_amp_m` and `<out>_harmonics_phase_rad`, 2-D (points × N+1).
///
/// The entries are stored uncompressed, as `numpy.savez` writes them: float64 results hardly
/// compress, and deflating them cost ten times the rest of the writing.
pub fn write_frf_npz(path: &Path, levels: &[LevelResult]) -> Result<(), OutputError> {
    let io = |source| OutputError::Io { path: path.to_path_buf(), source };
    let create = || File::create(path).map(|file| ZipWriter::new(BufWriter::new(file))).map_err(io);
    let Some(first) = template(levels)? else {
        return finish(create()?).map_err(io);
    };
    let columns = frf_columns(first);
    check_finite(path, levels, &columns)?;
    let points = || levels.iter().flat_map(|l| l.points.iter().map(move |p| (l.level_n, p)));
    let n_rows = points().count();
    // The table by columns: each array is then one contiguous slice.
    let mut table = vec![Vec::with_capacity(n_rows); columns.len()];
    for (level_n, p) in points() {
        for (column, v) in table.iter_mut().zip(frf_row(level_n, p)) {
            column.push(v);
        }
    }
    let mut zip = create()?;
    for (name, column) in columns.iter().zip(&table) {
        add_array(&mut zip, name, &[n_rows as u64], column).map_err(io)?;
    }
    for (o, out) in first.outputs.iter().enumerate() {
        let shape = [n_rows as u64, out.harmonics.len() as u64];
        let (amps, phases): (Vec<f64>, Vec<f64>) =
            points().flat_map(|(_, p)| p.outputs[o].harmonics.iter().copied()).unzip();
        add_array(&mut zip, &format!("{}_harmonics_amp_m", out.name), &shape, &amps).map_err(io)?;
        add_array(&mut zip, &format!("{}_harmonics_phase_rad", out.name), &shape, &phases).map_err(io)?;
    }
    finish(zip).map_err(io)
}

/// Add `<name>.npy` (float64, C order). The array is laid out in memory first and handed to the
/// archive in one write: written value by value, the archive's per-write work (checksum,
/// buffering) cost more than everything else.
fn add_array(zip: &mut ZipWriter<BufWriter<File>>, name: &str, shape: &[u64], values: &[f64]) -> std::io::Result<()> {
    let mut npy = Vec::with_capacity(128 + 8 * values.len());
    let mut writer = npyz::WriteOptions::<f64>::new().default_dtype().shape(shape).writer(&mut npy).begin_nd()?;
    writer.extend(values.iter().copied())?;
    writer.finish()?;
    let options =
        FileOptions::default().compression_method(CompressionMethod::Stored).large_file(npy.len() >= u32::MAX as usize);
    zip.start_file(npyz::npz::file_name_from_array_name(name), options)?;
    zip.write_all(&npy)
}

/// Write the zip directory and flush, so that errors are reported rather than lost on drop.
fn finish(mut zip: ZipWriter<BufWriter<File>>) -> std::io::Result<()> {
    zip.finish().map_err(std::io::Error::other)?.flush()
}
