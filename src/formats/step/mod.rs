//! Reader for ISO 10303-21 ("STEP Part 21") exchange structures.
//!
//! [`StepFile::parse`] turns the bytes of a `.stp`/`.step` file into its [`Header`] and a table
//! of entity instances; the geometry mapping then walks that table by reference through the
//! views [`EntityRef`], [`RecordRef`], [`ParamRef`] and [`ListRef`], whose accessors report
//! mistakes in the file precisely (`line 1234: #45 = PLANE: parameter 2 (position) should be a
//! reference, found a string`). Every error is a [`StepError`] whose message is one line
//! starting with the line number; the caller prefixes the file name.
//!
//! The reader does no I/O. It accepts editions 1–3 of the format: several DATA sections,
//! complex instances, comments anywhere between tokens, lower-case keywords, all string
//! escapes; ANCHOR, REFERENCE and SIGNATURE sections are skipped. It never panics on any input,
//! never recurses on input nesting, and sizes nothing from numbers written in the file.
//!
//! ```ignore
//! // Also run as the unit test `tests::doc_example`, since the crate path differs per crate.
//! let file = StepFile::parse_str(
//!     "ISO-10303-21;HEADER;FILE_SCHEMA(('CONFIG_CONTROL_DESIGN'));ENDSEC;\
//!      DATA;#1=CARTESIAN_POINT('',(0.,1.,2.));ENDSEC;END-ISO-10303-21;",
//! )?;
//! let point = file.get(1)?.record("CARTESIAN_POINT")?;
//! assert_eq!(point.param(1, "coordinates")?.reals()?, [0.0, 1.0, 2.0]);
//! ```

mod access;
mod error;
mod header;
mod lexer;
pub mod map;
mod model;
mod params;
mod parser;
mod strings;

pub use access::{EntityRef, RecordRef, Value};
pub use error::{Scope, StepError};
pub use model::{Header, StepFile};
pub use params::{ListRef, ParamRef};
pub use parser::MAX_DEPTH;

#[cfg(test)]
mod tests;

/// The STEP format (read only): every face instance of the product structure as a trimmed
/// NURBS surface in millimetres.
#[derive(Debug, Clone, Copy)]
pub struct Step;

impl super::FileFormat for Step {
    fn name(&self) -> &'static str {
        "STEP"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["stp", "step", "p21"]
    }

    fn read(
        &self,
        bytes: &[u8],
        ctx: &super::LoadContext<'_>,
    ) -> Result<super::Import, super::FormatError> {
        super::cad::check_read(bytes, ctx)?;
        map::read_step(bytes)
            .map(super::cad::to_import)
            .map_err(super::FormatError::new)
    }
}
