//! Static generalised forces and their exact tangent stiffness for a reducer scene.
//!
//! Everything is evaluated in the full coordinates of the compliant-joint model
//! (`x = [th_c, th_s, (x_i, y_i, alpha_i) per crank, (X_k, Y_k, theta_k) per disc]`, see
//! `dynamics::model::compliant`), at zero velocity: `Q(x)` and `K(x) = -dQ/dx`. The
//! rigid-joint model and the compliant model with rigid crank bearings are maps `x = x(q)` from
//! fewer unknowns `q`; their forces and stiffness follow by the chain rule
//! `Q_q = J^T Q_x`, `K_q = J^T K_x J - sum_r Q_x,r hess(x_r)` (`J = dx/dq`).
//!
//! Every coupling is a scalar or vector deflection of the coordinates with its gradient and
//! Hessian, and a force law with its derivative:
//! - pin contact: the exact gap (`contact::pin_tangent`), `Q = F grad g`,
//!   `K = F' grad g grad g^T - F hess g`;
//! - sun/planet mesh `i` along its line of action: `delta_i = r_bs (th_s - th_c) +
//!   r_bp (alpha_i - th_c) - (p_i - s_i) . w_i`, backlash `b`: the flank `sigma = sign(delta)`
//!   is loaded when `sigma delta > b/2`, `Q = -sigma F grad delta`,
//!   `K = F' grad delta grad delta^T + sigma F hess delta`;
//! - bearings: a vector deflection `d(x)` with the radial law `F(|d| - c)` along `n = d/|d|`
//!   (potential `V(d)`, `dV/dd = F n`, `hess_d V = F' n n^T + F/|d| (I - n n^T)`, `= k I`
//!   without clearance), `Q = -J_d^T dV/dd`, `K = J_d^T hess V J_d + sum_a (dV/dd)_a hess d_a`.

mod dense;
mod eval;
mod full_forces;
mod laws;
mod state;
mod vec2;

use std::f64::consts::TAU;

use crate::contact::law::{MeshLaw, PinLaw};
use crate::contact::line_contact::PinDiscLawBase;
use crate::contact::pin_tangent::{GapJet, line_jet};
use crate::dynamics::model::laws::BearingLaw;
use crate::dynamics::model::rigid::RigidModel;
use crate::dynamics::scene::{Joints, Scene};
use crate::error::{Result, RvdynError};

pub use dense::Dense;
pub use eval::Work;
pub use laws::{contact_damping, elastic};
pub use state::ContactState;
use vec2::{cos_sin, rotate};

/// Index of the carrier angle in the full coordinates.
pub const CARRIER: usize = 0;
/// Index of the sun angle in the full coordinates.
pub const SUN: usize = 1;

/// A family of couplings (for strain-energy shares of modes).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Family {
    /// The pin contacts of disc `k`.
    Pins(usize),
    /// The sun/planet meshes.
    Mesh,
    /// The crank (main) bearings between the cranks and the carrier.
    CrankBearings,
    /// The eccentric (needle) bearings between the cranks and the discs.
    EccentricBearings,
    /// The crankshafts' bending between their bearings (`crank_shaft`).
    CrankBending,
}

/// How the unknowns map to the full coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Rigid joints: unknowns `[th_c, alpha]` with the sun held (first stage), or `[th_c]`
    /// with the cranks held (no first stage).
    Rigid,
    /// Compliant joints: every full coordinate except the held input; crank centres are
    /// unknowns only with compliant crank bearings.
    Compliant,
}

/// The static reducer: geometry, laws and the map from unknowns to full coordinates.
#[derive(Debug, Clone)]
pub struct Statics {
    /// The rigid model of the scene (geometry, laws; its parts).
    pub model: RigidModel,
    /// Rigid or compliant joints.
    pub kind: Kind,
    /// Law of the eccentric bearings (compliant joints).
    pub eccentric_bearing: Option<BearingLaw>,
    /// Law of the crank bearings (`None`: rigid).
    pub crank_bearing: Option<BearingLaw>,
    /// Bending stiffness of each crankshaft at the discs' planes, row-major `discs x discs`
    /// \[N/m\] (`crank_shaft`; `None`: rigid cranks). With it, each eccentric's deflection
    /// from its crank's line is a full coordinate ([`Statics::node_index`]).
    pub bending: Option<Vec<f64>>,
    /// Number of cranks.
    pub cranks: usize,
    /// The pin law (IMPACT, Palmgren or line contact).
    pub pin_law: PinLaw,
    /// The mesh law (IMPACT or ISO 6336; `None` without a first stage).
    pub mesh_law: Option<MeshLaw>,
    /// `ln F` of each (disc, pin)'s last line-law force (warm start of its inversion).
    ln_warm: Vec<f64>,
    /// The contact-independent part of each (disc, pin)'s line law (empty for IMPACT).
    line_bases: Vec<PinDiscLawBase>,
    /// `ln` of each disc's body depth.
    ln_body_depth: Vec<f64>,
    seats: Vec<[f64; 2]>,
    /// Actual crank seat of each crank in the carrier frame (with its position error) \[m\]:
    /// the crank bearing's; the mesh keeps the nominal seat.
    seat_vecs: Vec<[f64; 2]>,
    /// Eccentricity of each crank (with its error) \[m\].
    ecc_radius: Vec<f64>,
    /// Eccentric phase error of each crank \[rad\].
    ecc_phase: Vec<f64>,
    holes: Vec<[f64; 2]>,
    /// `(sin, cos)` of the pressure angle.
    pressure: [f64; 2],
    /// Full coordinates that are unknowns (compliant), in order.
    pub unknowns: Vec<usize>,
    /// Length per unknown [m per unit] (rp for angles, 1 for translations).
    pub scale: Vec<f64>,
    /// Foot parameter offset from the kinematic one per (disc, pin): the gap warm start.
    warm: Vec<f64>,
    /// Largest contact penetration of the last evaluation \[m\].
    pub max_penetration: f64,
    /// Number of evaluations so far (for benchmarks and reports).
    pub evaluations: usize,
    /// Skip the exact gap of pins that provably cannot touch (same forces, tested).
    pub skip: bool,
    /// Evaluate every pin exactly this time (fresh gaps for reports).
    pub exact: bool,
    /// Pin queries skipped so far.
    pub skipped: usize,
    /// Evaluate only this family of couplings (and no load) when set.
    pub family: Option<Family>,
    /// When set, [`Statics::full_forces`] also fills this damping matrix `C = -dQ/dv` in the
    /// full coordinates (at zero velocity).
    pub damping: Option<Dense>,
    /// Per (disc, pin): disc centre, angle and gap at the last exact query.
    separation: Vec<([f64; 2], f64, f64)>,
    last_jets: Vec<GapJet>,
    /// `(cos, sin)` of each pin's nominal angle.
    pin_dirs: Vec<[f64; 2]>,
    /// `(cos, sin)` of each disc's angle at the current evaluation (the pins' and the
    /// eccentric bearings' one `sin_cos` per disc).
    disc_cs: Vec<[f64; 2]>,
    /// Largest distance of a profile point from its disc centre \[m\].
    reach: f64,
    /// Bound of each disc's profile error `|delta| <= bound` \[m\] (0 without one): the
    /// separation skip keeps `gap - bound` (the error-free gap less the bound is below the gap
    /// with the error, whatever the foot).
    error_bound: Vec<f64>,
}

impl Statics {
    /// Build from a scene (validated by the model).
    pub fn new(scene: &Scene) -> Result<Self> {
        if scene.errors.any() && matches!(scene.joints, Joints::Rigid) {
            return Err(RvdynError::Scene(
                "assembly errors (errors: crank eccentricity and phase, disc holes, carrier \
                 seats) need compliant joints (as in the dynamic models): set joints to \
                 compliant or remove them"
                    .into(),
            ));
        }
        let model = RigidModel::new(&scene.rigid_counterpart())?;
        let (kind, eccentric_bearing, crank_bearing) = match scene.joints {
            Joints::Rigid => (Kind::Rigid, None, None),
            Joints::Compliant {
                eccentric_bearing,
                crank_bearing,
            } => (
                Kind::Compliant,
                Some(BearingLaw::new(&eccentric_bearing)?),
                crank_bearing.as_ref().map(BearingLaw::new).transpose()?,
            ),
        };
        // Every law of the models has an analytic static tangent: IMPACT/Palmgren, the line
        // contact with its location term, the ISO 6336 mesh stiffness wave.
        let pin_law = model.pin_law;
        let mesh_law = model.mesh.as_ref().map(|m| m.law);
        let n = model.cranks;
        let nd = model.discs.len();
        let seats: Vec<[f64; 2]> = (0..n).map(|i| cos_sin(TAU * i as f64 / n as f64)).collect();
        let mut holes = Vec::with_capacity(n * nd);
        // Assembly errors (compliant joints), as the compliant model: disc hole and carrier
        // seat position errors, and each crank's eccentricity and phase errors.
        let errs = &scene.errors;
        for (i, seat) in seats.iter().enumerate() {
            for (k, d) in model.discs.iter().enumerate() {
                let r = [model.crank_radius * seat[0], model.crank_radius * seat[1]];
                let h = rotate(cos_sin(-d.angle_offset), r);
                let dh = errs.disc_holes.get(i * nd + k).copied().unwrap_or([0.0; 2]);
                holes.push([h[0] + dh[0], h[1] + dh[1]]);
            }
        }
        let seat_vecs: Vec<[f64; 2]> = seats
            .iter()
            .enumerate()
            .map(|(i, u)| {
                let ds = errs.carrier_seats.get(i).copied().unwrap_or([0.0; 2]);
                [
                    model.crank_radius * u[0] + ds[0],
                    model.crank_radius * u[1] + ds[1],
                ]
            })
            .collect();
        let ecc_radius: Vec<f64> = (0..n)
            .map(|i| model.eccentricity + errs.crank_eccentricity.get(i).copied().unwrap_or(0.0))
            .collect();
        let ecc_phase: Vec<f64> = (0..n)
            .map(|i| errs.crank_phase.get(i).copied().unwrap_or(0.0))
            .collect();
        let pressure = scene.stage1.as_ref().map_or([0.0, 1.0], |s| {
            let (s, c) = s.pressure_angle.sin_cos();
            [s, c]
        });
        let has_mesh = model.mesh.is_some();
        let rp = scene.cycloid.pin_circle_radius;
        let bending = match (&scene.crank_shaft, &scene.crank_layout, kind) {
            (Some(shaft), Some(layout), Kind::Compliant) => Some(
                shaft
                    .stiffness(layout)
                    .map_err(|e| RvdynError::Scene(format!("crank_shaft: {e}")))?,
            ),
            (Some(_), _, _) => {
                return Err(RvdynError::Scene(
                    "crank_shaft needs crank_layout and compliant joints".into(),
                ));
            }
            _ => None,
        };
        let (unknowns, scale) = match kind {
            Kind::Rigid => {
                if has_mesh {
                    (vec![], vec![rp, model.eccentricity])
                } else {
                    (vec![], vec![rp])
                }
            }
            Kind::Compliant => {
                let mut u = vec![CARRIER];
                let mut s = vec![rp];
                for i in 0..n {
                    let ci = 2 + 3 * i;
                    if crank_bearing.is_some() {
                        u.extend([ci, ci + 1]);
                        s.extend([1.0, 1.0]);
                    }
                    if has_mesh {
                        u.push(ci + 2);
                        s.push(model.eccentricity);
                    }
                }
                for k in 0..nd {
                    let dk = 2 + 3 * n + 3 * k;
                    u.extend([dk, dk + 1, dk + 2]);
                    s.extend([1.0, 1.0, rp]);
                }
                if bending.is_some() {
                    // Each eccentric's bending deflection (x, y) per crank and disc.
                    let first = 2 + 3 * n + 3 * nd;
                    u.extend(first..first + 2 * n * nd);
                    s.extend(std::iter::repeat_n(1.0, 2 * n * nd));
                }
                (u, s)
            }
        };
        let zp = model.pins.len();
        // Materials, pin radii, face widths and depths were checked with the scene.
        let line_bases = match &pin_law {
            PinLaw::Line { pin, disc, .. } => model
                .discs
                .iter()
                .flat_map(|d| {
                    let w = d.geometry.params().face_width;
                    model
                        .pins
                        .iter()
                        .map(move |p| PinDiscLawBase::new(p.radius, w, pin, disc))
                })
                .collect(),
            PinLaw::Impact(_) => Vec::new(),
        };
        let ln_body_depth = model.discs.iter().map(|d| d.body_depth.ln()).collect();
        Ok(Self {
            line_bases,
            ln_body_depth,
            kind,
            eccentric_bearing,
            crank_bearing,
            bending,
            cranks: n,
            pin_law,
            mesh_law,
            seats,
            seat_vecs,
            ecc_radius,
            ecc_phase,
            holes,
            pressure,
            unknowns,
            scale,
            warm: vec![0.0; nd * zp],
            ln_warm: vec![f64::NAN; nd * zp],
            max_penetration: 0.0,
            evaluations: 0,
            skip: true,
            exact: false,
            skipped: 0,
            family: None,
            damping: None,
            separation: vec![([0.0; 2], 0.0, f64::NEG_INFINITY); nd * zp],
            last_jets: vec![GapJet::default(); nd * zp],
            pin_dirs: model.pins.iter().map(|p| cos_sin(p.angle)).collect(),
            disc_cs: vec![[1.0, 0.0]; nd],
            reach: (0..nd)
                .map(|k| {
                    let p = scene.disc_params(k);
                    p.pin_circle_radius + p.d_rp + p.eccentricity - p.pin_radius - p.d_rrp
                })
                .fold(0.0, f64::max)
                * 1.000_001,
            error_bound: model
                .discs
                .iter()
                .map(|d| {
                    d.profile_error.as_ref().map_or(0.0, |p| {
                        p.harmonics.iter().map(|h| h[0].abs()).sum::<f64>()
                            + p.table.iter().map(|t| t[1].abs()).fold(0.0, f64::max)
                    })
                })
                .collect(),
            model,
        })
    }

    /// Secant stiffness `F(pen) / pen` [N/m] of the pin law at the approach `pen` \[m\] (the
    /// stiffest place along a lobe of disc 0 for the line law): a reference stiffness for the
    /// solver's scaling.
    pub fn pin_secant_stiffness(&self, pen: f64) -> f64 {
        match &self.pin_law {
            PinLaw::Impact(l) => elastic(l, pen).0 / pen,
            PinLaw::Line { pin, disc, .. } => {
                let d = &self.model.discs[0];
                let pr = self.model.pins[0].radius;
                let lobe = TAU / self.zc();
                (0..16)
                    .filter_map(|i| {
                        let phi = lobe * (i as f64 + 0.5) / 16.0;
                        line_jet(&d.geometry, phi, pen, pr, d.body_depth, pin, disc, f64::NAN)
                            .ok()
                            .map(|j| j.force / pen)
                    })
                    .fold(0.0, f64::max)
            }
        }
    }

    /// The families of couplings of this scene, named as in reports: the pin contacts of each
    /// disc, the sun/planet meshes (with a first stage), the eccentric bearings (compliant
    /// joints), the crank bearings (when compliant) and the crank bending (`crank_shaft`).
    /// Their stiffness parts sum to the whole tangent.
    pub fn families(&self) -> Vec<(String, Family)> {
        let mut families: Vec<(String, Family)> = (0..self.model.discs.len())
            .map(|d| (format!("pin contacts disc {d}"), Family::Pins(d)))
            .collect();
        if self.model.mesh.is_some() {
            families.push(("sun/planet meshes".into(), Family::Mesh));
        }
        if self.kind == Kind::Compliant {
            families.push(("eccentric bearings".into(), Family::EccentricBearings));
            if self.crank_bearing.is_some() {
                families.push(("crank bearings".into(), Family::CrankBearings));
            }
            if self.bending.is_some() {
                families.push(("crank bending".into(), Family::CrankBending));
            }
        }
        families
    }

    /// Number of unknowns.
    pub fn dim(&self) -> usize {
        self.scale.len()
    }

    /// Number of full coordinates.
    pub fn full_len(&self) -> usize {
        let nd = self.model.discs.len();
        let nodes = if self.bending.is_some() {
            2 * self.cranks * nd
        } else {
            0
        };
        2 + 3 * self.cranks + 3 * nd + nodes
    }

    /// Index of the `x` deflection of crank `i`'s eccentric for disc `k` from the crank's line
    /// (bending; `y` follows) in the full coordinates. Only with [`Statics::bending`].
    #[inline]
    pub fn node_index(&self, i: usize, k: usize) -> usize {
        let nd = self.model.discs.len();
        2 + 3 * self.cranks + 3 * nd + 2 * (i * nd + k)
    }

    /// Index of disc `k`'s `X` in the full coordinates.
    #[inline]
    pub fn disc_index(&self, k: usize) -> usize {
        2 + 3 * self.cranks + 3 * k
    }

    /// Index of crank `i`'s `x` in the full coordinates.
    #[inline]
    pub fn crank_index(&self, i: usize) -> usize {
        2 + 3 * i
    }

    /// Number of lobes.
    pub fn zc(&self) -> f64 {
        self.model.zc()
    }

    /// The held input angle (sun, or crank without a first stage) for the kinematic pose at
    /// crank angle `psi` \[rad\]: `th_c = -psi / zc`, mesh deflection zero.
    pub fn held_input(&self, psi: f64) -> f64 {
        let thc = -psi / self.zc();
        match &self.model.mesh {
            Some(m) => thc - m.planet_base_radius / m.sun_base_radius * (psi - thc),
            None => psi,
        }
    }

    /// The full kinematic pose at crank angle `psi` \[rad\] (bearings undeflected, no mesh
    /// deflection): [`full_len`](Self::full_len) coordinates in the module doc's order, angles
    /// \[rad\] and positions \[m\].
    pub fn kinematic_full(&self, psi: f64) -> Vec<f64> {
        let m = &self.model;
        let mut x = vec![0.0; self.full_len()];
        let thc = -psi / self.zc();
        x[CARRIER] = thc;
        x[SUN] = if m.mesh.is_some() {
            self.held_input(psi)
        } else {
            0.0
        };
        let u0 = cos_sin(thc);
        for i in 0..self.cranks {
            let ci = self.crank_index(i);
            let s = rotate(u0, self.seat_vecs[i]);
            x[ci] = s[0];
            x[ci + 1] = s[1];
            x[ci + 2] = psi;
        }
        for (k, d) in m.discs.iter().enumerate() {
            let dk = self.disc_index(k);
            let o = cos_sin(psi + d.phase);
            x[dk] = m.eccentricity * o[0];
            x[dk + 1] = m.eccentricity * o[1];
            x[dk + 2] = thc + d.angle_offset;
        }
        x
    }

    /// The unknowns of the kinematic pose at crank angle `psi` \[rad\]: [`dim`](Self::dim)
    /// values, `[th_c, alpha]` (or `[th_c]` without a first stage) \[rad\] for rigid joints,
    /// the full coordinates listed in [`unknowns`](Self::unknowns) (angles \[rad\], positions
    /// \[m\]) for compliant ones.
    pub fn kinematic_unknowns(&self, psi: f64) -> Vec<f64> {
        match self.kind {
            Kind::Rigid => {
                let thc = -psi / self.zc();
                if self.model.mesh.is_some() {
                    vec![thc, psi]
                } else {
                    vec![thc]
                }
            }
            Kind::Compliant => {
                let x = self.kinematic_full(psi);
                self.unknowns.iter().map(|&i| x[i]).collect()
            }
        }
    }

    /// Full coordinates (angles \[rad\], positions \[m\]; [`full_len`](Self::full_len) values)
    /// from the unknowns `q` ([`dim`](Self::dim) values, laid out as in
    /// [`kinematic_unknowns`](Self::kinematic_unknowns)) with the input held at crank angle
    /// `psi` \[rad\].
    pub fn full(&self, psi: f64, q: &[f64]) -> Vec<f64> {
        let mut x = Vec::new();
        self.full_into(psi, q, &mut x);
        x
    }

    /// [`Statics::full`] into `x` (resized; no allocation once sized): the coordinates the
    /// unknowns do not set are the kinematic pose's (the held input, and the crank rotations
    /// without a first stage), the rest come from `q` as in [`Statics::full`].
    pub fn full_into(&self, psi: f64, q: &[f64], x: &mut Vec<f64>) {
        let m = &self.model;
        x.clear();
        x.resize(self.full_len(), 0.0);
        x[SUN] = if m.mesh.is_some() {
            self.held_input(psi)
        } else {
            0.0
        };
        match self.kind {
            Kind::Rigid => {
                let thc = q[0];
                let alpha = if m.mesh.is_some() { q[1] } else { psi };
                x[CARRIER] = thc;
                let u0 = cos_sin(thc);
                for i in 0..self.cranks {
                    let ci = self.crank_index(i);
                    let s = rotate(u0, self.seats[i]);
                    x[ci] = m.crank_radius * s[0];
                    x[ci + 1] = m.crank_radius * s[1];
                    x[ci + 2] = alpha;
                }
                for (k, d) in m.discs.iter().enumerate() {
                    let dk = self.disc_index(k);
                    let o = cos_sin(alpha + d.phase);
                    x[dk] = m.eccentricity * o[0];
                    x[dk + 1] = m.eccentricity * o[1];
                    x[dk + 2] = thc + d.angle_offset;
                }
            }
            Kind::Compliant => {
                // Crank rotations held at the crank angle unless they are unknowns (first
                // stage); carrier, disc and (compliant) crank centre coordinates are unknowns.
                for i in 0..self.cranks {
                    x[self.crank_index(i) + 2] = psi;
                }
                for (a, &i) in self.unknowns.iter().enumerate() {
                    x[i] = q[a];
                }
                if self.crank_bearing.is_none() {
                    let u0 = cos_sin(x[CARRIER]);
                    for i in 0..self.cranks {
                        let ci = self.crank_index(i);
                        let s = rotate(u0, self.seat_vecs[i]);
                        x[ci] = s[0];
                        x[ci + 1] = s[1];
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests;
