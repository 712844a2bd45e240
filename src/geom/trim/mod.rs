//! Trimmed surfaces: the trimmed domain of a surface is given by closed loops of 2D curves in its
//! parameter space (u, v).
//!
//! The route: a file's loops as given ([`spec`], what is read, written back and carried through
//! edits); curves are flattened to polylines within a tolerance ([`curve`]); loops are
//! assembled, validated and classified by nesting into [`TrimRegions`] ([`loops`], [`regions`],
//! with the crossing tests in `crossings`); a uniform sample grid gets its [`Coverage`] once per
//! structure: inside samples, cell classes and a packed form for the fragment shader
//! ([`coverage`]); [`integrate`] integrates a function over the trimmed domain, the surface area
//! when `f = |S_u × S_v|` ([`area`]).
//!
//! A trim never moves when control points move, and knot insertion and degree elevation keep the
//! parametrisation, so all of this is computed once per structure, never per drag.

pub mod area;
pub mod coverage;
mod crossings;
pub mod curve;
pub mod error;
mod grid;
pub mod loops;
pub mod regions;
pub mod spec;
mod trimmed;

pub use area::{CELL_NODES, Integrand, integrate};
pub use coverage::{CellClass, Coverage};
pub use curve::{Curve2, Piece, flatten, flatten_piece, flatten_tracked};
pub use error::TrimError;
pub use loops::{LoopInput, Role, Tolerances};
pub use regions::{TrimLoop, TrimRegions};
pub use spec::{LoopSpec, Trim, TrimCurve, TrimPiece};
pub use trimmed::{FLATTEN_TOLERANCE, Trimmed, flatten_tolerance, regions_at};

#[cfg(test)]
mod tests;
