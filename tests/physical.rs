//! The physical preset (`Scene::physical`): checks against independent references.
//!
//! - pin forces and approaches of the dynamic model against the quasi-static line-law load
//!   sharing (`analysis::pin_load_sharing`), a second method on the same law;
//! - the damping ratio of the main torsional mode from the linearised model (eigenvalues of
//!   the first-order system by finite differences) against the ratio the preset sets;
//! - a reversed run mirrors a forward run (the coast flank has its own line of action);
//! - the energy balance closes with the time-varying mesh stiffness.

use rvdyn::analysis::pin_load_sharing::line_law_load_sharing;
use rvdyn::contact::Material;
use rvdyn::dynamics::model::ReducerModel;
use rvdyn::dynamics::model::compliant::CompliantModel;
use rvdyn::dynamics::scene::{
    Drive, Initial, Joints, Load, PAPER_INPUT_SPEED, PHYSICAL_DAMPING_RATIO,
    PHYSICAL_REFERENCE_FREQUENCY, StartKind,
};
use rvdyn::dynamics::{Recording, RunControl, Scene, SimOptions, simulate};
use rvdyn::geometry::CycloidGeometry;
use rvdyn::solve::generalized_alpha::GeneralizedAlpha;
use rvdyn::solve::{MechanicalSystem, Method, State};

/// The physical preset at full speed from t = 0 (steady initial state).
fn steady(load: &str) -> Scene {
    let mut s = Scene::physical(load).unwrap();
    s.initial = Initial::Steady;
    s.drive = Drive::Speed {
        speed: PAPER_INPUT_SPEED,
        start: StartKind::Step,
        ramp_time: 0.0,
    };
    s
}

fn run(s: &Scene, t_end: f64, rtol: f64, atol: f64) -> Recording {
    let mut opt = SimOptions::new(t_end, Method::Dopri5);
    opt.rtol = rtol;
    opt.atol = atol;
    opt.record_interval = Some(5e-5);
    simulate(s, &opt, &RunControl::default()).unwrap()
}

fn data<'a>(r: &'a Recording, name: &str) -> &'a [f64] {
    &r.series[name].data
}

#[test]
fn preset_validates_and_round_trips() {
    let s = Scene::physical("rated").unwrap();
    let back = Scene::from_json(&s.to_json().unwrap()).unwrap();
    assert_eq!(back, s);
    assert!(matches!(s.joints, Joints::Compliant { .. }));
    // The paper preset is untouched.
    let p = Scene::paper("rated").unwrap();
    assert!(matches!(p.joints, Joints::Rigid));
    assert!(Scene::physical("nonsense").is_err());
}

#[test]
fn rigid_joint_pin_forces_match_the_quasi_static_line_law() {
    // Rigid joints isolate the pin law: after the start transient has decayed (50 ms, the
    // main mode's decay time 1/(zeta w) is 2 ms), the peak pin force and approach of every
    // sample lie within the range the quasi-static load sharing gives over the crank angle,
    // widened by 2 % (dynamic ripple at the mesh and pin frequencies).
    let mut s = steady("rated");
    s.joints = Joints::Rigid;
    let r = run(&s, 0.06, 1e-6, 1e-9);
    let n = r.samples;
    let (f, pen, lp) = (
        data(&r, "pin_force"),
        data(&r, "pin_penetration"),
        data(&r, "loaded_pins"),
    );
    let g = CycloidGeometry::new(s.cycloid).unwrap();
    let steel = Material::steel();
    // Disc torque if the two discs share the housing torque equally.
    let tc = 0.5 * 43_904.0 * (1.0 - 1.0 / 57.0) * 23.0 / 24.0;
    let (mut qf_lo, mut qf_hi, mut qd_hi) = (f64::INFINITY, 0.0f64, 0.0f64);
    for k in 0..12 {
        let psi = std::f64::consts::TAU / 24.0 * k as f64 / 12.0;
        let q = line_law_load_sharing(&g, tc, psi, 0.010, &steel, &steel).unwrap();
        qf_lo = qf_lo.min(q.max_force);
        qf_hi = qf_hi.max(q.max_force);
        qd_hi = qd_hi.max(q.max_approach);
    }
    let mut worst_f: f64 = 0.0;
    let mut worst_d: f64 = 0.0;
    for i in (n * 5 / 6)..n {
        for k in 0..2 {
            let row = &f[(i * 2 + k) * 24..(i * 2 + k + 1) * 24];
            let prow = &pen[(i * 2 + k) * 24..(i * 2 + k + 1) * 24];
            worst_f = worst_f.max(row.iter().cloned().fold(0.0, f64::max));
            worst_d = worst_d.max(prow.iter().cloned().fold(0.0, f64::max));
            assert!((11.0..=13.0).contains(&lp[i * 2 + k]), "{}", lp[i * 2 + k]);
        }
    }
    eprintln!(
        "dynamic peak {worst_f:.0} N, {:.2} um; quasi-static {qf_lo:.0}-{qf_hi:.0} N, {:.2} um",
        worst_d * 1e6,
        qd_hi * 1e6
    );
    assert!(
        worst_f <= 1.02 * qf_hi && worst_f >= 0.98 * qf_lo,
        "{worst_f}"
    );
    assert!((worst_d / qd_hi - 1.0).abs() < 0.02, "{worst_d} vs {qd_hi}");
}

/// Modes `(frequency [Hz], damping ratio)` of the linearised free system at `st`, from the
/// eigenvalues of `[[0, I], [da/dq, da/dv]]` (central differences).
fn modes<S: MechanicalSystem>(sys: &S, st: &State) -> Vec<(f64, f64)> {
    let n = sys.dof();
    let mut p = [0.0; 3];
    let mut big = nalgebra::DMatrix::<f64>::zeros(2 * n, 2 * n);
    for i in 0..n {
        big[(i, n + i)] = 1.0;
    }
    for k in 0..n {
        for (col, h) in [(k, 1e-10), (n + k, 1e-7)] {
            let (mut qp, mut qm, mut vp, mut vm) =
                (st.q.clone(), st.q.clone(), st.v.clone(), st.v.clone());
            if col < n {
                qp[k] += h;
                qm[k] -= h;
            } else {
                vp[k] += h;
                vm[k] -= h;
            }
            let (mut ap, mut am) = (vec![0.0; n], vec![0.0; n]);
            sys.eval(st.t, &qp, &vp, &mut ap, &mut p).unwrap();
            sys.eval(st.t, &qm, &vm, &mut am, &mut p).unwrap();
            for i in 0..n {
                big[(n + i, col)] = (ap[i] - am[i]) / (2.0 * h);
            }
        }
    }
    let mut out: Vec<(f64, f64)> = big
        .complex_eigenvalues()
        .iter()
        .filter(|l| l.im > 0.0)
        .map(|l| (l.norm() / std::f64::consts::TAU, -l.re / l.norm()))
        .collect();
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    out
}

#[test]
fn main_torsional_mode_has_the_damping_ratio_the_preset_sets() {
    // Linearised at rated load after 40 ms at speed: the lowest mode is the main torsional
    // mode; every damper of the preset is stiffness-proportional with beta = 2 zeta / w_ref, so
    // a mode at w has zeta w / w_ref (Rayleigh damping), up to the undamped geometric
    // stiffness of the contacts. Tolerance 5 % of the ratio and 3 % of the frequency (the
    // mode moves with the crank angle and the mesh position).
    let s = steady("rated");
    let m = CompliantModel::new(&s).unwrap();
    let (q, v) = m.initial_state();
    let mut st = State::new(&m, 0.0, q, v).unwrap();
    let mut ga = GeneralizedAlpha::new(0.8, 1e-10, false).unwrap();
    for _ in 0..4000 {
        ga.step(&m, &mut st, 1e-5).unwrap();
    }
    let md = modes(&m, &st);
    let (f0, z0) = md[0];
    eprintln!("lowest modes {:?}", &md[..4]);
    assert!(
        (f0 / PHYSICAL_REFERENCE_FREQUENCY - 1.0).abs() < 0.03,
        "main mode {f0} Hz"
    );
    assert!(
        (z0 / PHYSICAL_DAMPING_RATIO - 1.0).abs() < 0.05,
        "damping ratio {z0}"
    );
    // The paper preset's main mode is overdamped (no complex pair at all at rated load).
    let mut p = Scene::paper("rated").unwrap();
    p.initial = Initial::Steady;
    let pm = rvdyn::dynamics::RigidModel::new(&p).unwrap();
    let sys = rvdyn::dynamics::model::rigid_system::RigidSystem::new(&pm);
    let (q, v) = sys.initial_state();
    let mut st = State::new(&sys, 0.0, q, v).unwrap();
    let mut ga = GeneralizedAlpha::new(0.8, 1e-10, false).unwrap();
    for _ in 0..4000 {
        ga.step(&sys, &mut st, 1e-5).unwrap();
    }
    assert!(modes(&sys, &st).is_empty());
}

#[test]
fn reversed_run_mirrors_the_forward_run() {
    // Mirror image about the x axis: pins j <-> 24 - j, cranks i <-> 3 - i, carrier and crank
    // angles change sign. Compliant joints, 5 ms from the steady state at rated load.
    let fwd = steady("rated");
    let mut rev = fwd.clone();
    rev.drive = Drive::Speed {
        speed: -PAPER_INPUT_SPEED,
        start: StartKind::Step,
        ramp_time: 0.0,
    };
    let Load::Constant { torque } = fwd.load else {
        panic!()
    };
    rev.load = Load::Constant { torque: -torque };
    // A fixed step gives both runs the same step sequence (an adaptive one would choose steps
    // from round-off-different error estimates and differ at its tolerance).
    let fixed = |s: &Scene| {
        let mut opt = SimOptions::new(0.005, Method::Rk4);
        opt.dt = Some(2e-6);
        opt.record_interval = Some(5e-5);
        simulate(s, &opt, &RunControl::default()).unwrap()
    };
    let (a, b) = (fixed(&fwd), fixed(&rev));
    assert_eq!(a.samples, b.samples);
    let n = a.samples;
    let scale_f = data(&a, "pin_force").iter().cloned().fold(0.0, f64::max);
    let mut worst_f: f64 = 0.0;
    let mut worst_te: f64 = 0.0;
    let (ca, cb) = (data(&a, "carrier_angle"), data(&b, "carrier_angle"));
    let (sa, sb) = (data(&a, "sun_angle"), data(&b, "sun_angle"));
    let (fa, fb) = (data(&a, "pin_force"), data(&b, "pin_force"));
    let (ma, mb) = (data(&a, "mesh_force"), data(&b, "mesh_force"));
    // The coast flank's deflection was reported along the drive flank's line of action (6.7 %
    // off the mirror image on the physical preset).
    let (da, db) = (data(&a, "mesh_deflection"), data(&b, "mesh_deflection"));
    let scale_d = da.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut worst_d: f64 = 0.0;
    let scale_te = (sa[n - 1] / 57.0 - ca[n - 1]).abs();
    for i in 0..n {
        // Transmission error: carrier lag behind the kinematic angle.
        let te_a = sa[i] / 57.0 - ca[i];
        let te_b = sb[i] / 57.0 - cb[i];
        worst_te = worst_te.max((te_a + te_b).abs());
        for k in 0..2 {
            for j in 0..24 {
                let jm = (24 - j) % 24;
                let x = fa[(i * 2 + k) * 24 + j];
                let y = fb[(i * 2 + k) * 24 + jm];
                worst_f = worst_f.max((x - y).abs());
            }
        }
        for c in 0..3 {
            let cm = (3 - c) % 3;
            worst_f = worst_f.max((ma[i * 3 + c] + mb[i * 3 + cm]).abs());
            worst_d = worst_d.max((da[i * 3 + c] + db[i * 3 + cm]).abs());
        }
    }
    assert!(
        worst_d <= 1e-9 * scale_d,
        "mesh deflection {worst_d} of {scale_d}"
    );
    eprintln!(
        "mirror: pin/mesh force {:.2e} of {scale_f:.0} N, TE {:.2e} of {scale_te:.2e} rad",
        worst_f, worst_te
    );
    assert!(worst_f <= 1e-9 * scale_f, "{worst_f} of {scale_f}");
    assert!(
        worst_te <= 1e-9 * scale_te.max(1e-12),
        "{worst_te} of {scale_te}"
    );
}

#[test]
fn energy_balance_closes_with_the_varying_mesh_stiffness() {
    // From rest along the preset's ramp: input work = output work + kinetic + elastic energy +
    // dissipation, to 1e-6 of the input work (dopri5 at tight tolerances).
    let s = Scene::physical("rated").unwrap();
    let r = run(&s, 0.02, 1e-9, 1e-12);
    let n = r.samples;
    let res = data(&r, "energy_residual")[n - 1];
    let win = data(&r, "input_work")[n - 1];
    eprintln!("energy residual {res:e} J of input work {win:e} J");
    assert!(win.abs() > 1.0);
    assert!(res.abs() < 1e-6 * win.abs(), "{res} of {win}");
}

fn with_friction(pin: f64, mesh: f64) -> Scene {
    let mut s = steady("rated");
    s.friction = rvdyn::dynamics::scene::Friction {
        pin,
        mesh,
        ..Default::default()
    };
    s
}

#[test]
fn efficiency_matches_the_analytic_estimate() {
    // Steady window of 40 ms after 20 ms at speed; efficiency = output work / input work.
    // Reference: analysis::efficiency::rv_efficiency (pin sliding loss from the classical load
    // distribution, Niemann-Winter tooth loss factor); requirement 2 percentage points.
    for (mu_pin, mu_mesh) in [(0.05, 0.05), (0.1, 0.05)] {
        let s = with_friction(mu_pin, mu_mesh);
        let r = run(&s, 0.06, 1e-7, 1e-10);
        let n = r.samples;
        let (wi, wo) = (data(&r, "input_work"), data(&r, "output_work"));
        let i0 = n / 3;
        let eta = (wo[n - 1] - wo[i0]) / (wi[n - 1] - wi[i0]);
        let an = rvdyn::analysis::efficiency::rv_efficiency(
            &s.cycloid,
            18,
            42,
            3e-3,
            20f64.to_radians(),
            57.0,
            mu_pin,
            1.0,
            mu_mesh,
        )
        .unwrap();
        eprintln!(
            "mu {mu_pin}/{mu_mesh}: simulated {eta:.4}, analytic {:.4}",
            an.efficiency
        );
        assert!((eta - an.efficiency).abs() < 0.02, "{eta} vs {:?}", an);
        // The energy balance closes with friction counted.
        let res = data(&r, "energy_residual")[n - 1];
        assert!(res.abs() < 1e-6 * wi[n - 1].abs(), "{res} of {}", wi[n - 1]);
    }
}

#[test]
fn zero_friction_gives_back_the_frictionless_run() {
    let a = run(&steady("rated"), 0.004, 1e-7, 1e-10);
    let b = run(&with_friction(0.0, 0.0), 0.004, 1e-7, 1e-10);
    for name in ["carrier_angle", "pin_force", "mesh_force"] {
        assert_eq!(data(&a, name), data(&b, name), "{name}");
    }
}

#[test]
fn nonsense_parameters_are_scene_errors_naming_the_field() {
    let cases: Vec<(&str, serde_json::Value, &str)> = vec![
        ("friction.pin", serde_json::json!(1.5), "friction.pin"),
        ("friction.mesh", serde_json::json!(-0.1), "friction.mesh"),
        (
            "friction.pin_rolling",
            serde_json::json!(0.0),
            "pin_rolling",
        ),
        (
            "joints.eccentric_bearing.rollers.count",
            serde_json::json!(0),
            "count",
        ),
        (
            "joints.eccentric_bearing.clearance",
            serde_json::json!(-1e-6),
            "clearance",
        ),
        (
            "contact.pin.damping.ratio",
            serde_json::json!(-0.1),
            "damping",
        ),
        (
            "pin_errors.radius",
            serde_json::json!([
                1e-3, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
                0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
            ]),
            "conformal",
        ),
    ];
    let base = Scene::physical("rated").unwrap();
    let tree = serde_json::to_value(&base).unwrap();
    for (path, value, needle) in cases {
        let mut t = tree.clone();
        let mut node = &mut t;
        let keys: Vec<&str> = path.split('.').collect();
        for k in &keys[..keys.len() - 1] {
            node = node.get_mut(*k).unwrap();
        }
        node[keys[keys.len() - 1]] = value;
        let err = Scene::from_json(&t.to_string()).unwrap_err();
        assert!(err.to_string().contains(needle), "{path}: {err}");
    }
}

/// Mean distance of disc 0's centre from the axis over the second half of a run.
fn path_radius(r: &Recording) -> f64 {
    let n = r.samples;
    let c = data(r, "disc_center");
    let (mut acc, mut cnt) = (0.0, 0.0);
    for i in n / 2..n {
        acc += c[i * 4].hypot(c[i * 4 + 1]);
        cnt += 1.0;
    }
    acc / cnt
}

#[test]
fn equal_eccentricity_error_shifts_the_disc_path_radius_by_that_error() {
    // Linear joints without clearance at idle and speed, a modified profile (20 um of
    // clearance to the pins, so that no pin holds the disc): the centrifugal deflection of
    // the bearings is the same with and without the error, so the path radius moves by
    // exactly the error (to the dynamic ripple: 1 % of 10 um).
    let mut s = Scene::paper("idle").unwrap();
    s.joints = rvdyn::dynamics::model::compliant::default_joints();
    s.cycloid.d_rrp = 20e-6;
    s.cycloid.d_rp = -20e-6;
    s.initial = Initial::Steady;
    let base = path_radius(&run(&s, 0.02, 1e-8, 1e-11));
    s.errors.crank_eccentricity = vec![10e-6; 3];
    let shifted = path_radius(&run(&s, 0.02, 1e-8, 1e-11));
    eprintln!("path radius {base:.9} -> {shifted:.9} m");
    assert!(
        ((shifted - base) - 10e-6).abs() < 0.1e-6,
        "{}",
        shifted - base
    );
    // Errors need compliant joints.
    let mut rigid = Scene::paper("idle").unwrap();
    rigid.errors.crank_phase = vec![1e-4; 3];
    assert!(rigid.validate().is_err());
    // Wrong lengths are named.
    s.errors.crank_eccentricity = vec![1e-6; 2];
    let e = s.validate().unwrap_err();
    assert!(e.to_string().contains("crank_eccentricity"), "{e}");
}

#[test]
fn equal_hole_error_moves_the_disc_by_that_error() {
    // The same hole error (disc frame) on all three holes of disc 0 moves disc 0's centre by
    // minus that error turned by the disc angle, and leaves disc 1 where it was (1 % of 10 um;
    // modified profile so that no pin holds the disc at idle).
    let mut s = Scene::paper("idle").unwrap();
    s.joints = rvdyn::dynamics::model::compliant::default_joints();
    s.cycloid.d_rrp = 20e-6;
    s.cycloid.d_rp = -20e-6;
    s.initial = Initial::Steady;
    let a = run(&s, 0.01, 1e-8, 1e-11);
    s.errors.disc_holes = vec![
        [10e-6, 0.0],
        [0.0, 0.0],
        [10e-6, 0.0],
        [0.0, 0.0],
        [10e-6, 0.0],
        [0.0, 0.0],
    ];
    let b = run(&s, 0.01, 1e-8, 1e-11);
    let n = a.samples;
    let (ca, cb) = (data(&a, "disc_center"), data(&b, "disc_center"));
    let th = data(&b, "disc_angle")[(n - 1) * 2];
    let want = [-10e-6 * th.cos(), -10e-6 * th.sin()];
    let got = [
        cb[(n - 1) * 4] - ca[(n - 1) * 4],
        cb[(n - 1) * 4 + 1] - ca[(n - 1) * 4 + 1],
    ];
    eprintln!("hole error: disc 0 moved {got:?}, expected {want:?}");
    assert!((got[0] - want[0]).abs() < 0.1e-6 && (got[1] - want[1]).abs() < 0.1e-6);
    let other = [
        cb[(n - 1) * 4 + 2] - ca[(n - 1) * 4 + 2],
        cb[(n - 1) * 4 + 3] - ca[(n - 1) * 4 + 3],
    ];
    assert!(other[0].hypot(other[1]) < 0.1e-6, "{other:?}");
}

#[test]
fn bearing_friction_closes_the_energy_balance_and_costs_efficiency() {
    // Palmgren torques on the roller bearings (f0 3, f1 3e-4, 68 cSt): positive friction power,
    // the energy balance still closes (1e-6 of the input work), efficiency below 1.
    let mut s = with_friction(0.0, 0.0);
    s.friction.bearing = Some(rvdyn::dynamics::scene::BearingFriction {
        f0: 3.0,
        f1: 3e-4,
        viscosity: 68e-6,
    });
    let r = run(&s, 0.03, 1e-7, 1e-10);
    let n = r.samples;
    let p = data(&r, "bearing_friction_power");
    let mean = p[n / 2..].iter().sum::<f64>() / (n - n / 2) as f64;
    let (wi, wo) = (data(&r, "input_work"), data(&r, "output_work"));
    let eta = (wo[n - 1] - wo[n / 2]) / (wi[n - 1] - wi[n / 2]);
    eprintln!("bearing friction power {mean:.0} W, efficiency {eta:.4}");
    assert!(mean > 0.0 && eta < 0.999, "{mean} {eta}");
    let res = data(&r, "energy_residual")[n - 1];
    assert!(res.abs() < 1e-6 * wi[n - 1].abs(), "{res}");
}

/// From rest, the physical preset's roller dampers switch on and off within picoseconds (held
/// at zero by "never pull" at first touch). At atol 3e-9 m the adaptive generalized-alpha's rows
/// of rejections shrank the step below `h_min` at t = 2.48e-5 s (a `SimulationError`, with no
/// samples recorded: `count_work run 0.0001 generalized-alpha-adaptive physical - 3e-9 3e-5`);
/// a step whose error per step is within the tolerance is now taken there instead. The end
/// coordinates (angles in rad, translations in m) agree with dopri5 at atol 1e-12 m, rtol 1e-8
/// to 3e-8, ten times the tolerance asked (measured 3.9e-9).
#[test]
fn the_adaptive_start_at_a_tight_tolerance_does_not_collapse_the_step() {
    let scene = Scene::physical("rated").unwrap();
    let run = |method: &str, atol: f64, rtol: f64| {
        let mut opt = SimOptions::new(1e-4, Method::parse(method).unwrap());
        (opt.atol, opt.rtol) = (atol, rtol);
        opt.channels = vec![];
        simulate(&scene, &opt, &RunControl::default()).unwrap()
    };
    let r = run("generalized-alpha-adaptive", 3e-9, 3e-5);
    let reference = run("dopri5", 1e-12, 1e-8);
    let nonsmooth = r
        .stats
        .counts
        .iter()
        .find(|(k, _)| *k == "nonsmooth")
        .unwrap()
        .1;
    assert!(nonsmooth >= 1, "{:?}", r.stats);
    let (q, q_ref) = (r.final_state.unwrap().1, reference.final_state.unwrap().1);
    let worst = q
        .iter()
        .zip(&q_ref)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(worst < 3e-8, "end state off by {worst:e}");
}
