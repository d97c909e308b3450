//! Bindings for dynamic runs: the run options (`rvdyn.Options`), `simulate` and `sweep`. The
//! Python `rvdyn.simulate`, `rvdyn.sweep` and `rvdyn.Result` (python/rvdyn/) wrap these.

use super::scene::CompiledScene;
use crate::dynamics::run::driver::{RunControl, SimOptions, StepCheck};
use crate::dynamics::run::recorder::{CHANNELS, Channel, Dtype, Recording};
use crate::dynamics::scene::Scene;
use crate::error::RvdynError;
use crate::solve::{INTEGRATORS, Method};
use numpy::{IntoPyArray, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rayon::prelude::*;
use std::io::Write;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Most worker threads a sweep may ask for.
const MAX_THREADS: usize = 1024;

/// Options of a dynamic run (all but the end time), validated when built; None = default.
///
/// integrator: "generalized-alpha" (default), "generalized-alpha-adaptive", "dopri5" or "rk4";
/// dt [s] (None = the integrator's default: 1e-4, 1e-5 (initial), 1e-6 (initial), 1e-5 s);
/// rtol (adaptive, velocities, default 1e-6, at most 1e-2); atol [m] (displacement tolerance
/// of the error control and of Newton, default 1e-9 m, at most 1e-6 m); rho_inf in [0, 1]
/// (default 0.8); record_interval [s], <= t_end (None = 1e-4 s or t_end if shorter);
/// max_samples (default 50 000); channels (groups: "motion", "pins", "contact_points", "mesh",
/// "energy", "bearings"; None = all but contact points); skip_separated (default True);
/// step_check ("warn", "raise" or "off": a step or tolerance that cannot be accurate, default "warn");
/// h_min [s] and max_steps (bounds of an adaptive method, default 1e-13 s and 1e8).
#[pyclass(name = "Options", module = "rvdyn", frozen, eq)]
#[derive(Clone, PartialEq)]
pub(crate) struct Options {
    inner: SimOptions,
}

/// Set one option from a Python value: the one place where option names map to fields.
fn set_option(o: &mut SimOptions, key: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
    let none = value.is_none();
    let float = |what: &str| -> PyResult<f64> {
        value.extract::<f64>().map_err(|_| {
            crate::python::parameter_error(format!(
                "{key} must be a number ({what}), got {}",
                super::arrays::short_repr(value, 40)
            ))
        })
    };
    match key {
        "integrator" => {
            let name: String = value.extract().map_err(|_| {
                crate::python::parameter_error("integrator must be a name such as \"rk4\"")
            })?;
            o.method = Method::parse(&name)?;
        }
        "dt" => o.dt = if none { None } else { Some(float("s")?) },
        "rtol" => o.rtol = float("relative")?,
        "atol" => o.atol = float("m")?,
        "rho_inf" => o.rho_inf = float("in [0, 1]")?,
        "record_interval" => o.record_interval = if none { None } else { Some(float("s")?) },
        "max_samples" => {
            let too_many = |text: &str| {
                crate::python::parameter_error(format!(
                    "max_samples must be a whole number in 2..={:.0e}, got {text}",
                    crate::dynamics::run::driver::MAX_SAMPLES as f64
                ))
            };
            o.max_samples = match value.extract::<crate::python::Whole>() {
                Ok(crate::python::Whole::Value(n)) => {
                    usize::try_from(n).map_err(|_| too_many(&n.to_string()))?
                }
                Ok(crate::python::Whole::TooLarge(text, _)) => return Err(too_many(&text)),
                Err(_) => return Err(too_many(&super::arrays::short_repr(value, 30))),
            };
        }
        "channels" => {
            o.channels = if none {
                Channel::defaults()
            } else if let Ok(one) = value.extract::<String>() {
                vec![Channel::parse(&one)?]
            } else {
                let names: Vec<String> = value.extract().map_err(|_| {
                    crate::python::parameter_error(
                        "channels must be a list of names such as [\"motion\", \"pins\"]",
                    )
                })?;
                names
                    .iter()
                    .map(|c| Channel::parse(c))
                    .collect::<Result<_, _>>()?
            }
        }
        "skip_separated" => {
            // A bool only: "no" is truthy, and reading it as True would do the opposite.
            o.skip_separated = value.extract::<bool>().map_err(|_| {
                crate::python::parameter_error(format!(
                    "skip_separated must be True or False, got {}",
                    super::arrays::short_repr(value, 30)
                ))
            })?;
        }
        "step_check" => {
            let name: String = value.extract().map_err(|_| {
                crate::python::parameter_error("step_check must be \"warn\", \"raise\" or \"off\"")
            })?;
            o.step_check = StepCheck::parse(&name)?;
        }
        "h_min" => o.h_min = float("s")?,
        "max_steps" => {
            let n: i64 = value.extract().map_err(|_| {
                crate::python::parameter_error("max_steps must be a whole number >= 1")
            })?;
            o.max_steps = u64::try_from(n).unwrap_or(0);
        }
        _ => {
            return Err(crate::python::parameter_error(format!(
                "unknown option {key:?}: the options are integrator, dt, rtol, atol, rho_inf, \
                 record_interval, max_samples, channels, skip_separated, step_check, h_min, \
                 max_steps"
            )));
        }
    }
    Ok(())
}

/// The arguments given (not None) as a dict for [`apply`].
fn given<'py, const N: usize>(
    py: Python<'py>,
    args: [(&str, Option<Bound<'py, PyAny>>); N],
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (k, v) in args {
        if let Some(v) = v.filter(|v| !v.is_none()) {
            d.set_item(k, v)?;
        }
    }
    Ok(d)
}

fn apply(mut o: SimOptions, changes: Option<&Bound<'_, PyDict>>) -> PyResult<Options> {
    if let Some(changes) = changes {
        for (k, v) in changes.iter() {
            set_option(&mut o, &k.extract::<String>()?, &v)?;
        }
    }
    o.validate_settings()?;
    Ok(Options { inner: o })
}

impl Options {
    /// The options for a run to `t_end` [s], checked.
    fn for_run(&self, t_end: f64) -> Result<SimOptions, RvdynError> {
        let mut o = self.inner.clone();
        o.t_end = t_end;
        o.validate()?;
        Ok(o)
    }
}

#[pymethods]
impl Options {
    #[new]
    #[pyo3(signature = (integrator = None, *, dt = None, rtol = None, atol = None, rho_inf = None,
        record_interval = None, max_samples = None, channels = None, skip_separated = None,
        step_check = None, h_min = None, max_steps = None))]
    #[allow(clippy::too_many_arguments)]
    fn py_new<'py>(
        py: Python<'py>,
        integrator: Option<Bound<'py, PyAny>>,
        dt: Option<Bound<'py, PyAny>>,
        rtol: Option<Bound<'py, PyAny>>,
        atol: Option<Bound<'py, PyAny>>,
        rho_inf: Option<Bound<'py, PyAny>>,
        record_interval: Option<Bound<'py, PyAny>>,
        max_samples: Option<Bound<'py, PyAny>>,
        channels: Option<Bound<'py, PyAny>>,
        skip_separated: Option<Bound<'py, PyAny>>,
        step_check: Option<Bound<'py, PyAny>>,
        h_min: Option<Bound<'py, PyAny>>,
        max_steps: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Self> {
        let given = given(
            py,
            [
                ("integrator", integrator),
                ("dt", dt),
                ("rtol", rtol),
                ("atol", atol),
                ("rho_inf", rho_inf),
                ("record_interval", record_interval),
                ("max_samples", max_samples),
                ("channels", channels),
                ("skip_separated", skip_separated),
                ("step_check", step_check),
                ("h_min", h_min),
                ("max_steps", max_steps),
            ],
        )?;
        apply(SimOptions::new(1.0, Method::GeneralizedAlpha), Some(&given))
    }

    /// A copy with the options given (not None) changed; same names as the constructor.
    #[pyo3(signature = (*, integrator = None, dt = None, rtol = None, atol = None, rho_inf = None,
        record_interval = None, max_samples = None, channels = None, skip_separated = None,
        step_check = None, h_min = None, max_steps = None))]
    #[allow(clippy::too_many_arguments)]
    fn replace<'py>(
        &self,
        py: Python<'py>,
        integrator: Option<Bound<'py, PyAny>>,
        dt: Option<Bound<'py, PyAny>>,
        rtol: Option<Bound<'py, PyAny>>,
        atol: Option<Bound<'py, PyAny>>,
        rho_inf: Option<Bound<'py, PyAny>>,
        record_interval: Option<Bound<'py, PyAny>>,
        max_samples: Option<Bound<'py, PyAny>>,
        channels: Option<Bound<'py, PyAny>>,
        skip_separated: Option<Bound<'py, PyAny>>,
        step_check: Option<Bound<'py, PyAny>>,
        h_min: Option<Bound<'py, PyAny>>,
        max_steps: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Self> {
        let given = given(
            py,
            [
                ("integrator", integrator),
                ("dt", dt),
                ("rtol", rtol),
                ("atol", atol),
                ("rho_inf", rho_inf),
                ("record_interval", record_interval),
                ("max_samples", max_samples),
                ("channels", channels),
                ("skip_separated", skip_separated),
                ("step_check", step_check),
                ("h_min", h_min),
                ("max_steps", max_steps),
            ],
        )?;
        apply(self.inner.clone(), Some(&given))
    }

    /// Integrator name.
    #[getter]
    fn integrator(&self) -> &'static str {
        self.inner.method.name()
    }
    /// Step [s] (initial step of an adaptive method); None = the integrator's default.
    #[getter]
    fn dt(&self) -> Option<f64> {
        self.inner.dt
    }
    /// Relative velocity tolerance of the adaptive method.
    #[getter]
    fn rtol(&self) -> f64 {
        self.inner.rtol
    }
    /// Displacement tolerance [m] (error control; Newton tolerance of generalized-alpha).
    #[getter]
    fn atol(&self) -> f64 {
        self.inner.atol
    }
    /// Spectral radius at infinite frequency of generalized-alpha, in [0, 1].
    #[getter]
    fn rho_inf(&self) -> f64 {
        self.inner.rho_inf
    }
    /// Sample interval [s]; None = 1e-4 s (coarsened to fit max_samples).
    #[getter]
    fn record_interval(&self) -> Option<f64> {
        self.inner.record_interval
    }
    /// Most samples kept.
    #[getter]
    fn max_samples(&self) -> usize {
        self.inner.max_samples
    }
    /// Channel groups recorded.
    #[getter]
    fn channels(&self) -> Vec<&'static str> {
        self.inner.channels.iter().map(Channel::name).collect()
    }
    /// Whether pins that provably cannot touch skip the exact gap query.
    #[getter]
    fn skip_separated(&self) -> bool {
        self.inner.skip_separated
    }
    /// What a fixed step that cannot be accurate does: "warn", "raise" or "off".
    #[getter]
    fn step_check(&self) -> &'static str {
        match self.inner.step_check {
            StepCheck::Warn => "warn",
            StepCheck::Raise => "raise",
            StepCheck::Off => "off",
        }
    }
    /// Smallest step of an adaptive method [s].
    #[getter]
    fn h_min(&self) -> f64 {
        self.inner.h_min
    }
    /// Most steps of an adaptive method.
    #[getter]
    fn max_steps(&self) -> u64 {
        self.inner.max_steps
    }

    /// The options as a dict (constructor names; `Options(**d)` rebuilds them).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("integrator", self.integrator())?;
        d.set_item("dt", self.dt())?;
        d.set_item("rtol", self.rtol())?;
        d.set_item("atol", self.atol())?;
        d.set_item("rho_inf", self.rho_inf())?;
        d.set_item("record_interval", self.record_interval())?;
        d.set_item("max_samples", self.max_samples())?;
        d.set_item("channels", self.channels())?;
        d.set_item("skip_separated", self.skip_separated())?;
        d.set_item("step_check", self.step_check())?;
        d.set_item("h_min", self.h_min())?;
        d.set_item("max_steps", self.max_steps())?;
        Ok(d)
    }

    /// The options a run to `t_end` [s] actually uses: the step and sample interval resolved,
    /// plus `t_end`.
    fn resolved<'py>(&self, py: Python<'py>, t_end: f64) -> PyResult<Bound<'py, PyDict>> {
        let o = self.for_run(t_end)?;
        let d = self.to_dict(py)?;
        d.set_item("t_end", t_end)?;
        let s = o.settings();
        let dt = if o.method.0.adaptive {
            s.dt
        } else {
            crate::solve::integrator::FixedClock::new(t_end, s.dt).h
        };
        d.set_item("dt", dt)?;
        d.set_item("record_interval", o.sample_interval())?;
        Ok(d)
    }

    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, (Bound<'py, PyDict>,))> {
        let rebuild = py.import("rvdyn._core")?.getattr("options_from_dict")?;
        Ok((rebuild, (self.to_dict(py)?,)))
    }

    fn __repr__(&self) -> String {
        let o = &self.inner;
        let opt = |v: Option<f64>| v.map_or("None".to_string(), |x| format!("{x:?}"));
        format!(
            "Options(integrator='{}', dt={}, rtol={:?}, atol={:?}, rho_inf={:?}, \
             record_interval={}, max_samples={}, channels=[{}], skip_separated={}, \
             step_check='{}', h_min={:?}, max_steps={})",
            o.method.name(),
            opt(o.dt),
            o.rtol,
            o.atol,
            o.rho_inf,
            opt(o.record_interval),
            o.max_samples,
            self.channels()
                .iter()
                .map(|c| format!("'{c}'"))
                .collect::<Vec<_>>()
                .join(", "),
            if o.skip_separated { "True" } else { "False" },
            self.step_check(),
            o.h_min,
            o.max_steps
        )
    }
}

/// Rebuild options from `Options.to_dict()` (used by pickle).
#[pyfunction]
fn options_from_dict(d: &Bound<'_, PyDict>) -> PyResult<Options> {
    apply(SimOptions::new(1.0, Method::GeneralizedAlpha), Some(d))
}

/// The registered integrators: (name, summary, default step [s], adaptive).
#[pyfunction]
fn integrators() -> Vec<(&'static str, &'static str, f64, bool)> {
    INTEGRATORS
        .iter()
        .map(|e| (e.name, e.summary, e.default_dt, e.adaptive))
        .collect()
}

/// The channel registry: per recorded array, a dict of name, group (the `channels` option
/// that records it; None = always), shape of one sample (dimension names), unit, dtype, doc.
#[pyfunction]
fn channels<'py>(py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
    CHANNELS
        .iter()
        .map(|c| {
            let d = PyDict::new(py);
            d.set_item("name", c.name)?;
            d.set_item("group", c.group.map(|g| g.name()))?;
            let shape: Vec<&str> = c.shape.iter().map(|x| x.name()).collect();
            d.set_item("shape", pyo3::types::PyTuple::new(py, shape)?)?;
            d.set_item("unit", c.unit)?;
            d.set_item(
                "dtype",
                match c.dtype {
                    Dtype::Float64 => "float64",
                    Dtype::Int64 => "int64",
                },
            )?;
            d.set_item("doc", c.doc)?;
            Ok(d)
        })
        .collect()
}

/// Recorded series as numpy arrays (first axis = samples), plus the run statistics.
fn to_python<'py>(
    py: Python<'py>,
    rec: Recording,
    wall_time: f64,
) -> PyResult<(Bound<'py, PyDict>, Bound<'py, PyDict>)> {
    let arrays = PyDict::new(py);
    let n = rec.samples;
    for (name, s) in rec.series {
        let mut shape = vec![n];
        shape.extend_from_slice(&s.sample_shape);
        let int = CHANNELS
            .iter()
            .any(|c| c.name == name && c.dtype == Dtype::Int64);
        // The Vec moves into numpy without a copy; reshape returns a view of it.
        if int {
            let counts: Vec<i64> = s.data.iter().map(|&v| v as i64).collect();
            arrays.set_item(name, counts.into_pyarray(py).reshape(shape)?)?;
        } else {
            arrays.set_item(name, s.data.into_pyarray(py).reshape(shape)?)?;
        }
    }
    let stats = PyDict::new(py);
    for (k, v) in rec.stats.counts {
        stats.set_item(k, v)?;
    }
    stats.set_item("dt", rec.stats.dt)?;
    stats.set_item("wall_time", wall_time)?;
    stats.set_item("warnings", rec.warnings)?;
    // The end state (free coordinates and velocities) for `rvdyn.modes_at`.
    if let Some((t, q, v)) = rec.final_state {
        stats.set_item("final_time", t)?;
        stats.set_item("final_q", q)?;
        stats.set_item("final_v", v)?;
    }
    Ok((arrays, stats))
}

/// Run `work` on a worker thread with the GIL released. This thread wakes every 50 ms to let
/// Python handle Ctrl-C (which asks the work to stop through `control` and raises
/// `KeyboardInterrupt` once it has) and to draw a progress bar when `progress` gives the end
/// time.
fn run_detached<T: Send>(
    py: Python<'_>,
    control: &RunControl,
    progress: Option<f64>,
    work: impl FnOnce(&RunControl) -> T + Send,
) -> PyResult<T> {
    let start = Instant::now();
    std::thread::scope(|s| -> PyResult<T> {
        // The worker reports through a channel, so this thread wakes the moment it is done.
        let (tx, rx) = std::sync::mpsc::channel();
        // A Mutex makes the receiver shareable with the GIL-free closure below.
        let rx = std::sync::Mutex::new(rx);
        let worker = s.spawn(move || {
            let _ = tx.send(work(control));
        });
        let mut last_draw = Instant::now();
        loop {
            let received = py.detach(|| match rx.lock() {
                Ok(rx) => rx.recv_timeout(Duration::from_millis(50)),
                Err(_) => Err(std::sync::mpsc::RecvTimeoutError::Disconnected),
            });
            match received {
                Ok(done) => {
                    if let Some(t_end) = progress {
                        draw_progress(t_end, t_end, start.elapsed().as_secs_f64());
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
                if progress.is_some() {
                    eprintln!();
                }
                return Err(e);
            }
            if let Some(t_end) = progress
                && last_draw.elapsed() > Duration::from_millis(250)
            {
                draw_progress(control.time(), t_end, start.elapsed().as_secs_f64());
                last_draw = Instant::now();
            }
        }
    })
}

/// Run one compiled scene to `t_end` [s]. Returns (arrays, statistics).
#[pyfunction]
#[pyo3(signature = (scene, t_end, options, progress = false))]
fn simulate<'py>(
    py: Python<'py>,
    scene: &CompiledScene,
    t_end: f64,
    options: &Options,
    progress: bool,
) -> PyResult<(Bound<'py, PyDict>, Bound<'py, PyDict>)> {
    let opt = options.for_run(t_end)?;
    let sc: Arc<Scene> = scene.scene.clone();
    let control = RunControl::default();
    let (result, core_time) = run_detached(py, &control, progress.then_some(t_end), |c| {
        let t0 = Instant::now();
        let r = crate::dynamics::simulate(&sc, &opt, c);
        (r, t0.elapsed().as_secs_f64())
    })?;
    to_python(py, result?, core_time)
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

/// Run many compiled scenes in parallel (rayon, GIL released). Options are checked once
/// (a bad option raises before any run); Ctrl-C stops every run within about 0.1 s and
/// raises `KeyboardInterrupt`. Returns, per scene, (arrays, statistics) or the exception its
/// run raised.
#[pyfunction]
#[pyo3(signature = (scenes, t_end, options, threads = None))]
fn sweep<'py>(
    py: Python<'py>,
    scenes: Vec<PyRef<'py, CompiledScene>>,
    t_end: f64,
    options: &Options,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyList>> {
    let opt = options.for_run(t_end)?;
    if threads.is_some_and(|n| n > MAX_THREADS) {
        return Err(crate::python::parameter_error(format!(
            "threads must be at most {MAX_THREADS} (None = one per core), got {}",
            threads.unwrap_or_default()
        )));
    }
    let scenes: Vec<Arc<Scene>> = scenes.iter().map(|s| s.scene.clone()).collect();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map_err(|e| {
            crate::python::parameter_error(format!("cannot start {threads:?} threads: {e}"))
        })?;
    let control = RunControl::default();
    let results: Vec<(Result<Recording, RvdynError>, f64)> =
        run_detached(py, &control, None, |c| {
            pool.install(|| {
                scenes
                    .par_iter()
                    .map(|sc| {
                        let start = Instant::now();
                        let r = crate::dynamics::simulate(sc, &opt, c);
                        (r, start.elapsed().as_secs_f64())
                    })
                    .collect()
            })
        })?;
    let out = PyList::empty(py);
    for (r, wall) in results {
        match r {
            Ok(rec) => out.append(to_python(py, rec, wall)?)?,
            Err(RvdynError::Interrupted) => {
                return Err(pyo3::exceptions::PyKeyboardInterrupt::new_err(
                    "sweep interrupted",
                ));
            }
            Err(e) => out.append(super::errors::to_pyerr(py, e).into_value(py))?,
        }
    }
    Ok(out)
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Options>()?;
    m.add_function(wrap_pyfunction!(options_from_dict, m)?)?;
    m.add_function(wrap_pyfunction!(integrators, m)?)?;
    m.add_function(wrap_pyfunction!(channels, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    Ok(())
}
