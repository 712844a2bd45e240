//! What an OBJ file holds that prespline does not use — `trim`, `hole`, `scrv`, `sp`, `curv2`,
//! `vp`, `con`, `ctech`, `stech` — survives every path: OBJ → OBJ and OBJ → JSON → OBJ through
//! `prespline convert`, edits through the scene edit list and through the viewer's document,
//! the JSON the autosave writes. Compared by an independent reader written here, which resolves
//! every statement's numbers to the values they name (parameter vertices, the `curv2` elements
//! with their own vertices, the surfaces a `con` joins), so renumbering is checked, not trusted.

use prespline::editor::{Editor, EditorOptions};
use prespline::formats::json::scene_to_json;
use prespline::formats::obj::{parse_obj, scene_to_obj, write_obj};
use prespline::formats::parse_scene;
use prespline::model::Model;
use prespline::sampling::SampleMode;
use prespline::sampling::budget::{MemoryBudget, Uses};
use prespline::scene::Scene;
use prespline::scene::edit::{apply_all, parse_edits};
use std::path::{Path, PathBuf};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn read(name: &str) -> String {
    std::fs::read_to_string(data(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The spec's "trimming with special points" and "trimming with a special curve" examples
/// (appendix B1), and a file of ours with `hole`, `con`, `ctech`/`stech`, a shared and an
/// unnamed `curv2`.
const FILES: [&str; 3] = [
    "obj_spec_special_points.obj",
    "obj_spec_special_curve.obj",
    "obj_kept_statements.obj",
];

// ---- an independent reader of the kept statements ----------------------------------------

/// A `curv2` with everything it names resolved to values.
#[derive(Debug, Clone, PartialEq)]
struct Curve2 {
    cstype: String,
    degree: usize,
    points: Vec<Vec<f64>>,
    parm: Vec<f64>,
    body: Vec<Stmt>,
    technique: Option<(String, Vec<f64>)>,
}

/// A body statement, resolved.
#[derive(Debug, Clone, PartialEq)]
enum Stmt {
    /// `trim`, `hole` or `scrv` with its (u0, u1, curve) triples.
    Loop(String, Vec<(f64, f64, Curve2)>),
    Sp(Vec<Vec<f64>>),
}

/// A `curv` or `surf` element's kept data.
#[derive(Debug, Clone, PartialEq)]
struct Element {
    keyword: String,
    technique: Option<(String, Vec<f64>)>,
    body: Vec<Stmt>,
}

/// A file's kept data: per element (in file order), the `con` statements with the element
/// each side names, and every distinct `curv2`.
#[derive(Debug, PartialEq)]
struct Resolved {
    elements: Vec<Element>,
    cons: Vec<[(usize, f64, f64, Curve2); 2]>,
    curves2: Vec<String>,
}

/// Statements with comments removed and `\` continuations joined.
fn statements(text: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let mut pending: Vec<String> = Vec::new();
    for raw in text.lines() {
        let code = raw.split('#').next().unwrap_or("").trim_end();
        let (code, continued) = match code.strip_suffix('\\') {
            Some(c) => (c, true),
            None => (code, false),
        };
        pending.extend(code.split_whitespace().map(String::from));
        if !continued && !pending.is_empty() {
            out.push(std::mem::take(&mut pending));
        }
    }
    out
}

/// An OBJ number made 0-based: 1 is the first, −1 the latest of `count` so far.
fn absolute(word: &str, count: usize) -> usize {
    let n: i64 = word.parse().unwrap();
    if n > 0 {
        n as usize - 1
    } else {
        count - n.unsigned_abs() as usize
    }
}

fn float(word: &str) -> f64 {
    word.parse().unwrap()
}

/// A body statement with file-wide numbers (0-based).
#[derive(Debug, Clone)]
enum RawStmt {
    Loop(String, Vec<(f64, f64, usize)>),
    Sp(Vec<usize>),
}

#[derive(Debug, Clone)]
struct RawCurve2 {
    cstype: String,
    degree: usize,
    points: Vec<usize>,
    parm: Vec<f64>,
    body: Vec<RawStmt>,
    technique: Option<(String, Vec<f64>)>,
}

fn resolve(text: &str) -> Resolved {
    let mut vp: Vec<Vec<f64>> = Vec::new();
    let mut curves2: Vec<RawCurve2> = Vec::new();
    let mut elements: Vec<(Element, Vec<RawStmt>)> = Vec::new();
    let mut surfaces: Vec<usize> = Vec::new();
    let mut raw_cons = Vec::new();
    let (mut cstype, mut degree) = (String::new(), 0);
    let (mut ctech, mut stech) = (None, None);
    // The element being read: (keyword, curv2 under construction, body).
    let mut open: Option<(String, Option<RawCurve2>, Vec<RawStmt>)> = None;
    for s in statements(text) {
        let args = &s[1..];
        match s[0].as_str() {
            "vp" => vp.push(args.iter().map(|w| float(w)).collect()),
            "cstype" => cstype = args.join(" "),
            "deg" => degree = args[0].parse().unwrap(),
            "ctech" | "stech" => {
                let t = Some((
                    args[0].clone(),
                    args[1..].iter().map(|w| float(w)).collect(),
                ));
                if s[0] == "ctech" {
                    ctech = t;
                } else {
                    stech = t;
                }
            }
            "curv2" => {
                let c = RawCurve2 {
                    cstype: cstype.clone(),
                    degree,
                    points: args.iter().map(|w| absolute(w, vp.len())).collect(),
                    parm: Vec::new(),
                    body: Vec::new(),
                    technique: ctech.clone(),
                };
                open = Some(("curv2".into(), Some(c), Vec::new()));
            }
            k @ ("curv" | "surf") => {
                if k == "surf" {
                    surfaces.push(elements.len());
                }
                open = Some((k.to_string(), None, Vec::new()));
            }
            "parm" => {
                if let Some((_, Some(c), _)) = &mut open {
                    c.parm = args[1..].iter().map(|w| float(w)).collect();
                }
            }
            k @ ("trim" | "hole" | "scrv") => {
                let triples = args
                    .chunks(3)
                    .map(|t| (float(&t[0]), float(&t[1]), absolute(&t[2], curves2.len())))
                    .collect();
                open.as_mut()
                    .unwrap()
                    .2
                    .push(RawStmt::Loop(k.into(), triples));
            }
            "sp" => {
                let points = args.iter().map(|w| absolute(w, vp.len())).collect();
                open.as_mut().unwrap().2.push(RawStmt::Sp(points));
            }
            "end" => {
                let (keyword, curve, body) = open.take().unwrap();
                match curve {
                    Some(mut c) => {
                        c.body = body;
                        curves2.push(c);
                    }
                    None => {
                        let technique = if keyword == "surf" {
                            stech.clone()
                        } else {
                            ctech.clone()
                        };
                        let e = Element {
                            keyword,
                            technique,
                            body: Vec::new(),
                        };
                        elements.push((e, body));
                    }
                }
            }
            "con" => {
                let side = |k: usize| {
                    (
                        absolute(&args[4 * k], surfaces.len()),
                        float(&args[4 * k + 1]),
                        float(&args[4 * k + 2]),
                        absolute(&args[4 * k + 3], curves2.len()),
                    )
                };
                raw_cons.push([side(0), side(1)]);
            }
            _ => {}
        }
    }
    let curve = |k: usize| value_of(&curves2[k], &curves2, &vp);
    let mut distinct: Vec<String> = (0..curves2.len())
        .map(|k| format!("{:?}", curve(k)))
        .collect();
    distinct.sort();
    distinct.dedup();
    Resolved {
        elements: elements
            .into_iter()
            .map(|(mut e, body)| {
                e.body = body.iter().map(|b| stmt(b, &curves2, &vp)).collect();
                e
            })
            .collect(),
        cons: raw_cons
            .into_iter()
            .map(|sides| sides.map(|(s, q0, q1, c)| (surfaces[s], q0, q1, curve(c))))
            .collect(),
        curves2: distinct,
    }
}

fn value_of(c: &RawCurve2, all: &[RawCurve2], vp: &[Vec<f64>]) -> Curve2 {
    Curve2 {
        cstype: c.cstype.clone(),
        degree: c.degree,
        points: c.points.iter().map(|&p| vp[p].clone()).collect(),
        parm: c.parm.clone(),
        body: c.body.iter().map(|b| stmt(b, all, vp)).collect(),
        technique: c.technique.clone(),
    }
}

fn stmt(b: &RawStmt, all: &[RawCurve2], vp: &[Vec<f64>]) -> Stmt {
    match b {
        RawStmt::Loop(k, triples) => Stmt::Loop(
            k.clone(),
            triples
                .iter()
                .map(|&(u0, u1, c)| (u0, u1, value_of(&all[c], all, vp)))
                .collect(),
        ),
        RawStmt::Sp(points) => Stmt::Sp(points.iter().map(|&p| vp[p].clone()).collect()),
    }
}

/// The reader sees what the files hold, and tells apart what differs (negative controls: a
/// comparison that cannot fail proves nothing).
#[test]
fn the_independent_reader_resolves_and_tells_differences_apart() {
    let text = read("obj_kept_statements.obj");
    let r = resolve(&text);
    assert_eq!(r.elements.len(), 3);
    let left = &r.elements[0];
    assert_eq!(left.technique, Some(("cparma".into(), vec![2.0, 2.0])));
    let Stmt::Loop(hole, triples) = &left.body[1] else {
        panic!("{:?}", left.body)
    };
    assert_eq!(hole, "hole");
    // `hole 0 3 -4` with five curv2 before it names the second: the triangle.
    assert_eq!(triples[0].2.points[2], vec![0.5, 0.75]);
    assert_eq!(triples[0].2.technique, Some(("cparm".into(), vec![4.0])));
    assert_eq!(left.body[3], Stmt::Sp(vec![vec![0.5, 0.75]]));
    assert_eq!(r.elements[2].body, [Stmt::Sp(vec![vec![0.25]])]);
    assert_eq!(r.cons.len(), 1);
    assert_eq!((r.cons[0][0].0, r.cons[0][1].0), (0, 1));
    assert_eq!(r.cons[0][1].3.points, [vec![0.0, 0.0], vec![0.0, 1.0]]);
    assert_eq!(r.curves2.len(), 5);

    for (what, from, to) in [
        ("a hole removed", "hole 0 3 -4\n", ""),
        ("a vp value", "vp 0.5 0.75\n", "vp 0.5 0.76\n"),
        ("the other curve", "scrv 0 1 3\n", "scrv 0 1 4\n"),
        ("a technique", "ctech curv 0.01 5\n", "ctech curv 0.01 6\n"),
        (
            "a con side",
            "con 1 0 1 3 2 0 1 4\n",
            "con 1 0 1 3 1 0 1 4\n",
        ),
        ("an unnamed curv2", "curv2 -1 -8\n", "curv2 -1 -7\n"),
        ("the whole kept data", "trim 0 4 1\nend", "end"),
    ] {
        assert!(text.contains(from), "{what}");
        assert_ne!(resolve(&text.replacen(from, to, 1)), r, "{what}");
    }
}

// ---- round trips -------------------------------------------------------------------------

fn convert(from: &Path, to: &Path) -> String {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_prespline"))
        .arg("convert")
        .args([from, to])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{err}");
    err
}

fn temp_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("prespline-kept-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn convert_obj_to_obj_and_through_json_keeps_every_statement() {
    let dir = temp_dir("convert");
    for name in FILES {
        let original = resolve(&read(name));
        assert!(
            original.elements.iter().any(|e| !e.body.is_empty()),
            "{name}"
        );
        let (obj, json, again) = (
            dir.join("direct.obj"),
            dir.join("scene.json"),
            dir.join("again.obj"),
        );
        for (a, b) in [(&data(name), &obj), (&data(name), &json), (&json, &again)] {
            let err = convert(a, b);
            assert!(!err.contains("written without"), "{name}: {err}");
        }
        let direct = std::fs::read_to_string(&obj).unwrap();
        assert_eq!(resolve(&direct), original, "{name}:\n{direct}");
        let through_json = std::fs::read_to_string(&again).unwrap();
        assert_eq!(through_json, direct, "{name}");
        // prespline's own form is a fixed point: read and written again, byte for byte.
        assert_eq!(
            scene_to_obj(&parse_obj(&direct).unwrap().scene).unwrap(),
            direct
        );
    }
}

#[test]
fn the_json_scene_keeps_the_data_exactly() {
    for name in FILES {
        let scene = parse_obj(&read(name)).unwrap().scene;
        assert!(scene.objects.iter().any(|o| !o.kept.is_empty()), "{name}");
        let json = scene_to_json(&scene);
        assert!(json.contains("\"obj\": {"), "{name}");
        let back = parse_scene(&json).unwrap_or_else(|e| panic!("{name}: {e}\n{json}"));
        assert_eq!(back, scene, "{name}");
        assert_eq!(scene_to_json(&back), json, "{name}");
    }
}

/// Edits through the scene edit list and through the viewer's document (point moves, knot
/// insertion, degree elevation) keep the data, and so do the JSON autosave and Ctrl+S.
#[test]
fn edits_keep_the_data() {
    let text = read("obj_kept_statements.obj");
    let original = resolve(&text);
    let scene = parse_obj(&text).unwrap().scene;
    let edits = parse_edits(
        r#"[{"object": "left", "point": [1, 1], "delta": [0, 0, 0.5]},
            {"object": "left", "insert_knot": {"u": 0.5}},
            {"object": "right", "elevate_degree": {"u": 1, "v": 0}},
            {"object": "rim", "insert_knot": 0.25},
            {"object": "rim", "point": 1, "delta": [0.5, 0, 0]}]"#,
        &scene,
    )
    .unwrap();

    let mut edited = scene.clone();
    apply_all(&mut edited, &edits).unwrap();
    let nets: Vec<usize> = edited
        .objects
        .iter()
        .map(|o| match &o.model {
            Model::Surface(s) => s.surface().points().len(),
            Model::Curve(c) => c.curve().points().len(),
            other => panic!("{other:?}"),
        })
        .collect();
    assert_eq!(nets, [6, 6, 3], "the edits were applied");
    assert_ne!(edited.objects[0].model, scene.objects[0].model);
    assert_eq!(resolve(&scene_to_obj(&edited).unwrap()), original);

    let options = EditorOptions {
        mode: SampleMode::Render,
        uses: Uses::default(),
        budget: MemoryBudget::machine_default(),
    };
    let mut editor = Editor::new(&scene, options).unwrap();
    for e in &edits {
        editor.submit(e.clone()).unwrap();
    }
    let saved = editor.to_scene();
    assert_eq!(saved, edited);
    assert_eq!(resolve(&scene_to_obj(&saved).unwrap()), original);
    let autosaved = parse_scene(&scene_to_json(&saved)).unwrap();
    assert_eq!(resolve(&scene_to_obj(&autosaved).unwrap()), original);

    let dir = temp_dir("ctrl-s");
    let path = dir.join("saved.obj");
    assert_eq!(
        prespline::formats::save(&saved, &path).unwrap(),
        Vec::<String>::new()
    );
    assert_eq!(resolve(&std::fs::read_to_string(&path).unwrap()), original);
}

// ---- what a save still cannot write ------------------------------------------------------

#[test]
fn a_con_whose_surface_vanished_is_named_when_dropped() {
    let mut scene = parse_obj(&read("obj_kept_statements.obj")).unwrap().scene;
    let right = scene.find("right").unwrap();
    scene.objects.remove(right);
    let out = write_obj(&scene).unwrap();
    assert_eq!(out.dropped.len(), 1, "{:?}", out.dropped);
    assert!(
        out.dropped[0].starts_with("object 'left': its con to 'right' (no object 'right'"),
        "{:?}",
        out.dropped
    );
    assert!(!out.text.contains("\ncon "), "{}", out.text);
    // Everything else of the left patch is still there.
    let left = resolve(&out.text).elements[0].clone();
    assert_eq!(left, resolve(&read("obj_kept_statements.obj")).elements[0]);

    let dir = temp_dir("vanished");
    let path = dir.join("left.obj");
    assert_eq!(
        prespline::formats::save(&scene, &path).unwrap(),
        out.dropped
    );
    assert_eq!(std::fs::read_to_string(&path).unwrap(), out.text);
    // JSON keeps everything, so its save drops nothing (and the JSON reader refuses the
    // dangling name, see below).
    assert!(
        prespline::formats::save(&scene, &dir.join("left.json"))
            .unwrap()
            .is_empty()
    );
}

/// A `curv2` without a technique that is named by a surface after an element with one: OBJ
/// cannot unset a `ctech`, so the written file gives it one; `convert` says so in one line.
#[test]
fn convert_says_in_one_line_what_it_cannot_write() {
    let dir = temp_dir("one-line");
    let src = dir.join("late.obj");
    std::fs::write(
        &src,
        "vp 0 0\nvp 1 0\nvp 0 1\ncstype bspline\ndeg 1\ncurv2 1 2 3 1\nparm u 0 0 1 2 3 3\nend\n\
         ctech cparm 3\nv 0 0 0\nv 1 0 0\ncstype bezier\ndeg 1\no edge\ncurv 0 1 1 2\nparm u 0 1\nend\n\
         v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\ncstype bspline\ndeg 1 1\no patch\nsurf 0 1 0 1 3 4 5 6\n\
         parm u 0 0 1 1\nparm v 0 0 1 1\ntrim 0 3 1\nend\n",
    )
    .unwrap();
    let out = dir.join("late-out.obj");
    let err = convert(&src, &out);
    let warned: Vec<&str> = err
        .lines()
        .filter(|l| l.contains("written without"))
        .collect();
    assert_eq!(warned.len(), 1, "{err}");
    assert!(
        warned[0].starts_with(&format!(
            "warning: {}: written without: object 'patch': ",
            out.display()
        )),
        "{err}"
    );
    assert!(warned[0].contains("ctech"), "{err}");
    // The trim itself is written.
    let text = std::fs::read_to_string(&out).unwrap();
    assert_eq!(
        resolve(&text).elements[1].body,
        resolve(&std::fs::read_to_string(&src).unwrap()).elements[1]
            .body
            .iter()
            .map(|b| match b {
                Stmt::Loop(k, t) => Stmt::Loop(
                    k.clone(),
                    t.iter()
                        .map(|(a, b, c)| {
                            let mut c = c.clone();
                            c.technique = Some(("cparm".into(), vec![3.0]));
                            (*a, *b, c)
                        })
                        .collect()
                ),
                other => other.clone(),
            })
            .collect::<Vec<_>>()
    );
}

// ---- the JSON field ----------------------------------------------------------------------

/// Bad `obj` fields fail with one line naming the object and the field.
#[test]
fn bad_obj_fields_are_one_line_errors() {
    let scene = parse_obj(&read("obj_kept_statements.obj")).unwrap().scene;
    let json = scene_to_json(&scene);
    let cases = [
        (
            "unknown field",
            "\"obj\": {",
            "\"obj\": {\"trims\": [], ",
            "unknown field 'trims'",
        ),
        (
            "sp past the vertices",
            "{\"sp\": [6]}",
            "{\"sp\": [99]}",
            "parameter vertex 99 does not exist",
        ),
        (
            "curve past the curves",
            "{\"trim\": [[0.0, 4.0, 0]]}",
            "{\"trim\": [[0.0, 4.0, 9]]}",
            "curve 9 does not exist",
        ),
        (
            "unknown statement",
            "{\"sp\": [6]}",
            "{\"bend\": [6]}",
            "unknown statement 'bend'",
        ),
        (
            "unknown technique",
            "\"name\": \"cparma\"",
            "\"name\": \"cparm\"",
            "stech: unknown technique 'cparm'",
        ),
        (
            "technique value count",
            "\"values\": [0.01, 5.0]",
            "\"values\": [0.01]",
            "ctech curv takes 2 value(s), found 1",
        ),
        (
            "unknown cstype",
            "\"cstype\": \"rat bezier\"",
            "\"cstype\": \"rat nurbs\"",
            "unknown cstype 'nurbs'",
        ),
        (
            "con to a missing surface",
            "\"surface\": \"right\"",
            "\"surface\": \"middle\"",
            "no object named 'middle'",
        ),
        (
            "con to a curve",
            "\"surface\": \"right\"",
            "\"surface\": \"rim\"",
            "'rim' is not a surface",
        ),
        (
            "vp without values",
            "\"parameter_vertices\": [[0.0, 0.0], ",
            "\"parameter_vertices\": [[], ",
            "vp takes 1 to 3",
        ),
    ];
    for (what, from, to, words) in cases {
        assert!(json.contains(from), "{what}: {from} not in {json}");
        let e = parse_scene(&json.replacen(from, to, 1))
            .expect_err(what)
            .to_string();
        assert!(!e.contains('\n'), "{what}: {e}");
        assert!(e.contains("field 'obj'"), "{what}: {e}");
        assert!(e.starts_with("object '"), "{what}: {e}");
        assert!(e.contains(words), "{what}: {e}");
    }
}

#[test]
fn connections_on_a_curve_are_refused() {
    let text = r#"{"objects": [{"name": "c", "type": "bezier_curve", "points": [[0,0,0],[1,0,0]], "samples": 3,
        "obj": {"curves2": [{"cstype": "bspline", "degree": 1, "vertices": [0, 0], "parm": [0, 0, 1, 1]}],
                "parameter_vertices": [[0.5]],
                "connections": [{"curve": [0, 1, 0], "surface": "c", "surface_curve": [0, 1, 0]}]}}]}"#;
    let e = parse_scene(text).unwrap_err().to_string();
    assert!(e.contains("connections join surfaces"), "{e}");
    let ok = text.replace(
        ",\n                \"connections\": [{\"curve\": [0, 1, 0], \"surface\": \"c\", \"surface_curve\": [0, 1, 0]}]",
        "",
    );
    assert_ne!(ok, text);
    let scene: Scene = parse_scene(&ok).unwrap();
    assert_eq!(
        scene.objects[0]
            .kept
            .get::<prespline::formats::obj::kept::ObjKept>()
            .unwrap()
            .curves2
            .len(),
        1
    );
}
