//! ERBS objects in scene files: explicit knots and locals (Bézier, B-spline or ERBS locals, to
//! any depth), or `from` a Bézier or B-spline source built by Hermite interpolation; open or
//! closed. Local ERBS entries may narrow their `domain` (what a refinement's exact restriction
//! writes).

use super::{
    ErbsCurveEdit, ErbsCurveModel, ErbsSurfaceEdit, ErbsSurfaceModel, LocalEdit, LocalPath,
};
use crate::fields::ReadCtx;
use crate::fields::json::*;
use crate::fields::write::{field, numbers, points};
use crate::geom::BFunctionKind;
use crate::geom::erbs::{ErbsCurve, ErbsKnots, ErbsSurface, LocalCurve, LocalPatch};
use crate::model::SplineForm;
use crate::model::file::{
    bfunction, check_degree, curve_samples, direction_parameter, edit, geom, index, opt, pair,
    surface_samples, usize_pair, with,
};
use crate::model::spline::file::{point_grid_text, spline_curve, spline_surface};
use crate::sampling::budget::MemoryBudget;
use glam::DMat4;
use serde_json::{Map, Value};
use std::fmt::Write;

/// Fields an ERBS body holds besides the object's (or the local entry's) own.
const CURVE_FIELDS: [&str; 4] = ["knots", "local", "closed", "bfunction"];
const FROM_FIELDS: [&str; 5] = [
    "from",
    "local_curves",
    "local_degree",
    "closed",
    "bfunction",
];
const SURFACE_FROM_FIELDS: [&str; 5] = [
    "from",
    "local_patches",
    "local_degree",
    "closed",
    "bfunction",
];
/// Fields of a local entry besides its geometry.
const LOCAL_FIELDS: [&str; 1] = ["type"];
const NESTED_FIELDS: [&str; 2] = ["type", "domain"];

/// An `erbs_curve` body; `outer` lists the other fields it may hold.
pub fn erbs_curve(
    at: &At,
    obj: &Map<String, Value>,
    outer: &[&'static str],
    budget: &MemoryBudget,
) -> Result<ErbsCurve, SceneError> {
    let bf = bfunction(at, obj)?;
    let closed = flag(at, obj, "closed")?;
    let c = if let Some(src) = obj.get("from") {
        only_from(at, obj)?;
        check_fields(at, obj, &with(outer, &FROM_FIELDS))?;
        let source = source_body(at, src, &["bezier_curve", "bspline_curve"])?;
        let (_, c) = spline_curve(&source.0, source.1, source.2, &LOCAL_FIELDS)?;
        let n = as_usize(
            at,
            "local_curves",
            "count",
            require(at, obj, "local_curves")?,
        )?;
        let d = as_usize(
            at,
            "local_degree",
            "degree",
            require(at, obj, "local_degree")?,
        )?;
        check_degree(at, "local_degree", d)?;
        check_count(at, "local_curves", "", n)?;
        budget
            .check_build(
                format_args!("{n} local curves of degree {d}"),
                ErbsCurve::from_curve_bytes(n, d),
            )
            .map_err(|e| at.err("local_curves", e))?;
        ErbsCurve::from_curve(&c, n, d, bf, closed).map_err(|e| geom(at, e))?
    } else {
        check_fields(at, obj, &with(outer, &CURVE_FIELDS))?;
        let knots = as_f64_list(at, "knots", "knot", require(at, obj, "knots")?)?;
        let local = as_array(at, "local", require(at, obj, "local")?)?;
        let locals = local
            .iter()
            .enumerate()
            .map(|(l, v)| local_curve(at, &format!("local[{l}]"), v, budget))
            .collect::<Result<Vec<_>, _>>()?;
        let n = locals.len();
        let knots = if closed {
            ErbsKnots::closed(knots, n)
        } else {
            ErbsKnots::open(knots, n)
        }
        .map_err(|e| geom(at, e))?;
        let knots = match opt(obj, "domain") {
            Some(d) => {
                let d = as_f64_list(at, "domain", "end", d)?;
                let [a, b] = d[..] else {
                    return Err(at.err(
                        "domain",
                        format!("expected [a, b], found {} values", d.len()),
                    ));
                };
                knots.with_domain((a, b)).map_err(|e| geom(at, e))?
            }
            None => knots,
        };
        ErbsCurve::with_locals(knots, locals, bf).map_err(|e| geom(at, e))?
    };
    Ok(c)
}

/// A `local` entry's object, where errors inside it are reported, and its `type` (`untyped`
/// when absent: the original form, a Bézier body).
fn typed_local<'v>(
    at: &At,
    which: &str,
    v: &'v Value,
    untyped: &'static str,
) -> Result<(At, &'v Map<String, Value>, &'v str), SceneError> {
    let la = At(format!("{}: {which}", at.0));
    let obj = as_object(at, "local", v).map_err(|_| {
        at.err(
            "local",
            format!(
                "{which}: expected {{\"points\": [...]}} or a typed local, found {}",
                kind(v)
            ),
        )
    })?;
    let ty = match obj.get("type") {
        None => untyped,
        Some(t) => as_str(&la, "type", t)?,
    };
    Ok((la, obj, ty))
}

/// One `local` entry of an ERBS curve: `{"points": …}` (a Bézier curve, the original form), or
/// a typed body: `bezier_curve`, `bspline_curve` (polynomial), or `erbs_curve`.
fn local_curve(
    at: &At,
    which: &str,
    v: &Value,
    budget: &MemoryBudget,
) -> Result<LocalCurve, SceneError> {
    let (la, obj, ty) = typed_local(at, which, v, "bezier_curve")?;
    match ty {
        "bezier_curve" | "bspline_curve" => {
            let (form, c) = spline_curve(&la, obj, ty, &LOCAL_FIELDS)?;
            if c.is_rational() {
                return Err(la.err(
                    "weights",
                    "rational local curves are not supported: local curves must be polynomial",
                ));
            }
            Ok(LocalCurve::Spline {
                curve: c,
                bezier: form == SplineForm::Bezier,
            })
        }
        "erbs_curve" => Ok(LocalCurve::Erbs(Box::new(erbs_curve(
            &la,
            obj,
            &NESTED_FIELDS,
            budget,
        )?))),
        other => Err(la.err(
            "type",
            format!("a local curve is a bezier_curve, bspline_curve or erbs_curve, not '{other}'"),
        )),
    }
}

/// An `erbs_surface` body.
pub fn erbs_surface(
    at: &At,
    obj: &Map<String, Value>,
    outer: &[&'static str],
    budget: &MemoryBudget,
) -> Result<ErbsSurface, SceneError> {
    let bf = bfunction(at, obj)?;
    let closed = match opt(obj, "closed") {
        None => [false, false],
        Some(v) => match v
            .as_array()
            .map(|a| a.iter().map(Value::as_bool).collect::<Vec<_>>())
        {
            Some(b) if b.len() == 2 && b.iter().all(Option::is_some) => {
                [b[0].unwrap_or(false), b[1].unwrap_or(false)]
            }
            _ => return Err(at.err("closed", format!("expected [u, v] booleans, found {v}"))),
        },
    };
    if let Some(src) = obj.get("from") {
        only_from(at, obj)?;
        check_fields(at, obj, &with(outer, &SURFACE_FROM_FIELDS))?;
        let source = source_body(at, src, &["bezier_surface", "bspline_surface"])?;
        let (_, s) = spline_surface(&source.0, source.1, source.2, &LOCAL_FIELDS)?;
        let count = usize_pair(
            at,
            "local_patches",
            "[nu, nv]",
            require(at, obj, "local_patches")?,
        )?;
        let degree = usize_pair(
            at,
            "local_degree",
            "[du, dv]",
            require(at, obj, "local_degree")?,
        )?;
        check_degree(at, "local_degree", degree[0].max(degree[1]))?;
        check_count(at, "local_patches", "u direction: ", count[0])?;
        check_count(at, "local_patches", "v direction: ", count[1])?;
        budget
            .check_build(
                format_args!(
                    "{}×{} local patches of degree [{}, {}]",
                    count[0], count[1], degree[0], degree[1]
                ),
                ErbsSurface::from_surface_bytes(count, degree),
            )
            .map_err(|e| at.err("local_patches", e))?;
        return ErbsSurface::from_surface(&s, count, degree, bf, closed).map_err(|e| geom(at, e));
    }
    check_fields(at, obj, &with(outer, &CURVE_FIELDS))?;
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
    let (count, patches) = as_grid(at, "local", require(at, obj, "local")?, |idx, v| {
        local_patch(at, &format!("local{idx}"), v, budget)
    })?;
    let mut knots = Vec::with_capacity(2);
    for (dir, name) in ["u", "v"].into_iter().enumerate() {
        let k = as_f64_list(at, "knots", format_args!("{name} knot"), &kv[dir])?;
        let k = if closed[dir] {
            ErbsKnots::closed_patches(k, count[dir])
        } else {
            ErbsKnots::open_patches(k, count[dir])
        }
        .map_err(|mut e| {
            e.message = format!("{name} direction: {}", e.message);
            geom(at, e)
        })?;
        knots.push(k);
    }
    if let Some(d) = opt(obj, "domain") {
        let bad = || {
            at.err(
                "domain",
                format!("expected [[u0, u1], [v0, v1]], found {d}"),
            )
        };
        let rows = d.as_array().filter(|r| r.len() == 2).ok_or_else(bad)?;
        for (dir, r) in rows.iter().enumerate() {
            let ends = as_f64_list(at, "domain", "end", r)?;
            let [a, b] = ends[..] else { return Err(bad()) };
            knots[dir] = knots[dir]
                .clone()
                .with_domain((a, b))
                .map_err(|e| geom(at, e))?;
        }
    }
    let knots: [ErbsKnots; 2] = knots.try_into().expect("two directions");
    ErbsSurface::with_locals(knots, patches, bf).map_err(|e| geom(at, e))
}

/// One `local` entry of an ERBS surface: `{"points": [a][b][3]}` (a Bézier patch), or a typed
/// body: `bezier_surface`, `bspline_surface` (polynomial), or `erbs_surface`.
fn local_patch(
    at: &At,
    which: &str,
    v: &Value,
    budget: &MemoryBudget,
) -> Result<LocalPatch, SceneError> {
    let (la, obj, ty) = typed_local(at, which, v, "bezier_surface")?;
    match ty {
        "bezier_surface" | "bspline_surface" => {
            let (form, s) = spline_surface(&la, obj, ty, &LOCAL_FIELDS)?;
            if s.is_rational() {
                return Err(la.err(
                    "weights",
                    "rational local patches are not supported: local patches must be polynomial",
                ));
            }
            Ok(LocalPatch::Spline {
                surface: s,
                bezier: form == SplineForm::Bezier,
            })
        }
        "erbs_surface" => Ok(LocalPatch::Erbs(Box::new(erbs_surface(
            &la,
            obj,
            &NESTED_FIELDS,
            budget,
        )?))),
        other => Err(la.err(
            "type",
            format!(
                "a local patch is a bezier_surface, bspline_surface or erbs_surface, not '{other}'"
            ),
        )),
    }
}

/// A `from` construction's local count, named by its own field.
fn check_count(at: &At, field: &str, dir: &str, n: usize) -> Result<(), SceneError> {
    if n < 2 {
        return Err(at.err(
            field,
            format!("{dir}an ERBS needs at least 2 locals per direction, got {n}"),
        ));
    }
    Ok(())
}

/// `from` and explicit knots, locals or a narrowed domain exclude each other (a local built
/// `from` a source covers its whole support).
fn only_from(at: &At, obj: &Map<String, Value>) -> Result<(), SceneError> {
    for f in ["knots", "local", "domain"] {
        if obj.contains_key(f) {
            return Err(at.err(
                "from",
                format!("`from` builds the knots and locals: give `from` or `knots`/`local`/`domain`, not both (found '{f}')"),
            ));
        }
    }
    Ok(())
}

/// The `from` source: its position for messages, its fields and its type.
fn source_body<'a>(
    at: &At,
    v: &'a Value,
    types: &[&str],
) -> Result<(At, &'a Map<String, Value>, &'a str), SceneError> {
    let src = as_object(at, "from", v)?;
    let sa = At(format!("{}: from", at.0));
    let ty = as_str(&sa, "type", require(&sa, src, "type")?)?;
    if !types.contains(&ty) {
        return Err(sa.err(
            "type",
            format!(
                "an ERBS is built from a {}, not a '{ty}'",
                types.join(" or ")
            ),
        ));
    }
    Ok((sa, src, ty))
}

fn flag(at: &At, obj: &Map<String, Value>, field: &str) -> Result<bool, SceneError> {
    match obj.get(field) {
        None => Ok(false),
        Some(v) => v
            .as_bool()
            .ok_or_else(|| at.err(field, format!("expected true or false, found {v}"))),
    }
}

/// The explicit form of an ERBS curve's fields: knots, `closed`, locals (typed where not the
/// original Bézier form), a narrowed `domain` of a local ERBS, the B-function.
pub fn write_erbs_curve(s: &mut String, c: &ErbsCurve) {
    let k = c.knots();
    field(s, "knots", &numbers(k.as_slice()));
    if k.is_closed() {
        field(s, "closed", "true");
    }
    if k.domain() != k.full_domain() {
        let (a, b) = k.domain();
        field(s, "domain", &numbers(&[a, b]));
    }
    let local: Vec<String> = c.local_curves().iter().map(write_local_curve).collect();
    field(s, "local", &format!("[{}]", local.join(", ")));
    write_bfunction(s, c.bfunction());
}

fn write_local_curve(l: &LocalCurve) -> String {
    let mut s = String::from("{");
    match l {
        LocalCurve::Spline {
            curve,
            bezier: true,
        } => {
            let _ = write!(s, "\"points\": {}", points(curve.points()));
        }
        LocalCurve::Spline { curve, .. } => {
            let _ = write!(
                s,
                "\"type\": \"bspline_curve\", \"degree\": {}, \"knots\": {}, \"points\": {}",
                curve.degree(),
                numbers(curve.knots()),
                points(curve.points())
            );
        }
        LocalCurve::Erbs(e) => {
            s.push_str("\"type\": \"erbs_curve\"");
            write_erbs_curve(&mut s, e);
        }
    }
    s.push('}');
    s
}

pub fn write_erbs_surface(s: &mut String, e: &ErbsSurface) {
    let [ku, kv] = e.knots();
    field(
        s,
        "knots",
        &format!("[{}, {}]", numbers(ku.as_slice()), numbers(kv.as_slice())),
    );
    if e.closed() != [false, false] {
        let [a, b] = e.closed();
        field(s, "closed", &format!("[{a}, {b}]"));
    }
    if ku.domain() != ku.full_domain() || kv.domain() != kv.full_domain() {
        let [(u0, u1), (v0, v1)] = e.domain();
        field(
            s,
            "domain",
            &format!("[{}, {}]", numbers(&[u0, u1]), numbers(&[v0, v1])),
        );
    }
    let [nu, nv] = e.count();
    let rows: Vec<String> = (0..nu)
        .map(|k| {
            let row: Vec<String> = (0..nv)
                .map(|l| write_local_patch(e.local_patch(k, l)))
                .collect();
            format!("[{}]", row.join(", "))
        })
        .collect();
    field(s, "local", &format!("[{}]", rows.join(", ")));
    write_bfunction(s, e.bfunction());
}

fn write_local_patch(p: &LocalPatch) -> String {
    let mut s = String::from("{");
    match p {
        LocalPatch::Spline {
            surface,
            bezier: true,
        } => {
            let _ = write!(s, "\"points\": {}", point_grid_text(surface));
        }
        LocalPatch::Spline { surface, .. } => {
            let [du, dv] = surface.degree();
            let [ku, kv] = surface.knots();
            let _ = write!(
                s,
                "\"type\": \"bspline_surface\", \"degree\": [{du}, {dv}], \"knots\": [{}, {}], \"points\": {}",
                numbers(ku),
                numbers(kv),
                point_grid_text(surface)
            );
        }
        LocalPatch::Erbs(e) => {
            s.push_str("\"type\": \"erbs_surface\"");
            write_erbs_surface(&mut s, e);
        }
    }
    s.push('}');
    s
}

fn write_bfunction(s: &mut String, b: BFunctionKind) {
    if b != BFunctionKind::default() {
        field(s, "bfunction", &format!("\"{}\"", b.name()));
    }
}

/// Degree elevation is refused: ERBS objects refine by knot insertion.
fn refuse_elevation(at: &At, obj: &Map<String, Value>) -> Result<(), SceneError> {
    if obj.contains_key("elevate_degree") {
        return Err(at.err(
            "elevate_degree",
            "ERBS objects are refined by inserting knots (insert_knot), not by degree elevation",
        ));
    }
    Ok(())
}

/// The `to_erbs` specification, its fields checked, with where errors inside it are reported.
fn to_erbs_spec<'v>(
    at: &At,
    v: &'v Value,
    count_field: &str,
) -> Result<(&'v Map<String, Value>, At), SceneError> {
    let spec = as_object(at, "to_erbs", v)?;
    let inner = At(format!("{}: field 'to_erbs'", at.0));
    check_fields(&inner, spec, &[count_field, "local_degree"])?;
    Ok((spec, inner))
}

/// An ERBS curve's edit: a local edit (`local` with `transform`, or `point` and `delta`), a refinement
/// (`insert_knot`, optionally of the ERBS local at `local`, with an optional `degree`), or a
/// local turned into an ERBS local of its own (`local` with `to_erbs`).
pub fn read_curve_edit(at: &At, obj: &Map<String, Value>) -> Result<ErbsCurveEdit, SceneError> {
    refuse_elevation(at, obj)?;
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
        });
    }
    if let Some(v) = obj.get("to_erbs") {
        check_fields(at, obj, &["object", "local", "to_erbs"])?;
        let local = path(require(at, obj, "local")?)?;
        let (spec, inner) = to_erbs_spec(at, v, "local_curves")?;
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
        });
    }
    Ok(ErbsCurveEdit::Local(local_edit(at, obj, path, point)?))
}

/// An ERBS surface's edit, likewise (paths and points are index pairs, knots are inserted in
/// one direction).
pub fn read_surface_edit(at: &At, obj: &Map<String, Value>) -> Result<ErbsSurfaceEdit, SceneError> {
    refuse_elevation(at, obj)?;
    let path = |v: &Value| surface_path(at, v);
    let point = |v: &Value| pair(at, "point", v);
    if let Some(v) = obj.get("insert_knot") {
        check_fields(at, obj, &["object", "local", "insert_knot", "degree"])?;
        let local = obj.get("local").map(path).transpose()?;
        let at_knot = direction_parameter(at, v)?;
        let degree = obj
            .get("degree")
            .map(|d| usize_pair(at, "degree", "[du, dv]", d))
            .transpose()?;
        return Ok(ErbsSurfaceEdit::InsertKnot {
            local,
            at: at_knot,
            degree,
        });
    }
    if let Some(v) = obj.get("to_erbs") {
        check_fields(at, obj, &["object", "local", "to_erbs"])?;
        let local = path(require(at, obj, "local")?)?;
        let (spec, inner) = to_erbs_spec(at, v, "local_patches")?;
        let count = usize_pair(
            at,
            "to_erbs",
            "[nu, nv]",
            require(&inner, spec, "local_patches")?,
        )?;
        let degree = usize_pair(
            at,
            "to_erbs",
            "[du, dv]",
            require(&inner, spec, "local_degree")?,
        )?;
        return Ok(ErbsSurfaceEdit::ToErbs {
            local,
            count,
            degree,
        });
    }
    Ok(ErbsSurfaceEdit::Local(local_edit(at, obj, path, point)?))
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

/// Reads an `erbs_curve` object.
pub fn read_curve(
    at: &At,
    obj: &Map<String, Value>,
    ctx: &ReadCtx<'_>,
) -> Result<ErbsCurveModel, SceneError> {
    let c = erbs_curve(at, obj, ctx.common, &ctx.budget)?;
    ErbsCurveModel::new(c, curve_samples(at, obj)?).map_err(|e| edit(at, e))
}

/// Reads an `erbs_surface` object.
pub fn read_surface(
    at: &At,
    obj: &Map<String, Value>,
    ctx: &ReadCtx<'_>,
) -> Result<ErbsSurfaceModel, SceneError> {
    let s = erbs_surface(at, obj, ctx.common, &ctx.budget)?;
    ErbsSurfaceModel::new(s, surface_samples(at, obj)?).map_err(|e| edit(at, e))
}
