//! `prespline convert IN OUT`: a scene from one file format to another, by the extensions.

use super::CliError;
use super::args::{MemoryArgs, SamplesArgs};
use super::load::load_scene;
use crate::formats::{self, format_of, known_extensions};
use crate::scene::escape_controls;
use clap::Args;
use std::path::PathBuf;

/// Convert a scene between file formats (direction from the extensions).
///
/// IN ends in the extension of any format prespline reads, OUT in that of one it writes
/// (.json, the scene format, or .obj, free-form curves and surfaces); control data are kept
/// bit for bit. docs/obj.md describes the exact mapping.
#[derive(Args, Debug, Clone)]
pub struct ConvertArgs {
    /// Input scene.
    pub input: PathBuf,
    /// Output scene, written atomically.
    pub output: PathBuf,
    #[command(flatten)]
    pub samples: SamplesArgs,
    #[command(flatten)]
    pub memory: MemoryArgs,
}

/// Converts and prints the closing line.
pub fn run(args: ConvertArgs) -> Result<(), CliError> {
    let (input, output) = (&args.input, &args.output);
    if format_of(input).is_none() {
        return Err(CliError(format!(
            "{}: cannot tell the format from the extension (use {})",
            input.display(),
            known_extensions(false)
        )));
    }
    if !format_of(output).is_some_and(|f| f.writes()) {
        return Err(CliError(format!(
            "{}: cannot tell the format from the extension (use {})",
            output.display(),
            known_extensions(true)
        )));
    }
    let (scene, notes) = load_scene(input, &args.samples.counts(), &args.memory.budget())?;
    let dropped =
        formats::save(&scene, output).map_err(|e| CliError(format!("{}: {e}", input.display())))?;
    notes.print();
    if !dropped.is_empty() {
        eprintln!(
            "warning: {}: written without: {}",
            escape_controls(&output.display().to_string()),
            escape_controls(&dropped.join("; "))
        );
    }
    eprintln!(
        "{}",
        escape_controls(&format!(
            "wrote {} ({} objects)",
            output.display(),
            scene.objects.len()
        ))
    );
    Ok(())
}
