//! Numbers as the overlays print them.

/// Four significant digits, plain ASCII (the overlay font).
#[must_use]
pub fn short(x: f64) -> String {
    if x == 0.0 {
        // log10(0) is −∞: a planar curve's torsion would overflow the digit count.
        "0".to_string()
    } else if (1e-3..1e5).contains(&x.abs()) {
        let digits = (3 - x.abs().log10().floor() as i32).clamp(0, 6) as usize;
        format!("{x:.digits$}")
    } else {
        format!("{x:.3e}")
    }
}
