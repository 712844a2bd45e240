//! Hierarchical ERBS editing in the viewer (Xvfb in `make test`, lavapipe): I refines an ERBS
//! surface at the cursor, X turns a local patch into an ERBS of its own, G moves one of its
//! local patches (a level-2 detail), I refines inside that detail, and undoing everything saves
//! the original scene bit for bit.

mod common;

use prespline::geom::erbs::{ErbsSurface, LocalPatch};
use prespline::model::Model;
use prespline::scene::Scene;
use std::path::Path;
use std::process::Command;
use std::time::Duration;

/// The example's 3 × 3 biquadratic domes (knots 0, 1, 2 in u and v).
const SCENE: &str = include_str!("../examples/erbs_surface.json");

/// `UNDO` becomes the undos, `SHOT` the screenshot's path.
const SCRIPT: &str = r#"[
 {"frame": 3, "move_to": {"object": "domes", "local": [1, 1], "point": [1, 1]}},
 {"frame": 4, "press": "left"},
 {"frame": 5, "release": "left"},
 {"frame": 6, "move_by": [14, 9]},
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
 {"frame": 23, "move_to": {"object": "domes", "local": [[1, 1], [1, 1]], "point": [1, 1]}},
 {"frame": 24, "move_by": [4, 90]},
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
    Scene::load(&saved).unwrap()
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
    let original = prespline::scene::parse_scene(SCENE).unwrap();
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
    assert_eq!(edited.depth(), 3, "the object, the detail, its patches");

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
        prespline::scene::scene_to_json(&undone),
        prespline::scene::scene_to_json(&original)
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
