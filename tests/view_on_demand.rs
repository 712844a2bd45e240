//! `prespline view` under X (Xvfb in `make test`) on lavapipe: an idle viewer draws nothing,
//! and a lost GPU device ends the viewer with one clear error line.
//!
//! Frames are counted from the `--profile` report (one line per drawn frame), never timed:
//! a session that quits after 6.5 s without input draws exactly as many frames as one that
//! quits after 1.5 s, so none were drawn in the 5 s between.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn display() -> bool {
    let ok = std::env::var_os("DISPLAY").is_some_and(|d| !d.is_empty());
    if !ok {
        assert!(
            std::env::var_os("CI").is_none(),
            "CI is set but DISPLAY is not: run under Xvfb (make test does)"
        );
        eprintln!("skipped: DISPLAY is not set (make test runs this under Xvfb)");
    }
    ok
}

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

/// Runs the viewer without input until a scripted quit at `quit_s` seconds; returns the
/// number of frames it drew.
fn frames_until_quit(dir: &Path, quit_s: f64) -> usize {
    let script = dir.join(format!("quit-{quit_s}.json"));
    std::fs::write(&script, format!(r#"[{{"t": {quit_s}, "quit": true}}]"#)).unwrap();
    let profile = dir.join(format!("profile-{quit_s}"));
    let out = prespline()
        .arg("view")
        .arg(example())
        .args(["--size", "320x240", "--script"])
        .arg(&script)
        .arg("--profile")
        .arg(&profile)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "viewer failed: {err}");
    let csv = std::fs::read_to_string(profile.join("frames.csv")).unwrap();
    csv.lines().count() - 1
}

#[test]
fn an_idle_viewer_draws_no_frames() {
    if !display() {
        return;
    }
    let dir = scratch("idle");
    let short = frames_until_quit(&dir, 1.5);
    let long = frames_until_quit(&dir, 6.5);
    eprintln!("frames: {short} when quitting at 1.5 s, {long} at 6.5 s");
    // Start-up (first frame, window events, the overlay's settle tick) and the quit frame.
    assert!(
        (2..=8).contains(&short),
        "{short} frames in a short idle session"
    );
    assert_eq!(
        long, short,
        "frames were drawn during 5 s without input ({long} against {short})"
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
    prespline()
        .arg("view")
        .arg(example())
        .args(["--size", "320x240", "--script"])
        .arg(&script)
        .env("PRESPLINE_FAULT", "device-lost@6")
        .output()
        .unwrap()
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
