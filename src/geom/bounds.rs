//! Axis-aligned bounding boxes.

use glam::DVec3;

/// Axis-aligned bounds of points (a scene for framing and clip planes, an object, a chunk of
/// samples).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bounds {
    pub min: DVec3,
    pub max: DVec3,
}

impl Bounds {
    pub const EMPTY: Bounds = Bounds {
        min: DVec3::splat(f64::INFINITY),
        max: DVec3::splat(f64::NEG_INFINITY),
    };

    pub fn include(&mut self, p: DVec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    /// Grows to cover `other` too (an empty `other` changes nothing).
    pub fn merge(&mut self, other: &Bounds) {
        self.min = self.min.min(other.min);
        self.max = self.max.max(other.max);
    }

    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x
    }

    #[must_use]
    pub fn centre(&self) -> DVec3 {
        if self.is_empty() {
            DVec3::ZERO
        } else {
            0.5 * (self.min + self.max)
        }
    }

    /// Radius of the bounding sphere around the centre (at least a tiny positive value).
    #[must_use]
    pub fn radius(&self) -> f64 {
        if self.is_empty() {
            1.0
        } else {
            (0.5 * (self.max - self.min).length()).max(1e-9)
        }
    }
}
