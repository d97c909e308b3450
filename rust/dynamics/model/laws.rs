//! The force laws of the model, each family evaluated in one place: the contact law of a
//! penetration (pins, meshes) and the law of a bearing. New families (roller bearings,
//! friction, ISO mesh stiffness, line contact) are new variants here; the models call only
//! these methods.

use crate::contact::ImpactLaw;
use crate::dynamics::model::vec2::dot;
use crate::dynamics::scene::{Bearing, ContactLawSpec};
use crate::error::Result;

/// The normal force law of a contact with penetration `x` [m] and penetration rate [m/s].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ContactLaw {
    /// `F = k x^e + STEP(x, 0, 0, d, cmax) xdot`, `F >= 0` (ADAMS IMPACT; the Palmgren line
    /// contact of the scene is this law with `e = 10/9`): docs/model.md#contact-laws.
    Impact(ImpactLaw),
}

impl ContactLaw {
    /// The law a scene specifies for a contact of length `face_width` [m].
    pub fn from_spec(spec: &ContactLawSpec, face_width: f64) -> Result<Self> {
        Ok(ContactLaw::Impact(spec.law(face_width)?))
    }

    /// Normal force [N] (>= 0) at penetration `x` [m] (> 0) and rate `rate` [m/s].
    #[inline]
    pub fn force(&self, x: f64, rate: f64) -> f64 {
        match self {
            ContactLaw::Impact(l) => l.force(x, rate),
        }
    }

    /// The elastic (conservative) part of the force [N].
    #[inline]
    pub fn elastic_force(&self, x: f64) -> f64 {
        match self {
            ContactLaw::Impact(l) => l.elastic_force(x),
        }
    }

    /// Elastic energy stored at penetration `x` [J].
    #[inline]
    pub fn elastic_energy(&self, x: f64) -> f64 {
        match self {
            ContactLaw::Impact(l) => l.elastic_energy(x),
        }
    }

    /// A mesh with total backlash `backlash` [m] along the line of action at deflection
    /// `delta` [m] (positive on the drive flank) and rate `rate` [m/s]: the signed force [N]
    /// (negative on the coast flank), its signed elastic part, the penetration [m] (0 inside
    /// the backlash) and the penetration rate [m/s].
    #[inline]
    pub fn mesh(&self, backlash: f64, delta: f64, rate: f64) -> (f64, f64, f64, f64) {
        let half = 0.5 * backlash;
        if delta > half {
            let p = delta - half;
            (self.force(p, rate), self.elastic_force(p), p, rate)
        } else if delta < -half {
            let p = -delta - half;
            (-self.force(p, -rate), -self.elastic_force(p), p, -rate)
        } else {
            (0.0, 0.0, 0.0, 0.0)
        }
    }
}

/// Force of one bearing and its energy flows.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct BearingLoad {
    /// Force on the body at the `+` end of the deflection `d` [N] (the other body gets the
    /// opposite).
    pub force: [f64; 2],
    /// Power dissipated by the damper [W] (>= 0).
    pub dissipation: f64,
    /// Elastic energy of the spring [J].
    pub energy: f64,
}

/// The radial law of a bearing (docs/model.md#compliant-joint-model).
#[derive(Debug, Clone, PartialEq)]
pub enum BearingLaw {
    /// Linear spring-damper with an optional radial clearance: no force inside the clearance,
    /// `F = (k pen + c pen') n` (>= 0) beyond it.
    Linear(Bearing),
    /// Roller bearing built from its rollers (`bearing::RollerBearing`, Palmgren per roller)
    /// with per-roller stiffness-proportional damping `beta` [s].
    Rollers {
        /// The rollers and the clearance.
        bearing: crate::bearing::RollerBearing,
        /// Damping factor of each roller [s].
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

    /// The load for a deflection `d` [m] and its rate `dd` [m/s].
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
