//! Quasi-static load sharing of one cycloid disc on rigid pins with the line-contact law
//! (loaded tooth contact analysis): the reference for the physical preset's pin forces.
//!
//! The method of the classical analyses (Li Lixing's and Li Shuting's loaded tooth contact
//! analysis, as used e.g. by Li et al., Appl. Sci. 10 (2020) 1266), with exact geometry: the
//! disc centre stays at its kinematic position for the crank angle `psi`
//! (`e (cos psi, sin psi)`) and the disc turns about its centre by `beta` from its kinematic
//! angle `-psi / zc`. Each pin's penetration is minus the exact gap of
//! [`CycloidGeometry::gap_seeded`] (modifications included: they open the initial clearance),
//! its force the line-contact law [`LineContactLaw::cycloid_contact`] at the contact's curve
//! parameter, with the pin circle radius minus the pin radius as the disc's body depth. `beta` solves the moment balance about the disc centre,
//! `sum_j F_j lever_j = T_c`, with `lever_j = arm_j x n_j` (the penetration of pin `j` grows
//! at the rate `beta' lever_j`), by bisection on a bracket (the moment is monotone in `beta`).
//!
//! Output wind-up: with the crank held at the same eccentric direction the disc's turn `beta`
//! about its centre relative to its kinematic angle is the pins' whole deflection. In an RV
//! reducer with the sun held and rigid meshes the eccentric direction follows the carrier
//! (`phi = (z_sun / z_planet) th_c` for the crank angle relative to the carrier), and the
//! disc turns with the carrier, so `beta = th_c (zp + z_sun / z_planet) / zc`: see
//! [`output_windup`].
//!
//! Theory: docs/model.md, section "Quasi-static load sharing with the line law".

use crate::contact::Material;
use crate::contact::line_contact::LineContactLaw;
use crate::error::{Result, RvdynError, require_finite};
use crate::geometry::CycloidGeometry;
use std::f64::consts::PI;

/// Result of [`line_law_load_sharing`] (SI).
#[derive(Debug, Clone, PartialEq)]
pub struct PinLoadSharing {
    /// Disc rotation about its centre from its kinematic angle \[rad\].
    pub beta: f64,
    /// Force of each pin \[N\] (index j = the paper's pin j + 1).
    pub forces: Vec<f64>,
    /// Approach (penetration) of each pin \[m\] (0 where it does not touch).
    pub approaches: Vec<f64>,
    /// Hertz peak pressure at each pin \[Pa\].
    pub peak_pressures: Vec<f64>,
    /// Number of pins with a force.
    pub loaded: usize,
    /// Largest pin force \[N\].
    pub max_force: f64,
    /// Largest approach \[m\].
    pub max_approach: f64,
    /// Residual of the moment balance [N m].
    pub moment_residual: f64,
}

struct Eval {
    moment: f64,
    forces: Vec<f64>,
    approaches: Vec<f64>,
    pressures: Vec<f64>,
}

/// Quasi-static pin forces of the disc `geometry` carrying the moment `disc_torque` [N m]
/// about its centre at the crank angle `crank_angle` \[rad\], rigid pins of radius
/// `pin_radius` \[m\] on the pin circle, line-contact law with the materials `pin` and `disc`.
///
/// Errors: `Parameter` for non-finite inputs; `Convergence` if no bracket is found within a
/// disc rotation of 0.05 rad (a torque far beyond any physical load); geometry errors from the
/// gap query and the law.
pub fn line_law_load_sharing(
    geometry: &CycloidGeometry,
    disc_torque: f64,
    crank_angle: f64,
    pin_radius: f64,
    pin: &Material,
    disc: &Material,
) -> Result<PinLoadSharing> {
    require_finite("disc torque", disc_torque)?;
    require_finite("crank angle", crank_angle)?;
    let zc = f64::from(geometry.lobes());
    let e = geometry.params().eccentricity;
    let rp = geometry.params().pin_circle_radius;
    let centre = [e * crank_angle.cos(), e * crank_angle.sin()];
    let base_angle = -crank_angle / zc;
    let n = geometry.pins() as usize;
    // The disc's body depth: about the distance from its centre to a contact (the same
    // constant as the dynamic models).
    let depth = rp - geometry.params().pin_radius;
    let eval = |beta: f64| -> Result<Eval> {
        let angle = base_angle + beta;
        let mut out = Eval {
            moment: 0.0,
            forces: vec![0.0; n],
            approaches: vec![0.0; n],
            pressures: vec![0.0; n],
        };
        for j in 0..n {
            let th = geometry.pin_angle(j);
            let pc = [rp * th.cos(), rp * th.sin()];
            let seed = th - angle - geometry.params().d_delta;
            let g = geometry.gap_seeded(pc, pin_radius, centre, angle, seed)?;
            let pen = -g.gap;
            if pen <= 0.0 {
                continue;
            }
            let arm = [g.point[0] - centre[0], g.point[1] - centre[1]];
            let law =
                LineContactLaw::cycloid_contact(geometry, g.phi, pin_radius, depth, pin, disc)?;
            let f = law.force(pen);
            let lever = arm[0] * g.normal[1] - arm[1] * g.normal[0];
            out.moment += f * lever;
            out.forces[j] = f;
            out.approaches[j] = pen;
            out.pressures[j] = law.peak_pressure(f)?;
        }
        Ok(out)
    };
    let target = disc_torque.abs();
    let dir = if disc_torque >= 0.0 { 1.0 } else { -1.0 };
    let finish = |beta: f64, ev: Eval| {
        let loaded = ev.forces.iter().filter(|f| **f > 0.0).count();
        PinLoadSharing {
            beta,
            max_force: ev.forces.iter().cloned().fold(0.0, f64::max),
            max_approach: ev.approaches.iter().cloned().fold(0.0, f64::max),
            loaded,
            moment_residual: ev.moment - disc_torque,
            forces: ev.forces,
            approaches: ev.approaches,
            peak_pressures: ev.pressures,
        }
    };
    if target == 0.0 {
        return Ok(finish(0.0, eval(0.0)?));
    }
    // Bracket: moment(dir * hi) >= target.
    let (mut lo, mut hi) = (0.0f64, 1e-5f64);
    loop {
        let m = dir * eval(dir * hi)?.moment;
        if m >= target {
            break;
        }
        lo = hi;
        hi *= 2.0;
        if hi > 0.05 {
            return Err(RvdynError::Convergence(format!(
                "no disc rotation below 0.05 rad carries the moment {disc_torque} N m"
            )));
        }
    }
    // Bisection to the last bits of beta (the moment is continuous and monotone in beta).
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if dir * eval(dir * mid)?.moment < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let beta = dir * 0.5 * (lo + hi);
    Ok(finish(beta, eval(beta)?))
}

/// Output (carrier) wind-up \[rad\] of an RV reducer with the sun held and rigid meshes, for the
/// disc rotation `beta` \[rad\] from [`line_law_load_sharing`]:
/// `th_c = beta zc / (zp + z_sun / z_planet)` (module documentation). Without a first stage
/// (cranks held) pass `z_sun = 0`: `th_c = beta zc / zp`.
///
/// Errors (`Parameter`) for fewer than 3 pins, zero planet teeth with a sun, a non-finite
/// `beta`.
pub fn output_windup(beta: f64, pins: u32, z_sun: u32, z_planet: u32) -> Result<f64> {
    require_finite("disc rotation", beta)?;
    if pins < 3 || (z_sun > 0 && z_planet == 0) {
        return Err(RvdynError::Parameter(format!(
            "need at least 3 pins and planet teeth with a sun, got zp = {pins}, z_planet = \
             {z_planet}"
        )));
    }
    let ratio = if z_sun == 0 {
        0.0
    } else {
        f64::from(z_sun) / f64::from(z_planet)
    };
    Ok(beta * f64::from(pins - 1) / (f64::from(pins) + ratio))
}

/// `arcmin` per radian (for reports).
pub const ARCMIN_PER_RAD: f64 = 60.0 * 180.0 / PI;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::classical_pin_forces;
    use crate::geometry::cycloid::CycloidParams;

    const STEEL: Material = Material {
        youngs_modulus: 2.17e11,
        poisson_ratio: 0.3,
    };

    /// Disc torque of the rated load (43.9 kN m at the output) shared by two discs, about the
    /// disc centre: 0.5 T_out (1 - 1/57) zc/zp.
    fn rated_disc_torque() -> f64 {
        0.5 * 43.9e3 * (1.0 - 1.0 / 57.0) * 23.0 / 24.0
    }

    #[test]
    fn unmodified_disc_balances_and_resembles_the_classical_distribution() {
        let g = CycloidGeometry::new(CycloidParams::paper()).unwrap();
        let tc = rated_disc_torque();
        let s = line_law_load_sharing(&g, tc, 0.1, 0.010, &STEEL, &STEEL).unwrap();
        assert!(s.moment_residual.abs() < 1e-6 * tc, "{}", s.moment_residual);
        // About half the pins loaded (a near-linear law loads the same half).
        assert!((11..=13).contains(&s.loaded), "{}", s.loaded);
        // Peak force near the classical 4 T_c / (zp rc') = 35 kN (within 5 %: the law is not
        // linear and the contact stiffness varies along the profile).
        let classical = classical_pin_forces(&g, tc, 0.1).unwrap();
        let cmax = classical.iter().cloned().fold(0.0, f64::max);
        assert!(
            (s.max_force / cmax - 1.0).abs() < 0.05,
            "{} vs {cmax}",
            s.max_force
        );
        // Approach near the 25.9 um of the peak pin (Johnson, 35 kN on the 94 mm radius).
        assert!(
            s.max_approach > 20e-6 && s.max_approach < 30e-6,
            "{}",
            s.max_approach
        );
        // Reversal mirrors: the opposite torque loads the other half with the same peak.
        let r = line_law_load_sharing(&g, -tc, 0.1, 0.010, &STEEL, &STEEL).unwrap();
        assert!(r.beta < 0.0 && (r.max_force / s.max_force - 1.0).abs() < 0.05);
    }

    #[test]
    fn modification_loads_fewer_pins_harder() {
        let mut p = CycloidParams::paper();
        p.d_rrp = 20e-6;
        p.d_rp = -20e-6;
        let g = CycloidGeometry::new(p).unwrap();
        let g0 = CycloidGeometry::new(CycloidParams::paper()).unwrap();
        let tc = rated_disc_torque();
        let s = line_law_load_sharing(&g, tc, 0.1, 0.010, &STEEL, &STEEL).unwrap();
        let s0 = line_law_load_sharing(&g0, tc, 0.1, 0.010, &STEEL, &STEEL).unwrap();
        assert!(s.moment_residual.abs() < 1e-6 * tc);
        assert!(s.loaded < s0.loaded, "{} vs {}", s.loaded, s0.loaded);
        assert!(
            s.max_force > 1.1 * s0.max_force,
            "{} vs {}",
            s.max_force,
            s0.max_force
        );
        // The backlash rotation alone, [d_rrp - d_rp sqrt(1 - K1^2)] / rc', is part of beta.
        let k1: f64 = 0.72;
        let backlash = (20e-6 + 20e-6 * (1.0 - k1 * k1).sqrt()) / (4.5e-3 * 23.0);
        assert!(s.beta > backlash + 0.5 * s0.beta, "{} {backlash}", s.beta);
    }

    #[test]
    fn windup_mapping_and_zero_torque() {
        let w = output_windup(1.0, 24, 18, 42).unwrap();
        assert!((w - 23.0 / (24.0 + 18.0 / 42.0)).abs() < 1e-15);
        assert!((output_windup(1.0, 24, 0, 0).unwrap() - 23.0 / 24.0).abs() < 1e-15);
        assert!(output_windup(1.0, 2, 18, 42).is_err());
        assert!(output_windup(f64::NAN, 24, 18, 42).is_err());
        let g = CycloidGeometry::new(CycloidParams::paper()).unwrap();
        let s = line_law_load_sharing(&g, 0.0, 0.1, 0.010, &STEEL, &STEEL).unwrap();
        assert_eq!(s.beta, 0.0);
        // The unmodified disc touches every pin to round-off (gap ~1e-13 m): no real force.
        assert!(s.max_force < 1e-3, "{}", s.max_force);
        assert!(line_law_load_sharing(&g, f64::NAN, 0.1, 0.010, &STEEL, &STEEL).is_err());
    }
}

/// The contact physics of a scene at the rated operating point (43.9 kN m output, 112 kW at
/// the paper's input speed), for side-by-side reports of the presets.
#[derive(Debug, Clone, PartialEq)]
pub struct PhysicsSummary {
    /// Pin law kind (`impact`, `palmgren`, `line`).
    pub pin_law: String,
    /// Reference pin force `4 T_c / (zp rc')` at rated load, `T_c` half the output torque \[N\]
    /// (a round reference: the pins' share of the torque gives the classical peak 6 % lower).
    pub peak_pin_force: f64,
    /// Approach of the pin law at that force, at the classical peak-load pin \[m\].
    pub pin_approach: f64,
    /// Mesh law kind (`impact`, `palmgren`, `iso6336`).
    pub mesh_law: String,
    /// Rated tooth force per planet mesh `T_in / (planets r_bs)` \[N\].
    pub mesh_force: f64,
    /// Mean mesh stiffness [N/m]: ISO 6336 `c_gamma b`, or the secant stiffness of the IMPACT
    /// law at the rated mesh force.
    pub mesh_stiffness: f64,
    /// Damping of the pin contacts, in words.
    pub damping: String,
}

/// [`PhysicsSummary`] of `scene` (needs a first stage for the mesh entries; without one they
/// are 0).
///
/// Errors from the laws (invalid parameters were rejected when the scene was built).
pub fn physics_summary(scene: &crate::dynamics::Scene) -> Result<PhysicsSummary> {
    use crate::contact::law::{ContactDamping, DampingSpec, MeshLaw, PinLaw};
    use crate::dynamics::scene::{ContactLawSpec, PAPER_INPUT_SPEED, PAPER_POWER};
    let kind = |s: &ContactLawSpec| {
        match s {
            ContactLawSpec::Impact { .. } => "impact",
            ContactLawSpec::Palmgren { .. } => "palmgren",
            ContactLawSpec::Line { .. } => "line",
            ContactLawSpec::Iso6336 { .. } => "iso6336",
        }
        .to_string()
    };
    let ratio = scene.ratio();
    let t_out = PAPER_POWER / (PAPER_INPUT_SPEED / ratio);
    let c = scene.cycloid;
    let zp = f64::from(c.pins);
    let zc = zp - 1.0;
    // Half the output torque per disc, the project's reference convention (the housing share
    // (1 - 1/i) zc/zp of it would give 6 % less).
    let tc = 0.5 * t_out;
    let rc = c.eccentricity * zc;
    let f_pin = 4.0 * tc / (zp * rc);
    let g = CycloidGeometry::new(scene.disc_params(0))?;
    let phi = g.k1().acos() / zc;
    let pin_law = scene.contact.pin.pin_law(c.face_width)?;
    let pin_approach = match &pin_law {
        PinLaw::Impact(l) => (f_pin / l.stiffness).powf(1.0 / l.exponent),
        PinLaw::Line { pin, disc, .. } => LineContactLaw::cycloid_contact(
            &g,
            phi,
            c.pin_radius,
            c.pin_circle_radius - c.pin_radius,
            pin,
            disc,
        )?
        .approach(f_pin)?,
    };
    let damping = match (&scene.contact.pin, &pin_law) {
        (ContactLawSpec::Line { damping, .. }, _) => match damping {
            DampingSpec::DampingRatio { ratio, frequency } => {
                format!("stiffness-proportional, damping ratio {ratio} at {frequency} Hz")
            }
            DampingSpec::Restitution {
                model,
                restitution,
                reference_speed,
            } => {
                let _ = ContactDamping::new(damping)?;
                format!(
                    "{} restitution {restitution} at {reference_speed} m/s",
                    model.name()
                )
            }
        },
        (_, PinLaw::Impact(l)) => format!(
            "IMPACT ramp to c_max = {} N s/m over {} m",
            l.max_damping, l.damping_depth
        ),
        _ => String::new(),
    };
    let (mesh_force, mesh_stiffness) = match &scene.stage1 {
        Some(s) => {
            let f = t_out / ratio / (f64::from(s.planets) * s.sun_base_radius());
            let k = match scene.stage_mesh_law(s)? {
                MeshLaw::Iso(m) => m.wave.mean(),
                MeshLaw::Impact(l) => {
                    let x = (f / l.stiffness).powf(1.0 / l.exponent);
                    f / x
                }
            };
            (f, k)
        }
        None => (0.0, 0.0),
    };
    Ok(PhysicsSummary {
        pin_law: kind(&scene.contact.pin),
        peak_pin_force: f_pin,
        pin_approach,
        mesh_law: kind(&scene.contact.mesh),
        mesh_force,
        mesh_stiffness,
        damping,
    })
}

#[cfg(test)]
mod summary_tests {
    use super::*;
    use crate::dynamics::Scene;

    #[test]
    fn presets_side_by_side() {
        // Paper: IMPACT at the classical 35.35 kN: (F / 1.2611e10)^(2/3) = 198 um; mesh secant
        // at 10.1 kN about 1.2e8 N/m. Physical: 25.9 um, ISO 5.546e8 N/m.
        let p = physics_summary(&Scene::paper("rated").unwrap()).unwrap();
        assert!((p.peak_pin_force / 35.35e3 - 1.0).abs() < 2e-3, "{p:?}");
        assert!((p.pin_approach / 198e-6 - 1.0).abs() < 0.01, "{p:?}");
        assert!((p.mesh_force / 10.1e3 - 1.0).abs() < 0.01, "{p:?}");
        assert!(
            p.mesh_stiffness > 1.1e8 && p.mesh_stiffness < 1.3e8,
            "{p:?}"
        );
        let q = physics_summary(&Scene::physical("rated").unwrap()).unwrap();
        assert_eq!(
            (q.pin_law.as_str(), q.mesh_law.as_str()),
            ("line", "iso6336")
        );
        assert!((q.pin_approach - 26.0e-6).abs() < 0.3e-6, "{q:?}");
        assert!((q.mesh_stiffness / 5.546e8 - 1.0).abs() < 1e-3, "{q:?}");
        assert!(q.damping.contains("0.05"), "{q:?}");
    }
}
