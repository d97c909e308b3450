//! Lossless operating point: speeds and torques from power, input speed and ratio
//! (paper section 4.1, docs/model.md#erratum-3).

use crate::error::{Result, RvdynError, num, require_finite};

/// The output torque printed in the paper, section 4.1 [N m].
///
/// Inconsistent with the paper's own data: at the output speed 8328/57 = 146.105 deg/s
/// (2.550 rad/s) it carries only 4024.9 * 2.550 = 10.26 kW, not the stated 112 kW; the
/// lossless output torque at 112 kW is 57 x 770.6 = 43.92 kN m (docs/model.md#erratum-3). Kept as
/// the paper's "full load" case, labelled as such.
pub const PAPER_PRINTED_OUTPUT_TORQUE: f64 = 4024.9;

/// Speeds [rad/s] and torques [N m] at one lossless operating point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OperatingPoint {
    /// Transmitted power \[W\].
    pub power: f64,
    /// Input (sun) speed [rad/s].
    pub input_speed: f64,
    /// Output (carrier) speed `input / ratio` [rad/s].
    pub output_speed: f64,
    /// Input torque `power / input_speed` [N m].
    pub input_torque: f64,
    /// Output torque `ratio * input_torque` [N m] (no losses).
    pub output_torque: f64,
    /// Transmission ratio `input / output speed` [-].
    pub ratio: f64,
}

/// Operating point for `power` \[W\] at `input_speed` [rad/s] through `ratio` [-], without
/// losses.
///
/// Returns speeds and torques with `input_torque * input_speed = output_torque * output_speed
/// = power`. Errors (`RvdynError::Parameter`) for non-finite values or a zero input speed or
/// ratio (the torque would be infinite).
///
/// # Example
///
/// ```
/// use rvdyn::kinematics::operating_point;
/// // The paper's section 4.1: 112 kW at 8328 deg/s through i = 57.
/// let op = operating_point(112e3, 8328f64.to_radians(), 57.0).unwrap();
/// assert!((op.input_torque - 770.55).abs() < 0.01); // 112e3 W / 145.351 rad/s
/// assert!((op.output_torque - 57.0 * op.input_torque).abs() < 1e-9);
/// assert!((op.output_torque * op.output_speed - 112e3).abs() < 1e-6); // no losses
/// ```
pub fn operating_point(power: f64, input_speed: f64, ratio: f64) -> Result<OperatingPoint> {
    require_finite("power", power)?;
    require_finite("input speed", input_speed)?;
    require_finite("transmission ratio", ratio)?;
    if input_speed == 0.0 || ratio == 0.0 {
        return Err(RvdynError::Parameter(format!(
            "input speed ({} rad/s) and ratio ({}) must be non-zero to turn a power into \
             torques; give a running speed",
            num(input_speed),
            num(ratio)
        )));
    }
    let input_torque = power / input_speed;
    let op = OperatingPoint {
        power,
        input_speed,
        output_speed: input_speed / ratio,
        input_torque,
        output_torque: input_torque * ratio,
        ratio,
    };
    if ![op.output_speed, op.input_torque, op.output_torque]
        .iter()
        .all(|v| v.is_finite())
    {
        return Err(RvdynError::Parameter(format!(
            "power {} W at input speed {} rad/s through ratio {} gives a torque or speed beyond \
             the range of floating point: give values of physical size (a speed far from zero)",
            num(power),
            num(input_speed),
            num(ratio)
        )));
    }
    Ok(op)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_section_4_1() {
        // 8328 deg/s = 8328 * pi / 180 = 145.3510 rad/s; 112e3 / 145.3510 = 770.548 N m;
        // output 8328 / 57 = 146.1053 deg/s; output torque 57 * 770.548 = 43921.2 N m.
        let op = operating_point(112e3, 8328f64.to_radians(), 57.0).unwrap();
        assert!(
            (op.output_speed.to_degrees() - 146.105).abs() < 1e-3,
            "{op:?}"
        );
        assert!((op.input_torque - 770.6).abs() < 0.1, "{op:?}");
        assert!((op.output_torque - 43_920.0).abs() < 10.0, "{op:?}");
        assert!((op.output_torque * op.output_speed - 112e3).abs() < 1e-6);
    }

    #[test]
    fn printed_output_torque_is_inconsistent() {
        let op = operating_point(112e3, 8328f64.to_radians(), 57.0).unwrap();
        // 4024.9 N m * 2.55000 rad/s = 10263 W ~ 10.3 kW, an 11x shortfall against 112 kW.
        let p = PAPER_PRINTED_OUTPUT_TORQUE * op.output_speed;
        assert!((p - 10.26e3).abs() < 10.0, "{p}");
        assert!(op.output_torque / PAPER_PRINTED_OUTPUT_TORQUE > 10.0);
    }

    #[test]
    fn invalid_inputs() {
        assert!(operating_point(1e3, 0.0, 57.0).is_err());
        assert!(operating_point(1e3, 1.0, 0.0).is_err());
        assert!(operating_point(f64::NAN, 1.0, 57.0).is_err());
        assert!(operating_point(1e3, f64::INFINITY, 57.0).is_err());
        // Finite inputs whose torque overflows: an error, not inf.
        assert!(operating_point(1.0, 5e-324, 1.0).is_err());
        assert!(operating_point(1e308, 1.0, 1e10).is_err());
        // Idle: zero power is a valid point with zero torques.
        let idle = operating_point(0.0, 10.0, 57.0).unwrap();
        assert_eq!((idle.input_torque, idle.output_torque), (0.0, 0.0));
    }
}
