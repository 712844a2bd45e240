//! Static index buffers for row-major sample grids, cached by shape and stride.
//!
//! A grid of `rows × cols` vertices stores vertex `(i, j)` at index `i * cols + j`. Triangles
//! cover every cell; isolines run along every `every`-th row and column, always including the
//! last ones so the boundary is closed (`every == 1` is the full wireframe).
//!
//! A [`GridStride`] draws a coarser mesh over the same vertices (display level of detail):
//! every `rows`-th row and `cols`-th column, plus the last ones, so the boundary and the
//! corners are those of the full grid. Changing the stride binds another cached index buffer;
//! the vertex data is never touched.

use std::collections::HashMap;
use std::collections::hash_map::Entry;

use ash::vk;

use super::device::Device;
use super::error::{GpuError, GpuResult};
use super::memory::Buffer;
use super::pod::slice_bytes;
use super::upload::Uploader;

/// Vertices one entry of a batch's multi-draw covers at most (see [`GridShape::run_cap`]):
/// large enough that llvmpipe's per-draw cost vanishes against the triangles drawn, small
/// enough that the repeated index buffers stay a few MiB per shape.
pub const RUN_VERTICES: u64 = 1 << 16;

/// Shape of a row-major vertex grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct GridShape {
    /// Number of rows (first index).
    pub rows: u32,
    /// Number of vertices per row.
    pub cols: u32,
}

impl GridShape {
    /// Number of vertices.
    #[must_use]
    pub fn vertices(self) -> u64 {
        u64::from(self.rows) * u64::from(self.cols)
    }

    /// The most grids of this shape one draw covers as a single index range. A run of
    /// surfaces stored back to back draws from a cached buffer of repeated copies of the
    /// grid's indices; uncapped, that buffer grew with the scene (80 bytes of indices and
    /// staging per sample on 32 × 32 teapots, as much as the vertex mirrors). Capped at about
    /// [`RUN_VERTICES`] vertices, a longer run becomes several entries of the same multi-draw,
    /// and the buffer's size no longer depends on the scene.
    #[must_use]
    pub fn run_cap(self) -> u32 {
        u32::try_from((RUN_VERTICES / self.vertices().max(1)).max(1)).unwrap_or(u32::MAX)
    }

    pub(crate) fn validate(self) -> GpuResult<()> {
        if self.rows < 2 || self.cols < 2 || self.vertices() > u64::from(u32::MAX) {
            return Err(GpuError::InvalidArgument(format!(
                "grid {}x{}: need at least 2x2 and fewer than 2^32 vertices",
                self.rows, self.cols
            )));
        }
        Ok(())
    }
}

/// Which rows and columns of a grid a draw uses: every `rows`-th row and every `cols`-th
/// column, plus the last row and column (display level of detail; `1 × 1` is the full grid).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct GridStride {
    /// Step between drawn rows (≥ 1).
    pub rows: u32,
    /// Step between drawn columns (≥ 1).
    pub cols: u32,
}

impl GridStride {
    /// Every row and column.
    pub const FULL: Self = Self { rows: 1, cols: 1 };

    /// Zero steps count as 1.
    #[must_use]
    pub fn normalized(self) -> Self {
        Self {
            rows: self.rows.max(1),
            cols: self.cols.max(1),
        }
    }

    /// Cells (quads) of the strided mesh over `shape`.
    #[must_use]
    pub fn cells(self, shape: GridShape) -> u64 {
        let s = self.normalized();
        let n = |count: u32, step: u32| u64::from(count.saturating_sub(1).div_ceil(step));
        n(shape.rows, s.rows) * n(shape.cols, s.cols)
    }
}

impl Default for GridStride {
    fn default() -> Self {
        Self::FULL
    }
}

/// Triangle-list indices for all cells, two triangles per cell.
#[must_use]
pub fn grid_triangles(shape: GridShape) -> Vec<u32> {
    grid_triangles_strided(shape, GridStride::FULL)
}

/// Triangle-list indices for the cells of the strided mesh (see [`GridStride`]).
#[must_use]
pub fn grid_triangles_strided(shape: GridShape, stride: GridStride) -> Vec<u32> {
    let stride = stride.normalized();
    let cols = shape.cols;
    let rows: Vec<u32> = iso_lines(shape.rows, stride.rows).collect();
    let cs: Vec<u32> = iso_lines(shape.cols, stride.cols).collect();
    let mut out = Vec::with_capacity(rows.len().saturating_sub(1) * cs.len().saturating_sub(1) * 6);
    for r in rows.windows(2) {
        for c in cs.windows(2) {
            let a = r[0] * cols + c[0];
            let b = r[0] * cols + c[1];
            let c0 = r[1] * cols + c[0];
            let d = r[1] * cols + c[1];
            out.extend_from_slice(&[a, c0, b, b, c0, d]);
        }
    }
    out
}

/// The rows (or columns) `0, every, 2*every, ...` plus `n - 1` (nothing for `n == 0`).
fn iso_lines(n: u32, every: u32) -> impl Iterator<Item = u32> {
    let every = every.max(1);
    let last = n.checked_sub(1);
    (0..n)
        .step_by(every as usize)
        .chain(last.filter(|l| !l.is_multiple_of(every)))
}

/// Line-list indices for isolines every `every` samples in both directions.
#[must_use]
pub fn grid_lines(shape: GridShape, every: u32) -> Vec<u32> {
    grid_lines_strided(shape, every, GridStride::FULL)
}

/// Isolines over the strided mesh: lines lie on rows and columns the mesh draws (the spacing
/// `every` is rounded up to a multiple of the stride) and follow the mesh's edges, so they sit
/// exactly on its triangles.
#[must_use]
pub fn grid_lines_strided(shape: GridShape, every: u32, stride: GridStride) -> Vec<u32> {
    let stride = stride.normalized();
    let (rows, cols) = (shape.rows, shape.cols);
    let mut out = Vec::new();
    if rows == 0 || cols == 0 {
        return out;
    }
    let along = |n: u32, step: u32| iso_lines(n, step).collect::<Vec<u32>>();
    let round_up = |every: u32, step: u32| every.max(1).div_ceil(step) * step;
    let (row_pts, col_pts) = (along(rows, stride.rows), along(cols, stride.cols));
    for i in iso_lines(rows, round_up(every, stride.rows)) {
        for w in col_pts.windows(2) {
            out.extend_from_slice(&[i * cols + w[0], i * cols + w[1]]);
        }
    }
    for j in iso_lines(cols, round_up(every, stride.cols)) {
        for w in row_pts.windows(2) {
            out.extend_from_slice(&[w[0] * cols + j, w[1] * cols + j]);
        }
    }
    out
}

/// A cached index buffer: `copies` back-to-back copies of one grid's `count` indices, copy
/// `k` offset by `k` grids' vertices, so a run of `n ≤ copies` surfaces stored back to back
/// draws as one range of `n · count` indices.
pub(crate) struct IndexBuffer {
    pub buffer: Buffer,
    pub count: u32,
    pub copies: u32,
}

/// `pattern` repeated for `copies` grids of `vertices` vertices each, stored back to back.
fn repeated(pattern: &[u32], vertices: u32, copies: u32) -> Vec<u32> {
    let mut out = Vec::with_capacity(pattern.len() * copies as usize);
    for k in 0..copies {
        out.extend(pattern.iter().map(|&i| i + k * vertices));
    }
    out
}

/// The copies to build for a run of `needed` grids: the next power of two (so a cache entry
/// is rebuilt at most log₂ times), as long as every index stays below 2³².
fn copies_for(shape: GridShape, needed: u32) -> GpuResult<u32> {
    let fits = |c: u32| shape.vertices() * u64::from(c) <= u64::from(u32::MAX);
    let c = needed.max(1).checked_next_power_of_two().unwrap_or(needed);
    if fits(c) {
        Ok(c)
    } else if fits(needed) {
        Ok(needed)
    } else {
        Err(GpuError::InvalidArgument(format!(
            "{needed} grids of {}x{} need more than 2^32 vertices",
            shape.rows, shape.cols
        )))
    }
}

/// Index buffers by shape + stride (triangles) and by shape + spacing + stride (lines).
#[derive(Default)]
pub(crate) struct GridCache {
    triangles: HashMap<(GridShape, GridStride), IndexBuffer>,
    lines: HashMap<(GridShape, u32, GridStride), IndexBuffer>,
}

fn upload_indices(
    device: &Device,
    uploader: &mut Uploader,
    name: &str,
    pattern: &[u32],
    vertices: u32,
    copies: u32,
) -> GpuResult<IndexBuffer> {
    let indices = repeated(pattern, vertices, copies);
    let buffer = uploader.upload(
        device,
        name,
        slice_bytes(&indices),
        vk::BufferUsageFlags::INDEX_BUFFER,
        vk::PipelineStageFlags2::INDEX_INPUT,
        vk::AccessFlags2::INDEX_READ,
    )?;
    Ok(IndexBuffer {
        buffer,
        count: pattern.len() as u32,
        copies,
    })
}

/// The cached buffer of `entry` if it holds at least `copies` copies, else a new one built by
/// `build` in its place (the old buffer goes to `release`).
fn cached<'a, K>(
    entry: Entry<'a, K, IndexBuffer>,
    copies: u32,
    release: &mut Vec<Buffer>,
    build: impl FnOnce(u32) -> GpuResult<IndexBuffer>,
) -> GpuResult<&'a IndexBuffer> {
    Ok(match entry {
        Entry::Occupied(e) if e.get().copies >= copies => e.into_mut(),
        Entry::Occupied(mut e) => {
            let old = std::mem::replace(e.get_mut(), build(copies)?);
            release.push(old.buffer);
            e.into_mut()
        }
        Entry::Vacant(e) => e.insert(build(copies)?),
    })
}

impl GridCache {
    /// Triangles of the strided mesh, for runs of up to `copies` grids stored back to back.
    /// A cached buffer too short for `copies` is replaced; the old one goes to `release`
    /// (freed once the current frame's slot is next waited for, after every earlier frame).
    pub(crate) fn triangles(
        &mut self,
        device: &Device,
        uploader: &mut Uploader,
        key: (GridShape, GridStride, u32),
        release: &mut Vec<Buffer>,
    ) -> GpuResult<&IndexBuffer> {
        let (shape, stride, copies) = key;
        shape.validate()?;
        let stride = stride.normalized();
        let build = |copies: u32, uploader: &mut Uploader| {
            let c = copies_for(shape, copies)?;
            let pattern = grid_triangles_strided(shape, stride);
            upload_indices(
                device,
                uploader,
                "grid triangles",
                &pattern,
                shape.vertices() as u32,
                c,
            )
        };
        cached(
            self.triangles.entry((shape, stride)),
            copies,
            release,
            |c| build(c, uploader),
        )
    }

    /// Isolines over the strided mesh, for runs of up to `copies` grids (see `triangles`).
    pub(crate) fn lines(
        &mut self,
        device: &Device,
        uploader: &mut Uploader,
        key: (GridShape, u32, GridStride, u32),
        release: &mut Vec<Buffer>,
    ) -> GpuResult<&IndexBuffer> {
        let (shape, every, stride, copies) = key;
        shape.validate()?;
        let key = (shape, every.max(1), stride.normalized());
        let build = |copies: u32, uploader: &mut Uploader| {
            let c = copies_for(shape, copies)?;
            let pattern = grid_lines_strided(shape, key.1, key.2);
            upload_indices(
                device,
                uploader,
                "grid lines",
                &pattern,
                shape.vertices() as u32,
                c,
            )
        };
        cached(self.lines.entry(key), copies, release, |c| {
            build(c, uploader)
        })
    }

    /// Destroys every cached index buffer.
    ///
    /// # Safety
    /// No submitted GPU work that uses these objects may still be pending (the device is idle
    /// or lost, or they were never used).
    pub(crate) unsafe fn destroy(self, device: &Device) {
        for ib in self.triangles.into_values().chain(self.lines.into_values()) {
            // SAFETY: the caller guarantees nothing pending uses them (this function's contract).
            unsafe { device.destroy_buffer(ib.buffer) };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangles_cover_cells() {
        let t = grid_triangles(GridShape { rows: 3, cols: 4 });
        assert_eq!(t.len(), 2 * 3 * 6);
        assert_eq!(&t[..6], &[0, 4, 1, 1, 4, 5]);
        assert!(t.iter().all(|&i| i < 12));
    }

    #[test]
    fn isolines_include_boundary() {
        assert_eq!(iso_lines(10, 4).collect::<Vec<_>>(), vec![0, 4, 8, 9]);
        assert_eq!(iso_lines(9, 4).collect::<Vec<_>>(), vec![0, 4, 8]);
        assert_eq!(iso_lines(3, 1).collect::<Vec<_>>(), vec![0, 1, 2]);
        let shape = GridShape { rows: 3, cols: 4 };
        // Full wireframe: 3 rows of 3 segments + 4 columns of 2 segments.
        assert_eq!(grid_lines(shape, 1).len(), 2 * (3 * 3 + 4 * 2));
        // every=2: rows 0,2 and columns 0,2,3.
        assert_eq!(grid_lines(shape, 2).len(), 2 * (2 * 3 + 3 * 2));
    }

    #[test]
    fn strided_triangles_keep_the_boundary_and_cover_the_grid() {
        let shape = GridShape { rows: 10, cols: 7 };
        let stride = GridStride { rows: 4, cols: 2 };
        let t = grid_triangles_strided(shape, stride);
        // Rows 0, 4, 8, 9 and columns 0, 2, 4, 6: 3 × 3 cells.
        assert_eq!(t.len(), 3 * 3 * 6);
        assert_eq!(stride.cells(shape), 9);
        let used: std::collections::BTreeSet<u32> = t.iter().copied().collect();
        let expect: std::collections::BTreeSet<u32> = [0, 4, 8, 9]
            .iter()
            .flat_map(|r| [0, 2, 4, 6].map(|c| r * 7 + c))
            .collect();
        assert_eq!(used, expect);
        assert_eq!(
            grid_triangles_strided(shape, GridStride::FULL),
            grid_triangles(shape)
        );
        // A stride larger than the grid still draws the outer quad.
        let big = GridStride { rows: 64, cols: 64 };
        assert_eq!(
            grid_triangles_strided(shape, big),
            vec![0, 63, 6, 6, 63, 69]
        );
    }

    #[test]
    fn copies_index_consecutive_grids() {
        let shape = GridShape { rows: 2, cols: 2 };
        let one = grid_triangles(shape);
        let three = repeated(&one, 4, 3);
        assert_eq!(three.len(), 3 * one.len());
        assert_eq!(&three[6..12], &[4, 6, 5, 5, 6, 7]);
        assert_eq!(copies_for(shape, 3).unwrap(), 4);
        assert_eq!(copies_for(shape, 0).unwrap(), 1);
        let big = GridShape {
            rows: 65536,
            cols: 32768,
        };
        assert_eq!(copies_for(big, 1).unwrap(), 1);
        assert!(copies_for(big, 2).is_err());
    }

    #[test]
    fn strided_isolines_follow_the_strided_mesh() {
        let shape = GridShape { rows: 9, cols: 9 };
        let stride = GridStride { rows: 2, cols: 2 };
        // every = 3 rounds up to 4: lines on rows/columns 0, 4, 8, each of 4 segments.
        let l = grid_lines_strided(shape, 3, stride);
        assert_eq!(l.len(), 2 * (3 * 4 + 3 * 4));
        let tri: std::collections::BTreeSet<u32> =
            grid_triangles_strided(shape, stride).into_iter().collect();
        assert!(
            l.iter().all(|i| tri.contains(i)),
            "isolines use mesh vertices only"
        );
        assert_eq!(
            grid_lines_strided(shape, 1, GridStride::FULL),
            grid_lines(shape, 1)
        );
    }
}
