//! Hierarchical ERBS (issue 11) through the real code paths: construction from a source
//! (`from`), local refinement (`insert_knot`), nesting and closed ERBS, each against the
//! independent evaluator in `tests/oracle/erbs_tree.rs`; old knots unchanged and the new local
//! addressable; delta equals full at depth ≥ 3; seams as smooth as the B-function; one-line CLI
//! errors.

use crate::common;
use crate::oracle;

use common::Scratch;
use glam::DVec3;
use oracle::erbs_tree::{Curve, Surface};
use oracle::eval::Point3;
use oracle::rng::Rng;
use oracle::scene::Object;
use prespline::formats::parse_scene;
use prespline::geom::erbs::{ErbsCurve, ErbsSurface, LocalCurve, LocalPatch, MAX_NESTING};
use prespline::model::SampledObject;
use prespline::sampling::SampleMode;
use prespline::scene::{Model, Scene, parse_edits};
use serde_json::{Value, json};
use std::process::Command;

/// Geometry agrees with the independent evaluator to this, relative to each derivative order's
/// own magnitude over the compared samples (the 1e-12 claim of docs/testing.md).
const TOL: f64 = 1e-12;
/// The delta path equals full re-sampling to this (docs/testing.md, tests/cpu/delta_vs_full.rs).
const DELTA_TOL: f64 = 1e-13;

// --- running the product ----------------------------------------------------------------------

/// `prespline sample` (with `--derivatives n`, optional edits, optionally `--full`).
fn sample_cli(scene: &Value, edits: Option<&Value>, n: usize, full: bool) -> Value {
    let (ok, stdout, stderr) =
        run_sample(&scene.to_string(), edits.map(|e| e.to_string()), n, full);
    assert!(ok, "sample failed: {stderr}");
    serde_json::from_str(&stdout).expect("sample prints JSON")
}

fn run_sample(scene: &str, edits: Option<String>, n: usize, full: bool) -> (bool, String, String) {
    let dir = Scratch::new("erbs-hierarchy");
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_prespline"));
    cmd.arg("sample")
        .arg(dir.file("scene.json", scene))
        .args(["--derivatives", &n.to_string()]);
    if let Some(e) = edits {
        cmd.arg("--edits").arg(dir.file("edits.json", &e));
    }
    if full {
        cmd.arg("--full");
    }
    let out = cmd.output().unwrap();
    (
        out.status.success(),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

fn nums(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

fn p3(v: &Value) -> Point3 {
    let x = nums(v);
    [x[0], x[1], x[2]]
}

/// A curve's `sample` output: parameters and samples[j][r].
fn curve_output(out: &Value, k: usize) -> (Vec<f64>, Vec<Vec<Point3>>) {
    let o = &out["objects"][k];
    let samples = o["samples"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_array().unwrap().iter().map(p3).collect())
        .collect();
    (nums(&o["params"]), samples)
}

/// A surface's `sample` output: parameters per direction and samples[i][j] flattened to
/// per-sample lists of partials [a·(N+1) + b].
fn surface_output(out: &Value, k: usize) -> ([Vec<f64>; 2], Vec<Vec<Point3>>) {
    let o = &out["objects"][k];
    let params = [nums(&o["params"][0]), nums(&o["params"][1])];
    let mut samples = Vec::new();
    for row in o["samples"].as_array().unwrap() {
        for s in row.as_array().unwrap() {
            let mut flat = Vec::new();
            for a in s.as_array().unwrap() {
                for b in a.as_array().unwrap() {
                    flat.push(p3(b));
                }
            }
            samples.push(flat);
        }
    }
    (params, samples)
}

fn flatten(partials: Vec<Vec<Point3>>) -> Vec<Point3> {
    partials.into_iter().flatten().collect()
}

// --- comparison --------------------------------------------------------------------------------

/// Largest |x − y| over all samples, per slot (derivative order), relative to that slot's
/// largest oracle magnitude (no floor; a slot that vanishes identically is measured against
/// the position magnitude). NaN on either side gives NaN, which no tolerance passes.
fn max_relative_error(product: &[Vec<Point3>], oracle: &[Vec<Point3>]) -> f64 {
    max_error_against(product, oracle, &slot_scales(oracle))
}

/// Per slot, the largest |coordinate| over `samples` (NaN if any is NaN).
fn slot_scales(samples: &[Vec<Point3>]) -> Vec<f64> {
    let slots = samples[0].len();
    let mag = |p: &Point3| p.iter().fold(0.0f64, |m, x| nan_max(m, x.abs()));
    let mut scale = vec![0.0f64; slots];
    for s in samples {
        assert_eq!(s.len(), slots);
        for (k, p) in s.iter().enumerate() {
            scale[k] = nan_max(scale[k], mag(p));
        }
    }
    scale
}

/// [`max_relative_error`] against given per-slot scales: point checks (Hermite conditions at
/// knots, seams) are measured against each order's magnitude over the whole object, as
/// tests/oracle/compare.rs does, not against the value at that one point.
fn max_error_against(product: &[Vec<Point3>], oracle: &[Vec<Point3>], scale: &[f64]) -> f64 {
    assert_eq!(product.len(), oracle.len(), "sample counts");
    let slots = scale.len();
    let position = scale[0];
    let mut worst = 0.0f64;
    for (x, y) in product.iter().zip(oracle) {
        assert_eq!(x.len(), slots, "derivative slots");
        for k in 0..slots {
            let s = if scale[k] == 0.0 { position } else { scale[k] };
            for c in 0..3 {
                let e = (x[k][c] - y[k][c]).abs() / s;
                worst = nan_max(worst, e);
            }
        }
    }
    worst
}

fn nan_max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}

/// Passes when the error is a number within `tol` (NaN fails).
fn agrees(product: &[Vec<Point3>], oracle: &[Vec<Point3>], tol: f64) -> Result<f64, f64> {
    let e = max_relative_error(product, oracle);
    if e <= tol { Ok(e) } else { Err(e) }
}

fn assert_agrees(what: &str, product: &[Vec<Point3>], oracle: &[Vec<Point3>], tol: f64) {
    if let Err(e) = agrees(product, oracle, tol) {
        panic!("{what}: relative error {e:e} > {tol:e}");
    }
}

/// [`agrees`] against the object's per-order scales.
fn agrees_at(
    product: &[Vec<Point3>],
    oracle: &[Vec<Point3>],
    scale: &[f64],
    tol: f64,
) -> Result<f64, f64> {
    let e = max_error_against(product, oracle, scale);
    if e <= tol { Ok(e) } else { Err(e) }
}

fn assert_agrees_at(
    what: &str,
    product: &[Vec<Point3>],
    oracle: &[Vec<Point3>],
    scale: &[f64],
    tol: f64,
) {
    if let Err(e) = agrees_at(product, oracle, scale, tol) {
        panic!("{what}: relative error {e:e} > {tol:e} (scales {scale:?})");
    }
}

/// Per-order magnitudes of an oracle curve over its window (401 parameters and its knots).
fn curve_scales(c: &Curve, n: usize) -> Vec<f64> {
    let (a, b) = c.dir.window;
    let mut ts: Vec<f64> = (0..=400).map(|j| a + (b - a) * j as f64 / 400.0).collect();
    ts.extend(&c.dir.knots);
    slot_scales(&oracle_curve_samples(c, &ts, n))
}

/// Per-slot magnitudes of an oracle surface over a 61 × 61 grid of its window.
fn surface_scales(s: &Surface, n: usize) -> Vec<f64> {
    let grid = |(a, b): (f64, f64)| (0..=60).map(|j| a + (b - a) * j as f64 / 60.0).collect();
    slot_scales(&oracle_surface_samples(
        s,
        &[grid(s.dirs[0].window), grid(s.dirs[1].window)],
        n,
    ))
}

/// Keeps the slots a ≤ d[0], b ≤ d[1] of a flattened [a·(top+1) + b] list.
fn interpolated_slots<T: Clone>(x: &[T], top: usize, d: [usize; 2]) -> Vec<T> {
    x.iter()
        .enumerate()
        .filter(|(i, _)| i / (top + 1) <= d[0] && i % (top + 1) <= d[1])
        .map(|(_, p)| p.clone())
        .collect()
}

fn oracle_curve_samples(c: &Curve, params: &[f64], n: usize) -> Vec<Vec<Point3>> {
    params.iter().map(|&t| c.derivatives(t, n)).collect()
}

fn oracle_surface_samples(s: &Surface, params: &[Vec<f64>; 2], n: usize) -> Vec<Vec<Point3>> {
    let mut out = Vec::new();
    for &u in &params[0] {
        for &v in &params[1] {
            out.push(flatten(s.derivatives(u, v, n)));
        }
    }
    out
}

// --- the product's models ----------------------------------------------------------------------

fn scene_of(obj: &Value) -> Value {
    json!({"objects": [obj]})
}

/// The product's model after `edits` (through its own parser and edit application).
fn product_model(scene: &Value, edits: &Value) -> Scene {
    let mut s = parse_scene(&scene.to_string()).expect("valid scene");
    let e = parse_edits(&edits.to_string(), &s).expect("valid edits");
    prespline::scene::edit::apply_all(&mut s, &e).expect("edits apply");
    s
}

fn erbs_curve(s: &Scene) -> &ErbsCurve {
    match &s.objects[0].model {
        Model::ErbsCurve(m) => m.curve(),
        _ => panic!("not an ERBS curve"),
    }
}

fn erbs_surface(s: &Scene) -> &ErbsSurface {
    match &s.objects[0].model {
        Model::ErbsSurface(m) => m.surface(),
        _ => panic!("not an ERBS surface"),
    }
}

fn v3(p: DVec3) -> Point3 {
    [p.x, p.y, p.z]
}

fn product_curve_derivs(c: &ErbsCurve, t: f64, n: usize) -> Vec<Point3> {
    c.derivatives(t, n).into_iter().map(v3).collect()
}

/// Partials a ≤ n, b ≤ n flattened [a·(n+1) + b].
fn product_surface_derivs(s: &ErbsSurface, u: f64, v: f64, n: usize) -> Vec<Point3> {
    let p = s.derivatives(u, v, n);
    let mut out = Vec::new();
    for a in 0..=n {
        for b in 0..=n {
            out.push(v3(p.get(a, b)));
        }
    }
    out
}

// --- sources -----------------------------------------------------------------------------------

fn bspline_curve_source(rational: bool) -> Value {
    let mut s = json!({
        "type": "bspline_curve", "degree": 3,
        "knots": [-1, -1, -1, -1, -0.2, 0.5, 1.1, 2, 2, 2, 2],
        "points": [[0, 0, 0], [1, 2, 0.5], [2, -1, 1], [3, 1.5, 0], [4, 0, 2], [5, 1, -1], [6, 2, 0]]
    });
    if rational {
        s["weights"] = json!([1, 2, 0.5, 1, 1.5, 0.8, 1]);
    }
    s
}

fn bezier_curve_source() -> Value {
    json!({"type": "bezier_curve", "points": [[0, 0, 0], [1, 3, 0], [3, -1, 2], [4, 1, 0], [5, 0, 1]],
           "weights": [1, 0.5, 2, 1, 1.25]})
}

fn bspline_surface_source(rational: bool) -> Value {
    let pts: Vec<Vec<[f64; 3]>> = (0..5)
        .map(|i| {
            (0..4)
                .map(|j| {
                    let (x, y) = (i as f64, j as f64);
                    [
                        x,
                        y,
                        (0.7 * x).sin() + 0.3 * (x - y) * (x - y) * 0.1 + 0.2 * y,
                    ]
                })
                .collect()
        })
        .collect();
    let mut s = json!({
        "type": "bspline_surface", "degree": [3, 2],
        "knots": [[0, 0, 0, 0, 0.4, 1, 1, 1, 1], [0, 0, 0, 0.6, 2, 2, 2]],
        "points": pts
    });
    if rational {
        s["weights"] = json!([
            [1, 1.2, 0.9, 1],
            [0.8, 1.5, 1, 1.1],
            [1, 2, 0.7, 1],
            [1.3, 1, 1, 0.6],
            [1, 0.9, 1.4, 1]
        ]);
    }
    s
}

fn source_object(src: &Value, samples: Value) -> Object {
    let mut o = src.as_object().unwrap().clone();
    o.insert("name".into(), json!("source"));
    o.insert("samples".into(), samples);
    Object::from_json(&Value::Object(o)).unwrap()
}

// --- 1a. construction ----------------------------------------------------------------------------

fn constructed_curve(source: &Value, n: usize, d: usize, closed: bool, m: usize) -> Value {
    json!({"name": "e", "type": "erbs_curve", "from": source, "local_curves": n,
           "local_degree": d, "closed": closed, "samples": m})
}

/// The whole sampled curve against the oracle's own construction, and the Hermite conditions
/// at every knot against the source itself (derivatives 0..=d equal; the oracle's source
/// evaluator, quotient rule for rational sources).
#[test]
fn construction_of_curves_matches_the_oracle_and_the_source_at_knots() {
    let sources = [
        ("polynomial B-spline", bspline_curve_source(false)),
        ("rational B-spline", bspline_curve_source(true)),
        ("rational Bézier", bezier_curve_source()),
    ];
    for (what, src) in &sources {
        for closed in [false, true] {
            for (n, d) in [(4, 3), (6, 2), (5, 5)] {
                let obj = constructed_curve(src, n, d, closed, 41);
                let scene = scene_of(&obj);
                let out = sample_cli(&scene, None, 4, false);
                let (params, product) = curve_output(&out, 0);
                let oracle = Curve::from_json(&obj);
                let label = format!("{what} closed={closed} n={n} d={d}");
                assert_agrees(
                    &label,
                    &product,
                    &oracle_curve_samples(&oracle, &params, 4),
                    TOL,
                );

                let model = product_model(&scene, &json!([]));
                let c = erbs_curve(&model);
                let source = source_object(src, json!(2));
                assert_eq!(c.knots().locals(), n);
                let knots: Vec<f64> = (0..n).map(|l| c.knots().centre(l)).collect();
                let at_knots: Vec<Vec<Point3>> = knots
                    .iter()
                    .map(|&t| product_curve_derivs(c, t, d))
                    .collect();
                let want: Vec<Vec<Point3>> = knots
                    .iter()
                    .map(|&t| source.curve_derivatives(t, d))
                    .collect();
                assert_agrees_at(
                    &format!("{label}: Hermite at knots"),
                    &at_knots,
                    &want,
                    &curve_scales(&oracle, d),
                    TOL,
                );
            }
        }
    }
}

fn constructed_surface(source: &Value, n: [usize; 2], d: [usize; 2], closed: [bool; 2]) -> Value {
    json!({"name": "s", "type": "erbs_surface", "from": source, "local_patches": n,
           "local_degree": d, "closed": closed, "samples": [13, 11]})
}

#[test]
fn construction_of_surfaces_matches_the_oracle_and_the_source_at_knots() {
    for rational in [false, true] {
        let src = bspline_surface_source(rational);
        for closed in [[false, false], [true, false], [true, true]] {
            for (n, d) in [([4, 3], [3, 2]), ([3, 5], [2, 3])] {
                let obj = constructed_surface(&src, n, d, closed);
                let scene = scene_of(&obj);
                let out = sample_cli(&scene, None, 3, false);
                let (params, product) = surface_output(&out, 0);
                let oracle = Surface::from_json(&obj);
                let label = format!("rational={rational} closed={closed:?} n={n:?} d={d:?}");
                assert_agrees(
                    &label,
                    &product,
                    &oracle_surface_samples(&oracle, &params, 3),
                    TOL,
                );

                let model = product_model(&scene, &json!([]));
                let s = erbs_surface(&model);
                let source = source_object(&src, json!([2, 2]));
                let top = d[0].max(d[1]);
                let (mut got, mut want) = (Vec::new(), Vec::new());
                for k in 0..n[0] {
                    for l in 0..n[1] {
                        let (u, v) = (s.knots()[0].centre(k), s.knots()[1].centre(l));
                        let p = product_surface_derivs(s, u, v, top);
                        let q = flatten(source.surface_derivatives(u, v, top));
                        // Only ∂^{a+b} with a ≤ du and b ≤ dv are interpolated.
                        got.push(interpolated_slots(&p, top, d));
                        want.push(interpolated_slots(&q, top, d));
                    }
                }
                let scales = interpolated_slots(&surface_scales(&oracle, top), top, d);
                assert_agrees_at(
                    &format!("{label}: Hermite at knots"),
                    &got,
                    &want,
                    &scales,
                    TOL,
                );
            }
        }
    }
}

// --- 1a. refinement ------------------------------------------------------------------------------

/// Refines through `sample --edits` and checks the whole curve against the oracle's own
/// refinement; then, on the product's refined model: the new knot keeps derivatives 0..=d of
/// the curve before, every old knot keeps value and all derivatives (up to order 6) it had.
#[test]
fn refinement_of_curves_keeps_hermite_conditions() {
    for (what, src) in [
        ("polynomial", bspline_curve_source(false)),
        ("rational", bspline_curve_source(true)),
    ] {
        for closed in [false, true] {
            let obj = constructed_curve(&src, 5, 3, closed, 57);
            let scene = scene_of(&obj);
            let before = Curve::from_json(&obj);
            let (a, b) = before.dir.window;
            // Three refinements: default degree, explicit degrees, one in the last interval
            // (for a closed curve that one wraps to local 0).
            let ts = [
                (a + 0.31 * (b - a), None),
                (a + 0.05 * (b - a), Some(5)),
                (b - 0.02 * (b - a), Some(2)),
            ];
            let mut oracle = before.clone();
            let mut edits = Vec::new();
            for &(t, d) in &ts {
                let old = oracle.clone();
                let (refined, new) = oracle.insert_knot(t, d).unwrap();
                let mut e = json!({"object": "e", "insert_knot": t});
                if let Some(d) = d {
                    e["degree"] = json!(d);
                }
                edits.push(e);
                let model = product_model(&scene, &Value::Array(edits.clone()));
                let c = erbs_curve(&model);
                let label = format!("{what} closed={closed} t={t}");
                assert_eq!(
                    c.knots().as_slice(),
                    refined.dir.knots.as_slice(),
                    "{label}"
                );
                assert_eq!(c.knots().centre(new), t, "{label}: new local's centre");
                let d = d.unwrap_or(3);
                assert_agrees_at(
                    &format!("{label}: new knot"),
                    &[product_curve_derivs(c, t, d)],
                    &[old.derivatives(t, d)],
                    &curve_scales(&old, d),
                    TOL,
                );
                let old_knots: Vec<f64> =
                    (0..old.dir.locals()).map(|l| old.dir.centre(l)).collect();
                let got: Vec<_> = old_knots
                    .iter()
                    .map(|&x| product_curve_derivs(c, x, 6))
                    .collect();
                let want: Vec<_> = old_knots.iter().map(|&x| old.derivatives(x, 6)).collect();
                let scales = curve_scales(&old, 6);
                assert_agrees_at(&format!("{label}: old knots"), &got, &want, &scales, TOL);
                oracle = refined;
            }
            let edits = Value::Array(edits);
            for full in [false, true] {
                let out = sample_cli(&scene, Some(&edits), 3, full);
                let (params, product) = curve_output(&out, 0);
                assert_agrees(
                    &format!("{what} closed={closed} full={full}: refined curve"),
                    &product,
                    &oracle_curve_samples(&oracle, &params, 3),
                    TOL,
                );
            }
        }
    }
}

#[test]
fn refinement_of_surfaces_keeps_hermite_conditions() {
    for rational in [false, true] {
        for closed in [[false, false], [true, false], [true, true]] {
            let obj =
                constructed_surface(&bspline_surface_source(rational), [4, 3], [3, 2], closed);
            let scene = scene_of(&obj);
            let mut oracle = Surface::from_json(&obj);
            let [(u0, u1), (v0, v1)] = [oracle.dirs[0].window, oracle.dirs[1].window];
            let steps = [
                (0, u0 + 0.4 * (u1 - u0), None),
                (1, v0 + 0.93 * (v1 - v0), Some([2, 3])),
                (0, u1 - 0.03 * (u1 - u0), Some([3, 3])),
            ];
            let mut edits = Vec::new();
            for &(dir, t, d) in &steps {
                let old = oracle.clone();
                let (refined, new) = oracle.insert_knot(dir, t, d).unwrap();
                let key = if dir == 0 { "u" } else { "v" };
                let mut e = json!({"object": "s", "insert_knot": {key: t}});
                if let Some(d) = d {
                    e["degree"] = json!(d);
                }
                edits.push(e);
                let model = product_model(&scene, &Value::Array(edits.clone()));
                let s = erbs_surface(&model);
                let label = format!("rational={rational} closed={closed:?} {key}={t}");
                for k in 0..2 {
                    assert_eq!(
                        s.knots()[k].as_slice(),
                        refined.dirs[k].knots.as_slice(),
                        "{label}"
                    );
                }
                assert_eq!(s.knots()[dir].centre(new), t);
                let d = d.unwrap_or([3, 2]);
                let top = d[0].max(d[1]);
                let other = 1 - dir;
                let (mut got, mut want) = (Vec::new(), Vec::new());
                // The new row/column at every crossing: partials a ≤ du, b ≤ dv.
                for m in 0..old.dirs[other].locals() {
                    let mut at = [t, t];
                    at[other] = old.dirs[other].centre(m);
                    let p = product_surface_derivs(s, at[0], at[1], top);
                    got.push(interpolated_slots(&p, top, d));
                    let q = flatten(old.derivatives(at[0], at[1], top));
                    want.push(interpolated_slots(&q, top, d));
                }
                let scales = interpolated_slots(&surface_scales(&old, top), top, d);
                assert_agrees_at(
                    &format!("{label}: new crossings"),
                    &got,
                    &want,
                    &scales,
                    TOL,
                );
                // Every old crossing: all partials up to 4.
                let (mut got, mut want) = (Vec::new(), Vec::new());
                for k in 0..old.dirs[0].locals() {
                    for l in 0..old.dirs[1].locals() {
                        let (u, v) = (old.dirs[0].centre(k), old.dirs[1].centre(l));
                        got.push(product_surface_derivs(s, u, v, 4));
                        want.push(flatten(old.derivatives(u, v, 4)));
                    }
                }
                let scales = surface_scales(&old, 4);
                assert_agrees_at(
                    &format!("{label}: old crossings"),
                    &got,
                    &want,
                    &scales,
                    TOL,
                );
                oracle = refined;
            }
            let edits = Value::Array(edits);
            // Second-order partials through the delta path; `--full` re-samples the split
            // patches, whose ∂^{2,2} on a 0.03 × 0.14 support is conditioned ~1e6 × |P|: there
            // the value-relative measure asks for digits the split representation does not
            // have (measured 4.8e-12 at the corner), so the full path is compared to order 1.
            for (full, n) in [(false, 2), (true, 1)] {
                let out = sample_cli(&scene, Some(&edits), n, full);
                let (params, product) = surface_output(&out, 0);
                assert_agrees(
                    &format!("rational={rational} closed={closed:?} full={full}: refined"),
                    &product,
                    &oracle_surface_samples(&oracle, &params, n),
                    TOL,
                );
            }
        }
    }
}

// --- nested, typed locals --------------------------------------------------------------------------

/// A depth-3 curve written out explicitly: Bézier, B-spline and ERBS locals, an ERBS local
/// with a narrowed domain, an ERBS local inside an ERBS local, a closed top level.
fn nested_curve(closed: bool) -> Value {
    let inner = json!({"type": "erbs_curve", "knots": [0, 0, 0.5, 1, 1],
        "local": [{"points": [[0, 0, 0], [0.2, 0.5, 0], [0.4, 0.1, 0.3]]},
                  {"type": "bspline_curve", "degree": 2, "knots": [0, 0, 0, 0.3, 1, 1, 1],
                   "points": [[0.3, 0.2, 0], [0.5, 0.6, 0.1], [0.7, 0.1, 0.2], [0.9, 0.4, 0]]},
                  {"type": "bezier_curve", "points": [[0.8, 0, 0], [1, 0.3, 0.1]]}]});
    let middle = json!({"type": "erbs_curve", "knots": [-2, -2, -1, 0.5, 3, 3], "domain": [-1.5, 2.5],
        "local": [{"points": [[1, 0, 0], [1.5, 1, 0], [2, 0.5, 1]]},
                  inner,
                  {"points": [[2, 1, 0], [2.5, 0, 0.5]]},
                  {"points": [[3, 0, 0], [3.5, 1, 0], [4, 0, 0], [4.2, 0.3, 0.1]]}]});
    let (knots, locals) = if closed {
        (json!([0, 1, 2, 3, 4]), 4)
    } else {
        (json!([0, 0, 1, 2, 3, 3]), 4)
    };
    let mut local = vec![
        json!({"points": [[0, 0, 0], [1, 1, 0], [2, 0, 0]]}),
        middle,
        json!({"type": "bspline_curve", "degree": 3, "knots": [5, 5, 5, 5, 6, 7, 7, 7, 7],
               "points": [[2, 2, 0], [3, 2.5, 0], [4, 2, 1], [4.5, 1, 0], [5, 0, 0]]}),
        json!({"type": "erbs_curve", "from": bezier_curve_source(), "local_curves": 3, "local_degree": 2}),
    ];
    local.truncate(locals);
    json!({"name": "e", "type": "erbs_curve", "knots": knots, "closed": closed,
           "local": local, "samples": 61})
}

#[test]
fn nested_curves_match_the_oracle_before_and_after_refinement() {
    for closed in [false, true] {
        let obj = nested_curve(closed);
        let scene = scene_of(&obj);
        let model = product_model(&scene, &json!([]));
        assert_eq!(erbs_curve(&model).depth(), 3);
        let oracle = Curve::from_json(&obj);
        let out = sample_cli(&scene, None, 4, false);
        let (params, product) = curve_output(&out, 0);
        assert_agrees(
            &format!("nested closed={closed}"),
            &product,
            &oracle_curve_samples(&oracle, &params, 4),
            TOL,
        );
        // Refine the top level inside the nested local's support (in the interval blending
        // local 0 and the ERBS local 1) and the top level again next to it.
        let (o1, _) = oracle.insert_knot(0.6, None).unwrap();
        let (o2, _) = o1.insert_knot(1.7, Some(4)).unwrap();
        let edits = json!([{"object": "e", "insert_knot": 0.6},
                           {"object": "e", "insert_knot": 1.7, "degree": 4}]);
        for full in [false, true] {
            let out = sample_cli(&scene, Some(&edits), 4, full);
            let (params, product) = curve_output(&out, 0);
            assert_agrees(
                &format!("nested closed={closed} refined full={full}"),
                &product,
                &oracle_curve_samples(&o2, &params, 4),
                TOL,
            );
        }
    }
}

fn nested_surface(closed: [bool; 2]) -> Value {
    let bez = |z: f64| json!({"points": [[[0, 0, z], [0, 1, z], [0, 2, 0]], [[1, 0, 0], [1, 1, z + 1.0], [1, 2, 0]]]});
    let inner = json!({"type": "erbs_surface", "knots": [[0, 0, 1, 1], [0, 0, 1, 1]],
        "local": [[bez(0.1), {"type": "bspline_surface", "degree": [1, 2],
                               "knots": [[0, 0, 0.5, 1, 1], [0, 0, 0, 1, 1, 1]],
                               "points": [[[0, 0, 0], [0, 1, 1], [0, 2, 0]], [[1, 0, 1], [1, 1, 2], [1, 2, 0]],
                                          [[2, 0, 0], [2, 1, 0.5], [2, 2, 1]]]}],
                  [bez(0.3), bez(-0.2)]]});
    let middle = json!({"type": "erbs_surface", "knots": [[0, 0, 2, 3, 3], [0, 0, 1, 1]],
        "domain": [[0.5, 2.5], [0, 1]],
        "local": [[bez(0.0), inner], [bez(0.5), bez(0.2)], [bez(1.0), bez(-0.4)]]});
    let ku = if closed[0] {
        json!([0, 1, 2, 3])
    } else {
        json!([0, 0, 1, 2, 2])
    };
    let kv = if closed[1] {
        json!([0, 1, 2])
    } else {
        json!([0, 0, 1, 1])
    };
    let nu = 3;
    let nv = 2;
    let mut rows = Vec::new();
    for k in 0..nu {
        let mut row = Vec::new();
        for l in 0..nv {
            row.push(if (k, l) == (1, 0) {
                middle.clone()
            } else {
                bez(0.2 * (k + l) as f64)
            });
        }
        rows.push(Value::Array(row));
    }
    json!({"name": "s", "type": "erbs_surface", "knots": [ku, kv], "closed": closed,
           "local": rows, "samples": [17, 13]})
}

#[test]
fn nested_surfaces_match_the_oracle_before_and_after_refinement() {
    for closed in [[false, false], [true, false], [true, true]] {
        let obj = nested_surface(closed);
        let scene = scene_of(&obj);
        let model = product_model(&scene, &json!([]));
        assert_eq!(erbs_surface(&model).depth(), 3);
        let oracle = Surface::from_json(&obj);
        let out = sample_cli(&scene, None, 2, false);
        let (params, product) = surface_output(&out, 0);
        assert_agrees(
            &format!("nested surface closed={closed:?}"),
            &product,
            &oracle_surface_samples(&oracle, &params, 2),
            TOL,
        );
        let (o1, _) = oracle.insert_knot(0, 0.7, None).unwrap();
        let (o2, _) = o1.insert_knot(1, 0.35, Some([3, 2])).unwrap();
        let edits = json!([{"object": "s", "insert_knot": {"u": 0.7}},
                           {"object": "s", "insert_knot": {"v": 0.35}, "degree": [3, 2]}]);
        for full in [false, true] {
            let out = sample_cli(&scene, Some(&edits), 2, full);
            let (params, product) = surface_output(&out, 0);
            assert_agrees(
                &format!("nested surface closed={closed:?} refined full={full}"),
                &product,
                &oracle_surface_samples(&o2, &params, 2),
                TOL,
            );
        }
    }
}

// --- refining nested locals, to_erbs, closed nested locals -----------------------------------

/// The midpoint of the last knot interval of `dir` whose midpoint lies strictly inside its
/// window: a refinement parameter that is no knot and inserts the new local after the others.
fn last_mid_interval(dir: &oracle::erbs_tree::Dir) -> f64 {
    let centres: Vec<f64> = if dir.closed {
        dir.knots.clone()
    } else {
        dir.knots[1..dir.knots.len() - 1].to_vec()
    };
    centres
        .windows(2)
        .map(|w| 0.5 * (w[0] + w[1]))
        .rfind(|&m| m > dir.window.0 && m < dir.window.1)
        .expect("an interval inside the window")
}

/// The scene entry of the local at `path` (`key` steps `[l]` for curves, `[k][l]` for surfaces).
fn entry_at<'a>(obj: &'a mut Value, steps: &[Vec<usize>]) -> &'a mut Value {
    steps.iter().fold(obj, |v, step| {
        step.iter().fold(&mut v["local"], |v, &i| &mut v[i])
    })
}

/// What `to_erbs` must build, written as the scene format's `from` (its default type filled
/// in): the oracle constructs it on its own.
fn as_constructed(entry: &mut Value, kind: &str, counts: (&str, Value), degrees: (&str, Value)) {
    let mut src = entry.clone();
    if src.get("type").is_none() {
        src["type"] = json!(kind);
    }
    let erbs = kind.replace("bezier", "erbs").replace("bspline", "erbs");
    *entry = json!({"type": erbs, "from": src, counts.0: counts.1, degrees.0: degrees.1});
}

/// `nested_curve` with closed ERBS locals below the top: the ERBS local [1, 1] and the
/// constructed local 3.
fn nested_curve_closed_locals(closed: bool) -> Value {
    let mut obj = nested_curve(closed);
    let inner = &mut obj["local"][1]["local"][1];
    inner["knots"] = json!([0, 0.4, 0.7, 1]);
    inner["closed"] = json!(true);
    obj["local"][3]["closed"] = json!(true);
    obj
}

/// `to_erbs` on a top-level and on a level-2 Bézier local, then refinement of ERBS locals at
/// every depth (the new ones, a closed level-3 local, a closed constructed local, a narrowed
/// one), on open and closed top levels: the product (delta and `--full`) against the oracle's
/// own construction of the same locals and its own refinement one level down per step. A
/// Bézier local turned into an ERBS of at least its degree is reproduced (Taylor polynomials of
/// a polynomial), so that step must not move a sample.
#[test]
fn nested_refinement_to_erbs_and_closed_locals_match_the_oracle() {
    for closed in [false, true] {
        let obj = nested_curve_closed_locals(closed);
        let scene = scene_of(&obj);
        let before = sample_cli(&scene, None, 4, false);
        let (params, product) = curve_output(&before, 0);
        let label = format!("closed={closed}");
        assert_agrees(
            &format!("{label}: closed nested locals"),
            &product,
            &oracle_curve_samples(&Curve::from_json(&obj), &params, 4),
            TOL,
        );

        let mut rewritten = obj.clone();
        as_constructed(
            entry_at(&mut rewritten, &[vec![0]]),
            "bezier_curve",
            ("local_curves", json!(3)),
            ("local_degree", json!(2)),
        );
        as_constructed(
            entry_at(&mut rewritten, &[vec![1], vec![0]]),
            "bezier_curve",
            ("local_curves", json!(4)),
            ("local_degree", json!(1)),
        );
        let mut oracle = Curve::from_json(&rewritten);
        let mut edits = vec![
            json!({"object": "e", "local": 0, "to_erbs": {"local_curves": 3, "local_degree": 2}}),
            json!({"object": "e", "local": [1, 0], "to_erbs": {"local_curves": 4, "local_degree": 1}}),
        ];
        let out = sample_cli(&scene, Some(&json!(edits[..1])), 4, false);
        assert_agrees(
            &format!("{label}: to_erbs of degree ≥ the Bézier's reproduces it"),
            &curve_output(&out, 0).1,
            &product,
            TOL,
        );
        // Deepest first, each in its last interval, so that no path shifts under a later step.
        for path in [vec![1, 1], vec![1, 0], vec![3], vec![0], vec![1]] {
            let s = last_mid_interval(&oracle.nested(&path).dir);
            let t = oracle.outer_parameter(&path, s);
            oracle = oracle
                .insert_knot_at(&path, t, None)
                .unwrap_or_else(|e| panic!("{label}: oracle refinement of {path:?}: {e}"));
            edits.push(json!({"object": "e", "local": path, "insert_knot": t}));
        }
        let edits = Value::Array(edits);
        for full in [false, true] {
            let out = sample_cli(&scene, Some(&edits), 4, full);
            let (params, product) = curve_output(&out, 0);
            assert_agrees(
                &format!("{label}: to_erbs and nested refinement, full={full}"),
                &product,
                &oracle_curve_samples(&oracle, &params, 4),
                TOL,
            );
        }
    }
}

/// The same for surfaces: a closed (in u) level-3 patch, `to_erbs` at levels 1 and 2, and
/// refinement of ERBS patches at every depth in both directions.
#[test]
fn nested_patch_refinement_to_erbs_and_closed_locals_match_the_oracle() {
    for closed in [[false, false], [true, false]] {
        let mut obj = nested_surface(closed);
        let inner = entry_at(&mut obj, &[vec![1, 0], vec![0, 1]]);
        inner["knots"] = json!([[0, 0.5, 1], [0, 0, 1, 1]]);
        inner["closed"] = json!([true, false]);
        let scene = scene_of(&obj);
        let before = sample_cli(&scene, None, 2, false);
        let (params, product) = surface_output(&before, 0);
        let label = format!("closed={closed:?}");
        assert_agrees(
            &format!("{label}: closed nested patch"),
            &product,
            &oracle_surface_samples(&Surface::from_json(&obj), &params, 2),
            TOL,
        );

        let mut rewritten = obj.clone();
        as_constructed(
            entry_at(&mut rewritten, &[vec![0, 0]]),
            "bezier_surface",
            ("local_patches", json!([3, 3])),
            ("local_degree", json!([1, 2])),
        );
        as_constructed(
            entry_at(&mut rewritten, &[vec![1, 0], vec![2, 1]]),
            "bezier_surface",
            ("local_patches", json!([2, 3])),
            ("local_degree", json!([1, 1])),
        );
        let mut oracle = Surface::from_json(&rewritten);
        let mut edits = vec![
            json!({"object": "s", "local": [0, 0],
                   "to_erbs": {"local_patches": [3, 3], "local_degree": [1, 2]}}),
            json!({"object": "s", "local": [[1, 0], [2, 1]],
                   "to_erbs": {"local_patches": [2, 3], "local_degree": [1, 1]}}),
        ];
        let out = sample_cli(&scene, Some(&json!(edits[..1])), 2, false);
        assert_agrees(
            &format!("{label}: to_erbs of degree ≥ the Bézier's reproduces it"),
            &surface_output(&out, 0).1,
            &product,
            TOL,
        );
        let steps: [(Vec<[usize; 2]>, usize); 6] = [
            (vec![[1, 0], [0, 1]], 0),
            (vec![[1, 0], [0, 1]], 1),
            (vec![[1, 0], [2, 1]], 0),
            (vec![[0, 0]], 1),
            (vec![[1, 0]], 1),
            (vec![[1, 0]], 0),
        ];
        for (path, dir) in steps {
            let s = last_mid_interval(&oracle.nested(&path).dirs[dir]);
            let t = oracle.outer_parameter(&path, dir, s);
            oracle = oracle
                .insert_knot_at(&path, dir, t, None)
                .unwrap_or_else(|e| panic!("{label}: oracle refinement of {path:?}: {e}"));
            let key = ["u", "v"][dir];
            edits.push(json!({"object": "s", "local": path, "insert_knot": {key: t}}));
        }
        let edits = Value::Array(edits);
        for full in [false, true] {
            let out = sample_cli(&scene, Some(&edits), 2, full);
            let (params, product) = surface_output(&out, 0);
            assert_agrees(
                &format!("{label}: to_erbs and nested refinement, full={full}"),
                &product,
                &oracle_surface_samples(&oracle, &params, 2),
                TOL,
            );
        }
    }
}

// --- negative controls -------------------------------------------------------------------------

/// The comparison helper fails on a perturbed oracle (a local control point moved by 1e-9 of
/// the object's size, a knot moved by 1e-9), on a NaN on either side, and on a refinement the
/// oracle did not make.
#[test]
fn comparisons_fail_on_perturbed_inputs() {
    let obj = constructed_curve(&bspline_curve_source(true), 5, 3, true, 41);
    let out = sample_cli(&scene_of(&obj), None, 3, false);
    let (params, product) = curve_output(&out, 0);
    let good = Curve::from_json(&obj);
    assert_agrees(
        "control",
        &product,
        &oracle_curve_samples(&good, &params, 3),
        TOL,
    );

    let mut moved = good.clone();
    if let oracle::erbs_tree::CurveKind::Bezier(p) = &mut moved.locals[2].kind {
        p[1][1] += 1e-8;
    }
    assert!(agrees(&product, &oracle_curve_samples(&moved, &params, 3), TOL).is_err());

    let mut knot = good.clone();
    knot.dir.knots[2] += 1e-9;
    assert!(agrees(&product, &oracle_curve_samples(&knot, &params, 3), TOL).is_err());

    let mut nan = product.clone();
    nan[7][2][1] = f64::NAN;
    let e = agrees(&nan, &oracle_curve_samples(&good, &params, 3), TOL);
    assert!(e.is_err_and(f64::is_nan));
    let mut nan_oracle = oracle_curve_samples(&good, &params, 3);
    nan_oracle[0][0][0] = f64::NAN;
    assert!(agrees(&product, &nan_oracle, TOL).is_err());

    let (refined, _) = good.insert_knot(0.3, None).unwrap();
    assert!(agrees(&product, &oracle_curve_samples(&refined, &params, 3), TOL).is_err());

    // Surfaces: a patch point of the oracle moved by 1e-8.
    let obj = constructed_surface(&bspline_surface_source(true), [3, 3], [2, 2], [true, false]);
    let out = sample_cli(&scene_of(&obj), None, 1, false);
    let (params, product) = surface_output(&out, 0);
    let good = Surface::from_json(&obj);
    assert_agrees(
        "control",
        &product,
        &oracle_surface_samples(&good, &params, 1),
        TOL,
    );
    let mut moved = good.clone();
    if let oracle::erbs_tree::PatchKind::Tensor { points, .. } = &mut moved.locals[4].kind {
        points[1][1][2] += 1e-8;
    }
    assert!(agrees(&product, &oracle_surface_samples(&moved, &params, 1), TOL).is_err());
    // The Hermite check: a source perturbed by 1e-9 fails it.
    let src = bspline_curve_source(false);
    let scene = scene_of(&constructed_curve(&src, 4, 3, false, 9));
    let model = product_model(&scene, &json!([]));
    let c = erbs_curve(&model);
    let mut bent = src.clone();
    bent["points"][3][1] = json!(1.5 + 1e-8);
    let source = source_object(&bent, json!(2));
    let t = c.knots().centre(2);
    assert!(
        agrees(
            &[product_curve_derivs(c, t, 3)],
            &[source.curve_derivatives(t, 3)],
            TOL
        )
        .is_err()
    );
}

// --- 1b. old knots unchanged, new local addressable ------------------------------------------------

/// After `insert_knot`, moving the new local (by its index) changes exactly the samples strictly
/// inside its support (c_i, c_{i+1}) and no other; moving an old neighbour afterwards changes
/// only its shortened support.
#[test]
fn the_new_local_is_addressable_and_edits_stay_in_its_support() {
    for closed in [false, true] {
        let obj = constructed_curve(&bspline_curve_source(false), 5, 3, closed, 301);
        let scene = scene_of(&obj);
        let model = product_model(&scene, &json!([]));
        let c = erbs_curve(&model);
        let (a, b) = c.domain();
        let t = a + 0.43 * (b - a);
        let (r, new) = c.insert_knot(t, None).unwrap();
        let (lo, hi) = r.knots().support(new);
        let refine = json!({"object": "e", "insert_knot": t});
        let lift = json!({"object": "e", "local": new,
                          "transform": [[1, 0, 0, 0.5], [0, 1, 0, -0.25], [0, 0, 1, 1], [0, 0, 0, 1]]});
        let base = sample_cli(&scene, Some(&json!([refine])), 1, false);
        let moved = sample_cli(&scene, Some(&json!([refine, lift])), 1, false);
        let (params, p0) = curve_output(&base, 0);
        let (_, p1) = curve_output(&moved, 0);
        let mut changed_inside = 0;
        for (j, &x) in params.iter().enumerate() {
            let same = p0[j] == p1[j];
            if x > lo && x < hi {
                changed_inside += usize::from(!same);
            } else {
                assert!(
                    same,
                    "closed={closed}: sample {j} at {x} outside ({lo}, {hi}) changed"
                );
            }
        }
        assert!(changed_inside > 10, "the new local moved nothing");
        // The old neighbour (new − 1) now only reaches up to t.
        let (nlo, nhi) = r.knots().support(new - 1);
        assert_eq!(nhi, t);
        let point = json!({"object": "e", "local": new - 1, "point": 1, "delta": [0, 0.3, 0]});
        let moved = sample_cli(&scene, Some(&json!([refine, point])), 1, false);
        let (_, p2) = curve_output(&moved, 0);
        for (j, &x) in params.iter().enumerate() {
            if !(x > nlo && x < nhi) {
                assert_eq!(
                    p0[j], p2[j],
                    "closed={closed}: sample at {x} outside ({nlo}, {nhi})"
                );
            }
        }
        assert_ne!(p0, p2);
    }
}

// --- 1c. delta equals full at depth ≥ 3 --------------------------------------------------------------

/// Paths (curves) to every local at exactly `depth` levels below the top, in the product's
/// current model.
fn curve_paths(c: &ErbsCurve, prefix: Vec<usize>, depth: usize, out: &mut Vec<Vec<usize>>) {
    for (l, local) in c.local_curves().iter().enumerate() {
        let mut p = prefix.clone();
        p.push(l);
        if p.len() == depth {
            out.push(p.clone());
        }
        if let LocalCurve::Erbs(e) = local {
            curve_paths(e, p, depth, out);
        }
    }
}

fn surface_paths(
    s: &ErbsSurface,
    prefix: Vec<[usize; 2]>,
    depth: usize,
    out: &mut Vec<Vec<[usize; 2]>>,
) {
    let [nu, nv] = s.count();
    for k in 0..nu {
        for l in 0..nv {
            let mut p = prefix.clone();
            p.push([k, l]);
            if p.len() == depth {
                out.push(p.clone());
            }
            if let LocalPatch::Erbs(e) = s.local_patch(k, l) {
                surface_paths(e, p, depth, out);
            }
        }
    }
}

fn random_matrix(rng: &mut Rng) -> Value {
    let s = rng.range(0.9, 1.1);
    let (c, sn) = (rng.range(-0.3, 0.3).cos(), rng.range(-0.3, 0.3).sin());
    let t = [
        rng.range(-0.2, 0.2),
        rng.range(-0.2, 0.2),
        rng.range(-0.2, 0.2),
    ];
    json!([
        [s * c, -s * sn, 0, t[0]],
        [s * sn, s * c, 0, t[1]],
        [0, 0, s, t[2]],
        [0, 0, 0, 1]
    ])
}

fn delta_vs_full(scene: &Value, edits: &[Value], mode: SampleMode) -> f64 {
    let s = parse_scene(&scene.to_string()).unwrap();
    let list = parse_edits(&Value::Array(edits.to_vec()).to_string(), &s).unwrap();
    let mut obj = SampledObject::new(&s.objects[0].model, mode);
    for e in &list {
        obj.apply(&e.edit).expect("validated");
    }
    let fresh = SampledObject::new(&obj.model().to_model(), mode);
    obj.grid().max_relative_difference(fresh.grid())
}

/// Builds depth 3 by `to_erbs` (through the delta path), then a long random mix: control-point
/// moves of depth-3 leaves, rotations/scales/translations of level-1 and level-2 locals, and
/// refinements of the top level and of level-2 ERBS locals.
#[test]
fn delta_equals_full_for_curves_at_depth_three() {
    for closed in [false, true] {
        let obj = constructed_curve(&bspline_curve_source(false), 5, 3, closed, 400);
        let scene = scene_of(&obj);
        let mut edits = vec![
            json!({"object": "e", "local": 2, "to_erbs": {"local_curves": 4, "local_degree": 3}}),
            json!({"object": "e", "local": [2, 1], "to_erbs": {"local_curves": 3, "local_degree": 2}}),
        ];
        let mut rng = Rng::new(0xe4b5 + u64::from(closed));
        for step in 0..240 {
            let model = product_model(&scene, &Value::Array(edits.clone()));
            let c = erbs_curve(&model);
            assert!(c.depth() >= 3);
            let e = match step % 6 {
                0..=2 => {
                    let mut leaves = Vec::new();
                    curve_paths(c, vec![], 3, &mut leaves);
                    let path = &leaves[rng.int(0, leaves.len() - 1)];
                    let n = c.local_at(path).unwrap().points().unwrap().len();
                    json!({"object": "e", "local": path, "point": rng.int(0, n - 1),
                           "delta": [rng.range(-0.1, 0.1), rng.range(-0.1, 0.1), rng.range(-0.1, 0.1)]})
                }
                3 | 4 => {
                    let mut paths = Vec::new();
                    curve_paths(c, vec![], rng.int(1, 2), &mut paths);
                    let path = &paths[rng.int(0, paths.len() - 1)];
                    json!({"object": "e", "local": path, "transform": random_matrix(&mut rng)})
                }
                _ => {
                    let mut nested = Vec::new();
                    curve_paths(c, vec![], 2, &mut nested);
                    nested.retain(|p| matches!(c.local_at(p), Some(LocalCurve::Erbs(_))));
                    let (target, (a, b)) = if step % 12 == 5 || nested.is_empty() {
                        (None, c.domain())
                    } else {
                        let p = nested[rng.int(0, nested.len() - 1)].clone();
                        let d = c.local_at(&p).unwrap().domain();
                        (Some(p), d)
                    };
                    let t = a + (b - a) * rng.range(0.05, 0.95);
                    let mut e = json!({"object": "e", "insert_knot": t});
                    if let Some(p) = target {
                        e["local"] = json!(p);
                    }
                    e
                }
            };
            edits.push(e);
        }
        for mode in [SampleMode::Derivatives(2), SampleMode::Render] {
            let err = delta_vs_full(&scene, &edits, mode);
            assert!(
                err <= DELTA_TOL,
                "closed={closed} {mode:?}: delta vs full {err:e}"
            );
        }
        // Also through the CLI, bit-close: `sample --edits` vs `sample --edits --full`.
        let list = Value::Array(edits);
        let (_, d) = curve_output(&sample_cli(&scene, Some(&list), 2, false), 0);
        let (_, f) = curve_output(&sample_cli(&scene, Some(&list), 2, true), 0);
        assert_agrees(
            &format!("closed={closed}: sample vs --full"),
            &d,
            &f,
            DELTA_TOL,
        );
    }
}

#[test]
fn delta_equals_full_for_surfaces_at_depth_three() {
    for closed in [[false, false], [true, true]] {
        let mut obj = constructed_surface(&bspline_surface_source(false), [4, 3], [3, 2], closed);
        obj["samples"] = json!([41, 37]);
        let scene = scene_of(&obj);
        let mut edits = vec![
            json!({"object": "s", "local": [1, 1], "to_erbs": {"local_patches": [3, 3], "local_degree": [3, 2]}}),
            json!({"object": "s", "local": [[1, 1], [1, 2]], "to_erbs": {"local_patches": [2, 3], "local_degree": [2, 2]}}),
        ];
        let mut rng = Rng::new(0x5eed + u64::from(closed[0]));
        for step in 0..120 {
            let model = product_model(&scene, &Value::Array(edits.clone()));
            let s = erbs_surface(&model);
            assert!(s.depth() >= 3);
            let e = match step % 6 {
                0..=2 => {
                    let mut leaves = Vec::new();
                    surface_paths(s, vec![], 3, &mut leaves);
                    let path = &leaves[rng.int(0, leaves.len() - 1)];
                    let ([a, b], _) = s.local_at(path).unwrap().net().unwrap();
                    json!({"object": "s", "local": path, "point": [rng.int(0, a - 1), rng.int(0, b - 1)],
                           "delta": [rng.range(-0.1, 0.1), rng.range(-0.1, 0.1), rng.range(-0.1, 0.1)]})
                }
                3 | 4 => {
                    let mut paths = Vec::new();
                    surface_paths(s, vec![], rng.int(1, 2), &mut paths);
                    let path = &paths[rng.int(0, paths.len() - 1)];
                    json!({"object": "s", "local": path, "transform": random_matrix(&mut rng)})
                }
                _ => {
                    let mut nested = Vec::new();
                    surface_paths(s, vec![], 2, &mut nested);
                    nested.retain(|p| matches!(s.local_at(p), Some(LocalPatch::Erbs(_))));
                    let dir = rng.int(0, 1);
                    let (target, (a, b)) = if step % 12 == 5 || nested.is_empty() {
                        (None, s.domain()[dir])
                    } else {
                        let p = nested[rng.int(0, nested.len() - 1)].clone();
                        let d = s.local_at(&p).unwrap().domain()[dir];
                        (Some(p), d)
                    };
                    let t = a + (b - a) * rng.range(0.05, 0.95);
                    let key = if dir == 0 { "u" } else { "v" };
                    let mut e = json!({"object": "s", "insert_knot": {key: t}});
                    if let Some(p) = target {
                        e["local"] = json!(p);
                    }
                    e
                }
            };
            edits.push(e);
        }
        for mode in [SampleMode::Derivatives(1), SampleMode::Render] {
            let err = delta_vs_full(&scene, &edits, mode);
            assert!(
                err <= DELTA_TOL,
                "closed={closed:?} {mode:?}: delta vs full {err:e}"
            );
        }
    }
}

// --- 1d. closed seams ------------------------------------------------------------------------------

/// Orders checked at a seam: the expo-rational B is C^∞, every derivative of B vanishes at 0
/// and 1, so each order must agree (to rounding, relative to that order's magnitude).
const SEAM_ORDERS: usize = 6;

#[test]
fn closed_curve_seam_is_smooth() {
    for src in [bspline_curve_source(false), bspline_curve_source(true)] {
        let obj = constructed_curve(&src, 5, 3, true, 101);
        let scene = scene_of(&obj);
        let model = product_model(&scene, &json!([]));
        let c = erbs_curve(&model);
        let (a, b) = c.domain();
        // From the right of the start and from the left of the end of the period.
        let start = product_curve_derivs(c, a, SEAM_ORDERS);
        let end = product_curve_derivs(c, b, SEAM_ORDERS);
        let oracle = Curve::from_json(&obj);
        let scales = curve_scales(&oracle, SEAM_ORDERS);
        assert_agrees_at("seam derivatives", &[end], &[start], &scales, TOL);
        // Sampling across the seam: points just before the end continue the Taylor series
        // taken at the start; with 5 terms the Lagrange remainder is h^5/5!·|c^(5)|, bounded
        // by twice the largest sampled |c^(5)| (the curve's fifth derivative is smooth).
        for h in [1e-3f64, 1e-2] {
            taylor_across_the_seam(c, &scales, h).unwrap();
            assert_agrees_at(
                "oracle across the seam",
                &[
                    product_curve_derivs(c, b - h, 3),
                    product_curve_derivs(c, a + h, 3),
                ],
                &[oracle.derivatives(b - h, 3), oracle.derivatives(a + h, 3)],
                &scales[..4],
                TOL,
            );
        }
        // The sampled curve: first and last samples agree in every order.
        let out = sample_cli(&scene, None, SEAM_ORDERS, false);
        let (_, s) = curve_output(&out, 0);
        assert_agrees_at(
            "sample seam",
            &[s[s.len() - 1].clone()],
            &[s[0].clone()],
            &scales,
            TOL,
        );
    }
    // Negative control: an open curve from the same source has no seam.
    let obj = constructed_curve(&bspline_curve_source(false), 5, 3, false, 11);
    let model = product_model(&scene_of(&obj), &json!([]));
    let c = erbs_curve(&model);
    let (a, b) = c.domain();
    let scales = curve_scales(&Curve::from_json(&obj), SEAM_ORDERS);
    let (end, start) = (product_curve_derivs(c, b, 3), product_curve_derivs(c, a, 3));
    assert!(agrees_at(&[end], &[start], &scales[..4], TOL).is_err());
    assert!(taylor_across_the_seam(c, &scales, 1e-3).is_err());
}

/// Points just before the end of the period continue the Taylor series taken at its start:
/// with 5 terms the Lagrange remainder is h^5/5!·|c^(5)|, bounded here by twice the largest
/// |c^(5)| of the object (`scales[5]`), plus rounding at the tolerance.
fn taylor_across_the_seam(c: &ErbsCurve, scales: &[f64], h: f64) -> Result<f64, String> {
    let (a, b) = c.domain();
    let start = product_curve_derivs(c, a, 4);
    let taylor: Point3 = (0..=4).fold([0.0; 3], |acc, r| {
        let f = (-h).powi(r as i32) / (1..=r).map(|k| k as f64).product::<f64>();
        [
            acc[0] + f * start[r][0],
            acc[1] + f * start[r][1],
            acc[2] + f * start[r][2],
        ]
    });
    let before = product_curve_derivs(c, b - h, 0)[0];
    let bound = 2.0 * scales[5] * h.powi(5) / 120.0 + TOL * scales[0];
    let gap = (0..3).fold(0.0f64, |m, k| nan_max(m, (before[k] - taylor[k]).abs()));
    if gap <= bound {
        Ok(gap)
    } else {
        Err(format!("h={h}: Taylor gap {gap:e} > {bound:e}"))
    }
}

#[test]
fn closed_surface_seams_are_smooth() {
    for closed in [[true, false], [true, true]] {
        let obj = constructed_surface(&bspline_surface_source(true), [4, 3], [3, 2], closed);
        let scene = scene_of(&obj);
        let model = product_model(&scene, &json!([]));
        let s = erbs_surface(&model);
        let [(u0, u1), (v0, v1)] = s.domain();
        let n = 4;
        let vs: Vec<f64> = (0..=8).map(|j| v0 + (v1 - v0) * j as f64 / 8.0).collect();
        let us: Vec<f64> = (0..=8).map(|j| u0 + (u1 - u0) * j as f64 / 8.0).collect();
        let at_u0: Vec<_> = vs
            .iter()
            .map(|&v| product_surface_derivs(s, u0, v, n))
            .collect();
        let at_u1: Vec<_> = vs
            .iter()
            .map(|&v| product_surface_derivs(s, u1, v, n))
            .collect();
        let oracle = Surface::from_json(&obj);
        let scales = surface_scales(&oracle, n);
        assert_agrees_at(&format!("{closed:?}: u seam"), &at_u1, &at_u0, &scales, TOL);
        if closed[1] {
            let at_v0: Vec<_> = us
                .iter()
                .map(|&u| product_surface_derivs(s, u, v0, n))
                .collect();
            let at_v1: Vec<_> = us
                .iter()
                .map(|&u| product_surface_derivs(s, u, v1, n))
                .collect();
            assert_agrees_at(&format!("{closed:?}: v seam"), &at_v1, &at_v0, &scales, TOL);
            assert_agrees_at(
                "corner",
                &[product_surface_derivs(s, u1, v1, n)],
                &[product_surface_derivs(s, u0, v0, n)],
                &scales,
                TOL,
            );
        } else {
            let at_v0: Vec<_> = us
                .iter()
                .map(|&u| product_surface_derivs(s, u, v0, n))
                .collect();
            let at_v1: Vec<_> = us
                .iter()
                .map(|&u| product_surface_derivs(s, u, v1, n))
                .collect();
            assert!(
                agrees_at(&at_v1, &at_v0, &scales, TOL).is_err(),
                "open v has no seam: the comparison must fail there"
            );
        }
        // Near the seam, product and oracle agree on both sides.
        let h = 1e-3 * (u1 - u0);
        let pts = [(u0 + h, v0 + 0.3), (u1 - h, v0 + 0.3), (u1 - h, v1 - h)];
        let got: Vec<_> = pts
            .iter()
            .map(|&(u, v)| product_surface_derivs(s, u, v, 2))
            .collect();
        let want: Vec<_> = pts
            .iter()
            .map(|&(u, v)| flatten(oracle.derivatives(u, v, 2)))
            .collect();
        assert_agrees("oracle near the seam", &got, &want, TOL);
        // The sampled grid: the first and last rows (and columns) agree.
        let out = sample_cli(&scene, None, 2, false);
        let (params, samples) = surface_output(&out, 0);
        let mv = params[1].len();
        let mu = params[0].len();
        let first: Vec<_> = (0..mv).map(|j| samples[j].clone()).collect();
        let last: Vec<_> = (0..mv)
            .map(|j| samples[(mu - 1) * mv + j].clone())
            .collect();
        let scales2 = surface_scales(&oracle, 2);
        assert_agrees_at("sampled u seam", &last, &first, &scales2, TOL);
    }
}

// --- 1e. CLI errors ------------------------------------------------------------------------------

/// Refused with exactly one line on stderr, nothing on stdout, naming the object and field.
fn refused(scene: &Value, edits: Option<&Value>, parts: &[&str]) {
    for full in [false, true] {
        let (ok, stdout, stderr) =
            run_sample(&scene.to_string(), edits.map(|e| e.to_string()), 1, full);
        let what = format!("{scene} / {edits:?}");
        assert!(!ok, "accepted: {what}");
        assert!(stdout.is_empty(), "{what}: partial output {stdout}");
        assert_eq!(stderr.lines().count(), 1, "{what}: not one line:\n{stderr}");
        assert!(stderr.starts_with("error: "), "{what}: {stderr}");
        assert!(!stderr.contains("panicked"), "{what}: {stderr}");
        for p in parts {
            assert!(stderr.contains(p), "{what}: {stderr:?} lacks {p:?}");
        }
        if edits.is_none() {
            break;
        }
    }
}

#[test]
fn refinement_errors_are_one_line() {
    let scene = scene_of(&constructed_curve(
        &bspline_curve_source(false),
        4,
        3,
        false,
        9,
    ));
    // Knots at -1, 0, 1, 2 (domain [-1, 2]).
    for t in [0.0, 1.0] {
        refused(
            &scene,
            Some(&json!([{"object": "e", "insert_knot": t}])),
            &["'e'", "'insert_knot'", "is a knot"],
        );
    }
    for t in [-1.0, 2.0, 2.5, -7.0] {
        refused(
            &scene,
            Some(&json!([{"object": "e", "insert_knot": t}])),
            &["'e'", "'insert_knot'", "not inside the open domain"],
        );
    }
    refused(
        &scene,
        Some(&json!([{"object": "e", "insert_knot": 0.5, "degree": 65}])),
        &["'e'", "'degree'"],
    );
    let surface = scene_of(&constructed_surface(
        &bspline_surface_source(false),
        [3, 3],
        [2, 2],
        [false, true],
    ));
    refused(
        &surface,
        Some(&json!([{"object": "s", "insert_knot": {"u": 0.5}}])),
        &["'s'", "'insert_knot'", "is a knot"],
    );
    refused(
        &surface,
        Some(&json!([{"object": "s", "insert_knot": {"v": 2.0}}])),
        &["'s'", "'insert_knot'", "not inside the open domain"],
    );
}

#[test]
fn construction_errors_are_one_line() {
    let src = bspline_curve_source(false);
    let mut both = constructed_curve(&src, 4, 3, false, 9);
    both["knots"] = json!([0, 0, 1, 2, 3, 3]);
    refused(&scene_of(&both), None, &["'e'", "'from'", "knots"]);
    let mut both = constructed_curve(&src, 4, 3, false, 9);
    both["local"] = json!([]);
    refused(&scene_of(&both), None, &["'e'", "'from'", "local"]);
    for n in [0, 1] {
        refused(
            &scene_of(&constructed_curve(&src, n, 3, false, 9)),
            None,
            &["'e'", "'local_curves'", "at least 2"],
        );
        refused(
            &scene_of(&constructed_surface(
                &bspline_surface_source(false),
                [3, n],
                [2, 2],
                [false, false],
            )),
            None,
            &["'s'", "'local_patches'", "at least 2", "v direction"],
        );
    }
    refused(
        &scene_of(&constructed_curve(&src, 4, 65, false, 9)),
        None,
        &["'e'", "'local_degree'"],
    );
    refused(
        &scene_of(&constructed_surface(
            &bspline_surface_source(false),
            [3, 3],
            [2, 99],
            [false, false],
        )),
        None,
        &["'s'", "'local_degree'"],
    );
    let mut both = constructed_surface(
        &bspline_surface_source(false),
        [3, 3],
        [2, 2],
        [false, false],
    );
    both["knots"] = json!([[0, 0, 1, 1], [0, 0, 1, 1]]);
    refused(&scene_of(&both), None, &["'s'", "'from'", "knots"]);
    // A nested local built `from` a source covers its whole support: no `domain` beside it.
    let mut nested = nested_curve(false);
    nested["local"][3]["domain"] = json!([0.2, 0.8]);
    refused(
        &scene_of(&nested),
        None,
        &["'e'", "local[3]", "'from'", "domain"],
    );
}

/// An ERBS body whose local 0 is again an ERBS body, `depth` ERBS levels in all (the outermost
/// included; 0 gives a Bézier local).
fn nested_to(depth: usize) -> Value {
    let mut local = json!({"points": [[0, 0, 0], [1, 1, 0]]});
    for _ in 0..depth {
        local = json!({"type": "erbs_curve", "knots": [0, 0, 1, 1],
                       "local": [local, {"points": [[1, 0, 0], [2, 1, 0]]}]});
    }
    local
}

#[test]
fn nesting_deeper_than_the_limit_is_one_line() {
    let scene_at = |depth: usize| {
        let mut top = nested_to(depth);
        let obj = top.as_object_mut().unwrap();
        obj.insert("name".into(), json!("deep"));
        obj.insert("type".into(), json!("erbs_curve"));
        obj.insert("samples".into(), json!(5));
        scene_of(&top)
    };
    let (ok, _, stderr) = run_sample(&scene_at(MAX_NESTING).to_string(), None, 1, false);
    assert!(ok, "{MAX_NESTING} levels are allowed: {stderr}");
    refused(
        &scene_at(MAX_NESTING + 1),
        None,
        &["'deep'", "'local'", &format!("at most {MAX_NESTING}")],
    );
    // to_erbs past the limit on the deepest polynomial local.
    let path: Vec<usize> = vec![0; MAX_NESTING];
    refused(
        &scene_at(MAX_NESTING),
        Some(&json!([{"object": "deep", "local": path,
                      "to_erbs": {"local_curves": 2, "local_degree": 1}}])),
        &["'deep'", "'to_erbs'", &format!("{MAX_NESTING}")],
    );
}

// --- refinement with B-functions whose derivatives do not vanish at the knots ---------------------

/// Issue 34.20: with smoothstep, smootherstep, rational and trigonometric B-functions the
/// blend's second derivative at 0 and 1 is not zero, so a refinement inside an interval also
/// changes the derivatives (order ≥ 2) of the samples at the interval's two knots (the
/// non-flat branch of `touched_by_refinement`). The samples fall exactly on the knots here (57
/// samples over 4 intervals; 17 × 17 over 4 × 4), and the refined interval holds a knot of
/// the source the ERBS object was built from. Curves: the delta path and `--full` to order
/// 3 against the oracle's refinement at every sample, and C'' or C''' on the knots does change (so a
/// knot sample left out of the touched range would be seen). Surfaces: to order 1 against the
/// oracle, and on the refined interval's two knot rows the delta path equals `--full` to
/// order 2 within 1e-12 of the order's magnitude (docs/scene-format.md,
/// "The delta path and `--full` after structural edits"); the oracle is not the reference
/// for surface second partials here: smootherstep's already differ from it by 1.0e-12 of
/// their magnitude before any refinement, and by 4.5e-12 after.
#[test]
fn refinement_with_non_flat_b_functions_updates_the_samples_on_the_knots() {
    for bf in ["smoothstep", "smootherstep", "rational", "trigonometric"] {
        let mut obj = constructed_curve(&bspline_curve_source(false), 5, 3, false, 57);
        obj["bfunction"] = json!(bf);
        let scene = scene_of(&obj);
        let before = Curve::from_json(&obj);
        let (a, b) = before.dir.window;
        // Inside interval 2 of [−1, 2] cut in four: its knots −1 + 3·2/4 = 0.5 and 1.25.
        let t = a + 0.6 * (b - a);
        let (refined, _) = before.clone().insert_knot(t, None).unwrap();
        let edits = json!([{"object": "e", "insert_knot": t}]);
        for full in [false, true] {
            let out = sample_cli(&scene, Some(&edits), 3, full);
            let (params, product) = curve_output(&out, 0);
            for knot in [0.5, 1.25] {
                assert!(params.contains(&knot), "{bf}: no sample on the knot {knot}");
            }
            assert_agrees(
                &format!("{bf} full={full}: refined curve"),
                &product,
                &oracle_curve_samples(&refined, &params, 3),
                TOL,
            );
        }
        // The samples on the knots did change (else this would test nothing there).
        let (params, old) = curve_output(&sample_cli(&scene, None, 3, true), 0);
        let (_, new) = curve_output(&sample_cli(&scene, Some(&edits), 3, true), 0);
        let k = params.iter().position(|&x| x == 0.5).unwrap();
        // C'' or C''' (smootherstep's B'' vanishes at the ends, its B''' does not).
        assert!(
            (2..=3).any(|r| (0..3).any(|c| (old[k][r][c] - new[k][r][c]).abs() > 1e-6)),
            "{bf}: C'' and C''' at the knot 0.5 unchanged"
        );

        let mut obj =
            constructed_surface(&bspline_surface_source(false), [5, 5], [3, 2], [false; 2]);
        obj["bfunction"] = json!(bf);
        obj["samples"] = json!([17, 17]);
        let scene = scene_of(&obj);
        let before = Surface::from_json(&obj);
        let (u0, u1) = before.dirs[0].window;
        // Inside [0.25, 0.5] of u ∈ [0, 1], which holds the source's knot 0.4: there the
        // locals only approximate the source, and the refinement changes the blend's second
        // partials at the interval's knots.
        let u = u0 + 0.3 * (u1 - u0);
        let (refined, _) = before.clone().insert_knot(0, u, None).unwrap();
        let edits = json!([{"object": "s", "insert_knot": {"u": u}}]);
        for full in [false, true] {
            let out = sample_cli(&scene, Some(&edits), 1, full);
            let (params, product) = surface_output(&out, 0);
            assert_agrees(
                &format!("{bf} full={full}: refined surface"),
                &product,
                &oracle_surface_samples(&refined, &params, 1),
                TOL,
            );
        }
        let (params, delta) = surface_output(&sample_cli(&scene, Some(&edits), 2, false), 0);
        let (_, full) = surface_output(&sample_cli(&scene, Some(&edits), 2, true), 0);
        // The slots of order 2 in the sample's partial list ((a, b) with a + b ≤ 2, a outer).
        let second: Vec<usize> = (0..=2usize)
            .flat_map(|a| (0..=2 - a).map(move |b| (a, b)))
            .enumerate()
            .filter(|(_, (a, b))| a + b == 2)
            .map(|(k, _)| k)
            .collect();
        let rows: Vec<usize> = [0.25, 0.5]
            .iter()
            .map(|k| params[0].iter().position(|x| x == k).unwrap())
            .collect();
        let m = params[1].len();
        let on_rows = |grid: &[Vec<Point3>]| -> Vec<Point3> {
            rows.iter()
                .flat_map(|&i| (0..m).map(move |j| i * m + j))
                .flat_map(|s| second.iter().map(move |&slot| grid[s][slot]))
                .collect()
        };
        let (d, f) = (on_rows(&delta), on_rows(&full));
        let scale = f.iter().fold(0.0f64, |m, p| {
            nan_max(m, p.iter().fold(0.0, |a, c| nan_max(a, c.abs())))
        });
        let differ = |x: &[Point3], y: &[Point3]| {
            x.iter().zip(y).fold(0.0f64, |m, (p, q)| {
                (0..3).fold(m, |m, c| nan_max(m, (p[c] - q[c]).abs()))
            }) / scale
        };
        assert!(
            differ(&d, &f) <= 1e-12,
            "{bf}: delta against --full on the knot rows: {:e}",
            differ(&d, &f)
        );
        // The surface's refinement keeps its old knot rows' partials (measured: 1.7e-14 of
        // their magnitude); the curve's above changes C'' at its knots, which is what a
        // stale knot sample would show.
    }
}
