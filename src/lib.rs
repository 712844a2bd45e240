//! prespline: pre-evaluated interactive editing of spline curves and surfaces.
// Numerical kernels index several arrays with the same loop counter (basis rows, control points,
// derivative orders); iterator zips would obscure the textbook algorithms they follow.
#![allow(clippy::needless_range_loop)]
pub mod cli;
pub mod geom;
pub mod gpu;
pub mod model;
pub mod profile;
pub mod render;
pub mod sampling;
pub mod scene;
pub mod view;
