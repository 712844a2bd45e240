//! The product's `prespline sample` against the independent oracle (`tests/oracle/`).
//!
//! For many seeds: generate a random scene (and, for some tests, a random edit list), write it
//! to a temporary directory, run `prespline sample SCENE --derivatives N [--edits EDITS] [--full]`
//! and compare every number of its output with the oracle evaluated at the product's parameters:
//!
//!   |x − y| ≤ tol · scale,  scale = max(1, max |value| over the object's oracle samples of the
//!   same derivative order: r for curves, (a, b) for surfaces),
//!
//! with tol = 1e-12 without edits and with `--full`, 1e-9 for the incremental edit path. The
//! parameters themselves must match the contract formula to within 4 ulp of the domain size.
//!
//! On failure the seed, object, indices and both numbers are printed and the scene, edits and
//! command line are saved under `target/oracle-failures/`.
//!
//! Environment knobs:
//! * `PRESPLINE_ORACLE_SEEDS=k` — run k seeds per test instead of the default;
//! * `PRESPLINE_ORACLE_SEED=s` — run only seed s (reproduce a failure);
//! * `PRESPLINE_ORACLE_BIN=path` — test another executable instead of this crate's binary;
//! * `PRESPLINE_ORACLE_WRITE_EXPECTED=1` — also write the oracle's own output next to each scene
//!   as `SCENE.expected.json` (lets a stand-in script exercise this harness).

mod oracle;

use std::path::{Path, PathBuf};
use std::process::Command;

use oracle::compare::{Report, compare_output};
use oracle::random::{self, Kind, Options};
use oracle::rng::Rng;
use oracle::scene::{Edit, Scene, apply_edits};
use serde_json::Value;

const TOL: f64 = 1e-12;
const TOL_INCREMENTAL: f64 = 1e-9;

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

/// Scratch directory of one test (cases within a test run sequentially).
fn work_dir(test: &str) -> PathBuf {
    target_tmp().join(format!("oracle-agreement-{}-{test}", std::process::id()))
}

/// The seeds a test runs: `default` of them, or as the environment says.
fn seeds(default: u64, salt: u64) -> Vec<u64> {
    if let Some(s) = std::env::var("PRESPLINE_ORACLE_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
    {
        return vec![s];
    }
    let count = std::env::var("PRESPLINE_ORACLE_SEEDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default);
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

    /// Runs the product and compares; Err carries a full description.
    fn run(&self) -> Result<Report, String> {
        let label = self.label();
        let dir = work_dir(self.test);
        std::fs::create_dir_all(&dir).map_err(|e| format!("{label}: {e}"))?;
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

/// Runs all cases, prints a summary, and fails listing the first failures.
fn run_all(test: &str, cases: Vec<Case>) {
    let total = cases.len();
    let mut failures = Vec::new();
    let mut worst = 0.0f64;
    let mut compared = 0usize;
    for case in &cases {
        match case.run() {
            Ok(report) => {
                worst = worst.max(report.max_relative_error);
                compared += report.compared;
            }
            Err(message) => {
                eprintln!("{message}");
                failures.push(message);
            }
        }
    }
    let _ = std::fs::remove_dir(work_dir(test));
    println!(
        "{test}: {} of {total} runs agree; {compared} numbers compared, max scaled error {worst:.3e}",
        total - failures.len()
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

/// Random edit sequences: the incremental path within 1e-9, `--full` within 1e-12.
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
                tolerance: if full { TOL } else { TOL_INCREMENTAL },
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
