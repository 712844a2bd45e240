//! Real CAD files (tests/data/cad, written by CATIA, NX, Creo, SolidWorks, OpenCASCADE…)
//! opened as a user opens them, `prespline info FILE --json`, and held to what OpenCASCADE 8.0
//! reports for each (tests/data/cad/reference.json, from scripts/occt_compare.py): the same
//! number of faces, the total area within 0.2 %, every side of the bounding box within 0.2 %
//! of its diagonal, lengths in mm. Two figures of OpenCASCADE's are not the file's, and the
//! test says which and checks what stands in their place (docs/cad.md):
//! - bug24595_281390.stp holds 20 ADVANCED_FACEs; OpenCASCADE's healing splits one at its
//!   seam and counts 21. The file's count is asserted.
//! - PRO20359-L1.igs: OpenCASCADE's optimal box (BRepBndLib::AddOptimal without its
//!   triangulation) is loose at x_max by 0.43 mm (0.26 % of the diagonal) on this B-spline
//!   face; its own fine triangulation's box (deflection 1e-5 of the diagonal) has x_max
//!   −637.0151, which bounds that side instead.

use crate::common::Scratch;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The tolerances the issue and README state.
const AREA_TOL: f64 = 2e-3;
const BOUNDS_TOL: f64 = 2e-3;

fn cad_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/cad")
}

fn reference() -> Value {
    let text = std::fs::read_to_string(cad_dir().join("reference.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// What OpenCASCADE reports for a file, in mm.
#[derive(Debug, Clone)]
struct Figures {
    faces: usize,
    area: f64,
    bounds: [[f64; 3]; 2],
}

fn figures(v: &Value, faces: &str, area: &str, bounds: &str) -> Option<Figures> {
    let b = v.get(bounds)?.as_array()?;
    let corner = |k: usize| -> Option<[f64; 3]> {
        let c = b.get(k)?.as_array()?;
        Some([
            c.first()?.as_f64()?,
            c.get(1)?.as_f64()?,
            c.get(2)?.as_f64()?,
        ])
    };
    Some(Figures {
        faces: usize::try_from(v.get(faces)?.as_u64()?).ok()?,
        area: v.get(area)?.as_f64()?,
        bounds: [corner(0)?, corner(1)?],
    })
}

/// Where `ours` departs from `theirs` beyond the tolerances (NaN departs), or `Ok`.
fn compare(ours: &Figures, theirs: &Figures, faces_expected: usize) -> Result<(), String> {
    let mut bad = Vec::new();
    if ours.faces != faces_expected {
        bad.push(format!("faces {} (expected {faces_expected})", ours.faces));
    }
    let area = (ours.area - theirs.area).abs() / theirs.area.abs();
    // NaN departs: only a number within the tolerance passes.
    if area.is_nan() || area > AREA_TOL {
        bad.push(format!(
            "area {} vs {} (relative {area:e})",
            ours.area, theirs.area
        ));
    }
    let diag = (0..3)
        .map(|k| (theirs.bounds[1][k] - theirs.bounds[0][k]).powi(2))
        .sum::<f64>()
        .sqrt();
    for side in 0..2 {
        for k in 0..3 {
            let off = (ours.bounds[side][k] - theirs.bounds[side][k]).abs() / diag;
            if off.is_nan() || off > BOUNDS_TOL {
                bad.push(format!(
                    "bound {}[{k}] {} vs {} ({off:e} of the diagonal)",
                    ["min", "max"][side],
                    ours.bounds[side][k],
                    theirs.bounds[side][k]
                ));
            }
        }
    }
    if bad.is_empty() {
        Ok(())
    } else {
        Err(bad.join("; "))
    }
}

/// `prespline info FILE --json`, parsed.
fn info(file: &Path) -> Value {
    let out = Command::new(env!("CARGO_BIN_EXE_prespline"))
        .arg("info")
        .arg(file)
        .arg("--json")
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}: {}",
        file.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn every_cad_file_agrees_with_opencascade() {
    let reference = reference();
    let files = reference.as_object().unwrap();
    assert_eq!(files.len(), 15, "reference.json lists the 15 files");
    let mut failures = Vec::new();
    for (name, r) in files {
        let json = info(&cad_dir().join(name));
        let ours = figures(&json, "faces", "area", "bounds").unwrap();
        let mut theirs = figures(r, "faces", "area_mm2", "bounds_mm").unwrap();
        assert_eq!(json["unit"], "mm", "{name}: lengths come out in mm");
        let mut faces = theirs.faces;
        match name.as_str() {
            // One ADVANCED_FACE per face in the file; OpenCASCADE splits one at its seam.
            "bug24595_281390.stp" => faces = 20,
            // OpenCASCADE's optimal box is loose at x_max; its fine triangulation's bound.
            "PRO20359-L1.igs" => theirs.bounds[1][0] = -637.015_087_8,
            _ => {}
        }
        eprintln!("{name}: {ours:?}");
        if let Err(e) = compare(&ours, &theirs, faces) {
            failures.push(format!("{name}: {e}"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The face count the exception names is the file's own.
#[test]
fn bug24595_holds_twenty_advanced_faces() {
    let text = std::fs::read_to_string(cad_dir().join("bug24595_281390.stp")).unwrap();
    assert_eq!(text.matches("ADVANCED_FACE").count(), 20);
}

/// Negative controls: the comparison fails a perturbed area, bound or count, and NaN.
#[test]
fn the_comparison_fails_perturbed_figures() {
    let theirs = Figures {
        faces: 10,
        area: 1000.0,
        bounds: [[0.0, 0.0, 0.0], [100.0, 100.0, 100.0]],
    };
    assert!(compare(&theirs, &theirs, 10).is_ok());
    let mut a = theirs.clone();
    a.area *= 1.0 + 2.5 * AREA_TOL;
    assert!(compare(&a, &theirs, 10).is_err());
    let mut b = theirs.clone();
    b.bounds[1][2] += 2.5 * BOUNDS_TOL * 100.0 * 3f64.sqrt();
    assert!(compare(&b, &theirs, 10).is_err());
    assert!(compare(&theirs, &theirs, 11).is_err());
    let mut n = theirs.clone();
    n.area = f64::NAN;
    assert!(compare(&n, &theirs, 10).is_err());
    let mut m = theirs.clone();
    m.bounds[0][0] = f64::NAN;
    assert!(compare(&m, &theirs, 10).is_err());
}

/// `convert` of a STEP model to OBJ and JSON keeps every face and its trims: the converted
/// files describe the same faces, area and bounds.
#[test]
fn convert_carries_cad_models_exactly() {
    let dir = Scratch::new("cad-convert");
    for name in ["screw.step", "BIGES.igs"] {
        let source = cad_dir().join(name);
        let before = info(&source);
        for ext in ["obj", "json"] {
            let out = dir.join(format!("{name}.{ext}"));
            let r = Command::new(env!("CARGO_BIN_EXE_prespline"))
                .arg("convert")
                .arg(&source)
                .arg(&out)
                .output()
                .unwrap();
            assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
            let after = info(&out);
            assert_eq!(after["faces"], before["faces"], "{name} → {ext}");
            let (a, b) = (
                after["area"].as_f64().unwrap(),
                before["area"].as_f64().unwrap(),
            );
            assert!((a - b).abs() <= 1e-9 * b, "{name} → {ext}: area {a} vs {b}");
            assert_eq!(after["bounds"], before["bounds"], "{name} → {ext}");
        }
    }
}
