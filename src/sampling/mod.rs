//! Pre-evaluation (Lakså): basis data is evaluated once at fixed sample parameters — per
//! direction the parameters S, per control point the sample range I it influences, per sample the
//! B-spline-Hermite matrix M — so that full sampling is a sequence of small dot products and an
//! edit updates only the samples it touches, reporting them as dirty ranges for GPU mirrors.
//!
//! `geom` knows the curves; this module knows where they are sampled. Nothing here knows Vulkan.

pub mod budget;
pub mod curvature;
pub mod dirty;
pub mod fallback;
pub mod grid;
pub(crate) mod kernels;
pub mod normals;
pub mod object;
pub mod rational;
pub mod tables;

pub use dirty::{DirtyRegion, DirtySet};
pub use grid::{PartialSet, SampleGrid};
pub use object::{SampleMode, Sampler, Tracked};
pub use tables::axis::HermiteTable;
