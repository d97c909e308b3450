//! Time integrators for second-order mechanical systems.
//!
//! - [`rk4::Rk4`]: fixed-step classical Runge-Kutta (explicit, order 4);
//! - [`dopri5::Dopri5`]: adaptive Dormand-Prince 5(4) with error control on displacements;
//! - [`generalized_alpha::GeneralizedAlpha`]: implicit generalized-alpha (order 2) with Newton,
//!   a finite-difference Jacobian reused across steps, and step splitting when Newton stalls.
//!
//! All three implement [`Integrator`] and are registered by name in [`INTEGRATORS`];
//! [`jacobian`] holds the finite-difference Jacobian they share with the stability check.

#![warn(missing_docs)]

pub mod adaptive_alpha;
pub mod dopri5;
pub mod generalized_alpha;
pub mod integrator;
pub mod jacobian;
pub mod rk4;
pub mod stability;
pub mod system;

pub use integrator::{INTEGRATORS, Integrator, IntegratorEntry, Method, Settings, Stats};
pub use system::{MechanicalSystem, State};

#[cfg(test)]
mod tests;
