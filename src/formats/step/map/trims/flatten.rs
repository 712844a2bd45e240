//! Adaptive flattening of a piece mapped into the NURBS parameters, for pieces whose points
//! must each be inverted onto the surface.
//!
//! Starts from the piece's coarse samples (each interval halved once), and halves every
//! interval whose chord is too far from the curve at its middle: the surface point at the
//! chord's middle farther than `tol3d` in space from the curve's point there (the drawn
//! boundary's error, measured where it is largest for a flat arc), or the chord's middle
//! farther than `tol_param` from the curve's in the parameter plane (which space does not see
//! near a pole). Each interval is split at most 24 times. Each new
//! point is computed next to the interpolation of its interval's ends, which are already
//! inverted, so a B-spline surface's Newton iteration starts within a fraction of the interval
//! and converges in a step or two (the trim crate's general flattening probes three points per
//! interval from the coarse reference instead, several times the cost here).

use glam::DVec2;

use super::piece::{Ctx, Piece};
use crate::geom::trim::curve::segment_foot;

/// Most halvings of one coarse interval.
const MAX_DEPTH: u32 = 24;
/// Most points of one piece.
const MAX_POINTS: usize = 1 << 20;

/// The polyline of `p` in NURBS parameters through `to_st` (see the module doc).
pub(crate) fn flatten(
    ctx: &Ctx<'_>,
    p: &Piece<'_>,
    to_st: &dyn Fn(DVec2) -> DVec2,
    m: &super::output::Maps<'_>,
) -> Result<Vec<DVec2>, String> {
    let in_space = |st: DVec2| m.surface.point(st.x, st.y).unwrap_or(glam::DVec3::NAN);
    let mut coarse: Vec<(f64, DVec2)> = p.samples.iter().map(|s| (s.t, s.uv + p.shift)).collect();
    // The curve's own ends (a 3D edge's coarse ends are its vertices, which may lie off the
    // curve by the file's tolerance: the caller blends that difference in).
    let n = coarse.len();
    for i in [0, n.saturating_sub(1)] {
        if let Some(c) = coarse.get_mut(i) {
            let own = p.uv_near(ctx, c.0, c.1);
            if own.is_finite() {
                c.1 = own;
            }
        }
    }
    let mut out: Vec<DVec2> = Vec::with_capacity(coarse.len() * 4);
    let Some(&(t0, uv0)) = coarse.first() else {
        return Ok(out);
    };
    out.push(to_st(uv0));
    let mut prev = (t0, uv0);
    for &(tb, uvb) in coarse.iter().skip(1) {
        // Each coarse interval is halved once before testing.
        let tm = 0.5 * (prev.0 + tb);
        let uvm = p.uv_near(ctx, tm, 0.5 * (prev.1 + uvb));
        let mut stack: Vec<(f64, DVec2, u32)> = vec![(tb, uvb, 1), (tm, uvm, 1)];
        let mut a = prev;
        while let Some(&(t, uv, depth)) = stack.last() {
            let (sa, sb) = (to_st(a.1), to_st(uv));
            let tm = 0.5 * (a.0 + t);
            let uvm = p.uv_near(ctx, tm, 0.5 * (a.1 + uv));
            let sm = to_st(uvm);
            let foot = segment_foot(sm, sa, sb);
            let far = (in_space(foot) - in_space(sm)).length() > m.tol3d
                || foot.distance(sm) > m.tol_param;
            if far && depth < MAX_DEPTH && tm != a.0 && tm != t {
                stack.push((tm, uvm, depth + 1));
                continue;
            }
            out.push(sb);
            if out.len() > MAX_POINTS {
                return Err("a trim curve needs more than a million segments".into());
            }
            a = (t, uv);
            stack.pop();
        }
        prev = (tb, uvb);
    }
    if out.iter().any(|q| !q.is_finite()) {
        return Err("a trim curve could not be inverted onto the surface".into());
    }
    Ok(out)
}

/// Moves the polyline's ends onto `a` and `b`, spreading each end's shift linearly in arc
/// length over the whole polyline, so that a difference between a curve's end and its vertex
/// (the file's tolerance) bends the polyline slightly instead of making a hook at the end.
pub(crate) fn blend_ends(pts: &mut [DVec2], a: Option<DVec2>, b: Option<DVec2>) {
    let (Some(&f), Some(&l)) = (pts.first(), pts.last()) else {
        return;
    };
    let (da, db) = (
        a.map_or(DVec2::ZERO, |a| a - f),
        b.map_or(DVec2::ZERO, |b| b - l),
    );
    let total: f64 = pts
        .windows(2)
        .map(|w| match w {
            [x, y] => y.distance(*x),
            _ => 0.0,
        })
        .sum();
    let n = pts.len();
    let mut run = 0.0;
    let mut prev = f;
    for (i, q) in pts.iter_mut().enumerate() {
        run += q.distance(prev);
        prev = *q;
        let s = if total > 0.0 {
            run / total
        } else if n > 1 {
            i as f64 / (n - 1) as f64
        } else {
            0.0
        };
        *q += da * (1.0 - s) + db * s;
    }
    if let Some(first) = pts.first_mut() {
        *first = f + da;
    }
    if let Some(last) = pts.last_mut() {
        *last = l + db;
    }
}
