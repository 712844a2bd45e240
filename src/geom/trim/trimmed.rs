//! A surface's trim as given together with the regions it bounds: built once, when the object
//! is read, against the surface's parameter domain, and carried unchanged through every edit
//! (point moves, weights, knot insertion and degree elevation keep the parametrisation).

use super::curve::{Curve2, Piece};
use super::error::TrimError;
use super::loops::{LoopInput, Tolerances};
use super::regions::TrimRegions;
use super::spec::{Trim, TrimCurve};
use glam::DVec2;
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

    /// For splines: the largest |c''| of 33 evenly spaced points of the span, plus a fifth (a
    /// span's second derivative varies smoothly; flattening checks every piece's midpoint
    /// besides, and bisects where the bound fell short).
    fn second_derivative_bound(&self, t0: f64, t1: f64) -> Option<f64> {
        let TrimCurve::Spline(c) = self else {
            return None;
        };
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

impl Trimmed {
    /// Validates `spec` against the surface's parameter `domain` and classifies its loops (see
    /// `loops` and `regions` for the rules); an error names the loop and curve.
    pub fn new(spec: Trim, domain: [(f64, f64); 2]) -> Result<Self, TrimError> {
        if spec.loops.is_empty() {
            return Err(TrimError::NoLoops);
        }
        let tol = flatten_tolerance(domain);
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
        let regions = TrimRegions::new(&inputs, domain, &Tolerances::default())?;
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
