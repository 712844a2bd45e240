//! Pure f64 geometry: knots, basis and Hermite matrices, Bézier, B-spline and NURBS curves and
//! surfaces, B-functions, ERBS curves and surfaces, curve and surface differential geometry.
//!
//! Nothing here knows about Vulkan, files or the sampling engine; every function is a plain
//! computation on f64 data so that it can be checked against independent evaluators.

pub mod analytic;
pub mod basis;
pub mod bezier;
pub mod bezier_spline;
pub mod bfunction;
pub mod bounds;
pub mod bspline;
pub mod catmull_rom;
pub mod continuity;
mod control;
pub mod differential;
pub mod erbs;
pub mod error;
pub mod knots;
pub mod point;
pub mod refine;
pub mod shape;
pub mod spline;
pub mod surface;
pub mod trim;

pub use basis::HermiteMatrix;
pub use bezier::BezierCurve;
pub use bfunction::{BFunction, BFunctionKind};
pub use bounds::Bounds;
pub use bspline::BSplineCurve;
pub use catmull_rom::{CatmullRom, Parametrization};
pub use erbs::{ErbsCurve, ErbsSurface, LocalCurve, LocalPatch};
pub use error::GeomError;
pub use knots::KnotVector;
pub use spline::{BezierSpline, Handles, JoinContinuity};
pub use surface::{Partials, TensorSurface};
