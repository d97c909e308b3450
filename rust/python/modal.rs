//! Bindings for the vibration analyses: excitation orders and Campbell crossings
//! (`rvdyn.analysis.spectrum`, `rvdyn.analysis.campbell` wrap these private functions).

use crate::analysis::orders::{ExcitationOrder, campbell_crossings, scene_orders};
use crate::dynamics::scene::Scene;
use pyo3::prelude::*;

/// Excitation orders of a scene (JSON) as `(name, harmonic, order, label)` tuples, by
/// increasing order; pin-pass and sun-mesh harmonics 1..=`harmonics`.
#[pyfunction]
#[pyo3(signature = (scene_json, harmonics = 3))]
fn excitation_orders(
    scene_json: &str,
    harmonics: u32,
) -> PyResult<Vec<(String, u32, f64, String)>> {
    let scene = Scene::from_json(scene_json)?;
    Ok(scene_orders(&scene, harmonics)?
        .into_iter()
        .map(|o| (o.name, o.harmonic, o.order, o.label))
        .collect())
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
    orders: Vec<(String, u32, f64, String)>,
) -> PyResult<Vec<(f64, f64, usize, usize)>> {
    let orders: Vec<ExcitationOrder> = orders
        .into_iter()
        .map(|(name, harmonic, order, label)| ExcitationOrder {
            name,
            harmonic,
            order,
            label,
        })
        .collect();
    let c = py.detach(|| campbell_crossings(&speeds, &frequencies, &orders))?;
    Ok(c.into_iter()
        .map(|x| (x.speed, x.frequency, x.order, x.mode))
        .collect())
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(excitation_orders, m)?)?;
    m.add_function(wrap_pyfunction!(campbell_crossings_py, m)?)?;
    Ok(())
}
