//! A fixed amount of work for counting instructions (BENCHMARKS.md section 7), which a shared
//! machine's load does not change as it changes times:
//!
//! ```sh
//! cargo build --release --example count_work
//! valgrind --tool=callgrind target/release/examples/count_work run 0.02 generalized-alpha rigid
//! valgrind --tool=callgrind target/release/examples/count_work rhs 20000   # minus `rhs 0`
//! valgrind --tool=callgrind target/release/examples/count_work phys 20000  # minus `phys 0`
//! ```
//!
//! `run T METHOD JOINTS [record|-] [ATOL RTOL]`: `dynamics::simulate` of the rated default
//! scene for T s with no channels recorded (JOINTS `rigid`, `compliant`, or `physical` for the
//! physical preset), or with `record` the default channels at every step, or with `goal=DT`
//! benches/speed_goal.py's run at the step DT (motion and pins every 1 ms; `checked=DT` the same
//! with Newton checked by the samples); `rhs N`: N force evaluations of the
//! rigid rated scene at one loaded state (after 0.05 s from rest); `phys N`: N force evaluations of
//! the physical rated preset (compliant roller bearings) at one loaded state (after 0.1 s from
//! rest).
use rvdyn::dynamics::model::ReducerModel;
use rvdyn::dynamics::model::compliant::CompliantModel;
use rvdyn::dynamics::model::rigid_system::RigidSystem;
use rvdyn::dynamics::run::recorder::Channel;
use rvdyn::dynamics::{RigidModel, RunControl, Scene, SimOptions, simulate};
use rvdyn::solve::generalized_alpha::GeneralizedAlpha;
use rvdyn::solve::{MechanicalSystem, Method, State};
use std::hint::black_box;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let arg = |i: usize, default: &str| args.get(i).cloned().unwrap_or_else(|| default.into());
    let mut scene = Scene::paper("rated")?;
    if arg(1, "run") == "phys" {
        let n: usize = arg(2, "20000").parse()?;
        let model = CompliantModel::new(&Scene::physical("rated")?)?;
        let (q, v) = model.initial_state();
        let mut st = State::new(&model, 0.0, q, v)?;
        let mut ga = GeneralizedAlpha::new(0.8, 1e-9, false)?;
        for _ in 0..5000 {
            ga.step(&model, &mut st, 2e-5)?;
        }
        let a = eval_loop(&model, &st, n)?;
        println!("{n} evaluations, a = {a:?}");
        return Ok(());
    }
    if arg(1, "run") == "rhs" {
        let n: usize = arg(2, "20000").parse()?;
        let model = RigidModel::new(&scene)?;
        let sys = RigidSystem::new(&model);
        let (q, v) = sys.initial_state();
        let mut st = State::new(&sys, 0.0, q, v)?;
        let mut ga = GeneralizedAlpha::new(0.8, 1e-9, false)?;
        for _ in 0..500 {
            ga.step(&sys, &mut st, 1e-4)?;
        }
        let (mut a, mut p) = (vec![0.0; sys.dof()], [0.0; 3]);
        for _ in 0..n {
            sys.eval(
                black_box(st.t),
                black_box(&st.q),
                black_box(&st.v),
                &mut a,
                &mut p,
            )?;
        }
        println!("{n} evaluations, a = {a:?}");
        return Ok(());
    }
    let t_end: f64 = arg(2, "0.02").parse()?;
    let method = Method::parse(&arg(3, "generalized-alpha"))?;
    if arg(4, "rigid") == "physical" {
        scene = Scene::physical("rated")?;
    }
    if arg(4, "rigid") == "compliant" {
        scene.joints = rvdyn::dynamics::model::compliant::default_joints();
    }
    let mut opt = SimOptions::new(t_end, method);
    if let (Ok(atol), Ok(rtol)) = (arg(6, "").parse::<f64>(), arg(7, "").parse::<f64>()) {
        (opt.atol, opt.rtol) = (atol, rtol);
    }
    let a5 = arg(5, "");
    if a5 == "record" {
        // The default channels at every step (record interval = the step).
        opt.record_interval = Some(SimOptions::default_dt(method));
    } else if let Some(dt) = a5
        .strip_prefix("goal=")
        .or_else(|| a5.strip_prefix("checked="))
    {
        // benches/speed_goal.py's run: step dt, motion and pins every 1 ms (`checked=DT`: with
        // Newton checked by the samples, SimOptions::check_with_samples).
        opt.check_with_samples = a5.starts_with("checked=");
        opt.dt = Some(dt.parse()?);
        opt.record_interval = Some(1e-3);
        opt.channels = vec![Channel::Motion, Channel::Pins];
    } else {
        opt.channels = vec![];
    }
    let r = simulate(&scene, &opt, &RunControl::default())?;
    println!("{} samples, stats {:?}", r.samples, r.stats);
    // A digest of the results, to check that a change of the code leaves them as they were.
    if let Some(f) = r.series.get("pin_force") {
        let sum: f64 = f.data.iter().sum();
        let peak = f.data.iter().fold(0.0_f64, |m, x| m.max(*x));
        println!("pin_force: sum {sum:.17e}, peak {peak:.17e}");
    }
    if let Some((t, q, v)) = &r.final_state {
        println!("final state at t = {t}: q = {q:?}, v = {v:?}");
    }
    Ok(())
}

/// `n` evaluations of `sys` at `st` (kept out of line so that a profiler can collect this
/// function alone: `--toggle-collect='*eval_loop*'`).
#[inline(never)]
fn eval_loop<S: MechanicalSystem>(sys: &S, st: &State, n: usize) -> rvdyn::Result<Vec<f64>> {
    let (mut a, mut p) = (vec![0.0; sys.dof()], [0.0; 3]);
    for _ in 0..n {
        sys.eval(
            black_box(st.t),
            black_box(&st.q),
            black_box(&st.v),
            &mut a,
            &mut p,
        )?;
    }
    Ok(a)
}
