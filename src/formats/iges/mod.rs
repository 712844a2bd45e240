//! The IGES 5.3 file structure, read from the fixed 80-column ASCII form into a table of
//! entities addressed by directory-entry number, for a geometry mapping to walk by pointer.
//!
//! Reading goes bytes → records sorted into the S, G, D, P, T sections (`records`) → the Global
//! section's delimiters, unit and scale (`global`) → directory entries (`directory`) → each
//! entity's parameters, joined from columns 1–64 of its P lines and split with the global
//! delimiters (`free`, `entity`). Everything structural is checked while reading (section order,
//! sequence numbers, Terminate counts, DE pointers, parameter back pointers, the entity type
//! repeated as parameter 0); what a parameter means is checked when the mapping asks for it
//! through the typed accessors of [`Entity`]. Every error is one line that starts with the line
//! of the file it is about. The compressed ASCII and binary forms are refused by name.
//!
//! Nothing here does I/O: the caller hands in the bytes and prefixes the file name to errors.

#![forbid(unsafe_code)]
#![deny(
    clippy::indexing_slicing,
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic
)]

mod directory;
mod entity;
mod error;
mod free;
mod global;
pub mod map;
mod names;
mod records;
mod transform;

#[cfg(test)]
mod test_files;
#[cfg(test)]
mod test_robust;
#[cfg(test)]
mod test_support;
#[cfg(test)]
mod test_synthetic;

use std::collections::BTreeMap;

pub use directory::{Attr, De, Directory, Status};
pub use entity::{Entity, Value};
pub use error::IgesError;
pub use global::{Global, Unit};
pub use names::type_name;
pub use transform::Transform;

/// A parsed IGES file: the Start text, the Global section and the entities in DE order.
#[derive(Debug, Clone, PartialEq)]
pub struct IgesFile {
    /// The Start section, columns 1–72 of each line with trailing blanks removed, one line each.
    pub start: String,
    pub global: Global,
    /// Entity `D n` is at index `(n - 1) / 2`.
    entities: Vec<Entity>,
}

impl IgesFile {
    /// Reads an IGES file in the fixed 80-column ASCII form.
    pub fn parse(bytes: &[u8]) -> Result<Self, IgesError> {
        let sections = records::split(bytes)?;
        let global = global::parse(&sections.global)?;
        let start = sections
            .start
            .iter()
            .map(|r| free::latin1(r.data).trim_end().to_owned())
            .collect::<Vec<_>>()
            .join("\n");
        let directory = &sections.directory;
        if directory.len() % 2 == 1 {
            let line = directory.last().map_or(1, |r| r.line);
            return Err(IgesError::layout(
                line,
                format!(
                    "the D section has {} lines, but every directory entry takes two",
                    directory.len()
                ),
            ));
        }
        let last_de = u32::try_from(directory.len().saturating_sub(1)).unwrap_or(u32::MAX);
        let context = entity::Context {
            parameter: &sections.parameter,
            last_de,
            parameter_delimiter: global.parameter_delimiter,
            record_delimiter: global.record_delimiter,
        };
        let mut entities = Vec::with_capacity(directory.len() / 2);
        for (pair_index, pair) in directory.chunks_exact(2).enumerate() {
            let [first, second] = pair else { continue };
            let de = u32::try_from(2 * pair_index + 1).unwrap_or(u32::MAX);
            let entry = directory::parse(de, first, second, last_de)?;
            entities.push(entity::parse(De(de), entry, &context)?);
        }
        Ok(Self {
            start,
            global,
            entities,
        })
    }

    /// All entities in DE order.
    #[must_use]
    pub fn entities(&self) -> &[Entity] {
        &self.entities
    }

    /// The entity numbered `de`, `None` if there is none (an even number, or past the end).
    #[must_use]
    pub fn entity(&self, de: De) -> Option<&Entity> {
        if de.0.is_multiple_of(2) {
            return None;
        }
        self.entities.get(de.index())
    }

    /// The entity that pointer parameter `k` of `from` points at.
    pub fn follow(&self, from: &Entity, k: usize) -> Result<&Entity, IgesError> {
        let de = from.pointer(k)?;
        self.entity(de)
            .ok_or_else(|| from.param_error(k, format!("points at {de}, which does not exist")))
    }

    /// Like [`Self::follow`], with 0 or an empty field meaning none.
    pub fn follow_optional(&self, from: &Entity, k: usize) -> Result<Option<&Entity>, IgesError> {
        match from.optional_pointer(k)? {
            None => Ok(None),
            Some(_) => self.follow(from, k).map(Some),
        }
    }

    /// The entity's placement in model space: the composition of its transformation chain
    /// (identity when its DE has no transformation matrix).
    pub fn transform(&self, entity: &Entity) -> Result<Transform, IgesError> {
        transform::placement(self, entity)
    }

    /// How many entities of each type the file holds, for inventories and tests.
    #[must_use]
    pub fn count_by_type(&self) -> BTreeMap<i32, usize> {
        let mut counts = BTreeMap::new();
        for entity in &self.entities {
            *counts.entry(entity.entity_type()).or_insert(0) += 1;
        }
        counts
    }

    /// Millimetres per model-space unit (see [`Global::mm_per_unit`]).
    #[must_use]
    pub fn mm_per_unit(&self) -> f64 {
        self.global.mm_per_unit()
    }
}

/// The IGES format (read only): trimmed faces as trimmed NURBS surfaces in millimetres.
#[derive(Debug, Clone, Copy)]
pub struct Iges;

impl super::FileFormat for Iges {
    fn name(&self) -> &'static str {
        "IGES"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["igs", "iges"]
    }

    fn read(
        &self,
        bytes: &[u8],
        ctx: &super::LoadContext<'_>,
    ) -> Result<super::Import, super::FormatError> {
        super::cad::check_read(bytes, ctx)?;
        map::read_iges_with_stem(bytes, ctx.stem)
            .map(super::cad::to_import)
            .map_err(super::FormatError::new)
    }
}
