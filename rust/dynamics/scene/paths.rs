//! Dotted field paths into a scene's JSON tree (`"discs.1.d_rrp"`), and the check that a tree
//! holds no field the schema does not know.

use crate::error::{Result, RvdynError};

/// The value at dotted `path` of a scene tree.
///
/// Each key is an object field or a list index. Errors (`Scene`) for an empty path or an
/// empty key (`"a..b"`), or a field the tree does not have (the message names the key where
/// the path stops).
///
/// # Example
///
/// ```
/// use rvdyn::dynamics::scene::{Scene, get_path};
/// let tree = serde_json::to_value(Scene::paper("idle").unwrap()).unwrap();
/// assert_eq!(get_path(&tree, "cycloid.pins").unwrap(), 24);
/// // The second disc sits half a turn round the crank [rad].
/// assert_eq!(get_path(&tree, "discs.1.phase").unwrap(), std::f64::consts::PI);
/// assert!(get_path(&tree, "discs.2.phase").is_err()); // two discs only
/// ```
pub fn get_path<'a>(tree: &'a serde_json::Value, path: &str) -> Result<&'a serde_json::Value> {
    let mut node = tree;
    for key in path_keys(path)? {
        node = match node {
            serde_json::Value::Object(m) => m.get(key),
            serde_json::Value::Array(a) => key.parse::<usize>().ok().and_then(|i| a.get(i)),
            _ => None,
        }
        .ok_or_else(|| RvdynError::Scene(format!("scene has no field {path:?} (at {key:?})")))?;
    }
    Ok(node)
}

fn path_keys(path: &str) -> Result<Vec<&str>> {
    if path.is_empty() || path.split('.').any(str::is_empty) {
        return Err(RvdynError::Scene(format!(
            "a scene field path must be a non-empty dotted path like \"load.torque\", got {path:?}"
        )));
    }
    Ok(path.split('.').collect())
}

/// Set the value at dotted `path` (the parent must exist; the last key must be a field of an
/// object, or an index inside a list).
pub(crate) fn set_path(
    tree: &mut serde_json::Value,
    path: &str,
    value: serde_json::Value,
) -> Result<()> {
    let keys = path_keys(path)?;
    let (last, parents) = keys
        .split_last()
        .ok_or_else(|| RvdynError::Scene("a scene field path must not be empty".into()))?;
    let missing = || RvdynError::Scene(format!("scene has no field {path:?}"));
    let mut node = tree;
    for key in parents {
        node = match node {
            serde_json::Value::Object(m) => m.get_mut(*key),
            serde_json::Value::Array(a) => key.parse::<usize>().ok().and_then(|i| a.get_mut(i)),
            _ => None,
        }
        .ok_or_else(|| RvdynError::Scene(format!("scene has no field {path:?} (at {key:?})")))?;
    }
    match node {
        serde_json::Value::Object(m) => {
            m.insert((*last).to_string(), value);
        }
        serde_json::Value::Array(a) => {
            let slot = last
                .parse::<usize>()
                .ok()
                .and_then(|i| a.get_mut(i))
                .ok_or_else(missing)?;
            *slot = value;
        }
        _ => return Err(missing()),
    }
    Ok(())
}

/// First key of `given` that the schema dropped when `normal` was written back.
pub(crate) fn unknown_fields(
    given: &serde_json::Value,
    normal: &serde_json::Value,
    at: &str,
) -> Result<()> {
    use serde_json::Value;
    match (given, normal) {
        (Value::Object(g), Value::Object(n)) => {
            for (k, gv) in g {
                let path = if at.is_empty() {
                    k.clone()
                } else {
                    format!("{at}.{k}")
                };
                match n.get(k) {
                    Some(nv) => unknown_fields(gv, nv, &path)?,
                    None => {
                        let known: Vec<&str> = n.keys().map(String::as_str).collect();
                        return Err(RvdynError::Scene(format!(
                            "unknown scene field {path:?}; the fields here are {}",
                            known.join(", ")
                        )));
                    }
                }
            }
            Ok(())
        }
        (Value::Array(g), Value::Array(n)) => {
            for (i, (gv, nv)) in g.iter().zip(n).enumerate() {
                unknown_fields(gv, nv, &format!("{at}.{i}"))?;
            }
            Ok(())
        }
        _ => Ok(()),
    }
}
