//! Functions on NumPy inputs: modes and reductions of a pair of matrices, harmonics of time
//! records.

use numpy::{PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use stickslip_core::model::{Damping, DofLabel, LinearModel, Matrix};
use stickslip_core::signal::harmonics::{extract as extract_blocks, SyncOptions};
use stickslip_fe::eigen::EigenOptions;
use stickslip_fe::reduction::{self, ReductionOptions, Release};

use crate::convert::{chain, guarded, InputError, SolveError};

/// A float64 array, with the argument's name in the error when it is not one.
fn matrix<'py>(a: &Bound<'py, PyAny>, name: &str) -> PyResult<PyReadonlyArray2<'py, f64>> {
    a.extract::<PyReadonlyArray2<'py, f64>>().map_err(|_| {
        let got = a.getattr("dtype").map(|d| format!("an array of dtype {d}")).unwrap_or_else(|_| {
            a.get_type().name().map(|n| format!("a {n}")).unwrap_or_else(|_| "another type".into())
        });
        let shape = a.getattr("shape").map(|s| format!(" and shape {s}")).unwrap_or_default();
        InputError::new_err(format!("{name}: expected a 2-D float64 array, got {got}{shape}"))
    })
}

fn vector<'py>(a: &Bound<'py, PyAny>, name: &str) -> PyResult<PyReadonlyArray1<'py, f64>> {
    a.extract::<PyReadonlyArray1<'py, f64>>().map_err(|_| {
        let got = a.getattr("dtype").map(|d| format!("an array of dtype {d}")).unwrap_or_else(|_| {
            a.get_type().name().map(|n| format!("a {n}")).unwrap_or_else(|_| "another type".into())
        });
        let shape = a.getattr("shape").map(|s| format!(" and shape {s}")).unwrap_or_default();
        InputError::new_err(format!("{name}: expected a 1-D float64 array, got {got}{shape}"))
    })
}

/// `mass` and `stiffness` as dense matrices of the same square size (at least 1x1).
fn square_pair(mass: &Bound<'_, PyAny>, stiffness: &Bound<'_, PyAny>) -> PyResult<(faer::Mat<f64>, faer::Mat<f64>)> {
    let (m, k) = (matrix(mass, "mass")?, matrix(stiffness, "stiffness")?);
    let n = m.shape()[0];
    for (name, a) in [("mass", &m), ("stiffness", &k)] {
        let s = a.shape();
        if s[0] != s[1] || s[0] != n {
            return Err(InputError::new_err(format!(
                "{name}: expected a square {n}x{n} array (the size of mass), got shape ({}, {})",
                s[0], s[1]
            )));
        }
        if n == 0 {
            return Err(InputError::new_err(format!("{name}: the model has no DOF")));
        }
    }
    let to_mat = |a: &PyReadonlyArray2<f64>| {
        let v = a.as_array();
        faer::Mat::from_fn(n, n, |i, j| v[(i, j)])
    };
    Ok((to_mat(&m), to_mat(&k)))
}

fn to_numpy<'py>(py: Python<'py>, a: &faer::Mat<f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    if a.nrows() == 0 || a.ncols() == 0 {
        return Ok(PyArray2::zeros(py, [a.nrows(), a.ncols()], false));
    }
    let rows: Vec<Vec<f64>> = (0..a.nrows()).map(|i| (0..a.ncols()).map(|j| a[(i, j)]).collect()).collect();
    Ok(PyArray2::from_vec2(py, &rows)?)
}

/// Reduction of `(M, K)` to the physical DOFs `retained` (indices) plus `modes` modal
/// coordinates (paper Section 3.3), as `[reduction]` does in a study: `method` "cb"
/// (Craig-Bampton: constraint modes, Eqs. 3-4, + fixed-interface modes), "free" (the paper's
/// variant: free modes cleaned on the retained DOFs, Eq. 5) or "enriched" ("free" plus the
/// `release_modes` lowest modes with the `releases` removed from K: a list of
/// `(direction, stiffness)`, `stiffness · d dᵀ` being the connector a joint replaces).
/// Returns a dict: `mass` and `stiffness` (`Tᵀ M T`, `Tᵀ K T`), `basis` (`T`, full DOFs x
/// reduced DOFs, with `U = T q`), `retained` (reduced-DOF order) and `frequencies_hz` of the
/// modes put in the basis.
#[pyfunction]
#[pyo3(signature = (mass, stiffness, retained, modes, method="cb", releases=None, release_modes=0))]
#[allow(clippy::too_many_arguments)]
pub fn reduce<'py>(
    py: Python<'py>,
    mass: &Bound<'py, PyAny>,
    stiffness: &Bound<'py, PyAny>,
    retained: Vec<usize>,
    modes: usize,
    method: &str,
    releases: Option<Vec<(Bound<'py, PyAny>, f64)>>,
    release_modes: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let (m, k) = square_pair(mass, stiffness)?;
    let n = m.nrows();
    let releases = releases
        .unwrap_or_default()
        .iter()
        .enumerate()
        .map(|(i, (d, stiffness))| {
            let name = format!("releases[{i}]");
            let direction = vector(d, &name)?.as_array().to_vec();
            if direction.len() != n {
                return Err(InputError::new_err(format!(
                    "{name}: direction has {} values, expected {n} (one per DOF)",
                    direction.len()
                )));
            }
            Ok(Release { name, direction, stiffness: *stiffness })
        })
        .collect::<PyResult<Vec<_>>>()?;
    match method {
        "cb" | "free" if !releases.is_empty() || release_modes > 0 => {
            return Err(InputError::new_err(format!(
                "releases and release_modes go with method=\"enriched\", got method={method:?}"
            )))
        }
        "cb" | "free" => {}
        "enriched" if releases.is_empty() || release_modes == 0 => {
            return Err(InputError::new_err(
                "method=\"enriched\" needs releases (a list of (direction, stiffness)) and release_modes >= 1",
            ))
        }
        "enriched" => {}
        other => {
            return Err(InputError::new_err(format!(
                "method: unknown method {other:?}, expected \"cb\" (Craig-Bampton), \"free\" (free modes, the paper's) or \"enriched\""
            )))
        }
    }
    let method = method.to_string();
    let red = py.detach(|| {
        guarded(|| {
            let dofs = (0..n).map(|i| DofLabel::named(format!("{}", i + 1))).collect();
            let model = LinearModel::new(Matrix::Dense(m), Matrix::Dense(k), Damping::None, dofs, Vec::new())
                .map_err(|e| InputError::new_err(chain(&e)))?;
            let options = ReductionOptions { retained, modes, band: None, eigen: EigenOptions::default() };
            match method.as_str() {
                "cb" => reduction::craig_bampton(&model, &options),
                "free" => reduction::free_modes(&model, &options),
                _ => reduction::enriched(&model, &options, &releases, release_modes),
            }
            .map_err(|e| SolveError::new_err(chain(&e)))
        })
    })?;
    let d = PyDict::new(py);
    d.set_item("mass", to_numpy(py, &red.model.mass.to_dense())?)?;
    d.set_item("stiffness", to_numpy(py, &red.model.stiffness.to_dense())?)?;
    d.set_item("basis", to_numpy(py, &red.basis)?)?;
    d.set_item("retained", red.retained.clone())?;
    d.set_item("frequencies_hz", PyArray1::from_vec(py, red.basis_frequencies_hz.clone()))?;
    Ok(d)
}

/// Frequencies (Hz) and mode shapes (one column per mode).
type FrequenciesAndShapes<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray2<f64>>);

/// Undamped modes of `(K, M)` by a dense generalised symmetric eigensolution (for small or
/// reduced models): returns `(frequencies_hz, shapes)` with shapes mass-normalised, one column
/// per mode, lowest first; `count` keeps the lowest `count` modes.
#[pyfunction]
#[pyo3(signature = (mass, stiffness, count=None))]
pub fn modes<'py>(
    py: Python<'py>,
    mass: &Bound<'py, PyAny>,
    stiffness: &Bound<'py, PyAny>,
    count: Option<usize>,
) -> PyResult<FrequenciesAndShapes<'py>> {
    let (m, k) = square_pair(mass, stiffness)?;
    let n = m.nrows();
    let result = py.detach(|| {
        guarded(|| {
            let dofs = (0..n).map(|i| DofLabel::named(format!("{}", i + 1))).collect();
            let model = LinearModel::new(Matrix::Dense(m), Matrix::Dense(k), Damping::None, dofs, Vec::new())
                .map_err(|e| InputError::new_err(chain(&e)))?;
            model.dense_modes().map_err(|e| SolveError::new_err(chain(&e)))
        })
    })?;
    let keep = count.unwrap_or(n).min(n);
    let f = result.frequencies_hz()[..keep].to_vec();
    let shapes: Vec<Vec<f64>> = (0..n).map(|i| (0..keep).map(|r| result.shapes[(i, r)]).collect()).collect();
    let shapes = if keep == 0 { PyArray2::zeros(py, [n, 0], false) } else { PyArray2::from_vec2(py, &shapes)? };
    Ok((PyArray1::from_vec(py, f), shapes))
}

/// Harmonics 1..N of time records, synchronised on the reference channel's cycles (what
/// `stickslip extract` does to a record): `reference` and each of `responses` (a dict of
/// name -> samples) sampled at `sample_rate_hz`. Returns a dict: `frequency_hz`, `start_s`,
/// `end_s` (one value per block), `reference` and `responses[name]` as Fourier coefficients
/// `[c0, c1, s1, ..., cN, sN]` (one row per block).
#[pyfunction]
#[pyo3(signature = (reference, responses, sample_rate_hz, harmonics=7, cycles_per_block=1, skip_cycles=0))]
pub fn extract<'py>(
    py: Python<'py>,
    reference: &Bound<'py, PyAny>,
    responses: &Bound<'py, PyDict>,
    sample_rate_hz: f64,
    harmonics: usize,
    cycles_per_block: usize,
    skip_cycles: usize,
) -> PyResult<Bound<'py, PyDict>> {
    if !(sample_rate_hz.is_finite() && sample_rate_hz > 0.0) {
        return Err(InputError::new_err(format!("sample_rate_hz must be > 0 Hz, got {sample_rate_hz}")));
    }
    let reference = vector(reference, "reference")?.as_array().to_vec();
    let mut channels: Vec<(String, Vec<f64>)> = Vec::new();
    for (name, samples) in responses.iter() {
        let name: String =
            name.extract().map_err(|_| InputError::new_err("responses: keys must be channel names (str)"))?;
        let v = vector(&samples, &format!("responses[{name:?}]"))?.as_array().to_vec();
        channels.push((name, v));
    }
    for (name, v) in
        std::iter::once(("reference".to_string(), &reference)).chain(channels.iter().map(|(n, v)| (n.clone(), v)))
    {
        if let Some((i, x)) = v.iter().enumerate().find(|(_, x)| !x.is_finite()) {
            return Err(InputError::new_err(format!("{name}: sample {i} is {x}, not a finite number")));
        }
    }
    let options = SyncOptions { n_harmonics: harmonics, cycles_per_block, skip_cycles };
    let blocks = py.detach(|| {
        guarded(|| {
            let refs: Vec<(&str, &[f64])> = channels.iter().map(|(n, v)| (n.as_str(), v.as_slice())).collect();
            extract_blocks(&reference, &refs, sample_rate_hz, &options).map_err(|e| SolveError::new_err(chain(&e)))
        })
    })?;
    let d = PyDict::new(py);
    let column =
        |f: &dyn Fn(&stickslip_core::signal::harmonics::Block) -> f64| -> Vec<f64> { blocks.iter().map(f).collect() };
    d.set_item("frequency_hz", PyArray1::from_vec(py, column(&|b| b.frequency_hz)))?;
    d.set_item("start_s", PyArray1::from_vec(py, column(&|b| b.start_s)))?;
    d.set_item("end_s", PyArray1::from_vec(py, column(&|b| b.end_s)))?;
    let coeffs = |rows: Vec<Vec<f64>>| -> PyResult<Bound<'py, PyArray2<f64>>> {
        if rows.is_empty() {
            Ok(PyArray2::zeros(py, [0, 2 * harmonics + 1], false))
        } else {
            Ok(PyArray2::from_vec2(py, &rows)?)
        }
    };
    d.set_item("reference", coeffs(blocks.iter().map(|b| b.reference.clone()).collect())?)?;
    let r = PyDict::new(py);
    for (c, (name, _)) in channels.iter().enumerate() {
        r.set_item(name, coeffs(blocks.iter().map(|b| b.responses[c].clone()).collect())?)?;
    }
    d.set_item("responses", r)?;
    Ok(d)
}
