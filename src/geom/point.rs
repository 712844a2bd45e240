//! The small vector algebra shared by Euclidean (`DVec3`) and homogeneous (`DVec4`) control points.

use glam::{DVec3, DVec4};
use std::ops::{Add, AddAssign, Mul, Sub};

/// A control-point type: anything that forms a real vector space. Evaluation routines are written
/// once over `Point` and used for Euclidean points and for homogeneous (rational) points alike.
pub trait Point:
    Copy
    + Default
    + PartialEq
    + std::fmt::Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + AddAssign
    + Mul<f64, Output = Self>
{
    /// Largest absolute component, used for relative tolerances; NaN when any component is
    /// NaN (glam's `max_element` would drop it).
    fn max_abs(self) -> f64;
}

impl Point for DVec3 {
    fn max_abs(self) -> f64 {
        if self.is_nan() {
            f64::NAN
        } else {
            self.abs().max_element()
        }
    }
}

impl Point for DVec4 {
    fn max_abs(self) -> f64 {
        if self.is_nan() {
            f64::NAN
        } else {
            self.abs().max_element()
        }
    }
}

/// The larger of two numbers, NaN when either is NaN (`f64::max` returns the other one), so a
/// NaN folded into a running maximum stays visible.
#[inline]
#[must_use]
pub fn nan_max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}

impl Point for f64 {
    fn max_abs(self) -> f64 {
        self.abs()
    }
}

/// Lift a Euclidean point with weight `w` to homogeneous coordinates `(w·p, w)`.
#[inline]
#[must_use]
pub fn to_homogeneous(p: DVec3, w: f64) -> DVec4 {
    (p * w).extend(w)
}

/// Homogeneous control points (w_i P_i, w_i); weight 1 for polynomial objects.
#[must_use]
pub fn homogeneous(points: &[DVec3], weights: Option<&[f64]>) -> Vec<DVec4> {
    match weights {
        Some(w) => points
            .iter()
            .zip(w)
            .map(|(&p, &w)| to_homogeneous(p, w))
            .collect(),
        None => points.iter().map(|p| p.extend(1.0)).collect(),
    }
}

/// Binomial coefficient C(n, k) as f64 (exact for the small n used in derivative rules).
#[must_use]
pub fn binomial(n: usize, k: usize) -> f64 {
    if k > n {
        return 0.0;
    }
    let k = k.min(n - k);
    let mut c = 1.0;
    for i in 0..k {
        c = c * (n - i) as f64 / (i + 1) as f64;
    }
    c.round()
}

/// Projects homogeneous derivatives `a[k] = d^k/dt^k (w·C, w)` to Euclidean derivatives of C by
/// the quotient (Leibniz) rule — NURBS Book A4.2 (RatCurveDerivs):
/// `C^(k) = (A^(k) − Σ_{i=1..k} C(k,i) w^(i) C^(k−i)) / w`.
pub fn rational_curve_derivs(a: &[DVec4], out: &mut [DVec3]) {
    debug_assert_eq!(a.len(), out.len());
    let w0 = a[0].w;
    for k in 0..a.len() {
        let mut v = a[k].truncate();
        for i in 1..=k {
            v -= out[k - i] * (binomial(k, i) * a[i].w);
        }
        out[k] = v / w0;
    }
}
