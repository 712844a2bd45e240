//! The product's `prespline sample` against the independent oracle (`tests/oracle/`).
//!
//! For many seeds: generate a random scene (and, for some tests, a random edit list), write it
//! to a temporary directory, run `prespline sample SCENE --derivatives N [--edits EDITS] [--full]`
//! and compare every number of its output with the oracle evaluated at the product's parameters:
//!
//!   |x − y| ≤ tol · scale,  scale = max |value| over the object's oracle samples of the same
//!   derivative order: r for curves, (a, b) for surfaces (no floor: a small object is held to
//!   its own size; see `oracle::compare`),
//!
//! with tol = 1e-13, what README.md and docs/testing.md claim, without edits, with `--full`
//! and for the incremental edit path alike (measured worst 3.4e-14 over 500 seeds per test). The
//! parameters themselves must match the contract formula to within 4 ulp of the domain size.
//! What the renderer samples (S, Su, Sv and unit normals, C and C', through the shading fast
//! path where it applies) is compared in-process the same way.
//!
//! On failure the seed, object, indices and both numbers are printed and the scene, edits and
//! command line are saved under `target/oracle-failures/`.
//!
//! Environment knobs:
//! * `PRESPLINE_ORACLE_SEEDS=k` — run k ≥ 1 seeds per test instead of the default (0, or
//!   anything that is not a count, fails: a run that compares nothing proves nothing);
//! * `PRESPLINE_ORACLE_SEED=s` — run only seed s (reproduce a failure);
//! * `PRESPLINE_ORACLE_BIN=path` — test another executable instead of this crate's binary;
//! * `PRESPLINE_ORACLE_WRITE_EXPECTED=1` — also write the oracle's own output next to each scene
//!   as `SCENE.expected.json` (lets a stand-in script exercise this harness).

use crate::common;
use crate::oracle;

use std::path::{Path, PathBuf};
use std::process::Command;

use oracle::compare::{Report, compare_output};
use oracle::condition::{compare_conditioned, compare_refined_outputs, nan_max};
use oracle::random::{self, Kind, Options};
use oracle::rng::Rng;
use oracle::scene::{Edit, Scene, apply_edits};
use serde_json::Value;

/// README.md and docs/testing.md: `prespline sample` agrees with the independent evaluator to
/// 1e-13 of each derivative order's magnitude, through the delta path too.
const TOL: f64 = 1e-13;

fn product_binary() -> PathBuf {
    std::env::var_os("PRESPLINE_ORACLE_BIN")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_BIN_EXE_prespline")))
}

fn target_tmp() -> &'static Path {
    Path::new(env!("CARGO_TARGET_TMPDIR"))
}

/// `target/oracle-failures/`.
fn failure_dir() -> PathBuf {
    target_tmp()
        .parent()
        .unwrap_or(target_tmp())
        .join("oracle-failures")
}

/// The seeds a test runs: `default` of them, or as the environment says.
fn seeds(default: u64, salt: u64) -> Vec<u64> {
    if let Some(s) = std::env::var("PRESPLINE_ORACLE_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
    {
        return vec![s];
    }
    let count = match std::env::var("PRESPLINE_ORACLE_SEEDS") {
        Err(_) => default,
        Ok(text) => match text.parse::<u64>() {
            Ok(k) if k > 0 => k,
            _ => panic!(
                "PRESPLINE_ORACLE_SEEDS={text:?}: expected a seed count of at least 1 (a run that compares nothing proves nothing)"
            ),
        },
    };
    (0..count).map(|i| salt * 1_000_003 + i).collect()
}

/// One invocation of `prespline sample`.
struct Case<'a> {
    test: &'a str,
    seed: u64,
    scene: &'a Scene,
    edits: Option<&'a [Edit]>,
    derivatives: usize,
    /// Pass `--derivatives N`; without it the contract's default N = 1 applies.
    explicit_derivatives: bool,
    full: bool,
    tolerance: f64,
}

impl Case<'_> {
    fn label(&self) -> String {
        format!(
            "{}-seed{}-n{}{}{}",
            self.test,
            self.seed,
            self.derivatives,
            if self.explicit_derivatives {
                ""
            } else {
                "-default"
            },
            match (self.edits.is_some(), self.full) {
                (false, _) => "",
                (true, false) => "-incremental",
                (true, true) => "-full",
            }
        )
    }

    /// Runs the product in `dir` and compares; Err carries a full description.
    fn run(&self, dir: &Path) -> Result<Report, String> {
        let label = self.label();
        let scene_path = dir.join(format!("{label}.json"));
        let edits_path = dir.join(format!("{label}-edits.json"));
        let scene_json = serde_json::to_string_pretty(&self.scene.to_json()).unwrap();
        std::fs::write(&scene_path, &scene_json).map_err(|e| format!("{label}: {e}"))?;
        let mut model = self.scene.clone();
        let mut edits_json = None;
        if let Some(edits) = self.edits {
            let text = serde_json::to_string_pretty(&Value::Array(
                edits.iter().map(Edit::to_json).collect(),
            ))
            .unwrap();
            std::fs::write(&edits_path, &text).map_err(|e| format!("{label}: {e}"))?;
            apply_edits(&mut model, edits).map_err(|e| format!("{label}: oracle: {e}"))?;
            edits_json = Some(text);
        }
        if std::env::var_os("PRESPLINE_ORACLE_WRITE_EXPECTED").is_some() {
            let expected = serde_json::to_string(&model.sample_json(self.derivatives)).unwrap();
            let path = PathBuf::from(format!("{}.expected.json", scene_path.display()));
            std::fs::write(path, expected).map_err(|e| format!("{label}: {e}"))?;
        }

        let mut command = Command::new(product_binary());
        command.arg("sample").arg(&scene_path);
        if self.explicit_derivatives {
            command
                .arg("--derivatives")
                .arg(self.derivatives.to_string());
        } else {
            assert_eq!(self.derivatives, 1, "the default derivative order is 1");
        }
        if self.edits.is_some() {
            command.arg("--edits").arg(&edits_path);
        }
        if self.full {
            command.arg("--full");
        }
        let command_line = format!("{command:?}");
        let result = command.output();

        let outcome: Result<Report, String> = match result {
            Err(e) => Err(format!("could not run {command_line}: {e}")),
            Ok(out) if !out.status.success() => Err(format!(
                "{command_line} exited with {}; stderr: {}",
                out.status,
                String::from_utf8_lossy(&out.stderr).trim()
            )),
            Ok(out) => match serde_json::from_slice::<Value>(&out.stdout) {
                Err(e) => Err(format!(
                    "{command_line}: stdout is not JSON ({e}); first bytes: {:?}",
                    String::from_utf8_lossy(&out.stdout[..out.stdout.len().min(200)])
                )),
                Ok(value) => {
                    let report = compare_output(&model, self.derivatives, &value, self.tolerance);
                    if report.ok() {
                        Ok(report)
                    } else {
                        Err(format!(
                            "{} mismatches (tolerance {:e} × scale), max scaled error {:.3e}:\n{}",
                            report.mismatch_count,
                            self.tolerance,
                            report.max_relative_error,
                            report.describe()
                        ))
                    }
                }
            },
        };
        let _ = std::fs::remove_file(&scene_path);
        let _ = std::fs::remove_file(&edits_path);
        let _ = std::fs::remove_file(format!("{}.expected.json", scene_path.display()));
        outcome.map_err(|message| {
            let saved = failure_dir().join(&label);
            let _ = std::fs::create_dir_all(&saved);
            let _ = std::fs::write(saved.join("scene.json"), &scene_json);
            if let Some(text) = &edits_json {
                let _ = std::fs::write(saved.join("edits.json"), text);
            }
            let _ = std::fs::write(
                saved.join("README.txt"),
                format!(
                    "seed {}\ncommand: prespline sample scene.json{}{}{}\n\n{message}\n",
                    self.seed,
                    if self.explicit_derivatives {
                        format!(" --derivatives {}", self.derivatives)
                    } else {
                        String::new()
                    },
                    if self.edits.is_some() {
                        " --edits edits.json"
                    } else {
                        ""
                    },
                    if self.full { " --full" } else { "" },
                ),
            );
            format!(
                "[{label}] seed {}: {message}  (saved in {})",
                self.seed,
                saved.display()
            )
        })
    }
}

/// Runs all cases, prints a summary, and fails listing the first failures. Fails too when
/// nothing was compared.
fn run_all(test: &str, cases: Vec<Case>) {
    let total = cases.len();
    let scratch = common::Scratch::new(&format!("oracle-agreement-{test}"));
    let mut failures = Vec::new();
    let mut worst = 0.0f64;
    let mut compared = 0usize;
    for case in &cases {
        match case.run(scratch.path()) {
            Ok(report) => {
                worst = oracle::compare::nan_max(worst, report.max_relative_error);
                compared += report.compared;
            }
            Err(message) => {
                eprintln!("{message}");
                failures.push(message);
            }
        }
    }
    println!(
        "{test}: {} of {total} runs agree; {compared} numbers compared, max scaled error {worst:.3e}",
        total - failures.len()
    );
    assert!(
        total > 0 && compared > 0,
        "{test}: nothing was compared ({total} runs)"
    );
    if !failures.is_empty() {
        let shown: Vec<&String> = failures.iter().take(5).collect();
        panic!(
            "{test}: {} of {total} runs disagree with the oracle. First ones:\n{}",
            failures.len(),
            shown
                .iter()
                .map(|s| s.as_str())
                .collect::<Vec<_>>()
                .join("\n")
        );
    }
}

fn scenes(seeds: &[u64], kinds: &[Kind], opts: &Options) -> Vec<Scene> {
    seeds
        .iter()
        .map(|&s| random::random_scene(s, kinds, opts))
        .collect()
}

/// One case per scene, no edits, derivative order 0..=2 by seed.
fn unedited_cases<'a>(test: &'static str, seeds: &[u64], scenes: &'a [Scene]) -> Vec<Case<'a>> {
    seeds
        .iter()
        .zip(scenes)
        .map(|(&seed, scene)| Case {
            test,
            seed,
            scene,
            edits: None,
            derivatives: (seed % 3) as usize,
            explicit_derivatives: true,
            full: false,
            tolerance: TOL,
        })
        .collect()
}

#[test]
fn curves_agree_with_oracle() {
    let seeds = seeds(60, 1);
    let kinds = [
        Kind::BezierCurve,
        Kind::BSplineCurve,
        Kind::ErbsCurve,
        Kind::BSplineCurve,
        Kind::BezierCurve,
        Kind::BSplineCurve,
    ];
    let scenes = scenes(&seeds, &kinds, &Options::default());
    run_all("curves", unedited_cases("curves", &seeds, &scenes));
}

#[test]
fn surfaces_agree_with_oracle() {
    let seeds = seeds(45, 2);
    let kinds = [
        Kind::BezierSurface,
        Kind::BSplineSurface,
        Kind::ErbsSurface,
        Kind::BSplineSurface,
    ];
    let scenes = scenes(&seeds, &kinds, &Options::default());
    run_all("surfaces", unedited_cases("surfaces", &seeds, &scenes));
}

/// ERBS with derivative orders 3 and 4 (B-function derivatives of high order, full Leibniz
/// rule), plus polynomial curves asked for derivatives above their degree.
#[test]
fn high_order_derivatives_agree_with_oracle() {
    let seeds = seeds(30, 3);
    let kinds = [
        Kind::ErbsCurve,
        Kind::ErbsSurface,
        Kind::ErbsCurve,
        Kind::BSplineCurve,
        Kind::BezierCurve,
    ];
    let opts = Options {
        max_samples: 25,
        ..Options::default()
    };
    let scenes = scenes(&seeds, &kinds, &opts);
    let cases = seeds
        .iter()
        .zip(&scenes)
        .map(|(&seed, scene)| Case {
            test: "high-order",
            seed,
            scene,
            edits: None,
            derivatives: 3 + (seed % 2) as usize,
            explicit_derivatives: true,
            full: false,
            tolerance: TOL,
        })
        .collect();
    run_all("high-order", cases);
}

/// Random edit sequences: the incremental path and `--full`, both within 1e-13.
#[test]
fn edits_agree_with_oracle() {
    let seeds = seeds(25, 4);
    let opts = Options {
        max_samples: 24,
        ..Options::default()
    };
    let scenes = scenes(&seeds, &Kind::ALL, &opts);
    let edits: Vec<Vec<Edit>> = seeds
        .iter()
        .zip(&scenes)
        .map(|(&seed, scene)| {
            let mut rng = Rng::new(seed ^ 0xED17_5EED);
            let count = rng.int(1, 30);
            random::random_edits(&mut rng, scene, count)
        })
        .collect();
    let mut cases = Vec::new();
    for ((&seed, scene), edits) in seeds.iter().zip(&scenes).zip(&edits) {
        for full in [false, true] {
            cases.push(Case {
                test: "edits",
                seed,
                scene,
                edits: Some(edits),
                derivatives: (seed % 3) as usize,
                explicit_derivatives: true,
                full,
                tolerance: TOL,
            });
        }
    }
    run_all("edits", cases);
}

/// The lecture's worked examples as a scene; exact numbers are checked by the self-check, here
/// the product only has to agree with the oracle.
#[test]
fn lecture_scene_agrees_with_oracle() {
    let r = std::f64::consts::FRAC_1_SQRT_2;
    let scene = Scene::from_json(&serde_json::json!({"objects": [
        {"name": "bezier", "type": "bezier_curve",
         "points": [[1, 1, 0], [1, 10, 0], [10, 10, 0], [10, 1, 0]], "samples": 4},
        {"name": "deboor", "type": "bspline_curve", "degree": 3,
         "knots": [0, 1, 2, 3, 4, 5, 6, 7],
         "points": [[1, 1, 0], [1, 10, 0], [10, 10, 0], [10, 1, 0]], "samples": 4},
        {"name": "circle", "type": "bezier_curve",
         "points": [[1, 0, 0], [1, 1, 0], [0, 1, 0]], "weights": [1, r, 1], "samples": 9},
        {"name": "erbs", "type": "erbs_curve", "knots": [0, 0, 1, 2, 2],
         "local": [{"points": [[0, 0, 0], [1, 1, 0]]}, {"points": [[1, 0, 0], [2, 2, 1], [3, 0, 0]]},
                   {"points": [[4, 4, 4]]}], "samples": 9}
    ]}))
    .unwrap();
    let mut cases: Vec<Case> = (0..=4)
        .map(|n| Case {
            test: "lecture",
            seed: 0,
            scene: &scene,
            edits: None,
            derivatives: n,
            explicit_derivatives: true,
            full: false,
            tolerance: TOL,
        })
        .collect();
    cases.push(Case {
        test: "lecture",
        seed: 0,
        scene: &scene,
        edits: None,
        derivatives: 1,
        explicit_derivatives: false,
        full: false,
        tolerance: TOL,
    });
    run_all("lecture", cases);
}

/// Tensor-product Bézier, B-spline and NURBS surfaces with every mixed partial up to order 3–5
/// per direction (the ERBS surfaces of `high_order_derivatives_agree_with_oracle` aside, no
/// other test asks a surface for more than second partials).
#[test]
fn tensor_surface_high_order_partials_agree_with_oracle() {
    let seeds = seeds(24, 6);
    let kinds = [
        Kind::BezierSurface,
        Kind::BSplineSurface,
        Kind::BSplineSurface,
    ];
    let opts = Options {
        max_samples: 12,
        ..Options::default()
    };
    let scenes = scenes(&seeds, &kinds, &opts);
    let cases = seeds
        .iter()
        .zip(&scenes)
        .map(|(&seed, scene)| Case {
            test: "surface-high-order",
            seed,
            scene,
            edits: None,
            derivatives: 3 + (seed % 3) as usize,
            explicit_derivatives: true,
            full: false,
            tolerance: TOL,
        })
        .collect();
    run_all("surface-high-order", cases);
}

/// Whether the product samples `object` for drawing through `sampling::kernels::shading`'s fast
/// kernels (polynomial, degree 1–3 in every direction; ERBS surfaces use them per local patch).
fn takes_fast_path(object: &oracle::scene::Object) -> bool {
    use oracle::eval::Basis;
    use oracle::scene::Shape;
    let degree = |basis: &Basis, points: usize| match basis {
        Basis::Bezier => points - 1,
        Basis::BSpline { degree, .. } => *degree,
    };
    let fast = |d: usize| (1..=3).contains(&d);
    match &object.shape {
        Shape::Curve {
            basis,
            points,
            weights: None,
        } => fast(degree(basis, points.len())),
        Shape::Surface {
            basis,
            points,
            weights: None,
        } => fast(degree(&basis[0], points.len())) && fast(degree(&basis[1], points[0].len())),
        Shape::ErbsSurface { .. } => true,
        _ => false,
    }
}

/// Largest scaled difference of the product's drawing samples (curves C, C'; surfaces S, Su,
/// Sv) against the oracle at the product's parameters, scales per partial as in
/// `oracle::compare`; and the largest ratio of a unit normal's error to what the partials'
/// tolerance allows there: TOL · (scale(Su)/|Su| + scale(Sv)/|Sv|) / sin∠(Su, Sv), times 10.
/// Samples where the product's Su × Sv is degenerate (it takes the model's one-sided limit
/// there) or the oracle's vanishes (no normal is defined) are not compared. Returns (error, normal ratio, normals compared).
fn render_grid_error(
    object: &oracle::scene::Object,
    sampled: &prespline::model::SampledObject,
) -> (f64, f64, usize) {
    use oracle::compare::nan_max;
    let grid = sampled.grid();
    let params = sampled.params();
    // Oracle values per sample and slot, in the grid's storage order.
    let mut expected: Vec<[f64; 3]> = Vec::with_capacity(grid.data.len());
    if object.is_surface() {
        let g = object.surface_grid(params[0], params[1], 1);
        for row in &g {
            for p in row {
                expected.extend([p[0][0], p[1][0], p[0][1]]);
            }
        }
    } else {
        for &t in params[0] {
            expected.extend(object.curve_derivatives(t, 1));
        }
    }
    let stride = grid.stride();
    let mut scales = vec![0.0f64; stride];
    for (i, e) in expected.iter().enumerate() {
        for x in e {
            scales[i % stride] = nan_max(scales[i % stride], x.abs());
        }
    }
    let position = scales[0];
    scales
        .iter_mut()
        .filter(|s| **s == 0.0)
        .for_each(|s| *s = position);
    let mut worst = 0.0f64;
    for (i, (e, p)) in expected.iter().zip(&grid.data).enumerate() {
        for k in 0..3 {
            let err = (e[k] - p[k]).abs();
            let rel = if err == 0.0 {
                0.0
            } else {
                err / scales[i % stride]
            };
            worst = nan_max(worst, rel);
        }
    }
    let (mut normal_worst, mut normals_compared) = (0.0f64, 0);
    let len = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if let Some(normals) = &grid.normals {
        for (s, n) in normals.iter().enumerate() {
            let (su, sv) = (expected[s * stride + 1], expected[s * stride + 2]);
            let (psu, psv) = (grid.data[s * stride + 1], grid.data[s * stride + 2]);
            if prespline::geom::surface::regular_normal(psu, psv).is_none() {
                continue;
            }
            let cross = [
                su[1] * sv[2] - su[2] * sv[1],
                su[2] * sv[0] - su[0] * sv[2],
                su[0] * sv[1] - su[1] * sv[0],
            ];
            if len(cross) == 0.0 {
                // No normal is defined there.
                continue;
            }
            let sin = len(cross) / (len(su) * len(sv));
            let allowed = 10.0 * TOL * (scales[1] / len(su) + scales[2] / len(sv)) / sin;
            let unit = cross.map(|c| c / len(cross));
            let err = len([unit[0] - n.x, unit[1] - n.y, unit[2] - n.z]);
            normals_compared += 1;
            normal_worst = nan_max(normal_worst, err / allowed);
        }
    }
    (worst, normal_worst, normals_compared)
}

/// What the renderer draws against the oracle: every kind sampled for drawing (curves C, C';
/// surfaces S, Su, Sv and unit normals), polynomial degree-1–3 objects through the shading
/// fast path, then again after random point moves through the fast path's delta updates.
#[test]
fn drawing_samples_and_the_shading_fast_path_agree_with_oracle() {
    use prespline::model::SampledObject;
    use prespline::sampling::SampleMode;
    use prespline::scene::edit::parse_edits;
    let seeds = seeds(40, 7);
    let opts = Options {
        max_samples: 30,
        high_degree_chance: 0.0,
        rational_chance: 0.15,
    };
    let (mut worst, mut normal_worst) = (0.0f64, 0.0f64);
    let (mut fast, mut normals, mut compared) = (0usize, 0usize, 0usize);
    let mut failures = Vec::new();
    for &seed in &seeds {
        let scene = random::random_scene(seed, &Kind::ALL, &opts);
        let mut rng = Rng::new(seed ^ 0xFA57);
        // Point moves only: a weight edit makes an object rational, off the fast path.
        let edits: Vec<Edit> = random::random_edits(&mut rng, &scene, 40)
            .into_iter()
            .filter(|e| !matches!(e, Edit::Weight { .. }))
            .collect();
        let product = prespline::formats::parse_scene(&scene.to_json().to_string())
            .expect("generator makes valid scenes");
        let edits_json = Value::Array(edits.iter().map(Edit::to_json).collect()).to_string();
        let product_edits = parse_edits(&edits_json, &product).expect("valid edits");
        let mut edited = scene.clone();
        apply_edits(&mut edited, &edits).unwrap();
        for (i, o) in product.objects.iter().enumerate() {
            let mut sampled = SampledObject::new(&o.model, SampleMode::Render);
            fast += usize::from(takes_fast_path(&scene.objects[i]));
            let mut check = |what: &str, model: &oracle::scene::Object, s: &SampledObject| {
                let (err, nerr, n) = render_grid_error(model, s);
                worst = oracle::compare::nan_max(worst, err);
                normal_worst = oracle::compare::nan_max(normal_worst, nerr);
                normals += n;
                compared += s.grid().data.len();
                if !(err <= TOL && nerr <= 1.0) {
                    failures.push(format!(
                        "seed {seed} {} ({}) {what}: scaled error {err:e}, normal error {nerr:e} of the allowed",
                        model.name,
                        model.type_name()
                    ));
                }
            };
            check("as loaded", &scene.objects[i], &sampled);
            for e in product_edits.iter().filter(|e| e.object == i) {
                sampled.apply(&e.edit).expect("validated edits fit");
            }
            check("after edits", &edited.objects[i], &sampled);
        }
    }
    println!(
        "drawing samples: {compared} vectors and {normals} normals compared ({fast} objects on the fast path), max scaled error {worst:.3e}, normal error at most {normal_worst:.3e} of the allowed"
    );
    assert!(fast >= 20, "only {fast} objects took the fast path");
    assert!(normals > 0 && compared > 0, "nothing compared");
    assert!(
        failures.is_empty(),
        "{} disagreements:\n{}",
        failures.len(),
        failures[..failures.len().min(8)].join("\n")
    );
}

/// `PRESPLINE_ORACLE_SEEDS=0` (or a value that is not a count) makes the oracle tests fail
/// instead of passing with nothing compared: this test runs one of them again in a child
/// process with the knob set.
#[test]
fn zero_seeds_fail_instead_of_comparing_nothing() {
    // The harness names a test by its module path below the crate root.
    let name = match module_path!().split_once("::") {
        Some((_, module)) => format!("{module}::curves_agree_with_oracle"),
        None => "curves_agree_with_oracle".to_string(),
    };
    for value in ["0", "many"] {
        let out = Command::new(std::env::current_exe().unwrap())
            .args(["--exact", name.as_str(), "--test-threads", "1"])
            .env("PRESPLINE_ORACLE_SEEDS", value)
            .env_remove("PRESPLINE_ORACLE_SEED")
            .output()
            .unwrap();
        let text = format!(
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(
            !out.status.success() && text.contains(&format!("test {name} ... FAILED")),
            "PRESPLINE_ORACLE_SEEDS={value} did not fail the oracle test:\n{text}"
        );
        assert!(
            text.contains(&format!("PRESPLINE_ORACLE_SEEDS=\"{value}\"")),
            "the failure does not name the knob:\n{text}"
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Structural edits: knot insertion and degree elevation against the oracle's blossoms
// ---------------------------------------------------------------------------------------------
//
// A refined object carries its shape on a different f64 control net, so its samples are
// measured against each (object, derivative order)'s condition scale Σ|N^(a)||N^(b)||w·P|
// (`oracle::condition`): how far rounding the net moves that derivative. The value-relative
// measure of `compare_output` is printed alongside, for information: after refinement it asks
// for digits no f64 net has (coordinates far from the origin, short new spans, fourth
// derivatives of degree-6 pieces, orders above a polynomial's degree before elevation).

/// The structural tests hold both paths to this many condition scales.
const TOL_CONDITIONED: f64 = 1e-13;

/// Scenes for the structural tests: every refinable kind (rational ones included) and an ERBS
/// curve that only gets the other edits; degrees 0..=5 before elevation, up to 6 after.
const STRUCTURAL_KINDS: [Kind; 6] = [
    Kind::BezierCurve,
    Kind::BSplineCurve,
    Kind::BezierSurface,
    Kind::BSplineSurface,
    Kind::ErbsCurve,
    Kind::BSplineCurve,
];

fn structural_options() -> Options {
    Options {
        max_samples: 16,
        high_degree_chance: 0.0,
        ..Options::default()
    }
}

fn structural_mix(chance: f64) -> random::StructuralMix {
    random::StructuralMix {
        chance,
        max_degree: 6,
        max_points: 20,
    }
}

/// Writes the scene (and edits) under `dir`, runs `prespline sample`, parses stdout.
fn sample_output(
    dir: &Path,
    label: &str,
    scene: &Scene,
    edits: Option<&[Edit]>,
    n: usize,
    full: bool,
) -> Result<Value, String> {
    let scene_path = dir.join(format!("{label}.json"));
    std::fs::write(&scene_path, scene.to_json().to_string()).map_err(|e| e.to_string())?;
    let mut command = Command::new(product_binary());
    command
        .arg("sample")
        .arg(&scene_path)
        .arg("--derivatives")
        .arg(n.to_string());
    if let Some(edits) = edits {
        let path = dir.join(format!("{label}-edits.json"));
        let text = Value::Array(edits.iter().map(Edit::to_json).collect()).to_string();
        std::fs::write(&path, text).map_err(|e| e.to_string())?;
        command.arg("--edits").arg(path);
    }
    if full {
        command.arg("--full");
    }
    let out = command
        .output()
        .map_err(|e| format!("could not run {command:?}: {e}"))?;
    if !out.status.success() {
        return Err(format!(
            "{command:?} exited with {}; stderr: {}",
            out.status,
            String::from_utf8_lossy(&out.stderr).trim()
        ));
    }
    serde_json::from_slice(&out.stdout)
        .map_err(|e| format!("{command:?}: stdout is not JSON ({e})"))
}

/// Saves a failing structural case under `target/oracle-failures/LABEL/`; returns the folder.
fn save_structural_failure(
    label: &str,
    scene: &Scene,
    edits: &[Edit],
    command: &str,
    message: &str,
) -> PathBuf {
    let saved = failure_dir().join(label);
    let _ = std::fs::create_dir_all(&saved);
    let _ = std::fs::write(
        saved.join("scene.json"),
        serde_json::to_string_pretty(&scene.to_json()).unwrap(),
    );
    let edits = Value::Array(edits.iter().map(Edit::to_json).collect());
    let _ = std::fs::write(
        saved.join("edits.json"),
        serde_json::to_string_pretty(&edits).unwrap(),
    );
    let _ = std::fs::write(
        saved.join("README.txt"),
        format!("command: {command}\n\n{message}\n"),
    );
    saved
}

/// Largest errors of a structural test per path (incremental, `--full`): under the condition
/// measure (asserted) and, where computed, under the value-relative measure of
/// `compare_output` (printed only).
#[derive(Default)]
struct StructuralSummary {
    runs: usize,
    compared: usize,
    worst_conditioned: [f64; 2],
    worst_value_relative: Option<[f64; 2]>,
    failures: Vec<String>,
}

impl StructuralSummary {
    fn record(&mut self, full: bool, report: &Report) {
        self.compared += report.compared;
        let slot = &mut self.worst_conditioned[usize::from(full)];
        *slot = nan_max(*slot, report.max_relative_error);
    }

    fn record_value_relative(&mut self, full: bool, error: f64) {
        let worst = self.worst_value_relative.get_or_insert([0.0; 2]);
        worst[usize::from(full)] = nan_max(worst[usize::from(full)], error);
    }

    fn finish(self, test: &str) {
        let [incremental, full] = self.worst_conditioned;
        let value = self.worst_value_relative.map_or(String::new(), |[i, f]| {
            format!(
                "; value-relative measure, for information: incremental {i:.3e}, --full {f:.3e}"
            )
        });
        println!(
            "{test}: {} of {} runs agree; {} numbers compared; max error of the condition scale: incremental {incremental:.3e}, --full {full:.3e} (tolerance {TOL_CONDITIONED:e}){value}",
            self.runs - self.failures.len(),
            self.runs,
            self.compared,
        );
        assert!(
            self.runs > 0 && self.compared > 0,
            "{test}: nothing compared"
        );
        assert!(
            self.failures.is_empty(),
            "{test}: {} of {} runs disagree. First ones:\n{}",
            self.failures.len(),
            self.runs,
            self.failures[..self.failures.len().min(5)].join("\n")
        );
    }
}

/// Runs every (scene, edit list) through the incremental path and `--full` and compares each
/// output with the oracle's edited model under the condition measure.
fn run_structural(
    test: &str,
    seeds: &[u64],
    scenes: &[Scene],
    edits: &[Vec<Edit>],
    order: impl Fn(u64) -> usize,
) {
    let dir = target_tmp().join(format!("oracle-{test}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut summary = StructuralSummary::default();
    for ((&seed, scene), edits) in seeds.iter().zip(scenes).zip(edits) {
        let n = order(seed);
        let mut model = scene.clone();
        apply_edits(&mut model, edits).expect("generated edits are valid");
        for full in [false, true] {
            let label = format!(
                "{test}-seed{seed}-n{n}-{}",
                if full { "full" } else { "incremental" }
            );
            let command = format!(
                "prespline sample scene.json --derivatives {n} --edits edits.json{}",
                if full { " --full" } else { "" }
            );
            summary.runs += 1;
            let outcome =
                sample_output(&dir, &label, scene, Some(edits), n, full).and_then(|out| {
                    let value = compare_output(&model, n, &out, f64::INFINITY);
                    summary.record_value_relative(full, value.max_relative_error);
                    let report = compare_conditioned(&model, n, &out, TOL_CONDITIONED);
                    summary.record(full, &report);
                    if report.ok() {
                        Ok(())
                    } else {
                        Err(format!(
                            "{} mismatches, max {:.3e} of the condition scale:\n{}",
                            report.mismatch_count,
                            report.max_relative_error,
                            report.describe()
                        ))
                    }
                });
            if let Err(message) = outcome {
                let saved = save_structural_failure(&label, scene, edits, &command, &message);
                let line = format!("[{label}] {message}  (saved in {})", saved.display());
                eprintln!("{line}");
                summary.failures.push(line);
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    summary.finish(test);
}

/// Random edit lists with knot insertions and degree elevations mixed into point, weight and
/// ERBS local edits; later edits address the refined nets. Curves and surfaces, rational
/// ones included, degrees up to 6, derivatives up to 4, the incremental path and `--full`.
#[test]
fn structural_edits_agree_with_oracle() {
    let seeds = seeds(24, 8);
    let scenes = scenes(&seeds, &STRUCTURAL_KINDS, &structural_options());
    let edits: Vec<Vec<Edit>> = seeds
        .iter()
        .zip(&scenes)
        .map(|(&seed, scene)| {
            let mut rng = Rng::new(seed ^ 0x57_2C7E);
            let count = rng.int(1, 25);
            random::random_edits_with_structure(&mut rng, scene, count, &structural_mix(0.35))
        })
        .collect();
    let structural = edits
        .iter()
        .flatten()
        .filter(|e| matches!(e, Edit::InsertKnot { .. } | Edit::ElevateDegree { .. }))
        .count();
    assert!(
        structural >= seeds.len(),
        "only {structural} structural edits in {} lists",
        seeds.len()
    );
    run_structural("structural", &seeds, &scenes, &edits, |seed| {
        (seed % 5) as usize
    });
}

/// The property: an insertion followed by a point edit on the refined net matches an
/// independent insertion. Every Bézier/B-spline object gets one `insert_knot` (a random
/// direction on surfaces), then a translation of a control point that the insertion created
/// (its blossom arguments contain the new knot) and, now and then, a new weight on another.
#[test]
fn insertion_then_point_edit_matches_independent_insertion() {
    let seeds = seeds(20, 9);
    let kinds = [
        Kind::BezierCurve,
        Kind::BSplineCurve,
        Kind::BezierSurface,
        Kind::BSplineSurface,
    ];
    let scenes = scenes(&seeds, &kinds, &structural_options());
    let edits: Vec<Vec<Edit>> = seeds
        .iter()
        .zip(&scenes)
        .map(|(&seed, scene)| insertion_then_new_point_edits(seed, scene))
        .collect();
    let inserted = edits
        .iter()
        .flatten()
        .filter(|e| matches!(e, Edit::InsertKnot { .. }))
        .count();
    assert!(inserted >= 2 * seeds.len(), "only {inserted} insertions");
    run_structural("insert-then-edit", &seeds, &scenes, &edits, |seed| {
        (seed % 5) as usize
    });
}
/// For each object with room for a knot: insert_knot, then edits of control points the
/// insertion created (indices into the refined net).
fn insertion_then_new_point_edits(seed: u64, scene: &Scene) -> Vec<Edit> {
    use oracle::scene::Index;
    let mut rng = Rng::new(seed ^ 0x1_5E27);
    let mut model = scene.clone();
    let mut edits = Vec::new();
    for i in 0..model.objects.len() {
        let Some(insert) = random::random_insertion_edit(&mut rng, &model.objects[i]) else {
            continue;
        };
        let Edit::InsertKnot { direction, t, .. } = insert else {
            unreachable!()
        };
        insert.apply(&mut model).unwrap();
        edits.push(insert);
        let object = &model.objects[i];
        let dir = direction.unwrap_or(0);
        let (degree, knots, _) = random::refinable_directions(object).unwrap()[dir].clone();
        // Control points whose blossom arguments t_{k+1..k+p} contain t: the new ones.
        let created: Vec<usize> = (0..knots.len() - degree - 1)
            .filter(|&k| knots[k + 1..=k + degree].contains(&t))
            .collect();
        let other = |rng: &mut Rng| match &object.shape {
            oracle::scene::Shape::Surface { points, .. } => {
                rng.int(0, [points[0].len(), points.len()][dir] - 1)
            }
            _ => 0,
        };
        let index = |k: usize, rng: &mut Rng| match direction {
            None => Index::One(k),
            Some(0) => Index::Two(k, other(rng)),
            Some(_) => Index::Two(other(rng), k),
        };
        let k = *rng.pick(&created);
        let magnitude = object.magnitude().max(1e-3);
        let delta = std::array::from_fn(|_| magnitude * rng.range(-0.5, 0.5));
        let mut follow = vec![Edit::PointDelta {
            object: object.name.clone(),
            point: index(k, &mut rng),
            delta,
        }];
        if rng.chance(0.4) {
            let k = *rng.pick(&created);
            follow.push(Edit::Weight {
                object: object.name.clone(),
                point: index(k, &mut rng),
                weight: rng.range(0.3, 3.0),
            });
        }
        apply_edits(&mut model, &follow).unwrap();
        edits.extend(follow);
    }
    edits
}

/// Structural edits alone leave `sample` unchanged (the issue: "to about 1e-13, positions and
/// derivatives, with and without --full"): after random insertions and elevations only, both
/// paths give the unedited scene's samples to within `TOL_CONDITIONED` of the condition scales
/// of the nets before and after (the oracle's models of them). Bézier objects that became
/// B-splines included; the ERBS curve, untouched, must not move either. The product's refined
/// nets also have the oracle's control counts (`check_refined_counts`).
#[test]
fn structural_edits_alone_leave_samples_unchanged() {
    let seeds = seeds(16, 10);
    let scenes = scenes(&seeds, &STRUCTURAL_KINDS, &structural_options());
    let dir = target_tmp().join(format!("oracle-unchanged-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut summary = StructuralSummary::default();
    let mut structural = 0;
    for (&seed, scene) in seeds.iter().zip(&scenes) {
        let n = (seed % 5) as usize;
        let mut rng = Rng::new(seed ^ 0x5A_3E);
        let mix = structural_mix(1.0);
        let mut model = scene.clone();
        let mut edits = Vec::new();
        for _ in 0..rng.int(1, 8) {
            let object = &model.objects[rng.int(0, model.objects.len() - 1)];
            if let Some(edit) = random::random_structural_edit(&mut rng, object, &mix) {
                edit.apply(&mut model).expect("generated edits are valid");
                edits.push(edit);
            }
        }
        structural += edits.len();
        let label = format!("unchanged-seed{seed}-n{n}");
        if let Err(e) = check_refined_counts(&dir, &label, scene, &model, &edits) {
            summary.runs += 1;
            summary
                .failures
                .push(format!("[{label}] control counts: {e}"));
        }
        let before = match sample_output(&dir, &label, scene, None, n, false) {
            Ok(out) => out,
            Err(e) => {
                summary.runs += 1;
                summary.failures.push(format!("[{label}] unedited: {e}"));
                continue;
            }
        };
        for full in [false, true] {
            summary.runs += 1;
            let label = format!("{label}-{}", if full { "full" } else { "incremental" });
            let outcome =
                sample_output(&dir, &label, scene, Some(&edits), n, full).and_then(|after| {
                    let report =
                        compare_refined_outputs(scene, &model, n, &before, &after, TOL_CONDITIONED);
                    summary.record(full, &report);
                    if report.ok() {
                        Ok(())
                    } else {
                        Err(format!(
                            "{} numbers moved, max {:.3e} of the condition scale:\n{}",
                            report.mismatch_count,
                            report.max_relative_error,
                            report.describe()
                        ))
                    }
                });
            if let Err(message) = outcome {
                let command = format!(
                    "prespline sample scene.json --derivatives {n} [--edits edits.json{}]",
                    if full { " --full" } else { "" }
                );
                let saved = save_structural_failure(&label, scene, &edits, &command, &message);
                let line = format!("[{label}] {message}  (saved in {})", saved.display());
                eprintln!("{line}");
                summary.failures.push(line);
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    assert!(
        structural >= seeds.len(),
        "only {structural} structural edits"
    );
    summary.finish("unchanged");
}

/// The product's refined nets have the oracle's control counts: after `edits`, a point edit at
/// the last index of every Bézier/B-spline object's net is accepted and one just past it (in
/// each direction) is refused naming the field `point`.
fn check_refined_counts(
    dir: &Path,
    label: &str,
    scene: &Scene,
    model: &Scene,
    edits: &[Edit],
) -> Result<(), String> {
    use oracle::scene::{Index, Shape};
    for object in &model.objects {
        let (last, past): (Index, Vec<Index>) = match &object.shape {
            Shape::Curve { points, .. } => {
                (Index::One(points.len() - 1), vec![Index::One(points.len())])
            }
            Shape::Surface { points, .. } => {
                let (nu, nv) = (points.len(), points[0].len());
                (
                    Index::Two(nu - 1, nv - 1),
                    vec![Index::Two(nu, 0), Index::Two(0, nv)],
                )
            }
            _ => continue,
        };
        let with = |point: Index| -> Vec<Edit> {
            let mut list = edits.to_vec();
            list.push(Edit::PointDelta {
                object: object.name.clone(),
                point,
                delta: [0.0, 0.0, 0.0],
            });
            list
        };
        let probe = format!("{label}-counts-{}", object.name);
        sample_output(dir, &probe, scene, Some(&with(last)), 0, false)
            .map_err(|e| format!("{}: the last point {last:?} was refused: {e}", object.name))?;
        for point in past {
            match sample_output(dir, &probe, scene, Some(&with(point)), 0, false) {
                Ok(_) => {
                    return Err(format!(
                        "{}: {point:?} past the net was accepted",
                        object.name
                    ));
                }
                Err(e) if e.contains("'point'") && e.contains(&format!("'{}'", object.name)) => {}
                Err(e) => {
                    return Err(format!(
                        "{}: {point:?}: unexpected refusal {e}",
                        object.name
                    ));
                }
            }
        }
    }
    Ok(())
}
