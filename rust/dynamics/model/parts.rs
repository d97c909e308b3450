//! The parts of a reducer model shared by the rigid and the compliant model: discs, pins,
//! first-stage meshes, force laws, mass properties, drive and load, built once from a scene.

use crate::contact::friction::{CoulombFriction, ToothPath};
use crate::contact::law::{MeshLaw, PinLaw};
use crate::dynamics::model::Layout;
use crate::dynamics::model::drive::DriveProfile;
use crate::dynamics::scene::{GearError, Initial, Load, ProfileError, Scene, Shaft};
use crate::error::{Result, RvdynError};
use crate::geometry::CycloidGeometry;
use crate::geometry::mass::{DiscHoles, MassProperties, disc_mass_properties, solid_cylinder};

/// One disc of the model.
#[derive(Debug, Clone)]
pub(crate) struct DiscModel {
    pub(crate) geometry: CycloidGeometry,
    /// Eccentric phase on the crank \[rad\].
    pub(crate) phase: f64,
    /// Disc angle offset from the carrier angle, `-phase / zc` \[rad\].
    pub(crate) angle_offset: f64,
    /// Cosine and sine of `phase` and of `angle_offset`: a disc's pose turns the crank's and
    /// the carrier's by them (the trigonometry of an evaluation is then shared by the discs).
    pub(crate) phase_cs: [f64; 2],
    pub(crate) offset_cs: [f64; 2],
    /// Body depth of the disc for the line contact law \[m\]: pin circle radius minus pin
    /// radius (about the distance from the disc centre to a contact).
    pub(crate) body_depth: f64,
    /// Profile error (normal offset of the ground profile), `None` when there is none.
    pub(crate) profile_error: Option<ProfileError>,
}

/// One fixed pin.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PinModel {
    pub(crate) centre: [f64; 2],
    pub(crate) radius: f64,
    /// Nominal angle of the pin on the pin circle \[rad\] (the kinematic seed of its contact).
    pub(crate) angle: f64,
}

/// The sun/planet meshes of the first stage.
#[derive(Debug, Clone, Copy)]
pub(crate) struct MeshModel {
    pub(crate) sun_base_radius: f64,
    pub(crate) planet_base_radius: f64,
    /// Total backlash along the line of action \[m\].
    pub(crate) backlash: f64,
    pub(crate) law: MeshLaw,
    pub(crate) count: usize,
    /// Mesh phase of each planet, fraction of a base pitch (`gear::planet_mesh_phases`).
    pub(crate) phases: [f64; MAX_PLANETS],
    /// Base pitch \[m\].
    pub(crate) base_pitch: f64,
    /// Path of contact for tooth friction.
    pub(crate) path: ToothPath,
}

/// Most planets a stage may have (a fixed array keeps `MeshModel` `Copy`).
pub(crate) const MAX_PLANETS: usize = 16;

/// Mass properties actually used by a model (computed or from the scene).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ModelInertias {
    pub(crate) sun: MassProperties,
    pub(crate) crank: MassProperties,
    pub(crate) disc: MassProperties,
    pub(crate) carrier: MassProperties,
    pub(crate) load_inertia: f64,
    pub(crate) motor_inertia: f64,
}

/// The bodies, contacts, laws, inertias, drive and load of a scene.
#[derive(Debug, Clone)]
pub struct Parts {
    /// The discs.
    pub(crate) discs: Vec<DiscModel>,
    /// The fixed pins.
    pub(crate) pins: Vec<PinModel>,
    /// Law of the pin / profile contacts.
    pub(crate) pin_law: PinLaw,
    /// Pin friction (coefficient already multiplied by the rolling-pin lever ratio).
    pub(crate) pin_friction: Option<CoulombFriction>,
    /// Tooth friction of the sun/planet meshes.
    pub(crate) mesh_friction: Option<CoulombFriction>,
    /// The first-stage meshes, if any.
    pub(crate) mesh: Option<MeshModel>,
    /// Number of crankshafts.
    pub(crate) cranks: usize,
    /// Distance of the crank axes from the reducer axis \[m\].
    pub(crate) crank_radius: f64,
    /// Eccentricity \[m\].
    pub(crate) eccentricity: f64,
    /// Mass properties used.
    pub(crate) inertias: ModelInertias,
    /// The input drive.
    pub(crate) drive: DriveProfile,
    /// The output load.
    pub(crate) load: Load,
    /// Transmission ratio.
    pub(crate) ratio: f64,
    /// Initial state.
    pub(crate) initial: Initial,
    /// Penetration beyond which a run is declared unstable \[m\].
    pub(crate) max_penetration: f64,
    /// Largest distance of a profile point from its disc centre \[m\].
    pub(crate) profile_reach: f64,
    /// Output shaft between the carrier and the load inertia (`None`: rigid).
    pub(crate) output_shaft: Option<Shaft>,
    /// Drive shaft between the motor and the sun (`None`: rigid).
    pub(crate) input_shaft: Option<Shaft>,
    /// Runout and pitch errors of the first-stage gears (`None`: perfect gears).
    pub(crate) mesh_errors: Option<MeshErrors>,
}

impl Parts {
    /// Build the parts of a validated scene.
    pub(crate) fn new(scene: &Scene) -> Result<Self> {
        let cyc = scene.cycloid;
        let zp = cyc.pins as usize;
        let zc = (cyc.pins - 1) as f64;
        let mut discs = Vec::with_capacity(scene.discs.len());
        for (k, d) in scene.discs.iter().enumerate() {
            let angle_offset = -d.phase / zc;
            let ((sp, cp), (so, co)) = (d.phase.sin_cos(), angle_offset.sin_cos());
            discs.push(DiscModel {
                geometry: CycloidGeometry::new(scene.disc_params(k))?,
                phase: d.phase,
                angle_offset,
                phase_cs: [cp, sp],
                offset_cs: [co, so],
                body_depth: cyc.pin_circle_radius - cyc.pin_radius,
                profile_error: d.profile_error.clone().filter(|p| !p.is_empty()),
            });
        }
        let pins = (0..zp)
            .map(|j| {
                let th = std::f64::consts::TAU * j as f64 / zp as f64;
                let dp = scene
                    .pin_errors
                    .position
                    .get(j)
                    .copied()
                    .unwrap_or([0.0, 0.0]);
                let dr = scene.pin_errors.radius.get(j).copied().unwrap_or(0.0);
                PinModel {
                    centre: [
                        cyc.pin_circle_radius * th.cos() + dp[0],
                        cyc.pin_circle_radius * th.sin() + dp[1],
                    ],
                    radius: cyc.pin_radius + dr,
                    angle: th,
                }
            })
            .collect();
        let pin_law = scene.contact.pin.pin_law(cyc.face_width)?;
        let mesh = match &scene.stage1 {
            Some(s) => {
                let count = s.planets as usize;
                if count > MAX_PLANETS {
                    return Err(RvdynError::Scene(format!(
                        "stage1.planets = {count} exceeds the model's limit of {MAX_PLANETS}"
                    )));
                }
                let mut phases = [0.0; MAX_PLANETS];
                let ph = crate::gear::planet_mesh_phases(s.z_sun, &s.planet_angles())?;
                phases[..count].copy_from_slice(&ph);
                let pb = crate::gear::iso6336::base_pitch(s.module, s.pressure_angle);
                Some(MeshModel {
                    sun_base_radius: s.sun_base_radius(),
                    planet_base_radius: s.planet_base_radius(),
                    backlash: s.backlash,
                    law: scene.stage_mesh_law(s)?,
                    count,
                    phases,
                    base_pitch: pb,
                    path: ToothPath::new(
                        s.sun_base_radius(),
                        s.planet_base_radius(),
                        s.planet_tip_radius(),
                        s.pressure_angle,
                        pb,
                        s.contact_ratio(),
                    ),
                })
            }
            None => None,
        };
        let crank_radius = scene.stage1.as_ref().map_or(0.09, |s| s.centre_distance());
        let inertias = default_inertias(scene, &discs[0].geometry, crank_radius)?;
        Ok(Self {
            discs,
            pins,
            pin_law,
            pin_friction: (scene.friction.pin > 0.0)
                .then(|| {
                    CoulombFriction::new(
                        scene.friction.pin * scene.friction.pin_rolling.unwrap_or(1.0),
                        scene.friction.regularisation_speed,
                    )
                })
                .transpose()?,
            mesh_friction: (scene.friction.mesh > 0.0)
                .then(|| {
                    CoulombFriction::new(scene.friction.mesh, scene.friction.regularisation_speed)
                })
                .transpose()?,
            mesh,
            cranks: scene.cranks as usize,
            crank_radius,
            eccentricity: cyc.eccentricity,
            inertias,
            drive: DriveProfile::new(&scene.drive),
            load: scene.load.clone(),
            ratio: scene.ratio(),
            initial: scene.initial,
            // A tenth of the pin radius is far beyond any elastic approach of steel.
            max_penetration: 0.1 * cyc.pin_radius,
            profile_reach: (0..scene.discs.len())
                .map(|k| {
                    let p = scene.disc_params(k);
                    p.pin_circle_radius + p.d_rp + p.eccentricity - p.pin_radius - p.d_rrp
                })
                .fold(0.0, f64::max)
                * 1.000_001
                // A profile error moves the profile outwards by at most its bound.
                + scene
                    .discs
                    .iter()
                    .filter_map(|d| d.profile_error.as_ref())
                    .map(|p| {
                        p.harmonics.iter().map(|h| h[0].abs()).sum::<f64>()
                            + p.table.iter().map(|q| q[1].abs()).fold(0.0, f64::max)
                    })
                    .fold(0.0, f64::max),
            output_shaft: scene.shafts.output,
            input_shaft: scene.shafts.input,
            mesh_errors: match &scene.stage1 {
                Some(s) if scene.gear_errors.any() => Some(MeshErrors::new(scene, s)),
                _ => None,
            },
        })
    }

    /// Load torque acting on the carrier at `t` [N m]: the scene's load, or 0 when an output
    /// shaft carries it to the load inertia.
    #[inline]
    pub(crate) fn carrier_load(&self, t: f64) -> f64 {
        if self.output_shaft.is_some() {
            0.0
        } else {
            self.load.torque(t)
        }
    }

    /// Drive torque acting on the reducer's input at `t` [N m] (torque drive without a drive
    /// shaft), else `None`.
    #[inline]
    pub(crate) fn input_drive_torque(&self, t: f64) -> Option<f64> {
        if self.input_shaft.is_some() {
            None
        } else {
            self.drive.torque(t)
        }
    }

    /// Torques of the output and drive shafts at `t` from (angle \[rad\], speed [rad/s]) of
    /// the carrier, the reducer input (sun), the load and the motor (docs/model.md#machine-shafts).
    pub(crate) fn shaft_loads(
        &self,
        t: f64,
        carrier: [f64; 2],
        input: [f64; 2],
        load: [f64; 2],
        motor: [f64; 2],
    ) -> ShaftLoads {
        let mut out = ShaftLoads::default();
        if let Some(sh) = &self.output_shaft {
            let (tw, rate) = (carrier[0] - load[0], carrier[1] - load[1]);
            let tq = sh.stiffness * tw + sh.damping * rate;
            out.carrier -= tq;
            out.load += tq - self.load.torque(t);
            out.output_torque = tq;
            out.potential += 0.5 * sh.stiffness * tw * tw;
            out.dissipation += sh.damping * rate * rate;
        }
        if let Some(sh) = &self.input_shaft {
            let (tw, rate) = (motor[0] - input[0], motor[1] - input[1]);
            let tq = sh.stiffness * tw + sh.damping * rate;
            out.input += tq;
            out.motor -= tq;
            if let Some(d) = self.drive.torque(t) {
                out.motor += d;
            }
            out.input_torque = tq;
            out.potential += 0.5 * sh.stiffness * tw * tw;
            out.dissipation += sh.damping * rate * rate;
        }
        out
    }

    /// Sizes of the bodies and contacts (the shapes of recorded arrays).
    pub(crate) fn layout(&self) -> Layout {
        Layout {
            discs: self.discs.len(),
            pins: self.pins.len(),
            cranks: self.cranks,
            meshes: self.mesh.map_or(0, |m| m.count),
        }
    }

    /// Number of lobes `zc`.
    pub(crate) fn zc(&self) -> f64 {
        f64::from(self.discs[0].geometry.lobes())
    }
}

/// Mass properties from the scene or from simple steel solids (stated in each line).
fn default_inertias(
    scene: &Scene,
    disc: &CycloidGeometry,
    crank_radius: f64,
) -> Result<ModelInertias> {
    let rho = scene.density;
    let i = &scene.inertias;
    let (sun_r, planet_r, gear_w) = scene.stage1.as_ref().map_or((0.027, 0.063, 0.03), |s| {
        (s.sun_pitch_radius(), s.planet_pitch_radius(), s.face_width)
    });
    // Sun: gear cylinder at its pitch radius, plus a 20 mm radius, 150 mm input shaft.
    let sun = i.sun.unwrap_or_else(|| {
        add(
            solid_cylinder(sun_r, gear_w, rho),
            solid_cylinder(0.020, 0.150, rho),
        )
    });
    // Crank: planet gear cylinder at its pitch radius, plus a 25 mm radius, 150 mm crankshaft.
    let crank = i.crank.unwrap_or_else(|| {
        add(
            solid_cylinder(planet_r, gear_w, rho),
            solid_cylinder(0.025, 0.150, rho),
        )
    });
    let disc_mp = match i.disc {
        Some(d) => d,
        None => disc_mass_properties(disc, &DiscHoles::paper(), rho)?,
    };
    // Carrier: two end plates of radius rp - rrp - 10 mm, 30 mm thick.
    let plate_r = scene.cycloid.pin_circle_radius - scene.cycloid.pin_radius - 0.010;
    let carrier = i.carrier.unwrap_or_else(|| {
        let p = solid_cylinder(plate_r.max(crank_radius), 0.030, rho);
        add(p, p)
    });
    Ok(ModelInertias {
        sun,
        crank,
        disc: disc_mp,
        carrier,
        load_inertia: i.load_inertia,
        motor_inertia: i.motor_inertia,
    })
}

fn add(a: MassProperties, b: MassProperties) -> MassProperties {
    MassProperties {
        mass: a.mass + b.mass,
        inertia: a.inertia + b.inertia,
    }
}

/// Generalised forces and energy of the machine shafts (see [`Parts::shaft_loads`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct ShaftLoads {
    /// Torque on the carrier [N m].
    pub(crate) carrier: f64,
    /// Torque on the reducer input (sun) [N m].
    pub(crate) input: f64,
    /// Torque on the load inertia (shaft minus load torque) [N m].
    pub(crate) load: f64,
    /// Torque on the motor (drive minus shaft torque) [N m].
    pub(crate) motor: f64,
    /// Torque in the output shaft, `k_o (th_c - th_L) + c_o (w_c - w_L)` [N m].
    pub(crate) output_torque: f64,
    /// Torque in the drive shaft, `k_i (th_m - th_s) + c_i (w_m - w_s)` [N m].
    pub(crate) input_torque: f64,
    /// Elastic energy of the shafts \[J\].
    pub(crate) potential: f64,
    /// Power dissipated by the shaft damping \[W\].
    pub(crate) dissipation: f64,
}

/// Runout and pitch errors of the first-stage gears as an extra approach of each mesh flank
/// (docs/model.md#manufacturing-errors-of-profile-and-gears).
#[derive(Debug, Clone)]
pub(crate) struct MeshErrors {
    sun: GearModelError,
    planets: Vec<GearModelError>,
    /// Angle of each planet on the carrier \[rad\].
    gamma: Vec<f64>,
    pressure_angle: f64,
    cos_pa: f64,
}

/// One gear's errors, with its pitch table at the tooth angles.
#[derive(Debug, Clone, Default)]
struct GearModelError {
    runout: f64,
    runout_phase: f64,
    pitch_amplitude: f64,
    pitch_phase: f64,
    table: Vec<[f64; 2]>,
}

impl GearModelError {
    fn new(g: &GearError) -> Self {
        let z = g.pitch_deviation.len() as f64;
        Self {
            runout: g.runout,
            runout_phase: g.runout_phase,
            pitch_amplitude: g.pitch_amplitude,
            pitch_phase: g.pitch_phase,
            table: g
                .pitch_deviation
                .iter()
                .enumerate()
                .map(|(k, &f)| [std::f64::consts::TAU * k as f64 / z, f])
                .collect(),
        }
    }

    /// Cumulative pitch deviation \[m\] and its slope [m/rad] at body angle `psi`.
    fn pitch(&self, psi: f64) -> (f64, f64) {
        let (s, c) = (psi + self.pitch_phase).sin_cos();
        let (t, ts) = crate::geometry::cycloid::periodic_table(&self.table, psi);
        (self.pitch_amplitude * s + t, self.pitch_amplitude * c + ts)
    }

    /// Second derivative of the cumulative pitch deviation [m/rad^2] at body angle `psi`:
    /// the sinusoid's (the table is linear between teeth).
    fn pitch_curvature(&self, psi: f64) -> f64 {
        -self.pitch_amplitude * (psi + self.pitch_phase).sin()
    }
}

/// Extra approach of one mesh flank \[m\] and its derivatives by the carrier, sun and crank
/// angles [m/rad].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct MeshOffset {
    pub(crate) value: f64,
    pub(crate) carrier: f64,
    pub(crate) sun: f64,
    pub(crate) crank: f64,
}

impl MeshOffset {
    /// Rate of the offset for the speeds of carrier, sun and crank [m/s].
    #[inline]
    pub(crate) fn rate(&self, vc: f64, vs: f64, va: f64) -> f64 {
        self.carrier * vc + self.sun * vs + self.crank * va
    }
}

impl MeshErrors {
    fn new(scene: &Scene, s: &crate::geometry::involute::InvoluteStage) -> Self {
        let g = &scene.gear_errors;
        let n = s.planets as usize;
        Self {
            sun: GearModelError::new(&g.sun),
            planets: (0..n)
                .map(|i| {
                    g.planets
                        .get(i)
                        .map(GearModelError::new)
                        .unwrap_or_default()
                })
                .collect(),
            gamma: s.planet_angles(),
            pressure_angle: s.pressure_angle,
            cos_pa: s.pressure_angle.cos(),
        }
    }

    /// Extra approach of flank `sign` (+1 drive, -1 coast) of mesh `i` at carrier angle
    /// `th_c` (argument `thc`), sun angle `th_s` (`ths`) and absolute crank angle `alpha`
    /// \[rad\]:
    ///
    /// ```text
    /// E = sign cos(pa) (F_s(th_c + g_i - th_s) + F_p(th_c + g_i + pi - alpha))
    ///     + e_s cos(th_s + p_s - psi) - e_p cos(alpha + p_p - psi)
    /// ```
    ///
    /// with `psi = th_c + g_i + sign (pi/2 - pa)` the direction of the flank's line of action.
    pub(crate) fn offset(&self, i: usize, sign: f64, thc: f64, ths: f64, alpha: f64) -> MeshOffset {
        use std::f64::consts::{FRAC_PI_2, PI};
        let g = self.gamma[i];
        let p = &self.planets[i];
        let (fs, fs1) = self.sun.pitch(thc + g - ths);
        let (fp, fp1) = p.pitch(thc + g + PI - alpha);
        let psi = thc + g + sign * (FRAC_PI_2 - self.pressure_angle);
        let (ss, cs) = (ths + self.sun.runout_phase - psi).sin_cos();
        let (sp, cp) = (alpha + p.runout_phase - psi).sin_cos();
        let (es, ep) = (self.sun.runout, p.runout);
        let k = sign * self.cos_pa;
        MeshOffset {
            value: k * (fs + fp) + es * cs - ep * cp,
            carrier: k * (fs1 + fp1) + es * ss - ep * sp,
            sun: -k * fs1 - es * ss,
            crank: -k * fp1 + ep * sp,
        }
    }

    /// Hessian of [`MeshErrors::offset`] by (carrier, sun, crank) angles [m/rad^2] (the
    /// quasi-static tangent's curvature term; a pitch table is linear between teeth).
    pub(crate) fn offset_hessian(
        &self,
        i: usize,
        sign: f64,
        thc: f64,
        ths: f64,
        alpha: f64,
    ) -> [[f64; 3]; 3] {
        use std::f64::consts::{FRAC_PI_2, PI};
        let g = self.gamma[i];
        let p = &self.planets[i];
        let psi = thc + g + sign * (FRAC_PI_2 - self.pressure_angle);
        let k = sign * self.cos_pa;
        // Each term is a function of one combination of the angles with gradient `u`:
        // its Hessian is (second derivative) u u^T.
        let terms = [
            (
                k * self.sun.pitch_curvature(thc + g - ths),
                [1.0, -1.0, 0.0],
            ),
            (
                k * p.pitch_curvature(thc + g + PI - alpha),
                [1.0, 0.0, -1.0],
            ),
            (
                -self.sun.runout * (ths + self.sun.runout_phase - psi).cos(),
                [-1.0, 1.0, 0.0],
            ),
            (
                p.runout * (alpha + p.runout_phase - psi).cos(),
                [-1.0, 0.0, 1.0],
            ),
        ];
        let mut h = [[0.0; 3]; 3];
        for (c, u) in terms {
            for (a, row) in h.iter_mut().enumerate() {
                for (b, v) in row.iter_mut().enumerate() {
                    *v += c * u[a] * u[b];
                }
            }
        }
        h
    }
}

#[cfg(test)]
mod tests {
    //! Machine shafts, profile errors and gear errors (docs/model.md#machine-shafts,
    //! docs/model.md#manufacturing-errors-of-profile-and-gears).
    use super::*;
    use crate::dynamics::model::ReducerModel;
    use crate::dynamics::model::compliant::CompliantModel;
    use crate::dynamics::model::pin_contact::{DiscPose, WarmStart, pin_query};
    use crate::dynamics::model::rigid::{CARRIER, CRANK, FULL, LOAD, MOTOR, RigidModel, SUN};
    use crate::dynamics::model::rigid_system::RigidSystem;
    use crate::dynamics::run::sink::ContactSink;
    use crate::dynamics::scene::{Drive, GearErrors, Shafts};
    use std::cell::Cell;
    use std::f64::consts::{PI, TAU};

    /// Wants the elastic energy; counts loaded pins; keeps mesh deflections.
    #[derive(Default)]
    struct Probe {
        pins: usize,
        mesh: Vec<(f64, f64)>,
    }
    impl ContactSink for Probe {
        fn wants_energy(&self) -> bool {
            true
        }
        fn pin(&mut self, _: usize, _: usize, f: f64, _: f64, _: f64, _: [f64; 2], _: [f64; 2]) {
            self.pins += usize::from(f > 0.0);
        }
        fn mesh(&mut self, _: usize, f: f64, d: f64) {
            self.mesh.push((f, d));
        }
    }

    fn profile(harmonics: Vec<[f64; 3]>, table: Vec<[f64; 2]>) -> Option<ProfileError> {
        Some(ProfileError { harmonics, table })
    }

    /// Penetration of every pin into disc 0 at the kinematic pose turned by `turn` \[rad\].
    fn penetrations(scene: &Scene, turn: f64) -> Vec<(f64, f64)> {
        let p = Parts::new(scene).unwrap();
        let d = &p.discs[0];
        let pose = DiscPose::new([p.eccentricity, 0.0], d.angle_offset + turn);
        p.pins
            .iter()
            .enumerate()
            .map(|(j, pin)| {
                let w = Cell::new(WarmStart::default());
                let c = pin_query(d, pin, &pose, 0.0, (0, j), &w).unwrap();
                (c.penetration, c.phi)
            })
            .collect()
    }

    #[test]
    fn a_constant_profile_offset_changes_every_gap_by_minus_a() {
        // Closed form: a normal offset a of the whole profile is an equidistant curve, the
        // profile of the equidistant modification d_rrp = -a: every gap shrinks by a. Against
        // the nominal disc: the same foot, so exact to one rounding (1e-18 m); against the
        // d_rrp = -a disc (its own Newton solve): the 1e-13 m Newton tolerance.
        let a = 7e-6;
        let nominal = Scene::paper("idle").unwrap();
        let mut offset = nominal.clone();
        offset.discs[0].profile_error = profile(vec![[a, 0.0, 0.0]], vec![]);
        let mut equidistant = nominal.clone();
        equidistant.discs[0].d_rrp = Some(-a);
        for turn in [0.0, -1e-4, 3e-3] {
            let (p0, p1, p2) = (
                penetrations(&nominal, turn),
                penetrations(&offset, turn),
                penetrations(&equidistant, turn),
            );
            for j in 0..p0.len() {
                assert!((p1[j].0 - p0[j].0 - a).abs() < 1e-18, "pin {j}");
                assert!((p1[j].0 - p2[j].0).abs() < 1e-12, "pin {j}");
            }
        }
    }

    /// Exact signed gap of a pin (centre `c` \[m\], radius `r`) to the offset profile
    /// `P(phi) + delta(phi) n(phi)` of disc `g` (disc frame, no rotation modification) by a
    /// dense scan and golden-section refinement around `phi0`: independent of the model's
    /// first-order formula.
    fn brute_gap(
        g: &crate::geometry::CycloidGeometry,
        pe: &ProfileError,
        c: [f64; 2],
        r: f64,
        phi0: f64,
    ) -> f64 {
        let dist = |phi: f64| {
            let p = g.profile_point(phi);
            let n = g.normal(phi);
            let d = pe.offset(phi).0;
            let q = [p[0] + d * n[0], p[1] + d * n[1]];
            (q[0] - c[0]).hypot(q[1] - c[1])
        };
        let (mut lo, mut hi) = (phi0 - 0.02, phi0 + 0.02);
        let mut best = phi0;
        for i in 0..=4000 {
            let phi = lo + (hi - lo) * f64::from(i) / 4000.0;
            if dist(phi) < dist(best) {
                best = phi;
            }
        }
        (lo, hi) = (best - 1e-5, best + 1e-5);
        let gr = 0.5 * (5f64.sqrt() - 1.0);
        for _ in 0..200 {
            let (x1, x2) = (hi - gr * (hi - lo), lo + gr * (hi - lo));
            if dist(x1) < dist(x2) {
                hi = x2;
            } else {
                lo = x1;
            }
        }
        // The pin centre is outside the disc here (a gap or a small penetration).
        dist(0.5 * (lo + hi)) - r
    }

    #[test]
    fn a_harmonic_profile_error_changes_each_gap_by_its_value_at_the_contact() {
        // First-order effect: the gap at pin j changes by -delta(phi_j), phi_j the contact's
        // curve parameter. Checked against the exact distance to the offset curve (brute
        // force): the first-order model neglects the foot's shift along the curve, of order
        // delta'^2 / |C'| ~ (5 um * 23)^2 / 0.15 m ~ 1e-7 um; tolerance 1e-10 m against an
        // effect of up to 5 um.
        let a = 5e-6;
        let mut s = Scene::paper("idle").unwrap();
        let pe = ProfileError {
            harmonics: vec![[a, 23.0, 0.7], [2e-6, 3.0, -1.0]],
            table: vec![[0.0, 1e-6], [2.0, -1e-6], [4.0, 0.5e-6]],
        };
        s.discs[0].profile_error = Some(pe.clone());
        let nominal = Scene::paper("idle").unwrap();
        let p = Parts::new(&s).unwrap();
        let g = &p.discs[0].geometry;
        let d = &p.discs[0];
        let turn = 2e-3;
        let (p0, p1) = (penetrations(&nominal, turn), penetrations(&s, turn));
        let th = d.angle_offset + turn;
        let mut largest: f64 = 0.0;
        let mut worst: f64 = 0.0;
        for j in 0..p0.len() {
            let want = pe.offset(p0[j].1).0;
            assert!((p1[j].0 - p0[j].0 - want).abs() < 1e-18, "pin {j}");
            // The pin centre in the disc frame.
            let pc = p.pins[j].centre;
            let dx = [pc[0] - p.eccentricity, pc[1]];
            let (sn, cs) = th.sin_cos();
            let local = [cs * dx[0] + sn * dx[1], -sn * dx[0] + cs * dx[1]];
            let exact = brute_gap(g, &pe, local, p.pins[j].radius, p0[j].1);
            // Second-order bound: the offset's slope along the arc, delta_s = delta' / |P'|,
            // moves the foot and lowers the distance by delta_s^2 / (2 A), A = 1/D + kappa
            // the second derivative of the distance along the profile (D: pin centre to
            // profile, kappa: profile curvature, convex positive); twice that, plus 1e-12 m.
            let phi = p0[j].1;
            let j1 = g.jet(phi);
            // Arc length of the profile per radian: |P'| = |C'| (1 - r kappa_C).
            let arc = j1.d1[0].hypot(j1.d1[1])
                * (1.0 - g.generating_pin_radius() * g.centre_curve_curvature(phi));
            let ds = pe.offset(phi).1 / arc;
            let dist = p.pins[j].radius - p0[j].0;
            let a_dd = 1.0 / dist + 1.0 / g.curvature_radius(phi);
            assert!(a_dd > 0.0);
            let bound = ds * ds / a_dd + 1e-12;
            let err = (-p1[j].0 - exact).abs();
            assert!(
                err <= bound,
                "pin {j}: first order {:e}, exact {exact:e}, bound {bound:e}",
                -p1[j].0
            );
            worst = worst.max(err);
            largest = largest.max(want.abs());
        }
        assert!(largest > 3e-6, "{largest}");
        // The first-order model is good to about a thousandth of the effect here.
        assert!(worst < 1e-3 * largest, "{worst:e} of {largest:e}");
    }

    fn errors_scene(torque_drive: bool) -> Scene {
        let mut s = Scene::paper("idle").unwrap();
        s.discs[0].profile_error = profile(vec![[4e-6, 23.0, 0.3]], vec![[0.0, 1e-6], [3.0, 0.0]]);
        s.discs[1].profile_error = profile(vec![[2e-6, 46.0, 1.3]], vec![]);
        let g = |e: f64, ph: f64| GearError {
            runout: e,
            runout_phase: ph,
            pitch_amplitude: 3e-6,
            pitch_phase: 0.4 + ph,
            pitch_deviation: vec![],
        };
        let mut sun = g(1e-5, 0.2);
        sun.pitch_deviation = (0..18).map(|k| 1e-6 * (k as f64 * 0.7).sin()).collect();
        s.gear_errors = GearErrors {
            sun,
            planets: vec![g(5e-6, 0.0), g(2e-6, 1.0), g(0.0, 2.0)],
        };
        s.inertias.load_inertia = 3.0;
        s.inertias.motor_inertia = 0.02;
        s.shafts = Shafts {
            output: Some(Shaft {
                stiffness: 2e6,
                damping: 50.0,
            }),
            input: Some(Shaft {
                stiffness: 3e4,
                damping: 0.2,
            }),
        };
        if torque_drive {
            s.drive = Drive::Torque {
                torque: 0.0,
                ramp_time: 0.0,
            };
        }
        s.validate().unwrap();
        s
    }

    #[test]
    fn rigid_forces_are_minus_the_energy_gradient_with_shafts_and_errors() {
        // At rest (no damping force) every generalised force is -dV/dq: the profile error's
        // foot term, the gear errors' gradients and the shafts are consistent with their
        // energies. Central differences at 1 nm of lever; tolerance 1e-6 of the largest force
        // (difference error ~ eps V / h).
        let s = errors_scene(true);
        let m = RigidModel::new(&s).unwrap();
        let sys = RigidSystem::new(&m);
        assert_eq!(sys.coords, vec![CARRIER, CRANK, SUN, LOAD, MOTOR]);
        let (mut q, _) = sys.initial_state();
        let v = vec![0.0; q.len()];
        q[0] += 1e-5; // carrier: pins loaded
        q[2] += 1e-3; // sun ahead: meshes loaded
        q[3] -= 2e-4; // load behind: output shaft twisted
        q[4] += 5e-3; // motor ahead: drive shaft twisted
        let energy = |q: &[f64]| {
            let (x, xv, _) = sys.full(0.0, q, &v);
            let (f, _, sh) = sys.all_forces(0.0, &x, &xv, &mut Probe::default()).unwrap();
            f.potential + sh.potential
        };
        let mut qf = vec![0.0; q.len()];
        sys.generalized_force(0.0, &q, &v, &mut qf).unwrap();
        let mut probe = Probe::default();
        let (x, xv, _) = sys.full(0.0, &q, &v);
        sys.all_forces(0.0, &x, &xv, &mut probe).unwrap();
        assert!(probe.pins >= 4, "{}", probe.pins);
        assert!(probe.mesh.iter().all(|m| m.0 > 0.0));
        let fmax = qf.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        for (k, &i) in sys.coords.iter().enumerate() {
            let h = 1e-9 / m.length_scale[i];
            let (mut qp, mut qm) = (q.clone(), q.clone());
            qp[k] += h;
            qm[k] -= h;
            let grad = (energy(&qp) - energy(&qm)) / (2.0 * h);
            assert!(
                (qf[k] + grad).abs() <= 1e-6 * fmax,
                "coordinate {i}: Q {} -dV/dq {}",
                qf[k],
                -grad
            );
        }
    }

    #[test]
    fn compliant_forces_are_minus_the_energy_gradient_with_shafts_and_errors() {
        let mut s = errors_scene(true);
        s.joints = crate::dynamics::model::compliant::default_joints();
        let m = CompliantModel::new(&s).unwrap();
        let (mut x, _) = m.full_initial_state();
        let (li, mi) = (m.load_index.unwrap(), m.motor_index.unwrap());
        assert!(m.coords.contains(&li) && m.coords.contains(&mi));
        assert!(!m.free.contains(&li) && !m.free.contains(&mi));
        let v = vec![0.0; x.len()];
        x[0] += 1e-5;
        x[1] += 1e-3;
        x[li] -= 2e-4;
        x[mi] += 5e-3;
        let energy = |x: &[f64]| {
            let mut q = vec![0.0; x.len()];
            m.forces(0.0, x, &v, &mut q, &mut Probe::default())
                .unwrap()
                .potential
        };
        let mut qf = vec![0.0; x.len()];
        let mut probe = Probe::default();
        m.forces(0.0, &x, &v, &mut qf, &mut probe).unwrap();
        assert!(probe.pins >= 4 && probe.mesh.iter().all(|m| m.0 > 0.0));
        let fmax = qf.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        for &i in &m.coords {
            use crate::solve::MechanicalSystem;
            let h = 1e-9 / m.length_scale()[m.coords.iter().position(|&f| f == i).unwrap()];
            let (mut xp, mut xm) = (x.clone(), x.clone());
            xp[i] += h;
            xm[i] -= h;
            let grad = (energy(&xp) - energy(&xm)) / (2.0 * h);
            assert!(
                (qf[i] + grad).abs() <= 1e-6 * fmax,
                "coordinate {i}: Q {} -dV/dq {}",
                qf[i],
                -grad
            );
        }
    }

    /// Drive-flank mesh deflections of the rigid model at `x` (sun prescribed by `x`).
    fn rigid_mesh_deflections(m: &RigidModel, x: [f64; 3]) -> Vec<f64> {
        let mut probe = Probe::default();
        m.forces(0.0, &x, &[0.0; 3], &mut probe).unwrap();
        probe.mesh.iter().map(|p| p.1).collect()
    }

    #[test]
    fn gear_runout_and_pitch_error_offset_the_mesh_approach() {
        // First-order effects on the drive flank of mesh i (planet at gamma_i on the carrier,
        // line of action at psi = th_c + gamma_i + pi/2 - pa):
        // - sun runout e_s, phase p_s: e_s cos(th_s + p_s - psi) = e_s sin(th_s - th_c + p_s -
        //   gamma_i + pa), once per sun revolution relative to the carrier;
        // - planet runout e_p: -e_p sin(alpha + p_p - th_c - gamma_i + pa);
        // - sinusoidal sun pitch deviation A: cos(pa) A sin(th_c + gamma_i - th_s + p);
        // - tabulated sun pitch deviation: cos(pa) F_k when tooth k is at the mesh.
        // Exact in the model up to round-off (1e-18 m); the effect is micrometres.
        let nominal = Scene::paper("idle").unwrap();
        let m0 = RigidModel::new(&nominal).unwrap();
        let pa = nominal.stage1.as_ref().unwrap().pressure_angle;
        let gamma = [0.0, TAU / 3.0, 2.0 * TAU / 3.0];
        let (es, ps, ep, pp, amp, ph) = (1e-5, 0.3, 4e-6, -0.8, 2e-6, 0.9);
        let mut runout = nominal.clone();
        runout.gear_errors.sun.runout = es;
        runout.gear_errors.sun.runout_phase = ps;
        let mut planet = nominal.clone();
        planet.gear_errors.planets = vec![GearError::default(); 3];
        planet.gear_errors.planets[1].runout = ep;
        planet.gear_errors.planets[1].runout_phase = pp;
        let mut sine = nominal.clone();
        sine.gear_errors.sun.pitch_amplitude = amp;
        sine.gear_errors.sun.pitch_phase = ph;
        let dev: Vec<f64> = (0..18).map(|k| 1e-6 * ((k * k) % 7) as f64).collect();
        let mut table = nominal.clone();
        table.gear_errors.sun.pitch_deviation = dev.clone();
        let models: Vec<RigidModel> = [&runout, &planet, &sine, &table]
            .iter()
            .map(|s| RigidModel::new(s).unwrap())
            .collect();
        for step in 0..40 {
            // The kinematic pose (alpha = -zc th_c, th_s = 57 th_c) with sun tooth `step` at
            // mesh 0: th_c - th_s = -56 th_c = 2 pi step / 18.
            let thc = -TAU * step as f64 / (18.0 * 56.0);
            let (alpha, ths) = (-23.0 * thc, 57.0 * thc);
            let x = [thc, alpha, ths];
            let d0 = rigid_mesh_deflections(&m0, x);
            let dd: Vec<Vec<f64>> = models
                .iter()
                .map(|m| {
                    rigid_mesh_deflections(m, x)
                        .iter()
                        .zip(&d0)
                        .map(|(a, b)| a - b)
                        .collect()
                })
                .collect();
            for i in 0..3 {
                let g = gamma[i];
                let want = [
                    es * (ths - thc + ps - g + pa).sin(),
                    if i == 1 {
                        -ep * (alpha + pp - thc - g + pa).sin()
                    } else {
                        0.0
                    },
                    pa.cos() * amp * (thc + g - ths + ph).sin(),
                ];
                for (c, w) in want.iter().enumerate() {
                    assert!(
                        (dd[c][i] - w).abs() < 1e-15,
                        "error {c} mesh {i} step {step}: {} vs {w}",
                        dd[c][i]
                    );
                }
            }
            // Mesh 0 sits on sun tooth `step` (body angle th_c - th_s = 2 pi step / 18).
            let want = pa.cos() * dev[step % 18];
            assert!((dd[3][0] - want).abs() < 1e-15, "{} vs {want}", dd[3][0]);
        }
    }

    #[test]
    fn without_shafts_or_errors_the_new_coordinates_are_absent() {
        let s = Scene::paper("rated").unwrap();
        let m = RigidModel::new(&s).unwrap();
        assert_eq!(m.free, vec![CARRIER, CRANK]);
        assert!(m.mesh_errors.is_none() && m.output_shaft.is_none() && m.input_shaft.is_none());
        assert!(m.skip_separated);
        let mut c = s.clone();
        c.joints = crate::dynamics::model::compliant::default_joints();
        let cm = CompliantModel::new(&c).unwrap();
        assert_eq!(cm.full_len(), 2 + 3 * 3 + 3 * 2);
        assert!(cm.load_index.is_none() && cm.motor_index.is_none());
        let _ = (FULL, PI, MOTOR, SUN);
    }

    #[test]
    fn drive_train_fields_are_validated_naming_the_field_and_limit() {
        let base = errors_scene(false);
        let bad = |f: &dyn Fn(&mut Scene), want: &str| {
            let mut s = base.clone();
            f(&mut s);
            let e = s.validate().unwrap_err().to_string();
            assert!(e.contains(want), "{e} should name {want}");
        };
        bad(
            &|s| s.shafts.output.as_mut().unwrap().stiffness = -1.0,
            "shafts.output.stiffness must be > 0",
        );
        bad(
            &|s| s.shafts.input.as_mut().unwrap().damping = -1.0,
            "shafts.input.damping must be >= 0",
        );
        bad(
            &|s| s.inertias.load_inertia = 0.0,
            "inertias.load_inertia > 0",
        );
        bad(
            &|s| s.inertias.motor_inertia = -1.0,
            "inertias.motor_inertia must be >= 0",
        );
        bad(
            &|s| {
                s.inertias.motor_inertia = 0.0;
                s.drive = Drive::Torque {
                    torque: 1.0,
                    ramp_time: 0.0,
                };
            },
            "inertias.motor_inertia > 0",
        );
        bad(&|s| s.stage1 = None, "needs a first stage");
        bad(
            &|s| s.gear_errors.sun.runout = -1e-6,
            "gear_errors.sun.runout must be in [0",
        );
        bad(
            &|s| s.gear_errors.planets[2].pitch_amplitude = 1e-3,
            "gear_errors.planets[2].pitch_amplitude",
        );
        bad(
            &|s| s.gear_errors.sun.pitch_deviation = vec![0.0; 5],
            "one value per tooth (18)",
        );
        bad(
            &|s| s.gear_errors.planets.truncate(2),
            "one entry per planet (3)",
        );
        bad(
            &|s| s.discs[1].profile_error = profile(vec![[1e-3, 1.0, 0.0]], vec![]),
            "discs[1].profile_error.offset bound",
        );
        bad(
            &|s| s.discs[0].profile_error = profile(vec![[1e-6, 1.5, 0.0]], vec![]),
            "discs[0].profile_error.harmonics[0] order must be an integer >= 0",
        );
        bad(
            &|s| s.discs[0].profile_error = profile(vec![], vec![[1.0, 0.0], [0.5, 0.0]]),
            "table angles must increase strictly",
        );
        bad(
            &|s| s.discs[0].profile_error = profile(vec![], vec![[7.0, 0.0]]),
            "table[0] angle must be in [0, 2 pi)",
        );
    }
}
