//! Area and bounds of a mapped face: what prespline's `info` reports and what the checks
//! against OpenCASCADE compare.
//!
//! The loops are flattened (NURBS pieces within 1e-8 of the parameter box's diagonal) and
//! built into the trim crate's validated regions (closed within 1e-6 of the diagonal, no
//! crossings), which is also the check that every loop of a face is usable. The area is
//! `∫∫ |S_u × S_v|` over the trimmed domain by the trim crate's `integrate` on a uniform grid
//! over the loops' box (at least 64 cells and 4 per knot span in each direction, at most 512),
//! with the partial derivatives of the exact NURBS. The bounds are those of the surface points
//! at the grid samples inside the trim and at every vertex of the flattened boundary, each
//! coordinate's extreme sample then refined by a pattern search inside the trim.

use crate::geom::analytic::NurbsCurve;
use crate::geom::trim::{Coverage, Curve2, LoopInput, Piece, Tolerances, TrimRegions, integrate};
use glam::{DVec2, DVec3};

use super::nurbs::FastSurface;
use super::{CadCurve2, CadFace};

/// Area and bounds of a face.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Measure {
    /// ∫∫ |S_u × S_v| over the trimmed domain, in mm².
    pub area: f64,
    /// `(min, max)` corners, in mm.
    pub bounds: ([f64; 3], [f64; 3]),
}

/// A 2D NURBS piece for the trim crate's flattening.
struct Nurbs2 {
    curve: NurbsCurve,
    breaks: Vec<f64>,
}

impl Curve2 for Nurbs2 {
    fn domain(&self) -> (f64, f64) {
        self.curve.domain().map_or((0.0, 0.0), |[a, b]| (a, b))
    }
    fn point(&self, t: f64) -> DVec2 {
        self.curve
            .point(t)
            .map_or(DVec2::NAN, |p| DVec2::new(p.x, p.y))
    }
    fn breaks(&self) -> &[f64] {
        &self.breaks
    }
}

/// Flattens one loop into the trim crate's input.
fn loop_input(pieces: &[super::CadPiece], tol: f64) -> Result<LoopInput, String> {
    let mut out = Vec::with_capacity(pieces.len());
    for p in pieces {
        match &p.curve {
            CadCurve2::Polyline(v) => {
                let mut pts: Vec<DVec2> = v.iter().map(|q| DVec2::from(*q)).collect();
                if p.range.0 > p.range.1 {
                    pts.reverse();
                }
                out.push(pts);
            }
            CadCurve2::Nurbs {
                degree,
                knots,
                points,
                weights,
            } => {
                let curve = NurbsCurve {
                    degree: *degree,
                    knots: knots.clone(),
                    points: points.iter().map(|q| DVec3::new(q[0], q[1], 0.0)).collect(),
                    weights: weights.clone().unwrap_or_else(|| vec![1.0; points.len()]),
                };
                curve.validate().map_err(|e| e.to_string())?;
                let mut breaks: Vec<f64> = knots.clone();
                breaks.dedup();
                let c = Nurbs2 { curve, breaks };
                let mut pts = Vec::new();
                crate::geom::trim::flatten_piece(&Piece::Curve(&c, p.range), tol, &mut pts)
                    .map_err(|e| e.to_string())?;
                out.push(pts);
            }
        }
    }
    Ok(LoopInput {
        pieces: out,
        role: None,
    })
}

/// The face's validated trim regions (the check that every loop is usable).
pub(crate) fn regions(face: &CadFace) -> Result<TrimRegions, String> {
    let fast = FastSurface::new(&face.surface);
    let [du, dv] = fast.domain();
    let diag = DVec2::new(du[1] - du[0], dv[1] - dv[0]).length();
    let inputs: Vec<LoopInput> = face
        .loops
        .iter()
        .map(|l| loop_input(&l.pieces, 1e-8 * diag))
        .collect::<Result<_, _>>()?;
    TrimRegions::new(
        &inputs,
        [(du[0], du[1]), (dv[0], dv[1])],
        &Tolerances::default(),
    )
    .map_err(|e| e.to_string())
}

/// Grid samples over `[lo, hi]` of direction `k`: at least 64 cells and 4 per knot span.
#[must_use]
fn axis(knots: &[f64], lo: f64, hi: f64) -> Vec<f64> {
    let spans = {
        let mut k: Vec<f64> = knots
            .iter()
            .copied()
            .filter(|&x| x > lo && x < hi)
            .collect();
        k.dedup();
        k.len() + 1
    };
    let n = (4 * spans).clamp(64, 512);
    (0..=n)
        .map(|i| lo + (hi - lo) * (i as f64 / n as f64))
        .collect()
}

/// Area and bounds of `face` (see the module doc).
pub fn measure(face: &CadFace) -> Result<Measure, String> {
    face.surface
        .validate()
        .map_err(|e| format!("{}: {e}", face.name))?;
    let regions = regions(face).map_err(|e| format!("{}: {e}", face.name))?;
    let fast = FastSurface::new(&face.surface);
    let [du, dv] = fast.domain();
    let (lo, hi) = regions.bounds();
    // The grid is the loops' box widened a little: the trim crate's integration mishandles a
    // loop edge that lies exactly on the grid's last cell edge (found on trj5 #154).
    let pad = 1e-7 * (hi - lo);
    let (u0, u1) = (
        (lo.x - pad.x).max(du[0] - pad.x),
        (hi.x + pad.x).min(du[1] + pad.x),
    );
    let (v0, v1) = (
        (lo.y - pad.y).max(dv[0] - pad.y),
        (hi.y + pad.y).min(dv[1] + pad.y),
    );
    if !(u0 < u1 && v0 < v1) {
        return Err(format!("{}: the trim encloses no area", face.name));
    }
    let us = axis(&face.surface.knots[0], u0, u1);
    let vs = axis(&face.surface.knots[1], v0, v1);
    let cov = Coverage::new(&regions, &us, &vs).map_err(|e| format!("{}: {e}", face.name))?;
    let f = |u: f64, v: f64| fast.d1(u, v).map_or(0.0, |d| d.su.cross(d.sv).length());
    let area = integrate(&regions, &us, &vs, &cov, f).map_err(|e| format!("{}: {e}", face.name))?;
    let mut b = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    // The samples extreme in each coordinate, to be refined.
    let mut extreme = [(f64::NEG_INFINITY, DVec2::ZERO); 6];
    let mut add = |q: DVec2, inside: bool| {
        let Some(d) = fast.d1(q.x, q.y) else { return };
        b = (b.0.min(d.p), b.1.max(d.p));
        if inside {
            for (k, e) in extreme.iter_mut().enumerate() {
                let x = sign(k) * coord(d.p, k);
                if x > e.0 {
                    *e = (x, q);
                }
            }
        }
    };
    for (i, &u) in us.iter().enumerate() {
        for (j, &v) in vs.iter().enumerate() {
            if cov.sample_inside(i, j) {
                add(DVec2::new(u, v), true);
            }
        }
    }
    for l in regions.loops() {
        for q in l.points() {
            add(*q, false);
        }
    }
    let cell = DVec2::new(
        (u1 - u0) / (us.len().max(2) - 1) as f64,
        (v1 - v0) / (vs.len().max(2) - 1) as f64,
    );
    for (k, &(x, q)) in extreme.iter().enumerate() {
        if x.is_finite() {
            let best = climb(&fast, &regions, k, q, cell);
            b = (b.0.min(best), b.1.max(best));
        }
    }
    Ok(Measure {
        area,
        bounds: (b.0.to_array(), b.1.to_array()),
    })
}

/// Coordinate `k % 3` of `p`.
#[must_use]
fn coord(p: DVec3, k: usize) -> f64 {
    match k % 3 {
        0 => p.x,
        1 => p.y,
        _ => p.z,
    }
}

/// `+1` for the maxima (k = 3, 4, 5 → x, y, z), `−1` for the minima (k = 0, 1, 2).
#[must_use]
fn sign(k: usize) -> f64 {
    if k < 3 { -1.0 } else { 1.0 }
}

/// Pattern search from grid sample `q` for the extreme of coordinate `k % 3` (see [`sign`])
/// inside the trim: steps from one cell down to 1e-9 of it, to each of the 8 neighbours that
/// improves and stays inside. Interior extremes (a torus's top) lie between grid samples.
#[must_use]
fn climb(s: &FastSurface, regions: &TrimRegions, k: usize, mut q: DVec2, cell: DVec2) -> DVec3 {
    let value = |q: DVec2| s.point(q.x, q.y).map(|p| (sign(k) * coord(p, k), p));
    let Some((mut best, mut point)) = value(q) else {
        return DVec3::NAN;
    };
    let mut h = cell;
    for _ in 0..32 {
        let mut moved = false;
        for (du, dv) in [
            (1.0, 0.0),
            (-1.0, 0.0),
            (0.0, 1.0),
            (0.0, -1.0),
            (1.0, 1.0),
            (1.0, -1.0),
            (-1.0, 1.0),
            (-1.0, -1.0),
        ] {
            let c = q + DVec2::new(du * h.x, dv * h.y);
            if !regions.contains(c) {
                continue;
            }
            if let Some((x, p)) = value(c)
                && x > best
            {
                (best, point, q, moved) = (x, p, c, true);
            }
        }
        if !moved {
            h *= 0.5;
        }
    }
    point
}
