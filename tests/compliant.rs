//! Integration tests of the compliant-joint model through the public driver `simulate`.

use rvdyn::dynamics::model::compliant::default_joints;
use rvdyn::dynamics::run::recorder::Recording;
use rvdyn::dynamics::scene::{Initial, Joints};
use rvdyn::dynamics::{RunControl, Scene, SimOptions, simulate};
use rvdyn::solve::Method;
use std::time::Instant;

fn scene(load: &str, joints: Joints, initial: Initial) -> Scene {
    let mut s = Scene::paper(load).unwrap();
    s.joints = joints;
    s.initial = initial;
    s
}

fn run(s: &Scene, method: Method, t_end: f64, dt: Option<f64>) -> (Recording, f64) {
    let mut opt = SimOptions::new(t_end, method);
    opt.dt = dt;
    let t0 = Instant::now();
    let r = simulate(s, &opt, &RunControl::default()).unwrap();
    (r, t0.elapsed().as_secs_f64())
}

/// Mean carrier speed over the second half of a run [rad/s].
fn mean_speed(r: &Recording) -> f64 {
    let t = &r.series["t"].data;
    let a = &r.series["carrier_angle"].data;
    let n = t.len();
    (a[n - 1] - a[n / 2]) / (t[n - 1] - t[n / 2])
}

/// Largest pin force over the second half of a run [N].
fn peak_pin_force(r: &Recording) -> f64 {
    let f = &r.series["pin_force"].data;
    f[f.len() / 2..].iter().cloned().fold(0.0, f64::max)
}

/// `simulate` with compliant joints records every channel with the layout's shapes (3 cranks,
/// 2 discs, 24 pins, 3 meshes), finite values, and three independent crank rotations.
#[test]
fn simulate_compliant_records_all_channels() {
    use rvdyn::dynamics::run::recorder::Channel;
    let s = scene("paper", default_joints(), Initial::Steady);
    let mut opt = SimOptions::new(2e-3, Method::GeneralizedAlpha);
    opt.dt = Some(2e-5);
    opt.record_interval = Some(1e-4);
    opt.channels = vec![
        Channel::Motion,
        Channel::Pins,
        Channel::ContactPoints,
        Channel::Mesh,
        Channel::Energy,
        Channel::Bearings,
    ];
    let r = simulate(&s, &opt, &RunControl::default()).unwrap();
    assert_eq!(r.samples, 21);
    let expected: &[(&str, &[usize])] = &[
        ("t", &[]),
        ("sun_angle", &[]),
        ("sun_speed", &[]),
        ("carrier_angle", &[]),
        ("carrier_speed", &[]),
        ("crank_angle", &[3]),
        ("crank_speed", &[3]),
        ("disc_center", &[2, 2]),
        ("disc_angle", &[2]),
        ("load_angle", &[]),
        ("load_speed", &[]),
        ("motor_angle", &[]),
        ("motor_speed", &[]),
        ("pin_force", &[2, 24]),
        ("pin_penetration", &[2, 24]),
        ("pin_moment", &[2, 24]),
        ("loaded_pins", &[2]),
        ("pin_point", &[2, 24, 2]),
        ("pin_normal", &[2, 24, 2]),
        ("mesh_force", &[3]),
        ("mesh_deflection", &[3]),
        ("input_torque", &[]),
        ("output_shaft_torque", &[]),
        ("input_shaft_torque", &[]),
        ("kinetic_energy", &[]),
        ("potential_energy", &[]),
        ("input_work", &[]),
        ("output_work", &[]),
        ("dissipated_energy", &[]),
        ("energy_residual", &[]),
        ("pin_friction_power", &[]),
        ("mesh_friction_power", &[]),
        ("bearing_friction_power", &[]),
        ("crank_bearing_force", &[3, 2]),
        ("eccentric_bearing_force", &[3, 2, 2]),
        ("crank_deflection", &[3, 2, 2]),
    ];
    assert_eq!(r.series.len(), expected.len());
    for (name, shape) in expected {
        let series = &r.series[name];
        assert_eq!(&series.sample_shape[..], *shape, "{name}");
        let per: usize = shape.iter().product();
        assert_eq!(series.data.len(), 21 * per, "{name}");
        assert!(series.data.iter().all(|v| v.is_finite()), "{name}");
    }
    let loaded = &r.series["loaded_pins"].data;
    assert!(
        loaded[loaded.len() - 2..].iter().all(|&n| n >= 3.0),
        "{loaded:?}"
    );
    let speed = &r.series["crank_speed"].data;
    let last = &speed[speed.len() - 3..];
    assert!(last[0] != last[1] && last[1] != last[2], "{last:?}");
    let torque = r.series["input_torque"].data[20];
    assert!(
        (torque - 4024.9 / 57.0).abs() < 0.3 * 4024.9 / 57.0,
        "{torque}"
    );
}

/// The release-mode report: 0.2 s of the rated default scene with the default compliant
/// bearings (generalized-alpha dt 2e-5 and the default step, dopri5) against the rigid model.
/// Ignored by default
/// (run `cargo test --release --test compliant -- --ignored --nocapture`).
#[test]
#[ignore]
fn report_rated_default_scene() {
    let theory = rvdyn::dynamics::scene::PAPER_INPUT_SPEED / 57.0;
    for (name, joints) in [("rigid", Joints::Rigid), ("compliant", default_joints())] {
        for (method, dt) in [
            (Method::GeneralizedAlpha, Some(2e-5)),
            (Method::GeneralizedAlpha, None),
            (Method::Dopri5, None),
        ] {
            let s = scene("rated", joints, Initial::Rest);
            let (r, wall) = run(&s, method, 0.2, dt);
            let n = r.samples;
            let res = r.series["energy_residual"].data[n - 1];
            let win = r.series["input_work"].data[n - 1];
            let all_peak = r.series["pin_force"]
                .data
                .iter()
                .cloned()
                .fold(0.0, f64::max);
            let e = s.cycloid.eccentricity;
            let path = r.series["disc_center"]
                .data
                .chunks(2)
                .fold(0.0f64, |a, p| a.max((p[0].hypot(p[1]) / e - 1.0).abs()));
            println!(
                "{name:9} {:17} wall {wall:6.3} s  mean speed rel err {:+.3e}  peak pin force \
                 whole run {all_peak:8.1} N, 2nd half {:8.1} N  max |r/e - 1| {path:.2e}  \
                 energy residual {res:+.3e} J of {win:.4e} J  stats {:?}",
                method.name(),
                mean_speed(&r) / theory - 1.0,
                peak_pin_force(&r),
                r.stats
            );
        }
    }
}
