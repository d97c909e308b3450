//! The generalised forces of the compliant model: bearings, first-stage meshes, pin contacts,
//! load and drive (docs/model.md#compliant-joint-model).

use super::{CARRIER, CompliantModel, Flows, SUN, crank_index};
use crate::contact::law::{PinLaw, PinSite};
use crate::contact::pin_tangent::{centre_curve_derivatives, curvature_derivatives_of};
use crate::dynamics::model::pin_contact::{
    DiscPose, penetration_error, pin_law_force, touching_pin,
};
use crate::dynamics::model::vec2::{add, cross, dot, perp, rotate, scaled, sub};
use crate::dynamics::run::sink::ContactSink;
use crate::error::{Result, RvdynError};

/// Most discs a bending crank carries (a scene has one or two).
const MAX_BENDING_DISCS: usize = 2;

impl CompliantModel {
    /// Generalised forces `qf` on every full coordinate at `(t, x, v)`, reporting every
    /// contact to `sink`.
    ///
    /// Fails with `SimulationError` if a force is not finite or a penetration exceeds the
    /// physical bound or an exact gap cannot be found (the disc is far from any sensible pose).
    pub(crate) fn forces<S: ContactSink>(
        &self,
        t: f64,
        x: &[f64],
        v: &[f64],
        qf: &mut [f64],
        sink: &mut S,
    ) -> Result<Flows> {
        let m = &self.parts;
        let nd = m.discs.len();
        let want_energy = sink.wants_energy();
        let mut out = Flows::default();
        qf.fill(0.0);
        let (thc, vc) = (x[CARRIER], v[CARRIER]);
        for (i, seat) in self.seats.iter().enumerate() {
            let ci = crank_index(i);
            let u = rotate(thc, *seat);
            // Nominal seat (the mesh geometry) and actual seat (with its error: the bearing).
            let s = scaled(m.crank_radius, u);
            let s_v = scaled(vc, perp(s));
            let s_act = rotate(thc, self.seat_vecs[i]);
            let p = [x[ci], x[ci + 1]];
            let pv = [v[ci], v[ci + 1]];
            let (alpha, va) = (x[ci + 2], v[ci + 2]);
            let d = sub(p, s);
            let dd = sub(pv, s_v);
            // Crank bearing: force on the crank centre, reaction on the carrier at s_i.
            if let Some(cb) = &self.crank_bearing {
                let b = cb.load(sub(p, s_act), sub(pv, scaled(vc, perp(s_act))));
                sink.bearing(0, i, b.force);
                qf[ci] += b.force[0];
                qf[ci + 1] += b.force[1];
                qf[CARRIER] -= cross(s_act, b.force);
                out.dissipation += b.dissipation;
                out.potential += b.energy;
                if let Some([_, (pf, w_reg)]) = &self.bearing_friction {
                    // Friction torque against the crank's rotation relative to the carrier.
                    let w = va - vc;
                    let m =
                        pf.torque_unchecked(w, dot(b.force, b.force).sqrt()) * (w / w_reg).tanh();
                    qf[ci + 2] -= m;
                    qf[CARRIER] += m;
                    out.dissipation += m * w;
                    out.friction[2] += m * w;
                }
            }
            // Eccentric bearings: force on the disc at H, opposite on the crank at E (or on the
            // eccentric's own centre when the crank bends, see below).
            let mut eccs = [[0.0; 2]; MAX_BENDING_DISCS];
            for (k, disc) in m.discs.iter().enumerate() {
                let dk = self.disc_index(k);
                let (sa, ca) = (alpha + disc.phase + self.ecc_phase[i]).sin_cos();
                let ecc = [self.ecc_radius[i] * ca, self.ecc_radius[i] * sa];
                eccs[k] = ecc;
                let node = self.bending.as_ref().map(|_| self.node_index(i, k));
                let (e_pos, e_v) = match node {
                    Some(ni) => ([x[ni], x[ni + 1]], [v[ni], v[ni + 1]]),
                    None => (add(p, ecc), add(pv, scaled(va, perp(ecc)))),
                };
                let o = [x[dk], x[dk + 1]];
                let ov = [v[dk], v[dk + 1]];
                let arm = rotate(x[dk + 2], self.holes[i * nd + k]);
                let h = add(o, arm);
                let h_v = add(ov, scaled(v[dk + 2], perp(arm)));
                let b = self.eccentric_bearing.load(sub(h, e_pos), sub(h_v, e_v));
                let f = b.force;
                sink.bearing(1, i * nd + k, f);
                qf[dk] += f[0];
                qf[dk + 1] += f[1];
                qf[dk + 2] += cross(arm, f);
                if let Some(ni) = node {
                    qf[ni] -= f[0];
                    qf[ni + 1] -= f[1];
                } else {
                    qf[ci] -= f[0];
                    qf[ci + 1] -= f[1];
                    qf[ci + 2] -= cross(ecc, f);
                }
                out.dissipation += b.dissipation;
                out.potential += b.energy;
                if let Some([(pf, w_reg), _]) = &self.bearing_friction {
                    // Friction torque against the eccentric's rotation relative to the disc.
                    let w = va - v[dk + 2];
                    let m = pf.torque_unchecked(w, dot(f, f).sqrt()) * (w / w_reg).tanh();
                    qf[ci + 2] -= m;
                    qf[dk + 2] += m;
                    out.dissipation += m * w;
                    out.friction[2] += m * w;
                }
            }
            // Crank bending: each eccentric centre is tied to where the straight crank puts
            // it, `u_k = w_k - (p + ecc_k)`, by the shaft's stiffness (the same in x and y);
            // the reaction goes to the crank at that point. No damping of its own.
            if let Some(bend) = &self.bending {
                let mut u = [[0.0; 2]; MAX_BENDING_DISCS];
                for (k, uk) in u.iter_mut().enumerate().take(nd) {
                    let ni = self.node_index(i, k);
                    *uk = sub([x[ni], x[ni + 1]], add(p, eccs[k]));
                }
                for k in 0..nd {
                    let mut fk = [0.0; 2];
                    for (l, ul) in u.iter().enumerate().take(nd) {
                        let kk = bend.stiffness[k * nd + l];
                        fk[0] += kk * ul[0];
                        fk[1] += kk * ul[1];
                    }
                    let ni = self.node_index(i, k);
                    qf[ni] -= fk[0];
                    qf[ni + 1] -= fk[1];
                    qf[ci] += fk[0];
                    qf[ci + 1] += fk[1];
                    qf[ci + 2] += cross(eccs[k], fk);
                    out.potential += 0.5 * dot(u[k], fk);
                    sink.crank_deflection(i * nd + k, u[k]);
                }
            }
            // Sun/planet mesh i. The sun pushes planet i along w_i = sin(pa) u_i + cos(pa)
            // z x u_i on the drive flank and along sin(pa) u_i - cos(pa) z x u_i on the coast
            // flank: both push the planet away from the sun. Each flank has its own
            // deflection, `sign * rot - d . w` (sign +1 drive, -1 coast), so a radial approach
            // of the planet closes both flanks and a reversed run mirrors a forward one.
            if let Some(mm) = &m.mesh {
                let [sp, cp] = self.pressure;
                let zu = perp(u);
                let (rbs, rbp) = (mm.sun_base_radius, mm.planet_base_radius);
                let rot = rbs * (x[SUN] - thc) + rbp * (alpha - thc);
                let rot_rate = rbs * (v[SUN] - vc) + rbp * (va - vc);
                let s_mesh = rbs * (x[SUN] - thc) - mm.phases[i] * mm.base_pitch;
                let half = 0.5 * mm.backlash;
                let w_drive = [sp * u[0] + cp * zu[0], sp * u[1] + cp * zu[1]];
                let w_coast = [sp * u[0] - cp * zu[0], sp * u[1] - cp * zu[1]];
                let mut f_report = 0.0;
                let (mut e_drive, mut e_coast) = (0.0, 0.0);
                for (sign, w) in [(1.0, w_drive), (-1.0, w_coast)] {
                    let zw = perp(w);
                    let mut pen = sign * rot - dot(d, w) - half;
                    // Gear errors (runout, pitch): an extra approach E(th_c, th_s, alpha_i).
                    let off = m
                        .mesh_errors
                        .as_ref()
                        .map(|me| me.offset(i, sign, thc, x[SUN], alpha));
                    if let Some(off) = &off {
                        pen += off.value;
                        if sign > 0.0 {
                            e_drive = off.value;
                        } else {
                            e_coast = off.value;
                        }
                    }
                    if pen <= 0.0 {
                        continue;
                    }
                    if sink.checks_bounds() && (pen.is_nan() || pen >= m.max_penetration) {
                        return Err(penetration_error(
                            t,
                            pen,
                            m.max_penetration,
                            &format!("sun/planet mesh {i}"),
                        ));
                    }
                    let mut rate = sign * rot_rate - dot(dd, w) - vc * dot(d, zw);
                    if let Some(off) = &off {
                        rate += off.rate(vc, v[SUN], va);
                    }
                    // The coast flank runs through its tooth pairs in the mirrored order:
                    // its mesh position is -s (a reversed run mirrors a forward one).
                    let (lf, dk) = mm.law.evaluate(pen, rate, sign * s_mesh, want_energy);
                    let f = lf.force;
                    // Q = -F grad(pen); d(pen)/d(th_c) includes ds_i/dth_c = z x s_i and
                    // dw/dth_c = z x w.
                    qf[SUN] -= f * sign * rbs;
                    qf[ci + 2] -= f * sign * rbp;
                    qf[ci] += f * w[0];
                    qf[ci + 1] += f * w[1];
                    qf[CARRIER] += f * (sign * (rbs + rbp) - dot(perp(s), w) + dot(d, zw));
                    if let Some(off) = &off {
                        qf[CARRIER] -= f * off.carrier;
                        qf[SUN] -= f * off.sun;
                        qf[ci + 2] -= f * off.crank;
                    }
                    // Position-dependent stiffness: dV/ds with ds/dth_s = r_bs,
                    // ds/dth_c = -r_bs (Oh, Grosh & Barber 2005).
                    let dv_ds = 0.5 * dk * pen * pen * sign;
                    qf[SUN] -= dv_ds * rbs;
                    qf[CARRIER] += dv_ds * rbs;
                    out.dissipation += (lf.force - lf.elastic) * rate;
                    out.potential += lf.energy;
                    // Tooth friction: torques on sun, planet and carrier (the rigid model's
                    // law; the friction force on the planet centre is not applied).
                    if let Some(fr) = &m.mesh_friction {
                        let w1 = sign * (v[SUN] - vc);
                        let w2 = sign * (va - vc);
                        let (t1, t2, p) = mm.path.torques(fr, f, sign * s_mesh, w1, w2);
                        qf[SUN] += sign * t1;
                        qf[ci + 2] += sign * t2;
                        qf[CARRIER] -= sign * (t1 + t2);
                        out.dissipation += p;
                        out.friction[1] += p;
                    }
                    f_report += sign * f;
                }
                // The loaded flank's approach, signed as its force (negative on the coast
                // flank, along its own line of action): a reversed run mirrors a forward one.
                let deflection = if f_report < 0.0 {
                    rot + dot(d, w_coast) - e_coast
                } else {
                    rot - dot(d, w_drive) + e_drive
                };
                sink.mesh(i, f_report, deflection);
            }
        }
        for (k, disc) in m.discs.iter().enumerate() {
            let dk = self.disc_index(k);
            let o = [x[dk], x[dk + 1]];
            let ov = [v[dk], v[dk + 1]];
            let (th, vt) = (x[dk + 2], v[dk + 2]);
            let pose = DiscPose::new(o, th);
            for (j, pin) in m.pins.iter().enumerate() {
                let idx = k * m.pins.len() + j;
                let sep = self
                    .skip_separated
                    .then(|| (&self.separation[idx], m.profile_reach));
                let bound = sink.checks_bounds().then_some(m.max_penetration);
                let warm = &self.warm_seeds[idx];
                let Some(pc) = touching_pin(disc, pin, &pose, t, (k, j), warm, sep, bound)? else {
                    sink.pin(k, j, 0.0, 0.0, 0.0, [0.0; 2], [0.0; 2]);
                    continue;
                };
                let pen = pc.penetration;
                let n = pc.normal;
                let lever = pc.lever();
                let pen_rate = dot(n, ov) + vt * lever + pc.error_rate(ov, vt);
                let site = PinSite {
                    geometry: &disc.geometry,
                    phi: pc.phi,
                    pin_radius: pin.radius,
                    depth: disc.body_depth,
                };
                // The line law's curvature, and its slope for the location term, from one set
                // of curve derivatives at the contact.
                let line = matches!(m.pin_law, PinLaw::Line { .. }).then(|| {
                    let d = centre_curve_derivatives(&disc.geometry, pc.phi);
                    let [kc, dkc, _] = curvature_derivatives_of(&d);
                    (d, [kc, dkc])
                });
                let prepared = line
                    .as_ref()
                    .map(|(_, [kc, _])| (&self.line_bases[idx], self.ln_depths[k], *kc));
                let lf = pin_law_force(
                    &m.pin_law,
                    pen,
                    pen_rate,
                    &site,
                    want_energy,
                    warm,
                    prepared,
                )?;
                let f = lf.force;
                qf[dk] -= f * n[0];
                qf[dk + 1] -= f * n[1];
                qf[dk + 2] -= f * lever;
                // A profile error's share of the penetration moves with the foot.
                if let Some((go, gt)) = pc.error_gradient {
                    qf[dk] -= f * go[0];
                    qf[dk + 1] -= f * go[1];
                    qf[dk + 2] -= f * gt;
                }
                // Sliding friction (see the rigid model): material point velocity
                // O' + th' z x arm, force ft t on the disc, t = z x n.
                if let Some(fr) = &m.pin_friction {
                    let arm = pc.arm;
                    let vx = [ov[0] - vt * arm[1], ov[1] + vt * arm[0]];
                    let vs = n[0] * vx[1] - n[1] * vx[0];
                    let ft = fr.force(vs, f);
                    qf[dk] -= ft * n[1];
                    qf[dk + 1] += ft * n[0];
                    qf[dk + 2] += ft * (arm[0] * n[0] + arm[1] * n[1]);
                    let p = -ft * vs;
                    out.dissipation += p;
                    out.friction[0] += p;
                }
                // Location term of a line law (see `PinLaw::location_slope`; tested for the law
                // here, not in the call, so that the IMPACT law's evaluations skip the call).
                if let Some((d, curvature)) = &line
                    && let Some(ls) = m.pin_law.location_slope_from(
                        lf.elastic,
                        &site,
                        d,
                        *curvature,
                        pin.centre,
                        o,
                        (pose.sin, pose.cos),
                    )
                {
                    let (fo, mt) = ls.forces();
                    qf[dk] += fo[0];
                    qf[dk + 1] += fo[1];
                    qf[dk + 2] += mt;
                }
                out.dissipation += (f - lf.elastic) * pen_rate;
                out.potential += lf.energy;
                sink.pin(k, j, f, pen, -f * lever, add(o, pc.arm), n);
            }
        }
        if self.crank_bearing.is_none() {
            // Rigid crank bearings: a force on a crank centre turns the carrier, through the
            // seat's lever (virtual work with ds_i/dth_c = z x s_i).
            for i in 0..self.cranks {
                let ci = crank_index(i);
                let s = rotate(thc, self.seat_vecs[i]);
                qf[CARRIER] += cross(s, [qf[ci], qf[ci + 1]]);
                qf[ci] = 0.0;
                qf[ci + 1] = 0.0;
            }
        }
        qf[CARRIER] -= m.carrier_load(t);
        if let Some(tq) = m.input_drive_torque(t) {
            let share = tq / self.input.len() as f64;
            for &i in &self.input {
                qf[i] += share;
            }
        }
        if self.load_index.is_some() || self.motor_index.is_some() {
            let (sh, li, mi) = self.shafts(t, x, v);
            qf[CARRIER] += sh.carrier;
            qf[SUN] += sh.input;
            qf[li] += sh.load;
            qf[mi] += sh.motor;
            out.dissipation += sh.dissipation;
            out.potential += sh.potential;
        }
        if !qf.iter().all(|v| v.is_finite()) {
            return Err(RvdynError::Simulation(format!(
                "non-finite generalised force at t = {t:.6e} s: the integration has diverged; \
                 reduce the step (dt) or the tolerances, or use the implicit integrator"
            )));
        }
        Ok(out)
    }
}
