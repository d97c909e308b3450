//! Crank bearing rows: the planar models lump each crank's two bearings into one row. Given
//! where the bearings, the discs and the planet sit along the crank, the statics of a rigid
//! crank on two radial supports (statically determinate) split the lumped reaction between
//! the two bearings, including the tilting moment of the two discs' loads.
//!
//! Theory: docs/model.md, "Crank bearing rows".

use serde::{Deserialize, Serialize};

use crate::error::{Result, RvdynError, num};

/// Axial positions [m] along the crank axis (any origin, one direction for all), and the
/// roller length of each of the two bearings; a scene may carry one (`crank_layout`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CrankLayout {
    /// The two crank bearings, `[z_a, z_b]`, at different positions.
    pub bearings: [f64; 2],
    /// The eccentric (disc) centre planes, one per disc, in the order of the discs.
    pub discs: Vec<f64>,
    /// The planet's mid-plane, where the mesh force acts; a dynamic run's crank inertia force
    /// is put there too (an error of `m_cr |p''| |z_c - z_planet| / span` per bearing; none
    /// in the quasi-static LTCA).
    pub planet: f64,
    /// Roller length of each of the two bearings \[m\] for their load ratings; `None`: half
    /// the scene's lumped crank roller length (the lumped row stands for two equal bearings).
    #[serde(default)]
    pub roller_length: Option<f64>,
}

impl CrankLayout {
    /// Check the positions. Errors (`Parameter`): a position that is not finite, no disc, the
    /// two bearings closer than `1e-9` of the layout's largest distance (no support against
    /// tilting), or a roller length that is not in (0, 1] m.
    ///
    /// ```
    /// use rvdyn::bearing::CrankLayout;
    /// let layout = CrankLayout {
    ///     bearings: [-0.06, 0.06], discs: vec![-0.02, 0.02], planet: -0.09, roller_length: None,
    /// };
    /// assert!(layout.validate().is_ok());
    /// let flat = CrankLayout { bearings: [0.06, 0.06], ..layout };
    /// assert!(flat.validate().is_err());
    /// ```
    pub fn validate(&self) -> Result<()> {
        let all = || {
            self.bearings
                .iter()
                .chain(&self.discs)
                .chain(std::iter::once(&self.planet))
        };
        if let Some(bad) = all().find(|z| !z.is_finite()) {
            return Err(RvdynError::Parameter(format!(
                "the crank layout's axial positions must be finite [m], got {}",
                num(*bad)
            )));
        }
        if self.discs.is_empty() {
            return Err(RvdynError::Parameter(
                "the crank layout needs the axial position of every disc [m], got none".into(),
            ));
        }
        let reach = all().fold(0.0_f64, |m, z| m.max((z - self.bearings[0]).abs()));
        let span = self.bearings[1] - self.bearings[0];
        if span.abs() <= 1e-9 * reach || span == 0.0 {
            return Err(RvdynError::Parameter(format!(
                "the two crank bearings must be at different axial positions to carry the \
                 discs' tilting moment, got {} and {} m: give each bearing's mid-plane",
                num(self.bearings[0]),
                num(self.bearings[1])
            )));
        }
        if let Some(l) = self.roller_length
            && !(l.is_finite() && l > 0.0 && l <= 1.0)
        {
            return Err(RvdynError::Parameter(format!(
                "the crank bearings' roller_length must be in (0, 1] m, or null for half the \
                 lumped crank roller length, got {}",
                num(l)
            )));
        }
        Ok(())
    }

    /// The forces [N] of the two bearings on the crank, `[b_a, b_b]` (in-plane vectors in the
    /// frame of the inputs), from the lumped crank bearing force on the crank `lumped` and
    /// each disc's eccentric bearing force on the disc `eccentric[k]` (the recorded
    /// `crank_bearing_force` and `eccentric_bearing_force`). `b_a + b_b = lumped` exactly up
    /// to round-off; the moments about any point of the axis balance. The layout must be
    /// valid ([`CrankLayout::validate`]) and hold one disc position per entry of `eccentric`
    /// (extra entries of either are ignored).
    ///
    /// ```
    /// use rvdyn::bearing::CrankLayout;
    /// // Everything at one plane a quarter of the span from bearing a: the lever rule.
    /// let layout = CrankLayout {
    ///     bearings: [0.0, 0.1], discs: vec![0.025, 0.025], planet: 0.025, roller_length: None,
    /// };
    /// let [a, b] = layout.split([4000.0, 0.0], &[[1000.0, 0.0], [2000.0, 0.0]]);
    /// assert!((a[0] - 3000.0).abs() < 1e-9 && (b[0] - 1000.0).abs() < 1e-9);
    /// ```
    pub fn split(&self, lumped: [f64; 2], eccentric: &[[f64; 2]]) -> [[f64; 2]; 2] {
        let [za, zb] = self.bearings;
        let span = zb - za;
        let lever_p = self.planet - za;
        let mut b = [0.0; 2];
        for j in 0..2 {
            // Moments about bearing a of the forces on the crank: the discs' reactions -R_k
            // at z_k, the mesh and inertia (sum R_k - lumped) at the planet, b_b at z_b.
            let mut moment = lever_p * lumped[j];
            for (r, z) in eccentric.iter().zip(&self.discs) {
                moment += (z - za) * r[j] - lever_p * r[j];
            }
            b[j] = moment / span;
        }
        [[lumped[0] - b[0], lumped[1] - b[1]], b]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn layout() -> CrankLayout {
        CrankLayout {
            bearings: [-0.06, 0.07],
            discs: vec![-0.021, 0.019],
            planet: -0.095,
            roller_length: None,
        }
    }

    /// Forces on the crank sum to its inertia force and their moments about two different
    /// points vanish: the statics the split rests on, checked with the mesh force it never sees.
    #[test]
    fn split_balances_forces_and_moments_of_the_crank() {
        let l = layout();
        let r = [[12_000.0, -35_000.0], [-8_000.0, 41_000.0]];
        let mesh = [3_100.0, -950.0];
        let inertia = [4.0, -2.0]; // m_cr p''
        // Crank balance: m p'' = lumped - sum R + mesh.
        let lumped = [
            inertia[0] + r[0][0] + r[1][0] - mesh[0],
            inertia[1] + r[0][1] + r[1][1] - mesh[1],
        ];
        let [a, b] = l.split(lumped, &r);
        for j in 0..2 {
            let net = a[j] + b[j] - r[0][j] - r[1][j] + mesh[j] - inertia[j];
            assert!(net.abs() < 1e-9, "force {j}: {net}");
            for origin in [0.0, 0.31] {
                let m = (l.bearings[0] - origin) * a[j] + (l.bearings[1] - origin) * b[j]
                    - (l.discs[0] - origin) * r[0][j]
                    - (l.discs[1] - origin) * r[1][j]
                    + (l.planet - origin) * (mesh[j] - inertia[j]);
                assert!(m.abs() < 1e-9, "moment {j} about {origin}: {m}");
            }
        }
    }

    /// Equal and opposite disc loads symmetric about the bearings' middle, no mesh: a pure
    /// tilting couple `R d / span` on each bearing, opposite.
    #[test]
    fn a_pure_couple_loads_the_bearings_equally_and_oppositely() {
        let l = CrankLayout {
            bearings: [-0.05, 0.05],
            discs: vec![-0.02, 0.02],
            planet: 0.3,
            roller_length: None,
        };
        let [a, b] = l.split([0.0, 0.0], &[[1000.0, 0.0], [-1000.0, 0.0]]);
        // Disc forces on the crank: -1000 at -0.02, +1000 at +0.02: couple 40 N m.
        assert!((b[0] + 400.0).abs() < 1e-9, "{b:?}");
        assert!((a[0] - 400.0).abs() < 1e-9, "{a:?}");
        assert_eq!(a[1], 0.0);
    }

    #[test]
    fn bad_layouts_are_refused_with_the_reason() {
        let mut l = layout();
        l.discs[1] = f64::NAN;
        assert!(l.validate().unwrap_err().to_string().contains("finite"));
        let mut l = layout();
        l.discs.clear();
        assert!(l.validate().unwrap_err().to_string().contains("every disc"));
        let mut l = layout();
        l.bearings = [0.02, 0.02];
        assert!(l.validate().unwrap_err().to_string().contains("different"));
        let mut l = layout();
        l.bearings = [1e3, 1e3 + 1e-12];
        assert!(l.validate().is_err());
    }
}
