//! One interface for every time integrator, and the registry that names them.
//!
//! An integrator advances a [`State`] of a [`MechanicalSystem`] by one step that does not pass
//! a target time, and counts its work in [`Stats`]. Adding one means one new file (the
//! stepper, an [`Integrator`] implementation and an [`IntegratorEntry`]) and one line in
//! [`INTEGRATORS`]; the `toy_integrator_plugs_in` test shows it.

use crate::error::{Result, RvdynError};
use crate::solve::{MechanicalSystem, State};

/// The settings an integrator is built from (a subset of the run options, SI).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// End time of the run \[s\].
    pub t_end: f64,
    /// Step \[s\] of a fixed-step method; initial step of an adaptive one.
    pub dt: f64,
    /// Relative tolerance (adaptive method, velocities).
    pub rtol: f64,
    /// Absolute displacement tolerance \[m\] (error control, Newton tolerance).
    pub atol: f64,
    /// Spectral radius at infinite frequency (generalized-alpha).
    pub rho_inf: f64,
    /// Largest step an adaptive method may take \[s\].
    pub h_max: f64,
    /// Smallest step an adaptive method may take \[s\] (below it the run fails).
    pub h_min: f64,
    /// Most steps an adaptive method may take (beyond it the run fails).
    pub max_steps: u64,
    /// Whether the work integrals (energy channel) are wanted.
    pub track_work: bool,
}

impl Settings {
    /// Check what an adaptive method needs (`Parameter` error naming the setting): `atol` a
    /// finite displacement > 0 m, `rtol` finite and >= 0, `0 < h_min <= h_max`.
    pub fn check_adaptive(&self) -> Result<()> {
        let bad = |m: String| Err(RvdynError::Parameter(m));
        if !(self.atol.is_finite() && self.atol > 0.0) {
            return bad(format!(
                "atol must be a finite displacement > 0 m, got {}: e.g. 1e-9 m",
                self.atol
            ));
        }
        if !(self.rtol.is_finite() && self.rtol >= 0.0) {
            return bad(format!(
                "rtol must be finite and >= 0, got {}: e.g. 1e-6",
                self.rtol
            ));
        }
        if !(self.h_min.is_finite() && self.h_min > 0.0) {
            return bad(format!(
                "the minimum step h_min = {:e} s must be finite and > 0: e.g. 1e-13 s",
                self.h_min
            ));
        }
        if self.h_min > self.t_end {
            return bad(format!(
                "t_end = {:e} s is shorter than the adaptive method's minimum step h_min = {:e} \
                 s: lower h_min below t_end",
                self.t_end, self.h_min
            ));
        }
        if self.h_min > self.h_max {
            return bad(format!(
                "the minimum step h_min = {:e} s is above the largest step {:e} s (for a \
                 speed-driven scene an eighth of the pin-mesh period): lower h_min",
                self.h_min, self.h_max
            ));
        }
        Ok(())
    }
}

/// The next step of an adaptive method: the proposal `h` \[s\] within `h_max`, landing on the
/// end time `remaining` s ahead without leaving a sliver of a last step (a step over half of
/// what remains becomes half of it).
pub fn landing_step(h: f64, h_max: f64, remaining: f64) -> f64 {
    let h = h.min(h_max);
    if h >= remaining {
        remaining
    } else if h > 0.5 * remaining {
        0.5 * remaining
    } else {
        h
    }
}

/// Work counters of a run: whole numbers, by name (only those a method has).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Stats {
    /// Named counts, e.g. `("steps", 10000)`, `("evaluations", 11532)`.
    pub counts: Vec<(&'static str, u64)>,
    /// The fixed step actually used \[s\]; `None` for an adaptive method.
    pub dt: Option<f64>,
}

/// A time integrator bound to one run.
pub trait Integrator: Send {
    /// Advance `st` by one step (possibly made of sub-steps or retried tries) that ends at or
    /// before `t_end` \[s\]; a fixed-step method lands exactly on `t_end` with its last step.
    fn advance(&mut self, sys: &dyn MechanicalSystem, st: &mut State, t_end: f64) -> Result<()>;
    /// Counts of the work done so far.
    fn stats(&self) -> Stats;
    /// Ask the integrator to leave the power flows at the end of each whole step, and the
    /// work increment `h (P0 + P1) / 2` that needs them, to the caller (see
    /// [`Integrator::pending_work`]); `true` if it does so from now on. A caller that records a
    /// sample at the step end gets the power flows from that sample's evaluation instead of a
    /// second one at the same state. The default integrator keeps doing its own.
    fn defer_step_power(&mut self) -> bool {
        false
    }
    /// After [`Integrator::advance`] with deferral on: `Some(h)` if the step (of `h` s) left
    /// `st.power` and `st.work` at their start values, for the caller to set
    /// `st.power = P1` and `st.work += h (P0 + P1) / 2`; `None` if they are done.
    fn pending_work(&self) -> Option<f64> {
        None
    }
    /// Offer to check each step end with an evaluation the caller makes there anyway (a
    /// recorded sample); `true` if the integrator may from now on end a step provisionally
    /// (see [`Integrator::provisional`]). The default integrator does not.
    fn check_with_samples(&mut self) -> bool {
        false
    }
    /// After [`Integrator::advance`]: whether the step ended provisionally. The caller must
    /// then call [`Integrator::confirm`] before it uses the state.
    fn provisional(&self) -> bool {
        false
    }
    /// Check a provisional step end `st` with the accelerations `f_end` (free coordinates, as
    /// `MechanicalSystem::eval` gives them) evaluated at it, or with an evaluation of the
    /// integrator's own (`None`). `Ok(true)`: the state stands and the caller's evaluation
    /// is valid; `Ok(false)`: `st` was moved (the caller evaluates again).
    fn confirm(
        &mut self,
        _sys: &dyn MechanicalSystem,
        _st: &mut State,
        _f_end: Option<&[f64]>,
    ) -> Result<bool> {
        Ok(true)
    }
}

/// A registered integrator: its names, default step and constructor.
#[derive(Debug)]
pub struct IntegratorEntry {
    /// Canonical name (`"rk4"`, `"dopri5"`, `"generalized-alpha"`).
    pub name: &'static str,
    /// Other accepted spellings (lower case, `-` for `_`).
    pub aliases: &'static [&'static str],
    /// Default step \[s\] (the initial step of an adaptive method).
    pub default_dt: f64,
    /// Whether the step size is chosen by the method.
    pub adaptive: bool,
    /// One line for listings and error messages.
    pub summary: &'static str,
    /// Build the integrator for one run.
    pub build: fn(&Settings) -> Result<Box<dyn Integrator>>,
}

/// Every integrator known by name. Add a line here to register a new one.
pub static INTEGRATORS: &[&IntegratorEntry] = &[
    &crate::solve::generalized_alpha::ENTRY,
    &crate::solve::adaptive_alpha::ENTRY,
    &crate::solve::dopri5::ENTRY,
    &crate::solve::rk4::ENTRY,
];

/// A handle on a registered integrator (cheap to copy; compares by name).
#[derive(Debug, Clone, Copy)]
pub struct Method(pub &'static IntegratorEntry);

impl PartialEq for Method {
    fn eq(&self, other: &Self) -> bool {
        self.0.name == other.0.name
    }
}
impl Eq for Method {}

#[allow(non_upper_case_globals)]
impl Method {
    /// Classical fixed-step Runge-Kutta of order 4.
    pub const Rk4: Method = Method(&crate::solve::rk4::ENTRY);
    /// Adaptive Dormand-Prince 5(4).
    pub const Dopri5: Method = Method(&crate::solve::dopri5::ENTRY);
    /// Implicit generalized-alpha (the default).
    pub const GeneralizedAlpha: Method = Method(&crate::solve::generalized_alpha::ENTRY);

    /// Look `name` up in [`INTEGRATORS`] (case and `_`/`-` insensitive, aliases accepted).
    pub fn parse(name: &str) -> Result<Self> {
        Self::parse_in(INTEGRATORS, name)
    }

    /// Look `name` up in a given registry.
    pub fn parse_in(registry: &[&'static IntegratorEntry], name: &str) -> Result<Self> {
        let key = name.to_ascii_lowercase().replace('_', "-");
        registry
            .iter()
            .find(|e| e.name == key || e.aliases.contains(&key.as_str()))
            .map(|e| Method(e))
            .ok_or_else(|| {
                let names: Vec<String> = registry.iter().map(|e| format!("{:?}", e.name)).collect();
                RvdynError::Parameter(format!(
                    "unknown integrator {name:?}: choose one of {}",
                    names.join(", ")
                ))
            })
    }

    /// Canonical name.
    pub fn name(&self) -> &'static str {
        self.0.name
    }

    /// Default step \[s\].
    pub fn default_dt(&self) -> f64 {
        self.0.default_dt
    }

    /// Build the integrator for one run.
    pub fn build(&self, settings: &Settings) -> Result<Box<dyn Integrator>> {
        (self.0.build)(settings)
    }
}

/// The clock of a fixed-step method: `n = ceil(t_end / dt)` equal steps `h = t_end / n`, the
/// last one landing exactly on `t_end` (no round-off drift of the end time).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FixedClock {
    /// The step \[s\].
    pub h: f64,
    /// Number of steps to `t_end`.
    pub n: u64,
    /// Steps taken so far.
    pub taken: u64,
    t_end: f64,
}

impl FixedClock {
    /// Equal steps of at most `dt` \[s\] to `t_end` \[s\].
    pub fn new(t_end: f64, dt: f64) -> Self {
        let n = (t_end / dt).ceil().max(1.0) as u64;
        Self {
            h: t_end / n as f64,
            n,
            taken: 0,
            t_end,
        }
    }

    /// Count a step just taken and set the time to `taken h` (the last one to `t_end`
    /// exactly): summing `h` step by step drifts by 1e-11 s over 50 000 steps, so that step
    /// ends would miss sample times `k h` of the same interval, and each such sample would
    /// cost an interpolation and a force evaluation of its own. A method that keeps state
    /// tied to the time (generalized-alpha's pseudo-acceleration) must follow the change.
    pub fn tick(&mut self, st: &mut State) {
        self.taken += 1;
        st.t = if self.taken == self.n {
            self.t_end
        } else {
            self.taken as f64 * self.h
        };
    }
}
