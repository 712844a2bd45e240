//! Tests of the reference evaluator (`tests/oracle/`) itself: exact lecture numbers, the
//! expo-rational B-function against an mpmath table, B-function identities, finite differences,
//! partition of unity, ERBS interpolation, an independent Cox–de Boor basis-function path, edit
//! semantics, refinement by blossoming (knot insertion, degree elevation: hand-worked cases,
//! unchanged shapes, refined knot vectors), the scene round trip and the comparison logic used
//! against the product.

// Index loops over derivative orders and coordinates read best as they are written in the books.
#![allow(clippy::needless_range_loop)]

use crate::oracle;

use oracle::bfunction::{self, BFunction, EXPO_SCALE};
use oracle::blossom::Spline;
use oracle::compare::{compare_output, nan_max};
use oracle::condition::{compare_conditioned, compare_refined_outputs, condition_scales};
use oracle::eval::{
    self, Basis, Homogeneous, Point3, bspline_derivatives, project_curve_derivatives,
};
use oracle::random::{self, Kind, Options};
use oracle::rng::Rng;
use oracle::scene::{Edit, Elevation, Index, Object, Scene, Shape, apply_edits, sample_params};
use serde_json::{Value, json};

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

fn assert_point(actual: Point3, expected: [f64; 3], tol: f64, what: &str) {
    for k in 0..3 {
        assert!(
            close(actual[k], expected[k], tol),
            "{what}: got {actual:?}, expected {expected:?}"
        );
    }
}

fn curve(points: &[[f64; 3]], weights: Option<Vec<f64>>, basis: Basis) -> Object {
    Object {
        name: "c".into(),
        shape: Shape::Curve {
            basis,
            points: points.to_vec(),
            weights,
        },
        samples: vec![2],
    }
}

const LECTURE_POINTS: [[f64; 3]; 4] = [
    [1.0, 1.0, 0.0],
    [1.0, 10.0, 0.0],
    [10.0, 10.0, 0.0],
    [10.0, 1.0, 0.0],
];

// ---------------------------------------------------------------------------------------------
// Lecture numbers
// ---------------------------------------------------------------------------------------------

#[test]
fn lecture_cubic_bezier_de_casteljau() {
    let c = curve(&LECTURE_POINTS, None, Basis::Bezier);
    let d = c.curve_derivatives(1.0 / 3.0, 3);
    assert_point(d[0], [10.0 / 3.0, 7.0, 0.0], 1e-14, "C(1/3)");
    assert_point(d[1], [12.0, 9.0, 0.0], 1e-13, "C'(1/3)");
    // C'' = 6 Σ Δ²P B¹: Δ²P_0 = (9, -9), Δ²P_1 = (-9, -9) → C''(1/3) = 6((2/3)(9,-9) + (1/3)(-9,-9)).
    assert_point(d[2], [18.0, -54.0, 0.0], 1e-12, "C''(1/3)");
    // C''' = 6 Δ³P_0 = 6 (-18, 0).
    assert_point(d[3], [-108.0, 0.0, 0.0], 1e-12, "C'''");
    assert_point(c.curve_derivatives(0.0, 0)[0], [1.0, 1.0, 0.0], 0.0, "C(0)");
    assert_point(
        c.curve_derivatives(1.0, 0)[0],
        [10.0, 1.0, 0.0],
        0.0,
        "C(1)",
    );
}

#[test]
fn lecture_uniform_cubic_de_boor() {
    let knots: Vec<f64> = (0..8).map(f64::from).collect();
    let c = curve(&LECTURE_POINTS, None, Basis::BSpline { degree: 3, knots });
    let d = c.curve_derivatives(10.0 / 3.0, 1);
    assert_point(d[0], [79.0 / 18.0, 171.0 / 18.0, 0.0], 1e-14, "D(10/3)");
    // Derivative: the hodograph of the uniform cubic is a uniform quadratic B-spline with
    // Q_i = P_{i+1} − P_i (p / (t_{i+4} − t_{i+1}) = 1), evaluated at local u = 1/3 on span 3:
    // weights ½(1−u)², ½(−2u²+2u+1), ½u² = 2/9, 13/18, 1/18.
    let q = [[0.0, 9.0], [9.0, 0.0], [0.0, -9.0]];
    let w = [2.0 / 9.0, 13.0 / 18.0, 1.0 / 18.0];
    let expected = [
        w[0] * q[0][0] + w[1] * q[1][0] + w[2] * q[2][0],
        w[0] * q[0][1] + w[1] * q[1][1] + w[2] * q[2][1],
        0.0,
    ];
    assert_point(d[1], expected, 1e-13, "D'(10/3)");
}

#[test]
fn quarter_circle_rational_bezier() {
    let s = std::f64::consts::FRAC_1_SQRT_2;
    let c = curve(
        &[[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
        Some(vec![1.0, s, 1.0]),
        Basis::Bezier,
    );
    for j in 0..=64 {
        let t = j as f64 / 64.0;
        let d = c.curve_derivatives(t, 3);
        let [x, y, _] = d[0];
        assert!(
            close(x * x + y * y, 1.0, 4e-16),
            "|C({t})| = {}",
            (x * x + y * y).sqrt()
        );
        // Tangent ⟂ radius and turning counter-clockwise: C' = |C'| (−y, x).
        let speed = (d[1][0].powi(2) + d[1][1].powi(2)).sqrt();
        assert_point(
            d[1],
            [-y * speed, x * speed, 0.0],
            1e-14,
            "tangent direction",
        );
        // d²/dt² (C·C) = 0 → C·C'' + |C'|² = 0.
        let dot = x * d[2][0] + y * d[2][1] + speed * speed;
        assert!(close(dot, 0.0, 1e-13), "C·C'' + |C'|² = {dot} at {t}");
        // d³/dt³ (C·C) = 0 → C·C''' + 3 C'·C'' = 0.
        let third = x * d[3][0] + y * d[3][1] + 3.0 * (d[1][0] * d[2][0] + d[1][1] * d[2][1]);
        assert!(close(third, 0.0, 1e-12), "third identity {third} at {t}");
    }
    let mid = c.curve_derivatives(0.5, 0)[0];
    assert_point(mid, [s, s, 0.0], 2e-16, "C(1/2)");
    // Endpoint derivatives: C'(0) = 2 w1/w0 (P1 − P0) = (0, √2), C'(1) = (−√2, 0).
    let root2 = std::f64::consts::SQRT_2;
    assert_point(
        c.curve_derivatives(0.0, 1)[1],
        [0.0, root2, 0.0],
        1e-15,
        "C'(0)",
    );
    assert_point(
        c.curve_derivatives(1.0, 1)[1],
        [-root2, 0.0, 0.0],
        1e-15,
        "C'(1)",
    );
}

// ---------------------------------------------------------------------------------------------
// B-functions
// ---------------------------------------------------------------------------------------------

#[test]
fn expo_scale_constant() {
    let integral = 2.0 * bfunction::expo_integral_lower(0.5);
    let from_quadrature = 1.0 / integral;
    assert!(
        close(from_quadrature, EXPO_SCALE, 2.0 * f64::EPSILON * EXPO_SCALE),
        "quadrature S_F = {from_quadrature:.17}, constant {EXPO_SCALE:.17}"
    );
    let table: Value = serde_json::from_str(REFERENCE).unwrap();
    let reference: f64 = table["scale"].as_str().unwrap().parse().unwrap();
    assert_eq!(
        reference, EXPO_SCALE,
        "constant is the correctly rounded S_F"
    );
    let printed_in_design = 1.657_137_679_738_210_5_f64;
    assert!(close(printed_in_design, EXPO_SCALE, 2.3e-16));
}

const REFERENCE: &str = include_str!("../data/expo_bfunction_reference.json");

/// (t, [B, B', …, B^(6)]) from the mpmath table.
fn reference_table() -> Vec<(f64, Vec<f64>)> {
    let table: Value = serde_json::from_str(REFERENCE).unwrap();
    table["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let t: f64 = p["t"].as_str().unwrap().parse().unwrap();
            let d = p["derivatives"]
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_str().unwrap().parse::<f64>().unwrap())
                .collect();
            (t, d)
        })
        .collect()
}

#[test]
fn expo_bfunction_matches_mpmath() {
    let table = reference_table();
    assert!(table.len() >= 20);
    let orders = table[0].1.len();
    // Per-order magnitude over the table, the natural scale of errors in derivative r.
    let scale: Vec<f64> = (0..orders)
        .map(|r| table.iter().map(|(_, d)| d[r].abs()).fold(1.0, nan_max))
        .collect();
    let mut worst_abs = vec![0.0f64; orders];
    let mut worst_rel = vec![0.0f64; orders];
    let mut worst_pointwise = vec![0.0f64; orders];
    for (t, reference) in &table {
        let ours = BFunction::Expo.derivatives(*t, orders - 1);
        for r in 0..orders {
            let err = (ours[r] - reference[r]).abs();
            worst_abs[r] = nan_max(worst_abs[r], err);
            worst_rel[r] = nan_max(worst_rel[r], err / scale[r]);
            // Pointwise relative accuracy where the value is not tiny compared to its order.
            if reference[r].abs() > 1e-6 * scale[r] {
                let rel = err / reference[r].abs();
                worst_pointwise[r] = nan_max(worst_pointwise[r], rel);
                assert!(
                    rel < 1e-13,
                    "B^({r})({t}): {} vs {} (rel {rel:e})",
                    ours[r],
                    reference[r]
                );
            }
        }
    }
    for r in 0..orders {
        println!(
            "expo B^({r}): max |err| {:.2e}, max |err|/max|B^({r})| {:.2e} (max |B^({r})| {:.3e}), \
             max relative error where |B^({r})| > 1e-6 max {:.2e}",
            worst_abs[r], worst_rel[r], scale[r], worst_pointwise[r]
        );
    }
    assert!(
        worst_abs[0] <= 2.5e-16,
        "B absolute error {:e}",
        worst_abs[0]
    );
    for r in 1..orders {
        assert!(
            worst_rel[r] <= 4e-15,
            "B^({r}) scaled error {:e}",
            worst_rel[r]
        );
    }
}

#[test]
fn bfunction_end_values_and_symmetry() {
    for b in BFunction::ALL {
        let at0 = b.derivatives(0.0, 0)[0];
        let at1 = b.derivatives(1.0, 0)[0];
        assert_eq!(at0, 0.0, "{b:?}: B(0)");
        assert!(close(at1, 1.0, 1e-16), "{b:?}: B(1) = {at1}");
        // B'(0) = B'(1) = 0 for all five.
        assert!(b.derivatives(0.0, 1)[1].abs() < 1e-15, "{b:?}: B'(0)");
        assert!(b.derivatives(1.0, 1)[1].abs() < 1e-15, "{b:?}: B'(1)");
        let mut rng = Rng::new(7);
        let mut previous = 0.0;
        for j in 0..=200 {
            let t = if j % 2 == 0 {
                j as f64 / 200.0
            } else {
                rng.uniform()
            };
            let d = b.derivatives(t, 4);
            let m = b.derivatives(1.0 - t, 4);
            assert!(
                close(d[0] + m[0], 1.0, 3e-16),
                "{b:?}: B({t}) + B(1−t) = {}",
                d[0] + m[0]
            );
            // B^(r)(1−t) = (−1)^(r+1) B^(r)(t)
            for r in 1..=4 {
                let sign = if r % 2 == 1 { 1.0 } else { -1.0 };
                let scale = [1.0, 2.0, 10.0, 100.0, 1000.0][r];
                assert!(
                    close(m[r], sign * d[r], 2e-14 * scale),
                    "{b:?}: symmetry of B^({r}) at {t}: {} vs {}",
                    m[r],
                    sign * d[r]
                );
            }
            if j % 2 == 0 {
                assert!(d[0] >= previous, "{b:?}: B not monotone at {t}");
                previous = d[0];
                assert!((0.0..=1.0).contains(&d[0]));
            }
        }
    }
}

/// Richardson-extrapolated central difference of f at t with step h (error O(h⁴)).
fn richardson<F: Fn(f64) -> Vec<f64>>(f: F, t: f64, h: f64) -> Vec<f64> {
    let central = |h: f64| -> Vec<f64> {
        let (a, b) = (f(t + h), f(t - h));
        a.iter().zip(&b).map(|(x, y)| (x - y) / (2.0 * h)).collect()
    };
    let (coarse, fine) = (central(h), central(0.5 * h));
    coarse
        .iter()
        .zip(&fine)
        .map(|(c, f)| (4.0 * f - c) / 3.0)
        .collect()
}

#[test]
fn bfunction_derivatives_match_finite_differences() {
    let mut rng = Rng::new(11);
    for b in BFunction::ALL {
        let mut worst = 0.0f64;
        for _ in 0..60 {
            let t = rng.range(0.05, 0.95);
            let d = b.derivatives(t, 7);
            let fd = richardson(|x| b.derivatives(x, 6), t, 1e-3);
            for r in 0..=6 {
                let scale = 1.0 + d[r + 1].abs() + d[r].abs();
                let err = (fd[r] - d[r + 1]).abs() / scale;
                worst = nan_max(worst, err);
                assert!(
                    err < 1e-5,
                    "{b:?}: B^({}) at {t}: {} vs FD {}",
                    r + 1,
                    d[r + 1],
                    fd[r]
                );
            }
        }
        println!("{b:?}: worst scaled FD error over orders 1..7: {worst:.2e}");
    }
}

#[test]
fn polynomial_bfunctions_have_exact_derivatives() {
    for (b, coeffs) in [
        (BFunction::Smoothstep, vec![0.0, 0.0, 3.0, -2.0]),
        (
            BFunction::Smootherstep,
            vec![0.0, 0.0, 0.0, 10.0, -15.0, 6.0],
        ),
    ] {
        for t in [0.0, 0.125, 0.25, 0.5, 0.75, 1.0] {
            let d = b.derivatives(t, 8);
            for (r, &value) in d.iter().enumerate() {
                // r-th derivative of Σ c_k t^k.
                let mut exact = 0.0;
                for (k, &c) in coeffs.iter().enumerate().skip(r) {
                    let falling: f64 = (k - r + 1..=k).map(|x| x as f64).product();
                    exact += c * falling * t.powi((k - r) as i32);
                }
                assert!(
                    close(value, exact, 1e-13),
                    "{b:?}^({r})({t}) = {value}, exact {exact}"
                );
            }
        }
    }
}

#[test]
fn trigonometric_and_rational_closed_forms() {
    use std::f64::consts::PI;
    for j in 0..=64 {
        let t = j as f64 / 64.0;
        let d = BFunction::Trigonometric.derivatives(t, 4);
        let (s, c) = (PI * t).sin_cos();
        let expected = [
            (1.0 - c) / 2.0,
            PI / 2.0 * s,
            PI * PI / 2.0 * c,
            -PI.powi(3) / 2.0 * s,
            -PI.powi(4) / 2.0 * c,
        ];
        for r in 0..=4 {
            assert!(
                close(d[r], expected[r], 1e-15 * PI.powi(r as i32)),
                "trig^({r})({t})"
            );
        }
        let d = BFunction::Rational.derivatives(t, 2);
        let den = t * t + (1.0 - t) * (1.0 - t);
        let expected = [
            t * t / den,
            2.0 * t * (1.0 - t) / (den * den),
            2.0 * (1.0 - 2.0 * t) * (1.0 + 2.0 * t - 2.0 * t * t) / (den * den * den),
        ];
        for r in 0..=2 {
            assert!(close(d[r], expected[r], 1e-14), "rational^({r})({t})");
        }
    }
}

// ---------------------------------------------------------------------------------------------
// B-splines: partition of unity, discontinuities, an independent basis-function path
// ---------------------------------------------------------------------------------------------

#[test]
fn bspline_partition_of_unity() {
    let mut rng = Rng::new(3);
    for _ in 0..300 {
        let p = rng.int(0, 8);
        let n = p + 1 + rng.int(0, 6);
        let knots = random::random_bspline_knots(&mut rng, p, n);
        let (a, b) = (knots[p], knots[n]);
        for j in 0..10 {
            let t = if j == 9 { b } else { rng.range(a, b) };
            let mut total = [0.0; 4];
            for i in 0..n {
                let mut unit = vec![[0.0]; n];
                unit[i] = [1.0];
                let d = bspline_derivatives(p, &knots, &unit, t, 3);
                assert!(d[0][0] >= -1e-15, "negative basis function");
                for k in 0..=3 {
                    total[k] += d[k][0];
                }
            }
            assert!(
                close(total[0], 1.0, 1e-14),
                "Σ N_i = {} (p={p}, t={t}, {knots:?})",
                total[0]
            );
            let ones = vec![[1.0]; n];
            let d = bspline_derivatives(p, &knots, &ones, t, 3);
            assert!(close(d[0][0], 1.0, 1e-15));
            for k in 1..=3 {
                assert_eq!(d[k][0], 0.0, "derivative {k} of a constant B-spline");
            }
        }
    }
}

#[test]
fn bspline_right_hand_values_at_discontinuity() {
    // Degree 1 with a double interior knot: C0-broken at t = 1. Right-hand value there.
    let points = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [5.0, 5.0, 0.0],
        [6.0, 5.0, 0.0],
    ];
    let knots = vec![0.0, 0.0, 1.0, 1.0, 2.0, 2.0];
    let c = curve(&points, None, Basis::BSpline { degree: 1, knots });
    let at = c.curve_derivatives(1.0, 2);
    assert_point(at[0], points[2], 0.0, "right-hand value at the break");
    assert_point(
        at[1],
        [1.0, 0.0, 0.0],
        1e-15,
        "right-hand derivative at the break",
    );
    assert_point(at[2], [0.0; 3], 0.0, "second derivative of a line");
    assert_point(c.curve_derivatives(2.0, 0)[0], points[3], 0.0, "domain end");
    assert_point(
        c.curve_derivatives(0.5, 0)[0],
        [0.5, 0.0, 0.0],
        1e-16,
        "left piece",
    );
    // Quadratic, interior knot of multiplicity 2 (C0): derivative jumps; right-hand one wins.
    let points = [
        [0.0, 0.0, 0.0],
        [1.0, 2.0, 0.0],
        [2.0, 0.0, 0.0],
        [4.0, 4.0, 0.0],
        [5.0, 0.0, 0.0],
    ];
    let knots = vec![0.0, 0.0, 0.0, 1.0, 1.0, 2.0, 2.0, 2.0];
    let c = curve(&points, None, Basis::BSpline { degree: 2, knots });
    let at = c.curve_derivatives(1.0, 1);
    assert_point(at[0], points[2], 1e-15, "interpolated C0 point");
    // Right piece is the Bézier (P2, P3, P4) on [1, 2]: C'(1) = 2 (P3 − P2).
    assert_point(at[1], [4.0, 8.0, 0.0], 1e-14, "right-hand derivative");
}

/// NURBS Book A2.3 (`DersBasisFuns`): derivatives 0..=n of the p+1 basis functions non-zero on
/// span i. Used only to cross-check the hodograph/de Boor path.
fn ders_basis_funs(i: usize, u: f64, p: usize, n: usize, knots: &[f64]) -> Vec<Vec<f64>> {
    let mut ndu = vec![vec![0.0; p + 1]; p + 1];
    let mut left = vec![0.0; p + 1];
    let mut right = vec![0.0; p + 1];
    ndu[0][0] = 1.0;
    for j in 1..=p {
        left[j] = u - knots[i + 1 - j];
        right[j] = knots[i + j] - u;
        let mut saved = 0.0;
        for r in 0..j {
            ndu[j][r] = right[r + 1] + left[j - r];
            let temp = ndu[r][j - 1] / ndu[j][r];
            ndu[r][j] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        ndu[j][j] = saved;
    }
    let mut ders = vec![vec![0.0; p + 1]; n + 1];
    for j in 0..=p {
        ders[0][j] = ndu[j][p];
    }
    let (p_i, n_top) = (p as i64, n.min(p));
    for r in 0..=p_i {
        let mut a = [vec![0.0; p + 1], vec![0.0; p + 1]];
        let (mut s1, mut s2) = (0, 1);
        a[0][0] = 1.0;
        for k in 1..=n_top as i64 {
            let mut d = 0.0;
            let (rk, pk) = (r - k, p_i - k);
            if r >= k {
                a[s2][0] = a[s1][0] / ndu[(pk + 1) as usize][rk as usize];
                d = a[s2][0] * ndu[rk as usize][pk as usize];
            }
            let j1 = if rk >= -1 { 1 } else { -rk };
            let j2 = if r - 1 <= pk { k - 1 } else { p_i - r };
            for j in j1..=j2 {
                let j = j as usize;
                a[s2][j] =
                    (a[s1][j] - a[s1][j - 1]) / ndu[(pk + 1) as usize][(rk + j as i64) as usize];
                d += a[s2][j] * ndu[(rk + j as i64) as usize][pk as usize];
            }
            if r <= pk {
                a[s2][k as usize] = -a[s1][(k - 1) as usize] / ndu[(pk + 1) as usize][r as usize];
                d += a[s2][k as usize] * ndu[r as usize][pk as usize];
            }
            ders[k as usize][r as usize] = d;
            std::mem::swap(&mut s1, &mut s2);
        }
    }
    let mut factor = p as f64;
    for k in 1..=n_top {
        for x in ders[k].iter_mut() {
            *x *= factor;
        }
        factor *= (p - k) as f64;
    }
    ders
}

/// Homogeneous derivatives of a B-spline curve via [`ders_basis_funs`].
fn curve_by_basis_functions(
    p: usize,
    knots: &[f64],
    pts: &[Homogeneous],
    t: f64,
    n: usize,
) -> Vec<Homogeneous> {
    let i = eval::find_span(p, knots, pts.len(), t);
    let ders = ders_basis_funs(i, t, p, n, knots);
    (0..=n)
        .map(|k| {
            let mut v = [0.0; 4];
            for j in 0..=p {
                v = eval::add(v, eval::scale(ders[k][j], pts[i - p + j]));
            }
            v
        })
        .collect()
}

fn lift(points: &[Point3], weights: Option<&Vec<f64>>) -> Vec<Homogeneous> {
    points
        .iter()
        .enumerate()
        .map(|(i, &p)| eval::homogeneous(p, weights.map_or(1.0, |w| w[i])))
        .collect()
}

/// Max over derivative orders of (max |difference| / max(1, max |value|)).
fn scaled_difference(a: &[Vec<Point3>], b: &[Vec<Point3>]) -> f64 {
    let orders = a[0].len();
    let mut worst = 0.0f64;
    for r in 0..orders {
        let scale = a
            .iter()
            .flat_map(|d| d[r])
            .fold(1.0f64, |m, x| nan_max(m, x.abs()));
        for (x, y) in a.iter().zip(b) {
            for k in 0..3 {
                worst = nan_max(worst, (x[r][k] - y[r][k]).abs() / scale);
            }
        }
    }
    worst
}

#[test]
fn bspline_curves_match_cox_de_boor_basis_functions() {
    let opts = Options::default();
    let mut worst = 0.0f64;
    for seed in 0..400 {
        let mut rng = Rng::new(1000 + seed);
        let object = random::random_object(&mut rng, Kind::BSplineCurve, "c", &opts);
        let Shape::Curve {
            basis: Basis::BSpline { degree, knots },
            points,
            weights,
        } = &object.shape
        else {
            unreachable!()
        };
        let h = lift(points, weights.as_ref());
        let n = 3;
        let params = object.params().remove(0);
        let ours: Vec<Vec<Point3>> = params
            .iter()
            .map(|&t| object.curve_derivatives(t, n))
            .collect();
        let theirs: Vec<Vec<Point3>> = params
            .iter()
            .map(|&t| {
                let mut hd = curve_by_basis_functions(*degree, knots, &h, t, n);
                if weights.is_none() {
                    // Polynomial: w ≡ 1 exactly (the basis-function sums are 1 and 0 only up to
                    // rounding, which the quotient rule would spread into every order).
                    hd.iter_mut()
                        .enumerate()
                        .for_each(|(k, x)| x[3] = if k == 0 { 1.0 } else { 0.0 });
                }
                project_curve_derivatives(&hd)
            })
            .collect();
        let diff = scaled_difference(&ours, &theirs);
        worst = nan_max(worst, diff);
        assert!(
            diff < 1e-12,
            "seed {seed}: hodograph path vs basis functions differ by {diff:e}"
        );
    }
    println!("B-spline curves, two algorithms: max scaled difference {worst:.2e}");
}

#[test]
fn bspline_surfaces_match_cox_de_boor_basis_functions() {
    let opts = Options {
        max_samples: 12,
        ..Options::default()
    };
    let mut worst = 0.0f64;
    for seed in 0..120 {
        let mut rng = Rng::new(5000 + seed);
        let object = random::random_object(&mut rng, Kind::BSplineSurface, "s", &opts);
        let Shape::Surface {
            basis:
                [
                    Basis::BSpline {
                        degree: du,
                        knots: ku,
                    },
                    Basis::BSpline {
                        degree: dv,
                        knots: kv,
                    },
                ],
            points,
            weights,
        } = &object.shape
        else {
            unreachable!()
        };
        let n = 2;
        let params = object.params();
        let grid = object.surface_grid(&params[0], &params[1], n);
        let (mut ours, mut theirs) = (Vec::new(), Vec::new());
        for (i, &u) in params[0].iter().enumerate() {
            let si = eval::find_span(*du, ku, points.len(), u);
            let bu = ders_basis_funs(si, u, *du, n, ku);
            for (j, &v) in params[1].iter().enumerate() {
                let sj = eval::find_span(*dv, kv, points[0].len(), v);
                let bv = ders_basis_funs(sj, v, *dv, n, kv);
                let mut h = vec![vec![[0.0; 4]; n + 1]; n + 1];
                for (a, row) in h.iter_mut().enumerate() {
                    for (b, cell) in row.iter_mut().enumerate() {
                        for k in 0..=*du {
                            for l in 0..=*dv {
                                let (pi, pj) = (si - du + k, sj - dv + l);
                                let w = weights.as_ref().map_or(1.0, |w| w[pi][pj]);
                                let pt = eval::homogeneous(points[pi][pj], w);
                                let c = bu.get(a).map_or(0.0, |x| x[k])
                                    * bv.get(b).map_or(0.0, |x| x[l]);
                                *cell = eval::add(*cell, eval::scale(c, pt));
                            }
                        }
                    }
                }
                if weights.is_none() {
                    for (a, row) in h.iter_mut().enumerate() {
                        for (b, cell) in row.iter_mut().enumerate() {
                            cell[3] = if a + b == 0 { 1.0 } else { 0.0 };
                        }
                    }
                }
                let s = eval::project_surface_derivatives(&h);
                // Flatten (a, b) into one "order" axis for the scaled comparison.
                ours.push(grid[i][j].iter().flatten().copied().collect::<Vec<_>>());
                theirs.push(s.iter().flatten().copied().collect::<Vec<_>>());
            }
        }
        let diff = scaled_difference(&ours, &theirs);
        worst = nan_max(worst, diff);
        assert!(
            diff < 1e-12,
            "seed {seed}: surface paths differ by {diff:e}"
        );
    }
    println!("B-spline surfaces, two algorithms: max scaled difference {worst:.2e}");
}

#[test]
fn bezier_equals_clamped_bspline() {
    let mut rng = Rng::new(99);
    for _ in 0..200 {
        let p = rng.int(0, 10);
        let pts: Vec<Point3> = (0..=p)
            .map(|_| std::array::from_fn(|_| rng.range(-10.0, 10.0)))
            .collect();
        let weights = rng
            .chance(0.5)
            .then(|| (0..=p).map(|_| rng.range(0.2, 5.0)).collect::<Vec<_>>());
        let mut knots = vec![0.0; p + 1];
        knots.extend(vec![1.0; p + 1]);
        let bezier = curve(&pts, weights.clone(), Basis::Bezier);
        let bspline = curve(&pts, weights, Basis::BSpline { degree: p, knots });
        let ts: Vec<f64> = (0..=20).map(|j| j as f64 / 20.0).collect();
        let a: Vec<_> = ts.iter().map(|&t| bezier.curve_derivatives(t, 4)).collect();
        let b: Vec<_> = ts
            .iter()
            .map(|&t| bspline.curve_derivatives(t, 4))
            .collect();
        let diff = scaled_difference(&a, &b);
        assert!(diff < 1e-12, "degree {p}: {diff:e}");
    }
}

// ---------------------------------------------------------------------------------------------
// Finite differences on random scenes (all six types)
// ---------------------------------------------------------------------------------------------

/// Random parameters strictly inside smooth pieces of direction `dir`, with a safe step.
fn interior_params(object: &Object, dir: usize, rng: &mut Rng, count: usize) -> Vec<(f64, f64)> {
    let pieces: Vec<(f64, f64)> = match &object.shape {
        Shape::Curve { basis, points, .. } => breaks(basis, points.len()),
        Shape::Surface { basis, points, .. } => {
            let n = if dir == 0 {
                points.len()
            } else {
                points[0].len()
            };
            breaks(&basis[dir], n)
        }
        Shape::ErbsCurve { knots, .. } => knots[1..knots.len() - 1]
            .windows(2)
            .map(|w| (w[0], w[1]))
            .collect(),
        Shape::ErbsSurface { knots, .. } => {
            let k = &knots[dir];
            k[1..k.len() - 1].windows(2).map(|w| (w[0], w[1])).collect()
        }
    };
    (0..count)
        .map(|_| {
            let &(a, b) = rng.pick(&pieces);
            (
                rng.range(a + 0.1 * (b - a), b - 0.1 * (b - a)),
                2e-4 * (b - a),
            )
        })
        .collect()
}

/// The non-empty knot spans inside the domain.
fn breaks(basis: &Basis, n: usize) -> Vec<(f64, f64)> {
    match basis {
        Basis::Bezier => vec![(0.0, 1.0)],
        Basis::BSpline { degree, knots } => (*degree..n)
            .filter(|&i| knots[i] < knots[i + 1])
            .map(|i| (knots[i], knots[i + 1]))
            .collect(),
    }
}

#[test]
fn derivatives_match_finite_differences() {
    let opts = Options {
        max_samples: 6,
        ..Options::default()
    };
    let order = 3;
    let mut worst = 0.0f64;
    for seed in 0..150 {
        let scene = random::random_scene(seed, &Kind::ALL, &opts);
        let mut rng = Rng::new(seed ^ 0xF00D);
        for object in &scene.objects {
            if object.is_surface() {
                let params = object.params();
                let grid = object.surface_grid(&params[0], &params[1], order + 1);
                let mut scale = vec![vec![1.0f64; order + 2]; order + 2];
                for cell in grid.iter().flatten() {
                    for (a, row) in cell.iter().enumerate() {
                        for (b, v) in row.iter().enumerate() {
                            scale[a][b] = v.iter().fold(scale[a][b], |m, x| nan_max(m, x.abs()));
                        }
                    }
                }
                let us = interior_params(object, 0, &mut rng, 4);
                let vs = interior_params(object, 1, &mut rng, 4);
                for (&(u, hu), &(v, hv)) in us.iter().zip(&vs) {
                    let exact = object.surface_derivatives(u, v, order + 1);
                    let flat = |d: Vec<Vec<Point3>>| -> Vec<f64> {
                        d.iter()
                            .take(order + 1)
                            .flat_map(|r| {
                                r.iter()
                                    .take(order + 1)
                                    .flatten()
                                    .copied()
                                    .collect::<Vec<_>>()
                            })
                            .collect()
                    };
                    let fd_u = richardson(|x| flat(object.surface_derivatives(x, v, order)), u, hu);
                    let fd_v = richardson(|y| flat(object.surface_derivatives(u, y, order)), v, hv);
                    for a in 0..=order {
                        for b in 0..=order {
                            // Scale: the sample grid may straddle only knots, where expo-rational
                            // ERBS derivatives vanish; include the values at this point.
                            let local =
                                |d: Point3, s: f64| d.iter().fold(s, |m, x| nan_max(m, x.abs()));
                            let su = local(exact[a + 1][b], scale[a + 1][b]);
                            let sv = local(exact[a][b + 1], scale[a][b + 1]);
                            for k in 0..3 {
                                let idx = (a * (order + 1) + b) * 3 + k;
                                let eu = (fd_u[idx] - exact[a + 1][b][k]).abs() / su;
                                let ev = (fd_v[idx] - exact[a][b + 1][k]).abs() / sv;
                                worst = nan_max(nan_max(worst, eu), ev);
                                assert!(
                                    eu < 1e-6 && ev < 1e-6,
                                    "seed {seed} {} ({a},{b})[{k}] at ({u},{v}): u {eu:e}, v {ev:e}",
                                    object.type_name()
                                );
                            }
                        }
                    }
                }
            } else {
                let params = object.params();
                let mut scale = vec![1.0f64; order + 2];
                for t in &params[0] {
                    for (r, v) in object.curve_derivatives(*t, order + 1).iter().enumerate() {
                        scale[r] = v.iter().fold(scale[r], |m, x| nan_max(m, x.abs()));
                    }
                }
                for (t, h) in interior_params(object, 0, &mut rng, 8) {
                    let exact = object.curve_derivatives(t, order + 1);
                    let fd = richardson(
                        |x| {
                            object
                                .curve_derivatives(x, order)
                                .into_iter()
                                .flatten()
                                .collect()
                        },
                        t,
                        h,
                    );
                    for r in 0..=order {
                        let s = exact[r + 1]
                            .iter()
                            .fold(scale[r + 1], |m, x| nan_max(m, x.abs()));
                        for k in 0..3 {
                            let e = (fd[r * 3 + k] - exact[r + 1][k]).abs() / s;
                            worst = nan_max(worst, e);
                            assert!(
                                e < 1e-6,
                                "seed {seed} {} order {} at {t}: {} vs FD {} ({e:e})",
                                object.type_name(),
                                r + 1,
                                exact[r + 1][k],
                                fd[r * 3 + k]
                            );
                        }
                    }
                }
            }
        }
    }
    println!("random scenes: worst scaled Richardson FD error {worst:.2e}");
}

// ---------------------------------------------------------------------------------------------
// ERBS properties
// ---------------------------------------------------------------------------------------------

#[test]
fn erbs_interpolates_local_curves_at_knots() {
    let opts = Options::default();
    for seed in 0..200 {
        let mut rng = Rng::new(seed);
        let object = random::random_object(&mut rng, Kind::ErbsCurve, "e", &opts);
        let Shape::ErbsCurve {
            knots,
            locals,
            bfunction,
        } = &object.shape
        else {
            unreachable!()
        };
        let b = bfunction.unwrap_or(BFunction::Expo);
        // Expo-rational: every derivative of B vanishes at 0 and 1; smootherstep: up to 2; the
        // others: the first derivative only.
        let smooth = match b {
            BFunction::Expo => 4,
            BFunction::Smootherstep => 2,
            _ => 1,
        };
        for (l, local) in locals.iter().enumerate() {
            let t = knots[l + 1];
            let ours = object.curve_derivatives(t, smooth);
            let direct = eval::erbs_local_curve_derivatives(knots, l, local, t, smooth);
            for r in 0..=smooth {
                let scale = 1.0 + direct[r].iter().fold(0.0f64, |m, x| nan_max(m, x.abs()));
                for k in 0..3 {
                    assert!(
                        close(ours[r][k], direct[r][k], 1e-13 * scale),
                        "seed {seed} {b:?}: c^({r})(t_{}) = {:?}, local {l} gives {:?}",
                        l + 1,
                        ours[r],
                        direct[r]
                    );
                }
            }
        }
    }
}

#[test]
fn erbs_with_equal_constant_locals_is_constant() {
    let p = [3.0, -2.0, 7.5];
    for b in BFunction::ALL {
        let knots = vec![0.0, 0.0, 0.7, 1.5, 2.0, 2.0];
        let object = Object {
            name: "e".into(),
            shape: Shape::ErbsCurve {
                knots: knots.clone(),
                locals: vec![vec![p]; 4],
                bfunction: Some(b),
            },
            samples: vec![2],
        };
        for j in 0..=40 {
            let t = 2.0 * j as f64 / 40.0;
            let d = object.curve_derivatives(t, 4);
            assert_point(d[0], p, 1e-14, "constant ERBS");
            for r in 1..=4 {
                assert_point(d[r], [0.0; 3], 1e-11, "derivative of constant ERBS");
            }
        }
        let surface = Object {
            name: "s".into(),
            shape: Shape::ErbsSurface {
                knots: [knots.clone(), vec![-1.0, -1.0, 0.0, 1.0, 1.0]],
                locals: vec![vec![vec![vec![p; 2]; 3]; 3]; 4],
                bfunction: Some(b),
            },
            samples: vec![2, 2],
        };
        for (u, v) in [(0.0, -1.0), (0.3, 0.2), (1.5, 0.0), (2.0, 1.0)] {
            let d = surface.surface_derivatives(u, v, 3);
            assert_point(d[0][0], p, 1e-14, "constant ERBS surface");
            for (a, row) in d.iter().enumerate() {
                for (bb, x) in row.iter().enumerate() {
                    if a + bb > 0 {
                        assert_point(*x, [0.0; 3], 1e-10, "derivative of constant surface");
                    }
                }
            }
        }
    }
}

#[test]
fn erbs_blend_values_by_hand() {
    let table = reference_table();
    let b_at = |t: f64| table.iter().find(|(x, _)| *x == t).unwrap().1[0];
    let (p, q) = ([1.0, 2.0, 3.0], [-4.0, 0.5, 10.0]);
    // Two constant local curves on [0, 1]: c(t) = (1 − B(t)) P + B(t) Q.
    let curve = Object {
        name: "e".into(),
        shape: Shape::ErbsCurve {
            knots: vec![0.0, 0.0, 1.0, 1.0],
            locals: vec![vec![p], vec![q]],
            bfunction: None,
        },
        samples: vec![2],
    };
    for t in [0.25, 0.5, 0.75] {
        let b = b_at(t);
        let expected = std::array::from_fn(|k| (1.0 - b) * p[k] + b * q[k]);
        assert_point(
            curve.curve_derivatives(t, 0)[0],
            expected,
            1e-15 * 10.0,
            "ERBS blend",
        );
    }
    // A linear local curve is mapped onto [t_l, t_{l+2}]: knots 0, 0, 1, 3, 3 → local 1 lives on
    // [0, 3] and the curve passes through local 1 at s = 1/3 when t = t_2 = 1.
    let (a, z) = ([0.0, 0.0, 0.0], [3.0, 6.0, -3.0]);
    let curve = Object {
        name: "e".into(),
        shape: Shape::ErbsCurve {
            knots: vec![0.0, 0.0, 1.0, 3.0, 3.0],
            locals: vec![vec![p], vec![a, z], vec![q]],
            bfunction: Some(BFunction::Smoothstep),
        },
        samples: vec![2],
    };
    let d = curve.curve_derivatives(1.0, 1);
    assert_point(d[0], [1.0, 2.0, -1.0], 1e-15, "local curve at s = 1/3");
    assert_point(d[1], [1.0, 2.0, -1.0], 1e-15, "local derivative (z − a)/3");
    // 2 × 2 constant patches: S(u, v) = Σ B_k(u) B_l(v) P_kl.
    let corners = [[p, q], [a, z]];
    let surface = Object {
        name: "s".into(),
        shape: Shape::ErbsSurface {
            knots: [vec![0.0, 0.0, 1.0, 1.0], vec![0.0, 0.0, 1.0, 1.0]],
            locals: corners
                .iter()
                .map(|row| row.iter().map(|&c| vec![vec![c]]).collect())
                .collect(),
            bfunction: None,
        },
        samples: vec![2, 2],
    };
    let (u, v) = (0.25, 0.75);
    let (bu, bv) = (b_at(u), b_at(v));
    let wu = [1.0 - bu, bu];
    let wv = [1.0 - bv, bv];
    let expected = std::array::from_fn(|k| {
        (0..2)
            .map(|i| {
                (0..2)
                    .map(|j| wu[i] * wv[j] * corners[i][j][k])
                    .sum::<f64>()
            })
            .sum()
    });
    assert_point(
        surface.surface_derivatives(u, v, 0)[0][0],
        expected,
        1e-14,
        "ERBS patch blend",
    );
}

#[test]
fn erbs_right_hand_second_derivative_at_knot() {
    // Smoothstep is only C1 at the knots: at t_2 the interval [t_2, t_3) decides.
    let knots = vec![0.0, 0.0, 1.0, 3.0, 3.0];
    let locals = vec![
        vec![[0.0, 0.0, 0.0]],
        vec![[1.0, 0.0, 0.0], [2.0, 1.0, 0.0]],
        vec![[5.0, 5.0, 5.0]],
    ];
    let object = Object {
        name: "e".into(),
        shape: Shape::ErbsCurve {
            knots: knots.clone(),
            locals: locals.clone(),
            bfunction: Some(BFunction::Smoothstep),
        },
        samples: vec![2],
    };
    let d = object.curve_derivatives(1.0, 2);
    // On [1, 3): c = c_1 + B(w)(c_2 − c_1), w = (t−1)/2; at w = 0: B = B' = 0, B'' = 6.
    let c1 = eval::erbs_local_curve_derivatives(&knots, 1, &locals[1], 1.0, 2);
    let diff = eval::sub([5.0, 5.0, 5.0], c1[0]);
    assert_point(d[0], c1[0], 1e-15, "value");
    assert_point(d[1], c1[1], 1e-15, "first derivative");
    let expected = eval::add(c1[2], eval::scale(6.0 / 4.0, diff));
    assert_point(d[2], expected, 1e-14, "right-hand second derivative");
}

// ---------------------------------------------------------------------------------------------
// Edits
// ---------------------------------------------------------------------------------------------

fn parse_edit(v: Value) -> Edit {
    Edit::from_json(&v).unwrap()
}

#[test]
fn edit_semantics() {
    let mut scene = random::random_scene(
        42,
        &Kind::ALL,
        &Options {
            max_samples: 5,
            ..Options::default()
        },
    );
    let before = scene.sample_json(2);
    // Identity transform and zero deltas change nothing.
    let identity = [
        [1.0, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ];
    let noop = vec![
        parse_edit(json!({"object": "o2", "local": 1, "transform": identity})),
        parse_edit(json!({"object": "o5", "local": [1, 1], "transform": identity})),
        parse_edit(json!({"object": "o0", "point": 0, "delta": [0.0, 0.0, 0.0]})),
        parse_edit(json!({"object": "o4", "point": [0, 0], "delta": [0.0, 0.0, 0.0]})),
    ];
    apply_edits(&mut scene, &noop).unwrap();
    assert_eq!(scene.sample_json(2), before);

    // A row-major translation matrix moves every local control point by its last column.
    let mut moved = scene.clone();
    let shift = [
        [1.0, 0.0, 0.0, 2.0],
        [0.0, 1.0, 0.0, -3.0],
        [0.0, 0.0, 1.0, 0.5],
        [0.0, 0.0, 0.0, 1.0],
    ];
    apply_edits(
        &mut moved,
        &[parse_edit(
            json!({"object": "o2", "local": 0, "transform": shift}),
        )],
    )
    .unwrap();
    let (Shape::ErbsCurve { locals: a, .. }, Shape::ErbsCurve { locals: b, .. }) =
        (&scene.objects[2].shape, &moved.objects[2].shape)
    else {
        unreachable!()
    };
    for (p, q) in a[0].iter().zip(&b[0]) {
        assert_point(
            *q,
            [p[0] + 2.0, p[1] - 3.0, p[2] + 0.5],
            1e-12 * (1.0 + p[0].abs() + p[1].abs()),
            "translated",
        );
    }
    assert_eq!(a[1..], b[1..]);

    // A weight of 1 on a non-rational curve makes it rational without changing it.
    let mut plain = Scene {
        objects: vec![curve(&LECTURE_POINTS, None, Basis::Bezier)],
    };
    let reference = plain.objects[0].curve_derivatives(0.3, 3);
    apply_edits(
        &mut plain,
        &[parse_edit(
            json!({"object": "c", "point": 2, "weight": 1.0}),
        )],
    )
    .unwrap();
    let Shape::Curve { weights, .. } = &plain.objects[0].shape else {
        unreachable!()
    };
    assert_eq!(weights.as_deref(), Some(&[1.0, 1.0, 1.0, 1.0][..]));
    let now = plain.objects[0].curve_derivatives(0.3, 3);
    for r in 0..=3 {
        assert_point(now[r], reference[r], 1e-12, "weight 1");
    }
    // Moving a rational point moves the Cartesian point; the weight stays.
    apply_edits(
        &mut plain,
        &[parse_edit(
            json!({"object": "c", "point": 2, "weight": 3.0}),
        )],
    )
    .unwrap();
    apply_edits(
        &mut plain,
        &[parse_edit(
            json!({"object": "c", "point": 2, "delta": [1.0, 0.0, 0.0]}),
        )],
    )
    .unwrap();
    let Shape::Curve {
        points, weights, ..
    } = &plain.objects[0].shape
    else {
        unreachable!()
    };
    assert_eq!(points[2], [11.0, 10.0, 0.0]);
    assert_eq!(weights.as_ref().unwrap()[2], 3.0);
    // The end point of a rational Bézier is its last control point whatever the weights.
    assert_point(
        plain.objects[0].curve_derivatives(1.0, 0)[0],
        [10.0, 1.0, 0.0],
        1e-15,
        "end point",
    );

    // Unknown objects, out-of-range indices and wrong kinds of edit are errors.
    for bad in [
        json!({"object": "nope", "point": 0, "delta": [0, 0, 0]}),
        json!({"object": "o0", "point": 99, "delta": [0, 0, 0]}),
        json!({"object": "o0", "point": [0, 0], "delta": [0, 0, 0]}),
        json!({"object": "o2", "point": 0, "delta": [0, 0, 0]}),
        json!({"object": "o2", "local": 99, "transform": identity}),
        json!({"object": "o5", "local": [0, 0], "point": [99, 0], "delta": [0, 0, 0]}),
    ] {
        let mut s = scene.clone();
        assert!(
            apply_edits(&mut s, &[parse_edit(bad.clone())]).is_err(),
            "accepted {bad}"
        );
    }
}

#[test]
fn affine_transform_of_all_locals_transforms_the_erbs() {
    let opts = Options::default();
    for seed in 0..60 {
        let mut rng = Rng::new(seed);
        let kind = if seed % 2 == 0 {
            Kind::ErbsCurve
        } else {
            Kind::ErbsSurface
        };
        let object = random::random_object(&mut rng, kind, "e", &opts);
        let matrix = random::random_affine(&mut rng, object.magnitude());
        let mut scene = Scene {
            objects: vec![object.clone()],
        };
        let edits: Vec<Edit> = match &object.shape {
            Shape::ErbsCurve { locals, .. } => (0..locals.len())
                .map(|l| Edit::LocalTransform {
                    object: "e".into(),
                    local: Index::One(l),
                    matrix,
                })
                .collect(),
            Shape::ErbsSurface { locals, .. } => (0..locals.len())
                .flat_map(|k| (0..locals[0].len()).map(move |l| (k, l)))
                .map(|(k, l)| Edit::LocalTransform {
                    object: "e".into(),
                    local: Index::Two(k, l),
                    matrix,
                })
                .collect(),
            _ => unreachable!(),
        };
        apply_edits(&mut scene, &edits).unwrap();
        let linear = |p: Point3| -> Point3 {
            std::array::from_fn(|r| (0..3).map(|c| matrix[r][c] * p[c]).sum())
        };
        let n = 2;
        let check = |before: Vec<Point3>, after: Vec<Point3>| {
            let scale = 1.0
                + before
                    .iter()
                    .chain(&after)
                    .flatten()
                    .fold(0.0f64, |m, x| nan_max(m, x.abs()));
            for (r, (x, y)) in before.iter().zip(&after).enumerate() {
                let expected = if r == 0 {
                    oracle::scene::affine(&matrix, *x)
                } else {
                    linear(*x)
                };
                assert_point(*y, expected, 1e-12 * scale, "affine invariance");
            }
        };
        if object.is_surface() {
            let params = object.params();
            let (a, b) = (
                object.surface_grid(&params[0], &params[1], n),
                scene.objects[0].surface_grid(&params[0], &params[1], n),
            );
            for (x, y) in a.iter().flatten().zip(b.iter().flatten()) {
                check(
                    x.iter().flatten().copied().collect(),
                    y.iter().flatten().copied().collect(),
                );
            }
        } else {
            for t in object.params().remove(0) {
                check(
                    object.curve_derivatives(t, n),
                    scene.objects[0].curve_derivatives(t, n),
                );
            }
        }
    }
}

#[test]
fn random_edits_are_valid_and_reversible_deltas() {
    let opts = Options {
        max_samples: 6,
        ..Options::default()
    };
    for seed in 0..100 {
        let scene = random::random_scene(seed, &Kind::ALL, &opts);
        let mut rng = Rng::new(seed);
        let edits = random::random_edits(&mut rng, &scene, 25);
        let json_edits = Value::Array(edits.iter().map(Edit::to_json).collect());
        let parsed = oracle::scene::parse_edits(&json_edits).unwrap();
        assert_eq!(parsed, edits, "edit JSON round trip");
        let mut edited = scene.clone();
        apply_edits(&mut edited, &edits).unwrap();
        // Edited models (e.g. objects made rational by a weight edit) stay valid scenes.
        let reparsed = Scene::from_json(&edited.to_json()).unwrap();
        assert_eq!(reparsed, edited, "seed {seed}: edited scene round trip");
        // Undo the pure translations in reverse order: deltas cancel (up to rounding).
        let deltas: Vec<Edit> = edits
            .iter()
            .rev()
            .filter_map(|e| match e {
                Edit::PointDelta {
                    object,
                    point,
                    delta,
                } => Some(Edit::PointDelta {
                    object: object.clone(),
                    point: *point,
                    delta: eval::scale(-1.0, *delta),
                }),
                Edit::LocalPointDelta {
                    object,
                    local,
                    point,
                    delta,
                } => Some(Edit::LocalPointDelta {
                    object: object.clone(),
                    local: *local,
                    point: *point,
                    delta: eval::scale(-1.0, *delta),
                }),
                _ => None,
            })
            .collect();
        let only_deltas: Vec<Edit> = edits
            .iter()
            .filter(|e| matches!(e, Edit::PointDelta { .. } | Edit::LocalPointDelta { .. }))
            .cloned()
            .collect();
        let mut round_trip = scene.clone();
        apply_edits(&mut round_trip, &only_deltas).unwrap();
        apply_edits(&mut round_trip, &deltas).unwrap();
        let report = compare_output(&scene, 1, &round_trip.sample_json(1), 1e-12);
        assert!(
            report.ok(),
            "seed {seed}: delta round trip\n{}",
            report.describe()
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Scene model, sampling and the comparison used against the product
// ---------------------------------------------------------------------------------------------

#[test]
fn sample_params_follow_the_formula() {
    assert_eq!(sample_params(0.0, 1.0, 2), vec![0.0, 1.0]);
    assert_eq!(sample_params(-1.0, 3.0, 5), vec![-1.0, 0.0, 1.0, 2.0, 3.0]);
    let p = sample_params(0.1, 0.7, 7);
    assert_eq!(p[6], 0.7);
    assert_eq!(p[3], 0.1 + (0.7 - 0.1) * (3.0 / 6.0));
    assert!(p.windows(2).all(|w| w[0] < w[1]));
}

#[test]
fn random_scenes_round_trip_and_sample_in_contract_shape() {
    for seed in 0..200 {
        let scene = random::random_scene(
            seed,
            &Kind::ALL,
            &Options {
                max_samples: 4,
                ..Options::default()
            },
        );
        let text = serde_json::to_string(&scene.to_json()).unwrap();
        let parsed = Scene::from_json(&serde_json::from_str(&text).unwrap()).unwrap();
        assert_eq!(parsed, scene, "seed {seed}: scene JSON round trip");
        let n = (seed % 3) as usize;
        let out = scene.sample_json(n);
        for (entry, object) in out["objects"]
            .as_array()
            .unwrap()
            .iter()
            .zip(&scene.objects)
        {
            assert_eq!(entry["name"], json!(object.name));
            assert_eq!(entry["type"], json!(object.type_name()));
            let samples = entry["samples"].as_array().unwrap();
            if object.is_surface() {
                assert_eq!(entry["params"].as_array().unwrap().len(), 2);
                assert_eq!(samples.len(), object.samples[0]);
                assert_eq!(samples[0].as_array().unwrap().len(), object.samples[1]);
                assert_eq!(samples[0][0].as_array().unwrap().len(), n + 1);
                assert_eq!(samples[0][0][0].as_array().unwrap().len(), n + 1);
                assert_eq!(samples[0][0][0][0].as_array().unwrap().len(), 3);
            } else {
                assert_eq!(entry["params"].as_array().unwrap().len(), object.samples[0]);
                assert_eq!(samples.len(), object.samples[0]);
                assert_eq!(samples[0].as_array().unwrap().len(), n + 1);
                assert_eq!(samples[0][0].as_array().unwrap().len(), 3);
            }
            for x in flatten_numbers(&entry["samples"]) {
                assert!(x.is_finite());
            }
        }
        let report = compare_output(&scene, n, &out, 0.0);
        assert!(
            report.ok(),
            "seed {seed}: self comparison\n{}",
            report.describe()
        );
    }
}

fn flatten_numbers(v: &Value) -> Vec<f64> {
    match v {
        Value::Array(items) => items.iter().flat_map(flatten_numbers).collect(),
        Value::Number(x) => vec![x.as_f64().unwrap()],
        _ => panic!("not numeric: {v}"),
    }
}

#[test]
fn invalid_scenes_are_rejected() {
    let good = json!({"objects": [{"name": "c", "type": "bspline_curve", "degree": 2,
        "knots": [0, 0, 0, 1, 1, 1], "points": [[0,0,0],[1,1,0],[2,0,0]], "samples": 5}]});
    assert!(Scene::from_json(&good).is_ok());
    let mut cases = Vec::new();
    for (key, value) in [
        ("knots", json!([0, 0, 1, 1, 1])),
        ("knots", json!([0, 0, 0, 1, 0.5, 1])),
        ("degree", json!(3)),
        ("samples", json!(1)),
        ("extra", json!(1)),
        ("points", json!([[0, 0], [1, 1, 0], [2, 0, 0]])),
    ] {
        let mut bad = good.clone();
        bad["objects"][0][key] = value;
        cases.push(bad);
    }
    cases.push(json!({"objects": [{"name": "e", "type": "erbs_curve", "knots": [0, 0, 1, 1],
        "local": [{"points": [[0,0,0]]}, {"points": [[1,0,0]]}], "bfunction": "cubic", "samples": 3}]}));
    cases.push(
        json!({"objects": [{"name": "e", "type": "erbs_curve", "knots": [0, 0.5, 1, 1],
        "local": [{"points": [[0,0,0]]}, {"points": [[1,0,0]]}], "samples": 3}]}),
    );
    for bad in cases {
        assert!(Scene::from_json(&bad).is_err(), "accepted {bad}");
    }
}

#[test]
fn comparison_detects_mismatches() {
    let scene = random::random_scene(
        5,
        &Kind::ALL,
        &Options {
            max_samples: 5,
            ..Options::default()
        },
    );
    let n = 2;
    let out = scene.sample_json(n);
    assert!(compare_output(&scene, n, &out, 1e-12).ok());

    // One perturbed number in a surface: reported with its location.
    let mut bad = out.clone();
    let x = bad["objects"][4]["samples"][1][0][1][0][2]
        .as_f64()
        .unwrap();
    bad["objects"][4]["samples"][1][0][1][0][2] = json!(x + 1e-6 * (1.0 + x.abs()));
    let report = compare_output(&scene, n, &bad, 1e-12);
    assert_eq!(report.mismatch_count, 1, "{}", report.describe());
    assert!(
        report.mismatches[0]
            .location
            .starts_with("samples[1][0][1][0] "),
        "{}",
        report.describe()
    );
    assert!(report.mismatches[0].location.ends_with("[2]"));

    // A tiny relative perturbation passes.
    let mut fine = out.clone();
    let x = fine["objects"][1]["samples"][0][1][0].as_f64().unwrap();
    fine["objects"][1]["samples"][0][1][0] = json!(x * (1.0 + 1e-15));
    assert!(compare_output(&scene, n, &fine, 1e-12).ok());

    // Structural problems.
    let mut missing = out.clone();
    missing["objects"].as_array_mut().unwrap().remove(3);
    assert!(!compare_output(&scene, n, &missing, 1e-12).ok());
    let mut params = out.clone();
    let t = params["objects"][0]["params"][1].as_f64().unwrap();
    params["objects"][0]["params"][1] = json!(t + 1e-9);
    assert!(
        !compare_output(&scene, n, &params, 1e-12)
            .problems
            .is_empty()
    );
    let mut shape = out.clone();
    shape["objects"][0]["samples"][0]
        .as_array_mut()
        .unwrap()
        .pop();
    assert!(!compare_output(&scene, n, &shape, 1e-12).problems.is_empty());
    assert!(
        !compare_output(&scene, n + 1, &out, 1e-12).ok(),
        "wrong derivative count"
    );
}

/// Negative controls of the error measure: a small object is held to its own size (a floor
/// of 1 on the scale let errors 1000× larger through on a millimetre-sized curve), and a NaN on
/// the oracle side is a mismatch that makes the maximum error NaN.
#[test]
fn comparison_is_relative_to_each_object_and_catches_nan() {
    let scene = Scene::from_json(&json!({"objects": [
        {"name": "tiny", "type": "bezier_curve",
         "points": [[0.001, 0.001, 0], [0.001, 0.01, 0], [0.01, 0.01, 0], [0.01, 0.001, 0]],
         "samples": 5}]}))
    .unwrap();
    let out = scene.sample_json(2);
    assert!(compare_output(&scene, 2, &out, 1e-12).ok());
    let mut off = out.clone();
    let x = off["objects"][0]["samples"][2][0][1].as_f64().unwrap();
    // 1e-10 of this object's size: far above the tolerance, far below 1e-12 × 1.
    off["objects"][0]["samples"][2][0][1] = json!(x + 1e-10 * 0.01);
    let report = compare_output(&scene, 2, &off, 1e-12);
    assert_eq!(report.mismatch_count, 1, "{}", report.describe());

    let mut poisoned = scene.clone();
    if let Shape::Curve { points, .. } = &mut poisoned.objects[0].shape {
        points[1][1] = f64::NAN;
    }
    let report = compare_output(&poisoned, 2, &out, 1e-12);
    assert!(!report.ok() && report.mismatch_count > 0);
    assert!(
        report.max_relative_error.is_nan(),
        "{}",
        report.max_relative_error
    );
    assert!(nan_max(0.0, f64::NAN).is_nan() && nan_max(f64::NAN, 1.0).is_nan());
}

/// The generator really produces the features the agreement test relies on.
#[test]
fn random_generator_covers_the_contract() {
    use std::collections::BTreeMap;
    let mut seen: BTreeMap<&str, usize> = BTreeMap::new();
    let mut mark = |key: &'static str, yes: bool| {
        if yes {
            *seen.entry(key).or_default() += 1;
        }
    };
    let opts = Options::default();
    for seed in 0..300 {
        let scene = random::random_scene(seed, &Kind::ALL, &opts);
        for object in &scene.objects {
            let params = object.params();
            mark("2 samples", object.samples.contains(&2));
            mark("40 samples", object.samples.contains(&40));
            let mut knot_checks: Vec<(usize, &Vec<f64>, usize)> = Vec::new();
            match &object.shape {
                Shape::Curve {
                    basis,
                    points,
                    weights,
                } => {
                    mark("rational curve", weights.is_some());
                    if let Basis::BSpline { degree, knots } = basis {
                        knot_checks.push((*degree, knots, points.len()));
                    } else {
                        mark("bezier degree 0", points.len() == 1);
                        mark("bezier degree > 5", points.len() > 6);
                    }
                }
                Shape::Surface {
                    basis,
                    points,
                    weights,
                } => {
                    mark("rational surface", weights.is_some());
                    for (dir, b) in basis.iter().enumerate() {
                        if let Basis::BSpline { degree, knots } = b {
                            let n = if dir == 0 {
                                points.len()
                            } else {
                                points[0].len()
                            };
                            knot_checks.push((*degree, knots, n));
                        }
                    }
                }
                Shape::ErbsCurve {
                    knots,
                    locals,
                    bfunction,
                } => {
                    mark(
                        bfunction.map_or("erbs default bfunction", |b| b.name()),
                        true,
                    );
                    mark("erbs constant local", locals.iter().any(|l| l.len() == 1));
                    let interior = &knots[2..knots.len() - 2];
                    mark(
                        "erbs param on knot",
                        params[0].iter().any(|t| interior.contains(t)),
                    );
                }
                Shape::ErbsSurface {
                    bfunction, locals, ..
                } => {
                    mark(
                        bfunction.map_or("erbs default bfunction", |b| b.name()),
                        true,
                    );
                    mark(
                        "erbs patch of degree 0 in u",
                        locals.iter().flatten().any(|g| g.len() == 1),
                    );
                }
            }
            for (p, knots, n) in knot_checks {
                mark("bspline degree 0", p == 0);
                mark("bspline degree > 5", p > 5);
                let clamped_start = knots[0] == knots[p];
                mark("clamped start", clamped_start && p > 0);
                mark("unclamped start", !clamped_start);
                // Largest multiplicity of a knot value strictly inside the domain.
                let (a, b) = (knots[p], knots[n]);
                let max_interior = knots
                    .iter()
                    .filter(|&&k| k > a && k < b)
                    .map(|k| knots.iter().filter(|&&x| x == *k).count())
                    .max()
                    .unwrap_or(0);
                mark(
                    "interior multiplicity 2..=p",
                    max_interior >= 2 && max_interior <= p,
                );
                mark("interior multiplicity p+1", p > 0 && max_interior == p + 1);
                let interior: Vec<f64> =
                    knots.iter().copied().filter(|&k| k > a && k < b).collect();
                mark(
                    "bspline param on interior knot",
                    params.iter().flatten().any(|t| interior.contains(t)),
                );
            }
        }
    }
    println!("{seen:#?}");
    for key in [
        "2 samples",
        "40 samples",
        "rational curve",
        "rational surface",
        "bezier degree 0",
        "bezier degree > 5",
        "bspline degree 0",
        "bspline degree > 5",
        "clamped start",
        "unclamped start",
        "interior multiplicity 2..=p",
        "interior multiplicity p+1",
        "bspline param on interior knot",
        "erbs default bfunction",
        "expo",
        "smoothstep",
        "smootherstep",
        "trigonometric",
        "rational",
        "erbs constant local",
        "erbs param on knot",
        "erbs patch of degree 0 in u",
    ] {
        assert!(
            seen.get(key).copied().unwrap_or(0) >= 3,
            "generator rarely produces {key:?}: {seen:?}"
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Structural edits: refinement by blossoming (tests/oracle/blossom.rs)
// ---------------------------------------------------------------------------------------------

/// A random homogeneous degree-p spline with n points on a random (clamped or not, possibly
/// discontinuous) knot vector.
fn random_spline(rng: &mut Rng, p: usize, n: usize) -> Spline<4> {
    let knots = random::random_bspline_knots(rng, p, n);
    let points = (0..n)
        .map(|_| {
            let x: Point3 = std::array::from_fn(|_| rng.range(-10.0, 10.0));
            eval::homogeneous(x, rng.range(0.2, 5.0))
        })
        .collect();
    Spline {
        degree: p,
        knots,
        points,
    }
}

fn max_abs<const D: usize>(points: &[[f64; D]]) -> f64 {
    points.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()))
}

fn distance<const D: usize>(a: [f64; D], b: [f64; D]) -> f64 {
    (0..D).fold(0.0f64, |m, k| m.max((a[k] - b[k]).abs()))
}

/// The non-empty spans of the domain: s in p..n with t_s < t_{s+1}.
fn domain_spans<const D: usize>(s: &Spline<D>) -> Vec<usize> {
    (s.degree..s.points.len())
        .filter(|&i| s.knots[i] < s.knots[i + 1])
        .collect()
}

#[test]
fn blossom_is_the_curve_on_its_diagonal_symmetric_and_multiaffine() {
    let mut rng = Rng::new(2024);
    let mut worst = [0.0f64; 3];
    for _ in 0..300 {
        let p = rng.int(0, 7);
        let n = p + 1 + rng.int(0, 6);
        let s = random_spline(&mut rng, p, n);
        let scale = max_abs(&s.points);
        for span in domain_spans(&s) {
            let (lo, hi) = (s.knots[span], s.knots[span + 1]);
            let t = rng.range(lo, hi);
            let diagonal = s.blossom(span, &vec![t; p]);
            let curve = bspline_derivatives(p, &s.knots, &s.points, t, 0)[0];
            worst[0] = worst[0].max(distance(diagonal, curve) / scale);
            // Symmetric: any order of the arguments (drawn from the knots that shape the span).
            let (first, last) = (s.knots[span + 1 - p.max(1)], s.knots[span + p.max(1)]);
            let args: Vec<f64> = (0..p).map(|_| rng.range(first, last)).collect();
            let f = s.blossom(span, &args);
            let mut shuffled = args.clone();
            for i in (1..shuffled.len()).rev() {
                shuffled.swap(i, rng.int(0, i));
            }
            worst[1] = worst[1].max(distance(f, s.blossom(span, &shuffled)) / scale);
            // Affine in each argument (here the first): f(αx + (1−α)y, …) = α f(x, …) + (1−α) f(y, …).
            if p > 0 {
                // Dyadic α, x, y: the mixed argument is exact, so only the blossom rounds.
                let alpha = *rng.pick(&[-0.5, 0.25, 0.75, 1.5]);
                let dyadic = |x: f64| (x * 1024.0).round() / 1024.0;
                let (x, y) = (dyadic(rng.range(lo, hi)), dyadic(rng.range(lo, hi)));
                let mut at = args.clone();
                at[0] = alpha * x + (1.0 - alpha) * y;
                let mixed = s.blossom(span, &at);
                at[0] = x;
                let fx = s.blossom(span, &at);
                at[0] = y;
                let fy = s.blossom(span, &at);
                let expected = eval::add(eval::scale(alpha, fx), eval::scale(1.0 - alpha, fy));
                worst[2] = worst[2].max(distance(mixed, expected) / scale.max(max_abs(&[fx, fy])));
            }
        }
    }
    println!("blossom diagonal/symmetry/affinity: worst {worst:?}");
    assert!(worst.iter().all(|&w| w < 1e-13), "{worst:?}");
}

#[test]
fn blossom_at_the_knots_gives_the_control_points() {
    // de Boor–Ramshaw: P_j = f_s(t_{j+1}, …, t_{j+p}) for every domain span s that P_j shapes.
    let mut rng = Rng::new(7);
    let mut checked = 0;
    for _ in 0..300 {
        let p = rng.int(0, 7);
        let n = p + 1 + rng.int(0, 6);
        let s = random_spline(&mut rng, p, n);
        let scale = max_abs(&s.points);
        for span in domain_spans(&s) {
            for j in span - p..=span {
                let f = s.blossom(span, &s.knots[j + 1..=j + p]);
                assert!(
                    distance(f, s.points[j]) <= 1e-13 * scale,
                    "P_{j} from span {span}: {f:?} vs {:?} (knots {:?})",
                    s.points[j],
                    s.knots
                );
                checked += 1;
            }
        }
    }
    assert!(checked > 1000);
}

#[test]
fn elevated_blossom_by_subsets_equals_one_at_a_time_elevation() {
    let mut rng = Rng::new(11);
    for _ in 0..100 {
        let p = rng.int(0, 5);
        let e = rng.int(0, 3);
        let n = p + 1 + rng.int(0, 4);
        let s = random_spline(&mut rng, p, n);
        let span = *rng.pick(&domain_spans(&s));
        let args: Vec<f64> = (0..p + e).map(|_| rng.range(-3.0, 3.0)).collect();
        let a = s.elevated_blossom(span, &args);
        let b = s.elevated_blossom_recursive(span, &args);
        let scale = max_abs(&[a]).max(max_abs(&s.points));
        assert!(
            distance(a, b) <= 1e-14 * scale,
            "p {p} e {e}: {a:?} vs {b:?}"
        );
        // On the diagonal, the elevated blossom is still the curve.
        let t = rng.range(s.knots[span], s.knots[span + 1]);
        let diagonal = s.elevated_blossom(span, &vec![t; p + e]);
        assert!(distance(diagonal, s.blossom(span, &vec![t; p])) <= 1e-13 * max_abs(&s.points));
    }
}

fn curve_points(object: &Object) -> (&Basis, &Vec<Point3>, &Option<Vec<f64>>) {
    match &object.shape {
        Shape::Curve {
            basis,
            points,
            weights,
        } => (basis, points, weights),
        _ => panic!("not a curve"),
    }
}

fn assert_points(actual: &[Point3], expected: &[[f64; 3]], tol: f64, what: &str) {
    assert_eq!(actual.len(), expected.len(), "{what}: point count");
    for (i, (a, e)) in actual.iter().zip(expected).enumerate() {
        assert_point(*a, *e, tol, &format!("{what}: point {i}"));
    }
}

#[test]
fn bezier_degree_elevation_by_hand() {
    // Q_i = i/(n+1) P_{i−1} + (1 − i/(n+1)) P_i for the lecture's cubic (n = 3):
    // Q_1 = P_0/4 + 3 P_1/4, Q_2 = (P_1 + P_2)/2, Q_3 = 3 P_2/4 + P_3/4.
    let mut scene = Scene {
        objects: vec![curve(&LECTURE_POINTS, None, Basis::Bezier)],
    };
    apply_edits(
        &mut scene,
        &[parse_edit(json!({"object": "c", "elevate_degree": 1}))],
    )
    .unwrap();
    let c = &scene.objects[0];
    assert_eq!(
        c.type_name(),
        "bezier_curve",
        "elevation keeps a Bézier curve Bézier"
    );
    let (basis, points, weights) = curve_points(c);
    assert_eq!(*basis, Basis::Bezier);
    assert!(weights.is_none());
    assert_points(
        points,
        &[
            [1.0, 1.0, 0.0],
            [1.0, 7.75, 0.0],
            [5.5, 10.0, 0.0],
            [10.0, 7.75, 0.0],
            [10.0, 1.0, 0.0],
        ],
        1e-14,
        "elevated lecture cubic",
    );
    // The formula on random Bézier curves of degree 0..=10, and e = 2 as two steps of 1.
    let mut rng = Rng::new(5);
    for _ in 0..100 {
        let n = rng.int(0, 10);
        let p: Vec<[f64; 3]> = (0..=n)
            .map(|_| std::array::from_fn(|_| rng.range(-10.0, 10.0)))
            .collect();
        let once = Spline::bezier(&p).elevate(1).unwrap();
        let expected: Vec<[f64; 3]> = (0..=n + 1)
            .map(|i| {
                let a = i as f64 / (n + 1) as f64;
                match i {
                    0 => p[0],
                    _ if i == n + 1 => p[n],
                    _ => eval::add(eval::scale(a, p[i - 1]), eval::scale(1.0 - a, p[i])),
                }
            })
            .collect();
        assert_points(&once.points, &expected, 1e-13, &format!("degree {n} + 1"));
        let twice = Spline::bezier(&p).elevate(2).unwrap();
        let stepwise = Spline::bezier(&once.points).elevate(1).unwrap();
        assert_points(&twice.points, &stepwise.points, 1e-13, "e = 2 = 1 + 1");
        assert_eq!(twice.knots, Spline::<3>::bezier(&twice.points).knots);
    }
}

#[test]
fn single_knot_insertion_into_uniform_cubic_by_hand() {
    // Knots 0..7, domain [3, 4]; t = 3.5 lies in span 3. Worked by hand:
    //   Q_0 = P_0, Q_1 = P_0/6 + 5 P_1/6, Q_2 = (P_1 + P_2)/2, Q_3 = 5 P_2/6 + P_3/6, Q_4 = P_3.
    let mut scene = Scene {
        objects: vec![curve(
            &LECTURE_POINTS,
            None,
            Basis::BSpline {
                degree: 3,
                knots: (0..8).map(f64::from).collect(),
            },
        )],
    };
    let before = scene.clone();
    apply_edits(
        &mut scene,
        &[parse_edit(json!({"object": "c", "insert_knot": 3.5}))],
    )
    .unwrap();
    let (basis, points, _) = curve_points(&scene.objects[0]);
    assert_eq!(
        *basis,
        Basis::BSpline {
            degree: 3,
            knots: vec![0.0, 1.0, 2.0, 3.0, 3.5, 4.0, 5.0, 6.0, 7.0]
        }
    );
    assert_points(
        points,
        &[
            [1.0, 1.0, 0.0],
            [1.0, 8.5, 0.0],
            [5.5, 10.0, 0.0],
            [10.0, 8.5, 0.0],
            [10.0, 1.0, 0.0],
        ],
        1e-14,
        "uniform cubic, t = 3.5",
    );
    assert!(compare_output(&before, 3, &scene.sample_json(3), 1e-14).ok());

    // The lecture's Bézier cubic, t = 1/2 three times: de Casteljau's subdivision
    // P_0, P_01, P_012, P_0123, P_123, P_23, P_3, and the object becomes a B-spline.
    let mut scene = Scene {
        objects: vec![curve(&LECTURE_POINTS, None, Basis::Bezier)],
    };
    apply_edits(
        &mut scene,
        &[parse_edit(
            json!({"object": "c", "insert_knot": 0.5, "times": 3}),
        )],
    )
    .unwrap();
    assert_eq!(scene.objects[0].type_name(), "bspline_curve");
    let (basis, points, _) = curve_points(&scene.objects[0]);
    assert_eq!(
        *basis,
        Basis::BSpline {
            degree: 3,
            knots: vec![0.0, 0.0, 0.0, 0.0, 0.5, 0.5, 0.5, 1.0, 1.0, 1.0, 1.0]
        }
    );
    assert_points(
        points,
        &[
            [1.0, 1.0, 0.0],
            [1.0, 5.5, 0.0],
            [3.25, 7.75, 0.0],
            [5.5, 7.75, 0.0],
            [7.75, 7.75, 0.0],
            [10.0, 5.5, 0.0],
            [10.0, 1.0, 0.0],
        ],
        1e-14,
        "Bézier subdivision at 1/2",
    );
}

#[test]
fn refined_quarter_circle_stays_on_the_circle() {
    // Homogeneous elevation of (1,0) (1,1) (0,1) with weights 1, 1/√2, 1:
    // H_1 = H_0/3 + 2 H_1/3, so w_1 = (1 + √2)/3 and Q_1 = (1/3 + √2/3, √2/3)/w_1.
    let r = std::f64::consts::FRAC_1_SQRT_2;
    let mut scene = Scene {
        objects: vec![curve(
            &[[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
            Some(vec![1.0, r, 1.0]),
            Basis::Bezier,
        )],
    };
    apply_edits(
        &mut scene,
        &[parse_edit(json!({"object": "c", "elevate_degree": 1}))],
    )
    .unwrap();
    let (_, points, weights) = curve_points(&scene.objects[0]);
    let w1 = (1.0 + 2.0 * r) / 3.0;
    let weights = weights.as_ref().unwrap();
    assert!(close(weights[1], w1, 1e-15) && close(weights[2], w1, 1e-15));
    assert!(close(weights[0], 1.0, 0.0) && close(weights[3], 1.0, 0.0));
    assert_point(points[1], [1.0, 2.0 * r / 3.0 / w1, 0.0], 1e-15, "Q_1");
    apply_edits(
        &mut scene,
        &[
            parse_edit(json!({"object": "c", "insert_knot": 0.3, "times": 2})),
            parse_edit(json!({"object": "c", "insert_knot": 0.8})),
        ],
    )
    .unwrap();
    for j in 0..=64 {
        let [x, y, _] = scene.objects[0].curve_derivatives(j as f64 / 64.0, 0)[0];
        let radius = (x * x + y * y).sqrt();
        assert!(close(radius, 1.0, 4e-16), "radius {radius} at {j}/64");
    }
}

/// Max over objects and derivative orders of |after − before| relative to the condition
/// scales of the two nets (`oracle::condition`), at the oracle's parameters (the domain does
/// not change).
fn shape_change(before: &Scene, after: &Scene, n: usize) -> f64 {
    let report = compare_refined_outputs(
        before,
        after,
        n,
        &before.sample_json(n),
        &after.sample_json(n),
        f64::INFINITY,
    );
    assert!(report.problems.is_empty(), "{}", report.describe());
    report.max_relative_error
}

/// Checks knots, degree and control counts of every direction after one structural edit.
fn check_structure(before: &Object, after: &Object, edit: &Edit) {
    let was = random::refinable_directions(before).unwrap();
    let now = random::refinable_directions(after).unwrap();
    let what = format!("{edit:?}");
    match edit {
        Edit::InsertKnot {
            direction,
            t,
            times,
            ..
        } => {
            let times = times.unwrap_or(1);
            let dir = direction.unwrap_or(0);
            for d in 0..was.len() {
                let ((p, k, n), (q, k2, n2)) = (&was[d], &now[d]);
                assert_eq!(p, q, "{what}: degree");
                if d != dir {
                    assert_eq!((k, n), (k2, n2), "{what}: other direction");
                    continue;
                }
                assert_eq!(*n2, n + times, "{what}: control count");
                let mult = |ks: &[f64]| ks.iter().filter(|&&x| x == *t).count();
                assert_eq!(mult(k2), mult(k) + times, "{what}: multiplicity");
                assert!(mult(k2) <= *q, "{what}: multiplicity above the degree");
                let mut expected = k.clone();
                expected.extend(std::iter::repeat_n(*t, times));
                expected.sort_by(f64::total_cmp);
                assert_eq!(*k2, expected, "{what}: refined knot vector");
            }
            if before.type_name().starts_with("bezier") {
                assert!(after.type_name().starts_with("bspline"), "{what}: type");
            }
        }
        Edit::ElevateDegree { by, .. } => {
            for (d, e) in by.amounts().into_iter().enumerate() {
                let ((p, k, n), (q, k2, n2)) = (&was[d], &now[d]);
                if e == 0 {
                    assert_eq!((p, n), (q, n2), "{what}: unelevated direction");
                    continue;
                }
                assert_eq!(*q, p + e, "{what}: degree");
                let (a, b) = (k[*p], k[*n]);
                assert!(k2[..=*q].iter().all(|&x| x == a), "{what}: clamped start");
                assert!(k2[*n2..].iter().all(|&x| x == b), "{what}: clamped end");
                assert_eq!(k2.len(), n2 + q + 1, "{what}: knot count");
                let interior = |ks: &[f64]| -> Vec<f64> {
                    let mut v: Vec<f64> = ks.iter().copied().filter(|&x| a < x && x < b).collect();
                    v.dedup();
                    v
                };
                assert_eq!(interior(k), interior(k2), "{what}: interior knot values");
                for x in interior(k) {
                    let mult = |ks: &[f64]| ks.iter().filter(|&&y| y == x).count();
                    assert_eq!(mult(k2), mult(k) + e, "{what}: multiplicity of {x}");
                }
            }
            assert_eq!(before.type_name(), after.type_name(), "{what}: type");
        }
        _ => unreachable!(),
    }
}

#[test]
fn structural_edits_keep_the_shape_and_refine_the_knots() {
    let kinds = [
        Kind::BezierCurve,
        Kind::BSplineCurve,
        Kind::BezierSurface,
        Kind::BSplineSurface,
    ];
    let opts = Options {
        max_samples: 7,
        high_degree_chance: 0.0,
        ..Options::default()
    };
    let mut worst = 0.0f64;
    let mut edits_checked = 0;
    for seed in 0..150 {
        // Derivatives up to 4, rational objects included, against the unrefined model.
        let n = (seed % 5) as usize;
        let mix = random::StructuralMix {
            max_points: 16,
            ..Default::default()
        };
        let original = random::random_scene(seed, &kinds, &opts);
        let mut rng = Rng::new(seed ^ 0x5EED);
        let mut scene = original.clone();
        for _ in 0..rng.int(1, 5) {
            let i = rng.int(0, scene.objects.len() - 1);
            let Some(edit) = random::random_structural_edit(&mut rng, &scene.objects[i], &mix)
            else {
                continue;
            };
            let before = scene.objects[i].clone();
            edit.apply(&mut scene).unwrap();
            check_structure(&before, &scene.objects[i], &edit);
            edits_checked += 1;
        }
        let change = shape_change(&original, &scene, n);
        assert!(
            change < 1e-14,
            "seed {seed}: shape changed by {change:e}\nbefore: {}\nafter: {}",
            original.to_json(),
            scene.to_json()
        );
        worst = worst.max(change);
    }
    println!("{edits_checked} structural edits; worst scaled shape change {worst:e}");
    assert!(edits_checked > 200);
}

#[test]
fn structural_edits_round_trip_and_bad_values_are_refused() {
    let scene = Scene::from_json(&json!({"objects": [
        {"name": "c", "type": "bspline_curve", "degree": 2, "knots": [0, 0, 0, 1, 1, 2, 2, 2],
         "points": [[0, 0, 0], [1, 1, 0], [2, 0, 0], [3, 1, 0], [4, 0, 0]], "samples": 5},
        {"name": "s", "type": "bezier_surface",
         "points": [[[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 1]]], "samples": [3, 3]},
        {"name": "e", "type": "erbs_curve", "knots": [0, 0, 1, 1],
         "local": [{"points": [[0, 0, 0]]}, {"points": [[1, 1, 1]]}], "samples": 3}
    ]}))
    .unwrap();
    let good = [
        json!({"object": "c", "insert_knot": 0.5}),
        json!({"object": "c", "insert_knot": 0.5, "times": 2}),
        json!({"object": "c", "insert_knot": 1.5, "times": 1}),
        json!({"object": "c", "elevate_degree": 3}),
        json!({"object": "s", "insert_knot": {"v": 0.25}}),
        json!({"object": "s", "elevate_degree": {"u": 1}}),
        json!({"object": "s", "elevate_degree": {"u": 0, "v": 2}}),
    ];
    for g in &good {
        let edit = parse_edit(g.clone());
        assert_eq!(edit.to_json(), *g, "round trip");
        let mut s = scene.clone();
        edit.apply(&mut s).unwrap_or_else(|e| panic!("{g}: {e}"));
        assert!(shape_change(&scene, &s, 2) < 1e-14, "{g}");
    }
    let bad = [
        json!({"object": "c", "insert_knot": 0}),
        json!({"object": "c", "insert_knot": 2}),
        json!({"object": "c", "insert_knot": -1}),
        json!({"object": "c", "insert_knot": 1}),
        json!({"object": "c", "insert_knot": 0.5, "times": 3}),
        json!({"object": "c", "insert_knot": 0.5, "times": 0}),
        json!({"object": "c", "elevate_degree": 0}),
        json!({"object": "c", "elevate_degree": 63}),
        json!({"object": "c", "insert_knot": {"u": 0.5}}),
        json!({"object": "s", "insert_knot": 0.5}),
        json!({"object": "s", "elevate_degree": {}}),
        json!({"object": "s", "elevate_degree": {"u": 0, "v": 0}}),
        json!({"object": "e", "insert_knot": 0.5}),
        json!({"object": "e", "elevate_degree": 1}),
    ];
    for b in &bad {
        let mut s = scene.clone();
        let result = Edit::from_json(b).and_then(|e| e.apply(&mut s));
        assert!(result.is_err(), "{b} accepted");
        assert_eq!(s, scene, "{b}: the model changed");
    }
    for b in [
        json!({"object": "c", "insert_knot": "0.5"}),
        json!({"object": "c", "insert_knot": 0.5, "times": -1}),
        json!({"object": "c", "elevate_degree": 1.5}),
        json!({"object": "s", "insert_knot": {"w": 0.5}}),
        json!({"object": "s", "insert_knot": {"u": 0.5, "v": 0.5}}),
    ] {
        assert!(Edit::from_json(&b).is_err(), "{b} parsed");
    }
}

#[test]
fn random_structural_edits_cover_the_contract() {
    use std::collections::BTreeMap;
    let mut seen: BTreeMap<&str, usize> = BTreeMap::new();
    let mut mark = |key: &'static str, yes: bool| {
        if yes {
            *seen.entry(key).or_default() += 1;
        }
    };
    let opts = Options {
        max_samples: 9,
        high_degree_chance: 0.0,
        ..Options::default()
    };
    let mix = random::StructuralMix::default();
    for seed in 0..150 {
        let scene = random::random_scene(seed, &Kind::ALL, &opts);
        let mut rng = Rng::new(seed);
        let edits = random::random_edits_with_structure(&mut rng, &scene, 25, &mix);
        let json_edits = Value::Array(edits.iter().map(Edit::to_json).collect());
        assert_eq!(oracle::scene::parse_edits(&json_edits).unwrap(), edits);
        let mut model = scene.clone();
        for (i, edit) in edits.iter().enumerate() {
            let object = model.object(edit.object()).unwrap().clone();
            let rational = matches!(
                &object.shape,
                Shape::Curve {
                    weights: Some(_),
                    ..
                } | Shape::Surface {
                    weights: Some(_),
                    ..
                }
            );
            let bezier = object.type_name().starts_with("bezier");
            let later_point_edit = edits[i + 1..]
                .iter()
                .any(|e| e.object() == edit.object() && matches!(e, Edit::PointDelta { .. }));
            match edit {
                Edit::InsertKnot {
                    direction,
                    t,
                    times,
                    ..
                } => {
                    let dirs = random::refinable_directions(&object).unwrap();
                    let (_, knots, _) = &dirs[direction.unwrap_or(0)];
                    mark("insert into a curve", direction.is_none());
                    mark("insert in u", *direction == Some(0));
                    mark("insert in v", *direction == Some(1));
                    mark("insert times > 1", times.unwrap_or(1) > 1);
                    mark("insert times written", times.is_some());
                    mark("insert at an existing knot", knots.contains(t));
                    mark(
                        "insert at a sample parameter",
                        object.params()[direction.unwrap_or(0)].contains(t),
                    );
                    mark("insert into a Bézier object", bezier);
                    mark("insert into a rational object", rational);
                    mark("point edit after an insertion", later_point_edit);
                }
                Edit::ElevateDegree { by, .. } => {
                    let dirs = random::refinable_directions(&object).unwrap();
                    let unclamped = dirs.iter().any(|(p, k, _)| k[0] != k[*p]);
                    mark("elevate a curve", matches!(by, Elevation::Curve(_)));
                    mark("elevate by 2", by.amounts().contains(&2));
                    mark(
                        "elevate a surface, one direction omitted",
                        matches!(
                            by,
                            Elevation::Surface { u: None, .. } | Elevation::Surface { v: None, .. }
                        ),
                    );
                    mark(
                        "elevate a surface, both directions",
                        by.amounts().iter().filter(|&&e| e > 0).count() == 2,
                    );
                    mark("elevate a Bézier object", bezier);
                    mark("elevate a rational object", rational);
                    mark("elevate an unclamped object", unclamped);
                    mark("point edit after an elevation", later_point_edit);
                }
                _ => {}
            }
            edit.apply(&mut model).unwrap();
        }
    }
    println!("{seen:#?}");
    for key in [
        "insert into a curve",
        "insert in u",
        "insert in v",
        "insert times > 1",
        "insert times written",
        "insert at an existing knot",
        "insert at a sample parameter",
        "insert into a Bézier object",
        "insert into a rational object",
        "point edit after an insertion",
        "elevate a curve",
        "elevate by 2",
        "elevate a surface, one direction omitted",
        "elevate a surface, both directions",
        "elevate a Bézier object",
        "elevate a rational object",
        "elevate an unclamped object",
        "point edit after an elevation",
    ] {
        assert!(
            seen.get(key).copied().unwrap_or(0) >= 3,
            "generator rarely produces {key:?}: {seen:?}"
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Condition scales (tests/oracle/condition.rs), the measure of the structural agreement tests
// ---------------------------------------------------------------------------------------------

#[test]
fn condition_scales_by_hand() {
    // C(t) = (1−t) P0 + t P1 with P0 = (1,0,0), P1 = (3,0,0), at t = 0 and 1:
    //   order 0: Σ|N_i||P_i| = (1−t)·1 + t·3, largest 3;  order 1: |−1|·1 + |1|·3 = 4.
    let line = |weights: Option<Vec<f64>>| {
        curve(&[[1.0, 0.0, 0.0], [3.0, 0.0, 0.0]], weights, Basis::Bezier)
    };
    let params = vec![vec![0.0, 1.0]];
    assert_eq!(
        condition_scales(&line(None), &params, 1).unwrap(),
        vec![3.0, 4.0]
    );
    // With unit weights the quotient rule adds the weights' bounds (w = 1, w' = 0, C = 1 + 2t,
    // C' = 2): order 0: (1+2t) + 1·|C| = 2 + 4t → 6; order 1: 4 + 1·|C'| + (|−1|+|1|)·|C| + 0
    // = 8 + 4t → 12.
    assert_eq!(
        condition_scales(&line(Some(vec![1.0, 1.0])), &params, 1).unwrap(),
        vec![6.0, 12.0]
    );
    // ERBS objects have none.
    let scene = random::random_scene(1, &[Kind::ErbsCurve], &Options::default());
    let erbs = &scene.objects[0];
    assert!(condition_scales(erbs, &erbs.params(), 1).is_none());
}

#[test]
fn condition_scales_bound_values_and_rounding_of_the_net() {
    let kinds = [
        Kind::BezierCurve,
        Kind::BSplineCurve,
        Kind::BezierSurface,
        Kind::BSplineSurface,
    ];
    let opts = Options {
        max_samples: 9,
        ..Options::default()
    };
    let mut worst = 0.0f64;
    for seed in 0..60 {
        let scene = random::random_scene(seed, &kinds, &opts);
        let n = (seed % 4) as usize + 1;
        // A polynomial order's condition scale is at least its largest value.
        for object in &scene.objects {
            if matches!(
                object.shape,
                Shape::Curve { weights: None, .. } | Shape::Surface { weights: None, .. }
            ) {
                let scales = condition_scales(object, &object.params(), n).unwrap();
                let values = object.sample_json(n)["samples"].clone();
                let largest = flatten_numbers(&values)
                    .into_iter()
                    .fold(0.0f64, |m, x| m.max(x.abs()));
                let top = scales.iter().fold(0.0f64, |m, &x| m.max(x));
                assert!(
                    top >= largest * (1.0 - 1e-15),
                    "seed {seed}: {top} < {largest}"
                );
            }
        }
        // Rounding every control coordinate and weight by a relative δ moves each sample by
        // at most δ times the condition scale (first order).
        let delta = 1e-11;
        let mut rng = Rng::new(seed);
        let mut nudge = |x: &mut f64| *x *= 1.0 + delta * rng.range(-1.0, 1.0);
        let mut perturbed = scene.clone();
        for object in &mut perturbed.objects {
            match &mut object.shape {
                Shape::Curve {
                    points, weights, ..
                } => {
                    points.iter_mut().flatten().for_each(&mut nudge);
                    weights.iter_mut().flatten().for_each(&mut nudge);
                }
                Shape::Surface {
                    points, weights, ..
                } => {
                    points.iter_mut().flatten().flatten().for_each(&mut nudge);
                    weights.iter_mut().flatten().flatten().for_each(&mut nudge);
                }
                _ => unreachable!(),
            }
        }
        let report = compare_conditioned(&scene, n, &perturbed.sample_json(n), f64::INFINITY);
        assert!(report.problems.is_empty(), "{}", report.describe());
        worst = worst.max(report.max_relative_error / delta);
    }
    println!("rounding by δ moved samples by at most {worst:.3} δ·(condition scale)");
    assert!(worst <= 1.0 + 1e-3, "{worst}");
    assert!(worst > 0.05, "the perturbation did not register: {worst}");
}

#[test]
fn conditioned_comparisons_detect_mismatches() {
    let kinds = [
        Kind::BezierCurve,
        Kind::BSplineSurface,
        Kind::ErbsCurve,
        Kind::BSplineCurve,
    ];
    let opts = Options {
        max_samples: 5,
        rational_chance: 0.5,
        ..Options::default()
    };
    // A seed whose B-spline surface has room for a knot in u.
    let scene = (0..)
        .map(|seed| random::random_scene(seed, &kinds, &opts))
        .find(|s| {
            matches!(&s.objects[1].shape,
                Shape::Surface { basis: [Basis::BSpline { degree, .. }, _], points, .. }
                    if *degree >= 1 && points.len() > *degree)
        })
        .unwrap();
    let n = 2;
    let out = scene.sample_json(n);
    let report = compare_conditioned(&scene, n, &out, 1e-13);
    assert!(report.ok(), "{}", report.describe());
    assert!(report.compared > 0);

    // One number of the surface and of a curve off by 1e-11 of its condition scale: one
    // mismatch each, located.
    for (object, path, slot) in [
        (1usize, vec![1usize, 0, 1, 0, 2], n + 1),
        (3, vec![2, 1, 0], 1),
    ] {
        let o = &scene.objects[object];
        let scale = condition_scales(o, &o.params(), n).unwrap()[slot];
        let mut bad = out.clone();
        let mut cell = &mut bad["objects"][object]["samples"];
        for &i in &path {
            cell = &mut cell[i];
        }
        let x = cell.as_f64().unwrap();
        *cell = json!(x + 1e-11 * scale);
        let report = compare_conditioned(&scene, n, &bad, 1e-13);
        assert_eq!(report.mismatch_count, 1, "{}", report.describe());
        assert_eq!(report.mismatches[0].object, format!("o{object}"));
    }
    // The ERBS curve is held to its values by compare_output.
    let mut bad = out.clone();
    let x = bad["objects"][2]["samples"][1][0][0].as_f64().unwrap();
    bad["objects"][2]["samples"][1][0][0] = json!(x + 1e-9 * x.abs().max(1.0));
    assert_eq!(
        compare_conditioned(&scene, n, &bad, 1e-13).mismatch_count,
        1
    );
    // A last-bit change passes.
    let mut fine = out.clone();
    let x = fine["objects"][0]["samples"][1][1][0].as_f64().unwrap();
    fine["objects"][0]["samples"][1][1][0] = json!(x * (1.0 + f64::EPSILON));
    assert!(compare_conditioned(&scene, n, &fine, 1e-13).ok());
    // Structure: a missing object, a wrong type, a non-number.
    let mut missing = out.clone();
    missing["objects"].as_array_mut().unwrap().remove(0);
    assert!(!compare_conditioned(&scene, n, &missing, 1e-13).ok());
    let mut typed = out.clone();
    typed["objects"][0]["type"] = json!("bspline_curve");
    assert!(!compare_conditioned(&scene, n, &typed, 1e-13).ok());
    let mut nan = out.clone();
    nan["objects"][3]["samples"][0][0][1] = json!(null);
    assert!(!compare_conditioned(&scene, n, &nan, 1e-13).ok());

    // compare_refined_outputs: a correct refinement passes, a refined net off by 1e-10 does not.
    let mut refined = scene.clone();
    apply_edits(
        &mut refined,
        &[
            parse_edit(json!({"object": "o0", "elevate_degree": 1})),
            parse_edit(
                json!({"object": "o1", "insert_knot": {"u": refined_middle(&scene.objects[1])}}),
            ),
        ],
    )
    .unwrap();
    let after = refined.sample_json(n);
    let report = compare_refined_outputs(&scene, &refined, n, &out, &after, 1e-13);
    assert!(report.ok(), "{}", report.describe());
    let mut wrong = refined.clone();
    if let Shape::Surface { points, .. } = &mut wrong.objects[1].shape {
        let p = &mut points[1][0];
        p[0] += 1e-10 * p[0].abs().max(1.0);
    }
    let report = compare_refined_outputs(&scene, &refined, n, &out, &wrong.sample_json(n), 1e-13);
    assert!(!report.ok() && report.mismatch_count > 0);
    // Changed parameters are a problem, not a pass.
    let mut moved = after.clone();
    let t = moved["objects"][0]["params"][1].as_f64().unwrap();
    moved["objects"][0]["params"][1] = json!(t + 1e-12);
    assert!(!compare_refined_outputs(&scene, &refined, n, &out, &moved, 1e-13).ok());
}

/// A parameter inside the u domain of a B-spline surface that is not a knot there.
fn refined_middle(object: &Object) -> f64 {
    let (a, b) = object.domains()[0];
    let Shape::Surface {
        basis: [Basis::BSpline { knots, .. }, _],
        ..
    } = &object.shape
    else {
        unreachable!()
    };
    (1..)
        .map(|k| a + (b - a) * (0.5 + 0.1 / f64::from(k)))
        .find(|t| !knots.contains(t))
        .unwrap()
}
