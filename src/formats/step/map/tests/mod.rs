//! Unit tests of the internals.

mod geometry;
mod trim_crate;
