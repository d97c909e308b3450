//! Developer smoke run of the default scene from the command line, without Python:
//! `cargo run --release --example smoke -- [idle|paper|rated] [integrator] [t_end] [dt]`.
use rvdyn::dynamics::{RunControl, Scene, SimOptions, simulate};
use rvdyn::solve::Method;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let load = args.get(1).map(|s| s.as_str()).unwrap_or("idle");
    let method = Method::parse(
        args.get(2)
            .map(|s| s.as_str())
            .unwrap_or("generalized-alpha"),
    )
    .unwrap();
    let t_end: f64 = args.get(3).map(|s| s.parse().unwrap()).unwrap_or(0.2);
    let dt: Option<f64> = args.get(4).map(|s| s.parse().unwrap());
    let scene = Scene::paper(load).unwrap();
    let mut opt = SimOptions::new(t_end, method);
    opt.dt = dt;
    let t0 = std::time::Instant::now();
    let r = simulate(&scene, &opt, &RunControl::default());
    let wall = t0.elapsed().as_secs_f64();
    match r {
        Err(e) => println!("ERROR {e}"),
        Ok(r) => {
            let t = &r.series["t"].data;
            let ca = &r.series["carrier_angle"].data;
            let cs = &r.series["carrier_speed"].data;
            let n = t.len();
            let i0 = n / 2;
            let mean = (ca[n - 1] - ca[i0]) / (t[n - 1] - t[i0]);
            let theory = 8328.0f64.to_radians() / 57.0;
            println!("wall {wall:.3}s stats {:?}", r.stats);
            println!(
                "mean speed {:.6} deg/s theory {:.6} rel {:.3e}",
                mean.to_degrees(),
                theory.to_degrees(),
                mean / theory - 1.0
            );
            println!("speed last {:.4} deg/s", cs[n - 1].to_degrees());
            let pf = &r.series["pin_force"].data;
            let lp = &r.series["loaded_pins"].data;
            let maxf = pf[pf.len() - 48..].iter().cloned().fold(0.0, f64::max);
            println!(
                "last max pin force {maxf:.1} N loaded {:?}",
                &lp[lp.len() - 2..]
            );
            let res = &r.series["energy_residual"].data;
            let win = &r.series["input_work"].data;
            println!(
                "energy residual {:.3e} J of input {:.3e} J",
                res[n - 1],
                win[n - 1]
            );
            let it = &r.series["input_torque"].data;
            println!("input torque last {:.2}", it[n - 1]);
        }
    }
}
