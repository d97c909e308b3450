//! Loaded tooth contact analysis (LTCA): the static equilibrium of the whole reducer under an
//! output torque with the input held, at a set of crank angles (docs/model.md, "Quasi-static
//! analysis").

pub mod statics;
