//! Gear mesh stiffness by ISO 6336-1 method B, and its variation along the line of action.
//!
//! ISO 6336-1 (*Calculation of load capacity of spur and helical gears, Part 1*, 2006 and
//! 2019 editions), tooth stiffness parameters `c'` and `c_gamma`, method B:
//!
//! - `q' = C1 + C2/zn1 + C3/zn2 + C4 x1 + C5 x1/zn1 + C6 x2 + C7 x2/zn2 + C8 x1^2 + C9 x2^2`
//!   [mm um / N] with `C1..C9 = 0.04723, 0.15551, 0.25791, -0.00635, -0.11654, -0.00193,
//!   -0.24188, 0.00529, 0.00182`, `zn = z / cos^3 beta` (virtual tooth numbers), `x` the
//!   profile shift coefficients (external gears);
//! - theoretical single stiffness `c'_th = 1 / q'` [N / (mm um)];
//! - single stiffness `c' = c'_th C_M C_R C_B cos beta`, with `C_M = 0.8` (correction from
//!   theory to measurement), `C_R = 1` for solid blanks (else `1 + ln(b_s/b) / (5 e^(s_R /
//!   (5 m_n)))`), `C_B = [1 + 0.5 (1.2 - h_fP/m_n)] [1 - 0.02 (20 deg - alpha_Pn)]` (basic rack
//!   factor; 0.975 for the standard rack with `h_fP = 1.25 m_n`, `alpha_Pn = 20 deg`);
//!   for a line load `F_t K_A / b` below 100 N/mm, `c'` is multiplied by
//!   `(F_t K_A / b / 100)^0.25`;
//! - mesh stiffness `c_gamma_alpha = c' (0.75 eps_alpha + 0.25)` [N / (mm um)] (spur gears,
//!   `eps_alpha >= 1.2`).
//!
//! Stiffnesses per unit face width are converted to N/m of the gear pair by multiplying by the
//! face width `b` in mm and by 1e6 (N/um -> N/m).
//!
//! Time variation (not in ISO 6336): along the line of action the number of tooth pairs in
//! contact alternates between 2 (double zone, length `(eps - 1) p_b` of every base pitch
//! `p_b`) and 1 (single zone). The single zone has the single stiffness `c'` (ISO's `c'` is
//! the stiffness of one pair), the double zone `1.75 c'`: then the mean over a base pitch is
//! `c' [(2 - eps) + 1.75 (eps - 1)] = c' (0.75 eps + 0.25) = c_gamma` exactly, so the
//! rectangular wave is consistent with the ISO mean. The jumps are smoothed by a cubic ramp of
//! a chosen width centred on each zone boundary; the ramp is antisymmetric about the boundary,
//! so the mean is unchanged. For `eps >= 2` the wave alternates between `n` and `n + 1`
//! pairs of stiffness `c_gamma / eps` each.
//!
//! Theory: docs/model.md, sections "ISO 6336-1 method B"
//! and "Time variation along the line of action".

use crate::error::{Result, RvdynError, require_finite, require_non_negative, require_positive};
use std::f64::consts::PI;

/// ISO 6336-1 method B coefficients `C1..C9` of `q'` [mm um / N].
pub const ISO6336_Q_COEFFS: [f64; 9] = [
    0.04723, 0.15551, 0.25791, -0.00635, -0.11654, -0.00193, -0.24188, 0.00529, 0.00182,
];

/// ISO 6336-1 theoretical correction factor `C_M` [-].
pub const ISO6336_CM: f64 = 0.8;

/// Inputs of the ISO 6336-1 method B stiffness of one external gear pair (SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IsoGearPair {
    /// Teeth of gear 1 (pinion) and gear 2.
    pub teeth: [u32; 2],
    /// Normal module `m_n` \[m\].
    pub module: f64,
    /// Normal pressure angle of the basic rack `alpha_Pn` \[rad\].
    pub pressure_angle: f64,
    /// Helix angle `beta` \[rad\] (0 for spur gears).
    pub helix_angle: f64,
    /// Profile shift coefficients `x1`, `x2` [-].
    pub profile_shift: [f64; 2],
    /// Common face width `b` \[m\].
    pub face_width: f64,
    /// Dedendum of the basic rack `h_fP` \[m\] (standard: `1.25 m_n`).
    pub rack_dedendum: f64,
    /// Gear blank factor `C_R` [-] (1 for solid blanks; see [`rim_blank_factor`]).
    pub blank_factor: f64,
}

impl IsoGearPair {
    /// A solid, unshifted spur pair with the standard basic rack (`h_fP = 1.25 m`).
    ///
    /// Module \[m\], pressure angle \[rad\], face width \[m\].
    pub fn spur(z1: u32, z2: u32, module: f64, pressure_angle: f64, face_width: f64) -> Self {
        Self {
            teeth: [z1, z2],
            module,
            pressure_angle,
            helix_angle: 0.0,
            profile_shift: [0.0, 0.0],
            face_width,
            rack_dedendum: 1.25 * module,
            blank_factor: 1.0,
        }
    }

    /// Check the fields. Errors (`Parameter`) for tooth counts below 5, non-positive module or
    /// face width, a pressure angle outside (0, 45 deg), a helix angle outside [0, 45 deg),
    /// non-finite shifts, a non-positive dedendum or blank factor.
    pub fn validate(&self) -> Result<()> {
        for z in self.teeth {
            if z < 5 {
                return Err(RvdynError::Parameter(format!(
                    "gear teeth must be at least 5 for ISO 6336 stiffness, got {z}"
                )));
            }
        }
        require_positive("gear module", self.module, "m")?;
        require_positive("gear face width", self.face_width, "m")?;
        require_positive("basic rack dedendum", self.rack_dedendum, "m")?;
        require_positive("gear blank factor C_R", self.blank_factor, "")?;
        let a = self.pressure_angle;
        if !(a.is_finite() && a > 0.0 && a < PI / 4.0) {
            return Err(RvdynError::Parameter(format!(
                "pressure angle must be in (0, 45 deg), got {a} rad"
            )));
        }
        let b = self.helix_angle;
        if !(b.is_finite() && (0.0..PI / 4.0).contains(&b)) {
            return Err(RvdynError::Parameter(format!(
                "helix angle must be in [0, 45 deg), got {b} rad"
            )));
        }
        require_finite("profile shift x1", self.profile_shift[0])?;
        require_finite("profile shift x2", self.profile_shift[1])?;
        Ok(())
    }

    /// Virtual tooth numbers `zn = z / cos^3 beta` [-].
    pub fn virtual_teeth(&self) -> [f64; 2] {
        let c3 = self.helix_angle.cos().powi(3);
        [f64::from(self.teeth[0]) / c3, f64::from(self.teeth[1]) / c3]
    }

    /// `q'` [mm um / N] (ISO 6336-1 method B polynomial).
    pub fn q_min(&self) -> Result<f64> {
        self.validate()?;
        let [zn1, zn2] = self.virtual_teeth();
        let [x1, x2] = self.profile_shift;
        let c = ISO6336_Q_COEFFS;
        let q = c[0]
            + c[1] / zn1
            + c[2] / zn2
            + c[3] * x1
            + c[4] * x1 / zn1
            + c[5] * x2
            + c[6] * x2 / zn2
            + c[7] * x1 * x1
            + c[8] * x2 * x2;
        if q.is_nan() || q <= 0.0 {
            return Err(RvdynError::Parameter(format!(
                "ISO 6336 q' = {q} mm um/N is not positive for these profile shifts"
            )));
        }
        Ok(q)
    }

    /// Basic rack factor `C_B = [1 + 0.5 (1.2 - h_fP/m_n)] [1 - 0.02 (20 deg - alpha_Pn)]` [-]
    /// (the angle difference in degrees).
    pub fn rack_factor(&self) -> f64 {
        let h = self.rack_dedendum / self.module;
        let d_deg = 20.0 - self.pressure_angle.to_degrees();
        (1.0 + 0.5 * (1.2 - h)) * (1.0 - 0.02 * d_deg)
    }

    /// Single stiffness `c'` [N / (mm um)] per unit face width at the line load
    /// `line_load = F_t K_A / b` [N/mm] (pass 100 or more for the full value).
    ///
    /// Errors as [`IsoGearPair::validate`], and (`Parameter`) for a non-positive line load.
    pub fn single_stiffness(&self, line_load: f64) -> Result<f64> {
        require_positive("line load F_t K_A / b", line_load, "N/mm")?;
        let c_th = 1.0 / self.q_min()?;
        let load_factor = if line_load < 100.0 {
            (line_load / 100.0).powf(0.25)
        } else {
            1.0
        };
        Ok(c_th
            * ISO6336_CM
            * self.blank_factor
            * self.rack_factor()
            * self.helix_angle.cos()
            * load_factor)
    }

    /// Mesh stiffness `c_gamma_alpha = c' (0.75 eps + 0.25)` [N / (mm um)] for the transverse
    /// contact ratio `contact_ratio` [-] and the line load [N/mm].
    ///
    /// Errors: as [`IsoGearPair::single_stiffness`]; `Parameter` for a contact ratio below 1.
    pub fn mesh_stiffness(&self, contact_ratio: f64, line_load: f64) -> Result<f64> {
        if !(contact_ratio.is_finite() && contact_ratio >= 1.0) {
            return Err(RvdynError::Parameter(format!(
                "transverse contact ratio must be >= 1 for a continuous mesh, got {contact_ratio}"
            )));
        }
        Ok(self.single_stiffness(line_load)? * (0.75 * contact_ratio + 0.25))
    }

    /// Convert a stiffness per unit face width [N / (mm um)] to the pair's stiffness [N/m].
    pub fn to_newton_per_metre(&self, per_width: f64) -> f64 {
        per_width * self.face_width * 1e3 * 1e6
    }
}

/// Gear blank factor `C_R = 1 + ln(b_s / b) / (5 exp(s_R / (5 m_n)))` [-] (ISO 6336-1) for a
/// web of width `web_width` `b_s` \[m\] under a face width `face_width` `b` \[m\] and a rim
/// thickness `rim_thickness` `s_R` \[m\], module `m_n` \[m\]; `b_s/b` is clamped to [0.2, 1.2] and
/// `s_R/m_n` to at least 1 as the standard prescribes.
///
/// Errors (`Parameter`) for non-positive or non-finite inputs.
pub fn rim_blank_factor(
    web_width: f64,
    face_width: f64,
    rim_thickness: f64,
    module: f64,
) -> Result<f64> {
    require_positive("web width b_s", web_width, "m")?;
    require_positive("face width b", face_width, "m")?;
    require_positive("rim thickness s_R", rim_thickness, "m")?;
    require_positive("module", module, "m")?;
    let ratio = (web_width / face_width).clamp(0.2, 1.2);
    let sr = (rim_thickness / module).max(1.0);
    Ok(1.0 + ratio.ln() / (5.0 * (sr / 5.0).exp()))
}

/// Transverse contact ratio `eps_alpha` [-] of an external spur pair at standard centre
/// distance without profile shift: `[sqrt(ra1^2 - rb1^2) + sqrt(ra2^2 - rb2^2) - a sin alpha]
/// / (pi m cos alpha)` with `r = m z / 2`, `ra = r + m`, `rb = r cos alpha`, `a = r1 + r2`.
///
/// Errors (`Parameter`) for tooth counts below 5, a non-positive module, a pressure angle
/// outside (0, 45 deg).
///
/// # Example
///
/// ```
/// use rvdyn::gear::spur_contact_ratio;
/// use std::f64::consts::PI;
/// // The paper's first stage: 18/42 teeth, module 3 mm, 20 deg.
/// let alpha = 20f64.to_radians();
/// let eps = spur_contact_ratio(18, 42, 3e-3, alpha).unwrap();
/// // Textbook form in tooth counts (addendum = module, so the module cancels).
/// let (z1, z2, c) = (18.0_f64, 42.0_f64, alpha.cos());
/// let path = |z: f64| ((z + 2.0).powi(2) - (z * c).powi(2)).sqrt();
/// let eps_z = (path(z1) + path(z2) - (z1 + z2) * alpha.sin()) / (2.0 * PI * c);
/// assert!((eps - eps_z).abs() < 1e-12);
/// assert!((eps - 1.626).abs() < 1e-3);
/// ```
pub fn spur_contact_ratio(z1: u32, z2: u32, module: f64, pressure_angle: f64) -> Result<f64> {
    IsoGearPair::spur(z1, z2, module, pressure_angle, 1.0).validate()?;
    let (s, c) = pressure_angle.sin_cos();
    let path = |z: u32| {
        let r = 0.5 * module * f64::from(z);
        let ra = r + module;
        let rb = r * c;
        (ra * ra - rb * rb).sqrt()
    };
    let a = 0.5 * module * f64::from(z1 + z2);
    Ok((path(z1) + path(z2) - a * s) / (PI * module * c))
}

/// Base pitch `p_b = pi m cos alpha` \[m\] (module \[m\], pressure angle \[rad\]).
pub fn base_pitch(module: f64, pressure_angle: f64) -> f64 {
    PI * module * pressure_angle.cos()
}

/// A periodic mesh stiffness along the line of action [N/m], period one base pitch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshStiffnessWave {
    /// Stiffness with the fewer pairs in contact [N/m].
    low: f64,
    /// Stiffness with one more pair in contact [N/m].
    high: f64,
    /// Fraction of the base pitch with the extra pair, `eps - floor(eps)` [-].
    high_fraction: f64,
    /// Base pitch \[m\].
    base_pitch: f64,
    /// Width of each smoothing ramp as a fraction of the base pitch [-].
    ramp: f64,
}

impl MeshStiffnessWave {
    /// The wave of a pair of single stiffness `single` [N/m] (ISO `c'` times face width),
    /// contact ratio `contact_ratio` >= 1 [-], base pitch `base_pitch` \[m\], with ramps of
    /// `ramp` (fraction of the base pitch, in [0, 0.5 min(f, 1 - f)] where `f` is the
    /// fractional part of the contact ratio; 0 for jumps).
    ///
    /// For `1 <= eps < 2`: `c'` in the single zone, `1.75 c'` in the double zone (mean
    /// `c' (0.75 eps + 0.25)`); for `eps >= 2`: `n` and `n + 1` pairs of `c_gamma / eps` each.
    ///
    /// Errors (`Parameter`) for a non-positive stiffness or pitch, a contact ratio below 1, a
    /// ramp outside its range.
    pub fn new(single: f64, contact_ratio: f64, base_pitch: f64, ramp: f64) -> Result<Self> {
        require_positive("single tooth stiffness", single, "N/m")?;
        require_positive("base pitch", base_pitch, "m")?;
        require_non_negative("stiffness ramp width", ramp, "(fraction of the base pitch)")?;
        if !(contact_ratio.is_finite() && contact_ratio >= 1.0) {
            return Err(RvdynError::Parameter(format!(
                "transverse contact ratio must be >= 1, got {contact_ratio}"
            )));
        }
        let n = contact_ratio.floor();
        let f = contact_ratio - n;
        let (low, high) = if n < 2.0 {
            (single, 1.75 * single)
        } else {
            let per_pair = single * (0.75 * contact_ratio + 0.25) / contact_ratio;
            (n * per_pair, (n + 1.0) * per_pair)
        };
        let max_ramp = 0.5 * f.min(1.0 - f);
        if ramp > max_ramp {
            return Err(RvdynError::Parameter(format!(
                "stiffness ramp width {ramp} (fraction of the base pitch) must be at most \
                 {max_ramp} for contact ratio {contact_ratio}"
            )));
        }
        Ok(Self {
            low,
            high,
            high_fraction: f,
            base_pitch,
            ramp,
        })
    }

    /// Mean stiffness over a base pitch [N/m] (`c_gamma` times face width for `eps < 2`).
    pub fn mean(&self) -> f64 {
        self.low + (self.high - self.low) * self.high_fraction
    }

    /// Base pitch \[m\]: the period of the wave along the line of action.
    pub fn period(&self) -> f64 {
        self.base_pitch
    }

    /// Stiffness [N/m] at the mesh position `s` \[m\] along the line of action (any real `s`;
    /// the double zone is `[0, (eps - n) p_b)` of each period).
    pub fn stiffness(&self, s: f64) -> f64 {
        self.stiffness_and_slope(s).0
    }

    /// Stiffness [N/m] and its slope `dk/ds` [N/m^2] at the mesh position `s` \[m\] (the slope
    /// is 0 outside the ramps; with jumps (`ramp = 0`) it is 0 everywhere but at the jumps).
    /// A non-finite `s` gives the mean and 0.
    pub fn stiffness_and_slope(&self, s: f64) -> (f64, f64) {
        if !s.is_finite() {
            return (self.mean(), 0.0);
        }
        let u = (s / self.base_pitch).rem_euclid(1.0);
        let f = self.high_fraction;
        if f == 0.0 {
            return (self.low, 0.0);
        }
        let w = self.ramp;
        // Fraction of "high" at u: 1 inside [0, f), 0 in [f, 1), ramps of width w centred on
        // u = 0 (= 1) and u = f. smooth(t) rises 0 -> 1 as t goes -w/2 -> w/2; returns the
        // value and its derivative in t.
        let smooth = |t: f64| {
            if w == 0.0 {
                (if t >= 0.0 { 1.0 } else { 0.0 }, 0.0)
            } else {
                let x = t / w + 0.5;
                if x <= 0.0 {
                    (0.0, 0.0)
                } else if x >= 1.0 {
                    (1.0, 0.0)
                } else {
                    (x * x * (3.0 - 2.0 * x), 6.0 * x * (1.0 - x) / w)
                }
            }
        };
        // Position in [-(1 - f)/2, (1 + f)/2): the rising edge at 0 and the falling edge at f
        // are both at least half a ramp away from the ends.
        let v = if u < 0.5 * (1.0 + f) { u } else { u - 1.0 };
        let (a, da) = smooth(v);
        let (b, db) = smooth(v - f);
        let span = self.high - self.low;
        (
            self.low + span * (a - b),
            span * (da - db) / self.base_pitch,
        )
    }
}

impl MeshStiffnessWave {
    /// Stiffness `k(s)` [N/m], slope `dk/ds` [N/m^2] and curvature `d2k/ds2` [N/m^3] at the
    /// mesh position `s` \[m\]: the derivatives of [`MeshStiffnessWave::stiffness_and_slope`]'s
    /// ramps `3 x^2 - 2 x^3` (`x` the position within a ramp), for the static tangent of the
    /// mesh energy `V = k(s) pen^2 / 2` (quasi-static analysis, modes). The curvature jumps at
    /// the ends of each ramp (the ramp is C1); it is that of the side `s` lies on.
    pub fn stiffness_slope_curvature(&self, s: f64) -> (f64, f64, f64) {
        let (k, dk) = self.stiffness_and_slope(s);
        let f = self.high_fraction;
        let w = self.ramp;
        if !s.is_finite() || f == 0.0 || w == 0.0 {
            return (k, dk, 0.0);
        }
        let u = (s / self.base_pitch).rem_euclid(1.0);
        let v = if u < 0.5 * (1.0 + f) { u } else { u - 1.0 };
        // d2/dt2 of the smooth step at t (in base pitches): 6 (1 - 2 x) / w^2 inside the ramp.
        let curv = |t: f64| {
            let x = t / w + 0.5;
            if x <= 0.0 || x >= 1.0 {
                0.0
            } else {
                6.0 * (1.0 - 2.0 * x) / (w * w)
            }
        };
        let span = self.high - self.low;
        let d2 = span * (curv(v) - curv(v - f)) / (self.base_pitch * self.base_pitch);
        (k, dk, d2)
    }
}

/// Mesh phases of the sun-planet meshes of a planetary stage, as fractions of a mesh period in
/// [0, 1): `gamma_k = frac(z_sun psi_k / (2 pi))` for planets at the angles `psi_k` \[rad\]
/// (measured in the direction of the sun's rotation relative to the carrier).
///
/// Planet `k` passes the same mesh position as planet 0 a time `gamma_k T_mesh` later
/// (R. G. Parker, J. Lin, *Mesh phasing relationships in planetary and epicyclic gears*, J.
/// Mech. Des. 126 (2004) 365-370, sun-planet phases). Equal spacing with `z_sun / N` an integer
/// gives all phases 0 (in phase). Errors (`Parameter`) for a non-finite angle.
///
/// # Example
///
/// ```
/// use rvdyn::gear::planet_mesh_phases;
/// use std::f64::consts::TAU;
/// let three = [0.0, TAU / 3.0, 2.0 * TAU / 3.0]; // three equally spaced planets
/// // 18 sun teeth: 18 / 3 is whole, the meshes are in phase.
/// assert_eq!(planet_mesh_phases(18, &three).unwrap(), vec![0.0; 3]);
/// // 19 sun teeth: sequential phases 0, 1/3, 2/3 of a mesh period.
/// let g = planet_mesh_phases(19, &three).unwrap();
/// assert!((g[1] - 1.0 / 3.0).abs() < 1e-12 && (g[2] - 2.0 / 3.0).abs() < 1e-12);
/// ```
pub fn planet_mesh_phases(z_sun: u32, planet_angles: &[f64]) -> Result<Vec<f64>> {
    planet_angles
        .iter()
        .map(|&psi| {
            require_finite("planet angle", psi)?;
            let g = (f64::from(z_sun) * psi / (2.0 * PI)).rem_euclid(1.0);
            // Round-off just below an integer phase reads as 0, not 0.9999999.
            Ok(if (1.0 - g) < 1e-12 || g < 1e-12 {
                0.0
            } else {
                g
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::involute::InvoluteStage;
    use crate::test_util::close;

    fn paper_pair() -> IsoGearPair {
        IsoGearPair::spur(18, 42, 3e-3, 20f64.to_radians(), 0.030)
    }

    #[test]
    fn paper_gear_by_hand() {
        // q' = 0.04723 + 0.15551/18 + 0.25791/42 = 0.0620101 mm um/N -> c'_th = 16.1264;
        // C_B = 1 + 0.5 (1.2 - 1.25) = 0.975; c' = 16.1264 * 0.8 * 0.975 = 12.5786 N/(mm um).
        let p = paper_pair();
        let q = p.q_min().unwrap();
        assert!(close(q, 0.04723 + 0.15551 / 18.0 + 0.25791 / 42.0, 1e-15));
        assert!(close(q, 0.062_010_1, 1e-6));
        assert!(close(p.rack_factor(), 0.975, 1e-12));
        let c1 = p.single_stiffness(100.0).unwrap();
        assert!(close(c1, 0.8 * 0.975 / q, 1e-15));
        assert!(close(c1, 12.5786, 1e-5), "{c1}");
        // eps_alpha = (16.00837 + 29.17599 - 30.78181) / 8.85639 = 1.626353.
        let eps = spur_contact_ratio(18, 42, 3e-3, 20f64.to_radians()).unwrap();
        assert!(close(eps, 1.626_353, 1e-6), "{eps}");
        // c_gamma = 12.5786 (0.75 * 1.626353 + 0.25) = 18.4876 N/(mm um); times 30 mm:
        // 554.6 N/um = 5.546e8 N/m.
        let cg = p.mesh_stiffness(eps, 100.0).unwrap();
        assert!(close(cg, 18.4876, 1e-5), "{cg}");
        let k = p.to_newton_per_metre(cg);
        assert!(close(k, 5.546e8, 1e-3), "{k}");
    }

    #[test]
    fn contact_ratio_agrees_with_the_geometry_module() {
        // For these tooth counts no path part reaches the base tangent point, so the capped
        // geometry formula equals the plain one.
        for (z1, z2) in [(18, 42), (20, 20), (17, 60), (30, 31)] {
            let s = InvoluteStage::new(z1, z2, 3, 3e-3, 20f64.to_radians(), 0.03).unwrap();
            let e = spur_contact_ratio(z1, z2, 3e-3, 20f64.to_radians()).unwrap();
            assert!(close(s.contact_ratio(), e, 1e-12), "{z1}/{z2}");
        }
    }

    #[test]
    fn helix_shift_blank_and_low_load_factors() {
        let mut p = paper_pair();
        p.helix_angle = 15f64.to_radians();
        let c3 = 15f64.to_radians().cos().powi(3);
        let q = 0.04723 + 0.15551 * c3 / 18.0 + 0.25791 * c3 / 42.0;
        let c = p.single_stiffness(200.0).unwrap();
        assert!(close(c, 0.8 * 0.975 * 15f64.to_radians().cos() / q, 1e-14));
        let mut p = paper_pair();
        p.profile_shift = [0.3, -0.3];
        let q = 0.04723 + 0.15551 / 18.0 + 0.25791 / 42.0 - 0.00635 * 0.3 - 0.11654 * 0.3 / 18.0
            + 0.00193 * 0.3
            + 0.24188 * 0.3 / 42.0
            + 0.00529 * 0.09
            + 0.00182 * 0.09;
        assert!(close(p.q_min().unwrap(), q, 1e-14));
        // Light load: (25/100)^0.25 = 0.70711.
        let p = paper_pair();
        let r = p.single_stiffness(25.0).unwrap() / p.single_stiffness(100.0).unwrap();
        assert!(close(r, 0.5f64.sqrt(), 1e-14));
        // Blank factor: b_s/b = 0.5, s_R = 2 m: 1 + ln 0.5 / (5 e^0.4) = 0.90707.
        let cr = rim_blank_factor(0.015, 0.030, 6e-3, 3e-3).unwrap();
        assert!(close(cr, 1.0 + 0.5f64.ln() / (5.0 * 0.4f64.exp()), 1e-15));
        // Rack: 25 deg, h_fP = 1.2 m -> C_B = 1 * (1 + 0.1) = 1.1.
        let mut p = paper_pair();
        p.pressure_angle = 25f64.to_radians();
        p.rack_dedendum = 1.2 * 3e-3;
        assert!(close(p.rack_factor(), 1.1, 1e-12));
    }

    #[test]
    fn wave_mean_equals_iso_mesh_stiffness_and_period_is_base_pitch() {
        let p = paper_pair();
        let eps = spur_contact_ratio(18, 42, 3e-3, 20f64.to_radians()).unwrap();
        let single = p.to_newton_per_metre(p.single_stiffness(100.0).unwrap());
        let cg = p.to_newton_per_metre(p.mesh_stiffness(eps, 100.0).unwrap());
        let pb = base_pitch(3e-3, 20f64.to_radians());
        for ramp in [0.0, 0.02, 0.1] {
            let w = MeshStiffnessWave::new(single, eps, pb, ramp).unwrap();
            assert!(close(w.mean(), cg, 1e-12));
            // Midpoint rule over one period (fine enough that the jumps cost < 1e-5).
            let n = 200_000;
            let avg = (0..n)
                .map(|i| w.stiffness((i as f64 + 0.5) / n as f64 * pb))
                .sum::<f64>()
                / n as f64;
            assert!(close(avg, cg, 1e-5), "ramp {ramp}: {avg} vs {cg}");
            // Period: shifted by one base pitch the wave repeats; by half a pitch it does not.
            for s in [0.1e-3, 2.0e-3, 7.5e-3] {
                assert!(close(w.stiffness(s), w.stiffness(s + pb), 1e-9));
                assert!(close(w.stiffness(s), w.stiffness(s - 3.0 * pb), 1e-9));
            }
            // Zones: double in the middle of [0, (eps-1) pb), single in the middle of the rest.
            assert!(close(
                w.stiffness(0.5 * (eps - 1.0) * pb),
                1.75 * single,
                1e-12
            ));
            assert!(close(w.stiffness(0.5 * eps * pb), single, 1e-12));
        }
        let w = MeshStiffnessWave::new(single, eps, pb, 0.02).unwrap();
        assert_eq!(w.period(), pb);
        assert!(close(w.stiffness(f64::NAN), cg, 1e-12));
        // Continuity with a ramp: no jump across the zone boundaries.
        let b = (eps - 1.0) * pb;
        let h = 1e-12;
        assert!(close(w.stiffness(b - h), w.stiffness(b + h), 1e-6));
        assert!(close(w.stiffness(-h), w.stiffness(h), 1e-6));
        // Slope by finite differences inside and outside the ramps.
        for s in [-0.05e-3, 0.03e-3, 1.0e-3, b - 0.05e-3, b + 0.01e-3, 7.0e-3] {
            let e = 1e-9;
            let fd = (w.stiffness(s + e) - w.stiffness(s - e)) / (2.0 * e);
            let (_, k1) = w.stiffness_and_slope(s);
            assert!((k1 - fd).abs() <= 1e-5 * (single / pb), "{s}: {k1} vs {fd}");
        }
    }

    #[test]
    fn high_contact_ratio_wave() {
        let w = MeshStiffnessWave::new(1e8, 2.4, 1e-2, 0.0).unwrap();
        let cg = 1e8 * (0.75 * 2.4 + 0.25);
        assert!(close(w.mean(), cg, 1e-12));
        assert!(close(w.stiffness(0.2e-2), 3.0 * cg / 2.4, 1e-12));
        assert!(close(w.stiffness(0.7e-2), 2.0 * cg / 2.4, 1e-12));
    }

    #[test]
    fn phases() {
        // 18 teeth, 3 planets: 18/3 = 6, all in phase.
        let ph = planet_mesh_phases(18, &[0.0, 2.0 * PI / 3.0, 4.0 * PI / 3.0]).unwrap();
        assert_eq!(ph, vec![0.0, 0.0, 0.0]);
        // 19 teeth, 3 planets: 1/3, 2/3.
        let ph = planet_mesh_phases(19, &[0.0, 2.0 * PI / 3.0, 4.0 * PI / 3.0]).unwrap();
        assert!(ph[0] == 0.0 && close(ph[1], 1.0 / 3.0, 1e-12) && close(ph[2], 2.0 / 3.0, 1e-12));
        assert!(planet_mesh_phases(18, &[f64::NAN]).is_err());
    }

    #[test]
    fn invalid_inputs() {
        let mut p = paper_pair();
        p.teeth = [4, 42];
        assert!(p.q_min().is_err());
        let mut p = paper_pair();
        p.module = 0.0;
        assert!(p.single_stiffness(100.0).is_err());
        let mut p = paper_pair();
        p.pressure_angle = 0.0;
        assert!(p.validate().is_err());
        let mut p = paper_pair();
        p.profile_shift = [f64::NAN, 0.0];
        assert!(p.validate().is_err());
        let p = paper_pair();
        assert!(p.single_stiffness(0.0).is_err());
        assert!(p.mesh_stiffness(0.9, 100.0).is_err());
        assert!(MeshStiffnessWave::new(1e8, 0.9, 1e-2, 0.0).is_err());
        assert!(MeshStiffnessWave::new(1e8, 1.6, 1e-2, 0.3).is_err());
        assert!(MeshStiffnessWave::new(-1.0, 1.6, 1e-2, 0.0).is_err());
        assert!(rim_blank_factor(0.0, 0.03, 6e-3, 3e-3).is_err());
        assert!(spur_contact_ratio(18, 42, -1.0, 0.3).is_err());
    }

    /// The curvature `d2k/ds2` equals central differences of the slope (step 1e-9 base
    /// pitches; inside a ramp the slope is a quadratic, so the difference is exact up to
    /// round-off: slope ~ span / (w pb) ~ 1e10 N/m^2 with ~1e-6 relative round-off over
    /// a 1e-11 m step gives ~1e-5 of the curvature scale span / (w pb)^2; asserted 1e-4),
    /// away from the ramp ends, where it jumps.
    #[test]
    fn stiffness_curvature_is_the_slope_derivative() {
        let w = MeshStiffnessWave::new(2e8, 1.6, 1e-2, 0.05).unwrap();
        let pb = 1e-2;
        let scale = (w.high - w.low) / (0.05 * 0.05 * pb * pb);
        let mut inside = 0;
        for i in 0..4000 {
            let s = -0.013 + 3.0 * pb * i as f64 / 4000.0;
            let u = (s / pb).rem_euclid(1.0);
            let near_end = [0.0, 0.6, 1.0]
                .iter()
                .any(|e| ((u - e).abs() - 0.025).abs() < 1e-4);
            if near_end {
                continue;
            }
            let h = 1e-9 * pb;
            let fd = (w.stiffness_and_slope(s + h).1 - w.stiffness_and_slope(s - h).1) / (2.0 * h);
            let (_, _, d2) = w.stiffness_slope_curvature(s);
            if d2 != 0.0 {
                inside += 1;
            }
            assert!((fd - d2).abs() < 1e-4 * scale, "s = {s}: {fd} vs {d2}");
        }
        assert!(inside > 100, "{inside}");
    }
}
