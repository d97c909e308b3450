//! What the simulation driver needs from a reducer model, whatever its joints.

use crate::dynamics::sink::ContactSink;
use crate::error::Result;
use crate::solve::MechanicalSystem;

/// Sizes of a model's bodies and contacts (fixes the shapes of recorded arrays).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Layout {
    pub discs: usize,
    pub pins: usize,
    pub cranks: usize,
    pub meshes: usize,
}

/// Everything recorded about the bodies at one instant (SI, fixed frame).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Observation {
    pub sun_angle: f64,
    pub sun_speed: f64,
    pub carrier_angle: f64,
    pub carrier_speed: f64,
    /// Absolute rotation angle and speed of each crankshaft.
    pub crank_angle: Vec<f64>,
    pub crank_speed: Vec<f64>,
    pub disc_center: Vec<[f64; 2]>,
    pub disc_angle: Vec<f64>,
    /// Torque the drive applies to the input [N m].
    pub input_torque: f64,
    pub kinetic_energy: f64,
    pub potential_energy: f64,
}

/// A reducer model the driver can integrate and record.
pub trait ReducerModel: MechanicalSystem {
    fn layout(&self) -> Layout;
    /// Free coordinates and velocities at t = 0.
    fn initial_state(&self) -> (Vec<f64>, Vec<f64>);
    /// Observe the state `(q, v)` at `t`, reporting every contact to `sink`.
    fn observe(
        &self,
        t: f64,
        q: &[f64],
        v: &[f64],
        sink: &mut dyn ContactSink,
    ) -> Result<Observation>;
}
