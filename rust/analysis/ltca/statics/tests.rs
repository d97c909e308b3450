use super::*;
use crate::dynamics::model::compliant::CompliantModel;
use crate::dynamics::run::sink::NoSink;
use crate::dynamics::scene::{ProfileError, Scene};
use crate::solve::MechanicalSystem;

fn rng(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed;
    move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as f64) / ((1u64 << 53) as f64) - 0.5
    }
}

fn scenes() -> Vec<Scene> {
    let mut out = Vec::new();
    let base = Scene::paper("rated").unwrap();
    out.push(base.clone());
    let mut m = base.clone();
    m.cycloid.d_rrp = 2e-5;
    m.cycloid.d_rp = -2e-5;
    m.stage1.as_mut().unwrap().backlash = 2e-5;
    out.push(m.clone());
    let mut c = m.clone();
    c.joints = crate::dynamics::model::compliant::default_joints();
    out.push(c.clone());
    let mut c2 = c.clone();
    if let Joints::Compliant {
        eccentric_bearing, ..
    } = &mut c2.joints
    {
        eccentric_bearing.clearance = 5e-6;
    }
    out.push(c2.clone());
    let mut c3 = c2.clone();
    if let Joints::Compliant { crank_bearing, .. } = &mut c3.joints {
        *crank_bearing = None;
    }
    out.push(c3);
    let mut single = base.clone();
    single.stage1 = None;
    out.push(single.clone());
    let mut single_c = single;
    single_c.joints = crate::dynamics::model::compliant::default_joints();
    out.push(single_c);
    out.extend(physical_scenes());
    // Disc profile errors (harmonics and a table) at rigid and compliant joints.
    let mut pe = m.clone();
    with_profile_errors(&mut pe);
    out.push(pe.clone());
    pe.joints = crate::dynamics::model::compliant::default_joints();
    out.push(pe);
    // Assembly errors (compliant joints only), with compliant and rigid crank bearings.
    let mut ae = c.clone();
    with_assembly_errors(&mut ae);
    out.push(ae.clone());
    if let Joints::Compliant { crank_bearing, .. } = &mut ae.joints {
        *crank_bearing = None;
    }
    out.push(ae);
    out
}

/// Assembly errors of a few um (and a few 1e-4 rad of phase) on every crank, hole and seat.
fn with_assembly_errors(s: &mut Scene) {
    let n = s.cranks as usize;
    let nd = s.discs.len();
    let e = &mut s.errors;
    e.crank_eccentricity = (0..n).map(|i| 2e-6 * (i as f64 - 0.7)).collect();
    e.crank_phase = (0..n).map(|i| 3e-4 * (1.0 - i as f64)).collect();
    e.disc_holes = (0..n * nd)
        .map(|j| [1e-6 * (j as f64 - 2.0), -1.5e-6 + 0.7e-6 * j as f64])
        .collect();
    e.carrier_seats = (0..n).map(|i| [-2e-6 + 1e-6 * i as f64, 1.5e-6]).collect();
}

/// Disc profile errors of a few um on both discs: harmonics of several orders and a
/// periodic table on disc 0. The 1 um waviness of order 400 on disc 1 makes the
/// `delta'' grad phi grad phi^T` term of the tangent visible to the central-difference
/// test (without it that test fails at 5e-6 > 1e-6; at the lower orders the term is
/// ~1e-6 of the contact stiffness).
fn with_profile_errors(s: &mut Scene) {
    s.discs[0].profile_error = Some(ProfileError {
        harmonics: vec![[3e-6, 23.0, 0.4], [2e-6, 2.0, 1.0]],
        table: vec![[0.0, 1e-6], [2.0, -1e-6], [4.0, 5e-7]],
    });
    s.discs[1].profile_error = Some(ProfileError {
        harmonics: vec![[2e-6, 46.0, 1.3], [1e-6, 1.0, 0.0], [1e-6, 400.0, 0.2]],
        table: vec![],
    });
}

/// The physical preset (line law, ISO mesh, roller bearings with clearance), modified,
/// with rigid crank bearings, and with rigid joints.
fn physical_scenes() -> Vec<Scene> {
    let mut out = Vec::new();
    let base = Scene::physical("rated").unwrap();
    out.push(base.clone());
    let mut m = base.clone();
    m.cycloid.d_rrp = 2e-5;
    m.cycloid.d_rp = -2e-5;
    m.stage1.as_mut().unwrap().backlash = 2e-5;
    out.push(m.clone());
    let mut c = m.clone();
    if let Joints::Compliant { crank_bearing, .. } = &mut c.joints {
        *crank_bearing = None;
    }
    out.push(c);
    let mut r = m;
    r.joints = Joints::Rigid;
    out.push(r.clone());
    // Line law with disc profile errors, compliant and rigid joints.
    let mut pe = base.clone();
    with_profile_errors(&mut pe);
    out.push(pe);
    with_profile_errors(&mut r);
    out.push(r);
    // Roller bearings with assembly errors.
    let mut ae = base.clone();
    with_assembly_errors(&mut ae);
    out.push(ae);
    out
}

/// A loaded-looking pose: the kinematic one plus random deflections of the size the
/// rated load gives (tens of um at the pins).
fn perturbed(st: &Statics, psi: f64, rnd: &mut impl FnMut() -> f64) -> Vec<f64> {
    let mut q = st.kinematic_unknowns(psi);
    for (a, v) in q.iter_mut().enumerate() {
        *v += 2e-5 * rnd() / st.scale[a] + if a == 0 { -3e-4 } else { 0.0 };
    }
    q
}

#[test]
fn static_forces_are_the_models_forces_at_rest() {
    // The static evaluation and the dynamic models' force evaluation (v = 0) agree. A
    // torque drive (of 0 N m) makes the input free, so that every body is at rest.
    let mut rnd = rng(3);
    for mut scene in scenes() {
        scene.drive = crate::dynamics::scene::Drive::Torque {
            torque: 0.0,
            ramp_time: 0.0,
        };
        let mut st = Statics::new(&scene).unwrap();
        let n = st.dim();
        let mut r = vec![0.0; n];
        let mut k = Dense::zeros(n);
        let mut work = Work::new();
        let torque = scene.load.torque(0.0);
        for _ in 0..5 {
            let psi = 6.0 * rnd();
            let q = perturbed(&st, psi, &mut rnd);
            st.eval(psi, &q, torque, &mut r, &mut k, &mut work, None)
                .unwrap();
            let x = st.full(psi, &q);
            // Model forces on the same full state at rest.
            let (model_q, free): (Vec<f64>, Vec<usize>) = match scene.joints {
                Joints::Rigid => {
                    let m = RigidModel::new(&scene).unwrap();
                    let xr = [x[CARRIER], x[st.crank_index(0) + 2], x[SUN]];
                    let f = m.forces(0.0, &xr, &[0.0; 3], &mut NoSink).unwrap();
                    let free = if m.mesh.is_some() {
                        vec![0, 1]
                    } else {
                        vec![0]
                    };
                    (f.q.to_vec(), free)
                }
                Joints::Compliant { .. } => {
                    let m = CompliantModel::new(&scene).unwrap();
                    let qfree: Vec<f64> = m.free.iter().map(|&i| x[i]).collect();
                    let mut a = vec![0.0; qfree.len()];
                    let mut p = [0.0; 3];
                    m.eval(0.0, &qfree, &vec![0.0; qfree.len()], &mut a, &mut p)
                        .unwrap();
                    let _ = &mut a;
                    let mut full = vec![0.0; x.len()];
                    for (kk, &i) in m.free.iter().enumerate() {
                        full[i] = a[kk] * m.mass[i];
                    }
                    let free: Vec<usize> = (0..st.unknowns.len()).map(|u| st.unknowns[u]).collect();
                    (full, free)
                }
            };
            let scale = r
                .iter()
                .zip(&st.scale)
                .map(|(v, l)| (v / l).abs())
                .fold(torque / 0.15, f64::max);
            for (a, &i) in free.iter().enumerate() {
                let diff = (r[a] - model_q[i]).abs() / st.scale[a];
                assert!(
                    diff < 1e-11 * scale,
                    "{:?} unknown {a}: static {} model {}",
                    scene.joints,
                    r[a],
                    model_q[i]
                );
            }
        }
    }
}

/// The analytic tangent equals the dynamic model's own finite-difference tangent
/// (`ReducerModel::tangent`, one-sided steps of about 1 nm) of its force evaluation, at
/// loaded states at rest (torque drive, so that every body is free and at rest; pin
/// approaches of tens of um; poses with a contact within 1 um of touching are skipped).
/// One-sided differences of a Hertz-type law are wrong by about `h F'' / (2 F')` =
/// `h / (4 x)` (relative) at an approach `x` (measured: 2e-5): 1e-4 of the largest entry
/// (N/m after scaling angles by rp) is asserted. At this tolerance the test ties the
/// analytic tangent to the model's force evaluation but cannot see the geometric term
/// `F hess g` (a flipped sign of it still passes); the central-difference test below, at
/// 1e-6 on the same forces, does fail for that mutation.
#[test]
fn tangent_matches_the_models_finite_difference_tangent() {
    use crate::dynamics::model::ReducerModel;
    let mut scene = Scene::paper("rated").unwrap();
    scene.cycloid.d_rrp = 1e-5;
    scene.joints = crate::dynamics::model::compliant::default_joints();
    scene.drive = crate::dynamics::scene::Drive::Torque {
        torque: 0.0,
        ramp_time: 0.0,
    };
    let mut st = Statics::new(&scene).unwrap();
    let model = CompliantModel::new(&scene).unwrap();
    let nf = st.full_len();
    let mut rnd = rng(17);
    let mut tested = 0;
    for _ in 0..500 {
        if tested == 3 {
            break;
        }
        let psi = 3.0 * rnd();
        let mut q = st.kinematic_unknowns(psi);
        q[0] -= 5e-4;
        let x = st.full(psi, &q);
        let mut qf = vec![0.0; nf];
        let mut kf = Dense::zeros(nf);
        let mut cs = ContactState::default();
        st.exact = true;
        st.full_forces(&x, 0.0, &mut qf, &mut kf, Some(&mut cs))
            .unwrap();
        // Near first touch one-sided differences of a Hertz law are wrong (see above).
        if cs.pin_gap.iter().any(|g| g.abs() < 1e-6) {
            continue;
        }
        tested += 1;
        let free: Vec<usize> = model.free.clone();
        let qm: Vec<f64> = free.iter().map(|&i| x[i]).collect();
        let (k_fd, _) = model.tangent(0.0, &qm, &vec![0.0; qm.len()]).unwrap();
        let len = |i: usize| {
            if i == CARRIER || i == SUN || (i >= 2 && (i - 2) % 3 == 2) {
                0.15
            } else {
                1.0
            }
        };
        let mut kmax: f64 = 0.0;
        for (a, &i) in free.iter().enumerate() {
            for (b, &j) in free.iter().enumerate() {
                kmax = kmax.max((k_fd[(a, b)] / (len(i) * len(j))).abs());
            }
        }
        let mut worst: f64 = 0.0;
        for (a, &i) in free.iter().enumerate() {
            for (b, &j) in free.iter().enumerate() {
                let d = (kf.at(i, j) - k_fd[(a, b)]).abs() / (len(i) * len(j));
                worst = worst.max(d / kmax);
            }
        }
        assert!(worst < 1e-4, "analytic vs model FD tangent: {worst:e}");
    }
    assert_eq!(tested, 3);
}

/// Skipping pins that provably cannot touch changes no force or stiffness: along a loaded
/// sweep, the skipping evaluator and one that queries every pin agree to round-off (also
/// with disc profile errors, where the bound keeps `gap - max |delta|`).
#[test]
fn skipping_separated_pins_gives_the_same_forces() {
    let mut scene = Scene::paper("rated").unwrap();
    scene.cycloid.d_rrp = 2e-5;
    scene.cycloid.d_rp = -2e-5;
    scene.joints = crate::dynamics::model::compliant::default_joints();
    let mut with_errors = scene.clone();
    with_profile_errors(&mut with_errors);
    for scene in [scene, with_errors] {
        let mut skipping = Statics::new(&scene).unwrap();
        let mut fresh = Statics::new(&scene).unwrap();
        fresh.skip = false;
        let n = skipping.dim();
        let (mut r1, mut r2) = (vec![0.0; n], vec![0.0; n]);
        let (mut k1, mut k2) = (Dense::zeros(n), Dense::zeros(n));
        let mut work = Work::new();
        let mut rnd = rng(5);
        let mut worst: f64 = 0.0;
        let mut skipped = 0;
        for i in 0..200 {
            let psi = 0.002 * i as f64;
            let mut q = skipping.kinematic_unknowns(psi);
            q[0] -= 2e-4 + 1e-5 * rnd();
            let mut cs = ContactState::default();
            skipping
                .eval(psi, &q, 4e4, &mut r1, &mut k1, &mut work, Some(&mut cs))
                .unwrap();
            fresh
                .eval(psi, &q, 4e4, &mut r2, &mut k2, &mut work, None)
                .unwrap();
            for a in 0..n {
                worst = worst.max((r1[a] - r2[a]).abs() / skipping.scale[a]);
                for b in 0..n {
                    worst = worst.max((k1.at(a, b) - k2.at(a, b)).abs() * 1e-9);
                }
            }
            skipped = skipping.skipped;
        }
        assert!(worst == 0.0, "skipping changes the forces by {worst:e}");
        assert!(skipped > 1000, "{skipped}");
    }
}

/// `eval_fresh` with `every_pin` gives exactly the evaluation of a model that never skips
/// a pin (residual, tangent and every pin's gap), also right after evaluations that
/// skipped pins, and leaves the skip setting as it was; without it, the gaps of skipped
/// pins are their last exact ones.
#[test]
fn fresh_evaluation_of_every_pin_equals_a_non_skipping_one() {
    let mut scene = Scene::paper("rated").unwrap();
    scene.cycloid.d_rrp = 2e-5;
    scene.cycloid.d_rp = -2e-5;
    scene.joints = crate::dynamics::model::compliant::default_joints();
    let mut skipping = Statics::new(&scene).unwrap();
    let mut never = Statics::new(&scene).unwrap();
    never.skip = false;
    let n = skipping.dim();
    let (mut r, mut k) = (vec![0.0; n], Dense::zeros(n));
    let mut work = Work::new();
    let psi = 0.1;
    let mut q = skipping.kinematic_unknowns(psi);
    q[0] -= 2e-4;
    skipping
        .eval(psi, &q, 4e4, &mut r, &mut k, &mut work, None)
        .unwrap();
    q[0] -= 1e-7;
    let skipped_before = skipping.skipped;
    let (r1, k1, cs1) = skipping.eval_fresh(psi, &q, 4e4, &mut work, true).unwrap();
    assert_eq!(skipping.skipped, skipped_before, "no pin skipped");
    assert!(!skipping.exact);
    let (r2, k2, cs2) = never.eval_fresh(psi, &q, 4e4, &mut work, false).unwrap();
    assert_eq!(r1, r2);
    assert_eq!(k1.a, k2.a);
    assert_eq!(cs1.pin_gap, cs2.pin_gap);
    // Without every_pin the skip applies again.
    q[0] -= 1e-7;
    skipping.eval_fresh(psi, &q, 4e4, &mut work, false).unwrap();
    assert!(skipping.skipped > skipped_before);
}

/// The tangent stiffness equals central differences of the static forces.
///
/// Step h = 1e-9 m of each unknown (h / length for angles). Near first touch a Hertz-type
/// law `k x^1.5` makes central differences of its stiffness wrong by `h^2 / (24 x^2)`
/// (relative), so poses with a contact within 1e-6 m of touching are skipped: then that
/// error is below 4e-8, and round-off (gaps to ~3e-17 m, times stiffnesses ~1e9 N/m,
/// over h) is ~3e-8 of the stiffness. Asserted: 1e-6 relative to the largest entry
/// (scaled to N/m). (The analytic value is also the limit of the differences as h -> 0:
/// their error falls as h^2 from h = 1e-6 to 1e-9 m.)
#[test]
fn tangent_matches_finite_differences_of_the_forces() {
    let mut rnd = rng(11);
    for scene in scenes() {
        assert_tangent_matches_differences(&scene, &mut rnd);
    }
}

/// Scenes with bending crankshafts (`crank_shaft`): the paper scene with compliant joints and
/// clearance, and the physical preset with its roller bearings, the two discs 40 mm apart
/// between bearings 120 mm apart on a 45 mm shaft.
fn bending_scenes() -> Vec<Scene> {
    let mut out: Vec<Scene> = vec![scenes()[3].clone(), Scene::physical("rated").unwrap()];
    for s in &mut out {
        crate::test_util::with_bending_cranks(s);
        s.validate().unwrap();
    }
    out
}

/// The crankshafts' bending terms (the beam's stiffness and the eccentric bearings' coupling to
/// the eccentrics' deflections) against central differences of the static forces, as above.
#[test]
fn tangent_with_bending_cranks_matches_finite_differences() {
    let mut rnd = rng(12);
    for scene in bending_scenes() {
        assert!(Statics::new(&scene).unwrap().bending.is_some());
        assert_tangent_matches_differences(&scene, &mut rnd);
    }
}

/// Asserts that the analytic tangent of `scene`'s static forces equals their central
/// differences (step 1e-9 m) at four perturbed poses away from first touch, to 1e-6 of the
/// largest entry.
fn assert_tangent_matches_differences(scene: &Scene, rnd: &mut impl FnMut() -> f64) {
    {
        let mut st = Statics::new(scene).unwrap();
        let n = st.dim();
        let torque = scene.load.torque(0.0);
        let mut work = Work::new();
        let mut worst: f64 = 0.0;
        let mut tested = 0;
        let backlash = scene.stage1.as_ref().map_or(0.0, |s| s.backlash);
        while tested < 4 {
            let psi = 6.0 * rnd();
            let q = perturbed(&st, psi, rnd);
            let mut r = vec![0.0; n];
            let mut k = Dense::zeros(n);
            let mut cs = ContactState::default();
            st.eval(psi, &q, torque, &mut r, &mut k, &mut work, Some(&mut cs))
                .unwrap();
            let near_touch = |g: f64| g.abs() < 1e-6;
            if cs.pin_gap.iter().any(|g| near_touch(*g))
                || cs
                    .mesh_deflection
                    .iter()
                    .any(|d| near_touch(d.abs() - 0.5 * backlash))
            {
                continue;
            }
            tested += 1;
            let mut kmax: f64 = 0.0;
            for a in 0..n {
                for b in 0..n {
                    kmax = kmax.max((k.at(a, b) / (st.scale[a] * st.scale[b])).abs());
                }
            }
            let h = 1e-9;
            for b in 0..n {
                let mut qp = q.clone();
                let mut qm = q.clone();
                qp[b] += h / st.scale[b];
                qm[b] -= h / st.scale[b];
                let mut rp = vec![0.0; n];
                let mut rm = vec![0.0; n];
                let mut scratch = Dense::zeros(n);
                st.eval(psi, &qp, torque, &mut rp, &mut scratch, &mut work, None)
                    .unwrap();
                st.eval(psi, &qm, torque, &mut rm, &mut scratch, &mut work, None)
                    .unwrap();
                for a in 0..n {
                    // K = -dQ/dq, scaled to N/m.
                    let fd = -(rp[a] - rm[a]) / (2.0 * h) / st.scale[a];
                    let an = k.at(a, b) / (st.scale[a] * st.scale[b]);
                    worst = worst.max((fd - an).abs() / kmax);
                }
            }
        }
        assert!(worst < 1e-6, "{:?}: K vs FD {worst:e}", scene.joints);
    }
}

/// The roller bearings' analytic static tangent and damping matrix against central
/// differences of their force (`BearingLaw::load`): in the deflection (step 1e-10 m) and
/// in the rate (step 1e-6 m/s; the damping is linear in the rate, so exact to round-off).
/// Deflections where a roller is within 1e-7 m of first touch are skipped: there the
/// difference of `Q = K delta^(10/9)` errs by `0.0165 h^2 / delta^2` (relative), below 2e-8
/// elsewhere; round-off ~1e-16 F / h ~ 1e-7 of the stiffness. Asserted 1e-6 of the
/// largest entry.
#[test]
fn roller_bearing_tangent_matches_finite_differences() {
    let scene = Scene::physical("rated").unwrap();
    let Joints::Compliant {
        eccentric_bearing,
        crank_bearing,
    } = &scene.joints
    else {
        panic!("physical joints are compliant")
    };
    let mut rnd = rng(41);
    for spec in [eccentric_bearing, crank_bearing.as_ref().unwrap()] {
        let law = BearingLaw::new(spec).unwrap();
        let BearingLaw::Rollers { bearing, .. } = &law else {
            panic!("rollers expected")
        };
        let z = bearing.rollers();
        let mut tested = 0;
        while tested < 30 {
            let d = [3e-5 * rnd(), 3e-5 * rnd()];
            let near = (0..z).any(|j| {
                let a = TAU * j as f64 / z as f64;
                (d[0] * a.cos() + d[1] * a.sin() - bearing.clearance()).abs() < 1e-7
            });
            if near || d[0].hypot(d[1]) < bearing.clearance() + 2e-6 {
                continue;
            }
            tested += 1;
            let (g, h) = law.static_tangent(d);
            let c = law.damping_matrix(d);
            let f0 = law.load(d, [0.0; 2]).force;
            assert_eq!(g, [-f0[0], -f0[1]]);
            let hmax = h.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
            let cmax = c.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
            for k in 0..2 {
                let (mut a, mut b) = (d, d);
                a[k] += 1e-10;
                b[k] -= 1e-10;
                let (fa, fb) = (law.load(a, [0.0; 2]).force, law.load(b, [0.0; 2]).force);
                let mut va = [0.0; 2];
                va[k] = 1e-6;
                let (ra, rb) = (law.load(d, va).force, law.load(d, [-va[0], -va[1]]).force);
                for r in 0..2 {
                    let fd = -(fa[r] - fb[r]) / 2e-10;
                    assert!(
                        (fd - h[r][k]).abs() < 1e-6 * hmax,
                        "K {r}{k}: {fd} {}",
                        h[r][k]
                    );
                    let fdc = -(ra[r] - rb[r]) / 2e-6;
                    assert!(
                        (fdc - c[r][k]).abs() < 1e-6 * cmax,
                        "C {r}{k}: {fdc} {}",
                        c[r][k]
                    );
                }
            }
        }
    }
}
