//! Point inversion: parameters recovered, seams, poles, clamping, and the
//! distance of points off the surface.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use glam::DVec3;

use super::super::{
    AnalyticSurface, Frame, InvertOptions, NewtonOptions, NurbsSurface, ParamBox, Seam, circle_arc,
    invert_nurbs, line_segment, unwrap_angle,
};
use super::{Rng, bspline_profile, close, ok_err, worst};

/// Radius of the parallel through `S(u, v)` (distance to the axis), so that
/// samples where `u` is ill-defined can be skipped.
fn axis_distance(s: &AnalyticSurface, u: f64, v: f64) -> f64 {
    let p = s.point(u, v).unwrap();
    let l = s.frame().to_local(p);
    l.x.hypot(l.y)
}

/// Generates points at random box parameters (optionally pushed `offset` of
/// the size along the normal) and checks the inversion. Returns the worst
/// parameter error.
fn recover(s: &AnalyticSurface, r: ParamBox, seed: u64, offset: f64) -> f64 {
    let face = s.to_nurbs(&r).unwrap();
    let size = face.surface.extent();
    let mut rng = Rng::new(seed);
    let opts = InvertOptions::default();
    let mut errs = Vec::new();
    for _ in 0..200 {
        let (u, v) = (rng.range(r.u[0], r.u[1]), rng.range(r.v[0], r.v[1]));
        if s.angular()[0] && axis_distance(s, u, v) < 0.05 * size {
            continue;
        }
        let [a, b] = face.map.to_nurbs([u, v]);
        let d = face.surface.derivs(a, b).unwrap();
        let n = d.su.cross(d.sv).normalize();
        let dist = offset * size * if rng.unit() < 0.5 { -1.0 } else { 1.0 };
        let p = s.point(u, v).unwrap() + dist * n;
        let inv = s.invert(p, &r, &opts).unwrap();
        assert!(inv.inside, "{:?} {u} {v}", s.kind());
        assert!(
            close(inv.distance, dist.abs(), 1e-12 * size),
            "{:?}: {} vs {dist}",
            s.kind(),
            inv.distance
        );
        errs.push((inv.uv[0] - u).abs().max((inv.uv[1] - v).abs()));
    }
    let e = worst(errs);
    assert!(ok_err(e, 1e-10), "{:?} {r:?}: param error {e:e}", s.kind());
    e
}

fn analytic_cases(rng: &mut Rng) -> Vec<(AnalyticSurface, ParamBox)> {
    let b = |u: [f64; 2], v: [f64; 2]| ParamBox { u, v };
    vec![
        (
            AnalyticSurface::plane(rng.frame()).unwrap(),
            b([-2.0, 3.0], [-1.0, 4.0]),
        ),
        (
            AnalyticSurface::cylinder(rng.frame(), 2.0).unwrap(),
            b([0.0, TAU], [-1.0, 4.0]),
        ),
        (
            AnalyticSurface::cylinder(rng.frame(), 0.3).unwrap(),
            b([-3.0, -1.0], [0.0, 1.0]),
        ),
        (
            AnalyticSurface::cone(rng.frame(), 1.0, 0.5).unwrap(),
            b([0.0, TAU], [-0.5, 3.0]),
        ),
        (
            AnalyticSurface::cone(rng.frame(), 1.0, 0.7).unwrap(),
            b([1.0, 4.0], [-4.0, 2.0]),
        ),
        (
            AnalyticSurface::cone(rng.frame(), 2.0, -0.4).unwrap(),
            b([-PI, PI], [0.0, 9.0]),
        ),
        (
            AnalyticSurface::sphere(rng.frame(), 3.0).unwrap(),
            b([0.0, TAU], [-FRAC_PI_2, FRAC_PI_2]),
        ),
        (
            AnalyticSurface::sphere(rng.frame(), 0.5).unwrap(),
            b([2.0, 3.0], [0.1, 0.9]),
        ),
        (
            AnalyticSurface::torus(rng.frame(), 3.0, 1.0).unwrap(),
            b([0.0, TAU], [0.0, TAU]),
        ),
        (
            AnalyticSurface::torus(rng.frame(), 1.0, 2.5).unwrap(),
            b([0.0, TAU], [-PI, PI]),
        ),
        (
            AnalyticSurface::torus(rng.frame(), 5.0, 0.2).unwrap(),
            b([4.0, 4.5], [1.0, 2.0]),
        ),
    ]
}

fn swept_cases(rng: &mut Rng) -> Vec<(AnalyticSurface, ParamBox)> {
    let f = rng.frame();
    let (circle, m) = circle_arc(&f, 0.7, -1.0, 2.0).unwrap();
    let axis = (f.origin + 2.0 * f.x + 0.3 * f.z, f.y + 0.1 * f.z);
    let line = line_segment(
        DVec3::new(2.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 2.0),
        0.0,
        3.0,
    )
    .unwrap();
    let b = |u: [f64; 2], v: [f64; 2]| ParamBox { u, v };
    vec![
        (
            AnalyticSurface::revolution(bspline_profile(), DVec3::ZERO, DVec3::Z).unwrap(),
            b([0.0, TAU], [0.0, 3.0]),
        ),
        (
            AnalyticSurface::revolution(bspline_profile(), DVec3::ZERO, DVec3::Z).unwrap(),
            b([1.0, 2.0], [0.5, 2.0]),
        ),
        (
            AnalyticSurface::revolution(circle.clone(), axis.0, axis.1).unwrap(),
            b([-1.0, 4.0], m.domain()),
        ),
        (
            AnalyticSurface::revolution(line, DVec3::ZERO, DVec3::Z).unwrap(),
            b([0.0, 5.0], [0.0, 3.0]),
        ),
        (
            AnalyticSurface::extrusion(bspline_profile(), DVec3::new(0.3, 1.0, 0.2)).unwrap(),
            b([0.0, 3.0], [-1.0, 2.0]),
        ),
        (
            AnalyticSurface::extrusion(circle, DVec3::new(0.0, 0.0, 2.0)).unwrap(),
            b(m.domain(), [0.0, 1.0]),
        ),
    ]
}

#[test]
fn closed_form_recovers_params() {
    let mut rng = Rng::new(21);
    let e = worst(
        analytic_cases(&mut rng)
            .into_iter()
            .map(|(s, r)| recover(&s, r, 1, 0.0)),
    );
    assert!(ok_err(e, 1e-10));
}

#[test]
fn closed_form_off_surface_reports_distance() {
    let mut rng = Rng::new(22);
    for (s, r) in analytic_cases(&mut rng) {
        recover(&s, r, 2, 1e-3);
    }
}

#[test]
fn swept_recovers_params_and_distance() {
    let mut rng = Rng::new(23);
    for (s, r) in swept_cases(&mut rng) {
        recover(&s, r, 3, 0.0);
        recover(&s, r, 4, 1e-4);
    }
}

/// Newton on the NURBS form itself: recovers the mapped parameters.
#[test]
fn nurbs_newton_recovers_params() {
    let mut rng = Rng::new(24);
    let mut cases = analytic_cases(&mut rng);
    cases.extend(swept_cases(&mut rng));
    let opts = NewtonOptions::default();
    for (s, r) in cases {
        let face = s.to_nurbs(&r).unwrap();
        let size = face.surface.extent();
        let mut errs = Vec::new();
        for _ in 0..40 {
            let (u, v) = (rng.range(r.u[0], r.u[1]), rng.range(r.v[0], r.v[1]));
            if s.angular()[0] && axis_distance(&s, u, v) < 0.05 * size {
                continue;
            }
            let st = face.map.to_nurbs([u, v]);
            let p = face.surface.point(st[0], st[1]).unwrap();
            let inv = invert_nurbs(&face.surface, p, &opts).unwrap();
            assert!(
                ok_err(inv.distance, 1e-12 * size),
                "{:?}: {}",
                s.kind(),
                inv.distance
            );
            errs.push((inv.uv[0] - st[0]).abs().max((inv.uv[1] - st[1]).abs()));
        }
        let e = worst(errs);
        assert!(ok_err(e, 1e-10), "{:?}: {e:e}", s.kind());
    }
}

#[test]
fn nurbs_newton_on_a_freeform_patch() {
    let mut rng = Rng::new(25);
    let (nu, nv) = (7, 6);
    let mut points = Vec::new();
    for i in 0..nu {
        for j in 0..nv {
            let (x, y) = (i as f64, j as f64);
            points.push(DVec3::new(x, y, 0.6 * (x * 0.9).sin() * (y * 0.7).cos()) + rng.vec(0.1));
        }
    }
    let s = NurbsSurface {
        degree: [3, 2],
        knots: [
            vec![0.0, 0.0, 0.0, 0.0, 0.3, 0.5, 0.8, 1.0, 1.0, 1.0, 1.0],
            vec![2.0, 2.0, 2.0, 2.5, 3.0, 3.5, 4.0, 4.0, 4.0],
        ],
        points,
        weights: (0..nu * nv).map(|_| rng.range(0.7, 1.5)).collect(),
    };
    let size = s.extent();
    for _ in 0..100 {
        let (u, v) = (rng.unit(), rng.range(2.0, 4.0));
        let d = s.derivs(u, v).unwrap();
        let inv = invert_nurbs(&s, d.p, &NewtonOptions::default()).unwrap();
        assert!(
            ok_err((inv.uv[0] - u).abs().max((inv.uv[1] - v).abs()), 1e-10),
            "{u} {v} {:?}",
            inv.uv
        );
        assert!(ok_err(inv.distance, 1e-12 * size));
        // Off the surface along the normal: same foot, distance reported.
        let off = d.p + 1e-3 * d.su.cross(d.sv).normalize();
        let inv = invert_nurbs(&s, off, &NewtonOptions::default()).unwrap();
        assert!(close(inv.distance, 1e-3, 1e-12 * size));
        assert!(ok_err(
            (inv.uv[0] - u).abs().max((inv.uv[1] - v).abs()),
            1e-8
        ));
    }
}

#[test]
fn seam_hint_picks_the_side() {
    let s = AnalyticSurface::cylinder(Frame::default(), 2.0).unwrap();
    let mut opts = InvertOptions::default();
    for (range, u) in [
        ([0.0, TAU], 0.0),
        ([0.0, TAU], TAU),
        ([-PI, PI], PI),
        ([-PI, PI], -PI),
        ([1.0, 1.0 + TAU], 1.0),
    ] {
        let r = ParamBox {
            u: range,
            v: [0.0, 1.0],
        };
        let p = s.point(u, 0.5).unwrap();
        opts.seam = Seam::Low;
        let lo = s.invert(p, &r, &opts).unwrap();
        opts.seam = Seam::High;
        let hi = s.invert(p, &r, &opts).unwrap();
        assert!(lo.on_seam[0] && hi.on_seam[0] && !lo.on_seam[1]);
        assert!(
            close(lo.uv[0], range[0], 1e-15 * 8.0),
            "{range:?} {u} {:?}",
            lo.uv
        );
        assert!(close(hi.uv[0], range[1], 1e-15 * 8.0));
        assert!(ok_err(lo.distance, 1e-14) && ok_err(hi.distance, 1e-14));
    }
    // Off the seam the hint changes nothing (negative control).
    let r = ParamBox {
        u: [0.0, TAU],
        v: [0.0, 1.0],
    };
    let inv = s.invert(s.point(1.0, 0.5).unwrap(), &r, &opts).unwrap();
    assert!(!inv.on_seam[0] && close(inv.uv[0], 1.0, 1e-15));
    // Torus: seam in v as well.
    let t = AnalyticSurface::torus(Frame::default(), 3.0, 1.0).unwrap();
    let r = ParamBox {
        u: [0.0, TAU],
        v: [-PI, PI],
    };
    let inv = t.invert(t.point(0.5, PI).unwrap(), &r, &opts).unwrap();
    assert!(inv.on_seam[1] && !inv.on_seam[0] && close(inv.uv[1], PI, 1e-15));
}

#[test]
fn angles_near_and_outside_the_range() {
    let s = AnalyticSurface::cylinder(Frame::default(), 1.0).unwrap();
    let r = ParamBox {
        u: [0.0, PI],
        v: [0.0, 1.0],
    };
    let opts = InvertOptions::default();
    let inv = s
        .invert(s.point(PI + 1e-11, 0.5).unwrap(), &r, &opts)
        .unwrap();
    assert!(inv.inside && inv.uv[0] == PI);
    let inv = s.invert(s.point(-1e-11, 0.5).unwrap(), &r, &opts).unwrap();
    assert!(inv.inside && inv.uv[0] == 0.0);
    let inv = s.invert(s.point(-0.5, 0.5).unwrap(), &r, &opts).unwrap();
    assert!(!inv.inside && close(inv.uv[0], -0.5, 1e-15));
    let inv = s
        .invert(s.point(1.2 * PI, 0.5).unwrap(), &r, &opts)
        .unwrap();
    assert!(!inv.inside && close(inv.uv[0], 1.2 * PI, 1e-14));
    // Linear parameter outside the box.
    let inv = s.invert(s.point(1.0, 1.5).unwrap(), &r, &opts).unwrap();
    assert!(!inv.inside && close(inv.uv[1], 1.5, 1e-15));
    // unwrap_angle directly, with the tolerance edge as negative control.
    let w = unwrap_angle(-1e-10, [0.0, 1.0], 1e-9, Seam::Low);
    assert!(w.inside && w.value == 0.0);
    let w = unwrap_angle(-1e-8, [0.0, 1.0], 1e-9, Seam::Low);
    assert!(!w.inside && close(w.value, -1e-8, 1e-20));
    let w = unwrap_angle(0.5 + 4.0 * TAU, [0.0, 1.0], 1e-9, Seam::High);
    assert!(w.inside && !w.on_seam && close(w.value, 0.5, 1e-14));
}

#[test]
fn poles_apex_and_axis() {
    let opts = InvertOptions::default();
    let f = Frame::from_axis2_placement(
        DVec3::new(1.0, 2.0, 3.0),
        Some(DVec3::new(1.0, 1.0, 0.0)),
        None,
    )
    .unwrap();
    let sph = AnalyticSurface::sphere(f, 2.0).unwrap();
    let r = ParamBox {
        u: [0.0, TAU],
        v: [-FRAC_PI_2, FRAC_PI_2],
    };
    for v in [FRAC_PI_2, -FRAC_PI_2] {
        let inv = sph.invert(sph.point(0.7, v).unwrap(), &r, &opts).unwrap();
        assert!(inv.u_free && close(inv.uv[1], v, 1e-15 * 4.0) && ok_err(inv.distance, 1e-14));
    }
    // Centre: every point is at distance R.
    let inv = sph.invert(f.origin, &r, &opts).unwrap();
    assert!(inv.u_free && close(inv.distance, 2.0, 1e-15));
    let cone = AnalyticSurface::cone(f, 1.0, 0.5).unwrap();
    let apex_v = -1.0 / 0.5f64.tan();
    let inv = cone
        .invert(
            cone.point(0.3, apex_v).unwrap(),
            &ParamBox {
                u: [0.0, TAU],
                v: [-3.0, 1.0],
            },
            &opts,
        )
        .unwrap();
    assert!(inv.u_free && close(inv.uv[1], apex_v, 1e-14) && ok_err(inv.distance, 1e-14));
    let cyl = AnalyticSurface::cylinder(f, 1.5).unwrap();
    let inv = cyl
        .invert(
            f.to_world(0.0, 0.0, 0.4),
            &ParamBox {
                u: [0.0, TAU],
                v: [0.0, 1.0],
            },
            &opts,
        )
        .unwrap();
    assert!(inv.u_free && close(inv.distance, 1.5, 1e-15 * 4.0) && close(inv.uv[1], 0.4, 1e-15));
    // Negative control: an ordinary point is not flagged.
    let inv = cyl
        .invert(
            f.to_world(1.5, 0.0, 0.4),
            &ParamBox {
                u: [0.0, TAU],
                v: [0.0, 1.0],
            },
            &opts,
        )
        .unwrap();
    assert!(!inv.u_free);
}

#[test]
fn far_points_report_their_distance() {
    let opts = InvertOptions::default();
    let sph = AnalyticSurface::sphere(Frame::default(), 1.0).unwrap();
    let r = ParamBox {
        u: [0.0, TAU],
        v: [-FRAC_PI_2, FRAC_PI_2],
    };
    let inv = sph.invert(DVec3::new(3.0, 4.0, 0.0), &r, &opts).unwrap();
    assert!(close(inv.distance, 4.0, 1e-15 * 8.0));
    let tor = AnalyticSurface::torus(Frame::default(), 3.0, 1.0).unwrap();
    let inv = tor
        .invert(
            DVec3::new(0.0, 0.0, 4.0),
            &ParamBox {
                u: [0.0, TAU],
                v: [0.0, TAU],
            },
            &opts,
        )
        .unwrap();
    assert!(close(inv.distance, 5.0 - 1.0, 1e-14));
    let rev = AnalyticSurface::revolution(bspline_profile(), DVec3::ZERO, DVec3::Z).unwrap();
    let inv = rev
        .invert(
            DVec3::new(0.0, 50.0, 1.0),
            &ParamBox {
                u: [0.0, TAU],
                v: [0.0, 3.0],
            },
            &opts,
        )
        .unwrap();
    assert!(inv.distance > 40.0 && inv.distance.is_finite());
    assert!(close(
        (inv.point - DVec3::new(0.0, 50.0, 1.0)).length(),
        inv.distance,
        0.0
    ));
}
