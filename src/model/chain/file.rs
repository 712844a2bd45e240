//! Catmull–Rom and Bézier splines in scene and edit files (docs/scene-format.md).

use super::{BezierSplineEdit, BezierSplineModel, CatmullRomEdit, CatmullRomModel};
use crate::fields::json::*;
use crate::fields::write::{field, numbers, points};
use crate::geom::{BezierSpline, CatmullRom, JoinContinuity, Parametrization};
use crate::model::PointEdit;
use crate::model::file::*;
use serde_json::{Map, Value};

pub fn read_catmull_rom(
    at: &At,
    obj: &Map<String, Value>,
    common: &[&'static str],
) -> Result<CatmullRomModel, SceneError> {
    check_fields(
        at,
        obj,
        &with(common, &["points", "parametrization", "closed"]),
    )?;
    let points = as_points(at, "points", require(at, obj, "points")?)?;
    let parametrization = match opt(obj, "parametrization") {
        None => Parametrization::default(),
        Some(v) => {
            let name = as_str(at, "parametrization", v)?;
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
    let c = CatmullRom::new(points, parametrization, closed).map_err(|e| geom(at, e))?;
    CatmullRomModel::new(c, curve_samples(at, obj)?).map_err(|e| edit(at, e))
}

pub fn read_bezier_spline(
    at: &At,
    obj: &Map<String, Value>,
    common: &[&'static str],
) -> Result<BezierSplineModel, SceneError> {
    check_fields(
        at,
        obj,
        &with(common, &["degree", "knots", "points", "continuity"]),
    )?;
    let degree = as_usize(at, "degree", "degree", require(at, obj, "degree")?)?;
    check_degree(at, "degree", degree)?;
    let knots = as_f64_list(at, "knots", "knot", require(at, obj, "knots")?)?;
    let points = as_points(at, "points", require(at, obj, "points")?)?;
    let name = as_str(at, "continuity", require(at, obj, "continuity")?)?;
    let continuity = JoinContinuity::from_name(name).ok_or_else(|| {
        at.err(
            "continuity",
            format!("unknown continuity '{name}' (expected one of: C0, G1, C1, C2)"),
        )
    })?;
    let c = BezierSpline::new(degree, knots, points, continuity).map_err(|e| geom(at, e))?;
    BezierSplineModel::new(c, curve_samples(at, obj)?).map_err(|e| edit(at, e))
}

pub fn write_catmull_rom(m: &CatmullRomModel, s: &mut String) {
    let c = m.spline();
    field(s, "points", &points(c.points()));
    if c.parametrization() != Parametrization::Uniform {
        field(
            s,
            "parametrization",
            &format!("\"{}\"", c.parametrization().name()),
        );
    }
    if c.closed() {
        field(s, "closed", "true");
    }
}

pub fn write_bezier_spline(m: &BezierSplineModel, s: &mut String) {
    let c = m.spline();
    field(s, "degree", &c.degree().to_string());
    field(s, "knots", &numbers(c.knots()));
    field(s, "points", &points(c.points()));
    field(s, "continuity", &format!("\"{}\"", c.continuity().name()));
}

/// A chain keeps its segment structure: knots and elevation are refused with the way out.
fn no_refinement(at: &At, obj: &Map<String, Value>, ty: &str) -> Result<(), SceneError> {
    let field = if obj.contains_key("insert_knot") {
        "insert_knot"
    } else if obj.contains_key("elevate_degree") {
        "elevate_degree"
    } else {
        return Ok(());
    };
    Err(at.err(
        field,
        format!("a {ty} keeps its own segment structure; convert it first ({{\"object\": …, \"to_bspline\": true}}) to refine it"),
    ))
}

pub fn read_catmull_rom_edit(
    at: &At,
    obj: &Map<String, Value>,
) -> Result<CatmullRomEdit, SceneError> {
    no_refinement(at, obj, "catmull_rom")?;
    Ok(CatmullRomEdit::Point(point_edit(at, obj, |v| {
        index(at, "point", v)
    })?))
}

pub fn read_bezier_spline_edit(
    at: &At,
    obj: &Map<String, Value>,
) -> Result<BezierSplineEdit, SceneError> {
    no_refinement(at, obj, "bezier_spline")?;
    match point_edit(at, obj, |v| index(at, "point", v))? {
        PointEdit::Move { point, delta } => Ok(BezierSplineEdit::Move { point, delta }),
        _ => Err(at.err(
            "weight",
            "a bezier_spline has no weights (its segments are polynomial; convert it to a bspline_curve first)",
        )),
    }
}
