//! What `prespline help` promises: the viewer's help points to its documentation and describes
//! the demo scene as it is; `render --help` names the image formats `--out` takes.

use std::process::Command;

/// The help text of `prespline help COMMAND`, with clap's line wrapping undone.
fn help(command: &str) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_prespline"))
        .args(["help", command])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout)
        .unwrap()
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
}

/// `help view` names docs/viewer.md (which exists) and every kind of object of the demo it
/// describes, the closed ERBS torus included, and the demo has that torus.
#[test]
fn help_view_names_the_viewer_docs_and_the_erbs_torus() {
    let text = help("view");
    assert!(text.contains("docs/viewer.md"), "{text}");
    assert!(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("docs/viewer.md")
            .is_file()
    );
    for part in [
        "B-spline surface",
        "ERBS surface and curve",
        "NURBS circle",
        "closed ERBS torus",
        "Utah teapot",
    ] {
        assert!(text.contains(part), "help view lacks {part:?}: {text}");
    }
    let demo = prespline::formats::demo::demo_scene();
    assert!(demo.objects.iter().any(|o| o.name == "erbs_torus"));
}

/// `render --help` says `--out` writes PNG or JPEG by the extension, not PNG only.
#[test]
fn help_render_names_png_and_jpeg() {
    let text = help("render");
    assert!(
        text.contains("into a PNG or JPEG image (by the extension)"),
        "{text}"
    );
    assert!(
        text.contains("PNG for .png, JPEG for .jpg or .jpeg"),
        "{text}"
    );
}

/// docs/viewer.md's option table names exactly the options `view --help` lists, so neither
/// can gain one the other lacks (negative control: a list with one left out differs).
#[test]
fn the_viewer_docs_list_every_view_option() {
    let options = |text: &str, start: &str| -> Vec<String> {
        let mut found: Vec<String> = text
            .lines()
            .filter_map(|l| l.trim_start().strip_prefix(start))
            .filter_map(|rest| rest.split(['`', ' ', '[', '=', '<']).next())
            .filter(|name| !name.is_empty() && *name != "help")
            .map(str::to_string)
            .collect();
        found.sort();
        found.dedup();
        found
    };
    let raw = Command::new(env!("CARGO_BIN_EXE_prespline"))
        .args(["help", "view"])
        .output()
        .unwrap();
    let from_help = options(&String::from_utf8(raw.stdout).unwrap(), "--");
    let doc =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/viewer.md")).unwrap();
    let from_doc = options(&doc, "| `--");
    assert!(from_help.len() >= 12, "{from_help:?}");
    assert_eq!(from_doc, from_help);
    let mut short = from_doc.clone();
    short.pop();
    assert_ne!(short, from_help);
}
