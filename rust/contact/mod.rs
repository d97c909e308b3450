//! Contact laws: the ADAMS IMPACT law, Hertz line contact, and the paper's contact stiffness
//! against contact width (eqs. 5-11, errata corrected).

pub mod hertz;
pub mod impact;
pub mod pin_tangent;
pub mod stiffness;

pub use hertz::{LineContact, Material, effective_modulus, hertz_line_contact};
pub use impact::ImpactLaw;
pub use stiffness::{ContactCondition, StiffnessParams, contact_stiffness};
