//! The paper's contact stiffness against contact width (its eqs. 5-11), errata corrected.
//!
//! With the paper's symbols, evaluated in the paper's units (N, mm):
//!
//! - eq. 8 corrected (docs/model.md#erratum-1): `C_E = 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2`;
//! - eq. 7: `R = R1 R2 / (R1 + R2)` convex-convex, `R1 R2 / (R2 - R1)` convex-concave;
//! - eq. 6: `k' = (4/3) E* sqrt(R)` [N/mm^1.5] (Hertz point-contact coefficient);
//! - eq. 10: `F = k' x^e`, `x` the IMPACT penetration depth parameter (paper 0.01 mm);
//! - eq. 11 corrected (erratum 2): Roark's FULL width `b = 1.60 sqrt(F/L K_D C_E)` with
//!   `K_D = 2R` (`2 R1 R2/(R1 + R2)` or `2 R1 R2/(R2 - R1)`);
//! - eq. 9: `w = 2F/(pi L) [C1 (1/3 + ln(4 R1/b)) + C2 (1/3 + ln(4 R2/b))]`,
//!   `Ck = (1 - nuk^2)/Ek` (Roark's per-body form with `b` the full width);
//! - eq. 5: `k = k' sqrt(w)`, `L` the contact width (face width; Fig. 3's x axis).
//!
//! Radii. The paper says "pitch radius of pin" (R1) and "pitch radius of cycloid" (R2). Eq. 9
//! is the elastic approach of two cylinders, so each radius must be the radius of curvature
//! of a body at the contact: here `r1` is the pin radius `rrp`, `r2` the magnitude of the
//! radius of curvature of the disc's actual profile at the contact (convex at a lobe tip,
//! concave at a root; a concave root must wrap the pin, `r2 > r1`). The paper's Fig. 3 gives
//! no radii; [`StiffnessParams::paper`] reads "pitch radius of cycloid" as the disc pitch radius
//! `rc' = e zc = 103.5 mm` with the assumed pin radius 10 mm, for both conditions (the paper
//! changes only the formula between them).
//!
//! Units, and what the formula cannot do. `k' sqrt(w)` has the unit N/mm (the paper's text
//! says so), yet the paper uses it as an IMPACT stiffness in N/mm^1.5 (erratum 4). The number
//! therefore depends on the length unit; we follow the paper: `w` in mm, the result read as
//! N/mm^e and converted once to N/m^e (x 1000^e). Equivalently `k = k'_SI sqrt(w / 1 mm)` for
//! e = 1.5.
//!
//! Against the paper (not tuned): with the errata corrected, `k` DECREASES monotonically with
//! width over every physical width. Its only maximum is at `L* = e^(1/3) 2.56 F K_D C_E /
//! (16 R1 R2)` (equal materials), about 1.6e-5 mm, where the Hertz width `b` is ~109 mm, far
//! outside Hertz theory. At 5 mm the reading above gives 2.84e4 N/mm^1.5 (convex-convex) and
//! 3.25e4 N/mm^1.5 (convex-concave), 14x and 16x below the paper's 3.988e5 and 5.093e5; the
//! paper's maximum near 5 mm is not reproduced (its eq. 8 as printed gives 0 compliance, so
//! its curves cannot come from the printed formulas either).

use crate::contact::hertz::Material;
use crate::error::{Result, RvdynError, num, require_finite, require_positive};
use std::f64::consts::PI;

/// Millimetres per metre: the paper's formulas are evaluated in mm (see the module doc).
const MM_PER_M: f64 = 1e3;

/// Where the pin touches the disc: the sign of the disc's curvature at the contact.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContactCondition {
    /// Pin on a convex lobe tip (paper's "pin-top of cycloid").
    ConvexConvex,
    /// Pin in a concave root (paper's "pin-dedendum of cycloid"); needs `r2 > r1`.
    ConvexConcave,
}

impl ContactCondition {
    /// Parse `"convex-convex"` or `"convex-concave"` (case-insensitive, `_` allowed for `-`).
    ///
    /// Returns the condition, or `RvdynError::Parameter` listing the accepted names.
    pub fn parse(s: &str) -> Result<Self> {
        match s.trim().to_ascii_lowercase().replace('_', "-").as_str() {
            "convex-convex" => Ok(Self::ConvexConvex),
            "convex-concave" => Ok(Self::ConvexConcave),
            _ => Err(RvdynError::Parameter(format!(
                "unknown contact condition {s:?}: choose \"convex-convex\" (pin on a lobe tip) \
                 or \"convex-concave\" (pin in a root)"
            ))),
        }
    }

    /// The canonical name, as accepted by [`ContactCondition::parse`].
    pub fn as_str(&self) -> &'static str {
        match self {
            Self::ConvexConvex => "convex-convex",
            Self::ConvexConcave => "convex-concave",
        }
    }
}

/// Inputs of the paper's stiffness formula (SI units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StiffnessParams {
    /// Pin radius `R1` \[m\].
    pub r1: f64,
    /// Magnitude of the disc profile's radius of curvature at the contact `R2` \[m\].
    pub r2: f64,
    /// Convex-convex or convex-concave.
    pub condition: ContactCondition,
    /// Pin material.
    pub material1: Material,
    /// Disc material.
    pub material2: Material,
    /// IMPACT force exponent `e` [-] (paper 1.5).
    pub exponent: f64,
    /// IMPACT penetration depth parameter `x` of eq. 10 \[m\] (paper 0.01 mm = 1e-5 m).
    pub penetration: f64,
}

impl StiffnessParams {
    /// The reading of the paper's Fig. 3 used by rvdyn: `R1` = 10 mm (assumed pin radius of
    /// the default scene), `R2` = `rc' = e zc = 4.5 mm * 23 = 103.5 mm`, the paper's steel,
    /// `e = 1.5`, `x = 0.01 mm`.
    pub fn paper(condition: ContactCondition) -> Self {
        Self {
            r1: 0.010,
            r2: 0.1035,
            condition,
            material1: Material::steel(),
            material2: Material::steel(),
            exponent: 1.5,
            penetration: 1.0e-5,
        }
    }

    /// Check the fields; returns `Ok(())` or the rule broken (`Parameter`, or `Geometry` for
    /// a concave radius that does not wrap the pin).
    pub fn validate(&self) -> Result<()> {
        require_positive("pin radius r1", self.r1, "m")?;
        require_positive("disc radius of curvature r2", self.r2, "m")?;
        if self.condition == ContactCondition::ConvexConcave && self.r2 <= self.r1 {
            return Err(RvdynError::Geometry(format!(
                "convex-concave contact needs the concave disc radius r2 = {} m to exceed the pin \
                 radius r1 = {} m (R = R1 R2/(R2 - R1) must be positive); use convex-convex or \
                 a larger r2",
                num(self.r2),
                num(self.r1)
            )));
        }
        self.material1.validate()?;
        self.material2.validate()?;
        if !(self.exponent.is_finite() && self.exponent >= 1.0) {
            return Err(RvdynError::Parameter(format!(
                "stiffness exponent must be a finite number >= 1, got {}; the paper uses 1.5",
                num(self.exponent)
            )));
        }
        require_positive("penetration depth x", self.penetration, "m")?;
        Ok(())
    }

    /// Effective radius `R` of eq. 7 \[m\]: `R1 R2/(R1 + R2)` or `R1 R2/(R2 - R1)`.
    ///
    /// Returns `R` without validation; call [`StiffnessParams::validate`] first.
    pub fn effective_radius(&self) -> f64 {
        match self.condition {
            ContactCondition::ConvexConvex => self.r1 * self.r2 / (self.r1 + self.r2),
            ContactCondition::ConvexConcave => self.r1 * self.r2 / (self.r2 - self.r1),
        }
    }
}

/// Every intermediate of eqs. 5-11 at one width (SI units), for reports and checks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StiffnessTerms {
    /// `k'` of eq. 6 [N/m^1.5].
    pub coefficient: f64,
    /// `F = k' x^e` of eq. 10 \[N\].
    pub force: f64,
    /// Roark's full contact width `b` of eq. 11 \[m\].
    pub full_width: f64,
    /// Contact deformation `w` of eq. 9 \[m\].
    pub deformation: f64,
    /// `k = k' sqrt(w)` of eq. 5, w in mm, read as N/mm^e and converted [N/m^e].
    pub stiffness: f64,
}

/// All terms of eqs. 5-11 at contact width `width` \[m\].
///
/// Returns [`StiffnessTerms`]. Errors: invalid parameters (see
/// [`StiffnessParams::validate`]), `width` not finite and > 0, or a width so small that the
/// Hertz width `b` makes the log terms of eq. 9 negative (no positive deformation).
pub fn contact_stiffness_terms(width: f64, p: &StiffnessParams) -> Result<StiffnessTerms> {
    require_positive("contact width", width, "m")?;
    p.validate()?;
    // The paper's units: N and mm (compliances in mm^2/N = 1e6 * 1/Pa).
    let (r1, r2) = (p.r1 * MM_PER_M, p.r2 * MM_PER_M);
    let length = width * MM_PER_M;
    let x = p.penetration * MM_PER_M;
    let c1 = p.material1.compliance() * 1e6;
    let c2 = p.material2.compliance() * 1e6;
    let c_e = c1 + c2;
    let r = p.effective_radius() * MM_PER_M;
    let coefficient = 4.0 / 3.0 / c_e * r.sqrt();
    let force = coefficient * x.powf(p.exponent);
    let k_d = 2.0 * r;
    let b = 1.60 * (force / length * k_d * c_e).sqrt();
    let bracket = c1 * (1.0 / 3.0 + (4.0 * r1 / b).ln()) + c2 * (1.0 / 3.0 + (4.0 * r2 / b).ln());
    let w = 2.0 * force / (PI * length) * bracket;
    let stiffness_per_mm = coefficient * w.sqrt();
    let out_of_range = || {
        RvdynError::Parameter(format!(
            "contact width {} m with radii r1 = {} m, r2 = {} m, exponent {} and penetration {} \
             m is beyond the range of floating point for eqs. 5-11 (an intermediate over- or \
             underflows); use values of physical size",
            num(width),
            num(p.r1),
            num(p.r2),
            num(p.exponent),
            num(p.penetration)
        ))
    };
    if b > 0.0 && bracket <= 0.0 {
        return Err(RvdynError::Parameter(format!(
            "contact width {} m is too small for eq. 9 at penetration {} m: the force k' x^e = \
             {} N gives a Hertz width b = {} m that exceeds the radii, so the deformation is {} \
             m <= 0; use a width of at least a few micrometres or a smaller penetration (the \
             paper's is 1e-5 m)",
            num(width),
            num(p.penetration),
            num(force),
            num(b / MM_PER_M),
            num(w / MM_PER_M)
        )));
    }
    let terms = [
        coefficient,
        force,
        b,
        w,
        stiffness_per_mm * MM_PER_M.powf(p.exponent),
    ];
    if !(w > 0.0 && terms.iter().all(|v| v.is_finite())) {
        return Err(out_of_range());
    }
    Ok(StiffnessTerms {
        coefficient: coefficient * MM_PER_M.powf(1.5),
        force,
        full_width: b / MM_PER_M,
        deformation: w / MM_PER_M,
        stiffness: stiffness_per_mm * MM_PER_M.powf(p.exponent),
    })
}

/// The paper's contact stiffness `k` [N/m^exponent] at contact width `width` \[m\].
///
/// Returns `k` of eq. 5 (see the module doc for the unit convention and for how it compares
/// with the paper). Errors as [`contact_stiffness_terms`].
///
/// # Example
///
/// ```
/// use rvdyn::contact::{ContactCondition, StiffnessParams, contact_stiffness};
/// let p = StiffnessParams::paper(ContactCondition::ConvexConvex); // e = 1.5
/// let k = contact_stiffness(0.005, &p).unwrap(); // 5 mm contact width
/// let per_mm = k / 1000f64.powf(1.5); // N/m^1.5 -> N/mm^1.5
/// assert!((per_mm - 2.8409e4).abs() < 1.0); // 14x below the paper's 3.988e5 N/mm^1.5
/// // The corrected formula decreases with width (no maximum near 5 mm).
/// assert!(contact_stiffness(0.010, &p).unwrap() < k);
/// ```
pub fn contact_stiffness(width: f64, p: &StiffnessParams) -> Result<f64> {
    contact_stiffness_terms(width, p).map(|t| t.stiffness)
}

/// [`contact_stiffness`] at each width \[m\]; returns the stiffnesses [N/m^exponent] in order,
/// or the first error.
pub fn contact_stiffness_many(widths: &[f64], p: &StiffnessParams) -> Result<Vec<f64>> {
    widths.iter().map(|&w| contact_stiffness(w, p)).collect()
}

/// Samples of the coarse scan that brackets the maximum before the golden-section search.
const SCAN_SAMPLES: usize = 64;

/// Width \[m\] and value [N/m^exponent] of the largest stiffness for widths in `[lo, hi]` \[m\].
///
/// A log-spaced scan brackets the largest sample, then a golden-section search (in ln width)
/// refines it to 1e-10 relative. Returns `(width_at_max, k_max)` for an interior maximum.
/// Errors: `Parameter` if `0 < lo < hi` (finite) does not hold, or if the largest value is at
/// an end of the bracket (no interior maximum: the curve is monotone there; the corrected
/// formula decreases with width over every physical range, see the module doc); any error of
/// [`contact_stiffness`].
pub fn stiffness_maximum(p: &StiffnessParams, lo: f64, hi: f64) -> Result<(f64, f64)> {
    require_positive("lower width bound", lo, "m")?;
    require_finite("upper width bound", hi)?;
    if hi <= lo {
        return Err(RvdynError::Parameter(format!(
            "width bracket must satisfy lo < hi, got lo = {} m, hi = {} m",
            num(lo),
            num(hi)
        )));
    }
    let (ln_lo, ln_hi) = (lo.ln(), hi.ln());
    let step = (ln_hi - ln_lo) / (SCAN_SAMPLES - 1) as f64;
    let k_at = |t: f64| contact_stiffness(t.exp(), p);
    let mut best = (0usize, f64::NEG_INFINITY);
    for i in 0..SCAN_SAMPLES {
        let k = k_at(ln_lo + step * i as f64)?;
        if k > best.1 {
            best = (i, k);
        }
    }
    if best.0 == 0 || best.0 == SCAN_SAMPLES - 1 {
        let (end, width) = if best.0 == 0 {
            ("lower", lo)
        } else {
            ("upper", hi)
        };
        return Err(RvdynError::Parameter(format!(
            "contact stiffness has no interior maximum for widths in [{}, {}] m: it is \
             largest at the {end} end, width {} m, k = {} N/m^{}; the corrected eqs. 5-11 \
             decrease with width over physical widths (the paper's maximum near 5 mm is not \
             reproduced); widen the bracket to find the formal maximum",
            num(lo),
            num(hi),
            num(width),
            num(best.1),
            num(p.exponent)
        )));
    }
    let (mut a, mut b) = (
        ln_lo + step * (best.0 - 1) as f64,
        ln_lo + step * (best.0 + 1) as f64,
    );
    let inv_phi = (5f64.sqrt() - 1.0) / 2.0;
    let mut c = b - inv_phi * (b - a);
    let mut d = a + inv_phi * (b - a);
    let (mut kc, mut kd) = (k_at(c)?, k_at(d)?);
    // ln-width tolerance 1e-10 ~ 1e-10 relative in width; 0.618^60 * bracket is far below it.
    while b - a > 1e-10 {
        if kc >= kd {
            b = d;
            d = c;
            kd = kc;
            c = b - inv_phi * (b - a);
            kc = k_at(c)?;
        } else {
            a = c;
            c = d;
            kc = kd;
            d = a + inv_phi * (b - a);
            kd = k_at(d)?;
        }
    }
    let t = 0.5 * (a + b);
    Ok((t.exp(), k_at(t)?))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::close;

    /// 1000^1.5: N/mm^1.5 -> N/m^1.5.
    const PER_MM15: f64 = 31_622.776_601_683_792;

    #[test]
    fn hand_value_at_5_mm_convex_convex() {
        // Paper units (N, mm). C = 0.91 / 2.17e5 = 4.193548e-6 mm^2/N, C_E = 8.387097e-6,
        // E* = 119230.77 N/mm^2. R = 10 * 103.5 / 113.5 = 9.118943 mm, sqrt(R) = 3.019759.
        // k' = 4/3 * 119230.77 * 3.019759 = 480064.2 N/mm^1.5; F = k' * 0.01^1.5 = 480.0642 N.
        // K_D = 18.237885 mm; p = F/5 = 96.01284 N/mm; p K_D C_E = 0.01468640 mm^2;
        // b = 1.60 * sqrt(0.01468640) = 0.1939000 mm.
        // ln(40/0.1939) = 5.329292, ln(414/0.1939) = 7.666279; bracket = 2/3 + sum = 13.662238.
        // w = 2 * 480.0642 / (pi * 5) * 4.193548e-6 * 13.662238 = 3.501974e-3 mm.
        // k = 480064.2 * sqrt(3.501974e-3) = 28408.99 N/mm^1.5 = 8.98371e8 N/m^1.5.
        let p = StiffnessParams::paper(ContactCondition::ConvexConvex);
        let t = contact_stiffness_terms(0.005, &p).unwrap();
        assert!(close(t.coefficient, 480_064.2 * PER_MM15, 1e-6), "{t:?}");
        assert!(close(t.force, 480.0642, 1e-6), "{t:?}");
        assert!(close(t.full_width, 0.193_900_0e-3, 1e-6), "{t:?}");
        assert!(close(t.deformation, 3.501_974e-6, 1e-6), "{t:?}");
        assert!(close(t.stiffness, 28_408.99 * PER_MM15, 1e-6), "{t:?}");
        assert_eq!(contact_stiffness(0.005, &p).unwrap(), t.stiffness);
    }

    #[test]
    fn symmetric_in_radii_for_convex_convex() {
        let p = StiffnessParams::paper(ContactCondition::ConvexConvex);
        let q = StiffnessParams {
            r1: p.r2,
            r2: p.r1,
            ..p
        };
        for w in [0.001, 0.005, 0.04] {
            let (a, b) = (
                contact_stiffness(w, &p).unwrap(),
                contact_stiffness(w, &q).unwrap(),
            );
            assert!(close(a, b, 1e-13), "{a} vs {b}");
        }
    }

    #[test]
    fn convex_concave_is_stiffer() {
        let cc = StiffnessParams::paper(ContactCondition::ConvexConvex);
        let cv = StiffnessParams::paper(ContactCondition::ConvexConcave);
        for w in [0.001, 0.005, 0.02, 0.04] {
            assert!(contact_stiffness(w, &cv).unwrap() > contact_stiffness(w, &cc).unwrap());
        }
        // R = 10 * 103.5 / 93.5 = 11.069519 mm for the concave root.
        assert!(close(cv.effective_radius(), 0.011_069_519, 1e-7));
    }

    #[test]
    fn golden_section_finds_the_closed_form_maximum() {
        // Equal materials: w = (2 F C / pi) (2/3 + ln(L/L0)) / L with
        // L0 = 2.56 F K_D C_E / (16 R1 R2), so dw/dL = 0 at L* = L0 e^(1/3) and
        // k_max = k' sqrt(2 F C / (pi L*)) (mm units).
        for cond in [
            ContactCondition::ConvexConvex,
            ContactCondition::ConvexConcave,
        ] {
            let p = StiffnessParams::paper(cond);
            let c = 0.91 / 2.17e5;
            let r = p.effective_radius() * 1e3;
            let kp = 4.0 / 3.0 / (2.0 * c) * r.sqrt();
            let f = kp * 1e-3;
            let l_star =
                (1.0f64 / 3.0).exp() * 2.56 * f * 2.0 * r * 2.0 * c / (16.0 * 10.0 * 103.5);
            let k_max = kp * (2.0 * f * c / (PI * l_star)).sqrt() * PER_MM15;
            let (w, k) = stiffness_maximum(&p, 1e-8, 1e-6).unwrap();
            assert!(close(w, l_star * 1e-3, 1e-6), "{w} vs {}", l_star * 1e-3);
            assert!(close(k, k_max, 1e-9), "{k} vs {k_max}");
        }
    }

    #[test]
    fn paper_figure_3_is_not_reproduced() {
        // The corrected formulas decrease with width over 0.5-40 mm: no maximum near 5 mm, and
        // at 5 mm they are an order of magnitude below the paper's 3.988e5 / 5.093e5 N/mm^1.5.
        for (cond, paper) in [
            (ContactCondition::ConvexConvex, 3.988e5),
            (ContactCondition::ConvexConcave, 5.093e5),
        ] {
            let p = StiffnessParams::paper(cond);
            let widths: Vec<f64> = (1..=80).map(|i| 0.5e-3 * i as f64).collect();
            let k = contact_stiffness_many(&widths, &p).unwrap();
            assert!(k.windows(2).all(|w| w[1] < w[0]));
            let k5 = contact_stiffness(0.005, &p).unwrap() / PER_MM15;
            assert!(k5 < 0.1 * paper, "{k5}");
            let e = stiffness_maximum(&p, 0.5e-3, 0.040).unwrap_err();
            assert!(e.to_string().contains("no interior maximum"), "{e}");
        }
    }

    #[test]
    fn parse_conditions() {
        assert_eq!(
            ContactCondition::parse("convex-convex").unwrap(),
            ContactCondition::ConvexConvex
        );
        assert_eq!(
            ContactCondition::parse(" Convex_Concave ").unwrap(),
            ContactCondition::ConvexConcave
        );
        let e = ContactCondition::parse("concave").unwrap_err();
        assert!(
            e.to_string().contains("convex-convex") && e.to_string().contains("convex-concave")
        );
        for c in [
            ContactCondition::ConvexConvex,
            ContactCondition::ConvexConcave,
        ] {
            assert_eq!(ContactCondition::parse(c.as_str()).unwrap(), c);
        }
    }

    #[test]
    fn invalid_inputs_are_errors() {
        let cc = StiffnessParams::paper(ContactCondition::ConvexConvex);
        let cv = StiffnessParams {
            r2: 0.010,
            ..StiffnessParams::paper(ContactCondition::ConvexConcave)
        };
        let e = contact_stiffness(0.005, &cv).unwrap_err();
        assert!(matches!(e, RvdynError::Geometry(_)), "{e}");
        assert!(contact_stiffness(0.005, &StiffnessParams { r2: 0.008, ..cv }).is_err());
        assert!(contact_stiffness(0.0, &cc).is_err());
        assert!(contact_stiffness(-0.005, &cc).is_err());
        assert!(contact_stiffness(f64::NAN, &cc).is_err());
        assert!(contact_stiffness(0.005, &StiffnessParams { r1: f64::NAN, ..cc }).is_err());
        assert!(
            contact_stiffness(
                0.005,
                &StiffnessParams {
                    r2: f64::INFINITY,
                    ..cc
                }
            )
            .is_err()
        );
        assert!(
            contact_stiffness(
                0.005,
                &StiffnessParams {
                    exponent: 0.5,
                    ..cc
                }
            )
            .is_err()
        );
        assert!(
            contact_stiffness(
                0.005,
                &StiffnessParams {
                    penetration: 0.0,
                    ..cc
                }
            )
            .is_err()
        );
        // A width so small that b >> R: no positive deformation.
        assert!(contact_stiffness(1e-12, &cc).is_err());
        assert!(contact_stiffness_many(&[0.005, -1.0], &cc).is_err());
        assert!(stiffness_maximum(&cc, 0.01, 0.005).is_err());
        assert!(stiffness_maximum(&cc, 0.0, 0.005).is_err());
    }

    #[test]
    fn extreme_widths_give_short_messages_that_say_why() {
        let cc = StiffnessParams::paper(ContactCondition::ConvexConvex);
        // The smallest width: too small, said in a short message (no 300-digit numbers).
        let e = contact_stiffness(5e-324, &cc).unwrap_err().to_string();
        assert!(
            e.contains("too small") && e.contains("5e-324") && e.len() < 300,
            "{e}"
        );
        // A huge width is not "too small": it is beyond floating point.
        let e = stiffness_maximum(&cc, 1e-8, 1e308).unwrap_err().to_string();
        assert!(
            !e.contains("too small") && e.contains("floating point"),
            "{e}"
        );
        assert!(e.len() < 400, "{e}");
    }
}
