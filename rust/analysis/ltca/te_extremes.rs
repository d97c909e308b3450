//! The extremes of a transmission-error sweep, located between its crank angles.
//!
//! A sweep samples the TE; its peak-to-peak is that of the samples, which falls short of the
//! curve's wherever a peak lies between two of them. On the physical preset the TE peaks at
//! the end of an ISO mesh stiffness ramp (2.9e-3 rad of crank angle, against a grid step of
//! 6.7e-2 rad at 90 angles per period): a corner, approached steeply from one side, so the
//! sampled peak-to-peak converges only linearly in the step (-1.7 % at 90 angles, -0.2 % at
//! 2880). Here each sampled local maximum (and minimum) that could pass the best sample is
//! searched on nested grids down to a crank-angle step of `STOP` of the period
//! (docs/model.md, "Transmission error").

use super::{Ltca, Solved};
use crate::error::Result;
use serde::Serialize;

/// At most this many sampled local extremes refined per curve and per sense (largest first).
const CANDIDATES: usize = 12;
/// Points per side and level of the nested grids: each level divides the step by this.
const SUBDIVISIONS: usize = 4;
/// The refinement stops at this crank-angle step, relative to the mesh period.
const STOP: f64 = 1e-6;
/// A point solved again along another path is the same equilibrium within this fraction of
/// the curve's sampled peak-to-peak plus `SAME_FLOOR` \[rad\] (loaded equilibria repeat within
/// 1e-10 of it; at the light load of the unloaded TE, where bodies float in their
/// clearances, within 2.5e-3 at 1e-6 of the rated torque and by up to a tenth at 1e-8).
const SAME_PATH: f64 = 1e-2;
const SAME_FLOOR: f64 = 1e-12;

/// A curve's extreme: crank angle \[rad\] and TE \[rad\].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Extreme {
    /// Crank angle \[rad\].
    pub crank_angle: f64,
    /// TE there \[rad\].
    pub value: f64,
}

/// The largest and smallest TE of one curve.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CurveExtremes {
    /// Largest TE.
    pub max: Extreme,
    /// Smallest TE.
    pub min: Extreme,
    /// Whether they were located between the samples (false: the samples' own, because the
    /// equilibria depend on the path to them; docs/model.md, "Transmission error").
    pub refined: bool,
}

impl CurveExtremes {
    /// `max - min` \[rad\].
    pub fn peak_to_peak(&self) -> f64 {
        self.max.value - self.min.value
    }
}

/// One solved crank angle of a sweep: its TE and the state that warm-starts its neighbours.
#[derive(Debug, Clone)]
pub(super) struct Sample {
    pub psi: f64,
    pub te: f64,
    pub solved: Solved,
}

impl Ltca {
    /// TE at `psi` under `torque`, warm-started from the history, with the solved state.
    pub(super) fn te_sample(&mut self, torque: f64, psi: f64) -> Result<Sample> {
        let (out, _) = self.output_angle(torque, psi)?;
        let input = if self.statics.model.mesh.is_some() {
            self.statics.held_input(psi)
        } else {
            psi
        };
        let solved = self.history.first().cloned().ok_or_else(|| {
            crate::error::RvdynError::Convergence("no equilibrium kept after a solve".into())
        })?;
        Ok(Sample {
            psi,
            te: out - input / self.ratio,
            solved,
        })
    }

    /// The largest and smallest TE of the sweep `samples` (equally spaced by `step` \[rad\],
    /// solved in that order) under `torque`, each refined between the samples: at most
    /// `CANDIDATES` sampled local extremes that could pass the best sample are searched on
    /// nested grids, each level `2 SUBDIVISIONS - 1` crank angles at `1 / SUBDIVISIONS` of the
    /// last step from one step before the best to one step after it, continued in the sweep's
    /// direction from the solution one step before, down to the step `STOP` times `period`.
    /// Never worse than the samples (they are among the points). Where a crank angle solved
    /// again along this path gives another equilibrium (bodies floating in their clearances at
    /// a very light load), the sampled extremes are returned, with `refined` false.
    pub(super) fn refine_extremes(
        &mut self,
        torque: f64,
        samples: &[Sample],
        step: f64,
        period: f64,
    ) -> Result<CurveExtremes> {
        let Some(first) = samples.first() else {
            return Err(crate::error::RvdynError::Parameter(
                "transmission error extremes need at least one crank angle".into(),
            ));
        };
        let max = self.refine_sense(torque, samples, step, period, 1.0)?;
        let min = match max {
            Some(_) => self.refine_sense(torque, samples, step, period, -1.0)?,
            None => None,
        };
        self.reset();
        Ok(match (max, min) {
            (Some(max), Some(min)) => CurveExtremes {
                max,
                min,
                refined: true,
            },
            _ => {
                let pick = |sense: f64| {
                    let s = samples
                        .iter()
                        .max_by(|x, y| (sense * x.te).total_cmp(&(sense * y.te)))
                        .unwrap_or(first);
                    Extreme {
                        crank_angle: s.psi,
                        value: s.te,
                    }
                };
                CurveExtremes {
                    max: pick(1.0),
                    min: pick(-1.0),
                    refined: false,
                }
            }
        })
    }

    /// [`Ltca::refine_extremes`] for the largest `sense * TE` (`sense` = 1 or -1); `None`
    /// when the equilibria depend on the path to them.
    fn refine_sense(
        &mut self,
        torque: f64,
        samples: &[Sample],
        step: f64,
        period: f64,
        sense: f64,
    ) -> Result<Option<Extreme>> {
        let n = samples.len();
        let v = |i: usize| sense * samples[i].te;
        // Local extremes of the periodic sampled curve that could pass the best sample: a peak
        // within a step of sample `i` (rising towards it no faster than from a neighbour, as
        // to a corner or a smooth maximum) rises above it by at most its larger drop to a
        // neighbour. Best first.
        let top = (0..n).map(v).fold(f64::NEG_INFINITY, f64::max);
        let mut candidates: Vec<usize> = (0..n)
            .filter(|&i| {
                let (a, b) = (v((i + n - 1) % n), v((i + 1) % n));
                v(i) >= a && v(i) >= b && v(i) + (v(i) - a).max(v(i) - b) >= top
            })
            .collect();
        candidates.sort_by(|&a, &b| v(b).total_cmp(&v(a)));
        candidates.truncate(CANDIDATES);
        let (lo, hi) = samples
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), s| {
                (a.min(s.te), b.max(s.te))
            });
        let same = SAME_PATH * (hi - lo) + SAME_FLOOR;
        let Some(&first) = candidates.first() else {
            return Ok(None);
        };
        let mut best = Extreme {
            crank_angle: samples[first].psi,
            value: samples[first].te,
        };
        for &i in &candidates {
            // Continued from the sample before, in the sweep's direction; the first sample's
            // neighbourhood as the period's end (the TE is periodic), from the last sample.
            let before = &samples[(i + n - 1) % n];
            let centre = Sample {
                psi: before.psi + step,
                te: samples[i].te,
                solved: samples[i].solved.clone(),
            };
            let wrapped = i == 0;
            let Some(mut found) =
                self.refine_one(torque, before, &centre, step, period, sense, same, wrapped)?
            else {
                return Ok(None);
            };
            if found.crank_angle >= samples[0].psi + period - 0.5 * step {
                found.crank_angle -= period;
            }
            if sense * found.value > sense * best.value {
                best = found;
            }
        }
        Ok(Some(best))
    }

    /// Nested grids around `centre` continued from `before` (see [`Ltca::refine_extremes`]);
    /// `None` if the centre solved again on the way differs from it by more than `same` \[rad\].
    #[allow(clippy::too_many_arguments)]
    fn refine_one(
        &mut self,
        torque: f64,
        before: &Sample,
        centre: &Sample,
        step: f64,
        period: f64,
        sense: f64,
        same: f64,
        wrapped: bool,
    ) -> Result<Option<Extreme>> {
        let mut start = before.clone();
        let mut best = centre.clone();
        let mut h = step;
        while h > STOP * period {
            let sub = h / SUBDIVISIONS as f64;
            // From the point one step before the best to one sub-step short of the point one
            // step after it, each warm-started from the one before.
            self.history.clear();
            self.history.push(start.solved.clone());
            let mut chain = Vec::with_capacity(2 * SUBDIVISIONS - 1);
            for j in 1..2 * SUBDIVISIONS {
                chain.push(self.te_sample(torque, start.psi + sub * j as f64)?);
            }
            // The centre again, along this level's path (at the first level of the first
            // sample's neighbourhood the centre's value is the first sample's, which the sweep
            // solved from the kinematic pose: not a value of this path).
            if !(wrapped && h == step) && (chain[SUBDIVISIONS - 1].te - best.te).abs() > same {
                return Ok(None);
            }
            let b = (0..chain.len())
                .max_by(|&x, &y| (sense * chain[x].te).total_cmp(&(sense * chain[y].te)))
                .unwrap_or(SUBDIVISIONS - 1);
            if b > 0 {
                start = chain[b - 1].clone();
            }
            best = chain.swap_remove(b);
            h = sub;
        }
        Ok(Some(Extreme {
            crank_angle: best.psi,
            value: best.te,
        }))
    }
}
