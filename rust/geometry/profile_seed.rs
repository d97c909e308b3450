//! Global seed for gap queries: a parry2d polyline of the exact profile with its BVH.
//!
//! The polyline is never the answer (its chord error is micrometres); it only tells which
//! stretch of the curve is nearest to a pin, so that Newton on the exact curve parameter starts
//! in the right basin, including on the concave root where local minima exist.

use crate::geometry::cycloid::CycloidGeometry;
use parry2d_f64::math::Vector;
use parry2d_f64::query::PointQueryWithLocation;
use parry2d_f64::shape::{Polyline, SegmentPointLocation};
use std::f64::consts::PI;

/// A closed, counter-clockwise polyline of the unrotated profile and the curve parameter of
/// each vertex (uniform in `phi`).
#[derive(Clone)]
pub struct ProfileSeed {
    polyline: Option<Polyline>,
    dphi: f64,
    pub(crate) curve: CurveConsts,
}

/// Constants of the pin-centre curve `C(phi) = R u - e v`, `u = exp(i phi)`,
/// `v = exp(i zp phi)`, whose k-th derivative is `i^k (R u - e zp^k v)`; kept here so that the
/// gap's Newton iteration does not recompute them per query.
#[derive(Debug, Clone, Copy)]
pub(crate) struct CurveConsts {
    pub zp: u32,
    /// Generating radius `R = rp + d_rp` [m].
    pub r: f64,
    /// `e zp^k` for k = 0..=4 [m].
    pub ez: [f64; 5],
    /// Lobe pitch `2 pi / zc` [rad]; the roots are at its multiples.
    pub pitch: f64,
    /// Pin centres farther outside `C` than this [m] may have more than one local foot (they
    /// can lie beyond the evolute of a concave root); half the smallest concave radius of
    /// curvature of `C`, infinite if `C` has no concave part.
    pub ambiguity_distance: f64,
}

impl CurveConsts {
    fn of(geometry: &CycloidGeometry) -> Self {
        let p = geometry.params();
        let zp = f64::from(p.pins);
        let r = p.pin_circle_radius + p.d_rp;
        let mut ez = [p.eccentricity; 5];
        for k in 1..5 {
            ez[k] = ez[k - 1] * zp;
        }
        // Curvature of C, (C' x C'')/|C'|^3, against c = cos(zc phi):
        // kappa = [1 + zp K1^2 - K1 (1 + zp) c]/(R S^3), S^2 = 1 + K1^2 - 2 K1 c. Where it is
        // negative both factors make |kappa| largest at the root c = 1:
        // rho = R (1 - K1)^2 / (zp K1 - 1) when zp K1 > 1 (0.72 mm for the paper's disc).
        let k1 = geometry.k1();
        let concave = if zp * k1 > 1.0 {
            r * (1.0 - k1) * (1.0 - k1) / (zp * k1 - 1.0)
        } else {
            f64::INFINITY
        };
        Self {
            zp: p.pins,
            r,
            ez,
            pitch: 2.0 * PI / (zp - 1.0),
            ambiguity_distance: 0.5 * concave,
        }
    }

    /// Unset (a geometry being built; never queried).
    fn unset() -> Self {
        Self {
            zp: 0,
            r: f64::NAN,
            ez: [f64::NAN; 5],
            pitch: f64::NAN,
            ambiguity_distance: f64::NAN,
        }
    }
}

impl ProfileSeed {
    pub(crate) fn empty() -> Self {
        Self {
            polyline: None,
            dphi: 0.0,
            curve: CurveConsts::unset(),
        }
    }

    /// Sample the profile with `per_lobe` vertices per lobe.
    pub(crate) fn build(geometry: &CycloidGeometry, per_lobe: usize) -> Self {
        let n = per_lobe.max(8) * geometry.lobes() as usize;
        let dphi = 2.0 * PI / n as f64;
        let vertices: Vec<Vector> = (0..n)
            .map(|i| {
                let p = geometry.unrotated_profile_point(i as f64 * dphi);
                Vector::new(p[0], p[1])
            })
            .collect();
        let indices: Vec<[u32; 2]> = (0..n as u32).map(|i| [i, (i + 1) % n as u32]).collect();
        Self {
            polyline: Some(Polyline::new(vertices, Some(indices))),
            dphi,
            curve: CurveConsts::of(geometry),
        }
    }

    /// Curve parameter of the polyline point nearest to `point` (unrotated disc frame), or
    /// `None` if the point is not finite.
    pub(crate) fn seed(&self, point: [f64; 2]) -> Option<f64> {
        let poly = self.polyline.as_ref()?;
        if !(point[0].is_finite() && point[1].is_finite()) {
            return None;
        }
        let (_, (seg, loc)) =
            poly.project_local_point_and_get_location(Vector::new(point[0], point[1]), false);
        let t = match loc {
            SegmentPointLocation::OnVertex(i) => f64::from(i),
            SegmentPointLocation::OnEdge([_, v]) => v,
        };
        Some((f64::from(seg) + t) * self.dphi)
    }

    /// Number of polyline vertices.
    pub fn len(&self) -> usize {
        self.polyline.as_ref().map_or(0, |p| p.vertices().len())
    }

    /// True if the seed has no polyline (only while a geometry is being built).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}
