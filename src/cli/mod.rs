//! Command implementations behind `src/main.rs`, kept in the library so tests can call them.

pub mod bench;
pub mod files;
pub mod render;
pub mod resident;
pub mod sample;
pub mod view;

/// A command failure: one line for stderr; the process exits non-zero.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct CliError(pub String);

impl CliError {
    /// Prefixes a scene/edit error with the file it came from.
    pub fn in_file(path: &std::path::Path, e: impl std::fmt::Display) -> Self {
        CliError(format!("{}: {e}", path.display()))
    }
}
