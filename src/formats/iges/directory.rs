//! Directory entries (IGES 5.3 §2.2.4.4): two D lines of ten 8-column fields per entity. The
//! entity number everything points by is the sequence number of the first line, so entities
//! are 1, 3, 5, …; pointer fields are checked against that numbering here, once, so that walking
//! the file later can never reach an entity that is not there.

use std::fmt;

use super::error::{IgesError, shown};
use super::free::{latin1, trim_blanks};
use super::records::Record;

/// A directory-entry number: the D-section sequence number of an entity's first line (odd).
/// IGES pointers are these numbers, so they are kept rather than turned into indices.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct De(pub u32);

impl De {
    /// Index of the entity in [`super::IgesFile::entities`].
    #[must_use]
    pub fn index(self) -> usize {
        usize::try_from(self.0 / 2).unwrap_or(usize::MAX)
    }
}

impl fmt::Display for De {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "D {}", self.0)
    }
}

/// A directory field that holds either a value or, when negative, a pointer to a definition
/// entity (structure, line font pattern, level, colour).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Attr {
    Value(i32),
    Pointer(De),
}

/// The status number (field 9): four 2-digit values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Status {
    /// 0 visible, 1 blanked.
    pub blank: u8,
    /// 0 independent, 1 physically dependent, 2 logically dependent, 3 both.
    pub subordinate: u8,
    /// 0 geometry, 1 annotation, 2 definition, 3 other, 4 logical/positional,
    /// 5 2D parametric, 6 construction geometry.
    pub entity_use: u8,
    /// 0 global top down, 1 global defer, 2 use hierarchy property.
    pub hierarchy: u8,
}

impl Status {
    /// Whether nothing else refers to the entity, i.e. it is a root for display.
    #[must_use]
    pub fn is_independent(&self) -> bool {
        self.subordinate == 0
    }
}

/// One directory entry, fields numbered as in IGES 5.3 in the comments.
#[derive(Debug, Clone, PartialEq)]
pub struct Directory {
    /// 1 and 11: entity type number.
    pub entity_type: i32,
    /// 2: P-section sequence number of the first parameter line.
    pub parameter_start: u32,
    /// 3: structure (negated pointer to a macro definition for macro instances).
    pub structure: Attr,
    /// 4: line font pattern number, or pointer to a 304.
    pub line_font: Attr,
    /// 5: level number, or pointer to a 406 form 1 definition-levels property.
    pub level: Attr,
    /// 6: view (410) or views-visible associativity (402); `None` for all views.
    pub view: Option<De>,
    /// 7: transformation matrix (124) applied to the entity; `None` for identity.
    pub transform: Option<De>,
    /// 8: label display associativity (402 form 5).
    pub label_display: Option<De>,
    /// 9: status number.
    pub status: Status,
    /// 12: line weight number.
    pub line_weight: i32,
    /// 13: colour number (0 none, 1–8 black, red, green, blue, yellow, magenta, cyan, white), or
    /// pointer to a 314 colour definition.
    pub colour: Attr,
    /// 14: number of P lines holding the parameters.
    pub parameter_lines: u32,
    /// 15: form number.
    pub form: i32,
    /// 18: entity label (up to 8 characters, blanks trimmed).
    pub label: String,
    /// 19: entity subscript number.
    pub subscript: i32,
    /// The file line of the entry's first D line.
    pub line: usize,
}

const NAMES: [&str; 20] = [
    "entity type",
    "parameter data pointer",
    "structure",
    "line font pattern",
    "level",
    "view",
    "transformation matrix",
    "label display associativity",
    "status number",
    "sequence number",
    "entity type",
    "line weight",
    "colour number",
    "parameter line count",
    "form number",
    "reserved",
    "reserved",
    "entity label",
    "entity subscript",
    "sequence number",
];

/// Reads the entry made of D records `first` and `second`; `last_de` is the highest entity
/// number of the file, for the pointer checks.
pub(super) fn parse(
    de: u32,
    first: &Record<'_>,
    second: &Record<'_>,
    last_de: u32,
) -> Result<Directory, IgesError> {
    let fields = EntryFields {
        de,
        first,
        second,
        last_de,
    };
    let entity_type = fields.int(1)?;
    let second_type = fields.int(11)?;
    if second_type != entity_type {
        return Err(fields.error(
            11,
            format!("the second line gives entity type {second_type}, the first {entity_type}"),
        ));
    }
    let parameter_start = fields.count(2)?;
    let parameter_lines = fields.count(14)?;
    Ok(Directory {
        entity_type,
        parameter_start,
        structure: fields.attr(3)?,
        line_font: fields.attr(4)?,
        level: fields.attr(5)?,
        view: fields.pointer(6)?,
        transform: fields.pointer(7)?,
        label_display: fields.pointer(8)?,
        status: fields.status()?,
        line_weight: fields.int(12)?,
        colour: fields.attr(13)?,
        parameter_lines,
        form: fields.int(15)?,
        label: latin1(trim_blanks(fields.raw(18))),
        subscript: fields.int(19)?,
        line: first.line,
    })
}

struct EntryFields<'r, 'a> {
    de: u32,
    first: &'r Record<'a>,
    second: &'r Record<'a>,
    last_de: u32,
}

impl EntryFields<'_, '_> {
    #[must_use]
    /// Field `index` (1–9 on the first line, 11–19 on the second) as written, 8 columns.
    fn raw(&self, index: usize) -> &[u8] {
        let (record, column) = if index <= 10 {
            (self.first, index - 1)
        } else {
            (self.second, index - 11)
        };
        record
            .data
            .get(column * 8..column * 8 + 8)
            .unwrap_or_default()
    }

    #[must_use]
    fn line(&self, index: usize) -> usize {
        if index <= 10 {
            self.first.line
        } else {
            self.second.line
        }
    }

    #[must_use]
    fn error(&self, index: usize, message: String) -> IgesError {
        IgesError::Directory {
            line: self.line(index),
            de: self.de,
            message: format!(
                "field {index} ({}) {message}",
                NAMES.get(index - 1).copied().unwrap_or("unknown")
            ),
        }
    }

    /// An integer field; blank means 0.
    fn int(&self, index: usize) -> Result<i32, IgesError> {
        let raw = self.raw(index);
        let text = trim_blanks(raw);
        let parsed = std::str::from_utf8(text)
            .ok()
            .filter(|t| {
                let digits = t.strip_prefix(['-', '+']).unwrap_or(t);
                !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit())
            })
            .and_then(|t| t.parse::<i32>().ok());
        match parsed {
            _ if text.is_empty() => Ok(0),
            Some(value) => Ok(value),
            None => Err(self.error(
                index,
                format!("should be an integer, found '{}'", shown(raw)),
            )),
        }
    }

    fn count(&self, index: usize) -> Result<u32, IgesError> {
        let value = self.int(index)?;
        u32::try_from(value)
            .map_err(|_| self.error(index, format!("is {value}, but it must not be negative")))
    }

    /// A pointer field where 0 means none and negative values mean nothing.
    fn pointer(&self, index: usize) -> Result<Option<De>, IgesError> {
        let value = self.int(index)?;
        match value {
            0 => Ok(None),
            v if v < 0 => Err(self.error(index, format!("is {v}, but it must be a pointer or 0"))),
            v => self.target(index, v).map(Some),
        }
    }

    /// A field whose negative values are pointers.
    fn attr(&self, index: usize) -> Result<Attr, IgesError> {
        let value = self.int(index)?;
        if value < 0 {
            self.target(index, value.saturating_neg())
                .map(Attr::Pointer)
        } else {
            Ok(Attr::Value(value))
        }
    }

    fn target(&self, index: usize, value: i32) -> Result<De, IgesError> {
        match u32::try_from(value) {
            Ok(v) if v % 2 == 1 && v <= self.last_de => Ok(De(v)),
            _ => Err(self.error(
                index,
                format!(
                    "points at D {value}, which is not a directory entry (odd, at most {})",
                    self.last_de
                ),
            )),
        }
    }

    fn status(&self) -> Result<Status, IgesError> {
        let raw = self.raw(9);
        let mut pairs = [0u8; 4];
        for (slot, pair) in pairs.iter_mut().zip(raw.chunks(2)) {
            let text = trim_blanks(pair);
            if text.is_empty() {
                continue;
            }
            *slot = std::str::from_utf8(text)
                .ok()
                .filter(|t| t.bytes().all(|b| b.is_ascii_digit()))
                .and_then(|t| t.parse().ok())
                .ok_or_else(|| {
                    self.error(
                        9,
                        format!("should be four 2-digit numbers, found '{}'", shown(raw)),
                    )
                })?;
        }
        let [blank, subordinate, entity_use, hierarchy] = pairs;
        Ok(Status {
            blank,
            subordinate,
            entity_use,
            hierarchy,
        })
    }
}
