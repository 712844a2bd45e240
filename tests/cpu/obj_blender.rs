//! OBJ files from Blender 2.7x–2.9x: its exporter (`io_scene_obj/export_obj.py`, `write_nurb`)
//! writes every NURBS curve as `curv 0.0 1.0` over a uniform knot vector `parm u` of
//! i/(k − 1), unclamped unless the spline uses end points, so the range reaches outside the
//! domain [t_d, t_n]. Such a curve loads (clamped to the domain, one warning per file), samples
//! over the domain, agrees with an independent de Boor evaluation, and converts.
//!
//! `tests/data/blender_nurbs_curves.obj` is written the exporter's way (header, `mtllib`,
//! `v %.6f`, `g NAME`, `cstype bspline`, `deg`, `curv 0.0 1.0 -1 -2 …` — negative numbers,
//! so the control points run backwards, and a cyclic spline repeats its first `deg` numbers —
//! `parm u` printed `%.6f`, `end`): an open cubic, a cyclic quadratic, and a cubic with end
//! points (clamped knots, nothing to clamp).

use crate::oracle::eval::bspline_derivatives;
use prespline::formats::obj::parse_obj;
use prespline::model::Model;
use std::path::{Path, PathBuf};

fn file() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/blender_nurbs_curves.obj")
}

/// Per `curv` of the file, as written: (line, degree, vertex numbers made absolute, knots).
fn curves_as_written(text: &str) -> Vec<(usize, usize, Vec<usize>, Vec<f64>)> {
    let (mut vertices, mut degree) = (0usize, 0usize);
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let w: Vec<&str> = line.split_whitespace().collect();
        match w.first() {
            Some(&"v") => vertices += 1,
            Some(&"deg") => degree = w[1].parse().unwrap(),
            Some(&"curv") => {
                let refs = w[3..]
                    .iter()
                    .map(|r| vertices - r.parse::<i64>().unwrap().unsigned_abs() as usize)
                    .collect();
                out.push((i + 1, degree, refs, Vec::new()));
            }
            Some(&"parm") => {
                out.last_mut().unwrap().3 = w[2..].iter().map(|x| x.parse().unwrap()).collect();
            }
            _ => {}
        }
    }
    out
}

fn vertices(text: &str) -> Vec<[f64; 3]> {
    text.lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let c: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            [c[0], c[1], c[2]]
        })
        .collect()
}

#[test]
fn blender_curves_load_clamped_with_one_warning_and_match_de_boor() {
    let text = std::fs::read_to_string(file()).unwrap();
    let written = curves_as_written(&text);
    assert_eq!(written.len(), 3);
    let import = parse_obj(&text).unwrap_or_else(|e| panic!("{e}"));

    // One warning line for the file, at the first curve, counting both unclamped curves.
    let clamped: Vec<_> = import
        .warnings
        .iter()
        .filter(|w| w.message.contains("clamped"))
        .collect();
    assert_eq!(clamped.len(), 1, "{:?}", import.warnings);
    assert_eq!(clamped[0].line, written[0].0);
    assert!(
        clamped[0]
            .message
            .starts_with("curv range [0, 1] reaches outside the domain [0.333333, 0.666667]"),
        "{}",
        clamped[0].message
    );
    assert!(
        clamped[0].message.ends_with("(2 times, first here)"),
        "{}",
        clamped[0].message
    );
    assert_eq!(import.warnings.len(), 1, "{:?}", import.warnings);

    let names: Vec<&str> = import
        .scene
        .objects
        .iter()
        .map(|o| o.name.as_str())
        .collect();
    assert_eq!(names, ["NurbsCurve", "NurbsCircle", "NurbsPath"]);
    let points = vertices(&text);
    for (o, (line, degree, refs, knots)) in import.scene.objects.iter().zip(&written) {
        let Model::Curve(m) = &o.model else {
            panic!("line {line}: {:?}", o.model)
        };
        let c = m.curve();
        // The whole curve, the control data as written: nothing cut, nothing recomputed.
        let domain = (knots[*degree], knots[refs.len()]);
        assert_eq!(c.domain(), domain, "line {line}");
        assert_eq!(c.knots().as_slice(), knots.as_slice(), "line {line}");
        let control: Vec<[f64; 3]> = refs.iter().map(|&r| points[r]).collect();
        let ours: Vec<[f64; 3]> = c.points().iter().map(|p| p.to_array()).collect();
        assert_eq!(ours, control, "line {line}");
        for j in 0..=64 {
            let t = domain.0 + (domain.1 - domain.0) * f64::from(j) / 64.0;
            let want = bspline_derivatives(*degree, knots, &control, t, 1);
            let got = c.derivatives(t, 1);
            for (g, w) in got.iter().zip(&want) {
                let scale = w.iter().fold(1.0f64, |a, x| a.max(x.abs()));
                let g = g.to_array();
                let err = (0..3).fold(0.0f64, |a, k| a.max((g[k] - w[k]).abs()));
                assert!(err <= 1e-12 * scale, "line {line}, t = {t}: {g:?} vs {w:?}");
            }
        }
    }
}

/// `prespline sample` samples the clamped curve over its knot domain, both ends exactly.
#[test]
fn blender_curves_sample_over_the_knot_domain() {
    let text = std::fs::read_to_string(file()).unwrap();
    let written = curves_as_written(&text);
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_prespline"))
        .arg("sample")
        .arg(file())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert_eq!(
        err.lines().filter(|l| l.contains("warning")).count(),
        1,
        "{err}"
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let objects = v["objects"].as_array().unwrap();
    for (o, (line, degree, refs, knots)) in objects.iter().zip(&written) {
        let params: Vec<f64> = o["params"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        assert_eq!(params.first(), Some(&knots[*degree]), "line {line}");
        assert_eq!(params.last(), Some(&knots[refs.len()]), "line {line}");
    }
}

/// `prespline convert` reads the file and writes it in prespline's form: the range now equals
/// the domain, so the written file reads back without the warning and with the same curves.
#[test]
fn blender_curves_convert() {
    let dir = std::env::temp_dir().join(format!("prespline-blender-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (obj, json) = (dir.join("curves.obj"), dir.join("curves.json"));
    for to in [&obj, &json] {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_prespline"))
            .arg("convert")
            .arg(file())
            .arg(to)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{err}");
        let warning = format!("{}:13: warning: curv range [0, 1]", file().display());
        assert_eq!(
            err.lines().filter(|l| l.starts_with(&warning)).count(),
            1,
            "{err}"
        );
    }
    let original = parse_obj(&std::fs::read_to_string(file()).unwrap())
        .unwrap()
        .scene;
    let back = parse_obj(&std::fs::read_to_string(&obj).unwrap()).unwrap();
    assert!(back.warnings.is_empty(), "{:?}", back.warnings);
    assert_eq!(back.scene, original);
    assert_eq!(prespline::formats::read_json(&json).unwrap(), original);
}
