//! Tests of the compliant-joint model: energy gradients, power balance, the rigid limit,
//! clearances and the initial state.
use super::*;
use crate::dynamics::run::driver::{RunControl, SimOptions, simulate};
use crate::dynamics::run::recorder::Recording;
use crate::dynamics::scene::{Drive, Load, StartKind};
use crate::solve::dopri5::Dopri5;
use crate::solve::{Method, State};

fn scene(load: &str, joints: Joints, initial: Initial) -> Scene {
    let mut s = Scene::paper(load).unwrap();
    s.joints = joints;
    s.initial = initial;
    s
}

fn joints(k: f64, c: f64, clearance: f64) -> Joints {
    let b = Bearing {
        stiffness: k,
        damping: c,
        clearance,
        rollers: None,
    };
    Joints::Compliant {
        eccentric_bearing: b,
        crank_bearing: Some(b),
    }
}

fn run(s: &Scene, t_end: f64, atol: f64) -> Recording {
    let mut opt = SimOptions::new(t_end, Method::Dopri5);
    opt.atol = atol;
    opt.record_interval = Some(2e-5);
    simulate(s, &opt, &RunControl::default()).unwrap()
}

fn series<'a>(r: &'a Recording, name: &str) -> &'a [f64] {
    &r.series[name].data
}

fn mean_speed(r: &Recording) -> f64 {
    let (t, a) = (series(r, "t"), series(r, "carrier_angle"));
    let n = t.len();
    (a[n - 1] - a[n / 2]) / (t[n - 1] - t[n / 2])
}

fn peak(v: &[f64]) -> f64 {
    v.iter().cloned().fold(0.0, f64::max)
}

fn last_residual(r: &Recording) -> (f64, f64) {
    let n = r.samples;
    (
        series(r, "energy_residual")[n - 1],
        series(r, "input_work")[n - 1],
    )
}

/// Wants the elastic energy and counts the loaded contacts.
#[derive(Default)]
struct Count {
    pins: usize,
    mesh: usize,
}
impl ContactSink for Count {
    fn wants_energy(&self) -> bool {
        true
    }
    fn pin(&mut self, _: usize, _: usize, f: f64, _: f64, _: f64, _: [f64; 2], _: [f64; 2]) {
        self.pins += usize::from(f > 0.0);
    }
    fn mesh(&mut self, _: usize, f: f64, _: f64) {
        self.mesh += usize::from(f != 0.0);
    }
}

/// At rest (no damping force), every generalised force, prescribed coordinates included,
/// is minus the derivative of the elastic energy (central differences, 1 nm of displacement
/// at each coordinate's lever). Checks every coupling's virtual work, signs and reactions.
/// Tolerance 1e-6 of the largest force: the difference error is about
/// eps V / h ~ 1e-16 * 10 J / 1e-9 m ~ 1e-6 N and h^2 V''' is smaller still.
/// `qf` (the generalised forces at the pose `x`, at rest) is minus the gradient of the model's
/// elastic energy: central differences of 1 nm at each coordinate's lever (carrier and disc
/// angles 0.1 m, the sun `r_bs`, crank angles `e`, lengths 1), to 1e-6 of the largest force.
fn assert_forces_are_minus_the_energy_gradient(
    m: &CompliantModel,
    x: &[f64],
    qf: &[f64],
    case: &str,
) {
    let v = vec![0.0; x.len()];
    let energy = |x: &[f64]| {
        let mut q = vec![0.0; x.len()];
        m.forces(0.0, x, &v, &mut q, &mut Count::default())
            .unwrap()
            .potential
    };
    let fmax = qf.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    let first_node = m
        .bending
        .as_ref()
        .map_or(usize::MAX, |_| m.node_index(0, 0));
    for i in 0..x.len() {
        let l = match i {
            CARRIER => 0.1,
            SUN => m.parts.mesh.map_or(1.0, |mm| mm.sun_base_radius),
            _ if i >= first_node => 1.0,
            _ if (i - 2) % 3 != 2 => 1.0,
            _ if i < m.disc_index(0) => m.parts.eccentricity,
            _ => 0.1,
        };
        let h = 1e-9 / l;
        let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
        xp[i] += h;
        xm[i] -= h;
        let fd = -(energy(&xp) - energy(&xm)) / (2.0 * h);
        assert!(
            (fd - qf[i]).abs() * l <= 1e-6 * fmax,
            "{case}: coordinate {i}: Q = {} but -dV/dq = {fd}",
            qf[i]
        );
    }
}

#[test]
fn generalised_forces_are_minus_the_energy_gradient() {
    // With bending crankshafts too: the eccentric centres are then coordinates of their own,
    // displaced off their crank's line below (a reaction of the shaft left out, or put at the
    // crank centre instead of the eccentric, fails at the crank's centre or angle).
    for (clearance, bending) in [(0.0, false), (2e-6, false), (0.0, true)] {
        let mut s = scene("idle", joints(1e9, 1e4, clearance), Initial::Rest);
        if bending {
            crate::test_util::with_bending_cranks(&mut s);
        }
        let m = CompliantModel::new(&s).unwrap();
        let (mut x, _) = m.full_initial_state();
        let v = vec![0.0; x.len()];
        // A deflected pose: sun ahead (mesh loaded), discs lagging (pins loaded), cranks and
        // discs displaced by micrometres (every bearing loaded, beyond the clearance).
        x[CARRIER] += 1e-5;
        x[SUN] += 1e-3;
        for i in 0..m.cranks {
            let ci = crank_index(i);
            x[ci] += 7e-6 * (i as f64 + 1.0);
            x[ci + 1] -= 5e-6 * (i as f64 - 0.7);
            x[ci + 2] += 2e-3 * (i as f64 + 1.0);
            for k in (0..2).filter(|_| bending) {
                let ni = m.node_index(i, k);
                x[ni] += 3e-6 * (k as f64 + 0.5);
                x[ni + 1] -= 2e-6 * (i as f64 + 0.3);
            }
        }
        assert_eq!(x.len(), if bending { 2 + 9 + 6 + 12 } else { 2 + 9 + 6 });
        for k in 0..2 {
            let dk = m.disc_index(k);
            x[dk] += 6e-6;
            x[dk + 1] -= 4e-6 * (k as f64 + 1.0);
            x[dk + 2] -= 2e-4;
        }
        let mut qf = vec![0.0; x.len()];
        let mut count = Count::default();
        m.forces(0.0, &x, &v, &mut qf, &mut count).unwrap();
        assert!(
            count.pins >= 4 && count.mesh == 3,
            "{} {}",
            count.pins,
            count.mesh
        );
        let (crank, ecc) = m.bearing_deflections(&x);
        assert!(
            crank
                .iter()
                .chain(&ecc)
                .all(|d| d[0].hypot(d[1]) > clearance)
        );
        assert_forces_are_minus_the_energy_gradient(&m, &x, &qf, &format!("clearance {clearance}"));
    }
}

/// Power identity with damping: for a deflected pose moving with arbitrary velocities, the
/// power of all generalised forces (prescribed coordinates included, no load or drive
/// torque) is `-dV/dt - D`: every penetration/deflection rate is the time derivative of its
/// penetration/deflection and the reported dissipation is the dampers' power. dV/dt by
/// central differences along v (1 nm steps); tolerance 1e-7 of sum |Q_i v_i|.
#[test]
fn force_power_is_minus_energy_rate_minus_dissipation() {
    for clearance in [0.0, 2e-6] {
        let s = scene("idle", joints(1e9, 3e4, clearance), Initial::Rest);
        let m = CompliantModel::new(&s).unwrap();
        let (mut x, _) = m.full_initial_state();
        x[SUN] += 1e-3;
        x[CARRIER] += 2e-5;
        let mut v = vec![0.0; x.len()];
        v[CARRIER] = 50.0;
        v[SUN] = 3.0;
        for i in 0..m.cranks {
            let ci = crank_index(i);
            let fi = i as f64;
            x[ci] += 7e-6 * (fi + 1.0);
            x[ci + 1] -= 5e-6 * (fi - 0.7);
            x[ci + 2] += 2e-3 * (fi + 1.0);
            v[ci..ci + 3].copy_from_slice(&[0.03 * (fi - 1.0), -0.02, 4.0 - fi]);
        }
        for k in 0..2 {
            let dk = m.disc_index(k);
            let fk = k as f64;
            x[dk] += 6e-6;
            x[dk + 1] -= 4e-6 * (fk + 1.0);
            x[dk + 2] -= 2e-4;
            v[dk..dk + 3].copy_from_slice(&[0.01 - 0.02 * fk, 0.015, -0.2 + 0.5 * fk]);
        }
        let mut qf = vec![0.0; x.len()];
        let flows = m
            .forces(0.0, &x, &v, &mut qf, &mut Count::default())
            .unwrap();
        let power: f64 = qf.iter().zip(&v).map(|(q, w)| q * w).sum();
        let scale: f64 = qf.iter().zip(&v).map(|(q, w)| (q * w).abs()).sum();
        let h = 1e-9 / 4.5;
        let energy = |sign: f64| {
            let xs: Vec<f64> = x.iter().zip(&v).map(|(a, b)| a + sign * h * b).collect();
            let mut q = vec![0.0; x.len()];
            m.forces(0.0, &xs, &v, &mut q, &mut Count::default())
                .unwrap()
                .potential
        };
        let dvdt = (energy(1.0) - energy(-1.0)) / (2.0 * h);
        let gap = power + dvdt + flows.dissipation;
        assert!(flows.dissipation > 0.0);
        assert!(
            gap.abs() < 1e-7 * scale,
            "clearance {clearance}: power {power} + dV/dt {dvdt} + D {} = {gap} (scale {scale})",
            flows.dissipation
        );
    }
}

/// Very stiff bearings (1e11 N/m; damping 1e6 N s/m, a damping ratio of about 0.4 so the
/// bearing modes the sudden load excites die within ~0.1 ms) reproduce the rigid model on the
/// rated default scene started at steady speed: mean output speed (second half of 10 ms)
/// within 1e-4, peak pin force over the run and every pin force at the end within 1 % (they
/// agree to ~0.05 %); 1e12 N/m is closer still (the rigid model is the limit).
#[test]
fn stiff_bearings_reproduce_the_rigid_model() {
    let t_end = 0.01;
    let rigid = run(&scene("rated", Joints::Rigid, Initial::Steady), t_end, 1e-9);
    let f_rigid = series(&rigid, "pin_force");
    let n = f_rigid.len();
    let last = |f: &[f64]| f[n - 48..].to_vec();
    let mut errors = Vec::new();
    for (k, c) in [(1e11, 1e6), (1e12, 3e6)] {
        let r = run(
            &scene("rated", joints(k, c, 0.0), Initial::Steady),
            t_end,
            1e-9,
        );
        let f = series(&r, "pin_force");
        let speed = mean_speed(&r) / mean_speed(&rigid) - 1.0;
        assert!(
            speed.abs() < 1e-4,
            "k = {k}: mean output speed differs by {speed:e}"
        );
        let dpeak = peak(f) / peak(f_rigid) - 1.0;
        assert!(
            dpeak.abs() < 0.01,
            "k = {k}: peak pin force differs by {dpeak:e}"
        );
        let dlast = last(f)
            .iter()
            .zip(last(f_rigid))
            .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()))
            / peak(f_rigid);
        assert!(
            dlast < 0.01,
            "k = {k}: pin forces at the end differ by {dlast:e}"
        );
        errors.push(dpeak.abs() + dlast);
    }
    assert!(errors[1] < errors[0], "{errors:?}");
}

/// Default bearings at rated load (steady start): the disc centres stay on a circle of
/// radius e within 1 % (the bearing deflections are tens of micrometres, mostly
/// tangential), but they do leave the rigid path (the joints are compliant: > 1 um).
#[test]
fn disc_centre_path_radius_is_the_eccentricity() {
    let s = scene("rated", default_joints(), Initial::Steady);
    let r = run(&s, 0.01, 1e-9);
    let e = s.cycloid.eccentricity;
    let (c, alpha) = (series(&r, "disc_center"), series(&r, "crank_angle"));
    let (mut worst, mut off_rigid) = (0.0f64, 0.0f64);
    for (i, p) in c.chunks(4).enumerate() {
        for k in 0..2 {
            let (x, y) = (p[2 * k], p[2 * k + 1]);
            worst = worst.max((x.hypot(y) / e - 1.0).abs());
            // Rigid path: O_k = e (cos(alpha + a_k), sin(..)), alpha = mean crank angle.
            let a = alpha[3 * i..3 * i + 3].iter().sum::<f64>() / 3.0 + s.discs[k].phase;
            off_rigid = off_rigid.max((x - e * a.cos()).hypot(y - e * a.sin()));
        }
    }
    assert!(worst < 0.01, "disc path radius deviates by {worst:e} of e");
    assert!(off_rigid > 1e-6, "{off_rigid:e}");
}

/// The energy balance closes on damped runs (contact damping, bearing damping, a step
/// start with its impact): |residual| < 1e-4 of the input work with dopri5 at atol 1e-10.
/// Covers the prescribed sun, a torque drive on the sun, and a single-stage reducer whose
/// cranks are the input (prescribed speed, or a torque shared by the cranks).
fn rigid_cranks(k: f64, c: f64) -> Joints {
    Joints::Compliant {
        eccentric_bearing: Bearing {
            stiffness: k,
            damping: c,
            clearance: 0.0,
            rollers: None,
        },
        crank_bearing: None,
    }
}

#[test]
fn rigid_crank_bearings_drop_the_crank_translations() {
    // 16 DOF with both families compliant, 10 with rigid crank bearings.
    let both = CompliantModel::new(&scene("rated", default_joints(), Initial::Rest)).unwrap();
    let ecc = CompliantModel::new(&scene("rated", rigid_cranks(1e9, 1e4), Initial::Rest)).unwrap();
    assert_eq!(both.dof(), 16);
    assert_eq!(ecc.dof(), 10);
    // With stiff eccentric bearings it is the rigid model again.
    let t_end = 0.01;
    let rigid = run(&scene("rated", Joints::Rigid, Initial::Steady), t_end, 1e-9);
    let stiff = run(
        &scene("rated", rigid_cranks(1e12, 3e6), Initial::Steady),
        t_end,
        1e-9,
    );
    let (fr, fs) = (series(&rigid, "pin_force"), series(&stiff, "pin_force"));
    let n = fr.len();
    let worst = fr[n - 48..]
        .iter()
        .zip(&fs[n - 48..])
        .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
    assert!(worst < 0.01 * peak(fr), "pin forces differ by {worst} N");
    let speed = mean_speed(&stiff) / mean_speed(&rigid) - 1.0;
    assert!(speed.abs() < 1e-4, "{speed:e}");
    // The energy balance closes with the crank mass moving with the carrier.
    let r = run(
        &scene("paper", rigid_cranks(1e9, 1e4), Initial::Rest),
        0.006,
        1e-10,
    );
    let (res, win) = last_residual(&r);
    assert!(
        res.abs() < 1e-4 * win.abs(),
        "residual {res:e} J of {win:e} J"
    );
}

#[test]
fn energy_balance_closes() {
    let mut cases = vec![scene("paper", default_joints(), Initial::Rest)];
    let mut torque = scene("paper", default_joints(), Initial::Rest);
    torque.drive = Drive::Torque {
        torque: 800.0,
        ramp_time: 1e-3,
    };
    cases.push(torque);
    let mut single = scene("idle", default_joints(), Initial::Rest);
    single.stage1 = None;
    single.load = Load::Constant { torque: -2000.0 };
    single.drive = Drive::Speed {
        speed: 150.0,
        start: StartKind::Ramp,
        ramp_time: 2e-3,
    };
    cases.push(single.clone());
    single.drive = Drive::Torque {
        torque: 100.0,
        ramp_time: 1e-3,
    };
    single.load = Load::Constant { torque: 500.0 };
    cases.push(single);
    for s in &cases {
        let r = run(s, 0.006, 1e-10);
        let (res, win) = last_residual(&r);
        let dis = series(&r, "dissipated_energy")[r.samples - 1];
        eprintln!(
            "{:?}: residual {res:e} J of input work {win:e} J, dissipated {dis:e} J",
            s.drive
        );
        assert!(win.abs() > 1.0 && dis > 0.0, "{:?}: {win} {dis}", s.drive);
        assert!(
            res.abs() < 1e-4 * win.abs(),
            "{:?}: residual {res:e} J of input work {win:e} J",
            s.drive
        );
    }
}

/// With radial clearances (10 um eccentric, 5 um crank) and a step start from rest, the
/// bearing contacts open and close many times; the state stays finite and the energy balance
/// still closes (< 1e-4 of the input work).
#[test]
fn bearing_clearance_opens_and_closes() {
    let b = |k, c| Bearing {
        stiffness: k,
        damping: 1e4,
        clearance: c,
        rollers: None,
    };
    let s = scene(
        "idle",
        Joints::Compliant {
            eccentric_bearing: b(1e9, 10e-6),
            crank_bearing: Some(b(2e9, 5e-6)),
        },
        Initial::Rest,
    );
    let m = CompliantModel::new(&s).unwrap();
    let (q0, v0) = m.initial_state();
    let mut st = State::new(&m, 0.0, q0, v0).unwrap();
    let energy = |st: &State| {
        let o = m
            .observe(st.t, &st.q, &st.v, &mut Count::default())
            .unwrap();
        o.kinetic_energy + o.potential_energy
    };
    let e0 = energy(&st);
    let mut dp = Dopri5::new(1e-6, 1e-10, 1e-6, 2e-5);
    let nb = m.cranks * 3;
    let mut closed = vec![false; nb];
    let (mut opens, mut closes) = (vec![0; nb], vec![0; nb]);
    let t_end = 0.006;
    while st.t < t_end {
        dp.step(&m, &mut st, t_end).unwrap();
        assert!(st.q.iter().chain(&st.v).all(|v| v.is_finite()));
        let (x, _, _) = m.full(st.t, &st.q, &st.v);
        let (crank, ecc) = m.bearing_deflections(&x);
        for (i, d) in crank.iter().chain(&ecc).enumerate() {
            let c = if i < m.cranks { 5e-6 } else { 10e-6 };
            let now = d[0].hypot(d[1]) > c;
            closes[i] += usize::from(now && !closed[i]);
            opens[i] += usize::from(!now && closed[i]);
            closed[i] = now;
        }
    }
    eprintln!("opens {opens:?} closes {closes:?}");
    let crank_opens: usize = opens[..m.cranks].iter().sum();
    let ecc_opens: usize = opens[m.cranks..].iter().sum();
    assert!(
        crank_opens >= 3 && ecc_opens >= 6,
        "opens {opens:?} closes {closes:?}"
    );
    assert!(closes.iter().all(|&c| c >= 1), "closes {closes:?}");
    let residual = energy(&st) - e0 - st.work[0] + st.work[1] + st.work[2];
    eprintln!("clearance residual {residual:e} of {:e}", st.work[0]);
    assert!(
        residual.abs() < 1e-4 * st.work[0].abs(),
        "{residual:e} of {:e}",
        st.work[0]
    );
}

#[test]
fn scenes_without_compliant_joints_are_refused() {
    let s = Scene::paper("idle").unwrap();
    let e = CompliantModel::new(&s).unwrap_err().to_string();
    assert!(e.contains("compliant"), "{e}");
    let s = scene("idle", joints(-1.0, 0.0, 0.0), Initial::Rest);
    assert!(CompliantModel::new(&s).is_err());
}

/// The kinematic initial state has undeflected bearings, and its steady-speed velocities
/// keep them undeflected to first order (d' = 0).
#[test]
fn steady_initial_state_is_kinematic() {
    let s = scene("rated", default_joints(), Initial::Steady);
    let m = CompliantModel::new(&s).unwrap();
    let (x, v) = m.full_initial_state();
    let (crank, ecc) = m.bearing_deflections(&x);
    assert!(crank.iter().chain(&ecc).all(|d| d[0].hypot(d[1]) < 1e-15));
    let h = 1e-6;
    let xh: Vec<f64> = x.iter().zip(&v).map(|(a, b)| a + h * b).collect();
    let (crank, ecc) = m.bearing_deflections(&xh);
    let worst = crank
        .iter()
        .chain(&ecc)
        .fold(0.0f64, |a, d| a.max(d[0].hypot(d[1])));
    // Second order: e (zc w h)^2 / 2 ~ 8e-12 m.
    assert!(worst < 2e-11, "{worst:e}");
    let w = v[CARRIER] * 57.0 / crate::dynamics::scene::PAPER_INPUT_SPEED;
    assert!((w - 1.0).abs() < 1e-12);
}

#[test]
fn skipping_separated_pins_gives_the_same_forces() {
    // As for the rigid model: along a loaded trajectory of a modified profile (many pins
    // clear), the model that skips separated pins and one that queries every pin give the same
    // generalised forces, also at states off the trajectory (the disc pushed sideways). Only
    // round-off may differ (different Newton warm starts): 1e-9 of the largest force.
    let mut s = scene(
        "rated",
        crate::dynamics::model::compliant::default_joints(),
        Initial::Rest,
    );
    s.cycloid.d_rrp = 2e-5;
    s.cycloid.d_rp = -2e-5;
    let skipping = CompliantModel::new(&s).unwrap();
    let mut fresh = CompliantModel::new(&s).unwrap();
    fresh.skip_separated = false;
    let (q, v) = skipping.initial_state();
    let mut st = State::new(&skipping, 0.0, q, v).unwrap();
    let mut ga = crate::solve::generalized_alpha::GeneralizedAlpha::new(0.8, 1e-9, false).unwrap();
    let n = skipping.full_len();
    let (mut qa, mut qb) = (vec![0.0; n], vec![0.0; n]);
    let (mut worst, mut scale, mut skipped) = (0.0f64, 0.0f64, 0usize);
    let dk = skipping.disc_index(0);
    for step in 0..200 {
        ga.step(&skipping, &mut st, 1e-4).unwrap();
        for wobble in [0.0, 3e-6, -2e-5] {
            let (mut x, xv, _) = skipping.full(st.t, &st.q, &st.v);
            x[dk] += wobble * ((step % 7) as f64 - 3.0);
            skipping
                .forces(st.t, &x, &xv, &mut qa, &mut NoSink)
                .unwrap();
            fresh.forces(st.t, &x, &xv, &mut qb, &mut NoSink).unwrap();
            for i in 0..n {
                worst = worst.max((qa[i] - qb[i]).abs());
                scale = scale.max(qb[i].abs());
            }
        }
        skipped += skipping
            .separation
            .iter()
            .filter(|b| b.get().gap > 0.0)
            .count();
    }
    assert!(skipped > 0, "the modified profile leaves pins clear");
    assert!(
        worst <= 1e-9 * scale,
        "skip changes the forces by {worst:e} of {scale:e}"
    );
}
