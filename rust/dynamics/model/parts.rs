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
    /// Eccentric phase on the crank [rad].
    pub(crate) phase: f64,
    /// Disc angle offset from the carrier angle, `-phase / zc` [rad].
    pub(crate) angle_offset: f64,
    /// Body depth of the disc for the line contact law [m]: pin circle radius minus pin
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
    /// Nominal angle of the pin on the pin circle [rad] (the kinematic seed of its contact).
    pub(crate) angle: f64,
}

/// The sun/planet meshes of the first stage.
#[derive(Debug, Clone, Copy)]
pub(crate) struct MeshModel {
    pub(crate) sun_base_radius: f64,
    pub(crate) planet_base_radius: f64,
    /// Total backlash along the line of action [m].
    pub(crate) backlash: f64,
    pub(crate) law: MeshLaw,
    pub(crate) count: usize,
    /// Mesh phase of each planet, fraction of a base pitch (`gear::planet_mesh_phases`).
    pub(crate) phases: [f64; MAX_PLANETS],
    /// Base pitch [m].
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
    /// Distance of the crank axes from the reducer axis [m].
    pub(crate) crank_radius: f64,
    /// Eccentricity [m].
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
    /// Penetration beyond which a run is declared unstable [m].
    pub(crate) max_penetration: f64,
    /// Largest distance of a profile point from its disc centre [m].
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
            discs.push(DiscModel {
                geometry: CycloidGeometry::new(scene.disc_params(k))?,
                phase: d.phase,
                angle_offset: -d.phase / zc,
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
                    law: scene.contact.mesh.mesh_law(s)?,
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

    /// Torques of the output and drive shafts at `t` from (angle [rad], speed [rad/s]) of
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
    /// Elastic energy of the shafts [J].
    pub(crate) potential: f64,
    /// Power dissipated by the shaft damping [W].
    pub(crate) dissipation: f64,
}

/// Runout and pitch errors of the first-stage gears as an extra approach of each mesh flank
/// (docs/model.md#manufacturing-errors-of-profile-and-gears).
#[derive(Debug, Clone)]
pub(crate) struct MeshErrors {
    sun: GearModelError,
    planets: Vec<GearModelError>,
    /// Angle of each planet on the carrier [rad].
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

    /// Cumulative pitch deviation [m] and its slope [m/rad] at body angle `psi`.
    fn pitch(&self, psi: f64) -> (f64, f64) {
        let (s, c) = (psi + self.pitch_phase).sin_cos();
        let (t, ts) = crate::geometry::cycloid::periodic_table(&self.table, psi);
        (self.pitch_amplitude * s + t, self.pitch_amplitude * c + ts)
    }
}

/// Extra approach of one mesh flank [m] and its derivatives by the carrier, sun and crank
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
                .map(|i| g.planets.get(i).map(GearModelError::new).unwrap_or_default())
                .collect(),
            gamma: s.planet_angles(),
            pressure_angle: s.pressure_angle,
            cos_pa: s.pressure_angle.cos(),
        }
    }

    /// Extra approach of flank `sign` (+1 drive, -1 coast) of mesh `i` at carrier angle
    /// `thc`, sun angle `ths` and absolute crank angle `alpha` [rad]:
    /// `E = sign cos(pa) (F_s(th_c + g_i - th_s) + F_p(th_c + g_i + pi - alpha))
    /// + e_s cos(th_s + p_s - psi) - e_p cos(alpha + p_p - psi)`, with
    /// `psi = th_c + g_i + sign (pi/2 - pa)` the direction of the flank's line of action.
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
}
