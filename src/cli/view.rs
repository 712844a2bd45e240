//! `prespline view`: the interactive viewer.

use super::CliError;
use crate::profile::{RunInfo, Summary, write_all};
use crate::scene::Scene;
use crate::scene::demo::demo_scene;
use crate::view::app::{self, ViewArgs};
use crate::view::script::parse_script;
use std::path::Path;

/// Command-line options of `prespline view`.
#[derive(Debug, Clone, Copy)]
pub struct ViewOptions<'a> {
    pub scene: Option<&'a Path>,
    pub size: (u32, u32),
    pub vsync: bool,
    pub script: Option<&'a Path>,
    pub save_as: Option<&'a Path>,
    pub profile: Option<&'a Path>,
}

pub fn run(opts: &ViewOptions) -> Result<(), CliError> {
    if !app::display_available() {
        return Err(CliError(
            "no display: DISPLAY is not set (prespline view needs X11 or XWayland; headless: `prespline render` or `prespline bench`, or `make run` which falls back to a headless demo)".into(),
        ));
    }
    let (scene, title, default_save) = match opts.scene {
        Some(p) => (
            Scene::load(p).map_err(|e| CliError::in_file(p, e))?,
            p.display().to_string(),
            p.to_path_buf(),
        ),
        None => (
            demo_scene(),
            "demo".to_string(),
            Path::new("prespline-demo.json").to_path_buf(),
        ),
    };
    let script = match opts.script {
        Some(p) => {
            let text = std::fs::read_to_string(p)
                .map_err(|e| CliError(format!("cannot read {}: {e}", p.display())))?;
            let doc = crate::render::Document::new(&scene);
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
        msaa: 0,
        lod: true,
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
