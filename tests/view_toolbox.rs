//! The lecture's toolbox in the viewer (Xvfb in `make test`, lavapipe): dragging handles of a
//! C1 Bézier spline and a Catmull–Rom spline keeps their construction, Alt+drag and Shift+W set
//! weights (a polynomial curve and surface become rational), B converts a spline to a
//! bspline_curve, and undoing everything saves the original scene bit for bit.

mod common;

use prespline::geom::JoinContinuity;
use prespline::model::{Model, ModelRef};
use prespline::render::analysis::curve_joins;
use prespline::scene::Scene;
use std::path::Path;
use std::process::Command;

const SCENE: &str = r#"{"objects": [
 {"name": "spline", "type": "bezier_spline", "degree": 3, "knots": [0, 1, 3], "points": [[0,0,0],[1,1.5,0],[2,1.5,0],[3,0,0],[5,-3,0],[6,0,0],[7,1,0]], "continuity": "C1", "samples": 300},
 {"name": "cr", "type": "catmull_rom", "points": [[0,-3,0],[1,-2,0],[2,-3.5,0],[3,-2,0],[4,-3,0]], "parametrization": "centripetal", "samples": 300},
 {"name": "curve", "type": "bspline_curve", "degree": 3, "knots": [0,0,0,0,1,2,2,2,2], "points": [[0,-6,0],[1,-5,0],[2,-7,0],[3,-5,0],[4,-6,0]], "samples": 200},
 {"name": "surface", "type": "bezier_surface", "points": [[[8,-6,0],[8,-4,1],[8,-2,0]],[[10,-6,1],[10,-4,2],[10,-2,1]],[[12,-6,0],[12,-4,1],[12,-2,0]]], "samples": [24, 24]}
]}"#;

/// Drags a spline handle and a Catmull–Rom point, Alt+drags a curve weight up, types a surface
/// weight, converts the Catmull–Rom spline; `UNDO` becomes undos and `SAVE` the save.
const SCRIPT: &str = r#"[
 {"frame": 3, "move_to": {"object": "spline", "point": 4}},
 {"frame": 4, "press": "left"},
 {"frame": 5, "move_by": [25, -20]},
 {"frame": 6, "move_by": [15, -10]},
 {"frame": 7, "release": "left"},
 {"frame": 8, "move_to": {"object": "cr", "point": 2}},
 {"frame": 9, "press": "left"},
 {"frame": 10, "move_by": [0, 30]},
 {"frame": 11, "release": "left"},
 {"frame": 12, "move_to": {"object": "curve", "point": 2}},
 {"frame": 13, "hold": ["alt"]},
 {"frame": 14, "press": "left"},
 {"frame": 15, "move_by": [0, -40]},
 {"frame": 16, "move_by": [0, -40]},
 {"frame": 17, "release": "left"},
 {"frame": 18, "hold": []},
 {"frame": 19, "move_to": {"object": "surface", "point": [1, 1]}},
 {"frame": 20, "press": "left"},
 {"frame": 21, "release": "left"},
 {"frame": 22, "key": "w", "shift": true},
 {"frame": 23, "type": "2.5"},
 {"frame": 24, "key": "enter"},
 {"frame": 25, "move_to": {"object": "cr", "point": 1}},
 {"frame": 26, "press": "left"},
 {"frame": 27, "release": "left"},
 {"frame": 28, "key": "b"},
 {"frame": 29, "key": "j"},
 {"frame": 30, "screenshot": "SHOT"}
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
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_prespline"));
    let icd = prespline::gpu::LAVAPIPE_ICD;
    cmd.env("VK_DRIVER_FILES", icd)
        .env("VK_ICD_FILENAMES", icd)
        .env("PRESPLINE_VALIDATION", "1")
        .args(["view", "--size", "960x600", "--script"])
        .arg(&script)
        .arg("--save-as")
        .arg(&saved)
        .arg(&scene);
    let out = common::output_with_timeout(&mut cmd, std::time::Duration::from_secs(300));
    assert!(
        out.status.success(),
        "viewer failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    prespline::formats::read_json(&saved).unwrap()
}

#[test]
fn toolbox_edits_keep_their_constructions_and_undo_exactly() {
    if !common::display() {
        return;
    }
    let scratch = common::Scratch::new("view-toolbox");
    let dir = scratch.path();
    let original = prespline::formats::parse_scene(SCENE).unwrap();

    let edited = run(dir, 0);
    let by = |s: &Scene, n: &str| s.objects[s.find(n).unwrap()].model.clone();
    // The spline: handle 4 moved, its mirror 2 followed, the junction stayed; still C1.
    let (Model::BezierSpline(a), Model::BezierSpline(b)) =
        (by(&original, "spline"), by(&edited, "spline"))
    else {
        panic!("the spline stays a bezier_spline")
    };
    let (pa, pb) = (a.spline().points(), b.spline().points());
    assert_ne!(pa[4], pb[4], "handle 4 was dragged");
    assert_ne!(pa[2], pb[2], "its mirror followed");
    assert_eq!(pa[3], pb[3], "the junction stays");
    assert_eq!(b.spline().continuity(), JoinContinuity::C1);
    assert_eq!(b.spline().junction_error(1), None);
    let joins = curve_joins(ModelRef::BezierSpline(&b));
    assert_eq!(joins[0].class.label(), "C1");
    // The Catmull–Rom spline was moved, then converted to the same curve as a B-spline.
    let converted = by(&edited, "cr");
    assert_eq!(converted.type_name(), "bspline_curve");
    // The curve's weight 2 went up by Alt+drag (80 px: a factor of 2).
    let Model::Curve(c) = by(&edited, "curve") else {
        panic!()
    };
    let w = c.curve().weights().expect("the curve became rational");
    assert!((w[2] - 2.0).abs() < 1e-9, "weight {}", w[2]);
    assert!(w.iter().enumerate().all(|(i, &x)| i == 2 || x == 1.0));
    // The surface's middle weight is exactly the typed 2.5.
    let Model::Surface(s) = by(&edited, "surface") else {
        panic!()
    };
    let w = s.surface().weights().expect("the surface became rational");
    assert_eq!(w[4], 2.5);

    // Six steps (drag, drag, weight drag, typed weight, conversion, …) undone: bit for bit.
    let undone = run(dir, 5);
    assert!(undone == original, "undo must restore the scene exactly");
    let text = prespline::formats::json::scene_to_json(&undone);
    assert_eq!(text, prespline::formats::json::scene_to_json(&original));
    let shot = prespline::gpu::Pixels::read_png(&dir.join("shot-0.png")).unwrap();
    assert!(shot.width == 960 && shot.height == 600);
}

/// Pixels whose colour leans clearly to red (`red`) or to blue (`!red`).
fn leaning(p: &prespline::gpu::Pixels, red: bool) -> usize {
    p.rgba
        .chunks_exact(4)
        .filter(|c| {
            let (r, b) = (i32::from(c[0]), i32::from(c[2]));
            if red { r > b + 60 } else { b > r + 60 }
        })
        .count()
}

/// `view --analysis gaussian` opens with the map on (the exact sphere: K = 1 > 0, red), M moves
/// on to the mean curvature (H = −1 with outward normals, blue), and a bad map name is refused
/// before any window opens.
#[test]
fn view_opens_with_an_analysis_map_and_m_cycles_it() {
    if !common::display() {
        return;
    }
    let dir = common::Scratch::new("view-map");
    let (k, h) = (dir.join("k.png"), dir.join("h.png"));
    let script = dir.join("script.json");
    std::fs::write(
        &script,
        format!(
            r#"[{{"frame": 4, "screenshot": {k:?}}}, {{"frame": 5, "key": "m"}},
               {{"frame": 8, "screenshot": {h:?}}}, {{"frame": 9, "quit": true}}]"#
        ),
    )
    .unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/sphere.json");
    let icd = prespline::gpu::LAVAPIPE_ICD;
    let view = |extra: &[&str]| {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_prespline"));
        cmd.env("VK_DRIVER_FILES", icd)
            .env("VK_ICD_FILENAMES", icd)
            .env("PRESPLINE_VALIDATION", "1")
            .args(["view", "--size", "640x480"])
            .args(extra)
            .arg(&scene);
        common::output_with_timeout(&mut cmd, std::time::Duration::from_secs(300))
    };
    let out = view(&[
        "--analysis",
        "gaussian",
        "--script",
        script.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "viewer failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let k = prespline::gpu::Pixels::read_png(&k).unwrap();
    let h = prespline::gpu::Pixels::read_png(&h).unwrap();
    let area = (k.width * k.height) as usize;
    assert!(leaning(&k, true) > area / 20, "K = 1 is not shown red");
    assert!(leaning(&k, false) < area / 200, "K = 1 shows blue");
    assert!(leaning(&h, false) > area / 20, "H = −1 is not shown blue");
    assert!(leaning(&h, true) < area / 200, "H = −1 shows red");
    let bad = view(&["--analysis", "curly"]);
    assert!(!bad.status.success());
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(err.contains("--analysis") && err.contains("curly"), "{err}");
}
