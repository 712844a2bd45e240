//! A surface's trim as given together with the regions it bounds: built once, when the object
//! is read, against the surface's parameter domain, and carried unchanged through every edit
//! (point moves, weights, knot insertion and degree elevation keep the parametrisation).

use super::curve::{Curve2, Piece};
use super::error::TrimError;
use super::loops::{LoopInput, Tolerances};
use super::regions::TrimRegions;
use super::spec::{Trim, TrimCurve};
use crate::geom::bspline::BSplineCurve;
use glam::{DVec2, DVec3};
use std::sync::Arc;

/// The flattening tolerance, as a fraction of the parameter domain's diagonal: every point of
/// a trim curve lies this close to the polyline that is drawn (areas are exact regardless:
/// `scene::measure` adds the lens between each chord and its curve). A 1280-pixel view of the
/// whole surface puts a pixel at about 1e-3 of it, so the boundary stays within a pixel until
/// a zoom of 2,500×. It stays below the gap tolerance (1e-6), as flattening must; the number
/// of segments goes as its inverse square root, and building a model's trims with it (the
/// 200-face benchmark, docs/performance.md) is what sets it.
pub const FLATTEN_TOLERANCE: f64 = 4e-7;

/// The flattening tolerance in parameter units for a surface of parameter `domain`.
#[must_use]
pub fn flatten_tolerance(domain: [(f64, f64); 2]) -> f64 {
    FLATTEN_TOLERANCE * (domain[0].1 - domain[0].0).hypot(domain[1].1 - domain[1].0)
}

impl Curve2 for TrimCurve {
    fn domain(&self) -> (f64, f64) {
        TrimCurve::domain(self)
    }

    fn point(&self, t: f64) -> DVec2 {
        TrimCurve::point(self, t)
    }

    /// For polynomial splines, exact: c'' is a B-spline of degree p − 2 whose control points
    /// are the second differences of the curve's (The NURBS Book eq. 3.8 twice), and on a span
    /// |c''| is at most the largest of the p − 1 that act there (convex hull; on cubics the
    /// bound is attained, c'' being linear). For rational splines: the largest |c''| of 33
    /// evenly spaced points of the span, plus a fifth (a span's second derivative varies
    /// smoothly; flattening checks every piece's midpoint besides, and bisects where the bound
    /// fell short).
    fn second_derivative_bound(&self, t0: f64, t1: f64) -> Option<f64> {
        let TrimCurve::Spline(c) = self else {
            return None;
        };
        if !c.is_rational() {
            return polynomial_second_derivative_bound(c, t0, t1);
        }
        let mut m: f64 = 0.0;
        for k in 0..=32 {
            let t = t0 + (t1 - t0) * f64::from(k) / 32.0;
            let d = c.derivatives(t, 2);
            m = m.max(d.get(2)?.truncate().length());
        }
        (m.is_finite()).then_some(1.2 * m)
    }

    fn breaks(&self) -> &[f64] {
        match self {
            TrimCurve::Polyline(_) => &[],
            TrimCurve::Spline(c) => {
                let k = c.knots().as_slice();
                let d = c.degree();
                k.get(d + 1..k.len().saturating_sub(d + 1)).unwrap_or(&[])
            }
        }
    }
}

/// The hull bound of |c''| over `[t0, t1]` of a polynomial B-spline (see
/// [`Curve2::second_derivative_bound`] for [`TrimCurve`]).
fn polynomial_second_derivative_bound(c: &BSplineCurve, t0: f64, t1: f64) -> Option<f64> {
    let p = c.degree();
    if p < 2 {
        return Some(0.0);
    }
    let u = c.knots().as_slice();
    let pts = c.points();
    let n = pts.len();
    let first = |i: usize| -> Option<DVec3> {
        let den = u.get(i + p + 1)? - u.get(i + 1)?;
        Some(if den > 0.0 {
            (*pts.get(i + 1)? - *pts.get(i)?) * (p as f64 / den)
        } else {
            DVec3::ZERO
        })
    };
    let second = |i: usize| -> Option<f64> {
        let den = u.get(i + p + 1)? - u.get(i + 2)?;
        Some(if den > 0.0 {
            ((first(i + 1)? - first(i)?) * ((p - 1) as f64 / den)).length()
        } else {
            0.0
        })
    };
    let lo = c.find_span(t0.min(t1));
    let mut hi = c.find_span(t0.max(t1));
    if hi > lo && u.get(hi).copied() == Some(t0.max(t1)) {
        hi -= 1;
    }
    let mut m: f64 = 0.0;
    for i in lo.saturating_sub(p)..=hi.saturating_sub(2).min(n.saturating_sub(3)) {
        m = m.max(second(i)?);
    }
    m.is_finite().then_some(m)
}

/// The vertices of the polyline `v` (vertex k at parameter k) over `range`, in its direction:
/// the two ends and every vertex strictly between them.
fn polyline_part(v: &[DVec2], range: (f64, f64)) -> Vec<DVec2> {
    let curve = TrimCurve::Polyline(v.to_vec());
    let (a, b) = (range.0.min(range.1), range.0.max(range.1));
    let mut out = vec![curve.point(a)];
    let first = a.floor() as i64 + 1;
    let last = b.ceil() as i64 - 1;
    for k in first.max(0)..=last.min(v.len() as i64 - 1) {
        if let Some(&p) = v.get(k as usize) {
            out.push(p);
        }
    }
    out.push(curve.point(b));
    out.dedup();
    if range.0 > range.1 {
        out.reverse();
    }
    out
}

/// A trim and its regions. Equal when the trims as given are.
#[derive(Debug, Clone)]
pub struct Trimmed {
    spec: Trim,
    regions: Arc<TrimRegions>,
}

impl PartialEq for Trimmed {
    fn eq(&self, other: &Self) -> bool {
        self.spec == other.spec
    }
}

/// The regions of `spec` on `domain` with its curves flattened within `tol` (polylines are
/// taken as they are): [`Trimmed::new`] at [`flatten_tolerance`], measures at a coarser one.
pub fn regions_at(
    spec: &Trim,
    domain: [(f64, f64); 2],
    tol: f64,
) -> Result<TrimRegions, TrimError> {
    if spec.loops.is_empty() {
        return Err(TrimError::NoLoops);
    }
    let mut inputs = Vec::with_capacity(spec.loops.len());
    for (k, l) in spec.loops.iter().enumerate() {
        if l.pieces.is_empty() {
            return Err(TrimError::EmptyLoop { loop_index: k });
        }
        // Polylines as their vertices over the range (exact, no flattening).
        let straight: Vec<Option<Vec<DVec2>>> = l
            .pieces
            .iter()
            .map(|p| match &p.curve {
                TrimCurve::Polyline(v) => Some(polyline_part(v, p.range)),
                TrimCurve::Spline(_) => None,
            })
            .collect();
        let pieces: Vec<Piece<'_>> = l
            .pieces
            .iter()
            .zip(&straight)
            .map(|(p, s)| match s {
                Some(points) => Piece::Points(points),
                None => Piece::Curve(&p.curve as &dyn Curve2, p.range),
            })
            .collect();
        inputs.push(LoopInput::from_pieces(k, &pieces, l.role, tol)?);
    }
    TrimRegions::new(&inputs, domain, &Tolerances::default())
}

impl Trimmed {
    /// Validates `spec` against the surface's parameter `domain` and classifies its loops (see
    /// `loops` and `regions` for the rules); an error names the loop and curve.
    pub fn new(spec: Trim, domain: [(f64, f64); 2]) -> Result<Self, TrimError> {
        let regions = regions_at(&spec, domain, flatten_tolerance(domain))?;
        Ok(Self {
            spec,
            regions: Arc::new(regions),
        })
    }

    /// The trim as given (what files write back).
    #[must_use]
    pub fn spec(&self) -> &Trim {
        &self.spec
    }

    /// The validated, classified loops.
    #[must_use]
    pub fn regions(&self) -> &TrimRegions {
        &self.regions
    }
}
