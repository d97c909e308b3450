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
use nalgebra::DMatrix;

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
    /// Sun (input) angle \[rad\].
    pub sun_angle: f64,
    /// Sun speed [rad/s].
    pub sun_speed: f64,
    /// Carrier (output) angle \[rad\].
    pub carrier_angle: f64,
    /// Carrier speed [rad/s].
    pub carrier_speed: f64,
    /// Absolute rotation angle and speed of each crankshaft.
    pub crank_angle: Vec<f64>,
    /// Absolute speed of each crankshaft [rad/s].
    pub crank_speed: Vec<f64>,
    /// Disc centres \[m\].
    pub disc_center: Vec<[f64; 2]>,
    /// Disc rotation angles \[rad\].
    pub disc_angle: Vec<f64>,
    /// Torque the drive applies to the input [N m].
    pub input_torque: f64,
    /// Kinetic energy of the free bodies \[J\].
    pub kinetic_energy: f64,
    /// Elastic energy of the contacts and bearings \[J\].
    pub potential_energy: f64,
    /// Friction power \[W\] at the pins, the teeth and the bearings.
    pub friction_power: [f64; 3],
    /// Load angle \[rad\] (the carrier's without an output shaft).
    pub load_angle: f64,
    /// Load speed [rad/s].
    pub load_speed: f64,
    /// Motor angle \[rad\] (the input's without a drive shaft).
    pub motor_angle: f64,
    /// Motor speed [rad/s].
    pub motor_speed: f64,
    /// Torque in the output shaft [N m] (without one: the load torque).
    pub output_shaft_torque: f64,
    /// Torque in the drive shaft [N m] (without one: the input torque).
    pub input_shaft_torque: f64,
    /// Power flows `[input, output, dissipated]` \[W\], as `MechanicalSystem::eval` gives them
    /// at this state (zero when the sink wants no forces).
    pub power: [f64; 3],
    /// Accelerations of the free coordinates `Q / M` (`ReducerModel::initial_state` order),
    /// as `MechanicalSystem::eval` gives them at this state (empty when the sink wants no
    /// forces): an integrator can check its step end with them.
    pub acceleration: Vec<f64>,
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

    /// Tangent stiffness `K = -dQ/dq` and damping `C = -dQ/dv` (free coordinates; N/m, N m/rad,
    /// ... as the coordinates give) at `(t, q, v)`, by one-sided finite differences of
    /// [`ReducerModel::generalized_force`] with the perturbations of [`crate::solve::jacobian`]
    /// (about 1 nm and 1 um/s at each coordinate's lever). A model with an analytic tangent
    /// overrides this; static and modal analyses call it.
    fn tangent(&self, t: f64, q: &[f64], v: &[f64]) -> Result<(DMatrix<f64>, DMatrix<f64>)> {
        use crate::solve::jacobian::{DISPLACEMENT_STEP, VELOCITY_STEP};
        let n = q.len();
        let scale = self.length_scale().to_vec();
        let (mut q1, mut v1) = (q.to_vec(), v.to_vec());
        let (mut f0, mut f1) = (vec![0.0; n], vec![0.0; n]);
        self.generalized_force(t, q, v, &mut f0)?;
        let mut k = DMatrix::zeros(n, n);
        let mut c = DMatrix::zeros(n, n);
        for j in 0..n {
            let dq = DISPLACEMENT_STEP / scale[j].max(1e-12);
            q1[j] += dq;
            self.generalized_force(t, &q1, v, &mut f1)?;
            q1[j] = q[j];
            for i in 0..n {
                k[(i, j)] = -(f1[i] - f0[i]) / dq;
            }
            let dv = VELOCITY_STEP / scale[j].max(1e-12);
            v1[j] += dv;
            self.generalized_force(t, q, &v1, &mut f1)?;
            v1[j] = v[j];
            for i in 0..n {
                c[(i, j)] = -(f1[i] - f0[i]) / dv;
            }
        }
        Ok((k, c))
    }
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
    fn tangent_stiffness_of_a_free_disc_is_its_three_bearings() {
        // Closed form: a disc held only by its three eccentric needle bearings (20 um of
        // profile clearance keeps the pins off it, idle, at rest) has a translation stiffness of
        // 3 k_b in x and y, no coupling between x and y, and a damping of 3 c_b: the
        // bearings act in parallel. Tolerance 1e-6: the one-sided difference of a linear spring
        // is exact up to round-off of the 1 nm perturbation against positions of 0.1 m.
        let mut scene = Scene::paper("idle").unwrap();
        scene.cycloid.d_rrp = 2e-5;
        let (kb, cb) = (1e9, 1e4);
        scene.joints = crate::dynamics::scene::Joints::Compliant {
            eccentric_bearing: crate::dynamics::scene::Bearing {
                stiffness: kb,
                damping: cb,
                clearance: 0.0,
                rollers: None,
            },
            crank_bearing: None,
        };
        let m = CompliantModel::new(&scene).unwrap();
        let (q, v) = m.initial_state();
        let (k, c) = m.tangent(0.0, &q, &v).unwrap();
        // The disc's x and y among the free coordinates.
        let i = m.free.iter().position(|&f| f == m.disc_index(0)).unwrap();
        for (a, b, want_k, want_c) in [
            (i, i, 3.0 * kb, 3.0 * cb),
            (i + 1, i + 1, 3.0 * kb, 3.0 * cb),
            (i, i + 1, 0.0, 0.0),
        ] {
            assert!(
                (k[(a, b)] - want_k).abs() <= 1e-6 * 3.0 * kb,
                "K {a} {b}: {}",
                k[(a, b)]
            );
            assert!(
                (c[(a, b)] - want_c).abs() <= 1e-6 * 3.0 * cb,
                "C {a} {b}: {}",
                c[(a, b)]
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
