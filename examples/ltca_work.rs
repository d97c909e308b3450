//! A fixed amount of LTCA work for counting instructions (BENCHMARKS.md section 10.1), which a
//! shared machine's load does not change as it changes times:
//!
//! ```sh
//! cargo build --release --example ltca_work
//! valgrind --tool=callgrind --collect-atstart=no --toggle-collect='*ltca_work*work*' \
//!     target/release/examples/ltca_work physical period 1
//! ```
//!
//! `PRESET WORKLOAD N` with PRESET `physical` (`Scene::physical("rated")`), `paper` (the
//! paper scene with compliant bearings and the Palmgren line law, as `benches/ltca.rs`) or
//! `line` (the same with the physical preset's line-contact pin law, as `ltca_line`) and
//! WORKLOAD `warm` (N warm crank angles with the full report, 1/360 of the period apart), `cold`
//! (N crank angles at 0.1 rad from the kinematic pose, as the bench's `one_crank_angle_cold`),
//! `period` (N sweeps of 360 crank angles over the mesh period with full reports), `bare` (N
//! transmission errors at 360 crank angles: four sweeps of equilibria without reports, loaded and
//! unloaded in both directions) or `loop` (N 200-point torque-twist loops at crank angle 0).
//! Prints the Newton iterations and force evaluations used, and with `LTCA_WORK_RESULTS` set
//! the results (for A/B comparisons of the same workload). `LTCA_WORK_LIGHT` sets the light
//! load of `bare` as a fraction of the torque (default 1e-6); `LTCA_WORK_TOL` the Newton
//! tolerance (`NewtonOptions::tolerance`, default 1e-12 of the load); `LTCA_WORK_REG` turns on
//! `NewtonOptions::regularise_singular` from the first attempt; `LTCA_WORK_PERIODS` the mesh
//! periods of `bare` (more than one: 336 angles per period, as `transmission_error`'s window).
use rvdyn::analysis::ltca::Ltca;
use rvdyn::dynamics::model::compliant::default_joints;
use rvdyn::dynamics::scene::{ContactLawSpec, Scene};
use std::hint::black_box;

fn scene(preset: &str) -> Result<Scene, Box<dyn std::error::Error>> {
    if preset == "physical" {
        return Ok(Scene::physical("rated")?);
    }
    let mut s = Scene::paper("rated")?;
    s.joints = default_joints();
    s.contact.pin = if preset == "line" {
        Scene::physical("rated")?.contact.pin
    } else {
        ContactLawSpec::Palmgren {
            max_damping: 1e5,
            damping_depth: 1e-5,
        }
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
        "cold" => {
            for _ in 0..n {
                ltca.reset();
                iterations += ltca.solve(black_box(torque), 0.1)?.iterations;
            }
        }
        "period" => {
            for _ in 0..n {
                ltca.reset();
                let pts = ltca.sweep(black_box(torque), angles)?;
                if std::env::var_os("LTCA_WORK_RESULTS").is_some() {
                    let te: Vec<f64> = pts.iter().map(|p| p.transmission_error).collect();
                    let peak = pts.iter().map(|p| p.peak_pin_force()).fold(0.0, f64::max);
                    let k: Vec<f64> = pts.iter().map(|p| p.torsional_stiffness).collect();
                    let gaps: f64 = pts
                        .iter()
                        .flat_map(|p| p.pins.iter().flatten().map(|l| l.gap))
                        .sum();
                    println!(
                        "TE p-p {:.15e} rad, peak pin force {peak:.15e} N, TE[0..3] {:?}, \
                         stiffness[0..2] {:?}, sum of gaps {gaps:.15e} m",
                        rvdyn::analysis::ltca::peak_to_peak(&te),
                        &te[..3],
                        &k[..2]
                    );
                }
                iterations += pts.iter().map(|p| p.iterations).sum::<usize>();
            }
        }
        "bare" => {
            for _ in 0..n {
                let lf: f64 = std::env::var("LTCA_WORK_LIGHT")
                    .ok()
                    .and_then(|v| v.parse().ok())
                    .unwrap_or(1e-6);
                let periods: usize = std::env::var("LTCA_WORK_PERIODS")
                    .ok()
                    .and_then(|v| v.parse().ok())
                    .unwrap_or(1);
                let points = if periods == 1 { 360 } else { 336 };
                let te = ltca.transmission_error(
                    black_box(torque),
                    Some(lf * torque),
                    points,
                    0.0,
                    periods,
                    false,
                )?;
                if std::env::var_os("LTCA_WORK_RESULTS").is_some() {
                    let pp = rvdyn::analysis::ltca::peak_to_peak;
                    println!(
                        "TE p-p fwd {:.15e} rev {:.15e} unloaded {:.15e} {:.15e} rad",
                        pp(&te.forward),
                        pp(&te.reverse),
                        pp(&te.unloaded_forward),
                        pp(&te.unloaded_reverse)
                    );
                }
                black_box(te);
            }
        }
        "loop" => {
            for _ in 0..n {
                let lp = ltca.twist_loop(black_box(torque), 0.0, 200)?;
                if std::env::var_os("LTCA_WORK_RESULTS").is_some() {
                    println!(
                        "rigidity {:.15e} N m/rad, lost motion {:.15e} rad, backlash {:.15e} \
                         rad, twist[100] {:.15e} rad, tangent[50] {:.15e}",
                        lp.rigidity,
                        lp.lost_motion,
                        lp.backlash,
                        lp.twist[100],
                        lp.tangent_stiffness[50]
                    );
                }
                black_box(lp);
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
    let mut options = rvdyn::analysis::ltca::NewtonOptions::default();
    if let Some(t) = std::env::var("LTCA_WORK_TOL")
        .ok()
        .and_then(|v| v.parse().ok())
    {
        options.tolerance = t;
    }
    if std::env::var_os("LTCA_WORK_REG").is_some() {
        options.regularise_singular = true;
    }
    let mut ltca = Ltca::with_options(&s, options)?;
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
