//! What every file format implements ([`FileFormat`]) and is handed when it reads
//! ([`LoadContext`]), and what a read gives back ([`Import`]).

use crate::fields::{At, SceneError};
use crate::progress::ProgressSink;
use crate::sampling::budget::MemoryBudget;
use crate::scene::{Kept, Scene};
use serde_json::Value;
use std::fmt;

/// A file format: reads scene objects from a file's bytes, writes them back, and reads what
/// it keeps of an object back from a JSON scene (the `obj` field of OBJ's).
pub trait FileFormat: Sync {
    /// The format's name in messages ("Wavefront OBJ").
    fn name(&self) -> &'static str;

    /// The file extensions it is told by, lower case, without the dot.
    fn extensions(&self) -> &'static [&'static str];

    /// Reads a file's bytes into scene objects.
    fn read(&self, bytes: &[u8], ctx: &LoadContext<'_>) -> Result<Import, FormatError>;

    /// The file's bytes for `scene`, and one line per thing it could not hold; an error when
    /// an object has no form in this format. Formats that are only read refuse.
    fn write(&self, _scene: &Scene) -> Result<Written, FormatError> {
        Err(FormatError::new(format!(
            "prespline reads {} files but does not write them (write .json or .obj)",
            self.name()
        )))
    }

    /// Whether [`FileFormat::write`] can succeed at all.
    fn writes(&self) -> bool {
        false
    }

    /// The JSON scene field under which this format's kept data are saved, if it keeps any.
    fn kept_key(&self) -> Option<&'static str> {
        None
    }

    /// Reads this format's kept data of an object (`surface`: whether it is one) back from
    /// the JSON scene field [`FileFormat::kept_key`].
    fn read_kept(&self, at: &At, _v: &Value, _surface: bool) -> Result<Box<dyn Kept>, SceneError> {
        Err(at.err("kept", format!("{} keeps nothing", self.name())))
    }
}

/// What a read is given besides the bytes.
pub struct LoadContext<'a> {
    /// Counts read from the file are held to it before anything is built from them.
    pub budget: MemoryBudget,
    /// Where long reads count their progress.
    pub progress: &'a dyn ProgressSink,
    /// Sample counts for objects that give none (`--samples`).
    pub samples: SampleDefaults,
    /// Every registered format, for the JSON scene's kept fields.
    pub formats: &'a [&'a dyn FileFormat],
    /// The file's name without directory and extension, where it came from a file: names
    /// objects when the file names nothing (an IGES file without a product id).
    pub stem: Option<&'a str>,
}

/// Sample counts for the objects of a file that give none (`--samples` on the command line):
/// curves take `curve`, surfaces `surface`. A JSON object without `samples` and without a
/// default is an error, as the format asks.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SampleDefaults {
    pub curve: Option<usize>,
    pub surface: Option<[usize; 2]>,
}

/// A scene read from a file, with what was read past.
#[derive(Debug, Clone, PartialEq)]
pub struct Import {
    pub scene: Scene,
    /// One line per kind of thing read past, each with the line it was first seen on.
    pub warnings: Vec<Located>,
    /// What was read but is not drawn, with the reason (`info`'s `skipped`).
    pub skipped: Vec<Skipped>,
    /// The unit of the file's lengths, where the file says ("mm").
    pub unit: Option<String>,
}

impl Import {
    /// A scene with nothing read past.
    #[must_use]
    pub fn plain(scene: Scene) -> Self {
        Self {
            scene,
            warnings: Vec::new(),
            skipped: Vec::new(),
            unit: None,
        }
    }
}

/// Entities of one type that were read and not drawn.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Skipped {
    /// The file's name for them ("TRIANGULATED_FACE", "entity 106").
    pub what: String,
    pub count: usize,
    pub reason: String,
}

/// A message about a place in a file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Located {
    /// 1-based line, when the message has one.
    pub line: Option<usize>,
    pub message: String,
}

impl Located {
    /// `FILE:LINE: message` (or `FILE: message`), the form compilers use, so editors can
    /// jump to it.
    #[must_use]
    pub fn in_file(&self, path: &std::path::Path) -> String {
        match self.line {
            Some(line) => format!("{}:{line}: {}", path.display(), self.message),
            None => format!("{}: {}", path.display(), self.message),
        }
    }
}

/// A file a format cannot read or write, as one line (the file's name is added by whoever
/// knows it: [`FormatError::in_file`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{}", self.0.message)]
pub struct FormatError(pub Located);

impl FormatError {
    /// An error about the whole file.
    #[must_use]
    pub fn new(message: impl Into<String>) -> Self {
        Self(Located {
            line: None,
            message: message.into(),
        })
    }

    /// An error at a line.
    #[must_use]
    pub fn at_line(line: usize, message: impl Into<String>) -> Self {
        Self(Located {
            line: Some(line),
            message: message.into(),
        })
    }

    /// The one line naming the file (and line).
    #[must_use]
    pub fn in_file(&self, path: &std::path::Path) -> String {
        self.0.in_file(path)
    }
}

impl From<SceneError> for FormatError {
    fn from(e: SceneError) -> Self {
        Self::new(e.0)
    }
}

/// A format's bytes for a scene and what it could not hold.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Written {
    pub bytes: Vec<u8>,
    /// One entry per thing left out, naming the object; empty when everything was written.
    pub dropped: Vec<String>,
}

impl fmt::Debug for dyn FileFormat + '_ {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}
