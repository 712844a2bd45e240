//! Bad CAD files, made from real ones the way files go bad (cut short, a reference to an
//! entity that is not there or of the wrong type, a count no file could hold, bytes that are
//! not STEP text, binary junk, IGES columns shifted by an editor): every command says what is
//! wrong in one line naming the file, the line and the entity, exits non-zero, writes
//! nothing, and never panics.

use crate::common::Scratch;
use std::path::{Path, PathBuf};
use std::process::Command;

fn cad(name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/cad")
        .join(name);
    String::from_utf8(std::fs::read(path).unwrap()).unwrap()
}

/// `text` with the first match of `pattern` (a regex-free needle) replaced.
fn replace_once(text: &str, needle: &str, with: &str) -> String {
    assert!(text.contains(needle), "the test file holds {needle:?}");
    text.replacen(needle, with, 1)
}

/// The bad files: (name, bytes, what the one line must contain).
fn cases() -> Vec<(&'static str, Vec<u8>, Vec<&'static str>)> {
    let screw = cad("screw.step");
    let linkrods = cad("linkrods.step");
    let cylinder = cad("OCC8842_cylinder_CATIA.igs");
    let biges = cad("BIGES.igs");
    // IGES columns shifted: one character dropped from a line of the global section.
    let shifted: String = cylinder
        .split_inclusive('\n')
        .enumerate()
        .map(|(i, l)| {
            if i == 3 {
                let mut s = l.to_string();
                s.remove(70);
                s
            } else {
                l.to_string()
            }
        })
        .collect();
    // A rational B-spline surface whose first count claims a billion control points.
    let huge_iges = replace_once(
        &biges,
        "128,1,1,1,1,0,0,1,0,0,0.,0.,100.,100.,-100.,-100.,0.,0.,1.,1.,   0000007P",
        "128,999999999,1,1,1,0,0,1,0,0,0.,0.,100.,100.,-100.,-100.,0.,0., 0000007P",
    );
    let junk: Vec<u8> = (0..5000u32)
        .map(|i| (i.wrapping_mul(2_654_435_761) >> 24) as u8)
        .collect();
    vec![
        (
            "truncated.step",
            screw.as_bytes()[..40_000].to_vec(),
            vec!["line ", "unexpected end of file", "#"],
        ),
        (
            "dangling.step",
            replace_once(
                &screw,
                "ADVANCED_FACE('',(#15),#49",
                "ADVANCED_FACE('',(#15),#987654",
            )
            .into_bytes(),
            vec![
                "line 25",
                "#14 = ADVANCED_FACE",
                "#987654",
                "not in the file",
            ],
        ),
        (
            "wrong-type.step",
            replace_once(
                &screw,
                "ADVANCED_FACE('',(#15),#49",
                "ADVANCED_FACE('',(#15),#20",
            )
            .into_bytes(),
            vec!["#20 = CARTESIAN_POINT", "should be a surface"],
        ),
        (
            "huge.step",
            replace_once(
                &linkrods,
                "B_SPLINE_SURFACE_WITH_KNOTS('',3,",
                "B_SPLINE_SURFACE_WITH_KNOTS('',2000000000,",
            )
            .into_bytes(),
            vec!["B_SPLINE_SURFACE_WITH_KNOTS", "u_degree 2000000000", "#"],
        ),
        (
            "non-ascii.step",
            replace_once(&screw, "ADVANCED_FACE", "ADVANCED_FACÉ").into_bytes(),
            vec!["line 25", "0xc3", "not STEP text"],
        ),
        ("junk.step", junk.clone(), vec!["line 1", "not a STEP file"]),
        ("junk.igs", junk, vec!["line 1", "IGES"]),
        (
            "columns.igs",
            shifted.into_bytes(),
            vec!["line 4", "column", "shifted"],
        ),
        (
            "huge.igs",
            huge_iges.into_bytes(),
            vec!["D 7", "entity 128", "999999999"],
        ),
    ]
}

fn run(args: &[&std::ffi::OsStr]) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_prespline"))
        .args(args)
        .env("PRESPLINE_VALIDATION", "0")
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn bad_cad_files_give_one_line_each_in_every_command() {
    let dir = Scratch::new("cad-errors");
    for (name, bytes, wanted) in cases() {
        let path = dir.join(name);
        std::fs::write(&path, &bytes).unwrap();
        let out: PathBuf = dir.join(format!("{name}.png"));
        let obj = dir.join(format!("{name}.obj"));
        let commands: Vec<Vec<&std::ffi::OsStr>> = vec![
            vec!["info".as_ref(), path.as_os_str()],
            vec!["sample".as_ref(), path.as_os_str()],
            vec!["convert".as_ref(), path.as_os_str(), obj.as_os_str()],
            vec![
                "render".as_ref(),
                path.as_os_str(),
                "--out".as_ref(),
                out.as_os_str(),
            ],
        ];
        for args in commands {
            let (ok, err) = run(&args);
            let what = format!("{:?} on {name}", args[0]);
            assert!(!ok, "{what} succeeded");
            assert!(!err.contains("panicked"), "{what} panicked: {err}");
            assert_eq!(err.lines().count(), 1, "{what}: {err}");
            assert!(err.starts_with("error: "), "{what}: {err}");
            assert!(err.contains(name), "{what} names the file: {err}");
            for w in &wanted {
                assert!(err.contains(w), "{what}: {w:?} missing from {err}");
            }
        }
        assert!(!out.exists(), "render wrote an image of {name}");
        assert!(!obj.exists(), "convert wrote {name}.obj");
    }
}

/// A CAD file over the memory budget is refused before it is parsed, in one line.
#[test]
fn a_cad_file_over_the_budget_is_refused_before_reading() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/cad/screw.step");
    let (ok, err) = run(&[
        "info".as_ref(),
        path.as_os_str(),
        "--memory-limit".as_ref(),
        "100K".as_ref(),
    ]);
    assert!(!ok);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("screw.step") && err.contains("over the memory budget"),
        "{err}"
    );
}

/// Negative control for the line checks: a good file passes every command.
#[test]
fn a_good_cad_file_passes_the_same_commands() {
    let dir = Scratch::new("cad-good");
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/cad/xr1-tu-rod.stp");
    let obj = dir.join("x.obj");
    for args in [
        vec!["info".as_ref(), path.as_os_str()],
        vec!["convert".as_ref(), path.as_os_str(), obj.as_os_str()],
    ] {
        let (ok, err) = run(&args);
        assert!(ok, "{err}");
    }
    assert!(obj.exists());
}
