//! The viewer's session core without a window (lavapipe, validation required): redo, scale and
//! cancel of ERBS local transforms checked exactly on the model, and the autosave — written at
//! most a second after an edit, on every way out, removed by a clean save, never overwriting an
//! earlier session's, falling back to the state directory and backing off when it cannot be
//! written, with its notes on the status line — plus durable (fsynced) scene writes.

mod common;

use glam::{DMat4, DVec3};
use prespline::editor::Handle;
use prespline::formats::parse_scene;
use prespline::model::{Index2, LocalPath, Model};
use prespline::sampling::budget::MemoryBudget;
use prespline::scene::Scene;
use prespline::view::Session;
use prespline::view::autosave::{AUTOSAVE_DELAY, Autosave, Places, RETRY_FIRST};
use prespline::view::input::{InputEvent, Key, Modifiers, MouseButton};
use prespline::view::script::Action;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// An ERBS curve with three local Bézier curves, and a B-spline curve.
const SCENE: &str = r#"{"objects": [
  {"name": "erbs", "type": "erbs_curve", "knots": [0, 0, 1, 2, 2],
   "local": [{"points": [[-1.2, -0.4, 0], [0.0, 1.6, 0], [1.2, -0.2, 0]]},
             {"points": [[0.8, -0.4, 0], [2.0, 2.0, 0.5], [3.2, -0.2, 0]]},
             {"points": [[2.8, -0.4, 0], [4.0, 1.6, 0], [5.2, -0.2, 0]]}], "samples": 120},
  {"name": "spline", "type": "bspline_curve", "degree": 3, "knots": [0, 0, 0, 0, 1, 2, 2, 2, 2],
   "points": [[0, -2, 0], [1, -1, 0], [2, -2.5, 0], [3, -1, 0], [4, -2, 0]], "samples": 60}
]}"#;

struct Viewer {
    session: Session,
    renderer: prespline::gpu::Renderer,
    sink: prespline::gpu::ValidationSink,
}

impl Viewer {
    fn new(save_path: PathBuf) -> Self {
        Self::with_scene(SCENE, save_path)
    }

    fn with_scene(text: &str, save_path: PathBuf) -> Self {
        let (mut renderer, sink) = common::renderer();
        let scene = parse_scene(text).unwrap();
        let session = Session::open(
            &mut renderer,
            &scene,
            save_path,
            [800, 600],
            MemoryBudget::machine_default(),
        )
        .unwrap();
        Viewer {
            session,
            renderer,
            sink,
        }
    }

    fn key(&mut self, c: char, ctrl: bool, shift: bool) {
        self.session.perform(Action::Key {
            key: Key::Char(c),
            mods: Modifiers {
                ctrl,
                shift,
                alt: false,
            },
        });
    }

    fn press(&mut self, key: Key) {
        self.session.perform(Action::Key {
            key,
            mods: Modifiers::default(),
        });
    }

    fn click(&mut self, button: MouseButton) {
        for pressed in [true, false] {
            self.session
                .perform(Action::Input(InputEvent::Button { button, pressed }));
        }
    }

    /// Aims at a control point and clicks it (selects it, and its local curve).
    fn select(&mut self, handle: Handle) {
        self.session.perform(Action::MoveTo(handle));
        self.click(MouseButton::Left);
        assert_eq!(self.session.selected(), Some(handle), "the click missed");
    }

    fn typed(&mut self, text: &str) {
        self.session.perform(Action::Type(text.into()));
    }

    fn scene(&mut self) -> Scene {
        self.session.apply_pending();
        self.session.doc().to_scene()
    }

    fn finish(self) {
        let Viewer {
            session,
            mut renderer,
            sink,
        } = self;
        session.destroy(&mut renderer);
        common::teardown(renderer, sink);
    }
}

fn local_point(local: usize, point: usize) -> Handle {
    Handle::LocalPoint {
        object: 0,
        local: LocalPath::top(Index2::One(local)),
        point: Index2::One(point),
    }
}

fn local_points(scene: &Scene, local: usize) -> Vec<DVec3> {
    match &scene.objects[0].model {
        Model::ErbsCurve(c) => c.curve().local_curves()[local]
            .points()
            .expect("a polynomial local")
            .to_vec(),
        other => panic!("not an ERBS curve: {other:?}"),
    }
}

fn spline_points(scene: &Scene) -> Vec<DVec3> {
    match &scene.objects[1].model {
        Model::Curve(c) => c.curve().points().to_vec(),
        other => panic!("not a B-spline curve: {other:?}"),
    }
}

#[test]
fn typed_scale_scales_the_local_curve_about_its_centre() {
    let scratch = common::Scratch::new("view-session");
    let mut v = Viewer::new(scratch.join("saved.json"));
    let before = v.scene();
    v.select(local_point(1, 1));
    v.key('s', false, false);
    v.typed("2");
    v.press(Key::Enter);
    let after = v.scene();
    let old = local_points(&before, 1);
    let centre = old.iter().sum::<DVec3>() / old.len() as f64;
    let m = DMat4::from_translation(centre)
        * DMat4::from_scale(DVec3::splat(2.0))
        * DMat4::from_translation(-centre);
    for (p, q) in old.iter().zip(local_points(&after, 1)) {
        let expect = m.transform_point3(*p);
        assert!(
            (q - expect).length() <= 1e-14 * (1.0 + expect.length()),
            "{p} scaled by 2 about {centre}: expected {expect}, got {q}"
        );
    }
    for l in [0, 2] {
        assert_eq!(local_points(&before, l), local_points(&after, l));
    }
    assert_eq!(v.session.undo_depth(), (1, 0), "one undo step");
    // Scaling along one axis only, by a typed value that passes through 0 while it is typed
    // ("0", "0.", "0.5"): a singular transform on the way must not turn the points into NaN.
    v.key('s', false, false);
    v.key('z', false, false);
    v.typed("0.5");
    v.press(Key::Enter);
    let squashed = v.scene();
    let c2 = local_points(&after, 1).iter().sum::<DVec3>() / 3.0;
    for (p, q) in local_points(&after, 1)
        .iter()
        .zip(local_points(&squashed, 1))
    {
        assert_eq!((p.x, p.y), (q.x, q.y), "x and y stay");
        assert!((q.z - (c2.z + 0.5 * (p.z - c2.z))).abs() < 1e-14);
    }
    v.finish();
}

#[test]
fn cancel_restores_the_model_bit_for_bit() {
    let scratch = common::Scratch::new("view-session");
    let mut v = Viewer::new(scratch.join("saved.json"));
    let before = v.scene();
    v.select(local_point(2, 0));
    // Each transform kind, cancelled by Esc and by a right click, with a typed value and with
    // cursor motion applied live before the cancel.
    for (kind, value) in [('g', "0.7"), ('r', "33"), ('s', "1.9")] {
        for cancel_by_escape in [true, false] {
            v.key(kind, false, false);
            v.session.perform(Action::MoveBy(37.0, -21.0));
            v.typed(value);
            assert_ne!(v.scene(), before, "{kind}: the transform shows live");
            if cancel_by_escape {
                v.press(Key::Escape);
            } else {
                v.click(MouseButton::Right);
            }
            assert_eq!(
                v.scene(),
                before,
                "{kind} cancelled: the model must be exactly as before"
            );
        }
    }
    assert_eq!(
        v.session.undo_depth(),
        (0, 0),
        "a cancelled transform leaves no undo step"
    );
    v.finish();
}

#[test]
fn redo_reapplies_undone_edits_exactly() {
    let scratch = common::Scratch::new("view-session");
    let mut v = Viewer::new(scratch.join("saved.json"));
    let original = v.scene();
    // A point drag on the B-spline curve.
    let handle = Handle::Point {
        object: 1,
        point: Index2::One(2),
    };
    v.session.perform(Action::MoveTo(handle));
    v.session.perform(Action::Input(InputEvent::Button {
        button: MouseButton::Left,
        pressed: true,
    }));
    v.session.perform(Action::MoveBy(25.0, -40.0));
    v.session.perform(Action::MoveBy(10.0, -5.0));
    v.session.perform(Action::Input(InputEvent::Button {
        button: MouseButton::Left,
        pressed: false,
    }));
    let dragged = v.scene();
    assert_ne!(spline_points(&dragged)[2], spline_points(&original)[2]);
    // A rotation of a local curve on top.
    v.select(local_point(0, 2));
    v.key('r', false, false);
    v.typed("45");
    v.press(Key::Enter);
    let rotated = v.scene();
    assert_eq!(v.session.undo_depth(), (2, 0));

    v.key('z', true, false);
    assert_eq!(v.scene(), dragged, "undo of the rotation");
    v.key('z', true, false);
    assert_eq!(v.scene(), original, "undo of the drag");
    assert_eq!(v.session.undo_depth(), (0, 2));
    v.key('z', true, true);
    assert_eq!(v.scene(), dragged, "Ctrl+Shift+Z redoes the drag exactly");
    v.key('y', true, false);
    assert_eq!(v.scene(), rotated, "Ctrl+Y redoes the rotation exactly");
    assert_eq!(v.session.undo_depth(), (2, 0));
    v.key('y', true, false);
    assert_eq!(v.scene(), rotated, "nothing left to redo");
    // A new edit after an undo drops the redo branch.
    v.key('z', true, false);
    v.select(local_point(1, 0));
    v.key('g', false, false);
    v.key('x', false, false);
    v.typed("1");
    v.press(Key::Enter);
    assert_eq!(v.session.undo_depth(), (2, 0));
    v.finish();
}

/// Moves local curve 1's first point by a typed exact amount (one edit).
fn typed_move(v: &mut Viewer, amount: &str) {
    v.select(local_point(1, 0));
    v.key('g', false, false);
    v.key('z', false, false);
    v.typed(amount);
    v.press(Key::Enter);
}

/// Autosave of the scene `scene` with no state directory.
fn autosave_beside(scene: &Path) -> Autosave {
    Autosave::new(Places::new(Some(scene), None))
}

#[test]
fn autosave_is_written_within_a_second_of_an_edit_and_removed_by_a_clean_save() {
    let scratch = common::Scratch::new("view-session");
    let path = scratch.join("scene.autosave.json");
    let mut v = Viewer::new(scratch.join("scene.json"));
    v.session
        .set_autosave(Some(autosave_beside(&scratch.join("scene.json"))));
    assert_eq!(v.session.tick(Instant::now()), None, "nothing to write");
    assert_eq!(v.session.on_exit(), Ok(None), "no edits, no autosave");
    assert!(!path.exists());

    typed_move(&mut v, "0.25");
    v.session.apply_pending(); // the frame that shows it
    let edited_at = Instant::now();
    let due = v.session.tick(edited_at).expect("an autosave is due");
    assert!(due <= edited_at + AUTOSAVE_DELAY && due > edited_at);
    assert!(!path.exists(), "not before its time");
    // Edits during the second join the same write and do not postpone it.
    typed_move(&mut v, "0.25");
    v.session.apply_pending();
    assert_eq!(v.session.tick(Instant::now()), Some(due));
    assert_eq!(v.session.tick(due), None, "written, nothing more due");
    let model = v.scene();
    assert_eq!(
        prespline::formats::read_json(&path).unwrap(),
        model,
        "the autosave holds the exact model"
    );

    // Ctrl+S: the scene file gets the model, the autosave goes.
    v.key('s', true, false);
    assert!(!path.exists(), "a clean save removes the autosave");
    assert_eq!(
        prespline::formats::read_json(&scratch.join("scene.json")).unwrap(),
        model
    );
    assert_eq!(v.session.on_exit(), Ok(None), "saved: nothing to keep");
    assert!(!path.exists());
    v.finish();
}

#[test]
fn every_way_out_writes_the_autosave() {
    let scratch = common::Scratch::new("view-session");
    // Quit (window close, Ctrl+Q, a script's quit, an error exit all end in on_exit): the
    // edit of this very frame, not yet applied, is included.
    for fatal in [false, true] {
        let scene = scratch.join(format!("scene-{fatal}.json"));
        let path = scratch.join(format!("scene-{fatal}.autosave.json"));
        let mut v = Viewer::new(scene.clone());
        v.session.set_autosave(Some(autosave_beside(&scene)));
        typed_move(&mut v, "-0.5");
        v.select(local_point(2, 1));
        v.key('g', false, false);
        v.key('y', false, false);
        v.typed("0.125");
        v.press(Key::Enter);
        let kept = if fatal {
            // Device loss: the app calls this hook before tearing anything down.
            v.session.on_fatal_exit()
        } else {
            v.session.on_exit()
        };
        let kept = kept.unwrap().expect("the edits are kept");
        assert_eq!(kept.path, path, "the path to print");
        assert_eq!(
            kept.command,
            format!("prespline view {} --recover", scene.display()),
            "the command names the real scene"
        );
        let model = v.scene();
        assert_eq!(prespline::formats::read_json(&path).unwrap(), model);
        let p = local_points(&model, 2)[1];
        let p0 = local_points(&parse_scene(SCENE).unwrap(), 2)[1];
        assert_eq!(p.y, p0.y + 0.125);
        v.finish();
    }
}

/// A session that finds an earlier session's autosave (not recovered) moves it aside to a
/// timestamped name before writing its own, and says so on the status line; the start-up
/// note (how many are waiting) is on the status line too.
#[test]
fn an_earlier_sessions_autosave_is_kept_aside() {
    let scratch = common::Scratch::new("view-session");
    let scene = scratch.join("scene.json");
    let path = scratch.join("scene.autosave.json");
    std::fs::write(&path, SCENE).unwrap();
    let mut v = Viewer::new(scene.clone());
    let places = Places::new(Some(&scene), None);
    let mut autosave = Autosave::new(places.clone());
    autosave.notify(places.waiting_note(None).expect("one is waiting"));
    v.session.set_autosave(Some(autosave));
    assert!(
        v.session.status().starts_with("note: 1 autosave of ")
            && v.session.status().contains(&path.display().to_string()),
        "{}",
        v.session.status()
    );
    typed_move(&mut v, "1");
    assert!(v.session.on_exit().unwrap().is_some());
    let waiting = places.waiting();
    assert_eq!(waiting.len(), 2, "{waiting:?}");
    assert_eq!(waiting[0], path, "this session's is the newest");
    let aside = &waiting[1];
    let name = aside.file_name().unwrap().to_string_lossy();
    assert!(
        name.starts_with("scene.autosave.2")
            && name.len() == "scene.autosave.YYYYMMDD-HHMMSS.json".len(),
        "{name}"
    );
    assert_eq!(std::fs::read_to_string(aside).unwrap(), SCENE);
    assert_eq!(prespline::formats::read_json(&path).unwrap(), v.scene());
    assert!(
        v.session.status().contains("kept the earlier autosave")
            && v.session.status().contains(&*name),
        "said on the status line: {}",
        v.session.status()
    );
    v.finish();
}

/// The scene's directory cannot take the autosave (its name is taken by a directory): the
/// state directory does, and the status line says so. Then neither can (the state directory
/// is made a regular file): the first failure is said once, and however often the event loop
/// asks, no write is tried before the backed-off retry; the way out reports the loss.
#[test]
fn an_unwritable_directory_falls_back_then_backs_off() {
    let scratch = common::Scratch::new("view-session");
    let scene = scratch.join("scene.json");
    std::fs::create_dir_all(scratch.join("scene.autosave.json/occupied")).unwrap();
    let state = scratch.join("state/prespline");
    let places = Places::new(Some(&scene), Some(&state));
    let fallback = places.in_state_dir().unwrap();
    let mut v = Viewer::new(scene.clone());
    v.session.set_autosave(Some(Autosave::new(places)));
    typed_move(&mut v, "0.5");
    v.session.apply_pending();
    let due = v.session.tick(Instant::now()).unwrap();
    assert_eq!(v.session.tick(due), None, "written");
    assert_eq!(prespline::formats::read_json(&fallback).unwrap(), v.scene());
    assert!(
        v.session
            .status()
            .contains("cannot autosave beside the scene")
            && v.session.status().contains(&fallback.display().to_string()),
        "{}",
        v.session.status()
    );

    // Now nothing takes it.
    std::fs::remove_dir_all(scratch.join("state")).unwrap();
    std::fs::write(scratch.join("state"), "").unwrap();
    typed_move(&mut v, "0.5");
    v.session.apply_pending();
    let due = v.session.tick(Instant::now()).unwrap();
    let retry = v.session.tick(due).expect("a retry is due");
    assert_eq!(retry, due + RETRY_FIRST, "the first retry a second later");
    assert!(
        v.session.status().starts_with("autosave failed ("),
        "{}",
        v.session.status()
    );
    v.session.set_status("");
    // An event loop that wakes up over and over before the retry (the busy loop of old).
    for _ in 0..10_000 {
        assert_eq!(v.session.tick(due), Some(retry));
    }
    let a = v.session.autosave().unwrap();
    assert_eq!(a.failures(), 1, "no write tried before the retry");
    assert_eq!(v.session.status(), "", "no further note");
    let lost = v.session.on_exit().unwrap_err();
    assert_eq!(lost.revisions, 1, "{lost}");
    assert_eq!(
        lost.older, None,
        "the earlier autosave went with the state directory"
    );
    let line = lost.to_string();
    assert!(
        line.contains(&scene.display().to_string())
            && line.contains("could not be autosaved")
            && line.contains(&state.display().to_string())
            && line.contains("Is a directory"),
        "{line}"
    );
    v.finish();
}

/// Saves and autosaves flush the temporary file to disk before renaming it over the scene,
/// and the directory after: traced with strace in a child process of this test binary.
#[test]
fn scene_writes_are_fsynced_before_the_rename() {
    const CHILD: &str = "PRESPLINE_FSYNC_CHILD";
    if let Some(target) = std::env::var_os(CHILD) {
        prespline::formats::save_json(&parse_scene(SCENE).unwrap(), &PathBuf::from(target))
            .unwrap();
        return;
    }
    let strace = std::process::Command::new("strace").arg("-V").output();
    if !common::precondition(
        strace.is_ok_and(|o| o.status.success()),
        "strace is not installed (scripts/install-deps.sh installs it)",
    ) {
        return;
    }
    let scratch = common::Scratch::new("view-session");
    let target = scratch.join("durable.json");
    let log = scratch.join("strace.log");
    let out = std::process::Command::new("strace")
        .args([
            "-f",
            "-qq",
            "-e",
            "trace=openat,fsync,fdatasync,rename,renameat,renameat2,close",
            "-o",
        ])
        .arg(&log)
        .arg(std::env::current_exe().unwrap())
        .args([
            "--exact",
            "scene_writes_are_fsynced_before_the_rename",
            "--test-threads",
            "1",
        ])
        .env(CHILD, &target)
        .output()
        .unwrap();
    let log = std::fs::read_to_string(&log).unwrap_or_default();
    assert!(
        out.status.success(),
        "strace or the child failed: {}\n{log}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        prespline::formats::read_json(&target).unwrap(),
        parse_scene(SCENE).unwrap()
    );
    let lines: Vec<&str> = log.lines().collect();
    let name = target.file_name().unwrap().to_string_lossy().into_owned();
    let dir = scratch.path().to_string_lossy().into_owned();
    // The temporary file: opened for writing (fd N), fsynced, then renamed over the target.
    let rename = lines
        .iter()
        .position(|l| l.contains("rename") && l.contains(&format!("/{name}\"")))
        .unwrap_or_else(|| panic!("no rename onto {name}:\n{log}"));
    let fd_of = |l: &str| {
        l.rsplit("= ")
            .next()
            .and_then(|n| n.trim().parse::<i64>().ok())
    };
    let tmp_open = lines[..rename]
        .iter()
        .rposition(|l| {
            l.contains("openat") && l.contains(&format!(".{name}.tmp")) && l.contains("O_CREAT")
        })
        .unwrap_or_else(|| panic!("no temporary file before the rename:\n{log}"));
    let fd = fd_of(lines[tmp_open]).expect("fd of the temporary file");
    assert!(
        lines[tmp_open..rename]
            .iter()
            .any(|l| l.contains(&format!("fsync({fd})")) || l.contains(&format!("fdatasync({fd})"))),
        "the temporary file is not fsynced before the rename:\n{log}"
    );
    let dir_open = lines[rename..]
        .iter()
        .position(|l| l.contains("openat") && l.contains(&format!("\"{dir}\"")))
        .map(|i| i + rename)
        .unwrap_or_else(|| panic!("the directory is not opened after the rename:\n{log}"));
    let dfd = fd_of(lines[dir_open]).expect("fd of the directory");
    assert!(
        lines[dir_open..]
            .iter()
            .any(|l| l.contains(&format!("fsync({dfd})"))),
        "the directory is not fsynced after the rename:\n{log}"
    );
}

/// Structural edits (degree elevation here; knot insertion, ERBS refinement, X and B take the
/// same check) grow nets and Hermite tables: one that would take the scene over the memory
/// budget is refused on the status line and changes nothing (no undo step); the same key under
/// a budget that has room applies it.
#[test]
fn structural_edits_over_the_memory_budget_are_refused() {
    use prespline::cli::render::DRAW_USES;
    use prespline::sampling::SampleMode;

    let scratch = common::Scratch::new("view-session");
    let mut v = Viewer::new(scratch.join("saved.json"));
    let before = v.scene();
    let now = before
        .check_budget(
            SampleMode::Render,
            DRAW_USES,
            &MemoryBudget::from_flag(Some(u64::MAX)),
        )
        .expect("an unlimited budget");
    // Exactly what the scene takes now: any growth is over it.
    v.session
        .set_memory_budget(MemoryBudget::from_flag(Some(now)));
    v.select(Handle::Point {
        object: 1,
        point: Index2::One(2),
    });
    v.key('e', false, false);
    let status = v.session.status().to_string();
    assert!(
        status.starts_with("no elevate degree: ") && status.contains("over the memory budget"),
        "status: {status}"
    );
    assert_eq!(v.scene(), before, "a refused elevation changes nothing");
    assert_eq!(v.session.undo_depth(), (0, 0), "and leaves no undo step");

    v.session
        .set_memory_budget(MemoryBudget::from_flag(Some(2 * now)));
    v.select(Handle::Point {
        object: 1,
        point: Index2::One(2),
    });
    v.key('e', false, false);
    match &v.scene().objects[1].model {
        Model::Curve(c) => assert_eq!(c.curve().degree(), 4, "{}", v.session.status()),
        other => panic!("not a B-spline curve: {other:?}"),
    }
    assert_eq!(v.session.undo_depth(), (1, 0));
    v.finish();
}

/// Issue 25's viewer path: a degree-10 B-spline curve with interior knots 0.5 and 0.5001.
const DEGREE_10: &str = r#"{"objects": [
  {"name": "c", "type": "bspline_curve", "degree": 10,
   "knots": [0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0.5, 0.5001, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1],
   "points": [[-2.0, 1.8, 0.6], [-1.6, 2.7, 1.0], [-1.2, -2.9, -0.2], [-0.8, -2.5, -0.4],
              [-0.4, -1.1, -3.0], [0.0, 0.1, -1.8], [0.4, -2.7, -1.7], [0.8, 1.2, 0.3],
              [1.2, 2.2, 0.9], [1.6, -0.6, 1.4], [2.0, 0.4, -0.9], [2.4, 1.9, 0.2],
              [2.8, -1.0, 0.5]], "samples": 200}
]}"#;

/// E on that curve used to send its net far away while the samples still showed the old curve,
/// and Ctrl+S wrote a curve 0.59 away from the one shown. Now the saved curve is the one shown
/// (to 1e-10 of its size), after one E and after two.
#[test]
fn elevating_beside_a_short_span_saves_the_curve_shown() {
    let scratch = common::Scratch::new("view-session");
    let path = scratch.join("saved.json");
    let mut v = Viewer::with_scene(DEGREE_10, path.clone());
    let curve = |scene: &Scene| match &scene.objects[0].model {
        Model::Curve(c) => c.curve().clone(),
        other => panic!("not a B-spline curve: {other:?}"),
    };
    let shown = curve(&v.scene());
    let size = {
        let p = shown.points();
        let lo = p.iter().fold(DVec3::INFINITY, |a, q| a.min(*q));
        let hi = p.iter().fold(DVec3::NEG_INFINITY, |a, q| a.max(*q));
        (hi - lo).length()
    };
    for presses in [1, 2] {
        v.select(Handle::Point {
            object: 0,
            point: Index2::One(3),
        });
        v.key('e', false, false);
        v.key('s', true, false);
        let saved = curve(&prespline::formats::read_json(&path).unwrap());
        let degree = if presses == 1 { 11 } else { 12 };
        assert_eq!(saved.degree(), degree, "status: {}", v.session.status());
        let moved = (0..=4000)
            .map(|i| {
                let t = i as f64 / 4000.0;
                shown.eval(t).distance(saved.eval(t))
            })
            .fold(
                0.0f64,
                |m, d| if d.is_nan() { f64::INFINITY } else { m.max(d) },
            );
        assert!(
            moved <= 1e-10 * size,
            "after {presses} E: the saved curve is {moved:e} from the one shown"
        );
    }
    v.finish();
}
