//! How far a structural edit moves a shape. Knot insertion and degree elevation promise the
//! same shape; ERBS refinement promises it outside the refined interval and at the knots. Before
//! such an edit is applied, its result is compared with the shape it replaces ([`shape_kept`],
//! [`shape_change`]) at parameters where the promise must hold ([`span_probes`]: d+1 per span),
//! and src/model refuses an edit that would move the shape by more than [`SHAPE_TOLERANCE`] of
//! its size.
//!
//! The check runs on every structural edit, so it is kept cheap: a tensor surface refined in
//! one direction is compared line by line along it (every line of the net, no sum across),
//! which bounds the comparison of the surfaces; the exact comparison runs only for a result
//! that bound cannot accept (docs/performance.md, structural edits).
//!
//! Positions only: a refined net carries the shape's derivatives as accurately as its spans
//! allow (docs/scene-format.md), and that is a property of the representation, not a move.

use super::basis::basis_funs_into;
use super::bspline::BSplineCurve;
use super::erbs::{ErbsCurve, ErbsKnots, ErbsSurface, LocalCurve, LocalPatch};
use super::knots::KnotVector;
use super::point::nan_max;
use super::surface::TensorSurface;
use glam::{DVec3, DVec4};
use std::borrow::Cow;
use std::ops::Range;

/// How far a structural edit may move a shape, as a fraction of its size: far above the rounding
/// of a stable refinement (about 1e-15 of the size), far below anything visible.
pub const SHAPE_TOLERANCE: f64 = 1e-9;

/// Rounding of the coordinates themselves, relative to their magnitude: a net far from the
/// origin compared with its size is refined to the last bits of its coordinates, not of its
/// size, so that much movement is always allowed.
const COORDINATE_ROUNDING: f64 = 1e3 * f64::EPSILON;

/// The largest distance between an old and a new shape at the compared parameters, the old
/// control net's size (bounding-box diagonal) and its largest coordinate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShapeChange {
    pub moved: f64,
    pub size: f64,
    pub magnitude: f64,
}

impl ShapeChange {
    /// The largest movement allowed: [`SHAPE_TOLERANCE`] of the size, or the rounding of the
    /// coordinates where that is larger.
    #[must_use]
    pub fn tolerance(&self) -> f64 {
        (SHAPE_TOLERANCE * self.size).max(COORDINATE_ROUNDING * self.magnitude)
    }

    /// The larger movement of two comparisons of the same shape.
    #[must_use]
    pub fn worse(self, other: ShapeChange) -> ShapeChange {
        ShapeChange {
            moved: nan_max(self.moved, other.moved),
            ..self
        }
    }

    /// Moved by at most [`ShapeChange::tolerance`]; a NaN anywhere counts as moved.
    #[must_use]
    pub fn is_kept(&self) -> bool {
        self.moved <= self.tolerance()
    }
}

/// A shape that structural edits compare: how far it lies from another shape of its type at
/// given parameters, and its control points (for its size).
pub trait Shape {
    /// Where positions are compared: parameters (curves) or a grid of them (surfaces).
    type Probes: ?Sized;

    /// The largest distance between this shape's and `other`'s positions at `at`; NaN when a
    /// position of either is NaN there.
    fn distance(&self, other: &Self, at: &Self::Probes) -> f64;

    /// At least [`Shape::distance`] (NaN where that is NaN), where a bound is cheaper to compute
    /// than the distance itself: enough to accept a change far below the tolerance.
    fn distance_bound(&self, other: &Self, at: &Self::Probes) -> f64 {
        self.distance(other, at)
    }

    /// Calls `f` on every control net (at any depth, for ERBS locals).
    fn each_control_net(&self, f: &mut dyn FnMut(&[DVec3]));
}

/// How far `new` lies from `old` at `at`, against the size of `old`'s control net.
#[must_use]
pub fn shape_change<S: Shape + ?Sized>(old: &S, new: &S, at: &S::Probes) -> ShapeChange {
    let (size, magnitude) = net_extent(old);
    ShapeChange {
        moved: old.distance(new, at),
        size,
        magnitude,
    }
}

/// Whether `new` keeps `old`'s shape at `at` ([`ShapeChange::is_kept`]), with the
/// [`ShapeChange`] when it does not: the check every structural edit runs before it is
/// applied. A refinement that keeps the shape moves it by rounding, orders of magnitude below
/// the tolerance, so a bound of the distance ([`Shape::distance_bound`]) against the size of a
/// few control points (a lower bound of the net's size) decides it; the distance itself and
/// the whole net are measured only for a change that may be refused.
pub fn shape_kept<S: Shape + ?Sized>(old: &S, new: &S, at: &S::Probes) -> Result<(), ShapeChange> {
    if old.distance_bound(new, at) <= SHAPE_TOLERANCE * sampled_size(old) {
        return Ok(());
    }
    let change = shape_change(old, new, at);
    if change.is_kept() {
        Ok(())
    } else {
        Err(change)
    }
}

/// A bounding box grown point by point.
struct Bounds {
    lo: DVec3,
    hi: DVec3,
}

impl Bounds {
    fn new() -> Self {
        Self {
            lo: DVec3::INFINITY,
            hi: DVec3::NEG_INFINITY,
        }
    }

    fn add(&mut self, p: DVec3) {
        self.lo = self.lo.min(p);
        self.hi = self.hi.max(p);
    }

    /// The diagonal; 0 for an empty box.
    fn diagonal(&self) -> f64 {
        if self.lo.cmple(self.hi).all() {
            (self.hi - self.lo).length()
        } else {
            0.0
        }
    }
}

/// The size (bounding-box diagonal) of every control net together, and its largest
/// coordinate (NaN when a net holds a NaN).
fn net_extent<S: Shape + ?Sized>(s: &S) -> (f64, f64) {
    let mut bounds = Bounds::new();
    let mut magnitude = 0.0;
    s.each_control_net(&mut |net| {
        net.iter().for_each(|&p| bounds.add(p));
        let nan = net.iter().any(|p| p.is_nan());
        magnitude = nan_max(
            magnitude,
            if nan {
                f64::NAN
            } else {
                bounds.lo.abs().max(bounds.hi.abs()).max_element()
            },
        );
    });
    (bounds.diagonal(), magnitude)
}

/// How many points of each control net [`sampled_size`] reads (besides the last), at most.
const SIZE_SAMPLE: usize = 16;

/// The size of every k-th point and the last of each control net: at most the nets' size
/// (a model's nets are finite), since the bounding box of some of the points lies inside that
/// of all.
fn sampled_size<S: Shape + ?Sized>(s: &S) -> f64 {
    let mut bounds = Bounds::new();
    s.each_control_net(&mut |net| {
        let step = (net.len() / SIZE_SAMPLE).max(1);
        net.iter()
            .step_by(step)
            .chain(net.last())
            .for_each(|&p| bounds.add(p));
    });
    bounds.diagonal()
}

/// The largest distance over pairs of positions. f64::max drops a NaN, so a NaN position is
/// looked for apart, where a distance came out NaN (a NaN or two infinities).
#[derive(Default)]
struct Farthest {
    squared: f64,
    nan: bool,
}

impl Farthest {
    fn add(&mut self, p: DVec3, q: DVec3) {
        let d = p.distance_squared(q);
        if d.is_nan() {
            self.nan |= p.is_nan() || q.is_nan();
        } else {
            self.squared = self.squared.max(d);
        }
    }

    fn distance(&self) -> f64 {
        if self.nan {
            f64::NAN
        } else {
            self.squared.sqrt()
        }
    }
}

/// The largest distance between the two positions of each pair.
fn farthest(pairs: impl Iterator<Item = (DVec3, DVec3)>) -> f64 {
    let mut far = Farthest::default();
    pairs.for_each(|(p, q)| far.add(p, q));
    far.distance()
}

/// d+1 parameters inside each non-empty span of `knots` within [a, b] (the midpoints of d+1
/// equal parts): two polynomials of degree ≤ d that agree there are equal on the span.
#[must_use]
pub fn span_probes(knots: &[f64], degree: usize, (a, b): (f64, f64)) -> Vec<f64> {
    let per = degree + 1;
    let mut out = Vec::new();
    for w in knots.windows(2) {
        let (lo, hi) = (w[0].max(a), w[1].min(b));
        if lo < hi {
            out.extend((0..per).map(|i| lo + (hi - lo) * (i as f64 + 0.5) / per as f64));
        }
    }
    out
}

/// Where a knot insertion at `t` can change the shape, within the domain `(a, b)`: the support
/// [u_{k−d}, u_{k+d+1}] of the basis functions of the span k holding t, the only ones
/// CurveKnotIns recombines; elsewhere the refined net copies the old points.
#[must_use]
pub fn insertion_window(
    knots: &KnotVector,
    degree: usize,
    t: f64,
    (a, b): (f64, f64),
) -> (f64, f64) {
    let n = knots.len() - degree - 1;
    let k = knots.find_span(degree, n, t);
    (knots[k - degree].max(a), knots[k + degree + 1].min(b))
}

/// The Greville abscissae (u_{i+1} + … + u_{i+d}) / d of n points, held inside [a, b]: at them
/// the d-th degree B-splines of a clamped vector without jumps are independent (Schoenberg and
/// Whitney), so a surface compared there along an unrefined direction is compared on every
/// line of its net. Degree 0 takes the midpoint of each span.
#[must_use]
pub fn greville(knots: &[f64], degree: usize, n: usize, (a, b): (f64, f64)) -> Vec<f64> {
    if degree == 0 {
        return span_probes(knots, 0, (a, b));
    }
    (0..n)
        .map(|i| {
            let mean = knots[i + 1..=i + degree].iter().sum::<f64>() / degree as f64;
            mean.clamp(a, b)
        })
        .collect()
}

/// Where an ERBS direction refined inside interval `changed` keeps its shape: the knots around
/// it and `per` parameters inside each neighbouring interval, where the two restricted locals
/// blend with unchanged ones; with `None`, every knot and every interval (a direction that was
/// not refined). Held to the domain window. An ERBS blend is no polynomial, so these are
/// samples, not a proof: they are where a wrong restriction or placement of a local shows.
#[must_use]
pub fn erbs_probes(knots: &ErbsKnots, per: usize, changed: Option<usize>) -> Vec<f64> {
    let count = knots.intervals();
    let intervals: Vec<usize> = match changed {
        None => (0..count).collect(),
        Some(i) if knots.is_closed() => vec![(i + count - 1) % count, (i + 1) % count],
        Some(i) => [i.checked_sub(1), Some(i + 1).filter(|&j| j < count)]
            .into_iter()
            .flatten()
            .collect(),
    };
    let (a, b) = knots.domain();
    let mut out = Vec::new();
    for i in intervals {
        let (lo, hi) = knots.interval(i);
        out.extend([lo, hi].into_iter().filter(|t| (a..=b).contains(t)));
        if per > 0 {
            out.extend(span_probes(&[lo, hi], per - 1, (a, b)));
        }
    }
    // Neighbouring intervals share their knots.
    out.sort_by(f64::total_cmp);
    out.dedup();
    out
}

/// The knots (centres) of an ERBS direction inside its domain window: where an ERBS built from
/// a local interpolates it.
#[must_use]
pub fn erbs_knot_probes(knots: &ErbsKnots) -> Vec<f64> {
    let (a, b) = knots.domain();
    (0..=knots.intervals())
        .map(|i| knots.centre(i))
        .filter(|t| (a..=b).contains(t))
        .collect()
}

/// A B-spline curve's positions at parameters: BasisFuns once per parameter into one buffer,
/// then the d+1 points of its span (homogeneous for a rational curve).
struct CurveProbe<'a> {
    curve: &'a BSplineCurve,
    basis: Vec<f64>,
}

impl<'a> CurveProbe<'a> {
    fn new(curve: &'a BSplineCurve) -> Self {
        Self {
            curve,
            basis: vec![0.0; curve.degree() + 1],
        }
    }

    fn at(&mut self, t: f64) -> DVec3 {
        let c = self.curve;
        let (d, n) = (c.degree(), c.points().len());
        let (a, b) = c.domain();
        let t = t.clamp(a, b);
        let span = c.knots().find_span(d, n, t);
        basis_funs_into(c.knots(), d, span, t, &mut self.basis);
        let first = span - d;
        let points = &c.points()[first..=span];
        match c.weights() {
            None => points.iter().zip(&self.basis).map(|(&p, &w)| p * w).sum(),
            Some(ws) => {
                let h: DVec4 = points
                    .iter()
                    .zip(&ws[first..=span])
                    .zip(&self.basis)
                    .map(|((&p, &h), &w)| (p * h).extend(h) * w)
                    .sum();
                h.truncate() / h.w
            }
        }
    }
}

impl Shape for BSplineCurve {
    type Probes = [f64];

    fn distance(&self, other: &Self, at: &[f64]) -> f64 {
        let (mut a, mut b) = (CurveProbe::new(self), CurveProbe::new(other));
        farthest(at.iter().map(|&t| (a.at(t), b.at(t))))
    }

    fn each_control_net(&self, f: &mut dyn FnMut(&[DVec3])) {
        f(self.points());
    }
}

/// One direction's B-spline basis at each probe parameter: the first control point of its
/// span and the d+1 non-vanishing functions (BasisFuns once per parameter, kept flat).
struct ProbeBasis {
    first: Vec<usize>,
    values: Vec<f64>,
    per: usize,
}

impl ProbeBasis {
    fn new(s: &TensorSurface, dir: usize, at: &[f64]) -> Self {
        let (d, n, knots) = (s.degree()[dir], s.count()[dir], &s.knots()[dir]);
        let (a, b) = s.domain()[dir];
        let per = d + 1;
        let mut values = vec![0.0; at.len() * per];
        let first = at
            .iter()
            .zip(values.chunks_exact_mut(per))
            .map(|(&t, out)| {
                let t = t.clamp(a, b);
                let span = knots.find_span(d, n, t);
                basis_funs_into(knots, d, span, t, out);
                span - d
            })
            .collect();
        Self { first, values, per }
    }

    fn len(&self) -> usize {
        self.first.len()
    }

    /// The first control point and the basis functions at the k-th parameter.
    fn get(&self, k: usize) -> (usize, &[f64]) {
        (
            self.first[k],
            &self.values[k * self.per..(k + 1) * self.per],
        )
    }

    /// The control points some parameter reaches (empty without parameters).
    fn reach(&self) -> Range<usize> {
        let lo = self.first.iter().copied().min().unwrap_or(0);
        let hi = self.first.iter().copied().max().map_or(0, |f| f + self.per);
        lo..hi
    }
}

/// Whether two surfaces have one basis in direction `dir` (degree, count and knots).
fn same_basis(a: &TensorSurface, b: &TensorSurface, dir: usize) -> bool {
    a.degree()[dir] == b.degree()[dir]
        && a.count()[dir] == b.count()[dir]
        && a.knots()[dir] == b.knots()[dir]
}

/// S(u, v) over a grid `us × vs`, one u at a time, by the tensor structure: each row of the
/// net is combined for every v once (kept in a ring of d_u + 1 rows, which is all one u
/// needs), then d_u + 1 such rows for each u. Sums are homogeneous (x·w, y·w, z·w, w); a
/// polynomial net's w is the partition of unity and its positions need no division.
struct GridRows<'a> {
    surface: &'a TensorSurface,
    bu: &'a ProbeBasis,
    bv: &'a ProbeBasis,
    /// Row i of the net combined for every v, in slot i mod (d_u + 1).
    ring: Vec<DVec4>,
    ring_rows: Vec<Option<usize>>,
    /// The current u's sums.
    acc: Vec<DVec4>,
}

impl<'a> GridRows<'a> {
    fn new(surface: &'a TensorSurface, bu: &'a ProbeBasis, bv: &'a ProbeBasis) -> Self {
        let slots = surface.degree()[0] + 1;
        Self {
            surface,
            bu,
            bv,
            ring: vec![DVec4::ZERO; slots * bv.len()],
            ring_rows: vec![None; slots],
            acc: vec![DVec4::ZERO; bv.len()],
        }
    }

    /// Makes sure row i of the net, combined for every v, is in its ring slot.
    fn combine_row(&mut self, i: usize) {
        let slot = i % self.ring_rows.len();
        if self.ring_rows[slot] == Some(i) {
            return;
        }
        let (s, bv, m) = (self.surface, self.bv, self.acc.len());
        let start = i * s.count()[1];
        let ring = &mut self.ring[slot * m..(slot + 1) * m];
        match s.weights() {
            None => {
                for (j, out) in ring.iter_mut().enumerate() {
                    let (first, n) = bv.get(j);
                    let net = &s.points()[start + first..];
                    *out = net.iter().zip(n).map(|(&p, &w)| p.extend(1.0) * w).sum();
                }
            }
            Some(ws) => {
                for (j, out) in ring.iter_mut().enumerate() {
                    let (first, n) = bv.get(j);
                    let k = start + first;
                    let net = s.points()[k..].iter().zip(&ws[k..]);
                    *out = net.zip(n).map(|((&p, &h), &w)| (p * h).extend(h) * w).sum();
                }
            }
        }
        self.ring_rows[slot] = Some(i);
    }

    /// The homogeneous sums at the k-th u.
    fn row(&mut self, k: usize) -> &[DVec4] {
        let (first, n) = self.bu.get(k);
        for i in first..first + n.len() {
            self.combine_row(i);
        }
        let (slots, m) = (self.ring_rows.len(), self.acc.len());
        self.acc.fill(DVec4::ZERO);
        for (i, &w) in (first..).zip(n) {
            let slot = i % slots;
            let ring = &self.ring[slot * m..(slot + 1) * m];
            for (a, &r) in self.acc.iter_mut().zip(ring) {
                *a += r * w;
            }
        }
        &self.acc
    }
}

/// The position of homogeneous sums.
fn project(h: DVec4, rational: bool) -> DVec3 {
    if rational {
        h.truncate() / h.w
    } else {
        h.truncate()
    }
}

/// The lines of a net along direction `dir` (the net's columns for u, its rows for v) that
/// parameters reach, each laid out across the other direction: the net's own rows for u, a
/// copy of the reached columns for v.
struct Lines<'a> {
    points: Cow<'a, [DVec3]>,
    first: usize,
    width: usize,
}

impl<'a> Lines<'a> {
    fn new(s: &'a TensorSurface, dir: usize, reach: Range<usize>) -> Self {
        let [nu, nv] = s.count();
        let points = if dir == 0 {
            Cow::Borrowed(&s.points()[reach.start * nv..reach.end * nv])
        } else {
            let net = s.points();
            let mut block = Vec::with_capacity(reach.len() * nu);
            for j in reach.clone() {
                block.extend(net[j..].iter().step_by(nv).take(nu));
            }
            Cow::Owned(block)
        };
        Self {
            points,
            first: reach.start,
            width: [nv, nu][dir],
        }
    }

    fn line(&self, i: usize) -> &[DVec3] {
        let start = (i - self.first) * self.width;
        &self.points[start..start + self.width]
    }
}

/// Points combined per pass of [`add_group`]: their coordinates fill three vector registers
/// of eight lanes.
const CHUNK: usize = 8;

/// Most parameters compared in one pass of [`add_group`].
const GROUP: usize = 6;

/// Adds, for each of the `G` parameters from `k` on (which share their span in both nets),
/// the squares of (new − old) line by line, coordinate by coordinate, to `squares`. One pass
/// over the lines of the span: each chunk of a line is read once for every parameter, and the
/// sums stay in registers.
fn add_group<const G: usize>(
    [old, new]: [(&Lines<'_>, &ProbeBasis); 2],
    k: usize,
    squares: &mut [f64; 3 * CHUNK],
) {
    let mut terms: Vec<(&[DVec3], [f64; G])> = Vec::new();
    for ((lines, basis), sign) in [(new, 1.0), (old, -1.0)] {
        let (first, _) = basis.get(k);
        for l in 0..basis.per {
            let w = std::array::from_fn(|g| sign * basis.get(k + g).1[l]);
            terms.push((lines.line(first + l), w));
        }
    }
    let width = old.0.width;
    let mut lanes = *squares;
    let whole = width - width % CHUNK;
    for x in (0..whole).step_by(CHUNK) {
        let mut acc = [[0.0; 3 * CHUNK]; G];
        for (line, w) in &terms {
            let mut coordinates = [0.0; 3 * CHUNK];
            for (c, p) in coordinates.chunks_exact_mut(3).zip(&line[x..x + CHUNK]) {
                c.copy_from_slice(&p.to_array());
            }
            for (acc, &w) in acc.iter_mut().zip(w) {
                for (a, &c) in acc.iter_mut().zip(&coordinates) {
                    *a += c * w;
                }
            }
        }
        for acc in acc {
            for (s, a) in lanes.iter_mut().zip(acc) {
                *s += a * a;
            }
        }
    }
    for x in whole..width {
        for g in 0..G {
            let a: DVec3 = terms.iter().map(|(line, w)| line[x] * w[g]).sum();
            lanes[0] += a.length_squared();
        }
    }
    *squares = lanes;
}

/// A bound of the grid distance between two polynomial surfaces with one basis across
/// direction `dir`: the root of the sum of squared distances between their lines along `dir`
/// at `at` (every line of both nets). Across `dir` a position is a convex combination of the
/// lines (B-splines are a partition of unity), so it moves by at most the farthest line, at
/// any parameter across. A NaN or an infinity anywhere gives a NaN.
fn lines_bound(old: &TensorSurface, new: &TensorSurface, dir: usize, at: &[f64]) -> f64 {
    let (bo, bn) = (ProbeBasis::new(old, dir, at), ProbeBasis::new(new, dir, at));
    let (lo, ln) = (
        Lines::new(old, dir, bo.reach()),
        Lines::new(new, dir, bn.reach()),
    );
    let nets = [(&lo, &bo), (&ln, &bn)];
    let mut squares = [0.0; 3 * CHUNK];
    let mut k = 0;
    while k < at.len() {
        let same = |j: usize| bo.first[j] == bo.first[k] && bn.first[j] == bn.first[k];
        let g = (k..at.len().min(k + GROUP))
            .take_while(|&j| same(j))
            .count();
        match g {
            1 => add_group::<1>(nets, k, &mut squares),
            2 => add_group::<2>(nets, k, &mut squares),
            3 => add_group::<3>(nets, k, &mut squares),
            4 => add_group::<4>(nets, k, &mut squares),
            5 => add_group::<5>(nets, k, &mut squares),
            _ => add_group::<GROUP>(nets, k, &mut squares),
        }
        k += g;
    }
    squares.iter().sum::<f64>().sqrt()
}

impl Shape for TensorSurface {
    /// The grid `us × vs`.
    type Probes = [Vec<f64>; 2];

    fn distance(&self, other: &Self, at: &[Vec<f64>; 2]) -> f64 {
        let [ou, ov] = [0, 1].map(|dir| ProbeBasis::new(self, dir, &at[dir]));
        // A direction an edit did not refine has one basis in both: computed once.
        let [tu, tv] = [0, 1].map(|dir| {
            (!same_basis(self, other, dir)).then(|| ProbeBasis::new(other, dir, &at[dir]))
        });
        let mut a = GridRows::new(self, &ou, &ov);
        let mut b = GridRows::new(
            other,
            tu.as_ref().unwrap_or(&ou),
            tv.as_ref().unwrap_or(&ov),
        );
        let (ra, rb) = (self.is_rational(), other.is_rational());
        let mut far = Farthest::default();
        for k in 0..ou.len() {
            for (&p, &q) in a.row(k).iter().zip(b.row(k)) {
                far.add(project(p, ra), project(q, rb));
            }
        }
        far.distance()
    }

    /// Polynomial surfaces refined in at most one direction: their lines along it (see
    /// `lines_bound`), without combining across.
    fn distance_bound(&self, other: &Self, at: &[Vec<f64>; 2]) -> f64 {
        let refined: Vec<usize> = (0..2).filter(|&d| !same_basis(self, other, d)).collect();
        match refined[..] {
            _ if self.is_rational() || other.is_rational() => self.distance(other, at),
            [] => lines_bound(self, other, 0, &at[0]),
            [dir] => lines_bound(self, other, dir, &at[dir]),
            _ => self.distance(other, at),
        }
    }

    fn each_control_net(&self, f: &mut dyn FnMut(&[DVec3])) {
        f(self.points());
    }
}

impl Shape for LocalCurve {
    type Probes = [f64];

    fn distance(&self, other: &Self, at: &[f64]) -> f64 {
        farthest(at.iter().map(|&t| (self.eval(t), other.eval(t))))
    }

    fn each_control_net(&self, f: &mut dyn FnMut(&[DVec3])) {
        match self {
            LocalCurve::Spline { curve, .. } => curve.each_control_net(f),
            LocalCurve::Erbs(e) => e.each_control_net(f),
        }
    }
}

impl Shape for ErbsCurve {
    type Probes = [f64];

    fn distance(&self, other: &Self, at: &[f64]) -> f64 {
        farthest(at.iter().map(|&t| (self.eval(t), other.eval(t))))
    }

    fn each_control_net(&self, f: &mut dyn FnMut(&[DVec3])) {
        for l in self.local_curves() {
            l.each_control_net(f);
        }
    }
}

/// Every (u, v) of a grid `us × vs`, u by u.
fn grid_points([us, vs]: &[Vec<f64>; 2]) -> impl Iterator<Item = (f64, f64)> + '_ {
    us.iter()
        .flat_map(move |&u| vs.iter().map(move |&v| (u, v)))
}

impl Shape for LocalPatch {
    type Probes = [Vec<f64>; 2];

    fn distance(&self, other: &Self, at: &[Vec<f64>; 2]) -> f64 {
        farthest(grid_points(at).map(|(u, v)| (self.eval(u, v), other.eval(u, v))))
    }

    fn each_control_net(&self, f: &mut dyn FnMut(&[DVec3])) {
        match self {
            LocalPatch::Spline { surface, .. } => surface.each_control_net(f),
            LocalPatch::Erbs(e) => e.each_control_net(f),
        }
    }
}

impl Shape for ErbsSurface {
    type Probes = [Vec<f64>; 2];

    fn distance(&self, other: &Self, at: &[Vec<f64>; 2]) -> f64 {
        farthest(grid_points(at).map(|(u, v)| (self.eval(u, v), other.eval(u, v))))
    }

    fn each_control_net(&self, f: &mut dyn FnMut(&[DVec3])) {
        for l in self.local_patches() {
            l.each_control_net(f);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn curve(weights: bool) -> BSplineCurve {
        let pts: Vec<DVec3> = (0..7)
            .map(|i| DVec3::new(i as f64, (i as f64).sin() * 2.0, 0.5 * (i % 2) as f64))
            .collect();
        let w = weights.then(|| vec![1.0, 2.0, 0.5, 1.0, 1.5, 1.0, 0.7]);
        BSplineCurve::new(3, vec![0., 0., 0., 0., 1., 1.5, 3., 4., 4., 4., 4.], pts, w).unwrap()
    }

    fn probes(c: &BSplineCurve) -> Vec<f64> {
        span_probes(c.knots(), c.degree(), c.domain())
    }

    #[test]
    fn span_probes_are_degree_plus_one_per_span_inside_the_domain() {
        let at = span_probes(&[0., 0., 1., 1., 3., 5.], 2, (0.5, 4.0));
        // Spans [0.5, 1] (clipped), [1, 3], [3, 4] (clipped): three points each, inside.
        assert_eq!(at.len(), 9);
        for (a, b) in at.iter().zip([0.5 + 0.5 / 6.0, 0.75, 1.0 - 0.5 / 6.0]) {
            assert!((a - b).abs() < 1e-15, "{a} {b}");
        }
        assert!(at.iter().all(|&t| t > 0.5 && t < 4.0));
    }

    /// Negative controls: a control point moved by 1e-7 of the size, or made NaN, is caught;
    /// rounding-sized noise is not.
    #[test]
    fn a_moved_or_nan_curve_is_caught_and_rounding_is_not() {
        for weights in [false, true] {
            let c = curve(weights);
            let same = shape_change(&c, &c.clone(), &probes(&c));
            assert_eq!(same.moved, 0.0);
            assert!(same.is_kept());
            assert!((same.size - (DVec3::new(6.0, 4.0, 0.5)).length()).abs() < 2.0);
            for (delta, kept) in [(1e-15, true), (1e-7, false)] {
                let mut d = c.clone();
                d.translate_point(3, DVec3::Y * delta * same.size);
                let change = shape_change(&c, &d, &probes(&c));
                assert_eq!(change.is_kept(), kept, "{delta}: {change:?}");
            }
            let mut d = c.clone();
            d.translate_point(6, DVec3::new(f64::NAN, 0.0, 0.0));
            assert!(!shape_change(&c, &d, &probes(&c)).is_kept());
            assert!(!shape_change(&d, &c, &probes(&c)).is_kept());
        }
    }

    /// A net far from the origin is allowed the rounding of its coordinates.
    #[test]
    fn coordinate_rounding_is_allowed_far_from_the_origin() {
        let far = ShapeChange {
            moved: 1e-9,
            size: 1e-3,
            magnitude: 1e7,
        };
        assert!(far.is_kept());
        assert!(
            !ShapeChange {
                magnitude: 1.0,
                ..far
            }
            .is_kept()
        );
        assert!(
            !ShapeChange {
                moved: f64::NAN,
                ..far
            }
            .is_kept()
        );
    }

    /// Compared along an unrefined direction at its Greville abscissae, every line of the net
    /// counts: one moved point anywhere in the net is caught.
    #[test]
    fn a_surface_compared_on_the_grid_sees_every_line() {
        let (nu, nv) = (5, 6);
        let pts: Vec<DVec3> = (0..nu * nv)
            .map(|k| DVec3::new((k / nv) as f64, (k % nv) as f64, ((k * 7) % 5) as f64 * 0.3))
            .collect();
        let ku = KnotVector::clamped_uniform(2, nu, 0.0, 1.0).into_vec();
        let kv = KnotVector::clamped_uniform(3, nv, 0.0, 2.0).into_vec();
        let s = TensorSurface::bspline([2, 3], [ku, kv], [nu, nv], pts, None).unwrap();
        let refined = s.elevate_degree(0, 1);
        let at = [
            span_probes(&refined.knots()[0], 3, refined.domain()[0]),
            greville(&s.knots()[1], 3, nv, s.domain()[1]),
        ];
        assert!(shape_change(&s, &refined, &at).moved < 1e-14);
        for i in 0..nu {
            for j in 0..nv {
                let mut moved = s.clone();
                moved.translate_point(i, j, DVec3::Z * 1e-6);
                let change = shape_change(&s, &moved, &at);
                assert!(!change.is_kept(), "point [{i}, {j}]: {change:?}");
            }
        }
    }

    fn surface(rational: bool) -> TensorSurface {
        let (nu, nv) = (9, 7);
        let pts: Vec<DVec3> = (0..nu * nv)
            .map(|k| {
                let (i, j) = ((k / nv) as f64, (k % nv) as f64);
                DVec3::new(i, j, (0.7 * i).sin() * (0.4 * j).cos() + 3.0)
            })
            .collect();
        let w = rational.then(|| (0..nu * nv).map(|k| 1.0 + 0.1 * (k % 5) as f64).collect());
        let ku = KnotVector::clamped_uniform(3, nu, 0.0, 1.0).into_vec();
        let kv = vec![0., 0., 0., 0.5, 0.7, 1.5, 1.8, 2., 2., 2.];
        TensorSurface::bspline([3, 2], [ku, kv], [nu, nv], pts, w).unwrap()
    }

    /// The probes the model compares a refinement at: d+1 per span where it changed, the
    /// Greville abscissae across.
    fn surface_probes(new: &TensorSurface, refined: [bool; 2]) -> [Vec<f64>; 2] {
        [0, 1].map(|dir| {
            let (d, knots) = (new.degree()[dir], &new.knots()[dir]);
            if refined[dir] {
                span_probes(knots, d, new.domain()[dir])
            } else {
                greville(knots, d, new.count()[dir], new.domain()[dir])
            }
        })
    }

    /// The cheap check decides as the exact comparison does, and reports the exact change:
    /// refinements in u, v and both, polynomial and rational, kept; each of them with one
    /// point of the result moved by 1e-6, or made NaN, refused.
    #[test]
    fn the_cheap_surface_check_decides_as_the_exact_comparison() {
        for rational in [false, true] {
            let s = surface(rational);
            let refinements = [
                (s.insert_knot(0, 0.37, 2).unwrap(), [true, false]),
                (s.insert_knot(1, 1.1, 1).unwrap(), [false, true]),
                (s.elevate_degree(0, 2), [true, false]),
                (s.elevate_degree(1, 1), [false, true]),
                (s.elevate_degree(0, 1).elevate_degree(1, 1), [true, true]),
            ];
            for (k, (new, refined)) in refinements.into_iter().enumerate() {
                let at = surface_probes(&new, refined);
                assert_eq!(shape_kept(&s, &new, &at), Ok(()), "{rational} {k}");
                assert!(shape_change(&s, &new, &at).is_kept());
                let [nu, nv] = new.count();
                for (i, j) in [(0, 0), (nu / 2, nv / 3), (nu - 1, nv - 1)] {
                    let mut moved = new.clone();
                    moved.translate_point(i, j, DVec3::new(0.0, 1e-6, 0.0));
                    let exact = shape_change(&s, &moved, &at);
                    assert!(!exact.is_kept(), "{rational} {k} [{i}, {j}]");
                    assert_eq!(shape_kept(&s, &moved, &at), Err(exact));
                    moved.translate_point(i, j, DVec3::new(f64::NAN, 0.0, 0.0));
                    let refused = shape_kept(&s, &moved, &at).unwrap_err();
                    assert!(refused.moved.is_nan(), "{rational} {k} [{i}, {j}]");
                }
            }
        }
    }

    /// The line bound is at least the distance on the grid, for moves anywhere in the net.
    #[test]
    fn the_line_bound_is_at_least_the_grid_distance() {
        let s = surface(false);
        for (new, refined) in [
            (s.insert_knot(0, 0.61, 1).unwrap(), [true, false]),
            (s.elevate_degree(1, 1), [false, true]),
        ] {
            let at = surface_probes(&new, refined);
            for k in 0..new.points().len() {
                let mut moved = new.clone();
                let [_, nv] = new.count();
                moved.translate_point(k / nv, k % nv, DVec3::new(0.3, -0.2, 0.1) * k as f64);
                let (bound, distance) = (s.distance_bound(&moved, &at), s.distance(&moved, &at));
                assert!(distance > 0.0 && bound >= distance * (1.0 - 1e-12), "{k}");
            }
        }
    }

    /// Curve positions at probes agree with the curve's own evaluator.
    #[test]
    fn curve_probes_agree_with_evaluation() {
        for weights in [false, true] {
            let c = curve(weights);
            let mut probe = CurveProbe::new(&c);
            for t in probes(&c) {
                let (a, b) = (probe.at(t), c.eval(t));
                assert!(a.distance(b) <= 1e-13 * b.length().max(1.0), "{t}: {a} {b}");
            }
        }
    }
}
