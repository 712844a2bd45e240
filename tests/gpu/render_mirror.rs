//! Mirror correctness with real scene edits: a long random edit sequence applied across many
//! frames with two frames in flight (each slot receives only the rows dirtied since it was last
//! written) must end with exactly the pixels of a fresh upload of the same document.

use crate::common;

use glam::{DMat4, DVec3};
use prespline::editor::{Document, Handle};
use prespline::formats::demo::demo_scene;
use prespline::gpu::{OffscreenDesc, OffscreenTarget, Pixels, Renderer};
use prespline::model::{CurveEdit, Edit, KindEdit, ModelRef, ObjectEdit, PointEdit, SurfaceEdit};
use prespline::render::offscreen::{Shot, shot_camera};
use prespline::render::{GpuScene, Highlight, Lod, NetMode, ViewOptions, Wire};
use prespline::scene::Scene;

/// The demo scene without the teapot (keeps the test fast): B-spline surface, ERBS surface,
/// ERBS curve, NURBS circle.
fn scene() -> Scene {
    let mut s = demo_scene();
    s.objects.truncate(4);
    s
}

struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        self.0 >> 33
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    fn signed(&mut self) -> f64 {
        (self.next() % 2001) as f64 / 1000.0 - 1.0
    }
}

/// A random edit: a control point (or local control point) moved, an ERBS local curve/patch
/// rotated, scaled and translated, or now and then a knot inserted or the degree elevated
/// (which reallocates that object's control mirror).
fn random_edit(doc: &Document, rng: &mut Lcg) -> Edit {
    let object = rng.below(doc.objects.len());
    if rng.below(12) == 0
        && let Some(edit) = structural_edit(doc.objects[object].sampled.model(), rng)
    {
        return Edit { object, edit };
    }
    let handles = doc.handles(object);
    let pick = handles.get(rng.below(handles.len())).copied();
    if let (0, Some((Handle::LocalPoint { local, .. }, pos))) = (rng.below(3), pick) {
        let m = DMat4::from_translation(pos)
            * DMat4::from_rotation_z(0.2 * rng.signed())
            * DMat4::from_scale(DVec3::splat(1.0 + 0.05 * rng.signed()))
            * DMat4::from_translation(
                -pos + DVec3::new(0.1 * rng.signed(), 0.1 * rng.signed(), 0.1 * rng.signed()),
            );
        return doc.transform_local(object, local, m).unwrap();
    }
    let (h, _) = handles[rng.below(handles.len())];
    doc.move_handle(
        h,
        DVec3::new(0.2 * rng.signed(), 0.2 * rng.signed(), 0.4 * rng.signed()),
    )
    .unwrap()
}

/// A knot insertion at a fresh parameter or a degree elevation (small degrees only).
fn structural_edit(model: ModelRef<'_>, rng: &mut Lcg) -> Option<ObjectEdit> {
    let s = 0.05 + 0.9 * (rng.below(1000) as f64 / 1000.0);
    match model {
        ModelRef::Curve(m) => {
            let c = m.curve();
            let (a, b) = c.domain();
            Some(if rng.below(3) == 0 && c.degree() < 4 {
                CurveEdit::ElevateDegree { by: 1 }.into_object()
            } else {
                CurveEdit::InsertKnot {
                    t: a + (b - a) * s,
                    times: 1,
                }
                .into_object()
            })
        }
        ModelRef::Surface(m) => {
            let su = m.surface();
            let dir = rng.below(2);
            let (a, b) = su.domain()[dir];
            Some(if rng.below(3) == 0 && su.degree()[dir] < 4 {
                let mut by = [0, 0];
                by[dir] = 1;
                SurfaceEdit::ElevateDegree { by }.into_object()
            } else {
                SurfaceEdit::InsertKnot {
                    dir,
                    t: a + (b - a) * s,
                    times: 1,
                }
                .into_object()
            })
        }
        _ => None,
    }
}

fn options() -> ViewOptions {
    ViewOptions {
        control_nets: NetMode::All,
        local_curves: true,
        wire: Wire::Isolines(6),
        ..ViewOptions::default()
    }
}

fn draw_frame(
    renderer: &mut Renderer,
    target: &mut OffscreenTarget,
    gs: &mut GpuScene,
    doc: &Document,
    shot: &Shot,
) -> usize {
    draw_frame_lit(
        renderer,
        target,
        gs,
        doc,
        shot,
        &Highlight::default(),
        false,
    )
}

/// [`draw_frame`] with `hl` marked; with `every_mirror` the control mirrors of every object
/// are made after the upload, as if each had been drawn before.
fn draw_frame_lit(
    renderer: &mut Renderer,
    target: &mut OffscreenTarget,
    gs: &mut GpuScene,
    doc: &Document,
    shot: &Shot,
    hl: &Highlight,
    every_mirror: bool,
) -> usize {
    let camera = shot_camera(doc, shot);
    let aspect = shot.width as f64 / shot.height as f64;
    let mut frame = renderer.begin_offscreen(target).unwrap();
    let stats = gs.upload(&mut frame, doc).unwrap();
    if every_mirror {
        gs.make_controls(&mut frame, doc, &options(), hl).unwrap();
    }
    frame.set_camera(camera.gpu(aspect, &doc.bounds()));
    let viewport = [shot.width as f64, shot.height as f64];
    let lod = Lod::new(
        camera.view_proj(aspect, &doc.bounds()),
        viewport,
        frame.samples(),
    );
    gs.draw(&mut frame, doc, &shot.options, hl, &lod).unwrap();
    frame.capture();
    frame.finish().unwrap();
    stats.bytes
}

/// A shot with the camera fixed on the unedited document, so renders before and after edits
/// frame the same view even though edits move the bounds.
fn fixed_shot(doc: &Document, width: u32, height: u32) -> Shot {
    let base = Shot {
        width,
        height,
        camera: None,
        options: options(),
        msaa: 1,
    };
    Shot {
        camera: Some(shot_camera(doc, &base)),
        ..base
    }
}

fn offscreen(renderer: &mut Renderer, shot: &Shot) -> OffscreenTarget {
    renderer
        .create_offscreen(&OffscreenDesc {
            width: shot.width,
            height: shot.height,
            samples: shot.msaa,
        })
        .unwrap()
}

/// One frame of `doc` through a freshly created (fully uploaded) GPU scene.
fn fresh_render(
    renderer: &mut Renderer,
    target: &mut OffscreenTarget,
    doc: &Document,
    shot: &Shot,
) -> Pixels {
    let mut gs = GpuScene::new(renderer, doc).unwrap();
    draw_frame(renderer, target, &mut gs, doc, shot);
    let pixels = renderer.read_pixels(target).unwrap();
    gs.destroy(renderer);
    pixels
}

#[test]
fn incremental_mirrors_end_identical_to_a_fresh_upload() {
    let (mut renderer, sink) = common::renderer();
    let mut ed = common::editor(&scene(), None);
    let shot = fixed_shot(ed.doc(), 480, 320);
    let mut target = offscreen(&mut renderer, &shot);
    let mut gs = GpuScene::new(&mut renderer, ed.doc()).unwrap();
    let mut rng = Lcg(7);
    let mut uploaded = 0;
    for _ in 0..60 {
        for _ in 0..1 + rng.below(4) {
            let e = random_edit(ed.doc(), &mut rng);
            ed.submit(e).unwrap();
        }
        gs.consume(&ed.apply_pending());
        uploaded += draw_frame(&mut renderer, &mut target, &mut gs, ed.doc(), &shot);
    }
    let doc = ed.into_document();
    assert!(uploaded > 0);
    let incremental: Pixels = renderer.read_pixels(&target).unwrap();
    gs.destroy(&mut renderer);

    let fresh = fresh_render(&mut renderer, &mut target, &doc, &shot);
    renderer.destroy_offscreen(target).unwrap();
    common::teardown(renderer, sink);

    let differing = incremental
        .rgba
        .chunks(4)
        .zip(fresh.rgba.chunks(4))
        .filter(|(a, b)| a != b)
        .count();
    if differing > 0 {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden");
        incremental
            .write_png(&dir.join("mirror-actual.png"))
            .unwrap();
        fresh.write_png(&dir.join("mirror-expected.png")).unwrap();
    }
    assert_eq!(
        differing, 0,
        "{differing} pixels differ between incremental and fresh uploads"
    );
}

/// Control mirrors are made by the first frame that draws them: edits (structural ones
/// included) before the nets are first shown, while they are hidden again and after, end with
/// the pixels of a fresh upload; once a mirror exists, a moved point copies its three floats
/// into each slot beside the sample rows.
#[test]
fn control_mirrors_made_late_end_identical_to_a_fresh_upload() {
    let (mut renderer, sink) = common::renderer();
    let mut ed = common::editor(&scene(), None);
    let shown = fixed_shot(ed.doc(), 480, 320);
    let hidden = Shot {
        options: ViewOptions {
            control_nets: NetMode::Off,
            ..shown.options
        },
        ..shown.clone()
    };
    let mut target = offscreen(&mut renderer, &shown);
    let mut gs = GpuScene::new(&mut renderer, ed.doc()).unwrap();
    let mut rng = Lcg(11);
    for f in 0..60 {
        for _ in 0..1 + rng.below(4) {
            let e = random_edit(ed.doc(), &mut rng);
            ed.submit(e).unwrap();
        }
        gs.consume(&ed.apply_pending());
        let shot = if (20..35).contains(&f) || f >= 45 {
            &shown
        } else {
            &hidden
        };
        draw_frame(&mut renderer, &mut target, &mut gs, ed.doc(), shot);
    }
    // Both slots up to date, then one interior point of the B-spline surface moved.
    draw_frame(&mut renderer, &mut target, &mut gs, ed.doc(), &shown);
    draw_frame(&mut renderer, &mut target, &mut gs, ed.doc(), &shown);
    let e = Edit {
        object: 0,
        edit: SurfaceEdit::Point(PointEdit::Move {
            point: [3, 4],
            delta: DVec3::new(0.0, 0.0, 0.3),
        })
        .into_object(),
    };
    let region = common::edit(&mut ed, &mut gs, e).changes[0].samples[0].clone();
    let row_bytes = region.rows.len() * ed.doc().objects[0].sampled.grid().dims[1] * 24;
    for slot in 0..2 {
        let copied = draw_frame(&mut renderer, &mut target, &mut gs, ed.doc(), &shown);
        assert_eq!(copied, row_bytes + 12, "slot {slot}");
    }
    let doc = ed.into_document();
    let incremental: Pixels = renderer.read_pixels(&target).unwrap();
    gs.destroy(&mut renderer);
    let fresh = fresh_render(&mut renderer, &mut target, &doc, &shown);
    renderer.destroy_offscreen(target).unwrap();
    common::teardown(renderer, sink);
    let diff = common::compare_images(&incremental, &fresh, 0).unwrap();
    assert_eq!(diff.differing, 0, "{} pixels differ", diff.differing);
}

/// Making the control mirrors reports the bytes it wrote (every slot of each display shown),
/// once: the viewer adds them to the frame's upload figures.
#[test]
fn making_control_mirrors_reports_their_bytes_once() {
    let (mut renderer, sink) = common::renderer();
    let ed = common::editor(&scene(), None);
    let doc = ed.doc();
    let shot = fixed_shot(doc, 64, 64);
    let mut target = offscreen(&mut renderer, &shot);
    let mut gs = GpuScene::new(&mut renderer, doc).unwrap();
    let hl = Highlight::default();
    let hidden = ViewOptions {
        control_nets: NetMode::Off,
        local_curves: false,
        ..options()
    };
    let vertices: usize = doc.objects.iter().map(|o| o.controls.vertices.len()).sum();
    let mut frame = renderer.begin_offscreen(&mut target).unwrap();
    let none = gs.make_controls(&mut frame, doc, &hidden, &hl).unwrap();
    let all = gs.make_controls(&mut frame, doc, &options(), &hl).unwrap();
    let again = gs.make_controls(&mut frame, doc, &options(), &hl).unwrap();
    frame.finish().unwrap();
    gs.destroy(&mut renderer);
    renderer.destroy_offscreen(target).unwrap();
    common::teardown(renderer, sink);
    assert_eq!(none, 0, "nothing of the displays is drawn");
    assert_eq!(all, vertices * 3 * 4 * prespline::gpu::FRAMES_IN_FLIGHT);
    assert_eq!(again, 0, "made once");
}

/// One frame of `doc` with `hl` through a fresh GPU scene ([`draw_frame_lit`]).
fn focused_frame(
    renderer: &mut Renderer,
    target: &mut OffscreenTarget,
    doc: &Document,
    shot: &Shot,
    hl: &Highlight,
    every_mirror: bool,
) -> Pixels {
    let mut gs = GpuScene::new(renderer, doc).unwrap();
    draw_frame_lit(renderer, target, &mut gs, doc, shot, hl, every_mirror);
    let pixels = renderer.read_pixels(target).unwrap();
    gs.destroy(renderer);
    pixels
}

/// With the nets shown for the focused objects only, hovering an object, hovering or
/// selecting one of its points, or choosing an ERBS local makes that object's control mirror:
/// the frame equals one where every mirror already existed, and differs from one with nothing
/// focused.
#[test]
fn focused_objects_get_their_control_mirrors() {
    let (mut renderer, sink) = common::renderer();
    let ed = common::editor(&scene(), None);
    let doc = ed.doc();
    let shot = Shot {
        options: ViewOptions {
            control_nets: NetMode::Focused,
            local_curves: false,
            ..options()
        },
        ..fixed_shot(doc, 320, 240)
    };
    let mut target = offscreen(&mut renderer, &shot);
    let point = doc.handles(0)[5].0;
    let local = doc
        .handles(1)
        .into_iter()
        .find_map(|(h, _)| match h {
            Handle::LocalPoint { object, local, .. } => Some((object, local)),
            _ => None,
        })
        .expect("the ERBS surface has local points");
    let focused = [
        Highlight {
            hovered_object: Some(3),
            ..Highlight::default()
        },
        Highlight {
            hovered: Some(point),
            ..Highlight::default()
        },
        Highlight {
            selected: Some(point),
            ..Highlight::default()
        },
        Highlight {
            selected_local: Some(local),
            ..Highlight::default()
        },
    ];
    let nothing = focused_frame(
        &mut renderer,
        &mut target,
        doc,
        &shot,
        &Highlight::default(),
        false,
    );
    for hl in &focused {
        let made_now = focused_frame(&mut renderer, &mut target, doc, &shot, hl, false);
        let made_before = focused_frame(&mut renderer, &mut target, doc, &shot, hl, true);
        let diff = common::compare_images(&made_before, &made_now, 0).unwrap();
        assert_eq!(
            diff.differing, 0,
            "{hl:?}: {} pixels differ",
            diff.differing
        );
        assert_ne!(made_now.rgba, nothing.rgba, "{hl:?}: nothing drawn");
    }
    renderer.destroy_offscreen(target).unwrap();
    common::teardown(renderer, sink);
}

#[test]
fn a_missed_update_is_detected() {
    // Negative control: if one slot skipped its dirty rows the comparison must fail.
    let (mut renderer, sink) = common::renderer();
    let mut ed = common::editor(&scene(), None);
    let shot = fixed_shot(ed.doc(), 320, 200);
    let mut target = offscreen(&mut renderer, &shot);
    let mut gs = GpuScene::new(&mut renderer, ed.doc()).unwrap();
    draw_frame(&mut renderer, &mut target, &mut gs, ed.doc(), &shot);
    // Lift the centre of the B-spline surface but do not tell the GPU scene.
    let e = Edit {
        object: 0,
        edit: SurfaceEdit::Point(PointEdit::Move {
            point: [3, 4],
            delta: DVec3::new(0.0, 0.0, 3.0),
        })
        .into_object(),
    };
    ed.submit(e).unwrap();
    let _ = ed.apply_pending();
    let doc = ed.into_document();
    draw_frame(&mut renderer, &mut target, &mut gs, &doc, &shot);
    let stale = renderer.read_pixels(&target).unwrap();
    gs.destroy(&mut renderer);
    let fresh = fresh_render(&mut renderer, &mut target, &doc, &shot);
    renderer.destroy_offscreen(target).unwrap();
    common::teardown(renderer, sink);
    assert_ne!(stale.rgba, fresh.rgba);
}

/// Issue 23: the sample arenas are filled on every core, each thread a run of consecutive
/// objects; the image equals the one of a fill on one thread, bit for bit (the demo scene and
/// 48 teapot patches, so a fill splits into many runs).
#[test]
fn mirror_fills_on_n_threads_equal_one_thread() {
    let (mut renderer, sink) = common::renderer();
    let mut scene = demo_scene();
    let teapot = prespline::formats::read_json(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/teapot.json"),
    )
    .unwrap();
    for k in 0..3 {
        for o in teapot.objects.iter().take(16) {
            let mut o = o.clone();
            o.name = format!("{k}_{}", o.name);
            scene.objects.push(o);
        }
    }
    let ed = common::editor(&scene, None);
    let shot = fixed_shot(ed.doc(), 320, 240);
    let mut target = offscreen(&mut renderer, &shot);
    let one = prespline::parallel::on_one_thread(|| {
        fresh_render(&mut renderer, &mut target, ed.doc(), &shot)
    });
    prespline::parallel::set_threads(3);
    let three = fresh_render(&mut renderer, &mut target, ed.doc(), &shot);
    prespline::parallel::set_threads(0);
    let diff = common::compare_images(&one, &three, 0).unwrap();
    assert_eq!(diff.differing, 0, "{} pixels differ", diff.differing);
    renderer.destroy_offscreen(target).unwrap();
    common::teardown(renderer, sink);
}
