//! Rigid-joint model in reduced coordinates (docs/model.md#coordinates-and-degrees-of-freedom).
//!
//! Coordinates `x = [th_c, alpha, th_s]`: carrier angle, absolute crank angle (all cranks equal
//! when the joints are ideal), sun angle. Disc `k` (eccentric phase `a_k`) has its centre at
//! `O_k = e (cos(alpha + a_k), sin(alpha + a_k))` and turns with the carrier,
//! `theta_k = th_c + delta_k`, `delta_k = -a_k / zc` (the half-lobe offset of the second disc).
//! The mass matrix is diagonal and constant in these coordinates:
//! `M_cc = J_c + J_load + n_cr m_cr r_cr^2 + sum J_d`, `M_aa = n_cr J_cr + sum m_d e^2`,
//! `M_ss = J_s`. Generalised forces come from virtual work: a pin force `-F N` at the profile
//! point `X` of disc `k` gives `Q_c = -F N.(z x (X - O_k))`, `Q_a = -F N.(z x O_k)`; a mesh
//! force `F` with deflection `delta = r_bs (th_s - th_c) + r_bp (alpha - th_c)` gives
//! `Q = -F grad(delta)`. Prescribed coordinates are taken from the drive; the reaction
//! `M_ii a_i - Q_i` on them is the input torque.

use crate::contact::law::{PinLaw, PinSite};
pub(crate) use crate::dynamics::model::parts::Parts;
use crate::dynamics::model::parts::{DiscModel, MeshOffset};
use crate::dynamics::model::pin_contact::{
    DiscPose, SeparationBound, WarmStart, penetration_error, pin_law_force, touching_pin,
};
use crate::dynamics::run::sink::ContactSink;
use crate::dynamics::scene::{Initial, Joints, Scene};
use crate::error::{Result, RvdynError};
use std::cell::Cell;

/// Index of the carrier angle in the full coordinate vector.
pub const CARRIER: usize = 0;
/// Index of the absolute crank angle.
pub const CRANK: usize = 1;
/// Index of the sun angle.
pub const SUN: usize = 2;
/// Index of the load angle (a coordinate only with an output shaft).
pub const LOAD: usize = 3;
/// Index of the motor angle (a coordinate only with a drive shaft).
pub const MOTOR: usize = 4;
/// Number of full coordinates `[th_c, alpha, th_s, th_L, th_m]`.
pub const FULL: usize = 5;

/// Generalised forces and power flows from one evaluation.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Forces {
    /// Generalised forces on `[th_c, alpha, th_s]` [N m] (the shafts' on the load and motor
    /// are added by the adapter).
    pub(crate) q: [f64; 3],
    /// Power dissipated by contact damping \[W\].
    pub(crate) dissipation: f64,
    /// Elastic energy stored in the contacts \[J\] (only when asked for).
    pub(crate) potential: f64,
    /// Friction power \[W\] (>= 0; part of `dissipation`) per family: pin/disc (or pin/housing
    /// for rolling pins), sun/planet teeth, bearings.
    pub(crate) friction: [f64; 3],
    /// Net load of the pins on each disc (at most 2): force \[N\] on the centre (fixed frame) and
    /// moment [N m] about it, friction and location terms included (for the joint reactions).
    pub(crate) disc_load: [[f64; 3]; 2],
}

/// The rigid-joint reducer model: the shared `Parts` plus its coordinates.
#[derive(Debug, Clone)]
pub struct RigidModel {
    /// Geometry, laws, inertias, drive and load (shared with the compliant model).
    pub(crate) parts: Parts,
    /// Diagonal generalised mass of `[th_c, alpha, th_s, th_L, th_m]`.
    pub(crate) mass: [f64; FULL],
    /// Free coordinates (indices into the full vector).
    pub(crate) free: Vec<usize>,
    /// Free shaft coordinates (`LOAD`, `MOTOR`; empty without shafts). The adapter's
    /// coordinates are `free` then these.
    pub(crate) shaft_free: Vec<usize>,
    /// The prescribed coordinate, if the drive is a speed.
    pub(crate) prescribed: Option<usize>,
    /// The coordinate the drive acts on (sun, or crank without a first stage).
    pub(crate) input: usize,
    /// Lever length per full coordinate [m per rad], turning angle errors into displacements.
    pub(crate) length_scale: [f64; FULL],
    /// Foot parameter of each (disc, pin) contact at the last evaluation (Newton warm start).
    pub(crate) warm_seeds: Vec<Cell<WarmStart>>,
    /// Skip the exact query of a pin that provably cannot touch (see [`SeparationBound`]).
    pub(crate) skip_separated: bool,
    separation: Vec<Cell<SeparationBound>>,
}

impl std::ops::Deref for RigidModel {
    type Target = Parts;
    fn deref(&self) -> &Parts {
        &self.parts
    }
}

impl RigidModel {
    /// Build the model of a validated scene.
    pub fn new(scene: &Scene) -> Result<Self> {
        scene.validate()?;
        if !matches!(scene.joints, Joints::Rigid) {
            return Err(RvdynError::Scene(
                "this model needs joints.kind = \"rigid\"; the compliant model is built by \
                 CompliantModel"
                    .into(),
            ));
        }
        let parts = Parts::new(scene)?;
        let cyc = scene.cycloid;
        let zp = cyc.pins as usize;
        let (inertias, mesh, crank_radius) = (parts.inertias, parts.mesh, parts.crank_radius);
        let n_cr = f64::from(scene.cranks);
        let e = cyc.eccentricity;
        let nd = parts.discs.len() as f64;
        // The load and motor inertias join the carrier and the sun unless a shaft separates
        // them (docs/model.md#machine-shafts).
        let (on_carrier, on_sun) = (
            if parts.output_shaft.is_some() {
                0.0
            } else {
                inertias.load_inertia
            },
            if parts.input_shaft.is_some() {
                0.0
            } else {
                inertias.motor_inertia
            },
        );
        let mass = [
            inertias.carrier.inertia
                + on_carrier
                + n_cr * inertias.crank.mass * crank_radius * crank_radius
                + nd * inertias.disc.inertia,
            n_cr * inertias.crank.inertia + nd * inertias.disc.mass * e * e,
            inertias.sun.inertia + on_sun,
            inertias.load_inertia,
            inertias.motor_inertia,
        ];
        let mut input = if mesh.is_some() { SUN } else { CRANK };
        let (mut free, mut prescribed) = match (parts.drive.is_speed(), mesh.is_some()) {
            (true, true) => (vec![CARRIER, CRANK], Some(SUN)),
            (false, true) => (vec![CARRIER, CRANK, SUN], None),
            (true, false) => (vec![CARRIER], Some(CRANK)),
            (false, false) => (vec![CARRIER, CRANK], None),
        };
        let mut shaft_free = Vec::new();
        if parts.output_shaft.is_some() {
            shaft_free.push(LOAD);
        }
        if parts.input_shaft.is_some() {
            // The drive acts on the motor; the sun becomes free.
            if let Some(p) = prescribed {
                free.push(p);
                prescribed = Some(MOTOR);
            } else {
                shaft_free.push(MOTOR);
            }
            input = MOTOR;
        }
        let rp = cyc.pin_circle_radius;
        let rs = mesh.map_or(0.0, |m| m.sun_base_radius);
        let length_scale = [rp, e, rs, rp, rs];
        let skip = parts.discs.iter().all(|d| d.profile_error.is_none());
        Ok(Self {
            parts,
            mass,
            free,
            shaft_free,
            prescribed,
            input,
            length_scale,
            warm_seeds: vec![Cell::new(WarmStart::default()); scene.discs.len() * zp],
            // The separation bound assumes a rigid profile; a profile error's first-order offset
            // is not one: query every pin.
            skip_separated: skip,
            separation: vec![Cell::new(SeparationBound::default()); scene.discs.len() * zp],
        })
    }

    /// Initial full state `(x, v)` at t = 0: kinematic pose, at rest or at kinematic speed
    /// (shafts untwisted).
    pub(crate) fn initial_state(&self) -> ([f64; FULL], [f64; FULL]) {
        let x = [0.0; FULL];
        let mut v = [0.0; FULL];
        if self.initial == Initial::Steady {
            let w_in = self.drive.full_speed();
            let zc = self.zc();
            let carrier = w_in / self.ratio;
            let sun = if self.mesh.is_some() { w_in } else { 0.0 };
            v = [carrier, -zc * carrier, sun, carrier, sun];
        }
        if let Some(p) = self.prescribed {
            let (ang, spd, _) = self.drive.motion(0.0);
            let mut x = x;
            x[p] = ang;
            v[p] = spd;
            return (x, v);
        }
        (x, v)
    }

    /// Overwrite the prescribed coordinate of a full state with the drive at time `t`;
    /// returns its acceleration.
    #[inline]
    pub(crate) fn apply_drive(&self, t: f64, x: &mut [f64; FULL], v: &mut [f64; FULL]) -> f64 {
        match self.prescribed {
            Some(p) => {
                let (ang, spd, acc) = self.drive.motion(t);
                x[p] = ang;
                v[p] = spd;
                acc
            }
            None => 0.0,
        }
    }

    /// Disc `k` centre \[m\] and angle \[rad\] for the full coordinates `x` (as the force
    /// evaluation places it; for tests).
    #[cfg(test)]
    pub(crate) fn disc_pose(&self, k: usize, x: &[f64; 3]) -> ([f64; 2], f64) {
        let d = &self.discs[k];
        (
            self.disc_centre(d, x[CRANK].sin_cos()),
            x[CARRIER] + d.angle_offset,
        )
    }

    /// The centre \[m\] of disc `d` from the sine and cosine of the crank angle, turned by the
    /// disc's phase (one `sin_cos` per evaluation instead of one per disc).
    #[inline]
    pub(crate) fn disc_centre(&self, d: &DiscModel, (sa, ca): (f64, f64)) -> [f64; 2] {
        let [cp, sp] = d.phase_cs;
        let e = self.eccentricity;
        [e * (ca * cp - sa * sp), e * (sa * cp + ca * sp)]
    }

    /// The pose of disc `d` for the full coordinates `x`, from the sine and cosine of the crank
    /// and of the carrier angle (the disc's are those turned by its phase and angle offset).
    #[inline]
    fn disc_pose_sc(
        &self,
        d: &DiscModel,
        x: &[f64; 3],
        crank: (f64, f64),
        (st, ct): (f64, f64),
    ) -> DiscPose {
        let [co, so] = d.offset_cs;
        DiscPose {
            centre: self.disc_centre(d, crank),
            angle: x[CARRIER] + d.angle_offset,
            sin: st * co + ct * so,
            cos: ct * co - st * so,
        }
    }

    /// Generalised forces at `(t, x, v)` (full coordinates), reporting every contact to `sink`.
    ///
    /// Fails with `SimulationError` if a state is not finite or a penetration exceeds the
    /// physical bound or an exact gap cannot be found (the disc is far from any sensible pose).
    pub(crate) fn forces<S: ContactSink>(
        &self,
        t: f64,
        x: &[f64; 3],
        v: &[f64; 3],
        sink: &mut S,
    ) -> Result<Forces> {
        let mut out = Forces::default();
        let want_energy = sink.wants_energy();
        let check = sink.checks_bounds();
        let vc = v[CARRIER];
        let va = v[CRANK];
        let (crank, carrier) = (x[CRANK].sin_cos(), x[CARRIER].sin_cos());
        for (k, d) in self.discs.iter().enumerate() {
            let pose = self.disc_pose_sc(d, x, crank, carrier);
            let o = pose.centre;
            for (j, pin) in self.pins.iter().enumerate() {
                let idx = k * self.pins.len() + j;
                let sep = self
                    .skip_separated
                    .then(|| (&self.separation[idx], self.profile_reach));
                let bound = check.then_some(self.max_penetration);
                let warm = &self.warm_seeds[idx];
                let Some(pc) = touching_pin(d, pin, &pose, t, (k, j), warm, sep, bound)? else {
                    sink.pin(k, j, 0.0, 0.0, 0.0, [0.0; 2], [0.0; 2]);
                    continue;
                };
                let pen = pc.penetration;
                // Levers of the normal about the disc centre (carrier DOF) and about the axis
                // through O_k (crank DOF).
                let n = pc.normal;
                let lever_c = pc.lever();
                let lever_a = o[0] * n[1] - o[1] * n[0];
                let mut pen_rate = lever_c * vc + lever_a * va;
                // A profile error's share of the penetration moves with the foot:
                // d/dth_c = g_theta, d/dalpha = g_O . (z x O).
                let err_lever = pc
                    .error_gradient
                    .map(|(go, gt)| (gt, go[1] * o[0] - go[0] * o[1]));
                if let Some((ec, ea)) = err_lever {
                    pen_rate += ec * vc + ea * va;
                }
                let site = PinSite {
                    geometry: &d.geometry,
                    phi: pc.phi,
                    pin_radius: pin.radius,
                    depth: d.body_depth,
                };
                let lf =
                    pin_law_force(&self.pin_law, pen, pen_rate, &site, want_energy, warm, None)?;
                let f = lf.force;
                out.q[CARRIER] -= f * lever_c;
                out.q[CRANK] -= f * lever_a;
                let dl = &mut out.disc_load[k];
                dl[0] -= f * n[0];
                dl[1] -= f * n[1];
                dl[2] -= f * lever_c;
                if let Some((ec, ea)) = err_lever {
                    out.q[CARRIER] -= f * ec;
                    out.q[CRANK] -= f * ea;
                    let (go, gt) = pc.error_gradient.unwrap_or_default();
                    let dl = &mut out.disc_load[k];
                    dl[0] -= f * go[0];
                    dl[1] -= f * go[1];
                    dl[2] -= f * gt;
                }
                // Sliding friction: the disc's material point at the contact moves at
                // O' + th' z x arm (O' = alpha' z x O); the force ft t (t = z x n) on the disc
                // has the virtual work ft (arm . n) on th_c and ft (O . n) on alpha.
                if let Some(fr) = &self.pin_friction {
                    let arm = pc.arm;
                    let vx = [-o[1] * va - vc * arm[1], o[0] * va + vc * arm[0]];
                    let vs = n[0] * vx[1] - n[1] * vx[0];
                    let ft = fr.force(vs, f);
                    out.q[CARRIER] += ft * (arm[0] * n[0] + arm[1] * n[1]);
                    out.q[CRANK] += ft * (o[0] * n[0] + o[1] * n[1]);
                    let dl = &mut out.disc_load[k];
                    dl[0] -= ft * n[1];
                    dl[1] += ft * n[0];
                    dl[2] += ft * (arm[0] * n[0] + arm[1] * n[1]);
                    let p = -ft * vs;
                    out.dissipation += p;
                    out.friction[0] += p;
                }
                // Location term of a line law (its energy depends on the contact's place on
                // the profile): dO/dalpha = z x O, dtheta/dth_c = 1. (Tested for the law here,
                // not in the call: the IMPACT law's evaluations then skip the call.)
                if matches!(self.pin_law, PinLaw::Line { .. })
                    && let Some(ls) = self.pin_law.location_slope_at(
                        lf.elastic,
                        &site,
                        pin.centre,
                        o,
                        (pose.sin, pose.cos),
                    )
                {
                    let (fo, m) = ls.forces();
                    out.q[CARRIER] += m;
                    out.q[CRANK] += fo[1] * o[0] - fo[0] * o[1];
                    let dl = &mut out.disc_load[k];
                    dl[0] += fo[0];
                    dl[1] += fo[1];
                    dl[2] += m;
                }
                out.dissipation += (f - lf.elastic) * pen_rate;
                out.potential += lf.energy;
                let point = [o[0] + pc.arm[0], o[1] + pc.arm[1]];
                sink.pin(k, j, f, pen, -f * lever_c, point, n);
            }
        }
        if let Some(m) = &self.mesh {
            let delta = m.sun_base_radius * (x[SUN] - x[CARRIER])
                + m.planet_base_radius * (x[CRANK] - x[CARRIER]);
            let rate = m.sun_base_radius * (v[SUN] - vc) + m.planet_base_radius * (va - vc);
            // The part of `s_i = r_bs (th_s - th_c) - gamma_i p_b` shared by all planets
            // (docs/model.md, "The ISO mesh in the dynamic models").
            let s0 = m.sun_base_radius * (x[SUN] - x[CARRIER]);
            let half = 0.5 * m.backlash;
            // Drive flank (delta > half) or coast flank (delta < -half): the same base
            // circles, so in this torsional model the coast flank is the mirror image.
            let (pen, pen_rate, sign) = if delta > half {
                (delta - half, rate, 1.0)
            } else if delta < -half {
                (-delta - half, -rate, -1.0)
            } else {
                (0.0, 0.0, 0.0)
            };
            for i in 0..m.count {
                let mut f_report = 0.0;
                let mut delta_report = delta;
                // Without gear errors one flank at most, shared by all planets; with errors
                // each flank of each planet has its own extra approach (runout, pitch).
                let mut flanks = [(pen, pen_rate, sign, MeshOffset::default()); 2];
                let nf = match &self.mesh_errors {
                    None => 1,
                    Some(me) => {
                        for (slot, sg) in flanks.iter_mut().zip([1.0, -1.0]) {
                            let off = me.offset(i, sg, x[CARRIER], x[SUN], x[CRANK]);
                            *slot = (
                                sg * delta + off.value - half,
                                sg * rate + off.rate(vc, v[SUN], va),
                                sg,
                                off,
                            );
                            if sg > 0.0 {
                                delta_report = delta + off.value;
                            }
                        }
                        2
                    }
                };
                for &(pen, pen_rate, sign, off) in &flanks[..nf] {
                    let mut f = 0.0;
                    if pen > 0.0 {
                        if check && (pen.is_nan() || pen >= self.max_penetration) {
                            return Err(penetration_error(
                                t,
                                pen,
                                self.max_penetration,
                                "a sun/planet mesh",
                            ));
                        }
                        // The coast flank (sign -1) runs through its tooth pairs in the mirrored
                        // order: its mesh position is -s.
                        let s_flank = sign * (s0 - m.phases[i] * m.base_pitch);
                        let (lf, dk) = m.law.evaluate(pen, pen_rate, s_flank, want_energy);
                        f = sign * lf.force;
                        out.q[CARRIER] += f * (m.sun_base_radius + m.planet_base_radius);
                        out.q[CRANK] -= f * m.planet_base_radius;
                        out.q[SUN] -= f * m.sun_base_radius;
                        // Gear errors: -F grad(E) (zero without them).
                        if self.mesh_errors.is_some() {
                            out.q[CARRIER] -= lf.force * off.carrier;
                            out.q[SUN] -= lf.force * off.sun;
                            out.q[CRANK] -= lf.force * off.crank;
                        }
                        // A stiffness that varies with the mesh position s stores
                        // V = k(s) pen^2 / 2; its s-derivative is a generalised force too
                        // (ds/dth_s = r_bs, ds/dth_c = -r_bs), which keeps the energy balance
                        // (Oh, Grosh & Barber 2005).
                        let dv_ds = 0.5 * dk * pen * pen * sign;
                        out.q[SUN] -= dv_ds * m.sun_base_radius;
                        out.q[CARRIER] += dv_ds * m.sun_base_radius;
                        out.dissipation += (lf.force - lf.elastic) * pen_rate;
                        out.potential += lf.energy;
                        // Tooth friction (mirrored on the coast flank like the mesh position).
                        if let Some(fr) = &self.mesh_friction {
                            let w1 = sign * (v[SUN] - vc);
                            let w2 = sign * (va - vc);
                            let (t1, t2, p) = m.path.torques(fr, lf.force, s_flank, w1, w2);
                            out.q[SUN] += sign * t1;
                            out.q[CRANK] += sign * t2;
                            out.q[CARRIER] -= sign * (t1 + t2);
                            out.dissipation += p;
                            out.friction[1] += p;
                        }
                    }
                    f_report += f;
                }
                sink.mesh(i, f_report, delta_report);
            }
        }
        out.q[CARRIER] -= self.carrier_load(t);
        if let Some(tq) = self.input_drive_torque(t) {
            out.q[self.input] += tq;
        }
        if !out.q.iter().all(|v| v.is_finite()) {
            return Err(RvdynError::Simulation(format!(
                "non-finite generalised force at t = {t:.6e} s: the integration has diverged; \
                 reduce the step (dt) or the tolerances, or use the implicit integrator"
            )));
        }
        Ok(out)
    }

    /// Reactions of the ideal eccentric bearings on the discs \[N\], at `i * discs + k` (crank
    /// `i`, disc `k`; fixed frame), from each disc's balance with the pins at the state
    /// `(x, v)` with accelerations `a` (docs/model.md#bearing-reactions-of-ideal-joints): the net
    /// reaction `R = m_d O'' - F_pins` and moment `M = J_d theta'' - M_pins` split over the
    /// cranks as equal isotropic bearings share them, `R_i = R / n + M (z x h_i) / sum |h|^2`
    /// (`h_i` the hole centres from the disc centre; the split of a redundant support is not
    /// given by the rigid constraints alone).
    pub(crate) fn eccentric_reactions(
        &self,
        x: &[f64],
        v: &[f64],
        a: &[f64],
        f: &Forces,
    ) -> Vec<[f64; 2]> {
        let n = self.cranks;
        let nd = self.discs.len();
        let md = self.inertias.disc;
        let e = self.eccentricity;
        let mut out = vec![[0.0; 2]; n * nd];
        let h2 = n as f64 * self.crank_radius * self.crank_radius;
        for (k, d) in self.discs.iter().enumerate() {
            let (sb, cb) = (x[CRANK] + d.phase).sin_cos();
            let (w, dw) = (v[CRANK], a[CRANK]);
            let acc = [e * (-sb * dw - cb * w * w), e * (cb * dw - sb * w * w)];
            let dl = f.disc_load[k];
            let r = [md.mass * acc[0] - dl[0], md.mass * acc[1] - dl[1]];
            let mr = md.inertia * a[CARRIER] - dl[2];
            for i in 0..n {
                let g = std::f64::consts::TAU * i as f64 / n as f64 + x[CARRIER];
                let (sg, cg) = g.sin_cos();
                // z x h_i / sum |h|^2, h_i = r_cr (cos g, sin g).
                let t = [-sg * self.crank_radius / h2, cg * self.crank_radius / h2];
                out[i * nd + k] = [r[0] / n as f64 + mr * t[0], r[1] / n as f64 + mr * t[1]];
            }
        }
        out
    }

    /// Reactions of the ideal crank (main) bearings on the cranks \[N\] (fixed frame), from each
    /// crank's balance (docs/model.md#bearing-reactions-of-ideal-joints):
    /// `B_i = m_cr p_i'' + sum_k R_ik - F_mesh,i`, with the crank centre's acceleration
    /// `p_i'' = r_cr ((z x u_i) th_c'' - u_i th_c'^2)` (`u_i` the crank's direction; the
    /// carrier's kinematics), `R_ik` the eccentric reactions on the discs
    /// ([`RigidModel::eccentric_reactions`], index `i * discs + k`) and the mesh force on planet
    /// `i`: `|f| sin(pa) u_i + f cos(pa) (z x u_i)` for the signed force `f` along the line of
    /// action (positive on the drive flank; `mesh_force`, one per crank, empty without a first
    /// stage). Tooth friction (torques only in this model) is not included.
    pub(crate) fn crank_reactions(
        &self,
        x: &[f64],
        v: &[f64],
        a: &[f64],
        eccentric: &[[f64; 2]],
        mesh_force: &[f64],
    ) -> Vec<[f64; 2]> {
        let n = self.cranks;
        let nd = self.discs.len();
        let mc = self.inertias.crank.mass;
        let r = self.crank_radius;
        // Pressure angle from the line of action's length between the tangency points,
        // `T1T2 = (r_bs + r_bp) tan(pa)`.
        let (sp, cp) = match &self.mesh {
            Some(mm) => (mm.path.t1t2 / (mm.sun_base_radius + mm.planet_base_radius))
                .atan()
                .sin_cos(),
            None => (0.0, 0.0),
        };
        (0..n)
            .map(|i| {
                let g = std::f64::consts::TAU * i as f64 / n as f64 + x[CARRIER];
                let (sg, cg) = g.sin_cos();
                let (u, zu) = ([cg, sg], [-sg, cg]);
                let (w, dw) = (v[CARRIER], a[CARRIER]);
                let mut b = [
                    mc * r * (zu[0] * dw - u[0] * w * w),
                    mc * r * (zu[1] * dw - u[1] * w * w),
                ];
                for e in &eccentric[i * nd..(i + 1) * nd] {
                    b[0] += e[0];
                    b[1] += e[1];
                }
                let f = mesh_force.get(i).copied().unwrap_or(0.0);
                b[0] -= f.abs() * sp * u[0] + f * cp * zu[0];
                b[1] -= f.abs() * sp * u[1] + f * cp * zu[1];
                b
            })
            .collect()
    }

    /// Kinetic energy of the free bodies \[J\] (the prescribed input is a driver, not counted).
    pub(crate) fn kinetic_energy(&self, v: &[f64; FULL]) -> f64 {
        (0..FULL)
            .filter(|i| {
                Some(*i) != self.prescribed
                    && (*i != SUN || self.mesh.is_some())
                    && (*i != LOAD || self.output_shaft.is_some())
                    && (*i != MOTOR || self.input_shaft.is_some())
            })
            .map(|i| 0.5 * self.mass[i] * v[i] * v[i])
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::model::rigid_system::RigidSystem;
    use crate::dynamics::run::sink::NoSink;
    use crate::solve::State;
    use crate::solve::generalized_alpha::GeneralizedAlpha;

    #[test]
    fn skipping_separated_pins_gives_the_same_forces() {
        // Along a loaded trajectory (with a modified profile, so that many pins are clear),
        // the model that skips separated pins and a fresh one that queries every pin must give
        // the same generalised forces at every state, also at states off the trajectory.
        // Steps of 1 ms move the discs farther than most gaps (the open test of the queries,
        // `pin_query_or_open`, then does the skipping); 0.1 ms steps leave it to the
        // pose-based bound.
        let mut scene = Scene::paper("rated").unwrap();
        scene.cycloid.d_rrp = 2e-5;
        scene.cycloid.d_rp = -2e-5;
        let mut fresh = RigidModel::new(&scene).unwrap();
        fresh.skip_separated = false;
        let mut worst: f64 = 0.0;
        let mut scale: f64 = 0.0;
        for (dt, steps) in [(1e-4, 300), (1e-3, 150)] {
            let skipping = RigidModel::new(&scene).unwrap();
            let sys = RigidSystem::new(&skipping);
            let (q, v) = {
                use crate::dynamics::model::ReducerModel;
                sys.initial_state()
            };
            let mut st = State::new(&sys, 0.0, q, v).unwrap();
            let mut ga = GeneralizedAlpha::new(0.8, 1e-9, false).unwrap();
            for step in 0..steps {
                ga.step(&sys, &mut st, dt).unwrap();
                for wobble in [0.0, 3e-6, -2e-5] {
                    let (x5, xv5, _) = sys.full(st.t, &st.q, &st.v);
                    let mut x = [x5[0], x5[1], x5[2]];
                    let xv = [xv5[0], xv5[1], xv5[2]];
                    x[CARRIER] += wobble * ((step % 7) as f64 - 3.0);
                    let a = skipping.forces(st.t, &x, &xv, &mut NoSink).unwrap();
                    let b = fresh.forces(st.t, &x, &xv, &mut NoSink).unwrap();
                    for i in 0..3 {
                        worst = worst.max((a.q[i] - b.q[i]).abs());
                        scale = scale.max(b.q[i].abs());
                    }
                }
            }
        }
        assert!(
            worst <= 1e-9 * scale,
            "skip changes the forces by {worst:e} of {scale:e}"
        );
    }
}
