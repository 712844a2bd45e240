//! Display level of detail: which rows and columns of a surface's sample grid to draw, chosen
//! from how large the grid projects on screen.
//!
//! Edits always update the full canonical grid and its full-resolution GPU mirror; the level of
//! detail only picks a cached strided index buffer over those vertices ([`GridStride`]), so
//! changing it copies nothing. Per direction, a surface is drawn with the largest power-of-two
//! stride `s ≤ MAX_STRIDE` for which, on screen,
//!
//! * every sample skipped lies within [`LodTolerance::error_px`] of the chord the coarse mesh
//!   draws instead (so silhouettes and occlusion edges move by less than that), and
//! * no cell edge is longer than [`LodTolerance::max_edge_px`] (so shading, interpolated from
//!   exact normals at the drawn vertices, stays smooth).
//!
//! Both are bounded from world-space measures of the grid ([`GridMetrics`]: the largest
//! distance of a skipped sample from its chord, for each stride, and the largest spacing of
//! adjacent samples), computed once per change of the samples, times the largest number of
//! pixels a world unit covers anywhere in the grid's bounding box for the current view — so
//! choosing strides for a new view costs eight projections per object, not a pass over its
//! samples. A 512² surface filling a 1280×720 window is drawn with a few tens of thousands of
//! triangles instead of half a million, which is what a software rasteriser needs; flat parts
//! coarsen more than curved ones.

use crate::gpu::GridStride;
use crate::sampling::SampleGrid;
use glam::{DMat4, DVec3, DVec4};

/// Largest stride ever chosen (a 17 × 17 Bézier patch then shrinks to its outer quad).
pub const MAX_STRIDE: u32 = 16;
/// Strides measured: 2, 4, …, `MAX_STRIDE`.
const STRIDES: usize = MAX_STRIDE.trailing_zeros() as usize;
/// Probe lines per direction at most when measuring a grid (every `q`-th row or column, and
/// the last): bounds the cost of re-measuring a large grid after each edit.
const MAX_PROBES: usize = 33;

/// How far the coarse mesh may depart from the full one on screen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LodTolerance {
    /// Largest screen distance, in pixels, of a skipped sample from the drawn mesh.
    pub error_px: f64,
    /// Longest screen-space cell edge in pixels.
    pub max_edge_px: f64,
}

impl LodTolerance {
    /// The default for an image with `samples` MSAA samples per pixel, chosen by measurement
    /// (docs/performance.md, "Display level of detail"): one pixel without multisampling, where
    /// a pixel is either covered or not, and a quarter pixel with 4× MSAA, whose coverage steps
    /// are that fine; cells up to 32 pixels. At the default views the image stays within the
    /// golden-image tolerance of the full draw.
    #[must_use]
    pub fn for_samples(samples: u32) -> Self {
        Self {
            error_px: 1.0 / f64::from(samples.clamp(1, 4)),
            max_edge_px: 32.0,
        }
    }
}

/// How an image is projected, for choosing strides.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lod {
    /// Projection × view of the image (depth in [0, 1], y up).
    pub view_proj: DMat4,
    /// Viewport size in pixels.
    pub viewport: [f64; 2],
    /// `None` draws every sample.
    pub tolerance: Option<LodTolerance>,
}

/// World-space measures of a sample grid that bound how far strided meshes depart from it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridMetrics {
    /// Per direction (rows, columns): the largest distance between adjacent samples.
    spacing: [f64; 2],
    /// Per direction and stride `2^(k+1)`: the largest distance of a skipped sample from the
    /// chord between the drawn samples around it.
    deviation: [[f64; STRIDES]; 2],
    /// Bounding box of all samples.
    min: DVec3,
    max: DVec3,
    /// Samples per direction.
    dims: [usize; 2],
}

impl GridMetrics {
    /// Measures `grid` on probe lines (every row and column of small grids, at most
    /// `MAX_PROBES` of each for large ones). `None` when a sample is not finite.
    #[must_use]
    pub fn new(grid: &SampleGrid) -> Option<Self> {
        let [rows, cols] = grid.dims;
        if rows < 2 || cols < 2 {
            return None;
        }
        let (mut min, mut max) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for &p in grid.data.iter().step_by(grid.stride()) {
            if !p.is_finite() {
                return None;
            }
            min = min.min(p);
            max = max.max(p);
        }
        let at = |i: usize, j: usize| grid.position(i, j);
        let mut m = Self {
            spacing: [0.0; 2],
            deviation: [[0.0; STRIDES]; 2],
            min,
            max,
            dims: grid.dims,
        };
        // Along the rows direction (index i varies) on probe columns, and vice versa.
        let mut line = Vec::with_capacity(rows.max(cols));
        for j in probe_lines(cols) {
            line.clear();
            line.extend((0..rows).map(|i| at(i, j)));
            measure_line(&line, &mut m.spacing[0], &mut m.deviation[0]);
        }
        for i in probe_lines(rows) {
            line.clear();
            line.extend((0..cols).map(|j| at(i, j)));
            measure_line(&line, &mut m.spacing[1], &mut m.deviation[1]);
        }
        Some(m)
    }
}

/// Largest spacing and, per stride, largest chord deviation along one line of samples.
///
/// Maxima are taken over squared distances and rooted once: the square root is monotone and
/// correctly rounded, so the result is bit for bit the maximum of the distances, without a
/// root per sample (this runs over every sample of every small patch when a scene loads).
fn measure_line(points: &[DVec3], spacing: &mut f64, deviation: &mut [f64; STRIDES]) {
    let n = points.len();
    let widest = points
        .windows(2)
        .fold(0.0f64, |m, w| m.max(w[0].distance_squared(w[1])));
    *spacing = spacing.max(widest.sqrt());
    for (k, dev) in deviation.iter_mut().enumerate() {
        let s = 2usize << k;
        let mut farthest = 0.0f64;
        // The chords of a stride-`s` mesh: between drawn samples 0, s, 2s, … and n − 1.
        let mut a = 0;
        while a + 1 < n {
            let b = (a + s).min(n - 1);
            for (m, q) in points.iter().enumerate().take(b).skip(a + 1) {
                let t = (m - a) as f64 / (b - a) as f64;
                farthest = farthest.max(q.distance_squared(points[a].lerp(points[b], t)));
            }
            a = b;
        }
        *dev = dev.max(farthest.sqrt());
    }
}

/// The indices `0, s, 2s, …` and `n − 1` that a stride-`s` mesh draws.
fn strided(n: usize, s: usize) -> Vec<usize> {
    let mut v: Vec<usize> = (0..n).step_by(s.max(1)).collect();
    if n > 0 && v.last() != Some(&(n - 1)) {
        v.push(n - 1);
    }
    v
}

/// Every `q`-th line of `n` and the last, at most about `MAX_PROBES`.
fn probe_lines(n: usize) -> Vec<usize> {
    let q = n.saturating_sub(1).div_ceil(MAX_PROBES - 1).max(1);
    strided(n, q)
}

impl Lod {
    /// Strides for an image of `viewport` pixels with `samples` MSAA samples projected by
    /// `view_proj`, at the default tolerance ([`LodTolerance::for_samples`]).
    #[must_use]
    pub fn new(view_proj: DMat4, viewport: [f64; 2], samples: u32) -> Self {
        Self {
            view_proj,
            viewport,
            tolerance: Some(LodTolerance::for_samples(samples)),
        }
    }

    /// The strides for a grid measured as `metrics` (see the module docs). A grid whose
    /// bounding box reaches behind the eye, or that was not measurable, is drawn in full.
    #[must_use]
    pub fn stride(&self, metrics: Option<&GridMetrics>) -> GridStride {
        self.stride_within(metrics, 1.0)
    }

    /// [`Lod::stride`] with the deviation allowed scaled by `factor` (≤ 1): trimmed faces of a
    /// solid share their edges with other faces, each coarsened on its own, so that their
    /// departures add up to less than a pixel at a seam they draw at a quarter of it.
    #[must_use]
    pub fn stride_within(&self, metrics: Option<&GridMetrics>, factor: f64) -> GridStride {
        let (Some(tol), Some(m)) = (self.tolerance, metrics) else {
            return GridStride::FULL;
        };
        let Some(scale) = self.pixels_per_unit(m.min, m.max) else {
            return GridStride::FULL;
        };
        let pick = |d: usize| {
            // Beyond the next power of two of the grid's span a stride draws the same mesh.
            let reach = m.dims[d].saturating_sub(1).max(1).next_power_of_two();
            let mut s = 1u32;
            for (k, &dev) in m.deviation[d].iter().enumerate() {
                let next = 2u32 << k;
                if next as usize > reach {
                    break;
                }
                let ok = dev * scale <= tol.error_px * factor
                    && f64::from(next) * m.spacing[d] * scale <= tol.max_edge_px;
                if !ok {
                    break;
                }
                s = next;
            }
            s
        };
        GridStride {
            rows: pick(0),
            cols: pick(1),
        }
    }

    /// An upper bound on the pixels one world unit covers anywhere in the box `[min, max]`:
    /// for clip coordinates `c = M p`, screen x is `c.x / c.w · W/2`, whose gradient is at most
    /// `(|row0| + |x/w| · |row3|) · W / (2 w)` and `|x/w| ≤ 1` on screen; likewise for y.
    /// `None` when the box reaches the eye plane (`w ≤ 0`) or the view is degenerate.
    fn pixels_per_unit(&self, min: DVec3, max: DVec3) -> Option<f64> {
        let m = self.view_proj;
        let row = |r: usize| DVec4::new(m.x_axis[r], m.y_axis[r], m.z_axis[r], m.w_axis[r]);
        let (r0, r1, r3) = (row(0), row(1), row(3));
        let mut w_min = f64::INFINITY;
        for k in 0..8 {
            let corner = DVec3::new(
                if k & 1 == 0 { min.x } else { max.x },
                if k & 2 == 0 { min.y } else { max.y },
                if k & 4 == 0 { min.z } else { max.z },
            );
            w_min = w_min.min(r3.dot(corner.extend(1.0)));
        }
        let [w, h] = self.viewport;
        let g = r3.truncate().length();
        let gx = (r0.truncate().length() + g) * 0.5 * w;
        let gy = (r1.truncate().length() + g) * 0.5 * h;
        let scale = gx.max(gy) / w_min;
        (w_min > 0.0 && scale.is_finite()).then_some(scale)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::PartialSet;

    fn grid(rows: usize, cols: usize, f: impl Fn(usize, usize) -> DVec3) -> SampleGrid {
        let mut g = SampleGrid::new([rows, cols], PartialSet::Square(0), false);
        for i in 0..rows {
            for j in 0..cols {
                g.sample_mut(i, j)[0] = f(i, j);
            }
        }
        g
    }

    /// A view where one world unit is one pixel at w = 1 (scale bound: (1 + 0)·W/2·(2/W) = 1).
    fn pixels(w: f64, h: f64) -> Lod {
        Lod {
            view_proj: DMat4::from_scale(DVec3::new(2.0 / w, 2.0 / h, 0.5)),
            viewport: [w, h],
            tolerance: Some(LodTolerance::for_samples(1)),
        }
    }

    #[test]
    fn flat_grids_coarsen_up_to_the_edge_limit() {
        let mut lod = pixels(1280.0, 720.0);
        lod.tolerance = Some(LodTolerance {
            error_px: 0.5,
            max_edge_px: 16.0,
        });
        // Flat, 1 px apart: no deviation; edges limit the stride to 16 (16 px ≤ 16).
        let flat = grid(513, 513, |i, j| DVec3::new(i as f64, j as f64, 0.0));
        let m = GridMetrics::new(&flat);
        assert_eq!(lod.stride(m.as_ref()), GridStride { rows: 16, cols: 16 });
        // 3 px apart: 4 × 3 = 12 ≤ 16 < 24.
        let wide = grid(65, 65, |i, j| {
            DVec3::new(3.0 * i as f64, 3.0 * j as f64, 0.0)
        });
        let m = GridMetrics::new(&wide);
        assert_eq!(lod.stride(m.as_ref()), GridStride { rows: 4, cols: 4 });
        let off = Lod {
            tolerance: None,
            ..lod
        };
        assert_eq!(off.stride(m.as_ref()), GridStride::FULL);
    }

    #[test]
    fn curvature_limits_the_stride_per_direction() {
        let mut lod = pixels(1280.0, 720.0);
        lod.tolerance = Some(LodTolerance {
            error_px: 0.5,
            max_edge_px: 16.0,
        });
        // Rows follow a circle of radius 100 px, 1 px apart along the arc; columns are straight.
        let r = 100.0;
        let g = grid(129, 9, |i, j| {
            let a = i as f64 / r;
            DVec3::new(r * a.cos(), r * a.sin(), j as f64)
        });
        let m = GridMetrics::new(&g).unwrap();
        // Sagitta of a chord over s px of arc: s² / (8 r) ≤ 0.5 ⇔ s ≤ 20: stride 16 → 0.32 px.
        assert_eq!(lod.stride(Some(&m)), GridStride { rows: 16, cols: 8 });
        let tight = Lod {
            tolerance: Some(LodTolerance {
                error_px: 0.1,
                max_edge_px: 16.0,
            }),
            ..lod
        };
        // s² / 800 ≤ 0.1 ⇔ s ≤ 8.9: stride 8.
        assert_eq!(tight.stride(Some(&m)).rows, 8);
        let dev2 = m.deviation[0][0];
        assert!((dev2 - (r - r * (1.0 / r).cos())).abs() < 1e-9, "{dev2}");
    }

    #[test]
    fn behind_the_eye_or_unmeasurable_draws_everything() {
        let mut lod = pixels(100.0, 100.0);
        // w = −1 everywhere.
        lod.view_proj = DMat4::from_cols_array(&[
            1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0,
        ]);
        let g = grid(33, 33, |i, j| {
            DVec3::new(i as f64 * 0.01, j as f64 * 0.01, 0.0)
        });
        assert_eq!(lod.stride(GridMetrics::new(&g).as_ref()), GridStride::FULL);
        let mut nan = g.clone();
        nan.sample_mut(4, 4)[0] = DVec3::NAN;
        assert!(GridMetrics::new(&nan).is_none());
        assert_eq!(pixels(100.0, 100.0).stride(None), GridStride::FULL);
    }

    #[test]
    fn probes_and_strides_cover_both_ends() {
        assert_eq!(strided(10, 4), vec![0, 4, 8, 9]);
        assert_eq!(strided(9, 4), vec![0, 4, 8]);
        assert_eq!(probe_lines(17), (0..17).collect::<Vec<_>>());
        let big = probe_lines(512);
        assert!(big.len() <= MAX_PROBES + 1 && *big.last().unwrap() == 511);
    }
}
