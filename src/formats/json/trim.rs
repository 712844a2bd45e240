//! The `trim` field of a surface (docs/scene-format.md, "Trims"): loops of parameter-space
//! curves, read with one-line errors naming the loop and curve, written so they read back bit
//! for bit.

use crate::fields::json::{At, as_array, as_f64_list, as_object, as_usize, kind};
use crate::fields::write::number;
use crate::geom::trim::{LoopSpec, Role, Trim, TrimCurve, TrimPiece};
use crate::scene::SceneError;
use glam::DVec2;
use serde_json::{Map, Value};

const FIELD: &str = "trim";

/// The loop keys: a declared outer boundary, a declared hole, or a loop classified by nesting.
const LOOP_KEYS: [&str; 3] = ["outer", "hole", "loop"];
/// The curve keys.
const CURVE_KEYS: [&str; 4] = ["line", "polyline", "bezier", "bspline"];

/// Reads a `trim` value: `[{"outer" | "hole" | "loop": [curve, …]}, …]`.
pub fn read_trim(at: &At, v: &Value) -> Result<Trim, SceneError> {
    let items = as_array(at, FIELD, v)?;
    if items.is_empty() {
        return Err(at.err(
            FIELD,
            "no loops (leave the field out for an untrimmed surface)",
        ));
    }
    let loops = items
        .iter()
        .enumerate()
        .map(|(k, item)| read_loop(at, k, item))
        .collect::<Result<_, _>>()?;
    Ok(Trim { loops })
}

fn read_loop(at: &At, k: usize, v: &Value) -> Result<LoopSpec, SceneError> {
    let bad = || {
        at.err(
            FIELD,
            format!(
                "loop {k}: expected {{\"outer\" | \"hole\" | \"loop\": [curve, ...]}}, found {}",
                kind(v)
            ),
        )
    };
    let obj = v.as_object().ok_or_else(bad)?;
    let (key, curves) = match obj.iter().next() {
        Some((key, curves)) if obj.len() == 1 && LOOP_KEYS.contains(&key.as_str()) => {
            (key.as_str(), curves)
        }
        _ => return Err(bad()),
    };
    let role = match key {
        "outer" => Some(Role::Outer),
        "hole" => Some(Role::Hole),
        _ => None,
    };
    let curves = as_array(at, FIELD, curves)?;
    if curves.is_empty() {
        return Err(at.err(FIELD, format!("loop {k}: no curves")));
    }
    let pieces = curves
        .iter()
        .enumerate()
        .map(|(c, v)| read_piece(at, &format!("loop {k}, curve {c}"), v))
        .collect::<Result<_, _>>()?;
    Ok(LoopSpec { pieces, role })
}

/// One curve: `{"line": [p, q]}`, `{"polyline": [p, …]}`, `{"bezier": [p, …], "weights"?}`,
/// `{"bspline": [p, …], "degree", "knots", "weights"?}`, each with an optional `"range":
/// [t0, t1]` (reversed runs it backwards).
fn read_piece(at: &At, what: &str, v: &Value) -> Result<TrimPiece, SceneError> {
    let obj = as_object(at, FIELD, v).map_err(|_| {
        at.err(
            FIELD,
            format!("{what}: expected a curve object, found {}", kind(v)),
        )
    })?;
    let key = CURVE_KEYS
        .into_iter()
        .find(|k| obj.contains_key(*k))
        .ok_or_else(|| {
            at.err(
                FIELD,
                format!("{what}: expected one of {}", CURVE_KEYS.join(", ")),
            )
        })?;
    let allowed: &[&str] = match key {
        "line" | "polyline" => &["range"],
        "bezier" => &["weights", "range"],
        _ => &["degree", "knots", "weights", "range"],
    };
    if let Some(other) = obj
        .keys()
        .find(|k| *k != key && !allowed.contains(&k.as_str()))
    {
        return Err(at.err(
            FIELD,
            format!(
                "{what}: unknown field '{other}' for a {key} (expected: {})",
                allowed.join(", ")
            ),
        ));
    }
    let points = read_points(at, what, &obj[key])?;
    let geom = |e: crate::geom::GeomError| at.err(FIELD, format!("{what}: {e}"));
    let curve = match key {
        "line" if points.len() != 2 => {
            return Err(at.err(
                FIELD,
                format!("{what}: a line has 2 points, found {}", points.len()),
            ));
        }
        "line" | "polyline" => TrimCurve::polyline(points).map_err(geom)?,
        "bezier" => TrimCurve::bezier(&points, weights(at, what, obj)?).map_err(geom)?,
        _ => {
            let need = |f: &str| {
                obj.get(f)
                    .ok_or_else(|| at.err(FIELD, format!("{what}: a bspline needs '{f}'")))
            };
            let degree = as_usize(at, FIELD, format_args!("{what} degree"), need("degree")?)?;
            let knots = as_f64_list(at, FIELD, format_args!("{what} knot"), need("knots")?)?;
            TrimCurve::bspline(degree, knots, &points, weights(at, what, obj)?).map_err(geom)?
        }
    };
    let piece = match obj.get("range") {
        None => TrimPiece::whole(curve),
        Some(r) => {
            let ends = as_f64_list(at, FIELD, format_args!("{what} range"), r)?;
            let [a, b] = ends[..] else {
                return Err(at.err(FIELD, format!("{what}: range is [t0, t1]")));
            };
            TrimPiece {
                curve,
                range: (a, b),
            }
        }
    };
    piece.check().map_err(geom)?;
    Ok(piece)
}

fn read_points(at: &At, what: &str, v: &Value) -> Result<Vec<DVec2>, SceneError> {
    as_array(at, FIELD, v)?
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let c = as_f64_list(at, FIELD, format_args!("{what} point {i}"), p)?;
            match c[..] {
                [u, v] => Ok(DVec2::new(u, v)),
                _ => Err(at.err(
                    FIELD,
                    format!(
                        "{what} point {i}: expected [u, v], found {} numbers",
                        c.len()
                    ),
                )),
            }
        })
        .collect()
}

fn weights(at: &At, what: &str, obj: &Map<String, Value>) -> Result<Option<Vec<f64>>, SceneError> {
    obj.get("weights")
        .map(|w| as_f64_list(at, FIELD, format_args!("{what} weight"), w))
        .transpose()
}

/// The `trim` value of a trim.
#[must_use]
pub fn trim_json(t: &Trim) -> String {
    let loops: Vec<String> = t
        .loops
        .iter()
        .map(|l| {
            let key = match l.role {
                Some(Role::Outer) => "outer",
                Some(Role::Hole) => "hole",
                None => "loop",
            };
            let curves: Vec<String> = l.pieces.iter().map(piece_json).collect();
            format!("{{\"{key}\": [{}]}}", curves.join(", "))
        })
        .collect();
    format!("[{}]", loops.join(", "))
}

fn piece_json(p: &TrimPiece) -> String {
    let pts = |v: &[DVec2]| {
        let items: Vec<String> = v
            .iter()
            .map(|q| format!("[{}, {}]", number(q.x), number(q.y)))
            .collect();
        format!("[{}]", items.join(", "))
    };
    let list = |v: &[f64]| {
        let items: Vec<String> = v.iter().map(|&x| number(x)).collect();
        format!("[{}]", items.join(", "))
    };
    let mut s = match &p.curve {
        TrimCurve::Polyline(v) if v.len() == 2 => format!("{{\"line\": {}", pts(v)),
        TrimCurve::Polyline(v) => format!("{{\"polyline\": {}", pts(v)),
        TrimCurve::Spline(c) => {
            let mut s = format!(
                "{{\"bspline\": {}, \"degree\": {}, \"knots\": {}",
                pts(&p.curve.points()),
                c.degree(),
                list(c.knots())
            );
            if let Some(w) = c.weights() {
                s.push_str(&format!(", \"weights\": {}", list(w)));
            }
            s
        }
    };
    if p.range != p.curve.domain() {
        s.push_str(&format!(
            ", \"range\": [{}, {}]",
            number(p.range.0),
            number(p.range.1)
        ));
    }
    s.push('}');
    s
}
