//! Analytic efficiency estimate of an RV reducer: sliding friction at the pins (cycloid stage)
//! and at the sun-planet meshes (involute stage), first order in the friction coefficients.
//!
//! **Pins.** The power lost at a contact is the friction force times the sliding speed,
//! `mu F_j v_j`, summed over the loaded pins with the quasi-static load distribution (the
//! method of Malhotra & Parameswaran, *Analysis of a cycloid speed reducer*, Mech. Mach. Theory
//! 18 (1983) 491-499, and of Gorla et al., *Theoretical and experimental analysis of a
//! cycloidal speed reducer*, J. Mech. Des. 130 (2008) 112604). Relative to the housing the disc
//! turns at the output speed `w_out` (its centre orbits at `-zc w_out`) about the pitch point
//! `P`, which lies on the line through both centres at `e zp` from the ring centre; every
//! contact normal passes through `P`, so the relative velocity at the contact of pin `j` is
//! purely tangential with the sliding speed
//!
//! `v_j = |w_out| (rp S_j - rrp)`,  `S_j = sqrt(1 + K1^2 - 2 K1 cos phi_j)`
//!
//! (`rp S_j` is the distance from `P` to the pin centre). With the classical distribution
//! `F_j = F_max sin phi_j / S_j` on the loaded half (see [`crate::analysis::load_sharing`]) and
//! many pins, `sum F_j (rp S_j - rrp) = F_max (zp / pi) (rp - rrp)` (because
//! `integral_0^pi sin phi dphi = 2` and `integral_0^pi sin phi / S dphi = 2`) while the disc
//! torque is `T_c = sum F_j l_j = F_max zp rc' / 4`. The pins react the housing torque
//! `T_out (1 - 1/i)`, i.e. `T_c = T_out (1 - 1/i) (zc / zp)` summed over the discs, so the pin
//! loss relative to the output power `T_out w_out` is
//!
//! `L_pin = mu_pin lambda (4 / pi) (1 - 1/i) (rp - rrp) / (e zp)`
//!
//! (derived here; `lambda = 1` for pins fixed in the housing or turning in a groove of their own
//! radius, `lambda = r_j / rrp` for a sleeve turning on a journal of radius `r_j`, where the
//! sliding then happens). [`pin_loss_ratio_discrete`] evaluates the same sums over the actual
//! pins and crank positions.
//!
//! **Meshes.** Average tooth friction loss of a spur pair (G. Niemann, H. Winter,
//! *Maschinenelemente* vol. II, Springer 1983, tooth loss factor after Ohlendorf; also
//! ISO/TR 14179-2:2001): `P_loss = mu_mesh H_V P_mesh` with
//! `H_V = pi (u + 1) / (z1 u cos beta_b) (1 - eps_alpha + eps_1^2 + eps_2^2)`,
//! `u = z2 / z1`, `eps_1`, `eps_2` the addendum contact ratios. In the RV the mesh carries the
//! power in the carrier frame, `P_mesh = P_in (1 - 1/i)`.
//!
//! **Total.** `P_in = P_out (1 + L_pin) + mu_mesh H_V (1 - 1/i) P_in`, so
//! `eta = (1 - mu_mesh H_V (1 - 1/i)) / (1 + L_pin)`. Bearing friction (Palmgren torques,
//! [`crate::bearing::PalmgrenFriction`]) adds `sum M_k |w_k| / P_out` to `L_pin` when known.
//!
//! Theory: docs/model.md, section "Analytic efficiency estimate".

use crate::error::{Result, RvdynError, require_finite};
use crate::geometry::CycloidGeometry;
use crate::geometry::cycloid::CycloidParams;
use std::f64::consts::PI;

fn check_mu(name: &str, mu: f64) -> Result<f64> {
    if mu.is_finite() && (0.0..=1.0).contains(&mu) {
        Ok(mu)
    } else {
        Err(RvdynError::Parameter(format!(
            "{name} friction coefficient must be in [0, 1], got {mu}"
        )))
    }
}

fn check_lever(lever: f64) -> Result<f64> {
    if lever.is_finite() && lever > 0.0 && lever <= 1.0 {
        Ok(lever)
    } else {
        Err(RvdynError::Parameter(format!(
            "pin sliding lever ratio must be in (0, 1] (1 for fixed pins), got {lever}"
        )))
    }
}

fn check_ratio(ratio: f64) -> Result<f64> {
    if ratio.is_finite() && ratio > 1.0 {
        Ok(ratio)
    } else {
        Err(RvdynError::Parameter(format!(
            "transmission ratio must be > 1, got {ratio}"
        )))
    }
}

/// Distance \[m\] from the pitch point to the contact of the pin at mesh angle `phi` \[rad\]
/// (from the eccentricity direction): `rp S - rrp`. The sliding speed is this times the disc's
/// angular speed relative to the pins.
pub fn pin_sliding_arm(params: &CycloidParams, phi: f64) -> f64 {
    let k1 = f64::from(params.pins) * params.eccentricity / params.pin_circle_radius;
    let s = (1.0 + k1 * k1 - 2.0 * k1 * phi.cos()).sqrt();
    params.pin_circle_radius * s - params.pin_radius
}

/// Pin friction loss relative to the output power, closed form for many pins:
/// `mu lambda (4/pi) (1 - 1/i) (rp - rrp) / (e zp)` [-].
///
/// `mu` in [0, 1], `lever` (lambda) in (0, 1], `ratio` the reducer ratio `i > 1`.
/// Errors (`Parameter`) outside those ranges; invalid geometry errors from the cycloid check.
pub fn pin_loss_ratio(params: &CycloidParams, ratio: f64, mu: f64, lever: f64) -> Result<f64> {
    CycloidGeometry::check(*params)?;
    let mu = check_mu("pin", mu)?;
    let lever = check_lever(lever)?;
    let ratio = check_ratio(ratio)?;
    let p = params;
    Ok(
        mu * lever * 4.0 / PI * (1.0 - 1.0 / ratio) * (p.pin_circle_radius - p.pin_radius)
            / (p.eccentricity * f64::from(p.pins)),
    )
}

/// Pin friction loss relative to the output power from the discrete classical pin forces,
/// averaged over `samples` crank angles of one pin pitch [-]:
/// `mu lambda (1 - 1/i) (zc/zp) <sum F_j (rp S_j - rrp) / sum F_j l_j>`.
///
/// Errors as [`pin_loss_ratio`], and (`Parameter`) for zero samples.
pub fn pin_loss_ratio_discrete(
    geometry: &CycloidGeometry,
    ratio: f64,
    mu: f64,
    lever: f64,
    samples: usize,
) -> Result<f64> {
    let mu = check_mu("pin", mu)?;
    let lever = check_lever(lever)?;
    let ratio = check_ratio(ratio)?;
    if samples == 0 {
        return Err(RvdynError::Parameter("samples must be at least 1".into()));
    }
    let p = geometry.params();
    let zp = f64::from(geometry.pins());
    let zc = f64::from(geometry.lobes());
    let mut acc = 0.0;
    for k in 0..samples {
        let psi = 2.0 * PI / zp * (k as f64 + 0.5) / samples as f64;
        let forces = crate::analysis::classical_pin_forces(geometry, 1.0, psi)?;
        let levers = crate::analysis::classical_levers(geometry, psi);
        let (mut num, mut den) = (0.0, 0.0);
        for (j, (&f, &l)) in forces.iter().zip(&levers).enumerate() {
            if f > 0.0 {
                num += f * pin_sliding_arm(p, geometry.pin_angle(j) - psi);
                den += f * l;
            }
        }
        acc += num / den;
    }
    Ok(mu * lever * (1.0 - 1.0 / ratio) * (zc / zp) * acc / samples as f64)
}

/// Addendum contact ratios `(eps_1, eps_2)` [-] of an external spur pair at standard centre
/// distance without shift: `eps_k = (sqrt(ra_k^2 - rb_k^2) - r_k sin alpha) / p_b`, the parts
/// of the path of contact beyond the pitch point on each gear's tip side.
///
/// Errors (`Parameter`) for tooth counts below 5, a non-positive module, a pressure angle
/// outside (0, 45 deg).
pub fn addendum_contact_ratios(
    z1: u32,
    z2: u32,
    module: f64,
    pressure_angle: f64,
) -> Result<(f64, f64)> {
    // Reuse the ISO pair's validation of the same inputs.
    crate::gear::IsoGearPair::spur(z1, z2, module, pressure_angle, 1.0).validate()?;
    let (s, c) = pressure_angle.sin_cos();
    let pb = PI * module * c;
    let part = |z: u32| {
        let r = 0.5 * module * f64::from(z);
        let ra = r + module;
        let rb = r * c;
        ((ra * ra - rb * rb).sqrt() - r * s) / pb
    };
    Ok((part(z1), part(z2)))
}

/// Tooth loss factor `H_V = pi (u + 1) / (z1 u) (1 - eps + eps_1^2 + eps_2^2)` [-] of a spur
/// pair (`cos beta_b = 1`) at standard centre distance without shift.
///
/// Errors as [`addendum_contact_ratios`].
pub fn tooth_loss_factor(z1: u32, z2: u32, module: f64, pressure_angle: f64) -> Result<f64> {
    let (e1, e2) = addendum_contact_ratios(z1, z2, module, pressure_angle)?;
    let u = f64::from(z2) / f64::from(z1);
    Ok(PI * (u + 1.0) / (f64::from(z1) * u) * (1.0 - (e1 + e2) + e1 * e1 + e2 * e2))
}

/// An efficiency estimate and its parts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EfficiencyEstimate {
    /// Pin friction loss relative to the output power [-].
    pub pin_loss_ratio: f64,
    /// Mesh friction loss relative to the input power [-], `mu_mesh H_V (1 - 1/i)`.
    pub mesh_loss_ratio: f64,
    /// Efficiency `(1 - mesh_loss_ratio) / (1 + pin_loss_ratio)` [-].
    pub efficiency: f64,
}

/// Efficiency estimate of an RV reducer with the cycloid `cycloid`, sun and planet teeth
/// `z_sun`, `z_planet`, module \[m\] and pressure angle \[rad\] of the first stage, reducer ratio
/// `ratio`, pin friction coefficient `mu_pin` with sliding lever ratio `pin_lever`, mesh
/// friction coefficient `mu_mesh` (module documentation; closed-form pin term).
///
/// Errors (`Parameter`/`Geometry`) for invalid inputs, as the functions it calls.
#[allow(clippy::too_many_arguments)]
pub fn rv_efficiency(
    cycloid: &CycloidParams,
    z_sun: u32,
    z_planet: u32,
    module: f64,
    pressure_angle: f64,
    ratio: f64,
    mu_pin: f64,
    pin_lever: f64,
    mu_mesh: f64,
) -> Result<EfficiencyEstimate> {
    require_finite("module", module)?;
    let mu_mesh = check_mu("mesh", mu_mesh)?;
    let pin = pin_loss_ratio(cycloid, ratio, mu_pin, pin_lever)?;
    let hv = tooth_loss_factor(z_sun, z_planet, module, pressure_angle)?;
    let mesh = mu_mesh * hv * (1.0 - 1.0 / ratio);
    Ok(EfficiencyEstimate {
        pin_loss_ratio: pin,
        mesh_loss_ratio: mesh,
        efficiency: (1.0 - mesh) / (1.0 + pin),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::close;

    #[test]
    fn pin_loss_closed_form_by_hand() {
        // (4/pi)(56/57)(150 - 10)/(4.5 * 24) = 1.27324 * 0.982456 * 1.296296 = 1.62154;
        // mu = 0.05 -> 8.108 % of the output power.
        let p = CycloidParams::paper();
        let l = pin_loss_ratio(&p, 57.0, 0.05, 1.0).unwrap();
        assert!(close(l, 0.05 * 1.621_54, 1e-5), "{l}");
        // Proportional to mu and to the lever.
        assert!(close(pin_loss_ratio(&p, 57.0, 0.1, 0.5).unwrap(), l, 1e-14));
        assert_eq!(pin_loss_ratio(&p, 57.0, 0.0, 1.0).unwrap(), 0.0);
    }

    #[test]
    fn discrete_sum_converges_to_the_closed_form() {
        // 24 pins: the discrete sums differ from the integrals by a few per cent at most;
        // with many pins (same K1 = 0.72, smaller pins) they converge to them.
        let g = CycloidGeometry::new(CycloidParams::paper()).unwrap();
        let d = pin_loss_ratio_discrete(&g, 57.0, 0.05, 1.0, 16).unwrap();
        let c = pin_loss_ratio(&CycloidParams::paper(), 57.0, 0.05, 1.0).unwrap();
        assert!(close(d, c, 0.03), "{d} vs {c}");
        let mut p = CycloidParams::paper();
        p.pins = 96;
        p.eccentricity = 0.72 * 0.150 / 96.0;
        p.pin_radius = 0.003;
        let g = CycloidGeometry::new(p).unwrap();
        let d = pin_loss_ratio_discrete(&g, 57.0, 0.05, 1.0, 8).unwrap();
        let c = pin_loss_ratio(&p, 57.0, 0.05, 1.0).unwrap();
        assert!(close(d, c, 2e-3), "{d} vs {c}");
    }

    #[test]
    fn sliding_arm_is_the_distance_from_the_pitch_point() {
        // Pitch point at e zp = 108 mm on +x; pin at 150 (cos phi, sin phi).
        let p = CycloidParams::paper();
        for phi in [0.3f64, 1.0, 2.5] {
            let d = ((0.150 * phi.cos() - 0.108).powi(2) + (0.150 * phi.sin()).powi(2)).sqrt();
            assert!(close(pin_sliding_arm(&p, phi), d - 0.010, 1e-12));
        }
    }

    #[test]
    fn tooth_loss_factor_by_hand() {
        // Paper stage: eps_1 = (16.00837 - 9.23454) / 8.85639 = 0.76484,
        // eps_2 = (29.17599 - 21.54727) / 8.85639 = 0.86138 (sum 1.62622 + rounding),
        // H_V = pi (10/3) / 42 * (1 - 1.62622 + 0.584980 + 0.741975) = 0.17472 (0.17474 from
        // the unrounded ratios).
        let (e1, e2) = addendum_contact_ratios(18, 42, 3e-3, 20f64.to_radians()).unwrap();
        let eps = crate::gear::spur_contact_ratio(18, 42, 3e-3, 20f64.to_radians()).unwrap();
        assert!(close(e1 + e2, eps, 1e-12));
        assert!(close(e1, 0.764_84, 1e-4), "{e1}");
        let hv = tooth_loss_factor(18, 42, 3e-3, 20f64.to_radians()).unwrap();
        assert!(close(hv, 0.17474, 1e-4), "{hv}");
    }

    #[test]
    fn total_and_zero_friction() {
        let p = CycloidParams::paper();
        let a = 20f64.to_radians();
        let e = rv_efficiency(&p, 18, 42, 3e-3, a, 57.0, 0.0, 1.0, 0.0).unwrap();
        assert_eq!(e.efficiency, 1.0);
        let e = rv_efficiency(&p, 18, 42, 3e-3, a, 57.0, 0.05, 1.0, 0.05).unwrap();
        let want = (1.0 - e.mesh_loss_ratio) / (1.0 + e.pin_loss_ratio);
        assert!(close(e.efficiency, want, 1e-15));
        // About 0.92 with fixed pins at mu = 0.05.
        assert!(e.efficiency > 0.91 && e.efficiency < 0.93, "{e:?}");
        assert!(rv_efficiency(&p, 18, 42, 3e-3, a, 57.0, 1.5, 1.0, 0.0).is_err());
        assert!(rv_efficiency(&p, 18, 42, 3e-3, a, 57.0, 0.1, 0.0, 0.0).is_err());
        assert!(rv_efficiency(&p, 18, 42, 3e-3, a, 0.5, 0.1, 1.0, 0.0).is_err());
        assert!(rv_efficiency(&p, 18, 42, 3e-3, a, 57.0, 0.1, 1.0, -0.1).is_err());
    }
}
