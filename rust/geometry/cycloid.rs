//! The exact cycloid disc: pin-centre curve, actual profile, normals, curvature, validity rules.
//!
//! Disc frame, origin at the disc centre, parameter `phi` (rad). With the generating radius
//! `R = rp + d_rp`, generating pin radius `r = rrp + d_rrp` and curtate ratio `K1 = e zp / R`:
//!
//! - pin-centre curve `C(phi) = R (cos phi, sin phi) - e (cos zp phi, sin zp phi)`;
//! - outward unit normal `n = (cos phi - K1 cos zp phi, sin phi - K1 sin zp phi) / S`,
//!   `S = sqrt(1 + K1^2 - 2 K1 cos(zc phi))`;
//! - actual profile `P = C - r n`, turned by the rotation modification `d_delta`.
//!
//! `phi = 0` is a tooth root (valley), `zc phi = pi` a lobe tip. The pins stay on the circle
//! `rp` with radius `rrp`; the modifications only change the ground profile.

use crate::error::{
    Result, RvdynError, num, require_finite, require_non_negative, require_positive,
};
use crate::geometry::profile_seed::ProfileSeed;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Most pins a disc may have. Real cycloid drives have about 10 to 100; the bound keeps the
/// work and memory of a geometry (a polyline of 48 vertices per lobe, one state per pin in a
/// run) finite for any accepted input.
pub const MAX_PINS: u32 = 1000;

/// Smallest length accepted for a size of the reducer \[m\] (1 nm).
pub const MIN_LENGTH: f64 = 1e-9;

/// Largest length accepted for a size of the reducer \[m\] (1 km). Between [`MIN_LENGTH`] and
/// this, every formula of the geometry (up to fourth powers of lengths, for the polar moment of
/// area) stays far inside the range of `f64`, so no result over- or underflows.
pub const MAX_LENGTH: f64 = 1e3;

/// `value` if it is a finite length in `[MIN_LENGTH, MAX_LENGTH]` \[m\], else
/// `RvdynError::Parameter` naming it and the range.
pub fn require_length(name: &str, value: f64) -> Result<f64> {
    require_positive(name, value, "m")?;
    if (MIN_LENGTH..=MAX_LENGTH).contains(&value) {
        Ok(value)
    } else {
        Err(RvdynError::Parameter(format!(
            "{name} = {} m is outside the supported range [{}, {}] m of reducer sizes",
            num(value),
            num(MIN_LENGTH),
            num(MAX_LENGTH)
        )))
    }
}

/// Check the radius of every pin with its size error: `pin_radius + errors[j]` must be a
/// length of at least [`MIN_LENGTH`] (a pin of zero or negative radius has no surface to
/// touch). `errors` is empty (no errors) or one value per pin \[m\].
///
/// Errors (`RvdynError::Geometry`) name the first pin that breaks the rule, its error and
/// the resulting radius.
pub fn check_pin_radii(pin_radius: f64, errors: &[f64]) -> Result<()> {
    for (j, &err) in errors.iter().enumerate() {
        let r = pin_radius + err;
        if !(r.is_finite() && r >= MIN_LENGTH) {
            return Err(RvdynError::Geometry(format!(
                "pin_errors.radius[{j}] = {} m makes pin {} (index {j}) {} m in radius \
                 (pin_radius {} m + error); every pin radius must be > 0: use an error above {} m",
                num(err),
                j + 1,
                num(r),
                num(pin_radius),
                num(-pin_radius)
            )));
        }
    }
    Ok(())
}

/// Profile error of a disc: a normal offset `delta(phi)` of the ground profile \[m\] as a function
/// of the curve parameter `phi` (rad; the polar angle of the pin-centre curve point in the
/// disc frame, before the rotation modification), positive = material added (outward), so
/// that every gap shrinks by `delta` at the contact (the opposite sign of `d_rrp`: a constant
/// offset `a` is the equidistant modification `d_rrp = -a`). The sum of harmonics
/// `a cos(n phi + p)` and a periodic table, each optional.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProfileError {
    /// `[amplitude \[m\], order n (integer >= 0), phase p \[rad\]]` of each harmonic
    /// `a cos(n phi + p)`.
    #[serde(default)]
    pub harmonics: Vec<[f64; 3]>,
    /// `[phi \[rad\], offset \[m\]]` points, `phi` strictly increasing in `[0, 2 pi)`; linear in
    /// between and periodic (the last point joins the first across `2 pi`).
    #[serde(default)]
    pub table: Vec<[f64; 2]>,
}

impl ProfileError {
    /// Largest `|delta|` the model accepts, as a fraction of the pin radius (a tenth: the
    /// penetration bound of a run).
    pub const LIMIT_FRACTION: f64 = 0.1;

    /// Whether the error is identically zero (no harmonic and no table).
    pub fn is_empty(&self) -> bool {
        self.harmonics.is_empty() && self.table.is_empty()
    }

    /// Check the fields; `at` names the field (`"discs[0].profile_error"`) in the message.
    /// Every number finite, orders non-negative integers, table angles strictly increasing in
    /// `[0, 2 pi)`, and `sum |a| + max |table|` below `limit` \[m\].
    pub fn check(&self, at: &str, limit: f64) -> Result<()> {
        let bad = |m: String| Err(RvdynError::Scene(format!("{at}.{m}")));
        for (i, h) in self.harmonics.iter().enumerate() {
            if !h.iter().all(|v| v.is_finite()) {
                return bad(format!("harmonics[{i}] must be finite numbers, got {h:?}"));
            }
            if !(h[1] >= 0.0 && h[1].fract() == 0.0 && h[1] <= 1e6) {
                return bad(format!(
                    "harmonics[{i}] order must be an integer >= 0 (the error is periodic over \
                     the disc), got {}",
                    h[1]
                ));
            }
        }
        for (i, p) in self.table.iter().enumerate() {
            if !p.iter().all(|v| v.is_finite()) {
                return bad(format!("table[{i}] must be finite numbers, got {p:?}"));
            }
            if !(0.0..2.0 * PI).contains(&p[0]) {
                return bad(format!(
                    "table[{i}] angle must be in [0, 2 pi) rad, got {}",
                    p[0]
                ));
            }
        }
        if self.table.windows(2).any(|w| w[1][0] <= w[0][0]) {
            return bad("table angles must increase strictly".into());
        }
        let size = self.harmonics.iter().map(|h| h[0].abs()).sum::<f64>()
            + self.table.iter().map(|p| p[1].abs()).fold(0.0, f64::max);
        if size >= limit {
            return bad(format!(
                "offset bound sum |a| + max |table| = {} m must be below {} m (a tenth of the \
                 pin radius)",
                num(size),
                num(limit)
            ));
        }
        Ok(())
    }

    /// The offset `delta(phi)` \[m\] and its slope `d delta / d phi` [m/rad].
    pub fn offset(&self, phi: f64) -> (f64, f64) {
        let mut d = 0.0;
        let mut s = 0.0;
        for h in &self.harmonics {
            let (sn, cs) = (h[1] * phi + h[2]).sin_cos();
            d += h[0] * cs;
            s -= h[0] * h[1] * sn;
        }
        let (td, ts) = periodic_table(&self.table, phi);
        (d + td, s + ts)
    }
}

/// Value and slope of a periodic piecewise-linear table `[x, y]` (x in `[0, 2 pi)`, strictly
/// increasing) at `x` (any real): the last point joins the first across `2 pi`. Empty: 0.
pub fn periodic_table(points: &[[f64; 2]], x: f64) -> (f64, f64) {
    match points {
        [] => (0.0, 0.0),
        [only] => (only[1], 0.0),
        _ => {
            let tau = 2.0 * PI;
            let x = x.rem_euclid(tau);
            let n = points.len();
            // Segment [a, b] containing x, with b wrapped across 2 pi for the last one.
            let i = points.partition_point(|p| p[0] <= x);
            let (a, b) = if i == 0 {
                ([points[n - 1][0] - tau, points[n - 1][1]], points[0])
            } else if i == n {
                (points[n - 1], [points[0][0] + tau, points[0][1]])
            } else {
                (points[i - 1], points[i])
            };
            let slope = (b[1] - a[1]) / (b[0] - a[0]);
            (a[1] + slope * (x - a[0]), slope)
        }
    }
}

/// The parameters that define a cycloid disc and its pin ring (SI units).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CycloidParams {
    /// Number of pins `zp` (the disc has `zp - 1` lobes).
    pub pins: u32,
    /// Eccentricity `e` \[m\].
    pub eccentricity: f64,
    /// Pin circle radius `rp` \[m\].
    pub pin_circle_radius: f64,
    /// Pin radius `rrp` \[m\].
    pub pin_radius: f64,
    /// Disc face width \[m\].
    pub face_width: f64,
    /// Shift modification `d_rp` \[m\] (grinding convention: `rp -> rp + d_rp`).
    #[serde(default)]
    pub d_rp: f64,
    /// Equidistant modification `d_rrp` \[m\] (`rrp -> rrp + d_rrp`; positive removes material).
    #[serde(default)]
    pub d_rrp: f64,
    /// Rotation modification `d_delta` \[rad\] (the profile turned by this angle).
    #[serde(default)]
    pub d_delta: f64,
}

impl CycloidParams {
    /// The default disc of the paper's scene (docs/model.md#default-scene): 24 pins and
    /// e = 4.5 mm are given; rp = 150 mm, rrp = 10 mm and the 40 mm face width are assumed;
    /// no modification.
    pub fn paper() -> Self {
        Self {
            pins: 24,
            eccentricity: 4.5e-3,
            pin_circle_radius: 0.150,
            pin_radius: 0.010,
            face_width: 0.040,
            d_rp: 0.0,
            d_rrp: 0.0,
            d_delta: 0.0,
        }
    }
}

/// A validated cycloid disc with its exact profile and the polyline used to seed gap queries.
#[derive(Clone)]
pub struct CycloidGeometry {
    params: CycloidParams,
    zp: f64,
    zc: f64,
    /// Generating radius `rp + d_rp` \[m\].
    gen_radius: f64,
    /// Generating pin radius `rrp + d_rrp` \[m\].
    gen_pin_radius: f64,
    k1: f64,
    min_convex_radius: f64,
    pub(crate) seed: ProfileSeed,
}

impl std::fmt::Debug for CycloidGeometry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CycloidGeometry")
            .field("params", &self.params)
            .field("k1", &self.k1)
            .field("min_convex_radius", &self.min_convex_radius)
            .finish()
    }
}

/// Points, first and second derivatives of the pin-centre curve at one parameter.
#[derive(Debug, Clone, Copy)]
pub(crate) struct CurveJet {
    pub c: [f64; 2],
    pub d1: [f64; 2],
    pub d2: [f64; 2],
}

impl CycloidGeometry {
    /// Build and validate a disc.
    ///
    /// Errors (`RvdynError::Geometry`) name the rule broken and its limit: fewer than 3 pins,
    /// curtate ratio `K1 = e zp / (rp + d_rp) >= 1`, overlapping pins (`rp sin(pi/zp) <= rrp`),
    /// undercut (`rrp + d_rrp >=` the minimum convex radius of curvature of the pin-centre curve),
    /// no material left at the root. Non-finite or non-positive sizes give
    /// `RvdynError::Parameter`.
    ///
    /// ```
    /// use rvdyn::geometry::{CycloidGeometry, cycloid::CycloidParams};
    /// let g = CycloidGeometry::new(CycloidParams {
    ///     pins: 24, eccentricity: 4.5e-3, pin_circle_radius: 0.150, pin_radius: 0.010,
    ///     face_width: 0.040, d_rp: 0.0, d_rrp: 0.0, d_delta: 0.0,
    /// }).unwrap();
    /// assert_eq!(g.lobes(), 23);
    /// assert!((g.k1() - 0.72).abs() < 1e-12);
    /// ```
    pub fn new(params: CycloidParams) -> Result<Self> {
        let mut g = Self::unseeded(params)?;
        g.seed = ProfileSeed::build(&g, 48);
        Ok(g)
    }

    /// Check `params` against every rule of [`CycloidGeometry::new`] without building the
    /// profile polyline (for validating scenes).
    pub fn check(params: CycloidParams) -> Result<()> {
        Self::unseeded(params).map(|_| ())
    }

    /// A validated disc without its seed polyline.
    fn unseeded(params: CycloidParams) -> Result<Self> {
        let p = params;
        if p.pins < 3 {
            return Err(RvdynError::Geometry(format!(
                "a cycloid drive needs at least 3 pins, got {}",
                p.pins
            )));
        }
        if p.pins > MAX_PINS {
            return Err(RvdynError::Geometry(format!(
                "at most {MAX_PINS} pins are supported, got {} (real cycloid drives have about \
                 10 to 100)",
                p.pins
            )));
        }
        require_length("eccentricity", p.eccentricity)?;
        require_length("pin_circle_radius", p.pin_circle_radius)?;
        require_length("pin_radius", p.pin_radius)?;
        require_length("face_width", p.face_width)?;
        require_finite("d_rp", p.d_rp)?;
        require_finite("d_rrp", p.d_rrp)?;
        require_finite("d_delta", p.d_delta)?;
        let zp = f64::from(p.pins);
        let zc = zp - 1.0;
        let gen_radius = p.pin_circle_radius + p.d_rp;
        let gen_pin_radius = p.pin_radius + p.d_rrp;
        require_length("pin_circle_radius + d_rp", gen_radius)?;
        require_length("pin_radius + d_rrp", gen_pin_radius)?;
        let k1 = p.eccentricity * zp / gen_radius;
        if k1 >= 1.0 {
            return Err(RvdynError::Geometry(format!(
                "curtate ratio K1 = e*zp/(rp+d_rp) = {k1:.4} must be < 1 (the pin-centre curve \
                 loops otherwise): reduce the eccentricity below {} m or enlarge the pin circle",
                num(gen_radius / zp)
            )));
        }
        let spacing = p.pin_circle_radius * (PI / zp).sin();
        if spacing <= p.pin_radius {
            return Err(RvdynError::Geometry(format!(
                "pins overlap: rp*sin(pi/zp) = {spacing:.6e} m must exceed the pin radius \
                 {:.6e} m; use smaller pins, fewer pins or a larger pin circle",
                p.pin_radius
            )));
        }
        let min_convex_radius = min_convex_radius_of(k1, zp, gen_radius);
        if gen_pin_radius >= min_convex_radius {
            return Err(RvdynError::Geometry(format!(
                "undercut: the generating pin radius rrp+d_rrp = {gen_pin_radius:.6e} m must be \
                 below the minimum convex radius of curvature of the pin-centre curve \
                 {min_convex_radius:.6e} m (the profile would form a cusp); use smaller pins or \
                 a smaller curtate ratio K1"
            )));
        }
        let root = gen_radius - p.eccentricity - gen_pin_radius;
        require_non_negative("root radius rp+d_rp-e-rrp-d_rrp", root, "m").map_err(|_| {
            RvdynError::Geometry(format!(
                "no material at the tooth root: rp+d_rp-e-rrp-d_rrp = {root:.6e} m must be > 0"
            ))
        })?;
        Ok(Self {
            params,
            zp,
            zc,
            gen_radius,
            gen_pin_radius,
            k1,
            min_convex_radius,
            seed: ProfileSeed::empty(),
        })
    }

    /// The parameters this disc was built from.
    pub fn params(&self) -> &CycloidParams {
        &self.params
    }
    /// Number of pins `zp`.
    pub fn pins(&self) -> u32 {
        self.params.pins
    }
    /// Number of lobes `zc = zp - 1`.
    pub fn lobes(&self) -> u32 {
        self.params.pins - 1
    }
    /// Curtate ratio `K1 = e zp / (rp + d_rp)` of the ground profile (dimensionless).
    pub fn k1(&self) -> f64 {
        self.k1
    }
    /// Minimum convex radius of curvature of the pin-centre curve \[m\] (undercut limit).
    pub fn min_convex_radius(&self) -> f64 {
        self.min_convex_radius
    }
    /// Generating pin radius `rrp + d_rrp` \[m\]: the offset from the pin-centre curve to the profile.
    pub fn generating_pin_radius(&self) -> f64 {
        self.gen_pin_radius
    }
    /// Pitch radius of the disc `rc' = e zc` \[m\].
    pub fn pitch_radius(&self) -> f64 {
        self.params.eccentricity * self.zc
    }
    /// Angle of pin `j` (0-based; the paper's pin `j + 1`) in the fixed frame \[rad\].
    pub fn pin_angle(&self, j: usize) -> f64 {
        2.0 * PI * j as f64 / self.zp
    }

    /// Pin-centre curve and its first two derivatives at `phi` (unrotated disc frame).
    #[inline]
    pub(crate) fn jet(&self, phi: f64) -> CurveJet {
        let (s1, c1) = phi.sin_cos();
        self.jet_cs(c1, s1)
    }

    /// As [`CycloidGeometry::jet`] from `cos phi` and `sin phi`.
    #[inline]
    pub(crate) fn jet_cs(&self, c1: f64, s1: f64) -> CurveJet {
        // (cos zp phi, sin zp phi) as the zp-th power of (cos phi, sin phi): half the cost of a
        // second sin_cos, relative error ~zp * eps (1e-17 m at the default eccentricity).
        let (cz, sz) = complex_pow(c1, s1, self.params.pins);
        let r = self.gen_radius;
        let e = self.params.eccentricity;
        let ez = e * self.zp;
        let ez2 = ez * self.zp;
        CurveJet {
            c: [r * c1 - e * cz, r * s1 - e * sz],
            d1: [-r * s1 + ez * sz, r * c1 - ez * cz],
            d2: [-r * c1 + ez2 * cz, -r * s1 + ez2 * sz],
        }
    }

    /// Outward unit normal of the curve at `phi` from its tangent (unrotated disc frame).
    #[inline]
    pub(crate) fn normal_from_tangent(d1: [f64; 2]) -> [f64; 2] {
        // |C'| = rp S >= rp (1 - K1) > 0: no overflow or underflow, so no need for hypot.
        let len = (d1[0] * d1[0] + d1[1] * d1[1]).sqrt();
        [d1[1] / len, -d1[0] / len]
    }

    /// Rotate a disc-frame vector by the rotation modification `d_delta`.
    #[inline]
    pub(crate) fn apply_rotation_mod(&self, v: [f64; 2]) -> [f64; 2] {
        if self.params.d_delta == 0.0 {
            return v;
        }
        let (s, c) = self.params.d_delta.sin_cos();
        [c * v[0] - s * v[1], s * v[0] + c * v[1]]
    }

    /// Undo the rotation modification on a disc-frame vector.
    #[inline]
    pub(crate) fn remove_rotation_mod(&self, v: [f64; 2]) -> [f64; 2] {
        if self.params.d_delta == 0.0 {
            return v;
        }
        let (s, c) = self.params.d_delta.sin_cos();
        [c * v[0] + s * v[1], -s * v[0] + c * v[1]]
    }

    /// Point of the actual (ground) profile at curve parameter `phi`, disc frame \[m\].
    ///
    /// ```
    /// # use rvdyn::geometry::{CycloidGeometry, cycloid::CycloidParams};
    /// # let g = CycloidGeometry::new(CycloidParams { pins: 24, eccentricity: 4.5e-3,
    /// #   pin_circle_radius: 0.15, pin_radius: 0.01, face_width: 0.04,
    /// #   d_rp: 0.0, d_rrp: 0.0, d_delta: 0.0 }).unwrap();
    /// let root = g.profile_point(0.0); // tooth root on +x: rp - e - rrp
    /// assert!((root[0] - 0.1355).abs() < 1e-12 && root[1].abs() < 1e-15);
    /// ```
    pub fn profile_point(&self, phi: f64) -> [f64; 2] {
        self.apply_rotation_mod(self.unrotated_profile_point(phi))
    }

    /// Profile point before the rotation modification is applied.
    pub(crate) fn unrotated_profile_point(&self, phi: f64) -> [f64; 2] {
        let j = self.jet(phi);
        let n = Self::normal_from_tangent(j.d1);
        let r = self.gen_pin_radius;
        [j.c[0] - r * n[0], j.c[1] - r * n[1]]
    }

    /// Outward unit normal of the profile at `phi`, disc frame.
    pub fn normal(&self, phi: f64) -> [f64; 2] {
        let j = self.jet(phi);
        self.apply_rotation_mod(Self::normal_from_tangent(j.d1))
    }

    /// Signed curvature of the pin-centre curve at `phi` [1/m] (positive convex).
    pub fn centre_curve_curvature(&self, phi: f64) -> f64 {
        let j = self.jet(phi);
        let cross = j.d1[0] * j.d2[1] - j.d1[1] * j.d2[0];
        let len = j.d1[0].hypot(j.d1[1]);
        cross / (len * len * len)
    }

    /// Signed radius of curvature of the actual profile at `phi` \[m\]: positive where the
    /// profile is convex (lobe flank and tip), negative where concave (around the root).
    /// Equals `1/kappa_C - (rrp + d_rrp)`.
    pub fn curvature_radius(&self, phi: f64) -> f64 {
        1.0 / self.centre_curve_curvature(phi) - self.gen_pin_radius
    }

    /// Area [m^2] and polar second moment of area about the disc centre [m^4] of the solid
    /// bounded by the profile (no holes). Green's theorem with the exact tangent
    /// `P' = C' (1 - r kappa_C)`; the trapezoid rule on a periodic analytic integrand converges
    /// geometrically: `samples_per_lobe = 128` is within 1e-12 of converged.
    pub fn profile_area_moments(&self, samples_per_lobe: usize) -> (f64, f64) {
        let n = samples_per_lobe.max(16) * self.lobes() as usize;
        let h = 2.0 * PI / n as f64;
        let (mut area, mut polar) = (0.0, 0.0);
        for i in 0..n {
            let phi = i as f64 * h;
            let j = self.jet(phi);
            let scale = 1.0 - self.gen_pin_radius * self.centre_curve_curvature(phi);
            let p = self.unrotated_profile_point(phi);
            let d = [j.d1[0] * scale, j.d1[1] * scale];
            area += 0.5 * (p[0] * d[1] - p[1] * d[0]) * h;
            polar += (p[0].powi(3) * d[1] - p[1].powi(3) * d[0]) / 3.0 * h;
        }
        (area, polar)
    }
}

/// `(c + i s)^n` by binary exponentiation.
#[inline]
fn complex_pow(c: f64, s: f64, mut n: u32) -> (f64, f64) {
    let (mut rc, mut rs) = (1.0, 0.0);
    let (mut bc, mut bs) = (c, s);
    while n > 0 {
        if n & 1 == 1 {
            (rc, rs) = (rc * bc - rs * bs, rc * bs + rs * bc);
        }
        (bc, bs) = (bc * bc - bs * bs, 2.0 * bc * bs);
        n >>= 1;
    }
    (rc, rs)
}

/// Minimum convex radius of curvature of the pin-centre curve \[m\].
///
/// The curvature depends on `c = cos(zc phi)` only:
/// `kappa = [1 + zp K1^2 - K1 (1 + zp) c] / (R S^3)`, `S^2 = 1 + K1^2 - 2 K1 c`.
fn min_convex_radius_of(k1: f64, zp: f64, r: f64) -> f64 {
    let kappa = |c: f64| {
        let s2 = 1.0 + k1 * k1 - 2.0 * k1 * c;
        (1.0 + zp * k1 * k1 - k1 * (1.0 + zp) * c) / (r * s2 * s2.sqrt())
    };
    // Dense scan then golden-section refinement of the largest curvature.
    let n = 4000;
    let mut best = (-1.0, f64::NEG_INFINITY);
    for i in 0..=n {
        let c = -1.0 + 2.0 * i as f64 / n as f64;
        let k = kappa(c);
        if k > best.1 {
            best = (c, k);
        }
    }
    let (mut a, mut b) = (
        (best.0 - 2.0 / n as f64).max(-1.0),
        (best.0 + 2.0 / n as f64).min(1.0),
    );
    let g = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..60 {
        let x1 = b - g * (b - a);
        let x2 = a + g * (b - a);
        if kappa(x1) > kappa(x2) {
            b = x2;
        } else {
            a = x1;
        }
    }
    let kmax = kappa(0.5 * (a + b)).max(best.1);
    if kmax > 0.0 {
        1.0 / kmax
    } else {
        f64::INFINITY
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    pub(crate) fn paper_params() -> CycloidParams {
        CycloidParams::paper()
    }

    #[test]
    fn root_and_tip_radii() {
        let g = CycloidGeometry::new(paper_params()).unwrap();
        let root = g.profile_point(0.0);
        assert!((root[0] - (0.150 - 0.0045 - 0.010)).abs() < 1e-15);
        let tip = g.profile_point(PI / 23.0);
        let r_tip = tip[0].hypot(tip[1]);
        assert!((r_tip - (0.150 + 0.0045 - 0.010)).abs() < 1e-14);
    }

    #[test]
    fn min_convex_radius_matches_the_notes() {
        // docs/model.md#cycloid-geometry: rho_min(convex) = 20.75 mm for the default geometry.
        let g = CycloidGeometry::new(paper_params()).unwrap();
        assert!(
            (g.min_convex_radius() - 20.75e-3).abs() < 0.01e-3,
            "{}",
            g.min_convex_radius()
        );
        // Against a dense sampling of the curvature from the curve derivatives.
        let mut best = f64::INFINITY;
        for i in 0..200_000 {
            let phi = 2.0 * PI * i as f64 / 200_000.0;
            let k = g.centre_curve_curvature(phi);
            if k > 0.0 {
                best = best.min(1.0 / k);
            }
        }
        assert!((best - g.min_convex_radius()).abs() < 1e-9);
    }

    #[test]
    fn root_is_concave_with_the_notes_radius() {
        // docs/model.md#cycloid-geometry: profile radius at the root is -10.72 mm.
        let g = CycloidGeometry::new(paper_params()).unwrap();
        assert!((g.curvature_radius(0.0) + 10.72e-3).abs() < 0.005e-3);
    }

    #[test]
    fn normal_is_unit_and_orthogonal_to_tangent() {
        let g = CycloidGeometry::new(paper_params()).unwrap();
        for i in 0..100 {
            let phi = 0.0731 * i as f64;
            let n = g.normal(phi);
            assert!((n[0].hypot(n[1]) - 1.0).abs() < 1e-14);
            let h = 1e-6;
            let a = g.profile_point(phi - h);
            let b = g.profile_point(phi + h);
            let t = [b[0] - a[0], b[1] - a[1]];
            let tl = t[0].hypot(t[1]);
            assert!((t[0] * n[0] + t[1] * n[1]).abs() / tl < 1e-6);
            // Outward: the normal points away from the centre on average at roots and tips.
        }
        let n0 = g.normal(0.0);
        assert!(n0[0] > 0.99);
    }

    #[test]
    fn counts_and_sizes_are_bounded() {
        // 10**8 pins with nanometre sizes passed every rule and then aborted the process
        // allocating the seed polyline (48 vertices per lobe).
        let mut p = paper_params();
        p.pins = 100_000_000;
        p.eccentricity = 1e-9;
        p.pin_radius = 1e-9;
        let e = CycloidGeometry::new(p).unwrap_err();
        assert!(e.to_string().contains("at most 1000 pins"), "{e}");
        p.pins = MAX_PINS;
        assert!(CycloidGeometry::check(p).is_ok());
        // Sizes at which profile, normal or curvature overflowed are rejected, naming the range.
        for (e, rp, rrp, face) in [
            (1e-303, 1e-300, 1e-302, 1e-300),
            (4.5e157, 1.5e160, 1e159, 4e159),
        ] {
            let q = CycloidParams {
                eccentricity: e,
                pin_circle_radius: rp,
                pin_radius: rrp,
                face_width: face,
                ..paper_params()
            };
            let err = CycloidGeometry::new(q).unwrap_err().to_string();
            assert!(err.contains("outside the supported range"), "{err}");
        }
        let q = CycloidParams {
            d_rp: 1e300,
            ..paper_params()
        };
        assert!(matches!(
            CycloidGeometry::new(q),
            Err(RvdynError::Parameter(_))
        ));
    }

    #[test]
    fn every_output_is_finite_at_the_ends_of_the_size_range() {
        for scale in [MIN_LENGTH * 1.5, 1.0, MAX_LENGTH / 1.5] {
            for pins in [3, 24, MAX_PINS] {
                let zp = f64::from(pins);
                let rp = scale;
                let q = CycloidParams {
                    pins,
                    eccentricity: 0.5 * rp / zp,
                    pin_circle_radius: rp,
                    pin_radius: (0.3 * rp * (PI / zp).sin()).max(MIN_LENGTH),
                    face_width: scale,
                    d_rp: 0.0,
                    d_rrp: 0.0,
                    d_delta: 0.0,
                };
                let Ok(g) = CycloidGeometry::new(q) else {
                    continue;
                };
                for i in 0..50 {
                    let phi = 0.37 * f64::from(i);
                    let v = [
                        g.profile_point(phi)[0],
                        g.profile_point(phi)[1],
                        g.normal(phi)[0],
                        g.curvature_radius(phi),
                    ];
                    assert!(v.iter().all(|x| x.is_finite()), "{q:?} phi {phi}: {v:?}");
                }
            }
        }
    }

    #[test]
    fn pin_radii_must_stay_positive() {
        assert!(check_pin_radii(0.01, &[]).is_ok());
        assert!(check_pin_radii(0.01, &[0.0, -0.005, 0.002]).is_ok());
        let e = check_pin_radii(0.01, &[0.0, -0.01]).unwrap_err();
        assert!(matches!(e, RvdynError::Geometry(_)), "{e}");
        assert!(e.to_string().contains("pin_errors.radius[1]"), "{e}");
        assert!(check_pin_radii(0.01, &[-0.02]).is_err());
    }

    #[test]
    fn each_rule_is_named() {
        let mut p = paper_params();
        p.pins = 2;
        assert!(
            CycloidGeometry::new(p)
                .unwrap_err()
                .to_string()
                .contains("at least 3 pins")
        );
        let mut p = paper_params();
        p.eccentricity = 7e-3; // K1 = 1.12
        assert!(
            CycloidGeometry::new(p)
                .unwrap_err()
                .to_string()
                .contains("curtate")
        );
        let mut p = paper_params();
        p.pin_radius = 0.0196; // rp sin(pi/24) = 19.58 mm
        assert!(
            CycloidGeometry::new(p)
                .unwrap_err()
                .to_string()
                .contains("overlap")
        );
        let mut p = paper_params();
        p.pin_radius = 0.0190; // below the overlap limit, above rho_min = 20.75 mm? no: use d_rrp
        p.d_rrp = 0.002;
        assert!(
            CycloidGeometry::new(p)
                .unwrap_err()
                .to_string()
                .contains("undercut")
        );
        let mut p = paper_params();
        p.face_width = f64::NAN;
        assert!(matches!(
            CycloidGeometry::new(p),
            Err(RvdynError::Parameter(_))
        ));
        let mut p = paper_params();
        p.d_rp = f64::INFINITY;
        assert!(matches!(
            CycloidGeometry::new(p),
            Err(RvdynError::Parameter(_))
        ));
    }
}
