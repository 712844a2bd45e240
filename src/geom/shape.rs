//! How far a structural edit moves a shape. Knot insertion and degree elevation promise the
//! same shape; ERBS refinement promises it outside the refined interval and at the knots. Before
//! such an edit is applied, its result is compared with the shape it replaces ([`shape_change`])
//! at parameters where the promise must hold ([`span_probes`]: d+1 per span), and src/model
//! refuses an edit that would move the shape by more than [`SHAPE_TOLERANCE`] of its size.
//!
//! Positions only: a refined net carries the shape's derivatives as accurately as its spans
//! allow (docs/scene-format.md), and that is a property of the representation, not a move.

use super::basis::basis_funs;
use super::bspline::BSplineCurve;
use super::erbs::{ErbsCurve, ErbsKnots, ErbsSurface, LocalCurve, LocalPatch};
use super::knots::KnotVector;
use super::point::nan_max;
use super::surface::TensorSurface;
use glam::{DVec3, DVec4};

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

/// A shape that structural edits compare: its positions at given parameters, and its control
/// points (for its size).
pub trait Shape {
    /// Where positions are compared: parameters (curves) or a grid of them (surfaces).
    type Probes: ?Sized;

    /// The positions at `at` in a fixed order, a row at a time (a surface: one u at a time),
    /// so a large surface's grid is never held in memory (fresh pages cost more than the
    /// arithmetic).
    fn positions<'a>(&'a self, at: &'a Self::Probes) -> Box<dyn Iterator<Item = Vec<DVec3>> + 'a>;

    /// Calls `f` on every control net (at any depth, for ERBS locals).
    fn each_control_net(&self, f: &mut dyn FnMut(&[DVec3]));
}

/// How far `new` lies from `old` at `at`, against the size of `old`'s control net: the one
/// comparison every structural edit runs before it is applied.
#[must_use]
pub fn shape_change<S: Shape + ?Sized>(old: &S, new: &S, at: &S::Probes) -> ShapeChange {
    let moved_squared = old
        .positions(at)
        .zip(new.positions(at))
        .fold(0.0, |m, (a, b)| {
            let row = a
                .iter()
                .zip(&b)
                .fold(0.0f64, |m, (p, q)| m.max(p.distance_squared(*q)));
            // f64::max drops a NaN: look for one per row.
            let nan = a.iter().chain(&b).any(|p| p.is_nan());
            nan_max(m, if nan { f64::NAN } else { row })
        });
    let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    let mut magnitude = 0.0;
    old.each_control_net(&mut |net| {
        for &p in net {
            lo = lo.min(p);
            hi = hi.max(p);
        }
        let nan = net.iter().any(|p| p.is_nan());
        magnitude = nan_max(
            magnitude,
            if nan {
                f64::NAN
            } else {
                lo.abs().max(hi.abs()).max_element()
            },
        );
    });
    let moved = moved_squared.sqrt();
    let size = if lo.cmple(hi).all() {
        (hi - lo).length()
    } else {
        0.0
    };
    ShapeChange {
        moved,
        size,
        magnitude,
    }
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

impl Shape for BSplineCurve {
    type Probes = [f64];

    fn positions<'a>(&'a self, at: &'a [f64]) -> Box<dyn Iterator<Item = Vec<DVec3>> + 'a> {
        Box::new(std::iter::once(at.iter().map(|&t| self.eval(t)).collect()))
    }

    fn each_control_net(&self, f: &mut dyn FnMut(&[DVec3])) {
        f(self.points());
    }
}

/// One direction's basis at a parameter: the span and the d+1 non-vanishing functions.
fn probe_basis(s: &TensorSurface, dir: usize, t: f64) -> (usize, Vec<f64>) {
    let (d, n, knots) = (s.degree()[dir], s.count()[dir], &s.knots()[dir]);
    let (a, b) = s.domain()[dir];
    let t = t.clamp(a, b);
    let span = knots.find_span(d, n, t);
    (span, basis_funs(knots, d, span, t))
}

/// S(u, v) over a grid `us × vs`, row by row of u, by the tensor structure: each row of the
/// net is combined for every v once (kept in a ring of d_u + 1 rows, which is all one u
/// needs), then d_u + 1 such rows for each u (BasisFuns once per parameter, homogeneous form).
struct GridPositions<'a> {
    surface: &'a TensorSurface,
    us: &'a [f64],
    bv: Vec<(usize, Vec<f64>)>,
    /// Row i of the net combined for every v, in slot i mod (d_u + 1).
    ring: Vec<DVec4>,
    ring_rows: Vec<Option<usize>>,
    /// The current u's homogeneous sums, and the next u.
    acc: Vec<DVec4>,
    next_u: usize,
}

impl<'a> GridPositions<'a> {
    fn new(surface: &'a TensorSurface, [us, vs]: &'a [Vec<f64>; 2]) -> Self {
        let du = surface.degree()[0];
        Self {
            surface,
            us,
            bv: vs.iter().map(|&v| probe_basis(surface, 1, v)).collect(),
            ring: vec![DVec4::ZERO; (du + 1) * vs.len()],
            ring_rows: vec![None; du + 1],
            acc: Vec::with_capacity(vs.len()),
            next_u: 0,
        }
    }

    /// Makes sure row i of the net, combined for every v, is in its ring slot.
    fn combine_row(&mut self, i: usize) {
        let slot = i % self.ring_rows.len();
        if self.ring_rows[slot] == Some(i) {
            return;
        }
        let s = self.surface;
        let (dv, nv) = (s.degree()[1], s.count()[1]);
        let (points, weights) = (s.points(), s.weights());
        let m = self.bv.len();
        for (r, (span, n)) in self.ring[slot * m..(slot + 1) * m].iter_mut().zip(&self.bv) {
            let first = i * nv + span - dv;
            *r = n
                .iter()
                .enumerate()
                .map(|(l, &w)| {
                    let k = first + l;
                    let h = weights.map_or(1.0, |ws| ws[k]);
                    (points[k] * h).extend(h) * w
                })
                .sum();
        }
        self.ring_rows[slot] = Some(i);
    }

    /// The positions at the next u, if any is left.
    fn next_row(&mut self) -> Option<Vec<DVec3>> {
        let &u = self.us.get(self.next_u)?;
        self.next_u += 1;
        let du = self.surface.degree()[0];
        let (span, n) = probe_basis(self.surface, 0, u);
        for i in span - du..=span {
            self.combine_row(i);
        }
        let m = self.bv.len();
        let mut acc = std::mem::take(&mut self.acc);
        acc.clear();
        acc.resize(m, DVec4::ZERO);
        for (i, &w) in (span - du..=span).zip(&n) {
            let slot = i % (du + 1);
            for (a, r) in acc.iter_mut().zip(&self.ring[slot * m..(slot + 1) * m]) {
                *a += *r * w;
            }
        }
        // A polynomial net's w is the partition of unity: its positions need no division.
        let row = if self.surface.is_rational() {
            acc.iter().map(|p| p.truncate() / p.w).collect()
        } else {
            acc.iter().map(|p| p.truncate()).collect()
        };
        self.acc = acc;
        Some(row)
    }
}

impl Iterator for GridPositions<'_> {
    type Item = Vec<DVec3>;

    fn next(&mut self) -> Option<Vec<DVec3>> {
        self.next_row()
    }
}

impl Shape for TensorSurface {
    /// The grid `us × vs`.
    type Probes = [Vec<f64>; 2];

    fn positions<'a>(&'a self, at: &'a [Vec<f64>; 2]) -> Box<dyn Iterator<Item = Vec<DVec3>> + 'a> {
        Box::new(GridPositions::new(self, at))
    }

    fn each_control_net(&self, f: &mut dyn FnMut(&[DVec3])) {
        f(self.points());
    }
}

impl Shape for LocalCurve {
    type Probes = [f64];

    fn positions<'a>(&'a self, at: &'a [f64]) -> Box<dyn Iterator<Item = Vec<DVec3>> + 'a> {
        Box::new(std::iter::once(at.iter().map(|&t| self.eval(t)).collect()))
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

    fn positions<'a>(&'a self, at: &'a [f64]) -> Box<dyn Iterator<Item = Vec<DVec3>> + 'a> {
        Box::new(std::iter::once(at.iter().map(|&t| self.eval(t)).collect()))
    }

    fn each_control_net(&self, f: &mut dyn FnMut(&[DVec3])) {
        for l in self.local_curves() {
            l.each_control_net(f);
        }
    }
}

/// `f` over a grid `us × vs`, a row of v for each u.
fn grid_rows<'a>(
    [us, vs]: &'a [Vec<f64>; 2],
    f: impl Fn(f64, f64) -> DVec3 + 'a,
) -> Box<dyn Iterator<Item = Vec<DVec3>> + 'a> {
    Box::new(
        us.iter()
            .map(move |&u| vs.iter().map(|&v| f(u, v)).collect()),
    )
}

impl Shape for LocalPatch {
    type Probes = [Vec<f64>; 2];

    fn positions<'a>(&'a self, at: &'a [Vec<f64>; 2]) -> Box<dyn Iterator<Item = Vec<DVec3>> + 'a> {
        grid_rows(at, |u, v| self.eval(u, v))
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

    fn positions<'a>(&'a self, at: &'a [Vec<f64>; 2]) -> Box<dyn Iterator<Item = Vec<DVec3>> + 'a> {
        grid_rows(at, |u, v| self.eval(u, v))
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
}
