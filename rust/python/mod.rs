//! Python bindings (`rvdyn._core`), compiled only with the `python` feature.
//!
//! Thin by rule: argument conversion, shape and finiteness checks, broadcasting, GIL release and
//! result packing live here; every number is computed by the core. Errors go through
//! [`errors`], the one place that maps [`crate::RvdynError`] to Python exceptions.
//!
//! Each submodule has a `register(m)` function that adds its classes and functions to the
//! module; a new submodule (e.g. `simulate`) adds `mod simulate;` and one `register` line in
//! [`rvdyn_core`].

mod bearing;
mod contact;
mod errors;
mod geometry;
mod kinematics;
mod ltca;
mod modes;
mod scene;
mod simulate;

use pyo3::prelude::*;

// Argument reading, broadcasting and result packing (sizes checked before allocating).
mod arrays;
pub(crate) use arrays::{Broadcast, FloatArray, Input, Real, Whole, count, output, point2, vec2};
pub(crate) use errors::{parameter_error, with_context};

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
    bearing::register(m)?;
    kinematics::register(m)?;
    scene::register(m)?;
    simulate::register(m)?;
    ltca::register(m)?;
    modes::register(m)?;
    Ok(())
}
