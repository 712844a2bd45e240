//! Placing a face's loops in one window of a periodic parameter plane.
//!
//! 1. *Chaining*: each piece is moved by whole periods so that it starts where the previous one
//!    ends. A join at a pole (where one parameter is arbitrary) is *singular*: any move fits, a
//!    straight segment along the pole line is inserted, and if the loop does not close the
//!    pieces after a singular join take the difference (a loop over a hemisphere: equator, seam
//!    up, pole, seam down). A loop through two or more poles (a lune, a great circle through
//!    both poles) closes either way round; its orientation picks the side (see [`orient`]).
//! 2. *Windows*: a loop that closes is moved by whole periods next to the outer loop (B-spline
//!    surfaces: into their domain). A loop that does not close winds once around the surface
//!    (a circle bounding a cylinder with no seam edge). Such loops are cut where the parameter
//!    crosses a window line `w` (chosen where every winding loop crosses it once and no closed
//!    loop does), each then runs from `w` to `w ± P`, and they are closed into regions: two
//!    winding loops with a band between them are joined by two segments along the window's
//!    edges (the seam); a lone one is closed along a pole beyond it (a sphere's cap, a cone up
//!    to its apex), or with its own copy one period further where the other parameter is
//!    periodic too (a torus cut once around). Which side the face lies on comes from the
//!    orientation: ISO 10303-42 bounds keep the face on their left seen against the face
//!    normal, and a VERTEX_LOOP at a pole, where there is one, names the pole.
//! 3. *Box*: the parameter box of all loops, one period wide where loops wind.

use crate::formats::step::map::attrs::{at, at_mut};
use glam::DVec2;

use super::piece::{Ctx, Piece, Sample, Source, near};

/// A loop during layout.
#[derive(Clone, Debug)]
pub(crate) struct LoopP<'f> {
    pub pieces: Vec<Piece<'f>>,
    pub outer: bool,
}

/// What the layout needs besides the pieces.
pub(crate) struct FaceSide {
    /// Face interior is on the left of its bounds in the parameter plane (`S_u × S_v` is the
    /// face normal).
    pub left: bool,
    /// Parameters of the face's VERTEX_LOOP points.
    pub hints: Vec<DVec2>,
    /// A fixed range per direction to place loops in (a B-spline surface's domain where it
    /// does not close on itself; a closed direction is re-seated around the loops instead).
    pub fixed: [Option<[f64; 2]>; 2],
    /// Natural limits of each parameter (a sphere's latitude) for closing at a boundary.
    pub natural: [Option<[f64; 2]>; 2],
}

/// Coordinate `d` of `v`.
#[must_use]
pub(crate) fn c(v: DVec2, d: usize) -> f64 {
    if d == 0 { v.x } else { v.y }
}

/// `v` with coordinate `d` set to `x`.
#[must_use]
pub(crate) fn with(mut v: DVec2, d: usize, x: f64) -> DVec2 {
    if d == 0 {
        v.x = x;
    } else {
        v.y = x;
    }
    v
}

/// A straight piece from `a` to `b`.
#[must_use]
pub(crate) fn segment<'f>(a: DVec2, b: DVec2) -> Piece<'f> {
    let s = |t: f64, uv| Sample {
        t,
        uv,
        free: [false, false],
    };
    Piece {
        src: Source::Segment(a, b),
        t: (0.0, 1.0),
        samples: vec![s(0.0, a), s(1.0, b)],
        shift: DVec2::ZERO,
        iso: true,
    }
}

/// Relative gap below which no segment is inserted at a singular join.
const JOIN_TOL: f64 = 1e-12;

/// Step 1: chains `lp` and returns its winding number per direction: the whole periods it
/// travels (+1: once around towards larger parameters) where no singular join absorbs them.
#[must_use]
pub(crate) fn chain(ctx: &Ctx<'_>, lp: &mut LoopP<'_>) -> [i64; 2] {
    let n = lp.pieces.len();
    let mut singular: [Option<usize>; 2] = [None, None];
    for i in 1..n {
        let Some(prev) = lp.pieces.get(i - 1) else {
            break;
        };
        let (end, free) = (prev.end(), [prev.end_free(0), prev.end_free(1)]);
        let Some(p) = lp.pieces.get_mut(i) else { break };
        for d in 0..2 {
            let Some(period) = *at(&ctx.periods, d) else {
                continue;
            };
            if *at(&free, d) || p.start_free(d) {
                at_mut(&mut singular, d).get_or_insert(i);
            }
            let s = c(p.start(), d);
            p.shift = with(
                p.shift,
                d,
                c(p.shift, d) + near(s, c(end, d), Some(period)) - s,
            );
        }
    }
    let mut wind = [0i64; 2];
    let (Some(first), Some(last)) = (lp.pieces.first(), lp.pieces.last()) else {
        return wind;
    };
    let (start, end) = (first.start(), last.end());
    let free = [0, 1].map(|d| first.start_free(d) || last.end_free(d));
    for d in 0..2 {
        let Some(period) = *at(&ctx.periods, d) else {
            continue;
        };
        if *at(&free, d) {
            continue;
        }
        // Periods travelled: +1 for a loop once around in the +d direction.
        let k = ((c(end, d) - c(start, d)) / period).round() as i64;
        if k == 0 {
            continue;
        }
        match *at(&singular, d) {
            Some(j) => {
                for p in lp.pieces.iter_mut().skip(j) {
                    p.shift = with(p.shift, d, c(p.shift, d) - k as f64 * period);
                }
            }
            None => *at_mut(&mut wind, d) = k,
        }
    }
    wind
}

/// Step 1 continued: the side of a loop with two or more joins at poles (a lune of a sphere
/// between two meridians, a hemisphere bounded by a great circle through the poles) is not
/// fixed by continuity: either way round closes. `ccw` is the orientation ISO 10303-42 gives
/// it in the parameter plane (the face on its left); if it runs the other way, the pieces
/// between the first two pole joins move by one period, which takes the other side.
pub(crate) fn orient(ctx: &Ctx<'_>, lp: &mut LoopP<'_>, ccw: bool) {
    let n = lp.pieces.len();
    for d in 0..2 {
        let Some(period) = *at(&ctx.periods, d) else {
            continue;
        };
        let joins: Vec<usize> = (0..n)
            .filter(|&i| {
                let prev = lp.pieces.get((i + n - 1) % n);
                let cur = lp.pieces.get(i);
                prev.is_some_and(|p| p.end_free(d)) || cur.is_some_and(|p| p.start_free(d))
            })
            .collect();
        if joins.len() < 2 || (signed_area(lp) > 0.0) == ccw {
            continue;
        }
        let (Some(&j), Some(&k)) = (joins.iter().find(|&&j| j > 0), joins.first()) else {
            continue;
        };
        let next = joins
            .iter()
            .copied()
            .find(|&x| x > j)
            .unwrap_or(if k == 0 { n } else { k + n });
        let jump = match (lp.pieces.get(j - 1), lp.pieces.get(j)) {
            (Some(a), Some(b)) => c(b.start(), d) - c(a.end(), d),
            _ => continue,
        };
        let by = -jump.signum() * period;
        for i in j..next {
            if let Some(p) = lp.pieces.get_mut(i % n) {
                p.shift = with(p.shift, d, c(p.shift, d) + by);
            }
        }
    }
}

/// Signed area of a loop's coarse polygon (positive: counter-clockwise).
#[must_use]
fn signed_area(lp: &LoopP<'_>) -> f64 {
    let pts: Vec<DVec2> = lp
        .pieces
        .iter()
        .flat_map(|p| p.samples.iter().map(move |s| s.uv + p.shift))
        .collect();
    let Some(&o) = pts.first() else { return 0.0 };
    let mut twice = 0.0;
    for w in pts.windows(2) {
        if let [a, b] = *w {
            twice += (a - o).perp_dot(b - o);
        }
    }
    0.5 * twice
}

/// Step 1 continued: segments along the pole lines at singular joins (and the closing join).
pub(crate) fn bridge_poles(ctx: &Ctx<'_>, lp: &mut LoopP<'_>) {
    let n = lp.pieces.len();
    let mut out = Vec::with_capacity(n + 2);
    for i in 0..n {
        let (Some(p), Some(q)) = (lp.pieces.get(i), lp.pieces.get((i + 1) % n)) else {
            continue;
        };
        let (a, b) = (p.end(), q.start());
        let free = (0..2).any(|d| p.end_free(d) || q.start_free(d));
        let gap = (0..2).any(|d| (c(a, d) - c(b, d)).abs() > JOIN_TOL * *at(&ctx.scale, d));
        out.push(p.clone());
        if free && gap {
            out.push(segment(a, b));
        }
    }
    lp.pieces = out;
}

/// The range of coordinate `d` over a loop's samples (shifted).
#[must_use]
pub(crate) fn range(lp: &LoopP<'_>, d: usize) -> [f64; 2] {
    let mut r = [f64::INFINITY, f64::NEG_INFINITY];
    for p in &lp.pieces {
        for s in &p.samples {
            let x = c(s.uv + p.shift, d);
            r = [r[0].min(x), r[1].max(x)];
        }
    }
    r
}

/// Moves a whole loop by `k` periods in direction `d`.
pub(crate) fn move_loop(lp: &mut LoopP<'_>, d: usize, by: f64) {
    for p in &mut lp.pieces {
        p.shift = with(p.shift, d, c(p.shift, d) + by);
    }
}

/// Step 2 for closed loops in periodic direction `d`: each loop next to the reference (the
/// outer loop, else the widest), or into the fixed box.
pub(crate) fn place_closed(
    loops: &mut [LoopP<'_>],
    d: usize,
    period: f64,
    fixed: Option<[f64; 2]>,
) {
    let centre = |lp: &LoopP<'_>| {
        let r = range(lp, d);
        0.5 * (r[0] + r[1])
    };
    let target = match fixed {
        Some(f) => 0.5 * (f[0] + f[1]),
        None => {
            let widest = loops.iter().max_by(|a, b| {
                let (ra, rb) = (range(a, d), range(b, d));
                (a.outer, ra[1] - ra[0])
                    .partial_cmp(&(b.outer, rb[1] - rb[0]))
                    .unwrap_or(std::cmp::Ordering::Equal)
            });
            match widest {
                Some(w) => centre(w),
                None => return,
            }
        }
    };
    for lp in loops.iter_mut() {
        let m = centre(lp);
        let by = near(m, target, Some(period)) - m;
        if by != 0.0 {
            move_loop(lp, d, by);
        }
    }
}
