//! Unit tests of the internal numerics: the evaluators against the analytic crate's, surface
//! cutting, power-to-Bézier conversion and angle continuity.

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]

use crate::geom::analytic::{NurbsCurve, NurbsSurface};
use glam::DVec3;

use super::curves::power_to_bezier;
use super::eval::{CurveEvaluator, Evaluator};
use super::invert::nearest_turn;
use super::segment::cut_surface;

/// A rational 4 × 3 net of degrees (3, 2) with uneven, unclamped-free knots.
fn surface() -> NurbsSurface {
    let mut points = Vec::new();
    let mut weights = Vec::new();
    for i in 0..4 {
        for j in 0..3 {
            let (x, y) = (i as f64, j as f64);
            points.push(DVec3::new(x, y, (x * 0.7).sin() + y * y * 0.3));
            weights.push(1.0 + 0.25 * ((i + 2 * j) % 3) as f64);
        }
    }
    NurbsSurface {
        degree: [3, 2],
        knots: [
            vec![0.0, 0.0, 0.0, 0.0, 2.5, 2.5, 2.5, 2.5],
            vec![-1.0, -1.0, -1.0, 0.5, 0.5, 0.5],
        ],
        points,
        weights,
    }
}

#[test]
fn surface_evaluator_matches_the_analytic_crate() {
    let s = surface();
    let ev = Evaluator::new(&s).unwrap();
    for (u, v) in [
        (0.0, -1.0),
        (0.3, 0.2),
        (1.7, -0.4),
        (2.5, 0.5),
        (2.2, 0.49),
    ] {
        let d = s.derivs(u, v).unwrap();
        let [p, su, sv] = ev.eval(u, v).unwrap();
        for (a, b) in [(p, d.p), (su, d.su), (sv, d.sv)] {
            assert!(
                (a - b).length() < 1e-12 * (1.0 + b.length()),
                "{a} vs {b} at {u} {v}"
            );
        }
    }
}

#[test]
fn curve_evaluator_matches_the_analytic_crate() {
    let c = NurbsCurve {
        degree: 2,
        knots: vec![0.0, 0.0, 0.0, 0.3, 1.0, 1.0, 1.0],
        points: vec![DVec3::X, DVec3::Y, DVec3::Z, DVec3::ONE],
        weights: vec![1.0, 0.5, 2.0, 1.0],
    };
    let ev = CurveEvaluator::new(&c).unwrap();
    for t in [0.0, 0.1, 0.3, 0.65, 1.0] {
        let (a, b) = (ev.point(t).unwrap(), c.point(t).unwrap());
        assert!((a - b).length() < 1e-14, "{a} vs {b}");
    }
}

#[test]
fn cutting_a_surface_keeps_its_points_and_parameters() {
    let s = surface();
    let cut = cut_surface(&s, [0.5, 2.0], [-0.8, 0.1]).unwrap();
    assert_eq!(cut.domain().unwrap(), [[0.5, 2.0], [-0.8, 0.1]]);
    for (u, v) in [(0.5, -0.8), (1.1, -0.3), (2.0, 0.1)] {
        let (a, b) = (cut.point(u, v).unwrap(), s.point(u, v).unwrap());
        assert!((a - b).length() < 1e-12, "{a} vs {b}");
    }
    // Negative control: a range outside the domain is clamped to it, not extrapolated.
    let whole = cut_surface(&s, [-5.0, 9.0], [-3.0, 3.0]).unwrap();
    assert_eq!(whole.domain().unwrap(), s.domain().unwrap());
}

#[test]
fn power_form_to_bezier() {
    let c = [1.0, -2.0, 0.5, 3.0];
    let h = 0.7;
    let b = power_to_bezier(&c, h);
    for s in [0.0, 0.2, 0.5, 0.7] {
        let t = s / h;
        let bern = b[0] * (1.0 - t).powi(3)
            + 3.0 * b[1] * t * (1.0 - t).powi(2)
            + 3.0 * b[2] * t * t * (1.0 - t)
            + b[3] * t.powi(3);
        let power = c[0] + c[1] * s + c[2] * s * s + c[3] * s * s * s;
        assert!((bern - power).abs() < 1e-12, "{bern} vs {power}");
    }
}

#[test]
fn angles_follow_their_neighbour() {
    let tau = std::f64::consts::TAU;
    assert!((nearest_turn(0.1, tau) - (tau + 0.1)).abs() < 1e-15);
    assert!((nearest_turn(6.2, 0.0) - (6.2 - tau)).abs() < 1e-15);
    assert_eq!(nearest_turn(1.0, 1.2), 1.0);
}
