//! Hierarchical ERBS editing in the viewer (Xvfb in `make test`, lavapipe): I refines an ERBS
//! surface at the cursor, X turns a local patch into an ERBS of its own, G moves one of its
//! local patches (a level-2 detail), I refines inside that detail, and undoing everything saves
//! the original scene bit for bit.

mod common;

use prespline::editor::Handle;
use prespline::geom::erbs::{ErbsCurve, ErbsSurface, LocalCurve, LocalPatch};
use prespline::model::{Index2, LocalPath, Model};
use prespline::scene::Scene;
use prespline::view::Session;
use prespline::view::input::{InputEvent, Key, Modifiers, MouseButton};
use prespline::view::script::Action;
use std::path::Path;
use std::process::Command;
use std::time::Duration;

/// The example's 3 × 3 biquadratic domes (knots 0, 1, 2 in u and v).
const SCENE: &str = include_str!("../examples/erbs_surface.json");

/// `UNDO` becomes the undos, `SHOT` the screenshot's path. Refinements aim at the surface by
/// parameter, off every knot (u, v = 0, 1, 2 and the refinements' new ones): first at
/// (0.5, 1.5) on the object (a new u knot 0.5 makes local [1, 1] the one on [0, 1] × [0, 2]),
/// then at (0.75, 1.5), inside that local once X has made it a detail.
const SCRIPT: &str = r#"[
 {"frame": 3, "move_to": {"object": "domes", "local": [1, 1], "point": [1, 1]}},
 {"frame": 4, "press": "left"},
 {"frame": 5, "release": "left"},
 {"frame": 6, "move_to": {"object": "domes", "at": [0.5, 1.5]}},
 {"frame": 7, "key": "i"},
 {"frame": 8, "key": "enter"},
 {"frame": 10, "move_to": {"object": "domes", "local": [1, 1], "point": [1, 1]}},
 {"frame": 11, "press": "left"},
 {"frame": 12, "release": "left"},
 {"frame": 13, "key": "x"},
 {"frame": 15, "move_to": {"object": "domes", "local": [[1, 1], [1, 1]], "point": [1, 1]}},
 {"frame": 16, "press": "left"},
 {"frame": 17, "release": "left"},
 {"frame": 18, "key": "g"},
 {"frame": 19, "key": "z"},
 {"frame": 20, "type": "0.8"},
 {"frame": 21, "key": "enter"},
 {"frame": 24, "move_to": {"object": "domes", "at": [0.75, 1.5]}},
 {"frame": 25, "key": "i"},
 {"frame": 26, "key": "v"},
 {"frame": 27, "key": "enter"},
 {"frame": 29, "key": "w"},
 {"frame": 30, "screenshot": "SHOT", "hud": true}
 UNDO,
 {"frame": 60, "key": "s", "ctrl": true},
 {"frame": 62, "quit": true}
]"#;

fn run(dir: &Path, undos: usize) -> Scene {
    let scene = dir.join("scene.json");
    std::fs::write(&scene, SCENE).unwrap();
    let saved = dir.join(format!("saved-{undos}.json"));
    let shot = dir.join(format!("shot-{undos}.png"));
    let undo: String = (0..undos)
        .map(|k| {
            format!(
                ", {{\"frame\": {}, \"key\": \"z\", \"ctrl\": true}}",
                32 + 2 * k
            )
        })
        .collect();
    let script = dir.join(format!("script-{undos}.json"));
    std::fs::write(
        &script,
        SCRIPT
            .replace("SHOT", shot.to_str().unwrap())
            .replace("\n UNDO,", &format!("{undo},")),
    )
    .unwrap();
    let icd = prespline::gpu::LAVAPIPE_ICD;
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_prespline"));
    cmd.env("VK_DRIVER_FILES", icd)
        .env("VK_ICD_FILENAMES", icd)
        .env("PRESPLINE_VALIDATION", "1")
        .args(["view", "--size", "960x600", "--script"])
        .arg(&script)
        .arg("--save-as")
        .arg(&saved)
        .arg(&scene);
    let out = common::output_with_timeout(&mut cmd, Duration::from_secs(300));
    assert!(
        out.status.success(),
        "viewer failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    prespline::formats::read_json(&saved).unwrap()
}

fn domes(s: &Scene) -> ErbsSurface {
    match &s.objects[s.find("domes").unwrap()].model {
        Model::ErbsSurface(m) => m.surface().clone(),
        other => panic!("domes is an erbs_surface, found {}", other.type_name()),
    }
}

/// The ERBS local made with X.
fn detail(s: &ErbsSurface) -> ErbsSurface {
    match s.local_at(&[[1, 1]]) {
        Some(LocalPatch::Erbs(e)) => (**e).clone(),
        _ => panic!("local [1, 1] became an ERBS local"),
    }
}

#[test]
fn erbs_refine_nest_transform_and_undo_exactly() {
    if !common::display() {
        return;
    }
    let dir = common::Scratch::new("view-erbs");
    let original = prespline::formats::parse_scene(SCENE).unwrap();
    let before = domes(&original);
    assert_eq!(before.count(), [3, 3]);

    let edited = domes(&run(dir.path(), 0));
    // I + Enter on the object: one more row of local patches (u, the default direction).
    assert_eq!(edited.count(), [4, 3], "the object was refined in u");
    // X made local [1, 1] an ERBS of 3 × 3 patches; I refined it in v.
    assert_eq!(
        detail(&edited).count(),
        [3, 4],
        "the detail was refined in v"
    );
    assert_eq!(
        edited.depth(),
        2,
        "two ERBS levels: the object and the detail"
    );

    // One undo takes back the refinement inside the detail, two the G of its local patch too.
    let moved = detail(&domes(&run(dir.path(), 1)));
    let made = detail(&domes(&run(dir.path(), 2)));
    assert_eq!((moved.count(), made.count()), ([3, 3], [3, 3]));
    // X kept the shape (3 Hermite patches of the local's degree 2 reproduce it) and G moved
    // exactly one level-2 patch, by exactly 0.8 along z.
    let changed: Vec<usize> = (0..9)
        .filter(|&k| moved.local_patches()[k] != made.local_patches()[k])
        .collect();
    assert_eq!(changed.len(), 1, "one level-2 patch moved: {changed:?}");
    let k = changed[0];
    let (Some((_, a)), Some((_, b))) = (
        made.local_patches()[k].net(),
        moved.local_patches()[k].net(),
    ) else {
        panic!("level-2 patches are polynomial")
    };
    for (p, q) in a.iter().zip(b) {
        let d = *q - *p;
        assert!(
            d.x == 0.0 && d.y == 0.0 && (d.z - 0.8).abs() < 1e-12,
            "moved by {d}"
        );
    }

    // Four steps (refine, X, G, refine inside) undone: the original scene, bit for bit.
    let undone = run(dir.path(), 4);
    assert!(undone == original, "undo must restore the scene exactly");
    assert_eq!(
        prespline::formats::json::scene_to_json(&undone),
        prespline::formats::json::scene_to_json(&original)
    );
    let shot = prespline::gpu::Pixels::read_png(&dir.join("shot-0.png")).unwrap();
    assert!(shot.width == 960 && shot.height == 600);
    // Kept for a look: the refined, nested and raised detail with the wireframe (W) and HUD.
    std::fs::copy(
        dir.join("shot-0.png"),
        Path::new(env!("CARGO_TARGET_TMPDIR")).join("view_erbs.png"),
    )
    .unwrap();
}

/// An ERBS curve whose local 1 is a straight, evenly parametrised quadratic: its middle control
/// point is the curve's point at the knot t = 1, which is a sample (121 samples on [0, 2]).
const CURVE: &str = r#"{"objects": [
  {"name": "erbs", "type": "erbs_curve", "knots": [0, 0, 1, 2, 2],
   "local": [{"points": [[-1.2, -0.4, 0], [0.0, 1.6, 0], [1.2, -0.2, 0]]},
             {"points": [[0.8, -0.4, 0], [2.0, 0.0, 0], [3.2, 0.4, 0]]},
             {"points": [[2.8, -0.4, 0], [4.0, 1.6, 0], [5.2, -0.2, 0]]}], "samples": 121}
]}"#;

struct Headless {
    session: Session,
    renderer: prespline::gpu::Renderer,
    sink: prespline::gpu::ValidationSink,
}

impl Headless {
    fn new(text: &str) -> Self {
        Self::with_scene(&prespline::formats::parse_scene(text).unwrap())
    }

    fn with_scene(scene: &Scene) -> Self {
        let (mut renderer, sink) = common::renderer();
        let session = Session::open(
            &mut renderer,
            scene,
            std::env::temp_dir().join("unused.json"),
            [800, 600],
            prespline::sampling::budget::MemoryBudget::machine_default(),
        )
        .unwrap();
        Self {
            session,
            renderer,
            sink,
        }
    }

    fn key(&mut self, key: Key, ctrl: bool) {
        self.session.perform(Action::Key {
            key,
            mods: Modifiers {
                ctrl,
                ..Modifiers::default()
            },
        });
    }

    fn select(&mut self, local: &[usize], point: usize) {
        let path: Vec<Index2> = local.iter().map(|&l| Index2::One(l)).collect();
        self.click(Handle::LocalPoint {
            object: 0,
            local: LocalPath::new(&path).unwrap(),
            point: Index2::One(point),
        });
    }

    fn click(&mut self, handle: Handle) {
        self.session.perform(Action::MoveTo(handle));
        for pressed in [true, false] {
            self.session.perform(Action::Input(InputEvent::Button {
                button: MouseButton::Left,
                pressed,
            }));
        }
        assert_eq!(self.session.selected(), Some(handle), "the click missed");
    }

    /// I, then Enter: refine at the cursor.
    fn refine(&mut self) {
        self.key(Key::Char('i'), false);
        self.key(Key::Enter, false);
    }

    fn curve(&mut self) -> ErbsCurve {
        self.session.apply_pending();
        match self.session.doc().to_scene().objects[0].model.clone() {
            Model::ErbsCurve(m) => m.curve().clone(),
            _ => panic!("an erbs_curve"),
        }
    }

    fn finish(self) {
        let Headless {
            session,
            mut renderer,
            sink,
        } = self;
        session.destroy(&mut renderer);
        common::teardown(renderer, sink);
    }
}

#[test]
fn refining_on_a_knot_is_refused_and_refinement_and_x_undo_exactly() {
    let mut v = Headless::new(CURVE);
    let original = v.curve();

    // The cursor on the knot t = 1 (local 1's middle point): refused on the status line.
    v.select(&[1], 1);
    v.refine();
    assert!(
        v.session.status().starts_with("cannot refine:") && v.session.status().contains("knot"),
        "{}",
        v.session.status()
    );
    assert_eq!(v.curve(), original, "nothing changed");
    assert_eq!(v.session.undo_depth().0, 0, "no undo step");

    // Off the knot, on the curve's sample at t = 1.25 (121 samples on [0, 2]): a new local
    // curve there, between knots 1 and 2.
    v.session.perform(Action::MoveOnto {
        object: 0,
        at: [1.25, 0.0],
    });
    v.refine();
    assert!(
        v.session.status().starts_with("refined erbs at t = 1.2500"),
        "{}",
        v.session.status()
    );
    let refined = v.curve();
    assert_eq!(refined.local_curves().len(), 4);
    for &t in &[0.0, 1.0, 2.0] {
        assert_eq!(
            refined.eval(t),
            original.eval(t),
            "old knot {t} keeps its point"
        );
    }
    v.key(Key::Char('z'), true);
    assert_eq!(v.curve(), original, "Ctrl+Z restores exactly");

    // X: local 1 becomes an ERBS of 3 quadratic local curves with the same shape.
    v.select(&[1], 0);
    v.key(Key::Char('x'), false);
    assert!(
        v.session
            .status()
            .contains("is an ERBS now: 3 curves of degree 2"),
        "{}",
        v.session.status()
    );
    let nested = v.curve();
    let LocalCurve::Erbs(detail) = &nested.local_curves()[1] else {
        panic!("local 1 became an ERBS local")
    };
    assert_eq!(detail.local_curves().len(), 3);
    for k in 0..=40 {
        let t = k as f64 / 20.0;
        let (a, b) = (original.eval(t), nested.eval(t));
        assert!((a - b).length() < 1e-12, "same shape at {t}: {a} vs {b}");
    }
    // The detail's own locals are selectable, G moves one (exactly 0.25 along z)…
    v.select(&[1, 0], 1);
    for k in [Key::Char('g'), Key::Char('z')] {
        v.key(k, false);
    }
    v.session.perform(Action::Type("0.25".into()));
    v.key(Key::Enter, false);
    let moved = v.curve();
    let (Some(LocalCurve::Spline { curve: a, .. }), Some(LocalCurve::Spline { curve: b, .. })) =
        (nested.local_at(&[1, 0]), moved.local_at(&[1, 0]))
    else {
        panic!("level-2 locals are polynomial")
    };
    for (p, q) in a.points().iter().zip(b.points()) {
        assert_eq!(*q - *p, glam::DVec3::new(0.0, 0.0, 0.25), "G Z 0.25");
    }
    // … and I refines inside the detail: the level of the selected level-2 local.
    v.select(&[1, 0], 1);
    v.refine();
    assert!(
        v.session.status().contains("in local 1"),
        "{}",
        v.session.status()
    );
    let inner = v.curve();
    let LocalCurve::Erbs(detail) = &inner.local_curves()[1] else {
        panic!("still an ERBS local")
    };
    assert_eq!(detail.local_curves().len(), 4, "the detail was refined");
    assert_eq!(inner.local_curves().len(), 3, "the object was not");
    for _ in 0..3 {
        v.key(Key::Char('z'), true);
    }
    assert_eq!(v.curve(), original, "three undos restore exactly");
    v.finish();
}

#[test]
fn closed_torus_refines_across_its_seam_and_inside_a_detail_there() {
    let scene = prespline::formats::demo::demo_scene();
    let object = scene.find("erbs_torus").unwrap();
    let mut v = Headless::with_scene(&scene);
    let torus = |v: &mut Headless| {
        v.session.apply_pending();
        match v.session.doc().to_scene().objects[object].model.clone() {
            Model::ErbsSurface(m) => m.surface().clone(),
            _ => panic!("the torus is an erbs_surface"),
        }
    };
    let original = torus(&mut v);
    let patch = |path: &[[usize; 2]], point: [usize; 2]| Handle::LocalPoint {
        object,
        local: LocalPath::new(
            &path
                .iter()
                .map(|&[a, b]| Index2::Two(a, b))
                .collect::<Vec<_>>(),
        )
        .unwrap(),
        point: Index2::Two(point[0], point[1]),
    };
    // Local patch [0, 0] straddles both seams; X makes it a detail of 3 × 3 bicubic patches.
    // Zoomed in towards it, so that its points are apart on screen.
    v.session.perform(Action::MoveTo(patch(&[[0, 0]], [1, 1])));
    v.session
        .perform(Action::Input(InputEvent::Wheel { delta: 12.0 }));
    v.click(patch(&[[0, 0]], [1, 1]));
    v.key(Key::Char('x'), false);
    let detail = match torus(&mut v).local_at(&[[0, 0]]) {
        Some(LocalPatch::Erbs(e)) => (**e).clone(),
        _ => panic!("local [0, 0] became an ERBS local"),
    };
    assert_eq!((detail.count(), detail.closed()), ([3, 3], [false, false]));
    // I on one of the detail's patches refines the detail, whichever side of the seam the
    // cursor's parameter is on (the torus's parameter is taken one period off where needed).
    for (dir, at) in [('u', [0.08, 0.09]), ('v', [0.91, 0.92])] {
        v.click(patch(&[[0, 0], [1, 1]], [1, 1]));
        // The cursor onto the surface inside the detail, on either side of the seam (a
        // control point's projection may fall on the surface elsewhere).
        v.session.perform(Action::MoveOnto { object, at });
        v.key(Key::Char('i'), false);
        v.key(Key::Char(dir), false);
        v.key(Key::Enter, false);
        assert!(
            v.session.status().contains("in local [0, 0]"),
            "{}",
            v.session.status()
        );
    }
    let refined = torus(&mut v);
    match refined.local_at(&[[0, 0]]) {
        Some(LocalPatch::Erbs(e)) => assert_eq!(e.count(), [4, 4], "refined in u and v"),
        _ => panic!("still an ERBS local"),
    }
    assert_eq!(
        refined.count(),
        original.count(),
        "the torus itself was not refined"
    );
    for _ in 0..3 {
        v.key(Key::Char('z'), true);
    }
    assert_eq!(torus(&mut v), original, "undo restores the torus exactly");
    v.finish();
}

/// The detail example of docs/viewer.md: the refinements move nothing outside the refined strips
/// u ∈ (2, 3) and v ∈ (2, 3), X keeps the surface, and the level-2 local patch raised by 0.5 raises the surface by
/// exactly 0.5 at its centre and nothing outside its support [2.5, 3]².
#[test]
fn detail_example_raises_a_bump_only_inside_the_refined_patch() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
    let scene = prespline::formats::read_json(&dir.join("erbs_detail.json")).unwrap();
    let text = std::fs::read_to_string(dir.join("erbs_detail_edits.json")).unwrap();
    let edits = prespline::scene::parse_edits(&text, &scene).unwrap();
    assert_eq!(edits.len(), 6);
    // The surface after the first `n` edits.
    let after = |n: usize| {
        let mut s = scene.clone();
        prespline::scene::edit::apply_all(&mut s, &edits[..n]).unwrap();
        match &s.objects[0].model {
            Model::ErbsSurface(m) => m.surface().clone(),
            _ => panic!("the detail is an erbs_surface"),
        }
    };
    let (source, refined, made, raised) = (after(0), after(4), after(5), after(6));
    assert_eq!(refined.count(), [7, 7], "two knots in u and two in v");
    assert_eq!(raised.depth(), 2, "two ERBS levels: a level-2 patch");
    let grid = (0..=40).flat_map(|i| (0..=40).map(move |j| (i as f64 * 0.1, j as f64 * 0.1)));
    let within = |t: f64, (a, b): (f64, f64)| t > a && t < b;
    for (u, v) in grid {
        let moved = |x: &ErbsSurface, y: &ErbsSurface| (x.eval(u, v) - y.eval(u, v)).length();
        if !within(u, (2.0, 3.0)) && !within(v, (2.0, 3.0)) {
            assert!(
                moved(&source, &refined) < 1e-12,
                "refinement moved ({u}, {v})"
            );
        }
        assert!(moved(&refined, &made) < 1e-12, "X moved ({u}, {v})");
        if !(within(u, (2.5, 3.0)) && within(v, (2.5, 3.0))) {
            assert!(moved(&made, &raised) < 1e-12, "the bump reaches ({u}, {v})");
        }
    }
    let lift = raised.eval(2.75, 2.75) - made.eval(2.75, 2.75);
    assert!(
        (lift - glam::DVec3::new(0.0, 0.0, 0.5)).length() < 1e-12,
        "{lift}"
    );
}

/// A `move_to` a point that does not exist when the event runs (no X made local [1, 1] an ERBS
/// local) ends the replay with one error line naming it; parsing accepted it, since an earlier
/// refinement could have made it.
#[test]
fn script_move_to_a_missing_nested_local_fails_with_one_line() {
    if !common::display() {
        return;
    }
    let dir = common::Scratch::new("view-erbs-missing");
    let scene = dir.file("scene.json", SCENE);
    let script = dir.file(
        "script.json",
        r#"[{"frame": 2, "move_to": {"object": "domes", "local": [[1, 1], [0, 0]], "point": [1, 1]}},
            {"frame": 4, "quit": true}]"#,
    );
    let icd = prespline::gpu::LAVAPIPE_ICD;
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_prespline"));
    cmd.env("VK_DRIVER_FILES", icd)
        .env("VK_ICD_FILENAMES", icd)
        .args(["view", "--size", "640x400", "--script"])
        .arg(&script)
        .arg(&scene);
    let out = common::output_with_timeout(&mut cmd, Duration::from_secs(120));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "the replay must fail: {err}");
    let line = err
        .lines()
        .find(|l| l.contains("move_to"))
        .unwrap_or_else(|| panic!("no move_to error in: {err}"));
    assert!(
        line.contains("there is no domes local [1, 1] → [0, 0] point [1, 1] now"),
        "{line}"
    );
}

/// Catmull–Rom and Bézier splines: I, E and Shift+W refuse at the key press, each with its
/// reason and the way out (B converts to a bspline_curve); nothing changes and no tool is left
/// waiting for Enter.
#[test]
fn catmull_rom_refuses_knots_elevation_and_weights_at_the_key_press() {
    let catmull_rom = r#"{"objects": [{"name": "cr", "type": "catmull_rom", "points": [[0,0,0],[1,1,0],[2,0,0],[3,1,0]], "samples": 64}]}"#;
    let bezier_spline = r#"{"objects": [{"name": "bz", "type": "bezier_spline", "degree": 3, "knots": [0, 1, 2], "points": [[0,0,0],[0.5,1,0],[1,1,0],[1.5,0,0],[2,-1,0],[2.5,-1,0],[3,0,0]], "continuity": "C0", "samples": 64}]}"#;
    for (scene, kind) in [
        (catmull_rom, "catmull_rom"),
        (bezier_spline, "bezier_spline"),
    ] {
        let mut h = Headless::new(scene);
        h.click(Handle::Point {
            object: 0,
            point: Index2::One(1),
        });
        let before = h.session.to_scene();
        for (key, shift) in [
            (Key::Char('i'), false),
            (Key::Char('e'), false),
            (Key::Char('w'), true),
        ] {
            h.session.perform(Action::Key {
                key,
                mods: Modifiers {
                    shift,
                    ..Modifiers::default()
                },
            });
            let status = h.session.status().to_string();
            assert!(
                status.contains(kind) && status.contains("B converts it to a bspline_curve"),
                "{kind}, {key:?}: {status}"
            );
            // Enter must not run a tool the key press refused.
            h.key(Key::Enter, false);
            assert_eq!(
                h.session.status(),
                status,
                "{kind}, {key:?}: Enter did something"
            );
        }
        assert_eq!(h.session.to_scene(), before, "{kind}");
        assert_eq!(h.session.undo_depth(), (0, 0), "{kind}");
        h.finish();
    }
}
