//! Bindings of the quasi-static analysis (`rvdyn.analysis`): a solver object that keeps its
//! warm start and its points across calls. Every number is computed by
//! [`crate::analysis::ltca`]; this file converts and packs.

use crate::analysis::ltca::export::{loads_csv, loads_json, worst_loads};
use crate::analysis::ltca::{Ltca, LtcaPoint, NewtonOptions};
use crate::error::RvdynError;
use crate::python::scene::CompiledScene;
use numpy::{IntoPyArray, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::Mutex;

/// The loaded tooth contact analysis of one scene (use `rvdyn.analysis`, which wraps it).
#[pyclass(name = "LtcaSolver", module = "rvdyn._core")]
pub(crate) struct LtcaSolver {
    /// Behind a mutex: the core keeps per-contact warm starts in cells (not `Sync`).
    ltca: Mutex<Ltca>,
    face_width: f64,
    /// Every point solved by `sweep` since construction (for the FEA loads).
    points: Vec<LtcaPoint>,
}

fn f64_array<'py>(py: Python<'py>, v: Vec<f64>, shape: Vec<usize>) -> PyResult<Bound<'py, PyAny>> {
    Ok(v.into_pyarray(py).reshape(shape)?.into_any())
}

#[pymethods]
impl LtcaSolver {
    /// A solver for `scene` converging to `tolerance` of the load scale.
    #[new]
    fn py_new(scene: &CompiledScene, tolerance: f64) -> PyResult<Self> {
        let opts = NewtonOptions {
            tolerance,
            ..NewtonOptions::default()
        };
        // Looser than 1e-6 of the load the equilibrium is visibly wrong (TE off by 30 % at
        // 1e-3, the pins unloaded at 1) while its residual looks small.
        if !(tolerance.is_finite() && tolerance > 0.0 && tolerance <= 1e-6) {
            return Err(RvdynError::Parameter(format!(
                "tolerance must be > 0 and at most 1e-6 (of the load scale), got {tolerance}: \
                 looser equilibria are not accurate; the default 1e-12 closes the balances to 1e-9"
            ))
            .into());
        }
        Ok(Self {
            ltca: Mutex::new(Ltca::with_options(&scene.scene, opts)?),
            face_width: scene.scene.cycloid.face_width,
            points: Vec::new(),
        })
    }

    /// Crank-angle period of the contact pattern [rad].
    #[getter]
    fn mesh_period(&self) -> PyResult<f64> {
        Ok(self.lock()?.mesh_period())
    }

    /// The crank-angle window after which the whole static state repeats [rad]: the mesh
    /// period, or a multiple of it with roller bearings (their roller sets stay fixed in the
    /// frame).
    #[getter]
    fn te_window(&self) -> PyResult<f64> {
        Ok(self.lock()?.te_window())
    }

    /// Transmission ratio input/output.
    #[getter]
    fn ratio(&self) -> PyResult<f64> {
        Ok(self.lock()?.ratio())
    }

    /// Disc face width [m].
    #[getter]
    fn face_width(&self) -> f64 {
        self.face_width
    }

    /// Equilibria at `crank_angles` [rad] under `torque` [N m] (warm-started from the last
    /// call); a dict of numpy arrays with the crank angle first.
    fn sweep<'py>(
        &mut self,
        py: Python<'py>,
        torque: f64,
        crank_angles: Vec<f64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let ltca = self.ltca.get_mut().map_err(|_| poisoned())?;
        let pts = py.detach(|| ltca.sweep(torque, &crank_angles))?;
        let d = pack(py, &pts)?;
        self.points.extend(pts);
        Ok(d)
    }

    /// The worst load case of each disc over every point solved so far, as (CSV, JSON).
    fn fea_loads(&self) -> PyResult<(String, String)> {
        let loads = worst_loads(&self.points)?;
        Ok((loads_csv(&loads), loads_json(&loads, self.face_width)?))
    }

    /// TE over `periods` mesh periods at `points` crank angles per period from `start` [rad],
    /// at +-`torque` and (unless `light` is None) +-`light` [N m], with each curve's extremes;
    /// with `pin_loads`, each loaded curve's peak pin force [N] and fewest loaded pins per angle.
    #[pyo3(signature = (torque, light, points, start, pin_loads = false, periods = 1))]
    #[allow(clippy::too_many_arguments)]
    fn transmission_error<'py>(
        &mut self,
        py: Python<'py>,
        torque: f64,
        light: Option<f64>,
        points: usize,
        start: f64,
        pin_loads: bool,
        periods: usize,
    ) -> PyResult<Bound<'py, PyDict>> {
        let ltca = self.ltca.get_mut().map_err(|_| poisoned())?;
        let te = py
            .detach(|| ltca.transmission_error(torque, light, points, start, periods, pin_loads))?;
        let d = PyDict::new(py);
        let n = te.crank_angle.len();
        d.set_item("crank_angle", f64_array(py, te.crank_angle, vec![n])?)?;
        d.set_item("period", te.period)?;
        d.set_item("periods", te.periods)?;
        d.set_item("forward", f64_array(py, te.forward, vec![n])?)?;
        d.set_item("reverse", f64_array(py, te.reverse, vec![n])?)?;
        // Empty without the unloaded curves.
        let m = te.unloaded_forward.len();
        d.set_item(
            "unloaded_forward",
            f64_array(py, te.unloaded_forward, vec![m])?,
        )?;
        d.set_item(
            "unloaded_reverse",
            f64_array(py, te.unloaded_reverse, vec![m])?,
        )?;
        let x = &te.extremes;
        let extremes = PyDict::new(py);
        for (name, e) in [
            ("forward", Some(x.forward)),
            ("reverse", Some(x.reverse)),
            ("unloaded_forward", x.unloaded_forward),
            ("unloaded_reverse", x.unloaded_reverse),
        ] {
            let Some(e) = e else { continue };
            let one = PyDict::new(py);
            one.set_item("max_angle", e.max.crank_angle)?;
            one.set_item("max", e.max.value)?;
            one.set_item("min_angle", e.min.crank_angle)?;
            one.set_item("min", e.min.value)?;
            one.set_item("refined", e.refined)?;
            extremes.set_item(name, one)?;
        }
        d.set_item("extremes", extremes)?;
        if let Some(loads) = te.pin_loads {
            let pins = PyDict::new(py);
            for (name, c) in [("forward", loads.forward), ("reverse", loads.reverse)] {
                let one = PyDict::new(py);
                one.set_item("peak_force", f64_array(py, c.peak_force, vec![n])?)?;
                let fewest: Vec<i64> = c.loaded_pins_min.iter().map(|&k| k as i64).collect();
                one.set_item("loaded_pins_min", fewest.into_pyarray(py))?;
                pins.set_item(name, one)?;
            }
            d.set_item("pin_loads", pins)?;
        }
        Ok(d)
    }

    /// The torque-twist loop at `crank_angle` [rad] over +-`rated` [N m] with `points` points;
    /// `friction`: apply the scene's friction (if it has any).
    #[pyo3(signature = (rated, crank_angle, points, friction = true))]
    fn twist_loop<'py>(
        &mut self,
        py: Python<'py>,
        rated: f64,
        crank_angle: f64,
        points: usize,
        friction: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let ltca = self.ltca.get_mut().map_err(|_| poisoned())?;
        let applied = friction && ltca.friction_laws().any();
        let lp = py.detach(|| ltca.twist_loop_with(rated, crank_angle, points, friction))?;
        let d = PyDict::new(py);
        d.set_item("friction", applied)?;
        let n = lp.torque.len();
        d.set_item("torque", f64_array(py, lp.torque, vec![n])?)?;
        d.set_item("twist", f64_array(py, lp.twist, vec![n])?)?;
        d.set_item(
            "tangent_stiffness",
            f64_array(py, lp.tangent_stiffness, vec![n])?,
        )?;
        d.set_item("rigidity", lp.rigidity)?;
        d.set_item("lost_motion", lp.lost_motion)?;
        d.set_item("backlash", lp.backlash)?;
        Ok(d)
    }

    /// The compliance budget at `crank_angle` [rad] for each output torque in `torques` [N m]:
    /// `parts` (names), `compliance` (torques, parts) [rad/(N m)], `torsional_stiffness`
    /// (torques,) [N m/rad], `split_error` (torques,).
    fn compliance_budget<'py>(
        &mut self,
        py: Python<'py>,
        torques: Vec<f64>,
        crank_angle: f64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let ltca = self.ltca.get_mut().map_err(|_| poisoned())?;
        let b = py.detach(|| ltca.compliance_budget(&torques, crank_angle))?;
        let (m, p) = (b.torque.len(), b.parts.len());
        let d = PyDict::new(py);
        d.set_item("parts", b.parts)?;
        let flat: Vec<f64> = b.compliance.into_iter().flatten().collect();
        d.set_item("compliance", f64_array(py, flat, vec![m, p])?)?;
        d.set_item(
            "torsional_stiffness",
            f64_array(py, b.torsional_stiffness, vec![m])?,
        )?;
        d.set_item("split_error", f64_array(py, b.split_error, vec![m])?)?;
        Ok(d)
    }

    /// A running sweep with the scene's friction at `crank_angles` [rad] under the output
    /// torque `torque` [N m] (the input driving against it): TE [rad] and the held input's
    /// torque [N m] per crank angle.
    fn friction_sweep<'py>(
        &mut self,
        py: Python<'py>,
        torque: f64,
        crank_angles: Vec<f64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let ltca = self.ltca.get_mut().map_err(|_| poisoned())?;
        let laws = ltca.friction_laws().clone();
        let r = py.detach(|| ltca.friction_sweep(&laws, torque, &crank_angles))?;
        let n = r.len();
        let d = PyDict::new(py);
        d.set_item(
            "transmission_error",
            f64_array(py, r.iter().map(|p| p.0).collect(), vec![n])?,
        )?;
        d.set_item(
            "input_torque",
            f64_array(py, r.iter().map(|p| p.1).collect(), vec![n])?,
        )?;
        Ok(d)
    }
}

impl LtcaSolver {
    fn lock(&self) -> PyResult<std::sync::MutexGuard<'_, Ltca>> {
        self.ltca.lock().map_err(|_| poisoned())
    }
}

fn poisoned() -> PyErr {
    RvdynError::Convergence("the LTCA solver failed in an earlier call; build a new one".into())
        .into()
}

/// LTCA points as arrays (first axis: crank angle).
fn pack<'py>(py: Python<'py>, pts: &[LtcaPoint]) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let n = pts.len();
    let nd = pts.first().map_or(0, |p| p.pins.len());
    let zp = pts
        .first()
        .map_or(0, |p| p.pins.first().map_or(0, |r| r.len()));
    let ncr = pts.first().map_or(0, |p| p.mesh_force.len());
    let scalar = |f: &dyn Fn(&LtcaPoint) -> f64| pts.iter().map(f).collect::<Vec<f64>>();
    for (name, v) in [
        ("crank_angle", scalar(&|p| p.crank_angle)),
        ("output_angle", scalar(&|p| p.output_angle)),
        ("input_angle", scalar(&|p| p.input_angle)),
        ("transmission_error", scalar(&|p| p.transmission_error)),
        ("input_torque", scalar(&|p| p.input_torque)),
        ("torque_balance", scalar(&|p| p.torque_balance)),
        ("residual", scalar(&|p| p.residual)),
        ("torsional_stiffness", scalar(&|p| p.torsional_stiffness)),
    ] {
        d.set_item(name, f64_array(py, v, vec![n])?)?;
    }
    let iters: Vec<i64> = pts.iter().map(|p| p.iterations as i64).collect();
    d.set_item("iterations", iters.into_pyarray(py))?;
    let per_pin = |f: &dyn Fn(&crate::analysis::ltca::PinLoad) -> f64| {
        pts.iter()
            .flat_map(|p| p.pins.iter().flatten().map(f))
            .collect::<Vec<f64>>()
    };
    for (name, v) in [
        ("pin_force", per_pin(&|l| l.force)),
        ("pin_gap", per_pin(&|l| l.gap)),
        ("half_width", per_pin(&|l| l.half_width)),
        ("peak_pressure", per_pin(&|l| l.peak_pressure)),
    ] {
        d.set_item(name, f64_array(py, v, vec![n, nd, zp])?)?;
    }
    let pair = |f: &dyn Fn(&crate::analysis::ltca::PinLoad) -> [f64; 2]| {
        pts.iter()
            .flat_map(|p| p.pins.iter().flatten().flat_map(f))
            .collect::<Vec<f64>>()
    };
    d.set_item(
        "contact_point",
        f64_array(py, pair(&|l| l.point), vec![n, nd, zp, 2])?,
    )?;
    d.set_item(
        "contact_normal",
        f64_array(py, pair(&|l| l.normal), vec![n, nd, zp, 2])?,
    )?;
    let loaded: Vec<i64> = pts
        .iter()
        .flat_map(|p| p.loaded_pins.iter().map(|&c| c as i64))
        .collect();
    d.set_item("loaded_pins", loaded.into_pyarray(py).reshape(vec![n, nd])?)?;
    let rot: Vec<f64> = pts.iter().flat_map(|p| p.disc_rotation.clone()).collect();
    d.set_item("disc_rotation", f64_array(py, rot, vec![n, nd])?)?;
    let angle: Vec<f64> = pts.iter().flat_map(|p| p.disc_angle.clone()).collect();
    d.set_item("disc_angle", f64_array(py, angle, vec![n, nd])?)?;
    let disp: Vec<f64> = pts
        .iter()
        .flat_map(|p| p.disc_displacement.iter().flatten().copied())
        .collect();
    d.set_item("disc_displacement", f64_array(py, disp, vec![n, nd, 2])?)?;
    let mesh: Vec<f64> = pts.iter().flat_map(|p| p.mesh_force.clone()).collect();
    d.set_item("mesh_force", f64_array(py, mesh, vec![n, ncr])?)?;
    let nb = pts.first().map_or(0, |p| p.crank_bearing_force.len());
    let cb: Vec<f64> = pts
        .iter()
        .flat_map(|p| p.crank_bearing_force.iter().flatten().copied())
        .collect();
    d.set_item("crank_bearing_force", f64_array(py, cb, vec![n, nb, 2])?)?;
    let ne = pts.first().map_or(0, |p| p.eccentric_bearing_force.len());
    let eb: Vec<f64> = pts
        .iter()
        .flat_map(|p| p.eccentric_bearing_force.iter().flatten().copied())
        .collect();
    let shape = if ne > 0 && nd > 0 {
        vec![n, ne / nd, nd, 2]
    } else {
        vec![n, 0, nd, 2]
    };
    d.set_item("eccentric_bearing_force", f64_array(py, eb, shape.clone())?)?;
    let bent: Vec<f64> = pts
        .iter()
        .flat_map(|p| p.crank_deflection.iter().flatten().copied())
        .collect();
    let shape = if bent.is_empty() {
        vec![n, 0, nd, 2]
    } else {
        shape
    };
    d.set_item("crank_deflection", f64_array(py, bent, shape)?)?;
    Ok(d)
}

/// Add the solver class to the module.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<LtcaSolver>()?;
    Ok(())
}
