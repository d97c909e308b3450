//! A fixed amount of LTCA work for counting instructions (BENCHMARKS.md section 10.1), which a
//! shared machine's load does not change as it changes times:
//!
//! ```sh
//! cargo build --release --example ltca_work
//! valgrind --tool=callgrind --collect-atstart=no --toggle-collect='*ltca_work*work*' \
//!     target/release/examples/ltca_work physical period 1
//! ```
//!
//! `PRESET WORKLOAD N` with PRESET `physical` (`Scene::physical("rated")`) or `paper` (the
//! paper scene with compliant bearings and the Palmgren line law, as `benches/ltca.rs`) and
//! WORKLOAD `warm` (N warm crank angles with the full report, 1/360 of the period apart),
//! `period` (N sweeps of 360 crank angles over the mesh period with full reports), `bare` (N
//! sweeps of 360 equilibria without reports, as the transmission error) or `loop` (N
//! 200-point torque-twist loops at crank angle 0). Prints the Newton iterations and force
//! evaluations used.
use rvdyn::analysis::ltca::Ltca;
use rvdyn::dynamics::compliant::default_joints;
use rvdyn::dynamics::scene::{ContactLawSpec, Scene};
use std::hint::black_box;

fn scene(preset: &str) -> Result<Scene, Box<dyn std::error::Error>> {
    if preset == "physical" {
        return Ok(Scene::physical("rated")?);
    }
    let mut s = Scene::paper("rated")?;
    s.joints = default_joints();
    s.contact.pin = ContactLawSpec::Palmgren {
        max_damping: 1e5,
        damping_depth: 1e-5,
    };
    Ok(s)
}

#[inline(never)]
fn ltca_work(
    ltca: &mut Ltca,
    what: &str,
    n: usize,
    torque: f64,
    angles: &[f64],
) -> Result<usize, Box<dyn std::error::Error>> {
    let mut iterations = 0;
    match what {
        "warm" => {
            for k in 1..=n {
                let p = ltca.solve(black_box(torque), angles[k % angles.len()])?;
                iterations += p.iterations;
            }
        }
        "period" => {
            for _ in 0..n {
                ltca.reset();
                let pts = ltca.sweep(black_box(torque), angles)?;
                if std::env::var_os("LTCA_WORK_ITERS").is_some() {
                    let it: Vec<usize> = pts.iter().map(|p| p.iterations).collect();
                    println!("{it:?}");
                }
                iterations += pts.iter().map(|p| p.iterations).sum::<usize>();
            }
        }
        "bare" => {
            for _ in 0..n {
                let te = ltca.transmission_error(black_box(torque), 1e-6 * torque, 360, 0.0)?;
                black_box(te);
            }
        }
        "loop" => {
            for _ in 0..n {
                black_box(ltca.twist_loop(black_box(torque), 0.0, 200)?);
            }
        }
        _ => return Err(format!("unknown workload {what}").into()),
    }
    Ok(iterations)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let arg = |i: usize, default: &str| args.get(i).cloned().unwrap_or_else(|| default.into());
    let s = scene(&arg(1, "physical"))?;
    let what = arg(2, "period");
    let n: usize = arg(3, "1").parse()?;
    let torque = s.load.torque(0.0);
    let mut ltca = Ltca::new(&s)?;
    let period = ltca.mesh_period();
    let angles: Vec<f64> = (0..360).map(|i| period * i as f64 / 360.0).collect();
    ltca.solve(torque, 0.0)?;
    let e0 = ltca.evaluations();
    let it = ltca_work(&mut ltca, &what, n, torque, &angles)?;
    println!(
        "{what} x{n}: {it} Newton iterations, {} force evaluations",
        ltca.evaluations() - e0
    );
    Ok(())
}
