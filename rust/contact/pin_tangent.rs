//! First and second derivatives of the exact pin-profile gap with respect to the disc pose.
//!
//! A disc with centre `O = (X, Y)` and angle `theta` (fixed frame) and a fixed pin of centre
//! `P` and radius `r_p`. In the (unrotated) disc frame the pin centre is
//! `p = R(-theta - d_delta) (P - O)`; its signed distance from the pin-centre curve `C(phi)` is
//! `d(p) = (p - C(phi*)) . n(phi*)` at the foot `phi*` (the nearest curve point), and the gap is
//! `g = d + (rrp + d_rrp) - r_p` (see `geometry::gap`).
//!
//! Derivatives of the signed distance to a smooth curve (do Carmo, *Differential Geometry of
//! Curves and Surfaces*, 1976, section 1-7 on parallel curves; the level sets of `d` are the
//! offset curves of `C`, of curvature `kappa / (1 + kappa d)`):
//! `grad_p d = n`, `hess_p d = kappa / (1 + kappa d) t t^T`, with `t` the unit tangent and
//! `kappa` the signed curvature of `C` at the foot (positive convex, `n` outward). The foot
//! moves along the curve as the disc moves; this is what the curvature term carries (the
//! "geometric stiffness" of the contact: the contact point slides along the curved profile).
//!
//! With `r = P - O`, the world normal `N` and tangent `T = z x N` at the foot, the chain rule
//! through `p(X, Y, theta)` (`dp/dO = -R^T`, `dp/dtheta = -z x p`, `d2p/dtheta2 = -p`,
//! `d2p/dtheta dO_a = z x R^T e_a`) gives, for `q = (X, Y, theta)`:
//!
//! - `grad g = -(N_x, N_y, r x N)`; `r x N` is the lever of the normal about the disc centre
//!   (the same as `(contact point - O) x N`);
//! - `hess g = kappa / (1 + kappa d) g_t g_t^T + [[0, 0, N_y], [0, 0, -N_x], [N_y, -N_x,
//!   -r . N]]`, with `g_t = -(T_x, T_y, r x T)`.
//!
//! A penetration `delta = -g` with a contact force `F(delta) >= 0` acting as `-F N` on the disc
//! has the generalised force `Q = -F grad(delta) = F grad(g)` and the tangent stiffness
//! `K = -dQ/dq = F'(delta) grad(g) grad(g)^T - F hess(g)`.
//!
//! Theory: docs/model.md, section "Derivatives of the exact gap".

use crate::error::{Result, RvdynError, require_finite};
use crate::geometry::CycloidGeometry;

/// The gap of one pin against one disc with its derivatives in the disc pose `(X, Y, theta)`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GapJet {
    /// Signed gap \[m\] (negative = penetration).
    pub gap: f64,
    /// `d gap / d(X, Y, theta)` [-, -, m].
    pub grad: [f64; 3],
    /// Second derivatives `d2 gap / dq_a dq_b` [1/m, 1/m, 1; 1/m, 1/m, 1; 1, 1, m].
    pub hess: [[f64; 3]; 3],
    /// Unit outward profile normal at the contact, fixed frame (from the disc to the pin).
    pub normal: [f64; 2],
    /// Contact point on the profile relative to the disc centre, fixed frame \[m\].
    pub arm: [f64; 2],
    /// Curve parameter of the foot \[rad\] (not reduced to `[0, 2 pi)`).
    pub phi: f64,
    /// `(cos phi, sin phi)` of the foot (a warm start for the next query).
    pub cos_sin: [f64; 2],
    /// `(cos, sin)` of [`GapJet::phi`] (the foot after its last Newton correction).
    pub phi_cos_sin: [f64; 2],
    /// Signed radius of curvature of the profile at the contact \[m\] (positive convex).
    pub curvature_radius: f64,
}

impl GapJet {
    /// Lever of the normal about the disc centre, `arm x normal` \[m\].
    #[inline]
    pub fn lever(&self) -> f64 {
        self.arm[0] * self.normal[1] - self.arm[1] * self.normal[0]
    }
}

/// The exact gap of the pin (`pin_centre` \[m\], `pin_radius` \[m\]) against `geometry` placed at
/// `disc_centre` \[m\], `disc_angle` \[rad\], with its gradient and Hessian in the disc pose.
///
/// `seed` is a curve parameter \[rad\] near the expected foot (e.g. the previous foot, or the
/// pin angle minus the disc angle); the answer does not depend on it (the polyline seed is
/// the fallback). Errors: non-finite input (`Parameter`), no unique foot (`Convergence`: the
/// pin centre is beyond a centre of curvature of the pin-centre curve).
///
/// ```
/// use rvdyn::contact::pin_tangent::pin_gap_jet;
/// use rvdyn::geometry::{CycloidGeometry, cycloid::CycloidParams};
/// let g = CycloidGeometry::new(CycloidParams::paper()).unwrap();
/// let psi: f64 = 0.3; // kinematic pose: every pin touches the unmodified disc
/// let (c, a) = ([4.5e-3 * psi.cos(), 4.5e-3 * psi.sin()], -psi / 23.0);
/// let th = g.pin_angle(3); // the paper's pin 4
/// let pin = [0.15 * th.cos(), 0.15 * th.sin()];
/// let jet = pin_gap_jet(&g, pin, 0.010, c, a, th - a).unwrap();
/// assert!(jet.gap.abs() < 1e-12);
/// assert!((jet.grad[2] + jet.lever()).abs() < 1e-15);
/// ```
pub fn pin_gap_jet(
    geometry: &CycloidGeometry,
    pin_centre: [f64; 2],
    pin_radius: f64,
    disc_centre: [f64; 2],
    disc_angle: f64,
    seed: f64,
) -> Result<GapJet> {
    for (name, v) in [
        ("pin_centre[0]", pin_centre[0]),
        ("pin_centre[1]", pin_centre[1]),
        ("pin_radius", pin_radius),
        ("disc_centre[0]", disc_centre[0]),
        ("disc_centre[1]", disc_centre[1]),
        ("disc_angle", disc_angle),
        ("seed", seed),
    ] {
        require_finite(name, v)?;
    }
    let (s, c) = disc_angle.sin_cos();
    gap_jet_cs(
        geometry,
        pin_centre,
        pin_radius,
        disc_centre,
        [c, s],
        seed,
        None,
    )
    .ok_or_else(|| {
        RvdynError::Convergence(format!(
            "no unique nearest profile point for the pin at ({:.6e}, {:.6e}) m with the disc at \
             ({:.6e}, {:.6e}) m, {disc_angle:.6e} rad: the pin is farther from the pin-centre \
             curve than its concave radius of curvature",
            pin_centre[0], pin_centre[1], disc_centre[0], disc_centre[1]
        ))
    })
}

/// As [`pin_gap_jet`] with `(cos, sin)` of the disc angle given and optionally `(cos, sin)` of
/// the seed (hot loops keep both). `None` if no foot is found. Inputs are assumed finite.
#[inline]
pub(crate) fn gap_jet_cs(
    geometry: &CycloidGeometry,
    pin_centre: [f64; 2],
    pin_radius: f64,
    disc_centre: [f64; 2],
    disc_cos_sin: [f64; 2],
    seed: f64,
    seed_cos_sin: Option<[f64; 2]>,
) -> Option<GapJet> {
    let g = geometry;
    let [c, s] = disc_cos_sin;
    let r = [
        pin_centre[0] - disc_centre[0],
        pin_centre[1] - disc_centre[1],
    ];
    let local = g.remove_rotation_mod([c * r[0] + s * r[1], -s * r[0] + c * r[1]]);
    let cs = seed_cos_sin.unwrap_or_else(|| {
        let (ss, cc) = seed.sin_cos();
        [cc, ss]
    });
    let foot = g.foot_with_fallback_cs(local, seed, cs)?;
    // One more Newton correction of the foot (the foot search stops at a step tolerance: this
    // brings the normal to round-off, which the Hessian needs), then the curvature of the
    // pin-centre curve there. The point and its first two derivatives at the foot are the
    // search's, moved to its last iterate by their Taylor series (error below 1e-20 m, far
    // below the round-off of a fresh evaluation), not evaluated again.
    let (c0, d1, d2) = (foot.centre_point, foot.d1, foot.d2);
    let rc = [c0[0] - local[0], c0[1] - local[1]];
    let d1sq = d1[0] * d1[0] + d1[1] * d1[1];
    let fp = d1sq + rc[0] * d2[0] + rc[1] * d2[1];
    let dphi = -(rc[0] * d1[0] + rc[1] * d1[1]) / fp;
    let h2 = 0.5 * dphi * dphi;
    let cp = [
        c0[0] + dphi * d1[0] + h2 * d2[0],
        c0[1] + dphi * d1[1] + h2 * d2[1],
    ];
    let normal = CycloidGeometry::normal_from_tangent([d1[0] + dphi * d2[0], d1[1] + dphi * d2[1]]);
    let dist = (local[0] - cp[0]) * normal[0] + (local[1] - cp[1]) * normal[1];
    let len = d1sq.sqrt();
    let kappa = (d1[0] * d2[1] - d1[1] * d2[0]) / (len * len * len);
    let one_plus = 1.0 + kappa * dist;
    if one_plus.is_nan() || one_plus <= 0.0 || fp <= 0.0 {
        return None;
    }
    let r_gen = g.generating_pin_radius();
    let rot = |v: [f64; 2]| {
        let v = g.apply_rotation_mod(v);
        [c * v[0] - s * v[1], s * v[0] + c * v[1]]
    };
    let n = rot(normal);
    let arm = rot([cp[0] - r_gen * normal[0], cp[1] - r_gen * normal[1]]);
    let t = [-n[1], n[0]];
    let cross = |a: [f64; 2], b: [f64; 2]| a[0] * b[1] - a[1] * b[0];
    let grad = [-n[0], -n[1], -cross(r, n)];
    let gt = [-t[0], -t[1], -cross(r, t)];
    let w = kappa / one_plus;
    let mut hess = [[0.0; 3]; 3];
    for a in 0..3 {
        for b in 0..3 {
            hess[a][b] = w * gt[a] * gt[b];
        }
    }
    hess[0][2] += n[1];
    hess[2][0] += n[1];
    hess[1][2] -= n[0];
    hess[2][1] -= n[0];
    hess[2][2] -= r[0] * n[0] + r[1] * n[1];
    Some(GapJet {
        gap: dist + r_gen - pin_radius,
        grad,
        hess,
        normal: n,
        arm,
        phi: foot.phi + dphi,
        cos_sin: foot.cos_sin,
        phi_cos_sin: {
            let (sd, cd) = crate::geometry::gap::small_sin_cos(dphi);
            let [c0, s0] = foot.cos_sin;
            [c0 * cd - s0 * sd, s0 * cd + c0 * sd]
        },
        curvature_radius: 1.0 / kappa - r_gen,
    })
}

/// The pin-centre curve `C(phi) = R (cos phi, sin phi) - e (cos zp phi, sin zp phi)`
/// (`R = rp + d_rp`, unrotated disc frame) and its derivatives of order 0 to 4 at `phi` \[m\]:
/// `C^(n) = R i^n e^(i phi) - e (i zp)^n e^(i zp phi)` in complex notation.
pub fn centre_curve_derivatives(geometry: &CycloidGeometry, phi: f64) -> [[f64; 2]; 5] {
    let (s1, c1) = phi.sin_cos();
    centre_curve_derivatives_cs(geometry, [c1, s1])
}

/// As [`centre_curve_derivatives`] from `(cos phi, sin phi)` (`cos zp phi`, `sin zp phi` as
/// the zp-th complex power, relative error ~zp eps).
pub fn centre_curve_derivatives_cs(geometry: &CycloidGeometry, cs: [f64; 2]) -> [[f64; 2]; 5] {
    let p = geometry.params();
    let r = p.pin_circle_radius + p.d_rp;
    let e = p.eccentricity;
    let z = f64::from(p.pins);
    let [c1, s1] = cs;
    let (cz, sz) = {
        let (mut rc, mut rs) = (1.0, 0.0);
        let (mut bc, mut bs) = (c1, s1);
        let mut n = p.pins;
        while n > 0 {
            if n & 1 == 1 {
                (rc, rs) = (rc * bc - rs * bs, rc * bs + rs * bc);
            }
            (bc, bs) = (bc * bc - bs * bs, 2.0 * bc * bs);
            n >>= 1;
        }
        (rc, rs)
    };
    // i^n (c, s): quarter turns.
    let turn = |n: usize, c: f64, s: f64| match n % 4 {
        0 => [c, s],
        1 => [-s, c],
        2 => [-c, -s],
        _ => [s, -c],
    };
    let mut out = [[0.0; 2]; 5];
    let mut zn = 1.0;
    for (n, o) in out.iter_mut().enumerate() {
        let a = turn(n, c1, s1);
        let b = turn(n, cz, sz);
        *o = [r * a[0] - e * zn * b[0], r * a[1] - e * zn * b[1]];
        zn *= z;
    }
    out
}

/// Signed curvature `kappa_C` [1/m] of the pin-centre curve at `phi` with its first and second
/// derivatives in `phi` [1/m per rad, 1/m per rad^2]: `kappa = X s^(-3/2)` with
/// `X = C' x C''`, `s = |C'|^2` (do Carmo 1976, section 1-5), differentiated twice
/// (`X' = C' x C'''`, `X'' = C'' x C''' + C' x C''''`, `s' = 2 C'.C''`,
/// `s'' = 2 (|C''|^2 + C'.C''')`).
pub fn centre_curvature_derivatives(geometry: &CycloidGeometry, phi: f64) -> [f64; 3] {
    curvature_derivatives_of(&centre_curve_derivatives(geometry, phi))
}

/// [`centre_curvature_derivatives`] from the curve derivatives `d` (orders 0-4).
pub fn curvature_derivatives_of(d: &[[f64; 2]; 5]) -> [f64; 3] {
    let [_, c1, c2, c3, c4] = *d;
    let cross = |a: [f64; 2], b: [f64; 2]| a[0] * b[1] - a[1] * b[0];
    let dot = |a: [f64; 2], b: [f64; 2]| a[0] * b[0] + a[1] * b[1];
    let x = cross(c1, c2);
    let x1 = cross(c1, c3);
    let x2 = cross(c2, c3) + cross(c1, c4);
    let s = dot(c1, c1);
    let s1 = 2.0 * dot(c1, c2);
    let s2 = 2.0 * (dot(c2, c2) + dot(c1, c3));
    let m32 = 1.0 / (s * s.sqrt());
    let m52 = m32 / s;
    let m72 = m52 / s;
    [
        x * m32,
        x1 * m32 - 1.5 * x * m52 * s1,
        x2 * m32 - 3.0 * x1 * m52 * s1 - 1.5 * x * m52 * s2 + 3.75 * x * m72 * s1 * s1,
    ]
}

/// How the foot (the contact's curve parameter `phi`) moves with the disc pose
/// `q = (X, Y, theta)`: `dphi/dq` [rad/m, rad/m, -] and `d2phi/dq2`.
///
/// The foot satisfies `G(phi, p) = (C(phi) - p) . C'(phi) = 0` with `p` the pin centre in the
/// disc frame, so `dphi/dp = C' / G_phi`, `G_phi = |C'|^2 + (C - p) . C''`, and differentiating
/// once more `d2phi/dp2 = (C'' C'^T + C' C''^T) / G_phi^2 - G_phi' C' C'^T / G_phi^3` with
/// `G_phi' = 3 C'.C'' + (C - p).C'''` (implicit function theorem). The chain rule through
/// `p = R(-theta - d_delta)(P - O)` (`dp/dO = -R^T`, `dp/dtheta = -z x p`,
/// `d2p/dtheta2 = -p`, `d2p/dtheta dO_a = z x R^T e_a`) gives the derivatives in `q`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FootJet {
    /// `dphi/dq`.
    pub grad: [f64; 3],
    /// `d2phi/dq_a dq_b`.
    pub hess: [[f64; 3]; 3],
}

/// The [`FootJet`] of the pin at `pin_centre` \[m\] against `geometry` placed at `disc_centre`
/// \[m\] with `(cos, sin)` of its angle `disc_cos_sin`, at the foot `phi` \[rad\] (from the gap
/// query). `None` where `G_phi <= 0` (no unique foot).
pub fn foot_jet(
    geometry: &CycloidGeometry,
    pin_centre: [f64; 2],
    disc_centre: [f64; 2],
    disc_cos_sin: [f64; 2],
    phi: f64,
) -> Option<FootJet> {
    let d = centre_curve_derivatives(geometry, phi);
    foot_jet_with(geometry, pin_centre, disc_centre, disc_cos_sin, &d)
}

/// As [`foot_jet`] with the curve derivatives at the foot given (orders 0-4).
#[allow(clippy::needless_range_loop)]
pub fn foot_jet_with(
    geometry: &CycloidGeometry,
    pin_centre: [f64; 2],
    disc_centre: [f64; 2],
    disc_cos_sin: [f64; 2],
    derivs: &[[f64; 2]; 5],
) -> Option<FootJet> {
    let g = geometry;
    let [c, s] = disc_cos_sin;
    let r = [
        pin_centre[0] - disc_centre[0],
        pin_centre[1] - disc_centre[1],
    ];
    let p = g.remove_rotation_mod([c * r[0] + s * r[1], -s * r[0] + c * r[1]]);
    let [c0, c1, c2, c3, _] = *derivs;
    let dot = |a: [f64; 2], b: [f64; 2]| a[0] * b[0] + a[1] * b[1];
    let perp = |a: [f64; 2]| [-a[1], a[0]];
    let cp = [c0[0] - p[0], c0[1] - p[1]];
    let gphi = dot(c1, c1) + dot(cp, c2);
    if gphi.is_nan() || gphi <= 0.0 {
        return None;
    }
    let gphi1 = 3.0 * dot(c1, c2) + dot(cp, c3);
    let phi_p = [c1[0] / gphi, c1[1] / gphi];
    let (g2, g3) = (gphi * gphi, gphi * gphi * gphi);
    let mut hp = [[0.0; 2]; 2];
    for (a, row) in hp.iter_mut().enumerate() {
        for (b, v) in row.iter_mut().enumerate() {
            *v = (c2[a] * c1[b] + c1[a] * c2[b]) / g2 - gphi1 * c1[a] * c1[b] / g3;
        }
    }
    // Images of the world axes in the disc frame.
    let mx = g.remove_rotation_mod([c, -s]);
    let my = g.remove_rotation_mod([s, c]);
    let pp = perp(p);
    let cols = [[-mx[0], -mx[1]], [-my[0], -my[1]], [-pp[0], -pp[1]]];
    let mut out = FootJet::default();
    for a in 0..3 {
        out.grad[a] = dot(phi_p, cols[a]);
        let ha = [
            hp[0][0] * cols[a][0] + hp[0][1] * cols[a][1],
            hp[1][0] * cols[a][0] + hp[1][1] * cols[a][1],
        ];
        for b in 0..3 {
            out.hess[b][a] = dot(cols[b], ha);
        }
    }
    let ex = dot(phi_p, perp(mx));
    let ey = dot(phi_p, perp(my));
    out.hess[0][2] += ex;
    out.hess[2][0] += ex;
    out.hess[1][2] += ey;
    out.hess[2][1] += ey;
    out.hess[2][2] -= dot(phi_p, p);
    Some(out)
}

/// The static (zero-rate) jet of the line-contact pin law at one contact: the elastic force and
/// everything the tangent of the energy `U(delta, phi)` needs.
///
/// With `delta = F (K0(phi) - K1 ln F)` (`contact::line_contact`): `F_delta = k_t`,
/// `F_phi = dF/dphi|_delta = -F k_t K0'` (from `dF/dK0 = -F k_t`), `U_phi = -F^2 K0' / 2`
/// (as [`crate::contact::law::PinLaw::location_slope`]) and
/// `U_phi,phi = F^2 k_t K0'^2 - F^2 K0'' / 2`. `K0' = [2 c_2 (ln h_2)' - (c_1 + c_2) (ln R)']
/// / (pi L)` and `K0''` the same with second derivatives, from the profile curvature
/// `kappa_P = kappa_C / (1 - r kappa_C)` and its derivatives.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LineJet {
    /// Elastic force \[N\].
    pub force: f64,
    /// `dF/d delta` [N/m].
    pub stiffness: f64,
    /// `ln F` (a warm start of the next force query).
    pub ln_force: f64,
    /// `K0' = dK0/dphi` [m/N per rad].
    pub dk0: f64,
    /// `K0''` [m/N per rad^2].
    pub d2k0: f64,
}

impl LineJet {
    /// `U_phi = dU/dphi` at fixed approach [J/rad].
    #[inline]
    pub fn energy_per_phi(&self) -> f64 {
        -0.5 * self.force * self.force * self.dk0
    }
    /// `d2U / d delta dphi` [N/rad].
    #[inline]
    pub fn cross(&self) -> f64 {
        -self.force * self.stiffness * self.dk0
    }
    /// `d2U/dphi2` at fixed approach [J/rad^2].
    #[inline]
    pub fn phi_phi(&self) -> f64 {
        let f2 = self.force * self.force;
        f2 * self.stiffness * self.dk0 * self.dk0 - 0.5 * f2 * self.d2k0
    }
}

/// The [`LineJet`] of a pin of radius `pin_radius` \[m\] touching `geometry` at `phi` with the
/// approach `pen` \[m\] (> 0), body depth `depth` \[m\] and the materials; `ln_guess` warm-starts
/// the force inversion. Errors as
/// [`crate::contact::line_contact::LineContactLaw::cycloid_contact`].
#[allow(clippy::too_many_arguments)]
pub fn line_jet(
    geometry: &CycloidGeometry,
    phi: f64,
    pen: f64,
    pin_radius: f64,
    depth: f64,
    pin: &crate::contact::Material,
    disc: &crate::contact::Material,
    ln_guess: f64,
) -> Result<LineJet> {
    let d = centre_curve_derivatives(geometry, phi);
    line_jet_with(geometry, &d, pen, pin_radius, depth, pin, disc, ln_guess)
}

/// As [`line_jet`] with the curve derivatives at the contact given (orders 0-4).
#[allow(clippy::too_many_arguments)]
pub fn line_jet_with(
    geometry: &CycloidGeometry,
    derivs: &[[f64; 2]; 5],
    pen: f64,
    pin_radius: f64,
    depth: f64,
    pin: &crate::contact::Material,
    disc: &crate::contact::Material,
    ln_guess: f64,
) -> Result<LineJet> {
    use crate::error::require_positive;
    require_positive("pin radius", pin_radius, "m")?;
    require_positive("disc reference depth", depth, "m")?;
    pin.validate()?;
    disc.validate()?;
    let base = crate::contact::line_contact::PinDiscLawBase::new(
        pin_radius,
        geometry.params().face_width,
        pin,
        disc,
    );
    line_jet_checked(geometry, derivs, pen, &base, depth, depth.ln(), ln_guess)
}

/// [`line_jet_with`] for a positive finite pin radius and depth and valid materials (checked
/// once, at the scene's build), given as the contact-independent part `base` of the law and the
/// body depth `depth` \[m\] with its logarithm `ln_depth`: the same jet to round-off (one
/// logarithm fewer per contact, see [`crate::contact::line_contact::PinDiscLawBase`]), without
/// re-checking the input at every contact.
#[inline]
pub(crate) fn line_jet_checked(
    geometry: &CycloidGeometry,
    derivs: &[[f64; 2]; 5],
    pen: f64,
    base: &crate::contact::line_contact::PinDiscLawBase,
    depth: f64,
    ln_depth: f64,
    ln_guess: f64,
) -> Result<LineJet> {
    use crate::contact::line_contact::{disc_reference_depth_ratio, profile_curvature_checked};
    let [kc, kc1, kc2] = curvature_derivatives_of(derivs);
    let r = geometry.generating_pin_radius();
    // kappa_P = kappa_C / (1 - r kappa_C) (`pin_disc_profile_curvature`).
    let k2 = profile_curvature_checked(kc, r)?;
    // ln h = ln D - ln(D / h).
    let (dj, ratio) = disc_reference_depth_ratio(k2, depth);
    let law = base.law(k2, dj.depth, ln_depth - ratio)?;
    let (force, stiffness, ln_force) = law.force_and_stiffness_from(pen, ln_guess);
    let den = 1.0 - r * kc;
    let dk2 = kc1 / (den * den);
    let d2k2 = kc2 / (den * den) + 2.0 * r * kc1 * kc1 / (den * den * den);
    let sum = base.pin_curvature() + k2;
    let dln_r = -dk2 / sum;
    let d2ln_r = -d2k2 / sum + dk2 * dk2 / (sum * sum);
    let (dln_h, d2ln_h) = (
        dj.dln_dkappa * dk2,
        dj.dln_dkappa * d2k2 + dj.d2ln_dkappa2 * dk2 * dk2,
    );
    let [c1, c2] = base.compliances();
    let pl = base.pi_length();
    Ok(LineJet {
        force,
        stiffness,
        ln_force,
        dk0: (2.0 * c2 * dln_h - (c1 + c2) * dln_r) / pl,
        d2k0: (2.0 * c2 * d2ln_h - (c1 + c2) * d2ln_r) / pl,
    })
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::*;
    use crate::geometry::cycloid::CycloidParams;

    fn rng(seed: u64) -> impl FnMut() -> f64 {
        let mut state = seed;
        move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64) / ((1u64 << 53) as f64) - 0.5
        }
    }

    fn gap_at(g: &CycloidGeometry, pin: [f64; 2], q: [f64; 3], seed: f64) -> GapJet {
        pin_gap_jet(g, pin, 0.010, [q[0], q[1]], q[2], seed).unwrap()
    }

    /// Central differences of the gap (gradient) and of the analytic gradient (Hessian) against
    /// the analytic derivatives, over random poses near the kinematic one, with and without
    /// modifications, for pins in contact and clear of it.
    ///
    /// Steps and why the tolerance holds: the gap is computed to round-off of the 0.15 m
    /// vectors it is made of (~3e-17 m) and the normal to ~1e-16. The pin-centre curve is
    /// sharply concave at the tooth root (radius 0.72 mm for the paper disc: |kappa| <= 1.4e3
    /// /m), which sets the truncation errors. Gradient by central differences of the gap with
    /// h = 1e-6 m (h / rp in the angle): truncation h^2 kappa^2 / 6 ~ 3e-7, round-off
    /// 3e-17 / 1e-6 = 3e-11, against |grad| ~ 1. Hessian by central differences of the
    /// analytic gradient with h = 1e-7 m: truncation h^2 kappa^3 / 6 ~ 5e-6 /m, round-off
    /// 1e-16 / 1e-7 = 1e-9 /m, against entries up to ~1.4e3 /m. Both asserted below 1e-6
    /// (the Hessian relative to its largest entry, the angle scaled by rp so that all entries
    /// have the same unit).
    #[test]
    fn gradient_and_hessian_match_finite_differences() {
        let mut rnd = rng(7);
        let mut worst_g: f64 = 0.0;
        let mut worst_h: f64 = 0.0;
        for (d_rp, d_rrp, d_delta) in [(0.0, 0.0, 0.0), (-2e-5, 2e-5, 1e-4), (1e-5, -1e-5, 0.0)] {
            let mut p = CycloidParams::paper();
            p.d_rp = d_rp;
            p.d_rrp = d_rrp;
            p.d_delta = d_delta;
            let g = CycloidGeometry::new(p).unwrap();
            let rp = 0.15;
            for _ in 0..60 {
                let psi = 10.0 * rnd();
                let q0 = [
                    4.5e-3 * psi.cos() + 1e-4 * rnd(),
                    4.5e-3 * psi.sin() + 1e-4 * rnd(),
                    -psi / 23.0 + 1e-3 * rnd(),
                ];
                let j = ((rnd() + 0.5) * 24.0) as usize % 24;
                let th = g.pin_angle(j);
                let pin = [rp * th.cos(), rp * th.sin()];
                let seed = th - q0[2];
                let jet = gap_at(&g, pin, q0, seed);
                // Coordinates (X, Y, rp theta): every derivative in 1 or 1/m.
                let scale = [1.0, 1.0, 1.0 / rp];
                let mut hmax: f64 = 0.0;
                for a in 0..3 {
                    for b in 0..3 {
                        hmax = hmax.max((jet.hess[a][b] * scale[a] * scale[b]).abs());
                    }
                }
                for a in 0..3 {
                    let shifted = |h: f64| {
                        let mut qp = q0;
                        let mut qm = q0;
                        qp[a] += h * scale[a];
                        qm[a] -= h * scale[a];
                        (gap_at(&g, pin, qp, seed), gap_at(&g, pin, qm, seed))
                    };
                    let (jp, jm) = shifted(1e-6);
                    let fd = (jp.gap - jm.gap) / 2e-6;
                    worst_g = worst_g.max((fd - jet.grad[a] * scale[a]).abs());
                    let (jp, jm) = shifted(1e-7);
                    for b in 0..3 {
                        let fd2 = (jp.grad[b] - jm.grad[b]) * scale[b] / 2e-7;
                        let an = jet.hess[a][b] * scale[a] * scale[b];
                        worst_h = worst_h.max((fd2 - an).abs() / hmax);
                    }
                }
            }
        }
        eprintln!("gradient vs FD {worst_g:e}, Hessian vs FD {worst_h:e}");
        assert!(worst_g < 1e-6, "gradient vs FD: {worst_g:e}");
        assert!(
            worst_h < 1e-6,
            "Hessian vs FD: {worst_h:e} of the largest entry"
        );
    }

    #[test]
    fn lever_and_gradient_agree_with_the_gap_module_and_the_classical_lever() {
        // At the kinematic pose of the unmodified disc the lever of pin j is the classical
        // l_j = rc' sin(phi_j) / S_j (crate::analysis::load_sharing), and the gap, point and
        // normal are those of CycloidGeometry::gap.
        let g = CycloidGeometry::new(CycloidParams::paper()).unwrap();
        for psi in [0.0, 0.123, 1.7, -2.9] {
            let (c, a) = (
                [4.5e-3 * f64::cos(psi), 4.5e-3 * f64::sin(psi)],
                -psi / 23.0,
            );
            let levers = crate::analysis::classical_levers(&g, psi);
            for (j, l) in levers.iter().enumerate() {
                let th = g.pin_angle(j);
                let pin = [0.15 * th.cos(), 0.15 * th.sin()];
                let jet = pin_gap_jet(&g, pin, 0.010, c, a, th - a).unwrap();
                let reference = g.gap(pin, c, a).unwrap();
                assert!((jet.gap - reference.gap).abs() < 1e-14);
                // The gap module stops its foot search at a step tolerance: its normal is good
                // to ~1e-11 (the jet adds one Newton correction).
                assert!((jet.normal[0] - reference.normal[0]).abs() < 1e-10);
                assert!((jet.normal[1] - reference.normal[1]).abs() < 1e-10);
                assert!((c[0] + jet.arm[0] - reference.point[0]).abs() < 1e-12);
                assert!((jet.curvature_radius - reference.curvature_radius).abs() < 1e-9);
                // d gap / d theta = -lever; classical lever to round-off.
                assert!((jet.grad[2] + jet.lever()).abs() < 1e-15);
                assert!(
                    (jet.lever() - l).abs() < 1e-13,
                    "pin {j}: {} {l}",
                    jet.lever()
                );
            }
        }
    }

    #[test]
    fn bad_input_is_an_error_not_nan() {
        let g = CycloidGeometry::new(CycloidParams::paper()).unwrap();
        assert!(matches!(
            pin_gap_jet(&g, [f64::NAN, 0.0], 0.01, [0.0; 2], 0.0, 0.0),
            Err(RvdynError::Parameter(_))
        ));
        assert!(pin_gap_jet(&g, [0.15, 0.0], 0.01, [0.0; 2], f64::INFINITY, 0.0).is_err());
    }

    /// The closed-form curve derivatives equal the geometry's own jet (orders 0-2, to
    /// round-off of the 0.15 m vectors) and central differences of the next lower order
    /// (orders 3-4; step 1e-6 rad, truncation h^2 zp^2 / 6 ~ 1e-10 relative, round-off
    /// 1e-16 / 1e-6 relative: asserted 1e-7 of the order's scale `e zp^n`).
    #[test]
    fn curve_derivatives_match_the_jet_and_differences() {
        let mut p = CycloidParams::paper();
        p.d_rp = -2e-5;
        let g = CycloidGeometry::new(p).unwrap();
        let e = p.eccentricity;
        for i in 0..50 {
            let phi = -3.0 + 0.137 * i as f64;
            let d = centre_curve_derivatives(&g, phi);
            let j = g.jet(phi);
            for a in 0..2 {
                assert!((d[0][a] - j.c[a]).abs() < 1e-15);
                assert!((d[1][a] - j.d1[a]).abs() < 1e-14);
                assert!((d[2][a] - j.d2[a]).abs() < 1e-13);
            }
            let h = 1e-6;
            let (dp, dm) = (
                centre_curve_derivatives(&g, phi + h),
                centre_curve_derivatives(&g, phi - h),
            );
            for n in 3..5 {
                let scale = e * 24f64.powi(n as i32);
                for a in 0..2 {
                    let fd = (dp[n - 1][a] - dm[n - 1][a]) / (2.0 * h);
                    assert!((fd - d[n][a]).abs() < 1e-7 * scale, "order {n}");
                }
            }
            // Curvature and its derivatives against the geometry and differences of them
            // (|kappa| up to 1.4e3 /m at the root; h = 2e-6 rad: truncation ~h^2 of the next
            // derivatives, round-off 1e-13 / 2e-6 relative: 1e-6 of the scale).
            let k = centre_curvature_derivatives(&g, phi);
            assert!((k[0] - g.centre_curve_curvature(phi)).abs() < 1e-9 * k[0].abs().max(1.0));
            let h = 2e-6;
            let fd1 =
                (g.centre_curve_curvature(phi + h) - g.centre_curve_curvature(phi - h)) / (2.0 * h);
            let fd2 = (centre_curvature_derivatives(&g, phi + h)[1]
                - centre_curvature_derivatives(&g, phi - h)[1])
                / (2.0 * h);
            let s1 = k[1].abs().max(1e3);
            let s2 = k[2].abs().max(1e4);
            assert!((fd1 - k[1]).abs() < 1e-6 * s1, "{fd1} {}", k[1]);
            assert!((fd2 - k[2]).abs() < 1e-6 * s2, "{fd2} {}", k[2]);
        }
    }

    /// The foot's gradient and Hessian in the disc pose equal central differences of the foot
    /// (from gap queries) and of the analytic gradient. Feet move by ~1/|C'| ~ 7 rad/m with
    /// the pose (more near the sharp root); steps h = 1e-6 m (gradient; truncation
    /// ~h^2 |phi'''|, round-off ~1e-12 rad / 1e-6) and 1e-7 m (Hessian). Asserted: 1e-5
    /// relative to the largest entry (angles scaled by rp).
    #[test]
    fn foot_jet_matches_finite_differences() {
        let mut rnd = rng(23);
        for d_delta in [0.0, 1e-4] {
            let mut p = CycloidParams::paper();
            p.d_rrp = 2e-5;
            p.d_delta = d_delta;
            let g = CycloidGeometry::new(p).unwrap();
            let rp = 0.15;
            for _ in 0..40 {
                let psi = 10.0 * rnd();
                let q0 = [
                    4.5e-3 * psi.cos() + 1e-5 * rnd(),
                    4.5e-3 * psi.sin() + 1e-5 * rnd(),
                    -psi / 23.0 + 1e-4 * rnd(),
                ];
                let j = ((rnd() + 0.5) * 24.0) as usize % 24;
                let th = g.pin_angle(j);
                let pin = [rp * th.cos(), rp * th.sin()];
                let seed = th - q0[2];
                let jet_at = |q: [f64; 3]| {
                    let jet = gap_at(&g, pin, q, seed);
                    let fj =
                        foot_jet(&g, pin, [q[0], q[1]], [q[2].cos(), q[2].sin()], jet.phi).unwrap();
                    (jet.phi, fj)
                };
                let (_, f0) = jet_at(q0);
                let scale = [1.0, 1.0, 1.0 / rp];
                let gmax = (0..3).fold(0.0f64, |m, a| m.max((f0.grad[a] * scale[a]).abs()));
                let mut hmax: f64 = 0.0;
                for a in 0..3 {
                    for b in 0..3 {
                        hmax = hmax.max((f0.hess[a][b] * scale[a] * scale[b]).abs());
                    }
                }
                for a in 0..3 {
                    let at = |h: f64| {
                        let (mut qp, mut qm) = (q0, q0);
                        qp[a] += h * scale[a];
                        qm[a] -= h * scale[a];
                        (jet_at(qp), jet_at(qm))
                    };
                    let ((pp, _), (pm, _)) = at(1e-6);
                    let fd = (pp - pm) / 2e-6;
                    assert!(
                        (fd - f0.grad[a] * scale[a]).abs() < 1e-5 * gmax,
                        "grad {a}: {fd} {}",
                        f0.grad[a] * scale[a]
                    );
                    let ((_, jp), (_, jm)) = at(1e-7);
                    for b in 0..3 {
                        let fd2 = (jp.grad[b] - jm.grad[b]) * scale[b] / 2e-7;
                        let an = f0.hess[a][b] * scale[a] * scale[b];
                        assert!((fd2 - an).abs() < 1e-5 * hmax, "hess {a}{b}: {fd2} {an}");
                    }
                }
            }
        }
    }

    /// The line jet against the law itself: the force is the law's, `U_phi` and `U_phi,phi`
    /// are central differences (in phi, at fixed approach) of the law's elastic energy, the
    /// cross term `d2U/d delta dphi` a central difference of its force, and `U_phi` is the
    /// models' location term (`PinLaw::location_slope`, whose `dK0/dphi` uses a difference
    /// of the curvature). Steps 1e-5 rad (first) and 3e-5 rad (second difference): the
    /// truncation ~h^2 of the third derivative is largest near the sharp root (5e-4 relative
    /// at h = 1e-4), the energy round-off 1e-16 / h^2 stays below 1e-6: asserted 1e-4 of the largest value over a lobe (1e-6 for the models'
    /// term), inside and outside the blend of the disc's reference depth.
    #[test]
    fn line_jet_matches_the_law() {
        use crate::contact::Material;
        use crate::contact::law::{ContactDamping, DampingSpec, PinLaw, PinSite};
        use crate::contact::line_contact::LineContactLaw;
        let g = CycloidGeometry::new(CycloidParams::paper()).unwrap();
        let steel = Material::new(2.17e11, 0.3).unwrap();
        let depth = 0.14;
        let pen = 2e-5;
        let law = PinLaw::Line {
            pin: steel,
            disc: steel,
            damping: ContactDamping::new(&DampingSpec::DampingRatio {
                ratio: 0.05,
                frequency: 1000.0,
            })
            .unwrap(),
        };
        let contact = |phi: f64| {
            LineContactLaw::cycloid_contact(&g, phi, 0.01, depth, &steel, &steel).unwrap()
        };
        let energy = |phi: f64| contact(phi).elastic_energy(pen);
        let force = |phi: f64| contact(phi).force(pen);
        let lobe = 2.0 * std::f64::consts::PI / 23.0;
        let jets: Vec<(f64, LineJet)> = (1..40)
            .map(|i| {
                let phi = lobe * i as f64 / 40.0;
                let j = line_jet(&g, phi, pen, 0.01, depth, &steel, &steel, f64::NAN).unwrap();
                (phi, j)
            })
            .collect();
        let m1 = jets
            .iter()
            .fold(0.0f64, |m, (_, j)| m.max(j.energy_per_phi().abs()));
        let m2 = jets
            .iter()
            .fold(0.0f64, |m, (_, j)| m.max(j.phi_phi().abs()));
        let mc = jets.iter().fold(0.0f64, |m, (_, j)| m.max(j.cross().abs()));
        let mut tested = 0;
        for (phi, j) in &jets {
            let phi = *phi;
            assert!((j.force - force(phi)).abs() < 1e-9 * j.force);
            let kc = g.centre_curve_curvature(phi);
            let kp = kc / (1.0 - g.generating_pin_radius() * kc);
            if ((kp * depth) - 1.0).abs() < 0.05 {
                continue;
            }
            tested += 1;
            let h = 1e-5;
            let fd1 = (energy(phi + h) - energy(phi - h)) / (2.0 * h);
            assert!(
                (fd1 - j.energy_per_phi()).abs() < 1e-4 * m1,
                "U_phi at {phi}"
            );
            let fdc = (force(phi + h) - force(phi - h)) / (2.0 * h);
            assert!((fdc - j.cross()).abs() < 1e-4 * mc, "U_dphi at {phi}");
            let h = 3e-5;
            let fd2 = (energy(phi + h) - 2.0 * energy(phi) + energy(phi - h)) / (h * h);
            assert!(
                (fd2 - j.phi_phi()).abs() < 1e-4 * m2,
                "U_phiphi at {phi}: {fd2} {}",
                j.phi_phi()
            );
            let site = PinSite {
                geometry: &g,
                phi,
                pin_radius: 0.01,
                depth,
            };
            let jj = g.jet(phi);
            let n = CycloidGeometry::normal_from_tangent(jj.d1);
            let pin = [jj.c[0] + 1e-3 * n[0], jj.c[1] + 1e-3 * n[1]];
            let ls = law
                .location_slope(j.force, &site, pin, [0.0; 2], 0.0)
                .unwrap();
            assert!(
                (ls.energy_per_phi - j.energy_per_phi()).abs() < 1e-6 * m1,
                "{} {}",
                ls.energy_per_phi,
                j.energy_per_phi()
            );
        }
        assert!(tested > 30, "{tested}");
    }

    /// The location term of the line law alone, `Q_loc = -U_phi(delta, phi) grad phi`, against
    /// central differences: `-dQ_loc/dq = -U_dphi phi g^T +
    /// U_phiphi phi phi^T + U_phi hess phi` (the matrix the LTCA tangent adds, less the half of
    /// the cross term that comes from `dF/dphi`). This checks `hess phi` and `U_phiphi`, which
    /// are ~1e-7 of the whole contact stiffness and invisible in the full tangent. Pose steps
    /// 1e-7 and 2e-7 m (rp times that in the angle), Richardson-extrapolated (the h^2 error of
    /// a plain central difference is 4e-5 relative at 1e-7 m; smaller steps meet the
    /// resolution of the foot and force inversions); asserted 1e-5 of the largest entry, at
    /// contacts away from the root and from the kink of the disc depth.
    #[test]
    fn line_location_term_matches_finite_differences() {
        use crate::contact::Material;
        let g = CycloidGeometry::new(CycloidParams::paper()).unwrap();
        let steel = Material::new(2.17e11, 0.3).unwrap();
        let depth = 0.14;
        let rp = 0.15;
        let mut rnd = rng(31);
        let mut tested = 0;
        while tested < 20 {
            let psi = 10.0 * rnd();
            let q0 = [
                4.5e-3 * psi.cos(),
                4.5e-3 * psi.sin(),
                -psi / 23.0 - 1e-4 * (rnd() + 0.6),
            ];
            let j = ((rnd() + 0.5) * 24.0) as usize % 24;
            let th = g.pin_angle(j);
            let pin = [rp * th.cos(), rp * th.sin()];
            let seed = th - q0[2];
            let eval = |q: [f64; 3]| {
                let jet = gap_at(&g, pin, q, seed);
                let cs = [q[2].cos(), q[2].sin()];
                let fj = foot_jet(&g, pin, [q[0], q[1]], cs, jet.phi).unwrap();
                let lj =
                    line_jet(&g, jet.phi, -jet.gap, 0.01, depth, &steel, &steel, f64::NAN).unwrap();
                (jet, fj, lj)
            };
            let (jet, fj, lj) = eval(q0);
            if -jet.gap < 1e-6 || jet.curvature_radius.abs() < 5e-3 {
                continue;
            }
            let kp = 1.0 / jet.curvature_radius;
            if (kp * depth - 1.0).abs() < 0.05 {
                continue;
            }
            tested += 1;
            let u = lj.energy_per_phi();
            let scale = [1.0, 1.0, 1.0 / rp];
            let mut an = [[0.0; 3]; 3];
            let mut amax: f64 = 0.0;
            for a in 0..3 {
                for b in 0..3 {
                    an[a][b] = (-lj.cross() * fj.grad[a] * jet.grad[b]
                        + lj.phi_phi() * fj.grad[a] * fj.grad[b]
                        + u * fj.hess[a][b])
                        * scale[a]
                        * scale[b];
                    amax = amax.max(an[a][b].abs());
                }
            }
            for b in 0..3 {
                // Central differences at h and 2h, extrapolated (Richardson): the h^2 error
                // (4e-5 relative at h = 1e-7) cancels.
                let diff = |h: f64| {
                    let (mut qp, mut qm) = (q0, q0);
                    qp[b] += h * scale[b];
                    qm[b] -= h * scale[b];
                    let (_, fp, lp) = eval(qp);
                    let (_, fm, lm) = eval(qm);
                    let mut out = [0.0; 3];
                    for (a, o) in out.iter_mut().enumerate() {
                        let qa_p = -lp.energy_per_phi() * fp.grad[a];
                        let qa_m = -lm.energy_per_phi() * fm.grad[a];
                        *o = -(qa_p - qa_m) / (2.0 * h) * scale[a];
                    }
                    out
                };
                let (d1, d2) = (diff(1e-7), diff(2e-7));
                for a in 0..3 {
                    let fd = (4.0 * d1[a] - d2[a]) / 3.0;
                    assert!(
                        (fd - an[a][b]).abs() < 1e-5 * amax,
                        "({a}, {b}): {fd} vs {} (largest {amax})",
                        an[a][b]
                    );
                }
            }
        }
    }
}
