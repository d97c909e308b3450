//! Modes of a reducer scene at an operating point, over a mesh period, and over the input
//! speed (Campbell diagram).

use crate::analysis::modes::{
    DampedTrack, Equilibrium, Linearizer, ModalAnalysis, modal_analysis_near,
};
use crate::analysis::orders::{Crossing, ExcitationOrder, campbell_crossings, scene_orders};
use crate::dynamics::scene::Scene;
use crate::error::{Result, RvdynError};

/// The modes at one operating point with the equilibrium they were linearised about.
#[derive(Debug, Clone)]
pub struct ModalPoint {
    /// The equilibrium linearised about.
    pub equilibrium: Equilibrium,
    /// Its modes.
    pub analysis: ModalAnalysis,
    /// The linearised system's mass matrix, row-major n x n [kg, kg m^2].
    pub mass: Vec<f64>,
    /// The summed tangent stiffness, row-major n x n [N/m, N m/rad].
    pub stiffness: Vec<f64>,
    /// The damping matrix, row-major n x n [N s/m, N m s/rad].
    pub damping: Vec<f64>,
}

/// Modes of `scene` about its equilibrium at `crank_angle` \[rad\] under the output torque
/// `torque` [N m].
///
/// # Example
///
/// ```
/// use rvdyn::analysis::modes::{Linearizer, modes_at};
/// use rvdyn::dynamics::scene::Scene;
/// // The paper's reducer with rigid joints: two modes (carrier and crank angle).
/// let mut lin = Linearizer::new(&Scene::paper("paper").unwrap()).unwrap();
/// let mut f = |torque: f64| -> Vec<f64> {
///     let p = modes_at(&mut lin, torque, 0.0).unwrap();
///     p.analysis.modes.iter().map(|m| m.frequency).collect()
/// };
/// let (light, heavy) = (f(1000.0), f(4000.0));
/// assert_eq!(light.len(), 2);
/// // Its contacts are Hertzian (F = k x^1.5, tangent stiffness ~ F^(1/3)), so the
/// // frequencies grow about as torque^(1/6): 4^(1/6) = 1.26.
/// assert!((heavy[0] / light[0] - 4f64.powf(1.0 / 6.0)).abs() < 0.01);
/// ```
pub fn modes_at(lin: &mut Linearizer, torque: f64, crank_angle: f64) -> Result<ModalPoint> {
    let (sys, eq) = lin.linearise(torque, crank_angle)?;
    point(sys, eq, None)
}

/// [`modes_at`] at each of `crank_angles` \[rad\] in turn (equilibria warm-started, damped
/// modes matched by tracking from the previous angle where unambiguous).
///
/// # Example
///
/// ```
/// use rvdyn::analysis::modes::{Linearizer, modes_over};
/// use rvdyn::dynamics::scene::{PAPER_PRINTED_LOAD, Scene};
/// let mut lin = Linearizer::new(&Scene::paper("paper").unwrap()).unwrap();
/// let angles = [0.0, 0.1, 0.2, 0.3]; // crank angles [rad]
/// let points = modes_over(&mut lin, PAPER_PRINTED_LOAD, &angles).unwrap();
/// assert_eq!(points.len(), angles.len());
/// assert_eq!(points[2].equilibrium.crank_angle, 0.2);
/// // The first mode, about 761 Hz, moves by less than 1 % as the pins roll.
/// let f0 = points[0].analysis.modes[0].frequency;
/// assert!(points.iter().all(|p| (p.analysis.modes[0].frequency / f0 - 1.0).abs() < 0.01));
/// ```
pub fn modes_over(
    lin: &mut Linearizer,
    torque: f64,
    crank_angles: &[f64],
) -> Result<Vec<ModalPoint>> {
    let mut out: Vec<ModalPoint> = Vec::with_capacity(crank_angles.len());
    for &a in crank_angles {
        let (sys, eq) = lin.linearise(torque, a)?;
        let previous = out.last().map(|p| &p.analysis.damped_track);
        let p = point(sys, eq, previous)?;
        out.push(p);
    }
    Ok(out)
}

fn point(
    sys: crate::analysis::modes::LinearSystem,
    eq: Equilibrium,
    previous: Option<&DampedTrack>,
) -> Result<ModalPoint> {
    let analysis = modal_analysis_near(&sys, previous)?;
    let n = sys.dof_names.len();
    let mut k = nalgebra::DMatrix::<f64>::zeros(n, n);
    for p in &sys.stiffness {
        k += &p.matrix;
    }
    let row_major = |m: &nalgebra::DMatrix<f64>| -> Vec<f64> {
        (0..n)
            .flat_map(|i| (0..n).map(move |j| (i, j)))
            .map(|(i, j)| m[(i, j)])
            .collect()
    };
    Ok(ModalPoint {
        equilibrium: eq,
        mass: row_major(&sys.mass),
        stiffness: row_major(&k),
        damping: row_major(&sys.damping),
        analysis,
    })
}

/// A Campbell diagram: natural frequencies over input speed and their crossings with the
/// excitation orders.
#[derive(Debug, Clone)]
pub struct Campbell {
    /// Input speeds [rad/s].
    pub speeds: Vec<f64>,
    /// Output torque at each speed [N m].
    pub torques: Vec<f64>,
    /// Natural frequency of the matched damped eigenvalue(s), `|lambda| / 2 pi` (the undamped
    /// one when unmatched) \[Hz\], `[speed][mode]`: where the mode resonates, which under
    /// non-proportional damping can lie far from the undamped frequency (for proportional
    /// damping the two are equal).
    pub frequencies: Vec<Vec<f64>>,
    /// Damping ratio of the matched damped eigenvalue (the modal estimate when unmatched),
    /// `[speed][mode]`.
    pub damping_ratios: Vec<Vec<f64>>,
    /// Indices of the modes kept (those in the frequency range at the first speed).
    pub modes: Vec<usize>,
    /// The excitation orders of the scene.
    pub orders: Vec<ExcitationOrder>,
    /// Crossings (mode indices refer to `modes`' positions).
    pub crossings: Vec<Crossing>,
}

/// The Campbell diagram of `scene` at the crank angle `crank_angle` \[rad\]: at each input speed
/// `speeds[s]` [rad/s] (increasing) the modes about the equilibrium under `torques[s]` [N m];
/// the modes in `frequency_range` \[Hz\] (at the first speed; all if `None`) are kept, and the
/// crossings of each excitation order (pin-pass and sun-mesh harmonics up to `harmonics`) with
/// them returned. The speed enters only through the torque (the models have no gyroscopic
/// or speed-dependent terms: constant masses in planar absolute or reduced coordinates).
///
/// # Example
///
/// ```
/// use rvdyn::analysis::modes::campbell;
/// use rvdyn::dynamics::scene::{PAPER_PRINTED_LOAD, Scene};
/// use std::f64::consts::TAU;
/// let scene = Scene::paper("paper").unwrap();
/// let (speeds, torques) = ([100.0, 400.0], [PAPER_PRINTED_LOAD; 2]); // [rad/s], [N m]
/// let c = campbell(&scene, &speeds, &torques, 0.0, 1, None).unwrap();
/// // Both modes (761 and 1052 Hz) meet the sun-mesh order z_sun (i - 1) / i = 18 * 56/57.
/// assert_eq!(c.crossings.len(), 2);
/// let x = &c.crossings[0];
/// assert_eq!(c.orders[x.order].name, "sun_mesh");
/// let speed = c.frequencies[0][x.mode] * TAU / (18.0 * 56.0 / 57.0);
/// assert!((x.speed / speed - 1.0).abs() < 1e-9); // about 270 rad/s
/// ```
pub fn campbell(
    scene: &Scene,
    speeds: &[f64],
    torques: &[f64],
    crank_angle: f64,
    harmonics: u32,
    frequency_range: Option<(f64, f64)>,
) -> Result<Campbell> {
    if torques.len() != speeds.len() {
        return Err(RvdynError::Parameter(format!(
            "{} torques for {} speeds",
            torques.len(),
            speeds.len()
        )));
    }
    let orders = scene_orders(scene, harmonics)?;
    // Check the speeds before the work.
    campbell_crossings(speeds, &vec![Vec::new(); speeds.len()], &orders)?;
    let mut lin = Linearizer::new(scene)?;
    let mut frequencies = Vec::with_capacity(speeds.len());
    let mut damping_ratios = Vec::with_capacity(speeds.len());
    let mut modes: Option<Vec<usize>> = None;
    let mut previous: Option<DampedTrack> = None;
    for &t in torques {
        let (sys, _) = lin.linearise(t, crank_angle)?;
        let a = modal_analysis_near(&sys, previous.as_ref())?;
        previous = Some(a.damped_track.clone());
        let keep = match &modes {
            Some(m) => m.clone(),
            None => {
                let m = match frequency_range {
                    Some((lo, hi)) => a.modes_in_range(lo, hi)?,
                    None => (0..a.modes.len()).collect(),
                };
                modes = Some(m.clone());
                m
            }
        };
        // The matched damped eigenvalue's, else the undamped frequency and modal estimate.
        let (f, z): (Vec<f64>, Vec<f64>) = keep
            .iter()
            .map(|&i| {
                let m = &a.modes[i];
                match &m.damped {
                    Some(d) => (d.natural_frequency, d.damping_ratio),
                    None => (m.frequency, m.modal_damping_ratio),
                }
            })
            .unzip();
        frequencies.push(f);
        damping_ratios.push(z);
    }
    let crossings = campbell_crossings(speeds, &frequencies, &orders)?;
    Ok(Campbell {
        speeds: speeds.to_vec(),
        torques: torques.to_vec(),
        frequencies,
        damping_ratios,
        modes: modes.unwrap_or_default(),
        orders,
        crossings,
    })
}

/// Modes of `scene` about the state `(q, v)` at time `t` \[s\] of a dynamic run (the run
/// model's free coordinates and velocities, `ReducerModel::initial_state` order), with the
/// linearizer `lin` built from the same scene (see [`Linearizer::state_point`]).
///
/// # Example
///
/// ```
/// use rvdyn::analysis::modes::{Linearizer, modes_at_state};
/// use rvdyn::dynamics::run::driver::{RunControl, SimOptions, simulate};
/// use rvdyn::dynamics::scene::Scene;
/// use rvdyn::solve::Method;
/// let scene = Scene::paper("paper").unwrap();
/// let options = SimOptions::new(1e-3, Method::GeneralizedAlpha);
/// let rec = simulate(&scene, &options, &RunControl::default()).unwrap();
/// let (t, q, v) = rec.final_state.unwrap(); // 1 ms after the start
/// let mut lin = Linearizer::new(&scene).unwrap();
/// let p = modes_at_state(&mut lin, &scene, t, &q, &v).unwrap();
/// assert!(!p.equilibrium.is_equilibrium && p.equilibrium.time == t);
/// assert_eq!(p.analysis.modes.len(), 2);
/// assert!(p.analysis.modes.iter().all(|m| m.frequency > 0.0));
/// ```
pub fn modes_at_state(
    lin: &mut Linearizer,
    scene: &Scene,
    t: f64,
    q: &[f64],
    v: &[f64],
) -> Result<ModalPoint> {
    let eq = lin.state_point(scene, t, q, v)?;
    let (sys, eq) = lin.linearise_about(eq)?;
    point(sys, eq, None)
}
