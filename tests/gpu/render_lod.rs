//! Display level of detail on lavapipe (validation on): at the default view of the demo the
//! image stays within the golden-image tolerance of the full draw while drawing far fewer
//! triangles; changing the level of detail copies nothing to the GPU; edits still update the
//! full-resolution rows; and the default interactive picture (the device's default MSAA, level
//! of detail on) matches its golden.

use crate::common;

use glam::DVec3;
use prespline::editor::Document;
use prespline::formats::demo::demo_scene;
use prespline::gpu::{OffscreenDesc, Pixels, Renderer};
use prespline::model::{Edit, KindEdit, PointEdit, SurfaceEdit};
use prespline::render::lod::{Lod, LodTolerance};
use prespline::render::offscreen::{Shot, shot_camera};
use prespline::render::{DrawReport, GpuScene, Highlight, ViewOptions};

/// The golden tolerance of the render tests: 2 levels per channel on at most 0.2 % of pixels.
const TOLERANCE: u8 = 2;
const MAX_FRACTION: f64 = 0.002;
const W: u32 = 1280;
const H: u32 = 720;

fn shot(doc: &Document) -> Shot {
    let base = Shot {
        width: W,
        height: H,
        camera: None,
        options: ViewOptions::default(),
        msaa: 0,
    };
    Shot {
        camera: Some(shot_camera(doc, &base)),
        ..base
    }
}

/// One frame of `doc` at the shot's view with level-of-detail `tolerance` (`None`: every
/// sample), through `scene`; returns the pixels, what was drawn and the bytes uploaded.
fn draw(
    r: &mut Renderer,
    scene: &mut GpuScene,
    doc: &Document,
    shot: &Shot,
    tolerance: Option<LodTolerance>,
) -> (Pixels, DrawReport, usize) {
    let mut target = r
        .create_offscreen(&OffscreenDesc {
            width: W,
            height: H,
            samples: shot.msaa,
        })
        .unwrap();
    let camera = shot_camera(doc, shot);
    let aspect = W as f64 / H as f64;
    let mut frame = r.begin_offscreen(&mut target).unwrap();
    let uploaded = scene.upload(&mut frame, doc).unwrap().bytes;
    frame.set_clear_color(prespline::render::Palette::default().background);
    frame.set_camera(camera.gpu(aspect, &doc.bounds()));
    let lod = Lod {
        tolerance,
        ..Lod::new(
            camera.view_proj(aspect, &doc.bounds()),
            [W as f64, H as f64],
            frame.samples(),
        )
    };
    let options = ViewOptions {
        lod: tolerance.is_some(),
        ..shot.options
    };
    let report = scene
        .draw(&mut frame, doc, &options, &Highlight::default(), &lod)
        .unwrap();
    frame.capture();
    frame.finish().unwrap();
    let px = r.read_pixels(&target).unwrap();
    r.destroy_offscreen(target).unwrap();
    (px, report, uploaded)
}

/// Pixels differing by more than `TOLERANCE` in some channel, as a fraction of all.
fn mismatch(a: &Pixels, b: &Pixels) -> f64 {
    assert_eq!((a.width, a.height), (b.width, b.height));
    let bad = a
        .rgba
        .chunks_exact(4)
        .zip(b.rgba.chunks_exact(4))
        .filter(|(x, y)| x.iter().zip(*y).any(|(p, q)| p.abs_diff(*q) > TOLERANCE))
        .count();
    bad as f64 / (a.width * a.height) as f64
}

fn default_tolerance(r: &Renderer) -> LodTolerance {
    LodTolerance::for_samples(r.default_samples())
}

#[test]
fn lod_at_the_default_view_stays_within_golden_tolerance_of_the_full_draw() {
    let (mut r, sink) = common::renderer();
    let doc = Document::new(&demo_scene());
    let shot = shot(&doc);
    let mut scene = GpuScene::new(&mut r, &doc).unwrap();
    let (full, full_report, _) = draw(&mut r, &mut scene, &doc, &shot, None);
    let tol = default_tolerance(&r);
    let (lod, report, _) = draw(&mut r, &mut scene, &doc, &shot, Some(tol));
    // A much coarser tolerance (8 px) is the negative control: the comparison must see it.
    let coarse = LodTolerance {
        error_px: 8.0,
        max_edge_px: 256.0,
    };
    let (rough, _, _) = draw(&mut r, &mut scene, &doc, &shot, Some(coarse));
    scene.destroy(&mut r);
    common::teardown(r, sink);

    assert_eq!(full_report.triangles, full_report.full_triangles);
    assert_eq!(report.full_triangles, full_report.full_triangles);
    eprintln!(
        "LOD draws {} of {} triangles; {:.3} % of pixels beyond tolerance (coarse: {:.3} %)",
        report.triangles,
        report.full_triangles,
        100.0 * mismatch(&full, &lod),
        100.0 * mismatch(&full, &rough)
    );
    assert!(
        report.triangles * 2 < report.full_triangles,
        "level of detail saved too little: {report:?}"
    );
    let m = mismatch(&full, &lod);
    assert!(
        m <= MAX_FRACTION,
        "{:.3} % of pixels differ from the full draw",
        100.0 * m
    );
    assert!(
        mismatch(&full, &rough) > MAX_FRACTION,
        "negative control: a coarse level of detail passed the comparison"
    );
}

#[test]
fn changing_the_level_of_detail_uploads_nothing_and_edits_update_full_rows() {
    let (mut r, sink) = common::renderer();
    let mut ed = common::editor(&demo_scene(), None);
    let near = shot(ed.doc());
    let mut far = near.clone();
    if let Some(c) = far.camera.as_mut() {
        c.distance *= 4.0;
    }
    let mut scene = GpuScene::new(&mut r, ed.doc()).unwrap();
    let tol = default_tolerance(&r);
    // The first frame into each slot writes the sample arenas there.
    for _ in 0..prespline::gpu::FRAMES_IN_FLIGHT {
        let (_, _, filled) = draw(&mut r, &mut scene, ed.doc(), &near, Some(tol));
        assert!(filled > 0, "a slot's first frame writes the samples");
    }
    let (_, a, first) = draw(&mut r, &mut scene, ed.doc(), &near, Some(tol));
    let (_, b, second) = draw(&mut r, &mut scene, ed.doc(), &far, Some(tol));
    let (_, c, third) = draw(&mut r, &mut scene, ed.doc(), &near, None);
    assert_eq!(
        (first, second, third),
        (0, 0, 0),
        "a view change uploaded data"
    );
    assert!(
        b.triangles < a.triangles && a.triangles < c.triangles,
        "{a:?} {b:?} {c:?}"
    );

    // An edit under level of detail copies whole rows of the full grid, in both slots.
    let edit = Edit {
        object: 0,
        edit: SurfaceEdit::Point(PointEdit::Move {
            point: [3, 4],
            delta: DVec3::new(0.0, 0.0, 0.5),
        })
        .into_object(),
    };
    let region = common::edit(&mut ed, &mut scene, edit).changes[0].samples[0].clone();
    let cols = ed.doc().objects[0].sampled.grid().dims[1];
    let rows = region.rows.len();
    let row_bytes = rows * cols * 6 * 4;
    let (_, _, slot0) = draw(&mut r, &mut scene, ed.doc(), &far, Some(tol));
    let (_, _, slot1) = draw(&mut r, &mut scene, ed.doc(), &far, Some(tol));
    assert!(rows > 0);
    // The samples' rows only: the nets are not drawn, so the control display has no mirror.
    assert_eq!(slot0, row_bytes, "first slot");
    assert_eq!(slot1, row_bytes, "second slot");
    let (_, _, after) = draw(&mut r, &mut scene, ed.doc(), &far, Some(tol));
    assert_eq!(after, 0, "nothing left to copy");
    scene.destroy(&mut r);
    common::teardown(r, sink);
}

#[test]
fn default_interactive_picture_matches_golden() {
    // What `prespline view` and `bench` show on this device: its default MSAA (1 on lavapipe)
    // and the default level of detail, at the demo's default view.
    let (mut r, sink) = common::renderer();
    let doc = Document::new(&demo_scene());
    let shot = shot(&doc);
    let mut scene = GpuScene::new(&mut r, &doc).unwrap();
    let tol = default_tolerance(&r);
    let (px, _, _) = draw(&mut r, &mut scene, &doc, &shot, Some(tol));
    scene.destroy(&mut r);
    common::teardown(r, sink);
    common::assert_golden("demo_default", &px);
}
