//! The edits file (docs/scene-format.md): a JSON list parsed into the model's edit vocabulary.
//! Edits are validated in order against the model as the earlier edits leave it, so an edit
//! after a knot insertion addresses the refined control net.

use super::json::*;
use super::{Scene, SceneError};
use crate::model::{
    BezierSplineEdit, CatmullRomEdit, CurveEdit, Edit, EditError, ErbsCurveEdit, ErbsSurfaceEdit,
    KindEdit, LocalEdit, LocalPath, Model, ModelRef, ObjectEdit, PointEdit, SurfaceEdit,
};
use glam::DMat4;
use serde_json::{Map, Value};

/// An edits file: a JSON list whose entries are parsed one at a time, each against its
/// object's model as the edits before it leave it (a refinement renumbers what follows).
#[derive(Debug, Clone)]
pub struct EditList(Vec<Value>);

impl EditList {
    /// The list, checked to be a JSON list; its entries are read by [`EditList::edit`].
    pub fn parse(text: &str) -> Result<Self, SceneError> {
        let v: Value =
            serde_json::from_str(text).map_err(|e| SceneError(format!("invalid JSON: {e}")))?;
        match v {
            Value::Array(list) => Ok(Self(list)),
            v => Err(SceneError(format!(
                "the edits file must be a JSON list of edits, found {}",
                kind(&v)
            ))),
        }
    }

    #[must_use]
    pub fn len(&self) -> usize {
        self.0.len()
    }

    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// Edit `k`: `find` gives the index and current model of the object it names. Returns the
    /// edit and its message prefix ("edit 3 (object 'c')") for a refusal later on.
    pub fn edit<'m>(
        &self,
        k: usize,
        find: impl Fn(&str) -> Option<(usize, ModelRef<'m>)>,
    ) -> Result<(Edit, At), SceneError> {
        let v = &self.0[k];
        let at = At(format!("edit {k}"));
        let obj = v.as_object().ok_or_else(|| {
            SceneError(format!("edit {k}: expected an object, found {}", kind(v)))
        })?;
        let name = as_str(&at, "object", require(&at, obj, "object")?)?;
        let (object, model) =
            find(name).ok_or_else(|| at.err("object", format!("unknown object '{name}'")))?;
        let at = At(format!("edit {k} (object '{name}')"));
        let edit = parse_edit(&at, obj, model)?;
        Ok((Edit { object, edit }, at))
    }
}

/// Parses an edits file against `scene`, validating each edit against the model the edits
/// before it leave (models are copied only for objects that are edited).
pub fn parse_edits(text: &str, scene: &Scene) -> Result<Vec<Edit>, SceneError> {
    let list = EditList::parse(text)?;
    let mut edited: Vec<Option<Model>> = vec![None; scene.objects.len()];
    let mut out = Vec::with_capacity(list.len());
    for k in 0..list.len() {
        let (edit, at) = list.edit(k, |name| {
            let i = scene.find(name)?;
            let m = edited[i].as_ref().unwrap_or(&scene.objects[i].model);
            Some((i, m.as_ref()))
        })?;
        let model =
            edited[edit.object].get_or_insert_with(|| scene.objects[edit.object].model.clone());
        edit.edit
            .validate(model.as_ref())
            .and_then(|()| model.apply(&edit.edit))
            .map_err(|e| at.err(e.field, e.message))?;
        out.push(edit);
    }
    Ok(out)
}

/// Applies validated edits to the scene's models in order (the `--full` reference path).
pub fn apply_all(scene: &mut Scene, edits: &[Edit]) -> Result<(), SceneError> {
    for (k, e) in edits.iter().enumerate() {
        let o = &mut scene.objects[e.object];
        o.model
            .apply(&e.edit)
            .map_err(|err| SceneError(format!("edit {k} (object '{}'): {err}", o.name)))?;
    }
    Ok(())
}

fn parse_edit(
    at: &At,
    obj: &Map<String, Value>,
    model: ModelRef<'_>,
) -> Result<ObjectEdit, SceneError> {
    if obj.contains_key("to_bspline") {
        return to_bspline(at, obj, model);
    }
    if let ModelRef::ErbsCurve(_) | ModelRef::ErbsSurface(_) = model {
        return erbs_edit(at, obj, model.is_surface());
    }
    if obj.contains_key("insert_knot") || obj.contains_key("elevate_degree") {
        return structural(at, obj, model);
    }
    Ok(match model {
        ModelRef::CatmullRom(_) => {
            CatmullRomEdit::Point(point_edit(at, obj, |v| index(at, "point", v))?).into_object()
        }
        ModelRef::BezierSpline(_) => match point_edit(at, obj, |v| index(at, "point", v))? {
            PointEdit::Move { point, delta } => {
                BezierSplineEdit::Move { point, delta }.into_object()
            }
            _ => {
                return Err(at.err(
                    "weight",
                    "a bezier_spline has no weights (its segments are polynomial; convert it to a bspline_curve first)",
                ));
            }
        },
        ModelRef::Curve(_) => {
            CurveEdit::Point(point_edit(at, obj, |v| index(at, "point", v))?).into_object()
        }
        ModelRef::Surface(_) => {
            SurfaceEdit::Point(point_edit(at, obj, |v| pair(at, "point", v))?).into_object()
        }
        ModelRef::ErbsCurve(_) | ModelRef::ErbsSurface(_) => unreachable!("handled above"),
    })
}

/// An ERBS edit: a local edit (`local` with `transform`, or `point` and `delta`), a refinement
/// (`insert_knot`, optionally of the ERBS local at `local`, with an optional `degree`), or a
/// local turned into an ERBS local of its own (`local` with `to_erbs`).
fn erbs_edit(at: &At, obj: &Map<String, Value>, surface: bool) -> Result<ObjectEdit, SceneError> {
    if obj.contains_key("elevate_degree") {
        return Err(at.err(
            "elevate_degree",
            "ERBS objects are refined by inserting knots (insert_knot), not by degree elevation",
        ));
    }
    if surface {
        let path = |v: &Value| surface_path(at, v);
        let point = |v: &Value| pair(at, "point", v);
        if let Some(v) = obj.get("insert_knot") {
            check_fields(at, obj, &["object", "local", "insert_knot", "degree"])?;
            let local = obj.get("local").map(path).transpose()?;
            let at_knot = direction_parameter(at, v)?;
            let degree = obj
                .get("degree")
                .map(|d| super::parse::usize_pair(at, "degree", "[du, dv]", d))
                .transpose()?;
            return Ok(ErbsSurfaceEdit::InsertKnot {
                local,
                at: at_knot,
                degree,
            }
            .into_object());
        }
        if let Some(v) = obj.get("to_erbs") {
            check_fields(at, obj, &["object", "local", "to_erbs"])?;
            let local = path(require(at, obj, "local")?)?;
            let spec = as_object(at, "to_erbs", v)?;
            let inner = At(format!("{}: field 'to_erbs'", at.0));
            check_fields(&inner, spec, &["local_patches", "local_degree"])?;
            let count = super::parse::usize_pair(
                at,
                "to_erbs",
                "[nu, nv]",
                require(&inner, spec, "local_patches")?,
            )?;
            let degree = super::parse::usize_pair(
                at,
                "to_erbs",
                "[du, dv]",
                require(&inner, spec, "local_degree")?,
            )?;
            return Ok(ErbsSurfaceEdit::ToErbs {
                local,
                count,
                degree,
            }
            .into_object());
        }
        return Ok(ErbsSurfaceEdit::Local(local_edit(at, obj, path, point)?).into_object());
    }
    let path = |v: &Value| curve_path(at, v);
    let point = |v: &Value| index(at, "point", v);
    if let Some(v) = obj.get("insert_knot") {
        check_fields(at, obj, &["object", "local", "insert_knot", "degree"])?;
        let local = obj.get("local").map(path).transpose()?;
        let t = as_f64(at, "insert_knot", "parameter", v)?;
        let degree = obj
            .get("degree")
            .map(|d| as_usize(at, "degree", "degree", d))
            .transpose()?;
        return Ok(ErbsCurveEdit::InsertKnot {
            local,
            at: t,
            degree,
        }
        .into_object());
    }
    if let Some(v) = obj.get("to_erbs") {
        check_fields(at, obj, &["object", "local", "to_erbs"])?;
        let local = path(require(at, obj, "local")?)?;
        let spec = as_object(at, "to_erbs", v)?;
        let inner = At(format!("{}: field 'to_erbs'", at.0));
        check_fields(&inner, spec, &["local_curves", "local_degree"])?;
        let count = as_usize(
            at,
            "to_erbs",
            "local_curves",
            require(&inner, spec, "local_curves")?,
        )?;
        let degree = as_usize(
            at,
            "to_erbs",
            "local_degree",
            require(&inner, spec, "local_degree")?,
        )?;
        return Ok(ErbsCurveEdit::ToErbs {
            local,
            count,
            degree,
        }
        .into_object());
    }
    Ok(ErbsCurveEdit::Local(local_edit(at, obj, path, point)?).into_object())
}

/// A curve's local path: `l` or `[l, l2, …]` descending through ERBS locals.
fn curve_path(at: &At, v: &Value) -> Result<LocalPath<usize>, SceneError> {
    let steps = match v.as_array() {
        Some(a) => a
            .iter()
            .map(|x| as_usize(at, "local", "index", x))
            .collect::<Result<Vec<_>, _>>()?,
        None => vec![as_usize(at, "local", "index", v)?],
    };
    LocalPath::new(&steps).ok_or_else(|| bad_path(at, steps.len()))
}

/// A surface's local path: `[k, l]` or `[[k, l], [k2, l2], …]`.
fn surface_path(at: &At, v: &Value) -> Result<LocalPath<[usize; 2]>, SceneError> {
    let nested = v
        .as_array()
        .is_some_and(|a| a.first().is_some_and(Value::is_array));
    let steps = if nested {
        as_array(at, "local", v)?
            .iter()
            .map(|x| pair(at, "local", x))
            .collect::<Result<Vec<_>, _>>()?
    } else {
        vec![pair(at, "local", v)?]
    };
    LocalPath::new(&steps).ok_or_else(|| bad_path(at, steps.len()))
}

fn bad_path(at: &At, len: usize) -> SceneError {
    at.err(
        "local",
        format!(
            "a path of {len} steps: paths have 1 to {} steps",
            crate::geom::erbs::MAX_NESTING
        ),
    )
}

/// `{"u": t}` or `{"v": t}`.
fn direction_parameter(at: &At, v: &Value) -> Result<(usize, f64), SceneError> {
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
fn point_edit<I>(
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

/// `{"local": l, "transform": [[4×4]]}` or `{"local": l, "point": q, "delta": [..]}`.
fn local_edit<I: Copy + Default>(
    at: &At,
    obj: &Map<String, Value>,
    path: impl Fn(&Value) -> Result<LocalPath<I>, SceneError>,
    index: impl Fn(&Value) -> Result<I, SceneError>,
) -> Result<LocalEdit<I>, SceneError> {
    let Some(l) = obj.get("local") else {
        let field = if obj.contains_key("transform") {
            "transform"
        } else {
            "point"
        };
        return Err(at.err(
            field,
            "an ERBS object is edited through its local curves: give \"local\" (with \"transform\", or \"point\" and \"delta\")",
        ));
    };
    let local = path(l)?;
    if obj.contains_key("transform") {
        check_fields(at, obj, &["object", "local", "transform"])?;
        let matrix = affine(at, require(at, obj, "transform")?)?;
        return Ok(LocalEdit::Transform { local, matrix });
    }
    check_fields(at, obj, &["object", "local", "point", "delta"])?;
    let point = index(require(at, obj, "point")?)?;
    let delta = as_point(at, "delta", "delta", require(at, obj, "delta")?)?;
    Ok(LocalEdit::MovePoint {
        local,
        point,
        delta,
    })
}

/// `{"object": o, "to_bspline": true}`: a Catmull–Rom or Bézier spline becomes the equivalent
/// `bspline_curve` (later edits address its B-spline control points).
fn to_bspline(
    at: &At,
    obj: &Map<String, Value>,
    model: ModelRef<'_>,
) -> Result<ObjectEdit, SceneError> {
    check_fields(at, obj, &["object", "to_bspline"])?;
    if obj["to_bspline"] != Value::Bool(true) {
        return Err(at.err(
            "to_bspline",
            format!("expected true, found {}", obj["to_bspline"]),
        ));
    }
    let chain = model.to_bspline_curve().ok_or_else(|| {
        at.err(
            "to_bspline",
            format!(
                "only catmull_rom and bezier_spline objects convert to a bspline_curve, not a {}",
                model.type_name()
            ),
        )
    })?;
    Ok(ObjectEdit::Replace(Box::new(chain)))
}

/// `insert_knot` (with optional `times`) and `elevate_degree`, per kind.
fn structural(
    at: &At,
    obj: &Map<String, Value>,
    model: ModelRef<'_>,
) -> Result<ObjectEdit, SceneError> {
    let ty = model.type_name();
    if let ModelRef::CatmullRom(_) | ModelRef::BezierSpline(_) = model {
        let field = if obj.contains_key("insert_knot") {
            "insert_knot"
        } else {
            "elevate_degree"
        };
        return Err(at.err(
            field,
            format!("a {ty} keeps its own segment structure; convert it first ({{\"object\": …, \"to_bspline\": true}}) to refine it"),
        ));
    }
    let surface = model.is_surface();
    if let Some(v) = obj.get("insert_knot") {
        check_fields(at, obj, &["object", "insert_knot", "times"])?;
        let times = match obj.get("times") {
            Some(t) => positive(at, "times", t)?,
            None => 1,
        };
        if !surface {
            let t = as_f64(at, "insert_knot", "parameter", v)?;
            return Ok(CurveEdit::InsertKnot { t, times }.into_object());
        }
        let (dir, t) = direction_parameter(at, v)?;
        return Ok(SurfaceEdit::InsertKnot { dir, t, times }.into_object());
    }
    check_fields(at, obj, &["object", "elevate_degree"])?;
    let v = require(at, obj, "elevate_degree")?;
    if !surface {
        let by = positive(at, "elevate_degree", v)?;
        return Ok(CurveEdit::ElevateDegree { by }.into_object());
    }
    let dirs = as_object(at, "elevate_degree", v)?;
    check_fields(
        &At(format!("{}: field 'elevate_degree'", at.0)),
        dirs,
        &["u", "v"],
    )?;
    let by = |d: &str| {
        dirs.get(d)
            .map_or(Ok(0), |x| count(at, "elevate_degree", x))
    };
    Ok(SurfaceEdit::ElevateDegree {
        by: [by("u")?, by("v")?],
    }
    .into_object())
}

/// A non-negative integer.
fn count(at: &At, field: &str, v: &Value) -> Result<usize, SceneError> {
    match v.as_i64() {
        Some(n) if n < 0 => Err(at.err(field, format!("{n} is negative"))),
        _ => as_usize(at, field, field, v),
    }
}

/// A positive integer.
fn positive(at: &At, field: &str, v: &Value) -> Result<usize, SceneError> {
    match count(at, field, v)? {
        0 => Err(at.err(field, "must be at least 1")),
        n => Ok(n),
    }
}

fn index(at: &At, field: &str, v: &Value) -> Result<usize, SceneError> {
    if v.is_array() {
        return Err(at.err(field, format!("expected an index for a curve, found {v}")));
    }
    as_usize(at, field, "index", v)
}

/// `[i, j]`.
fn pair(at: &At, field: &str, v: &Value) -> Result<[usize; 2], SceneError> {
    match v.as_array() {
        Some(a) if a.len() == 2 => Ok([
            as_usize(at, field, "index", &a[0])?,
            as_usize(at, field, "index", &a[1])?,
        ]),
        _ => Err(at.err(field, format!("expected [i, j] for a surface, found {v}"))),
    }
}

/// A row-major 4×4 affine matrix (last row 0 0 0 1).
fn affine(at: &At, v: &Value) -> Result<DMat4, SceneError> {
    let rows = as_array(at, "transform", v)?;
    if rows.len() != 4 {
        return Err(at.err(
            "transform",
            format!("expected 4 rows, found {}", rows.len()),
        ));
    }
    let mut m = [[0.0; 4]; 4];
    for (r, row) in rows.iter().enumerate() {
        let vals = as_f64_list(at, "transform", format_args!("row {r} entry"), row)?;
        if vals.len() != 4 {
            return Err(at.err(
                "transform",
                format!("row {r} has {} entries, expected 4", vals.len()),
            ));
        }
        m[r].copy_from_slice(&vals);
    }
    Ok(DMat4::from_cols_array_2d(&m).transpose())
}

impl From<EditError> for SceneError {
    fn from(e: EditError) -> Self {
        SceneError(e.to_string())
    }
}
