//! Pre-evaluated basis data, per parameter direction: the B-spline-Hermite tables (S, I, M),
//! the ERBS blend data of a direction, and the blended tables of an ERBS local patch. Tables
//! know the bases and the sample parameters, not the samples: the kernels and samplers above
//! read them.

pub mod axis;
pub mod erbs_axis;
pub(crate) mod erbs_patch;
