//! Loaded tooth contact analysis (LTCA): the static equilibrium of the whole reducer under an
//! output torque with the input held, at a set of crank angles; transmission error in both
//! drive directions, the torque-twist loop with rigidity, lost motion and backlash, and the
//! worst-case contact loads for FEA (formulation and sources: docs/model.md, "Quasi-static
//! analysis").
//!
//! Crank angle `psi` \[rad\]: the absolute crank rotation of the kinematic (unloaded, error-free)
//! pose, in which the carrier is at `-psi / zc`, disc `k`'s centre at
//! `e (cos(psi + a_k), sin(psi + a_k))` and the input (sun, or cranks without a first stage)
//! where the first stage has no deflection. The input is held there; the output torque `T`
//! [N m] acts on the carrier against positive rotation (as the scene's load), so a positive
//! `T` is the forward drive.

pub mod budget;
pub mod export;
pub mod friction;
mod gear_errors;
pub mod newton;
pub mod statics;
pub mod te_extremes;

use std::f64::consts::{PI, TAU};

use crate::contact::hertz::{Material, effective_modulus, hertz_line_strip};
use crate::dynamics::scene::Scene;
use crate::error::{Result, RvdynError, require_finite};
pub use budget::ComplianceBudget;
pub use newton::{NewtonOptions, NewtonReport};
use newton::{Scratch, equilibrium, solve_dense};
use rayon::prelude::*;
use serde::Serialize;
use statics::{CARRIER, Statics, Work};
pub use te_extremes::{CurveExtremes, Extreme};

/// One arc minute \[rad\].
pub const ARCMIN: f64 = PI / (180.0 * 60.0);
/// One arc second \[rad\].
pub const ARCSEC: f64 = PI / (180.0 * 3600.0);

/// One pin contact at equilibrium (disc frame: origin at the disc centre, axes turned with the
/// disc).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PinLoad {
    /// Normal force \[N\] (>= 0).
    pub force: f64,
    /// Signed gap \[m\] (negative = penetration).
    pub gap: f64,
    /// Contact point on the profile, disc frame \[m\].
    pub point: [f64; 2],
    /// Unit outward profile normal, disc frame.
    pub normal: [f64; 2],
    /// Hertz half-width of the contact strip \[m\] (0 without load).
    pub half_width: f64,
    /// Hertz peak pressure \[Pa\] (0 without load).
    pub peak_pressure: f64,
}

/// The static equilibrium at one crank angle and torque.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LtcaPoint {
    /// Crank angle \[rad\].
    pub crank_angle: f64,
    /// Output torque [N m].
    pub torque: f64,
    /// Carrier (output) angle \[rad\].
    pub output_angle: f64,
    /// Held input angle \[rad\].
    pub input_angle: f64,
    /// Transmission error `output - input / i` \[rad\].
    pub transmission_error: f64,
    /// Torque the held input carries [N m].
    pub input_torque: f64,
    /// Pin loads, `[disc][pin]`.
    pub pins: Vec<Vec<PinLoad>>,
    /// Loaded pins per disc.
    pub loaded_pins: Vec<usize>,
    /// Disc rotation from its kinematic angle \[rad\], per disc.
    pub disc_rotation: Vec<f64>,
    /// Angle of each disc in the fixed frame \[rad\]: the rotation from the disc frame of the
    /// pin loads to the fixed frame of the bearing forces.
    pub disc_angle: Vec<f64>,
    /// Disc centre displacement from its kinematic position \[m\], per disc.
    pub disc_displacement: Vec<[f64; 2]>,
    /// Signed sun/planet mesh force per crank \[N\] (positive on the drive flank).
    pub mesh_force: Vec<f64>,
    /// Crank bearing force on each crank centre \[N\] (compliant crank bearings; else empty).
    pub crank_bearing_force: Vec<[f64; 2]>,
    /// Eccentric bearing force on each disc, `[crank * discs + disc]` \[N\] (compliant joints).
    pub eccentric_bearing_force: Vec<[f64; 2]>,
    /// Bending deflection of each crank's eccentric from the crank's line, `[crank * discs +
    /// disc]` \[m\], fixed frame (bending cranks, `crank_shaft`; else empty).
    pub crank_deflection: Vec<[f64; 2]>,
    /// Moment balance of the whole reducer about its axis (input + load + pin reactions),
    /// relative to the torque (absolute, N m, at zero torque). Near the smallest torque an
    /// equilibrium resolves it is set by the round-off of the contact forces (about 1e-5 at 1e-3
    /// N m on the paper scene), not by the Newton tolerance.
    pub torque_balance: f64,
    /// Largest residual of the equilibrium equations (every free coordinate of every body),
    /// relative to the load scale.
    pub residual: f64,
    /// Newton iterations used.
    pub iterations: usize,
    /// Torsional stiffness `dT / d(output angle)` at this equilibrium [N m/rad], analytic.
    pub torsional_stiffness: f64,
}

impl LtcaPoint {
    /// Largest pin force \[N\] over both discs.
    pub fn peak_pin_force(&self) -> f64 {
        self.pins
            .iter()
            .flatten()
            .fold(0.0, |m: f64, p| m.max(p.force))
    }
}

/// Transmission error over one mesh period in both drive directions.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TransmissionError {
    /// Crank angles \[rad\] (`periods` whole mesh periods, endpoint excluded).
    pub crank_angle: Vec<f64>,
    /// Period of the mesh in crank angle \[rad\].
    pub period: f64,
    /// Mesh periods covered.
    pub periods: usize,
    /// TE at `+torque` (forward drive) \[rad\].
    pub forward: Vec<f64>,
    /// TE at `-torque` (reverse drive) \[rad\].
    pub reverse: Vec<f64>,
    /// TE at the light load `+light` \[rad\]: the geometric (unloaded) TE, forward.
    pub unloaded_forward: Vec<f64>,
    /// TE at `-light` \[rad\]: the unloaded TE, reverse.
    pub unloaded_reverse: Vec<f64>,
    /// Each curve's extremes, located between the crank angles ([`te_extremes`]): their
    /// difference is the curve's peak-to-peak.
    pub extremes: TeExtremes,
    /// Loaded torque [N m].
    pub torque: f64,
    /// Light torque of the unloaded TE [N m] (0 without the unloaded curves).
    pub light: f64,
    /// Pin loads at the crank angles of the loaded curves (with `pin_loads`; else `None`).
    pub pin_loads: Option<TePinLoads>,
}

/// Pin loads along the two loaded TE curves, read off the equilibria the TE is computed from
/// (the same as [`Ltca::sweep`]'s reports at these crank angles, to Newton's tolerance).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TePinLoads {
    /// At `+torque`.
    pub forward: CurvePinLoads,
    /// At `-torque`.
    pub reverse: CurvePinLoads,
}

/// Pin loads of one curve, per crank angle.
#[derive(Debug, Clone, PartialEq, Serialize, Default)]
pub struct CurvePinLoads {
    /// Largest pin force over both discs \[N\] ([`LtcaPoint::peak_pin_force`]).
    pub peak_force: Vec<f64>,
    /// Fewest loaded pins (force above zero) on any disc ([`LtcaPoint::loaded_pins`]).
    pub loaded_pins_min: Vec<usize>,
}

/// The extremes of the four TE curves.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TeExtremes {
    /// At `+torque`.
    pub forward: CurveExtremes,
    /// At `-torque`.
    pub reverse: CurveExtremes,
    /// At `+light` (`None` without the unloaded curves).
    pub unloaded_forward: Option<CurveExtremes>,
    /// At `-light` (`None` without the unloaded curves).
    pub unloaded_reverse: Option<CurveExtremes>,
}

impl TeExtremes {
    /// The same extremes at crank angles `shift` \[rad\] later.
    fn shift(&mut self, shift: f64) {
        let curves = [Some(&mut self.forward), Some(&mut self.reverse)]
            .into_iter()
            .chain([
                self.unloaded_forward.as_mut(),
                self.unloaded_reverse.as_mut(),
            ]);
        for c in curves.flatten() {
            c.max.crank_angle += shift;
            c.min.crank_angle += shift;
        }
    }
}

impl CurveExtremes {
    /// The extremes of two stretches of one curve together.
    fn join(self, other: CurveExtremes) -> CurveExtremes {
        CurveExtremes {
            max: if other.max.value > self.max.value {
                other.max
            } else {
                self.max
            },
            min: if other.min.value < self.min.value {
                other.min
            } else {
                self.min
            },
            refined: self.refined && other.refined,
        }
    }
}

impl TransmissionError {
    /// The same curves at crank angles `shift` \[rad\] later.
    fn shift_crank_angles(&mut self, shift: f64) {
        for a in &mut self.crank_angle {
            *a += shift;
        }
        self.extremes.shift(shift);
    }

    /// `next` (the following crank angles of the same curves) appended.
    fn join(&mut self, next: TransmissionError) {
        self.periods += next.periods;
        self.crank_angle.extend(next.crank_angle);
        self.forward.extend(next.forward);
        self.reverse.extend(next.reverse);
        self.unloaded_forward.extend(next.unloaded_forward);
        self.unloaded_reverse.extend(next.unloaded_reverse);
        let (a, b) = (&mut self.extremes, next.extremes);
        a.forward = a.forward.join(b.forward);
        a.reverse = a.reverse.join(b.reverse);
        let opt = |x: Option<CurveExtremes>, y: Option<CurveExtremes>| match (x, y) {
            (Some(x), Some(y)) => Some(x.join(y)),
            (x, y) => x.or(y),
        };
        a.unloaded_forward = opt(a.unloaded_forward, b.unloaded_forward);
        a.unloaded_reverse = opt(a.unloaded_reverse, b.unloaded_reverse);
        if let (Some(p), Some(q)) = (self.pin_loads.as_mut(), next.pin_loads) {
            for (x, y) in [(&mut p.forward, q.forward), (&mut p.reverse, q.reverse)] {
                x.peak_force.extend(y.peak_force);
                x.loaded_pins_min.extend(y.loaded_pins_min);
            }
        }
    }
}

/// Peak-to-peak of a series.
pub fn peak_to_peak(v: &[f64]) -> f64 {
    let (lo, hi) = v
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(*x), b.max(*x))
        });
    if v.is_empty() { 0.0 } else { hi - lo }
}

/// The torque-twist loop at one crank angle with rigidity, lost motion and backlash.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TwistLoop {
    /// Crank angle of the loop \[rad\].
    pub crank_angle: f64,
    /// Output torque along the loop [N m] (0 -> +rated -> -rated -> 0).
    pub torque: Vec<f64>,
    /// Output twist relative to the held input \[rad\] (positive with positive torque).
    pub twist: Vec<f64>,
    /// Rated torque of the loop [N m].
    pub rated_torque: f64,
    /// Catalogue torsional rigidity `2 T_r / (twist(+T_r) - twist(-T_r))` [N m/rad].
    pub rigidity: f64,
    /// Lost motion: twist width between the loop's midpoints at +-3 % of rated torque \[rad\].
    pub lost_motion: f64,
    /// Backlash: twist width at zero torque (limits from both sides) \[rad\].
    pub backlash: f64,
    /// Analytic tangent stiffness at each loop point [N m/rad].
    pub tangent_stiffness: Vec<f64>,
}

/// One point of the frictionless torque-twist loop: its index along the loop, the torque
/// solved (1e-7 rated at a zero of the loop), twist, tangent stiffness and unknowns.
#[derive(Clone)]
struct LoopPoint {
    index: usize,
    torque: f64,
    twist: f64,
    tangent: f64,
    q: Vec<f64>,
}

/// A solved equilibrium kept for warm starts.
#[derive(Debug, Clone)]
struct Solved {
    psi: f64,
    torque: f64,
    q: Vec<f64>,
    /// `q` minus the kinematic unknowns at `psi` (what the warm start extrapolates).
    deflection: Vec<f64>,
}

impl Solved {
    fn new(st: &Statics, psi: f64, torque: f64, q: Vec<f64>) -> Self {
        let kin = st.kinematic_unknowns(psi);
        Self::with_kinematic(psi, torque, q, &kin)
    }

    fn with_kinematic(psi: f64, torque: f64, q: Vec<f64>, kin: &[f64]) -> Self {
        let deflection = q.iter().zip(kin).map(|(a, b)| a - b).collect();
        Self {
            psi,
            torque,
            q,
            deflection,
        }
    }
}

/// Previous solutions kept for the warm start.
const HISTORY: usize = 3;

/// Angles per parallel chain of a long [`Ltca::sweep`]: a chain's start from the kinematic
/// pose costs about as much as nine warm-started angles (about 18 evaluations against 2), a
/// few per cent of a chain this long.
pub const SWEEP_CHAIN: usize = 150;

/// At most this many chains per sweep.
const MAX_SWEEP_CHAINS: usize = 64;

/// A pin is loaded above this fraction of the load scale `|T| / rp` (at least of 1 N): below
/// it a force is round-off.
pub const LOADED_FRACTION: f64 = 1e-9;

/// The most crank angles or loop points one analysis takes: ten million solves take hours, and
/// a count far beyond it (a typo) would otherwise abort on allocation instead of raising.
pub const MAX_POINTS: usize = 10_000_000;

/// `ParameterError` when `count` of `what` exceeds [`MAX_POINTS`].
pub(crate) fn require_points(what: &str, count: usize) -> Result<()> {
    if count > MAX_POINTS {
        return Err(RvdynError::Parameter(format!(
            "{what} = {count} is more than the {MAX_POINTS} one analysis takes (it would not fit \
             in memory or finish): use fewer"
        )));
    }
    Ok(())
}

/// The warm start at `(psi, torque)` from the previous solutions `history` (newest first):
/// their deflections from their kinematic poses, extrapolated by the Lagrange polynomial
/// through the newest ones that lie along the same torque (varying crank angle: linear) or
/// the same crank angle (varying torque: quadratic), added to the kinematic pose `kin` at
/// `psi`. Only one step ahead (at most 1.5 times the last spacing): a far jump is no
/// predictor. The degrees are measured (BENCHMARKS.md section 10.4): along the torque the
/// quadratic saves 18 % of the loop's evaluations; along the crank angle, where a pin or a
/// roller opens or closes every few steps and the deflection's curvature jumps there, it
/// costs 10 % more than the linear one, also when used only between solutions with the same
/// pins touching.
fn predictor(history: &[Solved], psi: f64, torque: f64, kin: Vec<f64>) -> Vec<f64> {
    let Some(last) = history.first() else {
        return kin;
    };
    // The parameter along which the history lies, and its value at each point.
    let along = |p: &Solved| -> Option<f64> {
        if p.torque == torque && last.torque == torque {
            Some(p.psi)
        } else if p.psi == psi && last.psi == psi {
            Some(p.torque)
        } else {
            None
        }
    };
    let (target, degree) = if last.torque == torque {
        (psi, 1)
    } else {
        (torque, 2)
    };
    let mut s: Vec<f64> = Vec::with_capacity(HISTORY);
    for p in history.iter().take(degree + 1) {
        match along(p) {
            Some(v) if s.iter().all(|&u| u != v) => s.push(v),
            _ => break,
        }
    }
    if s.len() >= 2 && (target - s[0]).abs() > 1.5 * (s[0] - s[1]).abs() {
        s.truncate(1);
    }
    let d0 = &last.deflection;
    let mut out = kin;
    if s.len() == 2 {
        // Linear: d0 + w (d0 - d1), summed in this order as before the quadratic was added
        // (the light-load solves' iteration counts follow round-off).
        let d1 = &history[1].deflection;
        let w = (target - s[0]) / (s[0] - s[1]);
        for (o, (a, b)) in out.iter_mut().zip(d0.iter().zip(d1)) {
            let k = *o;
            *o = k + a + w * (a - b);
        }
    } else if s.len() == 3 {
        let lagrange = |j: usize| -> f64 {
            (0..3)
                .filter(|&m| m != j)
                .map(|m| (target - s[m]) / (s[j] - s[m]))
                .product()
        };
        let (d1, d2) = (&history[1].deflection, &history[2].deflection);
        let w = [lagrange(0), lagrange(1), lagrange(2)];
        for (i, o) in out.iter_mut().enumerate() {
            *o += w[0] * d0[i] + w[1] * d1[i] + w[2] * d2[i];
        }
    } else {
        for (o, a) in out.iter_mut().zip(d0) {
            *o += a;
        }
    }
    out
}

/// The loaded tooth contact analysis of one scene.
#[derive(Debug, Clone)]
pub struct Ltca {
    statics: Statics,
    options: NewtonOptions,
    work: Work,
    /// Newton's scratch space, with the contact state at the last solution.
    scratch: Scratch,
    /// The unknowns whose contact state `scratch` holds for a report (empty: none).
    captured_q: Vec<f64>,
    /// Keep the contact state of the next solution (for its report).
    capture: bool,
    /// The last solutions `(psi, torque, q)`, newest first (at most [`HISTORY`]): the warm
    /// start of the next.
    history: Vec<Solved>,
    k_ref: f64,
    face_width: f64,
    ratio: f64,
    mesh_period: f64,
    te_window: f64,
    /// The scene's friction (as the dynamic models apply it; `friction`).
    friction: friction::FrictionLaws,
}

impl Ltca {
    /// Build the analysis of a scene (validated; its drive and load are ignored: the input is
    /// held and the torque is given per call).
    pub fn new(scene: &Scene) -> Result<Self> {
        Self::with_options(scene, NewtonOptions::default())
    }

    /// As [`Ltca::new`] with solver options.
    pub fn with_options(scene: &Scene, options: NewtonOptions) -> Result<Self> {
        require_finite("tolerance", options.tolerance)?;
        let statics = Statics::new(scene)?;
        let mut k_ref = statics.pin_secant_stiffness(1e-5);
        if let Some(b) = &statics.eccentric_bearing {
            // The bearing's stiffness at a 1 mm deflection (beyond any clearance it has).
            k_ref = k_ref.max(b.static_tangent([1e-3, 0.0]).1[0][0]);
        }
        Ok(Self {
            options,
            work: Work::new(),
            scratch: Scratch::default(),
            captured_q: Vec::new(),
            capture: false,
            history: Vec::new(),
            k_ref,
            face_width: scene.cycloid.face_width,
            ratio: scene.ratio(),
            mesh_period: mesh_period(scene),
            te_window: te_window(scene),
            friction: friction::FrictionLaws::new(scene),
            statics,
        })
    }

    /// Period of the mesh in crank angle \[rad\] (see [`mesh_period`]).
    pub fn mesh_period(&self) -> f64 {
        self.mesh_period
    }

    /// The crank-angle window after which the whole static state repeats \[rad\] (see
    /// [`te_window`]): the mesh period, or a multiple of it with roller bearings.
    pub fn te_window(&self) -> f64 {
        self.te_window
    }

    /// Transmission ratio input/output.
    pub fn ratio(&self) -> f64 {
        self.ratio
    }

    /// Force evaluations (static forces with their tangent) made so far (for benchmarks).
    pub fn evaluations(&self) -> usize {
        self.statics.evaluations
    }

    /// The unknowns of the last equilibrium found (empty before the first): angles \[rad\] and,
    /// with compliant joints, positions \[m\], laid out as in
    /// [`Statics::kinematic_unknowns`].
    pub fn last_unknowns(&self) -> &[f64] {
        self.history.first().map_or(&[], |s| &s.q)
    }

    /// Forget the warm start.
    pub fn reset(&mut self) {
        self.history.clear();
    }

    /// The equilibrium unknowns at `psi` and `torque`, warm-started from the last solution
    /// (its deflection carried to the new kinematic pose). Returns them with the report.
    pub(crate) fn solve_unknowns(
        &mut self,
        torque: f64,
        psi: f64,
    ) -> Result<(Vec<f64>, NewtonReport)> {
        require_finite("torque", torque)?;
        require_finite("crank angle", psi)?;
        let st = &mut self.statics;
        let kin = st.kinematic_unknowns(psi);
        let kin_here = kin.clone();
        // Warm start: the previous solutions' deflections from their kinematic poses carried to
        // this one; with two or three previous solutions along the same torque (or the same
        // crank angle), extrapolated by the polynomial through them in the crank angle (or the
        // torque).
        // The last solution's deflection carried unchanged: the second start where the
        // extrapolation lands off by more than the load (bodies floating in their clearances
        // at a light load; docs/model.md, "Newton iteration").
        let held: Option<Vec<f64>> = match self.history.as_slice() {
            [last, _, ..] => Some(
                kin.iter()
                    .zip(&last.deflection)
                    .map(|(a, b)| a + b)
                    .collect(),
            ),
            _ => None,
        };
        let mut q = predictor(&self.history, psi, torque, kin);
        let mut solve = |q: &mut [f64], second: Option<&[f64]>, options: &NewtonOptions| {
            equilibrium(
                st,
                psi,
                torque,
                q,
                second,
                self.k_ref,
                options,
                &mut self.work,
                &mut self.scratch,
                self.capture,
            )
        };
        let first = match solve(&mut q, held.as_deref(), &self.options) {
            Ok(r) => Ok(r),
            Err(e) if !self.history.is_empty() => {
                // A warm start from far away can be worse than the kinematic pose.
                let _ = e;
                let mut q2 = kin_here.clone();
                let r = solve(&mut q2, None, &self.options);
                if r.is_ok() {
                    q = q2;
                }
                r
            }
            Err(e) => Err(e),
        };
        let rep = match first {
            Ok(r) => r,
            Err(e) if !self.options.regularise_singular => {
                // Last, from the kinematic pose with the singular directions alone
                // regularised (a light load with bodies floating in their clearances, where
                // damping every direction stalls: BENCHMARKS.md section 10.4).
                let regularised = NewtonOptions {
                    regularise_singular: true,
                    ..self.options
                };
                let mut q3 = kin_here.clone();
                match solve(&mut q3, None, &regularised) {
                    Ok(r) => {
                        q = q3;
                        r
                    }
                    Err(_) => return Err(self.overlap_at_kinematic_pose(psi, torque, &kin_here, e)),
                }
            }
            Err(e) => return Err(self.overlap_at_kinematic_pose(psi, torque, &kin_here, e)),
        };
        if self.history.len() == HISTORY {
            self.history.pop();
        }
        self.history
            .insert(0, Solved::with_kinematic(psi, torque, q.clone(), &kin_here));
        Ok((q, rep))
    }

    /// `error`, or, where the contacts already overlap beyond the penetration bound at the
    /// kinematic pose `kin` (a negative `d_rrp`, a large `d_delta` or oversized pins: no torque
    /// resolves that), an error that says so. Newton's own message blames the torque or the
    /// clearances, which at the accepted limits of the modifications is the wrong advice.
    fn overlap_at_kinematic_pose(
        &mut self,
        psi: f64,
        torque: f64,
        kin: &[f64],
        error: RvdynError,
    ) -> RvdynError {
        let st = &mut self.statics;
        if st
            .eval_fresh(psi, kin, torque, &mut self.work, true)
            .is_err()
        {
            return error;
        }
        let (overlap, bound) = (st.max_penetration, st.model.max_penetration);
        if overlap <= bound {
            return error;
        }
        RvdynError::Convergence(format!(
            "at crank angle {psi} rad the contacts overlap by {overlap:.3e} m already at the \
             kinematic pose, beyond the bound of a tenth of the pin radius ({bound:.3e} m): the \
             profile modification (a negative cycloid.d_rrp or a large cycloid.d_delta) or the pin \
             errors make a disc that cannot be assembled with the pins; use modifications of tens \
             of micrometres"
        ))
    }

    /// The static equilibrium at crank angle `psi` \[rad\] under the output torque `torque`
    /// [N m]. Errors: non-finite input (`Parameter`); no equilibrium found or a penetration
    /// beyond a tenth of the pin radius (`Convergence`, naming the crank angle and residual).
    pub fn solve(&mut self, torque: f64, psi: f64) -> Result<LtcaPoint> {
        // The report reuses the contact state of Newton's evaluation at the solution.
        self.capture = true;
        let solved = self.solve_unknowns(torque, psi);
        self.capture = false;
        let (q, rep) = solved?;
        self.captured_q.clone_from(&q);
        self.point(torque, psi, &q, rep)
    }

    /// Equilibria at each crank angle in turn, each warm-started from the previous.
    ///
    /// A sweep of at least `2 * SWEEP_CHAIN` angles is cut into `len / SWEEP_CHAIN` chains of
    /// consecutive angles, solved in parallel: the first continues from the last solution,
    /// the others start from the kinematic pose. The cut depends on the number of angles only,
    /// so the results do not depend on the number of threads; they differ from one unbroken
    /// chain at the level of Newton's tolerance. A chain whose start from the kinematic pose
    /// fails is solved again as the continuation of the chain before it (the unbroken
    /// sweep). Afterwards the warm start is the last angle's solution.
    pub fn sweep(&mut self, torque: f64, crank_angles: &[f64]) -> Result<Vec<LtcaPoint>> {
        let n = crank_angles.len();
        let chains = (n / SWEEP_CHAIN).min(MAX_SWEEP_CHAINS);
        if chains < 2 {
            return self.sweep_chain(torque, crank_angles);
        }
        let part = |c: usize| &crank_angles[c * n / chains..(c + 1) * n / chains];
        let e0 = self.statics.evaluations;
        let mut solvers: Vec<Ltca> = (0..chains)
            .map(|c| {
                let mut l = self.clone();
                if c > 0 {
                    l.reset();
                }
                l
            })
            .collect();
        let results: Vec<Result<Vec<LtcaPoint>>> = solvers
            .par_iter_mut()
            .enumerate()
            .map(|(c, l)| l.sweep_chain(torque, part(c)))
            .collect();
        let mut evaluations = e0;
        let mut out = Vec::with_capacity(n);
        let mut prev: Option<Ltca> = None;
        for (c, (mut l, r)) in solvers.into_iter().zip(results).enumerate() {
            evaluations += l.statics.evaluations - e0;
            let pts = match (r, prev.take()) {
                (Ok(p), _) => p,
                (Err(_), Some(mut p)) => {
                    let before = p.statics.evaluations;
                    let r = p.sweep_chain(torque, part(c));
                    evaluations += p.statics.evaluations - before;
                    l = p;
                    match r {
                        Ok(pts) => pts,
                        Err(e) => {
                            *self = l;
                            self.statics.evaluations = evaluations;
                            return Err(e);
                        }
                    }
                }
                (Err(e), None) => {
                    *self = l;
                    self.statics.evaluations = evaluations;
                    return Err(e);
                }
            };
            out.extend(pts);
            prev = Some(l);
        }
        if let Some(l) = prev {
            *self = l;
        }
        self.statics.evaluations = evaluations;
        Ok(out)
    }

    /// [`Ltca::sweep`] as one chain.
    fn sweep_chain(&mut self, torque: f64, crank_angles: &[f64]) -> Result<Vec<LtcaPoint>> {
        crank_angles
            .iter()
            .map(|&p| self.solve(torque, p))
            .collect()
    }

    /// Output angle at equilibrium only (no contact details): the fast path of TE and loops.
    fn output_angle(&mut self, torque: f64, psi: f64) -> Result<(f64, f64)> {
        let (q, _) = self.solve_unknowns(torque, psi)?;
        let st = &self.statics;
        let x = st.full(psi, &q);
        let kin = -psi / st.zc();
        Ok((x[CARRIER], x[CARRIER] - kin))
    }

    /// Analytic torsional stiffness `dT / d(output angle)` [N m/rad] at the last equilibrium
    /// found: `1 / (K^-1)_00` (the output angle is unknown 0; the load enters as `-T e_0`).
    fn last_tangent_stiffness(&mut self) -> f64 {
        let mut k = self.work.k_last.clone();
        let mut e0 = vec![0.0; k.n];
        if k.n == 0 {
            return 0.0;
        }
        e0[0] = 1.0;
        if !solve_dense(&mut k, &mut e0) || e0[0] <= 0.0 {
            return 0.0;
        }
        1.0 / e0[0]
    }

    fn point(&mut self, torque: f64, psi: f64, q: &[f64], rep: NewtonReport) -> Result<LtcaPoint> {
        let st = &mut self.statics;
        let n = st.dim();
        // Newton's last evaluation is at the solution: its forces, its stiffness
        // (`work.k_last`) and its contact state, with fresh gaps of the pins the separation
        // bound skipped there (no force either way).
        let x = st.full(psi, q);
        let captured = std::mem::take(&mut self.captured_q);
        let (cs, mut k) = if captured.as_slice() == q {
            let mut cs = std::mem::take(&mut self.scratch.state);
            st.refresh_skipped_jets(&x, &mut cs)?;
            (cs, self.work.k_last.clone())
        } else {
            // Not the state Newton just captured (another caller's unknowns): evaluate afresh,
            // every pin queried.
            let (_, k, cs) = st.eval_fresh(psi, q, torque, &mut self.work, true)?;
            (cs, k)
        };
        let mut e0 = vec![0.0; n];
        e0[0] = 1.0;
        let stiff = if solve_dense(&mut k, &mut e0) && e0[0] > 0.0 {
            1.0 / e0[0]
        } else {
            0.0
        };
        let kin = st.kinematic_full(psi);
        let m = &st.model;
        let zp = m.pins.len();
        let e_star = match &m.pin_law {
            crate::contact::law::PinLaw::Line { pin, disc, .. } => effective_modulus(pin, disc),
            _ => effective_modulus(&Material::steel(), &Material::steel()),
        };
        let mut pins = Vec::with_capacity(m.discs.len());
        let mut loaded = Vec::new();
        // A pin counts as loaded above round-off: at zero torque the unmodified profile touches
        // pins with forces of 1e-15 N, which were counted (and exported for FEA).
        let loaded_above = LOADED_FRACTION * (torque.abs() / st.scale[0]).max(1.0);
        // Forces within the round-off floor of the force evaluation (Newton's, newton.rs) are
        // round-off, not contact: at zero torque the physical preset touched 7-8 pins per disc
        // with 1e-8 N, which were counted and exported for FEA. They are reported as 0.
        let round_off = 4.0 * f64::EPSILON * self.k_ref * st.scale[0];
        let mut rot = Vec::new();
        let mut angles = Vec::new();
        let mut disp = Vec::new();
        let mut pin_moment = 0.0;
        let max_pen = m.max_penetration;
        for (kd, _) in m.discs.iter().enumerate() {
            let dk = st.disc_index(kd);
            let th = x[dk + 2];
            let (s, c) = th.sin_cos();
            let to_disc = |v: [f64; 2]| [c * v[0] + s * v[1], -s * v[0] + c * v[1]];
            let mut row = Vec::with_capacity(zp);
            let mut count = 0;
            for j in 0..zp {
                let jet = &cs.pin_jet[kd * zp + j];
                let f = cs.pin_force[kd * zp + j];
                let f = if f > round_off { f } else { 0.0 };
                if -jet.gap > max_pen {
                    return Err(RvdynError::Convergence(format!(
                        "at crank angle {psi:.6} rad and torque {torque:.6e} N m pin {} on disc \
                         {kd} penetrates {:.3e} m, beyond a tenth of the pin radius: the contact \
                         law cannot carry this torque with the contact geometry intact; reduce \
                         the torque or use a stiffer contact law",
                        j + 1,
                        -jet.gap
                    )));
                }
                // Materials and face width are checked with the scene: the strip alone. No
                // strip for a conformal contact (no positive effective radius).
                let inv_r = 1.0 / m.pins[j].radius + 1.0 / jet.curvature_radius;
                let (hw, p0) = if f > 0.0 && inv_r.is_finite() && inv_r > 0.0 {
                    hertz_line_strip(f / self.face_width, 1.0 / inv_r, e_star)
                } else {
                    (0.0, 0.0)
                };
                if f > loaded_above {
                    count += 1;
                }
                // Moment about the reducer axis of the pin's force -f N on the disc.
                let point = [x[dk] + jet.arm[0], x[dk + 1] + jet.arm[1]];
                pin_moment -= f * (point[0] * jet.normal[1] - point[1] * jet.normal[0]);
                row.push(PinLoad {
                    force: f,
                    gap: jet.gap,
                    point: to_disc(jet.arm),
                    normal: to_disc(jet.normal),
                    half_width: hw,
                    peak_pressure: p0,
                });
            }
            pins.push(row);
            loaded.push(count);
            rot.push(th - kin[dk + 2]);
            angles.push(th);
            disp.push([x[dk] - kin[dk], x[dk + 1] - kin[dk + 1]]);
        }
        // The line law's location term acts on the discs too (its reaction on the pins).
        pin_moment += cs.pin_location_moment.iter().sum::<f64>();
        let input_torque = st.input_reaction(&self.work);
        // Relative to the torque at any torque (it used to be absolute below 1 N m, where the
        // light-load TE works); absolute \[N m\] at zero torque.
        let scale = if torque == 0.0 { 1.0 } else { torque.abs() };
        let balance = (input_torque - torque + pin_moment + cs.bearing_couple).abs() / scale;
        let input_angle = if m.mesh.is_some() {
            st.held_input(psi)
        } else {
            psi
        };
        let point = LtcaPoint {
            crank_angle: psi,
            torque,
            output_angle: x[CARRIER],
            input_angle,
            transmission_error: x[CARRIER] - input_angle / self.ratio,
            input_torque,
            pins,
            loaded_pins: loaded,
            disc_rotation: rot,
            disc_angle: angles,
            disc_displacement: disp,
            mesh_force: cs.mesh_force.clone(),
            crank_bearing_force: cs.crank_bearing_force.clone(),
            eccentric_bearing_force: cs.eccentric_bearing_force.clone(),
            crank_deflection: if st.bending.is_some() {
                (0..st.cranks)
                    .flat_map(|i| (0..m.discs.len()).map(move |k| (i, k)))
                    .map(|(i, k)| {
                        let n = st.node_index(i, k);
                        [x[n], x[n + 1]]
                    })
                    .collect()
            } else {
                Vec::new()
            },
            torque_balance: balance,
            residual: rep.residual,
            iterations: rep.iterations,
            torsional_stiffness: stiff,
        };
        // The contact state's buffers go back to Newton's scratch (no allocation at the next
        // capture).
        self.scratch.state = cs;
        Ok(point)
    }

    /// Transmission error over `periods` consecutive mesh periods from crank angle `start`
    /// \[rad\], at `points` crank angles per period, at `+-torque` (loaded) and, with `light`,
    /// at `+-light` (unloaded: a light load that keeps the flanks in contact, as in
    /// single-flank testing) [N m]; without it the unloaded curves are empty (and their
    /// extremes `None`). Each curve's extremes are located between the crank angles of each
    /// period ([`te_extremes`]) and are the largest and smallest over the periods.
    ///
    /// One period suffices where the whole static state repeats after it; with roller sets
    /// fixed in the frame it repeats only after [`Ltca::te_window`], a whole number of periods
    /// over which the TE differs from period to period (docs/model.md, "Mesh period").
    ///
    /// With `pin_loads`, the peak pin force and the fewest loaded pins of each loaded curve's
    /// equilibria are kept too ([`TePinLoads`]), which saves a [`Ltca::sweep`] at `+-torque`.
    ///
    /// Errors: `Parameter` for fewer than 2 points or no period, `Convergence` as
    /// [`Ltca::solve`].
    pub fn transmission_error(
        &mut self,
        torque: f64,
        light: Option<f64>,
        points: usize,
        start: f64,
        periods: usize,
        pin_loads: bool,
    ) -> Result<TransmissionError> {
        if periods == 0 {
            return Err(RvdynError::Parameter(
                "transmission error needs at least one mesh period".into(),
            ));
        }
        require_points("crank angles per period", points)?;
        require_points(
            "crank angles over the periods",
            points.saturating_mul(periods),
        )?;
        require_finite("start", start)?;
        // The TE is a scalar of a state that repeats (turned about the axis) every window:
        // solved from the start reduced into the first window, where the poses' angles are
        // small and Newton's round-off floor is that of the first turns; the crank angles
        // reported are the caller's.
        let shift = start - start.rem_euclid(self.te_window);
        let start = start - shift;
        // Each period as the one-period analysis from its own start (its sweeps from the
        // kinematic pose, its extremes located within it), then joined.
        let period = self.mesh_period;
        let mut all = self.te_one_period(torque, light, points, start, pin_loads)?;
        for k in 1..periods {
            let next =
                self.te_one_period(torque, light, points, start + k as f64 * period, pin_loads)?;
            all.join(next);
        }
        if shift != 0.0 {
            all.shift_crank_angles(shift);
        }
        Ok(all)
    }

    /// [`Ltca::transmission_error`] over the one mesh period from `start`.
    fn te_one_period(
        &mut self,
        torque: f64,
        light: Option<f64>,
        points: usize,
        start: f64,
        pin_loads: bool,
    ) -> Result<TransmissionError> {
        require_finite("start", start)?;
        if points < 2 {
            return Err(RvdynError::Parameter(format!(
                "transmission error needs at least 2 crank angles per period, got {points}"
            )));
        }
        let period = self.mesh_period;
        let step = period / points as f64;
        let angles: Vec<f64> = (0..points).map(|i| start + step * i as f64).collect();
        // One curve: the sweep, then its extremes refined between the crank angles.
        type Curve = (Vec<f64>, Option<CurveExtremes>, CurvePinLoads);
        let run = |ltca: &mut Ltca, t: Option<f64>, pins: bool| -> Result<Curve> {
            let Some(t) = t else {
                return Ok((Vec::new(), None, CurvePinLoads::default()));
            };
            ltca.reset();
            let mut loads = CurvePinLoads::default();
            // Newton's last evaluation at each solution keeps its contact state (as for a
            // report): the pin forces at the equilibrium.
            ltca.capture = pins;
            let samples = angles
                .iter()
                .map(|&p| {
                    let s = ltca.te_sample(t, p)?;
                    if pins {
                        let (peak, fewest) = ltca.captured_pin_summary();
                        loads.peak_force.push(peak);
                        loads.loaded_pins_min.push(fewest);
                    }
                    Ok(s)
                })
                .collect::<Result<Vec<_>>>();
            ltca.capture = false;
            let samples = samples?;
            let extremes = ltca.refine_extremes(t, &samples, step, period)?;
            Ok((
                samples.into_iter().map(|s| s.te).collect(),
                Some(extremes),
                loads,
            ))
        };
        // The four sweeps are independent (each starts from the kinematic pose): two chains
        // on two threads, each one loaded and one light sweep (the light ones cost several
        // times more), this analysis ending as after the light reverse sweep.
        let mut other = self.clone();
        let evaluations = self.statics.evaluations;
        let (t, l) = (torque.abs(), light.map(f64::abs));
        let p = pin_loads;
        let (a, b) = rayon::join(
            || -> Result<(Curve, Curve)> {
                Ok((run(&mut other, Some(t), p)?, run(&mut other, l, false)?))
            },
            || -> Result<(Curve, Curve)> {
                Ok((run(self, Some(-t), p)?, run(self, l.map(|v| -v), false)?))
            },
        );
        self.statics.evaluations += other.statics.evaluations - evaluations;
        let (
            ((forward, fe, fp), (unloaded_forward, ufe, _)),
            ((reverse, re, rp), (unloaded_reverse, ure, _)),
        ) = (a?, b?);
        let loaded = |e: Option<CurveExtremes>| {
            e.ok_or_else(|| RvdynError::Convergence("a loaded TE curve without extremes".into()))
        };
        Ok(TransmissionError {
            crank_angle: angles,
            period,
            periods: 1,
            forward,
            reverse,
            unloaded_forward,
            unloaded_reverse,
            extremes: TeExtremes {
                forward: loaded(fe)?,
                reverse: loaded(re)?,
                unloaded_forward: ufe,
                unloaded_reverse: ure,
            },
            torque: t,
            light: l.unwrap_or(0.0),
            pin_loads: pin_loads.then_some(TePinLoads {
                forward: fp,
                reverse: rp,
            }),
        })
    }

    /// Largest pin force \[N\] and fewest loaded pins on any disc in the contact state
    /// Newton captured at its last solution.
    fn captured_pin_summary(&self) -> (f64, usize) {
        let force = &self.scratch.state.pin_force;
        let zp = self.statics.model.pins.len();
        let peak = force.iter().fold(0.0f64, |m, f| m.max(*f));
        let fewest = force
            .chunks(zp.max(1))
            .map(|disc| disc.iter().filter(|f| **f > 0.0).count())
            .min()
            .unwrap_or(0);
        (peak, fewest)
    }

    /// The equilibrium at a torque `t` near zero (`|t|` far below `rated`): directly, or if
    /// that fails (bodies floating in their clearances make the start from the kinematic pose
    /// hard) by continuation from `1e-2 rated` on the same side down by factors of 10, each
    /// step warm-started from the last.
    fn solve_near_zero(
        &mut self,
        t: f64,
        psi: f64,
        rated: f64,
    ) -> Result<(Vec<f64>, NewtonReport)> {
        match self.solve_unknowns(t, psi) {
            Ok(r) => Ok(r),
            Err(e) => {
                self.reset();
                let mut level = 1e-2 * rated;
                while level > t.abs() * 10.0 {
                    self.solve_unknowns(level * t.signum(), psi)
                        .map_err(|_| e.clone())?;
                    level *= 0.1;
                }
                self.solve_unknowns(t, psi).map_err(|_| e)
            }
        }
    }

    /// The torque-twist loop at crank angle `psi` \[rad\]: `points` (at least 8) output torques
    /// [N m] along 0 -> +rated -> -rated -> 0 for the rated torque `rated` [N m] (its
    /// magnitude), with the output twists \[rad\], rigidity [N m/rad], lost motion and
    /// backlash \[rad\] (catalogue definitions, docs/model.md), with the scene's friction if it
    /// has any.
    pub fn twist_loop(&mut self, rated: f64, psi: f64, points: usize) -> Result<TwistLoop> {
        self.twist_loop_with(rated, psi, points, true)
    }

    /// The scene's friction laws as the LTCA applies them.
    pub fn friction_laws(&self) -> &friction::FrictionLaws {
        &self.friction
    }

    /// As [`Ltca::twist_loop`]; `friction = false` ignores the scene's friction (the closed
    /// loop of the frictionless reducer).
    pub fn twist_loop_with(
        &mut self,
        rated: f64,
        psi: f64,
        points: usize,
        friction: bool,
    ) -> Result<TwistLoop> {
        require_finite("crank angle", psi)?;
        // The loop's torques and twists are scalars of a state that repeats (turned about the
        // axis) every window: solved at the crank angle reduced into the first window, where
        // Newton's round-off floor is that of the first turns (at a few hundred radians it
        // failed at the loop's near-zero torques); reported at the caller's.
        let reduced = psi.rem_euclid(self.te_window);
        let mut out = self
            .twist_loop_reduced(rated, reduced, points, friction)
            .map_err(|e| match e {
                // The torque Newton names is the loop's own point next to zero, not the
                // caller's: say which, and what to raise.
                RvdynError::Parameter(m) if m.contains("too small to resolve") => {
                    RvdynError::Parameter(format!(
                        "the rated torque {:.3e} N m is too small for a torque-twist loop: its \
                         points next to zero torque, at {:.3e} N m (1e-7 of the rated torque, at \
                         least 1e-3 N m, at most 1 % of it), are below the smallest torque an \
                         equilibrium resolves; raise the rated torque to at least 100 times the \
                         smallest torque named here: {m}",
                        rated.abs(),
                        zero_side_torque(rated.abs())
                    ))
                }
                other => other,
            })?;
        out.crank_angle = psi;
        Ok(out)
    }

    fn twist_loop_reduced(
        &mut self,
        rated: f64,
        psi: f64,
        points: usize,
        friction: bool,
    ) -> Result<TwistLoop> {
        if friction && self.friction.any() {
            let laws = self.friction.clone();
            return self.twist_loop_with_friction(&laws, rated, psi, points);
        }
        let (torque, rated) = friction::loop_torques(rated, points)?;
        self.reset();
        // At zero torque the equilibrium is any pose inside the clearances: the loop takes the
        // limit along its branch (a torque of 1e-7 rated on the side it comes from; the elastic
        // twist at that torque is ~(1e-7)^(2/3) = 2e-5 of the rated one for Hertz contacts).
        let eps = zero_side_torque(rated);
        let mut side = 1.0;
        let sides: Vec<f64> = torque
            .iter()
            .map(|&t| {
                if t != 0.0 {
                    side = t.signum();
                }
                side
            })
            .collect();
        // Without friction the equilibrium at a torque does not depend on the path to it, so
        // the loop runs as two chains on two threads: its first part (0 -> +rated -> 0) in
        // order, and the rest (the negative torques) from its most loaded point outwards, each
        // point warm-started from its neighbour on the chain. The cut depends on the torques
        // only: the same results on any number of threads.
        let split = torque.iter().position(|&t| t < 0.0).unwrap_or(points);
        let point = |l: &mut Ltca, i: usize| -> Result<LoopPoint> {
            let t = torque[i];
            let ts = if t == 0.0 { sides[i] * eps } else { t };
            let (q, _) = if t == 0.0 {
                l.solve_near_zero(ts, psi, rated)?
            } else {
                l.solve_unknowns(ts, psi)?
            };
            let x = l.statics.full(psi, &q);
            Ok(LoopPoint {
                index: i,
                torque: ts,
                // Twist positive with positive torque: the load turns the output backwards.
                twist: -(x[CARRIER] + psi / l.statics.zc()),
                tangent: l.last_tangent_stiffness(),
                q,
            })
        };
        let mut other = self.clone();
        let evaluations = self.statics.evaluations;
        let (first, rest) = rayon::join(
            || -> Result<Vec<LoopPoint>> {
                // The first chain meets zero torque twice on the same side (start and middle).
                // Without friction the equilibrium there does not depend on the path (measured
                // on the physical preset: the two twists agree to 5e-17 rad), so the second is
                // the first: a solve with the bodies floating in their clearances, 150-300
                // force evaluations on the physical preset (BENCHMARKS.md section 11.1).
                let mut out: Vec<LoopPoint> = Vec::with_capacity(split);
                for i in 0..split {
                    let again = if torque[i] == 0.0 {
                        out.iter()
                            .find(|p| torque[p.index] == 0.0 && sides[p.index] == sides[i])
                            .cloned()
                    } else {
                        None
                    };
                    out.push(match again {
                        Some(p) => LoopPoint { index: i, ..p },
                        None => point(self, i)?,
                    });
                }
                Ok(out)
            },
            || -> Result<Vec<LoopPoint>> {
                let Some(peak) = (split..points)
                    .max_by(|&a, &b| torque[a].abs().total_cmp(&torque[b].abs()).then(b.cmp(&a)))
                else {
                    return Ok(Vec::new());
                };
                let mut out = vec![point(&mut other, peak)?];
                let at_peak = other.history.clone();
                for i in (split..peak).rev() {
                    out.push(point(&mut other, i)?);
                }
                other.history = at_peak;
                for i in peak + 1..points {
                    out.push(point(&mut other, i)?);
                }
                Ok(out)
            },
        );
        self.statics.evaluations += other.statics.evaluations - evaluations;
        let mut all = first?;
        all.extend(rest?);
        all.sort_by_key(|p| p.index);
        let twist: Vec<f64> = all.iter().map(|p| p.twist).collect();
        let tangent: Vec<f64> = all.iter().map(|p| p.tangent).collect();
        let solved: Vec<(f64, Vec<f64>)> = all.into_iter().map(|p| (p.torque, p.q)).collect();
        // The catalogue points, each warm-started from the loop point nearest in torque on the
        // same side of zero.
        let mut at = |t: f64| -> Result<f64> {
            self.reset();
            if let Some((t0, q0)) = solved
                .iter()
                .filter(|(s, _)| s.signum() == t.signum())
                .min_by(|a, b| (a.0 - t).abs().total_cmp(&(b.0 - t).abs()))
            {
                self.history = vec![Solved::new(&self.statics, psi, *t0, q0.clone())];
            }
            if t.abs() < 1e-6 * rated {
                self.solve_near_zero(t, psi, rated)?;
            }
            let (_, dev) = self.output_angle(t, psi)?;
            Ok(-dev)
        };
        let rigidity = 2.0 * rated / (at(rated)? - at(-rated)?);
        let lost_motion = at(0.03 * rated)? - at(-0.03 * rated)?;
        let backlash = at(eps)? - at(-eps)?;
        Ok(TwistLoop {
            crank_angle: psi,
            torque,
            twist,
            rated_torque: rated,
            rigidity,
            lost_motion,
            backlash,
            tangent_stiffness: tangent,
        })
    }
}

/// The torque [N m] at which a torque-twist loop takes its zero-torque points, on the side it
/// comes from: 1e-7 of the rated torque, but at least [`ZERO_SIDE_FLOOR`]. Below about 1e-5 N m
/// the bodies floating in their clearances no longer settle against them (a 1 N m loop's
/// backlash came out half the clearances' twist); at 1e-3 N m the elastic approach of a roller or
/// line contact is about 1e-11 m, nothing against micrometre clearances.
pub(crate) fn zero_side_torque(rated: f64) -> f64 {
    (1e-7 * rated).max(ZERO_SIDE_FLOOR).min(0.01 * rated)
}

/// The smallest torque of a loop's zero-torque points [N m]: they are taken at 1e-7 of the
/// rated torque, but at least this and at most 1 % of the rated torque.
pub const ZERO_SIDE_FLOOR: f64 = 1e-3;

/// The crank-angle period after which the whole contact pattern repeats \[rad\].
///
/// Turning the crank by `2 pi / zp` turns the disc by `-2 pi / (zp zc)`; the assembly then is
/// the old one rotated by `2 pi / zp` about the axis (pin `j` takes the place of pin `j - 1`)
/// with the disc turned by one lobe pitch `-2 pi / zc`, which the profile cannot tell. So with
/// identical pins the pattern repeats every `2 pi / zp` of crank angle (both discs at once:
/// their phases only shift the pattern). Pin errors make pins distinguishable: a pin returns to
/// the same lobe position only after the shift is a whole number of rings, `2 pi` of crank
/// angle. A disc profile error makes the lobes distinguishable: the turned assembly matches
/// only when the disc has turned by the same whole-ring angle, after `2 pi zc / zp` of crank
/// angle (`2 pi zc` with pin errors too, or with assembly errors). An IMPACT mesh law does not vary
/// with the tooth position; the ISO 6336 stiffness varies with the mesh position
/// `s = r_bs (th_s - th_c)` with the period of one base pitch,
/// which the held sun passes every `2 pi zc / (z_planet zp)` of crank angle
/// (`th_s - th_c = -(z_planet / z_sun)(1 + 1/zc) psi` with the input held): the pattern then
/// repeats after the least common multiple of both periods, counted in units of
/// `2 pi / (z_planet zp)`. Gear runout and pitch errors repeat only after a whole turn of the
/// sun relative to the carrier (`z_sun zc` units) or of a planet (`z_planet zc` units): the
/// window is then the least common multiple with those too.
pub fn mesh_period(scene: &Scene) -> f64 {
    // (The two forms round as the period always has.)
    match mesh_period_turns(scene) {
        (n, d, true) => TAU / d as f64 * n as f64,
        (n, d, false) => TAU * n as f64 / d as f64,
    }
}

/// [`mesh_period`] as a fraction `(numerator, denominator)` of a turn, and whether it is
/// counted in units of `2 pi / (z_planet zp)`.
fn mesh_period_turns(scene: &Scene) -> (u64, u64, bool) {
    let e = &scene.pin_errors;
    let errors =
        e.position.iter().any(|p| p[0] != 0.0 || p[1] != 0.0) || e.radius.iter().any(|r| *r != 0.0);
    let zp = u64::from(scene.cycloid.pins);
    // Whole pin pitches (of 2 pi / zp crank angle) after which the pattern repeats.
    let lobes = scene.discs.iter().any(|d| {
        d.profile_error
            .as_ref()
            .is_some_and(|p| !p.harmonics.is_empty() || !p.table.is_empty())
    });
    // Assembly errors make the cranks distinguishable: the carrier must return, after
    // `2 pi zc` of crank angle (which also brings back the disc and the pins).
    let pitches = match (errors, lobes) {
        _ if scene.errors.any() => zp * (zp - 1),
        (false, false) => 1,
        (true, false) => zp,
        (false, true) => zp - 1,
        (true, true) => zp * (zp - 1),
    };
    let pins = (pitches, zp, false);
    // The ISO law's stiffness varies with the tooth position, and so does tooth friction (the
    // sliding speed changes along the path of contact) with any mesh law.
    let iso = matches!(
        scene.contact.mesh,
        crate::dynamics::scene::ContactLawSpec::Iso6336 { .. }
    ) || scene.friction.mesh > 0.0;
    // Gear errors repeat after whole turns of the sun and planets (gear_errors.rs).
    let gear_units = gear_errors::period_units(scene);
    match (&scene.stage1, iso || gear_units > 1) {
        (Some(st), true) => {
            let zpl = u64::from(st.z_planet);
            let pin_units = zpl * pitches;
            let mesh_units = gear_errors::lcm(if iso { zp - 1 } else { 1 }, gear_units);
            // Units of `2 pi / (z_planet zp)`.
            (gear_errors::lcm(pin_units, mesh_units), zpl * zp, true)
        }
        _ => pins,
    }
}

/// The crank-angle window \[rad\] after which the whole static state repeats: the
/// [`mesh_period`], extended by the roller sets of roller bearings and, for bearings with
/// radial clearance, to a whole pin pitch of the carrier (`2 pi zc / zp` of crank angle). The static models keep
/// each roller set fixed in the frame (cage angle 0), so the reducer at `psi + w` must be the
/// one at `psi` turned about the axis (with the carrier, by `w / zc`) by a multiple of
/// `2 pi / Z` for every set of `Z` rollers: `w` a multiple of `2 pi zc / Z`. The window is the
/// least common multiple of the mesh period and these, as fractions of a turn
/// (`lcm(a/b, c/d) = lcm(a, c) / gcd(b, d)` in lowest terms). Physical preset: 23/24, 23/20
/// and 23/26 of a turn give 23/2, 72.26 rad, twelve mesh periods, which
/// [`Ltca::transmission_error`] covers when asked for that many periods (docs/model.md, "Mesh
/// period").
pub fn te_window(scene: &Scene) -> f64 {
    let (n, d, _) = mesh_period_turns(scene);
    let mut w = reduced((n, d));
    if let crate::dynamics::scene::Joints::Compliant {
        eccentric_bearing,
        crank_bearing,
    } = &scene.joints
    {
        let zc = u64::from(scene.cycloid.pins) - 1;
        let zp = u64::from(scene.cycloid.pins);
        let extend = |w: (u64, u64), (e, f): (u64, u64)| {
            reduced((gear_errors::lcm(w.0, e), gear_errors::gcd(w.1, f)))
        };
        for b in std::iter::once(eccentric_bearing).chain(crank_bearing.as_ref()) {
            if let Some(r) = &b.rollers {
                w = extend(w, reduced((zc, u64::from(r.count))));
            }
            // A clearance makes the load sharing among the cranks depend on where the crank
            // seats stand against the pins, which repeats only when the carrier has turned by a
            // pin pitch, `w / zc = 2 pi / zp`: an outside review measured the TE of the paper
            // scene with 50 um clearances 0.14-1.8 arcsec apart one mesh period on. Linear
            // bearings without clearance repeat after one period (to 1e-6 arcsec).
            if b.clearance > 0.0 {
                w = extend(w, reduced((zc, zp)));
            }
        }
    }
    if w == reduced((n, d)) {
        return mesh_period(scene);
    }
    TAU * w.0 as f64 / w.1 as f64
}

/// The fraction `n / d` in lowest terms.
fn reduced((n, d): (u64, u64)) -> (u64, u64) {
    let g = gear_errors::gcd(n, d).max(1);
    (n / g, d / g)
}

#[cfg(test)]
mod tests;
