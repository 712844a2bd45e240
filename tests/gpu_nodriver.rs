//! With no usable Vulkan driver, creating a renderer fails with one clear line saying what
//! to install. (Own test binary: the driver override is process-wide.)
//!
//! `make test` exports `VK_DRIVER_FILES` for lavapipe, and an environment variable cannot be
//! changed safely once threads run, so the check runs in a child process of this binary whose
//! environment points the loader at a driver manifest that does not exist: it runs under
//! `make test` and CI like anywhere else, and never skips.

mod common;

use prespline::gpu::{GpuError, Renderer, RendererDesc};
use std::process::Command;

const BOGUS: &str = "/nonexistent/prespline-no-such-icd.json";
/// Set in the child process.
const CHILD: &str = "PRESPLINE_NODRIVER_CHILD";

/// The check itself, in a process whose loader sees only the bogus manifest.
fn check_missing_driver() {
    assert_eq!(
        std::env::var("VK_DRIVER_FILES").as_deref(),
        Ok(BOGUS),
        "the child must see only the bogus driver"
    );
    let err = match Renderer::new(&RendererDesc::default()) {
        Ok(_) => panic!("a renderer was created without any driver"),
        Err(e) => e,
    };
    assert!(
        matches!(err, GpuError::NoDriver(_) | GpuError::NoLoader(_)),
        "unexpected error: {err:?}"
    );
    let text = err.to_string();
    eprintln!("error shown to users: {text}");
    assert!(!text.contains('\n'), "not one line: {text}");
    assert!(
        text.contains("mesa-vulkan-drivers") && text.contains("libvulkan1"),
        "no install hint: {text}"
    );
}

#[test]
fn missing_driver_is_one_clear_error() {
    if std::env::var_os(CHILD).is_some() {
        return check_missing_driver();
    }
    let out = Command::new(std::env::current_exe().unwrap())
        .args([
            "--exact",
            "missing_driver_is_one_clear_error",
            "--nocapture",
        ])
        .env(CHILD, "1")
        .env("VK_DRIVER_FILES", BOGUS)
        .env("VK_ICD_FILENAMES", BOGUS)
        .env_remove("VK_ADD_DRIVER_FILES")
        .output()
        .unwrap();
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        out.status.success() && text.contains("1 passed") && text.contains("error shown to users"),
        "the no-driver check failed or did not run in the child:\n{text}"
    );
}

/// The same from the command line: `prespline render` without a driver exits non-zero with
/// the one-line hint, nothing else. Validation off, as in the release binary users run (with
/// the layer on, the loader's own messages are echoed too).
#[test]
fn render_without_a_driver_says_what_to_install() {
    let scene = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/bezier_curve.json");
    let png = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("nodriver-{}.png", std::process::id()));
    let out = Command::new(env!("CARGO_BIN_EXE_prespline"))
        .arg("render")
        .arg(&scene)
        .arg("--out")
        .arg(&png)
        .env("VK_DRIVER_FILES", BOGUS)
        .env("VK_ICD_FILENAMES", BOGUS)
        .env_remove("VK_ADD_DRIVER_FILES")
        .env("PRESPLINE_VALIDATION", "0")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "rendered without a driver: {err}");
    assert_eq!(err.lines().count(), 1, "not one line: {err}");
    assert!(
        err.starts_with("error: ") && err.contains("mesa-vulkan-drivers"),
        "{err}"
    );
    assert!(!png.exists(), "an image was written without a driver");
}
