//! Bindings of the contact core: the paper's contact stiffness, Hertz line contact, the IMPACT
//! law. Array arguments broadcast together (numpy rules); scalar-only calls return floats.

use super::arrays::check_ndim;
use super::{Broadcast, FloatArray, Input, Real, output, python_type};
use crate::contact::hertz::{Material, hertz_line_contact as core_hertz};
use crate::contact::impact::ImpactLaw;
use crate::contact::stiffness::{
    ContactCondition, StiffnessParams, contact_stiffness as core_stiffness,
    stiffness_maximum as core_maximum,
};
use pyo3::prelude::*;

/// The paper's stiffness parameters for radii `r1`, `r2` [m], one condition and one material
/// for both bodies. Validated by the core when used.
fn stiffness_params(
    r1: f64,
    r2: f64,
    condition: ContactCondition,
    material: Material,
    exponent: f64,
    penetration: f64,
) -> StiffnessParams {
    StiffnessParams {
        r1,
        r2,
        condition,
        material1: material,
        material2: material,
        exponent,
        penetration,
    }
}

/// Contact stiffness k of the paper's eqs. 5-11 (errata corrected) against contact width.
///
/// k = k' sqrt(w) with k' = (4/3) E* sqrt(R) (eq. 6), F = k' x^e (eq. 10), Roark's full Hertz
/// width b = 1.60 sqrt(F/L K_D / E*) (eq. 11) and the approach w of eq. 9, evaluated in the
/// paper's N-mm units and converted to SI (the paper's "N/mm^2" is N/mm^e, erratum 4).
/// 1/E* = 2 (1 - nu^2)/E (both bodies of the same material; the paper's eq. 8 subtracts).
///
/// Parameters
/// ----------
/// width : float or array_like
///     Contact width L (the face width in contact) [m].
/// r1 : float or array_like
///     Pin radius R1 [m].
/// r2 : float or array_like
///     Magnitude of the disc's radius of curvature at the contact R2 [m] (> r1 for
///     convex-concave).
/// condition : {"convex-convex", "convex-concave"}
///     Pin on a lobe tip (R = R1 R2/(R1 + R2)) or in a root (R = R1 R2/(R2 - R1)).
/// youngs_modulus : float
///     Young's modulus E of both bodies [Pa] (paper: 2.17e11).
/// poisson_ratio : float
///     Poisson's ratio nu of both bodies [-] (paper: 0.3).
/// exponent : float
///     IMPACT force exponent e [-] (paper: 1.5).
/// penetration : float
///     IMPACT penetration depth x of eq. 10 [m] (paper: 0.01 mm = 1e-5 m).
///
/// Returns
/// -------
/// float or numpy.ndarray
///     k [N/m^exponent], shape of the broadcast width, r1, r2 (a float if all are scalars).
///
/// Raises
/// ------
/// ParameterError
///     Non-finite or non-positive inputs, unknown condition, shapes that do not broadcast.
/// GeometryError
///     Convex-concave contact with r2 <= r1.
#[pyfunction]
#[pyo3(
    signature = (width, r1, r2, condition="convex-convex", youngs_modulus=Real(2.17e11), poisson_ratio=Real(0.3), exponent=Real(1.5), penetration=Real(1e-5)),
    text_signature = "(width, r1, r2, condition=\"convex-convex\", youngs_modulus=2.17e11, poisson_ratio=0.3, exponent=1.5, penetration=1e-5)"
)]
#[allow(clippy::too_many_arguments)]
fn contact_stiffness<'py>(
    py: Python<'py>,
    width: FloatArray<'py>,
    r1: FloatArray<'py>,
    r2: FloatArray<'py>,
    condition: &str,
    youngs_modulus: Real,
    poisson_ratio: Real,
    exponent: Real,
    penetration: Real,
) -> PyResult<Bound<'py, PyAny>> {
    let condition = ContactCondition::parse(condition)?;
    let material = Material::new(youngs_modulus.0, poisson_ratio.0)?;
    let b = Broadcast::new(vec![
        ("width", Input::finite("width", "m", &width)?),
        ("r1", Input::finite("r1", "m", &r1)?),
        ("r2", Input::finite("r2", "m", &r2)?),
    ])?;
    check_ndim("the result of contact_stiffness", b.shape.len())?;
    let (exponent, penetration) = (exponent.0, penetration.0);
    let values = py.detach(|| {
        b.map_rows::<1>("the contact stiffness", |x| {
            let p = stiffness_params(x[1], x[2], condition, material, exponent, penetration);
            Ok([core_stiffness(x[0], &p)?])
        })
    })?;
    output(py, &b.shape, values)
}

/// Largest contact stiffness of eqs. 5-11 over contact widths in [lo, hi].
///
/// A log-spaced scan brackets the maximum, a golden-section search refines it (1e-10 relative
/// in width). With the errata corrected, k decreases with width over every physical width, so
/// the paper's maximum near 5 mm is not reproduced: a bracket of physical widths raises
/// ParameterError ("no interior maximum"); the formal maximum lies near 1e-8 m, where the
/// Hertz width is far larger than the radii.
///
/// Parameters
/// ----------
/// r1, r2 : float
///     Pin radius and magnitude of the disc radius of curvature [m] (see contact_stiffness).
/// condition : {"convex-convex", "convex-concave"}
/// lo, hi : float
///     Width bracket [m], 0 < lo < hi.
/// youngs_modulus [Pa], poisson_ratio [-], exponent [-], penetration [m]
///     As in contact_stiffness.
///
/// Returns
/// -------
/// (float, float)
///     (width at the maximum [m], k_max [N/m^exponent]).
///
/// Raises
/// ------
/// ParameterError
///     Invalid inputs, or no interior maximum in [lo, hi] (the largest value is at an end).
#[pyfunction]
#[pyo3(
    signature = (r1, r2, condition="convex-convex", lo=Real(1e-4), hi=Real(0.1), youngs_modulus=Real(2.17e11), poisson_ratio=Real(0.3), exponent=Real(1.5), penetration=Real(1e-5)),
    text_signature = "(r1, r2, condition=\"convex-convex\", lo=1e-4, hi=0.1, youngs_modulus=2.17e11, poisson_ratio=0.3, exponent=1.5, penetration=1e-5)"
)]
#[allow(clippy::too_many_arguments)]
fn stiffness_maximum(
    py: Python<'_>,
    r1: Real,
    r2: Real,
    condition: &str,
    lo: Real,
    hi: Real,
    youngs_modulus: Real,
    poisson_ratio: Real,
    exponent: Real,
    penetration: Real,
) -> PyResult<(f64, f64)> {
    let condition = ContactCondition::parse(condition)?;
    let material = Material::new(youngs_modulus.0, poisson_ratio.0)?;
    let p = stiffness_params(r1.0, r2.0, condition, material, exponent.0, penetration.0);
    Ok(py.detach(|| core_maximum(&p, lo.0, hi.0))?)
}

/// Hertz contact of two parallel cylinders (line contact), element-wise.
///
/// With the line load P = F/L, 1/R = 1/r1 + 1/r2 and 1/E* = 2 (1 - nu^2)/E (both bodies of
/// the same material): half width a = sqrt(4 P R / (pi E*)), peak pressure p0 = 2 P/(pi a),
/// mean pressure (pi/4) p0, approach of the two axes from Johnson's 2-D formula
/// sum_k P (1 - nu^2)/(pi E) (2 ln(4 |r_k| / a) - 1) (a model value: 2-D approach needs a
/// reference depth).
///
/// Parameters
/// ----------
/// force : float or array_like
///     Normal force F [N], >= 0.
/// width : float or array_like
///     Contact length L along the cylinder axes [m], > 0.
/// r1, r2 : float or array_like
///     Radii [m]: positive convex, negative concave (a pin in a root: r2 < 0, |r2| > r1).
/// youngs_modulus : float
///     Young's modulus E of both bodies [Pa].
/// poisson_ratio : float
///     Poisson's ratio nu of both bodies [-].
///
/// Returns
/// -------
/// LineContact
///     Named tuple (half_width [m], peak_pressure [Pa], mean_pressure [Pa], approach [m]);
///     each a float or an array of the broadcast input shape.
///
/// Raises
/// ------
/// ParameterError
///     Negative or non-finite force, non-positive width, invalid material, shapes that do not
///     broadcast, results beyond floating point, or a half width wider than the smaller
///     radius (outside Hertz theory).
/// GeometryError
///     Radii that cannot make a Hertz contact (zero, concave-concave, conformal or nested).
#[pyfunction]
#[pyo3(
    signature = (force, width, r1, r2, youngs_modulus=Real(2.17e11), poisson_ratio=Real(0.3)),
    text_signature = "(force, width, r1, r2, youngs_modulus=2.17e11, poisson_ratio=0.3)"
)]
fn hertz_line_contact<'py>(
    py: Python<'py>,
    force: FloatArray<'py>,
    width: FloatArray<'py>,
    r1: FloatArray<'py>,
    r2: FloatArray<'py>,
    youngs_modulus: Real,
    poisson_ratio: Real,
) -> PyResult<Bound<'py, PyAny>> {
    let m = Material::new(youngs_modulus.0, poisson_ratio.0)?;
    let b = Broadcast::new(vec![
        ("force", Input::finite("force", "N", &force)?),
        ("width", Input::finite("width", "m", &width)?),
        ("r1", Input::finite("r1", "m", &r1)?),
        ("r2", Input::finite("r2", "m", &r2)?),
    ])?;
    check_ndim("the result of hertz_line_contact", b.shape.len())?;
    let columns = py.detach(|| {
        b.map_columns::<4>("the Hertz contact", |x| {
            let c = core_hertz(x[0], x[1], x[2], x[3], &m, &m)?;
            Ok([c.half_width, c.peak_pressure, c.mean_pressure, c.approach])
        })
    })?;
    let arrays = columns
        .into_iter()
        .map(|c| output(py, &b.shape, c))
        .collect::<PyResult<Vec<_>>>()?;
    python_type(py, "LineContact")?.call1(pyo3::types::PyTuple::new(py, arrays)?)
}

/// Force of the ADAMS IMPACT contact law, element-wise.
///
/// F = k x^e + STEP(x, 0, 0, depth, cmax) * v for penetration x > 0, else 0; STEP is the cubic
/// ramp 3 s^2 - 2 s^3 of s = x / depth clamped to [0, 1], so the damping grows from 0 at first
/// touch to cmax at x >= depth (the force is continuous at contact). F >= 0 always: a contact
/// that separates fast does not pull.
///
/// Parameters
/// ----------
/// penetration : float or array_like
///     Penetration x [m] (positive = overlap; <= 0 means no contact).
/// velocity : float or array_like
///     Penetration rate dx/dt [m/s] (positive = closing).
/// k : float
///     Stiffness [N/m^exponent] (paper: 3.988e5 N/mm^1.5 = 1.2611e10 N/m^1.5).
/// exponent : float
///     Force exponent e [-], >= 1 (paper: 1.5).
/// cmax : float
///     Maximum damping coefficient [N s/m], >= 0 (paper: 100 N s/mm = 1e5 N s/m).
/// depth : float
///     Penetration at which the damping reaches cmax [m], > 0 (paper: 0.01 mm = 1e-5 m).
///
/// Returns
/// -------
/// float or numpy.ndarray
///     Contact force [N] (>= 0), shape of the broadcast penetration and velocity.
///
/// Raises
/// ------
/// ParameterError
///     Non-finite inputs, k <= 0, exponent < 1, cmax < 0, depth <= 0, shapes that do not
///     broadcast.
#[pyfunction]
#[pyo3(
    signature = (penetration, velocity, k, exponent=Real(1.5), cmax=Real(1.0e5), depth=Real(1.0e-5)),
    text_signature = "(penetration, velocity, k, exponent=1.5, cmax=1.0e5, depth=1.0e-5)"
)]
fn impact_force<'py>(
    py: Python<'py>,
    penetration: FloatArray<'py>,
    velocity: FloatArray<'py>,
    k: Real,
    exponent: Real,
    cmax: Real,
    depth: Real,
) -> PyResult<Bound<'py, PyAny>> {
    let law = ImpactLaw::new(k.0, exponent.0, cmax.0, depth.0)?;
    let b = Broadcast::new(vec![
        (
            "penetration",
            Input::finite("penetration", "m", &penetration)?,
        ),
        ("velocity", Input::finite("velocity", "m/s", &velocity)?),
    ])?;
    check_ndim("the result of impact_force", b.shape.len())?;
    let values = py
        .detach(|| b.map_rows::<1>("the IMPACT force", |x| Ok([law.checked_force(x[0], x[1])?])))?;
    output(py, &b.shape, values)
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(contact_stiffness, m)?)?;
    m.add_function(wrap_pyfunction!(stiffness_maximum, m)?)?;
    m.add_function(wrap_pyfunction!(hertz_line_contact, m)?)?;
    m.add_function(wrap_pyfunction!(impact_force, m)?)?;
    let paper = ImpactLaw::paper();
    m.add("PAPER_IMPACT_STIFFNESS", paper.stiffness)?;
    m.add("PAPER_IMPACT_EXPONENT", paper.exponent)?;
    m.add("PAPER_IMPACT_MAX_DAMPING", paper.max_damping)?;
    m.add("PAPER_IMPACT_DEPTH", paper.damping_depth)?;
    let fig3 = StiffnessParams::paper(ContactCondition::ConvexConvex);
    m.add("PAPER_STIFFNESS_R1", fig3.r1)?;
    m.add("PAPER_STIFFNESS_R2", fig3.r2)?;
    Ok(())
}
