//! STEP (ISO 10303-21 files of AP203, AP214, AP242) → trimmed rational B-spline faces.
//!
//! [`read_step`] parses the file (the `step` crate), walks its product structure to every face
//! instance in place ([`CadModel::faces`], counted per assembly instance), converts each face's
//! surface to its exact rational B-spline form over the face's parameter range (the `analytic`
//! crate; B-spline surfaces as they are) and gives its trim loops in that surface's own
//! parameter space. Lengths come out in millimetres whatever the file's unit; colours are
//! linear RGB. What is read but not drawn is listed in [`CadModel::skipped`] with a warning line
//! each; a malformed file is an `Err` of one line naming the line and `#id`.
//!
//! Everything is plain data: the caller (prespline's STEP format) turns it into scene objects.
//! [`measure`] integrates a face's area and samples its bounds (the checks against
//! OpenCASCADE use it).

mod assembly;
mod attrs;
mod curves;
mod invert;
mod measure_face;
mod model;
mod nurbs;
mod products;
mod style;
mod surface;
mod topology;
mod trims;
mod units;

pub use crate::geom::analytic::NurbsSurface;
pub use measure_face::{Measure, measure};

pub use crate::formats::cad::{CadCurve2, CadFace, CadLoop, CadModel, CadPiece, Skipped};

/// Reads a STEP file's faces (see the crate doc). The error is one line: `line N: #id …`.
pub fn read_step(bytes: &[u8]) -> Result<CadModel, String> {
    let file = crate::formats::step::StepFile::parse(bytes).map_err(|e| e.to_string())?;
    model::build(&file)
}

#[cfg(test)]
mod tests;
