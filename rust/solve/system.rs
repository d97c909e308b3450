//! What an integrator sees: a second-order mechanical system `q'' = f(t, q, v)` with three
//! power flows to integrate alongside (input, output, dissipated).

use crate::error::Result;

/// A second-order system in its free coordinates.
pub trait MechanicalSystem {
    /// Number of free coordinates.
    fn dof(&self) -> usize;
    /// Accelerations `a = M^-1 Q(t, q, v)` and the power flows `[input, output, dissipated]` \[W\].
    fn eval(&self, t: f64, q: &[f64], v: &[f64], a: &mut [f64], power: &mut [f64; 3])
    -> Result<()>;
    /// Length per unit of each coordinate \[m\] (a lever arm for an angle): error control and
    /// Newton convergence act on displacements, not on angles that grow to tens of radians.
    fn length_scale(&self) -> &[f64];
    /// Remember which contacts are open at the state of the last [`eval`](Self::eval) (an
    /// adaptive integrator calls this after accepting a step). Default: no contacts.
    fn mark_open_contacts(&self) {}
    /// The deepest first touch since [`mark_open_contacts`](Self::mark_open_contacts): the
    /// largest penetration, at the last evaluation, of a contact open at the mark, as a
    /// multiple of the depth its law can take in one step (a ramp that the step must not
    /// jump), with the contact's name. `None` when none closed (or no law has such a depth).
    fn deepest_first_touch(&self) -> Option<(f64, String)> {
        None
    }
    /// Mechanical energy (kinetic + potential) \[J\] at `(t, q, v)`, for an integrator that
    /// checks the energy balance against the integrated power flows; `None` when the system does
    /// not know it (the default).
    fn energy(&self, _t: f64, _q: &[f64], _v: &[f64]) -> Result<Option<f64>> {
        Ok(None)
    }
}

/// The integrated state: coordinates, velocities, accelerations and energy flows.
#[derive(Debug, Clone, PartialEq)]
pub struct State {
    /// Time \[s\].
    pub t: f64,
    /// Free coordinates.
    pub q: Vec<f64>,
    /// Their velocities.
    pub v: Vec<f64>,
    /// Acceleration at `t` (for dense output and the generalized-alpha recursion).
    pub a: Vec<f64>,
    /// Power flows at `t` `[input, output, dissipated]` \[W\].
    pub power: [f64; 3],
    /// Integrated `[input work, output work, dissipated energy]` \[J\].
    pub work: [f64; 3],
}

impl State {
    /// A state at `t` \[s\] with accelerations evaluated from the system.
    ///
    /// `q` and `v` hold [`MechanicalSystem::dof`] values each, in the system's units (for the
    /// reducer models angles \[rad\] or positions \[m\], and their speeds [rad/s] or [m/s]).
    pub fn new<S: MechanicalSystem>(sys: &S, t: f64, q: Vec<f64>, v: Vec<f64>) -> Result<Self> {
        let mut a = vec![0.0; q.len()];
        let mut p = [0.0; 3];
        sys.eval(t, &q, &v, &mut a, &mut p)?;
        Ok(Self {
            t,
            q,
            v,
            a,
            power: p,
            work: [0.0; 3],
        })
    }

    /// Cubic Hermite interpolation between `self` and `next` at time `t` \[s\] (clamped to
    /// `[self.t, next.t]`): positions from (q, v), velocities from (v, a); accelerations,
    /// power flows and work linearly. The result is in the units of the two states.
    pub fn interpolate(&self, next: &State, t: f64) -> State {
        let h = next.t - self.t;
        let s = if h > 0.0 {
            ((t - self.t) / h).clamp(0.0, 1.0)
        } else {
            1.0
        };
        let (h00, h10, h01, h11) = (
            (1.0 + 2.0 * s) * (1.0 - s) * (1.0 - s),
            s * (1.0 - s) * (1.0 - s),
            s * s * (3.0 - 2.0 * s),
            s * s * (s - 1.0),
        );
        let herm = |y0: &[f64], d0: &[f64], y1: &[f64], d1: &[f64]| -> Vec<f64> {
            (0..y0.len())
                .map(|i| h00 * y0[i] + h10 * h * d0[i] + h01 * y1[i] + h11 * h * d1[i])
                .collect()
        };
        State {
            t,
            q: herm(&self.q, &self.v, &next.q, &next.v),
            v: herm(&self.v, &self.a, &next.v, &next.a),
            a: (0..self.a.len())
                .map(|i| (1.0 - s) * self.a[i] + s * next.a[i])
                .collect(),
            power: std::array::from_fn(|i| (1.0 - s) * self.power[i] + s * next.power[i]),
            work: std::array::from_fn(|i| (1.0 - s) * self.work[i] + s * next.work[i]),
        }
    }
}
