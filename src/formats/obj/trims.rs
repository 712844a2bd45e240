//! OBJ `trim` and `hole` statements applied: each names `curv2` parameter-space curves with a
//! range, chained into one loop; a `trim` is an outer loop, a `hole` an inner one
//! (docs/obj.md, "Trimmed surfaces"). The statements stay kept as they were, so a save writes
//! them back unchanged; this builds the trim that is drawn and measured.

use super::kept::{Body, Curve2, CurveRef, ObjKept};
use super::model::{Basis, Direction};
use crate::geom::trim::{LoopSpec, Role, Trim, TrimCurve, TrimPiece, Trimmed};
use glam::DVec2;

/// The trim the kept body statements describe, `None` without `trim`/`hole`; an error names
/// the statement and curve.
pub fn trim_of(kept: &ObjKept) -> Result<Option<Trim>, String> {
    let mut loops = Vec::new();
    for (k, b) in kept.body.iter().enumerate() {
        let role = match b {
            Body::Trim(_) => Role::Outer,
            Body::Hole(_) => Role::Hole,
            Body::Scrv(_) | Body::Sp(_) => continue,
        };
        let at = |e: String| format!("{} statement {k}: {e}", b.keyword());
        let pieces = b
            .curves()
            .iter()
            .map(|r| {
                let c = kept
                    .curves2
                    .get(r.curve)
                    .ok_or_else(|| at(format!("curve {} does not exist", r.curve)))?;
                let curve = curve_of(kept, c).map_err(|e| at(format!("curv2 {}: {e}", r.curve)))?;
                let piece = TrimPiece {
                    curve,
                    range: (r.range[0], r.range[1]),
                };
                piece
                    .check()
                    .map_err(|e| at(format!("curv2 {}: {}", r.curve, e.message)))?;
                Ok(piece)
            })
            .collect::<Result<Vec<_>, String>>()?;
        loops.push(LoopSpec {
            pieces,
            role: Some(role),
        });
    }
    Ok((!loops.is_empty()).then_some(Trim { loops }))
}

/// A `curv2` as a parameter-space curve: its `vp` vertices (u, v, and the weight w of a
/// rational curve) over its `parm`, as `curv` maps to a B-spline (docs/obj.md).
fn curve_of(kept: &ObjKept, c: &Curve2) -> Result<TrimCurve, String> {
    let basis = match c.basis.as_str() {
        "bezier" => Basis::Bezier,
        "bspline" => Basis::BSpline,
        other => {
            return Err(format!(
                "a {other} curve cannot bound a trim (bezier or bspline)"
            ));
        }
    };
    let mut points = Vec::with_capacity(c.vertices.len());
    let mut weights = Vec::with_capacity(c.vertices.len());
    for &v in &c.vertices {
        let p = kept
            .parameter_vertices
            .get(v)
            .ok_or_else(|| format!("parameter vertex {v} does not exist"))?;
        let (u, w) = match p.as_slice() {
            [u, v, rest @ ..] => (DVec2::new(*u, *v), rest.first().copied().unwrap_or(1.0)),
            _ => return Err(format!("parameter vertex {v} has no v coordinate")),
        };
        points.push(u);
        weights.push(w);
    }
    let direction = Direction {
        degree: c.degree,
        range: [0.0, 0.0],
        parm: c.parm.clone(),
        count: points.len(),
        parm_line: 0,
    };
    let knots = match basis {
        Basis::Bezier if c.degree == 0 || c.parm.len() < 2 => {
            return Err("a Bézier curve needs a degree ≥ 1 and two breakpoints".into());
        }
        _ => direction.knots(basis),
    };
    // A straight, unweighted degree-1 curve over knots 0, 0, 1, …, n−1, n−1 is the polyline
    // these statements write (`kept_of`): read back as one, a JSON trim round-trips exactly.
    if c.degree == 1 && !c.rational && knots == polyline_knots(points.len()) {
        return TrimCurve::polyline(points).map_err(|e| e.message);
    }
    let weights = c.rational.then_some(weights);
    TrimCurve::bspline(c.degree, knots, &points, weights).map_err(|e| e.message)
}

/// Knots 0, 0, 1, …, n−2, n−1, n−1: a degree-1 B-spline through n points with point k at
/// parameter k, as a trim polyline is parametrised.
fn polyline_knots(n: usize) -> Vec<f64> {
    let mut k = vec![0.0];
    k.extend((0..n).map(|i| i as f64));
    k.push(n.saturating_sub(1) as f64);
    k
}

/// The `vp`, `curv2` and `trim`/`hole` statements of a trim that came from anywhere but an OBJ
/// file (a JSON scene, a CAD file), for writing it: polylines as degree-1 B-splines with point
/// k at parameter k, splines as themselves (rational where weighted); an outer loop is a
/// `trim`, a hole a `hole` (loops left to nesting take the role nesting gave them).
#[must_use]
pub fn kept_of(trimmed: &Trimmed) -> ObjKept {
    let mut kept = ObjKept::default();
    let built = trimmed.regions().loops();
    for (k, l) in trimmed.spec().loops.iter().enumerate() {
        let role = l.role.or_else(|| built.get(k).map(|b| b.role()));
        let mut refs = Vec::with_capacity(l.pieces.len());
        for p in &l.pieces {
            refs.push(CurveRef {
                range: [p.range.0, p.range.1],
                curve: kept.curves2.len(),
            });
            let curve = curve2_of(&p.curve, kept.parameter_vertices.len());
            for (q, w) in curve.1 {
                let mut vp = vec![q.x, q.y];
                if let Some(w) = w {
                    vp.push(w);
                }
                kept.parameter_vertices.push(vp);
            }
            kept.curves2.push(curve.0);
        }
        kept.body.push(match role {
            Some(Role::Hole) => Body::Hole(refs),
            _ => Body::Trim(refs),
        });
    }
    kept
}

/// A `vp` of a written `curv2`: its (u, v) and, where rational, its weight.
type Vertex = (DVec2, Option<f64>);

/// A trim curve as a `curv2` whose vertices start at parameter vertex `first`, with those
/// vertices (and their weights where rational).
fn curve2_of(c: &TrimCurve, first: usize) -> (Curve2, Vec<Vertex>) {
    let (degree, parm, vertices): (usize, Vec<f64>, Vec<Vertex>) = match c {
        TrimCurve::Polyline(p) => (
            1,
            polyline_knots(p.len()),
            p.iter().map(|&q| (q, None)).collect(),
        ),
        TrimCurve::Spline(s) => {
            let w = s.weights();
            let v = s
                .points()
                .iter()
                .enumerate()
                .map(|(i, q)| (q.truncate(), w.and_then(|w| w.get(i).copied())))
                .collect();
            (s.degree(), s.knots().to_vec(), v)
        }
    };
    let rational = vertices.iter().any(|v| v.1.is_some());
    let curve = Curve2 {
        rational,
        basis: "bspline".into(),
        degree,
        vertices: (first..first + vertices.len()).collect(),
        parm,
        body: Vec::new(),
        technique: None,
    };
    (curve, vertices)
}
