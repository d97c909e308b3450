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
}

impl ProfileSeed {
    pub(crate) fn empty() -> Self {
        Self {
            polyline: None,
            dphi: 0.0,
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
