//! The scalar laws of the couplings at rest (force, stiffness, damping coefficient) and the
//! bearings' and profile errors' contributions.

use super::Dense;
use super::vec2::dot;
use crate::contact::ImpactLaw;
use crate::contact::law::MeshLaw;
use crate::dynamics::scene::ProfileError;

/// Elastic force \[N\] and its derivative [N/m] of an IMPACT contact law at penetration `pen`
/// \[m\] (the laws [`Statics::new`](super::Statics::new) accepts).
#[inline]
pub fn elastic(law: &ImpactLaw, pen: f64) -> (f64, f64) {
    let (force, stiffness, _) = law.force_and_derivatives(pen, 0.0);
    (force, stiffness)
}

/// A mesh flank's static law at one pose: `V(pen, s)` and its derivatives.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct MeshStatic {
    pub(super) force: f64,
    pub(super) stiffness: f64,
    pub(super) v_s: f64,
    pub(super) v_ps: f64,
    pub(super) v_ss: f64,
    pub(super) damping: f64,
}

/// The static law of a mesh flank at penetration `pen` \[m\] and mesh position `s` \[m\]: IMPACT
/// (no dependence on `s`) or the ISO 6336 wave, `V = k(s) pen^2 / 2`: `F = k pen`,
/// `V_s = k' pen^2 / 2`, `V_pen,s = k' pen`, `V_ss = k'' pen^2 / 2`.
#[inline]
pub(super) fn mesh_static(law: &MeshLaw, pen: f64, s: f64) -> MeshStatic {
    if pen <= 0.0 {
        return MeshStatic::default();
    }
    match law {
        MeshLaw::Impact(l) => {
            let (force, stiffness) = elastic(l, pen);
            MeshStatic {
                force,
                stiffness,
                damping: contact_damping(l, pen),
                ..MeshStatic::default()
            }
        }
        MeshLaw::Iso(m) => {
            let (k, dk, d2k) = m.wave.stiffness_slope_curvature(s);
            let force = k * pen;
            MeshStatic {
                force,
                stiffness: k,
                v_s: 0.5 * dk * pen * pen,
                v_ps: dk * pen,
                v_ss: 0.5 * d2k * pen * pen,
                damping: m.damping.rate_coefficient(force, k),
            }
        }
    }
}

/// Damping coefficient [N s/m] of an IMPACT law at penetration `pen` \[m\] (at zero rate).
#[inline]
pub fn contact_damping(law: &ImpactLaw, pen: f64) -> f64 {
    law.force_and_derivatives(pen, 0.0).2
}

/// Add `J_d^T c J_d` for a bearing with deflection Jacobian columns `cols`.
#[inline]
pub(super) fn add_bearing_damping(cm: &mut Dense, cols: &[(usize, [f64; 2])], c: [[f64; 2]; 2]) {
    for &(i, ji) in cols {
        let cj = [
            c[0][0] * ji[0] + c[0][1] * ji[1],
            c[1][0] * ji[0] + c[1][1] * ji[1],
        ];
        for &(j, jj) in cols {
            cm.add(j, i, dot(jj, cj));
        }
    }
}

/// Add a bearing's force and stiffness: deflection Jacobian columns `cols` (full index,
/// `dd/dx_i`), `g = dV/dd`, `h = hess_d V`.
#[inline]
pub(super) fn add_bearing(
    qf: &mut [f64],
    kf: &mut Dense,
    cols: &[(usize, [f64; 2])],
    g: [f64; 2],
    h: [[f64; 2]; 2],
) {
    for &(i, ji) in cols {
        qf[i] -= dot(ji, g);
        let hj = [
            h[0][0] * ji[0] + h[0][1] * ji[1],
            h[1][0] * ji[0] + h[1][1] * ji[1],
        ];
        for &(j, jj) in cols {
            kf.add(j, i, dot(jj, hj));
        }
    }
}

/// A disc profile error's offset `delta(phi)` \[m\] with its first and second derivatives
/// [m/rad, m/rad^2] (the table is piecewise linear: no second derivative between its points;
/// at a point the slope jumps and the tangent is one-sided).
pub(super) fn profile_offset_jet(pe: &ProfileError, phi: f64) -> (f64, f64, f64) {
    let (d, d1) = pe.offset(phi);
    let d2 = pe
        .harmonics
        .iter()
        .map(|h| -h[0] * h[1] * h[1] * (h[1] * phi + h[2]).cos())
        .sum();
    (d, d1, d2)
}
