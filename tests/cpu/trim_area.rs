//! The area `prespline info` reports for a trimmed surface (`SceneObject::measure`: Legendre
//! fits on grid cells, the trim flattened to 1e-7 of the domain) against the independent
//! oracle (`tests/oracle/trim_area.rs`: Green's theorem on the exact loop curves with adaptive
//! Gauss–Kronrod), on polygons, circles, B-spline loops and holes, over planar, cylindrical
//! (rational) and freeform surfaces. The claim (docs/info.md) is 1e-6 relative; the comparison
//! has a negative control.

use crate::oracle::eval::Basis;
use crate::oracle::trim_area::{Loop, Nurbs2, Role, Segment, TensorSurface, trimmed_area};
use glam::{DVec2, DVec3};
use prespline::formats::parse_scene;
use std::f64::consts::{FRAC_1_SQRT_2, PI};

/// The relative accuracy docs/info.md claims for areas.
const CLAIM: f64 = 1e-6;

/// Whether `got` is within `rel` of `want` (NaN never is).
fn close(got: f64, want: f64, rel: f64) -> bool {
    (got - want).abs() <= rel * want.abs()
}

/// The product's area of the one object of `scene`.
fn product_area(scene: &str) -> f64 {
    let s = parse_scene(scene).unwrap_or_else(|e| panic!("{e}\n{scene}"));
    s.objects[0].measure().unwrap().area
}

/// A circle of radius r about c as the usual nine-point rational quadratic B-spline, JSON.
fn circle_json(c: DVec2, r: f64) -> String {
    let (pts, w, knots) = circle_data(c, r);
    let pts: Vec<String> = pts
        .iter()
        .map(|p| format!("[{:?}, {:?}]", p.x, p.y))
        .collect();
    format!(
        "{{\"bspline\": [{}], \"degree\": 2, \"knots\": {knots:?}, \"weights\": {w:?}}}",
        pts.join(", ")
    )
}

fn circle_data(c: DVec2, r: f64) -> (Vec<DVec2>, Vec<f64>, Vec<f64>) {
    let mut pts = Vec::new();
    let mut w = Vec::new();
    for k in 0..9 {
        let a = k as f64 * PI / 4.0;
        let rr = if k % 2 == 0 { r } else { r * 2f64.sqrt() };
        pts.push(c + rr * DVec2::new(a.cos(), a.sin()));
        w.push(if k % 2 == 0 { 1.0 } else { FRAC_1_SQRT_2 });
    }
    let knots = vec![0., 0., 0., 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1., 1., 1.];
    (pts, w, knots)
}

fn oracle_circle(c: DVec2, r: f64) -> Loop {
    let (pts, w, knots) = circle_data(c, r);
    Loop::new(vec![Segment::Nurbs(
        Nurbs2::new(2, knots, pts, Some(w)).unwrap(),
    )])
    .unwrap()
}

fn square_json(lo: DVec2, hi: DVec2) -> String {
    format!(
        "{{\"polyline\": [[{0:?}, {1:?}], [{2:?}, {1:?}], [{2:?}, {3:?}], [{0:?}, {3:?}], [{0:?}, {1:?}]]}}",
        lo.x, lo.y, hi.x, hi.y
    )
}

fn oracle_square(lo: DVec2, hi: DVec2) -> Loop {
    Loop::new(vec![Segment::Polyline(vec![
        lo,
        DVec2::new(hi.x, lo.y),
        hi,
        DVec2::new(lo.x, hi.y),
        lo,
    ])])
    .unwrap()
}

/// A bumpy bicubic B-spline over [0, 2] × [0, 1] (non-uniform knots), as JSON and for the
/// oracle.
fn freeform() -> (String, TensorSurface) {
    let ku = vec![0., 0., 0., 0., 0.3, 1.1, 2., 2., 2., 2.];
    let kv = vec![0., 0., 0., 0., 0.5, 1., 1., 1., 1.];
    let (nu, nv) = (6, 5);
    let mut pts = vec![vec![[0.0; 3]; nv]; nu];
    for (i, row) in pts.iter_mut().enumerate() {
        for (j, p) in row.iter_mut().enumerate() {
            let z = 0.3 * ((i * 7 + j * 3) % 5) as f64 - 0.5;
            *p = [i as f64 * 0.7, j as f64 * 0.5 + 0.1 * i as f64, z];
        }
    }
    let rows: Vec<String> = pts
        .iter()
        .map(|r| {
            let r: Vec<String> = r.iter().map(|p| format!("{p:?}")).collect();
            format!("[{}]", r.join(", "))
        })
        .collect();
    let json = format!(
        "\"type\": \"bspline_surface\", \"degree\": [3, 3], \"knots\": [{ku:?}, {kv:?}], \"points\": [{}], \"samples\": [33, 33]",
        rows.join(", ")
    );
    let surface = TensorSurface::new(
        [
            Basis::BSpline {
                degree: 3,
                knots: ku,
            },
            Basis::BSpline {
                degree: 3,
                knots: kv,
            },
        ],
        &pts,
        None,
    );
    (json, surface)
}

/// A quarter cylinder of radius 2 and height 3 as a rational quadratic × linear NURBS over
/// [0, 1]², JSON and for the oracle.
fn cylinder() -> (String, TensorSurface) {
    let r = 2.0;
    let ring = [[r, 0.0], [r, r], [0.0, r]];
    let pts: Vec<Vec<[f64; 3]>> = ring
        .iter()
        .map(|p| vec![[p[0], p[1], 0.0], [p[0], p[1], 3.0]])
        .collect();
    let w = vec![vec![1.0, 1.0], vec![FRAC_1_SQRT_2; 2], vec![1.0, 1.0]];
    let json = format!(
        "\"type\": \"bspline_surface\", \"degree\": [2, 1], \"knots\": [[0, 0, 0, 1, 1, 1], [0, 0, 1, 1]], \"points\": {pts:?}, \"weights\": {w:?}, \"samples\": [17, 9]"
    );
    let surface = TensorSurface::new(
        [
            Basis::BSpline {
                degree: 2,
                knots: vec![0., 0., 0., 1., 1., 1.],
            },
            Basis::BSpline {
                degree: 1,
                knots: vec![0., 0., 1., 1.],
            },
        ],
        &pts,
        Some(&w),
    );
    (json, surface)
}

fn scene(body: &str, trim: &str) -> String {
    format!("{{\"objects\": [{{\"name\": \"s\", {body}, \"trim\": [{trim}]}}]}}")
}

fn check(case: &str, product: f64, oracle: f64) {
    let rel = (product - oracle).abs() / oracle.abs();
    println!("{case}: product {product:.15} oracle {oracle:.15} rel {rel:.2e}");
    assert!(
        close(product, oracle, CLAIM),
        "{case}: {product} vs {oracle} ({rel:e})"
    );
}

#[test]
fn trimmed_areas_agree_with_the_green_theorem_oracle() {
    // A plane: the bilinear patch over [0, 4] × [0, 2] with corners of a skewed parallelogram.
    let plane = "\"type\": \"bspline_surface\", \"degree\": [1, 1], \"knots\": [[0, 0, 4, 4], [0, 0, 2, 2]], \"points\": [[[0, 0, 0], [1, 2, 0]], [[4, 0.5, 0], [5, 2.5, 0]]], \"samples\": [9, 9]";
    let plane_partials = |_: f64, _: f64| (DVec3::new(1.0, 0.125, 0.0), DVec3::new(0.5, 1.0, 0.0));
    let c = DVec2::new(2.0, 1.0);
    let disc = scene(plane, &format!("{{\"outer\": [{}]}}", circle_json(c, 0.8)));
    let oracle = trimmed_area(
        &plane_partials,
        &[(oracle_circle(c, 0.8), Role::Outer)],
        1e-13,
    );
    check("disc on a plane", product_area(&disc), oracle);

    // A square with a circular hole, on the plane.
    let (lo, hi) = (DVec2::new(0.5, 0.2), DVec2::new(3.5, 1.8));
    let holed = scene(
        plane,
        &format!(
            "{{\"loop\": [{}]}}, {{\"hole\": [{}]}}",
            square_json(lo, hi),
            circle_json(c, 0.6)
        ),
    );
    let oracle = trimmed_area(
        &plane_partials,
        &[
            (oracle_square(lo, hi), Role::Outer),
            (oracle_circle(c, 0.6), Role::Hole),
        ],
        1e-13,
    );
    check(
        "square with a hole on a plane",
        product_area(&holed),
        oracle,
    );

    // A rational quarter cylinder trimmed by a polygon and by a disc.
    let (body, cyl) = cylinder();
    let partials = |u: f64, v: f64| cyl.partials(u, v);
    let poly = "{\"polyline\": [[0.1, 0.1], [0.9, 0.2], [0.7, 0.9], [0.2, 0.7], [0.1, 0.1]]}";
    let oracle = trimmed_area(
        &partials,
        &[(
            Loop::new(vec![Segment::Polyline(vec![
                DVec2::new(0.1, 0.1),
                DVec2::new(0.9, 0.2),
                DVec2::new(0.7, 0.9),
                DVec2::new(0.2, 0.7),
                DVec2::new(0.1, 0.1),
            ])])
            .unwrap(),
            Role::Outer,
        )],
        1e-12,
    );
    check(
        "polygon on a rational cylinder",
        product_area(&scene(&body, &format!("{{\"outer\": [{poly}]}}"))),
        oracle,
    );
    let c2 = DVec2::new(0.5, 0.5);
    let oracle = trimmed_area(&partials, &[(oracle_circle(c2, 0.35), Role::Outer)], 1e-12);
    check(
        "disc on a rational cylinder",
        product_area(&scene(
            &body,
            &format!("{{\"loop\": [{}]}}", circle_json(c2, 0.35)),
        )),
        oracle,
    );

    // A freeform bicubic with a B-spline loop (a closed cubic through the domain) and a hole.
    let (body, free) = freeform();
    let partials = |u: f64, v: f64| free.partials(u, v);
    let loop_pts = [
        [0.2, 0.2],
        [1.0, 0.1],
        [1.8, 0.2],
        [1.9, 0.5],
        [1.8, 0.9],
        [1.0, 0.8],
        [0.2, 0.9],
        [0.1, 0.5],
        [0.2, 0.2],
    ];
    let knots = vec![0., 0., 0., 0., 0.2, 0.35, 0.5, 0.65, 0.8, 1., 1., 1., 1.];
    let pts_json: Vec<String> = loop_pts.iter().map(|p| format!("{p:?}")).collect();
    let hole_c = DVec2::new(1.0, 0.5);
    let trim = format!(
        "{{\"outer\": [{{\"bspline\": [{}], \"degree\": 3, \"knots\": {knots:?}}}]}}, {{\"hole\": [{}]}}",
        pts_json.join(", "),
        circle_json(hole_c, 0.2)
    );
    let spline_loop = Loop::new(vec![Segment::Nurbs(
        Nurbs2::new(
            3,
            knots,
            loop_pts.iter().map(|p| DVec2::new(p[0], p[1])).collect(),
            None,
        )
        .unwrap(),
    )])
    .unwrap();
    let oracle = trimmed_area(
        &partials,
        &[
            (spline_loop, Role::Outer),
            (oracle_circle(hole_c, 0.2), Role::Hole),
        ],
        1e-11,
    );
    check(
        "B-spline loop with a hole on a freeform surface",
        product_area(&scene(&body, &trim)),
        oracle,
    );
}

/// Negative control: a loop grown by 1e-5 of its size changes the area past the claim, so the
/// comparison above would see a wrong loop.
#[test]
fn a_slightly_larger_loop_fails_the_area_comparison() {
    let plane = "\"type\": \"bspline_surface\", \"degree\": [1, 1], \"knots\": [[0, 0, 1, 1], [0, 0, 1, 1]], \"points\": [[[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 0]]], \"samples\": [9, 9]";
    let c = DVec2::new(0.5, 0.5);
    let product = product_area(&scene(
        plane,
        &format!("{{\"outer\": [{}]}}", circle_json(c, 0.3 * (1.0 + 1e-5))),
    ));
    let partials = |_: f64, _: f64| (DVec3::X, DVec3::Y);
    let oracle = trimmed_area(&partials, &[(oracle_circle(c, 0.3), Role::Outer)], 1e-13);
    assert!(!close(product, oracle, CLAIM), "{product} vs {oracle}");
    assert!(
        !close(f64::NAN, oracle, CLAIM),
        "NaN must never compare close"
    );
}
