//! What the CAD readers (STEP, IGES) share: their output, trimmed NURBS faces in millimetres
//! ([`CadModel`]), and its conversion into scene objects with sample counts that fit each
//! face ([`to_import`]).

mod model;
mod scene;

pub use model::{CadCurve2, CadFace, CadLoop, CadModel, CadPiece, Skipped};
pub use scene::{face_samples, to_import};
