//! Every NURBS form, evaluated at analytic (u, v) pushed through its
//! ParamMap, equals the ISO 10303-42 formula to 1e-12 of its size; a
//! perturbed control point or weight fails the same check.

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI, TAU};

use glam::DVec3;

use super::super::{AnalyticSurface, AxisMap, Frame, ParamBox, circle_arc, line_segment};
use super::{Rng, box_samples, bspline_profile, close, ok_err, perturbed, surface_deviation};

const TOL: f64 = 1e-12;

/// Converts, checks exactness and the negative controls, returns the error.
fn check(s: &AnalyticSurface, r: ParamBox, seed: u64) -> f64 {
    let face = s.to_nurbs(&r).unwrap_or_else(|e| panic!("{e} for {r:?}"));
    assert!(face.surface.validate().is_ok());
    let mut rng = Rng::new(seed);
    let samples = box_samples(&mut rng, &r, 300);
    let e = surface_deviation(&face, s, &samples);
    assert!(ok_err(e, TOL), "{:?} {r:?}: deviation {e:e}", s.kind());
    for bad in perturbed(&face, 1e-6) {
        let e = surface_deviation(&bad, s, &samples);
        assert!(
            !ok_err(e, TOL),
            "perturbation not detected for {:?}",
            s.kind()
        );
    }
    // Map round trip and domain corners.
    let d = face.surface.domain().unwrap();
    for &[u, v] in &samples {
        let [a, b] = face.map.to_nurbs([u, v]);
        assert!(a >= d[0][0] && a <= d[0][1] && b >= d[1][0] && b <= d[1][1]);
        let [u2, v2] = face.map.to_analytic([a, b]);
        assert!(close(u2, u, 1e-14 * (1.0 + u.abs())) && close(v2, v, 1e-14 * (1.0 + v.abs())));
    }
    e
}

fn u_ranges() -> Vec<[f64; 2]> {
    vec![
        [0.0, TAU],
        [-1.0, 0.3],
        [5.0, 5.0 + 1.5 * PI + 0.1],
        [0.1, 0.1 + 1e-4],
        [-PI, PI],
        [2.0, 2.0 + FRAC_PI_2],
    ]
}

#[test]
fn plane() {
    let mut rng = Rng::new(1);
    for seed in 0..5 {
        let s = AnalyticSurface::plane(rng.frame()).unwrap();
        check(
            &s,
            ParamBox {
                u: [-3.0, 2.0],
                v: [0.5, 7.0],
            },
            seed,
        );
    }
}

#[test]
fn cylinders() {
    let mut rng = Rng::new(2);
    for (i, u) in u_ranges().into_iter().enumerate() {
        let s = AnalyticSurface::cylinder(rng.frame(), rng.range(0.1, 20.0)).unwrap();
        check(&s, ParamBox { u, v: [-2.0, 3.0] }, i as u64);
    }
}

#[test]
fn cones_including_negative_angle_and_apex() {
    let mut rng = Rng::new(3);
    let cases = [
        (1.0, 0.3, [0.0, 4.0]),
        (1.0, FRAC_PI_4, [-3.0, 2.0]), // apex at v = −1
        (2.0, -0.4, [0.0, 9.0]),       // apex at v = 2/tan 0.4 ≈ 4.7
        (0.0, 1.2, [-1.0, 1.0]),       // apex at v = 0
        (3.0, -1.5, [-0.5, 0.5]),
    ];
    for (i, (radius, alpha, v)) in cases.into_iter().enumerate() {
        for u in u_ranges() {
            let s = AnalyticSurface::cone(rng.frame(), radius, alpha).unwrap();
            check(&s, ParamBox { u, v }, i as u64);
        }
    }
}

#[test]
fn spheres_including_poles() {
    let mut rng = Rng::new(4);
    let vs = [
        [-FRAC_PI_2, FRAC_PI_2],
        [0.0, FRAC_PI_2],
        [-0.3, 0.2],
        [-FRAC_PI_2, -1.0],
    ];
    for (i, v) in vs.into_iter().enumerate() {
        for u in u_ranges() {
            let s = AnalyticSurface::sphere(rng.frame(), rng.range(0.01, 50.0)).unwrap();
            check(&s, ParamBox { u, v }, i as u64);
        }
    }
}

#[test]
fn tori_including_degenerate() {
    let mut rng = Rng::new(5);
    let vs = [[0.0, TAU], [-PI, PI], [0.2, 0.2 + 1e-5], [-1.0, 2.5]];
    for (i, (major, minor)) in [(3.0, 1.0), (1.0, 2.5), (1.0, 1.0), (10.0, 0.01)]
        .into_iter()
        .enumerate()
    {
        for v in vs {
            for u in u_ranges() {
                let s = AnalyticSurface::torus(rng.frame(), major, minor).unwrap();
                check(&s, ParamBox { u, v }, i as u64);
            }
        }
    }
}

#[test]
fn revolutions_of_line_circle_and_bspline() {
    let mut rng = Rng::new(6);
    let axis_p = DVec3::new(0.5, -1.0, 2.0);
    let axis_d = DVec3::new(0.2, 0.3, 1.0);
    let line = line_segment(
        DVec3::new(3.0, 0.0, 0.0),
        DVec3::new(-1.0, 0.5, 2.0),
        -1.0,
        4.0,
    )
    .unwrap();
    let f = rng.frame();
    let (circle, _) = circle_arc(&f, 0.7, -2.0, 3.0).unwrap();
    for (profile, vr) in [
        (line, [-1.0, 4.0]),
        (circle, [-2.0, 3.0]),
        (bspline_profile(), [0.0, 3.0]),
    ] {
        for u in u_ranges() {
            let s = AnalyticSurface::revolution(profile.clone(), axis_p, axis_d).unwrap();
            check(&s, ParamBox { u, v: vr }, 1);
            // A sub-range of the profile (cut between knots).
            let sub = [
                vr[0] + 0.13 * (vr[1] - vr[0]),
                vr[1] - 0.21 * (vr[1] - vr[0]),
            ];
            check(&s, ParamBox { u, v: sub }, 2);
        }
    }
}

#[test]
fn revolved_circle_is_the_torus() {
    // Independent formula check: revolving the circle (R + r cos v, r sin v)
    // about Z gives the torus, with v mapped by the profile's own ArcMap.
    let (major, minor) = (3.0, 1.2);
    let f =
        Frame::from_axis2_placement(DVec3::new(major, 0.0, 0.0), Some(-DVec3::Y), Some(DVec3::X))
            .unwrap();
    let (circle, vmap) = circle_arc(&f, minor, -PI, 2.0).unwrap();
    let rev = AnalyticSurface::revolution(circle, DVec3::ZERO, DVec3::Z).unwrap();
    let torus = AnalyticSurface::torus(Frame::default(), major, minor).unwrap();
    let face = rev
        .to_nurbs(&ParamBox {
            u: [0.0, 5.0],
            v: vmap.domain(),
        })
        .unwrap();
    assert!(matches!(face.map.v, AxisMap::Identity));
    let mut rng = Rng::new(8);
    for _ in 0..200 {
        let (u, v) = (rng.range(0.0, 5.0), rng.range(-PI, 2.0));
        let [s, t] = face.map.to_nurbs([u, vmap.angle_to_param(v)]);
        let p = face.surface.point(s, t).unwrap();
        let q = torus.point(u, v).unwrap();
        assert!((p - q).length() <= TOL * (major + minor), "{u} {v}");
    }
}

#[test]
fn extrusions() {
    let mut rng = Rng::new(7);
    let f = rng.frame();
    let (ellipse, _) = super::super::ellipse_arc(&f, 2.0, 0.5, 1.0, 4.0).unwrap();
    let line = line_segment(DVec3::ZERO, DVec3::new(1.0, 2.0, 0.0), 0.0, 3.0).unwrap();
    for (profile, ur) in [
        (ellipse, [1.0, 4.0]),
        (bspline_profile(), [0.0, 3.0]),
        (line, [0.0, 3.0]),
    ] {
        let s = AnalyticSurface::extrusion(profile, DVec3::new(0.3, -0.2, 2.5)).unwrap();
        check(
            &s,
            ParamBox {
                u: ur,
                v: [-1.0, 2.0],
            },
            3,
        );
        check(
            &s,
            ParamBox {
                u: [ur[0] + 0.4, ur[1] - 0.3],
                v: [0.5, 0.6],
            },
            4,
        );
    }
}

#[test]
fn frame_follows_step_rules() {
    let o = DVec3::new(1.0, 2.0, 3.0);
    let f = Frame::from_axis2_placement(o, None, None).unwrap();
    assert_eq!((f.origin, f.x, f.y, f.z), (o, DVec3::X, DVec3::Y, DVec3::Z));
    // ref_direction is projected perpendicular to the axis; Y = Z × X.
    let f = Frame::from_axis2_placement(
        o,
        Some(DVec3::new(0.0, 0.0, 2.0)),
        Some(DVec3::new(1.0, 1.0, 5.0)),
    )
    .unwrap();
    let s = 0.5f64.sqrt();
    assert!(close(f.x.x, s, 1e-15) && close(f.x.y, s, 1e-15) && close(f.x.z, 0.0, 0.0));
    assert!(close(f.y.x, -s, 1e-15) && close(f.y.y, s, 1e-15));
    assert!(f.validate().is_ok());
    // Axis along ±X with no ref_direction: STEP's first_proj_axis uses (0,1,0).
    let f = Frame::from_axis2_placement(o, Some(-DVec3::X), None).unwrap();
    assert_eq!((f.x, f.z), (DVec3::Y, -DVec3::X));
    // Otherwise (1,0,0) projected.
    let f = Frame::from_axis2_placement(o, Some(DVec3::new(1.0, 0.0, 1.0)), None).unwrap();
    assert!(close(f.x.dot(f.z), 0.0, 1e-15) && f.x.x > 0.0);
    assert!(close(f.z.cross(f.x).dot(f.y), 1.0, 1e-15));
    // Negative control: an unprojected ref_direction is not orthogonal.
    assert!(!close(
        DVec3::new(1.0, 1.0, 5.0).normalize().dot(DVec3::Z),
        0.0,
        1e-3
    ));
}
