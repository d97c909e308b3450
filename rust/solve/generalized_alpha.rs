//! Generalized-alpha, implicit, second order, with controllable high-frequency dissipation
//! `rho_inf` for stiff penalty contact, in the form of Arnold & Bruls (Convergence of the
//! generalized-alpha scheme for constrained mechanical systems, Multibody System Dynamics 18,
//! 2007, eqs. 5-6): the equation of motion holds at the step end, and a pseudo-acceleration
//! `p` carries the alpha weights.
//!
//! With `M` folded into `f = M^-1 Q`, each step solves for the acceleration `a1` at `t + h`:
//! `R(a1) = a1 - f(t + h, q1, v1) = 0`, with
//! `(1 - alpha_m) p1 + alpha_m p0 = (1 - alpha_f) a1 + alpha_f a0`,
//! `q1 = q0 + h v0 + h^2 ((1/2 - beta) p0 + beta p1)`,
//! `v1 = v0 + h ((1 - gamma) p0 + gamma p1)`, and the parameters of Chung & Hulbert (J. Appl.
//! Mech. 60, 1993) from `rho_inf`. For a linear system this is the Chung-Hulbert method; for
//! the strongly nonlinear contact forces here it is 5-9 times more accurate at large steps,
//! because the forces are evaluated at the step ends instead of at alpha-weighted intermediate
//! states (measured on the paper scenes: `examples/ga_experiment.rs`). The state's `a` is then
//! the true acceleration, as the cubic Hermite output between steps assumes.
//!
//! `p` approximates the acceleration at `t + (alpha_m - alpha_f) h` (Arnold & Bruls 2007,
//! section 3); it starts as `a` (restart), and when the step changes from `h` to `h'` its shift
//! is rescaled, `p <- a + (h'/h) (p - a)`.
//!
//! Newton uses a finite-difference Jacobian `J = I - s (beta h^2 K + gamma h C)`,
//! `s = (1 - alpha_f)/(1 - alpha_m)`, `K = df/dq`, `C = df/dv`, reused across steps while
//! Newton converges fast (re-assembled without new force evaluations when only the step
//! changes); a step whose Newton stalls is retried with a fresh Jacobian and then
//! split in halves (down to 1/1024 of the step) before the run is declared failed.
//!
//! Theory: docs/model.md, sections "Generalized-alpha (Arnold & Bruls form) with Newton"
//! and "Newton tolerance of generalized-alpha".

use crate::error::{Result, RvdynError};
use crate::solve::integrator::{FixedClock, Integrator, IntegratorEntry, Settings, Stats};
use crate::solve::jacobian;
use crate::solve::system::{MechanicalSystem, State};
use nalgebra::{DMatrix, DVector};

/// Newton stops once its remaining error is below this fraction of the step's local error
/// estimate (max norm, the estimate of `adaptive_alpha`) ... Chosen by work-precision on the
/// rated paper scene (BENCHMARKS.md section 3): from 0.001 to 0.005 the pin-force errors at
/// dt 2e-4 to 1e-3 s stay those of a fully converged Newton to 1 % with 27-43 % fewer
/// iterations at dt 5e-4 and 1e-3 s; from 0.01 up the iteration count grows erratically.
pub const NEWTON_KAPPA: f64 = 0.003;
/// ... but never looser than this multiple of the Newton tolerance `atol`.
pub const NEWTON_LOOSEST: f64 = 10.0;

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

/// A converged step not yet accepted: the state at its end and the pseudo-accelerations.
#[derive(Debug, Clone)]
pub struct Attempt {
    /// The state at the end of the step.
    pub next: State,
    /// Pseudo-acceleration at the start (rescaled to this step) and at the end.
    pub p0: Vec<f64>,
    /// Pseudo-acceleration at the end of the step.
    pub p1: Vec<f64>,
    /// The step \[s\].
    pub h: f64,
    /// Largest contraction factor of the Newton iteration of this step, over increments above
    /// the Newton tolerance (0 if none was measured).
    pub theta: f64,
}

/// The vectors of one Newton iteration: the start's pseudo-acceleration, the end's
/// acceleration, pseudo-acceleration, coordinates and velocities (which become the attempt),
/// and the scratch of the evaluation and the residual.
struct Vectors<'a> {
    p0: Vec<f64>,
    a1: Vec<f64>,
    p1: Vec<f64>,
    q1: Vec<f64>,
    v1: Vec<f64>,
    f: &'a mut Vec<f64>,
    r: &'a mut DVector<f64>,
}

/// Generalized-alpha stepper with Jacobian reuse.
#[derive(Debug)]
pub struct GeneralizedAlpha {
    alpha_m: f64,
    alpha_f: f64,
    beta: f64,
    gamma: f64,
    /// Newton tolerance on the displacement increment \[m\].
    pub newton_tol: f64,
    /// Fraction of the step's local error estimate below which Newton stops (within
    /// `[newton_tol, NEWTON_LOOSEST newton_tol]`); 0 iterates to `newton_tol` always.
    pub newton_kappa: f64,
    /// Maximum Newton iterations per try.
    pub max_newton: u32,
    /// Whether the end-of-step power flows are evaluated (one more force evaluation per step)
    /// for the energy balance; otherwise the work integrals are not kept.
    pub track_work: bool,
    /// With `track_work`: leave the end-of-step power flows and work increment of a step
    /// taken whole to the caller (`pending`), who may have an evaluation at that state anyway
    /// (a recorded sample); split steps still do their own.
    pub defer_work: bool,
    /// The step whose power flows and work increment were left to the caller.
    pub pending: Option<f64>,
    /// Whether the step being attempted defers its power flows.
    defer_now: bool,
    /// `df/dq` and `df/dv` by finite differences, kept to re-assemble `J` for a new step.
    stiffness: Option<(DMatrix<f64>, DMatrix<f64>)>,
    lu: Option<nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>>,
    lu_h: f64,
    /// Pseudo-acceleration at time `p_t`, made with the step `p_h` (empty: not started).
    p: Vec<f64>,
    p_t: f64,
    p_h: f64,
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
    /// Vectors of accepted steps' old states and pseudo-accelerations, reused by the next
    /// steps instead of new allocations.
    spare: Vec<Vec<f64>>,
    /// The accelerations of an evaluation and the Newton residual (solved in place).
    f: Vec<f64>,
    residual: DVector<f64>,
}

/// Most vectors kept in [`GeneralizedAlpha`]'s pool (a step takes five).
const SPARE_VECTORS: usize = 8;

impl GeneralizedAlpha {
    /// Parameters from the spectral radius at infinite frequency `rho_inf` in `[0, 1]`
    /// (1 = no numerical dissipation, 0 = asymptotic annihilation).
    pub fn new(rho_inf: f64, newton_tol: f64, track_work: bool) -> Result<Self> {
        if !(0.0..=1.0).contains(&rho_inf) {
            return Err(RvdynError::Parameter(format!(
                "rho_inf must be in [0, 1] (1 = no numerical damping), got {rho_inf}"
            )));
        }
        let alpha_m = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0);
        let alpha_f = rho_inf / (rho_inf + 1.0);
        let gamma = 0.5 - alpha_m + alpha_f;
        let beta = 0.25 * (1.0 - alpha_m + alpha_f).powi(2);
        Ok(Self {
            alpha_m,
            alpha_f,
            beta,
            gamma,
            newton_tol,
            newton_kappa: NEWTON_KAPPA,
            max_newton: 8,
            track_work,
            defer_work: false,
            pending: None,
            defer_now: false,
            stiffness: None,
            lu: None,
            lu_h: 0.0,
            p: Vec::new(),
            p_t: f64::NAN,
            p_h: f64::NAN,
            theta: 1.0,
            unmeasured: 0,
            jacobians: 0,
            newton_iterations: 0,
            splits: 0,
            evaluations: 0,
            spare: Vec::new(),
            f: Vec::new(),
            residual: DVector::zeros(0),
        })
    }

    /// A vector of length `n` (contents unspecified), from the pool if it has one.
    fn take(&mut self, n: usize) -> Vec<f64> {
        let mut v = self.spare.pop().unwrap_or_default();
        v.resize(n, 0.0);
        v
    }

    /// Return a vector to the pool.
    fn give(&mut self, v: Vec<f64>) {
        if self.spare.len() < SPARE_VECTORS {
            self.spare.push(v);
        }
    }

    /// `(beta, gamma)` of the Newmark updates.
    pub fn newmark(&self) -> (f64, f64) {
        (self.beta, self.gamma)
    }

    /// Advance `st` by `h` \[s\] (in sub-steps if Newton needs them).
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
        // Only a step taken whole leaves its power flows to the caller: the caller sees the
        // whole step's ends, not the inner ends of a split one.
        self.defer_now = self.track_work && self.defer_work && depth == 0;
        self.pending = None;
        match self.attempt(sys, st, h) {
            Ok(Some(a)) => {
                if self.defer_now {
                    self.pending = Some(h);
                }
                self.accept(st, a);
                Ok(())
            }
            Ok(None) | Err(_) if depth < 10 => {
                self.defer_now = false;
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

    /// Make `a` the state: its pseudo-acceleration becomes the start of the next step.
    pub fn accept(&mut self, st: &mut State, a: Attempt) {
        let old_p = std::mem::replace(&mut self.p, a.p1);
        self.p_t = a.next.t;
        self.p_h = a.h;
        let old = std::mem::replace(st, a.next);
        for v in [old_p, a.p0, old.q, old.v, old.a] {
            self.give(v);
        }
    }

    /// The state's time moved from `from` to `to` (a fixed-step clock setting it to `k h`,
    /// within an ulp of the running sum): the pseudo-acceleration made at `from` goes with it.
    pub fn retime(&mut self, from: f64, to: f64) {
        if self.p_t == from {
            self.p_t = to;
        }
    }

    /// Forget the pseudo-acceleration: the next step starts it again from the acceleration
    /// (after an impact, where its history says nothing about the next step).
    pub fn restart(&mut self) {
        self.p.clear();
    }

    /// The pseudo-acceleration at the start of a step `h` from `st`.
    fn p0(&mut self, st: &State, h: f64) -> Vec<f64> {
        let mut p0 = self.take(st.a.len());
        if self.p.len() != st.a.len() || self.p_t != st.t {
            p0.copy_from_slice(&st.a);
        } else if self.p_h == h {
            p0.copy_from_slice(&self.p);
        } else {
            let r = h / self.p_h;
            for (i, p) in p0.iter_mut().enumerate() {
                *p = st.a[i] + r * (self.p[i] - st.a[i]);
            }
        }
        p0
    }

    /// One step of size `h` from `st`, not yet accepted; `Ok(None)` if Newton does not
    /// converge (even with a fresh Jacobian).
    pub fn attempt<S: MechanicalSystem + ?Sized>(
        &mut self,
        sys: &S,
        st: &State,
        h: f64,
    ) -> Result<Option<Attempt>> {
        for attempt in 0..2 {
            if self.stiffness.is_none() || attempt == 1 {
                self.jacobian(sys, st)?;
            }
            if self.lu.is_none() || self.lu_h != h {
                self.factor(h);
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
    ) -> Result<Option<Attempt>> {
        let n = st.q.len();
        let p0 = self.p0(st, h);
        // Start from the old acceleration: the first increment then measures the change over
        // the step, and accepting only a small increment keeps small steps accurate (a
        // predictor that starts closer lets the displacement test, which scales with h^2,
        // accept a poorly converged acceleration at small h).
        let mut a1 = self.take(n);
        a1.copy_from_slice(&st.a);
        let p1 = self.take(n);
        let q1 = self.take(n);
        let v1 = self.take(n);
        let mut f = std::mem::take(&mut self.f);
        f.resize(n, 0.0);
        let mut r = std::mem::replace(&mut self.residual, DVector::zeros(0));
        if r.len() != n {
            r = DVector::zeros(n);
        }
        let outcome = self.iterate(
            sys,
            st,
            h,
            Vectors {
                p0,
                a1,
                p1,
                q1,
                v1,
                f: &mut f,
                r: &mut r,
            },
        );
        self.f = f;
        self.residual = r;
        outcome
    }

    /// The Newton iteration of [`GeneralizedAlpha::newton`] with its vectors.
    fn iterate<S: MechanicalSystem + ?Sized>(
        &mut self,
        sys: &S,
        st: &State,
        h: f64,
        vectors: Vectors<'_>,
    ) -> Result<Option<Attempt>> {
        let Vectors {
            p0,
            mut a1,
            mut p1,
            mut q1,
            mut v1,
            f,
            r,
        } = vectors;
        let n = st.q.len();
        let (alpha_m, alpha_f, beta, gamma) = (self.alpha_m, self.alpha_f, self.beta, self.gamma);
        let scale = sys.length_scale();
        // dq1/da1.
        let dq_da = beta * h * h * (1.0 - alpha_f) / (1.0 - alpha_m);
        let mut power = [0.0; 3];
        let t1 = st.t + h;
        let Some(lu) = self.lu.as_ref() else {
            return Ok(None);
        };
        let update = |a1: &[f64], p1: &mut [f64], q1: &mut [f64], v1: &mut [f64]| {
            for i in 0..n {
                p1[i] = ((1.0 - alpha_f) * a1[i] + alpha_f * st.a[i] - alpha_m * p0[i])
                    / (1.0 - alpha_m);
                q1[i] = st.q[i] + h * st.v[i] + h * h * ((0.5 - beta) * p0[i] + beta * p1[i]);
                v1[i] = st.v[i] + h * ((1.0 - gamma) * p0[i] + gamma * p1[i]);
            }
        };
        let mut previous_size = f64::NAN;
        // Contraction of this step's iteration, measured only on increments above the
        // tolerance (below it their ratio is round-off).
        let mut theta_step: f64 = 0.0;
        for iteration in 0..self.max_newton {
            update(&a1, &mut p1, &mut q1, &mut v1);
            sys.eval(t1, &q1, &v1, f, &mut power)?;
            self.evaluations += 1;
            self.newton_iterations += 1;
            for i in 0..n {
                r[i] = a1[i] - f[i];
            }
            if !lu.solve_mut(r) {
                return Ok(None);
            }
            let delta = &*r;
            let mut size: f64 = 0.0;
            let mut local: f64 = 0.0;
            for i in 0..n {
                a1[i] -= delta[i];
                size = size.max((dq_da * delta[i] * scale[i]).abs());
                let p1i = ((1.0 - alpha_f) * a1[i] + alpha_f * st.a[i] - alpha_m * p0[i])
                    / (1.0 - alpha_m);
                let e_q = h * h * ((0.5 - beta) * p0[i] + beta * p1i - st.a[i] / 3.0 - a1[i] / 6.0);
                local = local.max((e_q * scale[i]).abs());
            }
            if !size.is_finite() {
                return Ok(None);
            }
            // Iterating far below the step's own truncation error buys nothing: the tolerance
            // is newton_kappa (NEWTON_KAPPA) times the local error estimate (the adaptive method's, see
            // adaptive_alpha), within [newton_tol, NEWTON_LOOSEST newton_tol] (Hairer & Wanner,
            // Solving ODEs II, 2nd ed., section IV.8, stop Newton at kappa Tol).
            let tol = (self.newton_kappa * local)
                .clamp(self.newton_tol, NEWTON_LOOSEST * self.newton_tol);
            // Hairer's test: the error left after this increment is about theta/(1 - theta)
            // times it, theta the contraction of the iteration (kept from the last step that
            // took two iterations; 1 after a new Jacobian, which forces a second iteration).
            if iteration > 0 {
                self.theta = (size / previous_size).min(1.0);
                if previous_size > tol {
                    theta_step = theta_step.max(self.theta);
                }
            }
            previous_size = size;
            // One iteration is trusted only while theta is fresh: every fourth step measures it
            // again, since a contact change can slow the iteration without any failure showing.
            // It is also not trusted for a large first increment (a violent step, such as an
            // impact, where the linear model behind theta says little).
            let trusted = iteration > 0 || (self.unmeasured < 3 && size < 100.0 * tol);
            let remaining = if self.theta < 1.0 && trusted {
                self.theta / (1.0 - self.theta) * size
            } else {
                f64::INFINITY
            };
            if remaining < tol || (iteration > 0 && size < 1e-3 * tol) {
                if iteration == 0 {
                    self.unmeasured += 1;
                } else {
                    self.unmeasured = 0;
                    if self.theta > 0.3 {
                        // Slow contraction: the reused Jacobian is stale; refresh it next step.
                        self.stiffness = None;
                    }
                }
                update(&a1, &mut p1, &mut q1, &mut v1);
                let mut next = State {
                    t: t1,
                    q: q1,
                    v: v1,
                    a: a1,
                    power: st.power,
                    work: st.work,
                };
                if self.track_work && !self.defer_now {
                    let mut a_end = vec![0.0; n];
                    sys.eval(next.t, &next.q, &next.v, &mut a_end, &mut next.power)?;
                    self.evaluations += 1;
                    for j in 0..3 {
                        next.work[j] += 0.5 * h * (st.power[j] + next.power[j]);
                    }
                }
                return Ok(Some(Attempt {
                    next,
                    p0,
                    p1,
                    h,
                    theta: theta_step,
                }));
            }
        }
        Ok(None)
    }

    /// `df/dq` and `df/dv` at `st` by finite differences.
    fn jacobian<S: MechanicalSystem + ?Sized>(&mut self, sys: &S, st: &State) -> Result<()> {
        let n = st.q.len();
        let mut kq = DMatrix::<f64>::zeros(n, n);
        let mut kv = DMatrix::<f64>::zeros(n, n);
        self.evaluations += jacobian::finite_difference(sys, st, |c| {
            for i in 0..n {
                kq[(i, c.k)] = (c.f_dq[i] - c.f0[i]) / c.dq;
                kv[(i, c.k)] = (c.f_dv[i] - c.f0[i]) / c.dv;
            }
        })?;
        self.jacobians += 1;
        self.stiffness = Some((kq, kv));
        self.lu = None;
        self.theta = 1.0;
        Ok(())
    }

    /// Assemble and factor `J = I - s (beta h^2 K + gamma h C)` for the step `h`.
    fn factor(&mut self, h: f64) {
        let Some((kq, kv)) = self.stiffness.as_ref() else {
            return;
        };
        let n = kq.nrows();
        let s = (1.0 - self.alpha_f) / (1.0 - self.alpha_m);
        let (cq, cv) = (s * self.beta * h * h, s * self.gamma * h);
        let jac = DMatrix::from_fn(n, n, |i, k| {
            let id = if i == k { 1.0 } else { 0.0 };
            id - cq * kq[(i, k)] - cv * kv[(i, k)]
        });
        self.lu = Some(jac.lu());
        self.lu_h = h;
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
        let t = st.t;
        self.clock.tick(st);
        self.stepper.retime(t, st.t);
        Ok(())
    }

    fn defer_step_power(&mut self) -> bool {
        self.stepper.defer_work = true;
        true
    }

    fn pending_work(&self) -> Option<f64> {
        self.stepper.pending
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
