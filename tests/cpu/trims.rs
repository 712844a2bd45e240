//! Trims on the CPU side: bad trims are one-line errors naming the object, loop and place, and
//! nothing panics; trims survive `convert` both ways exactly; edits (point moves, weights, knot
//! insertion, degree elevation) keep the trim and what lies inside, through the delta path,
//! undo and the JSON the autosave writes.

use crate::common::Scratch;
use prespline::editor::{Editor, EditorOptions};
use prespline::formats::json::scene_to_json;
use prespline::formats::parse_scene;
use prespline::sampling::SampleMode;
use prespline::sampling::budget::{MemoryBudget, Uses};
use prespline::scene::{EditList, Scene};
use std::process::Command;

/// A bicubic over [0, 1]² with `trim` (the JSON of the field).
fn scene_with(trim: &str) -> String {
    format!(
        r#"{{"objects": [{{"name": "face", "type": "bspline_surface", "degree": [3, 3],
  "knots": [[0, 0, 0, 0, 0.5, 1, 1, 1, 1], [0, 0, 0, 0, 1, 1, 1, 1]],
  "points": [[[0,0,0],[0,1,0.2],[0,2,0],[0,3,0.1]], [[1,0,0.3],[1,1,0.5],[1,2,0.4],[1,3,0]],
             [[2,0,0],[2,1,0.6],[2,2,0.2],[2,3,0.3]], [[3,0,0.1],[3,1,0],[3,2,0.3],[3,3,0]],
             [[4,0,0],[4,1,0.2],[4,2,0],[4,3,0.1]]],
  "samples": [21, 17], "trim": {trim}}}]}}"#
    )
}

const SQUARE: &str =
    r#"{"polyline": [[0.1, 0.1], [0.9, 0.1], [0.9, 0.9], [0.1, 0.9], [0.1, 0.1]]}"#;

/// `prespline info` of the scene: (success, stdout, stderr).
fn info(scene: &str) -> (bool, String, String) {
    let dir = Scratch::new("trims");
    let out = Command::new(env!("CARGO_BIN_EXE_prespline"))
        .arg("info")
        .arg(dir.file("scene.json", scene))
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn bad_trims_are_one_line_errors() {
    let cases = [
        (
            "open loop",
            r#"[{"outer": [{"polyline": [[0.1, 0.1], [0.9, 0.1], [0.9, 0.9], [0.1, 0.9]]}]}]"#.to_string(),
            "a gap of",
        ),
        (
            "outside the domain",
            r#"[{"outer": [{"polyline": [[0.1, 0.1], [1.5, 0.1], [0.9, 0.9], [0.1, 0.1]]}]}]"#.to_string(),
            "leaves the parameter domain",
        ),
        (
            "self-intersecting",
            r#"[{"outer": [{"polyline": [[0.1, 0.1], [0.9, 0.1], [0.9, 0.9], [0.5, 0.05], [0.1, 0.1]]}]}]"#.to_string(),
            "crosses itself",
        ),
        (
            "hole outside its outer loop",
            format!(
                r#"[{{"outer": [{SQUARE}]}}, {{"hole": [{{"polyline": [[0.92, 0.92], [0.98, 0.92], [0.98, 0.98], [0.92, 0.92]]}}]}}]"#
            ),
            "outside every outer loop",
        ),
        ("empty loop", r#"[{"outer": []}]"#.to_string(), "no curves"),
        ("no loops", "[]".to_string(), "no loops"),
        (
            "loops crossing each other",
            format!(
                r#"[{{"loop": [{SQUARE}]}}, {{"loop": [{{"polyline": [[0.5, 0.5], [0.95, 0.5], [0.95, 0.95], [0.5, 0.5]]}}]}}]"#
            ),
            "cross",
        ),
        (
            "bad range",
            r#"[{"outer": [{"polyline": [[0.1, 0.1], [0.9, 0.1], [0.5, 0.9], [0.1, 0.1]], "range": [0, 7]}]}]"#.to_string(),
            "range",
        ),
    ];
    for (what, trim, words) in cases {
        let (ok, stdout, stderr) = info(&scene_with(&trim));
        assert!(!ok, "{what}: accepted\n{stdout}");
        assert!(stdout.is_empty(), "{what}: partial output {stdout}");
        assert_eq!(stderr.lines().count(), 1, "{what}: {stderr}");
        assert!(!stderr.contains("panicked"), "{what}: {stderr}");
        assert!(stderr.contains("object 'face'"), "{what}: {stderr}");
        assert!(stderr.contains("trim"), "{what}: {stderr}");
        assert!(stderr.contains(words), "{what}: {stderr} lacks {words:?}");
    }
    // JSON cannot spell NaN (an out-of-range number is refused by the JSON reader in one
    // line); an OBJ parameter vertex can.
    let (ok, _, stderr) = info(&scene_with(
        r#"[{"outer": [{"polyline": [[0.1, 0.1], [1e999, 0.1], [0.5, 0.9], [0.1, 0.1]]}]}]"#,
    ));
    assert!(
        !ok && stderr.lines().count() == 1 && stderr.contains("invalid JSON"),
        "{stderr}"
    );
    let dir = Scratch::new("trims");
    let obj = dir.file(
        "nan.obj",
        "vp 0.1 0.1\nvp nan 0.1\nvp 0.5 0.9\ncstype bspline\ndeg 1\ncurv2 1 2 3 1\nparm u 0 0 1 2 3 3\nend\n\
         v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\ndeg 1 1\nsurf 0 1 0 1 1 2 3 4\nparm u 0 0 1 1\nparm v 0 0 1 1\ntrim 0 3 1\nend\n",
    );
    let out = Command::new(env!("CARGO_BIN_EXE_prespline"))
        .arg("info")
        .arg(&obj)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "NaN accepted");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(stderr.contains("nan.obj:"), "{stderr}");
    // The same trim, valid, is read (a negative control for the cases above).
    let (ok, stdout, stderr) = info(&scene_with(&format!("[{{\"outer\": [{SQUARE}]}}]")));
    assert!(ok, "{stderr}");
    assert!(stdout.contains("1 loop"), "{stdout}");
}

#[test]
fn a_trim_on_a_curve_is_refused() {
    let text = r#"{"objects": [{"name": "c", "type": "bezier_curve", "points": [[0,0,0],[1,0,0]],
      "samples": 3, "trim": [{"outer": [{"polyline": [[0, 0], [1, 0], [1, 1], [0, 0]]}]}]}]}"#;
    let e = parse_scene(text).unwrap_err().to_string();
    assert!(e.contains("only surfaces have trims"), "{e}");
}

#[test]
fn trims_convert_to_obj_and_back_exactly() {
    let original = parse_scene(
        &std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/examples/trimmed_surface.json"
        ))
        .unwrap(),
    )
    .unwrap();
    let dir = Scratch::new("trims");
    let json = dir.file("a.json", &scene_to_json(&original));
    let obj = dir.join("b.obj");
    let back = dir.join("c.json");
    for (from, to) in [(&json, &obj), (&obj, &back)] {
        let out = Command::new(env!("CARGO_BIN_EXE_prespline"))
            .args(["convert"])
            .arg(from)
            .arg(to)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let again = prespline::formats::read_json(&back).unwrap();
    let (a, b) = (&original.objects[0], &again.objects[0]);
    assert_eq!(a.model, b.model, "control data bit for bit");
    let (ta, tb) = (
        a.trim.as_ref().unwrap().spec(),
        b.trim.as_ref().unwrap().spec(),
    );
    assert_eq!(ta.loops.len(), tb.loops.len());
    for (la, lb) in ta.loops.iter().zip(&tb.loops) {
        // Every curve and range bit for bit (the roles OBJ writes are the ones nesting gave).
        assert_eq!(la.pieces, lb.pieces);
    }
    let inside = |s: &Scene| {
        let doc = prespline::editor::Document::new(s);
        doc.objects[0]
            .trim
            .as_ref()
            .unwrap()
            .coverage
            .inside()
            .to_vec()
    };
    assert_eq!(inside(&original), inside(&again));
}

/// The inside flags of the one object after `edits`, through the delta path.
fn inside_after(scene: &Scene, edits: &str) -> (Vec<bool>, Scene) {
    let options = EditorOptions {
        mode: SampleMode::Render,
        uses: Uses {
            gpu_slots: 0,
            control_displays: false,
            json_text: false,
        },
        budget: MemoryBudget::machine_default(),
    };
    let mut editor = Editor::new(scene, options).unwrap();
    editor
        .submit_list(&EditList::parse(edits).unwrap())
        .unwrap_or_else(|e| panic!("{e:?}"));
    let doc = editor.into_document();
    let inside = doc.objects[0]
        .trim
        .as_ref()
        .unwrap()
        .coverage
        .inside()
        .to_vec();
    (inside, doc.to_scene())
}

#[test]
fn edits_keep_the_trim_and_what_lies_inside() {
    let scene = parse_scene(&scene_with(&format!(
        "[{{\"outer\": [{SQUARE}]}}, {{\"hole\": [{{\"polyline\": [[0.4, 0.4], [0.6, 0.4], [0.5, 0.6], [0.4, 0.4]]}}]}}]"
    )))
    .unwrap();
    let before = prespline::editor::Document::new(&scene).objects[0]
        .trim
        .as_ref()
        .unwrap()
        .coverage
        .inside()
        .to_vec();
    // A point whose support crosses the boundary, a weight, a knot, a degree.
    let edits = r#"[{"object": "face", "point": [1, 1], "delta": [0.1, -0.2, 0.3]},
        {"object": "face", "point": [2, 2], "weight": 1.7},
        {"object": "face", "insert_knot": {"u": 0.37}},
        {"object": "face", "elevate_degree": {"u": 1, "v": 0}}]"#;
    let (after, edited) = inside_after(&scene, edits);
    assert_eq!(
        before, after,
        "the samples inside the trim are the same after the edits"
    );
    assert_eq!(
        edited.objects[0].trim, scene.objects[0].trim,
        "the trim is unchanged in parameter space"
    );
    // What the autosave writes carries the trim.
    let reread = parse_scene(&scene_to_json(&edited)).unwrap();
    assert_eq!(reread.objects[0].trim, scene.objects[0].trim);
    // Negative control: a different trim changes what lies inside.
    let other = parse_scene(&scene_with(&format!("[{{\"outer\": [{SQUARE}]}}]"))).unwrap();
    let (without_hole, _) = inside_after(&other, "[]");
    assert_ne!(without_hole, before);
}

#[test]
fn undo_after_edits_gives_back_the_trimmed_scene() {
    let scene = parse_scene(&scene_with(&format!("[{{\"outer\": [{SQUARE}]}}]"))).unwrap();
    let options = EditorOptions {
        mode: SampleMode::Render,
        uses: Uses {
            gpu_slots: 0,
            control_displays: false,
            json_text: false,
        },
        budget: MemoryBudget::machine_default(),
    };
    let mut editor = Editor::new(&scene, options).unwrap();
    let edits = r#"[{"object": "face", "point": [3, 2], "delta": [0.1, 0.2, -0.3]},
        {"object": "face", "insert_knot": {"v": 0.6}},
        {"object": "face", "point": [0, 0], "delta": [0.5, 0, 0]}]"#;
    editor
        .submit_list(&EditList::parse(edits).unwrap())
        .unwrap();
    while editor.undo().is_some() {}
    let doc = editor.into_document();
    assert_eq!(
        doc.to_scene(),
        scene,
        "undo restores model and trim exactly"
    );
}
