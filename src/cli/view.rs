//! `prespline view`: the interactive viewer.

use super::CliError;
use super::args::{MapRangeArgs, MemoryArgs, SamplesArgs, parse_size};
use super::load::{Notes, load_scene};
use crate::formats::demo::demo_scene;
use crate::formats::{self, LoadOptions};
use crate::profile::{RunInfo, Summary, TerminalProgress, write_all};
use crate::render::Redraw;
use crate::render::maps::SurfaceMap;
use crate::view::app;
use crate::view::autosave::{Autosave, Places, state_dir};
use crate::view::script::parse_script;
use clap::Args;
use std::path::{Path, PathBuf};

/// Where Ctrl+S writes the demo scene.
const DEMO_SAVE: &str = "prespline-demo.json";

/// Open the interactive viewer on a scene (the built-in demo scene without SCENE).
///
/// docs/viewer.md describes the mouse, the keys, the editing modes and the --script
/// format; H or F1 in the viewer lists the keys.
#[derive(Args, Debug, Clone)]
pub struct ViewArgs {
    /// Scene file (JSON, OBJ, STEP or IGES, by extension); without it, the demo:
    /// B-spline surface, ERBS surface and curve, NURBS circle, closed ERBS torus, Utah
    /// teapot.
    pub scene: Option<PathBuf>,
    /// Window size.
    #[arg(long, default_value = "1280x720", value_parser = parse_size, value_name = "WxH")]
    pub size: (u32, u32),
    /// Present without vsync (MAILBOX or IMMEDIATE) to measure frame times.
    #[arg(long)]
    pub no_vsync: bool,
    /// Replay timed input events from a JSON script (format: docs/viewer.md, "Scripts").
    #[arg(long, value_name = "SCRIPT.json")]
    pub script: Option<PathBuf>,
    /// Where Ctrl+S writes (default: the scene file, its .json beside it for a STEP or IGES
    /// model, or prespline-demo.json for the demo);
    /// a path ending in .obj is written as Wavefront OBJ.
    #[arg(long, value_name = "PATH")]
    pub save_as: Option<PathBuf>,
    #[command(flatten)]
    pub samples: SamplesArgs,
    /// Record per-frame phase timings while interacting and write the reports (CSV, JSON
    /// summary, Chrome trace, SVG plots) into DIR when the window closes.
    #[arg(long, value_name = "DIR")]
    pub profile: Option<PathBuf>,
    /// Open an earlier session's unsaved edits instead of the scene: the newest autosave,
    /// or =FILE (the start-up note lists those waiting). Autosaves: NAME.autosave.json
    /// beside NAME.json (demo.autosave.json for the demo), earlier sessions' as
    /// NAME.autosave.YYYYMMDD-HHMMSS.json, or in $XDG_STATE_HOME/prespline/ when the
    /// scene's directory cannot take them. Ctrl+S removes the recovered autosave; see
    /// docs/autosave.md.
    #[arg(long, value_name = "FILE", num_args = 0..=1, require_equals = true)]
    pub recover: Option<Option<PathBuf>>,
    #[command(flatten)]
    pub memory: MemoryArgs,
    /// Open with a surface analysis map on: gaussian, mean, kmax, kmin or zebra (M cycles).
    #[arg(long, value_name = "MAP", value_parser = SurfaceMap::parse)]
    pub analysis: Option<SurfaceMap>,
    #[command(flatten)]
    pub map_range: MapRangeArgs,
    /// How a gesture redraws: retained (what it cannot change is drawn once into a static
    /// layer; each frame restores it and draws only what moves) or full (every object,
    /// every frame). Both give the same pixels.
    #[arg(long, default_value = "retained", value_parser = Redraw::parse, value_name = "retained|full")]
    pub redraw: Redraw,
}

/// Opens the viewer; returns when its window closes.
pub fn run(opts: ViewArgs) -> Result<(), CliError> {
    let budget = opts.memory.budget();
    let samples = opts.samples.counts();
    let places = Places::new(opts.scene.as_deref(), state_dir().as_deref());
    let recovered = match &opts.recover {
        Some(named) => Some(recover_file(&places, named.as_deref())?),
        None => None,
    };
    let mut notes = Notes::default();
    let (scene, title, default_save) = match (&recovered, opts.scene.as_deref()) {
        (Some(file), scene) => {
            let options = LoadOptions {
                budget,
                progress: &TerminalProgress,
                samples: Default::default(),
            };
            // An autosave is a JSON scene whatever the scene's own format.
            let mut loaded = formats::load_json(file, options).map_err(CliError)?;
            samples.apply(&mut loaded)?;
            let (title, save) = match scene {
                Some(p) => (p.display().to_string(), save_path_for(p)),
                None => ("demo".to_string(), Path::new(DEMO_SAVE).to_path_buf()),
            };
            (loaded, format!("{title} (recovered)"), save)
        }
        (None, Some(p)) => {
            let (loaded, said) = load_scene(p, &samples, &budget)?;
            notes = said;
            (loaded, p.display().to_string(), save_path_for(p))
        }
        (None, None) => {
            let mut demo = demo_scene();
            samples.apply(&mut demo)?;
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
    super::render::check_drawable(&scene, Path::new(&title), &budget)?;
    super::render::check_analysis(&scene, opts.analysis, &budget)?;
    if let Some(p) = &opts.save_as {
        formats::check_save(&scene, p)
            .map_err(|e| CliError(format!("--save-as {}: {e}", p.display())))?;
    }
    if !app::display_available() {
        return Err(CliError(
            "no display: DISPLAY is not set (prespline view needs X11 or XWayland; headless: `prespline render` or `prespline bench`, or `make run` which falls back to a headless demo)".into(),
        ));
    }
    let script = match &opts.script {
        Some(p) => {
            let text = std::fs::read_to_string(p)
                .map_err(|e| CliError(format!("cannot read {}: {e}", p.display())))?;
            let doc = crate::editor::Document::new(&scene);
            Some(parse_script(&text, &doc).map_err(|e| CliError::in_file(p, e))?)
        }
        None => None,
    };
    notes.print();
    let args = app::ViewArgs {
        scene,
        title,
        save_path: opts.save_as.clone().unwrap_or(default_save),
        size: opts.size,
        vsync: !opts.no_vsync,
        script,
        scenario: None,
        warmup: 0,
        max_frames: None,
        naive: false,
        autosave: Some(autosave),
        msaa: 0,
        lod: true,
        analysis: opts.analysis,
        map_range: opts.map_range.map_range,
        memory: budget,
        redraw: opts.redraw,
    };
    let title = args.title.clone();
    let run = app::run(args).map_err(CliError)?;
    if let Some(dir) = &opts.profile {
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

/// Where Ctrl+S writes a scene opened from `scene` without `--save-as`: the file itself, or,
/// for a format prespline reads but does not write (STEP, IGES), the JSON scene beside it
/// (`part.step` → `part.json`), so that saving a CAD model never fails.
#[must_use]
fn save_path_for(scene: &Path) -> std::path::PathBuf {
    if formats::format_of(scene).is_some_and(|f| f.writes()) {
        scene.to_path_buf()
    } else {
        scene.with_extension("json")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cad_models_save_as_json_beside_them() {
        for (scene, save) in [
            ("m/part.step", "m/part.json"),
            ("m/part.STP", "m/part.json"),
            ("part.igs", "part.json"),
            ("a.iges", "a.json"),
            ("vase.obj", "vase.obj"),
            ("scene.json", "scene.json"),
        ] {
            assert_eq!(save_path_for(Path::new(scene)), Path::new(save), "{scene}");
        }
    }
}
