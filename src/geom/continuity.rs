//! What a curve is at a join, from its left and right derivatives (lecture 3.2 and 3.5):
//! parametric continuity C1/C2 (equal derivatives) and geometric continuity G1/G2 (one unit
//! tangent, then one curvature vector κ·n̂).

use glam::DVec3;

/// Relative tolerance of the comparisons: joins built by the lecture's formulas agree to
/// rounding (≈1e-15); anything a user can see is far above this.
pub const JOIN_TOLERANCE: f64 = 1e-9;

/// The continuity of a curve at one parameter, from one-sided limits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct JoinClass {
    /// Whether the one-sided positions agree (G0 = C0).
    pub connected: bool,
    /// Highest r ≤ 2 with equal one-sided derivatives of orders 1..=r (0 when only positions
    /// agree).
    pub parametric: u8,
    /// Highest r ≤ 2 of geometric continuity: G1 = one unit tangent (non-zero derivatives in
    /// the same direction), G2 = G1 and one curvature vector.
    pub geometric: u8,
}

impl JoinClass {
    /// The badge text: "C2", "C1", "C1 G2", "G2", "G1", "G0", or "gap" when the positions
    /// differ.
    #[must_use]
    pub fn label(&self) -> &'static str {
        match (self.connected, self.parametric, self.geometric) {
            (false, _, _) => "gap",
            (true, 2, _) => "C2",
            (true, 1, 2) => "C1 G2",
            (true, 1, _) => "C1",
            (true, _, 2) => "G2",
            (true, _, 1) => "G1",
            _ => "G0",
        }
    }
}

/// Classifies a join from the left and right limits of c, c', c'' (`left[r]`, `right[r]`).
/// `size` is a length scale of the curve (its extent): values below 1e-12·size count as zero,
/// so exact zeros from cancellation do not decide a class.
#[must_use]
pub fn classify(left: [DVec3; 3], right: [DVec3; 3], size: f64) -> JoinClass {
    let tol = JOIN_TOLERANCE;
    let floor = 1e-12 * size.max(f64::MIN_POSITIVE);
    let same = |a: DVec3, b: DVec3, floor: f64| {
        (a - b).length() <= tol * a.length().max(b.length()) + floor
    };
    let connected = same(left[0], right[0], floor);
    let c1 = connected && same(left[1], right[1], floor);
    let c2 = c1 && same(left[2], right[2], floor);
    let (l1, r1) = (left[1].length(), right[1].length());
    let g1 = connected
        && l1 > floor
        && r1 > floor
        && left[1].cross(right[1]).length() <= tol * l1 * r1
        && left[1].dot(right[1]) > 0.0;
    let g2 = g1 && {
        let (kl, kr) = (
            curvature_vector(left[1], left[2]),
            curvature_vector(right[1], right[2]),
        );
        same(kl, kr, 1e-12 / size.max(f64::MIN_POSITIVE))
    };
    JoinClass {
        connected,
        parametric: if c2 { 2 } else { u8::from(c1) },
        geometric: if g2 { 2 } else { u8::from(g1) },
    }
}

/// κ·n̂ = (c' × c'') × c' / |c'|⁴, independent of the parameterisation.
#[must_use]
pub fn curvature_vector(d1: DVec3, d2: DVec3) -> DVec3 {
    let s2 = d1.length_squared();
    if s2 == 0.0 {
        return DVec3::ZERO;
    }
    d1.cross(d2).cross(d1) / (s2 * s2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_class_from_constructed_limits() {
        let p = DVec3::new(1.0, 2.0, 3.0);
        let d1 = DVec3::new(1.0, 0.5, 0.0);
        let d2 = DVec3::new(0.0, 2.0, 1.0);
        let c = |l: [DVec3; 3], r: [DVec3; 3]| classify(l, r, 5.0).label();
        assert_eq!(c([p, d1, d2], [p, d1, d2]), "C2");
        assert_eq!(c([p, d1, d2], [p, d1, d2 * 1.5]), "C1");
        // Reparameterised by γ: c' γ, c'' γ² + c' γ₂ — G2 (lecture 3.5).
        let g = 2.0;
        assert_eq!(c([p, d1, d2], [p, d1 * g, d2 * g * g + d1 * 0.7]), "G2");
        assert_eq!(c([p, d1, d2], [p, d1 * g, d2]), "G1");
        assert_eq!(c([p, d1, d2], [p, d1 * -1.0, d2]), "G0");
        assert_eq!(
            c([p, d1, d2], [p, d1 + DVec3::new(0.0, 0.0, 0.1), d2]),
            "G0"
        );
        assert_eq!(c([p, d1, d2], [p + DVec3::X * 1e-3, d1, d2]), "gap");
        // C1 with a curvature vector that agrees only because the second derivative differs
        // along the tangent.
        assert_eq!(c([p, d1, d2], [p, d1, d2 + d1 * 0.5]), "C1 G2");
    }
}
