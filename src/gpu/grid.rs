//! Static index buffers for row-major sample grids, cached by shape.
//!
//! A grid of `rows × cols` vertices stores vertex `(i, j)` at index `i * cols + j`. Triangles
//! cover every cell; isolines run along every `every`-th row and column, always including the
//! last ones so the boundary is closed (`every == 1` is the full wireframe).

use std::collections::HashMap;
use std::collections::hash_map::Entry;

use ash::vk;

use super::device::Device;
use super::error::{GpuError, GpuResult};
use super::memory::Buffer;
use super::pod::slice_bytes;
use super::upload::Uploader;

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
    pub fn vertices(self) -> u64 {
        u64::from(self.rows) * u64::from(self.cols)
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

/// Triangle-list indices for all cells, two triangles per cell.
pub fn grid_triangles(shape: GridShape) -> Vec<u32> {
    let (rows, cols) = (shape.rows, shape.cols);
    let mut out =
        Vec::with_capacity((rows.saturating_sub(1) * cols.saturating_sub(1) * 6) as usize);
    for i in 0..rows.saturating_sub(1) {
        for j in 0..cols.saturating_sub(1) {
            let a = i * cols + j;
            let b = a + 1;
            let c = a + cols;
            let d = c + 1;
            out.extend_from_slice(&[a, c, b, b, c, d]);
        }
    }
    out
}

/// The rows (or columns) `0, every, 2*every, ...` plus `n - 1`.
fn iso_lines(n: u32, every: u32) -> impl Iterator<Item = u32> {
    let every = every.max(1);
    (0..n)
        .step_by(every as usize)
        .chain((!(n - 1).is_multiple_of(every)).then_some(n - 1))
}

/// Line-list indices for isolines every `every` samples in both directions.
pub fn grid_lines(shape: GridShape, every: u32) -> Vec<u32> {
    let (rows, cols) = (shape.rows, shape.cols);
    let mut out = Vec::new();
    if rows == 0 || cols == 0 {
        return out;
    }
    for i in iso_lines(rows, every) {
        for j in 0..cols - 1 {
            out.extend_from_slice(&[i * cols + j, i * cols + j + 1]);
        }
    }
    for j in iso_lines(cols, every) {
        for i in 0..rows - 1 {
            out.extend_from_slice(&[i * cols + j, (i + 1) * cols + j]);
        }
    }
    out
}

/// A cached index buffer and its index count.
pub(crate) struct IndexBuffer {
    pub buffer: Buffer,
    pub count: u32,
}

/// Index buffers by shape (triangles) and by shape + spacing (lines).
#[derive(Default)]
pub(crate) struct GridCache {
    triangles: HashMap<GridShape, IndexBuffer>,
    lines: HashMap<(GridShape, u32), IndexBuffer>,
}

fn upload_indices(
    device: &Device,
    uploader: &mut Uploader,
    name: &str,
    indices: &[u32],
) -> GpuResult<IndexBuffer> {
    let buffer = uploader.upload(
        device,
        name,
        slice_bytes(indices),
        vk::BufferUsageFlags::INDEX_BUFFER,
        vk::PipelineStageFlags2::INDEX_INPUT,
        vk::AccessFlags2::INDEX_READ,
    )?;
    Ok(IndexBuffer {
        buffer,
        count: indices.len() as u32,
    })
}

impl GridCache {
    pub(crate) fn triangles(
        &mut self,
        device: &Device,
        uploader: &mut Uploader,
        shape: GridShape,
    ) -> GpuResult<&IndexBuffer> {
        shape.validate()?;
        Ok(match self.triangles.entry(shape) {
            Entry::Occupied(e) => e.into_mut(),
            Entry::Vacant(e) => e.insert(upload_indices(
                device,
                uploader,
                "grid triangles",
                &grid_triangles(shape),
            )?),
        })
    }

    pub(crate) fn lines(
        &mut self,
        device: &Device,
        uploader: &mut Uploader,
        shape: GridShape,
        every: u32,
    ) -> GpuResult<&IndexBuffer> {
        shape.validate()?;
        let key = (shape, every.max(1));
        Ok(match self.lines.entry(key) {
            Entry::Occupied(e) => e.into_mut(),
            Entry::Vacant(e) => e.insert(upload_indices(
                device,
                uploader,
                "grid lines",
                &grid_lines(shape, key.1),
            )?),
        })
    }

    pub(crate) fn destroy(self, device: &Device) {
        for ib in self.triangles.into_values().chain(self.lines.into_values()) {
            device.destroy_buffer(ib.buffer);
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
}
