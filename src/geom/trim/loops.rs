//! Raw trim loops → closed polygons: chaining the pieces, closing gaps, clamping to the domain.
//!
//! Real CAD files are inconsistent, so the rules are lenient where the meaning is clear and strict
//! where it is not: pieces whose ends meet within the gap tolerance are joined by snapping (the
//! next piece's first point is dropped), a piece that meets the chain with its far end is
//! reversed, points slightly outside the domain are clamped in. A gap, a loop leaving the domain
//! or a loop without area is an error naming the loop, the curves and the point.

use glam::DVec2;

use super::curve::{Piece, flatten_piece};
use super::error::TrimError;

/// What a loop bounds, as declared by the file (OBJ `trim` / `hole`) or found by nesting.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// The outer boundary of a region (nesting depth 0, 2, 4, …): counter-clockwise once built.
    Outer,
    /// A hole in a region (nesting depth 1, 3, …): clockwise once built.
    Hole,
}

/// One trim loop as read: its pieces, each already a polyline, in loop order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LoopInput {
    /// The pieces' polylines; either direction per piece, see the module doc.
    pub pieces: Vec<Vec<DVec2>>,
    /// The declared role, or `None` to classify by nesting alone.
    pub role: Option<Role>,
}

impl LoopInput {
    /// Flattens `pieces` to within `tol` (see [`super::curve::flatten`]); `loop_index` only names
    /// the loop in an error.
    pub fn from_pieces(
        loop_index: usize,
        pieces: &[Piece<'_>],
        role: Option<Role>,
        tol: f64,
    ) -> Result<Self, TrimError> {
        let mut out = Vec::with_capacity(pieces.len());
        for (piece, p) in pieces.iter().enumerate() {
            let mut points = Vec::new();
            flatten_piece(p, tol, &mut points).map_err(|e| TrimError::InCurve {
                loop_index,
                piece,
                source: Box::new(e),
            })?;
            out.push(points);
        }
        Ok(Self { pieces: out, role })
    }
}

/// Tolerances of loop assembly, as fractions of the parameter domain's diagonal so that they mean
/// the same in a unit square and in a face parametrised in millimetres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerances {
    /// Ends that miss by at most this are joined; also the distance within which two loops merely
    /// touch, and the smallest feature kept (shorter segments are merged). Default 1e-6. Keep it
    /// above the flattening tolerance, or tangent loops flatten into crossing ones.
    pub gap: f64,
    /// Points outside the domain by at most this are clamped in; farther is an error. Default
    /// 1e-4: p-curves fitted to a 3D edge commonly overshoot the face's box by their fit error.
    pub domain: f64,
}

impl Default for Tolerances {
    fn default() -> Self {
        Self {
            gap: 1e-6,
            domain: 1e-4,
        }
    }
}

/// The same tolerances in parameter units, with the domain they belong to.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Limits {
    pub gap: f64,
    pub domain_tol: f64,
    pub lo: DVec2,
    pub hi: DVec2,
}

impl Limits {
    pub(crate) fn new(domain: [(f64, f64); 2], tol: &Tolerances) -> Result<Self, TrimError> {
        let [u, v] = domain;
        let finite = [u.0, u.1, v.0, v.1].iter().all(|x| x.is_finite());
        if !(finite && u.0 < u.1 && v.0 < v.1) {
            return Err(TrimError::BadDomain { u, v });
        }
        for (name, value) in [("gap", tol.gap), ("domain", tol.domain)] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(TrimError::BadTolerance { name, value });
            }
        }
        let (lo, hi) = (DVec2::new(u.0, v.0), DVec2::new(u.1, v.1));
        let diagonal = lo.distance(hi);
        Ok(Self {
            gap: tol.gap * diagonal,
            domain_tol: tol.domain * diagonal,
            lo,
            hi,
        })
    }
}

/// Assembles loop `loop_index` into a closed polygon (first point not repeated), clamped into the
/// domain, with no segment shorter than the gap tolerance.
pub(crate) fn build_polygon(
    loop_index: usize,
    input: &LoopInput,
    lim: &Limits,
) -> Result<Vec<DVec2>, TrimError> {
    if input.pieces.is_empty() {
        return Err(TrimError::EmptyLoop { loop_index });
    }
    for (piece, points) in input.pieces.iter().enumerate() {
        if points.is_empty() {
            return Err(TrimError::EmptyCurve { loop_index, piece });
        }
        if let Some(point) = points.iter().position(|p| !p.is_finite()) {
            return Err(TrimError::NonFinite {
                loop_index,
                piece,
                point,
            });
        }
    }
    let mut pts = chain(loop_index, &input.pieces, lim.gap)?;
    clamp_to_domain(loop_index, &mut pts, lim)?;
    let pts = drop_short_segments(pts, lim.gap);
    let (lo, hi) = bounds(&pts);
    if pts.len() < 3 || signed_area(&pts).abs() <= lim.gap * lo.distance(hi) {
        return Err(TrimError::ZeroArea { loop_index });
    }
    Ok(pts)
}

/// Joins the pieces head to tail (reversing a piece that meets the chain with its far end) and
/// closes the loop; the closing point is dropped, so the polygon does not repeat its start.
fn chain(loop_index: usize, pieces: &[Vec<DVec2>], gap: f64) -> Result<Vec<DVec2>, TrimError> {
    let ends = |k: usize| -> (DVec2, DVec2) {
        let p = &pieces[k];
        (
            p.first().copied().unwrap_or_default(),
            p.last().copied().unwrap_or_default(),
        )
    };
    let meets = |a: DVec2, b: DVec2| a.distance(b) <= gap;
    let gap_error = |prev: usize, next: usize, end: DVec2, start: DVec2| TrimError::Gap {
        loop_index,
        prev,
        next,
        end,
        start,
        gap: end.distance(start),
        tol: gap,
    };
    let mut pts: Vec<DVec2> = pieces[0].clone();
    if pieces.len() > 1 {
        let ((s0, e0), (s1, e1)) = (ends(0), ends(1));
        let forward = meets(e0, s1) || meets(e0, e1);
        if !forward && (meets(s0, s1) || meets(s0, e1)) {
            pts.reverse();
        }
    }
    for k in 1..pieces.len() {
        let end = pts.last().copied().unwrap_or_default();
        let (s, e) = ends(k);
        if meets(end, s) {
            pts.extend_from_slice(&pieces[k][1..]);
        } else if meets(end, e) {
            pts.extend(pieces[k].iter().rev().skip(1));
        } else {
            return Err(gap_error(k - 1, k, end, s));
        }
    }
    let (first, last) = (pts[0], pts.last().copied().unwrap_or_default());
    if !meets(last, first) {
        return Err(gap_error(pieces.len() - 1, 0, last, first));
    }
    if pts.len() > 1 {
        pts.pop();
    }
    Ok(pts)
}

/// Clamps points within the domain tolerance into the domain; refuses the first one farther out.
fn clamp_to_domain(loop_index: usize, pts: &mut [DVec2], lim: &Limits) -> Result<(), TrimError> {
    for p in pts.iter_mut() {
        let out = (lim.lo - *p).max(*p - lim.hi).max(DVec2::ZERO);
        let by = out.x.max(out.y);
        if by > lim.domain_tol {
            return Err(TrimError::OutsideDomain {
                loop_index,
                point: *p,
                by,
                tol: lim.domain_tol,
            });
        }
        *p = p.clamp(lim.lo, lim.hi);
    }
    Ok(())
}

/// Removes points within `gap` of the previously kept one (and a last point within `gap` of the
/// first): a shorter segment is below the resolution of the trim, and dropping it guarantees
/// every segment a direction for the crossing tests.
#[must_use]
fn drop_short_segments(pts: Vec<DVec2>, gap: f64) -> Vec<DVec2> {
    let mut out: Vec<DVec2> = Vec::with_capacity(pts.len());
    for p in pts {
        match out.last() {
            Some(&q) if p == q || p.distance(q) <= gap => {}
            _ => out.push(p),
        }
    }
    while out.len() > 1
        && out
            .last()
            .is_some_and(|&q| q == out[0] || q.distance(out[0]) <= gap)
    {
        out.pop();
    }
    out
}

/// Signed area (shoelace formula about the first point, for less cancellation): positive for a
/// counter-clockwise polygon.
#[must_use]
pub(crate) fn signed_area(pts: &[DVec2]) -> f64 {
    let Some(&o) = pts.first() else { return 0.0 };
    let mut twice = 0.0;
    for k in 1..pts.len().saturating_sub(1) {
        twice += (pts[k] - o).perp_dot(pts[k + 1] - o);
    }
    0.5 * twice
}

/// Axis-aligned bounds of a point set (`(+inf, -inf)` when empty).
#[must_use]
pub(crate) fn bounds(pts: &[DVec2]) -> (DVec2, DVec2) {
    pts.iter()
        .fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        })
}
