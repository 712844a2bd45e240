//! `prespline render`: draws a scene headless into a PNG file.

use super::CliError;
use super::files::{SampleOverride, load_scene};
use crate::gpu::{Renderer, RendererDesc, ValidationMode};
use crate::render::maps::SurfaceMap;
use crate::render::offscreen::{Shot, render_document};
use crate::render::{Document, OrbitCamera, ViewOptions};
use crate::sampling::SampleMode;
use crate::sampling::budget::{MemoryBudget, Uses, check_scene};
use crate::scene::edit::{apply_all, parse_edits};
use crate::scene::{Scene, SceneError};
use std::path::Path;
use std::time::Instant;

/// Parses `WIDTHxHEIGHT`.
pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("'{s}' is not WIDTHxHEIGHT"))?;
    let w: u32 = w
        .trim()
        .parse()
        .map_err(|_| format!("'{w}' is not a width"))?;
    let h: u32 = h
        .trim()
        .parse()
        .map_err(|_| format!("'{h}' is not a height"))?;
    if !(1..=16384).contains(&w) || !(1..=16384).contains(&h) {
        return Err(format!("{w}x{h}: width and height must be within 1..16384"));
    }
    Ok((w, h))
}

/// Validation layer policy for interactive commands: on in debug builds or with
/// `PRESPLINE_VALIDATION=1`, when the layer is installed; `PRESPLINE_VALIDATION=required`
/// refuses to run without it (tests must not pass unvalidated); `0` turns it off.
pub fn validation_mode() -> ValidationMode {
    let env = std::env::var("PRESPLINE_VALIDATION").ok();
    match env.as_deref() {
        Some("required") => ValidationMode::Required,
        Some("1") => ValidationMode::IfAvailable,
        Some("0") => ValidationMode::Off,
        _ if cfg!(debug_assertions) => ValidationMode::IfAvailable,
        _ => ValidationMode::Off,
    }
}

/// What drawing commands (`render`, `view`, `bench`) keep per object.
pub const DRAW_USES: Uses = Uses {
    gpu: true,
    json_text: false,
};

/// Refuses a scene whose pre-evaluation and GPU mirrors would not fit `budget` (one line naming
/// the object and the estimate).
pub fn check_drawable(scene: &Scene, path: &Path, budget: &MemoryBudget) -> Result<(), CliError> {
    check_scene(scene, SampleMode::Render, DRAW_USES, budget)
        .map(|_| ())
        .map_err(|e| CliError::in_file(path, e))
}

/// Loads a scene (JSON or OBJ), checks it against the memory budget and applies an edits file
/// (through the delta path; edits that refine the model are budgeted too).
pub fn load_document(
    scene_path: &Path,
    edits: Option<&Path>,
    samples: &SampleOverride,
    budget: &MemoryBudget,
) -> Result<Document, CliError> {
    let scene = load_scene(scene_path, samples)?;
    check_drawable(&scene, scene_path, budget)?;
    let Some(path) = edits else {
        return Ok(Document::new(&scene));
    };
    let text = std::fs::read_to_string(path)
        .map_err(|e| CliError(format!("cannot read {}: {e}", path.display())))?;
    let edits = parse_edits(&text, &scene).map_err(|e| CliError::in_file(path, e))?;
    // Knot insertion and degree elevation grow the tables: budget the edited model too.
    let mut refined = scene.clone();
    apply_all(&mut refined, &edits).map_err(|e| CliError::in_file(path, e))?;
    check_drawable(&refined, scene_path, budget)?;
    let mut doc = Document::new(&scene);
    for e in edits {
        doc.apply(&e)
            .map_err(|err| CliError::in_file(path, SceneError(err.to_string())))?;
    }
    Ok(doc)
}

/// Shows `map` on the document's surfaces (`--analysis`). A curvature map keeps second
/// partials and K, H per sample: the scene is budgeted for that first (one line naming the
/// object when it does not fit).
pub fn show_analysis(
    doc: &mut Document,
    map: Option<SurfaceMap>,
    budget: &MemoryBudget,
) -> Result<(), CliError> {
    check_analysis(&doc.to_scene(), map, budget)?;
    doc.set_analysis(map);
    Ok(())
}

/// Budgets `scene` for `map` (`--analysis`): a curvature map keeps second partials, K and H
/// per sample and a scalar mirror; one line naming the object when that does not fit.
pub fn check_analysis(
    scene: &Scene,
    map: Option<SurfaceMap>,
    budget: &MemoryBudget,
) -> Result<(), CliError> {
    if let Some(m) = map.filter(|m| m.needs_curvature()) {
        check_scene(scene, SampleMode::Analysis, DRAW_USES, budget)
            .map_err(|e| CliError(format!("--analysis {}: {e}", m.name())))?;
    }
    Ok(())
}

/// The object index and parameter of `--osculating NAME@T`, checked: a curve object, T in its
/// domain.
pub fn osculating_at(doc: &Document, name: &str, t: f64) -> Result<(usize, f64), CliError> {
    let i = doc
        .objects
        .iter()
        .position(|o| o.name == name)
        .ok_or_else(|| CliError(format!("--osculating: unknown object '{name}'")))?;
    let model = doc.objects[i].sampled.model();
    if model.is_surface() {
        return Err(CliError(format!(
            "--osculating: object '{name}' is a {}, not a curve",
            model.type_name()
        )));
    }
    let (a, b) = model.domain()[0];
    if !(a..=b).contains(&t) {
        return Err(CliError(format!(
            "--osculating: parameter {t} is outside the domain [{a}, {b}] of object '{name}'"
        )));
    }
    Ok((i, t))
}

/// Renders `doc` headless and writes `out` (PNG); returns a one-line summary.
pub fn run(
    doc: &Document,
    out: &Path,
    width: u32,
    height: u32,
    camera: Option<OrbitCamera>,
    options: ViewOptions,
    msaa: u32,
) -> Result<String, CliError> {
    let start = Instant::now();
    let mut renderer = Renderer::new(&RendererDesc {
        app_name: "prespline render".into(),
        validation: validation_mode(),
        ..RendererDesc::default()
    })
    .map_err(|e| CliError(e.to_string()))?;
    let shot = Shot {
        width,
        height,
        camera,
        options,
        msaa,
    };
    let pixels = render_document(&mut renderer, doc, &shot).map_err(|e| CliError(e.to_string()))?;
    let sink = renderer.validation_sink();
    let device = renderer.caps().name.clone();
    // Teardown first: the layer reports leaked objects when the device is destroyed.
    drop(renderer);
    if let Some(errors) = sink.map(|s| s.errors()).filter(|e| !e.is_empty()) {
        let first = errors[0].to_string();
        return Err(CliError(format!(
            "Vulkan validation reported {} error(s), first: {}",
            errors.len(),
            first.lines().next().unwrap_or("")
        )));
    }
    pixels
        .write_png(out)
        .map_err(|e| CliError(format!("cannot write {}: {e}", out.display())))?;
    Ok(format!(
        "wrote {} ({width}x{height}, {} objects, {device}, {:.0} ms)",
        out.display(),
        doc.objects.len(),
        start.elapsed().as_secs_f64() * 1e3
    ))
}
