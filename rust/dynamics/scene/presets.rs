//! The default scene (docs/model.md#default-scene): the paper's travel drive with its errata
//! corrected and the dimensions it omits assumed.

use super::*;
use crate::kinematics::operating_point;

/// The paper's input speed, 8328 deg/s [rad/s].
pub const PAPER_INPUT_SPEED: f64 = 8328.0 * PI / 180.0;
/// The paper's power, 112 kW \[W\].
pub const PAPER_POWER: f64 = 112e3;
/// The paper's printed output torque [N m] (inconsistent with 112 kW: erratum 3).
pub const PAPER_PRINTED_LOAD: f64 = 4024.9;

/// Damping ratio of the physical preset's contacts, meshes and bearings [-], referred to
/// [`PHYSICAL_REFERENCE_FREQUENCY`]: a few per cent, as measured for lubricated steel gear
/// meshes (docs/model.md, "Damping").
pub const PHYSICAL_DAMPING_RATIO: f64 = 0.05;

/// Reference frequency of the physical preset's damping \[Hz\]: its main torsional mode at rated
/// load (linearised model, docs/model.md), so that this mode has the damping ratio
/// [`PHYSICAL_DAMPING_RATIO`].
pub const PHYSICAL_REFERENCE_FREQUENCY: f64 = 1790.0;

/// Joints of the physical preset (assumed sizes, stated): on each eccentric a needle bearing
/// in the 50 mm disc hole, 26 rollers of 5 mm x 36 mm on a 45 mm pitch diameter, 5 um radial
/// clearance; each crankshaft in the carrier on two roller bearings of 20 rollers of
/// 7 mm x 20 mm on a 50 mm pitch diameter, lumped as one row of 40 mm rollers, 5 um radial
/// clearance. The lengths are chosen so that the ISO 76 static safety at rated load is above 1
/// (about 1.2 and 1.3; docs/model.md, "Load rating, life and friction torque"). Roller damping
/// as the contacts.
///
/// # Example
///
/// ```
/// use rvdyn::dynamics::scene::{Joints, Scene, physical_joints};
/// let joints = physical_joints();
/// let Joints::Compliant { eccentric_bearing, crank_bearing } = joints else { unreachable!() };
/// let needles = eccentric_bearing.rollers.unwrap();
/// assert_eq!((needles.count, needles.diameter, needles.length), (26, 0.005, 0.036)); // [m]
/// assert_eq!(crank_bearing.unwrap().clearance, 5e-6); // [m]
/// assert_eq!(Scene::physical("idle").unwrap().joints, joints);
/// ```
pub fn physical_joints() -> Joints {
    let rollers = |count, length, diameter, pitch_diameter| Rollers {
        count,
        length,
        diameter,
        pitch_diameter,
        damping_ratio: PHYSICAL_DAMPING_RATIO,
        frequency: PHYSICAL_REFERENCE_FREQUENCY,
    };
    Joints::Compliant {
        eccentric_bearing: Bearing {
            stiffness: 0.0,
            damping: 0.0,
            clearance: 5e-6,
            rollers: Some(rollers(26, 0.036, 0.005, 0.045)),
        },
        crank_bearing: Some(Bearing {
            stiffness: 0.0,
            damping: 0.0,
            clearance: 5e-6,
            rollers: Some(rollers(20, 0.040, 0.007, 0.050)),
        }),
    }
}

impl Scene {
    /// The physical preset: the paper's reducer and load case (`"idle"`, `"paper"`, `"rated"`)
    /// with the physics derived from geometry and materials instead of the paper's laws:
    /// - pins: line contact from the local profile curvature (Johnson), steel;
    /// - meshes: ISO 6336-1 method B stiffness varying along the line of action;
    /// - damping: stiffness-proportional, damping ratio [`PHYSICAL_DAMPING_RATIO`] at
    ///   [`PHYSICAL_REFERENCE_FREQUENCY`] (the main torsional mode of this preset);
    /// - joints: needle bearings on the eccentrics and roller bearings in the carrier, built
    ///   from their rollers (Palmgren) with radial clearance (see [`physical_joints`]);
    /// - drive: the paper's input speed reached by a smooth ramp over 50 ms from rest.
    pub fn physical(load: &str) -> Result<Self> {
        let mut s = Self::paper(load)?;
        s.name = "physical".into();
        let damping = DampingSpec::DampingRatio {
            ratio: PHYSICAL_DAMPING_RATIO,
            frequency: PHYSICAL_REFERENCE_FREQUENCY,
        };
        s.contact = ContactLaws {
            pin: ContactLawSpec::Line {
                youngs_modulus: crate::contact::law::default_youngs_modulus(),
                poisson_ratio: crate::contact::law::default_poisson_ratio(),
                damping,
            },
            mesh: ContactLawSpec::Iso6336 {
                line_load: None,
                ramp: default_mesh_ramp(),
                damping,
            },
        };
        s.joints = physical_joints();
        s.drive = Drive::Speed {
            speed: PAPER_INPUT_SPEED,
            start: StartKind::Ramp,
            ramp_time: 0.05,
        };
        s.validate()?;
        Ok(s)
    }

    /// The default scene of docs/model.md#default-scene with the chosen load case: `"idle"`,
    /// `"paper"` (the printed 4024.9 N m) or `"rated"` (43.9 kN m = 57 x 770.6 N m, lossless
    /// 112 kW at 8328 deg/s).
    pub fn paper(load: &str) -> Result<Self> {
        let load = match load {
            "idle" => Load::Idle,
            "paper" => Load::Constant {
                torque: PAPER_PRINTED_LOAD,
            },
            "rated" => {
                let op = operating_point(PAPER_POWER, PAPER_INPUT_SPEED, 57.0)?;
                Load::Constant {
                    torque: op.output_torque,
                }
            }
            other => {
                return Err(RvdynError::Scene(format!(
                    "unknown load case {other:?}: choose \"idle\", \"paper\" (4024.9 N m as \
                     printed) or \"rated\" (43.9 kN m, consistent with 112 kW)"
                )));
            }
        };
        Ok(Scene {
            name: "paper".into(),
            stage1: Some(paper_stage1()?),
            cycloid: CycloidParams::paper(),
            discs: vec![
                DiscSpec {
                    phase: 0.0,
                    d_rp: None,
                    d_rrp: None,
                    d_delta: None,
                    profile_error: None,
                },
                DiscSpec {
                    phase: PI,
                    d_rp: None,
                    d_rrp: None,
                    d_delta: None,
                    profile_error: None,
                },
            ],
            cranks: 3,
            pin_errors: PinErrors::default(),
            density: crate::geometry::mass::STEEL_DENSITY,
            inertias: Inertias::default(),
            joints: Joints::Rigid,
            friction: Friction::default(),
            errors: AssemblyErrors::default(),
            gear_errors: GearErrors::default(),
            shafts: Shafts::default(),
            crank_layout: None,
            crank_shaft: None,
            contact: ContactLaws {
                pin: ContactLawSpec::paper(),
                mesh: ContactLawSpec::paper(),
            },
            drive: Drive::Speed {
                speed: PAPER_INPUT_SPEED,
                start: StartKind::Step,
                ramp_time: 0.0,
            },
            load,
            initial: Initial::Rest,
        })
    }
}

/// The paper's first stage: 18/42 teeth, 3 planets, module 3 mm, 20 deg, face 30 mm.
fn paper_stage1() -> Result<InvoluteStage> {
    InvoluteStage::new(18, 42, 3, 3e-3, 20f64.to_radians(), 0.030)
}
