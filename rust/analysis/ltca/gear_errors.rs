//! Gear runout and pitch errors in the LTCA's first-stage mesh
//! (docs/model.md#gear-errors-in-the-ltca).
//!
//! Each flank of each mesh gains the dynamic models' extra approach
//! `E(th_c, th_s, alpha_i)` (`MeshErrors::offset`, Velex & Maatar 1996; one formula for all
//! models) evaluated at the full coordinates of the static pose, with its gradient (forces)
//! and Hessian (the exact tangent's curvature term `F hess E`).
//!
//! The errors also set how long the transmission error takes to repeat: a sun error returns
//! after one turn of the sun relative to the carrier, a planet error after one turn of the
//! planet relative to the carrier; [`period_units`] counts both in the LTCA's mesh-period unit.

use super::statics::{CARRIER, Dense, SUN};
use crate::dynamics::model::parts::MeshErrors;
use crate::dynamics::scene::Scene;
#[cfg(test)]
use std::f64::consts::TAU;

/// One flank's error at a pose: value \[m\], gradient [m/rad] and Hessian [m/rad^2] by
/// (carrier, sun, crank) angles.
#[derive(Debug, Clone, Copy)]
pub(crate) struct FlankError {
    /// Extra approach of the flank \[m\].
    pub(crate) value: f64,
    grad: [f64; 3],
    hess: [[f64; 3]; 3],
}

impl FlankError {
    /// The error of flank `sigma` (+1 drive, -1 coast) of mesh `i` at carrier angle `thc`,
    /// sun angle `ths` and crank angle `alpha` \[rad\]; `None` without gear errors.
    #[inline]
    pub(crate) fn at(
        errors: Option<&MeshErrors>,
        i: usize,
        sigma: f64,
        thc: f64,
        ths: f64,
        alpha: f64,
    ) -> Option<Self> {
        let me = errors?;
        let off = me.offset(i, sigma, thc, ths, alpha);
        Some(Self {
            value: off.value,
            grad: [off.carrier, off.sun, off.crank],
            hess: me.offset_hessian(i, sigma, thc, ths, alpha),
        })
    }

    /// Full-coordinate indices of (carrier, sun, crank angle) for the crank whose `x` is at
    /// `ci`.
    #[inline]
    fn indices(ci: usize) -> [usize; 3] {
        [CARRIER, SUN, ci + 2]
    }

    /// Add the gradient to a mesh-flank gradient given on the statics' mesh indices
    /// `[SUN, CARRIER, alpha_i, x_i, y_i]`.
    #[inline]
    pub(crate) fn add_gradient(&self, grad: &mut [f64; 5]) {
        grad[0] += self.grad[1];
        grad[1] += self.grad[0];
        grad[2] += self.grad[2];
    }

    /// Add the curvature term `f hess E` of the flank force `f` \[N\] to the tangent stiffness
    /// `K = -dQ/dx` (`Q = -f grad pen`, `pen` including `E`).
    #[inline]
    pub(crate) fn add_curvature(&self, kf: &mut Dense, ci: usize, f: f64) {
        let idx = Self::indices(ci);
        for (a, &r) in idx.iter().enumerate() {
            for (b, &c) in idx.iter().enumerate() {
                kf.add(r, c, f * self.hess[a][b]);
            }
        }
    }
}

/// Greatest common divisor.
pub(crate) fn gcd(mut a: u64, mut b: u64) -> u64 {
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

/// Least common multiple (of positive numbers).
pub(crate) fn lcm(a: u64, b: u64) -> u64 {
    a / gcd(a, b) * b
}

/// Crank-angle period of the gear errors in units of `2 pi / (z_planet zp)` (1 without
/// gear errors). With the input held at crank angle `psi`, the sun turns relative to the
/// carrier by `-(z_planet / z_sun)(zp / zc) psi` and each planet by `(zp / zc) psi`: a sun
/// error repeats every `2 pi z_sun zc / (z_planet zp)` (`z_sun zc` units), a planet error
/// every `2 pi zc / zp` (`z_planet zc` units).
pub(crate) fn period_units(scene: &Scene) -> u64 {
    let (Some(st), g) = (&scene.stage1, &scene.gear_errors) else {
        return 1;
    };
    let zc = u64::from(scene.cycloid.pins.saturating_sub(1)).max(1);
    let mut units = 1;
    if g.sun.any() {
        units = lcm(units, u64::from(st.z_sun).max(1) * zc);
    }
    if g.planets.iter().any(|p| p.any()) {
        units = lcm(units, u64::from(st.z_planet).max(1) * zc);
    }
    units
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::ltca::statics::{ContactState, Family, Kind, Statics, Work};
    use crate::dynamics::model::compliant::CompliantModel;
    use crate::dynamics::model::rigid::RigidModel;
    use crate::dynamics::run::sink::NoSink;
    use crate::dynamics::scene::{Drive, GearError, Joints};
    use crate::solve::MechanicalSystem;

    /// Runout and pitch errors of 3-10 um on the sun and every planet (sinusoid and table).
    fn with_gear_errors(s: &mut Scene) {
        let zs = s.stage1.as_ref().map_or(0, |st| st.z_sun) as usize;
        let g = &mut s.gear_errors;
        g.sun = GearError {
            runout: 8e-6,
            runout_phase: 0.4,
            pitch_amplitude: 5e-6,
            pitch_phase: -0.3,
            pitch_deviation: (0..zs).map(|k| 2e-6 * ((k * 7 % 5) as f64 - 2.0)).collect(),
        };
        g.planets = (0..s.cranks)
            .map(|i| GearError {
                runout: 3e-6 * (1.0 + i as f64),
                runout_phase: 1.1 * i as f64,
                pitch_amplitude: -4e-6,
                pitch_phase: 0.7 + i as f64,
                pitch_deviation: vec![],
            })
            .collect();
    }

    fn scenes() -> Vec<Scene> {
        let mut out = Vec::new();
        for mut s in [
            Scene::paper("rated").unwrap(),
            Scene::physical("rated").unwrap(),
        ] {
            with_gear_errors(&mut s);
            s.stage1.as_mut().unwrap().backlash = 2e-5;
            out.push(s.clone());
            if let Joints::Compliant { crank_bearing, .. } = &mut s.joints {
                *crank_bearing = None;
                out.push(s.clone());
            } else {
                s.joints = crate::dynamics::model::compliant::default_joints();
                out.push(s.clone());
            }
        }
        out
    }

    /// A loaded-looking pose: the kinematic one turned back by 3e-4 rad of carrier plus
    /// deflections of ~10 um.
    fn pose(st: &Statics, psi: f64, seed: usize) -> Vec<f64> {
        let mut q = st.kinematic_unknowns(psi);
        for (a, v) in q.iter_mut().enumerate() {
            let r = ((a * 37 + seed * 11) % 17) as f64 / 17.0 - 0.5;
            *v += 2e-5 * r / st.scale[a] + if a == 0 { -3e-4 } else { 0.0 };
        }
        q
    }

    /// The static forces with gear errors are the dynamic models' forces at rest (rigid and
    /// compliant joints, same poses): the LTCA and the dynamic models use one formula for the
    /// errors. Tolerance as the statics' error-free test: 1e-11 of the largest force.
    #[test]
    fn static_forces_with_gear_errors_are_the_models_forces_at_rest() {
        for mut scene in scenes() {
            scene.drive = Drive::Torque {
                torque: 0.0,
                ramp_time: 0.0,
            };
            let mut st = Statics::new(&scene).unwrap();
            let n = st.dim();
            let mut r = vec![0.0; n];
            let mut k = Dense::zeros(n);
            let mut work = Work::new();
            let torque = scene.load.torque(0.0);
            let mut nominal = scene.clone();
            nominal.gear_errors = Default::default();
            let mut st0 = Statics::new(&nominal).unwrap();
            let mut r0 = vec![0.0; n];
            for seed in 0..4 {
                let psi = 1.3 * seed as f64 + 0.2;
                let q = pose(&st, psi, seed);
                st.eval(psi, &q, torque, &mut r, &mut k, &mut work, None)
                    .unwrap();
                st0.eval(psi, &q, torque, &mut r0, &mut k, &mut work, None)
                    .unwrap();
                let x = st.full(psi, &q);
                let (model_q, free): (Vec<f64>, Vec<usize>) = match scene.joints {
                    Joints::Rigid => {
                        let m = RigidModel::new(&scene).unwrap();
                        let xr = [x[CARRIER], x[st.crank_index(0) + 2], x[SUN]];
                        let f = m.forces(0.0, &xr, &[0.0; 3], &mut NoSink).unwrap();
                        (f.q.to_vec(), vec![0, 1])
                    }
                    Joints::Compliant { .. } => {
                        let m = CompliantModel::new(&scene).unwrap();
                        let qfree: Vec<f64> = m.free.iter().map(|&i| x[i]).collect();
                        let mut a = vec![0.0; qfree.len()];
                        let mut p = [0.0; 3];
                        m.eval(0.0, &qfree, &vec![0.0; qfree.len()], &mut a, &mut p)
                            .unwrap();
                        let mut full = vec![0.0; x.len()];
                        for (kk, &i) in m.free.iter().enumerate() {
                            full[i] = a[kk] * m.mass[i];
                        }
                        (full, st.unknowns.clone())
                    }
                };
                let scale = r
                    .iter()
                    .zip(&st.scale)
                    .map(|(v, l)| (v / l).abs())
                    .fold(torque / 0.15, f64::max);
                let mut changed: f64 = 0.0;
                for (a, &i) in free.iter().enumerate() {
                    let diff = (r[a] - model_q[i]).abs() / st.scale[a];
                    assert!(
                        diff < 1e-11 * scale,
                        "{:?} unknown {a}: static {} model {}",
                        scene.joints,
                        r[a],
                        model_q[i]
                    );
                    changed = changed.max((r[a] - r0[a]).abs() / st.scale[a]);
                }
                // ... and the errors do change the forces (the test can fail).
                assert!(changed > 1e-4 * scale, "{changed:e} vs {scale:e}");
            }
        }
    }

    /// The Hessian of the error against central differences of the dynamic models' analytic
    /// gradient (step 1e-5 rad; the sinusoids' third derivative bounds the error at
    /// ~h^2 e / 6 ~ 2e-16 m/rad^2, round-off ~1e-16 e / h ~ 1e-16). Asserted 1e-12 m/rad^2
    /// against entries of ~1e-5 m/rad^2. The tables' kinks are avoided by steps within one tooth.
    #[test]
    fn error_hessian_is_the_gradients_derivative() {
        let mut scene = Scene::paper("rated").unwrap();
        with_gear_errors(&mut scene);
        let m = RigidModel::new(&scene).unwrap();
        let me = m.mesh_errors.as_ref().unwrap();
        let h = 1e-5;
        let mut largest: f64 = 0.0;
        for i in 0..3 {
            for sign in [1.0, -1.0] {
                let x0 = [0.31 + 0.7 * i as f64, -1.7 + 0.2 * i as f64, 2.4];
                let hs = me.offset_hessian(i, sign, x0[0], x0[1], x0[2]);
                for b in 0..3 {
                    let mut xp = x0;
                    let mut xm = x0;
                    xp[b] += h;
                    xm[b] -= h;
                    let gp = me.offset(i, sign, xp[0], xp[1], xp[2]);
                    let gm = me.offset(i, sign, xm[0], xm[1], xm[2]);
                    let fd = [
                        (gp.carrier - gm.carrier) / (2.0 * h),
                        (gp.sun - gm.sun) / (2.0 * h),
                        (gp.crank - gm.crank) / (2.0 * h),
                    ];
                    for a in 0..3 {
                        largest = largest.max(hs[a][b].abs());
                        assert!(
                            (hs[a][b] - fd[a]).abs() < 1e-12,
                            "mesh {i} flank {sign} ({a}, {b}): {} vs {}",
                            hs[a][b],
                            fd[a]
                        );
                    }
                }
            }
        }
        assert!(largest > 1e-6, "{largest:e}");
    }

    /// The meshes' tangent with gear errors against central differences of their forces
    /// (step 1e-9 m; the meshes alone, so that the pins' warm-started gaps add no round-off).
    /// Measured floor of the differences: up to 3e-7 of the largest entry (forces ~1e4 N to
    /// 1e-16 over 2e-9 m, and the laws' higher derivatives); asserted 1e-6 as the statics' own
    /// test. The share the errors add, `K - K_0` (with and without errors, same pose), against
    /// the differences of `Q - Q_0`: it is 1e-4 to 1e-3 of `K`, so the same floor is up to
    /// 6e-4 of it (measured, ISO mesh); asserted 1e-2. The curvature term `F hess E` (~5e-7 of
    /// `K`) is below what either can see: `error_hessian_is_the_gradients_derivative` checks
    /// the Hessian itself.
    #[test]
    fn gear_error_tangent_matches_finite_differences() {
        for scene in scenes() {
            let mut nominal = scene.clone();
            nominal.gear_errors = Default::default();
            let mut st = Statics::new(&scene).unwrap();
            let mut st0 = Statics::new(&nominal).unwrap();
            // The meshes alone: the pins' exact gaps carry warm starts from call to call, and
            // their round-off (~1e-17 m of gap at 1e8 N/m) would not cancel in the difference.
            st.family = Some(Family::Mesh);
            st0.family = Some(Family::Mesh);
            let n = st.dim();
            let torque = scene.load.torque(0.0);
            let mut work = Work::new();
            let eval = |st: &mut Statics, psi: f64, q: &[f64], work: &mut Work| {
                let mut r = vec![0.0; n];
                let mut k = Dense::zeros(n);
                let mut cs = ContactState::default();
                st.eval(psi, q, torque, &mut r, &mut k, work, Some(&mut cs))
                    .unwrap();
                (r, k, cs)
            };
            for seed in 1..4 {
                // The cranks turned on by 1.5e-3 rad: every drive flank approaches by
                // ~9e-5 m and every coast flank is open by more than 6e-5 m, beyond the
                // errors (< 3e-5 m) and the 2e-6 m perturbations, so no flank is near its
                // first touch, where central differences of the IMPACT law fail.
                let psi = 0.9 * seed as f64;
                let mut q = st.kinematic_unknowns(psi);
                for (a, v) in q.iter_mut().enumerate() {
                    let r = ((a * 37 + seed * 11) % 17) as f64 / 17.0 - 0.5;
                    let crank = match st.kind {
                        Kind::Rigid => a == 1,
                        Kind::Compliant => {
                            let i = st.unknowns[a];
                            i >= 2 && i < 2 + 3 * st.cranks && (i - 2) % 3 == 2
                        }
                    };
                    *v += 2e-6 * r / st.scale[a] + if crank { 1.5e-3 } else { 0.0 };
                }
                let (_, k1, _) = eval(&mut st, psi, &q, &mut work);
                let (_, k0, _) = eval(&mut st0, psi, &q, &mut work);
                let scale = st.scale.clone();
                let dk = |a: usize, b: usize| (k1.at(a, b) - k0.at(a, b)) / (scale[a] * scale[b]);
                let mut kmax: f64 = 0.0;
                for a in 0..n {
                    for b in 0..n {
                        kmax = kmax.max(dk(a, b).abs());
                    }
                }
                assert!(kmax > 1e3, "the errors change the tangent: {kmax:e}");
                let h = 1e-9;
                let mut worst: f64 = 0.0;
                let mut worst1: f64 = 0.0;
                let mut kmax1: f64 = 0.0;
                for a in 0..n {
                    for b in 0..n {
                        kmax1 = kmax1.max((k1.at(a, b) / (scale[a] * scale[b])).abs());
                    }
                }
                for b in 0..n {
                    let mut qp = q.clone();
                    let mut qm = q.clone();
                    qp[b] += h / scale[b];
                    qm[b] -= h / scale[b];
                    let (rp, _, _) = eval(&mut st, psi, &qp, &mut work);
                    let (rm, _, _) = eval(&mut st, psi, &qm, &mut work);
                    let (rp0, _, _) = eval(&mut st0, psi, &qp, &mut work);
                    let (rm0, _, _) = eval(&mut st0, psi, &qm, &mut work);
                    for a in 0..n {
                        let fd = -((rp[a] - rp0[a]) - (rm[a] - rm0[a])) / (2.0 * h) / scale[a];
                        worst = worst.max((fd - dk(a, b)).abs() / kmax);
                        let fd1 = -(rp[a] - rm[a]) / (2.0 * h) / scale[a];
                        let an1 = k1.at(a, b) / (scale[a] * scale[b]);
                        worst1 = worst1.max((fd1 - an1).abs() / kmax1);
                    }
                }
                assert!(worst1 < 1e-6, "{:?}: K vs FD {worst1:e}", scene.joints);
                assert!(worst < 1e-2, "{:?}: K - K0 vs FD {worst:e}", scene.joints);
            }
        }
    }

    /// The TE window: the pattern's least common period with the sun's and the planets'
    /// turns relative to the carrier, in units of `2 pi / (z_planet zp)`.
    #[test]
    fn the_window_covers_the_gear_errors_periods() {
        use crate::analysis::ltca::mesh_period;
        let base = Scene::physical("rated").unwrap();
        let st = base.stage1.clone().unwrap();
        let (zs, zpl, zp) = (
            u64::from(st.z_sun),
            u64::from(st.z_planet),
            u64::from(base.cycloid.pins),
        );
        let unit = TAU / (zpl * zp) as f64;
        let zc = zp - 1;
        let mut sun = base.clone();
        sun.gear_errors.sun.runout = 1e-6;
        let mut planet = base.clone();
        planet.gear_errors.planets = vec![GearError::default(); 3];
        planet.gear_errors.planets[2].pitch_amplitude = 1e-6;
        let mut both = sun.clone();
        both.gear_errors.planets = planet.gear_errors.planets.clone();
        // The ISO mesh period is zc units; the pins' zpl units.
        let cases = [
            (&base, lcm(zpl, zc)),
            (&sun, lcm(zpl, zs * zc)),
            (&planet, lcm(zpl, zpl * zc)),
            (&both, lcm(zpl, lcm(zs * zc, zpl * zc))),
        ];
        for (s, units) in cases {
            let p = mesh_period(s);
            assert!(
                (p / unit - units as f64).abs() < 1e-9,
                "{p} vs {units} units"
            );
        }
        // With the IMPACT mesh law the gear errors alone set the mesh part.
        let mut paper = Scene::paper("rated").unwrap();
        let zpl = u64::from(paper.stage1.as_ref().unwrap().z_planet);
        let zs = u64::from(paper.stage1.as_ref().unwrap().z_sun);
        let zp = u64::from(paper.cycloid.pins);
        paper.gear_errors.sun.pitch_amplitude = 1e-6;
        let p = mesh_period(&paper);
        let units = lcm(zpl, zs * (zp - 1));
        assert!((p * (zpl * zp) as f64 / TAU - units as f64).abs() < 1e-9);
    }
}
