//! Bad input gives one-line errors, never a panic.

use std::f64::consts::{FRAC_PI_2, PI};

use glam::DVec3;

use super::super::{
    AnalyticError, AnalyticSurface, ArcMap, Frame, InvertOptions, NewtonOptions, NurbsCurve,
    NurbsSurface, ParamBox, circle_arc, ellipse_arc, invert_nurbs, line_segment,
};
use super::bspline_profile;

fn one_line<T: std::fmt::Debug>(r: Result<T, AnalyticError>) -> AnalyticError {
    let e = r.expect_err("expected an error");
    let msg = e.to_string();
    assert!(!msg.is_empty() && !msg.contains('\n'), "{msg:?}");
    e
}

#[test]
fn frame_errors() {
    let o = DVec3::ZERO;
    assert_eq!(
        one_line(Frame::from_axis2_placement(o, Some(DVec3::ZERO), None)),
        AnalyticError::ZeroVector {
            what: "placement axis"
        }
    );
    one_line(Frame::from_axis2_placement(
        o,
        Some(DVec3::Z),
        Some(DVec3::ZERO),
    ));
    assert_eq!(
        one_line(Frame::from_axis2_placement(
            o,
            Some(DVec3::Z),
            Some(-3.0 * DVec3::Z)
        )),
        AnalyticError::ParallelAxes
    );
    one_line(Frame::from_axis2_placement(
        DVec3::new(f64::NAN, 0.0, 0.0),
        None,
        None,
    ));
    one_line(Frame::from_axis2_placement(
        o,
        Some(DVec3::new(0.0, f64::INFINITY, 0.0)),
        None,
    ));
    one_line(
        Frame {
            x: DVec3::Y,
            ..Frame::default()
        }
        .validate(),
    );
    // Positive controls.
    assert!(
        Frame::from_axis2_placement(o, Some(DVec3::Z), Some(DVec3::new(1.0, 0.0, 5.0))).is_ok()
    );
    assert!(Frame::from_axis2_placement(o, Some(DVec3::new(1e300, 1e300, 0.0)), None).is_ok());
}

#[test]
fn surface_constructor_errors() {
    let f = Frame::default();
    for r in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        one_line(AnalyticSurface::cylinder(f, r));
        one_line(AnalyticSurface::sphere(f, r));
        one_line(AnalyticSurface::torus(f, r, 1.0));
        one_line(AnalyticSurface::torus(f, 1.0, r));
        one_line(ellipse_arc(&f, r, 1.0, 0.0, 1.0));
        one_line(circle_arc(&f, r, 0.0, 1.0));
    }
    one_line(AnalyticSurface::cone(f, -1.0, 0.3));
    for a in [FRAC_PI_2, -FRAC_PI_2, 2.0, f64::NAN] {
        one_line(AnalyticSurface::cone(f, 1.0, a));
    }
    assert!(AnalyticSurface::cone(f, 0.0, -0.3).is_ok());
    let bad_frame = Frame {
        z: DVec3::new(0.0, 0.0, 2.0),
        ..f
    };
    one_line(AnalyticSurface::plane(bad_frame));
    let p = bspline_profile();
    one_line(AnalyticSurface::revolution(
        p.clone(),
        DVec3::ZERO,
        DVec3::ZERO,
    ));
    one_line(AnalyticSurface::revolution(
        p.clone(),
        DVec3::splat(f64::NAN),
        DVec3::Z,
    ));
    one_line(AnalyticSurface::extrusion(p.clone(), DVec3::ZERO));
    one_line(AnalyticSurface::extrusion(
        p.clone(),
        DVec3::new(0.0, f64::NAN, 1.0),
    ));
    let mut broken = p;
    broken.knots.pop();
    one_line(AnalyticSurface::extrusion(broken, DVec3::Z));
}

#[test]
fn range_errors() {
    let f = Frame::default();
    let cyl = AnalyticSurface::cylinder(f, 1.0).unwrap();
    for (u, v) in [
        ([1.0, 1.0], [0.0, 1.0]),
        ([2.0, 1.0], [0.0, 1.0]),
        ([0.0, 1.0], [0.0, f64::NAN]),
    ] {
        one_line(cyl.to_nurbs(&ParamBox { u, v }));
    }
    assert!(matches!(
        one_line(cyl.to_nurbs(&ParamBox {
            u: [0.0, 7.0],
            v: [0.0, 1.0]
        })),
        AnalyticError::SweepTooLarge { .. }
    ));
    let sph = AnalyticSurface::sphere(f, 1.0).unwrap();
    one_line(sph.to_nurbs(&ParamBox {
        u: [0.0, 1.0],
        v: [0.0, 2.0],
    }));
    let rev = AnalyticSurface::revolution(bspline_profile(), DVec3::ZERO, DVec3::Z).unwrap();
    one_line(rev.to_nurbs(&ParamBox {
        u: [0.0, PI],
        v: [-1.0, 1.0],
    }));
    one_line(rev.to_nurbs(&ParamBox {
        u: [0.0, PI],
        v: [1.0, 1.0],
    }));
    one_line(ArcMap::new(f64::NAN, 1.0));
    one_line(ArcMap::new(1.0, 1.0));
    one_line(ArcMap::new(0.0, 6.3));
    one_line(ArcMap::new(1e300, -1e300));
    one_line(ArcMap::new(1e6, 1e6 + 1e-12));
    one_line(line_segment(DVec3::ZERO, DVec3::ZERO, 0.0, 1.0));
    one_line(line_segment(DVec3::ZERO, DVec3::X, 1.0, 0.0));
    one_line(line_segment(DVec3::ZERO, DVec3::X, 0.0, f64::NAN));
    let opts = InvertOptions::default();
    one_line(cyl.invert(
        DVec3::new(f64::NAN, 0.0, 0.0),
        &ParamBox {
            u: [0.0, 1.0],
            v: [0.0, 1.0],
        },
        &opts,
    ));
}

#[test]
fn nurbs_validation_errors() {
    let good = bspline_profile();
    assert!(good.validate().is_ok());
    let edits: [fn(&mut NurbsCurve); 8] = [
        |c| c.degree = 0,
        |c| c.knots.push(3.0),
        |c| c.knots.swap(4, 6),
        |c| c.weights[2] = 0.0,
        |c| c.weights[2] = -1.0,
        |c| c.weights.pop().map(|_| ()).unwrap_or(()),
        |c| c.points[1].y = f64::NAN,
        |c| c.knots = vec![1.0; 11],
    ];
    for edit in edits {
        let mut c = good.clone();
        edit(&mut c);
        one_line(c.validate());
        one_line(c.point(0.5));
        one_line(c.segment(0.5, 1.0));
    }
    let mut c = good.clone();
    c.degree = 20;
    one_line(c.derivs(0.5));
    let s = NurbsSurface {
        degree: [1, 1],
        knots: [vec![0.0, 0.0, 1.0, 1.0], vec![0.0, 0.0, 1.0, 1.0]],
        points: vec![DVec3::ZERO; 3],
        weights: vec![1.0; 3],
    };
    one_line(s.validate());
    one_line(s.point(0.5, 0.5));
    one_line(invert_nurbs(&s, DVec3::ZERO, &NewtonOptions::default()));
    let mut s2 = s.clone();
    s2.degree = [5, 1];
    one_line(s2.validate());
    let mut s3 = s;
    s3.points.push(DVec3::ZERO);
    s3.weights.push(1.0);
    assert!(s3.validate().is_ok());
    one_line(invert_nurbs(
        &s3,
        DVec3::splat(f64::NAN),
        &NewtonOptions::default(),
    ));
}

/// Garbage in every public entry point: errors or values, never a panic.
#[test]
fn garbage_never_panics() {
    use super::Rng;
    let mut rng = Rng::new(77);
    let specials = [
        0.0,
        -0.0,
        -1.0,
        1e-300,
        1e300,
        -1e300,
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        7.0,
    ];
    let mut pick = |rng: &mut Rng| {
        if rng.unit() < 0.5 {
            specials[(rng.next_u64() % specials.len() as u64) as usize]
        } else {
            rng.range(-10.0, 10.0)
        }
    };
    let opts = InvertOptions::default();
    for _ in 0..3000 {
        let v3 = |rng: &mut Rng, pick: &mut dyn FnMut(&mut Rng) -> f64| {
            DVec3::new(pick(rng), pick(rng), pick(rng))
        };
        let f = Frame::from_axis2_placement(
            v3(&mut rng, &mut pick),
            Some(v3(&mut rng, &mut pick)),
            None,
        )
        .unwrap_or_default();
        let (a, b, c, d) = (
            pick(&mut rng),
            pick(&mut rng),
            pick(&mut rng),
            pick(&mut rng),
        );
        let r = ParamBox {
            u: [a, b],
            v: [c, d],
        };
        let surfaces = [
            AnalyticSurface::cylinder(f, pick(&mut rng)),
            AnalyticSurface::cone(f, pick(&mut rng), pick(&mut rng)),
            AnalyticSurface::sphere(f, pick(&mut rng)),
            AnalyticSurface::torus(f, pick(&mut rng), pick(&mut rng)),
            AnalyticSurface::revolution(
                bspline_profile(),
                v3(&mut rng, &mut pick),
                v3(&mut rng, &mut pick),
            ),
            AnalyticSurface::extrusion(bspline_profile(), v3(&mut rng, &mut pick)),
        ];
        let p = v3(&mut rng, &mut pick);
        for s in surfaces.into_iter().flatten() {
            let _ = s.to_nurbs(&r);
            let _ = s.invert(p, &r, &opts);
            let _ = s.point(a, c);
        }
        if let Ok(m) = ArcMap::new(a, b) {
            let _ = (m.angle_to_param(c), m.param_to_angle(d));
        }
        let _ = ellipse_arc(&f, a, b, c, d);
        let mut curve = bspline_profile();
        curve.degree = (rng.next_u64() % 5) as usize;
        curve.knots.truncate((rng.next_u64() % 12) as usize);
        curve.weights[0] = pick(&mut rng);
        let _ = curve.segment(a, b);
        let _ = curve.derivs(c);
        let _ = super::super::unwrap_angle(a, [b, c], d, super::super::Seam::High);
        let knots = |rng: &mut Rng| -> Vec<f64> {
            let n = (rng.next_u64() % 10) as usize;
            let mut k: Vec<f64> = (0..n).map(|_| pick(rng)).collect();
            if rng.unit() < 0.7 {
                k.sort_by(f64::total_cmp);
            }
            k
        };
        let (ku, kv) = (knots(&mut rng), knots(&mut rng));
        let n = (rng.next_u64() % 30) as usize;
        let s = NurbsSurface {
            degree: [(rng.next_u64() % 4) as usize, (rng.next_u64() % 4) as usize],
            knots: [ku, kv],
            points: (0..n).map(|_| rng.vec(3.0)).collect(),
            weights: (0..n).map(|_| rng.range(0.1, 2.0)).collect(),
        };
        let nopts = NewtonOptions {
            samples_per_span: (rng.next_u64() % 3) as usize,
            starts: (rng.next_u64() % 3) as usize,
            max_iter: (rng.next_u64() % 5) as usize,
            ..NewtonOptions::default()
        };
        let _ = invert_nurbs(&s, p, &nopts);
        let _ = s.derivs(a, c);
    }
}
