//! `ParamDesign`: a study, its varied keys and its samples (`stickslip_io::params`), and the
//! runs of batches of samples as plain data for the Python scheduler (processes or Dask).

use std::sync::Mutex;

use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use stickslip_io::params::{files, ParamError as IoParamError, ParamStudy, SampleOutcome, SampleRunner, Vary};
use stickslip_io::study::LinearBase;

use crate::convert::{guarded, table_from_dict, ParamError, StudyError};
use crate::study::PyStudy;

fn param_error(e: IoParamError) -> PyErr {
    match e {
        IoParamError::Study(e) => StudyError::new_err(e.to_string()),
        e => ParamError::new_err(e.to_string()),
    }
}

/// The samples of a parameter study: built from a study and `KEY=SPEC` strings, exactly as
/// `stickslip params` does.
#[pyclass(module = "stickslip._stickslip", name = "ParamDesign", frozen)]
pub struct PyParamDesign {
    inner: ParamStudy,
    /// Linear models (or their reductions) built by earlier batches, one per batch that ran at
    /// the same time: a worker's next batch starts from one instead of rebuilding it.
    bases: Mutex<Vec<LinearBase>>,
}

#[pymethods]
impl PyParamDesign {
    /// `varies`: `KEY=LO:HI` (a Latin hypercube of `samples` points, seeded by `seed`),
    /// `KEY=LO:HI:N` or `KEY=a,b,c` (a grid).
    #[new]
    #[pyo3(signature = (study, varies, samples=None, seed=0))]
    fn new(study: &Bound<'_, PyAny>, varies: Vec<String>, samples: Option<usize>, seed: u64) -> PyResult<Self> {
        let (table, path) = table_and_path(study)?;
        guarded(|| {
            let varies = varies.iter().map(|v| Vary::parse(v)).collect::<Result<Vec<_>, _>>().map_err(param_error)?;
            let inner = ParamStudy::new(table, path, &varies, samples, seed).map_err(param_error)?;
            Ok(PyParamDesign { inner, bases: Mutex::new(Vec::new()) })
        })
    }

    /// A design given sample by sample: `samples[i][k]` is the value of `keys[k]` in sample
    /// `i`. The keys are checked now; a sample the study refuses fails alone when it runs.
    #[staticmethod]
    fn from_samples(study: &Bound<'_, PyAny>, keys: Vec<String>, samples: Vec<Vec<f64>>) -> PyResult<Self> {
        let (table, path) = table_and_path(study)?;
        guarded(|| {
            let inner = ParamStudy::with_samples(table, path, &keys, samples).map_err(param_error)?;
            Ok(PyParamDesign { inner, bases: Mutex::new(Vec::new()) })
        })
    }

    /// The varied keys, in column order.
    #[getter]
    fn keys(&self) -> Vec<String> {
        self.inner.keys.iter().map(|k| k.to_string()).collect()
    }

    /// One row per sample, one column per key.
    #[getter]
    fn samples<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        if self.inner.samples.is_empty() {
            return Ok(PyArray2::zeros(py, [0, self.inner.keys.len()], false));
        }
        Ok(PyArray2::from_vec2(py, &self.inner.samples)?)
    }

    #[getter]
    fn method(&self) -> String {
        self.inner.method.clone()
    }

    /// Identifies the study (without the samples' values): caches are bound to it.
    #[getter]
    fn study_id(&self) -> String {
        self.inner.study_id()
    }

    /// Identifies the keys and all samples' values.
    #[getter]
    fn design_id(&self) -> String {
        files::design_id(&self.inner)
    }

    /// Identifies sample `index` (the study, the keys and its values): its cache entry's name.
    fn sample_id(&self, index: usize) -> PyResult<String> {
        let v = self.inner.samples.get(index).ok_or_else(|| self.out_of_range(index))?;
        Ok(self.inner.sample_id(v))
    }

    /// Run samples `indices` one after the other without the GIL. Returns one dict per
    /// sample: `sample`, `values`, `rows` (per level, keyed by `SUMMARY_COLUMNS`), `error`
    /// (a message, or None) and, with `curves`, `curves` = (columns, table) as `Study.run`.
    #[pyo3(signature = (indices, output=None, curves=false))]
    fn run<'py>(
        &self,
        py: Python<'py>,
        indices: Vec<usize>,
        output: Option<String>,
        curves: bool,
    ) -> PyResult<Vec<Bound<'py, PyDict>>> {
        if let Some(i) = indices.iter().find(|i| **i >= self.inner.samples.len()) {
            return Err(self.out_of_range(*i));
        }
        let (inner, bases) = (&self.inner, &self.bases);
        let outcomes: Vec<SampleOutcome> = py.detach(|| {
            guarded(|| {
                // The samples share the linear model (and its reduction) while their varied
                // keys leave it unchanged (see `SampleRunner`), within a batch and across the
                // batches a worker runs. A poisoned lock only means a batch panicked; the
                // bases it holds are whole values.
                let kept = bases.lock().unwrap_or_else(|e| e.into_inner()).pop();
                let mut runner = SampleRunner::with_base(inner, kept);
                let outcomes = indices.iter().map(|&i| runner.run(i, output.as_deref(), curves)).collect();
                if let Some(base) = runner.into_base() {
                    bases.lock().unwrap_or_else(|e| e.into_inner()).push(base);
                }
                Ok(outcomes)
            })
        })?;
        outcomes.iter().map(|o| outcome_dict(py, o)).collect()
    }

    fn __len__(&self) -> usize {
        self.inner.samples.len()
    }
}

/// A Study, or a dict shaped like a study file.
fn table_and_path(study: &Bound<'_, PyAny>) -> PyResult<(toml::Table, std::path::PathBuf)> {
    match study.cast::<PyStudy>() {
        Ok(s) => {
            let s = s.get();
            Ok((s.table.clone(), s.study.path.clone()))
        }
        Err(_) => Ok((table_from_dict(study, "")?, std::path::PathBuf::from("<dict>"))),
    }
}

impl PyParamDesign {
    fn out_of_range(&self, index: usize) -> PyErr {
        ParamError::new_err(format!(
            "sample {index} does not exist: the design has {} samples",
            self.inner.samples.len()
        ))
    }
}

fn outcome_dict<'py>(py: Python<'py>, o: &SampleOutcome) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("sample", o.index)?;
    d.set_item("values", PyArray1::from_slice(py, &o.values))?;
    let rows = o
        .rows
        .iter()
        .map(|r| {
            let row = PyDict::new(py);
            row.set_item("level_N", r.level_n)?;
            row.set_item("peak_frequency_Hz", r.peak_frequency_hz)?;
            row.set_item("peak_amplitude_m", r.peak_amplitude_m)?;
            row.set_item("peak_energy_J", r.peak_energy_j)?;
            row.set_item("points", r.points)?;
            row.set_item("complete", r.complete)?;
            row.set_item("ending", &r.ending)?;
            row.set_item("error", py.None())?;
            Ok(row)
        })
        .collect::<PyResult<Vec<_>>>()?;
    d.set_item("rows", rows)?;
    d.set_item("error", o.error.clone())?;
    if let Some(levels) = &o.levels {
        let levels: Vec<&stickslip_io::output::LevelResult> = levels.iter().collect();
        d.set_item("curves", crate::study::frf_table(py, &levels)?)?;
    }
    Ok(d)
}
