//! Criterion benches of the vibration analyses: the modal analysis of the compliant model at
//! one operating point (linearisation about the LTCA equilibrium + eigen-analysis), the
//! eigen-analysis alone, and a Campbell diagram over 200 input speeds; the modes of the
//! physical preset at one operating point (`modal/physical_16dof_point`).
use criterion::{Criterion, criterion_group, criterion_main};
use rvdyn::analysis::modes::{Linearizer, campbell, modal_analysis, modes_at};
use rvdyn::dynamics::Scene;
use rvdyn::dynamics::model::compliant::default_joints;
use std::hint::black_box;

const RATED: f64 = 43_921.260_376_02;

fn compliant() -> Scene {
    let mut s = Scene::paper("rated").expect("paper scene");
    s.joints = default_joints();
    s
}

fn bench_modal(c: &mut Criterion) {
    let scene = compliant();
    let mut lin = Linearizer::new(&scene).expect("linearizer");
    // Alternate between two crank angles so that every call solves a new equilibrium.
    let mut flip = false;
    c.bench_function("modal/compliant_16dof_point", |b| {
        b.iter(|| {
            flip = !flip;
            let psi = if flip { 0.10 } else { 0.11 };
            black_box(modes_at(&mut lin, RATED, black_box(psi)).expect("modes"))
        })
    });
    let physical = Scene::physical("rated").expect("physical scene");
    let mut lin_p = Linearizer::new(&physical).expect("linearizer");
    c.bench_function("modal/physical_16dof_point", |b| {
        b.iter(|| {
            flip = !flip;
            let psi = if flip { 0.10 } else { 0.11 };
            black_box(modes_at(&mut lin_p, RATED, black_box(psi)).expect("modes"))
        })
    });
    let (sys, _) = lin.linearise(RATED, 0.1).expect("linearise");
    c.bench_function("modal/eigen_only_16dof", |b| {
        b.iter(|| black_box(modal_analysis(black_box(&sys)).expect("modal")))
    });
    c.bench_function("modal/linearise_only_16dof", |b| {
        b.iter(|| {
            flip = !flip;
            let psi = if flip { 0.10 } else { 0.11 };
            black_box(lin.linearise(RATED, black_box(psi)).expect("linearise"))
        })
    });
    let speeds: Vec<f64> = (0..200)
        .map(|k| 145.351 + (242.252 - 145.351) * k as f64 / 199.0)
        .collect();
    let torques: Vec<f64> = speeds.iter().map(|w| 112e3 * 57.0 / w).collect();
    let mut g = c.benchmark_group("campbell");
    g.sample_size(10);
    g.bench_function("compliant_200_speeds", |b| {
        b.iter(|| black_box(campbell(&scene, &speeds, &torques, 0.1, 3, None).expect("campbell")))
    });
    g.finish();
}

criterion_group!(benches, bench_modal);
criterion_main!(benches);
