//! Linearisation of the rigid and compliant reducer models about a loaded quasi-static
//! equilibrium (docs/model.md, "Modal analysis", "Linearisation").
//!
//! The operating point is the LTCA equilibrium (`analysis::ltca`) at a crank angle and an
//! output torque with the input held, which is also the state of a speed-driven reducer
//! turning slowly (the prescribed input does not move in a vibration). The coordinates are the
//! LTCA unknowns: `[carrier angle, crank angle]` for rigid joints (carrier angle only without
//! a first stage), every compliant coordinate but the held input for compliant joints (crank
//! centres only with compliant crank bearings) - the free coordinates of the dynamic model
//! with a prescribed input.
//!
//! - `M`: the models' constant diagonal masses of those coordinates;
//! - `K = -dQ/dq`: the analytic tangent stiffness of the LTCA statics (the static tangent of
//!   each contact and bearing law with the exact gaps and their curvature, the meshes, and the
//!   curvature of the rigid-joint map), split into named parts by evaluating one family of
//!   couplings at a time (the assembly is a sum over families, so the parts add up to `K`; the
//!   split error is reported): the pins of each disc, the sun/planet meshes, the eccentric
//!   bearings and the crank bearings;
//! - `C = -dQ/dv`: forward differences of the dynamic model's generalised force
//!   ([`ReducerModel::generalized_force`]) in the velocities at the equilibrium pose at rest.
//!   Every damping law of the models is linear in the rate at a fixed pose (IMPACT/Palmgren:
//!   `STEP(x) x'`; bearings `c_b d'`) while the contact stays closed and pushing, so the
//!   difference quotient is exact up to round-off.

use crate::analysis::ltca::Ltca;
use crate::analysis::ltca::statics::{CARRIER, Dense, Family, Kind, SUN, Statics, Work};
use crate::analysis::modes::{LinearSystem, StiffnessPart};
use crate::dynamics::model::ReducerModel;
use crate::dynamics::model::compliant::CompliantModel;
use crate::dynamics::model::rigid::{FULL, LOAD, MOTOR, RigidModel, SUN as RSUN};
use crate::dynamics::model::rigid_system::RigidSystem;
use crate::dynamics::scene::{Drive, Joints, Load, Scene};
use crate::error::{Result, RvdynError, require_finite};
use nalgebra::{DMatrix, DVector};

/// The dynamic model whose generalised force gives the damping (and checks the stiffness),
/// built with a zero torque drive and no load: the input is a free coordinate held at the
/// equilibrium's angle, and only derivatives of the force are used.
enum Dynamic {
    /// Rigid joints (full coordinates `[th_c, alpha, th_s, th_L, th_m]`).
    Rigid(Box<RigidModel>),
    /// Compliant joints (the model's full coordinates).
    Compliant(Box<CompliantModel>),
}

/// A coordinate the linearisation adds to the LTCA unknowns when the scene has machine shafts
/// (docs/model.md, "Modes with machine shafts").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Extra {
    /// The sun angle, free on the drive shaft.
    Sun,
    /// The load angle at the end of the output shaft.
    Load,
    /// The motor angle (a torque drive with a drive shaft).
    Motor,
}

/// The operating point a linearisation was taken at.
#[derive(Debug, Clone, PartialEq)]
pub struct Equilibrium {
    /// Crank angle \[rad\].
    pub crank_angle: f64,
    /// Output torque [N m].
    pub torque: f64,
    /// The LTCA unknowns at equilibrium (the linearisation's coordinates).
    pub unknowns: Vec<f64>,
    /// Full compliant-style coordinates at equilibrium.
    pub full: Vec<f64>,
    /// Largest equilibrium residual relative to the load scale (NaN about a dynamic state,
    /// which is no equilibrium).
    pub residual: f64,
    /// Newton iterations of the equilibrium.
    pub iterations: usize,
    /// `|sum_p K_p - K|_F / |K|_F` of the stiffness split.
    pub split_error: f64,
    /// Angles of the load and the motor \[rad\] (the carrier's and the sun's without shafts).
    pub shaft_angles: [f64; 2],
    /// Full coordinates and velocities of the dynamic model at the operating point (its own
    /// layout: `[th_c, alpha, th_s, th_L, th_m]` for rigid joints, the compliant full vector
    /// otherwise); velocities zero at an equilibrium.
    pub dynamic_state: (Vec<f64>, Vec<f64>),
    /// Time of the dynamic state \[s\] (0 for an equilibrium).
    pub time: f64,
    /// An LTCA equilibrium (true) or a dynamic state (false): about an equilibrium, which
    /// stands for a slowly turning reducer, the scene's friction is left out (see
    /// [`Linearizer::linearise_about`]).
    pub is_equilibrium: bool,
}

/// Linearises one scene about LTCA equilibria (warm-started from the previous one).
pub struct Linearizer {
    ltca: Ltca,
    statics: Statics,
    families: Vec<(String, Family)>,
    work: Work,
    names: Vec<String>,
    mass: Vec<f64>,
    dynamic: Dynamic,
    /// The same model without the scene's friction, for equilibria (`None`: no friction).
    frictionless: Option<Dynamic>,
    /// Coordinates added for the shafts (after the LTCA unknowns).
    extra: Vec<Extra>,
    /// Index of each linearisation coordinate in the dynamic model's full coordinates.
    dyn_index: Vec<usize>,
    /// Position of each of the dynamic model's full coordinates among its free ones.
    dyn_pos: Vec<Option<usize>>,
    /// Length scale of each coordinate [m per unit].
    scale: Vec<f64>,
    output_shaft: Option<crate::dynamics::scene::Shaft>,
    input_shaft: Option<crate::dynamics::scene::Shaft>,
    /// Eccentric deflections of bending crankshafts (`crank_shaft`) among the LTCA unknowns
    /// (the last ones), condensed out of the linearisation (0 without bending).
    nodes: usize,
    /// With bending: the eccentric bearings' damping over their tangent stiffness \[s\]
    /// (`C = ratio K`, exact for their laws; docs/model.md, "Modes with bending crankshafts").
    eccentric_damping: f64,
}

/// The damping of an eccentric bearing over its tangent stiffness \[s\] when the two are
/// proportional at every loaded pose: rollers without a parallel linear part (`beta`), or a
/// linear bearing without clearance (`c / k`). Other bearings: `None`.
fn proportional_damping(b: &crate::dynamics::scene::Bearing) -> Option<f64> {
    match &b.rollers {
        Some(r) if b.stiffness == 0.0 && b.damping == 0.0 => Some(r.beta()),
        None if b.clearance == 0.0 && b.stiffness > 0.0 => Some(b.damping / b.stiffness),
        _ => None,
    }
}

impl Linearizer {
    /// Prepare the linearisation of `scene` (validated; its drive and load are not used: the
    /// input is held and the torque is given per call).
    ///
    /// Errors: an invalid scene (`Parameter`/`Scene`); a coordinate without mass or inertia
    /// (`Scene`, naming it).
    pub fn new(scene: &Scene) -> Result<Self> {
        let statics = Statics::new(scene)?;
        let ltca = Ltca::new(scene)?;
        let families = statics.families();
        let mut free_scene = scene.clone();
        // Bending crankshafts: the dynamic model (for the masses and the damping) is the one
        // with straight cranks, without the eccentric bearings' damping, which acts on the
        // disc's motion relative to the deflected eccentric and is added from their tangent.
        let nodes = if statics.bending.is_some() {
            2 * statics.cranks * statics.model.discs.len()
        } else {
            0
        };
        let mut eccentric_damping = 0.0;
        if nodes > 0 {
            free_scene.crank_shaft = None;
            if let Joints::Compliant {
                eccentric_bearing, ..
            } = &mut free_scene.joints
            {
                eccentric_damping = proportional_damping(eccentric_bearing).ok_or_else(|| {
                    RvdynError::Scene(
                        "modes with crank_shaft need eccentric bearings whose damping is \
                         proportional to their stiffness: rollers without a parallel linear \
                         spring or damper (joints.eccentric_bearing.stiffness = damping = 0), or \
                         a linear bearing without clearance"
                            .into(),
                    )
                })?;
                eccentric_bearing.damping = 0.0;
                if let Some(r) = eccentric_bearing.rollers.as_mut() {
                    r.damping_ratio = 0.0;
                }
            }
        }
        free_scene.drive = Drive::Torque {
            torque: 0.0,
            ramp_time: 0.0,
        };
        free_scene.load = Load::Idle;
        // A speed drive holds the motor: it is no coordinate of the linearisation, but the
        // torque-driven copy has it free and needs some inertia for it (never used).
        if matches!(scene.drive, Drive::Speed { .. })
            && scene.shafts.input.is_some()
            && free_scene.inertias.motor_inertia <= 0.0
        {
            free_scene.inertias.motor_inertia = 1.0;
        }
        // Only forces are evaluated: the initial state does not matter (and a steady start
        // needs a speed drive).
        free_scene.initial = crate::dynamics::scene::Initial::Rest;
        let full = full_names(&statics);
        // The sun is free on a drive shaft (the motor held by a speed drive, or free under a
        // torque drive); the load is free on an output shaft.
        let mut extra = Vec::new();
        if scene.shafts.input.is_some() {
            extra.push(Extra::Sun);
        }
        if scene.shafts.output.is_some() {
            extra.push(Extra::Load);
        }
        if scene.shafts.input.is_some() && matches!(scene.drive, Drive::Torque { .. }) {
            extra.push(Extra::Motor);
        }
        // Regularised Coulomb friction about a state at rest has the slope mu N / v_reg, an
        // artefact of the regularisation; a slowly turning reducer slides at speeds far above
        // v_reg, where the friction force does not change with a small velocity change.
        let frictionless = if scene.friction.any() {
            let mut s = free_scene.clone();
            s.friction = crate::dynamics::scene::Friction::default();
            Some(match scene.joints {
                Joints::Rigid => Dynamic::Rigid(Box::new(RigidModel::new(&s)?)),
                Joints::Compliant { .. } => Dynamic::Compliant(Box::new(CompliantModel::new(&s)?)),
            })
        } else {
            None
        };
        // The LTCA unknowns the linearisation keeps (all but the condensed deflections).
        let kept = statics.dim() - nodes;
        let (mut names, mut mass, dynamic): (Vec<String>, Vec<f64>, Dynamic) = match scene.joints {
            Joints::Rigid => {
                let m = RigidModel::new(&free_scene)?;
                let mut names = vec!["carrier angle".to_string()];
                let mut mass = vec![m.mass[0]];
                if statics.dim() == 2 {
                    names.push("crank angle".into());
                    mass.push(m.mass[1]);
                }
                (names, mass, Dynamic::Rigid(Box::new(m)))
            }
            Joints::Compliant { .. } => {
                let m = CompliantModel::new(&free_scene)?;
                let unknowns = &statics.unknowns[..kept];
                let names = unknowns.iter().map(|&i| full[i].clone()).collect();
                let mass = unknowns.iter().map(|&i| m.mass[i]).collect();
                (names, mass, Dynamic::Compliant(Box::new(m)))
            }
        };
        let mut dyn_index: Vec<usize> = match &dynamic {
            Dynamic::Rigid(_) => (0..kept).collect(),
            Dynamic::Compliant(_) => statics.unknowns[..kept].to_vec(),
        };
        let mut scale = statics.scale[..kept].to_vec();
        let sun_lever = statics.model.mesh.map_or(1.0, |m| m.sun_base_radius);
        let rp = scene.cycloid.pin_circle_radius;
        for e in &extra {
            let (name, idx, lever) = match (&dynamic, e) {
                (Dynamic::Rigid(_), Extra::Sun) => ("sun angle", RSUN, sun_lever),
                (Dynamic::Rigid(_), Extra::Load) => ("load angle", LOAD, rp),
                (Dynamic::Rigid(_), Extra::Motor) => ("motor angle", MOTOR, sun_lever),
                (Dynamic::Compliant(_), Extra::Sun) => ("sun angle", SUN, sun_lever),
                (Dynamic::Compliant(m), Extra::Load) => {
                    ("load angle", m.load_index.unwrap_or(usize::MAX), rp)
                }
                (Dynamic::Compliant(m), Extra::Motor) => (
                    "motor angle",
                    m.motor_index.unwrap_or(usize::MAX),
                    sun_lever,
                ),
            };
            let mm = match &dynamic {
                Dynamic::Rigid(m) => m.mass.get(idx).copied(),
                Dynamic::Compliant(m) => m.mass.get(idx).copied(),
            }
            .ok_or_else(|| RvdynError::Parameter("shaft coordinate missing in the model".into()))?;
            names.push(name.into());
            mass.push(mm);
            dyn_index.push(idx);
            scale.push(lever);
        }
        let (dyn_len, coords): (usize, Vec<usize>) = match &dynamic {
            Dynamic::Rigid(m) => (FULL, RigidSystem::new(m).coords.clone()),
            Dynamic::Compliant(m) => (m.full_len(), m.coords.clone()),
        };
        let mut dyn_pos = vec![None; dyn_len];
        for (k, &i) in coords.iter().enumerate() {
            dyn_pos[i] = Some(k);
        }
        if let Some(&i) = dyn_index
            .iter()
            .find(|&&i| dyn_pos.get(i).is_none_or(|p| p.is_none()))
        {
            return Err(RvdynError::Parameter(format!(
                "coordinate {i} of the linearisation is not free in the dynamic model"
            )));
        }
        if let Some((i, m)) = mass
            .iter()
            .enumerate()
            .find(|(_, m): &(usize, &f64)| !m.is_finite() || **m <= 0.0)
        {
            return Err(RvdynError::Scene(format!(
                "the coordinate '{}' has mass or inertia {m}: every body needs a positive \
                 mass and inertia (scene.inertias) for a modal analysis",
                names[i]
            )));
        }
        Ok(Self {
            ltca,
            statics,
            families,
            work: Work::new(),
            names,
            mass,
            dynamic,
            frictionless,
            extra,
            dyn_index,
            dyn_pos,
            scale,
            output_shaft: scene.shafts.output,
            input_shaft: scene.shafts.input,
            nodes,
            eccentric_damping,
        })
    }

    /// Names of the coordinates.
    pub fn dof_names(&self) -> &[String] {
        &self.names
    }

    /// Diagonal mass of each coordinate [kg or kg m^2].
    pub fn mass(&self) -> &[f64] {
        &self.mass
    }

    /// The equilibrium at `crank_angle` \[rad\] under the output torque `torque` [N m]
    /// (warm-started from the last one). Errors: non-finite input (`Parameter`); no
    /// equilibrium (`Convergence`, from the LTCA, naming the crank angle and residual).
    pub fn equilibrium(&mut self, torque: f64, crank_angle: f64) -> Result<Equilibrium> {
        require_finite("torque", torque)?;
        require_finite("crank angle", crank_angle)?;
        let (q, rep) = self.ltca.solve_unknowns(torque, crank_angle)?;
        let full = self.statics.full(crank_angle, &q);
        // Static shaft twists: the output shaft carries the torque, the drive shaft the
        // input reaction (docs/model.md, "Modes with machine shafts").
        let (th_c, th_s) = (full[CARRIER], full[SUN]);
        let mut shaft_angles = [th_c, th_s];
        if let Some(sh) = &self.output_shaft {
            shaft_angles[0] = th_c - torque / sh.stiffness;
        }
        if let Some(sh) = &self.input_shaft {
            let n = self.statics.dim();
            let (mut r, mut k) = (vec![0.0; n], Dense::zeros(n));
            self.statics.eval(
                crank_angle,
                &q,
                torque,
                &mut r,
                &mut k,
                &mut self.work,
                None,
            )?;
            shaft_angles[1] = th_s + self.statics.input_reaction(&self.work) / sh.stiffness;
        }
        let dynamic_state = self.dynamic_pose(&full, shaft_angles);
        Ok(Equilibrium {
            crank_angle,
            torque,
            full,
            unknowns: q,
            residual: rep.residual,
            iterations: rep.iterations,
            split_error: 0.0,
            shaft_angles,
            dynamic_state,
            time: 0.0,
            is_equilibrium: true,
        })
    }

    /// The dynamic model's full state at rest from the compliant-style pose and the shaft
    /// angles.
    fn dynamic_pose(&self, full: &[f64], shaft_angles: [f64; 2]) -> (Vec<f64>, Vec<f64>) {
        match &self.dynamic {
            Dynamic::Rigid(_) => {
                let alpha = full[self.statics.crank_index(0) + 2];
                let x = vec![
                    full[CARRIER],
                    alpha,
                    full[SUN],
                    shaft_angles[0],
                    shaft_angles[1],
                ];
                (x, vec![0.0; FULL])
            }
            Dynamic::Compliant(m) => {
                let mut x = vec![0.0; m.full_len()];
                // Without the eccentric deflections of bending cranks (not the model's).
                let body = full.len() - self.nodes;
                x[..body].copy_from_slice(&full[..body]);
                if let Some(i) = m.load_index {
                    x[i] = shaft_angles[0];
                }
                if let Some(i) = m.motor_index {
                    x[i] = shaft_angles[1];
                }
                let n = x.len();
                (x, vec![0.0; n])
            }
        }
    }

    /// The operating point of a state `(q, v)` at time `t` \[s\] of a dynamic run of `scene`
    /// (the scene this linearizer was built from): `q`, `v` in the run model's free
    /// coordinates (`ReducerModel::initial_state` order; rad, m, rad/s, m/s). The pose is
    /// taken as it is (no equilibrium is solved): the held input at its angle at `t`, the
    /// crank angle that puts it there.
    ///
    /// Errors: a scene with `crank_shaft` (`Scene`); a scene with other joints or shafts, a state of the wrong length or not
    /// finite (`Parameter`).
    pub fn state_point(&self, scene: &Scene, t: f64, q: &[f64], v: &[f64]) -> Result<Equilibrium> {
        require_finite("time", t)?;
        if self.nodes > 0 {
            return Err(RvdynError::Scene(
                "modes about a dynamic state of a scene with crank_shaft are not available (the \
                 run's eccentrics carry mass, the linearisation condenses them as massless): \
                 linearise about an equilibrium instead (rvdyn.modes(scene, torque, crank_angle))"
                    .into(),
            ));
        }
        if !q.iter().chain(v).all(|x| x.is_finite()) {
            return Err(RvdynError::Parameter(
                "the state (q, v) must be finite".into(),
            ));
        }
        let wrong = |n: usize| {
            RvdynError::Parameter(format!(
                "the state has {} coordinates and {} velocities, but the model of this scene \
                 has {n} free coordinates (ReducerModel::initial_state order)",
                q.len(),
                v.len()
            ))
        };
        let st = &self.statics;
        let has_mesh = st.model.mesh.is_some();
        // d(held input)/d(crank angle) (the map is linear through 0).
        let gear = st.held_input(1.0);
        let (x, xv, psi, unknowns, shaft_angles) = match (&self.dynamic, &scene.joints) {
            (Dynamic::Rigid(_), Joints::Rigid) => {
                let m = RigidModel::new(scene)?;
                let sys = RigidSystem::new(&m);
                if q.len() != sys.coords.len() || v.len() != sys.coords.len() {
                    return Err(wrong(sys.coords.len()));
                }
                let (x, xv, _) = sys.full(t, q, v);
                let (psi, u) = if has_mesh {
                    (x[RSUN] / gear, vec![x[CARRIER], x[1]])
                } else {
                    (x[1], vec![x[CARRIER]])
                };
                (x.to_vec(), xv.to_vec(), psi, u, [x[LOAD], x[MOTOR]])
            }
            (Dynamic::Compliant(_), Joints::Compliant { .. }) => {
                let m = CompliantModel::new(scene)?;
                if q.len() != m.coords.len() || v.len() != m.coords.len() {
                    return Err(wrong(m.coords.len()));
                }
                let (x, xv, _) = m.full(t, q, v);
                let psi = if has_mesh {
                    x[SUN] / gear
                } else {
                    x[st.crank_index(0) + 2]
                };
                let u: Vec<f64> = st.unknowns.iter().map(|&i| x[i]).collect();
                let sa = [
                    m.load_index.map_or(x[CARRIER], |i| x[i]),
                    m.motor_index.map_or(x[SUN], |i| x[i]),
                ];
                (x, xv, psi, u, sa)
            }
            _ => {
                return Err(RvdynError::Parameter(
                    "the state's scene has other joints than the linearizer's".into(),
                ));
            }
        };
        let full = st.full(psi, &unknowns);
        Ok(Equilibrium {
            crank_angle: psi,
            torque: st.model.load.torque(t),
            full,
            unknowns,
            residual: f64::NAN,
            iterations: 0,
            split_error: 0.0,
            shaft_angles,
            dynamic_state: (x, xv),
            time: t,
            is_equilibrium: false,
        })
    }

    /// Linearise about the equilibrium at `crank_angle` \[rad\] and output torque `torque`
    /// [N m]: the system `(M, K parts, C)` and the equilibrium it was taken at.
    pub fn linearise(
        &mut self,
        torque: f64,
        crank_angle: f64,
    ) -> Result<(LinearSystem, Equilibrium)> {
        let eq = self.equilibrium(torque, crank_angle)?;
        self.linearise_about(eq)
    }

    /// Linearise about an operating point (an equilibrium or a dynamic state from
    /// [`Linearizer::state_point`]). The stiffness parts: the analytic static tangent of each
    /// family of couplings at the pose, the shafts (`k_o`, `k_i`, exact), and at a moving
    /// state the rate-dependent stiffness `K_fd(q, v) - K_fd(q, 0)` (finite differences of the
    /// dynamic force: contact damping `c(pen) pen'` and friction at speed).
    pub fn linearise_about(&mut self, mut eq: Equilibrium) -> Result<(LinearSystem, Equilibrium)> {
        let n = self.names.len();
        let k_big = self.reducer_stiffness(&eq)?;
        // Bending crankshafts: the eccentric deflections are condensed out, `K -> T^T K T`
        // for the whole tangent and for each part alike (so the parts still add up).
        let t = self.condensation(&k_big, &eq)?;
        let small = |k: DMatrix<f64>| match &t {
            Some(t) => t.transpose() * k * t,
            None => k,
        };
        let mut k_all = small(k_big);
        let mut parts = Vec::with_capacity(self.families.len() + 2);
        let mut sum = DMatrix::<f64>::zeros(n, n);
        let mut eccentric = None;
        for (name, fam) in self.families.clone() {
            self.statics.family = Some(fam);
            let k = self.reducer_stiffness(&eq);
            self.statics.family = None;
            let k = small(k?);
            sum += &k;
            if self.nodes > 0 && fam == Family::EccentricBearings {
                eccentric = Some(k.clone());
            }
            parts.push(StiffnessPart { name, matrix: k });
        }
        if let Some(ks) = self.shaft_stiffness().map(small) {
            k_all += &ks;
            sum += &ks;
            parts.push(StiffnessPart {
                name: "shafts".into(),
                matrix: ks,
            });
        }
        if eq.dynamic_state.1.iter().any(|v| *v != 0.0) {
            let rate = &self.fd_stiffness(&eq, true)? - &self.fd_stiffness(&eq, false)?;
            k_all += &rate;
            sum += &rate;
            parts.push(StiffnessPart {
                name: "rate-dependent".into(),
                matrix: rate,
            });
        }
        let norm = k_all.norm();
        eq.split_error = if norm > 0.0 {
            (&sum - &k_all).norm() / norm
        } else {
            0.0
        };
        let mut damping = self.damping_matrix(&eq)?;
        if let Some(k) = eccentric {
            damping += k * self.eccentric_damping;
        }
        let sys = LinearSystem {
            dof_names: self.names.clone(),
            mass: DMatrix::from_diagonal(&DVector::from_vec(self.mass.clone())),
            stiffness: parts,
            damping,
            length_scale: self.scale.clone(),
        };
        Ok((sys, eq))
    }

    /// With bending crankshafts, the static condensation of the eccentric deflections (the
    /// nodes, massless): `T` (big x small) with the identity on the kept coordinates and
    /// `-K_nn^-1 K_nk` on the nodes, so that `T^T K T` is the stiffness the kept coordinates
    /// see with each node in balance (Guyan 1965). `None` without bending.
    pub(crate) fn condensation(
        &self,
        k: &DMatrix<f64>,
        eq: &Equilibrium,
    ) -> Result<Option<DMatrix<f64>>> {
        if self.nodes == 0 {
            return Ok(None);
        }
        let n = self.names.len();
        let nn = self.nodes;
        let first = self.statics.dim() - nn;
        let big = |a: usize| if a < first { a } else { a + nn };
        let knn = k.view((first, first), (nn, nn)).into_owned();
        let knk = DMatrix::from_fn(nn, n, |r, a| k[(first + r, big(a))]);
        let lu = knn.lu();
        let Some(x) = lu.solve(&knk).filter(|x| x.iter().all(|v| v.is_finite())) else {
            return Err(RvdynError::Convergence(format!(
                "the crankshafts' bending stiffness at crank angle {:.6} rad is singular: no \
                 static condensation of the eccentric deflections (check crank_shaft)",
                eq.crank_angle
            )));
        };
        let mut t = DMatrix::<f64>::zeros(n + nn, n);
        for a in 0..n {
            t[(big(a), a)] = 1.0;
            for r in 0..nn {
                t[(first + r, a)] = -x[(r, a)];
            }
        }
        Ok(Some(t))
    }

    /// The analytic tangent stiffness `-dQ/dq` of the LTCA unknowns at an equilibrium [N/m,
    /// N m/rad, N] (of the family set on the statics, or of all couplings).
    pub fn tangent_stiffness(&mut self, eq: &Equilibrium) -> Result<DMatrix<f64>> {
        let st = &mut self.statics;
        let n = st.dim();
        let mut r = vec![0.0; n];
        let mut k = Dense::zeros(n);
        st.eval(
            eq.crank_angle,
            &eq.unknowns,
            eq.torque,
            &mut r,
            &mut k,
            &mut self.work,
            None,
        )?;
        Ok(DMatrix::from_row_slice(n, n, &k.a))
    }

    /// The reducer's analytic tangent stiffness on all the linearisation's coordinates (with
    /// bending crankshafts before their condensation: the eccentric deflections after the
    /// other LTCA unknowns, the shafts' coordinates after them): that
    /// of the LTCA unknowns, and with a drive shaft the sun's row and column (`J^T K_full e_s`
    /// with the map Jacobian `J` of the unknowns; the sun enters the map linearly).
    pub(crate) fn reducer_stiffness(&mut self, eq: &Equilibrium) -> Result<DMatrix<f64>> {
        let k0 = self.tangent_stiffness(eq)?;
        let n0 = k0.nrows();
        let n = self.names.len() + self.nodes;
        let mut k = DMatrix::<f64>::zeros(n, n);
        k.view_mut((0, 0), (n0, n0)).copy_from(&k0);
        if let Some(s) = self.extra.iter().position(|e| *e == Extra::Sun) {
            let s = n0 + s;
            let kf = &self.work.kf;
            let jac = self.map_jacobian(&eq.full);
            for (a, col) in jac.iter().enumerate() {
                k[(a, s)] = col.iter().map(|&(i, w)| w * kf.at(i, SUN)).sum();
                k[(s, a)] = col.iter().map(|&(i, w)| w * kf.at(SUN, i)).sum();
            }
            k[(s, s)] = kf.at(SUN, SUN);
        }
        Ok(k)
    }

    /// Columns of the map from the LTCA unknowns to the full coordinates at the pose `x`
    /// (as `Statics::eval` builds them): `(full index, d x_i / d q_a)`.
    fn map_jacobian(&self, x: &[f64]) -> Vec<Vec<(usize, f64)>> {
        let st = &self.statics;
        let m = &st.model;
        let n = st.dim();
        let seat = |i: usize| {
            let a = x[CARRIER] + std::f64::consts::TAU * i as f64 / st.cranks as f64;
            [m.crank_radius * a.cos(), m.crank_radius * a.sin()]
        };
        let mut jac = vec![Vec::new(); n];
        match st.kind {
            Kind::Rigid => {
                jac[0].push((CARRIER, 1.0));
                for k in 0..m.discs.len() {
                    jac[0].push((st.disc_index(k) + 2, 1.0));
                }
                for i in 0..st.cranks {
                    let p = seat(i);
                    let ci = st.crank_index(i);
                    jac[0].push((ci, -p[1]));
                    jac[0].push((ci + 1, p[0]));
                }
                if n == 2 {
                    for i in 0..st.cranks {
                        jac[1].push((st.crank_index(i) + 2, 1.0));
                    }
                    for k in 0..m.discs.len() {
                        let dk = st.disc_index(k);
                        jac[1].push((dk, -x[dk + 1]));
                        jac[1].push((dk + 1, x[dk]));
                    }
                }
            }
            Kind::Compliant => {
                for (a, &i) in st.unknowns.iter().enumerate() {
                    jac[a].push((i, 1.0));
                    if i == CARRIER && st.crank_bearing.is_none() {
                        for c in 0..st.cranks {
                            let p = seat(c);
                            let ci = st.crank_index(c);
                            jac[a].push((ci, -p[1]));
                            jac[a].push((ci + 1, p[0]));
                        }
                    }
                }
            }
        }
        jac
    }

    /// The shafts' stiffness on the linearisation's coordinates (exact: linear springs);
    /// `None` without shafts. A drive shaft with the motor held ties the sun to the ground.
    fn shaft_stiffness(&self) -> Option<DMatrix<f64>> {
        if self.extra.is_empty() {
            return None;
        }
        let n = self.names.len() + self.nodes;
        let n0 = self.statics.dim();
        let at = |e: Extra| self.extra.iter().position(|x| *x == e).map(|p| n0 + p);
        let mut k = DMatrix::<f64>::zeros(n, n);
        let mut spring = |a: usize, b: Option<usize>, kk: f64| {
            k[(a, a)] += kk;
            if let Some(b) = b {
                k[(b, b)] += kk;
                k[(a, b)] -= kk;
                k[(b, a)] -= kk;
            }
        };
        if let (Some(sh), Some(l)) = (&self.output_shaft, at(Extra::Load)) {
            spring(l, Some(0), sh.stiffness);
        }
        if let (Some(sh), Some(s)) = (&self.input_shaft, at(Extra::Sun)) {
            spring(s, at(Extra::Motor), sh.stiffness);
        }
        Some(k)
    }

    /// The dynamic model's generalised force on the linearisation's coordinates at the
    /// operating point's state displaced by `dq` with velocities changed by `v` (no load and
    /// no drive torque: only derivatives of it are meaningful) [N, N m]. `dq`, `v`: one entry
    /// per coordinate.
    pub fn dynamic_force(&self, eq: &Equilibrium, dq: &[f64], v: &[f64]) -> Result<Vec<f64>> {
        self.force_at(eq, dq, v, true)
    }

    /// [`Linearizer::dynamic_force`], about the state's velocities or (`moving = false`) at
    /// rest.
    fn force_at(&self, eq: &Equilibrium, dq: &[f64], v: &[f64], moving: bool) -> Result<Vec<f64>> {
        let n = self.names.len();
        if dq.len() != n || v.len() != n {
            return Err(RvdynError::Parameter(format!(
                "dq and v need {n} entries each, got {} and {}",
                dq.len(),
                v.len()
            )));
        }
        let (x, xv) = &eq.dynamic_state;
        let nc = self.dyn_pos.iter().flatten().count();
        let mut qc = vec![0.0; nc];
        let mut vc = vec![0.0; nc];
        for (i, p) in self.dyn_pos.iter().enumerate() {
            if let Some(p) = *p {
                qc[p] = x[i];
                vc[p] = if moving { xv[i] } else { 0.0 };
            }
        }
        let pos: Vec<usize> = self
            .dyn_index
            .iter()
            .map(|&i| self.dyn_pos[i].unwrap_or(0))
            .collect();
        for (a, &p) in pos.iter().enumerate() {
            qc[p] += dq[a];
            vc[p] += v[a];
        }
        let mut f = vec![0.0; nc];
        let model = match (&self.frictionless, eq.is_equilibrium) {
            (Some(m), true) => m,
            _ => &self.dynamic,
        };
        match model {
            Dynamic::Rigid(m) => {
                RigidSystem::new(m).generalized_force(eq.time, &qc, &vc, &mut f)?
            }
            Dynamic::Compliant(m) => m.generalized_force(eq.time, &qc, &vc, &mut f)?,
        }
        Ok(pos.iter().map(|&p| f[p]).collect())
    }

    /// `K = -dQ/dq` by forward differences of the dynamic force (the perturbations of
    /// `solve::jacobian`), about the state's velocities or at rest.
    fn fd_stiffness(&self, eq: &Equilibrium, moving: bool) -> Result<DMatrix<f64>> {
        use crate::solve::jacobian::DISPLACEMENT_STEP;
        let n = self.names.len();
        let zero = vec![0.0; n];
        let f0 = self.force_at(eq, &zero, &zero, moving)?;
        let mut k = DMatrix::<f64>::zeros(n, n);
        let mut dq = vec![0.0; n];
        for b in 0..n {
            let h = DISPLACEMENT_STEP / self.scale[b];
            dq[b] = h;
            let f1 = self.force_at(eq, &dq, &zero, moving)?;
            dq[b] = 0.0;
            for a in 0..n {
                k[(a, b)] = -(f1[a] - f0[a]) / h;
            }
        }
        Ok(k)
    }

    /// `C = -dQ/dv` by forward differences of 1 um/s (exact for rate-linear damping laws while
    /// the contacts stay pushing).
    fn damping_matrix(&self, eq: &Equilibrium) -> Result<DMatrix<f64>> {
        let n = self.names.len();
        let zero = vec![0.0; n];
        let q0 = self.dynamic_force(eq, &zero, &zero)?;
        let mut c = DMatrix::<f64>::zeros(n, n);
        let mut v = vec![0.0; n];
        for b in 0..n {
            // 1 um/s at the coordinate's lever. The rate-linear laws make any step exact while
            // the contact force stays positive, but 1 mm/s times a damper of 1e7 N s/m is 10 kN,
            // more than a lightly loaded contact carries: the force was clipped at zero and C
            // came out asymmetric and indefinite (damping ratio -0.45 seen).
            let dv = 1e-6 / self.scale[b];
            v[b] = dv;
            let q1 = self.dynamic_force(eq, &zero, &v)?;
            v[b] = 0.0;
            for a in 0..n {
                c[(a, b)] = -(q1[a] - q0[a]) / dv;
            }
        }
        Ok(c)
    }
}

/// Names of the full compliant-style coordinates.
fn full_names(st: &Statics) -> Vec<String> {
    let mut v = vec!["carrier angle".to_string(), "sun angle".to_string()];
    for i in 0..st.cranks {
        v.extend([
            format!("crank {i} x"),
            format!("crank {i} y"),
            format!("crank {i} angle"),
        ]);
    }
    for k in 0..st.model.discs.len() {
        v.extend([
            format!("disc {k} x"),
            format!("disc {k} y"),
            format!("disc {k} angle"),
        ]);
    }
    v
}
