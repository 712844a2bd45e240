//! `prespline render`: draws a scene headless into a PNG or JPEG file (by the extension).

use super::CliError;
use super::args::{DisplayArgs, MemoryArgs, SamplesArgs, parse_size};
use super::load::{Notes, load_scene};
use super::resident::{MemoryReport, Resident, image_bytes};
use super::samples::SampleOverride;
use crate::editor::{Document, Editor, EditorOptions, ListRefused};
use crate::gpu::{Renderer, RendererDesc};
use crate::render::OrbitCamera;
use crate::render::image_file::{ImageFormat, write_image};
use crate::render::maps::SurfaceMap;
use crate::render::offscreen::{Shot, render_document};
use crate::sampling::SampleMode;
use crate::sampling::budget::MemoryBudget;
use crate::scene::{EditList, Scene, escape_controls};
use clap::Args;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Render a scene headless (no display needed) into a PNG or JPEG image (by the extension).
#[derive(Args, Debug, Clone)]
pub struct RenderArgs {
    /// Scene file: JSON, Wavefront OBJ (.obj), STEP (.stp, .step) or IGES (.igs, .iges), by extension.
    pub scene: PathBuf,
    /// Output image: PNG for .png, JPEG for .jpg or .jpeg; other extensions are refused.
    #[arg(long, short = 'o', value_name = "IMAGE.png|IMAGE.jpg")]
    pub out: PathBuf,
    /// Image size.
    #[arg(long, default_value = "1280x720", value_parser = parse_size, value_name = "WxH")]
    pub size: (u32, u32),
    /// Camera as eye and target, optionally the vertical field of view in degrees:
    /// EX,EY,EZ,TX,TY,TZ[,FOV]. Default: frames the whole scene.
    #[arg(long, value_parser = OrbitCamera::parse, value_name = "EYE,TARGET[,FOV]", allow_hyphen_values = true)]
    pub camera: Option<OrbitCamera>,
    /// Edits (JSON list) applied before rendering.
    #[arg(long, value_name = "EDITS.json")]
    pub edits: Option<PathBuf>,
    /// MSAA samples (1, 2, 4, 8); a still image is worth 4; 0 picks the device's interactive
    /// default (1 on CPU rasterisers, 4 on GPUs).
    #[arg(long, default_value_t = 4)]
    pub msaa: u32,
    /// Draw the osculating circle of curve NAME at parameter T, labelled with its
    /// curvature, radius and torsion.
    #[arg(long, value_name = "NAME@T", value_parser = parse_osculating)]
    pub osculating: Option<(String, f64)>,
    #[command(flatten)]
    pub display: DisplayArgs,
    #[command(flatten)]
    pub samples: SamplesArgs,
    #[command(flatten)]
    pub memory: MemoryArgs,
    /// After writing the image, print the memory budget's estimate of the scene next to
    /// what it made resident (peak resident size less the program and the Vulkan driver).
    #[arg(long)]
    pub memory_report: bool,
    /// Print how long each phase took: load (parse, trims, pre-evaluation), the Vulkan device
    /// (started beside the load, so only its wait counts), drawing and reading back, writing
    /// the image.
    #[arg(long)]
    pub timings: bool,
}

/// Loads, edits and renders; prints the closing line (and the memory report).
///
/// The Vulkan device starts on a second thread while the scene loads (instance, device, the
/// driver's start and the surface pipelines' compilation take tens of milliseconds on
/// lavapipe), except with `--memory-report`,
/// which measures what the driver adds apart from what the scene does.
pub fn run(args: RenderArgs) -> Result<(), CliError> {
    let start = Instant::now();
    let before = Resident::read();
    ImageFormat::of(&args.out).map_err(CliError)?;
    let msaa = args.msaa;
    let early = (!args.memory_report).then(|| {
        std::thread::spawn(move || {
            let mut r = start_renderer()?;
            r.warm_offscreen(msaa)
                .map_err(|e| CliError(e.to_string()))?;
            Ok(r)
        })
    });
    let loaded_doc = load_document(
        &args.scene,
        args.edits.as_deref(),
        &args.samples.counts(),
        &args.memory.budget(),
        args.display.analysis,
        args.display.net,
    );
    let loaded = start.elapsed();
    let renderer = match early.map(std::thread::JoinHandle::join) {
        Some(Ok(r)) => Some(r),
        Some(Err(_)) => Some(Err(CliError("the Vulkan device's start failed".into()))),
        None => None,
    };
    // The device thread has finished either way: a process must not exit while the driver
    // starts on another thread (its exit handlers would free what that thread still uses).
    let (doc, estimate, notes) = loaded_doc?;
    let renderer = renderer.transpose()?;
    let waited = start.elapsed() - loaded;
    let mut options = args.display.options();
    if let Some((name, t)) = &args.osculating {
        options.osculating_at = Some(osculating_at(&doc, name, *t)?);
    }
    let probe = before
        .filter(|_| args.memory_report)
        .map(|before| MemoryProbe { estimate, before });
    let (w, h) = args.size;
    let shot = Shot {
        width: w,
        height: h,
        camera: args.camera,
        options,
        msaa: args.msaa,
    };
    let lines = render_image(&doc, &args.out, shot, probe, renderer);
    // The process ends with this command: freeing a large scene's allocations one by one
    // (two per object and more) would only delay the exit.
    std::mem::forget(doc);
    let (line, report, phases) = lines?;
    notes.print();
    eprintln!("{}", escape_controls(&line));
    if let Some(r) = report {
        eprintln!("{r}");
    } else if args.memory_report {
        eprintln!("memory: the resident size is not readable here (/proc/self/status)");
    }
    if args.timings {
        eprintln!(
            "timings: load {:.1} ms, device wait {:.1} ms, draw and read back {:.1} ms, write {:.1} ms, total {:.1} ms",
            ms(loaded),
            ms(waited + phases.device),
            ms(phases.draw),
            ms(phases.write),
            ms(start.elapsed())
        );
    }
    Ok(())
}

fn ms(d: std::time::Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// A headless renderer with the validation layer as `PRESPLINE_VALIDATION` says.
fn start_renderer() -> Result<Renderer, CliError> {
    Renderer::new(&RendererDesc {
        app_name: "prespline render".into(),
        validation: validation_mode(),
        ..RendererDesc::default()
    })
    .map_err(|e| CliError(e.to_string()))
}

/// How long [`render_image`]'s phases took.
#[derive(Debug, Clone, Copy, Default)]
pub struct Phases {
    /// Starting the renderer, or waiting for it.
    pub device: std::time::Duration,
    /// Uploading, drawing and reading the pixels back.
    pub draw: std::time::Duration,
    /// Encoding and writing the image.
    pub write: std::time::Duration,
}

/// `NAME@T` of `--osculating`.
pub fn parse_osculating(s: &str) -> Result<(String, f64), String> {
    let (name, t) = s
        .rsplit_once('@')
        .ok_or_else(|| format!("'{s}' is not NAME@T"))?;
    let t: f64 = t
        .parse()
        .ok()
        .filter(|t: &f64| t.is_finite())
        .ok_or_else(|| format!("'{t}' is not a parameter value"))?;
    Ok((name.to_string(), t))
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

/// Loads a scene (any format the registry reads) into an editor held to the memory budget and applies an edits
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
) -> Result<(Document, u64, Notes), CliError> {
    let (scene, notes) = load_scene(scene_path, samples, budget)?;
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
    Ok((editor.into_document(), estimate, notes))
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

/// Renders `doc` headless with `renderer` (one is started when `None`) and writes `out` (PNG
/// or JPEG, by its extension); returns a one-line summary, with `probe` the
/// `--memory-report` line, and the phases' times.
pub fn render_image(
    doc: &Document,
    out: &Path,
    shot: Shot,
    probe: Option<MemoryProbe>,
    renderer: Option<Renderer>,
) -> Result<(String, Option<String>, Phases), CliError> {
    let (width, height) = (shot.width, shot.height);
    let start = Instant::now();
    // An image name that names no format the renderer writes is refused before anything runs.
    ImageFormat::of(out).map_err(CliError)?;
    let before_driver = Resident::read();
    let mut renderer = match renderer {
        Some(r) => r,
        None => start_renderer()?,
    };
    let after_driver = Resident::read();
    let mut phases = Phases {
        device: start.elapsed(),
        ..Phases::default()
    };
    let pixels = render_document(&mut renderer, doc, &shot).map_err(|e| CliError(e.to_string()))?;
    let sink = renderer.validation_sink();
    let device = renderer.caps().name.clone();
    let samples = match shot.msaa {
        0 => renderer.caps().default_samples(),
        n => n,
    };
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
    phases.draw = start.elapsed() - phases.device;
    write_image(&pixels, out).map_err(CliError)?;
    phases.write = start.elapsed() - phases.device - phases.draw;
    let summary = format!(
        "wrote {} ({width}x{height}, {} objects, {device}, {:.0} ms)",
        out.display(),
        doc.objects.len(),
        start.elapsed().as_secs_f64() * 1e3
    );
    let report = probe.map(|p| match (before_driver, after_driver, Resident::read()) {
        (Some(a), Some(b), Some(end)) => MemoryReport {
            estimate: p.estimate,
            image: image_bytes(width, height, samples),
            peak: end.peak,
            program: p.before.now,
            driver: b.now.saturating_sub(a.now),
        }
        .line(),
        _ => "memory: the resident size is not readable here (/proc/self/status)".into(),
    });
    Ok((summary, report, phases))
}
