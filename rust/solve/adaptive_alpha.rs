//! Error-controlled generalized-alpha: the Arnold-Bruls stepper of
//! [`generalized_alpha`](crate::solve::generalized_alpha) with a step chosen for a local error
//! tolerance.
//!
//! **Local error estimate.** The step's displacement and velocity are compared with a
//! quadrature of the same end accelerations that is one order higher:
//! `q* = q0 + h v0 + h^2 (a0/3 + a1/6)` (the Taylor series to `h^3` with the jerk
//! `(a1 - a0)/h`) and the trapezoidal `v* = v0 + h (a0 + a1)/2`, so
//! `e_q = h^2 ((1/2 - b) p0 + b p1 - a0/3 - a1/6)` and
//! `e_v = h ((1 - g) p0 + g p1 - (a0 + a1)/2)`. With `p = a` this is the estimate of
//! Zienkiewicz & Xie (A simple error estimator and adaptive time stepping procedure for dynamic
//! analysis, Earthquake Eng. Struct. Dyn. 20, 1991), `e_q = (b - 1/6) h^2 (a1 - a0)`; the
//! Arnold-Bruls form makes `a0`, `a1` the true end accelerations it needs.
//!
//! **Norm.** As dopri5's: displacements at each coordinate's lever against `atol` \[m\],
//! velocities over [`VELOCITY_ERROR_TIME`] against `atol + rtol |v|`, weighted RMS over both;
//! then per unit step, times `VELOCITY_ERROR_TIME / h` (the error the step's rate would
//! accumulate over that time). The local error of a second-order method is `O(h^3)`, so this
//! is `O(h^2)` and the global error, `O(h^2)` too, is proportional to the tolerance
//! (Hairer, Norsett & Wanner, Solving ODEs I, 2nd ed., section II.4).
//!
//! **Controller.** A step is accepted when the norm is at most 1, and the next step is
//! `h 0.9 err^(-0.7/2) err_prev^(0.4/2)`, within `[0.2 h, 2 h]` (the PI controller of Gustafsson,
//! ACM Trans. Math. Softw. 17, 1991, with the exponents of Hairer & Wanner, Solving ODEs II,
//! 2nd ed., section IV.8, for an error of order 2). A rejected step is retried with
//! `h 0.9 err^(-1/2)`, within
//! `[0.2 h, 0.9 h]`. A step whose Newton iteration contracts poorly
//! (theta > 0.5: a contact changed state within it) or fails, or whose forces leave their
//! physical bounds, is retried 4 times shorter; after a rejection with an error above 10 (an
//! impact) the pseudo-acceleration restarts from the acceleration.
//!
//! **Non-smooth forces.** A roller's or a contact's stiffness-proportional damper at first touch
//! makes a force that rises as a fractional power of the time since contact (the roller law's
//! tangent stiffness grows as `delta^(1/9)`); within a step across it the error per unit step
//! stays near a constant however short the step, and the controller above would shrink the step
//! to `h_min`, or creeps up to the instant of touch with ever shorter accepted steps. After
//! [`MAX_REJECTIONS`] error-test rejections in a row (steps accepted in between that end before
//! the last rejected step would have do not break the row), a step is therefore
//! accepted when its error per step (the norm without the factor `VELOCITY_ERROR_TIME / h`) is
//! within the tolerance: error-per-step control, which a low-order event can satisfy (Hairer,
//! Norsett & Wanner, Solving ODEs I, 2nd ed., section II.4, on error per step and per unit
//! step). Counted as `nonsmooth` in the statistics. As a last resort, a rejected step whose
//! retry would fall below `h_min` is accepted the same way when its error per step allows (a
//! force that switches on and off step after step, where each new row of rejections would
//! shrink the step again).
//!
//! **First touch.** A step that closes a contact from open to deeper than its law's damping
//! ramp (`MechanicalSystem::deepest_first_touch`, the IMPACT law's damping depth) is rejected and
//! retried shorter, whatever its error estimate; counted as `too_deep`.
//!
//! **Limits.** The step stays in `[h_min, h_max]`; below `h_min`, or beyond `max_steps`
//! accepted steps, the run stops with a `SimulationError` naming the time and the cause.
//!
//! Theory: docs/model.md, section "Error-controlled generalized-alpha".

use crate::error::{Result, RvdynError};
use crate::solve::dopri5::VELOCITY_ERROR_TIME;
use crate::solve::generalized_alpha::{Attempt, GeneralizedAlpha};
use crate::solve::integrator::{Integrator, IntegratorEntry, Settings, Stats, landing_step};
use crate::solve::system::{MechanicalSystem, State};

/// Registry entry of the error-controlled generalized-alpha.
pub static ENTRY: IntegratorEntry = IntegratorEntry {
    name: "generalized-alpha-adaptive",
    aliases: &["adaptive-alpha", "ga-adaptive", "genalpha-adaptive"],
    default_dt: 1e-5,
    adaptive: true,
    summary: "generalized-alpha (Arnold-Bruls form), implicit, order 2, step chosen for \
              atol/rtol (local error estimate, PI controller)",
    build: |s: &Settings| Ok(Box::new(AdaptiveAlpha::new(s)?)),
};

/// Error-controlled generalized-alpha bound to one run.
#[derive(Debug)]
pub struct AdaptiveAlpha {
    stepper: GeneralizedAlpha,
    /// Step of the next try \[s\].
    pub h: f64,
    rtol: f64,
    atol: f64,
    h_min: f64,
    h_max: f64,
    max_steps: u64,
    err_prev: f64,
    /// Accepted steps.
    pub accepted: u64,
    /// Steps rejected by the error test.
    pub rejected: u64,
    /// Steps retried shorter because Newton failed or contracted poorly or a force left its
    /// bounds.
    pub retried: u64,
    /// Steps accepted on their error per step after [`MAX_REJECTIONS`] error-test rejections
    /// in a row (a force not smooth in time within them).
    pub nonsmooth: u64,
    /// Steps rejected because a contact closed deeper than its law allows in one step.
    pub too_deep: u64,
    /// Whether the contacts open at the run's start have been marked.
    marked: bool,
    /// Error-test rejections since the run last passed the end of a rejected step.
    streak: u32,
    /// End time of the last rejected step \[s\] (-inf without one).
    streak_end: f64,
}

/// Error-test rejections (in a row, or separated only by accepted steps that end before the
/// last rejected one would have) after which a step is accepted on its error per step (instead
/// of per unit step).
pub const MAX_REJECTIONS: u32 = 4;

impl AdaptiveAlpha {
    /// Build from the run settings: `dt` is the first step, `atol` \[m\] and `rtol` the
    /// tolerances (the Newton tolerance is a tenth of `atol`).
    pub fn new(s: &Settings) -> Result<Self> {
        s.check_adaptive()?;
        Ok(Self {
            stepper: GeneralizedAlpha::new(s.rho_inf, 0.1 * s.atol, s.track_work)?,
            h: s.dt.clamp(s.h_min, s.h_max),
            rtol: s.rtol,
            atol: s.atol,
            h_min: s.h_min,
            h_max: s.h_max,
            max_steps: s.max_steps,
            err_prev: 1e-4,
            accepted: 0,
            rejected: 0,
            retried: 0,
            nonsmooth: 0,
            too_deep: 0,
            marked: false,
            streak: 0,
            streak_end: f64::NEG_INFINITY,
        })
    }

    /// Weighted RMS norm [-] of the local error of the attempt `a` from the state `st` (see the
    /// module documentation): each coordinate's error is taken at its lever
    /// (`MechanicalSystem::length_scale`, \[m\] per unit) against `atol` \[m\] and `rtol`, so
    /// the step is accepted at a norm of at most 1.
    pub fn error_norm(
        &self,
        sys: &(impl MechanicalSystem + ?Sized),
        st: &State,
        a: &Attempt,
    ) -> f64 {
        let (b, g) = self.stepper.newmark();
        let (h, n) = (a.h, st.q.len());
        let scale = sys.length_scale();
        let (a0, a1) = (&st.a, &a.next.a);
        let mut sum = 0.0;
        for i in 0..n {
            let eq = h * h * ((0.5 - b) * a.p0[i] + b * a.p1[i] - a0[i] / 3.0 - a1[i] / 6.0);
            let ev = h * ((1.0 - g) * a.p0[i] + g * a.p1[i] - 0.5 * (a0[i] + a1[i]));
            let l = scale[i];
            let wq = eq * l / self.atol;
            let vmax = st.v[i].abs().max(a.next.v[i].abs());
            let t = VELOCITY_ERROR_TIME;
            let wv = ev * l * t / (self.atol + self.rtol * vmax * l * t);
            sum += wq * wq + wv * wv;
        }
        // Error per unit step: the local error over the step, times the time the
        // tolerance refers to over the step.
        (sum / (2 * n) as f64).sqrt() * (VELOCITY_ERROR_TIME / h)
    }

    fn too_small(&self, st: &State, h: f64, why: &str) -> RvdynError {
        RvdynError::Simulation(format!(
            "generalized-alpha-adaptive: the step fell to {h:.3e} s, below the minimum step \
             {:.3e} s, at t = {:.6e} s ({why}): an impact that never resolves or a state that \
             has gone unstable; loosen atol/rtol, lower h_min, or check the contact stiffness",
            self.h_min, st.t
        ))
    }
}

impl AdaptiveAlpha {
    /// Take the step `a` of size `h` on its error per step (counted as `nonsmooth`); the next
    /// step is as long.
    fn accept_nonsmooth(&mut self, sys: &dyn MechanicalSystem, st: &mut State, a: Attempt, h: f64) {
        self.streak = 0;
        self.streak_end = f64::NEG_INFINITY;
        self.accepted += 1;
        self.nonsmooth += 1;
        self.err_prev = 1.0;
        self.stepper.accept(st, a);
        sys.mark_open_contacts();
        self.h = h.clamp(self.h_min, self.h_max);
    }
}

impl Integrator for AdaptiveAlpha {
    fn advance(&mut self, sys: &dyn MechanicalSystem, st: &mut State, t_end: f64) -> Result<()> {
        if self.accepted >= self.max_steps {
            return Err(RvdynError::Simulation(format!(
                "generalized-alpha-adaptive needed more than max_steps = {} steps to reach \
                 t = {:.6e} s (stopped at t = {:.6e} s): loosen atol/rtol or raise max_steps",
                self.max_steps, t_end, st.t
            )));
        }
        if !self.marked {
            // The last evaluation is the start state's.
            sys.mark_open_contacts();
            self.marked = true;
        }
        loop {
            let remaining = t_end - st.t;
            let h = landing_step(self.h, self.h_max, remaining);
            if h < self.h_min && h < remaining {
                return Err(self.too_small(st, h, "error test"));
            }
            let outcome = self.stepper.attempt(sys, st, h);
            let (factor, why) = match outcome {
                Ok(Some(a)) if a.theta <= 0.5 => {
                    let err = self.error_norm(sys, st, &a);
                    // A contact that closed within the step deeper than its law's ramp (the
                    // IMPACT damping depth) jumped the ramp: retry shorter, whatever the error
                    // estimate says (the approach grows about linearly with the step).
                    if let Some((depth, what)) = sys.deepest_first_touch().filter(|d| d.0 > 1.0) {
                        self.too_deep += 1;
                        self.h = h * (0.9 / depth).clamp(0.2, 0.9);
                        if self.h < self.h_min {
                            return Err(self.too_small(
                                st,
                                self.h,
                                &format!("a contact closing too deep: {what}"),
                            ));
                        }
                        continue;
                    }
                    if err <= 1.0 {
                        // Past the trouble once the run passes the end of the last rejected
                        // step.
                        if st.t + h >= self.streak_end {
                            self.streak = 0;
                            self.streak_end = f64::NEG_INFINITY;
                        }
                        self.accepted += 1;
                        let grow =
                            0.9 * err.max(1e-10).powf(-0.7 / 2.0) * self.err_prev.powf(0.4 / 2.0);
                        self.err_prev = err.max(1e-4);
                        self.stepper.accept(st, a);
                        sys.mark_open_contacts();
                        self.h = (h * grow.clamp(0.2, 2.0)).clamp(self.h_min, self.h_max);
                        return Ok(());
                    }
                    // A force that is not smooth in time within the step (a roller or contact
                    // damper at first touch, whose force rises as a fractional power of the
                    // time since contact) leaves the error per unit step near a constant as
                    // the step shrinks: after MAX_REJECTIONS rejections in a row, the step is
                    // taken once its error per step is within the tolerance. The rejections
                    // count across the short steps accepted in between (the controller creeps
                    // up to the instant of first touch with ever shorter accepted steps) until
                    // the run passes the end of the last rejected step.
                    let per_step = err * h / VELOCITY_ERROR_TIME;
                    if self.streak >= MAX_REJECTIONS && per_step <= 1.0 {
                        self.accept_nonsmooth(sys, st, a, h);
                        return Ok(());
                    }
                    // A force that switches back and forth within microseconds (a roller's
                    // damper held at zero by "never pull", on the edge of separating) can
                    // need such steps one after another: each new row of rejections would
                    // shrink the step again, below h_min. Rather than stop the run there, a
                    // step whose error per step is within the tolerance is taken (a last
                    // resort: runs that never reach h_min are not changed by it).
                    let retry = (0.9 * err.powf(-0.5)).clamp(0.2, 0.9);
                    if h * retry < self.h_min && per_step <= 1.0 {
                        self.accept_nonsmooth(sys, st, a, h);
                        return Ok(());
                    }
                    self.rejected += 1;
                    self.streak += 1;
                    self.streak_end = st.t + h;
                    if err > 10.0 {
                        self.stepper.restart();
                    }
                    (retry, "error test")
                }
                Ok(_) => {
                    self.retried += 1;
                    self.stepper.restart();
                    (0.25, "Newton iteration contracting poorly")
                }
                Err(RvdynError::Simulation(m)) => {
                    self.retried += 1;
                    self.stepper.restart();
                    if h * 0.25 < self.h_min {
                        return Err(RvdynError::Simulation(format!(
                            "{} (generalized-alpha-adaptive could not avoid it with steps down \
                             to the minimum {:.3e} s)",
                            m, self.h_min
                        )));
                    }
                    (0.25, "forces beyond their physical bounds")
                }
                Err(e) => return Err(e),
            };
            self.h = h * factor;
            if self.h < self.h_min {
                return Err(self.too_small(st, self.h, why));
            }
        }
    }

    fn stats(&self) -> Stats {
        let g = &self.stepper;
        Stats {
            counts: vec![
                ("steps", self.accepted),
                ("rejected", self.rejected),
                ("retried", self.retried),
                ("nonsmooth", self.nonsmooth),
                ("too_deep", self.too_deep),
                ("evaluations", g.evaluations),
                ("jacobians", g.jacobians),
                ("newton_iterations", g.newton_iterations),
            ],
            dt: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solve::Method;

    /// `x'' = -w^2 x - 2 z w x'` in two uncoupled coordinates (metres), x(0) = 1, x'(0) = 0.
    struct Oscillator {
        w: [f64; 2],
        z: f64,
        /// Fails (as a force beyond its bound does) once `t` passes this.
        fail_after: f64,
    }

    impl MechanicalSystem for Oscillator {
        fn dof(&self) -> usize {
            2
        }
        fn eval(
            &self,
            t: f64,
            q: &[f64],
            v: &[f64],
            a: &mut [f64],
            _: &mut [f64; 3],
        ) -> Result<()> {
            if t > self.fail_after {
                return Err(RvdynError::Simulation("force beyond its bound".into()));
            }
            for i in 0..2 {
                a[i] = -self.w[i] * self.w[i] * q[i] - 2.0 * self.z * self.w[i] * v[i];
            }
            Ok(())
        }
        fn length_scale(&self) -> &[f64] {
            &[1.0, 1.0]
        }
    }

    fn exact(w: f64, z: f64, t: f64) -> f64 {
        let wd = w * (1.0 - z * z).sqrt();
        (-z * w * t).exp() * ((wd * t).cos() + z * w / wd * (wd * t).sin())
    }

    fn settings(atol: f64) -> Settings {
        Settings {
            t_end: 2.0,
            dt: 1e-3,
            rtol: 0.0,
            atol,
            rho_inf: 0.8,
            h_max: 2.0,
            h_min: 1e-12,
            max_steps: u64::MAX,
            track_work: false,
        }
    }

    fn osc() -> Oscillator {
        Oscillator {
            w: [3.0, 7.0],
            z: 0.05,
            fail_after: f64::INFINITY,
        }
    }

    /// Largest displacement error over the run, and the steps taken.
    fn run(atol: f64) -> (f64, u64) {
        let sys = osc();
        let mut ga = AdaptiveAlpha::new(&settings(atol)).unwrap();
        let mut st = State::new(&sys, 0.0, vec![1.0, 1.0], vec![0.0, 0.0]).unwrap();
        let mut worst: f64 = 0.0;
        while st.t < 2.0 {
            ga.advance(&sys, &mut st, 2.0).unwrap();
            for i in 0..2 {
                worst = worst.max((st.q[i] - exact(sys.w[i], sys.z, st.t)).abs());
            }
        }
        assert!((st.t - 2.0).abs() < 1e-12);
        (worst, ga.accepted)
    }

    #[test]
    fn error_is_proportional_to_the_tolerance_over_four_decades() {
        let tols = [1e-5, 1e-6, 1e-7, 1e-8, 1e-9];
        let runs: Vec<(f64, u64)> = tols.iter().map(|&t| run(t)).collect();
        for (k, (tol, (err, steps))) in tols.iter().zip(&runs).enumerate() {
            // The tolerance is per VELOCITY_ERROR_TIME = 1 ms of run: over these 2 s the
            // global error is at most a few thousand times it ...
            assert!(err / tol < 1e4 && err / tol > 0.1, "{tol:e}: {err:e}");
            // ... and falls with it by a decade per decade (within a factor of 3), while
            // the steps grow by 10^(1/2) per decade, as a second-order method's should.
            if k > 0 {
                let (e0, s0) = runs[k - 1];
                let ratio = e0 / err;
                assert!(
                    (10.0 / 3.0..30.0).contains(&ratio),
                    "{tol:e}: ratio {ratio}"
                );
                let growth = *steps as f64 / s0 as f64;
                assert!((2.5..4.0).contains(&growth), "{tol:e}: steps x{growth}");
            }
        }
    }

    #[test]
    fn the_step_ends_satisfy_the_equation_of_motion() {
        // Arnold-Bruls form: the state's acceleration is f at the step end (to the Newton
        // tolerance, 1e-11 m here, over h^2).
        let sys = osc();
        let mut ga = AdaptiveAlpha::new(&settings(1e-10)).unwrap();
        let mut st = State::new(&sys, 0.0, vec![1.0, 1.0], vec![0.0, 0.0]).unwrap();
        let mut f = [0.0; 2];
        for _ in 0..50 {
            ga.advance(&sys, &mut st, 2.0).unwrap();
            sys.eval(st.t, &st.q, &st.v, &mut f, &mut [0.0; 3]).unwrap();
            for ((a, f), w) in st.a.iter().zip(&f).zip(&sys.w) {
                assert!((a - f).abs() < 1e-6 * w * w, "{a} {f}");
            }
        }
    }

    #[test]
    fn bad_settings_are_parameter_errors() {
        for (atol, rtol, h_min) in [
            (0.0, 1e-6, 1e-12),
            (f64::NAN, 1e-6, 1e-12),
            (-1e-9, 1e-6, 1e-12),
            (1e-9, f64::INFINITY, 1e-12),
            (1e-9, -1.0, 1e-12),
            (1e-9, 1e-6, 0.0),
            (1e-9, 1e-6, 3.0),
        ] {
            let mut s = settings(atol);
            s.rtol = rtol;
            s.h_min = h_min;
            let e = AdaptiveAlpha::new(&s).unwrap_err();
            assert!(matches!(e, RvdynError::Parameter(_)), "{e}");
        }
    }

    #[test]
    fn a_step_budget_and_a_step_collapse_stop_the_run_with_the_time() {
        let sys = osc();
        let mut s = settings(1e-9);
        s.max_steps = 20;
        let mut ga = AdaptiveAlpha::new(&s).unwrap();
        let mut st = State::new(&sys, 0.0, vec![1.0, 1.0], vec![0.0, 0.0]).unwrap();
        let e = loop {
            if let Err(e) = ga.advance(&sys, &mut st, 2.0) {
                break e;
            }
        };
        assert!(e.to_string().contains("max_steps = 20"), "{e}");
        assert_eq!(ga.accepted, 20);
        // Forces that fail from t = 0.5 s on: the step shrinks to h_min at t = 0.5 s.
        let sys = Oscillator {
            fail_after: 0.5,
            ..osc()
        };
        let mut ga = AdaptiveAlpha::new(&settings(1e-9)).unwrap();
        let mut st = State::new(&sys, 0.0, vec![1.0, 1.0], vec![0.0, 0.0]).unwrap();
        let e = loop {
            if let Err(e) = ga.advance(&sys, &mut st, 2.0) {
                break e;
            }
        };
        let m = e.to_string();
        assert!(matches!(e, RvdynError::Simulation(_)), "{m}");
        assert!(
            m.contains("force beyond its bound") && m.contains("minimum"),
            "{m}"
        );
        assert!((st.t - 0.5).abs() < 1e-9, "stopped at {}", st.t);
    }

    #[test]
    fn registered_by_name() {
        let m = Method::parse("adaptive-alpha").unwrap();
        assert_eq!(m.name(), "generalized-alpha-adaptive");
        assert!(m.0.adaptive);
    }

    /// `x'' = 0` before `t0`, `x'' = 1` m/s^2 after: a force that jumps in time.
    struct Kick {
        t0: f64,
    }

    impl MechanicalSystem for Kick {
        fn dof(&self) -> usize {
            1
        }
        fn eval(
            &self,
            t: f64,
            _: &[f64],
            _: &[f64],
            a: &mut [f64],
            _: &mut [f64; 3],
        ) -> Result<()> {
            a[0] = if t >= self.t0 { 1.0 } else { 0.0 };
            Ok(())
        }
        fn length_scale(&self) -> &[f64] {
            &[1.0]
        }
    }

    /// A jump of the force in time leaves the error per unit step of a step across it near a
    /// constant however short the step: without the error-per-step acceptance the step falls
    /// below h_min (a step collapse). With it the run finishes, the step across the jump is
    /// counted as non-smooth, and the result is the exact `x = (t - t0)^2 / 2` to 1e-4 m
    /// (measured 1.1e-5 m at atol = 1e-9 m: where the jump falls within the step accepted
    /// across it is invisible to the estimate, which sees the end accelerations only, so that
    /// step leaves a velocity error of the order of its length; the smooth parts follow the
    /// tolerance test above).
    #[test]
    fn a_force_that_jumps_in_time_does_not_collapse_the_step() {
        let sys = Kick {
            t0: 0.3141592653589793,
        };
        let mut ga = AdaptiveAlpha::new(&settings(1e-9)).unwrap();
        let mut st = State::new(&sys, 0.0, vec![0.0], vec![0.0]).unwrap();
        while st.t < 1.0 {
            ga.advance(&sys, &mut st, 1.0).unwrap();
        }
        let exact = 0.5 * (1.0 - sys.t0) * (1.0 - sys.t0);
        assert!((st.q[0] - exact).abs() < 1e-4, "{} vs {exact}", st.q[0]);
        assert!(ga.nonsmooth >= 1, "{ga:?}");
    }

    /// A mass falling at 1 m/s onto a stop with an IMPACT-like law (`k x^1.5` with a damping
    /// ramp over `RAMP`), gravity-free, starting 1 mm away: the first touch.
    struct Drop {
        /// Whether it reports first touches (the models' hook); false = the default trait.
        report: bool,
        last: std::cell::Cell<f64>,
        marked: std::cell::Cell<f64>,
    }

    const RAMP: f64 = 1e-5;

    impl MechanicalSystem for Drop {
        fn dof(&self) -> usize {
            1
        }
        fn eval(
            &self,
            _: f64,
            q: &[f64],
            v: &[f64],
            a: &mut [f64],
            _: &mut [f64; 3],
        ) -> Result<()> {
            let pen = q[0] - 1e-3;
            self.last.set(pen);
            a[0] = if pen > 0.0 {
                let c = 2e2 * (pen / RAMP).min(1.0);
                -1e9 * pen * pen.sqrt() - c * v[0]
            } else {
                0.0
            };
            Ok(())
        }
        fn length_scale(&self) -> &[f64] {
            &[1.0]
        }
        fn mark_open_contacts(&self) {
            self.marked.set(self.last.get());
        }
        fn deepest_first_touch(&self) -> Option<(f64, String)> {
            let (m, l) = (self.marked.get(), self.last.get());
            (self.report && m <= 0.0 && l > 0.0).then(|| (l / RAMP, "the stop".to_string()))
        }
    }

    /// At a loose tolerance the step that first touches may close deeper than the law's
    /// damping ramp (the ramp is then jumped); the first-touch check rejects such a step and
    /// retries shorter: with it, no accepted step closes deeper than the ramp (within 1 %, the
    /// depth at the last Newton evaluation against the accepted state), without it one does.
    #[test]
    fn a_contact_never_closes_deeper_than_its_ramp_in_one_step() {
        let deepest_new_closure = |report: bool| {
            let sys = Drop {
                report,
                last: std::cell::Cell::new(-1e-3),
                marked: std::cell::Cell::new(-1e-3),
            };
            let mut ga = AdaptiveAlpha::new(&settings(1e-4)).unwrap();
            let mut st = State::new(&sys, 0.0, vec![0.0], vec![1.0]).unwrap();
            let mut worst: f64 = 0.0;
            while st.t < 3e-3 {
                let before = st.q[0] - 1e-3;
                ga.advance(&sys, &mut st, 3e-3).unwrap();
                let after = st.q[0] - 1e-3;
                if before <= 0.0 && after > 0.0 {
                    worst = worst.max(after);
                }
            }
            (worst, ga.too_deep)
        };
        let (with, rejected) = deepest_new_closure(true);
        let (without, _) = deepest_new_closure(false);
        assert!(
            without > RAMP,
            "the loose run must jump the ramp: {without:e}"
        );
        assert!(with <= 1.01 * RAMP, "{with:e} m closed in one step");
        assert!(rejected >= 1);
    }
}
