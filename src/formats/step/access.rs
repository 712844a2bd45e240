//! The typed access layer: borrowing views over a [`StepFile`] for the geometry mapping.
//!
//! Each view carries where it came from (entity, record, parameter index and name, list item
//! path), so that every accessor can fail with a message that points at the exact spot:
//! `line 1234: #45 = PLANE: parameter 2 (position) should be a reference, found a string`.
//! Parameter indices are 0-based in the API, like Rust slices; messages count from 1, like the
//! schema documentation ("parameter 2" is index 1).

use std::fmt;

use super::error::StepError;
use super::model::{Entity, Param, Record, StepFile};
use super::params::{ListRef, ParamRef, Path};

impl StepFile {
    /// Parses a whole STEP file from its bytes. Strings that are not valid UTF-8 are decoded
    /// as ISO 8859-1 rather than refused.
    pub fn parse(bytes: &[u8]) -> Result<StepFile, StepError> {
        super::parser::parse(bytes)
    }

    /// Parses a whole STEP file from text.
    pub fn parse_str(text: &str) -> Result<StepFile, StepError> {
        Self::parse(text.as_bytes())
    }

    /// The number of entity instances.
    #[must_use]
    pub fn len(&self) -> usize {
        self.entities.len()
    }

    /// Whether the DATA sections hold no instance.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.entities.is_empty()
    }

    /// All instances in file order.
    #[must_use]
    pub fn entities(&self) -> impl ExactSizeIterator<Item = EntityRef<'_>> + '_ {
        self.entities
            .iter()
            .map(move |entity| EntityRef { file: self, entity })
    }

    /// The instance `#id`. Without a referring instance the error has no line; prefer
    /// [`ParamRef::entity`] when following a reference, whose error names the referrer.
    pub fn get(&self, id: u64) -> Result<EntityRef<'_>, StepError> {
        self.find(id).ok_or(StepError::NoSuchEntity { id })
    }

    /// The instance `#id`, if there is one.
    #[must_use]
    pub fn find(&self, id: u64) -> Option<EntityRef<'_>> {
        let entity = self.entities.get(self.index.find(id)?)?;
        Some(EntityRef { file: self, entity })
    }

    /// Checks that every reference in the file points at an instance, reporting the first
    /// dangling one (in file order) with its referrer. Optional: following references with
    /// [`ParamRef::entity`] reports the same error lazily.
    pub fn check_references(&self) -> Result<(), StepError> {
        fn walk(p: ParamRef<'_>) -> Result<(), StepError> {
            match p.value() {
                Value::Ref(_) => p.entity().map(drop),
                Value::List(list) => list.iter().try_for_each(walk),
                Value::Typed(_, inner) => walk(inner),
                _ => Ok(()),
            }
        }
        // Recursion depth is bounded by the parser's nesting limit.
        self.entities()
            .flat_map(|e| e.records())
            .flat_map(|r| r.params())
            .try_for_each(walk)
    }

    /// How many records of each type name the file has (a complex instance counts once for
    /// each of its records), sorted by name.
    #[must_use]
    pub fn type_counts(&self) -> Vec<(&str, usize)> {
        let mut counts = vec![0usize; self.names.len()];
        for record in &self.records {
            if let Some(c) = counts.get_mut(record.name as usize) {
                *c += 1;
            }
        }
        let mut out: Vec<(&str, usize)> = self
            .names
            .iter()
            .zip(counts)
            .filter(|&(_, c)| c > 0)
            .map(|(n, c)| (n.as_ref(), c))
            .collect();
        out.sort_unstable();
        out
    }

    pub(super) fn name(&self, n: u32) -> &str {
        self.names.get(n as usize).map_or("", AsRef::as_ref)
    }

    pub(super) fn text_at(&self, start: u32, len: u32) -> &str {
        let start = start as usize;
        self.text
            .get(start..start.saturating_add(len as usize))
            .unwrap_or_default()
    }

    pub(super) fn slice<T>(table: &[T], start: u32, len: u32) -> &[T] {
        let start = start as usize;
        table
            .get(start..start.saturating_add(len as usize))
            .unwrap_or_default()
    }
}

/// One entity instance. Cheap to copy.
#[derive(Clone, Copy)]
pub struct EntityRef<'a> {
    file: &'a StepFile,
    entity: &'a Entity,
}

impl<'a> EntityRef<'a> {
    /// The instance name `#id`.
    #[must_use]
    pub fn id(&self) -> u64 {
        self.entity.id
    }

    /// The line where `#id` is written.
    #[must_use]
    pub fn line(&self) -> u32 {
        self.entity.line
    }

    /// Whether this is a complex instance `#id = (A(…) B(…));` with several records.
    #[must_use]
    pub fn is_complex(&self) -> bool {
        self.entity.len > 1
    }

    /// The type name of a simple instance (upper-case); for a complex instance, the first
    /// record's name (the first written; the standard orders them alphabetically).
    #[must_use]
    pub fn name(&self) -> &'a str {
        self.records().next().map_or("", |r| r.name())
    }

    /// The records: one for a simple instance, several for a complex one, as written.
    #[must_use]
    pub fn records(&self) -> impl ExactSizeIterator<Item = RecordRef<'a>> + use<'a> {
        let (file, entity) = (self.file, self.entity);
        StepFile::slice(&file.records, entity.start, entity.len)
            .iter()
            .map(move |record| RecordRef {
                file,
                entity,
                record,
            })
    }

    /// The record of type `name` (upper-case), e.g. `B_SPLINE_SURFACE_WITH_KNOTS` in a complex
    /// rational B-spline instance, or `PLANE` in a simple one.
    pub fn record(&self, name: &str) -> Result<RecordRef<'a>, StepError> {
        self.records()
            .find(|r| r.name() == name)
            .ok_or_else(|| StepError::MissingRecord {
                line: self.line(),
                id: self.id(),
                names: self.type_names(),
                wanted: name.to_owned(),
            })
    }

    /// Whether the instance has a record of type `name`.
    #[must_use]
    pub fn has_record(&self, name: &str) -> bool {
        self.records().any(|r| r.name() == name)
    }

    /// The type names as written: `PLANE`, or `(BOUNDED_CURVE B_SPLINE_CURVE …)`.
    #[must_use]
    pub fn type_names(&self) -> String {
        let names: Vec<&str> = self.records().map(|r| r.name()).collect();
        if self.is_complex() {
            format!("({})", names.join(" "))
        } else {
            names.concat()
        }
    }

    /// An error about this instance found by the caller, e.g. "a circle with radius 0".
    #[must_use]
    pub fn invalid(&self, message: impl Into<String>) -> StepError {
        let context = format!("#{} = {}", self.id(), self.type_names());
        StepError::Invalid {
            line: self.line(),
            id: self.id(),
            context,
            message: message.into(),
        }
    }
}

/// One `NAME(params)` record of an instance.
#[derive(Clone, Copy)]
pub struct RecordRef<'a> {
    pub(super) file: &'a StepFile,
    entity: &'a Entity,
    record: &'a Record,
}

impl<'a> RecordRef<'a> {
    /// The record's type name, upper-case.
    #[must_use]
    pub fn name(&self) -> &'a str {
        self.file.name(self.record.name)
    }

    /// The instance this record belongs to.
    #[must_use]
    pub fn entity(&self) -> EntityRef<'a> {
        EntityRef {
            file: self.file,
            entity: self.entity,
        }
    }

    /// The number of parameters.
    #[must_use]
    pub fn len(&self) -> usize {
        self.record.len as usize
    }

    /// Whether the record has no parameters, like `LENGTH_UNIT()`.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.record.len == 0
    }

    /// Parameter `index` (0-based), whose schema attribute `name` will appear in error messages
    /// (`""` for none).
    pub fn param(&self, index: usize, name: &'static str) -> Result<ParamRef<'a>, StepError> {
        let params = StepFile::slice(&self.file.params, self.record.start, self.record.len);
        let at = |param| ParamRef {
            record: *self,
            param,
            index,
            name,
            path: Path::default(),
        };
        match params.get(index) {
            Some(param) => Ok(at(param)),
            None => {
                let context = at(&Param::Unset).context();
                Err(self.missing(context, params.len()))
            }
        }
    }

    /// All parameters, without attribute names.
    #[must_use]
    pub fn params(&self) -> impl ExactSizeIterator<Item = ParamRef<'a>> + use<'a> {
        let record = *self;
        StepFile::slice(&self.file.params, self.record.start, self.record.len)
            .iter()
            .enumerate()
            .map(move |(index, param)| ParamRef {
                record,
                param,
                index,
                name: "",
                path: Path::default(),
            })
    }

    fn missing(&self, context: String, count: usize) -> StepError {
        StepError::Missing {
            line: self.entity.line,
            id: self.entity.id,
            context,
            count,
        }
    }

    /// `#45 = PLANE`, or `#45 = B_SPLINE_CURVE (complex instance)`.
    pub(super) fn context(&self) -> String {
        let complex = if self.entity.len > 1 {
            " (complex instance)"
        } else {
            ""
        };
        format!("#{} = {}{complex}", self.entity.id, self.name())
    }
}

/// A borrowed parameter value, for `match`.
#[derive(Clone, Copy, Debug)]
pub enum Value<'a> {
    /// An integer.
    Int(i64),
    /// A real.
    Real(f64),
    /// A decoded string.
    Str(&'a str),
    /// An enumeration value without its dots, upper-case: `T`, `UNSPECIFIED`.
    Enum(&'a str),
    /// A reference `#id`.
    Ref(u64),
    /// An aggregate `( … )`.
    List(ListRef<'a>),
    /// A typed parameter such as `LENGTH_MEASURE(5.)`: its type name and value.
    Typed(&'a str, ParamRef<'a>),
    /// `$`: no value.
    Unset,
    /// `*`: derived, value given by a supertype's rule.
    Derived,
    /// A binary literal's hex digits as written (the first counts the unused high bits).
    Binary(&'a str),
}

/// Short forms, so that views can be printed in tests and logs without dumping the whole file.
impl fmt::Debug for EntityRef<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "EntityRef(#{} = {}, line {})",
            self.id(),
            self.type_names(),
            self.line()
        )
    }
}

impl fmt::Debug for RecordRef<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "RecordRef({})", self.context())
    }
}
