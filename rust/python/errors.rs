//! The one place where core errors become Python exceptions.
//!
//! Each [`RvdynError`] variant maps to one class defined in `python/rvdyn/errors.py`:
//!
//! | core variant   | Python exception                                   |
//! |----------------|----------------------------------------------------|
//! | `Geometry`     | `rvdyn.GeometryError(RvdynError, ValueError)`      |
//! | `Parameter`    | `rvdyn.ParameterError(RvdynError, ValueError)`     |
//! | `Scene`        | `rvdyn.SceneError(RvdynError, ValueError)`         |
//! | `Convergence`  | `rvdyn.ConvergenceError(RvdynError, ArithmeticError)` |
//! | `Simulation`   | `rvdyn.SimulationError(RvdynError, RuntimeError)`  |
//! | `Memory`       | `MemoryError`                                      |
//! | `Interrupted`  | `KeyboardInterrupt`                                |
//!
//! Python errors raised while reading an argument (an integer too large for a count, a string
//! that is not a number) become the matching rvdyn class with the original exception chained as
//! `__cause__` ([`chained`]); a wrong argument type stays a `TypeError`, as in Python itself.
//!
//! The classes are looked up in `rvdyn.errors` when the error is raised; if that module cannot
//! be imported (a broken install), the built-in base class is raised with the same message, so
//! `except ValueError` still works.

use crate::error::RvdynError;
use pyo3::exceptions::{
    PyArithmeticError, PyKeyboardInterrupt, PyMemoryError, PyRuntimeError, PyValueError,
};
use pyo3::prelude::*;

/// Name of the Python class in `rvdyn.errors` for a variant (`None` for `Interrupted`).
fn class_name(err: &RvdynError) -> Option<&'static str> {
    match err {
        RvdynError::Geometry(_) => Some("GeometryError"),
        RvdynError::Parameter(_) => Some("ParameterError"),
        RvdynError::Scene(_) => Some("SceneError"),
        RvdynError::Convergence(_) => Some("ConvergenceError"),
        RvdynError::Simulation(_) => Some("SimulationError"),
        RvdynError::Memory(_) | RvdynError::Interrupted => None,
    }
}

/// The built-in exception raised when `rvdyn.errors` cannot be imported.
fn fallback(err: &RvdynError, message: String) -> PyErr {
    match err {
        RvdynError::Geometry(_) | RvdynError::Parameter(_) | RvdynError::Scene(_) => {
            PyValueError::new_err(message)
        }
        RvdynError::Convergence(_) => PyArithmeticError::new_err(message),
        RvdynError::Simulation(_) => PyRuntimeError::new_err(message),
        RvdynError::Memory(_) => PyMemoryError::new_err(message),
        RvdynError::Interrupted => PyKeyboardInterrupt::new_err(message),
    }
}

/// Convert a core error into the matching Python exception (see the module table).
pub(crate) fn to_pyerr(py: Python<'_>, err: RvdynError) -> PyErr {
    let message = err.to_string();
    let Some(name) = class_name(&err) else {
        return fallback(&err, message);
    };
    let built = py
        .import("rvdyn.errors")
        .and_then(|module| module.getattr(name))
        .and_then(|class| class.call1((message.clone(),)));
    match built {
        Ok(instance) => PyErr::from_value(instance),
        Err(_) => fallback(&err, message),
    }
}

impl From<RvdynError> for PyErr {
    fn from(err: RvdynError) -> Self {
        Python::attach(|py| to_pyerr(py, err))
    }
}

/// A `ParameterError` with `message` (bad input detected in the bindings, e.g. a wrong shape).
pub(crate) fn parameter_error(message: impl Into<String>) -> PyErr {
    RvdynError::Parameter(message.into()).into()
}

/// The same error with `context` appended to its message (e.g. which array element failed).
pub(crate) fn with_context(err: RvdynError, context: &str) -> RvdynError {
    match err {
        RvdynError::Geometry(m) => RvdynError::Geometry(format!("{m} ({context})")),
        RvdynError::Parameter(m) => RvdynError::Parameter(format!("{m} ({context})")),
        RvdynError::Scene(m) => RvdynError::Scene(format!("{m} ({context})")),
        RvdynError::Convergence(m) => RvdynError::Convergence(format!("{m} ({context})")),
        RvdynError::Simulation(m) => RvdynError::Simulation(format!("{m} ({context})")),
        RvdynError::Memory(m) => RvdynError::Memory(format!("{m} ({context})")),
        RvdynError::Interrupted => RvdynError::Interrupted,
    }
}

/// `err` as a Python exception with `cause` (the Python error that revealed it) chained as
/// its `__cause__`, so the user sees both.
pub(crate) fn chained(py: Python<'_>, err: RvdynError, cause: PyErr) -> PyErr {
    let e = to_pyerr(py, err);
    e.set_cause(py, Some(cause));
    e
}
