//! Time per exact pin-profile gap query on the default geometry.
use criterion::{Criterion, criterion_group, criterion_main};
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
}

criterion_group!(benches, bench_gap);
criterion_main!(benches);
