//! Tests of the quasi-static friction of the LTCA (module `friction`).

use super::*;
use crate::analysis::ltca::ARCMIN;
use crate::dynamics::scene::Friction;

fn rated() -> f64 {
    Scene::paper("rated").unwrap().load.torque(0.0)
}

fn with_friction(mut s: Scene, pin: f64, mesh: f64) -> Scene {
    s.friction = Friction {
        pin,
        mesh,
        ..Friction::default()
    };
    s
}

#[test]
#[ignore]
fn explore() {
    for (name, scene) in [
        ("physical", Scene::physical("rated").unwrap()),
        ("paper", Scene::paper("rated").unwrap()),
    ] {
        let s = with_friction(scene, 0.05, 0.05);
        let mut ltca = Ltca::new(&s).unwrap();
        let t0 = std::time::Instant::now();
        let lp0 = ltca.twist_loop_with(rated(), 0.0, 41, false).unwrap();
        let t1 = t0.elapsed();
        let lp = ltca.twist_loop(rated(), 0.0, 41).unwrap();
        let t2 = t0.elapsed();
        println!("{name}: {t1:?} {t2:?}");
        for (a, b) in [(&lp0, "frictionless"), (&lp, "friction")] {
            println!(
                "{b}: rigidity {:.1} Nm/arcmin, lost motion {:.4} arcmin, backlash {:.4} arcmin",
                a.rigidity * ARCMIN,
                a.lost_motion / ARCMIN,
                a.backlash / ARCMIN
            );
        }
        for i in 0..41 {
            println!(
                "{:10.1} {:10.5} {:10.5}",
                lp.torque[i],
                lp0.twist[i] / ARCMIN,
                lp.twist[i] / ARCMIN
            );
        }
    }
}
