//! The static forces and tangent stiffness in the unknowns `q` (the chain rule through the map
//! `x = x(q)`), their reductions and the reactions of the held input.

use super::vec2::{cos_sin, dot, perp, rotate};
use super::{CARRIER, ContactState, Dense, Kind, SUN, Statics};
use crate::error::Result;

impl Statics {
    /// Static forces `r` and tangent stiffness `k = -dQ/dq` in the unknowns `q` at crank angle
    /// `psi` with the input held, for the output torque `torque` [N m].
    #[allow(clippy::too_many_arguments)]
    pub fn eval(
        &mut self,
        psi: f64,
        q: &[f64],
        torque: f64,
        r: &mut [f64],
        k: &mut Dense,
        work: &mut Work,
        state: Option<&mut ContactState>,
    ) -> Result<()> {
        let mut x = std::mem::take(&mut work.x);
        self.full_into(psi, q, &mut x);
        let nf = x.len();
        if work.kf.n != nf {
            work.kf = Dense::zeros(nf);
            work.qf = vec![0.0; nf];
        }
        let (qf, kf) = (&mut work.qf, &mut work.kf);
        let res = self.full_forces(&x, torque, qf, kf, state);
        work.x = x;
        res?;
        let x = &work.x;
        let m = &self.model;
        let n = self.dim();
        // Jacobian columns of the map (sparse: list of (full index, value) per unknown) and
        // the curvature terms sum_r Q_r hess(x_r).
        // Reuse the column vectors (no allocation per evaluation).
        work.jac.resize_with(n, Vec::new);
        for c in work.jac.iter_mut() {
            c.clear();
        }
        let thc = x[CARRIER];
        let u0 = cos_sin(thc);
        let seat = |i: usize| rotate(u0, self.seat_vecs[i]);
        let slaved_cranks = match self.kind {
            Kind::Rigid => true,
            Kind::Compliant => self.crank_bearing.is_none(),
        };
        match self.kind {
            Kind::Rigid => {
                // dx/dth_c of the rigid-joint map: the carrier and every disc angle turn one
                // for one, each crank seat moves along z x s_i.
                let col = &mut work.jac[0];
                col.push((CARRIER, 1.0));
                for k in 0..m.discs.len() {
                    col.push((self.disc_index(k) + 2, 1.0));
                }
                for i in 0..self.cranks {
                    let ps = perp(seat(i));
                    let ci = self.crank_index(i);
                    col.push((ci, ps[0]));
                    col.push((ci + 1, ps[1]));
                }
                if m.mesh.is_some() {
                    let col = &mut work.jac[1];
                    for i in 0..self.cranks {
                        col.push((self.crank_index(i) + 2, 1.0));
                    }
                    for k in 0..m.discs.len() {
                        let dk = self.disc_index(k);
                        col.push((dk, -x[dk + 1]));
                        col.push((dk + 1, x[dk]));
                    }
                }
            }
            Kind::Compliant => {
                for (a, &i) in self.unknowns.iter().enumerate() {
                    let col = &mut work.jac[a];
                    col.push((i, 1.0));
                    if i == CARRIER && slaved_cranks {
                        for c in 0..self.cranks {
                            let ps = perp(seat(c));
                            let ci = self.crank_index(c);
                            col.push((ci, ps[0]));
                            col.push((ci + 1, ps[1]));
                        }
                    }
                }
            }
        }
        for (a, col) in work.jac.iter().enumerate() {
            r[a] = col.iter().map(|&(i, v)| v * qf[i]).sum();
        }
        // A column that is one full coordinate with weight 1 takes its entries as they are.
        let single = |c: &[(usize, f64)]| match c {
            [(i, v)] if *v == 1.0 => Some(*i),
            _ => None,
        };
        let mut singles = std::mem::take(&mut work.singles);
        singles.clear();
        singles.extend(work.jac.iter().map(|c| single(c)));
        let nf = kf.n;
        for a in 0..n {
            let ja = &work.jac[a];
            let sa = singles[a];
            if let Some(i) = sa {
                // A row of single columns: the entries of row i of K_x as they are.
                let row = &kf.a[i * nf..i * nf + nf];
                let out = &mut k.a[a * n..a * n + n];
                if singles.iter().zip(out.iter_mut()).all(|(sb, o)| match sb {
                    Some(j) => {
                        *o = row[*j];
                        true
                    }
                    None => false,
                }) {
                    continue;
                }
            }
            for (b, (jb, sb)) in work.jac.iter().zip(&singles).enumerate() {
                k.a[a * n + b] = match (sa, *sb) {
                    (Some(i), Some(j)) => kf.at(i, j),
                    _ => {
                        let mut s = 0.0;
                        for &(i, vi) in ja {
                            for &(j, vj) in jb {
                                s += vi * kf.at(i, j) * vj;
                            }
                        }
                        s
                    }
                };
            }
        }
        work.singles = singles;
        // Curvature of the map: slaved crank centres p_i = s_i(th_c) (hess = -s_i) and, for
        // rigid joints, disc centres O_k(alpha) (hess = -O_k).
        if slaved_cranks {
            let mut extra = 0.0;
            for i in 0..self.cranks {
                let ci = self.crank_index(i);
                extra += dot([qf[ci], qf[ci + 1]], seat(i));
            }
            k.a[0] += extra;
        }
        if self.kind == Kind::Rigid && m.mesh.is_some() {
            let mut extra = 0.0;
            for k in 0..m.discs.len() {
                let dk = self.disc_index(k);
                extra += qf[dk] * x[dk] + qf[dk + 1] * x[dk + 1];
            }
            k.a[n + 1] += extra;
        }
        Ok(())
    }

    /// A fresh [`Statics::eval`] at `q` into new buffers: the residual \[N\], the tangent and the
    /// contact state. With `every_pin`, no pin is skipped by the separation bound (exact gaps
    /// of every pin, as a report needs).
    pub fn eval_fresh(
        &mut self,
        psi: f64,
        q: &[f64],
        torque: f64,
        work: &mut Work,
        every_pin: bool,
    ) -> Result<(Vec<f64>, Dense, ContactState)> {
        let n = self.dim();
        let mut r = vec![0.0; n];
        let mut k = Dense::zeros(n);
        let mut cs = ContactState::default();
        let before = self.exact;
        self.exact = every_pin || before;
        let evaluated = self.eval(psi, q, torque, &mut r, &mut k, work, Some(&mut cs));
        self.exact = before;
        evaluated?;
        Ok((r, k, cs))
    }

    /// `out = J^T v` of a full-coordinate force `v` with the map Jacobian of the last
    /// [`Statics::eval`] (the friction forces of `ltca::friction`).
    pub fn reduce_force(&self, v: &[f64], work: &Work, out: &mut [f64]) {
        for (o, col) in out.iter_mut().zip(&work.jac) {
            *o = col.iter().map(|&(i, c)| c * v[i]).sum();
        }
    }

    /// `J^T A J` of a full-coordinate matrix `a` with the map Jacobian of the last
    /// [`Statics::eval`] (velocities map linearly: no curvature terms).
    pub fn reduce(&self, a: &Dense, work: &Work) -> Dense {
        let n = self.dim();
        let mut out = Dense::zeros(n);
        for p in 0..n {
            for b in 0..n {
                let mut s = 0.0;
                for &(i, vi) in &work.jac[p] {
                    for &(j, vj) in &work.jac[b] {
                        s += vi * a.at(i, j) * vj;
                    }
                }
                out.a[p * n + b] = s;
            }
        }
        out
    }

    /// The torque [N m] held cranks of a single stage with rigid joints carry against the
    /// generalised forces `qf` on the discs at the full coordinates `x`: the disc centres ride
    /// on the eccentrics, `dO_k/dpsi = z x O_k`, and the cranks carry minus the forces'
    /// virtual work on them.
    pub(crate) fn held_cranks_reaction(&self, qf: &[f64], x: &[f64]) -> f64 {
        -(0..self.model.discs.len())
            .map(|k| {
                let dk = self.disc_index(k);
                -qf[dk] * x[dk + 1] + qf[dk + 1] * x[dk]
            })
            .sum::<f64>()
    }

    /// The torque the held input carries [N m] (the reaction that holds it): minus the
    /// generalised force on the input coordinates in the last full evaluation.
    pub fn input_reaction(&self, work: &Work) -> f64 {
        if self.model.mesh.is_some() {
            -work.qf[SUN]
        } else if self.kind == Kind::Rigid {
            // Rigid joints: the disc forces never reach the crank coordinates.
            self.held_cranks_reaction(&work.qf, &work.x)
        } else {
            -(0..self.cranks)
                .map(|i| work.qf[self.crank_index(i) + 2])
                .sum::<f64>()
        }
    }
}

/// Scratch space of [`Statics::eval`].
#[derive(Debug, Clone)]
pub struct Work {
    /// Generalised forces in the full coordinates at the last evaluation.
    pub qf: Vec<f64>,
    /// Tangent stiffness in the full coordinates at the last evaluation.
    pub kf: Dense,
    /// Tangent stiffness in the unknowns at the last equilibrium found.
    pub k_last: Dense,
    jac: Vec<Vec<(usize, f64)>>,
    /// Per Jacobian column, the full coordinate it is when it is one with weight 1.
    singles: Vec<Option<usize>>,
    /// Full coordinates of the last evaluation.
    x: Vec<f64>,
}

impl Work {
    /// Empty scratch space (sized on first use).
    pub fn new() -> Self {
        Self {
            qf: Vec::new(),
            kf: Dense::zeros(0),
            k_last: Dense::zeros(0),
            jac: Vec::new(),
            singles: Vec::new(),
            x: Vec::new(),
        }
    }
}

impl Default for Work {
    fn default() -> Self {
        Self::new()
    }
}
