//! `prespline bench` produces every report in one run (structure only — timings are never
//! asserted in tests).

use crate::common;

use std::path::Path;
use std::process::Command;

fn prespline() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_prespline"));
    let icd = prespline::gpu::LAVAPIPE_ICD;
    c.env("VK_DRIVER_FILES", icd)
        .env("VK_ICD_FILENAMES", icd)
        .env("PRESPLINE_VALIDATION", "required");
    c
}

fn check_reports(dir: &Path, frames: usize, warmup: usize) {
    for f in [
        "frames.csv",
        "summary.json",
        "summary.txt",
        "trace.json",
        "frame_times.svg",
        "histogram.svg",
        "final.png",
    ] {
        assert!(dir.join(f).is_file(), "{} missing", dir.join(f).display());
    }
    let csv = std::fs::read_to_string(dir.join("frames.csv")).unwrap();
    let mut lines = csv.lines();
    let header = lines.next().unwrap();
    for col in [
        "frame",
        "frame_ms",
        "delta_ms",
        "upload_ms",
        "record_ms",
        "submit_ms",
        "present_ms",
        "gpu_ms",
        "bytes_uploaded",
    ] {
        assert!(
            header.split(',').any(|c| c == col),
            "CSV header lacks {col}: {header}"
        );
    }
    assert_eq!(lines.count(), frames + warmup, "one row per frame");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    let measured = &summary["summary"]["measured"];
    for key in ["mean", "p50", "p90", "p95", "p99", "max", "low_1pct"] {
        assert!(
            measured["frame_ms"][key].is_number(),
            "summary lacks frame_ms.{key}: {measured}"
        );
        assert!(
            measured["phase_ms"]["delta"][key].is_number(),
            "summary lacks delta.{key}"
        );
    }
    let trace: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("trace.json")).unwrap()).unwrap();
    let events = trace["traceEvents"].as_array().unwrap();
    assert!(
        events
            .iter()
            .any(|e| e["ph"] == "X" && e["dur"].is_number())
    );
    let summary_txt = std::fs::read_to_string(dir.join("summary.txt")).unwrap();
    for line in ["1% low    ", "present   ", "delta     "] {
        assert!(
            summary_txt.lines().any(|l| l.starts_with(line)),
            "summary.txt does not define {line:?}:\n{summary_txt}"
        );
    }
    for svg in ["frame_times.svg", "histogram.svg"] {
        let text = std::fs::read_to_string(dir.join(svg)).unwrap();
        assert!(
            text.starts_with("<svg") && text.trim_end().ends_with("</svg>"),
            "{svg}"
        );
    }
}

#[test]
fn bench_writes_every_report_for_both_modes() {
    // A fresh directory: reports left by an earlier run must not pass for this one's.
    let scratch = common::Scratch::new("cli-bench");
    let out = scratch.join("out");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/erbs_surface.json");
    let r = prespline()
        .arg("bench")
        .arg(&scene)
        .args([
            "--scenario",
            "erbs-rotate",
            "--frames",
            "6",
            "--warmup",
            "4",
            "--size",
            "320x200",
            "--naive",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(r.status.success(), "{err}");
    assert!(
        err.contains("p99") && err.contains("1% low"),
        "terminal table missing:\n{err}"
    );
    assert!(err.contains("edit cost"), "comparison missing:\n{err}");
    // The comparison is also kept, exactly as printed.
    let saved = std::fs::read_to_string(out.join("comparison.txt")).unwrap();
    assert!(saved.starts_with("A = incremental, B = naive\n"), "{saved}");
    assert!(saved.contains("edit cost"), "{saved}");
    assert!(
        err.contains(&saved),
        "comparison.txt differs from the printed table:\n{saved}"
    );
    assert!(
        err.lines().last().unwrap().contains(out.to_str().unwrap()),
        "the last line says where the results are:\n{err}"
    );
    check_reports(&out.join("incremental"), 6, 4);
    check_reports(&out.join("naive"), 6, 4);
}

#[test]
fn every_scenario_runs_headless() {
    for scenario in ["drag", "orbit", "idle"] {
        let scratch = common::Scratch::new("cli-bench");
        let out = scratch.join(scenario);
        let r = prespline()
            .args([
                "bench",
                "--scenario",
                scenario,
                "--frames",
                "3",
                "--warmup",
                "4",
                "--size",
                "200x120",
                "--out",
            ])
            .arg(&out)
            .output()
            .unwrap();
        assert!(
            r.status.success(),
            "{scenario}: {}",
            String::from_utf8_lossy(&r.stderr)
        );
        check_reports(&out, 3, 4);
    }
    let r = prespline()
        .args(["bench", "--scenario", "spin"])
        .output()
        .unwrap();
    assert!(!r.status.success());
    assert!(String::from_utf8_lossy(&r.stderr).contains("unknown scenario 'spin'"));
}

/// A bench that cannot run says so in one line, `error: …`, with nothing before it: here the
/// scene has no ERBS object for `erbs-rotate`, which shows only once the renderer and the
/// session are up (the run's banner used to come first).
#[test]
fn failing_bench_prints_one_line() {
    let scratch = common::Scratch::new("cli-bench");
    let out = scratch.join("out");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/bezier_surface.json");
    let r = prespline()
        .arg("bench")
        .arg(&scene)
        .args(["--scenario", "erbs-rotate", "--frames", "3", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(!r.status.success());
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(err.lines().count(), 1, "expected one line:\n{err}");
    assert!(
        err.starts_with("error: ") && err.contains("needs an ERBS curve or surface"),
        "{err}"
    );
    assert!(
        !out.join("summary.json").exists(),
        "no reports for a failed run"
    );
    // Negative control: the same scene with a scenario it supports runs, banner and all.
    let r = prespline()
        .arg("bench")
        .arg(&scene)
        .args(["--scenario", "drag", "--frames", "3", "--warmup", "4"])
        .args(["--size", "160x100", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(r.status.success(), "{err}");
    assert!(err.lines().count() > 1, "{err}");
    assert!(err.starts_with("bench: drag on "), "{err}");
}

/// `bench` takes `--samples` (the scene's counts are replaced, the demo's too) and reports the
/// problem size it ran, `scene_samples` in summary.json: 64×64 for the example file, 9×9 with
/// `--samples 9x9`.
#[test]
fn bench_takes_the_samples_override() {
    let scratch = common::Scratch::new("cli-bench");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/bspline_surface.json");
    let run = |name: &str, samples: &[&str]| {
        let out = scratch.join(name);
        let r = prespline()
            .arg("bench")
            .arg(&scene)
            .args([
                "--frames", "2", "--warmup", "4", "--size", "160x100", "--out",
            ])
            .arg(&out)
            .args(samples)
            .output()
            .unwrap();
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap())
                .unwrap();
        let found = find_key(&summary, "scene_samples");
        found
            .and_then(|v| v.as_u64())
            .expect("scene_samples reported")
    };
    assert_eq!(run("file", &[]), 64 * 64);
    assert_eq!(
        run("override", &["--samples", "9x9", "--samples", "50"]),
        81
    );
}

/// The first value under `key` anywhere in `v`.
fn find_key<'a>(v: &'a serde_json::Value, key: &str) -> Option<&'a serde_json::Value> {
    match v {
        serde_json::Value::Object(m) => m
            .get(key)
            .or_else(|| m.values().find_map(|x| find_key(x, key))),
        serde_json::Value::Array(a) => a.iter().find_map(|x| find_key(x, key)),
        _ => None,
    }
}

/// `--redraw` is recorded in the summary (default `retained`), and a bad value is one line.
#[test]
fn bench_records_the_redraw_mode() {
    let scratch = common::Scratch::new("cli-bench-redraw");
    for (flag, expect) in [(None, "retained"), (Some("full"), "full")] {
        let out = scratch.join(expect);
        let mut c = prespline();
        c.args([
            "bench", "--frames", "3", "--warmup", "4", "--size", "200x120",
        ]);
        if let Some(f) = flag {
            c.args(["--redraw", f]);
        }
        let r = c.arg("--out").arg(&out).output().unwrap();
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(r.status.success(), "{err}");
        assert!(err.contains(&format!("redraw {expect}")), "banner: {err}");
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap())
                .unwrap();
        let text = summary.to_string();
        assert!(
            text.contains(&format!("\"redraw\":\"{expect}\"")),
            "summary.json lacks the mode: {text}"
        );
        // And how many measured frames a static layer served: none with `full`.
        let retained = summary["run"]["extra"]["retained_frames"].as_u64();
        match expect {
            "full" => assert_eq!(retained, Some(0), "{text}"),
            _ => assert!(retained.is_some_and(|n| n > 0), "{text}"),
        }
    }
    let r = prespline()
        .args(["bench", "--redraw", "partial"])
        .output()
        .unwrap();
    assert!(!r.status.success());
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(err.contains("--redraw takes retained or full"), "{err}");
}
