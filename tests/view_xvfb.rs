//! The viewer under X (Xvfb in `make test`) with lavapipe: a scripted session drags a control
//! point along z, moves a circle point by a typed exact amount, rotates an ERBS local patch,
//! undoes once and saves. The saved scene must hold exactly the expected control data, and a
//! screenshot must match the golden image. Skipped (with a note) when DISPLAY is not set.

mod common;

use glam::DVec3;
use prespline::gpu::Pixels;
use prespline::scene::demo::demo_scene;
use prespline::scene::{Scene, Shape};
use std::process::Command;

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
    if !display() {
        return;
    }
    let dir = std::env::temp_dir().join(format!("prespline-view-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let shot = dir.join("shot.png");
    let saved = dir.join("saved.json");
    let script = dir.join("script.json");
    std::fs::write(&script, SCRIPT.replace("SHOT", shot.to_str().unwrap())).unwrap();
    let out = prespline()
        .args(["view", "--size", "960x600", "--script"])
        .arg(&script)
        .arg("--save-as")
        .arg(&saved)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "viewer failed: {err}");

    // Exact control data: only the two confirmed moves remain; the rotation was undone.
    let before = demo_scene();
    let after = Scene::load(&saved).unwrap();
    assert_eq!(before.objects.len(), after.objects.len());
    for (a, b) in before.objects.iter().zip(&after.objects) {
        assert_eq!(a.name, b.name);
        match (a.name.as_str(), &a.shape, &b.shape) {
            ("bspline_surface", Shape::BSplineSurface(s0), Shape::BSplineSurface(s1)) => {
                for (k, (p, q)) in s0.points().iter().zip(s1.points()).enumerate() {
                    if k == 3 * 8 + 4 {
                        assert_eq!((p.x, p.y), (q.x, q.y), "the drag was constrained to z");
                        assert!(q.z > p.z + 0.05, "the point was dragged up: {p:?} → {q:?}");
                    } else {
                        assert_eq!(p, q, "point {k} must not move");
                    }
                }
            }
            ("nurbs_circle", Shape::BSplineCurve(c0), Shape::BSplineCurve(c1)) => {
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
                a.shape, b.shape,
                "object {} must be unchanged (the rotation was undone)",
                a.name
            ),
        }
    }

    let pixels = Pixels::read_png(&shot).unwrap();
    common::assert_golden("view_session", &pixels);
}

fn display() -> bool {
    let ok = std::env::var_os("DISPLAY").is_some_and(|d| !d.is_empty());
    if !ok {
        eprintln!("skipped: DISPLAY is not set (make test runs this under Xvfb)");
    }
    ok
}

fn prespline() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_prespline"));
    let icd = prespline::gpu::LAVAPIPE_ICD;
    c.env("VK_DRIVER_FILES", icd)
        .env("VK_ICD_FILENAMES", icd)
        .env("PRESPLINE_VALIDATION", "required");
    c
}

#[test]
fn view_profile_writes_the_reports_when_the_window_closes() {
    if !display() {
        return;
    }
    let dir = std::env::temp_dir().join(format!("prespline-view-profile-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let script = dir.join("script.json");
    std::fs::write(&script, r#"[{"frame": 2, "move": [300, 200]}, {"frame": 3, "wheel": 1}, {"frame": 8, "quit": true}]"#).unwrap();
    let example =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/bspline_surface.json");
    let out = prespline()
        .arg("view")
        .arg(&example)
        .args(["--size", "320x240", "--script"])
        .arg(&script)
        .arg("--profile")
        .arg(dir.join("profile"))
        .output()
        .unwrap();
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
    if !display() {
        return;
    }
    let dir = std::env::temp_dir().join(format!("prespline-bench-window-{}", std::process::id()));
    let out = prespline()
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
        .arg(&dir)
        .output()
        .unwrap();
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
