//! Compliant-joint model: spring-damper bearings between the cranks, the discs and the carrier
//! (docs/model.md#compliant-joint-model: compliant joints add crank and disc translations).
//!
//! Every coordinate is absolute in the fixed frame, so the mass matrix is constant and
//! diagonal. The full coordinate vector is
//! `x = [th_c, th_s, (x_i, y_i, alpha_i) per crank i, (X_k, Y_k, theta_k) per disc k]`:
//! carrier angle (inertia `J_c + J_load`; rigid main bearings, rotation only), sun angle
//! (`J_s`), crank centre and absolute crank rotation (`m_cr`, `J_cr`), disc centre and disc
//! angle (`m_d`, `J_d`). The inertias, the disc and pin geometry, the contact laws, the drive
//! and the load are those of the rigid model built from the same scene, so both models agree
//! in the rigid limit (the rigid model's reduced mass matrix is this one's kinetic energy on
//! the rigid-joint manifold).
//!
//! Crank `i` sits at `gamma_i = 2 pi i / n` on the carrier, at the crank-circle radius `r_cr`:
//! its seat is `s_i = r_cr u_i`, `u_i = (cos(th_c + gamma_i), sin(th_c + gamma_i))`. Couplings,
//! each a potential `V` with a dissipation, generalised forces `Q = -dV/dq - damping` applied
//! consistently to both bodies (so the energy balance closes):
//! - crank bearing `i`: a radial spring-damper on `d = p_i - s_i` (force on the crank centre,
//!   reaction on the carrier at `s_i`);
//! - eccentric bearing `(i, k)`: a radial spring-damper on `d = H_ik - E_ik` between the
//!   eccentric centre `E_ik = p_i + e (cos(alpha_i + a_k), sin(alpha_i + a_k))` and the disc
//!   hole centre `H_ik = O_k + R(theta_k) h_ik`, `h_ik = R(-delta_k) r_cr (cos gamma_i,
//!   sin gamma_i)`, `delta_k = -a_k / zc`; in the kinematic pose (`p_i = s_i`,
//!   `alpha_i = alpha`, `O_k = e (cos(alpha + a_k), sin(alpha + a_k))`,
//!   `theta_k = th_c + delta_k`) `H = E` exactly;
//! - a bearing spring-damper with radial clearance `c` acts only when `|d| > c`, with magnitude
//!   `k (|d| - c) + c_b d|d|/dt`, clamped at 0 (it cannot pull), along `d / |d|`; with `c = 0`
//!   it is the linear vector spring-damper `F = -k d - c_b d'`;
//! - pin contacts: the exact contact of each pin with disc `k` in its free pose
//!   (`pin_query`; pins that provably cannot touch are skipped, as in the rigid model); penetration rate `N . (O_k' + theta_k' z x arm)`; force `-F N` on the disc;
//! - sun/planet mesh `i`: deflection along the line of action
//!   `delta_i = r_bs (th_s - th_c) + r_bp (alpha_i - th_c) - (p_i - s_i) . w_i`, with
//!   `w_i = R(pi/2 - pressure_angle) u_i` the direction in which the sun pushes planet `i`
//!   (in the rigid limit the rigid model's deflection), with backlash and the IMPACT law on
//!   both flanks; `Q = -F grad(delta_i)`, including the carrier-angle derivatives of `s_i` and
//!   `w_i`;
//! - the load torque on the carrier and the drive on the input (the sun, or the cranks when
//!   there is no first stage: a speed drive then prescribes every crank's absolute rotation,
//!   a torque drive is shared equally by the cranks).

use std::cell::Cell;
use std::f64::consts::TAU;

use crate::bearing::PalmgrenFriction;
use crate::contact::law::PinLaw;
use crate::contact::line_contact::PinDiscLawBase;
use crate::dynamics::model::laws::BearingLaw;
pub use crate::dynamics::model::laws::{BearingLoad, linear_bearing as bearing_load};
use crate::dynamics::model::parts::Parts;
use crate::dynamics::model::pin_contact::{
    SeparationBound, WarmStart, first_touch_report, mark_open,
};
use crate::dynamics::model::vec2::{add, perp, rotate, scaled, sub};
use crate::dynamics::model::{Layout, Observation, ReducerModel};
use crate::dynamics::run::sink::{ContactSink, DynSink, EnergySink, NoSink};
use crate::dynamics::scene::{Bearing, Initial, Joints, Scene};
use crate::error::{Result, RvdynError};
use crate::solve::MechanicalSystem;

/// Index of the carrier angle in the full coordinate vector.
pub const CARRIER: usize = 0;
/// Index of the sun angle in the full coordinate vector (unused without a first stage).
pub const SUN: usize = 1;

/// Typical compliant joints (assumed; orders of magnitude from docs/model.md#compliant-joint-model:
/// needle bearings ~1e9 N/m radial, crank/main bearings ~1e9-5e9 N/m):
/// - eccentric (needle) bearing between each eccentric and its disc hole: 1.0e9 N/m,
///   1.0e4 N s/m (damping ratio about 0.04 for a disc on its three bearings);
/// - crank bearing between each crankshaft and the carrier: 2.0e9 N/m, 1.0e4 N s/m;
/// - no clearance.
pub fn default_joints() -> Joints {
    Joints::Compliant {
        eccentric_bearing: Bearing {
            stiffness: 1.0e9,
            damping: 1.0e4,
            clearance: 0.0,
            rollers: None,
        },
        crank_bearing: Some(Bearing {
            stiffness: 2.0e9,
            damping: 1.0e4,
            clearance: 0.0,
            rollers: None,
        }),
    }
}

/// Energy flows of one force evaluation.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Flows {
    /// Power dissipated by contact and bearing damping and by friction \[W\].
    dissipation: f64,
    /// Elastic energy of the contacts and bearings \[J\] (contacts only when asked for).
    pub(crate) potential: f64,
    /// Friction power per family \[W\]: pins, teeth, bearings (part of `dissipation`).
    friction: [f64; 3],
}

/// Bending crankshafts in the dynamic model (docs/model.md, "Crankshaft bending in the
/// dynamic model").
#[derive(Debug, Clone)]
pub(crate) struct Bending {
    /// The eccentrics' stiffness against bending [N/m], row-major `discs x discs`, the same in
    /// `x` and `y` ([`crate::bearing::CrankShaft::stiffness`]).
    pub(crate) stiffness: Vec<f64>,
    /// Mass moving with each eccentric's centre [kg] (`crank_shaft.eccentric_mass`, by
    /// default the shaft's section over the disc's width).
    pub(crate) mass: f64,
}

impl Bending {
    /// From a validated scene; `None` without `crank_shaft`. Errors (`Scene`): eccentrics
    /// heavier than the crank they are part of.
    fn of(scene: &Scene, discs: usize, crank_mass: f64) -> Result<Option<Self>> {
        let (Some(shaft), Some(layout)) = (&scene.crank_shaft, &scene.crank_layout) else {
            return Ok(None);
        };
        let stiffness = shaft
            .stiffness(layout)
            .map_err(|e| RvdynError::Scene(format!("crank_shaft: {e}")))?;
        let width = scene.cycloid.face_width;
        let mass = shaft.eccentric_mass.unwrap_or(
            scene.density * 0.25 * std::f64::consts::PI * shaft.diameter.powi(2) * width,
        );
        if discs as f64 * mass >= crank_mass {
            return Err(RvdynError::Scene(format!(
                "crank_shaft: the eccentrics ({discs} x {mass:.4} kg, eccentric_mass or by \
                 default the shaft's section over the disc width) are heavier than the crank \
                 ({crank_mass:.4} kg, inertias.crank.mass): give the crank its real mass, the \
                 eccentrics a smaller one or the shaft a smaller diameter"
            )));
        }
        Ok(Some(Self { stiffness, mass }))
    }
}

/// The compliant-joint reducer model (a [`MechanicalSystem`] in its free coordinates).
#[derive(Debug, Clone)]
pub struct CompliantModel {
    /// Geometry, laws, inertias, drive and load (shared with the rigid model).
    pub(crate) parts: Parts,
    /// Law of the needle bearing between each eccentric and its disc hole.
    pub(crate) eccentric_bearing: BearingLaw,
    /// `None`: rigid crank bearings, the crank centres stay in their seats on the carrier
    /// (their mass then turns with the carrier: `n m_cr r_cr^2` joins its inertia).
    pub(crate) crank_bearing: Option<BearingLaw>,
    /// Number of cranks.
    pub(crate) cranks: usize,
    /// `(cos gamma_i, sin gamma_i)` of each crank seat.
    seats: Vec<[f64; 2]>,
    /// Disc hole centres `h_ik` in the disc frame, at `i * discs + k` \[m\].
    holes: Vec<[f64; 2]>,
    /// `(sin, cos)` of the pressure angle: `w_i = sin u_i + cos (z x u_i)`.
    pressure: [f64; 2],
    /// Diagonal mass of every full coordinate [kg or kg m^2].
    pub(crate) mass: Vec<f64>,
    /// Free coordinates of the reducer (indices into the full vector; what the quasi-static
    /// and modal analyses see).
    pub(crate) free: Vec<usize>,
    /// All free coordinates: `free`, then the machine shafts' (load, motor).
    pub(crate) coords: Vec<usize>,
    /// Prescribed coordinates (the sun, or every crank rotation without a first stage).
    pub(crate) prescribed: Vec<usize>,
    /// Coordinates the input torque acts on (shared equally).
    input: Vec<usize>,
    /// Lever per free coordinate [m per unit].
    scale: Vec<f64>,
    /// Foot parameter of each (disc, pin) contact at the last evaluation (Newton warm start;
    /// the contact found does not depend on it).
    warm_seeds: Vec<Cell<WarmStart>>,
    /// The line law's contact-independent part of each (disc, pin) contact and `ln` of each
    /// disc's body depth (empty for other pin laws), prepared once: the law at a contact
    /// then takes one logarithm ([`PinDiscLawBase`]).
    line_bases: Vec<PinDiscLawBase>,
    ln_depths: Vec<f64>,
    /// Skip the exact query of a pin that provably cannot touch ([`SeparationBound`]).
    pub(crate) skip_separated: bool,
    separation: Vec<Cell<SeparationBound>>,
    /// Crank seats in the carrier frame, `r_cr (cos g_i, sin g_i)` plus the seat error \[m\].
    seat_vecs: Vec<[f64; 2]>,
    /// Eccentricity \[m\] and phase error \[rad\] of each crank.
    ecc_radius: Vec<f64>,
    ecc_phase: Vec<f64>,
    /// Palmgren friction of the eccentric and crank bearings, with the regularisation speeds
    /// [rad/s] of their relative rotation.
    bearing_friction: Option<[(PalmgrenFriction, f64); 2]>,
    /// Bending crankshafts (`crank_shaft`): each eccentric centre is then a body of its own,
    /// tied to its crank's line by the shaft's stiffness.
    pub(crate) bending: Option<Bending>,
    /// Index of the load angle in the full vector (with an output shaft).
    pub(crate) load_index: Option<usize>,
    /// Index of the motor angle in the full vector (with a drive shaft).
    pub(crate) motor_index: Option<usize>,
}

impl CompliantModel {
    /// Build the model of a validated scene with `joints = Compliant {..}`.
    pub fn new(scene: &Scene) -> Result<Self> {
        scene.validate()?;
        let Joints::Compliant {
            eccentric_bearing,
            crank_bearing,
        } = scene.joints
        else {
            return Err(RvdynError::Scene(
                "this model needs joints.kind = \"compliant\"; the rigid model is built by \
                 RigidModel"
                    .into(),
            ));
        };
        let base = Parts::new(scene)?;
        let n = base.cranks;
        let nd = base.discs.len();
        let seats: Vec<[f64; 2]> = (0..n)
            .map(|i| {
                let (s, c) = (TAU * i as f64 / n as f64).sin_cos();
                [c, s]
            })
            .collect();
        let errs = &scene.errors;
        let mut holes = Vec::with_capacity(n * nd);
        for (i, seat) in seats.iter().enumerate() {
            for (k, d) in base.discs.iter().enumerate() {
                let dh = errs.disc_holes.get(i * nd + k).copied().unwrap_or([0.0; 2]);
                holes.push(add(
                    rotate(-d.angle_offset, scaled(base.crank_radius, *seat)),
                    dh,
                ));
            }
        }
        let seat_vecs: Vec<[f64; 2]> = seats
            .iter()
            .enumerate()
            .map(|(i, seat)| {
                add(
                    scaled(base.crank_radius, *seat),
                    errs.carrier_seats.get(i).copied().unwrap_or([0.0; 2]),
                )
            })
            .collect();
        let ecc_radius: Vec<f64> = (0..n)
            .map(|i| base.eccentricity + errs.crank_eccentricity.get(i).copied().unwrap_or(0.0))
            .collect();
        let ecc_phase: Vec<f64> = (0..n)
            .map(|i| errs.crank_phase.get(i).copied().unwrap_or(0.0))
            .collect();
        let bearing_friction = scene.friction.bearing.map(|bf| {
            // Pitch diameter from the rollers; 50 mm for a linear bearing (assumed).
            let pf = |b: Option<&Bearing>| {
                let dm = b
                    .and_then(|b| b.rollers.map(|r| r.pitch_diameter))
                    .unwrap_or(0.05);
                (
                    PalmgrenFriction {
                        f0: bf.f0,
                        f1: bf.f1,
                        pitch_diameter: dm,
                        viscosity: bf.viscosity,
                    },
                    scene.friction.regularisation_speed / (0.5 * dm),
                )
            };
            [pf(Some(&eccentric_bearing)), pf(crank_bearing.as_ref())]
        });
        let pressure = scene.stage1.as_ref().map_or([0.0, 1.0], |s| {
            let (s, c) = s.pressure_angle.sin_cos();
            [s, c]
        });
        let inr = &base.inertias;
        let e = base.eccentricity;
        let rp = scene.cycloid.pin_circle_radius;
        let crank_lever = base.mesh.map_or(e, |m| m.planet_base_radius.max(e));
        let zp = base.pins.len();
        let rigid_cranks = crank_bearing.is_none();
        let crank_orbit = if rigid_cranks {
            n as f64 * inr.crank.mass * base.crank_radius * base.crank_radius
        } else {
            0.0
        };
        // The load and motor inertias join the carrier and the sun unless a shaft separates
        // them (docs/model.md#machine-shafts).
        let on_carrier = if base.output_shaft.is_some() {
            0.0
        } else {
            inr.load_inertia
        };
        let on_sun = if base.input_shaft.is_some() {
            0.0
        } else {
            inr.motor_inertia
        };
        let bending = Bending::of(scene, nd, inr.crank.mass)?;
        // The eccentrics of bending cranks carry their own mass (their orbit on the carrier
        // with it): the crank keeps the rest.
        let crank_mass = inr.crank.mass - bending.as_ref().map_or(0.0, |b| nd as f64 * b.mass);
        let crank_orbit = crank_orbit * crank_mass / inr.crank.mass;
        let mut mass = vec![
            inr.carrier.inertia + on_carrier + crank_orbit,
            inr.sun.inertia + on_sun,
        ];
        let mut lever = vec![rp, base.mesh.map_or(0.0, |m| m.sun_base_radius)];
        for _ in 0..n {
            mass.extend([crank_mass, crank_mass, inr.crank.inertia]);
            lever.extend([1.0, 1.0, crank_lever]);
        }
        for _ in 0..nd {
            mass.extend([inr.disc.mass, inr.disc.mass, inr.disc.inertia]);
            lever.extend([1.0, 1.0, rp]);
        }
        if let Some(b) = &bending {
            // Each eccentric's centre, crank by crank (as the LTCA's deflections).
            for _ in 0..2 * n * nd {
                mass.push(b.mass);
                lever.push(1.0);
            }
        }
        let mut load_index = None;
        if base.output_shaft.is_some() {
            load_index = Some(mass.len());
            mass.push(inr.load_inertia);
            lever.push(rp);
        }
        let mut motor_index = None;
        if base.input_shaft.is_some() {
            motor_index = Some(mass.len());
            mass.push(inr.motor_inertia);
            lever.push(lever[SUN]);
        }
        let n_full = mass.len();
        let crank_rotations: Vec<usize> = (0..n).map(|i| crank_index(i) + 2).collect();
        let has_mesh = base.mesh.is_some();
        let input = match motor_index {
            Some(mi) => vec![mi],
            None if has_mesh => vec![SUN],
            None => crank_rotations.clone(),
        };
        let prescribed = match (base.drive.is_speed(), has_mesh, motor_index) {
            (true, _, Some(mi)) => vec![mi],
            (true, true, None) => vec![SUN],
            (true, false, None) => crank_rotations,
            (false, _, _) => Vec::new(),
        };
        let crank_centres: Vec<usize> = (0..n)
            .flat_map(|i| [crank_index(i), crank_index(i) + 1])
            .collect();
        let coords: Vec<usize> = (0..n_full)
            .filter(|i| !prescribed.contains(i) && (*i != SUN || has_mesh))
            .filter(|i| !(rigid_cranks && crank_centres.contains(i)))
            .collect();
        let free: Vec<usize> = coords
            .iter()
            .copied()
            .filter(|i| Some(*i) != load_index && Some(*i) != motor_index)
            .collect();
        let scale = coords.iter().map(|&i| lever[i]).collect();
        let base_skip = base.discs.iter().all(|d| d.profile_error.is_none());
        let (line_bases, ln_depths) = match &base.pin_law {
            PinLaw::Line { pin, disc, .. } => (
                base.discs
                    .iter()
                    .flat_map(|d| {
                        let width = d.geometry.params().face_width;
                        base.pins
                            .iter()
                            .map(move |p| PinDiscLawBase::new(p.radius, width, pin, disc))
                    })
                    .collect(),
                base.discs.iter().map(|d| d.body_depth.ln()).collect(),
            ),
            PinLaw::Impact(_) => (Vec::new(), Vec::new()),
        };
        Ok(Self {
            parts: base,
            eccentric_bearing: BearingLaw::new(&eccentric_bearing)?,
            crank_bearing: crank_bearing.as_ref().map(BearingLaw::new).transpose()?,
            cranks: n,
            seats,
            holes,
            pressure,
            mass,
            free,
            coords,
            prescribed,
            input,
            scale,
            warm_seeds: vec![Cell::new(WarmStart::default()); nd * zp],
            line_bases,
            ln_depths,
            // The separation bound assumes a rigid profile; a profile error's first-order
            // offset is not one: query every pin.
            skip_separated: base_skip,
            separation: vec![Cell::new(SeparationBound::default()); nd * zp],
            seat_vecs,
            ecc_radius,
            ecc_phase,
            bearing_friction,
            load_index,
            motor_index,
            bending,
        })
    }

    /// Index of the `x` of crank `i`'s eccentric for disc `k` (bending cranks; `y` follows)
    /// in the full vector: after the discs, as the LTCA's deflections.
    #[inline]
    pub fn node_index(&self, i: usize, k: usize) -> usize {
        let nd = self.parts.discs.len();
        2 + 3 * self.cranks + 3 * nd + 2 * (i * nd + k)
    }

    /// Number of full coordinates.
    pub fn full_len(&self) -> usize {
        self.mass.len()
    }

    /// Index of disc `k`'s first coordinate (`X_k`) in the full vector.
    #[inline]
    pub fn disc_index(&self, k: usize) -> usize {
        2 + 3 * self.cranks + 3 * k
    }

    /// Full kinematic state `(x, v)` at t = 0: kinematic pose, bearings undeflected, at rest
    /// or at kinematic speed (`Initial::Steady`); prescribed coordinates from the drive.
    ///
    /// Both have [`full_len`](Self::full_len) entries in the order of the module doc: `x`
    /// angles \[rad\] and positions \[m\], `v` their speeds [rad/s] and [m/s].
    pub fn full_initial_state(&self) -> (Vec<f64>, Vec<f64>) {
        let m = &self.parts;
        let n_full = self.full_len();
        let mut x = vec![0.0; n_full];
        let mut v = vec![0.0; n_full];
        let steady = m.initial == Initial::Steady;
        let w_in = m.drive.full_speed();
        let wc = if steady { w_in / m.ratio } else { 0.0 };
        let wa = -m.zc() * wc;
        v[CARRIER] = wc;
        if steady && m.mesh.is_some() {
            v[SUN] = w_in;
        }
        for i in 0..self.cranks {
            let ci = crank_index(i);
            let p = self.seat_vecs[i];
            let pv = scaled(wc, perp(p));
            x[ci..ci + 3].copy_from_slice(&[p[0], p[1], 0.0]);
            v[ci..ci + 3].copy_from_slice(&[pv[0], pv[1], wa]);
        }
        let nd = m.discs.len();
        for (k, d) in m.discs.iter().enumerate() {
            let dk = self.disc_index(k);
            // The disc centre that best fits its holes onto the eccentrics (least squares:
            // the mean of E_ik - h_ik); the kinematic centre without errors.
            let mut o = [0.0; 2];
            for i in 0..self.cranks {
                let (s, c) = (d.phase + self.ecc_phase[i]).sin_cos();
                let ecc = scaled(self.ecc_radius[i], [c, s]);
                let e_pos = add(self.seat_vecs[i], ecc);
                let h = rotate(d.angle_offset, self.holes[i * nd + k]);
                o = add(o, scaled(1.0 / self.cranks as f64, sub(e_pos, h)));
                if self.bending.is_some() {
                    // Straight cranks: each eccentric centre on its crank.
                    let ci = crank_index(i);
                    let e_v = add([v[ci], v[ci + 1]], scaled(wa, perp(ecc)));
                    let ni = self.node_index(i, k);
                    x[ni..ni + 2].copy_from_slice(&e_pos);
                    v[ni..ni + 2].copy_from_slice(&e_v);
                }
            }
            let ov = scaled(wa, perp(o));
            x[dk..dk + 3].copy_from_slice(&[o[0], o[1], d.angle_offset]);
            v[dk..dk + 3].copy_from_slice(&[ov[0], ov[1], wc]);
        }
        if let Some(li) = self.load_index {
            v[li] = v[CARRIER];
        }
        if let Some(mi) = self.motor_index {
            v[mi] = v[SUN];
        }
        self.apply_drive(0.0, &mut x, &mut v);
        (x, v)
    }

    /// With rigid crank bearings, put each crank centre in its seat (and moving with it).
    #[inline]
    fn place_rigid_cranks(&self, x: &mut [f64], v: &mut [f64]) {
        if self.crank_bearing.is_some() {
            return;
        }
        for i in 0..self.cranks {
            let ci = crank_index(i);
            let s = rotate(x[CARRIER], self.seat_vecs[i]);
            let sv = scaled(v[CARRIER], perp(s));
            x[ci..ci + 2].copy_from_slice(&s);
            v[ci..ci + 2].copy_from_slice(&sv);
        }
    }

    /// Overwrite the prescribed coordinates of a full state with the drive at `t`; returns
    /// the prescribed acceleration.
    #[inline]
    fn apply_drive(&self, t: f64, x: &mut [f64], v: &mut [f64]) -> f64 {
        if self.prescribed.is_empty() {
            return 0.0;
        }
        let (ang, spd, acc) = self.parts.drive.motion(t);
        for &p in &self.prescribed {
            x[p] = ang;
            v[p] = spd;
        }
        acc
    }

    /// Full coordinates from free ones at `t` \[s\]; returns `(x, v, prescribed acceleration)`.
    ///
    /// `q` [rad or m] and `v` [rad/s or m/s] are the free coordinates and velocities
    /// (`ReducerModel::initial_state` order). `x` and `v` returned have
    /// [`full_len`](Self::full_len) entries in the order of the module doc (angles \[rad\],
    /// positions \[m\] and their speeds); the prescribed (input) acceleration is in [rad/s^2].
    pub fn full(&self, t: f64, q: &[f64], v: &[f64]) -> (Vec<f64>, Vec<f64>, f64) {
        let n_full = self.full_len();
        let mut x = vec![0.0; n_full];
        let mut xv = vec![0.0; n_full];
        for (k, &i) in self.coords.iter().enumerate() {
            x[i] = q[k];
            xv[i] = v[k];
        }
        let acc = self.apply_drive(t, &mut x, &mut xv);
        self.place_rigid_cranks(&mut x, &mut xv);
        (x, xv, acc)
    }

    /// Deflection `d = p_i - s_i` of crank bearing `i` and `d = H_ik - E_ik` of eccentric
    /// bearing `(i, k)` (at `i * discs + k`) for the full coordinates `x` \[m\].
    pub fn bearing_deflections(&self, x: &[f64]) -> (Vec<[f64; 2]>, Vec<[f64; 2]>) {
        let m = &self.parts;
        let nd = m.discs.len();
        let mut crank = Vec::with_capacity(self.cranks);
        let mut ecc = Vec::with_capacity(self.cranks * nd);
        for i in 0..self.cranks {
            let ci = crank_index(i);
            let p = [x[ci], x[ci + 1]];
            crank.push(sub(p, rotate(x[CARRIER], self.seat_vecs[i])));
            for (k, d) in m.discs.iter().enumerate() {
                let dk = self.disc_index(k);
                let (s, c) = (x[ci + 2] + d.phase + self.ecc_phase[i]).sin_cos();
                let e_pos = add(p, [self.ecc_radius[i] * c, self.ecc_radius[i] * s]);
                let h = add(
                    [x[dk], x[dk + 1]],
                    rotate(x[dk + 2], self.holes[i * nd + k]),
                );
                ecc.push(sub(h, e_pos));
            }
        }
        (crank, ecc)
    }

    /// The shafts' loads at `(t, x, v)` (full coordinates) with the load and motor indices
    /// (the carrier's and the input's without shafts).
    pub(crate) fn shafts(
        &self,
        t: f64,
        x: &[f64],
        v: &[f64],
    ) -> (crate::dynamics::model::parts::ShaftLoads, usize, usize) {
        let li = self.load_index.unwrap_or(CARRIER);
        let mi = self.motor_index.unwrap_or(if self.parts.mesh.is_some() {
            SUN
        } else {
            crank_index(0) + 2
        });
        let sh = if self.load_index.is_some() || self.motor_index.is_some() {
            self.parts.shaft_loads(
                t,
                [x[CARRIER], v[CARRIER]],
                [x[SUN], v[SUN]],
                [x[li], v[li]],
                [x[mi], v[mi]],
            )
        } else {
            Default::default()
        };
        (sh, li, mi)
    }

    /// Kinetic energy of the free bodies \[J\] (a prescribed input is a driver, not counted).
    fn kinetic_energy(&self, v: &[f64]) -> f64 {
        self.coords
            .iter()
            .map(|&i| 0.5 * self.mass[i] * v[i] * v[i])
            .sum()
    }
}

/// Index of crank `i`'s first coordinate (`x_i`) in the full vector.
#[inline]
fn crank_index(i: usize) -> usize {
    2 + 3 * i
}

impl MechanicalSystem for CompliantModel {
    fn dof(&self) -> usize {
        self.coords.len()
    }

    fn energy(&self, t: f64, q: &[f64], v: &[f64]) -> Result<Option<f64>> {
        let o = self.observe(t, q, v, &mut EnergySink)?;
        Ok(Some(o.kinetic_energy + o.potential_energy))
    }

    fn eval(
        &self,
        t: f64,
        q: &[f64],
        v: &[f64],
        a: &mut [f64],
        power: &mut [f64; 3],
    ) -> Result<()> {
        let (x, xv, _) = self.full(t, q, v);
        let mut qf = vec![0.0; x.len()];
        let flows = self.forces(t, &x, &xv, &mut qf, &mut NoSink)?;
        for (k, &i) in self.coords.iter().enumerate() {
            a[k] = qf[i] / self.mass[i];
        }
        let m = &self.parts;
        power[0] = match m.drive.torque(t) {
            Some(tq) => {
                let share = tq / self.input.len() as f64;
                self.input.iter().map(|&i| share * xv[i]).sum()
            }
            None => -self.prescribed.iter().map(|&p| qf[p] * xv[p]).sum::<f64>(),
        };
        power[1] = m.load.torque(t) * xv[self.load_index.unwrap_or(CARRIER)];
        power[2] = flows.dissipation;
        Ok(())
    }

    fn length_scale(&self) -> &[f64] {
        &self.scale
    }

    fn mark_open_contacts(&self) {
        mark_open(&self.warm_seeds);
    }

    fn deepest_first_touch(&self) -> Option<(f64, String)> {
        let m = &self.parts;
        first_touch_report(&self.warm_seeds, &m.pin_law, m.pins.len())
    }
}

impl ReducerModel for CompliantModel {
    fn free_mass(&self) -> Vec<f64> {
        self.coords.iter().map(|&i| self.mass[i]).collect()
    }

    fn generalized_force(&self, t: f64, q: &[f64], v: &[f64], out: &mut [f64]) -> Result<()> {
        let n = self.coords.len();
        if q.len() != n || v.len() != n || out.len() != n {
            // An analysis built on the reducer's coordinates alone meets a scene with shafts.
            return Err(RvdynError::Scene(format!(
                "the compliant model of this scene has {n} free coordinates ({} with machine \
                 shafts: shafts.output / shafts.input), got {}: the analysis does not model the \
                 shafts yet; set them to null for it",
                n - self.free.len(),
                q.len()
            )));
        }
        let (x, xv, _) = self.full(t, q, v);
        let mut qf = vec![0.0; x.len()];
        self.forces(t, &x, &xv, &mut qf, &mut NoSink)?;
        for (k, &i) in self.coords.iter().enumerate() {
            out[k] = qf[i];
        }
        Ok(())
    }

    fn layout(&self) -> Layout {
        self.parts.layout()
    }

    fn initial_state(&self) -> (Vec<f64>, Vec<f64>) {
        let (x, v) = self.full_initial_state();
        (
            self.coords.iter().map(|&i| x[i]).collect(),
            self.coords.iter().map(|&i| v[i]).collect(),
        )
    }

    fn observe(
        &self,
        t: f64,
        q: &[f64],
        v: &[f64],
        sink: &mut dyn ContactSink,
    ) -> Result<Observation> {
        let m = &self.parts;
        let (x, xv, acc) = self.full(t, q, v);
        let mut qf = vec![0.0; x.len()];
        let flows = self.forces(t, &x, &xv, &mut qf, &mut DynSink(sink))?;
        let input_torque = match m.drive.torque(t) {
            Some(tq) => tq,
            None => self
                .prescribed
                .iter()
                .map(|&p| self.mass[p] * acc - qf[p])
                .sum(),
        };
        let rot = |i: usize| crank_index(i) + 2;
        let (sh, li, mi) = self.shafts(t, &x, &xv);
        Ok(Observation {
            load_angle: x[li],
            load_speed: xv[li],
            motor_angle: x[mi],
            motor_speed: xv[mi],
            output_shaft_torque: if m.output_shaft.is_some() {
                sh.output_torque
            } else {
                m.load.torque(t)
            },
            input_shaft_torque: if m.input_shaft.is_some() {
                sh.input_torque
            } else {
                input_torque
            },
            sun_angle: x[SUN],
            sun_speed: xv[SUN],
            carrier_angle: x[CARRIER],
            carrier_speed: xv[CARRIER],
            crank_angle: (0..self.cranks).map(|i| x[rot(i)]).collect(),
            crank_speed: (0..self.cranks).map(|i| xv[rot(i)]).collect(),
            disc_center: (0..m.discs.len())
                .map(|k| {
                    let dk = self.disc_index(k);
                    [x[dk], x[dk + 1]]
                })
                .collect(),
            disc_angle: (0..m.discs.len())
                .map(|k| x[self.disc_index(k) + 2])
                .collect(),
            input_torque,
            kinetic_energy: self.kinetic_energy(&xv),
            potential_energy: flows.potential,
            friction_power: flows.friction,
            // As `eval`.
            power: [
                match m.drive.torque(t) {
                    Some(tq) => {
                        let share = tq / self.input.len() as f64;
                        self.input.iter().map(|&i| share * xv[i]).sum()
                    }
                    None => -self.prescribed.iter().map(|&p| qf[p] * xv[p]).sum::<f64>(),
                },
                m.load.torque(t) * xv[self.load_index.unwrap_or(CARRIER)],
                flows.dissipation,
            ],
            // As `eval`.
            acceleration: self.coords.iter().map(|&i| qf[i] / self.mass[i]).collect(),
        })
    }
}

mod forces;
#[cfg(test)]
mod tests;
