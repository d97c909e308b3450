//! Bending of a crankshaft between its two bearings: the flexibility of the eccentrics (the
//! disc centre planes) under radial loads, for the quasi-static analyses (docs/model.md,
//! "Crankshaft bending").
//!
//! The shaft is a Timoshenko beam of one round section (bending `E I`, `I = pi d^4 / 64`, and
//! shear `kappa G A`, `A = pi d^2 / 4`, Cowper's `kappa = 6 (1 + nu) / (7 + 6 nu)`): a crank is
//! short and thick, and shear adds about `2.2 (d / L)^2` of the bending deflection (30 % for a
//! 45 mm shaft on a 120 mm span). It is simply supported at the two bearings' mid-planes (their
//! radial compliance is the lumped crank bearing's) and loaded at the discs' mid-planes. Its
//! deflection is taken relative to the line through the two supports: the planar models' crank
//! centre stands for that line. Beam elements with the shear parameter `Phi = 12 E I / (kappa G
//! A L^2)` and nodes at the supports and the loads are exact for point loads at nodes
//! (Przemieniecki 1968, the beam element with shear deformation), so the flexibility below is
//! the closed form of beam theory for any layout, overhangs included.

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

use super::CrankLayout;
use crate::error::{Result, RvdynError};

/// Young's modulus of steel \[Pa\], the default of [`CrankShaft::modulus`].
pub const STEEL_MODULUS: f64 = 2.06e11;

/// Poisson's ratio of steel, the default of [`CrankShaft::poisson`].
pub const STEEL_POISSON: f64 = 0.3;

fn steel() -> f64 {
    STEEL_MODULUS
}

fn steel_poisson() -> f64 {
    STEEL_POISSON
}

/// A crankshaft's section for its bending (a scene's `crank_shaft`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CrankShaft {
    /// Diameter of the solid round shaft between the bearings \[m\].
    pub diameter: f64,
    /// Young's modulus \[Pa\] (default steel, 206 GPa).
    #[serde(default = "steel")]
    pub modulus: f64,
    /// Poisson's ratio \[-\] (default steel, 0.3), for the shear modulus.
    #[serde(default = "steel_poisson")]
    pub poisson: f64,
    /// Mass \[kg\] moving with each eccentric's centre in the dynamic model (taken from the
    /// crank's); `None`: the shaft's section over the disc's width at the scene's density. The
    /// quasi-static analyses and the modes take the eccentrics as massless.
    #[serde(default)]
    pub eccentric_mass: Option<f64>,
}

impl CrankShaft {
    /// Check the values. Errors (`Parameter`): a diameter outside (0, 1] m or a modulus outside
    /// [1e9, 1e12] Pa (a value in mm or GPa).
    pub fn validate(&self) -> Result<()> {
        if !(self.diameter > 0.0 && self.diameter <= 1.0) {
            return Err(RvdynError::Parameter(format!(
                "diameter must be in (0, 1] m, got {} (a value in mm?)",
                self.diameter
            )));
        }
        if !(1e9..=1e12).contains(&self.modulus) {
            return Err(RvdynError::Parameter(format!(
                "modulus must be in [1e9, 1e12] Pa (steel 2.06e11), got {} (a value in GPa?)",
                self.modulus
            )));
        }
        if !(0.0..0.5).contains(&self.poisson) {
            return Err(RvdynError::Parameter(format!(
                "poisson must be in [0, 0.5) (steel 0.3), got {}",
                self.poisson
            )));
        }
        if let Some(m) = self.eccentric_mass
            && !(m.is_finite() && m > 0.0)
        {
            return Err(RvdynError::Parameter(format!(
                "eccentric_mass must be a positive mass [kg] (null: the shaft's section over the \
                 disc width), got {m}"
            )));
        }
        Ok(())
    }

    /// Shear stiffness `kappa G A` \[N\] of the round section: `G = E / (2 (1 + nu))`, Cowper's
    /// (1966) shear coefficient of a solid circle `kappa = 6 (1 + nu) / (7 + 6 nu)`.
    pub fn shear_stiffness(&self) -> f64 {
        let nu = self.poisson;
        let g = self.modulus / (2.0 * (1.0 + nu));
        let kappa = 6.0 * (1.0 + nu) / (7.0 + 6.0 * nu);
        kappa * g * std::f64::consts::PI * self.diameter.powi(2) / 4.0
    }

    /// Bending stiffness `E I` [N m^2] of the round section.
    pub fn bending_stiffness(&self) -> f64 {
        self.modulus * std::f64::consts::PI * self.diameter.powi(4) / 64.0
    }

    /// Flexibility of the eccentrics: `C[k][l]` [m/N] is the deflection at disc `k`'s plane
    /// under a unit radial force at disc `l`'s, relative to the line through the bearings
    /// (symmetric, positive definite). Row-major, `discs x discs`.
    ///
    /// Errors (`Parameter`): a disc at a bearing's plane (no deflection there to model; move it
    /// by a fraction of a millimetre or leave the shaft out).
    ///
    /// ```
    /// use rvdyn::bearing::{CrankLayout, CrankShaft};
    /// let layout = CrankLayout {
    ///     bearings: [0.0, 0.1], discs: vec![0.05], planet: -0.03, roller_length: None,
    /// };
    /// let shaft = CrankShaft { diameter: 0.04, modulus: 2.06e11, poisson: 0.3, eccentric_mass: None };
    /// let c = shaft.flexibility(&layout).unwrap();
    /// // Mid-span: L^3 / (48 E I) + L / (4 kappa G A).
    /// let want = 0.1f64.powi(3) / (48.0 * shaft.bending_stiffness())
    ///     + 0.1 / (4.0 * shaft.shear_stiffness());
    /// assert!((c[0] / want - 1.0).abs() < 1e-12);
    /// ```
    pub fn flexibility(&self, layout: &CrankLayout) -> Result<Vec<f64>> {
        self.validate()?;
        layout.validate()?;
        let [za, zb] = layout.bearings;
        let span = (zb - za).abs();
        for (k, &z) in layout.discs.iter().enumerate() {
            if (z - za).abs().min((z - zb).abs()) < 1e-6 * span {
                return Err(RvdynError::Parameter(format!(
                    "disc {k} sits at a crank bearing's plane ({z} m): the shaft does not bend \
                     there; move the disc off the bearing or leave crank_shaft out"
                )));
            }
        }
        for (k, &z) in layout.discs.iter().enumerate() {
            if let Some(j) = layout.discs[..k]
                .iter()
                .position(|&y| (y - z).abs() < 1e-6 * span)
            {
                return Err(RvdynError::Parameter(format!(
                    "discs {j} and {k} sit at the same plane of the crank ({z} m): their \
                     bending cannot be told apart; give each disc its own plane"
                )));
            }
        }
        // Nodes: the bearings and the discs, sorted and merged.
        let mut z: Vec<f64> = layout
            .bearings
            .iter()
            .chain(&layout.discs)
            .copied()
            .collect();
        z.sort_by(f64::total_cmp);
        z.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * span);
        // Every position is a node (the list was built from them); the nearest one, without a
        // tolerance to miss.
        let node = |x: f64| {
            (0..z.len())
                .min_by(|&a, &b| (z[a] - x).abs().total_cmp(&(z[b] - x).abs()))
                .unwrap_or(0)
        };
        let n = z.len();
        let ei = self.bending_stiffness();
        let gas = self.shear_stiffness();
        // DOFs (w, rotation of the section) per node.
        let mut k = DMatrix::<f64>::zeros(2 * n, 2 * n);
        for e in 0..n - 1 {
            let l = z[e + 1] - z[e];
            let phi = 12.0 * ei / (gas * l * l);
            let c = ei / ((1.0 + phi) * l.powi(3));
            let (d, o) = ((4.0 + phi) * l * l, (2.0 - phi) * l * l);
            let ke = [
                [12.0, 6.0 * l, -12.0, 6.0 * l],
                [6.0 * l, d, -6.0 * l, o],
                [-12.0, -6.0 * l, 12.0, -6.0 * l],
                [6.0 * l, o, -6.0 * l, d],
            ];
            for (a, row) in ke.iter().enumerate() {
                for (b, v) in row.iter().enumerate() {
                    k[(2 * e + a, 2 * e + b)] += c * v;
                }
            }
        }
        // Supports: w = 0 at both bearings (rows and columns replaced by the identity).
        let supports = [2 * node(za), 2 * node(zb)];
        for &s in &supports {
            for j in 0..2 * n {
                k[(s, j)] = 0.0;
                k[(j, s)] = 0.0;
            }
            k[(s, s)] = 1.0;
        }
        let lu = k.lu();
        let nd = layout.discs.len();
        let mut c = vec![0.0; nd * nd];
        for (l, &zl) in layout.discs.iter().enumerate() {
            let mut f = DVector::<f64>::zeros(2 * n);
            f[2 * node(zl)] = 1.0;
            let w = lu.solve(&f).ok_or_else(|| {
                RvdynError::Parameter("the crankshaft's beam model is singular".into())
            })?;
            for (kk, &zk) in layout.discs.iter().enumerate() {
                c[kk * nd + l] = w[2 * node(zk)];
            }
        }
        Ok(c)
    }

    /// Stiffness of the eccentrics against bending, the inverse of
    /// [`flexibility`](Self::flexibility) [N/m], row-major `discs x discs`. Errors as
    /// `flexibility`.
    pub fn stiffness(&self, layout: &CrankLayout) -> Result<Vec<f64>> {
        let c = self.flexibility(layout)?;
        let nd = layout.discs.len();
        let m = DMatrix::from_row_slice(nd, nd, &c);
        let inv = m.cholesky().map(|ch| ch.inverse()).ok_or_else(|| {
            RvdynError::Parameter(
                "two discs at the same plane of the crank: their bending cannot be told apart"
                    .into(),
            )
        })?;
        Ok((0..nd)
            .flat_map(|i| (0..nd).map(move |j| (i, j)))
            .map(|(i, j)| inv[(i, j)])
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn layout(bearings: [f64; 2], discs: Vec<f64>) -> CrankLayout {
        CrankLayout {
            bearings,
            discs,
            planet: -0.09,
            roller_length: None,
        }
    }

    /// Simply supported span `L`, load `P` at `a` from the left support (`b = L - a`): the
    /// bending deflection at `x <= a` is `P b x (L^2 - b^2 - x^2) / (6 E I L)` (Young & Budynas
    /// 2002, Roark's Formulas for Stress and Strain, table 8.1, simply supported ends) and the
    /// shear deflection `P b x / (kappa G A L)` (the shear force `P b / L` left of the load,
    /// integrated over `x`); symmetric by Maxwell's reciprocity. Overhang: a load at `c` beyond
    /// the right support deflects its own point by `P c^2 (L + c) / (3 E I) + P c (L + c) /
    /// (kappa G A L)`.
    #[test]
    fn flexibility_is_the_closed_form_of_beam_theory() {
        let s = CrankShaft {
            diameter: 0.04,
            modulus: STEEL_MODULUS,
            poisson: STEEL_POISSON,
            eccentric_mass: None,
        };
        let ei = s.bending_stiffness();
        let gas = s.shear_stiffness();
        let l = 0.12;
        let (x1, x2) = (0.04, 0.09);
        let c = s.flexibility(&layout([0.0, l], vec![x1, x2])).unwrap();
        let def = |x: f64, a: f64| {
            let b = l - a;
            let (x, b) = if x <= a { (x, b) } else { (l - x, a) };
            b * x * (l * l - b * b - x * x) / (6.0 * ei * l) + b * x / (gas * l)
        };
        let want = [def(x1, x1), def(x1, x2), def(x2, x1), def(x2, x2)];
        for (g, w) in c.iter().zip(want) {
            assert!((g / w - 1.0).abs() < 1e-12, "{g:e} {w:e}");
        }
        // Reversed axis and origin: the same.
        let r = s
            .flexibility(&layout([0.3, 0.3 - l], vec![0.3 - x1, 0.3 - x2]))
            .unwrap();
        for (a, b) in c.iter().zip(&r) {
            assert!((a / b - 1.0).abs() < 1e-12);
        }
        let over = 0.03;
        let o = s.flexibility(&layout([0.0, l], vec![l + over])).unwrap();
        let want = over * over * (l + over) / (3.0 * ei) + over * (l + over) / (gas * l);
        assert!((o[0] / want - 1.0).abs() < 1e-12, "{:e} {want:e}", o[0]);
        // The stiffness is the inverse.
        let k = s.stiffness(&layout([0.0, l], vec![x1, x2])).unwrap();
        for i in 0..2 {
            for j in 0..2 {
                let e: f64 = (0..2).map(|m| k[i * 2 + m] * c[m * 2 + j]).sum();
                assert!((e - f64::from(u8::from(i == j))).abs() < 1e-12, "{e}");
            }
        }
    }

    #[test]
    fn bad_sections_and_discs_at_a_bearing_are_named() {
        let l = layout([0.0, 0.1], vec![0.05]);
        for (d, e, nu) in [
            (0.0, STEEL_MODULUS, 0.3),
            (40.0, STEEL_MODULUS, 0.3),
            (0.04, 206.0, 0.3),
            (f64::NAN, 2e11, 0.3),
            (0.04, 2e11, 0.5),
            (0.04, 2e11, -0.1),
        ] {
            let err = CrankShaft {
                diameter: d,
                modulus: e,
                poisson: nu,
                eccentric_mass: None,
            }
            .flexibility(&l)
            .unwrap_err();
            assert!(matches!(err, RvdynError::Parameter(_)), "{err}");
        }
        let s = CrankShaft {
            diameter: 0.04,
            modulus: STEEL_MODULUS,
            poisson: STEEL_POISSON,
            eccentric_mass: None,
        };
        let err = s.flexibility(&layout([0.0, 0.1], vec![0.1])).unwrap_err();
        assert!(err.to_string().contains("bearing's plane"), "{err}");
        let err = s
            .stiffness(&layout([0.0, 0.1], vec![0.05, 0.05]))
            .unwrap_err();
        assert!(err.to_string().contains("same plane"), "{err}");
    }
}
