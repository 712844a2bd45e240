//! Parameter views: typed accessors that fail with the parameter's full context.

use std::fmt::{self, Write as _};

use super::access::{EntityRef, RecordRef, Value};
use super::error::StepError;
use super::model::{Param, StepFile};

/// One parameter (or list item) of a record, with where it came from.
#[derive(Clone, Copy)]
pub struct ParamRef<'a> {
    pub(super) record: RecordRef<'a>,
    pub(super) param: &'a Param,
    /// 0-based position in the record.
    pub(super) index: usize,
    /// Schema attribute name for messages, or `""`.
    pub(super) name: &'static str,
    pub(super) path: Path,
}

/// Where in nested lists a parameter sits: the first [`Path::KEPT`] item indices, and the depth.
#[derive(Clone, Copy, Default)]
pub(super) struct Path {
    items: [u32; Path::KEPT],
    depth: u8,
}

impl Path {
    const KEPT: usize = 4;

    #[must_use]
    fn child(self, index: usize) -> Path {
        let mut out = self;
        if let Some(slot) = out.items.get_mut(self.depth as usize) {
            *slot = u32::try_from(index).unwrap_or(u32::MAX);
        }
        out.depth = out.depth.saturating_add(1);
        out
    }
}

impl<'a> ParamRef<'a> {
    fn file(&self) -> &'a StepFile {
        self.record.file
    }

    /// The value, for `match`.
    #[must_use]
    pub fn value(&self) -> Value<'a> {
        let file = self.file();
        match *self.param {
            Param::Int(i) => Value::Int(i),
            Param::Real(r) => Value::Real(r),
            Param::Str(start, len) => Value::Str(file.text_at(start, len)),
            Param::Enum(n) => Value::Enum(file.name(n)),
            Param::Ref(id) => Value::Ref(id),
            Param::List(start, len) => Value::List(ListRef {
                parent: *self,
                items: StepFile::slice(&file.params, start, len),
            }),
            Param::Typed(name, at) => {
                let inner = file.params.get(at as usize).unwrap_or(&Param::Unset);
                Value::Typed(
                    file.name(name),
                    ParamRef {
                        param: inner,
                        ..*self
                    },
                )
            }
            Param::Unset => Value::Unset,
            Param::Derived => Value::Derived,
            Param::Binary(start, len) => Value::Binary(file.text_at(start, len)),
        }
    }

    /// Whether the value is `$`.
    #[must_use]
    pub fn is_unset(&self) -> bool {
        matches!(self.param, Param::Unset)
    }

    /// Whether the value is `*`.
    #[must_use]
    pub fn is_derived(&self) -> bool {
        matches!(self.param, Param::Derived)
    }

    /// `None` for `$`, else the parameter: for OPTIONAL attributes.
    #[must_use]
    pub fn optional(self) -> Option<ParamRef<'a>> {
        (!self.is_unset()).then_some(self)
    }

    /// The value with typed-parameter wrappers removed (`LENGTH_MEASURE(5.)` → `5.`), which
    /// the scalar accessors below apply so that measures read as plain numbers.
    #[must_use]
    pub fn untyped(self) -> ParamRef<'a> {
        let mut p = self;
        // Typed nesting is bounded by the parser's depth limit; the bound here only documents it.
        for _ in 0..=super::parser::MAX_DEPTH {
            match p.value() {
                Value::Typed(_, inner) => p = inner,
                _ => break,
            }
        }
        p
    }

    /// An integer.
    pub fn int(&self) -> Result<i64, StepError> {
        match self.untyped().value() {
            Value::Int(i) => Ok(i),
            _ => Err(self.wrong("an integer")),
        }
    }

    /// A real; integers are accepted and converted.
    pub fn real(&self) -> Result<f64, StepError> {
        match self.untyped().value() {
            Value::Real(r) => Ok(r),
            Value::Int(i) => Ok(i as f64),
            _ => Err(self.wrong("a real")),
        }
    }

    /// A string.
    pub fn string(&self) -> Result<&'a str, StepError> {
        match self.untyped().value() {
            Value::Str(s) => Ok(s),
            _ => Err(self.wrong("a string")),
        }
    }

    /// An enumeration value without dots, upper-case (`.unspecified.` → `UNSPECIFIED`).
    pub fn enumeration(&self) -> Result<&'a str, StepError> {
        match self.untyped().value() {
            Value::Enum(e) => Ok(e),
            _ => Err(self.wrong("an enumeration")),
        }
    }

    /// A BOOLEAN: `.T.` or `.F.`.
    pub fn boolean(&self) -> Result<bool, StepError> {
        match self.untyped().value() {
            Value::Enum("T") => Ok(true),
            Value::Enum("F") => Ok(false),
            _ => Err(self.wrong("a boolean (.T. or .F.)")),
        }
    }

    /// A LOGICAL: `.T.`, `.F.` or `.U.` (unknown, `None`).
    pub fn logical(&self) -> Result<Option<bool>, StepError> {
        match self.untyped().value() {
            Value::Enum("T") => Ok(Some(true)),
            Value::Enum("F") => Ok(Some(false)),
            Value::Enum("U") => Ok(None),
            _ => Err(self.wrong("a logical (.T., .F. or .U.)")),
        }
    }

    /// A reference's id. See [`ParamRef::entity`] to follow it.
    pub fn reference(&self) -> Result<u64, StepError> {
        match self.untyped().value() {
            Value::Ref(id) => Ok(id),
            _ => Err(self.wrong("a reference")),
        }
    }

    /// The instance a reference points at; a dangling reference is an error naming this
    /// parameter and its instance.
    pub fn entity(&self) -> Result<EntityRef<'a>, StepError> {
        let target = self.reference()?;
        self.file().find(target).ok_or_else(|| StepError::Dangling {
            line: self.record.entity().line(),
            id: self.record.entity().id(),
            context: self.context(),
            target,
        })
    }

    /// A list (aggregate).
    pub fn list(&self) -> Result<ListRef<'a>, StepError> {
        match self.untyped().value() {
            Value::List(list) => Ok(list),
            _ => Err(self.wrong("a list")),
        }
    }

    /// A typed parameter's type name and inner value.
    pub fn typed(&self) -> Result<(&'a str, ParamRef<'a>), StepError> {
        match self.value() {
            Value::Typed(name, inner) => Ok((name, inner)),
            _ => Err(self.wrong("a typed parameter")),
        }
    }

    /// A binary literal's hex digits.
    pub fn binary(&self) -> Result<&'a str, StepError> {
        match self.untyped().value() {
            Value::Binary(b) => Ok(b),
            _ => Err(self.wrong("a binary")),
        }
    }

    /// A list of reals (integers accepted), e.g. coordinates or knots.
    pub fn reals(&self) -> Result<Vec<f64>, StepError> {
        self.list()?.iter().map(|p| p.real()).collect()
    }

    /// A list of integers, e.g. knot multiplicities.
    pub fn ints(&self) -> Result<Vec<i64>, StepError> {
        self.list()?.iter().map(|p| p.int()).collect()
    }

    /// A list of reference ids, e.g. a shell's faces.
    pub fn references(&self) -> Result<Vec<u64>, StepError> {
        self.list()?.iter().map(|p| p.reference()).collect()
    }

    /// An error about this parameter found by the caller, e.g. "should have 3 coordinates".
    #[must_use]
    pub fn invalid(&self, message: impl Into<String>) -> StepError {
        let entity = self.record.entity();
        let context = self.context();
        StepError::Invalid {
            line: entity.line(),
            id: entity.id(),
            context,
            message: message.into(),
        }
    }

    /// `#45 = PLANE: parameter 2 (position) item 3.1`, counting from 1.
    #[must_use]
    pub fn context(&self) -> String {
        let mut out = self.record.context();
        let _ = write!(out, ": parameter {}", self.index.saturating_add(1));
        if !self.name.is_empty() {
            let _ = write!(out, " ({})", self.name);
        }
        let kept = (self.path.depth as usize).min(Path::KEPT);
        for (k, item) in self.path.items.iter().take(kept).enumerate() {
            out.push_str(if k == 0 { " item " } else { "." });
            let _ = write!(out, "{}", u64::from(*item) + 1);
        }
        if self.path.depth as usize > Path::KEPT {
            out.push_str(".…");
        }
        out
    }

    fn wrong(&self, expected: &'static str) -> StepError {
        let entity = self.record.entity();
        StepError::WrongType {
            line: entity.line(),
            id: entity.id(),
            context: self.context(),
            expected,
            found: describe(self.value()),
        }
    }
}

/// What a value is, for "found …" in messages.
#[must_use]
fn describe(value: Value<'_>) -> String {
    match value {
        Value::Int(i) => format!("an integer ({i})"),
        Value::Real(r) => format!("a real ({r:?})"),
        Value::Str(_) => "a string".to_owned(),
        Value::Enum(e) => format!("an enumeration (.{e}.)"),
        Value::Ref(id) => format!("a reference (#{id})"),
        Value::List(l) => format!("a list of {}", l.len()),
        Value::Typed(name, _) => format!("a typed parameter ({name})"),
        Value::Unset => "$ (unset)".to_owned(),
        Value::Derived => "* (derived)".to_owned(),
        Value::Binary(_) => "a binary".to_owned(),
    }
}

/// A list parameter's items.
#[derive(Clone, Copy)]
pub struct ListRef<'a> {
    parent: ParamRef<'a>,
    items: &'a [Param],
}

impl<'a> ListRef<'a> {
    /// The number of items.
    #[must_use]
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// Whether the list is `()`.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// Item `index` (0-based).
    pub fn get(&self, index: usize) -> Result<ParamRef<'a>, StepError> {
        let item = |param| ParamRef {
            param,
            path: self.parent.path.child(index),
            ..self.parent
        };
        match self.items.get(index) {
            Some(param) => Ok(item(param)),
            None => {
                let entity = self.parent.record.entity();
                let context = item(&Param::Unset).context();
                Err(StepError::Missing {
                    line: entity.line(),
                    id: entity.id(),
                    context,
                    count: self.len(),
                })
            }
        }
    }

    /// The items in order.
    #[must_use]
    pub fn iter(&self) -> impl ExactSizeIterator<Item = ParamRef<'a>> + use<'a> {
        let parent = self.parent;
        self.items
            .iter()
            .enumerate()
            .map(move |(i, param)| ParamRef {
                param,
                path: parent.path.child(i),
                ..parent
            })
    }

    /// The list as a parameter, for its context in a caller's error (e.g. a wrong length).
    #[must_use]
    pub fn param(&self) -> ParamRef<'a> {
        self.parent
    }
}

/// The context and value (lists print their items, at most [`super::MAX_DEPTH`] deep).
impl fmt::Debug for ParamRef<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "ParamRef({}: {:?})", self.context(), self.value())
    }
}

impl fmt::Debug for ListRef<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_list()
            .entries(self.iter().map(|p| p.value()))
            .finish()
    }
}
