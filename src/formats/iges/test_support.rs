//! Test helpers: a writer of synthetic fixed-form IGES files (so tests state entities as
//! parameter strings and get the columns right), and checks shared by the test modules.

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]

use super::IgesError;

/// A directory entry and its parameters for [`build`].
#[derive(Debug, Clone)]
pub(super) struct Ent {
    pub entity_type: i32,
    pub form: i32,
    /// The free-format parameters, entity type first, record delimiter included.
    pub params: String,
    /// DE field 7 (0 = none).
    pub transform: i32,
    /// DE field 13.
    pub colour: i32,
    /// DE field 9, eight characters.
    pub status: String,
    /// DE field 18.
    pub label: String,
}

pub(super) fn ent(entity_type: i32, params: &str) -> Ent {
    Ent {
        entity_type,
        form: 0,
        params: params.to_owned(),
        transform: 0,
        colour: 0,
        status: "00000000".to_owned(),
        label: String::new(),
    }
}

/// A Global section with the default delimiters, millimetres and scale 1.
pub(super) const GLOBAL: &str = "1H,,1H;,4Htest,8Htest.igs,9Hprespline,3H0.1,32,38,6,308,15,\
    4Htest,1.,2,2HMM,1,0.01,15H20240101.120000,0.001,1000.,6Hauthor,3Horg,11,0,\
    15H20240101.120000;";

/// One 80-column line: `data` (at most 72 columns) padded, then section letter and sequence.
pub(super) fn line(data: &str, letter: char, sequence: usize) -> String {
    assert!(data.len() <= 72, "{data:?} is longer than 72 columns");
    format!("{data:<72}{letter}{sequence:07}\n")
}

/// `text` cut into pieces of `width` bytes (the last one shorter).
fn pieces(text: &str, width: usize) -> Vec<String> {
    text.as_bytes()
        .chunks(width)
        .map(|c| String::from_utf8(c.to_vec()).unwrap())
        .collect()
}

/// A complete fixed-form file with the given Global text and entities. Parameters are cut at
/// exactly 64 columns, as a writer may do anywhere inside a string or list.
pub(super) fn build(global: &str, entities: &[Ent]) -> String {
    let mut out = String::new();
    out.push_str(&line(
        "synthetic file for the prespline IGES reader tests",
        'S',
        1,
    ));
    let globals = pieces(global, 72);
    for (i, piece) in globals.iter().enumerate() {
        out.push_str(&line(piece, 'G', i + 1));
    }
    let mut d_lines = Vec::new();
    let mut p_lines = Vec::new();
    for (index, e) in entities.iter().enumerate() {
        let de = 2 * index + 1;
        let params = pieces(&e.params, 64);
        let start = p_lines.len() + 1;
        for piece in &params {
            p_lines.push(format!("{piece:<64}{de:>8}"));
        }
        d_lines.push(format!(
            "{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}",
            e.entity_type, start, 0, 0, 0, 0, e.transform, 0, e.status
        ));
        d_lines.push(format!(
            "{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}",
            e.entity_type,
            0,
            e.colour,
            params.len(),
            e.form,
            "",
            "",
            e.label,
            0
        ));
    }
    for (i, d) in d_lines.iter().enumerate() {
        out.push_str(&line(d, 'D', i + 1));
    }
    for (i, p) in p_lines.iter().enumerate() {
        out.push_str(&line(p, 'P', i + 1));
    }
    let terminate = format!(
        "S{:07}G{:07}D{:07}P{:07}",
        1,
        globals.len(),
        d_lines.len(),
        p_lines.len()
    );
    out.push_str(&line(&terminate, 'T', 1));
    out
}

/// A small file exercising several entity kinds, for byte-by-byte robustness tests.
pub(super) fn small_file() -> String {
    let mut matrix = ent(124, "124,1.,0.,0.,10.,0.,1.,0.,0.,0.,0.,1.,0.;");
    matrix.status = "00000200".to_owned();
    let mut point = ent(116, "116,1.5D0,2.,3.,0;");
    point.transform = 1;
    let entities = [
        matrix,
        point,
        ent(110, "110,0.,0.,0.,1.,1.,1.;"),
        ent(102, "102,1,5;"),
        ent(406, "406,1,12Hname,;with;,;"),
    ];
    build(GLOBAL, &entities)
}

/// The error's line, after checking that its message is one line that starts with it.
pub(super) fn error_line(error: &IgesError) -> usize {
    let message = error.to_string();
    assert!(
        !message.contains('\n') && !message.contains('\r'),
        "a message spans lines: {message:?}"
    );
    let prefix = format!("line {}: ", error.line());
    assert!(
        message.starts_with(&prefix),
        "a message does not start with its line: {message:?}"
    );
    assert!(error.line() >= 1, "line 0 in {message:?}");
    error.line()
}

/// The lines of `text` (without their line breaks).
pub(super) fn lines(text: &str) -> Vec<String> {
    text.lines().map(str::to_owned).collect()
}

/// Rejoins lines with LF.
pub(super) fn unlines(lines: &[String]) -> String {
    let mut out = lines.join("\n");
    out.push('\n');
    out
}

/// The 1-based file line of the line with section letter `letter` and sequence `n`.
pub(super) fn line_of(text: &str, letter: char, n: usize) -> usize {
    let tail = format!("{letter}{n:07}");
    text.lines().position(|l| l.ends_with(&tail)).unwrap() + 1
}
