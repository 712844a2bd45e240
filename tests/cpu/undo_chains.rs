//! Undo gives back the model bit for bit: random chains of every edit kind on every object kind
//! (B-spline, Bézier and NURBS curves and surfaces, rational from the start and made rational
//! by an edit, ERBS curves and surfaces with local and nested edits, Catmull–Rom and Bézier
//! splines, conversions), submitted through `editor::Editor` in steps of one to three edits,
//! undone and redone at random. After every undo the document's models equal the state before
//! the step, compared by their `Debug` text, which prints every f64 (points, weights, knots)
//! with the shortest digits that read back to the same bits.

use crate::common;
use glam::{DMat4, DQuat, DVec3};
use prespline::editor::Editor;
use prespline::formats::parse_scene;
use prespline::geom::erbs::{LocalCurve, LocalPatch};
use prespline::model::{
    BezierSplineEdit, CatmullRomEdit, CurveEdit, Edit, ErbsCurveEdit, ErbsSurfaceEdit, KindEdit,
    LocalEdit, LocalPath, ModelRef, ObjectEdit, PointEdit, SurfaceEdit,
};
use std::collections::BTreeSet;

/// A `nu × nv` net (JSON) of a gently curved sheet, and positive weights for it.
fn net(nu: usize, nv: usize) -> (String, String) {
    let mut points = Vec::new();
    let mut weights = Vec::new();
    for i in 0..nu {
        let row: Vec<String> = (0..nv)
            .map(|j| format!("[{i}, {j}, {}]", ((i * 7 + j * 3) % 5) as f64 * 0.3))
            .collect();
        points.push(format!("[{}]", row.join(", ")));
        let w: Vec<String> = (0..nv)
            .map(|j| format!("{}", 0.6 + 0.37 * ((i + 2 * j) % 4) as f64))
            .collect();
        weights.push(format!("[{}]", w.join(", ")));
    }
    (
        format!("[{}]", points.join(", ")),
        format!("[{}]", weights.join(", ")),
    )
}

fn scene_text() -> String {
    let (p43, _) = net(4, 3);
    let (p33, w33) = net(3, 3);
    let (p34, w34) = net(3, 4);
    format!(
        r#"{{"objects": [
        {{"name": "bspline", "type": "bspline_curve", "degree": 3, "knots": [0, 0, 0, 0, 1, 2, 3, 3, 3, 3],
          "points": [[0, 0, 0], [1, 2, 0], [2, -1, 1], [3, 1, 0], [4, 0, 2], [5, 1, 0]], "samples": 9}},
        {{"name": "bezier", "type": "bezier_curve", "points": [[0, 0, 0], [1, 1, 0], [2, 0, 1], [3, 1, 0]], "samples": 9}},
        {{"name": "nurbs", "type": "bspline_curve", "degree": 2, "knots": [0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1],
          "points": [[2, 0, 0], [2, 2, 0], [0, 2, 0], [-2, 2, 0], [-2, 0, 0], [-2, -2, 0], [0, -2, 0], [2, -2, 0], [2, 0, 0]],
          "weights": [1, 0.7071067811865476, 1, 0.7071067811865476, 1, 0.7071067811865476, 1, 0.7071067811865476, 1], "samples": 9}},
        {{"name": "rational_bezier", "type": "bezier_curve", "points": [[1, 0, 0], [1, 1, 0], [0, 1, 0]],
          "weights": [1, 0.7071067811865476, 1], "samples": 9}},
        {{"name": "surface", "type": "bspline_surface", "degree": [2, 2], "knots": [[0, 0, 0, 0.5, 1, 1, 1], [0, 0, 0, 1, 1, 1]],
          "points": {p43}, "samples": [5, 5]}},
        {{"name": "bezier_surface", "type": "bezier_surface", "points": {p33}, "samples": [5, 5]}},
        {{"name": "nurbs_surface", "type": "bspline_surface", "degree": [2, 1], "knots": [[0, 0, 0, 1, 1, 1], [0, 0, 0.4, 0.7, 1, 1]],
          "points": {p34}, "weights": {w34}, "samples": [5, 5]}},
        {{"name": "rational_bezier_surface", "type": "bezier_surface", "points": {p33}, "weights": {w33}, "samples": [5, 5]}},
        {{"name": "erbs", "type": "erbs_curve", "knots": [0, 0, 1, 2, 3, 3], "local": [
          {{"points": [[-1.2, -0.4, 0], [0.0, 1.6, 0], [1.2, -0.2, 0]]}}, {{"points": [[0.8, -0.4, 0], [2.0, 2.0, 0], [3.2, -0.2, 0]]}},
          {{"points": [[2.8, -0.4, 0], [4.0, 1.6, 0], [5.2, -0.2, 0]]}}, {{"points": [[4.8, -0.4, 0], [6.0, 2.0, 0], [7.2, -0.2, 0]]}}], "samples": 9}},
        {{"name": "erbs_surface", "type": "erbs_surface", "knots": [[0, 0, 1, 1], [0, 0, 1, 2, 2]], "local": [
          [{{"points": [[[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 0]]]}}, {{"points": [[[0, 1, 0], [0, 1.5, 0.5]], [[1, 1, 0], [1, 1.5, 0]]]}}, {{"points": [[[0, 2, 0], [1, 2, 0]]]}}],
          [{{"points": [[[1, 0, 0], [1, 0.5, 0.2]], [[2, 0, 0], [2, 1, 0]]]}}, {{"points": [[[1, 1, 1], [1, 1.5, 1]], [[2, 1, 1], [2, 2, 0]]]}}, {{"points": [[[1, 2, 0], [2, 2, 0.3]]]}}]],
          "samples": [5, 6]}},
        {{"name": "catmull_rom", "type": "catmull_rom", "points": [[0, 0, 0], [1, 2, 0], [3, 1, 0], [4, 3, 1], [6, 0, 0]], "samples": 9}},
        {{"name": "ring", "type": "catmull_rom", "points": [[1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0.5]], "closed": true, "samples": 9}},
        {{"name": "bezier_spline", "type": "bezier_spline", "degree": 3, "knots": [0, 1, 3],
          "points": [[0, 0, 0], [1, 1, 0], [2, 1, 0], [3, 0, 0], [5, -2, 0], [6, 0, 0], [7, 1, 0]], "continuity": "C1", "samples": 9}},
        {{"name": "bezier_spline_c2", "type": "bezier_spline", "degree": 3, "knots": [0, 1, 2],
          "points": [[0, 0, 0], [1, 1, 0], [2, 1, 0], [3, 0, 0], [4, -1, 0], [5, -3, 0], [6, 0, 0]], "continuity": "C2", "samples": 9}}
        ]}}"#
    )
}

/// A uniform f64 in [lo, hi) with all 53 bits random (weights like 1.4142135623730951 whose
/// quotients round).
fn uniform(rng: &mut common::Rng, lo: f64, hi: f64) -> f64 {
    lo + (hi - lo) * ((rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
}

fn vector(rng: &mut common::Rng) -> DVec3 {
    DVec3::new(
        uniform(rng, -0.7, 0.7),
        uniform(rng, -0.7, 0.7),
        uniform(rng, -0.7, 0.7),
    )
}

/// An affine map: scale, rotation and translation (last row exactly 0, 0, 0, 1).
fn affine(rng: &mut common::Rng) -> DMat4 {
    let axis = (vector(rng) + DVec3::new(0.0, 0.0, 1.0)).normalize();
    DMat4::from_scale_rotation_translation(
        DVec3::splat(uniform(rng, 0.8, 1.25)),
        DQuat::from_axis_angle(axis, uniform(rng, -0.8, 0.8)),
        vector(rng),
    )
}

/// A point edit on a net of `count` points (indices past it are refused, which is tested
/// too): move, set or weight. The label says whether the weight edit starts on a rational net.
fn point_edit<I>(rng: &mut common::Rng, index: I, rational: bool) -> (String, PointEdit<I>) {
    match rng.range(0, 3) {
        0 => (
            "move".into(),
            PointEdit::Move {
                point: index,
                delta: vector(rng),
            },
        ),
        1 => (
            "set".into(),
            PointEdit::Set {
                point: index,
                position: vector(rng) * 4.0,
            },
        ),
        _ => {
            let on = if rational { "rational" } else { "polynomial" };
            (
                format!("weight on {on}"),
                PointEdit::Weight {
                    point: index,
                    weight: uniform(rng, 0.3, 3.0),
                },
            )
        }
    }
}

/// A random edit for `model` and its label ("type: edit").
fn random_edit(rng: &mut common::Rng, model: ModelRef<'_>) -> (String, ObjectEdit) {
    let structural = rng.range(0, 5) == 0;
    let (label, edit) = match model {
        ModelRef::Curve(c) => {
            let c = c.curve();
            let (a, b) = c.domain();
            if structural && rng.range(0, 2) == 0 {
                let t = uniform(rng, a, b);
                let e = CurveEdit::InsertKnot {
                    t,
                    times: rng.range(1, 3),
                };
                ("insert_knot".into(), e.into_object())
            } else if structural && c.degree() < 5 {
                let e = CurveEdit::ElevateDegree {
                    by: rng.range(1, 3),
                };
                ("elevate_degree".into(), e.into_object())
            } else {
                let i = rng.range(0, c.points().len() + 1);
                let (l, p) = point_edit(rng, i, c.weights().is_some());
                (l, CurveEdit::Point(p).into_object())
            }
        }
        ModelRef::Surface(s) => {
            let s = s.surface();
            let [nu, nv] = s.count();
            if structural && rng.range(0, 2) == 0 {
                let dir = rng.range(0, 2);
                let (a, b) = s.domain()[dir];
                let e = SurfaceEdit::InsertKnot {
                    dir,
                    t: uniform(rng, a, b),
                    times: 1,
                };
                ("insert_knot".into(), e.into_object())
            } else if structural && s.degree().iter().all(|&d| d < 4) {
                let by = [rng.range(0, 2), rng.range(0, 2)];
                let by = if by == [0, 0] { [1, 0] } else { by };
                let e = SurfaceEdit::ElevateDegree { by };
                ("elevate_degree".into(), e.into_object())
            } else {
                let i = [rng.range(0, nu), rng.range(0, nv)];
                let (l, p) = point_edit(rng, i, s.weights().is_some());
                (l, SurfaceEdit::Point(p).into_object())
            }
        }
        ModelRef::ErbsCurve(e) => {
            let e = e.curve();
            let n = e.local_curves().len();
            let (a, b) = e.domain();
            // A local of the object, or a local of one of its ERBS locals (made by to_erbs).
            let erbs: Vec<usize> = (0..n)
                .filter(|&i| matches!(e.local_curves()[i], LocalCurve::Erbs(_)))
                .collect();
            let nested = !erbs.is_empty() && rng.range(0, 2) == 0;
            let l = if nested {
                erbs[rng.range(0, erbs.len())]
            } else {
                rng.range(0, n)
            };
            let (path, depth) = if nested {
                (LocalPath::new(&[l, rng.range(0, 3)]).unwrap(), "nested ")
            } else {
                (LocalPath::new(&[l]).unwrap(), "")
            };
            // Refinement inside a local needs an ERBS local.
            let lr = if erbs.is_empty() {
                l
            } else {
                erbs[rng.range(0, erbs.len())]
            };
            let (c, d) = match &e.local_curves()[lr] {
                LocalCurve::Erbs(inner) => inner.domain(),
                LocalCurve::Spline { .. } => (a, b),
            };
            let (label, edit) = match (structural, rng.range(0, 3)) {
                (true, 0) => (
                    "insert_knot",
                    ErbsCurveEdit::InsertKnot {
                        local: None,
                        at: uniform(rng, a, b),
                        degree: None,
                    },
                ),
                (true, 1) => (
                    "insert_knot in a local",
                    ErbsCurveEdit::InsertKnot {
                        local: Some(LocalPath::new(&[lr]).unwrap()),
                        at: uniform(rng, c, d),
                        degree: Some(2),
                    },
                ),
                (true, _) => (
                    "to_erbs",
                    ErbsCurveEdit::ToErbs {
                        local: LocalPath::new(&[l]).unwrap(),
                        count: rng.range(2, 4),
                        degree: rng.range(1, 4),
                    },
                ),
                (false, 0) => (
                    "local point",
                    ErbsCurveEdit::Local(LocalEdit::MovePoint {
                        local: path,
                        point: rng.range(0, 3),
                        delta: vector(rng),
                    }),
                ),
                (false, _) => (
                    "local transform",
                    ErbsCurveEdit::Local(LocalEdit::Transform {
                        local: path,
                        matrix: affine(rng),
                    }),
                ),
            };
            let label = if structural {
                label.to_string()
            } else {
                format!("{depth}{label}")
            };
            (label, edit.into_object())
        }
        ModelRef::ErbsSurface(e) => {
            let e = e.surface();
            let [nu, nv] = e.count();
            let erbs: Vec<[usize; 2]> = (0..nu * nv)
                .filter(|&i| matches!(e.local_patches()[i], LocalPatch::Erbs(_)))
                .map(|i| [i / nv, i % nv])
                .collect();
            let nested = !erbs.is_empty() && rng.range(0, 2) == 0;
            let l = if nested {
                erbs[rng.range(0, erbs.len())]
            } else {
                [rng.range(0, nu), rng.range(0, nv)]
            };
            let (path, depth) = if nested {
                let k = [rng.range(0, 2), rng.range(0, 2)];
                (LocalPath::new(&[l, k]).unwrap(), "nested ")
            } else {
                (LocalPath::new(&[l]).unwrap(), "")
            };
            let dir = rng.range(0, 2);
            let (a, b) = e.domain()[dir];
            let lr = if erbs.is_empty() {
                l
            } else {
                erbs[rng.range(0, erbs.len())]
            };
            let (c, d) = match &e.local_patches()[lr[0] * nv + lr[1]] {
                LocalPatch::Erbs(inner) => inner.domain()[dir],
                LocalPatch::Spline { .. } => (a, b),
            };
            let (label, edit) = match (structural, rng.range(0, 3)) {
                (true, 0) => (
                    "insert_knot",
                    ErbsSurfaceEdit::InsertKnot {
                        local: None,
                        at: (dir, uniform(rng, a, b)),
                        degree: None,
                    },
                ),
                (true, 1) => (
                    "insert_knot in a local",
                    ErbsSurfaceEdit::InsertKnot {
                        local: Some(LocalPath::new(&[lr]).unwrap()),
                        at: (dir, uniform(rng, c, d)),
                        degree: Some([1, 1]),
                    },
                ),
                (true, _) => (
                    "to_erbs",
                    ErbsSurfaceEdit::ToErbs {
                        local: LocalPath::new(&[l]).unwrap(),
                        count: [2, rng.range(2, 4)],
                        degree: [1, rng.range(1, 3)],
                    },
                ),
                (false, 0) => (
                    "local point",
                    ErbsSurfaceEdit::Local(LocalEdit::MovePoint {
                        local: path,
                        point: [rng.range(0, 2), rng.range(0, 2)],
                        delta: vector(rng),
                    }),
                ),
                (false, _) => (
                    "local transform",
                    ErbsSurfaceEdit::Local(LocalEdit::Transform {
                        local: path,
                        matrix: affine(rng),
                    }),
                ),
            };
            let label = if structural {
                label.to_string()
            } else {
                format!("{depth}{label}")
            };
            (label, edit.into_object())
        }
        ModelRef::CatmullRom(c) => {
            if structural {
                let chain = model.to_bspline_curve().unwrap();
                ("to_bspline".into(), ObjectEdit::Replace(Box::new(chain)))
            } else {
                let n = c.spline().points().len();
                let i = rng.range(0, n);
                let (l, p) = if rng.range(0, 2) == 0 {
                    (
                        "move",
                        PointEdit::Move {
                            point: i,
                            delta: vector(rng),
                        },
                    )
                } else {
                    (
                        "set",
                        PointEdit::Set {
                            point: i,
                            position: vector(rng) * 4.0,
                        },
                    )
                };
                (l.into(), CatmullRomEdit::Point(p).into_object())
            }
        }
        ModelRef::BezierSpline(s) => {
            if structural {
                let chain = model.to_bspline_curve().unwrap();
                ("to_bspline".into(), ObjectEdit::Replace(Box::new(chain)))
            } else {
                let e = BezierSplineEdit::Move {
                    point: rng.range(0, s.spline().points().len()),
                    delta: vector(rng),
                };
                ("move".into(), e.into_object())
            }
        }
    };
    (format!("{}: {label}", model.type_name()), edit)
}

/// Every model of the document, as text that differs whenever one f64 bit does.
fn fingerprint(ed: &Editor) -> Vec<String> {
    ed.doc()
        .objects
        .iter()
        .map(|o| format!("{}: {:?}", o.name, o.sampled.model()))
        .collect()
}

/// The first object whose model differs, with a little context around the first difference.
fn difference(got: &[String], want: &[String]) -> String {
    for (g, w) in got.iter().zip(want) {
        if g != w {
            let at = g
                .bytes()
                .zip(w.bytes())
                .position(|(a, b)| a != b)
                .unwrap_or(g.len().min(w.len()));
            let around = |s: &str| {
                let bytes = &s.as_bytes()[at.saturating_sub(80)..(at + 80).min(s.len())];
                String::from_utf8_lossy(bytes).into_owned()
            };
            return format!("\n got: …{}…\nwant: …{}…", around(g), around(w));
        }
    }
    String::new()
}

/// One random chain; returns the labels of the edits whose undo was checked.
fn chain(seed: u64, steps: usize) -> BTreeSet<String> {
    let scene = parse_scene(&scene_text()).unwrap();
    let mut rng = common::Rng::new(seed);
    let mut ed = common::editor(&scene, None);
    let start = fingerprint(&ed);
    let mut now = start.clone();
    // The state before each done step (with its labels), and after each undone one.
    let mut before: Vec<(Vec<String>, Vec<String>)> = Vec::new();
    let mut redo_to: Vec<(Vec<String>, Vec<String>)> = Vec::new();
    let mut covered = BTreeSet::new();
    let n = scene.objects.len();
    let mut undo = |ed: &mut Editor,
                    now: &mut Vec<String>,
                    before: &mut Vec<(Vec<String>, Vec<String>)>,
                    redo_to: &mut Vec<(Vec<String>, Vec<String>)>| {
        let (want, labels) = before.pop().unwrap();
        assert!(ed.undo().is_some(), "seed {seed}: nothing to undo");
        let got = fingerprint(ed);
        assert!(
            got == want,
            "seed {seed}: undo of {labels:?} did not give back the model bit for bit:{}",
            difference(&got, &want)
        );
        covered.extend(labels.iter().cloned());
        redo_to.push((std::mem::replace(now, got), labels));
    };
    for _ in 0..steps {
        match rng.range(0, 10) {
            0..=2 if !before.is_empty() => undo(&mut ed, &mut now, &mut before, &mut redo_to),
            3 if !redo_to.is_empty() => {
                let (want, labels) = redo_to.pop().unwrap();
                assert!(ed.redo().is_some());
                let got = fingerprint(&ed);
                assert!(
                    got == want,
                    "seed {seed}: redo of {labels:?} differs:{}",
                    difference(&got, &want)
                );
                before.push((std::mem::replace(&mut now, got), labels));
            }
            _ => {
                ed.begin("step");
                let mut labels = Vec::new();
                for _ in 0..rng.range(1, 4) {
                    let object = rng.range(0, n);
                    let (label, edit) =
                        random_edit(&mut rng, ed.doc().objects[object].sampled.model());
                    if ed.submit(Edit { object, edit }).is_ok() {
                        labels.push(label);
                    }
                }
                ed.end();
                ed.apply_pending();
                if !labels.is_empty() {
                    before.push((std::mem::replace(&mut now, fingerprint(&ed)), labels));
                    redo_to.clear();
                }
            }
        }
    }
    while !before.is_empty() {
        undo(&mut ed, &mut now, &mut before, &mut redo_to);
    }
    assert!(
        now == start,
        "seed {seed}: back at the start:{}",
        difference(&now, &start)
    );
    covered
}

#[test]
fn undo_gives_back_every_model_bit_for_bit() {
    let mut covered = BTreeSet::new();
    for seed in 1..=32 {
        covered.extend(chain(seed, 120));
    }
    // Every edit kind on every object kind was undone at least once, weights on nets that
    // started rational (no whole-model restore hides them) and on polynomial ones.
    let mut missing = Vec::new();
    for (kind, edits) in [
        (
            "bspline_curve",
            &[
                "move",
                "set",
                "weight on rational",
                "weight on polynomial",
                "insert_knot",
                "elevate_degree",
            ][..],
        ),
        (
            "bezier_curve",
            &[
                "move",
                "set",
                "weight on rational",
                "weight on polynomial",
                "insert_knot",
                "elevate_degree",
            ],
        ),
        (
            "bspline_surface",
            &[
                "move",
                "set",
                "weight on rational",
                "weight on polynomial",
                "insert_knot",
                "elevate_degree",
            ],
        ),
        (
            "bezier_surface",
            &[
                "move",
                "set",
                "weight on rational",
                "weight on polynomial",
                "insert_knot",
                "elevate_degree",
            ],
        ),
        (
            "erbs_curve",
            &[
                "local point",
                "local transform",
                "nested local point",
                "nested local transform",
                "insert_knot",
                "insert_knot in a local",
                "to_erbs",
            ],
        ),
        (
            "erbs_surface",
            &[
                "local point",
                "local transform",
                "nested local point",
                "nested local transform",
                "insert_knot",
                "insert_knot in a local",
                "to_erbs",
            ],
        ),
        ("catmull_rom", &["move", "set", "to_bspline"]),
        ("bezier_spline", &["move", "to_bspline"]),
    ] {
        for e in edits {
            let label = format!("{kind}: {e}");
            if !covered.contains(&label) {
                missing.push(label);
            }
        }
    }
    assert!(
        missing.is_empty(),
        "never undone: {missing:?}\ncovered: {covered:?}"
    );
}
