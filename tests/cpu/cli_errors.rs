//! Bad input never panics: every class of malformed scene or edit file exits non-zero with one
//! line naming the object, field and index, and prints nothing on stdout.

use crate::common;

use common::Scratch;
use std::process::Command;

/// Runs `prespline sample` on its own copy of the scene (and edits) in a scratch directory of
/// this call alone, so no test rewrites a file another test's child is reading; returns
/// (success, stdout, stderr).
fn sample(scene: &str, edits: Option<&str>) -> (bool, String, String) {
    let dir = Scratch::new("cli-errors");
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_prespline"));
    cmd.arg("sample").arg(dir.file("scene.json", scene));
    if let Some(e) = edits {
        cmd.arg("--edits").arg(dir.file("edits.json", e));
    }
    let out = cmd.output().unwrap();
    (
        out.status.success(),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
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
    // Other programs' names for NURBS point to the B-spline kinds with weights.
    expect_error(
        &scene(&[&CURVE.replace("bspline_curve", "nurbs_curve")]),
        None,
        &[
            "unknown type 'nurbs_curve'",
            "bspline_curve with \"weights\"",
        ],
    );
    expect_error(
        &scene(&[&CURVE.replace("bspline_curve", "nurbs_surface")]),
        None,
        &[
            "unknown type 'nurbs_surface'",
            "bspline_surface with \"weights\"",
        ],
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
    // A surface weight is named as the file writes it, [row][column], not by a flat index.
    expect_error(
        &scene(&[&SURF.replace("\"samples\"", "\"weights\": [[1, 1], [1, -2]], \"samples\"")]),
        None,
        &[
            "object 's'",
            "field 'weights'",
            "weight [1][1] is -2",
            "positive",
        ],
    );
    expect_error(
        &scene(&[&SURF.replace("\"samples\"", "\"weights\": [[1, 0], [1, 1]], \"samples\"")]),
        None,
        &[
            "object 's'",
            "field 'weights'",
            "weight [0][1] is 0",
            "positive",
        ],
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
    let dir = Scratch::new("cli-errors");
    let s = dir.file("ok.json", &scene(&[CURVE]));
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

/// Scratch directories are unique per call (no two tests share a file), start empty even when
/// an earlier run with the same process id left one behind, and are removed afterwards.
#[test]
fn scratch_directories_are_unique_and_cleared() {
    let (a, b) = (Scratch::new("cli-errors"), Scratch::new("cli-errors"));
    assert_ne!(a.path(), b.path());
    let stale = a.path().to_path_buf();
    a.file("result.json", "stale");
    std::mem::forget(a); // as a crashed run leaves it
    let again = Scratch::at(stale.clone());
    assert_eq!(std::fs::read_dir(again.path()).unwrap().count(), 0);
    drop(again);
    assert!(!stale.exists(), "not removed after use");
}

/// Many tests sampling the same scene text at once each read their own file.
#[test]
fn concurrent_samples_of_one_scene_do_not_interfere() {
    let text = scene(&[CURVE, SURF, ERBS]);
    let runs: Vec<_> = (0..8)
        .map(|_| {
            let text = text.clone();
            std::thread::spawn(move || sample(&text, None))
        })
        .collect();
    for r in runs {
        let (ok, stdout, stderr) = r.join().unwrap();
        assert!(ok && stdout.starts_with("{\"objects\""), "{stderr}");
    }
}

const BSURF: &str = r#"{"name": "b", "type": "bspline_surface", "degree": [2, 1], "knots": [[0,0,0,1,1,1],[0,0,1,2,2]], "points": [[[0,0,0],[0,1,0],[0,2,0]],[[1,0,0],[1,1,1],[1,2,0]],[[2,0,0],[2,1,0],[2,2,0]]], "samples": [4, 5]}"#;
const ESURF: &str = r#"{"name": "es", "type": "erbs_surface", "knots": [[0,0,1,1],[0,0,1,2,2]], "local": [[{"points": [[[0,0,0],[0,1,0]],[[1,0,0],[1,1,0]]]}, {"points": [[[0,1,0]]]}, {"points": [[[0,2,0],[1,2,0]]]}], [{"points": [[[1,0,0]]]}, {"points": [[[1,1,1]]]}, {"points": [[[1,2,0]]]}]], "samples": [5, 6]}"#;

#[test]
fn bspline_surface_fields() {
    let (ok, _, stderr) = sample(&scene(&[BSURF]), None);
    assert!(ok, "the base surface is valid: {stderr}");
    let bad = |from: &str, to: &str, parts: &[&str]| {
        assert!(BSURF.contains(from), "{from}");
        expect_error(&scene(&[&BSURF.replace(from, to)]), None, parts);
    };
    let at = "object 'b' (objects[0])";
    bad(
        "\"degree\": [2, 1]",
        "\"degree\": [2]",
        &[at, "field 'degree'", "expected [du, dv]"],
    );
    bad(
        "\"degree\": [2, 1]",
        "\"degree\": [3, 1]",
        &[
            at,
            "field 'degree'",
            "u direction",
            "degree 3 needs at least 4 control points, got 3",
        ],
    );
    bad(
        "[0,0,0,1,1,1]",
        "[0,0,1,1,1]",
        &[
            at,
            "field 'knots'",
            "u direction",
            "expected 6 knots",
            "got 5",
        ],
    );
    bad(
        "[0,0,1,2,2]",
        "[0,0,2,1,2]",
        &[
            at,
            "field 'knots'",
            "v direction",
            "knot 3 (1) is smaller than knot 2 (2)",
        ],
    );
    bad(
        "\"knots\": [[0,0,0,1,1,1],[0,0,1,2,2]]",
        "\"knots\": [[0,0,0,1,1,1]]",
        &[at, "field 'knots'", "expected [[u knots], [v knots]]"],
    );
    bad(
        "[[2,0,0],[2,1,0],[2,2,0]]",
        "[[2,0,0],[2,1,0]]",
        &[at, "field 'points'", "row 2 has 2 entries, row 0 has 3"],
    );
    bad(
        "[1,1,1]",
        "[1,\"x\",1]",
        &[
            at,
            "field 'points'",
            "point [1][1] coordinate 1",
            "expected a number, found a string",
        ],
    );
    bad(
        "\"samples\": [4, 5]",
        "\"weights\": [[1,1,1],[1,1,1],[1,1,-1]], \"samples\": [4, 5]",
        &[at, "field 'weights'", "is -1", "positive"],
    );
    bad(
        "\"samples\": [4, 5]",
        "\"samples\": [4, 1]",
        &[at, "field 'samples'", "at least 2"],
    );
}

#[test]
fn erbs_surface_fields() {
    let (ok, _, stderr) = sample(&scene(&[ESURF]), None);
    assert!(ok, "the base surface is valid: {stderr}");
    let bad = |from: &str, to: &str, parts: &[&str]| {
        assert!(ESURF.contains(from), "{from}");
        expect_error(&scene(&[&ESURF.replace(from, to)]), None, parts);
    };
    let at = "object 'es' (objects[0])";
    bad(
        "[[0,0,1,1],[0,0,1,2,2]]",
        "[[0,0,1,1],[0,0,1,1,2]]",
        &[
            at,
            "field 'knots'",
            "v direction",
            "knot 4 (2) must equal knot 3 (1)",
        ],
    );
    bad(
        "[[0,0,1,1],[0,0,1,2,2]]",
        "[[0,1,1,1],[0,0,1,2,2]]",
        &[
            at,
            "field 'knots'",
            "u direction",
            "knot 0 (0) must equal knot 1 (1)",
        ],
    );
    bad(
        "[[0,0,1,1],[0,0,1,2,2]]",
        "[[0,0,1,1],[0,0,1,2]]",
        &[
            at,
            "field 'knots'",
            "v direction",
            "expected 5 knots (local patches + 2 = 3 + 2)",
            "got 4",
        ],
    );
    bad(
        "{\"points\": [[[1,1,1]]]}",
        "{\"points\": [[[1,1,1]]], \"w\": 2}",
        &[at, "local[1][1]", "unknown field 'w'"],
    );
    bad(
        "{\"points\": [[[1,1,1]]]}",
        "{\"points\": [[1,1,1]]}",
        &[at, "local[1][1]", "field 'points'", "point [0][0]"],
    );
    bad(
        "[{\"points\": [[[1,0,0]]]}, {\"points\": [[[1,1,1]]]}, {\"points\": [[[1,2,0]]]}]",
        "[{\"points\": [[[1,0,0]]]}, {\"points\": [[[1,1,1]]]}]",
        &[at, "field 'local'", "row 1 has 2 entries, row 0 has 3"],
    );
    bad(
        "[[[0,2,0],[1,2,0]]]",
        "[[[0,2,0],[1,2,0]],[[0,3,0]]]",
        &[at, "local[0][2]", "field 'points'", "row 1 has 1 entries"],
    );
    bad(
        "\"samples\": [5, 6]",
        "\"bfunction\": \"x\", \"samples\": [5, 6]",
        &[at, "field 'bfunction'", "unknown B-function 'x'"],
    );
    bad(
        "\"samples\": [5, 6]",
        "\"samples\": 5",
        &[at, "field 'samples'", "expected [mu, mv]"],
    );
}

/// The issue's example: a degree-60 B-spline curve with 5 000 000 samples and 20 derivatives
/// needs ≈ 51 GB of Hermite tables. It must be refused before anything is allocated, with one
/// line naming the object and the estimate — not abort the process in the allocator.
#[test]
fn a_request_too_large_for_memory_is_refused_in_one_line() {
    let points: Vec<String> = (0..61).map(|i| format!("[{i}, {}, 0]", i % 3)).collect();
    let knots: Vec<&str> = std::iter::repeat_n("0", 61)
        .chain(std::iter::repeat_n("1", 61))
        .collect();
    let big = format!(
        r#"{{"name": "big", "type": "bspline_curve", "degree": 60, "knots": [{}], "points": [{}], "samples": 5000000}}"#,
        knots.join(","),
        points.join(",")
    );
    let dir = Scratch::new("cli-errors");
    let path = dir.file("big.json", &scene(&[CURVE, &big]));
    let start = std::time::Instant::now();
    let out = Command::new(env!("CARGO_BIN_EXE_prespline"))
        .arg("sample")
        .arg(&path)
        .args(["--derivatives", "20"])
        .output()
        .unwrap();
    let stderr = String::from_utf8(out.stderr).unwrap();
    eprintln!("refused in {:?}: {stderr}", start.elapsed());
    assert!(!out.status.success());
    assert!(out.stdout.is_empty(), "partial output");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    for part in [
        "error: ",
        "big.json: object 'big' (objects[1])",
        "needs about",
        "GiB to pre-evaluate",
        "Hermite tables",
        "5000000 samples × 21 derivative orders × 61 basis functions",
        "over the memory budget of",
        "half of physical memory; --memory-limit overrides",
    ] {
        assert!(stderr.contains(part), "{stderr:?} lacks {part:?}");
    }
}

/// `--memory-limit` applies to every command that pre-evaluates, and refuses before a window,
/// a device or any output exists.
#[test]
fn memory_limit_applies_to_every_command() {
    let dir = Scratch::new("cli-errors");
    let path = dir.file("scene.json", &scene(&[SURF]));
    let png = dir.join("out.png");
    let out_dir = dir.join("bench");
    let runs: [Vec<&std::ffi::OsStr>; 4] = [
        vec!["sample".as_ref(), path.as_ref()],
        vec![
            "render".as_ref(),
            path.as_ref(),
            "--out".as_ref(),
            png.as_ref(),
        ],
        vec!["view".as_ref(), path.as_ref()],
        vec![
            "bench".as_ref(),
            path.as_ref(),
            "--out".as_ref(),
            out_dir.as_ref(),
        ],
    ];
    for args in runs {
        let out = Command::new(env!("CARGO_BIN_EXE_prespline"))
            .args(&args)
            .args(["--memory-limit", "2K"])
            .output()
            .unwrap();
        let stderr = String::from_utf8(out.stderr).unwrap();
        assert!(!out.status.success(), "{args:?}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{args:?}: {stderr}");
        assert!(
            stderr.contains("object 's' (objects[0]): needs about")
                && stderr.contains("over the memory budget of 2.0 KiB (--memory-limit)"),
            "{args:?}: {stderr}"
        );
    }
    // Within the limit the same scene samples.
    assert!(
        !png.exists() && !out_dir.exists(),
        "output written after refusing"
    );
    let out = Command::new(env!("CARGO_BIN_EXE_prespline"))
        .arg("sample")
        .arg(&path)
        .args(["--memory-limit", "1M"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let bad = Command::new(env!("CARGO_BIN_EXE_prespline"))
        .arg("sample")
        .arg(&path)
        .args(["--memory-limit", "lots"])
        .output()
        .unwrap();
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--memory-limit"));
}

/// User text is echoed escaped: a name with a newline cannot split the error line, an ESC
/// sequence in a name or an unknown field never reaches the terminal.
#[test]
fn control_characters_in_user_text_are_escaped() {
    let bad_name = CURVE.replace(r#""name": "c""#, r#""name": "c\nd\u001b[31m", "oops": 1"#);
    expect_error(&scene(&[&bad_name]), None, &[r"c\nd\u{1b}[31m", "'oops'"]);
    let bad_field = CURVE.replace(
        r#""name": "c","#,
        r#""name": "c", "x\u001b]0;pwned\u0007": 1,"#,
    );
    expect_error(&scene(&[&bad_field]), None, &[r"x\u{1b}]0;pwned\u{7}"]);
    // C1 controls alone: the 8-bit CSI (U+009B) and NEL (U+0085).
    let c1_name = CURVE.replace(
        r#""name": "c""#,
        r#""name": "c\u009b31md\u0085", "oops": 1"#,
    );
    expect_error(&scene(&[&c1_name]), None, &[r"c\u{9b}31md\u{85}", "'oops'"]);
    for text in [&bad_name, &bad_field, &c1_name] {
        let (_, _, stderr) = sample(&scene(&[text]), None);
        assert!(
            !stderr.trim_end_matches('\n').chars().any(char::is_control),
            "a control character reached stderr: {stderr:?}"
        );
    }
}

/// `bench` on a malformed scene fails in one line before any GPU work, and writes nothing.
#[test]
fn bench_on_a_malformed_scene_prints_one_line() {
    let dir = Scratch::new("cli-errors");
    let scene = dir.file("scene.json", "{\"objects\": [");
    let out = Command::new(env!("CARGO_BIN_EXE_prespline"))
        .arg("bench")
        .arg(&scene)
        .args(["--scenario", "drag", "--frames", "3", "--out"])
        .arg(dir.join("out"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stderr.lines().count(), 1, "expected one line:\n{stderr}");
    assert!(
        stderr.starts_with("error: ") && stderr.contains("invalid JSON"),
        "{stderr}"
    );
    assert!(
        !dir.join("out").exists(),
        "nothing written for a failed run"
    );
}

/// `sample` takes `--samples` like every command that loads a scene: `N` for every curve,
/// `NxM` for every surface, JSON and OBJ alike (the file's counts without it); a bad count is
/// refused in one line.
#[test]
fn sample_takes_the_samples_override() {
    let dir = Scratch::new("cli-samples");
    let json = dir.file("scene.json", &scene(&[CURVE, SURF]));
    let counts = |args: &[&str], path: &std::path::Path| -> Vec<Vec<usize>> {
        let out = Command::new(env!("CARGO_BIN_EXE_prespline"))
            .arg("sample")
            .arg(path)
            .args(args)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        v["objects"]
            .as_array()
            .unwrap()
            .iter()
            .map(|o| match o["params"][0].as_array() {
                Some(u) => vec![u.len(), o["params"][1].as_array().unwrap().len()],
                None => vec![o["params"].as_array().unwrap().len()],
            })
            .collect()
    };
    assert_eq!(counts(&[], &json), [vec![10], vec![3, 3]]);
    assert_eq!(
        counts(&["--samples", "7", "--samples", "4x6"], &json),
        [vec![7], vec![4, 6]]
    );
    assert_eq!(counts(&["--samples", "5x5"], &json), [vec![10], vec![5, 5]]);
    // The issue's case: an OBJ file.
    let vase = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/vase.obj");
    let with = counts(&["--samples", "5", "--samples", "6x7"], &vase);
    assert!(!with.is_empty());
    for c in with {
        assert!(c == [5] || c == [6, 7], "{c:?}");
    }
    let out = Command::new(env!("CARGO_BIN_EXE_prespline"))
        .arg("sample")
        .arg(&json)
        .args(["--samples", "1"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(out.stdout.is_empty());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("1 samples: expected 2..="), "{err}");
    // Objects that give no count of their own take the flag's.
    let bare = dir.file(
        "bare.json",
        &scene(&[
            &CURVE.replace(r#", "samples": 10"#, ""),
            &SURF.replace(r#", "samples": [3, 3]"#, ""),
        ]),
    );
    assert_eq!(
        counts(&["--samples", "7", "--samples", "4x6"], &bare),
        [vec![7], vec![4, 6]]
    );
    // Negative control: without the flag (or without the surfaces' count) they are refused
    // as the format asks.
    for args in [&[][..], &["--samples", "7"][..]] {
        let out = Command::new(env!("CARGO_BIN_EXE_prespline"))
            .arg("sample")
            .arg(&bare)
            .args(args)
            .output()
            .unwrap();
        assert!(!out.status.success(), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("field 'samples': missing"), "{args:?}: {err}");
    }
}

/// `--samples N` sets curves only and `NxM` surfaces only (`--help`: "N for every curve, NxM
/// for every surface"): a count the scene has no object for changes nothing and says so in one
/// note on stderr. The teapot OBJ (surfaces only) with `--samples 5` keeps its counts and gets
/// the note; a scene with curves gets none (the negative control).
#[test]
fn a_samples_count_no_object_takes_is_noted() {
    let run = |path: &std::path::Path, args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_prespline"))
            .arg("sample")
            .arg(path)
            .args(args)
            .output()
            .unwrap();
        let err = String::from_utf8(out.stderr).unwrap();
        assert!(out.status.success(), "{args:?}: {err}");
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        (v, err)
    };
    let teapot = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/teapot.obj");
    let (plain, err) = run(&teapot, &[]);
    assert!(!err.contains("note:"), "{err}");
    let (with, err) = run(&teapot, &["--samples", "5"]);
    assert_eq!(with, plain, "no object of the teapot takes N");
    let notes: Vec<&str> = err.lines().filter(|l| l.contains("--samples")).collect();
    assert_eq!(notes.len(), 1, "{err}");
    assert!(
        notes[0].starts_with("note: --samples 5 sets the sample count of curves")
            && notes[0].contains("teapot.obj has none")
            && notes[0].contains("--samples 5x5"),
        "{err}"
    );
    let dir = Scratch::new("cli-samples-note");
    let curves = dir.file("curves.json", &scene(&[CURVE]));
    let (_, err) = run(&curves, &["--samples", "4x6"]);
    assert!(
        err.lines()
            .any(|l| l.starts_with("note: --samples 4x6 sets the sample count of surfaces")),
        "{err}"
    );
    let mixed = dir.file("mixed.json", &scene(&[CURVE, SURF]));
    let (_, err) = run(&mixed, &["--samples", "5", "--samples", "4x6"]);
    assert!(!err.contains("note:"), "every count applies: {err}");
}

/// The `--samples` note is held back until the command's own checks pass: an error found
/// after loading (an unwritable output, a bad view script, bad edits) is still one line, and a
/// command that succeeds prints the note (the negative control).
#[test]
fn a_samples_note_never_stands_before_an_error() {
    let dir = Scratch::new("cli-samples-held");
    let teapot = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/teapot.json");
    let script = dir.file("bad.json", r#"[{"frame": 1, "jump": 1}]"#);
    let edits = dir.file(
        "edits.json",
        r#"[{"object": "nobody", "point": [0, 0], "delta": [0, 0, 1]}]"#,
    );
    let stderr = |args: &[&std::ffi::OsStr]| {
        let out = Command::new(env!("CARGO_BIN_EXE_prespline"))
            .args(args)
            .env("DISPLAY", ":99")
            .output()
            .unwrap();
        (out.status.success(), String::from_utf8(out.stderr).unwrap())
    };
    let os = |s: &str| std::ffi::OsString::from(s);
    let t = teapot.as_os_str().to_owned();
    for args in [
        vec![
            os("convert"),
            t.clone(),
            os("--samples"),
            os("2"),
            os("/nonexistent/x.json"),
        ],
        vec![
            os("view"),
            t.clone(),
            os("--samples"),
            os("2"),
            os("--script"),
            script.clone().into(),
        ],
        vec![
            os("sample"),
            t.clone(),
            os("--samples"),
            os("2"),
            os("--edits"),
            edits.clone().into(),
        ],
    ] {
        let args: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_os_str()).collect();
        let (ok, err) = stderr(&args);
        assert!(!ok, "{args:?}");
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        assert!(
            err.starts_with("error: ") && !err.contains("note:"),
            "{err}"
        );
    }
    let out = dir.path().join("ok.json");
    let (ok, err) = stderr(&[
        os("convert").as_os_str(),
        t.as_os_str(),
        os("--samples").as_os_str(),
        os("2").as_os_str(),
        out.as_os_str(),
    ]);
    assert!(ok, "{err}");
    assert!(
        err.lines()
            .next()
            .is_some_and(|l| l.starts_with("note: --samples 2")),
        "{err}"
    );
}

/// Command-line mistakes get one line like every other error, naming what is wrong and
/// pointing to `--help` (clap writes a usage block and a hint over several lines).
#[test]
fn command_line_errors_are_one_line() {
    let run = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_prespline"))
            .args(args)
            .output()
            .unwrap();
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stdout).into_owned(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    for (args, part) in [
        (&["bench", "--scenario", "nosuch"][..], "nosuch"),
        (&["render"][..], "--out"),
        (
            &["sample", "x.json", "--samples", "10000001"][..],
            "10000001",
        ),
        (&["sample", "x.json", "--bogus"][..], "--bogus"),
        (&["nosuchcommand"][..], "nosuchcommand"),
    ] {
        let (code, stdout, stderr) = run(args);
        assert_eq!(code, Some(2), "{args:?}: {stderr}");
        assert!(stdout.is_empty(), "{args:?}: {stdout}");
        assert_eq!(
            stderr.lines().count(),
            1,
            "{args:?}: not one line:\n{stderr}"
        );
        assert!(
            stderr.starts_with("error: ") && stderr.contains(part) && stderr.contains("--help"),
            "{args:?}: {stderr}"
        );
    }
    // Both missing arguments are named on the one line.
    let (_, _, stderr) = run(&["render"]);
    assert!(stderr.contains("<SCENE>"), "{stderr}");
    // Negative control: help is not an error and keeps its lines.
    let (code, stdout, _) = run(&["render", "--help"]);
    assert_eq!(code, Some(0));
    assert!(stdout.lines().count() > 5, "{stdout}");
}

/// `view --save-as x.obj` on a scene OBJ cannot hold (an ERBS curve with the exponential
/// B-function has no B-spline form) is refused when the viewer starts, in one line, instead of
/// at the first Ctrl+S; the same scene with `--save-as x.json` gets past that check (to the
/// missing display here).
#[test]
fn view_refuses_a_save_path_that_cannot_hold_the_scene() {
    let dir = Scratch::new("cli-errors");
    let scene = dir.file("scene.json", &scene(&[ERBS]));
    let view = |save: &str| {
        let out = Command::new(env!("CARGO_BIN_EXE_prespline"))
            .arg("view")
            .arg(&scene)
            .arg("--save-as")
            .arg(dir.path().join(save))
            .env_remove("DISPLAY")
            .env_remove("WAYLAND_DISPLAY")
            .output()
            .unwrap();
        assert!(!out.status.success());
        String::from_utf8(out.stderr).unwrap()
    };
    let err = view("x.obj");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("--save-as") && err.contains("x.obj") && err.contains("object 'e'"),
        "{err}"
    );
    assert!(!dir.path().join("x.obj").exists());
    let err = view("x.json");
    assert!(err.contains("no display"), "{err}");
}

/// A sample that overflows is one line naming the file and the object and saying why: a
/// rational patch whose corner weight is 1e-300 has finite points but derivatives that divide
/// by a sum near 1e-300 (the weights' range is named); huge coordinates overflow their
/// powers (scale down). Negative control: the same patch at `--derivatives 0` samples.
#[test]
fn an_overflowing_sample_names_the_file_and_the_cause() {
    let dir = Scratch::new("cli-overflow");
    let tiny = dir.file(
        "tiny.json",
        r#"{"objects": [{"name": "tiny", "type": "bezier_surface", "points": [[[0,0,0],[0,1,0]],[[1,0,0],[1,1,0]]], "weights": [[1e-300, 1],[1, 1]], "samples": [5, 5]}]}"#,
    );
    let huge = dir.file(
        "huge.json",
        r#"{"objects": [{"name": "huge", "type": "bezier_curve", "points": [[0,0,0],[1e307,1e308,0],[1e308,0,0]], "samples": 5}]}"#,
    );
    let run = |path: &std::path::Path, d: &str| {
        let out = Command::new(env!("CARGO_BIN_EXE_prespline"))
            .arg("sample")
            .arg(path)
            .args(["--derivatives", d])
            .output()
            .unwrap();
        (out.status.success(), String::from_utf8(out.stderr).unwrap())
    };
    let (ok, err) = run(&tiny, "1");
    assert!(!ok);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("tiny.json: object 'tiny': evaluation overflowed")
            && err.contains("weights range from 1e-300 to 1e0"),
        "{err}"
    );
    let (ok, err) = run(&tiny, "0");
    assert!(ok, "{err}");
    let (ok, err) = run(&huge, "2");
    assert!(!ok);
    assert!(
        err.contains("huge.json: object 'huge'") && err.contains("scale the coordinates down"),
        "{err}"
    );
}
