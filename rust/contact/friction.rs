//! Regularised Coulomb friction (optionally with a Stribeck drop) for smooth integrators.
//!
//! Tangential force on a body whose contact point slides at `v` [m/s] relative to the other
//! body, under the normal force `N >= 0` \[N\]:
//!
//! `F_t = -mu(|v|) N tanh(v / v_reg)`
//!
//! `v_reg > 0` is the regularisation speed: below it the law is a steep viscous damper of
//! coefficient `mu N / v_reg` (the "stick" of Coulomb friction is replaced by creep at speeds
//! of order `v_reg`); above a few `v_reg` it is Coulomb's `mu N sign(v)` to within
//! `1 - tanh(3) = 0.5 %`. The tanh regularisation is the common smooth choice of multibody
//! codes (review: E. Pennestri, V. Rossi, P. Salvini, P. P. Valentini, *Review and comparison
//! of dry friction force models*, Nonlinear Dyn. 83 (2016) 1785-1801).
//!
//! Stribeck (optional): `mu(v) = mu_c + (mu_s - mu_c) exp(-(v / v_s)^2)` with the static
//! coefficient `mu_s >= mu_c` and the Stribeck speed `v_s` (B. Armstrong-Helouvry, P. Dupont,
//! C. Canudas de Wit, *A survey of models, analysis tools and compensation methods for the
//! control of machines with friction*, Automatica 30 (1994) 1083-1138, the "Gaussian"
//! Stribeck curve). Without it `mu = mu_c`.
//!
//! Friction power dissipated: `P = -F_t v = mu N v tanh(v / v_reg) >= 0`.
//!
//! Theory: docs/model.md, sections "Regularised Coulomb friction"
//! and "Friction in the dynamic models".

use crate::error::{Result, RvdynError, require_positive};

/// Parameters of a regularised Coulomb friction law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoulombFriction {
    /// Kinetic (Coulomb) coefficient `mu_c` [-], in [0, 1].
    pub coefficient: f64,
    /// Regularisation speed `v_reg` [m/s], > 0.
    pub regularisation_speed: f64,
    /// Optional Stribeck: static coefficient `mu_s` [-] (>= `mu_c`, <= 1) and Stribeck speed
    /// `v_s` [m/s] (> 0).
    pub stribeck: Option<(f64, f64)>,
}

impl CoulombFriction {
    /// A plain regularised Coulomb law. Errors as [`CoulombFriction::validate`].
    pub fn new(coefficient: f64, regularisation_speed: f64) -> Result<Self> {
        let f = Self {
            coefficient,
            regularisation_speed,
            stribeck: None,
        };
        f.validate()?;
        Ok(f)
    }

    /// Check the fields. Errors (`Parameter`): a coefficient outside [0, 1], a non-positive or
    /// non-finite regularisation or Stribeck speed, a static coefficient below the kinetic one
    /// or above 1.
    pub fn validate(&self) -> Result<()> {
        let mu = self.coefficient;
        if !(mu.is_finite() && (0.0..=1.0).contains(&mu)) {
            return Err(RvdynError::Parameter(format!(
                "friction coefficient must be in [0, 1], got {mu}; lubricated steel is about \
                 0.03-0.1"
            )));
        }
        require_positive(
            "friction regularisation speed",
            self.regularisation_speed,
            "m/s",
        )?;
        if let Some((mu_s, v_s)) = self.stribeck {
            if !(mu_s.is_finite() && mu_s >= mu && mu_s <= 1.0) {
                return Err(RvdynError::Parameter(format!(
                    "static friction coefficient must be in [mu_c = {mu}, 1], got {mu_s}"
                )));
            }
            require_positive("Stribeck speed", v_s, "m/s")?;
        }
        Ok(())
    }

    /// Friction coefficient `mu(|v|)` [-] at the sliding speed `v` [m/s].
    #[inline]
    pub fn mu(&self, v: f64) -> f64 {
        match self.stribeck {
            None => self.coefficient,
            Some((mu_s, v_s)) => {
                let r = v / v_s;
                self.coefficient + (mu_s - self.coefficient) * (-r * r).exp()
            }
        }
    }

    /// Tangential force \[N\] on the body whose contact point slides at `v` [m/s], under the
    /// normal force `normal` \[N\] (negative normal forces count as 0), and its derivative
    /// `dF_t/dv` [N s/m] (<= 0 without Stribeck).
    #[inline]
    pub fn force_and_slope(&self, v: f64, normal: f64) -> (f64, f64) {
        let n = normal.max(0.0);
        if n == 0.0 || !v.is_finite() {
            return (0.0, 0.0);
        }
        let vr = self.regularisation_speed;
        let t = (v / vr).tanh();
        let mu = self.mu(v);
        let dmu = match self.stribeck {
            None => 0.0,
            Some((mu_s, v_s)) => {
                let r = v / v_s;
                -2.0 * (mu_s - self.coefficient) * r / v_s * (-r * r).exp()
            }
        };
        let f = -mu * n * t;
        let slope = -n * (dmu * t + mu * (1.0 - t * t) / vr);
        (f, slope)
    }

    /// Tangential force \[N\] only (see [`CoulombFriction::force_and_slope`]).
    #[inline]
    pub fn force(&self, v: f64, normal: f64) -> f64 {
        self.force_and_slope(v, normal).0
    }

    /// Dissipated power `-F_t v` \[W\] (>= 0) at the sliding speed `v` [m/s] and normal force
    /// `normal` \[N\].
    #[inline]
    pub fn power(&self, v: f64, normal: f64) -> f64 {
        -self.force(v, normal) * v
    }
}

/// Geometry of the path of contact of an external spur pair for tooth friction (SI).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToothPath {
    /// Distance between the base-circle tangency points `T1 T2` \[m\], `(r_b1 + r_b2) tan a`.
    pub t1t2: f64,
    /// Distance from `T1` to the start of contact `A` \[m\], `T1T2 - sqrt(ra2^2 - rb2^2)`.
    pub t1a: f64,
    /// Base pitch \[m\].
    pub base_pitch: f64,
    /// Fractional part of the transverse contact ratio (double-contact share of a pitch).
    pub double_fraction: f64,
}

impl ToothPath {
    /// Path of a standard spur pair (no shift, standard centre distance) of base radii
    /// `rb1`, `rb2` \[m\], tip radius of gear 2 `ra2` \[m\], pressure angle \[rad\], base pitch \[m\]
    /// and contact ratio [-].
    pub fn new(
        rb1: f64,
        rb2: f64,
        ra2: f64,
        pressure_angle: f64,
        base_pitch: f64,
        eps: f64,
    ) -> Self {
        let t1t2 = (rb1 + rb2) * pressure_angle.tan();
        Self {
            t1t2,
            t1a: t1t2 - (ra2 * ra2 - rb2 * rb2).sqrt(),
            base_pitch,
            double_fraction: eps - eps.floor(),
        }
    }

    /// Friction torques [N m] on gear 1 and gear 2 (about their own axes, in the carrier
    /// frame) and the friction power \[W\] (>= 0) for the total normal force `normal` \[N\] of the
    /// mesh at the mesh position `s` \[m\] (position of the newest pair along the path from `A`,
    /// modulo the base pitch), gear speeds `w1`, `w2` [rad/s] relative to the carrier, and the
    /// friction law `law`.
    ///
    /// Pairs at `xi = s mod p_b` and, in the double zone (`xi < f p_b`), at `xi + p_b`, sharing
    /// the normal force equally. At a pair `rho1 = T1A + xi`, `rho2 = T1T2 - rho1` (distances of
    /// the contact from the tangency points); the sliding speed is `v = w1 rho1 + w2 rho2`
    /// (0 at the pitch point), the friction force on gear 1 `F = -mu N tanh(v / v_reg)`
    /// perpendicular to the line of action, and the torques `F rho1` on gear 1 and `F rho2` on
    /// gear 2 (power `F v <= 0`). The force on the gear centres (a couple of the line-of-action
    /// model) is not applied. Source of the kinematics: e.g. Niemann & Winter (1983) vol. II.
    pub fn torques(
        &self,
        law: &CoulombFriction,
        normal: f64,
        s: f64,
        w1: f64,
        w2: f64,
    ) -> (f64, f64, f64) {
        if normal <= 0.0 || !s.is_finite() {
            return (0.0, 0.0, 0.0);
        }
        let xi = s.rem_euclid(self.base_pitch);
        let double = xi < self.double_fraction * self.base_pitch;
        let share = if double { 0.5 * normal } else { normal };
        let (mut t1, mut t2, mut p) = (0.0, 0.0, 0.0);
        let mut pair = |x: f64| {
            let rho1 = self.t1a + x;
            let rho2 = self.t1t2 - rho1;
            let v = w1 * rho1 + w2 * rho2;
            let f = law.force(v, share);
            t1 += f * rho1;
            t2 += f * rho2;
            p -= f * v;
        };
        pair(xi);
        if double {
            pair(xi + self.base_pitch);
        }
        (t1, t2, p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coulomb_limit_and_creep() {
        let f = CoulombFriction::new(0.08, 1e-3).unwrap();
        // Far above v_reg: Coulomb to tanh(100) = 1 - 3e-87.
        assert_eq!(f.force(0.1, 1e3), -80.0);
        assert_eq!(f.force(-0.1, 1e3), 80.0);
        // At 3 v_reg: 99.5 % of Coulomb.
        let r = f.force(3e-3, 1e3) / -80.0;
        assert!((r - 3f64.tanh()).abs() < 1e-15 && r > 0.995);
        // Creep: viscous slope mu N / v_reg at v = 0.
        let (f0, k0) = f.force_and_slope(0.0, 1e3);
        assert_eq!(f0, 0.0);
        assert!((k0 + 0.08 * 1e3 / 1e-3).abs() < 1e-9);
        // Never negative power, odd in v, zero without normal force.
        for v in [-1.0, -1e-4, 0.0, 2e-4, 0.5] {
            assert!(f.power(v, 500.0) >= 0.0);
            assert_eq!(f.force(v, 500.0), -f.force(-v, 500.0));
            assert_eq!(f.force(v, 0.0), 0.0);
            assert_eq!(f.force(v, -10.0), 0.0);
        }
        assert_eq!(f.force(f64::NAN, 10.0), 0.0);
    }

    #[test]
    fn stribeck_and_slope_by_finite_differences() {
        let f = CoulombFriction {
            coefficient: 0.05,
            regularisation_speed: 1e-4,
            stribeck: Some((0.12, 0.01)),
        };
        f.validate().unwrap();
        assert!((f.mu(0.0) - 0.12).abs() < 1e-15);
        assert!((f.mu(0.01) - (0.05 + 0.07 * (-1.0f64).exp())).abs() < 1e-15);
        assert!((f.mu(1.0) - 0.05).abs() < 1e-12);
        for v in [-0.02, -3e-4, 5e-5, 0.004, 0.05] {
            let h = 1e-9;
            let fd = (f.force(v + h, 200.0) - f.force(v - h, 200.0)) / (2.0 * h);
            let s = f.force_and_slope(v, 200.0).1;
            assert!((s - fd).abs() < 1e-5 * s.abs().max(1.0), "{v}: {s} vs {fd}");
        }
    }

    #[test]
    fn tooth_friction_vanishes_at_the_pitch_point_and_dissipates() {
        // Paper stage: rb 25.372 / 59.201 mm, ra2 66 mm, 20 deg, pb 8.856 mm, eps 1.626.
        let a = 20f64.to_radians();
        let (rb1, rb2) = (0.027 * a.cos(), 0.063 * a.cos());
        let path = ToothPath::new(
            rb1,
            rb2,
            0.066,
            a,
            std::f64::consts::PI * 3e-3 * a.cos(),
            1.626,
        );
        let law = CoulombFriction::new(0.05, 1e-3).unwrap();
        // Rolling speeds: w1 rb1 = -w2 rb2.
        let w1 = 140.0;
        let w2 = -w1 * rb1 / rb2;
        // Single pair at the pitch point: xi = T1P - T1A = rb1 tan a - t1a.
        let xi_p = rb1 * a.tan() - path.t1a;
        assert!(xi_p > path.double_fraction * path.base_pitch && xi_p < path.base_pitch);
        let (t1, t2, p) = path.torques(&law, 1e4, xi_p, w1, w2);
        assert!(
            t1.abs() < 1e-6 && t2.abs() < 1e-6 && p.abs() < 1e-6,
            "{t1} {t2} {p}"
        );
        // Elsewhere: power = -(t1 w1 + t2 w2) >= 0 and equals mu N |v| (beyond v_reg).
        for xi in [0.5e-3, 3e-3, 8e-3] {
            let (t1, t2, p) = path.torques(&law, 1e4, xi, w1, w2);
            assert!(p > 0.0);
            assert!((p + t1 * w1 + t2 * w2).abs() < 1e-9 * p);
        }
        assert_eq!(path.torques(&law, 0.0, 1e-3, w1, w2), (0.0, 0.0, 0.0));
    }

    #[test]
    fn invalid_parameters() {
        assert!(CoulombFriction::new(-0.01, 1e-3).is_err());
        let e = CoulombFriction::new(1.2, 1e-3).unwrap_err();
        assert!(e.to_string().contains("[0, 1]"), "{e}");
        assert!(CoulombFriction::new(f64::NAN, 1e-3).is_err());
        assert!(CoulombFriction::new(0.1, 0.0).is_err());
        assert!(CoulombFriction::new(0.0, 1e-3).is_ok());
        assert!(CoulombFriction::new(1.0, 1e-3).is_ok());
        let mut f = CoulombFriction::new(0.1, 1e-3).unwrap();
        f.stribeck = Some((0.05, 0.01));
        assert!(f.validate().is_err());
        f.stribeck = Some((0.15, 0.0));
        assert!(f.validate().is_err());
    }
}
