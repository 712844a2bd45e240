//! Loops that wind once around a periodic direction: cut at a window line and closed into
//! regions (see the `layout` module doc, step 2).

use crate::formats::step::map::attrs::at;
use glam::DVec2;

use super::layout::{FaceSide, LoopP, c, move_loop, range, segment, with};
use super::piece::{Ctx, Piece, Sample};

/// Cuts the winding loops (`winds[k] = ±1` in direction `d`, 0 for closed loops) at a window
/// line and closes them into regions. Returns the loops and the window `[w, w + P]`.
pub(crate) fn close<'f>(
    ctx: &Ctx<'_>,
    loops: Vec<LoopP<'f>>,
    winds: &[i64],
    d: usize,
    side: &FaceSide,
) -> Result<(Vec<LoopP<'f>>, [f64; 2]), String> {
    let period = at(&ctx.periods, d).ok_or("winding loop in a direction that is not periodic")?;
    let mut closed = Vec::new();
    let mut winding = Vec::new();
    for (lp, &k) in loops.into_iter().zip(winds) {
        match k {
            0 => closed.push(lp),
            1 | -1 => winding.push((lp, k)),
            _ => return Err(format!("a loop winds {k} times around the surface")),
        }
    }
    let w = window(&closed, &winding, d, period, *at(&side.fixed, d))
        .ok_or("no window line crosses each loop winding around the surface once")?;
    let mut cut = Vec::with_capacity(winding.len());
    for (lp, k) in winding {
        cut.push((cut_at(ctx, lp, d, w, period, k)?, k));
    }
    for lp in &mut closed {
        let r = range(lp, d);
        let m = 0.5 * (r[0] + r[1]);
        let target = w + 0.5 * period;
        move_loop(lp, d, super::piece::near(m, target, Some(period)) - m);
    }
    closed.extend(pair(ctx, cut, d, side)?);
    Ok((closed, [w, w + period]))
}

/// Candidate window lines tried across one period when no simpler candidate fits.
const WINDOW_COMB: usize = 256;

/// Number of crossings of the loop's coarse polygon with the lines `w + kP`.
#[must_use]
fn crossings(lp: &LoopP<'_>, d: usize, w: f64, period: f64) -> usize {
    let mut n = 0;
    for p in &lp.pieces {
        for pair in p.samples.windows(2) {
            let [a, b] = pair else { continue };
            let (x0, x1) = (c(a.uv + p.shift, d), c(b.uv + p.shift, d));
            let (lo, hi) = (x0.min(x1), x0.max(x1));
            let k0 = ((lo - w) / period).floor() as i64;
            let k1 = ((hi - w) / period).ceil() as i64;
            for k in k0..=k1 {
                let l = w + k as f64 * period;
                if (x0 < l && x1 >= l) || (x0 > l && x1 <= l) {
                    n += 1;
                }
            }
        }
    }
    n
}

/// A window line: fixed (a B-spline surface's domain start), or the first candidate (each
/// winding loop's start, the middles of the gaps between closed loops, then a comb of lines
/// across the period) that every winding loop crosses once and no closed loop reaches across.
#[must_use]
fn window(
    closed: &[LoopP<'_>],
    winding: &[(LoopP<'_>, i64)],
    d: usize,
    period: f64,
    fixed: Option<[f64; 2]>,
) -> Option<f64> {
    let mut candidates: Vec<f64> = match fixed {
        Some(f) => vec![f[0]],
        None => winding
            .iter()
            .filter_map(|(lp, _)| lp.pieces.first().map(|p| c(p.start(), d)))
            .collect(),
    };
    if fixed.is_none() {
        let mut spans: Vec<[f64; 2]> = closed.iter().map(|lp| range(lp, d)).collect();
        spans.sort_by(|a, b| a[0].total_cmp(&b[0]));
        for pair in spans.windows(2) {
            if let [a, b] = pair {
                candidates.push(0.5 * (a[1] + b[0]));
            }
        }
        if let (Some(first), Some(last)) = (spans.first(), spans.last()) {
            candidates.push(0.5 * (last[1] + first[0] + period));
        }
        // Loops that turn back on themselves (fluted ends) are crossed once only by some
        // lines: try a comb of them too.
        let start = candidates.first().copied().unwrap_or(0.0);
        candidates
            .extend((1..WINDOW_COMB).map(|k| start + period * (k as f64 / WINDOW_COMB as f64)));
    }
    candidates.into_iter().find(|&w| {
        winding
            .iter()
            .all(|(lp, _)| crossings(lp, d, w, period) == 1)
            && closed.iter().all(|lp| {
                let r = range(lp, d);
                let k = ((r[0] - w) / period).ceil();
                let l = w + k * period;
                !(r[0] < l && l < r[1])
            })
    })
}

/// Splits the loop where it crosses `w + kP`, starts it there and moves it into `[w, w + P]`.
fn cut_at<'f>(
    ctx: &Ctx<'_>,
    lp: LoopP<'f>,
    d: usize,
    w: f64,
    period: f64,
    wind: i64,
) -> Result<LoopP<'f>, String> {
    let outer = lp.outer;
    let mut pieces = lp.pieces;
    let mut at: Option<(usize, usize, f64)> = None;
    'find: for (i, p) in pieces.iter().enumerate() {
        for (j, pair) in p.samples.windows(2).enumerate() {
            let [a, b] = pair else { continue };
            let (x0, x1) = (c(a.uv + p.shift, d), c(b.uv + p.shift, d));
            let (lo, hi) = (x0.min(x1), x0.max(x1));
            let k = ((hi - w) / period).floor();
            let l = w + k * period;
            if (x0 < l && x1 >= l) || (x0 > l && x1 <= l) || (lo < l && l < hi) {
                at = Some((i, j, l));
                break 'find;
            }
        }
    }
    let (i, j, l) = at.ok_or("a winding loop does not cross its window line")?;
    let piece = pieces.get(i).ok_or("cut outside the loop")?.clone();
    let (first, second) = split(ctx, piece, j, d, l);
    let mut rotated: Vec<Piece<'f>> = Vec::with_capacity(pieces.len() + 1);
    rotated.extend(second);
    rotated.extend(pieces.drain(i + 1..));
    let before: Vec<Piece<'f>> = pieces.drain(..i).chain(first).collect();
    for mut p in before {
        p.shift = with(p.shift, d, c(p.shift, d) + wind as f64 * period);
        rotated.push(p);
    }
    let mut out = LoopP {
        pieces: rotated,
        outer,
    };
    let start = if wind > 0 { w } else { w + period };
    move_loop(&mut out, d, start - l);
    Ok(out)
}

/// Splits `p` between samples `j` and `j + 1` where coordinate `d` equals `l` (bisection on
/// the piece's parameter). A crossing at an end keeps the piece whole on that side.
#[must_use]
fn split<'f>(
    ctx: &Ctx<'_>,
    p: Piece<'f>,
    j: usize,
    d: usize,
    l: f64,
) -> (Option<Piece<'f>>, Option<Piece<'f>>) {
    let (Some(a), Some(b)) = (p.samples.get(j).copied(), p.samples.get(j + 1).copied()) else {
        return (Some(p), None);
    };
    let n = p.samples.len();
    let x = |s: &Sample| c(s.uv + p.shift, d);
    if x(&b) == l && j + 2 == n {
        return (Some(p), None);
    }
    if x(&a) == l && j == 0 {
        return (None, Some(p));
    }
    let (mut ta, mut tb) = (a.t, b.t);
    let fa = x(&a) - l;
    for _ in 0..60 {
        let tm = 0.5 * (ta + tb);
        let fm = c(p.uv_at(ctx, tm), d) - l;
        if (fm < 0.0) == (fa < 0.0) {
            ta = tm;
        } else {
            tb = tm;
        }
    }
    let tc = 0.5 * (ta + tb);
    let uv = with(p.uv_at(ctx, tc), d, l) - p.shift;
    let mid = Sample {
        t: tc,
        uv,
        free: [false, false],
    };
    let mut one = p.clone();
    one.samples = p.samples.get(..=j).unwrap_or_default().to_vec();
    one.samples.push(mid);
    one.t = (p.t.0, tc);
    let mut two = p.clone();
    two.samples = vec![mid];
    two.samples
        .extend_from_slice(p.samples.get(j + 1..).unwrap_or_default());
    two.t = (tc, p.t.1);
    if let super::piece::Source::Segment(s, e) = p.src {
        let f = if (p.t.1 - p.t.0) != 0.0 {
            (tc - p.t.0) / (p.t.1 - p.t.0)
        } else {
            0.0
        };
        let m = s + (e - s) * f;
        one.src = super::piece::Source::Segment(s, m);
        one.t = (0.0, 1.0);
        two.src = super::piece::Source::Segment(m, e);
        two.t = (0.0, 1.0);
        one.samples = vec![
            with_t(p.samples.first().copied(), 0.0),
            with_t(Some(mid), 1.0),
        ];
        two.samples = vec![
            with_t(Some(mid), 0.0),
            with_t(p.samples.last().copied(), 1.0),
        ];
    }
    (Some(one), Some(two))
}

/// A sample with its parameter replaced (segments are re-parametrised on `[0, 1]`).
#[must_use]
fn with_t(s: Option<Sample>, t: f64) -> Sample {
    let mut s = s.unwrap_or(Sample {
        t,
        uv: DVec2::NAN,
        free: [false, false],
    });
    s.t = t;
    s
}

/// One cut loop: where it starts across the window (`o`-coordinate), and whether the face lies
/// towards larger `o` from it.
struct Cut<'f> {
    lp: LoopP<'f>,
    at: f64,
    face_above: bool,
}

/// Closes cut loops into regions (see the `layout` module doc).
fn pair<'f>(
    ctx: &Ctx<'_>,
    cut: Vec<(LoopP<'f>, i64)>,
    d: usize,
    side: &FaceSide,
) -> Result<Vec<LoopP<'f>>, String> {
    let o = 1 - d;
    let mut lows = Vec::new();
    let mut highs = Vec::new();
    for (lp, k) in cut {
        let at = lp.pieces.first().map_or(0.0, |p| c(p.start(), o));
        let face_above = (k > 0) == side.left;
        let item = Cut { lp, at, face_above };
        if face_above {
            lows.push(item)
        } else {
            highs.push(item)
        }
    }
    lows.sort_by(|a, b| a.at.total_cmp(&b.at));
    highs.sort_by(|a, b| a.at.total_cmp(&b.at));
    if !side.hints.is_empty() && lows.len() + highs.len() == 1 {
        // A VERTEX_LOOP names the pole: the face lies towards it.
        let hint = side.hints.first().map_or(0.0, |h| c(*h, o));
        for x in lows.iter_mut().chain(highs.iter_mut()) {
            x.face_above = hint > x.at;
        }
        let all: Vec<Cut<'f>> = lows.drain(..).chain(highs.drain(..)).collect();
        for x in all {
            if x.face_above {
                lows.push(x)
            } else {
                highs.push(x)
            }
        }
    }
    let mut out = Vec::new();
    let period_o = *at(&ctx.periods, o);
    while let Some(a) = lows.pop() {
        // The nearest upper boundary above `a` (modulo the period of `o` where it has one).
        let above = |h: &Cut<'_>| match period_o {
            Some(p) => (h.at - a.at).rem_euclid(p),
            None => h.at - a.at,
        };
        let best = highs
            .iter()
            .enumerate()
            .filter(|(_, h)| above(h) > 0.0)
            .min_by(|x, y| above(x.1).total_cmp(&above(y.1)))
            .map(|(i, _)| i);
        match best {
            Some(i) => {
                let mut b = highs.remove(i);
                let by = a.at + above(&b) - b.at;
                move_loop(&mut b.lp, o, by);
                out.push(join(a.lp, b.lp));
            }
            None => out.push(close_alone(ctx, a.lp, d, true, side)?),
        }
    }
    for b in highs {
        out.push(close_alone(ctx, b.lp, d, false, side)?);
    }
    Ok(out)
}

/// Two cut loops running opposite ways, joined by segments along the window's edges.
#[must_use]
fn join<'f>(mut a: LoopP<'f>, b: LoopP<'f>) -> LoopP<'f> {
    let (a0, a1) = ends(&a);
    let (b0, b1) = ends(&b);
    a.pieces.push(segment(a1, b0));
    a.pieces.extend(b.pieces);
    a.pieces.push(segment(b1, a0));
    a.outer |= b.outer;
    a
}

/// First and last point of a loop.
#[must_use]
fn ends(lp: &LoopP<'_>) -> (DVec2, DVec2) {
    let a = lp.pieces.first().map_or(DVec2::NAN, Piece::start);
    let b = lp.pieces.last().map_or(DVec2::NAN, Piece::end);
    (a, b)
}

/// A cut loop with nothing across from it: closed along the nearest pole (or natural limit) on
/// the face's side, or with its own copy one period further where `o` is periodic.
fn close_alone<'f>(
    ctx: &Ctx<'_>,
    mut a: LoopP<'f>,
    d: usize,
    up: bool,
    side: &FaceSide,
) -> Result<LoopP<'f>, String> {
    let o = 1 - d;
    let r = range(&a, o);
    let mut limits: Vec<f64> = ctx
        .poles
        .iter()
        .filter(|p| p.dir == o)
        .map(|p| p.at)
        .collect();
    if let Some(n) = *at(&side.natural, o) {
        limits.extend(n);
    }
    if let Some(f) = *at(&side.fixed, o) {
        limits.extend(f);
    }
    let tol = 1e-9 * *at(&ctx.scale, o);
    let pick = if up {
        limits
            .into_iter()
            .filter(|&x| x >= r[1] - tol)
            .min_by(f64::total_cmp)
    } else {
        limits
            .into_iter()
            .filter(|&x| x <= r[0] + tol)
            .max_by(f64::total_cmp)
    };
    if let Some(at) = pick {
        let (a0, a1) = ends(&a);
        let (p1, p0) = (with(a1, o, at), with(a0, o, at));
        a.pieces.push(segment(a1, p1));
        a.pieces.push(segment(p1, p0));
        a.pieces.push(segment(p0, a0));
        return Ok(a);
    }
    let Some(period) = *at(&ctx.periods, o) else {
        return Err(
            "a loop winds around the surface with nothing bounding the face on one side".into(),
        );
    };
    let mut b = a.clone();
    for p in &mut b.pieces {
        p.reverse();
    }
    b.pieces.reverse();
    move_loop(&mut b, o, if up { period } else { -period });
    Ok(join(a, b))
}
