//! Contact laws: the ADAMS IMPACT law, Hertz line contact, and the paper's contact stiffness
//! against contact width (eqs. 5-11, errata corrected); the line-contact force law from
//! geometry, restitution-based damping and regularised Coulomb friction.

pub mod damping;
pub mod friction;
pub mod hertz;
pub mod impact;
pub mod law;
pub mod line_contact;
pub mod stiffness;

pub use hertz::{LineContact, Material, effective_modulus, hertz_line_contact};
pub use impact::ImpactLaw;
pub use stiffness::{ContactCondition, StiffnessParams, contact_stiffness};
