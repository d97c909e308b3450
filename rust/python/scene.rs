//! The compiled scene: a validated [`Scene`] held by Python (`rvdyn.Scene` wraps it), built
//! once from JSON, TOML or the paper's preset and changed by dotted paths in Rust. Runs take it
//! as it is, without parsing or validating again.

use crate::dynamics::model::compliant::{CompliantModel, default_joints};
use crate::dynamics::model::rigid::RigidModel;
use crate::dynamics::scene::{Joints, Scene, get_path};
use crate::error::RvdynError;
use crate::solve::MechanicalSystem;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::hash::{Hash, Hasher};
use std::sync::Arc;

/// A validated scene (immutable). Use `rvdyn.Scene`, which wraps this class.
#[pyclass(name = "CompiledScene", module = "rvdyn._core", frozen)]
pub(crate) struct CompiledScene {
    pub(crate) scene: Arc<Scene>,
    /// The scene as a JSON tree (for field reads and hashing).
    tree: serde_json::Value,
}

impl CompiledScene {
    pub(crate) fn new(scene: Scene) -> Result<Self, RvdynError> {
        let tree = scene.to_value()?;
        Ok(Self {
            scene: Arc::new(scene),
            tree,
        })
    }
}

fn json_error(e: serde_json::Error) -> RvdynError {
    RvdynError::Scene(format!("invalid scene value: {e}"))
}

/// Hash a JSON tree with -0.0 and 0.0 equal (they compare equal as scene values).
fn hash_value<H: Hasher>(v: &serde_json::Value, h: &mut H) {
    use serde_json::Value;
    match v {
        Value::Null => 0u8.hash(h),
        Value::Bool(b) => b.hash(h),
        Value::Number(n) => {
            let x = n.as_f64().unwrap_or(0.0);
            (if x == 0.0 { 0.0f64 } else { x }).to_bits().hash(h);
        }
        Value::String(s) => s.hash(h),
        Value::Array(a) => {
            a.len().hash(h);
            for x in a {
                hash_value(x, h);
            }
        }
        Value::Object(m) => {
            m.len().hash(h);
            for (k, x) in m {
                k.hash(h);
                hash_value(x, h);
            }
        }
    }
}

#[pymethods]
impl CompiledScene {
    /// Validate a scene given as JSON text (the whole schema; unknown fields are errors).
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<Self> {
        Ok(Self::new(Scene::from_json(text)?)?)
    }

    /// Validate a scene given as TOML text.
    #[staticmethod]
    fn from_toml(text: &str) -> PyResult<Self> {
        Ok(Self::new(Scene::from_toml(text)?)?)
    }

    /// The default scene (docs/model.md#default-scene); `load` is "idle", "paper" or "rated".
    #[staticmethod]
    fn paper(load: &str) -> PyResult<Self> {
        Ok(Self::new(Scene::paper(load)?)?)
    }

    /// The physical preset (docs/model.md#the-physical-preset): the paper's reducer with line
    /// contact pins, ISO 6336 meshes, roller bearings and 5 % modal damping; `load` as for
    /// `paper`.
    #[staticmethod]
    fn physical(load: &str) -> PyResult<Self> {
        Ok(Self::new(Scene::physical(load)?)?)
    }

    /// ISO 281 basic dynamic load ratings [N] (`kind="static"`: ISO 76 basic static load
    /// ratings) of the eccentric and the crank bearings that are built from rollers (`None` for
    /// a linear bearing, rigid crank bearings or ideal joints).
    #[pyo3(signature = (kind = "dynamic"))]
    fn bearing_ratings(&self, kind: &str) -> PyResult<(Option<f64>, Option<f64>)> {
        use crate::dynamics::scene::Joints;
        let static_ = match kind {
            "dynamic" => false,
            "static" => true,
            other => {
                return Err(crate::python::parameter_error(format!(
                    "kind must be \"dynamic\" (ISO 281) or \"static\" (ISO 76), got {other:?}"
                )));
            }
        };
        let rating = |b: Option<&crate::dynamics::scene::Bearing>| -> PyResult<Option<f64>> {
            match b.and_then(|b| b.rollers) {
                Some(r) if static_ => Ok(Some(r.static_load_rating()?)),
                Some(r) => Ok(Some(r.load_rating()?)),
                None => Ok(None),
            }
        };
        match &self.scene.joints {
            Joints::Rigid => Ok((None, None)),
            Joints::Compliant {
                eccentric_bearing,
                crank_bearing,
            } => Ok((
                rating(Some(eccentric_bearing))?,
                rating(crank_bearing.as_ref())?,
            )),
        }
    }

    /// The contact physics at the rated operating point, as JSON text: pin law, classical peak
    /// pin force [N] and the law's approach there [m], mesh law, rated mesh force [N] and mean
    /// mesh stiffness [N/m], damping in words (`analysis::pin_load_sharing::physics_summary`).
    fn physics_summary(&self) -> PyResult<String> {
        let p = crate::analysis::pin_load_sharing::physics_summary(&self.scene)?;
        let v = serde_json::json!({
            "pin_law": p.pin_law,
            "peak_pin_force_N": p.peak_pin_force,
            "pin_approach_m": p.pin_approach,
            "mesh_law": p.mesh_law,
            "mesh_force_N": p.mesh_force,
            "mesh_stiffness_N_per_m": p.mesh_stiffness,
            "damping": p.damping,
        });
        Ok(v.to_string())
    }

    /// The scene as JSON text (pretty when `indent`).
    #[pyo3(signature = (indent = true))]
    fn to_json(&self, indent: bool) -> PyResult<String> {
        let text = if indent {
            serde_json::to_string_pretty(&self.tree)
        } else {
            serde_json::to_string(&self.tree)
        };
        Ok(text.map_err(json_error)?)
    }

    /// The scene as TOML text.
    fn to_toml(&self) -> PyResult<String> {
        Ok(self.scene.to_toml()?)
    }

    /// The value at a dotted field path, as JSON text.
    fn get(&self, path: &str) -> PyResult<String> {
        Ok(serde_json::to_string(get_path(&self.tree, path)?).map_err(json_error)?)
    }

    /// A new validated scene with fields changed: `(dotted path, JSON text of the value)` pairs.
    fn replace(&self, changes: Vec<(String, String)>) -> PyResult<Self> {
        let parsed = changes
            .into_iter()
            .map(|(p, v)| Ok((p, serde_json::from_str(&v).map_err(json_error)?)))
            .collect::<Result<Vec<_>, RvdynError>>()?;
        Ok(Self::new(self.scene.replace(&parsed)?)?)
    }

    /// Nominal tangential force of one sun/planet mesh at the load's largest torque \[N\] (0
    /// idle, `None` without a first stage).
    fn nominal_mesh_force(&self) -> Option<f64> {
        self.scene.nominal_mesh_force()
    }

    /// Whether the load is light (idle, or a nominal mesh force below 10 N).
    fn is_light_load(&self) -> bool {
        self.scene.is_light_load()
    }

    /// Mass properties and generalised masses the model uses (SI).
    fn model_info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        model_info(py, &self.scene)
    }

    fn __eq__(&self, other: &Self) -> bool {
        self.scene == other.scene
    }

    fn __hash__(&self) -> u64 {
        let mut h = std::collections::hash_map::DefaultHasher::new();
        hash_value(&self.tree, &mut h);
        h.finish()
    }
}

/// Mass properties and generalised masses the model uses for a scene (SI).
fn model_info<'py>(py: Python<'py>, sc: &Scene) -> PyResult<Bound<'py, PyDict>> {
    let dof = match sc.joints {
        Joints::Rigid => None,
        Joints::Compliant { .. } => Some(CompliantModel::new(sc)?.dof()),
    };
    let model = RigidModel::new(&sc.rigid_counterpart())?;
    let d = PyDict::new(py);
    let i = model.inertias;
    // Without a first stage there is no sun: its coordinate stays in the model's vectors but
    // carries nothing, so its mass is reported as zero rather than the default sun's.
    let no_sun = sc.stage1.is_none();
    let sun = if no_sun {
        crate::geometry::mass::MassProperties {
            mass: 0.0,
            inertia: 0.0,
        }
    } else {
        i.sun
    };
    for (name, mp) in [
        ("sun", sun),
        ("crank", i.crank),
        ("disc", i.disc),
        ("carrier", i.carrier),
    ] {
        d.set_item(format!("{name}_mass"), mp.mass)?;
        d.set_item(format!("{name}_inertia"), mp.inertia)?;
    }
    d.set_item("load_inertia", i.load_inertia)?;
    d.set_item("motor_inertia", i.motor_inertia)?;
    let mut mass = model.mass.to_vec();
    if no_sun {
        mass[crate::dynamics::model::rigid::SUN] = 0.0;
    }
    d.set_item("generalized_mass", mass)?;
    d.set_item("crank_radius", model.crank_radius)?;
    d.set_item("ratio", model.ratio)?;
    d.set_item("max_penetration", model.max_penetration)?;
    d.set_item(
        "dof",
        dof.unwrap_or(model.free.len() + model.shaft_free.len()),
    )?;
    d.set_item("joints", if dof.is_some() { "compliant" } else { "rigid" })?;
    Ok(d)
}

/// The default compliant joints (assumed bearing stiffness and damping) as JSON.
#[pyfunction]
fn default_compliant_joints() -> PyResult<String> {
    serde_json::to_string(&default_joints())
        .map_err(|e| crate::python::parameter_error(format!("cannot write joints: {e}")))
}

/// The scene schema (docs/scene.md): one dict per field with its dotted `path` (`[]` for any
/// list index), the variant it belongs to (`when`), JSON `type`, SI `unit` (`-` for none),
/// `default` as JSON text (None = required), `rule` and `doc`.
#[pyfunction]
fn scene_fields(py: Python<'_>) -> PyResult<Vec<Bound<'_, pyo3::types::PyDict>>> {
    crate::dynamics::scene::schema::FIELDS
        .iter()
        .map(|f| {
            let d = pyo3::types::PyDict::new(py);
            d.set_item("path", f.path)?;
            d.set_item("when", f.when)?;
            d.set_item("type", f.ty)?;
            d.set_item("unit", f.unit)?;
            d.set_item("default", f.default)?;
            d.set_item("rule", f.rule)?;
            d.set_item("doc", f.doc)?;
            Ok(d)
        })
        .collect()
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<CompiledScene>()?;
    m.add_function(wrap_pyfunction!(default_compliant_joints, m)?)?;
    m.add_function(wrap_pyfunction!(scene_fields, m)?)?;
    Ok(())
}
