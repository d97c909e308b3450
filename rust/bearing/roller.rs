//! Radial roller (needle) bearing with clearance: force on the inner ring from its 2-D
//! displacement, summed over the rollers.
//!
//! Rollers `j = 0..Z` at the angles `psi_j = psi_0 + 2 pi j / Z` (the cage angle `psi_0` turns
//! with the cage; pass 0 for a fixed reference). For a displacement `u = (x, y)` of the inner
//! ring relative to the outer ring, roller `j` is compressed by
//!
//! `delta_j = x cos psi_j + y sin psi_j - g`,
//!
//! `g` the radial clearance per side (half the diametral clearance `P_d`), and carries the load
//! `Q_j = K_n delta_j^(10/9)` if `delta_j > 0`, else 0. `K_n` combines the inner and outer
//! raceway contacts in series, each following Palmgren's line-contact law
//! `delta = 3.84e-5 Q^0.9 / l^0.8` [mm, N, mm] (T. A. Harris, M. N. Kotzalas, *Rolling Bearing
//! Analysis*, 5th ed., Taylor & Francis 2007, vol. 1, ch. 6 (contact deformation of line
//! contact) and ch. 7 (distribution of internal loading)): the roller deflection is
//! `2 * 3.84e-5 Q^0.9 / l^0.8`, so `K_n = (l^0.8 / (2 * 3.84e-5))^(10/9)` N/mm^(10/9) with `l`
//! in mm. The force on the inner ring is `F = -sum_j Q_j (cos psi_j, sin psi_j)` and the
//! tangent stiffness matrix `K = -dF/du = sum_j (dQ_j/d delta_j) n_j n_j^T` (symmetric,
//! positive semi-definite; both continuous in `u` because `Q ~ delta^(10/9)` has a slope that
//! tends to 0 at first contact).
//!
//! Check (zero clearance, many rollers): `F_r = Z K_n delta_r^(10/9) J_r(0.5)` with Sjovall's
//! radial integral `J_r(0.5) = (1/2pi) integral_{-pi/2}^{pi/2} cos^(19/9) psi d psi = 0.24480`
//! (Harris & Kotzalas, ch. 7, tabulate `J_r(epsilon)` for line contact: 0.2453, computed with
//! the exponent rounded to 1.1), hence the radial
//! stiffness `dF_r / d delta_r = (10/9) F_r / delta_r`.
//!
//! Theory: docs/model.md, sections "Roller bearing with clearance"
//! and "Roller bearings in the compliant model".

use crate::error::{Result, RvdynError, require_non_negative, require_positive};
use std::f64::consts::PI;

/// Palmgren's line-contact coefficient 3.84e-5 [mm N^-0.9 mm^0.8].
const PALMGREN_MM: f64 = 3.84e-5;

/// Load-deflection exponent of a roller (line contact, Palmgren): 10/9.
pub const ROLLER_EXPONENT: f64 = 10.0 / 9.0;

/// A radial roller bearing as a set of rollers with clearance (SI units).
#[derive(Debug, Clone, PartialEq)]
pub struct RollerBearing {
    rollers: usize,
    /// Effective roller length `l` \[m\].
    roller_length: f64,
    /// Radial clearance per side `g` \[m\].
    clearance: f64,
    /// `K_n` in SI: `Q \[N\] = k_si * delta[m]^(10/9)`.
    k_si: f64,
    /// Unit directions of the rollers for cage angle 0.
    dirs: Vec<[f64; 2]>,
}

/// Force on the inner ring, its tangent stiffness and the roller loads at one displacement.
#[derive(Debug, Clone, PartialEq)]
pub struct BearingState {
    /// Force on the inner ring \[N\], `(F_x, F_y)`.
    pub force: [f64; 2],
    /// Tangent stiffness `K = -dF/du` [N/m], row-major `[[Kxx, Kxy], [Kyx, Kyy]]`.
    pub stiffness: [[f64; 2]; 2],
    /// Number of loaded rollers.
    pub loaded: usize,
    /// Largest roller load `Q_max` \[N\].
    pub max_roller_load: f64,
}

/// Result of [`RollerBearing::damped_force`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct DampedBearingForce {
    /// Force on the inner ring \[N\].
    pub force: [f64; 2],
    /// Power dissipated by the roller dampers \[W\] (>= 0).
    pub dissipation: f64,
    /// Elastic energy of the rollers \[J\].
    pub energy: f64,
    /// Largest roller force \[N\].
    pub max_roller_load: f64,
}

impl RollerBearing {
    /// Build a bearing of `rollers` rollers of effective length `roller_length` \[m\] with the
    /// radial clearance per side `clearance` \[m\] (half the diametral clearance; 0 allowed).
    ///
    /// Errors (`Parameter`): zero rollers (or fewer than 3, which cannot hold a radial load in
    /// every direction), a non-positive or non-finite length, a negative or non-finite
    /// clearance (a preloaded bearing is not modelled).
    pub fn new(rollers: usize, roller_length: f64, clearance: f64) -> Result<Self> {
        if rollers < 3 {
            return Err(RvdynError::Parameter(format!(
                "a roller bearing needs at least 3 rollers, got {rollers}"
            )));
        }
        require_positive("roller length", roller_length, "m")?;
        require_non_negative("bearing radial clearance", clearance, "m (no preload)")?;
        let l_mm = roller_length * 1e3;
        // Per roller, both raceways: delta_mm = 2 * 3.84e-5 Q^0.9 / l^0.8
        // -> Q = (delta_mm l^0.8 / (2 * 3.84e-5))^(10/9) = k_mm delta_mm^(10/9).
        let k_mm = (l_mm.powf(0.8) / (2.0 * PALMGREN_MM)).powf(ROLLER_EXPONENT);
        // delta_mm = 1e3 delta_m.
        let k_si = k_mm * 1e3f64.powf(ROLLER_EXPONENT);
        let dirs = (0..rollers)
            .map(|j| {
                let a = 2.0 * PI * j as f64 / rollers as f64;
                [a.cos(), a.sin()]
            })
            .collect();
        Ok(Self {
            rollers,
            roller_length,
            clearance,
            k_si,
            dirs,
        })
    }

    /// Number of rollers `Z`.
    pub fn rollers(&self) -> usize {
        self.rollers
    }

    /// Effective roller length \[m\].
    pub fn roller_length(&self) -> f64 {
        self.roller_length
    }

    /// Radial clearance per side \[m\].
    pub fn clearance(&self) -> f64 {
        self.clearance
    }

    /// Load `Q` \[N\] and slope `dQ/d delta` [N/m] of one roller compressed by `delta` \[m\]
    /// (0 and 0 for `delta <= 0`).
    #[inline]
    pub fn roller_load(&self, delta: f64) -> (f64, f64) {
        if delta.is_nan() || delta <= 0.0 {
            return (0.0, 0.0);
        }
        let p = ninth_root(delta); // delta^(1/9)
        let q = self.k_si * delta * p;
        (q, ROLLER_EXPONENT * self.k_si * p)
    }

    /// Force on the inner ring and tangent stiffness at the displacement `u` \[m\] of the inner
    /// ring relative to the outer ring, with the cage (roller set) turned by `cage_angle` \[rad\].
    ///
    /// A non-finite displacement gives zero force (callers check their state for NaN).
    pub fn state(&self, u: [f64; 2], cage_angle: f64) -> BearingState {
        // A fixed roller set (cage angle 0, the static path) takes the directions as they are:
        // the rotation by (cos 0, sin 0) = (1, 0) would change no bit of them.
        if cage_angle == 0.0 {
            self.state_with(u, |d0| *d0)
        } else {
            let (s, c) = cage_angle.sin_cos();
            self.state_with(u, |d0| [c * d0[0] - s * d0[1], s * d0[0] + c * d0[1]])
        }
    }

    /// [`RollerBearing::state`] with the roller directions `dir(d0)` of the directions `d0` at
    /// cage angle 0.
    #[inline(always)]
    fn state_with(&self, u: [f64; 2], dir: impl Fn(&[f64; 2]) -> [f64; 2]) -> BearingState {
        let mut st = BearingState {
            force: [0.0, 0.0],
            stiffness: [[0.0; 2]; 2],
            loaded: 0,
            max_roller_load: 0.0,
        };
        // Cheap exit: no roller can touch inside the clearance circle.
        let r2 = u[0] * u[0] + u[1] * u[1];
        if r2.is_nan() || r2 <= self.clearance * self.clearance {
            return st;
        }
        for d0 in &self.dirs {
            let n = dir(d0);
            let delta = u[0] * n[0] + u[1] * n[1] - self.clearance;
            let (q, k) = self.roller_load(delta);
            if q > 0.0 {
                st.loaded += 1;
                st.max_roller_load = st.max_roller_load.max(q);
                st.force[0] -= q * n[0];
                st.force[1] -= q * n[1];
                st.stiffness[0][0] += k * n[0] * n[0];
                st.stiffness[0][1] += k * n[0] * n[1];
                st.stiffness[1][1] += k * n[1] * n[1];
            }
        }
        st.stiffness[1][0] = st.stiffness[0][1];
        st
    }

    /// Force on the inner ring \[N\] with stiffness-proportional damping per roller, at the
    /// displacement `u` \[m\] and its rate `u_rate` [m/s]: roller `j` pushes with
    /// `max(0, Q_j + beta k_j n_j . u_rate)` (`k_j = dQ_j/d delta_j`, `beta` \[s\] >= 0), so no
    /// roller pulls. Returns the force, the power dissipated by the dampers \[W\] (>= 0), the
    /// elastic energy \[J\] and the largest roller force \[N\]. Roller set fixed (cage angle 0).
    pub fn damped_force(&self, u: [f64; 2], u_rate: [f64; 2], beta: f64) -> DampedBearingForce {
        let mut out = DampedBearingForce::default();
        let r2 = u[0] * u[0] + u[1] * u[1];
        if r2.is_nan() || r2 <= self.clearance * self.clearance {
            return out;
        }
        for n in &self.dirs {
            let delta = u[0] * n[0] + u[1] * n[1] - self.clearance;
            if delta <= 0.0 {
                continue;
            }
            let (q, k) = self.roller_load(delta);
            let rate = u_rate[0] * n[0] + u_rate[1] * n[1];
            let f = (q + beta * k * rate).max(0.0);
            out.force[0] -= f * n[0];
            out.force[1] -= f * n[1];
            out.dissipation += (f - q) * rate;
            out.energy += q * delta / (1.0 + ROLLER_EXPONENT);
            out.max_roller_load = out.max_roller_load.max(f);
        }
        out
    }

    /// Elastic energy \[J\] stored in the rollers at the displacement `u` \[m\] and cage angle
    /// `cage_angle` \[rad\]: `sum_j K_n delta_j^(19/9) / (19/9)` over the compressed rollers
    /// (its gradient is `-force`).
    pub fn elastic_energy(&self, u: [f64; 2], cage_angle: f64) -> f64 {
        let r2 = u[0] * u[0] + u[1] * u[1];
        if r2.is_nan() || r2 <= self.clearance * self.clearance {
            return 0.0;
        }
        let (s, c) = cage_angle.sin_cos();
        self.dirs
            .iter()
            .map(|d0| {
                let n = [c * d0[0] - s * d0[1], s * d0[0] + c * d0[1]];
                let delta = u[0] * n[0] + u[1] * n[1] - self.clearance;
                if delta > 0.0 {
                    self.roller_load(delta).0 * delta / (1.0 + ROLLER_EXPONENT)
                } else {
                    0.0
                }
            })
            .sum()
    }

    /// Radial load \[N\] along `x` at the radial displacement `delta_r` \[m\] along `x`, from
    /// Harris's many-roller integral for zero clearance: `Z K_n delta_r^(10/9) J_r(0.5)`.
    /// Valid for `clearance = 0`; independent of the cage angle only in the limit of many
    /// rollers. Errors (`Parameter`) for a negative or non-finite displacement.
    pub fn harris_radial_load(&self, delta_r: f64) -> Result<f64> {
        require_non_negative("radial displacement", delta_r, "m")?;
        Ok(self.rollers as f64 * self.k_si * delta_r.powf(ROLLER_EXPONENT) * RADIAL_INTEGRAL_HALF)
    }

    /// Radial stiffness [N/m] of Harris's closed form at the displacement `delta_r` \[m\]
    /// (zero clearance): `(10/9) Z K_n delta_r^(1/9) J_r(0.5)`.
    pub fn harris_radial_stiffness(&self, delta_r: f64) -> Result<f64> {
        require_non_negative("radial displacement", delta_r, "m")?;
        Ok(ROLLER_EXPONENT
            * self.rollers as f64
            * self.k_si
            * delta_r.powf(1.0 / 9.0)
            * RADIAL_INTEGRAL_HALF)
    }
}

/// `x^(1/9)` for `x > 0` [any unit], to within 2 ulps of `x.powf(1.0 / 9.0)` (tested), at
/// about a third of its cost: the exponent-halving bit estimate (relative error below 7 %),
/// three Halley steps for `y^9 = x` (cubic convergence: `y <- y (8 y^9 + 10 x) / (10 y^9 + 8 x)`,
/// relative error about `6.7 e^3` per step, so 7e-2 -> 2e-3 -> 6e-8 -> round-off), and a
/// final Newton correction `y - y (y^9 - x) / (9 y^9)` written as a small correction, which
/// leaves about one rounding of `y` (Halley's and Newton's methods: A. S. Householder, *The
/// Numerical Treatment of a Single Nonlinear Equation*, McGraw-Hill 1970). Input outside
/// `[1e-200, 1e200]` (where `y^9` could leave the normal range) and NaN take `powf`.
#[inline]
pub(crate) fn ninth_root(x: f64) -> f64 {
    if !(1e-200..=1e200).contains(&x) {
        return x.powf(1.0 / 9.0);
    }
    // ln2-linear estimate of the bit pattern: bits(y) ~ bits(x)/9 + (8/9) bits(1.0).
    let mut y = f64::from_bits(x.to_bits() / 9 + (1023u64 << 52) / 9 * 8);
    for _ in 0..3 {
        let y2 = y * y;
        let y4 = y2 * y2;
        let t = y4 * y4 * y;
        y *= (8.0 * t + 10.0 * x) / (10.0 * t + 8.0 * x);
    }
    let y2 = y * y;
    let y4 = y2 * y2;
    let t = y4 * y4 * y;
    y - y * (t - x) / (9.0 * t)
}

/// Sjovall's radial integral `J_r(0.5)` for line contact (`n = 10/9`):
/// `(1/2pi) integral_{-pi/2}^{pi/2} cos^(19/9) psi d psi
///  = Gamma(14/9) / (2 sqrt(pi) Gamma(37/18)) = 0.244 799` (checked by quadrature in the
/// tests). Harris tabulates 0.2453 for line contact, computed with the rounded exponent
/// `n = 1.1` (the integral with `n = 1.1` is 0.245 30); the two differ by 0.2 %.
pub const RADIAL_INTEGRAL_HALF: f64 = 0.244_798_558_710;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::close;

    #[test]
    fn radial_integral_by_quadrature() {
        // Simpson on (1/2pi) int_{-pi/2}^{pi/2} cos^(19/9).
        let n = 200_000;
        let h = PI / n as f64;
        let f = |x: f64| x.cos().max(0.0).powf(19.0 / 9.0);
        let mut s = f(-PI / 2.0) + f(PI / 2.0);
        for i in 1..n {
            s += if i % 2 == 1 { 4.0 } else { 2.0 } * f(-PI / 2.0 + i as f64 * h);
        }
        let j = s * h / 3.0 / (2.0 * PI);
        assert!(close(j, RADIAL_INTEGRAL_HALF, 1e-8), "{j}");
        // Harris's table value (exponent 1.1) is 0.2 % higher.
        assert!(close(j, 0.2453, 3e-3));
    }

    /// The ninth root against the library `powf` (an independent implementation) and against
    /// its definition `y^9 = x`, over the range of roller deflections and beyond: within 2 ulps
    /// of `powf` (whose own exponent `1/9` is rounded: about 1 ulp of error here), and `y^9`
    /// within 12 ulps of `x` (9 times the root's error plus the roundings of the power).
    #[test]
    fn ninth_root_matches_powf_and_its_definition() {
        let mut s: u64 = 12345;
        let mut worst_ulps = 0i64;
        let mut worst_pow: f64 = 0.0;
        for i in 0..200_000 {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let u = (s >> 11) as f64 / (1u64 << 53) as f64;
            // Deflections 1e-12..1e-2 m, and every tenth sample over 1e-200..1e200.
            let x = if i % 10 == 0 {
                10f64.powf(-200.0 + 400.0 * u)
            } else {
                10f64.powf(-12.0 + 10.0 * u)
            };
            let y = ninth_root(x);
            if i % 10 != 0 {
                let r = x.powf(1.0 / 9.0);
                worst_ulps = worst_ulps.max((y.to_bits() as i64 - r.to_bits() as i64).abs());
            }
            let y2 = y * y;
            let y4 = y2 * y2;
            worst_pow = worst_pow.max(((y4 * y4 * y - x) / x).abs());
        }
        assert!(worst_ulps <= 2, "{worst_ulps} ulps from powf");
        assert!(worst_pow <= 12.0 * f64::EPSILON, "y^9 off by {worst_pow:e}");
        assert_eq!(ninth_root(1.0), 1.0);
        assert!((ninth_root(512.0f64.powi(3)) - 8.0).abs() <= 2.0 * 8.0 * f64::EPSILON);
        assert!(ninth_root(f64::NAN).is_nan());
        assert_eq!(ninth_root(f64::INFINITY), f64::INFINITY);
        assert_eq!(ninth_root(0.0), 0.0);
        for out in [1e-310, 1e-250, 1e250, f64::MAX] {
            assert_eq!(ninth_root(out), out.powf(1.0 / 9.0));
        }
    }

    #[test]
    fn roller_law_is_palmgren() {
        // One roller, 20 mm: Q = 5 kN -> per contact 3.84e-5 * 5000^0.9 / 20^0.8 mm, twice.
        let b = RollerBearing::new(12, 0.020, 0.0).unwrap();
        let d_mm = 2.0 * 3.84e-5 * 5000f64.powf(0.9) / 20f64.powf(0.8);
        let (q, k) = b.roller_load(d_mm * 1e-3);
        assert!(close(q, 5000.0, 1e-12), "{q}");
        let h = 1e-12;
        let fd = (b.roller_load(d_mm * 1e-3 + h).0 - b.roller_load(d_mm * 1e-3 - h).0) / (2.0 * h);
        assert!(close(k, fd, 1e-5));
        assert_eq!(b.roller_load(0.0), (0.0, 0.0));
        assert_eq!(b.roller_load(-1e-6), (0.0, 0.0));
        assert_eq!(b.roller_load(f64::NAN), (0.0, 0.0));
    }

    #[test]
    fn many_rollers_match_harris_closed_form() {
        // 400 rollers, zero clearance: the sum approaches the integral.
        let b = RollerBearing::new(400, 0.020, 0.0).unwrap();
        for d in [1e-6, 5e-6, 2e-5] {
            let st = b.state([d, 0.0], 0.0);
            let fr = -st.force[0];
            assert!(close(fr, b.harris_radial_load(d).unwrap(), 1e-4), "{fr}");
            assert!(st.force[1].abs() < 1e-9 * fr);
            let kr = st.stiffness[0][0];
            assert!(
                close(kr, b.harris_radial_stiffness(d).unwrap(), 1e-4),
                "{kr}"
            );
            // Secant/tangent relation of a 10/9 power law.
            assert!(close(kr, ROLLER_EXPONENT * fr / d, 1e-4));
        }
    }

    #[test]
    fn few_rollers_ripple_with_the_cage_and_stiffness_is_the_jacobian() {
        let b = RollerBearing::new(14, 0.018, 5e-6).unwrap();
        let u = [1.5e-5, -0.7e-5];
        for cage in [0.0, 0.1, 0.3] {
            let st = b.state(u, cage);
            // Finite-difference Jacobian.
            let h = 1e-11;
            for (i, e) in [[h, 0.0], [0.0, h]].iter().enumerate() {
                let p = b.state([u[0] + e[0], u[1] + e[1]], cage).force;
                let m = b.state([u[0] - e[0], u[1] - e[1]], cage).force;
                for r in 0..2 {
                    let fd = -(p[r] - m[r]) / (2.0 * h);
                    assert!(
                        (st.stiffness[r][i] - fd).abs() < 1e-5 * st.stiffness[0][0],
                        "{cage} {r}{i}: {} vs {fd}",
                        st.stiffness[r][i]
                    );
                }
            }
            // The force opposes the displacement (restoring).
            assert!(st.force[0] * u[0] + st.force[1] * u[1] < 0.0);
            assert!(st.loaded >= 1 && st.loaded < 14);
        }
        // The force is minus the gradient of the elastic energy.
        let h = 1e-12;
        for (i, e) in [[h, 0.0], [0.0, h]].iter().enumerate() {
            let up = b.elastic_energy([u[0] + e[0], u[1] + e[1]], 0.1);
            let um = b.elastic_energy([u[0] - e[0], u[1] - e[1]], 0.1);
            let f = b.state(u, 0.1).force[i];
            assert!(((um - up) / (2.0 * h) - f).abs() < 1e-5 * f.abs(), "{i}");
        }
        // Radial clearance: nothing inside it.
        let st = b.state([4.9e-6, 0.0], 0.0);
        assert_eq!(st.force, [0.0, 0.0]);
        assert_eq!(st.loaded, 0);
    }

    #[test]
    fn damped_force_never_pulls_and_dissipates() {
        let b = RollerBearing::new(14, 0.018, 2e-6).unwrap();
        let u = [1.5e-5, -0.7e-5];
        let st = b.state(u, 0.0);
        let undamped = b.damped_force(u, [0.0, 0.0], 1e-4);
        assert!((undamped.force[0] - st.force[0]).abs() < 1e-9 * st.force[0].abs());
        assert_eq!(undamped.dissipation, 0.0);
        assert!((undamped.energy - b.elastic_energy(u, 0.0)).abs() < 1e-12);
        // Closing: more force, positive dissipation; separating fast: rollers let go.
        let closing = b.damped_force(u, [1e-2, -0.5e-2], 1e-4);
        assert!(closing.force[0] < st.force[0] && closing.dissipation > 0.0);
        let opening = b.damped_force(u, [-1e3, 0.5e3], 1e-4);
        assert_eq!(opening.force, [0.0, 0.0]);
        assert!(opening.dissipation >= 0.0);
        assert_eq!(
            b.damped_force([1e-6, 0.0], [1.0, 0.0], 1e-4).force,
            [0.0, 0.0]
        );
    }

    #[test]
    fn invalid_parameters() {
        assert!(RollerBearing::new(0, 0.02, 0.0).is_err());
        assert!(RollerBearing::new(2, 0.02, 0.0).is_err());
        assert!(RollerBearing::new(12, 0.0, 0.0).is_err());
        let e = RollerBearing::new(12, 0.02, -1e-6).unwrap_err();
        assert!(e.to_string().contains("clearance"), "{e}");
        assert!(RollerBearing::new(12, 0.02, f64::NAN).is_err());
        let b = RollerBearing::new(12, 0.02, 0.0).unwrap();
        assert!(b.harris_radial_load(-1.0).is_err());
        let st = b.state([f64::NAN, 0.0], 0.0);
        assert_eq!(st.force, [0.0, 0.0]);
    }
}
