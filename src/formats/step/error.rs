//! The one error type of the STEP reader.
//!
//! Every message is a single line that starts with the line number it concerns (the caller adds
//! the file name), and names the entity instance (`#id`) where one is known, so that a user can
//! open the file at the right place. Syntax errors carry a [`Scope`] saying what the reader was
//! inside when it failed; access errors carry a ready-made context string such as
//! `#45 = PLANE: parameter 2 (position)`.

use std::fmt;

use thiserror::Error;

/// What the reader was inside when a syntax error happened; it becomes part of the message.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scope {
    /// Before the `ISO-10303-21;` keyword had been read.
    Start,
    /// Between sections (after `ENDSEC;`, before the next section or `END-ISO-10303-21;`).
    Between,
    /// Directly in the HEADER section, between its entries.
    Header,
    /// Inside one HEADER entry such as `FILE_NAME(…)`, which started at `line`.
    HeaderEntry {
        /// The line where the entry's keyword is.
        line: u32,
    },
    /// Directly in a DATA section, between instances.
    Data,
    /// Inside the entity instance `#id`, which started at `line`.
    Entity {
        /// The instance's name (`#id`).
        id: u64,
        /// The line where `#id` is.
        line: u32,
    },
    /// Inside an edition-3 section that the reader skips (ANCHOR, REFERENCE, SIGNATURE).
    Skipped,
}

impl Scope {
    /// The entity instance this scope is inside, if any.
    #[must_use]
    pub fn entity_id(self) -> Option<u64> {
        match self {
            Scope::Entity { id, .. } => Some(id),
            _ => None,
        }
    }
}

impl fmt::Display for Scope {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Scope::Start => f.write_str("at the start of the file"),
            Scope::Between => f.write_str("between sections"),
            Scope::Header => f.write_str("in the HEADER section"),
            Scope::HeaderEntry { line } => {
                write!(f, "inside a HEADER entry (started at line {line})")
            }
            Scope::Data => f.write_str("in a DATA section"),
            Scope::Entity { id, line } => write!(f, "inside #{id} (started at line {line})"),
            Scope::Skipped => f.write_str("in a skipped section"),
        }
    }
}

/// Everything that can go wrong while reading a STEP file or walking its entities.
///
/// `Display` is one line with no file name: `line 1234: #45 = PLANE: parameter 2 (position)
/// should be a reference, found a string`.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum StepError {
    /// The first token is not `ISO-10303-21` (another format, or binary data).
    #[error("line {line}: not a STEP file: expected ISO-10303-21, found {found}")]
    NotStep {
        /// Line of the first token.
        line: u32,
        /// The first token, escaped and shortened.
        found: String,
    },
    /// The file ends before the structure is complete (a truncated file).
    #[error("line {line}: unexpected end of file {scope}, expected {expected}")]
    UnexpectedEof {
        /// The last line of the file.
        line: u32,
        /// What was open when the file ended.
        scope: Scope,
        /// What the reader was waiting for.
        expected: &'static str,
    },
    /// A string literal has no closing `'`.
    #[error("line {line}: unterminated string {scope}")]
    UnterminatedString {
        /// Line where the string starts.
        line: u32,
        /// Where the string is.
        scope: Scope,
    },
    /// A `/* …` comment has no closing `*/`.
    #[error("line {line}: unterminated comment {scope}")]
    UnterminatedComment {
        /// Line where the comment starts.
        line: u32,
        /// Where the comment is.
        scope: Scope,
    },
    /// A token that does not fit the grammar at this point.
    #[error("line {line}: unexpected {found} {scope}, expected {expected}")]
    Unexpected {
        /// Line of the offending token.
        line: u32,
        /// Where it is.
        scope: Scope,
        /// The offending token or byte, escaped.
        found: String,
        /// What would have been valid.
        expected: &'static str,
    },
    /// A control or non-ASCII byte outside a string: the file is damaged or not text.
    #[error("line {line}: binary byte 0x{byte:02x} {scope}: not STEP text")]
    Binary {
        /// Line of the byte.
        line: u32,
        /// Where it is.
        scope: Scope,
        /// The byte.
        byte: u8,
    },
    /// An entity instance ends without its `;`.
    #[error("line {line}: missing ';' after #{id} (started at line {start}), found {found}")]
    MissingSemicolon {
        /// Line of the token found instead.
        line: u32,
        /// The instance that lacks its `;`.
        id: u64,
        /// Line where the instance started.
        start: u32,
        /// The token found instead, escaped.
        found: String,
    },
    /// Two instances with the same `#id`.
    #[error("line {line}: duplicate entity #{id} (first defined at line {first})")]
    DuplicateId {
        /// Line of the second definition.
        line: u32,
        /// The id defined twice.
        id: u64,
        /// Line of the first definition.
        first: u32,
    },
    /// Lists or typed parameters nested deeper than the reader allows (guards the memory and
    /// the stack of every later recursive walk).
    #[error("line {line}: parameters nested deeper than {limit} levels {scope}")]
    TooDeep {
        /// Line where the limit was passed.
        line: u32,
        /// Where it is.
        scope: Scope,
        /// The nesting limit.
        limit: usize,
    },
    /// An integer, real or `#id` that does not fit its type.
    #[error("line {line}: number {text} out of range {scope}")]
    NumberOutOfRange {
        /// Line of the number.
        line: u32,
        /// Where it is.
        scope: Scope,
        /// The number as written (shortened).
        text: String,
    },
    /// The file has more parameters or string bytes than the compact tables can index.
    #[error("line {line}: file too large: more than 4294967295 {what}")]
    TooLarge {
        /// Line where the limit was passed.
        line: u32,
        /// What overflowed.
        what: &'static str,
    },
    /// [`StepFile::get`](super::StepFile::get) was asked for an id that no instance has.
    #[error("no entity #{id} in the file")]
    NoSuchEntity {
        /// The id asked for.
        id: u64,
    },
    /// A reference to an instance that is not in the file.
    #[error("line {line}: {context} refers to #{target}, which is not in the file")]
    Dangling {
        /// Line of the referring instance.
        line: u32,
        /// The referring instance.
        id: u64,
        /// The referring parameter, e.g. `#45 = PLANE: parameter 2 (position)`.
        context: String,
        /// The missing id.
        target: u64,
    },
    /// A parameter of another type than the schema requires.
    #[error("line {line}: {context} should be {expected}, found {found}")]
    WrongType {
        /// Line of the instance.
        line: u32,
        /// The instance.
        id: u64,
        /// The parameter, e.g. `#45 = PLANE: parameter 2 (position)`.
        context: String,
        /// The type required, e.g. `a reference`.
        expected: &'static str,
        /// What was there, e.g. `a string`.
        found: String,
    },
    /// A record has fewer parameters (or a list fewer items) than asked for.
    #[error("line {line}: {context} is missing: only {count} present")]
    Missing {
        /// Line of the instance.
        line: u32,
        /// The instance.
        id: u64,
        /// The parameter or item asked for.
        context: String,
        /// How many there are.
        count: usize,
    },
    /// An instance has no record of the asked-for type (complex instances hold several).
    #[error("line {line}: #{id} = {names} has no {wanted} record")]
    MissingRecord {
        /// Line of the instance.
        line: u32,
        /// The instance.
        id: u64,
        /// The record types it does have, e.g. `(BOUNDED_CURVE B_SPLINE_CURVE …)`.
        names: String,
        /// The record type asked for.
        wanted: String,
    },
    /// A semantic problem found by the caller (e.g. a direction of length zero), reported with
    /// the same context as the other access errors.
    #[error("line {line}: {context}: {message}")]
    Invalid {
        /// Line of the instance.
        line: u32,
        /// The instance.
        id: u64,
        /// The instance or parameter concerned.
        context: String,
        /// What is wrong.
        message: String,
    },
}

impl StepError {
    /// The line the error concerns; `None` only for [`StepError::NoSuchEntity`], which is asked
    /// for without a referring instance.
    #[must_use]
    pub fn line(&self) -> Option<u32> {
        match self {
            StepError::NotStep { line, .. }
            | StepError::UnexpectedEof { line, .. }
            | StepError::UnterminatedString { line, .. }
            | StepError::UnterminatedComment { line, .. }
            | StepError::Unexpected { line, .. }
            | StepError::Binary { line, .. }
            | StepError::MissingSemicolon { line, .. }
            | StepError::DuplicateId { line, .. }
            | StepError::TooDeep { line, .. }
            | StepError::NumberOutOfRange { line, .. }
            | StepError::TooLarge { line, .. }
            | StepError::Dangling { line, .. }
            | StepError::WrongType { line, .. }
            | StepError::Missing { line, .. }
            | StepError::MissingRecord { line, .. }
            | StepError::Invalid { line, .. } => Some(*line),
            StepError::NoSuchEntity { .. } => None,
        }
    }

    /// The entity instance the error is in (or, for a dangling reference, the referring one).
    #[must_use]
    pub fn entity_id(&self) -> Option<u64> {
        match self {
            StepError::UnexpectedEof { scope, .. }
            | StepError::UnterminatedString { scope, .. }
            | StepError::UnterminatedComment { scope, .. }
            | StepError::Unexpected { scope, .. }
            | StepError::Binary { scope, .. }
            | StepError::TooDeep { scope, .. }
            | StepError::NumberOutOfRange { scope, .. } => scope.entity_id(),
            StepError::MissingSemicolon { id, .. }
            | StepError::DuplicateId { id, .. }
            | StepError::NoSuchEntity { id }
            | StepError::Dangling { id, .. }
            | StepError::WrongType { id, .. }
            | StepError::Missing { id, .. }
            | StepError::MissingRecord { id, .. }
            | StepError::Invalid { id, .. } => Some(*id),
            StepError::NotStep { .. } | StepError::TooLarge { .. } => None,
        }
    }
}
