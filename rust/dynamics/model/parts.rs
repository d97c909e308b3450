//! The parts of a reducer model shared by the rigid and the compliant model: discs, pins,
//! first-stage meshes, force laws, mass properties, drive and load, built once from a scene.

use crate::contact::friction::{CoulombFriction, ToothPath};
use crate::contact::law::{MeshLaw, PinLaw};
use crate::dynamics::model::Layout;
use crate::dynamics::model::drive::DriveProfile;
use crate::dynamics::scene::{Initial, Load, Scene};
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
                * 1.000_001,
        })
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
    })
}

fn add(a: MassProperties, b: MassProperties) -> MassProperties {
    MassProperties {
        mass: a.mass + b.mass,
        inertia: a.inertia + b.inertia,
    }
}
