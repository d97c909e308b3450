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
use crate::solve::dopri5::VELOCITY_ERROR_TIME;
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
/// A step whose Newton iteration contracts slower than this counts its iterations beyond the
/// first against the cost of a new Jacobian (see `GeneralizedAlpha::stale_iterations`); a
/// fresh finite-difference Jacobian gives about 0.005 on the rated paper scene at dt 1e-3 s, a
/// stale one 0.03-0.2 (BENCHMARKS.md section 3, "Newton checked by the sample").
pub const THETA_STALE: f64 = 0.1;
/// Contraction above which the Jacobian is refreshed at once (Newton barely converges).
pub const THETA_SLOW: f64 = 0.3;

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
    /// `Some(size)` if the step ended after Newton's first increment (of `size`, in
    /// displacement at the levers \[m\]) without a measured contraction, its check left to
    /// [`GeneralizedAlpha::confirm`] (only with `provisional_ok`).
    pub provisional: Option<f64>,
}

/// A step accepted after Newton's first increment, awaiting [`GeneralizedAlpha::confirm`]:
/// the state at its start, the start's pseudo-acceleration (rescaled to the step), the size of
/// that increment and the step.
#[derive(Debug)]
struct Held {
    old: State,
    p0: Vec<f64>,
    size: f64,
    h: f64,
    /// The pseudo-acceleration as it was before the step (`p`, `p_t`, `p_h`), for a step taken
    /// again from its start.
    p_before: (Vec<f64>, f64, f64),
}

/// Where a Newton iteration resumes: an evaluation at the current iterate made by someone
/// else (the accelerations `f`), and the size of the increment that led to it.
struct Resume<'a> {
    f: &'a [f64],
    previous_size: f64,
    /// Whether the evaluated iterate should stand if it is within the tolerance (the caller
    /// keeps its evaluation); otherwise the increment is applied as in any iteration.
    keep: bool,
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
    /// Newton iterations beyond the first, on steps that contracted slower than
    /// [`THETA_STALE`], since the last Jacobian. When they reach `stale_budget` the next step
    /// takes a new Jacobian: the stale one has then cost as many evaluations as a new one
    /// (the rent-or-buy rule; Karlin et al., Competitive randomized algorithms for
    /// nonuniform problems, Algorithmica 11, 1994, spend at most twice the best choice).
    stale_iterations: u64,
    /// Stale iterations that buy a new Jacobian: its cost in evaluations (`1 + 2 n`),
    /// multiplied by 4 each time a new one did not contract at least twice as fast (the
    /// contraction is then the forces' nonlinearity, which no Jacobian removes).
    stale_budget: u64,
    /// The contraction that last bought a Jacobian (NaN: none awaiting its verdict).
    theta_bought: f64,
    /// Whether a step may end after Newton's first increment without a measured contraction,
    /// leaving its check to [`GeneralizedAlpha::confirm`] with an evaluation the caller makes
    /// at the step end anyway (a recorded sample).
    pub provisional_ok: bool,
    /// The step last accepted provisionally: what `confirm` needs to continue its Newton
    /// iteration.
    held: Option<Held>,
    /// Whether `confirm` moved the state (the step's end was not within the tolerance).
    moved: bool,
    /// Scratch of `confirm`: the iterate it checks.
    kept: Vec<f64>,
    /// Jacobians computed (and factored).
    pub jacobians: u64,
    /// Newton iterations, all steps.
    pub newton_iterations: u64,
    /// Steps split in halves because Newton stalled.
    pub splits: u64,
    /// Provisional steps taken again from their start because their check's iteration failed.
    pub redone: u64,
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
            stale_iterations: 0,
            stale_budget: 0,
            theta_bought: f64::NAN,
            provisional_ok: false,
            held: None,
            moved: false,
            kept: Vec::new(),
            jacobians: 0,
            newton_iterations: 0,
            splits: 0,
            redone: 0,
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
        if self.held.is_some() {
            // Nobody checked the last step: check it before going on from it.
            self.confirm(sys, st, None)?;
        }
        // Only a step taken whole leaves its power flows to the caller: the caller sees the
        // whole step's ends, not the inner ends of a split one.
        self.defer_now = self.track_work && self.defer_work && depth == 0;
        self.pending = None;
        // A provisional end is checked by an evaluation there, so only a whole step may
        // have one, and only if nobody evaluates the step end's power flows before the check.
        let provisional_ok = self.provisional_ok;
        self.provisional_ok &= depth == 0 && (!self.track_work || self.defer_now);
        let outcome = self.attempt(sys, st, h);
        self.provisional_ok = provisional_ok;
        match outcome {
            Ok(Some(a)) => {
                if self.defer_now {
                    self.pending = Some(h);
                }
                if let Some(size) = a.provisional {
                    self.hold(st, a, size);
                } else {
                    self.accept(st, a);
                }
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

    /// As [`GeneralizedAlpha::accept`] for a provisional `a`, keeping what
    /// [`GeneralizedAlpha::confirm`] needs.
    fn hold(&mut self, st: &mut State, a: Attempt, size: f64) {
        let old_p = std::mem::replace(&mut self.p, a.p1);
        let p_before = (old_p, self.p_t, self.p_h);
        self.p_t = a.next.t;
        self.p_h = a.h;
        let old = std::mem::replace(st, a.next);
        self.held = Some(Held {
            old,
            p0: a.p0,
            size,
            h: a.h,
            p_before,
        });
    }

    /// Whether the last step ended provisionally: [`GeneralizedAlpha::confirm`] must check it
    /// before the state is used (the next `step` does so itself if nobody did).
    pub fn provisional(&self) -> bool {
        self.held.is_some()
    }

    /// Check a provisional step end `st` with the accelerations `f_end` evaluated there (by a
    /// caller that evaluates the state anyway), or with an evaluation of its own (`None`, or a
    /// slice whose length is not the number of coordinates).
    /// Newton's next increment is computed from it: if it is within the tolerance the state
    /// stands (`Ok(true)`); otherwise the iteration goes on from it as it would have, and `st`
    /// becomes its result (`Ok(false)`: what was evaluated at the old `st` is void). A step
    /// whose iteration then fails is taken again from its start, as an unconverged step is.
    pub fn confirm<S: MechanicalSystem + ?Sized>(
        &mut self,
        sys: &S,
        st: &mut State,
        f_end: Option<&[f64]>,
    ) -> Result<bool> {
        let Some(held) = self.held.take() else {
            return Ok(true);
        };
        let n = st.q.len();
        let Held {
            old,
            p0,
            size,
            h,
            p_before,
        } = held;
        // The caller's evaluation, or one of our own (an iterate that failed to evaluate is
        // a step whose Newton failed).
        let mut own = None;
        if f_end.is_none_or(|f| f.len() != n) {
            let mut f = self.take(n);
            let mut power = st.power;
            self.evaluations += 1;
            if sys.eval(st.t, &st.q, &st.v, &mut f, &mut power).is_err() {
                self.give(f);
                self.give(p0);
                return self.redo(sys, st, old, p_before, h);
            }
            own = Some(f);
        }
        let (f_end, keep) = match own.as_deref() {
            Some(f) => (f, false),
            None => (f_end.unwrap_or_default(), true),
        };
        self.moved = false;
        let outcome = self.iterate_from(
            sys,
            &old,
            h,
            p0,
            &st.a,
            Some(Resume {
                f: f_end,
                previous_size: size,
                keep,
            }),
        );
        if let Some(f) = own {
            self.give(f);
        }
        match outcome {
            Ok(Some(a)) => {
                self.give(p_before.0);
                let moved = self.moved;
                // The pseudo-acceleration at `st` is replaced by the confirmed one (the same
                // numbers when the state stands).
                let old_p = std::mem::replace(&mut self.p, a.p1);
                self.p_t = a.next.t;
                self.p_h = a.h;
                let was = std::mem::replace(st, a.next);
                for v in [old_p, a.p0, was.q, was.v, was.a, old.q, old.v, old.a] {
                    self.give(v);
                }
                Ok(!moved)
            }
            Ok(None) | Err(_) => self.redo(sys, st, old, p_before, h),
        }
    }

    /// Take a provisional step that failed its check again from its start `old` (with the
    /// pseudo-acceleration as it was, `p_before`), with a new Jacobian and without a
    /// provisional end, as a step whose Newton fails. `Ok(false)`: the state moved.
    fn redo<S: MechanicalSystem + ?Sized>(
        &mut self,
        sys: &S,
        st: &mut State,
        old: State,
        p_before: (Vec<f64>, f64, f64),
        h: f64,
    ) -> Result<bool> {
        let (p, p_t, p_h) = p_before;
        let p = std::mem::replace(&mut self.p, p);
        self.give(p);
        self.p_t = p_t;
        self.p_h = p_h;
        let was = std::mem::replace(st, old);
        for v in [was.q, was.v, was.a] {
            self.give(v);
        }
        self.stiffness = None;
        self.redone += 1;
        let provisional_ok = std::mem::replace(&mut self.provisional_ok, false);
        let redo = self.advance(sys, st, h, 0);
        self.provisional_ok = provisional_ok;
        redo.map(|()| false)
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
        let p0 = self.p0(st, h);
        // Start from the old acceleration: the first increment then measures the change over
        // the step, and accepting only a small increment keeps small steps accurate (a
        // predictor that starts closer lets the displacement test, which scales with h^2,
        // accept a poorly converged acceleration at small h).
        self.iterate_from(sys, st, h, p0, &st.a, None)
    }

    /// [`GeneralizedAlpha::iterate`] from the step start `st` with the start's
    /// pseudo-acceleration `p0` and the end's acceleration `a1` first set to `a1_start`, with
    /// vectors from the pool and the kept scratch.
    fn iterate_from<S: MechanicalSystem + ?Sized>(
        &mut self,
        sys: &S,
        st: &State,
        h: f64,
        p0: Vec<f64>,
        a1_start: &[f64],
        resume: Option<Resume<'_>>,
    ) -> Result<Option<Attempt>> {
        let n = st.q.len();
        let mut a1 = self.take(n);
        a1.copy_from_slice(a1_start);
        let (p1, q1, v1) = (self.take(n), self.take(n), self.take(n));
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
            resume,
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
        resume: Option<Resume<'_>>,
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
        // A resumed iteration keeps its first iterate here.
        let mut kept = Vec::new();
        if resume.is_some() {
            kept = std::mem::take(&mut self.kept);
            kept.resize(n, 0.0);
        }
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
        let mut previous_size = resume.as_ref().map_or(f64::NAN, |r| r.previous_size);
        // Contraction of this step's iteration, measured only on increments above the
        // tolerance (below it their ratio is round-off).
        let mut theta_step: f64 = 0.0;
        // A resumed iteration is at its second iterate, evaluated by the caller.
        let start = u32::from(resume.is_some());

        for iteration in start..self.max_newton {
            let resumed = iteration == start && resume.is_some();
            if let (true, Some(rs)) = (resumed, resume.as_ref()) {
                f.copy_from_slice(rs.f);
                // The iterate as it was: it stands if its increment is within the tolerance.
                kept.copy_from_slice(&a1);
            } else {
                update(&a1, &mut p1, &mut q1, &mut v1);
                sys.eval(t1, &q1, &v1, f, &mut power)?;
                self.evaluations += 1;
            }
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
            // The evaluated iterate of a resumed iteration stands when its own increment is
            // within the tolerance (the caller's evaluation then stays valid), in displacement
            // and in the displacement its velocity change makes in VELOCITY_ERROR_TIME (the
            // error norm of the adaptive methods): Hairer's test leaves theta times less, and
            // a heavily damped contact feels the velocity error.
            let stands = resumed
                && resume.as_ref().is_some_and(|r| r.keep)
                && size * (gamma * VELOCITY_ERROR_TIME / (beta * h)).max(1.0) < tol;
            // A step may end provisionally after its first increment when a check is sure to
            // follow (`provisional_ok`): it costs the evaluation the next iteration would make.
            let provisional =
                resume.is_none() && iteration == 0 && self.provisional_ok && remaining >= tol;
            if remaining < tol || (iteration > 0 && size < 1e-3 * tol) || stands || provisional {
                if stands {
                    a1.copy_from_slice(&kept);
                }
                if !kept.is_empty() {
                    self.kept = kept;
                }
                if resumed {
                    self.moved = !stands;
                }
                if provisional {
                } else if iteration == 0 {
                    self.unmeasured += 1;
                } else {
                    self.unmeasured = 0;
                    if self.theta > THETA_SLOW {
                        // Slow contraction: the reused Jacobian is stale; refresh it next step.
                        self.stiffness = None;
                    }
                    if !self.theta_bought.is_nan() && theta_step > 0.0 {
                        let cost = 1 + 2 * n as u64;
                        self.stale_budget = if theta_step > 0.5 * self.theta_bought {
                            (self.stale_budget.max(cost) * 4).min(1 << 20)
                        } else {
                            cost
                        };
                        self.theta_bought = f64::NAN;
                    }
                    if theta_step > THETA_STALE && theta_step <= THETA_SLOW {
                        self.stale_iterations += u64::from(iteration);
                        if self.stale_iterations >= self.stale_budget.max(1 + 2 * n as u64) {
                            self.stiffness = None;
                            self.theta_bought = theta_step;
                        }
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
                    provisional: provisional.then_some(size),
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
        self.stale_iterations = 0;
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

    fn check_with_samples(&mut self) -> bool {
        self.stepper.provisional_ok = true;
        true
    }

    fn provisional(&self) -> bool {
        self.stepper.provisional()
    }

    fn confirm(
        &mut self,
        sys: &dyn MechanicalSystem,
        st: &mut State,
        f_end: Option<&[f64]>,
    ) -> Result<bool> {
        let t = st.t;
        let stands = self.stepper.confirm(sys, st, f_end)?;
        // A step taken again from its start ends at the clock's time again.
        if st.t != t {
            self.stepper.retime(st.t, t);
            st.t = t;
        }
        Ok(stands)
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
