//! Reads the standard HEADER entries (FILE_DESCRIPTION, FILE_NAME, FILE_SCHEMA) into
//! [`Header`].
//!
//! Leniently: a missing entry, a `$`, or a value of the wrong type leaves the field empty,
//! because the header only informs (units and geometry are in the DATA section) and writers
//! get it wrong often enough that refusing the file would help nobody.

use super::model::{Header, Param, Record};

/// The header fields found in `records`, with names, parameters and text from the parser's
/// tables.
#[must_use]
pub(super) fn extract(
    records: &[Record],
    names: &[Box<str>],
    params: &[Param],
    text: &str,
) -> Header {
    let tables = Tables { params, text };
    let mut header = Header::default();
    for record in records {
        let args = range(params, record.start, record.len);
        let string = |i: usize| tables.string(args.get(i));
        let strings = |i: usize| tables.strings(args.get(i));
        match names.get(record.name as usize).map(AsRef::as_ref) {
            Some("FILE_DESCRIPTION") => {
                header.description = strings(0);
                header.implementation_level = string(1);
            }
            Some("FILE_NAME") => {
                header.name = string(0);
                header.time_stamp = string(1);
                header.author = strings(2);
                header.organization = strings(3);
                header.preprocessor_version = string(4);
                header.originating_system = string(5);
                header.authorization = string(6);
            }
            Some("FILE_SCHEMA") => {
                header.schema_identifiers = strings(0);
                header.schemas = header
                    .schema_identifiers
                    .iter()
                    .map(|s| schema_name(s))
                    .collect();
            }
            _ => {}
        }
    }
    header
}

/// The schema name without its ASN.1 object identifier: `AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1
/// 1 1 }` → `AUTOMOTIVE_DESIGN`.
#[must_use]
fn schema_name(identifier: &str) -> String {
    let name = identifier
        .split(['{', ' ', '\t'])
        .find(|part| !part.is_empty())
        .unwrap_or_default();
    name.to_ascii_uppercase()
}

/// The slice `start..start + len` of `params`, or empty if out of range.
#[must_use]
fn range(params: &[Param], start: u32, len: u32) -> &[Param] {
    let start = start as usize;
    params
        .get(start..start.saturating_add(len as usize))
        .unwrap_or_default()
}

struct Tables<'a> {
    params: &'a [Param],
    text: &'a str,
}

impl Tables<'_> {
    /// The string value of `param`, or empty when it is not a string.
    #[must_use]
    fn string(&self, param: Option<&Param>) -> String {
        match param {
            Some(&Param::Str(start, len)) => {
                let start = start as usize;
                self.text
                    .get(start..start.saturating_add(len as usize))
                    .unwrap_or_default()
                    .to_owned()
            }
            _ => String::new(),
        }
    }

    /// The strings in the list `param`, skipping anything else; empty when it is not a list.
    #[must_use]
    fn strings(&self, param: Option<&Param>) -> Vec<String> {
        match param {
            Some(&Param::List(start, len)) => range(self.params, start, len)
                .iter()
                .filter(|p| matches!(p, Param::Str(..)))
                .map(|p| self.string(Some(p)))
                .collect(),
            _ => Vec::new(),
        }
    }
}
