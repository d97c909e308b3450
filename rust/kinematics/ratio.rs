//! Transmission ratio and body speeds of the two-stage RV reducer (paper eqs. 1-4).
//!
//! Sun (input) -> planets on crankshafts whose axes are fixed in the carrier -> eccentrics ->
//! cycloid discs meshing with fixed pins -> carrier (output). With carrier speed `w_c`, crank
//! speed relative to the carrier `phi'` and the disc lobes `zc = pins - 1`:
//! - the discs mesh with the fixed pins when `phi' = -pins w_c`
//!   (docs/model.md#coordinates-and-degrees-of-freedom);
//! - the sun/planet mesh rolls: `r_s (w_s - w_c) = -r_p phi'`, so
//!   `w_s = w_c (1 + pins z_planet / z_sun)` and `i = w_s / w_c = 1 + (z_planet/z_sun) pins`.

use crate::error::{Result, RvdynError, num, require_finite};

/// Overall ratio `i = input speed / output speed = 1 + (z_planet / z_sun) * pins` (eq. 4) [-].
///
/// Returns 57 for the paper (18, 42, 24). Errors (`RvdynError::Geometry`) if `z_sun` or
/// `z_planet` is 0 or `pins < 3`.
///
/// # Example
///
/// ```
/// use rvdyn::kinematics::transmission_ratio;
/// // The paper's reducer: sun 18, planet 42, 24 pins: 1 + (42/18) 24 = 57.
/// assert_eq!(transmission_ratio(18, 42, 24).unwrap(), 57.0);
/// assert!(transmission_ratio(18, 42, 2).is_err()); // a cycloid stage needs 3 pins
/// ```
pub fn transmission_ratio(z_sun: u32, z_planet: u32, pins: u32) -> Result<f64> {
    if z_sun < 1 || z_planet < 1 {
        return Err(RvdynError::Geometry(format!(
            "tooth counts must be at least 1, got z_sun = {z_sun}, z_planet = {z_planet}"
        )));
    }
    if pins < 3 {
        return Err(RvdynError::Geometry(format!(
            "a cycloid stage needs at least 3 pins (a disc with pins - 1 >= 2 lobes), got \
             {pins}"
        )));
    }
    Ok(1.0 + f64::from(z_planet) / f64::from(z_sun) * f64::from(pins))
}

/// Angular speeds of the bodies [rad/s], counter-clockwise positive, for a given input.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodySpeeds {
    /// Sun gear (input shaft) [rad/s].
    pub sun: f64,
    /// Crankshaft (and its planet) about its own axis, absolute [rad/s].
    pub crank_absolute: f64,
    /// Crankshaft about its own axis, relative to the carrier `phi'` [rad/s].
    pub crank_relative: f64,
    /// Spin of each cycloid disc about its own centre [rad/s] (equals the carrier: the
    /// parallel cranks keep the discs from turning relative to the carrier).
    pub disc_spin: f64,
    /// Orbit of each disc centre about the reducer axis [rad/s] (equals the absolute crank
    /// speed: the eccentric points along the crank's absolute angle).
    pub disc_orbit: f64,
    /// Carrier (output) [rad/s].
    pub carrier: f64,
}

/// Body speeds [rad/s] for an input (sun) speed `input_speed` [rad/s].
///
/// Returns carrier `= input / i`, crank relative `phi' = -pins * carrier`, crank absolute
/// `= carrier + phi'`, disc spin `= carrier`, disc orbit `= crank absolute`, sun `= input`.
/// Errors: a non-finite input speed (`Parameter`) or the tooth-count errors of
/// [`transmission_ratio`].
///
/// # Example
///
/// ```
/// use rvdyn::kinematics::body_speeds;
/// let w_in = 8328f64.to_radians(); // the paper's input speed, 145.35 rad/s
/// let s = body_speeds(w_in, 18, 42, 24).unwrap();
/// assert!((s.carrier - w_in / 57.0).abs() < 1e-12);
/// // Cycloid kinematics: a disc with zc = 23 lobes turns by -1/zc of its orbit.
/// assert!((s.disc_spin + s.disc_orbit / 23.0).abs() < 1e-12);
/// ```
pub fn body_speeds(input_speed: f64, z_sun: u32, z_planet: u32, pins: u32) -> Result<BodySpeeds> {
    require_finite("input speed", input_speed)?;
    let carrier = input_speed / transmission_ratio(z_sun, z_planet, pins)?;
    let crank_relative = -f64::from(pins) * carrier;
    let crank_absolute = carrier + crank_relative;
    if !(crank_relative.is_finite() && crank_absolute.is_finite()) {
        return Err(RvdynError::Parameter(format!(
            "input speed {} rad/s overflows the crank speed for z_sun = {z_sun}, z_planet = \
             {z_planet}, pins = {pins}: give a speed of physical size",
            num(input_speed)
        )));
    }
    Ok(BodySpeeds {
        sun: input_speed,
        crank_absolute,
        crank_relative,
        disc_spin: carrier,
        disc_orbit: crank_absolute,
        carrier,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::close;

    #[test]
    fn paper_ratio_is_57() {
        // 1 + (42/18) * 24 = 1 + 56 = 57.
        assert_eq!(transmission_ratio(18, 42, 24).unwrap(), 57.0);
        // 1 + (30/20) * 12 = 19.
        assert_eq!(transmission_ratio(20, 30, 12).unwrap(), 19.0);
    }

    #[test]
    fn invalid_counts() {
        assert!(transmission_ratio(0, 42, 24).is_err());
        assert!(transmission_ratio(18, 0, 24).is_err());
        let e = transmission_ratio(18, 42, 2).unwrap_err();
        assert!(matches!(e, RvdynError::Geometry(_)) && e.to_string().contains("3 pins"));
        assert!(body_speeds(f64::NAN, 18, 42, 24).is_err());
        // Finite input, overflowing crank speed (crank/carrier = pins): an error, not inf.
        assert!(body_speeds(1e308, u32::MAX, 1, u32::MAX).is_err());
        assert!(body_speeds(1e290, u32::MAX, 1, u32::MAX).is_ok());
    }

    #[test]
    fn speeds_satisfy_the_paper_equations() {
        let (z1, z2, zp) = (18u32, 42u32, 24u32);
        let zc = f64::from(zp - 1);
        let w = 8328f64.to_radians();
        let s = body_speeds(w, z1, z2, zp).unwrap();
        assert!(close(s.carrier, w / 57.0, 1e-15));
        // Eq. 1 (carrier fixed): (n1 - nw) / (n2 - nw) = -z2/z1 with n2 the planet (crank).
        let eq1 = (s.sun - s.carrier) / (s.crank_absolute - s.carrier);
        assert!(close(eq1, -42.0 / 18.0, 1e-14));
        // Eq. 2 (eccentric fixed): (n3 - n5) / (n4 - n5) = z4/z3 with n3 the disc spin,
        // n4 = 0 the pins, n5 the eccentric (disc orbit): (c - (1-24)c) / (23c) = 24/23.
        let eq2 = (s.disc_spin - s.disc_orbit) / (0.0 - s.disc_orbit);
        assert!(close(eq2, f64::from(zp) / zc, 1e-14));
        // The disc turns by -psi/zc when its centre orbits by psi (cycloid kinematics).
        assert!(close(s.disc_spin, -s.disc_orbit / zc, 1e-14));
        // Rolling of the sun/planet mesh with radii proportional to the tooth counts.
        let (rs, rp) = (f64::from(z1), f64::from(z2));
        assert!((rs * (s.sun - s.carrier) + rp * s.crank_relative).abs() < 1e-12 * rs * s.sun);
        assert!(close(s.crank_absolute, s.carrier + s.crank_relative, 1e-15));
        assert_eq!(s.sun, w);
    }

    #[test]
    fn reverse_input_reverses_everything() {
        let f = body_speeds(1.0, 18, 42, 24).unwrap();
        let r = body_speeds(-1.0, 18, 42, 24).unwrap();
        assert_eq!(r.carrier, -f.carrier);
        assert_eq!(r.crank_absolute, -f.crank_absolute);
        // Carrier turns with the input, the cranks against it: 1/57 and -23/57.
        assert!(close(f.crank_absolute, -23.0 / 57.0, 1e-15));
    }
}
