//! Scenes, the equations of motion and the simulation driver.

pub mod compliant;
pub mod drive;
pub mod model;
pub mod pin_contact;
pub mod record;
pub mod rigid;
pub mod scene;
pub mod simulate;
pub mod sink;
pub mod system;

pub use record::Recording;
pub use rigid::RigidModel;
pub use scene::Scene;
pub use simulate::{RunControl, SimOptions, simulate};
