//! Line contact of two parallel elastic cylinders as a force law `F(delta)` from geometry.
//!
//! Two bodies touch along a line of length `L` (the face width). Body `k` has the signed
//! curvature `kappa_k` at the contact (positive convex, negative concave, 0 flat) and a
//! reference depth `h_k`: the distance from the contact into the body at which the approach is
//! measured (for a solid cylinder its radius). With the line load `P = F / L`:
//!
//! - effective radius `1/R = kappa_1 + kappa_2` (a concave body contributes the *difference*
//!   of curvatures; `R > 0` is required);
//! - effective modulus `1/E* = (1 - nu_1^2)/E_1 + (1 - nu_2^2)/E_2`;
//! - Hertz half width `a = sqrt(4 P R / (pi E*))`, peak pressure `p0 = 2 P / (pi a)`
//!   (K. L. Johnson, *Contact Mechanics*, Cambridge University Press 1985, ch. 4,
//!   two-dimensional contact of cylinders, pp. 99-104);
//! - approach (the sum over both bodies of the compression from depth `h_k` to the contact):
//!
//!   `delta(F) = sum_k P (1 - nu_k^2) / (pi E_k) * (2 ln(4 h_k / a) - 1)`
//!
//!   which is Johnson's compression of a cylinder of radius `h_k` from its axis to the contact
//!   (Johnson 1985, same section; the same expression is reviewed as "Johnson's model" by
//!   C. M. Pereira, A. L. Ramalho, J. A. Ambrosio, *A critical overview of internal and
//!   external cylinder contact force models*, Nonlinear Dyn. 63 (2011) 681-697).
//!
//! With `x = ln F` the approach is `delta = e^x (K0 - K1 x)` with
//! `K1 = 1 / (pi L E*)` and `K0 = sum_k c_k (2 ln(4 h_k / alpha) - 1) / (pi L)`,
//! `c_k = (1 - nu_k^2)/E_k`, `a = alpha sqrt(F)`, `alpha = sqrt(4 R / (pi L E*))`. The law gives
//! `delta(F)` explicitly; [`LineContactLaw::force`] inverts it (Newton on `ln F`, which is
//! monotone and cannot overshoot, see the function). The tangent stiffness
//! `dF/d delta = 1 / (K0 - K1 (1 + ln F))` tends to 0 as `F -> 0` (logarithmically), so force
//! and stiffness are continuous from zero load.
//!
//! Validity: the 2-D Hertz theory needs `a << h_k` and `a << R`. Beyond the load at which
//! `a = min(h_1, h_2, R) / 2` the law continues as a straight line with the tangent stiffness of
//! that point (force and stiffness continuous); at the default pin contact that load is about
//! 240 times the rated peak pin force (35 kN), so this extension only guards against nonsense states.
//!
//! Profile curvature of a cycloid disc at a pin contact: see [`pin_disc_profile_curvature`].

use crate::contact::hertz::{Material, effective_modulus};
use crate::error::{Result, RvdynError, require_non_negative, require_positive};
use std::f64::consts::PI;

/// A line-contact force law `F(delta)` of two parallel cylinders (Johnson 1985; see the module
/// documentation). All quantities SI: m, N, Pa.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineContactLaw {
    length: f64,
    /// Effective radius `R` \[m\].
    radius: f64,
    /// Effective modulus `E*` \[Pa\].
    e_star: f64,
    /// Reference depths `h_1`, `h_2` \[m\].
    depths: [f64; 2],
    /// Plane-strain compliances `(1 - nu_k^2)/E_k` [1/Pa].
    compliances: [f64; 2],
    /// `delta = F (k0 - k1 ln F)` [m/N].
    k0: f64,
    k1: f64,
    /// `a = alpha sqrt(F)` [m/sqrt(N)].
    alpha: f64,
    /// Start of the linear extension: force \[N\], approach \[m\], compliance d delta/dF [m/N].
    f_lim: f64,
    /// `ln f_lim` (kept: the inversion's bound).
    x_lim: f64,
    delta_lim: f64,
    compliance_lim: f64,
}

impl LineContactLaw {
    /// Build the law from the contact length \[m\], the signed curvatures of the two surfaces at
    /// the contact [1/m] (positive convex, negative concave, 0 flat), the reference depths of
    /// the two bodies \[m\] and their materials.
    ///
    /// Errors: `Parameter` for a non-positive or non-finite length or depth, a non-finite
    /// curvature, an invalid material; `Geometry` if `kappa_1 + kappa_2 <= 0` (concave-concave,
    /// conformal or nested surfaces: no Hertz line contact).
    ///
    /// ```
    /// # use rvdyn::contact::{Material, line_contact::LineContactLaw};
    /// // 10 mm pin on a convex 94 mm profile radius, 40 mm face width, two steels.
    /// let s = Material::steel();
    /// let law = LineContactLaw::new(0.040, 1.0 / 0.010, 1.0 / 0.094, 0.010, 0.094, &s, &s)
    ///     .unwrap();
    /// let d = law.approach(35e3).unwrap();
    /// assert!((d - 25.9e-6).abs() < 0.1e-6);
    /// assert!((law.force(d) - 35e3).abs() < 1e-6);
    /// ```
    pub fn new(
        length: f64,
        curvature1: f64,
        curvature2: f64,
        depth1: f64,
        depth2: f64,
        m1: &Material,
        m2: &Material,
    ) -> Result<Self> {
        require_positive("contact length", length, "m")?;
        require_positive("reference depth of body 1", depth1, "m")?;
        require_positive("reference depth of body 2", depth2, "m")?;
        for (name, k) in [("curvature 1", curvature1), ("curvature 2", curvature2)] {
            if !k.is_finite() {
                return Err(RvdynError::Parameter(format!(
                    "contact {name} must be finite (1/m, positive convex, negative concave), \
                     got {k}"
                )));
            }
        }
        m1.validate()?;
        m2.validate()?;
        Self::from_checked(length, curvature1, curvature2, depth1, depth2, m1, m2)
    }

    /// [`LineContactLaw::new`] without the checks of the length, depths, curvatures and
    /// materials (the caller has validated them once, e.g. at scene build): the same arithmetic
    /// and the same `Geometry` error for a non-positive curvature sum.
    #[inline]
    pub(crate) fn from_checked(
        length: f64,
        curvature1: f64,
        curvature2: f64,
        depth1: f64,
        depth2: f64,
        m1: &Material,
        m2: &Material,
    ) -> Result<Self> {
        let sum = curvature1 + curvature2;
        if !(sum > 0.0 && sum.is_finite()) {
            return Err(curvature_sum_error(curvature1, curvature2));
        }
        let radius = 1.0 / sum;
        let e_star = effective_modulus(m1, m2);
        let compliances = [m1.compliance(), m2.compliance()];
        let depths = [depth1, depth2];
        let alpha = (4.0 * radius / (PI * length * e_star)).sqrt();
        let k1 = 1.0 / (PI * length * e_star);
        let k0 = (0..2)
            .map(|k| compliances[k] * (2.0 * (4.0 * depths[k] / alpha).ln() - 1.0))
            .sum::<f64>()
            / (PI * length);
        let a_lim = 0.5 * depth1.min(depth2).min(radius);
        let f_lim = (a_lim / alpha).powi(2);
        Self::from_coefficients(
            length,
            radius,
            e_star,
            depths,
            compliances,
            [k0, k1, alpha],
            f_lim,
            f_lim.ln(),
        )
    }

    /// The law from its coefficients `[K0, K1, alpha]` and validity limit `f_lim` \[N\] with
    /// `x_lim = ln f_lim`: the approach and compliance at the limit, and an error (never a
    /// NaN) for coefficients beyond floating-point range. With `a <= h/2` every log term is
    /// `>= ln 8 > 1`, so this cannot fail for finite input.
    #[allow(clippy::too_many_arguments)]
    fn from_coefficients(
        length: f64,
        radius: f64,
        e_star: f64,
        depths: [f64; 2],
        compliances: [f64; 2],
        [k0, k1, alpha]: [f64; 3],
        f_lim: f64,
        x_lim: f64,
    ) -> Result<Self> {
        let delta_lim = f_lim * (k0 - k1 * x_lim);
        let compliance_lim = k0 - k1 * (1.0 + x_lim);
        if !(f_lim.is_finite() && delta_lim > 0.0 && compliance_lim > 0.0) {
            return Err(RvdynError::Parameter(format!(
                "line contact law out of range (length {length} m, R {radius} m, depths {} m, \
                 {} m)",
                depths[0], depths[1]
            )));
        }
        Ok(Self {
            length,
            radius,
            e_star,
            depths,
            compliances,
            k0,
            k1,
            alpha,
            f_lim,
            x_lim,
            delta_lim,
            compliance_lim,
        })
    }

    /// The law of a pin of radius `pin_radius` \[m\] against a disc profile of signed curvature
    /// `profile_curvature` [1/m] (positive convex, negative concave), face width
    /// `face_width` \[m\].
    ///
    /// Reference depths: the pin radius for the pin (a solid cylinder, Johnson's case); for the
    /// disc, where the profile is convex, its local radius of curvature `1/kappa` (the
    /// "cylinder of the actual radius at the contact"), capped at `disc_depth` \[m\], a body
    /// dimension (e.g. the distance from the disc centre to the contact): near a profile
    /// inflection the radius of curvature is unbounded, while the disc is not. Where the
    /// profile is concave or flat there is no solid cylinder on the disc side: the seat is
    /// backed by the disc body, and the depth is `disc_depth`. The switch between the two
    /// branches is blended (see [`disc_reference_depth`]), so the law and its derivatives
    /// along the profile are continuous.
    ///
    /// Errors as [`LineContactLaw::new`].
    pub fn pin_disc(
        pin_radius: f64,
        profile_curvature: f64,
        disc_depth: f64,
        face_width: f64,
        pin: &Material,
        disc: &Material,
    ) -> Result<Self> {
        require_positive("pin radius", pin_radius, "m")?;
        require_positive("disc reference depth", disc_depth, "m")?;
        if !profile_curvature.is_finite() {
            return Err(RvdynError::Parameter(format!(
                "profile curvature must be finite (1/m), got {profile_curvature}"
            )));
        }
        let h2 = disc_reference_depth(profile_curvature, disc_depth).depth;
        Self::new(
            face_width,
            1.0 / pin_radius,
            profile_curvature,
            pin_radius,
            h2,
            pin,
            disc,
        )
    }

    /// The law of a pin of radius `pin_radius` \[m\] touching the disc `geometry` at the curve
    /// parameter `phi` \[rad\] (the foot of an exact gap query), with the disc body depth
    /// `disc_depth` \[m\] (e.g. the distance from the disc centre to the contact) and the face
    /// width of the disc. The profile curvature is [`pin_disc_profile_curvature`] of the
    /// pin-centre curve's curvature at `phi`.
    ///
    /// Errors as [`LineContactLaw::pin_disc`] and [`pin_disc_profile_curvature`].
    pub fn cycloid_contact(
        geometry: &crate::geometry::CycloidGeometry,
        phi: f64,
        pin_radius: f64,
        disc_depth: f64,
        pin: &Material,
        disc: &Material,
    ) -> Result<Self> {
        require_positive("pin radius", pin_radius, "m")?;
        require_positive("disc reference depth", disc_depth, "m")?;
        pin.validate()?;
        disc.validate()?;
        Self::cycloid_contact_checked(geometry, phi, pin_radius, disc_depth, pin, disc)
    }

    /// [`LineContactLaw::cycloid_contact`] for a positive finite pin radius and disc depth and
    /// valid materials (checked once by the caller): the same law, without re-checking them
    /// at every contact evaluation. Errors (`Geometry`) as [`pin_disc_profile_curvature`] and
    /// for a non-positive curvature sum.
    #[inline]
    pub(crate) fn cycloid_contact_checked(
        geometry: &crate::geometry::CycloidGeometry,
        phi: f64,
        pin_radius: f64,
        disc_depth: f64,
        pin: &Material,
        disc: &Material,
    ) -> Result<Self> {
        let kappa = pin_disc_profile_curvature(
            geometry.centre_curve_curvature(phi),
            geometry.generating_pin_radius(),
        )?;
        let h2 = disc_reference_depth(kappa, disc_depth).depth;
        Self::from_checked(
            geometry.params().face_width,
            1.0 / pin_radius,
            kappa,
            pin_radius,
            h2,
            pin,
            disc,
        )
    }

    /// Contact length \[m\].
    pub fn length(&self) -> f64 {
        self.length
    }

    /// Effective radius `R` \[m\], `1/R = kappa_1 + kappa_2`.
    pub fn effective_radius(&self) -> f64 {
        self.radius
    }

    /// Effective modulus `E*` \[Pa\].
    pub fn effective_modulus(&self) -> f64 {
        self.e_star
    }

    /// Reference depths `[h_1, h_2]` \[m\].
    pub fn depths(&self) -> [f64; 2] {
        self.depths
    }

    /// Force \[N\] above which the law is continued linearly (`a = min(h_1, h_2, R)/2`).
    pub fn validity_limit(&self) -> f64 {
        self.f_lim
    }

    /// Hertz half width `a = sqrt(4 F R / (pi L E*))` \[m\] at the force `force` \[N\].
    ///
    /// Errors (`Parameter`) for a negative or non-finite force.
    pub fn half_width(&self, force: f64) -> Result<f64> {
        require_non_negative("contact force", force, "N")?;
        Ok(self.alpha * force.sqrt())
    }

    /// Hertz peak pressure `p0 = 2 F / (pi L a) = sqrt(F E* / (pi L R))` \[Pa\] at `force` \[N\].
    ///
    /// Errors (`Parameter`) for a negative or non-finite force.
    pub fn peak_pressure(&self, force: f64) -> Result<f64> {
        require_non_negative("contact force", force, "N")?;
        Ok((force * self.e_star / (PI * self.length * self.radius)).sqrt())
    }

    /// The approach `delta(F)` \[m\] at the force `force` \[N\], the closed form of the module
    /// documentation (linear beyond [`LineContactLaw::validity_limit`]).
    ///
    /// Returns 0 at zero force. Errors (`Parameter`) for a negative or non-finite force.
    pub fn approach(&self, force: f64) -> Result<f64> {
        require_non_negative("contact force", force, "N")?;
        Ok(self.approach_unchecked(force))
    }

    /// The approach written as Johnson's sum over the two bodies (the same value as
    /// [`LineContactLaw::approach`] below the validity limit; an independent form for checks).
    pub fn approach_johnson_sum(&self, force: f64) -> Result<f64> {
        require_non_negative("contact force", force, "N")?;
        if force == 0.0 {
            return Ok(0.0);
        }
        let p = force / self.length;
        let a = self.alpha * force.sqrt();
        Ok((0..2)
            .map(|k| p * self.compliances[k] / PI * (2.0 * (4.0 * self.depths[k] / a).ln() - 1.0))
            .sum())
    }

    fn approach_unchecked(&self, force: f64) -> f64 {
        if force <= 0.0 {
            0.0
        } else if force >= self.f_lim {
            self.delta_lim + (force - self.f_lim) * self.compliance_lim
        } else {
            force * (self.k0 - self.k1 * force.ln())
        }
    }

    /// Contact force \[N\] at the approach `delta` \[m\]: 0 for `delta <= 0` (and for NaN).
    ///
    /// Inverts `delta = e^x (K0 - K1 x)`, `x = ln F`, by Newton's method on
    /// `g(x) = x + ln(K0 - K1 x) - ln delta`. `g` is increasing and concave below the validity
    /// limit, so the first Newton step from the limit lands left of the root and the iterates
    /// then increase monotonically to it (no overshoot, no bracketing needed); stops when the
    /// step is below 1e-15 (relative force error about 1e-15), or when the error it leaves,
    /// bounded by Newton's quadratic convergence `(|g''| / g') step^2` (`g'' = -(K1/q)^2`,
    /// `q = K0 - K1 x`, with a factor 2 of margin), is below 1e-17 of `|x|` (a tenth of an ulp):
    /// from a warm start one logarithm fewer for the same result to round-off.
    #[inline]
    pub fn force(&self, delta: f64) -> f64 {
        self.force_and_stiffness(delta).0
    }

    /// Contact force \[N\] and tangent stiffness `dF/d delta` [N/m] at the approach `delta` \[m\].
    ///
    /// Both are 0 for `delta <= 0`; both are continuous in `delta` and tend to 0 as
    /// `delta -> 0+`.
    pub fn force_and_stiffness(&self, delta: f64) -> (f64, f64) {
        let (f, k, _) = self.force_and_stiffness_from(delta, f64::NAN);
        (f, k)
    }

    /// As [`LineContactLaw::force_and_stiffness`], starting Newton from `ln_force_guess`
    /// (`ln F` of a nearby earlier solution; a non-finite guess or one above the validity limit
    /// starts from the limit). Returns `(F, dF/d delta, ln F)`; keep the last value as the next guess.
    /// Any start at or below the limit converges monotonically after at most one step (see
    /// [`LineContactLaw::force`]), so the guess only saves iterations (1-2 from a close one).
    pub fn force_and_stiffness_from(&self, delta: f64, ln_force_guess: f64) -> (f64, f64, f64) {
        if delta.is_nan() || delta <= 0.0 {
            return (0.0, 0.0, f64::NEG_INFINITY);
        }
        if delta >= self.delta_lim {
            let f = self.f_lim + (delta - self.delta_lim) / self.compliance_lim;
            return (f, 1.0 / self.compliance_lim, f.ln());
        }
        let ln_d = delta.ln();
        let x_lim = self.x_lim;
        let mut x = if ln_force_guess.is_finite() && ln_force_guess <= x_lim {
            ln_force_guess
        } else {
            x_lim
        };
        for _ in 0..100 {
            let q = self.k0 - self.k1 * x; // > K1 > 0 for x <= x_lim
            let g = x + q.ln() - ln_d;
            let r = self.k1 / q;
            let dg = 1.0 - r;
            let step = g / dg;
            x -= step;
            let clamped = x > x_lim;
            if clamped {
                x = x_lim;
            }
            // Newton's error after this step is (|g''(xi)| / (2 g')) step^2 to leading order,
            // g'' = -(K1/q)^2; with a factor 2 for xi (q changes by K1 |step| << q there): below
            // 1e-17 of |x| the iterate is exact to a tenth of its last bit, and the next step
            // (a logarithm) would change nothing.
            let scale = x.abs().max(1.0);
            if step.abs() <= 1e-15 * scale
                || (!clamped && r * r / dg * step * step <= 1e-17 * scale)
            {
                break;
            }
        }
        let f = x.exp();
        let compliance = self.k0 - self.k1 * (1.0 + x);
        (f, 1.0 / compliance, x)
    }

    /// Elastic energy stored at the approach `delta` \[m\], `U = integral_0^delta F d delta` \[J\].
    ///
    /// Closed form `U = F delta - integral_0^F delta(f) df` with
    /// `integral_0^F f (K0 - K1 ln f) df = F^2 (K0/2 - K1 (ln F / 2 - 1/4))`; 0 for
    /// `delta <= 0`.
    pub fn elastic_energy(&self, delta: f64) -> f64 {
        if delta.is_nan() || delta <= 0.0 {
            return 0.0;
        }
        let integral_below = |f: f64| f * f * (0.5 * self.k0 - self.k1 * (0.5 * f.ln() - 0.25));
        if delta >= self.delta_lim {
            // Energy at the limit plus the trapezoid of the linear part.
            let u_lim = self.f_lim * self.delta_lim - integral_below(self.f_lim);
            let f = self.f_lim + (delta - self.delta_lim) / self.compliance_lim;
            return u_lim + 0.5 * (self.f_lim + f) * (delta - self.delta_lim);
        }
        let f = self.force(delta);
        f * delta - integral_below(f)
    }
}

/// The part of a pin-disc line law that does not depend on the contact point (a pin radius, a
/// face width and the two materials, checked once by the caller): with it the law at a contact
/// ([`PinDiscLawBase::law`]) takes one logarithm, `ln R`, where
/// [`LineContactLaw::pin_disc`] takes three (`ln(4 h_k / alpha)` for both bodies and
/// `ln f_lim`): with `ln alpha = ln sqrt(4 / (pi L E*)) + (ln R) / 2`,
/// `ln(4 h_k / alpha) = ln 4 + ln h_k - ln alpha` and `ln f_lim = 2 (ln a_lim - ln alpha)`, the
/// pin's `ln h_1` kept here and the disc's `ln h_2` given. The same law as
/// [`LineContactLaw::pin_disc`] to round-off (tested).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PinDiscLawBase {
    length: f64,
    pin_radius: f64,
    inv_pin_radius: f64,
    e_star: f64,
    compliances: [f64; 2],
    /// `pi L` \[m\].
    pi_length: f64,
    /// `1 / (pi L E*)` [m/N].
    k1: f64,
    /// `ln sqrt(4 / (pi L E*))`.
    ln_alpha0: f64,
    /// `ln r_pin`.
    ln_h1: f64,
}

impl PinDiscLawBase {
    /// For a pin of radius `pin_radius` \[m\] (positive, finite), the face width `face_width` \[m\]
    /// (positive, finite) and valid materials.
    pub(crate) fn new(pin_radius: f64, face_width: f64, pin: &Material, disc: &Material) -> Self {
        let e_star = effective_modulus(pin, disc);
        let pi_length = PI * face_width;
        Self {
            length: face_width,
            pin_radius,
            inv_pin_radius: 1.0 / pin_radius,
            e_star,
            compliances: [pin.compliance(), disc.compliance()],
            pi_length,
            k1: 1.0 / (pi_length * e_star),
            ln_alpha0: 0.5 * (4.0 / (pi_length * e_star)).ln(),
            ln_h1: pin_radius.ln(),
        }
    }

    /// `(1 - nu^2)/E` of the pin and of the disc [1/Pa].
    #[inline]
    pub(crate) fn compliances(&self) -> [f64; 2] {
        self.compliances
    }

    /// `pi L` \[m\].
    #[inline]
    pub(crate) fn pi_length(&self) -> f64 {
        self.pi_length
    }

    /// `1 / r_pin` [1/m].
    #[inline]
    pub(crate) fn pin_curvature(&self) -> f64 {
        self.inv_pin_radius
    }

    /// The law against a disc profile of signed curvature `kappa` [1/m] with the disc's
    /// reference depth `h2` \[m\] and its logarithm `ln_h2`. Errors (`Geometry`) for a
    /// non-positive curvature sum, as [`LineContactLaw::new`].
    #[inline]
    pub(crate) fn law(&self, kappa: f64, h2: f64, ln_h2: f64) -> Result<LineContactLaw> {
        let sum = self.inv_pin_radius + kappa;
        if !(sum > 0.0 && sum.is_finite()) {
            return Err(curvature_sum_error(self.inv_pin_radius, kappa));
        }
        let radius = 1.0 / sum;
        let ln_r = -sum.ln();
        let (length, e_star, c) = (self.length, self.e_star, self.compliances);
        let alpha = (4.0 * radius / (PI * length * e_star)).sqrt();
        let ln_alpha = self.ln_alpha0 + 0.5 * ln_r;
        let ln4 = 2.0 * std::f64::consts::LN_2;
        let k1 = self.k1;
        let k0 = (c[0] * (2.0 * (ln4 + self.ln_h1 - ln_alpha) - 1.0)
            + c[1] * (2.0 * (ln4 + ln_h2 - ln_alpha) - 1.0))
            / self.pi_length;
        let (mut a_min, mut ln_a_min) = (self.pin_radius, self.ln_h1);
        if h2 < a_min {
            (a_min, ln_a_min) = (h2, ln_h2);
        }
        if radius < a_min {
            (a_min, ln_a_min) = (radius, ln_r);
        }
        let a_lim = 0.5 * a_min;
        let f_lim = (a_lim / alpha).powi(2);
        let x_lim = 2.0 * (ln_a_min - std::f64::consts::LN_2 - ln_alpha);
        LineContactLaw::from_coefficients(
            length,
            radius,
            e_star,
            [self.pin_radius, h2],
            c,
            [k0, k1, alpha],
            f_lim,
            x_lim,
        )
    }
}

/// The `Geometry` error of a non-positive (or non-finite) curvature sum.
fn curvature_sum_error(curvature1: f64, curvature2: f64) -> RvdynError {
    let sum = curvature1 + curvature2;
    RvdynError::Geometry(format!(
        "curvatures {curvature1} 1/m and {curvature2} 1/m add up to {sum} 1/m <= 0: the \
         surfaces are concave-concave, conformal or nested and do not make a Hertz line \
         contact; a concave surface must be flatter than the convex one it holds"
    ))
}

/// Half-width `w` of the blend of the disc's reference depth, in `ln(kappa D)`: the two
/// branches are blended for `kappa D` in `[e^-w, e^w] = [0.8, 1.25]`.
pub const DEPTH_BLEND_HALF_WIDTH: f64 = 0.223_143_551_314_209_76; // ln 1.25

/// `e^-w` of [`DEPTH_BLEND_HALF_WIDTH`]: the lower end 0.8 of the blend in `kappa D`.
const DEPTH_BLEND_LOWER: f64 = 0.8;

/// The disc's reference depth at a contact and its derivatives along the curvature.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DepthJet {
    /// Reference depth `h` \[m\].
    pub depth: f64,
    /// `d ln h / d kappa` \[m\].
    pub dln_dkappa: f64,
    /// `d^2 ln h / d kappa^2` [m^2].
    pub d2ln_dkappa2: f64,
}

/// Reference depth `h` of the disc side of a pin contact, for the signed profile curvature
/// `kappa` [1/m] and the body depth `body_depth` `D` \[m\] (docs/model.md, "Pin against cycloid
/// disc"): `h = D` where `kappa D <= 0.8` (concave, flat or gently convex: the seat is backed
/// by the body), `h = 1/kappa` where `kappa D >= 1.25` (the cylinder of the actual radius), and
/// between them `ln h = ln D - r(ln(kappa D))` with the C2 ramp
/// `r(x) = w [(1 + t)/2 + (15/16)(t^2/2 - t^4/6 + t^6/30 - 11/30)]`, `t = x/w`, whose second
/// derivative is the quartic kernel `(15/(16 w))(1 - t^2)^2`. A plain `min(1/kappa, D)` has a
/// kink at `kappa D = 1`, which makes the location force of the law jump where a loaded contact
/// crosses it (no static equilibrium exists there); the ramp keeps that force and its tangent
/// continuous. Returns `h` and `d ln h/d kappa`, `d^2 ln h/d kappa^2`.
///
/// ```
/// use rvdyn::contact::line_contact::disc_reference_depth;
/// let d = 0.14;
/// assert_eq!(disc_reference_depth(-5.0, d).depth, d); // concave: backed by the body
/// let convex = disc_reference_depth(1.0 / 0.094, d); // kappa D = 1.49
/// assert!((convex.depth - 0.094).abs() < 1e-15);
/// ```
pub fn disc_reference_depth(kappa: f64, body_depth: f64) -> DepthJet {
    disc_reference_depth_ratio(kappa, body_depth).0
}

/// [`disc_reference_depth`] and the ramp `r = ln(D / h)` (0 where `h = D`), so that `ln h` is
/// `ln D - r` without another logarithm.
#[inline]
pub(crate) fn disc_reference_depth_ratio(kappa: f64, body_depth: f64) -> (DepthJet, f64) {
    let w = DEPTH_BLEND_HALF_WIDTH;
    let u = kappa * body_depth;
    // e^-w = 0.8 (the same double as `(-w).exp()`, tested), without an exp per call.
    if u.is_nan() || u <= DEPTH_BLEND_LOWER {
        return (
            DepthJet {
                depth: body_depth,
                dln_dkappa: 0.0,
                d2ln_dkappa2: 0.0,
            },
            0.0,
        );
    }
    let x = u.ln();
    let (r, r1, r2) = if x >= w {
        (x, 1.0, 0.0)
    } else {
        let t = x / w;
        let t2 = t * t;
        let r = w
            * (0.5 * (1.0 + t)
                + (15.0 / 16.0) * (0.5 * t2 - t2 * t2 / 6.0 + t2 * t2 * t2 / 30.0 - 11.0 / 30.0));
        let r1 = 0.5 + (15.0 / 16.0) * (t - 2.0 * t2 * t / 3.0 + t2 * t2 * t / 5.0);
        let r2 = (15.0 / (16.0 * w)) * (1.0 - t2) * (1.0 - t2);
        (r, r1, r2)
    };
    // x = ln(kappa D): dx/dkappa = 1/kappa, d2x/dkappa2 = -1/kappa^2.
    (
        DepthJet {
            depth: body_depth * (-r).exp(),
            dln_dkappa: -r1 / kappa,
            d2ln_dkappa2: (r1 - r2) / (kappa * kappa),
        },
        r,
    )
}

/// Signed curvature [1/m] of the actual cycloid profile from the signed curvature
/// `centre_curvature` [1/m] of the pin-centre curve and the generating pin radius `r` \[m\]:
/// `kappa_P = kappa_C / (1 - r kappa_C)` (the profile is the inner offset of the centre curve
/// by `r`; positive convex).
///
/// Finite through the profile's inflection (where `kappa_C = 0`), unlike the radius
/// `1/kappa_C - r`. Errors (`Geometry`) if `1 - r kappa_C <= 0` (undercut: the offset curve has
/// a cusp) or an input is not finite.
pub fn pin_disc_profile_curvature(
    centre_curvature: f64,
    generating_pin_radius: f64,
) -> Result<f64> {
    require_non_negative("generating pin radius", generating_pin_radius, "m")?;
    profile_curvature_checked(centre_curvature, generating_pin_radius)
}

/// [`pin_disc_profile_curvature`] for a generating pin radius checked once by the caller
/// (finite, >= 0): the same value and the same `Geometry` error.
#[inline]
pub(crate) fn profile_curvature_checked(
    centre_curvature: f64,
    generating_pin_radius: f64,
) -> Result<f64> {
    let denom = 1.0 - generating_pin_radius * centre_curvature;
    if !(centre_curvature.is_finite() && denom > 0.0) {
        return Err(RvdynError::Geometry(format!(
            "profile curvature undefined: 1 - r kappa_C = {denom} (kappa_C = {centre_curvature} \
             1/m, r = {generating_pin_radius} m); the profile is undercut there"
        )));
    }
    Ok(centre_curvature / denom)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::hertz::{hertz_line_contact, palmgren_approach};
    use crate::geometry::CycloidGeometry;
    use crate::geometry::cycloid::CycloidParams;
    use crate::test_util::close;

    const STEEL: Material = Material {
        youngs_modulus: 2.17e11,
        poisson_ratio: 0.3,
    };

    /// The profile curvature of the paper disc at the pin of classical peak load
    /// (`cos phi = K1`): there `rho_C = rp sqrt(1 - K1^2)` (from the curvature formula with
    /// `S^2 = 1 - K1^2`), so `rho_P = 150 sqrt(1 - 0.72^2) - 10 = 94.096 mm`.
    fn peak_pin_profile_curvature() -> f64 {
        let g = CycloidGeometry::new(CycloidParams::paper()).unwrap();
        // Curve parameter phi with cos(zc phi) = K1: mesh angle arccos K1 over zc.
        let phi = g.k1().acos() / f64::from(g.lobes());
        let kc = g.centre_curve_curvature(phi);
        pin_disc_profile_curvature(kc, g.generating_pin_radius()).unwrap()
    }

    #[test]
    fn profile_radius_at_the_peak_pin_is_94_mm() {
        let k = peak_pin_profile_curvature();
        let expected = 0.150 * (1.0f64 - 0.72 * 0.72).sqrt() - 0.010;
        assert!(close(1.0 / k, expected, 1e-9), "{} vs {expected}", 1.0 / k);
        assert!(close(1.0 / k, 0.094_096, 1e-5));
    }

    #[test]
    fn rated_pin_contact_figures_at_35_kn() {
        // Pin 10 mm, profile radius 94.1 mm at the classical peak-load pin, face width 40 mm
        // (CycloidParams::paper), two steels E = 2.17e11 Pa, nu = 0.3, F = 35 kN:
        // Johnson 25.9 um, Palmgren 24.7 um.
        let law = LineContactLaw::pin_disc(
            0.010,
            peak_pin_profile_curvature(),
            0.140,
            CycloidParams::paper().face_width,
            &STEEL,
            &STEEL,
        )
        .unwrap();
        let d = law.approach(35e3).unwrap();
        assert!((d - 25.9e-6).abs() < 0.05e-6, "{d}");
        let p = palmgren_approach(35e3, 0.040).unwrap();
        assert!((p - 24.7e-6).abs() < 0.05e-6, "{p}");
        // Half width and peak pressure: R = 1/(100 + 10.627) = 9.0394 mm,
        // a = sqrt(4 * 875e3 * 9.0394e-3 / (pi * 1.19231e11)) = 0.29062 mm,
        // p0 = 2 * 875e3 / (pi * 2.9062e-4) = 1.9167 GPa.
        let a = law.half_width(35e3).unwrap();
        assert!(close(a, 2.9062e-4, 2e-4), "{a}");
        let p0 = law.peak_pressure(35e3).unwrap();
        assert!(close(p0, 2.0 * 35e3 / (PI * 0.040 * a), 1e-12));
        assert!(close(p0, 1.9167e9, 2e-4), "{p0}");
    }

    #[test]
    fn inverse_matches_closed_form_at_five_loads() {
        // Convex (pin on the flank), concave (pin in the root) and near-flat profiles.
        for kappa2 in [1.0 / 0.094, -1.0 / 0.0107, 1e-3, 0.0] {
            let law =
                LineContactLaw::pin_disc(0.010, kappa2, 0.140, 0.040, &STEEL, &STEEL).unwrap();
            for f in [1.0, 100.0, 5e3, 35e3, 2e5] {
                let d = law.approach(f).unwrap();
                let d2 = law.approach_johnson_sum(f).unwrap();
                assert!(close(d, d2, 1e-12), "{d} {d2}");
                let back = law.force(d);
                assert!(close(back, f, 1e-9), "kappa {kappa2}: {f} -> {d} -> {back}");
            }
        }
    }

    #[test]
    fn agrees_with_the_independent_hertz_module_for_convex_cylinders() {
        // hertz::hertz_line_contact implements the same Johnson sum with the radii as depths.
        for (f, r2) in [(1e3, 0.05), (35e3, 0.094), (8e4, 0.3)] {
            let law =
                LineContactLaw::new(0.04, 100.0, 1.0 / r2, 0.010, r2, &STEEL, &STEEL).unwrap();
            let c = hertz_line_contact(f, 0.04, 0.010, r2, &STEEL, &STEEL).unwrap();
            assert!(close(law.approach(f).unwrap(), c.approach, 1e-12));
            assert!(close(law.half_width(f).unwrap(), c.half_width, 1e-12));
            assert!(close(law.peak_pressure(f).unwrap(), c.peak_pressure, 1e-12));
        }
    }

    #[test]
    fn concave_uses_the_difference_of_curvatures() {
        // Pin 10 mm in a concave 12 mm seat: R = 1/(1/10 - 1/12) mm = 60 mm.
        let law =
            LineContactLaw::pin_disc(0.010, -1.0 / 0.012, 0.14, 0.04, &STEEL, &STEEL).unwrap();
        assert!(close(law.effective_radius(), 0.060, 1e-12));
        // A concave seat is backed by the disc body: the depth is the body dimension.
        assert_eq!(law.depths(), [0.010, 0.14]);
        // Convex with a radius beyond the body dimension: capped too.
        let big = LineContactLaw::pin_disc(0.010, 1.0 / 0.5, 0.14, 0.04, &STEEL, &STEEL).unwrap();
        assert_eq!(big.depths(), [0.010, 0.14]);
        // A conformal or nested contact is a geometry error.
        let e = LineContactLaw::pin_disc(0.010, -1.0 / 0.010, 0.14, 0.04, &STEEL, &STEEL);
        assert!(matches!(e, Err(RvdynError::Geometry(_))));
        assert!(LineContactLaw::pin_disc(0.010, -200.0, 0.14, 0.04, &STEEL, &STEEL).is_err());
        // Flat profile: depth capped at the body depth.
        let flat = LineContactLaw::pin_disc(0.010, 0.0, 0.14, 0.04, &STEEL, &STEEL).unwrap();
        assert_eq!(flat.depths(), [0.010, 0.14]);
        assert!(close(flat.effective_radius(), 0.010, 1e-12));
    }

    #[test]
    fn continuous_force_and_stiffness_from_zero() {
        let law = LineContactLaw::pin_disc(0.010, 10.6, 0.14, 0.04, &STEEL, &STEEL).unwrap();
        assert_eq!(law.force_and_stiffness(0.0), (0.0, 0.0));
        assert_eq!(law.force_and_stiffness(-1e-6), (0.0, 0.0));
        assert_eq!(law.force_and_stiffness(f64::NAN), (0.0, 0.0));
        // Stiffness falls towards 0 as delta -> 0 (logarithmically), never NaN.
        let mut last = f64::INFINITY;
        for d in [1e-6, 1e-9, 1e-12, 1e-15, 1e-20, 1e-300] {
            let (f, k) = law.force_and_stiffness(d);
            assert!(
                f > 0.0 && f.is_finite() && k > 0.0 && k < last,
                "{d}: {f} {k}"
            );
            last = k;
        }
        assert!(law.force_and_stiffness(1e-300).1 < 0.05 * law.force_and_stiffness(1e-6).1);
        // Tangent stiffness equals the finite-difference slope.
        for d in [1e-7, 5e-6, 2.6e-5, 1e-4] {
            let h = d * 1e-6;
            let fd = (law.force(d + h) - law.force(d - h)) / (2.0 * h);
            let k = law.force_and_stiffness(d).1;
            assert!(close(k, fd, 1e-6), "{d}: {k} vs {fd}");
        }
    }

    #[test]
    fn warm_start_gives_the_same_force() {
        let law = LineContactLaw::pin_disc(0.010, 10.6, 0.14, 0.04, &STEEL, &STEEL).unwrap();
        for d in [1e-9, 3e-6, 2.6e-5] {
            let cold = law.force_and_stiffness(d);
            for guess in [f64::NAN, -50.0, 0.0, 10.0, 1e3, f64::NEG_INFINITY] {
                let (f, k, x) = law.force_and_stiffness_from(d, guess);
                assert!(
                    close(f, cold.0, 1e-13) && close(k, cold.1, 1e-12),
                    "{d} {guess}"
                );
                assert!(close(x, f.ln(), 1e-15));
            }
        }
    }

    #[test]
    fn linear_extension_is_c1() {
        let law = LineContactLaw::pin_disc(0.010, 10.6, 0.14, 0.04, &STEEL, &STEEL).unwrap();
        let f_lim = law.validity_limit();
        // a = R/2 = 4.5 mm at the limit; far beyond the rated 35 kN.
        assert!(f_lim > 200.0 * 35e3, "{f_lim}");
        assert!(close(
            law.half_width(f_lim).unwrap(),
            0.5 * law.effective_radius(),
            1e-12
        ));
        let d_lim = law.approach(f_lim).unwrap();
        let (f_lo, k_lo) = law.force_and_stiffness(d_lim * (1.0 - 1e-12));
        let (f_hi, k_hi) = law.force_and_stiffness(d_lim * (1.0 + 1e-12));
        assert!(close(f_lo, f_hi, 1e-9) && close(k_lo, k_hi, 1e-6));
        let d2 = 2.0 * d_lim;
        assert!(close(law.force(d2), f_lim + d_lim * k_hi, 1e-12));
        assert!(close(law.approach(law.force(d2)).unwrap(), d2, 1e-12));
    }

    #[test]
    fn elastic_energy_is_the_integral_of_the_force() {
        let law = LineContactLaw::pin_disc(0.010, 10.6, 0.14, 0.04, &STEEL, &STEEL).unwrap();
        let d_end = 3e-5;
        let n = 20_000;
        let h = d_end / n as f64;
        // Simpson's rule.
        let mut s = law.force(0.0) + law.force(d_end);
        for i in 1..n {
            let w = if i % 2 == 1 { 4.0 } else { 2.0 };
            s += w * law.force(i as f64 * h);
        }
        let u = s * h / 3.0;
        assert!(close(law.elastic_energy(d_end), u, 1e-6), "{u}");
        assert_eq!(law.elastic_energy(0.0), 0.0);
        // Beyond the limit, dU/d delta = F.
        let d = 3.0 * law.approach(law.validity_limit()).unwrap();
        let e = 1e-6 * d;
        let fd = (law.elastic_energy(d + e) - law.elastic_energy(d - e)) / (2.0 * e);
        assert!(close(fd, law.force(d), 1e-6));
    }

    #[test]
    fn invalid_inputs() {
        assert!(LineContactLaw::new(0.0, 100.0, 10.0, 0.01, 0.1, &STEEL, &STEEL).is_err());
        assert!(LineContactLaw::new(0.04, f64::NAN, 10.0, 0.01, 0.1, &STEEL, &STEEL).is_err());
        assert!(LineContactLaw::new(0.04, 100.0, 10.0, -0.01, 0.1, &STEEL, &STEEL).is_err());
        assert!(LineContactLaw::new(0.04, 100.0, 10.0, 0.01, 0.0, &STEEL, &STEEL).is_err());
        let bad = Material {
            youngs_modulus: 2e11,
            poisson_ratio: 0.6,
        };
        assert!(LineContactLaw::new(0.04, 100.0, 10.0, 0.01, 0.1, &bad, &STEEL).is_err());
        let law = LineContactLaw::new(0.04, 100.0, 10.0, 0.01, 0.1, &STEEL, &STEEL).unwrap();
        assert!(law.approach(-1.0).is_err());
        assert!(law.approach(f64::NAN).is_err());
        assert!(law.half_width(-1.0).is_err());
        assert!(law.peak_pressure(f64::INFINITY).is_err());
        assert!(pin_disc_profile_curvature(200.0, 0.01).is_err());
        assert!(pin_disc_profile_curvature(f64::NAN, 0.01).is_err());
        assert!(close(
            pin_disc_profile_curvature(50.0, 0.01).unwrap(),
            100.0,
            1e-12
        ));
    }

    #[test]
    fn disc_depth_blend_is_twice_differentiable_and_exact_outside() {
        let d = 0.14;
        let w = DEPTH_BLEND_HALF_WIDTH;
        // Outside the blend: the two branches exactly.
        assert_eq!((-DEPTH_BLEND_HALF_WIDTH).exp(), DEPTH_BLEND_LOWER);
        assert_eq!(DEPTH_BLEND_HALF_WIDTH.exp(), 1.25);
        assert_eq!(disc_reference_depth(0.0, d).depth, d);
        assert_eq!(disc_reference_depth(0.79 / d, d).depth, d);
        let k = 1.26 / d;
        assert!(close(disc_reference_depth(k, d).depth, 1.0 / k, 1e-15));
        // Inside: between the two branches, and the derivatives equal central differences
        // (step 1e-5 of kappa; tolerance 1e-6 relative, the truncation error of the difference).
        let mut prev = d;
        for i in 0..=200 {
            let u = (-w).exp() + ((w).exp() - (-w).exp()) * i as f64 / 200.0;
            let k = u / d;
            let j = disc_reference_depth(k, d);
            assert!(
                j.depth <= d && j.depth >= (1.0 / k).min(d) * 0.96,
                "u {u}: {}",
                j.depth
            );
            assert!(j.depth <= prev + 1e-18, "monotone");
            prev = j.depth;
            let h = 1e-5 * k;
            let (a, b) = (
                disc_reference_depth(k + h, d),
                disc_reference_depth(k - h, d),
            );
            let d1 = (a.depth.ln() - b.depth.ln()) / (2.0 * h);
            let d2 = (a.dln_dkappa - b.dln_dkappa) / (2.0 * h);
            let scale = 1.0 / k;
            assert!(
                (d1 - j.dln_dkappa).abs() < 1e-6 * scale,
                "u {u}: {d1} vs {}",
                j.dln_dkappa
            );
            assert!(
                (d2 - j.d2ln_dkappa2).abs() < 1e-6 * scale * scale,
                "u {u}: {d2} vs {}",
                j.d2ln_dkappa2
            );
        }
        // Value, slope and curvature continuous at both ends of the blend.
        for u in [(-w).exp(), w.exp()] {
            let (lo, hi) = (
                disc_reference_depth((u - 1e-12) / d, d),
                disc_reference_depth((u + 1e-12) / d, d),
            );
            assert!(close(lo.depth, hi.depth, 1e-10));
            assert!((lo.dln_dkappa - hi.dln_dkappa).abs() < 1e-9 * d);
            assert!((lo.d2ln_dkappa2 - hi.d2ln_dkappa2).abs() < 1e-8 * d * d);
        }
    }

    /// The law built from its contact-independent part with one logarithm equals the law of
    /// the full constructor (three logarithms) to round-off: every coefficient, and force,
    /// stiffness and `ln F` over the whole range of approaches (including the linear extension
    /// and from warm and cold starts of the inversion), for convex, concave, blended and
    /// body-backed contacts and a pin radius that caps the validity limit. Round-off of the
    /// coefficients: a few ulps of the logarithms (about 20 in size), so 1e-14 relative.
    #[test]
    fn law_from_its_base_equals_the_full_constructor() {
        let (pin, disc) = (STEEL, Material::steel());
        let body = 0.14;
        for &(rp, kappa) in &[
            (0.010, 1.0 / 0.094),
            (0.010, -1.0 / 0.2),
            (0.010, 0.9 / body),
            (0.010, 0.0),
            (0.004, 1.0 / 0.001),
            (0.012, 7.0),
        ] {
            let full = LineContactLaw::pin_disc(rp, kappa, body, 0.03, &pin, &disc).unwrap();
            let (dj, ratio) = disc_reference_depth_ratio(kappa, body);
            assert!(close(dj.depth, body * (-ratio).exp(), 1e-15));
            let base = PinDiscLawBase::new(rp, 0.03, &pin, &disc);
            let fast = base.law(kappa, dj.depth, body.ln() - ratio).unwrap();
            assert_eq!(fast.depths, full.depths);
            for (a, b) in [
                (fast.k0, full.k0),
                (fast.k1, full.k1),
                (fast.alpha, full.alpha),
                (fast.f_lim, full.f_lim),
                (fast.x_lim, full.x_lim),
                (fast.delta_lim, full.delta_lim),
                (fast.compliance_lim, full.compliance_lim),
                (fast.radius, full.radius),
                (fast.e_star, full.e_star),
            ] {
                assert!(close(a, b, 1e-14), "{rp} {kappa}: {a} vs {b}");
            }
            for frac in [1e-9, 1e-4, 0.01, 0.3, 0.999, 1.5, 10.0] {
                let d = frac * full.delta_lim;
                for guess in [f64::NAN, (0.5 * frac * full.f_lim).ln()] {
                    let a = fast.force_and_stiffness_from(d, guess);
                    let b = full.force_and_stiffness_from(d, f64::NAN);
                    assert!(close(a.0, b.0, 1e-13), "{frac}: {} vs {}", a.0, b.0);
                    assert!(close(a.1, b.1, 1e-13), "{frac}: {} vs {}", a.1, b.1);
                    // The force is the inverse of the closed-form approach.
                    assert!(close(full.approach(a.0).unwrap(), d, 1e-13));
                }
            }
        }
        // A concave profile as curved as the pin: no Hertz contact, the same error.
        let base = PinDiscLawBase::new(0.01, 0.03, &pin, &disc);
        let e = base.law(-100.0, body, body.ln()).unwrap_err();
        assert!(matches!(e, RvdynError::Geometry(_)), "{e}");
    }
}
