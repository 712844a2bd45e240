//! Flattening: accuracy, direction, breaks and refusals.

use glam::DVec2;

use super::super::curve::{MAX_SEGMENTS, point_segment_distance};
use super::super::{Curve2, LoopInput, Piece, TrimError, flatten};
use super::{BezierCircle, Circle};

/// Largest distance from densely sampled curve points to the polyline.
fn max_deviation(c: &dyn Curve2, range: (f64, f64), poly: &[DVec2]) -> f64 {
    let mut worst: f64 = 0.0;
    for k in 0..=4000 {
        let t = range.0 + (range.1 - range.0) * k as f64 / 4000.0;
        let q = c.point(t);
        let d = poly
            .windows(2)
            .map(|w| point_segment_distance(q, w[0], w[1]))
            .fold(f64::INFINITY, f64::min);
        worst = worst.max(d);
    }
    worst
}

fn flat(c: &dyn Curve2, range: (f64, f64), tol: f64) -> Vec<DVec2> {
    let mut out = Vec::new();
    match flatten(c, range, tol, &mut out) {
        Ok(()) => out,
        Err(e) => panic!("flatten failed: {e}"),
    }
}

#[test]
fn flattening_stays_within_the_tolerance() {
    let curves: [&dyn Curve2; 2] = [
        &Circle {
            c: DVec2::new(0.5, 0.5),
            r: 0.3,
        },
        &BezierCircle {
            c: DVec2::new(0.5, 0.5),
            r: 0.3,
        },
    ];
    for c in curves {
        let range = c.domain();
        let tol = 1e-5;
        let poly = flat(c, range, tol);
        assert!(max_deviation(c, range, &poly) <= tol * (1.0 + 1e-9));
        assert!(poly[0].distance(c.point(range.0)) == 0.0);
        // Negative control: a coarser polyline (tolerance 100x) fails the same check.
        let coarse = flat(c, range, 100.0 * tol);
        assert!(max_deviation(c, range, &coarse) > tol);
    }
}

#[test]
fn backwards_range_gives_the_reversed_polyline() {
    let c = Circle {
        c: DVec2::ZERO,
        r: 1.0,
    };
    let fwd = flat(&c, (0.5, 2.0), 1e-4);
    let back = flat(&c, (2.0, 0.5), 1e-4);
    assert_eq!(back[0], c.point(2.0));
    assert_eq!(*back.last().unwrap_or(&DVec2::NAN), c.point(0.5));
    assert!(max_deviation(&c, (2.0, 0.5), &back) <= 1e-4);
    assert!(close_sets(&fwd, &back));
    // Negative control: another range is not the same set.
    assert!(!close_sets(&fwd, &flat(&c, (2.0, 0.6), 1e-4)));
}

/// Same start/end points up to order: compares the first and last points, reversed.
fn close_sets(fwd: &[DVec2], back: &[DVec2]) -> bool {
    let (Some(f0), Some(f1), Some(b0), Some(b1)) =
        (fwd.first(), fwd.last(), back.first(), back.last())
    else {
        return false;
    };
    f0.distance(*b1) < 1e-12 && f1.distance(*b0) < 1e-12
}

/// `|t|`-shaped curve with a kink at a break.
struct Kink;

impl Curve2 for Kink {
    fn domain(&self) -> (f64, f64) {
        (-1.0, 1.0)
    }

    fn point(&self, t: f64) -> DVec2 {
        DVec2::new(t, t.abs())
    }

    fn breaks(&self) -> &[f64] {
        &[0.3, 0.3, 5.0, -0.1]
    }
}

#[test]
fn breaks_start_spans_and_a_line_needs_no_subdivision() {
    let poly = flat(&Kink, (-1.0, 1.0), 1e-6);
    // Spans [-1, -0.1], [-0.1, 0.3], [0.3, 1], 8 pieces each; the kink at 0 is a vertex.
    assert_eq!(poly.len(), 3 * 8 + 1);
    assert!(max_deviation(&Kink, (-1.0, 1.0), &poly) <= 1e-6);
    // Negative control: straight pieces across the kink miss it.
    let wrong = [DVec2::new(-1.0, 1.0), DVec2::new(1.0, 1.0)];
    assert!(max_deviation(&Kink, (-1.0, 1.0), &wrong) > 1e-6);
}

struct Broken;

impl Curve2 for Broken {
    fn domain(&self) -> (f64, f64) {
        (0.0, 1.0)
    }

    fn point(&self, t: f64) -> DVec2 {
        if t > 0.6 {
            DVec2::new(f64::NAN, 0.0)
        } else {
            DVec2::new(t, 0.0)
        }
    }
}

#[test]
fn bad_curves_are_refused() {
    let mut out = Vec::new();
    let e = flatten(&Broken, (0.0, 1.0), 1e-3, &mut out);
    assert!(matches!(e, Err(TrimError::CurveNotFinite { .. })));
    assert!(flatten(&Broken, (0.0, 0.5), 1e-3, &mut Vec::new()).is_ok());
    let e = flatten(&Broken, (0.0, 1.5), 1e-3, &mut out);
    assert!(matches!(e, Err(TrimError::BadCurveRange { .. })));
    let e = flatten(&Broken, (0.0, 0.5), 0.0, &mut out);
    assert!(matches!(e, Err(TrimError::BadTolerance { .. })));
    let circle = Circle {
        c: DVec2::ZERO,
        r: 1.0,
    };
    let e = flatten(&circle, (0.0, 1.0), 1e-300, &mut out);
    assert!(matches!(
        e,
        Err(TrimError::TooManySegments {
            limit: MAX_SEGMENTS,
            ..
        })
    ));
    let e = LoopInput::from_pieces(
        3,
        &[Piece::Points(&[]), Piece::Curve(&Broken, (0.0, 1.0))],
        None,
        1e-3,
    );
    let msg = e.map(|_| String::new()).unwrap_or_else(|e| e.to_string());
    assert_eq!(
        msg,
        "trim loop 3, curve 1: curve is not finite at t = 0.625"
    );
}
