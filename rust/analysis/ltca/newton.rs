//! Damped Newton on the static equilibrium `Q(q) = 0` with the exact tangent `K = -dQ/dq`.
//!
//! Each iteration solves `(K + mu D) dq = Q` (Levenberg-Marquardt: `mu = 0`, plain Newton,
//! whenever that step is acceptable; `D = diag(k_ref L_a^2)` with `L_a` the length of unknown
//! `a` and `k_ref` a reference contact stiffness) and backtracks along `dq` until the scaled
//! residual norm decreases (Armijo condition; Nocedal and Wright, *Numerical Optimization*,
//! 2nd ed., 2006, sections 3.1 and 10.3). `mu` is raised tenfold when no step along the
//! direction decreases the residual (or `K` is singular, as at first touch of a Hertz law,
//! whose stiffness is zero at zero penetration) and lowered tenfold after each accepted step.
//! Contacts that open or close need no active set: a contact law is zero (with zero
//! derivative) for a positive gap.

#![allow(clippy::needless_range_loop)]

use crate::analysis::ltca::statics::{ContactState, Dense, Statics, Work};
use crate::error::{Result, RvdynError};

thread_local! {
    /// Scratch of [`cholesky_solve`] per thread (the factor, inverse pivots and the
    /// intermediate solution), sized on first use: no allocation and no clearing per solve.
    static CHOLESKY_SCRATCH: std::cell::RefCell<Vec<f64>> = const {
        std::cell::RefCell::new(Vec::new())
    };
}

/// Solve `a x = b` in place (`b` becomes `x`); `a` may be destroyed. Returns false if the
/// matrix is numerically singular: a pivot of Gaussian elimination with partial pivoting below
/// `1e-14` times the largest entry.
///
/// A matrix symmetric to round-off (every `|a_ij - a_ji|` below `1e-13` of the largest entry:
/// the LTCA tangent of a frictionless scene, which is a Hessian of the potential, assembled
/// symmetric up to the rounding of its outer products) that is positive definite with every
/// pivot `d_j` of `L D L^T` above `1e-14` times the largest entry is solved by Cholesky, half
/// the operations of LU (G. H. Golub, C. F. Van Loan, *Matrix Computations*, 4th ed., Johns
/// Hopkins 2013, section 4.2; no pivoting is needed for a positive definite matrix). Any other
/// matrix (unsymmetric, as with friction; indefinite, as far from equilibrium; or nearly
/// singular) takes Gaussian elimination with partial pivoting (section 3.4), whose pivot test
/// decides singularity as before. Both agree to round-off where both apply (tested).
pub fn solve_dense(a: &mut Dense, b: &mut [f64]) -> bool {
    let n = a.n;
    let m = &mut a.a[..n * n];
    let b = &mut b[..n];
    // The largest entry; the sum of all is finite only if every entry is (NaN and infinities
    // propagate into it; entries near overflow would be singular to working accuracy anyway).
    let (mut amax, mut sum) = (0.0f64, 0.0f64);
    for v in m.iter() {
        let a = v.abs();
        if a > amax {
            amax = a;
        }
        sum += v;
    }
    if amax == 0.0 || !amax.is_finite() || !sum.is_finite() {
        return false;
    }
    if symmetric(m, n, 1e-13 * amax)
        && let Some(ok) = cholesky_solve(m, n, b, 1e-14 * amax)
    {
        return ok;
    }
    lu_solve(m, n, b, amax)
}

/// Whether `|m_ij - m_ji| <= tol` for every pair.
fn symmetric(m: &[f64], n: usize, tol: f64) -> bool {
    for i in 0..n {
        let row = &m[i * n..i * n + n];
        for (j, v) in row.iter().enumerate().skip(i + 1) {
            if (v - m[j * n + i]).abs() > tol {
                return false;
            }
        }
    }
    true
}

/// Cholesky `m = L L^T` from the lower triangle of `m` (row by row, in a per-thread scratch;
/// `m` is not changed) and the two triangular solves, `b` overwritten only on success. `None`
/// if a pivot `d_j = L_jj^2` is not above `tiny` (not positive definite to working accuracy):
/// the caller then eliminates with pivoting.
fn cholesky_solve(m: &[f64], n: usize, b: &mut [f64], tiny: f64) -> Option<bool> {
    // The LTCA's sizes, with the loop bounds known to the compiler (no bounds checks).
    macro_rules! fixed {
        ($($n:literal)*) => {
            match n {
                $($n => return cholesky_fixed::<$n>(m, b, tiny),)*
                _ => {}
            }
        };
    }
    fixed!(4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20);
    CHOLESKY_SCRATCH.with_borrow_mut(|scratch| {
        if scratch.len() < n * n + 2 * n {
            scratch.resize(n * n + 2 * n, 0.0);
        }
        let (l, rest) = scratch.split_at_mut(n * n);
        let (inv_diag, y) = rest.split_at_mut(n);
        cholesky_in(m, n, b, tiny, None, l, inv_diag, &mut y[..n])
    })
}

/// Solve `m x = b` for a symmetric `m` by a modified Cholesky factorization (Gill, Murray and
/// Wright, Practical Optimization, 1981, section 4.4.2.2): a pivot `d_j` not above `tiny` is
/// replaced by `max(|d_j|, floor[j])`, which adds to `m` a diagonal perturbation only in the
/// directions that are singular (or indefinite) to working accuracy, so the step stays the
/// Newton step in every other direction and is a descent direction. False for an
/// unsymmetric or non-finite `m` (or a non-finite result).
fn modified_cholesky_solve(m: &[f64], n: usize, b: &mut [f64], floor: &[f64]) -> bool {
    let m = &m[..n * n];
    let b = &mut b[..n];
    let amax = m.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    if amax == 0.0 || !amax.is_finite() || !symmetric(m, n, 1e-13 * amax) {
        return false;
    }
    CHOLESKY_SCRATCH.with_borrow_mut(|scratch| {
        if scratch.len() < n * n + 2 * n {
            scratch.resize(n * n + 2 * n, 0.0);
        }
        let (l, rest) = scratch.split_at_mut(n * n);
        let (inv_diag, y) = rest.split_at_mut(n);
        cholesky_in(m, n, b, 1e-14 * amax, Some(floor), l, inv_diag, &mut y[..n]).unwrap_or(false)
    })
}

/// [`cholesky_solve`] for `N x N` on the stack: the same operations in the same order as
/// [`cholesky_in`] (the same results bit for bit).
fn cholesky_fixed<const N: usize>(m: &[f64], b: &mut [f64], tiny: f64) -> Option<bool> {
    let m = m.get(..N * N)?;
    let b: &mut [f64; N] = b.get_mut(..N)?.try_into().ok()?;
    let mut l = [[0.0f64; N]; N];
    let mut inv_diag = [0.0f64; N];
    let sub = |s: f64, a: &[f64], b: &[f64]| a.iter().zip(b).fold(s, |s, (x, y)| s - x * y);
    for j in 0..N {
        for k in 0..j {
            let s = sub(m[j * N + k], &l[j][..k], &l[k][..k]);
            l[j][k] = s * inv_diag[k];
        }
        let d = sub(m[j * N + j], &l[j][..j], &l[j][..j]);
        if d.is_nan() || d <= tiny {
            return None;
        }
        let r = d.sqrt();
        l[j][j] = r;
        inv_diag[j] = 1.0 / r;
    }
    let mut y = [0.0f64; N];
    for j in 0..N {
        y[j] = sub(b[j], &l[j][..j], &y[..j]) * inv_diag[j];
    }
    for j in (0..N).rev() {
        let xj = y[j] * inv_diag[j];
        y[j] = xj;
        for (v, x) in y[..j].iter_mut().zip(&l[j][..j]) {
            *v -= x * xj;
        }
    }
    *b = y;
    Some(b.iter().all(|v| v.is_finite()))
}

/// [`cholesky_solve`] with its scratch: `l` (`n * n`), `inv_diag` and `y` (`n` each); with
/// `floor`, the modified factorization of [`modified_cholesky_solve`].
#[allow(clippy::too_many_arguments)]
fn cholesky_in(
    m: &[f64],
    n: usize,
    b: &mut [f64],
    tiny: f64,
    floor: Option<&[f64]>,
    l: &mut [f64],
    inv_diag: &mut [f64],
    y: &mut [f64],
) -> Option<bool> {
    for j in 0..n {
        let (done, rest) = l.split_at_mut(j * n);
        let lj = &mut rest[..n];
        let aj = &m[j * n..j * n + n];
        for k in 0..j {
            let s = dot_from(aj[k], &lj[..k], &done[k * n..k * n + k]);
            lj[k] = s * inv_diag[k];
        }
        let mut d = dot_from(aj[j], &lj[..j], &lj[..j]);
        if d.is_nan() {
            return None;
        }
        if d <= tiny {
            d = d.abs().max(floor?[j]);
        }
        let r = d.sqrt();
        lj[j] = r;
        inv_diag[j] = 1.0 / r;
    }
    // L y = b, then L^T x = y (by columns of L^T, i.e. rows of L).
    for j in 0..n {
        let s = dot_from(b[j], &l[j * n..j * n + j], &y[..j]);
        y[j] = s * inv_diag[j];
    }
    for j in (0..n).rev() {
        let xj = y[j] * inv_diag[j];
        y[j] = xj;
        for (v, x) in y[..j].iter_mut().zip(&l[j * n..j * n + j]) {
            *v -= x * xj;
        }
    }
    b.copy_from_slice(y);
    Some(b.iter().all(|v| v.is_finite()))
}

/// `s - a . b` over the common length (a plain loop: these rows are short, where an iterator
/// pair's set-up costs more than the products).
#[inline(always)]
fn dot_from(mut s: f64, a: &[f64], b: &[f64]) -> f64 {
    let k = a.len().min(b.len());
    let (a, b) = (&a[..k], &b[..k]);
    for i in 0..k {
        s -= a[i] * b[i];
    }
    s
}

/// Gaussian elimination with partial pivoting on `m` (destroyed); false for a pivot below
/// `1e-14 amax`.
fn lu_solve(m: &mut [f64], n: usize, b: &mut [f64], amax: f64) -> bool {
    let b = &mut b[..n];
    for c in 0..n {
        // Pivot: the first largest |a(r, c)|, r >= c.
        let mut p = c;
        let mut best = m[c * n + c].abs();
        for r in c + 1..n {
            let v = m[r * n + c].abs();
            if v > best {
                p = r;
                best = v;
            }
        }
        if best <= 1e-14 * amax {
            return false;
        }
        if p != c {
            // Columns left of c are no longer read.
            let (upper, lower) = m.split_at_mut(p * n);
            upper[c * n + c..c * n + n].swap_with_slice(&mut lower[c..n]);
            b.swap(c, p);
        }
        let (upper, lower) = m.split_at_mut((c + 1) * n);
        let prow = &upper[c * n + c..c * n + n];
        let piv = prow[0];
        let (bu, bl) = b.split_at_mut(c + 1);
        let bc = bu[c];
        for (row, br) in lower.chunks_exact_mut(n).zip(bl.iter_mut()) {
            let f = row[c] / piv;
            if f != 0.0 {
                for (x, y) in row[c..].iter_mut().zip(prow) {
                    *x -= f * y;
                }
                *br -= f * bc;
            }
        }
    }
    for c in (0..n).rev() {
        let row = &m[c * n..c * n + n];
        let mut s = b[c];
        for (x, y) in row[c + 1..].iter().zip(&b[c + 1..]) {
            s -= x * y;
        }
        b[c] = s / row[c];
    }
    b.iter().all(|v| v.is_finite())
}

/// A plain Newton correction below this many ulps of the pin circle radius `rp` (on every
/// unknown, as a length) is round-off: the equilibrium is accepted without taking it (and
/// without the evaluation there). The residual tolerance 1e-12 of the load corresponds to a
/// correction of about 7 ulps of `rp` in the softest direction of the physical preset at rated
/// torque (`1e-12 T / rp` over the torsional stiffness `k_t / rp^2`, 2.8e7 N m/rad); in its
/// 360-angle sweep the third step, where one was needed, was 2-5 ulps after second steps above
/// 5e4 ulps. Accepting instead of taking a correction changes the unknowns by at most
/// `16 eps rp`.
pub(crate) const STEP_ROUND_OFF: f64 = 16.0;

/// The smallest load scale `|T| / rp` an equilibrium resolves, in multiples of the round-off
/// floor of the contact forces (three significant digits of force).
const MIN_LOAD_OVER_FLOOR: f64 = 1e3;

/// Options of the equilibrium solver.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonOptions {
    /// Converged when every scaled residual `|Q_a| / L_a` is below `tolerance` times the load
    /// scale `|T| / rp` (or below the round-off floor of the force evaluation,
    /// `~1e2 eps k_ref rp`), or when the residual is below 1e-9 of that scale and the next Newton
    /// correction is round-off (below 16 ulps of `rp` on every unknown).
    pub tolerance: f64,
    /// Most iterations per equilibrium.
    pub max_iterations: usize,
    /// Where the tangent is singular to working accuracy, try the Newton step with only the
    /// singular directions regularised (a modified Cholesky factorization) before damping
    /// every direction (Levenberg-Marquardt). Off by default: [`crate::analysis::ltca::Ltca`]
    /// turns it on for a second attempt at an equilibrium the default iteration failed to find
    /// (measured: BENCHMARKS.md section 10.4).
    pub regularise_singular: bool,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        Self {
            tolerance: 1e-12,
            max_iterations: 200,
            regularise_singular: false,
        }
    }
}

/// How one equilibrium was reached.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonReport {
    /// Newton iterations used.
    pub iterations: usize,
    /// Largest scaled residual relative to the force scale.
    pub residual: f64,
}

/// The scaled residual norms (max and 2-norm) relative to `force_scale`.
fn norms(r: &[f64], scale: &[f64], force_scale: f64) -> (f64, f64) {
    let mut m: f64 = 0.0;
    let mut s = 0.0;
    for (v, l) in r.iter().zip(scale) {
        let x = v / l / force_scale;
        m = m.max(x.abs());
        s += x * x;
    }
    (m, s.sqrt())
}

/// Scratch space of [`equilibrium`] (sized on first use, kept between calls: no allocation per
/// equilibrium), and the contact state at the solution when asked for.
#[derive(Debug, Clone, Default)]
pub struct Scratch {
    r: Vec<f64>,
    k: Dense,
    rt: Vec<f64>,
    kt: Dense,
    a: Dense,
    dq: Vec<f64>,
    qt: Vec<f64>,
    scale: Vec<f64>,
    floor: Vec<f64>,
    /// Contact state of the evaluation at the solution (filled when `capture` is asked for).
    pub state: ContactState,
    trial: ContactState,
}

impl Scratch {
    fn size(&mut self, n: usize) {
        if self.k.n != n || self.r.len() != n {
            for v in [
                &mut self.r,
                &mut self.rt,
                &mut self.dq,
                &mut self.qt,
                &mut self.floor,
            ] {
                *v = vec![0.0; n];
            }
            for m in [&mut self.k, &mut self.kt, &mut self.a] {
                *m = Dense::zeros(n);
            }
        }
    }
}

/// Find the equilibrium at crank angle `psi` \[rad\] and output torque `torque` [N m] from the
/// guess `q` (overwritten with the solution). `k_ref` [N/m]: reference stiffness of the
/// regularisation. With `capture`, on success `scratch.state` holds the contact state of an
/// evaluation at the solution, and `work` (full forces) and `work.k_last` are that
/// evaluation's: the same as a fresh evaluation there, except that the pins the separation
/// bound skipped keep their last exact gaps (their forces are zero either way).
#[allow(clippy::too_many_arguments)]
///
/// `second_start`: unknowns to start from instead of `q` when the residual at `q` exceeds the
/// load and is larger than there (a warm start extrapolated from solutions whose bodies float
/// in their clearances can land far off, docs/model.md, "Newton iteration"); one evaluation
/// more where it is tried.
pub fn equilibrium(
    st: &mut Statics,
    psi: f64,
    torque: f64,
    q: &mut [f64],
    second_start: Option<&[f64]>,
    k_ref: f64,
    opts: &NewtonOptions,
    work: &mut Work,
    scratch: &mut Scratch,
    capture: bool,
) -> Result<NewtonReport> {
    // Residuals in N (moments over the unknown's length). Converged at `tolerance` of the load
    // scale |T| / rp, or below the round-off floor of the force evaluation (positions carry
    // ~eps |x| of round-off, times the stiffness).
    scratch.scale.clone_from(&st.scale);
    let n = st.dim();
    let rp = st.scale[0];
    let load = torque.abs() / rp;
    // Positions carry round-off of about eps times their size: the pin circle radius, or a
    // body turned by many revolutions (a crank angle of 1e4 rad puts the carrier 65 m of arc
    // away), whose positions near the contacts lose that much.
    let size = q
        .iter()
        .zip(&scratch.scale)
        .fold(rp, |m, (x, l)| m.max((x * l).abs()));
    let floor = 4.0 * f64::EPSILON * k_ref * size;
    // A load within a thousand times the round-off floor cannot be resolved: Newton would
    // accept the kinematic pose as converged (1e-7 N m on the physical preset returned TE 0
    // instead of the clearances' take-up).
    if load > 0.0 && load < MIN_LOAD_OVER_FLOOR * floor {
        if size > 10.0 * rp {
            // The floor is the large crank angle's, not the torque's.
            return Err(RvdynError::Parameter(format!(
                "at crank angle {psi} rad the bodies are turned so far that their positions \
                 lose digits: the torque {torque:.3e} N m is within {MIN_LOAD_OVER_FLOOR} times \
                 the round-off of the contact forces there; reduce the crank angle by whole \
                 mesh periods (the equilibria repeat; transmission_error and torque_twist do \
                 this themselves) or raise the torque"
            )));
        }
        return Err(RvdynError::Parameter(format!(
            "the torque {torque:.3e} N m is too small to resolve: its load scale |T|/rp = \
             {load:.3e} N is within {MIN_LOAD_OVER_FLOOR} times the round-off of the contact \
             forces ({floor:.3e} N); use at least {:.3e} N m (or 0 for the unloaded pose)",
            MIN_LOAD_OVER_FLOOR * floor * rp
        )));
    }
    let done = (opts.tolerance * load).max(floor);
    let stalled_ok = (1e-9 * load).max(10.0 * floor);
    let report_scale = load.max(1.0);
    let max_pen = st.model.max_penetration;
    let force_scale = 1.0;
    scratch.size(n);
    let Scratch {
        r,
        k,
        rt,
        kt,
        a,
        dq,
        qt,
        state,
        trial: trial_state,
        scale,
        floor,
    } = scratch;
    let scale: &[f64] = scale;
    if opts.regularise_singular {
        // The modified factorization's floor: the first damping below, per direction.
        for (f, l) in floor.iter_mut().zip(scale) {
            *f = 1e-6 * k_ref * l * l;
        }
    }
    // Whether the last evaluation (whose full forces `work` keeps) is at `q`.
    let mut last_at_q = true;
    // Before returning: with `capture`, the last evaluation must be at `q`.
    macro_rules! finish {
        ($it:expr, $res:expr) => {{
            if capture && !last_at_q {
                st.eval(psi, q, torque, rt, kt, work, Some(&mut *state))?;
            }
            work.k_last.clone_from(&*k);
            return Ok(NewtonReport {
                iterations: $it,
                residual: $res,
            });
        }};
    }
    st.eval(psi, q, torque, r, k, work, capture.then_some(&mut *state))?;
    let (mut rmax, mut r2) = norms(r, scale, force_scale);
    if let Some(alt) = second_start
        && alt.len() == n
        && rmax > load
    {
        qt.copy_from_slice(alt);
        if st
            .eval(
                psi,
                qt,
                torque,
                rt,
                kt,
                work,
                capture.then_some(&mut *trial_state),
            )
            .is_ok()
        {
            let (m2, n2) = norms(rt, scale, force_scale);
            if m2 < rmax {
                q.copy_from_slice(qt);
                std::mem::swap(r, rt);
                std::mem::swap(k, kt);
                std::mem::swap(state, trial_state);
                (rmax, r2) = (m2, n2);
            } else {
                last_at_q = false;
            }
        } else {
            last_at_q = false;
        }
    }
    let mut mu = 0.0;
    let mut it = 0;
    while rmax > done {
        if it >= opts.max_iterations {
            return Err(not_converged(psi, torque, rmax / report_scale, it));
        }
        it += 1;
        let mut accepted = false;
        for _attempt in 0..12 {
            a.a.copy_from_slice(&k.a);
            for (i, l) in scale.iter().enumerate() {
                a.a[i * n + i] += mu * k_ref * l * l;
            }
            dq.copy_from_slice(r);
            if !solve_dense(a, dq) {
                // Singular to working accuracy (a body floating in a clearance, a contact at
                // first touch). With `regularise_singular`, first the Newton step with the
                // singular directions alone regularised (as the damping below, 1e-6 k_ref per
                // unit length squared); otherwise, and if that fails, damping of all.
                let regularised = opts.regularise_singular && mu == 0.0 && {
                    dq.copy_from_slice(r);
                    modified_cholesky_solve(&k.a, n, dq, floor)
                };
                if !regularised {
                    mu = if mu == 0.0 { 1e-6 } else { mu * 10.0 };
                    continue;
                }
            }
            // Line search along dq. The fast path is the full step when it reduces the
            // residual. Otherwise a one-dimensional search for the minimum of the potential
            // along dq, on its slope `s(a) = Q(q + a dq) . dq` (positive while the potential
            // still falls): expand the step while the slope stays positive (inside a clearance
            // nothing resists and the slope is the load's), then bisect to a point where the
            // slope has fallen to half of its initial value or below (a strong-Wolfe condition,
            // Nocedal and Wright section 3.1). No energy is needed.
            // Converged at the round-off floor: a plain Newton correction that moves no point
            // by more than `STEP_ROUND_OFF` ulps of the pin circle radius changes the solution
            // by round-off only (the residual tolerance itself allows about that much, see
            // below); the state at `q` is kept without another evaluation.
            if mu == 0.0 && rmax <= stalled_ok {
                let moved = dq
                    .iter()
                    .zip(scale)
                    .fold(0.0f64, |m, (d, l)| m.max((d * l).abs()));
                if moved <= STEP_ROUND_OFF * f64::EPSILON * size {
                    finish!(it - 1, rmax / report_scale);
                }
            }
            let s0: f64 = r.iter().zip(dq.iter()).map(|(a, b)| a * b).sum();
            if s0.is_nan() || s0 <= 0.0 {
                mu = if mu == 0.0 { 1e-6 } else { mu * 10.0 };
                continue;
            }
            let mut trial = |step: f64,
                             qt: &mut [f64],
                             rt: &mut [f64],
                             kt: &mut Dense,
                             ts: &mut ContactState| {
                for i in 0..n {
                    qt[i] = q[i] + step * dq[i];
                }
                // A trial that moves any point by more than the penetration bound, or that
                // penetrates beyond it, is rejected: a larger step could carry a disc through
                // a pin onto the next lobe (the nearest-point gap would not notice).
                let moved = dq
                    .iter()
                    .zip(scale.iter())
                    .fold(0.0f64, |m, (d, l)| m.max((step * d * l).abs()));
                if moved > max_pen {
                    return None;
                }
                match st.eval(psi, qt, torque, rt, kt, work, capture.then_some(ts)) {
                    Ok(()) if st.max_penetration > max_pen => None,
                    Ok(()) => {
                        let (m2, n2) = norms(rt, scale, force_scale);
                        let slope: f64 = rt.iter().zip(dq.iter()).map(|(a, b)| a * b).sum();
                        Some((m2, n2, slope))
                    }
                    Err(_) => None,
                }
            };
            let mut chosen: Option<(f64, f64, f64)> = None;
            last_at_q = false;
            let first = trial(1.0, qt, rt, kt, trial_state);
            if let Some((m2, n2, _)) = first
                && (n2 < (1.0 - 1e-4) * r2 || m2 <= done)
            {
                chosen = Some((1.0, m2, n2));
            } else if rmax <= stalled_ok {
                // A full Newton step that cannot reduce a residual this small: round-off floor.
                finish!(it, rmax / report_scale);
            } else {
                let (mut lo, mut hi) = (0.0, 1.0);
                let mut lo_norms = (rmax, r2);
                if let Some((m2, n2, s1)) = first
                    && s1 > 0.0
                {
                    lo = 1.0;
                    lo_norms = (m2, n2);
                    hi = f64::INFINITY;
                    let mut step = 1.0;
                    for _ in 0..60 {
                        step *= 2.0;
                        match trial(step, qt, rt, kt, trial_state) {
                            Some((m2, n2, s)) if s > 0.0 => {
                                lo = step;
                                lo_norms = (m2, n2);
                            }
                            Some((m2, n2, s)) if s.abs() <= 0.5 * s0 => {
                                chosen = Some((step, m2, n2));
                                break;
                            }
                            _ => {
                                hi = step;
                                break;
                            }
                        }
                    }
                }
                if chosen.is_none() && hi.is_finite() {
                    for _ in 0..40 {
                        let mid = 0.5 * (lo + hi);
                        match trial(mid, qt, rt, kt, trial_state) {
                            Some((m2, n2, s)) if s.abs() <= 0.5 * s0 => {
                                chosen = Some((mid, m2, n2));
                                break;
                            }
                            Some((m2, n2, s)) if s > 0.0 => {
                                lo = mid;
                                lo_norms = (m2, n2);
                            }
                            _ => hi = mid,
                        }
                    }
                }
                if chosen.is_none() && lo > 0.0 {
                    chosen = Some((lo, lo_norms.0, lo_norms.1));
                }
            }
            if let Some((step, m2, n2)) = chosen {
                // The last trial is usually the chosen step: keep its evaluation.
                let same = (0..n).all(|i| qt[i] == q[i] + step * dq[i]);
                for i in 0..n {
                    q[i] += step * dq[i];
                }
                if same {
                    std::mem::swap(r, rt);
                    std::mem::swap(k, kt);
                    std::mem::swap(state, trial_state);
                } else {
                    st.eval(psi, q, torque, r, k, work, capture.then_some(&mut *state))?;
                }
                last_at_q = true;
                rmax = m2;
                r2 = n2;
                accepted = true;
            }
            if accepted {
                mu = if mu <= 1e-6 { 0.0 } else { mu * 0.1 };
                break;
            }
            // A full Newton step that cannot reduce a residual this small: round-off floor.
            if mu == 0.0 && rmax <= stalled_ok {
                finish!(it, rmax / report_scale);
            }
            mu = if mu == 0.0 { 1e-6 } else { mu * 10.0 };
        }
        if !accepted {
            if rmax <= stalled_ok {
                break;
            }
            return Err(not_converged(psi, torque, rmax / report_scale, it));
        }
    }
    finish!(it, rmax / report_scale);
}

fn not_converged(psi: f64, torque: f64, residual: f64, it: usize) -> RvdynError {
    // Beyond about 1e2 rad (small torques) to 1e4 rad (rated) the round-off of whole turns in the positions can exceed the
    // tolerance (docs/model.md, "Newton iteration").
    let turns = if psi.abs() > 1e2 {
        " Or the crank angle is so large that the round-off of its whole turns exceeds the \
         tolerance: give it modulo the mesh period (the TE repeats)."
    } else {
        ""
    };
    RvdynError::Convergence(format!(
        "the static equilibrium (LTCA) did not converge at crank angle {psi:.6} rad, output \
         torque {torque:.6e} N m: scaled residual {residual:.3e} of the load after {it} \
         iterations. Either the torque exceeds what the contacts can carry, or a clearance \
         leaves a body unsupported (no equilibrium): reduce the torque or the clearances.{turns}"
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Uniform numbers in [-0.5, 0.5) from a 64-bit linear congruential generator (Knuth's
    /// MMIX constants), reproducible from `seed`.
    fn uniform(mut state: u64) -> impl FnMut() -> f64 {
        move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64) / ((1u64 << 53) as f64) - 0.5
        }
    }

    #[test]
    fn dense_solve_matches_a_known_system_and_flags_singular() {
        let mut a = Dense {
            n: 3,
            a: vec![2.0, 1.0, 0.0, 1.0, 3.0, 1.0, 0.0, 1.0, 4.0],
        };
        let x = [1.0, -2.0, 0.5];
        let mut b = vec![2.0 - 2.0, 1.0 - 6.0 + 0.5, -2.0 + 2.0];
        assert!(solve_dense(&mut a, &mut b));
        for i in 0..3 {
            assert!((b[i] - x[i]).abs() < 1e-14);
        }
        let mut s = Dense {
            n: 2,
            a: vec![1.0, 2.0, 2.0, 4.0],
        };
        assert!(!solve_dense(&mut s, &mut [1.0, 1.0]));
    }

    /// The fixed-size Cholesky gives the general one's solution bit for bit (the same
    /// operations in the same order), for every size it covers, on symmetric positive definite
    /// matrices `B B^T + n I` with a known solution, which both reproduce to 1e-12.
    #[test]
    fn fixed_size_cholesky_equals_the_general_one() {
        let mut rnd = uniform(7);
        for n in 1..=22 {
            let bm: Vec<f64> = (0..n * n).map(|_| rnd()).collect();
            let mut m = vec![0.0; n * n];
            for i in 0..n {
                for j in 0..n {
                    let s: f64 = (0..n).map(|k| bm[i * n + k] * bm[j * n + k]).sum();
                    m[i * n + j] = s + if i == j { n as f64 } else { 0.0 };
                }
            }
            let x: Vec<f64> = (0..n).map(|_| rnd()).collect();
            let b: Vec<f64> = (0..n)
                .map(|i| (0..n).map(|j| m[i * n + j] * x[j]).sum())
                .collect();
            let mut via_dispatch = b.clone();
            assert_eq!(cholesky_solve(&m, n, &mut via_dispatch, 1e-14), Some(true));
            let (mut l, mut inv, mut y) = (vec![0.0; n * n], vec![0.0; n], vec![0.0; n]);
            let mut general = b.clone();
            assert_eq!(
                cholesky_in(&m, n, &mut general, 1e-14, None, &mut l, &mut inv, &mut y),
                Some(true)
            );
            assert_eq!(via_dispatch, general, "size {n}");
            for (g, w) in general.iter().zip(&x) {
                assert!((g - w).abs() < 1e-12, "size {n}: {g} against {w}");
            }
        }
    }

    /// Both paths of the solver (Cholesky for symmetric positive definite matrices, LU with
    /// pivoting for the rest) against known solutions: `b = A x` for a chosen `x`, on random
    /// matrices of size 16 (the physical preset's unknowns) and 23. Positive definite
    /// `A = B B^T + I` with condition numbers up to about 1e3 (residual of the solution 1e-12
    /// relative, i.e. round-off times the condition); the same matrix with a 1e-3 asymmetry
    /// (LU path) and a symmetric indefinite one (Cholesky fails, LU takes over) to the same
    /// tolerance; the Cholesky and LU results of one matrix agree to 1e-12; non-finite entries
    /// and singular symmetric matrices are refused.
    #[test]
    fn symmetric_and_general_solves_match_known_solutions() {
        let mut rnd = uniform(99);
        for n in [16usize, 23] {
            let bm: Vec<f64> = (0..n * n).map(|_| rnd()).collect();
            let mut spd = Dense::zeros(n);
            for i in 0..n {
                for j in 0..n {
                    let s: f64 = (0..n).map(|k| bm[i * n + k] * bm[j * n + k]).sum();
                    spd.a[i * n + j] = s + if i == j { 1.0 } else { 0.0 };
                }
            }
            let x: Vec<f64> = (0..n).map(|_| rnd()).collect();
            let rhs = |a: &Dense| -> Vec<f64> {
                (0..n)
                    .map(|i| (0..n).map(|j| a.at(i, j) * x[j]).sum())
                    .collect()
            };
            let check = |a: &Dense, what: &str| -> Vec<f64> {
                let mut b = rhs(a);
                let mut m = a.clone();
                assert!(solve_dense(&mut m, &mut b), "{what}");
                for i in 0..n {
                    assert!(
                        (b[i] - x[i]).abs() < 1e-12,
                        "{what} {n}: {} vs {}",
                        b[i],
                        x[i]
                    );
                }
                b
            };
            assert!(symmetric(&spd.a, n, 0.0));
            let chol = check(&spd, "positive definite");
            // The LU path on the same matrix.
            let mut b = rhs(&spd);
            let amax = spd.a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let mut m = spd.clone();
            assert!(lu_solve(&mut m.a, n, &mut b, amax));
            for i in 0..n {
                assert!((b[i] - chol[i]).abs() < 1e-12);
            }
            let mut unsym = spd.clone();
            unsym.a[1] += 1e-3;
            assert!(!symmetric(&unsym.a, n, 1e-13 * amax));
            check(&unsym, "unsymmetric");
            let mut indefinite = spd.clone();
            indefinite.a[0] = -3.0;
            let mut b = rhs(&indefinite);
            assert!(cholesky_solve(&indefinite.a, n, &mut b, 1e-14).is_none());
            check(&indefinite, "indefinite");
            let mut bad = spd.clone();
            bad.a[5] = f64::NAN;
            assert!(!solve_dense(&mut bad, &mut rhs(&spd)));
        }
        // Symmetric, positive semi-definite and singular: refused by both paths.
        let mut s = Dense {
            n: 3,
            a: vec![1.0, 1.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 2.0],
        };
        assert!(!solve_dense(&mut s, &mut [1.0, 1.0, 1.0]));
    }

    /// The modified factorization changes only the singular (or indefinite) directions: on a
    /// block-diagonal matrix with a regular block, a zero row and a negative pivot, the step
    /// is the exact solve on the regular block, `b / floor` on the zero row and `b / |d|` on
    /// the negative one (a descent direction); an unsymmetric matrix is refused.
    #[test]
    fn modified_cholesky_regularises_only_the_singular_directions() {
        // [[4, 1, 0, 0], [1, 3, 0, 0], [0, 0, 0, 0], [0, 0, 0, -2]]
        let mut m = vec![0.0; 16];
        m[0] = 4.0;
        m[1] = 1.0;
        m[4] = 1.0;
        m[5] = 3.0;
        m[15] = -2.0;
        let floor = [1e-3, 1e-3, 0.5, 1e-3];
        let mut b = [1.0, 2.0, 3.0, 4.0];
        assert!(modified_cholesky_solve(&m, 4, &mut b, &floor));
        // The regular block: 4 x + y = 1, x + 3 y = 2.
        let (x, y) = (1.0 / 11.0, 7.0 / 11.0);
        assert!(
            (b[0] - x).abs() < 1e-15 && (b[1] - y).abs() < 1e-15,
            "{b:?}"
        );
        assert!((b[2] - 3.0 / 0.5).abs() < 1e-14, "{b:?}");
        assert!((b[3] - 4.0 / 2.0).abs() < 1e-14, "{b:?}");
        // The plain factorization refuses the same matrix.
        let mut plain = Dense { n: 4, a: m.clone() };
        assert!(!solve_dense(&mut plain, &mut [1.0, 2.0, 3.0, 4.0]));
        // Unsymmetric: refused.
        m[2] = 0.5;
        assert!(!modified_cholesky_solve(&m, 4, &mut [1.0; 4], &floor));
    }
}
