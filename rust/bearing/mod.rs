//! Rolling bearings: roller load distribution with clearance, ISO 281 rating and life,
//! Palmgren friction torque, the split of a lumped crank bearing into its two rows, and the
//! crankshaft's bending between its bearings.

pub mod crank_beam;
pub mod crank_rows;
pub mod life;
pub mod roller;

pub use crank_beam::CrankShaft;
pub use crank_rows::CrankLayout;
pub use life::{
    PalmgrenFriction, RollerBearingGeometry, equivalent_load, l10_roller, system_life_roller,
};
pub use roller::{BearingState, DampedBearingForce, RollerBearing};
