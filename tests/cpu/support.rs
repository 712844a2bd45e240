//! The support query (`Sampler::support`) against what edits really change: for every kind —
//! Bézier, B-spline and rational curves and surfaces, weights, ERBS locals at depth 1 to 3
//! (open and closed), Catmull–Rom and Bézier-spline points (closed and every continuity) —
//! every sample whose value an edit of a target changes lies in the support the sampler names
//! for that target before the edit, bit for bit (the renderer's static layer rests on it).
//! A negative control: a support shrunk by one row misses changed samples.

use crate::common::Rng;
use glam::{DMat4, DVec3};
use prespline::editor::{Document, Handle};
use prespline::formats::demo::demo_scene;
use prespline::formats::parse_scene;
use prespline::model::{Index2, ObjectEdit, SampledObject, Target};
use prespline::sampling::{DirtyRegion, SampleGrid};
use prespline::scene::Scene;

/// Closed and open ERBS curves and surfaces, small enough to nest.
const ERBS: &str = r#"{"objects": [
  {"name": "e", "type": "erbs_curve",
   "from": {"type": "bspline_curve", "degree": 3, "knots": [0, 0, 0, 0, 1, 2, 2, 2, 2],
            "points": [[0, 0, 0], [1, 2, 0], [2, -1, 0], [3, 1, 0], [4, 0, 0]]},
   "local_curves": 5, "local_degree": 3, "samples": 90},
  {"name": "ring", "type": "erbs_curve", "closed": true,
   "from": {"type": "bezier_curve", "points": [[1, 0, 0], [1, 1, 0], [0, 1, 0]], "weights": [1, 0.7071067811865476, 1]},
   "local_curves": 4, "local_degree": 2, "samples": 81},
  {"name": "es", "type": "erbs_surface",
   "from": {"type": "bspline_surface", "degree": [2, 2], "knots": [[0, 0, 0, 1, 1, 1], [0, 0, 0, 1, 1, 1]],
            "points": [[[0, 0, 0], [0, 1, 0], [0, 2, 0]], [[1, 0, 0], [1, 1, 1], [1, 2, 0]], [[2, 0, 0], [2, 1, 0], [2, 2, 0]]]},
   "local_patches": [3, 4], "local_degree": [2, 2], "closed": [false, true], "samples": [41, 37]},
  {"name": "rational", "type": "bspline_surface", "degree": [2, 2],
   "knots": [[0, 0, 0, 1, 2, 2, 2], [0, 0, 0, 1, 2, 2, 2]],
   "points": [[[0, 0, 0], [0, 1, 0], [0, 2, 0], [0, 3, 0]], [[1, 0, 0], [1, 1, 1], [1, 2, 1], [1, 3, 0]],
              [[2, 0, 0], [2, 1, 1], [2, 2, 1], [2, 3, 0]], [[3, 0, 0], [3, 1, 0], [3, 2, 0], [3, 3, 0]]],
   "weights": [[1, 1, 1, 1], [1, 2, 0.5, 1], [1, 1, 1, 1], [1, 1, 3, 1]], "samples": [33, 29]}
]}"#;

fn scene() -> Scene {
    let mut s = demo_scene();
    for text in [
        ERBS.to_string(),
        std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/examples/catmull_rom.json"
        ))
        .unwrap(),
        std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/examples/bezier_spline.json"
        ))
        .unwrap(),
    ] {
        s.objects.extend(parse_scene(&text).unwrap().objects);
    }
    s
}

/// Every stored value of sample (i, j): partials, normal, curvatures, as bits.
fn sample_bits(g: &SampleGrid, i: usize, j: usize) -> Vec<u64> {
    let mut out: Vec<u64> = g
        .sample(i, j)
        .iter()
        .flat_map(|v| v.to_array().map(f64::to_bits))
        .collect();
    let k = i * g.dims[1] + j;
    if let Some(n) = &g.normals {
        out.extend(n[k].to_array().map(f64::to_bits));
    }
    if let Some(c) = &g.curvatures {
        out.extend(c[k].map(f64::to_bits));
    }
    out
}

/// The samples whose values differ between two grids of the same shape.
fn changed(a: &SampleGrid, b: &SampleGrid) -> Vec<(usize, usize)> {
    let [rows, cols] = a.dims;
    let mut out = Vec::new();
    for i in 0..rows {
        for j in 0..cols {
            if sample_bits(a, i, j) != sample_bits(b, i, j) {
                out.push((i, j));
            }
        }
    }
    out
}

fn inside(support: &[DirtyRegion], (i, j): (usize, usize)) -> bool {
    support
        .iter()
        .any(|r| r.rows.contains(&i) && r.cols.contains(&j))
}

/// Applies `edit` and returns the samples it changed that `support` misses.
fn missed(obj: &mut SampledObject, edit: &ObjectEdit, support: &[DirtyRegion]) -> usize {
    let before = obj.grid().clone();
    obj.apply(edit).expect("a valid edit");
    changed(&before, obj.grid())
        .into_iter()
        .filter(|&s| !inside(support, s))
        .count()
}

/// What a gesture on `handle` edits: the point, or the local it belongs to.
fn target_of(handle: Handle) -> Target {
    match handle {
        Handle::Point { point, .. } => Target::Point(point),
        Handle::LocalPoint { local, .. } => Target::Local(local),
    }
}

fn delta(rng: &mut Rng) -> DVec3 {
    let mut c = || f64::from(rng.f32(-0.3, 0.3));
    DVec3::new(c(), c(), c())
}

/// Random moves of random handles, weights where the object has them, and transforms of
/// ERBS locals, each checked against the support of its target.
fn check_document(doc: &mut Document, rng: &mut Rng, edits_per_object: usize) -> usize {
    let mut checked = 0;
    for object in 0..doc.objects.len() {
        doc.objects[object].sampled.set_rebuild_interval(None);
        let handles = doc.handles(object);
        // A polynomial object becoming rational is sampled again whole once (documented).
        if let Some((h, _)) = handles.first()
            && let Ok(e) = doc.set_weight(*h, 1.0)
        {
            doc.objects[object].sampled.apply(&e.edit).unwrap();
        }
        for _ in 0..edits_per_object {
            let (handle, at) = handles[rng.range(0, handles.len())];
            let (edit, target) = match (rng.range(0, 3), handle) {
                (0, Handle::LocalPoint { local, .. }) => {
                    let m = DMat4::from_translation(at)
                        * DMat4::from_rotation_z(0.3)
                        * DMat4::from_scale(DVec3::splat(1.1))
                        * DMat4::from_translation(-at + delta(rng));
                    let e = doc.transform_local(object, local, m).unwrap();
                    (e, Target::Local(local))
                }
                (1, Handle::Point { point, .. }) if doc.weight_of(handle).is_some() => {
                    let w = 0.5 + f64::from(rng.f32(0.0, 2.0));
                    (doc.set_weight(handle, w).unwrap(), Target::Weight(point))
                }
                _ => (
                    doc.move_handle(handle, delta(rng)).unwrap(),
                    target_of(handle),
                ),
            };
            let support = doc.objects[object].sampled.support(target);
            let miss = missed(&mut doc.objects[object].sampled, &edit.edit, &support);
            let name = &doc.objects[object].name;
            assert_eq!(
                miss, 0,
                "{name}: an edit of {target:?} changed {miss} samples outside its support {support:?}"
            );
            checked += 1;
        }
    }
    checked
}

/// Nests the middle local of every ERBS object `levels` times (an ERBS local inside an ERBS
/// local inside …), through the editor's own edit.
fn nest(doc: &mut Document, levels: usize) {
    for object in 0..doc.objects.len() {
        for _ in 0..levels {
            let deepest = doc
                .handles(object)
                .into_iter()
                .filter_map(|(h, _)| match h {
                    Handle::LocalPoint { local, .. } => Some(local),
                    _ => None,
                })
                .max_by_key(|l| l.steps().len());
            let Some(local) = deepest else {
                break;
            };
            let Some((edit, _)) = doc.local_to_erbs_edit(object, local, 3) else {
                break;
            };
            doc.objects[object].sampled.apply(&edit).unwrap();
            let model = doc.objects[object].sampled.model();
            doc.objects[object].controls = prespline::editor::ControlDisplay::of(model);
        }
    }
}

#[test]
fn edits_change_no_sample_outside_the_support_of_their_target() {
    let mut rng = Rng::new(0x005e_ed22);
    let mut doc = Document::new(&scene());
    let n = check_document(&mut doc, &mut rng, 12);
    assert!(n > 100, "only {n} edits checked");
    for levels in [1, 2] {
        let mut doc = Document::new(&parse_scene(ERBS).unwrap());
        nest(&mut doc, levels);
        let depth = (0..doc.objects.len())
            .flat_map(|o| doc.handles(o))
            .filter_map(|(h, _)| match h {
                Handle::LocalPoint { local, .. } => Some(local.steps().len()),
                _ => None,
            })
            .max();
        assert_eq!(depth, Some(levels + 1), "nesting reached depth {depth:?}");
        check_document(&mut doc, &mut rng, 10);
    }
}

#[test]
fn supports_are_local_and_a_shrunk_support_misses_changes() {
    let doc = Document::new(&demo_scene());
    let (object, handle) = (0..doc.objects.len())
        .find_map(|o| match doc.handles(o).as_slice() {
            [
                ..,
                (
                    h @ Handle::Point {
                        point: Index2::Two(..),
                        ..
                    },
                    _,
                ),
            ] => Some((o, *h)),
            _ => None,
        })
        .expect("the demo has a tensor surface");
    let Handle::Point { point, .. } = handle else {
        unreachable!()
    };
    let mut sampled = doc.objects[object].sampled.clone();
    let support = sampled.support(Target::Point(point));
    let whole = sampled.grid().dims[0] * sampled.grid().dims[1];
    let size: usize = support.iter().map(DirtyRegion::samples).sum();
    assert!(0 < size && size < whole / 4, "support of {size} of {whole}");
    // Negative control: one row less and the same edit changes samples outside.
    let mut shrunk = support.clone();
    shrunk[0].rows.end -= 1;
    let edit = doc.move_handle(handle, DVec3::new(0.0, 0.0, 0.25)).unwrap();
    assert!(missed(&mut sampled, &edit.edit, &shrunk) > 0);
}

/// Bounds and framing read control positions through `ControlDisplay::grip_points`, which
/// must name the very points picking offers (`grips`), in order, for every layout: polygons,
/// nets, ERBS local curves and patches. Negative control: one point dropped is seen.
#[test]
fn grip_points_are_the_grips_positions_for_every_layout() {
    let doc = Document::new(&scene());
    let mut layouts = std::collections::HashSet::new();
    for o in &doc.objects {
        let from_grips: Vec<DVec3> = o.controls.grips().into_iter().map(|(_, p)| p).collect();
        let points: Vec<DVec3> = o.controls.grip_points().collect();
        assert!(!points.is_empty(), "{}: no control points", o.name);
        assert_eq!(points, from_grips, "{}", o.name);
        assert_ne!(points[1..], from_grips[..], "negative control");
        layouts.insert(std::mem::discriminant(&o.controls.layout));
    }
    assert_eq!(layouts.len(), 4, "every layout kind is covered");
}
