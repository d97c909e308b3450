//! Criterion benches of the dynamics: one force evaluation, one step of each integrator, and
//! 0.1 s of the default scene at full load.
use criterion::{Criterion, criterion_group, criterion_main};
use rvdyn::dynamics::model::ReducerModel;
use rvdyn::dynamics::model::rigid_system::RigidSystem;
use rvdyn::dynamics::{RigidModel, RunControl, Scene, SimOptions, simulate};
use rvdyn::solve::dopri5::Dopri5;
use rvdyn::solve::generalized_alpha::GeneralizedAlpha;
use rvdyn::solve::rk4::Rk4;
use rvdyn::solve::{MechanicalSystem, Method, State};
use std::hint::black_box;

/// The rated default scene, run 0.05 s from rest so that the state is a loaded one.
fn loaded_state(model: &RigidModel) -> State {
    let sys = RigidSystem::new(model);
    let (q, v) = sys.initial_state();
    let mut st = State::new(&sys, 0.0, q, v).expect("initial state");
    let mut ga = GeneralizedAlpha::new(0.8, 1e-9, false).expect("valid rho");
    for _ in 0..500 {
        ga.step(&sys, &mut st, 1e-4).expect("step");
    }
    st
}

fn bench_dynamics(c: &mut Criterion) {
    let scene = Scene::paper("rated").expect("paper scene");
    let model = RigidModel::new(&scene).expect("model");
    let sys = RigidSystem::new(&model);
    let st = loaded_state(&model);
    let mut a = vec![0.0; sys.dof()];
    let mut p = [0.0; 3];
    c.bench_function("rhs/rigid_rated_48_pins_3_meshes", |b| {
        b.iter(|| {
            sys.eval(
                black_box(st.t),
                black_box(&st.q),
                black_box(&st.v),
                &mut a,
                &mut p,
            )
        })
    });
    let mut rk4 = Rk4::default();
    c.bench_function("step/rk4_dt_1e-5", |b| {
        b.iter(|| {
            let mut s = st.clone();
            rk4.step(&sys, &mut s, 1e-5).map(|_| s.t)
        })
    });
    c.bench_function("step/dopri5_atol_1e-9", |b| {
        b.iter(|| {
            let mut s = st.clone();
            let mut d = Dopri5::new(1e-6, 1e-9, 2e-5, 1e-3);
            d.step(&sys, &mut s, 1.0).map(|_| s.t)
        })
    });
    let mut ga = GeneralizedAlpha::new(0.8, 1e-9, false).expect("valid rho");
    c.bench_function("step/generalized_alpha_dt_1e-4", |b| {
        b.iter(|| {
            let mut s = st.clone();
            ga.step(&sys, &mut s, 1e-4).map(|_| s.t)
        })
    });
    let mut group = c.benchmark_group("scene");
    group.sample_size(10);
    let mut opt = SimOptions::new(0.1, Method::GeneralizedAlpha);
    opt.channels = vec![];
    group.bench_function("rated_0.1s_generalized_alpha_default", |b| {
        b.iter(|| simulate(&scene, &opt, &RunControl::default()).map(|r| r.samples))
    });
    group.finish();
}

criterion_group!(benches, bench_dynamics);
criterion_main!(benches);
