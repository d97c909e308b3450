//! Order of convergence of each integrator on a damped linear oscillator with a known exact
//! solution (smooth, so every method must show its nominal order).

use crate::error::Result;
use crate::solve::dopri5::Dopri5;
use crate::solve::generalized_alpha::GeneralizedAlpha;
use crate::solve::rk4::Rk4;
use crate::solve::{MechanicalSystem, State};

/// `x'' = -w^2 x - 2 z w x'` in two uncoupled coordinates with different frequencies.
struct Oscillator {
    w: [f64; 2],
    z: f64,
    scale: [f64; 2],
}

impl MechanicalSystem for Oscillator {
    fn dof(&self) -> usize {
        2
    }
    fn eval(&self, _t: f64, q: &[f64], v: &[f64], a: &mut [f64], p: &mut [f64; 3]) -> Result<()> {
        for i in 0..2 {
            a[i] = -self.w[i] * self.w[i] * q[i] - 2.0 * self.z * self.w[i] * v[i];
        }
        p[2] = (0..2).map(|i| 2.0 * self.z * self.w[i] * v[i] * v[i]).sum();
        Ok(())
    }
    fn length_scale(&self) -> &[f64] {
        &self.scale
    }
}

fn exact(w: f64, z: f64, t: f64) -> f64 {
    // x(0) = 1, x'(0) = 0.
    let wd = w * (1.0 - z * z).sqrt();
    (-z * w * t).exp() * ((wd * t).cos() + z * w / wd * (wd * t).sin())
}

fn osc() -> Oscillator {
    Oscillator {
        w: [3.0, 7.0],
        z: 0.05,
        scale: [1.0, 1.0],
    }
}

fn error_after(method: &str, h: f64) -> f64 {
    let sys = osc();
    let t_end = 2.0;
    let mut st = State::new(&sys, 0.0, vec![1.0, 1.0], vec![0.0, 0.0]).unwrap();
    let n = (t_end / h).round() as usize;
    let mut rk4 = Rk4::default();
    let mut ga = GeneralizedAlpha::new(0.8, 1e-14, false).unwrap();
    // Fixed step Dormand-Prince: tolerances so loose that no step is rejected.
    let mut dp = Dopri5::new(1e10, 1e10, h, h);
    // Largest error over the whole trajectory (the error at one instant can pass near zero).
    let mut worst: f64 = 0.0;
    for _ in 0..n {
        match method {
            "rk4" => rk4.step(&sys, &mut st, h).unwrap(),
            "ga" => ga.step(&sys, &mut st, h).unwrap(),
            _ => dp.step(&sys, &mut st, t_end).unwrap(),
        }
        for i in 0..2 {
            worst = worst.max((st.q[i] - exact(sys.w[i], sys.z, st.t)).abs());
        }
    }
    worst
}

fn observed_order(method: &str, h: f64) -> f64 {
    (error_after(method, h) / error_after(method, h / 2.0)).log2()
}

#[test]
fn rk4_is_fourth_order() {
    let p = observed_order("rk4", 0.01);
    assert!((p - 4.0).abs() < 0.15, "observed order {p}");
}

#[test]
fn dormand_prince_is_fifth_order() {
    let p = observed_order("dopri", 0.1);
    assert!((p - 5.0).abs() < 0.3, "observed order {p}");
}

#[test]
fn generalized_alpha_is_second_order() {
    let p = observed_order("ga", 0.005);
    assert!((p - 2.0).abs() < 0.1, "observed order {p}");
}

#[test]
fn adaptive_error_follows_the_tolerance() {
    let sys = osc();
    let run = |atol: f64| {
        let mut st = State::new(&sys, 0.0, vec![1.0, 1.0], vec![0.0, 0.0]).unwrap();
        let mut dp = Dopri5::new(0.0, atol, 1e-3, 1.0);
        while st.t < 2.0 {
            dp.step(&sys, &mut st, 2.0).unwrap();
        }
        (0..2)
            .map(|i| (st.q[i] - exact(sys.w[i], sys.z, st.t)).abs())
            .fold(0.0, f64::max)
    };
    let (e1, e2) = (run(1e-6), run(1e-9));
    // Global error within two decades of the tolerance and shrinking with it.
    assert!(e1 < 1e-4 && e2 < 1e-7 && e2 < e1 / 50.0, "{e1:e} {e2:e}");
}

#[test]
fn energy_flows_integrate_the_dissipation() {
    // The dissipated work must equal the loss of mechanical energy.
    let sys = osc();
    let mut st = State::new(&sys, 0.0, vec![1.0, 1.0], vec![0.0, 0.0]).unwrap();
    let mut rk4 = Rk4::default();
    for _ in 0..2000 {
        rk4.step(&sys, &mut st, 1e-3).unwrap();
    }
    let energy = |q: &[f64], v: &[f64]| -> f64 {
        (0..2)
            .map(|i| 0.5 * v[i] * v[i] + 0.5 * sys.w[i] * sys.w[i] * q[i] * q[i])
            .sum()
    };
    let e0 = energy(&[1.0, 1.0], &[0.0, 0.0]);
    let lost = e0 - energy(&st.q, &st.v);
    assert!(
        (lost - st.work[2]).abs() < 1e-9 * e0,
        "{lost} {}",
        st.work[2]
    );
}

// ---------------------------------------------------------------------------------------------
// A toy integrator plugged in through the registry: one file (this block) and one registration
// line (the `REGISTRY` slice below; the crate's own list is `solve::INTEGRATORS`).

use crate::solve::integrator::{FixedClock, Integrator, IntegratorEntry, Method, Settings, Stats};

/// Semi-implicit (symplectic) Euler: v1 = v0 + h a(q0, v0), q1 = q0 + h v1. Order 1.
struct SymplecticEuler {
    clock: FixedClock,
    evaluations: u64,
}

impl Integrator for SymplecticEuler {
    fn advance(&mut self, sys: &dyn MechanicalSystem, st: &mut State, _t_end: f64) -> Result<()> {
        let h = self.clock.h;
        for i in 0..st.q.len() {
            st.v[i] += h * st.a[i];
            st.q[i] += h * st.v[i];
        }
        for j in 0..3 {
            st.work[j] += h * st.power[j];
        }
        st.t += h;
        sys.eval(st.t, &st.q, &st.v, &mut st.a, &mut st.power)?;
        self.evaluations += 1;
        self.clock.tick(st);
        Ok(())
    }
    fn stats(&self) -> Stats {
        Stats {
            counts: vec![
                ("steps", self.clock.taken),
                ("evaluations", self.evaluations),
            ],
            dt: Some(self.clock.h),
        }
    }
}

static TOY: IntegratorEntry = IntegratorEntry {
    name: "symplectic-euler",
    aliases: &["toy"],
    default_dt: 1e-7,
    adaptive: false,
    summary: "semi-implicit Euler, explicit, order 1 (a test of the registry)",
    build: |s: &Settings| {
        Ok(Box::new(SymplecticEuler {
            clock: FixedClock::new(s.t_end, s.dt),
            evaluations: 0,
        }))
    },
};

static REGISTRY: &[&IntegratorEntry] = &[
    &crate::solve::generalized_alpha::ENTRY,
    &crate::solve::dopri5::ENTRY,
    &crate::solve::rk4::ENTRY,
    &TOY, // the registration line
];

#[test]
fn registry_names_and_aliases() {
    assert_eq!(Method::parse("RK4").unwrap(), Method::Rk4);
    assert_eq!(
        Method::parse("gen_alpha").unwrap(),
        Method::GeneralizedAlpha
    );
    assert_eq!(Method::parse("rk45").unwrap(), Method::Dopri5);
    let err = Method::parse("toy").unwrap_err().to_string();
    assert!(err.contains("\"generalized-alpha\""), "{err}");
    assert_eq!(
        Method::parse_in(REGISTRY, "toy").unwrap().name(),
        "symplectic-euler"
    );
}

#[test]
fn toy_integrator_plugs_in() {
    use crate::dynamics::{RunControl, Scene, SimOptions, simulate};
    // The rated default scene for 0.2 ms: the toy run must reach the end time with its step
    // count, and agree with RK4 at the same step on the carrier angle (a first-order method
    // against a fourth-order one at 1e-7 s: within 1 % of the angle turned).
    let scene = Scene::paper("rated").unwrap();
    let mut opt = SimOptions::new(2e-4, Method::parse_in(REGISTRY, "toy").unwrap());
    let toy = simulate(&scene, &opt, &RunControl::default()).unwrap();
    assert_eq!(
        toy.stats.counts[0],
        ("steps", FixedClock::new(2e-4, 1e-7).n)
    );
    assert_eq!(toy.series["t"].data.last(), Some(&2e-4));
    opt.method = Method::Rk4;
    opt.dt = Some(1e-7);
    let ga = simulate(&scene, &opt, &RunControl::default()).unwrap();
    let last = |r: &crate::dynamics::Recording| *r.series["carrier_angle"].data.last().unwrap();
    assert_eq!(toy.samples, ga.samples);
    assert!(
        (last(&toy) - last(&ga)).abs() < 1e-2 * last(&ga).abs(),
        "{} {}",
        last(&toy),
        last(&ga)
    );
}

/// `x'' = -k x^1.5 (x > 0) - c x'`: a Hertz-like one-sided spring, stiff when pressed.
struct Hertzian {
    scale: [f64; 1],
}

impl MechanicalSystem for Hertzian {
    fn dof(&self) -> usize {
        1
    }
    fn eval(&self, _t: f64, q: &[f64], v: &[f64], a: &mut [f64], _p: &mut [f64; 3]) -> Result<()> {
        // Preloaded by a constant force 1e4 so the contact stays closed and the motion is smooth.
        let x = q[0].max(0.0);
        a[0] = 1e4 - 1e9 * x * x.sqrt() - 20.0 * v[0];
        Ok(())
    }
    fn length_scale(&self) -> &[f64] {
        &self.scale
    }
}

/// Newton stopped at a fraction of the local error estimate (Hairer & Wanner's kappa Tol)
/// saves iterations and changes the result by a minor part of the step's own error: the
/// difference to a fully converged Newton, accumulated over 200 steps of 1e-4 s (about 18
/// periods of the pressed contact, 0.57 rad of phase per step), stays below 1 % of the global
/// error against a converged small-step run (measured 2e-5, with 26 % fewer iterations).
#[test]
fn newton_stopped_at_the_local_error_keeps_the_accuracy() {
    let sys = Hertzian { scale: [1.0] };
    let run = |h: f64, kappa: f64, tol: f64| {
        let mut st = State::new(&sys, 0.0, vec![0.0], vec![0.0]).unwrap();
        let mut ga = GeneralizedAlpha::new(0.8, tol, false).unwrap();
        ga.newton_kappa = kappa;
        let n = (0.02 / h).round() as usize;
        let mut path = Vec::with_capacity(n);
        for _ in 0..n {
            ga.step(&sys, &mut st, h).unwrap();
            path.push(st.q[0]);
        }
        (path, ga.newton_iterations)
    };
    let h = 1e-4;
    let (reference, _) = run(h / 64.0, 0.0, 1e-16);
    let every = 64;
    let (strict, it_strict) = run(h, 0.0, 1e-12);
    let (loose, it_loose) = run(h, crate::solve::generalized_alpha::NEWTON_KAPPA, 1e-12);
    let worst = |p: &[f64]| {
        p.iter()
            .enumerate()
            .map(|(i, x)| (x - reference[(i + 1) * every - 1]).abs())
            .fold(0.0, f64::max)
    };
    let err = worst(&strict);
    let diff = strict
        .iter()
        .zip(&loose)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(err > 1e-9, "the step must have a visible error: {err:e}");
    assert!(
        diff < 0.2 * err,
        "loose Newton moved the result by {diff:e}, error {err:e}"
    );
    assert!(it_loose < it_strict, "{it_loose} >= {it_strict}");
}

/// A step ended provisionally after Newton's first increment and checked by an evaluation
/// at its end (`confirm` with its own evaluation) is the same iteration as a step that
/// iterates on: the same iterates, tests and Jacobians, so the same trajectory bit for bit,
/// including the steps whose iteration fails and is taken again (the pressed Hertzian
/// contact from rest at 5e-4 s steps, 0.3 of its period, where Newton with the reused
/// Jacobian often diverges and steps are split; `redone` counts the provisional steps taken
/// again, and the test fails if none is).
#[test]
fn a_provisional_step_checked_at_its_end_is_the_same_step() {
    let sys = Hertzian { scale: [1.0] };
    let run = |provisional: bool| {
        let mut st = State::new(&sys, 0.0, vec![0.0], vec![0.0]).unwrap();
        let mut ga = GeneralizedAlpha::new(0.8, 1e-12, false).unwrap();
        ga.provisional_ok = provisional;
        let mut path = Vec::new();
        let mut held = 0;
        for _ in 0..200 {
            ga.step(&sys, &mut st, 5e-4).unwrap();
            if ga.provisional() {
                held += 1;
                ga.confirm(&sys, &mut st, None).unwrap();
            }
            assert!(!ga.provisional());
            path.push((st.q[0], st.v[0], st.a[0]));
        }
        (path, held, ga.redone, ga.newton_iterations)
    };
    let (plain, held_plain, _, it_plain) = run(false);
    let (checked, held, redone, it_checked) = run(true);
    assert_eq!(held_plain, 0);
    assert!(held > 100, "only {held} provisional steps");
    assert!(redone > 0, "no provisional step failed its check");
    assert_eq!(plain, checked);
    assert!(it_checked >= it_plain);
}

/// The adaptive methods' next step lands on the end time without a sliver: a step over half
/// of what remains becomes half of it, one at or past the end becomes the rest, and `h_max`
/// caps the proposal.
#[test]
fn landing_step_leaves_no_sliver() {
    use crate::solve::integrator::landing_step;
    assert_eq!(landing_step(0.1, 1.0, 1.0), 0.1);
    assert_eq!(landing_step(0.6, 1.0, 1.0), 0.5);
    assert_eq!(landing_step(2.0, 5.0, 1.0), 1.0);
    assert_eq!(landing_step(0.3, 0.2, 1.0), 0.2);
    assert_eq!(landing_step(0.3, 0.2, 0.25), 0.125);
}

/// Bad tolerances of an adaptive method are `Parameter` errors naming the setting.
#[test]
fn adaptive_settings_are_checked() {
    use crate::error::RvdynError;
    use crate::solve::Settings;
    let ok = Settings {
        t_end: 1.0,
        dt: 1e-5,
        rtol: 1e-6,
        atol: 1e-9,
        rho_inf: 0.8,
        h_max: 1.0,
        h_min: 1e-13,
        max_steps: 10,
        track_work: false,
    };
    assert!(ok.check_adaptive().is_ok());
    for (bad, name) in [
        (Settings { atol: 0.0, ..ok }, "atol"),
        (
            Settings {
                atol: f64::NAN,
                ..ok
            },
            "atol",
        ),
        (Settings { rtol: -1.0, ..ok }, "rtol"),
        (Settings { h_min: 2.0, ..ok }, "h_min"),
    ] {
        match bad.check_adaptive() {
            Err(RvdynError::Parameter(m)) => assert!(m.contains(name), "{m}"),
            other => panic!("{name}: {other:?}"),
        }
    }
}

/// The fixed-step clock puts the time after step `k` at `k h` exactly (a running sum of `h`
/// drifts past the samples' 1e-12 s allowance within a long run, and each missed sample then
/// costs an evaluation of its own), and generalized-alpha's pseudo-acceleration follows the
/// time: the registered run (clock included) steps exactly as the bare stepper does, without
/// a restart at any step.
#[test]
fn fixed_clock_times_are_exact_multiples_and_generalized_alpha_does_not_restart() {
    let sys = osc();
    let settings = Settings {
        t_end: 3.0,
        dt: 1e-4,
        rtol: 1e-6,
        atol: 1e-12,
        rho_inf: 0.8,
        h_max: 1.0,
        h_min: 1e-13,
        max_steps: u64::MAX,
        track_work: false,
    };
    let clock = FixedClock::new(settings.t_end, settings.dt);
    let mut run = Method::GeneralizedAlpha.build(&settings).unwrap();
    let mut bare = GeneralizedAlpha::new(settings.rho_inf, settings.atol, false).unwrap();
    let start = State::new(&sys, 0.0, vec![1.0, 1.0], vec![0.0, 0.0]).unwrap();
    let (mut a, mut b) = (start.clone(), start);
    let mut summed = 0.0f64;
    let mut drift: f64 = 0.0;
    for k in 1..=clock.n {
        run.advance(&sys, &mut a, settings.t_end).unwrap();
        bare.step(&sys, &mut b, clock.h).unwrap();
        summed += clock.h;
        drift = drift.max((summed - k as f64 * clock.h).abs());
        let want = if k == clock.n {
            settings.t_end
        } else {
            k as f64 * clock.h
        };
        assert_eq!(a.t, want, "step {k}");
        // The oscillator does not depend on the time: with the same pseudo-acceleration the
        // two are the same to the last bit.
        assert_eq!((&a.q, &a.v), (&b.q, &b.v), "step {k}");
    }
    // The running sum this replaces would have missed samples at k h.
    assert!(drift > 1e-12, "{drift}");
}
