//! `prespline view`: the interactive viewer.

use super::CliError;
use super::files::{SampleOverride, load_scene};
use crate::profile::{RunInfo, Summary, write_all};
use crate::sampling::budget::MemoryBudget;
use crate::scene::Scene;
use crate::scene::demo::demo_scene;
use crate::view::app::{self, ViewArgs};
use crate::view::autosave::{Autosave, autosave_path, newer_autosave, previous_path};
use crate::view::script::parse_script;
use std::path::Path;

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
    /// Open the scene's autosave (unsaved edits of an earlier session) instead of the scene.
    pub recover: bool,
    /// A surface analysis map shown from the start (`--analysis`; M cycles it later).
    pub analysis: Option<crate::render::maps::SurfaceMap>,
}

pub fn run(opts: &ViewOptions) -> Result<(), CliError> {
    let autosave_file = autosave_path(opts.scene);
    let (scene, title, default_save) = match opts.scene {
        _ if opts.recover => {
            if !autosave_file.exists() {
                return Err(CliError(format!(
                    "--recover: there is no autosave {} to open",
                    autosave_file.display()
                )));
            }
            let mut scene =
                Scene::load(&autosave_file).map_err(|e| CliError::in_file(&autosave_file, e))?;
            opts.samples.apply(&mut scene)?;
            let (title, save) = match opts.scene {
                Some(p) => (p.display().to_string(), p.to_path_buf()),
                None => ("demo".to_string(), Path::new(DEMO_SAVE).to_path_buf()),
            };
            (scene, format!("{title} (recovered)"), save)
        }
        Some(p) => (
            load_scene(p, &opts.samples)?,
            p.display().to_string(),
            p.to_path_buf(),
        ),
        None => (
            demo_scene(),
            "demo".to_string(),
            Path::new(DEMO_SAVE).to_path_buf(),
        ),
    };
    let autosave = if opts.recover {
        Autosave::recovered(autosave_file)
    } else {
        if let Some(newer) = newer_autosave(opts.scene) {
            eprintln!(
                "note: {} holds unsaved edits newer than {}; `--recover` opens them (this session keeps them as {} when it autosaves)",
                newer.display(),
                opts.scene
                    .map_or("the demo".to_string(), |p| p.display().to_string()),
                previous_path(&newer).display()
            );
        }
        Autosave::new(autosave_file)
    };
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
        memory: opts.memory,
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
