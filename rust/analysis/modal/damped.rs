//! Damped eigenvalues of `y'' + Ct y' + Kt y = 0` (mass-normalised coordinates, `Kt`
//! symmetric) and their matching to the undamped modes.
//!
//! The 2n eigenvalues come from the real Schur form of the first-order state matrix
//! `[[0, s I], [-Kt/s, -Ct]]` (state `(y, y'/s)`, `s = sqrt(max w^2)` so that both blocks
//! have the same scale; the eigenvalues do not depend on `s`). Each eigenvalue in the upper
//! half plane is then polished on the quadratic pencil `P(l) = l^2 I + l Ct + Kt`
//! (Tisseur & Meerbergen 2001, section 6): inverse iteration `x <- P(mu)^-1 P'(mu) x` at a
//! shift `mu` next to it gives the eigenvector, and the root of the scalar quadratic
//! `x^H P(l) x = 0` nearest to it (the pencil's Rayleigh quotient) the refined eigenvalue.

use crate::error::{Result, RvdynError};
use nalgebra::{Complex, DMatrix, DVector, Schur};

/// A damped eigen-solution matched to one undamped mode.
pub(super) struct Matched {
    pub eigenvalue: Complex<f64>,
    pub natural_omega: f64,
    pub damping_ratio: f64,
    pub mac: f64,
    /// Eigenvector in the mass-normalised coordinates.
    pub reduced_shape: DVector<Complex<f64>>,
}

pub(super) struct DampedSet {
    /// (undamped mode index, its damped solution).
    pub matched: Vec<(usize, Matched)>,
    /// All 2n refined eigenvalues, by increasing modulus.
    pub all: Vec<Complex<f64>>,
    pub unmatched: Vec<Complex<f64>>,
}

struct Candidate {
    lambda: Complex<f64>,
    x: DVector<Complex<f64>>,
    oscillatory: bool,
}

/// Damped eigenvalues of the reduced system, matched to the undamped reduced shapes
/// `shapes` (unit vectors, by increasing `w^2`; `lam_max` the largest `|w^2|`).
pub(super) fn damped_modes(
    kt: &DMatrix<f64>,
    ct: &DMatrix<f64>,
    lam_max: f64,
    shapes: &[DVector<f64>],
) -> Result<DampedSet> {
    let n = kt.nrows();
    let s = if lam_max > 0.0 {
        lam_max.sqrt()
    } else {
        ct.norm().max(1.0)
    };
    let mut a = DMatrix::<f64>::zeros(2 * n, 2 * n);
    for i in 0..n {
        a[(i, n + i)] = s;
        for j in 0..n {
            a[(n + i, j)] = -kt[(i, j)] / s;
            a[(n + i, n + j)] = -ct[(i, j)];
        }
    }
    // The QR iteration stops at a relative subdiagonal of 1e-10 (about half the sweeps of
    // machine precision); every eigenvalue is then polished on the pencil to round-off. If it
    // does not converge (QR without exceptional shifts can cycle), retry on the same spectrum
    // with a different velocity scaling, which changes the iteration's path.
    let mut raw: Option<Vec<Complex<f64>>> = None;
    for (attempt, factor) in [1.0, 1.37, 0.61].into_iter().enumerate() {
        let mut m = a.clone();
        if attempt > 0 {
            for i in 0..n {
                m[(i, n + i)] = s * factor;
                for j in 0..n {
                    m[(n + i, j)] = -kt[(i, j)] / (s * factor);
                }
            }
        }
        if let Some(schur) = Schur::try_new(m, 1e-10, 1000 * (2 * n).max(10)) {
            raw = Some(schur.complex_eigenvalues().iter().copied().collect());
            break;
        }
    }
    let raw = raw.ok_or_else(|| {
        RvdynError::Convergence(
            "the Schur iteration for the damped eigenvalues did not converge".into(),
        )
    })?;
    let scale = raw.iter().fold(s, |m, l| m.max(l.norm()));
    let tol_im = 1e-8 * scale;

    // Upper-half-plane eigenvalues (complex) and real ones.
    let mut osc: Vec<Complex<f64>> = raw.iter().copied().filter(|l| l.im > tol_im).collect();
    let mut real: Vec<Complex<f64>> = raw
        .iter()
        .filter(|l| l.im.abs() <= tol_im)
        .map(|l| Complex::new(l.re, 0.0))
        .collect();
    osc.sort_by(|x, y| x.norm().total_cmp(&y.norm()));
    real.sort_by(|x, y| x.norm().total_cmp(&y.norm()));

    // Start vectors: the k-th oscillatory eigenvalue starts from the k-th undamped shape of
    // the non-rigid modes (keeps degenerate pairs apart); real ones from a fixed vector.
    let first_flexible = shapes.len().saturating_sub(osc.len());
    let kc = kt.map(|v| Complex::new(v, 0.0));
    let cc = ct.map(|v| Complex::new(v, 0.0));
    let mut cands = Vec::with_capacity(osc.len() + real.len());
    for (k, l) in osc.iter().enumerate() {
        let start = shapes
            .get(first_flexible + k)
            .map(|y| y.map(|v| Complex::new(v, 0.0)))
            .unwrap_or_else(|| generic_start(n));
        let (lambda, x) = refine(&kc, &cc, *l, start, scale)?;
        cands.push(Candidate {
            lambda,
            x,
            oscillatory: true,
        });
    }
    for l in &real {
        let (lambda, x) = refine(&kc, &cc, *l, generic_start(n), scale)?;
        cands.push(Candidate {
            lambda: Complex::new(lambda.re, 0.0),
            x,
            oscillatory: false,
        });
    }

    // Mass-weighted MAC in reduced coordinates: |y_j^T x|^2 / |x|^2 (y_j unit).
    let mac = |c: &Candidate, y: &DVector<f64>| -> f64 {
        let dot: Complex<f64> = y.iter().zip(c.x.iter()).map(|(a, b)| b * *a).sum();
        let xx: f64 = c.x.iter().map(|v| v.norm_sqr()).sum();
        if xx > 0.0 { dot.norm_sqr() / xx } else { 0.0 }
    };
    let mut pairs: Vec<(f64, usize, usize)> = Vec::with_capacity(cands.len() * shapes.len());
    for (ci, c) in cands.iter().enumerate() {
        for (j, y) in shapes.iter().enumerate() {
            pairs.push((mac(c, y), ci, j));
        }
    }
    pairs.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mut slots = vec![2u8; shapes.len()];
    let mut owner: Vec<Option<(usize, f64)>> = vec![None; cands.len()];
    for (m, ci, j) in pairs {
        if owner[ci].is_some() {
            continue;
        }
        let need = if cands[ci].oscillatory { 2 } else { 1 };
        if slots[j] >= need {
            slots[j] -= need;
            owner[ci] = Some((j, m));
        }
    }

    let mut matched = Vec::new();
    let mut unmatched = Vec::new();
    for j in 0..shapes.len() {
        let mine: Vec<(usize, f64)> = owner
            .iter()
            .enumerate()
            .filter_map(|(ci, o)| o.filter(|(jj, _)| *jj == j).map(|(_, m)| (ci, m)))
            .collect();
        let zero = 1e-9 * scale;
        let m = match mine.as_slice() {
            [(ci, m)] if cands[*ci].oscillatory => {
                let l = cands[*ci].lambda;
                Some(Matched {
                    eigenvalue: l,
                    natural_omega: l.norm(),
                    damping_ratio: -l.re / l.norm(),
                    mac: *m,
                    reduced_shape: cands[*ci].x.clone(),
                })
            }
            [(c1, m1), (c2, m2)] => {
                let (l1, l2) = (cands[*c1].lambda.re, cands[*c2].lambda.re);
                let (slow, fast) = if l1.abs() <= l2.abs() {
                    (*c1, *c2)
                } else {
                    (*c2, *c1)
                };
                let _ = fast;
                if l1 * l2 > 0.0 && l1.abs().min(l2.abs()) > zero {
                    let w = (l1 * l2).sqrt();
                    Some(Matched {
                        eigenvalue: cands[slow].lambda,
                        natural_omega: w,
                        damping_ratio: -(l1 + l2) / (2.0 * w),
                        mac: m1.min(*m2),
                        reduced_shape: cands[slow].x.clone(),
                    })
                } else {
                    None
                }
            }
            // One real root alone defines no damping ratio (an overdamped mode has two): the
            // mode stays unmatched rather than given a ratio of 1.
            _ => None,
        };
        if let Some(m) = m {
            matched.push((j, m));
        }
    }
    for (ci, c) in cands.iter().enumerate() {
        if owner[ci].is_none() {
            unmatched.push(c.lambda);
        }
    }
    let mut all: Vec<Complex<f64>> = Vec::with_capacity(2 * n);
    for c in &cands {
        all.push(c.lambda);
        if c.oscillatory {
            all.push(c.lambda.conj());
        }
    }
    all.sort_by(|x, y| x.norm().total_cmp(&y.norm()).then(y.im.total_cmp(&x.im)));
    Ok(DampedSet {
        matched,
        all,
        unmatched,
    })
}

fn generic_start(n: usize) -> DVector<Complex<f64>> {
    // Not orthogonal to any particular eigenvector in practice: distinct, irregular entries.
    DVector::from_fn(n, |i, _| {
        Complex::new(1.0 + 0.37 * i as f64, 0.11 * i as f64)
    })
}

/// [`polish`] repeated from its own result (Rayleigh-quotient iteration on the pencil) until
/// the eigenvalue stops moving (1e-14 of the spectrum's scale; at most 6 rounds). One round is
/// not enough when the Schur value is off by more than the shift's offset: on the compliant
/// paper preset (heavy, non-proportional damping) the first round left an eigenvalue 1e-4 off
/// (pencil residual 2e-7); the repeated rounds bring every one to round-off (test
/// `damped_eigenvalues_are_roots_of_the_pencil`).
fn refine(
    kc: &DMatrix<Complex<f64>>,
    cc: &DMatrix<Complex<f64>>,
    l: Complex<f64>,
    start: DVector<Complex<f64>>,
    scale: f64,
) -> Result<(Complex<f64>, DVector<Complex<f64>>)> {
    let (mut lambda, mut x) = polish(kc, cc, l, start, scale)?;
    for _ in 0..5 {
        let (l2, x2) = polish(kc, cc, lambda, x.clone(), scale)?;
        let moved = (l2 - lambda).norm();
        lambda = l2;
        x = x2;
        if moved <= 1e-14 * scale {
            break;
        }
    }
    Ok((lambda, x))
}

/// Inverse iteration at a shift next to `l`, then the pencil's Rayleigh quotient. `kc`, `cc`:
/// the reduced stiffness and damping as complex matrices.
fn polish(
    kc: &DMatrix<Complex<f64>>,
    cc: &DMatrix<Complex<f64>>,
    l: Complex<f64>,
    start: DVector<Complex<f64>>,
    scale: f64,
) -> Result<(Complex<f64>, DVector<Complex<f64>>)> {
    let n = kc.nrows();
    let mut x = start;
    for attempt in 0..3 {
        let delta = 1e-7 * 10f64.powi(attempt) * l.norm().max(1e-6 * scale);
        let mu = l + Complex::new(delta, 0.5 * delta);
        let mut p = cc * mu + kc;
        let mut dp = cc.clone();
        for i in 0..n {
            p[(i, i)] += mu * mu;
            dp[(i, i)] += mu * 2.0;
        }
        let lu = p.lu();
        let mut ok = true;
        // Two steps: the shift is 1e-7 of |l| away from an eigenvalue accurate to ~1e-10, so
        // each step shrinks the other eigen-directions by the ratio of the distances.
        for _ in 0..2 {
            match lu.solve(&(&dp * &x)) {
                Some(y) => {
                    let nrm = y.norm();
                    if !(nrm.is_finite() && nrm > 0.0) {
                        ok = false;
                        break;
                    }
                    x = y / Complex::new(nrm, 0.0);
                }
                None => {
                    ok = false;
                    break;
                }
            }
        }
        if ok {
            let a: Complex<f64> = x.iter().map(|v| v.norm_sqr()).sum::<f64>().into();
            let b = x.dotc(&(cc * &x));
            let c = x.dotc(&(kc * &x));
            let disc = (b * b - a * c * 4.0).sqrt();
            let r1 = (-b + disc) / (a * 2.0);
            let r2 = (-b - disc) / (a * 2.0);
            let mut lambda = if (r1 - l).norm() <= (r2 - l).norm() {
                r1
            } else {
                r2
            };
            if !(lambda.re.is_finite() && lambda.im.is_finite()) {
                lambda = l;
            }
            return Ok((lambda, x));
        }
    }
    Err(RvdynError::Convergence(format!(
        "inverse iteration for the damped eigenvalue {l} failed"
    )))
}
