//! `frf.npz`: the columns of `frf.csv` as NumPy arrays (`numpy.load("frf.npz")`); and the
//! archive writer that it and `reduced.npz` share.

use std::fs::File;
use std::io::{BufWriter, Write as _};
use std::path::Path;

use npyz::zip::write::FileOptions;
use npyz::zip::{CompressionMethod, DateTime, ZipWriter};
use npyz::WriterBuilder;

use super::csv::{check_finite, frf_columns, frf_row, template};
use super::{LevelResult, OutputError};

/// Write `frf.npz`: one 1-D float64 array per column of `frf.csv`, same names and row order,
/// plus per output `<out>_harmonics_amp_m` and `<out>_harmonics_phase_rad`, 2-D (points × N+1).
pub fn write_frf_npz(path: &Path, levels: &[LevelResult]) -> Result<(), OutputError> {
    let io = |source| OutputError::Io { path: path.to_path_buf(), source };
    let Some(first) = template(levels)? else {
        return NpzFile::create(path).and_then(NpzFile::finish).map_err(io);
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
    let mut npz = NpzFile::create(path).map_err(io)?;
    for (name, column) in columns.iter().zip(&table) {
        npz.add(name, &[n_rows as u64], column.iter().copied()).map_err(io)?;
    }
    for (o, out) in first.outputs.iter().enumerate() {
        let shape = [n_rows as u64, out.harmonics.len() as u64];
        let (amps, phases): (Vec<f64>, Vec<f64>) =
            points().flat_map(|(_, p)| p.outputs[o].harmonics.iter().copied()).unzip();
        npz.add(&format!("{}_harmonics_amp_m", out.name), &shape, amps).map_err(io)?;
        npz.add(&format!("{}_harmonics_phase_rad", out.name), &shape, phases).map_err(io)?;
    }
    npz.finish().map_err(io)
}

/// A `.npz` archive being written. Its entries are stored uncompressed, as `numpy.savez`
/// stores them: float64 results hardly compress (Table 6's `frf.npz`: 83 kB stored, 56 kB
/// deflated), and a result file should cost the time of writing it. Its bytes depend on the
/// results alone.
pub(crate) struct NpzFile {
    zip: ZipWriter<BufWriter<File>>,
}

impl NpzFile {
    /// Create (or replace) the archive at `path`.
    pub(crate) fn create(path: &Path) -> std::io::Result<Self> {
        Ok(NpzFile { zip: ZipWriter::new(BufWriter::new(File::create(path)?)) })
    }

    /// Add `<name>.npy` of `shape` (C order). The array is laid out in memory first and handed
    /// to the archive in one write: written value by value, the archive's per-write work
    /// (checksum, compression, buffering) cost more than everything else.
    pub(crate) fn add<T: npyz::AutoSerialize>(
        &mut self,
        name: &str,
        shape: &[u64],
        values: impl IntoIterator<Item = T>,
    ) -> std::io::Result<()> {
        let n: u64 = shape.iter().product();
        let mut npy = Vec::with_capacity(128 + n as usize * std::mem::size_of::<T>());
        let mut writer = npyz::WriteOptions::<T>::new().default_dtype().shape(shape).writer(&mut npy).begin_nd()?;
        writer.extend(values)?;
        writer.finish()?;
        // Entries dated 1980-01-01, the zip format's first date, not the time of the run: the
        // same results make the same bytes, so two runs' files compare with `cmp`.
        let options = FileOptions::default()
            .last_modified_time(DateTime::default())
            .compression_method(CompressionMethod::Stored)
            .large_file(npy.len() >= u32::MAX as usize);
        self.zip.start_file(npyz::npz::file_name_from_array_name(name), options)?;
        self.zip.write_all(&npy)
    }

    /// Write the zip directory and flush, so that errors are reported rather than lost on drop.
    pub(crate) fn finish(mut self) -> std::io::Result<()> {
        self.zip.finish().map_err(std::io::Error::other)?.flush()
    }
}
