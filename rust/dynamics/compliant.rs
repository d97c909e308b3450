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
//!   hole centre `H_ik = O_k + R(theta_k) h_ik`, `h_ik = R(-d_k) r_cr (cos gamma_i,
//!   sin gamma_i)`, `d_k = -a_k / zc`; in the kinematic pose (`p_i = s_i`, `alpha_i = alpha`,
//!   `O_k = e (cos(alpha + a_k), sin(alpha + a_k))`, `theta_k = th_c + d_k`) `H = E` exactly;
//! - a bearing spring-damper with radial clearance `c` acts only when `|d| > c`, with magnitude
//!   `k (|d| - c) + c_b d|d|/dt`, clamped at 0 (it cannot pull), along `d / |d|`; with `c = 0`
//!   it is the linear vector spring-damper `F = -k d - c_b d'`;
//! - pin contacts: the exact contact of each pin with disc `k` in its free pose
//!   (`pin_contact`); penetration rate `N . (O_k' + theta_k' z x arm)`; force `-F N` on the disc;
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

use crate::dynamics::model::{Layout, Observation, ReducerModel};
use crate::dynamics::pin_contact::{DiscPose, WarmStart, penetration_error, pin_contact};
use crate::dynamics::rigid::RigidModel;
use crate::dynamics::scene::{Bearing, Initial, Joints, Scene};
use crate::dynamics::sink::{ContactSink, DynSink, NoSink};
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
        },
        crank_bearing: Some(Bearing {
            stiffness: 2.0e9,
            damping: 1.0e4,
            clearance: 0.0,
        }),
    }
}

/// Force of one bearing spring-damper and its energy flows.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct BearingLoad {
    /// Force on the body at the `+` end of the deflection `d` [N] (the other body gets the
    /// opposite).
    pub force: [f64; 2],
    /// Power dissipated by the damper [W] (>= 0).
    pub dissipation: f64,
    /// Elastic energy of the spring [J].
    pub energy: f64,
}

/// The bearing law for a deflection `d` [m] and its rate `dd` [m/s] (see the module doc).
#[inline]
pub fn bearing_load(b: &Bearing, d: [f64; 2], dd: [f64; 2]) -> BearingLoad {
    if b.clearance <= 0.0 {
        let f = [
            -b.stiffness * d[0] - b.damping * dd[0],
            -b.stiffness * d[1] - b.damping * dd[1],
        ];
        return BearingLoad {
            force: f,
            dissipation: b.damping * dot(dd, dd),
            energy: 0.5 * b.stiffness * dot(d, d),
        };
    }
    let dist = dot(d, d).sqrt();
    if dist <= b.clearance {
        return BearingLoad::default();
    }
    let n = [d[0] / dist, d[1] / dist];
    let pen = dist - b.clearance;
    let rate = dot(n, dd);
    let elastic = b.stiffness * pen;
    let f = (elastic + b.damping * rate).max(0.0);
    BearingLoad {
        force: [-f * n[0], -f * n[1]],
        dissipation: (f - elastic) * rate,
        energy: 0.5 * b.stiffness * pen * pen,
    }
}

/// Energy flows of one force evaluation.
#[derive(Debug, Clone, Copy, Default)]
struct Flows {
    /// Power dissipated by contact and bearing damping [W].
    dissipation: f64,
    /// Elastic energy of the contacts and bearings [J] (contacts only when asked for).
    potential: f64,
}

/// The compliant-joint reducer model (a [`MechanicalSystem`] in its free coordinates).
#[derive(Debug, Clone)]
pub struct CompliantModel {
    /// The rigid model of the same scene: geometry, laws, inertias, drive and load.
    pub base: RigidModel,
    pub eccentric_bearing: Bearing,
    /// `None`: rigid crank bearings, the crank centres stay in their seats on the carrier
    /// (their mass then turns with the carrier: `n m_cr r_cr^2` joins its inertia).
    pub crank_bearing: Option<Bearing>,
    /// Number of cranks.
    pub cranks: usize,
    /// `(cos gamma_i, sin gamma_i)` of each crank seat.
    seats: Vec<[f64; 2]>,
    /// Disc hole centres `h_ik` in the disc frame, at `i * discs + k` [m].
    holes: Vec<[f64; 2]>,
    /// `(sin, cos)` of the pressure angle: `w_i = sin u_i + cos (z x u_i)`.
    pressure: [f64; 2],
    /// Diagonal mass of every full coordinate [kg or kg m^2].
    pub mass: Vec<f64>,
    /// Free coordinates (indices into the full vector).
    pub free: Vec<usize>,
    /// Prescribed coordinates (the sun, or every crank rotation without a first stage).
    pub prescribed: Vec<usize>,
    /// Coordinates the input torque acts on (shared equally).
    input: Vec<usize>,
    /// Lever per free coordinate [m per unit].
    scale: Vec<f64>,
    /// Foot parameter of each (disc, pin) contact at the last evaluation (Newton warm start;
    /// the contact found does not depend on it).
    warm_seeds: Vec<Cell<WarmStart>>,
}

#[inline]
fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// `(a x b)_z`.
#[inline]
fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// `z x a`.
#[inline]
fn perp(a: [f64; 2]) -> [f64; 2] {
    [-a[1], a[0]]
}

#[inline]
fn rotate(angle: f64, a: [f64; 2]) -> [f64; 2] {
    let (s, c) = angle.sin_cos();
    [c * a[0] - s * a[1], s * a[0] + c * a[1]]
}

#[inline]
fn add(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] + b[0], a[1] + b[1]]
}

#[inline]
fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

#[inline]
fn scaled(s: f64, a: [f64; 2]) -> [f64; 2] {
    [s * a[0], s * a[1]]
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
        let mut rigid_scene = scene.clone();
        rigid_scene.joints = Joints::Rigid;
        let base = RigidModel::new(&rigid_scene)?;
        let n = base.cranks;
        let nd = base.discs.len();
        let seats: Vec<[f64; 2]> = (0..n)
            .map(|i| {
                let (s, c) = (TAU * i as f64 / n as f64).sin_cos();
                [c, s]
            })
            .collect();
        let mut holes = Vec::with_capacity(n * nd);
        for seat in &seats {
            for d in &base.discs {
                holes.push(rotate(-d.angle_offset, scaled(base.crank_radius, *seat)));
            }
        }
        let pressure = scene.stage1.as_ref().map_or([0.0, 1.0], |s| {
            let (s, c) = s.pressure_angle.sin_cos();
            [s, c]
        });
        let inr = &base.inertias;
        let e = base.eccentricity;
        let rp = scene.cycloid.pin_circle_radius;
        let crank_lever = base.mesh.map_or(e, |m| m.planet_base_radius.max(e));
        let n_full = 2 + 3 * n + 3 * nd;
        let zp = base.pins.len();
        let rigid_cranks = crank_bearing.is_none();
        let crank_orbit = if rigid_cranks {
            n as f64 * inr.crank.mass * base.crank_radius * base.crank_radius
        } else {
            0.0
        };
        let mut mass = vec![
            inr.carrier.inertia + inr.load_inertia + crank_orbit,
            inr.sun.inertia,
        ];
        let mut lever = vec![rp, base.mesh.map_or(0.0, |m| m.sun_base_radius)];
        for _ in 0..n {
            mass.extend([inr.crank.mass, inr.crank.mass, inr.crank.inertia]);
            lever.extend([1.0, 1.0, crank_lever]);
        }
        for _ in 0..nd {
            mass.extend([inr.disc.mass, inr.disc.mass, inr.disc.inertia]);
            lever.extend([1.0, 1.0, rp]);
        }
        let crank_rotations: Vec<usize> = (0..n).map(|i| crank_index(i) + 2).collect();
        let has_mesh = base.mesh.is_some();
        let input = if has_mesh {
            vec![SUN]
        } else {
            crank_rotations.clone()
        };
        let prescribed = match (base.drive.is_speed(), has_mesh) {
            (true, true) => vec![SUN],
            (true, false) => crank_rotations,
            (false, _) => Vec::new(),
        };
        let crank_centres: Vec<usize> = (0..n)
            .flat_map(|i| [crank_index(i), crank_index(i) + 1])
            .collect();
        let free: Vec<usize> = (0..n_full)
            .filter(|i| !prescribed.contains(i) && (*i != SUN || has_mesh))
            .filter(|i| !(rigid_cranks && crank_centres.contains(i)))
            .collect();
        let scale = free.iter().map(|&i| lever[i]).collect();
        Ok(Self {
            base,
            eccentric_bearing,
            crank_bearing,
            cranks: n,
            seats,
            holes,
            pressure,
            mass,
            free,
            prescribed,
            input,
            scale,
            warm_seeds: vec![Cell::new(WarmStart::default()); nd * zp],
        })
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
    pub fn full_initial_state(&self) -> (Vec<f64>, Vec<f64>) {
        let m = &self.base;
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
        for (i, seat) in self.seats.iter().enumerate() {
            let ci = crank_index(i);
            let p = scaled(m.crank_radius, *seat);
            let pv = scaled(wc, perp(p));
            x[ci..ci + 3].copy_from_slice(&[p[0], p[1], 0.0]);
            v[ci..ci + 3].copy_from_slice(&[pv[0], pv[1], wa]);
        }
        for (k, d) in m.discs.iter().enumerate() {
            let dk = self.disc_index(k);
            let (s, c) = d.phase.sin_cos();
            let o = [m.eccentricity * c, m.eccentricity * s];
            let ov = scaled(wa, perp(o));
            x[dk..dk + 3].copy_from_slice(&[o[0], o[1], d.angle_offset]);
            v[dk..dk + 3].copy_from_slice(&[ov[0], ov[1], wc]);
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
        for (i, seat) in self.seats.iter().enumerate() {
            let ci = crank_index(i);
            let s = scaled(self.base.crank_radius, rotate(x[CARRIER], *seat));
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
        let (ang, spd, acc) = self.base.drive.motion(t);
        for &p in &self.prescribed {
            x[p] = ang;
            v[p] = spd;
        }
        acc
    }

    /// Full coordinates from free ones at `t`; returns `(x, v, prescribed acceleration)`.
    pub fn full(&self, t: f64, q: &[f64], v: &[f64]) -> (Vec<f64>, Vec<f64>, f64) {
        let n_full = self.full_len();
        let mut x = vec![0.0; n_full];
        let mut xv = vec![0.0; n_full];
        for (k, &i) in self.free.iter().enumerate() {
            x[i] = q[k];
            xv[i] = v[k];
        }
        let acc = self.apply_drive(t, &mut x, &mut xv);
        self.place_rigid_cranks(&mut x, &mut xv);
        (x, xv, acc)
    }

    /// Deflection `d = p_i - s_i` of crank bearing `i` and `d = H_ik - E_ik` of eccentric
    /// bearing `(i, k)` (at `i * discs + k`) for the full coordinates `x` [m].
    pub fn bearing_deflections(&self, x: &[f64]) -> (Vec<[f64; 2]>, Vec<[f64; 2]>) {
        let m = &self.base;
        let nd = m.discs.len();
        let mut crank = Vec::with_capacity(self.cranks);
        let mut ecc = Vec::with_capacity(self.cranks * nd);
        for (i, seat) in self.seats.iter().enumerate() {
            let ci = crank_index(i);
            let p = [x[ci], x[ci + 1]];
            crank.push(sub(p, scaled(m.crank_radius, rotate(x[CARRIER], *seat))));
            for (k, d) in m.discs.iter().enumerate() {
                let dk = self.disc_index(k);
                let (s, c) = (x[ci + 2] + d.phase).sin_cos();
                let e_pos = add(p, [m.eccentricity * c, m.eccentricity * s]);
                let h = add(
                    [x[dk], x[dk + 1]],
                    rotate(x[dk + 2], self.holes[i * nd + k]),
                );
                ecc.push(sub(h, e_pos));
            }
        }
        (crank, ecc)
    }

    /// Generalised forces `qf` on every full coordinate at `(t, x, v)`, reporting every
    /// contact to `sink`.
    ///
    /// Fails with `SimulationError` if a force is not finite or a penetration exceeds the
    /// physical bound or an exact gap cannot be found (the disc is far from any sensible pose).
    fn forces<S: ContactSink>(
        &self,
        t: f64,
        x: &[f64],
        v: &[f64],
        qf: &mut [f64],
        sink: &mut S,
    ) -> Result<Flows> {
        let m = &self.base;
        let nd = m.discs.len();
        let want_energy = sink.wants_energy();
        let mut out = Flows::default();
        qf.fill(0.0);
        let (thc, vc) = (x[CARRIER], v[CARRIER]);
        let e = m.eccentricity;
        for (i, seat) in self.seats.iter().enumerate() {
            let ci = crank_index(i);
            let u = rotate(thc, *seat);
            let s = scaled(m.crank_radius, u);
            let s_v = scaled(vc, perp(s));
            let p = [x[ci], x[ci + 1]];
            let pv = [v[ci], v[ci + 1]];
            let (alpha, va) = (x[ci + 2], v[ci + 2]);
            let d = sub(p, s);
            let dd = sub(pv, s_v);
            // Crank bearing: force on the crank centre, reaction on the carrier at s_i.
            if let Some(cb) = &self.crank_bearing {
                let b = bearing_load(cb, d, dd);
                qf[ci] += b.force[0];
                qf[ci + 1] += b.force[1];
                qf[CARRIER] -= cross(s, b.force);
                out.dissipation += b.dissipation;
                out.potential += b.energy;
            }
            // Eccentric bearings: force on the disc at H, opposite on the crank at E.
            for (k, disc) in m.discs.iter().enumerate() {
                let dk = self.disc_index(k);
                let (sa, ca) = (alpha + disc.phase).sin_cos();
                let ecc = [e * ca, e * sa];
                let e_pos = add(p, ecc);
                let e_v = add(pv, scaled(va, perp(ecc)));
                let o = [x[dk], x[dk + 1]];
                let ov = [v[dk], v[dk + 1]];
                let arm = rotate(x[dk + 2], self.holes[i * nd + k]);
                let h = add(o, arm);
                let h_v = add(ov, scaled(v[dk + 2], perp(arm)));
                let b = bearing_load(&self.eccentric_bearing, sub(h, e_pos), sub(h_v, e_v));
                let f = b.force;
                qf[dk] += f[0];
                qf[dk + 1] += f[1];
                qf[dk + 2] += cross(arm, f);
                qf[ci] -= f[0];
                qf[ci + 1] -= f[1];
                qf[ci + 2] -= cross(ecc, f);
                out.dissipation += b.dissipation;
                out.potential += b.energy;
            }
            // Sun/planet mesh i along w_i = sin(pa) u_i + cos(pa) z x u_i.
            if let Some(mm) = &m.mesh {
                let [sp, cp] = self.pressure;
                let zu = perp(u);
                let w = [sp * u[0] + cp * zu[0], sp * u[1] + cp * zu[1]];
                let zw = perp(w);
                let (rbs, rbp) = (mm.sun_base_radius, mm.planet_base_radius);
                let delta = rbs * (x[SUN] - thc) + rbp * (alpha - thc) - dot(d, w);
                let rate = rbs * (v[SUN] - vc) + rbp * (va - vc) - dot(dd, w) - vc * dot(d, zw);
                let half = 0.5 * mm.backlash;
                let (f, elastic, pen, pen_rate) = if delta > half {
                    let x = delta - half;
                    (mm.law.force(x, rate), mm.law.elastic_force(x), x, rate)
                } else if delta < -half {
                    let x = -delta - half;
                    (-mm.law.force(x, -rate), -mm.law.elastic_force(x), x, -rate)
                } else {
                    (0.0, 0.0, 0.0, 0.0)
                };
                if pen > 0.0 {
                    if sink.checks_bounds() && (pen.is_nan() || pen >= m.max_penetration) {
                        return Err(penetration_error(
                            t,
                            pen,
                            m.max_penetration,
                            &format!("sun/planet mesh {i}"),
                        ));
                    }
                    // Q = -F grad(delta); d(delta)/d(th_c) includes ds_i/dth_c = z x s_i and
                    // dw_i/dth_c = z x w_i.
                    qf[SUN] -= f * rbs;
                    qf[ci + 2] -= f * rbp;
                    qf[ci] += f * w[0];
                    qf[ci + 1] += f * w[1];
                    qf[CARRIER] += f * (rbs + rbp - dot(perp(s), w) + dot(d, zw));
                    out.dissipation += (f.abs() - elastic.abs()) * pen_rate;
                    if want_energy {
                        out.potential += mm.law.elastic_energy(pen);
                    }
                }
                sink.mesh(i, f, delta);
            }
        }
        for (k, disc) in m.discs.iter().enumerate() {
            let dk = self.disc_index(k);
            let o = [x[dk], x[dk + 1]];
            let ov = [v[dk], v[dk + 1]];
            let (th, vt) = (x[dk + 2], v[dk + 2]);
            let pose = DiscPose::new(o, th);
            for (j, pin) in m.pins.iter().enumerate() {
                let warm = &self.warm_seeds[k * m.pins.len() + j];
                let Some(pc) = pin_contact(disc, pin, &pose, t, (k, j), warm)? else {
                    sink.pin(k, j, 0.0, 0.0, 0.0, [0.0; 2], [0.0; 2]);
                    continue;
                };
                let pen = pc.penetration;
                if sink.checks_bounds() && (pen.is_nan() || pen >= m.max_penetration) {
                    let what = format!("pin {} on disc {k}", j + 1);
                    return Err(penetration_error(t, pen, m.max_penetration, &what));
                }
                let n = pc.normal;
                let lever = pc.lever();
                let pen_rate = dot(n, ov) + vt * lever;
                let f = m.pin_law.force(pen, pen_rate);
                qf[dk] -= f * n[0];
                qf[dk + 1] -= f * n[1];
                qf[dk + 2] -= f * lever;
                out.dissipation += (f - m.pin_law.elastic_force(pen)) * pen_rate;
                if want_energy {
                    out.potential += m.pin_law.elastic_energy(pen);
                }
                // Moment of the pin's force (-f n) on the disc about the disc centre.
                sink.pin(k, j, f, pen, -f * lever, add(o, pc.arm), n);
            }
        }
        if self.crank_bearing.is_none() {
            // Rigid crank bearings: a force on a crank centre turns the carrier, through the
            // seat's lever (virtual work with ds_i/dth_c = z x s_i).
            for (i, seat) in self.seats.iter().enumerate() {
                let ci = crank_index(i);
                let s = scaled(m.crank_radius, rotate(thc, *seat));
                qf[CARRIER] += cross(s, [qf[ci], qf[ci + 1]]);
                qf[ci] = 0.0;
                qf[ci + 1] = 0.0;
            }
        }
        qf[CARRIER] -= m.load.torque(t);
        if let Some(tq) = m.drive.torque(t) {
            let share = tq / self.input.len() as f64;
            for &i in &self.input {
                qf[i] += share;
            }
        }
        if !qf.iter().all(|v| v.is_finite()) {
            return Err(RvdynError::Simulation(format!(
                "non-finite generalised force at t = {t:.6e} s: the integration has diverged; \
                 reduce the step (dt) or the tolerances, or use the implicit integrator"
            )));
        }
        Ok(out)
    }

    /// Kinetic energy of the free bodies [J] (a prescribed input is a driver, not counted).
    fn kinetic_energy(&self, v: &[f64]) -> f64 {
        self.free
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
        self.free.len()
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
        for (k, &i) in self.free.iter().enumerate() {
            a[k] = qf[i] / self.mass[i];
        }
        let m = &self.base;
        power[0] = match m.drive.torque(t) {
            Some(tq) => {
                let share = tq / self.input.len() as f64;
                self.input.iter().map(|&i| share * xv[i]).sum()
            }
            None => -self.prescribed.iter().map(|&p| qf[p] * xv[p]).sum::<f64>(),
        };
        power[1] = m.load.torque(t) * xv[CARRIER];
        power[2] = flows.dissipation;
        Ok(())
    }

    fn length_scale(&self) -> &[f64] {
        &self.scale
    }
}

impl ReducerModel for CompliantModel {
    fn layout(&self) -> Layout {
        self.base.layout()
    }

    fn initial_state(&self) -> (Vec<f64>, Vec<f64>) {
        let (x, v) = self.full_initial_state();
        (
            self.free.iter().map(|&i| x[i]).collect(),
            self.free.iter().map(|&i| v[i]).collect(),
        )
    }

    fn observe(
        &self,
        t: f64,
        q: &[f64],
        v: &[f64],
        sink: &mut dyn ContactSink,
    ) -> Result<Observation> {
        let m = &self.base;
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
        Ok(Observation {
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
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::record::Recording;
    use crate::dynamics::scene::{Drive, Load, StartKind};
    use crate::dynamics::simulate::{RunControl, SimOptions, simulate};
    use crate::solve::dopri5::Dopri5;
    use crate::solve::{Method, State};

    fn scene(load: &str, joints: Joints, initial: Initial) -> Scene {
        let mut s = Scene::paper(load).unwrap();
        s.joints = joints;
        s.initial = initial;
        s
    }

    fn joints(k: f64, c: f64, clearance: f64) -> Joints {
        let b = Bearing {
            stiffness: k,
            damping: c,
            clearance,
        };
        Joints::Compliant {
            eccentric_bearing: b,
            crank_bearing: Some(b),
        }
    }

    fn run(s: &Scene, t_end: f64, atol: f64) -> Recording {
        let mut opt = SimOptions::new(t_end, Method::Dopri5);
        opt.atol = atol;
        opt.record_interval = Some(2e-5);
        simulate(s, &opt, &RunControl::default()).unwrap()
    }

    fn series<'a>(r: &'a Recording, name: &str) -> &'a [f64] {
        &r.series[name].data
    }

    fn mean_speed(r: &Recording) -> f64 {
        let (t, a) = (series(r, "t"), series(r, "carrier_angle"));
        let n = t.len();
        (a[n - 1] - a[n / 2]) / (t[n - 1] - t[n / 2])
    }

    fn peak(v: &[f64]) -> f64 {
        v.iter().cloned().fold(0.0, f64::max)
    }

    fn last_residual(r: &Recording) -> (f64, f64) {
        let n = r.samples;
        (
            series(r, "energy_residual")[n - 1],
            series(r, "input_work")[n - 1],
        )
    }

    /// Wants the elastic energy and counts the loaded contacts.
    #[derive(Default)]
    struct Count {
        pins: usize,
        mesh: usize,
    }
    impl ContactSink for Count {
        fn wants_energy(&self) -> bool {
            true
        }
        fn pin(&mut self, _: usize, _: usize, f: f64, _: f64, _: f64, _: [f64; 2], _: [f64; 2]) {
            self.pins += usize::from(f > 0.0);
        }
        fn mesh(&mut self, _: usize, f: f64, _: f64) {
            self.mesh += usize::from(f != 0.0);
        }
    }

    /// At rest (no damping force), every generalised force, prescribed coordinates included,
    /// is minus the derivative of the elastic energy (central differences, 1 nm of displacement
    /// at each coordinate's lever). Checks every coupling's virtual work, signs and reactions.
    /// Tolerance 1e-6 of the largest force: the difference error is about
    /// eps V / h ~ 1e-16 * 10 J / 1e-9 m ~ 1e-6 N and h^2 V''' is smaller still.
    #[test]
    fn generalised_forces_are_minus_the_energy_gradient() {
        for clearance in [0.0, 2e-6] {
            let s = scene("idle", joints(1e9, 1e4, clearance), Initial::Rest);
            let m = CompliantModel::new(&s).unwrap();
            let (mut x, _) = m.full_initial_state();
            let v = vec![0.0; x.len()];
            // A deflected pose: sun ahead (mesh loaded), discs lagging (pins loaded), cranks and
            // discs displaced by micrometres (every bearing loaded, beyond the clearance).
            x[CARRIER] += 1e-5;
            x[SUN] += 1e-3;
            for i in 0..m.cranks {
                let ci = crank_index(i);
                x[ci] += 7e-6 * (i as f64 + 1.0);
                x[ci + 1] -= 5e-6 * (i as f64 - 0.7);
                x[ci + 2] += 2e-3 * (i as f64 + 1.0);
            }
            for k in 0..2 {
                let dk = m.disc_index(k);
                x[dk] += 6e-6;
                x[dk + 1] -= 4e-6 * (k as f64 + 1.0);
                x[dk + 2] -= 2e-4;
            }
            let mut qf = vec![0.0; x.len()];
            let mut count = Count::default();
            m.forces(0.0, &x, &v, &mut qf, &mut count).unwrap();
            assert!(
                count.pins >= 4 && count.mesh == 3,
                "{} {}",
                count.pins,
                count.mesh
            );
            let (crank, ecc) = m.bearing_deflections(&x);
            assert!(
                crank
                    .iter()
                    .chain(&ecc)
                    .all(|d| d[0].hypot(d[1]) > clearance)
            );
            let energy = |x: &[f64]| {
                let mut q = vec![0.0; x.len()];
                m.forces(0.0, x, &v, &mut q, &mut Count::default())
                    .unwrap()
                    .potential
            };
            let fmax = qf.iter().fold(0.0f64, |a, b| a.max(b.abs()));
            for i in 0..x.len() {
                // Levers: carrier and disc angles 0.1 m, sun r_bs, crank angles e, else 1.
                let l = match i {
                    CARRIER => 0.1,
                    SUN => m.base.mesh.map_or(1.0, |mm| mm.sun_base_radius),
                    _ if (i - 2) % 3 != 2 => 1.0,
                    _ if i < m.disc_index(0) => m.base.eccentricity,
                    _ => 0.1,
                };
                let h = 1e-9 / l;
                let (mut xp, mut xm) = (x.clone(), x.clone());
                xp[i] += h;
                xm[i] -= h;
                let fd = -(energy(&xp) - energy(&xm)) / (2.0 * h);
                assert!(
                    (fd - qf[i]).abs() * l <= 1e-6 * fmax,
                    "clearance {clearance}: coordinate {i}: Q = {} but -dV/dq = {fd}",
                    qf[i]
                );
            }
        }
    }

    /// Power identity with damping: for a deflected pose moving with arbitrary velocities, the
    /// power of all generalised forces (prescribed coordinates included, no load or drive
    /// torque) is `-dV/dt - D`: every penetration/deflection rate is the time derivative of its
    /// penetration/deflection and the reported dissipation is the dampers' power. dV/dt by
    /// central differences along v (1 nm steps); tolerance 1e-7 of sum |Q_i v_i|.
    #[test]
    fn force_power_is_minus_energy_rate_minus_dissipation() {
        for clearance in [0.0, 2e-6] {
            let s = scene("idle", joints(1e9, 3e4, clearance), Initial::Rest);
            let m = CompliantModel::new(&s).unwrap();
            let (mut x, _) = m.full_initial_state();
            x[SUN] += 1e-3;
            x[CARRIER] += 2e-5;
            let mut v = vec![0.0; x.len()];
            v[CARRIER] = 50.0;
            v[SUN] = 3.0;
            for i in 0..m.cranks {
                let ci = crank_index(i);
                let fi = i as f64;
                x[ci] += 7e-6 * (fi + 1.0);
                x[ci + 1] -= 5e-6 * (fi - 0.7);
                x[ci + 2] += 2e-3 * (fi + 1.0);
                v[ci..ci + 3].copy_from_slice(&[0.03 * (fi - 1.0), -0.02, 4.0 - fi]);
            }
            for k in 0..2 {
                let dk = m.disc_index(k);
                let fk = k as f64;
                x[dk] += 6e-6;
                x[dk + 1] -= 4e-6 * (fk + 1.0);
                x[dk + 2] -= 2e-4;
                v[dk..dk + 3].copy_from_slice(&[0.01 - 0.02 * fk, 0.015, -0.2 + 0.5 * fk]);
            }
            let mut qf = vec![0.0; x.len()];
            let flows = m
                .forces(0.0, &x, &v, &mut qf, &mut Count::default())
                .unwrap();
            let power: f64 = qf.iter().zip(&v).map(|(q, w)| q * w).sum();
            let scale: f64 = qf.iter().zip(&v).map(|(q, w)| (q * w).abs()).sum();
            let h = 1e-9 / 4.5;
            let energy = |sign: f64| {
                let xs: Vec<f64> = x.iter().zip(&v).map(|(a, b)| a + sign * h * b).collect();
                let mut q = vec![0.0; x.len()];
                m.forces(0.0, &xs, &v, &mut q, &mut Count::default())
                    .unwrap()
                    .potential
            };
            let dvdt = (energy(1.0) - energy(-1.0)) / (2.0 * h);
            let gap = power + dvdt + flows.dissipation;
            assert!(flows.dissipation > 0.0);
            assert!(
                gap.abs() < 1e-7 * scale,
                "clearance {clearance}: power {power} + dV/dt {dvdt} + D {} = {gap} (scale {scale})",
                flows.dissipation
            );
        }
    }

    /// Very stiff bearings (1e11 N/m; damping 1e6 N s/m, a damping ratio of about 0.4 so the
    /// bearing modes the sudden load excites die within ~0.1 ms) reproduce the rigid model on the
    /// rated default scene started at steady speed: mean output speed (second half of 10 ms)
    /// within 1e-4, peak pin force over the run and every pin force at the end within 1 % (they
    /// agree to ~0.05 %); 1e12 N/m is closer still (the rigid model is the limit).
    #[test]
    fn stiff_bearings_reproduce_the_rigid_model() {
        let t_end = 0.01;
        let rigid = run(&scene("rated", Joints::Rigid, Initial::Steady), t_end, 1e-9);
        let f_rigid = series(&rigid, "pin_force");
        let n = f_rigid.len();
        let last = |f: &[f64]| f[n - 48..].to_vec();
        let mut errors = Vec::new();
        for (k, c) in [(1e11, 1e6), (1e12, 3e6)] {
            let r = run(
                &scene("rated", joints(k, c, 0.0), Initial::Steady),
                t_end,
                1e-9,
            );
            let f = series(&r, "pin_force");
            let speed = mean_speed(&r) / mean_speed(&rigid) - 1.0;
            assert!(
                speed.abs() < 1e-4,
                "k = {k}: mean output speed differs by {speed:e}"
            );
            let dpeak = peak(f) / peak(f_rigid) - 1.0;
            assert!(
                dpeak.abs() < 0.01,
                "k = {k}: peak pin force differs by {dpeak:e}"
            );
            let dlast = last(f)
                .iter()
                .zip(last(f_rigid))
                .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()))
                / peak(f_rigid);
            assert!(
                dlast < 0.01,
                "k = {k}: pin forces at the end differ by {dlast:e}"
            );
            errors.push(dpeak.abs() + dlast);
        }
        assert!(errors[1] < errors[0], "{errors:?}");
    }

    /// Default bearings at rated load (steady start): the disc centres stay on a circle of
    /// radius e within 1 % (the bearing deflections are tens of micrometres, mostly
    /// tangential), but they do leave the rigid path (the joints are compliant: > 1 um).
    #[test]
    fn disc_centre_path_radius_is_the_eccentricity() {
        let s = scene("rated", default_joints(), Initial::Steady);
        let r = run(&s, 0.01, 1e-9);
        let e = s.cycloid.eccentricity;
        let (c, alpha) = (series(&r, "disc_center"), series(&r, "crank_angle"));
        let (mut worst, mut off_rigid) = (0.0f64, 0.0f64);
        for (i, p) in c.chunks(4).enumerate() {
            for k in 0..2 {
                let (x, y) = (p[2 * k], p[2 * k + 1]);
                worst = worst.max((x.hypot(y) / e - 1.0).abs());
                // Rigid path: O_k = e (cos(alpha + a_k), sin(..)), alpha = mean crank angle.
                let a = alpha[3 * i..3 * i + 3].iter().sum::<f64>() / 3.0 + s.discs[k].phase;
                off_rigid = off_rigid.max((x - e * a.cos()).hypot(y - e * a.sin()));
            }
        }
        assert!(worst < 0.01, "disc path radius deviates by {worst:e} of e");
        assert!(off_rigid > 1e-6, "{off_rigid:e}");
    }

    /// The energy balance closes on damped runs (contact damping, bearing damping, a step
    /// start with its impact): |residual| < 1e-4 of the input work with dopri5 at atol 1e-10.
    /// Covers the prescribed sun, a torque drive on the sun, and a single-stage reducer whose
    /// cranks are the input (prescribed speed, or a torque shared by the cranks).
    fn rigid_cranks(k: f64, c: f64) -> Joints {
        Joints::Compliant {
            eccentric_bearing: Bearing {
                stiffness: k,
                damping: c,
                clearance: 0.0,
            },
            crank_bearing: None,
        }
    }

    #[test]
    fn rigid_crank_bearings_drop_the_crank_translations() {
        // 16 DOF with both families compliant, 10 with rigid crank bearings.
        let both = CompliantModel::new(&scene("rated", default_joints(), Initial::Rest)).unwrap();
        let ecc =
            CompliantModel::new(&scene("rated", rigid_cranks(1e9, 1e4), Initial::Rest)).unwrap();
        assert_eq!(both.dof(), 16);
        assert_eq!(ecc.dof(), 10);
        // With stiff eccentric bearings it is the rigid model again.
        let t_end = 0.01;
        let rigid = run(&scene("rated", Joints::Rigid, Initial::Steady), t_end, 1e-9);
        let stiff = run(
            &scene("rated", rigid_cranks(1e12, 3e6), Initial::Steady),
            t_end,
            1e-9,
        );
        let (fr, fs) = (series(&rigid, "pin_force"), series(&stiff, "pin_force"));
        let n = fr.len();
        let worst = fr[n - 48..]
            .iter()
            .zip(&fs[n - 48..])
            .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
        assert!(worst < 0.01 * peak(fr), "pin forces differ by {worst} N");
        let speed = mean_speed(&stiff) / mean_speed(&rigid) - 1.0;
        assert!(speed.abs() < 1e-4, "{speed:e}");
        // The energy balance closes with the crank mass moving with the carrier.
        let r = run(
            &scene("paper", rigid_cranks(1e9, 1e4), Initial::Rest),
            0.006,
            1e-10,
        );
        let (res, win) = last_residual(&r);
        assert!(
            res.abs() < 1e-4 * win.abs(),
            "residual {res:e} J of {win:e} J"
        );
    }

    #[test]
    fn energy_balance_closes() {
        let mut cases = vec![scene("paper", default_joints(), Initial::Rest)];
        let mut torque = scene("paper", default_joints(), Initial::Rest);
        torque.drive = Drive::Torque {
            torque: 800.0,
            ramp_time: 1e-3,
        };
        cases.push(torque);
        let mut single = scene("idle", default_joints(), Initial::Rest);
        single.stage1 = None;
        single.load = Load::Constant { torque: -2000.0 };
        single.drive = Drive::Speed {
            speed: 150.0,
            start: StartKind::Ramp,
            ramp_time: 2e-3,
        };
        cases.push(single.clone());
        single.drive = Drive::Torque {
            torque: 100.0,
            ramp_time: 1e-3,
        };
        single.load = Load::Constant { torque: 500.0 };
        cases.push(single);
        for s in &cases {
            let r = run(s, 0.006, 1e-10);
            let (res, win) = last_residual(&r);
            let dis = series(&r, "dissipated_energy")[r.samples - 1];
            eprintln!(
                "{:?}: residual {res:e} J of input work {win:e} J, dissipated {dis:e} J",
                s.drive
            );
            assert!(win.abs() > 1.0 && dis > 0.0, "{:?}: {win} {dis}", s.drive);
            assert!(
                res.abs() < 1e-4 * win.abs(),
                "{:?}: residual {res:e} J of input work {win:e} J",
                s.drive
            );
        }
    }

    /// With radial clearances (10 um eccentric, 5 um crank) and a step start from rest, the
    /// bearing contacts open and close many times; the state stays finite and the energy balance
    /// still closes (< 1e-4 of the input work).
    #[test]
    fn bearing_clearance_opens_and_closes() {
        let b = |k, c| Bearing {
            stiffness: k,
            damping: 1e4,
            clearance: c,
        };
        let s = scene(
            "idle",
            Joints::Compliant {
                eccentric_bearing: b(1e9, 10e-6),
                crank_bearing: Some(b(2e9, 5e-6)),
            },
            Initial::Rest,
        );
        let m = CompliantModel::new(&s).unwrap();
        let (q0, v0) = m.initial_state();
        let mut st = State::new(&m, 0.0, q0, v0).unwrap();
        let energy = |st: &State| {
            let o = m
                .observe(st.t, &st.q, &st.v, &mut Count::default())
                .unwrap();
            o.kinetic_energy + o.potential_energy
        };
        let e0 = energy(&st);
        let mut dp = Dopri5::new(1e-6, 1e-10, 1e-6, 2e-5);
        let nb = m.cranks * 3;
        let mut closed = vec![false; nb];
        let (mut opens, mut closes) = (vec![0; nb], vec![0; nb]);
        let t_end = 0.006;
        while st.t < t_end {
            dp.step(&m, &mut st, t_end).unwrap();
            assert!(st.q.iter().chain(&st.v).all(|v| v.is_finite()));
            let (x, _, _) = m.full(st.t, &st.q, &st.v);
            let (crank, ecc) = m.bearing_deflections(&x);
            for (i, d) in crank.iter().chain(&ecc).enumerate() {
                let c = if i < m.cranks { 5e-6 } else { 10e-6 };
                let now = d[0].hypot(d[1]) > c;
                closes[i] += usize::from(now && !closed[i]);
                opens[i] += usize::from(!now && closed[i]);
                closed[i] = now;
            }
        }
        eprintln!("opens {opens:?} closes {closes:?}");
        let crank_opens: usize = opens[..m.cranks].iter().sum();
        let ecc_opens: usize = opens[m.cranks..].iter().sum();
        assert!(
            crank_opens >= 3 && ecc_opens >= 6,
            "opens {opens:?} closes {closes:?}"
        );
        assert!(closes.iter().all(|&c| c >= 1), "closes {closes:?}");
        let residual = energy(&st) - e0 - st.work[0] + st.work[1] + st.work[2];
        eprintln!("clearance residual {residual:e} of {:e}", st.work[0]);
        assert!(
            residual.abs() < 1e-4 * st.work[0].abs(),
            "{residual:e} of {:e}",
            st.work[0]
        );
    }

    #[test]
    fn scenes_without_compliant_joints_are_refused() {
        let s = Scene::paper("idle").unwrap();
        let e = CompliantModel::new(&s).unwrap_err().to_string();
        assert!(e.contains("compliant"), "{e}");
        let s = scene("idle", joints(-1.0, 0.0, 0.0), Initial::Rest);
        assert!(CompliantModel::new(&s).is_err());
    }

    /// The kinematic initial state has undeflected bearings, and its steady-speed velocities
    /// keep them undeflected to first order (d' = 0).
    #[test]
    fn steady_initial_state_is_kinematic() {
        let s = scene("rated", default_joints(), Initial::Steady);
        let m = CompliantModel::new(&s).unwrap();
        let (x, v) = m.full_initial_state();
        let (crank, ecc) = m.bearing_deflections(&x);
        assert!(crank.iter().chain(&ecc).all(|d| d[0].hypot(d[1]) < 1e-15));
        let h = 1e-6;
        let xh: Vec<f64> = x.iter().zip(&v).map(|(a, b)| a + h * b).collect();
        let (crank, ecc) = m.bearing_deflections(&xh);
        let worst = crank
            .iter()
            .chain(&ecc)
            .fold(0.0f64, |a, d| a.max(d[0].hypot(d[1])));
        // Second order: e (zc w h)^2 / 2 ~ 8e-12 m.
        assert!(worst < 2e-11, "{worst:e}");
        let w = v[CARRIER] * 57.0 / crate::dynamics::scene::PAPER_INPUT_SPEED;
        assert!((w - 1.0).abs() < 1e-12);
    }
}
