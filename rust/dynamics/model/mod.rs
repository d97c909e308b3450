//! The equations of motion of the reducer, and what the simulation driver needs from a model
//! whatever its joints ([`ReducerModel`]).
//!
//! - [`rigid`] (with its adapter [`rigid_system`]): ideal joints, coordinates carrier, crank
//!   and sun angles;
//! - [`compliant`]: spring-damper bearings, every body in absolute coordinates;
//! - [`pin_contact`]: the exact pin / profile contact both use; [`drive`]: the input motion.

pub mod compliant;
pub mod drive;
pub mod laws;
pub(crate) mod parts;
pub mod pin_contact;
pub mod rigid;
pub mod rigid_system;
pub mod vec2;

use crate::dynamics::run::sink::ContactSink;
use crate::error::Result;
use crate::solve::MechanicalSystem;

/// Sizes of a model's bodies and contacts (fixes the shapes of recorded arrays).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Layout {
    /// Cycloid discs.
    pub discs: usize,
    /// Pins of the ring.
    pub pins: usize,
    /// Crankshafts.
    pub cranks: usize,
    /// Sun/planet meshes (0 without a first stage).
    pub meshes: usize,
}

/// Everything recorded about the bodies at one instant (SI, fixed frame).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Observation {
    /// Sun (input) angle [rad].
    pub sun_angle: f64,
    /// Sun speed [rad/s].
    pub sun_speed: f64,
    /// Carrier (output) angle [rad].
    pub carrier_angle: f64,
    /// Carrier speed [rad/s].
    pub carrier_speed: f64,
    /// Absolute rotation angle and speed of each crankshaft.
    pub crank_angle: Vec<f64>,
    /// Absolute speed of each crankshaft [rad/s].
    pub crank_speed: Vec<f64>,
    /// Disc centres [m].
    pub disc_center: Vec<[f64; 2]>,
    /// Disc rotation angles [rad].
    pub disc_angle: Vec<f64>,
    /// Torque the drive applies to the input [N m].
    pub input_torque: f64,
    /// Kinetic energy of the free bodies [J].
    pub kinetic_energy: f64,
    /// Elastic energy of the contacts and bearings [J].
    pub potential_energy: f64,
    /// Friction power [W] at the pins, the teeth and the bearings.
    pub friction_power: [f64; 3],
}

/// A reducer model the driver can integrate and record.
pub trait ReducerModel: MechanicalSystem {
    /// Sizes of bodies and contacts.
    fn layout(&self) -> Layout;
    /// Free coordinates and velocities at t = 0.
    fn initial_state(&self) -> (Vec<f64>, Vec<f64>);
    /// The (constant, diagonal) mass of each free coordinate [kg, or kg m^2 for an angle]:
    /// the equations of motion are `M a = Q(t, q, v)`.
    fn free_mass(&self) -> Vec<f64>;
    /// The generalised forces `Q(t, q, v)` on the free coordinates [N, or N m for an angle],
    /// into `qf` (length `dof()`): what a static (load sharing) or modal analysis needs
    /// separately from the mass. `eval` returns `Q / M`.
    fn generalized_force(&self, t: f64, q: &[f64], v: &[f64], qf: &mut [f64]) -> Result<()>;
    /// Observe the state `(q, v)` at `t`, reporting every contact to `sink`.
    fn observe(
        &self,
        t: f64,
        q: &[f64],
        v: &[f64],
        sink: &mut dyn ContactSink,
    ) -> Result<Observation>;
}

#[cfg(test)]
mod tests {
    use super::ReducerModel;
    use crate::dynamics::model::compliant::CompliantModel;
    use crate::dynamics::model::rigid::RigidModel;
    use crate::dynamics::model::rigid_system::RigidSystem;
    use crate::dynamics::scene::Scene;
    use crate::solve::State;
    use crate::solve::generalized_alpha::GeneralizedAlpha;

    /// After 2 ms of the rated scene from rest (a loaded state), `eval` is `Q / M`. Not bit for
    /// bit: the second evaluation starts each exact-gap Newton iteration from the first one's
    /// answer, which moves the contact point by round-off (1e-13 m Newton tolerance); 1e-9 of
    /// the largest acceleration covers that and nothing more.
    fn check<M: ReducerModel>(sys: &M) {
        let (q, v) = sys.initial_state();
        let mut st = State::new(sys, 0.0, q, v).unwrap();
        let mut ga = GeneralizedAlpha::new(0.8, 1e-9, false).unwrap();
        for _ in 0..20 {
            ga.step(sys, &mut st, 1e-4).unwrap();
        }
        let n = sys.dof();
        let (mut a, mut qf, mut p) = (vec![0.0; n], vec![0.0; n], [0.0; 3]);
        sys.eval(st.t, &st.q, &st.v, &mut a, &mut p).unwrap();
        sys.generalized_force(st.t, &st.q, &st.v, &mut qf).unwrap();
        let m = sys.free_mass();
        assert_eq!(m.len(), n);
        assert!(qf.iter().any(|x| x.abs() > 1.0), "a loaded state: {qf:?}");
        let scale = a.iter().fold(0.0f64, |s, x| s.max(x.abs()));
        for k in 0..n {
            assert!(
                (a[k] - qf[k] / m[k]).abs() <= 1e-9 * scale,
                "coordinate {k}: {} {}",
                a[k],
                qf[k] / m[k]
            );
        }
    }

    #[test]
    fn acceleration_is_force_over_mass() {
        let scene = Scene::paper("rated").unwrap();
        let rigid = RigidModel::new(&scene).unwrap();
        check(&RigidSystem::new(&rigid));
        let mut compliant = scene.clone();
        compliant.joints = crate::dynamics::model::compliant::default_joints();
        check(&CompliantModel::new(&compliant).unwrap());
    }
}
