//! The ADAMS IMPACT contact law: a nonlinear spring plus a damper that ramps in with depth.
//!
//! For penetration `x > 0`: `F = k x^e + STEP(x, 0, 0, d, cmax) * xdot`, and `F >= 0`.
//! The damping coefficient is 0 at first touch and `cmax` from the depth `d` on, so the force
//! is continuous at contact (a plain `c * xdot` would jump at impact). Sources: MSC ADAMS
//! solver manual, IMPACT function; see docs/model.md#contact-laws.

use crate::error::{Result, RvdynError, num, require_positive};
use serde::{Deserialize, Serialize};

/// ADAMS STEP: cubic ramp from `h0` at `x0` to `h1` at `x1`, flat outside.
///
/// Returns `h0 + (h1 - h0) s^2 (3 - 2 s)` with `s = (x - x0) / (x1 - x0)` clamped to `[0, 1]`
/// (same unit as `h0`, `h1`). The ramp and its slope are continuous at both ends. A degenerate
/// interval (`x1 == x0`) is a jump: `h0` below `x0`, `h1` from `x0` on.
#[inline]
pub fn step_cubic(x: f64, x0: f64, h0: f64, x1: f64, h1: f64) -> f64 {
    let width = x1 - x0;
    if width == 0.0 {
        return if x < x0 { h0 } else { h1 };
    }
    let s = ((x - x0) / width).clamp(0.0, 1.0);
    h0 + (h1 - h0) * s * s * (3.0 - 2.0 * s)
}

/// Slope d(STEP)/dx of [`step_cubic`] (unit of `h` per unit of `x`); 0 outside the ramp.
#[inline]
fn step_cubic_slope(x: f64, x0: f64, h0: f64, x1: f64, h1: f64) -> f64 {
    let width = x1 - x0;
    if width == 0.0 {
        return 0.0;
    }
    let s = (x - x0) / width;
    if s <= 0.0 || s >= 1.0 {
        return 0.0;
    }
    (h1 - h0) * 6.0 * s * (1.0 - s) / width
}

/// Parameters of one IMPACT contact law (SI units).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImpactLaw {
    /// Stiffness `k` [N/m^exponent].
    pub stiffness: f64,
    /// Force exponent `e` [-], at least 1 (1.5 for Hertz-like metal contact).
    pub exponent: f64,
    /// Damping coefficient `cmax` reached at full damping depth [N s/m].
    pub max_damping: f64,
    /// Penetration `d` at which the damping reaches `cmax` \[m\].
    pub damping_depth: f64,
}

impl ImpactLaw {
    /// Build a validated law from stiffness [N/m^exponent], exponent [-], maximum damping
    /// [N s/m] and damping depth \[m\].
    ///
    /// Errors (`RvdynError::Parameter`) if any value is not finite, `stiffness <= 0`,
    /// `exponent < 1`, `max_damping < 0` or `damping_depth <= 0`.
    pub fn new(
        stiffness: f64,
        exponent: f64,
        max_damping: f64,
        damping_depth: f64,
    ) -> Result<Self> {
        let law = Self {
            stiffness,
            exponent,
            max_damping,
            damping_depth,
        };
        law.validate()?;
        Ok(law)
    }

    /// Check the fields (they are public, so a deserialized or edited law may be invalid).
    ///
    /// Returns `Ok(())` or the first rule broken (`RvdynError::Parameter`).
    pub fn validate(&self) -> Result<()> {
        require_positive("impact stiffness", self.stiffness, "N/m^exponent")?;
        if !(self.exponent.is_finite() && self.exponent >= 1.0) {
            // dF/dx = k e x^(e-1) is infinite at x = 0 when e < 1: no integrator can step
            // through first contact.
            return Err(RvdynError::Parameter(format!(
                "impact exponent must be a finite number >= 1, got {}: an exponent below 1 gives \
                 an infinite contact stiffness at zero penetration; use 1.5 for metal contacts \
                 (Hertz) or 1 for a linear spring",
                num(self.exponent)
            )));
        }
        if !(self.max_damping.is_finite() && self.max_damping >= 0.0) {
            return Err(RvdynError::Parameter(format!(
                "impact max_damping must be a finite number >= 0 N s/m, got {}; use 0 for an \
                 undamped contact",
                num(self.max_damping)
            )));
        }
        require_positive("impact damping_depth", self.damping_depth, "m")?;
        Ok(())
    }

    /// The paper's pin-cycloid law (section 3.1): k = 3.988e5 N/mm^1.5 (printed as "N/mm^2",
    /// docs/model.md#erratum-4) = 3.988e5 * 1000^1.5 N/m^1.5, e = 1.5,
    /// cmax = 100 N s/mm = 1e5 N s/m, d = 0.01 mm = 1e-5 m.
    pub fn paper() -> Self {
        Self {
            stiffness: 3.988e5 * 1000f64.powf(1.5),
            exponent: 1.5,
            max_damping: 1.0e5,
            damping_depth: 1.0e-5,
        }
    }

    /// `x^e`, without `powf` for the common exponents 1, 1.5 and 10/9 (this runs once per
    /// contact per step).
    #[inline]
    fn spring_power(&self, x: f64) -> f64 {
        if self.exponent == 1.5 {
            x * x.sqrt()
        } else if self.exponent == 1.0 {
            x
        } else if self.exponent == 10.0 / 9.0 && x > 0.0 {
            // Palmgren's line contact (and its roller law): x * x^(1/9) by Halley steps,
            // within a few ulps of powf.
            x * crate::bearing::roller::ninth_root(x)
        } else {
            x.powf(self.exponent)
        }
    }

    /// Contact force \[N\] for a penetration \[m\] and penetration rate [m/s] (positive = closing).
    ///
    /// Returns 0 for `penetration <= 0`, otherwise `k x^e + STEP(x, 0, 0, d, cmax) xdot`
    /// clamped at 0: a contact can push, never pull, even when it separates fast.
    #[inline]
    pub fn force(&self, penetration: f64, penetration_rate: f64) -> f64 {
        if penetration <= 0.0 {
            return 0.0;
        }
        let damping = step_cubic(penetration, 0.0, 0.0, self.damping_depth, self.max_damping);
        let f = self.stiffness * self.spring_power(penetration) + damping * penetration_rate;
        f.max(0.0)
    }

    /// [`ImpactLaw::force`] for values given by a user: the same force, or
    /// `RvdynError::Parameter` if it is not finite (a penetration or rate so large that `k x^e`
    /// or the damping term overflows), naming both inputs.
    pub fn checked_force(&self, penetration: f64, penetration_rate: f64) -> Result<f64> {
        let f = self.force(penetration, penetration_rate);
        if f.is_finite() {
            Ok(f)
        } else {
            Err(RvdynError::Parameter(format!(
                "the IMPACT force overflows for penetration {} m and penetration rate {} m/s \
                 (k = {} N/m^{}): give penetrations and rates of physical size",
                num(penetration),
                num(penetration_rate),
                num(self.stiffness),
                num(self.exponent)
            )))
        }
    }

    /// Elastic part of the force, `k x^e` \[N\] (0 without penetration).
    #[inline]
    pub fn elastic_force(&self, penetration: f64) -> f64 {
        if penetration <= 0.0 {
            0.0
        } else {
            self.stiffness * self.spring_power(penetration)
        }
    }

    /// Elastic energy stored at a penetration, `k x^(e+1) / (e+1)` \[J\].
    #[inline]
    pub fn elastic_energy(&self, penetration: f64) -> f64 {
        if penetration <= 0.0 {
            0.0
        } else {
            self.stiffness * self.spring_power(penetration) * penetration / (self.exponent + 1.0)
        }
    }

    /// Force \[N\] and its partial derivatives dF/dx [N/m] and dF/dxdot [N s/m], for implicit
    /// integrators.
    ///
    /// Returns `(f, df_dx, df_dxdot)`; all three are 0 where the force is 0 (no contact, or
    /// the clamp at 0 is active).
    #[inline]
    pub fn force_and_derivatives(
        &self,
        penetration: f64,
        penetration_rate: f64,
    ) -> (f64, f64, f64) {
        let x = penetration;
        if x <= 0.0 {
            return (0.0, 0.0, 0.0);
        }
        let (c, dc) = (
            step_cubic(x, 0.0, 0.0, self.damping_depth, self.max_damping),
            step_cubic_slope(x, 0.0, 0.0, self.damping_depth, self.max_damping),
        );
        let xe = self.spring_power(x);
        let f = self.stiffness * xe + c * penetration_rate;
        if f <= 0.0 {
            return (0.0, 0.0, 0.0);
        }
        // d(x^e)/dx = e x^e / x, valid for x > 0.
        let dspring = self.stiffness * self.exponent * xe / x;
        (f, dspring + dc * penetration_rate, c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::close;

    #[test]
    fn elastic_energy_is_the_integral_of_the_elastic_force() {
        let law = ImpactLaw::paper();
        let x = 3e-5;
        let n = 10_000;
        let h = x / n as f64;
        let integral: f64 = (0..n)
            .map(|i| law.elastic_force((i as f64 + 0.5) * h) * h)
            .sum();
        assert!((integral - law.elastic_energy(x)).abs() < 1e-7 * law.elastic_energy(x));
        assert_eq!(law.elastic_energy(-1.0), 0.0);
        assert_eq!(law.elastic_force(0.0), 0.0);
    }

    #[test]
    fn step_ends_midpoint_and_clamp() {
        assert_eq!(step_cubic(-1.0, 0.0, 2.0, 1.0, 5.0), 2.0);
        assert_eq!(step_cubic(0.0, 0.0, 2.0, 1.0, 5.0), 2.0);
        assert_eq!(step_cubic(1.0, 0.0, 2.0, 1.0, 5.0), 5.0);
        assert_eq!(step_cubic(7.0, 0.0, 2.0, 1.0, 5.0), 5.0);
        // s = 0.5: 2 + 3 * 0.25 * 2 = 3.5 (the midpoint of the ramp).
        assert!(close(step_cubic(0.5, 0.0, 2.0, 1.0, 5.0), 3.5, 1e-15));
        // s = 0.25: 0.0625 * 2.5 = 0.15625 of the rise.
        assert!(close(step_cubic(0.25, 0.0, 0.0, 1.0, 1.0), 0.15625, 1e-15));
        assert_eq!(step_cubic(0.0, 1.0, 0.0, 1.0, 3.0), 0.0);
        assert_eq!(step_cubic(1.0, 1.0, 0.0, 1.0, 3.0), 3.0);
    }

    #[test]
    fn paper_law_in_si() {
        let law = ImpactLaw::paper();
        law.validate().unwrap();
        // 3.988e5 N/mm^1.5 * (1000 mm/m)^1.5 = 3.988e5 * 31622.7766 = 1.2611163e10 N/m^1.5.
        assert!(close(law.stiffness, 1.261_116_3e10, 1e-6));
        // Same force in both unit systems at 0.01 mm: 3.988e5 * 0.01^1.5 = 398.8 N.
        assert!(close(law.force(1e-5, 0.0), 398.8, 1e-12));
    }

    #[test]
    fn continuous_at_zero_penetration() {
        let law = ImpactLaw::paper();
        assert_eq!(law.force(0.0, 1.0), 0.0);
        assert_eq!(law.force(-1e-6, 10.0), 0.0);
        // At 1 nm closing at 1 m/s: spring 1.26e10 * 3.16e-14 = 4e-4 N, damping
        // 1e5 * (1e-4)^2 * 3 = 3e-3 N: both vanish with the penetration.
        let f = law.force(1e-9, 1.0);
        assert!(f > 0.0 && f < 1e-2, "{f}");
    }

    #[test]
    fn full_damping_at_and_beyond_depth() {
        let law = ImpactLaw::new(1e9, 1.0, 2e4, 1e-5).unwrap();
        // At x = d the damping is cmax: 1e9 * 1e-5 + 2e4 * 0.1 = 1e4 + 2e3 = 1.2e4 N.
        assert!(close(law.force(1e-5, 0.1), 1.2e4, 1e-12));
        assert!(close(law.force(3e-5, 0.1), 3e4 + 2e3, 1e-12));
    }

    #[test]
    fn hand_value_at_half_depth() {
        let law = ImpactLaw::paper();
        // x = 5e-6 m, xdot = 0.02 m/s. Spring: 1.2611163e10 * (5e-6)^1.5
        //   (5e-6)^1.5 = 5e-6 * 2.2360680e-3 = 1.1180340e-8  -> 140.9971 N.
        // Damping: s = 0.5, c = 1e5 * 0.5 = 5e4 N s/m -> 5e4 * 0.02 = 1000 N.
        let expected = 3.988e5 * 1000f64.powf(1.5) * 1.118_034_0e-8 + 1000.0;
        assert!(close(law.force(5e-6, 0.02), expected, 1e-7));
        assert!(close(expected, 1140.997, 1e-5));
    }

    #[test]
    fn no_pulling_force_when_separating_fast() {
        let law = ImpactLaw::paper();
        assert_eq!(law.force(1e-5, -10.0), 0.0);
        let (f, dx, dv) = law.force_and_derivatives(1e-5, -10.0);
        assert_eq!((f, dx, dv), (0.0, 0.0, 0.0));
    }

    #[test]
    fn general_exponent_matches_powf() {
        let law = ImpactLaw::new(2e8, 1.3, 0.0, 1e-4).unwrap();
        // 2e8 * (1e-5)^1.3 = 2e8 * 10^(-6.5) = 2e8 * 3.16227766e-7 = 63.2455532 N.
        assert!(close(law.force(1e-5, 5.0), 63.245_553_2, 1e-8));
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let laws = [
            ImpactLaw::paper(),
            ImpactLaw::new(3e9, 1.0, 5e3, 2e-5).unwrap(),
            ImpactLaw::new(1e10, 2.2, 1e4, 1e-5).unwrap(),
        ];
        let states = [(2e-6, 0.3), (7e-6, -0.01), (1.5e-5, 0.05), (4e-5, -0.2)];
        for law in laws {
            for (x, v) in states {
                let (f, dfdx, dfdv) = law.force_and_derivatives(x, v);
                assert!(close(f, law.force(x, v), 1e-14));
                if f == 0.0 {
                    continue;
                }
                let hx = x * 1e-6;
                let fd_x = (law.force(x + hx, v) - law.force(x - hx, v)) / (2.0 * hx);
                let hv = 1e-6;
                let fd_v = (law.force(x, v + hv) - law.force(x, v - hv)) / (2.0 * hv);
                assert!(
                    close(dfdx, fd_x, 1e-6),
                    "{law:?} x={x} v={v}: {dfdx} vs {fd_x}"
                );
                assert!(
                    (dfdv - fd_v).abs() <= 1e-6 * dfdv.abs().max(1.0),
                    "{dfdv} vs {fd_v}"
                );
            }
        }
    }

    #[test]
    fn overflowing_forces_are_errors_not_infinity() {
        let law = ImpactLaw::paper();
        assert!(law.force(1e300, 0.0).is_infinite());
        let e = law.checked_force(1e300, 0.0).unwrap_err().to_string();
        assert!(e.contains("overflows") && e.contains("1e300"), "{e}");
        assert!(law.checked_force(1e-5, 1e308).is_err());
        assert_eq!(law.checked_force(1e-5, 0.1).unwrap(), law.force(1e-5, 0.1));
        assert_eq!(law.checked_force(-1.0, 1e308).unwrap(), 0.0);
    }

    #[test]
    fn invalid_parameters_are_rejected_with_reason() {
        let e = ImpactLaw::new(1e9, 0.8, 0.0, 1e-5).unwrap_err();
        assert!(e.to_string().contains("infinite contact stiffness"), "{e}");
        assert!(ImpactLaw::new(0.0, 1.5, 0.0, 1e-5).is_err());
        assert!(ImpactLaw::new(f64::NAN, 1.5, 0.0, 1e-5).is_err());
        assert!(ImpactLaw::new(1e9, f64::INFINITY, 0.0, 1e-5).is_err());
        assert!(ImpactLaw::new(1e9, 1.5, -1.0, 1e-5).is_err());
        assert!(ImpactLaw::new(1e9, 1.5, 0.0, 0.0).is_err());
        assert!(ImpactLaw::new(1e9, 1.5, 0.0, 1e-5).is_ok());
    }
}
