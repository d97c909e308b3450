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
use crate::analysis::modal::{LinearSystem, StiffnessPart};
use crate::dynamics::model::ReducerModel;
use crate::dynamics::model::compliant::CompliantModel;
use crate::dynamics::model::rigid::RigidModel;
use crate::dynamics::model::rigid_system::RigidSystem;
use crate::dynamics::scene::{Drive, Joints, Load, Scene};
use crate::error::{Result, RvdynError, require_finite};
use nalgebra::{DMatrix, DVector};

/// The dynamic model whose generalised force gives the damping (and checks the stiffness),
/// built with a zero torque drive and no load: the input is a free coordinate held at the
/// equilibrium's angle, and only derivatives of the force are used.
enum Dynamic {
    /// Rigid joints; the position of each free coordinate of the model in `[th_c, alpha, th_s]`
    /// is the model's own `free` list.
    Rigid(Box<RigidModel>),
    /// Compliant joints and the position of each full coordinate in the model's free list.
    Compliant(Box<CompliantModel>, Vec<Option<usize>>),
}

/// The operating point a linearisation was taken at.
#[derive(Debug, Clone, PartialEq)]
pub struct Equilibrium {
    /// Crank angle [rad].
    pub crank_angle: f64,
    /// Output torque [N m].
    pub torque: f64,
    /// The LTCA unknowns at equilibrium (the linearisation's coordinates).
    pub unknowns: Vec<f64>,
    /// Full compliant-style coordinates at equilibrium.
    pub full: Vec<f64>,
    /// Largest equilibrium residual relative to the load scale.
    pub residual: f64,
    /// Newton iterations of the equilibrium.
    pub iterations: usize,
    /// `|sum_p K_p - K|_F / |K|_F` of the stiffness split.
    pub split_error: f64,
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
        let mut families: Vec<(String, Family)> = (0..statics.model.discs.len())
            .map(|d| (format!("pin contacts disc {d}"), Family::Pins(d)))
            .collect();
        if statics.model.mesh.is_some() {
            families.push(("sun/planet meshes".into(), Family::Mesh));
        }
        if statics.kind == Kind::Compliant {
            families.push(("eccentric bearings".into(), Family::EccentricBearings));
            if statics.crank_bearing.is_some() {
                families.push(("crank bearings".into(), Family::CrankBearings));
            }
        }
        let mut free_scene = scene.clone();
        free_scene.drive = Drive::Torque {
            torque: 0.0,
            ramp_time: 0.0,
        };
        free_scene.load = Load::Idle;
        // Only forces are evaluated: the initial state does not matter (and a steady start
        // needs a speed drive).
        free_scene.initial = crate::dynamics::scene::Initial::Rest;
        let full = full_names(&statics);
        let (names, mass, dynamic) = match scene.joints {
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
                let names = statics.unknowns.iter().map(|&i| full[i].clone()).collect();
                let mass = statics.unknowns.iter().map(|&i| m.mass[i]).collect();
                let mut pos = vec![None; m.full_len()];
                for (k, &i) in m.free.iter().enumerate() {
                    pos[i] = Some(k);
                }
                (names, mass, Dynamic::Compliant(Box::new(m), pos))
            }
        };
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

    /// The equilibrium at `crank_angle` [rad] under the output torque `torque` [N m]
    /// (warm-started from the last one). Errors: non-finite input (`Parameter`); no
    /// equilibrium (`Convergence`, from the LTCA, naming the crank angle and residual).
    pub fn equilibrium(&mut self, torque: f64, crank_angle: f64) -> Result<Equilibrium> {
        require_finite("torque", torque)?;
        require_finite("crank angle", crank_angle)?;
        let (q, rep) = self.ltca.solve_unknowns(torque, crank_angle)?;
        Ok(Equilibrium {
            crank_angle,
            torque,
            full: self.statics.full(crank_angle, &q),
            unknowns: q,
            residual: rep.residual,
            iterations: rep.iterations,
            split_error: 0.0,
        })
    }

    /// Linearise about the equilibrium at `crank_angle` [rad] and output torque `torque`
    /// [N m]: the system `(M, K parts, C)` and the equilibrium it was taken at.
    pub fn linearise(
        &mut self,
        torque: f64,
        crank_angle: f64,
    ) -> Result<(LinearSystem, Equilibrium)> {
        let mut eq = self.equilibrium(torque, crank_angle)?;
        let n = self.names.len();
        let k_all = self.tangent_stiffness(&eq)?;
        let mut parts = Vec::with_capacity(self.families.len());
        let mut sum = DMatrix::<f64>::zeros(n, n);
        for (name, fam) in self.families.clone() {
            self.statics.family = Some(fam);
            let k = self.tangent_stiffness(&eq);
            self.statics.family = None;
            let k = k?;
            sum += &k;
            parts.push(StiffnessPart { name, matrix: k });
        }
        let norm = k_all.norm();
        eq.split_error = if norm > 0.0 {
            (&sum - &k_all).norm() / norm
        } else {
            0.0
        };
        let damping = self.damping_matrix(&eq)?;
        let sys = LinearSystem {
            dof_names: self.names.clone(),
            mass: DMatrix::from_diagonal(&DVector::from_vec(self.mass.clone())),
            stiffness: parts,
            damping,
            length_scale: self.statics.scale.clone(),
        };
        Ok((sys, eq))
    }

    /// The analytic tangent stiffness `-dQ/dq` at an equilibrium [N/m, N m/rad, N] (of the
    /// family set on the statics, or of all couplings).
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

    /// The dynamic model's generalised force on the linearisation's coordinates at the
    /// equilibrium pose displaced by `dq` with velocities `v` (no load and no drive torque:
    /// only derivatives of it are meaningful) [N, N m]. `dq`, `v`: one entry per coordinate.
    pub fn dynamic_force(&self, eq: &Equilibrium, dq: &[f64], v: &[f64]) -> Result<Vec<f64>> {
        let n = self.names.len();
        if dq.len() != n || v.len() != n {
            return Err(RvdynError::Parameter(format!(
                "dq and v need {n} entries each, got {} and {}",
                dq.len(),
                v.len()
            )));
        }
        match &self.dynamic {
            Dynamic::Rigid(m) => {
                // [th_c, alpha, th_s]; the unknowns are th_c and (with a first stage) alpha.
                let alpha = if n == 2 {
                    eq.unknowns[1]
                } else {
                    eq.crank_angle
                };
                let mut x = [eq.full[CARRIER], alpha, eq.full[SUN]];
                let mut xv = [0.0; 3];
                for (xa, d) in x.iter_mut().zip(dq) {
                    *xa += d;
                }
                xv[..n].copy_from_slice(v);
                let sys = RigidSystem::new(m);
                let q: Vec<f64> = m.free.iter().map(|&i| x[i]).collect();
                let qv: Vec<f64> = m.free.iter().map(|&i| xv[i]).collect();
                let mut f = vec![0.0; q.len()];
                sys.generalized_force(0.0, &q, &qv, &mut f)?;
                (0..n)
                    .map(|a| {
                        m.free
                            .iter()
                            .position(|&i| i == a)
                            .map(|k| f[k])
                            .ok_or_else(|| {
                                RvdynError::Parameter(
                                    "coordinate maps differ between models".into(),
                                )
                            })
                    })
                    .collect()
            }
            Dynamic::Compliant(m, pos) => {
                let nf = m.free.len();
                let mut qf = vec![0.0; nf];
                let mut vf = vec![0.0; nf];
                for (k, &i) in m.free.iter().enumerate() {
                    qf[k] = eq.full[i];
                }
                let mut at = Vec::with_capacity(n);
                for (a, &i) in self.statics.unknowns.iter().enumerate() {
                    let k = pos[i].ok_or_else(|| {
                        RvdynError::Parameter("coordinate maps differ between models".into())
                    })?;
                    qf[k] += dq[a];
                    vf[k] = v[a];
                    at.push(k);
                }
                let mut f = vec![0.0; nf];
                m.generalized_force(0.0, &qf, &vf, &mut f)?;
                Ok(at.into_iter().map(|k| f[k]).collect())
            }
        }
    }

    /// `C = -dQ/dv` by forward differences (exact for rate-linear damping laws).
    fn damping_matrix(&self, eq: &Equilibrium) -> Result<DMatrix<f64>> {
        let n = self.names.len();
        let zero = vec![0.0; n];
        let q0 = self.dynamic_force(eq, &zero, &zero)?;
        let mut c = DMatrix::<f64>::zeros(n, n);
        let mut v = vec![0.0; n];
        for b in 0..n {
            // 1 mm/s at the coordinate's lever: small against any separation speed.
            let dv = 1e-3 / self.statics.scale[b];
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

/// Whether a scene has compliant joints.
pub fn is_compliant(scene: &Scene) -> bool {
    matches!(scene.joints, Joints::Compliant { .. })
}
