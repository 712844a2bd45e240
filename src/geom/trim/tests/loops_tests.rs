//! Loop assembly, validation and classification.

use std::f64::consts::TAU;

use glam::DVec2;

use super::super::{Curve2, LoopInput, Role, Tolerances, TrimError, TrimRegions};
use super::{Rng, brute_inside, build, close, curve_loop, err, ok, one_piece, rect, reversed};

fn p(x: f64, y: f64) -> DVec2 {
    DVec2::new(x, y)
}

/// The unit-ish square as 4 line pieces, the joint between pieces 1 and 2 off by `gap`.
fn square_pieces(gap: f64) -> LoopInput {
    let pieces = vec![
        vec![p(0.2, 0.2), p(0.8, 0.2)],
        vec![p(0.8, 0.2), p(0.8, 0.8)],
        vec![p(0.8 + gap, 0.8), p(0.2, 0.8)],
        vec![p(0.2, 0.8), p(0.2, 0.2)],
    ];
    LoopInput { pieces, role: None }
}

#[test]
fn small_gaps_are_closed_and_large_ones_refused() {
    let t = ok(build(&[square_pieces(1e-8)]));
    assert!(close(t.area(), 0.36, 1e-7));
    let e = err(build(&[square_pieces(1e-3)]));
    assert!(matches!(
        e,
        TrimError::Gap {
            loop_index: 0,
            prev: 1,
            next: 2,
            ..
        }
    ));
    assert_eq!(
        e.to_string(),
        "trim loop 0: curve 1 ends at (0.8, 0.8) and curve 2 starts at (0.801, 0.8): \
         a gap of 0.001 (more than 1.414e-6)"
    );
    // A loop that does not return to its start.
    let mut open = square_pieces(0.0);
    open.pieces[3] = vec![p(0.2, 0.8), p(0.2, 0.3)];
    let e = err(build(&[open]));
    assert!(matches!(
        e,
        TrimError::Gap {
            prev: 3,
            next: 0,
            ..
        }
    ));
}

#[test]
fn the_message_names_loop_curves_gap_and_tolerance() {
    // Diagonal 1, so the gap tolerance is 1e-6 exactly.
    let domain = [(0.0, 0.6), (0.0, 0.8)];
    let good = one_piece(rect(0.05, 0.05, 0.1, 0.1), None);
    let pieces = vec![
        vec![p(0.3, 0.2), p(0.4, 0.2)],
        vec![p(0.4, 0.2), p(0.45, 0.2)],
        vec![p(0.45, 0.2), p(0.5, 0.2)],
        vec![p(0.5, 0.2), p(0.5, 0.25)],
        vec![p(0.5, 0.31), p(0.3, 0.31)],
    ];
    let bad = LoopInput { pieces, role: None };
    let loops = [good.clone(), good, bad];
    let e = TrimRegions::new(&loops, domain, &Tolerances::default());
    let msg = e.map(|_| String::new()).unwrap_or_else(|e| e.to_string());
    assert_eq!(
        msg,
        "trim loop 2: curve 3 ends at (0.5, 0.25) and curve 4 starts at (0.5, 0.31): \
         a gap of 0.06 (more than 1e-6)"
    );
}

#[test]
fn reversed_pieces_are_accepted() {
    let straight = ok(build(&[square_pieces(0.0)]));
    for k in 0..4 {
        let mut l = square_pieces(0.0);
        l.pieces[k].reverse();
        let t = ok(build(&[l]));
        assert_eq!(t.area(), straight.area());
        assert!(close(t.area(), 0.36, 1e-15));
    }
    // Negative control: a piece displaced is a gap, reversed or not.
    let mut l = square_pieces(0.0);
    l.pieces[2] = vec![p(0.2, 0.7), p(0.8, 0.7)];
    assert!(matches!(err(build(&[l])), TrimError::Gap { .. }));
}

#[test]
fn figure_eight_is_refused() {
    // A proper crossing between segments.
    let bow = vec![p(0.2, 0.2), p(0.8, 0.8), p(0.8, 0.4), p(0.2, 0.8)];
    let e = err(build(&[one_piece(bow, None)]));
    assert!(matches!(e, TrimError::SelfCrossing { loop_index: 0, .. }));
    assert_eq!(
        e.to_string(),
        "trim loop 0 crosses itself near (0.56, 0.56)"
    );
    // A crossing exactly at a vertex the loop visits twice (the flattened lemniscate).
    let lemniscate = Lemniscate;
    let e = err(build(&[curve_loop(&lemniscate, 1e-6, None)]));
    assert!(matches!(e, TrimError::SelfCrossing { .. }));
    // Negative control: two squares touching at a corner, traversed without crossing.
    let pinch = vec![
        p(0.1, 0.1),
        p(0.5, 0.1),
        p(0.5, 0.5),
        p(0.9, 0.5),
        p(0.9, 0.9),
        p(0.5, 0.9),
        p(0.5, 0.5),
        p(0.1, 0.5),
    ];
    let t = ok(build(&[one_piece(pinch, None)]));
    assert!(close(t.area(), 0.32, 1e-15));
}

/// Gerono's lemniscate around (0.5, 0.5), one lobe wider so the loop has area: crosses itself
/// at t = 0 and t = π, both vertices of the flattening.
struct Lemniscate;

impl Curve2 for Lemniscate {
    fn domain(&self) -> (f64, f64) {
        (0.0, TAU)
    }

    fn point(&self, t: f64) -> DVec2 {
        p(
            0.5 + (0.25 + 0.1 * t.sin()) * t.sin(),
            0.5 + 0.3 * t.sin() * t.cos(),
        )
    }
}

#[test]
fn crossing_loops_are_refused_and_touching_ones_accepted() {
    let a = one_piece(rect(0.2, 0.2, 0.6, 0.6), None);
    let e = err(build(&[
        a.clone(),
        one_piece(rect(0.4, 0.4, 0.8, 0.8), None),
    ]));
    assert!(matches!(
        e,
        TrimError::LoopsCross {
            first: 0,
            second: 1,
            ..
        }
    ));
    // Negative control: the same squares apart.
    ok(build(&[
        a.clone(),
        one_piece(rect(0.65, 0.65, 0.8, 0.8), None),
    ]));
    // Touching at a point: a triangle whose edge passes through the square's corner.
    let tri = vec![p(0.4, 0.8), p(0.8, 0.4), p(0.9, 0.9)];
    let t = ok(build(&[a.clone(), one_piece(tri, None)]));
    assert!(t.loops().iter().all(|l| l.depth() == 0));
    // A hole touching the outer loop at a vertex, and one sharing part of its bottom edge.
    let diamond = vec![p(0.4, 0.2), p(0.5, 0.3), p(0.4, 0.4), p(0.3, 0.3)];
    let t = ok(build(&[a.clone(), one_piece(diamond, None)]));
    assert_eq!(t.loops()[1].depth(), 1);
    let t = ok(build(&[
        a.clone(),
        one_piece(rect(0.3, 0.2, 0.4, 0.3), None),
    ]));
    assert!(close(t.area(), 0.16 - 0.01, 1e-15));
    // Crossing exactly at vertices (no proper crossing): in through a corner, out through an edge.
    let through = vec![
        p(0.6, 0.4),
        p(0.7, 0.35),
        p(0.8, 0.3),
        p(0.7, 0.25),
        p(0.6, 0.2),
        p(0.55, 0.25),
        p(0.5, 0.3),
        p(0.55, 0.35),
    ];
    let e = err(build(&[a, one_piece(through, None)]));
    assert!(matches!(e, TrimError::LoopsCross { .. }));
}

#[test]
fn loops_leaving_the_domain_are_refused_or_clamped() {
    let mut poly = rect(0.2, 0.2, 0.6, 0.6);
    poly[1].x = 1.01;
    let e = err(build(&[one_piece(poly.clone(), None)]));
    assert!(matches!(e, TrimError::OutsideDomain { loop_index: 0, .. }));
    assert_eq!(
        e.to_string(),
        "trim loop 0 leaves the parameter domain at (1.01, 0.2) by 0.01 (more than 1.414e-4)"
    );
    // Negative control: outside by less than the tolerance is clamped in.
    poly[1].x = 1.0 + 1e-6;
    let t = ok(build(&[one_piece(poly, None)]));
    assert_eq!(
        t.loops()[0]
            .points()
            .iter()
            .map(|q| q.x)
            .fold(0.0, f64::max),
        1.0
    );
}

#[test]
fn empty_degenerate_and_non_finite_loops_are_refused() {
    let e = err(build(&[LoopInput::default()]));
    assert_eq!(e.to_string(), "trim loop 0 has no curves");
    let line = vec![p(0.2, 0.2), p(0.5, 0.5), p(0.8, 0.8), p(0.2, 0.2)];
    assert!(matches!(
        err(build(&[one_piece(line, None)])),
        TrimError::ZeroArea { .. }
    ));
    let mut nan = rect(0.2, 0.2, 0.6, 0.6);
    nan[2].y = f64::NAN;
    let e = err(build(&[one_piece(nan, None)]));
    assert_eq!(
        e.to_string(),
        "trim loop 0: curve 0 has a non-finite point (number 2)"
    );
    assert!(matches!(err(build(&[])), TrimError::NoLoops));
    // Negative control: the same loop with finite points is fine.
    ok(build(&[one_piece(rect(0.2, 0.2, 0.6, 0.6), None)]));
}

#[test]
fn declared_roles_must_agree_with_nesting() {
    let outer = one_piece(rect(0.1, 0.1, 0.5, 0.5), Some(Role::Outer));
    let stray = one_piece(rect(0.6, 0.6, 0.8, 0.8), Some(Role::Hole));
    let e = err(build(&[outer.clone(), stray]));
    assert_eq!(e.to_string(), "hole 1 lies outside every outer loop");
    // Negative control: the same hole inside the outer loop.
    let hole = one_piece(rect(0.2, 0.2, 0.3, 0.3), Some(Role::Hole));
    let t = ok(build(&[outer.clone(), hole]));
    assert_eq!(t.loops()[1].role(), Role::Hole);
    assert_eq!(t.loops()[1].parent(), Some(0));
    let inner_outer = one_piece(rect(0.2, 0.2, 0.3, 0.3), Some(Role::Outer));
    let e = err(build(&[outer, inner_outer]));
    assert!(matches!(
        e,
        TrimError::OuterInOuter {
            loop_index: 1,
            parent: 0
        }
    ));
}

/// Outer square, hole, island in the hole, hole in the island, and a second region.
fn nested() -> Vec<Vec<DVec2>> {
    vec![
        rect(0.05, 0.05, 0.6, 0.95),
        rect(0.1, 0.1, 0.55, 0.9),
        rect(0.15, 0.15, 0.5, 0.85),
        rect(0.2, 0.2, 0.45, 0.8),
        rect(0.7, 0.1, 0.9, 0.9),
    ]
}

#[test]
fn nesting_depths_roles_and_orientation() {
    let polys = nested();
    // Every other loop given clockwise: orientation does not matter.
    let loops: Vec<LoopInput> = polys
        .iter()
        .enumerate()
        .map(|(k, q)| {
            one_piece(
                if k % 2 == 1 {
                    reversed(q.clone())
                } else {
                    q.clone()
                },
                None,
            )
        })
        .collect();
    let t = ok(build(&loops));
    let depths: Vec<usize> = t.loops().iter().map(|l| l.depth()).collect();
    assert_eq!(depths, [0, 1, 2, 3, 0]);
    let parents: Vec<Option<usize>> = t.loops().iter().map(|l| l.parent()).collect();
    assert_eq!(parents, [None, Some(0), Some(1), Some(2), None]);
    for l in t.loops() {
        assert_eq!(l.signed_area() > 0.0, l.role() == Role::Outer);
    }
    let expected = 0.55 * 0.9 - 0.45 * 0.8 + 0.35 * 0.7 - 0.25 * 0.6 + 0.2 * 0.8;
    assert!(close(t.area(), expected, 1e-14));
    // The same with every loop reversed gives the same answer everywhere.
    let flipped: Vec<LoopInput> = loops
        .iter()
        .map(|l| one_piece(reversed(l.pieces[0].clone()), None))
        .collect();
    let u = ok(build(&flipped));
    assert!(close(u.area(), t.area(), 1e-15));
    let mut rng = Rng(7);
    for _ in 0..500 {
        let q = rng.point(DVec2::ZERO, DVec2::ONE);
        assert_eq!(t.contains(q), u.contains(q));
        assert_eq!(t.contains(q), brute_inside(&polys, q));
    }
    // Negative control: dropping the island changes the answer.
    let fewer = ok(build(&loops[..2]));
    assert!(!close(fewer.area(), t.area(), 1e-3));
}

#[test]
fn contains_agrees_with_brute_force_winding() {
    let polys = nested();
    let t = ok(build(
        &polys
            .iter()
            .map(|q| one_piece(q.clone(), None))
            .collect::<Vec<_>>(),
    ));
    let circle = super::Circle {
        c: DVec2::new(0.3, 0.6),
        r: 0.12,
    };
    let with_circle = {
        let mut l: Vec<LoopInput> = vec![one_piece(rect(0.05, 0.05, 0.95, 0.95), None)];
        l.push(curve_loop(&circle, 1e-5, None));
        ok(build(&l))
    };
    let circle_polys: Vec<Vec<DVec2>> = with_circle
        .loops()
        .iter()
        .map(|l| l.points().to_vec())
        .collect();
    // Negative control: a slightly larger hole disagrees somewhere.
    let mut moved = circle_polys.clone();
    moved[1]
        .iter_mut()
        .for_each(|v| *v = circle.c + (*v - circle.c) * 1.1);
    let mut rng = Rng(11);
    let (mut checked, mut mismatches_control) = (0, 0);
    for _ in 0..3000 {
        let q = rng.point(DVec2::ZERO, DVec2::ONE);
        assert_eq!(t.contains(q), brute_inside(&polys, q), "at {q}");
        if super::boundary_distance(&circle_polys, q) > 1e-12 {
            assert_eq!(
                with_circle.contains(q),
                brute_inside(&circle_polys, q),
                "at {q}"
            );
            checked += 1;
        }
        if brute_inside(&moved, q) != with_circle.contains(q) {
            mismatches_control += 1;
        }
    }
    assert!(checked > 2900);
    assert!(mismatches_control > 0);
}

#[test]
fn obj_trimming_with_holes() {
    // Two outer rectangles, each with a rectangular hole, declared as OBJ does.
    let loops = [
        one_piece(rect(0.1, 0.1, 0.45, 0.9), Some(Role::Outer)),
        one_piece(rect(0.55, 0.1, 0.9, 0.9), Some(Role::Outer)),
        one_piece(reversed(rect(0.2, 0.3, 0.35, 0.7)), Some(Role::Hole)),
        one_piece(rect(0.65, 0.3, 0.8, 0.7), Some(Role::Hole)),
    ];
    let t = ok(build(&loops));
    let parents: Vec<Option<usize>> = t.loops().iter().map(|l| l.parent()).collect();
    assert_eq!(parents, [None, None, Some(0), Some(1)]);
    let expected = 2.0 * (0.35 * 0.8 - 0.15 * 0.4);
    assert!(close(t.area(), expected, 1e-14));
    assert!(t.contains(p(0.15, 0.5)) && !t.contains(p(0.3, 0.5)) && !t.contains(p(0.5, 0.5)));
    assert!(t.contains(p(0.85, 0.5)) && !t.contains(p(0.7, 0.5)));
    // Negative control: without the holes the area is larger.
    assert!(!close(ok(build(&loops[..2])).area(), expected, 1e-3));
}

#[test]
fn fine_loops_build_quickly_enough_for_a_test() {
    // 65,536 segments: the crossing test is bucketed, not quadratic.
    let circle = super::Circle {
        c: DVec2::new(0.5, 0.5),
        r: 0.4,
    };
    let l = curve_loop(&circle, 1e-9, None);
    let t = ok(build(&[one_piece(rect(0.01, 0.01, 0.99, 0.99), None), l]));
    assert!(t.segment_count() > 30_000);
    assert_eq!(t.loops()[1].role(), Role::Hole);
}

#[test]
fn tangent_circles_touch_and_duplicates_overlap() {
    // Flattened separately (tolerance 1e-7, below the gap tolerance), tangent circles may
    // cross by the flattening error: that is touching, inside and outside.
    let circle = |c: DVec2, r: f64| curve_loop(&super::Circle { c, r }, 1e-7, None);
    let outer = circle(p(0.5, 0.5), 0.4);
    let inner = circle(p(0.3, 0.5), 0.2);
    let beside = circle(
        p(
            0.5 + 0.4 * 2.0f64.sqrt() / 2.0 + 0.05,
            0.5 - 0.4 * 2.0f64.sqrt() / 2.0 - 0.05,
        ),
        0.05 * 2.0f64.sqrt(),
    );
    let t = ok(build(&[outer.clone(), inner, beside]));
    let depths: Vec<usize> = t.loops().iter().map(|l| l.depth()).collect();
    assert_eq!(depths, [0, 1, 0]);
    // Negative control: the inner circle a little larger crosses the outer one.
    let e = err(build(&[outer.clone(), circle(p(0.3, 0.5), 0.201)]));
    assert!(matches!(
        e,
        TrimError::LoopsCross {
            first: 0,
            second: 1,
            ..
        }
    ));
    // The same loop twice runs along itself.
    let e = err(build(&[outer.clone(), outer]));
    assert!(matches!(
        e,
        TrimError::LoopsOverlap {
            first: 0,
            second: 1,
            ..
        }
    ));
}
