//! The unsafe-code rules hold and are enforced by the compiler, not by convention: the crate
//! roots deny `unsafe_code` and only `gpu` is allowed it; clippy's `undocumented_unsafe_blocks`
//! is on (so `make test`'s `clippy -D warnings` fails an unsafe block without a `// SAFETY:`
//! reason); and, read from the sources, every unsafe block has that reason and every
//! `unsafe fn` a `# Safety` section.

use std::path::{Path, PathBuf};

fn source(path: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join(path);
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// Code lines (comments stripped) with `unsafe` used as a keyword.
fn unsafe_lines(text: &str) -> Vec<(usize, String)> {
    text.lines()
        .enumerate()
        .filter_map(|(i, line)| {
            let code = line.split("//").next().unwrap_or("");
            let uses = ["unsafe {", "unsafe fn", "unsafe impl", "unsafe extern"]
                .iter()
                .any(|k| code.contains(k));
            uses.then(|| (i, line.to_string()))
        })
        .collect()
}

#[test]
fn crate_roots_deny_unsafe_code_outside_gpu() {
    let lib = source("src/lib.rs");
    for attr in [
        "#![deny(unsafe_code)]",
        "#![warn(clippy::undocumented_unsafe_blocks)]",
    ] {
        assert!(lib.contains(attr), "src/lib.rs lacks {attr}");
    }
    assert!(
        lib.contains("#[allow(unsafe_code)]\npub mod gpu;"),
        "only `gpu` may be allowed unsafe code"
    );
    assert_eq!(lib.matches("allow(unsafe_code)").count(), 1);
    assert!(source("src/main.rs").contains("#![deny(unsafe_code)]"));
}

#[test]
fn unsafe_code_is_only_in_gpu_and_always_explained() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    // Tests, benchmarks and examples too: a counting allocator in a test is `unsafe impl`
    // like any other (tests/budget_accuracy.rs takes one from `stats_alloc` instead).
    for dir in ["src", "tests", "benches", "examples"] {
        rust_files(&root.join(dir), &mut files);
    }
    // This file names the keywords it looks for.
    files.retain(|f| !f.ends_with("tests/cpu/lints.rs"));
    let gpu = root.join("src/gpu");
    let mut blocks = 0;
    for file in files {
        let text = std::fs::read_to_string(&file).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        for (i, line) in unsafe_lines(&text) {
            let at = format!("{}:{}", file.display(), i + 1);
            assert!(
                file.starts_with(&gpu),
                "{at}: unsafe outside src/gpu: {line}"
            );
            // The comments and attributes just above (or on) the line.
            let above: Vec<&str> = lines[..i]
                .iter()
                .rev()
                .take_while(|l| {
                    let t = l.trim_start();
                    t.starts_with("//") || t.starts_with("#[") || t.starts_with("///")
                })
                .copied()
                .collect();
            if line.contains("unsafe fn") || line.contains("unsafe extern") {
                assert!(
                    above.iter().any(|l| l.contains("# Safety")),
                    "{at}: an unsafe fn needs a `# Safety` section: {line}"
                );
            } else if line.contains("unsafe {") {
                blocks += 1;
                let explained = line.contains("SAFETY:")
                    || above.iter().any(|l| l.contains("SAFETY:"))
                    // A block continuing an expression started on the line(s) above.
                    || lines[..i]
                        .iter()
                        .rev()
                        .take(4)
                        .any(|l| l.contains("// SAFETY:"));
                assert!(explained, "{at}: unsafe block without `// SAFETY:`: {line}");
            }
        }
    }
    assert!(blocks > 0, "no unsafe blocks found: the scan is broken");
}

/// Every repository path the documentation names in backticks (`src/…`, `tests/…`,
/// `examples/…`, …) exists, so moved files cannot leave the docs pointing nowhere. A path
/// may end in `:LINE` or name a folder; globs and placeholders (`*`, `…`, `<`, `{`, a word
/// in capitals) are skipped. Negative control: a made-up path in the same text is reported.
#[test]
fn paths_named_in_the_docs_exist() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root.join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.push(root.join("README.md"));
    docs.push(root.join("src/gpu/README.md"));
    let mut missing = Vec::new();
    for doc in &docs {
        let text = std::fs::read_to_string(doc).unwrap();
        for path in named_paths(&text) {
            if !root.join(&path).exists() {
                missing.push(format!("{}: {path}", doc.display()));
            }
        }
    }
    assert!(
        missing.is_empty(),
        "paths that do not exist:\n{}",
        missing.join("\n")
    );
    let control = named_paths("see `src/sampling/no_such_file.rs:12` and `tests/cpu/lints.rs`");
    assert_eq!(
        control,
        ["src/sampling/no_such_file.rs", "tests/cpu/lints.rs"]
    );
    assert!(!root.join(&control[0]).exists() && root.join(&control[1]).exists());
}

/// The repository paths in backticks in `text`, without a `:LINE` suffix.
fn named_paths(text: &str) -> Vec<String> {
    const ROOTS: [&str; 9] = [
        "src/",
        "tests/",
        "examples/",
        "benches/",
        "shaders/",
        "docs/",
        "scripts/",
        ".ci/",
        "build.rs",
    ];
    text.split('`')
        .skip(1)
        .step_by(2)
        .filter(|s| ROOTS.iter().any(|r| s.starts_with(r)))
        .filter(|s| !s.contains(['*', '…', '<', '{', ' ', '$']))
        // A placeholder in capitals (`tests/golden/NAME.png`).
        .filter(|s| {
            !s.split(['/', '.'])
                .any(|w| w.len() > 1 && w.chars().all(|c| c.is_ascii_uppercase()))
        })
        .map(|s| {
            s.split(':')
                .next()
                .unwrap_or(s)
                .trim_end_matches('/')
                .to_string()
        })
        .collect()
}
