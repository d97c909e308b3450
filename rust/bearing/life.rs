//! Basic dynamic load rating and basic rating life of radial roller bearings (ISO 281), and
//! the Palmgren bearing friction torque.
//!
//! ISO 281:2007, *Rolling bearings - Dynamic load ratings and rating life*, radial roller
//! bearings:
//!
//! `C_r = b_m f_c (i L_we cos alpha)^(7/9) Z^(3/4) D_we^(29/27)` [N, with lengths in mm],
//!
//! `b_m = 1.1` for cylindrical and needle roller bearings with machined rings (1.0 for drawn
//! cups), `i` rows, `L_we` effective roller length, `Z` rollers per row, `D_we` roller
//! diameter. The factor `f_c` of ISO 281 (tabulated against `gamma = D_we cos alpha / D_pw`,
//! `D_pw` the pitch diameter) is computed from the Lundberg-Palmgren expression that the table
//! is generated from (ISO/TR 1281-1, explanatory notes on ISO 281):
//!
//! `f_c = 207.9 lambda nu gamma^(2/9) (1 - gamma)^(29/27) (1 + gamma)^(-1/4)
//!        [1 + (1.04 ((1 - gamma)/(1 + gamma))^(143/108))^(9/2)]^(-2/9)`
//!
//! with the reduction factor `lambda nu = 0.83` for line contact. This reproduces the table
//! only to its rounding and is not checked here against the printed table (which is not in the
//! repository): treat `C_r` from it as an estimate within a few per cent.
//!
//! Basic rating life of a roller bearing: `L10 = (C_r / P)^(10/3)` million revolutions; for a
//! load varying over the revolutions, the equivalent load is
//! `P = (sum P_k^(10/3) N_k / sum N_k)^(3/10)` (ISO 281, variable load; Harris & Kotzalas,
//! *Rolling Bearing Analysis*, 5th ed. 2007, vol. 2, ch. on fatigue life).
//!
//! Basic static radial load rating of a radial roller bearing (ISO 76:2006, *Rolling bearings -
//! Static load ratings*): `C0r = 44 (1 - D_we cos alpha / D_pw) i Z L_we D_we cos alpha` [N,
//! with lengths in mm], the load at which the most loaded roller's contact reaches `4000 MPa` and a
//! permanent deformation of about 1e-4 of the roller diameter. The static safety factor
//! `s0 = C0r / P0` (`P0` the peak radial load) should be at least 1 (ISO 76 gives 1-3 by
//! application); below it the raceways yield and an elastic roller law no longer holds.
//!
//! Friction torque (A. Palmgren, *Ball and Roller Bearing Engineering*, 3rd ed., Burbank 1959;
//! as given by Harris & Kotzalas 2007, vol. 1, ch. on friction): `M = M0 + M1` [N mm] with the
//! load-independent (viscous) part `M0 = 1e-7 f0 (nu n)^(2/3) d_m^3` for `nu n >= 2000` and
//! `M0 = 160e-7 f0 d_m^3` below (`nu` oil kinematic viscosity in mm^2/s, `n` speed in rpm,
//! `d_m` pitch diameter in mm) and the load part `M1 = f1 F d_m` (`F` radial load in N).
//! `f0` and `f1` depend on the bearing type and lubrication (for cylindrical and needle roller
//! bearings `f1` is about 2e-4 to 4e-4 and `f0` a few units; they are inputs here).
//!
//! Theory: docs/model.md, section "Load rating, life and friction torque".

use crate::error::{Result, RvdynError, num, require_non_negative, require_positive};

/// Rating factor `b_m` of ISO 281 for cylindrical and needle roller bearings (machined rings).
pub const BM_ROLLER: f64 = 1.1;

/// Reduction factor `lambda nu` of the Lundberg-Palmgren `f_c` expression for line contact.
pub const LAMBDA_NU_LINE: f64 = 0.83;

/// Geometry of a radial roller bearing for its load rating (SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RollerBearingGeometry {
    /// Rollers per row `Z`.
    pub rollers: u32,
    /// Rows `i`.
    pub rows: u32,
    /// Roller diameter `D_we` \[m\].
    pub roller_diameter: f64,
    /// Effective roller length `L_we` \[m\].
    pub roller_length: f64,
    /// Pitch diameter of the roller set `D_pw` \[m\].
    pub pitch_diameter: f64,
    /// Nominal contact angle `alpha` \[rad\] (0 for radial roller bearings).
    pub contact_angle: f64,
    /// Rating factor `b_m` [-] (see [`BM_ROLLER`]).
    pub rating_factor: f64,
}

impl RollerBearingGeometry {
    /// Check the fields. Errors (`Parameter`): zero rollers or rows, non-positive sizes,
    /// roller diameter not below the pitch diameter, contact angle outside [0, 45 deg),
    /// non-positive rating factor.
    pub fn validate(&self) -> Result<()> {
        if self.rollers == 0 || self.rows == 0 {
            return Err(RvdynError::Parameter(format!(
                "a roller bearing needs at least one roller and one row, got {} rollers and {} \
                 rows",
                self.rollers, self.rows
            )));
        }
        require_positive("roller diameter", self.roller_diameter, "m")?;
        require_positive("roller length", self.roller_length, "m")?;
        require_positive("pitch diameter", self.pitch_diameter, "m")?;
        require_positive("rating factor b_m", self.rating_factor, "")?;
        if self.roller_diameter >= self.pitch_diameter {
            return Err(RvdynError::Parameter(format!(
                "roller diameter {} m must be smaller than the pitch diameter {} m",
                self.roller_diameter, self.pitch_diameter
            )));
        }
        let a = self.contact_angle;
        if !(a.is_finite() && (0.0..std::f64::consts::FRAC_PI_4).contains(&a)) {
            return Err(RvdynError::Parameter(format!(
                "contact angle of a radial roller bearing must be in [0, 45 deg), got {a} rad"
            )));
        }
        Ok(())
    }

    /// `gamma = D_we cos alpha / D_pw` [-].
    pub fn gamma(&self) -> f64 {
        self.roller_diameter * self.contact_angle.cos() / self.pitch_diameter
    }

    /// Basic static radial load rating `C0r` \[N\] (ISO 76; module documentation).
    pub fn static_load_rating(&self) -> Result<f64> {
        self.validate()?;
        let c = self.contact_angle.cos();
        Ok(44.0
            * (1.0 - self.gamma())
            * f64::from(self.rows)
            * f64::from(self.rollers)
            * (self.roller_length * 1e3)
            * (self.roller_diameter * 1e3)
            * c)
    }

    /// Basic dynamic radial load rating `C_r` \[N\] (ISO 281 with `f_c` from the
    /// Lundberg-Palmgren expression; module documentation).
    pub fn dynamic_load_rating(&self) -> Result<f64> {
        self.validate()?;
        let fc = fc_line_contact(self.gamma())?;
        let l_mm = self.roller_length * 1e3;
        let d_mm = self.roller_diameter * 1e3;
        Ok(self.rating_factor
            * fc
            * (f64::from(self.rows) * l_mm * self.contact_angle.cos()).powf(7.0 / 9.0)
            * f64::from(self.rollers).powf(0.75)
            * d_mm.powf(29.0 / 27.0))
    }
}

/// Factor `f_c` [-] of ISO 281 for radial roller bearings at `gamma = D_we cos alpha / D_pw`
/// (Lundberg-Palmgren expression with `lambda nu = 0.83`).
///
/// Errors (`Parameter`) unless `0 < gamma < 1`.
pub fn fc_line_contact(gamma: f64) -> Result<f64> {
    if !(gamma.is_finite() && gamma > 0.0 && gamma < 1.0) {
        return Err(RvdynError::Parameter(format!(
            "gamma = D_we cos(alpha) / D_pw must be in (0, 1), got {gamma}"
        )));
    }
    let g = gamma;
    let ratio = ((1.0 - g) / (1.0 + g)).powf(143.0 / 108.0);
    let bracket = 1.0 + (1.04 * ratio).powf(4.5);
    Ok(207.9
        * LAMBDA_NU_LINE
        * g.powf(2.0 / 9.0)
        * (1.0 - g).powf(29.0 / 27.0)
        * (1.0 + g).powf(-0.25)
        * bracket.powf(-2.0 / 9.0))
}

/// Basic rating life `L10 = (C / P)^(10/3)` [million revolutions] of a roller bearing.
///
/// Returns infinity for `P = 0` (no load, no fatigue). Errors (`Parameter`) for a non-positive
/// rating or a negative or non-finite load.
///
/// # Example
///
/// ```
/// use rvdyn::bearing::l10_roller;
/// // C = 80 kN, P = 10 kN: (C/P)^(10/3) = 8^(10/3) = 2^10 = 1024 million revolutions.
/// let life = l10_roller(80e3, 10e3).unwrap();
/// assert!((life - 1024.0).abs() < 1e-9);
/// assert_eq!(l10_roller(80e3, 0.0).unwrap(), f64::INFINITY);
/// ```
pub fn l10_roller(rating: f64, equivalent_load: f64) -> Result<f64> {
    require_positive("dynamic load rating", rating, "N")?;
    require_non_negative("equivalent dynamic load", equivalent_load, "N")?;
    if equivalent_load == 0.0 {
        return Ok(f64::INFINITY);
    }
    Ok((rating / equivalent_load).powf(10.0 / 3.0))
}

/// Weibull slope of roller bearings' fatigue lives (Lundberg-Palmgren; Harris & Kotzalas,
/// Essential Concepts of Bearing Technology, 5th ed., 2007, ch. 11).
pub const ROLLER_WEIBULL_SLOPE: f64 = 9.0 / 8.0;

/// L10 of a system of roller bearings that fails when any one does (Lundberg-Palmgren:
/// `L = (sum L_i^-e)^(-1/e)`, `e` = [`ROLLER_WEIBULL_SLOPE`]), in the unit of `lives`.
///
/// Errors (`Parameter`) for no life, or a life that is not positive (`inf`, a bearing that
/// never fails, is allowed).
///
/// # Example
///
/// ```
/// use rvdyn::bearing::system_life_roller;
/// // Two equal bearings: 2^(-8/9) of one's life.
/// let l = system_life_roller(&[1.0, 1.0]).unwrap();
/// assert!((l - 2f64.powf(-8.0 / 9.0)).abs() < 1e-15);
/// assert_eq!(system_life_roller(&[3.0, f64::INFINITY]).unwrap(), 3.0);
/// ```
pub fn system_life_roller(lives: &[f64]) -> Result<f64> {
    if lives.is_empty() {
        return Err(RvdynError::Parameter(
            "a system life needs the life of at least one bearing".into(),
        ));
    }
    let e = ROLLER_WEIBULL_SLOPE;
    if let Some(&bad) = lives.iter().find(|l| l.is_nan() || **l <= 0.0) {
        return Err(RvdynError::Parameter(format!(
            "a bearing life must be positive (inf for a bearing that never fails), got {}",
            num(bad)
        )));
    }
    // Scaled by the shortest life: no overflow of L^-e for tiny lives, and one finite life
    // comes back exactly.
    let shortest = lives.iter().copied().fold(f64::INFINITY, f64::min);
    if shortest == f64::INFINITY {
        return Ok(f64::INFINITY);
    }
    let sum: f64 = lives.iter().map(|l| (l / shortest).powf(-e)).sum();
    Ok(shortest * sum.powf(-1.0 / e))
}

/// Equivalent load \[N\] of a load history for roller-bearing life: `(sum w_k P_k^(10/3) /
/// sum w_k)^(3/10)` over samples `loads` \[N\] with weights `revolutions` (the revolutions, or
/// the rotation angle, spent at each sample; any consistent unit).
///
/// Errors (`Parameter`) for different lengths, an empty history, a negative or non-finite
/// load or weight, or all-zero weights.
///
/// # Example
///
/// ```
/// use rvdyn::bearing::{equivalent_load, l10_roller};
/// // 3/4 of the revolutions at 10 kN, 1/4 at 20 kN.
/// let p = equivalent_load(&[10e3, 20e3], &[3.0, 1.0]).unwrap();
/// // The life at P is the Palmgren-Miner sum of the lives at each load.
/// let c = 80e3;
/// let (l1, l2) = (l10_roller(c, 10e3).unwrap(), l10_roller(c, 20e3).unwrap());
/// let miner = 1.0 / (0.75 / l1 + 0.25 / l2);
/// assert!((l10_roller(c, p).unwrap() / miner - 1.0).abs() < 1e-12);
/// ```
pub fn equivalent_load(loads: &[f64], revolutions: &[f64]) -> Result<f64> {
    if loads.len() != revolutions.len() || loads.is_empty() {
        return Err(RvdynError::Parameter(format!(
            "load history and revolution weights must have the same non-zero length, got {} \
             and {}",
            loads.len(),
            revolutions.len()
        )));
    }
    let p = 10.0 / 3.0;
    let (mut num, mut den) = (0.0, 0.0);
    for (&f, &w) in loads.iter().zip(revolutions) {
        require_non_negative("bearing load sample", f, "N")?;
        require_non_negative("revolution weight", w, "")?;
        num += w * f.powf(p);
        den += w;
    }
    if den <= 0.0 {
        return Err(RvdynError::Parameter(
            "revolution weights are all zero: the bearing did not turn, no rating life".into(),
        ));
    }
    Ok((num / den).powf(1.0 / p))
}

/// Palmgren friction torque coefficients of a bearing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PalmgrenFriction {
    /// Load-independent factor `f0` [-].
    pub f0: f64,
    /// Load factor `f1` [-].
    pub f1: f64,
    /// Pitch diameter `d_m` \[m\].
    pub pitch_diameter: f64,
    /// Oil kinematic viscosity at operating temperature `nu` [m^2/s].
    pub viscosity: f64,
}

impl PalmgrenFriction {
    /// As [`PalmgrenFriction::torque`] without the checks (validated inputs, hot loops):
    /// friction torque magnitude [N m] at `speed` [rad/s] and radial load `load` \[N\].
    #[inline]
    pub fn torque_unchecked(&self, speed: f64, load: f64) -> f64 {
        let dm = self.pitch_diameter * 1e3;
        let vn = self.viscosity * 1e6 * speed.abs() * 60.0 / std::f64::consts::TAU;
        let m0 = if vn >= 2000.0 {
            1e-7 * self.f0 * vn.powf(2.0 / 3.0) * dm * dm * dm
        } else {
            160e-7 * self.f0 * dm * dm * dm
        };
        (m0 + self.f1 * load.max(0.0) * dm) * 1e-3
    }

    /// Friction torque [N m] at the speed `speed` [rad/s] (sign ignored) and radial load
    /// `load` \[N\]: `M0 + M1` of the module documentation, converted from N mm.
    ///
    /// Errors (`Parameter`) for negative factors, non-positive pitch diameter, negative
    /// viscosity or load, non-finite speed.
    pub fn torque(&self, speed: f64, load: f64) -> Result<f64> {
        require_non_negative("Palmgren f0", self.f0, "")?;
        require_non_negative("Palmgren f1", self.f1, "")?;
        require_positive("bearing pitch diameter", self.pitch_diameter, "m")?;
        require_non_negative("oil viscosity", self.viscosity, "m^2/s")?;
        require_non_negative("bearing load", load, "N")?;
        if !speed.is_finite() {
            return Err(RvdynError::Parameter(format!(
                "bearing speed must be finite, got {speed} rad/s"
            )));
        }
        let dm = self.pitch_diameter * 1e3; // mm
        let nu_cst = self.viscosity * 1e6; // mm^2/s
        let rpm = speed.abs() * 60.0 / (2.0 * std::f64::consts::PI);
        let vn = nu_cst * rpm;
        let m0 = if vn >= 2000.0 {
            1e-7 * self.f0 * vn.powf(2.0 / 3.0) * dm.powi(3)
        } else {
            160e-7 * self.f0 * dm.powi(3)
        };
        let m1 = self.f1 * load * dm;
        Ok((m0 + m1) * 1e-3)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::close;

    #[test]
    fn fc_by_hand() {
        // gamma = 0.1: 0.1^(2/9) = 0.599484, 0.9^(29/27) = 0.893 029, 1.1^(-1/4) = 0.976 454,
        // (0.9/1.1)^(143/108) = 0.766 668, (1.04 * 0.766 668)^4.5 = 0.360 897,
        // 1.360 897^(-2/9) = 0.933 826:
        // f_c = 207.9 * 0.83 * 0.599484 * 0.893029 * 0.976454 * 0.933826 = 84.235 (84.232
        // from the unrounded factors; ISO 281 tabulates 84.2 at gamma 0.1).
        let fc = fc_line_contact(0.1).unwrap();
        assert!(close(fc, 84.232, 1e-5), "{fc}");
        assert!(fc_line_contact(0.0).is_err());
        assert!(fc_line_contact(1.0).is_err());
    }

    #[test]
    fn rating_scales_as_the_standard_says() {
        let g = RollerBearingGeometry {
            rollers: 14,
            rows: 1,
            roller_diameter: 0.008,
            roller_length: 0.020,
            pitch_diameter: 0.080,
            contact_angle: 0.0,
            rating_factor: BM_ROLLER,
        };
        let c = g.dynamic_load_rating().unwrap();
        let by_hand = 1.1
            * fc_line_contact(0.1).unwrap()
            * 20f64.powf(7.0 / 9.0)
            * 14f64.powf(0.75)
            * 8f64.powf(29.0 / 27.0);
        assert!(close(c, by_hand, 1e-14));
        // 84.23 * 1.1 * 10.27 * 7.24 * 9.33: about 64 kN, the size class of a needle bearing
        // with 14 rollers of 8 x 20 mm.
        assert!(c > 55e3 && c < 75e3, "{c}");
        // Doubling the rows multiplies by 2^(7/9).
        let mut g2 = g;
        g2.rows = 2;
        assert!(close(
            g2.dynamic_load_rating().unwrap(),
            c * 2f64.powf(7.0 / 9.0),
            1e-14
        ));
        let mut bad = g;
        bad.rollers = 0;
        assert!(bad.dynamic_load_rating().is_err());
        let mut bad = g;
        bad.roller_diameter = 0.1;
        assert!(bad.validate().is_err());
    }

    #[test]
    fn life_and_equivalent_load() {
        // C = 2P -> L10 = 2^(10/3) = 10.079 million revolutions.
        assert!(close(
            l10_roller(2e4, 1e4).unwrap(),
            2f64.powf(10.0 / 3.0),
            1e-14
        ));
        assert_eq!(l10_roller(2e4, 0.0).unwrap(), f64::INFINITY);
        assert!(l10_roller(0.0, 1.0).is_err());
        assert!(l10_roller(1.0, -1.0).is_err());
        // Constant load: P itself; two levels by hand.
        assert!(close(
            equivalent_load(&[5e3; 4], &[1.0; 4]).unwrap(),
            5e3,
            1e-14
        ));
        let p = equivalent_load(&[1e3, 2e3], &[3.0, 1.0]).unwrap();
        let by_hand = ((3.0 * 1e3f64.powf(10.0 / 3.0) + 2e3f64.powf(10.0 / 3.0)) / 4.0).powf(0.3);
        assert!(close(p, by_hand, 1e-14));
        assert!(equivalent_load(&[1.0], &[0.0]).is_err());
        assert!(equivalent_load(&[1.0, 2.0], &[1.0]).is_err());
        assert!(equivalent_load(&[], &[]).is_err());
        assert!(equivalent_load(&[-1.0], &[1.0]).is_err());
    }

    #[test]
    fn palmgren_torque_by_hand() {
        // d_m = 50 mm, f0 = 3, f1 = 3e-4, nu = 68 cSt, 1500 rpm (nu n = 102 000 >= 2000),
        // F = 10 kN: M0 = 1e-7 * 3 * 102000^(2/3) * 125000 = 81.86 N mm;
        // M1 = 3e-4 * 1e4 * 50 = 150 N mm -> 0.2319 N m.
        let f = PalmgrenFriction {
            f0: 3.0,
            f1: 3e-4,
            pitch_diameter: 0.050,
            viscosity: 68e-6,
        };
        let w = 1500.0 * 2.0 * std::f64::consts::PI / 60.0;
        let m = f.torque(w, 1e4).unwrap();
        assert!(close(f.torque_unchecked(w, 1e4), m, 1e-12));
        let m0 = 1e-7 * 3.0 * 102_000f64.powf(2.0 / 3.0) * 125_000.0;
        assert!(close(m, (m0 + 150.0) * 1e-3, 1e-12), "{m}");
        assert!(close(m, 0.2319, 1e-3), "{m}");
        // Slow: the constant branch 160e-7 f0 d_m^3 = 6 N mm.
        let m = f.torque(0.0, 0.0).unwrap();
        assert!(close(m, 160e-7 * 3.0 * 125_000.0 * 1e-3, 1e-12));
        let mut bad = f;
        bad.f1 = -1.0;
        assert!(bad.torque(1.0, 1.0).is_err());
        assert!(f.torque(f64::NAN, 1.0).is_err());
    }
}
