//! The built-in demo scene of `prespline view` with no file: a B-spline surface with its control
//! net, an ERBS surface with visible local patches, an ERBS curve with its local curves, an exact
//! NURBS circle, a closed ERBS torus built from a NURBS torus, and the Utah teapot.

use super::parse_scene;
use crate::geom::{
    BFunctionKind, BSplineCurve, BezierCurve, ErbsCurve, ErbsSurface, KnotVector, TensorSurface,
};
use crate::model::{CurveModel, ErbsCurveModel, ErbsSurfaceModel, SplineForm, SurfaceModel};
use crate::scene::{Model, Scene, SceneObject};
use glam::DVec3;

/// Newell's teapot (32 bicubic Bézier patches), the file shipped in `examples/`.
pub const TEAPOT_JSON: &str = include_str!("../../examples/teapot.json");

/// Builds the demo scene. Objects are laid out side by side along x, z up.
#[must_use]
pub fn demo_scene() -> Scene {
    let object = |name: &str, model, color| SceneObject {
        name: name.into(),
        model,
        color: Some(color),
        kept: Default::default(),
        trim: None,
    };
    let valid = "the demo's sample counts are valid";
    let mut objects = vec![
        object(
            "bspline_surface",
            Model::Surface(
                SurfaceModel::new(SplineForm::BSpline, bspline_surface(), [96, 96]).expect(valid),
            ),
            [0.80, 0.55, 0.30],
        ),
        object(
            "erbs_surface",
            Model::ErbsSurface(ErbsSurfaceModel::new(erbs_surface(), [96, 96]).expect(valid)),
            [0.35, 0.60, 0.85],
        ),
        object(
            "erbs_curve",
            Model::ErbsCurve(ErbsCurveModel::new(erbs_curve(), 400).expect(valid)),
            [0.90, 0.20, 0.20],
        ),
        object(
            "nurbs_circle",
            Model::Curve(
                CurveModel::new(
                    SplineForm::BSpline,
                    nurbs_circle(DVec3::new(0.0, -5.5, 0.0), 1.5),
                    256,
                )
                .expect(valid),
            ),
            [0.95, 0.85, 0.20],
        ),
        object(
            "erbs_torus",
            Model::ErbsSurface(ErbsSurfaceModel::new(erbs_torus(), [96, 64]).expect(valid)),
            [0.45, 0.75, 0.45],
        ),
    ];
    let mut teapot = parse_scene(TEAPOT_JSON).expect("the bundled teapot is valid");
    for o in &mut teapot.objects {
        if let Model::Surface(s) = &mut o.model {
            s.map_points(|p| p + DVec3::new(9.0, 0.0, 0.0));
        }
        o.color = Some([0.85, 0.85, 0.88]);
    }
    objects.extend(teapot.objects);
    Scene { objects }
}

/// Bicubic clamped B-spline surface over [−3, 3]² with a few bumps.
fn bspline_surface() -> TensorSurface {
    let n = 8;
    let mut pts = Vec::with_capacity(n * n);
    for i in 0..n {
        for j in 0..n {
            let x = -3.0 + 6.0 * i as f64 / (n - 1) as f64;
            let y = -3.0 + 6.0 * j as f64 / (n - 1) as f64;
            let z =
                0.8 * (0.9 * x).sin() * (0.7 * y).cos() + if (i, j) == (3, 4) { 1.5 } else { 0.0 };
            pts.push(DVec3::new(x - 9.0, y, z));
        }
    }
    let k = KnotVector::clamped_uniform(3, n, 0.0, 1.0).into_vec();
    TensorSurface::bspline([3, 3], [k.clone(), k], [n, n], pts, None).expect("valid demo surface")
}

/// ERBS surface with 4 × 4 biquadratic local patches, each a small dome over its grid cell.
fn erbs_surface() -> ErbsSurface {
    let n = 4;
    let knots: Vec<f64> = std::iter::once(0.0)
        .chain((0..n).map(|i| i as f64))
        .chain(std::iter::once((n - 1) as f64))
        .collect();
    let mut patches = Vec::new();
    for k in 0..n {
        for l in 0..n {
            let centre = DVec3::new(-2.7 + 1.8 * k as f64, -2.7 + 1.8 * l as f64, 0.0);
            let mut pts = Vec::new();
            for a in 0..3 {
                for b in 0..3 {
                    let (x, y) = (a as f64 - 1.0, b as f64 - 1.0);
                    let h = if a == 1 && b == 1 {
                        0.9 + 0.3 * ((k + l) % 2) as f64
                    } else {
                        0.0
                    };
                    pts.push(centre + DVec3::new(1.2 * x, 1.2 * y, h));
                }
            }
            patches.push(TensorSurface::bezier([3, 3], pts, None).expect("valid patch"));
        }
    }
    ErbsSurface::new(
        [knots.clone(), knots],
        [n, n],
        patches,
        BFunctionKind::ExpoRational,
    )
    .expect("valid demo ERBS")
}

/// ERBS curve with 5 quadratic local curves along a wave above the ERBS surface.
fn erbs_curve() -> ErbsCurve {
    let n = 5;
    let knots: Vec<f64> = std::iter::once(0.0)
        .chain((0..n).map(|i| i as f64))
        .chain(std::iter::once((n - 1) as f64))
        .collect();
    let local = (0..n)
        .map(|l| {
            let x = -3.0 + 1.5 * l as f64;
            let z = 3.0 + 0.8 * (l as f64 * 1.7).sin();
            BezierCurve::new(vec![
                DVec3::new(x - 0.9, -0.3, z - 0.4),
                DVec3::new(x, 0.9, z + 0.6),
                DVec3::new(x + 0.9, 0.3, z - 0.2),
            ])
            .expect("valid local curve")
        })
        .collect();
    ErbsCurve::new(knots, local, BFunctionKind::ExpoRational).expect("valid demo ERBS curve")
}

/// The closed (in u and v) ERBS torus: 8 × 6 bicubic local patches Hermite-interpolating the
/// exact NURBS torus (major radius 2, minor 0.7) at the knot crossings, in front of the teapot.
fn erbs_torus() -> ErbsSurface {
    let torus = nurbs_torus(DVec3::new(9.0, -6.5, 0.7), 2.0, 0.7);
    ErbsSurface::from_surface(
        &torus,
        [8, 6],
        [3, 3],
        BFunctionKind::ExpoRational,
        [true, true],
    )
    .expect("valid demo ERBS torus")
}

/// The exact NURBS torus around the z axis through `centre`: the circle of radius `minor` in
/// the (radius, z) half-plane at `major`, revolved by the nine-point circle (biquadratic,
/// weights the products of the circles' 1 and √2/2).
#[must_use]
pub fn nurbs_torus(centre: DVec3, major: f64, minor: f64) -> TensorSurface {
    let around = nurbs_circle(DVec3::ZERO, 1.0);
    let tube = nurbs_circle(DVec3::ZERO, 1.0);
    let (aw, tw) = (around.weights(), tube.weights());
    let mut points = Vec::with_capacity(81);
    let mut weights = Vec::with_capacity(81);
    for (i, a) in around.points().iter().enumerate() {
        for (j, t) in tube.points().iter().enumerate() {
            let r = major + minor * t.x;
            points.push(centre + DVec3::new(r * a.x, r * a.y, minor * t.y));
            weights.push(aw.map_or(1.0, |w| w[i]) * tw.map_or(1.0, |w| w[j]));
        }
    }
    let k = around.knots().to_vec();
    TensorSurface::bspline([2, 2], [k.clone(), k], [9, 9], points, Some(weights))
        .expect("valid torus")
}

/// The exact NURBS circle: degree 2, nine control points on a square, weights 1 and √2/2.
#[must_use]
pub fn nurbs_circle(centre: DVec3, radius: f64) -> BSplineCurve {
    let w = std::f64::consts::FRAC_1_SQRT_2;
    let corners = [
        (1., 0.),
        (1., 1.),
        (0., 1.),
        (-1., 1.),
        (-1., 0.),
        (-1., -1.),
        (0., -1.),
        (1., -1.),
        (1., 0.),
    ];
    let pts = corners
        .iter()
        .map(|&(x, y)| centre + DVec3::new(x, y, 0.0) * radius)
        .collect();
    let weights = (0..9).map(|i| if i % 2 == 1 { w } else { 1.0 }).collect();
    let knots = vec![0., 0., 0., 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1., 1., 1.];
    BSplineCurve::new(2, knots, pts, Some(weights)).expect("valid circle")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn demo_scene_is_complete_and_round_trips() {
        let scene = demo_scene();
        assert_eq!(scene.objects.len(), 5 + 32);
        let text = super::super::json::scene_to_json(&scene);
        let back = parse_scene(&text).unwrap();
        assert_eq!(back, scene);
    }

    #[test]
    fn torus_is_exact_and_its_erbs_is_close() {
        let c = DVec3::new(1.0, -2.0, 0.5);
        let t = nurbs_torus(c, 2.0, 0.7);
        let e = erbs_torus();
        let off = DVec3::new(9.0, -6.5, 0.7);
        for i in 0..=40 {
            for j in 0..=40 {
                let (u, v) = (i as f64 / 40.0, j as f64 / 40.0);
                let p = t.eval(u, v) - c;
                let ring = DVec3::new(p.x, p.y, 0.0).length() - 2.0;
                assert!(
                    (ring.hypot(p.z) - 0.7).abs() < 1e-13,
                    "NURBS torus at ({u}, {v})"
                );
                // The ERBS blends cubic Taylor polynomials: close to the torus, not on it.
                let q = e.eval(u, v) - off;
                let ring = DVec3::new(q.x, q.y, 0.0).length() - 2.0;
                assert!(
                    (ring.hypot(q.z) - 0.7).abs() < 0.02,
                    "ERBS torus at ({u}, {v})"
                );
            }
        }
        assert_eq!(e.closed(), [true, true]);
    }

    #[test]
    fn circle_is_exact() {
        let c = nurbs_circle(DVec3::new(1.0, 2.0, 0.0), 2.0);
        for i in 0..=100 {
            let p = c.eval(i as f64 / 100.0);
            assert!(((p - DVec3::new(1.0, 2.0, 0.0)).length() - 2.0).abs() < 1e-14);
        }
    }
}
