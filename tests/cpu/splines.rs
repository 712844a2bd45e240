//! Catmull–Rom and Bézier splines through the scene format and the pre-evaluation engine,
//! against an independent piecewise Bézier evaluator written here (de Casteljau on the
//! segment's points, derivatives from forward differences), never `prespline::geom`.

use glam::DVec3;
use prespline::formats::parse_scene;
use prespline::model::SampledObject;
use prespline::model::exact::exact_grid;
use prespline::model::{
    BezierSplineEdit, CatmullRomEdit, KindEdit, Model, ModelRef, ObjectEdit, PointEdit,
};
use prespline::sampling::{PartialSet, SampleMode};
use prespline::scene::Scene;

use crate::common;
use common::Rng;

// ---------------------------------------------------------------------------------------------
// The independent evaluator.

/// c, c', …, c^(n) of the Bézier curve `pts` over [a, b] at t: de Casteljau on the r-th forward
/// differences, times d!/(d−r)! / (b−a)^r.
fn bezier(pts: &[DVec3], a: f64, b: f64, t: f64, n: usize) -> Vec<DVec3> {
    let s = (t - a) / (b - a);
    let mut diffs = pts.to_vec();
    let mut out = Vec::with_capacity(n + 1);
    let mut factor = 1.0;
    for r in 0..=n {
        if diffs.is_empty() {
            out.push(DVec3::ZERO);
            continue;
        }
        let mut c = diffs.clone();
        for k in 1..c.len() {
            for i in 0..c.len() - k {
                c[i] = c[i] * (1.0 - s) + c[i + 1] * s;
            }
        }
        out.push(c[0] * factor);
        let d = diffs.len() - 1;
        factor *= d as f64 / (b - a);
        diffs = diffs.windows(2).map(|w| w[1] - w[0]).collect();
        let _ = r;
    }
    out
}

/// A piecewise Bézier curve: segment j has points `pts[j·d ..= (j+1)·d]` over
/// [breaks[j], breaks[j+1]].
struct Piecewise {
    degree: usize,
    breaks: Vec<f64>,
    pts: Vec<DVec3>,
}

impl Piecewise {
    fn segment(&self, j: usize) -> &[DVec3] {
        &self.pts[j * self.degree..=(j + 1) * self.degree]
    }

    /// Derivatives at t, from the segment containing t (the last one for its right end).
    fn eval(&self, t: f64, n: usize) -> Vec<DVec3> {
        let k = self.breaks.len() - 1;
        let j = (0..k)
            .rev()
            .find(|&j| t >= self.breaks[j])
            .unwrap_or(0)
            .min(k - 1);
        self.limit(j, t, n)
    }

    fn limit(&self, j: usize, t: f64, n: usize) -> Vec<DVec3> {
        bezier(self.segment(j), self.breaks[j], self.breaks[j + 1], t, n)
    }
}

/// The lecture's Catmull–Rom construction, spelled out: T_j = (P_{j+1} − P_{j−1})/2, end
/// tangents (P_1 − P_0)/2 and (P_{k+1} − P_k)/2, segment j = [P_j, P_j + T_j/3,
/// P_{j+1} − T_{j+1}/3, P_{j+1}] over [j, j+1].
fn lecture_catmull_rom(p: &[DVec3]) -> Piecewise {
    let n = p.len();
    let t = |j: usize| {
        if j == 0 {
            (p[1] - p[0]) / 2.0
        } else if j == n - 1 {
            (p[n - 1] - p[n - 2]) / 2.0
        } else {
            (p[j + 1] - p[j - 1]) / 2.0
        }
    };
    let mut pts = vec![p[0]];
    for j in 0..n - 1 {
        pts.push(p[j] + t(j) / 3.0);
        pts.push(p[j + 1] - t(j + 1) / 3.0);
        pts.push(p[j + 1]);
    }
    Piecewise {
        degree: 3,
        breaks: (0..n).map(|j| j as f64).collect(),
        pts,
    }
}

fn close(a: DVec3, b: DVec3, scale: f64, tol: f64) -> bool {
    (a - b).abs().max_element() <= tol * scale.max(1.0)
}

/// Every sample (and its derivatives up to `n`) of `obj` against `curve`, relative to each
/// order's largest magnitude.
fn assert_samples_match(obj: &SampledObject, curve: &Piecewise, n: usize, tol: f64, what: &str) {
    let params = obj.params()[0].to_vec();
    let grid = obj.grid();
    let expect: Vec<Vec<DVec3>> = params.iter().map(|&t| curve.eval(t, n)).collect();
    for r in 0..=n.min(grid.stride() - 1) {
        let scale = expect
            .iter()
            .map(|e| e[r].abs().max_element())
            .fold(0.0, f64::max);
        for (j, e) in expect.iter().enumerate() {
            let got = grid.sample(j, 0)[r];
            assert!(
                close(got, e[r], scale, tol),
                "{what}: sample {j} (t = {}) order {r}: {got} vs {}",
                params[j],
                e[r]
            );
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Scenes.

fn points_json(p: &[DVec3]) -> String {
    let items: Vec<String> = p
        .iter()
        .map(|q| format!("[{:?}, {:?}, {:?}]", q.x, q.y, q.z))
        .collect();
    format!("[{}]", items.join(", "))
}

fn random_points(rng: &mut Rng, n: usize) -> Vec<DVec3> {
    (0..n)
        .map(|i| {
            DVec3::new(
                i as f64 + rng.f32(-0.3, 0.3) as f64,
                rng.f32(-2.0, 2.0) as f64,
                rng.f32(-1.0, 1.0) as f64,
            )
        })
        .collect()
}

fn one(scene: &str) -> Model {
    parse_scene(scene)
        .unwrap_or_else(|e| panic!("{e}"))
        .objects
        .remove(0)
        .model
}

// ---------------------------------------------------------------------------------------------
// Catmull–Rom.

#[test]
fn catmull_rom_is_the_lecture_construction_exactly() {
    let mut rng = Rng::new(11);
    for n in [2, 3, 4, 7, 12] {
        let p = random_points(&mut rng, n);
        let text = format!(
            r#"{{"objects": [{{"name": "c", "type": "catmull_rom", "points": {}, "samples": 301}}]}}"#,
            points_json(&p)
        );
        let model = one(&text);
        let lecture = lecture_catmull_rom(&p);
        // The chain's Bézier points are the lecture's, bit for bit.
        let ModelRef::CatmullRom(m) = model.as_ref() else {
            panic!("not a catmull_rom")
        };
        assert_eq!(m.spline().bezier_points(), lecture.pts, "{n} points");
        // Interpolation and the lecture's tangents at every P_j (one-sided limits at both
        // sides of each junction): c(j) = P_j and c'(j) = T_j.
        let chain = model.as_ref().to_bspline_curve().unwrap();
        let Model::Curve(b) = chain else { panic!() };
        for j in 0..n {
            let t = j as f64;
            let d = b.curve().derivatives(t, 1);
            assert_eq!(b.curve().eval(t), p[j], "interpolates P_{j}");
            let tangent = if j == 0 {
                (p[1] - p[0]) / 2.0
            } else if j == n - 1 {
                (p[n - 1] - p[n - 2]) / 2.0
            } else {
                (p[j + 1] - p[j - 1]) / 2.0
            };
            assert!(close(d[1], tangent, tangent.length(), 1e-14), "T_{j}");
            for side in [j.checked_sub(1), (j + 1 < n).then_some(j)] {
                let Some(seg) = side else { continue };
                let l = lecture.limit(seg, t, 1);
                assert!(close(l[0], p[j], 1.0, 0.0), "segment {seg} ends at P_{j}");
                assert!(close(l[1], tangent, tangent.length(), 1e-14));
            }
        }
        // And the engine samples it: positions and first and second derivatives.
        for mode in [SampleMode::Render, SampleMode::Derivatives(3)] {
            let obj = SampledObject::new(&model, mode);
            let order = if mode == SampleMode::Render { 1 } else { 3 };
            assert_samples_match(&obj, &lecture, order, 1e-13, "catmull_rom");
        }
    }
}

#[test]
fn catmull_rom_edits_touch_at_most_four_segments_and_equal_full_sampling() {
    let mut rng = Rng::new(5);
    for (par, closed) in [
        ("uniform", false),
        ("centripetal", false),
        ("chordal", false),
        ("centripetal", true),
        ("uniform", true),
    ] {
        let n = 12;
        let p = random_points(&mut rng, n);
        let text = format!(
            r#"{{"objects": [{{"name": "c", "type": "catmull_rom", "points": {}, "parametrization": "{par}", "closed": {closed}, "samples": 1201}}]}}"#,
            points_json(&p)
        );
        let model = one(&text);
        let segments = if closed { n } else { n - 1 };
        let per_segment = 1200 / segments;
        let mut obj = SampledObject::new(&model, SampleMode::Derivatives(2));
        let mut reference = model.clone();
        for step in 0..300 {
            let point = rng.range(0, n);
            let delta = DVec3::new(
                rng.f32(-0.2, 0.2) as f64,
                rng.f32(-0.2, 0.2) as f64,
                rng.f32(-0.2, 0.2) as f64,
            );
            let edit = CatmullRomEdit::Point(PointEdit::Move { point, delta }).into_object();
            edit.validate(reference.as_ref()).unwrap();
            let region = obj.apply(&edit).unwrap();
            reference.apply(&edit).unwrap();
            // A seam point of a closed spline touches both ends: the reported span is their hull.
            let wraps = closed && (point < 2 || point + 2 >= n);
            if !wraps {
                assert!(
                    region.samples() <= 4 * (per_segment + 1) + 1,
                    "{par}: step {step} moved P{point} and touched {} samples",
                    region.samples()
                );
            }
        }
        let fresh = exact_grid(reference.as_ref(), &PartialSet::Curve(2));
        let d = obj.grid().max_relative_difference(&fresh);
        assert!(d < 1e-12, "{par} closed {closed}: delta vs exact {d:e}");
        // The model the delta path carried is the model the edits describe.
        assert_eq!(obj.model().to_model(), reference);
    }
}

// ---------------------------------------------------------------------------------------------
// Bézier splines.

/// A spline scene of every continuity the editor keeps, with unequal intervals.
fn splines() -> Vec<Model> {
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/bezier_spline.json"),
    )
    .unwrap();
    let mut out: Vec<Model> = parse_scene(&text)
        .unwrap()
        .objects
        .into_iter()
        .map(|o| o.model)
        .collect();
    // Quadratic C1 (de Boor editing) and quintic C2 (mirrors), built here from the conditions.
    let q = [
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 2.0, 0.0),
        DVec3::new(3.0, 1.0, 0.5),
        DVec3::new(4.0, -1.0, 0.0),
        DVec3::new(6.0, 0.0, 1.0),
    ];
    // Junctions as the h-weighted means of their neighbours (the lecture's quadratic B-spline).
    let h = [1.0, 0.5, 2.0];
    let mut pts = vec![q[0], q[1]];
    for j in 1..3 {
        pts.push((q[j] * h[j] + q[j + 1] * h[j - 1]) / (h[j - 1] + h[j]));
        pts.push(q[j + 1]);
    }
    pts.push(q[4]);
    out.push(one(&format!(
        r#"{{"objects": [{{"name": "q", "type": "bezier_spline", "degree": 2, "knots": [0, 1, 1.5, 3.5], "points": {}, "continuity": "C1", "samples": 200}}]}}"#,
        points_json(&pts)
    )));
    let mut pts: Vec<DVec3> = (0..6)
        .map(|i| DVec3::new(i as f64, ((i * 7) % 5) as f64 * 0.3, 0.0))
        .collect();
    let r = 0.4 / 1.0;
    let j = 5;
    let m1 = pts[j] + (pts[j] - pts[j - 1]) * r;
    let m2 = m1 * 2.0 - pts[j] + (pts[j] - pts[j - 1] * 2.0 + pts[j - 2]) * (r * r);
    pts.extend([
        m1,
        m2,
        DVec3::new(7.0, 2.0, 1.0),
        DVec3::new(8.0, 1.0, 0.0),
        DVec3::new(9.0, 0.0, 0.0),
    ]);
    out.push(one(&format!(
        r#"{{"objects": [{{"name": "quintic", "type": "bezier_spline", "degree": 5, "knots": [0, 1, 1.4], "points": {}, "continuity": "C2", "samples": 200}}]}}"#,
        points_json(&pts)
    )));
    out
}

fn piecewise(m: &Model) -> Piecewise {
    let ModelRef::BezierSpline(s) = m.as_ref() else {
        panic!("not a bezier_spline")
    };
    let s = s.spline();
    Piecewise {
        degree: s.degree(),
        breaks: s.knots().to_vec(),
        pts: s.points().to_vec(),
    }
}

/// Checks the declared continuity at every junction from the left and right limits of the
/// independent evaluator.
fn assert_continuity(m: &Model, what: &str) {
    let ModelRef::BezierSpline(s) = m.as_ref() else {
        panic!()
    };
    assert_junctions(&piecewise(m), s.spline().continuity().name(), what);
}

fn assert_junctions(pw: &Piecewise, c: &str, what: &str) {
    let size = pw
        .pts
        .iter()
        .fold(1.0f64, |a, p| a.max(p.abs().max_element()));
    for j in 1..pw.breaks.len() - 1 {
        let t = pw.breaks[j];
        let (l, r) = (pw.limit(j - 1, t, 2), pw.limit(j, t, 2));
        let at = format!("{what}: {c} junction {j}");
        assert!(close(l[0], r[0], size, 1e-14), "{at}: positions");
        match c {
            "C0" => {}
            "G1" => {
                let (a, b) = (l[1].normalize(), r[1].normalize());
                assert!(close(a, b, 1.0, 1e-10), "{at}: tangents {a} {b}");
            }
            _ => {
                let s1 = l[1].length().max(r[1].length());
                assert!(close(l[1], r[1], s1, 1e-10), "{at}: c' {} {}", l[1], r[1]);
                if c == "C2" {
                    let s2 = l[2].length().max(r[2].length());
                    assert!(close(l[2], r[2], s2, 1e-10), "{at}: c'' {} {}", l[2], r[2]);
                }
            }
        }
    }
}

#[test]
fn bezier_splines_agree_with_a_piecewise_bezier_evaluation() {
    for m in splines() {
        let pw = piecewise(&m);
        for mode in [SampleMode::Render, SampleMode::Derivatives(3)] {
            let obj = SampledObject::new(&m, mode);
            let order = if mode == SampleMode::Render { 1 } else { 3 };
            assert_samples_match(&obj, &pw, order, 1e-12, m.type_name());
        }
        assert_continuity(&m, "as loaded");
    }
}

#[test]
fn random_edits_keep_the_declared_continuity_and_the_delta_path_exact() {
    let mut rng = Rng::new(77);
    for m in splines() {
        let ModelRef::BezierSpline(s) = m.as_ref() else {
            panic!()
        };
        let handles = s.spline().handle_count();
        let name = format!(
            "{} degree {}",
            s.spline().continuity().name(),
            s.spline().degree()
        );
        let mut obj = SampledObject::new(&m, SampleMode::Derivatives(2));
        let mut inverses: Vec<ObjectEdit> = Vec::new();
        let mut history = vec![m.clone()];
        for step in 0..400 {
            let point = rng.range(0, handles);
            let delta = DVec3::new(
                rng.f32(-0.3, 0.3) as f64,
                rng.f32(-0.3, 0.3) as f64,
                rng.f32(-0.3, 0.3) as f64,
            );
            let edit = BezierSplineEdit::Move { point, delta }.into_object();
            let model = obj.model().to_model();
            if edit.validate(model.as_ref()).is_err() {
                continue;
            }
            inverses.push(edit.inverse(model.as_ref()).unwrap());
            obj.apply(&edit).unwrap();
            let now = obj.model().to_model();
            if step % 50 == 0 {
                assert_continuity(&now, &format!("{name} after {step} edits"));
            }
            history.push(now);
        }
        let last = obj.model().to_model();
        assert_continuity(&last, &format!("{name} after every edit"));
        let fresh = exact_grid(last.as_ref(), &PartialSet::Curve(2));
        let d = obj.grid().max_relative_difference(&fresh);
        assert!(d < 1e-12, "{name}: delta path vs exact {d:e}");
        // Undo: each inverse brings the previous model back bit for bit.
        history.pop();
        for inv in inverses.iter().rev() {
            obj.apply(inv).unwrap();
            let expect = history.pop().unwrap();
            assert!(
                obj.model().to_model() == expect,
                "{name}: inverse not exact"
            );
        }
        assert!(history.is_empty());
    }
}

#[test]
fn moves_spread_as_documented() {
    // C1 cubic: P4 (after junction 3) mirrors P2 with ratio h0/h1; the junction carries both.
    let m = splines().remove(0);
    let ModelRef::BezierSpline(s) = m.as_ref() else {
        panic!()
    };
    let s = s.spline();
    assert_eq!(s.continuity().name(), "C1");
    let (h0, h1) = (s.knots()[1] - s.knots()[0], s.knots()[2] - s.knots()[1]);
    let d = DVec3::new(0.5, -0.25, 0.125);
    let moves = s.move_handle(4, d).unwrap();
    let idx: Vec<usize> = moves.iter().map(|m| m.0).collect();
    assert_eq!(idx, vec![4, 2]);
    let p4 = s.points()[4] + d;
    let p2 = s.points()[3] - (p4 - s.points()[3]) * (h0 / h1);
    assert!(close(moves[1].1, p2, 10.0, 1e-15));
    let moves = s.move_handle(3, d).unwrap();
    let mut idx: Vec<usize> = moves.iter().map(|m| m.0).collect();
    idx.sort();
    assert_eq!(idx, vec![2, 3, 4]);
    for (i, p) in moves {
        assert_eq!(p, s.points()[i] + d);
    }
    // G1: the opposite handle keeps its length and turns to the moved one's direction.
    let g = splines().remove(2);
    let ModelRef::BezierSpline(g) = g.as_ref() else {
        panic!()
    };
    let g = g.spline();
    assert_eq!(g.continuity().name(), "G1");
    let before = (g.points()[2] - g.points()[3]).length();
    let moves = g.move_handle(4, DVec3::new(0.0, 1.0, 0.0)).unwrap();
    let (_, p2) = moves.iter().find(|m| m.0 == 2).copied().unwrap();
    let leg = g.points()[4] + DVec3::new(0.0, 1.0, 0.0) - g.points()[3];
    assert!(((p2 - g.points()[3]).length() - before).abs() < 1e-14);
    assert!(close(
        (g.points()[3] - p2).normalize(),
        leg.normalize(),
        1.0,
        1e-15
    ));
    // Onto the junction: refused.
    let onto = g.points()[3] - g.points()[4];
    assert!(g.move_handle(4, onto).is_err());
}

#[test]
fn conversion_to_bspline_keeps_the_shape_and_undoes_exactly() {
    let scene: Scene = parse_scene(
        &std::fs::read_to_string(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/catmull_rom.json"),
        )
        .unwrap(),
    )
    .unwrap();
    for o in scene.objects.iter().chain(
        parse_scene(
            &std::fs::read_to_string(
                std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                    .join("examples/bezier_spline.json"),
            )
            .unwrap(),
        )
        .unwrap()
        .objects
        .iter(),
    ) {
        let mut obj = SampledObject::new(&o.model, SampleMode::Derivatives(2));
        let before = obj.grid().clone();
        let chain = o.model.as_ref().to_bspline_curve().unwrap();
        let edit = ObjectEdit::Replace(Box::new(chain));
        let inverse = edit.inverse(obj.model()).unwrap();
        obj.apply(&edit).unwrap();
        assert_eq!(obj.type_name(), "bspline_curve");
        let d = obj.grid().max_relative_difference(&before);
        assert!(d < 1e-13, "{}: {d:e}", o.name);
        obj.apply(&inverse).unwrap();
        assert!(obj.model().to_model() == o.model);
        assert!(obj.grid() == &before, "{}: samples after undo", o.name);
    }
}

#[test]
fn files_round_trip_bit_for_bit() {
    for f in ["examples/catmull_rom.json", "examples/bezier_spline.json"] {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(f);
        let scene = prespline::formats::read_json(&path).unwrap();
        let text = prespline::formats::json::scene_to_json(&scene);
        assert_eq!(parse_scene(&text).unwrap(), scene, "{f}");
    }
}

#[test]
fn the_comparisons_fail_on_perturbed_input() {
    let caught = |f: &dyn Fn()| std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).is_err();
    let m = splines().remove(1);
    let obj = SampledObject::new(&m, SampleMode::Derivatives(2));
    let mut pw = piecewise(&m);
    assert!(!caught(&|| assert_samples_match(
        &obj,
        &pw,
        2,
        1e-12,
        "unperturbed"
    )));
    // One inner point moved by 1e-9 of the curve's size: samples and second derivatives move.
    pw.pts[4] += DVec3::new(0.0, 3e-9, 0.0);
    assert!(caught(&|| assert_samples_match(
        &obj,
        &pw,
        2,
        1e-12,
        "perturbed"
    )));
    assert!(caught(&|| assert_junctions(&pw, "C2", "perturbed")));
    assert!(caught(&|| assert_junctions(&pw, "C1", "perturbed")));
    let mut g = piecewise(&splines().remove(2));
    assert!(!caught(&|| assert_junctions(&g, "G1", "unperturbed")));
    g.pts[4] += DVec3::new(0.0, 0.0, 1e-6);
    assert!(caught(&|| assert_junctions(&g, "G1", "perturbed")));
}

// ---------------------------------------------------------------------------------------------
// Continuity badges.

#[test]
fn badges_name_each_constructed_junction() {
    use prespline::render::analysis::curve_joins;
    // tests/data/badges.json: a cubic spline declared C0 whose junctions were built (by a
    // script from the lecture's conditions, outside this crate) to be, in order: C2, C1 with
    // equal curvature vectors, C1, G2 (derivatives scaled by γ, γ²), G1, G0.
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/badges.json"),
    )
    .unwrap();
    let m = one(&text);
    let labels: Vec<&str> = curve_joins(m.as_ref())
        .iter()
        .map(|j| j.class.label())
        .collect();
    assert_eq!(labels, ["C2", "C1 G2", "C1", "G2", "G1", "G0"]);
    // The independent evaluator agrees on the parametric part of each class.
    let pw = piecewise(&m);
    for (j, want) in labels.iter().enumerate() {
        let t = pw.breaks[j + 1];
        let (l, r) = (pw.limit(j, t, 2), pw.limit(j + 1, t, 2));
        let c1 = close(l[1], r[1], l[1].length(), 1e-12);
        let c2 = c1 && close(l[2], r[2], l[2].length(), 1e-12);
        assert_eq!(c1, want.starts_with('C'), "junction {}", j + 1);
        assert_eq!(c2, *want == "C2", "junction {}", j + 1);
    }
    // Catmull–Rom: uniform knots are C1 at every point; centripetal ones G1 (C1 in the knot
    // parameter, written over [j, j+1]) unless neighbouring chords are equal.
    let mut rng = Rng::new(3);
    let p = random_points(&mut rng, 6);
    for (par, want) in [("uniform", "C1"), ("centripetal", "G1")] {
        let m = one(&format!(
            r#"{{"objects": [{{"name": "c", "type": "catmull_rom", "points": {}, "parametrization": "{par}", "samples": 50}}]}}"#,
            points_json(&p)
        ));
        let joins = curve_joins(m.as_ref());
        assert_eq!(joins.len(), 4);
        for j in joins {
            assert_eq!(j.class.label(), want, "{par} at {}", j.t);
        }
    }
}

/// The lecture's construction for a closed point list: T_j = (P_{j+1} − P_{j−1})/2 with indices
/// taken cyclically, one segment per pair including the closing one (P_{n−1}, P_0).
fn lecture_closed_catmull_rom(p: &[DVec3]) -> Piecewise {
    let n = p.len();
    let at = |j: usize| p[j % n];
    let t = |j: usize| (at(j + 1) - at(j + n - 1)) / 2.0;
    let mut pts = vec![p[0]];
    for j in 0..n {
        pts.push(at(j) + t(j) / 3.0);
        pts.push(at(j + 1) - t(j + 1) / 3.0);
        pts.push(at(j + 1));
    }
    Piecewise {
        degree: 3,
        breaks: (0..=n).map(|j| j as f64).collect(),
        pts,
    }
}

#[test]
fn closed_curves_have_a_badge_at_their_seam() {
    use prespline::geom::continuity::classify;
    use prespline::render::analysis::curve_joins;
    // A closed uniform Catmull–Rom through n points has n junctions: 1 … n−1 and the seam,
    // where segment n−1 ends (t = n) and segment 0 starts (t = 0). It is C1 there like
    // everywhere (the cyclic tangent), not C2: the seam's left limit comes from the end.
    let mut rng = Rng::new(5);
    let p = random_points(&mut rng, 6);
    let m = one(&format!(
        r#"{{"objects": [{{"name": "ring", "type": "catmull_rom", "points": {}, "closed": true, "samples": 60}}]}}"#,
        points_json(&p)
    ));
    let joins = curve_joins(m.as_ref());
    let ts: Vec<f64> = joins.iter().map(|j| j.t).collect();
    assert_eq!(ts, [0.0, 1.0, 2.0, 3.0, 4.0, 5.0]);
    assert_eq!(joins[0].position, p[0]);
    for j in &joins {
        assert_eq!(j.class.label(), "C1", "closed uniform at {}", j.t);
    }
    // The independent evaluator's limits across the seam classify the same.
    let pw = lecture_closed_catmull_rom(&p);
    let (l, r) = (pw.limit(5, 6.0, 2), pw.limit(0, 0.0, 2));
    let size = p.iter().fold(0.0f64, |m, q| m.max(q.abs().max_element()));
    assert_eq!(
        classify([l[0], l[1], l[2]], [r[0], r[1], r[2]], size),
        joins[0].class
    );
    assert!(close(l[0], joins[0].position, size, 1e-15));

    // examples/catmull_rom.json: the closed centripetal ring has 8 points, so 8 badges; the
    // open curves of 7 points have 5 each.
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/catmull_rom.json"),
    )
    .unwrap();
    let scene = parse_scene(&text).unwrap();
    let counts: Vec<(&str, usize)> = scene
        .objects
        .iter()
        .map(|o| (o.name.as_str(), curve_joins(o.model.as_ref()).len()))
        .collect();
    assert_eq!(
        counts,
        [
            ("uniform", 5),
            ("centripetal", 5),
            ("chordal", 5),
            ("closed_ring", 8)
        ]
    );
    let ring = curve_joins(scene.objects[3].model.as_ref());
    assert_eq!(ring[0].t, 0.0);
    // Centripetal knots: one tangent direction at every junction, the seam included (G1, or
    // C1 where neighbouring chords happen to be equal).
    for j in &ring {
        assert!(
            matches!(j.class.label(), "G1" | "C1"),
            "ring at {}: {}",
            j.t,
            j.class.label()
        );
    }

    // ERBS curves get no badges, closed ones neither: the blend is C^∞ across the seam too.
    let erbs = one(
        r#"{"objects": [{"name": "e", "type": "erbs_curve", "closed": true, "knots": [0, 1, 2, 3],
        "local": [{"points": [[1,0,0],[1,1,0]]}, {"points": [[0,1,0],[-1,0,0]]}, {"points": [[-1,-1,0],[1,-1,0]]}],
        "samples": 30}]}"#,
    );
    assert!(curve_joins(erbs.as_ref()).is_empty());
}
