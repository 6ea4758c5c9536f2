//! Between Python values and the Rust side: dictionaries to TOML tables and back, errors to
//! exceptions, panics caught before they reach the interpreter.

use std::panic::{catch_unwind, AssertUnwindSafe};

use pyo3::exceptions::PyException;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use toml::{Table, Value};

pyo3::create_exception!(_stickslip, Error, PyException, "Base class of every stickslip error.");
pyo3::create_exception!(
    _stickslip,
    StudyError,
    Error,
    "A study that does not validate or whose model cannot be built."
);
pyo3::create_exception!(
    _stickslip,
    SolveError,
    Error,
    "The harmonic balance, the time integration or a signal analysis failed."
);
pyo3::create_exception!(
    _stickslip,
    ParamError,
    Error,
    "A parameter study that cannot be set up: key, range, design, files."
);
pyo3::create_exception!(_stickslip, InputError, Error, "An argument of the wrong type, shape or value.");

/// An error and its causes, as the command line prints them (`a: b: c`).
pub fn chain(e: &(dyn std::error::Error + 'static)) -> String {
    let mut text = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        let s_text = s.to_string();
        // thiserror messages often already include their source (`{context}: {source}`).
        if !text.ends_with(&s_text) {
            text.push_str(": ");
            text.push_str(&s_text);
        }
        source = s.source();
    }
    text
}

/// Run `f`, turning a panic into a Python exception instead of unwinding into the interpreter.
pub fn guarded<T>(f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(r) => r,
        Err(payload) => {
            let what = payload
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| payload.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_else(|| "unknown panic".into());
            Err(Error::new_err(format!("internal error (a bug; please report it with the study): {what}")))
        }
    }
}

/// A Python dict as a TOML table; `at` names the place in errors (`study.joint[0].threshold`).
pub fn table_from_dict(d: &Bound<'_, PyAny>, at: &str) -> PyResult<Table> {
    match value_from_py(d, at)? {
        Value::Table(t) => Ok(t),
        _ => Err(InputError::new_err(format!("{at}: expected a dict, got {}", type_name(d)))),
    }
}

fn type_name(v: &Bound<'_, PyAny>) -> String {
    v.get_type().name().map(|n| n.to_string()).unwrap_or_else(|_| "?".into())
}

fn value_from_py(v: &Bound<'_, PyAny>, at: &str) -> PyResult<Value> {
    // bool before int: Python's bool is an int.
    if v.is_instance_of::<PyBool>() {
        return Ok(Value::Boolean(v.extract()?));
    }
    if v.is_instance_of::<PyInt>() {
        return v
            .extract::<i64>()
            .map(Value::Integer)
            .map_err(|_| InputError::new_err(format!("{at}: the integer {v} does not fit in 64 bits")));
    }
    if v.is_instance_of::<PyFloat>() {
        return Ok(Value::Float(v.extract()?));
    }
    if v.is_instance_of::<PyString>() {
        return Ok(Value::String(v.extract()?));
    }
    if let Ok(d) = v.cast::<PyDict>() {
        let mut t = Table::new();
        for (k, x) in d.iter() {
            let Ok(key) = k.extract::<String>() else {
                return Err(InputError::new_err(format!("{at}: keys must be strings, got {} {k}", type_name(&k))));
            };
            let here = if at.is_empty() { key.clone() } else { format!("{at}.{key}") };
            t.insert(key, value_from_py(&x, &here)?);
        }
        return Ok(Value::Table(t));
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let mut a = Vec::new();
        for (i, x) in v.try_iter()?.enumerate() {
            a.push(value_from_py(&x?, &format!("{at}[{i}]"))?);
        }
        return Ok(Value::Array(a));
    }
    if v.is_none() {
        return Err(InputError::new_err(format!("{at}: None is not a value (leave the key out for its default)")));
    }
    // NumPy scalars and arrays: through their Python equivalents.
    if v.hasattr("tolist")? && v.hasattr("dtype")? {
        let kind: String = v.getattr("dtype")?.getattr("kind")?.extract()?;
        if !matches!(kind.as_str(), "f" | "i" | "u" | "b") {
            return Err(InputError::new_err(format!(
                "{at}: a NumPy value of dtype {} is not a number (expected float, int or bool)",
                v.getattr("dtype")?
            )));
        }
        return value_from_py(&v.call_method0("tolist")?, at);
    }
    Err(InputError::new_err(format!(
        "{at}: a {} cannot go into a study (expected a dict, list, str, int, float or bool)",
        type_name(v)
    )))
}

/// A TOML value as a Python value (tables as dicts, arrays as lists).
pub fn value_to_py<'py>(py: Python<'py>, v: &Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        Value::String(s) => PyString::new(py, s).into_any(),
        Value::Integer(i) => i.into_pyobject(py)?.into_any(),
        Value::Float(f) => PyFloat::new(py, *f).into_any(),
        Value::Boolean(b) => PyBool::new(py, *b).to_owned().into_any(),
        Value::Datetime(d) => PyString::new(py, &d.to_string()).into_any(),
        Value::Array(a) => {
            let items = a.iter().map(|x| value_to_py(py, x)).collect::<PyResult<Vec<_>>>()?;
            PyList::new(py, items)?.into_any()
        }
        Value::Table(t) => {
            let d = PyDict::new(py);
            for (k, x) in t {
                d.set_item(k, value_to_py(py, x)?)?;
            }
            d.into_any()
        }
    })
}
