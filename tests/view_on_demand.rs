//! `prespline view` under X (Xvfb in `make test`) on lavapipe: an idle viewer draws nothing,
//! and a lost GPU device ends the viewer with one clear error line.
//!
//! Frames are counted from the `--profile` report (one line per drawn frame), never timed:
//! a session that quits after 6.5 s without input draws exactly as many frames as one that
//! quits after 1.5 s, so none were drawn in the 5 s between.

mod common;

use common::display;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Duration;

/// Longer than any session here (the longest quits after 6.5 s), short of a hung suite.
const LIMIT: Duration = Duration::from_secs(120);

fn prespline() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_prespline"));
    let icd = prespline::gpu::LAVAPIPE_ICD;
    c.env("VK_DRIVER_FILES", icd)
        .env("VK_ICD_FILENAMES", icd)
        .env("PRESPLINE_VALIDATION", "1");
    c
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("prespline-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn example() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/bspline_surface.json")
}

/// Runs the viewer without input until a scripted quit at `quit_s` seconds; returns the start
/// time (seconds since the first frame) of every frame it drew.
fn frame_starts(dir: &Path, quit_s: f64) -> Vec<f64> {
    let script = dir.join(format!("quit-{quit_s}.json"));
    std::fs::write(&script, format!(r#"[{{"t": {quit_s}, "quit": true}}]"#)).unwrap();
    let profile = dir.join(format!("profile-{quit_s}"));
    let out = common::output_with_timeout(
        prespline()
            .arg("view")
            .arg(example())
            .args(["--size", "320x240", "--script"])
            .arg(&script)
            .arg("--profile")
            .arg(&profile),
        LIMIT,
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "viewer failed: {err}");
    let csv = std::fs::read_to_string(profile.join("frames.csv")).unwrap();
    csv.lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap().parse().unwrap())
        .collect()
}

#[test]
fn an_idle_viewer_draws_no_frames() {
    if !display() {
        return;
    }
    let dir = scratch("idle");
    // Start-up (first frame, window events, the overlay's settle tick) is over well within
    // 2.5 s even on a loaded machine; then nothing may be drawn until the scripted quit.
    let starts = frame_starts(&dir, 7.0);
    let idle: Vec<f64> = starts
        .iter()
        .copied()
        .filter(|&t| t > 2.5 && t < 6.9)
        .collect();
    eprintln!("{} frames, at {starts:?} s", starts.len());
    assert!(!starts.is_empty(), "the viewer drew nothing at all");
    assert!(
        idle.is_empty(),
        "frames were drawn during 4.4 s without input, at {idle:?} s"
    );
}

fn run_with_lost_device(dir: &Path) -> Output {
    let script = dir.join("script.json");
    // Input keeps frames coming until the injected loss at frame 6.
    std::fs::write(
        &script,
        r#"[{"frame": 2, "move": [100, 100]}, {"frame": 4, "move": [120, 110]},
            {"frame": 8, "move": [140, 120]}, {"frame": 40, "quit": true}]"#,
    )
    .unwrap();
    common::output_with_timeout(
        prespline()
            .arg("view")
            .arg(example())
            .args(["--size", "320x240", "--script"])
            .arg(&script)
            .env("PRESPLINE_FAULT", "device-lost@6"),
        LIMIT,
    )
}

#[test]
fn a_lost_device_ends_the_viewer_with_one_line() {
    if !display() {
        return;
    }
    let dir = scratch("device-lost");
    let out = run_with_lost_device(&dir);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success(),
        "the viewer went on after losing its device: {err}"
    );
    let errors: Vec<&str> = err.lines().filter(|l| l.starts_with("error:")).collect();
    assert_eq!(errors.len(), 1, "not one error line:\n{err}");
    assert!(
        errors[0].contains("device was lost") && !errors[0].contains("panicked"),
        "unclear error line: {}",
        errors[0]
    );
    assert!(
        !err.contains("vulkan: [Error]") && !err.contains("panicked"),
        "validation errors or a panic on the way out:\n{err}"
    );
}
