//! The exchange-structure grammar: sections, instances and parameter lists.
//!
//! Parameters are parsed with an explicit stack instead of recursion, so no input can overflow
//! the call stack; nesting is still capped at [`MAX_DEPTH`] so that later recursive walks of
//! the tree are safe too. Items of an open list collect on a scratch stack and move into the
//! arena when the list closes, which keeps every list's items contiguous.

use super::error::{Scope, StepError};
use super::header;
use super::lexer::{Lexer, Number};
use super::model::{Entity, Index, Interner, Param, Record, StepFile};
use super::strings;

/// Deepest nesting of lists and typed parameters accepted. Real files need about 4 (a
/// B-spline surface's control points are a list of lists).
pub const MAX_DEPTH: usize = 64;

/// What an open parenthesis belongs to.
#[derive(Clone, Copy)]
enum Open {
    /// The parameter list of a record.
    Record,
    /// An aggregate `( … )`.
    List,
    /// A typed parameter `NAME( … )` with its interned name.
    Typed(u32),
}

/// Where the parameter parser is between tokens.
#[derive(Clone, Copy, PartialEq, Eq)]
enum State {
    /// Just after `(`: a value or `)`.
    Opened,
    /// Just after `,`: a value.
    Comma,
    /// Just after a value: `,` or `)`.
    Value,
}

/// The parser's state: the lexer plus the tables being filled.
struct Parser<'a> {
    lex: Lexer<'a>,
    names: Interner,
    params: Vec<Param>,
    records: Vec<Record>,
    entities: Vec<Entity>,
    text: String,
    /// Values of the lists still open.
    scratch: Vec<Param>,
    /// The open parentheses: what each belongs to and where its items start in `scratch`.
    frames: Vec<(Open, usize)>,
}

/// Parses a whole exchange structure.
pub(super) fn parse(bytes: &[u8]) -> Result<StepFile, StepError> {
    let mut p = Parser::new(bytes);
    p.lex.skip_ws()?;
    let line = p.lex.line;
    if !p.word_is("ISO-10303-21") {
        let found = if p.lex.peek().is_none() {
            "an empty file".to_owned()
        } else {
            p.lex.describe()
        };
        return Err(StepError::NotStep { line, found });
    }
    p.semicolon("';' after ISO-10303-21")?;
    p.lex.scope = Scope::Between;
    p.lex.skip_ws()?;
    if !p.word_is("HEADER") {
        return Err(p.lex.unexpected("HEADER"));
    }
    p.semicolon("';' after HEADER")?;
    let header_records = p.header_section()?;
    p.sections()?;
    let header = header::extract(&header_records, &p.names.names, &p.params, &p.text);
    let index = Index::build(&p.entities)?;
    Ok(StepFile {
        header,
        entities: p.entities,
        records: p.records,
        params: p.params,
        text: p.text,
        names: p.names.names,
        index,
    })
}

impl<'a> Parser<'a> {
    fn new(bytes: &'a [u8]) -> Self {
        // Sized from the file length (about 7 bytes per parameter and 45 per instance in real
        // files), never from anything written in the file, and capped so that a huge file of
        // junk reserves little before failing; the tables grow as needed beyond.
        let len = bytes.len().min(64 << 20);
        Parser {
            lex: Lexer::new(bytes),
            names: Interner::default(),
            params: Vec::with_capacity(len / 8),
            records: Vec::with_capacity(len / 48),
            entities: Vec::with_capacity(len / 48),
            text: String::with_capacity(len / 32),
            scratch: Vec::with_capacity(64),
            frames: Vec::with_capacity(MAX_DEPTH + 1),
        }
    }

    /// Consumes the keyword `word` (case-insensitively) if it is next.
    /// Otherwise the cursor does not move, so an error can quote what is there.
    fn word_is(&mut self, word: &str) -> bool {
        let mark = self.lex.mark();
        match self.lex.keyword(true) {
            Some(found) if found.eq_ignore_ascii_case(word.as_bytes()) => true,
            _ => {
                self.lex.reset(mark);
                false
            }
        }
    }

    /// Skips whitespace and consumes `;`.
    fn semicolon(&mut self, what: &'static str) -> Result<(), StepError> {
        self.lex.skip_ws()?;
        self.lex.expect(b';', what)
    }

    /// Parses the HEADER entries up to `ENDSEC;`, returning them as records.
    fn header_section(&mut self) -> Result<Vec<Record>, StepError> {
        let mut out = Vec::new();
        loop {
            self.lex.scope = Scope::Header;
            self.lex.skip_ws()?;
            let line = self.lex.line;
            let Some(word) = self.lex.keyword(false) else {
                return Err(self.lex.unexpected("a HEADER entry or ENDSEC"));
            };
            if word.eq_ignore_ascii_case(b"ENDSEC") {
                return self.semicolon("';' after ENDSEC").map(|()| out);
            }
            self.lex.scope = Scope::HeaderEntry { line };
            let name = self.intern(word)?;
            self.lex.skip_ws()?;
            self.lex.expect(b'(', "'(' after a HEADER entry's name")?;
            let (start, len) = self.parameters()?;
            out.push(Record { name, start, len });
            self.semicolon("';' after a HEADER entry")?;
        }
    }

    /// Parses the sections after the header up to `END-ISO-10303-21;`.
    fn sections(&mut self) -> Result<(), StepError> {
        loop {
            self.lex.scope = Scope::Between;
            self.lex.skip_ws()?;
            let mark = self.lex.mark();
            let Some(word) = self.lex.keyword(true) else {
                return Err(self.lex.unexpected("DATA or END-ISO-10303-21"));
            };
            if word.eq_ignore_ascii_case(b"END-ISO-10303-21") {
                // Anything after the terminator (signatures, padding) is ignored.
                return self.semicolon("';' after END-ISO-10303-21");
            } else if word.eq_ignore_ascii_case(b"DATA") {
                self.data_section()?;
            } else if [&b"ANCHOR"[..], b"REFERENCE", b"SIGNATURE"]
                .iter()
                .any(|s| word.eq_ignore_ascii_case(s))
            {
                self.skip_section()?;
            } else {
                self.lex.reset(mark);
                return Err(self.lex.unexpected("DATA or END-ISO-10303-21"));
            }
        }
    }

    /// Parses one DATA section (after its keyword) up to `ENDSEC;`. Edition 3's section
    /// parameters `DATA('name', ('SCHEMA'));` are read and dropped.
    fn data_section(&mut self) -> Result<(), StepError> {
        self.lex.skip_ws()?;
        if self.lex.peek() == Some(b'(') {
            self.lex.bump();
            let _section_parameters = self.parameters()?;
        }
        self.semicolon("';' after DATA")?;
        loop {
            self.lex.scope = Scope::Data;
            self.lex.skip_ws()?;
            match self.lex.peek() {
                Some(b'#') => self.instance()?,
                Some(b) if b.is_ascii_alphabetic() => {
                    if self.word_is("ENDSEC") {
                        return self.semicolon("';' after ENDSEC");
                    }
                    return Err(self.lex.unexpected("an entity instance '#…' or ENDSEC"));
                }
                _ => return Err(self.lex.unexpected("an entity instance '#…' or ENDSEC")),
            }
        }
    }

    /// Skips an edition-3 ANCHOR, REFERENCE or SIGNATURE section up to its `ENDSEC;`, honouring
    /// strings and comments.
    fn skip_section(&mut self) -> Result<(), StepError> {
        self.lex.scope = Scope::Skipped;
        loop {
            self.lex.skip_ws()?;
            match self.lex.peek() {
                None => return Err(self.lex.unexpected("ENDSEC")),
                Some(b'\'') => {
                    let _ = self.lex.string()?;
                }
                Some(b) if b.is_ascii_alphabetic() => {
                    if self.word_is("ENDSEC") {
                        return self.semicolon("';' after ENDSEC");
                    }
                    let _ = self.lex.keyword(true);
                }
                Some(_) => self.lex.bump(),
            }
        }
    }

    /// Parses `#id = NAME(…);` or `#id = (NAME(…) NAME(…) …);`; the cursor is on `#`.
    fn instance(&mut self) -> Result<(), StepError> {
        let line = self.lex.line;
        self.lex.bump();
        let id = self.lex.id_digits()?;
        self.lex.scope = Scope::Entity { id, line };
        self.lex.skip_ws()?;
        self.lex.expect(b'=', "'=' after the entity name")?;
        self.lex.skip_ws()?;
        let start = self.records.len();
        if self.lex.peek() == Some(b'(') {
            self.lex.bump();
            loop {
                self.lex.skip_ws()?;
                if self.lex.peek() == Some(b')') && self.records.len() > start {
                    self.lex.bump();
                    break;
                }
                self.record("a record name in a complex instance")?;
            }
        } else {
            self.record("an entity type name or '('")?;
        }
        self.lex.skip_ws()?;
        if self.lex.peek() != Some(b';') {
            let err = self.lex.unexpected("';'");
            return Err(match err {
                StepError::Unexpected { found, .. } => StepError::MissingSemicolon {
                    line: self.lex.line,
                    id,
                    start: line,
                    found,
                },
                other => other,
            });
        }
        self.lex.bump();
        let (start, len) = (
            self.index(start, "records")?,
            self.index(self.records.len() - start, "records")?,
        );
        self.entities.push(Entity {
            id,
            line,
            start,
            len,
        });
        Ok(())
    }

    /// Parses one `NAME(params)` record into `records`.
    fn record(&mut self, expected: &'static str) -> Result<(), StepError> {
        let Some(word) = self.lex.keyword(false) else {
            return Err(self.lex.unexpected(expected));
        };
        let name = self.intern(word)?;
        self.lex.skip_ws()?;
        self.lex.expect(b'(', "'(' after the entity type name")?;
        let (start, len) = self.parameters()?;
        self.records.push(Record { name, start, len });
        Ok(())
    }

    /// Parses a parameter list whose `(` has been consumed, through its `)`. Returns the range
    /// of its parameters in the arena.
    fn parameters(&mut self) -> Result<(u32, u32), StepError> {
        self.scratch.clear();
        self.frames.clear();
        self.frames.push((Open::Record, 0));
        let mut state = State::Opened;
        loop {
            self.lex.skip_ws()?;
            let Some(byte) = self.lex.peek() else {
                return Err(self.lex.unexpected(match state {
                    State::Opened => "a parameter or ')'",
                    State::Comma => "a parameter",
                    State::Value => "',' or ')'",
                }));
            };
            match (state, byte) {
                (State::Opened | State::Value, b')') => {
                    self.lex.bump();
                    if let Some(range) = self.close()? {
                        return Ok(range);
                    }
                    state = State::Value;
                }
                (State::Value, b',') => {
                    self.lex.bump();
                    state = State::Comma;
                }
                (State::Value, _) => return Err(self.lex.unexpected("',' or ')'")),
                (State::Opened | State::Comma, b'(') => {
                    self.lex.bump();
                    self.open(Open::List)?;
                    state = State::Opened;
                }
                (State::Opened | State::Comma, _) => {
                    state = if self.value(byte)? {
                        State::Opened
                    } else {
                        State::Value
                    };
                }
            }
        }
    }

    /// Starts a list or typed parameter, enforcing [`MAX_DEPTH`].
    fn open(&mut self, what: Open) -> Result<(), StepError> {
        if self.frames.len() > MAX_DEPTH {
            let (line, scope) = (self.lex.line, self.lex.scope);
            return Err(StepError::TooDeep {
                line,
                scope,
                limit: MAX_DEPTH,
            });
        }
        self.frames.push((what, self.scratch.len()));
        Ok(())
    }

    /// Closes the innermost parenthesis. Returns the record's range when it was the record's
    /// own parameter list.
    fn close(&mut self) -> Result<Option<(u32, u32)>, StepError> {
        let Some((what, start)) = self.frames.pop() else {
            return Err(self.lex.unexpected("a parameter"));
        };
        let count = self.scratch.len().saturating_sub(start);
        match what {
            Open::Record | Open::List => {
                let first = self.index(self.params.len(), "parameters")?;
                let len = self.index(count, "parameters")?;
                self.params.extend(self.scratch.drain(start..));
                if matches!(what, Open::Record) {
                    return Ok(Some((first, len)));
                }
                self.scratch.push(Param::List(first, len));
            }
            Open::Typed(name) => {
                let value = match (count, self.scratch.pop()) {
                    (1, Some(value)) => value,
                    _ => {
                        return Err(StepError::Unexpected {
                            line: self.lex.line,
                            scope: self.lex.scope,
                            found: format!("{count} values"),
                            expected: "exactly one value in a typed parameter",
                        });
                    }
                };
                let at = self.index(self.params.len(), "parameters")?;
                self.params.push(value);
                self.scratch.push(Param::Typed(name, at));
            }
        }
        Ok(None)
    }

    /// Parses one value starting with `byte` onto the scratch stack. Returns `true` when it was
    /// the name of a typed parameter, whose `(` has then been opened.
    fn value(&mut self, byte: u8) -> Result<bool, StepError> {
        let param = match byte {
            b'#' => {
                self.lex.bump();
                Param::Ref(self.lex.id_digits()?)
            }
            b'\'' => {
                let raw = self.lex.string()?;
                let start = self.index(self.text.len(), "bytes of strings")?;
                strings::decode(raw, &mut self.text);
                Param::Str(
                    start,
                    self.index(self.text.len() - start as usize, "bytes of strings")?,
                )
            }
            b'"' => {
                let digits = self.lex.binary()?;
                let start = self.index(self.text.len(), "bytes of strings")?;
                self.text.extend(digits.iter().map(|&b| char::from(b)));
                Param::Binary(start, self.index(digits.len(), "bytes of strings")?)
            }
            b'$' => self.single(Param::Unset),
            b'*' => self.single(Param::Derived),
            b'.' if !self.lex.dot_starts_number() => {
                let name = self.lex.enumeration()?;
                Param::Enum(self.intern(name)?)
            }
            b'.' | b'+' | b'-' | b'0'..=b'9' => match self.lex.number()? {
                Number::Int(i) => Param::Int(i),
                Number::Real(r) => Param::Real(r),
            },
            _ => {
                let Some(word) = self.lex.keyword(false) else {
                    return Err(self.lex.unexpected("a parameter"));
                };
                let name = self.intern(word)?;
                self.lex.skip_ws()?;
                self.lex
                    .expect(b'(', "'(' after a typed parameter's type name")?;
                self.open(Open::Typed(name))?;
                return Ok(true);
            }
        };
        self.scratch.push(param);
        Ok(false)
    }

    /// Consumes the one-byte token at the cursor and returns `param`.
    fn single(&mut self, param: Param) -> Param {
        self.lex.bump();
        param
    }

    /// Interns a name read from the file.
    fn intern(&mut self, word: &[u8]) -> Result<u32, StepError> {
        self.names.intern(word).ok_or(StepError::TooLarge {
            line: self.lex.line,
            what: "distinct names",
        })
    }

    /// Converts a table position to the `u32` the compact tables store.
    fn index(&self, n: usize, what: &'static str) -> Result<u32, StepError> {
        u32::try_from(n).map_err(|_| StepError::TooLarge {
            line: self.lex.line,
            what,
        })
    }
}
