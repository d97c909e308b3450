//! Analysis: quasi-static references for the dynamic results.

pub mod efficiency;
pub mod load_sharing;
pub mod ltca;
pub mod modes;
pub mod orders;
pub mod pin_load_sharing;

pub use load_sharing::{classical_levers, classical_pin_forces};
