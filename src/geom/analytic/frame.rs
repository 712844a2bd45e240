//! Right-handed placement frames built the way STEP's AXIS2_PLACEMENT_3D is.

use glam::DVec3;

use super::error::{AnalyticError, Result, finite_vec};

/// An orthonormal right-handed frame: origin `C`, axes `X`, `Y = Z × X`, `Z`.
///
/// Every analytic surface in ISO 10303-42 is written in such a frame, so the
/// conversions take one instead of loose vectors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Location `C`.
    pub origin: DVec3,
    /// Reference direction `X` (unit, ⟂ `Z`).
    pub x: DVec3,
    /// `Y = Z × X` (unit).
    pub y: DVec3,
    /// Axis `Z` (unit).
    pub z: DVec3,
}

/// Cross products shorter than this (relative to the unit vectors) count as
/// parallel: the projected X would keep fewer than ~4 significant digits.
const PARALLEL_SIN: f64 = 1e-12;

impl Default for Frame {
    fn default() -> Self {
        Self {
            origin: DVec3::ZERO,
            x: DVec3::X,
            y: DVec3::Y,
            z: DVec3::Z,
        }
    }
}

impl Frame {
    /// Builds the frame of a STEP `AXIS2_PLACEMENT_3D` (ISO 10303-42 `build_axes`).
    ///
    /// * `axis` absent → `Z = (0,0,1)`; present → normalised (error if zero).
    /// * `ref_direction` is projected perpendicular to `Z`:
    ///   `X = normalise(r − (r·Z) Z)`; an explicit `r` parallel to `Z` is an
    ///   error. When `r` is absent STEP's `first_proj_axis` uses `(1,0,0)`, or
    ///   `(0,1,0)` when `Z` is `±(1,0,0)`; we switch to `(0,1,0)` whenever `Z`
    ///   is within ~1.4e-6 rad of `±(1,0,0)` (STEP says "exactly"), because the
    ///   projection would otherwise be numerically meaningless.
    /// * `Y = Z × X`.
    ///
    /// # Errors
    /// Non-finite input, zero axis/ref_direction, or parallel axes.
    pub fn from_axis2_placement(
        location: DVec3,
        axis: Option<DVec3>,
        ref_direction: Option<DVec3>,
    ) -> Result<Self> {
        let origin = finite_vec(location, "placement location")?;
        let z = match axis {
            Some(a) => unit(a, "placement axis")?,
            None => DVec3::Z,
        };
        let r = match ref_direction {
            Some(r) => {
                let r = unit(r, "placement ref_direction")?;
                if r.cross(z).length() <= PARALLEL_SIN {
                    return Err(AnalyticError::ParallelAxes);
                }
                r
            }
            None if z.x.abs() >= 1.0 - PARALLEL_SIN => DVec3::Y,
            None => DVec3::X,
        };
        let x = unit(r - r.dot(z) * z, "projected ref_direction")?;
        let y = z.cross(x);
        Ok(Self { origin, x, y, z })
    }

    /// Checks that the (public) fields form a finite, orthonormal,
    /// right-handed frame to 1e-9, so hand-built frames fail loudly instead of
    /// producing skewed surfaces.
    ///
    /// # Errors
    /// [`AnalyticError::NonFinite`] or [`AnalyticError::NotOrthonormal`].
    pub fn validate(&self) -> Result<()> {
        for (v, what) in [
            (self.origin, "frame origin"),
            (self.x, "frame x"),
            (self.y, "frame y"),
            (self.z, "frame z"),
        ] {
            finite_vec(v, what)?;
        }
        let tol = 1e-9;
        let ok = [self.x, self.y, self.z]
            .iter()
            .all(|a| (a.length() - 1.0).abs() <= tol)
            && self.x.dot(self.y).abs() <= tol
            && self.y.dot(self.z).abs() <= tol
            && self.z.dot(self.x).abs() <= tol
            && (self.z.cross(self.x) - self.y).length() <= tol;
        if ok {
            Ok(())
        } else {
            Err(AnalyticError::NotOrthonormal)
        }
    }

    /// Maps local coordinates `(a, b, c)` to `C + aX + bY + cZ`.
    #[must_use]
    pub fn to_world(&self, a: f64, b: f64, c: f64) -> DVec3 {
        self.origin + a * self.x + b * self.y + c * self.z
    }

    /// Local coordinates `((p−C)·X, (p−C)·Y, (p−C)·Z)` of a world point.
    #[must_use]
    pub fn to_local(&self, p: DVec3) -> DVec3 {
        let d = p - self.origin;
        DVec3::new(d.dot(self.x), d.dot(self.y), d.dot(self.z))
    }
}

/// Normalises `v`, rejecting non-finite and zero vectors.
pub(crate) fn unit(v: DVec3, what: &'static str) -> Result<DVec3> {
    finite_vec(v, what)?;
    let len = v.length();
    if len > 0.0 && len.is_finite() {
        Ok(v / len)
    } else if len > 0.0 {
        // |v| overflowed: rescale first.
        let m = v.abs().max_element();
        Ok((v / m).normalize())
    } else {
        Err(AnalyticError::ZeroVector { what })
    }
}
