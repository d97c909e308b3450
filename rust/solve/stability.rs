//! Linearised stability of the explicit fixed-step method (RK4) at a state: an explicit method
//! beyond its stability limit can return smooth-looking but wrong results (a mode flipping
//! sign every step), so the driver checks the limit from time to time and stops with advice.
//!
//! Theory: docs/model.md, section "RK4 and its stability check".

use crate::error::Result;
use crate::solve::{MechanicalSystem, State, jacobian};
use nalgebra::{Complex, DMatrix};

/// Eigenvalues [1/s] of the linearised first-order system `d(q, v)/dt = (v, a(q, v))` at `st`,
/// from a finite-difference Jacobian (2 n force evaluations).
pub fn linearised_eigenvalues<S: MechanicalSystem + ?Sized>(
    sys: &S,
    st: &State,
) -> Result<Vec<Complex<f64>>> {
    let n = st.q.len();
    let mut m = DMatrix::<f64>::zeros(2 * n, 2 * n);
    for i in 0..n {
        m[(i, n + i)] = 1.0;
    }
    jacobian::finite_difference(sys, st, |c| {
        for i in 0..n {
            m[(n + i, c.k)] = (c.f_dq[i] - c.f0[i]) / c.dq;
            m[(n + i, n + c.k)] = (c.f_dv[i] - c.f0[i]) / c.dv;
        }
    })?;
    Ok(m.complex_eigenvalues().iter().copied().collect())
}

/// RK4's amplification factor `R(z) = 1 + z + z^2/2 + z^3/6 + z^4/24`.
pub fn rk4_amplification(z: Complex<f64>) -> f64 {
    let one = Complex::new(1.0, 0.0);
    (one + z * (one + z * (one / 2.0 + z * (one / 6.0 + z / 24.0)))).norm()
}

/// How much RK4 with step `h` \[s\] amplifies a mode beyond its exact growth, worst over the
/// eigenvalues `eigs` [1/s] (a ratio [-]; > 1: numerically unstable).
pub fn rk4_excess_growth(eigs: &[Complex<f64>], h: f64) -> f64 {
    eigs.iter()
        .map(|l| {
            let z = *l * h;
            rk4_amplification(z) / z.exp().norm().max(1.0)
        })
        .fold(0.0, f64::max)
}

/// The largest step \[s\] at which RK4 does not amplify any of the eigenvalues `eigs` [1/s]
/// beyond its exact growth (bisection below the step `h` \[s\]).
pub fn rk4_step_limit(eigs: &[Complex<f64>], h: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, h);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if rk4_excess_growth(eigs, mid) <= 1.0 + 1e-9 {
            lo = mid
        } else {
            hi = mid
        }
    }
    lo
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rk4_real_axis_limit_is_2_785() {
        // Classical result: RK4 is stable on the negative real axis down to z = -2.7853.
        let eig = [Complex::new(-1.0, 0.0)];
        assert!((rk4_step_limit(&eig, 10.0) - 2.7853).abs() < 1e-3);
        // And on the imaginary axis up to 2 sqrt(2).
        let eig = [Complex::new(0.0, 1.0)];
        assert!((rk4_step_limit(&eig, 10.0) - 2.0 * 2f64.sqrt()).abs() < 1e-3);
    }
}
