//! The B-spline family: Bézier, B-spline and NURBS curves and tensor-product surfaces, with
//! their edits and samplers.

pub mod curve;
pub mod curve_sampler;
pub mod file;
pub mod form;
#[cfg(test)]
mod kernel_tests;
mod kinds;
pub mod surface;
pub mod surface_sampler;
