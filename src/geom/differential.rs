//! Differential geometry of curves: Frenet–Serret frame, curvature, torsion (lecture 3.5).

use glam::DVec3;

/// The Frenet–Serret frame {t, n, b} at a curve point with curvature and torsion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrenetFrame {
    pub tangent: DVec3,
    pub normal: DVec3,
    pub binormal: DVec3,
    pub curvature: f64,
    pub torsion: f64,
}

/// Frame from C', C'', C''': t = C'/|C'|, b = C'×C''/|C'×C''|, n = b × t,
/// κ = |C'×C''|/|C'|³, τ = (C'×C'')·C'''/|C'×C''|². `None` where C' vanishes or C' ∥ C''
/// (straight pieces and inflections have no osculating plane).
#[must_use]
pub fn frenet_frame(d1: DVec3, d2: DVec3, d3: DVec3) -> Option<FrenetFrame> {
    let speed = d1.length();
    let c = d1.cross(d2);
    let c_len = c.length();
    if speed == 0.0 || c_len <= 1e-12 * speed * d2.length() || !c_len.is_finite() {
        return None;
    }
    let tangent = d1 / speed;
    let binormal = c / c_len;
    Some(FrenetFrame {
        tangent,
        normal: binormal.cross(tangent),
        binormal,
        curvature: c_len / (speed * speed * speed),
        torsion: c.dot(d3) / (c_len * c_len),
    })
}

/// Curvature κ = |C'×C''|/|C'|³ (0 where C' vanishes).
#[must_use]
pub fn curvature(d1: DVec3, d2: DVec3) -> f64 {
    let speed = d1.length();
    if speed == 0.0 {
        0.0
    } else {
        d1.cross(d2).length() / (speed * speed * speed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_1_SQRT_2, FRAC_PI_2};

    #[test]
    fn lecture_helix_frame_at_half_pi() {
        // C(u) = (sin u, cos u, u).
        let u = FRAC_PI_2;
        let d1 = DVec3::new(u.cos(), -u.sin(), 1.0);
        let d2 = DVec3::new(-u.sin(), -u.cos(), 0.0);
        let d3 = DVec3::new(-u.cos(), u.sin(), 0.0);
        let f = frenet_frame(d1, d2, d3).unwrap();
        let close = |a: DVec3, b: DVec3| (a - b).length() < 1e-15;
        assert!(
            close(f.tangent, DVec3::new(0.0, -FRAC_1_SQRT_2, FRAC_1_SQRT_2)),
            "{:?}",
            f.tangent
        );
        assert!(
            close(f.normal, DVec3::new(-1.0, 0.0, 0.0)),
            "{:?}",
            f.normal
        );
        assert!(
            close(f.binormal, DVec3::new(0.0, -FRAC_1_SQRT_2, -FRAC_1_SQRT_2)),
            "{:?}",
            f.binormal
        );
        assert!((f.curvature - 0.5).abs() < 1e-15);
        // Helix (a cos, a sin, b u) has τ = b/(a²+b²); this one is left-handed: τ = −1/2.
        assert!((f.torsion + 0.5).abs() < 1e-15, "{}", f.torsion);
    }

    #[test]
    fn straight_line_has_no_frame() {
        assert!(frenet_frame(DVec3::X, DVec3::X * 2.0, DVec3::ZERO).is_none());
        assert_eq!(curvature(DVec3::X, DVec3::X), 0.0);
    }
}
