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

use crate::error::{Result, RvdynError, require_finite};
use crate::geometry::CycloidGeometry;

/// The gap of one pin against one disc with its derivatives in the disc pose `(X, Y, theta)`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GapJet {
    /// Signed gap [m] (negative = penetration).
    pub gap: f64,
    /// `d gap / d(X, Y, theta)` [-, -, m].
    pub grad: [f64; 3],
    /// Second derivatives `d2 gap / dq_a dq_b` [1/m, 1/m, 1; 1/m, 1/m, 1; 1, 1, m].
    pub hess: [[f64; 3]; 3],
    /// Unit outward profile normal at the contact, fixed frame (from the disc to the pin).
    pub normal: [f64; 2],
    /// Contact point on the profile relative to the disc centre, fixed frame [m].
    pub arm: [f64; 2],
    /// Curve parameter of the foot [rad] (not reduced to `[0, 2 pi)`).
    pub phi: f64,
    /// `(cos phi, sin phi)` of the foot (a warm start for the next query).
    pub cos_sin: [f64; 2],
    /// Signed radius of curvature of the profile at the contact [m] (positive convex).
    pub curvature_radius: f64,
}

impl GapJet {
    /// Lever of the normal about the disc centre, `arm x normal` [m].
    #[inline]
    pub fn lever(&self) -> f64 {
        self.arm[0] * self.normal[1] - self.arm[1] * self.normal[0]
    }
}

/// The exact gap of the pin (`pin_centre` [m], `pin_radius` [m]) against `geometry` placed at
/// `disc_centre` [m], `disc_angle` [rad], with its gradient and Hessian in the disc pose.
///
/// `seed` is a curve parameter [rad] near the expected foot (e.g. the previous foot, or the
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
    // One more Newton correction of the foot from a fresh jet (the foot search stops at a
    // step tolerance: this brings the normal to round-off, which the Hessian needs), then the
    // curvature of the pin-centre curve there.
    let jet = g.jet_cs(foot.cos_sin[0], foot.cos_sin[1]);
    let (d1, d2) = (jet.d1, jet.d2);
    let rc = [jet.c[0] - local[0], jet.c[1] - local[1]];
    let d1sq = d1[0] * d1[0] + d1[1] * d1[1];
    let fp = d1sq + rc[0] * d2[0] + rc[1] * d2[1];
    let dphi = -(rc[0] * d1[0] + rc[1] * d1[1]) / fp;
    let h2 = 0.5 * dphi * dphi;
    let cp = [
        jet.c[0] + dphi * d1[0] + h2 * d2[0],
        jet.c[1] + dphi * d1[1] + h2 * d2[1],
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
        curvature_radius: 1.0 / kappa - r_gen,
    })
}

#[cfg(test)]
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
}
