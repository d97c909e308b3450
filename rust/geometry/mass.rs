//! Mass properties of the reducer bodies from their geometry (steel by default).
//!
//! The paper gives no masses; these simple solids are the default scene's assumptions
//! (docs/model.md#default-scene), each stated where it is built.

use crate::error::{Result, RvdynError, num, require_positive};
use crate::geometry::cycloid::CycloidGeometry;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Density of steel [kg/m^3].
pub const STEEL_DENSITY: f64 = 7850.0;

/// Largest density accepted [kg/m^3]: above every solid (osmium, the densest element, is
/// 22 590 kg/m^3); keeps masses and inertias of any accepted geometry finite.
pub const MAX_DENSITY: f64 = 1e5;

/// `density` if it is finite, positive and at most [`MAX_DENSITY`] [kg/m^3]; else
/// `RvdynError::Parameter` naming the rule.
pub fn require_density(density: f64) -> Result<f64> {
    require_positive("density", density, "kg/m^3")?;
    if density <= MAX_DENSITY {
        Ok(density)
    } else {
        Err(RvdynError::Parameter(format!(
            "density {} kg/m^3 is above {} kg/m^3, denser than any solid (steel is 7850)",
            num(density),
            num(MAX_DENSITY)
        )))
    }
}

/// Mass \[kg\] and moment of inertia about the body's own axis [kg m^2].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MassProperties {
    /// Mass \[kg\].
    pub mass: f64,
    /// Moment of inertia about the body's own axis [kg m^2].
    pub inertia: f64,
}

/// Holes cut through a cycloid disc (radii and hole-circle radius in m).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DiscHoles {
    /// Central bore radius \[m\].
    pub bore_radius: f64,
    /// Radius of the circle the crank and pillar holes sit on \[m\].
    pub hole_circle_radius: f64,
    /// Number of crank (eccentric bearing) holes and their radius \[m\].
    pub crank_holes: u32,
    /// Radius of each crank hole \[m\].
    pub crank_hole_radius: f64,
    /// Number of pillar holes (between the crank holes) and their radius \[m\].
    pub pillar_holes: u32,
    /// Radius of each pillar hole \[m\].
    pub pillar_hole_radius: f64,
}

impl DiscHoles {
    /// The default disc (docs/model.md#default-scene): 40 mm bore radius, 3 crank holes
    /// r = 25 mm and 3 pillar holes r = 20 mm on a 90 mm circle.
    pub fn paper() -> Self {
        Self {
            bore_radius: 0.040,
            hole_circle_radius: 0.090,
            crank_holes: 3,
            crank_hole_radius: 0.025,
            pillar_holes: 3,
            pillar_hole_radius: 0.020,
        }
    }
}

impl DiscHoles {
    /// Check that the holes lie inside the disc material: the bore inside the hole circle's
    /// inner edge, the holes' outer edge inside the tooth root circle `rp + d_rp - e - rrp -
    /// d_rrp` (the profile's smallest radius), and neighbouring holes apart (the crank and
    /// pillar holes alternate, equally spaced). Errors (`RvdynError::Geometry`) name the rule
    /// and ask for explicit mass properties.
    pub fn check_fit(&self, geometry: &CycloidGeometry) -> Result<()> {
        let p = geometry.params();
        let root = p.pin_circle_radius + p.d_rp - p.eccentricity - p.pin_radius - p.d_rrp;
        let mut radii = Vec::new();
        if self.crank_holes > 0 {
            radii.push(self.crank_hole_radius);
        }
        if self.pillar_holes > 0 {
            radii.push(self.pillar_hole_radius);
        }
        let largest = radii.iter().copied().fold(0.0, f64::max);
        let d = self.hole_circle_radius;
        let n = self.crank_holes + self.pillar_holes;
        let pattern = format!(
            "the hole pattern ({} m bore radius; {} crank holes of radius {} m and {} pillar holes \
             of radius {} m on a {} m circle)",
            num(self.bore_radius),
            self.crank_holes,
            num(self.crank_hole_radius),
            self.pillar_holes,
            num(self.pillar_hole_radius),
            num(d)
        );
        let advice = "give the disc's mass and inertia explicitly (scene field inertias.disc)";
        let fail = |rule: String| {
            Err(RvdynError::Geometry(format!(
                "{pattern} does not fit in this disc: {rule}; {advice}"
            )))
        };
        if self.bore_radius >= root {
            return fail(format!(
                "the bore reaches r = {} m, beyond the tooth root circle r = {} m",
                num(self.bore_radius),
                num(root)
            ));
        }
        if n == 0 {
            return Ok(());
        }
        if d + largest >= root {
            return fail(format!(
                "the holes reach r = {} m, beyond the tooth root circle r = {} m",
                num(d + largest),
                num(root)
            ));
        }
        if d - largest <= self.bore_radius {
            return fail(format!(
                "the holes reach in to r = {} m, into the bore (radius {} m)",
                num(d - largest),
                num(self.bore_radius)
            ));
        }
        if n > 1 {
            let gap = 2.0 * d * (PI / f64::from(n)).sin();
            let need = if self.crank_holes > 0 && self.pillar_holes > 0 {
                self.crank_hole_radius + self.pillar_hole_radius
            } else {
                2.0 * largest
            };
            if gap <= need {
                return fail(format!(
                    "neighbouring holes are {} m apart (centre to centre) but their radii add \
                     up to {} m",
                    num(gap),
                    num(need)
                ));
            }
        }
        Ok(())
    }
}

/// Mass and polar moment of inertia about its centre of a cycloid disc: the exact profile
/// (Green's theorem, exact to round-off) minus the bore and the holes, times face width and
/// density.
///
/// Errors: `Parameter` for a density that is not in `(0, MAX_DENSITY]`; `Geometry` when the
/// holes do not fit in the disc ([`DiscHoles::check_fit`]), so the mass and inertia are always
/// positive.
pub fn disc_mass_properties(
    geometry: &CycloidGeometry,
    holes: &DiscHoles,
    density: f64,
) -> Result<MassProperties> {
    require_density(density)?;
    holes.check_fit(geometry)?;
    let (area, polar) = geometry.profile_area_moments(128);
    let circle = |r: f64, d: f64| (PI * r * r, PI * r * r * r * r / 2.0 + PI * r * r * d * d);
    let mut a = area;
    let mut j = polar;
    let mut cut = |(ca, cj): (f64, f64)| {
        a -= ca;
        j -= cj;
    };
    cut(circle(holes.bore_radius, 0.0));
    for _ in 0..holes.crank_holes {
        cut(circle(holes.crank_hole_radius, holes.hole_circle_radius));
    }
    for _ in 0..holes.pillar_holes {
        cut(circle(holes.pillar_hole_radius, holes.hole_circle_radius));
    }
    let t = geometry.params().face_width * density;
    let mp = MassProperties {
        mass: a * t,
        inertia: j * t,
    };
    // Holes inside the material leave a positive area and inertia; this guards the rule.
    if !(mp.mass.is_finite() && mp.mass > 0.0 && mp.inertia.is_finite() && mp.inertia > 0.0) {
        return Err(RvdynError::Geometry(format!(
            "the disc's mass properties are not positive and finite (area {} m^2, mass {} kg, \
             inertia {} kg m^2); give them explicitly (scene field inertias.disc)",
            num(a),
            num(mp.mass),
            num(mp.inertia)
        )));
    }
    Ok(mp)
}

/// Solid cylinder of radius `r` \[m\] and length `l` \[m\]: mass and inertia about its axis.
pub fn solid_cylinder(r: f64, l: f64, density: f64) -> MassProperties {
    let m = density * PI * r * r * l;
    MassProperties {
        mass: m,
        inertia: 0.5 * m * r * r,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::cycloid::CycloidParams;
    use crate::geometry::cycloid::tests::paper_params;

    #[test]
    fn default_disc_matches_the_design_estimate() {
        let g = CycloidGeometry::new(paper_params()).unwrap();
        let mp = disc_mass_properties(&g, &DiscHoles::paper(), STEEL_DENSITY).unwrap();
        // Plausibility against a hand estimate, a solid disc of radius rp - rrp less the same
        // holes: 14.72 kg and 0.1628 kg m^2 (the exact value, 14.80 kg and 0.1649 kg m^2, is
        // docs/model.md#default-scene's and tests/test_geometry.py checks it to 1e-8).
        assert!((mp.mass - 14.7).abs() < 0.15, "{mp:?}");
        assert!((mp.inertia - 0.163).abs() < 0.004, "{mp:?}");
    }

    #[test]
    fn profile_area_is_between_root_and_tip_circles() {
        let g = CycloidGeometry::new(paper_params()).unwrap();
        let (a, _) = g.profile_area_moments(128);
        assert!(a > PI * 0.1355f64.powi(2) && a < PI * 0.1445f64.powi(2));
        // Converged in the sampling.
        let (a2, _) = g.profile_area_moments(1024);
        assert!((a - a2).abs() / a < 1e-12, "{a} {a2}");
    }

    #[test]
    fn holes_that_do_not_fit_are_an_error_never_a_negative_inertia() {
        // A valid disc with rp = 80 mm: root circle 72.3 mm, the default holes reach 115 mm.
        // Before the fit rule the computed polar inertia was -0.00558 kg m^2.
        let small = CycloidParams {
            pins: 24,
            eccentricity: 0.03 * 0.08,
            pin_circle_radius: 0.08,
            pin_radius: 0.08 / 15.0,
            face_width: 0.02,
            d_rp: 0.0,
            d_rrp: 0.0,
            d_delta: 0.0,
        };
        let g = CycloidGeometry::new(small).unwrap();
        let e = disc_mass_properties(&g, &DiscHoles::paper(), STEEL_DENSITY).unwrap_err();
        assert!(matches!(e, RvdynError::Geometry(_)), "{e}");
        assert!(e.to_string().contains("does not fit") && e.to_string().contains("inertias.disc"));
        // The same disc without holes: positive, and the solid disc's closed form bounds it.
        let none = DiscHoles {
            bore_radius: 0.0,
            crank_holes: 0,
            pillar_holes: 0,
            ..DiscHoles::paper()
        };
        let mp = disc_mass_properties(&g, &none, STEEL_DENSITY).unwrap();
        let tip = 0.08 + 0.0024 - 0.08 / 15.0;
        let outer = solid_cylinder(tip, 0.02, STEEL_DENSITY);
        assert!(
            mp.mass > 0.0 && mp.mass < outer.mass && mp.inertia < outer.inertia,
            "{mp:?}"
        );
        // Every size from the smallest to the paper's: an error or a positive inertia.
        for i in 0..40 {
            let rp = 0.06 + 0.003 * f64::from(i);
            let p = CycloidParams {
                eccentricity: 0.03 * rp,
                pin_circle_radius: rp,
                pin_radius: rp / 15.0,
                ..small
            };
            let g = CycloidGeometry::new(p).unwrap();
            if let Ok(mp) = disc_mass_properties(&g, &DiscHoles::paper(), STEEL_DENSITY) {
                assert!(mp.mass > 0.0 && mp.inertia > 0.0, "rp {rp}: {mp:?}");
            }
        }
    }

    #[test]
    fn density_is_bounded() {
        let g = CycloidGeometry::new(paper_params()).unwrap();
        assert!(disc_mass_properties(&g, &DiscHoles::paper(), 1e308).is_err());
        assert!(disc_mass_properties(&g, &DiscHoles::paper(), 0.0).is_err());
        assert!(require_density(MAX_DENSITY).is_ok());
    }

    #[test]
    fn cylinder_formula() {
        let c = solid_cylinder(0.1, 0.2, 1000.0);
        assert!((c.mass - PI * 0.01 * 0.2 * 1000.0).abs() < 1e-12);
        assert!((c.inertia - 0.5 * c.mass * 0.01).abs() < 1e-15);
    }
}
