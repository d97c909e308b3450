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
            balance: None,
            anchor: None,
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

/// RK4 steps between two checks of the energy balance (one observation of the state each).
const ENERGY_CHECK: u64 = 25;

/// The largest share of the energy exchanged over one energy-check interval that a stable run
/// may lose from its balance (its residual's growth over the interval). Within the stability
/// limit RK4 keeps it near 1e-6 except while an impact (the paper's start) is integrated
/// coarsely, up to 0.4 in the start's interval; a run that went unstable and then chattered
/// loses nearly all of it in every interval.
const ENERGY_LOSS_LIMIT: f64 = 0.5;
/// Changes below this fraction of the stored energy plus the work magnitudes are round-off.
const ENERGY_NOISE: f64 = 1e-9;

/// The largest share of the energy exchanged since the second energy check (after the start)
/// that a stable run may lose from its balance: a step just beyond the limit of a stiff mesh
/// leaves the pins nearly right but lets the mesh chatter, leaking a few per cent steadily
/// (rated paper scene at dt 6e-5 s: 5 % over 0.2 s, against 0.1 % at dt 5e-5 s).
const ENERGY_LEAK_LIMIT: f64 = 0.02;

/// RK4 bound to one run: fixed steps, with a check of the linearised stability limit every
/// [`STABILITY_CHECK`] steps (an explicit method beyond it can return smooth-looking but wrong
/// results) and of the energy balance every [`ENERGY_CHECK`] steps.
struct Rk4Run {
    stepper: Rk4,
    clock: FixedClock,
    /// Energy balance at the last energy check and at the second one:
    /// `(E, [W_in, W_out, D], residual)`.
    balance: Option<(f64, [f64; 3], f64)>,
    anchor: Option<(f64, [f64; 3], f64)>,
}

impl Integrator for Rk4Run {
    fn advance(&mut self, sys: &dyn MechanicalSystem, st: &mut State, _t_end: f64) -> Result<()> {
        if self.clock.taken.is_multiple_of(STABILITY_CHECK) {
            check_stability(sys, st, self.clock.h)?;
        }
        // The linearised check misses a step that is stable about the state it looks at but
        // not about the loaded one: the first impact grows, the contacts chatter open, and at
        // the next check the stiff mode is gone. The energy balance keeps the damage.
        if self.clock.taken.is_multiple_of(ENERGY_CHECK)
            && let Err(broken) =
                check_energy(sys, st, self.clock.h, &mut self.balance, &mut self.anchor)
        {
            // Name the limit when the linearised check sees it at this state.
            check_stability(sys, st, self.clock.h)?;
            return Err(broken);
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

/// Stop an RK4 run that loses more than [`ENERGY_LOSS_LIMIT`] of the energy exchanged since
/// the last check from its balance `E - E0 - W_in + W_out + D` (docs/model.md, "Energy
/// accounting"); the first call only records the balance.
fn check_energy(
    sys: &dyn MechanicalSystem,
    st: &State,
    h: f64,
    last: &mut Option<(f64, [f64; 3], f64)>,
    anchor: &mut Option<(f64, [f64; 3], f64)>,
) -> Result<()> {
    let Some(e) = sys.energy(st.t, &st.q, &st.v)? else {
        return Ok(());
    };
    // The residual's growth over an interval is judged against the energy exchanged in it
    // (the largest of |dE| and each work), not against the stored energy.
    let since = |from: (f64, [f64; 3], f64)| {
        let (e0, w0, r0) = from;
        let dw: [f64; 3] = std::array::from_fn(|j| st.work[j] - w0[j]);
        let residual = r0 + (e - e0) - dw[0] + dw[1] + dw[2];
        let exchanged = dw.iter().map(|x| x.abs()).fold((e - e0).abs(), f64::max);
        (residual, (residual - r0).abs(), exchanged)
    };
    let Some(previous) = *last else {
        *last = Some((e, st.work, 0.0));
        return Ok(());
    };
    let (residual, lost, exchanged) = since(previous);
    let now = (e, st.work, residual);
    *last = Some(now);
    let (leaked, exchanged_since_start) = match *anchor {
        Some(a) => {
            let (_, l, x) = since(a);
            (l, x)
        }
        None => {
            *anchor = Some(now);
            (0.0, 0.0)
        }
    };
    // Changes at the round-off of the stored energy and the work are no exchange: a run that
    // exchanges none (a steady start at idle, a held input) compared two round-off numbers and
    // stopped at every step.
    let noise = ENERGY_NOISE * (e.abs() + st.work.iter().map(|w| w.abs()).sum::<f64>());
    if !lost.is_finite()
        || (exchanged > noise && lost > noise && lost > ENERGY_LOSS_LIMIT * exchanged)
    {
        return Err(RvdynError::Simulation(format!(
            "rk4 with dt = {h:.3e} s broke the energy balance by t = {:.6e} s: over the last \
             {ENERGY_CHECK} steps the energy's change and the work done differ by {:.0} % of the \
             energy exchanged (a stable run: about 1e-4 %), so the step is beyond the stability \
             limit of the loaded reducer: reduce dt (halve it and compare) or use \
             integrator=\"generalized-alpha\" or \"dopri5\"",
            st.t,
            100.0 * lost / exchanged.max(f64::MIN_POSITIVE)
        )));
    }
    if exchanged_since_start > noise
        && leaked > noise
        && leaked > ENERGY_LEAK_LIMIT * exchanged_since_start
    {
        return Err(RvdynError::Simulation(format!(
            "rk4 with dt = {h:.3e} s leaks energy: by t = {:.6e} s the energy's change and the \
             work done since the start differ by {:.1} % of the energy exchanged (a stable run: \
             below 0.1 %), so a stiff contact or mesh chatters beyond the method's stability \
             limit: reduce dt (halve it and compare) or use integrator=\"generalized-alpha\" or \
             \"dopri5\"",
            st.t,
            100.0 * leaked / exchanged_since_start
        )));
    }
    Ok(())
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
             stable step at this state is about {limit:.3e} s (loaded contacts are stiffer: a \
             loaded state can need several times less): reduce dt below {:.2e} s or use \
             integrator=\"generalized-alpha\"",
            st.t,
            0.8 * limit
        )));
    }
    Ok(())
}
