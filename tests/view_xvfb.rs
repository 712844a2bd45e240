//! The viewer under X (Xvfb in `make test`) with lavapipe and the validation layer required: a
//! scripted session drags a control point along z, moves a circle point by a typed exact
//! amount, rotates an ERBS local patch, undoes once and saves. The saved scene must hold exactly
//! the expected control data, and a screenshot must match the golden image. Unsaved edits go to
//! the autosave within a second and on quit, and `--recover` brings them back. Every run has a
//! time limit and a scratch directory of its own (also its working directory, where the demo's
//! autosave goes). Skipped (with a note) when DISPLAY is not set, except under `make test` and
//! CI, where that fails.

mod common;

use common::Scratch;
use glam::DVec3;
use prespline::formats::demo::demo_scene;
use prespline::gpu::Pixels;
use prespline::model::Model;
use std::process::{Command, Output};
use std::time::{Duration, Instant};

/// Longest a scripted viewer run may take (a few seconds normally).
const LIMIT: Duration = Duration::from_secs(180);

const SCRIPT: &str = r#"[
 {"frame": 3, "move_to": {"object": "bspline_surface", "point": [3, 4]}},
 {"frame": 4, "press": "left"},
 {"frame": 5, "key": "z"},
 {"frame": 6, "move_by": [0, -30]},
 {"frame": 7, "move_by": [0, -30]},
 {"frame": 8, "release": "left"},
 {"frame": 9, "move_to": {"object": "nurbs_circle", "point": 2}},
 {"frame": 10, "press": "left"},
 {"frame": 11, "release": "left"},
 {"frame": 12, "key": "g"},
 {"frame": 13, "key": "z"},
 {"frame": 14, "type": "0.5"},
 {"frame": 15, "key": "enter"},
 {"frame": 16, "move_to": {"object": "erbs_surface", "local": [1, 2], "point": [1, 1]}},
 {"frame": 17, "press": "left"},
 {"frame": 18, "release": "left"},
 {"frame": 19, "key": "r"},
 {"frame": 20, "key": "z"},
 {"frame": 21, "type": "30"},
 {"frame": 22, "key": "enter"},
 {"frame": 24, "key": "z", "ctrl": true},
 {"frame": 26, "screenshot": "SHOT"},
 {"frame": 27, "key": "s", "ctrl": true},
 {"frame": 29, "quit": true}
]"#;

#[test]
fn scripted_session_saves_exact_edits_and_matches_the_golden() {
    if !common::display() {
        return;
    }
    let dir = Scratch::new("view-xvfb");
    let shot = dir.join("shot.png");
    let saved = dir.join("saved.json");
    let script = dir.file(
        "script.json",
        &SCRIPT.replace("SHOT", shot.to_str().unwrap()),
    );
    let out = run(prespline(&dir)
        .args(["view", "--size", "960x600", "--script"])
        .arg(&script)
        .arg("--save-as")
        .arg(&saved));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "viewer failed: {err}");
    // Saved before quitting: no autosave is left behind.
    assert!(!dir.join("demo.autosave.json").exists(), "{err}");
    assert!(!err.contains("unsaved edits"), "{err}");

    // Exact control data: only the two confirmed moves remain; the rotation was undone.
    let before = demo_scene();
    let after = prespline::formats::read_json(&saved).unwrap();
    assert_eq!(before.objects.len(), after.objects.len());
    for (a, b) in before.objects.iter().zip(&after.objects) {
        assert_eq!(a.name, b.name);
        match (a.name.as_str(), &a.model, &b.model) {
            ("bspline_surface", Model::Surface(s0), Model::Surface(s1)) => {
                let (s0, s1) = (s0.surface(), s1.surface());
                for (k, (p, q)) in s0.points().iter().zip(s1.points()).enumerate() {
                    if k == 3 * 8 + 4 {
                        assert_eq!((p.x, p.y), (q.x, q.y), "the drag was constrained to z");
                        assert!(q.z > p.z + 0.05, "the point was dragged up: {p:?} → {q:?}");
                    } else {
                        assert_eq!(p, q, "point {k} must not move");
                    }
                }
            }
            ("nurbs_circle", Model::Curve(c0), Model::Curve(c1)) => {
                let (c0, c1) = (c0.curve(), c1.curve());
                let mut expect = c0.points().to_vec();
                expect[2] += DVec3::new(0.0, 0.0, 0.5);
                assert_eq!(
                    c1.points(),
                    expect.as_slice(),
                    "G Z 0.5 moves exactly 0.5 along z"
                );
                assert_eq!(c0.weights(), c1.weights());
            }
            _ => assert_eq!(
                a.model, b.model,
                "object {} must be unchanged (the rotation was undone)",
                a.name
            ),
        }
    }

    let pixels = Pixels::read_png(&shot).unwrap();
    common::assert_golden("view_session", &pixels);
}

/// `prespline` on lavapipe with the validation layer required, in `dir`, with `dir/state` as
/// XDG_STATE_HOME (never the user's own).
fn prespline(dir: &Scratch) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_prespline"));
    let icd = prespline::gpu::LAVAPIPE_ICD;
    c.env("VK_DRIVER_FILES", icd)
        .env("VK_ICD_FILENAMES", icd)
        .env("PRESPLINE_VALIDATION", "required")
        .env("XDG_STATE_HOME", dir.join("state"))
        .current_dir(dir.path());
    c
}

fn run(command: &mut Command) -> Output {
    common::output_with_timeout(command, LIMIT)
}

#[test]
fn view_profile_writes_the_reports_when_the_window_closes() {
    if !common::display() {
        return;
    }
    let dir = Scratch::new("view-xvfb");
    let script = dir.file(
        "script.json",
        r#"[{"frame": 2, "move": [300, 200]}, {"frame": 3, "wheel": 1}, {"frame": 8, "quit": true}]"#,
    );
    let example =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/bspline_surface.json");
    let out = run(prespline(&dir)
        .arg("view")
        .arg(&example)
        .args(["--size", "320x240", "--script"])
        .arg(&script)
        .arg("--profile")
        .arg(dir.join("profile")));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("profile of"), "{err}");
    for f in [
        "frames.csv",
        "summary.json",
        "summary.txt",
        "trace.json",
        "frame_times.svg",
        "histogram.svg",
    ] {
        assert!(dir.join("profile").join(f).is_file(), "{f} missing: {err}");
    }
}

#[test]
fn bench_runs_in_a_window() {
    if !common::display() {
        return;
    }
    let scratch = Scratch::new("view-xvfb");
    let dir = scratch.join("bench");
    let out = run(prespline(&scratch)
        .args([
            "bench",
            "--window",
            "--scenario",
            "drag",
            "--frames",
            "5",
            "--warmup",
            "4",
            "--size",
            "320x200",
            "--out",
        ])
        .arg(&dir));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let csv = std::fs::read_to_string(dir.join("frames.csv")).unwrap();
    assert_eq!(
        csv.lines().count(),
        1 + 9,
        "header + warm-up + measured frames:\n{csv}"
    );
    assert!(dir.join("frame_times.svg").is_file());
}

/// Runs the viewer on `scene` with `script` (JSON text) in `dir`; returns the child to watch.
fn spawn_view(
    dir: &Scratch,
    scene: &std::path::Path,
    script: &str,
    extra: &[&str],
) -> std::process::Child {
    let script = dir.file("script.json", script);
    prespline(dir)
        .arg("view")
        .arg(scene)
        .args(["--size", "480x320", "--script"])
        .arg(&script)
        .args(extra)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap()
}

/// Unsaved edits reach NAME.autosave.json about a second after the edit, while the viewer is
/// still open (not only when it closes); its path is printed when the viewer closes; opening
/// the scene again prints a notice, and `--recover` opens the edits, which a clean save then
/// writes to the scene and removes from the autosave.
#[test]
fn unsaved_edits_survive_in_the_autosave_and_come_back_with_recover() {
    if !common::display() {
        return;
    }
    let dir = Scratch::new("view-xvfb");
    let example =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/bspline_surface.json");
    let scene = dir.join("surface.json");
    std::fs::copy(&example, &scene).unwrap();
    let autosave = dir.join("surface.autosave.json");
    let original = prespline::formats::read_json(&scene).unwrap();

    // A drag, then nothing for seconds before the script quits.
    let mut child = spawn_view(
        &dir,
        &scene,
        r#"[{"frame": 3, "move_to": {"object": "bumps", "point": [3, 3]}},
            {"frame": 4, "press": "left"}, {"frame": 5, "move_by": [0, -30]},
            {"frame": 6, "move_by": [0, -30]}, {"frame": 7, "release": "left"},
            {"t": 6.0, "quit": true}]"#,
        &[],
    );
    let start = Instant::now();
    let mut appeared = None;
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if appeared.is_none() && autosave.exists() {
            appeared = Some(Instant::now());
        }
        assert!(start.elapsed() < LIMIT, "the viewer did not quit");
        std::thread::sleep(Duration::from_millis(20));
    };
    // Written by the timer about a second after the drag, seconds before the script's quit
    // at t = 6 s writes it again on the way out.
    let before_exit = appeared.map(|t| t.elapsed());
    let seen_while_open = before_exit.is_some_and(|d| d > Duration::from_secs(2));
    let mut err = String::new();
    std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut err).unwrap();
    assert!(status.success(), "{err}");
    assert!(
        seen_while_open,
        "the autosave was not written while the viewer was open ({before_exit:?} before it closed): {err}"
    );
    assert!(
        err.contains(&format!(
            "unsaved edits kept in {} (`prespline view {} --recover` opens them)",
            autosave.display(),
            scene.display()
        )),
        "the autosave's path and the real command are not printed on close: {err}"
    );
    let kept = prespline::formats::read_json(&autosave).unwrap();
    assert_ne!(kept, original, "the drag is in the autosave");
    assert_eq!(
        prespline::formats::read_json(&scene).unwrap(),
        original,
        "the scene file is untouched"
    );

    // Opening the scene again: a one-line notice.
    let out = run(prespline(&dir)
        .arg("view")
        .arg(&scene)
        .args(["--size", "320x240", "--script"])
        .arg(dir.file("quit.json", r#"[{"frame": 2, "quit": true}]"#)));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let notice: Vec<&str> = err.lines().filter(|l| l.contains("--recover")).collect();
    assert_eq!(notice.len(), 1, "{err}");
    assert!(notice[0].contains(&autosave.display().to_string()), "{err}");
    assert_eq!(
        prespline::formats::read_json(&autosave).unwrap(),
        kept,
        "the notice alone changes nothing"
    );

    // --recover opens the edits; Ctrl+S writes them to the scene and removes the autosave.
    let out = run(prespline(&dir)
        .arg("view")
        .arg(&scene)
        .arg("--recover")
        .args(["--size", "320x240", "--script"])
        .arg(dir.file(
            "save.json",
            r#"[{"frame": 2, "key": "s", "ctrl": true}, {"frame": 4, "quit": true}]"#,
        )));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert_eq!(
        prespline::formats::read_json(&scene).unwrap(),
        kept,
        "the recovered edits were saved"
    );
    assert!(
        !autosave.exists(),
        "a clean save removes the autosave: {err}"
    );
    assert!(!err.contains("unsaved edits"), "{err}");

    // Nothing to recover now: one clear line.
    let out = run(prespline(&dir).arg("view").arg(&scene).arg("--recover"));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("--recover") && err.contains("no autosave"),
        "{err}"
    );
}

/// The demo's autosave is demo.autosave.json in the working directory.
#[test]
fn the_demo_autosaves_in_the_working_directory() {
    if !common::display() {
        return;
    }
    let dir = Scratch::new("view-xvfb");
    let out = run(prespline(&dir)
        .args(["view", "--size", "320x240", "--script"])
        .arg(dir.file(
            "script.json",
            r#"[{"frame": 3, "move_to": {"object": "nurbs_circle", "point": 2}},
                {"frame": 4, "press": "left"}, {"frame": 5, "release": "left"},
                {"frame": 6, "key": "g"}, {"frame": 7, "key": "z"}, {"frame": 8, "type": "1"},
                {"frame": 9, "key": "enter"}, {"frame": 11, "quit": true}]"#,
        )));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let autosave = dir.join("demo.autosave.json");
    assert!(
        err.contains(
            "unsaved edits kept in demo.autosave.json (`prespline view --recover` opens them)"
        ),
        "{err}"
    );
    let kept = prespline::formats::read_json(&autosave).unwrap();
    assert_ne!(kept, demo_scene());
}

/// With the validation layer missing, a run that requires it fails with one line instead of
/// running unvalidated.
#[test]
fn a_missing_validation_layer_fails_the_viewer() {
    if !common::display() {
        return;
    }
    let dir = Scratch::new("view-xvfb");
    let out = run(prespline(&dir)
        .env("VK_LAYER_PATH", dir.path())
        .env_remove("VK_ADD_LAYER_PATH")
        .args(["view", "--size", "320x240", "--script"])
        .arg(dir.file("quit.json", r#"[{"frame": 2, "quit": true}]"#)));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success(),
        "ran without the validation layer: {err}"
    );
    assert!(err.contains("validation layer"), "{err}");
}

/// Under `make test` (PRESPLINE_STRICT=1) or CI, a missing display fails these tests instead of
/// skipping them: each is run again without DISPLAY in a child process of this binary.
#[test]
fn without_a_display_strict_runs_fail() {
    for (var, value, fails) in [
        ("PRESPLINE_STRICT", "1", true),
        ("CI", "true", true),
        ("PRESPLINE_STRICT", "0", false),
    ] {
        let out = Command::new(std::env::current_exe().unwrap())
            .args([
                "--exact",
                "scripted_session_saves_exact_edits_and_matches_the_golden",
            ])
            .env_remove("DISPLAY")
            .env_remove("PRESPLINE_STRICT")
            .env_remove("CI")
            .env(var, value)
            .output()
            .unwrap();
        let text = format!(
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        assert_eq!(!out.status.success(), fails, "{var}={value}:\n{text}");
        if fails {
            assert!(text.contains("DISPLAY is not set"), "{text}");
        }
    }
}

/// An error that ends the viewer after an edit (a screenshot that cannot be written, a
/// scripted `move_to` a point that does not exist) still keeps the unsaved edits, and the one
/// error line says where.
#[test]
fn an_error_exit_keeps_the_unsaved_edits() {
    if !common::display() {
        return;
    }
    for (failing, names) in [
        (
            r#"{"frame": 11, "screenshot": "/nonexistent/directory/shot.png"}"#,
            "/nonexistent/directory/shot.png",
        ),
        (
            r#"{"frame": 11, "move_to": {"object": "nurbs_circle", "point": 99}}"#,
            "error: script: move_to: there is no ",
        ),
    ] {
        let dir = Scratch::new("view-xvfb");
        let script = format!(
            r#"[{{"frame": 3, "move_to": {{"object": "nurbs_circle", "point": 2}}}},
                {{"frame": 4, "press": "left"}}, {{"frame": 5, "release": "left"}},
                {{"frame": 6, "key": "g"}}, {{"frame": 7, "key": "x"}}, {{"frame": 8, "type": "2"}},
                {{"frame": 9, "key": "enter"}}, {failing}, {{"frame": 30, "quit": true}}]"#
        );
        let out = run(prespline(&dir)
            .args(["view", "--size", "320x240", "--script"])
            .arg(dir.file("script.json", &script)));
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "the script cannot succeed: {err}");
        let lines: Vec<&str> = err
            .lines()
            .filter(|l| l.contains(names) || l.contains("unsaved edits"))
            .collect();
        assert_eq!(lines.len(), 1, "one line: {err}");
        assert!(
            lines[0].starts_with("error: ")
                && lines[0].contains(names)
                && lines[0].ends_with(
                    "; unsaved edits kept in demo.autosave.json (`prespline view --recover` opens them)"
                ),
            "{err}"
        );
        assert_ne!(
            prespline::formats::read_json(&dir.join("demo.autosave.json")).unwrap(),
            demo_scene()
        );
    }
}

/// Insert a knot at the cursor (aimed at u = 0.45 on the surface), drag one of the new control
/// points, save: the net is refined and
/// the point moved. The same session with two undos before saving gives back the original
/// scene bit for bit (the file text is the exact, shortest round-trip serialisation).
#[test]
fn knot_insertion_drag_and_two_undos_restore_the_scene_exactly() {
    if !common::display() {
        return;
    }
    let dir = Scratch::new("view-xvfb");
    let steps = r#"
 {"frame": 3, "move_to": {"object": "bspline_surface", "point": [3, 4]}},
 {"frame": 4, "press": "left"},
 {"frame": 5, "release": "left"},
 {"frame": 6, "key": "i"},
 {"frame": 7, "move_to": {"object": "bspline_surface", "at": [0.45, 0.55]}},
 {"frame": 8, "press": "left"},
 {"frame": 9, "release": "left"},
 {"frame": 10, "move_to": {"object": "bspline_surface", "point": [4, 4]}},
 {"frame": 11, "press": "left"},
 {"frame": 12, "move_by": [0, -30]},
 {"frame": 13, "move_by": [0, -30]},
 {"frame": 14, "release": "left"},"#;
    let session = |name: &str, undo: &str| {
        let saved = dir.join(format!("{name}.json"));
        let script = dir.join(format!("{name}-script.json"));
        let text = format!(
            r#"[{steps}{undo}
 {{"frame": 20, "key": "s", "ctrl": true}},
 {{"frame": 22, "quit": true}}]"#
        );
        std::fs::write(&script, text).unwrap();
        let out = run(prespline(&dir)
            .args(["view", "--size", "960x600", "--script"])
            .arg(&script)
            .arg("--save-as")
            .arg(&saved));
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "viewer failed: {err}");
        std::fs::read_to_string(&saved).unwrap()
    };
    let original = prespline::formats::json::scene_to_json(&demo_scene());

    let refined = session("refined", "");
    let after = prespline::formats::parse_scene(&refined).unwrap();
    let (Model::Surface(s0), Model::Surface(s1)) =
        (&demo_scene().objects[0].model, &after.objects[0].model)
    else {
        panic!("the demo's first object is the B-spline surface");
    };
    let (s0, s1) = (s0.surface(), s1.surface());
    assert_eq!(
        s1.count(),
        [s0.count()[0] + 1, s0.count()[1]],
        "one u knot inserted"
    );
    assert_eq!(s1.knots()[0].len(), s0.knots()[0].len() + 1);
    // The refined net is the old net's refinement except for the dragged point: compare with a
    // fresh insertion of the same knot.
    let t = s1.knots()[0]
        .iter()
        .copied()
        .find(|&t| s0.knots()[0].multiplicity(t) < s1.knots()[0].multiplicity(t))
        .unwrap();
    // Where the script aimed: the drawn sample nearest u = 0.45 (96 samples on [0, 1]).
    assert!((t - 0.45).abs() <= 0.5 / 95.0, "inserted u = {t}");
    let fresh = s0.insert_knot(0, t, 1).unwrap();
    let moved: Vec<(usize, usize)> = (0..s1.count()[0])
        .flat_map(|i| (0..s1.count()[1]).map(move |j| (i, j)))
        .filter(|&(i, j)| fresh.point(i, j) != s1.point(i, j))
        .collect();
    assert_eq!(moved, vec![(4, 4)], "exactly the dragged new point moved");
    assert_ne!(refined, original);

    let undone = session(
        "undone",
        r#"
 {"frame": 16, "key": "z", "ctrl": true},
 {"frame": 18, "key": "z", "ctrl": true},"#,
    );
    assert_eq!(undone, original, "two undos restore the scene bit for bit");
}

/// Script times and frames past what a replay can reach are refused up front in one line
/// (they used to panic converting to a `Duration`, or draw until killed).
#[test]
fn script_times_out_of_reach_are_one_line_errors() {
    if !common::display() {
        return;
    }
    let dir = Scratch::new("view-xvfb");
    for script in [
        r#"[{"t": 1e300, "key": "a"}]"#,
        r#"[{"t": 1e19, "key": "a"}]"#,
        r#"[{"frame": 18446744073709551615, "key": "a"}]"#,
    ] {
        let out = run(prespline(&dir)
            .args(["view", "--size", "320x240", "--script"])
            .arg(dir.file("times.json", script)));
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{script}: {err}");
        assert_eq!(err.lines().count(), 1, "{script}: one line, got {err}");
        assert!(
            err.starts_with("error: ") && err.contains("event 0"),
            "{err}"
        );
    }
}

/// Screenshots with the HUD: the frame after a drag step (its slot still lacks that step's
/// rows, while the screenshot's slot has them), and once idle.
const DRAG_SCRIPT: &str = r#"[
 {"frame": 3, "move_to": {"object": "bspline_surface", "point": [3, 4]}},
 {"frame": 4, "press": "left"},
 {"frame": 5, "move_by": [0, -20]},
 {"frame": 6, "move_by": [0, -20]},
 {"frame": 7, "screenshot": "SHOT7", "hud": true},
 {"frame": 8, "release": "left"},
 {"frame": 12, "screenshot": "SHOT12", "hud": true},
 {"frame": 13, "quit": true}
]"#;

/// The "KB to GPU" figure of the HUD's second line, read back from a screenshot.
fn kb_to_gpu(shot: &std::path::Path) -> (String, String) {
    use prespline::gpu::font::{Font, TextSize};
    use prespline::render::analysis::PANEL;
    use prespline::view::hud::TEXT;
    let px = Pixels::read_png(shot).unwrap();
    let font = Font::new(1.0);
    let line = font.metrics(TextSize::Normal).line_height + 2;
    let read = |row: u32| {
        let at = [16, 14 + row * line];
        common::read_text(&px, &font, TextSize::Normal, at, 48, PANEL, TEXT)
    };
    // The reader reads what is there: the first line is the frame time.
    assert!(read(0).starts_with("frame "), "{:?}", read(0));
    let edit = read(1);
    let kb = edit
        .split(" KB to GPU")
        .next()
        .and_then(|s| s.rsplit(' ').next())
        .filter(|n| n.parse::<f64>().is_ok())
        .unwrap_or_else(|| panic!("no KB figure in {edit:?}"))
        .to_string();
    (edit, kb)
}

/// A viewer screenshot shows the HUD's figures as the window showed them: the edit line's
/// "KB to GPU" is what its edit's frame copied, as the profile recorded it, also on later frames
/// that copy nothing (the screenshot's own upload of its frame slot used to replace it, and a
/// frame without an edit used to show 0.0 KB beside the last edit's time and samples).
#[test]
fn screenshots_show_the_bytes_of_the_last_edit() {
    if !common::display() {
        return;
    }
    let dir = Scratch::new("view-kb");
    let frames = [7, 12];
    let mut script = DRAG_SCRIPT.to_string();
    for f in frames {
        let shot = dir.join(format!("shot{f}.png"));
        script = script.replace(
            &format!("\"SHOT{f}\""),
            &format!("{:?}", shot.to_str().unwrap()),
        );
    }
    let script = dir.file("script.json", &script);
    let profile = dir.join("profile");
    let out = run(prespline(&dir)
        .args(["view", "--size", "800x600", "--script"])
        .arg(&script)
        .arg("--profile")
        .arg(&profile));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "viewer failed: {err}");
    let csv = std::fs::read_to_string(profile.join("frames.csv")).unwrap();
    let column = |name: &str| {
        let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
        let k = header.iter().position(|c| *c == name).unwrap();
        csv.lines()
            .skip(1)
            .map(|l| l.split(',').nth(k).unwrap().parse::<u64>().unwrap())
            .collect::<Vec<u64>>()
    };
    let (bytes, samples) = (column("bytes_uploaded"), column("samples_touched"));
    for f in frames {
        let (line, kb) = kb_to_gpu(&dir.join(format!("shot{f}.png")));
        // The last frame up to f that applied an edit.
        let edit = (0..=f).rev().find(|&k| samples[k] > 0).unwrap();
        let recorded = format!("{:.1}", bytes[edit] as f64 / 1024.0);
        assert_eq!(
            kb, recorded,
            "frame {f} (edit at {edit}): {line:?}, profile {bytes:?}"
        );
        assert!(bytes[edit] > 0, "the drag's frames copied rows: {bytes:?}");
    }
    // Negative control: frame 12 copied nothing itself, yet its screenshot shows the edit's.
    assert_eq!(bytes[12], 0, "{bytes:?}");
    eprintln!("frame 12: {:?}", kb_to_gpu(&dir.join("shot12.png")).0);
}

/// A status message the window can only show with its middle elided (a save into a folder
/// that does not exist, with the reason at the end) goes to stderr whole, once; a short one
/// does not.
#[test]
fn an_elided_status_goes_to_stderr_whole() {
    if !common::display() {
        return;
    }
    let dir = Scratch::new("view-xvfb");
    let example =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/erbs_surface.json");
    let out = run(prespline(&dir)
        .arg("view")
        .arg(&example)
        .args(["--size", "320x240", "--save-as"])
        .arg(dir.join("no such folder, so the save fails and says why/x.json"))
        .arg("--script")
        .arg(dir.file(
            "save.json",
            r#"[{"frame": 2, "key": "s", "ctrl": true}, {"frame": 4, "key": "j"}, {"frame": 6, "quit": true}]"#,
        )));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let echoed: Vec<&str> = err
        .lines()
        .filter(|l| l.starts_with("prespline: "))
        .collect();
    assert_eq!(
        echoed.len(),
        1,
        "the long message once, the short one never: {err}"
    );
    assert!(
        echoed[0].starts_with("prespline: save failed: ") && echoed[0].ends_with(')'),
        "the whole message, advice included: {err}"
    );
    assert!(
        !dir.path()
            .join("no such folder, so the save fails and says why")
            .exists()
    );
}

/// A drag in the window, screenshots in the middle of it and after it: `--redraw retained`
/// (the default) gives exactly the pixels of `--redraw full`. The window's own frames run
/// through the swapchain's static layer under the validation layer.
#[test]
fn a_retained_drag_looks_exactly_like_a_full_redraw() {
    if !common::display() {
        return;
    }
    const DRAG: &str = r#"[
 {"frame": 3, "move_to": {"object": "bspline_surface", "point": [3, 4]}},
 {"frame": 4, "press": "left"},
 {"frame": 5, "move_by": [10, -25]},
 {"frame": 6, "move_by": [-4, -20]},
 {"frame": 7, "move_by": [15, 8]},
 {"frame": 8, "screenshot": "MID"},
 {"frame": 9, "move_by": [-12, 6]},
 {"frame": 10, "release": "left"},
 {"frame": 12, "screenshot": "LAST"},
 {"frame": 13, "quit": true}
]"#;
    let dir = Scratch::new("view-retained");
    let mut shots = Vec::new();
    for redraw in ["retained", "full"] {
        let (mid, last) = (
            dir.join(format!("{redraw}-mid.png")),
            dir.join(format!("{redraw}-last.png")),
        );
        let script = dir.file(
            &format!("{redraw}.json"),
            &DRAG
                .replace("MID", mid.to_str().unwrap())
                .replace("LAST", last.to_str().unwrap()),
        );
        let out = run(prespline(&dir)
            .args(["view", "--size", "480x320", "--redraw", redraw, "--script"])
            .arg(&script)
            .arg("--save-as")
            .arg(dir.join(format!("{redraw}.json"))));
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "viewer ({redraw}) failed: {err}");
        shots.push([mid, last].map(|p| Pixels::read_png(&p).unwrap()));
    }
    for (k, name) in ["mid-drag", "last"].iter().enumerate() {
        let (a, b) = (&shots[0][k], &shots[1][k]);
        let diff = common::compare_images(b, a, 0).unwrap();
        assert_eq!(
            diff.differing, 0,
            "{name} screenshot: retained differs from full in {} pixels",
            diff.differing
        );
    }
    // The negative control of the comparison: the mid-drag and last images differ.
    let moved = common::compare_images(&shots[0][0], &shots[0][1], 0).unwrap();
    assert!(moved.differing > 0, "the drag moved nothing");
}

/// A flat 6 × 4 Bézier patch in z = 0 (the viewer looks at flat scenes from above, tilted).
const FLAT: &str = r#"{"objects": [{"name": "plate", "type": "bezier_surface", "samples": [24, 24],
  "points": [[[-3, -2, 0], [-3, -0.7, 0], [-3, 0.7, 0], [-3, 2, 0]],
             [[-1, -2, 0], [-1, -0.7, 0], [-1, 0.7, 0], [-1, 2, 0]],
             [[1, -2, 0], [1, -0.7, 0], [1, 0.7, 0], [1, 2, 0]],
             [[3, -2, 0], [3, -0.7, 0], [3, 0.7, 0], [3, 2, 0]]]}]}"#;

/// Empty rows above and below what is drawn: a row is empty when every pixel is within 24
/// levels of the row's first pixel (the background, whatever its gradient).
fn vertical_margins(px: &Pixels) -> (u32, u32) {
    let at = |x: u32, y: u32| {
        let i = 4 * (y * px.width + x) as usize;
        &px.rgba[i..i + 3]
    };
    let drawn = |y: u32| {
        let bg = at(0, y);
        (1..px.width).any(|x| at(x, y).iter().zip(bg).any(|(a, b)| a.abs_diff(*b) > 24))
    };
    let rows: Vec<u32> = (0..px.height).filter(|&y| drawn(y)).collect();
    let (Some(first), Some(last)) = (rows.first(), rows.last()) else {
        panic!("nothing drawn in the {}×{} screenshot", px.width, px.height)
    };
    (*first, px.height - 1 - last)
}

/// Whether the empty bands above and below differ by at most `px` pixels.
fn balanced(margins: (u32, u32), px: u32) -> bool {
    margins.0.abs_diff(margins.1) <= px
}

/// Issue 24 (8): a flat object opened in the viewer is framed by what is drawn, with equal
/// empty bands above and below within the part the overlays leave free (issue 34: below the
/// performance panel, above the status line); the bounding-box framing left about 340 px above
/// and 35 below.
/// The same measure on the view panned down by 20 px finds them about 40 px apart.
#[test]
fn a_flat_object_opens_with_balanced_margins() {
    if !common::display() {
        return;
    }
    let dir = Scratch::new("view-margins");
    let scene = dir.file("flat.json", FLAT);
    let script = dir.file(
        "script.json",
        r#"[{"frame": 2, "screenshot": "opened.png"},
            {"frame": 3, "move": [4, 4]}, {"frame": 4, "press": "right"},
            {"frame": 5, "move_by": [0, 20]}, {"frame": 6, "release": "right"},
            {"frame": 8, "screenshot": "panned.png"}, {"frame": 9, "quit": true}]"#,
    );
    let out = run(prespline(&dir)
        .args(["view", "--size", "960x600", "--script"])
        .arg(&script)
        .arg(&scene));
    assert!(
        out.status.success(),
        "viewer failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    // Margins within the band the overlays leave free (performance panel above, status
    // line below), which framing fills.
    let font = prespline::gpu::font::Font::new(1.0);
    let panel = prespline::view::hud::Hud::new().panel_rect(&font);
    let status = prespline::view::hud::status_band(&font);
    let [_, _, top, bottom] = prespline::view::hud::free_rect([960.0, 600.0], panel, status);
    let within = |(t, b): (u32, u32)| {
        (
            t.saturating_sub(top.round() as u32),
            b.saturating_sub((600.0 - bottom).round() as u32),
        )
    };
    let opened = within(vertical_margins(
        &Pixels::read_png(&dir.join("opened.png")).unwrap(),
    ));
    let panned = within(vertical_margins(
        &Pixels::read_png(&dir.join("panned.png")).unwrap(),
    ));
    eprintln!("margins (top, bottom): opened {opened:?}, panned {panned:?}");
    assert!(balanced(opened, 3), "opened with margins {opened:?}");
    // Framing fills 90 % of the band: 5 % each side, less the edges' anti-aliasing.
    assert!(
        f64::from(opened.0) >= 0.03 * (bottom - top),
        "a margin is kept: {opened:?}"
    );
    // Negative control: the measure sees a real imbalance in a viewer screenshot.
    assert!(!balanced(panned, 3), "panned by 20 px: {panned:?}");
    assert!(panned.0 > panned.1 + 30, "panned down by 20 px: {panned:?}");
}
