//! Experiment: accuracy of generalized-alpha at large steps, Chung-Hulbert form against the
//! Arnold-Bruls form, on the rigid-joint paper scenes.
//!
//! `cargo run --release --example ga_experiment -- [rated|paper] [discs] [t_end]`
//!
//! Both forms use the same parameters from `rho_inf` (Chung & Hulbert 1993):
//! `am = (2 rho - 1)/(rho + 1)`, `af = rho/(rho + 1)`, `gamma = 1/2 - am + af`,
//! `beta = (1 - am + af)^2 / 4`.
//!
//! - Chung-Hulbert (CH; J. Appl. Mech. 60, 1993): unknown `a1`, equation
//!   `(1 - am) a1 + am a0 = f(t + (1 - af) h, (1 - af) q1 + af q0, (1 - af) v1 + af v0)`,
//!   Newmark updates from `a0, a1`.
//! - Arnold-Bruls (AB; Multibody Syst. Dyn. 18, 2007, eqs. 5-6): the equation of motion at the
//!   step end, `a1 = f(t + h, q1, v1)`, and a pseudo-acceleration `p` in the Newmark updates,
//!   `(1 - am) p1 + am p0 = (1 - af) a1 + af a0`, `p0 = a0` at the start.
//!
//! Newton here is exact to round-off (fresh finite-difference Jacobian every step, iterated to
//! 1e-14 m), so that only the form differs. rvdyn's own stepper (Arnold-Bruls since this
//! experiment; Jacobian reuse, Newton tolerance `atol`) runs alongside. Error: largest pin-force difference to a dopri5 reference
//! (rtol 1e-11, atol 1e-13 m) over the second half of the run, sampled every 1 ms (a step end
//! for every dt used, so no interpolation is involved), over the peak pin force.
use nalgebra::{DMatrix, DVector};
use rvdyn::dynamics::model::ReducerModel;
use rvdyn::dynamics::model::rigid_system::RigidSystem;
use rvdyn::dynamics::run::sink::ContactSink;
use rvdyn::dynamics::{RigidModel, Scene};
use rvdyn::solve::dopri5::Dopri5;
use rvdyn::solve::generalized_alpha::GeneralizedAlpha;
use rvdyn::solve::{MechanicalSystem, State};

struct PinSink {
    pins: usize,
    f: Vec<f64>,
}

impl ContactSink for PinSink {
    fn checks_bounds(&self) -> bool {
        false
    }
    fn pin(&mut self, k: usize, j: usize, force: f64, _: f64, _: f64, _: [f64; 2], _: [f64; 2]) {
        self.f[k * self.pins + j] = force;
    }
}

fn pin_forces(sys: &RigidSystem, st: &State) -> Vec<f64> {
    let l = sys.layout();
    let mut sink = PinSink {
        pins: l.pins,
        f: vec![0.0; l.discs * l.pins],
    };
    sys.observe(st.t, &st.q, &st.v, &mut sink).unwrap();
    sink.f
}

#[derive(Clone, Copy, PartialEq)]
enum Form {
    ChungHulbert,
    ArnoldBruls,
}

struct Ga {
    form: Form,
    am: f64,
    af: f64,
    b: f64,
    g: f64,
    /// Pseudo-acceleration (AB only).
    p: Vec<f64>,
    evaluations: u64,
}

impl Ga {
    fn new(form: Form, rho: f64, a0: &[f64]) -> Self {
        let am = (2.0 * rho - 1.0) / (rho + 1.0);
        let af = rho / (rho + 1.0);
        Self {
            form,
            am,
            af,
            b: 0.25 * (1.0 - am + af).powi(2),
            g: 0.5 - am + af,
            p: a0.to_vec(),
            evaluations: 0,
        }
    }

    /// A step, split in halves while an iterate leaves the physical bounds (as rvdyn does).
    fn step(&mut self, sys: &RigidSystem, st: &mut State, h: f64) {
        self.advance(sys, st, h, 0);
    }

    fn advance(&mut self, sys: &RigidSystem, st: &mut State, h: f64, depth: u32) {
        let (keep, p) = (st.clone(), self.p.clone());
        if self.try_step(sys, st, h).is_err() {
            assert!(depth < 12, "step collapsed at t = {}", keep.t);
            *st = keep;
            self.p = p;
            self.advance(sys, st, 0.5 * h, depth + 1);
            self.advance(sys, st, 0.5 * h, depth + 1);
        }
    }

    fn try_step(&mut self, sys: &RigidSystem, st: &mut State, h: f64) -> rvdyn::Result<()> {
        let n = st.q.len();
        let (am, af, b, g) = (self.am, self.af, self.b, self.g);
        let scale = sys.length_scale().to_vec();
        let mut pw = [0.0; 3];
        // Jacobian of f at the step start.
        let mut f0 = vec![0.0; n];
        let mut f1 = vec![0.0; n];
        sys.eval(st.t, &st.q, &st.v, &mut f0, &mut pw)?;
        let (mut kq, mut kv) = (DMatrix::zeros(n, n), DMatrix::zeros(n, n));
        for k in 0..n {
            let mut q = st.q.clone();
            let dq = 1e-9 / scale[k];
            q[k] += dq;
            sys.eval(st.t, &q, &st.v, &mut f1, &mut pw)?;
            for i in 0..n {
                kq[(i, k)] = (f1[i] - f0[i]) / dq;
            }
            let mut v = st.v.clone();
            let dv = 1e-6 / scale[k];
            v[k] += dv;
            sys.eval(st.t, &st.q, &v, &mut f1, &mut pw)?;
            for i in 0..n {
                kv[(i, k)] = (f1[i] - f0[i]) / dv;
            }
        }
        self.evaluations += 1 + 2 * n as u64;
        // Increments of (q1, v1) per unit increment of the unknown a1.
        let (dq_da, dv_da, lead, t_eval, w) = match self.form {
            Form::ChungHulbert => (b * h * h, g * h, 1.0 - am, st.t + (1.0 - af) * h, 1.0 - af),
            Form::ArnoldBruls => {
                let s = (1.0 - af) / (1.0 - am);
                (b * h * h * s, g * h * s, 1.0, st.t + h, 1.0)
            }
        };
        let jac = DMatrix::identity(n, n) * lead - (kq * (w * dq_da) + kv * (w * dv_da));
        let lu = jac.lu();
        let a0 = st.a.clone();
        let p0 = self.p.clone();
        let mut a1 = a0.clone();
        let (mut q1, mut v1, mut p1) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let mut fe = vec![0.0; n];
        for it in 0..50 {
            for i in 0..n {
                match self.form {
                    Form::ChungHulbert => {
                        q1[i] = st.q[i] + h * st.v[i] + h * h * ((0.5 - b) * a0[i] + b * a1[i]);
                        v1[i] = st.v[i] + h * ((1.0 - g) * a0[i] + g * a1[i]);
                    }
                    Form::ArnoldBruls => {
                        p1[i] = ((1.0 - af) * a1[i] + af * a0[i] - am * p0[i]) / (1.0 - am);
                        q1[i] = st.q[i] + h * st.v[i] + h * h * ((0.5 - b) * p0[i] + b * p1[i]);
                        v1[i] = st.v[i] + h * ((1.0 - g) * p0[i] + g * p1[i]);
                    }
                }
            }
            let r = match self.form {
                Form::ChungHulbert => {
                    let qf: Vec<f64> = (0..n).map(|i| (1.0 - af) * q1[i] + af * st.q[i]).collect();
                    let vf: Vec<f64> = (0..n).map(|i| (1.0 - af) * v1[i] + af * st.v[i]).collect();
                    sys.eval(t_eval, &qf, &vf, &mut fe, &mut pw)?;
                    DVector::from_fn(n, |i, _| (1.0 - am) * a1[i] + am * a0[i] - fe[i])
                }
                Form::ArnoldBruls => {
                    sys.eval(t_eval, &q1, &v1, &mut fe, &mut pw)?;
                    DVector::from_fn(n, |i, _| a1[i] - fe[i])
                }
            };
            self.evaluations += 1;
            let d = lu.solve(&r).unwrap();
            let mut size: f64 = 0.0;
            for i in 0..n {
                a1[i] -= d[i];
                size = size.max((dq_da * d[i] * scale[i]).abs());
            }
            if size < 1e-14 || it == 49 {
                break;
            }
        }
        for i in 0..n {
            match self.form {
                Form::ChungHulbert => {
                    q1[i] = st.q[i] + h * st.v[i] + h * h * ((0.5 - b) * a0[i] + b * a1[i]);
                    v1[i] = st.v[i] + h * ((1.0 - g) * a0[i] + g * a1[i]);
                }
                Form::ArnoldBruls => {
                    p1[i] = ((1.0 - af) * a1[i] + af * a0[i] - am * p0[i]) / (1.0 - am);
                    q1[i] = st.q[i] + h * st.v[i] + h * h * ((0.5 - b) * p0[i] + b * p1[i]);
                    v1[i] = st.v[i] + h * ((1.0 - g) * p0[i] + g * p1[i]);
                }
            }
        }
        st.t += h;
        st.q = q1;
        st.v = v1;
        st.a = a1;
        self.p = p1;
        Ok(())
    }
}

/// Pin forces at the samples `k * interval`, k = 0..=t_end/interval.
fn run(
    sys: &RigidSystem,
    t_end: f64,
    interval: f64,
    mut step: impl FnMut(&mut State, f64),
) -> Vec<Vec<f64>> {
    let (q0, v0) = sys.initial_state();
    let mut st = State::new(sys, 0.0, q0, v0).unwrap();
    let samples = (t_end / interval).round() as usize;
    let mut out = vec![pin_forces(sys, &st)];
    for k in 1..=samples {
        let ts = k as f64 * interval;
        while st.t < ts - 1e-12 {
            step(&mut st, ts);
        }
        assert!((st.t - ts).abs() < 1e-9, "{} {}", st.t, ts);
        st.t = ts;
        out.push(pin_forces(sys, &st));
    }
    out
}

/// Pin forces at the samples `k * interval` interpolated (cubic Hermite, as rvdyn's driver)
/// between the steps of size `dt`.
/// Quintic Hermite interpolation of `q` from `(q, v, a)` at both ends, `v` its derivative.
fn quintic(a: &State, b: &State, t: f64) -> State {
    let h = b.t - a.t;
    let s = (t - a.t) / h;
    let (s2, s3, s4, s5) = (s * s, s * s * s, s.powi(4), s.powi(5));
    let w = [
        1.0 - 10.0 * s3 + 15.0 * s4 - 6.0 * s5,
        s - 6.0 * s3 + 8.0 * s4 - 3.0 * s5,
        0.5 * s2 - 1.5 * s3 + 1.5 * s4 - 0.5 * s5,
        0.5 * s3 - s4 + 0.5 * s5,
        -4.0 * s3 + 7.0 * s4 - 3.0 * s5,
        10.0 * s3 - 15.0 * s4 + 6.0 * s5,
    ];
    let d = [
        -30.0 * s2 + 60.0 * s3 - 30.0 * s4,
        1.0 - 18.0 * s2 + 32.0 * s3 - 15.0 * s4,
        s - 4.5 * s2 + 6.0 * s3 - 2.5 * s4,
        1.5 * s2 - 4.0 * s3 + 2.5 * s4,
        -12.0 * s2 + 28.0 * s3 - 15.0 * s4,
        30.0 * s2 - 60.0 * s3 + 30.0 * s4,
    ];
    let n = a.q.len();
    let mut out = a.interpolate(b, t);
    for i in 0..n {
        let y = [
            a.q[i],
            h * a.v[i],
            h * h * a.a[i],
            h * h * b.a[i],
            h * b.v[i],
            b.q[i],
        ];
        out.q[i] = (0..6).map(|k| w[k] * y[k]).sum();
        out.v[i] = (0..6).map(|k| d[k] * y[k]).sum::<f64>() / h;
    }
    out
}

fn run_interpolated(
    sys: &RigidSystem,
    t_end: f64,
    interval: f64,
    dt: f64,
    quintic_output: bool,
    mut step: impl FnMut(&mut State, f64),
) -> Vec<Vec<f64>> {
    let (q0, v0) = sys.initial_state();
    let mut st = State::new(sys, 0.0, q0, v0).unwrap();
    let samples = (t_end / interval).round() as usize;
    let mut out = vec![pin_forces(sys, &st)];
    let mut k = 1;
    while k <= samples {
        let prev = st.clone();
        step(&mut st, dt);
        while k <= samples && k as f64 * interval <= st.t + 1e-12 {
            let ts = k as f64 * interval;
            let s = if quintic_output {
                quintic(&prev, &st, ts)
            } else {
                prev.interpolate(&st, ts)
            };
            out.push(pin_forces(sys, &s));
            k += 1;
        }
    }
    out
}

fn error(reference: &[Vec<f64>], run: &[Vec<f64>]) -> f64 {
    let start = reference.len() / 2;
    let peak = reference[start..]
        .iter()
        .flatten()
        .fold(0.0f64, |m, &x| m.max(x.abs()));
    let mut worst: f64 = 0.0;
    for (a, b) in reference[start..].iter().zip(&run[start..]) {
        for (x, y) in a.iter().zip(b) {
            worst = worst.max((x - y).abs());
        }
    }
    worst / peak
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let load = args.get(1).map_or("rated", |s| s.as_str());
    let discs: usize = args.get(2).map_or(2, |s| s.parse().unwrap());
    let t_end: f64 = args.get(3).map_or(0.2, |s| s.parse().unwrap());
    let mut scene = Scene::paper(load).unwrap();
    scene.discs.truncate(discs);
    let model = RigidModel::new(&scene).unwrap();
    let sys = RigidSystem::new(&model);
    let interval = 1e-3;
    let t0 = std::time::Instant::now();
    let mut dp = Dopri5::new(1e-11, 1e-13, 1e-7, 1e-3);
    let mut dp_fine = Dopri5::new(1e-11, 1e-13, 1e-7, 1e-3);
    let reference = run(&sys, t_end, interval, |st, ts| {
        dp.step(&sys, st, ts).unwrap()
    });
    eprintln!(
        "reference: dopri5 {} steps in {:.1} s",
        dp.accepted,
        t0.elapsed().as_secs_f64()
    );
    let fine = run(&sys, t_end, 1e-4, |st, ts| {
        dp_fine.step(&sys, st, ts).unwrap()
    });
    // Convergence of the reference: dopri5 ten times looser.
    let mut dp2 = Dopri5::new(1e-10, 1e-12, 1e-7, 1e-3);
    let check = run(&sys, t_end, interval, |st, ts| {
        dp2.step(&sys, st, ts).unwrap()
    });
    println!(
        "scene {load}, {discs} disc(s), {t_end} s from rest; reference error estimate {:.1e}",
        error(&reference, &check)
    );
    println!(
        "| dt [s] | CH (exact Newton) | AB (exact Newton) | rvdyn stepper (atol 1e-9) | CH / AB | evals CH, AB |"
    );
    println!("|---|---|---|---|---|---|");
    for dt in [1e-4, 2e-4, 5e-4, 1e-3] {
        let mut errs = Vec::new();
        let mut evals = Vec::new();
        for form in [Form::ChungHulbert, Form::ArnoldBruls] {
            let (q0, v0) = sys.initial_state();
            let a0 = State::new(&sys, 0.0, q0, v0).unwrap().a;
            let mut ga = Ga::new(form, 0.8, &a0);
            let f = run(&sys, t_end, interval, |st, _| ga.step(&sys, st, dt));
            errs.push(error(&reference, &f));
            evals.push(ga.evaluations);
        }
        let mut ours = GeneralizedAlpha::new(0.8, 1e-9, false).unwrap();
        let f = run(&sys, t_end, interval, |st, _| {
            ours.step(&sys, st, dt).unwrap()
        });
        errs.push(error(&reference, &f));
        println!(
            "| {dt:.0e} | {:.2e} | {:.2e} | {:.2e} | {:.1} | {}, {} |",
            errs[0],
            errs[1],
            errs[2],
            errs[0] / errs[1],
            evals[0],
            evals[1]
        );
    }
    println!();
    println!("Samples every 0.1 ms, interpolated within the steps (cubic Hermite of q, v, a):");
    println!("| dt [s] | CH | AB | CH / AB | AB, quintic Hermite of q from (q, v, a) |");
    println!("|---|---|---|---|---|");
    for dt in [2e-4, 5e-4, 1e-3] {
        let mut errs = Vec::new();
        for form in [Form::ChungHulbert, Form::ArnoldBruls] {
            let (q0, v0) = sys.initial_state();
            let a0 = State::new(&sys, 0.0, q0, v0).unwrap().a;
            let mut ga = Ga::new(form, 0.8, &a0);
            let f = run_interpolated(&sys, t_end, 1e-4, dt, false, |st, h| ga.step(&sys, st, h));
            errs.push(error(&fine, &f));
        }
        let (q0, v0) = sys.initial_state();
        let a0 = State::new(&sys, 0.0, q0, v0).unwrap().a;
        let mut ga = Ga::new(Form::ArnoldBruls, 0.8, &a0);
        let f = run_interpolated(&sys, t_end, 1e-4, dt, true, |st, h| ga.step(&sys, st, h));
        errs.push(error(&fine, &f));
        println!(
            "| {dt:.0e} | {:.2e} | {:.2e} | {:.1} | {:.2e} |",
            errs[0],
            errs[1],
            errs[0] / errs[1],
            errs[2]
        );
    }
}
