//! rvdyn: dynamics of RV cycloid planetary reducers.
//!
//! Pure-Rust core (no pyo3 outside `python`, which is compiled only with the `python` feature).
//! Folders by concern:
//! - [`geometry`]: exact cycloid profile and pin gap, involute first stage, mass properties;
//! - [`bearing`]: roller bearings with clearance (Palmgren rollers), ISO 281 life, friction;
//! - [`contact`]: contact stiffness (the paper's eqs. 5-11, corrected), Hertz line contact,
//!   the ADAMS IMPACT law;
//! - [`gear`]: ISO 6336-1 mesh stiffness of the involute stage, its time variation;
//! - [`kinematics`]: transmission ratio, body speeds, operating point;
//! - [`dynamics`]: scenes and the equations of motion;
//! - [`solve`]: time integrators;
//! - [`analysis`]: quasi-static load sharing and run summaries.
//!
//! Units are SI everywhere: m, kg, s, N, rad, Pa.

#![warn(missing_docs)]

pub mod analysis;
pub mod bearing;
pub mod contact;
pub mod dynamics;
pub mod error;
pub mod gear;
pub mod geometry;
pub mod kinematics;
pub mod solve;

#[cfg(test)]
pub(crate) mod test_util;

#[cfg(feature = "python")]
mod python;

pub use error::{Result, RvdynError};
