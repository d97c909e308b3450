//! The generalised forces of the compliant model: bearings, first-stage meshes, pin contacts,
//! load and drive (docs/model.md#compliant-joint-model).

use super::{CARRIER, CompliantModel, Flows, SUN, crank_index};
use crate::dynamics::model::pin_contact::{
    DiscPose, SeparationBound, penetration_error, pin_query,
};
use crate::dynamics::model::vec2::{add, cross, dot, perp, rotate, scaled, sub};
use crate::dynamics::run::sink::ContactSink;
use crate::error::{Result, RvdynError};

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
                let b = cb.load(d, dd);
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
                let b = self.eccentric_bearing.load(sub(h, e_pos), sub(h_v, e_v));
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
                let (f, elastic, pen, pen_rate) = mm.law.mesh(mm.backlash, delta, rate);
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
                let idx = k * m.pins.len() + j;
                if self.skip_separated
                    && self.separation[idx].get().separated(o, th, m.profile_reach)
                {
                    sink.pin(k, j, 0.0, 0.0, 0.0, [0.0; 2], [0.0; 2]);
                    continue;
                }
                let pc = pin_query(disc, pin, &pose, t, (k, j), &self.warm_seeds[idx])?;
                if self.skip_separated {
                    self.separation[idx].set(SeparationBound {
                        centre: o,
                        angle: th,
                        gap: -pc.penetration,
                    });
                }
                if pc.penetration <= 0.0 {
                    sink.pin(k, j, 0.0, 0.0, 0.0, [0.0; 2], [0.0; 2]);
                    continue;
                }
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
}
