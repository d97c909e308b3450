//! Involute first stage: a sun and equally spaced planets on crankshafts (no ring gear).
//!
//! Standard full-depth spur gears (addendum = module, no profile shift), centre distance
//! `a = m (z_sun + z_planet) / 2` = crank circle radius.
//!
//! Assembly. In an RV reducer each planet sits on a crankshaft whose bearings are fixed in the
//! carrier and there is no ring gear in this stage, so the classical `(z_sun + z_ring) /
//! planets` integer condition does not apply: each planet can be turned on its own axis until
//! it meshes with the sun at its angle, which is always possible for an external pair. (The
//! cranks must then be phased alike for the eccentrics; that is a crank matter, not a gear
//! one.) What can fail is spacing (neighbouring planets' tip circles overlap) and continuity
//! of mesh (contact ratio below 1); both are checked.
//!
//! Theory: docs/model.md, section "Geometry" of "First-stage mesh".

use crate::error::{Result, RvdynError, num, require_non_negative};
use crate::geometry::cycloid::require_length;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Smallest tooth count accepted: below it the involute hardly exists above the base circle.
const MIN_TEETH: u32 = 5;

/// Largest tooth count accepted (far above any gear of a reducer's first stage); keeps every
/// radius `m z / 2` well inside the range of `f64`.
pub const MAX_TEETH: u32 = 10_000;

/// Most planets, and so most crankshafts, a reducer may have (RV reducers have 2 or 3); the
/// bound keeps the per-crank work and memory of a run finite for any accepted input.
pub const MAX_PLANETS: u32 = 64;

/// Check a crankshaft count (`cranks` of a scene, with or without a first stage): between 1
/// and [`MAX_PLANETS`]. Errors (`RvdynError::Geometry`) name the count and the range.
pub fn check_crank_count(cranks: u32) -> Result<()> {
    if (1..=MAX_PLANETS).contains(&cranks) {
        Ok(())
    } else {
        Err(RvdynError::Geometry(format!(
            "cranks must be from 1 to {MAX_PLANETS}, got {cranks} (RV reducers have 2 or 3)"
        )))
    }
}

/// A sun/planet involute stage (SI units).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InvoluteStage {
    /// Sun teeth `z1`.
    pub z_sun: u32,
    /// Teeth of each planet `z2`.
    pub z_planet: u32,
    /// Number of planets (equally spaced).
    pub planets: u32,
    /// Module `m` \[m\].
    pub module: f64,
    /// Pressure angle `alpha` \[rad\].
    pub pressure_angle: f64,
    /// Face width \[m\].
    pub face_width: f64,
    /// Total backlash of one mesh, measured along the line of action \[m\].
    #[serde(default)]
    pub backlash: f64,
}

impl InvoluteStage {
    /// Build a validated stage without backlash: teeth, planets, module \[m\], pressure angle
    /// \[rad\], face width \[m\].
    ///
    /// Errors as [`InvoluteStage::validate`].
    pub fn new(
        z_sun: u32,
        z_planet: u32,
        planets: u32,
        module: f64,
        pressure_angle: f64,
        face_width: f64,
    ) -> Result<Self> {
        let stage = Self {
            z_sun,
            z_planet,
            planets,
            module,
            pressure_angle,
            face_width,
            backlash: 0.0,
        };
        stage.validate()?;
        Ok(stage)
    }

    /// The same stage with a total backlash \[m\] along the line of action.
    ///
    /// Errors (`Parameter`) for a negative or non-finite backlash.
    pub fn with_backlash(mut self, backlash: f64) -> Result<Self> {
        require_non_negative("gear backlash", backlash, "m")?;
        self.backlash = backlash;
        Ok(self)
    }

    /// Check the stage; returns `Ok(())` or the first rule broken.
    ///
    /// `Parameter`: module, face width not > 0; pressure angle outside (0, 45 deg); negative
    /// backlash. `Geometry`: fewer than 5 teeth, no planet, neighbouring planets whose tip
    /// circles overlap (`2 a sin(pi/planets) <= 2 r_a,planet`), involute interference (a tip
    /// circle reaching past the other gear's base tangent point: `sqrt(ra^2 - rb^2) - r sin
    /// alpha` above `r_other sin alpha`), contact ratio below 1.
    pub fn validate(&self) -> Result<()> {
        require_length("gear module", self.module)?;
        require_length("gear face width", self.face_width)?;
        require_non_negative("gear backlash", self.backlash, "m")?;
        let alpha = self.pressure_angle;
        if !(alpha.is_finite() && alpha > 0.0 && alpha < PI / 4.0) {
            return Err(RvdynError::Parameter(format!(
                "pressure angle must be in (0, 45) deg, got {} deg; 20 deg is standard",
                num(alpha.to_degrees())
            )));
        }
        if self.z_sun < MIN_TEETH || self.z_planet < MIN_TEETH {
            return Err(RvdynError::Geometry(format!(
                "gear tooth counts must be at least {MIN_TEETH}, got z_sun = {}, z_planet = {} \
                 (below about 17 teeth at 20 deg a generated gear is undercut)",
                self.z_sun, self.z_planet
            )));
        }
        if self.z_sun > MAX_TEETH || self.z_planet > MAX_TEETH {
            return Err(RvdynError::Geometry(format!(
                "gear tooth counts must be at most {MAX_TEETH}, got z_sun = {}, z_planet = {}",
                self.z_sun, self.z_planet
            )));
        }
        if self.planets > MAX_PLANETS {
            return Err(RvdynError::Geometry(format!(
                "at most {MAX_PLANETS} planets are supported, got {}",
                self.planets
            )));
        }
        if self.planets < 1 {
            return Err(RvdynError::Geometry(
                "the involute stage needs at least 1 planet, got 0".to_string(),
            ));
        }
        self.check_planet_spacing()?;
        self.check_interference()?;
        let eps = self.contact_ratio();
        if eps < 1.0 {
            return Err(RvdynError::Geometry(format!(
                "sun/planet contact ratio {eps:.3} < 1 (z_sun = {}, z_planet = {}, pressure angle \
                 {:.1} deg): one tooth pair leaves the mesh before the next engages, so the \
                 gears cannot transmit continuously; use more teeth or a smaller pressure angle",
                self.z_sun,
                self.z_planet,
                alpha.to_degrees()
            )));
        }
        Ok(())
    }

    /// Involute interference: a tip circle that reaches past the other gear's base tangent
    /// point would contact it below its base circle, where a standard gear has no involute
    /// (it is undercut when generated). The model has only full involutes, so such a pair is
    /// refused rather than given a path of contact the real, undercut teeth do not have.
    fn check_interference(&self) -> Result<()> {
        let (recess, approach) = self.path_parts();
        let sin_a = self.pressure_angle.sin();
        let (cap_recess, cap_approach) = (
            self.planet_pitch_radius() * sin_a,
            self.sun_pitch_radius() * sin_a,
        );
        if recess <= cap_recess && approach <= cap_approach {
            return Ok(());
        }
        let (small, z_small, z_other) = if approach > cap_approach {
            ("sun", self.z_sun, self.z_planet)
        } else {
            ("planet", self.z_planet, self.z_sun)
        };
        // The pair clears both tips: the fewest teeth of the interfering gear that do (with
        // the other as it is), else of the other gear (a small one cannot be cleared).
        let clear = |z_sun: u32, z_planet: u32| {
            let s = Self {
                z_sun,
                z_planet,
                ..*self
            };
            let (r, a) = s.path_parts();
            r <= s.planet_pitch_radius() * sin_a && a <= s.sun_pitch_radius() * sin_a
        };
        let other = if small == "sun" { "planet" } else { "sun" };
        let pair = |z_named: u32, named_is_sun: bool, z_fixed: u32| {
            if named_is_sun {
                clear(z_named, z_fixed)
            } else {
                clear(z_fixed, z_named)
            }
        };
        let remedy = if let Some(z) =
            (z_small..=MAX_TEETH).find(|&z| pair(z, small == "sun", z_other))
        {
            format!("at least {z} {small} teeth")
        } else if let Some(z) = (z_other..=MAX_TEETH).find(|&z| pair(z, other == "sun", z_small)) {
            format!(
                "at least {z} {other} teeth (no number of {small} teeth clears a {z_other}-tooth \
                 {other})"
            )
        } else {
            "more teeth".to_string()
        };
        // Generation by a standard rack (ISO 53) undercuts a gear of fewer than 2 / sin^2(alpha)
        // teeth (Niemann & Winter; 17.1 at 20 deg), which this tip rule does not see: a
        // 15-tooth sun passes it while a 42-tooth planet's tip reaches into its undercut.
        let undercut_free = (2.0 / (sin_a * sin_a)).ceil();
        Err(RvdynError::Geometry(format!(
            "involute interference: the tip of the {z_other}-tooth {other} reaches below the base \
             circle of the {z_small}-tooth {small} (pressure angle {:.1} deg), where a standard \
             gear has no involute (it is undercut); rvdyn models unshifted full involutes only: \
             use {remedy} or a larger pressure angle (a gear cut by a standard rack is free of \
             undercut from {undercut_free} teeth, 2 / sin^2 of the pressure angle)",
            self.pressure_angle.to_degrees(),
        )))
    }

    /// The two parts of the path of contact from the pitch point, uncapped \[m\]: recess (to
    /// the sun's tip circle) and approach (to the planet's).
    fn path_parts(&self) -> (f64, f64) {
        let sin_a = self.pressure_angle.sin();
        let part = |ra: f64, rb: f64, r: f64| (ra * ra - rb * rb).sqrt() - r * sin_a;
        (
            part(
                self.sun_tip_radius(),
                self.sun_base_radius(),
                self.sun_pitch_radius(),
            ),
            part(
                self.planet_tip_radius(),
                self.planet_base_radius(),
                self.planet_pitch_radius(),
            ),
        )
    }

    fn check_planet_spacing(&self) -> Result<()> {
        if self.planets < 2 {
            return Ok(());
        }
        let a = self.centre_distance();
        let ra = self.planet_tip_radius();
        let spacing = 2.0 * a * (PI / f64::from(self.planets)).sin();
        if spacing <= 2.0 * ra {
            // Largest n with sin(pi/n) > ra/a (ra < a always for z_sun > 2).
            let max_planets = (PI / (ra / a).asin()).ceil() as u32 - 1;
            return Err(RvdynError::Geometry(format!(
                "planets collide: neighbouring planet centres are 2 a sin(pi/planets) = {:.3} mm \
                 apart but their tip circles need more than 2 r_a = {:.3} mm ({} planets of {} \
                 teeth around a {}-tooth sun); use at most {max_planets} planets",
                spacing * 1e3,
                2.0 * ra * 1e3,
                self.planets,
                self.z_planet,
                self.z_sun
            )));
        }
        Ok(())
    }

    /// Sun pitch radius `m z1 / 2` \[m\].
    pub fn sun_pitch_radius(&self) -> f64 {
        0.5 * self.module * f64::from(self.z_sun)
    }

    /// Planet pitch radius `m z2 / 2` \[m\].
    pub fn planet_pitch_radius(&self) -> f64 {
        0.5 * self.module * f64::from(self.z_planet)
    }

    /// Sun base radius `r1 cos(alpha)` \[m\].
    pub fn sun_base_radius(&self) -> f64 {
        self.sun_pitch_radius() * self.pressure_angle.cos()
    }

    /// Planet base radius `r2 cos(alpha)` \[m\].
    pub fn planet_base_radius(&self) -> f64 {
        self.planet_pitch_radius() * self.pressure_angle.cos()
    }

    /// Centre distance `a = r1 + r2` \[m\], which is also the crank circle radius.
    pub fn centre_distance(&self) -> f64 {
        self.sun_pitch_radius() + self.planet_pitch_radius()
    }

    /// Addendum \[m\]: equal to the module (standard full depth).
    pub fn addendum(&self) -> f64 {
        self.module
    }

    /// Sun tip radius `r1 + m` \[m\].
    pub fn sun_tip_radius(&self) -> f64 {
        self.sun_pitch_radius() + self.addendum()
    }

    /// Planet tip radius `r2 + m` \[m\].
    pub fn planet_tip_radius(&self) -> f64 {
        self.planet_pitch_radius() + self.addendum()
    }

    /// Length of the path of contact along the line of action \[m\].
    ///
    /// Returns `[sqrt(ra1^2 - rb1^2) - r1 sin(alpha)] + [sqrt(ra2^2 - rb2^2) - r2 sin(alpha)]`
    /// (the standard `sqrt(ra1^2-rb1^2) + sqrt(ra2^2-rb2^2) - a sin(alpha)`), except that each
    /// part is capped at the distance from the pitch point to the other gear's base tangent
    /// point (`r2 sin(alpha)`, `r1 sin(alpha)`): the involute ends at the base circle, so
    /// contact beyond it is interference (small tooth counts), not transmission.
    pub fn line_of_action_length(&self) -> f64 {
        let sin_a = self.pressure_angle.sin();
        let part = |ra: f64, rb: f64, r: f64| (ra * ra - rb * rb).sqrt() - r * sin_a;
        let recess = part(
            self.sun_tip_radius(),
            self.sun_base_radius(),
            self.sun_pitch_radius(),
        );
        let approach = part(
            self.planet_tip_radius(),
            self.planet_base_radius(),
            self.planet_pitch_radius(),
        );
        recess.min(self.planet_pitch_radius() * sin_a)
            + approach.min(self.sun_pitch_radius() * sin_a)
    }

    /// Transverse contact ratio [-]: path of contact over base pitch `pi m cos(alpha)`.
    ///
    /// Returns the mean number of tooth pairs in mesh (1.63 for the paper's stage).
    pub fn contact_ratio(&self) -> f64 {
        self.line_of_action_length() / (PI * self.module * self.pressure_angle.cos())
    }

    /// Angles of the planet centres about the axis \[rad\]: `2 pi k / planets`, `k = 0..planets`,
    /// planet 0 on +x, in the carrier frame.
    pub fn planet_angles(&self) -> Vec<f64> {
        let n = f64::from(self.planets);
        (0..self.planets)
            .map(|k| 2.0 * PI * f64::from(k) / n)
            .collect()
    }

    /// Fixed-carrier ratio of the stage (paper eq. 1) [-]:
    /// `(w_sun - w_carrier) / (w_planet - w_carrier) = -z_planet / z_sun`.
    ///
    /// Negative: an external pair turns in opposite directions relative to the carrier. This
    /// is not the overall reducer ratio (see `kinematics::transmission_ratio`).
    pub fn stage_ratio(&self) -> f64 {
        -f64::from(self.z_planet) / f64::from(self.z_sun)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::close;

    fn paper() -> InvoluteStage {
        InvoluteStage::new(18, 42, 3, 0.003, 20f64.to_radians(), 0.030).unwrap()
    }

    #[test]
    fn paper_stage_radii() {
        let s = paper();
        assert!(close(s.sun_pitch_radius(), 0.027, 1e-14));
        assert!(close(s.planet_pitch_radius(), 0.063, 1e-14));
        assert!(close(s.centre_distance(), 0.090, 1e-14));
        // cos 20 deg = 0.9396926: 27 * 0.9396926 = 25.3717 mm, 63 * 0.9396926 = 59.2006 mm.
        assert!((s.sun_base_radius() - 0.025_371_7).abs() < 1e-7);
        assert!((s.planet_base_radius() - 0.059_200_6).abs() < 1e-7);
        assert!(close(s.sun_tip_radius(), 0.030, 1e-14));
        assert!(close(s.planet_tip_radius(), 0.066, 1e-14));
        assert_eq!(s.addendum(), 0.003);
        assert!(close(s.stage_ratio(), -42.0 / 18.0, 1e-15));
    }

    #[test]
    fn paper_stage_contact_ratio_by_hand() {
        // mm: sqrt(30^2 - 25.3717^2) = sqrt(900 - 643.724) = 16.0086;
        // sqrt(66^2 - 59.2006^2) = sqrt(4356 - 3504.71) = 29.1769; a sin(alpha) =
        // 90 * 0.3420201 = 30.7818. Path = 16.0086 + 29.1769 - 30.7818 = 14.4037 mm (neither
        // part reaches its interference cap: 6.7742 < 21.5473 and 7.6296 < 9.2345).
        // Base pitch = pi * 3 * 0.9396926 = 8.8564 mm. Contact ratio = 14.4037/8.8564 = 1.6264.
        let s = paper();
        assert!((s.line_of_action_length() - 0.014_403_7).abs() < 2e-7);
        assert!(
            (s.contact_ratio() - 1.6264).abs() < 2e-4,
            "{}",
            s.contact_ratio()
        );
    }

    #[test]
    fn planet_angles_equally_spaced() {
        let a = paper().planet_angles();
        assert_eq!(a.len(), 3);
        assert_eq!(a[0], 0.0);
        assert!(close(a[1], 2.0 * PI / 3.0, 1e-15));
        assert!(close(a[2], 4.0 * PI / 3.0, 1e-15));
    }

    #[test]
    fn colliding_planets_are_rejected() {
        // 2 * 90 * sin(pi/8) = 68.9 mm < 2 * 66 = 132 mm.
        let e = InvoluteStage::new(18, 42, 8, 0.003, 20f64.to_radians(), 0.03).unwrap_err();
        assert!(matches!(e, RvdynError::Geometry(_)));
        assert!(e.to_string().contains("planets collide"), "{e}");
        // sin(pi/n) > 66/90 = 0.7333 -> pi/n > 0.8230 -> n <= 3: 4 planets collide already.
        assert!(e.to_string().contains("at most 3 planets"), "{e}");
        assert!(InvoluteStage::new(18, 42, 4, 0.003, 20f64.to_radians(), 0.03).is_err());
        assert!(InvoluteStage::new(18, 42, 1, 0.003, 20f64.to_radians(), 0.03).is_ok());
    }

    #[test]
    fn contact_ratio_below_one_is_rejected() {
        // z 5/5, 20 deg, m = 1: r = 2.5, rb = 2.34923, ra = 3.5. Each part
        // sqrt(12.25 - 5.51889) - 2.5 sin 20 = 2.59444 - 0.85505 = 1.73939 exceeds the cap
        // 0.85505 (interference), so the path is 1.71010 and the ratio 1.71010 / 2.95213 = 0.579.
        let s = InvoluteStage {
            z_sun: 5,
            z_planet: 5,
            planets: 1,
            module: 0.001,
            pressure_angle: 20f64.to_radians(),
            face_width: 0.01,
            backlash: 0.0,
        };
        assert!(
            (s.contact_ratio() - 0.5793).abs() < 1e-3,
            "{}",
            s.contact_ratio()
        );
        // Each tip reaches past the other's base tangent point: refused as interference,
        // which every standard pair with a contact ratio below 1 has (a search of 5-59 by
        // 5-199 teeth at 0.1-44.9 deg found none without it).
        let e = s.validate().unwrap_err();
        assert!(e.to_string().contains("involute interference"), "{e}");
    }

    #[test]
    fn interference_is_refused_with_the_teeth_that_avoid_it() {
        let alpha = 20f64.to_radians();
        // 42-tooth planet at 20 deg: its tip part sqrt(22^2 - 19.734^2) - 21 sin 20 = 2.543 m
        // (module 1) must not exceed r1 sin 20 = 0.171 z1, so z1 >= 14.87.
        let e = InvoluteStage::new(14, 42, 1, 0.003, alpha, 0.03).unwrap_err();
        assert!(matches!(e, RvdynError::Geometry(_)), "{e}");
        assert!(
            e.to_string().contains("at least 15 sun teeth")
                && e.to_string().contains("42-tooth planet"),
            "{e}"
        );
        assert!(InvoluteStage::new(15, 42, 1, 0.003, alpha, 0.03).is_ok());
        // A larger pressure angle clears it.
        assert!(InvoluteStage::new(14, 42, 1, 0.003, 25f64.to_radians(), 0.03).is_ok());
    }

    #[test]
    fn counts_are_bounded() {
        assert!(check_crank_count(0).is_err());
        assert!(check_crank_count(3).is_ok());
        let e = check_crank_count(u32::MAX).unwrap_err().to_string();
        assert!(e.contains("from 1 to 64"), "{e}");
        // 2**32 - 1 planets around a huge sun passed the spacing rule before.
        assert!(InvoluteStage::new(u32::MAX, 5, u32::MAX, 3e-3, 0.35, 0.03).is_err());
        assert!(InvoluteStage::new(18, 42, MAX_PLANETS + 1, 3e-3, 0.35, 0.03).is_err());
        assert!(InvoluteStage::new(18, 42, 3, 1e300, 0.35, 0.03).is_err());
    }

    #[test]
    fn parameter_errors() {
        let deg20 = 20f64.to_radians();
        assert!(InvoluteStage::new(4, 42, 3, 0.003, deg20, 0.03).is_err());
        assert!(InvoluteStage::new(18, 42, 0, 0.003, deg20, 0.03).is_err());
        assert!(InvoluteStage::new(18, 42, 3, 0.0, deg20, 0.03).is_err());
        assert!(InvoluteStage::new(18, 42, 3, f64::NAN, deg20, 0.03).is_err());
        assert!(InvoluteStage::new(18, 42, 3, 0.003, 0.0, 0.03).is_err());
        assert!(InvoluteStage::new(18, 42, 3, 0.003, PI / 4.0, 0.03).is_err());
        assert!(InvoluteStage::new(18, 42, 3, 0.003, deg20, 0.0).is_err());
        assert!(paper().with_backlash(-1e-6).is_err());
        let b = paper().with_backlash(50e-6).unwrap();
        assert_eq!(b.backlash, 50e-6);
        assert!(b.validate().is_ok());
    }
}
