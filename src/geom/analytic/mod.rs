//! Exact rational B-spline forms of CAD's analytic curves and surfaces (STEP /
//! IGES planes, cylinders, cones, spheres, tori, surfaces of revolution and
//! linear extrusions), the maps between their analytic parameters and the
//! NURBS parameters, and point inversion.
//!
//! Pure `f64` math, no I/O. This file becomes `geom/analytic/mod.rs`; all
//! sibling references use `super::` so the folder can move as a unit.
//!
//! * [`frame`]: [`Frame`] from STEP's AXIS2_PLACEMENT_3D.
//! * [`arc`]: circle/ellipse arcs (A7.1), line segments, [`ArcMap`].
//! * [`surface`]: [`AnalyticSurface`] → [`FaceNurbs`] (surface + [`ParamMap`]).
//! * [`invert`]: closed-form inversion for the analytic kinds.
//! * [`newton`]: Newton point inversion on curves and NURBS surfaces (§6.1).
//! * [`nurbs`]: plain-data [`NurbsCurve`] / [`NurbsSurface`] and a de Boor
//!   evaluator with first and second derivatives.

pub mod arc;
pub mod error;
pub mod frame;
pub mod invert;
pub mod newton;
pub mod nurbs;
mod split;
pub mod surface;
mod swept;

pub use arc::{ArcMap, circle_arc, ellipse_arc, line_segment};
pub use error::{AnalyticError, Result};
pub use frame::Frame;
pub use invert::{Inversion, InvertOptions, Seam, Unwrapped, unwrap_angle};
pub use newton::{NewtonOptions, invert_nurbs};
pub use nurbs::{NurbsCurve, NurbsSurface, SurfaceDerivs};
pub use surface::{AnalyticSurface, AxisMap, FaceNurbs, ParamBox, ParamMap, SurfaceKind};

#[cfg(test)]
mod tests;
