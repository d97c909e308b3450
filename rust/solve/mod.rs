//! Time integrators for second-order mechanical systems.
//!
//! - [`rk4::Rk4`]: fixed-step classical Runge-Kutta (explicit, order 4);
//! - [`dopri5::Dopri5`]: adaptive Dormand-Prince 5(4) with error control on displacements;
//! - [`generalized_alpha::GeneralizedAlpha`]: implicit generalized-alpha (order 2) with Newton,
//!   a finite-difference Jacobian reused across steps, and step splitting when Newton stalls.

pub mod dopri5;
pub mod generalized_alpha;
pub mod rk4;
pub mod stability;
pub mod system;

pub use system::{MechanicalSystem, State};

#[cfg(test)]
mod tests;

use crate::error::{Result, RvdynError};
use serde::{Deserialize, Serialize};

/// The integration method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    Rk4,
    Dopri5,
    GeneralizedAlpha,
}

impl Method {
    /// Parse `"rk4"`, `"dopri5"` or `"generalized-alpha"`.
    pub fn parse(name: &str) -> Result<Self> {
        match name.to_ascii_lowercase().replace('_', "-").as_str() {
            "rk4" => Ok(Method::Rk4),
            "dopri5" | "dopri" | "rk45" => Ok(Method::Dopri5),
            "generalized-alpha" | "genalpha" | "gen-alpha" => Ok(Method::GeneralizedAlpha),
            _ => Err(RvdynError::Parameter(format!(
                "unknown integrator {name:?}: choose \"rk4\", \"dopri5\" or \"generalized-alpha\""
            ))),
        }
    }

    /// Canonical name.
    pub fn name(&self) -> &'static str {
        match self {
            Method::Rk4 => "rk4",
            Method::Dopri5 => "dopri5",
            Method::GeneralizedAlpha => "generalized-alpha",
        }
    }
}
