//! Tests of the quasi-static friction of the LTCA (module `friction`).

use super::*;
use crate::analysis::ltca::LtcaPoint;
use crate::dynamics::scene::Friction;

fn rated() -> f64 {
    Scene::paper("rated").unwrap().load.torque(0.0)
}

fn with_friction(mut s: Scene, pin: f64, mesh: f64) -> Scene {
    s.friction = Friction {
        pin,
        mesh,
        ..Friction::default()
    };
    s
}

/// The paper's reducer without its first stage, rigid joints (cranks held), IMPACT pins.
fn single_stage() -> Scene {
    let mut s = Scene::paper("rated").unwrap();
    s.stage1 = None;
    s
}

/// `S = sum over loaded pins of N |arm . n|` [N m] at an equilibrium (disc frame; the dot
/// product does not depend on the frame).
fn pin_friction_lever_sum(p: &LtcaPoint) -> f64 {
    p.pins
        .iter()
        .flatten()
        .map(|l| l.force * (l.point[0] * l.normal[0] + l.point[1] * l.normal[1]).abs())
        .sum()
}

/// With the friction solver and zero coefficients the loop, rigidity, lost motion and
/// backlash are today's frictionless ones to 1e-12 (rad, relative for the rigidity): the
/// friction path adds nothing when there is no friction (the stick logic included).
#[test]
fn zero_friction_gives_the_closed_loop() {
    let mut modified = Scene::paper("rated").unwrap();
    modified.joints = crate::dynamics::model::compliant::default_joints();
    modified.cycloid.d_rrp = 2e-5;
    modified.cycloid.d_rp = -2e-5;
    for s in [Scene::physical("rated").unwrap(), modified] {
        let mut ltca = Ltca::new(&s).unwrap();
        let a = ltca.twist_loop(rated(), 0.1, 21).unwrap();
        let none = FrictionLaws::none(&s);
        assert!(!none.any());
        let b = ltca
            .twist_loop_with_friction(&none, rated(), 0.1, 21)
            .unwrap();
        for (x, y) in a.twist.iter().zip(&b.twist) {
            assert!((x - y).abs() < 1e-12, "{x} {y}");
        }
        assert!((a.rigidity / b.rigidity - 1.0).abs() < 1e-12);
        assert!((a.lost_motion - b.lost_motion).abs() < 1e-12);
        assert!((a.backlash - b.backlash).abs() < 1e-12);
        // A frictional scene with friction switched off is the same closed loop.
        let f = with_friction(s.clone(), 0.05, 0.05);
        let c = Ltca::new(&f)
            .unwrap()
            .twist_loop_with(rated(), 0.1, 21, false)
            .unwrap();
        assert_eq!(a, c);
    }
}

/// Closed form of the friction moment, single stage with rigid joints (cranks held): the
/// disc centres stay put and the discs turn with the carrier, so pin `j` slips by
/// `(arm . n) d theta` and its friction `mu lambda N_j` has the moment `mu lambda N_j |arm . n|`
/// against the rotation. At the same pose (same normal forces) loading and unloading differ in
/// torque by exactly `2 mu lambda S`, `S = sum N_j |arm_j . n_j|` over both discs. So the
/// unloading equilibrium at `T_L - 2 mu lambda S` (S from the loading pose) must have the
/// loading twist at `T_L`: asserted to 1e-9 of it (Newton solves to 1e-12 of the load; the
/// twist's sensitivity to the torque is the compliance, ~1e-10 rad per N m here). Pin rolling
/// (lambda = 0.5) checks the lever ratio.
#[test]
fn loading_and_unloading_differ_by_the_closed_form_friction_torque() {
    let mut s = with_friction(single_stage(), 0.08, 0.0);
    s.friction.pin_rolling = Some(0.5);
    let laws = FrictionLaws::new(&s);
    assert_eq!(laws.pin, 0.04);
    let mut ltca = Ltca::new(&s).unwrap();
    for (psi, frac) in [(0.0, 1.0), (0.11, 0.5), (0.3, 0.2)] {
        let tl = frac * rated();
        let (ql, rep) = ltca.solve_friction(&laws, tl, psi, 1.0, None).unwrap();
        assert!(rep.iterations <= 6, "{} iterations", rep.iterations);
        let pl = ltca.point(tl, psi, &ql, rep).unwrap();
        let sum = pin_friction_lever_sum(&pl);
        let tu = tl - 2.0 * laws.pin * sum;
        let (qu, _) = ltca.solve_friction(&laws, tu, psi, -1.0, None).unwrap();
        let rel = (qu[0] - ql[0]).abs() / (ql[0] + psi / ltca.statics.zc()).abs();
        eprintln!(
            "closed form: psi {psi} twist differs by {rel:e}, {} iterations",
            rep.iterations
        );
        assert!(rel < 1e-9, "psi {psi}: twist differs by {rel:e}");
        // The hysteresis torque is a few per cent of the load (mu lambda 0.04).
        let h = 2.0 * laws.pin * sum / tl;
        assert!(h > 0.02 && h < 0.2, "{h}");
    }
}

/// Loop width against the first-order estimate `2 mu S / k` (S as above from the frictionless
/// LTCA at the same torque, `k` its tangent torsional stiffness): the branches are
/// `phi0 -+ mu S / k + O(mu^2)`, and the second-order terms of both branches cancel in the
/// width to within their difference, measured 0.3 % at mu = 0.05; asserted 1 %.
#[test]
fn loop_width_is_the_friction_torque_over_the_stiffness() {
    let s = with_friction(single_stage(), 0.05, 0.0);
    let mut ltca = Ltca::new(&s).unwrap();
    let lp = ltca.twist_loop(rated(), 0.0, 41).unwrap();
    // Loop points 5 (loading, 0.5 T_r) and 15 (unloading, 0.5 T_r).
    assert!((lp.torque[5] - 0.5 * rated()).abs() < 1e-6 && lp.torque[5] == lp.torque[15]);
    let width = lp.twist[15] - lp.twist[5];
    let p = ltca.solve(0.5 * rated(), 0.0).unwrap();
    let est = 2.0 * 0.05 * pin_friction_lever_sum(&p) / p.torsional_stiffness;
    eprintln!(
        "loop width {width:e} estimate {est:e}: {:e}",
        width / est - 1.0
    );
    assert!(
        (width / est - 1.0).abs() < 0.01,
        "width {width:e} estimate {est:e}"
    );
    // Open: every unloading point (beyond the stick at the tip) above the loading one.
    for i in 1..10 {
        assert!(lp.twist[20 - i] > lp.twist[i], "point {i}");
    }
}

/// Reversing the torque mirrors the loop with friction too: at crank angle 0 the physical
/// preset is its own mirror image (see `reversing_the_torque_mirrors_the_result`), so the
/// branch from `-T_r` back to 0 is the point reflection of the branch from `+T_r` to 0. The
/// two are solved independently at mirrored poses: asserted to 1e-9 of the rated twist.
/// Newton converges in a few iterations at every point (never NaN).
#[test]
fn friction_loop_is_point_symmetric() {
    let s = with_friction(Scene::physical("rated").unwrap(), 0.05, 0.05);
    let mut ltca = Ltca::new(&s).unwrap();
    let lp = ltca.twist_loop(rated(), 0.0, 41).unwrap();
    let tip = lp.twist[10];
    let worst = (0..=10).fold(0.0f64, |m, i| {
        m.max((lp.twist[10 + i] + lp.twist[30 + i]).abs())
    });
    eprintln!("point symmetry: {:e} of the tip twist", worst / tip);
    for i in 0..=10 {
        let (a, b) = (lp.twist[10 + i], lp.twist[30 + i]);
        assert!((a + b).abs() < 1e-9 * tip, "point {i}: {a:e} {b:e}");
    }
    assert!(lp.twist.iter().all(|v| v.is_finite()));
    // Opens: the unloading branch at half the rated torque lies above the loading one.
    assert!(lp.twist[15] - lp.twist[5] > 1e-3 * tip);
    for (t, d) in [
        (0.5 * rated(), 1.0),
        (0.5 * rated(), -1.0),
        (-rated(), -1.0),
    ] {
        let laws = ltca.friction_laws().clone();
        let (_, rep) = ltca.solve_friction(&laws, t, 0.3, d, None).unwrap();
        eprintln!("physical friction Newton: {rep:?}");
        assert!(rep.iterations <= 6 && rep.residual.is_finite(), "{rep:?}");
    }
}

/// Bad input: a friction coefficient outside [0, 1] is refused by the scene, a non-finite or
/// zero rated torque by the loop, with messages naming the field.
#[test]
fn bad_input_is_a_clear_error() {
    let mut s = with_friction(Scene::physical("rated").unwrap(), 1.5, 0.0);
    let e = Ltca::new(&s).unwrap_err();
    assert!(e.to_string().contains("friction.pin"), "{e}");
    s.friction.pin = 0.05;
    let mut ltca = Ltca::new(&s).unwrap();
    for (t, n) in [(f64::NAN, 21), (0.0, 21), (1e4, 3)] {
        let e = ltca.twist_loop(t, 0.0, n).unwrap_err();
        assert!(matches!(e, RvdynError::Parameter(_)), "{e}");
    }
    let e = ltca.twist_loop(1e4, f64::INFINITY, 21).unwrap_err();
    assert!(matches!(e, RvdynError::Parameter(_)), "{e}");
}

/// The quasi-static efficiency of a running sweep with pin friction against the power balance
/// of the running reducer (`analysis::efficiency`, Malhotra and Parameswaran 1983): relative to
/// the pins the disc turns at `1/zc` per unit crank angle about the pitch point, so pin `j`
/// slides at `(rp S_j - rrp) / zc` (`efficiency::pin_sliding_arm`) and, per unit crank angle,
/// `|T_in| = |T| / |i| + mu lambda sum N_j (rp S_j - rrp) / zc`, i.e. (single stage,
/// `|i| = zc`) `eta = 1 / (1 + mu lambda sum N_j (rp S_j - rrp) / |T|)`, with the normal forces
/// `N_j` of the frictional equilibrium. The LTCA finds the input torque from the equilibrium
/// of forces instead; the two agree up to the deformation (the loaded pose is not the
/// kinematic one: ~2e-3 rad of twist, relative changes of the arms of that order). Measured
/// 1.4e-3 and 2.8e-3 of the loss (eta 0.9252 at rated, mu 0.05); asserted 1 % of it. Both drive directions (forward at `+T` with the crank
/// angle decreasing, reverse at `-T` increasing) give the same efficiency by the mirror
/// symmetry, and the same within 1e-9 at mirrored crank angles.
#[test]
fn running_efficiency_is_the_power_balance_of_the_sliding() {
    use crate::analysis::efficiency::pin_sliding_arm;
    use crate::geometry::CycloidGeometry;
    let s = with_friction(single_stage(), 0.05, 0.0);
    let laws = FrictionLaws::new(&s);
    let g = CycloidGeometry::new(s.cycloid).unwrap();
    let mut ltca = Ltca::new(&s).unwrap();
    let i = ltca.ratio().abs();
    let zc = ltca.statics.zc();
    assert!((i - zc).abs() < 1e-12);
    let mut etas = Vec::new();
    for (t, psi) in [(rated(), 0.13), (-rated(), -0.13), (0.5 * rated(), 0.05)] {
        let r = ltca.friction_sweep(&laws, t, &[psi]).unwrap();
        let (_, tin) = r[0];
        let eta = (t / (ltca.ratio() * tin)).abs();
        // The frictional equilibrium's pin forces (sliding the running way).
        let drive = if t < 0.0 { 1.0 } else { -1.0 };
        let (q, _) = ltca.solve_unknowns(t, psi).unwrap();
        let xp = ltca.statics.kinematic_full(psi + 1e-6);
        let xm = ltca.statics.kinematic_full(psi - 1e-6);
        let dir: Vec<f64> = xp
            .iter()
            .zip(&xm)
            .map(|(a, b)| drive * (a - b) / 2e-6)
            .collect();
        let e0 = ltca.eval_friction(&laws, psi, t, &q, None).unwrap();
        let (qf, rep, tin2) = ltca.newton_friction(&laws, t, psi, q, &e0.cs, dir).unwrap();
        assert!((tin2 / tin - 1.0).abs() < 1e-9, "{tin2} {tin}");
        let p = ltca.point(t, psi, &qf, rep).unwrap();
        let mut slide = 0.0;
        for (k, disc) in s.discs.iter().enumerate() {
            for j in 0..24 {
                let phi = g.pin_angle(j) - (psi + disc.phase);
                slide += p.pins[k][j].force * pin_sliding_arm(&s.cycloid, phi);
            }
        }
        let loss = laws.pin * slide / t.abs();
        let eta_closed = 1.0 / (1.0 + loss);
        eprintln!(
            "eta LTCA {eta} closed form {eta_closed}: {:e} of the loss",
            (1.0 / eta - 1.0) / loss - 1.0
        );
        assert!(
            ((1.0 / eta - 1.0) / loss - 1.0).abs() < 0.01,
            "{eta} {eta_closed}"
        );
        assert!(eta < 1.0 && eta > 0.85);
        etas.push(eta);
    }
    assert!((etas[0] - etas[1]).abs() < 1e-9, "{etas:?}");
}

#[test]
fn the_loop_passes_through_its_tips_at_any_point_count() {
    // With 10 points the tip used to be 0.89 rated (the steps were equal over the whole loop).
    for points in 8..60 {
        let (t, rated) = super::loop_torques(-2.0, points).unwrap();
        assert_eq!((t.len(), rated), (points, 2.0));
        assert_eq!((t[0], t[points - 1]), (0.0, 0.0));
        assert!(t.contains(&2.0) && t.contains(&-2.0), "{points}: {t:?}");
        assert_eq!(t.iter().filter(|v| **v == 0.0).count(), 3, "{points}");
    }
    // 4k + 1 points: the equal steps of before.
    let (t, _) = super::loop_torques(1.0, 9).unwrap();
    assert_eq!(t, [0.0, 0.5, 1.0, 0.5, 0.0, -0.5, -1.0, -0.5, 0.0]);
}
