//! numpy in, numpy and scipy.sparse out.
//!
//! Inputs are taken through `numpy.ascontiguousarray` (so lists, tuples and arrays of
//! any numeric dtype work) and their shape is checked; a wrong shape is an
//! `ArgumentError` that names the argument and the shape expected. Outputs are new
//! arrays the caller owns; matrices are `scipy.sparse.csr_matrix`.

use numpy::{PyArray1, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::error::argument;

/// `obj` as a C-contiguous numpy array of `dtype` ("float64" or "int64").
fn contiguous<'py, T: numpy::Element>(
    obj: &Bound<'py, PyAny>,
    dtype: &str,
    what: &str,
) -> PyResult<Bound<'py, PyArrayDyn<T>>> {
    let py = obj.py();
    let kwargs = PyDict::new(py);
    kwargs.set_item("dtype", dtype)?;
    let array = py
        .import("numpy")?
        .getattr("ascontiguousarray")?
        .call((obj,), Some(&kwargs))
        .map_err(|e| {
            argument(
                format!("{what}: cannot be read as an array of {dtype} ({e})"),
                "pass a numpy array or a list of numbers",
            )
        })?;
    array
        .cast_into::<PyArrayDyn<T>>()
        .map_err(|_| argument(format!("{what} is no {dtype} array"), "pass a numpy array"))
}

/// A 1-D array's values (a scalar counts as one value only where `what` allows it).
fn vector<T: numpy::Element + Copy>(
    obj: &Bound<'_, PyAny>,
    dtype: &str,
    what: &str,
) -> PyResult<Vec<T>> {
    let a = contiguous::<T>(obj, dtype, what)?;
    if a.ndim() != 1 {
        return Err(argument(
            format!("{what} has shape {:?}; a 1-D array is expected", a.shape()),
            "pass one value per entry (numpy.ravel flattens)",
        ));
    }
    Ok(a.readonly().as_slice()?.to_vec())
}

/// A 2-D array with `cols` columns (any of `cols`), row by row, and its column count.
fn matrix<T: numpy::Element + Copy>(
    obj: &Bound<'_, PyAny>,
    dtype: &str,
    cols: &[usize],
    what: &str,
) -> PyResult<(Vec<T>, usize)> {
    let a = contiguous::<T>(obj, dtype, what)?;
    let shape = a.shape().to_vec();
    let expected = cols
        .iter()
        .map(|c| format!("(m, {c})"))
        .collect::<Vec<_>>()
        .join(" or ");
    if shape.len() != 2 || !cols.contains(&shape[1]) {
        return Err(argument(
            format!("{what} has shape {shape:?}; {expected} is expected"),
            "one row per item; transpose an array given column by column (a.T)",
        ));
    }
    Ok((a.readonly().as_slice()?.to_vec(), shape[1]))
}

/// Doubles, any length.
pub fn f64s(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<f64>> {
    vector::<f64>(obj, "float64", what)
}

/// Points as an (n, 3) array.
pub fn points(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<[f64; 3]>> {
    let (v, _) = matrix::<f64>(obj, "float64", &[3], what)?;
    Ok(v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
}

/// Signed integers, any length.
pub fn i64s(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<i64>> {
    vector::<i64>(obj, "int64", what)
}

/// Non-negative indices, any length.
pub fn indices(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<usize>> {
    i64s(obj, what)?
        .into_iter()
        .map(|v| index(v, what))
        .collect()
}

/// Rows of non-negative indices with `cols` columns (any of them): the flat values and
/// the column count.
pub fn index_rows(
    obj: &Bound<'_, PyAny>,
    cols: &[usize],
    what: &str,
) -> PyResult<(Vec<usize>, usize)> {
    let (v, c) = matrix::<i64>(obj, "int64", cols, what)?;
    let v = v
        .into_iter()
        .map(|v| index(v, what))
        .collect::<PyResult<_>>()?;
    Ok((v, c))
}

fn index(v: i64, what: &str) -> PyResult<usize> {
    usize::try_from(v).map_err(|_| {
        argument(
            format!("{what} holds {v}, a negative index"),
            "indices are 0-based",
        )
    })
}

/// A new 1-D array.
pub fn array<T: numpy::Element>(py: Python<'_>, v: Vec<T>) -> Py<PyAny> {
    PyArray1::from_vec(py, v).into_any().unbind()
}

/// A new (n, 3) array of points.
pub fn points_array(py: Python<'_>, v: &[[f64; 3]]) -> PyResult<Py<PyAny>> {
    let flat: Vec<f64> = v.iter().flatten().copied().collect();
    Ok(PyArray1::from_vec(py, flat)
        .reshape([v.len(), 3])?
        .into_any()
        .unbind())
}

/// `scipy.sparse.csr_matrix` of shape `(rows, cols)` from CSR arrays.
pub fn csr(
    py: Python<'_>,
    shape: (usize, usize),
    offsets: Vec<usize>,
    columns: Vec<usize>,
    values: Vec<f64>,
) -> PyResult<Py<PyAny>> {
    let to_i64 = |v: Vec<usize>| v.into_iter().map(|x| x as i64).collect::<Vec<i64>>();
    let data = (
        PyArray1::from_vec(py, values),
        PyArray1::from_vec(py, to_i64(columns)),
        PyArray1::from_vec(py, to_i64(offsets)),
    );
    Ok(py
        .import("scipy.sparse")?
        .getattr("csr_matrix")?
        .call1((data, shape))?
        .unbind())
}

/// `scipy.sparse.csr_matrix` of shape `(rows, cols)` from triplets (repeats summed).
pub fn csr_from_triplets(
    py: Python<'_>,
    shape: (usize, usize),
    triplets: impl Iterator<Item = (usize, usize, f64)>,
) -> PyResult<Py<PyAny>> {
    let (mut r, mut c, mut v) = (Vec::new(), Vec::new(), Vec::new());
    for (i, j, x) in triplets {
        r.push(i as i64);
        c.push(j as i64);
        v.push(x);
    }
    let ij = (PyArray1::from_vec(py, r), PyArray1::from_vec(py, c));
    let data = (PyArray1::from_vec(py, v), ij);
    let coo = py
        .import("scipy.sparse")?
        .getattr("coo_matrix")?
        .call1((data, shape))?;
    Ok(coo.call_method0("tocsr")?.unbind())
}

/// `(index, value)` pairs summed into a dense vector of length `n`.
pub fn dense(py: Python<'_>, n: usize, pairs: &[(usize, f64)]) -> Py<PyAny> {
    let mut v = vec![0.0; n];
    for &(i, x) in pairs {
        v[i] += x;
    }
    array(py, v)
}
