//! Recording of selected channels at sample times, into flat arrays (first axis = time).

use crate::dynamics::model::{Layout, ReducerModel};
use crate::dynamics::sink::ContactSink;
use crate::error::{Result, RvdynError};
use std::collections::BTreeMap;

/// Groups of recorded quantities; a group not asked for is neither computed nor stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Channel {
    /// Angles and speeds of sun, cranks and carrier; disc centres and angles.
    Motion,
    /// Per disc and pin: normal force, penetration, moment about the disc centre; loaded pins.
    Pins,
    /// Per disc and pin: contact point and normal (fixed frame).
    ContactPoints,
    /// Mesh forces and deflections, input torque.
    Mesh,
    /// Kinetic and elastic energy, input and output work, dissipation, balance residual.
    Energy,
}

impl Channel {
    /// Parse a channel name.
    pub fn parse(name: &str) -> Result<Self> {
        Ok(match name {
            "motion" => Channel::Motion,
            "pins" => Channel::Pins,
            "contact_points" => Channel::ContactPoints,
            "mesh" => Channel::Mesh,
            "energy" => Channel::Energy,
            _ => {
                return Err(RvdynError::Parameter(format!(
                    "unknown channel {name:?}: choose from \"motion\", \"pins\", \
                     \"contact_points\", \"mesh\", \"energy\""
                )));
            }
        })
    }

    /// The channels recorded when none are named (all but contact points).
    pub fn defaults() -> Vec<Channel> {
        vec![
            Channel::Motion,
            Channel::Pins,
            Channel::Mesh,
            Channel::Energy,
        ]
    }
}

/// One recorded array: flat data and the shape of one sample.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Series {
    pub data: Vec<f64>,
    pub sample_shape: Vec<usize>,
}

/// Everything a run recorded, by name (see the Python `Result` for the meaning of each).
#[derive(Debug, Clone, Default)]
pub struct Recording {
    pub series: BTreeMap<&'static str, Series>,
    pub samples: usize,
    /// Integrator statistics: steps, force evaluations, Jacobians, rejected or split steps.
    pub stats: BTreeMap<&'static str, f64>,
}

/// Collects the contacts of one evaluation into per-sample buffers.
pub(crate) struct SampleSink {
    pub zp: usize,
    pub forces: bool,
    pub pins: bool,
    pub points: bool,
    pub energy: bool,
    pub force: Vec<f64>,
    pub pen: Vec<f64>,
    pub moment: Vec<f64>,
    pub point: Vec<f64>,
    pub normal: Vec<f64>,
    pub mesh_force: Vec<f64>,
    pub mesh_deflection: Vec<f64>,
}

impl ContactSink for SampleSink {
    fn wants_energy(&self) -> bool {
        self.energy
    }
    fn wants_forces(&self) -> bool {
        self.forces
    }
    fn checks_bounds(&self) -> bool {
        false
    }
    fn pin(
        &mut self,
        k: usize,
        j: usize,
        force: f64,
        pen: f64,
        moment: f64,
        point: [f64; 2],
        normal: [f64; 2],
    ) {
        let i = k * self.zp + j;
        if self.pins {
            self.force[i] = force;
            self.pen[i] = pen;
            self.moment[i] = moment;
        }
        if self.points {
            self.point[2 * i..2 * i + 2].copy_from_slice(&point);
            self.normal[2 * i..2 * i + 2].copy_from_slice(&normal);
        }
    }
    fn mesh(&mut self, i: usize, force: f64, deflection: f64) {
        if let Some(f) = self.mesh_force.get_mut(i) {
            *f = force;
            self.mesh_deflection[i] = deflection;
        }
    }
}

/// Appends samples of the chosen channels.
pub(crate) struct Recorder {
    channels: Vec<Channel>,
    rec: Recording,
    sink: SampleSink,
    nd: usize,
    initial_energy: Option<f64>,
}

impl Recorder {
    pub fn new(layout: Layout, channels: &[Channel], capacity: usize) -> Self {
        let nd = layout.discs;
        let zp = layout.pins;
        let nm = layout.meshes;
        let has = |c| channels.contains(&c);
        let mut series: BTreeMap<&'static str, Series> = BTreeMap::new();
        let mut add = |name: &'static str, shape: Vec<usize>| {
            let per: usize = shape.iter().product();
            series.insert(
                name,
                Series {
                    data: Vec::with_capacity(capacity * per),
                    sample_shape: shape,
                },
            );
        };
        add("t", vec![]);
        if has(Channel::Motion) {
            for n in ["sun_angle", "sun_speed", "carrier_angle", "carrier_speed"] {
                add(n, vec![]);
            }
            add("crank_angle", vec![layout.cranks]);
            add("crank_speed", vec![layout.cranks]);
            add("disc_center", vec![nd, 2]);
            add("disc_angle", vec![nd]);
        }
        if has(Channel::Pins) {
            add("pin_force", vec![nd, zp]);
            add("pin_penetration", vec![nd, zp]);
            add("pin_moment", vec![nd, zp]);
            add("loaded_pins", vec![nd]);
        }
        if has(Channel::ContactPoints) {
            add("pin_point", vec![nd, zp, 2]);
            add("pin_normal", vec![nd, zp, 2]);
        }
        if has(Channel::Mesh) {
            add("mesh_force", vec![nm]);
            add("mesh_deflection", vec![nm]);
            add("input_torque", vec![]);
        }
        if has(Channel::Energy) {
            for n in [
                "kinetic_energy",
                "potential_energy",
                "input_work",
                "output_work",
                "dissipated_energy",
                "energy_residual",
            ] {
                add(n, vec![]);
            }
        }
        let sink = SampleSink {
            zp,
            forces: channels.iter().any(|c| *c != Channel::Motion),
            pins: has(Channel::Pins),
            points: has(Channel::ContactPoints),
            energy: has(Channel::Energy),
            force: vec![0.0; nd * zp],
            pen: vec![0.0; nd * zp],
            moment: vec![0.0; nd * zp],
            point: vec![0.0; 2 * nd * zp],
            normal: vec![0.0; 2 * nd * zp],
            mesh_force: vec![0.0; nm],
            mesh_deflection: vec![0.0; nm],
        };
        Self {
            channels: channels.to_vec(),
            rec: Recording {
                series,
                samples: 0,
                stats: BTreeMap::new(),
            },
            sink,
            nd,
            initial_energy: None,
        }
    }

    fn push(&mut self, name: &'static str, values: &[f64]) {
        if let Some(s) = self.rec.series.get_mut(name) {
            s.data.extend_from_slice(values);
        }
    }

    /// Record the free state `(q, v)` at `t` with integrated `work`.
    pub fn sample<M: ReducerModel>(
        &mut self,
        model: &M,
        t: f64,
        q: &[f64],
        v: &[f64],
        work: [f64; 3],
    ) -> Result<()> {
        let channels = self.channels.clone();
        let has = |c| channels.contains(&c);
        let obs = model.observe(t, q, v, &mut self.sink)?;
        self.push("t", &[t]);
        if has(Channel::Motion) {
            self.push("sun_angle", &[obs.sun_angle]);
            self.push("sun_speed", &[obs.sun_speed]);
            self.push("carrier_angle", &[obs.carrier_angle]);
            self.push("carrier_speed", &[obs.carrier_speed]);
            self.push("crank_angle", &obs.crank_angle);
            self.push("crank_speed", &obs.crank_speed);
            for k in 0..self.nd {
                self.push("disc_center", &obs.disc_center[k]);
            }
            self.push("disc_angle", &obs.disc_angle);
        }
        if has(Channel::Pins) {
            let zp = self.sink.zp;
            let loaded: Vec<f64> = (0..self.nd)
                .map(|k| {
                    self.sink.force[k * zp..(k + 1) * zp]
                        .iter()
                        .filter(|f| **f > 0.0)
                        .count() as f64
                })
                .collect();
            let (f, p, m) = (
                self.sink.force.clone(),
                self.sink.pen.clone(),
                self.sink.moment.clone(),
            );
            self.push("pin_force", &f);
            self.push("pin_penetration", &p);
            self.push("pin_moment", &m);
            self.push("loaded_pins", &loaded);
        }
        if has(Channel::ContactPoints) {
            let (pt, nm) = (self.sink.point.clone(), self.sink.normal.clone());
            self.push("pin_point", &pt);
            self.push("pin_normal", &nm);
        }
        if has(Channel::Mesh) {
            let (mf, md) = (
                self.sink.mesh_force.clone(),
                self.sink.mesh_deflection.clone(),
            );
            self.push("mesh_force", &mf);
            self.push("mesh_deflection", &md);
            self.push("input_torque", &[obs.input_torque]);
        }
        if has(Channel::Energy) {
            let e = obs.kinetic_energy + obs.potential_energy;
            let e0 = *self.initial_energy.get_or_insert(e);
            let residual = e - e0 - work[0] + work[1] + work[2];
            self.push("kinetic_energy", &[obs.kinetic_energy]);
            self.push("potential_energy", &[obs.potential_energy]);
            self.push("input_work", &[work[0]]);
            self.push("output_work", &[work[1]]);
            self.push("dissipated_energy", &[work[2]]);
            self.push("energy_residual", &[residual]);
        }
        self.rec.samples += 1;
        Ok(())
    }

    pub fn finish(self) -> Recording {
        self.rec
    }
}
