//! Trimmed surfaces (docs/performance.md, "Trims"): the cost of an edit on a trimmed surface
//! against the same surface untrimmed — the editor's whole route, submit and apply, since the
//! trim sits beside the samplers and no edit reads it — and building the trims of a model of
//! 100, 200 and 400 faces, each with an outer loop of 28 curves (24 lines and 4 quarter arcs)
//! and a circular hole, from the loops as given to validated regions.
//!
//! `cargo bench --bench trims` runs criterion; docs/performance.md ("Trimmed surfaces") has the
//! ratio of the edits and the build time per face from its estimates.

use criterion::{BenchmarkId, Criterion};
use glam::{DVec2, DVec3};
use prespline::editor::{Editor, EditorOptions};
use prespline::geom::trim::{LoopSpec, Trim, TrimCurve, TrimPiece, Trimmed};
use prespline::geom::{KnotVector, TensorSurface};
use prespline::model::{Edit, Model, ObjectEdit, PointEdit, SplineForm, SurfaceEdit, SurfaceModel};
use prespline::sampling::SampleMode;
use prespline::sampling::budget::{MemoryBudget, Uses};
use prespline::scene::{Scene, SceneObject};
use std::f64::consts::{FRAC_1_SQRT_2, FRAC_PI_2};
use std::hint::black_box;

/// The sampling benchmark's surface: bicubic, 100 × 100 control points, 512² samples.
fn surface() -> Model {
    let n = 100;
    let pts = (0..n * n)
        .map(|k| {
            let (i, j) = ((k / n) as f64, (k % n) as f64);
            DVec3::new(i, j, (0.3 * i).sin() * (0.2 * j).cos())
        })
        .collect();
    let k = KnotVector::clamped_uniform(3, n, 0.0, 1.0).into_vec();
    let s = TensorSurface::bspline([3, 3], [k.clone(), k], [n, n], pts, None).unwrap();
    Model::Surface(SurfaceModel::new(SplineForm::BSpline, s, [512, 512]).unwrap())
}

/// A quarter arc of radius `r` about `c` from angle `a` (rational quadratic).
fn arc(c: DVec2, r: f64, a: f64) -> TrimCurve {
    let at = |t: f64| c + r * DVec2::new(t.cos(), t.sin());
    let mid =
        c + r * 2f64.sqrt() * DVec2::new((a + FRAC_PI_2 / 2.0).cos(), (a + FRAC_PI_2 / 2.0).sin());
    TrimCurve::bezier(
        &[at(a), mid, at(a + FRAC_PI_2)],
        Some(vec![1.0, FRAC_1_SQRT_2, 1.0]),
    )
    .unwrap()
}

/// A rounded rectangle of 24 lines and 4 quarter arcs in [0, 1]², with a circular hole.
fn face_trim() -> Trim {
    let (lo, hi, r) = (0.05, 0.95, 0.1);
    let corners = [
        (DVec2::new(hi - r, lo + r), -FRAC_PI_2),
        (DVec2::new(hi - r, hi - r), 0.0),
        (DVec2::new(lo + r, hi - r), FRAC_PI_2),
        (DVec2::new(lo + r, lo + r), std::f64::consts::PI),
    ];
    let on = |c: DVec2, t: f64| c + r * DVec2::new(t.cos(), t.sin());
    let mut pieces = Vec::new();
    for (k, &(c, a)) in corners.iter().enumerate() {
        pieces.push(TrimPiece::whole(arc(c, r, a)));
        // The straight side to the next corner's arc, in 6 lines.
        let (next, b) = corners[(k + 1) % 4];
        let (from, to) = (on(c, a + FRAC_PI_2), on(next, b));
        for s in 0..6 {
            let p = |t: f64| from.lerp(to, t);
            let line =
                TrimCurve::polyline(vec![p(s as f64 / 6.0), p((s + 1) as f64 / 6.0)]).unwrap();
            pieces.push(TrimPiece::whole(line));
        }
    }
    let hole = (0..4)
        .map(|q| TrimPiece::whole(arc(DVec2::splat(0.5), 0.2, q as f64 * FRAC_PI_2)))
        .collect();
    Trim {
        loops: vec![
            LoopSpec { pieces, role: None },
            LoopSpec {
                pieces: hole,
                role: None,
            },
        ],
    }
}

fn editor(trimmed: bool) -> Editor {
    let trim = trimmed.then(|| Trimmed::new(face_trim(), [(0.0, 1.0), (0.0, 1.0)]).unwrap());
    let scene = Scene {
        objects: vec![SceneObject {
            name: "s".into(),
            model: surface(),
            color: None,
            kept: Default::default(),
            trim,
        }],
    };
    let options = EditorOptions {
        mode: SampleMode::Render,
        uses: Uses {
            gpu_slots: 2,
            control_displays: true,
            json_text: false,
        },
        budget: MemoryBudget::machine_default(),
    };
    Editor::new(&scene, options).unwrap()
}

fn edits(c: &mut Criterion) {
    let mut g = c.benchmark_group("trims");
    for trimmed in [false, true] {
        let mut ed = editor(trimmed);
        let mut sign = 1.0;
        let id = if trimmed {
            "edit, trimmed"
        } else {
            "edit, untrimmed"
        };
        g.bench_function(id, |b| {
            b.iter(|| {
                sign = -sign;
                let edit = Edit {
                    object: 0,
                    edit: ObjectEdit::Surface(SurfaceEdit::Point(PointEdit::Move {
                        point: [50, 50],
                        delta: DVec3::new(0.0, 0.0, 0.1 * sign),
                    })),
                };
                ed.submit(edit).unwrap();
                black_box(ed.apply_pending());
            });
        });
    }
    for faces in [100, 200, 400] {
        let spec = face_trim();
        g.bench_with_input(BenchmarkId::new("build faces", faces), &faces, |b, &n| {
            b.iter(|| {
                for _ in 0..n {
                    black_box(Trimmed::new(spec.clone(), [(0.0, 1.0), (0.0, 1.0)]).unwrap());
                }
            });
        });
    }
    g.finish();
}

fn main() {
    let mut c = Criterion::default().configure_from_args();
    edits(&mut c);
    c.final_summary();
}
