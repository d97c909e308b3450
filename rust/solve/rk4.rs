//! Classical fixed-step fourth-order Runge-Kutta on `(q, v, work)`.

use crate::error::{Result, RvdynError};
use crate::solve::integrator::{FixedClock, Integrator, IntegratorEntry, Settings, Stats};
use crate::solve::stability;
use crate::solve::system::{MechanicalSystem, State};

/// Registry entry of RK4.
pub static ENTRY: IntegratorEntry = IntegratorEntry {
    name: "rk4",
    aliases: &[],
    default_dt: 1e-5,
    adaptive: false,
    summary: "classical Runge-Kutta, explicit, order 4, fixed step (stops at its stability limit)",
    build: |s: &Settings| {
        Ok(Box::new(Rk4Run {
            stepper: Rk4::default(),
            clock: FixedClock::new(s.t_end, s.dt),
        }))
    },
};

/// Reusable stage storage for RK4.
#[derive(Debug, Default)]
pub struct Rk4 {
    kq: [Vec<f64>; 4],
    kv: [Vec<f64>; 4],
    kw: [[f64; 3]; 4],
    q: Vec<f64>,
    v: Vec<f64>,
}

impl Rk4 {
    /// Advance `st` by `h` \[s\].
    #[allow(clippy::needless_range_loop)]
    pub fn step<S: MechanicalSystem + ?Sized>(
        &mut self,
        sys: &S,
        st: &mut State,
        h: f64,
    ) -> Result<()> {
        let n = st.q.len();
        for k in 0..4 {
            self.kq[k].resize(n, 0.0);
            self.kv[k].resize(n, 0.0);
        }
        self.q.resize(n, 0.0);
        self.v.resize(n, 0.0);
        let c = [0.0, 0.5, 0.5, 1.0];
        for s in 0..4 {
            if s == 0 {
                // First stage = the state's own evaluation (kept from the previous step).
                self.kq[0].copy_from_slice(&st.v);
                self.kv[0].copy_from_slice(&st.a);
                self.kw[0] = st.power;
                continue;
            }
            for i in 0..n {
                self.q[i] = st.q[i] + c[s] * h * self.kq[s - 1][i];
                self.v[i] = st.v[i] + c[s] * h * self.kv[s - 1][i];
            }
            self.kq[s].copy_from_slice(&self.v);
            let (kv, kw) = (&mut self.kv[s], &mut self.kw[s]);
            sys.eval(st.t + c[s] * h, &self.q, &self.v, kv, kw)?;
        }
        for i in 0..n {
            st.q[i] += h / 6.0
                * (self.kq[0][i] + 2.0 * self.kq[1][i] + 2.0 * self.kq[2][i] + self.kq[3][i]);
            st.v[i] += h / 6.0
                * (self.kv[0][i] + 2.0 * self.kv[1][i] + 2.0 * self.kv[2][i] + self.kv[3][i]);
        }
        for j in 0..3 {
            st.work[j] += h / 6.0
                * (self.kw[0][j] + 2.0 * self.kw[1][j] + 2.0 * self.kw[2][j] + self.kw[3][j]);
        }
        st.t += h;
        sys.eval(st.t, &st.q, &st.v, &mut st.a, &mut st.power)?;
        Ok(())
    }
}

/// RK4 steps between two checks of its linearised stability (2 n force evaluations each).
const STABILITY_CHECK: u64 = 250;

/// RK4 bound to one run: fixed steps, with a check of the linearised stability limit every
/// [`STABILITY_CHECK`] steps (an explicit method beyond it can return smooth-looking but wrong
/// results).
struct Rk4Run {
    stepper: Rk4,
    clock: FixedClock,
}

impl Integrator for Rk4Run {
    fn advance(&mut self, sys: &dyn MechanicalSystem, st: &mut State, _t_end: f64) -> Result<()> {
        if self.clock.taken.is_multiple_of(STABILITY_CHECK) {
            check_stability(sys, st, self.clock.h)?;
        }
        self.stepper.step(sys, st, self.clock.h)?;
        self.clock.tick(st);
        Ok(())
    }

    fn stats(&self) -> Stats {
        Stats {
            counts: vec![
                ("steps", self.clock.taken),
                ("evaluations", 4 * self.clock.taken),
            ],
            dt: Some(self.clock.h),
        }
    }
}

/// Stop an RK4 run whose step is beyond the method's linearised stability limit at this state.
fn check_stability(sys: &dyn MechanicalSystem, st: &State, h: f64) -> Result<()> {
    let eigs = stability::linearised_eigenvalues(sys, st)?;
    let growth = stability::rk4_excess_growth(&eigs, h);
    if growth > 1.0 + 1e-6 {
        let limit = stability::rk4_step_limit(&eigs, h);
        return Err(RvdynError::Simulation(format!(
            "rk4 with dt = {h:.3e} s is beyond its stability limit at t = {:.6e} s: a mode of the \
             linearised reducer grows {growth:.3} times per step more than it should; the largest \
             stable step here is about {limit:.3e} s: reduce dt below {:.2e} s or use \
             integrator=\"generalized-alpha\"",
            st.t,
            0.8 * limit
        )));
    }
    Ok(())
}
