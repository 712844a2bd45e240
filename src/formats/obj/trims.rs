//! OBJ `trim` and `hole` statements applied: each names `curv2` parameter-space curves with a
//! range, chained into one loop; a `trim` is an outer loop, a `hole` an inner one
//! (docs/obj.md, "Trimmed surfaces"). The statements stay kept as they were, so a save writes
//! them back unchanged; this builds the trim that is drawn and measured.

use super::kept::{Body, Curve2, ObjKept};
use super::model::{Basis, Direction};
use crate::geom::trim::{LoopSpec, Role, Trim, TrimCurve, TrimPiece};
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
        other => return Err(format!("a {other} curve cannot bound a trim (bezier or bspline)")),
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
    let weights = c.rational.then_some(weights);
    TrimCurve::bspline(c.degree, knots, &points, weights).map_err(|e| e.message)
}
