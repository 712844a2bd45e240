//! A face's trim loops in its NURBS surface's own parameter space.
//!
//! Route: every ORIENTED_EDGE becomes a [`piece::Piece`] in the analytic parameters (from its
//! PCURVE or its 3D curve, [`edge`]), split where it passes a pole; the loops are chained,
//! oriented and placed in one window of the periodic parameter plane ([`layout`], [`wind`]);
//! their parameter box is the box the analytic surface is converted over (a closed B-spline
//! surface is re-seated to start where the loops need it), so that no loop crosses the NURBS's
//! boundary; finally each piece is mapped into the NURBS parameters, exactly where it can be
//! ([`output`]), and the ends of consecutive pieces are joined.
//!
//! Tolerances: curves that are flattened stay within `REL_TOL_3D` (1e-6) of the face's size
//! in space and within `REL_TOL_PARAM` (1e-5) of the parameter box in the plane (see
//! `flatten`); pieces whose ends miss each other by more than `MAX_GAP` (1e-3 of
//! the parameter box's diagonal) make the face fail, smaller gaps (PCURVE fit errors, vertices
//! off their curves) are closed by moving both ends to their middle, spreading the move along
//! a polyline rather than bending its last segment.

mod edge;
mod flatten;
mod layout;
mod output;
mod piece;
mod wind;

use crate::formats::step::map::attrs::{at, at_mut};
use crate::geom::analytic::{AxisMap, FaceNurbs, NurbsSurface, ParamBox, ParamMap, SurfaceKind};
use glam::DVec2;

use super::attrs::{Res, failed};
use super::surface::{Geometry, Surface};
use super::topology::FaceIn;
use crate::formats::step::map::{CadLoop, CadPiece};
use layout::{FaceSide, LoopP, c};
use piece::Ctx;

/// Flattened curves stay within this fraction of the face's size of the true edge, in space.
pub(crate) const REL_TOL_3D: f64 = 1e-6;
/// Flattened curves also stay within this fraction of the parameter box's diagonal of the true
/// curve in the parameter plane (where the surface is degenerate, space says little).
pub(crate) const REL_TOL_PARAM: f64 = 1e-5;
/// Gaps between consecutive pieces up to this fraction of the parameter box's diagonal are
/// closed; larger ones fail the face.
const MAX_GAP: f64 = 1e-3;

/// A mapped face: its exact NURBS surface and loops in the surface's parameters.
pub(crate) struct Mapped {
    pub surface: NurbsSurface,
    pub loops: Vec<CadLoop>,
}

/// Maps face `face` on surface `surf` (see the module doc).
pub(crate) fn map_face(face: &FaceIn<'_>, surf: &Surface) -> Res<Mapped> {
    let e = &face.entity;
    let (lo, hi) = face.extent;
    let size = (hi - lo)
        .length()
        .max(1e-12 * (lo.length() + hi.length() + 1.0));
    let periods = surf.periods;
    let natural = surf.natural;
    let scale = [0, 1].map(|d| {
        at(&periods, d)
            .or_else(|| at(&natural, d).map(|n| n[1] - n[0]))
            .unwrap_or(size)
    });
    let ctx = Ctx {
        surf,
        periods,
        poles: surf.poles(),
        size,
        scale,
    };
    let mut loops = Vec::new();
    for l in &face.loops {
        let mut pieces: Vec<piece::Piece<'_>> = Vec::new();
        for u in &l.edges {
            let prev_end = pieces.last().and_then(|p| p.samples.last()).map(|s| s.uv);
            if let Some(p) = edge::piece(&ctx, u, e, prev_end)? {
                pieces.extend(edge::split_at_poles(&ctx, p));
            }
        }
        if !pieces.is_empty() {
            loops.push(LoopP {
                pieces,
                outer: l.outer,
            });
        }
    }
    let fixed = match &surf.geom {
        Geometry::Nurbs(n) => {
            let dom = n.fast.domain();
            [0, 1].map(|d| at(&periods, d).is_none().then_some(*at(&dom, d)))
        }
        Geometry::Analytic(_) => [None, None],
    };
    let hints = face
        .vertex_points
        .iter()
        .filter_map(|&p| surf.invert(p, None).map(|i| i.uv))
        .collect();
    let side = FaceSide {
        left: face.same_sense != surf.flip,
        hints,
        fixed,
        natural,
    };
    let (loops, window) = place(&ctx, loops, &side).map_err(|m| failed(e, m))?;
    let loops = if loops.is_empty() {
        vec![
            whole(&ctx, surf, &side)
                .ok_or_else(|| failed(e, "face has no loops and no bounded parameter range"))?,
        ]
    } else {
        loops
    };
    finish(&ctx, surf, &loops, window, fixed).map_err(|m| failed(e, m))
}

/// Per direction, the window loops were cut to where they wind around.
type Window = [Option<[f64; 2]>; 2];

/// Chains every loop, bridges its poles, and places the loops direction by direction.
fn place<'f>(
    ctx: &Ctx<'_>,
    mut loops: Vec<LoopP<'f>>,
    side: &FaceSide,
) -> Result<(Vec<LoopP<'f>>, Window), String> {
    let mut winds: Vec<[i64; 2]> = Vec::with_capacity(loops.len());
    let single = loops.len() == 1;
    for lp in &mut loops {
        winds.push(layout::chain(ctx, lp));
        let outer = lp.outer || single;
        layout::orient(ctx, lp, outer == side.left);
        layout::bridge_poles(ctx, lp);
    }
    let mut window = [None, None];
    for d in 0..2 {
        let Some(period) = *at(&ctx.periods, d) else {
            continue;
        };
        let wd: Vec<i64> = winds.iter().map(|w| *at(w, d)).collect();
        if wd.iter().all(|&k| k == 0) {
            layout::place_closed(&mut loops, d, period, *at(&side.fixed, d));
            continue;
        }
        let (placed, w) = wind::close(ctx, loops, &wd, d, side)?;
        loops = placed;
        // The new loops are closed in `d`; a loop that also winds in the other direction is
        // not supported (a torus knot).
        winds = vec![[0, 0]; loops.len()];
        *at_mut(&mut window, d) = Some(w);
    }
    for d in 0..2 {
        // Into a natural range of two periods (a closed swept profile stored twice).
        let (Some(period), Some(n), None) = (
            *at(&ctx.periods, d),
            *at(&side.natural, d),
            *at(&side.fixed, d),
        ) else {
            continue;
        };
        let lo = loops
            .iter()
            .map(|l| layout::range(l, d)[0])
            .fold(f64::INFINITY, f64::min);
        let k = ((lo - n[0]) / period).floor();
        if k.is_finite() && k != 0.0 {
            for lp in &mut loops {
                layout::move_loop(lp, d, -k * period);
            }
            if let Some(w) = at_mut(&mut window, d).as_mut() {
                *w = [w[0] - k * period, w[1] - k * period];
            }
        }
    }
    Ok((loops, window))
}

/// The loop of a face without loops: the whole natural box (a full sphere or torus).
#[must_use]
fn whole<'f>(ctx: &Ctx<'_>, surf: &Surface, side: &FaceSide) -> Option<LoopP<'f>> {
    let b = |d: usize| -> Option<[f64; 2]> {
        let periodic = at(&ctx.periods, d).map(|p| {
            let lo = at(&side.natural, d).map_or(0.0, |n| n[0]);
            [lo, lo + p]
        });
        at(&side.fixed, d)
            .or(surf.limits.map(|l| *at(&l, d)))
            .or(periodic)
            .or(*at(&side.natural, d))
    };
    let (u, v) = (b(0)?, b(1)?);
    let corners = [
        DVec2::new(u[0], v[0]),
        DVec2::new(u[1], v[0]),
        DVec2::new(u[1], v[1]),
        DVec2::new(u[0], v[1]),
    ];
    let pieces = corners
        .iter()
        .zip(corners.iter().cycle().skip(1))
        .map(|(&a, &b)| layout::segment(a, b))
        .collect();
    Some(LoopP {
        pieces,
        outer: true,
    })
}

/// Samples per coarse interval when measuring a loop's parameter box.
const BOX_SAMPLES: usize = 8;

/// The box of all loops, from finer samples than the coarse ones (window where loops wind,
/// at most one period wide, within the natural limits).
#[must_use]
fn param_box(ctx: &Ctx<'_>, loops: &[LoopP<'_>], window: [Option<[f64; 2]>; 2]) -> [[f64; 2]; 2] {
    let mut r = [[f64::INFINITY, f64::NEG_INFINITY]; 2];
    let mut add = |q: DVec2| {
        for (d, rd) in r.iter_mut().enumerate() {
            rd[0] = rd[0].min(c(q, d));
            rd[1] = rd[1].max(c(q, d));
        }
    };
    for p in loops.iter().flat_map(|l| &l.pieces) {
        for s in &p.samples {
            add(s.uv + p.shift);
        }
        if p.iso {
            continue;
        }
        for w in p.samples.windows(2) {
            let [a, b] = w else { continue };
            for k in 1..BOX_SAMPLES {
                let t = a.t + (b.t - a.t) * (k as f64 / BOX_SAMPLES as f64);
                let q = p.uv_at(ctx, t);
                if q.is_finite() {
                    add(q);
                }
            }
        }
    }
    for d in 0..2 {
        if let Some(w) = *at(&window, d) {
            *at_mut(&mut r, d) = w;
        }
        if let Some(p) = *at(&ctx.periods, d)
            && at(&r, d)[1] - at(&r, d)[0] > p
        {
            let mid = 0.5 * (at(&r, d)[0] + at(&r, d)[1]);
            *at_mut(&mut r, d) = [mid - 0.5 * p, mid + 0.5 * p];
        }
        // A natural range (a sphere's latitudes, a profile stored twice) limits the box; a
        // closed B-spline direction's domain does not: the surface is re-seated instead.
        if let Some(n) = *at(&ctx.surf.natural, d) {
            let limits = at(&ctx.periods, d).is_none_or(|p| n[1] - n[0] > 1.5 * p);
            if limits {
                *at_mut(&mut r, d) = [at(&r, d)[0].max(n[0]), at(&r, d)[1].min(n[1])];
            }
        }
    }
    r
}

/// The NURBS over the box, the output pieces, gap snapping.
fn finish(
    ctx: &Ctx<'_>,
    surf: &Surface,
    loops: &[LoopP<'_>],
    window: [Option<[f64; 2]>; 2],
    fixed: [Option<[f64; 2]>; 2],
) -> Result<Mapped, String> {
    let loose = match fixed {
        [Some(u), Some(v)] => [u, v],
        _ => param_box(ctx, loops, window),
    };
    let mut bx = [0, 1].map(|d| at(&fixed, d).unwrap_or(*at(&loose, d)));
    if bx.iter().any(|r| {
        r[0] >= r[1] || r[0].is_nan() || r[1].is_nan() || !r[0].is_finite() || !r[1].is_finite()
    }) {
        return Err("the loops enclose no area in the parameter plane".into());
    }
    let identity = surf
        .pre
        .iter()
        .all(|p| matches!(p, super::surface::Pre::Identity));
    let plane = match &surf.geom {
        Geometry::Analytic(a) if matches!(a.kind(), SurfaceKind::Plane) => Some(*a.frame()),
        _ => None,
    };
    let mut fn_ = nurbs_over(surf, bx)?;
    let identity = identity && is_identity(&fn_.map);
    let fast = super::nurbs::FastSurface::new(&fn_.surface);
    let diag = DVec2::new(bx[0][1] - bx[0][0], bx[1][1] - bx[1][0]).length();
    let maps = output::Maps {
        map: &fn_.map,
        identity,
        plane,
        surface: &fast,
        tol3d: REL_TOL_3D * ctx.size,
        tol_param: REL_TOL_PARAM * diag,
    };
    let mut out = Vec::with_capacity(loops.len());
    for lp in loops {
        let pieces: Vec<CadPiece> = lp
            .pieces
            .iter()
            .map(|p| output::piece(ctx, p, &maps))
            .collect::<Result<_, _>>()?;
        out.push(CadLoop {
            outer: lp.outer,
            pieces,
        });
    }
    if identity && fixed.iter().all(Option::is_none) {
        // Exact curves may bulge beyond their samples: grow the (plane's) box to their hulls.
        let all: Vec<CadPiece> = out.iter().flat_map(|l| l.pieces.clone()).collect();
        let (lo, hi) = output::hull(&all);
        let grown = [
            [bx[0][0].min(lo.x), bx[0][1].max(hi.x)],
            [bx[1][0].min(lo.y), bx[1][1].max(hi.y)],
        ];
        if grown != bx && ctx.periods.iter().all(Option::is_none) {
            bx = grown;
            fn_ = nurbs_over(surf, bx)?;
        }
    }
    let diag = DVec2::new(bx[0][1] - bx[0][0], bx[1][1] - bx[1][0]).length();
    for lp in &mut out {
        snap(&mut lp.pieces, MAX_GAP * diag)?;
    }
    mark_outer(&mut out);
    Ok(Mapped {
        surface: fn_.surface,
        loops: out,
    })
}

/// The exact NURBS form of `surf` over `bx` (a B-spline surface as it is).
fn nurbs_over(surf: &Surface, bx: [[f64; 2]; 2]) -> Result<FaceNurbs, String> {
    match &surf.geom {
        Geometry::Analytic(a) => a
            .to_nurbs(&ParamBox { u: bx[0], v: bx[1] })
            .map_err(|e| e.to_string()),
        Geometry::Nurbs(n) => {
            let mut s = n.surface.clone();
            let dom = n.fast.domain();
            for d in 0..2 {
                let Some(p) = *at(&surf.periods, d) else {
                    continue;
                };
                let inside = at(&bx, d)[0] >= at(&dom, d)[0] - 1e-12 * p
                    && at(&bx, d)[1] <= at(&dom, d)[1] + 1e-12 * p;
                if !inside {
                    s = super::nurbs::reseat(&s, d, at(&bx, d)[0], p)
                        .ok_or("a closed B-spline surface cannot be re-seated around its loops")?;
                }
            }
            Ok(FaceNurbs {
                surface: s,
                map: ParamMap {
                    u: AxisMap::Identity,
                    v: AxisMap::Identity,
                },
            })
        }
    }
}

#[must_use]
fn is_identity(m: &ParamMap) -> bool {
    matches!((&m.u, &m.v), (AxisMap::Identity, AxisMap::Identity))
}

/// Closes the gaps between consecutive pieces (both ends to the middle); fails above `max`.
fn snap(pieces: &mut [CadPiece], max: f64) -> Result<(), String> {
    let n = pieces.len();
    for i in 0..n {
        let j = (i + 1) % n;
        let (Some(a), Some(b)) = (pieces.get(i), pieces.get(j)) else {
            continue;
        };
        let (Some((_, end)), Some((start, _))) = (output::piece_ends(a), output::piece_ends(b))
        else {
            continue;
        };
        let gap = end.distance(start);
        if gap > max {
            return Err(format!(
                "trim curves {i} and {j} of a loop are {gap:.3e} apart in the parameter plane"
            ));
        }
        if gap > 0.0 {
            let m = 0.5 * (end + start);
            if let Some(a) = pieces.get_mut(i) {
                output::move_end(a, true, m);
            }
            if let Some(b) = pieces.get_mut(j) {
                output::move_end(b, false, m);
            }
        }
    }
    Ok(())
}

/// Where the file marks no FACE_OUTER_BOUND, the loop with the largest box is the outer one.
fn mark_outer(loops: &mut [CadLoop]) {
    if loops.iter().any(|l| l.outer) {
        return;
    }
    let area = |l: &CadLoop| {
        let (lo, hi) = output::hull(&l.pieces);
        (hi - lo).x * (hi - lo).y
    };
    let best = loops
        .iter()
        .enumerate()
        .max_by(|a, b| area(a.1).total_cmp(&area(b.1)))
        .map(|(i, _)| i);
    if let Some(l) = best.and_then(|i| loops.get_mut(i)) {
        l.outer = true;
    }
}

/// [`flatten::blend_ends`] for the unit tests.
#[cfg(test)]
pub(crate) fn blend_for_tests(pts: &mut [DVec2], a: Option<DVec2>, b: Option<DVec2>) {
    flatten::blend_ends(pts, a, b);
}
