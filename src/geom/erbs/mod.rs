//! ERBS (expo-rational B-spline) curves and tensor-product surfaces of blending type.
//!
//! On interval i of a direction the curve blends two local curves:
//! c(t) = (1 − B(w)) c_i(t) + B(w) c_{i+1}(t), w = (t − c_i)/(c_{i+1} − c_i), with derivatives
//! by the full Leibniz rule c^(r) = Σ_k C(r,k) [W_i^(r−k) c_i^(k) + W_{i+1}^(r−k) c_{i+1}^(k)] —
//! not the paper's printed update loop, which drops the product-rule terms. [`ErbsKnots`] says
//! which interval, which locals and which supports (open or closed directions).
//!
//! A local curve (patch) is a polynomial Bézier or B-spline curve, or itself an ERBS curve with
//! its own locals, to any depth up to [`MAX_NESTING`]; each is stored *placed*: its parameter
//! is the parent's, its domain the local's support. Locals are built from any curve or surface
//! by Hermite interpolation at the knots (the source's Taylor polynomial at each knot in
//! Bernstein form) and refined by inserting a knot between two others.

mod curve;
mod knots;
mod surface;
mod taylor;

pub use curve::{ErbsCurve, LocalCurve};
pub use knots::ErbsKnots;
pub use surface::{ErbsSurface, LocalPatch};
pub use taylor::{taylor_bezier, taylor_patch};

use super::bfunction::BFunction;

/// Deepest nesting of ERBS local curves inside ERBS local curves: at most this many ERBS levels,
/// the object itself included, so a local path has at most this many steps. Each level is
/// pre-sampled at its parent's sample parameters, so memory grows with the depth.
pub const MAX_NESTING: usize = 6;

/// Blend weights on the interval [a, b] and their derivatives with respect to the parameter:
/// `out[0][r]` for the left local (1 − B), `out[1][r]` for the right one (B), r = 0..=n.
pub fn blend_weights(bf: &impl BFunction, (a, b): (f64, f64), t: f64, n: usize) -> [Vec<f64>; 2] {
    let delta = 1.0 / (b - a);
    let w = ((t - a) * delta).clamp(0.0, 1.0);
    let mut bd = vec![0.0; n + 1];
    bf.derivatives(w, &mut bd);
    let mut scale = 1.0;
    for v in bd.iter_mut() {
        *v *= scale;
        scale *= delta;
    }
    let left = bd
        .iter()
        .enumerate()
        .map(|(r, &v)| if r == 0 { 1.0 - v } else { -v })
        .collect();
    [left, bd]
}
