//! Global seed for gap queries: a parry2d polyline of the exact profile with its BVH.
//!
//! The polyline is never the answer (its chord error is micrometres); it only tells which
//! stretch of the curve is nearest to a pin, so that Newton on the exact curve parameter starts
//! in the right basin, including on the concave root where local minima exist. It is built at
//! the first query that needs it: a run whose warm-started queries never fail never builds it.

use crate::geometry::cycloid::CycloidGeometry;
use parry2d_f64::math::Vector;
use parry2d_f64::query::PointQueryWithLocation;
use parry2d_f64::shape::{Polyline, SegmentPointLocation};
use std::f64::consts::PI;
use std::sync::OnceLock;

/// A closed, counter-clockwise polyline of the unrotated profile and the curve parameter of
/// each vertex (uniform in `phi`), built when first queried.
#[derive(Clone)]
pub struct ProfileSeed {
    /// Vertices per lobe (0: no polyline, a geometry being built).
    per_lobe: usize,
    polyline: OnceLock<Polyline>,
    pub(crate) curve: CurveConsts,
}

/// Constants of the pin-centre curve `C(phi) = R u - e v`, `u = exp(i phi)`,
/// `v = exp(i zp phi)`, whose k-th derivative is `i^k (R u - e zp^k v)`; kept here so that the
/// gap's Newton iteration does not recompute them per query.
#[derive(Debug, Clone, Copy)]
pub(crate) struct CurveConsts {
    pub zp: u32,
    /// Generating radius `R = rp + d_rp` \[m\].
    pub r: f64,
    /// `e zp^k` for k = 0..=4 \[m\].
    pub ez: [f64; 5],
    /// Lobe pitch `2 pi / zc` \[rad\]; the roots are at its multiples.
    pub pitch: f64,
    /// Pin centres farther outside `C` than this \[m\] may have more than one local foot (they
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
            per_lobe: 0,
            polyline: OnceLock::new(),
            curve: CurveConsts::unset(),
        }
    }

    /// The seed of `geometry` with `per_lobe` vertices per lobe (at least 8), sampled at the
    /// first query.
    pub(crate) fn build(geometry: &CycloidGeometry, per_lobe: usize) -> Self {
        Self {
            per_lobe: per_lobe.max(8),
            polyline: OnceLock::new(),
            curve: CurveConsts::of(geometry),
        }
    }

    /// Parameter step between vertices \[rad\] of `geometry`'s polyline.
    fn dphi(&self, geometry: &CycloidGeometry) -> f64 {
        2.0 * PI / (self.per_lobe * geometry.lobes() as usize) as f64
    }

    /// The polyline of `geometry` (whose seed this is), sampled now if it was not yet.
    fn polyline(&self, geometry: &CycloidGeometry) -> Option<&Polyline> {
        if self.per_lobe == 0 {
            return None;
        }
        Some(self.polyline.get_or_init(|| {
            let n = self.per_lobe * geometry.lobes() as usize;
            let dphi = self.dphi(geometry);
            let vertices: Vec<Vector> = (0..n)
                .map(|i| {
                    let p = geometry.unrotated_profile_point(i as f64 * dphi);
                    Vector::new(p[0], p[1])
                })
                .collect();
            let indices: Vec<[u32; 2]> = (0..n as u32).map(|i| [i, (i + 1) % n as u32]).collect();
            Polyline::new(vertices, Some(indices))
        }))
    }

    /// Curve parameter of the polyline point nearest to `point` (unrotated disc frame) of
    /// `geometry` (whose seed this is), or `None` if the point is not finite.
    pub(crate) fn seed(&self, geometry: &CycloidGeometry, point: [f64; 2]) -> Option<f64> {
        if !(point[0].is_finite() && point[1].is_finite()) {
            return None;
        }
        let poly = self.polyline(geometry)?;
        let (_, (seg, loc)) =
            poly.project_local_point_and_get_location(Vector::new(point[0], point[1]), false);
        let t = match loc {
            SegmentPointLocation::OnVertex(i) => f64::from(i),
            SegmentPointLocation::OnEdge([_, v]) => v,
        };
        Some((f64::from(seg) + t) * self.dphi(geometry))
    }

    /// Number of polyline vertices (sampled or not yet).
    pub fn len(&self) -> usize {
        self.per_lobe * self.curve.zp.saturating_sub(1) as usize
    }

    /// True if the seed has no polyline (only while a geometry is being built).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}
