//! Decoding of STEP string literals into Rust strings.
//!
//! Part 21 strings are written in printable ASCII with escapes for everything else: `''` for a
//! quote, `\\` for a backslash, `\X\hh` for one ISO 8859-1 character, `\X2\hhhh…\X0\` for UCS-2
//! (UTF-16 surrogate pairs are joined), `\X4\hhhhhhhh…\X0\` for UCS-4, `\S\c` for the character
//! `c` + 128 of the current page, `\P?\` to select a page (ignored: ISO 8859-1 is assumed).
//! Line breaks inside a string are print controls, not content, and are dropped: writers wrap
//! long strings at column 72 (`'Undefined De` / `scription'`).
//!
//! Decoding is lenient on purpose, because real files break the rules and a viewer should still
//! show them: raw bytes above 127 are read as UTF-8 when the whole string is valid UTF-8 (edition
//! 3 allows it) and as ISO 8859-1 otherwise; a backslash that starts no known escape, or an
//! escape with bad hex digits, is kept as written (Windows paths such as `C:\parts\a.stp` are
//! common); an unclosed `\X2\` run ends at the end of the string; an invalid code point becomes
//! U+FFFD.

/// Appends the decoded form of `raw` (the bytes between the quotes) to `out`.
pub(super) fn decode(raw: &[u8], out: &mut String) {
    let plain = raw
        .iter()
        .all(|&b| b.is_ascii() && !matches!(b, b'\'' | b'\\' | b'\n' | b'\r'));
    if plain {
        // The common case: nothing to decode.
        out.push_str(std::str::from_utf8(raw).unwrap_or_default());
        return;
    }
    match std::str::from_utf8(raw) {
        Ok(text) => unescape(text, out),
        Err(_) => {
            let latin1: String = raw.iter().map(|&b| char::from(b)).collect();
            unescape(&latin1, out);
        }
    }
}

/// Resolves `''`, line breaks and backslash escapes in `text`, appending to `out`.
fn unescape(mut text: &str, out: &mut String) {
    while let Some(at) = text.find(['\'', '\\', '\n', '\r']) {
        let (before, special) = text.split_at(at);
        out.push_str(before);
        text = if let Some(rest) = special.strip_prefix("''") {
            out.push('\'');
            rest
        } else if let Some(rest) = special.strip_prefix('\\') {
            escape(rest, out)
        } else {
            // A lone `'` cannot be inside a literal; a line break is dropped.
            special.get(1..).unwrap_or_default()
        };
    }
    out.push_str(text);
}

/// Handles one escape; `text` follows its backslash. Returns the text after the escape.
fn escape<'a>(text: &'a str, out: &mut String) -> &'a str {
    if let Some(rest) = text.strip_prefix('\\') {
        out.push('\\');
        return rest;
    }
    if let Some(rest) = text.strip_prefix("X\\")
        && let Some(code) = rest.get(..2).and_then(hex)
    {
        out.push(char::from_u32(code).unwrap_or(char::REPLACEMENT_CHARACTER));
        return rest.get(2..).unwrap_or_default();
    }
    if let Some(rest) = text.strip_prefix("X2\\") {
        return wide(rest, 4, out);
    }
    if let Some(rest) = text.strip_prefix("X4\\") {
        return wide(rest, 8, out);
    }
    if let Some(rest) = text.strip_prefix("S\\") {
        let mut chars = rest.chars();
        if let Some(c) = chars.next() {
            let code = u32::from(c);
            let shifted = if code < 0x80 { code + 0x80 } else { code };
            out.push(char::from_u32(shifted).unwrap_or(char::REPLACEMENT_CHARACTER));
            let after = chars.as_str();
            // An apostrophe written as `''` after `\S\` counts as one character.
            return if c == '\'' {
                after.strip_prefix('\'').unwrap_or(after)
            } else {
                after
            };
        }
    }
    if let Some(rest) = text.strip_prefix('P')
        && let Some(after) = rest.get(1..).and_then(|r| r.strip_prefix('\\'))
        && rest.starts_with(|c: char| c.is_ascii_uppercase())
    {
        return after;
    }
    // Not an escape: keep the backslash as written.
    out.push('\\');
    text
}

/// Decodes the hex groups of a `\X2\` (`width` 4) or `\X4\` (`width` 8) run up to `\X0\`.
fn wide<'a>(mut text: &'a str, width: usize, out: &mut String) -> &'a str {
    let mut units: Vec<u16> = Vec::new();
    loop {
        if let Some(rest) = text.strip_prefix("\\X0\\") {
            text = rest;
            break;
        }
        let Some(code) = text.get(..width).and_then(hex) else {
            break;
        };
        text = text.get(width..).unwrap_or_default();
        if width == 4 {
            units.push(u16::try_from(code).unwrap_or(0xFFFD));
        } else {
            out.push(char::from_u32(code).unwrap_or(char::REPLACEMENT_CHARACTER));
        }
    }
    out.extend(char::decode_utf16(units).map(|c| c.unwrap_or(char::REPLACEMENT_CHARACTER)));
    text
}

/// The value of a run of hex digits (and nothing else: `from_str_radix` alone would accept a
/// sign).
#[must_use]
fn hex(digits: &str) -> Option<u32> {
    if digits.bytes().all(|b| b.is_ascii_hexdigit()) {
        u32::from_str_radix(digits, 16).ok()
    } else {
        None
    }
}
