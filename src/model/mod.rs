//! The table of object kinds: per kind its model (geometry with its sample counts), its edits
//! with their exact inverses, and its sampler, all reached through one trait, [`Kind`].
//!
//! This layer sits on `geom` (the mathematics) and `sampling` (the pre-evaluation machinery:
//! tables, kernels, the [`Sampler`](crate::sampling::Sampler) trait) and below the editor and
//! the file formats. The list of kinds is written once (`registered_kinds!` in
//! [`registry`]); [`Model`], [`ObjectEdit`] and [`SampledObject`] are the closed sums over it,
//! and pairing a model with an edit of another kind is an error value, never a panic.
//!
//! The files form layers: what every kind uses (`index`, `edit`, `limits`, `points`,
//! `controls`, `file`, `kind`), the kinds (`spline/`, `erbs/`, `chain/`), and above them the
//! registry, what the sums do (`object`), the live control display (`display`) and the exact
//! reference (`exact`). This file only declares and re-exports.

mod chain;
pub mod controls;
mod display;
mod edit;
mod erbs;
pub mod exact;
pub mod file;
mod index;
pub mod kind;
mod limits;
mod object;
mod points;
pub mod registry;
mod spline;

pub use chain::sampler::ChainCurveSampler;
pub use chain::{
    BezierSplineEdit, BezierSplineModel, CatmullRomEdit, CatmullRomModel, ChainEdit, ChainModel,
};
pub use controls::{ControlDisplay, ControlLayout, ControlsChange, Grip};
pub use edit::{Build, EditError, IntoObject, KindEdit, Target};
pub use erbs::controls::{each_curve_leaf_of, each_patch_leaf_of};
pub use erbs::curve_sampler::ErbsCurveSampler;
pub use erbs::surface_sampler::ErbsSurfaceSampler;
pub use erbs::{
    ErbsCurveEdit, ErbsCurveModel, ErbsEdit, ErbsNet, ErbsSurfaceEdit, ErbsSurfaceModel, LocalEdit,
    LocalPath,
};
pub use index::Index2;
pub use kind::Kind;
pub use limits::{
    MAX_CURVE_SAMPLES, MAX_DEGREE, MAX_SURFACE_SAMPLES, check_samples, check_surface_samples,
};
pub use object::{Edit, merge_edits};
pub use points::{PointEdit, PointNet};
pub use registry::{Model, ModelRef, ObjectEdit, SampledObject, edit_kind_mismatch};
pub use spline::curve::{CurveEdit, CurveModel};
pub use spline::curve_sampler::SplineCurveSampler;
pub use spline::form::SplineForm;
pub use spline::surface::{SurfaceEdit, SurfaceModel};
pub use spline::surface_sampler::SplineSurfaceSampler;
