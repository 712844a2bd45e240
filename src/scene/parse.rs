//! Scene file → [`Scene`], validating everything with one-line errors.

use super::json::*;
use super::{MAX_CURVE_SAMPLES, MAX_DEGREE, MAX_SURFACE_SAMPLES, Scene, SceneError, SceneObject};
use crate::geom::{
    BFunctionKind, BSplineCurve, BezierSpline, CatmullRom, GeomError, JoinContinuity, KnotVector,
    Parametrization, TensorSurface,
};
use crate::model::{
    BezierSplineModel, CatmullRomModel, CurveModel, EditError, ErbsCurveModel, ErbsSurfaceModel,
    Model, SplineForm, SurfaceModel,
};
use crate::profile::{LOAD_PROGRESS_AFTER, Progress};
use glam::DVec3;
use serde::Deserialize;
use serde_json::{Map, Value};
use std::collections::HashMap;

/// Parses and validates scene JSON text.
///
/// The objects are streamed: each one is read into a small `Value`, validated into its model and
/// dropped before the next, so that a large scene never holds a `Value` tree of the whole file
/// (which took more time to build and free than the parsing itself, and four times the memory
/// of the models).
pub fn parse_scene(text: &str) -> Result<Scene, SceneError> {
    if !text.trim_start().starts_with('{') {
        // Not an object (or not JSON): the whole-value path words the message.
        return parse_scene_value(text);
    }
    let failed = std::cell::RefCell::new(None);
    let mut de = serde_json::Deserializer::from_str(text);
    let parsed =
        serde::de::Deserializer::deserialize_map(&mut de, SceneVisitor { failed: &failed })
            .and_then(|objects| de.end().map(|()| objects));
    match (parsed, failed.into_inner()) {
        (_, Some(e)) => Err(e),
        (Ok(objects), None) => {
            check_connections(&objects)?;
            Ok(Scene { objects })
        }
        (Err(e), None) => Err(SceneError(format!("invalid JSON: {e}"))),
    }
}

/// The scene text through one `Value` tree: only for text that is not a JSON object, whose
/// message this words.
fn parse_scene_value(text: &str) -> Result<Scene, SceneError> {
    let v: Value =
        serde_json::from_str(text).map_err(|e| SceneError(format!("invalid JSON: {e}")))?;
    Err(SceneError(format!(
        "the scene must be a JSON object {{\"objects\": [...]}}, found {}",
        kind(&v)
    )))
}

/// A scene error raised inside the streaming deserializer: kept here and handed to serde as an
/// empty custom error, so that it reaches the user as it was worded, not with serde's position.
type Failed<'a> = &'a std::cell::RefCell<Option<SceneError>>;

fn fail<E: serde::de::Error>(failed: Failed<'_>, e: SceneError) -> E {
    failed.replace(Some(e));
    E::custom("")
}

/// The top-level `{"objects": [...]}`.
struct SceneVisitor<'a> {
    failed: Failed<'a>,
}

impl<'de> serde::de::Visitor<'de> for SceneVisitor<'_> {
    type Value = Vec<SceneObject>;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("a scene object {\"objects\": [...]}")
    }

    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
        let at = At("scene".into());
        let mut objects = None;
        while let Some(key) = map.next_key::<String>()? {
            match key.as_str() {
                "objects" if objects.is_some() => {
                    return Err(fail(self.failed, at.err("objects", "given twice")));
                }
                "objects" => {
                    objects = Some(map.next_value_seed(ObjectsSeed {
                        failed: self.failed,
                    })?);
                }
                _ => {
                    return Err(fail(
                        self.failed,
                        SceneError(format!(
                            "scene: unknown field '{key}' (expected one of: objects)"
                        )),
                    ));
                }
            }
        }
        objects.ok_or_else(|| fail(self.failed, at.err("objects", "missing")))
    }
}

/// The `objects` array, parsed one object at a time.
struct ObjectsSeed<'a> {
    failed: Failed<'a>,
}

impl<'de> serde::de::DeserializeSeed<'de> for ObjectsSeed<'_> {
    type Value = Vec<SceneObject>;

    fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
        // Any JSON value: an array is streamed, anything else is refused with its kind.
        let v = d.deserialize_any(self)?;
        Ok(v)
    }
}

impl<'de> serde::de::Visitor<'de> for ObjectsSeed<'_> {
    type Value = Vec<SceneObject>;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("an array of objects")
    }

    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
        let mut objects: Vec<SceneObject> = Vec::with_capacity(seq.size_hint().unwrap_or(0));
        // Name → index, so that uniqueness costs one hash per object, not a scan of all before
        // it.
        let mut names: HashMap<String, usize> = HashMap::new();
        let progress = Progress::delayed("parsing", None, LOAD_PROGRESS_AFTER).unit("objects");
        while let Some(item) = seq.next_element::<Value>()? {
            progress.inc(1);
            let i = objects.len();
            let obj = parse_object(i, &item).map_err(|e| fail(self.failed, e))?;
            if let Some(j) = names.insert(obj.name.clone(), i) {
                return Err(fail(
                    self.failed,
                    SceneError(format!(
                        "object '{}' (objects[{i}]): field 'name': duplicate name, already used by objects[{j}]",
                        obj.name
                    )),
                ));
            }
            objects.push(obj);
        }
        // Cleared, not left: the load's progress is transient, and an error that follows
        // must stand on its own line.
        drop(progress);
        Ok(objects)
    }

    fn visit_map<A: serde::de::MapAccess<'de>>(self, map: A) -> Result<Self::Value, A::Error> {
        let v = Value::deserialize(serde::de::value::MapAccessDeserializer::new(map))?;
        Err(self.wrong_kind(&v))
    }

    fn visit_bool<E: serde::de::Error>(self, b: bool) -> Result<Self::Value, E> {
        Err(self.wrong_kind(&Value::Bool(b)))
    }

    fn visit_i64<E: serde::de::Error>(self, x: i64) -> Result<Self::Value, E> {
        Err(self.wrong_kind(&Value::from(x)))
    }

    fn visit_u64<E: serde::de::Error>(self, x: u64) -> Result<Self::Value, E> {
        Err(self.wrong_kind(&Value::from(x)))
    }

    fn visit_f64<E: serde::de::Error>(self, x: f64) -> Result<Self::Value, E> {
        Err(self.wrong_kind(&Value::from(x)))
    }

    fn visit_str<E: serde::de::Error>(self, x: &str) -> Result<Self::Value, E> {
        Err(self.wrong_kind(&Value::from(x)))
    }

    fn visit_unit<E: serde::de::Error>(self) -> Result<Self::Value, E> {
        Err(self.wrong_kind(&Value::Null))
    }
}

impl ObjectsSeed<'_> {
    fn wrong_kind<E: serde::de::Error>(&self, v: &Value) -> E {
        let at = At("scene".into());
        fail(self.failed, as_array(&at, "objects", v).unwrap_err())
    }
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
    let model = match ty {
        "bezier_curve" | "bspline_curve" => {
            let (form, c) = spline_curve(&at, obj, ty, &OBJECT_FIELDS)?;
            curve(&at, form, c, curve_samples(&at, obj)?)?
        }
        "bezier_surface" | "bspline_surface" => {
            let (form, s) = spline_surface(&at, obj, ty, &OBJECT_FIELDS)?;
            surface(&at, form, s, surface_samples(&at, obj)?)?
        }
        "erbs_curve" => {
            let c = super::parse_erbs::erbs_curve(&at, obj, &OBJECT_FIELDS)?;
            let m = ErbsCurveModel::new(c, curve_samples(&at, obj)?);
            Model::ErbsCurve(m.map_err(|e| edit(&at, e))?)
        }
        "erbs_surface" => {
            let s = super::parse_erbs::erbs_surface(&at, obj, &OBJECT_FIELDS)?;
            let m = ErbsSurfaceModel::new(s, surface_samples(&at, obj)?);
            Model::ErbsSurface(m.map_err(|e| edit(&at, e))?)
        }
        "catmull_rom" => {
            check_fields(
                &at,
                obj,
                &with(&OBJECT_FIELDS, &["points", "parametrization", "closed"]),
            )?;
            let points = as_points(&at, "points", require(&at, obj, "points")?)?;
            let parametrization = match opt(obj, "parametrization") {
                None => Parametrization::default(),
                Some(v) => {
                    let name = as_str(&at, "parametrization", v)?;
                    Parametrization::from_name(name).ok_or_else(|| {
                        at.err(
                            "parametrization",
                            format!(
                                "unknown parametrization '{name}' (expected one of: uniform, centripetal, chordal)"
                            ),
                        )
                    })?
                }
            };
            let closed = match opt(obj, "closed") {
                None => false,
                Some(v) => v.as_bool().ok_or_else(|| {
                    at.err(
                        "closed",
                        format!("expected true or false, found {}", kind(v)),
                    )
                })?,
            };
            let c = CatmullRom::new(points, parametrization, closed).map_err(|e| geom(&at, e))?;
            let m = CatmullRomModel::new(c, curve_samples(&at, obj)?);
            Model::CatmullRom(m.map_err(|e| edit(&at, e))?)
        }
        "bezier_spline" => {
            check_fields(
                &at,
                obj,
                &with(&OBJECT_FIELDS, &["degree", "knots", "points", "continuity"]),
            )?;
            let degree = as_usize(&at, "degree", "degree", require(&at, obj, "degree")?)?;
            check_degree(&at, "degree", degree)?;
            let knots = as_f64_list(&at, "knots", "knot", require(&at, obj, "knots")?)?;
            let points = as_points(&at, "points", require(&at, obj, "points")?)?;
            let name = as_str(&at, "continuity", require(&at, obj, "continuity")?)?;
            let continuity = JoinContinuity::from_name(name).ok_or_else(|| {
                at.err(
                    "continuity",
                    format!("unknown continuity '{name}' (expected one of: C0, G1, C1, C2)"),
                )
            })?;
            let c =
                BezierSpline::new(degree, knots, points, continuity).map_err(|e| geom(&at, e))?;
            let m = BezierSplineModel::new(c, curve_samples(&at, obj)?);
            Model::BezierSpline(m.map_err(|e| edit(&at, e))?)
        }
        other => {
            return Err(at.err(
                "type",
                format!(
                    "unknown type '{other}' (expected one of: bezier_curve, bspline_curve, erbs_curve, catmull_rom, bezier_spline, bezier_surface, bspline_surface, erbs_surface)"
                ),
            ));
        }
    };
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

/// The geometry of a `bezier_curve` or `bspline_curve` body (an object, an ERBS `from`
/// source, a local curve); `outer` lists the other fields the body may hold.
pub(super) fn spline_curve(
    at: &At,
    obj: &Map<String, Value>,
    ty: &str,
    outer: &[&'static str],
) -> Result<(SplineForm, BSplineCurve), SceneError> {
    let weights = || {
        opt(obj, "weights")
            .map(|w| as_f64_list(at, "weights", "weight", w))
            .transpose()
    };
    if ty == "bezier_curve" {
        check_fields(at, obj, &with(outer, &["points", "weights"]))?;
        let points = as_points(at, "points", require(at, obj, "points")?)?;
        check_degree(at, "points", points.len() - 1)?;
        let knots = KnotVector::bezier(points.len() - 1, 0.0, 1.0).into_vec();
        let c = BSplineCurve::new(points.len() - 1, knots, points, weights()?)
            .map_err(|e| geom(at, e))?;
        return Ok((SplineForm::Bezier, c));
    }
    check_fields(
        at,
        obj,
        &with(outer, &["degree", "knots", "points", "weights"]),
    )?;
    let degree = as_usize(at, "degree", "degree", require(at, obj, "degree")?)?;
    check_degree(at, "degree", degree)?;
    let knots = as_f64_list(at, "knots", "knot", require(at, obj, "knots")?)?;
    let points = as_points(at, "points", require(at, obj, "points")?)?;
    let c = BSplineCurve::new(degree, knots, points, weights()?).map_err(|e| geom(at, e))?;
    Ok((SplineForm::BSpline, c))
}

/// The geometry of a `bezier_surface` or `bspline_surface` body.
pub(super) fn spline_surface(
    at: &At,
    obj: &Map<String, Value>,
    ty: &str,
    outer: &[&'static str],
) -> Result<(SplineForm, TensorSurface), SceneError> {
    if ty == "bezier_surface" {
        check_fields(at, obj, &with(outer, &["points", "weights"]))?;
        let (count, points) = point_grid(at, "points", require(at, obj, "points")?)?;
        check_degree(at, "points", count[0].max(count[1]) - 1)?;
        let weights = weight_grid(at, obj, count)?;
        let s = TensorSurface::bezier(count, points, weights).map_err(|e| geom(at, e))?;
        return Ok((SplineForm::Bezier, s));
    }
    check_fields(
        at,
        obj,
        &with(outer, &["degree", "knots", "points", "weights"]),
    )?;
    let degree = usize_pair(at, "degree", "[du, dv]", require(at, obj, "degree")?)?;
    check_degree(at, "degree", degree[0].max(degree[1]))?;
    let knots = knot_pair(at, obj)?;
    let (count, points) = point_grid(at, "points", require(at, obj, "points")?)?;
    let weights = weight_grid(at, obj, count)?;
    let s =
        TensorSurface::bspline(degree, knots, count, points, weights).map_err(|e| geom(at, e))?;
    Ok((SplineForm::BSpline, s))
}

/// `[a, b]` of non-negative integers, one per direction (`form` shows it in messages, e.g.
/// "[du, dv]").
pub(super) fn usize_pair(
    at: &At,
    field: &str,
    form: &str,
    v: &Value,
) -> Result<[usize; 2], SceneError> {
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
pub(super) fn with(outer: &[&'static str], own: &[&'static str]) -> Vec<&'static str> {
    outer.iter().chain(own).copied().collect()
}

fn curve(at: &At, form: SplineForm, c: BSplineCurve, m: usize) -> Result<Model, SceneError> {
    Ok(Model::Curve(
        CurveModel::new(form, c, m).map_err(|e| edit(at, e))?,
    ))
}

fn surface(
    at: &At,
    form: SplineForm,
    s: TensorSurface,
    m: [usize; 2],
) -> Result<Model, SceneError> {
    Ok(Model::Surface(
        SurfaceModel::new(form, s, m).map_err(|e| edit(at, e))?,
    ))
}

pub(super) fn edit(at: &At, e: EditError) -> SceneError {
    at.err(e.field, e.message)
}

pub(super) fn opt<'a>(obj: &'a Map<String, Value>, field: &str) -> Option<&'a Value> {
    obj.get(field)
}

pub(super) fn geom(at: &At, e: GeomError) -> SceneError {
    at.err(e.field, e.message)
}

/// `[[u knots], [v knots]]` of a surface.
pub(super) fn knot_pair(at: &At, obj: &Map<String, Value>) -> Result<[Vec<f64>; 2], SceneError> {
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

pub(super) fn check_degree(at: &At, field: &str, degree: usize) -> Result<(), SceneError> {
    if degree > MAX_DEGREE {
        return Err(at.err(
            field,
            format!("degree {degree} exceeds the supported maximum {MAX_DEGREE}"),
        ));
    }
    Ok(())
}

pub(super) fn curve_samples(at: &At, obj: &Map<String, Value>) -> Result<usize, SceneError> {
    let m = as_usize(at, "samples", "samples", require(at, obj, "samples")?)?;
    check_count(at, m, MAX_CURVE_SAMPLES)?;
    Ok(m)
}

pub(super) fn surface_samples(at: &At, obj: &Map<String, Value>) -> Result<[usize; 2], SceneError> {
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

pub(super) fn check_count(at: &At, m: usize, max: usize) -> Result<(), SceneError> {
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

pub(super) fn bfunction(at: &At, obj: &Map<String, Value>) -> Result<BFunctionKind, SceneError> {
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

pub(super) fn point_grid(
    at: &At,
    field: &str,
    v: &Value,
) -> Result<([usize; 2], Vec<DVec3>), SceneError> {
    as_grid(at, field, v, |idx, p| {
        as_point(at, field, format_args!("point {idx}"), p)
    })
}

pub(super) fn weight_grid(
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
