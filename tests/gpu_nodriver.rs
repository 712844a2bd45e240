//! With no usable Vulkan driver, the program fails with one clear line saying what to install.
//! The driver override is set on a child process (the process environment is not ours to
//! change while test threads run).

use std::process::Command;

#[test]
fn missing_driver_is_one_clear_error() {
    let bogus = "/nonexistent/prespline-no-such-icd.json";
    let example = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/teapot.json");
    let out_png =
        std::env::temp_dir().join(format!("prespline-nodriver-{}.png", std::process::id()));
    let out = Command::new(env!("CARGO_BIN_EXE_prespline"))
        .arg("render")
        .arg(&example)
        .arg("--out")
        .arg(&out_png)
        .env("VK_DRIVER_FILES", bogus)
        .env("VK_ICD_FILENAMES", bogus)
        .env_remove("PRESPLINE_VALIDATION")
        .output()
        .expect("run prespline");
    assert!(!out.status.success(), "rendered without any driver");
    assert!(!out_png.exists(), "an image was written without a driver");
    let err = String::from_utf8_lossy(&out.stderr);
    eprintln!("error shown to users: {err}");
    let lines: Vec<&str> = err.lines().filter(|l| l.starts_with("error:")).collect();
    assert_eq!(lines.len(), 1, "not one error line: {err}");
    assert!(
        lines[0].contains("mesa-vulkan-drivers") && lines[0].contains("libvulkan1"),
        "no install hint: {err}"
    );
}
