//! Bézier and B-spline curves and surfaces in scene and edit files (docs/scene-format.md).

use super::curve::{CurveEdit, CurveModel};
use super::surface::{SurfaceEdit, SurfaceModel};
use crate::fields::json::*;
use crate::fields::write::{field, numbers, points};
use crate::geom::{BSplineCurve, KnotVector, TensorSurface};
use crate::model::SplineForm;
use crate::model::file::*;
use serde_json::{Map, Value};

/// `bezier_curve` and `bspline_curve`.
pub const CURVE_TYPES: &[&str] = &["bezier_curve", "bspline_curve"];
/// `bezier_surface` and `bspline_surface`.
pub const SURFACE_TYPES: &[&str] = &["bezier_surface", "bspline_surface"];

pub fn read_curve(
    ty: &str,
    at: &At,
    obj: &Map<String, Value>,
    common: &[&'static str],
) -> Result<CurveModel, SceneError> {
    let (form, c) = spline_curve(at, obj, ty, common)?;
    CurveModel::new(form, c, curve_samples(at, obj)?).map_err(|e| edit(at, e))
}

pub fn read_surface(
    ty: &str,
    at: &At,
    obj: &Map<String, Value>,
    common: &[&'static str],
) -> Result<SurfaceModel, SceneError> {
    let (form, s) = spline_surface(at, obj, ty, common)?;
    SurfaceModel::new(form, s, surface_samples(at, obj)?).map_err(|e| edit(at, e))
}

/// The geometry of a `bezier_curve` or `bspline_curve` body (an object, an ERBS `from`
/// source, a local curve); `outer` lists the other fields the body may hold.
pub fn spline_curve(
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
pub fn spline_surface(
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

pub fn write_curve(m: &CurveModel, s: &mut String) {
    let c = m.curve();
    if m.form() == SplineForm::BSpline {
        field(s, "degree", &c.degree().to_string());
        field(s, "knots", &numbers(c.knots()));
    }
    field(s, "points", &points(c.points()));
    if let Some(w) = c.weights() {
        field(s, "weights", &numbers(w));
    }
}

pub fn write_surface(m: &SurfaceModel, s: &mut String) {
    let p = m.surface();
    if m.form() == SplineForm::BSpline {
        let [du, dv] = p.degree();
        field(s, "degree", &format!("[{du}, {dv}]"));
        let [ku, kv] = p.knots();
        field(s, "knots", &format!("[{}, {}]", numbers(ku), numbers(kv)));
    }
    field(s, "points", &point_grid_text(p));
    weights(s, p);
}

pub fn point_grid_text(p: &TensorSurface) -> String {
    let nv = p.count()[1];
    let rows: Vec<String> = p.points().chunks(nv).map(points).collect();
    format!("[{}]", rows.join(", "))
}

fn weights(s: &mut String, p: &TensorSurface) {
    if let Some(w) = p.weights() {
        let nv = p.count()[1];
        let rows: Vec<String> = w.chunks(nv).map(numbers).collect();
        field(s, "weights", &format!("[{}]", rows.join(", ")));
    }
}

/// A curve's edit: `insert_knot` (with optional `times`), `elevate_degree`, or a point edit.
pub fn read_curve_edit(at: &At, obj: &Map<String, Value>) -> Result<CurveEdit, SceneError> {
    if let Some(v) = obj.get("insert_knot") {
        let times = times(at, obj)?;
        let t = as_f64(at, "insert_knot", "parameter", v)?;
        return Ok(CurveEdit::InsertKnot { t, times });
    }
    if obj.contains_key("elevate_degree") {
        check_fields(at, obj, &["object", "elevate_degree"])?;
        let by = positive(at, "elevate_degree", require(at, obj, "elevate_degree")?)?;
        return Ok(CurveEdit::ElevateDegree { by });
    }
    Ok(CurveEdit::Point(point_edit(at, obj, |v| {
        index(at, "point", v)
    })?))
}

/// A surface's edit: `insert_knot` in one direction, `elevate_degree` per direction, or a
/// point edit.
pub fn read_surface_edit(at: &At, obj: &Map<String, Value>) -> Result<SurfaceEdit, SceneError> {
    if let Some(v) = obj.get("insert_knot") {
        let times = times(at, obj)?;
        let (dir, t) = direction_parameter(at, v)?;
        return Ok(SurfaceEdit::InsertKnot { dir, t, times });
    }
    if obj.contains_key("elevate_degree") {
        check_fields(at, obj, &["object", "elevate_degree"])?;
        let v = require(at, obj, "elevate_degree")?;
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
        return Ok(SurfaceEdit::ElevateDegree {
            by: [by("u")?, by("v")?],
        });
    }
    Ok(SurfaceEdit::Point(point_edit(at, obj, |v| {
        pair(at, "point", v)
    })?))
}

/// `insert_knot`'s optional `times` (1 when absent), the fields checked.
fn times(at: &At, obj: &Map<String, Value>) -> Result<usize, SceneError> {
    check_fields(at, obj, &["object", "insert_knot", "times"])?;
    match obj.get("times") {
        Some(t) => positive(at, "times", t),
        None => Ok(1),
    }
}
