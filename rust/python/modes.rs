//! Bindings for the vibration analyses: excitation orders, modes about an equilibrium, modes
//! over crank angle, Campbell diagrams (`python/rvdyn/analysis/{spectrum,modes,campbell}.py`
//! wrap these private functions).

use crate::analysis::modes::{Linearizer, ModalPoint, campbell, modes_at_state, modes_over};
use crate::analysis::orders::{ExcitationOrder, campbell_crossings, scene_orders};
use crate::dynamics::scene::Scene;
use numpy::IntoPyArray;
use numpy::ndarray::Array2;
use pyo3::prelude::*;
use pyo3::types::PyDict;

type OrderTuple = (String, u32, f64, String);

fn array2<'py>(
    py: Python<'py>,
    rows: usize,
    cols: usize,
    v: Vec<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let a = Array2::from_shape_vec((rows, cols), v)
        .map_err(|e| crate::python::parameter_error(format!("internal shape error: {e}")))?;
    Ok(a.into_pyarray(py).into_any())
}

/// Excitation orders of a scene (JSON) as `(name, harmonic, order, label)` tuples, by
/// increasing order; pin-pass and sun-mesh harmonics 1..=`harmonics`.
#[pyfunction]
#[pyo3(signature = (scene_json, harmonics = 3))]
fn excitation_orders(scene_json: &str, harmonics: u32) -> PyResult<Vec<OrderTuple>> {
    let scene = Scene::from_json(scene_json)?;
    Ok(scene_orders(&scene, harmonics)?
        .into_iter()
        .map(|o| (o.name, o.harmonic, o.order, o.label))
        .collect())
}

fn to_orders(orders: Vec<OrderTuple>) -> Vec<ExcitationOrder> {
    orders
        .into_iter()
        .map(|(name, harmonic, order, label)| ExcitationOrder {
            name,
            harmonic,
            order,
            label,
        })
        .collect()
}

/// Crossings of order lines with natural-frequency curves: `speeds` [rad/s] (n),
/// `frequencies` [Hz] (n rows of m modes), `orders` as `(name, harmonic, order, label)`.
/// Returns `(speed [rad/s], frequency [Hz], order index, mode index)` tuples.
#[pyfunction]
#[pyo3(name = "campbell_crossings")]
fn campbell_crossings_py(
    py: Python<'_>,
    speeds: Vec<f64>,
    frequencies: Vec<Vec<f64>>,
    orders: Vec<OrderTuple>,
) -> PyResult<Vec<(f64, f64, usize, usize)>> {
    let orders = to_orders(orders);
    let c = py.detach(|| campbell_crossings(&speeds, &frequencies, &orders))?;
    Ok(c.into_iter()
        .map(|x| (x.speed, x.frequency, x.order, x.mode))
        .collect())
}

fn point_dict<'py>(py: Python<'py>, p: &ModalPoint) -> PyResult<Bound<'py, PyDict>> {
    let a = &p.analysis;
    let n = a.dof_names.len();
    let nm = a.modes.len();
    let d = PyDict::new(py);
    d.set_item("dof_names", a.dof_names.clone())?;
    d.set_item("part_names", a.part_names.clone())?;
    d.set_item(
        "frequency",
        a.modes.iter().map(|m| m.frequency).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "omega_squared",
        a.modes.iter().map(|m| m.omega_squared).collect::<Vec<_>>(),
    )?;
    let damped = |f: &dyn Fn(&crate::analysis::modes::DampedMode) -> f64, fallback: f64| {
        a.modes
            .iter()
            .map(|m| m.damped.as_ref().map_or(fallback, f))
            .collect::<Vec<f64>>()
    };
    d.set_item(
        "damped_natural_frequency",
        damped(&|x| x.natural_frequency, f64::NAN),
    )?;
    d.set_item(
        "damped_frequency",
        damped(&|x| x.damped_frequency, f64::NAN),
    )?;
    d.set_item("damping_ratio", damped(&|x| x.damping_ratio, f64::NAN))?;
    d.set_item("mac", damped(&|x| x.mac, f64::NAN))?;
    d.set_item(
        "matched",
        a.modes
            .iter()
            .map(|m| m.damped.is_some())
            .collect::<Vec<_>>(),
    )?;
    d.set_item(
        "modal_damping_ratio",
        a.modes
            .iter()
            .map(|m| m.modal_damping_ratio)
            .collect::<Vec<_>>(),
    )?;
    d.set_item(
        "rigid_body",
        a.modes.iter().map(|m| m.rigid_body).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "unstable",
        a.modes.iter().map(|m| m.unstable).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "dominant_dof",
        a.modes.iter().map(|m| m.dominant_dof).collect::<Vec<_>>(),
    )?;
    let shapes: Vec<f64> = a
        .modes
        .iter()
        .flat_map(|m| m.display_shape.iter().copied())
        .collect();
    d.set_item("shape", array2(py, nm, n, shapes)?)?;
    let np = a.part_names.len();
    let energy: Vec<f64> = a
        .modes
        .iter()
        .flat_map(|m| m.energy_share.iter().copied())
        .collect();
    d.set_item("energy_share", array2(py, nm, np, energy)?)?;
    d.set_item(
        "eigenvalues",
        a.eigenvalues
            .iter()
            .map(|l| (l.re, l.im))
            .collect::<Vec<_>>(),
    )?;
    d.set_item("stiffness_asymmetry", a.stiffness_asymmetry)?;
    d.set_item("damping_asymmetry", a.damping_asymmetry)?;
    d.set_item("mass", array2(py, n, n, p.mass.clone())?)?;
    d.set_item("stiffness", array2(py, n, n, p.stiffness.clone())?)?;
    d.set_item("damping", array2(py, n, n, p.damping.clone())?)?;
    let eq = &p.equilibrium;
    d.set_item("crank_angle", eq.crank_angle)?;
    d.set_item("torque", eq.torque)?;
    d.set_item("equilibrium", eq.unknowns.clone())?;
    d.set_item("residual", eq.residual)?;
    d.set_item("split_error", eq.split_error)?;
    d.set_item("time", eq.time)?;
    d.set_item("shaft_angles", eq.shaft_angles.to_vec())?;
    Ok(d)
}

/// Modes of a scene about its equilibrium at each crank angle [rad] under the output torque
/// [N m] (warm-started in turn): one dict per angle (see `rvdyn.modes`).
#[pyfunction]
fn modes<'py>(
    py: Python<'py>,
    scene_json: &str,
    torque: f64,
    crank_angles: Vec<f64>,
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let scene = Scene::from_json(scene_json)?;
    let points = py.detach(|| -> crate::Result<Vec<ModalPoint>> {
        let mut lin = Linearizer::new(&scene)?;
        modes_over(&mut lin, torque, &crank_angles)
    })?;
    points.iter().map(|p| point_dict(py, p)).collect()
}

/// Modes of a scene about the state `(q, v)` at time `t` [s] of a dynamic run: `q`, `v` the
/// run model's free coordinates [rad, m] and velocities [rad/s, m/s] (see `rvdyn.modes_at`).
#[pyfunction]
fn modes_state<'py>(
    py: Python<'py>,
    scene_json: &str,
    t: f64,
    q: Vec<f64>,
    v: Vec<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let scene = Scene::from_json(scene_json)?;
    let p = py.detach(|| -> crate::Result<ModalPoint> {
        let mut lin = Linearizer::new(&scene)?;
        modes_at_state(&mut lin, &scene, t, &q, &v)
    })?;
    point_dict(py, &p)
}

/// The rigid model's free coordinates as indices into `[carrier, crank, sun, load, motor]`
/// (its `initial_state` order); `None` for compliant joints.
#[pyfunction]
fn rigid_coordinates(scene_json: &str) -> PyResult<Option<Vec<usize>>> {
    let scene = Scene::from_json(scene_json)?;
    if !matches!(scene.joints, crate::dynamics::scene::Joints::Rigid) {
        return Ok(None);
    }
    let m = crate::dynamics::model::rigid::RigidModel::new(&scene)?;
    Ok(Some(
        crate::dynamics::model::rigid_system::RigidSystem::new(&m)
            .coords
            .clone(),
    ))
}

/// Campbell diagram: natural frequencies over input speeds [rad/s] with the output torque at
/// each speed [N m], at one crank angle [rad].
#[pyfunction]
#[pyo3(signature = (scene_json, speeds, torques, crank_angle = 0.0, harmonics = 3, frequency_range = None))]
fn campbell_diagram<'py>(
    py: Python<'py>,
    scene_json: &str,
    speeds: Vec<f64>,
    torques: Vec<f64>,
    crank_angle: f64,
    harmonics: u32,
    frequency_range: Option<(f64, f64)>,
) -> PyResult<Bound<'py, PyDict>> {
    let scene = Scene::from_json(scene_json)?;
    let c = py.detach(|| {
        campbell(
            &scene,
            &speeds,
            &torques,
            crank_angle,
            harmonics,
            frequency_range,
        )
    })?;
    let d = PyDict::new(py);
    let ns = c.speeds.len();
    let nm = c.modes.len();
    d.set_item("modes", c.modes.clone())?;
    d.set_item(
        "frequency",
        array2(
            py,
            ns,
            nm,
            c.frequencies.iter().flatten().copied().collect(),
        )?,
    )?;
    d.set_item(
        "damping_ratio",
        array2(
            py,
            ns,
            nm,
            c.damping_ratios.iter().flatten().copied().collect(),
        )?,
    )?;
    d.set_item(
        "orders",
        c.orders
            .iter()
            .map(|o| (o.name.clone(), o.harmonic, o.order, o.label.clone()))
            .collect::<Vec<_>>(),
    )?;
    d.set_item(
        "crossings",
        c.crossings
            .iter()
            .map(|x| (x.speed, x.frequency, x.order, x.mode))
            .collect::<Vec<_>>(),
    )?;
    Ok(d)
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(excitation_orders, m)?)?;
    m.add_function(wrap_pyfunction!(campbell_crossings_py, m)?)?;
    m.add_function(wrap_pyfunction!(modes, m)?)?;
    m.add_function(wrap_pyfunction!(modes_state, m)?)?;
    m.add_function(wrap_pyfunction!(rigid_coordinates, m)?)?;
    m.add_function(wrap_pyfunction!(campbell_diagram, m)?)?;
    Ok(())
}
