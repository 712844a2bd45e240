//! Bad input never panics: every class of malformed scene or edit file exits non-zero with one
//! line naming the object, field and index, and prints nothing on stdout.

use std::path::PathBuf;
use std::process::Command;

fn tmp(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("prespline-cli-errors-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// Runs `prespline sample` and returns (success, stdout, stderr).
fn sample(scene: &str, edits: Option<&str>) -> (bool, String, String) {
    let s = tmp(&format!("scene-{:x}.json", hash(scene)), scene);
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_prespline"));
    cmd.arg("sample").arg(&s);
    if let Some(e) = edits {
        cmd.arg("--edits")
            .arg(tmp(&format!("edits-{:x}.json", hash(e)), e));
    }
    let out = cmd.output().unwrap();
    (
        out.status.success(),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

fn hash(s: &str) -> u64 {
    s.bytes().fold(0xcbf29ce484222325u64, |h, b| {
        (h ^ b as u64).wrapping_mul(0x100000001b3)
    })
}

fn expect_error(scene: &str, edits: Option<&str>, parts: &[&str]) {
    let (ok, stdout, stderr) = sample(scene, edits);
    assert!(!ok, "expected failure for {scene}");
    assert!(stdout.is_empty(), "partial output on stdout: {stdout}");
    assert_eq!(
        stderr.lines().count(),
        1,
        "expected exactly one line, got:\n{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(stderr.starts_with("error: "), "{stderr}");
    for p in parts {
        assert!(stderr.contains(p), "message {stderr:?} lacks {p:?}");
    }
}

const CURVE: &str = r#"{"name": "c", "type": "bspline_curve", "degree": 3, "knots": [0,0,0,0,1,2,2,2,2], "points": [[0,0,0],[1,1,0],[2,0,0],[3,1,0],[4,0,0]], "samples": 10}"#;
const SURF: &str = r#"{"name": "s", "type": "bezier_surface", "points": [[[0,0,0],[0,1,0]],[[1,0,0],[1,1,1]]], "samples": [3, 3]}"#;
const ERBS: &str = r#"{"name": "e", "type": "erbs_curve", "knots": [0,0,1,2,2], "local": [{"points": [[0,0,0],[1,0,0]]}, {"points": [[1,1,0]]}, {"points": [[2,0,0],[3,1,0]]}], "samples": 9}"#;

fn scene(objs: &[&str]) -> String {
    format!("{{\"objects\": [{}]}}", objs.join(", "))
}

#[test]
fn valid_scene_is_accepted() {
    let (ok, stdout, stderr) = sample(&scene(&[CURVE, SURF, ERBS]), None);
    assert!(ok, "{stderr}");
    assert!(stdout.starts_with("{\"objects\""));
}

#[test]
fn malformed_json() {
    expect_error("{\"objects\": [", None, &["invalid JSON", "line 1"]);
    expect_error("[1, 2]", None, &["must be a JSON object"]);
    expect_error(
        r#"{"objects": 3}"#,
        None,
        &["field 'objects'", "expected an array"],
    );
}

#[test]
fn nan_and_non_numbers() {
    // JSON has no NaN literal: the parser rejects it with a position.
    expect_error(
        &scene(&[&CURVE.replace("[1,1,0]", "[NaN,1,0]")]),
        None,
        &["invalid JSON"],
    );
    expect_error(
        &scene(&[&CURVE.replace("[1,1,0]", "[\"NaN\",1,0]")]),
        None,
        &[
            "object 'c'",
            "field 'points'",
            "point 1 coordinate 0",
            "expected a number, found a string",
        ],
    );
    expect_error(
        &scene(&[&CURVE
            .replace("1e0", "1e999")
            .replace("[1,1,0]", "[1e999,1,0]")]),
        None,
        &["invalid JSON"],
    );
}

#[test]
fn knot_vectors() {
    expect_error(
        &scene(&[&CURVE.replace("[0,0,0,0,1,2,2,2,2]", "[0,0,0,0,1,2,2,2]")]),
        None,
        &[
            "object 'c' (objects[0])",
            "field 'knots'",
            "expected 9 knots",
            "got 8",
        ],
    );
    expect_error(
        &scene(&[&CURVE.replace("[0,0,0,0,1,2,2,2,2]", "[0,0,0,0,2,1,2,2,2]")]),
        None,
        &[
            "object 'c'",
            "field 'knots'",
            "knot 5 (1) is smaller than knot 4 (2)",
        ],
    );
    expect_error(
        &scene(&[&CURVE.replace("[0,0,0,0,1,2,2,2,2]", "[0,0,0,0,0,2,2,2,2]")]),
        None,
        &["field 'knots'", "multiplicity 5"],
    );
    expect_error(
        &scene(&[&ERBS.replace("[0,0,1,2,2]", "[0,0,1,1,1]")]),
        None,
        &["object 'e'", "field 'knots'", "strictly increasing"],
    );
    expect_error(
        &scene(&[&ERBS.replace("[0,0,1,2,2]", "[0,1,1.5,2,2]")]),
        None,
        &["knot 0 (0) must equal knot 1 (1)"],
    );
}

#[test]
fn degree_and_counts() {
    expect_error(
        &scene(&[&CURVE.replace("\"degree\": 3", "\"degree\": 5")]),
        None,
        &[
            "object 'c'",
            "field 'degree'",
            "degree 5 needs at least 6 control points, got 5",
        ],
    );
    expect_error(
        &scene(&[&CURVE.replace("\"degree\": 3", "\"degree\": -1")]),
        None,
        &["field 'degree'", "non-negative integer"],
    );
    expect_error(
        &scene(&[&CURVE.replace("\"samples\": 10", "\"samples\": 1")]),
        None,
        &["field 'samples'", "at least 2"],
    );
    expect_error(
        &scene(&[&SURF.replace("[3, 3]", "[3]")]),
        None,
        &["object 's'", "field 'samples'", "expected [mu, mv]"],
    );
    expect_error(
        &scene(&[&SURF.replace("[[1,0,0],[1,1,1]]", "[[1,0,0]]")]),
        None,
        &[
            "object 's'",
            "field 'points'",
            "row 1 has 1 entries, row 0 has 2",
        ],
    );
}

#[test]
fn fields_and_names() {
    expect_error(
        &scene(&[&CURVE.replace("\"samples\": 10", "\"samples\": 10, \"colour\": 1")]),
        None,
        &["object 'c'", "unknown field 'colour'"],
    );
    expect_error(
        &scene(&[&CURVE.replace(", \"samples\": 10", "")]),
        None,
        &["object 'c'", "field 'samples': missing"],
    );
    expect_error(
        &scene(&[CURVE, CURVE]),
        None,
        &["object 'c' (objects[1])", "duplicate name", "objects[0]"],
    );
    expect_error(
        &scene(&[&CURVE.replace("bspline_curve", "spline")]),
        None,
        &["field 'type'", "unknown type 'spline'"],
    );
    expect_error(
        &scene(&[&ERBS.replace("\"samples\"", "\"bfunction\": \"gauss\", \"samples\"")]),
        None,
        &["field 'bfunction'", "unknown B-function 'gauss'", "expo"],
    );
    expect_error(
        r#"{"objects": [{"type": "bezier_curve"}]}"#,
        None,
        &["objects[0]", "field 'name': missing"],
    );
    expect_error(
        &scene(&[&ERBS.replace(
            "{\"points\": [[1,1,0]]}",
            "{\"points\": [[1,1,0]], \"w\": 1}",
        )]),
        None,
        &["local[1]", "unknown field 'w'"],
    );
}

#[test]
fn weights() {
    expect_error(
        &scene(&[&CURVE.replace("\"samples\"", "\"weights\": [1, 1, -2, 1, 1], \"samples\"")]),
        None,
        &[
            "object 'c'",
            "field 'weights'",
            "weight 2 is -2",
            "positive",
        ],
    );
    expect_error(
        &scene(&[&CURVE.replace("\"samples\"", "\"weights\": [1, 1], \"samples\"")]),
        None,
        &["field 'weights'", "2 weights for 5 control points"],
    );
    expect_error(
        &scene(&[&SURF.replace("\"samples\"", "\"weights\": [[1, 1]], \"samples\"")]),
        None,
        &["object 's'", "field 'weights'", "1 × 2 weights for 2 × 2"],
    );
}

#[test]
fn edits() {
    let sc = scene(&[CURVE, SURF, ERBS]);
    expect_error(
        &sc,
        Some(r#"[{"object": "x", "point": 1, "delta": [0,0,1]}]"#),
        &["edit 0", "field 'object'", "unknown object 'x'"],
    );
    expect_error(
        &sc,
        Some(
            r#"[{"object": "c", "point": 1, "delta": [0,0,1]}, {"object": "c", "point": 5, "delta": [0,0,1]}]"#,
        ),
        &[
            "edit 1 (object 'c')",
            "field 'point'",
            "index 5 out of range (valid: 0..=4)",
        ],
    );
    expect_error(
        &sc,
        Some(r#"[{"object": "s", "point": [0, 2], "delta": [0,0,1]}]"#),
        &["edit 0 (object 's')", "index [0, 2] out of range"],
    );
    expect_error(
        &sc,
        Some(r#"[{"object": "s", "point": 1, "delta": [0,0,1]}]"#),
        &["field 'point'", "expected [i, j]"],
    );
    expect_error(
        &sc,
        Some(r#"[{"object": "c", "point": 1, "delta": [0,0]}]"#),
        &["field 'delta'", "expected 3 coordinates"],
    );
    expect_error(
        &sc,
        Some(r#"[{"object": "c", "point": 1, "weight": 0}]"#),
        &["field 'weight'", "must be positive"],
    );
    expect_error(
        &sc,
        Some(
            r#"[{"object": "e", "local": 3, "transform": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}]"#,
        ),
        &[
            "edit 0 (object 'e')",
            "field 'local'",
            "index 3 out of range",
        ],
    );
    expect_error(
        &sc,
        Some(
            r#"[{"object": "e", "local": 1, "transform": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,1,1]]}]"#,
        ),
        &["field 'transform'", "not affine"],
    );
    expect_error(
        &sc,
        Some(r#"[{"object": "e", "local": 1, "point": 1, "delta": [1,0,0]}]"#),
        &["field 'point'", "index 1 out of range (valid: 0..=0)"],
    );
    expect_error(
        &sc,
        Some(r#"[{"object": "e", "point": 1, "delta": [1,0,0]}]"#),
        &["edit 0 (object 'e')", "through its local curves"],
    );
    expect_error(
        &sc,
        Some(r#"[{"object": "c", "local": 0, "transform": []}]"#),
        &["field 'local'", "only ERBS objects"],
    );
    expect_error(
        &sc,
        Some(r#"[{"object": "c", "point": 1, "delta": [0,0,1], "scale": 2}]"#),
        &["unknown field 'scale'"],
    );
    expect_error(&sc, Some(r#"{"object": "c"}"#), &["must be a JSON list"]);
}

#[test]
fn files_and_options() {
    let out = Command::new(env!("CARGO_BIN_EXE_prespline"))
        .args(["sample", "/nonexistent/scene.json"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(err.contains("cannot read /nonexistent/scene.json"), "{err}");
    assert_eq!(err.lines().count(), 1);
    let s = tmp("ok.json", &scene(&[CURVE]));
    let out = Command::new(env!("CARGO_BIN_EXE_prespline"))
        .arg("sample")
        .arg(&s)
        .args(["--derivatives", "99"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(
        String::from_utf8(out.stderr)
            .unwrap()
            .contains("exceeds the supported maximum")
    );
}
