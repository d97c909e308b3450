//! Bindings of the bearing core: the ISO 281 rating life of a load history.

use super::Real;
use crate::bearing::{equivalent_load, l10_roller};
use pyo3::prelude::*;

/// Equivalent dynamic load and basic rating life of a roller bearing over a load history (ISO
/// 281: `P = (sum w P_k^(10/3) / sum w)^(3/10)`, `L10 = (C / P)^(10/3)`; docs/model.md,
/// "Load rating, life and friction torque").
///
/// Parameters
/// ----------
/// rating : float
///     Basic dynamic load rating C [N], > 0.
/// loads : sequence of float, shape (n,)
///     Radial load magnitudes P_k [N], >= 0.
/// revolutions : sequence of float, shape (n,)
///     Revolutions spent at each load (weights, >= 0; any consistent unit).
///
/// Returns
/// -------
/// tuple[float, float]
///     The equivalent load P [N] and L10 [million revolutions]; (0, inf) for a bearing that did
///     not turn (all weights zero) or carried no load.
///
/// Raises
/// ------
/// ParameterError
///     A non-positive rating, negative or non-finite loads or weights, or histories of different
///     or zero length.
#[pyfunction]
fn roller_bearing_life(
    rating: Real,
    loads: Vec<f64>,
    revolutions: Vec<f64>,
) -> PyResult<(f64, f64)> {
    // A bearing that did not turn has seen no load cycles: no equivalent load, no fatigue.
    let p = if !loads.is_empty()
        && loads.len() == revolutions.len()
        && revolutions.iter().all(|&w| w == 0.0)
    {
        0.0
    } else {
        equivalent_load(&loads, &revolutions)?
    };
    Ok((p, l10_roller(rating.0, p)?))
}

/// Add the bearing functions to the module.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(roller_bearing_life, m)?)?;
    Ok(())
}
