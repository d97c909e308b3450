//! The rigid-joint model seen by the integrators: free coordinates only.

use crate::dynamics::model::rigid::{CARRIER, CRANK, Forces, RigidModel, SUN};
use crate::dynamics::model::{Layout, Observation, ReducerModel};
use crate::dynamics::run::sink::{ContactSink, DynSink, NoSink};
use crate::error::Result;
use crate::solve::MechanicalSystem;

/// Adapter from [`RigidModel`] (full coordinates) to a [`MechanicalSystem`] in the free ones.
pub struct RigidSystem<'a> {
    pub(crate) model: &'a RigidModel,
    scale: Vec<f64>,
}

impl<'a> RigidSystem<'a> {
    /// The adapter of a built model.
    pub fn new(model: &'a RigidModel) -> Self {
        let scale = model.free.iter().map(|&i| model.length_scale[i]).collect();
        Self { model, scale }
    }

    /// Full coordinates from free ones at time `t` (prescribed ones from the drive); returns
    /// the prescribed acceleration.
    #[inline]
    pub(crate) fn full(&self, t: f64, q: &[f64], v: &[f64]) -> ([f64; 3], [f64; 3], f64) {
        let mut x = [0.0; 3];
        let mut xv = [0.0; 3];
        for (k, &i) in self.model.free.iter().enumerate() {
            x[i] = q[k];
            xv[i] = v[k];
        }
        let acc = self.model.apply_drive(t, &mut x, &mut xv);
        (x, xv, acc)
    }
}

impl MechanicalSystem for RigidSystem<'_> {
    fn dof(&self) -> usize {
        self.model.free.len()
    }

    fn eval(
        &self,
        t: f64,
        q: &[f64],
        v: &[f64],
        a: &mut [f64],
        power: &mut [f64; 3],
    ) -> Result<()> {
        let m = self.model;
        let (x, xv, _) = self.full(t, q, v);
        let f = m.forces(t, &x, &xv, &mut NoSink)?;
        for (k, &i) in m.free.iter().enumerate() {
            a[k] = f.q[i] / m.mass[i];
        }
        power[0] = match (m.prescribed, m.drive.torque(t)) {
            (Some(p), _) => -f.q[p] * xv[p],
            (None, Some(tq)) => tq * xv[m.input],
            (None, None) => 0.0,
        };
        power[1] = m.load.torque(t) * xv[CARRIER];
        power[2] = f.dissipation;
        Ok(())
    }

    fn length_scale(&self) -> &[f64] {
        &self.scale
    }
}

impl ReducerModel for RigidSystem<'_> {
    fn free_mass(&self) -> Vec<f64> {
        self.model
            .free
            .iter()
            .map(|&i| self.model.mass[i])
            .collect()
    }

    fn generalized_force(&self, t: f64, q: &[f64], v: &[f64], out: &mut [f64]) -> Result<()> {
        let (x, xv, _) = self.full(t, q, v);
        let f = self.model.forces(t, &x, &xv, &mut NoSink)?;
        for (k, &i) in self.model.free.iter().enumerate() {
            out[k] = f.q[i];
        }
        Ok(())
    }

    fn layout(&self) -> Layout {
        self.model.layout()
    }

    fn initial_state(&self) -> (Vec<f64>, Vec<f64>) {
        let (x, v) = self.model.initial_state();
        let free = &self.model.free;
        (
            free.iter().map(|&i| x[i]).collect(),
            free.iter().map(|&i| v[i]).collect(),
        )
    }

    fn observe(
        &self,
        t: f64,
        q: &[f64],
        v: &[f64],
        sink: &mut dyn ContactSink,
    ) -> Result<Observation> {
        let m = self.model;
        let (x, xv, acc) = self.full(t, q, v);
        let f = if sink.wants_forces() {
            m.forces(t, &x, &xv, &mut DynSink(sink))?
        } else {
            Forces::default()
        };
        let input_torque = match (m.prescribed, m.drive.torque(t)) {
            (Some(p), _) => m.mass[p] * acc - f.q[p],
            (None, Some(tq)) => tq,
            (None, None) => 0.0,
        };
        let (centres, angles): (Vec<[f64; 2]>, Vec<f64>) =
            (0..m.discs.len()).map(|k| m.disc_pose(k, &x)).unzip();
        Ok(Observation {
            sun_angle: x[SUN],
            sun_speed: xv[SUN],
            carrier_angle: x[CARRIER],
            carrier_speed: xv[CARRIER],
            crank_angle: vec![x[CRANK]; m.cranks],
            crank_speed: vec![xv[CRANK]; m.cranks],
            disc_center: centres,
            disc_angle: angles,
            input_torque,
            kinetic_energy: m.kinetic_energy(&xv),
            potential_energy: f.potential,
            friction_power: f.friction,
        })
    }
}
