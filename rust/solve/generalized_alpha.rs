//! Generalized-alpha (Chung & Hulbert 1993), implicit, second order, with controllable
//! high-frequency dissipation `rho_inf` for stiff penalty contact.
//!
//! With `M` folded into `f = M^-1 Q`, each step solves for the new acceleration `a1`:
//! `R(a1) = (1 - am) a1 + am a0 - f(t_f, q_f, v_f) = 0`, where `x_f = (1 - af) x1 + af x0` and
//! the Newmark updates `q1 = q0 + h v0 + h^2 ((1/2 - b) a0 + b a1)`,
//! `v1 = v0 + h ((1 - g) a0 + g a1)`. Newton uses a finite-difference Jacobian
//! `J = (1 - am) I - (1 - af) (b h^2 K + g h C)`, `K = df/dq`, `C = df/dv`, reused across steps
//! while Newton converges fast; a step whose Newton stalls is retried with a fresh Jacobian and
//! then split in halves (down to 1/1024 of the step) before the run is declared failed.

use crate::error::{Result, RvdynError};
use crate::solve::integrator::{FixedClock, Integrator, IntegratorEntry, Settings, Stats};
use crate::solve::jacobian;
use crate::solve::system::{MechanicalSystem, State};
use nalgebra::{DMatrix, DVector};

/// Registry entry of generalized-alpha.
pub static ENTRY: IntegratorEntry = IntegratorEntry {
    name: "generalized-alpha",
    aliases: &["genalpha", "gen-alpha"],
    default_dt: 1e-4,
    adaptive: false,
    summary: "generalized-alpha, implicit, order 2, fixed step, Newton with a reused Jacobian",
    build: |s: &Settings| {
        Ok(Box::new(GeneralizedAlphaRun {
            stepper: GeneralizedAlpha::new(s.rho_inf, s.atol, s.track_work)?,
            clock: FixedClock::new(s.t_end, s.dt),
        }))
    },
};

/// Generalized-alpha stepper with Jacobian reuse.
#[derive(Debug)]
pub struct GeneralizedAlpha {
    am: f64,
    af: f64,
    beta: f64,
    gamma: f64,
    /// Newton tolerance on the displacement increment [m].
    pub newton_tol: f64,
    /// Maximum Newton iterations per try.
    pub max_newton: u32,
    /// Whether the end-of-step power flows are evaluated (one more force evaluation per step)
    /// for the energy balance; otherwise the work integrals are not kept.
    pub track_work: bool,
    lu: Option<nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>>,
    lu_h: f64,
    /// Contraction factor of the Newton iteration (see `newton`).
    theta: f64,
    /// Steps accepted after one iteration since theta was last measured.
    unmeasured: u32,
    /// Jacobians computed (and factored).
    pub jacobians: u64,
    /// Newton iterations, all steps.
    pub newton_iterations: u64,
    /// Steps split in halves because Newton stalled.
    pub splits: u64,
    /// Force evaluations, Jacobians included.
    pub evaluations: u64,
}

impl GeneralizedAlpha {
    /// Parameters from the spectral radius at infinite frequency `rho_inf` in `[0, 1]`
    /// (1 = no numerical dissipation, 0 = asymptotic annihilation).
    pub fn new(rho_inf: f64, newton_tol: f64, track_work: bool) -> Result<Self> {
        if !(0.0..=1.0).contains(&rho_inf) {
            return Err(RvdynError::Parameter(format!(
                "rho_inf must be in [0, 1] (1 = no numerical damping), got {rho_inf}"
            )));
        }
        let am = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0);
        let af = rho_inf / (rho_inf + 1.0);
        let gamma = 0.5 - am + af;
        let beta = 0.25 * (1.0 - am + af).powi(2);
        Ok(Self {
            am,
            af,
            beta,
            gamma,
            newton_tol,
            max_newton: 8,
            track_work,
            lu: None,
            lu_h: 0.0,
            theta: 1.0,
            unmeasured: 0,
            jacobians: 0,
            newton_iterations: 0,
            splits: 0,
            evaluations: 0,
        })
    }

    /// Advance `st` by `h` [s] (in sub-steps if Newton needs them).
    pub fn step<S: MechanicalSystem + ?Sized>(
        &mut self,
        sys: &S,
        st: &mut State,
        h: f64,
    ) -> Result<()> {
        self.advance(sys, st, h, 0)
    }

    fn advance<S: MechanicalSystem + ?Sized>(
        &mut self,
        sys: &S,
        st: &mut State,
        h: f64,
        depth: u32,
    ) -> Result<()> {
        match self.try_step(sys, st, h) {
            Ok(Some(next)) => {
                *st = next;
                Ok(())
            }
            Ok(None) | Err(_) if depth < 10 => {
                self.splits += 1;
                self.advance(sys, st, 0.5 * h, depth + 1)?;
                self.advance(sys, st, 0.5 * h, depth + 1)
            }
            Ok(None) => Err(RvdynError::Simulation(format!(
                "generalized-alpha Newton iteration did not converge at t = {:.6e} s even with the \
                 step split to {:.3e} s: the contact state changes too violently; reduce dt",
                st.t, h
            ))),
            Err(e) => Err(e),
        }
    }

    /// One step of size `h`; `Ok(None)` if Newton does not converge (even with a fresh Jacobian).
    fn try_step<S: MechanicalSystem + ?Sized>(
        &mut self,
        sys: &S,
        st: &State,
        h: f64,
    ) -> Result<Option<State>> {
        for attempt in 0..2 {
            if self.lu.is_none() || self.lu_h != h || attempt == 1 {
                self.factor_jacobian(sys, st, h)?;
            }
            if let Some(next) = self.newton(sys, st, h)? {
                return Ok(Some(next));
            }
        }
        Ok(None)
    }

    fn newton<S: MechanicalSystem + ?Sized>(
        &mut self,
        sys: &S,
        st: &State,
        h: f64,
    ) -> Result<Option<State>> {
        let n = st.q.len();
        let (am, af, b, g) = (self.am, self.af, self.beta, self.gamma);
        let scale = sys.length_scale();
        // Start from the old acceleration: the first increment then measures the change over
        // the step, and accepting only a small increment keeps small steps accurate (a
        // predictor that starts closer lets the displacement test, which scales with h^2,
        // accept a poorly converged acceleration at small h).
        let mut a1 = st.a.clone();
        let mut q1 = vec![0.0; n];
        let mut v1 = vec![0.0; n];
        let mut qf = vec![0.0; n];
        let mut vf = vec![0.0; n];
        let mut f = vec![0.0; n];
        let mut power = [0.0; 3];
        let tf = st.t + (1.0 - af) * h;
        let Some(lu) = self.lu.as_ref() else {
            return Ok(None);
        };
        let mut previous_size = f64::NAN;
        for iteration in 0..self.max_newton {
            for i in 0..n {
                q1[i] = st.q[i] + h * st.v[i] + h * h * ((0.5 - b) * st.a[i] + b * a1[i]);
                v1[i] = st.v[i] + h * ((1.0 - g) * st.a[i] + g * a1[i]);
                qf[i] = (1.0 - af) * q1[i] + af * st.q[i];
                vf[i] = (1.0 - af) * v1[i] + af * st.v[i];
            }
            sys.eval(tf, &qf, &vf, &mut f, &mut power)?;
            self.evaluations += 1;
            self.newton_iterations += 1;
            let r = DVector::from_fn(n, |i, _| (1.0 - am) * a1[i] + am * st.a[i] - f[i]);
            let Some(delta) = lu.solve(&r) else {
                return Ok(None);
            };
            let mut size: f64 = 0.0;
            for i in 0..n {
                a1[i] -= delta[i];
                size = size.max((b * h * h * delta[i] * scale[i]).abs());
            }
            if !size.is_finite() {
                return Ok(None);
            }
            // Hairer's test: the error left after this increment is about theta/(1 - theta)
            // times it, theta the contraction of the iteration (kept from the last step that
            // took two iterations; 1 after a new Jacobian, which forces a second iteration).
            if iteration > 0 {
                self.theta = (size / previous_size).min(1.0);
            }
            previous_size = size;
            // One iteration is trusted only while theta is fresh: every fourth step measures it
            // again, since a contact change can slow the iteration without any failure showing.
            // It is also not trusted for a large first increment (a violent step, such as an
            // impact, where the linear model behind theta says little).
            let trusted = iteration > 0 || (self.unmeasured < 3 && size < 100.0 * self.newton_tol);
            let remaining = if self.theta < 1.0 && trusted {
                self.theta / (1.0 - self.theta) * size
            } else {
                f64::INFINITY
            };
            if remaining < self.newton_tol || (iteration > 0 && size < 1e-3 * self.newton_tol) {
                if iteration == 0 {
                    self.unmeasured += 1;
                } else {
                    self.unmeasured = 0;
                    if self.theta > 0.3 {
                        // Slow contraction: the reused Jacobian is stale; refresh it next step.
                        self.lu = None;
                    }
                }
                for i in 0..n {
                    q1[i] = st.q[i] + h * st.v[i] + h * h * ((0.5 - b) * st.a[i] + b * a1[i]);
                    v1[i] = st.v[i] + h * ((1.0 - g) * st.a[i] + g * a1[i]);
                }
                let mut next = State {
                    t: st.t + h,
                    q: q1,
                    v: v1,
                    a: a1,
                    power: st.power,
                    work: st.work,
                };
                if self.track_work {
                    let mut a_end = vec![0.0; n];
                    sys.eval(next.t, &next.q, &next.v, &mut a_end, &mut next.power)?;
                    self.evaluations += 1;
                    for j in 0..3 {
                        next.work[j] += 0.5 * h * (st.power[j] + next.power[j]);
                    }
                }
                return Ok(Some(next));
            }
        }
        Ok(None)
    }

    fn factor_jacobian<S: MechanicalSystem + ?Sized>(
        &mut self,
        sys: &S,
        st: &State,
        h: f64,
    ) -> Result<()> {
        let n = st.q.len();
        let (am, af, b, g) = (self.am, self.af, self.beta, self.gamma);
        let mut jac = DMatrix::<f64>::identity(n, n) * (1.0 - am);
        // J = (1 - am) I - (1 - af) (b h^2 df/dq + g h df/dv), in this arithmetic order.
        self.evaluations += jacobian::finite_difference(sys, st, |c| {
            for i in 0..n {
                jac[(i, c.k)] -= (1.0 - af) * b * h * h * (c.f_dq[i] - c.f0[i]) / c.dq;
            }
            for i in 0..n {
                jac[(i, c.k)] -= (1.0 - af) * g * h * (c.f_dv[i] - c.f0[i]) / c.dv;
            }
        })?;
        self.jacobians += 1;
        self.lu = Some(jac.lu());
        self.lu_h = h;
        self.theta = 1.0;
        Ok(())
    }
}

/// Generalized-alpha bound to one run: fixed steps to the end time.
struct GeneralizedAlphaRun {
    stepper: GeneralizedAlpha,
    clock: FixedClock,
}

impl Integrator for GeneralizedAlphaRun {
    fn advance(&mut self, sys: &dyn MechanicalSystem, st: &mut State, _t_end: f64) -> Result<()> {
        self.stepper.step(sys, st, self.clock.h)?;
        self.clock.tick(st);
        Ok(())
    }

    fn stats(&self) -> Stats {
        let g = &self.stepper;
        Stats {
            counts: vec![
                ("steps", self.clock.taken),
                ("evaluations", g.evaluations),
                ("jacobians", g.jacobians),
                ("newton_iterations", g.newton_iterations),
                ("splits", g.splits),
            ],
            dt: Some(self.clock.h),
        }
    }
}
