//! Imported OBJ models on lavapipe (validation layer required): a render golden of the
//! hand-written vase, the teapot as OBJ rendering and sampling identically to teapot.json, and
//! the viewer under Xvfb editing an OBJ model and saving it back as OBJ.

use crate::common;

use prespline::editor::Document;
use prespline::formats::obj::{load_obj, parse_obj};
use prespline::model::Model;
use prespline::render::offscreen::{Shot, render_document};
use prespline::render::{NetMode, ViewOptions};
use prespline::scene::Scene;
use std::path::{Path, PathBuf};
use std::process::Command;

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples")
        .join(name)
}

fn render(scene: &Scene, options: ViewOptions) -> prespline::gpu::Pixels {
    let (mut renderer, sink) = common::renderer();
    let shot = Shot {
        width: 640,
        height: 400,
        camera: None,
        options,
        msaa: 4,
    };
    let pixels = render_document(&mut renderer, &Document::new(scene), &shot).unwrap();
    common::teardown(renderer, sink);
    pixels
}

#[test]
fn imported_vase_matches_the_golden() {
    let import = load_obj(&example("vase.obj")).unwrap();
    assert!(import.warnings.is_empty(), "{:?}", import.warnings);
    let px = render(
        &import.scene,
        ViewOptions {
            control_nets: NetMode::All,
            ..ViewOptions::default()
        },
    );
    common::assert_golden("obj_vase", &px);
}

#[test]
fn teapot_obj_renders_exactly_like_teapot_json() {
    let json = prespline::formats::read_json(&example("teapot.json")).unwrap();
    let obj = load_obj(&example("teapot.obj")).unwrap().scene;
    assert_eq!(obj, json, "the converted teapot holds the same scene");
    let (a, b) = (
        render(&obj, ViewOptions::default()),
        render(&json, ViewOptions::default()),
    );
    assert_eq!((a.width, a.height), (b.width, b.height));
    assert!(
        a.rgba == b.rgba,
        "teapot.obj and teapot.json render differently"
    );
}

#[test]
fn prespline_sample_gives_the_same_output_for_teapot_obj_and_json() {
    let run = |file: &str| {
        let out = Command::new(env!("CARGO_BIN_EXE_prespline"))
            .arg("sample")
            .arg(example(file))
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        out.stdout
    };
    let (a, b) = (run("teapot.obj"), run("teapot.json"));
    assert!(!a.is_empty());
    assert!(
        a == b,
        "sample output differs between teapot.obj and teapot.json"
    );
}

fn prespline() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_prespline"));
    let icd = prespline::gpu::LAVAPIPE_ICD;
    c.env("VK_DRIVER_FILES", icd)
        .env("VK_ICD_FILENAMES", icd)
        .env("PRESPLINE_VALIDATION", "1");
    c
}

/// Windowed tests need X; only a run by hand without a display may skip them (with a note).
fn display() -> bool {
    if std::env::var_os("DISPLAY").is_some_and(|d| !d.is_empty()) {
        return true;
    }
    assert!(
        std::env::var_os("CI").is_none() && std::env::var_os("MAKELEVEL").is_none(),
        "DISPLAY is not set under make test or CI: run under Xvfb (make test does)"
    );
    eprintln!("skipped: DISPLAY is not set (make test runs this under Xvfb)");
    false
}

/// Drag one control point of the vase along z in the viewer, save with Ctrl+S to an .obj
/// path: the file is OBJ, that point moved along z only, everything else is bit-exact.
#[test]
fn viewer_edits_an_obj_model_and_saves_obj() {
    if !display() {
        return;
    }
    let dir = std::env::temp_dir().join(format!("prespline-obj-view-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let saved = dir.join("edited.obj");
    let shot = dir.join("shot.png");
    let script = dir.join("script.json");
    let text = r#"[
 {"frame": 3, "move_to": {"object": "vase", "point": [4, 3]}},
 {"frame": 4, "press": "left"},
 {"frame": 5, "key": "z"},
 {"frame": 6, "move_by": [0, -25]},
 {"frame": 7, "move_by": [0, -25]},
 {"frame": 8, "release": "left"},
 {"frame": 10, "screenshot": "SHOT"},
 {"frame": 11, "key": "s", "ctrl": true},
 {"frame": 13, "quit": true}
]"#;
    std::fs::write(&script, text.replace("SHOT", shot.to_str().unwrap())).unwrap();
    let out = prespline()
        .arg("view")
        .arg(example("vase.obj"))
        .args(["--size", "800x600", "--script"])
        .arg(&script)
        .arg("--save-as")
        .arg(&saved)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "viewer failed: {err}");

    let written = std::fs::read_to_string(&saved).unwrap();
    assert!(written.starts_with("# Wavefront OBJ"), "{written}");
    let before = load_obj(&example("vase.obj")).unwrap().scene;
    let after = parse_obj(&written).unwrap().scene;
    assert_eq!(before.objects.len(), after.objects.len());
    for (a, b) in before.objects.iter().zip(&after.objects) {
        assert_eq!(a.name, b.name);
        assert_eq!(a.model.sample_dims(), b.model.sample_dims());
        match (&a.model, &b.model) {
            (Model::Surface(s0), Model::Surface(s1)) if a.name == "vase" => {
                let (s0, s1) = (s0.surface(), s1.surface());
                assert_eq!(s0.knots(), s1.knots());
                assert_eq!(s0.weights(), s1.weights());
                let nv = s0.count()[1];
                for (k, (p, q)) in s0.points().iter().zip(s1.points()).enumerate() {
                    if k == 4 * nv + 3 {
                        assert_eq!((p.x, p.y), (q.x, q.y), "the drag was constrained to z");
                        assert!(q.z > p.z + 0.05, "the point was dragged up: {p:?} → {q:?}");
                    } else {
                        assert_eq!(p, q, "point {k} must not move");
                    }
                }
            }
            _ => assert_eq!(a.model, b.model, "{} must be unchanged", a.name),
        }
    }
    assert!(shot.is_file(), "{err}");
}
