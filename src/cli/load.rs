//! Loading a scene file of any registered format for a command, `--samples` applied, with
//! its warnings and notes held in [`Notes`] for the command to print once its own checks have
//! passed (the command line is the floor that prints): an error stands alone on its line.

use super::CliError;
use super::samples::SampleOverride;
use crate::formats::{self, Import, LoadOptions};
use crate::profile::TerminalProgress;
use crate::sampling::budget::MemoryBudget;
use crate::scene::{Scene, escape_controls};
use std::path::Path;

/// What loading has to say: the file's warnings (`FILE:LINE: warning: …`), then a note for a
/// `--samples` count the scene has no object for. Printed by the command when it gets past
/// its own checks, so that a later error (a bad script, an unwritable output) is one line.
#[must_use = "a command prints its notes once its checks pass"]
#[derive(Debug, Default)]
pub struct Notes(Vec<String>);

impl Notes {
    /// Writes the notes to stderr, one line each.
    pub fn print(self) {
        for line in self.0 {
            eprintln!("{line}");
        }
    }
}

/// Loads a scene file in the format its extension names, with what loading has to say.
pub fn load_scene(
    path: &Path,
    samples: &SampleOverride,
    budget: &MemoryBudget,
) -> Result<(Scene, Notes), CliError> {
    load_import(path, samples, budget).map(|(i, notes)| (i.scene, notes))
}

/// [`load_scene`], keeping what the file's format reported (skipped entities, unit).
pub fn load_import(
    path: &Path,
    samples: &SampleOverride,
    budget: &MemoryBudget,
) -> Result<(Import, Notes), CliError> {
    let options = LoadOptions {
        budget: *budget,
        progress: &TerminalProgress,
        samples: samples.defaults(),
    };
    let mut import = formats::load(path, options).map_err(CliError)?;
    let mut notes: Vec<String> = import
        .warnings
        .iter()
        .map(|w| escape_controls(&w.in_file(path)).into_owned())
        .collect();
    samples.apply(&mut import.scene)?;
    let shown = path.display().to_string();
    notes.extend(samples.unused_notes(&import.scene, &escape_controls(&shown)));
    Ok((import, Notes(notes)))
}
