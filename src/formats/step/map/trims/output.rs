//! Laid-out pieces → [`CadPiece`]s in the NURBS surface's own parameters.
//!
//! Exact where the file's curve survives the parameter map unchanged:
//! - a straight segment along a parameter direction (a seam, a pole line, an isoparametric
//!   edge: a circle around a cylinder, a ruling) stays straight, because the map acts on each
//!   parameter separately: two points;
//! - where the map is the identity (planes, B-spline surfaces, extrusions of splines), a PCURVE
//!   is its own exact rational B-spline, and on a plane a 3D edge projects exactly (the plane's
//!   coordinates are affine in space, so the projected control points and the same weights
//!   give the same curve);
//!
//! and otherwise a polyline whose every point is inverted onto the surface (see `flatten` for
//! its tolerances).

use crate::geom::analytic::{AxisMap, Frame, ParamMap};
use glam::{DVec2, DVec3};

use super::super::curves::Curve;
use super::piece::{Ctx, Piece, Source};
use crate::formats::step::map::{CadCurve2, CadPiece};

/// How a surface's parameters relate to the file's.
pub(crate) struct Maps<'a> {
    pub map: &'a ParamMap,
    /// Crate parameters are the file's and the NURBS's (no angle factor, no arc map).
    pub identity: bool,
    /// The plane's frame, where the surface is a PLANE.
    pub plane: Option<Frame>,
    /// The NURBS surface, to measure the flattening error in space.
    pub surface: &'a crate::formats::step::map::nurbs::FastSurface,
    /// Flattening tolerances in space and in the parameter plane.
    pub tol3d: f64,
    pub tol_param: f64,
}

/// The output piece of `p`.
pub(crate) fn piece(ctx: &Ctx<'_>, p: &Piece<'_>, m: &Maps<'_>) -> Result<CadPiece, String> {
    let to = |uv: DVec2| DVec2::from(m.map.to_nurbs(uv.to_array()));
    let (a, b) = (to(p.start()), to(p.end()));
    let line = || CadPiece {
        curve: CadCurve2::Polyline(vec![a.to_array(), b.to_array()]),
        range: (0.0, 1.0),
    };
    if p.iso {
        return Ok(line());
    }
    if m.identity {
        let exact = match p.src {
            Source::Pcurve(c) => exact(c, p.t, p.shift, None),
            Source::Edge(c) => m.plane.and_then(|f| exact(c, p.t, p.shift, Some(f))),
            Source::Segment(..) => Some(line()),
        };
        if let Some(e) = exact {
            return Ok(e);
        }
    }
    let to_st = |uv: DVec2| DVec2::from(m.map.to_nurbs(uv.to_array()));
    let mut out = super::flatten::flatten(ctx, p, &to_st, m)?;
    super::flatten::blend_ends(&mut out, Some(a), Some(b));
    let n = out.len().saturating_sub(1) as f64;
    Ok(CadPiece {
        curve: CadCurve2::Polyline(out.into_iter().map(|q| q.to_array()).collect()),
        range: (0.0, n),
    })
}

/// The exact 2D form of curve `c` over `t` (traversal order), moved by `shift`; on a plane
/// (`plane` given) the 3D curve projected into the plane's coordinates.
#[must_use]
fn exact(c: &Curve, t: (f64, f64), shift: DVec2, plane: Option<Frame>) -> Option<CadPiece> {
    let (lo, hi) = (t.0.min(t.1), t.0.max(t.1));
    if hi <= lo {
        return None;
    }
    let (n, axis) = c.to_nurbs(lo, hi)?;
    let flat = |q: DVec3| match plane {
        Some(f) => {
            let l = f.to_local(q);
            DVec2::new(l.x, l.y) + shift
        }
        None => DVec2::new(q.x, q.y) + shift,
    };
    let points: Vec<[f64; 2]> = n.points.iter().map(|&q| flat(q).to_array()).collect();
    // The arc map of a conic equals the angle at the ends, so the range keeps its values.
    let (r0, r1) = match axis {
        AxisMap::Identity | AxisMap::Arc(_) => (t.0, t.1),
    };
    if n.degree == 1 && points.len() == 2 {
        let (p0, p1) = (points.first()?, points.get(1)?);
        let (s, e) = if t.0 <= t.1 { (*p0, *p1) } else { (*p1, *p0) };
        return Some(CadPiece {
            curve: CadCurve2::Polyline(vec![s, e]),
            range: (0.0, 1.0),
        });
    }
    let rational = n.weights.iter().any(|&w| w != 1.0);
    Some(CadPiece {
        curve: CadCurve2::Nurbs {
            degree: n.degree,
            knots: n.knots,
            points,
            weights: rational.then_some(n.weights),
        },
        range: (r0, r1),
    })
}

/// The first and last point of an output piece in traversal order.
#[must_use]
pub(crate) fn piece_ends(p: &CadPiece) -> Option<(DVec2, DVec2)> {
    let pts = match &p.curve {
        CadCurve2::Polyline(v) | CadCurve2::Nurbs { points: v, .. } => v,
    };
    let (f, l) = (DVec2::from(*pts.first()?), DVec2::from(*pts.last()?));
    Some(if p.range.0 <= p.range.1 {
        (f, l)
    } else {
        (l, f)
    })
}

/// Moves an output piece's start (`at_end = false`) or end point to `q`: the end control point
/// of a clamped NURBS, or a polyline's end with the shift spread along it.
pub(crate) fn move_end(p: &mut CadPiece, at_end: bool, q: DVec2) {
    let forward = p.range.0 <= p.range.1;
    let last = at_end == forward;
    match &mut p.curve {
        CadCurve2::Polyline(v) => {
            let mut pts: Vec<DVec2> = v.iter().map(|x| DVec2::from(*x)).collect();
            let (a, b) = if last {
                (None, Some(q))
            } else {
                (Some(q), None)
            };
            super::flatten::blend_ends(&mut pts, a, b);
            *v = pts.into_iter().map(|x| x.to_array()).collect();
        }
        CadCurve2::Nurbs { points, .. } => {
            let slot = if last {
                points.last_mut()
            } else {
                points.first_mut()
            };
            if let Some(s) = slot {
                *s = q.to_array();
            }
        }
    }
}

/// Control-point box of output pieces (contains the curves: convex hull property).
#[must_use]
pub(crate) fn hull(pieces: &[CadPiece]) -> (DVec2, DVec2) {
    let mut lo = DVec2::INFINITY;
    let mut hi = DVec2::NEG_INFINITY;
    for p in pieces {
        let pts = match &p.curve {
            CadCurve2::Polyline(v) | CadCurve2::Nurbs { points: v, .. } => v,
        };
        for q in pts {
            lo = lo.min(DVec2::from(*q));
            hi = hi.max(DVec2::from(*q));
        }
    }
    (lo, hi)
}
