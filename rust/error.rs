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
    /// Memory for a result or a working array cannot be allocated (the size was checked and
    /// the allocation attempted without aborting). Maps to `MemoryError`.
    #[error("{0}")]
    Memory(String),
    /// The run was interrupted by the user (Ctrl-C). Maps to `KeyboardInterrupt`.
    #[error("interrupted")]
    Interrupted,
}

/// Result alias used throughout the core.
pub type Result<T> = std::result::Result<T, RvdynError>;

/// A number for a message: rounded to 6 significant digits and written in its shortest form,
/// in exponent form for very large or small magnitudes (`0.115`, `0.0722667`, `1e308`,
/// `5e-324`, `NaN`, `inf`), never the hundreds of digits that `{}` prints for `1e308`.
pub fn num(x: f64) -> String {
    if !x.is_finite() {
        return format!("{x:?}");
    }
    let rounded: f64 = format!("{x:.5e}").parse().unwrap_or(x);
    format!("{rounded:?}")
}

/// An empty vector with room for `n` values, or `RvdynError::Memory` (naming `what`) if the
/// memory cannot be had. The size is checked and the allocation attempted without the abort
/// of the standard allocation path, so a huge request becomes a Python `MemoryError`.
pub fn try_vec<T>(n: usize, what: &str) -> Result<Vec<T>> {
    let mut v = Vec::new();
    let bytes = n.checked_mul(std::mem::size_of::<T>());
    let reserved =
        bytes.is_some_and(|b| b <= isize::MAX as usize) && v.try_reserve_exact(n).is_ok();
    if reserved {
        Ok(v)
    } else {
        Err(RvdynError::Memory(format!(
            "cannot allocate {what}: {n} values of {} bytes ({:.3e} bytes) do not fit in memory; \
             ask for fewer values",
            std::mem::size_of::<T>(),
            n as f64 * std::mem::size_of::<T>() as f64
        )))
    }
}

/// Reject a value that is not finite, naming it.
pub fn require_finite(name: &str, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(RvdynError::Parameter(format!(
            "{name} must be a finite number, got {}",
            num(value)
        )))
    }
}

/// Reject a value that is not finite and strictly positive, naming it and its unit.
pub fn require_positive(name: &str, value: f64, unit: &str) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(RvdynError::Parameter(format!(
            "{name} must be a finite number > 0 {unit}, got {}",
            num(value)
        )))
    }
}

/// Reject a value that is not finite and non-negative, naming it and its unit.
pub fn require_non_negative(name: &str, value: f64, unit: &str) -> Result<f64> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(RvdynError::Parameter(format!(
            "{name} must be a finite number >= 0 {unit}, got {}",
            num(value)
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

    #[test]
    fn extreme_numbers_print_short() {
        let e = require_non_negative("x", -1e308, "m")
            .unwrap_err()
            .to_string();
        assert!(e.len() < 60, "{e}");
        assert!(e.contains("-1e308"), "{e}");
        assert_eq!(num(5e-324), "5e-324");
        assert_eq!(num(0.01), "0.01");
        assert_eq!(num(0.11499999999999999), "0.115");
        assert_eq!(num(1.0000000000000136e308), "1e308");
        assert_eq!(num(f64::NAN), "NaN");
    }

    #[test]
    fn impossible_allocations_are_errors() {
        assert!(matches!(
            try_vec::<f64>(usize::MAX / 4, "a test array"),
            Err(RvdynError::Memory(_))
        ));
        assert!(matches!(
            try_vec::<f64>(1 << 50, "a test array"),
            Err(RvdynError::Memory(_))
        ));
        assert_eq!(try_vec::<f64>(10, "x").unwrap().capacity(), 10);
    }
}
