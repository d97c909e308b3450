//! Bindings of the bearing core: the ISO 281 rating life of a load history, the split of a
//! lumped crank bearing into its two rows.

use super::Real;
use super::arrays::{FloatArray, Input, output, shape_str};
use super::errors::parameter_error;
use crate::bearing::{CrankLayout, equivalent_load, l10_roller, system_life_roller};
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

/// L10 of roller bearings that fail together when any one fails (Lundberg-Palmgren system
/// life `L = (sum L_i^-e)^(-1/e)`, `e = 9/8`; docs/model.md, "Crank bearing rows").
///
/// Parameters
/// ----------
/// lives : sequence of float
///     Each bearing's L10 (any one unit; ``inf`` for one that never fails), > 0.
///
/// Returns
/// -------
/// float
///     The system's L10, in the unit of ``lives``.
///
/// Raises
/// ------
/// ParameterError
///     No life, or one that is not positive.
#[pyfunction]
fn roller_system_life(lives: Vec<Real>) -> PyResult<f64> {
    let lives: Vec<f64> = lives.iter().map(|l| l.0).collect();
    Ok(system_life_roller(&lives)?)
}

/// The forces of a crank's two bearings on the crank, from the lumped crank bearing force of
/// the planar models and the discs' eccentric bearing forces, by the statics of a rigid crank
/// on two radial supports (docs/model.md, "Crank bearing rows").
///
/// Parameters
/// ----------
/// crank_bearing_force : array_like, shape (..., 2)
///     Lumped crank bearing force on the crank [N] (``Result.crank_bearing_force``, or the
///     LTCA's ``crank_bearing_force``).
/// eccentric_bearing_force : array_like, shape (..., discs, 2)
///     Each disc's eccentric bearing force on the disc [N], the same leading shape
///     (``Result.eccentric_bearing_force``).
/// bearings : tuple[float, float]
///     Axial positions of the two crank bearings' mid-planes [m], different.
/// discs : sequence of float, length discs
///     Axial positions of the discs' mid-planes [m], in the order of the discs.
/// planet : float
///     Axial position of the planet's mid-plane [m] (where the mesh force, and the crank's
///     inertia force, act).
///
/// Returns
/// -------
/// numpy.ndarray, shape (..., 2, 2)
///     Force of bearing ``bearings[0]`` and of bearing ``bearings[1]`` on the crank [N], in
///     the frame of the inputs; the two add up to ``crank_bearing_force``.
///
/// Raises
/// ------
/// ParameterError
///     Non-finite values or positions, shapes that do not match, or bearings at one position.
///
/// Examples
/// --------
/// >>> import rvdyn
/// >>> rvdyn.crank_bearing_rows([4000.0, 0.0], [[1000.0, 0.0], [2000.0, 0.0]],
/// ...                          bearings=(0.0, 0.1), discs=(0.025, 0.025), planet=0.025)
/// array([[3000.,    0.],
///        [1000.,    0.]])
#[pyfunction]
#[pyo3(signature = (crank_bearing_force, eccentric_bearing_force, *, bearings, discs, planet))]
fn crank_bearing_rows<'py>(
    py: Python<'py>,
    crank_bearing_force: FloatArray<'py>,
    eccentric_bearing_force: FloatArray<'py>,
    bearings: (Real, Real),
    discs: Vec<Real>,
    planet: Real,
) -> PyResult<Bound<'py, PyAny>> {
    let layout = CrankLayout {
        bearings: [bearings.0.0, bearings.1.0],
        discs: discs.iter().map(|z| z.0).collect(),
        planet: planet.0,
        roller_length: None,
    };
    layout.validate()?;
    let crank = Input::finite("crank_bearing_force", "N", &crank_bearing_force)?;
    let ecc = Input::finite("eccentric_bearing_force", "N", &eccentric_bearing_force)?;
    let nd = layout.discs.len();
    let (cs, es) = (&crank.shape, &ecc.shape);
    if cs.last() != Some(&2) {
        return Err(parameter_error(format!(
            "crank_bearing_force must have shape (..., 2) [N], got {}",
            shape_str(cs)
        )));
    }
    let lead = &cs[..cs.len() - 1];
    if es.len() != cs.len() + 1 || es[..lead.len()] != *lead || es[lead.len()..] != [nd, 2] {
        let mut want = lead.to_vec();
        want.extend([nd, 2]);
        return Err(parameter_error(format!(
            "eccentric_bearing_force must have shape {} [N] (the leading shape of \
             crank_bearing_force, then one force per disc position given: {nd}), got {}",
            shape_str(&want),
            shape_str(es)
        )));
    }
    let (c, e) = (crank.to_vec()?, ecc.to_vec()?);
    let values = py.detach(|| {
        let mut out = Vec::with_capacity(2 * c.len());
        let mut forces = vec![[0.0; 2]; nd];
        for (i, lumped) in c.chunks_exact(2).enumerate() {
            for (k, f) in forces.iter_mut().enumerate() {
                let at = 2 * (i * nd + k);
                *f = [e[at], e[at + 1]];
            }
            let [a, b] = layout.split([lumped[0], lumped[1]], &forces);
            out.extend([a[0], a[1], b[0], b[1]]);
        }
        out
    });
    let mut shape = lead.to_vec();
    shape.extend([2, 2]);
    output(py, &shape, values)
}

/// Add the bearing functions to the module.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(roller_bearing_life, m)?)?;
    m.add_function(wrap_pyfunction!(crank_bearing_rows, m)?)?;
    m.add_function(wrap_pyfunction!(roller_system_life, m)?)?;
    Ok(())
}
