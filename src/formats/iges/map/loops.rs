//! Traced pieces → closed [`CadLoop`]s: pieces are oriented head to tail, ends that miss by at
//! most [`SNAP`] × the domain diagonal are moved to their midpoint (files round their curve ends
//! independently), and a larger gap whose two ends are the same point of the surface (a pole or
//! an apex, where a boundary edge degenerates to a point in model space) is bridged by a straight
//! piece. What still does not close is left for the trim check to refuse, naming the gap.

use crate::geom::analytic::NurbsSurface;
use glam::{DVec2, DVec3};

use super::trace::Traced;
use crate::formats::cad::{CadCurve2, CadLoop, CadPiece};

/// Largest gap closed by moving curve ends, relative to the parameter domain's diagonal.
pub const SNAP: f64 = 1e-4;

/// Gaps below this (relative to the diagonal) are rounding, closed without being reported.
const ROUNDING: f64 = 1e-12;

/// Relative 3D distance under which two parameter points are the same surface point.
const SAME_POINT: f64 = 1e-7;

/// What assembling a loop changed.
#[derive(Debug, Default, Clone, Copy)]
pub(crate) struct Repairs {
    /// Gaps closed by moving ends, and the largest (parameter units).
    pub snapped: usize,
    pub largest: f64,
    /// Degenerate edges bridged.
    pub bridged: usize,
}

fn ends(t: &Traced) -> (DVec2, DVec2) {
    t.ends().unwrap_or((DVec2::NAN, DVec2::NAN))
}

fn flip(t: &mut Traced) {
    match t {
        Traced::Poly(p) => p.reverse(),
        Traced::Exact { range, .. } => *range = (range.1, range.0),
    }
}

/// Moves the traversal start (`at_start`) or end of a piece to `m`. Exact curves are clamped, so
/// their end control point is their end point.
fn move_end(t: &mut Traced, at_start: bool, m: DVec2) {
    match t {
        Traced::Poly(p) => {
            let slot = if at_start {
                p.first_mut()
            } else {
                p.last_mut()
            };
            if let Some(q) = slot {
                *q = m;
            }
        }
        Traced::Exact { curve, range } => {
            let first_cp = (range.0 <= range.1) == at_start;
            let slot = if first_cp {
                curve.points.first_mut()
            } else {
                curve.points.last_mut()
            };
            if let Some(q) = slot {
                *q = DVec3::new(m.x, m.y, 0.0);
            }
        }
    }
}

/// Turns each piece so that it starts where the previous one ends (the first so that it ends
/// where the second lies).
fn orient(pieces: &mut [Traced]) {
    if let [first, second, ..] = pieces {
        let ((s0, e0), (s1, e1)) = (ends(first), ends(second));
        let d_end = e0.distance(s1).min(e0.distance(e1));
        let d_start = s0.distance(s1).min(s0.distance(e1));
        if d_start < d_end {
            flip(first);
        }
    }
    for k in 1..pieces.len() {
        let (head, tail) = pieces.split_at_mut(k);
        if let (Some(prev), Some(cur)) = (head.last(), tail.first_mut()) {
            let prev_end = ends(prev).1;
            let (s, e) = ends(cur);
            if prev_end.distance(e) < prev_end.distance(s) {
                flip(cur);
            }
        }
    }
}

/// Orients, snaps and bridges one loop's pieces.
pub(crate) fn assemble(
    mut pieces: Vec<Traced>,
    surface: &NurbsSurface,
    diagonal: f64,
    repairs: &mut Repairs,
) -> Vec<Traced> {
    orient(&mut pieces);
    let n = pieces.len();
    // Junction k joins the end of piece k to the start of piece k + 1 (cyclically).
    let starts: Vec<DVec2> = pieces.iter().map(|p| ends(p).0).collect();
    let junctions: Vec<(DVec2, DVec2)> = pieces
        .iter()
        .enumerate()
        .map(|(k, p)| {
            (
                ends(p).1,
                starts.get((k + 1) % n).copied().unwrap_or(DVec2::NAN),
            )
        })
        .collect();
    let snapped: Vec<Option<DVec2>> = junctions
        .iter()
        .map(|&(end, start)| {
            let gap = end.distance(start);
            if gap > ROUNDING * diagonal && gap <= SNAP * diagonal {
                repairs.snapped += 1;
                repairs.largest = repairs.largest.max(gap);
            }
            (gap > 0.0 && gap <= SNAP * diagonal).then(|| 0.5 * (end + start))
        })
        .collect();
    for (k, piece) in pieces.iter_mut().enumerate() {
        if let Some(Some(m)) = snapped.get((k + n - 1) % n) {
            move_end(piece, true, *m);
        }
        if let Some(Some(m)) = snapped.get(k) {
            move_end(piece, false, *m);
        }
    }
    let scale = surface.extent().max(f64::MIN_POSITIVE);
    let same_point = |a: DVec2, b: DVec2| match (surface.point(a.x, a.y), surface.point(b.x, b.y)) {
        (Ok(p), Ok(q)) => p.distance(q) <= SAME_POINT * scale,
        _ => false,
    };
    let mut out: Vec<Traced> = Vec::with_capacity(n + 2);
    for (piece, &(end, start)) in pieces.into_iter().zip(&junctions) {
        out.push(piece);
        if end.distance(start) > SNAP * diagonal && same_point(end, start) {
            out.push(Traced::Poly(vec![end, start]));
            repairs.bridged += 1;
        }
    }
    out
}

/// The traced pieces as output pieces.
#[must_use]
pub(crate) fn to_cad(pieces: Vec<Traced>) -> Vec<CadPiece> {
    pieces
        .into_iter()
        .map(|t| match t {
            Traced::Poly(p) => CadPiece {
                range: (0.0, p.len().saturating_sub(1) as f64),
                curve: CadCurve2::Polyline(p.iter().map(|q| q.to_array()).collect()),
            },
            Traced::Exact { curve, range } => {
                let rational = curve.weights.iter().any(|&w| w != 1.0);
                CadPiece {
                    range,
                    curve: CadCurve2::Nurbs {
                        degree: curve.degree,
                        knots: curve.knots,
                        points: curve.points.iter().map(|p| [p.x, p.y]).collect(),
                        weights: rational.then_some(curve.weights),
                    },
                }
            }
        })
        .collect()
}

/// The whole NURBS domain as a loop (the outer boundary of a 144 with `N1 = 0` and holes).
#[must_use]
pub(crate) fn domain_loop(dom: [[f64; 2]; 2]) -> CadLoop {
    let [[u0, u1], [v0, v1]] = dom;
    CadLoop {
        outer: true,
        pieces: vec![CadPiece {
            curve: CadCurve2::Polyline(vec![[u0, v0], [u1, v0], [u1, v1], [u0, v1], [u0, v0]]),
            range: (0.0, 4.0),
        }],
    }
}
