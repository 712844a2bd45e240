//! The B-spline family: Bézier, B-spline and NURBS curves and tensor-product surfaces, with
//! their edits and samplers.

pub mod curve;
pub mod curve_sampler;
pub mod file;
#[cfg(test)]
mod kernel_tests;
pub mod surface;
pub mod surface_sampler;
