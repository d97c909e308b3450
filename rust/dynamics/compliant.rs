//! Compliant-joint model (being written).
use crate::dynamics::model::{Layout, Observation, ReducerModel};
use crate::dynamics::scene::Scene;
use crate::dynamics::sink::ContactSink;
use crate::error::{Result, RvdynError};
use crate::solve::MechanicalSystem;

pub struct CompliantModel;

impl CompliantModel {
    pub fn new(_scene: &Scene) -> Result<Self> {
        Err(RvdynError::Scene("compliant joints are not available in this version; use joints = {kind = \"rigid\"}".into()))
    }
}

impl MechanicalSystem for CompliantModel {
    fn dof(&self) -> usize {
        0
    }
    fn eval(&self, _t: f64, _q: &[f64], _v: &[f64], _a: &mut [f64], _p: &mut [f64; 3]) -> Result<()> {
        Ok(())
    }
    fn length_scale(&self) -> &[f64] {
        &[]
    }
}

impl ReducerModel for CompliantModel {
    fn layout(&self) -> Layout {
        Layout { discs: 0, pins: 0, cranks: 0, meshes: 0 }
    }
    fn initial_state(&self) -> (Vec<f64>, Vec<f64>) {
        (vec![], vec![])
    }
    fn observe(&self, _t: f64, _q: &[f64], _v: &[f64], _s: &mut dyn ContactSink) -> Result<Observation> {
        Ok(Observation::default())
    }
}
