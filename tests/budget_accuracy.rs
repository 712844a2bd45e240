//! The memory budget's estimate against the bytes pre-evaluation actually allocates (issue
//! 25.8 for ERBS curves and surfaces, nested ones included; issue 23 on the teapot scene).
//!
//! A counting allocator (`stats_alloc`) gives the bytes allocated and not freed while a
//! document is built on one thread; the tests of this binary run one at a time, so nothing
//! else counts.

use prespline::editor::{Editor, EditorOptions};
use prespline::formats::parse_scene;
use prespline::sampling::SampleMode;
use prespline::sampling::budget::{MemoryBudget, Uses};
use prespline::scene::Scene;
use stats_alloc::{INSTRUMENTED_SYSTEM, Region, StatsAlloc};
use std::alloc::System;
use std::path::Path;
use std::sync::{Mutex, MutexGuard, PoisonError};

// `stats_alloc` keeps the counts (its `unsafe` is the crate's, not ours: ours stays in
// src/gpu). The counts are process-wide, so this file is a test binary of its own and every
// test in it holds `ALONE` while it runs: nothing else allocates while one measures.
#[global_allocator]
static GLOBAL: &StatsAlloc<System> = &INSTRUMENTED_SYSTEM;

static ALONE: Mutex<()> = Mutex::new(());

fn alone() -> MutexGuard<'static, ()> {
    ALONE.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Bytes allocated and not freed since `region` began (`stats_alloc` books a reallocation's
/// growth as allocated and its shrinking as freed; `bytes_reallocated` repeats that net).
fn live(region: &Region<'_, System>) -> i64 {
    let s = region.change();
    s.bytes_allocated as i64 - s.bytes_deallocated as i64
}

/// (estimated bytes, bytes the document holds after pre-evaluating `scene` in `mode`).
fn estimate_and_held(scene: &Scene, mode: SampleMode) -> (u64, i64) {
    let uses = Uses::default();
    let budget = MemoryBudget::from_flag(Some(u64::MAX / 2));
    let estimate = scene.check_budget(mode, uses, &budget).unwrap();
    let region = Region::new(GLOBAL);
    // Pre-evaluation on one thread, so the figure is the document's and not the workers'.
    let doc = prespline::parallel::on_one_thread(|| {
        Editor::new(scene, EditorOptions { mode, uses, budget })
            .unwrap()
            .into_document()
    });
    let held = live(&region);
    drop(doc);
    (estimate, held)
}

/// The estimate is within `tol` of the bytes held (relative to the bytes held).
fn assert_close(what: &str, estimate: u64, held: i64, tol: f64) {
    let rel = (estimate as f64 - held as f64).abs() / held as f64;
    eprintln!("{what}: estimate {estimate} B, held {held} B, off by {rel:.3}");
    assert!(
        rel <= tol,
        "{what}: estimate {estimate} B vs {held} B held: off by {:.1} % (> {:.0} %)",
        rel * 100.0,
        tol * 100.0
    );
}

fn erbs_curve_scene(nested: bool) -> Scene {
    let local2 = if nested {
        r#"{"type":"erbs_curve","from":{"type":"bezier_curve","points":[[1,0,0],[1.5,1,0],[2,0,1]]},"local_curves":6,"local_degree":3}"#
    } else {
        r#"{"points":[[1,0,0],[1.5,1,0],[2,0,1]]}"#
    };
    parse_scene(&format!(
        r#"{{"objects":[{{"name":"e","type":"erbs_curve","samples":20000,"knots":[0,0,1,2,3,3],"local":[{{"points":[[0,0,0],[0.5,1,0],[1,0,0]]}},{local2},{{"points":[[2,0,1],[2.5,-1,0],[3,0,0]]}},{{"points":[[3,0,0],[3.5,1,0],[4,0,0]]}}]}}]}}"#
    ))
    .unwrap()
}

fn erbs_surface_scene(nested: bool) -> Scene {
    let patch = |x: f64| {
        format!(
            r#"{{"points":[[[{x},0,0],[{x},1,0],[{x},2,0]],[[{a},0,0],[{a},1,1],[{a},2,0]],[[{b},0,0],[{b},1,0],[{b},2,0]]]}}"#,
            a = x + 0.5,
            b = x + 1.0
        )
    };
    let nested_patch = r#"{"type":"erbs_surface","from":{"type":"bezier_surface","points":[[[1,0,0],[1,1,0]],[[2,0,0],[2,1,1]]]},"local_patches":[4,4],"local_degree":[2,2]}"#;
    let p11 = if nested {
        nested_patch.to_string()
    } else {
        patch(1.0)
    };
    parse_scene(&format!(
        r#"{{"objects":[{{"name":"s","type":"erbs_surface","samples":[200,200],"knots":[[0,0,1,2,2],[0,0,1,2,2]],"local":[[{},{},{}],[{},{p11},{}],[{},{},{}]]}}]}}"#,
        patch(0.0),
        patch(0.0),
        patch(0.0),
        patch(1.0),
        patch(1.0),
        patch(2.0),
        patch(2.0),
        patch(2.0),
    ))
    .unwrap()
}

const MODES: [(&str, SampleMode); 3] = [
    ("render", SampleMode::Render),
    ("analysis", SampleMode::Analysis),
    ("derivatives 2", SampleMode::Derivatives(2)),
];

/// ERBS estimates within 15 % of what is allocated, in every mode, nested or not.
const ERBS_TOLERANCE: f64 = 0.15;

#[test]
fn erbs_curve_estimate_matches_allocated_bytes() {
    let _alone = alone();
    for nested in [false, true] {
        let scene = erbs_curve_scene(nested);
        for (name, mode) in MODES {
            let (e, held) = estimate_and_held(&scene, mode);
            assert_close(
                &format!("erbs curve, nested {nested}, {name}"),
                e,
                held,
                ERBS_TOLERANCE,
            );
        }
    }
}

#[test]
fn erbs_surface_estimate_matches_allocated_bytes() {
    let _alone = alone();
    for nested in [false, true] {
        let scene = erbs_surface_scene(nested);
        for (name, mode) in MODES {
            let (e, held) = estimate_and_held(&scene, mode);
            assert_close(
                &format!("erbs surface, nested {nested}, {name}"),
                e,
                held,
                ERBS_TOLERANCE,
            );
        }
    }
}

/// Many locals and few samples: the control display (48 samples and the points of each
/// local curve, 81 position and normal pairs and the net of each local patch) outweighs the
/// samples, so the estimate must count it.
#[test]
fn many_small_locals_estimate_matches_allocated_bytes() {
    let _alone = alone();
    let curve = parse_scene(
        r#"{"objects":[{"name":"e","type":"erbs_curve","samples":10,"from":{"type":"bezier_curve","points":[[0,0,0],[1,1,0],[2,0,1]]},"local_curves":5000,"local_degree":3}]}"#,
    )
    .unwrap();
    let surface = parse_scene(
        r#"{"objects":[{"name":"s","type":"erbs_surface","samples":[4,4],"from":{"type":"bezier_surface","points":[[[0,0,0],[1,0,0]],[[0,1,0],[1,1,1]]]},"local_patches":[60,60],"local_degree":[2,2]}]}"#,
    )
    .unwrap();
    for (what, scene) in [
        ("5000 local curves", curve),
        ("60 × 60 local patches", surface),
    ] {
        for (name, mode) in MODES {
            let (e, held) = estimate_and_held(&scene, mode);
            assert_close(&format!("{what}, {name}"), e, held, ERBS_TOLERANCE);
        }
    }
}

/// A control polygon of 200,000 points sampled 101 times: the points, knots, display and
/// table ranges are the object.
#[test]
fn a_long_control_polygon_estimate_matches_allocated_bytes() {
    let _alone = alone();
    let n = 200_000;
    let points: Vec<String> = (0..n)
        .map(|i| format!("[{},{},0]", i as f64 * 1e-3, (i % 7) as f64 * 1e-2))
        .collect();
    let knots: Vec<String> = std::iter::once(0)
        .chain(0..n)
        .chain(std::iter::once(n - 1))
        .map(|k| k.to_string())
        .collect();
    let scene = parse_scene(&format!(
        r#"{{"objects":[{{"name":"c","type":"bspline_curve","degree":1,"samples":101,"knots":[{}],"points":[{}]}}]}}"#,
        knots.join(","),
        points.join(",")
    ))
    .unwrap();
    let (e, held) = estimate_and_held(&scene, SampleMode::Render);
    assert_close("200,000-point polygon, render", e, held, 0.15);
}

#[test]
fn teapot_scene_estimate_matches_allocated_bytes() {
    let _alone = alone();
    let teapot = prespline::formats::read_json(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/teapot.json"),
    )
    .unwrap();
    let (e, held) = estimate_and_held(&teapot, SampleMode::Render);
    assert_close("teapot, render", e, held, 0.15);
}

#[test]
fn the_comparison_fails_on_a_halved_estimate() {
    let _alone = alone();
    // Negative control: an estimate that halves what is held is caught.
    let r = std::panic::catch_unwind(|| assert_close("halved", 500, 1000, 0.15));
    assert!(r.is_err());
    let nan = std::panic::catch_unwind(|| assert_close("nothing held", 0, 0, 0.15));
    assert!(nan.is_err(), "0/0 must not pass");
}

/// Issue 23: pre-evaluation on many threads gives the same bits as on one (each object is
/// computed by the same code; only the order of work differs).
#[test]
fn pre_evaluation_on_n_threads_equals_one_thread_bit_for_bit() {
    let _alone = alone();
    let teapot = prespline::formats::read_json(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/teapot.json"),
    )
    .unwrap();
    let mut scene = erbs_surface_scene(true);
    scene.objects.extend(erbs_curve_scene(true).objects);
    for k in 0..8 {
        for o in &teapot.objects {
            let mut o = o.clone();
            o.name = format!("{k}_{}", o.name);
            scene.objects.push(o);
        }
    }
    let bits = || -> Vec<u64> {
        let doc = prespline::editor::Document::with_mode(&scene, SampleMode::Analysis);
        doc.objects
            .iter()
            .flat_map(|o| o.sampled.grid().data.iter().flat_map(|v| v.to_array()))
            .map(f64::to_bits)
            .collect()
    };
    let one = prespline::parallel::on_one_thread(bits);
    prespline::parallel::set_threads(4);
    let four = bits();
    prespline::parallel::set_threads(0);
    assert_eq!(one.len(), four.len());
    assert!(one == four, "1 and 4 threads differ");
    // Negative control: one flipped bit is seen.
    let mut flipped = four.clone();
    flipped[7] ^= 1;
    assert!(one != flipped);
}
