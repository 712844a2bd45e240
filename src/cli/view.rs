//! `prespline view`: the interactive viewer.

use super::CliError;
use super::files::{SampleOverride, load_scene};
use crate::profile::{RunInfo, Summary, write_all};
use crate::sampling::budget::MemoryBudget;
use crate::scene::Scene;
use crate::scene::demo::demo_scene;
use crate::view::app::{self, ViewArgs};
use crate::view::autosave::{Autosave, Places, state_dir};
use crate::view::script::parse_script;
use std::path::{Path, PathBuf};

/// Where Ctrl+S writes the demo scene.
const DEMO_SAVE: &str = "prespline-demo.json";

/// Command-line options of `prespline view`.
#[derive(Debug, Clone, Copy)]
pub struct ViewOptions<'a> {
    pub scene: Option<&'a Path>,
    pub size: (u32, u32),
    pub vsync: bool,
    pub script: Option<&'a Path>,
    pub save_as: Option<&'a Path>,
    pub profile: Option<&'a Path>,
    /// `--samples` overrides for the loaded scene.
    pub samples: SampleOverride,
    /// What pre-evaluation and the GPU mirrors may take.
    pub memory: MemoryBudget,
    /// Open an autosave (unsaved edits of an earlier session) instead of the scene: `Some(None)`
    /// the newest, `Some(Some(FILE))` the one named.
    pub recover: Option<Option<&'a Path>>,
    /// A surface analysis map shown from the start (`--analysis`; M cycles it later).
    pub analysis: Option<crate::render::maps::SurfaceMap>,
    /// How the map's colour scale is chosen (`--map-range`).
    pub map_range: crate::render::maps::MapRange,
    /// How gestures redraw (`--redraw`).
    pub redraw: crate::render::Redraw,
}

pub fn run(opts: &ViewOptions) -> Result<(), CliError> {
    let places = Places::new(opts.scene, state_dir().as_deref());
    let recovered = match opts.recover {
        Some(named) => Some(recover_file(&places, named)?),
        None => None,
    };
    let (scene, title, default_save) = match (&recovered, opts.scene) {
        (Some(file), scene) => {
            let mut loaded = Scene::load(file).map_err(|e| CliError::in_file(file, e))?;
            opts.samples.apply(&mut loaded)?;
            let (title, save) = match scene {
                Some(p) => (p.display().to_string(), p.to_path_buf()),
                None => ("demo".to_string(), Path::new(DEMO_SAVE).to_path_buf()),
            };
            (loaded, format!("{title} (recovered)"), save)
        }
        (None, Some(p)) => (
            load_scene(p, &opts.samples)?,
            p.display().to_string(),
            p.to_path_buf(),
        ),
        (None, None) => {
            let mut demo = demo_scene();
            opts.samples.apply(&mut demo)?;
            (demo, "demo".to_string(), Path::new(DEMO_SAVE).to_path_buf())
        }
    };
    let note = places.waiting_note(recovered.as_deref());
    let mut autosave = match recovered {
        Some(file) => Autosave::recovered(places, file),
        None => Autosave::new(places),
    };
    if let Some(note) = note {
        // Shown by the session, on the status line and stderr.
        autosave.notify(note);
    }
    super::render::check_drawable(&scene, Path::new(&title), &opts.memory)?;
    super::render::check_analysis(&scene, opts.analysis, &opts.memory)?;
    if !app::display_available() {
        return Err(CliError(
            "no display: DISPLAY is not set (prespline view needs X11 or XWayland; headless: `prespline render` or `prespline bench`, or `make run` which falls back to a headless demo)".into(),
        ));
    }
    let script = match opts.script {
        Some(p) => {
            let text = std::fs::read_to_string(p)
                .map_err(|e| CliError(format!("cannot read {}: {e}", p.display())))?;
            let doc = crate::editor::Document::new(&scene);
            Some(parse_script(&text, &doc).map_err(|e| CliError::in_file(p, e))?)
        }
        None => None,
    };
    let args = ViewArgs {
        scene,
        title,
        save_path: opts.save_as.map_or(default_save, Path::to_path_buf),
        size: opts.size,
        vsync: opts.vsync,
        script,
        scenario: None,
        warmup: 0,
        max_frames: None,
        naive: false,
        autosave: Some(autosave),
        msaa: 0,
        lod: true,
        analysis: opts.analysis,
        map_range: opts.map_range,
        memory: opts.memory,
        redraw: opts.redraw,
    };
    let title = args.title.clone();
    let run = app::run(args).map_err(CliError)?;
    if let Some(dir) = opts.profile {
        let summary = Summary::from_frames(&run.frames);
        eprint!("{}", summary.table());
        let info = RunInfo {
            scenario: "interactive".into(),
            scene: title,
            size: format!("{}x{}", opts.size.0, opts.size.1),
            frames: run.frames.len(),
            device: run.device,
            mode: "incremental".into(),
            ..RunInfo::default()
        };
        let paths = write_all(dir, &info, &run.frames).map_err(|e| CliError(e.to_string()))?;
        eprintln!(
            "profile of {} frames in {} ({} files)",
            run.frames.len(),
            dir.display(),
            paths.len()
        );
    }
    Ok(())
}

/// The autosave `--recover` opens: the newest of the scene's, or the one `named`.
fn recover_file(places: &Places, named: Option<&Path>) -> Result<PathBuf, CliError> {
    let waiting = places.waiting();
    let listed = || {
        if waiting.is_empty() {
            "there are none".to_string()
        } else {
            let names: Vec<String> = waiting.iter().map(|p| p.display().to_string()).collect();
            format!("waiting: {}", names.join(", "))
        }
    };
    match named {
        None => waiting.first().cloned().ok_or_else(|| {
            let looked = match places.in_state_dir() {
                Some(state) => format!(
                    "looked for {} and {}, and earlier sessions' beside them",
                    places.beside().display(),
                    state.display()
                ),
                None => format!(
                    "looked for {} and earlier sessions' beside it; no state directory: neither XDG_STATE_HOME nor HOME is set",
                    places.beside().display()
                ),
            };
            CliError(format!(
                "--recover: there is no autosave of {} to open ({looked})",
                places.scene_name()
            ))
        }),
        Some(file) => places.find(file).ok_or_else(|| {
            CliError(format!(
                "--recover={}: not an autosave of {} ({})",
                file.display(),
                places.scene_name(),
                listed()
            ))
        }),
    }
}
