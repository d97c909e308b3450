//! Python bindings (`rvdyn._core`), compiled only with the `python` feature.
//!
//! Thin by rule: argument conversion, shape and finiteness checks, broadcasting, GIL release and
//! result packing live here; every number is computed by the core. Errors go through
//! [`errors`], the one place that maps [`crate::RvdynError`] to Python exceptions.
//!
//! Each submodule has a `register(m)` function that adds its classes and functions to the
//! module; a new submodule (e.g. `simulate`) adds `mod simulate;` and one `register` line in
//! [`rvdyn_core`].

mod contact;
mod errors;
mod geometry;
mod kinematics;
mod scene;
mod simulate;

use numpy::ndarray::{ArrayD, IxDyn};
use numpy::{AllowTypeChange, IntoPyArray, PyArrayLikeDyn};
use pyo3::prelude::*;
use pyo3::types::PyFloat;

pub(crate) use errors::{parameter_error, with_context};

/// Any float-convertible Python value: a float, a sequence or a numpy array of any shape.
pub(crate) type FloatArray<'py> = PyArrayLikeDyn<'py, f64, AllowTypeChange>;

/// An input array copied out of Python (so the GIL can be released while the core runs), with
/// its shape; every value has been checked to be finite.
pub(crate) struct Input {
    pub shape: Vec<usize>,
    pub values: Vec<f64>,
}

impl Input {
    /// Copy `array` (any layout) in logical order, rejecting NaN and infinity with a
    /// `ParameterError` that names the argument, its unit and the first bad element.
    pub fn finite(name: &str, unit: &str, array: &FloatArray<'_>) -> PyResult<Self> {
        let view = array.as_array();
        let shape = view.shape().to_vec();
        let values: Vec<f64> = view.iter().copied().collect();
        if let Some((index, bad)) = values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            let at = if shape.is_empty() {
                String::new()
            } else {
                format!(" at flat index {index}")
            };
            return Err(parameter_error(format!(
                "{name} must contain only finite numbers [{unit}], got {bad}{at}; remove NaN \
                 and infinite values"
            )));
        }
        Ok(Self { shape, values })
    }
}

/// Several inputs broadcast to one shape (numpy rules). Scalars are not expanded.
pub(crate) struct Broadcast {
    pub shape: Vec<usize>,
    pub len: usize,
    columns: Vec<Column>,
}

enum Column {
    Scalar(f64),
    Full(Vec<f64>),
}

impl Broadcast {
    /// Broadcast named inputs together; a `ParameterError` names the shapes that do not fit.
    pub fn new(inputs: Vec<(&str, Input)>) -> PyResult<Self> {
        let mut shape: Vec<usize> = Vec::new();
        for (name, input) in &inputs {
            shape = broadcast_pair(&shape, &input.shape).ok_or_else(|| {
                let all: Vec<String> = inputs
                    .iter()
                    .map(|(n, i)| format!("{n} {}", shape_str(&i.shape)))
                    .collect();
                parameter_error(format!(
                    "cannot broadcast {name} {} with the other inputs ({}): give arrays of the \
                     same shape, or scalars",
                    shape_str(&input.shape),
                    all.join(", ")
                ))
            })?;
        }
        let len = shape.iter().product();
        let mut columns = Vec::with_capacity(inputs.len());
        for (name, input) in inputs {
            if input.values.len() == 1 {
                columns.push(Column::Scalar(input.values[0]));
            } else if input.shape == shape {
                columns.push(Column::Full(input.values));
            } else {
                let view =
                    numpy::ndarray::ArrayViewD::from_shape(IxDyn(&input.shape), &input.values)
                        .map_err(|e| parameter_error(format!("{name}: {e}")))?;
                let wide = view.broadcast(IxDyn(&shape)).ok_or_else(|| {
                    parameter_error(format!("cannot broadcast {name} to {}", shape_str(&shape)))
                })?;
                columns.push(Column::Full(wide.iter().copied().collect()));
            }
        }
        Ok(Self {
            shape,
            len,
            columns,
        })
    }

    /// Value of input `column` at flat output index `i`.
    #[inline]
    pub fn get(&self, column: usize, i: usize) -> f64 {
        match &self.columns[column] {
            Column::Scalar(v) => *v,
            Column::Full(values) => values[i],
        }
    }
}

/// Numpy broadcasting of two shapes; `None` if incompatible.
fn broadcast_pair(a: &[usize], b: &[usize]) -> Option<Vec<usize>> {
    let n = a.len().max(b.len());
    let mut out = vec![0; n];
    for k in 0..n {
        let da = if k < n - a.len() {
            1
        } else {
            a[k - (n - a.len())]
        };
        let db = if k < n - b.len() {
            1
        } else {
            b[k - (n - b.len())]
        };
        out[k] = match (da, db) {
            (x, y) if x == y => x,
            (1, y) => y,
            (x, 1) => x,
            _ => return None,
        };
    }
    Some(out)
}

/// A shape written as Python does: `()`, `(3,)`, `(2, 4)`.
pub(crate) fn shape_str(shape: &[usize]) -> String {
    match shape {
        [] => "()".into(),
        [n] => format!("({n},)"),
        _ => {
            let parts: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
            format!("({})", parts.join(", "))
        }
    }
}

/// Hand `values` (row-major, `shape`) to Python: a float for a 0-d shape, otherwise a numpy
/// array that takes ownership of the vector (no copy).
pub(crate) fn output<'py>(
    py: Python<'py>,
    shape: &[usize],
    values: Vec<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    if shape.is_empty() {
        let v = values.first().copied().unwrap_or(f64::NAN);
        return Ok(PyFloat::new(py, v).into_any());
    }
    let array = ArrayD::from_shape_vec(IxDyn(shape), values)
        .map_err(|e| parameter_error(format!("internal shape error: {e}")))?;
    Ok(array.into_pyarray(py).into_any())
}

/// A 1-D numpy array of length 2 from a point or vector.
pub(crate) fn vec2<'py>(py: Python<'py>, v: [f64; 2]) -> Bound<'py, PyAny> {
    numpy::PyArray1::from_vec(py, v.to_vec()).into_any()
}

/// Read a point or vector given as a sequence or array of shape `(2,)` [unit], finite.
pub(crate) fn point2(name: &str, unit: &str, value: &FloatArray<'_>) -> PyResult<[f64; 2]> {
    let input = Input::finite(name, unit, value)?;
    if input.shape != [2] {
        return Err(parameter_error(format!(
            "{name} must be a point (x, y) [{unit}] of shape (2,), got shape {}",
            shape_str(&input.shape)
        )));
    }
    Ok([input.values[0], input.values[1]])
}

/// A tooth or pin count from Python: a whole number in 0..=u32::MAX (the core checks the
/// minimum and names the rule).
pub(crate) fn count(name: &str, value: i64) -> PyResult<u32> {
    u32::try_from(value).map_err(|_| {
        parameter_error(format!(
            "{name} must be a positive whole number (a tooth or pin count), got {value}"
        ))
    })
}

/// A class defined in Python (`rvdyn._types`), used to pack structured results.
pub(crate) fn python_type<'py>(py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
    py.import("rvdyn._types")?.getattr(name)
}

/// The compiled part of rvdyn. Import `rvdyn`, not this module: the package re-exports
/// everything with the Python-side types and exceptions.
#[pymodule]
#[pyo3(name = "_core")]
fn rvdyn_core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    geometry::register(m)?;
    contact::register(m)?;
    kinematics::register(m)?;
    scene::register(m)?;
    simulate::register(m)?;
    Ok(())
}
