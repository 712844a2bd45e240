//! prespline: pre-evaluated interactive editing of spline curves and surfaces.
pub mod geom;
pub mod gpu;
