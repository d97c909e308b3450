//! The exact signed gap between a pin and the cycloid profile.
//!
//! A pin is a circle; the profile is the offset (by `rrp + d_rrp`) of the pin-centre curve `C`,
//! and offsets share normals. So the nearest profile point to a pin is found as the foot of the
//! pin centre on `C`: Newton on `f(phi) = (C(phi) - p) . C'(phi) = 0`. The parry2d polyline
//! supplies the starting parameter (global), or a caller that knows a good one (the previous
//! step, or the kinematic parameter) passes it in and the polyline is used only as a fallback.

use crate::error::{Result, RvdynError, require_finite, require_positive};
use crate::geometry::cycloid::CycloidGeometry;
use std::f64::consts::PI;

/// Newton stops once a step moves the foot by less than this [m]. Convergence is quadratic:
/// the foot error left after such a step is about `step^2 / rho`, `rho >= 0.72 mm` the smallest
/// radius of curvature of the default pin-centre curve, i.e. below 1e-12 m; the gap, which is
/// stationary at the foot, is exact to round-off.
pub const FOOT_TOLERANCE: f64 = 2.5e-8;
const MAX_NEWTON: u32 = 40;

/// `(sin x, cos x)` for `|x| < 0.01` by their Taylor series (truncation below 1e-20).
#[inline]
pub(crate) fn small_sin_cos(x: f64) -> (f64, f64) {
    let x2 = x * x;
    let s = x * (1.0 - x2 / 6.0 * (1.0 - x2 / 20.0 * (1.0 - x2 / 42.0 * (1.0 - x2 / 72.0))));
    let c = 1.0 - x2 / 2.0 * (1.0 - x2 / 12.0 * (1.0 - x2 / 30.0 * (1.0 - x2 / 56.0)));
    (s, c)
}

/// Result of an exact gap query, in the fixed frame (SI).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PinGap {
    /// Signed normal gap between the pin circle and the profile [m]; negative = penetration.
    pub gap: f64,
    /// Contact point on the disc profile, fixed frame [m].
    pub point: [f64; 2],
    /// Unit outward normal of the profile at the contact (points from the disc to the pin).
    pub normal: [f64; 2],
    /// Curve parameter of the contact, in `[0, 2 pi)` [rad].
    pub phi: f64,
    /// Signed radius of curvature of the profile at the contact [m] (positive convex).
    pub curvature_radius: f64,
    /// Newton iterations used.
    pub iterations: u32,
}

/// Foot of a point on the pin-centre curve, unrotated disc frame.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LocalFoot {
    pub phi: f64,
    /// `cos phi`, `sin phi`.
    pub cos_sin: [f64; 2],
    /// Signed distance `(p - C) . n` [m].
    pub dist: f64,
    /// Outward unit normal at the foot.
    pub normal: [f64; 2],
    /// Foot point on `C`.
    pub centre_point: [f64; 2],
    pub iterations: u32,
}

impl CycloidGeometry {
    /// Exact gap between pin circle (centre `pin_center` [m], radius the disc's `pin_radius`)
    /// and the profile of this disc placed with its centre at `disc_center` [m] and turned by
    /// `disc_angle` [rad] (fixed frame).
    ///
    /// Returns the signed gap (negative = penetration), the contact point on the profile, the
    /// outward unit normal, the curve parameter and the local curvature radius. Valid while the
    /// pin centre is closer to the pin-centre curve than its smallest concave radius of
    /// curvature (0.72 mm for the default disc); beyond that the foot is not unique.
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

    /// As [`CycloidGeometry::gap`] for a pin of another radius [m] (pin radius errors).
    pub fn gap_with_pin_radius(
        &self,
        pin_center: [f64; 2],
        pin_radius: f64,
        disc_center: [f64; 2],
        disc_angle: f64,
    ) -> Result<PinGap> {
        let p = self.to_local(pin_center, disc_center, disc_angle)?;
        require_positive("pin_radius", pin_radius, "m")?;
        let seed = self
            .seed
            .seed(p)
            .ok_or_else(|| RvdynError::Parameter("pin and disc positions must be finite".into()))?;
        let foot = self.foot(p, seed).ok_or_else(|| self.no_foot(p))?;
        Ok(self.to_global(&foot, pin_radius, disc_center, disc_angle))
    }

    /// As [`CycloidGeometry::gap_with_pin_radius`], starting Newton from `seed_phi` [rad]; the
    /// polyline seed is used only if Newton fails from there. For hot loops that know where the
    /// contact was (previous step) or should be (kinematics).
    pub fn gap_seeded(
        &self,
        pin_center: [f64; 2],
        pin_radius: f64,
        disc_center: [f64; 2],
        disc_angle: f64,
        seed_phi: f64,
    ) -> Result<PinGap> {
        let p = self.to_local(pin_center, disc_center, disc_angle)?;
        let foot = self
            .foot_with_fallback(p, seed_phi)
            .ok_or_else(|| self.no_foot(p))?;
        Ok(self.to_global(&foot, pin_radius, disc_center, disc_angle))
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
            None => self.foot(p, self.seed.seed(p)?),
        }
    }

    /// Newton on the exact curve parameter. `None` if it leaves the convex basin of the
    /// distance (the point is beyond a centre of curvature) or does not converge.
    #[inline]
    pub(crate) fn foot(&self, p: [f64; 2], seed: f64) -> Option<LocalFoot> {
        let (s, c) = seed.sin_cos();
        self.foot_cs(p, seed, [c, s])
    }

    /// As [`CycloidGeometry::foot`] with `cos` and `sin` of the seed given (a caller that kept
    /// them from the previous foot saves the trigonometry). Small Newton steps turn
    /// `(cos, sin)` by the step's rotation (Taylor series to the 9th order: exact to round-off
    /// for steps below 0.01 rad) instead of evaluating `sin_cos` again.
    #[inline]
    pub(crate) fn foot_cs(&self, p: [f64; 2], seed: f64, seed_cs: [f64; 2]) -> Option<LocalFoot> {
        let max_step = PI / (2.0 * f64::from(self.pins()));
        let mut phi = seed;
        let [mut c1, mut s1] = seed_cs;
        for it in 1..=MAX_NEWTON {
            let j = self.jet_cs(c1, s1);
            let r = [j.c[0] - p[0], j.c[1] - p[1]];
            let dot = |a: [f64; 2], b: [f64; 2]| a[0] * b[0] + a[1] * b[1];
            let f = dot(r, j.d1);
            let d1sq = dot(j.d1, j.d1);
            let fp = d1sq + dot(r, j.d2);
            if fp.is_nan() || fp <= 0.0 {
                return None;
            }
            let step = (-f / fp).clamp(-max_step, max_step);
            phi += step;
            [c1, s1] = if step.abs() < 0.01 {
                let (ds, dc) = small_sin_cos(step);
                [c1 * dc - s1 * ds, s1 * dc + c1 * ds]
            } else {
                let (s, c) = phi.sin_cos();
                [c, s]
            };
            if step.abs() * d1sq.sqrt() < FOOT_TOLERANCE {
                // The last step moved the foot by less than the tolerance: update point and
                // tangent by their Taylor series instead of evaluating the jet again (errors
                // ~1e-20 m and ~1e-15 rad; the distance is stationary at the foot).
                let h2 = 0.5 * step * step;
                let c = [
                    j.c[0] + step * j.d1[0] + h2 * j.d2[0],
                    j.c[1] + step * j.d1[1] + h2 * j.d2[1],
                ];
                let d1 = [j.d1[0] + step * j.d2[0], j.d1[1] + step * j.d2[1]];
                let n = Self::normal_from_tangent(d1);
                let dist = (p[0] - c[0]) * n[0] + (p[1] - c[1]) * n[1];
                return Some(LocalFoot {
                    phi,
                    cos_sin: [c1, s1],
                    dist,
                    normal: n,
                    centre_point: c,
                    iterations: it,
                });
            }
        }
        None
    }

    /// Pin centre in the unrotated disc frame (rotation modification removed).
    #[inline]
    fn to_local(&self, pin: [f64; 2], centre: [f64; 2], angle: f64) -> Result<[f64; 2]> {
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
        Ok(self.remove_rotation_mod([c * d[0] + s * d[1], -s * d[0] + c * d[1]]))
    }

    fn to_global(&self, foot: &LocalFoot, pin_radius: f64, centre: [f64; 2], angle: f64) -> PinGap {
        let r = self.generating_pin_radius();
        let local_point = [
            foot.centre_point[0] - r * foot.normal[0],
            foot.centre_point[1] - r * foot.normal[1],
        ];
        let (s, c) = angle.sin_cos();
        let rot = |v: [f64; 2]| {
            let v = self.apply_rotation_mod(v);
            [c * v[0] - s * v[1], s * v[0] + c * v[1]]
        };
        let pt = rot(local_point);
        PinGap {
            gap: foot.dist + r - pin_radius,
            point: [pt[0] + centre[0], pt[1] + centre[1]],
            normal: rot(foot.normal),
            phi: foot.phi.rem_euclid(2.0 * PI),
            curvature_radius: self.curvature_radius(foot.phi),
            iterations: foot.iterations,
        }
    }

    fn no_foot(&self, p: [f64; 2]) -> RvdynError {
        RvdynError::Convergence(format!(
            "no unique nearest profile point for a pin centre at ({:.6e}, {:.6e}) m in the disc \
             frame: the pin is farther from the pin-centre curve than its concave radius of \
             curvature (deep inside or far outside the disc)",
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
        // notes/physics.md 1.3: g0(phi) = d_rrp - d_rp (1 - K1 cos phi)/S at the kinematic pose,
        // phi = mesh angle of the pin from the eccentricity direction.
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
        // Second-order remainder: ~3e-5 mm for 0.02 mm modifications (notes 1.3).
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
