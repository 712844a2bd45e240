//! The parsed file: header fields and a compact entity table.
//!
//! Layout, chosen for parse speed and memory (a 1.8 MB file has ~250 000 parameters):
//! - every parameter is a 16-byte [`Param`] in one arena `Vec`; a list is a range of that arena
//!   (its items are contiguous), so a file costs a handful of allocations instead of one per
//!   list;
//! - decoded string contents share one `String`; strings are ranges of it;
//! - entity and enumeration names are interned (a file has a few hundred distinct ones), stored
//!   upper-case, and referred to by number;
//! - a record is a name plus a range of parameters; an entity is an id, a line and a range of
//!   records (one for a simple instance, several for a complex one);
//! - lookup by id goes through a direct table when ids are dense enough (the usual case), and a
//!   sorted array with binary search otherwise, so sparse ids never size a table.
//!
//! The raw arena types stay private; callers use the borrowing views of the `access` module,
//! which also carry the context for precise error messages.

use std::collections::HashMap;

use super::error::StepError;

/// One parameter value in the arena. Ranges are `(start, len)` into the owning table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Param {
    Int(i64),
    Real(f64),
    /// Range of [`StepFile::text`].
    Str(u32, u32),
    /// Interned name.
    Enum(u32),
    Ref(u64),
    /// Range of [`StepFile::params`].
    List(u32, u32),
    /// Interned type name and the arena index of the one wrapped value.
    Typed(u32, u32),
    Unset,
    Derived,
    /// Range of [`StepFile::text`] holding the hex digits as written.
    Binary(u32, u32),
}

/// One `NAME(params)` part of an instance.
#[derive(Debug, Clone, Copy)]
pub(super) struct Record {
    pub(super) name: u32,
    pub(super) start: u32,
    pub(super) len: u32,
}

/// One entity instance `#id = …;`.
#[derive(Debug, Clone, Copy)]
pub(super) struct Entity {
    pub(super) id: u64,
    pub(super) line: u32,
    /// Range of [`StepFile::records`].
    pub(super) start: u32,
    pub(super) len: u32,
}

/// The HEADER section's standard entries. Missing or malformed entries leave fields empty
/// rather than failing: the header is informative and files in the wild get it wrong.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Header {
    /// FILE_DESCRIPTION.description.
    pub description: Vec<String>,
    /// FILE_DESCRIPTION.implementation_level, e.g. `2;1`.
    pub implementation_level: String,
    /// FILE_NAME.name.
    pub name: String,
    /// FILE_NAME.time_stamp.
    pub time_stamp: String,
    /// FILE_NAME.author.
    pub author: Vec<String>,
    /// FILE_NAME.organization.
    pub organization: Vec<String>,
    /// FILE_NAME.preprocessor_version.
    pub preprocessor_version: String,
    /// FILE_NAME.originating_system: the CAD system that wrote the file.
    pub originating_system: String,
    /// FILE_NAME.authorization.
    pub authorization: String,
    /// FILE_SCHEMA names, upper-case, without the object identifier: `AUTOMOTIVE_DESIGN`,
    /// `CONFIG_CONTROL_DESIGN`, `AP242_MANAGED_MODEL_BASED_3D_ENGINEERING_MIM_LF`.
    pub schemas: Vec<String>,
    /// FILE_SCHEMA entries as written: `AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }`.
    pub schema_identifiers: Vec<String>,
}

/// A whole parsed STEP file. Build it with [`StepFile::parse`]; walk it with
/// [`StepFile::get`] and the views in the `access` module.
#[derive(Debug, Clone)]
pub struct StepFile {
    /// The HEADER section.
    pub header: Header,
    pub(super) entities: Vec<Entity>,
    pub(super) records: Vec<Record>,
    pub(super) params: Vec<Param>,
    pub(super) text: String,
    pub(super) names: Vec<Box<str>>,
    pub(super) index: Index,
}

/// Lookup from `#id` to a position in [`StepFile::entities`].
#[derive(Debug, Clone)]
pub(super) enum Index {
    /// `table[id]` is the position, or `u32::MAX` for none.
    Dense(Vec<u32>),
    /// `(id, position)` sorted by id.
    Sorted(Vec<(u64, u32)>),
}

/// Marks an id with no entity in [`Index::Dense`].
const NONE: u32 = u32::MAX;

impl Index {
    /// Builds the index, reporting the first duplicate id in file order. The direct table is
    /// used only when it is at most a few times the entity count, so a file with one entity
    /// `#4000000000` costs no more memory than any other.
    pub(super) fn build(entities: &[Entity]) -> Result<Index, StepError> {
        let max = entities.iter().map(|e| e.id).max().unwrap_or(0);
        let dense_limit = (entities.len() as u64)
            .saturating_mul(4)
            .saturating_add(1024);
        if max < dense_limit && entities.len() < NONE as usize {
            let size = usize::try_from(max).unwrap_or(0).saturating_add(1);
            let mut table = vec![NONE; size];
            for (pos, e) in (0u32..).zip(entities) {
                let slot = usize::try_from(e.id).ok().and_then(|id| table.get_mut(id));
                if let Some(slot) = slot {
                    if *slot != NONE {
                        return Err(duplicate(entities, *slot, e));
                    }
                    *slot = pos;
                }
            }
            return Ok(Index::Dense(table));
        }
        let mut sorted: Vec<(u64, u32)> = (0u32..).zip(entities).map(|(p, e)| (e.id, p)).collect();
        sorted.sort_unstable();
        // The later definition (in file order) of the first duplicated id is reported.
        let dup = sorted
            .windows(2)
            .filter_map(|w| match w {
                [a, b] if a.0 == b.0 => Some((a.1, b.1)),
                _ => None,
            })
            .min_by_key(|&(_, second)| second);
        if let Some((first, second)) = dup {
            let later = entities.get(second as usize).copied();
            if let Some(later) = later {
                return Err(duplicate(entities, first, &later));
            }
        }
        Ok(Index::Sorted(sorted))
    }

    /// The position of `id` in the entity table.
    #[must_use]
    pub(super) fn find(&self, id: u64) -> Option<usize> {
        match self {
            Index::Dense(table) => {
                let pos = *usize::try_from(id).ok().and_then(|i| table.get(i))?;
                (pos != NONE).then_some(pos as usize)
            }
            Index::Sorted(sorted) => sorted
                .binary_search_by_key(&id, |&(id, _)| id)
                .ok()
                .and_then(|i| sorted.get(i))
                .map(|&(_, pos)| pos as usize),
        }
    }
}

#[must_use]
fn duplicate(entities: &[Entity], first: u32, second: &Entity) -> StepError {
    let first_line = entities.get(first as usize).map_or(0, |e| e.line);
    StepError::DuplicateId {
        line: second.line,
        id: second.id,
        first: first_line,
    }
}

/// Interns upper-cased names to small numbers while parsing. std's SipHash is kept: measured,
/// a faster hash saved nothing visible (a file has only ~40 000 names to look up per 2 MB), and
/// SipHash keeps crafted names from degrading the table.
#[derive(Default)]
pub(super) struct Interner {
    map: HashMap<Box<[u8]>, u32>,
    pub(super) names: Vec<Box<str>>,
    upper: Vec<u8>,
}

impl Interner {
    /// The number of `name` (ASCII letters, digits, `_`, `!`), upper-cased; `None` only if a
    /// file has more than `u32::MAX` distinct names.
    #[must_use]
    pub(super) fn intern(&mut self, name: &[u8]) -> Option<u32> {
        let key = if name.iter().any(u8::is_ascii_lowercase) {
            self.upper.clear();
            self.upper.extend(name.iter().map(u8::to_ascii_uppercase));
            self.upper.as_slice()
        } else {
            name
        };
        if let Some(&n) = self.map.get(key) {
            return Some(n);
        }
        let n = u32::try_from(self.names.len()).ok()?;
        let text: String = key.iter().map(|&b| char::from(b)).collect();
        self.names.push(text.into_boxed_str());
        self.map.insert(key.into(), n);
        Some(n)
    }
}
