//! Bad values in structural edits (`insert_knot`, `times`, `elevate_degree`) are refused by
//! `prespline sample`, through the incremental path and `--full` alike: a non-zero exit, one
//! line on stderr naming the object and the field, nothing on stdout (nothing is half-applied).
//! Each refusal has an accepted neighbour, so the table cannot pass by refusing everything.

use std::path::PathBuf;
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};

/// A clamped cubic "c" on [0, 2] with a simple knot at 1, a quadratic Bézier "b", a rational
/// B-spline surface "s" of degree (2, 1) on [0, 1]², and ERBS objects "e" and "es".
const SCENE: &str = r#"{"objects": [
 {"name": "c", "type": "bspline_curve", "degree": 3, "knots": [0, 0, 0, 0, 1, 2, 2, 2, 2],
  "points": [[0, 0, 0], [1, 1, 0], [2, 0, 0], [3, 1, 0], [4, 0, 0]], "samples": 5},
 {"name": "b", "type": "bezier_curve", "points": [[0, 0, 0], [1, 2, 0], [3, 0, 0]], "samples": 3},
 {"name": "s", "type": "bspline_surface", "degree": [2, 1], "knots": [[0, 0, 0, 1, 1, 1], [0, 0, 1, 1]],
  "points": [[[0, 0, 0], [0, 1, 0]], [[1, 0, 1], [1, 1, 0]], [[2, 0, 0], [2, 1, 1]]],
  "weights": [[1, 2], [1, 1], [0.5, 1]], "samples": [3, 3]},
 {"name": "e", "type": "erbs_curve", "knots": [0, 0, 1, 1],
  "local": [{"points": [[0, 0, 0]]}, {"points": [[1, 1, 1]]}], "samples": 3},
 {"name": "es", "type": "erbs_surface", "knots": [[0, 0, 1, 1], [0, 0, 1, 1]],
  "local": [[{"points": [[[0, 0, 0]]]}, {"points": [[[0, 1, 0]]]}],
            [{"points": [[[1, 0, 0]]]}, {"points": [[[1, 1, 1]]]}]], "samples": [2, 2]}
]}"#;

/// A fresh file under this run's scratch folder (tests run in parallel: one name per call).
fn scratch(stem: &str, text: &str) -> PathBuf {
    static NEXT: AtomicUsize = AtomicUsize::new(0);
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("structural-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!(
        "{stem}-{}.json",
        NEXT.fetch_add(1, Ordering::Relaxed)
    ));
    std::fs::write(&path, text).unwrap();
    path
}

/// `prespline sample SCENE --derivatives 1 --edits EDITS [--full]`: (success, stdout, stderr).
fn sample(edits: &str, full: bool) -> (bool, String, String) {
    let mut command = Command::new(env!("CARGO_BIN_EXE_prespline"));
    command
        .arg("sample")
        .arg(scratch("scene", SCENE))
        .args(["--derivatives", "1", "--edits"])
        .arg(scratch("edits", edits));
    if full {
        command.arg("--full");
    }
    let out = command.output().unwrap();
    (
        out.status.success(),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

fn accepted(edits: &str) {
    for full in [false, true] {
        let (ok, stdout, stderr) = sample(edits, full);
        assert!(ok, "{edits} (full: {full}) refused: {stderr}");
        assert!(stdout.starts_with("{\"objects\""), "{edits}: {stdout}");
    }
}

/// Refused with one line that names `object` and `field` (quoted as the CLI quotes them).
fn refused(edits: &str, object: &str, field: &str) {
    for full in [false, true] {
        let (ok, stdout, stderr) = sample(edits, full);
        let what = format!("{edits} (full: {full})");
        assert!(!ok, "{what} was accepted");
        assert!(stdout.is_empty(), "{what}: output on stdout: {stdout}");
        assert_eq!(stderr.lines().count(), 1, "{what}: not one line:\n{stderr}");
        assert!(stderr.starts_with("error: "), "{what}: {stderr}");
        assert!(!stderr.contains("panicked"), "{what}: {stderr}");
        for part in [format!("'{object}'"), format!("'{field}'")] {
            assert!(
                stderr.contains(&part),
                "{what}: {stderr:?} does not name {part}"
            );
        }
    }
}

#[test]
fn valid_structural_edits_are_accepted() {
    for edits in [
        r#"[{"object": "c", "insert_knot": 0.5}]"#,
        r#"[{"object": "c", "insert_knot": 1, "times": 2}]"#,
        r#"[{"object": "c", "insert_knot": 0.5, "times": 3}]"#,
        r#"[{"object": "c", "elevate_degree": 1}]"#,
        r#"[{"object": "c", "elevate_degree": 61}]"#,
        r#"[{"object": "b", "insert_knot": 0.25, "times": 2}]"#,
        r#"[{"object": "b", "elevate_degree": 2}]"#,
        r#"[{"object": "s", "insert_knot": {"u": 0.5}}]"#,
        r#"[{"object": "s", "insert_knot": {"v": 0.5}, "times": 1}]"#,
        r#"[{"object": "s", "elevate_degree": {"u": 1, "v": 0}}]"#,
        r#"[{"object": "s", "elevate_degree": {"v": 2}}]"#,
        // Later edits address the refined net: 6 points after one insertion, 4 rows in u.
        r#"[{"object": "c", "insert_knot": 0.5}, {"object": "c", "point": 5, "delta": [1, 0, 0]}]"#,
        r#"[{"object": "s", "insert_knot": {"u": 0.5}}, {"object": "s", "point": [3, 1], "weight": 2}]"#,
        r#"[{"object": "b", "elevate_degree": 1}, {"object": "b", "point": 3, "delta": [0, 1, 0]}]"#,
    ] {
        accepted(edits);
    }
}

#[test]
fn parameter_outside_the_open_domain() {
    for t in ["0", "2", "-0.0", "-1", "2.5", "1e300"] {
        refused(
            &format!(r#"[{{"object": "c", "insert_knot": {t}}}]"#),
            "c",
            "insert_knot",
        );
    }
    refused(r#"[{"object": "b", "insert_knot": 1}]"#, "b", "insert_knot");
    refused(
        r#"[{"object": "s", "insert_knot": {"v": 1}}]"#,
        "s",
        "insert_knot",
    );
    refused(
        r#"[{"object": "s", "insert_knot": {"u": -0.5}}]"#,
        "s",
        "insert_knot",
    );
}

#[test]
fn multiplicity_above_the_degree() {
    refused(
        r#"[{"object": "c", "insert_knot": 1, "times": 3}]"#,
        "c",
        "times",
    );
    refused(
        r#"[{"object": "c", "insert_knot": 0.5, "times": 4}]"#,
        "c",
        "times",
    );
    refused(
        r#"[{"object": "b", "insert_knot": 0.5, "times": 3}]"#,
        "b",
        "times",
    );
    refused(
        r#"[{"object": "s", "insert_knot": {"v": 0.5}, "times": 2}]"#,
        "s",
        "times",
    );
    // The earlier insertion counts: 1 is then at multiplicity 3 = degree.
    refused(
        r#"[{"object": "c", "insert_knot": 1, "times": 2}, {"object": "c", "insert_knot": 1}]"#,
        "c",
        "times",
    );
}

#[test]
fn times_zero_negative_or_not_a_count() {
    for times in ["0", "-1", "1.5", "\"2\"", "null", "[1]"] {
        refused(
            &format!(r#"[{{"object": "c", "insert_knot": 0.5, "times": {times}}}]"#),
            "c",
            "times",
        );
    }
}

#[test]
fn elevation_zero_negative_over_the_limit_or_not_a_count() {
    for e in ["0", "-1", "1.5", "\"1\"", "null", "62", "1000000"] {
        refused(
            &format!(r#"[{{"object": "c", "elevate_degree": {e}}}]"#),
            "c",
            "elevate_degree",
        );
    }
    for by in [
        r#"{"u": 0, "v": 0}"#,
        "{}",
        r#"{"u": 63}"#,
        r#"{"v": -1}"#,
        r#"{"u": 1.5}"#,
        r#"{"w": 1}"#,
        "1",
    ] {
        refused(
            &format!(r#"[{{"object": "s", "elevate_degree": {by}}}]"#),
            "s",
            "elevate_degree",
        );
    }
}

#[test]
fn parameter_not_a_number() {
    for t in ["\"0.5\"", "null", "true", "[0.5]", r#"{"u": 0.5}"#] {
        refused(
            &format!(r#"[{{"object": "c", "insert_knot": {t}}}]"#),
            "c",
            "insert_knot",
        );
    }
    for at in [
        "0.5",
        r#"{"u": "x"}"#,
        r#"{"u": 0.5, "v": 0.5}"#,
        r#"{"w": 0.5}"#,
        "{}",
    ] {
        refused(
            &format!(r#"[{{"object": "s", "insert_knot": {at}}}]"#),
            "s",
            "insert_knot",
        );
    }
}

#[test]
fn erbs_objects_refine_by_their_own_insertion_only() {
    // ERBS refinement inserts a local between two knots; B-spline refinement does not apply.
    accepted(r#"[{"object": "e", "insert_knot": 0.5}]"#);
    accepted(r#"[{"object": "es", "insert_knot": {"u": 0.5}}]"#);
    refused(
        r#"[{"object": "e", "elevate_degree": 1}]"#,
        "e",
        "elevate_degree",
    );
    refused(
        r#"[{"object": "es", "elevate_degree": {"u": 1}}]"#,
        "es",
        "elevate_degree",
    );
    refused(r#"[{"object": "e", "insert_knot": 1}]"#, "e", "insert_knot");
    refused(
        r#"[{"object": "e", "insert_knot": 0.5}, {"object": "e", "insert_knot": 0.5}]"#,
        "e",
        "insert_knot",
    );
    refused(
        r#"[{"object": "es", "insert_knot": {"v": -0.5}}]"#,
        "es",
        "insert_knot",
    );
}

#[test]
fn an_index_past_the_refined_net_is_refused() {
    refused(
        r#"[{"object": "c", "insert_knot": 0.5}, {"object": "c", "point": 6, "delta": [1, 0, 0]}]"#,
        "c",
        "point",
    );
    refused(
        r#"[{"object": "s", "insert_knot": {"u": 0.5}}, {"object": "s", "point": [4, 0], "delta": [1, 0, 0]}]"#,
        "s",
        "point",
    );
    refused(
        r#"[{"object": "b", "elevate_degree": 1}, {"object": "b", "point": 4, "weight": 2}]"#,
        "b",
        "point",
    );
}
