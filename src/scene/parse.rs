//! Scene file → [`Scene`], validating everything with one-line errors.

use super::json::*;
use super::{Scene, SceneError, SceneObject};
use crate::model::Model;
use crate::model::file::opt;
use serde_json::Value;

/// Parses and validates scene JSON text.
pub fn parse_scene(text: &str) -> Result<Scene, SceneError> {
    let v: Value =
        serde_json::from_str(text).map_err(|e| SceneError(format!("invalid JSON: {e}")))?;
    let top = v.as_object().ok_or_else(|| {
        SceneError(format!(
            "the scene must be a JSON object {{\"objects\": [...]}}, found {}",
            kind(&v)
        ))
    })?;
    let at = At("scene".into());
    check_fields(&at, top, &["objects"])?;
    let list = as_array(&at, "objects", require(&at, top, "objects")?)?;
    let mut objects: Vec<SceneObject> = Vec::with_capacity(list.len());
    for (i, item) in list.iter().enumerate() {
        let obj = parse_object(i, item)?;
        if let Some(j) = objects.iter().position(|o| o.name == obj.name) {
            return Err(SceneError(format!(
                "object '{}' (objects[{i}]): field 'name': duplicate name, already used by objects[{j}]",
                obj.name
            )));
        }
        objects.push(obj);
    }
    check_connections(&objects)?;
    Ok(Scene { objects })
}

/// Every kept OBJ `con` joins two surfaces of the scene along curves they keep.
fn check_connections(objects: &[SceneObject]) -> Result<(), SceneError> {
    for (i, o) in objects.iter().enumerate() {
        for (k, c) in o.obj.connections.iter().enumerate() {
            let at = At(format!("object '{}' (objects[{i}])", o.name));
            let other = objects
                .iter()
                .find(|p| p.name == c.surface)
                .ok_or_else(|| {
                    at.err(
                        "obj",
                        format!("connections[{k}]: no object named '{}'", c.surface),
                    )
                })?;
            if !other.model.is_surface() {
                return Err(at.err(
                    "obj",
                    format!("connections[{k}]: '{}' is not a surface", c.surface),
                ));
            }
            let curves = other.obj.curves2.len();
            if c.surface_curve.curve >= curves {
                return Err(at.err(
                    "obj",
                    format!(
                        "connections[{k}]: '{}' keeps no curve {} ({curves} curves)",
                        c.surface, c.surface_curve.curve
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Fields every object has besides its geometry.
const OBJECT_FIELDS: [&str; 5] = ["name", "type", "samples", "color", "obj"];

fn parse_object(i: usize, v: &Value) -> Result<SceneObject, SceneError> {
    let at = At(format!("objects[{i}]"));
    let obj = v.as_object().ok_or_else(|| {
        SceneError(format!(
            "objects[{i}]: expected an object, found {}",
            kind(v)
        ))
    })?;
    let name = as_str(&at, "name", require(&at, obj, "name")?)?;
    if name.is_empty() {
        return Err(at.err("name", "empty name"));
    }
    let at = At(format!("object '{name}' (objects[{i}])"));
    let ty = as_str(&at, "type", require(&at, obj, "type")?)?;
    let model = Model::read(ty, &at, obj, &OBJECT_FIELDS).unwrap_or_else(|| {
        Err(at.err(
            "type",
            format!(
                "unknown type '{ty}' (expected one of: {})",
                Model::types().join(", ")
            ),
        ))
    })?;
    let color = opt(obj, "color").map(|c| parse_color(&at, c)).transpose()?;
    let kept = opt(obj, "obj")
        .map(|v| super::obj::carried::from_json(&at, v, model.is_surface()))
        .transpose()?
        .unwrap_or_default();
    Ok(SceneObject {
        name: name.to_string(),
        model,
        color,
        obj: kept,
    })
}

fn parse_color(at: &At, v: &Value) -> Result<[f64; 3], SceneError> {
    let p = as_point(at, "color", "color", v)?;
    if !p.cmpge(glam::DVec3::ZERO).all() || !p.cmple(glam::DVec3::ONE).all() {
        return Err(at.err(
            "color",
            format!("components must lie in [0, 1], found {:?}", p.to_array()),
        ));
    }
    Ok(p.to_array())
}
