//! Tests of the trim module, with the shapes and independent references they share.
//!
//! Every comparison has a negative control: the same check on a perturbed input must fail, so a
//! check that cannot fail is caught. Comparisons are NaN-aware (`close` is false for NaN).

use std::f64::consts::{FRAC_1_SQRT_2, TAU};

use glam::DVec2;

use super::{Curve2, LoopInput, Piece, Role, Tolerances, TrimError, TrimRegions};

mod area_tests;
mod coverage_tests;
mod curve_tests;
mod loops_tests;

pub(super) const UNIT: [(f64, f64); 2] = [(0.0, 1.0), (0.0, 1.0)];

/// `|a - b| <= tol`, false when either is NaN.
pub(super) fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

/// SplitMix64: a small deterministic generator, so failures reproduce.
pub(super) struct Rng(pub u64);

impl Rng {
    pub(super) fn next_f64(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        (z ^ (z >> 31)) as f64 / u64::MAX as f64
    }

    pub(super) fn point(&mut self, lo: DVec2, hi: DVec2) -> DVec2 {
        let (x, y) = (self.next_f64(), self.next_f64());
        lo + (hi - lo) * DVec2::new(x, y)
    }
}

/// Counter-clockwise rectangle.
pub(super) fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<DVec2> {
    [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
        .iter()
        .map(|&(x, y)| DVec2::new(x, y))
        .collect()
}

/// A loop of one polyline piece: `points` and back to the first.
pub(super) fn one_piece(mut points: Vec<DVec2>, role: Option<Role>) -> LoopInput {
    if let Some(&first) = points.first() {
        points.push(first);
    }
    LoopInput {
        pieces: vec![points],
        role,
    }
}

pub(super) fn reversed(mut points: Vec<DVec2>) -> Vec<DVec2> {
    points.reverse();
    points
}

/// Regions on the unit square with the default tolerances.
pub(super) fn build(loops: &[LoopInput]) -> Result<TrimRegions, TrimError> {
    TrimRegions::new(loops, UNIT, &Tolerances::default())
}

/// Winding number of a closed polygon at `p` by summing the angles its edges subtend: an
/// independent method (no ray casting, no slabs).
pub(super) fn angle_winding(poly: &[DVec2], p: DVec2) -> i32 {
    let mut total = 0.0;
    for (k, &a) in poly.iter().enumerate() {
        let b = poly[(k + 1) % poly.len()];
        let (da, db) = (a - p, b - p);
        total += da.perp_dot(db).atan2(da.dot(db));
    }
    (total / TAU).round() as i32
}

/// Brute-force inside test of nested, non-crossing polygons: an odd number of them around `p`.
pub(super) fn brute_inside(polys: &[Vec<DVec2>], p: DVec2) -> bool {
    polys
        .iter()
        .filter(|poly| angle_winding(poly, p) != 0)
        .count()
        % 2
        == 1
}

/// Distance from `p` to the nearest edge of any polygon.
pub(super) fn boundary_distance(polys: &[Vec<DVec2>], p: DVec2) -> f64 {
    let mut best = f64::INFINITY;
    for poly in polys {
        for (k, &a) in poly.iter().enumerate() {
            let b = poly[(k + 1) % poly.len()];
            best = best.min(super::curve::point_segment_distance(p, a, b));
        }
    }
    best
}

/// A circle evaluated by cos/sin, `t` in `[0, 2π]`.
pub(super) struct Circle {
    pub c: DVec2,
    pub r: f64,
}

impl Curve2 for Circle {
    fn domain(&self) -> (f64, f64) {
        (0.0, TAU)
    }

    fn point(&self, t: f64) -> DVec2 {
        self.c + self.r * DVec2::new(t.cos(), t.sin())
    }
}

/// A full circle as four rational quadratic Bézier arcs (weights 1, √2/2, 1), `t` in `[0, 4]`,
/// arc `k` on `[k, k+1]`: the exact circle of NURBS files.
pub(super) struct BezierCircle {
    pub c: DVec2,
    pub r: f64,
}

impl Curve2 for BezierCircle {
    fn domain(&self) -> (f64, f64) {
        (0.0, 4.0)
    }

    fn point(&self, t: f64) -> DVec2 {
        let k = t.floor().clamp(0.0, 3.0);
        let s = t - k;
        let dir = |m: f64| {
            let a = m * TAU / 4.0;
            DVec2::new(a.cos().round(), a.sin().round())
        };
        let (d0, d2) = (dir(k), dir(k + 1.0));
        let (p0, p1, p2) = (
            self.c + self.r * d0,
            self.c + self.r * (d0 + d2),
            self.c + self.r * d2,
        );
        let (b0, b1, b2) = (
            (1.0 - s) * (1.0 - s),
            2.0 * s * (1.0 - s) * FRAC_1_SQRT_2,
            s * s,
        );
        (b0 * p0 + b1 * p1 + b2 * p2) / (b0 + b1 + b2)
    }

    fn breaks(&self) -> &[f64] {
        &[1.0, 2.0, 3.0]
    }
}

/// A loop of one curve, flattened within `tol`.
pub(super) fn curve_loop(curve: &dyn Curve2, tol: f64, role: Option<Role>) -> LoopInput {
    let range = curve.domain();
    match LoopInput::from_pieces(0, &[Piece::Curve(curve, range)], role, tol) {
        Ok(l) => l,
        Err(e) => panic!("flattening a test curve failed: {e}"),
    }
}

/// Unwraps a build result in a test, with the error's message on failure.
pub(super) fn ok(r: Result<TrimRegions, TrimError>) -> TrimRegions {
    match r {
        Ok(t) => t,
        Err(e) => panic!("expected valid trim loops, got: {e}"),
    }
}

/// Expects an error, returning its message.
pub(super) fn err(r: Result<TrimRegions, TrimError>) -> TrimError {
    match r {
        Ok(_) => panic!("expected an error"),
        Err(e) => e,
    }
}
