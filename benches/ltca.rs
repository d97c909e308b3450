//! Quasi-static analysis speed: LTCA of one crank angle, a mesh period at 360 crank angles and a
//! 200-point torque-twist loop, on the paper's scene with compliant bearings and the line
//! (Palmgren) pin law at rated torque, and on the physical preset (line-contact pins, ISO 6336
//! meshes, roller bearings with clearance) at rated torque (`ltca_physical/...`).
use criterion::{Criterion, criterion_group, criterion_main};
use rvdyn::analysis::ltca::Ltca;
use rvdyn::dynamics::model::compliant::default_joints;
use rvdyn::dynamics::scene::{ContactLawSpec, Scene};
use std::hint::black_box;

fn scene() -> Scene {
    let mut s = Scene::paper("rated").expect("paper scene");
    s.joints = default_joints();
    s.contact.pin = ContactLawSpec::Palmgren {
        max_damping: 1e5,
        damping_depth: 1e-5,
    };
    s
}

fn bench_ltca(c: &mut Criterion) {
    // One crank angle in a sweep: warm-started from the previous angle, a step of 1/360 of
    // the period; and one from the kinematic pose.
    let (mut ltca, torque) = bench_sweeps(c, "ltca", &scene());
    c.bench_function("ltca/one_crank_angle_cold", |b| {
        b.iter(|| {
            ltca.reset();
            black_box(ltca.solve(black_box(torque), 0.1).expect("solve"))
        })
    });
}

/// The paper's scene with the physical preset's pin law: two discs of 24 pins, the
/// line-contact (Johnson) law with its location term, linear compliant bearings, the paper's
/// constant mesh stiffness. It separates what the physical preset's roller bearings with
/// clearance and ISO meshes cost from what its pin law costs.
fn line_scene() -> Scene {
    let mut s = Scene::paper("rated").expect("paper scene");
    s.joints = default_joints();
    s.contact.pin = Scene::physical("rated")
        .expect("physical scene")
        .contact
        .pin;
    s
}

/// The warm crank angle (1/360 of the mesh period from the last), the 360-angle period and
/// the 200-point loop of `s` at its load, named `{group}/...`; returns the analysis, warm.
fn bench_sweeps(c: &mut Criterion, group: &str, s: &Scene) -> (Ltca, f64) {
    let torque = s.load.torque(0.0);
    let mut ltca = Ltca::new(s).expect("ltca");
    let period = ltca.mesh_period();
    let angles: Vec<f64> = (0..360).map(|i| period * i as f64 / 360.0).collect();
    ltca.solve(torque, 0.0).expect("first angle");
    let mut k = 0usize;
    c.bench_function(&format!("{group}/one_crank_angle_warm"), |b| {
        b.iter(|| {
            k += 1;
            let psi = period * (k % 360) as f64 / 360.0;
            black_box(ltca.solve(black_box(torque), psi).expect("solve"))
        })
    });
    c.bench_function(&format!("{group}/mesh_period_360_angles"), |b| {
        b.iter(|| {
            ltca.reset();
            black_box(ltca.sweep(black_box(torque), &angles).expect("sweep"))
        })
    });
    c.bench_function(&format!("{group}/twist_loop_200_points"), |b| {
        b.iter(|| black_box(ltca.twist_loop(black_box(torque), 0.0, 200).expect("loop")))
    });
    (ltca, torque)
}

fn bench_ltca_line(c: &mut Criterion) {
    bench_sweeps(c, "ltca_line", &line_scene());
}

fn bench_ltca_physical(c: &mut Criterion) {
    let (mut ltca, torque) = bench_sweeps(
        c,
        "ltca_physical",
        &Scene::physical("rated").expect("physical scene"),
    );
    // `transmission_error(scene, window=False)`: one mesh period at 336 angles, loaded and at
    // the light load 1e-6 of the torque, both directions, extremes located between the angles
    // (the window is twelve of these).
    c.bench_function("ltca_physical/transmission_error_one_period_336", |b| {
        b.iter(|| {
            black_box(
                ltca.transmission_error(black_box(torque), Some(1e-6 * torque), 336, 0.0, 1, false)
                    .expect("te"),
            )
        })
    });
    // `compliance_budget(scene)`: the warm equilibrium at the rated torque and its five family
    // parts (one evaluation each, plus the whole tangent's).
    c.bench_function("ltca_physical/compliance_budget_rated", |b| {
        b.iter(|| {
            black_box(
                ltca.compliance_budget(&[black_box(torque)], 0.0)
                    .expect("budget"),
            )
        })
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = bench_ltca, bench_ltca_line, bench_ltca_physical
}
criterion_main!(benches);
