//! Integrals over the trimmed domain against closed forms and an independent quadrature.

use std::f64::consts::PI;

use glam::DVec2;

use super::super::{Coverage, Curve2, LoopInput, TrimError, TrimRegions, integrate};
use super::coverage_tests::axis;
use super::{BezierCircle, Circle, build, close, curve_loop, ok, one_piece, rect, reversed};

/// `∫∫ f` over `t` on an `n` × `n` grid of the unit square.
fn integral(t: &TrimRegions, n: usize, f: impl Fn(f64, f64) -> f64 + Sync) -> f64 {
    let (u, v) = (axis(0.0, 1.0, n), axis(0.0, 1.0, n));
    let r = Coverage::new(t, &u, &v).and_then(|c| integrate(t, &u, &v, &c, f));
    match r {
        Ok(x) => x,
        Err(e) => panic!("integration failed: {e}"),
    }
}

/// Gauss–Legendre nodes and weights on `[-1, 1]` by Newton's method on `P_n`: computed here, not
/// taken from the module under test.
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    (p0, p1) = (p1, p2);
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let step = p1 / dp;
                x -= step;
                if step.abs() < 1e-16 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

/// `∮ F dv` over the normalised loops of `t` (Green's theorem with `∂F/∂u = f`), each edge split
/// in `pieces` with 10 Gauss nodes each: an independent reference for `∫∫ f`.
fn green(t: &TrimRegions, big_f: impl Fn(f64, f64) -> f64, pieces: usize) -> f64 {
    let rule = gauss_legendre(10);
    let mut sum = 0.0;
    for l in t.loops() {
        let pts = l.points();
        for (k, &a) in pts.iter().enumerate() {
            let d = (pts[(k + 1) % pts.len()] - a) / pieces as f64;
            for m in 0..pieces {
                let s = a + d * m as f64;
                for &(x, w) in &rule {
                    let q = s + d * (0.5 * (x + 1.0));
                    sum += 0.5 * w * big_f(q.x, q.y) * d.y;
                }
            }
        }
    }
    sum
}

#[test]
fn circle_area_is_pi_r_squared() {
    let (c, r) = (DVec2::new(0.5, 0.45), 0.3);
    let exact = PI * r * r;
    let curves: [&dyn Curve2; 3] = [
        &Circle { c, r },
        &BezierCircle { c, r },
        &Circle {
            c,
            r: r * (1.0 + 1e-8),
        },
    ];
    for (k, curve) in curves.into_iter().enumerate() {
        let t = ok(build(&[curve_loop(curve, 1e-10, None)]));
        let by_grid = integral(&t, 64, |_, _| 1.0);
        // The last curve is the negative control: a radius 1e-8 larger fails.
        let control = k == 2;
        assert_eq!(close(t.area(), exact, 1e-9 * exact), !control);
        assert_eq!(close(by_grid, exact, 1e-9 * exact), !control);
        assert!(close(by_grid, t.area(), 1e-14));
    }
}

#[test]
fn disc_integral_of_a_polynomial() {
    let (c, r) = (DVec2::new(0.45, 0.55), 0.35);
    let f = |u: f64, v: f64| 1.0 + u * u * v;
    let big_f = |u: f64, v: f64| u + u * u * u * v / 3.0;
    let closed = PI * r * r + c.y * (c.x * c.x * PI * r * r + PI * r.powi(4) / 4.0);
    let t = ok(build(&[curve_loop(&Circle { c, r }, 1e-10, None)]));
    let by_grid = integral(&t, 64, f);
    assert!(close(by_grid, closed, 1e-9 * closed));
    // Exact for the polygon (f has degree <= 5): agrees with Green's theorem to rounding.
    let coarse = ok(build(&[curve_loop(&Circle { c, r }, 1e-4, None)]));
    let polygon = green(&coarse, big_f, 1);
    for n in [2, 9, 64, 100] {
        assert!(
            close(integral(&coarse, n, f), polygon, 1e-14 * polygon),
            "{n} samples"
        );
    }
    // Negative control: the disc moved by 1e-6 fails the closed form.
    let moved = ok(build(&[curve_loop(
        &Circle { c: c + 1e-6, r },
        1e-10,
        None,
    )]));
    assert!(!close(integral(&moved, 64, f), closed, 1e-9 * closed));
}

/// A square with a tilted square hole and a circular hole, and an island in the circle.
fn mixed() -> Vec<LoopInput> {
    let tilted = vec![
        DVec2::new(0.3, 0.15),
        DVec2::new(0.45, 0.3),
        DVec2::new(0.3, 0.45),
        DVec2::new(0.15, 0.3),
    ];
    vec![
        one_piece(rect(0.05, 0.05, 0.95, 0.9), None),
        one_piece(tilted, None),
        curve_loop(
            &Circle {
                c: DVec2::new(0.65, 0.6),
                r: 0.2,
            },
            1e-4,
            None,
        ),
        one_piece(reversed(rect(0.6, 0.55, 0.7, 0.65)), None),
    ]
}

#[test]
fn smooth_function_matches_an_independent_quadrature() {
    let f = |u: f64, v: f64| u.exp() * (3.0 * v).cos();
    let big_f = |u: f64, v: f64| u.exp() * (3.0 * v).cos();
    let t = ok(build(&mixed()));
    let reference = green(&t, big_f, 4);
    for (n, tol) in [(17, 1e-9), (65, 1e-12), (257, 1e-12)] {
        let by_grid = integral(&t, n, f);
        assert!(
            close(by_grid, reference, tol * reference.abs()),
            "{n}: {by_grid} vs {reference}"
        );
    }
    // Negative control: the island moved by 1e-5 changes the integral beyond the tolerance.
    let mut loops = mixed();
    loops[3].pieces[0].iter_mut().for_each(|p| p.x += 1e-5);
    let moved = ok(build(&loops));
    assert!(!close(
        integral(&moved, 65, f),
        reference,
        1e-9 * reference.abs()
    ));
}

#[test]
fn boundaries_on_grid_lines_and_through_samples() {
    // Outer loop = the domain's boundary, a hole on grid lines, a diamond island through samples.
    let diamond = vec![
        DVec2::new(0.375, 0.375),
        DVec2::new(0.5, 0.5),
        DVec2::new(0.375, 0.625),
        DVec2::new(0.25, 0.5),
    ];
    let loops = [
        one_piece(rect(0.0, 0.0, 1.0, 1.0), None),
        one_piece(rect(0.125, 0.25, 0.625, 0.75), None),
        one_piece(diamond, None),
    ];
    let t = ok(build(&loops));
    let f = |u: f64, v: f64| 1.0 + u * u * v;
    // Green's theorem on the loops is exact here: F = u + u³v/3 has degree 4 along an edge.
    let exact = green(&t, |u, v| u + u * u * u * v / 3.0, 1);
    // Sanity of the reference: the box minus the hole, plus an island of area 1/32 with f <= 1.2.
    let cube = |x: f64| x * x * x;
    let hole = 0.25 + (cube(0.625) - cube(0.125)) / 3.0 * (0.75 * 0.75 - 0.25 * 0.25) / 2.0;
    let rectangles = 1.0 + 1.0 / 6.0 - hole;
    assert!(exact > rectangles + 1.0 / 32.0 && exact < rectangles + 1.2 / 32.0);
    for n in [9, 17, 33] {
        assert!(close(integral(&t, n, f), exact, 1e-14), "{n} samples");
        assert!(
            close(integral(&t, n, |_, _| 1.0), t.area(), 1e-15),
            "{n} samples"
        );
    }
    // Negative control: the hole shifted by one grid line.
    let shifted = [
        loops[0].clone(),
        one_piece(rect(0.25, 0.25, 0.75, 0.75), None),
        loops[2].clone(),
    ];
    assert!(!close(integral(&ok(build(&shifted)), 9, f), exact, 1e-6));
}

#[test]
fn orientation_does_not_change_the_integral() {
    let f = |u: f64, v: f64| (u + 2.0 * v).sin() + 2.0;
    let loops = mixed();
    let flipped: Vec<LoopInput> = loops
        .iter()
        .map(|l| one_piece(reversed(l.pieces[0].clone()), None))
        .collect();
    let (a, b) = (
        integral(&ok(build(&loops)), 33, f),
        integral(&ok(build(&flipped)), 33, f),
    );
    assert!(close(a, b, 1e-14));
    // Negative control: without the island the integral differs.
    assert!(!close(integral(&ok(build(&loops[..3])), 33, f), a, 1e-6));
}

#[test]
fn a_coverage_of_another_grid_is_refused() {
    let t = ok(build(&mixed()));
    let (u, v) = (axis(0.0, 1.0, 9), axis(0.0, 1.0, 9));
    let u2 = axis(0.0, 1.0, 10);
    let c = Coverage::new(&t, &u, &v);
    let c = match c {
        Ok(c) => c,
        Err(e) => panic!("{e}"),
    };
    assert!(matches!(
        integrate(&t, &u2, &v, &c, |_, _| 1.0),
        Err(TrimError::BadGrid { .. })
    ));
    assert!(integrate(&t, &u, &v, &c, |_, _| 1.0).is_ok());
}
