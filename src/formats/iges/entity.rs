//! Entities: a directory entry with its parameters, and the typed access the geometry mapping
//! uses. Parameters are numbered as in the IGES 5.3 entity descriptions, 1 being the first after
//! the entity type (parameter 0). Every accessor either returns the value or an error naming the
//! entity, the parameter and what was found, at the line the parameter is on, so a mapping can be
//! written as a plain sequence of `?` and still report precisely.

use super::directory::{De, Directory};
use super::error::{IgesError, shown, shown_str};
use super::free::{Joined, Number, Token, latin1, number, tokenize, trim_blanks};
use super::names::type_name;
use super::records::Record;

/// Columns 1–64 of a P line hold the parameters; 65–72 the pointer back to the entity.
const PARAMETER_COLUMNS: usize = 64;

/// One parameter as written.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    /// A defaulted (empty) field.
    Empty,
    Int(i64),
    Real(f64),
    /// A Hollerith string's contents.
    Text(String),
    /// Text that is no IGES number, kept to be shown when something asks for a number.
    Invalid(String),
}

#[derive(Debug, Clone, PartialEq)]
struct Param {
    value: Value,
    line: usize,
}

/// One entity of the file.
#[derive(Debug, Clone, PartialEq)]
pub struct Entity {
    de: De,
    directory: Directory,
    /// Parameter 0 is the entity type.
    params: Vec<Param>,
    /// The highest entity number of the file, to check pointers without the file at hand.
    last_de: u32,
    /// The last P line, where a missing parameter is reported.
    last_line: usize,
}

impl Entity {
    /// The entity number (DE sequence number) pointers use.
    #[must_use]
    pub fn de(&self) -> De {
        self.de
    }

    #[must_use]
    pub fn entity_type(&self) -> i32 {
        self.directory.entity_type
    }

    #[must_use]
    pub fn form(&self) -> i32 {
        self.directory.form
    }

    /// The IGES name of the entity's type.
    #[must_use]
    pub fn type_name(&self) -> &'static str {
        type_name(self.directory.entity_type)
    }

    #[must_use]
    pub fn directory(&self) -> &Directory {
        &self.directory
    }

    /// How many parameters follow the entity type (the highest valid `k`).
    #[must_use]
    pub fn param_count(&self) -> usize {
        self.params.len().saturating_sub(1)
    }

    /// Parameter `k` as written, `None` past the end.
    #[must_use]
    pub fn value(&self, k: usize) -> Option<&Value> {
        self.params.get(k).map(|p| &p.value)
    }

    /// An error about the entity as a whole, at its directory entry.
    #[must_use]
    pub fn error(&self, message: impl Into<String>) -> IgesError {
        self.error_at(self.directory.line, message.into())
    }

    /// An error about parameter `k`: the message reads `parameter k {what}`.
    #[must_use]
    pub fn param_error(&self, k: usize, what: impl AsRef<str>) -> IgesError {
        let line = self.params.get(k).map_or(self.last_line, |p| p.line);
        self.error_at(line, format!("parameter {k} {}", what.as_ref()))
    }

    #[must_use]
    fn error_at(&self, line: usize, message: String) -> IgesError {
        IgesError::Entity {
            line,
            de: self.de.0,
            entity_type: self.directory.entity_type,
            message,
        }
    }

    fn present(&self, k: usize) -> Result<&Value, IgesError> {
        self.value(k).ok_or_else(|| {
            self.param_error(
                k,
                format!("is missing (the entity has {})", self.param_count()),
            )
        })
    }

    #[must_use]
    fn wrong(&self, k: usize, what: &str, found: &Value) -> IgesError {
        self.param_error(k, format!("should be {what}, found {}", describe(found)))
    }

    /// Integer parameter `k`; an empty field is 0.
    pub fn int(&self, k: usize) -> Result<i64, IgesError> {
        match self.present(k)? {
            Value::Empty => Ok(0),
            Value::Int(v) => Ok(*v),
            other => Err(self.wrong(k, "an integer", other)),
        }
    }

    /// Integer parameter `k`, or `default` when it is empty or omitted at the end (optional
    /// trailing parameters).
    pub fn int_or(&self, k: usize, default: i64) -> Result<i64, IgesError> {
        match self.value(k) {
            None | Some(Value::Empty) => Ok(default),
            Some(_) => self.int(k),
        }
    }

    /// Real parameter `k`; an integer is taken as a real (writers put `0` for `0.`), an empty
    /// field is 0.0.
    pub fn real(&self, k: usize) -> Result<f64, IgesError> {
        match self.present(k)? {
            Value::Empty => Ok(0.0),
            Value::Int(v) => Ok(*v as f64),
            Value::Real(v) => Ok(*v),
            other => Err(self.wrong(k, "a real", other)),
        }
    }

    /// Real parameter `k`, or `default` when it is empty or omitted at the end.
    pub fn real_or(&self, k: usize, default: f64) -> Result<f64, IgesError> {
        match self.value(k) {
            None | Some(Value::Empty) => Ok(default),
            Some(_) => self.real(k),
        }
    }

    /// String parameter `k` (a Hollerith string); an empty field is "".
    pub fn string(&self, k: usize) -> Result<&str, IgesError> {
        match self.present(k)? {
            Value::Empty => Ok(""),
            Value::Text(text) => Ok(text),
            other => Err(self.wrong(k, "a string (nH...)", other)),
        }
    }

    /// Pointer parameter `k` that must point somewhere: 0 or empty is an error.
    pub fn pointer(&self, k: usize) -> Result<De, IgesError> {
        self.optional_pointer(k)?
            .ok_or_else(|| self.param_error(k, "is a null pointer where an entity is required"))
    }

    /// Pointer parameter `k` where 0, empty or omission means "none". A pointer must be the
    /// number of an existing entry (odd, within the D section); anything else is an error.
    pub fn optional_pointer(&self, k: usize) -> Result<Option<De>, IgesError> {
        let value = match self.value(k) {
            None | Some(Value::Empty) => return Ok(None),
            Some(value) => value,
        };
        let Value::Int(v) = value else {
            return Err(self.wrong(k, "a pointer", value));
        };
        match u32::try_from(*v) {
            Ok(0) => Ok(None),
            Ok(p) if p % 2 == 1 && p <= self.last_de => Ok(Some(De(p))),
            _ => Err(self.param_error(
                k,
                format!(
                    "points at D {v}, which is not a directory entry (odd, at most {})",
                    self.last_de
                ),
            )),
        }
    }

    /// A count at parameter `k`, checked to be non-negative and at most the number of
    /// parameters the entity has, since every counted item takes at least one parameter. That
    /// bound is what makes `Vec::with_capacity(count)` safe against a damaged file.
    pub fn count(&self, k: usize) -> Result<usize, IgesError> {
        let n = self.int(k)?;
        match usize::try_from(n) {
            Ok(n) if n <= self.param_count() => Ok(n),
            Ok(_) => Err(self.param_error(
                k,
                format!(
                    "is a count of {n}, more than the entity's {} parameters",
                    self.param_count()
                ),
            )),
            Err(_) => Err(self.param_error(k, format!("is a count of {n}, which is negative"))),
        }
    }

    /// `n` parameters from `first` on, checked to exist before anything is allocated.
    fn range(&self, first: usize, n: usize) -> Result<std::ops::Range<usize>, IgesError> {
        let end = first.checked_add(n);
        match end {
            Some(end) if end <= self.param_count() + 1 => Ok(first..end),
            _ => Err(self.param_error(
                first,
                format!(
                    "starts a list of {n} that runs past the entity's {} parameters",
                    self.param_count()
                ),
            )),
        }
    }

    /// `n` reals from parameter `first` on (knots, weights, coordinates).
    pub fn reals(&self, first: usize, n: usize) -> Result<Vec<f64>, IgesError> {
        self.range(first, n)?.map(|k| self.real(k)).collect()
    }

    /// `n` integers from parameter `first` on.
    pub fn ints(&self, first: usize, n: usize) -> Result<Vec<i64>, IgesError> {
        self.range(first, n)?.map(|k| self.int(k)).collect()
    }

    /// `n` required pointers from parameter `first` on.
    pub fn pointers(&self, first: usize, n: usize) -> Result<Vec<De>, IgesError> {
        self.range(first, n)?.map(|k| self.pointer(k)).collect()
    }
}

#[must_use]
/// What a parameter holds, for messages.
fn describe(value: &Value) -> String {
    match value {
        Value::Empty => "an empty field".to_owned(),
        Value::Int(v) => format!("the integer {v}"),
        Value::Real(v) => format!("the real {v:?}"),
        Value::Text(t) => format!("the string '{}'", shown_str(t)),
        Value::Invalid(t) => format!("'{}'", shown_str(t)),
    }
}

/// What parsing an entity needs besides its directory entry.
pub(super) struct Context<'r, 'a> {
    pub parameter: &'r [Record<'a>],
    pub last_de: u32,
    pub parameter_delimiter: u8,
    pub record_delimiter: u8,
}

/// Reads the parameters of the entity at `de` described by `directory`. A null entity (type 0)
/// has none to read; the standard lets its other fields be anything.
pub(super) fn parse(
    de: De,
    directory: Directory,
    context: &Context<'_, '_>,
) -> Result<Entity, IgesError> {
    let mut entity = Entity {
        de,
        params: vec![Param {
            value: Value::Int(i64::from(directory.entity_type)),
            line: directory.line,
        }],
        directory,
        last_de: context.last_de,
        last_line: 0,
    };
    entity.last_line = entity.directory.line + 1;
    if entity.directory.entity_type == 0 {
        return Ok(entity);
    }
    let records = parameter_records(&entity, context.parameter)?;
    entity.last_line = records.last().map_or(entity.last_line, |r| r.line);
    for record in records {
        let back = record.data.get(PARAMETER_COLUMNS..).unwrap_or_default();
        let back = trim_blanks(back);
        let points_back = std::str::from_utf8(back)
            .ok()
            .and_then(|t| t.parse::<u32>().ok());
        if points_back != Some(de.0) {
            return Err(entity.error_at(
                record.line,
                format!(
                    "this P line is in the entity's parameter data, but columns 65-72 point back at '{}', not {}",
                    shown(back),
                    de.0
                ),
            ));
        }
    }
    let joined = Joined::new(PARAMETER_COLUMNS, records.iter().map(|r| (r.line, r.data)));
    let tokens = tokenize(
        &joined,
        context.parameter_delimiter,
        context.record_delimiter,
    )
    .map_err(|e| entity.error_at(e.line, e.message))?;
    let mut params = Vec::with_capacity(tokens.len());
    for located in tokens {
        let value = match located.token {
            Token::Text(text) => Value::Text(text),
            Token::Plain(raw) => match number(raw) {
                Number::Empty => Value::Empty,
                Number::Int(v) => Value::Int(v),
                Number::Real(v) => Value::Real(v),
                Number::Invalid => Value::Invalid(latin1(raw)),
            },
        };
        params.push(Param {
            value,
            line: located.line,
        });
    }
    let first = params.first();
    if first.map(|p| &p.value) != Some(&Value::Int(i64::from(entity.directory.entity_type))) {
        let found = first.map_or("nothing".to_owned(), |p| describe(&p.value));
        let line = first.map_or(entity.last_line, |p| p.line);
        return Err(entity.error_at(
            line,
            format!("the parameters start with {found}, not the entity type"),
        ));
    }
    entity.params = params;
    Ok(entity)
}

/// The P lines the directory entry claims, checked to lie inside the P section before any
/// slicing, so that a damaged count or pointer is an error and never an allocation.
fn parameter_records<'r, 'a>(
    entity: &Entity,
    parameter: &'r [Record<'a>],
) -> Result<&'r [Record<'a>], IgesError> {
    let directory = &entity.directory;
    let start = usize::try_from(directory.parameter_start).unwrap_or(usize::MAX);
    let count = usize::try_from(directory.parameter_lines).unwrap_or(usize::MAX);
    let end = start.checked_add(count).map(|e| e - 1);
    let bad = |message: String| {
        Err(IgesError::Directory {
            line: directory.line,
            de: entity.de.0,
            message,
        })
    };
    if start == 0 || count == 0 {
        return bad(format!(
            "entity {} has parameter data pointer {start} and {count} parameter lines; both must be at least 1",
            directory.entity_type
        ));
    }
    match end.and_then(|end| parameter.get(start - 1..end)) {
        Some(records) => Ok(records),
        None => bad(format!(
            "entity {} claims P lines {start} to {}, but the P section has {} lines",
            directory.entity_type,
            end.map_or("beyond".to_owned(), |e| e.to_string()),
            parameter.len()
        )),
    }
}
