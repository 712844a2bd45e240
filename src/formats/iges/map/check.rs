//! The trim crate's view of a face: loops flattened and built into validated regions, and what
//! the checks against OpenCASCADE measure on them (trimmed area, bounds of what is drawn). The
//! mapping itself uses [`regions`] to classify loops and to refuse a face whose loops the viewer
//! would refuse, so every face it returns is one the trim crate accepts.

use crate::geom::analytic::{NurbsCurve, NurbsSurface};
use crate::geom::trim::{Coverage, Curve2, LoopInput, Tolerances, TrimRegions, integrate};
use glam::{DVec2, DVec3};

use super::eval::{CurveEvaluator, Evaluator};
use super::trace::FLATTEN;
use crate::formats::cad::{CadCurve2, CadFace, CadLoop};

/// A 2D NURBS for the trim crate's flattening.
struct Flat<'c> {
    curve: CurveEvaluator<'c>,
    breaks: Vec<f64>,
}

impl Curve2 for Flat<'_> {
    fn domain(&self) -> (f64, f64) {
        self.curve.domain()
    }
    fn point(&self, t: f64) -> DVec2 {
        self.curve.point(t).map_or(DVec2::NAN, |p| p.truncate())
    }
    fn breaks(&self) -> &[f64] {
        &self.breaks
    }
}

/// The 3D form (z = 0) of a 2D NURBS.
fn curve3(
    degree: usize,
    knots: &[f64],
    points: &[[f64; 2]],
    weights: Option<&Vec<f64>>,
) -> NurbsCurve {
    NurbsCurve {
        degree,
        knots: knots.to_vec(),
        points: points.iter().map(|p| DVec3::new(p[0], p[1], 0.0)).collect(),
        weights: weights.cloned().unwrap_or_else(|| vec![1.0; points.len()]),
    }
}

fn flat(curve: &NurbsCurve) -> Result<Flat<'_>, String> {
    let ev = CurveEvaluator::new(curve)?;
    let (lo, hi) = ev.domain();
    let mut breaks: Vec<f64> = curve
        .knots
        .iter()
        .copied()
        .filter(|&k| k > lo && k < hi)
        .collect();
    breaks.dedup();
    Ok(Flat { curve: ev, breaks })
}

/// The parameter domain `[(u0, u1), (v0, v1)]` of a surface.
pub fn domain(s: &NurbsSurface) -> Result<[(f64, f64); 2], String> {
    let [[u0, u1], [v0, v1]] = s.domain().map_err(|e| e.to_string())?;
    Ok([(u0, u1), (v0, v1)])
}

/// One loop flattened within `tol` (parameter units) for the trim crate.
pub fn loop_input(l: &CadLoop, tol: f64) -> Result<LoopInput, String> {
    let mut pieces = Vec::with_capacity(l.pieces.len());
    for p in &l.pieces {
        let points = match &p.curve {
            CadCurve2::Polyline(pts) => {
                let mut v: Vec<DVec2> = pts.iter().map(|q| DVec2::from_array(*q)).collect();
                if p.range.0 > p.range.1 {
                    v.reverse();
                }
                v
            }
            CadCurve2::Nurbs {
                degree,
                knots,
                points,
                weights,
            } => {
                let c = curve3(*degree, knots, points, weights.as_ref());
                let f = flat(&c)?;
                let mut out = Vec::new();
                crate::geom::trim::curve::flatten(&f, p.range, tol, &mut out)
                    .map_err(|e| e.to_string())?;
                out
            }
        };
        pieces.push(points);
    }
    Ok(LoopInput { pieces, role: None })
}

/// The validated, classified regions of a face's loops (`None` for an untrimmed face), with the
/// trim crate's default tolerances and flattening at [`crate::FLATTEN`] × the domain diagonal.
pub fn regions(surface: &NurbsSurface, loops: &[CadLoop]) -> Result<Option<TrimRegions>, String> {
    if loops.is_empty() {
        return Ok(None);
    }
    let dom = domain(surface)?;
    let diagonal = (dom[0].1 - dom[0].0).hypot(dom[1].1 - dom[1].0);
    let tol = FLATTEN * diagonal;
    let inputs = loops
        .iter()
        .map(|l| loop_input(l, tol))
        .collect::<Result<Vec<_>, _>>()?;
    TrimRegions::new(&inputs, dom, &Tolerances::default())
        .map(Some)
        .map_err(|e| e.to_string())
}

/// A uniform sample axis (the trim crate's coverage needs one) of at least `min_cells` cells and
/// at least 8 per knot span, at most 4096. It is shifted off the domain by small, unequal,
/// irrational fractions of a cell at its two ends: trims commonly run exactly along the domain's
/// edges and along knot lines (the middle of a revolution's angle range), and the trim crate's
/// integral of a cell is wrong when a boundary segment lies exactly on a grid line (a whole
/// column counted or not: 1.5 % of a face on 64 cells; see the report).
fn grid(knots: &[f64], lo: f64, hi: f64, min_cells: usize) -> Vec<f64> {
    let mut inner: Vec<f64> = knots
        .iter()
        .copied()
        .filter(|&k| k > lo && k < hi)
        .collect();
    inner.dedup();
    let cells = min_cells.max(8 * (inner.len() + 1)).min(4096);
    let h = (hi - lo) / cells as f64;
    let (a, b) = (
        lo - (std::f64::consts::SQRT_2 - 1.0) * 1e-3 * h,
        hi + (std::f64::consts::E - 2.0) * 1e-3 * h,
    );
    (0..=cells)
        .map(|k| a + (b - a) * k as f64 / cells as f64)
        .collect()
}

/// What is measured on one face.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Metrics {
    /// `∫∫ |S_u × S_v|` over the trimmed domain, in mm².
    pub area: f64,
    /// Bounds of the drawn face: inside samples of a dense grid and the boundary polygons.
    pub lo: DVec3,
    pub hi: DVec3,
}

/// Area and bounds of a face, with `min_cells` grid lines at least per direction.
pub fn metrics(face: &CadFace, min_cells: usize) -> Result<Metrics, String> {
    let s = &face.surface;
    let dom = domain(s)?;
    let u = grid(&s.knots[0], dom[0].0, dom[0].1, min_cells);
    let v = grid(&s.knots[1], dom[1].0, dom[1].1, min_cells);
    let loops = if face.loops.is_empty() {
        vec![super::loops::domain_loop([
            [dom[0].0, dom[0].1],
            [dom[1].0, dom[1].1],
        ])]
    } else {
        face.loops.clone()
    };
    let regions = regions(s, &loops)?.ok_or("no loops")?;
    let coverage = Coverage::new(&regions, &u, &v).map_err(|e| e.to_string())?;
    let ev = Evaluator::new(s)?;
    let dens = |a: f64, b: f64| {
        ev.eval(a, b)
            .map_or(0.0, |[_, su, sv]| su.cross(sv).length())
    };
    let area = integrate(&regions, &u, &v, &coverage, dens).map_err(|e| e.to_string())?;
    let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    let mut add = |a: f64, b: f64| {
        if let Some([p, _, _]) = ev.eval(a, b) {
            lo = lo.min(p);
            hi = hi.max(p);
        }
    };
    for (i, &a) in u.iter().enumerate() {
        for (j, &b) in v.iter().enumerate() {
            if coverage.sample_inside(i, j) {
                add(a, b);
            }
        }
    }
    for l in regions.loops() {
        for p in l.points() {
            add(p.x, p.y);
        }
    }
    Ok(Metrics { area, lo, hi })
}
