//! Work of the exact gap query, for instruction counting (valgrind --tool=callgrind), which a
//! shared machine's load does not change:
//! `cargo run --release --example gap_work -- [kinematic|warm] [rounds]` runs `rounds` times the
//! 24 pins of the default disc, seeded with the kinematic parameter (`gap_seeded`) or warm
//! started along a trajectory (`gap_warm`, the poses of `benches/gap.rs`). Counting two round
//! numbers and taking the difference removes the fixed cost (geometry build, process start).
use rvdyn::geometry::gap::GapWarmStart;
use rvdyn::geometry::{CycloidGeometry, cycloid::CycloidParams};
use std::hint::black_box;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mode = args.get(1).map_or("kinematic", |s| s.as_str());
    let rounds: usize = args.get(2).map_or(1000, |s| s.parse().expect("rounds"));
    let g = CycloidGeometry::new(CycloidParams::paper()).expect("paper disc");
    let pins: Vec<[f64; 2]> = (0..24)
        .map(|j| {
            let th = g.pin_angle(j);
            [0.15 * th.cos(), 0.15 * th.sin()]
        })
        .collect();
    let mut sum = 0.0;
    match mode {
        "kinematic" => {
            let psi: f64 = 1.234;
            let centre = [4.5e-3 * psi.cos() + 2e-5, 4.5e-3 * psi.sin()];
            let angle = -psi / 23.0 + 1e-4;
            for _ in 0..rounds {
                for (j, p) in pins.iter().enumerate() {
                    let seed = g.pin_angle(j) - angle;
                    let r = g.gap_seeded(black_box(*p), 0.01, black_box(centre), angle, seed);
                    sum += r.map_or(0.0, |r| r.gap);
                }
            }
        }
        "warm" => {
            let mut warm = [GapWarmStart::default(); 24];
            for k in 0..rounds {
                let t = (k % 1000) as f64 * 2e-4;
                let psi = 157.0 * t;
                let centre = [
                    4.5e-3 * psi.cos() + 2e-5 * (900.0 * t).sin(),
                    4.5e-3 * psi.sin() + 1e-5 * (1300.0 * t).cos(),
                ];
                let angle = -psi / 23.0 + 1e-4 * (700.0 * t).sin();
                for (p, w) in pins.iter().zip(warm.iter_mut()) {
                    let r = g.gap_warm(black_box(*p), 0.01, black_box(centre), angle, w);
                    sum += r.map_or(0.0, |r| r.gap);
                }
            }
        }
        other => panic!("mode {other:?}: kinematic or warm"),
    }
    println!("{mode}: {rounds} x 24 queries, sum of gaps {sum:e}");
}
