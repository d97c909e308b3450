use super::*;
use nalgebra::dmatrix;

fn names(n: usize) -> Vec<String> {
    (0..n).map(|i| format!("q{i}")).collect()
}

fn system(m: DMatrix<f64>, parts: Vec<(&str, DMatrix<f64>)>, c: DMatrix<f64>) -> LinearSystem {
    let n = m.nrows();
    LinearSystem {
        dof_names: names(n),
        mass: m,
        stiffness: parts
            .into_iter()
            .map(|(name, matrix)| StiffnessPart {
                name: name.into(),
                matrix,
            })
            .collect(),
        damping: c,
        length_scale: vec![],
    }
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn one_dof_torsional_oscillator_closed_form() {
    // J theta'' + k theta = 0: w = sqrt(k/J).
    let (j, k) = (0.2111, 3.7e6);
    let sys = system(dmatrix![j], vec![("shaft", dmatrix![k])], dmatrix![0.0]);
    let r = modal_analysis(&sys).unwrap();
    assert_eq!(r.modes.len(), 1);
    let f = (k / j).sqrt() / TAU;
    assert!(rel(r.modes[0].frequency, f) < 1e-9);
    let d = r.modes[0].damped.as_ref().unwrap();
    assert!(rel(d.natural_frequency, f) < 1e-9);
    assert!(d.damping_ratio.abs() < 1e-12);
    assert!((r.modes[0].energy_share[0] - 1.0).abs() < 1e-12);
    // Mass-normalised: J phi^2 = 1.
    assert!(rel(j * r.modes[0].shape[0].powi(2), 1.0) < 1e-12);
    assert_eq!(r.modes[0].display_shape[0], 1.0);
}

/// Natural frequencies [rad/s] of the grounded chain ground -k1- J1 -k2- J2, from
/// `J1 J2 w^4 - (J1 k2 + J2 (k1 + k2)) w^2 + k1 k2 = 0` (roots in a cancellation-free form).
fn chain_omegas(j1: f64, j2: f64, k1: f64, k2: f64) -> (f64, f64) {
    let a = j1 * j2;
    let b = j1 * k2 + j2 * (k1 + k2);
    let c = k1 * k2;
    let s = (b * b - 4.0 * a * c).sqrt();
    let hi = (b + s) / (2.0 * a);
    let lo = c / (a * hi);
    (lo.sqrt(), hi.sqrt())
}

#[test]
fn two_dof_torsional_chain_closed_form_and_energy_shares() {
    let (j1, j2, k1, k2) = (0.2, 0.05, 1.0e6, 3.0e5);
    let sys = system(
        DMatrix::from_diagonal(&DVector::from_vec(vec![j1, j2])),
        vec![
            ("shaft 1", dmatrix![k1, 0.0; 0.0, 0.0]),
            ("shaft 2", dmatrix![k2, -k2; -k2, k2]),
        ],
        DMatrix::zeros(2, 2),
    );
    let r = modal_analysis(&sys).unwrap();
    let (w1, w2) = chain_omegas(j1, j2, k1, k2);
    assert!(rel(r.modes[0].frequency, w1 / TAU) < 1e-9);
    assert!(rel(r.modes[1].frequency, w2 / TAU) < 1e-9);
    for (mode, w) in r.modes.iter().zip([w1, w2]) {
        // Shape from the first row: (k1 + k2 - w^2 J1) phi1 = k2 phi2.
        let ratio = (k1 + k2 - w * w * j1) / k2;
        let phi = &mode.shape;
        assert!(rel(phi[1] / phi[0], ratio) < 1e-9);
        // Strain energy of each shaft over the total (phi^T K phi = w^2 when mass-normalised).
        let e1 = k1 * phi[0] * phi[0];
        let e2 = k2 * (phi[1] - phi[0]).powi(2);
        assert!((mode.energy_share[0] - e1 / (e1 + e2)).abs() < 1e-9);
        assert!((mode.energy_share[1] - e2 / (e1 + e2)).abs() < 1e-9);
        assert!(rel(e1 + e2, w * w) < 1e-9);
        let d = mode.damped.as_ref().unwrap();
        assert!(d.mac > 1.0 - 1e-12);
        assert!(rel(d.natural_frequency, w / TAU) < 1e-9);
    }
    // Orthogonality in M.
    let m = &sys.mass;
    let cross = r.modes[0].shape.dot(&(m * &r.modes[1].shape));
    assert!(cross.abs() < 1e-12);
    assert!(r.stiffness_asymmetry == 0.0);
}

#[test]
fn free_chain_has_one_rigid_body_mode() {
    // J1 -k- J2 without ground: w = 0 and w^2 = k (J1 + J2)/(J1 J2).
    let (j1, j2, k) = (0.3, 0.07, 2.0e5);
    let sys = system(
        DMatrix::from_diagonal(&DVector::from_vec(vec![j1, j2])),
        vec![("shaft", dmatrix![k, -k; -k, k])],
        dmatrix![5.0, -5.0; -5.0, 5.0],
    );
    let r = modal_analysis(&sys).unwrap();
    assert!(r.modes[0].rigid_body && r.modes[0].frequency == 0.0);
    assert!(r.modes[0].damped.is_none());
    assert_eq!(r.modes[0].energy_share, vec![0.0]);
    let w = (k * (j1 + j2) / (j1 * j2)).sqrt();
    assert!(rel(r.modes[1].frequency, w / TAU) < 1e-9);
    // Damper in parallel with the spring: zeta = c / (2 w m_eff), m_eff = J1 J2/(J1 + J2).
    let zeta = 5.0 / (2.0 * w * j1 * j2 / (j1 + j2));
    let d = r.modes[1].damped.as_ref().unwrap();
    assert!(rel(d.damping_ratio, zeta) < 1e-9);
    assert!((r.frequency_span().0 - w / TAU).abs() < 1e-9);
}

#[test]
fn damped_one_dof_oscillator_damping_ratio_is_exact() {
    // m x'' + c x' + k x = 0: lambda = -zeta w +- i w sqrt(1 - zeta^2), zeta = c/(2 sqrt(k m)).
    for (m, k, c) in [(14.8, 1.0e9, 1.0e4), (2.0, 5.0e4, 150.0), (0.5, 8.0e3, 1.0)] {
        let sys = system(dmatrix![m], vec![("spring", dmatrix![k])], dmatrix![c]);
        let r = modal_analysis(&sys).unwrap();
        let w = (k / m).sqrt();
        let zeta = c / (2.0 * (k * m).sqrt());
        let d = r.modes[0].damped.as_ref().unwrap();
        assert!(
            rel(d.damping_ratio, zeta) < 1e-12,
            "{} vs {zeta}",
            d.damping_ratio
        );
        assert!(rel(d.natural_frequency, w / TAU) < 1e-12);
        assert!(rel(d.damped_frequency, w * (1.0 - zeta * zeta).sqrt() / TAU) < 1e-12);
        assert!(rel(r.modes[0].modal_damping_ratio, zeta) < 1e-12);
        assert_eq!(r.eigenvalues.len(), 2);
    }
}

#[test]
fn overdamped_one_dof_gives_the_real_pair() {
    // zeta = 2: two real roots -w (2 +- sqrt(3)); w_n = sqrt(l1 l2), zeta = -(l1 + l2)/(2 w_n).
    let (m, k): (f64, f64) = (1.5, 6.0e4);
    let w = (k / m).sqrt();
    let c = 2.0 * 2.0 * (k * m).sqrt();
    let sys = system(dmatrix![m], vec![("spring", dmatrix![k])], dmatrix![c]);
    let r = modal_analysis(&sys).unwrap();
    let d = r.modes[0].damped.as_ref().unwrap();
    assert!(rel(d.damping_ratio, 2.0) < 1e-10);
    assert!(rel(d.natural_frequency, w / TAU) < 1e-10);
    assert_eq!(d.damped_frequency, 0.0);
    assert!(rel(-d.eigenvalue.re, w * (2.0 - 3f64.sqrt())) < 1e-10);
}

#[test]
fn rayleigh_damping_gives_the_closed_form_ratios() {
    // C = a M + b K: zeta_i = a / (2 w_i) + b w_i / 2 (Rayleigh damping, e.g. Chopra 2012
    // section 11.4), non-trivially coupled 3-DOF chain.
    let m = DMatrix::from_diagonal(&DVector::from_vec(vec![2.0, 1.0, 0.5]));
    let k = dmatrix![3.0e5, -1.0e5, 0.0; -1.0e5, 1.6e5, -6.0e4; 0.0, -6.0e4, 6.0e4];
    let (a, b) = (3.0, 2.0e-5);
    let c = &m * a + &k * b;
    let sys = system(m, vec![("springs", k)], c);
    let r = modal_analysis(&sys).unwrap();
    for mode in &r.modes {
        let w = TAU * mode.frequency;
        let zeta = a / (2.0 * w) + b * w / 2.0;
        let d = mode.damped.as_ref().unwrap();
        assert!(
            rel(d.damping_ratio, zeta) < 1e-9,
            "{} {zeta}",
            d.damping_ratio
        );
        assert!(rel(d.natural_frequency, mode.frequency) < 1e-9);
        assert!(rel(mode.modal_damping_ratio, zeta) < 1e-9);
        assert!(d.mac > 1.0 - 1e-9);
    }
    assert!(r.unmatched.is_empty());
}

#[test]
fn degenerate_modes_are_both_matched() {
    // Two identical uncoupled oscillators with the same light damping: a repeated eigenvalue.
    let sys = system(
        DMatrix::identity(2, 2),
        vec![("springs", DMatrix::identity(2, 2) * 100.0)],
        DMatrix::identity(2, 2) * 0.2,
    );
    let r = modal_analysis(&sys).unwrap();
    for mode in &r.modes {
        let d = mode.damped.as_ref().unwrap();
        assert!(rel(d.damping_ratio, 0.01) < 1e-9);
    }
}

#[test]
fn asymmetric_stiffness_is_symmetrised_and_reported() {
    let sys = system(
        DMatrix::identity(2, 2),
        vec![("k", dmatrix![4.0, 1.2; 0.8, 3.0])],
        DMatrix::zeros(2, 2),
    );
    let r = modal_analysis(&sys).unwrap();
    // Skew part [[0, 0.2], [-0.2, 0]]: |.|_F = 0.2 sqrt(2); |K|_F = sqrt(16 + 1.44 + 0.64 + 9).
    let expect = 0.2 * 2f64.sqrt() / (16.0f64 + 1.44 + 0.64 + 9.0).sqrt();
    assert!(rel(r.stiffness_asymmetry, expect) < 1e-12);
    // Symmetric part [[4, 1], [1, 3]]: w^2 = (7 -+ sqrt(5))/2.
    assert!(rel(r.modes[0].omega_squared, (7.0 - 5f64.sqrt()) / 2.0) < 1e-12);
}

#[test]
fn zero_inertia_body_is_named() {
    let mut sys = system(
        DMatrix::from_diagonal(&DVector::from_vec(vec![1.0, 0.0])),
        vec![("k", DMatrix::identity(2, 2))],
        DMatrix::zeros(2, 2),
    );
    sys.dof_names = vec!["carrier angle".into(), "sun angle".into()];
    let e = modal_analysis(&sys).unwrap_err();
    assert!(matches!(e, RvdynError::Parameter(_)));
    assert!(e.to_string().contains("'sun angle'"), "{e}");
    assert!(e.to_string().contains("zero inertia"), "{e}");
    // Positive diagonal but singular: the coordinate where the factorisation fails.
    sys.mass = dmatrix![1.0, 1.0; 1.0, 1.0];
    let e = modal_analysis(&sys).unwrap_err();
    assert!(e.to_string().contains("not positive definite"), "{e}");
    assert!(e.to_string().contains("'sun angle'"), "{e}");
}

#[test]
fn bad_entries_and_shapes_are_rejected() {
    let mut sys = system(
        DMatrix::identity(2, 2),
        vec![("pins", dmatrix![1.0, f64::NAN; 0.0, 1.0])],
        DMatrix::zeros(2, 2),
    );
    let e = modal_analysis(&sys).unwrap_err().to_string();
    assert!(e.contains("pins entry (q0, q1) is NaN"), "{e}");
    sys.stiffness[0].matrix = DMatrix::identity(3, 3);
    let e = modal_analysis(&sys).unwrap_err().to_string();
    assert!(e.contains("pins is 3x3"), "{e}");
    sys.stiffness.clear();
    assert!(modal_analysis(&sys).is_err());
    let mut sys = system(
        dmatrix![1.0, 0.5; 0.0, 1.0],
        vec![("k", DMatrix::identity(2, 2))],
        DMatrix::zeros(2, 2),
    );
    let e = modal_analysis(&sys).unwrap_err().to_string();
    assert!(e.contains("not symmetric"), "{e}");
    sys.mass = DMatrix::identity(2, 2);
    sys.length_scale = vec![1.0, -1.0];
    let e = modal_analysis(&sys).unwrap_err().to_string();
    assert!(e.contains("length_scale of q1"), "{e}");
}

#[test]
fn frequency_range_outside_the_model_is_an_error() {
    let sys = system(
        DMatrix::identity(2, 2),
        vec![("k", dmatrix![4.0e4, 0.0; 0.0, 9.0e4])],
        DMatrix::zeros(2, 2),
    );
    let r = modal_analysis(&sys).unwrap();
    // 200/2pi = 31.8 Hz and 300/2pi = 47.7 Hz.
    assert_eq!(r.modes_in_range(30.0, 40.0).unwrap(), vec![0]);
    assert_eq!(r.modes_in_range(0.0, 100.0).unwrap(), vec![0, 1]);
    let e = r.modes_in_range(100.0, 200.0).unwrap_err().to_string();
    assert!(e.contains("span 31.83 to 47.75 Hz"), "{e}");
    assert!(r.modes_in_range(5.0, 1.0).is_err());
    assert!(r.modes_in_range(f64::NAN, 1.0).is_err());
}

#[test]
fn negative_stiffness_direction_is_flagged_unstable() {
    let sys = system(
        DMatrix::identity(2, 2),
        vec![("k", dmatrix![-1.0e3, 0.0; 0.0, 1.0e4])],
        DMatrix::zeros(2, 2),
    );
    let r = modal_analysis(&sys).unwrap();
    assert!(r.modes[0].unstable && r.modes[0].frequency == 0.0);
    assert!(rel(r.modes[0].omega_squared, -1.0e3) < 1e-12);
    assert!(!r.modes[1].unstable);
}

// ---- linearised reducer models ---------------------------------------------------------------

use crate::dynamics::model::compliant::default_joints;
use crate::dynamics::scene::{Bearing, Joints, Scene};

fn rated_torque() -> f64 {
    match Scene::paper("rated").unwrap().load {
        crate::dynamics::scene::Load::Constant { torque } => torque,
        _ => unreachable!(),
    }
}

fn compliant_scene(k_ecc: f64, k_crank: Option<f64>) -> Scene {
    let mut s = Scene::paper("rated").unwrap();
    s.joints = Joints::Compliant {
        eccentric_bearing: Bearing {
            stiffness: k_ecc,
            damping: 1e4,
            clearance: 0.0,
            rollers: None,
        },
        crank_bearing: k_crank.map(|k| Bearing {
            stiffness: k,
            damping: 1e4,
            clearance: 0.0,
            rollers: None,
        }),
    };
    s
}

#[test]
fn modes_count_equals_the_dof_count() {
    let t = rated_torque();
    let rigid = Scene::paper("rated").unwrap();
    let mut compliant = rigid.clone();
    compliant.joints = default_joints();
    for (scene, dof) in [
        (rigid, 2),
        (compliant, 16),
        (compliant_scene(1e9, None), 10),
    ] {
        let mut lin = Linearizer::new(&scene).unwrap();
        let (sys, eq) = lin.linearise(t, 0.1).unwrap();
        assert_eq!(sys.dof_names.len(), dof);
        let r = modal_analysis(&sys).unwrap();
        assert_eq!(r.modes.len(), dof);
        assert!(eq.split_error < 1e-12, "split {}", eq.split_error);
        assert!(eq.residual < 1e-9);
        for m in &r.modes {
            assert!(!m.unstable && !m.rigid_body && m.frequency > 0.0);
            let total: f64 = m.energy_share.iter().sum();
            assert!((total - 1.0).abs() < 1e-9, "{total}");
            assert!(m.damped.is_some(), "mode at {} Hz unmatched", m.frequency);
        }
    }
}

#[test]
fn tangent_stiffness_equals_finite_differences_of_the_dynamic_force() {
    // K = -dQ/dq from the LTCA's analytic tangent against central differences of the dynamic
    // model's generalised force (a separate implementation of the same forces) at the rated
    // equilibrium: steps of 1e-8 m at each coordinate's lever; the truncation error of the
    // 1.5-power law over that step and the round-off of the exact-gap Newton (1e-13 m) are
    // far below the 1e-5 relative tolerance (measured in the test output).
    let t = rated_torque();
    let mut compliant = Scene::paper("rated").unwrap();
    compliant.joints = default_joints();
    for scene in [Scene::paper("rated").unwrap(), compliant] {
        let mut lin = Linearizer::new(&scene).unwrap();
        let (sys, eq) = lin.linearise(t, 0.37).unwrap();
        let k = lin.tangent_stiffness(&eq).unwrap();
        let n = sys.dof_names.len();
        let zero = vec![0.0; n];
        let mut fd = DMatrix::<f64>::zeros(n, n);
        for b in 0..n {
            let h = 1e-8 / sys.length_scale[b];
            let mut dq = zero.clone();
            dq[b] = h;
            let qp = lin.dynamic_force(&eq, &dq, &zero).unwrap();
            dq[b] = -h;
            let qm = lin.dynamic_force(&eq, &dq, &zero).unwrap();
            for a in 0..n {
                fd[(a, b)] = -(qp[a] - qm[a]) / (2.0 * h);
            }
        }
        // Compare in displacement units: K_ab L_a^-1 L_b^-1 [N/m].
        let mut worst: f64 = 0.0;
        let mut scale: f64 = 0.0;
        for a in 0..n {
            for b in 0..n {
                let s = 1.0 / (sys.length_scale[a] * sys.length_scale[b]);
                worst = worst.max((k[(a, b)] - fd[(a, b)]).abs() * s);
                scale = scale.max(k[(a, b)].abs() * s);
            }
        }
        assert!(worst < 1e-5 * scale, "{n} dof: {worst:e} of {scale:e}");
    }
}

#[test]
fn very_stiff_bearings_give_the_rigid_low_modes() {
    // The compliant model with eccentric and crank bearings 1e4 times the default stiffness
    // tends to the rigid-joint model (same masses on the rigid manifold): its two lowest modes
    // must agree with the rigid model's two within 1 %.
    let t = rated_torque();
    let mut lin = Linearizer::new(&Scene::paper("rated").unwrap()).unwrap();
    let (sys, _) = lin.linearise(t, 0.2).unwrap();
    let rigid = modal_analysis(&sys).unwrap();
    let mut lin = Linearizer::new(&compliant_scene(1e13, Some(2e13))).unwrap();
    let (sys, _) = lin.linearise(t, 0.2).unwrap();
    let stiff = modal_analysis(&sys).unwrap();
    for i in 0..2 {
        let (a, b) = (rigid.modes[i].frequency, stiff.modes[i].frequency);
        assert!(
            (a - b).abs() < 0.01 * a,
            "mode {i}: rigid {a} Hz, stiff {b} Hz"
        );
    }
    // The bearings' share of the low modes' strain energy vanishes in that limit.
    let bearing = stiff
        .part_names
        .iter()
        .position(|p| p == "eccentric bearings")
        .unwrap();
    assert!(stiff.modes[0].energy_share[bearing] < 0.01);
}

// ---- closed forms of the linearised reducer ----------------------------------------------------

use crate::analysis::classical_levers;
use crate::dynamics::scene::ContactLawSpec;
use crate::geometry::CycloidGeometry;

fn linear_law(k: f64) -> ContactLawSpec {
    ContactLawSpec::Impact {
        stiffness: k,
        exponent: 1.0,
        max_damping: 0.0,
        damping_depth: 1e-5,
    }
}

/// Sum of `l^2` over the pins a positive output torque loads (negative classical lever),
/// both discs.
fn loaded_lever_sum(g: &CycloidGeometry, psi: f64) -> f64 {
    [0.0, std::f64::consts::PI]
        .iter()
        .flat_map(|ph| classical_levers(g, psi + ph))
        .filter(|l| *l < 0.0)
        .map(|l| l * l)
        .sum()
}

/// One torsional DOF: rigid joints, cranks held (no first stage), linear pin law `k`, at a
/// vanishing load (1e-3 N m: the geometric term `F hess g` is ~1e-14 of `k l^2`):
/// `w^2 = k sum(l_j^2) / M_c` over the loaded pins of both discs, `l_j` the classical
/// levers. Asserted to 1e-9.
#[test]
fn one_dof_reducer_frequency_is_the_closed_form() {
    let mut s = Scene::paper("rated").unwrap();
    s.stage1 = None;
    s.contact.pin = linear_law(1e9);
    let g = CycloidGeometry::new(s.cycloid).unwrap();
    let psi = 0.37;
    let mut lin = Linearizer::new(&s).unwrap();
    let (sys, _) = lin.linearise(1e-3, psi).unwrap();
    let r = modal_analysis(&sys).unwrap();
    assert_eq!(r.modes.len(), 1);
    let w = (1e9 * loaded_lever_sum(&g, psi) / sys.mass[(0, 0)]).sqrt();
    let f = w / TAU;
    assert!((r.modes[0].frequency / f - 1.0).abs() < 1e-9);
    assert!((r.modes[0].energy_share.iter().sum::<f64>() - 1.0).abs() < 1e-9);
}

/// Two DOFs (carrier, crank) with the first stage: linear pin law `k`, linear mesh law
/// `k_m` on `n` meshes. With the classical levers `l_c` about the disc centre and
/// `l_a = l_c / zc` about the reducer axis: `K_cc = k S2 + n k_m (r_bs + r_bp)^2`,
/// `K_ca = k S2 / zc - n k_m (r_bs + r_bp) r_bp`, `K_aa = k S2 / zc^2 + n k_m r_bp^2`
/// (`S2 = sum l_c^2`), and the frequencies from `det(K - w^2 M) = 0`. Asserted to 1e-9.
#[test]
fn two_dof_reducer_frequencies_are_the_closed_form() {
    let mut s = Scene::paper("rated").unwrap();
    let (k, km) = (1e9, 3e8);
    s.contact.pin = linear_law(k);
    s.contact.mesh = linear_law(km);
    let g = CycloidGeometry::new(s.cycloid).unwrap();
    let psi = 0.21;
    let mut lin = Linearizer::new(&s).unwrap();
    let (sys, _) = lin.linearise(1e-3, psi).unwrap();
    let r = modal_analysis(&sys).unwrap();
    assert_eq!(r.modes.len(), 2);
    let rm = crate::dynamics::RigidModel::new(&s).unwrap();
    let mesh = rm.mesh.unwrap();
    let (rbs, rbp, n) = (
        mesh.sun_base_radius,
        mesh.planet_base_radius,
        mesh.count as f64,
    );
    let s2 = loaded_lever_sum(&g, psi);
    let zc = 23.0;
    let kcc = k * s2 + n * km * (rbs + rbp).powi(2);
    let kca = k * s2 / zc - n * km * (rbs + rbp) * rbp;
    let kaa = k * s2 / (zc * zc) + n * km * rbp * rbp;
    let (mc, ma) = (sys.mass[(0, 0)], sys.mass[(1, 1)]);
    let a = mc * ma;
    let b = -(kcc * ma + kaa * mc);
    let c = kcc * kaa - kca * kca;
    let disc = (b * b - 4.0 * a * c).sqrt();
    let w2 = [(-b - disc) / (2.0 * a), (-b + disc) / (2.0 * a)];
    for (m, w2) in r.modes.iter().zip(w2) {
        let f = w2.sqrt() / TAU;
        assert!((m.frequency / f - 1.0).abs() < 1e-9, "{} {f}", m.frequency);
    }
    assert_eq!(
        r.part_names,
        vec![
            "pin contacts disc 0",
            "pin contacts disc 1",
            "sun/planet meshes"
        ]
    );
}

/// The mode table of the paper scene at rated load, rigid and compliant (printed; run with
/// `--ignored --nocapture`).
#[test]
#[ignore]
fn print_paper_mode_tables() {
    let t = rated_torque();
    let mut compliant = Scene::paper("rated").unwrap();
    compliant.joints = default_joints();
    for scene in [Scene::paper("rated").unwrap(), compliant] {
        let mut lin = Linearizer::new(&scene).unwrap();
        let (sys, eq) = lin.linearise(t, 0.1).unwrap();
        let r = modal_analysis(&sys).unwrap();
        println!(
            "split error {:.1e}; parts {:?}",
            eq.split_error, r.part_names
        );
        for m in &r.modes {
            let z = m
                .damped
                .as_ref()
                .map_or(m.modal_damping_ratio, |d| d.damping_ratio);
            let shares: Vec<String> = m
                .energy_share
                .iter()
                .map(|e| format!("{:.0}", 100.0 * e))
                .collect();
            println!(
                "{:10.1} Hz  zeta {:.4}  {:16}  energy % {}",
                m.frequency,
                z,
                r.dof_names[m.dominant_dof],
                shares.join(" ")
            );
        }
    }
}

/// Every damped eigenvalue of a heavily, non-proportionally damped reducer (the compliant
/// paper preset: modal damping ratios up to 2.5, overdamped pairs, close oscillatory modes)
/// is a root of the pencil: the smallest singular value of `P(l) = l^2 M + l C + K`, scaled
/// by `|l|^2 |M| + |l| |C| + |K|`, is at round-off (asserted 1e-12; a wrong eigenvalue off by
/// 1e-4 relative gives about 1e-5).
#[test]
fn damped_eigenvalues_are_roots_of_the_pencil() {
    use crate::dynamics::scene::Scene;
    let mut scene = Scene::paper("rated").unwrap();
    scene.joints = crate::dynamics::model::compliant::default_joints();
    for scene in [scene, Scene::physical("rated").unwrap()] {
        let mut lin = Linearizer::new(&scene).unwrap();
        let torque = scene.load.torque(0.0);
        let (sys, _) = lin.linearise(torque, 0.1).unwrap();
        let ma = modal_analysis(&sys).unwrap();
        let n = sys.mass.nrows();
        let mut k = DMatrix::<f64>::zeros(n, n);
        for p in &sys.stiffness {
            k += &p.matrix;
        }
        let c = &sys.damping;
        let m = &sys.mass;
        let mut worst: f64 = 0.0;
        for l in &ma.eigenvalues {
            let p = DMatrix::from_fn(n, n, |i, j| {
                Complex::new(m[(i, j)], 0.0) * l * l
                    + Complex::new(c[(i, j)], 0.0) * l
                    + Complex::new(k[(i, j)], 0.0)
            });
            let sv = p.singular_values();
            let smin = sv.iter().fold(f64::INFINITY, |a, v| a.min(*v));
            let scale = l.norm_sqr() * m.norm() + l.norm() * c.norm() + k.norm();
            worst = worst.max(smin / scale);
        }
        eprintln!("{}: worst pencil residual {worst:e}", scene.name);
        assert!(worst < 1e-12, "{}: {worst:e}", scene.name);
    }
}

// ---- machine shafts and dynamic-run states ------------------------------------------------------

use crate::dynamics::scene::{Drive, Load, Shaft};

/// The rated paper scene with load inertia `jl` [kg m^2] and motor inertia `jm`, an output
/// shaft `ko` and a drive shaft `ki` [N m/rad] (`None`: rigid connection).
fn shaft_scene(ko: Option<f64>, ki: Option<f64>, jl: f64, jm: f64, compliant: bool) -> Scene {
    let mut s = Scene::paper("rated").unwrap();
    s.inertias.load_inertia = jl;
    s.inertias.motor_inertia = jm;
    s.shafts.output = ko.map(|k| Shaft {
        stiffness: k,
        damping: 10.0,
    });
    s.shafts.input = ki.map(|k| Shaft {
        stiffness: k,
        damping: 0.1,
    });
    if compliant {
        s.joints = default_joints();
    }
    s
}

fn torque_driven(mut s: Scene) -> Scene {
    s.drive = Drive::Torque {
        torque: rated_torque() / s.ratio(),
        ramp_time: 0.0,
    };
    s
}

#[test]
fn shaft_coordinates_are_named_and_their_tangent_equals_finite_differences() {
    // With shafts the linearisation adds the sun (free on the drive shaft), the load and (torque
    // drive) the motor; its stiffness (the LTCA's analytic tangent with the sun's row and
    // column from the full-coordinate tangent, plus the shafts' springs) must equal central
    // differences of the dynamic model's generalised force over every coordinate (1e-5
    // relative in displacement units, as the test without shafts). The number of modes equals
    // the number of coordinates.
    let t = rated_torque();
    for compliant in [false, true] {
        let speed = shaft_scene(Some(2e6), Some(5e4), 20.0, 0.05, compliant);
        for (scene, extra) in [
            (speed.clone(), vec!["sun angle", "load angle"]),
            (
                torque_driven(speed),
                vec!["sun angle", "load angle", "motor angle"],
            ),
        ] {
            let mut lin = Linearizer::new(&scene).unwrap();
            let (sys, eq) = lin.linearise(t, 0.37).unwrap();
            let n = sys.dof_names.len();
            assert_eq!(&sys.dof_names[n - extra.len()..], extra.as_slice());
            assert_eq!(sys.stiffness.last().unwrap().name, "shafts");
            assert!(eq.split_error < 1e-12, "split {}", eq.split_error);
            let mut k = DMatrix::<f64>::zeros(n, n);
            for p in &sys.stiffness {
                k += &p.matrix;
            }
            let zero = vec![0.0; n];
            let mut fd = DMatrix::<f64>::zeros(n, n);
            for b in 0..n {
                let h = 1e-8 / sys.length_scale[b];
                let mut dq = zero.clone();
                dq[b] = h;
                let qp = lin.dynamic_force(&eq, &dq, &zero).unwrap();
                dq[b] = -h;
                let qm = lin.dynamic_force(&eq, &dq, &zero).unwrap();
                for a in 0..n {
                    fd[(a, b)] = -(qp[a] - qm[a]) / (2.0 * h);
                }
            }
            let mut worst: f64 = 0.0;
            let mut scale: f64 = 0.0;
            for a in 0..n {
                for b in 0..n {
                    let s = 1.0 / (sys.length_scale[a] * sys.length_scale[b]);
                    worst = worst.max((k[(a, b)] - fd[(a, b)]).abs() * s);
                    scale = scale.max(k[(a, b)].abs() * s);
                }
            }
            println!(
                "shafts compliant={compliant} n={n}: FD {:.1e}",
                worst / scale
            );
            assert!(worst < 1e-5 * scale, "{n} dof: {worst:e} of {scale:e}");
            // The shafts' damping is in C: the load row holds -c_o on the carrier.
            let l = sys
                .dof_names
                .iter()
                .position(|d| d == "load angle")
                .unwrap();
            assert!((sys.damping[(l, 0)] + 10.0).abs() < 1e-6 * 10.0);
            let r = modal_analysis(&sys).unwrap();
            assert_eq!(r.modes.len(), n);
        }
    }
}

/// Reflected inertia of the rigid reducer (with the motor) at the carrier: `r^T M r` over the
/// kinematic direction `r = d(coordinate)/d(th_c)`: crank `-zc`, sun and motor the gear ratio
/// `i = ratio` (docs/model.md, "Modes with machine shafts").
fn reflected_inertia(sys: &LinearSystem, scene: &Scene) -> f64 {
    let zc = f64::from(scene.cycloid.pins - 1);
    let i = scene.ratio();
    sys.dof_names
        .iter()
        .enumerate()
        .map(|(a, name)| {
            let r = match name.as_str() {
                "carrier angle" => 1.0,
                "crank angle" => -zc,
                "sun angle" | "motor angle" => i,
                _ => 0.0,
            };
            sys.mass[(a, a)] * r * r
        })
        .sum()
}

#[test]
fn soft_output_shaft_gives_the_two_inertia_frequency() {
    // Torque drive, stiff drive shaft (the motor free with the reducer), very soft output
    // shaft: the lowest elastic mode is the load against the whole drive train,
    // w^2 = k_o (1/J_L + 1/J_red), J_red the reducer and motor reflected to the carrier
    // (r^T M r along the kinematic direction). The reducer's own flexibility adds a relative
    // error of order (w / w_reducer)^2 (2e-5 here).
    let (ko, jl) = (2e4, 20.0);
    let scene = torque_driven(shaft_scene(Some(ko), Some(1e9), jl, 0.05, false));
    let mut lin = Linearizer::new(&scene).unwrap();
    let (sys, _) = lin.linearise(rated_torque(), 0.2).unwrap();
    let r = modal_analysis(&sys).unwrap();
    let jr = reflected_inertia(&sys, &scene);
    let want = (ko * (1.0 / jl + 1.0 / jr)).sqrt() / std::f64::consts::TAU;
    // Mode 0 is the drive train's kinematic motion (free under a torque drive), not quite at
    // 0 Hz: under load the tangent stiffness along the kinematic path is not zero (0.6 Hz
    // here: the transmitted torque varies with the crank angle), and it shifts the shaft mode
    // by about (0.6 / 5.3)^2 / 20 = 6e-4, the error measured; tolerance 2e-3 (the issue asks
    // 1 %).
    assert!(
        r.modes[0].frequency < 0.2 * want,
        "{}",
        r.modes[0].frequency
    );
    let got = r.modes[1].frequency;
    println!("two-inertia: {got} Hz vs {want} Hz (J_red {jr} kg m^2)");
    assert!(rel(got, want) < 2e-3, "{got} vs {want}");
    let shafts = r.part_names.iter().position(|p| p == "shafts").unwrap();
    assert!(r.modes[1].energy_share[shafts] > 0.99);
}

#[test]
fn stiff_shafts_give_back_the_modes_without_shafts() {
    // Output and drive shafts 1e5 times stiffer than the reducer at the carrier/sun: the
    // load joins the carrier and (speed drive: the motor held) the sun is held, as without
    // shafts; the modes without shafts must come back within 1 % (the tolerance for
    // the rigid/stiff-bearing limit).
    let t = rated_torque();
    for compliant in [false, true] {
        let base = shaft_scene(None, None, 20.0, 0.05, compliant);
        let stiff = shaft_scene(Some(1e13), Some(1e12), 20.0, 0.05, compliant);
        let mut lin = Linearizer::new(&base).unwrap();
        let a = modal_analysis(&lin.linearise(t, 0.2).unwrap().0).unwrap();
        let mut lin = Linearizer::new(&stiff).unwrap();
        let b = modal_analysis(&lin.linearise(t, 0.2).unwrap().0).unwrap();
        assert_eq!(b.modes.len(), a.modes.len() + 2);
        let mut worst: f64 = 0.0;
        for (x, y) in a.modes.iter().zip(&b.modes) {
            worst = worst.max(rel(y.frequency, x.frequency));
        }
        println!("stiff shafts compliant={compliant}: worst {worst:.2e}");
        assert!(worst < 0.01, "{worst}");
    }
}

#[test]
fn state_of_a_slow_run_linearises_like_the_equilibrium() {
    // The rigid paper reducer turning at 1 % of the paper's speed with the load ramped to rated
    // over 0.05 s, run to 0.12 s (the paper's damping settles the ramp's transient): the
    // state at the end is the loaded equilibrium at its crank angle up to the slow motion's
    // damping and inertia forces. Its linearisation must have as many modes as the model's
    // free coordinates and give the equilibrium linearisation's frequencies within 1e-3
    // (measured in the output; the pose differs from the equilibrium by the contact
    // deflection the damping forces of the slow motion add).
    use crate::dynamics::run::driver::{RunControl, SimOptions, simulate};
    use crate::solve::Method;
    let t_rated = rated_torque();
    let mut scene = Scene::paper("rated").unwrap();
    if let Drive::Speed { speed, .. } = &mut scene.drive {
        *speed *= 0.01;
    }
    scene.load = Load::Table {
        points: vec![[0.0, 0.0], [0.05, t_rated]],
    };
    let mut opt = SimOptions::new(0.12, Method::GeneralizedAlpha);
    opt.dt = Some(1e-4);
    opt.channels = vec![];
    let rec = simulate(&scene, &opt, &RunControl::default()).unwrap();
    let (t, q, v) = rec.final_state.unwrap();
    let mut lin = Linearizer::new(&scene).unwrap();
    let p = modes_at_state(&mut lin, &scene, t, &q, &v).unwrap();
    assert_eq!(p.analysis.modes.len(), q.len());
    assert!((p.equilibrium.torque - t_rated).abs() < 1e-9 * t_rated);
    let e = modes_at(&mut lin, t_rated, p.equilibrium.crank_angle).unwrap();
    for (a, b) in p.analysis.modes.iter().zip(&e.analysis.modes) {
        println!(
            "state {} Hz, equilibrium {} Hz ({:.1e})",
            a.frequency,
            b.frequency,
            rel(a.frequency, b.frequency)
        );
        assert!(rel(a.frequency, b.frequency) < 1e-3);
    }
    assert!(p.analysis.part_names.iter().any(|n| n == "rate-dependent"));
    // A state of the wrong length names the model's count.
    let e = lin.state_point(&scene, t, &q[..1], &v[..1]).unwrap_err();
    assert!(e.to_string().contains("2 free coordinates"), "{e}");
}

/// The physical preset with its crankshafts bending (45 mm, bearings 120 mm apart, discs 40 mm
/// apart; as the LTCA's tests).
fn bending_physical() -> Scene {
    let mut s = Scene::physical("rated").unwrap();
    crate::test_util::with_bending_cranks(&mut s);
    s.validate().unwrap();
    s
}

/// The static condensation of the eccentric deflections is the limit of the full eigenproblem
/// as the eccentrics' mass vanishes: with 1e-6 kg at each node (node modes at 8 MHz) the
/// full problem's lowest frequencies are the condensed ones to the order of
/// `(w / w_node)^2` (measured at most 1.5e-7 over the 16 modes, 1.2 to 6.6 kHz); asserted
/// 1e-6. A condensation that dropped the coupling
/// `K_nk` (or used it with the wrong sign) moves the main mode by tens of per cent.
#[test]
fn condensed_bending_modes_are_the_limit_of_massless_eccentrics() {
    let scene = bending_physical();
    let mut lin = Linearizer::new(&scene).unwrap();
    let eq = lin.equilibrium(scene.load.torque(0.0), 0.0).unwrap();
    let k_big = lin.reducer_stiffness(&eq).unwrap();
    let (sys, eq) = lin.linearise_about(eq).unwrap();
    let condensed = modal_analysis(&sys).unwrap();
    let n = sys.dof_names.len();
    let nn = k_big.nrows() - n;
    assert_eq!(nn, 12);
    let mut m = vec![1e-6; n + nn];
    m[..n].copy_from_slice(lin.mass());
    // Symmetric form M^-1/2 K M^-1/2 (K symmetric at a frictionless equilibrium).
    let ks = DMatrix::from_fn(n + nn, n + nn, |i, j| {
        0.5 * (k_big[(i, j)] + k_big[(j, i)]) / (m[i] * m[j]).sqrt()
    });
    let mut w2: Vec<f64> = SymmetricEigen::new(ks)
        .eigenvalues
        .iter()
        .copied()
        .collect();
    w2.sort_by(f64::total_cmp);
    for (mode, w2) in condensed.modes.iter().zip(&w2) {
        let f = w2.sqrt() / TAU;
        assert!(
            rel(f, mode.frequency) < 1e-6,
            "{} Hz against {} Hz",
            f,
            mode.frequency
        );
    }
    assert!(w2[n].sqrt() / TAU > 1e6);
    // The static torsional compliance is kept too (a Schur complement's inverse is a block of
    // the inverse).
    let kc: DMatrix<f64> = sys.stiffness.iter().map(|p| &p.matrix).sum();
    let c_small = kc.try_inverse().unwrap()[(0, 0)];
    let c_big = k_big.try_inverse().unwrap()[(0, 0)];
    assert!(rel(c_small, c_big) < 1e-9);
    assert!(eq.split_error < 1e-12);
}
