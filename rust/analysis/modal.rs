//! Linearised modal analysis about a loaded static equilibrium (docs/model.md, "Modes").
//!
//! About the LTCA equilibrium `q0` at crank angle `psi` and output torque `T` (input held, as a
//! speed drive holds it in a run), the equations of motion linearise to
//! `M dq'' + C dq' + K dq = 0` with the models' diagonal mass `M`, the exact tangent stiffness
//! `K = -dQ/dq` and the damping `C = -dQ/dv` (contact and bearing dampers at zero velocity).
//! Undamped modes from the symmetric problem `M^-1/2 K M^-1/2 v = w^2 v`, shapes
//! `phi = M^-1/2 v` (mass-normalised); modal damping ratios `zeta = phi^T C phi / (2 w)` (the
//! diagonal of the modal damping matrix: light, non-proportional damping; Geradin & Rixen,
//! *Mechanical Vibrations*, 3rd ed., 2015, section 2.7); the share of each coupling family in a
//! mode's strain energy `phi^T K_f phi / phi^T K phi`.

use crate::analysis::ltca::Ltca;
use crate::analysis::ltca::statics::{Dense, Family, Kind, Statics, Work};
use crate::dynamics::compliant::CompliantModel;
use crate::dynamics::rigid::RigidModel;
use crate::dynamics::scene::{Joints, Scene};
use crate::error::{Result, RvdynError};
use nalgebra::{DMatrix, SymmetricEigen};

/// One mode.
#[derive(Debug, Clone, PartialEq)]
pub struct Mode {
    /// Natural frequency [Hz].
    pub frequency: f64,
    /// Modal damping ratio [-].
    pub damping_ratio: f64,
    /// Mass-normalised shape over the degrees of freedom.
    pub shape: Vec<f64>,
    /// Share of the mode's strain energy per family (names in [`Modal::families`]).
    pub energy: Vec<f64>,
}

/// The modes of a scene about one loaded equilibrium.
#[derive(Debug, Clone, PartialEq)]
pub struct Modal {
    /// Crank angle of the equilibrium [rad].
    pub crank_angle: f64,
    /// Output torque of the equilibrium [N m].
    pub torque: f64,
    /// Names of the degrees of freedom.
    pub dofs: Vec<String>,
    /// Names of the coupling families of the energy shares.
    pub families: Vec<String>,
    /// Diagonal mass [kg or kg m^2] per degree of freedom.
    pub mass: Vec<f64>,
    /// Modes sorted by frequency.
    pub modes: Vec<Mode>,
}

fn to_na(a: &Dense) -> DMatrix<f64> {
    DMatrix::from_row_slice(a.n, a.n, &a.a)
}

/// Modes of `scene` about its equilibrium at crank angle `psi` [rad] under the output torque
/// `torque` [N m] (input held).
///
/// Errors: no equilibrium (`Convergence`, from the LTCA); a degree of freedom without mass
/// (`Scene`: a body with zero inertia); a negative stiffness eigenvalue, i.e. an unstable
/// equilibrium (`Convergence`).
pub fn modes(scene: &Scene, torque: f64, psi: f64) -> Result<Modal> {
    let mut ltca = Ltca::new(scene)?;
    ltca.solve(torque, psi)?;
    let q = ltca.last_unknowns().to_vec();
    let mut st = Statics::new(scene)?;
    let n = st.dim();
    let (mass, dofs) = masses(scene, &st)?;
    if let Some((i, _)) = mass
        .iter()
        .enumerate()
        .find(|(_, m)| m.is_nan() || **m <= 0.0)
    {
        return Err(RvdynError::Scene(format!(
            "the degree of freedom {} has no mass or inertia: give the body a positive mass \
             (scene.inertias)",
            dofs[i]
        )));
    }
    let mut work = Work::new();
    let mut r = vec![0.0; n];
    let mut k = Dense::zeros(n);
    st.damping = Some(Dense::zeros(0));
    st.eval(psi, &q, torque, &mut r, &mut k, &mut work, None)?;
    let cf = st.damping.take().unwrap_or_else(|| Dense::zeros(0));
    let c = st.reduce(&cf, &work);
    let mut families = Vec::new();
    let mut fam_k = Vec::new();
    let nd = st.model.discs.len();
    let mut list: Vec<(String, Family)> = (0..nd)
        .map(|d| (format!("pins of disc {d}"), Family::Pins(d)))
        .collect();
    if st.model.mesh.is_some() {
        list.push(("sun/planet meshes".into(), Family::Mesh));
    }
    if st.kind == Kind::Compliant {
        list.push(("eccentric bearings".into(), Family::EccentricBearings));
        if st.crank_bearing.is_some() {
            list.push(("crank bearings".into(), Family::CrankBearings));
        }
    }
    for (name, f) in list {
        st.family = Some(f);
        let mut kf = Dense::zeros(n);
        st.eval(psi, &q, torque, &mut r, &mut kf, &mut work, None)?;
        families.push(name);
        fam_k.push(to_na(&kf));
    }
    st.family = None;
    let kk = to_na(&k);
    let inv_sqrt: Vec<f64> = mass.iter().map(|m| 1.0 / m.sqrt()).collect();
    let mut a = DMatrix::zeros(n, n);
    for i in 0..n {
        for j in 0..n {
            a[(i, j)] = 0.5 * (kk[(i, j)] + kk[(j, i)]) * inv_sqrt[i] * inv_sqrt[j];
        }
    }
    let eig = SymmetricEigen::new(a);
    let scale = eig.eigenvalues.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let cc = to_na(&c);
    let mut out = Vec::with_capacity(n);
    for (idx, &lam) in eig.eigenvalues.iter().enumerate() {
        if lam < -1e-9 * scale {
            return Err(RvdynError::Convergence(format!(
                "the equilibrium at crank angle {psi:.6} rad, torque {torque:.6e} N m is \
                 unstable (stiffness eigenvalue {lam:.3e} < 0): no modes about it"
            )));
        }
        let w = lam.max(0.0).sqrt();
        let v = eig.eigenvectors.column(idx);
        let phi: Vec<f64> = (0..n).map(|i| v[i] * inv_sqrt[i]).collect();
        let p = nalgebra::DVector::from_vec(phi.clone());
        let kphi = (p.transpose() * &kk * &p)[(0, 0)];
        let cphi = (p.transpose() * &cc * &p)[(0, 0)];
        let energy = fam_k
            .iter()
            .map(|kf| {
                if kphi > 0.0 {
                    (p.transpose() * kf * &p)[(0, 0)] / kphi
                } else {
                    0.0
                }
            })
            .collect();
        out.push(Mode {
            frequency: w / std::f64::consts::TAU,
            damping_ratio: if w > 0.0 { cphi / (2.0 * w) } else { 0.0 },
            shape: phi,
            energy,
        });
    }
    out.sort_by(|a, b| a.frequency.total_cmp(&b.frequency));
    Ok(Modal {
        crank_angle: psi,
        torque,
        dofs,
        families,
        mass,
        modes: out,
    })
}

/// Natural frequencies [Hz] at `points` crank angles over one mesh period (the stiffness varies
/// with the crank angle): `(crank angles [rad], frequencies [point][mode])`.
pub fn modes_over_period(
    scene: &Scene,
    torque: f64,
    points: usize,
) -> Result<(Vec<f64>, Vec<Vec<f64>>)> {
    if points == 0 {
        return Err(RvdynError::Parameter(
            "modes over a mesh period need at least one crank angle".into(),
        ));
    }
    let period = crate::analysis::ltca::mesh_period(scene);
    let angles: Vec<f64> = (0..points)
        .map(|i| period * i as f64 / points as f64)
        .collect();
    let freqs = angles
        .iter()
        .map(|&p| modes(scene, torque, p).map(|m| m.modes.iter().map(|x| x.frequency).collect()))
        .collect::<Result<Vec<Vec<f64>>>>()?;
    Ok((angles, freqs))
}

/// The excitation orders of a scene, as multiples of the input rotation frequency
/// (docs/model.md, "Excitation orders"): carrier `1/i`, crank and disc-centre orbit `zc/i`,
/// pin-pass `zp zc / i` and its 2nd and 3rd harmonics, and with a first stage the input `1`
/// and the sun mesh `z_s (i - 1)/i`.
pub fn excitation_orders(scene: &Scene) -> Vec<(String, f64)> {
    let i = scene.ratio().abs();
    let zp = f64::from(scene.cycloid.pins);
    let zc = zp - 1.0;
    let mut out = vec![
        ("carrier (output)".to_string(), 1.0 / i),
        ("crank orbit".to_string(), zc / i),
        ("pin pass".to_string(), zp * zc / i),
        ("pin pass x2".to_string(), 2.0 * zp * zc / i),
        ("pin pass x3".to_string(), 3.0 * zp * zc / i),
    ];
    if let Some(s) = &scene.stage1 {
        out.push(("input".to_string(), 1.0));
        out.push(("sun mesh".to_string(), f64::from(s.z_sun) * (i - 1.0) / i));
    }
    out
}

/// One crossing of an excitation order with a natural frequency in a Campbell diagram.
#[derive(Debug, Clone, PartialEq)]
pub struct Crossing {
    /// Name of the order.
    pub order: String,
    /// Order value (multiple of the input rotation frequency).
    pub order_value: f64,
    /// Index of the mode (sorted by frequency).
    pub mode: usize,
    /// Natural frequency [Hz].
    pub frequency: f64,
    /// Input speed at the crossing [rad/s]: `2 pi f / order`.
    pub input_speed: f64,
}

/// The crossings of `orders` with the natural frequencies `frequencies` [Hz] for input speeds
/// in `[speed_min, speed_max]` [rad/s] (the natural frequencies of the linearised model do not
/// depend on the speed). Errors (`Parameter`) for a speed range that is not finite, not
/// positive or empty.
pub fn campbell_crossings(
    frequencies: &[f64],
    orders: &[(String, f64)],
    speed_min: f64,
    speed_max: f64,
) -> Result<Vec<Crossing>> {
    if !(speed_min.is_finite()
        && speed_max.is_finite()
        && speed_min >= 0.0
        && speed_max > speed_min)
    {
        return Err(RvdynError::Parameter(format!(
            "the Campbell speed range must satisfy 0 <= min < max (finite, rad/s), got              [{speed_min}, {speed_max}]"
        )));
    }
    let mut out = Vec::new();
    for (name, order) in orders {
        for (m, &f) in frequencies.iter().enumerate() {
            let w = std::f64::consts::TAU * f / order;
            if w >= speed_min && w <= speed_max {
                out.push(Crossing {
                    order: name.clone(),
                    order_value: *order,
                    mode: m,
                    frequency: f,
                    input_speed: w,
                });
            }
        }
    }
    out.sort_by(|a, b| a.input_speed.total_cmp(&b.input_speed));
    Ok(out)
}

/// Diagonal masses and names of the unknowns of `st`.
fn masses(scene: &Scene, st: &Statics) -> Result<(Vec<f64>, Vec<String>)> {
    match scene.joints {
        Joints::Rigid => {
            let m = RigidModel::new(scene)?;
            let mut mass = vec![m.mass[0]];
            let mut names = vec!["carrier rotation".to_string()];
            if m.mesh.is_some() {
                mass.push(m.mass[1]);
                names.push("crank rotation".into());
            }
            Ok((mass, names))
        }
        Joints::Compliant { .. } => {
            let m = CompliantModel::new(scene)?;
            let names = st
                .unknowns
                .iter()
                .map(|&i| {
                    if i == 0 {
                        "carrier rotation".to_string()
                    } else if i < 2 + 3 * st.cranks {
                        let c = (i - 2) / 3;
                        let what = ["x", "y", "rotation"][(i - 2) % 3];
                        format!("crank {c} {what}")
                    } else {
                        let j = i - 2 - 3 * st.cranks;
                        let what = ["x", "y", "rotation"][j % 3];
                        format!("disc {} {what}", j / 3)
                    }
                })
                .collect();
            Ok((st.unknowns.iter().map(|&i| m.mass[i]).collect(), names))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::classical_levers;
    use crate::dynamics::scene::ContactLawSpec;
    use crate::geometry::CycloidGeometry;

    fn linear(k: f64) -> ContactLawSpec {
        ContactLawSpec::Impact {
            stiffness: k,
            exponent: 1.0,
            max_damping: 0.0,
            damping_depth: 1e-5,
        }
    }

    /// Sum of `l^2` over the pins a positive output torque loads (negative classical lever),
    /// both discs.
    fn loaded_sum(g: &CycloidGeometry, psi: f64, power: i32) -> f64 {
        [0.0, std::f64::consts::PI]
            .iter()
            .flat_map(|ph| classical_levers(g, psi + ph))
            .filter(|l| *l < 0.0)
            .map(|l| l.abs().powi(power))
            .sum()
    }

    /// One torsional DOF: rigid joints, cranks held (no first stage), linear pin law `k`, at a
    /// vanishing load (1e-3 N m: the geometric term `F hess g` is ~1e-14 of `k l^2`):
    /// `w^2 = k sum(l_j^2) / M_c` over the loaded pins of both discs, `l_j` the classical
    /// levers. Asserted to 1e-9.
    #[test]
    fn one_dof_torsional_frequency_is_the_closed_form() {
        let mut s = Scene::paper("rated").unwrap();
        s.stage1 = None;
        s.contact.pin = linear(1e9);
        let g = CycloidGeometry::new(s.cycloid).unwrap();
        let psi = 0.37;
        let modal = modes(&s, 1e-3, psi).unwrap();
        assert_eq!(modal.modes.len(), 1);
        let m = RigidModel::new(&s).unwrap().mass[0];
        let w = (1e9 * loaded_sum(&g, psi, 2) / m).sqrt();
        let f = w / std::f64::consts::TAU;
        assert!((modal.modes[0].frequency / f - 1.0).abs() < 1e-9);
        assert!((modal.modes[0].energy.iter().sum::<f64>() - 1.0).abs() < 1e-9);
    }

    /// Two DOFs (carrier, crank) with the first stage: linear pin law `k`, linear mesh law
    /// `k_m` on `n` meshes. With the classical levers `l_c` about the disc centre and
    /// `l_a = l_c / zc` about the reducer axis (the normals pass through the pitch point, at
    /// `e zp` from the axis and `e zc` from the disc centre, so `O x N = l_c / zc`):
    /// `K_cc = k S2 + n k_m (r_bs + r_bp)^2`, `K_ca = k S2 / zc - n k_m (r_bs + r_bp) r_bp`,
    /// `K_aa = k S2 / zc^2 + n k_m r_bp^2` with the sign of `l_a` following `l_c`
    /// (`S2 = sum l_c^2`), and the frequencies from `det(K - w^2 M) = 0`. Asserted to 1e-9.
    #[test]
    fn two_dof_torsional_frequencies_are_the_closed_form() {
        let mut s = Scene::paper("rated").unwrap();
        let (k, km) = (1e9, 3e8);
        s.contact.pin = linear(k);
        s.contact.mesh = linear(km);
        let g = CycloidGeometry::new(s.cycloid).unwrap();
        let psi = 0.21;
        let modal = modes(&s, 1e-3, psi).unwrap();
        assert_eq!(modal.modes.len(), 2);
        let rm = RigidModel::new(&s).unwrap();
        let mesh = rm.mesh.unwrap();
        let (rbs, rbp, n) = (
            mesh.sun_base_radius,
            mesh.planet_base_radius,
            mesh.count as f64,
        );
        let s2 = loaded_sum(&g, psi, 2);
        let zc = 23.0;
        let kcc = k * s2 + n * km * (rbs + rbp).powi(2);
        let kca = k * s2 / zc - n * km * (rbs + rbp) * rbp;
        let kaa = k * s2 / (zc * zc) + n * km * rbp * rbp;
        let (mc, ma) = (rm.mass[0], rm.mass[1]);
        // det([[kcc - w2 mc, kca], [kca, kaa - w2 ma]]) = 0.
        let a = mc * ma;
        let b = -(kcc * ma + kaa * mc);
        let c = kcc * kaa - kca * kca;
        let disc = (b * b - 4.0 * a * c).sqrt();
        let w2 = [(-b - disc) / (2.0 * a), (-b + disc) / (2.0 * a)];
        for (m, w2) in modal.modes.iter().zip(w2) {
            let f = w2.sqrt() / std::f64::consts::TAU;
            assert!((m.frequency / f - 1.0).abs() < 1e-9, "{} {f}", m.frequency);
        }
        assert_eq!(
            modal.families,
            vec!["pins of disc 0", "pins of disc 1", "sun/planet meshes"]
        );
    }

    #[test]
    fn orders_and_campbell_crossings() {
        let s = Scene::paper("rated").unwrap();
        let orders = excitation_orders(&s);
        let pin = orders.iter().find(|o| o.0 == "pin pass").unwrap().1;
        assert!((pin - 552.0 / 57.0).abs() < 1e-12);
        let mesh = orders.iter().find(|o| o.0 == "sun mesh").unwrap().1;
        assert!((mesh - 1008.0 / 57.0).abs() < 1e-12);
        // A 224.03 Hz mode is crossed by the pin-pass order at the paper's input speed.
        let w_in = 8328f64.to_radians();
        let f = pin * w_in / std::f64::consts::TAU;
        let c = campbell_crossings(&[f], &orders, 0.5 * w_in, 2.0 * w_in).unwrap();
        let hit = c.iter().find(|x| x.order == "pin pass").unwrap();
        assert!((hit.input_speed / w_in - 1.0).abs() < 1e-12);
        assert!((f - 224.03).abs() < 0.01);
        assert!(campbell_crossings(&[f], &orders, 1.0, 0.5).is_err());
        let (angles, freqs) = modes_over_period(&s, 43_921.3, 3).unwrap();
        assert_eq!(angles.len(), 3);
        assert!(freqs.iter().all(|f| f.len() == 2 && f[0] > 0.0));
    }

    #[test]
    fn compliant_modes_count_names_and_energy() {
        let mut s = Scene::paper("rated").unwrap();
        s.joints = crate::dynamics::compliant::default_joints();
        let modal = modes(&s, 43_921.3, 0.1).unwrap();
        // Unknowns: carrier, 3 cranks x (x, y, rotation), 2 discs x 3.
        assert_eq!(modal.modes.len(), 16);
        assert_eq!(modal.dofs.len(), 16);
        assert_eq!(modal.dofs[1], "crank 0 x");
        assert_eq!(modal.dofs[15], "disc 1 rotation");
        for m in &modal.modes {
            assert!(m.frequency > 0.0 && m.frequency.is_finite());
            let total: f64 = m.energy.iter().sum();
            assert!((total - 1.0).abs() < 1e-6, "{total}");
            // The paper's pin damping (1e5 N s/m per contact) overdamps some modes.
            assert!(m.damping_ratio >= 0.0 && m.damping_ratio.is_finite());
        }
    }
}
#[cfg(test)]
mod table {
    /// The mode table of the compliant paper scene at rated load (printed; run with
    /// `--ignored --nocapture`).
    #[test]
    #[ignore]
    fn print_modes() {
        let mut s = crate::dynamics::scene::Scene::paper("rated").unwrap();
        s.joints = crate::dynamics::compliant::default_joints();
        let m = super::modes(&s, 43_921.3, 0.1).unwrap();
        println!("{:?}", m.families);
        for md in &m.modes {
            let (imax, _) =
                md.shape
                    .iter()
                    .zip(&m.mass)
                    .enumerate()
                    .fold(
                        (0, 0.0),
                        |b, (i, (p, ms))| if p * p * ms > b.1 { (i, p * p * ms) } else { b },
                    );
            println!(
                "{:9.1} Hz zeta {:.3} main dof {:18} energy {:?}",
                md.frequency,
                md.damping_ratio,
                m.dofs[imax],
                md.energy
                    .iter()
                    .map(|e| (e * 100.0).round())
                    .collect::<Vec<_>>()
            );
        }
    }
}
