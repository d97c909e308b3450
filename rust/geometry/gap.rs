//! The exact signed gap between a pin and the cycloid profile.
//!
//! A pin is a circle; the profile is the offset (by `rrp + d_rrp`) of the pin-centre curve `C`,
//! and offsets share normals. So the nearest profile point to a pin is found as the foot of the
//! pin centre on `C`: Newton on `f(phi) = (C(phi) - p) . C'(phi) = 0`. The parry2d polyline
//! supplies the starting parameter (global), or a caller that knows a good one (the previous
//! step, or the kinematic parameter) passes it in and the polyline is used only as a fallback.

use crate::error::{Result, RvdynError, require_finite, require_positive};
use crate::geometry::cycloid::CycloidGeometry;
use crate::geometry::profile_seed::CurveConsts;
use std::f64::consts::PI;

/// The iteration stops once its estimate of the foot error left after the last step (arc
/// length along the pin-centre curve) is below this \[m\]. The gap is stationary at the foot, so
/// it is exact to round-off; the normal, turned by `kappa` times the foot error, to 1e-11 rad.
pub const FOOT_TOLERANCE: f64 = 1e-14;
const MAX_NEWTON: u32 = 40;

/// `(sin x, cos x)` for `|x| < 0.01` by their Taylor series to the 9th and 8th order
/// (truncation below 1e-20; the coefficients `1/n!` are rounded, which adds less than an ulp).
#[inline]
pub(crate) fn small_sin_cos(x: f64) -> (f64, f64) {
    const S: [f64; 4] = [-1.0 / 6.0, 1.0 / 120.0, -1.0 / 5040.0, 1.0 / 362_880.0];
    const C: [f64; 4] = [-0.5, 1.0 / 24.0, -1.0 / 720.0, 1.0 / 40_320.0];
    let x2 = x * x;
    let s = x + x * x2 * (S[0] + x2 * (S[1] + x2 * (S[2] + x2 * S[3])));
    let c = 1.0 + x2 * (C[0] + x2 * (C[1] + x2 * (C[2] + x2 * C[3])));
    (s, c)
}

#[inline]
fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// `a * b` as complex numbers `(re, im)`.
#[inline]
fn cmul(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] * b[0] - a[1] * b[1], a[0] * b[1] + a[1] * b[0]]
}

/// `u^n` by binary exponentiation (relative error about `n` ulp).
#[inline]
fn cpow(u: [f64; 2], mut n: u32) -> [f64; 2] {
    let (mut acc, mut base) = ([1.0, 0.0], u);
    while n > 0 {
        if n & 1 == 1 {
            acc = cmul(acc, base);
        }
        base = cmul(base, base);
        n >>= 1;
    }
    acc
}

/// `u exp(i x)`: a Taylor rotation for small `x`, else `exact()`.
#[inline]
fn turn(u: [f64; 2], x: f64, exact: impl FnOnce() -> [f64; 2]) -> [f64; 2] {
    if x.abs() < 0.01 {
        let (s, c) = small_sin_cos(x);
        cmul(u, [c, s])
    } else {
        exact()
    }
}

/// The pin-centre curve and its first four derivatives at one parameter, from
/// `u = exp(i phi)` and `v = exp(i zp phi)`: `C^(k) = i^k (R u - e zp^k v)`.
#[derive(Debug, Clone, Copy)]
struct Derivs {
    c: [f64; 2],
    d1: [f64; 2],
    d2: [f64; 2],
    d3: [f64; 2],
    d4: [f64; 2],
}

impl Derivs {
    #[inline]
    fn new(k: &CurveConsts, u: [f64; 2], v: [f64; 2]) -> Self {
        let w = |m: usize| [k.r * u[0] - k.ez[m] * v[0], k.r * u[1] - k.ez[m] * v[1]];
        let (w1, w2, w3) = (w(1), w(2), w(3));
        Self {
            c: w(0),
            d1: [-w1[1], w1[0]],
            d2: [-w2[0], -w2[1]],
            d3: [w3[1], -w3[0]],
            d4: w(4),
        }
    }

    /// Derivatives 1..=4 of `h = |C - p|^2 / 2` with respect to `phi`, and `|C'|^2`.
    #[inline]
    fn distance_derivatives(&self, p: [f64; 2]) -> ([f64; 4], f64) {
        let r = [self.c[0] - p[0], self.c[1] - p[1]];
        let g = dot(self.d1, self.d1);
        (
            [
                dot(r, self.d1),
                g + dot(r, self.d2),
                3.0 * dot(self.d1, self.d2) + dot(r, self.d3),
                3.0 * dot(self.d2, self.d2) + 4.0 * dot(self.d1, self.d3) + dot(r, self.d4),
            ],
            g,
        )
    }
}

/// Result of an exact gap query, in the fixed frame (SI).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PinGap {
    /// Signed normal gap between the pin circle and the profile \[m\]; negative = penetration.
    pub gap: f64,
    /// Contact point on the disc profile, fixed frame \[m\].
    pub point: [f64; 2],
    /// Unit outward normal of the profile at the contact (points from the disc to the pin).
    pub normal: [f64; 2],
    /// Curve parameter of the contact, in `[0, 2 pi)` \[rad\].
    pub phi: f64,
    /// Signed radius of curvature of the profile at the contact \[m\] (positive convex).
    pub curvature_radius: f64,
    /// Iterations used on the exact curve (0: found by the search around a tooth root).
    pub iterations: u32,
}

/// The state a sequence of gap queries of one pin against one disc carries from query to
/// query (see [`CycloidGeometry::gap_warm`]). `Default` is a cold start.
#[derive(Debug, Clone, Copy)]
pub struct GapWarmStart {
    phi: f64,
    disc_angle: f64,
    cos_sin: [f64; 2],
    /// How far the foot moved along the curve, beyond the disc's rotation, at the last query
    /// \[rad\]: the next query expects the same (a linear predictor along a trajectory).
    drift: f64,
}

impl Default for GapWarmStart {
    fn default() -> Self {
        Self {
            phi: f64::NAN,
            disc_angle: f64::NAN,
            cos_sin: [1.0, 0.0],
            drift: 0.0,
        }
    }
}

/// Foot of a point on the pin-centre curve, unrotated disc frame.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LocalFoot {
    pub phi: f64,
    /// `cos phi`, `sin phi`.
    pub cos_sin: [f64; 2],
    /// Signed distance `(p - C) . n` \[m\].
    pub dist: f64,
    /// Outward unit normal at the foot.
    pub normal: [f64; 2],
    /// Foot point on `C`.
    pub centre_point: [f64; 2],
    /// `C'` at the foot.
    pub d1: [f64; 2],
    /// `C''` at the foot.
    pub d2: [f64; 2],
    pub iterations: u32,
}

impl LocalFoot {
    #[inline]
    fn at(p: [f64; 2], phi: f64, cos_sin: [f64; 2], d: &Derivs, iterations: u32) -> Self {
        // |C'| = R S >= R (1 - K1) > 0.
        let inv_len = 1.0 / dot(d.d1, d.d1).sqrt();
        let n = [d.d1[1] * inv_len, -d.d1[0] * inv_len];
        Self {
            phi,
            cos_sin,
            dist: (p[0] - d.c[0]) * n[0] + (p[1] - d.c[1]) * n[1],
            normal: n,
            centre_point: d.c,
            d1: d.d1,
            d2: d.d2,
            iterations,
        }
    }
}

/// A foot, or a pin shown to be farther from the curve than asked
/// ([`CycloidGeometry::contact_foot_or_open`]), with the lower bound of its signed distance
/// \[m\] that showed it.
#[derive(Debug, Clone, Copy)]
pub(crate) enum FootOrOpen {
    Foot(LocalFoot),
    Open(f64),
}

/// A root of `g` (value, derivative) in the bracket `[a, b]` where `g` changes sign: Newton
/// steps while they stay inside the shrinking bracket and at least halve the previous step,
/// bisection otherwise (the safeguard of Press et al., Numerical Recipes, 3rd ed., 2007,
/// section 9.4). `None` if `g` has the same sign at both ends.
fn bracketed_root(g: impl Fn(f64) -> (f64, f64), a: f64, b: f64) -> Option<f64> {
    let (ga, gb) = (g(a).0, g(b).0);
    if ga == 0.0 {
        return Some(a);
    }
    if gb == 0.0 {
        return Some(b);
    }
    if !(ga.is_finite() && gb.is_finite()) || ga.signum() == gb.signum() {
        return None;
    }
    // neg, pos: the ends of the bracket where g < 0 and g > 0.
    let (mut neg, mut pos) = if ga < 0.0 { (a, b) } else { (b, a) };
    let mut x = 0.5 * (a + b);
    let mut last = (b - a).abs();
    for _ in 0..200 {
        let (gx, dg) = g(x);
        if gx == 0.0 {
            return Some(x);
        }
        if gx < 0.0 {
            neg = x;
        } else {
            pos = x;
        }
        let newton = x - gx / dg;
        let inside = (newton - neg) * (newton - pos) < 0.0;
        let next = if inside && (newton - x).abs() < 0.5 * last {
            newton
        } else {
            0.5 * (neg + pos)
        };
        last = (next - x).abs();
        x = next;
        if last <= 1e-15 * (1.0 + x.abs()) {
            return Some(x);
        }
    }
    Some(x)
}

impl CycloidGeometry {
    /// Exact gap between pin circle (centre `pin_center` \[m\], radius the disc's `pin_radius`)
    /// and the profile of this disc placed with its centre at `disc_center` \[m\] and turned by
    /// `disc_angle` \[rad\] (fixed frame).
    ///
    /// Returns the signed gap (negative = penetration), the contact point on the profile, the
    /// outward unit normal, the curve parameter and the local curvature radius. The gap is the
    /// minimum distance; where a pin is so far outside a tooth root that two profile points
    /// are locally nearest (beyond the centre of curvature of the concave root, 0.72 mm for
    /// the default disc), the nearer one is returned.
    ///
    /// ```
    /// # use rvdyn::geometry::{CycloidGeometry, cycloid::CycloidParams};
    /// let g = CycloidGeometry::new(CycloidParams { pins: 24, eccentricity: 4.5e-3,
    ///     pin_circle_radius: 0.15, pin_radius: 0.01, face_width: 0.04,
    ///     d_rp: 0.0, d_rrp: 0.0, d_delta: 0.0 }).unwrap();
    /// // Kinematic pose at crank angle psi: centre e(cos psi, sin psi), disc angle -psi/zc.
    /// let psi = 0.3_f64;
    /// let centre = [4.5e-3 * psi.cos(), 4.5e-3 * psi.sin()];
    /// let pin = [0.15, 0.0];
    /// let gap = g.gap(pin, centre, -psi / 23.0).unwrap();
    /// assert!(gap.gap.abs() < 1e-12);
    /// ```
    pub fn gap(
        &self,
        pin_center: [f64; 2],
        disc_center: [f64; 2],
        disc_angle: f64,
    ) -> Result<PinGap> {
        self.gap_with_pin_radius(
            pin_center,
            self.params().pin_radius,
            disc_center,
            disc_angle,
        )
    }

    /// As [`CycloidGeometry::gap`] for a pin of another radius \[m\] (pin radius errors).
    pub fn gap_with_pin_radius(
        &self,
        pin_center: [f64; 2],
        pin_radius: f64,
        disc_center: [f64; 2],
        disc_angle: f64,
    ) -> Result<PinGap> {
        let (p, sc) = self.to_local(pin_center, disc_center, disc_angle)?;
        require_positive("pin_radius", pin_radius, "m")?;
        let seed = self
            .seed
            .seed(self, p)
            .ok_or_else(|| RvdynError::Parameter("pin and disc positions must be finite".into()))?;
        let foot = self.foot(p, seed).ok_or_else(|| self.no_foot(p))?;
        Ok(self.to_global(&foot, pin_radius, disc_center, sc))
    }

    /// As [`CycloidGeometry::gap_with_pin_radius`], starting the iteration from `seed_phi`
    /// \[rad\]; the polyline seed is used only if it fails from there. For hot loops that know
    /// where the contact was (previous step) or should be (kinematics).
    pub fn gap_seeded(
        &self,
        pin_center: [f64; 2],
        pin_radius: f64,
        disc_center: [f64; 2],
        disc_angle: f64,
        seed_phi: f64,
    ) -> Result<PinGap> {
        let (p, sc) = self.to_local(pin_center, disc_center, disc_angle)?;
        require_finite("seed_phi", seed_phi)?;
        let foot = self
            .foot_with_fallback(p, seed_phi)
            .ok_or_else(|| self.no_foot(p))?;
        Ok(self.to_global(&foot, pin_radius, disc_center, sc))
    }

    /// As [`CycloidGeometry::gap_with_pin_radius`] for one pin in a sequence of queries (a
    /// trajectory): the foot of the previous query, turned by the disc's rotation since and by
    /// the drift of the foot at the previous query (a linear predictor), seeds the iteration
    /// without any trigonometry; the first query, and one after the disc turned by 0.01 rad or
    /// more, are seeded by the polyline. `warm` is updated. The result does not
    /// depend on the warm start (the iteration converges to 1e-14 m on the exact curve).
    pub fn gap_warm(
        &self,
        pin_center: [f64; 2],
        pin_radius: f64,
        disc_center: [f64; 2],
        disc_angle: f64,
        warm: &mut GapWarmStart,
    ) -> Result<PinGap> {
        let (p, sc) = self.to_local(pin_center, disc_center, disc_angle)?;
        // The pin is fixed, so its kinematic parameter turns by minus the disc's rotation; the
        // foot moves by that plus about the drift it had at the last query.
        let rot = warm.disc_angle - disc_angle;
        let turn_by = rot + warm.drift;
        let foot = if turn_by.abs() < 0.01 {
            let (s, c) = small_sin_cos(turn_by);
            self.foot_with_fallback_cs(p, warm.phi + turn_by, cmul(warm.cos_sin, [c, s]))
        } else {
            self.seed.seed(self, p).and_then(|seed| self.foot(p, seed))
        }
        .ok_or_else(|| self.no_foot(p))?;
        let drift = foot.phi - (warm.phi + rot);
        *warm = GapWarmStart {
            phi: foot.phi,
            disc_angle,
            cos_sin: foot.cos_sin,
            drift: if drift.abs() < 1e-3 { drift } else { 0.0 },
        };
        Ok(self.to_global(&foot, pin_radius, disc_center, sc))
    }

    /// Foot from `seed`, with the polyline seed as the fallback. Unrotated disc frame.
    #[inline]
    pub(crate) fn foot_with_fallback(&self, p: [f64; 2], seed: f64) -> Option<LocalFoot> {
        let (s, c) = seed.sin_cos();
        self.foot_with_fallback_cs(p, seed, [c, s])
    }

    /// As [`CycloidGeometry::foot_with_fallback`] with `cos` and `sin` of the seed given.
    #[inline]
    pub(crate) fn foot_with_fallback_cs(
        &self,
        p: [f64; 2],
        seed: f64,
        cs: [f64; 2],
    ) -> Option<LocalFoot> {
        match self.foot_cs(p, seed, cs) {
            Some(f) => Some(f),
            None => self.foot(p, self.seed.seed(self, p)?),
        }
    }

    /// As [`CycloidGeometry::foot_with_fallback_cs`] for a caller that uses neither `d1` nor
    /// `d2` of the foot (the models' pin queries): `d2` is not moved to the foot and is NaN;
    /// everything else is the same, bit for bit. Or [`FootOrOpen::Open`] when `probe = (dist,
    /// open_above)` shows at the seed that the signed distance of `p` from `C` exceeds
    /// `open_above`: the seed point `C(seed)` and its outward normal `n` give the point
    /// `r = C(seed) + dist n`, exactly `dist` from `C` while `0 <= dist <` the ambiguity
    /// distance (half the smallest concave radius of curvature: `r` is within the curve's
    /// reach on its outer side, so its nearest point is `C(seed)`), and the signed distance is
    /// 1-Lipschitz, so it is at least `dist - |p - r|` at `p` (less the round-off of a seed
    /// `(cos, sin)` that is not exactly of unit length); `Open` carries that bound. The test costs a few operations on
    /// top of the first iteration's curve evaluation, which the search needs anyway.
    #[inline]
    pub(crate) fn contact_foot_or_open(
        &self,
        p: [f64; 2],
        seed: f64,
        cs: [f64; 2],
        probe: Option<(f64, f64)>,
    ) -> Option<FootOrOpen> {
        match self.foot_iterate::<false>(p, seed, cs, probe) {
            Some(f) => Some(f),
            None => self.foot(p, self.seed.seed(self, p)?).map(FootOrOpen::Foot),
        }
    }

    /// The nearest point of the pin-centre curve to `p` from `seed`. Unrotated disc frame.
    #[inline]
    pub(crate) fn foot(&self, p: [f64; 2], seed: f64) -> Option<LocalFoot> {
        let (s, c) = seed.sin_cos();
        self.foot_cs(p, seed, [c, s])
    }

    /// As [`CycloidGeometry::foot`] with `cos` and `sin` of the seed given (a caller that kept
    /// them from the previous foot saves the trigonometry).
    ///
    /// Halley's iteration on `h'(phi) = 0`, `h = |C(phi) - p|^2 / 2` (cubic convergence; Traub,
    /// Iterative Methods for the Solution of Equations, 1964, section 5.2), on
    /// `u = exp(i phi)` and `v = exp(i zp phi)` turned by each step's rotation (Taylor series
    /// to the 9th order, exact to round-off for steps below 0.01 rad) instead of evaluating
    /// trigonometric functions. It stops when the error left after the step, estimated as
    /// Halley's error constant `(h3 / 2 h2)^2 + |h4 / 6 h2|` (`hk` the k-th derivative of `h`)
    /// times the step cubed, is below [`FOOT_TOLERANCE`]; the foot point and the first two
    /// derivatives are then moved by their Taylor series (error below 1e-20 m) instead of a new
    /// evaluation.
    ///
    /// Where `h'' <= 0` (the point lies beyond a centre of curvature of a concave root, so the
    /// distance may have two local minima there) or the point is farther outside the curve
    /// than half the concave radius of curvature, [`CycloidGeometry::foot_near_root`] finds
    /// the nearer foot. `None` if no foot is found.
    #[inline]
    pub(crate) fn foot_cs(&self, p: [f64; 2], seed: f64, seed_cs: [f64; 2]) -> Option<LocalFoot> {
        match self.foot_iterate::<true>(p, seed, seed_cs, None)? {
            FootOrOpen::Foot(f) => Some(f),
            FootOrOpen::Open(_) => None,
        }
    }

    /// [`CycloidGeometry::foot_cs`]; without `D2` the foot's `d2` is NaN (not moved to it).
    #[inline]
    fn foot_iterate<const D2: bool>(
        &self,
        p: [f64; 2],
        seed: f64,
        seed_cs: [f64; 2],
        probe: Option<(f64, f64)>,
    ) -> Option<FootOrOpen> {
        let k = &self.seed.curve;
        let zp = f64::from(k.zp);
        let max_step = PI / (2.0 * zp);
        let mut phi = seed;
        let mut u = seed_cs;
        let mut v = cpow(u, k.zp);
        if let Some((dist, open_above)) = probe
            && dist >= 0.0
            && dist < k.ambiguity_distance
        {
            // The first iteration evaluates the same point again (the compiler shares the
            // two: keeping it in an Option instead cost 1.3 % more instructions).
            let d = Derivs::new(k, u, v);
            let inv_len = 1.0 / dot(d.d1, d.d1).sqrt();
            let n = [d.d1[1] * inv_len, -d.d1[0] * inv_len];
            let (dx, dy) = (p[0] - d.c[0] - dist * n[0], p[1] - d.c[1] - dist * n[1]);
            // C(u) = R u - e u^zp is off the curve by about (R + zp e) |1 - |u|^2| when u is
            // not of unit length.
            let off = (k.r + k.ez[1]) * (1.0 - dot(u, u)).abs();
            let lower = dist - (dx * dx + dy * dy).sqrt() - off;
            if lower > open_above {
                return Some(FootOrOpen::Open(lower));
            }
        }
        for it in 1..=MAX_NEWTON {
            let d = Derivs::new(k, u, v);
            let ([h1, h2, h3, h4], g) = d.distance_derivatives(p);
            if h2.is_nan() || h2 <= 0.0 {
                return self.foot_near_root(p).map(FootOrOpen::Foot);
            }
            // Halley's step -h1 / (h2 (1 + n q)), n = -h1 / h2 the Newton step and
            // q = h3 / (2 h2), written with one division: -h1 h2 / (h2^2 - h1 h3 / 2); it is
            // taken while 1 + n q > 1/2. (The division of q and of the error estimate is off
            // the iteration's chain of dependent operations.)
            let h2sq = h2 * h2;
            let den = h2sq - 0.5 * h1 * h3;
            let halley = den > 0.5 * h2sq;
            let step = if halley { -h1 * h2 / den } else { -h1 / h2 }.clamp(-max_step, max_step);
            let inv = 1.0 / h2;
            let q = 0.5 * h3 * inv;
            let err = (q * q + (h4 * inv).abs() / 6.0) * (step * step * step).abs();
            phi += step;
            u = turn(u, step, || {
                let (s, c) = phi.sin_cos();
                [c, s]
            });
            if halley && err * err * g < FOOT_TOLERANCE * FOOT_TOLERANCE {
                let (s, s2, s3) = (step, 0.5 * step * step, step * step * step / 6.0);
                let taylor = |a: [f64; 2], b: [f64; 2], c: [f64; 2], e: [f64; 2]| {
                    [
                        a[0] + s * b[0] + s2 * c[0] + s3 * e[0],
                        a[1] + s * b[1] + s2 * c[1] + s3 * e[1],
                    ]
                };
                let moved = Derivs {
                    c: taylor(d.c, d.d1, d.d2, d.d3),
                    d1: taylor(d.d1, d.d2, d.d3, d.d4),
                    d2: if D2 {
                        taylor(d.d2, d.d3, d.d4, [0.0; 2])
                    } else {
                        [f64::NAN; 2]
                    },
                    d3: d.d3,
                    d4: d.d4,
                };
                let foot = LocalFoot::at(p, phi, u, &moved, it);
                if foot.dist > k.ambiguity_distance
                    && let Some(other) = self.foot_near_root(p)
                    && other.dist < foot.dist
                {
                    return Some(FootOrOpen::Foot(other));
                }
                return Some(FootOrOpen::Foot(foot));
            }
            v = turn(v, zp * step, || cpow(u, k.zp));
        }
        None
    }

    /// The nearest point of the pin-centre curve to `p` between the two lobe tips around the
    /// root nearest to `p`'s direction, found globally. Where the distance has a concave
    /// stretch (`h'' <= 0`: the point is beyond the evolute of the root) there can be a local
    /// minimum on each side of it; both are found and compared. `h''` has a single minimum
    /// between the tips (checked against brute force in the tests): it and the ends of the
    /// concave stretch bracket each minimum, and each is found by a safeguarded Newton
    /// iteration. `None` if the nearest point is not between the tips.
    pub(crate) fn foot_near_root(&self, p: [f64; 2]) -> Option<LocalFoot> {
        let k = &self.seed.curve;
        let half = 0.5 * k.pitch;
        let root = (p[1].atan2(p[0]) / k.pitch).round() * k.pitch;
        let (lo, hi) = (root - half, root + half);
        let derivs = |phi: f64| {
            let (s, c) = phi.sin_cos();
            let u = [c, s];
            Derivs::new(k, u, cpow(u, k.zp))
        };
        let h = |phi: f64| derivs(phi).distance_derivatives(p).0;
        // Smallest h'' on a coarse grid, refined as a root of h'''.
        const M: usize = 16;
        let grid = |i: usize| lo + (hi - lo) * i as f64 / M as f64;
        let i_min = (0..=M)
            .map(|i| (i, h(grid(i))[1]))
            .min_by(|a, b| a.1.total_cmp(&b.1))?
            .0;
        let (a, b) = (grid(i_min.saturating_sub(1)), grid((i_min + 1).min(M)));
        let z = bracketed_root(
            |x| {
                let d = h(x);
                (d[2], d[3])
            },
            a,
            b,
        )
        .unwrap_or(grid(i_min));
        let slope = |x: f64| {
            let d = h(x);
            (d[0], d[1])
        };
        let mut candidates = [None, None];
        if h(z)[1] > 0.0 {
            candidates[0] = bracketed_root(slope, lo, hi);
        } else {
            let curvature = |x: f64| {
                let d = h(x);
                (d[1], d[2])
            };
            // The concave stretch is [zl, zr]: a minimum lies left of it if h' > 0 at zl, and
            // right of it if h' < 0 at zr.
            if let Some(zl) = bracketed_root(curvature, lo, z) {
                candidates[0] = bracketed_root(slope, lo, zl);
            }
            if let Some(zr) = bracketed_root(curvature, z, hi) {
                candidates[1] = bracketed_root(slope, zr, hi);
            }
        }
        let dist2 = |f: &LocalFoot| {
            let r = [f.centre_point[0] - p[0], f.centre_point[1] - p[1]];
            dot(r, r)
        };
        candidates
            .into_iter()
            .flatten()
            .map(|phi| {
                let (s, c) = phi.sin_cos();
                LocalFoot::at(p, phi, [c, s], &derivs(phi), 0)
            })
            .min_by(|a, b| dist2(a).total_cmp(&dist2(b)))
    }

    /// Pin centre in the unrotated disc frame (rotation modification removed), and
    /// `(sin, cos)` of the disc angle.
    #[inline]
    fn to_local(
        &self,
        pin: [f64; 2],
        centre: [f64; 2],
        angle: f64,
    ) -> Result<([f64; 2], [f64; 2])> {
        for (name, v) in [
            ("pin_center[0]", pin[0]),
            ("pin_center[1]", pin[1]),
            ("disc_center[0]", centre[0]),
            ("disc_center[1]", centre[1]),
            ("disc_angle", angle),
        ] {
            require_finite(name, v)?;
        }
        let (s, c) = angle.sin_cos();
        let d = [pin[0] - centre[0], pin[1] - centre[1]];
        Ok((
            self.remove_rotation_mod([c * d[0] + s * d[1], -s * d[0] + c * d[1]]),
            [s, c],
        ))
    }

    fn to_global(
        &self,
        foot: &LocalFoot,
        pin_radius: f64,
        centre: [f64; 2],
        [s, c]: [f64; 2],
    ) -> PinGap {
        let r = self.generating_pin_radius();
        let local_point = [
            foot.centre_point[0] - r * foot.normal[0],
            foot.centre_point[1] - r * foot.normal[1],
        ];
        let rot = |v: [f64; 2]| {
            let v = self.apply_rotation_mod(v);
            [c * v[0] - s * v[1], s * v[0] + c * v[1]]
        };
        let pt = rot(local_point);
        let (d1, d2) = (foot.d1, foot.d2);
        let len2 = dot(d1, d1);
        let kappa = (d1[0] * d2[1] - d1[1] * d2[0]) / (len2 * len2.sqrt());
        let tau = 2.0 * PI;
        let mut phi = foot.phi;
        if !(0.0..tau).contains(&phi) {
            phi = phi.rem_euclid(tau);
            if phi >= tau {
                phi -= tau;
            }
        }
        PinGap {
            gap: foot.dist + r - pin_radius,
            point: [pt[0] + centre[0], pt[1] + centre[1]],
            normal: rot(foot.normal),
            phi,
            curvature_radius: 1.0 / kappa - r,
            iterations: foot.iterations,
        }
    }

    fn no_foot(&self, p: [f64; 2]) -> RvdynError {
        RvdynError::Convergence(format!(
            "no nearest profile point found for a pin centre at ({:.6e}, {:.6e}) m in the disc \
             frame: the pin is deeper inside the disc than the profile's convex radius of \
             curvature, or not near the profile at all",
            p[0], p[1]
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::cycloid::tests::paper_params;

    fn kinematic_pose(e: f64, psi: f64, zc: f64) -> ([f64; 2], f64) {
        ([e * psi.cos(), e * psi.sin()], -psi / zc)
    }

    #[test]
    fn unmodified_disc_touches_every_pin_at_any_crank_angle() {
        let g = CycloidGeometry::new(paper_params()).unwrap();
        let mut worst: f64 = 0.0;
        for k in 0..97 {
            let psi = -7.0 + 0.1371 * k as f64;
            let (c, a) = kinematic_pose(4.5e-3, psi, 23.0);
            for j in 0..24 {
                let th = g.pin_angle(j);
                let pin = [0.15 * th.cos(), 0.15 * th.sin()];
                let gap = g.gap(pin, c, a).unwrap();
                worst = worst.max(gap.gap.abs());
            }
        }
        assert!(worst < 1e-12, "largest |gap| = {worst:e} m");
    }

    /// Brute force: the distance from the pin centre to a dense sampling of the profile, refined
    /// by a fine local scan, minus the pin radius; sign from the exact normal.
    fn brute_force_gap(g: &CycloidGeometry, pin: [f64; 2], c: [f64; 2], a: f64) -> f64 {
        let n = 400_000;
        let (s, co) = a.sin_cos();
        let world = |phi: f64| {
            let q = g.profile_point(phi);
            [co * q[0] - s * q[1] + c[0], s * q[0] + co * q[1] + c[1]]
        };
        let dist = |phi: f64| {
            let q = world(phi);
            (q[0] - pin[0]).hypot(q[1] - pin[1])
        };
        let mut best = (0.0, f64::INFINITY);
        for i in 0..n {
            let phi = 2.0 * PI * i as f64 / n as f64;
            let d = dist(phi);
            if d < best.1 {
                best = (phi, d);
            }
        }
        let h = 2.0 * PI / n as f64;
        let (mut lo, mut hi) = (best.0 - h, best.0 + h);
        for _ in 0..200 {
            let m1 = lo + (hi - lo) / 3.0;
            let m2 = hi - (hi - lo) / 3.0;
            if dist(m1) < dist(m2) {
                hi = m2
            } else {
                lo = m1
            }
        }
        let phi = 0.5 * (lo + hi);
        let q = world(phi);
        let nl = g.normal(phi);
        let nw = [co * nl[0] - s * nl[1], s * nl[0] + co * nl[1]];
        let side = (pin[0] - q[0]) * nw[0] + (pin[1] - q[1]) * nw[1];
        side.signum() * dist(phi) - g.params().pin_radius
    }

    #[test]
    fn agrees_with_brute_force_on_perturbed_poses() {
        let mut p = paper_params();
        p.d_rp = -2e-5;
        p.d_rrp = 2e-5;
        p.d_delta = 1e-4;
        let g = CycloidGeometry::new(p).unwrap();
        let mut worst: f64 = 0.0;
        let mut state = 12345u64;
        let mut rnd = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64) / ((1u64 << 53) as f64) - 0.5
        };
        for _ in 0..40 {
            let psi = 20.0 * rnd();
            let (mut c, mut a) = kinematic_pose(4.5e-3, psi, 23.0);
            c[0] += 2e-4 * rnd();
            c[1] += 2e-4 * rnd();
            a += 2e-3 * rnd();
            let j = (24.0 * (rnd() + 0.5)) as usize % 24;
            let th = g.pin_angle(j);
            let pin = [0.15 * th.cos(), 0.15 * th.sin()];
            let exact = g.gap(pin, c, a).unwrap();
            let brute = brute_force_gap(&g, pin, c, a);
            worst = worst.max((exact.gap - brute).abs());
            // Contact point lies on the profile and the pin is along the normal from it.
            let back = [
                exact.point[0] + (exact.gap + 0.01) * exact.normal[0],
                exact.point[1] + (exact.gap + 0.01) * exact.normal[1],
            ];
            assert!((back[0] - pin[0]).hypot(back[1] - pin[1]) < 1e-12);
        }
        // The brute force itself is limited by round-off of distances ~0.01 m.
        assert!(worst < 1e-11, "worst |exact - brute| = {worst:e} m");
    }

    #[test]
    fn modifications_open_the_first_order_clearance() {
        // docs/model.md (modifications): g0(phi) = d_rrp - d_rp (1 - K1 cos phi)/S at the
        // kinematic pose, phi = mesh angle of the pin from the eccentricity direction.
        let (d_rp, d_rrp) = (-2e-5, 2e-5);
        let mut p = paper_params();
        p.d_rp = d_rp;
        p.d_rrp = d_rrp;
        let g = CycloidGeometry::new(p).unwrap();
        let k1 = 0.72;
        let psi = 0.4;
        let (c, a) = kinematic_pose(4.5e-3, psi, 23.0);
        let mut worst: f64 = 0.0;
        for j in 0..24 {
            let th = g.pin_angle(j);
            let pin = [0.15 * th.cos(), 0.15 * th.sin()];
            let gap = g.gap(pin, c, a).unwrap().gap;
            let phi = th - psi;
            let s = (1.0 + k1 * k1 - 2.0 * k1 * phi.cos()).sqrt();
            let first_order = d_rrp - d_rp * (1.0 - k1 * phi.cos()) / s;
            worst = worst.max((gap - first_order).abs());
            assert!(gap > 0.0);
        }
        // Second-order remainder: ~3e-5 mm for 0.02 mm modifications (docs/model.md).
        assert!(worst < 1e-7, "worst deviation from first order {worst:e} m");
        assert!(
            worst > 1e-10,
            "the exact gap should differ from first order at second order"
        );
    }

    #[test]
    fn seeded_query_matches_global_and_recovers_from_a_bad_seed() {
        let g = CycloidGeometry::new(paper_params()).unwrap();
        let (c, a) = kinematic_pose(4.5e-3, 1.3, 23.0);
        let (c, a) = ([c[0] + 3e-5, c[1] - 1e-5], a + 2e-4);
        for j in 0..24 {
            let th = g.pin_angle(j);
            let pin = [0.15 * th.cos(), 0.15 * th.sin()];
            let global = g.gap(pin, c, a).unwrap();
            let seeded = g.gap_seeded(pin, 0.01, c, a, th - a).unwrap();
            assert!((global.gap - seeded.gap).abs() < 1e-14);
            let bad = g.gap_seeded(pin, 0.01, c, a, th - a + 0.9).unwrap();
            assert!((global.gap - bad.gap).abs() < 1e-14);
        }
    }

    #[test]
    fn the_gap_does_not_depend_on_the_seed() {
        // Warm starts differ from run to run; the gap they lead to must not (else the force
        // evaluation is noisy and adaptive error control suffers).
        let g = CycloidGeometry::new(paper_params()).unwrap();
        let mut state = 99u64;
        let mut rnd = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64) / ((1u64 << 53) as f64) - 0.5
        };
        let mut worst: f64 = 0.0;
        for _ in 0..2000 {
            let phi0 = 7.0 * rnd();
            let j = g.jet(phi0);
            let n = CycloidGeometry::normal_from_tangent(j.d1);
            let off = 4e-4 * rnd();
            let p = [j.c[0] + off * n[0], j.c[1] + off * n[1]];
            let exact = g.foot(p, phi0).unwrap();
            for k in 0..4 {
                let seed = phi0 + 0.1 * 10f64.powi(-k) * rnd();
                let f = g.foot_with_fallback(p, seed).unwrap();
                worst = worst
                    .max((f.dist - exact.dist).abs())
                    .max((f.dist - off).abs());
            }
        }
        assert!(worst < 1e-14, "gap differs by {worst:e} m between seeds");
    }

    #[test]
    fn small_angle_sin_cos_is_exact_to_round_off() {
        for i in -100..=100 {
            let x = 1e-4 * f64::from(i);
            let (s, c) = small_sin_cos(x);
            assert!(
                (s - x.sin()).abs() < 2e-17 && (c - x.cos()).abs() < 2e-16,
                "{x}"
            );
        }
    }

    #[test]
    fn non_finite_input_is_rejected() {
        let g = CycloidGeometry::new(paper_params()).unwrap();
        assert!(matches!(
            g.gap([f64::NAN, 0.0], [0.0, 0.0], 0.0),
            Err(RvdynError::Parameter(_))
        ));
        assert!(g.gap([0.15, 0.0], [0.0, 0.0], f64::INFINITY).is_err());
    }
}

#[cfg(test)]
mod shift_tests {
    use super::*;
    use crate::geometry::cycloid::tests::paper_params;

    /// Global minimum of |C(phi) - p| over the whole curve by dense sampling and golden
    /// refinement of the best few samples (independent of the Newton machinery).
    pub(super) fn brute_min_distance(g: &CycloidGeometry, p: [f64; 2]) -> (f64, f64) {
        let n = 200_000;
        let d = |phi: f64| {
            let c = g.jet(phi).c;
            (c[0] - p[0]).hypot(c[1] - p[1])
        };
        let h = 2.0 * PI / n as f64;
        let mut samples: Vec<(f64, f64)> =
            (0..n).map(|i| (i as f64 * h, d(i as f64 * h))).collect();
        samples.sort_by(|a, b| a.1.total_cmp(&b.1));
        let mut best = (f64::NAN, f64::INFINITY);
        for &(phi0, _) in samples.iter().take(8) {
            let (mut lo, mut hi) = (phi0 - h, phi0 + h);
            for _ in 0..100 {
                let m1 = lo + (hi - lo) / 3.0;
                let m2 = hi - (hi - lo) / 3.0;
                if d(m1) < d(m2) { hi = m2 } else { lo = m1 }
            }
            let phi = 0.5 * (lo + hi);
            if d(phi) < best.1 {
                best = (phi, d(phi));
            }
        }
        best
    }

    fn rnd_stream(mut state: u64) -> impl FnMut() -> f64 {
        move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64) / ((1u64 << 53) as f64) - 0.5
        }
    }

    /// A disc with a shift modification of -0.3 .. -2 mm at its kinematic pose. Pins
    /// near a root are 0.3 .. 2 mm outside the pin-centre curve, beyond its 0.72 mm concave
    /// radius of curvature for the larger ones: the distance has two local minima, and the gap
    /// is the smaller (against brute force).
    #[test]
    fn shift_modified_disc_gap_at_the_kinematic_pose() {
        for d_rp in [-3e-4, -5e-4, -8e-4, -1e-3, -2e-3] {
            let mut params = paper_params();
            params.d_rp = d_rp;
            let g = CycloidGeometry::new(params).unwrap();
            for (psi, j) in [(0.0, 0), (0.0, 3), (0.4, 0), (2.0, 7)] {
                let c = [4.5e-3 * f64::cos(psi), 4.5e-3 * f64::sin(psi)];
                let a = -psi / 23.0;
                let th = g.pin_angle(j);
                let pin = [0.15 * th.cos(), 0.15 * th.sin()];
                let gap = g.gap(pin, c, a).unwrap();
                let seeded = g.gap_seeded(pin, 0.01, c, a, th - a).unwrap();
                let (p, _) = g.to_local(pin, c, a).unwrap();
                let (_, dmin) = brute_min_distance(&g, p);
                assert!(
                    (gap.gap - dmin).abs() < 1e-14 && (seeded.gap - dmin).abs() < 1e-14,
                    "d_rp {d_rp}, psi {psi}, pin {j}: {} {} brute {dmin}",
                    gap.gap,
                    seeded.gap
                );
                assert!(gap.gap > 0.0);
            }
        }
    }

    /// Points around a root from 2 mm inside the curve to 3 mm outside, shifted along it by up
    /// to 1.5 mm: the distance from every seed agrees with brute force (this also checks that
    /// h'' has a single minimum between the tips, which the search around the root assumes).
    #[test]
    fn nearest_point_around_a_root_agrees_with_brute_force() {
        let mut rnd = rnd_stream(7);
        for d_rp in [0.0, -8e-4] {
            let mut params = paper_params();
            params.d_rp = d_rp;
            let g = CycloidGeometry::new(params).unwrap();
            let mut worst: f64 = 0.0;
            for _ in 0..60 {
                let root = (24.0 * (rnd() + 0.5)).floor() * g.seed.curve.pitch;
                let j = g.jet(root);
                let n = CycloidGeometry::normal_from_tangent(j.d1);
                let (out, along) = (5e-3 * rnd() + 0.5e-3, 3e-3 * rnd());
                let t = [-n[1], n[0]];
                let p = [
                    j.c[0] + out * n[0] + along * t[0],
                    j.c[1] + out * n[1] + along * t[1],
                ];
                let (_, dmin) = brute_min_distance(&g, p);
                for seed in [root, root + 0.02, root - 0.05, g.seed.seed(&g, p).unwrap()] {
                    let f = g.foot(p, seed).unwrap();
                    let sign = if f.dist < 0.0 { -1.0 } else { 1.0 };
                    worst = worst.max((f.dist - sign * dmin).abs());
                }
            }
            assert!(worst < 1e-14, "d_rp {d_rp}: worst {worst:e} m");
        }
    }

    /// The open test of `contact_foot_or_open`: whenever it answers `Open(lower)`, the exact
    /// signed distance (the converged foot, itself checked against brute force above) is at
    /// least `lower` and above the threshold asked. Points scattered around `r = C(phi) +
    /// dist n` (the carried point of the last query) by up to 20 um, seeds up to 1e-4 rad from
    /// `phi`, thresholds across the range: both answers occur.
    #[test]
    fn the_open_test_never_opens_a_closer_pin() {
        let mut rnd = rnd_stream(23);
        for d_rp in [0.0, -8e-4] {
            let mut params = paper_params();
            params.d_rp = d_rp;
            let g = CycloidGeometry::new(params).unwrap();
            let amb = g.seed.curve.ambiguity_distance;
            let (mut opened, mut queried) = (0, 0);
            for _ in 0..4000 {
                let phi = 2.0 * PI * rnd();
                let j = g.jet(phi);
                let n = CycloidGeometry::normal_from_tangent(j.d1);
                let dist = amb * 0.999 * rnd();
                let (a, rad) = (2.0 * PI * rnd(), 2e-5 * rnd());
                let p = [
                    j.c[0] + dist * n[0] + rad * a.cos(),
                    j.c[1] + dist * n[1] + rad * a.sin(),
                ];
                let seed = phi + 2e-4 * (rnd() - 0.5);
                let cs = [seed.cos(), seed.sin()];
                let open_above = dist * (rnd() - 0.2);
                let exact = g.foot(p, phi).unwrap().dist;
                match g.contact_foot_or_open(p, seed, cs, Some((dist, open_above))) {
                    Some(FootOrOpen::Open(lower)) => {
                        opened += 1;
                        assert!(
                            lower > open_above && exact >= lower - 1e-15,
                            "{exact} {lower}"
                        );
                    }
                    Some(FootOrOpen::Foot(f)) => {
                        queried += 1;
                        assert!((f.dist - exact).abs() < 1e-13, "{} {exact}", f.dist);
                    }
                    None => panic!("no foot"),
                }
            }
            assert!(opened > 500 && queried > 500, "{opened} {queried}");
        }
    }

    /// Below the ambiguity distance (half the concave radius of curvature) a converged local
    /// foot is the nearest point (no second local minimum nearer), so the search around the
    /// root is skipped there: against brute force from seeds anywhere in the basin.
    #[test]
    fn a_local_foot_below_the_ambiguity_distance_is_the_nearest() {
        let mut rnd = rnd_stream(11);
        for d_rp in [0.0, -8e-4, -2e-3] {
            let mut params = paper_params();
            params.d_rp = d_rp;
            let g = CycloidGeometry::new(params).unwrap();
            let k = g.seed.curve;
            for _ in 0..25 {
                let phi0 = k.pitch * rnd();
                let j = g.jet(phi0);
                let n = CycloidGeometry::normal_from_tangent(j.d1);
                let out = k.ambiguity_distance * (0.5 + 0.499 * rnd());
                let p = [j.c[0] + out * n[0], j.c[1] + out * n[1]];
                let (_, dmin) = brute_min_distance(&g, p);
                let f = g.foot(p, phi0 + 1e-3 * rnd()).unwrap();
                assert!(
                    (f.dist - dmin).abs() < 1e-14,
                    "d_rp {d_rp}: {} {dmin}",
                    f.dist
                );
            }
        }
    }

    #[test]
    fn warm_started_queries_along_a_trajectory_match_cold_ones() {
        let mut params = paper_params();
        params.d_rp = -2e-5;
        params.d_rrp = 1e-5;
        params.d_delta = 2e-4;
        let g = CycloidGeometry::new(params).unwrap();
        let mut warm = [GapWarmStart::default(); 24];
        let mut worst: f64 = 0.0;
        for step in 0..400 {
            let t = step as f64 * 2e-4;
            let psi = 157.0 * t;
            let c = [
                4.5e-3 * psi.cos() + 2e-5 * (900.0 * t).sin(),
                4.5e-3 * psi.sin() + 1e-5 * (1300.0 * t).cos(),
            ];
            let a = -psi / 23.0 + 1e-4 * (700.0 * t).sin();
            for (j, w) in warm.iter_mut().enumerate() {
                let th = g.pin_angle(j);
                let pin = [0.15 * th.cos(), 0.15 * th.sin()];
                let cold = g.gap(pin, c, a).unwrap();
                let hot = g.gap_warm(pin, 0.01, c, a, w).unwrap();
                // The foot agrees to FOOT_TOLERANCE along the curve; the normal turns by
                // kappa (up to 1/0.72 mm at a root) times that, the profile point by the pin
                // radius times the normal's turn.
                worst = worst
                    .max((cold.gap - hot.gap).abs() / 1e-14)
                    .max((cold.point[0] - hot.point[0]).abs() / 1e-12)
                    .max((cold.point[1] - hot.point[1]).abs() / 1e-12)
                    .max((cold.normal[0] - hot.normal[0]).abs() / 1e-10)
                    .max((cold.normal[1] - hot.normal[1]).abs() / 1e-10);
                let rho = g.curvature_radius(hot.phi);
                assert!(
                    (hot.curvature_radius - rho).abs() < 1e-9 * rho.abs(),
                    "{rho}"
                );
            }
        }
        assert!(worst < 1.0, "warm and cold differ by {worst} tolerances");
    }
}
