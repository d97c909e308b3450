//! One pin against one disc in a given pose: the exact penetration, normal and contact point.
//! Shared by the rigid- and compliant-joint models.

use crate::dynamics::rigid::{DiscModel, PinModel};
use crate::error::{Result, RvdynError};

/// A pin in contact with a disc (fixed frame, SI).
#[derive(Debug, Clone, Copy)]
pub struct PinContact {
    /// Penetration [m] (> 0).
    pub penetration: f64,
    /// Unit outward profile normal (from the disc towards the pin).
    pub normal: [f64; 2],
    /// Contact point on the profile relative to the disc centre [m].
    pub arm: [f64; 2],
}

impl PinContact {
    /// `arm x normal` (z): the lever of the normal about the disc centre [m].
    #[inline]
    pub fn lever(&self) -> f64 {
        self.arm[0] * self.normal[1] - self.arm[1] * self.normal[0]
    }
}

/// Exact contact of `pin` with `disc` whose centre is at `centre` [m] and angle `angle` [rad];
/// `None` when they do not touch. The kinematic parameter (pin angle minus disc angle) seeds
/// Newton; the parry polyline is the fallback seed.
#[inline]
pub fn pin_contact(
    disc: &DiscModel,
    pin: &PinModel,
    centre: [f64; 2],
    angle: f64,
    t: f64,
    labels: (usize, usize),
) -> Result<Option<PinContact>> {
    let g = &disc.geometry;
    let (s, c) = angle.sin_cos();
    let dp = [pin.centre[0] - centre[0], pin.centre[1] - centre[1]];
    let local = g.remove_rotation_mod([c * dp[0] + s * dp[1], -s * dp[0] + c * dp[1]]);
    let seed = pin.angle - angle - g.params().d_delta;
    let foot = g.foot_with_fallback(local, seed).ok_or_else(|| {
        RvdynError::Convergence(format!(
            "exact gap of pin {} on disc {} not found at t = {t:.6e} s: the disc is far from \
             its kinematic pose (the run has gone unstable; reduce the step)",
            labels.1 + 1,
            labels.0
        ))
    })?;
    let r_gen = g.generating_pin_radius();
    let gap = foot.dist + r_gen - pin.radius;
    if gap >= 0.0 {
        return Ok(None);
    }
    let nl = g.apply_rotation_mod(foot.normal);
    let pl = g.apply_rotation_mod([
        foot.centre_point[0] - r_gen * foot.normal[0],
        foot.centre_point[1] - r_gen * foot.normal[1],
    ]);
    Ok(Some(PinContact {
        penetration: -gap,
        normal: [c * nl[0] - s * nl[1], s * nl[0] + c * nl[1]],
        arm: [c * pl[0] - s * pl[1], s * pl[0] + c * pl[1]],
    }))
}

/// The error raised when a penetration exceeds the physical bound.
pub fn penetration_error(t: f64, pen: f64, bound: f64, what: &str) -> RvdynError {
    RvdynError::Simulation(format!(
        "penetration {pen:.3e} m of {what} at t = {t:.6e} s exceeds the physical bound \
         {bound:.3e} m: the run has gone unstable; reduce the step (dt) or tolerances, or use \
         the implicit integrator"
    ))
}
