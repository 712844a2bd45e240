//! Retained redraw (`--redraw retained`) against the full redraw, bit for bit at MSAA 1, on
//! lavapipe with validation and synchronization validation: two viewer sessions of the same
//! scene take the same input frame by frame, one drawing from its static layer, one in full,
//! and every frame of the first must equal the second's exactly. Random scenes (Bézier,
//! B-spline and rational surfaces and curves, an exact twin of a surface to force depth ties,
//! Catmull–Rom and Bézier splines, ERBS surfaces with locals nested to depth 2) and random
//! gestures (point drags, weight drags, G/R/S of ERBS locals), with maps on and off; orbit,
//! resize, toggles and undo during and after gestures. A negative control drops one chunk
//! from the dynamic set and must be caught.

use crate::common::{self, Rng, compare_images};
use prespline::editor::Handle;
use prespline::formats::parse_scene;
use prespline::gpu::{OffscreenDesc, OffscreenTarget, Pixels, Renderer, ValidationSink};
use prespline::render::Redraw;
use prespline::render::maps::SurfaceMap;
use prespline::sampling::budget::MemoryBudget;
use prespline::scene::Scene;
use prespline::view::Session;
use prespline::view::input::{InputEvent, Key, Modifiers, MouseButton};
use prespline::view::script::Action;

const SIZE: [u32; 2] = [320, 240];

struct Run {
    session: Session,
    target: OffscreenTarget,
}

/// The same session twice: `[retained, full]`.
struct Pair {
    renderer: Renderer,
    sink: ValidationSink,
    runs: Vec<Run>,
    /// Frames the retained run drew from its static layer.
    retained_frames: usize,
    frames: usize,
}

impl Pair {
    fn new(scene: &Scene, map: Option<SurfaceMap>) -> Self {
        Self::with_samples(scene, map, 1)
    }

    /// Both sessions drawing into `samples`-times multisampled targets.
    fn with_samples(scene: &Scene, map: Option<SurfaceMap>, samples: u32) -> Self {
        let (mut renderer, sink) = common::renderer();
        let mut runs = Vec::new();
        for redraw in [Redraw::Retained, Redraw::Full] {
            let target = renderer
                .create_offscreen(&OffscreenDesc {
                    width: SIZE[0],
                    height: SIZE[1],
                    samples,
                })
                .unwrap();
            let mut session = Session::open(
                &mut renderer,
                scene,
                std::env::temp_dir().join("prespline-retained-test.json"),
                SIZE,
                MemoryBudget::machine_default(),
            )
            .unwrap();
            session.set_redraw(redraw);
            // Small test scenes: gestures whose support is most of the frame still take the
            // retained path here (`a_layer_that_would_not_pay_is_skipped` covers the rule).
            session.set_layer_always(true);
            session.set_map(map);
            runs.push(Run { session, target });
        }
        Pair {
            renderer,
            sink,
            runs,
            retained_frames: 0,
            frames: 0,
        }
    }

    /// One frame of both sessions after `actions`; their images.
    fn frame(&mut self, actions: &[Action]) -> [Pixels; 2] {
        let mut images = Vec::new();
        for run in &mut self.runs {
            for a in actions {
                run.session.perform(a.clone());
            }
            run.session.apply_pending();
            let mut frame = self.renderer.begin_offscreen(&mut run.target).unwrap();
            run.session.upload(&mut frame).unwrap();
            run.session.record(&mut frame, false).unwrap();
            frame.capture();
            frame.finish().unwrap();
            images.push(self.renderer.read_pixels(&run.target).unwrap());
        }
        self.frames += 1;
        if self.runs[0].session.hud.retained.is_some() {
            self.retained_frames += 1;
        }
        assert!(
            self.runs[1].session.hud.retained.is_none(),
            "--redraw full drew from a layer"
        );
        let full = images.pop().unwrap();
        [images.pop().unwrap(), full]
    }

    /// Frames until the first that differs (its number and how), or `None`.
    fn first_difference(&mut self, script: &[Vec<Action>]) -> Option<String> {
        for (k, actions) in script.iter().enumerate() {
            let [retained, full] = self.frame(actions);
            let diff = compare_images(&full, &retained, 0).unwrap();
            if diff.differing > 0 {
                return Some(format!(
                    "frame {k}: {} pixels differ (worst {})",
                    diff.differing, diff.worst
                ));
            }
        }
        None
    }

    fn resize(&mut self, w: u32, h: u32) {
        for run in &mut self.runs {
            let t = self
                .renderer
                .create_offscreen(&OffscreenDesc {
                    width: w,
                    height: h,
                    samples: 1,
                })
                .unwrap();
            let old = std::mem::replace(&mut run.target, t);
            self.renderer.destroy_offscreen(old).unwrap();
            run.session.resize(w, h);
        }
    }

    fn finish(self) {
        let Pair {
            mut renderer,
            sink,
            runs,
            ..
        } = self;
        for run in runs {
            run.session.destroy(&mut renderer);
            renderer.destroy_offscreen(run.target).unwrap();
        }
        common::teardown(renderer, sink);
    }
}

fn button(pressed: bool) -> Action {
    Action::Input(InputEvent::Button {
        button: MouseButton::Left,
        pressed,
    })
}

fn mods(alt: bool) -> Action {
    Action::Input(InputEvent::Modifiers(Modifiers {
        ctrl: false,
        shift: false,
        alt,
    }))
}

fn key(c: char) -> Action {
    Action::Key {
        key: Key::Char(c),
        mods: Modifiers::default(),
    }
}

fn ctrl(c: char) -> Action {
    Action::Key {
        key: Key::Char(c),
        mods: Modifiers {
            ctrl: true,
            shift: false,
            alt: false,
        },
    }
}

/// A drag of `handle` along a random path (`alt`: its weight).
fn drag(rng: &mut Rng, handle: Handle, alt: bool, frames: usize) -> Vec<Vec<Action>> {
    let mut s = vec![vec![mods(alt), Action::MoveTo(handle)], vec![button(true)]];
    for _ in 0..frames {
        let d = |rng: &mut Rng| f64::from(rng.f32(-12.0, 12.0));
        s.push(vec![Action::MoveBy(d(rng), d(rng))]);
    }
    s.push(vec![button(false), mods(false)]);
    s
}

/// Selects `handle` (its ERBS local too) and grabs, rotates or scales that local with the
/// cursor, then confirms.
fn transform(rng: &mut Rng, handle: Handle, frames: usize) -> Vec<Vec<Action>> {
    let kind = ['g', 'r', 's'][rng.range(0, 3)];
    let mut s = vec![
        vec![Action::MoveTo(handle)],
        vec![button(true), button(false)],
        vec![Action::MoveBy(25.0, 5.0)],
        vec![key(kind)],
    ];
    for _ in 0..frames {
        s.push(vec![Action::MoveBy(
            f64::from(rng.f32(-8.0, 8.0)),
            f64::from(rng.f32(-8.0, 8.0)),
        )]);
    }
    s.push(vec![Action::Key {
        key: Key::Enter,
        mods: Modifiers::default(),
    }]);
    s
}

fn points_json(rng: &mut Rng, nu: usize, nv: usize, x0: f64) -> String {
    let rows: Vec<String> = (0..nu)
        .map(|i| {
            let row: Vec<String> = (0..nv)
                .map(|j| {
                    format!(
                        "[{}, {}, {}]",
                        x0 + i as f64,
                        j as f64 - 1.5,
                        rng.f32(-0.8, 0.8)
                    )
                })
                .collect();
            format!("[{}]", row.join(", "))
        })
        .collect();
    format!("[{}]", rows.join(", "))
}

/// Bézier, B-spline and rational surfaces (the first with an exact twin drawn after it, so
/// depth ties decide pixels), curves of each kind, a Catmull–Rom and a Bézier spline.
fn random_scene(rng: &mut Rng) -> Scene {
    let bez = points_json(rng, 4, 4, -4.0);
    let bsp = points_json(rng, 5, 4, -0.5);
    let nurbs = points_json(rng, 4, 5, 3.0);
    let weights: Vec<String> = (0..4)
        .map(|_| {
            let w: Vec<String> = (0..5).map(|_| format!("{}", rng.f32(0.5, 2.0))).collect();
            format!("[{}]", w.join(", "))
        })
        .collect();
    let text = format!(
        r#"{{"objects": [
  {{"name": "bez", "type": "bezier_surface", "points": {bez}, "samples": [70, 66]}},
  {{"name": "twin", "type": "bezier_surface", "points": {bez}, "samples": [70, 66]}},
  {{"name": "bsp", "type": "bspline_surface", "degree": [2, 3],
    "knots": [[0, 0, 0, 1, 2, 3, 3, 3], [0, 0, 0, 0, 1, 1, 1, 1]], "points": {bsp}, "samples": [80, 40]}},
  {{"name": "nurbs", "type": "bspline_surface", "degree": [3, 2],
    "knots": [[0, 0, 0, 0, 1, 1, 1, 1], [0, 0, 0, 1, 2, 3, 3, 3]], "points": {nurbs},
    "weights": [{w}], "samples": [50, 90]}},
  {{"name": "curve", "type": "bspline_curve", "degree": 3, "knots": [0, 0, 0, 0, 1, 2, 2, 2, 2],
    "points": [[-4, -3, {a}], [-2, -2, 1], [0, -3, {b}], [2, -2, 0], [4, -3, 0.5]],
    "weights": [1, 2, 0.7, 1, 1], "samples": 200}},
  {{"name": "bcurve", "type": "bezier_curve", "points": [[-4, 3, 0], [0, {c}, 1], [4, 3, 0]], "samples": 100}},
  {{"name": "cr", "type": "catmull_rom", "points": [[-4, 4, 0], [-2, 5, {a}], [0, 4, 0], [2, 5, 1], [4, 4, 0]], "samples": 120}},
  {{"name": "bs", "type": "bezier_spline", "degree": 3, "knots": [0, 1, 2], "continuity": "C0",
    "points": [[-4, -5, 0], [-3, -4, 1], [-2, -5, 0], [-1, -4, {b}], [0, -5, 0], [1, -4, 0], [2, -5, 0]], "samples": 120}}
]}}"#,
        w = weights.join(", "),
        a = rng.f32(-1.0, 1.0),
        b = rng.f32(-1.0, 1.0),
        c = rng.f32(1.0, 5.0),
    );
    parse_scene(&text).unwrap()
}

fn erbs_scene() -> Scene {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/erbs_surface.json"
    ))
    .unwrap();
    parse_scene(&text).unwrap()
}

/// A random handle of `object` in the retained run's document.
fn handle_of(pair: &Pair, rng: &mut Rng, object: usize) -> Handle {
    let handles = pair.runs[0].session.doc().handles(object);
    handles[rng.range(0, handles.len())].0
}

fn check(pair: &mut Pair, script: &[Vec<Action>], what: &str) {
    if let Some(d) = pair.first_difference(script) {
        panic!("{what}: retained differs from full at {d}");
    }
}

#[test]
fn retained_frames_equal_full_redraws_over_random_scenes_and_gestures() {
    for seed in 0..3u64 {
        let mut rng = Rng::new(0x5eed + seed);
        let scene = random_scene(&mut rng);
        let map = match seed {
            1 => Some(SurfaceMap::parse("gaussian").unwrap()),
            2 => Some(SurfaceMap::parse("zebra").unwrap()),
            _ => None,
        };
        let mut pair = Pair::new(&scene, map);
        check(&mut pair, &[vec![]], "first frame");
        // Point drags on every object, weight drags on the rational ones.
        for object in 0..pair.runs[0].session.doc().objects.len() {
            let h = handle_of(&pair, &mut rng, object);
            let script = drag(&mut rng, h, false, 6);
            check(&mut pair, &script, &format!("seed {seed}: drag of {h:?}"));
        }
        for object in [0, 3, 4] {
            let h = handle_of(&pair, &mut rng, object);
            let script = drag(&mut rng, h, true, 5);
            check(
                &mut pair,
                &script,
                &format!("seed {seed}: weight drag of {h:?}"),
            );
        }
        assert!(
            pair.retained_frames * 2 > pair.frames,
            "seed {seed}: only {} of {} frames were retained: the test would prove nothing",
            pair.retained_frames,
            pair.frames
        );
        pair.finish();
    }
}

/// At MSAA 4 a target has no static layer (a multisampled depth buffer cannot be restored
/// bit for bit), so `--redraw retained` draws every frame in full: the same pixels as
/// `--redraw full`, within any golden tolerance because within none.
#[test]
fn at_msaa_4_retained_draws_in_full_and_equals_full() {
    let mut rng = Rng::new(0x5eed);
    let scene = random_scene(&mut rng);
    let mut pair = Pair::with_samples(&scene, None, 4);
    check(&mut pair, &[vec![]], "MSAA 4: first frame");
    let h = handle_of(&pair, &mut rng, 0);
    let script = drag(&mut rng, h, false, 5);
    check(&mut pair, &script, &format!("MSAA 4: drag of {h:?}"));
    assert_eq!(pair.retained_frames, 0, "no layer at MSAA 4");
    pair.finish();
}

#[test]
fn erbs_local_transforms_at_depth_two_redraw_exactly() {
    let mut rng = Rng::new(7);
    let mut pair = Pair::new(&erbs_scene(), None);
    check(&mut pair, &[vec![]], "first frame");
    // Nest a local (X on a selected local makes it an ERBS surface of its own), then work on
    // locals at depth 2.
    let h = handle_of(&pair, &mut rng, 0);
    check(
        &mut pair,
        &[
            vec![Action::MoveTo(h)],
            vec![button(true), button(false)],
            vec![key('x')],
        ],
        "nesting",
    );
    let deep: Vec<Handle> = pair.runs[0]
        .session
        .doc()
        .handles(0)
        .into_iter()
        .map(|(h, _)| h)
        .filter(|h| matches!(h, Handle::LocalPoint { local, .. } if local.steps().len() >= 2))
        .collect();
    assert!(!deep.is_empty(), "X made no local at depth 2");
    for _ in 0..4 {
        let h = deep[rng.range(0, deep.len())];
        let script = transform(&mut rng, h, 5);
        check(&mut pair, &script, &format!("transform of {h:?}"));
        let script = drag(&mut rng, h, false, 4);
        check(&mut pair, &script, &format!("drag of {h:?}"));
    }
    assert!(
        pair.retained_frames > 10,
        "{} retained frames",
        pair.retained_frames
    );
    pair.finish();
}

#[test]
fn orbit_resize_toggles_and_undo_during_and_after_gestures_give_the_full_image() {
    let mut rng = Rng::new(11);
    let scene = random_scene(&mut rng);
    let mut pair = Pair::new(&scene, None);
    let h = handle_of(&pair, &mut rng, 2);
    let mut script = drag(&mut rng, h, false, 3);
    let release = script.pop().unwrap();
    // During the gesture: a toggle (level of detail), a map, undo; then after it: orbit,
    // resize (below), more toggles.
    script.push(vec![key('d')]);
    script.push(vec![Action::MoveBy(5.0, 3.0)]);
    script.push(vec![key('m')]);
    script.push(vec![Action::MoveBy(-4.0, 2.0)]);
    script.push(vec![ctrl('z')]);
    script.push(vec![Action::MoveBy(3.0, -6.0)]);
    script.push(release);
    script.push(vec![ctrl('z')]);
    script.push(vec![ctrl('z'), key('m')]);
    // Orbit: a drag on empty space (the corner).
    script.push(vec![Action::Input(InputEvent::CursorMoved {
        x: 3.0,
        y: 3.0,
    })]);
    script.push(vec![button(true)]);
    script.push(vec![Action::MoveBy(20.0, 4.0)]);
    script.push(vec![Action::MoveBy(10.0, 0.0), button(false)]);
    check(&mut pair, &script, "toggles, undo and orbit");
    let used = pair.retained_frames;
    assert!(used > 0, "no frame was retained");
    // A gesture, a resize in the middle of it, and the gesture going on.
    let h = handle_of(&pair, &mut rng, 0);
    let mut script = drag(&mut rng, h, false, 4);
    let tail = script.split_off(4);
    check(&mut pair, &script, "before the resize");
    pair.resize(280, 200);
    check(&mut pair, &tail, "after the resize");
    pair.finish();
}

#[test]
fn a_dynamic_set_missing_one_chunk_is_caught() {
    let mut rng = Rng::new(3);
    let scene = random_scene(&mut rng);
    let mut pair = Pair::new(&scene, None);
    pair.runs[0].session.set_drop_chunk(true);
    // The middle control point of the B-spline surface: its support is inside the surface.
    let h = Handle::Point {
        object: 2,
        point: prespline::model::Index2::Two(2, 2),
    };
    let script = drag(&mut rng, h, false, 6);
    let found = pair.first_difference(&script);
    assert!(
        found.is_some(),
        "a stale chunk in the static layer went unnoticed ({} retained frames)",
        pair.retained_frames
    );
    pair.finish();
}

/// Nets of every object (the twin's net lies over the dragged surface and crosses its
/// dynamic rectangle), then nets of the focused object only: every frame of point drags on
/// surfaces and curves equals the full redraw.
#[test]
fn static_nets_over_the_dragged_surface_and_focused_nets_redraw_exactly() {
    let mut rng = Rng::new(0xc0de);
    let scene = random_scene(&mut rng);
    let mut pair = Pair::new(&scene, None);
    check(&mut pair, &[vec![]], "first frame");
    for round in 0..2 {
        for object in [0, 1, 2, 4, 6] {
            let h = handle_of(&pair, &mut rng, object);
            let script = drag(&mut rng, h, false, 5);
            check(&mut pair, &script, &format!("round {round}: drag of {h:?}"));
        }
        // All → focused nets.
        check(&mut pair, &[vec![key('c')]], "cycling the nets");
    }
    assert!(
        pair.retained_frames * 2 > pair.frames,
        "only {} of {} frames were retained",
        pair.retained_frames,
        pair.frames
    );
    pair.finish();
}

#[test]
fn lines_left_out_of_the_redrawn_rectangle_are_caught() {
    let mut rng = Rng::new(5);
    let scene = random_scene(&mut rng);
    let mut pair = Pair::new(&scene, None);
    pair.runs[0].session.set_drop_lines(true);
    // A middle point of the B-spline curve: its polygon and samples move.
    let h = Handle::Point {
        object: 4,
        point: prespline::model::Index2::One(2),
    };
    let script = drag(&mut rng, h, false, 6);
    let found = pair.first_difference(&script);
    assert!(
        found.is_some(),
        "moved lines left in the static layer went unnoticed ({} retained frames)",
        pair.retained_frames
    );
    pair.finish();
}

/// Without the test hook, a gesture whose dynamic set is most of the frame's triangles draws
/// in full (a layer would cost two image copies and save little): rotating the middle local
/// patch of `examples/erbs_surface.json`, whose support is the whole surface, and dragging a
/// point of a scene of curves only. A drag whose support is a small part of the frame still
/// takes the retained path. All equal full.
#[test]
fn a_layer_that_would_not_pay_is_skipped() {
    let mut rng = Rng::new(11);
    let mut pair = Pair::new(&erbs_scene(), None);
    pair.runs[0].session.set_layer_always(false);
    check(&mut pair, &[vec![]], "first frame");
    let middle = pair.runs[0]
        .session
        .doc()
        .handles(0)
        .into_iter()
        .map(|(h, _)| h)
        .find(|h| {
            matches!(h, Handle::LocalPoint { local, .. }
                if local.steps() == [prespline::model::Index2::Two(1, 1)])
        })
        .expect("a point of the middle local patch");
    let before = pair.retained_frames;
    let script = transform(&mut rng, middle, 5);
    check(&mut pair, &script, "rotating the middle local patch");
    assert_eq!(
        pair.retained_frames, before,
        "a gesture over the whole surface drew from a layer"
    );
    pair.finish();

    let mut rng = Rng::new(3);
    let scene = random_scene(&mut rng);
    let mut pair = Pair::new(&scene, None);
    pair.runs[0].session.set_layer_always(false);
    let h = Handle::Point {
        object: 2,
        point: prespline::model::Index2::Two(2, 2),
    };
    let script = drag(&mut rng, h, false, 6);
    check(&mut pair, &script, "a drag on a scene of several objects");
    assert!(
        pair.retained_frames > 0,
        "a drag on one of several objects drew no frame from a layer"
    );
    pair.finish();

    // Curves only: no surface would stay in a layer.
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/bezier_curve.json"
    ))
    .unwrap();
    let mut pair = Pair::new(&parse_scene(&text).unwrap(), None);
    pair.runs[0].session.set_layer_always(false);
    let h = handle_of(&pair, &mut rng, 0);
    let script = drag(&mut rng, h, false, 6);
    check(&mut pair, &script, "a drag on a curve");
    assert_eq!(
        pair.retained_frames, 0,
        "a curve-only scene drew from a layer"
    );
    pair.finish();
}

/// [`random_scene`] with trims on its surfaces: a polygon with a circular hole on the Bézier
/// surface and its twin (domain [0, 1]²), a curved B-spline loop on the B-spline surface
/// (u over [0, 3]), a hole-only island in a ring on the NURBS surface (v over [0, 3]).
fn trimmed_scene(rng: &mut Rng) -> Scene {
    let json = prespline::formats::json::scene_to_json(&random_scene(rng));
    let hole = r#"{"hole": [{"bspline": [[0.7, 0.5], [0.7, 0.7], [0.5, 0.7], [0.3, 0.7], [0.3, 0.5], [0.3, 0.3], [0.5, 0.3], [0.7, 0.3], [0.7, 0.5]], "degree": 2, "knots": [0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1], "weights": [1, 0.7071067811865476, 1, 0.7071067811865476, 1, 0.7071067811865476, 1, 0.7071067811865476, 1]}]}"#;
    let unit = format!(
        r#""trim": [{{"outer": [{{"polyline": [[0.05, 0.1], [0.95, 0.05], [0.9, 0.95], [0.1, 0.9], [0.05, 0.1]]}}]}}, {hole}], "#
    );
    let curved = r#""trim": [{"loop": [{"bspline": [[0.2, 0.1], [1.5, 0.02], [2.8, 0.1], [2.9, 0.9], [1.5, 0.98], [0.1, 0.9], [0.2, 0.1]], "degree": 3, "knots": [0, 0, 0, 0, 0.25, 0.5, 0.75, 1, 1, 1, 1]}]}], "#;
    let ring = r#""trim": [{"loop": [{"polyline": [[0.05, 0.1], [0.95, 0.1], [0.95, 2.9], [0.05, 2.9], [0.05, 0.1]]}]}, {"loop": [{"polyline": [[0.2, 0.5], [0.2, 2.5], [0.8, 2.5], [0.8, 0.5], [0.2, 0.5]]}]}, {"loop": [{"polyline": [[0.4, 1.0], [0.6, 1.0], [0.6, 2.0], [0.4, 2.0], [0.4, 1.0]]}]}], "#;
    let text = json
        .replacen(
            "{\"name\": \"bez\", ",
            &format!("{{\"name\": \"bez\", {unit}"),
            1,
        )
        .replacen(
            "{\"name\": \"twin\", ",
            &format!("{{\"name\": \"twin\", {unit}"),
            1,
        )
        .replacen(
            "{\"name\": \"bsp\", ",
            &format!("{{\"name\": \"bsp\", {curved}"),
            1,
        )
        .replacen(
            "{\"name\": \"nurbs\", ",
            &format!("{{\"name\": \"nurbs\", {ring}"),
            1,
        );
    let scene = parse_scene(&text).unwrap();
    assert_eq!(
        scene.objects.iter().filter(|o| o.trim.is_some()).count(),
        4,
        "every surface is trimmed"
    );
    scene
}

/// With trims present the retained frames still equal the full redraw bit for bit at MSAA 1,
/// for point drags on every surface (the random handles include points whose support crosses
/// the trim boundary) and weight drags, with maps on and off.
#[test]
fn trimmed_surfaces_redraw_retained_exactly_as_in_full() {
    for seed in 0..2u64 {
        let mut rng = Rng::new(0x7e1a + seed);
        let scene = trimmed_scene(&mut rng);
        let map = (seed == 1).then(|| SurfaceMap::parse("mean").unwrap());
        let mut pair = Pair::new(&scene, map);
        check(&mut pair, &[vec![]], "first frame");
        for object in 0..4 {
            for _ in 0..2 {
                let h = handle_of(&pair, &mut rng, object);
                let script = drag(&mut rng, h, object == 3, 5);
                check(
                    &mut pair,
                    &script,
                    &format!("seed {seed}: trimmed drag of {h:?}"),
                );
            }
        }
        assert!(
            pair.retained_frames * 2 > pair.frames,
            "seed {seed}: only {} of {} frames were retained",
            pair.retained_frames,
            pair.frames
        );
        pair.finish();
    }
}

/// A dense control net (60 × 60 points a few pixels apart) draws only some of its grips
/// (src/render/grips.rs): drags of points on and off the drawn rows and columns, the dragged
/// grip shown wherever it is, redraw exactly as in full, with the net of a second, coarse
/// surface over it.
#[test]
fn thinned_grips_of_a_dense_net_redraw_exactly() {
    let mut rng = Rng::new(0x9e1d);
    let n = 60;
    let points: Vec<String> = (0..n)
        .map(|i| {
            let row: Vec<String> = (0..n)
                .map(|j| {
                    let (x, y) = (i as f64 * 0.12 - 3.5, j as f64 * 0.12 - 3.5);
                    format!("[{x}, {y}, {}]", 0.3 * (x * 1.3).sin() * (y * 0.9).cos())
                })
                .collect();
            format!("[{}]", row.join(", "))
        })
        .collect();
    let knots: Vec<String> = (0..n + 4)
        .map(|k| k.clamp(3, n) as f64)
        .map(|k| k.to_string())
        .collect();
    let knots = knots.join(", ");
    let coarse = points_json(&mut rng, 4, 4, -1.0);
    let text = format!(
        r#"{{"objects": [
  {{"name": "dense", "type": "bspline_surface", "degree": [3, 3],
    "knots": [[{knots}], [{knots}]], "points": [{}], "samples": [120, 120]}},
  {{"name": "coarse", "type": "bezier_surface", "points": {coarse}, "samples": [30, 30]}}
]}}"#,
        points.join(", ")
    );
    let scene = parse_scene(&text).unwrap();
    let mut pair = Pair::new(&scene, None);
    check(&mut pair, &[vec![]], "first frame");
    let on_and_off = [(8, 8), (8, 9), (13, 31), (59, 59), (0, 30), (31, 0)];
    for (a, b) in on_and_off {
        let h = Handle::Point {
            object: 0,
            point: prespline::model::Index2::Two(a, b),
        };
        let script = drag(&mut rng, h, false, 4);
        check(&mut pair, &script, &format!("drag of ({a}, {b})"));
    }
    let h = handle_of(&pair, &mut rng, 1);
    check(
        &mut pair,
        &drag(&mut rng, h, false, 4),
        "drag of the coarse net",
    );
    assert!(pair.retained_frames * 2 > pair.frames);
    pair.finish();
}
