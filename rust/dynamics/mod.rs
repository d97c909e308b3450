//! Scenes, the equations of motion and the simulation driver, in the order data flows:
//!
//! - [`scene`]: the reducer description (schema, validation, the paper's preset);
//! - [`model`]: the equations of motion built from a scene: the parts shared by both models,
//!   the rigid-joint and the compliant-joint model, the contact and bearing laws;
//! - [`run`](mod@run): the driver that integrates a model with a registered integrator
//!   ([`crate::solve`]) and records the channels into a [`Recording`].

#![warn(missing_docs)]

pub mod model;
pub mod run;
pub mod scene;

pub use model::rigid::RigidModel;
pub use run::driver::{RunControl, SimOptions, run, simulate};
pub use run::recorder::Recording;
pub use scene::Scene;
