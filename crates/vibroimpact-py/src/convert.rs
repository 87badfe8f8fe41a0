//! Conversions between Python and the library: JSON documents to Python
//! objects, arrays, and library errors to Python exceptions.

use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use pyo3::IntoPyObjectExt;
use serde_json::Value;
use vibroimpact::integrate::Method;

use crate::VibroimpactError;

/// A JSON document as Python objects (dicts, lists, floats, ints, str,
/// bool, None); the Python package turns numeric lists into arrays.
pub fn to_python<'py>(py: Python<'py>, v: &Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => b.into_bound_py_any(py)?,
        Value::Number(n) => match (n.as_i64(), n.as_f64()) {
            (Some(i), _) if !n.is_f64() => i.into_bound_py_any(py)?,
            (_, Some(x)) => x.into_bound_py_any(py)?,
            _ => n.to_string().into_bound_py_any(py)?,
        },
        Value::String(s) => s.into_bound_py_any(py)?,
        Value::Array(a) => {
            let items: Vec<Bound<'py, PyAny>> = a
                .iter()
                .map(|x| to_python(py, x))
                .collect::<PyResult<_>>()?;
            PyList::new(py, items)?.into_any()
        }
        Value::Object(o) => {
            let d = PyDict::new(py);
            for (k, x) in o {
                d.set_item(k, to_python(py, x)?)?;
            }
            d.into_any()
        }
    })
}

/// A serialisable result as a Python dict.
pub fn document<'py, T: serde::Serialize>(
    py: Python<'py>,
    value: &T,
) -> PyResult<Bound<'py, PyDict>> {
    let v = serde_json::to_value(value)
        .map_err(|e| VibroimpactError::new_err(format!("cannot convert the result: {e}")))?;
    Ok(to_python(py, &v)?.cast_into::<PyDict>()?)
}

/// A 1-D float array.
pub fn array1<'py>(py: Python<'py>, v: Vec<f64>) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_vec(py, v)
}

/// A row-major `rows × cols` float array.
pub fn array2<'py>(
    py: Python<'py>,
    v: Vec<f64>,
    rows: usize,
    cols: usize,
) -> PyResult<Bound<'py, PyAny>> {
    Ok(PyArray1::from_vec(py, v).reshape([rows, cols])?.into_any())
}

/// The values of a float array argument (`name` in messages); NaN and
/// infinities are rejected.
pub fn floats(a: &PyReadonlyArray1<'_, f64>, name: &str) -> PyResult<Vec<f64>> {
    let s = a
        .as_slice()
        .map_err(|e| PyValueError::new_err(format!("{name}: {e}")))?;
    if let Some(i) = s.iter().position(|x| !x.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "{name}[{i}] = {}: must be finite",
            s[i]
        )));
    }
    Ok(s.to_vec())
}

/// Bad input: `ValueError` with the library's message.
pub fn value_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// A numerical failure: `VibroimpactError` with the library's message.
pub fn numerical_error(e: impl std::fmt::Display) -> PyErr {
    VibroimpactError::new_err(e.to_string())
}

/// A rayon pool of `threads` threads (None: one per core) for the calls
/// that run cells or values in parallel.
pub fn thread_pool(threads: Option<usize>) -> PyResult<rayon::ThreadPool> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map_err(numerical_error)
}

/// The integration method named `name`.
pub(crate) fn method(name: &str) -> PyResult<Method> {
    match name {
        "dop853" => Ok(Method::Dop853),
        "dopri5" => Ok(Method::Dopri5),
        "rodas" => Ok(Method::Rodas),
        "auto" => Ok(Method::Auto),
        other => Err(value_error(format!(
            "method = {other:?}: give \"dop853\", \"dopri5\", \"rodas\" or \"auto\""
        ))),
    }
}

/// Sampled states (`rows` of `[u_1..u_N, v_1..v_N]`) as two `rows × N`
/// arrays: displacements and velocities.
pub(crate) fn split_states<'py>(
    py: Python<'py>,
    states: &[f64],
    rows: usize,
    n: usize,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let (mut u, mut v) = (Vec::with_capacity(rows * n), Vec::with_capacity(rows * n));
    for row in states.chunks_exact(2 * n).take(rows) {
        u.extend_from_slice(&row[..n]);
        v.extend_from_slice(&row[n..]);
    }
    Ok((array2(py, u, rows, n)?, array2(py, v, rows, n)?))
}
