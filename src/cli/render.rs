//! `prespline render`: draws a scene headless into a PNG or JPEG file (by the extension).

use super::CliError;
use super::files::{SampleOverride, load_scene};
use super::resident::{MemoryReport, Resident};
use crate::editor::{Document, Editor, EditorOptions, ListRefused};
use crate::gpu::{Renderer, RendererDesc};
use crate::render::image_file::{ImageFormat, write_image};
use crate::render::maps::SurfaceMap;
use crate::render::offscreen::{Shot, render_document};
use crate::render::{OrbitCamera, ViewOptions};
use crate::sampling::SampleMode;
use crate::sampling::budget::MemoryBudget;
use crate::scene::{EditList, Scene};
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

pub use crate::render::{DRAW_USES, render_uses, validation_mode};

/// Refuses a scene whose pre-evaluation and GPU mirrors would not fit `budget` (one line naming
/// the object and the estimate).
pub fn check_drawable(scene: &Scene, path: &Path, budget: &MemoryBudget) -> Result<(), CliError> {
    scene
        .check_budget(SampleMode::Render, DRAW_USES, budget)
        .map(|_| ())
        .map_err(|e| CliError::in_file(path, e))
}

/// Loads a scene (JSON or OBJ) into an editor held to the memory budget and applies an edits
/// file through it (the delta path; edits that grow an object are budgeted as they come), with
/// `map` shown on the surfaces (a curvature map is budgeted first) and, with `nets`, every
/// object's control display drawn.
pub fn load_document(
    scene_path: &Path,
    edits: Option<&Path>,
    samples: &SampleOverride,
    budget: &MemoryBudget,
    map: Option<SurfaceMap>,
    nets: bool,
) -> Result<(Document, u64), CliError> {
    let scene = load_scene(scene_path, samples)?;
    let options = EditorOptions {
        mode: SampleMode::Render,
        uses: render_uses(nets),
        budget: *budget,
    };
    let mut editor = Editor::new(&scene, options).map_err(|e| CliError::in_file(scene_path, e))?;
    if let Some(path) = edits {
        let text = std::fs::read_to_string(path)
            .map_err(|e| CliError(format!("cannot read {}: {e}", path.display())))?;
        let list = EditList::parse(&text).map_err(|e| CliError::in_file(path, e))?;
        editor.submit_list(&list).map_err(|r| match r {
            ListRefused::Edit(e) => CliError::in_file(path, e),
            ListRefused::OverBudget(e) => CliError::in_file(scene_path, e),
        })?;
    }
    if let Some(m) = map.filter(|m| m.needs_curvature()) {
        editor
            .set_surface_mode(SampleMode::Analysis)
            .map_err(|e| CliError(format!("--analysis {}: {e}", m.name())))?;
    }
    let estimate = editor.estimated_bytes();
    Ok((editor.into_document(), estimate))
}

/// Budgets `scene` for `map` (`--analysis`): a curvature map keeps second partials, K and H
/// per sample and a scalar mirror; one line naming the object when that does not fit.
pub fn check_analysis(
    scene: &Scene,
    map: Option<SurfaceMap>,
    budget: &MemoryBudget,
) -> Result<(), CliError> {
    if let Some(m) = map.filter(|m| m.needs_curvature()) {
        scene
            .check_budget(SampleMode::Analysis, DRAW_USES, budget)
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

/// What `--memory-report` needs from before the render: the budget's estimate of the
/// document and the resident size before it was loaded.
#[derive(Debug, Clone, Copy)]
pub struct MemoryProbe {
    pub estimate: u64,
    pub before: Resident,
}

/// Renders `doc` headless and writes `out` (PNG or JPEG, by its extension); returns a one-line summary, and with
/// `probe` the `--memory-report` line.
#[allow(clippy::too_many_arguments)]
pub fn run(
    doc: &Document,
    out: &Path,
    width: u32,
    height: u32,
    camera: Option<OrbitCamera>,
    options: ViewOptions,
    msaa: u32,
    probe: Option<MemoryProbe>,
) -> Result<(String, Option<String>), CliError> {
    let start = Instant::now();
    // An image name that names no format the renderer writes is refused before anything runs.
    ImageFormat::of(out).map_err(CliError)?;
    let before_driver = Resident::read();
    let mut renderer = Renderer::new(&RendererDesc {
        app_name: "prespline render".into(),
        validation: validation_mode(),
        ..RendererDesc::default()
    })
    .map_err(|e| CliError(e.to_string()))?;
    let after_driver = Resident::read();
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
    write_image(&pixels, out).map_err(CliError)?;
    let summary = format!(
        "wrote {} ({width}x{height}, {} objects, {device}, {:.0} ms)",
        out.display(),
        doc.objects.len(),
        start.elapsed().as_secs_f64() * 1e3
    );
    let report = probe.map(|p| match (before_driver, after_driver, Resident::read()) {
        (Some(a), Some(b), Some(end)) => MemoryReport {
            estimate: p.estimate,
            peak: end.peak,
            program: p.before.now,
            driver: b.now.saturating_sub(a.now),
        }
        .line(),
        _ => "memory: the resident size is not readable here (/proc/self/status)".into(),
    });
    Ok((summary, report))
}
