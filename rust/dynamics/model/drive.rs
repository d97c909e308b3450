//! The input drive as a function of time: prescribed motion (step or smooth ramp) or torque.

use crate::contact::impact::step_cubic;
use crate::dynamics::scene::{Drive, StartKind};

/// Time law of the input.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum DriveProfile {
    /// Prescribed speed [rad/s], reached at once (`ramp = None`) or over a cubic ramp \[s\].
    Speed { speed: f64, ramp: Option<f64> },
    /// Prescribed torque [N m], ramped over `ramp` \[s\] (0 = step).
    Torque { torque: f64, ramp: f64 },
}

impl DriveProfile {
    /// The time law of a scene's drive.
    pub(crate) fn new(drive: &Drive) -> Self {
        match *drive {
            Drive::Speed {
                speed,
                start,
                ramp_time,
            } => DriveProfile::Speed {
                speed,
                ramp: (start == StartKind::Ramp).then_some(ramp_time),
            },
            Drive::Torque { torque, ramp_time } => DriveProfile::Torque {
                torque,
                ramp: ramp_time,
            },
        }
    }

    /// True for a prescribed-speed drive.
    pub(crate) fn is_speed(&self) -> bool {
        matches!(self, DriveProfile::Speed { .. })
    }

    /// Full input speed [rad/s] (0 for a torque drive).
    pub(crate) fn full_speed(&self) -> f64 {
        match *self {
            DriveProfile::Speed { speed, .. } => speed,
            DriveProfile::Torque { .. } => 0.0,
        }
    }

    /// Prescribed (angle \[rad\], speed [rad/s], acceleration [rad/s^2]) at time `t` \[s\].
    /// The ramp `w(t) = W s^2 (3 - 2 s)`, `s = t/T`, integrates to `W T (s^3 - s^4/2)`.
    pub(crate) fn motion(&self, t: f64) -> (f64, f64, f64) {
        match *self {
            DriveProfile::Speed { speed, ramp: None } => (speed * t, speed, 0.0),
            DriveProfile::Speed {
                speed,
                ramp: Some(tr),
            } => {
                if t >= tr {
                    (speed * (0.5 * tr + (t - tr)), speed, 0.0)
                } else {
                    let s = (t / tr).max(0.0);
                    let s2 = s * s;
                    (
                        speed * tr * (s2 * s - 0.5 * s2 * s2),
                        speed * s2 * (3.0 - 2.0 * s),
                        speed * 6.0 * s * (1.0 - s) / tr,
                    )
                }
            }
            DriveProfile::Torque { .. } => (0.0, 0.0, 0.0),
        }
    }

    /// Applied input torque [N m] at `t`, for a torque drive.
    pub(crate) fn torque(&self, t: f64) -> Option<f64> {
        match *self {
            DriveProfile::Torque { torque, ramp } => Some(if ramp > 0.0 {
                step_cubic(t, 0.0, 0.0, ramp, torque)
            } else {
                torque
            }),
            DriveProfile::Speed { .. } => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ramp_angle_is_the_integral_of_speed() {
        let d = DriveProfile::Speed {
            speed: 10.0,
            ramp: Some(0.2),
        };
        let n = 20000;
        let mut integral = 0.0;
        let h = 0.3 / n as f64;
        for i in 0..n {
            let t = (i as f64 + 0.5) * h;
            integral += d.motion(t).1 * h;
        }
        assert!((integral - d.motion(0.3).0).abs() < 1e-8);
        // Acceleration is the derivative of speed.
        let t = 0.07;
        let fd = (d.motion(t + 1e-6).1 - d.motion(t - 1e-6).1) / 2e-6;
        assert!((fd - d.motion(t).2).abs() < 1e-5);
        assert_eq!(d.motion(1.0).1, 10.0);
    }
}
