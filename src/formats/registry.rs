//! The registered file formats, listed once, and loading and saving by a path's extension.

use super::context::{FileFormat, Import, LoadContext, SampleDefaults};
use super::{iges, json, obj, step};
use crate::progress::ProgressSink;
use crate::sampling::budget::MemoryBudget;
use crate::scene::{Scene, SceneError, write_durably};
use std::path::Path;

/// Every file format prespline reads. A new format is a folder under formats/ and one entry
/// here; the first is the default for a path with an unknown extension when writing.
pub static FORMATS: &[&dyn FileFormat] = &[&json::JsonScene, &obj::Obj, &step::Step, &iges::Iges];

/// The format a path's extension names (any case), if any.
#[must_use]
pub fn format_of(path: &Path) -> Option<&'static dyn FileFormat> {
    let ext = path.extension()?.to_str()?;
    FORMATS
        .iter()
        .copied()
        .find(|f| f.extensions().iter().any(|e| ext.eq_ignore_ascii_case(e)))
}

/// The extensions of every format, for messages: ".json, .obj".
#[must_use]
pub fn known_extensions(writable: bool) -> String {
    let list: Vec<String> = FORMATS
        .iter()
        .filter(|f| !writable || f.writes())
        .flat_map(|f| f.extensions().iter().map(|e| format!(".{e}")))
        .collect();
    list.join(", ")
}

/// A load's settings, for [`load`]: everything in [`LoadContext`] but the formats.
#[derive(Clone, Copy)]
pub struct LoadOptions<'a> {
    pub budget: MemoryBudget,
    pub progress: &'a dyn ProgressSink,
    pub samples: SampleDefaults,
}

/// Reads a scene file in the format its extension names (the JSON scene format for any other
/// extension). Errors name the file (and line): `FILE:LINE: message`.
pub fn load(path: &Path, options: LoadOptions<'_>) -> Result<Import, String> {
    load_as(path, format_of(path).unwrap_or(FORMATS[0]), options)
}

/// Reads a JSON scene file whatever its extension (an autosave).
pub fn load_json(path: &Path, options: LoadOptions<'_>) -> Result<Scene, String> {
    load_as(path, &json::JsonScene, options).map(|i| i.scene)
}

/// Reads a JSON scene file with the defaults: the machine's memory budget, no progress, no
/// `--samples` (tests and tools that read what the viewer saved).
pub fn read_json(path: &Path) -> Result<Scene, String> {
    let options = LoadOptions {
        budget: MemoryBudget::machine_default(),
        progress: &crate::progress::Silent,
        samples: SampleDefaults::default(),
    };
    load_json(path, options)
}

/// Writes a JSON scene file atomically and durably whatever its extension (an autosave).
pub fn save_json(scene: &Scene, path: &Path) -> Result<(), String> {
    write_durably(path, json::scene_to_json(scene).as_bytes())
        .map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// Reads `path` in `format`.
fn load_as(
    path: &Path,
    format: &dyn FileFormat,
    options: LoadOptions<'_>,
) -> Result<Import, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let stem = path.file_stem().and_then(|s| s.to_str());
    let ctx = LoadContext {
        budget: options.budget,
        progress: options.progress,
        samples: options.samples,
        formats: FORMATS,
        stem,
    };
    format.read(&bytes, &ctx).map_err(|e| e.in_file(path))
}

/// Reads scene text in the JSON scene format with no defaults, for built-in scenes and tests.
pub fn parse_scene(text: &str) -> Result<Scene, SceneError> {
    let ctx = LoadContext {
        budget: MemoryBudget::machine_default(),
        progress: &crate::progress::Silent,
        samples: SampleDefaults::default(),
        formats: FORMATS,
        stem: None,
    };
    json::parse_scene(text, &ctx)
}

/// Whether [`save`] could write `scene` to `path`: the format's whole text is made and
/// dropped, so a save that can only fail is refused when the path is given, not when the user
/// saves.
pub fn check_save(scene: &Scene, path: &Path) -> Result<(), String> {
    let format = format_of(path).unwrap_or(FORMATS[0]);
    format.write(scene).map(|_| ()).map_err(|e| e.to_string())
}

/// Writes the scene in the format the path names (the JSON scene format for any other
/// extension) atomically and durably ([`write_durably`]), so a failed save never destroys the
/// previous file; nothing is written when an object has no form in that format. Returns what
/// the file could not hold, for one warning line.
pub fn save(scene: &Scene, path: &Path) -> Result<Vec<String>, String> {
    let format = format_of(path).unwrap_or(FORMATS[0]);
    let written = format.write(scene).map_err(|e| e.to_string())?;
    write_durably(path, &written.bytes)
        .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    Ok(written.dropped)
}
