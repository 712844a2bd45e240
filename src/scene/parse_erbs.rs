//! ERBS objects in scene files: explicit knots and locals (Bézier, B-spline or ERBS locals, to
//! any depth), or `from` a Bézier or B-spline source built by Hermite interpolation; open or
//! closed. Local ERBS entries may narrow their `domain` (what a refinement's exact restriction
//! writes).

use super::SceneError;
use super::json::*;
use super::parse::{
    bfunction, check_degree, geom, opt, spline_curve, spline_surface, usize_pair, with,
};
use crate::geom::erbs::{ErbsCurve, ErbsKnots, ErbsSurface, LocalCurve, LocalPatch};
use crate::model::SplineForm;
use crate::sampling::budget::check_build;
use serde_json::{Map, Value};

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
pub(super) fn erbs_curve(
    at: &At,
    obj: &Map<String, Value>,
    outer: &[&'static str],
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
        check_build(
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
            .map(|(l, v)| local_curve(at, &format!("local[{l}]"), v))
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
fn local_curve(at: &At, which: &str, v: &Value) -> Result<LocalCurve, SceneError> {
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
        )?))),
        other => Err(la.err(
            "type",
            format!("a local curve is a bezier_curve, bspline_curve or erbs_curve, not '{other}'"),
        )),
    }
}

/// An `erbs_surface` body.
pub(super) fn erbs_surface(
    at: &At,
    obj: &Map<String, Value>,
    outer: &[&'static str],
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
        check_build(
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
        local_patch(at, &format!("local{idx}"), v)
    })?;
    let mut knots = Vec::with_capacity(2);
    for (dir, name) in ["u", "v"].into_iter().enumerate() {
        let k = as_f64_list(at, "knots", format_args!("{name} knot"), &kv[dir])?;
        let k = if closed[dir] {
            ErbsKnots::closed(k, count[dir])
        } else {
            ErbsKnots::open(k, count[dir])
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
fn local_patch(at: &At, which: &str, v: &Value) -> Result<LocalPatch, SceneError> {
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
