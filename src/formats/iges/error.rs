//! The one error type of the IGES reader. Every message is a single line that starts with the
//! (1-based) line of the file it is about, so a caller only has to prefix the file name to get
//! the `FILE: line N: …` form editors and users can act on.

use std::fmt::Write as _;

use super::names::type_name;

/// Why an IGES file (or one of its entities) could not be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum IgesError {
    /// The compressed ASCII or binary form: both are rare, and refusing them plainly is better
    /// than misreading them as a damaged fixed-form file.
    #[error(
        "line {line}: this is the IGES {form} form, which is not supported; export the file in the fixed 80-column ASCII form"
    )]
    UnsupportedForm { line: usize, form: &'static str },
    /// The 80-column record layout, the section order, sequence numbers or the Terminate
    /// section are broken.
    #[error("line {line}: {message}")]
    Layout { line: usize, message: String },
    /// A Global-section field (numbered as in IGES 5.3 §2.2.4, 1 = parameter delimiter).
    #[error("line {line}: global parameter {index} ({name}) {message}")]
    Global {
        line: usize,
        index: usize,
        name: &'static str,
        message: String,
    },
    /// A directory entry (two D lines) before its entity type is known to be consistent.
    #[error("line {line}: D {de}: {message}")]
    Directory {
        line: usize,
        de: u32,
        message: String,
    },
    /// An entity's parameter data, or what the mapping code found wrong with it.
    #[error("line {line}: D {de} (entity {entity_type}, {}): {message}", type_name(*entity_type))]
    Entity {
        line: usize,
        de: u32,
        entity_type: i32,
        message: String,
    },
}

impl IgesError {
    /// The 1-based line of the file the error is about, for callers that format `FILE:LINE:`.
    #[must_use]
    pub fn line(&self) -> usize {
        match self {
            Self::UnsupportedForm { line, .. }
            | Self::Layout { line, .. }
            | Self::Global { line, .. }
            | Self::Directory { line, .. }
            | Self::Entity { line, .. } => *line,
        }
    }

    #[must_use]
    pub(super) fn layout(line: usize, message: impl Into<String>) -> Self {
        Self::Layout {
            line,
            message: message.into(),
        }
    }
}

/// Text from the file as it may appear inside a message: printable ASCII kept, anything else
/// (a CR, a control byte, a byte above 127) written as `\xNN`, and cut after 40 characters, so
/// that a damaged file can never make a message span lines or grow without bound.
#[must_use]
pub(super) fn shown(bytes: &[u8]) -> String {
    const LIMIT: usize = 40;
    let mut out = String::new();
    for (count, &b) in bytes.iter().enumerate() {
        if count == LIMIT {
            out.push('…');
            break;
        }
        if (b' '..=b'~').contains(&b) {
            out.push(char::from(b));
        } else {
            let _ = write!(out, "\\x{b:02X}");
        }
    }
    out
}

/// [`shown`] for text that is already a `String` (Hollerith contents).
#[must_use]
pub(super) fn shown_str(text: &str) -> String {
    let bytes: Vec<u8> = text
        .chars()
        .map(|c| u8::try_from(u32::from(c)).unwrap_or(b'?'))
        .collect();
    shown(&bytes)
}
