//! The fixed 80-column record layout: splitting the bytes into lines, reading the section letter
//! (column 73) and sequence number (columns 74–80) of each, and checking the order S, G, D, P, T,
//! the sequence numbers and the Terminate section's counts. Everything later addresses lines by
//! these sequence numbers (DE pointers, parameter pointers), so they are checked here once.

use super::error::{IgesError, shown};

/// Columns 1–72 of a record: the data, without section letter and sequence number.
pub(super) const DATA_COLUMNS: usize = 72;

/// One of the five sections of the fixed ASCII form.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(super) enum Section {
    Start,
    Global,
    Directory,
    Parameter,
    Terminate,
}

impl Section {
    #[must_use]
    fn from_letter(letter: u8) -> Option<Self> {
        match letter {
            b'S' => Some(Self::Start),
            b'G' => Some(Self::Global),
            b'D' => Some(Self::Directory),
            b'P' => Some(Self::Parameter),
            b'T' => Some(Self::Terminate),
            _ => None,
        }
    }

    #[must_use]
    fn name(self) -> &'static str {
        match self {
            Self::Start => "Start (S)",
            Self::Global => "Global (G)",
            Self::Directory => "Directory Entry (D)",
            Self::Parameter => "Parameter Data (P)",
            Self::Terminate => "Terminate (T)",
        }
    }
}

/// One line of the file with its section known and its sequence number checked.
#[derive(Debug, Clone, Copy)]
pub(super) struct Record<'a> {
    /// 1-based line of the file (record number for files without line breaks).
    pub line: usize,
    /// Columns 1–72, always exactly 72 bytes (a line is at least 73 columns long).
    pub data: &'a [u8],
}

/// The lines of a file sorted into its sections.
#[derive(Debug, Default)]
pub(super) struct Sections<'a> {
    pub start: Vec<Record<'a>>,
    pub global: Vec<Record<'a>>,
    pub directory: Vec<Record<'a>>,
    pub parameter: Vec<Record<'a>>,
}

/// Splits `bytes` into sections, refusing the compressed and binary forms and any line whose
/// layout is not the fixed 80-column one.
pub(super) fn split(bytes: &[u8]) -> Result<Sections<'_>, IgesError> {
    let lines = physical_lines(bytes);
    if lines.is_empty() {
        return Err(IgesError::layout(1, "the file is empty"));
    }
    check_form(&lines, bytes)?;
    let mut sections = Sections::default();
    let mut current = Section::Start;
    let mut terminate: Option<Record<'_>> = None;
    for (index, raw) in lines.iter().enumerate() {
        let line = index + 1;
        let (section, sequence, data) = parse_line(line, raw)?;
        if let Some(t) = terminate {
            return Err(IgesError::layout(
                line,
                format!("a line after the Terminate section on line {}", t.line),
            ));
        }
        if section < current {
            return Err(IgesError::layout(
                line,
                format!(
                    "a {} line after the {} section; the sections must come in the order S, G, D, P, T",
                    section.name(),
                    current.name()
                ),
            ));
        }
        current = section;
        let record = Record { line, data };
        let list = match section {
            Section::Start => &mut sections.start,
            Section::Global => &mut sections.global,
            Section::Directory => &mut sections.directory,
            Section::Parameter => &mut sections.parameter,
            Section::Terminate => {
                terminate = Some(record);
                check_sequence(line, section, sequence, 0)?;
                continue;
            }
        };
        check_sequence(line, section, sequence, list.len())?;
        list.push(record);
    }
    let Some(terminate) = terminate else {
        return Err(IgesError::layout(
            lines.len(),
            "the file ends without a Terminate (T) section; it is probably truncated",
        ));
    };
    if sections.global.is_empty() {
        return Err(IgesError::layout(
            terminate.line,
            "the file has no Global (G) section",
        ));
    }
    check_terminate(&terminate, &sections)?;
    Ok(sections)
}

#[must_use]
/// The lines of the file: split at LF (a CR before it dropped), at CR alone for old Mac files,
/// or into 80-byte records for files written without line breaks. Trailing blanks, line breaks,
/// NULs and a DOS end-of-file byte (0x1A) at the very end are ignored.
fn physical_lines(bytes: &[u8]) -> Vec<&[u8]> {
    let end = bytes
        .iter()
        .rposition(|b| !matches!(b, b'\n' | b'\r' | b' ' | 0 | 0x1A))
        .map_or(0, |i| i + 1);
    let bytes = bytes.get(..end).unwrap_or_default();
    if bytes.is_empty() {
        return Vec::new();
    }
    let lines: Vec<&[u8]> = if bytes.contains(&b'\n') {
        bytes
            .split(|&b| b == b'\n')
            .map(|l| l.strip_suffix(b"\r").unwrap_or(l))
            .collect()
    } else if bytes.contains(&b'\r') {
        bytes.split(|&b| b == b'\r').collect()
    } else {
        bytes.chunks(80).collect()
    };
    lines.into_iter().map(trim_end).collect()
}

#[must_use]
fn trim_end(line: &[u8]) -> &[u8] {
    let end = line.iter().rposition(|&b| b != b' ').map_or(0, |i| i + 1);
    line.get(..end).unwrap_or_default()
}

/// Refuses the compressed ASCII form (a flag line with `C` in column 73) and the binary form
/// (first byte `B`, no fixed-form section letter) with a message saying what they are.
fn check_form(lines: &[&[u8]], bytes: &[u8]) -> Result<(), IgesError> {
    let first = lines.first().copied().unwrap_or_default();
    let letter = first.get(72).copied();
    if letter == Some(b'C') {
        return Err(IgesError::UnsupportedForm {
            line: 1,
            form: "compressed ASCII",
        });
    }
    let fixed = letter.and_then(Section::from_letter).is_some();
    if !fixed && (bytes.first() == Some(&b'B') || first.iter().any(|&b| b == 0 || b > 127)) {
        return Err(IgesError::UnsupportedForm {
            line: 1,
            form: "binary",
        });
    }
    Ok(())
}

/// Section letter, sequence number and data columns of one line, or why it is not a fixed-form
/// record.
fn parse_line(line: usize, raw: &[u8]) -> Result<(Section, u32, &[u8]), IgesError> {
    if raw.len() > 80 {
        return Err(IgesError::layout(
            line,
            format!(
                "{} columns, but an IGES line has at most 80 (section letter in column 73)",
                raw.len()
            ),
        ));
    }
    if raw.is_empty() {
        return Err(IgesError::layout(
            line,
            "a blank line; every IGES line carries a section letter in column 73",
        ));
    }
    let letter = raw.get(72).copied();
    let Some(section) = letter.and_then(Section::from_letter) else {
        return Err(IgesError::layout(line, no_letter_message(raw)));
    };
    let data = raw.get(..DATA_COLUMNS).unwrap_or_default();
    let digits = raw.get(73..).unwrap_or_default();
    let sequence = parse_sequence(digits).ok_or_else(|| {
        IgesError::layout(
            line,
            format!(
                "columns 74-80 should hold the {} sequence number, found '{}'",
                section.name(),
                shown(digits)
            ),
        )
    })?;
    Ok((section, sequence, data))
}

#[must_use]
/// What is wrong with a line that has no section letter in column 73, naming a letter found in
/// a neighbouring column, which is what a line shifted by a column looks like.
fn no_letter_message(raw: &[u8]) -> String {
    let Some(&found) = raw.get(72) else {
        return format!(
            "only {} columns; the section letter (S, G, D, P or T) belongs in column 73",
            raw.len()
        );
    };
    let near = [71usize, 73, 70, 74].into_iter().find_map(|i| {
        raw.get(i)
            .copied()
            .filter(|&b| Section::from_letter(b).is_some())
            .map(|b| (i + 1, char::from(b)))
    });
    let hint = near.map_or(String::new(), |(column, letter)| {
        format!(" ('{letter}' is in column {column}: the columns are shifted)")
    });
    format!(
        "column 73 holds '{}', not a section letter (S, G, D, P or T){hint}",
        shown(&[found])
    )
}

#[must_use]
/// Columns 74–80: digits, right- or left-aligned in blanks or padded with zeros.
fn parse_sequence(digits: &[u8]) -> Option<u32> {
    let text = std::str::from_utf8(digits).ok()?.trim_matches(' ');
    if text.is_empty() || !text.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    text.parse().ok()
}

fn check_sequence(
    line: usize,
    section: Section,
    sequence: u32,
    before: usize,
) -> Result<(), IgesError> {
    let expected = before + 1;
    if usize::try_from(sequence).ok() != Some(expected) {
        return Err(IgesError::layout(
            line,
            format!(
                "{} sequence number {sequence}, expected {expected} (a line is missing, repeated or out of order)",
                section.name()
            ),
        ));
    }
    Ok(())
}

/// The Terminate line holds the line counts of S, G, D and P as `S0000001G0000004…`; a mismatch
/// means lines were lost or added.
fn check_terminate(terminate: &Record<'_>, sections: &Sections<'_>) -> Result<(), IgesError> {
    let expected = [
        (b'S', sections.start.len()),
        (b'G', sections.global.len()),
        (b'D', sections.directory.len()),
        (b'P', sections.parameter.len()),
    ];
    for (index, (letter, count)) in expected.into_iter().enumerate() {
        let field = terminate
            .data
            .get(index * 8..index * 8 + 8)
            .unwrap_or_default();
        let letter_ok = field.first() == Some(&letter);
        let number = field.get(1..).and_then(parse_sequence);
        if !letter_ok || number.is_none() {
            return Err(IgesError::layout(
                terminate.line,
                format!(
                    "Terminate columns {}-{} should read '{}' and a line count, found '{}'",
                    index * 8 + 1,
                    index * 8 + 8,
                    char::from(letter),
                    shown(field)
                ),
            ));
        }
        if number.and_then(|n| usize::try_from(n).ok()) != Some(count) {
            return Err(IgesError::layout(
                terminate.line,
                format!(
                    "the Terminate section counts {} {} lines, but the file has {count}",
                    number.unwrap_or(0),
                    char::from(letter)
                ),
            ));
        }
    }
    Ok(())
}
