//! Arguments and results of the bindings: numbers, counts and arrays read from Python with
//! every failure mapped to the rvdyn hierarchy, broadcasting, and output packing.
//!
//! Sizes are checked before anything is allocated: an input is copied without its zero-stride
//! (broadcast) axes, so `np.broadcast_to(x, (2**40,))` costs one value; the size of every
//! result is computed with overflow checks and its memory reserved without the aborting
//! allocation path (a `MemoryError`, as numpy raises, instead of a dead interpreter); arrays
//! with more dimensions than the numpy bindings handle (32) are a `ParameterError`.

use super::errors::{chained, parameter_error};
use crate::error::{RvdynError, try_vec};
use numpy::ndarray::{ArrayD, IxDyn, Slice};
use numpy::{
    AllowTypeChange, IntoPyArray, PyArrayDescrMethods, PyArrayLikeDyn, PyUntypedArray,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::PyFloat;

/// Most dimensions an input or a result may have (the limit of the numpy bindings; numpy 2
/// itself allows 64).
pub(crate) const MAX_NDIM: usize = 32;

/// The first `limit` characters of `repr(value)` (for messages about unreadable arguments).
pub(crate) fn short_repr(value: &Bound<'_, PyAny>, limit: usize) -> String {
    let text = value
        .repr()
        .map(|r| r.to_string())
        .unwrap_or_else(|_| "<unprintable>".into());
    if text.chars().count() <= limit {
        text
    } else {
        let head: String = text.chars().take(limit).collect();
        format!("{head}...")
    }
}

/// A Python error raised while converting an argument: a `TypeError` stays one (wrong type);
/// anything else (`OverflowError`, `ValueError` from a string, ...) becomes a
/// `ParameterError` that says what was expected, with the original chained.
fn conversion_error(py: Python<'_>, value: &Bound<'_, PyAny>, expected: &str, err: PyErr) -> PyErr {
    if err.is_instance_of::<PyTypeError>(py)
        || err.is_instance_of::<pyo3::exceptions::PyMemoryError>(py)
        || err.is_instance_of::<pyo3::exceptions::PyKeyboardInterrupt>(py)
    {
        return err;
    }
    let message = format!(
        "cannot read {} as {expected}: {}",
        short_repr(value, 40),
        err.value(py)
    );
    chained(py, RvdynError::Parameter(message), err)
}

/// A real-number argument: anything Python converts with `float()` (int, float, numpy
/// scalars). An int too large for a float is a `ParameterError`, not an `OverflowError`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Real(pub f64);

impl<'a, 'py> FromPyObject<'a, 'py> for Real {
    type Error = PyErr;

    fn extract(ob: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        match ob.extract::<f64>() {
            Ok(v) => Ok(Real(v)),
            Err(e) => Err(conversion_error(ob.py(), &ob, "a real number", e)),
        }
    }
}

/// A whole-number argument (a count): any Python or numpy integer. Its range is checked by
/// [`count`], which names the argument.
pub(crate) enum Whole {
    /// The value, if it fits in an `i64`.
    Value(i64),
    /// An integer beyond `i64`: its text and the Python error.
    TooLarge(String, PyErr),
}

impl<'a, 'py> FromPyObject<'a, 'py> for Whole {
    type Error = PyErr;

    fn extract(ob: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        match ob.extract::<i64>() {
            Ok(v) => Ok(Whole::Value(v)),
            Err(e) if e.is_instance_of::<pyo3::exceptions::PyOverflowError>(ob.py()) => {
                Ok(Whole::TooLarge(short_repr(&ob, 30), e))
            }
            Err(e) => Err(e),
        }
    }
}

impl From<i64> for Whole {
    fn from(v: i64) -> Self {
        Whole::Value(v)
    }
}

/// A tooth, pin or planet count from Python: a whole number in `0..=u32::MAX` (the core checks
/// the minimum and maximum for its use and names the rule).
pub(crate) fn count(name: &str, value: Whole) -> PyResult<u32> {
    let message = |text: &str| {
        format!("{name} must be a whole number from 0 to 4294967295 (a count), got {text}")
    };
    match value {
        Whole::Value(v) => u32::try_from(v).map_err(|_| parameter_error(message(&v.to_string()))),
        Whole::TooLarge(text, cause) => Err(Python::attach(|py| {
            chained(py, RvdynError::Parameter(message(&text)), cause)
        })),
    }
}

/// Any float-convertible Python value: a float, a sequence or a numpy array of any shape.
/// Conversion failures other than a wrong type (a string, an int beyond the float range,
/// ragged nesting) are a `ParameterError` with the numpy error chained; `None` is a
/// `TypeError` (numpy would read it as NaN).
pub(crate) struct FloatArray<'py>(PyArrayLikeDyn<'py, f64, AllowTypeChange>);

impl<'a, 'py> FromPyObject<'a, 'py> for FloatArray<'py> {
    type Error = PyErr;

    fn extract(ob: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        if ob.is_none() {
            return Err(PyTypeError::new_err(
                "expected a number or an array of numbers, got None",
            ));
        }
        if ob.is_instance_of::<pyo3::types::PyString>()
            || ob.is_instance_of::<pyo3::types::PyBytes>()
        {
            return Err(PyTypeError::new_err(format!(
                "expected a number or an array of numbers, got {}",
                short_repr(&ob, 40)
            )));
        }
        // numpy would cast complex (dropping the imaginary part with only a warning), dates
        // and strings to float: only booleans, integers and reals are numbers here.
        if let Ok(array) = ob.cast::<PyUntypedArray>() {
            let dtype = array.dtype();
            let kind = dtype.kind();
            if !matches!(kind, b'b' | b'i' | b'u' | b'f') {
                return Err(PyTypeError::new_err(format!(
                    "expected an array of real numbers, got an array of dtype {}",
                    dtype
                        .str()
                        .map(|s| s.to_string())
                        .unwrap_or_else(|_| "?".into())
                )));
            }
        }
        match ob.extract::<PyArrayLikeDyn<'py, f64, AllowTypeChange>>() {
            Ok(a) => Ok(FloatArray(a)),
            Err(e) => Err(conversion_error(
                ob.py(),
                &ob,
                "an array of real numbers",
                e,
            )),
        }
    }
}

/// An index written as Python does: `3` for one dimension, `(1, 2)` for more.
fn index_str(index: &[usize]) -> String {
    match index {
        [i] => i.to_string(),
        _ => {
            let parts: Vec<String> = index.iter().map(|d| d.to_string()).collect();
            format!("({})", parts.join(", "))
        }
    }
}

/// The multi-index of flat (row-major) position `flat` in `shape`.
fn unravel(mut flat: usize, shape: &[usize]) -> Vec<usize> {
    let mut index = vec![0; shape.len()];
    for (k, &n) in shape.iter().enumerate().rev() {
        if n > 0 {
            index[k] = flat % n;
            flat /= n;
        }
    }
    index
}

/// Number of elements of `shape`, or a `ParameterError` if it overflows.
fn checked_len(shape: &[usize]) -> PyResult<usize> {
    shape
        .iter()
        .try_fold(1usize, |acc, &n| acc.checked_mul(n))
        .ok_or_else(|| {
            parameter_error(format!(
                "an array of shape {} has more elements than memory can address",
                shape_str(shape)
            ))
        })
}

/// A `ParameterError` unless an array with `ndim` dimensions can be handed to numpy.
pub(crate) fn check_ndim(what: &str, ndim: usize) -> PyResult<()> {
    if ndim > MAX_NDIM {
        return Err(parameter_error(format!(
            "{what} would have {ndim} dimensions; at most {MAX_NDIM} are supported: reshape \
             the input to fewer dimensions"
        )));
    }
    Ok(())
}

/// An input array copied out of Python (so the GIL can be released while the core runs),
/// every value checked to be finite. Axes along which numpy repeats one value (stride 0, as
/// made by `np.broadcast_to`) are stored once.
pub(crate) struct Input {
    /// Logical shape (what the user passed).
    pub shape: Vec<usize>,
    /// Stored values, row-major over the shape with the repeated axes reduced to length 1.
    values: Vec<f64>,
    /// Step in `values` along each logical axis (0 on repeated and length-1 axes).
    strides: Vec<usize>,
}

impl Input {
    /// Copy `array` (any layout), rejecting NaN and infinity with a `ParameterError` that
    /// names the argument, its unit and the first bad element, and arrays of more than
    /// [`MAX_NDIM`] dimensions.
    pub fn finite(name: &str, unit: &str, array: &FloatArray<'_>) -> PyResult<Self> {
        check_ndim(name, array.0.ndim())?;
        let view = array.0.as_array();
        let shape = view.shape().to_vec();
        let repeated: Vec<bool> = view
            .strides()
            .iter()
            .zip(&shape)
            .map(|(&s, &n)| s == 0 && n > 1)
            .collect();
        let stored = view.slice_each_axis(|axis| {
            if repeated[axis.axis.index()] {
                Slice::from(0..1)
            } else {
                Slice::from(..)
            }
        });
        let mut values = try_vec(stored.len(), &format!("a copy of {name}"))?;
        values.extend(stored.iter().copied());
        let stored_shape = stored.shape().to_vec();
        let mut strides = vec![0; shape.len()];
        let mut step = 1;
        for k in (0..shape.len()).rev() {
            if stored_shape[k] > 1 {
                strides[k] = step;
            }
            step *= stored_shape[k];
        }
        if let Some((flat, bad)) = values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            let at = if shape.is_empty() {
                String::new()
            } else {
                format!(" at index {}", index_str(&unravel(flat, &stored_shape)))
            };
            return Err(parameter_error(format!(
                "{name} must contain only finite numbers [{unit}], got {}{at}; remove NaN \
                 and infinite values",
                crate::error::num(*bad)
            )));
        }
        Ok(Self {
            shape,
            values,
            strides,
        })
    }

    /// Every value in logical (row-major) order; for small arrays whose shape was checked.
    pub fn to_vec(&self) -> PyResult<Vec<f64>> {
        let b = Broadcast::new(vec![("", self.clone_shallow())])?;
        let mut out = Vec::with_capacity(b.len);
        b.for_each(|_, x| {
            out.push(x[0]);
            Ok(())
        })?;
        Ok(out)
    }

    fn clone_shallow(&self) -> Input {
        Input {
            shape: self.shape.clone(),
            values: self.values.clone(),
            strides: self.strides.clone(),
        }
    }
}

/// Several inputs broadcast to one shape (numpy rules), read without materialising the
/// broadcast.
pub(crate) struct Broadcast {
    /// The broadcast shape.
    pub shape: Vec<usize>,
    /// Number of elements of the broadcast shape.
    pub len: usize,
    columns: Vec<Column>,
}

/// One input seen through the broadcast shape.
struct Column {
    values: Vec<f64>,
    /// Step in `values` along each axis of the broadcast shape (0 where repeated).
    strides: Vec<usize>,
}

/// Most inputs one broadcast combines.
const MAX_INPUTS: usize = 8;

impl Broadcast {
    /// Broadcast named inputs together; a `ParameterError` names the shapes that do not fit,
    /// or a broadcast shape whose size overflows.
    pub fn new(inputs: Vec<(&str, Input)>) -> PyResult<Self> {
        assert!(inputs.len() <= MAX_INPUTS, "too many broadcast inputs");
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
        let len = checked_len(&shape)?;
        let columns = inputs
            .into_iter()
            .map(|(_, input)| {
                let offset = shape.len() - input.shape.len();
                let mut strides = vec![0; shape.len()];
                strides[offset..].copy_from_slice(&input.strides);
                Column {
                    values: input.values,
                    strides,
                }
            })
            .collect();
        Ok(Self {
            shape,
            len,
            columns,
        })
    }

    /// Call `f(flat_index, values)` for every element in row-major order, `values[c]` being
    /// input `c` there; stops at the first error.
    pub fn for_each(
        &self,
        mut f: impl FnMut(usize, &[f64]) -> Result<(), RvdynError>,
    ) -> Result<(), RvdynError> {
        if self.len == 0 {
            return Ok(());
        }
        let ncol = self.columns.len();
        let nd = self.shape.len();
        let mut index = vec![0usize; nd];
        let mut offsets = [0usize; MAX_INPUTS];
        let mut args = [0.0f64; MAX_INPUTS];
        let columns = &self.columns;
        for flat in 0..self.len {
            for ((arg, col), &at) in args.iter_mut().zip(columns).zip(&offsets) {
                *arg = col.values[at];
            }
            f(flat, &args[..ncol])?;
            // Advance the odometer: last axis fastest.
            for k in (0..nd).rev() {
                index[k] += 1;
                if index[k] < self.shape[k] {
                    for (at, col) in offsets.iter_mut().zip(columns) {
                        *at += col.strides[k];
                    }
                    break;
                }
                index[k] = 0;
                for (at, col) in offsets.iter_mut().zip(columns) {
                    *at -= col.strides[k] * (self.shape[k] - 1);
                }
            }
        }
        Ok(())
    }

    /// `f` on every element, `N` results each, laid out row-major with a trailing axis of
    /// length `N` (dropped for `N = 1`). Every result must be finite: a non-finite one is a
    /// `ParameterError` naming `what` and the element (the inputs are beyond what the formulas
    /// can represent in floating point). Errors of `f` get the element's index when there is
    /// more than one element.
    pub fn map_rows<const N: usize>(
        &self,
        what: &str,
        f: impl Fn(&[f64]) -> Result<[f64; N], RvdynError>,
    ) -> Result<Vec<f64>, RvdynError> {
        let n = self
            .len
            .checked_mul(N)
            .ok_or_else(|| RvdynError::Memory(format!("the result of {what} is too large")))?;
        let mut out = try_vec(n, &format!("the result of {what}"))?;
        self.for_each(|flat, x| {
            let row = self.checked(what, flat, f(x))?;
            out.extend_from_slice(&row);
            Ok(())
        })?;
        Ok(out)
    }

    /// As [`Broadcast::map_rows`], one array per result column.
    pub fn map_columns<const N: usize>(
        &self,
        what: &str,
        f: impl Fn(&[f64]) -> Result<[f64; N], RvdynError>,
    ) -> Result<Vec<Vec<f64>>, RvdynError> {
        let mut cols = Vec::with_capacity(N);
        for _ in 0..N {
            cols.push(try_vec(self.len, &format!("the result of {what}"))?);
        }
        self.for_each(|flat, x| {
            let row = self.checked(what, flat, f(x))?;
            for (c, v) in cols.iter_mut().zip(row) {
                c.push(v);
            }
            Ok(())
        })?;
        Ok(cols)
    }

    /// `row` if it is `Ok` and finite, else the error with the element's index.
    fn checked<const N: usize>(
        &self,
        what: &str,
        flat: usize,
        row: Result<[f64; N], RvdynError>,
    ) -> Result<[f64; N], RvdynError> {
        let at = || {
            format!(
                "at index {} of the inputs",
                index_str(&unravel(flat, &self.shape))
            )
        };
        match row {
            Ok(r) if r.iter().all(|v| v.is_finite()) => Ok(r),
            Ok(r) => {
                let bad = r
                    .iter()
                    .find(|v| !v.is_finite())
                    .copied()
                    .unwrap_or(f64::NAN);
                let message = format!(
                    "{what} is not finite ({}) for these inputs: they are beyond the range the \
                     formulas can represent in floating point; use values of physical size",
                    crate::error::num(bad)
                );
                let e = RvdynError::Parameter(message);
                Err(if self.len > 1 {
                    super::with_context(e, &at())
                } else {
                    e
                })
            }
            Err(e) if self.len > 1 => Err(super::with_context(e, &at())),
            Err(e) => Err(e),
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
/// array that takes ownership of the vector (no copy). Values must be finite (the callers
/// check; a non-finite value here is a `ParameterError`, never returned).
pub(crate) fn output<'py>(
    py: Python<'py>,
    shape: &[usize],
    values: Vec<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    check_ndim("the result", shape.len())?;
    if let Some(bad) = values.iter().find(|v| !v.is_finite()) {
        return Err(parameter_error(format!(
            "a result is not finite ({}): the inputs are beyond the range the formulas can \
             represent in floating point",
            crate::error::num(*bad)
        )));
    }
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
    let v = input.to_vec()?;
    Ok([v[0], v[1]])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn broadcasting_follows_numpy() {
        assert_eq!(broadcast_pair(&[3, 1], &[4]), Some(vec![3, 4]));
        assert_eq!(broadcast_pair(&[], &[2, 2]), Some(vec![2, 2]));
        assert_eq!(broadcast_pair(&[3], &[4]), None);
        assert_eq!(unravel(5, &[2, 3]), vec![1, 2]);
        assert_eq!(index_str(&[1, 2]), "(1, 2)");
    }
}
