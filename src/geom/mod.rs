//! Pure f64 geometry.
