//! Rolling bearings: roller load distribution with clearance, ISO 281 rating and life,
//! Palmgren friction torque.

pub mod life;
pub mod roller;

pub use life::{PalmgrenFriction, RollerBearingGeometry, equivalent_load, l10_roller};
pub use roller::{BearingState, DampedBearingForce, RollerBearing};
