//! Hertz line contact of two parallel cylinders: width, pressure, approach; Palmgren's law.
//!
//! Convention: a radius is positive for a convex surface and negative for a concave one (a
//! pin inside a concave cycloid root). Sources: Johnson, Contact Mechanics (1985), ch. 4-5;
//! Roark's Formulas for Stress and Strain (cylinder on cylinder); Harris, Rolling Bearing
//! Analysis (Palmgren); see docs/model.md#contact-laws.

use crate::error::{Result, RvdynError, num, require_non_negative, require_positive};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// An isotropic linear-elastic material.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// Young's modulus `E` \[Pa\].
    pub youngs_modulus: f64,
    /// Poisson's ratio `nu` [-], in (-1, 0.5).
    pub poisson_ratio: f64,
}

impl Material {
    /// Build a validated material from `E` \[Pa\] and `nu` [-].
    ///
    /// Errors (`RvdynError::Parameter`) unless `E > 0` and `-1 < nu < 0.5`, both finite.
    pub fn new(youngs_modulus: f64, poisson_ratio: f64) -> Result<Self> {
        let m = Self {
            youngs_modulus,
            poisson_ratio,
        };
        m.validate()?;
        Ok(m)
    }

    /// The paper's steel: `E = 2.17e5 N/mm^2 = 2.17e11 Pa`, `nu = 0.3`.
    pub fn steel() -> Self {
        Self {
            youngs_modulus: 2.17e11,
            poisson_ratio: 0.3,
        }
    }

    /// Check the fields; returns `Ok(())` or the rule broken (`RvdynError::Parameter`).
    pub fn validate(&self) -> Result<()> {
        require_positive("Young's modulus", self.youngs_modulus, "Pa")?;
        let nu = self.poisson_ratio;
        // Outside (-1, 0.5) the bulk or shear modulus is negative or infinite.
        if !(nu.is_finite() && nu > -1.0 && nu < 0.5) {
            return Err(RvdynError::Parameter(format!(
                "Poisson's ratio must be in (-1, 0.5) for a stable isotropic material, got {}; \
                 steel is 0.3",
                num(nu)
            )));
        }
        Ok(())
    }

    /// Plane-strain compliance `(1 - nu^2) / E` [1/Pa].
    #[inline]
    pub fn compliance(&self) -> f64 {
        (1.0 - self.poisson_ratio * self.poisson_ratio) / self.youngs_modulus
    }
}

/// Effective (contact) modulus `E*` \[Pa\] of two materials.
///
/// Returns `E*` with `1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2`. The paper's eq. 8 subtracts the
/// two terms (docs/model.md#erratum-1), which is zero for equal materials; the sum is Hertz's.
/// Two paper steels give `E* = 2.17e11 / (2 * 0.91) = 1.1923e11 Pa`.
///
/// # Example
///
/// ```
/// use rvdyn::contact::{Material, effective_modulus};
/// let steel = Material::steel(); // E = 2.17e11 Pa, nu = 0.3
/// let e_star = effective_modulus(&steel, &steel);
/// assert!((e_star - 2.17e11 / (2.0 * (1.0 - 0.3 * 0.3))).abs() < 1.0); // 1.1923e11 Pa
/// ```
pub fn effective_modulus(m1: &Material, m2: &Material) -> f64 {
    1.0 / (m1.compliance() + m2.compliance())
}

/// Effective radius `R` \[m\] of two parallel cylinders, `1/R = 1/r1 + 1/r2`.
///
/// Radii in m, positive convex, negative concave. Returns `R > 0`. Errors
/// (`RvdynError::Geometry`) if a radius is zero or not finite, or if `R` is not positive: two
/// concave surfaces, or a convex cylinder at least as large as the concave seat around it
/// (conformal or nested surfaces do not make a Hertz line contact).
pub fn effective_radius(r1: f64, r2: f64) -> Result<f64> {
    for (name, r) in [("r1", r1), ("r2", r2)] {
        if !r.is_finite() || r == 0.0 {
            return Err(RvdynError::Geometry(format!(
                "contact radius {name} must be finite and non-zero (positive convex, negative \
                 concave), got {} m",
                num(r)
            )));
        }
    }
    let inv = 1.0 / r1 + 1.0 / r2;
    if inv.is_finite() && inv > 0.0 {
        Ok(1.0 / inv)
    } else {
        Err(RvdynError::Geometry(format!(
            "radii r1 = {} m and r2 = {} m give 1/R = {} 1/m, not a finite positive number: the \
             surfaces are concave-concave, conformal or nested and cannot touch as a Hertz line \
             contact (a concave radius, negative, must be larger in magnitude than the convex \
             one), or the radii are beyond the range of floating point",
            num(r1),
            num(r2),
            num(inv)
        )))
    }
}

/// Result of a Hertz line contact (SI units).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LineContact {
    /// Half width `a` of the contact strip \[m\].
    pub half_width: f64,
    /// Peak (central) pressure `p0` \[Pa\].
    pub peak_pressure: f64,
    /// Mean pressure `(pi/4) p0` \[Pa\].
    pub mean_pressure: f64,
    /// Approach of the two cylinder axes (sum of both bodies' centre-to-contact deflections) \[m\].
    pub approach: f64,
}

/// Hertz contact of two parallel cylinders pressed together by `force` \[N\] over `length` \[m\].
///
/// Radii `r1`, `r2` in m (positive convex, negative concave). Returns, with `P = F/L` and
/// `R`, `E*` from [`effective_radius`] and [`effective_modulus`]:
/// `a = sqrt(4 P R / (pi E*))`, `p0 = 2 P / (pi a)`, mean pressure `(pi/4) p0`, and the
/// approach `sum_k P (1 - nu_k^2)/(pi E_k) (2 ln(4 |R_k| / a) - 1)`.
///
/// The approach is Johnson's 2-D formula for a cylinder's centre-to-contact deflection
/// (K. L. Johnson, Contact Mechanics, 1985, section 5.6, eq. 5.39, quoted from memory, not
/// checked against the book). Using `|R_k|` for a concave body is an approximation (the
/// formula is derived for a solid cylinder). A 2-D approach needs a reference depth; the log
/// term carries it, so the result is a model value, not a unique physical one.
///
/// Errors: `Parameter` for a negative or non-finite force, non-positive length, invalid
/// material, results beyond floating point, or a half-width wider than the smaller radius
/// (outside Hertz theory); `Geometry` from [`effective_radius`]. Zero force gives all-zero
/// output.
///
/// # Example
///
/// ```
/// use rvdyn::contact::{Material, hertz_line_contact};
/// use std::f64::consts::PI;
/// // Two steel cylinders of radius 20 mm (R = 10 mm), 10 kN over 40 mm.
/// let steel = Material::steel();
/// let (force, length) = (10e3, 0.040);
/// let c = hertz_line_contact(force, length, 0.020, 0.020, &steel, &steel).unwrap();
/// // a = sqrt(4 P R / (pi E*)) with P = F/L and E* = E / (2 (1 - nu^2)).
/// let a = (4.0 * force / length * 0.010 / (PI * 2.17e11 / 1.82)).sqrt();
/// assert!((c.half_width - a).abs() < 1e-12 * a); // 0.163 mm
/// // The elliptic pressure over the strip carries the force: (pi/2) p0 a L = F.
/// assert!((PI / 2.0 * c.peak_pressure * c.half_width * length - force).abs() < 1e-6);
/// ```
pub fn hertz_line_contact(
    force: f64,
    length: f64,
    r1: f64,
    r2: f64,
    m1: &Material,
    m2: &Material,
) -> Result<LineContact> {
    require_non_negative("contact force", force, "N")?;
    require_positive("contact length", length, "m")?;
    m1.validate()?;
    m2.validate()?;
    let r = effective_radius(r1, r2)?;
    if force == 0.0 {
        // The log term of the approach is 0 * ln(inf): the limit is 0.
        return Ok(LineContact {
            half_width: 0.0,
            peak_pressure: 0.0,
            mean_pressure: 0.0,
            approach: 0.0,
        });
    }
    let e_star = effective_modulus(m1, m2);
    let p = force / length;
    // The closed forms rearranged so that no intermediate over- or underflows for any force
    // whose results are representable: a = sqrt(P) sqrt(4R/(pi E*)),
    // p0 = 2P/(pi a) = sqrt(P) sqrt(E*/(pi R)), ln(4|R_k|/a) = ln(4|R_k|) - ln(a) with
    // ln(a) = (ln P + ln(4R/(pi E*)))/2 (P = 5e-324 N/m gives a ~ 1e-168 m, not 0).
    let (a, p0) = hertz_line_strip(p, r, e_star);
    let ln_a = 0.5 * (p.ln() + (4.0 * r / (PI * e_star)).ln());
    let deflection = |m: &Material, rk: f64| {
        p * m.compliance() / PI * (2.0 * ((4.0 * rk.abs()).ln() - ln_a) - 1.0)
    };
    let c = LineContact {
        half_width: a,
        peak_pressure: p0,
        mean_pressure: 0.25 * PI * p0,
        approach: deflection(m1, r1) + deflection(m2, r2),
    };
    let values = [c.half_width, c.peak_pressure, c.mean_pressure, c.approach];
    if !(values.iter().all(|v| v.is_finite()) && p.is_finite() && p > 0.0) {
        return Err(RvdynError::Parameter(format!(
            "the Hertz contact of force {} N over length {} m (radii {} m, {} m) is beyond the \
             range of floating point (line load {} N/m): give a force, length and radii of \
             physical size",
            num(force),
            num(length),
            num(r1),
            num(r2),
            num(p)
        )));
    }
    // Hertz's half-spaces need a strip narrow against both bodies; one wider than the smaller
    // radius is no contact of cylinders (and past 2.4 times it the approach turns negative).
    let r_min = r1.abs().min(r2.abs());
    if a > r_min {
        return Err(RvdynError::Parameter(format!(
            "the Hertz half-width {} m of force {} N over length {} m is wider than the smaller \
             radius {} m: Hertz theory needs a contact strip narrow against the radii; lower the \
             line load (force / length, now {} N/m) or check the radii",
            num(a),
            num(force),
            num(length),
            num(r_min),
            num(p)
        )));
    }
    Ok(c)
}

/// Half-width `a` \[m\] and peak pressure `p0` \[Pa\] of the Hertz line contact under the line
/// load `p` [N/m] (`p >= 0`), effective radius `r` \[m\] (`> 0`) and effective modulus `e_star`
/// \[Pa\] (`> 0`): `a = sqrt(p) sqrt(4 r / (pi E*))`, `p0 = sqrt(p) sqrt(E* / (pi r))`
/// (`= 2 p / (pi a)`), the strip of [`hertz_line_contact`] without its checks or the approach
/// (for inputs checked once, as the LTCA's report does per loaded pin).
///
/// ```
/// use rvdyn::contact::hertz::{hertz_line_contact, hertz_line_strip, effective_modulus, Material};
/// let steel = Material::steel();
/// let (a, p0) = hertz_line_strip(1e6, 0.01, effective_modulus(&steel, &steel));
/// let full = hertz_line_contact(1e4, 0.01, 0.02, 0.02, &steel, &steel).unwrap();
/// assert!((a - full.half_width).abs() < 1e-15 && (p0 - full.peak_pressure).abs() < 1e-3);
/// ```
#[inline]
pub fn hertz_line_strip(p: f64, r: f64, e_star: f64) -> (f64, f64) {
    let sqrt_p = p.sqrt();
    (
        sqrt_p * (4.0 * r / (PI * e_star)).sqrt(),
        sqrt_p * (e_star / (PI * r)).sqrt(),
    )
}

/// Palmgren's coefficient 3.84e-5 mm N^-0.9 mm^0.8 (steel roller against raceway).
const PALMGREN_COEFF_MM: f64 = 3.84e-5;

/// Palmgren's approach \[m\] of a steel line contact under `force` \[N\] over `length` \[m\].
///
/// Returns `delta = 3.84e-5 Q^0.9 / l^0.8` evaluated in mm with `Q` in N and `l` in mm
/// (T. A. Harris, Rolling Bearing Analysis), converted to m. Empirical for steel on steel;
/// independent of the radii. Errors (`Parameter`) for a negative or non-finite force or a
/// non-positive length.
pub fn palmgren_approach(force: f64, length: f64) -> Result<f64> {
    require_non_negative("contact force", force, "N")?;
    require_positive("contact length", length, "m")?;
    let l_mm = length * 1e3;
    Ok(PALMGREN_COEFF_MM * force.powf(0.9) / l_mm.powf(0.8) * 1e-3)
}

/// Palmgren tangent stiffness `dQ/d delta` [N/m] at `force` \[N\] over `length` \[m\].
///
/// Returns `Q / (0.9 delta)` = `Q^0.1 l^0.8 / (0.9 * 3.84e-5)` (mm units, converted), which is
/// 0 at zero force. Errors as [`palmgren_approach`].
pub fn palmgren_stiffness(force: f64, length: f64) -> Result<f64> {
    require_non_negative("contact force", force, "N")?;
    require_positive("contact length", length, "m")?;
    let l_mm = length * 1e3;
    // Closed form instead of Q / (0.9 delta): finite (zero) at Q = 0.
    let n_per_mm = force.powf(0.1) * l_mm.powf(0.8) / (0.9 * PALMGREN_COEFF_MM);
    Ok(n_per_mm * 1e3)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::close;

    const STEEL: Material = Material {
        youngs_modulus: 2.17e11,
        poisson_ratio: 0.3,
    };

    #[test]
    fn effective_modulus_is_the_sum_of_compliances() {
        // Erratum 1: 1/E* = 2 * 0.91 / 2.17e11 -> E* = 1.192308e11 Pa (not 1/0).
        assert!(close(
            effective_modulus(&STEEL, &STEEL),
            1.192_307_7e11,
            1e-7
        ));
        // A rigid body (E -> huge) leaves E/(1-nu^2) of the other.
        let rigid = Material::new(1e30, 0.3).unwrap();
        assert!(close(
            effective_modulus(&STEEL, &rigid),
            2.17e11 / 0.91,
            1e-12
        ));
        assert_eq!(Material::steel(), STEEL);
    }

    #[test]
    fn material_validation() {
        assert!(Material::new(2e11, 0.5).is_err());
        assert!(Material::new(2e11, -1.0).is_err());
        assert!(Material::new(0.0, 0.3).is_err());
        assert!(Material::new(f64::NAN, 0.3).is_err());
        let e = Material::new(2e11, 0.7).unwrap_err();
        assert!(e.to_string().contains("(-1, 0.5)"), "{e}");
    }

    #[test]
    fn effective_radius_convex_and_concave() {
        // 10 mm and 94 mm: 940/104 = 9.0385 mm.
        assert!(close(
            effective_radius(0.010, 0.094).unwrap(),
            0.940 / 104.0,
            1e-12
        ));
        // Pin 10 mm in a 12 mm concave seat: 1/R = 1/10 - 1/12 = 1/60 -> 60 mm.
        assert!(close(
            effective_radius(0.010, -0.012).unwrap(),
            0.060,
            1e-12
        ));
        let e = effective_radius(0.012, -0.010).unwrap_err();
        assert!(matches!(e, RvdynError::Geometry(_)));
        assert!(
            e.to_string().contains("0.012") && e.to_string().contains("-0.01"),
            "{e}"
        );
        assert!(effective_radius(0.010, -0.010).is_err());
        assert!(effective_radius(-0.010, -0.020).is_err());
        assert!(effective_radius(0.0, 0.010).is_err());
        assert!(effective_radius(f64::INFINITY, 0.010).is_err());
    }

    #[test]
    fn default_pin_contact_numbers() {
        // docs/model.md#contact-laws: F = 35 kN, L = 40 mm, R_pin 10 mm, R_disc 94 mm.
        // P = 875e3 N/m, R = 9.0385e-3 m, E* = 1.19231e11 Pa:
        // a = sqrt(4 * 875e3 * 9.0385e-3 / (pi * 1.19231e11)) = sqrt(8.4453e-8) = 2.9061e-4 m.
        let c = hertz_line_contact(35e3, 0.040, 0.010, 0.094, &STEEL, &STEEL).unwrap();
        assert!(close(c.half_width, 2.9061e-4, 1e-4), "{c:?}");
        // p0 = 2 * 875e3 / (pi * 2.9061e-4) = 1.9168e9 Pa.
        assert!(close(c.peak_pressure, 1.9168e9, 1e-4), "{c:?}");
        assert!(close(c.mean_pressure, 0.25 * PI * c.peak_pressure, 1e-15));
        // Approach: P (1-nu^2)/(pi E) = 875e3 * 4.19355e-12 / pi = 1.16799e-6 m, times
        // [2 ln(40/0.29061) - 1] + [2 ln(376/0.29061) - 1] = 8.8494 + 13.3300 = 22.1794
        // -> 2.5905e-5 m ~ 0.026 mm.
        assert!(close(c.approach, 2.5905e-5, 1e-3), "{c:?}");
        // Palmgren for the same load: 0.0247 mm (independent of the radii).
        let d = palmgren_approach(35e3, 0.040).unwrap();
        assert!(close(d, 2.470e-5, 2e-3), "{d}");
        // The two models agree to within 5 % here.
        assert!(close(c.approach, d, 0.05));
    }

    #[test]
    fn roark_form_cross_check() {
        // Roark: full width b = 1.60 sqrt(p K_D C_E), sigma_max = 0.798 sqrt(p / (K_D C_E)),
        // K_D = D1 D2 / (D1 + D2) = 2R, C_E = 1/E*. Exact factors: sqrt(32/pi)/2 = 1.5958 and
        // sqrt(2/pi) = 0.79788, so the printed 1.60 and 0.798 agree to 0.3 % and 0.02 %.
        for (f, l, r1, r2) in [(35e3, 0.04, 0.01, 0.094), (1e3, 0.01, 0.02, -0.05)] {
            let c = hertz_line_contact(f, l, r1, r2, &STEEL, &STEEL).unwrap();
            let p = f / l;
            let k_d = 2.0 * effective_radius(r1, r2).unwrap();
            let c_e = 1.0 / effective_modulus(&STEEL, &STEEL);
            let b = 1.60 * (p * k_d * c_e).sqrt();
            let sigma = 0.798 * (p / (k_d * c_e)).sqrt();
            assert!(
                close(b, 2.0 * c.half_width, 3e-3),
                "{b} vs {}",
                2.0 * c.half_width
            );
            assert!(
                close(sigma, c.peak_pressure, 3e-4),
                "{sigma} vs {}",
                c.peak_pressure
            );
        }
    }

    #[test]
    fn extreme_forces_are_finite_or_errors() {
        let m = Material::steel();
        // The smallest force: the old form gave a = 0 and p0 = inf; the limits are a -> 0+,
        // p0 -> 0+, approach -> 0.
        let c = hertz_line_contact(5e-324, 0.04, 0.01, 0.1, &m, &m).unwrap();
        assert!(c.half_width > 0.0 && c.half_width < 1e-150, "{c:?}");
        assert!(c.peak_pressure > 0.0 && c.peak_pressure < 1e-140, "{c:?}");
        assert!(c.approach.is_finite() && c.approach.abs() < 1e-300, "{c:?}");
        // A line load beyond f64: an error naming the inputs, not inf/NaN.
        let e = hertz_line_contact(1e308, 0.04, 0.01, 0.1, &m, &m).unwrap_err();
        assert!(matches!(e, RvdynError::Parameter(_)), "{e}");
        assert!(
            e.to_string().contains("1e308") && e.to_string().len() < 400,
            "{e}"
        );
        // A strip wider than the smaller radius is outside Hertz theory: an error naming the
        // radius, not a negative approach (force 1e12 N: a = 0.6 m against r1 = 0.01 m).
        let e = hertz_line_contact(1e12, 0.04, 0.01, 0.1, &m, &m).unwrap_err();
        assert!(
            matches!(e, RvdynError::Parameter(_)) && e.to_string().contains("smaller radius"),
            "{e}"
        );
        // The radius itself too small for the force (a = 1.0e-9 m > r1 = 1e-12 m).
        assert!(hertz_line_contact(1e3, 0.01, 1e-12, 0.01, &m, &m).is_err());
        // The rearranged closed forms agree with the textbook ones at ordinary loads.
        let c = hertz_line_contact(5e3, 0.04, 0.01, 0.1, &m, &m).unwrap();
        let (p, r, es) = (
            5e3 / 0.04,
            1.0 / (1.0 / 0.01 + 1.0 / 0.1),
            effective_modulus(&m, &m),
        );
        let a = (4.0 * p * r / (PI * es)).sqrt();
        assert!(close(c.half_width, a, 1e-14) && close(c.peak_pressure, 2.0 * p / (PI * a), 1e-14));
        let d = |rk: f64| p * m.compliance() / PI * (2.0 * (4.0 * rk / a).ln() - 1.0);
        assert!(close(c.approach, d(0.01) + d(0.1), 1e-12), "{c:?}");
    }

    #[test]
    fn half_width_scales_as_sqrt_of_load() {
        let c1 = hertz_line_contact(1e3, 0.04, 0.01, 0.1, &STEEL, &STEEL).unwrap();
        let c4 = hertz_line_contact(4e3, 0.04, 0.01, 0.1, &STEEL, &STEEL).unwrap();
        assert!(close(c4.half_width, 2.0 * c1.half_width, 1e-12));
        assert!(close(c4.peak_pressure, 2.0 * c1.peak_pressure, 1e-12));
    }

    #[test]
    fn palmgren_stiffness_is_tangent() {
        // Secant 35e3 / 2.470e-5 = 1.417e9 N/m; tangent = secant / 0.9 = 1.574e9 N/m.
        let k = palmgren_stiffness(35e3, 0.040).unwrap();
        assert!(close(
            k,
            35e3 / (0.9 * palmgren_approach(35e3, 0.040).unwrap()),
            1e-12
        ));
        assert!(close(k, 1.574e9, 3e-3), "{k}");
        let h = 1.0;
        let fd = 2.0 * h
            / (palmgren_approach(35e3 + h, 0.04).unwrap()
                - palmgren_approach(35e3 - h, 0.04).unwrap());
        assert!(close(k, fd, 1e-6));
        assert_eq!(palmgren_stiffness(0.0, 0.04).unwrap(), 0.0);
    }

    #[test]
    fn zero_force_and_invalid_inputs() {
        let c = hertz_line_contact(0.0, 0.04, 0.01, 0.1, &STEEL, &STEEL).unwrap();
        assert_eq!(c.half_width, 0.0);
        assert_eq!(c.approach, 0.0);
        assert!(!c.peak_pressure.is_nan());
        assert_eq!(palmgren_approach(0.0, 0.04).unwrap(), 0.0);
        assert!(hertz_line_contact(-1.0, 0.04, 0.01, 0.1, &STEEL, &STEEL).is_err());
        assert!(hertz_line_contact(f64::NAN, 0.04, 0.01, 0.1, &STEEL, &STEEL).is_err());
        assert!(hertz_line_contact(1.0, 0.0, 0.01, 0.1, &STEEL, &STEEL).is_err());
        assert!(hertz_line_contact(1.0, 0.04, f64::NAN, 0.1, &STEEL, &STEEL).is_err());
        assert!(hertz_line_contact(1.0, 0.04, 0.01, f64::INFINITY, &STEEL, &STEEL).is_err());
        let bad = Material {
            youngs_modulus: -1.0,
            poisson_ratio: 0.3,
        };
        assert!(hertz_line_contact(1.0, 0.04, 0.01, 0.1, &bad, &STEEL).is_err());
        assert!(palmgren_approach(-1.0, 0.04).is_err());
        assert!(palmgren_approach(1.0, f64::NAN).is_err());
        assert!(palmgren_stiffness(f64::INFINITY, 0.04).is_err());
    }
}
