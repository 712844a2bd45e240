//! A trim as a file gives it: loops of curves in a surface's parameter space, each curve a
//! line, a polyline or a 2D Bézier/B-spline/NURBS curve over a range of its parameter. This is
//! what is read, written back and carried through edits; the validated, classified regions
//! and what the samples and cells see of them are built from it (`regions`, `coverage`).
//!
//! Parameter-space curves are B-spline curves with z = 0, so one evaluator (de Boor in
//! homogeneous coordinates, `geom::bspline`) serves trims and space curves alike.

use super::loops::Role;
use crate::geom::bspline::BSplineCurve;
use crate::geom::error::{GeomError, GeomResult};
use crate::geom::knots::KnotVector;
use glam::{DVec2, DVec3};

/// One curve of a trim loop, in the surface's (u, v).
#[derive(Debug, Clone, PartialEq)]
pub enum TrimCurve {
    /// Straight segments through the points in order (two points: a line), parameter t ∈
    /// [0, n − 1] with point k at t = k.
    Polyline(Vec<DVec2>),
    /// A 2D B-spline or NURBS curve (a Bézier curve is one clamped span on [0, 1]), stored with
    /// z = 0.
    Spline(BSplineCurve),
}

impl TrimCurve {
    /// A polyline through at least two finite points.
    pub fn polyline(points: Vec<DVec2>) -> GeomResult<Self> {
        if points.len() < 2 {
            return Err(GeomError::new(
                "points",
                format!(
                    "a line or polyline needs at least 2 points, found {}",
                    points.len()
                ),
            ));
        }
        if let Some(k) = points.iter().position(|p| !p.is_finite()) {
            return Err(GeomError::new("points", format!("point {k} is not finite")));
        }
        Ok(Self::Polyline(points))
    }

    /// A 2D B-spline (NURBS with weights) curve of `degree` over `knots`.
    pub fn bspline(
        degree: usize,
        knots: Vec<f64>,
        points: &[DVec2],
        weights: Option<Vec<f64>>,
    ) -> GeomResult<Self> {
        let p3 = points.iter().map(|p| p.extend(0.0)).collect();
        BSplineCurve::new(degree, knots, p3, weights).map(Self::Spline)
    }

    /// A 2D Bézier curve on [0, 1] (rational with weights).
    pub fn bezier(points: &[DVec2], weights: Option<Vec<f64>>) -> GeomResult<Self> {
        let d = points
            .len()
            .checked_sub(1)
            .filter(|&d| d >= 1)
            .ok_or_else(|| GeomError::new("points", "a Bézier curve needs at least 2 points"))?;
        Self::bspline(
            d,
            KnotVector::bezier(d, 0.0, 1.0).into_vec(),
            points,
            weights,
        )
    }

    /// The parameter domain.
    #[must_use]
    pub fn domain(&self) -> (f64, f64) {
        match self {
            Self::Polyline(p) => (0.0, p.len().saturating_sub(1) as f64),
            Self::Spline(c) => c.domain(),
        }
    }

    /// The point at parameter `t` (clamped to the domain).
    #[must_use]
    pub fn point(&self, t: f64) -> DVec2 {
        match self {
            Self::Polyline(p) => {
                let last = p.len().saturating_sub(1);
                let t = t.clamp(0.0, last as f64);
                let k = (t.floor() as usize).min(last.saturating_sub(1));
                let (a, b) = (p[k], p[(k + 1).min(last)]);
                a.lerp(b, t - k as f64)
            }
            Self::Spline(c) => spline_point(c, t),
        }
    }

    /// Whether evaluation is exact on straight pieces (no flattening needed).
    #[must_use]
    pub fn is_straight(&self) -> bool {
        match self {
            Self::Polyline(_) => true,
            Self::Spline(c) => c.degree() == 1 && c.weights().is_none(),
        }
    }

    /// The control points (polyline vertices), in (u, v).
    #[must_use]
    pub fn points(&self) -> Vec<DVec2> {
        match self {
            Self::Polyline(p) => p.clone(),
            Self::Spline(c) => c.points().iter().map(|p| p.truncate()).collect(),
        }
    }
}

/// Degrees up to which [`spline_point`] runs de Boor's algorithm in a stack array.
const STACK_DEGREE: usize = 15;

/// The 2D point of `c` at `t` (clamped to the domain): de Boor's algorithm on the active
/// control points in homogeneous (wx, wy, w) form, in a stack array — flattening a trim
/// evaluates its curves thousands of times, and `BSplineCurve::eval` allocates per call.
fn spline_point(c: &BSplineCurve, t: f64) -> DVec2 {
    let p = c.degree();
    if p > STACK_DEGREE {
        let (a, b) = c.domain();
        return c.eval(t.clamp(a, b)).truncate();
    }
    let (points, knots) = (c.points(), c.knots());
    let n = points.len();
    let (a, b) = knots.domain(p, n);
    let t = t.clamp(a, b);
    let k = knots.find_span(p, n, t);
    let w = |i: usize| c.weights().and_then(|w| w.get(i).copied()).unwrap_or(1.0);
    let mut d = [DVec3::ZERO; STACK_DEGREE + 1];
    for (j, slot) in d.iter_mut().enumerate().take(p + 1) {
        let i = k - p + j;
        let wi = w(i);
        *slot = DVec3::new(points[i].x * wi, points[i].y * wi, wi);
    }
    for r in 1..=p {
        for j in (r..=p).rev() {
            let lo = knots[j + k - p];
            let alpha = (t - lo) / (knots[j + 1 + k - r] - lo);
            d[j] = d[j - 1] * (1.0 - alpha) + d[j] * alpha;
        }
    }
    d[p].truncate() / d[p].z
}

/// A curve over a range of its parameter; `range.0 > range.1` runs it backwards (OBJ, IGES and
/// STEP all write reversed edges that way).
#[derive(Debug, Clone, PartialEq)]
pub struct TrimPiece {
    pub curve: TrimCurve,
    pub range: (f64, f64),
}

impl TrimPiece {
    /// The whole curve, forwards.
    #[must_use]
    pub fn whole(curve: TrimCurve) -> Self {
        let range = curve.domain();
        Self { curve, range }
    }

    /// Checks that the range is finite, non-empty and inside the curve's domain.
    pub fn check(&self) -> GeomResult<()> {
        let (a, b) = self.range;
        let (lo, hi) = self.curve.domain();
        let slack = 1e-9 * (hi - lo).abs().max(1.0);
        if !a.is_finite() || !b.is_finite() || a == b {
            return Err(GeomError::new(
                "range",
                format!("[{a}, {b}] is not a non-empty range"),
            ));
        }
        if a.min(b) < lo - slack || a.max(b) > hi + slack {
            return Err(GeomError::new(
                "range",
                format!("[{a}, {b}] reaches outside the curve's domain [{lo}, {hi}]"),
            ));
        }
        Ok(())
    }
}

/// A closed chain of pieces, each starting where the one before ends, with what the file
/// says it is (OBJ `trim`/`hole`, STEP `FACE_OUTER_BOUND`); `None` leaves it to nesting.
#[derive(Debug, Clone, PartialEq)]
pub struct LoopSpec {
    pub pieces: Vec<TrimPiece>,
    pub role: Option<Role>,
}

/// Every loop of one surface, as given.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Trim {
    pub loops: Vec<LoopSpec>,
}

impl Trim {
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.loops.is_empty()
    }
}
