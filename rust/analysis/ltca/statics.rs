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

use std::f64::consts::TAU;

use super::gear_errors::FlankError;
use crate::contact::ImpactLaw;
use crate::contact::law::{MeshLaw, PinLaw};
use crate::contact::line_contact::PinDiscLawBase;
use crate::contact::pin_tangent::{
    GapJet, centre_curve_derivatives_cs, foot_jet_with, gap_jet_cs, line_jet, line_jet_checked,
};
use crate::dynamics::model::laws::BearingLaw;
use crate::dynamics::model::rigid::RigidModel;
use crate::dynamics::scene::{Joints, ProfileError, Scene};
use crate::error::{Result, RvdynError};
use crate::geometry::gap::small_sin_cos;

/// Index of the carrier angle in the full coordinates.
pub const CARRIER: usize = 0;
/// Index of the sun angle in the full coordinates.
pub const SUN: usize = 1;

#[inline]
fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}
#[inline]
fn perp(a: [f64; 2]) -> [f64; 2] {
    [-a[1], a[0]]
}
#[inline]
fn rotate(cs: [f64; 2], a: [f64; 2]) -> [f64; 2] {
    [cs[0] * a[0] - cs[1] * a[1], cs[1] * a[0] + cs[0] * a[1]]
}
#[inline]
fn cos_sin(a: f64) -> [f64; 2] {
    let (s, c) = a.sin_cos();
    [c, s]
}

/// A dense symmetric-by-construction matrix of size `n` (row-major).
#[derive(Debug, Clone, Default)]
pub struct Dense {
    /// Size.
    pub n: usize,
    /// Entries, row-major.
    pub a: Vec<f64>,
}

impl Dense {
    /// The zero matrix of size `n`.
    pub fn zeros(n: usize) -> Self {
        Self {
            n,
            a: vec![0.0; n * n],
        }
    }
    /// Entry `(i, j)`.
    #[inline]
    pub fn at(&self, i: usize, j: usize) -> f64 {
        self.a[i * self.n + j]
    }
    /// Add `v` to entry `(i, j)`.
    #[inline]
    pub fn add(&mut self, i: usize, j: usize, v: f64) {
        self.a[i * self.n + j] += v;
    }
    /// Set every entry to `v`.
    pub fn fill(&mut self, v: f64) {
        self.a.fill(v);
    }
    /// Add `w u u^T` on the index set `idx` (`u` given on `idx`).
    #[inline]
    fn outer(&mut self, idx: &[usize], u: &[f64], w: f64) {
        for (a, &i) in idx.iter().enumerate() {
            let wa = w * u[a];
            for (b, &j) in idx.iter().enumerate() {
                self.a[i * self.n + j] += wa * u[b];
            }
        }
    }
    /// Add `w (u v^T + v u^T)` on the index set `idx` (`u`, `v` given on `idx`).
    #[inline]
    fn outer_sym(&mut self, idx: &[usize], u: &[f64], v: &[f64], w: f64) {
        for (a, &i) in idx.iter().enumerate() {
            for (b, &j) in idx.iter().enumerate() {
                self.a[i * self.n + j] += w * (u[a] * v[b] + v[a] * u[b]);
            }
        }
    }
    /// Replace each entry `v` of the 3x3 block at rows and columns `i0..i0 + 3` by
    /// `upd(a, b, v)` (`a`, `b` in `0..3`).
    #[inline]
    fn update_block3(&mut self, i0: usize, upd: impl Fn(usize, usize, f64) -> f64) {
        let n = self.n;
        for a in 0..3 {
            let start = (i0 + a) * n + i0;
            for (b, v) in self.a[start..start + 3].iter_mut().enumerate() {
                *v = upd(a, b, *v);
            }
        }
    }
    /// Add `v` to the symmetric pair `(i, j)`, `(j, i)` (once on the diagonal).
    #[inline]
    fn sym(&mut self, i: usize, j: usize, v: f64) {
        self.add(i, j, v);
        if i != j {
            self.add(j, i, v);
        }
    }
}

/// What one evaluation found at every contact (fixed frame, SI).
#[derive(Debug, Clone, Default)]
pub struct ContactState {
    /// Pin force \[N\] (>= 0) per disc and pin, at `k * pins + j`.
    pub pin_force: Vec<f64>,
    /// Signed gap \[m\] per disc and pin (negative = penetration).
    pub pin_gap: Vec<f64>,
    /// The gap jets (contact point, normal, curvature) per disc and pin.
    pub pin_jet: Vec<GapJet>,
    /// Moment about the reducer axis of the line law's location term on each disc, per disc
    /// and pin [N m] (0 for IMPACT): `O x Q_O + Q_theta` of `Q = -U_phi grad phi`, plus the
    /// same moment of a profile error's share `-F delta' grad phi`.
    pub pin_location_moment: Vec<f64>,
    /// Sum over the bearings of the couple `d x F` of each bearing's force pair [N m]: zero
    /// for an isotropic law (force along the deflection); the roller laws, with their roller
    /// sets fixed in the frame, push slightly off the deflection.
    pub bearing_couple: f64,
    /// Signed mesh force along the line of action per crank \[N\] (positive: drive flank).
    pub mesh_force: Vec<f64>,
    /// Mesh deflection along the line of action per crank \[m\].
    pub mesh_deflection: Vec<f64>,
    /// Crank bearing force on each crank centre \[N\] (compliant crank bearings).
    pub crank_bearing_force: Vec<[f64; 2]>,
    /// Eccentric bearing force on each disc at `i * discs + k` \[N\].
    pub eccentric_bearing_force: Vec<[f64; 2]>,
}

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

    /// Number of unknowns.
    pub fn dim(&self) -> usize {
        self.scale.len()
    }

    /// Number of full coordinates.
    pub fn full_len(&self) -> usize {
        2 + 3 * self.cranks + 3 * self.model.discs.len()
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

    /// Static generalised forces `qf` and tangent stiffness `kf = -dQ/dx` in the full
    /// coordinates at `x` (zero velocity), for the output torque `torque` [N m] on the
    /// carrier (acting against positive rotation, as the scene's load). `state`, if given,
    /// receives every contact force.
    ///
    /// Errors: `Convergence` if an exact gap cannot be found (the disc is far from any
    /// sensible pose).
    pub fn full_forces(
        &mut self,
        x: &[f64],
        torque: f64,
        qf: &mut [f64],
        kf: &mut Dense,
        mut state: Option<&mut ContactState>,
    ) -> Result<()> {
        qf.fill(0.0);
        kf.fill(0.0);
        self.max_penetration = 0.0;
        self.evaluations += 1;
        let fam = self.family;
        let on = |f: Family| fam.is_none_or(|x| x == f);
        let mut cf = self.damping.take();
        if let Some(c) = cf.as_mut() {
            if c.n != x.len() {
                *c = Dense::zeros(x.len());
            }
            c.fill(0.0);
        }
        let m = &self.model;
        let nd = m.discs.len();
        let zp = m.pins.len();
        if let Some(s) = state.as_deref_mut() {
            s.pin_force.resize(nd * zp, 0.0);
            s.pin_gap.resize(nd * zp, 0.0);
            s.pin_location_moment.clear();
            s.bearing_couple = 0.0;
            s.pin_location_moment.resize(nd * zp, 0.0);
            s.pin_jet.clear();
            s.mesh_force.clear();
            s.mesh_deflection.clear();
            s.crank_bearing_force.clear();
            s.eccentric_bearing_force.clear();
            // Their final sizes at once (a state handed to a report starts empty).
            let nc = self.cranks;
            s.pin_jet.reserve(nd * zp);
            s.mesh_force.reserve(nc);
            s.mesh_deflection.reserve(nc);
            s.crank_bearing_force.reserve(nc);
            s.eccentric_bearing_force.reserve(nc * nd);
        }
        for (k, d) in m.discs.iter().enumerate() {
            let dk = self.disc_index(k);
            let o = [x[dk], x[dk + 1]];
            let th = x[dk + 2];
            let cs = cos_sin(th);
            self.disc_cs[k] = cs;
            // (cos, sin) of -(theta + d_delta), to turn each pin's angle into its kinematic
            // foot parameter without a sin_cos per pin.
            let back = cos_sin(-th - d.geometry.params().d_delta);
            let idx = [dk, dk + 1, dk + 2];
            for (j, pin) in m.pins.iter().enumerate() {
                let slot = k * zp + j;
                // Skip a pin that provably cannot touch: moving the disc by dO and turning it
                // by dth moves every profile point by at most |dO| + reach |dth|, and its gap
                // by no more (the dynamic model's separation bound).
                // `gap - reach |dth| > |dO|`, compared squared (no hypot per pin).
                if self.skip && !self.exact {
                    let b = &self.separation[slot];
                    let slack = b.2 - self.reach * (th - b.1).abs();
                    let (dx, dy) = (o[0] - b.0[0], o[1] - b.0[1]);
                    if slack > 0.0 && dx * dx + dy * dy < slack * slack {
                        self.skipped += 1;
                        if let Some(s) = state.as_deref_mut() {
                            s.pin_force[slot] = 0.0;
                            s.pin_gap[slot] = self.last_jets[slot].gap;
                            s.pin_jet.push(self.last_jets[slot]);
                        }
                        continue;
                    }
                }
                // The same pose as this pin's last exact query: the same jet.
                let same = self.skip && {
                    let b = &self.separation[slot];
                    b.0 == o && b.1 == th && b.2.is_finite()
                };
                // `jet` is the error-free gap (the one kept for reuse); the disc's profile
                // error enters below.
                let jet = if same {
                    self.last_jets[slot]
                } else {
                    let kin = pin.angle - th - d.geometry.params().d_delta;
                    let w = &mut self.warm[slot];
                    let seed = kin + *w;
                    let kcs = rotate(back, self.pin_dirs[j]);
                    let (ds, dc) = small_sin_cos(*w);
                    let scs = [kcs[0] * dc - kcs[1] * ds, kcs[1] * dc + kcs[0] * ds];
                    let jet =
                        gap_jet_cs(&d.geometry, pin.centre, pin.radius, o, cs, seed, Some(scs))
                            .ok_or_else(|| {
                                RvdynError::Convergence(format!(
                                    "exact gap of pin {} on disc {k} not found: the disc is \
                                     farther from its kinematic pose than the profile's radius \
                                     of curvature (the contacts cannot carry this torque)",
                                    j + 1
                                ))
                            })?;
                    let off = jet.phi - kin;
                    *w = if off.abs() < 0.01 { off } else { 0.0 };
                    if self.skip {
                        self.separation[slot] = (o, th, jet.gap - self.error_bound[k]);
                        self.last_jets[slot] = jet;
                    }
                    jet
                };
                // Profile error: gap' = gap - delta(phi(q)) (the dynamic models' first-order
                // offset at the foot), grad' = grad - delta' grad phi,
                // hess' = hess - delta'' grad phi grad phi^T - delta' hess phi.
                let (jet, err) = match &d.profile_error {
                    Some(pe) => {
                        let cd = centre_curve_derivatives_cs(&d.geometry, jet.phi_cos_sin);
                        let fj = foot_jet_with(&d.geometry, pin.centre, o, cs, &cd)
                            .ok_or_else(|| no_foot(k, j))?;
                        let (delta, d1, d2) = profile_offset_jet(pe, jet.phi);
                        let mut e = jet;
                        e.gap -= delta;
                        for a in 0..3 {
                            e.grad[a] -= d1 * fj.grad[a];
                            for b in 0..3 {
                                e.hess[a][b] -= d2 * fj.grad[a] * fj.grad[b] + d1 * fj.hess[a][b];
                            }
                        }
                        (e, Some((cd, fj, d1)))
                    }
                    None => (jet, None),
                };
                let pen = -jet.gap;
                self.max_penetration = self.max_penetration.max(pen);
                let mut f = 0.0;
                let mut fp = 0.0;
                if on(Family::Pins(k)) && pen > 0.0 {
                    match &self.pin_law {
                        PinLaw::Impact(l) => {
                            (f, fp) = elastic(l, pen);
                            if let Some(c) = cf.as_mut() {
                                c.outer(&idx, &jet.grad, contact_damping(l, pen));
                            }
                        }
                        PinLaw::Line { damping, .. } => {
                            // Line contact: the force depends on the approach and on where
                            // the pin touches (K0(phi)); V = U(pen, phi(x)),
                            // Q = F grad g - U_phi grad phi,
                            // K = k_t gg^T - U_dphi (g phi^T + phi g^T) + U_phiphi phi phi^T
                            //     - F hess g + U_phi hess phi (docs/model.md).
                            // The curve's derivatives at the contact, once for both jets.
                            let cd = match &err {
                                Some((cd, ..)) => *cd,
                                None => centre_curve_derivatives_cs(&d.geometry, jet.phi_cos_sin),
                            };
                            // Materials, pin radius and depth were checked with the scene.
                            let lj = line_jet_checked(
                                &d.geometry,
                                &cd,
                                pen,
                                &self.line_bases[slot],
                                d.body_depth,
                                self.ln_body_depth[k],
                                self.ln_warm[slot],
                            )?;
                            self.ln_warm[slot] = lj.ln_force;
                            let fj = match &err {
                                Some((_, fj, _)) => *fj,
                                None => foot_jet_with(&d.geometry, pin.centre, o, cs, &cd)
                                    .ok_or_else(|| no_foot(k, j))?,
                            };
                            f = lj.force;
                            let u_phi = lj.energy_per_phi();
                            for a in 0..3 {
                                qf[idx[a]] += f * jet.grad[a] - u_phi * fj.grad[a];
                            }
                            if let Some(s) = state.as_deref_mut() {
                                let q = [-u_phi * fj.grad[0], -u_phi * fj.grad[1]];
                                s.pin_location_moment[slot] =
                                    o[0] * q[1] - o[1] * q[0] - u_phi * fj.grad[2];
                            }
                            // The disc's 3x3 block, each entry updated by the terms in the
                            // order of `outer`, `outer_sym`, `outer`, `add` (the same
                            // arithmetic, one pass).
                            let (g, p) = (&jet.grad, &fj.grad);
                            let (wk, wc, wp) = (lj.stiffness, -lj.cross(), lj.phi_phi());
                            kf.update_block3(dk, |a, b, mut v| {
                                v += (wk * g[a]) * g[b];
                                v += wc * (g[a] * p[b] + p[a] * g[b]);
                                v += (wp * p[a]) * p[b];
                                v + (-f * jet.hess[a][b] + u_phi * fj.hess[a][b])
                            });
                            if let Some(c) = cf.as_mut() {
                                c.outer(&idx, &jet.grad, damping.rate_coefficient(f, lj.stiffness));
                            }
                        }
                    }
                }
                if matches!(self.pin_law, PinLaw::Impact(_)) && (f > 0.0 || fp > 0.0) {
                    for a in 0..3 {
                        qf[idx[a]] += f * jet.grad[a];
                    }
                    let g = &jet.grad;
                    kf.update_block3(dk, |a, b, v| (v + (fp * g[a]) * g[b]) + -f * jet.hess[a][b]);
                }
                if let Some(s) = state.as_deref_mut() {
                    // The profile error's share of the force, -F delta' grad phi on the
                    // disc, is off the normal: its moment about the axis, as the location
                    // term's.
                    if let Some((_, fj, d1)) = &err {
                        let w = f * d1;
                        s.pin_location_moment[slot] -=
                            w * (o[0] * fj.grad[1] - o[1] * fj.grad[0] + fj.grad[2]);
                    }
                    s.pin_force[k * zp + j] = f;
                    s.pin_gap[k * zp + j] = jet.gap;
                    s.pin_jet.push(jet);
                }
            }
        }
        let thc = x[CARRIER];
        let u0 = cos_sin(thc);
        for i in 0..self.cranks {
            let ci = self.crank_index(i);
            let u = rotate(u0, self.seats[i]);
            let s = [m.crank_radius * u[0], m.crank_radius * u[1]];
            let p = [x[ci], x[ci + 1]];
            let dcr = [p[0] - s[0], p[1] - s[1]];
            let alpha = x[ci + 2];
            // Sun/planet mesh i, two flanks with their own lines of action
            // w = sin(pa) u +- cos(pa) z x u (the compliant model's mesh): the flank
            // `sigma` (+1 drive, -1 coast) penetrates by `sigma rot - d . w - b/2`.
            if let Some(mm) = &m.mesh {
                let [sp, cp] = self.pressure;
                let zu = perp(u);
                let (rbs, rbp) = (mm.sun_base_radius, mm.planet_base_radius);
                let rot = rbs * (x[SUN] - thc) + rbp * (alpha - thc);
                let half = 0.5 * mm.backlash;
                let idx = [SUN, CARRIER, ci + 2, ci, ci + 1];
                // `s_i` as in the dynamic models (docs/model.md, "The ISO mesh in the dynamic
                // models"), so the LTCA meets the same stiffness wave at the same pose.
                let s_mesh = rbs * (x[SUN] - thc) - mm.phases[i] * mm.base_pitch;
                let mut f_report = 0.0;
                let mut e_drive = 0.0;
                for sigma in [1.0, -1.0] {
                    // Gear runout and pitch errors: the flank's extra approach E.
                    let ge = FlankError::at(m.mesh_errors.as_ref(), i, sigma, thc, x[SUN], alpha);
                    let e = ge.map_or(0.0, |g| g.value);
                    if sigma > 0.0 {
                        e_drive = e;
                    }
                    let w = [
                        sp * u[0] + sigma * cp * zu[0],
                        sp * u[1] + sigma * cp * zu[1],
                    ];
                    let zw = perp(w);
                    let pen = sigma * rot - dot(dcr, w) - half + e;
                    self.max_penetration = self.max_penetration.max(pen);
                    // V = k(s') pen^2 / 2 for the ISO wave at the flank's position
                    // s' = sigma s: force, stiffness, V_s, V_pen,s, V_ss, damping coefficient.
                    let ms = if on(Family::Mesh) {
                        mesh_static(&mm.law, pen, sigma * s_mesh)
                    } else {
                        MeshStatic::default()
                    };
                    let (f, fp) = (ms.force, ms.stiffness);
                    let mut grad = [
                        sigma * rbs,
                        -sigma * (rbs + rbp) + dot(perp(s), w) - dot(dcr, zw),
                        sigma * rbp,
                        -w[0],
                        -w[1],
                    ];
                    if let Some(g) = &ge {
                        g.add_gradient(&mut grad);
                    }
                    if let Some(c) = cf.as_mut()
                        && on(Family::Mesh)
                    {
                        c.outer(&idx, &grad, ms.damping);
                    }
                    if f > 0.0 || fp > 0.0 {
                        let gs = [sigma * rbs, -sigma * rbs, 0.0, 0.0, 0.0];
                        for a in 0..5 {
                            qf[idx[a]] -= f * grad[a] + ms.v_s * gs[a];
                        }
                        kf.outer(&idx, &grad, fp);
                        if ms.v_ps != 0.0 || ms.v_ss != 0.0 {
                            kf.outer_sym(&idx, &grad, &gs, ms.v_ps);
                            kf.outer(&idx, &gs, ms.v_ss);
                        }
                        kf.add(CARRIER, CARRIER, f * dot(p, w));
                        kf.sym(CARRIER, ci, -f * zw[0]);
                        kf.sym(CARRIER, ci + 1, -f * zw[1]);
                        if let Some(g) = &ge {
                            g.add_curvature(kf, ci, f);
                        }
                    }
                    f_report += sigma * f;
                }
                if let Some(st) = state.as_deref_mut() {
                    st.mesh_force.push(f_report);
                    st.mesh_deflection.push(
                        rot - dot(dcr, [sp * u[0] + cp * zu[0], sp * u[1] + cp * zu[1]]) + e_drive,
                    );
                }
            }
            // Crank bearing: d = p - s_act(th_c) (the actual seat, with its error).
            if let Some(cb) = self
                .crank_bearing
                .as_ref()
                .filter(|_| on(Family::CrankBearings))
            {
                let s = rotate(u0, self.seat_vecs[i]);
                let dcr = [p[0] - s[0], p[1] - s[1]];
                let (g, h) = cb.static_tangent(dcr);
                // J_d: p -> I, th_c -> -perp(s).
                let ps = perp(s);
                let cols: [(usize, [f64; 2]); 3] = [
                    (ci, [1.0, 0.0]),
                    (ci + 1, [0.0, 1.0]),
                    (CARRIER, [-ps[0], -ps[1]]),
                ];
                add_bearing(qf, kf, &cols, g, h);
                if let Some(c) = cf.as_mut() {
                    add_bearing_damping(c, &cols, cb.damping_matrix(dcr));
                }
                kf.add(CARRIER, CARRIER, dot(g, s));
                if let Some(st) = state.as_deref_mut() {
                    st.crank_bearing_force.push([-g[0], -g[1]]);
                    st.bearing_couple -= dcr[0] * g[1] - dcr[1] * g[0];
                }
            }
            // Eccentric bearings (i, k): d = O_k + R(theta_k) h_ik - p_i - eps_ik(alpha_i).
            if let Some(eb) = self
                .eccentric_bearing
                .as_ref()
                .filter(|_| on(Family::EccentricBearings))
            {
                for (k, disc) in m.discs.iter().enumerate() {
                    let dk = self.disc_index(k);
                    let ecc = {
                        let c = cos_sin(alpha + disc.phase + self.ecc_phase[i]);
                        let e = self.ecc_radius[i];
                        [e * c[0], e * c[1]]
                    };
                    let arm = rotate(self.disc_cs[k], self.holes[i * nd + k]);
                    let d = [
                        x[dk] + arm[0] - p[0] - ecc[0],
                        x[dk + 1] + arm[1] - p[1] - ecc[1],
                    ];
                    let (g, h) = eb.static_tangent(d);
                    let pa = perp(arm);
                    let pe = perp(ecc);
                    let cols: [(usize, [f64; 2]); 6] = [
                        (dk, [1.0, 0.0]),
                        (dk + 1, [0.0, 1.0]),
                        (dk + 2, pa),
                        (ci, [-1.0, 0.0]),
                        (ci + 1, [0.0, -1.0]),
                        (ci + 2, [-pe[0], -pe[1]]),
                    ];
                    add_bearing(qf, kf, &cols, g, h);
                    if let Some(c) = cf.as_mut() {
                        add_bearing_damping(c, &cols, eb.damping_matrix(d));
                    }
                    kf.add(dk + 2, dk + 2, -dot(g, arm));
                    kf.add(ci + 2, ci + 2, dot(g, ecc));
                    if let Some(st) = state.as_deref_mut() {
                        st.eccentric_bearing_force.push([-g[0], -g[1]]);
                        st.bearing_couple -= d[0] * g[1] - d[1] * g[0];
                    }
                }
            }
        }
        if fam.is_none() {
            qf[CARRIER] -= torque;
        }
        self.damping = cf;
        if !qf.iter().all(|v| v.is_finite()) || !kf.a.iter().all(|v| v.is_finite()) {
            return Err(RvdynError::Convergence(
                "non-finite static force or stiffness: the pose is far from equilibrium".into(),
            ));
        }
        Ok(())
    }

    /// Static forces `r` and tangent stiffness `k = -dQ/dq` in the unknowns `q` at crank angle
    /// `psi` with the input held, for the output torque `torque` [N m].
    #[allow(clippy::too_many_arguments)]
    pub fn eval(
        &mut self,
        psi: f64,
        q: &[f64],
        torque: f64,
        r: &mut [f64],
        k: &mut Dense,
        work: &mut Work,
        state: Option<&mut ContactState>,
    ) -> Result<()> {
        let mut x = std::mem::take(&mut work.x);
        self.full_into(psi, q, &mut x);
        let nf = x.len();
        if work.kf.n != nf {
            work.kf = Dense::zeros(nf);
            work.qf = vec![0.0; nf];
        }
        let (qf, kf) = (&mut work.qf, &mut work.kf);
        let res = self.full_forces(&x, torque, qf, kf, state);
        work.x = x;
        res?;
        let x = &work.x;
        let m = &self.model;
        let n = self.dim();
        // Jacobian columns of the map (sparse: list of (full index, value) per unknown) and
        // the curvature terms sum_r Q_r hess(x_r).
        // Reuse the column vectors (no allocation per evaluation).
        work.jac.resize_with(n, Vec::new);
        for c in work.jac.iter_mut() {
            c.clear();
        }
        let thc = x[CARRIER];
        let u0 = cos_sin(thc);
        let seat = |i: usize| rotate(u0, self.seat_vecs[i]);
        let slaved_cranks = match self.kind {
            Kind::Rigid => true,
            Kind::Compliant => self.crank_bearing.is_none(),
        };
        match self.kind {
            Kind::Rigid => {
                // dx/dth_c of the rigid-joint map: the carrier and every disc angle turn one
                // for one, each crank seat moves along z x s_i.
                let col = &mut work.jac[0];
                col.push((CARRIER, 1.0));
                for k in 0..m.discs.len() {
                    col.push((self.disc_index(k) + 2, 1.0));
                }
                for i in 0..self.cranks {
                    let ps = perp(seat(i));
                    let ci = self.crank_index(i);
                    col.push((ci, ps[0]));
                    col.push((ci + 1, ps[1]));
                }
                if m.mesh.is_some() {
                    let col = &mut work.jac[1];
                    for i in 0..self.cranks {
                        col.push((self.crank_index(i) + 2, 1.0));
                    }
                    for k in 0..m.discs.len() {
                        let dk = self.disc_index(k);
                        col.push((dk, -x[dk + 1]));
                        col.push((dk + 1, x[dk]));
                    }
                }
            }
            Kind::Compliant => {
                for (a, &i) in self.unknowns.iter().enumerate() {
                    let col = &mut work.jac[a];
                    col.push((i, 1.0));
                    if i == CARRIER && slaved_cranks {
                        for c in 0..self.cranks {
                            let ps = perp(seat(c));
                            let ci = self.crank_index(c);
                            col.push((ci, ps[0]));
                            col.push((ci + 1, ps[1]));
                        }
                    }
                }
            }
        }
        for (a, col) in work.jac.iter().enumerate() {
            r[a] = col.iter().map(|&(i, v)| v * qf[i]).sum();
        }
        // A column that is one full coordinate with weight 1 takes its entries as they are.
        let single = |c: &[(usize, f64)]| match c {
            [(i, v)] if *v == 1.0 => Some(*i),
            _ => None,
        };
        let mut singles = std::mem::take(&mut work.singles);
        singles.clear();
        singles.extend(work.jac.iter().map(|c| single(c)));
        let nf = kf.n;
        for a in 0..n {
            let ja = &work.jac[a];
            let sa = singles[a];
            if let Some(i) = sa {
                // A row of single columns: the entries of row i of K_x as they are.
                let row = &kf.a[i * nf..i * nf + nf];
                let out = &mut k.a[a * n..a * n + n];
                if singles.iter().zip(out.iter_mut()).all(|(sb, o)| match sb {
                    Some(j) => {
                        *o = row[*j];
                        true
                    }
                    None => false,
                }) {
                    continue;
                }
            }
            for (b, (jb, sb)) in work.jac.iter().zip(&singles).enumerate() {
                k.a[a * n + b] = match (sa, *sb) {
                    (Some(i), Some(j)) => kf.at(i, j),
                    _ => {
                        let mut s = 0.0;
                        for &(i, vi) in ja {
                            for &(j, vj) in jb {
                                s += vi * kf.at(i, j) * vj;
                            }
                        }
                        s
                    }
                };
            }
        }
        work.singles = singles;
        // Curvature of the map: slaved crank centres p_i = s_i(th_c) (hess = -s_i) and, for
        // rigid joints, disc centres O_k(alpha) (hess = -O_k).
        if slaved_cranks {
            let mut extra = 0.0;
            for i in 0..self.cranks {
                let ci = self.crank_index(i);
                extra += dot([qf[ci], qf[ci + 1]], seat(i));
            }
            k.a[0] += extra;
        }
        if self.kind == Kind::Rigid && m.mesh.is_some() {
            let mut extra = 0.0;
            for k in 0..m.discs.len() {
                let dk = self.disc_index(k);
                extra += qf[dk] * x[dk] + qf[dk + 1] * x[dk + 1];
            }
            k.a[n + 1] += extra;
        }
        Ok(())
    }

    /// A fresh [`Statics::eval`] at `q` into new buffers: the residual \[N\], the tangent and the
    /// contact state. With `every_pin`, no pin is skipped by the separation bound (exact gaps
    /// of every pin, as a report needs).
    pub fn eval_fresh(
        &mut self,
        psi: f64,
        q: &[f64],
        torque: f64,
        work: &mut Work,
        every_pin: bool,
    ) -> Result<(Vec<f64>, Dense, ContactState)> {
        let n = self.dim();
        let mut r = vec![0.0; n];
        let mut k = Dense::zeros(n);
        let mut cs = ContactState::default();
        let before = self.exact;
        self.exact = every_pin || before;
        let evaluated = self.eval(psi, q, torque, &mut r, &mut k, work, Some(&mut cs));
        self.exact = before;
        evaluated?;
        Ok((r, k, cs))
    }

    /// `out = J^T v` of a full-coordinate force `v` with the map Jacobian of the last
    /// [`Statics::eval`] (the friction forces of `ltca::friction`).
    pub fn reduce_force(&self, v: &[f64], work: &Work, out: &mut [f64]) {
        for (o, col) in out.iter_mut().zip(&work.jac) {
            *o = col.iter().map(|&(i, c)| c * v[i]).sum();
        }
    }

    /// `J^T A J` of a full-coordinate matrix `a` with the map Jacobian of the last
    /// [`Statics::eval`] (velocities map linearly: no curvature terms).
    pub fn reduce(&self, a: &Dense, work: &Work) -> Dense {
        let n = self.dim();
        let mut out = Dense::zeros(n);
        for p in 0..n {
            for b in 0..n {
                let mut s = 0.0;
                for &(i, vi) in &work.jac[p] {
                    for &(j, vj) in &work.jac[b] {
                        s += vi * a.at(i, j) * vj;
                    }
                }
                out.a[p * n + b] = s;
            }
        }
        out
    }

    /// The torque [N m] held cranks of a single stage with rigid joints carry against the
    /// generalised forces `qf` on the discs at the full coordinates `x`: the disc centres ride
    /// on the eccentrics, `dO_k/dpsi = z x O_k`, and the cranks carry minus the forces'
    /// virtual work on them.
    pub(crate) fn held_cranks_reaction(&self, qf: &[f64], x: &[f64]) -> f64 {
        -(0..self.model.discs.len())
            .map(|k| {
                let dk = self.disc_index(k);
                -qf[dk] * x[dk + 1] + qf[dk + 1] * x[dk]
            })
            .sum::<f64>()
    }

    /// The torque the held input carries [N m] (the reaction that holds it): minus the
    /// generalised force on the input coordinates in the last full evaluation.
    pub fn input_reaction(&self, work: &Work) -> f64 {
        if self.model.mesh.is_some() {
            -work.qf[SUN]
        } else if self.kind == Kind::Rigid {
            // Rigid joints: the disc forces never reach the crank coordinates.
            self.held_cranks_reaction(&work.qf, &work.x)
        } else {
            -(0..self.cranks)
                .map(|i| work.qf[self.crank_index(i) + 2])
                .sum::<f64>()
        }
    }

    /// Fresh gaps (with the disc's profile error) in `cs` of the pins that the last
    /// [`Statics::eval`], at the full coordinates `x`, skipped by the separation bound (which
    /// proves them open: no force); the pins it queried keep their jets. For reports: the same
    /// gaps as an evaluation with `exact` set. Errors as [`Statics::full_forces`].
    pub(crate) fn refresh_skipped_jets(&mut self, x: &[f64], cs: &mut ContactState) -> Result<()> {
        let m = &self.model;
        let zp = m.pins.len();
        if !self.skip || cs.pin_jet.len() != m.discs.len() * zp {
            return Ok(());
        }
        for (k, d) in m.discs.iter().enumerate() {
            let dk = self.disc_index(k);
            let o = [x[dk], x[dk + 1]];
            let th = x[dk + 2];
            let cs_th = cos_sin(th);
            // The seed's (cos, sin) as in `full_forces` (no sin_cos per pin).
            let back = cos_sin(-th - d.geometry.params().d_delta);
            for (j, pin) in m.pins.iter().enumerate() {
                let slot = k * zp + j;
                let b = &self.separation[slot];
                if b.0 == o && b.1 == th && b.2.is_finite() {
                    continue;
                }
                let kin = pin.angle - th - d.geometry.params().d_delta;
                let w = &mut self.warm[slot];
                let kcs = rotate(back, self.pin_dirs[j]);
                let (ds, dc) = small_sin_cos(*w);
                let scs = [kcs[0] * dc - kcs[1] * ds, kcs[1] * dc + kcs[0] * ds];
                let jet = gap_jet_cs(
                    &d.geometry,
                    pin.centre,
                    pin.radius,
                    o,
                    cs_th,
                    kin + *w,
                    Some(scs),
                )
                .ok_or_else(|| no_foot(k, j))?;
                let off = jet.phi - kin;
                *w = if off.abs() < 0.01 { off } else { 0.0 };
                self.separation[slot] = (o, th, jet.gap - self.error_bound[k]);
                self.last_jets[slot] = jet;
                let mut e = jet;
                if let Some(pe) = &d.profile_error {
                    e.gap -= pe.offset(jet.phi).0;
                }
                cs.pin_gap[slot] = e.gap;
                cs.pin_jet[slot] = e;
            }
        }
        Ok(())
    }
}

/// The error of a pin query whose foot is not unique.
fn no_foot(k: usize, j: usize) -> RvdynError {
    RvdynError::Convergence(format!(
        "pin {} on disc {k}: no unique contact point on the profile (the disc is far from any \
         sensible pose)",
        j + 1
    ))
}

/// A disc profile error's offset `delta(phi)` \[m\] with its first and second derivatives
/// [m/rad, m/rad^2] (the table is piecewise linear: no second derivative between its points;
/// at a point the slope jumps and the tangent is one-sided).
fn profile_offset_jet(pe: &ProfileError, phi: f64) -> (f64, f64, f64) {
    let (d, d1) = pe.offset(phi);
    let d2 = pe
        .harmonics
        .iter()
        .map(|h| -h[0] * h[1] * h[1] * (h[1] * phi + h[2]).cos())
        .sum();
    (d, d1, d2)
}

/// Scratch space of [`Statics::eval`].
#[derive(Debug, Clone)]
pub struct Work {
    /// Generalised forces in the full coordinates at the last evaluation.
    pub qf: Vec<f64>,
    /// Tangent stiffness in the full coordinates at the last evaluation.
    pub kf: Dense,
    /// Tangent stiffness in the unknowns at the last equilibrium found.
    pub k_last: Dense,
    jac: Vec<Vec<(usize, f64)>>,
    /// Per Jacobian column, the full coordinate it is when it is one with weight 1.
    singles: Vec<Option<usize>>,
    /// Full coordinates of the last evaluation.
    x: Vec<f64>,
}

impl Work {
    /// Empty scratch space (sized on first use).
    pub fn new() -> Self {
        Self {
            qf: Vec::new(),
            kf: Dense::zeros(0),
            k_last: Dense::zeros(0),
            jac: Vec::new(),
            singles: Vec::new(),
            x: Vec::new(),
        }
    }
}

impl Default for Work {
    fn default() -> Self {
        Self::new()
    }
}

/// Elastic force \[N\] and its derivative [N/m] of an IMPACT contact law at penetration `pen`
/// \[m\] (the laws [`Statics::new`] accepts).
#[inline]
pub fn elastic(law: &ImpactLaw, pen: f64) -> (f64, f64) {
    let (force, stiffness, _) = law.force_and_derivatives(pen, 0.0);
    (force, stiffness)
}

/// A mesh flank's static law at one pose: `V(pen, s)` and its derivatives.
#[derive(Debug, Clone, Copy, Default)]
struct MeshStatic {
    force: f64,
    stiffness: f64,
    v_s: f64,
    v_ps: f64,
    v_ss: f64,
    damping: f64,
}

/// The static law of a mesh flank at penetration `pen` \[m\] and mesh position `s` \[m\]: IMPACT
/// (no dependence on `s`) or the ISO 6336 wave, `V = k(s) pen^2 / 2`: `F = k pen`,
/// `V_s = k' pen^2 / 2`, `V_pen,s = k' pen`, `V_ss = k'' pen^2 / 2`.
#[inline]
fn mesh_static(law: &MeshLaw, pen: f64, s: f64) -> MeshStatic {
    if pen <= 0.0 {
        return MeshStatic::default();
    }
    match law {
        MeshLaw::Impact(l) => {
            let (force, stiffness) = elastic(l, pen);
            MeshStatic {
                force,
                stiffness,
                damping: contact_damping(l, pen),
                ..MeshStatic::default()
            }
        }
        MeshLaw::Iso(m) => {
            let (k, dk, d2k) = m.wave.stiffness_slope_curvature(s);
            let force = k * pen;
            MeshStatic {
                force,
                stiffness: k,
                v_s: 0.5 * dk * pen * pen,
                v_ps: dk * pen,
                v_ss: 0.5 * d2k * pen * pen,
                damping: m.damping.rate_coefficient(force, k),
            }
        }
    }
}

/// Damping coefficient [N s/m] of an IMPACT law at penetration `pen` \[m\] (at zero rate).
#[inline]
pub fn contact_damping(law: &ImpactLaw, pen: f64) -> f64 {
    law.force_and_derivatives(pen, 0.0).2
}

/// Add `J_d^T c J_d` for a bearing with deflection Jacobian columns `cols`.
#[inline]
fn add_bearing_damping(cm: &mut Dense, cols: &[(usize, [f64; 2])], c: [[f64; 2]; 2]) {
    for &(i, ji) in cols {
        let cj = [
            c[0][0] * ji[0] + c[0][1] * ji[1],
            c[1][0] * ji[0] + c[1][1] * ji[1],
        ];
        for &(j, jj) in cols {
            cm.add(j, i, dot(jj, cj));
        }
    }
}

/// Add a bearing's force and stiffness: deflection Jacobian columns `cols` (full index,
/// `dd/dx_i`), `g = dV/dd`, `h = hess_d V`.
#[inline]
fn add_bearing(
    qf: &mut [f64],
    kf: &mut Dense,
    cols: &[(usize, [f64; 2])],
    g: [f64; 2],
    h: [[f64; 2]; 2],
) {
    for &(i, ji) in cols {
        qf[i] -= dot(ji, g);
        let hj = [
            h[0][0] * ji[0] + h[0][1] * ji[1],
            h[1][0] * ji[0] + h[1][1] * ji[1],
        ];
        for &(j, jj) in cols {
            kf.add(j, i, dot(jj, hj));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::model::compliant::CompliantModel;
    use crate::dynamics::run::sink::NoSink;
    use crate::dynamics::scene::Scene;
    use crate::solve::MechanicalSystem;

    fn rng(seed: u64) -> impl FnMut() -> f64 {
        let mut state = seed;
        move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64) / ((1u64 << 53) as f64) - 0.5
        }
    }

    fn scenes() -> Vec<Scene> {
        let mut out = Vec::new();
        let base = Scene::paper("rated").unwrap();
        out.push(base.clone());
        let mut m = base.clone();
        m.cycloid.d_rrp = 2e-5;
        m.cycloid.d_rp = -2e-5;
        m.stage1.as_mut().unwrap().backlash = 2e-5;
        out.push(m.clone());
        let mut c = m.clone();
        c.joints = crate::dynamics::model::compliant::default_joints();
        out.push(c.clone());
        let mut c2 = c.clone();
        if let Joints::Compliant {
            eccentric_bearing, ..
        } = &mut c2.joints
        {
            eccentric_bearing.clearance = 5e-6;
        }
        out.push(c2.clone());
        let mut c3 = c2.clone();
        if let Joints::Compliant { crank_bearing, .. } = &mut c3.joints {
            *crank_bearing = None;
        }
        out.push(c3);
        let mut single = base.clone();
        single.stage1 = None;
        out.push(single.clone());
        let mut single_c = single;
        single_c.joints = crate::dynamics::model::compliant::default_joints();
        out.push(single_c);
        out.extend(physical_scenes());
        // Disc profile errors (harmonics and a table) at rigid and compliant joints.
        let mut pe = m.clone();
        with_profile_errors(&mut pe);
        out.push(pe.clone());
        pe.joints = crate::dynamics::model::compliant::default_joints();
        out.push(pe);
        // Assembly errors (compliant joints only), with compliant and rigid crank bearings.
        let mut ae = c.clone();
        with_assembly_errors(&mut ae);
        out.push(ae.clone());
        if let Joints::Compliant { crank_bearing, .. } = &mut ae.joints {
            *crank_bearing = None;
        }
        out.push(ae);
        out
    }

    /// Assembly errors of a few um (and a few 1e-4 rad of phase) on every crank, hole and seat.
    fn with_assembly_errors(s: &mut Scene) {
        let n = s.cranks as usize;
        let nd = s.discs.len();
        let e = &mut s.errors;
        e.crank_eccentricity = (0..n).map(|i| 2e-6 * (i as f64 - 0.7)).collect();
        e.crank_phase = (0..n).map(|i| 3e-4 * (1.0 - i as f64)).collect();
        e.disc_holes = (0..n * nd)
            .map(|j| [1e-6 * (j as f64 - 2.0), -1.5e-6 + 0.7e-6 * j as f64])
            .collect();
        e.carrier_seats = (0..n).map(|i| [-2e-6 + 1e-6 * i as f64, 1.5e-6]).collect();
    }

    /// Disc profile errors of a few um on both discs: harmonics of several orders and a
    /// periodic table on disc 0. The 1 um waviness of order 400 on disc 1 makes the
    /// `delta'' grad phi grad phi^T` term of the tangent visible to the central-difference
    /// test (without it that test fails at 5e-6 > 1e-6; at the lower orders the term is
    /// ~1e-6 of the contact stiffness).
    fn with_profile_errors(s: &mut Scene) {
        s.discs[0].profile_error = Some(ProfileError {
            harmonics: vec![[3e-6, 23.0, 0.4], [2e-6, 2.0, 1.0]],
            table: vec![[0.0, 1e-6], [2.0, -1e-6], [4.0, 5e-7]],
        });
        s.discs[1].profile_error = Some(ProfileError {
            harmonics: vec![[2e-6, 46.0, 1.3], [1e-6, 1.0, 0.0], [1e-6, 400.0, 0.2]],
            table: vec![],
        });
    }

    /// The physical preset (line law, ISO mesh, roller bearings with clearance), modified,
    /// with rigid crank bearings, and with rigid joints.
    fn physical_scenes() -> Vec<Scene> {
        let mut out = Vec::new();
        let base = Scene::physical("rated").unwrap();
        out.push(base.clone());
        let mut m = base.clone();
        m.cycloid.d_rrp = 2e-5;
        m.cycloid.d_rp = -2e-5;
        m.stage1.as_mut().unwrap().backlash = 2e-5;
        out.push(m.clone());
        let mut c = m.clone();
        if let Joints::Compliant { crank_bearing, .. } = &mut c.joints {
            *crank_bearing = None;
        }
        out.push(c);
        let mut r = m;
        r.joints = Joints::Rigid;
        out.push(r.clone());
        // Line law with disc profile errors, compliant and rigid joints.
        let mut pe = base.clone();
        with_profile_errors(&mut pe);
        out.push(pe);
        with_profile_errors(&mut r);
        out.push(r);
        // Roller bearings with assembly errors.
        let mut ae = base.clone();
        with_assembly_errors(&mut ae);
        out.push(ae);
        out
    }

    /// A loaded-looking pose: the kinematic one plus random deflections of the size the
    /// rated load gives (tens of um at the pins).
    fn perturbed(st: &Statics, psi: f64, rnd: &mut impl FnMut() -> f64) -> Vec<f64> {
        let mut q = st.kinematic_unknowns(psi);
        for (a, v) in q.iter_mut().enumerate() {
            *v += 2e-5 * rnd() / st.scale[a] + if a == 0 { -3e-4 } else { 0.0 };
        }
        q
    }

    #[test]
    fn static_forces_are_the_models_forces_at_rest() {
        // The static evaluation and the dynamic models' force evaluation (v = 0) agree. A
        // torque drive (of 0 N m) makes the input free, so that every body is at rest.
        let mut rnd = rng(3);
        for mut scene in scenes() {
            scene.drive = crate::dynamics::scene::Drive::Torque {
                torque: 0.0,
                ramp_time: 0.0,
            };
            let mut st = Statics::new(&scene).unwrap();
            let n = st.dim();
            let mut r = vec![0.0; n];
            let mut k = Dense::zeros(n);
            let mut work = Work::new();
            let torque = scene.load.torque(0.0);
            for _ in 0..5 {
                let psi = 6.0 * rnd();
                let q = perturbed(&st, psi, &mut rnd);
                st.eval(psi, &q, torque, &mut r, &mut k, &mut work, None)
                    .unwrap();
                let x = st.full(psi, &q);
                // Model forces on the same full state at rest.
                let (model_q, free): (Vec<f64>, Vec<usize>) = match scene.joints {
                    Joints::Rigid => {
                        let m = RigidModel::new(&scene).unwrap();
                        let xr = [x[CARRIER], x[st.crank_index(0) + 2], x[SUN]];
                        let f = m.forces(0.0, &xr, &[0.0; 3], &mut NoSink).unwrap();
                        let free = if m.mesh.is_some() {
                            vec![0, 1]
                        } else {
                            vec![0]
                        };
                        (f.q.to_vec(), free)
                    }
                    Joints::Compliant { .. } => {
                        let m = CompliantModel::new(&scene).unwrap();
                        let qfree: Vec<f64> = m.free.iter().map(|&i| x[i]).collect();
                        let mut a = vec![0.0; qfree.len()];
                        let mut p = [0.0; 3];
                        m.eval(0.0, &qfree, &vec![0.0; qfree.len()], &mut a, &mut p)
                            .unwrap();
                        let _ = &mut a;
                        let mut full = vec![0.0; x.len()];
                        for (kk, &i) in m.free.iter().enumerate() {
                            full[i] = a[kk] * m.mass[i];
                        }
                        let free: Vec<usize> =
                            (0..st.unknowns.len()).map(|u| st.unknowns[u]).collect();
                        (full, free)
                    }
                };
                let scale = r
                    .iter()
                    .zip(&st.scale)
                    .map(|(v, l)| (v / l).abs())
                    .fold(torque / 0.15, f64::max);
                for (a, &i) in free.iter().enumerate() {
                    let diff = (r[a] - model_q[i]).abs() / st.scale[a];
                    assert!(
                        diff < 1e-11 * scale,
                        "{:?} unknown {a}: static {} model {}",
                        scene.joints,
                        r[a],
                        model_q[i]
                    );
                }
            }
        }
    }

    /// The analytic tangent equals the dynamic model's own finite-difference tangent
    /// (`ReducerModel::tangent`, one-sided steps of about 1 nm) of its force evaluation, at
    /// loaded states at rest (torque drive, so that every body is free and at rest; pin
    /// approaches of tens of um; poses with a contact within 1 um of touching are skipped).
    /// One-sided differences of a Hertz-type law are wrong by about `h F'' / (2 F')` =
    /// `h / (4 x)` (relative) at an approach `x` (measured: 2e-5): 1e-4 of the largest entry
    /// (N/m after scaling angles by rp) is asserted. At this tolerance the test ties the
    /// analytic tangent to the model's force evaluation but cannot see the geometric term
    /// `F hess g` (a flipped sign of it still passes); the central-difference test below, at
    /// 1e-6 on the same forces, does fail for that mutation.
    #[test]
    fn tangent_matches_the_models_finite_difference_tangent() {
        use crate::dynamics::model::ReducerModel;
        let mut scene = Scene::paper("rated").unwrap();
        scene.cycloid.d_rrp = 1e-5;
        scene.joints = crate::dynamics::model::compliant::default_joints();
        scene.drive = crate::dynamics::scene::Drive::Torque {
            torque: 0.0,
            ramp_time: 0.0,
        };
        let mut st = Statics::new(&scene).unwrap();
        let model = CompliantModel::new(&scene).unwrap();
        let nf = st.full_len();
        let mut rnd = rng(17);
        let mut tested = 0;
        for _ in 0..500 {
            if tested == 3 {
                break;
            }
            let psi = 3.0 * rnd();
            let mut q = st.kinematic_unknowns(psi);
            q[0] -= 5e-4;
            let x = st.full(psi, &q);
            let mut qf = vec![0.0; nf];
            let mut kf = Dense::zeros(nf);
            let mut cs = ContactState::default();
            st.exact = true;
            st.full_forces(&x, 0.0, &mut qf, &mut kf, Some(&mut cs))
                .unwrap();
            // Near first touch one-sided differences of a Hertz law are wrong (see above).
            if cs.pin_gap.iter().any(|g| g.abs() < 1e-6) {
                continue;
            }
            tested += 1;
            let free: Vec<usize> = model.free.clone();
            let qm: Vec<f64> = free.iter().map(|&i| x[i]).collect();
            let (k_fd, _) = model.tangent(0.0, &qm, &vec![0.0; qm.len()]).unwrap();
            let len = |i: usize| {
                if i == CARRIER || i == SUN || (i >= 2 && (i - 2) % 3 == 2) {
                    0.15
                } else {
                    1.0
                }
            };
            let mut kmax: f64 = 0.0;
            for (a, &i) in free.iter().enumerate() {
                for (b, &j) in free.iter().enumerate() {
                    kmax = kmax.max((k_fd[(a, b)] / (len(i) * len(j))).abs());
                }
            }
            let mut worst: f64 = 0.0;
            for (a, &i) in free.iter().enumerate() {
                for (b, &j) in free.iter().enumerate() {
                    let d = (kf.at(i, j) - k_fd[(a, b)]).abs() / (len(i) * len(j));
                    worst = worst.max(d / kmax);
                }
            }
            assert!(worst < 1e-4, "analytic vs model FD tangent: {worst:e}");
        }
        assert_eq!(tested, 3);
    }

    /// Skipping pins that provably cannot touch changes no force or stiffness: along a loaded
    /// sweep, the skipping evaluator and one that queries every pin agree to round-off (also
    /// with disc profile errors, where the bound keeps `gap - max |delta|`).
    #[test]
    fn skipping_separated_pins_gives_the_same_forces() {
        let mut scene = Scene::paper("rated").unwrap();
        scene.cycloid.d_rrp = 2e-5;
        scene.cycloid.d_rp = -2e-5;
        scene.joints = crate::dynamics::model::compliant::default_joints();
        let mut with_errors = scene.clone();
        with_profile_errors(&mut with_errors);
        for scene in [scene, with_errors] {
            let mut skipping = Statics::new(&scene).unwrap();
            let mut fresh = Statics::new(&scene).unwrap();
            fresh.skip = false;
            let n = skipping.dim();
            let (mut r1, mut r2) = (vec![0.0; n], vec![0.0; n]);
            let (mut k1, mut k2) = (Dense::zeros(n), Dense::zeros(n));
            let mut work = Work::new();
            let mut rnd = rng(5);
            let mut worst: f64 = 0.0;
            let mut skipped = 0;
            for i in 0..200 {
                let psi = 0.002 * i as f64;
                let mut q = skipping.kinematic_unknowns(psi);
                q[0] -= 2e-4 + 1e-5 * rnd();
                let mut cs = ContactState::default();
                skipping
                    .eval(psi, &q, 4e4, &mut r1, &mut k1, &mut work, Some(&mut cs))
                    .unwrap();
                fresh
                    .eval(psi, &q, 4e4, &mut r2, &mut k2, &mut work, None)
                    .unwrap();
                for a in 0..n {
                    worst = worst.max((r1[a] - r2[a]).abs() / skipping.scale[a]);
                    for b in 0..n {
                        worst = worst.max((k1.at(a, b) - k2.at(a, b)).abs() * 1e-9);
                    }
                }
                skipped = skipping.skipped;
            }
            assert!(worst == 0.0, "skipping changes the forces by {worst:e}");
            assert!(skipped > 1000, "{skipped}");
        }
    }

    /// `eval_fresh` with `every_pin` gives exactly the evaluation of a model that never skips
    /// a pin (residual, tangent and every pin's gap), also right after evaluations that
    /// skipped pins, and leaves the skip setting as it was; without it, the gaps of skipped
    /// pins are their last exact ones.
    #[test]
    fn fresh_evaluation_of_every_pin_equals_a_non_skipping_one() {
        let mut scene = Scene::paper("rated").unwrap();
        scene.cycloid.d_rrp = 2e-5;
        scene.cycloid.d_rp = -2e-5;
        scene.joints = crate::dynamics::model::compliant::default_joints();
        let mut skipping = Statics::new(&scene).unwrap();
        let mut never = Statics::new(&scene).unwrap();
        never.skip = false;
        let n = skipping.dim();
        let (mut r, mut k) = (vec![0.0; n], Dense::zeros(n));
        let mut work = Work::new();
        let psi = 0.1;
        let mut q = skipping.kinematic_unknowns(psi);
        q[0] -= 2e-4;
        skipping
            .eval(psi, &q, 4e4, &mut r, &mut k, &mut work, None)
            .unwrap();
        q[0] -= 1e-7;
        let skipped_before = skipping.skipped;
        let (r1, k1, cs1) = skipping.eval_fresh(psi, &q, 4e4, &mut work, true).unwrap();
        assert_eq!(skipping.skipped, skipped_before, "no pin skipped");
        assert!(!skipping.exact);
        let (r2, k2, cs2) = never.eval_fresh(psi, &q, 4e4, &mut work, false).unwrap();
        assert_eq!(r1, r2);
        assert_eq!(k1.a, k2.a);
        assert_eq!(cs1.pin_gap, cs2.pin_gap);
        // Without every_pin the skip applies again.
        q[0] -= 1e-7;
        skipping.eval_fresh(psi, &q, 4e4, &mut work, false).unwrap();
        assert!(skipping.skipped > skipped_before);
    }

    /// The tangent stiffness equals central differences of the static forces.
    ///
    /// Step h = 1e-9 m of each unknown (h / length for angles). Near first touch a Hertz-type
    /// law `k x^1.5` makes central differences of its stiffness wrong by `h^2 / (24 x^2)`
    /// (relative), so poses with a contact within 1e-6 m of touching are skipped: then that
    /// error is below 4e-8, and round-off (gaps to ~3e-17 m, times stiffnesses ~1e9 N/m,
    /// over h) is ~3e-8 of the stiffness. Asserted: 1e-6 relative to the largest entry
    /// (scaled to N/m). (The analytic value is also the limit of the differences as h -> 0:
    /// their error falls as h^2 from h = 1e-6 to 1e-9 m.)
    #[test]
    fn tangent_matches_finite_differences_of_the_forces() {
        let mut rnd = rng(11);
        for scene in scenes() {
            let mut st = Statics::new(&scene).unwrap();
            let n = st.dim();
            let torque = scene.load.torque(0.0);
            let mut work = Work::new();
            let mut worst: f64 = 0.0;
            let mut tested = 0;
            let backlash = scene.stage1.as_ref().map_or(0.0, |s| s.backlash);
            while tested < 4 {
                let psi = 6.0 * rnd();
                let q = perturbed(&st, psi, &mut rnd);
                let mut r = vec![0.0; n];
                let mut k = Dense::zeros(n);
                let mut cs = ContactState::default();
                st.eval(psi, &q, torque, &mut r, &mut k, &mut work, Some(&mut cs))
                    .unwrap();
                let near_touch = |g: f64| g.abs() < 1e-6;
                if cs.pin_gap.iter().any(|g| near_touch(*g))
                    || cs
                        .mesh_deflection
                        .iter()
                        .any(|d| near_touch(d.abs() - 0.5 * backlash))
                {
                    continue;
                }
                tested += 1;
                let mut kmax: f64 = 0.0;
                for a in 0..n {
                    for b in 0..n {
                        kmax = kmax.max((k.at(a, b) / (st.scale[a] * st.scale[b])).abs());
                    }
                }
                let h = 1e-9;
                for b in 0..n {
                    let mut qp = q.clone();
                    let mut qm = q.clone();
                    qp[b] += h / st.scale[b];
                    qm[b] -= h / st.scale[b];
                    let mut rp = vec![0.0; n];
                    let mut rm = vec![0.0; n];
                    let mut scratch = Dense::zeros(n);
                    st.eval(psi, &qp, torque, &mut rp, &mut scratch, &mut work, None)
                        .unwrap();
                    st.eval(psi, &qm, torque, &mut rm, &mut scratch, &mut work, None)
                        .unwrap();
                    for a in 0..n {
                        // K = -dQ/dq, scaled to N/m.
                        let fd = -(rp[a] - rm[a]) / (2.0 * h) / st.scale[a];
                        let an = k.at(a, b) / (st.scale[a] * st.scale[b]);
                        worst = worst.max((fd - an).abs() / kmax);
                    }
                }
            }
            assert!(worst < 1e-6, "{:?}: K vs FD {worst:e}", scene.joints);
        }
    }

    /// The roller bearings' analytic static tangent and damping matrix against central
    /// differences of their force (`BearingLaw::load`): in the deflection (step 1e-10 m) and
    /// in the rate (step 1e-6 m/s; the damping is linear in the rate, so exact to round-off).
    /// Deflections where a roller is within 1e-7 m of first touch are skipped: there the
    /// difference of `Q = K delta^(10/9)` errs by `0.0165 h^2 / delta^2` (relative), below 2e-8
    /// elsewhere; round-off ~1e-16 F / h ~ 1e-7 of the stiffness. Asserted 1e-6 of the
    /// largest entry.
    #[test]
    fn roller_bearing_tangent_matches_finite_differences() {
        let scene = Scene::physical("rated").unwrap();
        let Joints::Compliant {
            eccentric_bearing,
            crank_bearing,
        } = &scene.joints
        else {
            panic!("physical joints are compliant")
        };
        let mut rnd = rng(41);
        for spec in [eccentric_bearing, crank_bearing.as_ref().unwrap()] {
            let law = BearingLaw::new(spec).unwrap();
            let BearingLaw::Rollers { bearing, .. } = &law else {
                panic!("rollers expected")
            };
            let z = bearing.rollers();
            let mut tested = 0;
            while tested < 30 {
                let d = [3e-5 * rnd(), 3e-5 * rnd()];
                let near = (0..z).any(|j| {
                    let a = TAU * j as f64 / z as f64;
                    (d[0] * a.cos() + d[1] * a.sin() - bearing.clearance()).abs() < 1e-7
                });
                if near || d[0].hypot(d[1]) < bearing.clearance() + 2e-6 {
                    continue;
                }
                tested += 1;
                let (g, h) = law.static_tangent(d);
                let c = law.damping_matrix(d);
                let f0 = law.load(d, [0.0; 2]).force;
                assert_eq!(g, [-f0[0], -f0[1]]);
                let hmax = h.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
                let cmax = c.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
                for k in 0..2 {
                    let (mut a, mut b) = (d, d);
                    a[k] += 1e-10;
                    b[k] -= 1e-10;
                    let (fa, fb) = (law.load(a, [0.0; 2]).force, law.load(b, [0.0; 2]).force);
                    let mut va = [0.0; 2];
                    va[k] = 1e-6;
                    let (ra, rb) = (law.load(d, va).force, law.load(d, [-va[0], -va[1]]).force);
                    for r in 0..2 {
                        let fd = -(fa[r] - fb[r]) / 2e-10;
                        assert!(
                            (fd - h[r][k]).abs() < 1e-6 * hmax,
                            "K {r}{k}: {fd} {}",
                            h[r][k]
                        );
                        let fdc = -(ra[r] - rb[r]) / 2e-6;
                        assert!(
                            (fdc - c[r][k]).abs() < 1e-6 * cmax,
                            "C {r}{k}: {fdc} {}",
                            c[r][k]
                        );
                    }
                }
            }
        }
    }
}
