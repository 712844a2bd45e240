//! The table of object kinds: per kind its model (geometry with its sample counts), its edits
//! with their exact inverses, and its sampler, all reached through one trait, [`Kind`].
//!
//! This layer sits on `geom` (the mathematics) and `sampling` (the pre-evaluation machinery:
//! tables, kernels, the [`Sampler`](crate::sampling::Sampler) trait) and below the editor and
//! the file formats. The list of kinds is written once ([`registered_kinds`]); [`Model`],
//! [`ObjectEdit`] and [`SampledObject`] are the closed sums over it, and pairing a model with an
//! edit of another kind is an error value, never a panic.

/// The registered kinds: `Variant(model type)` each. A new kind is one module below and one
/// line here; [`registry`] generates the sums over these and everything reaches a kind through
/// its [`Kind`] implementation.
macro_rules! registered_kinds {
    ($then:ident) => {
        $then! {
            Curve(crate::model::CurveModel),
            Surface(crate::model::SurfaceModel),
            ErbsCurve(crate::model::ErbsCurveModel),
            ErbsSurface(crate::model::ErbsSurfaceModel),
            CatmullRom(crate::model::CatmullRomModel),
            BezierSpline(crate::model::BezierSplineModel),
        }
    };
}

mod chain;
pub mod controls;
mod edit;
mod erbs;
pub mod exact;
pub mod file;
pub mod kind;
mod points;
pub mod registry;
mod spline;

pub use chain::sampler::ChainCurveSampler;
pub use chain::{
    BezierSplineEdit, BezierSplineModel, CatmullRomEdit, CatmullRomModel, ChainEdit, ChainModel,
};
pub use controls::{ControlDisplay, ControlLayout, ControlsChange, Grip};
pub use edit::{Edit, EditError, KindEdit, Target, merge_edits};
pub use erbs::controls::{each_curve_leaf_of, each_patch_leaf_of};
pub use erbs::curve_sampler::ErbsCurveSampler;
pub use erbs::surface_sampler::ErbsSurfaceSampler;
pub use erbs::{
    ErbsCurveEdit, ErbsCurveModel, ErbsEdit, ErbsNet, ErbsSurfaceEdit, ErbsSurfaceModel, LocalEdit,
    LocalPath,
};
pub use kind::{Kind, edit_kind_mismatch};
pub use points::{PointEdit, PointNet};
pub use registry::{IntoObject, Model, ModelRef, ObjectEdit, SampledObject};
pub use spline::curve::{CurveEdit, CurveModel};
pub use spline::curve_sampler::SplineCurveSampler;
pub use spline::surface::{SurfaceEdit, SurfaceModel};
pub use spline::surface_sampler::SplineSurfaceSampler;

/// Largest polynomial degree per direction (files, degree elevation). Evaluation works for any
/// degree; this bounds memory (pre-evaluated matrices grow with (d+1)²) and rejects nonsense.
pub const MAX_DEGREE: usize = 64;
/// Largest sample count per curve.
pub const MAX_CURVE_SAMPLES: usize = 10_000_000;
/// Largest sample count of a surface (mu · mv).
pub const MAX_SURFACE_SAMPLES: usize = 1 << 24;

/// A control point or local curve/patch index: one index for curves, two for surfaces.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Index2 {
    One(usize),
    Two(usize, usize),
}

/// "3" or "[1, 2]", as messages and the file format write an index.
impl std::fmt::Display for Index2 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Index2::One(k) => write!(f, "{k}"),
            Index2::Two(a, b) => write!(f, "[{a}, {b}]"),
        }
    }
}

/// How a polynomial-basis object is written: as a Bézier object (one span on [0, 1]) or as a
/// B-spline. Both are evaluated as B-splines; knot insertion turns a Bézier object into a
/// B-spline object.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SplineForm {
    Bezier,
    BSpline,
}

/// Checks a sample count: at least 2 (both ends are sampled), at most `max`.
pub fn check_samples(m: usize, max: usize) -> Result<(), EditError> {
    if m < 2 {
        return Err(EditError::new(
            "samples",
            format!("{m} samples: at least 2 are needed (both ends are sampled)"),
        ));
    }
    if m > max {
        return Err(EditError::new(
            "samples",
            format!("{m} samples exceed the limit of {max}"),
        ));
    }
    Ok(())
}

/// Checks surface sample counts [mu, mv].
pub fn check_surface_samples([mu, mv]: [usize; 2]) -> Result<(), EditError> {
    check_samples(mu, MAX_SURFACE_SAMPLES)?;
    check_samples(mv, MAX_SURFACE_SAMPLES)?;
    if mu.saturating_mul(mv) > MAX_SURFACE_SAMPLES {
        return Err(EditError::new(
            "samples",
            format!("{mu} × {mv} samples exceed the limit of {MAX_SURFACE_SAMPLES}"),
        ));
    }
    Ok(())
}
