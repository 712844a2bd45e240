//! Every field of `catmull_rom` and `bezier_spline` objects and of their edits: bad values exit
//! non-zero with one line naming the object and the field (and the junction or index), and print
//! nothing on stdout.

use std::path::PathBuf;
use std::process::Command;

/// A file of its own per call (tests run in parallel and may write the same text).
fn tmp(name: &str, text: &str) -> PathBuf {
    static NEXT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let name = format!("{n}-{name}");
    let dir = std::env::temp_dir().join(format!("prespline-spline-errors-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn hash(s: &str) -> u64 {
    s.bytes().fold(0xcbf29ce484222325u64, |h, b| {
        (h ^ b as u64).wrapping_mul(0x100000001b3)
    })
}

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

fn expect_error(scene: &str, edits: Option<&str>, parts: &[&str]) {
    let (ok, stdout, stderr) = sample(scene, edits);
    assert!(!ok, "expected failure for {scene} / {edits:?}");
    assert!(stdout.is_empty(), "partial output on stdout: {stdout}");
    assert_eq!(stderr.lines().count(), 1, "expected one line:\n{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    for p in parts {
        assert!(stderr.contains(p), "message {stderr:?} lacks {p:?}");
    }
}

fn scene(obj: &str) -> String {
    format!("{{\"objects\": [{obj}]}}")
}

const CR: &str = r#"{"name": "cr", "type": "catmull_rom", "points": [[0,0,0],[1,1,0],[2,0,0],[3,1,0]], "samples": 20}"#;
const BS: &str = r#"{"name": "bs", "type": "bezier_spline", "degree": 3, "knots": [0, 1, 3], "points": [[0,0,0],[1,1,0],[2,1,0],[3,0,0],[5,-2,0],[6,0,0],[7,1,0]], "continuity": "C1", "samples": 20}"#;

/// `base` with `field` replaced by (or, for `None`, without) `value`.
fn with(base: &str, field: &str, value: Option<&str>) -> String {
    let mut v: serde_json::Value = serde_json::from_str(base).unwrap();
    let o = v.as_object_mut().unwrap();
    match value {
        Some(x) => {
            o.insert(field.into(), serde_json::from_str(x).unwrap());
        }
        None => {
            o.remove(field);
        }
    }
    scene(&v.to_string())
}

#[test]
fn valid_splines_sample() {
    let (ok, stdout, stderr) = sample(&scene(&format!("{CR}, {BS}")), None);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("\"type\": \"catmull_rom\""));
    assert!(stdout.contains("\"type\": \"bezier_spline\""));
}

#[test]
fn catmull_rom_fields() {
    let at = "object 'cr' (objects[0])";
    let e = |f: &str, v: Option<&str>, parts: &[&str]| {
        let mut p = vec![at];
        p.extend_from_slice(parts);
        expect_error(&with(CR, f, v), None, &p);
    };
    e("points", None, &["field 'points'", "missing"]);
    e(
        "points",
        Some("[[0,0,0]]"),
        &["field 'points'", "at least 2"],
    );
    e(
        "points",
        Some("3"),
        &["field 'points'", "expected an array"],
    );
    e(
        "points",
        Some("[[0,0],[1,1,1]]"),
        &["field 'points'", "point 0"],
    );
    e(
        "closed",
        Some("\"yes\""),
        &["field 'closed'", "true or false"],
    );
    e(
        "parametrization",
        Some("\"arc\""),
        &["field 'parametrization'", "unknown parametrization 'arc'"],
    );
    e(
        "parametrization",
        Some("0.5"),
        &["field 'parametrization'", "expected a string"],
    );
    e("samples", Some("1"), &["field 'samples'", "at least 2"]);
    e("samples", None, &["field 'samples'", "missing"]);
    e("knots", Some("[0, 1]"), &["unknown field 'knots'"]);
    // A closed spline needs 3 points; centripetal knots need distinct neighbours.
    let two = with(CR, "points", Some("[[0,0,0],[1,1,0]]"));
    let closed = two.replace("\"samples\"", "\"closed\": true, \"samples\"");
    expect_error(&closed, None, &[at, "field 'points'", "at least 3"]);
    let dup = with(CR, "points", Some("[[0,0,0],[1,1,0],[1,1,0],[3,1,0]]"));
    let dup = dup.replace(
        "\"samples\"",
        "\"parametrization\": \"chordal\", \"samples\"",
    );
    expect_error(
        &dup,
        None,
        &[at, "field 'points'", "points 1 and 2 coincide"],
    );
}

#[test]
fn bezier_spline_fields() {
    let at = "object 'bs' (objects[0])";
    let e = |f: &str, v: Option<&str>, parts: &[&str]| {
        let mut p = vec![at];
        p.extend_from_slice(parts);
        expect_error(&with(BS, f, v), None, &p);
    };
    e("degree", None, &["field 'degree'", "missing"]);
    e("degree", Some("-1"), &["field 'degree'"]);
    e(
        "degree",
        Some("2"),
        &["field 'points'", "need k·d + 1 = 5 points"],
    );
    e("degree", Some("99"), &["field 'degree'", "exceeds"]);
    e("knots", None, &["field 'knots'", "missing"]);
    e("knots", Some("[0]"), &["field 'knots'", "at least 2 knots"]);
    e(
        "knots",
        Some("[0, 2, 1]"),
        &["field 'knots'", "knot 2 (1) is not above knot 1 (2)"],
    );
    e(
        "knots",
        Some("[0, 0, 1]"),
        &["field 'knots'", "strictly increasing"],
    );
    e("knots", Some("[0, \"a\", 1]"), &["field 'knots'", "knot 1"]);
    e("points", Some("[[0,0,0]]"), &["field 'points'", "got 1"]);
    e(
        "continuity",
        Some("\"C3\""),
        &["field 'continuity'", "unknown continuity 'C3'"],
    );
    e("continuity", None, &["field 'continuity'", "missing"]);
    e(
        "continuity",
        Some("\"C2\""),
        &["field 'points'", "junction 1 (t = 1, point 3)", "C2"],
    );
    e(
        "weights",
        Some("[1,1,1,1,1,1,1]"),
        &["unknown field 'weights'"],
    );
    e("samples", Some("0"), &["field 'samples'"]);
    // Continuity that breaks at the named junction: P4 is not P3 + (h1/h0)(P3 − P2).
    e(
        "points",
        Some("[[0,0,0],[1,1,0],[2,1,0],[3,0,0],[4,-2,0],[6,0,0],[7,1,0]]"),
        &[
            "field 'points'",
            "junction 1 (t = 1, point 3)",
            "declared C1",
        ],
    );
    let g1 = with(
        BS,
        "points",
        Some("[[0,0,0],[1,1,0],[2,1,0],[3,0,0],[3.5,0.5,0],[6,0,0],[7,1,0]]"),
    )
    .replace("\"C1\"", "\"G1\"");
    expect_error(
        &g1,
        None,
        &[at, "junction 1", "declared G1", "not collinear"],
    );
    let d2 = BS
        .replace("\"degree\": 3", "\"degree\": 2")
        .replace("\"C1\"", "\"G1\"");
    expect_error(
        &scene(&d2),
        None,
        &[at, "field 'degree'", "G1 needs degree ≥ 3"],
    );
    let d4 = BS
        .replace("\"degree\": 3", "\"degree\": 4")
        .replace("\"C1\"", "\"C2\"");
    expect_error(&scene(&d4), None, &[at, "field 'degree'", "degree 4"]);
}

#[test]
fn spline_edit_fields() {
    let both = scene(&format!("{CR}, {BS}"));
    let e = |edits: &str, parts: &[&str]| expect_error(&both, Some(edits), parts);
    e(
        r#"[{"object": "cr", "point": 4, "delta": [1, 0, 0]}]"#,
        &[
            "edit 0 (object 'cr')",
            "field 'point'",
            "index 4 out of range",
        ],
    );
    e(
        r#"[{"object": "bs", "point": 7, "delta": [1, 0, 0]}]"#,
        &[
            "edit 0 (object 'bs')",
            "field 'point'",
            "Bézier point index 7",
        ],
    );
    e(
        r#"[{"object": "cr", "point": 1, "weight": 2}]"#,
        &["object 'cr'", "field 'weight'", "no weights"],
    );
    e(
        r#"[{"object": "bs", "point": 1, "weight": 2}]"#,
        &["object 'bs'", "field 'weight'", "no weights"],
    );
    e(
        r#"[{"object": "bs", "point": 1, "delta": [1, "x", 0]}]"#,
        &["object 'bs'", "field 'delta'"],
    );
    e(
        r#"[{"object": "cr", "insert_knot": 0.5}]"#,
        &["object 'cr'", "field 'insert_knot'", "to_bspline"],
    );
    e(
        r#"[{"object": "bs", "elevate_degree": 1}]"#,
        &["object 'bs'", "field 'elevate_degree'"],
    );
    e(
        r#"[{"object": "bs", "to_bspline": false}]"#,
        &["object 'bs'", "field 'to_bspline'", "expected true"],
    );
    e(
        r#"[{"object": "bs", "to_bspline": true, "point": 1}]"#,
        &["object 'bs'", "unknown field 'point'"],
    );
    e(
        r#"[{"object": "bs", "to_bspline": true}, {"object": "bs", "point": 30, "delta": [0, 0, 1]}]"#,
        &[
            "edit 1 (object 'bs')",
            "field 'point'",
            "index 30 out of range",
        ],
    );
    let curve = scene(
        r#"{"name": "c", "type": "bezier_curve", "points": [[0,0,0],[1,1,0]], "samples": 5}"#,
    );
    expect_error(
        &curve,
        Some(r#"[{"object": "c", "to_bspline": true}]"#),
        &[
            "object 'c'",
            "field 'to_bspline'",
            "only catmull_rom and bezier_spline",
        ],
    );
    // A G1 move that puts a handle onto its junction.
    let g1 = with(
        BS,
        "points",
        Some("[[0,0,0],[1,1,0],[2,1,0],[3,0,0],[3.5,-0.5,0],[6,0,0],[7,1,0]]"),
    )
    .replace("\"C1\"", "\"G1\"");
    expect_error(
        &g1,
        Some(r#"[{"object": "bs", "point": 4, "delta": [-0.5, 0.5, 0]}]"#),
        &["object 'bs'", "field 'delta'", "onto junction 1"],
    );
    // Centripetal knots: a move onto the neighbour.
    let cr = with(CR, "parametrization", Some("\"centripetal\""));
    expect_error(
        &cr,
        Some(r#"[{"object": "cr", "point": 1, "delta": [1, -1, 0]}]"#),
        &["object 'cr'", "field 'points'", "coincide"],
    );
}

#[test]
fn conversion_through_sample_edits_keeps_the_samples() {
    let both = scene(&format!("{CR}, {BS}"));
    let (ok, before, err) = sample(&both, None);
    assert!(ok, "{err}");
    let (ok, after, err) = sample(
        &both,
        Some(r#"[{"object": "cr", "to_bspline": true}, {"object": "bs", "to_bspline": true}]"#),
    );
    assert!(ok, "{err}");
    let strip = |s: &str| {
        s.replace("\"catmull_rom\"", "\"bspline_curve\"")
            .replace("\"bezier_spline\"", "\"bspline_curve\"")
    };
    assert_eq!(strip(&before), after);
}
