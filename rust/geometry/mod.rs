//! Geometry: the exact cycloid profile and pin gap, the involute first stage, mass properties.

pub mod cycloid;
pub mod gap;
pub mod involute;
pub mod mass;
pub mod profile_seed;

pub use cycloid::CycloidGeometry;
pub use gap::PinGap;
pub use involute::InvoluteStage;
