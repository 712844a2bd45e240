//! The de Boor evaluator against an independent Cox–de Boor basis sum,
//! derivatives against finite differences, and curve segment extraction.

use glam::DVec3;

use super::super::{NurbsCurve, NurbsSurface};
use super::{Rng, bspline_profile, close, close_vec, ok_err, worst};

/// Cox–de Boor recursion, written independently of the module's evaluator.
fn basis(knots: &[f64], i: usize, p: usize, t: f64, last: bool) -> f64 {
    if p == 0 {
        let (a, b) = (knots[i], knots[i + 1]);
        return if (a <= t && t < b) || (last && t == b && a < b) {
            1.0
        } else {
            0.0
        };
    }
    let mut r = 0.0;
    let d1 = knots[i + p] - knots[i];
    if d1 > 0.0 {
        r += (t - knots[i]) / d1 * basis(knots, i, p - 1, t, last);
    }
    let d2 = knots[i + p + 1] - knots[i + 1];
    if d2 > 0.0 {
        r += (knots[i + p + 1] - t) / d2 * basis(knots, i + 1, p - 1, t, last);
    }
    r
}

fn reference_curve(c: &NurbsCurve, t: f64) -> DVec3 {
    let n = c.points.len();
    let last = t >= c.knots[n];
    // Only the last non-empty span may own its right end.
    let mut num = DVec3::ZERO;
    let mut den = 0.0;
    for i in 0..n {
        let b = basis(
            &c.knots,
            i,
            c.degree,
            t,
            last && c.knots[i + 1] == c.knots[n] && c.knots[i] < c.knots[n],
        ) * c.weights[i];
        num += b * c.points[i];
        den += b;
    }
    num / den
}

fn random_surface(rng: &mut Rng) -> NurbsSurface {
    let (nu, nv) = (6, 5);
    let ku = vec![0.0, 0.0, 0.0, 0.0, 0.4, 1.3, 2.0, 2.0, 2.0, 2.0];
    let kv = vec![-1.0, -1.0, -1.0, 0.0, 0.5, 1.0, 1.0, 1.0];
    let mut points = Vec::new();
    let mut weights = Vec::new();
    for i in 0..nu {
        for j in 0..nv {
            points.push(DVec3::new(i as f64, j as f64, 0.0) + rng.vec(0.4));
            weights.push(rng.range(0.5, 2.0));
        }
    }
    NurbsSurface {
        degree: [3, 2],
        knots: [ku, kv],
        points,
        weights,
    }
}

#[test]
fn de_boor_matches_cox_de_boor() {
    let c = bspline_profile();
    let mut rng = Rng::new(2);
    let mut ts: Vec<f64> = (0..300).map(|_| rng.range(0.0, 3.0)).collect();
    ts.extend([0.0, 0.7, 1.1, 2.5, 3.0]);
    let e = worst(
        ts.iter()
            .map(|&t| (c.point(t).unwrap() - reference_curve(&c, t)).length()),
    );
    assert!(ok_err(e, 1e-14), "{e:e}");
    // Negative control: the reference notices a changed weight.
    let mut bad = c.clone();
    bad.weights[3] = 1.01;
    assert!(!close_vec(
        bad.point(1.2).unwrap(),
        reference_curve(&c, 1.2),
        1e-9
    ));
}

#[test]
fn curve_derivatives_match_finite_differences() {
    let c = bspline_profile();
    let h = 1e-5;
    for t in [0.1, 0.5, 0.9, 1.7, 2.2, 2.9] {
        let [_, d1, d2] = c.derivs(t).unwrap();
        let fd1 = (c.point(t + h).unwrap() - c.point(t - h).unwrap()) / (2.0 * h);
        let fd2 = (c.point(t + h).unwrap() - 2.0 * c.point(t).unwrap() + c.point(t - h).unwrap())
            / (h * h);
        assert!(close_vec(d1, fd1, 1e-8 * (1.0 + d1.length())), "t {t}");
        assert!(close_vec(d2, fd2, 1e-4 * (1.0 + d2.length())), "t {t}");
        assert!(!close_vec(d1, 1.001 * fd1, 1e-8 * (1.0 + d1.length())));
    }
}

#[test]
fn surface_derivatives_match_finite_differences() {
    let mut rng = Rng::new(9);
    let s = random_surface(&mut rng);
    let h = 1e-5;
    let p = |u: f64, v: f64| s.point(u, v).unwrap();
    for _ in 0..30 {
        let (u, v) = (rng.range(0.01, 1.99), rng.range(-0.99, 0.99));
        let d = s.derivs(u, v).unwrap();
        let tol = |x: DVec3, k: f64| k * (1.0 + x.length());
        assert!(close_vec(
            d.su,
            (p(u + h, v) - p(u - h, v)) / (2.0 * h),
            tol(d.su, 1e-8)
        ));
        assert!(close_vec(
            d.sv,
            (p(u, v + h) - p(u, v - h)) / (2.0 * h),
            tol(d.sv, 1e-8)
        ));
        let fuu = (p(u + h, v) - 2.0 * p(u, v) + p(u - h, v)) / (h * h);
        let fvv = (p(u, v + h) - 2.0 * p(u, v) + p(u, v - h)) / (h * h);
        let fuv =
            (p(u + h, v + h) - p(u + h, v - h) - p(u - h, v + h) + p(u - h, v - h)) / (4.0 * h * h);
        assert!(close_vec(d.suu, fuu, tol(d.suu, 1e-4)));
        assert!(close_vec(d.svv, fvv, tol(d.svv, 1e-4)));
        assert!(close_vec(d.suv, fuv, tol(d.suv, 1e-4)));
        assert!(!close_vec(d.suv, fuv + DVec3::X * 1e-2, tol(d.suv, 1e-4)));
    }
    assert!(close(s.domain().unwrap()[1][0], -1.0, 0.0));
}

#[test]
fn segment_is_the_same_curve() {
    let c = bspline_profile();
    // Unclamped (uniform) variant as well.
    let unclamped = NurbsCurve {
        knots: (0..11).map(f64::from).collect(),
        ..c.clone()
    };
    for (curve, cuts) in [
        (
            &c,
            vec![
                (0.0, 3.0),
                (0.2, 2.9),
                (0.7, 2.5),
                (1.0, 1.1),
                (0.0, 0.35),
                (2.6, 3.0),
            ],
        ),
        (&unclamped, vec![(3.0, 7.0), (3.5, 6.2), (4.0, 5.0)]),
    ] {
        for (a, b) in cuts {
            let s = curve.segment(a, b).unwrap();
            assert!(s.validate().is_ok());
            assert_eq!(s.domain().unwrap(), [a, b]);
            let e = worst((0..=50).map(|i| {
                let t = a + (b - a) * i as f64 / 50.0;
                (s.point(t).unwrap() - curve.point(t).unwrap()).length()
            }));
            assert!(ok_err(e, 1e-14), "cut {a} {b}: {e:e}");
        }
    }
    assert!(c.segment(-0.5, 1.0).is_err());
    assert!(c.segment(1.0, 1.0).is_err());
    // Slightly outside the domain is clamped.
    assert_eq!(
        c.segment(-1e-15, 3.0).unwrap().domain().unwrap(),
        [0.0, 3.0]
    );
}
