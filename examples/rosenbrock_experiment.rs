//! Experiment: an adaptive Rosenbrock-W method, ROS34PW2 (J. Rang and L. Angermann, New
//! Rosenbrock W-methods of order 3 for partial differential algebraic equations of index 1, BIT
//! Numerical Mathematics 45, 2005, 761-787), against dopri5 on the physical preset and against
//! generalized-alpha on the rigid paper scene (BENCHMARKS.md section 11). The question: does a
//! linearly implicit method of order 3, which steps over the 8.2 kHz bearing modes that hold
//! dopri5 at its stability limit, reach 1e-3 of the peak pin force with fewer force evaluations?
//!
//! `cargo run --release --example rosenbrock_experiment -- [physical|paper] [t_end]`
//!
//! Plugged into `simulate` through its own registry entry (the integrator interface); not
//! registered in `rvdyn::solve::INTEGRATORS`, because it loses to the registered methods on
//! every scene measured.
//!
//! A W-method keeps its order with *any* matrix in place of the Jacobian (Hairer & Wanner,
//! Solving ODEs II, 2nd ed., section IV.7, "W-methods"); only its stability needs the matrix
//! to hold the stiff directions. One finite-difference Jacobian therefore serves many steps
//! while contacts open and close, and no Newton iteration is needed: each stage is one force
//! evaluation and one linear solve.
//!
//! With `y = (q, v)`, `F(t, y) = (v, f(t, q, v))` and `W = [[0, I], [K, C]]`
//! (`K = df/dq`, `C = df/dv` by finite differences), stage `i` solves
//! `(I - h gamma W) k_i = h F(t + c_i h, y + sum_j a_ij k_j) + h W sum_j g_ij k_j` and
//! `y1 = y + sum_i b_i k_i`. The time enters as a coordinate whose row of `W` is zero, which a
//! W-method allows (no `dF/dt` term). The `2n` system is reduced to `n` unknowns:
//! `(I - h gamma C - (h gamma)^2 K) k_v = r_v + h gamma K r_q`, `k_q = r_q + h gamma k_v`.
//!
//! Error `e = sum_i (b_i - b^_i) k_i` in dopri5's norm (error per step); PI controller for an
//! estimate of order 2 (exponents 0.7/3, 0.4/3). The Jacobian is evaluated at the start, before
//! retrying a rejected step with a Jacobian from an earlier step, and after `JACOBIAN_AGE`
//! accepted steps. Each accepted step costs four force evaluations (stages 2-4 and the end
//! state), each Jacobian `1 + 2n`.

use nalgebra::{DMatrix, DVector};
use rvdyn::dynamics::run::recorder::Channel;
use rvdyn::dynamics::{RunControl, Scene, SimOptions, simulate};
use rvdyn::error::{Result, RvdynError};
use rvdyn::solve::dopri5::VELOCITY_ERROR_TIME;
use rvdyn::solve::integrator::{
    Integrator, IntegratorEntry, Method, Settings, Stats, landing_step,
};
use rvdyn::solve::jacobian;
use rvdyn::solve::system::{MechanicalSystem, State};

/// Registry entry of ROS34PW2.
static ENTRY: IntegratorEntry = IntegratorEntry {
    name: "rosenbrock",
    aliases: &["ros34pw2", "rosenbrock-w"],
    default_dt: 1e-5,
    adaptive: true,
    summary: "Rosenbrock-W ROS34PW2, linearly implicit, order 3, L-stable, adaptive step \
              (atol/rtol), a finite-difference Jacobian reused across steps",
    build: |s: &Settings| Ok(Box::new(Rosenbrock::new(s)?)),
};

/// The diagonal coefficient `gamma`.
const GAMMA: f64 = 4.358_665_215_084_59e-1;
/// Stage coefficients `a_ij` (j < i).
const A: [[f64; 4]; 4] = [
    [0.0; 4],
    [8.717_330_430_169_18e-1, 0.0, 0.0, 0.0],
    [
        8.445_706_001_536_942e-1,
        -1.129_906_423_648_418_5e-1,
        0.0,
        0.0,
    ],
    [0.0, 0.0, 1.0, 0.0],
];
/// Off-diagonal coefficients `g_ij` (j < i) of the Jacobian terms.
const G: [[f64; 4]; 4] = [
    [0.0; 4],
    [-8.717_330_430_169_18e-1, 0.0, 0.0, 0.0],
    [
        -9.033_805_701_304_408e-1,
        5.418_067_238_809_533e-2,
        0.0,
        0.0,
    ],
    [
        2.421_238_070_609_535e-1,
        -1.223_250_583_904_514_7,
        5.452_602_553_351_021e-1,
        0.0,
    ],
];
/// Weights of the third-order solution.
const B: [f64; 4] = [
    2.421_238_070_609_535e-1,
    -1.223_250_583_904_514_7,
    1.545_260_255_335_102,
    4.358_665_215_084_59e-1,
];
/// Weights of the embedded second-order solution.
const B_HAT: [f64; 4] = [
    3.781_090_314_581_937e-1,
    -9.604_229_221_242_318e-2,
    0.5,
    2.179_332_607_542_295e-1,
];

/// Accepted steps after which the Jacobian is evaluated again.
const JACOBIAN_AGE: u32 = 20;

/// ROS34PW2 bound to one run.
#[derive(Debug)]
struct Rosenbrock {
    /// Relative tolerance on velocities.
    rtol: f64,
    /// Displacement tolerance \[m\].
    atol: f64,
    /// Step of the next try \[s\].
    h: f64,
    h_min: f64,
    h_max: f64,
    track_work: bool,
    err_prev: f64,
    /// Accepted steps.
    accepted: u64,
    /// Rejected tries.
    rejected: u64,
    /// Jacobians evaluated.
    jacobians: u64,
    /// Force evaluations (stages, end states and Jacobians).
    evaluations: u64,
    /// `K = df/dq` and `C = df/dv` (empty before the first step).
    k: DMatrix<f64>,
    c: DMatrix<f64>,
    /// Accepted steps since the Jacobian was evaluated.
    age: u32,
    lu: Option<nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>>,
    lu_h: f64,
    kq: [Vec<f64>; 4],
    kv: [Vec<f64>; 4],
}

impl Rosenbrock {
    /// Build from the run settings: `dt` is the first step, `atol` \[m\] and `rtol` the
    /// tolerances.
    fn new(s: &Settings) -> Result<Self> {
        s.check_adaptive()?;
        Ok(Self {
            rtol: s.rtol,
            atol: s.atol,
            h: s.dt.clamp(s.h_min, s.h_max),
            h_min: s.h_min,
            h_max: s.h_max,
            track_work: s.track_work,
            err_prev: 1e-4,
            accepted: 0,
            rejected: 0,
            jacobians: 0,
            evaluations: 0,
            k: DMatrix::zeros(0, 0),
            c: DMatrix::zeros(0, 0),
            age: 0,
            lu: None,
            lu_h: 0.0,
            kq: Default::default(),
            kv: Default::default(),
        })
    }

    /// Evaluate `K` and `C` at `st` by finite differences.
    fn jacobian(&mut self, sys: &(impl MechanicalSystem + ?Sized), st: &State) -> Result<()> {
        let n = st.q.len();
        let mut k = DMatrix::zeros(n, n);
        let mut c = DMatrix::zeros(n, n);
        self.evaluations += jacobian::finite_difference(sys, st, |col| {
            for i in 0..n {
                k[(i, col.k)] = (col.f_dq[i] - col.f0[i]) / col.dq;
                c[(i, col.k)] = (col.f_dv[i] - col.f0[i]) / col.dv;
            }
        })?;
        self.k = k;
        self.c = c;
        self.age = 0;
        self.jacobians += 1;
        self.lu = None;
        Ok(())
    }

    /// Factorize `I - h gamma C - (h gamma)^2 K` unless it is the current one.
    fn factorize(&mut self, h: f64) -> Result<()> {
        if self.lu.is_some() && self.lu_h == h {
            return Ok(());
        }
        let n = self.k.nrows();
        let hg = h * GAMMA;
        let m = DMatrix::from_fn(n, n, |i, j| {
            let id = if i == j { 1.0 } else { 0.0 };
            id - hg * self.c[(i, j)] - hg * hg * self.k[(i, j)]
        });
        let lu = m.lu();
        if !lu.is_invertible() {
            return Err(RvdynError::Simulation(format!(
                "rosenbrock: the step matrix I - h gamma J is singular at h = {h:.3e} s"
            )));
        }
        self.lu = Some(lu);
        self.lu_h = h;
        Ok(())
    }

    /// The four stages of a step of `h` from `st`: `Ok(Some(err))` with the stage increments
    /// kept, `Ok(None)` when a stage's forces left their physical bounds (a step too long).
    #[allow(clippy::needless_range_loop)]
    fn stages(
        &mut self,
        sys: &(impl MechanicalSystem + ?Sized),
        st: &State,
        h: f64,
    ) -> Result<Option<f64>> {
        let n = st.q.len();
        self.factorize(h)?;
        let hg = h * GAMMA;
        let mut yq = vec![0.0; n];
        let mut yv = vec![0.0; n];
        let mut fv = vec![0.0; n];
        let mut p = [0.0; 3];
        let mut gq = DVector::zeros(n);
        let mut gv = DVector::zeros(n);
        for s in 0..4 {
            let c_s: f64 = A[s].iter().sum();
            for i in 0..n {
                let (mut dq, mut dv, mut eq, mut ev) = (0.0, 0.0, 0.0, 0.0);
                for j in 0..s {
                    dq += A[s][j] * self.kq[j][i];
                    dv += A[s][j] * self.kv[j][i];
                    eq += G[s][j] * self.kq[j][i];
                    ev += G[s][j] * self.kv[j][i];
                }
                yq[i] = st.q[i] + dq;
                yv[i] = st.v[i] + dv;
                gq[i] = eq;
                gv[i] = ev;
            }
            if s == 0 {
                fv.copy_from_slice(&st.a);
            } else {
                self.evaluations += 1;
                match sys.eval(st.t + c_s * h, &yq, &yv, &mut fv, &mut p) {
                    Ok(()) => {}
                    Err(RvdynError::Simulation(_)) => return Ok(None),
                    Err(e) => return Err(e),
                }
            }
            // r = h F(Y) + h W g: r_q = h (v_Y + g_v), r_v = h (f(Y) + K g_q + C g_v).
            let wv = &self.k * &gq + &self.c * &gv;
            let rq: Vec<f64> = (0..n).map(|i| h * (yv[i] + gv[i])).collect();
            let mut rhs = DVector::from_fn(n, |i, _| h * (fv[i] + wv[i]));
            let krq = &self.k * DVector::from_column_slice(&rq);
            for i in 0..n {
                rhs[i] += hg * krq[i];
            }
            let Some(lu) = self.lu.as_ref() else {
                return Err(RvdynError::Simulation(
                    "rosenbrock: no factorization".into(),
                ));
            };
            if !lu.solve_mut(&mut rhs) {
                return Ok(None);
            }
            self.kv[s].clear();
            self.kv[s].extend(rhs.iter());
            self.kq[s].clear();
            self.kq[s].extend((0..n).map(|i| rq[i] + hg * rhs[i]));
        }
        // Error of the embedded solution, in dopri5's norm (per step).
        let scale = sys.length_scale();
        let mut sum = 0.0;
        for i in 0..n {
            let (mut eq, mut ev) = (0.0, 0.0);
            let mut v1 = st.v[i];
            for s in 0..4 {
                let w = B[s] - B_HAT[s];
                eq += w * self.kq[s][i];
                ev += w * self.kv[s][i];
                v1 += B[s] * self.kv[s][i];
            }
            let l = scale[i];
            let t = VELOCITY_ERROR_TIME;
            let wq = eq * l / self.atol;
            let vmax = st.v[i].abs().max(v1.abs());
            let wv = ev * l * t / (self.atol + self.rtol * vmax * l * t);
            sum += wq * wq + wv * wv;
        }
        let err = (sum / (2 * n).max(1) as f64).sqrt();
        Ok(Some(if err.is_nan() { f64::INFINITY } else { err }))
    }

    fn too_small(&self, st: &State, h: f64, why: &str) -> RvdynError {
        RvdynError::Simulation(format!(
            "rosenbrock: the step fell to {h:.3e} s, below the minimum step {:.3e} s, at \
             t = {:.6e} s ({why}): an impact that never resolves or a state that has gone \
             unstable; loosen atol/rtol, lower h_min, or check the contact stiffness",
            self.h_min, st.t
        ))
    }

    /// One accepted step from `st`, not past `t_end`.
    #[allow(clippy::needless_range_loop)]
    fn step(
        &mut self,
        sys: &(impl MechanicalSystem + ?Sized),
        st: &mut State,
        t_end: f64,
    ) -> Result<()> {
        let n = st.q.len();
        if self.k.nrows() != n {
            self.jacobian(sys, st)?;
        }
        loop {
            let remaining = t_end - st.t;
            let h = landing_step(self.h, self.h_max, remaining);
            if h < self.h_min && h < remaining {
                return Err(self.too_small(st, h, "error test"));
            }
            let err = self.stages(sys, st, h)?.unwrap_or(f64::INFINITY);
            let mut end = None;
            if err <= 1.0 {
                let mut q1 = st.q.clone();
                let mut v1 = st.v.clone();
                for i in 0..n {
                    for s in 0..4 {
                        q1[i] += B[s] * self.kq[s][i];
                        v1[i] += B[s] * self.kv[s][i];
                    }
                }
                let mut a1 = vec![0.0; n];
                let mut p1 = [0.0; 3];
                self.evaluations += 1;
                match sys.eval(st.t + h, &q1, &v1, &mut a1, &mut p1) {
                    Ok(()) => {
                        let deep = sys.deepest_first_touch().filter(|d| d.0 > 1.0);
                        if deep.is_none() {
                            end = Some((q1, v1, a1, p1));
                        }
                    }
                    Err(RvdynError::Simulation(_)) => {}
                    Err(e) => return Err(e),
                }
            }
            if let Some((q1, v1, a1, p1)) = end {
                if self.track_work {
                    for j in 0..3 {
                        st.work[j] += 0.5 * h * (st.power[j] + p1[j]);
                    }
                }
                st.t += h;
                st.q = q1;
                st.v = v1;
                st.a = a1;
                st.power = p1;
                sys.mark_open_contacts();
                self.accepted += 1;
                self.age += 1;
                let grow = 0.9 * err.max(1e-10).powf(-0.7 / 3.0) * self.err_prev.powf(0.4 / 3.0);
                self.err_prev = err.max(1e-4);
                self.h = (h * grow.clamp(0.2, 4.0)).clamp(self.h_min, self.h_max);
                if self.age >= JACOBIAN_AGE {
                    self.jacobian(sys, st)?;
                }
                return Ok(());
            }
            self.rejected += 1;
            let factor = if err.is_finite() && err > 1.0 {
                (0.9 * err.powf(-1.0 / 3.0)).clamp(0.1, 0.5)
            } else {
                0.25
            };
            self.h = h * factor;
            if self.age > 0 {
                // A Jacobian from an earlier step may no longer hold the stiff directions.
                self.jacobian(sys, st)?;
            }
            if self.h < self.h_min {
                return Err(self.too_small(st, self.h, "rejected steps"));
            }
        }
    }
}

impl Integrator for Rosenbrock {
    fn advance(&mut self, sys: &dyn MechanicalSystem, st: &mut State, t_end: f64) -> Result<()> {
        if self.accepted == 0 && self.k.nrows() == 0 {
            sys.mark_open_contacts();
        }
        self.step(sys, st, t_end)
    }

    fn stats(&self) -> Stats {
        Stats {
            counts: vec![
                ("steps", self.accepted),
                ("rejected", self.rejected),
                ("jacobians", self.jacobians),
                ("evaluations", self.evaluations),
            ],
            dt: None,
        }
    }
}

/// Largest pin-force difference over `[0.5, t_end]` relative to the reference's peak there.
fn pin_error(t: &[f64], f: &[f64], f_ref: &[f64]) -> f64 {
    let per = f.len() / t.len();
    let (mut peak, mut worst) = (0.0f64, 0.0f64);
    for (k, &tk) in t.iter().enumerate() {
        if tk < 0.5 {
            continue;
        }
        for i in k * per..(k + 1) * per {
            peak = peak.max(f_ref[i].abs());
            worst = worst.max((f[i] - f_ref[i]).abs());
        }
    }
    worst / peak
}

/// `x'' = -w^2 x - 2 z w x'` in two coordinates: the method's own order check.
struct Oscillator {
    w: [f64; 2],
    scale: [f64; 2],
}

impl MechanicalSystem for Oscillator {
    fn dof(&self) -> usize {
        2
    }
    fn eval(&self, _t: f64, q: &[f64], v: &[f64], a: &mut [f64], _p: &mut [f64; 3]) -> Result<()> {
        for i in 0..2 {
            a[i] = -self.w[i] * self.w[i] * q[i] - 0.1 * self.w[i] * v[i];
        }
        Ok(())
    }
    fn length_scale(&self) -> &[f64] {
        &self.scale
    }
}

/// Largest displacement error over 2 s at a fixed step `h` (tolerances so loose that every
/// step is taken), against a dopri5 run at 1e-13.
fn oscillator_error(h: f64) -> Result<f64> {
    let sys = Oscillator {
        w: [3.0, 7.0],
        scale: [1.0, 1.0],
    };
    let settings = Settings {
        t_end: 2.0,
        dt: h,
        rtol: 1e10,
        atol: 1e10,
        rho_inf: 0.8,
        h_max: h,
        h_min: 1e-13,
        max_steps: u64::MAX,
        track_work: false,
    };
    let mut ros = Rosenbrock::new(&settings)?;
    let mut st = State::new(&sys, 0.0, vec![1.0, 1.0], vec![0.0, 0.0])?;
    let mut refd = rvdyn::solve::dopri5::Dopri5::new(1e-13, 1e-13, 1e-4, 1e-2);
    let mut sr = st.clone();
    let mut worst: f64 = 0.0;
    while st.t < 2.0 - 1e-12 {
        ros.step(&sys, &mut st, 2.0)?;
        while sr.t < st.t {
            refd.step(&sys, &mut sr, st.t)?;
        }
        for i in 0..2 {
            worst = worst.max((st.q[i] - sr.q[i]).abs());
        }
    }
    Ok(worst)
}

fn main() -> std::result::Result<(), Box<dyn std::error::Error>> {
    let (e1, e2) = (oscillator_error(0.02)?, oscillator_error(0.01)?);
    println!(
        "order check (damped oscillator, h 0.02 and 0.01 s): errors {e1:.2e}, {e2:.2e}, \
         observed order {:.2} (3 expected)",
        (e1 / e2).log2()
    );
    let args: Vec<String> = std::env::args().collect();
    let preset = args.get(1).map_or("physical", |s| s.as_str());
    let t_end: f64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1.0);
    let scene = match preset {
        "physical" => Scene::physical("rated")?,
        _ => Scene::paper("rated")?,
    };
    let run = |method: Method, dt: Option<f64>, atol: f64, rtol: f64| -> Result<_> {
        let mut opt = SimOptions::new(t_end, method);
        opt.dt = dt;
        opt.atol = atol;
        opt.rtol = rtol;
        opt.record_interval = Some(1e-3);
        opt.channels = vec![Channel::Motion, Channel::Pins];
        let start = std::time::Instant::now();
        let rec = simulate(&scene, &opt, &RunControl::default())?;
        Ok((rec, start.elapsed().as_secs_f64()))
    };
    let dopri5 = Method::parse("dopri5")?;
    let (reference, _) = if preset == "physical" {
        run(dopri5, None, 1e-12, 1e-8)?
    } else {
        run(dopri5, None, 1e-12, 1e-10)?
    };
    let t = reference.series["t"].data.clone();
    let f_ref = reference.series["pin_force"].data.clone();
    let rosenbrock = Method(&ENTRY);
    let settings: Vec<(Method, Option<f64>, f64, f64)> = if preset == "physical" {
        vec![
            (dopri5, None, 1e-8, 3e-4),
            (dopri5, None, 1e-7, 1e-3),
            (rosenbrock, None, 1e-8, 1e-4),
            (rosenbrock, None, 1e-7, 1e-3),
            (rosenbrock, None, 1e-6, 1e-2),
            (rosenbrock, None, 1e-5, 1e-1),
        ]
    } else {
        let ga = Method::parse("generalized-alpha")?;
        vec![
            (ga, Some(2e-4), 1e-9, 1e-6),
            (ga, Some(1e-3), 1e-9, 1e-6),
            (rosenbrock, None, 1e-8, 1e-5),
            (rosenbrock, None, 1e-7, 1e-4),
            (rosenbrock, None, 1e-6, 1e-3),
        ]
    };
    println!("{preset}, {t_end} s, pin-force error over [0.5, {t_end}] s against dopri5 (tight)");
    for (method, dt, atol, rtol) in settings {
        let (rec, wall) = run(method, dt, atol, rtol)?;
        let e = pin_error(&t, &rec.series["pin_force"].data, &f_ref);
        println!(
            "{:18} dt {:?} atol {atol:e} rtol {rtol:e}: error {e:.2e}, wall {wall:.3} s, {:?}",
            method.name(),
            dt,
            rec.stats.counts
        );
    }
    Ok(())
}
