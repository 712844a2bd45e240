//! Self-checks of the trimmed-area oracle (`tests/oracle/trim_area.rs`): its quadrature rule
//! and 2D NURBS evaluator, exact areas (discs, holes, polygons on planes; rectangles and discs
//! on a cylinder, analytic and rational; the sphere), Fubini cross-checks where no closed form
//! exists (freeform bicubic B-spline and NURBS surfaces, a hyperbolic paraboloid) and negative
//! controls showing that a perturbed loop, surface or role moves the result past the tolerance.
//!
//! The Fubini references integrate ∫ dv ∫ du directly over the region (chords of a disc in
//! closed form, v = c_v + r sin φ against the square-root endpoints), with no loops and no
//! Green's theorem; they share only the 1D adaptive rule, which is checked here on its own.
//! Every check prints its measured error (`cargo test oracle_trim_area -- --nocapture`).

use std::f64::consts::{FRAC_1_SQRT_2, FRAC_PI_2, PI};

use glam::{DVec2, DVec3};

use crate::oracle;

use oracle::eval::{Basis, Point3, bspline_derivatives, project_curve_derivatives};
use oracle::trim_area::{
    AreaEstimate, Loop, MAX_INNER_INTERVALS, Nurbs2, Role, Segment, TensorSurface,
    bilinear_partials, cylinder_partials, estimate_trimmed_area, integrate_adaptive,
    integrate_pieces, kronrod15, plane_partials, sphere_partials, trimmed_area,
};

/// The accuracy the task asks of the oracle on exact cases.
const ACCURACY: f64 = 1e-10;
/// The tolerance the oracle is run at (relative to the expected area), well inside `ACCURACY`.
const TOL: f64 = 1e-12;

type Partials<'a> = &'a dyn Fn(f64, f64) -> (DVec3, DVec3);

/// Relative error, printed so the measured numbers are on record.
fn relative_error(what: &str, got: f64, expected: f64) -> f64 {
    let e = ((got - expected) / expected).abs();
    eprintln!("trim_area {what}: got {got:.16e}, expected {expected:.16e}, relative error {e:.2e}");
    e
}

/// The oracle at TOL relative to `scale`, checked for being certified.
fn area(
    surface: Partials,
    breaks: [&[f64]; 2],
    loops: &[(Loop, Role)],
    scale: f64,
) -> AreaEstimate {
    let tol = TOL * scale;
    let e = estimate_trimmed_area(surface, breaks, loops, tol);
    assert!(e.certified(tol), "not certified at {tol:e}: {e:?}");
    e
}

fn metric(surface: Partials<'_>) -> impl Fn(f64, f64) -> f64 + '_ {
    move |u, v| {
        let (su, sv) = surface(u, v);
        su.cross(sv).length()
    }
}

/// No knot lines (analytic surfaces).
const NONE: [&[f64]; 2] = [&[], &[]];

/// Tolerance of the Fubini references, relative to the region's area times g at its centre.
const FUBINI_TOL: f64 = 1e-13;

/// ∫_lo^hi g(u, v) du split at the u-knots (each piece analytic), for the Fubini references.
fn chord(g: &dyn Fn(f64, f64) -> f64, v: f64, lo: f64, hi: f64, u_breaks: &[f64], tol: f64) -> f64 {
    let mut cuts = vec![lo];
    cuts.extend(u_breaks.iter().copied().filter(|&x| x > lo && x < hi));
    cuts.push(hi);
    let pieces: Vec<(f64, f64)> = cuts.windows(2).map(|w| (w[0], w[1])).collect();
    let q = integrate_pieces(
        &mut |_, u| (g(u, v), 0.0),
        &pieces,
        tol,
        MAX_INNER_INTERVALS,
    );
    assert_eq!(q.capped, 0, "Fubini inner integral capped");
    q.value
}

/// Adaptive quadrature of f over [a, b] split at `cuts`, for the Fubini references.
fn split_integral(f: &mut dyn FnMut(f64) -> f64, mut cuts: Vec<f64>, tol: f64) -> f64 {
    cuts.sort_by(f64::total_cmp);
    let pieces: Vec<(f64, f64)> = cuts.windows(2).map(|w| (w[0], w[1])).collect();
    let q = integrate_pieces(&mut |_, x| (f(x), 0.0), &pieces, tol, MAX_INNER_INTERVALS);
    assert_eq!(q.capped, 0, "Fubini outer integral capped");
    q.value
}

/// ∫∫ g over the disc |(u, v) − c| ≤ r by Fubini: ∫_{−π/2}^{π/2} r cos φ ∫_{c_u−s}^{c_u+s} g du dφ
/// with v = c_v + r sin φ and s = r cos φ (the substitution removes the √ at the poles). Split
/// at the knot lines [u, v] like the oracle (φ = asin((v_k − c_v)/r) for the v-knots): without
/// the splits the 7/15 estimate missed the kinks of g there and the value was off by 60× it.
fn disc_fubini(g: &dyn Fn(f64, f64) -> f64, c: DVec2, r: f64, breaks: [&[f64]; 2]) -> f64 {
    let tol = FUBINI_TOL * PI * r * r * g(c.x, c.y);
    let mut cuts = vec![-FRAC_PI_2, FRAC_PI_2];
    cuts.extend(
        breaks[1]
            .iter()
            .filter(|&&k| (k - c.y).abs() < r)
            .map(|&k| ((k - c.y) / r).asin()),
    );
    let mut outer = |phi: f64| {
        let (v, s) = (c.y + r * phi.sin(), r * phi.cos());
        chord(g, v, c.x - s, c.x + s, breaks[0], tol / (32.0 * r)) * s
    };
    split_integral(&mut outer, cuts, 0.5 * tol)
}

/// ∫∫ g over the rectangle [min, max] by Fubini, split at the knot lines.
fn rectangle_fubini(
    g: &dyn Fn(f64, f64) -> f64,
    min: DVec2,
    max: DVec2,
    breaks: [&[f64]; 2],
) -> f64 {
    let centre = 0.5 * (min + max);
    let tol = FUBINI_TOL * (max - min).x * (max - min).y * g(centre.x, centre.y);
    let mut cuts = vec![min.y, max.y];
    cuts.extend(breaks[1].iter().filter(|&&k| k > min.y && k < max.y));
    let height = max.y - min.y;
    let mut outer = |v: f64| chord(g, v, min.x, max.x, breaks[0], tol / (8.0 * height));
    split_integral(&mut outer, cuts, 0.5 * tol)
}

fn v2(x: f64, y: f64) -> DVec2 {
    DVec2::new(x, y)
}

/// A plane with skew, unequal axes, so |X × Y| is not a round number.
const PLANE_X: DVec3 = DVec3::new(2.0, 0.5, 1.0);
const PLANE_Y: DVec3 = DVec3::new(-0.3, 1.5, 0.7);

// ---------------------------------------------------------------------------------------------
// The building blocks
// ---------------------------------------------------------------------------------------------

#[test]
fn kronrod_rule_is_exact_to_degree_23_and_gauss_to_13() {
    let (a, b) = (-1.0f64, 2.0f64);
    for k in 0..=24i32 {
        let exact = (b.powi(k + 1) - a.powi(k + 1)) / f64::from(k + 1);
        let rule = kronrod15(&mut |x| (x.powi(k), 0.0), a, b);
        let kronrod_error = ((rule.value - exact) / exact).abs();
        let gauss_error = rule.error / exact.abs();
        if k <= 23 {
            assert!(kronrod_error < 1e-14, "K15 on x^{k}: {kronrod_error:e}");
        } else {
            // Negative control: beyond degree 3·7 + 2 the Kronrod rule is no longer exact.
            assert!(kronrod_error > 1e-14, "K15 exact on x^{k}?");
        }
        if k <= 13 {
            assert!(gauss_error < 1e-14, "G7 on x^{k}: {gauss_error:e}");
        } else {
            // The error estimate |K − G| sees the Gauss rule's first inexact degree.
            assert!(gauss_error > 1e-10, "G7 exact on x^{k}? {gauss_error:e}");
        }
    }
}

#[test]
fn adaptive_rule_on_known_integrals() {
    /// (what, f, a, b, ∫_a^b f)
    type Case = (&'static str, fn(f64) -> f64, f64, f64, f64);
    let cases: [Case; 3] = [
        ("sin on [0, π]", f64::sin, 0.0, PI, 2.0),
        ("√x on [0, 1]", f64::sqrt, 0.0, 1.0, 2.0 / 3.0),
        (
            "|x − 0.7|³ on [0, 2]",
            |x: f64| (x - 0.7).abs().powi(3),
            0.0,
            2.0,
            (0.7f64.powi(4) + 1.3f64.powi(4)) / 4.0,
        ),
    ];
    for (what, f, a, b, exact) in cases {
        let q = integrate_adaptive(&mut |x| f(x), a, b, 1e-13);
        assert_eq!(q.capped, 0, "{what}");
        assert!(q.error <= 1e-13, "{what}: estimate {:e}", q.error);
        assert!(relative_error(what, q.value, exact) < 1e-12, "{what}");
    }
    // Negative control: a tolerance rounding cannot reach is reported as capped, in bounded work.
    let q = integrate_adaptive(&mut f64::sqrt, 0.0, 1.0, 1e-300);
    assert!(q.capped > 0 && q.intervals <= 2 * oracle::trim_area::MAX_INNER_INTERVALS + 1);
}

/// A degree-3 NURBS with a double interior knot and uneven weights.
fn sample_nurbs() -> Nurbs2 {
    let points = [
        (0.0, 0.0),
        (1.0, 2.0),
        (3.0, 2.5),
        (4.0, 0.5),
        (5.5, 1.0),
        (6.0, 3.0),
        (4.0, 4.0),
    ]
    .map(|(x, y)| v2(x, y))
    .to_vec();
    let knots = vec![0.0, 0.0, 0.0, 0.0, 0.3, 0.55, 0.55, 1.2, 1.2, 1.2, 1.2];
    let weights = vec![1.0, 0.6, 2.0, 1.3, 0.8, 1.7, 1.0];
    Nurbs2::new(3, knots, points, Some(weights)).unwrap()
}

#[test]
fn nurbs_curve_evaluator_agrees_with_eval_rs() {
    // The Cox–de Boor basis path of trim_area.rs against the de Boor triangle on derivative
    // control points of eval.rs, two different algorithms.
    let c = sample_nurbs();
    let w = c.weights.clone().unwrap();
    let h: Vec<[f64; 4]> = c
        .points
        .iter()
        .zip(&w)
        .map(|(p, &w)| [w * p.x, w * p.y, 0.0, w])
        .collect();
    let mut worst: f64 = 0.0;
    for k in 0..=240 {
        let t = 1.2 * f64::from(k) / 240.0;
        let (p, d) = c.eval(t);
        let reference = project_curve_derivatives(&bspline_derivatives(3, &c.knots, &h, t, 1));
        worst = worst
            .max((p - v2(reference[0][0], reference[0][1])).length() / 6.0)
            .max((d - v2(reference[1][0], reference[1][1])).length() / 60.0);
    }
    eprintln!("trim_area NURBS evaluator vs eval.rs: max scaled difference {worst:.2e}");
    assert!(worst < 1e-13, "{worst:e}");

    // The reversed curve is the same point set backwards, with the derivative negated.
    let r = c.reversed();
    for t in [0.0, 0.2, 0.55, 0.9, 1.2] {
        let ((p, d), (q, e)) = (c.eval(t), r.eval(1.2 - t));
        assert!(
            (p - q).length() < 1e-13 && (d + e).length() < 1e-11,
            "t = {t}"
        );
    }

    // The rational circle lies on the circle, its derivative tangent to it.
    let circle = Nurbs2::circle(v2(1.0, -2.0), 0.75);
    for k in 0..=400 {
        let (p, d) = circle.eval(4.0 * f64::from(k) / 400.0);
        let radial = p - v2(1.0, -2.0);
        assert!((radial.length() - 0.75).abs() < 1e-15, "off the circle");
        assert!(radial.dot(d).abs() < 1e-14 * d.length(), "not tangent");
        assert!(radial.perp_dot(d) > 0.0, "not counter-clockwise");
    }
}

#[test]
fn malformed_loops_are_refused() {
    let open = Loop::new(vec![Segment::Polyline(vec![
        v2(0.0, 0.0),
        v2(1.0, 0.0),
        v2(1.0, 1.0),
    ])]);
    assert!(open.unwrap_err().contains("gap"));
    let flat = Loop::polygon(&[v2(0.0, 0.0), v2(1.0, 1.0), v2(2.0, 2.0)]);
    assert!(flat.unwrap_err().contains("no area"));
    assert!(Loop::polygon(&[v2(0.0, 0.0), v2(1.0, 1.0)]).is_err());
    let arc = Loop::circle(v2(0.0, 0.0), -1.0);
    assert!(arc.unwrap_err().contains("radius"));
    let knots = Nurbs2::new(
        2,
        vec![0.0, 0.0, 1.0, 0.5, 1.0, 1.0],
        vec![DVec2::ZERO; 3],
        None,
    );
    assert!(knots.unwrap_err().contains("non-decreasing"));
    // A half circle closed by its diameter is fine, a half circle alone is not.
    let half = |end| Segment::Arc {
        center: DVec2::ZERO,
        radius: 1.0,
        start: 0.0,
        end,
    };
    assert!(Loop::new(vec![half(PI)]).is_err());
    let closed = Loop::new(vec![
        half(PI),
        Segment::Line {
            from: v2(-1.0, 0.0),
            to: v2(1.0, 0.0),
        },
    ])
    .unwrap();
    assert!((closed.signed_area() - FRAC_PI_2).abs() < 1e-14);
}

// ---------------------------------------------------------------------------------------------
// Exact areas
// ---------------------------------------------------------------------------------------------

#[test]
fn disc_on_plane_with_every_circle_kind() {
    let plane = plane_partials(PLANE_X, PLANE_Y);
    let g = PLANE_X.cross(PLANE_Y).length();
    let (c, r) = (v2(0.4, -1.3), 0.7);
    let exact = PI * r * r * g;
    let semicircle = |start: f64| Segment::Arc {
        center: c,
        radius: r,
        start,
        end: start + PI,
    };
    let loops = [
        ("arc circle", Loop::circle(c, r).unwrap()),
        (
            "NURBS circle",
            Loop::new(vec![Segment::Nurbs(Nurbs2::circle(c, r))]).unwrap(),
        ),
        (
            "two semicircles",
            Loop::new(vec![semicircle(0.3), semicircle(0.3 + PI)]).unwrap(),
        ),
    ];
    for (what, l) in loops {
        for (orientation, l) in [("ccw", l.clone()), ("cw", l.reversed())] {
            let e = area(&plane, NONE, &[(l, Role::Outer)], exact);
            let what = format!("disc on plane, {what} {orientation}");
            assert!(relative_error(&what, e.area, exact) < ACCURACY, "{what}");
        }
    }
}

#[test]
fn square_with_circular_hole_on_plane() {
    let plane = plane_partials(PLANE_X, PLANE_Y);
    let g = PLANE_X.cross(PLANE_Y).length();
    let (c, r) = (v2(1.5, 2.2), 0.9);
    let exact = (16.0 - PI * r * r) * g;
    let square = Loop::rectangle(v2(0.0, 0.0), v2(4.0, 4.0)).unwrap();
    let holes = [
        Loop::circle(c, r).unwrap(),
        Loop::new(vec![Segment::Nurbs(Nurbs2::circle(c, r))]).unwrap(),
    ];
    for hole in holes {
        // Either orientation of either loop: the roles decide.
        for (outer, hole) in [
            (square.clone(), hole.clone()),
            (square.reversed(), hole.reversed()),
        ] {
            let loops = [(outer, Role::Outer), (hole, Role::Hole)];
            let e = area(&plane, NONE, &loops, exact);
            assert!(relative_error("square with hole", e.area, exact) < ACCURACY);
        }
    }
}

#[test]
fn polygon_and_bspline_loops_on_plane() {
    let plane = plane_partials(PLANE_X, PLANE_Y);
    let g = PLANE_X.cross(PLANE_Y).length();
    // A non-convex star: the shoelace formula is exact.
    let star: Vec<DVec2> = (0..10)
        .map(|k| {
            let radius = if k % 2 == 0 { 2.0 } else { 0.8 };
            v2(3.0, 1.0) + radius * DVec2::from_angle(0.2 + PI * f64::from(k) / 5.0)
        })
        .collect();
    let shoelace: f64 = (0..10)
        .map(|k| star[k].perp_dot(star[(k + 1) % 10]))
        .sum::<f64>()
        / 2.0;
    let exact = shoelace * g;
    let e = area(
        &plane,
        NONE,
        &[(Loop::polygon(&star).unwrap(), Role::Outer)],
        exact,
    );
    assert!(relative_error("star polygon on plane", e.area, exact) < ACCURACY);

    // A closed clamped cubic B-spline: u·v' is a quintic on each span, so 3-point Gauss–Legendre
    // per span (with eval.rs's evaluator) gives ∮ u dv exactly.
    let points: Vec<Point3> = [
        (0.0, 0.0),
        (2.0, -0.5),
        (3.5, 0.8),
        (2.5, 2.0),
        (3.0, 3.5),
        (0.5, 3.0),
        (-1.0, 1.5),
        (0.0, 0.0),
    ]
    .iter()
    .map(|&(x, y)| [x, y, 0.0])
    .collect();
    let knots = vec![0.0, 0.0, 0.0, 0.0, 0.1, 0.35, 0.5, 0.7, 1.0, 1.0, 1.0, 1.0];
    let gauss = [
        (-(0.6f64.sqrt()), 5.0 / 9.0),
        (0.0, 8.0 / 9.0),
        (0.6f64.sqrt(), 5.0 / 9.0),
    ];
    let mut enclosed = 0.0;
    for i in 3..8 {
        let (a, b) = (knots[i], knots[i + 1]);
        for (x, w) in gauss {
            let t = 0.5 * (a + b) + 0.5 * (b - a) * x;
            let d = bspline_derivatives(3, &knots, &points, t, 1);
            enclosed += 0.5 * (b - a) * w * d[0][0] * d[1][1];
        }
    }
    let curve = Nurbs2::new(
        3,
        knots,
        points.iter().map(|p| v2(p[0], p[1])).collect(),
        None,
    )
    .unwrap();
    let exact = enclosed.abs() * g;
    let e = area(
        &plane,
        NONE,
        &[(Loop::new(vec![Segment::Nurbs(curve)]).unwrap(), Role::Outer)],
        exact,
    );
    assert!(relative_error("cubic B-spline loop on plane", e.area, exact) < ACCURACY);
}

#[test]
fn analytic_cylinder_rectangle_and_disc() {
    let radius = 3.0;
    let cylinder = cylinder_partials(radius);
    let exact = radius * 1.7 * 3.5;
    let rectangle = Loop::rectangle(v2(0.3, -1.0), v2(2.0, 2.5)).unwrap();
    let e = area(&cylinder, NONE, &[(rectangle, Role::Outer)], exact);
    assert!(relative_error("cylinder, rectangle", e.area, exact) < ACCURACY);

    let r = 0.8;
    let exact = radius * PI * r * r;
    let disc = Loop::circle(v2(1.2, 0.4), r).unwrap();
    let e = area(&cylinder, NONE, &[(disc, Role::Outer)], exact);
    assert!(relative_error("cylinder, disc", e.area, exact) < ACCURACY);
}

/// The quarter cylinder of radius R and height H as a rational patch written out by hand:
/// u quadratic (the 90° arc (R,0) → (R,R) → (0,R), middle weight 1/√2), v linear (z = 0 → H).
fn quarter_cylinder(radius: f64, height: f64) -> TensorSurface {
    let arc = [(radius, 0.0), (radius, radius), (0.0, radius)];
    let points: Vec<Vec<Point3>> = arc
        .iter()
        .map(|&(x, y)| vec![[x, y, 0.0], [x, y, height]])
        .collect();
    let weights = vec![vec![1.0, 1.0], vec![FRAC_1_SQRT_2; 2], vec![1.0, 1.0]];
    TensorSurface::new([Basis::Bezier, Basis::Bezier], &points, Some(&weights))
}

#[test]
fn rational_quarter_cylinder() {
    let (radius, height) = (2.0, 5.0);
    let s = quarter_cylinder(radius, height);
    let partials = |u, v| s.partials(u, v);
    // The angle of the rational parametrisation, from points only (no derivatives).
    let theta = |u: f64| {
        let p = s.point(u, 0.0);
        p.y.atan2(p.x)
    };
    let full = Loop::rectangle(v2(0.0, 0.0), v2(1.0, 1.0)).unwrap();
    let exact = radius * FRAC_PI_2 * height;
    let e = area(&partials, NONE, &[(full, Role::Outer)], exact);
    assert!(relative_error("quarter cylinder, full", e.area, exact) < ACCURACY);

    let part = Loop::rectangle(v2(0.2, 0.1), v2(0.7, 0.9)).unwrap();
    let exact = radius * (theta(0.7) - theta(0.2)) * height * 0.8;
    let e = area(&partials, NONE, &[(part, Role::Outer)], exact);
    assert!(relative_error("quarter cylinder, rectangle", e.area, exact) < ACCURACY);

    // A disc: ∫ dv of R·H·(θ(u_hi) − θ(u_lo)) over the chords, again from points only.
    let (c, r) = (v2(0.5, 0.45), 0.3);
    let q = integrate_adaptive(
        &mut |phi: f64| {
            let s = r * phi.cos();
            radius * height * (theta(c.x + s) - theta(c.x - s)) * s
        },
        -FRAC_PI_2,
        FRAC_PI_2,
        1e-13 * radius * height,
    );
    assert_eq!(q.capped, 0);
    let exact = q.value;
    let e = area(
        &partials,
        NONE,
        &[(Loop::circle(c, r).unwrap(), Role::Outer)],
        exact,
    );
    assert!(relative_error("quarter cylinder, disc", e.area, exact) < ACCURACY);
}

#[test]
fn sphere_full_domain_cap_and_disc() {
    let radius = 1.5;
    let sphere = sphere_partials(radius);
    let full = Loop::rectangle(v2(0.0, -FRAC_PI_2), v2(2.0 * PI, FRAC_PI_2)).unwrap();
    let exact = 4.0 * PI * radius * radius;
    let e = area(&sphere, NONE, &[(full, Role::Outer)], exact);
    assert!(relative_error("sphere, full domain", e.area, exact) < ACCURACY);

    let cap = Loop::rectangle(v2(0.0, 0.4), v2(2.0 * PI, FRAC_PI_2)).unwrap();
    let exact = 2.0 * PI * radius * radius * (1.0 - 0.4f64.sin());
    let e = area(&sphere, NONE, &[(cap, Role::Outer)], exact);
    assert!(relative_error("sphere, cap", e.area, exact) < ACCURACY);

    // Disc in (u, v): R² ∫ 2s cos v dv over the chords, v = c_v + r sin φ.
    let (c, r) = (v2(2.0, 0.3), 0.9);
    let q = integrate_adaptive(
        &mut |phi: f64| {
            let s = r * phi.cos();
            radius * radius * 2.0 * s * (c.y + r * phi.sin()).cos() * s
        },
        -FRAC_PI_2,
        FRAC_PI_2,
        1e-13 * radius * radius,
    );
    assert_eq!(q.capped, 0);
    let exact = q.value;
    let e = area(
        &sphere,
        NONE,
        &[(Loop::circle(c, r).unwrap(), Role::Outer)],
        exact,
    );
    assert!(relative_error("sphere, disc", e.area, exact) < ACCURACY);
}

// ---------------------------------------------------------------------------------------------
// Freeform surfaces
// ---------------------------------------------------------------------------------------------

const KNOTS_U: [f64; 11] = [0.0, 0.0, 0.0, 0.0, 0.15, 0.5, 0.6, 1.0, 1.0, 1.0, 1.0];
const KNOTS_V: [f64; 10] = [0.0, 0.0, 0.0, 0.0, 0.3, 0.45, 1.0, 1.0, 1.0, 1.0];

/// Greville abscissae (t_{i+1} + t_{i+2} + t_{i+3}) / 3 of a cubic: the control points there
/// reproduce a linear function exactly (linear precision).
fn greville(knots: &[f64]) -> Vec<f64> {
    (0..knots.len() - 4)
        .map(|i| (knots[i + 1] + knots[i + 2] + knots[i + 3]) / 3.0)
        .collect()
}

fn bicubic(points: &[Vec<Point3>], weights: Option<&[Vec<f64>]>) -> TensorSurface {
    let basis = |k: &[f64]| Basis::BSpline {
        degree: 3,
        knots: k.to_vec(),
    };
    TensorSurface::new([basis(&KNOTS_U), basis(&KNOTS_V)], points, weights)
}

/// A bumpy bicubic over [0, 1]², 7 × 6 points, non-uniform knots in both directions.
fn bumpy_points() -> Vec<Vec<Point3>> {
    let (gu, gv) = (greville(&KNOTS_U), greville(&KNOTS_V));
    (0..7)
        .map(|i| {
            (0..6)
                .map(|j| {
                    let (fi, fj) = (i as f64, j as f64);
                    [
                        4.0 * gu[i] + 0.3 * fj.sin(),
                        3.0 * gv[j] + 0.2 * fi.cos(),
                        0.8 * (1.3 * fi).sin() * (0.7 * fj).cos(),
                    ]
                })
                .collect()
        })
        .collect()
}

fn bumpy_weights() -> Vec<Vec<f64>> {
    (0..7)
        .map(|i| {
            (0..6)
                .map(|j| 1.0 + 0.8 * (f64::from(i) + 2.0 * f64::from(j)).sin().powi(2))
                .collect()
        })
        .collect()
}

#[test]
fn bicubic_plane_in_disguise_is_exact() {
    // Control points at the Greville abscissae of an affine map: S(u, v) = O + uX + vY exactly,
    // so g = |X × Y| although it comes through the B-spline (and, with equal weights, the
    // rational) evaluator with all its knots.
    let (gu, gv) = (greville(&KNOTS_U), greville(&KNOTS_V));
    let origin = DVec3::new(1.0, -2.0, 0.5);
    let points: Vec<Vec<Point3>> = gu
        .iter()
        .map(|&u| {
            gv.iter()
                .map(|&v| (origin + u * PLANE_X + v * PLANE_Y).to_array())
                .collect()
        })
        .collect();
    let weights = vec![vec![2.5; 6]; 7];
    let g = PLANE_X.cross(PLANE_Y).length();
    let (c, r) = (v2(0.45, 0.5), 0.35);
    let exact = PI * r * r * g;
    for (what, s) in [
        ("B-spline", bicubic(&points, None)),
        ("NURBS", bicubic(&points, Some(&weights))),
    ] {
        let partials = |u, v| s.partials(u, v);
        let disc = [(Loop::circle(c, r).unwrap(), Role::Outer)];
        let e = area(&partials, [&s.breaks(0), &s.breaks(1)], &disc, exact);
        assert!(relative_error(&format!("{what} plane, disc"), e.area, exact) < ACCURACY);
    }
}

/// Green (with and without the knot lines) against Fubini, for a disc and a rectangle.
fn check_against_fubini(what: &str, s: &TensorSurface) {
    let partials = |u, v| s.partials(u, v);
    let g = metric(&partials);
    let (u_breaks, v_breaks) = (s.breaks(0), s.breaks(1));
    let knots: [&[f64]; 2] = [&u_breaks, &v_breaks];
    let (c, r) = (v2(0.45, 0.5), 0.35);
    let (min, max) = (v2(0.1, 0.2), v2(0.9, 0.7));
    let cases = [
        (
            "disc",
            Loop::circle(c, r).unwrap(),
            disc_fubini(&g, c, r, knots),
        ),
        (
            "rectangle",
            Loop::rectangle(min, max).unwrap(),
            rectangle_fubini(&g, min, max, knots),
        ),
    ];
    for (shape, l, reference) in cases {
        for (with, breaks) in [("knot lines", knots), ("no knot lines", NONE)] {
            let e = area(&partials, breaks, &[(l.clone(), Role::Outer)], reference);
            let label = format!(
                "{what}, {shape} vs Fubini ({with}, {} evaluations)",
                e.evaluations
            );
            assert!(
                relative_error(&label, e.area, reference) < ACCURACY,
                "{label}"
            );
        }
    }
}

#[test]
fn bicubic_bspline_against_fubini() {
    check_against_fubini("bicubic B-spline", &bicubic(&bumpy_points(), None));
}

#[test]
fn bicubic_nurbs_against_fubini() {
    check_against_fubini(
        "bicubic NURBS",
        &bicubic(&bumpy_points(), Some(&bumpy_weights())),
    );
}

#[test]
fn hyperbolic_paraboloid_against_fubini() {
    let hypar = bilinear_partials(
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(2.0, 0.0, 1.0),
        DVec3::new(0.0, 1.5, -0.5),
        DVec3::new(2.5, 2.0, 2.0),
    );
    let (c, r) = (v2(0.5, 0.5), 0.45);
    let reference = disc_fubini(&metric(&hypar), c, r, NONE);
    let e = area(
        &hypar,
        NONE,
        &[(Loop::circle(c, r).unwrap(), Role::Outer)],
        reference,
    );
    assert!(relative_error("hyperbolic paraboloid, disc vs Fubini", e.area, reference) < ACCURACY);
}

// ---------------------------------------------------------------------------------------------
// Tolerances and negative controls
// ---------------------------------------------------------------------------------------------

#[test]
fn error_estimate_bounds_the_actual_error() {
    let s = bicubic(&bumpy_points(), Some(&bumpy_weights()));
    let partials = |u, v| s.partials(u, v);
    let (u_breaks, v_breaks) = (s.breaks(0), s.breaks(1));
    let knots: [&[f64]; 2] = [&u_breaks, &v_breaks];
    let disc = [(Loop::circle(v2(0.45, 0.5), 0.35).unwrap(), Role::Outer)];
    let reference = area(&partials, knots, &disc, 5.0).area;
    for (with, breaks) in [("knot lines", knots), ("no knot lines", NONE)] {
        for tol in [1e-3, 1e-6, 1e-9] {
            let e = estimate_trimmed_area(&partials, breaks, &disc, tol);
            let actual = (e.area - reference).abs();
            eprintln!(
                "trim_area tol {tol:e} ({with}): actual error {actual:.2e}, estimate {:.2e}, {} evaluations",
                e.error_estimate, e.evaluations
            );
            assert!(e.certified(tol) && actual <= e.error_estimate && actual <= tol);
        }
    }
}

#[test]
#[should_panic(expected = "did not reach")]
fn unreachable_tolerance_is_refused() {
    let plane = plane_partials(PLANE_X, PLANE_Y);
    trimmed_area(
        &plane,
        &[(Loop::circle(v2(0.0, 0.0), 1.0).unwrap(), Role::Outer)],
        1e-300,
    );
}

#[test]
fn negative_controls_move_the_result_past_the_tolerance() {
    // Perturbations of 1e-7 relative: 1000 × the oracle's own tolerance, yet small.
    let detect = |what: &str, perturbed: f64, exact: f64| {
        let e = relative_error(&format!("negative control: {what}"), perturbed, exact);
        assert!(e > 100.0 * ACCURACY, "{what}: not detected ({e:e})");
    };
    let plane = plane_partials(PLANE_X, PLANE_Y);
    let g = PLANE_X.cross(PLANE_Y).length();
    let (c, r) = (v2(0.4, -1.3), 0.7);
    let exact = PI * r * r * g;
    let disc = |r| [(Loop::circle(c, r).unwrap(), Role::Outer)];
    assert!(
        relative_error(
            "negative control: baseline",
            trimmed_area(&plane, &disc(r), TOL * exact),
            exact
        ) < ACCURACY
    );
    detect(
        "disc radius × (1 + 1e-7)",
        trimmed_area(&plane, &disc(r * (1.0 + 1e-7)), TOL * exact),
        exact,
    );
    // (Stretched, not tilted out of the plane: a normal tilt changes |X × Y| only at 2nd order.)
    let stretched = plane_partials(PLANE_X, PLANE_Y * (1.0 + 1e-7));
    detect(
        "plane axis stretched by 1e-7",
        trimmed_area(&stretched, &disc(r), TOL * exact),
        exact,
    );

    // One polygon vertex moved by 1e-7.
    let star = [
        v2(0.0, 0.0),
        v2(2.0, 0.3),
        v2(1.2, 1.0),
        v2(1.5, 2.0),
        v2(-0.4, 1.1),
    ];
    let mut moved = star;
    moved[2] += v2(1e-7, -1e-7);
    let polygon = |p: &[DVec2]| [(Loop::polygon(p).unwrap(), Role::Outer)];
    let exact = trimmed_area(&plane, &polygon(&star), 1e-12);
    detect(
        "polygon vertex moved by 1e-7",
        trimmed_area(&plane, &polygon(&moved), 1e-12),
        exact,
    );

    // A hole declared as an outer loop adds its area instead of removing it.
    let square = Loop::rectangle(v2(0.0, 0.0), v2(4.0, 4.0)).unwrap();
    let hole = Loop::circle(v2(1.5, 2.2), 0.9).unwrap();
    let exact = (16.0 - PI * 0.81) * g;
    detect(
        "hole declared outer",
        trimmed_area(
            &plane,
            &[(square.clone(), Role::Outer), (hole, Role::Outer)],
            TOL * exact,
        ),
        exact,
    );

    // One control point of the freeform surface moved by 1e-6 of its size; and the Fubini
    // reference of the perturbed surface must disagree with Green on the unperturbed one.
    let points = bumpy_points();
    let s = bicubic(&points, Some(&bumpy_weights()));
    let mut bent_points = points.clone();
    bent_points[3][2][2] += 4e-6;
    let bent = bicubic(&bent_points, Some(&bumpy_weights()));
    let (c, r) = (v2(0.45, 0.5), 0.35);
    let disc = [(Loop::circle(c, r).unwrap(), Role::Outer)];
    let (u_breaks, v_breaks) = (s.breaks(0), s.breaks(1));
    let knots: [&[f64]; 2] = [&u_breaks, &v_breaks];
    let exact = area(&|u, v| s.partials(u, v), knots, &disc, 5.0).area;
    let bent_partials = |u, v| bent.partials(u, v);
    detect(
        "freeform control point moved by 4e-6",
        area(&bent_partials, knots, &disc, 5.0).area,
        exact,
    );
    detect(
        "Fubini of the moved surface",
        disc_fubini(&metric(&bent_partials), c, r, knots),
        exact,
    );
}
