//! Wavefront OBJ round trips, bit for bit: JSON → OBJ → JSON for every object type that maps
//! (examples and random scenes with extreme numbers), OBJ → JSON → OBJ for prespline's own
//! form and for hand-written files (control data unchanged), and the exact B-spline export of
//! ERBS objects against the ERBS evaluator.

use crate::common;

use common::Rng;
use glam::DVec3;
use prespline::formats::json::scene_to_json;
use prespline::formats::obj::model::{Basis, FreeForm};
use prespline::formats::obj::{parse_obj, read_elements, scene_to_obj};
use prespline::formats::parse_scene;
use prespline::geom::{BFunctionKind, BSplineCurve, ErbsCurve, ErbsSurface, TensorSurface};
use prespline::model::{
    CurveModel, ErbsCurveModel, ErbsSurfaceModel, Model, SplineForm, SurfaceModel,
};
use prespline::scene::{Scene, SceneObject};
use std::path::Path;

fn example(name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples")
        .join(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// JSON → OBJ → JSON, compared as JSON text (the writer prints shortest round-trip numbers,
/// so equal text means equal bits, −0.0 included) and as values.
fn assert_json_obj_json(scene: &Scene) {
    let obj = scene_to_obj(scene).expect("every Bézier/B-spline object maps to OBJ");
    let back = parse_obj(&obj).unwrap_or_else(|e| panic!("{e}\n{obj}"));
    assert!(back.warnings.is_empty(), "{:?}", back.warnings);
    assert_eq!(scene_to_json(&back.scene), scene_to_json(scene));
    assert_eq!(&back.scene, scene);
}

#[test]
fn examples_json_obj_json_are_exact() {
    for name in [
        "bezier_curve.json",
        "bspline_curve.json",
        "nurbs_circle.json",
        "bezier_surface.json",
        "bspline_surface.json",
        "surface_100x100.json",
        "teapot.json",
    ] {
        let scene = parse_scene(&example(name)).unwrap();
        assert_json_obj_json(&scene);
    }
}

/// Finite numbers of every magnitude, subnormals and −0.0 included.
fn number(rng: &mut Rng) -> f64 {
    match rng.range(0, 6) {
        0 => loop {
            let x = f64::from_bits(rng.next_u64());
            if x.is_finite() {
                break x;
            }
        },
        1 => -0.0,
        2 => f64::from_bits(rng.range(1, 1 << 20) as u64), // subnormal
        3 => (rng.range(0, 2001) as f64 - 1000.0) / 7.0,
        _ => (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64 * 10.0 - 5.0,
    }
}

fn points(rng: &mut Rng, n: usize) -> Vec<DVec3> {
    (0..n)
        .map(|_| DVec3::new(number(rng), number(rng), number(rng)))
        .collect()
}

fn weights(rng: &mut Rng, n: usize) -> Option<Vec<f64>> {
    (rng.range(0, 2) == 1).then(|| {
        (0..n)
            .map(|_| match rng.range(0, 4) {
                0 => 1.0,
                1 => f64::from_bits(rng.range(1, 1 << 30) as u64), // tiny but positive
                _ => (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64 * 3.0 + 1e-3,
            })
            .collect()
    })
}

/// n + d + 1 non-decreasing knots with repeats (multiplicity ≤ d + 1, non-empty domain).
fn knots(rng: &mut Rng, d: usize, n: usize) -> Vec<f64> {
    loop {
        let mut k = Vec::new();
        let mut t = number(rng).clamp(-1e6, 1e6);
        while k.len() < n + d + 1 {
            let times = rng.range(1, d + 2).min(n + d + 1 - k.len());
            k.extend(std::iter::repeat_n(t, times));
            t += [1.0, 0.1, 1e-9, 3.0][rng.range(0, 4)];
        }
        if BSplineCurve::new(d, k.clone(), vec![DVec3::ZERO; n], None).is_ok() {
            return k;
        }
    }
}

fn random_object(rng: &mut Rng, i: usize) -> SceneObject {
    let d = rng.range(1, 5);
    let n = d + 1 + rng.range(0, 5);
    let [du, dv] = [rng.range(1, 4), rng.range(1, 4)];
    let [nu, nv] = [du + 1 + rng.range(0, 3), dv + 1 + rng.range(0, 3)];
    let model = match rng.range(0, 4) {
        0 => {
            let p = points(rng, d + 1);
            let w = weights(rng, d + 1);
            let k = prespline::geom::KnotVector::bezier(d, 0.0, 1.0).into_vec();
            let c = BSplineCurve::new(d, k, p, w).unwrap();
            Model::Curve(CurveModel::new(SplineForm::Bezier, c, rng.range(2, 300)).unwrap())
        }
        1 => {
            let c =
                BSplineCurve::new(d, knots(rng, d, n), points(rng, n), weights(rng, n)).unwrap();
            Model::Curve(CurveModel::new(SplineForm::BSpline, c, rng.range(2, 300)).unwrap())
        }
        2 => {
            let m = (du + 1) * (dv + 1);
            let s =
                TensorSurface::bezier([du + 1, dv + 1], points(rng, m), weights(rng, m)).unwrap();
            Model::Surface(SurfaceModel::new(SplineForm::Bezier, s, [5, 7]).unwrap())
        }
        _ => {
            let k = [knots(rng, du, nu), knots(rng, dv, nv)];
            let m = nu * nv;
            let s = TensorSurface::bspline([du, dv], k, [nu, nv], points(rng, m), weights(rng, m))
                .unwrap();
            Model::Surface(SurfaceModel::new(SplineForm::BSpline, s, [9, 4]).unwrap())
        }
    };
    let names = ["c", "surface", "a b c", "été", "x.2", "curve"];
    SceneObject {
        name: format!("{}{i}", names[rng.range(0, names.len())]),
        model,
        color: (rng.range(0, 2) == 1).then_some([0.25, 1.0, 0.0]),
        kept: Default::default(),
        trim: None,
    }
}

#[test]
fn random_scenes_json_obj_json_are_exact() {
    let mut rng = Rng::new(0x0b1_0b1);
    for _ in 0..200 {
        let n = rng.range(1, 5);
        let scene = Scene {
            objects: (0..n).map(|i| random_object(&mut rng, i)).collect(),
        };
        assert_json_obj_json(&scene);
    }
}

/// OBJ (prespline's form) → JSON → OBJ gives the same bytes.
fn assert_obj_json_obj(obj: &str) {
    let scene = parse_obj(obj).unwrap().scene;
    let json = scene_to_json(&scene);
    let again = scene_to_obj(&parse_scene(&json).unwrap()).unwrap();
    assert_eq!(again, obj);
}

#[test]
fn prespline_obj_files_survive_json_byte_for_byte() {
    assert_obj_json_obj(&example("teapot.obj"));
    let mut rng = Rng::new(77);
    for _ in 0..50 {
        let scene = Scene {
            objects: (0..3).map(|i| random_object(&mut rng, i)).collect(),
        };
        assert_obj_json_obj(&scene_to_obj(&scene).unwrap());
    }
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

fn point_bits(v: &[DVec3]) -> Vec<[u64; 3]> {
    v.iter()
        .map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
        .collect()
}

/// The control data of two element lists agree bit for bit (Bézier elements compared through
/// their B-spline knots, since several segments come back as `bspline`).
fn assert_same_control_data(a: &[FreeForm], b: &[FreeForm]) {
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(b) {
        assert_eq!(x.rational, y.rational, "{:?}", x.name);
        assert_eq!(point_bits(&x.points), point_bits(&y.points), "{:?}", x.name);
        if x.rational {
            assert_eq!(bits(&x.weights), bits(&y.weights), "{:?}", x.name);
        }
        assert_eq!(x.dirs.len(), y.dirs.len());
        for (dx, dy) in x.dirs.iter().zip(&y.dirs) {
            assert_eq!(dx.degree, dy.degree);
            assert_eq!(dx.count, dy.count);
            assert_eq!(bits(&dx.range), bits(&dy.range));
            assert_eq!(bits(&dx.knots(x.basis)), bits(&dy.knots(y.basis)));
        }
        if x.basis == Basis::BSpline {
            assert_eq!(y.basis, Basis::BSpline);
        }
    }
}

/// A hand-written file in other writers' habits: shared vertices, relative numbers, `v/vt/vn`
/// references, continuation lines, comments, several Bézier segments, `g` names, a vertex
/// written after its element.
const HAND_WRITTEN: &str = "\
# made by hand
g patch
v 0 0 0 1
v 1 0 0.5 2
v 2 0 0
v 0 1 0.25
v 1 1 1.5 0.5
v 2 1 0
vt 0 0
vn 0 0 1
cstype rat bezier
deg 2 1
surf 0 1 0 1 1/1/1 2 3//1 4 5/1 6
parm u 0 1
parm v 0 1
end
g two segments
cstype bezier
deg 2
curv 0.0 3.5 -6 -5 -4 \\
  -3 7
parm u 0 1.25 3.5   # breakpoints of the two segments
end
o tail
cstype bspline
deg 1
curv 2 4 1 2 3 4 \\
   5 6
parm u 0 1 2 3 4 5 6 7
end
v 3 3 3
";

#[test]
fn hand_written_obj_keeps_its_control_data_through_json() {
    let (original, warnings) = read_elements(HAND_WRITTEN).unwrap();
    let lines: Vec<(usize, &str)> = warnings
        .iter()
        .map(|w| (w.line, w.message.as_str()))
        .collect();
    assert_eq!(lines.len(), 2, "{lines:?}");
    assert_eq!(lines[0].0, 4, "{lines:?}");
    assert!(lines[0].1.starts_with("weight 2 ignored"), "{lines:?}");
    assert!(lines[0].1.ends_with("(3 times, first here)"), "{lines:?}");
    assert_eq!(lines[1].0, 27, "{lines:?}");
    assert!(
        lines[1].1.contains("cut to it by knot insertion"),
        "{lines:?}"
    );
    let imported = parse_obj(HAND_WRITTEN).unwrap();
    let names: Vec<&str> = imported
        .scene
        .objects
        .iter()
        .map(|o| o.name.as_str())
        .collect();
    assert_eq!(names, ["patch", "two segments", "tail"]);
    let types: Vec<&str> = imported
        .scene
        .objects
        .iter()
        .map(|o| o.model.type_name())
        .collect();
    assert_eq!(types, ["bezier_surface", "bspline_curve", "bspline_curve"]);
    // Cut to [2, 4] of the degree-1 curve's domain [1, 6], where it passes through vertices
    // 2, 3 and 4 at the knots 2, 3 and 4.
    let Model::Curve(tail) = &imported.scene.objects[2].model else {
        unreachable!()
    };
    let tail = tail.curve();
    assert_eq!(tail.domain(), (2.0, 4.0));
    assert_eq!(tail.knots().as_slice(), [2.0, 2.0, 3.0, 4.0, 4.0]);
    let expect = [[1.0, 0.0, 0.5], [2.0, 0.0, 0.0], [0.0, 1.0, 0.25]].map(DVec3::from_array);
    assert_eq!(tail.points(), expect);

    let json = scene_to_json(&imported.scene);
    let obj = scene_to_obj(&parse_scene(&json).unwrap()).unwrap();
    let (written, _) = read_elements(&obj).unwrap();
    // The first two keep their control data exactly; the cut curve was refined on import.
    assert_same_control_data(&original[..2], &written[..2]);
    assert_eq!(written[1].basis, Basis::BSpline);
    assert_obj_json_obj(&obj);
}

#[test]
fn vase_example_keeps_its_control_data() {
    let text = example("vase.obj");
    let (original, warnings) = read_elements(&text).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    let scene = parse_obj(&text).unwrap().scene;
    let obj = scene_to_obj(&parse_scene(&scene_to_json(&scene)).unwrap()).unwrap();
    assert_same_control_data(&original, &read_elements(&obj).unwrap().0);
    assert_obj_json_obj(&obj);
}

// ---- ERBS export -------------------------------------------------------------------------

/// Relative agreement the project asks of geometry against an independent evaluator.
const TOL: f64 = 1e-12;

fn erbs_curve(bf: BFunctionKind) -> SceneObject {
    let scene = parse_scene(&example("erbs_curve.json")).unwrap();
    let mut o = scene.objects[0].clone();
    let Model::ErbsCurve(c) = &o.model else {
        panic!("erbs_curve.json holds an ERBS curve first")
    };
    let c = c.curve();
    let e = ErbsCurve::with_locals(c.knots().clone(), c.local_curves().to_vec(), bf).unwrap();
    o.model = Model::ErbsCurve(ErbsCurveModel::new(e, o.model.sample_dims()[0]).unwrap());
    o
}

fn erbs_surface(bf: BFunctionKind) -> SceneObject {
    let scene = parse_scene(&example("erbs_surface.json")).unwrap();
    let mut o = scene.objects[0].clone();
    let Model::ErbsSurface(s) = &o.model else {
        panic!("erbs_surface.json holds an ERBS surface first")
    };
    let s = s.surface();
    let e = ErbsSurface::with_locals(s.knots().clone(), s.local_patches().to_vec(), bf).unwrap();
    o.model = Model::ErbsSurface(ErbsSurfaceModel::new(e, o.model.sample_dims()).unwrap());
    o
}

/// Exports one object and reads it back.
fn exported(o: &SceneObject) -> Model {
    let obj = scene_to_obj(&Scene {
        objects: vec![o.clone()],
    })
    .unwrap();
    let back = parse_obj(&obj).unwrap().scene;
    assert_eq!(back.objects[0].model.sample_dims(), o.model.sample_dims());
    back.objects[0].model.clone()
}

/// The exported B-spline curve of an ERBS curve object.
fn exported_curve(o: &SceneObject) -> BSplineCurve {
    let Model::Curve(b) = exported(o) else {
        panic!("expected a bspline_curve")
    };
    assert_eq!(b.form(), SplineForm::BSpline);
    b.curve().clone()
}

fn params(a: f64, b: f64, n: usize) -> impl Iterator<Item = f64> {
    (0..=n).map(move |k| a + (b - a) * k as f64 / n as f64)
}

/// Worst relative difference of values and first derivatives (relative to the largest value
/// of the same order, so zero crossings do not inflate it); infinite when anything is NaN.
fn worst(pairs: &[(DVec3, DVec3)]) -> f64 {
    if pairs.iter().any(|(a, b)| !(a.is_finite() && b.is_finite())) {
        return f64::INFINITY;
    }
    let scale = pairs
        .iter()
        .map(|(a, _)| a.abs().max_element())
        .fold(0.0, f64::max);
    pairs
        .iter()
        .map(|(a, b)| (*a - *b).abs().max_element() / scale)
        .fold(0.0, f64::max)
}

#[test]
fn erbs_curves_with_polynomial_and_rational_blends_export_exactly() {
    for bf in [
        BFunctionKind::Smoothstep,
        BFunctionKind::Smootherstep,
        BFunctionKind::Rational,
    ] {
        let o = erbs_curve(bf);
        let Model::ErbsCurve(e) = &o.model else {
            unreachable!()
        };
        let e = e.curve();
        let b = exported_curve(&o);
        assert_eq!(b.is_rational(), bf == BFunctionKind::Rational);
        let (lo, hi) = e.domain();
        assert_eq!(b.domain(), (lo, hi));
        let d: Vec<_> = params(lo, hi, 997)
            .map(|t| (e.derivatives(t, 1), b.derivatives(t, 1)))
            .collect();
        let values: Vec<_> = d.iter().map(|(x, y)| (x[0], y[0])).collect();
        let firsts: Vec<_> = d.iter().map(|(x, y)| (x[1], y[1])).collect();
        let (ev, ed) = (worst(&values), worst(&firsts));
        eprintln!("{bf:?} curve: values {ev:.1e}, first derivatives {ed:.1e}");
        assert!(ev <= TOL && ed <= TOL, "{bf:?}: {ev:e} {ed:e}");
    }
}

#[test]
fn erbs_surfaces_with_polynomial_and_rational_blends_export_exactly() {
    for bf in [
        BFunctionKind::Smoothstep,
        BFunctionKind::Smootherstep,
        BFunctionKind::Rational,
    ] {
        let o = erbs_surface(bf);
        let Model::ErbsSurface(e) = &o.model else {
            unreachable!()
        };
        let e = e.surface();
        let Model::Surface(b) = exported(&o) else {
            panic!("{bf:?}: expected a bspline_surface")
        };
        assert_eq!(b.form(), SplineForm::BSpline);
        let b = b.surface();
        let [(u0, u1), (v0, v1)] = e.domain();
        assert_eq!(b.domain(), e.domain());
        let mut pairs = [Vec::new(), Vec::new(), Vec::new()];
        for u in params(u0, u1, 41) {
            for v in params(v0, v1, 37) {
                let (x, y) = (e.derivatives(u, v, 1), b.derivatives(u, v, 1));
                for (k, (a, c)) in [(0, 0), (1, 0), (0, 1)].into_iter().enumerate() {
                    pairs[k].push((x.get(a, c), y.get(a, c)));
                }
            }
        }
        let w = pairs.map(|p| worst(&p));
        eprintln!(
            "{bf:?} surface: S {:.1e}, Su {:.1e}, Sv {:.1e}",
            w[0], w[1], w[2]
        );
        assert!(w.iter().all(|&x| x <= TOL), "{bf:?}: {w:?}");
    }
}

#[test]
fn erbs_without_a_rational_form_is_refused_in_one_line() {
    for bf in [BFunctionKind::ExpoRational, BFunctionKind::Trigonometric] {
        for o in [erbs_curve(bf), erbs_surface(bf)] {
            let e = scene_to_obj(&Scene {
                objects: vec![o.clone()],
            })
            .unwrap_err()
            .to_string();
            assert!(!e.contains('\n'), "{e}");
            assert!(e.starts_with(&format!("object '{}': ", o.name)), "{e}");
            assert!(e.contains("cannot be written to OBJ"), "{e}");
            assert!(e.contains("no rational B-spline equals this ERBS"), "{e}");
            assert!(e.contains(bf.name()), "{e}");
        }
    }
}

/// Negative control for the comparison: a perturbed export must fail it.
#[test]
fn the_erbs_comparison_catches_a_perturbation() {
    let o = erbs_curve(BFunctionKind::Smoothstep);
    let Model::ErbsCurve(e) = &o.model else {
        unreachable!()
    };
    let e = e.curve();
    let b = exported_curve(&o);
    let mut p = b.points().to_vec();
    let mid = p.len() / 2;
    p[mid] += DVec3::splat(1e-9);
    let bad = BSplineCurve::new(b.degree(), b.knots().to_vec(), p, None).unwrap();
    let (lo, hi) = e.domain();
    let pairs: Vec<_> = params(lo, hi, 997)
        .map(|t| (e.eval(t), bad.eval(t)))
        .collect();
    assert!(worst(&pairs) > TOL);
    let nan: Vec<_> = vec![(DVec3::ONE, DVec3::new(f64::NAN, 1.0, 1.0))];
    assert!(worst(&nan) > TOL, "NaN must not pass");
}

// ---- prespline convert -------------------------------------------------------------------

fn convert(args: &[&std::ffi::OsStr]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_prespline"))
        .arg("convert")
        .args(args)
        .output()
        .unwrap()
}

fn temp_dir(tag: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("prespline-convert-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn convert_goes_both_ways_exactly_and_applies_samples() {
    let dir = temp_dir("both");
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/nurbs_circle.json");
    let (obj, json) = (dir.join("circle.OBJ"), dir.join("circle.json"));
    for (a, b) in [(&src, &obj), (&obj, &json)] {
        let out = convert(&[a.as_os_str(), b.as_os_str()]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{err}");
        assert!(err.starts_with("wrote "), "{err}");
    }
    assert!(
        std::fs::read_to_string(&obj)
            .unwrap()
            .contains("cstype rat bspline")
    );
    let original = prespline::formats::read_json(&src).unwrap();
    assert_eq!(prespline::formats::read_json(&json).unwrap(), original);

    let out = convert(&[
        obj.as_os_str(),
        json.as_os_str(),
        "--samples".as_ref(),
        "33".as_ref(),
        "--samples".as_ref(),
        "5x6".as_ref(),
    ]);
    assert!(out.status.success());
    let resampled = prespline::formats::read_json(&json).unwrap();
    let (Model::Curve(a), Model::Curve(b)) =
        (&resampled.objects[0].model, &original.objects[0].model)
    else {
        panic!("nurbs_circle.json holds a curve")
    };
    assert_eq!(a.samples(), 33);
    assert_eq!(a.curve(), b.curve());
}

#[test]
fn convert_refuses_what_it_cannot_write_and_writes_nothing() {
    let dir = temp_dir("refuse");
    let erbs = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/erbs_curve.json");
    let obj = dir.join("erbs.obj");
    let out = convert(&[erbs.as_os_str(), obj.as_os_str()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with(&format!("error: {}: object 'erbs': ", erbs.display())),
        "{err}"
    );
    assert!(!obj.exists() && !dir.join("erbs.obj.tmp").exists());

    let txt = dir.join("scene.txt");
    let out = convert(&[erbs.as_os_str(), txt.as_os_str()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("cannot tell the format from the extension"),
        "{err}"
    );
    for bad in ["0", "1", "2x1", "x", "4x", "100000x100000"] {
        let out = convert(&[
            erbs.as_os_str(),
            obj.as_os_str(),
            "--samples".as_ref(),
            bad.as_ref(),
        ]);
        assert!(!out.status.success(), "--samples {bad}");
    }
}

/// The OBJ specification's example of trimming with special points: a Bézier curve evaluated
/// over part of its domain, a trimming curve (`curv2`), and a rational B-spline surface with a
/// trimming loop and special points.
const SPEC_TRIMMING_EXAMPLE: &str = include_str!("../data/obj_spec_special_points.obj");

#[test]
fn spec_trimming_example_reads_with_warnings_and_an_exact_cut() {
    let import = parse_obj(SPEC_TRIMMING_EXAMPLE).unwrap();
    let warned: Vec<(usize, &str)> = import
        .warnings
        .iter()
        .map(|w| (w.line, w.message.split(':').next().unwrap()))
        .collect();
    assert_eq!(
        warned,
        [
            (
                12,
                "curv range [0.2, 0.9] is part of the domain [0, 1] of parm u"
            ),
            (
                13,
                "'sp' kept for saving, not applied (special point; on the curv) (3 times, first here)"
            ),
        ],
        "{:?}",
        import.warnings
    );
    let objects = &import.scene.objects;
    assert_eq!(objects.len(), 2);
    assert_eq!(
        (objects[0].name.as_str(), objects[1].name.as_str()),
        ("curve", "surface")
    );

    // The cut curve is the Bézier curve on [0.2, 0.9], to rounding.
    let Model::Curve(cut) = &objects[0].model else {
        panic!("{:?}", objects[0].model)
    };
    assert_eq!(cut.form(), SplineForm::BSpline);
    let cut = cut.curve();
    assert_eq!(cut.domain(), (0.2, 0.9));
    let full = prespline::geom::BezierCurve::new(
        [
            [0.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [2.0, 1.0, 0.0],
            [3.0, 0.0, 0.0],
        ]
        .map(DVec3::from_array)
        .to_vec(),
    )
    .unwrap();
    let pairs: Vec<_> = params(0.2, 0.9, 200)
        .map(|t| (full.eval(t), cut.eval(t)))
        .collect();
    assert!(worst(&pairs) <= TOL, "{:e}", worst(&pairs));

    // The surface keeps its data: 3 × 3, weights from the fourth coordinates, u fastest.
    let Model::Surface(s) = &objects[1].model else {
        panic!("{:?}", objects[1].model)
    };
    let s = s.surface();
    assert_eq!(s.count(), [3, 3]);
    assert_eq!(s.domain(), [(-1.0, 2.5), (-2.0, 2.0)]);
    assert_eq!(s.point(1, 0), DVec3::new(0.130, -1.030, 0.432));
    assert_eq!(s.point(0, 1), DVec3::new(-1.460, 0.060, 0.201));
    let w = s.weights().unwrap();
    assert_eq!(w, [1.0, 1.0, 2.3, 7.6, 0.5, 6.1, 2.3, 1.5, 3.3]);
}

/// Names with `#` (CAD faces such as `bracket#1234`) and `%` survive OBJ: written as `%23` and
/// `%25`, read back as they were; a `%` that starts neither stays as written.
#[test]
fn names_with_comment_and_percent_signs_round_trip() {
    let mut scene = parse_scene(&example("bezier_curve.json")).unwrap();
    scene.objects[0].name = "bracket#1234 50% %23".into();
    let obj = scene_to_obj(&scene).unwrap();
    assert!(obj.contains("o bracket%231234 50%25 %2523\n"), "{obj}");
    assert_json_obj_json(&scene);
    // A hand-written name with a lone '%' reads as written.
    let text = obj.replace("o bracket%231234 50%25 %2523", "o 100%x");
    assert_eq!(parse_obj(&text).unwrap().scene.objects[0].name, "100%x");
    // Negative control: the encoded name read without decoding would differ.
    let raw = obj.replace("o bracket%231234 50%25 %2523", "o bracket%231234");
    assert_ne!(
        parse_obj(&raw).unwrap().scene.objects[0].name,
        "bracket%231234"
    );
}
