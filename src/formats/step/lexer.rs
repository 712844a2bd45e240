//! Byte-level tokenizer for ISO 10303-21.
//!
//! It works on `&[u8]` with a position and a line counter, without building a token stream:
//! the parser asks for the token it expects next, which keeps the hot loop small (one pass, no
//! per-token allocation). Whitespace and `/* … */` comments are skipped between any two tokens.
//! Every error carries the current line and [`Scope`], so messages point at the right place.

use super::error::{Scope, StepError};

/// Longest token text quoted back in an error message.
const SHOWN: usize = 32;

/// A cursor over the file's bytes.
pub(super) struct Lexer<'a> {
    bytes: &'a [u8],
    pos: usize,
    /// 1-based line of `pos`.
    pub(super) line: u32,
    /// What the parser is inside; used for error messages.
    pub(super) scope: Scope,
}

/// An integer or real literal.
pub(super) enum Number {
    Int(i64),
    Real(f64),
}

impl<'a> Lexer<'a> {
    /// A lexer at the start of `bytes`, skipping a UTF-8 byte-order mark that some Windows tools
    /// write.
    #[must_use]
    pub(super) fn new(bytes: &'a [u8]) -> Self {
        let pos = if bytes.starts_with(&[0xEF, 0xBB, 0xBF]) {
            3
        } else {
            0
        };
        Lexer {
            bytes,
            pos,
            line: 1,
            scope: Scope::Start,
        }
    }

    /// The byte at the cursor.
    #[must_use]
    pub(super) fn peek(&self) -> Option<u8> {
        self.bytes.get(self.pos).copied()
    }

    /// The byte `k` places after the cursor.
    #[must_use]
    fn peek_at(&self, k: usize) -> Option<u8> {
        self.bytes.get(self.pos.saturating_add(k)).copied()
    }

    /// Moves past one byte that the caller has peeked (never a newline).
    pub(super) fn bump(&mut self) {
        self.pos = self.pos.saturating_add(1).min(self.bytes.len());
    }

    /// The cursor position, to go back to with [`Lexer::reset`].
    #[must_use]
    pub(super) fn mark(&self) -> (usize, u32) {
        (self.pos, self.line)
    }

    /// Goes back to a position from [`Lexer::mark`].
    pub(super) fn reset(&mut self, (pos, line): (usize, u32)) {
        self.pos = pos.min(self.bytes.len());
        self.line = line;
    }

    /// Skips whitespace (including CR/LF and other print controls) and comments.
    pub(super) fn skip_ws(&mut self) -> Result<(), StepError> {
        loop {
            match self.peek() {
                Some(b'\n') => {
                    self.line = self.line.saturating_add(1);
                    self.pos += 1;
                }
                Some(b' ' | b'\t' | b'\r' | 0x0b | 0x0c) => self.pos += 1,
                Some(b'/') if self.peek_at(1) == Some(b'*') => self.skip_comment()?,
                _ => return Ok(()),
            }
        }
    }

    /// Skips one `/* … */` comment; the cursor is on its `/`.
    fn skip_comment(&mut self) -> Result<(), StepError> {
        let start_line = self.line;
        let body = self.bytes.get(self.pos + 2..).unwrap_or_default();
        let Some(end) = body.windows(2).position(|w| w == b"*/") else {
            return Err(StepError::UnterminatedComment {
                line: start_line,
                scope: self.scope,
            });
        };
        let inside = body.get(..end).unwrap_or_default();
        self.line = self.line.saturating_add(count_newlines(inside));
        self.pos += 2 + end + 2;
        Ok(())
    }

    /// Reads a keyword: `[A-Za-z_!][A-Za-z0-9_]*`, plus `-` when `hyphen` (for the
    /// `ISO-10303-21` / `END-ISO-10303-21` delimiters). Returns `None`, consuming nothing, when
    /// the cursor is not on a keyword.
    #[must_use]
    pub(super) fn keyword(&mut self, hyphen: bool) -> Option<&'a [u8]> {
        let rest = self.bytes.get(self.pos..).unwrap_or_default();
        let first = *rest.first()?;
        if !(first.is_ascii_alphabetic() || first == b'_' || first == b'!') {
            return None;
        }
        let len = 1 + rest
            .iter()
            .skip(1)
            .take_while(|&&b| b.is_ascii_alphanumeric() || b == b'_' || (hyphen && b == b'-'))
            .count();
        self.pos += len;
        rest.get(..len)
    }

    /// Reads the digits of an entity name after `#` as a `u64`.
    pub(super) fn id_digits(&mut self) -> Result<u64, StepError> {
        let rest = self.bytes.get(self.pos..).unwrap_or_default();
        let len = rest.iter().take_while(|b| b.is_ascii_digit()).count();
        if len == 0 {
            return Err(self.unexpected("digits of an entity name after '#'"));
        }
        let digits = rest.get(..len).unwrap_or_default();
        let mut value: u64 = 0;
        for &d in digits {
            value = value
                .checked_mul(10)
                .and_then(|v| v.checked_add(u64::from(d.saturating_sub(b'0'))))
                .ok_or_else(|| self.out_of_range(digits))?;
        }
        self.pos += len;
        Ok(value)
    }

    /// Reads an integer or real: `[+-] digits [. digits] [E [+-] digits]`. Also accepts a
    /// mantissa with no digits before the point (`-.5`), which some writers produce although
    /// the grammar requires one.
    pub(super) fn number(&mut self) -> Result<Number, StepError> {
        let rest = self.bytes.get(self.pos..).unwrap_or_default();
        let digits_at = |i: usize| {
            rest.iter()
                .skip(i)
                .take_while(|b| b.is_ascii_digit())
                .count()
        };
        let mut i = usize::from(matches!(rest.first(), Some(b'+' | b'-')));
        let mut mantissa = digits_at(i);
        i += mantissa;
        let mut real = false;
        if rest.get(i) == Some(&b'.') {
            real = true;
            let frac = digits_at(i + 1);
            mantissa += frac;
            i += 1 + frac;
        }
        if mantissa == 0 {
            return Err(self.unexpected("a number"));
        }
        if matches!(rest.get(i), Some(b'E' | b'e')) {
            real = true;
            let sign = usize::from(matches!(rest.get(i + 1), Some(b'+' | b'-')));
            let exp = digits_at(i + 1 + sign);
            if exp == 0 {
                self.pos += i + 1 + sign;
                return Err(self.unexpected("the digits of an exponent"));
            }
            i += 1 + sign + exp;
        }
        let text = rest.get(..i).unwrap_or_default();
        let number = if real {
            parse_real(text)
        } else {
            parse_int(text)
        };
        let number = number.ok_or_else(|| self.out_of_range(text))?;
        self.pos += i;
        Ok(number)
    }

    /// Reads a string literal; the cursor is on its opening `'`. Returns the raw bytes between
    /// the quotes (with `''` and escapes still in them) for [`super::strings::decode`].
    pub(super) fn string(&mut self) -> Result<&'a [u8], StepError> {
        let start_line = self.line;
        let body = self.bytes.get(self.pos + 1..).unwrap_or_default();
        let mut i = 0;
        loop {
            let Some(q) = body.iter().skip(i).position(|&b| b == b'\'') else {
                return Err(StepError::UnterminatedString {
                    line: start_line,
                    scope: self.scope,
                });
            };
            i += q;
            if body.get(i + 1) == Some(&b'\'') {
                i += 2;
            } else {
                break;
            }
        }
        let raw = body.get(..i).unwrap_or_default();
        self.line = self.line.saturating_add(count_newlines(raw));
        self.pos += i + 2;
        Ok(raw)
    }

    /// Reads a binary literal `"…"`; the cursor is on its opening `"`. Returns the hex digits,
    /// the first of which (0–3) counts the unused high bits.
    pub(super) fn binary(&mut self) -> Result<&'a [u8], StepError> {
        self.bump();
        let rest = self.bytes.get(self.pos..).unwrap_or_default();
        let len = rest.iter().take_while(|b| b.is_ascii_hexdigit()).count();
        let digits = rest.get(..len).unwrap_or_default();
        if !matches!(digits.first(), Some(b'0'..=b'3')) {
            return Err(self.unexpected("a binary literal starting with 0, 1, 2 or 3"));
        }
        self.pos += len;
        self.expect(b'"', "'\"' closing a binary literal")?;
        Ok(digits)
    }

    /// Reads an enumeration `.NAME.`; the cursor is on the first `.`. Returns `NAME`.
    pub(super) fn enumeration(&mut self) -> Result<&'a [u8], StepError> {
        self.bump();
        let Some(name) = self.keyword(false) else {
            return Err(self.unexpected("an enumeration name after '.'"));
        };
        self.expect(b'.', "'.' closing an enumeration")?;
        Ok(name)
    }

    /// Whether the cursor is on a `.` that starts a number (`.5`) rather than an enumeration.
    #[must_use]
    pub(super) fn dot_starts_number(&self) -> bool {
        self.peek_at(1).is_some_and(|b| b.is_ascii_digit())
    }

    /// Consumes `byte` or fails naming `what` was expected.
    pub(super) fn expect(&mut self, byte: u8, what: &'static str) -> Result<(), StepError> {
        if self.peek() == Some(byte) {
            self.bump();
            Ok(())
        } else {
            Err(self.unexpected(what))
        }
    }

    /// The error for whatever is at the cursor when `expected` was wanted: end of file, binary
    /// junk, or an unexpected token.
    #[must_use]
    pub(super) fn unexpected(&self, expected: &'static str) -> StepError {
        let (line, scope) = (self.line, self.scope);
        match self.peek() {
            None => StepError::UnexpectedEof {
                line,
                scope,
                expected,
            },
            Some(byte) if is_binary(byte) => StepError::Binary { line, scope, byte },
            Some(_) => StepError::Unexpected {
                line,
                scope,
                found: self.describe(),
                expected,
            },
        }
    }

    /// The token at the cursor, escaped and shortened for an error message.
    #[must_use]
    pub(super) fn describe(&self) -> String {
        let rest = self.bytes.get(self.pos..).unwrap_or_default();
        match rest.first() {
            None => "end of file".to_owned(),
            Some(b) if b.is_ascii_alphabetic() => {
                let len = rest
                    .iter()
                    .take(SHOWN)
                    .take_while(|b| b.is_ascii_alphanumeric() || **b == b'_' || **b == b'-')
                    .count();
                format!("keyword {}", escape(rest.get(..len).unwrap_or_default()))
            }
            Some(&b) if is_binary(b) => format!("byte 0x{b:02x}"),
            Some(&b) => format!("'{}'", escape(&[b])),
        }
    }

    fn out_of_range(&self, text: &[u8]) -> StepError {
        let shown = text.get(..SHOWN).unwrap_or(text);
        StepError::NumberOutOfRange {
            line: self.line,
            scope: self.scope,
            text: escape(shown),
        }
    }
}

/// Bytes that never occur in STEP text outside strings: controls other than whitespace, DEL
/// and anything non-ASCII.
#[must_use]
pub(super) fn is_binary(b: u8) -> bool {
    (b < 0x20 && !matches!(b, b'\t' | b'\n' | b'\r' | 0x0b | 0x0c)) || b >= 0x7f
}

/// Bytes shown in an error message, with anything unprintable escaped (`\x00`).
#[must_use]
pub(super) fn escape(bytes: &[u8]) -> String {
    bytes
        .iter()
        .flat_map(|b| b.escape_ascii())
        .map(char::from)
        .collect()
}

/// Line breaks in a string or comment, to keep the line counter right.
#[must_use]
fn count_newlines(bytes: &[u8]) -> u32 {
    let count = bytes.iter().filter(|&&b| b == b'\n').count();
    u32::try_from(count).unwrap_or(u32::MAX)
}

/// Integer literal (sign and ASCII digits only, as checked by the caller) or `None` on overflow.
#[must_use]
fn parse_int(text: &[u8]) -> Option<Number> {
    let (negative, digits) = match text.split_first() {
        Some((b'-', d)) => (true, d),
        Some((b'+', d)) => (false, d),
        _ => (false, text),
    };
    let mut value: i64 = 0;
    for &d in digits {
        let d = i64::from(d.saturating_sub(b'0'));
        value = value.checked_mul(10)?;
        value = if negative {
            value.checked_sub(d)?
        } else {
            value.checked_add(d)?
        };
    }
    Some(Number::Int(value))
}

/// Real literal (already checked to be `[+-] digits . digits E [+-] digits` in ASCII) or
/// `None` when it overflows to infinity.
#[must_use]
fn parse_real(text: &[u8]) -> Option<Number> {
    let value: f64 = std::str::from_utf8(text).ok()?.parse().ok()?;
    value.is_finite().then_some(Number::Real(value))
}
