//! The radial force laws of the bearings ([`BearingLaw`], [`linear_bearing`]) used by the
//! models and the quasi-static analysis. The pin and mesh contact laws are in
//! [`crate::contact::law`].

use crate::dynamics::model::vec2::dot;
use crate::dynamics::scene::Bearing;
use crate::error::Result;

/// Force of one bearing and its energy flows.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct BearingLoad {
    /// Force on the body at the `+` end of the deflection `d` \[N\] (the other body gets the
    /// opposite).
    pub force: [f64; 2],
    /// Power dissipated by the damper \[W\] (>= 0).
    pub dissipation: f64,
    /// Elastic energy of the spring \[J\].
    pub energy: f64,
}

/// The radial law of a bearing (docs/model.md#compliant-joint-model).
#[derive(Debug, Clone, PartialEq)]
pub enum BearingLaw {
    /// Linear spring-damper with an optional radial clearance: no force inside the clearance,
    /// `F = (k pen + c pen') n` (>= 0) beyond it.
    Linear(Bearing),
    /// Roller bearing built from its rollers (`bearing::RollerBearing`, Palmgren per roller)
    /// with per-roller stiffness-proportional damping `beta` \[s\].
    Rollers {
        /// The rollers and the clearance.
        bearing: crate::bearing::RollerBearing,
        /// Damping factor of each roller \[s\].
        beta: f64,
        /// The scene bearing: its `stiffness` and `damping` act in parallel (0 for none).
        parallel: Bearing,
    },
}

impl BearingLaw {
    /// The law of a scene bearing. Errors as [`crate::bearing::RollerBearing::new`].
    pub fn new(b: &Bearing) -> Result<Self> {
        Ok(match &b.rollers {
            None => BearingLaw::Linear(*b),
            Some(r) => BearingLaw::Rollers {
                bearing: r.bearing(b.clearance)?,
                beta: r.beta(),
                parallel: *b,
            },
        })
    }

    /// The load for a deflection `d` \[m\] and its rate `dd` [m/s].
    #[inline]
    pub fn load(&self, d: [f64; 2], dd: [f64; 2]) -> BearingLoad {
        match self {
            BearingLaw::Linear(b) => linear_bearing(b, d, dd),
            BearingLaw::Rollers {
                bearing,
                beta,
                parallel,
            } => {
                let r = bearing.damped_force(d, dd, *beta);
                let mut out = BearingLoad {
                    force: r.force,
                    dissipation: r.dissipation,
                    energy: r.energy,
                };
                if parallel.stiffness > 0.0 || parallel.damping > 0.0 {
                    let l = linear_bearing(parallel, d, dd);
                    out.force = [out.force[0] + l.force[0], out.force[1] + l.force[1]];
                    out.dissipation += l.dissipation;
                    out.energy += l.energy;
                }
                out
            }
        }
    }
}

impl BearingLaw {
    /// Static tangent of the bearing at deflection `d` \[m\] and zero rate: the gradient of its
    /// potential `dV/dd` \[N\] (minus the force on the `+` body) and its Hessian `hess_d V`
    /// [N/m]: `F n` and `F' n n^T + (F/|d|)(I - n n^T)` for the radial law `F(|d| - c)` along
    /// `n = d/|d|`, `k d` and `k I` without clearance (docs/model.md, quasi-static analysis).
    #[inline]
    pub fn static_tangent(&self, d: [f64; 2]) -> ([f64; 2], [[f64; 2]; 2]) {
        match self {
            BearingLaw::Rollers {
                bearing, parallel, ..
            } => {
                // Each roller j is compressed by delta_j = d . n_j - c along its fixed
                // direction n_j, linear in d: hess V = sum_j Q_j'(delta_j) n_j n_j^T, no
                // geometric term (Harris & Kotzalas 2007, ch. 7; docs/model.md).
                let st = bearing.state(d, 0.0);
                let (mut g, mut h) = ([-st.force[0], -st.force[1]], st.stiffness);
                if parallel.stiffness > 0.0 {
                    let (gl, hl) = BearingLaw::Linear(*parallel).static_tangent(d);
                    for a in 0..2 {
                        g[a] += gl[a];
                        for c in 0..2 {
                            h[a][c] += hl[a][c];
                        }
                    }
                }
                (g, h)
            }
            BearingLaw::Linear(b) => {
                if b.clearance <= 0.0 {
                    let k = b.stiffness;
                    return ([k * d[0], k * d[1]], [[k, 0.0], [0.0, k]]);
                }
                let len = dot(d, d).sqrt();
                let pen = len - b.clearance;
                if pen <= 0.0 {
                    return ([0.0; 2], [[0.0; 2]; 2]);
                }
                let (f, fp) = (b.stiffness * pen, b.stiffness);
                let n = [d[0] / len, d[1] / len];
                let t = f / len;
                let mut h = [[0.0; 2]; 2];
                for (a, row) in h.iter_mut().enumerate() {
                    for (c, v) in row.iter_mut().enumerate() {
                        let id = if a == c { 1.0 } else { 0.0 };
                        *v = fp * n[a] * n[c] + t * (id - n[a] * n[c]);
                    }
                }
                ([f * n[0], f * n[1]], h)
            }
        }
    }

    /// Damping matrix `dF/dd'` [N s/m] at deflection `d` and zero rate: `c I` without
    /// clearance, `c n n^T` beyond it, 0 inside.
    #[inline]
    pub fn damping_matrix(&self, d: [f64; 2]) -> [[f64; 2]; 2] {
        match self {
            BearingLaw::Rollers {
                bearing,
                beta,
                parallel,
            } => {
                // Roller j damps with beta Q_j' along n_j: C = beta K (stiffness-proportional
                // per roller, `RollerBearing::damped_force`).
                let k = bearing.state(d, 0.0).stiffness;
                let mut c = [[0.0; 2]; 2];
                for a in 0..2 {
                    for b in 0..2 {
                        c[a][b] = beta * k[a][b];
                    }
                }
                if parallel.damping > 0.0 {
                    let cl = BearingLaw::Linear(*parallel).damping_matrix(d);
                    for a in 0..2 {
                        for b in 0..2 {
                            c[a][b] += cl[a][b];
                        }
                    }
                }
                c
            }
            BearingLaw::Linear(b) => {
                if b.clearance <= 0.0 {
                    return [[b.damping, 0.0], [0.0, b.damping]];
                }
                let len = dot(d, d).sqrt();
                if len <= b.clearance {
                    return [[0.0; 2]; 2];
                }
                let n = [d[0] / len, d[1] / len];
                [
                    [b.damping * n[0] * n[0], b.damping * n[0] * n[1]],
                    [b.damping * n[1] * n[0], b.damping * n[1] * n[1]],
                ]
            }
        }
    }
}

/// The linear bearing law (see [`BearingLaw::Linear`]).
#[inline]
pub fn linear_bearing(b: &Bearing, d: [f64; 2], dd: [f64; 2]) -> BearingLoad {
    if b.clearance <= 0.0 {
        let f = [
            -b.stiffness * d[0] - b.damping * dd[0],
            -b.stiffness * d[1] - b.damping * dd[1],
        ];
        return BearingLoad {
            force: f,
            dissipation: b.damping * dot(dd, dd),
            energy: 0.5 * b.stiffness * dot(d, d),
        };
    }
    let dist = dot(d, d).sqrt();
    if dist <= b.clearance {
        return BearingLoad::default();
    }
    let n = [d[0] / dist, d[1] / dist];
    let pen = dist - b.clearance;
    let rate = dot(n, dd);
    let elastic = b.stiffness * pen;
    let f = (elastic + b.damping * rate).max(0.0);
    BearingLoad {
        force: [-f * n[0], -f * n[1]],
        dissipation: (f - elastic) * rate,
        energy: 0.5 * b.stiffness * pen * pen,
    }
}
