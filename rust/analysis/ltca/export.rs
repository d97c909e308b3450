//! Contact loads for finite-element analysis: for each disc, the crank angle with the largest
//! pin force and every loaded pin's force, contact point, normal and Hertz strip there, as CSV
//! and JSON (format in docs/model.md, "Loads for FEA").

use super::LtcaPoint;
use crate::error::{Result, RvdynError};
use serde::Serialize;

/// Format tag written into the JSON.
pub const FORMAT: &str = "rvdyn-ltca-loads/1";

/// One loaded pin of the worst crank angle of a disc (disc frame: origin at the disc centre,
/// axes turned with the disc; SI).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FeaLoad {
    /// Disc index (0-based).
    pub disc: usize,
    /// Pin number (1-based, the paper's numbering).
    pub pin: usize,
    /// Crank angle \[rad\] of this load case.
    pub crank_angle: f64,
    /// Output torque [N m] of this load case.
    pub torque: f64,
    /// Normal force \[N\]; the pin pushes the disc along `-normal`.
    pub force: f64,
    /// Contact point on the profile \[m\] (disc frame).
    pub point: [f64; 2],
    /// Outward unit normal of the profile (disc frame).
    pub normal: [f64; 2],
    /// Hertz half-width \[m\].
    pub half_width: f64,
    /// Hertz peak pressure \[Pa\].
    pub peak_pressure: f64,
}

/// The worst load case of each disc among `points`: the crank angle with the largest pin
/// force on that disc, with all its loaded pins. Errors (`Parameter`) if `points` is empty.
pub fn worst_loads(points: &[LtcaPoint]) -> Result<Vec<FeaLoad>> {
    let first = points.first().ok_or_else(|| {
        RvdynError::Parameter("loads for FEA need at least one LTCA point".into())
    })?;
    let mut out = Vec::new();
    for k in 0..first.pins.len() {
        let peak = |p: &LtcaPoint| p.pins[k].iter().fold(0.0f64, |m, l| m.max(l.force));
        let worst = points
            .iter()
            .max_by(|a, b| peak(a).total_cmp(&peak(b)))
            .unwrap_or(first);
        // Round-off forces (1e-15 N at zero torque) are not loads.
        let floor = super::LOADED_FRACTION * peak(worst).max(1.0);
        for (j, l) in worst.pins[k].iter().enumerate() {
            if l.force > floor {
                out.push(FeaLoad {
                    disc: k,
                    pin: j + 1,
                    crank_angle: worst.crank_angle,
                    torque: worst.torque,
                    force: l.force,
                    point: l.point,
                    normal: l.normal,
                    half_width: l.half_width,
                    peak_pressure: l.peak_pressure,
                });
            }
        }
    }
    Ok(out)
}

/// The CSV header of [`loads_csv`].
pub const CSV_HEADER: &str = "disc,pin,crank_angle_rad,torque_Nm,force_N,point_x_m,point_y_m,\
                              normal_x,normal_y,half_width_m,peak_pressure_Pa";

/// CSV text: [`CSV_HEADER`] then one line per load (shortest round-trip decimal floats).
pub fn loads_csv(loads: &[FeaLoad]) -> String {
    let mut s = String::from(CSV_HEADER);
    s.push('\n');
    for l in loads {
        s.push_str(&format!(
            "{},{},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?}\n",
            l.disc,
            l.pin,
            l.crank_angle,
            l.torque,
            l.force,
            l.point[0],
            l.point[1],
            l.normal[0],
            l.normal[1],
            l.half_width,
            l.peak_pressure
        ));
    }
    s
}

#[derive(Serialize)]
struct Units {
    length: &'static str,
    force: &'static str,
    angle: &'static str,
    torque: &'static str,
    pressure: &'static str,
}

#[derive(Serialize)]
struct Document<'a> {
    format: &'static str,
    frame: &'static str,
    units: Units,
    face_width: f64,
    loads: &'a [FeaLoad],
}

/// JSON text: `{"format", "frame", "units", "face_width", "loads": [..]}`.
pub fn loads_json(loads: &[FeaLoad], face_width: f64) -> Result<String> {
    let doc = Document {
        format: FORMAT,
        frame: "disc: origin at the disc centre, axes turned with the disc; the pin pushes \
                the disc along -normal",
        units: Units {
            length: "m",
            force: "N",
            angle: "rad",
            torque: "N m",
            pressure: "Pa",
        },
        face_width,
        loads,
    };
    serde_json::to_string_pretty(&doc)
        .map_err(|e| RvdynError::Parameter(format!("loads cannot be written as JSON: {e}")))
}
