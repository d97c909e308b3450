//! Time per exact pin-profile gap query on the default geometry.
use criterion::{Criterion, criterion_group, criterion_main};
use rvdyn::geometry::gap::GapWarmStart;
use rvdyn::geometry::{CycloidGeometry, cycloid::CycloidParams};
use std::hint::black_box;

fn default_disc() -> CycloidGeometry {
    CycloidGeometry::new(CycloidParams {
        pins: 24,
        eccentricity: 4.5e-3,
        pin_circle_radius: 0.15,
        pin_radius: 0.01,
        face_width: 0.04,
        d_rp: 0.0,
        d_rrp: 0.0,
        d_delta: 0.0,
    })
    .expect("default geometry is valid")
}

fn bench_gap(c: &mut Criterion) {
    let g = default_disc();
    let psi: f64 = 1.234;
    let centre = [4.5e-3 * psi.cos() + 2e-5, 4.5e-3 * psi.sin()];
    let angle = -psi / 23.0 + 1e-4;
    let pins: Vec<[f64; 2]> = (0..24)
        .map(|j| {
            let th = g.pin_angle(j);
            [0.15 * th.cos(), 0.15 * th.sin()]
        })
        .collect();
    c.bench_function("gap/parry_seed_newton_24_pins", |b| {
        b.iter(|| {
            let mut s = 0.0;
            for p in &pins {
                s += g
                    .gap(black_box(*p), black_box(centre), black_box(angle))
                    .map_or(0.0, |r| r.gap);
            }
            s
        })
    });
    c.bench_function("gap/kinematic_seed_newton_24_pins", |b| {
        b.iter(|| {
            let mut s = 0.0;
            for (j, p) in pins.iter().enumerate() {
                let seed = g.pin_angle(j) - angle;
                s += g
                    .gap_seeded(
                        black_box(*p),
                        0.01,
                        black_box(centre),
                        black_box(angle),
                        seed,
                    )
                    .map_or(0.0, |r| r.gap);
            }
            s
        })
    });
    // Along a trajectory: 1000 poses 2e-4 s apart at 1500 rpm crank speed, with a deflection
    // of 20 um and 0.1 mrad oscillating on top of the kinematic pose; each query warm-started
    // from the previous pose's foot of the same pin (as in a time-stepping run).
    let poses: Vec<([f64; 2], f64)> = (0..1000)
        .map(|k| {
            let t = k as f64 * 2e-4;
            let psi = 157.0 * t;
            let c = [
                4.5e-3 * psi.cos() + 2e-5 * (900.0 * t).sin(),
                4.5e-3 * psi.sin() + 1e-5 * (1300.0 * t).cos(),
            ];
            (c, -psi / 23.0 + 1e-4 * (700.0 * t).sin())
        })
        .collect();
    let mut warm = [GapWarmStart::default(); 24];
    let mut k = 0;
    c.bench_function("gap/warm_start_24_pins", |b| {
        b.iter(|| {
            let (centre, angle) = poses[k % poses.len()];
            k += 1;
            let mut s = 0.0;
            for (p, w) in pins.iter().zip(warm.iter_mut()) {
                s += g
                    .gap_warm(black_box(*p), 0.01, black_box(centre), black_box(angle), w)
                    .map_or(0.0, |r| r.gap);
            }
            s
        })
    });
}

criterion_group!(benches, bench_gap);
criterion_main!(benches);
