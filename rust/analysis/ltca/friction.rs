//! Quasi-static Coulomb friction in the LTCA: the torque-twist loop opens.
//!
//! In a quasi-static sweep every contact slides in the direction of its tangential relative
//! displacement per unit load parameter along the current branch; Coulomb's law in full
//! sliding puts the friction force `mu N` against it (the sliding limit of the dynamic
//! models' `-mu N tanh(v / v_reg)`: far below any sliding speed the regularisation has no
//! quasi-static meaning, and the load path alone sets the direction). The contacts, laws and
//! coefficients are the dynamic models' (`dynamics::model`, docs/model.md "Friction in the
//! dynamic models"):
//!
//! - pins: the disc's material point at the contact moves along `t = z x n` by
//!   `dv = t . dO + (arm . n) dtheta`; the disc gets `F_t t` with
//!   `F_t = -mu lambda N sign(dv)` (`lambda = pin_rolling`, or 1 for fixed pins), i.e. the
//!   generalised force `F_t G` with `G = (t_x, t_y, arm . n)` on `(X, Y, theta)`;
//! - teeth (first stage): each pair of the path of contact (`contact::friction::ToothPath`)
//!   slides by `dv = rho_1 dw_1 + rho_2 dw_2` (`w_1 = sigma (th_s - th_c)`,
//!   `w_2 = sigma (alpha - th_c)`); the force `F = -mu N_pair sign(dv)` gives the torques
//!   `F rho_1`, `F rho_2` on sun and planet and `-(F rho_1 + F rho_2)` on the carrier;
//! - joint bearings (compliant joints only, as the dynamic model): the Palmgren torque
//!   `M0 + M1` at zero speed (`M0 = 160e-7 f0 d_m^3` N mm, `M1 = f1 |F| d_m`) against the
//!   relative rotation (eccentric: crank minus disc; crank bearing: crank minus carrier).
//!
//! The slip direction of each contact is taken from the frictionless tangent at the same
//! torque: `dq/dT = -K^-1 e_0` times the branch direction (`+1` loading, `-1` unloading),
//! carried to the full coordinates, and frozen during the Newton iteration of that point
//! (so the equilibrium equations are smooth). The Newton tangent is the exact frictionless
//! tangent plus forward differences of the friction forces (their normal-force dependence;
//! the signs are frozen), so the iteration converges quadratically up to the difference
//! error.
//!
//! At a reversal of the load every contact first sticks: without tangential compliance the
//! pose, hence the twist, is held while the friction forces reverse, until the sliding branch
//! of the new direction reaches the held twist (the loop's vertical stick segment).

use super::newton::{NewtonReport, solve_dense};
use super::statics::{CARRIER, ContactState, Dense, Kind, SUN, Statics};
use super::{Ltca, TwistLoop};
use crate::bearing::PalmgrenFriction;
use crate::contact::friction::ToothPath;
use crate::dynamics::scene::{Joints, Scene};
use crate::error::{Result, RvdynError};

/// The friction laws of a scene for the LTCA (the dynamic models' coefficients).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FrictionLaws {
    /// Effective pin coefficient `mu_pin lambda` [-] (0: none).
    pub pin: f64,
    /// Tooth coefficient [-] (0: none; needs a first stage).
    pub mesh: f64,
    /// Palmgren laws of the eccentric and crank bearings (compliant joints; `None`: none).
    pub bearings: Option<[PalmgrenFriction; 2]>,
    /// `(sin, cos)` of the first stage's pressure angle.
    pressure: [f64; 2],
    /// The scene's steady input speed [rad/s] (0 for a torque drive).
    input_speed: f64,
    /// Crank angle per second of the motion the friction acts in: the running reducer's in a
    /// running sweep, 0 in the held-input twist loop. It sets the bearings' speed-dependent
    /// Palmgren `M0` (the dynamic models use their bearings' speeds).
    crank_rate: f64,
}

impl FrictionLaws {
    /// The friction of `scene` as the dynamic models apply it.
    pub fn new(scene: &Scene) -> Self {
        let f = &scene.friction;
        let bearings = match (&scene.joints, f.bearing) {
            (
                Joints::Compliant {
                    eccentric_bearing,
                    crank_bearing,
                },
                Some(bf),
            ) => {
                let pf = |b: Option<&crate::dynamics::scene::Bearing>| PalmgrenFriction {
                    f0: bf.f0,
                    f1: bf.f1,
                    pitch_diameter: b
                        .and_then(|b| b.rollers.map(|r| r.pitch_diameter))
                        .unwrap_or(0.05),
                    viscosity: bf.viscosity,
                };
                Some([pf(Some(eccentric_bearing)), pf(crank_bearing.as_ref())])
            }
            _ => None,
        };
        Self {
            input_speed: match scene.drive {
                crate::dynamics::scene::Drive::Speed { speed, .. } => speed.abs(),
                _ => 0.0,
            },
            crank_rate: 0.0,
            pin: f.pin * f.pin_rolling.unwrap_or(1.0),
            mesh: if scene.stage1.is_some() { f.mesh } else { 0.0 },
            bearings,
            pressure: scene.stage1.as_ref().map_or([0.0, 1.0], |s| {
                let (s, c) = s.pressure_angle.sin_cos();
                [s, c]
            }),
        }
    }

    /// No friction (the frictionless LTCA through the friction solver: a check).
    pub fn none(scene: &Scene) -> Self {
        Self {
            pin: 0.0,
            mesh: 0.0,
            bearings: None,
            ..Self::new(scene)
        }
    }

    /// Whether any friction acts.
    pub fn any(&self) -> bool {
        self.pin > 0.0 || self.mesh > 0.0 || self.bearings.is_some()
    }
}

/// The slip directions of one equilibrium, frozen while it is solved.
#[derive(Debug, Clone, Default)]
pub(crate) struct Slip {
    /// Rate of the full coordinates along the branch (per unit load parameter).
    pub dir: Vec<f64>,
    /// Sign of each pin's slip, `k * pins + j`.
    pub pins: Vec<f64>,
}

#[inline]
fn sgn(v: f64) -> f64 {
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// Slip gradient `G = (t_x, t_y, arm . n)` of a pin contact.
#[inline]
fn pin_slip_gradient(normal: [f64; 2], arm: [f64; 2]) -> [f64; 3] {
    [
        -normal[1],
        normal[0],
        arm[0] * normal[0] + arm[1] * normal[1],
    ]
}

/// Sign of a bearing's relative rotation along `dir`.
#[inline]
fn rel(dir: &[f64], a: usize, b: usize) -> f64 {
    sgn(dir[a] - dir[b])
}

impl Slip {
    /// Freeze the pin slip signs at the pose of `cs` along `dir`.
    pub(crate) fn new(st: &Statics, cs: &ContactState, dir: Vec<f64>) -> Self {
        let zp = st.model.pins.len();
        let mut pins = vec![0.0; st.model.discs.len() * zp];
        for (k, _) in st.model.discs.iter().enumerate() {
            let dk = st.disc_index(k);
            for j in 0..zp {
                let jet = &cs.pin_jet[k * zp + j];
                let g = pin_slip_gradient(jet.normal, jet.arm);
                pins[k * zp + j] = sgn(g[0] * dir[dk] + g[1] * dir[dk + 1] + g[2] * dir[dk + 2]);
            }
        }
        Self { dir, pins }
    }
}

/// The friction generalised forces `qf` in the full coordinates at `x` with the contact
/// state `cs` of the same pose and the frozen slip `slip`. Returns the friction moment on the
/// carrier and the held input (for reports).
pub(crate) fn friction_forces(
    laws: &FrictionLaws,
    st: &Statics,
    x: &[f64],
    cs: &ContactState,
    slip: &Slip,
    qf: &mut [f64],
) {
    qf.fill(0.0);
    let m = &st.model;
    let zp = m.pins.len();
    let nd = m.discs.len();
    if laws.pin > 0.0 {
        for k in 0..nd {
            let dk = st.disc_index(k);
            for j in 0..zp {
                let f = cs.pin_force[k * zp + j];
                let s = slip.pins[k * zp + j];
                if f <= 0.0 || s == 0.0 {
                    continue;
                }
                let jet = &cs.pin_jet[k * zp + j];
                let g = pin_slip_gradient(jet.normal, jet.arm);
                let ft = -laws.pin * f * s;
                qf[dk] += ft * g[0];
                qf[dk + 1] += ft * g[1];
                qf[dk + 2] += ft * g[2];
            }
        }
    }
    let dir = &slip.dir;
    if laws.mesh > 0.0
        && let Some(mm) = &m.mesh
    {
        let path: &ToothPath = &mm.path;
        let thc = x[CARRIER];
        let [sp, cp] = laws.pressure;
        for i in 0..st.cranks {
            let ci = st.crank_index(i);
            let (u, s) = seat_dirs(st, thc, i);
            let zu = [-u[1], u[0]];
            let dcr = [x[ci] - s[0], x[ci + 1] - s[1]];
            let (rbs, rbp) = (mm.sun_base_radius, mm.planet_base_radius);
            let rot = rbs * (x[SUN] - thc) + rbp * (x[ci + 2] - thc);
            let s_mesh = rbs * (x[SUN] - thc) - mm.phases[i] * mm.base_pitch;
            for sigma in [1.0, -1.0] {
                let w = [
                    sp * u[0] + sigma * cp * zu[0],
                    sp * u[1] + sigma * cp * zu[1],
                ];
                let pen = sigma * rot - (dcr[0] * w[0] + dcr[1] * w[1]) - 0.5 * mm.backlash;
                if pen <= 0.0 {
                    continue;
                }
                let f = mm.law.evaluate(pen, 0.0, sigma * s_mesh, false).0.elastic;
                if f <= 0.0 {
                    continue;
                }
                let w1 = sigma * (dir[SUN] - dir[CARRIER]);
                let w2 = sigma * (dir[ci + 2] - dir[CARRIER]);
                let xi = (sigma * s_mesh).rem_euclid(path.base_pitch);
                let double = xi < path.double_fraction * path.base_pitch;
                let share = if double { 0.5 * f } else { f };
                let mut pair = |xp: f64| {
                    let rho1 = path.t1a + xp;
                    let rho2 = path.t1t2 - rho1;
                    let fr = -laws.mesh * share * sgn(w1 * rho1 + w2 * rho2);
                    let (t1, t2) = (fr * rho1, fr * rho2);
                    qf[SUN] += sigma * t1;
                    qf[ci + 2] += sigma * t2;
                    qf[CARRIER] -= sigma * (t1 + t2);
                };
                pair(xi);
                if double {
                    pair(xi + path.base_pitch);
                }
            }
        }
    }
    if let Some([ecc, crank]) = &laws.bearings
        && st.kind == Kind::Compliant
    {
        for i in 0..st.cranks {
            let ci = st.crank_index(i);
            if st.crank_bearing.is_some()
                && let Some(fb) = cs.crank_bearing_force.get(i)
            {
                let w = laws.crank_rate * (dir[ci + 2] - dir[CARRIER]).abs();
                let mt = crank.torque_unchecked(w, fb[0].hypot(fb[1])) * rel(dir, ci + 2, CARRIER);
                qf[ci + 2] -= mt;
                qf[CARRIER] += mt;
            }
            for k in 0..nd {
                let dk = st.disc_index(k);
                if let Some(fb) = cs.eccentric_bearing_force.get(i * nd + k) {
                    let w = laws.crank_rate * (dir[ci + 2] - dir[dk + 2]).abs();
                    let mt = ecc.torque_unchecked(w, fb[0].hypot(fb[1])) * rel(dir, ci + 2, dk + 2);
                    qf[ci + 2] -= mt;
                    qf[dk + 2] += mt;
                }
            }
        }
    }
}

/// Unit seat direction `u_i` and nominal seat `s_i` of crank `i` at carrier angle `thc`.
fn seat_dirs(st: &Statics, thc: f64, i: usize) -> ([f64; 2], [f64; 2]) {
    let a = thc + std::f64::consts::TAU * i as f64 / st.cranks as f64;
    let u = [a.cos(), a.sin()];
    let r = st.model.crank_radius;
    (u, [r * u[0], r * u[1]])
}

/// One frictional evaluation in the unknowns: residual `r` (frictionless + friction),
/// frictionless tangent `k` and the contact state.
struct Eval {
    r: Vec<f64>,
    rf: Vec<f64>,
    k: Dense,
    cs: ContactState,
}

impl Ltca {
    /// Residual and frictionless tangent with friction along `slip` at `q`.
    fn eval_friction(
        &mut self,
        laws: &FrictionLaws,
        psi: f64,
        torque: f64,
        q: &[f64],
        slip: Option<&Slip>,
    ) -> Result<Eval> {
        let n = self.statics.dim();
        let (mut r, k, cs) = self
            .statics
            .eval_fresh(psi, q, torque, &mut self.work, false)?;
        let mut rf = vec![0.0; n];
        if let Some(slip) = slip {
            let x = self.statics.full(psi, q);
            let mut qf = vec![0.0; x.len()];
            friction_forces(laws, &self.statics, &x, &cs, slip, &mut qf);
            self.statics.reduce_force(&qf, &self.work, &mut rf);
            for (a, b) in r.iter_mut().zip(&rf) {
                *a += b;
            }
        }
        Ok(Eval { r, rf, k, cs })
    }

    /// The branch direction in the full coordinates at the frictionless equilibrium `q`:
    /// `d x/d T` from the tangent `K` (`dq/dT = -K^-1 e_0`) times `direction`.
    fn branch_rate(&self, psi: f64, q: &[f64], k: &Dense, direction: f64) -> Result<Vec<f64>> {
        let n = q.len();
        let mut v = vec![0.0; n];
        // A body floating in a clearance (near zero torque) makes K singular: regularise it
        // as the Newton solver does (`K + mu k_ref L^2`), raising mu until it solves. The
        // floating body carries no contact force, so its slip direction does not matter.
        let mut mu = 0.0;
        loop {
            let mut a = k.clone();
            for (i, l) in self.statics.scale.iter().enumerate() {
                a.a[i * n + i] += mu * self.k_ref * l * l;
            }
            v.fill(0.0);
            v[0] = -1.0;
            if solve_dense(&mut a, &mut v) {
                break;
            }
            mu = if mu == 0.0 { 1e-12 } else { mu * 10.0 };
            if mu > 1.0 {
                return Err(RvdynError::Convergence(format!(
                    "at crank angle {psi:.6} rad the frictionless tangent is singular: no slip \
                     direction for the friction"
                )));
            }
        }
        let vmax = v
            .iter()
            .zip(&self.statics.scale)
            .fold(0.0f64, |m, (d, l)| m.max((d * l).abs()));
        if vmax == 0.0 || !vmax.is_finite() {
            return Err(RvdynError::Convergence(format!(
                "at crank angle {psi:.6} rad no finite slip direction"
            )));
        }
        // Central difference of the (smooth) map x(q) along v, stepped 1e-9 m.
        let h = 1e-9 / vmax;
        let qp: Vec<f64> = q.iter().zip(&v).map(|(a, b)| a + h * b).collect();
        let qm: Vec<f64> = q.iter().zip(&v).map(|(a, b)| a - h * b).collect();
        let xp = self.statics.full(psi, &qp);
        let xm = self.statics.full(psi, &qm);
        Ok(xp
            .iter()
            .zip(&xm)
            .map(|(a, b)| direction * (a - b) / (2.0 * h * vmax))
            .collect())
    }

    /// The equilibrium at `torque` with friction sliding along `direction` (+1: the torque
    /// increasing, -1: decreasing) from the frictionless equilibrium at the same torque.
    /// `near_zero`: reach that one by continuation (see `solve_near_zero`).
    pub(crate) fn solve_friction(
        &mut self,
        laws: &FrictionLaws,
        torque: f64,
        psi: f64,
        direction: f64,
        near_zero: Option<f64>,
    ) -> Result<(Vec<f64>, NewtonReport)> {
        let (q, _) = match near_zero {
            Some(rated) => self.solve_near_zero(torque, psi, rated)?,
            None => self.solve_unknowns(torque, psi)?,
        };
        let e0 = self.eval_friction(laws, psi, torque, &q, None)?;
        let dir = self.branch_rate(psi, &q, &e0.k, direction)?;
        let (q, rep, _) = self.newton_friction(laws, torque, psi, q, &e0.cs, dir)?;
        Ok((q, rep))
    }

    /// The equilibrium at `torque` and crank angle `psi` with friction sliding along the full
    /// coordinate rate `dir`, by Newton from `q` (whose contact state is `cs0`). Returns the
    /// unknowns, the report and the torque the held input carries [N m] (friction included).
    fn newton_friction(
        &mut self,
        laws: &FrictionLaws,
        torque: f64,
        psi: f64,
        mut q: Vec<f64>,
        cs0: &ContactState,
        dir: Vec<f64>,
    ) -> Result<(Vec<f64>, NewtonReport, f64)> {
        let slip = Slip::new(&self.statics, cs0, dir);
        let n = q.len();
        let scale = self.statics.scale.clone();
        let rp = scale[0];
        let load = torque.abs() / rp;
        // The frictionless solver's round-off floor: positions carry about eps times the
        // largest of them (a crank angle of 48 rad puts the carrier 7 m of arc away).
        let size = q
            .iter()
            .zip(&scale)
            .fold(rp, |m, (x, l)| m.max((x * l).abs()));
        let floor = 4.0 * f64::EPSILON * self.k_ref * size;
        let done = (self.options.tolerance * load).max(floor);
        let stalled_ok = (1e-9 * load).max(100.0 * floor);
        let norm = |r: &[f64]| {
            r.iter()
                .zip(&scale)
                .fold((0.0f64, 0.0f64), |(m, s), (v, l)| {
                    let x = v / l;
                    (m.max(x.abs()), s + x * x)
                })
        };
        let mut ev = self.eval_friction(laws, psi, torque, &q, Some(&slip))?;
        let (mut rmax, mut r2) = norm(&ev.r);
        let mut it = 0;
        while rmax > done {
            if it >= self.options.max_iterations.min(60) {
                // Stalled within a few hundred ulps of the forces (light loads): converged.
                if rmax <= stalled_ok {
                    break;
                }
                return Err(not_converged(psi, torque, rmax / load.max(1.0), it));
            }
            it += 1;
            // Tangent: exact frictionless part plus forward differences of the friction
            // (the normal forces' dependence on the pose; signs frozen).
            let mut kt = ev.k.clone();
            if laws.any() {
                for b in 0..n {
                    let h = 1e-9 / scale[b];
                    let mut qb = q.clone();
                    qb[b] += h;
                    let e1 = self.eval_friction(laws, psi, torque, &qb, Some(&slip))?;
                    for a in 0..n {
                        kt.a[a * n + b] -= (e1.rf[a] - ev.rf[a]) / h;
                    }
                }
            }
            // Newton step, regularised as the frictionless solver (`K + mu k_ref L^2`, mu
            // raised tenfold while the step fails) where K is singular (bodies floating in
            // clearances near zero torque); backtracking on the scaled residual norm.
            let mut accepted = false;
            let mut round_off = false;
            let mut mu = 0.0;
            for _attempt in 0..14 {
                let mut a = kt.clone();
                for (i, l) in scale.iter().enumerate() {
                    a.a[i * n + i] += mu * self.k_ref * l * l;
                }
                let mut dq = ev.r.clone();
                if !solve_dense(&mut a, &mut dq) {
                    mu = if mu == 0.0 { 1e-9 } else { mu * 10.0 };
                    continue;
                }
                // Converged at the round-off floor (as the frictionless solver): a plain Newton
                // correction that moves no point by more than round-off.
                if mu == 0.0 && rmax <= stalled_ok {
                    let moved = dq
                        .iter()
                        .zip(&scale)
                        .fold(0.0f64, |m, (d, l)| m.max((d * l).abs()));
                    if moved <= super::newton::STEP_ROUND_OFF * f64::EPSILON * size {
                        accepted = true;
                        round_off = true;
                        break;
                    }
                }
                let mut step = 1.0;
                for _ in 0..20 {
                    let qt: Vec<f64> = q.iter().zip(&dq).map(|(a, b)| a + step * b).collect();
                    if let Ok(e) = self.eval_friction(laws, psi, torque, &qt, Some(&slip))
                        && self.statics.max_penetration <= self.statics.model.max_penetration
                    {
                        let (m2, n2) = norm(&e.r);
                        if n2 < (1.0 - 1e-4 * step) * r2 || m2 <= done {
                            q = qt;
                            ev = e;
                            rmax = m2;
                            r2 = n2;
                            accepted = true;
                            break;
                        }
                    }
                    step *= 0.5;
                }
                if accepted {
                    break;
                }
                mu = if mu == 0.0 { 1e-9 } else { mu * 10.0 };
            }
            if round_off {
                break;
            }
            if !accepted {
                if rmax <= stalled_ok {
                    break;
                }
                return Err(not_converged(psi, torque, rmax / load.max(1.0), it));
            }
        }
        // The held input's torque: the reaction of the elastic and the friction forces on it.
        let ev = self.eval_friction(laws, psi, torque, &q, Some(&slip))?;
        let x = self.statics.full(psi, &q);
        let mut qf = vec![0.0; x.len()];
        friction_forces(laws, &self.statics, &x, &ev.cs, &slip, &mut qf);
        let st = &self.statics;
        let input_torque = if st.model.mesh.is_some() {
            st.input_reaction(&self.work) - qf[SUN]
        } else if st.kind == Kind::Rigid {
            // The elastic and the friction forces' reactions on the held cranks.
            st.held_cranks_reaction(&self.work.qf, &x) + st.held_cranks_reaction(&qf, &x)
        } else {
            st.input_reaction(&self.work)
                - (0..st.cranks)
                    .map(|i| qf[st.crank_index(i) + 2])
                    .sum::<f64>()
        };
        // The frictionless tangent at the frictional pose (the reported tangent stiffness);
        // the warm start stays the frictionless sequence.
        self.work.k_last = ev.k;
        Ok((
            q,
            NewtonReport {
                iterations: it,
                residual: rmax / load.max(1.0),
            },
            input_torque,
        ))
    }

    /// Equilibria along a running sweep with friction: at each crank angle in turn, under the
    /// output torque `torque`, with every contact sliding as the running reducer slides (the
    /// kinematic rate of the full coordinates per crank angle, the input driving against the
    /// load: the crank angle decreasing for `torque > 0`, increasing for `torque < 0`). Returns
    /// per crank angle the transmission error \[rad\] and the torque the held input carries
    /// [N m]; with the ratio `i`, `torque / (i input_torque)` is the quasi-static efficiency.
    pub fn friction_sweep(
        &mut self,
        laws: &FrictionLaws,
        torque: f64,
        crank_angles: &[f64],
    ) -> Result<Vec<(f64, f64)>> {
        crate::error::require_finite("torque", torque)?;
        // The load acts against positive carrier rotation and the carrier turns by
        // `-psi / zc`: the input drives it against a positive torque with psi decreasing.
        let drive = if torque < 0.0 { 1.0 } else { -1.0 };
        // The running reducer at the scene's input speed: crank angle per second.
        let mut laws = laws.clone();
        laws.crank_rate = if self.statics.model.mesh.is_some() {
            laws.input_speed / self.statics.held_input(1.0).abs()
        } else {
            laws.input_speed
        };
        let laws = &laws;
        let mut out = Vec::with_capacity(crank_angles.len());
        for &psi in crank_angles {
            let (q, _) = self.solve_unknowns(torque, psi)?;
            let h = 1e-6;
            let xp = self.statics.kinematic_full(psi + h);
            let xm = self.statics.kinematic_full(psi - h);
            let dir: Vec<f64> = xp
                .iter()
                .zip(&xm)
                .map(|(a, b)| drive * (a - b) / (2.0 * h))
                .collect();
            let e0 = self.eval_friction(laws, psi, torque, &q, None)?;
            let (q, _, input) = self.newton_friction(laws, torque, psi, q, &e0.cs, dir)?;
            let x = self.statics.full(psi, &q);
            let held = if self.statics.model.mesh.is_some() {
                self.statics.held_input(psi)
            } else {
                psi
            };
            out.push((x[CARRIER] - held / self.ratio, input));
        }
        Ok(out)
    }
}

fn not_converged(psi: f64, torque: f64, res: f64, it: usize) -> RvdynError {
    RvdynError::Convergence(format!(
        "no equilibrium with friction at crank angle {psi:.6} rad and torque {torque:.6e} N m \
         (residual {res:.3e} of the load after {it} iterations): the friction coefficients may \
         be too large for a sliding equilibrium, or the torque too small to seat the bodies in \
         their bearing clearances; reduce the coefficients or raise the torque"
    ))
}

impl Ltca {
    /// The twist \[rad\] of the sliding equilibrium at `torque` along `direction`.
    fn friction_twist(
        &mut self,
        laws: &FrictionLaws,
        torque: f64,
        psi: f64,
        direction: f64,
        near_zero: Option<f64>,
    ) -> Result<f64> {
        let (q, _) = self.solve_friction(laws, torque, psi, direction, near_zero)?;
        let x = self.statics.full(psi, &q);
        Ok(-(x[CARRIER] + psi / self.statics.zc()))
    }

    /// The torque-twist loop with the friction `laws` (see [`Ltca::twist_loop`] and the
    /// module documentation): loading (`+1`) and unloading (`-1`) sliding branches, with the
    /// stick segment at each reversal; the catalogue values from the same branches.
    pub fn twist_loop_with_friction(
        &mut self,
        laws: &FrictionLaws,
        rated: f64,
        psi: f64,
        points: usize,
    ) -> Result<TwistLoop> {
        let (torque, rated) = loop_torques(rated, points)?;
        crate::error::require_finite("crank angle", psi)?;
        self.reset();
        let eps = super::zero_side_torque(rated);
        let mut side = 1.0;
        let mut twist = Vec::with_capacity(points);
        let mut tangent = Vec::with_capacity(points);
        let mut solved: Vec<(f64, Vec<f64>)> = Vec::with_capacity(points);
        let mut direction = 1.0;
        let mut held: Option<f64> = None;
        // (torque solved, direction, twist) of every loop point.
        let mut branch: Vec<(f64, f64, f64)> = Vec::with_capacity(points);
        for (i, &t) in torque.iter().enumerate() {
            if i > 0 {
                let d = (t - torque[i - 1]).signum();
                if d != direction {
                    // A reversal at the previous point: every contact sticks there.
                    held = twist.last().copied();
                    direction = d;
                }
            }
            let ts = if t == 0.0 { side * eps } else { t };
            if t != 0.0 {
                side = t.signum();
            }
            let near = (t == 0.0).then_some(rated);
            let tw = match self.friction_twist(laws, ts, psi, direction, near) {
                Ok(slide) => stick(held, direction, slide),
                // Near zero torque a load-independent friction (the bearings' M0) can exceed
                // the load and what the elastic forces can overcome: no sliding equilibrium
                // exists, the contacts stick and the twist is held.
                // Then the contacts stick where the sliding branch ends: continuation from the
                // previous point's torque down by factors of 10, the last sliding twist held.
                Err(_) if t == 0.0 && !twist.is_empty() => {
                    let mut tw = twist[twist.len() - 1];
                    let mut level = 0.1 * torque[i - 1].abs();
                    while level > eps {
                        match self.friction_twist(laws, level * ts.signum(), psi, direction, None) {
                            Ok(v) => tw = stick(held, direction, v),
                            Err(_) => break,
                        }
                        level *= 0.1;
                    }
                    tw
                }
                // At the start, at rest: the frictionless equilibrium (no friction acts yet).
                Err(_) if t == 0.0 => {
                    let (q, _) = self.solve_near_zero(ts, psi, rated)?;
                    let x = self.statics.full(psi, &q);
                    -(x[CARRIER] + psi / self.statics.zc())
                }
                Err(e) => return Err(e),
            };
            if let Some(l) = self.history.first() {
                solved.push((ts, l.q.clone()));
            }
            tangent.push(self.last_tangent_stiffness());
            twist.push(tw);
            branch.push((ts, direction, tw));
        }
        // Catalogue points on the sliding branches (each warm-started from the loop point
        // nearest in torque on the same side of zero), with the stick at the loop's tips.
        let mut at = |t: f64, d: f64| -> Result<f64> {
            self.reset();
            if let Some((t0, q0)) = solved
                .iter()
                .filter(|(s, _)| s.signum() == t.signum())
                .min_by(|a, b| (a.0 - t).abs().total_cmp(&(b.0 - t).abs()))
            {
                self.history = vec![super::Solved::new(&self.statics, psi, *t0, q0.clone())];
            }
            let near = (t.abs() < 1e-6 * rated).then_some(rated);
            match self.friction_twist(laws, t, psi, d, near) {
                Ok(v) => Ok(v),
                // Stuck near zero torque (see above): the loop's own twist there.
                Err(e) => branch
                    .iter()
                    .filter(|(s, dd, _)| *dd == d && s.signum() == t.signum())
                    .min_by(|a, b| (a.0 - t).abs().total_cmp(&(b.0 - t).abs()))
                    .filter(|_| near.is_some())
                    .map(|b| b.2)
                    .ok_or(e),
            }
        };
        let tip_plus = at(rated, 1.0)?;
        let tip_minus = at(-rated, -1.0)?;
        let upper = |v: f64| stick(Some(tip_plus), -1.0, v);
        let lower = |v: f64| stick(Some(tip_minus), 1.0, v);
        let t3 = 0.03 * rated;
        let mid_plus = 0.5 * (upper(at(t3, -1.0)?) + lower(at(t3, 1.0)?));
        let mid_minus = 0.5 * (upper(at(-t3, -1.0)?) + lower(at(-t3, 1.0)?));
        let backlash = upper(at(eps, -1.0)?) - lower(at(-eps, 1.0)?);
        Ok(TwistLoop {
            crank_angle: psi,
            torque,
            twist,
            rated_torque: rated,
            rigidity: 2.0 * rated / (tip_plus - tip_minus),
            lost_motion: mid_plus - mid_minus,
            backlash,
            tangent_stiffness: tangent,
        })
    }
}

/// The twist on a branch of direction `direction` that began by sticking at the twist
/// `held`: the pose is held until the sliding twist `slide` passes it.
fn stick(held: Option<f64>, direction: f64, slide: f64) -> f64 {
    match held {
        Some(h) if direction < 0.0 => slide.min(h),
        Some(h) => slide.max(h),
        None => slide,
    }
}

/// The loop's torques `0 -> +rated -> 0 -> -rated -> 0`, linear in the point index within each
/// quarter, with `points - 1` steps shared among the quarters as evenly as whole numbers allow
/// (so that `+-rated` and the zeros are always points, whatever the count), and `|rated|`.
/// Errors (`Parameter`) for a non-finite or zero rated torque or fewer than 8 points.
pub(crate) fn loop_torques(rated: f64, points: usize) -> Result<(Vec<f64>, f64)> {
    crate::error::require_finite("rated torque", rated)?;
    let rated = rated.abs();
    super::require_points("loop points", points)?;
    if rated == 0.0 || points < 8 {
        return Err(RvdynError::Parameter(format!(
            "the torque-twist loop needs a rated torque > 0 N m and at least 8 points, got \
             {rated} N m and {points}"
        )));
    }
    let steps = points - 1;
    let mut torque = Vec::with_capacity(points);
    torque.push(0.0);
    for (k, (a, b)) in [(0.0, 1.0), (1.0, 0.0), (0.0, -1.0), (-1.0, 0.0)]
        .into_iter()
        .enumerate()
    {
        let q = steps / 4 + usize::from(k < steps % 4);
        for j in 1..=q {
            torque.push(rated * (a + (b - a) * j as f64 / q as f64));
        }
    }
    Ok((torque, rated))
}

#[cfg(test)]
#[path = "friction_tests.rs"]
mod tests;
