//! A reducer scene: everything a dynamic run needs, serialisable to JSON and TOML.
//!
//! Every field is SI. Optional fields (`None`) are computed from the geometry when the model is
//! built. [`Scene::paper`] is the default scene of docs/model.md#default-scene.

mod paths;
mod presets;
pub mod schema;
mod validate;

pub use paths::get_path;
pub(crate) use paths::{set_path, unknown_fields};
pub use presets::{
    PAPER_INPUT_SPEED, PAPER_POWER, PAPER_PRINTED_LOAD, PHYSICAL_DAMPING_RATIO,
    PHYSICAL_REFERENCE_FREQUENCY, physical_joints,
};

use crate::contact::ImpactLaw;
use crate::contact::law::{ContactDamping, DampingSpec, IsoMesh, MeshLaw, PinLaw, scene_material};
use crate::error::{Result, RvdynError, num};
use crate::geometry::cycloid::CycloidParams;
use crate::geometry::involute::InvoluteStage;
use crate::geometry::mass::MassProperties;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// One cycloid disc on the crank eccentrics.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiscSpec {
    /// Phase of this disc's eccentric on the crank \[rad\] (0 and pi for the two-disc RV).
    pub phase: f64,
    /// Profile modifications of this disc [m, m, rad]; overrides the scene's `cycloid` values.
    #[serde(default)]
    pub d_rp: Option<f64>,
    /// Equidistant modification of this disc \[m\] (`None` = the scene's).
    #[serde(default)]
    pub d_rrp: Option<f64>,
    /// Rotation modification of this disc \[rad\] (`None` = the scene's).
    #[serde(default)]
    pub d_delta: Option<f64>,
    /// Profile error of this disc: a normal offset of the ground profile (`None` = none;
    /// docs/model.md#manufacturing-errors-of-profile-and-gears).
    #[serde(default)]
    pub profile_error: Option<ProfileError>,
}

pub use crate::geometry::cycloid::ProfileError;

/// A torsional shaft between two inertias (SI).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Shaft {
    /// Torsional stiffness [N m/rad] (> 0).
    pub stiffness: f64,
    /// Torsional damping [N m s/rad] (>= 0; default 0).
    #[serde(default)]
    pub damping: f64,
}

/// The shafts that connect the reducer to its machine: `None` = rigid connection (the load
/// inertia joins the carrier, the motor inertia the sun).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Shafts {
    /// Output shaft between the carrier and the load inertia (`inertias.load_inertia`, which
    /// must then be > 0); the load torque acts on the load inertia.
    #[serde(default)]
    pub output: Option<Shaft>,
    /// Drive shaft (coupling) between the motor (`inertias.motor_inertia`) and the sun; the
    /// drive then acts on the motor. Needs a first stage.
    #[serde(default)]
    pub input: Option<Shaft>,
}

/// Runout and pitch error of one gear of the first stage (SI; zero = a perfect gear).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GearError {
    /// Runout: eccentricity of the gear's toothing on its axis \[m\] (>= 0).
    #[serde(default)]
    pub runout: f64,
    /// Direction of the runout in the gear's body frame \[rad\].
    #[serde(default)]
    pub runout_phase: f64,
    /// Amplitude of a sinusoidal cumulative pitch deviation at the rotation order [m, on the
    /// reference circle]: `F(psi) = A sin(psi + pitch_phase)`, `psi` the body angle of the tooth.
    #[serde(default)]
    pub pitch_amplitude: f64,
    /// Phase of the sinusoidal pitch deviation \[rad\].
    #[serde(default)]
    pub pitch_phase: f64,
    /// Cumulative pitch deviation of each tooth [m, on the reference circle] (empty, or one
    /// per tooth; tooth k at body angle `2 pi k / z`, linear in between, periodic; positive =
    /// the tooth is ahead in the positive sense of rotation).
    #[serde(default)]
    pub pitch_deviation: Vec<f64>,
}

impl GearError {
    /// Whether this gear has any error.
    pub fn any(&self) -> bool {
        self.runout != 0.0 || self.pitch_amplitude != 0.0 || !self.pitch_deviation.is_empty()
    }

    /// Check the fields (`at` names the gear, e.g. `"gear_errors.sun"`): finite, runout >= 0,
    /// every deviation below `limit` \[m\] in magnitude, `teeth` deviations or none.
    pub fn check(&self, at: &str, teeth: u32, limit: f64) -> Result<()> {
        let bad = |m: String| Err(RvdynError::Scene(format!("{at}.{m}")));
        for (n, v) in [
            ("runout_phase", self.runout_phase),
            ("pitch_phase", self.pitch_phase),
        ] {
            if !v.is_finite() {
                return bad(format!("{n} must be finite rad, got {v}"));
            }
        }
        if !(self.runout.is_finite() && self.runout >= 0.0 && self.runout < limit) {
            return bad(format!(
                "runout must be in [0, {}) m (a tenth of the module), got {}",
                num(limit),
                self.runout
            ));
        }
        if !(self.pitch_amplitude.is_finite() && self.pitch_amplitude.abs() < limit) {
            return bad(format!(
                "pitch_amplitude must be finite and smaller than {} m (a tenth of the \
                 module) in magnitude, got {}",
                num(limit),
                self.pitch_amplitude
            ));
        }
        let n = self.pitch_deviation.len();
        if n != 0 && n != teeth as usize {
            return bad(format!(
                "pitch_deviation must be empty or have one value per tooth ({teeth}), got {n}"
            ));
        }
        if let Some(v) = self
            .pitch_deviation
            .iter()
            .find(|v| !(v.is_finite() && v.abs() < limit))
        {
            return bad(format!(
                "pitch_deviation values must be finite and smaller than {} m (a tenth of \
                 the module) in magnitude, got {v}",
                num(limit)
            ));
        }
        Ok(())
    }
}

/// Runout and pitch errors of the first-stage gears (docs/model.md#manufacturing-errors-of-profile-and-gears).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GearErrors {
    /// The sun.
    #[serde(default)]
    pub sun: GearError,
    /// Each planet (empty = none, or one per planet).
    #[serde(default)]
    pub planets: Vec<GearError>,
}

impl GearErrors {
    /// Whether any gear has an error.
    pub fn any(&self) -> bool {
        self.sun.any() || self.planets.iter().any(GearError::any)
    }
}

/// Pin manufacturing errors (optional, per pin; index j is the paper's pin j+1).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PinErrors {
    /// Position error of each pin centre, (dx, dy) in the fixed frame \[m\].
    #[serde(default)]
    pub position: Vec<[f64; 2]>,
    /// Radius error of each pin \[m\] (positive = larger pin).
    #[serde(default)]
    pub radius: Vec<f64>,
}

/// Manufacturing and assembly errors of the cranks, discs and carrier (SI; compliant joints
/// only: with ideal joints they would over-constrain the discs). Empty lists mean no error.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AssemblyErrors {
    /// Eccentricity error of each crank \[m\] (`e -> e + de_i`, both eccentrics of the crank).
    #[serde(default)]
    pub crank_eccentricity: Vec<f64>,
    /// Phase error of each crank's eccentrics \[rad\].
    #[serde(default)]
    pub crank_phase: Vec<f64>,
    /// Position error of each crank hole in each disc, `[crank][disc]` flattened as
    /// `crank * discs + disc`, (dx, dy) in the disc frame \[m\].
    #[serde(default)]
    pub disc_holes: Vec<[f64; 2]>,
    /// Position error of each crank seat in the carrier, (dx, dy) in the carrier frame \[m\].
    #[serde(default)]
    pub carrier_seats: Vec<[f64; 2]>,
}

impl AssemblyErrors {
    /// Whether any error is given.
    pub fn any(&self) -> bool {
        !(self.crank_eccentricity.is_empty()
            && self.crank_phase.is_empty()
            && self.disc_holes.is_empty()
            && self.carrier_seats.is_empty())
    }

    /// Check lengths (`cranks`, `cranks * discs`), finiteness, and that an eccentricity error
    /// stays below the eccentricity `e` \[m\] in magnitude.
    pub fn check(&self, cranks: usize, discs: usize, e: f64) -> Result<()> {
        let bad = |m: String| Err(RvdynError::Scene(m));
        for (n, len, want) in [
            ("crank_eccentricity", self.crank_eccentricity.len(), cranks),
            ("crank_phase", self.crank_phase.len(), cranks),
            ("disc_holes", self.disc_holes.len(), cranks * discs),
            ("carrier_seats", self.carrier_seats.len(), cranks),
        ] {
            if len != 0 && len != want {
                return bad(format!(
                    "errors.{n} must be empty or have {want} entries, got {len}"
                ));
            }
        }
        let finite = self
            .crank_eccentricity
            .iter()
            .chain(&self.crank_phase)
            .chain(self.disc_holes.iter().flatten())
            .chain(self.carrier_seats.iter().flatten())
            .all(|v| v.is_finite());
        if !finite {
            return bad("errors must be finite numbers (m, rad)".into());
        }
        if let Some(de) = self.crank_eccentricity.iter().find(|d| d.abs() >= e) {
            return bad(format!(
                "errors.crank_eccentricity {de} m must be smaller in magnitude than the \
                 eccentricity {e} m"
            ));
        }
        Ok(())
    }
}

/// Mass properties of the bodies; `None` = computed from the geometry (steel).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Inertias {
    /// Sun gear and input shaft (inertia about the reducer axis).
    #[serde(default)]
    pub sun: Option<MassProperties>,
    /// One crankshaft with its planet gear and eccentrics (inertia about the crank axis).
    #[serde(default)]
    pub crank: Option<MassProperties>,
    /// One cycloid disc (inertia about its centre).
    #[serde(default)]
    pub disc: Option<MassProperties>,
    /// Carrier (output) with everything bolted to it (inertia about the reducer axis).
    #[serde(default)]
    pub carrier: Option<MassProperties>,
    /// Extra load inertia on the output [kg m^2] (on the carrier, or at the end of the output
    /// shaft when `shafts.output` is given).
    #[serde(default)]
    pub load_inertia: f64,
    /// Motor (rotor) inertia on the input [kg m^2] (on the sun, or at the end of the drive
    /// shaft when `shafts.input` is given; needs a first stage when > 0).
    #[serde(default)]
    pub motor_inertia: f64,
}

/// A bearing spring-damper (compliant joints): linear (`stiffness`, `damping`), or built from
/// its rollers (`rollers`), with `stiffness` and `damping` then a linear spring-damper in
/// parallel (0 for none; same clearance).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Bearing {
    /// Radial stiffness [N/m] (with rollers: a parallel linear spring, 0 for none).
    pub stiffness: f64,
    /// Radial damping [N s/m] (with rollers: a parallel damper, 0 for none).
    pub damping: f64,
    /// Radial clearance per side \[m\].
    #[serde(default)]
    pub clearance: f64,
    /// Roller (needle) bearing: nonlinear load-deflection from its rollers (Palmgren line
    /// contact per roller at both raceways; `bearing::roller`).
    #[serde(default)]
    pub rollers: Option<Rollers>,
}

/// The largest roller length and diameter a scene accepts \[m\]: a larger value is a length in
/// millimetres.
pub const MAX_ROLLER_SIZE: f64 = 1.0;

/// The largest radial clearance per side of a roller bearing, as a share of its pitch
/// diameter: ISO 5753's largest clearance groups stay below about 2e-3 of the bore.
pub const MAX_CLEARANCE_SHARE: f64 = 0.01;

/// The largest Palmgren load factor `f1` a scene accepts: roller bearings have 1e-4 to 1e-3
/// (Palmgren 1959; Harris and Kotzalas 2007, section 7.3).
pub const MAX_PALMGREN_F1: f64 = 1e-2;

/// The rollers of a roller bearing (SI).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Rollers {
    /// Number of rollers (at least 3).
    pub count: u32,
    /// Effective roller length \[m\].
    pub length: f64,
    /// Roller diameter \[m\] (for the ISO 281 load rating).
    pub diameter: f64,
    /// Pitch diameter of the roller set \[m\] (for the load rating).
    pub pitch_diameter: f64,
    /// Damping ratio [-] of the stiffness-proportional roller damping, referred to
    /// `frequency`: each roller pushes with `max(0, Q + beta k delta')`,
    /// `beta = 2 damping_ratio / (2 pi frequency)`.
    pub damping_ratio: f64,
    /// Reference frequency of the damping ratio \[Hz\].
    pub frequency: f64,
}

impl Rollers {
    /// The roller load-deflection law with the bearing's clearance \[m\].
    pub fn bearing(&self, clearance: f64) -> Result<crate::bearing::RollerBearing> {
        crate::bearing::RollerBearing::new(self.count as usize, self.length, clearance)
    }

    /// `beta` \[s\] of the roller damping.
    pub fn beta(&self) -> f64 {
        2.0 * self.damping_ratio / (std::f64::consts::TAU * self.frequency)
    }

    /// ISO 281 basic dynamic load rating \[N\] (one row, `b_m = 1.1`).
    pub fn load_rating(&self) -> Result<f64> {
        self.geometry().dynamic_load_rating()
    }

    /// ISO 76 basic static load rating \[N\] (one row).
    pub fn static_load_rating(&self) -> Result<f64> {
        self.geometry().static_load_rating()
    }

    fn geometry(&self) -> crate::bearing::RollerBearingGeometry {
        crate::bearing::RollerBearingGeometry {
            rollers: self.count,
            rows: 1,
            roller_diameter: self.diameter,
            roller_length: self.length,
            pitch_diameter: self.pitch_diameter,
            contact_angle: 0.0,
            rating_factor: crate::bearing::life::BM_ROLLER,
        }
    }

    /// Check the fields, naming `at` (e.g. `"joints.eccentric_bearing"`) in the message.
    pub fn check(&self, at: &str) -> Result<()> {
        let bad = |m: String| Err(RvdynError::Scene(format!("{at}.rollers: {m}")));
        if self.count < 3 {
            return bad(format!(
                "count must be at least 3 rollers, got {}",
                self.count
            ));
        }
        for (n, v) in [
            ("length", self.length),
            ("diameter", self.diameter),
            ("pitch_diameter", self.pitch_diameter),
            ("frequency", self.frequency),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return bad(format!("{n} must be > 0, got {v}"));
            }
        }
        if self.diameter >= self.pitch_diameter {
            return bad(format!(
                "diameter {} m must be below pitch_diameter {} m",
                self.diameter, self.pitch_diameter
            ));
        }
        // A metre-long roller is a length typed in millimetres (36 for 36 mm gave a 21 MN
        // rating without a word).
        for (n, v) in [("length", self.length), ("diameter", self.diameter)] {
            if v > MAX_ROLLER_SIZE {
                return bad(format!(
                    "{n} is in m and at most {MAX_ROLLER_SIZE} m, got {v} m (a value in mm? \
                     36 mm is 0.036 m)"
                ));
            }
        }
        // The rollers must fit side by side on their pitch circle (full complement at most).
        let circle = std::f64::consts::PI * self.pitch_diameter;
        if f64::from(self.count) * self.diameter >= circle {
            return bad(format!(
                "{} rollers of diameter {} m do not fit on the pitch circle of {} m: count x \
                 diameter = {:.4e} m must be below pi x pitch_diameter = {circle:.4e} m",
                self.count,
                self.diameter,
                self.pitch_diameter,
                f64::from(self.count) * self.diameter
            ));
        }
        if !(self.damping_ratio.is_finite() && (0.0..1.0).contains(&self.damping_ratio)) {
            return bad(format!(
                "damping_ratio must be in [0, 1), got {}",
                self.damping_ratio
            ));
        }
        Ok(())
    }
}

/// Crank-eccentric/disc and crank/carrier bearings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Joints {
    /// Ideal joints (the paper): the discs move exactly with the cranks; DOFs carrier, crank.
    Rigid,
    /// Spring-damper bearings: disc translations and rotations, crank translations are DOFs.
    /// Each family is compliant or rigid on its own where that is consistent: the crank
    /// bearings may stay rigid (`crank_bearing` omitted or null: the crank centres stay in
    /// their seats) while the eccentric bearings are compliant. The reverse (rigid eccentric
    /// bearings on compliant cranks) would tie each disc rigidly to three moving eccentrics,
    /// an over-constrained mechanism; with both rigid, use `Rigid`.
    Compliant {
        /// Needle bearing between each eccentric and its disc hole.
        eccentric_bearing: Bearing,
        /// Bearing between each crankshaft and the carrier; `None` = rigid.
        #[serde(default)]
        crank_bearing: Option<Bearing>,
    },
}

/// Contact law of one contact family.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum ContactLawSpec {
    /// ADAMS IMPACT: `F = k x^e + STEP(x, 0, 0, depth, cmax) xdot`, `F >= 0`.
    Impact {
        /// k [N/m^exponent].
        stiffness: f64,
        /// Force exponent e.
        exponent: f64,
        /// cmax [N s/m].
        max_damping: f64,
        /// Penetration at which the full damping acts \[m\].
        damping_depth: f64,
    },
    /// Steel line contact from the face width (Palmgren, Harris: `delta = 3.84e-5 Q^0.9 /
    /// l^0.8` in mm and N), written as `F = K x^(10/9)` plus the same damping ramp.
    Palmgren {
        /// cmax [N s/m].
        max_damping: f64,
        /// Penetration at which the full damping acts \[m\].
        damping_depth: f64,
    },
    /// Pins only: line contact of the pin and the local profile curvature (Johnson; see
    /// `contact::line_contact`), materials of pin and disc, and a damping law.
    Line {
        /// Young's modulus of pins and discs \[Pa\] (default the paper's 2.17e11).
        #[serde(default = "crate::contact::law::default_youngs_modulus")]
        youngs_modulus: f64,
        /// Poisson's ratio [-] (default 0.3).
        #[serde(default = "crate::contact::law::default_poisson_ratio")]
        poisson_ratio: f64,
        /// Damping of the contacts.
        damping: DampingSpec,
    },
    /// Meshes only: ISO 6336-1 method B stiffness, varying along the line of action with the
    /// single- and double-tooth zones (`gear::iso6336`), and a damping law.
    Iso6336 {
        /// Width of the smoothing ramps at the zone boundaries, fraction of a base pitch
        /// (default 0.02; 0 for jumps).
        #[serde(default = "default_mesh_ramp")]
        ramp: f64,
        /// Damping of the meshes.
        damping: DampingSpec,
        /// Nominal line load `F_t K_A / b` \[N/m\] of one sun/planet mesh for the ISO 6336-1
        /// load factor: below 1e5 N/m (100 N/mm) `c'` is scaled by `(w / 1e5)^(1/4)`. `None`
        /// (default): from the scene's load ([`Scene::nominal_mesh_line_load`]).
        #[serde(default)]
        line_load: Option<f64>,
    },
}

fn default_mesh_ramp() -> f64 {
    0.02
}

impl ContactLawSpec {
    /// Whether the law dissipates nothing (zero damping, or restitution 1).
    pub fn undamped(&self) -> bool {
        use crate::contact::law::DampingSpec;
        match self {
            ContactLawSpec::Impact { max_damping, .. }
            | ContactLawSpec::Palmgren { max_damping, .. } => *max_damping == 0.0,
            ContactLawSpec::Line { damping, .. } | ContactLawSpec::Iso6336 { damping, .. } => {
                match damping {
                    DampingSpec::Restitution { restitution, .. } => *restitution == 1.0,
                    DampingSpec::DampingRatio { ratio, .. } => *ratio == 0.0,
                }
            }
        }
    }

    /// The paper's IMPACT parameters (k = 3.988e5 N/mm^1.5, e = 1.5, cmax = 100 N s/mm,
    /// d = 0.01 mm) in SI.
    pub fn paper() -> Self {
        let l = ImpactLaw::paper();
        ContactLawSpec::Impact {
            stiffness: l.stiffness,
            exponent: l.exponent,
            max_damping: l.max_damping,
            damping_depth: l.damping_depth,
        }
    }

    /// The IMPACT-type law for a contact of length `face_width` \[m\] (`impact` and `palmgren`).
    ///
    /// Errors (`Scene`) for `line` and `iso6336`, which are not IMPACT laws.
    pub fn law(&self, face_width: f64) -> Result<ImpactLaw> {
        match *self {
            ContactLawSpec::Impact {
                stiffness,
                exponent,
                max_damping,
                damping_depth,
            } => ImpactLaw::new(stiffness, exponent, max_damping, damping_depth),
            ContactLawSpec::Palmgren {
                max_damping,
                damping_depth,
            } => {
                // delta_mm = 3.84e-5 F^0.9 / l_mm^0.8  ->  F = (1000 delta l_mm^0.8 / 3.84e-5)^(1/0.9)
                let l_mm = face_width * 1e3;
                let k = (1e3 * l_mm.powf(0.8) / 3.84e-5).powf(1.0 / 0.9);
                ImpactLaw::new(k, 1.0 / 0.9, max_damping, damping_depth)
            }
            ContactLawSpec::Line { .. } | ContactLawSpec::Iso6336 { .. } => Err(RvdynError::Scene(
                "this contact law is not an IMPACT-type law (line and iso6336 are built \
                     from the geometry)"
                    .into(),
            )),
        }
    }

    /// The pin/disc law for discs of face width `face_width` \[m\].
    ///
    /// Errors (`Scene`) for `iso6336` (a mesh law) and invalid parameters.
    pub fn pin_law(&self, face_width: f64) -> Result<PinLaw> {
        match *self {
            ContactLawSpec::Line {
                youngs_modulus,
                poisson_ratio,
                damping,
            } => {
                let m = scene_material("pin", youngs_modulus, poisson_ratio)?;
                Ok(PinLaw::Line {
                    pin: m,
                    disc: m,
                    damping: ContactDamping::new(&damping)
                        .map_err(|e| RvdynError::Scene(format!("contact.pin.damping: {e}")))?,
                })
            }
            ContactLawSpec::Iso6336 { .. } => Err(RvdynError::Scene(
                "contact.pin cannot be \"iso6336\" (a gear mesh law); use \"line\", \
                 \"impact\" or \"palmgren\""
                    .into(),
            )),
            _ => Ok(PinLaw::Impact(self.law(face_width)?)),
        }
    }

    /// The sun/planet mesh law for the stage `stage`; `nominal_line_load` \[N/m\] is the ISO
    /// law's line load when the spec gives none (`None`: the full-load `c'`).
    ///
    /// Errors (`Scene`) for `line` (a pin law) and invalid parameters.
    pub fn mesh_law(
        &self,
        stage: &InvoluteStage,
        nominal_line_load: Option<f64>,
    ) -> Result<MeshLaw> {
        match *self {
            ContactLawSpec::Iso6336 {
                ramp,
                damping,
                line_load,
            } => Ok(MeshLaw::Iso(
                IsoMesh::new(
                    stage.z_sun,
                    stage.z_planet,
                    stage.module,
                    stage.pressure_angle,
                    stage.face_width,
                    ramp,
                    &damping,
                    line_load.or(nominal_line_load),
                )
                .map_err(|e| RvdynError::Scene(format!("contact.mesh: {e}")))?,
            )),
            ContactLawSpec::Line { .. } => Err(RvdynError::Scene(
                "contact.mesh cannot be \"line\" (the pin/disc law); use \"iso6336\", \
                 \"impact\" or \"palmgren\""
                    .into(),
            )),
            _ => Ok(MeshLaw::Impact(self.law(stage.face_width)?)),
        }
    }
}

/// Contact laws per family.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactLaws {
    /// Pin / cycloid profile contacts.
    pub pin: ContactLawSpec,
    /// Sun / planet meshes (along the line of action).
    pub mesh: ContactLawSpec,
}

/// Friction in the reducer (all zero by default: frictionless, as the paper).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Friction {
    /// Coulomb coefficient at the pin/disc contacts [-], in [0, 1].
    #[serde(default)]
    pub pin: f64,
    /// Pins that roll in the housing: the sliding moves to the pin/housing contact, at the
    /// radius `pin_rolling * rrp` (1 for a pin in a groove of its own radius, less for a
    /// sleeve on a journal); the tangential force on the disc is then `pin * pin_rolling * N`.
    /// `None`: pins fixed, sliding at the disc.
    #[serde(default)]
    pub pin_rolling: Option<f64>,
    /// Coulomb coefficient at the sun/planet teeth [-], in [0, 1] (sliding along the tooth).
    #[serde(default)]
    pub mesh: f64,
    /// Regularisation speed of the Coulomb law [m/s] (`contact::friction`): default 1e-3.
    #[serde(default = "default_regularisation_speed")]
    pub regularisation_speed: f64,
    /// Palmgren friction torque of the joint bearings (compliant joints only).
    #[serde(default)]
    pub bearing: Option<BearingFriction>,
}

/// Largest accepted bearing-oil kinematic viscosity [m^2/s] (10 000 cSt).
pub const MAX_OIL_VISCOSITY: f64 = 1e-2;

fn default_regularisation_speed() -> f64 {
    1e-3
}

impl Default for Friction {
    fn default() -> Self {
        Self {
            pin: 0.0,
            pin_rolling: None,
            mesh: 0.0,
            regularisation_speed: default_regularisation_speed(),
            bearing: None,
        }
    }
}

impl Friction {
    /// Whether any friction acts.
    pub fn any(&self) -> bool {
        self.pin > 0.0 || self.mesh > 0.0 || self.bearing.is_some()
    }

    /// Check the fields; errors name the field and its limits.
    pub fn check(&self) -> Result<()> {
        let bad = |m: String| Err(RvdynError::Scene(m));
        for (n, mu) in [("pin", self.pin), ("mesh", self.mesh)] {
            if !(mu.is_finite() && (0.0..=1.0).contains(&mu)) {
                return bad(format!(
                    "friction.{n} must be a friction coefficient in [0, 1], got {mu}"
                ));
            }
        }
        if let Some(l) = self.pin_rolling
            && !(l.is_finite() && l > 0.0 && l <= 1.0)
        {
            return bad(format!(
                "friction.pin_rolling must be a lever ratio in (0, 1], got {l}"
            ));
        }
        let v = self.regularisation_speed;
        if !(v.is_finite() && v > 0.0) {
            return bad(format!(
                "friction.regularisation_speed must be > 0 m/s, got {v}"
            ));
        }
        if let Some(b) = &self.bearing {
            for (n, x) in [("f0", b.f0), ("f1", b.f1), ("viscosity", b.viscosity)] {
                if !(x.is_finite() && x >= 0.0) {
                    return bad(format!("friction.bearing.{n} must be >= 0, got {x}"));
                }
            }
            if b.f1 > MAX_PALMGREN_F1 {
                return bad(format!(
                    "friction.bearing.f1 is Palmgren's load factor, 1e-4 to 1e-3 for roller \
                     bearings, at most {MAX_PALMGREN_F1}; got {}",
                    b.f1
                ));
            }
            // 1e-2 m^2/s is 10 000 cSt, thicker than any bearing oil at its running
            // temperature (ISO VG 1000 has 1000 cSt at 40 C): a larger value is a unit mistake.
            if b.viscosity > MAX_OIL_VISCOSITY {
                return bad(format!(
                    "friction.bearing.viscosity is a kinematic viscosity in m^2/s, got {} m^2/s \
                     ({:.6} cSt, above the limit of {MAX_OIL_VISCOSITY} m^2/s = 10 000 cSt, more than \
                     any bearing oil); 68 cSt is 68e-6 m^2/s",
                    b.viscosity,
                    b.viscosity * 1e6
                ));
            }
        }
        Ok(())
    }
}

/// Palmgren bearing friction coefficients (`bearing::PalmgrenFriction`); the pitch diameters
/// come from the bearings' rollers (linear bearings: 50 mm assumed).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BearingFriction {
    /// Load-independent factor `f0` [-].
    pub f0: f64,
    /// Load factor `f1` [-].
    pub f1: f64,
    /// Oil kinematic viscosity [m^2/s].
    pub viscosity: f64,
}

/// How the input starts.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StartKind {
    /// Full speed from t = 0 (the paper: an impact at start).
    Step,
    /// Smooth cubic ramp from 0 to full speed over `ramp_time`.
    Ramp,
}

/// The drive on the input (sun, or the cranks when there is no first stage).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Drive {
    /// Prescribed input speed [rad/s].
    Speed {
        /// Input speed [rad/s].
        speed: f64,
        /// How the speed starts.
        start: StartKind,
        /// Ramp duration \[s\] (for `start = "ramp"`).
        #[serde(default)]
        ramp_time: f64,
    },
    /// Prescribed input torque [N m] (the input becomes a degree of freedom).
    Torque {
        /// Input torque [N m].
        torque: f64,
        /// Ramp duration \[s\] (0 = full torque from t = 0).
        #[serde(default)]
        ramp_time: f64,
    },
}

/// Nominal sun/planet mesh force \[N\] below which a load is light
/// ([`Scene::is_light_load`]): measured from rest over [0.5, 1] s of 1 s runs
/// (docs/validation.md, "Idle rattle and light loads"), generalized-alpha at dt 1e-4 s put the
/// paper scene's peak mesh force 78 % too high at 0.95 N and was exact to 1e-5 at 2.9 N; dopri5
/// at atol 1e-8 m put the physical preset's peak pin force 120 % too high at 0.95 N, 32 % at
/// 2.9 N and 2 % at 9.5 N (against 1-3 % between its references).
pub const LIGHT_LOAD_MESH_FORCE: f64 = 10.0;

/// Load torque on the carrier (acts against positive, counter-clockwise output rotation).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Load {
    /// No load.
    Idle,
    /// Constant torque [N m] from t = 0.
    Constant {
        /// Torque [N m].
        torque: f64,
    },
    /// `before` [N m] until `time` \[s\], then `after`.
    Step {
        /// Torque before the step [N m].
        before: f64,
        /// Torque after the step [N m].
        after: f64,
        /// Time of the step \[s\].
        time: f64,
    },
    /// Piecewise-linear table of (t \[s\], torque [N m]), held constant outside.
    Table {
        /// (t \[s\], torque [N m]) pairs, times strictly increasing.
        points: Vec<[f64; 2]>,
    },
}

impl Load {
    /// Load torque at time `t` [N m].
    pub fn torque(&self, t: f64) -> f64 {
        match self {
            Load::Idle => 0.0,
            Load::Constant { torque } => *torque,
            Load::Step {
                before,
                after,
                time,
            } => {
                if t < *time {
                    *before
                } else {
                    *after
                }
            }
            Load::Table { points } => table_value(points, t),
        }
    }
}

fn table_value(points: &[[f64; 2]], t: f64) -> f64 {
    match points {
        [] => 0.0,
        [only] => only[1],
        _ => {
            if t <= points[0][0] {
                return points[0][1];
            }
            for w in points.windows(2) {
                if t <= w[1][0] {
                    let s = (t - w[0][0]) / (w[1][0] - w[0][0]);
                    return w[0][1] + s * (w[1][1] - w[0][1]);
                }
            }
            points[points.len() - 1][1]
        }
    }
}

/// Initial state.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Initial {
    /// Everything at rest in the kinematic pose (the paper's start).
    Rest,
    /// Every body at its kinematic speed for the drive's full input speed.
    Steady,
}

/// A complete reducer description.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// A label for reports.
    #[serde(default)]
    pub name: String,
    /// First (involute) stage; `None` = single-stage cycloid drive driven at the cranks.
    #[serde(default)]
    pub stage1: Option<InvoluteStage>,
    /// Cycloid disc geometry and default modifications.
    pub cycloid: CycloidParams,
    /// The discs (one or two).
    pub discs: Vec<DiscSpec>,
    /// Number of crankshafts (3 in the paper's RV).
    pub cranks: u32,
    /// Pin manufacturing errors.
    #[serde(default)]
    pub pin_errors: PinErrors,
    /// Material density for computed inertias [kg/m^3].
    pub density: f64,
    /// Mass properties (`None` entries computed from the geometry).
    #[serde(default)]
    pub inertias: Inertias,
    /// Rigid or compliant joints.
    pub joints: Joints,
    /// Contact laws of the pins and meshes.
    pub contact: ContactLaws,
    /// Friction (default: none).
    #[serde(default)]
    pub friction: Friction,
    /// Manufacturing and assembly errors of cranks, discs and carrier (default: none).
    #[serde(default)]
    pub errors: AssemblyErrors,
    /// Runout and pitch errors of the first-stage gears (default: none).
    #[serde(default)]
    pub gear_errors: GearErrors,
    /// Output and drive shafts (default: rigid connections).
    #[serde(default)]
    pub shafts: Shafts,
    /// Where the crank's bearings, discs and planet sit along its axis, to split the models'
    /// lumped crank bearing into its two bearings (default: none, the lumped row only).
    #[serde(default)]
    pub crank_layout: Option<crate::bearing::CrankLayout>,
    /// The crankshafts' section, for their bending between the bearings in the quasi-static
    /// analyses, the modes and the dynamic model (needs `crank_layout` and compliant joints;
    /// default: none, rigid cranks).
    #[serde(default)]
    pub crank_shaft: Option<crate::bearing::CrankShaft>,
    /// The input drive.
    pub drive: Drive,
    /// The load on the output.
    pub load: Load,
    /// Initial state.
    pub initial: Initial,
}

/// A parser's multi-line report (position, source excerpt with a caret, message) as one line:
/// the first line and the message.
fn one_line(e: &dyn std::fmt::Display) -> String {
    let text = e.to_string();
    let lines: Vec<&str> = text
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('|') && !l.contains(" | "))
        .collect();
    match lines.as_slice() {
        [] => text,
        [one] => (*one).to_string(),
        [first, .., last] => format!("{first}: {last}"),
    }
}

impl Scene {
    /// The same reducer with rigid joints, for what only the rigid model's geometry, laws and
    /// masses are wanted from (the LTCA's laws, the mass properties): without the assembly
    /// errors, the bearing friction and the crankshaft bending that only compliant joints
    /// carry, which a rigid scene refuses.
    pub fn rigid_counterpart(&self) -> Scene {
        let mut s = self.clone();
        s.joints = Joints::Rigid;
        s.errors = AssemblyErrors::default();
        s.friction.bearing = None;
        s.crank_shaft = None;
        s
    }

    /// Parse a scene from JSON text.
    pub fn from_json(text: &str) -> Result<Self> {
        let v: serde_json::Value = serde_json::from_str(text)
            .map_err(|e| RvdynError::Scene(format!("scene text is not valid JSON: {e}")))?;
        Self::from_value(&v)
    }

    /// Build and validate a scene from a JSON tree. Every key of the tree must be a field of
    /// the schema: an unknown one (a typo, or a field of another `kind`) is a `Scene` error
    /// naming its path, in internally tagged enums too (where serde's `deny_unknown_fields`
    /// does not reach).
    pub fn from_value(v: &serde_json::Value) -> Result<Self> {
        // The path of the value serde could not read, not only what was wrong with it: from
        // the schema table where a value has the wrong type, else from serde's path (which
        // stops at an internally tagged object).
        let s: Scene = serde_path_to_error::deserialize(v.clone()).map_err(|e| {
            if let Some(m) = schema::mistyped(v) {
                return RvdynError::Scene(format!("invalid scene: {m}"));
            }
            let path = e.path().to_string();
            let at = if path == "." {
                String::new()
            } else {
                format!("{path}: ")
            };
            RvdynError::Scene(format!("invalid scene: {at}{}", e.inner()))
        })?;
        let normal = s.to_value()?;
        unknown_fields(v, &normal, "")?;
        s.validate()?;
        Ok(s)
    }

    /// The scene as a JSON tree (every field present, `null` for an absent optional one).
    pub fn to_value(&self) -> Result<serde_json::Value> {
        serde_json::to_value(self)
            .map_err(|e| RvdynError::Scene(format!("scene cannot be written as JSON: {e}")))
    }

    /// Serialise to pretty JSON.
    pub fn to_json(&self) -> Result<String> {
        serde_json::to_string_pretty(self)
            .map_err(|e| RvdynError::Scene(format!("scene cannot be written as JSON: {e}")))
    }

    /// Parse a scene from TOML text.
    pub fn from_toml(text: &str) -> Result<Self> {
        let v: serde_json::Value = toml::from_str(text).map_err(|e| {
            RvdynError::Scene(format!("scene text is not valid TOML: {}", one_line(&e)))
        })?;
        Self::from_value(&v)
    }

    /// Serialise to TOML.
    pub fn to_toml(&self) -> Result<String> {
        toml::to_string(self)
            .map_err(|e| RvdynError::Scene(format!("scene cannot be written as TOML: {e}")))
    }

    /// A new validated scene with fields changed: `changes` maps dotted paths (list indices as
    /// numbers: `"discs.1.d_rrp"`) to JSON values; a whole sub-tree may be replaced.
    pub fn replace(&self, changes: &[(String, serde_json::Value)]) -> Result<Self> {
        let mut tree = self.to_value()?;
        for (path, value) in changes {
            set_path(&mut tree, path, value.clone())?;
        }
        Self::from_value(&tree).map_err(|e| match e {
            // The type errors of the deserialiser name no field: name the changed ones.
            RvdynError::Scene(m) if m.starts_with("invalid scene:") => {
                let paths: Vec<&str> = changes.iter().map(|(p, _)| p.as_str()).collect();
                RvdynError::Scene(format!("{m} (in the change of {})", paths.join(", ")))
            }
            other => other,
        })
    }

    /// Geometry parameters of disc `k` (scene values with the disc's own modifications).
    pub fn disc_params(&self, k: usize) -> CycloidParams {
        let mut p = self.cycloid;
        if let Some(d) = self.discs.get(k) {
            p.d_rp = d.d_rp.unwrap_or(p.d_rp);
            p.d_rrp = d.d_rrp.unwrap_or(p.d_rrp);
            p.d_delta = d.d_delta.unwrap_or(p.d_delta);
        }
        p
    }

    /// Nominal line load `F_t K_A / b` \[N/m\] of one sun/planet mesh for the ISO 6336-1 load
    /// factor: the largest output torque magnitude of the load law over the ratio is the sun's
    /// torque, shared by the planets at the sun's reference radius `m z_sun / 2`
    /// (`F_t = 2 T_sun / (d_sun planets)`, ISO 6336-1 clause 6), with `K_A = 1` (the dynamics
    /// are modelled, not factored) and `b` the face width. `None` without a first stage or
    /// without load (idle: the load factor is then not applied).
    pub fn nominal_mesh_line_load(&self) -> Option<f64> {
        let w = self.nominal_mesh_force()? / self.stage1.as_ref()?.face_width;
        (w.is_finite() && w > 0.0).then_some(w)
    }

    /// The largest load torque magnitude of the load law [N m] (0 for idle).
    pub fn peak_load_torque(&self) -> f64 {
        match &self.load {
            Load::Idle => 0.0,
            Load::Constant { torque } => torque.abs(),
            Load::Step { before, after, .. } => before.abs().max(after.abs()),
            Load::Table { points } => points.iter().fold(0.0f64, |m, p| m.max(p[1].abs())),
        }
    }

    /// Nominal tangential force `F_t = 2 T_sun / (d_sun planets)` \[N\] of one sun/planet mesh
    /// at the load's largest torque ([`Scene::peak_load_torque`] over the ratio is the sun's
    /// torque; ISO 6336-1 clause 6); 0 for idle, `None` without a first stage.
    ///
    /// ```
    /// use rvdyn::dynamics::scene::Scene;
    /// // 43.9 kN m / 57 on a sun of 18 teeth, module 3 mm, shared by 3 planets: 9.5 kN.
    /// let f = Scene::paper("rated").unwrap().nominal_mesh_force().unwrap();
    /// assert!((f - 9512.9).abs() < 0.1);
    /// ```
    pub fn nominal_mesh_force(&self) -> Option<f64> {
        let s = self.stage1.as_ref()?;
        let t_sun = self.peak_load_torque() / self.ratio().abs();
        Some(t_sun / (0.5 * s.module * f64::from(s.z_sun) * f64::from(s.planets)))
    }

    /// Whether the load is light: idle, or a first-stage [`Scene::nominal_mesh_force`] below
    /// [`LIGHT_LOAD_MESH_FORCE`] (a scene without a first stage is light only when idle). The
    /// contact forces of a light scene are a few newtons, which the loaded scenes' default
    /// integrators do not resolve (docs/validation.md, "Idle rattle and light loads").
    pub fn is_light_load(&self) -> bool {
        match self.nominal_mesh_force() {
            Some(f) => f < LIGHT_LOAD_MESH_FORCE,
            None => matches!(self.load, Load::Idle),
        }
    }

    /// The sun/planet mesh law of this scene's first stage `stage`, with the ISO law's line
    /// load from [`Scene::nominal_mesh_line_load`] unless the spec sets it.
    pub fn stage_mesh_law(&self, stage: &InvoluteStage) -> Result<MeshLaw> {
        self.contact
            .mesh
            .mesh_law(stage, self.nominal_mesh_line_load())
    }

    /// Transmission ratio input speed / output speed of this scene (57 for the paper; `-zc`
    /// when there is no first stage and the cranks are the input: the output turns backwards).
    pub fn ratio(&self) -> f64 {
        let zp = f64::from(self.cycloid.pins);
        match &self.stage1 {
            Some(s) => 1.0 + f64::from(s.z_planet) / f64::from(s.z_sun) * zp,
            None => -(zp - 1.0),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn json_close(a: &serde_json::Value, b: &serde_json::Value) -> bool {
        use serde_json::Value::*;
        match (a, b) {
            (Number(x), Number(y)) => {
                let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
                (x - y).abs() <= 4.0 * f64::EPSILON * x.abs().max(y.abs())
            }
            (Array(x), Array(y)) => {
                x.len() == y.len() && x.iter().zip(y).all(|(p, q)| json_close(p, q))
            }
            (Object(x), Object(y)) => {
                x.len() == y.len()
                    && x.iter()
                        .all(|(k, v)| y.get(k).is_some_and(|w| json_close(v, w)))
            }
            _ => a == b,
        }
    }

    #[test]
    fn paper_scene_is_valid_and_round_trips() {
        for load in ["idle", "paper", "rated"] {
            let s = Scene::paper(load).unwrap();
            s.validate().unwrap();
            assert_eq!(Scene::from_json(&s.to_json().unwrap()).unwrap(), s);
            // The toml crate may round the last bit of a float: compare through JSON numbers.
            let back = Scene::from_toml(&s.to_toml().unwrap()).unwrap();
            let (a, b): (serde_json::Value, serde_json::Value) = (
                serde_json::from_str(&s.to_json().unwrap()).unwrap(),
                serde_json::from_str(&back.to_json().unwrap()).unwrap(),
            );
            assert!(json_close(&a, &b), "{a}\n{b}");
        }
        assert!((Scene::paper("idle").unwrap().ratio() - 57.0).abs() < 1e-12);
        match Scene::paper("rated").unwrap().load {
            Load::Constant { torque } => assert!((torque - 43_923.0).abs() < 5.0, "{torque}"),
            _ => panic!(),
        }
    }

    #[test]
    fn unknown_fields_are_rejected_in_tagged_enums_too() {
        // serde's deny_unknown_fields does not reach internally tagged enums, so a misspelt
        // field there must still be an error.
        let base = Scene::paper("idle").unwrap();
        for (path, value) in [
            (
                "load",
                r#"{"kind": "constant", "torque": 1.0, "torqe": 2.0}"#,
            ),
            ("load", r#"{"kind": "idle", "torque": 5.0}"#),
            ("joints", r#"{"kind": "rigid", "stiffness": 1e9}"#),
            (
                "inertias.sun",
                r#"{"mass": 1.0, "inertia": 1.0, "mas": 2.0}"#,
            ),
            (
                "contact.pin",
                r#"{"kind": "palmgren", "max_damping": 1.0, "damping_depth": 1e-5, "stiffness": 1.0}"#,
            ),
            ("drive.spede", "1.0"),
        ] {
            let v: serde_json::Value = serde_json::from_str(value).unwrap();
            let err = base.replace(&[(path.to_string(), v)]).unwrap_err();
            assert!(
                matches!(err, RvdynError::Scene(_)) && err.to_string().contains("unknown"),
                "{path}: {err}"
            );
        }
        // A known field through the same path works.
        let v = serde_json::json!({"kind": "constant", "torque": 1.0});
        let s = base.replace(&[("load".into(), v)]).unwrap();
        assert_eq!(s.load, Load::Constant { torque: 1.0 });
        let s = s
            .replace(&[("discs.1.d_rrp".into(), serde_json::json!(2e-5))])
            .unwrap();
        assert_eq!(s.discs[1].d_rrp, Some(2e-5));
        assert!(
            s.replace(&[("discs.2.d_rrp".into(), serde_json::json!(1.0))])
                .is_err()
        );
        assert!(s.replace(&[("".into(), serde_json::json!(1.0))]).is_err());
    }

    #[test]
    fn bad_scenes_say_what_is_wrong() {
        assert!(
            Scene::paper("heavy")
                .unwrap_err()
                .to_string()
                .contains("unknown load case")
        );
        let mut s = Scene::paper("idle").unwrap();
        s.discs.clear();
        assert!(
            s.validate()
                .unwrap_err()
                .to_string()
                .contains("1 or 2 discs")
        );
        let mut s = Scene::paper("idle").unwrap();
        s.pin_errors.radius = vec![0.0; 5];
        assert!(
            s.validate()
                .unwrap_err()
                .to_string()
                .contains("one value per pin")
        );
        let mut s = Scene::paper("idle").unwrap();
        s.load = Load::Constant { torque: f64::NAN };
        assert!(s.validate().is_err());
        assert!(Scene::from_json("{\"name\": 3}").is_err());
        let text = Scene::paper("idle")
            .unwrap()
            .to_json()
            .unwrap()
            .replace("\"cranks\"", "\"crankz\"");
        assert!(
            Scene::from_json(&text)
                .unwrap_err()
                .to_string()
                .contains("crankz")
        );
    }

    #[test]
    fn load_table_interpolates() {
        let l = Load::Table {
            points: vec![[0.0, 0.0], [1.0, 10.0], [2.0, 10.0]],
        };
        assert_eq!(l.torque(-1.0), 0.0);
        assert!((l.torque(0.25) - 2.5).abs() < 1e-12);
        assert_eq!(l.torque(5.0), 10.0);
    }
}
