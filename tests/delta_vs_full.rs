//! The incremental (delta) path equals full re-sampling after long random edit sequences, for
//! every object kind and edit kind, with and without the periodic exact rebuild.

mod oracle;

use oracle::random::{Kind, Options, random_edits, random_scene};
use oracle::rng::Rng;
use prespline::model::{Edit, merge_edits};
use prespline::sampling::{SampleMode, SampledObject};
use prespline::scene::{Scene, parse_edits, parse_scene};

/// A random one-object scene of `kind` and `count` random edits for it, through the product's
/// own parsers (so the edits are validated exactly as `prespline sample --edits` does).
fn case(kind: Kind, seed: u64, count: usize, max_samples: usize) -> (Scene, Vec<Edit>) {
    let opts = Options {
        max_samples,
        ..Options::default()
    };
    let s = random_scene(seed, &[kind], &opts);
    let scene = parse_scene(&s.to_json().to_string()).expect("generator makes valid scenes");
    let mut rng = Rng::new(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ 0x5eed);
    let edits = random_edits(&mut rng, &s, count);
    let list = serde_json::Value::Array(edits.iter().map(|e| e.to_json()).collect());
    let edits = parse_edits(&list.to_string(), &scene).expect("generator makes valid edits");
    (scene, edits)
}

/// Applies the edits incrementally and compares with a fresh full sampling of the edited model.
fn delta_error(
    scene: &Scene,
    edits: &[Edit],
    mode: SampleMode,
    rebuild: Option<usize>,
) -> (f64, f64) {
    let o = &scene.objects[0];
    let mut obj = SampledObject::new(&o.model, mode);
    obj.set_rebuild_interval(rebuild);
    for e in edits {
        obj.apply(&e.edit).expect("validated edits fit");
    }
    let fresh = SampledObject::new(&obj.model().to_model(), mode);
    let err = obj.grid().max_relative_difference(fresh.grid());
    let normal_err = match (&obj.grid().normals, &fresh.grid().normals) {
        (Some(a), Some(b)) => a
            .iter()
            .zip(b)
            .map(|(x, y)| (*x - *y).length())
            .fold(0.0, f64::max),
        _ => 0.0,
    };
    (err, normal_err)
}

#[test]
fn delta_equals_full_for_every_kind_and_mode() {
    let mut worst = 0.0f64;
    for kind in Kind::ALL {
        for seed in 0..40u64 {
            let (scene, edits) = case(kind, seed * 7 + kind as u64, 300, 20);
            for mode in [
                SampleMode::Derivatives(0),
                SampleMode::Derivatives(2),
                SampleMode::Render,
            ] {
                let (err, nerr) = delta_error(&scene, &edits, mode, None);
                worst = worst.max(err);
                assert!(
                    err < 1e-9,
                    "{kind:?} seed {seed} {mode:?}: relative error {err:e}"
                );
                assert!(
                    nerr < 1e-6,
                    "{kind:?} seed {seed} {mode:?}: normal error {nerr:e}"
                );
            }
        }
    }
    eprintln!("delta vs full, 300 edits: worst relative error {worst:e}");
}

/// 100 000 edits per object kind with the periodic rebuild switched off measure the raw drift
/// of the delta path; with it on, the error is reset every few thousand edits.
#[test]
fn drift_after_100k_edits_stays_bounded() {
    for kind in Kind::ALL {
        let (scene, edits) = case(kind, 1000 + kind as u64, 100_000, 12);
        let (raw, _) = delta_error(&scene, &edits, SampleMode::Render, None);
        let (rebuilt, _) = delta_error(&scene, &edits, SampleMode::Render, Some(4096));
        eprintln!("{kind:?}: 100k edits, drift {raw:e} without rebuild, {rebuilt:e} with");
        assert!(raw < 1e-9, "{kind:?}: raw drift {raw:e}");
        assert!(rebuilt < 1e-9, "{kind:?}: drift with rebuild {rebuilt:e}");
    }
}

#[test]
fn merged_frame_edits_give_the_same_result() {
    for kind in Kind::ALL {
        for seed in 0..10u64 {
            let (scene, edits) = case(kind, 500 + seed, 60, 12);
            let merged = merge_edits(&edits);
            assert!(merged.len() <= edits.len());
            let o = &scene.objects[0];
            let run = |list: &[Edit]| {
                let mut obj = SampledObject::new(&o.model, SampleMode::Derivatives(1));
                for e in list {
                    obj.apply(&e.edit).expect("validated edits fit");
                }
                obj
            };
            let (a, b) = (run(&edits), run(&merged));
            let err = a.grid().max_relative_difference(b.grid());
            assert!(err < 1e-9, "{kind:?} seed {seed}: {err:e}");
        }
    }
}

#[test]
fn merging_collapses_repeated_drags() {
    let (scene, edits) = case(Kind::BSplineSurface, 3, 1, 8);
    let one = &edits[0];
    let drag: Vec<Edit> = (0..50).map(|_| one.clone()).collect();
    let merged = merge_edits(&drag);
    assert_eq!(merged.len(), 1, "50 moves of one point become one update");
    let _ = scene;
}
