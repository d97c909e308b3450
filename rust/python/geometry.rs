//! Bindings of the geometry core: `CycloidGeometry` and `InvoluteStage`.

use super::arrays::check_ndim;
use super::{
    Broadcast, FloatArray, Input, Real, Whole, count, output, parameter_error, point2, python_type,
    vec2,
};
use crate::error::RvdynError;
use crate::geometry::cycloid::CycloidParams;
use crate::geometry::mass::{DiscHoles, STEEL_DENSITY, disc_mass_properties};
use crate::geometry::{CycloidGeometry, InvoluteStage, PinGap};
use pyo3::prelude::*;
use pyo3::types::{PyTuple, PyType};

/// The default disc of the paper's scene (docs/model.md#default-scene): 24 pins and
/// e = 4.5 mm are given; rp = 150 mm, rrp = 10 mm and the 40 mm face width are assumed.
fn paper_cycloid() -> CycloidParams {
    CycloidParams::paper()
}

/// A validated cycloid disc and its pin ring (SI units: m, rad).
///
/// CycloidGeometry(pins, eccentricity, pin_circle_radius, pin_radius, face_width,
///                 d_rp=0.0, d_rrp=0.0, d_delta=0.0)
///
/// Parameters
/// ----------
/// pins : int
///     Number of pins zp (>= 3); the disc has zc = zp - 1 lobes.
/// eccentricity : float
///     Eccentricity e [m].
/// pin_circle_radius : float
///     Pin circle radius rp [m].
/// pin_radius : float
///     Pin radius rrp [m].
/// face_width : float
///     Disc face width [m].
/// d_rp, d_rrp : float
///     Shift and equidistant profile modifications [m] (grinding convention: the profile is
///     generated with rp + d_rp and rrp + d_rrp; the pins stay at rp with radius rrp;
///     d_rrp > 0 and d_rp < 0 open clearance).
/// d_delta : float
///     Rotation modification [rad].
///
/// Raises
/// ------
/// GeometryError
///     If the disc cannot exist, naming the rule: fewer than 3 pins, curtate ratio
///     K1 = e zp / (rp + d_rp) >= 1, overlapping pins (rp sin(pi/zp) <= rrp), undercut
///     (rrp + d_rrp >= minimum convex radius of curvature), no material at the root.
/// ParameterError
///     If a size is not finite or not positive.
///
/// Frame: disc frame with the origin at the disc centre; curve parameter phi [rad], phi = 0 is
/// a tooth root on +x, zc phi = pi a lobe tip.
#[pyclass(name = "CycloidGeometry", module = "rvdyn", frozen)]
pub(crate) struct PyCycloidGeometry {
    inner: CycloidGeometry,
}

impl PyCycloidGeometry {
    /// Evaluate `f` (returning `N` values per angle) over an array of angles, GIL released.
    /// The result's size and dimensions are checked before anything is allocated; a
    /// non-finite value is an error naming `what`, never returned.
    fn map_angles<'py, const N: usize>(
        &self,
        py: Python<'py>,
        what: &str,
        phi: &FloatArray<'py>,
        f: impl Fn(&CycloidGeometry, f64) -> Result<[f64; N], RvdynError> + Send + Sync,
    ) -> PyResult<Bound<'py, PyAny>> {
        let input = Input::finite("phi", "rad", phi)?;
        let mut shape = input.shape.clone();
        if N > 1 {
            shape.push(N);
        }
        check_ndim(&format!("the result of {what}"), shape.len())?;
        let b = Broadcast::new(vec![("phi", input)])?;
        let g = &self.inner;
        let values = py.detach(|| b.map_rows::<N>(what, |x| f(g, x[0])))?;
        output(py, &shape, values)
    }
}

/// A radius of curvature, or a `GeometryError` where the profile is straight (the pin-centre
/// curve has an inflection exactly at `phi`, e.g. the root of a disc with K1 = 1/zp): the
/// radius is infinite there.
fn finite_curvature_radius(radius: f64, phi: f64) -> Result<[f64; 1], RvdynError> {
    if radius.is_finite() {
        Ok([radius])
    } else {
        Err(RvdynError::Geometry(format!(
            "the profile is straight at phi = {} rad (an inflection of the pin-centre curve, \
             e.g. the root of a disc with K1 = 1/zp): its radius of curvature is infinite",
            crate::error::num(phi)
        )))
    }
}

/// Pack a core gap result as `rvdyn.GapResult`.
/// A non-finite field (inputs beyond what the formulas represent) is a `ParameterError`.
fn gap_result<'py>(py: Python<'py>, g: &PinGap) -> PyResult<Bound<'py, PyAny>> {
    let fields = [
        g.gap,
        g.point[0],
        g.point[1],
        g.normal[0],
        g.normal[1],
        g.phi,
        g.curvature_radius,
    ];
    if !g.curvature_radius.is_finite() && fields[..6].iter().all(|v| v.is_finite()) {
        finite_curvature_radius(g.curvature_radius, g.phi)?;
    }
    if fields.iter().any(|v| !v.is_finite()) {
        return Err(parameter_error(
            "the gap is not finite for these inputs: they are beyond the range the formulas \
             can represent in floating point; use positions of physical size",
        ));
    }
    python_type(py, "GapResult")?.call1((
        g.gap,
        vec2(py, g.point),
        vec2(py, g.normal),
        g.phi,
        g.curvature_radius,
    ))
}

#[pymethods]
impl PyCycloidGeometry {
    #[new]
    #[pyo3(
        signature = (pins, eccentricity, pin_circle_radius, pin_radius, face_width, d_rp=Real(0.0), d_rrp=Real(0.0), d_delta=Real(0.0)),
        text_signature = "(pins, eccentricity, pin_circle_radius, pin_radius, face_width, d_rp=0.0, d_rrp=0.0, d_delta=0.0)"
    )]
    #[allow(clippy::too_many_arguments)]
    fn new(
        pins: Whole,
        eccentricity: Real,
        pin_circle_radius: Real,
        pin_radius: Real,
        face_width: Real,
        d_rp: Real,
        d_rrp: Real,
        d_delta: Real,
    ) -> PyResult<Self> {
        let pins = count("pins", pins)?;
        let inner = CycloidGeometry::new(CycloidParams {
            pins,
            eccentricity: eccentricity.0,
            pin_circle_radius: pin_circle_radius.0,
            pin_radius: pin_radius.0,
            face_width: face_width.0,
            d_rp: d_rp.0,
            d_rrp: d_rrp.0,
            d_delta: d_delta.0,
        })?;
        Ok(Self { inner })
    }

    /// The paper's default disc: zp = 24, e = 4.5 mm (given); rp = 150 mm, rrp = 10 mm, face
    /// width 40 mm (assumed, docs/model.md#default-scene); no modification.
    #[classmethod]
    fn paper(_cls: &Bound<'_, PyType>) -> PyResult<Self> {
        Ok(Self {
            inner: CycloidGeometry::new(paper_cycloid())?,
        })
    }

    /// Number of pins zp.
    #[getter]
    fn pins(&self) -> u32 {
        self.inner.pins()
    }
    /// Number of lobes zc = zp - 1.
    #[getter]
    fn lobes(&self) -> u32 {
        self.inner.lobes()
    }
    /// Eccentricity e [m].
    #[getter]
    fn eccentricity(&self) -> f64 {
        self.inner.params().eccentricity
    }
    /// Pin circle radius rp [m].
    #[getter]
    fn pin_circle_radius(&self) -> f64 {
        self.inner.params().pin_circle_radius
    }
    /// Pin radius rrp [m].
    #[getter]
    fn pin_radius(&self) -> f64 {
        self.inner.params().pin_radius
    }
    /// Disc face width [m].
    #[getter]
    fn face_width(&self) -> f64 {
        self.inner.params().face_width
    }
    /// Shift modification d_rp [m].
    #[getter]
    fn d_rp(&self) -> f64 {
        self.inner.params().d_rp
    }
    /// Equidistant modification d_rrp [m].
    #[getter]
    fn d_rrp(&self) -> f64 {
        self.inner.params().d_rrp
    }
    /// Rotation modification d_delta [rad].
    #[getter]
    fn d_delta(&self) -> f64 {
        self.inner.params().d_delta
    }
    /// Curtate ratio K1 = e zp / (rp + d_rp) of the ground profile [-].
    #[getter]
    fn k1(&self) -> f64 {
        self.inner.k1()
    }
    /// Pitch radius of the disc rc' = e zc [m].
    #[getter]
    fn pitch_radius(&self) -> f64 {
        self.inner.pitch_radius()
    }
    /// Minimum convex radius of curvature of the pin-centre curve [m] (the undercut limit for
    /// rrp + d_rrp).
    #[getter]
    fn min_convex_radius(&self) -> f64 {
        self.inner.min_convex_radius()
    }

    /// Points of the actual (ground) profile, disc frame.
    ///
    /// Parameters
    /// ----------
    /// phi : float or array_like of any shape
    ///     Curve parameter [rad].
    ///
    /// Returns
    /// -------
    /// numpy.ndarray, shape phi.shape + (2,)
    ///     (x, y) [m]; shape (2,) for a scalar phi, (n, 2) for n angles.
    fn profile<'py>(&self, py: Python<'py>, phi: FloatArray<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.map_angles::<2>(py, "profile", &phi, |g, p| Ok(g.profile_point(p)))
    }

    /// Outward unit normals of the profile, disc frame.
    ///
    /// Parameters
    /// ----------
    /// phi : float or array_like of any shape
    ///     Curve parameter [rad].
    ///
    /// Returns
    /// -------
    /// numpy.ndarray, shape phi.shape + (2,)
    ///     Unit vectors (x, y) [-], pointing from the disc material to the pins.
    fn normal<'py>(&self, py: Python<'py>, phi: FloatArray<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.map_angles::<2>(py, "normal", &phi, |g, p| Ok(g.normal(p)))
    }

    /// Signed radius of curvature of the profile [m]: positive where convex (lobe flanks and
    /// tips), negative where concave (around the roots; -10.72 mm at the root of the paper
    /// disc).
    ///
    /// Parameters
    /// ----------
    /// phi : float or array_like of any shape
    ///     Curve parameter [rad].
    ///
    /// Returns
    /// -------
    /// float or numpy.ndarray of shape phi.shape
    ///     Radius of curvature [m].
    fn curvature_radius<'py>(
        &self,
        py: Python<'py>,
        phi: FloatArray<'py>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.map_angles::<1>(py, "curvature_radius", &phi, |g, p| {
            finite_curvature_radius(g.curvature_radius(p), p)
        })
    }

    /// Exact signed gap between one pin and the profile of this disc placed in the fixed frame.
    ///
    /// Parameters
    /// ----------
    /// pin_center : array_like, shape (2,)
    ///     Pin centre [m], fixed frame.
    /// disc_center : array_like, shape (2,)
    ///     Disc centre [m], fixed frame.
    /// disc_angle : float
    ///     Disc rotation [rad], counter-clockwise.
    /// pin_radius : float, optional
    ///     Radius of this pin [m] (e.g. with a pin size error); the disc's pin radius if None.
    ///
    /// Returns
    /// -------
    /// GapResult
    ///     gap [m] (negative = penetration), point (2,) [m] contact point on the profile,
    ///     normal (2,) outward unit normal, phi [rad] curve parameter in [0, 2 pi),
    ///     curvature_radius [m] signed (positive convex).
    ///
    /// Raises
    /// ------
    /// ParameterError
    ///     For non-finite inputs or a non-positive pin_radius.
    /// ConvergenceError
    ///     If the pin centre is so far from the profile that the nearest point is not unique.
    #[pyo3(signature = (pin_center, disc_center, disc_angle, pin_radius=None))]
    fn gap<'py>(
        &self,
        py: Python<'py>,
        pin_center: FloatArray<'py>,
        disc_center: FloatArray<'py>,
        disc_angle: Real,
        pin_radius: Option<Real>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let pin = point2("pin_center", "m", &pin_center)?;
        let centre = point2("disc_center", "m", &disc_center)?;
        let result = match pin_radius {
            None => self.inner.gap(pin, centre, disc_angle.0)?,
            Some(r) => self
                .inner
                .gap_with_pin_radius(pin, r.0, centre, disc_angle.0)?,
        };
        gap_result(py, &result)
    }

    /// Pin centres in the fixed frame.
    ///
    /// Returns
    /// -------
    /// numpy.ndarray, shape (zp, 2)
    ///     (x, y) [m]; row j is the pin at angle 2 pi j / zp from +x, the paper's pin j + 1.
    fn pin_positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let n = self.inner.pins() as usize;
        let rp = self.inner.params().pin_circle_radius;
        let mut values = Vec::with_capacity(2 * n);
        for j in 0..n {
            let (s, c) = self.inner.pin_angle(j).sin_cos();
            values.extend_from_slice(&[rp * c, rp * s]);
        }
        output(py, &[n, 2], values)
    }

    /// Classical quasi-static pin forces [N], shape (zp,), of the unmodified disc carrying
    /// `disc_torque` [N m] about its centre with its centre at crank angle `crank_angle` [rad]
    /// (docs/model.md#lever-arms-and-the-classical-load-sharing: F_j = T l_j / sum l^2 on the
    /// loaded half, the pins with lever of the torque's sign). A positive output torque of the
    /// reducer loads the pins with negative lever: compare `ltca(scene, +T)` with
    /// `classical_pin_forces(-T_c, psi)`.
    fn classical_pin_forces<'py>(
        &self,
        py: Python<'py>,
        disc_torque: Real,
        crank_angle: Real,
    ) -> PyResult<Bound<'py, PyAny>> {
        let f = crate::analysis::classical_pin_forces(&self.inner, disc_torque.0, crank_angle.0)?;
        output(py, &[f.len()], f)
    }

    /// Classical levers l_j = rc' sin(phi_j)/S_j [m], shape (zp,), of the contact normals
    /// about the disc centre at crank angle `crank_angle` [rad].
    fn classical_levers<'py>(
        &self,
        py: Python<'py>,
        crank_angle: Real,
    ) -> PyResult<Bound<'py, PyAny>> {
        let crank_angle = crate::error::require_finite("crank_angle", crank_angle.0)?;
        let l = crate::analysis::classical_levers(&self.inner, crank_angle);
        output(py, &[l.len()], l)
    }

    /// Rigid-body (kinematic) pose of the disc at crank angle psi, meshing exactly with the
    /// pins: centre e (cos psi, sin psi), rotation -psi / zc.
    ///
    /// Parameters
    /// ----------
    /// psi : float
    ///     Crank (eccentric) angle [rad].
    ///
    /// Returns
    /// -------
    /// (numpy.ndarray of shape (2,), float)
    ///     Disc centre [m] and disc angle [rad].
    fn kinematic_pose<'py>(&self, py: Python<'py>, psi: Real) -> PyResult<Bound<'py, PyTuple>> {
        let psi = psi.0;
        if !psi.is_finite() {
            return Err(parameter_error(format!(
                "psi must be a finite crank angle [rad], got {}",
                crate::error::num(psi)
            )));
        }
        let e = self.inner.params().eccentricity;
        let (s, c) = psi.sin_cos();
        let angle = -psi / f64::from(self.inner.lobes());
        PyTuple::new(
            py,
            [
                vec2(py, [e * c, e * s]),
                angle.into_pyobject(py)?.into_any(),
            ],
        )
    }

    /// Mass [kg] and polar moment of inertia about the disc centre [kg m^2] of the solid disc:
    /// exact profile area times face width and density, minus the default holes (40 mm bore,
    /// 3 crank holes r = 25 mm and 3 pillar holes r = 20 mm on a 90 mm circle).
    ///
    /// Parameters
    /// ----------
    /// density : float
    ///     Material density [kg/m^3], steel 7850 by default.
    ///
    /// Returns
    /// -------
    /// (float, float)
    ///     (mass [kg], inertia [kg m^2]).
    // The text signature spells out STEEL_DENSITY (tests/test_geometry.py checks they agree).
    #[pyo3(signature = (density=Real(STEEL_DENSITY)), text_signature = "($self, density=7850.0)")]
    fn mass_properties(&self, density: Real) -> PyResult<(f64, f64)> {
        let mp = disc_mass_properties(&self.inner, &DiscHoles::paper(), density.0)?;
        Ok((mp.mass, mp.inertia))
    }

    fn __repr__(&self) -> String {
        let p = self.inner.params();
        let mut s = format!(
            "CycloidGeometry(pins={}, eccentricity={:?}, pin_circle_radius={:?}, pin_radius={:?}, \
             face_width={:?}",
            p.pins, p.eccentricity, p.pin_circle_radius, p.pin_radius, p.face_width
        );
        for (name, v) in [("d_rp", p.d_rp), ("d_rrp", p.d_rrp), ("d_delta", p.d_delta)] {
            if v != 0.0 {
                s.push_str(&format!(", {name}={v:?}"));
            }
        }
        s.push(')');
        s
    }

    /// Support for pickle and copy: rebuild from the constructor arguments.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let p = *slf.get().inner.params();
        let args = (
            p.pins,
            p.eccentricity,
            p.pin_circle_radius,
            p.pin_radius,
            p.face_width,
            p.d_rp,
            p.d_rrp,
            p.d_delta,
        )
            .into_pyobject(py)?;
        PyTuple::new(py, [slf.get_type().into_any(), args.into_any()])
    }
}

/// The involute first stage: a sun and equally spaced planets on the crankshafts (SI units).
///
/// InvoluteStage(z_sun, z_planet, planets, module, pressure_angle, face_width, backlash=0.0)
///
/// Standard full-depth spur gears (addendum = module, no profile shift); the centre distance
/// m (z_sun + z_planet) / 2 is the crank circle radius.
///
/// Parameters
/// ----------
/// z_sun, z_planet : int
///     Teeth of the sun and of each planet (>= 5).
/// planets : int
///     Number of planets (equally spaced, >= 1).
/// module : float
///     Module m [m].
/// pressure_angle : float
///     Pressure angle [rad], in (0, 45 deg).
/// face_width : float
///     Gear face width [m].
/// backlash : float
///     Total backlash of one mesh along the line of action [m], >= 0.
///
/// Raises
/// ------
/// GeometryError
///     Too few teeth, no planet, colliding planets (tip circles overlap), involute
///     interference (a tip reaching below the other gear's base circle), contact ratio < 1.
/// ParameterError
///     Non-finite or non-positive sizes, pressure angle out of range, negative backlash.
#[pyclass(name = "InvoluteStage", module = "rvdyn", frozen)]
pub(crate) struct PyInvoluteStage {
    inner: InvoluteStage,
}

#[pymethods]
impl PyInvoluteStage {
    #[new]
    #[pyo3(
        signature = (z_sun, z_planet, planets, module, pressure_angle, face_width, backlash=Real(0.0)),
        text_signature = "(z_sun, z_planet, planets, module, pressure_angle, face_width, backlash=0.0)"
    )]
    fn new(
        z_sun: Whole,
        z_planet: Whole,
        planets: Whole,
        module: Real,
        pressure_angle: Real,
        face_width: Real,
        backlash: Real,
    ) -> PyResult<Self> {
        let inner = InvoluteStage::new(
            count("z_sun", z_sun)?,
            count("z_planet", z_planet)?,
            count("planets", planets)?,
            module.0,
            pressure_angle.0,
            face_width.0,
        )?
        .with_backlash(backlash.0)?;
        Ok(Self { inner })
    }

    /// The paper's first stage: z_sun 18, z_planet 42, 3 planets (given); module 3 mm,
    /// pressure angle 20 deg, face width 30 mm (assumed, docs/model.md#default-scene); no backlash.
    #[classmethod]
    fn paper(_cls: &Bound<'_, PyType>) -> PyResult<Self> {
        Ok(Self {
            inner: InvoluteStage::new(18, 42, 3, 3e-3, 20f64.to_radians(), 0.030)?,
        })
    }

    /// Sun teeth.
    #[getter]
    fn z_sun(&self) -> u32 {
        self.inner.z_sun
    }
    /// Teeth of each planet.
    #[getter]
    fn z_planet(&self) -> u32 {
        self.inner.z_planet
    }
    /// Number of planets.
    #[getter]
    fn planets(&self) -> u32 {
        self.inner.planets
    }
    /// Module [m].
    #[getter]
    fn module(&self) -> f64 {
        self.inner.module
    }
    /// Pressure angle [rad].
    #[getter]
    fn pressure_angle(&self) -> f64 {
        self.inner.pressure_angle
    }
    /// Face width [m].
    #[getter]
    fn face_width(&self) -> f64 {
        self.inner.face_width
    }
    /// Total backlash of one mesh along the line of action [m].
    #[getter]
    fn backlash(&self) -> f64 {
        self.inner.backlash
    }
    /// Sun pitch radius m z_sun / 2 [m].
    #[getter]
    fn sun_pitch_radius(&self) -> f64 {
        self.inner.sun_pitch_radius()
    }
    /// Planet pitch radius m z_planet / 2 [m].
    #[getter]
    fn planet_pitch_radius(&self) -> f64 {
        self.inner.planet_pitch_radius()
    }
    /// Sun base radius [m].
    #[getter]
    fn sun_base_radius(&self) -> f64 {
        self.inner.sun_base_radius()
    }
    /// Planet base radius [m].
    #[getter]
    fn planet_base_radius(&self) -> f64 {
        self.inner.planet_base_radius()
    }
    /// Centre distance = crank circle radius [m].
    #[getter]
    fn centre_distance(&self) -> f64 {
        self.inner.centre_distance()
    }
    /// Addendum (= module) [m].
    #[getter]
    fn addendum(&self) -> f64 {
        self.inner.addendum()
    }
    /// Sun tip radius [m].
    #[getter]
    fn sun_tip_radius(&self) -> f64 {
        self.inner.sun_tip_radius()
    }
    /// Planet tip radius [m].
    #[getter]
    fn planet_tip_radius(&self) -> f64 {
        self.inner.planet_tip_radius()
    }
    /// Length of the path of contact along the line of action [m].
    #[getter]
    fn line_of_action_length(&self) -> f64 {
        self.inner.line_of_action_length()
    }
    /// Transverse contact ratio [-] (mean number of tooth pairs in mesh).
    #[getter]
    fn contact_ratio(&self) -> f64 {
        self.inner.contact_ratio()
    }
    /// Fixed-carrier stage ratio -z_planet / z_sun [-] (paper eq. 1).
    #[getter]
    fn stage_ratio(&self) -> f64 {
        self.inner.stage_ratio()
    }
    /// Angles of the planet centres about the axis in the carrier frame [rad], shape
    /// (planets,), planet 0 on +x.
    #[getter]
    fn planet_angles<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let angles = self.inner.planet_angles();
        let n = angles.len();
        output(py, &[n], angles)
    }

    fn __repr__(&self) -> String {
        let s = &self.inner;
        let mut r = format!(
            "InvoluteStage(z_sun={}, z_planet={}, planets={}, module={:?}, pressure_angle={:?}, \
             face_width={:?}",
            s.z_sun, s.z_planet, s.planets, s.module, s.pressure_angle, s.face_width
        );
        if s.backlash != 0.0 {
            r.push_str(&format!(", backlash={:?}", s.backlash));
        }
        r.push(')');
        r
    }

    /// Support for pickle and copy: rebuild from the constructor arguments.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let s = &slf.get().inner;
        let args = (
            s.z_sun,
            s.z_planet,
            s.planets,
            s.module,
            s.pressure_angle,
            s.face_width,
            s.backlash,
        )
            .into_pyobject(py)?;
        PyTuple::new(py, [slf.get_type().into_any(), args.into_any()])
    }
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyCycloidGeometry>()?;
    m.add_class::<PyInvoluteStage>()?;
    Ok(())
}
