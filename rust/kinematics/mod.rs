//! Kinematics: the transmission ratio, the speed of every body, the operating point.

pub mod operating_point;
pub mod ratio;

pub use operating_point::{OperatingPoint, PAPER_PRINTED_OUTPUT_TORQUE, operating_point};
pub use ratio::{BodySpeeds, body_speeds, transmission_ratio};
