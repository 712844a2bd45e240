//! Surface curvature maps against analytic values (exact NURBS sphere: K = 1/r², |H| = 1/r;
//! cylinder: K = 0, |H| = 1/(2r)), and the analysis delta path (six partials, normals, K and H)
//! against exact re-evaluation after long random edit sequences.

use glam::DVec3;
use prespline::geom::TensorSurface;
use prespline::model::SampledObject;
use prespline::model::exact::exact_grid;
use prespline::model::{KindEdit, Model, PointEdit, SplineForm, SurfaceEdit, SurfaceModel};
use prespline::sampling::curvature::principal;
use prespline::sampling::{PartialSet, SampleMode};

use crate::common;
use common::Rng;

const W: f64 = std::f64::consts::FRAC_1_SQRT_2;

/// The full circle of radius 1 as a degree-2 NURBS: 9 points on the square, weights 1, √2/2.
fn circle() -> (Vec<f64>, Vec<(f64, f64)>, Vec<f64>) {
    let knots = vec![
        0.0, 0.0, 0.0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1.0, 1.0, 1.0,
    ];
    let pts = vec![
        (1.0, 0.0),
        (1.0, 1.0),
        (0.0, 1.0),
        (-1.0, 1.0),
        (-1.0, 0.0),
        (-1.0, -1.0),
        (0.0, -1.0),
        (1.0, -1.0),
        (1.0, 0.0),
    ];
    let w = (0..9).map(|i| if i % 2 == 1 { W } else { 1.0 }).collect();
    (knots, pts, w)
}

/// Sphere of radius r: the circle swept along a half circle from the south to the north pole
/// (rational biquadratic, 9 × 5 points, the poles are collapsed rows).
fn sphere(r: f64, samples: [usize; 2]) -> Model {
    let (ku, cu, wu) = circle();
    let kv = vec![0.0, 0.0, 0.0, 0.5, 0.5, 1.0, 1.0, 1.0];
    let profile = [(0.0, -1.0), (1.0, -1.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
    let wv = [1.0, W, 1.0, W, 1.0];
    let mut pts = Vec::new();
    let mut w = Vec::new();
    for (i, &(x, y)) in cu.iter().enumerate() {
        for (j, &(rho, z)) in profile.iter().enumerate() {
            pts.push(DVec3::new(x * rho, y * rho, z) * r);
            w.push(wu[i] * wv[j]);
        }
    }
    let s = TensorSurface::bspline([2, 2], [ku, kv], [9, 5], pts, Some(w)).unwrap();
    Model::Surface(SurfaceModel::new(SplineForm::BSpline, s, samples).unwrap())
}

/// Cylinder of radius r and height h: the circle times a line.
fn cylinder(r: f64, h: f64, samples: [usize; 2]) -> Model {
    let (ku, cu, wu) = circle();
    let mut pts = Vec::new();
    let mut w = Vec::new();
    for (i, &(x, y)) in cu.iter().enumerate() {
        for z in [0.0, h] {
            pts.push(DVec3::new(x * r, y * r, z));
            w.push(wu[i]);
        }
    }
    let kv = vec![0.0, 0.0, 1.0, 1.0];
    let s = TensorSurface::bspline([2, 1], [ku, kv], [9, 2], pts, Some(w)).unwrap();
    Model::Surface(SurfaceModel::new(SplineForm::BSpline, s, samples).unwrap())
}

fn curvatures(obj: &SampledObject) -> &[[f64; 2]] {
    obj.grid()
        .curvatures
        .as_deref()
        .expect("analysis grids keep curvatures")
}

/// Largest deviation of K and |H| from the expected values, and of the principal curvatures
/// scaled down by `kappa_slack` (κ = H ± √(H² − K) takes a square root of rounding at
/// umbilics: a sphere's 1e-16 becomes 1e-8), relative to the expected scale; NaN anywhere
/// counts as infinitely wrong.
fn worst(obj: &SampledObject, k: f64, h_abs: f64, kappa_abs: [f64; 2]) -> f64 {
    let kappa_slack = 1e-5;
    let scale = k.abs().max(h_abs).max(1e-300);
    curvatures(obj)
        .iter()
        .map(|&kh| {
            let [kmax, kmin] = principal(kh);
            let mut kappa = [kmax.abs(), kmin.abs()];
            kappa.sort_by(|a, b| b.total_cmp(a));
            let e = [
                (kh[0] - k).abs(),
                (kh[1].abs() - h_abs).abs(),
                (kappa[0] - kappa_abs[0]).abs() * kappa_slack,
                (kappa[1] - kappa_abs[1]).abs() * kappa_slack,
            ];
            e.iter()
                .map(|&x| if x.is_nan() { f64::INFINITY } else { x })
                .fold(0.0, f64::max)
                / scale
        })
        .fold(0.0, f64::max)
}

#[test]
fn sphere_and_cylinder_have_their_analytic_curvatures() {
    for r in [0.5, 1.0, 3.0] {
        let obj = SampledObject::new(&sphere(r, [41, 23]), SampleMode::Analysis);
        let e = worst(&obj, 1.0 / (r * r), 1.0 / r, [1.0 / r; 2]);
        // Poles included: their samples take the curvature next to the collapsed row.
        assert!(e < 1e-9, "sphere r = {r}: {e:e}");
        let inner: f64 = {
            let [mu, mv] = obj.grid().dims;
            let c = curvatures(&obj);
            (0..mu)
                .flat_map(|i| (1..mv - 1).map(move |j| (i, j)))
                .map(|(i, j)| {
                    let [k, h] = c[i * mv + j];
                    ((k * r * r - 1.0).abs()).max((h.abs() * r - 1.0).abs())
                })
                .fold(0.0, f64::max)
        };
        assert!(inner < 1e-12, "sphere r = {r} off the poles: {inner:e}");
        let obj = SampledObject::new(&cylinder(r, 2.0, [33, 9]), SampleMode::Analysis);
        let e = worst(&obj, 0.0, 0.5 / r, [1.0 / r, 0.0]);
        assert!(e < 1e-13, "cylinder r = {r}: {e:e}");
    }
    // The sign of H follows the orientation Su × Sv: outward on this sphere, so H = −1/r.
    let obj = SampledObject::new(&sphere(2.0, [9, 9]), SampleMode::Analysis);
    assert!(curvatures(&obj)[4 * 9 + 4][1] < 0.0);
}

#[test]
fn the_curvature_check_fails_on_a_wrong_radius() {
    let obj = SampledObject::new(&sphere(1.0, [21, 11]), SampleMode::Analysis);
    assert!(worst(&obj, 1.0, 1.0, [1.0; 2]) < 1e-9);
    assert!(worst(&obj, 1.0 / (1.0 + 1e-7), 1.0, [1.0; 2]) > 5e-8);
    assert!(worst(&obj, 1.0, 1.0 + 1e-7, [1.0; 2]) > 5e-8);
    assert!(worst(&obj, 1.0, 1.0, [1.0, 0.99]) > 5e-8);
    let cyl = SampledObject::new(&cylinder(1.0, 1.0, [9, 9]), SampleMode::Analysis);
    assert!(worst(&cyl, 0.0, 0.5, [1.0, 0.0]) < 1e-12);
    assert!(worst(&cyl, 0.0, 0.5, [1.0, 1e-4]) > 1e-10);
    assert!(worst(&cyl, 1e-9, 0.5, [1.0, 0.0]) > 1e-10);
}

/// K and H from exact partials (the geometry layer's own evaluator and formula).
fn exact_curvatures(model: &Model) -> Vec<[f64; 2]> {
    let Model::Surface(m) = model else { panic!() };
    let g = exact_grid(model.as_ref(), &PartialSet::Curvature);
    let [mu, mv] = g.dims;
    let (pu, pv) = (
        prespline::geom::knots::uniform_params(0.0, 1.0, mu),
        prespline::geom::knots::uniform_params(0.0, 1.0, mv),
    );
    let mut out = Vec::with_capacity(mu * mv);
    for &u in &pu {
        for &v in &pv {
            let (k, h) = m.surface().curvatures(u, v).unwrap_or((f64::NAN, f64::NAN));
            out.push([k, h]);
        }
    }
    out
}

#[test]
fn analysis_delta_path_equals_full_evaluation_after_random_edits() {
    let mut rng = Rng::new(2024);
    for (degree, rational) in [
        ([3, 3], false),
        ([2, 3], false),
        ([1, 2], false),
        ([3, 2], true),
    ] {
        let n = [7, 8];
        let count = n[0] * n[1];
        let pts = (0..count)
            .map(|k| {
                DVec3::new(
                    (k / n[1]) as f64,
                    (k % n[1]) as f64,
                    rng.f32(-1.0, 1.0) as f64,
                )
            })
            .collect();
        let weights = rational.then(|| (0..count).map(|_| rng.f32(0.5, 2.0) as f64).collect());
        let knots = [0, 1].map(|d| {
            prespline::geom::KnotVector::clamped_uniform(degree[d], n[d], 0.0, 1.0).into_vec()
        });
        let s = TensorSurface::bspline(degree, knots, n, pts, weights).unwrap();
        let model = Model::Surface(SurfaceModel::new(SplineForm::BSpline, s, [37, 29]).unwrap());
        let mut obj = SampledObject::new(&model, SampleMode::Analysis);
        obj.set_rebuild_interval(None);
        let mut reference = model.clone();
        for _ in 0..2000 {
            let point = [rng.range(0, n[0]), rng.range(0, n[1])];
            let delta = DVec3::new(
                rng.f32(-0.1, 0.1) as f64,
                rng.f32(-0.1, 0.1) as f64,
                rng.f32(-0.1, 0.1) as f64,
            );
            let e = SurfaceEdit::Point(PointEdit::Move { point, delta }).into_object();
            obj.apply(&e).unwrap();
            reference.apply(&e).unwrap();
        }
        let exact = exact_grid(reference.as_ref(), &PartialSet::Curvature);
        let d = obj.grid().max_relative_difference(&exact);
        assert!(d < 1e-12, "{degree:?} rational {rational}: partials {d:e}");
        let want = exact_curvatures(&reference);
        let got = curvatures(&obj);
        let scale = want
            .iter()
            .flat_map(|kh| kh.iter())
            .filter(|x| x.is_finite())
            .fold(1e-300f64, |m, x| m.max(x.abs()));
        for (s, (a, b)) in got.iter().zip(&want).enumerate() {
            for c in 0..2 {
                let e = (a[c] - b[c]).abs() / scale;
                assert!(
                    e < 1e-9,
                    "{degree:?}: sample {s} [K, H][{c}] {} vs {}",
                    a[c],
                    b[c]
                );
            }
        }
    }
}

/// The saddle z = (x + 1)(y + 1) over [0, 1]², tilted and moved by a rigid motion, as a bicubic
/// Bézier patch (a bilinear function's control points are its values at the Greville points
/// i/3, j/3). F = Su·Sv and M = Suv·n are nonzero everywhere, so every term of K and H counts.
fn tilted_saddle(samples: [usize; 2]) -> (Model, glam::DMat3) {
    let rot = glam::DMat3::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7);
    let shift = DVec3::new(0.3, -1.2, 2.5);
    let pts = (0..16)
        .map(|k| {
            let (x, y) = ((k / 4) as f64 / 3.0, (k % 4) as f64 / 3.0);
            rot * DVec3::new(x, y, (x + 1.0) * (y + 1.0)) + shift
        })
        .collect();
    let s = TensorSurface::bezier([4, 4], pts, None).unwrap();
    let m = Model::Surface(SurfaceModel::new(SplineForm::Bezier, s, samples).unwrap());
    (m, rot)
}

/// K and H of the graph z = f(x, y), f = (x + 1)(y + 1), with the upward normal Su × Sv (a
/// rigid motion changes neither): with W² = 1 + f_x² + f_y², K = −f_xy² / W⁴ and
/// H = −f_x f_y f_xy / W³.
fn saddle_curvatures(u: f64, v: f64, h_factor: f64) -> [f64; 2] {
    let (fx, fy) = (v + 1.0, u + 1.0);
    let w2 = 1.0 + fx * fx + fy * fy;
    [-1.0 / (w2 * w2), -h_factor * fx * fy / (w2 * w2.sqrt())]
}

/// Largest relative error of every sample's [K, H] against the saddle's (NaN: infinite).
fn saddle_error(obj: &SampledObject, h_factor: f64) -> f64 {
    let params = obj.params();
    let mv = params[1].len();
    curvatures(obj)
        .iter()
        .enumerate()
        .map(|(s, kh)| {
            let want = saddle_curvatures(params[0][s / mv], params[1][s % mv], h_factor);
            (0..2)
                .map(|c| (kh[c] - want[c]).abs() / want[c].abs())
                .map(|e| if e.is_nan() { f64::INFINITY } else { e })
                .fold(0.0, f64::max)
        })
        .fold(0.0, f64::max)
}

#[test]
fn a_tilted_saddle_has_its_analytic_curvatures_in_the_full_and_the_delta_path() {
    let (model, rot) = tilted_saddle([37, 23]);
    let mut obj = SampledObject::new(&model, SampleMode::Analysis);
    let full = saddle_error(&obj, 1.0);
    assert!(full < 1e-13, "full pass: {full:e}");
    // Negative control: the check sees a mean curvature missing its 2·F·M term's half.
    assert!(saddle_error(&obj, 0.5) > 0.4);
    // The delta path's kernel recomputes K and H of every touched sample: move an interior
    // point out of the plane and back (the samples return to within rounding).
    obj.set_rebuild_interval(None);
    for (point, sign) in [([1, 2], 1.0), ([1, 2], -1.0), ([2, 1], 1.0), ([2, 1], -1.0)] {
        let delta = rot * DVec3::new(0.0, 0.0, 0.25 * sign);
        let e = SurfaceEdit::Point(PointEdit::Move { point, delta }).into_object();
        let region = obj.apply(&e).unwrap();
        assert_eq!(
            region.samples(),
            37 * 23,
            "a Bézier point touches every sample"
        );
    }
    let delta = saddle_error(&obj, 1.0);
    assert!(delta < 1e-12, "delta path: {delta:e}");
}

/// A scene file's objects with every point moved by `dx` in x and the names renamed by `name`.
fn moved(
    scene: &serde_json::Value,
    dx: f64,
    name: impl Fn(&str) -> String,
) -> Vec<serde_json::Value> {
    fn shift(v: &mut serde_json::Value, dx: f64) {
        match v {
            serde_json::Value::Array(a) if a.len() == 3 && a.iter().all(|c| c.is_number()) => {
                a[0] = serde_json::json!(a[0].as_f64().unwrap() + dx);
            }
            serde_json::Value::Array(a) => a.iter_mut().for_each(|x| shift(x, dx)),
            _ => {}
        }
    }
    scene["objects"]
        .as_array()
        .unwrap()
        .iter()
        .map(|o| {
            let mut o = o.clone();
            shift(&mut o["points"], dx);
            o["name"] = serde_json::json!(name(o["name"].as_str().unwrap()));
            o
        })
        .collect()
}

/// Curvature-map families (`--map-range per-object`): the teapot's 32 patches, which touch
/// one another, are one family named `teapot`; a second teapot numbered on (`teapot_32` …
/// `teapot_63`) but placed apart is a family of its own, both then named by their first and
/// last patch; surfaces numbered alike but apart (Blender's `Surface.001`, OBJ's `surface`,
/// `surface.2`) are one family each.
#[test]
fn surface_families_are_numbered_names_that_touch() {
    use prespline::render::maps::surface_families;
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/teapot.json");
    let teapot: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let families = |objects: Vec<serde_json::Value>| {
        let text = serde_json::json!({ "objects": objects }).to_string();
        let scene = prespline::formats::parse_scene(&text).unwrap();
        surface_families(&common::editor(&scene, None).into_document())
    };
    let one = families(moved(&teapot, 0.0, str::to_string));
    assert_eq!(one, [("teapot".to_string(), (0..32).collect::<Vec<_>>())]);

    let renumber = |n: &str| {
        format!(
            "teapot_{}",
            n["teapot_".len()..].parse::<usize>().unwrap() + 32
        )
    };
    let mut two = moved(&teapot, 0.0, str::to_string);
    two.extend(moved(&teapot, 10.0, renumber));
    assert_eq!(
        families(two),
        [
            (
                "teapot_00…teapot_31".to_string(),
                (0..32).collect::<Vec<_>>()
            ),
            ("teapot_32…teapot_63".to_string(), (32..64).collect()),
        ]
    );
    // Negative control: the second teapot moved onto the first joins it.
    let mut overlapping = moved(&teapot, 0.0, str::to_string);
    overlapping.extend(moved(&teapot, 0.5, renumber));
    assert_eq!(families(overlapping).len(), 1);

    let patch = &teapot["objects"][0];
    let apart = |names: &[&str]| -> Vec<serde_json::Value> {
        names
            .iter()
            .enumerate()
            .flat_map(|(k, n)| {
                let one = serde_json::json!({ "objects": [patch] });
                moved(&one, 5.0 * k as f64, |_| (*n).to_string())
            })
            .collect()
    };
    for names in [
        &["Surface.001", "Surface.002", "Surface.003"][..],
        &["surface", "surface.2", "surface.3"],
    ] {
        let got = families(apart(names));
        let want: Vec<(String, Vec<usize>)> = names
            .iter()
            .enumerate()
            .map(|(k, n)| (n.to_string(), vec![k]))
            .collect();
        assert_eq!(got, want);
    }
}

/// Families that do not start at object 0: a curve and a lone patch come first, then the
/// teapot's 32 touching patches, then the teapot scaled up four times (its curvature a
/// sixteenth) under other names. Every member's per-object range is its own family's, computed
/// here from the members' values, so mixing family and object indices cannot pass; the
/// negative control is the shared scale, which gives the big teapot the small one's range.
#[test]
fn families_after_other_objects_take_their_own_ranges() {
    use prespline::render::maps::{MapRange, SurfaceMap, map_scales, surface_families};
    use prespline::render::maps::{MapScale, symmetric_range};
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/teapot.json");
    let teapot: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let mut objects = vec![serde_json::json!({
        "name": "rail", "type": "bezier_curve",
        "points": [[0, 0, 0], [1, 2, 0], [2, 0, 0]], "samples": 20
    })];
    let lone = serde_json::json!({ "objects": [&teapot["objects"][5]] });
    objects.extend(moved(&lone, 30.0, |_| "lone".to_string()));
    objects.extend(moved(&teapot, 0.0, str::to_string));
    let mut big = moved(&teapot, 0.0, |n| n.replace("teapot", "big"));
    for o in &mut big {
        scale(&mut o["points"], 4.0);
    }
    let big = serde_json::json!({ "objects": big });
    objects.extend(moved(&big, 60.0, str::to_string));
    let text = serde_json::json!({ "objects": objects }).to_string();
    let scene = prespline::formats::parse_scene(&text).unwrap();
    let doc = common::editor(&scene, Some(SurfaceMap::Gaussian)).into_document();

    let families = surface_families(&doc);
    let want: Vec<(String, Vec<usize>)> = vec![
        ("lone".into(), vec![1]),
        ("teapot".into(), (2..34).collect()),
        ("big".into(), (34..66).collect()),
    ];
    assert_eq!(families, want);

    let values = |members: &[usize]| -> Vec<f64> {
        members
            .iter()
            .flat_map(|&i| doc.objects[i].sampled.grid().curvatures.clone().unwrap())
            .map(|kh| SurfaceMap::Gaussian.value(kh))
            .collect()
    };
    let own = map_scales(&doc, SurfaceMap::Gaussian, MapRange::PerObject);
    let shared = map_scales(&doc, SurfaceMap::Gaussian, MapRange::Shared);
    let mismatches = |scales: &[MapScale]| -> usize {
        want.iter()
            .map(|(_, members)| {
                let r = MapScale::symmetric(symmetric_range(values(members).into_iter()));
                members.iter().filter(|&&i| scales[i] != r).count()
            })
            .sum()
    };
    assert_eq!(mismatches(&own), 0, "{own:?}");
    let (small, large) = (own[2].high, own[34].high);
    assert!(small > 8.0 * large, "teapot {small}, big teapot {large}");
    assert!(
        mismatches(&shared) >= 32,
        "the shared scale is seen as wrong"
    );
}

/// Every point of a scene object's `points` scaled by `k` about the origin.
fn scale(v: &mut serde_json::Value, k: f64) {
    match v {
        serde_json::Value::Array(a) if a.len() == 3 && a.iter().all(|c| c.is_number()) => {
            for c in a.iter_mut() {
                *c = serde_json::json!(c.as_f64().unwrap() * k);
            }
        }
        serde_json::Value::Array(a) => a.iter_mut().for_each(|x| scale(x, k)),
        _ => {}
    }
}

/// Issue 34.2: families whose colour ranges are the same share one legend, named by their
/// first and last surface with the count; a family with another range keeps its own. Two
/// copies of the teapot placed apart (two families, one range) and a scaled copy (its own
/// range): two legends, not three. Negative control: the scaled one is not merged.
#[test]
fn families_with_one_range_share_a_legend() {
    use prespline::render::maps::{MapRange, SurfaceMap, map_scales, surface_families};
    use prespline::render::offscreen::legend_groups;
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/teapot.json");
    let teapot: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let mut objects = moved(&teapot, 0.0, str::to_string);
    objects.extend(moved(&teapot, 10.0, |n| n.replace("teapot", "copy")));
    let mut big = moved(&teapot, 0.0, |n| n.replace("teapot", "big"));
    for o in &mut big {
        scale(&mut o["points"], 4.0);
    }
    objects.extend(moved(
        &serde_json::json!({ "objects": big }),
        40.0,
        str::to_string,
    ));
    let text = serde_json::json!({ "objects": objects }).to_string();
    let scene = prespline::formats::parse_scene(&text).unwrap();
    let doc = common::editor(&scene, Some(SurfaceMap::Mean)).into_document();
    let families = surface_families(&doc);
    assert_eq!(families.len(), 3, "{families:?}");
    let scales = map_scales(&doc, SurfaceMap::Mean, MapRange::PerObject);
    let groups = legend_groups(&doc, &families, &scales);
    let names: Vec<(&str, usize)> = groups.iter().map(|(n, _, k)| (n.as_str(), *k)).collect();
    assert_eq!(
        names,
        [("teapot_00 … copy_31 (64 surfaces)", 64), ("big", 32)]
    );
    assert_ne!(groups[0].1, groups[1].1);
}
