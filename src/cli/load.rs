//! Loading a scene file of any registered format for a command: its warnings and notes on
//! stderr (the command line is the floor that prints), `--samples` applied.

use super::CliError;
use super::samples::SampleOverride;
use crate::formats::{self, Import, LoadOptions};
use crate::profile::TerminalProgress;
use crate::sampling::budget::MemoryBudget;
use crate::scene::{Scene, escape_controls};
use std::path::Path;

/// Loads a scene file in the format its extension names; warnings go to stderr as
/// `FILE:LINE: warning: …`, then a note for a `--samples` count the scene has no object for.
pub fn load_scene(
    path: &Path,
    samples: &SampleOverride,
    budget: &MemoryBudget,
) -> Result<Scene, CliError> {
    load_import(path, samples, budget).map(|i| i.scene)
}

/// [`load_scene`], keeping what the file's format reported (skipped entities, unit).
pub fn load_import(
    path: &Path,
    samples: &SampleOverride,
    budget: &MemoryBudget,
) -> Result<Import, CliError> {
    let options = LoadOptions {
        budget: *budget,
        progress: &TerminalProgress,
        samples: samples.defaults(),
    };
    let mut import = formats::load(path, options).map_err(CliError)?;
    for w in &import.warnings {
        eprintln!("{}", escape_controls(&w.in_file(path)));
    }
    samples.apply(&mut import.scene)?;
    let shown = path.display().to_string();
    for note in samples.unused_notes(&import.scene, &escape_controls(&shown)) {
        eprintln!("{note}");
    }
    Ok(import)
}
