//! Where a draw's data lies inside a mirror: a grid surface, a batch of surfaces of one
//! shape, a run of points. Offsets and strides are in f32 elements.

use super::error::{GpuError, GpuResult};
use super::grid::{GridShape, GridStride};
use super::mirror::Mirror;

/// A surface's vertices inside a mirror: `shape.rows × shape.cols` vertices of 6 floats
/// (position xyz, normal xyz), row-major, starting at float `offset`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SurfaceGrid {
    /// Float offset of vertex (0, 0).
    pub offset: usize,
    /// Grid shape.
    pub shape: GridShape,
}

impl SurfaceGrid {
    /// Floats per surface vertex.
    pub const FLOATS_PER_VERTEX: usize = 6;

    /// Number of floats the grid occupies.
    #[must_use]
    pub fn floats(&self) -> usize {
        self.shape.vertices() as usize * Self::FLOATS_PER_VERTEX
    }
}

/// Surfaces of one grid shape, each at its own float offset in one mirror, drawn with one
/// stride in one call: many small patches (a teapot's 32, a scene's thousands) cost one
/// multi-draw (`VK_EXT_multi_draw`) instead of a draw each, and surfaces stored back to back
/// (each offset the previous one's end) are a single range of a repeated index buffer
/// within it. Offsets must be congruent modulo [`SurfaceGrid::FLOATS_PER_VERTEX`] (vertices
/// of one mirror bound once).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SurfaceBatch<'a> {
    /// Shape shared by every surface.
    pub shape: GridShape,
    /// Rows and columns drawn (display level of detail).
    pub stride: GridStride,
    /// Float offset of each surface's vertex (0, 0).
    pub offsets: &'a [usize],
    /// The coverage mask every fragment is tested against (a trimmed surface: the batch holds
    /// that one surface), `None` for surfaces drawn whole.
    pub mask: Option<MaskRef<'a>>,
}

/// A per-fragment coverage mask in grid coordinates: entry `entry` of `table`, a mirror of
/// `uvec4`s written as f32 bits — the device address of the mask's words (low, high), the
/// vertices per grid row, and the surface's first vertex in the mirror its vertices are
/// bound from (`shaders/trim.glsl` reads the words).
#[derive(Clone, Copy)]
pub struct MaskRef<'a> {
    pub table: &'a Mirror,
    pub entry: u32,
}

impl std::fmt::Debug for MaskRef<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "MaskRef {{ entry: {} }}", self.entry)
    }
}

impl PartialEq for MaskRef<'_> {
    fn eq(&self, other: &Self) -> bool {
        std::ptr::eq(self.table, other.table) && self.entry == other.entry
    }
}

impl Eq for MaskRef<'_> {}

impl MaskRef<'_> {
    /// Floats per table entry.
    pub const FLOATS: usize = 4;

    /// Checks the entry against the table and that the batch is one surface.
    pub(crate) fn check(&self, surfaces: usize) -> GpuResult<()> {
        let entries = self.table.len() / Self::FLOATS;
        if self.entry as usize >= entries || surfaces != 1 {
            return Err(GpuError::InvalidArgument(format!(
                "coverage mask {} of {entries} for a batch of {surfaces} surfaces (one expected)",
                self.entry
            )));
        }
        Ok(())
    }
}

impl SurfaceBatch<'_> {
    /// Checks the batch against a mirror of `mirror_len` floats; returns the byte offset to
    /// bind the vertices at and the batch's runs: (vertex offset from there, number of
    /// surfaces stored back to back, at most [`GridShape::run_cap`] each).
    pub(crate) fn runs(&self, mirror_len: usize) -> GpuResult<(u64, Vec<(i32, u32)>)> {
        let batch = self;
        batch.shape.validate()?;
        let per = SurfaceGrid::FLOATS_PER_VERTEX;
        let floats = SurfaceGrid {
            offset: 0,
            shape: batch.shape,
        }
        .floats();
        let residue = batch.offsets.first().map_or(0, |o| o % per);
        let cap = batch.shape.run_cap();
        let mut runs: Vec<(i32, u32)> = Vec::with_capacity(batch.offsets.len());
        let mut next = None;
        for &offset in batch.offsets {
            let fits = offset
                .checked_add(floats)
                .is_some_and(|end| end <= mirror_len);
            let vertex = i32::try_from((offset - offset % per) / per).ok();
            match vertex {
                Some(v) if fits && offset % per == residue => {
                    match runs.last_mut() {
                        // Right after the previous surface: the same run, up to the cap.
                        Some(run) if next == Some(offset) && run.1 < cap => run.1 += 1,
                        _ => runs.push((v, 1)),
                    }
                    next = Some(offset + floats);
                }
                _ => {
                    return Err(GpuError::InvalidArgument(format!(
                        "surface grid {}x{} at float {offset} does not fit a mirror of {} \
                         floats (or its offset is not {residue} modulo {per})",
                        batch.shape.rows, batch.shape.cols, mirror_len
                    )));
                }
            }
        }
        Ok((residue as u64 * 4, runs))
    }
}

/// A run of points inside a float buffer: point `i` is `xyz` at floats
/// `offset + i*stride ..+3`. Covers tight runs (stride 3), the positions of surface vertices
/// (stride 6) and columns of row-major grids (stride = row length × floats per vertex).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PointRun {
    /// Float offset of point 0.
    pub offset: usize,
    /// Floats between consecutive points (≥ 3).
    pub stride: usize,
    /// Number of points.
    pub count: usize,
}

impl PointRun {
    /// `count` tightly packed xyz points starting at point index `first`.
    #[must_use]
    pub fn packed(first: usize, count: usize) -> Self {
        Self {
            offset: first * 3,
            stride: 3,
            count,
        }
    }

    /// Row `row` of a row-major grid of `cols` points with `floats_per_point` floats each,
    /// starting at float `base`.
    #[must_use]
    pub fn grid_row(base: usize, cols: usize, floats_per_point: usize, row: usize) -> Self {
        Self {
            offset: base + row * cols * floats_per_point,
            stride: floats_per_point,
            count: cols,
        }
    }

    /// Column `col` of a row-major grid of `rows × cols` points (no copy: strided access).
    #[must_use]
    pub fn grid_column(
        base: usize,
        rows: usize,
        cols: usize,
        floats_per_point: usize,
        col: usize,
    ) -> Self {
        Self {
            offset: base + col * floats_per_point,
            stride: cols * floats_per_point,
            count: rows,
        }
    }

    pub(crate) fn check(&self, len: usize, min_count: usize) -> GpuResult<()> {
        // One past the last float read; the shader's u32 index arithmetic stays below it.
        let end = self
            .count
            .checked_sub(1)
            .and_then(|n| n.checked_mul(self.stride))
            .and_then(|n| n.checked_add(self.offset))
            .and_then(|n| n.checked_add(3));
        let ok = self.count >= min_count.max(1)
            && self.stride >= 3
            && end.is_some_and(|end| end <= len && u32::try_from(end).is_ok());
        if ok {
            Ok(())
        } else {
            Err(GpuError::InvalidArgument(format!(
                "point run {self:?} does not fit a buffer of {len} floats \
                 (or has fewer than {min_count} points / stride < 3)"
            )))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_of_surfaces_stored_back_to_back_stop_at_the_cap() {
        let shape = GridShape { rows: 17, cols: 17 };
        let floats = 17 * 17 * SurfaceGrid::FLOATS_PER_VERTEX;
        let cap = shape.run_cap();
        assert_eq!(cap, (1 << 16) / 289);
        // 500 patches back to back, then one after a gap.
        let mut offsets: Vec<usize> = (0..500).map(|k| k * floats).collect();
        offsets.push(501 * floats);
        let batch = SurfaceBatch {
            shape,
            stride: GridStride::FULL,
            offsets: &offsets,
            mask: None,
        };
        let (base, runs) = batch.runs(502 * floats).unwrap();
        assert_eq!(base, 0);
        let c = cap as i32;
        assert_eq!(
            runs,
            vec![
                (0, cap),
                (c * 289, cap),
                (2 * c * 289, 500 - 2 * cap),
                (501 * 289, 1)
            ]
        );
        // A grid larger than the run length is a run of its own.
        let big = GridShape {
            rows: 512,
            cols: 512,
        };
        assert_eq!(big.run_cap(), 1);
    }
}
