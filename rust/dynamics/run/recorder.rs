//! Recording of selected channels at sample times, into flat arrays (first axis = time).

use crate::dynamics::model::{Layout, Observation, ReducerModel};
use crate::dynamics::run::sink::ContactSink;
use crate::error::{Result, RvdynError};
use crate::solve::Stats;
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
    /// Kinetic and elastic energy, input and output work, dissipation, balance residual;
    /// friction power per family.
    Energy,
    /// Bearing forces of the compliant joints.
    Bearings,
}

impl Channel {
    /// Every channel group, in recording order.
    pub const ALL: [Channel; 6] = [
        Channel::Motion,
        Channel::Pins,
        Channel::ContactPoints,
        Channel::Mesh,
        Channel::Energy,
        Channel::Bearings,
    ];

    /// The name used in the API (`"motion"`, `"pins"`, `"contact_points"`, `"mesh"`, `"energy"`).
    pub fn name(&self) -> &'static str {
        match self {
            Channel::Motion => "motion",
            Channel::Pins => "pins",
            Channel::ContactPoints => "contact_points",
            Channel::Mesh => "mesh",
            Channel::Energy => "energy",
            Channel::Bearings => "bearings",
        }
    }

    /// Parse a channel name.
    pub fn parse(name: &str) -> Result<Self> {
        Ok(match name {
            "motion" => Channel::Motion,
            "pins" => Channel::Pins,
            "contact_points" => Channel::ContactPoints,
            "mesh" => Channel::Mesh,
            "energy" => Channel::Energy,
            "bearings" => Channel::Bearings,
            _ => {
                return Err(RvdynError::Parameter(format!(
                    "unknown channel {name:?}: choose from \"motion\", \"pins\", \
                     \"contact_points\", \"mesh\", \"energy\", \"bearings\""
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
            Channel::Bearings,
        ]
    }
}

/// A dimension of one sample of a channel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dim {
    /// One per cycloid disc.
    Discs,
    /// One per pin (index j is the paper's pin j+1).
    Pins,
    /// One per crankshaft.
    Cranks,
    /// One per sun/planet mesh.
    Meshes,
    /// A plane vector (x, y), fixed frame.
    Xy,
}

impl Dim {
    /// The dimension's name in shapes (`"discs"`, `"pins"`, `"cranks"`, `"meshes"`, `"2"`).
    pub fn name(&self) -> &'static str {
        match self {
            Dim::Discs => "discs",
            Dim::Pins => "pins",
            Dim::Cranks => "cranks",
            Dim::Meshes => "meshes",
            Dim::Xy => "2",
        }
    }

    fn size(&self, layout: &Layout) -> usize {
        match self {
            Dim::Discs => layout.discs,
            Dim::Pins => layout.pins,
            Dim::Cranks => layout.cranks,
            Dim::Meshes => layout.meshes,
            Dim::Xy => 2,
        }
    }
}

/// Element type of a recorded channel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dtype {
    /// 64-bit float.
    Float64,
    /// 64-bit integer (counts).
    Int64,
}

/// The declaration of one recorded channel: everything the Python `Result`, its stubs and
/// the docs say about it comes from here.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ChannelSpec {
    /// Attribute name in the Python `Result`.
    pub name: &'static str,
    /// The group that records it (`None` for the time axis, always recorded).
    pub group: Option<Channel>,
    /// Shape of one sample (the first axis of the array is time).
    pub shape: &'static [Dim],
    /// SI unit (`"1"` for a number without unit).
    pub unit: &'static str,
    /// Element type.
    pub dtype: Dtype,
    /// What it is.
    pub doc: &'static str,
}

const fn spec(
    name: &'static str,
    group: Option<Channel>,
    shape: &'static [Dim],
    unit: &'static str,
    doc: &'static str,
) -> ChannelSpec {
    ChannelSpec {
        name,
        group,
        shape,
        unit,
        dtype: Dtype::Float64,
        doc,
    }
}

use Channel::{Bearings, ContactPoints, Energy, Mesh, Motion, Pins};

/// Every recorded channel, in recording order.
pub static CHANNELS: &[ChannelSpec] = &[
    spec("t", None, &[], "s", "sample time"),
    spec("sun_angle", Some(Motion), &[], "rad", "sun (input) angle"),
    spec("sun_speed", Some(Motion), &[], "rad/s", "sun (input) speed"),
    spec(
        "carrier_angle",
        Some(Motion),
        &[],
        "rad",
        "carrier (output) angle",
    ),
    spec(
        "carrier_speed",
        Some(Motion),
        &[],
        "rad/s",
        "carrier (output) speed",
    ),
    spec(
        "crank_angle",
        Some(Motion),
        &[Dim::Cranks],
        "rad",
        "absolute rotation angle of each crankshaft",
    ),
    spec(
        "crank_speed",
        Some(Motion),
        &[Dim::Cranks],
        "rad/s",
        "absolute speed of each crankshaft",
    ),
    spec(
        "disc_center",
        Some(Motion),
        &[Dim::Discs, Dim::Xy],
        "m",
        "disc centres about the reducer axis",
    ),
    spec(
        "disc_angle",
        Some(Motion),
        &[Dim::Discs],
        "rad",
        "disc rotation angles",
    ),
    spec(
        "load_angle",
        Some(Motion),
        &[],
        "rad",
        "load angle (the carrier's without an output shaft)",
    ),
    spec(
        "load_speed",
        Some(Motion),
        &[],
        "rad/s",
        "load speed (the carrier's without an output shaft)",
    ),
    spec(
        "motor_angle",
        Some(Motion),
        &[],
        "rad",
        "motor angle (the input's without a drive shaft)",
    ),
    spec(
        "motor_speed",
        Some(Motion),
        &[],
        "rad/s",
        "motor speed (the input's without a drive shaft)",
    ),
    spec(
        "pin_force",
        Some(Pins),
        &[Dim::Discs, Dim::Pins],
        "N",
        "normal force of pin j on disc k (j = the paper's pin j+1)",
    ),
    spec(
        "pin_penetration",
        Some(Pins),
        &[Dim::Discs, Dim::Pins],
        "m",
        "penetration of pin j into disc k (0 for a pin out of contact, whatever its gap)",
    ),
    spec(
        "pin_moment",
        Some(Pins),
        &[Dim::Discs, Dim::Pins],
        "N m",
        "moment of pin j's normal force (with its damping; not its friction) about disc k's \
         centre (z component; about the ring centre it is zp/zc times larger)",
    ),
    ChannelSpec {
        name: "loaded_pins",
        group: Some(Pins),
        shape: &[Dim::Discs],
        unit: "1",
        dtype: Dtype::Int64,
        doc: "number of pins in contact per disc (force > 0, however small: an unmodified \
              profile at idle touches about half the pins with forces below 1 N)",
    },
    spec(
        "pin_point",
        Some(ContactPoints),
        &[Dim::Discs, Dim::Pins, Dim::Xy],
        "m",
        "contact point on the profile, fixed frame ((0, 0) for a pin whose exact gap was not \
         queried: out of contact and skipped)",
    ),
    spec(
        "pin_normal",
        Some(ContactPoints),
        &[Dim::Discs, Dim::Pins, Dim::Xy],
        "1",
        "unit outward profile normal at the contact ((0, 0) where the point is)",
    ),
    spec(
        "mesh_force",
        Some(Mesh),
        &[Dim::Meshes],
        "N",
        "sun/planet mesh force along the line of action (negative on the coast flank)",
    ),
    spec(
        "mesh_deflection",
        Some(Mesh),
        &[Dim::Meshes],
        "m",
        "mesh deflection along the line of action",
    ),
    spec(
        "input_torque",
        Some(Mesh),
        &[],
        "N m",
        "torque the drive applies to the input",
    ),
    spec(
        "output_shaft_torque",
        Some(Mesh),
        &[],
        "N m",
        "torque in the output shaft (the load torque without one)",
    ),
    spec(
        "input_shaft_torque",
        Some(Mesh),
        &[],
        "N m",
        "torque in the drive shaft (the input torque without one)",
    ),
    spec(
        "kinetic_energy",
        Some(Energy),
        &[],
        "J",
        "kinetic energy of the free bodies",
    ),
    spec(
        "potential_energy",
        Some(Energy),
        &[],
        "J",
        "elastic energy in the contacts and bearings",
    ),
    spec(
        "input_work",
        Some(Energy),
        &[],
        "J",
        "work done by the drive",
    ),
    spec(
        "output_work",
        Some(Energy),
        &[],
        "J",
        "work done against the load",
    ),
    spec(
        "dissipated_energy",
        Some(Energy),
        &[],
        "J",
        "energy dissipated by contact and bearing damping",
    ),
    spec(
        "pin_friction_power",
        Some(Energy),
        &[],
        "W",
        "friction power at the pins (pin/disc, or pin/housing for rolling pins)",
    ),
    spec(
        "mesh_friction_power",
        Some(Energy),
        &[],
        "W",
        "friction power at the sun/planet teeth",
    ),
    spec(
        "bearing_friction_power",
        Some(Energy),
        &[],
        "W",
        "friction power of the joint bearings (compliant joints)",
    ),
    spec(
        "energy_residual",
        Some(Energy),
        &[],
        "J",
        "E_kin + E_el - E0 - W_in + W_out + D (0 for an exact integration)",
    ),
    spec(
        "crank_bearing_force",
        Some(Bearings),
        &[Dim::Cranks, Dim::Xy],
        "N",
        "force of crank bearing i on its crank centre, fixed frame (ideal joints: the reaction \
         from the crank's balance; compliant joints with rigid crank bearings: not computed, 0)",
    ),
    spec(
        "eccentric_bearing_force",
        Some(Bearings),
        &[Dim::Cranks, Dim::Discs, Dim::Xy],
        "N",
        "force of the eccentric bearing of crank i on disc k, fixed frame (ideal joints: the \
         reactions from each disc's balance, split as equal bearings share them)",
    ),
    spec(
        "crank_deflection",
        Some(Bearings),
        &[Dim::Cranks, Dim::Discs, Dim::Xy],
        "m",
        "deflection of crank i's eccentric for disc k from the crank's line, fixed frame \
         (bending crankshafts, crank_shaft; 0 for straight cranks)",
    ),
];

/// One recorded array: flat data and the shape of one sample.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Series {
    /// Samples one after the other, each row-major.
    pub data: Vec<f64>,
    /// Shape of one sample.
    pub sample_shape: Vec<usize>,
}

/// Everything a run recorded, by name (see the Python `Result` for the meaning of each).
#[derive(Debug, Clone, Default)]
pub struct Recording {
    /// Recorded arrays by channel name (see [`CHANNELS`]).
    pub series: BTreeMap<&'static str, Series>,
    /// Number of samples.
    pub samples: usize,
    /// Integrator statistics: steps, force evaluations, Jacobians, rejected or split steps.
    pub stats: Stats,
    /// Why the run may be inaccurate (see `driver::fixed_step_warnings`).
    pub warnings: Vec<String>,
    /// The state at the end of the run: time \[s\] and the model's free coordinates and
    /// velocities (`ReducerModel::initial_state` order), e.g. for a modal analysis about it.
    pub final_state: Option<(f64, Vec<f64>, Vec<f64>)>,
}

/// Collects the contacts of one evaluation into per-sample buffers.
pub(crate) struct SampleSink {
    pub zp: usize,
    pub forces: bool,
    pub pins: bool,
    pub points: bool,
    pub energy: bool,
    pub bearings: bool,
    pub force: Vec<f64>,
    pub pen: Vec<f64>,
    pub moment: Vec<f64>,
    pub point: Vec<f64>,
    pub normal: Vec<f64>,
    pub mesh_force: Vec<f64>,
    pub mesh_deflection: Vec<f64>,
    /// Crank bearing forces `(cranks, 2)` and eccentric bearing forces `(cranks, discs, 2)`.
    pub crank_bearing: Vec<f64>,
    pub eccentric_bearing: Vec<f64>,
    /// Eccentric deflections of bending cranks `(cranks, discs, 2)`.
    pub crank_deflection: Vec<f64>,
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
    fn wants_bearings(&self) -> bool {
        self.bearings
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
    fn crank_deflection(&mut self, index: usize, deflection: [f64; 2]) {
        if let Some(slot) = self.crank_deflection.get_mut(2 * index..2 * index + 2) {
            slot.copy_from_slice(&deflection);
        }
    }
    fn bearing(&mut self, family: usize, index: usize, force: [f64; 2]) {
        let v = if family == 0 {
            &mut self.crank_bearing
        } else {
            &mut self.eccentric_bearing
        };
        if let Some(slot) = v.get_mut(2 * index..2 * index + 2) {
            slot.copy_from_slice(&force);
        }
    }
}

/// Appends samples of the chosen channels.
pub(crate) struct Recorder {
    channels: Vec<Channel>,
    rec: Recording,
    /// The recorded series in [`CHANNELS`] order while recording (into `rec` at the end):
    /// a sample pushes them in this order, so each is found at or just after the last one.
    buffers: Vec<(&'static str, Series)>,
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
        let mut buffers: Vec<(&'static str, Series)> = Vec::new();
        for c in CHANNELS {
            if c.group.is_some_and(|g| !has(g)) {
                continue;
            }
            let shape: Vec<usize> = c.shape.iter().map(|d| d.size(&layout)).collect();
            let per: usize = shape.iter().product();
            buffers.push((
                c.name,
                Series {
                    // Reserve at most 2^20 samples up front: a huge sample count from a long run
                    // grows as it runs instead of failing an allocation at the start.
                    data: Vec::with_capacity(capacity.min(1 << 20) * per),
                    sample_shape: shape,
                },
            ));
        }
        let sink = SampleSink {
            zp,
            forces: channels.iter().any(|c| *c != Channel::Motion),
            pins: has(Channel::Pins),
            points: has(Channel::ContactPoints),
            energy: has(Channel::Energy),
            bearings: has(Channel::Bearings),
            force: vec![0.0; nd * zp],
            pen: vec![0.0; nd * zp],
            moment: vec![0.0; nd * zp],
            point: vec![0.0; 2 * nd * zp],
            normal: vec![0.0; 2 * nd * zp],
            mesh_force: vec![0.0; nm],
            mesh_deflection: vec![0.0; nm],
            crank_bearing: vec![0.0; 2 * layout.cranks],
            eccentric_bearing: vec![0.0; 2 * layout.cranks * nd],
            crank_deflection: vec![0.0; 2 * layout.cranks * nd],
        };
        Self {
            channels: channels.to_vec(),
            rec: Recording {
                series: BTreeMap::new(),
                samples: 0,
                stats: Stats::default(),
                warnings: Vec::new(),
                final_state: None,
            },
            buffers,
            sink,
            nd,
            initial_energy: None,
        }
    }

    /// Values recorded per sample over all series.
    pub fn values_per_sample(&self) -> usize {
        self.buffers
            .iter()
            .map(|(_, s)| s.sample_shape.iter().product::<usize>())
            .sum()
    }

    /// Reserve room for `samples` samples in every series without the aborting allocation
    /// path: `RvdynError::Memory` if the memory cannot be had.
    pub fn reserve(&mut self, samples: usize) -> Result<()> {
        for (name, s) in self.buffers.iter_mut() {
            let per: usize = s.sample_shape.iter().product();
            let n = samples.saturating_mul(per);
            let extra = n.saturating_sub(s.data.len());
            if s.data.try_reserve_exact(extra).is_err() {
                return Err(RvdynError::Memory(format!(
                    "cannot allocate channel {name}: {samples} samples of {per} values \
                     ({:.3e} bytes); record fewer samples (max_samples, record_interval) or \
                     fewer channels",
                    n as f64 * 8.0
                )));
            }
        }
        Ok(())
    }

    /// Record the free state `(q, v)` at `t` \[s\] with integrated `work` \[J\] (`[input,
    /// output, dissipated]`). `q` [rad or m] and `v` [rad/s or m/s] hold one value per free
    /// coordinate, in `ReducerModel::initial_state` order.
    pub fn sample<M: ReducerModel>(
        &mut self,
        model: &M,
        t: f64,
        q: &[f64],
        v: &[f64],
        work: [f64; 3],
    ) -> Result<()> {
        let obs = self.observe(model, t, q, v)?;
        self.push_observed(t, &obs, work);
        Ok(())
    }

    /// Whether a sample evaluates the forces (its observation then carries the accelerations).
    pub fn wants_forces(&self) -> bool {
        self.sink.forces
    }

    /// The first half of [`Recorder::sample`]: evaluate the state `(q, v)` at `t` into the
    /// sample buffers; the observation's power flows can then serve the work integral before
    /// [`Recorder::push_observed`] records the sample.
    pub fn observe<M: ReducerModel>(
        &mut self,
        model: &M,
        t: f64,
        q: &[f64],
        v: &[f64],
    ) -> Result<Observation> {
        model.observe(t, q, v, &mut self.sink)
    }

    /// The second half of [`Recorder::sample`]: append the sample at `t` of the last
    /// [`Recorder::observe`], with integrated `work`.
    pub fn push_observed(&mut self, t: f64, obs: &Observation, work: [f64; 3]) {
        // Split borrows: the sink's buffers go into the series without copies.
        let Self {
            channels,
            rec,
            buffers,
            sink,
            nd,
            initial_energy,
        } = self;
        let nd = *nd;
        let has = |c| channels.contains(&c);
        let mut cursor = 0;
        let mut push = |name: &'static str, values: &[f64]| {
            let n = buffers.len();
            for k in 0..n {
                let i = (cursor + k) % n;
                if buffers[i].0 == name {
                    buffers[i].1.data.extend_from_slice(values);
                    cursor = i;
                    return;
                }
            }
        };
        push("t", &[t]);
        if has(Channel::Motion) {
            push("sun_angle", &[obs.sun_angle]);
            push("sun_speed", &[obs.sun_speed]);
            push("carrier_angle", &[obs.carrier_angle]);
            push("carrier_speed", &[obs.carrier_speed]);
            push("crank_angle", &obs.crank_angle);
            push("crank_speed", &obs.crank_speed);
            for k in 0..nd {
                push("disc_center", &obs.disc_center[k]);
            }
            push("disc_angle", &obs.disc_angle);
            push("load_angle", &[obs.load_angle]);
            push("load_speed", &[obs.load_speed]);
            push("motor_angle", &[obs.motor_angle]);
            push("motor_speed", &[obs.motor_speed]);
        }
        if has(Channel::Pins) {
            let zp = sink.zp;
            let loaded: Vec<f64> = (0..nd)
                .map(|k| {
                    sink.force[k * zp..(k + 1) * zp]
                        .iter()
                        .filter(|f| **f > 0.0)
                        .count() as f64
                })
                .collect();
            push("pin_force", &sink.force);
            push("pin_penetration", &sink.pen);
            push("pin_moment", &sink.moment);
            push("loaded_pins", &loaded);
        }
        if has(Channel::ContactPoints) {
            push("pin_point", &sink.point);
            push("pin_normal", &sink.normal);
        }
        if has(Channel::Mesh) {
            push("mesh_force", &sink.mesh_force);
            push("mesh_deflection", &sink.mesh_deflection);
            push("input_torque", &[obs.input_torque]);
            push("output_shaft_torque", &[obs.output_shaft_torque]);
            push("input_shaft_torque", &[obs.input_shaft_torque]);
        }
        if has(Channel::Energy) {
            let e = obs.kinetic_energy + obs.potential_energy;
            let e0 = *initial_energy.get_or_insert(e);
            let residual = e - e0 - work[0] + work[1] + work[2];
            push("kinetic_energy", &[obs.kinetic_energy]);
            push("potential_energy", &[obs.potential_energy]);
            push("input_work", &[work[0]]);
            push("output_work", &[work[1]]);
            push("dissipated_energy", &[work[2]]);
            push("pin_friction_power", &[obs.friction_power[0]]);
            push("mesh_friction_power", &[obs.friction_power[1]]);
            push("bearing_friction_power", &[obs.friction_power[2]]);
            push("energy_residual", &[residual]);
        }
        if has(Channel::Bearings) {
            push("crank_bearing_force", &sink.crank_bearing);
            push("eccentric_bearing_force", &sink.eccentric_bearing);
            push("crank_deflection", &sink.crank_deflection);
        }
        rec.samples += 1;
    }

    pub fn finish(self) -> Recording {
        let mut rec = self.rec;
        rec.series = self.buffers.into_iter().collect();
        rec
    }
}
