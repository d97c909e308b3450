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
