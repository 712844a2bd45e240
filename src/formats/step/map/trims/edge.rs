//! One ORIENTED_EDGE of a face → one [`Piece`]: from the PCURVE on this face's surface where
//! the file has one that agrees with the 3D geometry, else from the 3D curve by inversion.
//!
//! Ranges. The edge runs over its 3D curve from the parameter of `edge_start` to that of
//! `edge_end` (points inverted onto the curve in closed form for lines and conics); on a closed
//! curve (a conic) the direction is EDGE_CURVE.same_sense and equal ends mean the whole curve.
//! A PCURVE usually shares the 3D curve's parameter (ISO 10303-42 SURFACE_CURVE; OpenCASCADE
//! and most writers do); where it does not, its range is found by inverting the vertices onto
//! the PCURVE mapped onto the surface. A PCURVE is used only if its ends land on the vertices
//! (to 1e-9 of the face's size with the shared parameter, else to 1e-4: its fit error, closed
//! later) and its middle on the 3D curve to 1e-3; a file whose PCURVEs disagree
//! (another angle unit, another surface) is thus read from its 3D edges instead.

use crate::formats::step::map::attrs::{at, at_mut};
use glam::{DVec2, DVec3};

use super::super::attrs::{Res, failed};
use super::super::curves::{Curve, invert_sampled, wrap_after};
use super::super::topology::EdgeUse;
use super::piece::{Ctx, Piece, Sample, Source};

/// How far (relative to the face's size) a PCURVE's middle may stray from the 3D edge.
const PCURVE_AGREE: f64 = 1e-3;
/// How near its ends must land on the vertices with the 3D curve's parameters (shared
/// parametrisation: rounding only).
const PCURVE_SHARED: f64 = 1e-9;
/// How near its ends must land on the vertices otherwise (its fit error; the gap is closed).
const PCURVE_ENDS: f64 = 1e-4;
/// Relative spread of a coordinate below which a piece is isoparametric.
const ISO_TOL: f64 = 1e-9;

/// The piece of edge use `u`, or `None` for a degenerate edge (zero length).
pub(crate) fn piece<'f>(
    ctx: &Ctx<'_>,
    u: &'f EdgeUse,
    face: &crate::formats::step::EntityRef<'_>,
    prev_end: Option<DVec2>,
) -> Res<Option<Piece<'f>>> {
    let (from, to) = if u.forward {
        (u.start, u.end)
    } else {
        (u.end, u.start)
    };
    let range3 = u.curve.as_ref().map(|c| {
        let r = edge_range(&c.curve, u);
        if u.forward { r } else { (r.1, r.0) }
    });
    if !u.closed && (from - to).length() <= 1e-12 * ctx.size.max(1.0) {
        let zero = range3.is_none_or(|(a, b)| (a - b).abs() <= 1e-12 * (a.abs() + b.abs() + 1.0));
        if zero {
            return Ok(None);
        }
    }
    for (sid, pc) in &u.pcurves {
        if !ctx.surf.ids.contains(sid) {
            continue;
        }
        if let Some(p) = from_pcurve(ctx, u, &pc.curve, range3, (from, to)) {
            return Ok(Some(p));
        }
    }
    let Some(read) = u.curve.as_ref() else {
        let why = format!(
            "edge #{}: its PCURVE does not fit this face's surface",
            u.id
        );
        return Err(failed(face, why));
    };
    let t = range3.unwrap_or((0.0, 0.0));
    let src = Source::Edge(&read.curve);
    let n = coarse_count(&read.curve, t);
    let samples = ctx
        .sample(&src, t, (Some(from), Some(to)), n, prev_end)
        .ok_or_else(|| {
            failed(
                face,
                format!("edge #{}: cannot invert onto the surface", u.id),
            )
        })?;
    Ok(Some(finish(ctx, src, t, samples)))
}

/// The 3D parameter range from `edge_start` to `edge_end` (see the module doc).
#[must_use]
fn edge_range(c: &Curve, u: &EdgeUse) -> (f64, f64) {
    let ts = c.invert(u.start);
    let te = c.invert(u.end);
    match c.period() {
        Some(p) if u.closed => (ts, if u.same_sense { ts + p } else { ts - p }),
        Some(p) => (ts, wrap_after(ts, te, p, u.same_sense)),
        None if u.closed => {
            let (lo, hi) = c.domain();
            if u.same_sense { (lo, hi) } else { (hi, lo) }
        }
        None => (ts, te),
    }
}

/// Initial coarse samples for a range of a curve: lines 8, conics every 22.5°, splines 4 per
/// knot span (at least 8).
#[must_use]
fn coarse_count(c: &Curve, (t0, t1): (f64, f64)) -> usize {
    match c {
        Curve::Line { .. } => 8,
        Curve::Conic { .. } => ((t1 - t0).abs() / (std::f64::consts::PI / 8.0))
            .ceil()
            .max(4.0) as usize,
        Curve::Nurbs(_) => {
            let (lo, hi) = (t0.min(t1), t0.max(t1));
            let spans = c.breaks().iter().filter(|&&k| k > lo && k < hi).count() + 1;
            (4 * spans).max(8)
        }
        _ => 16,
    }
}

/// The piece from PCURVE `pc` if it agrees with the 3D edge (see the module doc).
#[must_use]
fn from_pcurve<'f>(
    ctx: &Ctx<'_>,
    u: &EdgeUse,
    pc: &'f Curve,
    range3: Option<(f64, f64)>,
    (from, to): (DVec3, DVec3),
) -> Option<Piece<'f>> {
    let src = Source::Pcurve(pc);
    let on_surface = |t: f64| {
        let q = pc.eval(t);
        ctx.surf
            .file_point(glam::DVec2::new(q.x, q.y))
            .unwrap_or(DVec3::NAN)
    };
    let tol = PCURVE_AGREE * ctx.size.max(f64::MIN_POSITIVE);
    let fits = |t: (f64, f64), ends: f64| {
        t.0 != t.1
            && (on_surface(t.0) - from).length() <= ends
            && (on_surface(t.1) - to).length() <= ends
            && u.curve.as_ref().zip(range3).is_none_or(|(c, r)| {
                // The middle lies on the edge, the quarter point on its first half (which
                // also tells the direction round a closed edge).
                let m = on_surface(0.5 * (t.0 + t.1));
                let q = on_surface(0.75 * t.0 + 0.25 * t.1);
                let (tm, tq) = (c.curve.invert(m), c.curve.invert(q));
                let half = (r.0, 0.5 * (r.0 + r.1));
                (c.curve.eval(tm) - m).length() <= tol
                    && within(&c.curve, tm, r)
                    && within(&c.curve, tq, half)
            })
    };
    // The 3D curve's range first: a shared parametrisation (the usual case) puts the ends on
    // the vertices to rounding; else the vertices inverted onto the PCURVE, whose ends may
    // then miss by its fit error.
    let tight = PCURVE_SHARED * ctx.size.max(f64::MIN_POSITIVE);
    let loose = PCURVE_ENDS * ctx.size.max(f64::MIN_POSITIVE);
    let shared = range3.filter(|&t| fits(t, tight));
    let t = match shared {
        Some(t) => t,
        None => {
            let (lo, hi) = match (pc, range3) {
                (Curve::Nurbs(_), _) => pc.domain(),
                (_, Some((a, b))) => {
                    let w = (b - a).abs().max(f64::MIN_POSITIVE);
                    (a.min(b) - 0.5 * w, a.max(b) + 0.5 * w)
                }
                _ => return None,
            };
            let b = pc.breaks();
            let a = invert_sampled(on_surface, lo, hi, &b, from);
            let z = invert_sampled(on_surface, lo, hi, &b, to);
            // On a closed PCURVE a vertex at its seam may be either end of the domain.
            let closed = (on_surface(lo) - on_surface(hi)).length() <= loose;
            let other = |x: f64| {
                let e = 1e-9 * (hi - lo);
                if !closed {
                    None
                } else if (x - lo).abs() <= e {
                    Some(hi)
                } else if (x - hi).abs() <= e {
                    Some(lo)
                } else {
                    None
                }
            };
            let mut candidates = Vec::with_capacity(4);
            for a in std::iter::once(a).chain(other(a)) {
                for z in std::iter::once(z).chain(other(z)) {
                    candidates.push((a, z));
                }
            }
            candidates.into_iter().find(|&t| fits(t, loose))?
        }
    };
    let samples = ctx.sample(&src, t, (None, None), coarse_count(pc, t), None)?;
    Some(finish(ctx, src, t, samples))
}

/// Splits a piece where it passes through a pole (a meridian over a sphere's pole: its angle
/// jumps by π there), so that the layout sees the pole as a join, where the side the face lies
/// on is chosen (see `layout::orient`). The two parts end at the pole's line; the sliver of
/// parameter between the samples around the pole (2⁻¹⁴ of the range, see `piece`) is dropped.
#[must_use]
pub(crate) fn split_at_poles<'f>(ctx: &Ctx<'_>, p: Piece<'f>) -> Vec<Piece<'f>> {
    let jump = |a: &Sample, b: &Sample| {
        (0..2).find(|&d| match *at(&ctx.periods, d) {
            Some(period) => {
                let (x, y) = if d == 0 {
                    (a.uv.x, b.uv.x)
                } else {
                    (a.uv.y, b.uv.y)
                };
                (x - y).abs() > 0.25 * period
            }
            None => false,
        })
    };
    let at = p
        .samples
        .windows(2)
        .position(|w| matches!(w, [a, b] if jump(a, b).is_some()));
    let (Some(i), false) = (at, matches!(p.src, Source::Segment(..))) else {
        return vec![p];
    };
    let (Some(&a), Some(&b)) = (p.samples.get(i), p.samples.get(i + 1)) else {
        return vec![p];
    };
    let d = jump(&a, &b).unwrap_or(0);
    let o = 1 - d;
    // The pole line the piece passes: the nearest pole in the other parameter.
    let mid = if o == 0 {
        0.5 * (a.uv.x + b.uv.x)
    } else {
        0.5 * (a.uv.y + b.uv.y)
    };
    let pole = ctx
        .poles
        .iter()
        .filter(|q| q.dir == o)
        .map(|q| q.at)
        .min_by(|x, y| (x - mid).abs().total_cmp(&(y - mid).abs()));
    let onto = |mut s: Sample| {
        if let Some(v) = pole {
            s.uv = if o == 0 {
                DVec2::new(v, s.uv.y)
            } else {
                DVec2::new(s.uv.x, v)
            };
        }
        *at_mut(&mut s.free, d) = true;
        s
    };
    let mut first: Vec<Sample> = p.samples.get(..=i).unwrap_or_default().to_vec();
    let mut second: Vec<Sample> = p.samples.get(i + 1..).unwrap_or_default().to_vec();
    if let Some(s) = first.last_mut() {
        *s = onto(*s);
    }
    if let Some(s) = second.first_mut() {
        *s = onto(*s);
    }
    let one = finish(ctx, p.src, (p.t.0, a.t), first);
    let two = finish(ctx, p.src, (b.t, p.t.1), second);
    let mut out = vec![one];
    out.extend(split_at_poles(ctx, two));
    out
}

/// Whether parameter `t` of curve `c` lies on the range `r` (traversal order; modulo the
/// period for a closed curve).
#[must_use]
fn within(c: &Curve, t: f64, r: (f64, f64)) -> bool {
    let slack = 1e-9 * (r.1 - r.0).abs().max(1.0);
    match c.period() {
        Some(p) if r.1 >= r.0 => (t - r.0).rem_euclid(p) <= r.1 - r.0 + slack,
        Some(p) => (r.0 - t).rem_euclid(p) <= r.0 - r.1 + slack,
        None => t >= r.0.min(r.1) - slack && t <= r.0.max(r.1) + slack,
    }
}

/// A piece from its samples, with the isoparametric test: one coordinate constant to
/// [`ISO_TOL`] of its scale and the other monotone.
#[must_use]
pub(crate) fn finish<'f>(
    ctx: &Ctx<'_>,
    src: Source<'f>,
    t: (f64, f64),
    samples: Vec<Sample>,
) -> Piece<'f> {
    let iso = matches!(src, Source::Segment(..)) || (0..2).any(|d| is_iso(ctx, &samples, d));
    Piece {
        src,
        t,
        samples,
        shift: DVec2::ZERO,
        iso,
    }
}

/// Whether coordinate `d` is constant and the other monotone over the samples.
#[must_use]
fn is_iso(ctx: &Ctx<'_>, s: &[Sample], d: usize) -> bool {
    let c = |x: &Sample, k: usize| if k == 0 { x.uv.x } else { x.uv.y };
    let Some(first) = s.first() else { return false };
    let tol = ISO_TOL * *at(&ctx.scale, d);
    if s.iter().any(|x| (c(x, d) - c(first, d)).abs() > tol) {
        return false;
    }
    let o = 1 - d;
    let up = s
        .windows(2)
        .all(|w| matches!(w, [a, b] if c(b, o) >= c(a, o)));
    let down = s
        .windows(2)
        .all(|w| matches!(w, [a, b] if c(b, o) <= c(a, o)));
    up || down
}
