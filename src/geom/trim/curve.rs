//! Trim curves in parameter space and their flattening into polylines.
//!
//! Everything downstream (validation, point queries, coverage, area) works on polylines, so the
//! accuracy of the whole trim is the flattening tolerance: every point of the curve lies within
//! `tol` of its polyline. Flattening is adaptive bisection with a chord-deviation test at three
//! interior points per piece, starting from [`INITIAL_PIECES`] pieces per span between
//! [`Curve2::breaks`], so a curve that wiggles between the first samples is still seen.

use glam::DVec2;

use super::error::TrimError;

/// Most segments one flattened curve may have: a curve that does not converge (noise, a bad
/// tolerance) is refused instead of filling memory.
pub const MAX_SEGMENTS: usize = 1 << 20;

/// Pieces per span before the deviation test starts: a minimum subdivision depth, because a
/// deviation test only sees the points it probes.
pub const INITIAL_PIECES: usize = 8;

/// Where the deviation test probes each piece besides its midpoint, as fractions of its interval.
const PROBES: [f64; 2] = [0.25, 0.75];

/// A curve in parameter space: anything that can be evaluated on its domain (lines, 2D Bézier,
/// B-spline and NURBS curves of OBJ, IGES and STEP files).
pub trait Curve2 {
    /// The parameter interval the curve is defined on, `lo <= hi`.
    fn domain(&self) -> (f64, f64);
    /// The point at parameter `t` (inside [`Curve2::domain`]).
    fn point(&self, t: f64) -> DVec2;
    /// Interior parameters where the curve may be less smooth (the distinct interior knots of a
    /// spline). Flattening starts a new span at each, so a kink is a vertex of the polyline and
    /// every span gets its own [`INITIAL_PIECES`]. Default: none.
    fn breaks(&self) -> &[f64] {
        &[]
    }

    /// An upper bound of |c''(t)| on `[t0, t1]` (inside one span between breaks), where the
    /// curve can give one: flattening then spaces the span's points evenly, as many as the
    /// bound asks, instead of bisecting (half the points, a quarter of the evaluations).
    /// Default: none.
    fn second_derivative_bound(&self, _t0: f64, _t1: f64) -> Option<f64> {
        None
    }
}

/// One piece of a trim loop before flattening.
///
/// Lines and polylines need no subdivision: [`Piece::Points`] is copied as it is (the fast path).
/// [`Piece::Curve`] is flattened over its range; `range.0 > range.1` traverses it backwards, as
/// OBJ and IGES allow.
#[derive(Clone, Copy)]
pub enum Piece<'a> {
    /// A polyline, used as given (a line is two points).
    Points(&'a [DVec2]),
    /// A curve and the parameter range of it that belongs to the loop.
    Curve(&'a dyn Curve2, (f64, f64)),
}

/// Appends the polyline of `piece` to `out`, its first point included.
pub fn flatten_piece(piece: &Piece<'_>, tol: f64, out: &mut Vec<DVec2>) -> Result<(), TrimError> {
    match *piece {
        Piece::Points(points) => {
            out.extend_from_slice(points);
            Ok(())
        }
        Piece::Curve(curve, range) => flatten(curve, range, tol, out),
    }
}

/// Appends to `out` a polyline through `c(range.0)`, …, `c(range.1)` such that every point of the
/// curve on `range` lies within `tol` of it (to the accuracy of a test at 3 points per segment
/// after at least [`INITIAL_PIECES`] pieces per span).
///
/// `range.0 > range.1` runs the curve backwards. The range may exceed the curve's domain by
/// 1e-9 of its length (rounding in files); more is an error, as are a non-finite point, a
/// `tol` that is not finite and positive, and more than [`MAX_SEGMENTS`] segments.
pub fn flatten(
    c: &dyn Curve2,
    range: (f64, f64),
    tol: f64,
    out: &mut Vec<DVec2>,
) -> Result<(), TrimError> {
    flatten_tracked(c, range, tol, out, None)
}

/// [`flatten`], also appending to `params` the curve parameter of every point appended to
/// `out` (so each chord of the polyline is known with the stretch of curve it replaces: the
/// area measure corrects for the lens between them).
pub fn flatten_tracked(
    c: &dyn Curve2,
    range: (f64, f64),
    tol: f64,
    out: &mut Vec<DVec2>,
    mut params: Option<&mut Vec<f64>>,
) -> Result<(), TrimError> {
    if !(tol.is_finite() && tol > 0.0) {
        return Err(TrimError::BadTolerance {
            name: "flattening",
            value: tol,
        });
    }
    let spans = span_ends(c, range)?;
    let start = out.len();
    out.push(eval(c, range.0)?);
    if let Some(p) = params.as_deref_mut() {
        p.push(range.0);
    }
    for pair in spans.windows(2) {
        let (t0, t1) = (pair[0], pair[1]);
        if even_span(c, t0, t1, tol, out, params.as_deref_mut())? {
            continue;
        }
        for k in 0..INITIAL_PIECES {
            let s0 = t0 + (t1 - t0) * k as f64 / INITIAL_PIECES as f64;
            let s1 = if k + 1 == INITIAL_PIECES {
                t1
            } else {
                t0 + (t1 - t0) * (k + 1) as f64 / INITIAL_PIECES as f64
            };
            subdivide(c, s0, s1, tol, start, out, params.as_deref_mut())?;
        }
    }
    Ok(())
}

/// Flattens `[t0, t1]` by evenly spaced parameters where the curve bounds its second
/// derivative there: a chord over a parameter step `h` departs from the curve by at most
/// `h² max|c''| / 8`, so `n = ⌈|t1 − t0| √(M / 8 tol)⌉` pieces meet `tol`; each piece's midpoint
/// is checked besides, and any miss (an underestimated bound) leaves the span to bisection.
/// Returns whether the span was done.
fn even_span(
    c: &dyn Curve2,
    t0: f64,
    t1: f64,
    tol: f64,
    out: &mut Vec<DVec2>,
    mut params: Option<&mut Vec<f64>>,
) -> Result<bool, TrimError> {
    let Some(m) = c.second_derivative_bound(t0.min(t1), t0.max(t1)) else {
        return Ok(false);
    };
    let n = ((t1 - t0).abs() * (m / (8.0 * tol)).sqrt()).ceil();
    if !n.is_finite() || n > MAX_SEGMENTS as f64 {
        return Ok(false);
    }
    let n = (n as usize).max(1);
    let mark = (out.len(), params.as_ref().map(|p| p.len()));
    let mut prev = eval(c, t0)?;
    for k in 1..=n {
        let t = if k == n {
            t1
        } else {
            t0 + (t1 - t0) * k as f64 / n as f64
        };
        let tm = t0 + (t1 - t0) * (k as f64 - 0.5) / n as f64;
        let (p, mid) = (eval(c, t)?, eval(c, tm)?);
        if point_segment_distance(mid, prev, p) > tol {
            out.truncate(mark.0);
            if let (Some(p), Some(len)) = (params.as_deref_mut(), mark.1) {
                p.truncate(len);
            }
            return Ok(false);
        }
        out.push(p);
        if let Some(params) = params.as_deref_mut() {
            params.push(t);
        }
        prev = p;
    }
    Ok(true)
}

/// The range's ends with the curve's breaks strictly between them, in the traversal's order.
fn span_ends(c: &dyn Curve2, range: (f64, f64)) -> Result<Vec<f64>, TrimError> {
    let domain = c.domain();
    let slack = 1e-9 * (domain.1 - domain.0).abs();
    let (lo, hi) = (range.0.min(range.1), range.0.max(range.1));
    let ok = range.0.is_finite()
        && range.1.is_finite()
        && lo >= domain.0 - slack
        && hi <= domain.1 + slack;
    if !ok {
        return Err(TrimError::BadCurveRange { range, domain });
    }
    let mut ends: Vec<f64> = c
        .breaks()
        .iter()
        .copied()
        .filter(|&t| lo < t && t < hi)
        .collect();
    ends.sort_by(f64::total_cmp);
    ends.dedup();
    if range.0 > range.1 {
        ends.reverse();
    }
    ends.insert(0, range.0);
    ends.push(range.1);
    Ok(ends)
}

/// The curve's point at `t`, refused when not finite.
fn eval(c: &dyn Curve2, t: f64) -> Result<DVec2, TrimError> {
    let p = c.point(t);
    if p.is_finite() {
        Ok(p)
    } else {
        Err(TrimError::CurveNotFinite { t })
    }
}

/// The point of the segment `a`–`b` nearest to `q`.
#[must_use]
pub(crate) fn segment_foot(q: DVec2, a: DVec2, b: DVec2) -> DVec2 {
    let e = b - a;
    let len2 = e.length_squared();
    let s = if len2 > 0.0 {
        ((q - a).dot(e) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    a + e * s
}

/// Distance from `q` to the segment `a`–`b`.
#[must_use]
pub(crate) fn point_segment_distance(q: DVec2, a: DVec2, b: DVec2) -> f64 {
    q.distance(segment_foot(q, a, b))
}

/// Adaptive bisection of `[t0, t1]` (whose start point is already the last of `out`), with an
/// explicit stack so deep subdivision near a cusp cannot overflow the call stack. A piece is
/// accepted when its probes lie within `tol` of its chord, or when it can no longer be halved.
fn subdivide(
    c: &dyn Curve2,
    t0: f64,
    t1: f64,
    tol: f64,
    start: usize,
    out: &mut Vec<DVec2>,
    mut params: Option<&mut Vec<f64>>,
) -> Result<(), TrimError> {
    let (mut ta, mut pa) = (t0, eval(c, t0)?);
    let mut stack = vec![(t1, eval(c, t1)?)];
    while let Some(&(tb, pb)) = stack.last() {
        let tm = 0.5 * (ta + tb);
        let mid = eval(c, tm)?;
        let mut deviates = point_segment_distance(mid, pa, pb) > tol;
        for f in PROBES {
            deviates |= point_segment_distance(eval(c, ta + (tb - ta) * f)?, pa, pb) > tol;
        }
        if deviates && tm != ta && tm != tb {
            stack.push((tm, mid));
            continue;
        }
        out.push(pb);
        if let Some(p) = params.as_deref_mut() {
            p.push(tb);
        }
        if out.len() - start > MAX_SEGMENTS {
            return Err(TrimError::TooManySegments {
                limit: MAX_SEGMENTS,
                tol,
            });
        }
        (ta, pa) = (tb, pb);
        stack.pop();
    }
    Ok(())
}
