//! The compliance budget: where the torsional compliance of the loaded reducer comes from.
//!
//! At an equilibrium with the input held, a small extra output torque `dT` turns the unknowns by
//! `dq = -K^-1 e_0 dT` (the output angle is unknown 0 and the load enters as `-T e_0`), so the
//! tangent compliance is `c = (K^-1)_00 = d^T K d` with `d = K^-1 e_0`. The tangent is the sum of
//! the families' parts, `K = sum_f K_f` ([`Statics::families`]), hence
//!
//! ```text
//! c = sum_f c_f,   c_f = d^T K_f d
//! ```
//!
//! the strain energy that family `f` stores per unit of torque squared (twice it): the part of
//! the twist that family gives. It is also `-dc/ds_f`, the change of the compliance when family
//! `f`'s stiffness is scaled by `s_f` (tested against finite differences of that scaling).
//! Formulation and sources: docs/model.md, "Compliance budget".

use serde::Serialize;

use super::Ltca;
use super::newton::solve_dense;
use super::statics::Dense;
use crate::error::{Result, RvdynError};

/// The compliance budget at one crank angle over a set of torques.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ComplianceBudget {
    /// Crank angle \[rad\].
    pub crank_angle: f64,
    /// Output torques \[N m\], as given.
    pub torque: Vec<f64>,
    /// The families, named as in [`super::statics::Statics::families`].
    pub parts: Vec<String>,
    /// Tangent compliance of each family at each torque, `[torque][part]` [rad/(N m)]: they sum
    /// to the reducer's tangent compliance. A family whose geometric stiffness (forces turning
    /// with the bodies) outweighs its elastic one can give a small negative part.
    pub compliance: Vec<Vec<f64>>,
    /// The reducer's tangent torsional stiffness `dT / d twist` at each torque [N m/rad].
    pub torsional_stiffness: Vec<f64>,
    /// `|sum_f c_f - c| / c` at each torque: how well the parts add up (round-off).
    pub split_error: Vec<f64>,
}

impl Ltca {
    /// The compliance budget at crank angle `psi` \[rad\] for each output torque in `torques`
    /// [N m] (each equilibrium warm-started from the previous; without friction).
    ///
    /// Errors: a torque that is zero or not finite, a crank angle that is not finite
    /// (`Parameter`); no equilibrium, or one whose tangent is singular (bodies free in their
    /// clearances: `Convergence`, naming the torque and the fix).
    pub fn compliance_budget(&mut self, torques: &[f64], psi: f64) -> Result<ComplianceBudget> {
        super::require_points("torques", torques.len())?;
        let families = self.statics.families();
        let mut out = ComplianceBudget {
            crank_angle: psi,
            torque: torques.to_vec(),
            parts: families.iter().map(|(n, _)| n.clone()).collect(),
            compliance: Vec::with_capacity(torques.len()),
            torsional_stiffness: Vec::with_capacity(torques.len()),
            split_error: Vec::with_capacity(torques.len()),
        };
        for &torque in torques {
            if torque == 0.0 {
                return Err(RvdynError::Parameter(
                    "a torque of the compliance budget is 0 N m: at zero torque any pose inside \
                     the clearances is an equilibrium and the tangent is not defined; give a \
                     small torque instead (e.g. 1e-3 of the rated torque)"
                        .into(),
                ));
            }
            let (q, _) = self.solve_unknowns(torque, psi)?;
            let n = self.statics.dim();
            let mut r = vec![0.0; n];
            let mut k = Dense::zeros(n);
            self.statics
                .eval(psi, &q, torque, &mut r, &mut k, &mut self.work, None)?;
            let mut d = vec![0.0; n];
            d[0] = 1.0;
            let kk = k.clone();
            if !(solve_dense(&mut k, &mut d) && d[0] > 0.0 && d[0].is_finite()) {
                return Err(RvdynError::Convergence(format!(
                    "at crank angle {psi} rad and torque {torque} N m the equilibrium has no \
                     torsional stiffness (a body is free in its clearances: the tangent is \
                     singular); give a larger torque"
                )));
            }
            let total = d[0];
            let mut parts = Vec::with_capacity(families.len());
            for (_, fam) in &families {
                self.statics.family = Some(*fam);
                let res = self
                    .statics
                    .eval(psi, &q, torque, &mut r, &mut k, &mut self.work, None);
                self.statics.family = None;
                res?;
                parts.push(quadratic_form(&k, &d));
            }
            let sum: f64 = parts.iter().sum();
            // The whole tangent's own form, to say how well the parts add up.
            let whole = quadratic_form(&kk, &d);
            out.split_error
                .push(((sum - total).abs()).max((whole - total).abs()) / total);
            out.compliance.push(parts);
            out.torsional_stiffness.push(1.0 / total);
        }
        Ok(out)
    }
}

/// `d^T K d`.
fn quadratic_form(k: &Dense, d: &[f64]) -> f64 {
    let n = k.n;
    (0..n)
        .map(|i| d[i] * (0..n).map(|j| k.a[i * n + j] * d[j]).sum::<f64>())
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::ltca::tests::linear;
    use crate::dynamics::model::compliant::default_joints;
    use crate::dynamics::scene::{Joints, Scene};

    /// The paper scene with linear laws everywhere and compliant joints without clearance:
    /// each family's stiffness scaled by `s` (pins, mesh, eccentric and crank bearings).
    fn linear_scene(s: [f64; 4]) -> Scene {
        let mut sc = Scene::paper("rated").unwrap();
        sc.contact.pin = linear(1e9 * s[0]);
        sc.contact.mesh = linear(6e8 * s[1]);
        let mut j = default_joints();
        if let Joints::Compliant {
            eccentric_bearing,
            crank_bearing,
        } = &mut j
        {
            eccentric_bearing.stiffness *= s[2];
            crank_bearing.as_mut().unwrap().stiffness *= s[3];
        }
        sc.joints = j;
        sc
    }

    fn compliance(s: [f64; 4], torque: f64, psi: f64) -> f64 {
        let mut l = Ltca::new(&linear_scene(s)).unwrap();
        1.0 / l.solve(torque, psi).unwrap().torsional_stiffness
    }

    /// With linear laws `K = sum_f s_f K_f`, so `dc/ds_f = -d^T K_f d = -c_f` at `s = 1`: each
    /// family's part equals the central difference of the compliance of scenes with that
    /// family's stiffness scaled by `1 +- 1e-4` (an independent computation: new scenes, new
    /// equilibria). What the identity leaves out: the equilibrium moves with `s_f`, which changes
    /// the levers and the geometric stiffness in proportion to the load (measured on the pins'
    /// part: 3.2e-4 of it at 1e-2 of the rated torque, 3.2e-5 at 1e-3, where the test runs; the
    /// other parts 2e-6 and less); the difference's truncation `(1e-4)^2` and the round-off of
    /// compliances solved to 1e-12, divided by 2e-4. Asserted: 1e-4 of each part (the mesh's is
    /// 4e-3 of the compliance: the first stage is referred to the output through the ratio).
    #[test]
    fn each_part_is_the_compliance_change_of_scaling_its_family() {
        let torque = 0.001 * Scene::paper("rated").unwrap().load.torque(0.0);
        let psi = 0.3;
        let mut l = Ltca::new(&linear_scene([1.0; 4])).unwrap();
        let b = l.compliance_budget(&[torque], psi).unwrap();
        assert_eq!(
            b.parts,
            [
                "pin contacts disc 0",
                "pin contacts disc 1",
                "sun/planet meshes",
                "eccentric bearings",
                "crank bearings"
            ]
        );
        let c = 1.0 / b.torsional_stiffness[0];
        let parts = &b.compliance[0];
        // Both discs' pins share the pin law.
        let expected = [parts[0] + parts[1], parts[2], parts[3], parts[4]];
        let h = 1e-4;
        for (f, want) in expected.iter().enumerate() {
            let mut up = [1.0; 4];
            let mut down = [1.0; 4];
            up[f] += h;
            down[f] -= h;
            let fd = -(compliance(up, torque, psi) - compliance(down, torque, psi)) / (2.0 * h);
            assert!(
                (fd - want).abs() < 1e-4 * want,
                "family {f}: finite differences {fd:e}, budget {want:e}, compliance {c:e}"
            );
            assert!(
                *want > 1e-3 * c,
                "family {f} is a real part: {want:e} of {c:e}"
            );
        }
        assert!(b.split_error[0] < 1e-10, "{:e}", b.split_error[0]);
    }

    /// On the physical preset (nonlinear laws, roller bearings with clearance) at the rated
    /// torque: the parts sum to the tangent compliance of the LTCA point, every part is
    /// positive, and both discs' pins give the same part within 5 % (the discs carry equal
    /// halves of the torque, half a pin pitch apart in their pattern).
    #[test]
    fn physical_preset_budget_adds_up_to_the_torsional_stiffness() {
        let sc = Scene::physical("rated").unwrap();
        let torque = sc.load.torque(0.0);
        let mut l = Ltca::new(&sc).unwrap();
        let p = l.solve(torque, 0.0).unwrap();
        let b = l.compliance_budget(&[torque, -torque], 0.0).unwrap();
        for (i, parts) in b.compliance.iter().enumerate() {
            let c: f64 = parts.iter().sum();
            assert!(parts.iter().all(|&x| x > 0.0), "{parts:?}");
            assert!((c * b.torsional_stiffness[i] - 1.0).abs() < 1e-10);
            assert!(
                ((parts[0] - parts[1]) / (parts[0] + parts[1])).abs() < 0.05,
                "{parts:?}"
            );
        }
        assert!((b.torsional_stiffness[0] / p.torsional_stiffness - 1.0).abs() < 1e-9);
    }

    #[test]
    fn zero_torque_and_non_finite_input_are_refused() {
        let mut l = Ltca::new(&Scene::physical("rated").unwrap()).unwrap();
        let e = l.compliance_budget(&[0.0], 0.0).unwrap_err();
        assert!(matches!(e, RvdynError::Parameter(_)), "{e}");
        assert!(e.to_string().contains("small torque"), "{e}");
        for (t, psi) in [(f64::NAN, 0.0), (1e3, f64::INFINITY)] {
            let e = l.compliance_budget(&[t], psi).unwrap_err();
            assert!(matches!(e, RvdynError::Parameter(_)), "{e}");
        }
    }
}
