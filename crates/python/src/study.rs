//! `Study`: a validated study, run as data (no files, no plots).

use std::path::PathBuf;

use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use stickslip_core::continuation::Point;
use stickslip_core::timesim::{steady_state, SteadyStateOptions};
use stickslip_io::analysis::{backbone_ending, run_nonlinear_mode, LevelRun, LevelSweeper};
use stickslip_io::backbone::{backbone_columns, backbone_rows, singular_kind_name};
use stickslip_io::output::{frf_columns, frf_row, LevelResult, PointRecord};
use stickslip_io::study::Study as IoStudy;

use crate::convert::{chain, guarded, table_from_dict, value_to_py, InputError, SolveError, StudyError};

/// A validated study (see docs/study-file.md for every key).
#[pyclass(module = "stickslip._stickslip", name = "Study", frozen)]
pub struct PyStudy {
    pub(crate) study: IoStudy,
    /// The study as a table, for `to_dict` and parameter studies.
    pub(crate) table: toml::Table,
}

fn study_error(e: stickslip_io::study::StudyError) -> PyErr {
    StudyError::new_err(e.to_string())
}

#[pymethods]
impl PyStudy {
    /// Read and validate a study file (errors as the command line's, with line and column).
    #[staticmethod]
    fn from_toml(path: PathBuf) -> PyResult<Self> {
        guarded(|| {
            let study = IoStudy::load(&path).map_err(study_error)?;
            let text = std::fs::read_to_string(&path).map_err(|e| StudyError::new_err(e.to_string()))?;
            let table = toml::from_str(&text).map_err(|e| StudyError::new_err(e.to_string()))?;
            Ok(PyStudy { study, table })
        })
    }

    /// Validate a study given as a dict shaped like the file (`{"model": {...}, "joint":
    /// [{...}], ...}`). `path` names it in errors and anchors relative file paths (by default
    /// `<dict>` in the current folder).
    #[staticmethod]
    #[pyo3(signature = (d, path=None))]
    fn from_dict(d: &Bound<'_, PyAny>, path: Option<PathBuf>) -> PyResult<Self> {
        let table = table_from_dict(d, "")?;
        let path = path.unwrap_or_else(|| PathBuf::from("<dict>"));
        guarded(|| {
            let study = IoStudy::from_table(&table, &path).map_err(study_error)?;
            Ok(PyStudy { study, table })
        })
    }

    /// The study as a dict (a copy: change it and build a new study with `from_dict`).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        value_to_py(py, &toml::Value::Table(self.table.clone()))
    }

    /// The study as TOML text.
    fn to_toml(&self) -> PyResult<String> {
        toml::to_string(&self.table).map_err(|e| StudyError::new_err(e.to_string()))
    }

    /// Where the study comes from (a file, or the `path` given to `from_dict`).
    #[getter]
    fn path(&self) -> PathBuf {
        self.study.path.clone()
    }

    /// The force levels (N).
    #[getter]
    fn levels(&self) -> Vec<f64> {
        self.study.excitation.levels.clone()
    }

    /// Sweep the band at every force level (in parallel, as the command line). `progress`, if
    /// given, is called as `progress(level_n, fraction_done, frequency_hz)` after each
    /// converged point. Returns a dict: `columns` (those of `frf.csv`), `table` (one row per
    /// point, all levels), `levels` (per level: `level_N`, `points`, `complete`, `ending`,
    /// `newton_iterations`, `evaluations`), `outputs`, `elements`, `harmonics`.
    #[pyo3(signature = (progress=None))]
    fn _run<'py>(&self, py: Python<'py>, progress: Option<Py<PyAny>>) -> PyResult<Bound<'py, PyDict>> {
        let study = &self.study;
        // The solve runs without the GIL; the callback takes it back for each point.
        let callback_error: std::sync::Mutex<Option<PyErr>> = std::sync::Mutex::new(None);
        let runs = py.detach(|| {
            guarded(|| {
                let (model, excitation, outputs) = study.build_model().map_err(study_error)?;
                let sweeper = LevelSweeper::new(study, &model, &excitation, &outputs)
                    .map_err(|e| SolveError::new_err(format!("setting up the harmonic balance: {}", chain(&e))))?;
                // Levels are independent sweeps: solved in parallel on the thread pool, as the
                // command line does, and returned in the study's order.
                excitation
                    .levels_n
                    .par_iter()
                    .map(|&level| {
                        let mut observer = |p: &Point, done: f64| {
                            let Some(cb) = &progress else { return };
                            let mut failed = callback_error.lock().unwrap_or_else(|e| e.into_inner());
                            if failed.is_some() {
                                return;
                            }
                            let hz = p.lambda / (2.0 * std::f64::consts::PI);
                            if let Err(e) = Python::attach(|py| cb.call1(py, (level, done, hz)).map(|_| ())) {
                                *failed = Some(e);
                            }
                        };
                        sweeper
                            .run(level, &mut observer)
                            .map_err(|e| SolveError::new_err(format!("level {level} N: {}", chain(&e))))
                    })
                    .collect::<PyResult<Vec<LevelRun>>>()
            })
        })?;
        if let Some(e) = callback_error.into_inner().unwrap_or_else(|e| e.into_inner()) {
            return Err(e);
        }
        results_dict(py, &runs)
    }

    /// Steady-state time integration (Newmark, average acceleration) at `frequency_hz` and
    /// force `level_n`: the independent check of the harmonic balance. Returns a dict: `time_s`
    /// (one period), `force_N`, per output its displacement (m) in `outputs`, per element
    /// direction its displacement and force in `elements`, `periods`, `periodicity`,
    /// `dissipated_J` (per cycle).
    #[pyo3(signature = (frequency_hz, level_n, steps_per_period=256, tolerance=1e-6, max_periods=5000))]
    fn timesim<'py>(
        &self,
        py: Python<'py>,
        frequency_hz: f64,
        level_n: f64,
        steps_per_period: usize,
        tolerance: f64,
        max_periods: usize,
    ) -> PyResult<Bound<'py, PyDict>> {
        if !(level_n.is_finite() && level_n > 0.0) {
            return Err(InputError::new_err(format!("level_n must be a force > 0 N, got {level_n}")));
        }
        let study = &self.study;
        let solved = py.detach(|| {
            guarded(|| {
                study.require_penalty_contacts("the time integration").map_err(study_error)?;
                let (model, excitation, outputs) = study.build_model().map_err(study_error)?;
                let mut o =
                    SteadyStateOptions::new(frequency_hz, excitation.pattern.iter().map(|p| p * level_n).collect());
                o.steps_per_period = steps_per_period;
                o.harmonics = study.hbm.harmonics;
                o.tolerance = tolerance;
                o.max_periods = max_periods;
                o.record_dofs = (0..model.linear.n_dofs()).collect();
                let s = steady_state(&model, &o).map_err(|e| {
                    SolveError::new_err(format!("level {level_n} N at {frequency_hz} Hz: {}", chain(&e)))
                })?;
                Ok((s, outputs))
            })
        })?;
        let (s, outputs) = solved;
        let d = PyDict::new(py);
        let r = &s.records;
        d.set_item("time_s", PyArray1::from_slice(py, &r.time))?;
        d.set_item("force_N", PyArray1::from_vec(py, r.excitation.iter().map(|e| e * level_n).collect()))?;
        let outs = PyDict::new(py);
        for o in &outputs {
            let x: Vec<f64> = (0..r.time.len())
                .map(|j| o.vector.iter().zip(&r.displacement).map(|(v, dof)| v * dof[j]).sum())
                .collect();
            outs.set_item(&o.name, PyArray1::from_vec(py, x))?;
        }
        d.set_item("outputs", outs)?;
        let els = PyDict::new(py);
        for (k, name) in r.elements.names.iter().enumerate() {
            let e = PyDict::new(py);
            e.set_item("displacement_m", PyArray1::from_slice(py, &r.elements.displacement[k]))?;
            e.set_item("force_N", PyArray1::from_slice(py, &r.elements.force[k]))?;
            e.set_item("slider_velocity_m_s", PyArray1::from_slice(py, &r.elements.slider_velocity[k]))?;
            els.set_item(name, e)?;
        }
        d.set_item("elements", els)?;
        d.set_item("periods", s.periods)?;
        d.set_item("periodicity", s.periodicity)?;
        d.set_item("dissipated_J", s.energy.dissipated())?;
        Ok(d)
    }

    /// The backbone of the study's `[nonlinear_mode]` (docs/nonlinear-modes.md). `progress`, if
    /// given, is called as `progress(modal_amplitude)` after each converged point. Returns a
    /// dict: `columns` and `table` (those of `backbone.csv`, one row per point), `bifurcations`
    /// (its folds in amplitude and branch points, as `backbone_bifurcations.csv`), `complete`
    /// (the last amplitude reached), `ending` (why the branch ended, as the command line says
    /// it), `notes`, and the linear mode's `linear_frequency_Hz` and `linear_damping_ratio`.
    /// A branch that stops short is returned with its points, `complete` false.
    #[pyo3(signature = (progress=None))]
    fn nonlinear_mode<'py>(&self, py: Python<'py>, progress: Option<Py<PyAny>>) -> PyResult<Bound<'py, PyDict>> {
        let study = &self.study;
        if study.nonlinear_mode.is_none() {
            return Err(StudyError::new_err(format!(
                "{}: the study has no [nonlinear_mode] section (keys: mode, amplitude_start, amplitude_end; see docs/nonlinear-modes.md)",
                study.path.display()
            )));
        }
        let callback_error: std::sync::Mutex<Option<PyErr>> = std::sync::Mutex::new(None);
        let solved = py.detach(|| {
            guarded(|| {
                let (model, _, outputs) = study.build_model().map_err(study_error)?;
                let mut observer = |p: &Point, _: f64| {
                    let Some(cb) = &progress else { return };
                    let mut failed = callback_error.lock().unwrap_or_else(|e| e.into_inner());
                    if failed.is_none() {
                        if let Err(e) = Python::attach(|py| cb.call1(py, (10f64.powf(p.lambda),)).map(|_| ())) {
                            *failed = Some(e);
                        }
                    }
                };
                let result =
                    run_nonlinear_mode(study, &model, &outputs, &mut observer).expect("the section is present");
                let (backbone, names) =
                    result.map_err(|e| SolveError::new_err(format!("nonlinear mode: {}", chain(&e))))?;
                let joints: Vec<String> = model.elements.iter().map(|e| e.name.clone()).collect();
                Ok((backbone, names, joints))
            })
        })?;
        if let Some(e) = callback_error.into_inner().unwrap_or_else(|e| e.into_inner()) {
            return Err(e);
        }
        let (backbone, names, joints) = solved;
        let harmonics = study.hbm.harmonics;
        let columns = backbone_columns(&joints, &names, harmonics);
        let rows = backbone_rows(&backbone, joints.len(), harmonics);
        let table = PyArray2::from_vec2(py, &rows).map_err(|e| SolveError::new_err(e.to_string()))?;
        let d = PyDict::new(py);
        d.set_item("columns", columns)?;
        d.set_item("table", table)?;
        let bifurcations = backbone
            .singular_points
            .iter()
            .map(|s| {
                let b = PyDict::new(py);
                b.set_item("kind", singular_kind_name(s.kind))?;
                b.set_item("modal_amplitude_m_sqrtkg", s.amplitude)?;
                b.set_item("frequency_Hz", s.omega / (2.0 * std::f64::consts::PI))?;
                b.set_item("damping_ratio", s.damping_ratio())?;
                b.set_item("located", s.located)?;
                Ok(b)
            })
            .collect::<PyResult<Vec<_>>>()?;
        d.set_item("bifurcations", bifurcations)?;
        let complete = backbone.complete();
        d.set_item("complete", complete)?;
        d.set_item("ending", backbone_ending(&backbone))?;
        d.set_item("notes", backbone.notes.clone())?;
        d.set_item("linear_frequency_Hz", backbone.linear_omega / (2.0 * std::f64::consts::PI))?;
        d.set_item("linear_damping_ratio", backbone.linear_damping_ratio)?;
        Ok(d)
    }

    fn __repr__(&self) -> String {
        format!("Study({:?})", self.study.path.display().to_string())
    }
}

/// The runs of a study as plain data: the `frf.csv` table (same columns, same numbers) and
/// how each level ended.
pub(crate) fn results_dict<'py>(py: Python<'py>, runs: &[LevelRun]) -> PyResult<Bound<'py, PyDict>> {
    let levels: Vec<&LevelResult> = runs.iter().map(|r| &r.result).collect();
    let d = PyDict::new(py);
    let (columns, table) = frf_table(py, &levels)?;
    d.set_item("columns", columns)?;
    d.set_item("table", table)?;
    let info = runs
        .iter()
        .map(|r| {
            let l = PyDict::new(py);
            l.set_item("level_N", r.result.level_n)?;
            l.set_item("points", r.result.points.len())?;
            l.set_item("complete", r.is_complete())?;
            l.set_item("ending", r.ending())?;
            l.set_item("newton_iterations", r.newton_iterations)?;
            l.set_item("evaluations", r.evaluations)?;
            l.set_item("sweep_s", r.seconds.sweep)?;
            l.set_item("located_peaks_s", r.seconds.peaks)?;
            l.set_item("located_bifurcations_s", r.seconds.bifurcations)?;
            Ok(l)
        })
        .collect::<PyResult<Vec<_>>>()?;
    d.set_item("levels", info)?;
    let names = |p: &PointRecord| -> (Vec<String>, Vec<String>, usize) {
        (
            p.outputs.iter().map(|o| o.name.clone()).collect(),
            p.elements.iter().map(|e| e.name.clone()).collect(),
            p.outputs.first().map_or(0, |o| o.harmonics.len().saturating_sub(1)),
        )
    };
    let template = levels.iter().flat_map(|l| l.points.first()).next().cloned().unwrap_or_default();
    let (outputs, elements, harmonics) = names(&template);
    d.set_item("outputs", outputs)?;
    d.set_item("elements", elements)?;
    d.set_item("harmonics", harmonics)?;
    Ok(d)
}

/// The `frf.csv` columns and rows of `levels` (one row per point, all levels in order).
pub(crate) fn frf_table<'py>(
    py: Python<'py>,
    levels: &[&LevelResult],
) -> PyResult<(Vec<String>, Bound<'py, PyArray2<f64>>)> {
    let template = levels.iter().flat_map(|l| l.points.first()).next().cloned().unwrap_or_default();
    let columns = frf_columns(&template);
    let rows: Vec<Vec<f64>> = levels.iter().flat_map(|l| l.points.iter().map(|p| frf_row(l.level_n, p))).collect();
    let table = if rows.is_empty() {
        PyArray2::zeros(py, [0, columns.len()], false)
    } else {
        PyArray2::from_vec2(py, &rows).map_err(|e| SolveError::new_err(format!("points of different shapes: {e}")))?
    };
    Ok((columns, table))
}
