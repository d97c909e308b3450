//! One pin against one disc in a given pose: the exact penetration, normal and contact point.
//! Shared by the rigid- and compliant-joint models.

use crate::contact::law::{LawForce, PinLaw, PinSite};
use crate::contact::line_contact::PinDiscLawBase;
use crate::dynamics::model::parts::{DiscModel, PinModel};
use crate::error::{Result, RvdynError};
use crate::geometry::gap::{FootOrOpen, small_sin_cos};
use std::cell::Cell;

/// Where a disc is: centre \[m\], angle \[rad\] and the angle's sine and cosine (computed once per
/// disc, not once per pin).
#[derive(Debug, Clone, Copy)]
pub(crate) struct DiscPose {
    pub(crate) centre: [f64; 2],
    pub(crate) angle: f64,
    pub(crate) sin: f64,
    pub(crate) cos: f64,
}

impl DiscPose {
    pub(crate) fn new(centre: [f64; 2], angle: f64) -> Self {
        let (sin, cos) = angle.sin_cos();
        Self {
            centre,
            angle,
            sin,
            cos,
        }
    }
}

/// The foot parameter of a (disc, pin) contact at the previous evaluation, with its cosine and
/// sine: the Newton warm start of the next one.
#[derive(Debug, Clone, Copy)]
pub(crate) struct WarmStart {
    pub(crate) phi: f64,
    /// The kinematic parameter (pin angle minus disc angle) at that evaluation.
    pub(crate) kinematic: f64,
    pub(crate) cos_sin: [f64; 2],
    /// `ln F` of the line law's force at that evaluation (its inversion's warm start; NaN
    /// when unknown).
    pub(crate) ln_force: f64,
    /// Signed gap \[m\] at that evaluation (`+inf` before the first).
    pub(crate) gap: f64,
    /// The gap at the last accepted step end ([`mark_open`]): a pin open there that touches
    /// at the next evaluation closed within the step.
    pub(crate) marked_gap: f64,
}

/// The depth \[m\] a first touch may reach within one integrator step under `law`: the IMPACT
/// law's damping ramp `d` (a step that closes deeper jumps the damping from 0 to `cmax`, the
/// failure a ramp exists to prevent). `None` for laws whose force and damping rise
/// continuously from zero approach (the line law), where the error estimate covers first touch.
pub(crate) fn first_touch_allowance(law: &PinLaw) -> Option<f64> {
    match law {
        PinLaw::Impact(l) => Some(l.damping_depth),
        PinLaw::Line { .. } => None,
    }
}

/// [`deepest_first_touch`] for a model's law, with the pin named as in its errors.
pub(crate) fn first_touch_report(
    seeds: &[Cell<WarmStart>],
    law: &PinLaw,
    pins_per_disc: usize,
) -> Option<(f64, String)> {
    let allowed = first_touch_allowance(law)?;
    let (r, i) = deepest_first_touch(seeds, allowed)?;
    Some((
        r,
        format!(
            "pin {} on disc {} (first touch {:.3e} m deep, its law's damping ramp is {:.3e} m)",
            i % pins_per_disc + 1,
            i / pins_per_disc,
            r * allowed,
            allowed
        ),
    ))
}

/// Remember which pins are open at the state just evaluated (an integrator's accepted step).
pub(crate) fn mark_open(seeds: &[Cell<WarmStart>]) {
    for w in seeds {
        let mut ws = w.get();
        ws.marked_gap = ws.gap;
        w.set(ws);
    }
}

/// The deepest first touch since [`mark_open`], over `allowed` \[m\]: the largest penetration of
/// a pin open at the mark and touching at the last evaluation, divided by `allowed`, with the
/// pin's index (disc-major, as the seeds). `None` if no pin closed.
pub(crate) fn deepest_first_touch(seeds: &[Cell<WarmStart>], allowed: f64) -> Option<(f64, usize)> {
    let mut worst: Option<(f64, usize)> = None;
    for (i, w) in seeds.iter().enumerate() {
        let ws = w.get();
        if ws.marked_gap > 0.0 && ws.gap < 0.0 {
            let r = -ws.gap / allowed;
            if worst.is_none_or(|(b, _)| r > b) {
                worst = Some((r, i));
            }
        }
    }
    worst
}

impl Default for WarmStart {
    /// No warm start yet (never within reach of a kinematic seed).
    fn default() -> Self {
        Self {
            phi: f64::NAN,
            kinematic: f64::NAN,
            cos_sin: [1.0, 0.0],
            ln_force: f64::NAN,
            gap: f64::INFINITY,
            marked_gap: f64::INFINITY,
        }
    }
}

/// A pin in contact with a disc (fixed frame, SI).
#[derive(Debug, Clone, Copy)]
pub(crate) struct PinContact {
    /// Penetration \[m\] (> 0).
    pub(crate) penetration: f64,
    /// Unit outward profile normal (from the disc towards the pin).
    pub(crate) normal: [f64; 2],
    /// Contact point on the profile relative to the disc centre \[m\].
    pub(crate) arm: [f64; 2],
    /// Curve parameter of the contact on the profile \[rad\] (for laws that need the local
    /// curvature).
    pub(crate) phi: f64,
    /// With a profile error `delta(phi)`: the derivatives of its share of the penetration,
    /// `delta'(phi) dphi/dO` [-] (fixed frame) and `delta'(phi) dphi/dtheta` [m/rad].
    pub(crate) error_gradient: Option<([f64; 2], f64)>,
}

impl PinContact {
    /// Rate of the profile error's share of the penetration for the disc centre velocity
    /// `ov` [m/s] and angular speed `w` [rad/s] (0 without an error).
    #[inline]
    pub(crate) fn error_rate(&self, ov: [f64; 2], w: f64) -> f64 {
        self.error_gradient
            .map_or(0.0, |(go, gt)| go[0] * ov[0] + go[1] * ov[1] + gt * w)
    }
}

impl PinContact {
    /// `arm x normal` (z): the lever of the normal about the disc centre \[m\].
    #[inline]
    pub(crate) fn lever(&self) -> f64 {
        self.arm[0] * self.normal[1] - self.arm[1] * self.normal[0]
    }
}

/// Exact signed contact of `pin` with `disc` at `pose`: `penetration = -gap`, negative when
/// they do not touch.
///
/// Newton starts from `warm` (the foot parameter this pin had at the previous evaluation) when
/// it is within 0.05 rad of the kinematic parameter (pin angle minus disc angle), else from the
/// kinematic parameter; the parry polyline is the fallback seed. The answer does not depend on
/// the seed (Newton converges to 1e-13 m on the exact curve): the warm start only saves
/// iterations. `warm` is updated.
#[cfg(test)]
pub(crate) fn pin_query(
    disc: &DiscModel,
    pin: &PinModel,
    pose: &DiscPose,
    t: f64,
    labels: (usize, usize),
    warm: &Cell<WarmStart>,
) -> Result<PinContact> {
    match pin_query_or_open(disc, pin, pose, t, labels, warm, false)? {
        PinQuery::Contact(c) => Ok(c),
        PinQuery::Open(_) => Err(RvdynError::Simulation(
            "a pin query without the open test found the pin open".into(),
        )),
    }
}

/// What [`pin_query_or_open`] found: the exact contact, or a pin shown open with a lower
/// bound of its gap \[m\].
pub(crate) enum PinQuery {
    Contact(PinContact),
    Open(f64),
}

/// The exact pin query (as `pin_query`), or [`PinQuery::Open`] with a lower bound of the gap
/// when `open_test` is set and the pin is shown open at the seed, from its last exact gap
/// carried along the disc's rotation
/// ([`crate::geometry::CycloidGeometry::contact_foot_or_open`]: the seed is the last foot
/// turned with the disc, and the pin keeps its place relative to a conjugate profile, so the
/// test stays tight while the disc moves farther than the gap, where [`SeparationBound`]
/// cannot skip). The warm start then moves to the seed and keeps its gap (a lower bound is all
/// the test needs). Rigid profiles only: the caller sets `open_test` only without profile
/// errors.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(crate) fn pin_query_or_open(
    disc: &DiscModel,
    pin: &PinModel,
    pose: &DiscPose,
    t: f64,
    labels: (usize, usize),
    warm: &Cell<WarmStart>,
    open_test: bool,
) -> Result<PinQuery> {
    let g = &disc.geometry;
    let (centre, angle, s, c) = (pose.centre, pose.angle, pose.sin, pose.cos);
    let dp = [pin.centre[0] - centre[0], pin.centre[1] - centre[1]];
    let local = g.remove_rotation_mod([c * dp[0] + s * dp[1], -s * dp[0] + c * dp[1]]);
    let kinematic = pin.angle - angle - g.params().d_delta;
    let w = warm.get();
    // The foot moves with the disc's rotation (the kinematic parameter) plus a slowly varying
    // offset from the deflection: seed with the kinematic parameter plus the last offset, and
    // turn the kept cos/sin by the change instead of evaluating them.
    let turn = kinematic - w.kinematic;
    let (seed, cs) = if turn.abs() < 0.01 && (w.phi - w.kinematic).abs() < 0.05 {
        let (ds, dc) = small_sin_cos(turn);
        let [c0, s0] = w.cos_sin;
        (w.phi + turn, [c0 * dc - s0 * ds, s0 * dc + c0 * ds])
    } else {
        let (s, c) = kinematic.sin_cos();
        (kinematic, [c, s])
    };
    let r_gen = g.generating_pin_radius();
    // The last exact gap as a signed distance from the pin-centre curve, and the distance
    // beyond which the pin is open (with a round-off allowance).
    let probe = (open_test && w.gap > OPEN_SLACK && w.gap.is_finite())
        .then_some((w.gap + pin.radius - r_gen, pin.radius - r_gen + OPEN_SLACK));
    let found = g.contact_foot_or_open(local, seed, cs, probe);
    if let Some(FootOrOpen::Open(lower)) = found {
        warm.set(WarmStart {
            phi: seed,
            kinematic,
            cos_sin: cs,
            ..w
        });
        return Ok(PinQuery::Open(lower + r_gen - pin.radius - OPEN_SLACK));
    }
    let foot = found.and_then(|f| match f {
        FootOrOpen::Foot(f) => Some(f),
        FootOrOpen::Open(_) => None,
    });
    let foot = foot.ok_or_else(|| {
        // In a run this means the state is unphysical, so it is a simulation failure.
        RvdynError::Simulation(format!(
            "exact gap of pin {} on disc {} not found at t = {t:.6e} s: the disc is farther \
             from its kinematic pose than the profile's radius of curvature; either the run has \
             gone unstable (reduce the step dt or the tolerances) or the contact is too soft for \
             the load (raise the contact stiffness)",
            labels.1 + 1,
            labels.0
        ))
    })?;
    let mut gap = foot.dist + r_gen - pin.radius;
    // Profile error: the ground profile offset by delta(phi) along its normal shrinks the gap
    // by delta at the foot (first order); the foot moves with the disc, so the penetration's
    // gradient gets delta'(phi) dphi/dq (docs/model.md#manufacturing-errors-of-profile-and-gears).
    let error_gradient = disc.profile_error.as_ref().map(|pe| {
        let (delta, slope) = pe.offset(foot.phi);
        gap -= delta;
        let j = g.jet(foot.phi);
        let gp = j.d1[0] * j.d1[0]
            + j.d1[1] * j.d1[1]
            + (j.c[0] - local[0]) * j.d2[0]
            + (j.c[1] - local[1]) * j.d2[1];
        let t = g.apply_rotation_mod(j.d1);
        let t_global = [c * t[0] - s * t[1], s * t[0] + c * t[1]];
        let zxp = [-local[1], local[0]];
        // gp > 0 at a distance minimum (the foot); guard the degenerate case.
        let k = if gp > 0.0 { slope / gp } else { 0.0 };
        (
            [-k * t_global[0], -k * t_global[1]],
            -k * (j.d1[0] * zxp[0] + j.d1[1] * zxp[1]),
        )
    });
    warm.set(WarmStart {
        phi: foot.phi,
        kinematic,
        cos_sin: foot.cos_sin,
        ln_force: w.ln_force,
        gap,
        marked_gap: w.marked_gap,
    });
    let nl = g.apply_rotation_mod(foot.normal);
    let pl = g.apply_rotation_mod([
        foot.centre_point[0] - r_gen * foot.normal[0],
        foot.centre_point[1] - r_gen * foot.normal[1],
    ]);
    Ok(PinQuery::Contact(PinContact {
        penetration: -gap,
        normal: [c * nl[0] - s * nl[1], s * nl[0] + c * nl[1]],
        arm: [c * pl[0] - s * pl[1], s * pl[0] + c * pl[1]],
        phi: foot.phi,
        error_gradient,
    }))
}

/// Round-off allowance of the open test of [`pin_query_or_open`] \[m\] (the seed's curve point
/// and normal carry about 1e-16 of the pin circle radius).
const OPEN_SLACK: f64 = 1e-12;

/// The error raised when a penetration exceeds the physical bound.
pub(crate) fn penetration_error(t: f64, pen: f64, bound: f64, what: &str) -> RvdynError {
    RvdynError::Simulation(format!(
        "penetration {pen:.3e} m of {what} at t = {t:.6e} s exceeds the physical bound \
         {bound:.3e} m (a tenth of the pin radius, the model's bound for every contact): in a run, either the motion has gone unstable \
         (reduce the step dt or the tolerances; with an explicit integrator, use the implicit \
         integrator=\"generalized-alpha\"), the load is too heavy for the start (a speed step \
         against a large load inertia: start the drive with a ramp, drive.start = \"ramp\"), or \
         the contact is too soft for the load (raise the contact stiffness); for a given state, \
         the pose is not one the reducer can take"
    ))
}

/// The last exact gap of one (disc, pin) pair and the disc pose it was computed at. Moving a
/// disc by `dO` and turning it by `dth` moves every profile point by at most
/// `|dO| + reach |dth|` (`reach`: the largest distance of a profile point from the disc
/// centre), and the gap by no more, the pins being fixed: while `gap - that > 0` the pin cannot
/// touch and its exact query is skipped. The answer is the same as without skipping (tested
/// for both models). Used by both models.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SeparationBound {
    pub(crate) centre: [f64; 2],
    pub(crate) angle: f64,
    pub(crate) gap: f64,
}

impl Default for SeparationBound {
    /// No bound yet: the first evaluation queries.
    fn default() -> Self {
        Self {
            centre: [0.0; 2],
            angle: 0.0,
            gap: f64::NEG_INFINITY,
        }
    }
}

impl SeparationBound {
    /// Whether the pin provably cannot touch the disc at centre `o` \[m\], angle `th` \[rad\].
    #[inline]
    pub(crate) fn separated(&self, o: [f64; 2], th: f64, reach: f64) -> bool {
        let (dx, dy) = (o[0] - self.centre[0], o[1] - self.centre[1]);
        let moved = (dx * dx + dy * dy).sqrt() + reach * (th - self.angle).abs();
        self.gap > moved
    }
}

/// One (disc, pin) pair as both models evaluate it: the separation skip (when `separation` is
/// given), the exact query, the bound update and the penetration check (when `max_penetration`
/// is given). `Ok(None)` when the pin does not touch.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(crate) fn touching_pin(
    disc: &DiscModel,
    pin: &PinModel,
    pose: &DiscPose,
    t: f64,
    labels: (usize, usize),
    warm: &Cell<WarmStart>,
    separation: Option<(&Cell<SeparationBound>, f64)>,
    max_penetration: Option<f64>,
) -> Result<Option<PinContact>> {
    if let Some((bound, reach)) = separation
        && bound.get().separated(pose.centre, pose.angle, reach)
    {
        return Ok(None);
    }
    // The open test only where the pose-based bound is kept (rigid profiles); either answer
    // renews that bound at this pose (a pin shown open with its gap's lower bound).
    let (pc, gap) = match pin_query_or_open(disc, pin, pose, t, labels, warm, separation.is_some())?
    {
        PinQuery::Contact(pc) => {
            let gap = -pc.penetration;
            (Some(pc), gap)
        }
        PinQuery::Open(lower) => (None, lower),
    };
    if let Some((bound, _)) = separation {
        bound.set(SeparationBound {
            centre: pose.centre,
            angle: pose.angle,
            gap,
        });
    }
    let Some(pc) = pc else {
        return Ok(None);
    };
    if pc.penetration <= 0.0 {
        return Ok(None);
    }
    let pen = pc.penetration;
    if let Some(bound) = max_penetration
        && (pen.is_nan() || pen >= bound)
    {
        let what = format!("pin {} on disc {}", labels.1 + 1, labels.0);
        return Err(penetration_error(t, pen, bound, &what));
    }
    Ok(Some(pc))
}

/// The force of `law` on a touching pin at `site` (approach `pen` \[m\], rate `rate` [m/s]), as
/// [`PinLaw::evaluate`]; a line law's inversion starts from the `ln F` this pin had at the
/// previous evaluation (kept in `warm`), which saves Newton iterations and not accuracy. With
/// `prepared`, `(base, ln body depth, curvature of the pin-centre curve at the contact)`, the
/// line law is built from its prepared part ([`PinLaw::evaluate_warm`]).
#[inline]
pub(crate) fn pin_law_force(
    law: &PinLaw,
    pen: f64,
    rate: f64,
    site: &PinSite<'_>,
    want_energy: bool,
    warm: &Cell<WarmStart>,
    prepared: Option<(&PinDiscLawBase, f64, f64)>,
) -> Result<LawForce> {
    if let PinLaw::Impact(_) = law {
        return law.evaluate(pen, rate, site, want_energy);
    }
    let mut ws = warm.get();
    let (lf, ln_f) = law.evaluate_warm(pen, rate, site, want_energy, ws.ln_force, prepared)?;
    ws.ln_force = ln_f;
    warm.set(ws);
    Ok(lf)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::hertz::Material;
    use crate::contact::law::{ContactDamping, DampingSpec};
    use crate::geometry::CycloidGeometry;
    use crate::geometry::cycloid::CycloidParams;

    /// The models' line law (checked once, inversion warm-started from the pin's last `ln F`)
    /// gives the force of the fully checked `PinLaw::evaluate` to 1e-14 relative, from any
    /// earlier force (none, far below, far above, the previous one), over the profile and from
    /// 1e-9 m to 1e-4 m of approach; so does the compliant model's law built from its
    /// prepared part.
    #[test]
    fn warm_started_line_law_gives_the_checked_force() {
        let g = CycloidGeometry::new(CycloidParams::paper()).unwrap();
        let s = Material::steel();
        let damping = ContactDamping::new(&DampingSpec::DampingRatio {
            ratio: 0.05,
            frequency: 1000.0,
        })
        .unwrap();
        let law = PinLaw::Line {
            pin: s,
            disc: s,
            damping,
        };
        let warm = Cell::new(WarmStart::default());
        for i in 0..40 {
            let phi = 0.2 * i as f64 / 23.0;
            let site = PinSite {
                geometry: &g,
                phi,
                pin_radius: 0.010,
                depth: 0.14,
            };
            for pen in [1e-9, 3e-7, 2.59e-5, 1e-4] {
                let want = law.evaluate(pen, 1e-3, &site, true).unwrap();
                for guess in [f64::NAN, 0.0, 30.0, warm.get().ln_force] {
                    let mut w = warm.get();
                    w.ln_force = guess;
                    warm.set(w);
                    let same = |got: LawForce, what: &str| {
                        for (a, b) in [
                            (got.force, want.force),
                            (got.elastic, want.elastic),
                            (got.energy, want.energy),
                        ] {
                            assert!(
                                (a - b).abs() <= 1e-14 * b.abs(),
                                "{what} {phi} {pen} {guess}: {a} {b}"
                            );
                        }
                    };
                    same(
                        pin_law_force(&law, pen, 1e-3, &site, true, &warm, None).unwrap(),
                        "warm",
                    );
                    assert!((warm.get().ln_force - want.elastic.ln()).abs() < 1e-13);
                    // The compliant model's prepared law: the same force to 1e-14 (its
                    // curvature from the curve derivatives, the law from the pin's base).
                    let base = PinDiscLawBase::new(0.010, g.params().face_width, &s, &s);
                    let d = crate::contact::pin_tangent::centre_curve_derivatives(&g, phi);
                    let kc = crate::contact::pin_tangent::curvature_derivatives_of(&d)[0];
                    let mut w = warm.get();
                    w.ln_force = guess;
                    warm.set(w);
                    let prepared = (&base, site.depth.ln(), kc);
                    let got = pin_law_force(&law, pen, 1e-3, &site, true, &warm, Some(prepared));
                    same(got.unwrap(), "prepared");
                }
            }
        }
    }
}
