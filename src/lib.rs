//! prespline: pre-evaluated interactive editing of spline curves and surfaces.
// Numerical kernels index several arrays with the same loop counter (basis rows, control points,
// derivative orders); iterator zips would obscure the textbook algorithms they follow.
#![allow(clippy::needless_range_loop)]
// `unsafe` lives in `gpu` alone (Vulkan through ash), every block with a `// SAFETY:` reason.
#![deny(unsafe_code)]
#![warn(clippy::undocumented_unsafe_blocks)]
pub mod cli;
pub mod editor;
pub mod fields;
pub mod formats;
pub mod geom;
#[allow(unsafe_code)]
pub mod gpu;
pub mod model;
pub mod parallel;
pub mod profile;
pub mod progress;
pub mod render;
pub mod sampling;
pub mod scene;
pub mod view;
