//! The speed goal of BENCHMARKS.md: 5 s simulated of the rated default scene at the setting the
//! work-precision benchmark found for a pin-force error <= 0.1 % of the peak. Used for
//! profiling: `valgrind --tool=callgrind target/release/examples/speed_goal`.
use rvdyn::dynamics::run::recorder::Channel;
use rvdyn::dynamics::{RunControl, Scene, SimOptions, simulate};
use rvdyn::solve::Method;

fn main() -> Result<(), rvdyn::RvdynError> {
    let args: Vec<String> = std::env::args().collect();
    let dt: f64 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(2e-4);
    let scene = Scene::paper("rated")?;
    let mut opt = SimOptions::new(5.0, Method::GeneralizedAlpha);
    opt.dt = Some(dt);
    opt.record_interval = Some(1e-3);
    opt.channels = vec![Channel::Motion, Channel::Pins];
    let start = std::time::Instant::now();
    let rec = simulate(&scene, &opt, &RunControl::default())?;
    println!(
        "5 s simulated, dt {dt:e} s: wall {:.3} s, {} samples, stats {:?}",
        start.elapsed().as_secs_f64(),
        rec.samples,
        rec.stats
    );
    Ok(())
}
