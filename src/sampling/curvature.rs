//! Gaussian and mean curvature of surface samples, kept with the samples they come from so a
//! control point edit updates only the touched samples of a curvature map.
//!
//! From the first and second fundamental forms (E, F, G from Su, Sv; L, M, N the second
//! partials along the unit normal): K = (LN − M²)/(EG − F²), H = (EN − 2FM + GL)/(2(EG − F²)),
//! with the normal Su × Sv (a sphere with outward normals has H = −1/r). Principal curvatures
//! are κ = H ± √(H² − K).

use super::grid::SampleGrid;
use crate::geom::surface::regular_normal;
use glam::DVec3;
use std::ops::Range;

/// [K, H] from Su, Sv, Suu, Suv, Svv and the unit normal n.
#[inline]
#[must_use]
pub fn fundamental_forms(p: &[DVec3; 5], n: DVec3) -> [f64; 2] {
    let [su, sv, suu, suv, svv] = *p;
    let (e, f, g) = (su.dot(su), su.dot(sv), sv.dot(sv));
    let (l, m, nn) = (suu.dot(n), suv.dot(n), svv.dot(n));
    // EG − F² is |Su × Sv|², whose reciprocal square root the normal already takes; the
    // cross product also loses less to cancellation than EG − F² where Su and Sv are near
    // parallel. The lane kernel in `shape_of` computes exactly this.
    let inv = 1.0 / su.cross(sv).length_squared().sqrt();
    let r = inv * inv;
    [
        (l * nn - m * m) * r,
        (e * nn - 2.0 * f * m + g * l) * (0.5 * r),
    ]
}

/// Principal curvatures [κ_max, κ_min] from [K, H] (the discriminant clamped at 0 against
/// rounding at umbilics).
#[inline]
#[must_use]
pub fn principal([k, h]: [f64; 2]) -> [f64; 2] {
    let r = (h * h - k).max(0.0).sqrt();
    [h + r, h - r]
}

/// Storage slots of Su, Sv, Suu, Suv, Svv.
#[must_use]
fn slots(grid: &SampleGrid) -> Option<[usize; 5]> {
    let p = &grid.partials;
    Some([
        p.index(1, 0)?,
        p.index(0, 1)?,
        p.index(2, 0)?,
        p.index(1, 1)?,
        p.index(0, 2)?,
    ])
}

/// Recomputes [K, H] of the samples in `rows × cols` (after their partials and normals) where
/// Su × Sv is regular; the caller resolves the others (`fallback::resolve_degenerate`), as it
/// does their normals.
pub(crate) fn update(grid: &mut SampleGrid, rows: Range<usize>, cols: Range<usize>) {
    let Some(idx) = slots(grid) else { return };
    let (Some(curv), Some(normals)) = (grid.curvatures.as_mut(), grid.normals.as_ref()) else {
        return;
    };
    let stride = grid.partials.len();
    let mv = grid.dims[1];
    for i in rows {
        for j in cols.clone() {
            let s = &grid.data[(i * mv + j) * stride..(i * mv + j + 1) * stride];
            let p = idx.map(|k| s[k]);
            if regular_normal(p[0], p[1]).is_some() {
                curv[i * mv + j] = fundamental_forms(&p, normals[i * mv + j]);
            }
        }
    }
}
