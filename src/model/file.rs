//! What every kind's file code shares: sample counts, degrees, point grids and weights read
//! with one-line errors, and the pieces of the edit vocabulary common to all kinds.

use super::{EditError, MAX_CURVE_SAMPLES, MAX_DEGREE, MAX_SURFACE_SAMPLES, PointEdit};
use crate::fields::json::*;
use crate::geom::{BFunctionKind, GeomError};
use glam::DVec3;
use serde_json::{Map, Value};

/// `[a, b]` of non-negative integers, one per direction (`form` shows it in messages, e.g.
/// "[du, dv]").
pub fn usize_pair(at: &At, field: &str, form: &str, v: &Value) -> Result<[usize; 2], SceneError> {
    match v.as_array() {
        Some(a) if a.len() == 2 => Ok([
            as_usize(at, field, format_args!("{field}[0]"), &a[0])?,
            as_usize(at, field, format_args!("{field}[1]"), &a[1])?,
        ]),
        Some(a) => Err(at.err(field, format!("expected {form}, found {} entries", a.len()))),
        None => Err(at.err(field, format!("expected {form}, found {v}"))),
    }
}

/// `outer` plus the body's own fields.
#[must_use]
pub fn with(outer: &[&'static str], own: &[&'static str]) -> Vec<&'static str> {
    outer.iter().chain(own).copied().collect()
}

#[must_use]
pub fn edit(at: &At, e: EditError) -> SceneError {
    at.err(e.field, e.message)
}

#[must_use]
pub fn opt<'a>(obj: &'a Map<String, Value>, field: &str) -> Option<&'a Value> {
    obj.get(field)
}

#[must_use]
pub fn geom(at: &At, e: GeomError) -> SceneError {
    at.err(e.field, e.message)
}

/// `[[u knots], [v knots]]` of a surface.
pub fn knot_pair(at: &At, obj: &Map<String, Value>) -> Result<[Vec<f64>; 2], SceneError> {
    let kv = as_array(at, "knots", require(at, obj, "knots")?)?;
    if kv.len() != 2 {
        return Err(at.err(
            "knots",
            format!(
                "expected [[u knots], [v knots]], found {} entries",
                kv.len()
            ),
        ));
    }
    Ok([
        as_f64_list(at, "knots", "u knot", &kv[0])?,
        as_f64_list(at, "knots", "v knot", &kv[1])?,
    ])
}

pub fn check_degree(at: &At, field: &str, degree: usize) -> Result<(), SceneError> {
    if degree > MAX_DEGREE {
        return Err(at.err(
            field,
            format!("degree {degree} exceeds the supported maximum {MAX_DEGREE}"),
        ));
    }
    Ok(())
}

pub fn curve_samples(at: &At, obj: &Map<String, Value>) -> Result<usize, SceneError> {
    let m = as_usize(at, "samples", "samples", require(at, obj, "samples")?)?;
    check_count(at, m, MAX_CURVE_SAMPLES)?;
    Ok(m)
}

pub fn surface_samples(at: &At, obj: &Map<String, Value>) -> Result<[usize; 2], SceneError> {
    let v = require(at, obj, "samples")?;
    let a = v
        .as_array()
        .filter(|a| a.len() == 2)
        .ok_or_else(|| at.err("samples", format!("expected [mu, mv], found {v}")))?;
    let mu = as_usize(at, "samples", "samples[0]", &a[0])?;
    let mv = as_usize(at, "samples", "samples[1]", &a[1])?;
    check_count(at, mu, MAX_SURFACE_SAMPLES)?;
    check_count(at, mv, MAX_SURFACE_SAMPLES)?;
    if mu.saturating_mul(mv) > MAX_SURFACE_SAMPLES {
        return Err(at.err(
            "samples",
            format!("{mu} × {mv} samples exceed the limit of {MAX_SURFACE_SAMPLES}"),
        ));
    }
    Ok([mu, mv])
}

pub fn check_count(at: &At, m: usize, max: usize) -> Result<(), SceneError> {
    if m < 2 {
        return Err(at.err(
            "samples",
            format!("{m} samples: at least 2 are needed (both ends are sampled)"),
        ));
    }
    if m > max {
        return Err(at.err("samples", format!("{m} samples exceed the limit of {max}")));
    }
    Ok(())
}

pub fn bfunction(at: &At, obj: &Map<String, Value>) -> Result<BFunctionKind, SceneError> {
    let Some(v) = obj.get("bfunction") else {
        return Ok(BFunctionKind::default());
    };
    let name = as_str(at, "bfunction", v)?;
    BFunctionKind::from_name(name).ok_or_else(|| {
        let names: Vec<_> = BFunctionKind::ALL.iter().map(|k| k.name()).collect();
        at.err(
            "bfunction",
            format!(
                "unknown B-function '{name}' (expected one of: {})",
                names.join(", ")
            ),
        )
    })
}

pub fn point_grid(at: &At, field: &str, v: &Value) -> Result<([usize; 2], Vec<DVec3>), SceneError> {
    as_grid(at, field, v, |idx, p| {
        as_point(at, field, format_args!("point {idx}"), p)
    })
}

pub fn weight_grid(
    at: &At,
    obj: &Map<String, Value>,
    count: [usize; 2],
) -> Result<Option<Vec<f64>>, SceneError> {
    let Some(v) = obj.get("weights") else {
        return Ok(None);
    };
    let (shape, w) = as_grid(at, "weights", v, |idx, x| {
        as_f64(at, "weights", format_args!("weight {idx}"), x)
    })?;
    if shape != count {
        return Err(at.err(
            "weights",
            format!(
                "{} × {} weights for {} × {} control points",
                shape[0], shape[1], count[0], count[1]
            ),
        ));
    }
    // Checked here rather than left to the geometry's flat check, so that the message names
    // the weight the way the file writes it: [row][column].
    if let Some(k) = w.iter().position(|x| !(x.is_finite() && *x > 0.0)) {
        let (i, j) = (k / count[1], k % count[1]);
        return Err(at.err(
            "weights",
            format!(
                "weight [{i}][{j}] is {}; weights must be positive and finite",
                w[k]
            ),
        ));
    }
    Ok(Some(w))
}

/// A non-negative integer.
pub fn count(at: &At, field: &str, v: &Value) -> Result<usize, SceneError> {
    match v.as_i64() {
        Some(n) if n < 0 => Err(at.err(field, format!("{n} is negative"))),
        _ => as_usize(at, field, field, v),
    }
}

/// A positive integer.
pub fn positive(at: &At, field: &str, v: &Value) -> Result<usize, SceneError> {
    match count(at, field, v)? {
        0 => Err(at.err(field, "must be at least 1")),
        n => Ok(n),
    }
}

pub fn index(at: &At, field: &str, v: &Value) -> Result<usize, SceneError> {
    if v.is_array() {
        return Err(at.err(field, format!("expected an index for a curve, found {v}")));
    }
    as_usize(at, field, "index", v)
}

/// `[i, j]`.
pub fn pair(at: &At, field: &str, v: &Value) -> Result<[usize; 2], SceneError> {
    match v.as_array() {
        Some(a) if a.len() == 2 => Ok([
            as_usize(at, field, "index", &a[0])?,
            as_usize(at, field, "index", &a[1])?,
        ]),
        _ => Err(at.err(field, format!("expected [i, j] for a surface, found {v}"))),
    }
}

/// `{"u": t}` or `{"v": t}`.
pub fn direction_parameter(at: &At, v: &Value) -> Result<(usize, f64), SceneError> {
    let one = |key: &str| {
        v.as_object()
            .filter(|d| d.len() == 1)
            .and_then(|d| d.get(key))
    };
    let (dir, t) = match (one("u"), one("v")) {
        (Some(t), _) => (0, t),
        (_, Some(t)) => (1, t),
        _ => {
            return Err(at.err(
                "insert_knot",
                format!("a surface takes {{\"u\": t}} or {{\"v\": t}}, found {v}"),
            ));
        }
    };
    Ok((dir, as_f64(at, "insert_knot", "parameter", t)?))
}

/// `{"point": i, "delta": [..]}` or `{"point": i, "weight": w}`.
pub fn point_edit<I>(
    at: &At,
    obj: &Map<String, Value>,
    index: impl Fn(&Value) -> Result<I, SceneError>,
) -> Result<PointEdit<I>, SceneError> {
    if obj.contains_key("local") {
        return Err(at.err("local", "only ERBS objects have local curves or patches"));
    }
    let point = index(require(at, obj, "point")?)?;
    if obj.contains_key("weight") {
        check_fields(at, obj, &["object", "point", "weight"])?;
        let weight = as_f64(at, "weight", "weight", require(at, obj, "weight")?)?;
        return Ok(PointEdit::Weight { point, weight });
    }
    check_fields(at, obj, &["object", "point", "delta"])?;
    let delta = as_point(at, "delta", "delta", require(at, obj, "delta")?)?;
    Ok(PointEdit::Move { point, delta })
}

impl From<EditError> for SceneError {
    fn from(e: EditError) -> Self {
        SceneError(e.to_string())
    }
}
