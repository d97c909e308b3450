//! The rigid-joint model seen by the integrators: free coordinates only.

use crate::dynamics::model::parts::ShaftLoads;
use crate::dynamics::model::pin_contact::{first_touch_report, mark_open};
use crate::dynamics::model::rigid::{CARRIER, CRANK, FULL, Forces, LOAD, MOTOR, RigidModel, SUN};
use crate::dynamics::model::{Layout, Observation, ReducerModel};
use crate::dynamics::run::sink::{ContactSink, EnergySink, NoSink};
use crate::error::Result;
use crate::solve::MechanicalSystem;

/// Adapter from [`RigidModel`] (full coordinates) to a [`MechanicalSystem`] in the free ones.
pub struct RigidSystem<'a> {
    pub(crate) model: &'a RigidModel,
    /// The free coordinates: the reducer's (`model.free`), then the shafts'.
    pub(crate) coords: Vec<usize>,
    scale: Vec<f64>,
}

impl<'a> RigidSystem<'a> {
    /// The adapter of a built model.
    pub fn new(model: &'a RigidModel) -> Self {
        let coords: Vec<usize> = model
            .free
            .iter()
            .chain(&model.shaft_free)
            .copied()
            .collect();
        let scale = coords.iter().map(|&i| model.length_scale[i]).collect();
        Self {
            model,
            coords,
            scale,
        }
    }

    /// Full coordinates from free ones at time `t` (prescribed ones from the drive); returns
    /// the prescribed acceleration.
    /// Without a shaft, the load (motor) angle is the carrier (input) angle.
    #[inline]
    pub(crate) fn full(&self, t: f64, q: &[f64], v: &[f64]) -> ([f64; FULL], [f64; FULL], f64) {
        let m = self.model;
        let mut x = [0.0; FULL];
        let mut xv = [0.0; FULL];
        for (k, &i) in self.coords.iter().enumerate() {
            x[i] = q[k];
            xv[i] = v[k];
        }
        let acc = m.apply_drive(t, &mut x, &mut xv);
        if m.output_shaft.is_none() {
            (x[LOAD], xv[LOAD]) = (x[CARRIER], xv[CARRIER]);
        }
        if m.input_shaft.is_none() {
            let i = if m.mesh.is_some() { SUN } else { CRANK };
            (x[MOTOR], xv[MOTOR]) = (x[i], xv[i]);
        }
        (x, xv, acc)
    }

    /// Generalised forces on all five coordinates: the reducer's plus the shafts'.
    #[inline]
    pub(crate) fn all_forces<S: crate::dynamics::run::sink::ContactSink>(
        &self,
        t: f64,
        x: &[f64; FULL],
        xv: &[f64; FULL],
        sink: &mut S,
    ) -> Result<(Forces, [f64; FULL], ShaftLoads)> {
        let m = self.model;
        let f = m.forces(t, &[x[0], x[1], x[2]], &[xv[0], xv[1], xv[2]], sink)?;
        let mut q = [f.q[0], f.q[1], f.q[2], 0.0, 0.0];
        let mut sh = ShaftLoads::default();
        if m.output_shaft.is_some() || m.input_shaft.is_some() {
            sh = m.shaft_loads(
                t,
                [x[CARRIER], xv[CARRIER]],
                [x[SUN], xv[SUN]],
                [x[LOAD], xv[LOAD]],
                [x[MOTOR], xv[MOTOR]],
            );
            q[CARRIER] += sh.carrier;
            q[SUN] += sh.input;
            q[LOAD] += sh.load;
            q[MOTOR] += sh.motor;
        }
        Ok((f, q, sh))
    }
}

impl MechanicalSystem for RigidSystem<'_> {
    fn dof(&self) -> usize {
        self.coords.len()
    }

    fn energy(&self, t: f64, q: &[f64], v: &[f64]) -> Result<Option<f64>> {
        let o = self.observe(t, q, v, &mut EnergySink)?;
        Ok(Some(o.kinetic_energy + o.potential_energy))
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
        if m.output_shaft.is_none() && m.input_shaft.is_none() {
            // No shafts: the reducer's three coordinates only (the hot path).
            let mut x = [0.0; 3];
            let mut xv = [0.0; 3];
            for (k, &i) in m.free.iter().enumerate() {
                x[i] = q[k];
                xv[i] = v[k];
            }
            if let Some(p) = m.prescribed {
                let (ang, spd, _) = m.drive.motion(t);
                x[p] = ang;
                xv[p] = spd;
            }
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
            return Ok(());
        }
        let (x, xv, _) = self.full(t, q, v);
        let (f, qa, sh) = self.all_forces(t, &x, &xv, &mut NoSink)?;
        for (k, &i) in self.coords.iter().enumerate() {
            a[k] = qa[i] / m.mass[i];
        }
        power[0] = match (m.prescribed, m.drive.torque(t)) {
            (Some(p), _) => -qa[p] * xv[p],
            (None, Some(tq)) => tq * xv[m.input],
            (None, None) => 0.0,
        };
        power[1] = m.load.torque(t) * xv[LOAD];
        power[2] = f.dissipation + sh.dissipation;
        Ok(())
    }

    fn length_scale(&self) -> &[f64] {
        &self.scale
    }

    fn mark_open_contacts(&self) {
        mark_open(&self.model.warm_seeds);
    }

    fn deepest_first_touch(&self) -> Option<(f64, String)> {
        let m = self.model;
        first_touch_report(&m.warm_seeds, &m.pin_law, m.pins.len())
    }
}

impl ReducerModel for RigidSystem<'_> {
    fn free_mass(&self) -> Vec<f64> {
        self.coords.iter().map(|&i| self.model.mass[i]).collect()
    }

    fn generalized_force(&self, t: f64, q: &[f64], v: &[f64], out: &mut [f64]) -> Result<()> {
        let n = self.coords.len();
        if q.len() != n || v.len() != n || out.len() != n {
            // An analysis built on the reducer's coordinates alone meets a scene with shafts.
            return Err(crate::error::RvdynError::Scene(format!(
                "the rigid model of this scene has {n} free coordinates ({} with machine shafts: \
                 shafts.output / shafts.input), got {}: the analysis does not model the shafts \
                 yet; set them to null for it",
                self.model.shaft_free.len(),
                q.len()
            )));
        }
        let (x, xv, _) = self.full(t, q, v);
        let (_, qa, _) = self.all_forces(t, &x, &xv, &mut NoSink)?;
        for (k, &i) in self.coords.iter().enumerate() {
            out[k] = qa[i];
        }
        Ok(())
    }

    fn layout(&self) -> Layout {
        self.model.layout()
    }

    fn initial_state(&self) -> (Vec<f64>, Vec<f64>) {
        let (x, v) = self.model.initial_state();
        let free = &self.coords;
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
        // Keep each planet's mesh force for the crank reactions (when they are wanted).
        let bearings = sink.wants_bearings();
        let sink = &mut MeshCapture {
            inner: sink,
            force: if bearings {
                vec![0.0; m.cranks]
            } else {
                Vec::new()
            },
        };
        let (f, qa, sh) = if sink.wants_forces() {
            if m.output_shaft.is_none() && m.input_shaft.is_none() {
                // No shafts: the reducer's forces alone, called directly (as in `eval`).
                let f = m.forces(t, &[x[0], x[1], x[2]], &[xv[0], xv[1], xv[2]], sink)?;
                let qa = [f.q[0], f.q[1], f.q[2], 0.0, 0.0];
                (f, qa, ShaftLoads::default())
            } else {
                self.all_forces(t, &x, &xv, sink)?
            }
        } else {
            let sh = m.shaft_loads(
                t,
                [x[CARRIER], xv[CARRIER]],
                [x[SUN], xv[SUN]],
                [x[LOAD], xv[LOAD]],
                [x[MOTOR], xv[MOTOR]],
            );
            (Forces::default(), [0.0; FULL], sh)
        };
        let input_torque = match (m.prescribed, m.drive.torque(t)) {
            (Some(p), _) => m.mass[p] * acc - qa[p],
            (None, Some(tq)) => tq,
            (None, None) => 0.0,
        };
        if sink.wants_forces() && bearings {
            // Accelerations of the full coordinates: Q / M of the free ones, the drive's of the
            // prescribed one.
            let mut xa = [0.0; FULL];
            for &i in &self.coords {
                xa[i] = qa[i] / m.mass[i];
            }
            if let Some(p) = m.prescribed {
                xa[p] = acc;
            }
            let ecc = m.eccentric_reactions(&x, &xv, &xa, &f);
            for (i, r) in ecc.iter().enumerate() {
                sink.bearing(1, i, *r);
            }
            let mesh_force = std::mem::take(&mut sink.force);
            for (i, r) in m
                .crank_reactions(&x, &xv, &xa, &ecc, &mesh_force)
                .iter()
                .enumerate()
            {
                sink.bearing(0, i, *r);
            }
        }
        // As `eval` computes them (the same coordinates and operations).
        let acceleration = if !sink.wants_forces() {
            Vec::new()
        } else if m.output_shaft.is_none() && m.input_shaft.is_none() {
            m.free.iter().map(|&i| qa[i] / m.mass[i]).collect()
        } else {
            self.coords.iter().map(|&i| qa[i] / m.mass[i]).collect()
        };
        let crank = x[CRANK].sin_cos();
        let (centres, angles): (Vec<[f64; 2]>, Vec<f64>) = m
            .discs
            .iter()
            .map(|d| (m.disc_centre(d, crank), x[CARRIER] + d.angle_offset))
            .unzip();
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
            potential_energy: f.potential + sh.potential,
            friction_power: f.friction,
            load_angle: x[LOAD],
            load_speed: xv[LOAD],
            motor_angle: x[MOTOR],
            motor_speed: xv[MOTOR],
            output_shaft_torque: if m.output_shaft.is_some() {
                sh.output_torque
            } else {
                m.load.torque(t)
            },
            input_shaft_torque: if m.input_shaft.is_some() {
                sh.input_torque
            } else {
                input_torque
            },
            // As `eval` (xv[LOAD] is the carrier's without an output shaft).
            power: if sink.wants_forces() {
                [
                    match (m.prescribed, m.drive.torque(t)) {
                        (Some(p), _) => -qa[p] * xv[p],
                        (None, Some(tq)) => tq * xv[m.input],
                        (None, None) => 0.0,
                    },
                    m.load.torque(t) * xv[LOAD],
                    f.dissipation + sh.dissipation,
                ]
            } else {
                [0.0; 3]
            },
            acceleration,
        })
    }
}

/// A sink that passes everything on and keeps each mesh's force (for the crank reactions);
/// the force routine is instantiated for it, so that a contact reaches the recorder's sink
/// through one dynamic call.
struct MeshCapture<'a> {
    inner: &'a mut dyn ContactSink,
    force: Vec<f64>,
}

impl ContactSink for MeshCapture<'_> {
    fn wants_energy(&self) -> bool {
        self.inner.wants_energy()
    }
    fn wants_forces(&self) -> bool {
        self.inner.wants_forces()
    }
    fn checks_bounds(&self) -> bool {
        self.inner.checks_bounds()
    }
    fn wants_bearings(&self) -> bool {
        self.inner.wants_bearings()
    }
    fn pin(
        &mut self,
        k: usize,
        j: usize,
        force: f64,
        pen: f64,
        moment: f64,
        point: [f64; 2],
        normal: [f64; 2],
    ) {
        self.inner.pin(k, j, force, pen, moment, point, normal);
    }
    fn mesh(&mut self, i: usize, force: f64, deflection: f64) {
        if let Some(f) = self.force.get_mut(i) {
            *f = force;
        }
        self.inner.mesh(i, force, deflection);
    }
    fn bearing(&mut self, family: usize, index: usize, force: [f64; 2]) {
        self.inner.bearing(family, index, force);
    }
}
