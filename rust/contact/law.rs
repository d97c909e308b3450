//! Force laws of the dynamic models, as the scene describes them: the damping of a contact
//! family, the pin/disc law (IMPACT or line contact from geometry) and the sun/planet mesh law
//! (IMPACT or ISO 6336 stiffness along the line of action).
//!
//! Each law returns the force with its elastic part, so that a model can book the dissipated
//! power `(F - F_el) * rate` and the stored energy.

use crate::contact::damping::{HysteresisDamping, HysteresisModel, StiffnessProportionalDamping};
use crate::contact::hertz::Material;
use crate::contact::impact::ImpactLaw;
use crate::contact::line_contact::{
    LineContactLaw, PinDiscLawBase, disc_reference_depth, disc_reference_depth_ratio,
    profile_curvature_checked,
};
use crate::contact::pin_tangent::{centre_curve_derivatives, curvature_derivatives_of};
use crate::error::{Result, RvdynError, require_positive};
use crate::gear::iso6336::{IsoGearPair, MeshStiffnessWave, base_pitch, spur_contact_ratio};
use crate::geometry::CycloidGeometry;
use serde::{Deserialize, Serialize};

/// How a contact family is damped (scene field `damping` of a `line` or `iso6336` law).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum DampingSpec {
    /// Restitution-based (Hunt-Crossley family): `F = F_el (1 + chi rate / v_ref)`, `chi` from
    /// the coefficient of restitution `restitution` by `model` ("exact", "hunt-crossley",
    /// "lankarani-nikravesh", "flores") at the reference speed `reference_speed` [m/s].
    Restitution {
        /// Closed form of the hysteresis factor.
        model: HysteresisModel,
        /// Coefficient of restitution [-], in (0, 1].
        restitution: f64,
        /// Impact speed at which the restitution holds [m/s].
        reference_speed: f64,
    },
    /// Stiffness-proportional: `F = F_el + beta k_t rate`, `beta = 2 ratio / (2 pi frequency)`:
    /// the damping ratio `ratio` [-] of a linearised mode at `frequency` \[Hz\].
    DampingRatio {
        /// Damping ratio [-], in [0, 1).
        ratio: f64,
        /// Reference frequency \[Hz\].
        frequency: f64,
    },
}

/// A damping law built from a [`DampingSpec`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ContactDamping {
    /// Restitution-based (Hunt-Crossley family).
    Hysteresis(HysteresisDamping),
    /// Stiffness-proportional.
    Proportional(StiffnessProportionalDamping),
}

impl ContactDamping {
    /// Build from the scene's spec. Errors (`Parameter`) for a restitution outside (0, 1], a
    /// non-positive speed or frequency, a ratio outside [0, 1).
    pub fn new(spec: &DampingSpec) -> Result<Self> {
        match *spec {
            DampingSpec::Restitution {
                model,
                restitution,
                reference_speed,
            } => Ok(Self::Hysteresis(HysteresisDamping::new(
                model,
                restitution,
                reference_speed,
            )?)),
            DampingSpec::DampingRatio { ratio, frequency } => {
                require_positive("damping reference frequency", frequency, "Hz")?;
                Ok(Self::Proportional(StiffnessProportionalDamping::for_mode(
                    ratio,
                    2.0 * std::f64::consts::PI * frequency,
                )?))
            }
        }
    }

    /// Total force \[N\] (>= 0) from the elastic force `elastic` \[N\], its tangent stiffness
    /// `stiffness` [N/m] and the approach rate `rate` [m/s] (positive closing).
    #[inline]
    pub fn force(&self, elastic: f64, stiffness: f64, rate: f64) -> f64 {
        match self {
            Self::Hysteresis(h) => h.force(elastic, rate),
            Self::Proportional(p) => (elastic + p.beta * stiffness * rate).max(0.0),
        }
    }
}

impl ContactDamping {
    /// Damping coefficient `dF/d(rate)` [N s/m] at zero rate for the elastic force `elastic`
    /// \[N\] and its tangent stiffness `stiffness` [N/m] (0 without contact): the contact's part
    /// of a linearised damping matrix.
    #[inline]
    pub fn rate_coefficient(&self, elastic: f64, stiffness: f64) -> f64 {
        match self {
            Self::Hysteresis(h) => h.force_and_derivatives(elastic, stiffness, 0.0).2,
            Self::Proportional(p) => p.force_and_derivatives(elastic, stiffness, 0.0, 0.0).2,
        }
    }
}

/// The steel of the paper's scene (`E = 2.17e11 Pa`, `nu = 0.3`) for serde defaults.
pub fn default_youngs_modulus() -> f64 {
    2.17e11
}

/// Poisson's ratio of the paper's steel (0.3) for serde defaults.
pub fn default_poisson_ratio() -> f64 {
    0.3
}

/// A force and its elastic part, plus the stored energy when asked for.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LawForce {
    /// Total force \[N\] (>= 0).
    pub force: f64,
    /// Elastic force \[N\].
    pub elastic: f64,
    /// Elastic energy \[J\] (0 unless asked for).
    pub energy: f64,
}

/// Where a pin touches its disc (what the line law needs besides the approach).
#[derive(Debug, Clone, Copy)]
pub struct PinSite<'a> {
    /// The disc.
    pub geometry: &'a CycloidGeometry,
    /// Curve parameter of the contact \[rad\].
    pub phi: f64,
    /// Pin radius \[m\].
    pub pin_radius: f64,
    /// The disc's body depth \[m\] (the cap of its reference depth; the models use the pin
    /// circle radius minus the pin radius, a constant, so that the law's energy depends on the
    /// state only through the approach and the contact's curve parameter).
    pub depth: f64,
}

/// The pin/disc force law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PinLaw {
    /// ADAMS IMPACT (the paper).
    Impact(ImpactLaw),
    /// Line contact from the local geometry (Johnson; `contact::line_contact`) with damping.
    Line {
        /// Pin material.
        pin: Material,
        /// Disc material.
        disc: Material,
        /// Damping of the contact.
        damping: ContactDamping,
    },
}

impl PinLaw {
    /// Force at the approach `pen` \[m\] (> 0) and rate `rate` [m/s] at the contact `site`.
    ///
    /// Errors (`Geometry`) only if the local geometry cannot make a line contact (an undercut
    /// or conformal profile, rejected by the scene check before a run).
    #[inline]
    pub fn evaluate(
        &self,
        pen: f64,
        rate: f64,
        site: &PinSite<'_>,
        want_energy: bool,
    ) -> Result<LawForce> {
        match self {
            PinLaw::Impact(l) => Ok(LawForce {
                force: l.force(pen, rate),
                elastic: l.elastic_force(pen),
                energy: if want_energy {
                    l.elastic_energy(pen)
                } else {
                    0.0
                },
            }),
            PinLaw::Line { pin, disc, damping } => {
                let law = LineContactLaw::cycloid_contact(
                    site.geometry,
                    site.phi,
                    site.pin_radius,
                    site.depth,
                    pin,
                    disc,
                )?;
                let (fe, k) = law.force_and_stiffness(pen);
                Ok(LawForce {
                    force: damping.force(fe, k, rate),
                    elastic: fe,
                    energy: if want_energy {
                        law.elastic_energy(pen)
                    } else {
                        0.0
                    },
                })
            }
        }
    }

    /// As [`PinLaw::evaluate`] for a law and site built by a model from a validated scene
    /// (materials, pin radius and depth checked once), with the line law's Newton inversion
    /// started from `ln_force_guess` (`ln F` of this contact at the previous evaluation, or NaN):
    /// the same force to round-off (the inversion converges to 1e-15, see
    /// [`LineContactLaw::force_and_stiffness_from`]), in fewer iterations. Returns the force and
    /// `ln F` to keep as the next guess (NaN for IMPACT).
    ///
    /// With `prepared = (base, ln_depth, kappa_c)` the line law at the contact is built from its
    /// prepared part `base` (checked with the scene), `ln` of the disc's body depth and the
    /// pin-centre curve's curvature `kappa_c` \[1/m\] at the contact: one logarithm instead of
    /// a curve evaluation and three (the same law to round-off: [`PinDiscLawBase::law`]).
    #[inline]
    pub(crate) fn evaluate_warm(
        &self,
        pen: f64,
        rate: f64,
        site: &PinSite<'_>,
        want_energy: bool,
        ln_force_guess: f64,
        prepared: Option<(&PinDiscLawBase, f64, f64)>,
    ) -> Result<(LawForce, f64)> {
        let PinLaw::Line { pin, disc, damping } = self else {
            return Ok((self.evaluate(pen, rate, site, want_energy)?, f64::NAN));
        };
        let law = match prepared {
            Some((base, ln_depth, kappa_c)) => {
                let r = site.geometry.generating_pin_radius();
                let kappa = profile_curvature_checked(kappa_c, r)?;
                let (depth, ratio) = disc_reference_depth_ratio(kappa, site.depth);
                base.law(kappa, depth.depth, ln_depth - ratio)?
            }
            None => LineContactLaw::cycloid_contact_checked(
                site.geometry,
                site.phi,
                site.pin_radius,
                site.depth,
                pin,
                disc,
            )?,
        };
        let (fe, k, ln_f) = law.force_and_stiffness_from(pen, ln_force_guess);
        let energy = if want_energy {
            law.elastic_energy(pen)
        } else {
            0.0
        };
        let force = damping.force(fe, k, rate);
        Ok((
            LawForce {
                force,
                elastic: fe,
                energy,
            },
            ln_f,
        ))
    }

    /// The line law's energy depends on where the pin touches the profile (the curvature
    /// sets `K0`, see `contact::line_contact`), so a conservative force field needs, besides
    /// the normal force, the term `-dU/dphi dphi/dq`. With `delta = F (K0 - K1 ln F)`,
    /// `dU/dK0` at fixed approach is `-F^2 / 2` (from `dF/dK0 = -F k_t`), and
    /// `dK0/dphi = [2 c_2 dln(h_2)/dphi - (c_1 + c_2) dln(R)/dphi] / (pi L)`. The curve parameter
    /// moves with the pin's position `p` in the disc frame by `dphi/dp = C' / (|C'|^2 +
    /// (C - p).C'')` (the foot condition `(C - p).C' = 0`).
    ///
    /// `elastic` \[N\] is the elastic force of this contact, `pin_centre`, `disc_centre` \[m\] and
    /// `disc_angle` \[rad\] the pose. `None` for IMPACT (no location dependence). The `dU/dK0`
    /// formula holds below the line law's validity limit (about 240 times the rated pin force).
    pub fn location_slope(
        &self,
        elastic: f64,
        site: &PinSite<'_>,
        pin_centre: [f64; 2],
        disc_centre: [f64; 2],
        disc_angle: f64,
    ) -> Option<LocationSlope> {
        self.location_slope_at(elastic, site, pin_centre, disc_centre, disc_angle.sin_cos())
    }

    /// As [`PinLaw::location_slope`] with the disc angle given by its sine and cosine (a model
    /// has them per disc already).
    #[inline]
    pub(crate) fn location_slope_at(
        &self,
        elastic: f64,
        site: &PinSite<'_>,
        pin_centre: [f64; 2],
        disc_centre: [f64; 2],
        sin_cos: (f64, f64),
    ) -> Option<LocationSlope> {
        if elastic <= 0.0 || !matches!(self, PinLaw::Line { .. }) {
            return None;
        }
        // The curve's derivatives at the contact, used twice: the curvature and its slope
        // (exact) and the foot sensitivity.
        let d = centre_curve_derivatives(site.geometry, site.phi);
        let [kc, dkc, _] = curvature_derivatives_of(&d);
        self.location_slope_from(
            elastic,
            site,
            &d,
            [kc, dkc],
            pin_centre,
            disc_centre,
            sin_cos,
        )
    }

    /// As [`PinLaw::location_slope_at`] with the curve derivatives `d` (orders 0-4) at the
    /// contact and the curvature `kappa_c` with its slope in `phi` given.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub(crate) fn location_slope_from(
        &self,
        elastic: f64,
        site: &PinSite<'_>,
        d: &[[f64; 2]; 5],
        [kc, dkc]: [f64; 2],
        pin_centre: [f64; 2],
        disc_centre: [f64; 2],
        (sn, cs): (f64, f64),
    ) -> Option<LocationSlope> {
        let PinLaw::Line { pin, disc, .. } = self else {
            return None;
        };
        if elastic <= 0.0 {
            return None;
        }
        let g = site.geometry;
        let r = g.generating_pin_radius();
        let [c, d1, d2, ..] = *d;
        let den = 1.0 - r * kc;
        let k2 = kc / den;
        let dk2 = dkc / (den * den);
        let k1 = 1.0 / site.pin_radius;
        let dln_r = -dk2 / (k1 + k2);
        let dln_h2 = disc_reference_depth(k2, site.depth).dln_dkappa * dk2;
        let (c1, c2) = (pin.compliance(), disc.compliance());
        let length = g.params().face_width;
        let dk0 = (2.0 * c2 * dln_h2 - (c1 + c2) * dln_r) / (std::f64::consts::PI * length);
        let energy_per_phi = -0.5 * elastic * elastic * dk0;
        // Foot sensitivity in the (unrotated) disc frame.
        let d = [
            pin_centre[0] - disc_centre[0],
            pin_centre[1] - disc_centre[1],
        ];
        let p = g.remove_rotation_mod([cs * d[0] + sn * d[1], -sn * d[0] + cs * d[1]]);
        let gp = d1[0] * d1[0] + d1[1] * d1[1] + (c[0] - p[0]) * d2[0] + (c[1] - p[1]) * d2[1];
        if gp.is_nan() || gp <= 0.0 {
            return None;
        }
        let t = g.apply_rotation_mod(d1);
        let t_global = [cs * t[0] - sn * t[1], sn * t[0] + cs * t[1]];
        // dp/dtheta = -z x p; dp/dO = -R(-theta) (mod removed).
        let zxp = [-p[1], p[0]];
        Some(LocationSlope {
            energy_per_phi,
            phi_per_centre: [-t_global[0] / gp, -t_global[1] / gp],
            phi_per_angle: -(d1[0] * zxp[0] + d1[1] * zxp[1]) / gp,
        })
    }
}

/// How the elastic energy of a line contact changes with the contact's place on the profile,
/// and how that place moves with the disc (see [`PinLaw::location_slope`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LocationSlope {
    /// `dU/dphi` at fixed approach [J/rad].
    pub energy_per_phi: f64,
    /// `dphi/dO`: change of the contact's curve parameter with the disc centre [rad/m]
    /// (fixed frame).
    pub phi_per_centre: [f64; 2],
    /// `dphi/dtheta`: change with the disc angle [rad/rad].
    pub phi_per_angle: f64,
}

impl LocationSlope {
    /// The generalised force of the location term on the disc centre \[N\] and angle [N m]:
    /// `-dU/dphi * dphi/dq`.
    #[inline]
    pub fn forces(&self) -> ([f64; 2], f64) {
        let u = self.energy_per_phi;
        (
            [-u * self.phi_per_centre[0], -u * self.phi_per_centre[1]],
            -u * self.phi_per_angle,
        )
    }
}

/// ISO 6336 mesh stiffness along the line of action with damping (one sun/planet mesh).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IsoMesh {
    /// Stiffness wave along the line of action (period one base pitch).
    pub wave: MeshStiffnessWave,
    /// Damping of the mesh.
    pub damping: ContactDamping,
}

impl IsoMesh {
    /// The ISO 6336-1 method B mesh of a solid, unshifted spur pair (standard rack) with
    /// `z_sun`, `z_planet` teeth, module \[m\], pressure angle \[rad\], face width \[m\], the stiffness
    /// ramps `ramp` (fraction of a base pitch), the damping and the nominal line load
    /// `F_t K_A / b` \[N/m\] of the load factor (`None`: 100 N/mm or more, factor 1).
    ///
    /// Errors as [`IsoGearPair::validate`], [`MeshStiffnessWave::new`], [`ContactDamping::new`],
    /// `Parameter` for a line load that is not finite and > 0.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        z_sun: u32,
        z_planet: u32,
        module: f64,
        pressure_angle: f64,
        face_width: f64,
        ramp: f64,
        damping: &DampingSpec,
        line_load: Option<f64>,
    ) -> Result<Self> {
        let pair = IsoGearPair::spur(z_sun, z_planet, module, pressure_angle, face_width);
        let eps = spur_contact_ratio(z_sun, z_planet, module, pressure_angle)?;
        // ISO 6336-1 takes the line load in N/mm.
        if let Some(w) = line_load
            && !(w.is_finite() && w > 0.0)
        {
            return Err(RvdynError::Parameter(format!(
                "line_load must be a finite line load > 0 N/m (e.g. 1e5 N/m = 100 N/mm), got {w}"
            )));
        }
        let per_mm = line_load.map_or(100.0, |w| 1e-3 * w);
        let single = pair.to_newton_per_metre(pair.single_stiffness(per_mm)?);
        let wave = MeshStiffnessWave::new(single, eps, base_pitch(module, pressure_angle), ramp)?;
        Ok(Self {
            wave,
            damping: ContactDamping::new(damping)?,
        })
    }

    /// Force at the approach `pen` \[m\] (> 0), rate `rate` [m/s] and mesh position `s` \[m\]
    /// along the line of action, with the slope `dk/ds` [N/m^2] for the energy-consistent
    /// generalised force (`V = k(s) pen^2 / 2`, so `dV/ds = k'(s) pen^2 / 2`).
    #[inline]
    pub fn evaluate(&self, pen: f64, rate: f64, s: f64, want_energy: bool) -> (LawForce, f64) {
        let (k, dk) = self.wave.stiffness_and_slope(s);
        let fe = k * pen;
        (
            LawForce {
                force: self.damping.force(fe, k, rate),
                elastic: fe,
                energy: if want_energy { 0.5 * fe * pen } else { 0.0 },
            },
            dk,
        )
    }
}

/// The sun/planet mesh law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MeshLaw {
    /// ADAMS IMPACT along the line of action (the paper).
    Impact(ImpactLaw),
    /// ISO 6336 time-varying stiffness.
    Iso(IsoMesh),
}

impl MeshLaw {
    /// The IMPACT law, if this is one.
    pub fn impact(&self) -> Option<&ImpactLaw> {
        match self {
            MeshLaw::Impact(l) => Some(l),
            MeshLaw::Iso(_) => None,
        }
    }

    /// Force at the approach `pen` \[m\] (> 0), rate `rate` [m/s] and mesh position `s` \[m\],
    /// with the stiffness slope `dk/ds` [N/m^2] (0 for IMPACT, which does not vary with `s`).
    #[inline]
    pub fn evaluate(&self, pen: f64, rate: f64, s: f64, want_energy: bool) -> (LawForce, f64) {
        match self {
            MeshLaw::Impact(l) => (
                LawForce {
                    force: l.force(pen, rate),
                    elastic: l.elastic_force(pen),
                    energy: if want_energy {
                        l.elastic_energy(pen)
                    } else {
                        0.0
                    },
                },
                0.0,
            ),
            MeshLaw::Iso(m) => m.evaluate(pen, rate, s, want_energy),
        }
    }

    /// Mean stiffness [N/m] for reports: ISO's `c_gamma b`, or the IMPACT secant stiffness at
    /// the approach `pen` \[m\].
    pub fn mean_stiffness(&self, pen: f64) -> f64 {
        match self {
            MeshLaw::Impact(l) => {
                if pen > 0.0 {
                    l.elastic_force(pen) / pen
                } else {
                    0.0
                }
            }
            MeshLaw::Iso(m) => m.wave.mean(),
        }
    }
}

/// Check a material given in a scene: Young's modulus `youngs_modulus` `E` \[Pa\] (`> 0`) and
/// Poisson's ratio `poisson_ratio` `nu` [-] (`-1 < nu < 0.5`); an error (`Scene`) names the
/// contact family `family` (e.g. `"pin"`) as `contact.<family>`.
pub fn scene_material(family: &str, youngs_modulus: f64, poisson_ratio: f64) -> Result<Material> {
    Material::new(youngs_modulus, poisson_ratio)
        .map_err(|e| RvdynError::Scene(format!("contact.{family}: {e}")))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::cycloid::CycloidParams;

    #[test]
    fn line_pin_law_matches_the_line_contact_module() {
        let g = CycloidGeometry::new(CycloidParams::paper()).unwrap();
        let s = Material::steel();
        let damping = ContactDamping::new(&DampingSpec::DampingRatio {
            ratio: 0.05,
            frequency: 1000.0,
        })
        .unwrap();
        let law = PinLaw::Line {
            pin: s,
            disc: s,
            damping,
        };
        let phi = 0.72f64.acos() / 23.0;
        let site = PinSite {
            geometry: &g,
            phi,
            pin_radius: 0.010,
            depth: 0.14,
        };
        let r = law.evaluate(2.59e-5, 0.0, &site, true).unwrap();
        // The rated 25.9 um at the peak pin gives 35 kN back (to the rounding of 25.9).
        assert!((r.force - 35e3).abs() < 0.01 * 35e3, "{r:?}");
        assert_eq!(r.force, r.elastic);
        assert!(r.energy > 0.0);
        // Damping adds beta k rate, beta = 2 * 0.05 / (2 pi 1000).
        let d = law.evaluate(2.59e-5, 1e-3, &site, false).unwrap();
        let direct = LineContactLaw::cycloid_contact(&g, phi, 0.010, 0.14, &s, &s).unwrap();
        let (_, k) = direct.force_and_stiffness(2.59e-5);
        let beta = 0.1 / (2.0 * std::f64::consts::PI * 1000.0);
        assert!((d.force - d.elastic - beta * k * 1e-3).abs() < 1e-9 * d.force);
    }

    #[test]
    fn iso_mesh_law_of_the_paper_stage() {
        let mesh = |line_load: Option<f64>| {
            IsoMesh::new(
                18,
                42,
                3e-3,
                20f64.to_radians(),
                0.030,
                0.02,
                &DampingSpec::DampingRatio {
                    ratio: 0.05,
                    frequency: 1000.0,
                },
                line_load,
            )
        };
        let m = mesh(None).unwrap();
        assert!((m.wave.mean() / 5.546e8 - 1.0).abs() < 1e-3);
        // ISO 6336-1: at or above 100 N/mm the full c'; below, c' (w / 100 N/mm)^(1/4).
        assert_eq!(mesh(Some(2e5)).unwrap().wave.mean(), m.wave.mean());
        let light = mesh(Some(29e3)).unwrap().wave.mean();
        assert!((light / m.wave.mean() - 0.29f64.powf(0.25)).abs() < 1e-12);
        for bad in [0.0, -1.0, f64::NAN] {
            assert!(matches!(mesh(Some(bad)), Err(RvdynError::Parameter(_))));
        }
        let law = MeshLaw::Iso(m);
        assert_eq!(law.mean_stiffness(0.0), m.wave.mean());
        let (f, _) = m.evaluate(1e-5, 0.0, 0.004, true);
        assert!((f.energy - 0.5 * f.elastic * 1e-5).abs() < 1e-12);
    }

    #[test]
    fn single_pin_radius_error_changes_only_that_pins_gap() {
        // Scene pin errors reach the models' pins: +3 um on pin 6 changes its penetration by
        // 3 um (to 1e-12 m) and no other pin's, at several poses of both discs.
        use crate::dynamics::Scene;
        use crate::dynamics::model::pin_contact::{DiscPose, WarmStart, pin_query};
        use crate::dynamics::model::rigid::RigidModel;
        let s0 = Scene::paper("idle").unwrap();
        let mut s1 = s0.clone();
        let mut radius = vec![0.0; 24];
        radius[5] = 3e-6;
        s1.pin_errors.radius = radius;
        let (m0, m1) = (RigidModel::new(&s0).unwrap(), RigidModel::new(&s1).unwrap());
        for psi in [0.0, 0.1, 0.2] {
            for k in 0..2 {
                let (o, th) = m0.disc_pose(k, &[0.0, psi, 0.0]);
                let pose = DiscPose::new(o, th - psi / 23.0);
                for j in 0..24 {
                    let w = std::cell::Cell::new(WarmStart::default());
                    let g0 = pin_query(
                        &m0.parts.discs[k],
                        &m0.parts.pins[j],
                        &pose,
                        0.0,
                        (k, j),
                        &w,
                    )
                    .unwrap();
                    let w = std::cell::Cell::new(WarmStart::default());
                    let g1 = pin_query(
                        &m1.parts.discs[k],
                        &m1.parts.pins[j],
                        &pose,
                        0.0,
                        (k, j),
                        &w,
                    )
                    .unwrap();
                    let change = g1.penetration - g0.penetration;
                    let want = if j == 5 { 3e-6 } else { 0.0 };
                    assert!((change - want).abs() < 1e-12, "pin {j}: {change}");
                }
            }
        }
    }

    #[test]
    fn damping_specs_round_trip_and_validate() {
        let spec = DampingSpec::Restitution {
            model: HysteresisModel::LankaraniNikravesh,
            restitution: 0.8,
            reference_speed: 0.1,
        };
        let text = serde_json::to_string(&spec).unwrap();
        assert!(text.contains("\"lankarani-nikravesh\""), "{text}");
        let back: DampingSpec = serde_json::from_str(&text).unwrap();
        assert_eq!(back, spec);
        assert!(
            ContactDamping::new(&DampingSpec::Restitution {
                model: HysteresisModel::Exact,
                restitution: 1.5,
                reference_speed: 0.1
            })
            .is_err()
        );
        assert!(
            ContactDamping::new(&DampingSpec::DampingRatio {
                ratio: -0.1,
                frequency: 1e3
            })
            .is_err()
        );
        assert!(
            ContactDamping::new(&DampingSpec::DampingRatio {
                ratio: 0.05,
                frequency: 0.0
            })
            .is_err()
        );
        assert!(scene_material("pin", 2e11, 0.7).is_err());
    }
}
