//! The finite-difference Jacobian of a mechanical system, shared by the implicit integrator
//! (its Newton matrix) and the stability check of the explicit one (its eigenvalues).
//!
//! Each free coordinate `k` is perturbed by about 1 nm of displacement and about 1 um/s of
//! velocity at its lever (`MechanicalSystem::length_scale`), one-sided; the caller receives the
//! raw differences of the accelerations and the perturbation sizes, so that it combines them
//! in its own arithmetic order (the generalized-alpha matrix is assembled bit for bit as it
//! always was).

use crate::error::Result;
use crate::solve::{MechanicalSystem, State};

/// Displacement perturbation at the lever \[m\].
pub const DISPLACEMENT_STEP: f64 = 1e-9;
/// Velocity perturbation at the lever [m/s].
pub const VELOCITY_STEP: f64 = 1e-6;

/// One column of the finite-difference Jacobian: coordinate `k` perturbed.
pub struct Column<'a> {
    /// Index of the perturbed coordinate.
    pub k: usize,
    /// The unperturbed accelerations `f(t, q, v)`.
    pub f0: &'a [f64],
    /// Accelerations with `q[k] += dq`.
    pub f_dq: &'a [f64],
    /// Displacement perturbation of coordinate `k` (its own unit).
    pub dq: f64,
    /// Accelerations with `v[k] += dv`.
    pub f_dv: &'a [f64],
    /// Velocity perturbation of coordinate `k` (its own unit per second).
    pub dv: f64,
}

/// Evaluate `sys` at `st` and at `2 n` one-sided perturbations (`1 + 2 n` force evaluations,
/// the count returned), handing each column to `column`.
pub fn finite_difference<S: MechanicalSystem + ?Sized>(
    sys: &S,
    st: &State,
    mut column: impl FnMut(Column<'_>),
) -> Result<u64> {
    let n = st.q.len();
    let scale = sys.length_scale();
    let mut f0 = vec![0.0; n];
    let mut f_dq = vec![0.0; n];
    let mut f_dv = vec![0.0; n];
    let mut p = [0.0; 3];
    sys.eval(st.t, &st.q, &st.v, &mut f0, &mut p)?;
    let mut q = st.q.clone();
    let mut v = st.v.clone();
    for k in 0..n {
        let dq = DISPLACEMENT_STEP / scale[k].max(1e-12);
        q[k] += dq;
        sys.eval(st.t, &q, &v, &mut f_dq, &mut p)?;
        q[k] = st.q[k];
        let dv = VELOCITY_STEP / scale[k].max(1e-12);
        v[k] += dv;
        sys.eval(st.t, &q, &v, &mut f_dv, &mut p)?;
        v[k] = st.v[k];
        column(Column {
            k,
            f0: &f0,
            f_dq: &f_dq,
            dq,
            f_dv: &f_dv,
            dv,
        });
    }
    Ok(1 + 2 * n as u64)
}
