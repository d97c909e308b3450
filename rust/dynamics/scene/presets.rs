//! The default scene (docs/model.md#default-scene): the paper's travel drive with its errata
//! corrected and the dimensions it omits assumed.

use super::*;
use crate::kinematics::operating_point;

/// The paper's input speed, 8328 deg/s [rad/s].
pub const PAPER_INPUT_SPEED: f64 = 8328.0 * PI / 180.0;
/// The paper's power, 112 kW [W].
pub const PAPER_POWER: f64 = 112e3;
/// The paper's printed output torque [N m] (inconsistent with 112 kW: erratum 3).
pub const PAPER_PRINTED_LOAD: f64 = 4024.9;

impl Scene {
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
                },
                DiscSpec {
                    phase: PI,
                    d_rp: None,
                    d_rrp: None,
                    d_delta: None,
                },
            ],
            cranks: 3,
            pin_errors: PinErrors::default(),
            density: crate::geometry::mass::STEEL_DENSITY,
            inertias: Inertias::default(),
            joints: Joints::Rigid,
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
