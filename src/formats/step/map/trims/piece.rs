//! One piece of a trim loop in the surface's (crate) parameters: where it comes from, its
//! parameter range, and a coarse, continuous sampling of it.
//!
//! The coarse samples serve the layout (which 2π copy of each piece to use, where loops wind
//! around) and are the reference for every later evaluation: an angle is always taken as the
//! copy nearest to the coarse samples' interpolation, which they keep within a quarter period
//! of the truth by construction (consecutive samples never differ by more than a quarter period
//! in a periodic direction; where they would, the interval is halved).

use crate::formats::step::map::attrs::{at, at_mut};
use glam::{DVec2, DVec3};

use super::super::curves::Curve;
use super::super::invert::Pole;
use super::super::surface::Surface;

/// Where a piece's points come from.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Source<'f> {
    /// A PCURVE's 2D curve in the file's parameters (`z = 0`).
    Pcurve(&'f Curve),
    /// The edge's 3D curve, inverted onto the surface point by point.
    Edge(&'f Curve),
    /// A straight segment of the parameter plane, `t ∈ [0, 1]` (closing along a seam or pole).
    Segment(DVec2, DVec2),
}

/// One coarse sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Sample {
    pub t: f64,
    pub uv: DVec2,
    /// Per parameter: arbitrary here (a pole); its value was copied from a neighbour.
    pub free: [bool; 2],
}

/// A piece of a loop.
#[derive(Clone, Debug)]
pub(crate) struct Piece<'f> {
    pub src: Source<'f>,
    /// Traversal range (`t.0 > t.1`: backwards).
    pub t: (f64, f64),
    /// Coarse samples from `t.0` to `t.1`, continuous, without `shift`.
    pub samples: Vec<Sample>,
    /// Whole periods added to every point of the piece.
    pub shift: DVec2,
    /// The piece is an isoparametric line: the straight segment between its ends is exact.
    pub iso: bool,
}

/// What evaluating a piece needs of the face.
pub(crate) struct Ctx<'s> {
    pub surf: &'s Surface,
    pub periods: [Option<f64>; 2],
    pub poles: Vec<Pole>,
    /// Diagonal of the face's edge box (file units).
    pub size: f64,
    /// Typical size of each parameter's range (periods, or the face's size for lengths).
    pub scale: [f64; 2],
}

/// Most halvings of a coarse interval before giving up on continuity.
const MAX_REFINE: usize = 14;
/// Most coarse samples per piece.
const MAX_SAMPLES: usize = 4096;
/// Distance from the surface (relative to the face's size) beyond which an edge's point is
/// refused.
const FAR: f64 = 1e-2;
/// Relative distance to a pole line within which a parameter counts as free.
const POLE_TOL: f64 = 1e-9;

/// `x` moved by whole periods to lie nearest `reference`.
#[must_use]
pub(crate) fn near(x: f64, reference: f64, period: Option<f64>) -> f64 {
    match period {
        Some(p) if p > 0.0 => x + p * ((reference - x) / p).round(),
        _ => x,
    }
}

impl Ctx<'_> {
    /// Which parameters are free at `uv` because it lies on a pole line.
    #[must_use]
    fn pole_free(&self, uv: DVec2, mut free: [bool; 2]) -> [bool; 2] {
        for pole in &self.poles {
            let (d, o) = (pole.dir.min(1), 1 - pole.dir.min(1));
            let x = if d == 0 { uv.x } else { uv.y };
            let s = if d == 0 { self.scale[0] } else { self.scale[1] };
            let on = match *at(&self.periods, d) {
                Some(p) => (x - near(pole.at, x, Some(p))).abs() <= POLE_TOL * s,
                None => (x - pole.at).abs() <= POLE_TOL * s,
            };
            if on {
                *at_mut(&mut free, o) = true;
            }
        }
        free
    }

    /// The raw (not unwrapped) parameters of `src` at `t`; `at_point` replaces the curve's
    /// point (a vertex) for 3D sources.
    #[must_use]
    pub(crate) fn raw(
        &self,
        src: &Source<'_>,
        t: f64,
        at_point: Option<DVec3>,
        hint: Option<DVec2>,
    ) -> Option<(DVec2, [bool; 2])> {
        match src {
            Source::Segment(a, b) => Some((*a + (*b - *a) * t, [false, false])),
            Source::Pcurve(c) => {
                let q = c.eval(t);
                let uv = DVec2::new(self.surf.pre[0].apply(q.x), self.surf.pre[1].apply(q.y));
                uv.is_finite()
                    .then(|| (uv, self.pole_free(uv, [false, false])))
            }
            Source::Edge(c) => {
                let p = at_point.unwrap_or_else(|| c.eval(t));
                let inv = self.surf.invert(p, hint)?;
                // An edge far from its face's surface is a broken file, not a tolerance.
                if inv.distance > FAR * self.size {
                    return None;
                }
                Some((inv.uv, self.pole_free(inv.uv, inv.free)))
            }
        }
    }

    /// The coarse sampling of `src` over `t0 → t1` (see the module doc); `ends` are the points
    /// that replace the curve's at the two ends (the vertices). `n` is the initial count;
    /// `first_hint` is a parameter pair near the start (the previous piece's end, the same
    /// vertex), where a B-spline surface's inversion starts.
    #[must_use]
    pub(crate) fn sample(
        &self,
        src: &Source<'_>,
        (t0, t1): (f64, f64),
        ends: (Option<DVec3>, Option<DVec3>),
        n: usize,
        first_hint: Option<DVec2>,
    ) -> Option<Vec<Sample>> {
        let n = n.clamp(1, MAX_SAMPLES);
        let mut out: Vec<Sample> = Vec::with_capacity(n + 1);
        for i in 0..=n {
            let t = t0 + (t1 - t0) * (i as f64 / n as f64);
            let at = match i {
                0 => ends.0,
                _ if i == n => ends.1,
                _ => None,
            };
            let hint = out.last().map(|s| s.uv).or(first_hint);
            let (uv, free) = self.raw(src, t, at, hint)?;
            let uv = self.unwrap_after(uv, free, &out);
            out.push(Sample { t, uv, free });
        }
        self.refine(src, &mut out)?;
        fill_free(&mut out);
        Some(out)
    }

    /// `uv` moved by periods next to the last sample not free in each direction.
    #[must_use]
    fn unwrap_after(&self, mut uv: DVec2, free: [bool; 2], before: &[Sample]) -> DVec2 {
        for d in 0..2 {
            if *at(&free, d) {
                continue;
            }
            if let Some(prev) = before.iter().rev().find(|s| !*at(&s.free, d)) {
                let (x, r) = if d == 0 {
                    (uv.x, prev.uv.x)
                } else {
                    (uv.y, prev.uv.y)
                };
                let moved = near(x, r, *at(&self.periods, d));
                if d == 0 { uv.x = moved } else { uv.y = moved }
            }
        }
        uv
    }

    /// Halves coarse intervals that jump by more than a quarter period.
    #[must_use]
    fn refine(&self, src: &Source<'_>, s: &mut Vec<Sample>) -> Option<()> {
        let mut i = 1;
        let mut inserted = 0usize;
        while i < s.len() {
            let (a, b) = (*s.get(i - 1)?, *s.get(i)?);
            let jumps = (0..2).any(|d| match *at(&self.periods, d) {
                Some(p) if !*at(&a.free, d) && !*at(&b.free, d) => {
                    let (x, y) = if d == 0 {
                        (a.uv.x, b.uv.x)
                    } else {
                        (a.uv.y, b.uv.y)
                    };
                    (x - y).abs() > 0.25 * p
                }
                _ => false,
            });
            let depth_ok = (b.t - a.t).abs()
                > (s.last()?.t - s.first()?.t).abs() / f64::from(1u32 << MAX_REFINE);
            if jumps && depth_ok && s.len() < MAX_SAMPLES {
                let t = 0.5 * (a.t + b.t);
                let (uv, free) = self.raw(src, t, None, Some(a.uv))?;
                let uv = self.unwrap_after(uv, free, s.get(..i)?);
                s.insert(i, Sample { t, uv, free });
                inserted += 1;
                // Re-unwrap the rest of the piece against the new sample.
                let tail: Vec<Sample> = s.get(i + 1..)?.to_vec();
                for (k, mut x) in tail.into_iter().enumerate() {
                    x.uv = self.unwrap_after(x.uv, x.free, s.get(..i + 1 + k)?);
                    *s.get_mut(i + 1 + k)? = x;
                }
                if inserted > MAX_SAMPLES {
                    return None;
                }
            } else {
                i += 1;
            }
        }
        Some(())
    }
}

/// Free coordinates take the value of the nearest sample where they are not free (the limit
/// along the piece), so a piece ending at a pole ends at the pole's point of its own meridian.
fn fill_free(s: &mut [Sample]) {
    for d in 0..2 {
        let values: Vec<Option<f64>> = s
            .iter()
            .map(|x| (!*at(&x.free, d)).then_some(if d == 0 { x.uv.x } else { x.uv.y }))
            .collect();
        for (i, x) in s.iter_mut().enumerate() {
            if !*at(&x.free, d) {
                continue;
            }
            let before = values
                .get(..i)
                .and_then(|v| v.iter().rev().flatten().next());
            let after = values.get(i + 1..).and_then(|v| v.iter().flatten().next());
            let pick = match (before, after) {
                (Some(&b), _) if i + 1 == values.len() => Some(b),
                (_, Some(&a)) => Some(a),
                (Some(&b), None) => Some(b),
                (None, None) => None,
            };
            if let Some(v) = pick {
                if d == 0 { x.uv.x = v } else { x.uv.y = v }
            }
        }
    }
}

impl Piece<'_> {
    /// First and last point, shifted.
    #[must_use]
    pub(crate) fn start(&self) -> DVec2 {
        self.samples.first().map_or(DVec2::NAN, |s| s.uv) + self.shift
    }

    #[must_use]
    pub(crate) fn end(&self) -> DVec2 {
        self.samples.last().map_or(DVec2::NAN, |s| s.uv) + self.shift
    }

    /// Whether the first / last point is free in direction `d`.
    #[must_use]
    pub(crate) fn start_free(&self, d: usize) -> bool {
        self.samples.first().is_some_and(|s| *at(&s.free, d))
    }

    #[must_use]
    pub(crate) fn end_free(&self, d: usize) -> bool {
        self.samples.last().is_some_and(|s| *at(&s.free, d))
    }

    /// The piece traversed the other way.
    pub(crate) fn reverse(&mut self) {
        self.t = (self.t.1, self.t.0);
        self.samples.reverse();
    }

    /// The reference (interpolated coarse samples, unshifted) at `t`.
    #[must_use]
    pub(crate) fn reference(&self, t: f64) -> DVec2 {
        let s = &self.samples;
        let up = self.t.1 >= self.t.0;
        let k = s.partition_point(|x| if up { x.t < t } else { x.t > t });
        match (k.checked_sub(1).and_then(|i| s.get(i)), s.get(k)) {
            (Some(a), Some(b)) if a.t != b.t => a.uv + (b.uv - a.uv) * ((t - a.t) / (b.t - a.t)),
            (_, Some(b)) => b.uv,
            (Some(a), None) => a.uv,
            (None, None) => DVec2::NAN,
        }
    }

    /// The point at `t` (shifted), unwrapped next to the coarse reference; a free coordinate
    /// (at a pole) is taken from a point slightly inside the piece.
    #[must_use]
    pub(crate) fn uv_at(&self, ctx: &Ctx<'_>, t: f64) -> DVec2 {
        self.uv_near(ctx, t, self.reference(t) + self.shift)
    }

    /// [`Piece::uv_at`] next to `near_uv` (shifted), a nearby point of the piece: the start of
    /// a B-spline surface's Newton iteration and the copy chosen for each angle.
    #[must_use]
    pub(crate) fn uv_near(&self, ctx: &Ctx<'_>, t: f64, near_uv: DVec2) -> DVec2 {
        let reference = near_uv - self.shift;
        let Some((mut uv, free)) = ctx.raw(&self.src, t, None, Some(reference)) else {
            return DVec2::NAN;
        };
        for d in 0..2 {
            let r = if d == 0 { reference.x } else { reference.y };
            let x = if *at(&free, d) {
                let span = self.t.1 - self.t.0;
                let inward = if (t - self.t.0).abs() < (t - self.t.1).abs() {
                    1e-6
                } else {
                    -1e-6
                };
                ctx.raw(&self.src, t + inward * span, None, Some(reference))
                    .map_or(r, |(q, _)| if d == 0 { q.x } else { q.y })
            } else if d == 0 {
                uv.x
            } else {
                uv.y
            };
            let x = near(x, r, *at(&ctx.periods, d));
            if d == 0 { uv.x = x } else { uv.y = x }
        }
        uv + self.shift
    }
}
