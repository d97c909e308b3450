//! Classical quasi-static load sharing of an unmodified cycloid disc (Kudryavtsev; Li Lixing):
//! a reference for the dynamic pin forces (docs/validation.md).
//!
//! With rigid pins and housing and a linear contact law, a disc turning by a small angle
//! `beta` about its centre deforms pin `j` by `beta l_j`, where `l_j = rc' sin(phi_j) / S_j` is
//! the lever of the contact normal about the disc centre, `phi_j` the pin's mesh angle from the
//! eccentricity direction, `rc' = e zc` and `S = sqrt(1 + K1^2 - 2 K1 cos phi)`. The pins on the
//! loaded half (`l_j > 0`) carry `F_j = T_c l_j / sum(l^2)`, so that `sum F_j l_j = T_c`.
//!
//! Theory: docs/model.md, section "Lever arms and the classical load sharing".

use crate::error::{Result, RvdynError, require_finite};
use crate::geometry::CycloidGeometry;

/// Classical pin forces \[N\], one per pin (index j = the paper's pin j + 1), for a disc that
/// carries the torque `disc_torque` [N m] about its own centre when its centre is at crank
/// angle `crank_angle` \[rad\] (`e (cos, sin)` of it). Forces are compressive (>= 0); a negative
/// torque loads the other half.
///
/// Holds for the unmodified profile; modifications reduce the loaded pins (see the dynamic
/// model for those).
///
/// ```
/// # use rvdyn::geometry::{CycloidGeometry, cycloid::CycloidParams};
/// # use rvdyn::analysis::classical_pin_forces;
/// let g = CycloidGeometry::new(CycloidParams::paper()).unwrap();
/// let f = classical_pin_forces(&g, 21_000.0, 0.1).unwrap();
/// assert_eq!(f.iter().filter(|x| **x > 0.0).count(), 12); // half the pins
/// ```
pub fn classical_pin_forces(
    geometry: &CycloidGeometry,
    disc_torque: f64,
    crank_angle: f64,
) -> Result<Vec<f64>> {
    require_finite("disc_torque", disc_torque)?;
    require_finite("crank_angle", crank_angle)?;
    let levers = classical_levers(geometry, crank_angle);
    let sign = disc_torque.signum();
    let sum_sq: f64 = levers
        .iter()
        .filter(|l| sign * **l > 0.0)
        .map(|l| l * l)
        .sum();
    if disc_torque != 0.0 && sum_sq <= 0.0 {
        return Err(RvdynError::Geometry(
            "no pin has a lever to carry the torque".into(),
        ));
    }
    Ok(levers
        .iter()
        .map(|&l| {
            if sign * l > 0.0 {
                disc_torque * l / sum_sq
            } else {
                0.0
            }
        })
        .collect())
}

/// Lever `l_j = rc' sin(phi_j) / S_j` \[m\] of each pin's contact normal about the disc centre
/// for the disc centre at crank angle `crank_angle` \[rad\].
///
/// # Example
///
/// ```
/// use rvdyn::analysis::classical_levers;
/// use rvdyn::contact::pin_tangent::pin_gap_jet;
/// use rvdyn::geometry::{CycloidGeometry, cycloid::CycloidParams};
/// let g = CycloidGeometry::new(CycloidParams::paper()).unwrap();
/// let psi: f64 = 0.3;
/// let levers = classical_levers(&g, psi);
/// // The lever of the exact contact normal in the kinematic pose is the same.
/// let (centre, angle) = ([4.5e-3 * psi.cos(), 4.5e-3 * psi.sin()], -psi / 23.0);
/// let th = g.pin_angle(3);
/// let pin = [0.15 * th.cos(), 0.15 * th.sin()];
/// let jet = pin_gap_jet(&g, pin, 0.010, centre, angle, th - angle).unwrap();
/// assert!((levers[3] - jet.lever()).abs() < 1e-12); // 97.6 mm
/// ```
pub fn classical_levers(geometry: &CycloidGeometry, crank_angle: f64) -> Vec<f64> {
    let k1 = geometry.k1();
    let rc = geometry.pitch_radius();
    // Reduced first (exactly): at |angle| ~ 1e16 rad the pins' offsets 2 pi j / zp would fall
    // below the angle's last bit and every pin would get the same lever.
    let psi = crank_angle.rem_euclid(std::f64::consts::TAU);
    (0..geometry.pins() as usize)
        .map(|j| {
            let phi = geometry.pin_angle(j) - psi;
            let s = (1.0 + k1 * k1 - 2.0 * k1 * phi.cos()).sqrt();
            rc * phi.sin() / s
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::cycloid::CycloidParams;

    #[test]
    fn huge_crank_angles_keep_the_load_pattern() {
        let g = CycloidGeometry::new(CycloidParams::paper()).unwrap();
        for psi in [1e17, -1e17, 1e300] {
            let f = classical_pin_forces(&g, 1e3, psi).unwrap();
            assert_eq!(f.iter().filter(|x| **x > 0.0).count(), 12, "{psi}: {f:?}");
            let l = classical_levers(&g, psi);
            let moment: f64 = f.iter().zip(&l).map(|(a, b)| a * b).sum();
            assert!((moment - 1e3).abs() < 1e-9 * 1e3);
        }
    }

    #[test]
    fn forces_balance_the_torque_and_match_the_closed_form_maximum() {
        let g = CycloidGeometry::new(CycloidParams::paper()).unwrap();
        let t_c = 0.5 * 43_921.3 * (1.0 - 1.0 / 57.0) * 23.0 / 24.0;
        for psi in [0.0, 0.1, 0.7, -2.0] {
            let f = classical_pin_forces(&g, t_c, psi).unwrap();
            let l = classical_levers(&g, psi);
            let moment: f64 = f.iter().zip(&l).map(|(a, b)| a * b).sum();
            assert!((moment - t_c).abs() < 1e-9 * t_c);
            // F_max ~ 4 T_c / (zp rc') = 33.29 kN for this T_c (20.68 kN m); the sum over 24
            // pins approximates the integral to a few per cent.
            let f_max = f.iter().cloned().fold(0.0, f64::max);
            let closed = 4.0 * t_c / (24.0 * g.pitch_radius());
            assert!((f_max / closed - 1.0).abs() < 0.05, "{f_max} {closed}");
            let n = f.iter().filter(|x| **x > 0.0).count();
            assert!((11..=12).contains(&n), "{n}");
        }
        // A reversed torque loads the other half (forces stay compressive, >= 0).
        let back = classical_pin_forces(&g, -1000.0, 0.3).unwrap();
        let l = classical_levers(&g, 0.3);
        assert!(
            back.iter()
                .zip(&l)
                .all(|(f, l)| *f >= 0.0 && (*f == 0.0 || *l < 0.0))
        );
        assert!(back.iter().any(|f| *f > 0.0));
        assert!(classical_pin_forces(&g, f64::NAN, 0.0).is_err());
    }
}
