//! Excitation orders of an RV reducer and the crossings of a Campbell diagram.
//!
//! An order is a frequency as a multiple of the input rotation frequency
//! `f_in = omega_in / 2 pi` (docs/model.md, "Excitation orders"). With a first stage
//! (`z1` sun teeth, `z2` planet teeth, `zp` pins, `zc = zp - 1` lobes) the ratio is
//! `i = 1 + zp z2/z1` and
//!
//! | order name | meaning | order |
//! |---|---|---|
//! | `output` | carrier rotation = disc spin relative to the pins | `1/i` |
//! | `crank` | crank absolute = disc-centre orbit = load cycle of one pin | `zc/i` |
//! | `crank_relative` | crank relative to the carrier | `zp/i` |
//! | `input` | input shaft rotation | `1` |
//! | `pin_pass` | pin meshing (the pin-force pattern repeats) | `zp zc / i` |
//! | `sun_mesh` | sun/planet tooth mesh | `z1 (i - 1)/i` |
//!
//! Without a first stage the cranks are the input (`i = -zc`, the output turns backwards):
//! `output 1/zc`, `crank 1`, `crank_relative zp/zc`, `pin_pass zp`, no sun mesh; the input
//! rotation is the crank rotation. Harmonics `h` of the pin pass and the sun mesh are the orders
//! `h x` the fundamental.
//!
//! A Campbell diagram plots the natural frequencies against the input speed with the order
//! lines `f = order omega_in / 2 pi`; a crossing is a speed at which an order excites a mode
//! (e.g. Geradin & Rixen 2015; Friswell et al. 2010, ch. 3, for rotating machinery).

use crate::dynamics::scene::Scene;
use crate::error::{Result, RvdynError};
use std::f64::consts::TAU;

/// The most harmonics of each excitation family (two orders each: far beyond any mode).
pub const MAX_HARMONICS: u32 = 10_000;

/// One excitation order.
#[derive(Debug, Clone, PartialEq)]
pub struct ExcitationOrder {
    /// Machine name of the family (`"pin_pass"`, `"sun_mesh"`, ...).
    pub name: String,
    /// Harmonic number (1 = fundamental).
    pub harmonic: u32,
    /// Frequency over the input rotation frequency (positive).
    pub order: f64,
    /// Human-readable label, e.g. `"pin pass x2"`.
    pub label: String,
}

impl ExcitationOrder {
    /// Frequency \[Hz\] of this order at the input speed `input_speed` [rad/s] (its magnitude).
    pub fn frequency(&self, input_speed: f64) -> f64 {
        self.order * input_speed.abs() / TAU
    }
}

/// The excitation orders of a reducer with `pins` pins (`zc = pins - 1` lobes) and, if it has
/// a first stage, `(sun teeth, planet teeth)`; pin-pass and sun-mesh harmonics 1..=`harmonics`.
/// Sorted by increasing order. `ParameterError` for fewer than 3 pins, a stage with a zero
/// tooth count, or `harmonics = 0`.
pub fn excitation_orders(
    pins: u32,
    stage1: Option<(u32, u32)>,
    harmonics: u32,
) -> Result<Vec<ExcitationOrder>> {
    if pins < 3 {
        return Err(RvdynError::Parameter(format!(
            "a cycloid stage needs at least 3 pins, got {pins}"
        )));
    }
    if harmonics == 0 {
        return Err(RvdynError::Parameter(
            "harmonics must be at least 1 (the fundamentals)".into(),
        ));
    }
    if harmonics > MAX_HARMONICS {
        return Err(RvdynError::Parameter(format!(
            "harmonics = {harmonics} is more than {MAX_HARMONICS}: no model resolves orders that \
             high; use fewer"
        )));
    }
    let zp = f64::from(pins);
    let zc = zp - 1.0;
    let mut out = Vec::new();
    let mut push = |name: &str, text: &str, h: u32, order: f64| {
        let label = if h == 1 {
            text.to_string()
        } else {
            format!("{text} x{h}")
        };
        out.push(ExcitationOrder {
            name: name.into(),
            harmonic: h,
            order: order * f64::from(h),
            label,
        });
    };
    match stage1 {
        Some((z1, z2)) => {
            if z1 == 0 || z2 == 0 {
                return Err(RvdynError::Parameter(format!(
                    "tooth counts must be positive, got sun {z1}, planet {z2}"
                )));
            }
            let i = 1.0 + zp * f64::from(z2) / f64::from(z1);
            push("output", "output (carrier, disc spin)", 1, 1.0 / i);
            push("crank", "crank (disc orbit)", 1, zc / i);
            push("crank_relative", "crank relative to carrier", 1, zp / i);
            push("input", "input shaft", 1, 1.0);
            for h in 1..=harmonics {
                push("pin_pass", "pin pass", h, zp * zc / i);
                push("sun_mesh", "sun mesh", h, f64::from(z1) * (i - 1.0) / i);
            }
        }
        None => {
            push("output", "output (carrier, disc spin)", 1, 1.0 / zc);
            push("crank", "crank = input (disc orbit)", 1, 1.0);
            push("crank_relative", "crank relative to carrier", 1, zp / zc);
            for h in 1..=harmonics {
                push("pin_pass", "pin pass", h, zp);
            }
        }
    }
    out.sort_by(|a, b| a.order.total_cmp(&b.order));
    Ok(out)
}

/// The excitation orders of a scene (see [`excitation_orders`]).
pub fn scene_orders(scene: &Scene, harmonics: u32) -> Result<Vec<ExcitationOrder>> {
    excitation_orders(
        scene.cycloid.pins,
        scene.stage1.as_ref().map(|s| (s.z_sun, s.z_planet)),
        harmonics,
    )
}

/// A crossing of an order line with a natural-frequency curve in a Campbell diagram.
#[derive(Debug, Clone, PartialEq)]
pub struct Crossing {
    /// Input speed [rad/s].
    pub speed: f64,
    /// Frequency \[Hz\] (the mode's natural frequency at that speed = the order's frequency).
    pub frequency: f64,
    /// Index into the orders given.
    pub order: usize,
    /// Index of the mode (column of the frequency table).
    pub mode: usize,
}

/// Crossings of each order line `f = order omega / 2 pi` with each natural-frequency curve.
///
/// `speeds` [rad/s]: at least 2, finite, > 0, strictly increasing. `frequencies[s][m]` \[Hz\]:
/// the natural frequency of mode `m` at speed `s` (finite, >= 0, the same number of modes at
/// every speed), linear between the speeds, so each crossing is the exact root on its
/// interval. Sorted by speed, then order, then mode. A frequency that does not depend on the
/// speed is given by repeating it (two speeds suffice: the ends of the range).
pub fn campbell_crossings(
    speeds: &[f64],
    frequencies: &[Vec<f64>],
    orders: &[ExcitationOrder],
) -> Result<Vec<Crossing>> {
    let perr = |m: String| Err(RvdynError::Parameter(m));
    if speeds.len() < 2 {
        return perr(format!(
            "a Campbell diagram needs at least 2 input speeds, got {}",
            speeds.len()
        ));
    }
    if let Some(s) = speeds.iter().find(|s| !(s.is_finite() && **s > 0.0)) {
        return perr(format!(
            "input speeds must be finite and > 0 rad/s, got {s}"
        ));
    }
    if speeds.windows(2).any(|w| w[1] <= w[0]) {
        return perr("input speeds must be strictly increasing".into());
    }
    if frequencies.len() != speeds.len() {
        return perr(format!(
            "{} rows of natural frequencies for {} speeds",
            frequencies.len(),
            speeds.len()
        ));
    }
    let modes = frequencies[0].len();
    for (s, row) in frequencies.iter().enumerate() {
        if row.len() != modes {
            return perr(format!(
                "speed {s} has {} natural frequencies, the first speed {modes}",
                row.len()
            ));
        }
        if let Some(f) = row.iter().find(|f| !(f.is_finite() && **f >= 0.0)) {
            return perr(format!(
                "natural frequencies must be finite and >= 0 Hz, got {f} at speed {s}"
            ));
        }
    }
    if let Some(o) = orders
        .iter()
        .find(|o| !(o.order.is_finite() && o.order > 0.0))
    {
        return perr(format!(
            "order {} must be finite and > 0, got {}",
            o.label, o.order
        ));
    }
    let mut out = Vec::new();
    for (oi, o) in orders.iter().enumerate() {
        #[allow(clippy::needless_range_loop)] // m indexes the inner rows, not `frequencies`
        for m in 0..modes {
            // g(s) = order s / 2 pi - f_m(s), linear on each interval.
            let g = |k: usize| o.order * speeds[k] / TAU - frequencies[k][m];
            for k in 0..speeds.len() - 1 {
                let (g0, g1) = (g(k), g(k + 1));
                let hit = if g0 == 0.0 {
                    Some(0.0)
                } else if g0 * g1 < 0.0 || (g1 == 0.0 && k + 2 == speeds.len()) {
                    Some(g0 / (g0 - g1))
                } else {
                    None
                };
                if let Some(t) = hit {
                    let speed = speeds[k] + t * (speeds[k + 1] - speeds[k]);
                    let frequency =
                        frequencies[k][m] + t * (frequencies[k + 1][m] - frequencies[k][m]);
                    out.push(Crossing {
                        speed,
                        frequency,
                        order: oi,
                        mode: m,
                    });
                }
            }
        }
    }
    out.sort_by(|a, b| {
        a.speed
            .total_cmp(&b.speed)
            .then(a.order.cmp(&b.order))
            .then(a.mode.cmp(&b.mode))
    });
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn find<'a>(o: &'a [ExcitationOrder], name: &str, h: u32) -> &'a ExcitationOrder {
        o.iter()
            .find(|x| x.name == name && x.harmonic == h)
            .unwrap()
    }

    #[test]
    fn paper_reducer_orders_match_the_model_docs() {
        // docs/model.md, Excitation orders: i = 57; pin pass 552/57, sun mesh 1008/57; at
        // 8328 deg/s the pin pass is 224.03 Hz and the sun mesh 409.1 Hz.
        let scene = Scene::paper("rated").unwrap();
        let o = scene_orders(&scene, 3).unwrap();
        let w_in = 8328f64.to_radians();
        let pp = find(&o, "pin_pass", 1);
        assert!((pp.order - 552.0 / 57.0).abs() < 1e-12);
        assert!((pp.frequency(w_in) - 224.03).abs() < 0.005);
        assert!((find(&o, "pin_pass", 2).frequency(w_in) - 448.06).abs() < 0.01);
        assert!((find(&o, "pin_pass", 3).label == "pin pass x3"));
        let sm = find(&o, "sun_mesh", 1);
        assert!((sm.order - 1008.0 / 57.0).abs() < 1e-12);
        assert!((sm.frequency(w_in) - 409.1).abs() < 0.05);
        assert!((find(&o, "output", 1).order - 1.0 / 57.0).abs() < 1e-15);
        assert!((find(&o, "crank", 1).order - 23.0 / 57.0).abs() < 1e-15);
        assert!((find(&o, "crank_relative", 1).order - 24.0 / 57.0).abs() < 1e-15);
        assert!(o.windows(2).all(|w| w[0].order <= w[1].order));
        // The pin pass seen from the output: zp zc f_out.
        assert!((pp.order - 24.0 * 23.0 * find(&o, "output", 1).order).abs() < 1e-12);
    }

    #[test]
    fn single_stage_orders() {
        let o = excitation_orders(24, None, 2).unwrap();
        assert_eq!(find(&o, "pin_pass", 1).order, 24.0);
        assert_eq!(find(&o, "pin_pass", 2).order, 48.0);
        assert_eq!(find(&o, "crank", 1).order, 1.0);
        assert!((find(&o, "output", 1).order - 1.0 / 23.0).abs() < 1e-15);
        assert!(o.iter().all(|x| x.name != "sun_mesh"));
        assert!(excitation_orders(2, None, 1).is_err());
        assert!(excitation_orders(24, None, 0).is_err());
        assert!(excitation_orders(24, Some((0, 42)), 1).is_err());
    }

    #[test]
    fn crossings_of_constant_and_varying_frequencies() {
        let o = excitation_orders(24, Some((18, 42)), 1).unwrap();
        let pp = o.iter().position(|x| x.name == "pin_pass").unwrap();
        // A constant 300 Hz mode: the pin pass reaches it at omega = 2 pi 300 / (552/57).
        let speeds = [100.0, 300.0];
        let freqs = vec![vec![300.0, 5000.0], vec![300.0, 5000.0]];
        let c = campbell_crossings(&speeds, &freqs, &o).unwrap();
        let hit: Vec<&Crossing> = c.iter().filter(|x| x.order == pp).collect();
        assert_eq!(hit.len(), 1);
        let expect = TAU * 300.0 / (552.0 / 57.0);
        assert!((hit[0].speed - expect).abs() < 1e-9 * expect);
        assert_eq!(hit[0].mode, 0);
        assert!((hit[0].frequency - 300.0).abs() < 1e-9);
        // Every crossing lies on its order line.
        for x in &c {
            let f = o[x.order].order * x.speed / TAU;
            assert!((f - x.frequency).abs() < 1e-9 * f.max(1.0));
        }
        // A linearly varying mode f = 200 + 0.5 s: crossing with the pin pass in closed form.
        let speeds: Vec<f64> = (0..11).map(|k| 100.0 + 20.0 * k as f64).collect();
        let freqs: Vec<Vec<f64>> = speeds.iter().map(|s| vec![200.0 + 0.5 * s]).collect();
        let c = campbell_crossings(&speeds, &freqs, &o).unwrap();
        let hit: Vec<&Crossing> = c.iter().filter(|x| x.order == pp).collect();
        let slope = 552.0 / 57.0 / TAU;
        let s_star = 200.0 / (slope - 0.5);
        assert_eq!(hit.len(), 1);
        assert!((hit[0].speed - s_star).abs() < 1e-9 * s_star);
    }

    #[test]
    fn bad_campbell_input_is_rejected() {
        let o = excitation_orders(24, None, 1).unwrap();
        let f = vec![vec![1.0], vec![1.0]];
        assert!(campbell_crossings(&[1.0], &f[..1], &o).is_err());
        assert!(campbell_crossings(&[2.0, 1.0], &f, &o).is_err());
        assert!(campbell_crossings(&[0.0, 1.0], &f, &o).is_err());
        assert!(campbell_crossings(&[1.0, 2.0], &[vec![1.0], vec![f64::NAN]], &o).is_err());
        assert!(campbell_crossings(&[1.0, 2.0], &[vec![1.0], vec![1.0, 2.0]], &o).is_err());
        assert!(campbell_crossings(&[1.0, 2.0, 3.0], &f, &o).is_err());
    }
}
