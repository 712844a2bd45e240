//! Independent reference ("oracle") for the area of a trimmed surface,
//!   A = ∫∫_D |S_u × S_v| du dv,
//! over the trimmed parameter domain D (DESIGN.md, "Trims (contract)").
//!
//! Written from the contract only, apart from the product's trimming code, and by a method the
//! product does not use (it classifies samples, or tessellates): **Green's theorem** on loops
//! given as exact parametric 2D curves, never polylines that approximate them.
//!
//! With g = |S_u × S_v| and G(u, v) = ∫_{u_ref}^{u} g(s, v) ds (so ∂G/∂u = g), Green's theorem
//! ∮ (L du + M dv) = ∫∫ (∂M/∂u − ∂L/∂v) with L = 0, M = G gives
//!   ∫∫_D g du dv = ∮_∂D G(u, v) dv = Σ_loops Σ_pieces ∫ G(c(t)) v'(t) dt,
//! outer loops counter-clockwise and holes clockwise. u_ref may be any constant per loop (a
//! change adds ∮ h(v) dv = 0 over a closed loop); the loop's smallest u keeps every inner
//! integral inside the loop's bounding box, hence inside the surface's domain.
//!
//! * Both integrals are globally adaptive 7-point Gauss / 15-point Kronrod (QUADPACK's `qk15`
//!   rule inside a `qag`-style loop: always bisect the interval with the largest error), the
//!   error estimate being |K15 − G7| (pessimistic: the Kronrod value is far more accurate than
//!   the Gauss value whose error this measures). The outer integral runs over all pieces of all
//!   loops at once. Depth and interval counts are capped; an interval that cannot be split while
//!   the tolerance is unmet is counted, and [`trimmed_area`] refuses a result with any such
//!   interval or with an error estimate above the tolerance, so the oracle never silently
//!   returns a number it could not certify.
//! * Tolerance budget: the outer integral gets tol/2; each inner integral tol/(4V), V being the
//!   total variation of v along all loops, since an error δ in G moves ∮ G dv by at most δ·V.
//!   The reported error estimate adds the outer |K − G| and the inner errors carried through
//!   the outer weights.
//! * Loops: lines, polylines, circular arcs/circles (cos/sin), and 2D B-spline/NURBS curves,
//!   each split into smooth pieces (polyline edges, arcs of at most 90°, non-empty knot spans)
//!   so that the quadrature never straddles a corner or a knot of the trim. The 2D NURBS
//!   evaluator here is the Cox–de Boor recursion of basis functions with their derivative
//!   formula (NURBS Book eq. 2.5 and 2.9) and the quotient rule — deliberately not the de Boor
//!   triangle on derivative control points of `eval.rs`, so the two can check each other.
//! * Orientation: each loop's signed area ∮ u dv is computed once; a loop whose orientation does
//!   not match its role (outer: counter-clockwise, hole: clockwise) contributes with the sign
//!   flipped, so either orientation is accepted, as the contract says. Nesting is the caller's:
//!   an island inside a hole is an outer loop again. Self-intersecting loops are not supported
//!   (Green's theorem would weight each region by its winding number).
//! * Surfaces are any `Fn(u, v) -> (S_u, S_v)` with exact partials: analytic ones here
//!   ([`plane_partials`], [`bilinear_partials`], [`cylinder_partials`], [`sphere_partials`]),
//!   tensor-product Bézier/B-spline/NURBS through the oracle's own evaluator ([`TensorSurface`]).
//! * Knot lines: g is only C^(k−1) across a knot line of a C^k surface, and |K15 − G7| can
//!   underestimate the error of an interval that straddles such a kink (both rules then err by
//!   the same order; a Fubini reference without breaks was seen off by 60× its estimate). The
//!   surface's interior knots may therefore be given as `breaks` [u, v] to
//!   [`estimate_trimmed_area`]: every inner integral starts split at the u-knots, and every loop
//!   piece is split where it crosses a u- or v-knot line (sign changes of u(t) − knot, v(t) − knot
//!   on 64 samples per piece, then bisection to machine precision), so each interval integrates
//!   an analytic function and the estimate is the pessimistic one again. [`trimmed_area`] passes
//!   none (analytic surfaces, or when the kinks are left to adaptivity).

use std::cell::Cell;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

use glam::{DVec2, DVec3};

use super::eval::{
    Basis, Homogeneous, Point3, homogeneous, project_surface_derivatives, tensor_derivatives,
};

// ---------------------------------------------------------------------------------------------
// Gauss–Kronrod 7/15 (QUADPACK qk15, verbatim)
// ---------------------------------------------------------------------------------------------

/// Kronrod abscissae on [-1, 1], positive half, descending; the odd entries (1, 3, 5, 7) are the
/// 7-point Gauss nodes.
#[allow(clippy::excessive_precision)]
const XGK: [f64; 8] = [
    0.991455371120812639206854697526329,
    0.949107912342758524526189684047851,
    0.864864423359769072789712788640926,
    0.741531185599394439863864773280788,
    0.586087235467691130294144845693013,
    0.405845151377397166906606412076961,
    0.207784955007898467600689403773245,
    0.000000000000000000000000000000000,
];

/// Kronrod weights belonging to `XGK`.
#[allow(clippy::excessive_precision)]
const WGK: [f64; 8] = [
    0.022935322010529224963732008058970,
    0.063092092629978553290700663189204,
    0.104790010322250183839876322541518,
    0.140653259715525918745189590510238,
    0.169004726639267902826583426598550,
    0.190350578064785409913256402421014,
    0.204432940075298892414161999234649,
    0.209482141084727828012999174891714,
];

/// Gauss weights belonging to `XGK[1]`, `XGK[3]`, `XGK[5]`, `XGK[7]` (= 0).
#[allow(clippy::excessive_precision)]
const WG: [f64; 4] = [
    0.129484966168869693270611432679082,
    0.279705391489276667901467771423780,
    0.381830050505118944950369775488975,
    0.417959183673469387755102040816327,
];

/// Bisection depth at which an interval is no longer split (and counted as capped when it has
/// not met the tolerance): 2^-48 of the starting interval is below any meaningful width.
pub const MAX_DEPTH: u32 = 48;
/// At most this many outer intervals in all; more is counted as capped.
pub const MAX_OUTER_INTERVALS: usize = 200_000;
/// At most this many intervals per inner integral.
pub const MAX_INNER_INTERVALS: usize = 2_000;

/// One application of the 7/15 rule on [a, b].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Rule {
    /// The 15-point Kronrod value.
    pub value: f64,
    /// |K15 − G7|.
    pub error: f64,
    /// Σ_k w_k |e_k| · (b − a)/2 for integrands that report their own error e_k (the inner
    /// integral's error carried through the outer rule); 0 for exact integrands.
    pub carried: f64,
}

/// The 7/15 rule of f on [a, b]; f returns (value, error of that value).
pub fn kronrod15(f: &mut dyn FnMut(f64) -> (f64, f64), a: f64, b: f64) -> Rule {
    let half = 0.5 * (b - a);
    let centre = 0.5 * (a + b);
    let (mut kronrod, mut gauss, mut carried) = (0.0, 0.0, 0.0);
    for k in 0..8 {
        let nodes: &[f64] = if k == 7 {
            &[centre]
        } else {
            &[centre - half * XGK[k], centre + half * XGK[k]]
        };
        for &x in nodes {
            let (y, e) = f(x);
            kronrod += WGK[k] * y;
            carried += WGK[k] * e.abs();
            if k % 2 == 1 {
                gauss += WG[k / 2] * y;
            }
        }
    }
    Rule {
        value: kronrod * half,
        error: ((kronrod - gauss) * half).abs(),
        carried: carried * half.abs(),
    }
}

/// Result of an adaptive integration.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Quadrature {
    /// NaN when the integrand was not finite somewhere.
    pub value: f64,
    /// Σ |K15 − G7| over the final intervals.
    pub error: f64,
    /// Σ of the integrand's own errors carried through the rule (see [`Rule::carried`]).
    pub carried: f64,
    /// Intervals that could not be split further (depth, machine resolution, interval budget,
    /// non-finite integrand) while the total was above the tolerance. Non-zero: not certified.
    pub capped: usize,
    /// Intervals in the final partition.
    pub intervals: usize,
}

/// An interval of [`integrate_pieces`], ordered by its error for the max-heap.
#[derive(Clone, Copy, Debug)]
struct Interval {
    piece: usize,
    a: f64,
    b: f64,
    depth: u32,
    rule: Rule,
}

impl PartialEq for Interval {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Interval {}
impl PartialOrd for Interval {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Interval {
    fn cmp(&self, other: &Self) -> Ordering {
        self.rule.error.total_cmp(&other.rule.error)
    }
}

/// Globally adaptive 7/15 quadrature of Σ_k ∫_{a_k}^{b_k} f(k, t) dt to an absolute tolerance
/// (QUADPACK `qag` style): always bisect the interval with the largest |K15 − G7| until their
/// sum is at most `tol`. Global rather than recursive with the tolerance halved per level, so an
/// integrable endpoint singularity or a kink costs a few bisections next to it instead of
/// exhausting the depth. f returns (value, own error), see [`Rule::carried`]. Stops at the first
/// non-finite rule (value NaN) and at `max_intervals`, counting capped intervals.
pub fn integrate_pieces(
    f: &mut dyn FnMut(usize, f64) -> (f64, f64),
    pieces: &[(f64, f64)],
    tol: f64,
    max_intervals: usize,
) -> Quadrature {
    assert!(tol >= 0.0, "negative tolerance {tol:e}");
    let mut rule_on = |k: usize, a: f64, b: f64| kronrod15(&mut |t| f(k, t), a, b);
    let mut heap = BinaryHeap::with_capacity(2 * pieces.len());
    let mut done: Vec<Interval> = Vec::new();
    let mut capped = 0;
    let mut error = 0.0;
    let mut finite = true;
    for (k, &(a, b)) in pieces.iter().enumerate() {
        let rule = rule_on(k, a, b);
        error += rule.error;
        finite &= rule.value.is_finite() && rule.error.is_finite();
        heap.push(Interval {
            piece: k,
            a,
            b,
            depth: 0,
            rule,
        });
    }
    let total = |heap: &BinaryHeap<Interval>| heap.iter().map(|i| i.rule.error).sum::<f64>();
    loop {
        if !finite {
            return Quadrature {
                value: f64::NAN,
                error: f64::NAN,
                carried: f64::NAN,
                capped: capped + 1,
                intervals: heap.len() + done.len(),
            };
        }
        if error <= tol {
            // The running total is updated by differences; confirm it before stopping.
            error = total(&heap);
            if error <= tol {
                break;
            }
        }
        let Some(worst) = heap.pop() else { break };
        error -= worst.rule.error;
        let m = 0.5 * (worst.a + worst.b);
        if heap.len() + done.len() + 2 > max_intervals {
            capped += 1;
            done.push(worst);
            break;
        }
        if worst.depth >= MAX_DEPTH || m == worst.a || m == worst.b {
            capped += 1;
            done.push(worst);
            continue;
        }
        for (a, b) in [(worst.a, m), (m, worst.b)] {
            let rule = rule_on(worst.piece, a, b);
            error += rule.error;
            finite &= rule.value.is_finite() && rule.error.is_finite();
            heap.push(Interval {
                piece: worst.piece,
                a,
                b,
                depth: worst.depth + 1,
                rule,
            });
        }
    }
    done.extend(heap);
    // Neumaier summation: the total is a sum of many small, partly cancelling contributions.
    let (mut sum, mut compensation) = (0.0f64, 0.0f64);
    for i in &done {
        let x = i.rule.value;
        let t = sum + x;
        compensation += if sum.abs() >= x.abs() {
            (sum - t) + x
        } else {
            (x - t) + sum
        };
        sum = t;
    }
    Quadrature {
        value: sum + compensation,
        error: done.iter().map(|i| i.rule.error).sum(),
        carried: done.iter().map(|i| i.rule.carried).sum(),
        capped,
        intervals: done.len(),
    }
}

/// Adaptive quadrature of f over [a, b] to an absolute tolerance ([`integrate_pieces`] with one
/// piece and at most [`MAX_INNER_INTERVALS`] intervals).
pub fn integrate_adaptive(f: &mut dyn FnMut(f64) -> f64, a: f64, b: f64, tol: f64) -> Quadrature {
    integrate_pieces(&mut |_, x| (f(x), 0.0), &[(a, b)], tol, MAX_INNER_INTERVALS)
}

// ---------------------------------------------------------------------------------------------
// 2D curves
// ---------------------------------------------------------------------------------------------

/// A 2D B-spline or NURBS curve in parameter space (degree p, n points, n + p + 1 knots,
/// domain [t_p, t_n], as in the math conventions of DESIGN.md).
#[derive(Clone, Debug, PartialEq)]
pub struct Nurbs2 {
    pub degree: usize,
    pub knots: Vec<f64>,
    pub points: Vec<DVec2>,
    /// Positive weights, one per point; `None` for a non-rational B-spline.
    pub weights: Option<Vec<f64>>,
}

impl Nurbs2 {
    /// Validates the shape of the data (so a malformed test fixture fails loudly, not wrongly).
    pub fn new(
        degree: usize,
        knots: Vec<f64>,
        points: Vec<DVec2>,
        weights: Option<Vec<f64>>,
    ) -> Result<Nurbs2, String> {
        let n = points.len();
        if degree == 0 || n <= degree {
            return Err(format!("NURBS: degree {degree} needs more than {n} points"));
        }
        if knots.len() != n + degree + 1 {
            return Err(format!(
                "NURBS: {} knots, expected {}",
                knots.len(),
                n + degree + 1
            ));
        }
        if knots.iter().any(|k| !k.is_finite()) || knots.windows(2).any(|w| w[1] < w[0]) {
            return Err("NURBS: knots must be finite and non-decreasing".into());
        }
        if knots[degree] >= knots[n] {
            return Err("NURBS: empty domain".into());
        }
        if points.iter().any(|p| !p.is_finite()) {
            return Err("NURBS: non-finite point".into());
        }
        if let Some(w) = &weights
            && (w.len() != n || w.iter().any(|&x| !(x > 0.0 && x.is_finite())))
        {
            return Err("NURBS: weights must be positive, one per point".into());
        }
        Ok(Nurbs2 {
            degree,
            knots,
            points,
            weights,
        })
    }

    /// Parameter domain [t_p, t_n].
    pub fn domain(&self) -> (f64, f64) {
        (self.knots[self.degree], self.knots[self.points.len()])
    }

    fn weight(&self, j: usize) -> f64 {
        self.weights.as_ref().map_or(1.0, |w| w[j])
    }

    /// Indices i of the non-empty spans [t_i, t_{i+1}) inside the domain.
    pub fn spans(&self) -> Vec<usize> {
        (self.degree..self.points.len())
            .filter(|&i| self.knots[i] < self.knots[i + 1])
            .collect()
    }

    /// The span containing t (the last non-empty one at and beyond t_n, the first before t_p).
    pub fn span_of(&self, t: f64) -> usize {
        let spans = self.spans();
        *spans
            .iter()
            .rev()
            .find(|&&i| self.knots[i] <= t)
            .unwrap_or(&spans[0])
    }

    /// N_{j,p}(t) and N'_{j,p}(t) for j = i−p ..= i on span i, by the Cox–de Boor recursion
    ///   N_{j,k} = (t − t_j)/(t_{j+k} − t_j) N_{j,k−1} + (t_{j+k+1} − t)/(t_{j+k+1} − t_{j+1}) N_{j+1,k−1}
    /// with 0/0 = 0, and N'_{j,p} = p (N_{j,p−1}/(t_{j+p} − t_j) − N_{j+1,p−1}/(t_{j+p+1} − t_{j+1})).
    fn basis(&self, i: usize, t: f64) -> (Vec<f64>, Vec<f64>) {
        let (p, u) = (self.degree, &self.knots);
        let ratio = |num: f64, den: f64| if den == 0.0 { 0.0 } else { num / den };
        // `row` holds N_{j,k} for j = i−k ..= i; outside that range the function is 0 on the span.
        let lower = |row: &[f64], k: usize, j: usize| -> f64 {
            if j + k < i || j > i {
                0.0
            } else {
                row[j + k - i]
            }
        };
        let mut row = vec![1.0];
        let mut previous = Vec::new();
        for k in 1..=p {
            let next: Vec<f64> = (i - k..=i)
                .map(|j| {
                    ratio(t - u[j], u[j + k] - u[j]) * lower(&row, k - 1, j)
                        + ratio(u[j + k + 1] - t, u[j + k + 1] - u[j + 1])
                            * lower(&row, k - 1, j + 1)
                })
                .collect();
            previous = std::mem::replace(&mut row, next);
        }
        let derivative = (i - p..=i)
            .map(|j| {
                p as f64
                    * (ratio(lower(&previous, p - 1, j), u[j + p] - u[j])
                        - ratio(lower(&previous, p - 1, j + 1), u[j + p + 1] - u[j + 1]))
            })
            .collect();
        (row, derivative)
    }

    /// C(t) and C'(t) evaluated on span i: homogeneous sums A = Σ N w P, W = Σ N w, then
    /// C = A/W and C' = (A' − W' C)/W.
    pub fn eval_on_span(&self, i: usize, t: f64) -> (DVec2, DVec2) {
        let p = self.degree;
        let (n, dn) = self.basis(i, t);
        let (mut a, mut da, mut w, mut dw) = (DVec2::ZERO, DVec2::ZERO, 0.0, 0.0);
        for (k, j) in (i - p..=i).enumerate() {
            let wj = self.weight(j);
            a += n[k] * wj * self.points[j];
            da += dn[k] * wj * self.points[j];
            w += n[k] * wj;
            dw += dn[k] * wj;
        }
        let c = a / w;
        (c, (da - dw * c) / w)
    }

    /// C(t) and C'(t) (right-hand values at interior knots).
    pub fn eval(&self, t: f64) -> (DVec2, DVec2) {
        self.eval_on_span(self.span_of(t), t)
    }

    /// The same curve traversed backwards: knots t ↦ a + b − t reversed, points reversed.
    pub fn reversed(&self) -> Nurbs2 {
        let (a, b) = (self.knots[0], self.knots[self.knots.len() - 1]);
        Nurbs2 {
            degree: self.degree,
            knots: self.knots.iter().rev().map(|&t| a + b - t).collect(),
            points: self.points.iter().rev().copied().collect(),
            weights: self
                .weights
                .as_ref()
                .map(|w| w.iter().rev().copied().collect()),
        }
    }

    /// The full circle c + r(cos θ, sin θ) as the usual 9-point rational quadratic (four
    /// 90° arcs, corner weights 1/√2), counter-clockwise from θ = 0.
    pub fn circle(center: DVec2, radius: f64) -> Nurbs2 {
        let corner = std::f64::consts::FRAC_1_SQRT_2;
        let offsets = [
            (1.0, 0.0),
            (1.0, 1.0),
            (0.0, 1.0),
            (-1.0, 1.0),
            (-1.0, 0.0),
            (-1.0, -1.0),
            (0.0, -1.0),
            (1.0, -1.0),
            (1.0, 0.0),
        ];
        let points = offsets
            .iter()
            .map(|&(x, y)| center + radius * DVec2::new(x, y))
            .collect();
        let weights = (0..9)
            .map(|k| if k % 2 == 1 { corner } else { 1.0 })
            .collect();
        let knots = vec![0.0, 0.0, 0.0, 1.0, 1.0, 2.0, 2.0, 3.0, 3.0, 4.0, 4.0, 4.0];
        Nurbs2::new(2, knots, points, Some(weights)).expect("circle data is valid")
    }
}

/// One piece of a trim loop: an exact parametric curve in the surface's (u, v) space.
#[derive(Clone, Debug, PartialEq)]
pub enum Segment {
    /// The straight line from `from` to `to`.
    Line { from: DVec2, to: DVec2 },
    /// Straight lines through the points in order (not closed by itself).
    Polyline(Vec<DVec2>),
    /// center + radius (cos θ, sin θ) for θ from `start` to `end` (radians): counter-clockwise
    /// when end > start; |end − start| = 2π is a full circle.
    Arc {
        center: DVec2,
        radius: f64,
        start: f64,
        end: f64,
    },
    /// A 2D B-spline or NURBS curve over its whole domain.
    Nurbs(Nurbs2),
}

impl Segment {
    /// The full circle, counter-clockwise from θ = 0.
    pub fn circle(center: DVec2, radius: f64) -> Segment {
        Segment::Arc {
            center,
            radius,
            start: 0.0,
            end: std::f64::consts::TAU,
        }
    }

    fn endpoints(&self) -> (DVec2, DVec2) {
        match self {
            Segment::Line { from, to } => (*from, *to),
            Segment::Polyline(p) => (p[0], p[p.len() - 1]),
            Segment::Arc {
                center,
                radius,
                start,
                end,
            } => (
                *center + *radius * DVec2::from_angle(*start),
                *center + *radius * DVec2::from_angle(*end),
            ),
            Segment::Nurbs(c) => {
                let (a, b) = c.domain();
                (c.eval(a).0, c.eval(b).0)
            }
        }
    }

    fn validate(&self) -> Result<(), String> {
        match self {
            Segment::Line { from, to } if !(from.is_finite() && to.is_finite()) => {
                Err("line: non-finite point".into())
            }
            Segment::Polyline(p) if p.len() < 2 || p.iter().any(|x| !x.is_finite()) => {
                Err("polyline: needs at least 2 finite points".into())
            }
            Segment::Arc {
                center,
                radius,
                start,
                end,
            } if !(center.is_finite()
                && *radius > 0.0
                && radius.is_finite()
                && start.is_finite()
                && end.is_finite()
                && start != end) =>
            {
                Err("arc: needs a finite centre, a positive radius and start ≠ end".into())
            }
            _ => Ok(()),
        }
    }

    /// The same segment traversed backwards.
    pub fn reversed(&self) -> Segment {
        match self {
            Segment::Line { from, to } => Segment::Line {
                from: *to,
                to: *from,
            },
            Segment::Polyline(p) => Segment::Polyline(p.iter().rev().copied().collect()),
            Segment::Arc {
                center,
                radius,
                start,
                end,
            } => Segment::Arc {
                center: *center,
                radius: *radius,
                start: *end,
                end: *start,
            },
            Segment::Nurbs(c) => Segment::Nurbs(c.reversed()),
        }
    }

    /// Smooth pieces: polyline edges, arcs of at most 90°, non-empty knot spans.
    fn pieces(&self) -> Vec<Piece> {
        match self {
            Segment::Line { from, to } => vec![Piece::line(*from, *to)],
            Segment::Polyline(p) => p.windows(2).map(|w| Piece::line(w[0], w[1])).collect(),
            Segment::Arc {
                center,
                radius,
                start,
                end,
            } => {
                let count = ((end - start).abs() / std::f64::consts::FRAC_PI_2).ceil() as usize;
                (0..count.max(1))
                    .map(|k| {
                        let at = |k: usize| start + (end - start) * k as f64 / count as f64;
                        Piece {
                            curve: PieceCurve::Arc {
                                center: *center,
                                radius: *radius,
                            },
                            a: at(k),
                            b: at(k + 1),
                        }
                    })
                    .collect()
            }
            Segment::Nurbs(c) => c
                .spans()
                .into_iter()
                .map(|i| Piece {
                    curve: PieceCurve::Span {
                        curve: c.clone(),
                        span: i,
                    },
                    a: c.knots[i],
                    b: c.knots[i + 1],
                })
                .collect(),
        }
    }
}

/// A smooth parametric piece of a loop on [a, b].
#[derive(Clone, Debug)]
struct Piece {
    curve: PieceCurve,
    a: f64,
    b: f64,
}

#[derive(Clone, Debug)]
enum PieceCurve {
    /// from + t (to − from), t ∈ [0, 1].
    Line {
        from: DVec2,
        to: DVec2,
    },
    Arc {
        center: DVec2,
        radius: f64,
    },
    /// One knot span, evaluated on that span even at its ends.
    Span {
        curve: Nurbs2,
        span: usize,
    },
}

impl Piece {
    fn line(from: DVec2, to: DVec2) -> Piece {
        Piece {
            curve: PieceCurve::Line { from, to },
            a: 0.0,
            b: 1.0,
        }
    }

    /// a, the parameters in between where u(t) crosses one of `breaks[0]` or v(t) one of
    /// `breaks[1]` (in the direction of travel), and b. Found as sign changes on 64 samples and
    /// refined by bisection to machine precision; a tangential touch is not a cut.
    fn crossings(&self, breaks: [&[f64]; 2]) -> Vec<f64> {
        const SAMPLES: usize = 64;
        let at = |j: usize| self.a + (self.b - self.a) * j as f64 / SAMPLES as f64;
        let points: Vec<DVec2> = (0..=SAMPLES).map(|j| self.eval(at(j)).0).collect();
        let mut cuts = Vec::new();
        for (dir, values) in breaks.iter().enumerate() {
            for &value in values.iter() {
                let h = |p: DVec2| p[dir] - value;
                for j in 0..SAMPLES {
                    let (h0, h1) = (h(points[j]), h(points[j + 1]));
                    if j > 0 && h0 == 0.0 {
                        cuts.push(at(j));
                    } else if h0 * h1 < 0.0 {
                        let (mut lo, mut hi) = (at(j), at(j + 1));
                        loop {
                            let mid = 0.5 * (lo + hi);
                            if mid == lo || mid == hi {
                                break;
                            }
                            if (h(self.eval(mid).0) < 0.0) == (h0 < 0.0) {
                                lo = mid;
                            } else {
                                hi = mid;
                            }
                        }
                        cuts.push(0.5 * (lo + hi));
                    }
                }
            }
        }
        cuts.sort_by(f64::total_cmp);
        if self.b < self.a {
            cuts.reverse();
        }
        cuts.dedup();
        let mut out = vec![self.a];
        out.extend(cuts.into_iter().filter(|&t| t != self.a && t != self.b));
        out.push(self.b);
        out
    }

    /// (c(t), c'(t)).
    fn eval(&self, t: f64) -> (DVec2, DVec2) {
        match &self.curve {
            PieceCurve::Line { from, to } => (*from + t * (*to - *from), *to - *from),
            PieceCurve::Arc { center, radius } => {
                let (s, c) = t.sin_cos();
                (
                    *center + *radius * DVec2::new(c, s),
                    *radius * DVec2::new(-s, c),
                )
            }
            PieceCurve::Span { curve, span } => curve.eval_on_span(*span, t),
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Loops
// ---------------------------------------------------------------------------------------------

/// Whether a loop bounds material (outer, counter-clockwise) or removes it (hole, clockwise).
/// Nesting is the caller's: an island inside a hole is `Outer` again.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    Outer,
    Hole,
}

/// A closed chain of segments (either orientation), with what the integration needs of it
/// worked out once.
#[derive(Clone, Debug)]
pub struct Loop {
    segments: Vec<Segment>,
    pieces: Vec<Piece>,
    /// ∮ u dv: positive for counter-clockwise.
    signed_area: f64,
    /// The smallest u seen on the loop (sampled; any constant would do, see the module notes).
    u_ref: f64,
    /// ∮ |v'| dt, the total variation of v (for the inner tolerance; an estimate suffices).
    v_variation: f64,
}

impl Loop {
    /// Checks every segment and that each ends where the next begins, the last where the first
    /// begins (to 1e-9 of the loop's size), and that the loop encloses some area.
    pub fn new(segments: Vec<Segment>) -> Result<Loop, String> {
        if segments.is_empty() {
            return Err("loop: no segments".into());
        }
        for (k, s) in segments.iter().enumerate() {
            s.validate().map_err(|e| format!("loop segment {k}: {e}"))?;
        }
        let ends: Vec<(DVec2, DVec2)> = segments.iter().map(Segment::endpoints).collect();
        let pieces: Vec<Piece> = segments.iter().flat_map(Segment::pieces).collect();
        let samples: Vec<DVec2> = pieces
            .iter()
            .flat_map(|p| (0..=16).map(move |k| p.eval(p.a + (p.b - p.a) * k as f64 / 16.0).0))
            .collect();
        let (lo, hi) = samples.iter().fold(
            (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        );
        let size = (hi - lo)
            .max_element()
            .max(lo.abs().max_element())
            .max(hi.abs().max_element());
        for k in 0..ends.len() {
            let next = (k + 1) % ends.len();
            let gap = ends[k].1.distance(ends[next].0);
            if gap.is_nan() || gap > 1e-9 * size {
                return Err(format!(
                    "loop: segment {k} ends at {:?}, segment {next} starts at {:?} (gap {gap:e})",
                    ends[k].1, ends[next].0
                ));
            }
        }
        let box_area = (hi - lo).x * (hi - lo).y;
        let mut signed_area = 0.0;
        let mut v_variation = 0.0;
        for p in &pieces {
            let q = integrate_adaptive(
                &mut |t| {
                    let (c, d) = p.eval(t);
                    (c.x - lo.x) * d.y
                },
                p.a,
                p.b,
                1e-12 * box_area.max(f64::MIN_POSITIVE),
            );
            signed_area += q.value;
            let r = integrate_adaptive(&mut |t| p.eval(t).1.y.abs(), p.a, p.b, 1e-6 * size);
            // |…|: an arc running clockwise has b < a, so its integral comes out negative.
            v_variation += r.value.abs();
        }
        if signed_area.is_nan() || signed_area.abs() <= 1e-9 * box_area {
            return Err(format!(
                "loop: encloses no area (∮ u dv = {signed_area:e}, box {box_area:e})"
            ));
        }
        Ok(Loop {
            segments,
            pieces,
            signed_area,
            u_ref: lo.x,
            v_variation,
        })
    }

    /// The circle center + radius (cos θ, sin θ), counter-clockwise.
    pub fn circle(center: DVec2, radius: f64) -> Result<Loop, String> {
        Loop::new(vec![Segment::circle(center, radius)])
    }

    /// The closed polygon through `points` (the closing edge is added).
    pub fn polygon(points: &[DVec2]) -> Result<Loop, String> {
        if points.len() < 3 {
            return Err(format!(
                "polygon: {} points, at least 3 needed",
                points.len()
            ));
        }
        let mut p = points.to_vec();
        p.push(points[0]);
        Loop::new(vec![Segment::Polyline(p)])
    }

    /// The axis-parallel rectangle [min, max], counter-clockwise.
    pub fn rectangle(min: DVec2, max: DVec2) -> Result<Loop, String> {
        Loop::polygon(&[min, DVec2::new(max.x, min.y), max, DVec2::new(min.x, max.y)])
    }

    /// The same loop traversed the other way round.
    pub fn reversed(&self) -> Loop {
        Loop::new(self.segments.iter().rev().map(Segment::reversed).collect())
            .expect("the reverse of a valid loop is valid")
    }

    pub fn segments(&self) -> &[Segment] {
        &self.segments
    }

    /// ∮ u dv: the loop's parameter-space area, positive when counter-clockwise.
    pub fn signed_area(&self) -> f64 {
        self.signed_area
    }
}

// ---------------------------------------------------------------------------------------------
// The area
// ---------------------------------------------------------------------------------------------

/// The outcome of [`estimate_trimmed_area`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AreaEstimate {
    pub area: f64,
    /// Outer |K15 − G7| summed, plus the inner errors carried through the outer rule.
    pub error_estimate: f64,
    /// Evaluations of the surface's partials.
    pub evaluations: usize,
    /// Capped intervals, outer and inner (see [`Quadrature::capped`]); after a capped inner
    /// integral the area is NaN and the integration stopped there.
    pub capped: usize,
    /// Outer intervals in the final partition.
    pub outer_intervals: usize,
}

impl AreaEstimate {
    /// Whether the estimate met the tolerance it was asked for without hitting a cap.
    pub fn certified(&self, tol: f64) -> bool {
        self.capped == 0 && self.error_estimate <= tol && self.area.is_finite()
    }
}

/// ∫∫_D |S_u × S_v| du dv over the domain bounded by `loops`, to the absolute tolerance `tol`;
/// `surface(u, v)` returns the exact partials (S_u, S_v). Panics when the quadrature cannot
/// certify `tol` (a capped interval or an error estimate above it): a test that needs the
/// oracle must not get an uncertified number.
pub fn trimmed_area(
    surface: &dyn Fn(f64, f64) -> (DVec3, DVec3),
    loops: &[(Loop, Role)],
    tol: f64,
) -> f64 {
    let e = estimate_trimmed_area(surface, [&[], &[]], loops, tol);
    assert!(
        e.certified(tol),
        "trimmed-area oracle did not reach tol {tol:e}: {e:?}"
    );
    e.area
}

/// [`trimmed_area`] with the details: `breaks` = [u, v] knot lines of the surface (interior
/// knots; may be empty) at which the integrals are split before adaptivity starts (see the
/// module notes); the result says how good it is instead of panicking.
pub fn estimate_trimmed_area(
    surface: &dyn Fn(f64, f64) -> (DVec3, DVec3),
    breaks: [&[f64]; 2],
    loops: &[(Loop, Role)],
    tol: f64,
) -> AreaEstimate {
    assert!(tol > 0.0 && tol.is_finite(), "tolerance must be positive");
    let evaluations = Cell::new(0usize);
    let inner_capped = Cell::new(0usize);
    let g = |u: f64, v: f64| {
        evaluations.set(evaluations.get() + 1);
        let (su, sv) = surface(u, v);
        su.cross(sv).length()
    };
    let v_variation: f64 = loops.iter().map(|(l, _)| l.v_variation).sum();
    let inner_tol = tol / (4.0 * v_variation);

    // G(u, v) = ∫_{u_ref}^{u} g(s, v) ds, split at the breaks strictly between the limits. A
    // capped inner integral makes the outer integrand NaN, which stops the outer integration:
    // the result could not be certified anyway.
    let inner = |u_ref: f64, u: f64, v: f64| -> (f64, f64) {
        if inner_capped.get() > 0 {
            return (f64::NAN, f64::NAN);
        }
        let (lo, hi, sign) = if u >= u_ref {
            (u_ref, u, 1.0)
        } else {
            (u, u_ref, -1.0)
        };
        if hi == lo {
            return (0.0, 0.0);
        }
        let mut cuts = vec![lo];
        cuts.extend(breaks[0].iter().copied().filter(|&x| x > lo && x < hi));
        cuts.push(hi);
        let pieces: Vec<(f64, f64)> = cuts.windows(2).map(|w| (w[0], w[1])).collect();
        let q = integrate_pieces(
            &mut |_, s| (g(s, v), 0.0),
            &pieces,
            inner_tol,
            MAX_INNER_INTERVALS,
        );
        if q.capped > 0 {
            inner_capped.set(inner_capped.get() + q.capped);
            return (f64::NAN, f64::NAN);
        }
        (sign * q.value, q.error)
    };

    // Every piece of every loop, with its loop's reference u and orientation factor.
    let mut pieces: Vec<(&Piece, f64, f64)> = Vec::new();
    for (l, role) in loops {
        let wanted = match role {
            Role::Outer => 1.0,
            Role::Hole => -1.0,
        };
        let factor = wanted * l.signed_area.signum();
        pieces.extend(l.pieces.iter().map(|p| (p, l.u_ref, factor)));
    }
    let integrand = |k: usize, t: f64| {
        let (piece, u_ref, factor) = pieces[k];
        let (c, d) = piece.eval(t);
        if d.y == 0.0 {
            return (0.0, 0.0);
        }
        let (value, error) = inner(u_ref, c.x, c.y);
        (factor * value * d.y, error * d.y.abs())
    };
    // The pieces cut where they cross a knot line; `owner[k]` is the piece of range k.
    let (mut ranges, mut owner) = (Vec::new(), Vec::new());
    for (k, (p, _, _)) in pieces.iter().enumerate() {
        let cuts = p.crossings(breaks);
        for w in cuts.windows(2) {
            ranges.push((w[0], w[1]));
            owner.push(k);
        }
    }
    let q = integrate_pieces(
        &mut |k, t| integrand(owner[k], t),
        &ranges,
        0.5 * tol,
        MAX_OUTER_INTERVALS,
    );
    AreaEstimate {
        area: q.value,
        error_estimate: q.error + q.carried,
        evaluations: evaluations.get(),
        capped: q.capped + inner_capped.get(),
        outer_intervals: q.intervals,
    }
}

// ---------------------------------------------------------------------------------------------
// Surfaces
// ---------------------------------------------------------------------------------------------

/// The plane O + u X + v Y: S_u = X, S_v = Y, so g = |X × Y| everywhere.
pub fn plane_partials(x: DVec3, y: DVec3) -> impl Fn(f64, f64) -> (DVec3, DVec3) {
    move |_, _| (x, y)
}

/// The bilinear patch (1−u)(1−v) P00 + u(1−v) P10 + (1−u)v P01 + uv P11 (a plane when the
/// corners form a parallelogram, a hyperbolic paraboloid otherwise).
pub fn bilinear_partials(
    p00: DVec3,
    p10: DVec3,
    p01: DVec3,
    p11: DVec3,
) -> impl Fn(f64, f64) -> (DVec3, DVec3) {
    move |u, v| {
        (
            (1.0 - v) * (p10 - p00) + v * (p11 - p01),
            (1.0 - u) * (p01 - p00) + u * (p11 - p10),
        )
    }
}

/// The cylinder R (cos u, sin u, 0) + (0, 0, v): |S_u × S_v| = R.
pub fn cylinder_partials(radius: f64) -> impl Fn(f64, f64) -> (DVec3, DVec3) {
    move |u, _| {
        let (s, c) = u.sin_cos();
        (radius * DVec3::new(-s, c, 0.0), DVec3::Z)
    }
}

/// The sphere R (cos u cos v, sin u cos v, sin v), u longitude, v latitude in [−π/2, π/2]:
/// |S_u × S_v| = R² cos v.
pub fn sphere_partials(radius: f64) -> impl Fn(f64, f64) -> (DVec3, DVec3) {
    move |u, v| {
        let (su, cu) = u.sin_cos();
        let (sv, cv) = v.sin_cos();
        (
            radius * DVec3::new(-su * cv, cu * cv, 0.0),
            radius * DVec3::new(-cu * sv, -su * sv, cv),
        )
    }
}

/// A tensor-product Bézier/B-spline/NURBS surface evaluated by the oracle's own evaluator
/// (`eval.rs`: curves of curves in homogeneous coordinates, quotient rule).
#[derive(Clone, Debug, PartialEq)]
pub struct TensorSurface {
    pub basis: [Basis; 2],
    /// `[i][j]`, i along u: (w·x, w·y, w·z, w).
    pub homogeneous: Vec<Vec<Homogeneous>>,
}

impl TensorSurface {
    pub fn new(
        basis: [Basis; 2],
        points: &[Vec<Point3>],
        weights: Option<&[Vec<f64>]>,
    ) -> TensorSurface {
        let homogeneous = points
            .iter()
            .enumerate()
            .map(|(i, row)| {
                row.iter()
                    .enumerate()
                    .map(|(j, &p)| homogeneous(p, weights.map_or(1.0, |w| w[i][j])))
                    .collect()
            })
            .collect();
        TensorSurface { basis, homogeneous }
    }

    /// [(u_min, u_max), (v_min, v_max)].
    pub fn domain(&self) -> [(f64, f64); 2] {
        [
            self.basis[0].domain(self.homogeneous.len()),
            self.basis[1].domain(self.homogeneous[0].len()),
        ]
    }

    /// The distinct knots strictly inside the domain of direction `dir` (0 = u, 1 = v).
    pub fn breaks(&self, dir: usize) -> Vec<f64> {
        let (a, b) = self.domain()[dir];
        let mut out: Vec<f64> = match &self.basis[dir] {
            Basis::Bezier => Vec::new(),
            Basis::BSpline { knots, .. } => {
                knots.iter().copied().filter(|&t| t > a && t < b).collect()
            }
        };
        out.dedup();
        out
    }

    fn derivatives(&self, u: f64, v: f64, n: usize) -> Vec<Vec<Point3>> {
        let h = tensor_derivatives(&self.basis[0], &self.basis[1], &self.homogeneous, u, v, n);
        project_surface_derivatives(&h)
    }

    pub fn point(&self, u: f64, v: f64) -> DVec3 {
        DVec3::from_array(self.derivatives(u, v, 0)[0][0])
    }

    /// (S_u, S_v).
    pub fn partials(&self, u: f64, v: f64) -> (DVec3, DVec3) {
        let d = self.derivatives(u, v, 1);
        (DVec3::from_array(d[1][0]), DVec3::from_array(d[0][1]))
    }
}
