//! What every curve and surface does with its control points: validate them on construction
//! and combine them with the rows of a B-spline-Hermite matrix. Bézier and B-spline code both
//! use these, so they live below both.

use glam::DVec3;

use super::error::{GeomError, GeomResult};
use super::point::Point;

/// Σ_k M[r][k] P_k for r = 0..=n (rows above the degree are zero).
pub(crate) fn combine_rows<P: Point>(m: &[f64], degree: usize, points: &[P], n: usize) -> Vec<P> {
    let w = degree + 1;
    (0..=n)
        .map(|r| {
            if r > degree {
                return P::default();
            }
            let mut acc = P::default();
            for k in 0..w {
                acc += points[k] * m[r * w + k];
            }
            acc
        })
        .collect()
}

pub(crate) fn check_points(points: &[DVec3]) -> GeomResult<()> {
    if points.is_empty() {
        return Err(GeomError::new("points", "no control points"));
    }
    for (i, p) in points.iter().enumerate() {
        if !p.is_finite() {
            return Err(GeomError::new(
                "points",
                format!("point {i} {p:?} is not finite"),
            ));
        }
    }
    Ok(())
}

pub(crate) fn check_weights(weights: &[f64], n: usize) -> GeomResult<()> {
    if weights.len() != n {
        return Err(GeomError::new(
            "weights",
            format!("{} weights for {n} control points", weights.len()),
        ));
    }
    for (i, &w) in weights.iter().enumerate() {
        if !(w.is_finite() && w > 0.0) {
            return Err(GeomError::new(
                "weights",
                format!("weight {i} is {w}; weights must be positive and finite"),
            ));
        }
    }
    Ok(())
}
