//! The mapping's own geometry helpers, against exact values, with negative controls.

use crate::geom::analytic::{NurbsCurve, NurbsSurface};
use glam::{DVec2, DVec3};

use crate::formats::step::map::curves::wrap_after;
use crate::formats::step::map::nurbs::{FastCurve, FastSurface, reseat};
use crate::formats::step::map::surface::{Pre, twice};

const TAU: f64 = std::f64::consts::TAU;

#[test]
fn wrap_after_runs_the_given_way_round() {
    assert!((wrap_after(0.0, 1.0, TAU, true) - 1.0).abs() < 1e-15);
    assert!((wrap_after(0.0, 1.0, TAU, false) - (1.0 - TAU)).abs() < 1e-15);
    assert!(
        (wrap_after(1.0, 1.0, TAU, true) - (1.0 + TAU)).abs() < 1e-15,
        "equal ends: all round"
    );
    assert!((wrap_after(1.0, 1.0, TAU, false) - (1.0 - TAU)).abs() < 1e-15);
    assert!((wrap_after(6.0, 0.5, TAU, true) - (0.5 + TAU)).abs() < 1e-15);
}

/// The periodic continuation of a conic's arc map is continuous and increasing across 2π
/// (a swept circle's PCURVE may run past it), unlike the plain map, which clamps.
#[test]
fn arc_premap_is_continuous_across_the_period() {
    let map = crate::formats::step::map::curves::full_arc().expect("arc");
    let pre = Pre::Arc(1.0, map.clone());
    let mut last = pre.apply(-1.0);
    for k in 1..=400 {
        let x = -1.0 + 9.0 * f64::from(k) / 400.0;
        let y = pre.apply(x);
        assert!(y > last && y - last < 0.05, "{x}: {last} → {y}");
        last = y;
    }
    assert!((pre.apply(TAU + 0.3) - (TAU + map.angle_to_param(0.3))).abs() < 1e-12);
    // Control: the plain map stops at the end of its range.
    assert!((map.angle_to_param(TAU + 0.3) - TAU).abs() < 1e-12);
}

/// A unit circle as a closed rational quadratic, stored twice: the same points one period on.
#[test]
fn a_closed_curve_twice_over_is_the_same_curve() {
    let (c, _) = crate::formats::step::map::curves::Curve::Conic {
        frame: crate::geom::analytic::Frame::default(),
        a: 1.0,
        b: 1.0,
    }
    .to_nurbs(0.0, TAU)
    .expect("arc");
    let d = twice(&c).expect("twice");
    let (fc, fd) = (FastCurve::new(&c), FastCurve::new(&d));
    for k in 0..50 {
        let t = TAU * f64::from(k) / 50.0;
        let (a, b, e) = (
            fc.point(t).expect("a"),
            fd.point(t).expect("b"),
            fd.point(t + TAU).expect("c"),
        );
        assert!((a - b).length() < 1e-14 && (a - e).length() < 1e-14, "{t}");
    }
}

/// A full cylinder as a rational B-spline closed in u, re-seated to start at u = 1.3: the same
/// surface at the same parameters modulo the period.
#[test]
fn reseated_surface_keeps_points_and_parameters() {
    let arc = crate::formats::step::map::curves::Curve::Conic {
        frame: crate::geom::analytic::Frame::default(),
        a: 1.0,
        b: 1.0,
    };
    let (c, _) = arc.to_nurbs(0.0, TAU).expect("arc");
    let n = c.points.len();
    let mut points = Vec::new();
    let mut weights = Vec::new();
    for (p, w) in c.points.iter().zip(&c.weights) {
        for z in [0.0, 2.0] {
            points.push(*p + DVec3::new(0.0, 0.0, z));
            weights.push(*w);
        }
    }
    let s = NurbsSurface {
        degree: [2, 1],
        knots: [c.knots.clone(), vec![0.0, 0.0, 2.0, 2.0]],
        points,
        weights,
    };
    assert_eq!(s.points.len(), n * 2);
    let moved = reseat(&s, 0, 1.3, TAU).expect("reseat");
    let (fa, fb) = (FastSurface::new(&s), FastSurface::new(&moved));
    assert!(
        (fb.domain()[0][0] - 1.3).abs() < 1e-12 && (fb.domain()[0][1] - (1.3 + TAU)).abs() < 1e-12
    );
    for k in 0..40 {
        let u = 1.3 + TAU * f64::from(k) / 40.0;
        let a = fa.d1(u.rem_euclid(TAU), 0.7).expect("a").p;
        let b = fb.d1(u, 0.7).expect("b").p;
        assert!((a - b).length() < 1e-12, "{u}: {a} vs {b}");
    }
    // Control: without the re-seat the parameter past 2π clamps to the end.
    let end = fa.d1(TAU + 0.5, 0.7).expect("end").p;
    assert!((end - fa.d1(0.5, 0.7).expect("p").p).length() > 0.1);
}

/// The fast evaluator against the analytic crate's (value and first partials), on a rational
/// surface of mixed degree.
#[test]
fn fast_surface_matches_the_reference_evaluator() {
    let nu = 4;
    let nv = 5;
    let points: Vec<DVec3> = (0..nu * nv)
        .map(|i| DVec3::new((i / nv) as f64, (i % nv) as f64, ((i * 7) % 5) as f64 * 0.3))
        .collect();
    let weights: Vec<f64> = (0..nu * nv)
        .map(|i| 1.0 + ((i * 3) % 4) as f64 * 0.25)
        .collect();
    let s = NurbsSurface {
        degree: [2, 3],
        knots: [
            vec![0.0, 0.0, 0.0, 0.4, 1.0, 1.0, 1.0],
            vec![0.0, 0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0, 1.0],
        ],
        points,
        weights,
    };
    let fast = FastSurface::new(&s);
    for (u, v) in [(0.0, 0.0), (0.2, 0.9), (0.4, 0.5), (0.77, 0.31), (1.0, 1.0)] {
        let a = s.derivs(u, v).expect("reference");
        let b = fast.d1(u, v).expect("fast");
        assert!((a.p - b.p).length() < 1e-13, "{u} {v}");
        // The point-only path is the same arithmetic: the same bits.
        let q = fast.point(u, v).expect("point");
        assert_eq!(
            q.to_array().map(f64::to_bits),
            b.p.to_array().map(f64::to_bits)
        );
        assert!(
            (a.su - b.su).length() < 1e-11 && (a.sv - b.sv).length() < 1e-11,
            "{u} {v}"
        );
    }
    assert!(
        fast.d1(f64::NAN, 0.5).is_none(),
        "a NaN parameter is refused, not clamped"
    );
    assert!(fast.point(0.5, f64::NAN).is_none());
    // Negative control for the bit comparison: a nearby parameter gives other bits.
    let (p, q) = (fast.point(0.3, 0.6), fast.point(0.3 + 1e-9, 0.6));
    assert_ne!(p.map(|p| p.x.to_bits()), q.map(|q| q.x.to_bits()));
    let curve = NurbsCurve {
        degree: 2,
        knots: vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        points: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
        weights: vec![1.0, 0.5, 1.0],
    };
    let fc = FastCurve::new(&curve);
    for t in [0.0, 0.3, 1.0] {
        assert!((fc.point(t).expect("fast") - curve.point(t).expect("ref")).length() < 1e-14);
    }
}

/// Spreading an end offset along a polyline moves the ends exactly and the middle partly.
#[test]
fn blend_spreads_end_offsets() {
    let mut pts = vec![DVec2::ZERO, DVec2::new(1.0, 0.0), DVec2::new(2.0, 0.0)];
    crate::formats::step::map::trims::blend_for_tests(&mut pts, Some(DVec2::new(0.0, 1.0)), None);
    assert_eq!(pts[0], DVec2::new(0.0, 1.0));
    assert!((pts[1] - DVec2::new(1.0, 0.5)).length() < 1e-15);
    assert_eq!(pts[2], DVec2::new(2.0, 0.0));
}
