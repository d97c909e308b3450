//! Gear meshes: ISO 6336-1 tooth stiffness and its variation along the line of action.

pub mod iso6336;

pub use iso6336::{IsoGearPair, MeshStiffnessWave, planet_mesh_phases, spur_contact_ratio};
