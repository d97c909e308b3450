//! Mass properties of the reducer bodies from their geometry (steel by default).
//!
//! The paper gives no masses; these simple solids are the default scene's assumptions
//! (design.md section 7), each stated where it is built.

use crate::error::{Result, RvdynError, require_positive};
use crate::geometry::cycloid::CycloidGeometry;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Density of steel [kg/m^3].
pub const STEEL_DENSITY: f64 = 7850.0;

/// Mass [kg] and moment of inertia about the body's own axis [kg m^2].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MassProperties {
    /// Mass [kg].
    pub mass: f64,
    /// Moment of inertia about the body's own axis [kg m^2].
    pub inertia: f64,
}

/// Holes cut through a cycloid disc (radii and hole-circle radius in m).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DiscHoles {
    /// Central bore radius [m].
    pub bore_radius: f64,
    /// Radius of the circle the crank and pillar holes sit on [m].
    pub hole_circle_radius: f64,
    /// Number of crank (eccentric bearing) holes and their radius [m].
    pub crank_holes: u32,
    /// Radius of each crank hole [m].
    pub crank_hole_radius: f64,
    /// Number of pillar holes (between the crank holes) and their radius [m].
    pub pillar_holes: u32,
    /// Radius of each pillar hole [m].
    pub pillar_hole_radius: f64,
}

impl DiscHoles {
    /// The default disc (design.md section 7): 40 mm bore radius, 3 crank holes r = 25 mm and
    /// 3 pillar holes r = 20 mm on a 90 mm circle.
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

/// Mass and polar moment of inertia about its centre of a cycloid disc: the exact profile
/// (Green's theorem, exact to round-off) minus the bore and the holes, times face width and
/// density.
pub fn disc_mass_properties(
    geometry: &CycloidGeometry,
    holes: &DiscHoles,
    density: f64,
) -> Result<MassProperties> {
    require_positive("density", density, "kg/m^3")?;
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
    if a.is_nan() || a <= 0.0 {
        return Err(RvdynError::Geometry(format!(
            "the disc holes remove all material (remaining area {a:.3e} m^2)"
        )));
    }
    let t = geometry.params().face_width * density;
    Ok(MassProperties {
        mass: a * t,
        inertia: j * t,
    })
}

/// Solid cylinder of radius `r` [m] and length `l` [m]: mass and inertia about its axis.
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
    use crate::geometry::cycloid::tests::paper_params;

    #[test]
    fn default_disc_matches_the_design_estimate() {
        let g = CycloidGeometry::new(paper_params()).unwrap();
        let mp = disc_mass_properties(&g, &DiscHoles::paper(), STEEL_DENSITY).unwrap();
        // design.md section 7: about 14.7 kg and 0.163 kg m^2.
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
    fn cylinder_formula() {
        let c = solid_cylinder(0.1, 0.2, 1000.0);
        assert!((c.mass - PI * 0.01 * 0.2 * 1000.0).abs() < 1e-12);
        assert!((c.inertia - 0.5 * c.mass * 0.01).abs() < 1e-15);
    }
}
