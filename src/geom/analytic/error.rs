//! Errors for the analytic → NURBS conversions and point inversion.
//!
//! Every variant renders as one line so a STEP/IGES importer can attach it to
//! the offending entity and skip the face instead of aborting the whole file.

use thiserror::Error;

/// Why an analytic curve/surface could not be built, converted or inverted.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum AnalyticError {
    /// A coordinate, radius, angle or parameter was NaN or infinite.
    #[error("{what} is not finite")]
    NonFinite {
        /// Which input was bad.
        what: &'static str,
    },
    /// A length that must be strictly positive was zero or negative.
    #[error("{what} must be positive, got {value}")]
    NonPositive {
        /// Which input was bad.
        what: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A direction vector had zero length.
    #[error("{what} has zero length")]
    ZeroVector {
        /// Which input was bad.
        what: &'static str,
    },
    /// The placement's axis and ref_direction are parallel, so X is undefined.
    #[error("axis and ref_direction are parallel")]
    ParallelAxes,
    /// A frame whose axes are not unit, orthogonal and right-handed.
    #[error("frame axes are not orthonormal and right-handed")]
    NotOrthonormal,
    /// A parameter range was empty, reversed where that is not allowed, or too
    /// small to split into segments.
    #[error("empty {what} range [{lo}, {hi}]")]
    EmptyRange {
        /// Which range was bad.
        what: &'static str,
        /// Range start.
        lo: f64,
        /// Range end.
        hi: f64,
    },
    /// An angular range sweeps more than one full turn.
    #[error("{what} range sweeps {sweep} rad, more than 2π")]
    SweepTooLarge {
        /// Which range was bad.
        what: &'static str,
        /// The absolute sweep in radians.
        sweep: f64,
    },
    /// A cone semi-angle outside the open interval (−π/2, π/2).
    #[error("cone semi-angle {0} rad is outside (-π/2, π/2)")]
    SemiAngle(f64),
    /// A parameter range that lies outside the valid domain.
    #[error("{what} range [{lo}, {hi}] lies outside the domain [{dom_lo}, {dom_hi}]")]
    OutOfDomain {
        /// Which range was bad.
        what: &'static str,
        /// Requested start.
        lo: f64,
        /// Requested end.
        hi: f64,
        /// Domain start.
        dom_lo: f64,
        /// Domain end.
        dom_hi: f64,
    },
    /// A NURBS curve or surface whose arrays are inconsistent.
    #[error("invalid NURBS: {0}")]
    InvalidNurbs(&'static str),
}

/// Result alias used throughout the module.
pub type Result<T> = std::result::Result<T, AnalyticError>;

/// Fails with [`AnalyticError::NonFinite`] unless `x` is finite.
pub(crate) fn finite(x: f64, what: &'static str) -> Result<f64> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(AnalyticError::NonFinite { what })
    }
}

/// Fails unless `x` is finite and strictly positive.
pub(crate) fn positive(x: f64, what: &'static str) -> Result<f64> {
    finite(x, what)?;
    if x > 0.0 {
        Ok(x)
    } else {
        Err(AnalyticError::NonPositive { what, value: x })
    }
}

/// Fails unless every component of `v` is finite.
pub(crate) fn finite_vec(v: glam::DVec3, what: &'static str) -> Result<glam::DVec3> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(AnalyticError::NonFinite { what })
    }
}

/// `x` limited to `[lo, hi]`, NaN staying NaN. Unlike `f64::clamp` it never
/// panics (on `lo > hi` it returns `hi`), so input-derived bounds are safe.
pub(crate) fn clamp(x: f64, lo: f64, hi: f64) -> f64 {
    if x.is_nan() { x } else { x.max(lo).min(hi) }
}
