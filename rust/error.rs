//! The one error type of the core.
//!
//! Every fallible function returns [`Result<T>`]. The Python bindings map each variant to one
//! exception class in one place (`python/errors.rs`), so a message written here is what the
//! user reads: say what is wrong, the limit, and how to fix it.

use thiserror::Error;

/// All errors raised by the rvdyn core.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum RvdynError {
    /// A geometry that cannot exist or cannot mesh (curtate ratio, overlapping pins, undercut,
    /// tooth counts, planet spacing). Maps to `rvdyn.GeometryError`.
    #[error("{0}")]
    Geometry(String),
    /// A parameter outside its domain (non-finite, negative, wrong shape, unknown option).
    /// Maps to `rvdyn.ParameterError`.
    #[error("{0}")]
    Parameter(String),
    /// A scene description that cannot be read or is inconsistent. Maps to `rvdyn.SceneError`.
    #[error("{0}")]
    Scene(String),
    /// A numerical query that did not converge (e.g. the exact gap Newton iteration).
    /// Maps to `rvdyn.ConvergenceError`.
    #[error("{0}")]
    Convergence(String),
    /// A dynamic run that cannot go on (non-finite state, penetration beyond a physical bound,
    /// step size collapse). Maps to `rvdyn.SimulationError`.
    #[error("{0}")]
    Simulation(String),
    /// The run was interrupted by the user (Ctrl-C). Maps to `KeyboardInterrupt`.
    #[error("interrupted")]
    Interrupted,
}

/// Result alias used throughout the core.
pub type Result<T> = std::result::Result<T, RvdynError>;

/// Reject a value that is not finite, naming it.
pub fn require_finite(name: &str, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(RvdynError::Parameter(format!(
            "{name} must be a finite number, got {value}"
        )))
    }
}

/// Reject a value that is not finite and strictly positive, naming it and its unit.
pub fn require_positive(name: &str, value: f64, unit: &str) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(RvdynError::Parameter(format!(
            "{name} must be a finite number > 0 {unit}, got {value}"
        )))
    }
}

/// Reject a value that is not finite and non-negative, naming it and its unit.
pub fn require_non_negative(name: &str, value: f64, unit: &str) -> Result<f64> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(RvdynError::Parameter(format!(
            "{name} must be a finite number >= 0 {unit}, got {value}"
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finite_checks_name_the_value() {
        assert!(require_finite("x", 1.0).is_ok());
        let e = require_positive("pin_radius", f64::NAN, "m").unwrap_err();
        assert!(e.to_string().contains("pin_radius"));
        assert!(require_non_negative("d", -1.0, "m").is_err());
        assert!(require_non_negative("d", 0.0, "m").is_ok());
        assert!(require_positive("d", 0.0, "m").is_err());
    }
}
