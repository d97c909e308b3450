//! The static generalised forces `Q(x)` and tangent stiffness `K(x) = -dQ/dx` in the full
//! coordinates: every coupling (pin contacts with their profile errors, sun/planet meshes, crank
//! and eccentric bearings), and the fresh pin gaps for reports.

use super::laws::{
    MeshStatic, add_bearing, add_bearing_damping, contact_damping, elastic, mesh_static,
    profile_offset_jet,
};
use super::vec2::{cos_sin, dot, perp, rotate};
use super::{CARRIER, ContactState, Dense, Family, SUN, Statics};
use crate::analysis::ltca::gear_errors::FlankError;
use crate::contact::law::PinLaw;
use crate::contact::pin_tangent::{
    centre_curve_derivatives_cs, foot_jet_with, gap_jet_cs, line_jet_checked,
};
use crate::error::{Result, RvdynError};
use crate::geometry::gap::small_sin_cos;

impl Statics {
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
                    // The eccentric's bending deflection from the crank's line (0 without).
                    let nk = self.bending.as_ref().map(|_| self.node_index(i, k));
                    let bend = nk.map_or([0.0; 2], |n| [x[n], x[n + 1]]);
                    let ecc = {
                        let c = cos_sin(alpha + disc.phase + self.ecc_phase[i]);
                        let e = self.ecc_radius[i];
                        [e * c[0], e * c[1]]
                    };
                    let arm = rotate(self.disc_cs[k], self.holes[i * nd + k]);
                    let d = [
                        x[dk] + arm[0] - p[0] - bend[0] - ecc[0],
                        x[dk + 1] + arm[1] - p[1] - bend[1] - ecc[1],
                    ];
                    let (g, h) = eb.static_tangent(d);
                    let pa = perp(arm);
                    let pe = perp(ecc);
                    // With bending, the eccentric's deflection enters as the crank centre does.
                    let n = nk.unwrap_or(0);
                    let all: [(usize, [f64; 2]); 8] = [
                        (dk, [1.0, 0.0]),
                        (dk + 1, [0.0, 1.0]),
                        (dk + 2, pa),
                        (ci, [-1.0, 0.0]),
                        (ci + 1, [0.0, -1.0]),
                        (ci + 2, [-pe[0], -pe[1]]),
                        (n, [-1.0, 0.0]),
                        (n + 1, [0.0, -1.0]),
                    ];
                    let cols = &all[..if nk.is_some() { 8 } else { 6 }];
                    add_bearing(qf, kf, cols, g, h);
                    if let Some(c) = cf.as_mut() {
                        add_bearing_damping(c, cols, eb.damping_matrix(d));
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
        // Crankshaft bending: V = 1/2 sum_axes u^T K_b u over each crank's eccentric deflections.
        if let Some(kb) = self.bending.as_ref().filter(|_| on(Family::CrankBending)) {
            for i in 0..self.cranks {
                for a in 0..nd {
                    let na = self.node_index(i, a);
                    for b in 0..nd {
                        let nb = self.node_index(i, b);
                        let kab = kb[a * nd + b];
                        for axis in 0..2 {
                            qf[na + axis] -= kab * x[nb + axis];
                            kf.add(na + axis, nb + axis, kab);
                        }
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
