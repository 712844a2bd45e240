//! Typed access to `serde_json::Value` with one-line errors that say where the problem is.
//!
//! Scene and edit files are parsed in two steps (text → `Value` → model) rather than with serde
//! derives so that every message names the object, the field and the index that is wrong.

use glam::DVec3;
use serde_json::{Map, Value};
use std::fmt::Display;

/// Anything wrong with a scene or edit file, as one line naming the object, field and index.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct SceneError(pub String);

/// What reading an object's fields needs besides them: the fields every object has (which
/// the kinds accept without reading), and the memory budget counts read from the file are
/// held to before anything is built from them.
#[derive(Debug, Clone, Copy)]
pub struct ReadCtx<'a> {
    pub common: &'a [&'static str],
    pub budget: crate::sampling::budget::MemoryBudget,
}

/// Where we are, e.g. "object 'c' (objects[2])"; prefixes every message.
#[derive(Clone)]
pub struct At(pub String);

impl At {
    pub fn err(&self, field: &str, msg: impl std::fmt::Display) -> SceneError {
        SceneError(format!("{}: field '{field}': {msg}", self.0))
    }
}

/// Describes a JSON value's kind for messages.
#[must_use]
pub fn kind(v: &Value) -> &'static str {
    match v {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

/// Rejects fields outside `allowed` (unknown fields are an error, never silently ignored).
pub fn check_fields(at: &At, obj: &Map<String, Value>, allowed: &[&str]) -> Result<(), SceneError> {
    for key in obj.keys() {
        if !allowed.contains(&key.as_str()) {
            return Err(SceneError(format!(
                "{}: unknown field '{key}' (expected one of: {})",
                at.0,
                allowed.join(", ")
            )));
        }
    }
    Ok(())
}

pub fn require<'a>(
    at: &At,
    obj: &'a Map<String, Value>,
    field: &str,
) -> Result<&'a Value, SceneError> {
    obj.get(field).ok_or_else(|| at.err(field, "missing"))
}

pub fn as_object<'a>(
    at: &At,
    field: &str,
    v: &'a Value,
) -> Result<&'a Map<String, Value>, SceneError> {
    v.as_object()
        .ok_or_else(|| at.err(field, format!("expected an object, found {}", kind(v))))
}

pub fn as_array<'a>(at: &At, field: &str, v: &'a Value) -> Result<&'a Vec<Value>, SceneError> {
    v.as_array()
        .ok_or_else(|| at.err(field, format!("expected an array, found {}", kind(v))))
}

pub fn as_str<'a>(at: &At, field: &str, v: &'a Value) -> Result<&'a str, SceneError> {
    v.as_str()
        .ok_or_else(|| at.err(field, format!("expected a string, found {}", kind(v))))
}

/// A finite number. (JSON itself cannot spell NaN or infinity; out-of-range literals are caught
/// by the JSON parser.)
pub fn as_f64(at: &At, field: &str, what: impl Display, v: &Value) -> Result<f64, SceneError> {
    match v.as_f64() {
        Some(x) if x.is_finite() => Ok(x),
        Some(x) => Err(at.err(field, format!("{what} is {x}, not a finite number"))),
        None => Err(at.err(
            field,
            format!("{what}: expected a number, found {}", kind(v)),
        )),
    }
}

/// A non-negative integer (1.0 is not accepted: counts and indices are integers).
pub fn as_usize(at: &At, field: &str, what: impl Display, v: &Value) -> Result<usize, SceneError> {
    match v.as_u64() {
        Some(x) => {
            usize::try_from(x).map_err(|_| at.err(field, format!("{what} {x} is too large")))
        }
        None => Err(at.err(
            field,
            format!("{what}: expected a non-negative integer, found {v}"),
        )),
    }
}

pub fn as_f64_list(
    at: &At,
    field: &str,
    what: impl Display,
    v: &Value,
) -> Result<Vec<f64>, SceneError> {
    as_array(at, field, v)?
        .iter()
        .enumerate()
        .map(|(i, x)| as_f64(at, field, format_args!("{what} {i}"), x))
        .collect()
}

/// [x, y, z].
pub fn as_point(at: &At, field: &str, what: impl Display, v: &Value) -> Result<DVec3, SceneError> {
    let a = v.as_array().ok_or_else(|| {
        at.err(
            field,
            format!("{what}: expected [x, y, z], found {}", kind(v)),
        )
    })?;
    if a.len() != 3 {
        return Err(at.err(
            field,
            format!("{what}: expected 3 coordinates, found {}", a.len()),
        ));
    }
    let c = |i: usize| as_f64(at, field, format_args!("{what} coordinate {i}"), &a[i]);
    Ok(DVec3::new(c(0)?, c(1)?, c(2)?))
}

/// [[x,y,z], …].
pub fn as_points(at: &At, field: &str, v: &Value) -> Result<Vec<DVec3>, SceneError> {
    let a = as_array(at, field, v)?;
    if a.is_empty() {
        return Err(at.err(field, "no points"));
    }
    a.iter()
        .enumerate()
        .map(|(i, p)| as_point(at, field, format_args!("point {i}"), p))
        .collect()
}

/// Where an entry of a grid is, displayed "[i][j]" only when a message needs it (formatting it
/// for every entry of a large scene costs more than parsing the number).
#[derive(Debug, Clone, Copy)]
pub struct GridIndex(pub usize, pub usize);

impl Display for GridIndex {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "[{}][{}]", self.0, self.1)
    }
}

/// A rectangular [rows][cols] array, flattened row-major, with its shape.
pub fn as_grid<T>(
    at: &At,
    field: &str,
    v: &Value,
    item: impl Fn(GridIndex, &Value) -> Result<T, SceneError>,
) -> Result<([usize; 2], Vec<T>), SceneError> {
    let rows = as_array(at, field, v)?;
    if rows.is_empty() {
        return Err(at.err(field, "empty grid"));
    }
    let mut cols = None;
    let mut out = Vec::new();
    for (i, row) in rows.iter().enumerate() {
        let r = row.as_array().ok_or_else(|| {
            at.err(
                field,
                format!("row {i}: expected an array, found {}", kind(row)),
            )
        })?;
        match cols {
            None if r.is_empty() => return Err(at.err(field, format!("row {i} is empty"))),
            None => cols = Some(r.len()),
            Some(c) if c != r.len() => {
                return Err(at.err(
                    field,
                    format!("row {i} has {} entries, row 0 has {c}", r.len()),
                ));
            }
            Some(_) => {}
        }
        for (j, x) in r.iter().enumerate() {
            out.push(item(GridIndex(i, j), x)?);
        }
    }
    Ok(([rows.len(), cols.unwrap_or(0)], out))
}
