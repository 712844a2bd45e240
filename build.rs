//! Compiles every GLSL shader in `shaders/` to SPIR-V in `OUT_DIR` (`NAME.EXT.spv`) through the
//! `glslang` crate, so no system shader compiler is needed. A GLSL error fails the build with
//! lines formatted `shaders/NAME:LINE: message`. A line `#include "NAME.glsl"` is replaced by
//! that file of `shaders/` (expanded in turn, a few levels deep; line numbers then count the
//! spliced text), so shaders that differ only in their inputs share one body.

use std::fs;
use std::path::{Path, PathBuf};

use glslang::{
    Compiler, CompilerOptions, ShaderInput, ShaderSource, ShaderStage, SpirvVersion, Target,
    VulkanVersion,
};

fn main() {
    let out_dir = PathBuf::from(std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    println!("cargo:rerun-if-changed=shaders");

    let mut files: Vec<PathBuf> = fs::read_dir("shaders")
        .expect("shaders/ directory is missing")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| stage_of(p).is_some())
        .collect();
    files.sort();

    let compiler = Compiler::acquire().expect("glslang compiler already acquired");
    let mut failures = Vec::new();
    for path in &files {
        println!("cargo:rerun-if-changed={}", path.display());
        match compile(compiler, path) {
            Ok(words) => {
                let name = path.file_name().expect("file has a name").to_string_lossy();
                let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
                let dst = out_dir.join(format!("{name}.spv"));
                fs::write(&dst, bytes)
                    .unwrap_or_else(|e| panic!("cannot write {}: {e}", dst.display()));
            }
            Err(lines) => failures.extend(lines),
        }
    }
    if !failures.is_empty() {
        for line in &failures {
            eprintln!("{line}");
        }
        // A plain exit keeps cargo's output to the formatted lines (no build-script backtrace).
        std::process::exit(1);
    }
}

fn stage_of(path: &Path) -> Option<ShaderStage> {
    match path.extension()?.to_str()? {
        "vert" => Some(ShaderStage::Vertex),
        "frag" => Some(ShaderStage::Fragment),
        "comp" => Some(ShaderStage::Compute),
        _ => None,
    }
}

/// Returns SPIR-V words or the error lines, already in `shaders/NAME:LINE: message` form.
fn compile(compiler: &Compiler, path: &Path) -> Result<Vec<u32>, Vec<String>> {
    let display = format!(
        "shaders/{}",
        path.file_name()
            .map(|n| n.to_string_lossy())
            .unwrap_or_default()
    );
    let stage = stage_of(path).ok_or_else(|| vec![format!("{display}:0: unknown stage")])?;
    let text = fs::read_to_string(path).map_err(|e| vec![format!("{display}:0: {e}")])?;
    let source = ShaderSource::from(expand_includes(&text, &display)?);
    let options = CompilerOptions {
        target: Target::Vulkan {
            version: VulkanVersion::Vulkan1_3,
            spirv_version: SpirvVersion::SPIRV1_6,
        },
        ..CompilerOptions::default()
    };
    let input = ShaderInput::new(
        &source,
        stage,
        &options,
        None::<&[(&str, Option<&str>)]>,
        None,
    )
    .map_err(|e| vec![format!("{display}:1: {e}")])?;
    let shader = compiler
        .create_shader(input)
        .map_err(|e| format_log(&display, &e))?;
    shader.compile().map_err(|e| format_log(&display, &e))
}

/// `text` with each `#include "NAME.glsl"` line replaced by `shaders/NAME.glsl`, itself
/// expanded.
fn expand_includes(text: &str, display: &str) -> Result<String, Vec<String>> {
    expand_nested(text, display, 0)
}

fn expand_nested(text: &str, display: &str, depth: usize) -> Result<String, Vec<String>> {
    if depth > 4 {
        return Err(vec![format!("{display}:1: #include nested too deeply")]);
    }
    let mut out = String::with_capacity(text.len());
    for (n, line) in text.lines().enumerate() {
        let included = line
            .trim()
            .strip_prefix("#include")
            .map(|rest| rest.trim().trim_matches('"'));
        match included {
            Some(name) => {
                let path = Path::new("shaders").join(name);
                println!("cargo:rerun-if-changed={}", path.display());
                let body = fs::read_to_string(&path)
                    .map_err(|e| vec![format!("{display}:{}: {name}: {e}", n + 1)])?;
                out.push_str(&expand_nested(&body, display, depth + 1)?);
            }
            None => out.push_str(line),
        }
        out.push('\n');
    }
    Ok(out)
}

/// glslang reports `ERROR: 0:LINE: message`; rewrite that to `shaders/NAME:LINE: message`.
fn format_log(display: &str, err: &glslang::error::GlslangError) -> Vec<String> {
    use glslang::error::GlslangError as E;
    let log = match err {
        E::PreprocessError(l) | E::ParseError(l) | E::MapIoError(l) | E::LinkError(l) => &l.log,
        other => return vec![format!("{display}:1: {other}")],
    };
    let mut lines = Vec::new();
    for raw in log.lines() {
        let Some(rest) = raw
            .strip_prefix("ERROR: ")
            .or_else(|| raw.strip_prefix("WARNING: "))
        else {
            continue;
        };
        // rest = "0:12: 'x' : undeclared identifier" or "N compilation errors.  No code generated."
        let mut parts = rest.splitn(3, ':');
        match (parts.next(), parts.next(), parts.next()) {
            // glslang's trailing "'' : compilation terminated" repeats the last error.
            (Some(_src), Some(line), Some(msg))
                if line.trim().parse::<u32>().is_ok()
                    && !msg.contains("compilation terminated") =>
            {
                lines.push(format!("{display}:{}: {}", line.trim(), msg.trim()));
            }
            (Some(_src), Some(line), Some(_)) if line.trim().parse::<u32>().is_ok() => {}
            _ if raw.starts_with("ERROR: ") && !rest.contains("compilation errors") => {
                lines.push(format!("{display}:1: {}", rest.trim()));
            }
            _ => {}
        }
    }
    if lines.is_empty() {
        lines.push(format!("{display}:1: {}", log.trim().replace('\n', " ")));
    }
    lines
}
