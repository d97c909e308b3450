//! Adaptive Dormand-Prince 5(4) with an error norm on displacements.
//!
//! The error of coordinate `i` is weighed by its lever `L_i` (m per rad): a position error
//! counts as `|e_q| L_i` against `atol` \[m\]; a velocity error as `|e_v| L_i tau` against
//! `atol + rtol |v_i| L_i tau` with `tau = 1 ms`, so that `atol` bounds both the displacement
//! error and the displacement a velocity error makes within a millisecond. No relative
//! tolerance on positions: absolute angles grow without bound and say nothing about accuracy.
//!
//! Theory: docs/model.md, section "Dormand-Prince 5(4)".

use crate::error::{Result, RvdynError};
use crate::solve::integrator::{Integrator, IntegratorEntry, Settings, Stats};
use crate::solve::system::{MechanicalSystem, State};

/// Registry entry of Dormand-Prince 5(4).
pub static ENTRY: IntegratorEntry = IntegratorEntry {
    name: "dopri5",
    aliases: &["dopri", "rk45"],
    default_dt: 1e-6,
    adaptive: true,
    summary: "Dormand-Prince 5(4), explicit, adaptive step with error control on displacements",
    build: |s: &Settings| {
        s.check_adaptive()?;
        // The first step is a guess: raised to h_min rather than failing there at once.
        let mut d = Dopri5::new(s.rtol, s.atol, s.dt.max(s.h_min).min(s.h_max), s.h_max);
        d.h_min = s.h_min;
        d.max_steps = s.max_steps;
        Ok(Box::new(d))
    },
};

/// Time over which a velocity error is turned into a displacement error \[s\].
pub const VELOCITY_ERROR_TIME: f64 = 1e-3;

/// `h lambda` beyond which a step counts as limited by stability, not accuracy (Hairer &
/// Wanner, Solving ODEs II, section IV.2: the stability boundary of DOPRI5 on the negative
/// real axis is about 3.3).
const STIFF_H_LAMBDA: f64 = 3.25;
/// Stability-limited steps (with fewer than 6 others between them) before the run counts as
/// stiff (Hairer's DOPRI5 code uses 15).
const STIFF_STEPS: u32 = 15;
/// A stiff run stops when its step is below this \[s\]: more than 10^7 steps per simulated
/// second, where the implicit method takes 10^4 (the legitimate steps of the default scenes
/// are 1e-5 to 1e-4 s).
pub const STIFF_STEP_FLOOR: f64 = 1e-7;

const C: [f64; 7] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];
const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];
/// Fifth-order weights (= last row of A: first same as last).
const B: [f64; 7] = [
    35.0 / 384.0,
    0.0,
    500.0 / 1113.0,
    125.0 / 192.0,
    -2187.0 / 6784.0,
    11.0 / 84.0,
    0.0,
];
/// Difference between the fifth- and fourth-order weights.
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];

/// Step-size controller settings and statistics of the adaptive method.
#[derive(Debug)]
pub struct Dopri5 {
    /// Relative tolerance on velocities.
    pub rtol: f64,
    /// Displacement tolerance \[m\].
    pub atol: f64,
    /// Current step proposal \[s\].
    pub h: f64,
    /// Smallest step allowed before the run is declared failed \[s\].
    pub h_min: f64,
    /// Largest step \[s\].
    pub h_max: f64,
    /// Most accepted steps before the run is declared failed.
    pub max_steps: u64,
    /// Accepted steps.
    pub accepted: u64,
    /// Rejected tries.
    pub rejected: u64,
    kq: [Vec<f64>; 7],
    kv: [Vec<f64>; 7],
    kw: [[f64; 3]; 7],
    q: Vec<f64>,
    v: Vec<f64>,
    /// State of stage 6 (for the stiffness estimate).
    q6: Vec<f64>,
    v6: Vec<f64>,
    err_prev: f64,
    /// Stability-limited steps counted by the stiffness detector.
    stiff_steps: u32,
    /// Other steps since the last stability-limited one.
    calm_steps: u32,
}

impl Dopri5 {
    /// A controller starting with step `h0` \[s\].
    pub fn new(rtol: f64, atol: f64, h0: f64, h_max: f64) -> Self {
        Self {
            rtol,
            atol,
            h: h0,
            h_min: 1e-13,
            h_max,
            max_steps: u64::MAX,
            accepted: 0,
            rejected: 0,
            kq: Default::default(),
            kv: Default::default(),
            kw: [[0.0; 3]; 7],
            q: Vec::new(),
            v: Vec::new(),
            q6: Vec::new(),
            v6: Vec::new(),
            err_prev: 1e-4,
            stiff_steps: 0,
            calm_steps: 0,
        }
    }

    /// Take one accepted step of `st` (in place: `t` \[s\], and `q`, `v` in the system's units),
    /// not past `t_stop` \[s\]; rejected tries are retried with a smaller step. Fails with
    /// `SimulationError` when the step collapses below `h_min` \[s\].
    pub fn step<S: MechanicalSystem + ?Sized>(
        &mut self,
        sys: &S,
        st: &mut State,
        t_stop: f64,
    ) -> Result<()> {
        let n = st.q.len();
        for k in 0..7 {
            self.kq[k].resize(n, 0.0);
            self.kv[k].resize(n, 0.0);
        }
        self.q.resize(n, 0.0);
        self.v.resize(n, 0.0);
        self.q6.resize(n, 0.0);
        self.v6.resize(n, 0.0);
        let scale = sys.length_scale().to_vec();
        loop {
            let h = self.h.min(t_stop - st.t).min(self.h_max);
            if h < self.h_min {
                return Err(RvdynError::Simulation(format!(
                    "adaptive step size collapsed to {h:.3e} s at t = {:.6e} s: the contact is \
                     too stiff or the state too violent for the explicit Dormand-Prince method; \
                     use integrator=\"generalized-alpha\" or loosen atol/rtol",
                    st.t
                )));
            }
            self.kq[0].copy_from_slice(&st.v);
            self.kv[0].copy_from_slice(&st.a);
            self.kw[0] = st.power;
            let mut failed = None;
            for s in 1..7 {
                for i in 0..n {
                    let mut dq = 0.0;
                    let mut dv = 0.0;
                    for (r, a) in A[s].iter().enumerate().take(s) {
                        dq += a * self.kq[r][i];
                        dv += a * self.kv[r][i];
                    }
                    self.q[i] = st.q[i] + h * dq;
                    self.v[i] = st.v[i] + h * dv;
                }
                if s == 5 {
                    self.q6.copy_from_slice(&self.q);
                    self.v6.copy_from_slice(&self.v);
                }
                self.kq[s].copy_from_slice(&self.v);
                let (kv, kw) = (&mut self.kv[s], &mut self.kw[s]);
                if let Err(e) = sys.eval(st.t + C[s] * h, &self.q, &self.v, kv, kw) {
                    failed = Some(e);
                    break;
                }
            }
            // A stage that went unphysical is a too-large step, not yet a failed run.
            let err = match failed {
                Some(e) => {
                    if h <= self.h_min * 16.0 {
                        return Err(e);
                    }
                    f64::INFINITY
                }
                None => self.error_norm(st, h, &scale),
            };
            if err <= 1.0 {
                // Stage 7 is the new state (FSAL).
                st.q.copy_from_slice(&self.q);
                st.v.copy_from_slice(&self.v);
                st.a.copy_from_slice(&self.kv[6]);
                st.power = self.kw[6];
                for j in 0..3 {
                    st.work[j] += h * (0..7).map(|s| B[s] * self.kw[s][j]).sum::<f64>();
                }
                st.t += h;
                self.accepted += 1;
                // PI controller (Hairer's DOPRI5 constants).
                let fac = 0.9 * err.max(1e-10).powf(-0.7 / 5.0) * self.err_prev.powf(0.4 / 5.0);
                self.h = h * fac.clamp(0.2, 5.0);
                self.err_prev = err.max(1e-4);
                return self.detect_stiffness(st, h, &scale);
            }
            self.rejected += 1;
            let fac = if err.is_finite() {
                0.9 * err.powf(-0.2)
            } else {
                0.1
            };
            self.h = h * fac.clamp(0.1, 0.5);
        }
    }

    /// Hairer's stiffness detection after an accepted step of size `h`: `h lambda` estimated
    /// from the last two stages (`|f7 - f6| / |y7 - y6|`, coordinates weighted as in the error
    /// norm). A run whose step is held at the stability limit below [`STIFF_STEP_FLOOR`] stops
    /// with a `Simulation` error and advice, instead of crawling.
    #[allow(clippy::needless_range_loop)]
    fn detect_stiffness(&mut self, st: &State, h: f64, scale: &[f64]) -> Result<()> {
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..st.q.len() {
            let (wq, wv) = (scale[i], scale[i] * VELOCITY_ERROR_TIME);
            num += (wq * (self.kq[6][i] - self.kq[5][i])).powi(2)
                + (wv * (self.kv[6][i] - self.kv[5][i])).powi(2);
            den += (wq * (st.q[i] - self.q6[i])).powi(2) + (wv * (st.v[i] - self.v6[i])).powi(2);
        }
        if den <= 0.0 {
            return Ok(());
        }
        let h_lambda = h * (num / den).sqrt();
        if h_lambda > STIFF_H_LAMBDA {
            self.calm_steps = 0;
            self.stiff_steps += 1;
            if self.stiff_steps >= STIFF_STEPS && h < STIFF_STEP_FLOOR {
                let lambda = h_lambda / h;
                return Err(RvdynError::Simulation(format!(
                    "dopri5 is held by stability, not accuracy, at t = {:.6e} s: its step is \
                     {h:.2e} s because this scene's fastest mode has an eigenvalue of about \
                     {lambda:.2e} 1/s ({:.2e} Hz); an explicit method would need more than {:.0e} \
                     steps per simulated second. Use integrator=\"generalized-alpha\" (implicit, \
                     stable at any step), or make the scene less stiff (softer bearings, a \
                     heavier disc, or with friction a larger friction.regularisation_speed: \
                     friction near zero sliding speed acts as a damper of mu N / v_reg)",
                    st.t,
                    lambda / (2.0 * std::f64::consts::PI),
                    1.0 / h
                )));
            }
        } else {
            self.calm_steps += 1;
            if self.calm_steps >= 6 {
                self.stiff_steps = 0;
            }
        }
        Ok(())
    }

    // Index loops over several parallel arrays read more plainly than zipped iterators here.
    #[allow(clippy::needless_range_loop)]
    fn error_norm(&self, st: &State, h: f64, scale: &[f64]) -> f64 {
        let n = st.q.len();
        let mut sum = 0.0;
        for i in 0..n {
            let (mut e_q, mut e_v) = (0.0, 0.0);
            for s in 0..7 {
                e_q += E[s] * self.kq[s][i];
                e_v += E[s] * self.kv[s][i];
            }
            let l = scale[i];
            let w_q = (h * e_q * l) / self.atol;
            let vmax = st.v[i].abs().max(self.v[i].abs());
            let w_v = (h * e_v * l * VELOCITY_ERROR_TIME)
                / (self.atol + self.rtol * vmax * l * VELOCITY_ERROR_TIME);
            sum += w_q * w_q + w_v * w_v;
        }
        (sum / (2 * n) as f64).sqrt()
    }
}

impl Integrator for Dopri5 {
    fn advance(&mut self, sys: &dyn MechanicalSystem, st: &mut State, t_end: f64) -> Result<()> {
        if self.accepted >= self.max_steps {
            return Err(RvdynError::Simulation(format!(
                "dopri5 needed more than max_steps = {} steps to reach t = {t_end:.6e} s \
                 (stopped at t = {:.6e} s): loosen atol/rtol, raise max_steps, or use \
                 integrator=\"generalized-alpha-adaptive\" if the steps are limited by stability",
                self.max_steps, st.t
            )));
        }
        self.step(sys, st, t_end)
    }

    fn stats(&self) -> Stats {
        Stats {
            counts: vec![
                ("steps", self.accepted),
                ("rejected", self.rejected),
                ("evaluations", 6 * (self.accepted + self.rejected)),
            ],
            dt: None,
        }
    }
}
