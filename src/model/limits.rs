//! What every kind holds its objects to: degrees and sample counts.

use super::edit::EditError;

/// Largest polynomial degree per direction (files, degree elevation). Evaluation works for any
/// degree; this bounds memory (pre-evaluated matrices grow with (d+1)²) and rejects nonsense.
pub const MAX_DEGREE: usize = 64;
/// Largest sample count per curve.
pub const MAX_CURVE_SAMPLES: usize = 10_000_000;
/// Largest sample count of a surface (mu · mv).
pub const MAX_SURFACE_SAMPLES: usize = 1 << 24;

/// Checks a sample count: at least 2 (both ends are sampled), at most `max`.
pub fn check_samples(m: usize, max: usize) -> Result<(), EditError> {
    if m < 2 {
        return Err(EditError::new(
            "samples",
            format!("{m} samples: at least 2 are needed (both ends are sampled)"),
        ));
    }
    if m > max {
        return Err(EditError::new(
            "samples",
            format!("{m} samples exceed the limit of {max}"),
        ));
    }
    Ok(())
}

/// Checks surface sample counts [mu, mv].
pub fn check_surface_samples([mu, mv]: [usize; 2]) -> Result<(), EditError> {
    check_samples(mu, MAX_SURFACE_SAMPLES)?;
    check_samples(mv, MAX_SURFACE_SAMPLES)?;
    if mu.saturating_mul(mv) > MAX_SURFACE_SAMPLES {
        return Err(EditError::new(
            "samples",
            format!("{mu} × {mv} samples exceed the limit of {MAX_SURFACE_SAMPLES}"),
        ));
    }
    Ok(())
}
