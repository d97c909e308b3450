#![allow(clippy::needless_range_loop)]

use super::*;
use crate::analysis::classical_pin_forces;
use crate::dynamics::model::compliant::default_joints;
use crate::dynamics::scene::{ContactLawSpec, Joints};
use crate::geometry::CycloidGeometry;

/// A linear pin law `F = k x` (no damping at rest).
pub(super) fn linear(k: f64) -> ContactLawSpec {
    ContactLawSpec::Impact {
        stiffness: k,
        exponent: 1.0,
        max_damping: 0.0,
        damping_depth: 1e-5,
    }
}

fn single_stage_linear() -> Scene {
    let mut s = Scene::paper("rated").unwrap();
    s.stage1 = None;
    s.contact.pin = linear(1e9);
    s
}

fn rated() -> f64 {
    Scene::paper("rated").unwrap().load.torque(0.0)
}

/// Linear law, no clearance, unmodified profile, rigid joints, cranks held (no first stage):
/// the LTCA tends to the classical load sharing as the load (the rotation `beta`) goes to 0.
///
/// The exact gap is `-beta l_j + O(beta^2)`, so `F_j(T) / T = a_j + b_j T + c_j T^2 + ...`
/// with `a_j` the classical share. Richardson extrapolation from `T`, `2T`, `4T`
/// (`h1 = 2 g(T) - g(2T)`, `h2 = 2 g(2T) - g(4T)`, `a = (4 h1 - h2) / 3`, `g = F/T`) removes
/// the first- and second-order terms. Measured: the two-level remainder falls as `T^2`
/// (2.2e-6 of the peak force at 1000 N m, 1.4e-7 at 250 N m); at `T` = 500 N m (penetrations
/// ~5e-7 m) the three-level remainder is ~1e-9 and the round-off of the gaps (~3e-17 m over
/// 5e-7 m, times ~5 for the extrapolation) ~3e-10. Each disc carries half the torque (both
/// discs see the same pin pattern, half a ring apart). Asserted: 2e-9 of the peak force.
#[test]
fn linear_rigid_unmodified_ltca_is_the_classical_load_sharing() {
    let scene = single_stage_linear();
    let g = CycloidGeometry::new(scene.cycloid).unwrap();
    let mut ltca = Ltca::new(&scene).unwrap();
    let t = 500.0;
    for psi in [0.1, 0.37, 1.3, -2.2] {
        let p1 = ltca.solve(t, psi).unwrap();
        let p2 = ltca.solve(2.0 * t, psi).unwrap();
        let p4 = ltca.solve(4.0 * t, psi).unwrap();
        for (k, phase) in [0.0, PI].into_iter().enumerate() {
            // A positive output torque turns the discs back: the pins with a negative classical
            // lever carry it (classical_pin_forces of a negative disc torque).
            let classical = classical_pin_forces(&g, -0.5, psi + phase).unwrap();
            let peak = classical.iter().cloned().fold(0.0, f64::max);
            let mut worst: f64 = 0.0;
            let mut worst_plain: f64 = 0.0;
            for j in 0..24 {
                let g1 = p1.pins[k][j].force / t;
                let g2 = p2.pins[k][j].force / (2.0 * t);
                let g4 = p4.pins[k][j].force / (4.0 * t);
                let a = (4.0 * (2.0 * g1 - g2) - (2.0 * g2 - g4)) / 3.0;
                worst = worst.max((a - classical[j]).abs() / peak);
                worst_plain = worst_plain.max((g1 - classical[j]).abs() / peak);
            }
            assert!(worst < 2e-9, "disc {k} psi {psi}: {worst:e}");
            // The finite-load LTCA itself differs at first order (it is exact, not linear).
            assert!(worst_plain > 1e-6 && worst_plain < 1e-3, "{worst_plain:e}");
            assert_eq!(
                p1.loaded_pins[k],
                classical.iter().filter(|f| **f > 0.0).count()
            );
        }
    }
}

#[test]
fn balances_close_and_zero_load_has_zero_te() {
    let mut scenes = vec![Scene::paper("rated").unwrap()];
    let mut c = Scene::paper("rated").unwrap();
    c.joints = default_joints();
    scenes.push(c.clone());
    let mut m = c;
    m.cycloid.d_rrp = 2e-5;
    m.cycloid.d_rp = -2e-5;
    scenes.push(m);
    for scene in scenes {
        let mut ltca = Ltca::new(&scene).unwrap();
        for psi in [0.0, 0.2, 0.45] {
            let p = ltca.solve(rated(), psi).unwrap();
            assert!(p.torque_balance < 1e-9, "balance {:e}", p.torque_balance);
            assert!(p.residual < 1e-9, "residual {:e}", p.residual);
            assert!(p.loaded_pins.iter().all(|n| *n > 0));
            assert!(p.transmission_error < 0.0, "the load turns the output back");
        }
    }
    // Error-free, unmodified: zero TE at zero load, in both models.
    for joints in [Joints::Rigid, default_joints()] {
        let mut s = Scene::paper("rated").unwrap();
        s.joints = joints;
        let mut ltca = Ltca::new(&s).unwrap();
        for psi in [0.0, 0.3, 2.0] {
            let p = ltca.solve(0.0, psi).unwrap();
            assert!(
                p.transmission_error.abs() < 1e-12,
                "{:e}",
                p.transmission_error
            );
            assert!(p.peak_pin_force() < 1e-6, "{}", p.peak_pin_force());
        }
    }
}

/// Mirror symmetry (no friction): the reducer mirrored about the x axis is itself with the
/// crank angle negated (pins j -> zp - j; the second disc's offset changes by a lobe pitch,
/// which the profile cannot tell; the planet seats map onto each other). So the equilibrium at
/// (psi, -T) is the mirror image of that at (-psi, T): pin forces of mirrored pins equal, TE
/// opposite. Symmetric modifications (d_rp, d_rrp) keep the symmetry. (Rigid crank bearings
/// here; the two-flank mesh of the compliant model keeps the symmetry with compliant ones too.)
#[test]
fn reversing_the_torque_mirrors_the_result() {
    let mut s = Scene::paper("rated").unwrap();
    s.joints = default_joints();
    if let Joints::Compliant { crank_bearing, .. } = &mut s.joints {
        *crank_bearing = None;
    }
    s.cycloid.d_rrp = 2e-5;
    s.cycloid.d_rp = -2e-5;
    let mut ltca = Ltca::new(&s).unwrap();
    for psi in [0.13, 0.4] {
        let a = ltca.solve(rated(), psi).unwrap();
        let b = ltca.solve(-rated(), -psi).unwrap();
        let peak = a.peak_pin_force();
        for k in 0..2 {
            // Disc k at -psi + phase is the mirror of disc k at psi + phase (phase 0 or pi).
            for j in 0..24 {
                let jm = (24 - j) % 24;
                let d = (a.pins[k][j].force - b.pins[k][jm].force).abs();
                assert!(d < 1e-9 * peak, "disc {k} pin {j}: {d:e}");
            }
            assert_eq!(a.loaded_pins[k], b.loaded_pins[k]);
        }
        let te = (a.transmission_error + b.transmission_error).abs();
        assert!(te < 1e-9 * a.transmission_error.abs(), "{te:e}");
    }
}

/// The analytic torsional stiffness equals central differences of the twist.
///
/// Step 1e-3 of the torque: the twist-torque curve is smooth at a fixed crank angle except
/// where a pin enters or leaves contact; the truncation error is ~(h/T)^2 times the curvature
/// of the curve (Hertz: `twist ~ T^(2/3)`), ~1e-6, the round-off of twists solved to 1e-12 of
/// the load ~1e-9. Asserted: 1e-5.
#[test]
fn rigidity_by_finite_differences_equals_the_analytic_tangent() {
    let mut s = Scene::paper("rated").unwrap();
    s.joints = default_joints();
    s.cycloid.d_rrp = 1e-5;
    let mut ltca = Ltca::new(&s).unwrap();
    let psi = 0.21;
    for t0 in [0.3 * rated(), rated()] {
        let p = ltca.solve(t0, psi).unwrap();
        let h = 1e-3 * t0;
        let (_, up) = ltca.output_angle(t0 + h, psi).unwrap();
        let (_, down) = ltca.output_angle(t0 - h, psi).unwrap();
        // Output deviation falls with torque: stiffness = -dT / d(deviation).
        let fd = -2.0 * h / (up - down);
        let rel = (fd / p.torsional_stiffness - 1.0).abs();
        assert!(rel < 1e-5, "fd {fd:e} analytic {:e}", p.torsional_stiffness);
    }
}

#[test]
fn twist_loop_gives_rigidity_lost_motion_and_backlash() {
    let mut s = Scene::paper("rated").unwrap();
    s.joints = default_joints();
    s.cycloid.d_rrp = 2e-5;
    s.cycloid.d_rp = -2e-5;
    let mut ltca = Ltca::new(&s).unwrap();
    let lp = ltca.twist_loop(rated(), 0.0, 41).unwrap();
    assert_eq!(lp.torque.len(), 41);
    assert!(lp.rigidity > 0.0 && lp.rigidity.is_finite());
    // Clearance from the modifications: a backlash, and lost motion at least the backlash.
    assert!(lp.backlash > 0.0);
    assert!(lp.lost_motion > lp.backlash);
    // Without friction the loop is closed: loading and unloading branches coincide.
    let n = lp.torque.len();
    for i in 0..n {
        for j in 0..n {
            if i != j && (lp.torque[i] - lp.torque[j]).abs() < 1e-9 * rated() && lp.torque[i] != 0.0
            {
                assert!((lp.twist[i] - lp.twist[j]).abs() < 1e-12);
            }
        }
    }
    // The unmodified reducer has no backlash (the conjugate profile touches every pin).
    let mut u = Scene::paper("rated").unwrap();
    u.joints = default_joints();
    let mut ltca = Ltca::new(&u).unwrap();
    let lp0 = ltca.twist_loop(rated(), 0.0, 9).unwrap();
    assert!(
        lp0.backlash.abs() < 1e-3 * lp.backlash,
        "{:e}",
        lp0.backlash
    );
}

/// TE over the true mesh period: the period check (TE at psi and psi + period agree), and
/// convergence of its peak-to-peak as the crank-angle grid is refined.
#[test]
fn te_repeats_over_the_mesh_period_and_converges_with_refinement() {
    let mut s = Scene::paper("rated").unwrap();
    s.cycloid.d_rrp = 2e-5;
    s.cycloid.d_rp = -2e-5;
    let mut ltca = Ltca::new(&s).unwrap();
    let period = ltca.mesh_period();
    assert!((period - TAU / 24.0).abs() < 1e-15);
    let a = ltca.solve(rated(), 0.05).unwrap();
    let b = ltca.solve(rated(), 0.05 + period).unwrap();
    assert!((a.transmission_error - b.transmission_error).abs() < 1e-12);
    let c = ltca.solve(rated(), 0.05 + 0.5 * period).unwrap();
    assert!((a.transmission_error - c.transmission_error).abs() > 1e-9);
    let mut pp = Vec::new();
    for n in [8, 16, 32, 64, 128] {
        let te = ltca
            .transmission_error(rated(), Some(1.0), n, 0.0, 1, false)
            .unwrap();
        pp.push(peak_to_peak(&te.forward));
    }
    let d: Vec<f64> = pp.windows(2).map(|w| (w[1] - w[0]).abs()).collect();
    assert!(d[3] < d[0], "{pp:?}");
    assert!(d[3] < 1e-2 * pp[4], "{pp:?}");
    // Pin errors make the pins distinguishable: the period is a full crank turn.
    let mut e = s.clone();
    e.pin_errors.radius = vec![0.0; 24];
    e.pin_errors.radius[3] = 5e-6;
    assert_eq!(mesh_period(&e), TAU);
}

#[test]
fn bad_input_is_a_clear_error() {
    let mut ltca = Ltca::new(&Scene::paper("rated").unwrap()).unwrap();
    assert!(matches!(
        ltca.solve(f64::NAN, 0.0),
        Err(RvdynError::Parameter(_))
    ));
    assert!(matches!(
        ltca.solve(1e3, f64::INFINITY),
        Err(RvdynError::Parameter(_))
    ));
    // Far beyond what the soft paper law carries with the geometry intact.
    let e = ltca.solve(1e9, 0.1).unwrap_err();
    assert!(matches!(e, RvdynError::Convergence(_)));
    assert!(e.to_string().contains("crank angle"), "{e}");
}
#[test]
fn fea_loads_take_the_worst_crank_angle_of_each_disc() {
    let mut s = Scene::paper("rated").unwrap();
    s.cycloid.d_rrp = 2e-5;
    s.cycloid.d_rp = -2e-5;
    let mut ltca = Ltca::new(&s).unwrap();
    let angles: Vec<f64> = (0..12).map(|i| 0.02 * i as f64).collect();
    let points = ltca.sweep(rated(), &angles).unwrap();
    let loads = export::worst_loads(&points).unwrap();
    for k in 0..2 {
        let worst = points
            .iter()
            .map(|p| p.pins[k].iter().fold(0.0f64, |m, l| m.max(l.force)))
            .fold(0.0, f64::max);
        let mine: Vec<_> = loads.iter().filter(|l| l.disc == k).collect();
        let peak = mine.iter().fold(0.0f64, |m, l| m.max(l.force));
        assert_eq!(peak, worst);
        let psi = mine[0].crank_angle;
        assert!(mine.iter().all(|l| l.crank_angle == psi && l.force > 0.0));
        // The contact point is on the profile and the normal is a unit vector.
        for l in &mine {
            assert!((l.normal[0].hypot(l.normal[1]) - 1.0).abs() < 1e-12);
            assert!(l.half_width > 0.0 && l.peak_pressure > 0.0);
        }
    }
    let csv = export::loads_csv(&loads);
    assert_eq!(csv.lines().count(), loads.len() + 1);
    assert!(csv.starts_with(export::CSV_HEADER));
    let json: serde_json::Value =
        serde_json::from_str(&export::loads_json(&loads, 0.04).unwrap()).unwrap();
    assert_eq!(json["format"], export::FORMAT);
    assert_eq!(json["loads"].as_array().unwrap().len(), loads.len());
    assert!(export::worst_loads(&[]).is_err());
}

/// The figures of the closing note (printed; run with `--ignored --nocapture`).
#[test]
#[ignore]
fn figures() {
    for (name, joints) in [("rigid", Joints::Rigid), ("compliant", default_joints())] {
        for (label, d_rrp, d_rp) in [
            ("unmodified", 0.0, 0.0),
            ("d_rrp +20 um, d_rp -20 um", 2e-5, -2e-5),
        ] {
            let mut s = Scene::paper("rated").unwrap();
            s.joints = joints;
            s.cycloid.d_rrp = d_rrp;
            s.cycloid.d_rp = d_rp;
            let mut ltca = Ltca::new(&s).unwrap();
            let period = ltca.mesh_period();
            let angles: Vec<f64> = (0..90).map(|i| period * i as f64 / 90.0).collect();
            let pts = ltca.sweep(rated(), &angles).unwrap();
            let peak = pts.iter().map(|p| p.peak_pin_force()).fold(0.0, f64::max);
            let lo = pts.iter().map(|p| p.loaded_pins[0]).min().unwrap();
            let hi = pts.iter().map(|p| p.loaded_pins[0]).max().unwrap();
            let te = ltca
                .transmission_error(rated(), Some(1e-6 * rated()), 90, 0.0, 1, false)
                .unwrap();
            let lp = ltca.twist_loop(rated(), 0.0, 81).unwrap();
            println!(
                "{name} {label}: loaded pins/disc {lo}-{hi}, peak pin force {:.1} kN, TE p-p fwd {:.3} arcsec rev {:.3} arcsec (mean fwd {:.2} rev {:.2} arcmin), unloaded TE p-p {:.4} arcsec, rigidity {:.1} N m/arcmin, lost motion {:.3} arcmin, backlash {:.3} arcmin",
                peak / 1e3,
                te.extremes.forward.peak_to_peak() / ARCSEC,
                te.extremes.reverse.peak_to_peak() / ARCSEC,
                te.forward.iter().sum::<f64>() / te.forward.len() as f64 / ARCMIN,
                te.reverse.iter().sum::<f64>() / te.reverse.len() as f64 / ARCMIN,
                te.extremes
                    .unloaded_forward
                    .map_or(f64::NAN, |e| e.peak_to_peak())
                    / ARCSEC,
                lp.rigidity * ARCMIN,
                lp.lost_motion / ARCMIN,
                lp.backlash / ARCMIN,
            );
        }
    }
}

/// Errors of the benchmarked results against converged references (printed; run with
/// `--ignored --nocapture`): the bench scene (compliant bearings, Palmgren line law, rated
/// torque) and the physical preset at 360 crank angles per period against 2880, at the default
/// Newton tolerance against 1e-14, and the 200-point loop against 801 points.
#[test]
#[ignore]
fn bench_reference_errors() {
    let mut paper = Scene::paper("rated").unwrap();
    paper.joints = default_joints();
    paper.contact.pin = ContactLawSpec::Palmgren {
        max_damping: 1e5,
        damping_depth: 1e-5,
    };
    // The bench's `ltca_line` scene: the paper's with linear compliant bearings and the
    // physical preset's line-contact pin law.
    let mut line = Scene::paper("rated").unwrap();
    line.joints = default_joints();
    line.contact.pin = Scene::physical("rated").unwrap().contact.pin;
    for (name, s) in [
        ("paper", paper),
        ("line", line),
        ("physical", Scene::physical("rated").unwrap()),
    ] {
        println!("{name}:");
        reference_errors(&s, s.load.torque(0.0));
    }
}

fn reference_errors(s: &Scene, rated: f64) {
    let rated = || rated;
    let mut ltca = Ltca::new(s).unwrap();
    let period = ltca.mesh_period();
    let grid = |n: usize| -> Vec<f64> { (0..n).map(|i| period * i as f64 / n as f64).collect() };
    let coarse = ltca.sweep(rated(), &grid(360)).unwrap();
    ltca.reset();
    let fine = ltca.sweep(rated(), &grid(2880)).unwrap();
    let te =
        |p: &[LtcaPoint]| peak_to_peak(&p.iter().map(|x| x.transmission_error).collect::<Vec<_>>());
    let peak = |p: &[LtcaPoint]| p.iter().map(|x| x.peak_pin_force()).fold(0.0, f64::max);
    println!(
        "360 vs 2880 angles: TE p-p {:.6e} vs {:.6e} rad (rel {:.2e}); peak pin force {:.3} vs {:.3} N (rel {:.2e})",
        te(&coarse),
        te(&fine),
        te(&coarse) / te(&fine) - 1.0,
        peak(&coarse),
        peak(&fine),
        peak(&coarse) / peak(&fine) - 1.0
    );
    let mut tight = Ltca::with_options(
        s,
        NewtonOptions {
            tolerance: 1e-14,
            ..NewtonOptions::default()
        },
    )
    .unwrap();
    let t = tight.sweep(rated(), &grid(360)).unwrap();
    let worst = coarse
        .iter()
        .zip(&t)
        .map(|(a, b)| (a.output_angle - b.output_angle).abs())
        .fold(0.0, f64::max);
    let worst_f = coarse
        .iter()
        .zip(&t)
        .map(|(a, b)| (a.peak_pin_force() - b.peak_pin_force()).abs())
        .fold(0.0, f64::max);
    println!(
        "tolerance 1e-12 vs 1e-14: output angle {worst:.2e} rad, peak pin force {worst_f:.2e} N"
    );
    let lp = ltca.twist_loop(rated(), 0.0, 200).unwrap();
    let lp2 = ltca.twist_loop(rated(), 0.0, 801).unwrap();
    println!(
        "loop 200 vs 801 points: rigidity {:.9} vs {:.9} N m/arcmin, lost motion {:.9} vs {:.9} arcmin, backlash {:.9} vs {:.9} arcmin",
        lp.rigidity * ARCMIN,
        lp2.rigidity * ARCMIN,
        lp.lost_motion / ARCMIN,
        lp2.lost_motion / ARCMIN,
        lp.backlash / ARCMIN,
        lp2.backlash / ARCMIN
    );
    let tl = tight.twist_loop(rated(), 0.0, 200).unwrap();
    println!(
        "loop at tolerance 1e-12 vs 1e-14: rigidity {:.2e}, lost motion {:.2e}, backlash {:.2e} relative; twist {:.2e} rad",
        lp.rigidity / tl.rigidity - 1.0,
        lp.lost_motion / tl.lost_motion - 1.0,
        lp.backlash / tl.backlash - 1.0,
        lp.twist
            .iter()
            .zip(&tl.twist)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
    );
}

/// Thread CPU time of the benchmarked workloads (printed; run with `--release --ignored
/// --nocapture`): on a shared machine the wall-clock medians of `benches/ltca.rs` include the
/// waits for a core; the CPU time of the measuring thread does not (Linux only).
#[test]
#[ignore]
fn cpu_time_report() {
    fn cpu() -> f64 {
        let s = std::fs::read_to_string("/proc/thread-self/stat").unwrap_or_default();
        let rest = s.rfind(')').map_or("", |i| &s[i + 2..]);
        let f: Vec<&str> = rest.split_whitespace().collect();
        // utime and stime are fields 14 and 15 of stat, the 12th and 13th after the name.
        let field = |i: usize| f.get(i).and_then(|x| x.parse::<f64>().ok()).unwrap_or(0.0);
        (field(11) + field(12)) / 100.0
    }
    let mut paper = Scene::paper("rated").unwrap();
    paper.joints = default_joints();
    paper.contact.pin = ContactLawSpec::Palmgren {
        max_damping: 1e5,
        damping_depth: 1e-5,
    };
    // The bench's `ltca_line` scene: the paper's with linear compliant bearings and the
    // physical preset's line-contact pin law.
    let mut line = Scene::paper("rated").unwrap();
    line.joints = default_joints();
    line.contact.pin = Scene::physical("rated").unwrap().contact.pin;
    for (name, s) in [
        ("paper", paper),
        ("line", line),
        ("physical", Scene::physical("rated").unwrap()),
    ] {
        let rated = s.load.torque(0.0);
        print!("{name}: ");
        cpu_times(&s, rated, cpu);
    }
}

fn cpu_times(s: &Scene, rated: f64, cpu: fn() -> f64) {
    let rated = || rated;
    let mut ltca = Ltca::new(s).unwrap();
    let period = ltca.mesh_period();
    let angles: Vec<f64> = (0..360).map(|i| period * i as f64 / 360.0).collect();
    let reps = 30;
    let t0 = cpu();
    for _ in 0..reps {
        ltca.reset();
        ltca.sweep(rated(), &angles).unwrap();
    }
    let sweep = (cpu() - t0) / reps as f64;
    let t0 = cpu();
    for _ in 0..reps {
        ltca.reset();
        for &a in &angles {
            ltca.solve_unknowns(rated(), a).unwrap();
        }
    }
    let bare = (cpu() - t0) / reps as f64;
    let t0 = cpu();
    for _ in 0..reps {
        ltca.twist_loop(rated(), 0.0, 200).unwrap();
    }
    let lp = (cpu() - t0) / reps as f64;
    println!(
        "CPU: 360 angles with full reports {:.2} ms ({:.1} us/angle); equilibria only {:.2} ms \
         ({:.1} us/angle); 200-point loop {:.2} ms",
        sweep * 1e3,
        sweep / 360.0 * 1e6,
        bare * 1e3,
        bare / 360.0 * 1e6,
        lp * 1e3
    );
}

/// Errors the statics do not model (assembly errors at rigid joints, which the dynamic models
/// refuse too) are refused with a `SceneError` naming them (the LTCA does not silently analyse
/// the error-free reducer instead); gear errors are modelled (gear_errors.rs).
#[test]
fn unsupported_errors_are_named() {
    let base = Scene::physical("rated").unwrap();
    let mut gear = base.clone();
    gear.gear_errors.sun.runout = 1e-6;
    assert!(Ltca::new(&gear).is_ok());
    // Assembly errors are modelled at compliant joints; the models refuse them at rigid ones.
    let mut assembly = base.clone();
    assembly.errors.crank_eccentricity = vec![1e-6, 0.0, 0.0];
    assert!(Ltca::new(&assembly).is_ok());
    assembly.joints = Joints::Rigid;
    for (s, what) in [(assembly, "need compliant joints")] {
        match Ltca::new(&s) {
            Err(RvdynError::Scene(m)) => assert!(m.contains(what), "{m}"),
            other => panic!("{what}: expected a SceneError, got {:?}", other.err()),
        }
    }
    assert!(Ltca::new(&base).is_ok());
}

fn profile_error(harmonics: Vec<[f64; 3]>) -> Option<crate::dynamics::scene::ProfileError> {
    Some(crate::dynamics::scene::ProfileError {
        harmonics,
        table: vec![],
    })
}

/// A constant profile error `a` (the harmonic of order 0) on every disc is the equidistant
/// modification `d_rrp = -a` (docs/model.md, "Manufacturing errors of profile and gears": every
/// gap shrinks by `a`; the foot on the pin-centre curve does not move with `d_rrp`), so the
/// LTCA of both scenes is the same equilibrium. Paper preset (IMPACT law: the line law's
/// curvature would see the generating radius change), rigid and compliant joints, rated
/// torque, a = 5 um. Asserted: output angles within 1e-9 of the load's twist and pin forces
/// within 1e-9 of the peak (both solve to Newton's tolerance, ~1e-12 relative).
#[test]
fn a_constant_profile_error_is_an_equidistant_modification() {
    let a = 5e-6;
    for joints in [Joints::Rigid, default_joints()] {
        let mut err = Scene::paper("rated").unwrap();
        err.joints = joints;
        let mut equi = err.clone();
        for d in &mut err.discs {
            d.profile_error = profile_error(vec![[a, 0.0, 0.0]]);
        }
        equi.cycloid.d_rrp = -a;
        let mut l1 = Ltca::new(&err).unwrap();
        let mut l2 = Ltca::new(&equi).unwrap();
        for psi in [0.1, 0.77, 2.3] {
            let p1 = l1.solve(rated(), psi).unwrap();
            let p2 = l2.solve(rated(), psi).unwrap();
            let twist = p1.transmission_error.abs().max(1e-12);
            assert!(
                (p1.output_angle - p2.output_angle).abs() < 1e-9 * twist,
                "{:?}: {} vs {}",
                err.joints,
                p1.output_angle,
                p2.output_angle
            );
            let f1: Vec<f64> = p1.pins.iter().flatten().map(|l| l.force).collect();
            let f2: Vec<f64> = p2.pins.iter().flatten().map(|l| l.force).collect();
            let peak = f1.iter().cloned().fold(0.0, f64::max);
            for (x, y) in f1.iter().zip(&f2) {
                assert!((x - y).abs() < 1e-9 * peak, "{x} vs {y}");
            }
            assert_eq!(p1.loaded_pins, p2.loaded_pins);
            assert!(p1.torque_balance < 1e-9, "{}", p1.torque_balance);
        }
    }
}

/// With a disc profile error the pattern repeats after `2 pi zc / zp` of crank angle, not one
/// pin pitch (`mesh_period`): the LTCA (paper preset, rigid joints, a harmonic of order 1 on
/// disc 0 of 5 um) gives the same transmission error and peak pin force one period later (to
/// 1e-9 of the twist / peak: two Newton solutions), but a different one a pin pitch later
/// (the error is seen: more than 1e-4 of the twist apart, measured 8e-4). The torque balance, which now
/// includes the error's force off the normal, closes to 1e-9.
#[test]
fn profile_errors_repeat_after_their_period() {
    let mut s = Scene::paper("rated").unwrap();
    s.discs[0].profile_error = profile_error(vec![[5e-6, 1.0, 0.3]]);
    let zp = f64::from(s.cycloid.pins);
    let period = mesh_period(&s);
    assert!((period - TAU * (zp - 1.0) / zp).abs() < 1e-12);
    let mut l = Ltca::new(&s).unwrap();
    let psi = 0.4;
    let a = l.solve(rated(), psi).unwrap();
    let b = l.solve(rated(), psi + period).unwrap();
    let c = l.solve(rated(), psi + TAU / zp).unwrap();
    let peak = |p: &LtcaPoint| p.pins.iter().flatten().map(|x| x.force).fold(0.0, f64::max);
    let twist = a.transmission_error.abs();
    assert!((a.transmission_error - b.transmission_error).abs() < 1e-9 * twist);
    assert!((peak(&a) - peak(&b)).abs() < 1e-9 * peak(&a));
    assert!(
        (a.transmission_error - c.transmission_error).abs() > 1e-4 * twist,
        "{} {} {}",
        a.transmission_error,
        b.transmission_error,
        c.transmission_error
    );
    for p in [&a, &b, &c] {
        assert!(p.torque_balance < 1e-9, "{}", p.torque_balance);
    }
}

/// The line law blends the disc's reference depth across `kappa_P D = 1` (docs/model.md, "Pin
/// against cycloid disc"). Before the blend, a loaded contact crossing that point (physical
/// preset, `d_rp = -20 um`, crank angle 2.3082 rad) made the location force jump and Newton
/// found no equilibrium there. Now it solves, and the pin forces across it change smoothly:
/// over 2e-4 rad centred on the crossing, the largest pin-force change between neighbouring
/// angles 2e-5 rad apart stays within 3 times the mean change per step (a jump of the old
/// kind was 20 times it).
#[test]
fn pin_forces_are_smooth_across_the_depth_blend() {
    let mut s = Scene::physical("rated").unwrap();
    s.cycloid.d_rp = -2e-5;
    let mut ltca = Ltca::new(&s).unwrap();
    let psi0 = 2.308_197_935_762_501;
    let forces: Vec<Vec<f64>> = (-5..=5)
        .map(|i| {
            let p = ltca.solve(rated(), psi0 + 2e-5 * i as f64).unwrap();
            p.pins.iter().flatten().map(|l| l.force).collect()
        })
        .collect();
    let steps: Vec<f64> = forces
        .windows(2)
        .map(|w| {
            w[0].iter()
                .zip(&w[1])
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max)
        })
        .collect();
    let mean = steps.iter().sum::<f64>() / steps.len() as f64;
    let worst = steps.iter().cloned().fold(0.0, f64::max);
    assert!(mean > 0.0 && worst < 3.0 * mean, "steps {steps:?}");
}

/// A torque-twist loop whose zero-torque point Newton cannot reach from the kinematic pose
/// (physical preset with pin radius errors and modifications, sample 428 of the 10 000-sample
/// study in BENCHMARKS.md 13.1: the bodies float in the bearing clearances, some pins are
/// preloaded) is completed by continuation from 1e-2 rated; its catalogue figures are finite
/// and ordered.
#[test]
fn zero_torque_limit_by_continuation() {
    let mut s = Scene::physical("rated").unwrap();
    s.cycloid.d_rrp = -2.564_952_275_363_655e-7;
    s.cycloid.d_rp = -2.826_951_413_145_57e-6;
    s.pin_errors.radius = vec![
        -1.112_599_373_492_489_8e-6,
        -1.768_539_243_792_398_7e-6,
        -4.777_438_123_914_611_5e-6,
        4.882_652_362_319_679e-6,
        3.248_265_596_608_798e-7,
        7.882_658_047_440_166e-7,
        7.256_710_737_919_903e-8,
        4.080_799_420_314_174e-6,
        1.120_731_849_109_812_7e-6,
        -1.091_075_135_946_992_7e-6,
        -2.217_840_467_851_037e-6,
        -2.972_824_126_105_944e-6,
        1.220_949_778_776_095_2e-6,
        4.023_083_627_160_912e-6,
        3.308_289_345_363_807_4e-6,
        -4.250_067_239_665_637e-6,
        4.638_259_778_539_203e-6,
        1.629_894_266_273_321e-6,
        -2.161_710_383_519_091e-6,
        -1.177_098_475_687_473e-6,
        1.468_255_901_030_791_3e-6,
        2.079_780_955_800_177_2e-6,
        -3.084_438_091_951_610_5e-6,
        -2.806_222_544_910_242e-6,
    ];
    // (Without the continuation this loop fails: Newton from the kinematic pose at 1e-7
    // rated stalls after 200 iterations.)
    let mut ltca = Ltca::new(&s).unwrap();
    let lp = ltca.twist_loop(rated(), 0.0, 41).unwrap();
    assert!(lp.rigidity > 0.0 && lp.backlash >= 0.0 && lp.lost_motion > lp.backlash);
    assert!(lp.twist.iter().all(|v| v.is_finite()));
}

/// The report of a solved crank angle comes from Newton's last evaluation (at the solution,
/// with the pins the separation bound skipped there re-queried), not from a fresh evaluation:
/// it must equal one. Checked against an independent evaluation at the same unknowns by a new
/// `Statics` that never skips a pin, along warm-started sweeps (where skipping is active) of
/// the physical preset and of the physical preset with a profile error on disc 0 (whose gaps
/// the re-query must include). Both evaluations are at the same unknowns; only the exact-gap
/// searches start from other seeds (gaps agree to ~3e-17 m, forces to that times the contact
/// stiffness, ~1e-12 of the peak). Asserted: gaps to 1e-13 m (a skipped pin left with its
/// gap from an earlier Newton iterate is off by the Newton corrections, 1e-9 to 1e-6 m),
/// pin, mesh and bearing forces to 1e-9 of the largest, torsional stiffness and input torque
/// to 1e-9 relative.
#[test]
fn report_equals_a_fresh_evaluation_at_the_solution() {
    use super::statics::{ContactState, Dense};
    let base = Scene::physical("rated").unwrap();
    let mut with_error = base.clone();
    with_error.discs[0].profile_error = profile_error(vec![[3e-6, 2.0, 0.4]]);
    for scene in [base, with_error] {
        let torque = scene.load.torque(0.0);
        let mut ltca = Ltca::new(&scene).unwrap();
        let mut fresh = Statics::new(&scene).unwrap();
        fresh.skip = false;
        let n = fresh.dim();
        let period = ltca.mesh_period();
        for i in 0..24 {
            let psi = 0.3 + period * i as f64 / 360.0;
            let p = ltca.solve(torque, psi).unwrap();
            let q = ltca.last_unknowns().to_vec();
            let (mut r, mut k) = (vec![0.0; n], Dense::zeros(n));
            let mut work = Work::new();
            let mut cs = ContactState::default();
            fresh
                .eval(psi, &q, torque, &mut r, &mut k, &mut work, Some(&mut cs))
                .unwrap();
            let zp = p.pins[0].len();
            let peak = cs.pin_force.iter().cloned().fold(0.0, f64::max);
            for (kd, row) in p.pins.iter().enumerate() {
                for (j, pin) in row.iter().enumerate() {
                    let slot = kd * zp + j;
                    assert!(
                        (pin.gap - cs.pin_gap[slot]).abs() < 1e-13,
                        "psi {psi} disc {kd} pin {j}: gap {} vs fresh {}",
                        pin.gap,
                        cs.pin_gap[slot]
                    );
                    assert!((pin.force - cs.pin_force[slot]).abs() < 1e-9 * peak);
                }
            }
            let close = |a: &[[f64; 2]], b: &[[f64; 2]]| {
                let m = b.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
                a.len() == b.len()
                    && a.iter()
                        .flatten()
                        .zip(b.iter().flatten())
                        .all(|(x, y)| (x - y).abs() <= 1e-9 * m)
            };
            assert!(close(
                &p.eccentric_bearing_force,
                &cs.eccentric_bearing_force
            ));
            assert!(close(&p.crank_bearing_force, &cs.crank_bearing_force));
            let mesh = cs.mesh_force.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (a, b) in p.mesh_force.iter().zip(&cs.mesh_force) {
                assert!((a - b).abs() <= 1e-9 * mesh);
            }
            let input = fresh.input_reaction(&work);
            assert!((p.input_torque - input).abs() <= 1e-9 * input.abs());
            let mut e0 = vec![0.0; n];
            e0[0] = 1.0;
            assert!(solve_dense(&mut k, &mut e0));
            let stiffness = 1.0 / e0[0];
            assert!(
                (p.torsional_stiffness / stiffness - 1.0).abs() < 1e-9,
                "{} vs {stiffness}",
                p.torsional_stiffness
            );
        }
        // The sweep did skip pins (the path under test ran).
        assert!(ltca.statics.skipped > 100, "{}", ltca.statics.skipped);
    }
}

/// The warm start reproduces deflections that are polynomials of its degree along the history:
/// quadratic in the torque at a fixed crank angle, linear in the crank angle at a fixed torque
/// (exactly, to round-off of the deflections' size), and falls back to the last deflection
/// beyond 1.5 spacings or across a change of both.
#[test]
fn warm_start_extrapolates_polynomials_of_its_degree() {
    let st = Statics::new(&Scene::paper("rated").unwrap()).unwrap();
    let n = st.dim();
    let shape: Vec<f64> = (0..n).map(|a| 1e-6 * (1.0 + a as f64)).collect();
    let point = |psi: f64, torque: f64, d: &dyn Fn(f64, f64) -> f64| {
        let q = st
            .kinematic_unknowns(psi)
            .iter()
            .zip(&shape)
            .map(|(k, s)| k + s * d(psi, torque))
            .collect();
        Solved::new(&st, psi, torque, q)
    };
    let close = |got: &[f64], psi: f64, torque: f64, d: &dyn Fn(f64, f64) -> f64, tol: f64| {
        let want = point(psi, torque, d).q;
        let worst = got
            .iter()
            .zip(&want)
            .zip(&shape)
            .map(|((g, w), s)| ((g - w) / s).abs())
            .fold(0.0, f64::max);
        assert!(worst < tol, "predictor off by {worst:e} of the deflection");
    };
    // Quadratic in the torque (varying steps), crank angle fixed.
    let quad = |_: f64, t: f64| 0.3 + 2e-4 * t - 3e-9 * t * t;
    let h: Vec<Solved> = [3000.0, 2500.0, 1800.0]
        .iter()
        .map(|&t| point(0.7, t, &quad))
        .collect();
    let q = predictor(&h, 0.7, 3600.0, st.kinematic_unknowns(0.7));
    close(&q, 0.7, 3600.0, &quad, 1e-9);
    // The same history with a linear deflection along the crank angle: linear is exact there,
    // a quadratic one is not (so the degree is the one documented).
    let lin = |p: f64, _: f64| 0.2 + 0.5 * p;
    let curved = |p: f64, _: f64| 0.2 + 0.5 * p * p;
    let h: Vec<Solved> = [0.72, 0.71, 0.70]
        .iter()
        .map(|&p| point(p, 5000.0, &lin))
        .collect();
    let q = predictor(&h, 0.73, 5000.0, st.kinematic_unknowns(0.73));
    close(&q, 0.73, 5000.0, &lin, 1e-9);
    let h: Vec<Solved> = [0.72, 0.71, 0.70]
        .iter()
        .map(|&p| point(p, 5000.0, &curved))
        .collect();
    let q = predictor(&h, 0.73, 5000.0, st.kinematic_unknowns(0.73));
    let want = point(0.73, 5000.0, &curved).q;
    let off = (q[0] - want[0]) / shape[0];
    // Linear extrapolation through two points one step h ahead errs by h^2 f'' = 1e-4 for
    // f = 0.5 p^2, h = 0.01 (below the truth).
    assert!((off + 1e-4).abs() < 1e-9, "linear predictor error {off:e}");
    // Two steps and a half ahead: no extrapolation, the last deflection.
    let q = predictor(&h, 0.745, 5000.0, st.kinematic_unknowns(0.745));
    let last = 0.2 + 0.5 * 0.72 * 0.72;
    close(&q, 0.745, 5000.0, &|_, _| last, 1e-9);
    // Neither the torque nor the crank angle shared: the last deflection.
    let q = predictor(&h, 0.75, 100.0, st.kinematic_unknowns(0.75));
    close(&q, 0.75, 100.0, &|_, _| last, 1e-9);
}

/// The report's Hertz strip of each loaded pin (half-width and peak pressure) is the checked
/// Hertz line contact (`hertz_line_contact`) at the pin radius and the profile's radius of
/// curvature from an independent exact gap query at the reported disc pose; unloaded pins have
/// none.
#[test]
fn report_hertz_strips_equal_the_checked_hertz_contact() {
    use crate::contact::hertz::hertz_line_contact;
    use crate::contact::law::PinLaw;
    use crate::contact::pin_tangent::pin_gap_jet;
    let scene = Scene::physical("rated").unwrap();
    let torque = scene.load.torque(0.0);
    let mut ltca = Ltca::new(&scene).unwrap();
    let st = Statics::new(&scene).unwrap();
    let PinLaw::Line { pin, disc, .. } = &st.model.pin_law else {
        panic!("the physical preset has the line law")
    };
    let (pin_mat, disc_mat) = (*pin, *disc);
    for psi in [0.0, 0.1, 0.23] {
        let p = ltca.solve(torque, psi).unwrap();
        let kin = st.kinematic_full(psi);
        let mut checked = 0;
        for k in 0..2 {
            let dk = st.disc_index(k);
            let o = [
                kin[dk] + p.disc_displacement[k][0],
                kin[dk + 1] + p.disc_displacement[k][1],
            ];
            let th = kin[dk + 2] + p.disc_rotation[k];
            let d = &st.model.discs[k];
            for (j, l) in p.pins[k].iter().enumerate() {
                if l.force <= 0.0 {
                    assert_eq!((l.half_width, l.peak_pressure), (0.0, 0.0));
                    continue;
                }
                let pin = &st.model.pins[j];
                let seed = pin.angle - th - d.geometry.params().d_delta;
                let jet = pin_gap_jet(&d.geometry, pin.centre, pin.radius, o, th, seed).unwrap();
                let h = hertz_line_contact(
                    l.force,
                    scene.cycloid.face_width,
                    pin.radius,
                    jet.curvature_radius,
                    &pin_mat,
                    &disc_mat,
                )
                .unwrap();
                let rel = |a: f64, b: f64| (a - b).abs() / b;
                assert!(
                    rel(l.half_width, h.half_width) < 1e-9
                        && rel(l.peak_pressure, h.peak_pressure) < 1e-9,
                    "pin {j} disc {k}: strip ({}, {}) against ({}, {})",
                    l.half_width,
                    l.peak_pressure,
                    h.half_width,
                    h.peak_pressure
                );
                checked += 1;
            }
        }
        assert!(checked >= 10, "only {checked} loaded pins at {psi}");
    }
}

/// `f` run in a rayon pool of `threads` threads.
fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

/// A sweep of `2 SWEEP_CHAIN` angles runs as two chains in parallel (the second from the
/// kinematic pose): the same bits on one thread as on two, and the same equilibria as one
/// unbroken chain of single solves to the Newton tolerance. Tolerances: forces 1e-9 of the
/// peak and TE 1e-13 rad (both chains' residuals are below `1e-12 |T| / rp`; measured
/// differences 3.4e-12 of the peak force and 2e-16 rad).
#[test]
fn parallel_chains_equal_one_unbroken_sweep() {
    let mut s = Scene::paper("rated").unwrap();
    s.joints = default_joints();
    s.contact.pin = ContactLawSpec::Palmgren {
        max_damping: 1e5,
        damping_depth: 1e-5,
    };
    let n = 2 * SWEEP_CHAIN;
    let period = Ltca::new(&s).unwrap().mesh_period();
    let angles: Vec<f64> = (0..n).map(|i| period * i as f64 / n as f64).collect();
    let run = |threads: usize| {
        on_threads(threads, || {
            let mut l = Ltca::new(&s).unwrap();
            let pts = l.sweep(rated(), &angles).unwrap();
            (pts, l.evaluations(), l.last_unknowns().to_vec())
        })
    };
    let (one, e1, q1) = run(1);
    let (two, e2, q2) = run(2);
    assert_eq!(e1, e2);
    assert_eq!(q1, q2);
    for (a, b) in one.iter().zip(&two) {
        assert_eq!(a.transmission_error, b.transmission_error);
        assert_eq!(a.pins, b.pins);
    }
    let mut l = Ltca::new(&s).unwrap();
    let unbroken: Vec<LtcaPoint> = angles
        .iter()
        .map(|&p| l.solve(rated(), p).unwrap())
        .collect();
    // The second chain's start from the kinematic pose costs evaluations.
    assert!(e1 > l.evaluations(), "{e1} {}", l.evaluations());
    let peak = unbroken
        .iter()
        .map(|p| p.peak_pin_force())
        .fold(0.0, f64::max);
    for (a, b) in one.iter().zip(&unbroken) {
        assert_eq!(a.loaded_pins, b.loaded_pins);
        assert!((a.transmission_error - b.transmission_error).abs() < 1e-13);
        for (ra, rb) in a.pins.iter().zip(&b.pins) {
            for (pa, pb) in ra.iter().zip(rb) {
                assert!((pa.force - pb.force).abs() < 1e-9 * peak);
            }
        }
    }
    // The warm start afterwards is the last angle's solution.
    for (a, b) in q1.iter().zip(l.last_unknowns()) {
        assert!((a - b).abs() < 1e-12, "{a} {b}");
    }
}

/// A chain whose start from the kinematic pose fails (here: Newton limited to fewer
/// iterations than that start needs, but enough for the warm-started angles) is solved again
/// as the continuation of the chain before it: the sweep succeeds with exactly the unbroken
/// chain's results.
#[test]
fn a_chain_that_fails_from_the_kinematic_pose_continues_the_one_before() {
    let mut s = Scene::paper("rated").unwrap();
    s.joints = default_joints();
    let n = 2 * SWEEP_CHAIN;
    let mut warm = Ltca::new(&s).unwrap();
    let period = warm.mesh_period();
    let angles: Vec<f64> = (0..n).map(|i| period * i as f64 / n as f64).collect();
    warm.solve(rated(), -period / n as f64).unwrap();
    let cold_iterations = {
        let mut l = Ltca::new(&s).unwrap();
        l.solve(rated(), angles[n / 2]).unwrap().iterations
    };
    warm.options.max_iterations = 4;
    assert!(
        cold_iterations > warm.options.max_iterations,
        "{cold_iterations}"
    );
    let mut unbroken = warm.clone();
    let expected = unbroken.sweep_chain(rated(), &angles).unwrap();
    let e_unbroken = unbroken.evaluations();
    let got = warm.sweep(rated(), &angles).unwrap();
    assert_eq!(got, expected);
    assert_eq!(warm.last_unknowns(), unbroken.last_unknowns());
    // The failed cold start's evaluations are counted.
    assert!(warm.evaluations() > e_unbroken);
}

/// The frictionless loop runs as two chains (the positive part in order, the negative part
/// from its most loaded point outwards): the same bits on one thread as on two, and the same
/// twist as the loop solved in order (the frictional loop's path with no friction, which
/// `zero_friction_gives_the_closed_loop` also checks) to 1e-12 rad. That includes the first
/// chain's second zero-torque point, which the two-chain loop takes from its first instead of
/// solving it again along the path.
#[test]
fn the_two_chain_loop_is_the_same_on_any_thread_count() {
    let s = Scene::physical("rated").unwrap();
    let run = |threads: usize| {
        on_threads(threads, || {
            let mut l = Ltca::new(&s).unwrap();
            (l.twist_loop(rated(), 0.0, 40).unwrap(), l.evaluations())
        })
    };
    let (one, e1) = run(1);
    let (two, e2) = run(2);
    assert_eq!(one, two);
    assert_eq!(e1, e2);
    let none = friction::FrictionLaws::none(&s);
    let in_order = Ltca::new(&s)
        .unwrap()
        .twist_loop_with_friction(&none, rated(), 0.0, 40)
        .unwrap();
    for (a, b) in one.twist.iter().zip(&in_order.twist) {
        assert!((a - b).abs() < 1e-12, "{a} {b}");
    }
}

/// The extremes located between the crank angles (`te_extremes`): on the modified paper
/// reducer they are at least the samples' and agree from 8 and 64 angles per period (measured
/// 2.5e-10 of the peak-to-peak, asserted 1e-7), where the samples' own peak-to-peak falls
/// short by 4.2 % and 2.7e-4 (asserted above 1e-4); a sample made inconsistent with its path (its TE moved by a tenth of the
/// peak-to-peak, as a second equilibrium would be) is found when solved again, and the
/// curve then keeps the samples' extremes, flagged as not refined.
#[test]
fn te_extremes_are_refined_between_the_samples_and_checked_along_the_path() {
    let mut s = Scene::paper("rated").unwrap();
    s.cycloid.d_rrp = 2e-5;
    s.cycloid.d_rp = -2e-5;
    let mut ltca = Ltca::new(&s).unwrap();
    let coarse = ltca
        .transmission_error(rated(), None, 8, 0.0, 1, false)
        .unwrap();
    let fine = ltca
        .transmission_error(rated(), None, 64, 0.0, 1, false)
        .unwrap();
    let (a, b) = (coarse.extremes.forward, fine.extremes.forward);
    assert!(a.refined && b.refined);
    let pp = b.peak_to_peak();
    assert!(a.peak_to_peak() >= peak_to_peak(&coarse.forward));
    assert!(
        peak_to_peak(&fine.forward) < (1.0 - 1e-4) * pp,
        "{} {pp}",
        peak_to_peak(&fine.forward)
    );
    assert!((a.peak_to_peak() - pp).abs() < 1e-7 * pp, "{a:?} {b:?}");
    assert!((a.max.value - b.max.value).abs() < 1e-7 * pp);

    // The samples of that sweep, one of them moved off its equilibrium.
    let period = ltca.mesh_period();
    let step = period / 8.0;
    ltca.reset();
    let mut samples: Vec<_> = (0..8)
        .map(|i| ltca.te_sample(rated(), step * i as f64).unwrap())
        .collect();
    let clean = ltca
        .refine_extremes(rated(), &samples, step, period)
        .unwrap();
    assert!(clean.refined);
    assert_eq!(clean.peak_to_peak(), a.peak_to_peak());
    let top = (0..8)
        .max_by(|&x, &y| samples[x].te.total_cmp(&samples[y].te))
        .unwrap();
    samples[top].te += 0.1 * pp;
    let moved = ltca
        .refine_extremes(rated(), &samples, step, period)
        .unwrap();
    assert!(!moved.refined);
    assert_eq!(moved.max.value, samples[top].te);
}

/// The window after which the whole static state repeats: the mesh period without roller
/// bearings; with the physical preset's fixed roller sets (26 and 20 rollers, 23 lobes)
/// `lcm(23/24, 23/26, 23/20)` = 23/2 turns, twelve mesh periods; one set of 23 rollers
/// (`23/23` = 1 turn) gives `lcm(23/24, 1)` = 23 turns.
#[test]
fn te_window_is_the_mesh_period_extended_by_the_roller_sets() {
    let paper = Scene::paper("rated").unwrap();
    assert_eq!(te_window(&paper), mesh_period(&paper));
    let mut s = Scene::physical("rated").unwrap();
    assert!((te_window(&s) - 23.0 * PI).abs() < 1e-12);
    assert!((te_window(&s) / mesh_period(&s) - 12.0).abs() < 1e-12);
    if let Joints::Compliant {
        eccentric_bearing,
        crank_bearing,
    } = &mut s.joints
    {
        if let Some(r) = eccentric_bearing.rollers.as_mut() {
            r.count = 23;
        }
        *crank_bearing = None;
    }
    assert!((te_window(&s) - 23.0 * TAU).abs() < 1e-10);
}

/// The pin loads kept along the loaded TE curves are those of the sweep's reports at the same
/// crank angles (physical preset with both profile modifications: the peak pin force agrees
/// to Newton's tolerance, measured 2.4e-12 relative, asserted 1e-9; the loaded-pin counts
/// exactly), and asking for them leaves the TE as it is (the same equilibria).
#[test]
fn te_pin_loads_equal_the_sweep_reports() {
    let mut s = Scene::physical("rated").unwrap();
    s.cycloid.d_rrp = 2e-5;
    s.cycloid.d_rp = -2e-5;
    let t = rated();
    let mut ltca = Ltca::new(&s).unwrap();
    let with = ltca.transmission_error(t, None, 24, 0.0, 1, true).unwrap();
    let without = ltca.transmission_error(t, None, 24, 0.0, 1, false).unwrap();
    assert!(without.pin_loads.is_none());
    let loads = with.pin_loads.clone().unwrap();
    for (k, (a, b)) in with.forward.iter().zip(&without.forward).enumerate() {
        assert!((a - b).abs() < 1e-15, "TE at angle {k}: {a} {b}");
    }
    let mut worst = 0.0f64;
    for (sign, curve) in [(1.0, &loads.forward), (-1.0, &loads.reverse)] {
        let mut fresh = Ltca::new(&s).unwrap();
        let pts = fresh.sweep(sign * t, &with.crank_angle).unwrap();
        assert_eq!(curve.peak_force.len(), pts.len());
        for (k, p) in pts.iter().enumerate() {
            let f = p.peak_pin_force();
            worst = worst.max((curve.peak_force[k] - f).abs() / f);
            assert!(
                (curve.peak_force[k] - f).abs() <= 1e-9 * f,
                "{sign} angle {k}: {} {f}",
                curve.peak_force[k]
            );
            assert_eq!(
                curve.loaded_pins_min[k],
                *p.loaded_pins.iter().min().unwrap()
            );
        }
    }
    println!("largest relative difference of the peak pin force: {worst:.2e}");
}

/// Several periods are the one-period analyses from each period's start, joined: the curves
/// end to end, each curve's extremes the largest and smallest of the periods', the pin loads
/// end to end (physical preset, whose TE differs from period to period: its roller sets are
/// fixed in the frame). No period is a `Parameter` error.
#[test]
fn te_over_several_periods_joins_the_periods() {
    let s = Scene::physical("rated").unwrap();
    let t = rated();
    let mut ltca = Ltca::new(&s).unwrap();
    let p = ltca.mesh_period();
    let two = ltca
        .transmission_error(t, Some(1e-6 * t), 24, 0.0, 2, true)
        .unwrap();
    let first = ltca
        .transmission_error(t, Some(1e-6 * t), 24, 0.0, 1, true)
        .unwrap();
    let second = ltca
        .transmission_error(t, Some(1e-6 * t), 24, p, 1, true)
        .unwrap();
    assert_eq!(two.periods, 2);
    assert_eq!(two.crank_angle.len(), 48);
    // The same equilibria; the exact gaps' warm starts carried from call to call move them by
    // round-off: loaded 1e-16 rad, at the light load (whose solves stop at a round-off floor
    // relative to a tiny load) up to 4e-13 rad per angle and 1.3e-11 rad (2e-5 of the
    // peak-to-peak) in the located extremes.
    let close = |a: &[f64], b: &[f64]| {
        a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-14)
    };
    assert!(close(&two.forward[..24], &first.forward));
    assert!(close(&two.forward[24..], &second.forward));
    let light_diff = two.unloaded_reverse[24..]
        .iter()
        .zip(&second.unloaded_reverse)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    println!("unloaded: largest difference {light_diff:.2e} rad");
    assert!(light_diff < 1e-9, "{light_diff}");
    assert!((two.crank_angle[24] - p).abs() < 1e-12);
    // The periods differ (roller-pass ripple), so the joined extremes are a real choice.
    let (a, b, c) = (&two.extremes, &first.extremes, &second.extremes);
    assert!((b.forward.max.value - c.forward.max.value).abs() > 1e-9);
    let near = |x: f64, y: f64| (x - y).abs() < 1e-14;
    assert!(near(
        a.forward.max.value,
        b.forward.max.value.max(c.forward.max.value)
    ));
    assert!(near(
        a.reverse.min.value,
        b.reverse.min.value.min(c.reverse.min.value)
    ));
    let ua = a.unloaded_forward.unwrap();
    let (ub, uc) = (b.unloaded_forward.unwrap(), c.unloaded_forward.unwrap());
    let upp = ua.max.value - ua.min.value;
    let ud = (ua.max.value - ub.max.value.max(uc.max.value)).abs();
    println!("unloaded extremes: {ud:.2e} rad of {upp:.2e}");
    assert!(ud < 1e-4 * upp, "{ud} {upp}");
    let loads = two.pin_loads.unwrap();
    assert_eq!(loads.forward.peak_force.len(), 48);
    let later = second.pin_loads.unwrap().forward.peak_force;
    assert!(
        loads.forward.peak_force[24..]
            .iter()
            .zip(&later)
            .all(|(x, y)| (x - y).abs() < 1e-9 * y)
    );
    assert!(matches!(
        ltca.transmission_error(t, None, 24, 0.0, 0, false),
        Err(RvdynError::Parameter(_))
    ));
}

/// Newton from `start` (and `second`) at `psi` under `t`: the unknowns and the force
/// evaluations it took.
fn newton_from(
    ltca: &mut Ltca,
    psi: f64,
    t: f64,
    start: &[f64],
    second: Option<&[f64]>,
) -> (Vec<f64>, usize) {
    let mut q = start.to_vec();
    let before = ltca.statics.evaluations;
    equilibrium(
        &mut ltca.statics,
        psi,
        t,
        &mut q,
        second,
        ltca.k_ref,
        &ltca.options,
        &mut ltca.work,
        &mut ltca.scratch,
        false,
    )
    .unwrap();
    (q, ltca.statics.evaluations - before)
}

/// Newton's second start (the last solution's deflection carried unchanged): tried only when
/// the residual at the first start exceeds the load, and then Newton runs from the better of
/// the two. At a light load (1e-7 rated, bodies floating in their clearances) a first start
/// with the last deflection overshot 30 times lands far off; with the second start the
/// iteration is the one from the second start itself (the same unknowns to round-off, measured
/// 6e-17, and one evaluation more: 42 against 41), without it Newton needs 203 evaluations. A
/// first start within the load leaves the second one untried.
#[test]
fn second_start_is_taken_when_the_first_lands_beyond_the_load() {
    let s = Scene::physical("rated").unwrap();
    let t = 1e-7 * rated();
    let mut ltca = Ltca::new(&s).unwrap();
    let (q0, _) = ltca.solve_unknowns(t, 0.3).unwrap();
    let psi = 0.3 + 0.0167;
    let kin0 = ltca.statics.kinematic_unknowns(0.3);
    let kin = ltca.statics.kinematic_unknowns(psi);
    let held: Vec<f64> = (0..kin.len()).map(|i| kin[i] + q0[i] - kin0[i]).collect();
    let overshot: Vec<f64> = (0..kin.len())
        .map(|i| kin[i] + 30.0 * (q0[i] - kin0[i]))
        .collect();
    let (q_held, n_held) = newton_from(&mut ltca, psi, t, &held, None);
    let (q_both, n_both) = newton_from(&mut ltca, psi, t, &overshot, Some(&held));
    let (_, n_over) = newton_from(&mut ltca, psi, t, &overshot, None);
    let apart = |a: &[f64], b: &[f64]| {
        a.iter()
            .zip(b)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
    };
    println!(
        "held {n_held}, overshot with the second start {n_both}, without {n_over}; apart {:.1e}",
        apart(&q_both, &q_held)
    );
    assert!(apart(&q_both, &q_held) < 1e-12);
    assert_eq!(n_both, n_held + 1);
    assert!(n_over > n_both, "{n_over} {n_both}");
    // At rated torque the held deflection is a start within the load (residual about 0.2 of
    // it): the second start is not tried, the same iteration bit for bit.
    let t = rated();
    let (q1, _) = ltca.solve_unknowns(t, 0.3).unwrap();
    let start: Vec<f64> = (0..kin.len()).map(|i| kin[i] + q1[i] - kin0[i]).collect();
    let a = newton_from(&mut ltca, psi, t, &start, None);
    let b = newton_from(&mut ltca, psi, t, &start, Some(&overshot));
    assert_eq!(a.1, b.1);
    assert!(apart(&a.0, &b.0) < 1e-15);
}

/// One disc per crank: the beam's deflection at the disc is `C11 F` along the eccentric
/// bearing's force, in series with the (linear, clearance-free) bearing, so a bending crank is
/// the same reducer as a rigid one with the eccentric bearing's stiffness `1 / (1/k + C11)`
/// (`C11` the closed form of beam theory, `bearing::crank_beam`). The two scenes are solved
/// separately; equal to Newton's tolerance (1e-12 of the load): asserted 1e-9 of the twist and
/// of the peak pin force, and the bending visibly softer than the rigid crank (over 5 %).
#[test]
fn bending_of_a_one_disc_crank_is_a_softer_eccentric_bearing() {
    use crate::bearing::{CrankLayout, CrankShaft};
    let mut bent = Scene::paper("rated").unwrap();
    bent.discs.truncate(1);
    bent.joints = default_joints();
    let layout = CrankLayout {
        bearings: [-0.06, 0.06],
        discs: vec![0.01],
        planet: -0.09,
        roller_length: None,
    };
    let shaft = CrankShaft {
        diameter: 0.04,
        modulus: 2.06e11,
        poisson: 0.3,
        eccentric_mass: None,
    };
    let c11 = shaft.flexibility(&layout).unwrap()[0];
    bent.crank_layout = Some(layout);
    bent.crank_shaft = Some(shaft);
    let mut series = bent.clone();
    series.crank_shaft = None;
    let rigid = series.clone();
    if let Joints::Compliant {
        eccentric_bearing, ..
    } = &mut series.joints
    {
        eccentric_bearing.stiffness = 1.0 / (1.0 / eccentric_bearing.stiffness + c11);
    }
    let torque = rated();
    let (mut a, mut b, mut r) = (
        Ltca::new(&bent).unwrap(),
        Ltca::new(&series).unwrap(),
        Ltca::new(&rigid).unwrap(),
    );
    for psi in [0.0, 0.4, 1.7] {
        let (pa, pb, pr) = (
            a.solve(torque, psi).unwrap(),
            b.solve(torque, psi).unwrap(),
            r.solve(torque, psi).unwrap(),
        );
        let twist = |p: &LtcaPoint| -(p.output_angle + psi / 23.0);
        assert!(
            (twist(&pa) - twist(&pb)).abs() < 1e-9 * twist(&pb).abs(),
            "{} {}",
            twist(&pa),
            twist(&pb)
        );
        let peak = pb.peak_pin_force();
        for (fa, fb) in pa.pins[0].iter().zip(&pb.pins[0]) {
            assert!((fa.force - fb.force).abs() < 1e-9 * peak);
        }
        assert!(
            twist(&pa) > 1.05 * twist(&pr),
            "{} {}",
            twist(&pa),
            twist(&pr)
        );
    }
}
