//! What the CAD readers (STEP, IGES) share: their output, trimmed NURBS faces in millimetres
//! ([`CadModel`]), and its conversion into scene objects with sample counts that fit each
//! face ([`to_import`]).

mod model;
mod scene;

pub use model::{CadCurve2, CadFace, CadLoop, CadModel, CadPiece, Skipped};
pub use scene::{face_samples, to_import};

use crate::formats::context::{FormatError, LoadContext};

/// Bytes of memory a CAD file takes while it is read, per byte of file, at least: the text
/// and its table of entities (measured 2.6–19 times the file's size at the peak on
/// tests/data/cad, the rest being faces, which the pre-evaluation budget counts later).
const READ_BYTES_PER_FILE_BYTE: u128 = 2;

/// Refuses a CAD file too large to read within the memory budget, before parsing it.
pub fn check_read(bytes: &[u8], ctx: &LoadContext<'_>) -> Result<(), FormatError> {
    let len = bytes.len() as u128;
    ctx.budget
        .check_build(
            format_args!(
                "the file's {} of text and its entities",
                crate::sampling::budget::format_bytes(bytes.len() as u64)
            ),
            len * READ_BYTES_PER_FILE_BYTE,
        )
        .map_err(FormatError::new)
}
