//! The free-format parameter syntax shared by the Global and Parameter Data sections: fields
//! separated by the parameter delimiter, ended by the record delimiter, Hollerith strings `nH…`
//! that may contain either delimiter, and the IGES number forms. The text is first joined from the
//! data columns of its lines (1–72 for G, 1–64 for P) so that strings and lists can run across
//! line ends exactly as the standard allows; a map from offset back to line keeps every message
//! pointing at a real line.

use super::error::shown;

/// Text joined from fixed-width column ranges of consecutive lines.
#[derive(Debug)]
pub(super) struct Joined {
    pub bytes: Vec<u8>,
    width: usize,
    lines: Vec<usize>,
}

impl Joined {
    #[must_use]
    /// Joins the first `columns` bytes of each `(line, data)`. Records always carry 72 data
    /// columns (a line reaches column 73), so every line contributes exactly `columns` bytes and
    /// an offset divided by `columns` is the line it came from.
    pub fn new<'a>(columns: usize, parts: impl Iterator<Item = (usize, &'a [u8])>) -> Self {
        let mut bytes = Vec::new();
        let mut lines = Vec::new();
        for (line, data) in parts {
            bytes.extend_from_slice(data.get(..columns).unwrap_or(data));
            lines.push(line);
        }
        Self {
            bytes,
            width: columns.max(1),
            lines,
        }
    }

    /// The file line holding byte `offset` of the joined text (the last line past the end).
    #[must_use]
    pub fn line_at(&self, offset: usize) -> usize {
        let index = offset / self.width;
        self.lines
            .get(index)
            .or(self.lines.last())
            .copied()
            .unwrap_or(1)
    }
}

/// One field as written: a Hollerith string's contents, or the plain text between delimiters
/// (blanks around it removed; empty for a defaulted field).
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Token<'a> {
    Text(String),
    Plain(&'a [u8]),
}

/// A token with the line it starts on.
#[derive(Debug, Clone)]
pub(super) struct Located<'a> {
    pub token: Token<'a>,
    pub line: usize,
}

/// A syntax error in free-format text, at a line.
#[derive(Debug)]
pub(super) struct FreeError {
    pub line: usize,
    pub message: String,
}

/// Splits `joined` into fields up to the record delimiter; whatever follows it is ignored, as
/// the standard allows comments there.
pub(super) fn tokenize(
    joined: &Joined,
    parameter: u8,
    record: u8,
) -> Result<Vec<Located<'_>>, FreeError> {
    let text = joined.bytes.as_slice();
    let mut out = Vec::new();
    let mut pos = 0;
    loop {
        pos = skip_blanks(text, pos);
        let line = joined.line_at(pos);
        let digits_end = pos + text.get(pos..).map_or(0, count_digits);
        let is_hollerith = digits_end > pos && matches!(text.get(digits_end), Some(b'H' | b'h'));
        let delimiter_at = if is_hollerith {
            let (contents, end) = hollerith(joined, pos, digits_end)?;
            out.push(Located {
                token: Token::Text(contents),
                line,
            });
            let after = skip_blanks(text, end);
            match text.get(after) {
                Some(&b) if b == parameter || b == record => after,
                Some(&b) => {
                    return Err(FreeError {
                        line: joined.line_at(after),
                        message: format!(
                            "parameter {} has '{}' after its Hollerith string where a delimiter ('{}' or '{}') belongs",
                            out.len(),
                            shown(&[b]),
                            char::from(parameter),
                            char::from(record)
                        ),
                    });
                }
                None => return Err(unterminated(joined, record)),
            }
        } else {
            let rest = text.get(pos..).unwrap_or_default();
            let Some(length) = rest.iter().position(|&b| b == parameter || b == record) else {
                return Err(unterminated(joined, record));
            };
            let field = rest.get(..length).unwrap_or_default();
            out.push(Located {
                token: Token::Plain(trim_blanks(field)),
                line,
            });
            pos + length
        };
        if text.get(delimiter_at) == Some(&record) {
            return Ok(out);
        }
        pos = delimiter_at + 1;
    }
}

#[must_use]
fn unterminated(joined: &Joined, record: u8) -> FreeError {
    FreeError {
        line: joined.line_at(joined.bytes.len().saturating_sub(1)),
        message: format!(
            "the parameters are not ended by the record delimiter '{}'",
            char::from(record)
        ),
    }
}

/// The contents of the Hollerith string whose count runs from `start` to `digits_end` (where
/// the `H` is), and the offset just after it. The count is checked against the text left before
/// anything is copied, so a huge count costs nothing.
fn hollerith(
    joined: &Joined,
    start: usize,
    digits_end: usize,
) -> Result<(String, usize), FreeError> {
    let text = joined.bytes.as_slice();
    let count = text
        .get(start..digits_end)
        .unwrap_or_default()
        .iter()
        .fold(0usize, |n, &d| {
            n.saturating_mul(10).saturating_add(usize::from(d - b'0'))
        });
    let first = digits_end + 1;
    let available = text.len().saturating_sub(first);
    if count > available {
        return Err(FreeError {
            line: joined.line_at(start),
            message: format!(
                "a Hollerith string of {count} characters runs past the end of the parameters ({available} left)"
            ),
        });
    }
    let contents = text.get(first..first + count).unwrap_or_default();
    Ok((latin1(contents), first + count))
}

/// IGES text is ASCII; bytes above 127 (national characters some systems write) are read as
/// Latin-1 so that every byte maps to exactly one character and counts stay byte counts.
#[must_use]
pub(super) fn latin1(bytes: &[u8]) -> String {
    bytes.iter().map(|&b| char::from(b)).collect()
}

#[must_use]
fn count_digits(text: &[u8]) -> usize {
    text.iter().take_while(|b| b.is_ascii_digit()).count()
}

#[must_use]
fn skip_blanks(text: &[u8], pos: usize) -> usize {
    pos + text
        .get(pos..)
        .map_or(0, |rest| rest.iter().take_while(|&&b| b == b' ').count())
}

#[must_use]
pub(super) fn trim_blanks(field: &[u8]) -> &[u8] {
    let start = field.iter().position(|&b| b != b' ').unwrap_or(field.len());
    let end = field
        .iter()
        .rposition(|&b| b != b' ')
        .map_or(start, |i| i + 1);
    field.get(start..end).unwrap_or_default()
}

/// A plain field read as a number.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Number {
    Empty,
    Int(i64),
    Real(f64),
    /// Not an IGES number (or a real that overflows `f64`).
    Invalid,
}

/// Reads `+12`, `-3`, `1.5`, `.5`, `5.`, `1.5E-3`, `1.5D-3`, `1E3`: an optional sign, digits with
/// at most one point (digits on at least one side), an optional `E`/`D` exponent. A field with
/// digits only is an integer; one that overflows `i64` is invalid rather than silently a real.
#[must_use]
pub(super) fn number(field: &[u8]) -> Number {
    if field.is_empty() {
        return Number::Empty;
    }
    let (negative, body) = match field.split_first() {
        Some((b'-', rest)) => (true, rest),
        Some((b'+', rest)) => (false, rest),
        _ => (false, field),
    };
    let int_len = count_digits(body);
    let int_digits = body.get(..int_len).unwrap_or_default();
    let mut rest = body.get(int_len..).unwrap_or_default();
    if rest.is_empty() {
        return integer(negative, int_digits);
    }
    let mut frac_digits: &[u8] = &[];
    if let Some(after) = rest.strip_prefix(b".") {
        let frac_len = count_digits(after);
        frac_digits = after.get(..frac_len).unwrap_or_default();
        rest = after.get(frac_len..).unwrap_or_default();
    }
    if int_digits.is_empty() && frac_digits.is_empty() {
        return Number::Invalid;
    }
    let exponent = match rest.split_first() {
        None => Some(&b"0"[..]),
        Some((b'E' | b'e' | b'D' | b'd', exp)) => valid_exponent(exp),
        Some(_) => None,
    };
    let Some(exponent) = exponent else {
        return Number::Invalid;
    };
    real(negative, int_digits, frac_digits, exponent)
}

#[must_use]
fn valid_exponent(exp: &[u8]) -> Option<&[u8]> {
    let digits = match exp.first() {
        Some(b'+' | b'-') => exp.get(1..).unwrap_or_default(),
        _ => exp,
    };
    (!digits.is_empty() && digits.iter().all(u8::is_ascii_digit)).then_some(exp)
}

#[must_use]
fn integer(negative: bool, digits: &[u8]) -> Number {
    if digits.is_empty() {
        return Number::Invalid;
    }
    let mut value: i64 = 0;
    for &d in digits {
        let Some(next) = value
            .checked_mul(10)
            .and_then(|v| v.checked_add(i64::from(d - b'0')))
        else {
            return Number::Invalid;
        };
        value = next;
    }
    Number::Int(if negative { -value } else { value })
}

#[must_use]
/// Builds a canonical `[-]I.FeX` string (Rust's parser does not take `D` or a bare `.5` in every
/// position) and parses that; infinities are invalid.
fn real(negative: bool, int_digits: &[u8], frac_digits: &[u8], exponent: &[u8]) -> Number {
    let mut canonical = String::with_capacity(int_digits.len() + frac_digits.len() + 24);
    if negative {
        canonical.push('-');
    }
    canonical.push_str(&latin1(if int_digits.is_empty() {
        b"0"
    } else {
        int_digits
    }));
    canonical.push('.');
    canonical.push_str(&latin1(if frac_digits.is_empty() {
        b"0"
    } else {
        frac_digits
    }));
    canonical.push('e');
    canonical.push_str(&latin1(exponent));
    match canonical.parse::<f64>() {
        Ok(v) if v.is_finite() => Number::Real(v),
        _ => Number::Invalid,
    }
}
