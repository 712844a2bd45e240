//! Scenes: named objects with sample counts, display style and what their file kept, and
//! the edits files (docs/scene-format.md). The file formats that read and write scenes live
//! one floor up, in `formats`.

pub mod edit;
mod kept;
mod measure;

pub use crate::fields::json::{self, At, SceneError};
pub use crate::model::{Index2, MAX_CURVE_SAMPLES, MAX_DEGREE, MAX_SURFACE_SAMPLES, Model};
pub use edit::{EditList, parse_edits};
pub use kept::{Carried, Kept, SceneNames};
pub use measure::Measure;

use std::borrow::Cow;
use std::path::Path;

/// User text (object and field names, file contents) as a one-line message may echo it: control
/// characters escaped as Rust writes them (`\n`, `\u{1b}`), so a name can neither split the line
/// nor reach the terminal as an escape sequence. Every line the program prints about user input
/// passes through here.
#[must_use]
pub fn escape_controls(s: &str) -> Cow<'_, str> {
    if !s.chars().any(char::is_control) {
        return Cow::Borrowed(s);
    }
    let mut out = String::with_capacity(s.len() + 8);
    for c in s.chars() {
        if c.is_control() {
            out.extend(c.escape_debug());
        } else {
            out.push(c);
        }
    }
    Cow::Owned(out)
}

/// A whole scene: objects in file order.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Scene {
    pub objects: Vec<SceneObject>,
}

/// One named object: its model (geometry with sample counts), display colour, and what its
/// file held that prespline does not use.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneObject {
    pub name: String,
    pub model: Model,
    /// Optional display colour (linear RGB in [0, 1]); the viewer picks one per object otherwise.
    pub color: Option<[f64; 3]>,
    /// What the object's file held that prespline does not use (OBJ's `curv2`, `vp`, `con`,
    /// techniques), kept for every save; empty for objects from anywhere else.
    pub kept: Carried,
    /// A surface's trim loops in its parameter space (`None`: drawn whole).
    pub trim: Option<crate::geom::trim::Trimmed>,
}

impl Scene {
    /// Refuses, as one line naming the object, a scene whose objects do not fit `budget`
    /// together; returns the estimated total otherwise.
    pub fn check_budget(
        &self,
        mode: crate::sampling::SampleMode,
        uses: crate::sampling::budget::Uses,
        budget: &crate::sampling::budget::MemoryBudget,
    ) -> Result<u64, String> {
        let extents: Vec<(&str, crate::sampling::budget::Extent)> = self
            .objects
            .iter()
            .map(|o| (o.name.as_str(), o.model.kind().extent()))
            .collect();
        crate::sampling::budget::check_extents(&extents, mode, uses, budget)
    }

    #[must_use]
    pub fn find(&self, name: &str) -> Option<usize> {
        self.objects.iter().position(|o| o.name == name)
    }

    /// The scene with every Catmull–Rom and Bézier spline replaced by its equivalent
    /// `bspline_curve` (the B-spline of its Bézier chain; same shape, samples and colour).
    #[must_use]
    pub fn with_bspline_curves(mut self) -> Scene {
        for o in &mut self.objects {
            if let Some(m) = o.model.as_ref().to_bspline_curve() {
                o.model = m;
            }
        }
        self
    }
}

/// Replaces `path` with `bytes` atomically and durably: the bytes go to a temporary file in the
/// same directory, which is flushed to disk (fsync) before it is renamed over `path`, and the
/// directory is flushed after the rename. Readers see the old file or the new one, never a
/// part; after a crash the rename is not there without the data it points to.
pub fn write_durably(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    use std::io::Write;
    let name = path
        .file_name()
        .ok_or_else(|| std::io::Error::new(std::io::ErrorKind::InvalidInput, "not a file path"))?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let tmp = dir.join(format!(
        ".{}.tmp-{}",
        name.to_string_lossy(),
        std::process::id()
    ));
    let written = std::fs::File::create(&tmp).and_then(|mut f| {
        f.write_all(bytes)?;
        f.sync_all()
    });
    if let Err(e) = written.and_then(|()| std::fs::rename(&tmp, path)) {
        let _ = std::fs::remove_file(&tmp);
        return Err(e);
    }
    std::fs::File::open(dir).and_then(|d| d.sync_all())
}

#[cfg(test)]
mod escape_tests {
    use super::*;

    #[test]
    fn control_characters_are_escaped_and_nothing_else() {
        assert!(matches!(escape_controls("teapot_03 ü ∂"), Cow::Borrowed(_)));
        assert_eq!(
            escape_controls("a\nb\u{1b}[31m\t\u{7f}c"),
            r"a\nb\u{1b}[31m\t\u{7f}c"
        );
        // C1 controls alone (the 8-bit CSI, NEL, the first and last of the block).
        assert_eq!(
            escape_controls("a\u{9b}31mb\u{85}\u{80}\u{9f}"),
            r"a\u{9b}31mb\u{85}\u{80}\u{9f}"
        );
        assert!(matches!(escape_controls("\u{a0}\u{7e}"), Cow::Borrowed(_)));
        // Negative control: a line that still holds a control character fails the check.
        assert!(escape_controls("x\ry").chars().all(|c| !c.is_control()));
        assert!("x\ry".chars().any(char::is_control));
    }
}
