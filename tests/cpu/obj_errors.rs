//! Bad OBJ input: a table of malformed files, each rejected with one line naming its line
//! number (through the library and through `prespline convert`/`render`, which must exit
//! non-zero and write nothing); a fuzz-style test mutating valid files with fixed seeds, where
//! every outcome must be a usable scene or one such line, never a panic.

use crate::common;

use common::Rng;
use prespline::cli::samples::SampleOverride;
use prespline::formats::obj::{parse_obj, parse_obj_bytes, scene_to_obj};
use prespline::model::Model;
use prespline::model::SampledObject;
use prespline::sampling::SampleMode;
use std::path::{Path, PathBuf};
use std::process::Command;

/// A valid cubic B-spline curve and bicubic Bézier patch; the table edits one thing each.
const GOOD: &str = "\
v 0 0 0
v 1 1 0
v 2 -1 0
v 3 0 0
cstype bspline
deg 3
curv 0 1 1 2 3 4
parm u 0 0 0 0 1 1 1 1
end
";

/// (what, file, line of the error, words the message must contain)
const TABLE: &[(&str, &str, usize, &str)] = &[
    (
        "missing end at the end of the file",
        "v 0 0 0\nv 1 0 0\ncstype bspline\ndeg 1\ncurv 0 1 1 2\nparm u 0 0 1 1\n",
        5,
        "curv has no end before the end of the file",
    ),
    (
        "missing end before the next element",
        "v 0 0 0\nv 1 0 0\ncstype bspline\ndeg 1\ncurv 0 1 1 2\nparm u 0 0 1 1\ncurv 0 1 1 2\nparm u 0 0 1 1\nend\n",
        5,
        "curv has no end: line 7 starts 'curv'",
    ),
    (
        "missing end before a vertex",
        "v 0 0 0\nv 1 0 0\ncstype bezier\ndeg 1\ncurv 0 1 1 2\nparm u 0 1\nv 2 0 0\n",
        5,
        "line 7 starts 'v'",
    ),
    (
        "end without an element",
        "v 0 0 0\nend\n",
        2,
        "end without a curv",
    ),
    (
        "too few knots",
        "v 0 0 0\nv 1 1 0\nv 2 -1 0\nv 3 0 0\ncstype bspline\ndeg 3\ncurv 0 1 1 2 3 4\nparm u 0 0 0 0 1 1 1\nend\n",
        8,
        "parm u has 7 knots; a degree-3 B-spline with 4 control vertices needs 8",
    ),
    (
        "too many knots",
        "v 0 0 0\nv 1 1 0\nv 2 -1 0\nv 3 0 0\ncstype bspline\ndeg 3\ncurv 0 1 1 2 3 4\n\nparm u 0 0 0 0 0.5 1 1 1 1\nend\n",
        9,
        "has 9 knots",
    ),
    (
        "surface knots and vertices do not fit",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\ncstype bspline\ndeg 1 1\nsurf 0 1 0 1 1 2 3\nparm u 0 0 1 1\nparm v 0 0 1 1\nend\n",
        6,
        "surf lists 3 control vertices, but parm u and parm v with deg 1 1 describe 2 × 2 = 4",
    ),
    (
        "surface knot vector too short for its degree",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\ncstype bspline\ndeg 2 1\nsurf 0 1 0 1 1 2 3 4\nparm u 0 0 1 1\nparm v 0 0 1 1\nend\n",
        8,
        "parm u has 4 knots; degree 2 needs at least 6",
    ),
    (
        "Bézier breakpoints do not fit the segments",
        "v 0 0 0\nv 1 1 0\nv 2 0 0\nv 3 1 0\nv 4 0 0\ncstype bezier\ndeg 2\ncurv 0 1 1 2 3 4 5\nparm u 0 1\nend\n",
        9,
        "2 Bézier segment(s) need 3 breakpoints",
    ),
    (
        "vertex number past the last vertex",
        "v 0 0 0\nv 1 0 0\ncstype bezier\ndeg 1\ncurv 0 1 1 3\nparm u 0 1\nend\n",
        5,
        "v 3 does not exist: the file has 2 v statement(s)",
    ),
    (
        "vertex number 0",
        "v 0 0 0\nv 1 0 0\ncstype bezier\ndeg 1\ncurv 0 1 0 1\nparm u 0 1\nend\n",
        5,
        "v number 0 is invalid",
    ),
    (
        "relative vertex number before the first vertex",
        "v 0 0 0\nv 1 0 0\ncstype bezier\ndeg 1\ncurv 0 1 -1 -3\nparm u 0 1\nend\n",
        5,
        "relative v number -3 reaches before the first one (2 defined so far)",
    ),
    (
        "relative vertex number on a continuation line",
        "v 0 0 0\nv 1 0 0\ncstype bezier\ndeg 1\ncurv 0 1 \\\n -2 \\\n -9\nparm u 0 1\nend\n",
        7,
        "relative v number -9",
    ),
    (
        "texture vertex number out of range",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\ncstype bezier\ndeg 1 1\nsurf 0 1 0 1 1/1 2/2 3 4\nparm u 0 1\nparm v 0 1\nend\n",
        8,
        "vt 2 does not exist",
    ),
    (
        "vertex number that is not a number",
        "v 0 0 0\nv 1 0 0\ncstype bezier\ndeg 1\ncurv 0 1 1 two\nparm u 0 1\nend\n",
        5,
        "'two' is not a v number",
    ),
    (
        "texture reference on a curve",
        "v 0 0 0\nv 1 0 0\ncstype bezier\ndeg 1\ncurv 0 1 1/1 2\nparm u 0 1\nend\n",
        5,
        "must be a plain vertex number",
    ),
    (
        "NaN coordinate",
        "v 0 0 0\nv 1 NaN 0\ncstype bezier\ndeg 1\ncurv 0 1 1 2\nparm u 0 1\nend\n",
        2,
        "v: coordinate 2 is 'NaN', not a finite number",
    ),
    (
        "NaN knot",
        "v 0 0 0\nv 1 0 0\ncstype bspline\ndeg 1\ncurv 0 1 1 2\nparm u 0 nan 1 1\nend\n",
        6,
        "parm u: value 2 is 'nan'",
    ),
    (
        "overflowing range",
        "v 0 0 0\nv 1 0 0\ncstype bezier\ndeg 1\ncurv 0 1e999 1 2\nparm u 0 1\nend\n",
        5,
        "curv: range end is '1e999', not a finite number",
    ),
    ("infinite weight", "v 0 0 0 inf\n", 1, "v: weight is 'inf'"),
    (
        "zero weight on a rational curve",
        "v 0 0 0 1\nv 1 0 0 0\ncstype rat bezier\ndeg 1\ncurv 0 1 1 2\nparm u 0 1\nend\n",
        2,
        "v has weight 0, but the rational curv at line 5 needs positive weights",
    ),
    (
        "too few vertex coordinates",
        "v 0 0\n",
        1,
        "v takes x y z and an optional weight w, found 2 values",
    ),
    (
        "Bézier degree does not match the control vertices",
        "v 0 0 0\nv 1 1 0\nv 2 -1 0\nv 3 0 0\ncstype bezier\ndeg 2\ncurv 0 1 1 2 3 4\nparm u 0 1\nend\n",
        7,
        "curv lists 4 control vertices; a Bézier curve of degree 2 needs k·2 + 1",
    ),
    (
        "B-spline degree too high for its control vertices",
        "v 0 0 0\nv 1 1 0\nv 2 -1 0\ncstype bspline\ndeg 3\ncurv 0 1 1 2 3\nparm u 0 0 0 0 1 1 1\nend\n",
        6,
        "curv lists 3 control vertices; degree 3 needs at least 4",
    ),
    (
        "surface with one degree",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\ncstype bezier\ndeg 1\nsurf 0 1 0 1 1 2 3 4\nparm u 0 1\nparm v 0 1\nend\n",
        7,
        "surf needs two degrees, but the deg statement at line 6 gives one",
    ),
    (
        "degree 0",
        "deg 0\n",
        1,
        "degree 0 is outside the supported range 1..=64",
    ),
    ("degree 65", "deg 3 65\n", 1, "degree 65 is outside"),
    (
        "decreasing knots",
        "v 0 0 0\nv 1 0 0\ncstype bspline\ndeg 1\ncurv 0 1 1 2\nparm u 0 1 0 1\nend\n",
        6,
        "value 3 (0) follows value 2 (1): knots must be non-decreasing",
    ),
    (
        "knot repeated more than degree + 1 times",
        "v 0 0 0\nv 1 0 0\nv 2 0 0\ncstype bspline\ndeg 1\ncurv 0 1 1 2 3\nparm u 0 0 0 1 1\nend\n",
        7,
        "knot 0 appears 3 times, more than degree + 1 = 2",
    ),
    (
        "empty knot domain",
        "v 0 0 0\nv 1 0 0\ncstype bspline\ndeg 1\ncurv 0 0 1 2\nparm u 0 1 1 2\nend\n",
        6,
        "empty domain",
    ),
    (
        "range outside the domain",
        "v 0 0 0\nv 1 0 0\ncstype bezier\ndeg 1\ncurv 2 3 1 2\nparm u 0 1\nend\n",
        5,
        "curv range [2, 3] lies outside the domain [0, 1] of parm u (line 6)",
    ),
    (
        "range touching the domain at its end",
        "v 0 0 0\nv 1 0 0\ncstype bezier\ndeg 1\ncurv 1 2 1 2\nparm u 0 1\nend\n",
        5,
        "curv range [1, 2] lies outside the domain [0, 1]",
    ),
    (
        "reversed range",
        "v 0 0 0\nv 1 0 0\ncstype bezier\ndeg 1\ncurv 1 0 1 2\nparm u 0 1\nend\n",
        5,
        "curv range [1, 0] is empty or reversed",
    ),
    (
        "no cstype",
        "v 0 0 0\nv 1 0 0\ndeg 1\ncurv 0 1 1 2\nparm u 0 1\nend\n",
        4,
        "curv without a cstype statement before it",
    ),
    (
        "no deg",
        "v 0 0 0\nv 1 0 0\ncstype bezier\ncurv 0 1 1 2\nparm u 0 1\nend\n",
        4,
        "curv without a deg statement before it",
    ),
    (
        "no parm",
        "v 0 0 0\nv 1 0 0\ncstype bezier\ndeg 1\ncurv 0 1 1 2\nend\n",
        5,
        "curv has no parm u before its end",
    ),
    (
        "second parm u",
        "v 0 0 0\nv 1 0 0\ncstype bezier\ndeg 1\ncurv 0 1 1 2\nparm u 0 1\nparm u 0 1\nend\n",
        7,
        "second parm u for the curv at line 5 (the first is at line 6)",
    ),
    (
        "parm v on a curve",
        "v 0 0 0\nv 1 0 0\ncstype bezier\ndeg 1\ncurv 0 1 1 2\nparm v 0 1\nend\n",
        6,
        "parm v: the curv at line 5 has only a u direction",
    ),
    (
        "parm outside an element",
        "parm u 0 1\n",
        1,
        "parm outside a curv or surf",
    ),
    (
        "unknown cstype",
        "cstype nurbs\n",
        1,
        "cstype: unknown type 'nurbs'",
    ),
    (
        "bad sample count comment",
        "# prespline samples 1\n",
        1,
        "# prespline samples takes one count",
    ),
    (
        "too many samples",
        "# prespline samples 100000 100000\n",
        1,
        "exceed the limit",
    ),
    (
        "nothing to read but polygons",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        4,
        "no free-form curve or surface",
    ),
    (
        "only an unsupported type",
        "v 0 0 0\nv 1 0 0\ncstype cardinal\ndeg 3\ncurv 0 1 1 2\nparm u 0 1\nend\n",
        5,
        "cstype cardinal is not supported",
    ),
];

#[test]
fn the_valid_base_file_reads() {
    let s = parse_obj(GOOD).unwrap();
    assert_eq!(s.scene.objects.len(), 1);
    assert!(s.warnings.is_empty());
}

#[test]
fn malformed_files_fail_with_one_line_naming_the_line() {
    for &(what, text, line, words) in TABLE {
        let e = parse_obj(text).expect_err(what);
        assert_eq!(e.line, line, "{what}: {e}");
        assert!(e.message.contains(words), "{what}: {e}");
        assert!(!e.message.contains('\n'), "{what}: {e}");
    }
}

#[test]
fn text_that_is_not_utf8_names_its_line() {
    let e = parse_obj_bytes(b"v 0 0 0\nv 1 0 0\no caf\xe9\n").unwrap_err();
    assert_eq!(e.line, 3, "{e}");
    assert!(e.message.contains("not valid UTF-8"), "{e}");
}

fn prespline() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_prespline"));
    let icd = prespline::gpu::LAVAPIPE_ICD;
    c.env("VK_DRIVER_FILES", icd).env("VK_ICD_FILENAMES", icd);
    c
}

fn temp_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("prespline-obj-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The one stderr line of a failed command, checked for `error: FILE:LINE: `.
fn one_error_line(out: &std::process::Output, file: &Path, line: usize) -> String {
    assert!(!out.status.success());
    assert!(out.stdout.is_empty());
    let err = String::from_utf8(out.stderr.clone()).unwrap();
    assert_eq!(err.lines().count(), 1, "{err}");
    let prefix = format!("error: {}:{line}: ", file.display());
    assert!(err.starts_with(&prefix), "expected {prefix}…, got {err}");
    err
}

#[test]
fn commands_report_malformed_files_in_one_line_and_write_nothing() {
    let dir = temp_dir("errors");
    for (k, &(what, text, line, words)) in TABLE.iter().enumerate() {
        let bad = dir.join(format!("bad{k}.obj"));
        std::fs::write(&bad, text).unwrap();
        let out_json = dir.join(format!("out{k}.json"));
        let out = prespline()
            .arg("convert")
            .arg(&bad)
            .arg(&out_json)
            .output()
            .unwrap();
        let err = one_error_line(&out, &bad, line);
        assert!(err.contains(words), "{what}: {err}");
        assert!(!out_json.exists(), "{what}: nothing may be written");
        if k % 8 == 0 {
            let png = dir.join(format!("out{k}.png"));
            let out = prespline()
                .arg("render")
                .arg(&bad)
                .arg("--out")
                .arg(&png)
                .output()
                .unwrap();
            one_error_line(&out, &bad, line);
            assert!(!png.exists());
        }
    }
}

// ---- fuzz -------------------------------------------------------------------------------

fn example(name: &str) -> String {
    std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("examples")
            .join(name),
    )
    .unwrap()
}

/// Bases for mutation: the vase (rational surface, curves, relative numbers, continuations),
/// three teapot patches, and a file with multi-segment Bézier, a cut range, references and
/// kept statements (`vp`, `curv2`, `sp`, `trim`, `con`).
fn bases() -> Vec<String> {
    let teapot = example("teapot.obj");
    let three: String = teapot
        .split("\no ")
        .take(4)
        .collect::<Vec<_>>()
        .join("\no ");
    vec![
        example("vase.obj"),
        three,
        format!(
            "{GOOD}vt 0 0\nvn 0 0 1\ng pair\ncstype rat bezier\ndeg 1 1\nsurf 0 1 0 1 1/1 2/1/1 3//1 4\nparm u 0 1\nparm v 0 1\nend\n\
             vp 0 0\nvp 1 0\nvp 1 1\ncstype bspline\ndeg 1\ncurv2 -3 -2 -1 -3\nparm u 0 0 1 2 3 3\nsp 1\nend\n\
             cstype bezier\ndeg 1\ncurv 0.5 2 -4 -3 -2\nparm u 0 1 2\ntrim 0 1 1\nend\nf 1 2 3\n\
             con 1 0 1 1 1 1 0 1\n"
        ),
    ]
}

const JUNK: &[&str] = &[
    "0",
    "1",
    "-1",
    "2",
    "-2",
    "999",
    "-999",
    "99999999999999999999",
    "nan",
    "inf",
    "-inf",
    "1e308",
    "1e999",
    "-0",
    "5e-324",
    "0.5",
    "\\",
    "#",
    "/",
    "1/2/3",
    "1//1",
    "end",
    "rat",
    "bezier",
    "bspline",
    "cardinal",
    "u",
    "v",
    "x",
    "",
    "curv",
    "surf",
    "parm",
];

const LINES: &[&str] = &[
    "end",
    "parm u 0 1",
    "parm v 0 0 1 1",
    "deg 0",
    "deg 2 2",
    "deg 1",
    "cstype cardinal",
    "cstype rat bspline",
    "surf 0 1 0 1 1 2 3 4",
    "curv 0 1 -1 -2",
    "curv2 1 2",
    "# prespline samples 3",
    "# prespline samples 3 4",
    "# prespline color 1 0 0",
    "trim 0 1 1",
    "hole 0 1 -1",
    "sp 1 -1",
    "con 1 0 1 1 1 0 1 1",
    "stech cparma 1 2",
    "f 1 2 3",
    "o x",
    "g",
    "v 1 2 3 0",
    "vp 0.5",
    "vp 0.5 0.5 2",
    "\\",
];

fn mutate(text: &str, rng: &mut Rng) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    for _ in 0..rng.range(1, 5) {
        if lines.is_empty() {
            lines.push(String::new());
        }
        let i = rng.range(0, lines.len());
        match rng.range(0, 8) {
            0 => {
                lines.remove(i);
            }
            1 => {
                let l = lines[i].clone();
                lines.insert(rng.range(0, lines.len() + 1), l);
            }
            2 => {
                let j = rng.range(0, lines.len());
                lines.swap(i, j);
            }
            3 | 4 => {
                let mut words: Vec<String> =
                    lines[i].split_whitespace().map(str::to_string).collect();
                if !words.is_empty() {
                    let k = rng.range(0, words.len());
                    words[k] = JUNK[rng.range(0, JUNK.len())].to_string();
                }
                lines[i] = words.join(" ");
            }
            5 => lines.insert(i, LINES[rng.range(0, LINES.len())].to_string()),
            6 => lines[i].push_str(" \\"),
            _ => lines.truncate(i),
        }
    }
    lines.join("\n")
}

/// Every mutation of every base either reads into objects that sample, write and read back
/// identically, or fails with one line at a line number inside the file. Fixed seeds.
#[test]
fn mutated_files_never_panic() {
    let bases = bases();
    let (mut ok, mut err) = (0, 0);
    for seed in 1..=3000u64 {
        let mut rng = Rng::new(seed);
        let base = &bases[rng.range(0, bases.len())];
        let text = mutate(base, &mut rng);
        let lines = text.lines().count().max(1);
        match parse_obj(&text) {
            Ok(import) => {
                ok += 1;
                for o in &import.scene.objects {
                    assert!(matches!(o.model, Model::Curve(_) | Model::Surface(_)));
                }
                // Every accepted object samples (with few samples: this is about validity).
                let mut small = import.scene.clone();
                SampleOverride {
                    curve: Some(3),
                    surface: Some([3, 3]),
                }
                .apply(&mut small)
                .unwrap();
                for o in &small.objects {
                    drop(SampledObject::new(&o.model, SampleMode::Render));
                }
                let again =
                    scene_to_obj(&import.scene).unwrap_or_else(|e| panic!("seed {seed}: {e}"));
                let back =
                    parse_obj(&again).unwrap_or_else(|e| panic!("seed {seed}: {e}\n{again}"));
                assert_eq!(back.scene, import.scene, "seed {seed}");
            }
            Err(e) => {
                err += 1;
                assert!(!e.message.contains('\n'), "seed {seed}: {e}");
                assert!(
                    (1..=lines + 1).contains(&e.line),
                    "seed {seed}: line {} of {lines}: {e}",
                    e.line
                );
            }
        }
    }
    eprintln!("3000 mutations: {ok} read, {err} rejected");
    // Both outcomes must be exercised, or the mutations are too weak or too strong to test much.
    assert!(ok > 300 && err > 300, "{ok} read, {err} rejected");
}

/// Random bytes spliced into a file: never a panic, UTF-8 errors included.
#[test]
fn mutated_bytes_never_panic() {
    let base = example("vase.obj").into_bytes();
    for seed in 1..=1000u64 {
        let mut rng = Rng::new(seed);
        let mut bytes = base.clone();
        for _ in 0..rng.range(1, 6) {
            let i = rng.range(0, bytes.len());
            bytes[i] = (rng.next_u64() & 0xff) as u8;
        }
        if let Err(e) = parse_obj_bytes(&bytes) {
            assert!(!e.message.contains('\n'), "seed {seed}: {e}");
            assert!(e.line >= 1, "seed {seed}: {e}");
        }
    }
}
