//! `prespline render` run the way a user runs it (on lavapipe).

use std::path::Path;
use std::process::Command;

fn prespline() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_prespline"));
    let icd = "/usr/share/vulkan/icd.d/lvp_icd.x86_64.json";
    c.env("VK_DRIVER_FILES", icd)
        .env("VK_ICD_FILENAMES", icd)
        .env("PRESPLINE_VALIDATION", "required");
    c
}

#[test]
fn renders_a_png_with_edits_and_camera() {
    let dir = std::env::temp_dir().join(format!("prespline-cli-render-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let edits = dir.join("edits.json");
    std::fs::write(
        &edits,
        r#"[{"object": "bumps", "point": [3, 3], "delta": [0, 0, -2]}]"#,
    )
    .unwrap();
    let out = dir.join("bumps.png");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/bspline_surface.json");
    let r = prespline()
        .arg("render")
        .arg(&scene)
        .arg("--out")
        .arg(&out)
        .args([
            "--size",
            "320x200",
            "--camera",
            "-6,-6,5,0,0,0,45",
            "--net",
            "--wire",
            "4",
        ])
        .arg("--edits")
        .arg(&edits)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(r.status.success(), "{err}");
    assert!(err.contains("wrote") && err.contains("320x200"), "{err}");
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&out).unwrap()));
    let reader = decoder.read_info().unwrap();
    assert_eq!((reader.info().width, reader.info().height), (320, 200));
}

#[test]
fn bad_input_is_one_line() {
    let dir = std::env::temp_dir();
    let r = prespline()
        .args(["render", "/nonexistent.json", "--out"])
        .arg(dir.join("x.png"))
        .output()
        .unwrap();
    assert!(!r.status.success());
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("cannot read /nonexistent.json"), "{err}");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/teapot.json");
    for (flag, value, msg) in [
        ("--size", "0x10", "within 1..16384"),
        ("--camera", "1,2,3", "EX,EY,EZ,TX,TY,TZ"),
    ] {
        let r = prespline()
            .arg("render")
            .arg(&scene)
            .args(["--out", "/tmp/x.png", flag, value])
            .output()
            .unwrap();
        assert!(!r.status.success());
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(err.contains(msg), "{flag} {value}: {err}");
    }
}
