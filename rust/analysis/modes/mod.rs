//! Linear modal analysis of a linearised mechanical system
//!
//! ```text
//! M q'' + C q' + K q = 0,      K = sum_p K_p   (named stiffness parts)
//! ```
//!
//! about an operating point (docs/model.md, "Modal analysis"):
//!
//! - **undamped modes**: the symmetric generalized eigenproblem `K phi = w^2 M phi`, reduced to
//!   a standard symmetric one with the Cholesky factor `M = L L^T`:
//!   `(L^-1 K L^-T) y = w^2 y`, `phi = L^-T y`, so `phi^T M phi = 1` (Golub & Van Loan 2013,
//!   section 8.7; Geradin & Rixen 2015, ch. 2);
//! - **damped modes**: the eigenvalues `lambda` of the first-order state matrix (a real Schur
//!   form), each refined and given its eigenvector by inverse iteration on the quadratic pencil
//!   `lambda^2 M + lambda C + K` (Tisseur & Meerbergen 2001), then matched to the undamped mode
//!   with the largest mass-weighted modal assurance criterion; `w_n = |lambda|`,
//!   `zeta = -Re(lambda)/|lambda|` (a pair of real roots: `w_n = sqrt(l1 l2)`,
//!   `zeta = -(l1 + l2)/(2 w_n)`);
//! - **strain-energy shares**: `share_p = phi^T K_p phi / phi^T K phi` (the modal strain energy
//!   distribution used to locate a mode in a structure, e.g. Geradin & Rixen 2015).
//!
//! `K` is symmetrised (its relative skew part is reported); `C` is used as given.
//! Units: coordinates in any consistent units (m, rad), `M` in kg or kg m^2, `K` in N/m or
//! N m/rad, `C` in N s/m or N m s/rad; frequencies in Hz, eigenvalues in 1/s.

mod damped;
pub mod linearise;
pub mod sweep;
#[cfg(test)]
mod tests;

use crate::error::{Result, RvdynError};
use nalgebra::{Complex, DMatrix, DVector, SymmetricEigen};
use std::f64::consts::TAU;

pub use damped::DampedTrack;
pub use linearise::{Equilibrium, Linearizer};
pub use sweep::{Campbell, ModalPoint, campbell, modes_at, modes_at_state, modes_over};

/// One named contribution to the stiffness matrix (a contact family or a bearing family).
#[derive(Debug, Clone, PartialEq)]
pub struct StiffnessPart {
    /// Name shown in the energy table (e.g. "pin contacts disc 0", "eccentric bearings").
    pub name: String,
    /// Its stiffness matrix, n x n in the system's coordinates.
    pub matrix: DMatrix<f64>,
}

/// A linearised system `M q'' + C q' + K q = 0` with named coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearSystem {
    /// One name per coordinate (e.g. "carrier angle", "disc 0 x"); n entries.
    pub dof_names: Vec<String>,
    /// Mass matrix, symmetric positive definite, n x n.
    pub mass: DMatrix<f64>,
    /// The stiffness as a sum of named parts (at least one).
    pub stiffness: Vec<StiffnessPart>,
    /// Damping matrix, n x n (zeros for an undamped analysis).
    pub damping: DMatrix<f64>,
    /// Length per unit of each coordinate \[m\] (a lever arm for an angle), used only to pick
    /// the dominant coordinate of a mode shape; empty = all 1.
    pub length_scale: Vec<f64>,
}

/// The damped counterpart of an undamped mode.
#[derive(Debug, Clone, PartialEq)]
pub struct DampedMode {
    /// Eigenvalue of the state matrix [1/s] (the one with positive imaginary part; for an
    /// overdamped pair the slower real root).
    pub eigenvalue: Complex<f64>,
    /// Undamped natural frequency of the damped eigenvalue(s), `|lambda| / 2 pi` \[Hz\].
    pub natural_frequency: f64,
    /// Damped frequency `Im(lambda) / 2 pi` \[Hz\] (0 for an overdamped mode).
    pub damped_frequency: f64,
    /// Damping ratio (dimensionless; >= 1 for an overdamped pair).
    pub damping_ratio: f64,
    /// Mass-weighted modal assurance criterion with the undamped shape, in [0, 1].
    pub mac: f64,
    /// Complex mode shape in the system's coordinates, scaled so that the component with the
    /// largest `|q_i| L_i` is real and positive with `|q_i| L_i = 1`.
    pub shape: DVector<Complex<f64>>,
}

/// One undamped mode with its damped counterpart.
#[derive(Debug, Clone, PartialEq)]
pub struct Mode {
    /// `w^2` [1/s^2] (negative: a statically unstable direction of the tangent stiffness).
    pub omega_squared: f64,
    /// Undamped natural frequency `sqrt(max(w^2, 0)) / 2 pi` \[Hz\].
    pub frequency: f64,
    /// A rigid-body (zero-stiffness) mode: `|w^2|` below 1e-10 of the largest.
    pub rigid_body: bool,
    /// `w^2 < 0` beyond round-off: the tangent stiffness is indefinite along this mode.
    pub unstable: bool,
    /// Mass-normalised shape, `phi^T M phi = 1`.
    pub shape: DVector<f64>,
    /// The same shape scaled so that its largest `|phi_i| L_i` is +1.
    pub display_shape: DVector<f64>,
    /// Index of the coordinate with the largest `|phi_i| L_i`.
    pub dominant_dof: usize,
    /// Share of the modal strain energy in each stiffness part (sums to 1; zeros for a
    /// rigid-body mode).
    pub energy_share: Vec<f64>,
    /// Modal damping ratio of the undamped shape, `phi^T C phi / (2 w)` (exact for
    /// proportional damping; the damped analysis is the reference otherwise). 0 for a
    /// rigid-body mode.
    pub modal_damping_ratio: f64,
    /// The matched damped eigenvalue(s); `None` for a rigid-body mode or when no eigenvalue
    /// matched.
    pub damped: Option<DampedMode>,
}

/// The modes of a [`LinearSystem`], lowest frequency first.
#[derive(Debug, Clone, PartialEq)]
pub struct ModalAnalysis {
    /// Names of the coordinates (as given).
    pub dof_names: Vec<String>,
    /// Names of the stiffness parts (as given).
    pub part_names: Vec<String>,
    /// n modes (as many as coordinates).
    pub modes: Vec<Mode>,
    /// `|K - K^T|_F / (2 |K|_F)` of the stiffness before symmetrisation.
    pub stiffness_asymmetry: f64,
    /// `|C - C^T|_F / (2 |C|_F)` of the damping (used as given).
    pub damping_asymmetry: f64,
    /// All 2n eigenvalues of the state matrix [1/s], refined.
    pub eigenvalues: Vec<Complex<f64>>,
    /// Eigenvalues (upper half plane) that matched no undamped mode.
    pub unmatched: Vec<Complex<f64>>,
    /// Each matched mode's two eigenvalues (a conjugate pair or two real roots) with the
    /// reduced matrices: pass it to [`modal_analysis_near`] for the next point of a sweep.
    pub damped_track: DampedTrack,
}

impl ModalAnalysis {
    /// Lowest and highest undamped natural frequency of the non-rigid modes \[Hz\].
    pub fn frequency_span(&self) -> (f64, f64) {
        let f: Vec<f64> = self
            .modes
            .iter()
            .filter(|m| !m.rigid_body && !m.unstable)
            .map(|m| m.frequency)
            .collect();
        (
            f.iter().copied().fold(f64::INFINITY, f64::min),
            f.iter().copied().fold(0.0, f64::max),
        )
    }

    /// Indices of the modes whose undamped frequency lies in `[lo, hi]` \[Hz\]. A range that is
    /// not finite, not ordered, negative, or holds no mode of the model is a `ParameterError`
    /// that gives the model's frequency span.
    pub fn modes_in_range(&self, lo: f64, hi: f64) -> Result<Vec<usize>> {
        let (fmin, fmax) = self.frequency_span();
        if !(lo.is_finite() && hi.is_finite() && lo >= 0.0 && hi > lo) {
            return Err(RvdynError::Parameter(format!(
                "frequency range [{lo}, {hi}] Hz must be finite with 0 <= low < high"
            )));
        }
        let idx: Vec<usize> = (0..self.modes.len())
            .filter(|&i| {
                let m = &self.modes[i];
                !m.rigid_body && m.frequency >= lo && m.frequency <= hi
            })
            .collect();
        if idx.is_empty() {
            return Err(RvdynError::Parameter(format!(
                "no mode in [{}, {}] Hz: the model's natural frequencies span {} to {} Hz; ask \
                 for a range that overlaps them",
                sig(lo),
                sig(hi),
                sig(fmin),
                sig(fmax)
            )));
        }
        Ok(idx)
    }
}

/// Modal analysis of `sys` (see the module documentation for the method).
///
/// Errors: `ParameterError` for shapes that do not fit, non-finite entries (naming the matrix
/// and coordinates), an asymmetric mass matrix, a coordinate with zero or negative mass
/// (naming it) or a mass matrix that is not positive definite (naming the coordinate where the
/// Cholesky factorisation fails); `ConvergenceError` if an eigenvalue iteration fails.
pub fn modal_analysis(sys: &LinearSystem) -> Result<ModalAnalysis> {
    modal_analysis_near(sys, None)
}

/// [`modal_analysis`] at a point of a sweep: `previous` holds the previous point's
/// [`ModalAnalysis::damped_track`], from which the damped eigenvalues are matched to the modes
/// when each previous pair is clearly nearest to two of the new eigenvalues (the step is
/// small), instead of the continuation from zero damping that an uncertain matching otherwise
/// takes; docs/model.md, "Modal analysis").
pub fn modal_analysis_near(
    sys: &LinearSystem,
    previous: Option<&DampedTrack>,
) -> Result<ModalAnalysis> {
    let n = sys.dof_names.len();
    check_inputs(sys)?;
    let names = &sys.dof_names;
    let m_asym = skew_ratio(&sys.mass);
    if m_asym > 1e-9 {
        return Err(RvdynError::Parameter(format!(
            "the mass matrix is not symmetric (relative skew part {m_asym:.3e}); a mass matrix \
             from a kinetic energy is symmetric"
        )));
    }
    let mass = symmetrise(&sys.mass);
    let l = cholesky(&mass, names)?;
    let mut k_raw = DMatrix::<f64>::zeros(n, n);
    for p in &sys.stiffness {
        k_raw += &p.matrix;
    }
    let stiffness_asymmetry = skew_ratio(&k_raw);
    let damping_asymmetry = skew_ratio(&sys.damping);
    let parts: Vec<DMatrix<f64>> = sys
        .stiffness
        .iter()
        .map(|p| symmetrise(&p.matrix))
        .collect();
    let k = symmetrise(&k_raw);

    // Reduced stiffness Kt = L^-1 K L^-T (symmetric), damping Ct = L^-1 C L^-T.
    let kt = symmetrise(&congruence(&l, &k)?);
    let ct = congruence(&l, &sys.damping)?;
    let eig =
        SymmetricEigen::try_new(kt.clone(), f64::EPSILON, 1000 * n.max(10)).ok_or_else(|| {
            RvdynError::Convergence("the symmetric eigenvalue iteration did not converge".into())
        })?;
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
    let lam_max = eig.eigenvalues.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let zero_tol = 1e-10 * lam_max;
    let lt = l.transpose();
    let lever: Vec<f64> = if sys.length_scale.is_empty() {
        vec![1.0; n]
    } else {
        sys.length_scale.clone()
    };
    let mut modes = Vec::with_capacity(n);
    let mut reduced_shapes = Vec::with_capacity(n);
    for &i in &order {
        let w2 = eig.eigenvalues[i];
        let y = eig.eigenvectors.column(i).into_owned();
        let phi = lt
            .solve_upper_triangular(&y)
            .ok_or_else(|| RvdynError::Parameter("singular mass factor".into()))?;
        let rigid_body = w2.abs() <= zero_tol || lam_max == 0.0;
        let unstable = !rigid_body && w2 < 0.0;
        let (dominant_dof, display_shape) = display(&phi, &lever);
        let total = phi.dot(&(&k * &phi));
        let energy_share = parts
            .iter()
            .map(|kp| {
                if rigid_body || total == 0.0 {
                    0.0
                } else {
                    phi.dot(&(kp * &phi)) / total
                }
            })
            .collect();
        let omega = w2.max(0.0).sqrt();
        let modal_damping_ratio = if rigid_body || omega == 0.0 {
            0.0
        } else {
            phi.dot(&(&sys.damping * &phi)) / (2.0 * omega)
        };
        modes.push(Mode {
            omega_squared: w2,
            frequency: omega / TAU,
            rigid_body,
            unstable,
            shape: phi,
            display_shape,
            dominant_dof,
            energy_share,
            modal_damping_ratio,
            damped: None,
        });
        reduced_shapes.push(y);
    }

    let damped = damped::damped_modes(&kt, &ct, lam_max, &reduced_shapes, previous)?;
    for (mode_index, dm) in damped.matched {
        let md = &mut modes[mode_index];
        if md.rigid_body {
            continue;
        }
        // q = L^-T x, real and imaginary parts separately.
        let solve = |v: DVector<f64>| {
            lt.solve_upper_triangular(&v)
                .ok_or_else(|| RvdynError::Parameter("singular mass factor".into()))
        };
        let re = solve(dm.reduced_shape.map(|v| v.re))?;
        let im = solve(dm.reduced_shape.map(|v| v.im))?;
        let q = DVector::from_fn(n, |i, _| Complex::new(re[i], im[i]));
        md.damped = Some(DampedMode {
            eigenvalue: dm.eigenvalue,
            natural_frequency: dm.natural_omega / TAU,
            damped_frequency: dm.eigenvalue.im.max(0.0) / TAU,
            damping_ratio: dm.damping_ratio,
            mac: dm.mac,
            shape: display_complex(&q, &lever),
        });
    }
    Ok(ModalAnalysis {
        dof_names: names.clone(),
        part_names: sys.stiffness.iter().map(|p| p.name.clone()).collect(),
        modes,
        stiffness_asymmetry,
        damping_asymmetry,
        eigenvalues: damped.all,
        unmatched: damped.unmatched,
        damped_track: DampedTrack {
            pairs: damped.ends,
            before: previous.map(|p| p.pairs.clone()).unwrap_or_default(),
        },
    })
}

fn check_inputs(sys: &LinearSystem) -> Result<()> {
    let n = sys.dof_names.len();
    let perr = |m: String| Err(RvdynError::Parameter(m));
    if n == 0 {
        return perr("a modal analysis needs at least one coordinate".into());
    }
    if sys.stiffness.is_empty() {
        return perr("give the stiffness as at least one named part".into());
    }
    let mut all: Vec<(&str, &DMatrix<f64>)> =
        vec![("mass matrix", &sys.mass), ("damping matrix", &sys.damping)];
    for p in &sys.stiffness {
        all.push((p.name.as_str(), &p.matrix));
    }
    for (what, m) in all {
        if m.nrows() != n || m.ncols() != n {
            return perr(format!(
                "{what} is {}x{}, but there are {n} coordinates",
                m.nrows(),
                m.ncols()
            ));
        }
        for i in 0..n {
            for j in 0..n {
                let v = m[(i, j)];
                if !v.is_finite() {
                    return perr(format!(
                        "{what} entry ({}, {}) is {v}: every entry must be finite",
                        sys.dof_names[i], sys.dof_names[j]
                    ));
                }
            }
        }
    }
    if !sys.length_scale.is_empty() {
        if sys.length_scale.len() != n {
            return perr(format!(
                "length_scale has {} entries for {n} coordinates",
                sys.length_scale.len()
            ));
        }
        if let Some((i, v)) = sys
            .length_scale
            .iter()
            .enumerate()
            .find(|(_, v)| !(v.is_finite() && **v > 0.0))
        {
            return perr(format!(
                "length_scale of {} must be finite and > 0 m, got {v}",
                sys.dof_names[i]
            ));
        }
    }
    Ok(())
}

/// `v` with 4 significant digits (plain notation).
pub(crate) fn sig(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let decimals = (3 - v.abs().log10().floor() as i32).max(0) as usize;
    format!("{v:.decimals$}")
}

/// `(A + A^T)/2`.
fn symmetrise(a: &DMatrix<f64>) -> DMatrix<f64> {
    (a + a.transpose()) * 0.5
}

/// `|A - A^T|_F / (2 |A|_F)` (0 for a zero matrix).
fn skew_ratio(a: &DMatrix<f64>) -> f64 {
    let norm = a.norm();
    if norm == 0.0 {
        0.0
    } else {
        (a - a.transpose()).norm() / (2.0 * norm)
    }
}

/// `L^-1 A L^-T` for a lower-triangular, non-singular `L`.
fn congruence(l: &DMatrix<f64>, a: &DMatrix<f64>) -> Result<DMatrix<f64>> {
    // X = L^-1 A, then L^-1 A L^-T = (L^-1 X^T)^T.
    let singular = || RvdynError::Parameter("singular mass factor".into());
    let x = l.solve_lower_triangular(a).ok_or_else(singular)?;
    Ok(l.solve_lower_triangular(&x.transpose())
        .ok_or_else(singular)?
        .transpose())
}

/// Lower Cholesky factor of a symmetric matrix, or a `ParameterError` naming the coordinate
/// with zero/negative mass, or where positive definiteness fails (Golub & Van Loan 2013,
/// algorithm 4.2.1).
fn cholesky(a: &DMatrix<f64>, names: &[String]) -> Result<DMatrix<f64>> {
    let n = a.nrows();
    let scale = (0..n).fold(0.0f64, |s, i| s.max(a[(i, i)].abs()));
    for i in 0..n {
        let d = a[(i, i)];
        if d <= 0.0 {
            return Err(RvdynError::Parameter(format!(
                "the mass matrix has {d} on the diagonal of coordinate '{}': a body with zero \
                 inertia (or mass) makes the mass matrix singular; give the body its mass \
                 properties (scene inertias) or remove the coordinate",
                names[i]
            )));
        }
    }
    let mut l = DMatrix::<f64>::zeros(n, n);
    for j in 0..n {
        let mut d = a[(j, j)];
        for k in 0..j {
            d -= l[(j, k)] * l[(j, k)];
        }
        if d <= 1e-13 * scale.max(a[(j, j)]) {
            return Err(RvdynError::Parameter(format!(
                "the mass matrix is not positive definite: it becomes singular at coordinate \
                 '{}' (pivot {d:.3e}); a coordinate that no body's inertia moves on its own \
                 (a zero-inertia body, or a coordinate that depends on the others) must be \
                 removed",
                names[j]
            )));
        }
        let djj = d.sqrt();
        l[(j, j)] = djj;
        for i in (j + 1)..n {
            let mut s = a[(i, j)];
            for k in 0..j {
                s -= l[(i, k)] * l[(j, k)];
            }
            l[(i, j)] = s / djj;
        }
    }
    Ok(l)
}

/// Dominant coordinate (largest `|phi_i| L_i`) and the shape scaled so that it is +1.
fn display(phi: &DVector<f64>, lever: &[f64]) -> (usize, DVector<f64>) {
    let mut best = 0;
    let mut big = -1.0;
    for (i, v) in phi.iter().enumerate() {
        let w = v.abs() * lever[i];
        if w > big {
            big = w;
            best = i;
        }
    }
    let s = if big > 0.0 {
        1.0 / (phi[best] * lever[best])
    } else {
        1.0
    };
    (best, phi * s)
}

/// A complex shape scaled so that its largest `|q_i| L_i` component is real, positive and 1.
fn display_complex(q: &DVector<Complex<f64>>, lever: &[f64]) -> DVector<Complex<f64>> {
    let mut best = 0;
    let mut big = -1.0;
    for (i, v) in q.iter().enumerate() {
        let w = v.norm() * lever[i];
        if w > big {
            big = w;
            best = i;
        }
    }
    if big <= 0.0 {
        return q.clone();
    }
    let s = Complex::new(1.0, 0.0) / (q[best] * lever[best]);
    q.map(|v| v * s)
}
