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
    /// Each matched mode's two eigenvalues (a conjugate pair or two real roots), the hint
    /// for the next point of a sweep.
    pub ends: Vec<(usize, [Complex<f64>; 2])>,
}

struct Candidate {
    lambda: Complex<f64>,
    x: DVector<Complex<f64>>,
    oscillatory: bool,
}

/// Below this smallest MAC of the greedy matching, the matching is redone by continuation.
const CONTINUATION_BELOW_MAC: f64 = 0.9;

/// The damped pairs of a sweep's previous point.
#[derive(Debug, Clone, PartialEq)]
pub struct DampedTrack {
    /// Each matched mode's two eigenvalues (a conjugate pair or two real roots) [1/s].
    pub pairs: Vec<(usize, [Complex<f64>; 2])>,
    /// The same at the point before (empty at a sweep's first point): with it the next
    /// point's pairs are extrapolated.
    pub before: Vec<(usize, [Complex<f64>; 2])>,
}

/// A pair's sum and squared difference: smooth where the pair meets on the real axis.
fn pair_invariants([a, b]: [Complex<f64>; 2]) -> [Complex<f64>; 2] {
    [a + b, (a - b) * (a - b)]
}

/// The pair with the sum and squared difference `[s, d]`.
fn pair_from_invariants([s, d]: [Complex<f64>; 2]) -> [Complex<f64>; 2] {
    let r = d.sqrt();
    [(s + r) * 0.5, (s - r) * 0.5]
}

/// Follow the damped eigenvalues of the flexible modes `omegas` (`(j, w_j)`) from `+-i w_j`
/// as the damping `alpha ct` grows from 0 to `ct`: at each step the 2n eigenvalues are
/// assigned one to one, nearest first, to the points predicted from each pair's sum and squared
/// difference extrapolated in `alpha` (smooth where the pair meets on the real axis; the first
/// step from first-order perturbation, `slopes[j] = y_j^T ct y_j`), and a step is halved until
/// every point's eigenvalue is nearer than a third of the distance to any eigenvalue another
/// mode holds (a pair that meets on the real axis and splits into two real roots stays with
/// its mode); the next step is sized from the accepted one's margin. This continuation defines which damped
/// solution belongs to which undamped mode (a path in another parameter can end on a different
/// assignment: eigenvalues of a non-symmetric problem can swap around an exceptional point).
/// Returns each mode's two eigenvalues at `alpha = 1`, or `None` when the step falls below
/// 1e-7 (modes that stay together, such as equal frequencies) or after 5000 steps.
fn continuation(
    kt: &DMatrix<f64>,
    ct: &DMatrix<f64>,
    s: f64,
    omegas: &[(usize, f64)],
    slopes: &[f64],
    tol_im: f64,
) -> Option<Vec<(usize, [Complex<f64>; 2])>> {
    let modes: Vec<usize> = omegas.iter().map(|&(j, _)| j).collect();
    let mut pts: Vec<Complex<f64>> = omegas
        .iter()
        .flat_map(|&(_, w)| [Complex::new(0.0, w), Complex::new(0.0, -w)])
        .collect();
    let mut prev: Option<(Vec<Complex<f64>>, f64)> = None;
    let mut prev2: Option<(Vec<Complex<f64>>, f64)> = None;
    let (mut alpha, mut h) = (0.0f64, 0.02f64);
    let mut steps = 0;
    while alpha < 1.0 {
        steps += 1;
        if steps > 5000 || h < 1e-7 {
            return None;
        }
        let h_try = h.min(1.0 - alpha);
        let e = state_eigenvalues(kt, &(ct * (alpha + h_try)), s).ok()?;
        // Each mode's pair through its sum and squared difference, which stay smooth where
        // the pair meets on the real axis and splits (the roots themselves move there like a
        // square root): extrapolated quadratically through the last three steps (linearly
        // from two), then the roots `(s +- sqrt(d)) / 2`.
        let invariants = |p: &[Complex<f64>]| -> Vec<[Complex<f64>; 2]> {
            p.chunks(2)
                .map(|ab| pair_invariants([ab[0], ab[1]]))
                .collect()
        };
        let now = invariants(&pts);
        let guess: Vec<[Complex<f64>; 2]> = match (&prev, &prev2) {
            (Some((p1, h1)), Some((p2, h2))) => {
                let (a1, a2) = (invariants(p1), invariants(p2));
                let (t0, t1, t) = (-(h1 + h2), -h1, h_try);
                let l0 = (t - t1) * t / ((t0 - t1) * t0);
                let l1 = (t - t0) * t / ((t1 - t0) * t1);
                let l2 = (t - t0) * (t - t1) / (t0 * t1);
                now.iter()
                    .zip(&a1)
                    .zip(&a2)
                    .map(|((c, b), a)| [0, 1].map(|i| a[i] * l0 + b[i] * l1 + c[i] * l2))
                    .collect()
            }
            (Some((p1, h1)), None) => now
                .iter()
                .zip(invariants(p1))
                .map(|(c, b)| [0, 1].map(|i| c[i] + (c[i] - b[i]) * (h_try / h1)))
                .collect(),
            // From zero damping: first-order perturbation of each undamped pair, whose sum
            // moves by `-alpha y^T ct y` and whose squared difference does not move.
            _ => now
                .iter()
                .zip(slopes)
                .map(|(c, sl)| [c[0] - h_try * sl, c[1]])
                .collect(),
        };
        let pred: Vec<Complex<f64>> = guess.into_iter().flat_map(pair_from_invariants).collect();
        let Some((next, worst)) = assign_with_margin(&pred, &e) else {
            h = 0.5 * h_try;
            continue;
        };
        prev2 = prev.take();
        prev = Some((std::mem::replace(&mut pts, next), h_try));
        alpha += h_try;
        // The prediction error grows like h^3 (quadratic extrapolation): aim at a margin of
        // 1/6, half the acceptance limit.
        let grow = if worst > 0.0 {
            0.9 * (1.0 / (6.0 * worst)).cbrt()
        } else {
            2.0
        };
        h = (h_try * grow.clamp(0.5, 2.0)).min(0.25);
    }
    Some(pair_up(&modes, &pts, tol_im))
}

/// The tracked points `pts` (two per mode, in the order of `modes`) as each mode's pair, with
/// imaginary parts within `tol_im` of zero set to zero.
fn pair_up(modes: &[usize], pts: &[Complex<f64>], tol_im: f64) -> Vec<(usize, [Complex<f64>; 2])> {
    let snap = |v: Complex<f64>| {
        if v.im.abs() <= tol_im {
            Complex::new(v.re, 0.0)
        } else {
            v
        }
    };
    modes
        .iter()
        .enumerate()
        .map(|(m, &j)| (j, [snap(pts[2 * m]), snap(pts[2 * m + 1])]))
        .collect()
}

/// One step of the tracking: the eigenvalues `e` assigned one to one, nearest first, to the
/// points `pred` (two per mode, consecutive), or `None` unless each point's eigenvalue is
/// nearer than a third of the distance to any eigenvalue another mode holds or none does
/// (rigid-body roots).
fn assign(pred: &[Complex<f64>], e: &[Complex<f64>]) -> Option<Vec<Complex<f64>>> {
    assign_with_margin(pred, e).map(|(v, _)| v)
}

/// As `assign`, also returning the largest ratio of a point's distance to its eigenvalue over
/// the distance to the nearest eigenvalue another mode holds (`assign` accepts up to 1/3).
fn assign_with_margin(
    pred: &[Complex<f64>],
    e: &[Complex<f64>],
) -> Option<(Vec<Complex<f64>>, f64)> {
    let mut pairs: Vec<(f64, usize, usize)> = Vec::with_capacity(pred.len() * e.len());
    for (i, p) in pred.iter().enumerate() {
        for (k, v) in e.iter().enumerate() {
            pairs.push(((p - v).norm(), i, k));
        }
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut of_point = vec![usize::MAX; pred.len()];
    let mut taken = vec![usize::MAX; e.len()];
    for (_, i, k) in pairs {
        if of_point[i] == usize::MAX && taken[k] == usize::MAX {
            of_point[i] = k;
            taken[k] = i;
        }
    }
    if of_point.contains(&usize::MAX) {
        return None;
    }
    let mut worst = 0.0f64;
    for (i, p) in pred.iter().enumerate() {
        let d1 = (p - e[of_point[i]]).norm();
        let d2 = e
            .iter()
            .enumerate()
            .filter(|&(k, _)| taken[k] == usize::MAX || taken[k] / 2 != i / 2)
            .map(|(_, v)| (p - v).norm())
            .fold(f64::INFINITY, f64::min);
        worst = worst.max(if d1 == 0.0 { 0.0 } else { d1 / d2 });
    }
    (worst <= 1.0 / 3.0).then(|| (of_point.iter().map(|&k| e[k]).collect(), worst))
}

/// The candidates' owners from the continuation's end points: a conjugate pair gives its
/// upper eigenvalue's candidate, two real roots their two candidates (nearest, each once).
/// `None` if an end point has no candidate of its kind left.
fn owners_from_ends(
    cands: &[Candidate],
    ends: &[(usize, [Complex<f64>; 2])],
    shapes: &[DVector<f64>],
    mac: &dyn Fn(&Candidate, &DVector<f64>) -> f64,
) -> Option<Vec<Option<(usize, f64)>>> {
    let mut owner: Vec<Option<(usize, f64)>> = vec![None; cands.len()];
    for &(j, [a, b]) in ends {
        let wanted: Vec<Complex<f64>> = if a.im != 0.0 || b.im != 0.0 {
            vec![if a.im >= b.im { a } else { b }]
        } else {
            vec![a, b]
        };
        for w in wanted {
            let oscillatory = w.im != 0.0;
            let ci = cands
                .iter()
                .enumerate()
                .filter(|(ci, c)| c.oscillatory == oscillatory && owner[*ci].is_none())
                .min_by(|x, y| (x.1.lambda - w).norm().total_cmp(&(y.1.lambda - w).norm()))?
                .0;
            owner[ci] = Some((j, mac(&cands[ci], &shapes[j])));
        }
    }
    Some(owner)
}

/// Damped eigenvalues of the reduced system, matched to the undamped reduced shapes
/// `shapes` (unit vectors, by increasing `w^2`; `lam_max` the largest `|w^2|`).
pub(super) fn damped_modes(
    kt: &DMatrix<f64>,
    ct: &DMatrix<f64>,
    lam_max: f64,
    shapes: &[DVector<f64>],
    hint: Option<&DampedTrack>,
) -> Result<DampedSet> {
    let n = kt.nrows();
    let s = if lam_max > 0.0 {
        lam_max.sqrt()
    } else {
        ct.norm().max(1.0)
    };
    let raw = state_eigenvalues(kt, ct, s)?;
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
        let (lambda, x) = refine(&kc, &cc, *l, start, scale, reach(&raw, *l))?;
        cands.push(Candidate {
            lambda,
            x,
            oscillatory: true,
        });
    }
    for l in &real {
        let (lambda, x) = refine(&kc, &cc, *l, generic_start(n), scale, reach(&raw, *l))?;
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

    // The greedy MAC matching can pair a damped solution with the wrong undamped mode under
    // heavy non-proportional damping (the shapes turn). When any match is uncertain, follow
    // every flexible mode from i w_j as the damping grows from 0 to C instead.
    let min_mac = owner.iter().flatten().fold(1.0f64, |a, (_, m)| a.min(*m));
    if min_mac < CONTINUATION_BELOW_MAC {
        let omegas: Vec<(usize, f64)> = shapes
            .iter()
            .enumerate()
            .filter_map(|(j, y)| {
                let w2 = y.dot(&(kt * y));
                (w2 > 1e-10 * lam_max).then(|| (j, w2.sqrt()))
            })
            .collect();
        // A sweep's previous point (the same modes at a nearby torque or crank angle) is
        // one tracking step away; the continuation from zero damping otherwise.
        let flexible: Vec<usize> = omegas.iter().map(|&(j, _)| j).collect();
        // A sweep's previous point (the same modes at a nearby torque or crank angle): when
        // its pairs are each clearly nearest to two of these eigenvalues, the continuation
        // would end there too; otherwise it is run.
        let from_hint = hint.and_then(|h| {
            let modes: Vec<usize> = h.pairs.iter().map(|&(j, _)| j).collect();
            if modes != flexible {
                return None;
            }
            // Extrapolated from the two points before when the sweep has them.
            let same = h.before.iter().map(|&(j, _)| j).eq(modes.iter().copied());
            let pts: Vec<Complex<f64>> = if same {
                h.pairs
                    .iter()
                    .zip(&h.before)
                    .flat_map(|(&(_, p), &(_, q))| {
                        let (a, b) = (pair_invariants(p), pair_invariants(q));
                        pair_from_invariants([0, 1].map(|i| a[i] * 2.0 - b[i]))
                    })
                    .collect()
            } else {
                h.pairs.iter().flat_map(|&(_, p)| p).collect()
            };
            assign(&pts, &raw).map(|next| pair_up(&modes, &next, tol_im))
        });
        let slopes: Vec<f64> = omegas
            .iter()
            .map(|&(j, _)| shapes[j].dot(&(ct * &shapes[j])))
            .collect();
        let ends = from_hint.or_else(|| continuation(kt, ct, s, &omegas, &slopes, tol_im));
        if let Some(o) = ends.and_then(|e| owners_from_ends(&cands, &e, shapes, &mac)) {
            owner = o;
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
    let mut ends = Vec::with_capacity(matched.len());
    for (j, _) in &matched {
        let mine: Vec<&Candidate> = owner
            .iter()
            .zip(&cands)
            .filter_map(|(o, c)| o.filter(|(jj, _)| jj == j).map(|_| c))
            .collect();
        match mine.as_slice() {
            [c] if c.oscillatory => ends.push((*j, [c.lambda, c.lambda.conj()])),
            [a, b] => ends.push((*j, [a.lambda, b.lambda])),
            _ => {}
        }
    }
    Ok(DampedSet {
        matched,
        all,
        unmatched,
        ends,
    })
}

/// The 2n eigenvalues of `y'' + ct y' + kt y = 0` from the real Schur form of the state matrix
/// `[[0, s I], [-kt/s, -ct]]` (`s` a velocity scale; the eigenvalues do not depend on it),
/// unpolished.
fn state_eigenvalues(kt: &DMatrix<f64>, ct: &DMatrix<f64>, s: f64) -> Result<Vec<Complex<f64>>> {
    let n = kt.nrows();
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
    raw.ok_or_else(|| {
        RvdynError::Convergence(
            "the Schur iteration for the damped eigenvalues did not converge".into(),
        )
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
    reach: f64,
) -> Result<(Complex<f64>, DVector<Complex<f64>>)> {
    let (mut lambda, mut x) = polish(kc, cc, l, start, scale)?;
    // The Rayleigh quotient can jump to a neighbouring eigenvalue (heavy, non-proportional
    // damping): a polished value must stay nearer its Schur value than any other Schur value
    // is, or the Schur value (accurate to about 1e-10) is kept.
    if (lambda - l).norm() > reach {
        return Ok((l, x));
    }
    for _ in 0..5 {
        let (l2, x2) = polish(kc, cc, lambda, x.clone(), scale)?;
        if (l2 - l).norm() > reach {
            break;
        }
        let moved = (l2 - lambda).norm();
        lambda = l2;
        x = x2;
        if moved <= 1e-14 * scale {
            break;
        }
    }
    Ok((lambda, x))
}

/// A third of the distance from the Schur value `l` to the nearest other one of `raw` (the
/// whole spectrum): how far polishing may move it.
fn reach(raw: &[Complex<f64>], l: Complex<f64>) -> f64 {
    // The nearest is `l` itself (a real one stored with its imaginary round-off set to 0).
    let (mut first, mut second) = (f64::INFINITY, f64::INFINITY);
    for v in raw {
        let d = (v - l).norm();
        if d < first {
            second = first;
            first = d;
        } else if d < second {
            second = d;
        }
    }
    second / 3.0
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
