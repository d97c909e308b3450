//! Bindings for scenes and dynamic runs. The Python `rvdyn.Scene`, `rvdyn.simulate` and
//! `rvdyn.Result` (python/rvdyn/) wrap these private functions.

use crate::dynamics::compliant::{CompliantModel, default_joints};
use crate::dynamics::record::{Channel, Recording};
use crate::dynamics::rigid::RigidModel;
use crate::dynamics::scene::{Joints, Scene};
use crate::dynamics::simulate::{RunControl, SimOptions};
use crate::error::RvdynError;
use crate::solve::MechanicalSystem;
use crate::solve::Method;
use numpy::{IntoPyArray, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use std::io::Write;
use std::time::{Duration, Instant};

fn scene(json: &str) -> PyResult<Scene> {
    Ok(Scene::from_json(json)?)
}

/// The default scene of design.md section 7 as JSON; `load` is "idle", "paper" or "rated".
#[pyfunction]
fn scene_paper(load: &str) -> PyResult<String> {
    Ok(Scene::paper(load)?.to_json()?)
}

/// Validate a scene given as JSON; returns it normalised (defaults filled in) as JSON.
#[pyfunction]
fn scene_validate(json: &str) -> PyResult<String> {
    Ok(scene(json)?.to_json()?)
}

/// Scene JSON -> TOML text.
#[pyfunction]
fn scene_to_toml(json: &str) -> PyResult<String> {
    Ok(scene(json)?.to_toml()?)
}

/// TOML text -> scene JSON (validated).
#[pyfunction]
fn scene_from_toml(text: &str) -> PyResult<String> {
    Ok(Scene::from_toml(text)?.to_json()?)
}

/// The default compliant joints (assumed bearing stiffness and damping) as JSON.
#[pyfunction]
fn default_compliant_joints() -> PyResult<String> {
    serde_json::to_string(&default_joints())
        .map_err(|e| crate::python::parameter_error(format!("cannot write joints: {e}")))
}

/// Mass properties and generalised masses the model uses for a scene (SI).
#[pyfunction]
fn scene_model_info<'py>(py: Python<'py>, json: &str) -> PyResult<Bound<'py, PyDict>> {
    let sc = scene(json)?;
    let dof = match sc.joints {
        Joints::Rigid => None,
        Joints::Compliant { .. } => Some(CompliantModel::new(&sc)?.dof()),
    };
    let mut rigid = sc.clone();
    rigid.joints = Joints::Rigid;
    let model = RigidModel::new(&rigid)?;
    let d = PyDict::new(py);
    let i = model.inertias;
    for (name, mp) in [
        ("sun", i.sun),
        ("crank", i.crank),
        ("disc", i.disc),
        ("carrier", i.carrier),
    ] {
        d.set_item(format!("{name}_mass"), mp.mass)?;
        d.set_item(format!("{name}_inertia"), mp.inertia)?;
    }
    d.set_item("load_inertia", i.load_inertia)?;
    d.set_item("generalized_mass", model.mass.to_vec())?;
    d.set_item("crank_radius", model.crank_radius)?;
    d.set_item("ratio", model.ratio)?;
    d.set_item("max_penetration", model.max_penetration)?;
    d.set_item("dof", dof.unwrap_or(model.free.len()))?;
    d.set_item("joints", if dof.is_some() { "compliant" } else { "rigid" })?;
    Ok(d)
}

/// Options of a run, as passed from Python.
#[allow(clippy::too_many_arguments)]
fn options(
    t_end: f64,
    integrator: &str,
    dt: Option<f64>,
    rtol: Option<f64>,
    atol: Option<f64>,
    rho_inf: Option<f64>,
    record_interval: Option<f64>,
    max_samples: Option<usize>,
    channels: Option<Vec<String>>,
    skip_separated: bool,
) -> Result<SimOptions, RvdynError> {
    let mut o = SimOptions::new(t_end, Method::parse(integrator)?);
    o.dt = dt;
    if let Some(v) = rtol {
        o.rtol = v;
    }
    if let Some(v) = atol {
        o.atol = v;
    }
    if let Some(v) = rho_inf {
        o.rho_inf = v;
    }
    o.record_interval = record_interval;
    if let Some(v) = max_samples {
        o.max_samples = v;
    }
    if let Some(ch) = channels {
        o.channels = ch
            .iter()
            .map(|c| Channel::parse(c))
            .collect::<Result<_, _>>()?;
    }
    o.skip_separated = skip_separated;
    Ok(o)
}

/// Recorded series as numpy arrays (first axis = samples), plus the run statistics.
fn to_python<'py>(
    py: Python<'py>,
    rec: Recording,
) -> PyResult<(Bound<'py, PyDict>, Bound<'py, PyDict>)> {
    let arrays = PyDict::new(py);
    let n = rec.samples;
    for (name, s) in rec.series {
        let mut shape = vec![n];
        shape.extend_from_slice(&s.sample_shape);
        // The Vec moves into numpy without a copy; reshape returns a view of it.
        let a = s.data.into_pyarray(py).reshape(shape)?;
        arrays.set_item(name, a)?;
    }
    let stats = PyDict::new(py);
    for (k, v) in rec.stats {
        stats.set_item(k, v)?;
    }
    Ok((arrays, stats))
}

/// Run one scene. The core runs on a worker thread with the GIL released; this thread wakes
/// every 50 ms to let Python handle Ctrl-C (which stops the run cleanly) and to draw a
/// progress bar on stderr when `progress` is true.
#[pyfunction]
#[pyo3(signature = (scene_json, t_end, integrator, dt=None, rtol=None, atol=None, rho_inf=None,
    record_interval=None, max_samples=None, channels=None, progress=false, skip_separated=true))]
#[allow(clippy::too_many_arguments)]
fn simulate<'py>(
    py: Python<'py>,
    scene_json: &str,
    t_end: f64,
    integrator: &str,
    dt: Option<f64>,
    rtol: Option<f64>,
    atol: Option<f64>,
    rho_inf: Option<f64>,
    record_interval: Option<f64>,
    max_samples: Option<usize>,
    channels: Option<Vec<String>>,
    progress: bool,
    skip_separated: bool,
) -> PyResult<(Bound<'py, PyDict>, Bound<'py, PyDict>)> {
    let sc = scene(scene_json)?;
    let opt = options(
        t_end,
        integrator,
        dt,
        rtol,
        atol,
        rho_inf,
        record_interval,
        max_samples,
        channels,
        skip_separated,
    )?;
    let control = RunControl::default();
    let start = Instant::now();
    let outcome = std::thread::scope(|s| -> PyResult<(Result<Recording, RvdynError>, f64)> {
        // The worker reports through a channel, so this thread wakes the moment it is done
        // (and every 50 ms meanwhile, for Ctrl-C and the progress bar).
        let (tx, rx) = std::sync::mpsc::channel();
        // A Mutex makes the receiver shareable with the GIL-free closure below.
        let rx = std::sync::Mutex::new(rx);
        let (sc, opt, control) = (&sc, &opt, &control);
        let worker = s.spawn(move || {
            let t0 = Instant::now();
            let r = crate::dynamics::simulate(sc, opt, control);
            let _ = tx.send((r, t0.elapsed().as_secs_f64()));
        });
        let mut last_draw = Instant::now();
        loop {
            let received = py.detach(|| match rx.lock() {
                Ok(rx) => rx.recv_timeout(Duration::from_millis(50)),
                Err(_) => Err(std::sync::mpsc::RecvTimeoutError::Disconnected),
            });
            match received {
                Ok(done) => {
                    if progress {
                        draw_progress(opt.t_end, opt.t_end, start.elapsed().as_secs_f64());
                        eprintln!();
                    }
                    let _ = worker.join();
                    return Ok(done);
                }
                Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
                    return Err(pyo3::exceptions::PyRuntimeError::new_err(
                        "the simulation thread panicked (a bug: please report it)",
                    ));
                }
                Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {}
            }
            if let Err(e) = py.check_signals() {
                control.request_stop();
                let _ = worker.join();
                if progress {
                    eprintln!();
                }
                return Err(e);
            }
            if progress && last_draw.elapsed() > Duration::from_millis(250) {
                draw_progress(control.time(), opt.t_end, start.elapsed().as_secs_f64());
                last_draw = Instant::now();
            }
        }
    })?;
    let (result, core_time) = outcome;
    let mut rec = result?;
    rec.stats.insert("wall_time", core_time);
    to_python(py, rec)
}

fn draw_progress(t: f64, t_end: f64, wall: f64) {
    let frac = (t / t_end).clamp(0.0, 1.0);
    let filled = (frac * 30.0).round() as usize;
    let mut err = std::io::stderr();
    let _ = write!(
        err,
        "\r[{}{}] {:5.1}%  t = {:.3} s  wall {:.1} s",
        "#".repeat(filled),
        " ".repeat(30 - filled),
        100.0 * frac,
        t,
        wall
    );
    let _ = err.flush();
}

/// Run many scenes in parallel (rayon, GIL released). Returns, per scene, either the
/// recorded arrays and statistics or the exception its run raised.
#[pyfunction]
#[pyo3(signature = (scene_jsons, t_end, integrator, dt=None, rtol=None, atol=None, rho_inf=None,
    record_interval=None, max_samples=None, channels=None, threads=None, skip_separated=true))]
#[allow(clippy::too_many_arguments)]
fn sweep<'py>(
    py: Python<'py>,
    scene_jsons: Vec<String>,
    t_end: f64,
    integrator: &str,
    dt: Option<f64>,
    rtol: Option<f64>,
    atol: Option<f64>,
    rho_inf: Option<f64>,
    record_interval: Option<f64>,
    max_samples: Option<usize>,
    channels: Option<Vec<String>>,
    threads: Option<usize>,
    skip_separated: bool,
) -> PyResult<Vec<Bound<'py, PyAny>>> {
    let opt = options(
        t_end,
        integrator,
        dt,
        rtol,
        atol,
        rho_inf,
        record_interval,
        max_samples,
        channels,
        skip_separated,
    )?;
    let scenes: Vec<Scene> = scene_jsons
        .iter()
        .map(|j| scene(j))
        .collect::<PyResult<_>>()?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map_err(|e| {
            crate::python::parameter_error(format!("cannot start {threads:?} threads: {e}"))
        })?;
    let results: Vec<(Result<Recording, RvdynError>, f64)> = py.detach(|| {
        pool.install(|| {
            scenes
                .par_iter()
                .map(|sc| {
                    let start = Instant::now();
                    let r = crate::dynamics::simulate(sc, &opt, &RunControl::default());
                    (r, start.elapsed().as_secs_f64())
                })
                .collect()
        })
    });
    results
        .into_iter()
        .map(|(r, wall)| match r {
            Ok(mut rec) => {
                rec.stats.insert("wall_time", wall);
                let (a, s) = to_python(py, rec)?;
                Ok((a, s).into_pyobject(py)?.into_any())
            }
            Err(e) => Ok(super::errors::to_pyerr(py, e)
                .into_value(py)
                .into_bound(py)
                .into_any()),
        })
        .collect()
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(scene_paper, m)?)?;
    m.add_function(wrap_pyfunction!(scene_validate, m)?)?;
    m.add_function(wrap_pyfunction!(scene_to_toml, m)?)?;
    m.add_function(wrap_pyfunction!(scene_from_toml, m)?)?;
    m.add_function(wrap_pyfunction!(scene_model_info, m)?)?;
    m.add_function(wrap_pyfunction!(default_compliant_joints, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    Ok(())
}
