//! The `stickslip` Python module's native part (`stickslip._stickslip`): studies run as data,
//! parameter designs and their sample runs, modes and harmonic extraction on NumPy arrays.
//! The Python layer (`python/stickslip`) adds result tables, the schedulers and the cache.
//!
//! Every solve runs without the GIL; every error becomes an exception of this module with the
//! command line's message, and a panic is caught and raised as `Error` before it can reach the
//! interpreter.

mod convert;
mod params;
mod study;
mod tools;

use pyo3::prelude::*;

#[pymodule]
fn _stickslip(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("Error", py.get_type::<convert::Error>())?;
    m.add("StudyError", py.get_type::<convert::StudyError>())?;
    m.add("SolveError", py.get_type::<convert::SolveError>())?;
    m.add("ParamError", py.get_type::<convert::ParamError>())?;
    m.add("InputError", py.get_type::<convert::InputError>())?;
    m.add_class::<study::PyStudy>()?;
    m.add_class::<params::PyParamDesign>()?;
    m.add_function(wrap_pyfunction!(tools::modes, m)?)?;
    m.add_function(wrap_pyfunction!(tools::reduce, m)?)?;
    m.add_function(wrap_pyfunction!(tools::extract, m)?)?;
    m.add("SUMMARY_COLUMNS", stickslip_io::params::files::SUMMARY_COLUMNS.to_vec())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
