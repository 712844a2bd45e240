//! Coverage of a uniform sample grid by the trimmed domain, computed once per structure: which
//! samples are inside, which cells are inside, outside or crossed by the boundary, and a packed
//! form of the crossed cells for a fragment shader.
//!
//! * Samples: one sweep per grid row. The row's crossings with the boundary come from the same
//!   slab and the same `crossing` function (`regions.rs`) as [`TrimRegions::contains`], sorted
//!   by u; walking the samples from the right accumulates the
//!   winding number, so every sample agrees exactly with `contains`.
//! * Cells: each boundary segment visits the cells it passes within [`EPS`] grid units of (the
//!   column-by-column Amanatides–Woo traversal of `grid.rs`); a visited cell is `Boundary`
//!   and keeps the segments, every other cell has no boundary on it and takes the class of its
//!   corner sample. Cost: linear in cells plus segment–cell incidences.
//!
//! # Packed GPU layout
//!
//! The shader knows only the fragment's grid coordinates `g = ((u - u0)/du, (v - v0)/dv)`:
//! `cell = clamp(floor(g), 0, (mu - 2, mv - 2))`, `local = g - cell` in `[0, 1]²`.
//!
//! * `cells: [u32]`, one word per cell, index `cell.x * (mv - 1) + cell.y`: `word & 3` is
//!   [`CELL_OUTSIDE`] (discard), [`CELL_INSIDE`] (keep) or [`CELL_BOUNDARY`], and then
//!   `word >> 2` indexes `records`.
//! * `records: [uvec4]`, one per boundary cell: `x` = first segment, `y >> 1` = segment count,
//!   `y & 1` = whether the reference point is inside, `z`, `w` = the reference point in
//!   cell-local coordinates (`floatBitsToUint`).
//! * `segments: [vec4]` = `(a.x, a.y, b.x, b.y)` in cell-local coordinates (f32), clipped to
//!   `[-1/16, 17/16]²`, so their precision does not depend on the domain's magnitude or the
//!   cell's position.
//!
//! The fragment is inside iff the reference point's flag XOR the parity of crossings of the
//! straight path `local → reference` with the cell's segments; [`Coverage::fragment_inside`] is
//! the shader on the CPU, in f32, operation for operation. The reference point is the candidate of
//! a lattice farthest from every segment, so the rounding of the path's far end never matters.
//! In GLSL (`ncell = (mu - 1, mv - 1)`):
//!
//! ```text
//! ivec2 c = clamp(ivec2(floor(g)), ivec2(0), ncell - 1);
//! vec2 p = g - vec2(c);
//! uint word = cells[c.x * ncell.y + c.y];
//! if ((word & 3u) != 2u) return (word & 3u) == 1u;          // inside: keep, outside: discard
//! uvec4 r = records[word >> 2];
//! vec2 q = uintBitsToFloat(r.zw);
//! bool inside = (r.y & 1u) != 0u;
//! for (uint k = r.x; k < r.x + (r.y >> 1); k++) {
//!     vec4 s = segments[k];
//!     float ex = s.z - s.x, ey = s.w - s.y, fx = q.x - p.x, fy = q.y - p.y;
//!     precise float d1 = ex * (p.y - s.y) - ey * (p.x - s.x);
//!     precise float d2 = ex * (q.y - s.y) - ey * (q.x - s.x);
//!     precise float d3 = fx * (s.y - p.y) - fy * (s.x - p.x);
//!     precise float d4 = fx * (s.w - p.y) - fy * (s.z - p.x);
//!     if (((d1 > 0.0) != (d2 > 0.0)) && ((d3 > 0.0) != (d4 > 0.0))) inside = !inside;
//! }
//! return inside;
//! ```
//!
//! Precision: the stored geometry is exact to ~1e-7 cell units; what limits the test is `g`
//! itself, an f32 of magnitude up to the grid size (~`g`·6e-8 grid units: 3e-5 at 512 cells).

use glam::DVec2;

use super::curve::point_segment_distance;
use super::error::TrimError;
use super::grid::for_each_cell;
use super::regions::TrimRegions;

/// Cell word: no boundary within the cell, outside the trimmed domain.
pub const CELL_OUTSIDE: u32 = 0;
/// Cell word: no boundary within the cell, inside the trimmed domain.
pub const CELL_INSIDE: u32 = 1;
/// Cell word tag (low 2 bits): the boundary passes through; `word >> 2` is the record index.
pub const CELL_BOUNDARY: u32 = 2;

/// Margin, in grid units, within which a segment counts as touching a cell: well above the
/// rounding of grid coordinates, well below anything visible.
pub const EPS: f64 = 1e-6;

/// Stored segments are clipped to the cell widened by this (cell units): endpoints stay small
/// numbers, and a clipped end never lies on the cell where a path could reach it.
const CLIP_MARGIN: f64 = 1.0 / 16.0;

/// Most cells a grid may have: keeps the packed indices in 32 bits and memory bounded.
pub const MAX_CELLS: usize = 1 << 26;

/// Samples may deviate from the uniform grid by this fraction of the spacing.
const UNIFORM_TOL: f64 = 1e-8;

/// Class of one grid cell (or of a block of cells).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CellClass {
    /// Entirely outside the trimmed domain.
    Outside,
    /// Entirely inside the trimmed domain.
    Inside,
    /// The boundary passes within [`EPS`] grid units of the cell.
    Boundary,
}

/// Coverage of a uniform sample grid (see the module doc for the GPU layout).
#[derive(Clone, Debug, PartialEq)]
pub struct Coverage {
    mu: usize,
    mv: usize,
    u0: f64,
    du: f64,
    v0: f64,
    dv: f64,
    segment_count: usize,
    bounds: (DVec2, DVec2),
    inside: Vec<bool>,
    cells: Vec<u32>,
    records: Vec<[u32; 4]>,
    segments: Vec<[f32; 4]>,
    segment_ids: Vec<u32>,
}

/// `(first, spacing)` of a uniform, increasing sample axis.
fn uniform_axis(name: &str, s: &[f64]) -> Result<(f64, f64), TrimError> {
    let bad = |reason: String| Err(TrimError::BadGrid { reason });
    let (Some(&first), Some(&last)) = (s.first(), s.last()) else {
        return bad(format!("{name} has no samples"));
    };
    if s.len() < 2 || s.len() > 1 << 15 {
        return bad(format!(
            "{name} has {} samples (2 to 32768 needed)",
            s.len()
        ));
    }
    let d = (last - first) / (s.len() - 1) as f64;
    if !(first.is_finite() && last.is_finite() && d > 0.0) {
        return bad(format!("{name} is not finite and increasing"));
    }
    for (i, &x) in s.iter().enumerate() {
        let expected = first + i as f64 * d;
        let off = (x - expected).abs();
        if off.is_nan() || off > UNIFORM_TOL * d {
            return bad(format!(
                "{name}[{i}] = {x} is not on the uniform grid ({expected})"
            ));
        }
    }
    Ok((first, d))
}

impl Coverage {
    /// Coverage of the grid of samples `(u[i], v[j])` by `regions`; `u` and `v` must be uniform
    /// and increasing, with 2 to 32768 samples each.
    pub fn new(regions: &TrimRegions, u: &[f64], v: &[f64]) -> Result<Self, TrimError> {
        let (u0, du) = uniform_axis("u", u)?;
        let (v0, dv) = uniform_axis("v", v)?;
        let (mu, mv) = (u.len(), v.len());
        if (mu - 1) * (mv - 1) > MAX_CELLS {
            let reason = format!("{} x {} cells (at most {MAX_CELLS} in all)", mu - 1, mv - 1);
            return Err(TrimError::BadGrid { reason });
        }
        let mut cov = Self {
            mu,
            mv,
            u0,
            du,
            v0,
            dv,
            segment_count: regions.segment_count(),
            bounds: regions.bounds(),
            inside: sample_sweep(regions, u, v),
            cells: vec![CELL_OUTSIDE; (mu - 1) * (mv - 1)],
            records: Vec::new(),
            segments: Vec::new(),
            segment_ids: Vec::new(),
        };
        let (start, ids) = cov.bucket(regions);
        for i in 0..mu - 1 {
            for j in 0..mv - 1 {
                let cell = i * (mv - 1) + j;
                let here = ids.get(start[cell]..start[cell + 1]).unwrap_or(&[]);
                if here.is_empty() {
                    cov.cells[cell] = if cov.inside[i * mv + j] {
                        CELL_INSIDE
                    } else {
                        CELL_OUTSIDE
                    };
                } else {
                    cov.add_boundary_cell(regions, i, j, here)?;
                }
            }
        }
        Ok(cov)
    }

    /// Segment ids per cell (compressed rows over cells), from one traversal per segment.
    #[must_use]
    fn bucket(&self, regions: &TrimRegions) -> (Vec<usize>, Vec<u32>) {
        let (ncu, ncv) = (self.mu - 1, self.mv - 1);
        let mut start = vec![0usize; ncu * ncv + 1];
        let mut ids = Vec::new();
        for pass in 0..2 {
            let mut fill = start.clone();
            for id in 0..regions.segment_count() {
                let Some([a, b]) = regions.segment(id) else {
                    continue;
                };
                let (ga, gb) = (self.to_grid(a), self.to_grid(b));
                for_each_cell(ga, gb, EPS, ncu, ncv, |i, j| {
                    let cell = i * ncv + j;
                    if pass == 0 {
                        start[cell + 1] += 1;
                    } else {
                        ids[fill[cell]] = id as u32;
                        fill[cell] += 1;
                    }
                });
            }
            if pass == 0 {
                for k in 1..start.len() {
                    start[k] += start[k - 1];
                }
                ids = vec![0; start[ncu * ncv]];
            }
        }
        (start, ids)
    }

    #[must_use]
    fn to_grid(&self, p: DVec2) -> DVec2 {
        DVec2::new((p.x - self.u0) / self.du, (p.y - self.v0) / self.dv)
    }

    /// Stores cell `(i, j)`'s segments in cell-local coordinates, its reference point and record.
    fn add_boundary_cell(
        &mut self,
        regions: &TrimRegions,
        i: usize,
        j: usize,
        ids: &[u32],
    ) -> Result<(), TrimError> {
        let corner = DVec2::new(i as f64, j as f64);
        let mut local = Vec::with_capacity(ids.len());
        for &id in ids {
            let Some([a, b]) = regions.segment(id as usize) else {
                continue;
            };
            let (a, b) = (self.to_grid(a) - corner, self.to_grid(b) - corner);
            let [a, b] = clip(a, b, -CLIP_MARGIN, 1.0 + CLIP_MARGIN).unwrap_or([a, b]);
            local.push([a, b]);
            self.segments
                .push([a.x as f32, a.y as f32, b.x as f32, b.y as f32]);
            self.segment_ids.push(id);
        }
        let r = reference_point(&local);
        let at = DVec2::new(
            self.u0 + (i as f64 + r.x) * self.du,
            self.v0 + (j as f64 + r.y) * self.dv,
        );
        let flag = u32::from(regions.contains(at));
        let first = self.segments.len() - local.len();
        let (Ok(first), Ok(count), Ok(index)) = (
            u32::try_from(first),
            u32::try_from(local.len() << 1),
            u32::try_from(self.records.len() << 2),
        ) else {
            return Err(TrimError::BadGrid {
                reason: "too many boundary segments for 32-bit indices".into(),
            });
        };
        let cell = i * (self.mv - 1) + j;
        self.cells[cell] = CELL_BOUNDARY | index;
        self.records.push([
            first,
            count | flag,
            (r.x as f32).to_bits(),
            (r.y as f32).to_bits(),
        ]);
        Ok(())
    }

    /// Number of samples along u and v.
    #[must_use]
    pub fn samples(&self) -> (usize, usize) {
        (self.mu, self.mv)
    }

    /// Inside flags of all samples, row-major `i * mv + j`.
    #[must_use]
    pub fn inside(&self) -> &[bool] {
        &self.inside
    }

    /// Whether sample `(i, j)` is inside (false out of range).
    #[must_use]
    pub fn sample_inside(&self, i: usize, j: usize) -> bool {
        i < self.mu && j < self.mv && self.inside.get(i * self.mv + j).copied().unwrap_or(false)
    }

    /// Class of cell `(i, j)`, the cell from sample `(i, j)` to sample `(i+1, j+1)`; `Outside` out
    /// of range.
    #[must_use]
    pub fn cell_class(&self, i: usize, j: usize) -> CellClass {
        if i + 1 >= self.mu || j + 1 >= self.mv {
            return CellClass::Outside;
        }
        match self.cells.get(i * (self.mv - 1) + j).map(|w| w & 3) {
            Some(CELL_INSIDE) => CellClass::Inside,
            Some(CELL_BOUNDARY) => CellClass::Boundary,
            _ => CellClass::Outside,
        }
    }

    /// Ids (see [`TrimRegions::segment`]) of the boundary segments touching cell `(i, j)`.
    #[must_use]
    pub fn cell_segments(&self, i: usize, j: usize) -> &[u32] {
        self.record(i, j)
            .and_then(|r| {
                self.segment_ids
                    .get(r[0] as usize..(r[0] + (r[1] >> 1)) as usize)
            })
            .unwrap_or(&[])
    }

    #[must_use]
    fn record(&self, i: usize, j: usize) -> Option<&[u32; 4]> {
        if self.cell_class(i, j) != CellClass::Boundary {
            return None;
        }
        let word = self.cells.get(i * (self.mv - 1) + j)?;
        self.records.get((word >> 2) as usize)
    }

    /// Class of the block of `s` × `s` cells starting at cell `(i0, j0)` (cut at the grid's
    /// edge): `Inside` if all its cells are, `Outside` if all are, else `Boundary`. For a display
    /// level of detail drawing coarser cells.
    #[must_use]
    pub fn block_class(&self, i0: usize, j0: usize, s: usize) -> CellClass {
        let (i1, j1) = ((i0 + s).min(self.mu - 1), (j0 + s).min(self.mv - 1));
        let mut seen = (false, false);
        for i in i0..i1 {
            for j in j0..j1 {
                match self.cell_class(i, j) {
                    CellClass::Boundary => return CellClass::Boundary,
                    CellClass::Inside => seen.0 = true,
                    CellClass::Outside => seen.1 = true,
                }
            }
        }
        match seen {
            (true, true) => CellClass::Boundary,
            (true, false) => CellClass::Inside,
            _ => CellClass::Outside,
        }
    }

    /// [`Coverage::block_class`] of every block of `s` × `s` cells: `(blocks along u, blocks
    /// along v, classes row-major)`.
    #[must_use]
    pub fn block_classes(&self, s: usize) -> (usize, usize, Vec<CellClass>) {
        let s = s.max(1);
        let (nu, nv) = ((self.mu - 1).div_ceil(s), (self.mv - 1).div_ceil(s));
        let classes = (0..nu * nv)
            .map(|k| self.block_class(k / nv * s, k % nv * s, s))
            .collect();
        (nu, nv, classes)
    }

    /// The packed cell words (see the module doc).
    #[must_use]
    pub fn gpu_cells(&self) -> &[u32] {
        &self.cells
    }

    /// The packed boundary-cell records (see the module doc).
    #[must_use]
    pub fn gpu_records(&self) -> &[[u32; 4]] {
        &self.records
    }

    /// The packed cell-local segments (see the module doc).
    #[must_use]
    pub fn gpu_segments(&self) -> &[[f32; 4]] {
        &self.segments
    }

    /// Whether `regions` is (probably) the one this coverage was built from.
    #[must_use]
    pub(crate) fn matches(&self, regions: &TrimRegions, u: &[f64], v: &[f64]) -> bool {
        self.segment_count == regions.segment_count()
            && self.bounds == regions.bounds()
            && (self.mu, self.mv) == (u.len(), v.len())
            && u.first() == Some(&self.u0)
            && v.first() == Some(&self.v0)
    }

    /// The fragment shader's inside test on the CPU, in f32 exactly as the GLSL does it (see
    /// the module doc); `g` is the fragment's grid coordinate, in `[0, mu-1] × [0, mv-1]`.
    #[must_use]
    pub fn fragment_inside(&self, g: [f32; 2]) -> bool {
        self.fragment_inside_within(g, [[0.0; 2]; 2])
    }

    /// [`Coverage::fragment_inside`] with the drawn region grown by half a pixel: a fragment
    /// of a boundary cell outside the trim counts as inside when `reach` (pixels per grid
    /// unit, the inverse of the screen-space derivatives of `g`, column-major as GLSL's `mat2`)
    /// maps its offset from a boundary segment to less than half a pixel. So faces that share
    /// an edge overlap by a sub-pixel sliver instead of leaving pinholes where the two
    /// tessellations of the edge part, and the drawn boundary stays within half a pixel of
    /// the trim on screen, at any angle (a pixel's footprint in the grid is anisotropic).
    #[must_use]
    pub fn fragment_inside_within(&self, g: [f32; 2], reach: [[f32; 2]; 2]) -> bool {
        let (ncu, ncv) = ((self.mu - 1) as i32, (self.mv - 1) as i32);
        let cx = (g[0].floor() as i32).clamp(0, ncu - 1);
        let cy = (g[1].floor() as i32).clamp(0, ncv - 1);
        let p = [g[0] - cx as f32, g[1] - cy as f32];
        let Some(&word) = self.cells.get((cx * ncv + cy) as usize) else {
            return false;
        };
        if word & 3 != CELL_BOUNDARY {
            return word & 3 == CELL_INSIDE;
        }
        let Some(rec) = self.records.get((word >> 2) as usize) else {
            return false;
        };
        let r = [f32::from_bits(rec[2]), f32::from_bits(rec[3])];
        let mut inside = rec[1] & 1 == 1;
        let (first, count) = (rec[0] as usize, (rec[1] >> 1) as usize);
        let segments = self.segments.get(first..first + count).unwrap_or(&[]);
        for s in segments {
            if path_crosses(p, r, s) {
                inside = !inside;
            }
        }
        let grows = reach != [[0.0; 2]; 2];
        inside
            || grows
                && segments.iter().any(|s| {
                    let v = segment_offset(p, s);
                    let x = reach[0][0] * v[0] + reach[1][0] * v[1];
                    let y = reach[0][1] * v[0] + reach[1][1] * v[1];
                    x * x + y * y < 0.25
                })
    }
}

/// The vector from segment `s = (a, b)` to `p`, in f32 as the shader computes it.
#[must_use]
fn segment_offset(p: [f32; 2], s: &[f32; 4]) -> [f32; 2] {
    let (ex, ey) = (s[2] - s[0], s[3] - s[1]);
    let (qx, qy) = (p[0] - s[0], p[1] - s[1]);
    let len2 = (ex * ex + ey * ey).max(1e-30);
    let t = ((qx * ex + qy * ey) / len2).clamp(0.0, 1.0);
    [qx - ex * t, qy - ey * t]
}

/// Whether the path `p`–`r` crosses segment `s = (a, b)`, in f32 as the shader does it
/// (declare `d1`…`d4` `precise` in GLSL so no multiply-add is fused). Half-open at the segment's
/// ends (`> 0` versus `<= 0`): a path through a vertex shared by two segments counts once or
/// twice exactly as the boundary passes or bounces.
#[must_use]
fn path_crosses(p: [f32; 2], r: [f32; 2], s: &[f32; 4]) -> bool {
    let (ex, ey) = (s[2] - s[0], s[3] - s[1]);
    let d1 = ex * (p[1] - s[1]) - ey * (p[0] - s[0]);
    let d2 = ex * (r[1] - s[1]) - ey * (r[0] - s[0]);
    let (fx, fy) = (r[0] - p[0], r[1] - p[1]);
    let d3 = fx * (s[1] - p[1]) - fy * (s[0] - p[0]);
    let d4 = fx * (s[3] - p[1]) - fy * (s[2] - p[0]);
    ((d1 > 0.0) != (d2 > 0.0)) && ((d3 > 0.0) != (d4 > 0.0))
}

/// Inside flags of all samples by one sweep per row (see the module doc).
#[must_use]
fn sample_sweep(regions: &TrimRegions, u: &[f64], v: &[f64]) -> Vec<bool> {
    let (mu, mv) = (u.len(), v.len());
    let mut inside = vec![false; mu * mv];
    let mut xs = Vec::new();
    for (j, &vj) in v.iter().enumerate() {
        regions.crossings_at(vj, &mut xs);
        xs.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (mut w, mut k) = (0, xs.len());
        for i in (0..mu).rev() {
            while k > 0 && xs[k - 1].0 > u[i] {
                k -= 1;
                w += xs[k].1;
            }
            inside[i * mv + j] = w > 0 && regions.in_bounds(DVec2::new(u[i], vj));
        }
    }
    inside
}

/// Liang–Barsky clipping of `a`–`b` to the square `[lo, hi]²`; endpoints inside stay bit-exact,
/// so two segments sharing a vertex in the cell still share it.
#[must_use]
pub(crate) fn clip(a: DVec2, b: DVec2, lo: f64, hi: f64) -> Option<[DVec2; 2]> {
    let d = b - a;
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [
        (-d.x, a.x - lo),
        (d.x, hi - a.x),
        (-d.y, a.y - lo),
        (d.y, hi - a.y),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let t = q / p;
            if p < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
        }
    }
    if t0 > t1 {
        return None;
    }
    let ca = if t0 > 0.0 { a + d * t0 } else { a };
    let cb = if t1 < 1.0 { a + d * t1 } else { b };
    Some([ca, cb])
}

/// The candidate point of the unit cell farthest from every segment: the centre and the quarter
/// points first, a 4 × 4 and then a 16 × 16 lattice only while the best is close to a segment
/// (a dense boundary). All candidates are exact in f32, so the shader's reference point is the
/// one whose flag was computed.
#[must_use]
fn reference_point(segs: &[[DVec2; 2]]) -> DVec2 {
    let clearance = |p: DVec2| {
        segs.iter()
            .map(|s| point_segment_distance(p, s[0], s[1]))
            .fold(f64::INFINITY, f64::min)
    };
    let pick = |best: (f64, DVec2), p: DVec2| {
        let c = clearance(p);
        if c > best.0 { (c, p) } else { best }
    };
    let lattice = |n: u32| {
        (0..n * n)
            .map(move |k| (DVec2::new(f64::from(k / n), f64::from(k % n)) + 0.5) / f64::from(n))
    };
    let first = [
        (0.5, 0.5),
        (0.25, 0.25),
        (0.75, 0.25),
        (0.25, 0.75),
        (0.75, 0.75),
    ];
    let start = (f64::NEG_INFINITY, DVec2::splat(0.5));
    let mut best = first
        .iter()
        .map(|&(x, y)| DVec2::new(x, y))
        .fold(start, pick);
    if best.0 < 0.1 {
        best = lattice(4).fold(best, pick);
    }
    if best.0 < 1e-3 {
        best = lattice(16).fold(best, pick);
    }
    best.1
}
