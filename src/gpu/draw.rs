//! What a frame can draw: the argument types (styles, runs, vertices) and the draw calls.
//!
//! Every draw binds its pipeline and pushes its constants; vertex data comes from this
//! frame's slot of a mirror or from the frame's transient memory.

use ash::vk;
use glam::{Mat4, Vec3};

use super::error::{GpuError, GpuResult};
use super::frame::Frame;
use super::grid::GridShape;
use super::mirror::Mirror;
use super::pipeline::{
    Lines3dPush, OverlayPush, PUSH_STAGES, PointsPush, PolylinePush, SurfacePush, WirePush,
};
use super::pod::{Pod, bytes_of};
use super::transient::TransientAlloc;

/// Camera for 3D draws.
///
/// `view_proj` maps world space to Vulkan clip space with depth in `[0, 1]` and **y up**
/// (e.g. `Mat4::perspective_rh(..) * Mat4::look_at_rh(..)`): the renderer flips the viewport
/// so that the conventional y-up projection comes out upright.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Projection × view.
    pub view_proj: Mat4,
    /// Camera position in world space (lighting, two-sided shading).
    pub eye: Vec3,
}

impl Default for Camera {
    fn default() -> Self {
        Self {
            view_proj: Mat4::IDENTITY,
            eye: Vec3::new(0.0, 0.0, 1.0),
        }
    }
}

/// Shading of a grid surface. Colours are linear RGBA.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceStyle {
    /// Colour of the side the normals point to.
    pub front: [f32; 4],
    /// Colour of the other side.
    pub back: [f32; 4],
    /// Direction towards the light in world space; zero means a headlight (from the eye).
    pub light_dir: Vec3,
    /// Ambient fraction in `[0, 1]`.
    pub ambient: f32,
    /// Blinn–Phong specular exponent.
    pub shininess: f32,
}

impl Default for SurfaceStyle {
    fn default() -> Self {
        Self {
            front: [0.55, 0.62, 0.80, 1.0],
            back: [0.80, 0.45, 0.35, 1.0],
            light_dir: Vec3::ZERO,
            ambient: 0.15,
            shininess: 48.0,
        }
    }
}

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
    pub fn floats(&self) -> usize {
        self.shape.vertices() as usize * Self::FLOATS_PER_VERTEX
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
    pub fn packed(first: usize, count: usize) -> Self {
        Self {
            offset: first * 3,
            stride: 3,
            count,
        }
    }

    /// Row `row` of a row-major grid of `cols` points with `floats_per_point` floats each,
    /// starting at float `base`.
    pub fn grid_row(base: usize, cols: usize, floats_per_point: usize, row: usize) -> Self {
        Self {
            offset: base + row * cols * floats_per_point,
            stride: floats_per_point,
            count: cols,
        }
    }

    /// Column `col` of a row-major grid of `rows × cols` points (no copy: strided access).
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

    fn check(&self, len: usize, min_count: usize) -> GpuResult<()> {
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

/// Wide-line style. Colour is linear RGBA.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PolylineStyle {
    /// Linear RGBA.
    pub color: [f32; 4],
    /// Width in pixels.
    pub width: f32,
    /// Whether the line is hidden behind nearer geometry.
    pub depth_test: bool,
}

impl Default for PolylineStyle {
    fn default() -> Self {
        Self {
            color: [0.9, 0.9, 0.9, 1.0],
            width: 2.0,
            depth_test: true,
        }
    }
}

/// Control-point style. Colours are linear RGBA.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointStyle {
    /// Colour of ordinary points.
    pub color: [f32; 4],
    /// Side of the square in pixels (hovered/selected points are drawn larger).
    pub size: f32,
    /// Index (within the run) of the point under the cursor.
    pub hovered: Option<u32>,
    /// Index (within the run) of the selected point.
    pub selected: Option<u32>,
    /// Colour of the hovered point.
    pub hovered_color: [f32; 4],
    /// Colour of the selected point.
    pub selected_color: [f32; 4],
    /// Whether points are hidden behind nearer geometry.
    pub depth_test: bool,
}

impl Default for PointStyle {
    fn default() -> Self {
        Self {
            color: [0.95, 0.95, 0.95, 1.0],
            size: 8.0,
            hovered: None,
            selected: None,
            hovered_color: [1.0, 0.8, 0.1, 1.0],
            selected_color: [1.0, 0.2, 0.1, 1.0],
            depth_test: false,
        }
    }
}

/// Vertex of [`Frame::draw_lines3d`]: world position and sRGB-encoded RGBA8 colour.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LineVertex {
    /// World-space position.
    pub pos: [f32; 3],
    /// sRGB-encoded colour, straight alpha.
    pub color: [u8; 4],
}

/// Vertex of [`Frame::draw_overlay`]: pixel position (origin top-left, y down) and
/// sRGB-encoded RGBA8 colour (alpha-blended).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OverlayVertex {
    /// Pixel coordinates relative to the current viewport.
    pub pos: [f32; 2],
    /// sRGB-encoded colour, straight alpha.
    pub color: [u8; 4],
}

// SAFETY: repr(C), 12 + 4 bytes, no padding, every bit pattern valid.
unsafe impl Pod for LineVertex {}
// SAFETY: repr(C), 8 + 4 bytes, no padding, every bit pattern valid.
unsafe impl Pod for OverlayVertex {}

const _: () = {
    assert!(size_of::<LineVertex>() == 16);
    assert!(size_of::<OverlayVertex>() == 12);
};

/// Packs a linear colour into RGBA8 (for `unpackUnorm4x8` in shaders).
fn pack_unorm(c: [f32; 4]) -> u32 {
    let b = |x: f32| (x.clamp(0.0, 1.0) * 255.0 + 0.5) as u32;
    b(c[0]) | (b(c[1]) << 8) | (b(c[2]) << 16) | (b(c[3]) << 24)
}

impl Frame<'_> {
    fn bind_and_push<T: Pod>(&mut self, pipeline: vk::Pipeline, push: &T) {
        self.ensure_rendering();
        let layout = self.renderer.pipelines.layout;
        // SAFETY: recording inside a rendering scope; the push struct fits the layout range.
        unsafe {
            let raw = &self.renderer.device.raw;
            raw.cmd_bind_pipeline(self.cmd, vk::PipelineBindPoint::GRAPHICS, pipeline);
            raw.cmd_push_constants(self.cmd, layout, PUSH_STAGES, 0, bytes_of(push));
        }
    }

    fn view_proj(&self) -> [f32; 16] {
        self.camera.view_proj.to_cols_array()
    }

    fn viewport_size(&self) -> [f32; 2] {
        [
            self.viewport.extent.width as f32,
            self.viewport.extent.height as f32,
        ]
    }

    fn check_grid(mirror: &Mirror, grid: &SurfaceGrid) -> GpuResult<()> {
        grid.shape.validate()?;
        if grid
            .offset
            .checked_add(grid.floats())
            .is_none_or(|end| end > mirror.len())
        {
            return Err(GpuError::InvalidArgument(format!(
                "surface grid {grid:?} needs {} floats after its offset, mirror has {}",
                grid.floats(),
                mirror.len()
            )));
        }
        Ok(())
    }

    /// Draws a shaded grid surface from this frame's slot of `mirror`.
    pub fn draw_surface(
        &mut self,
        mirror: &Mirror,
        grid: SurfaceGrid,
        style: &SurfaceStyle,
    ) -> GpuResult<()> {
        Self::check_grid(mirror, &grid)?;
        let r = &mut *self.renderer;
        let ib = r.grids.triangles(&r.device, &mut r.uploader, grid.shape)?;
        let (index_buffer, count) = (ib.buffer.raw, ib.count);
        let eye = self.camera.eye;
        let push = SurfacePush {
            view_proj: self.view_proj(),
            eye: [eye.x, eye.y, eye.z, style.shininess],
            light: [
                style.light_dir.x,
                style.light_dir.y,
                style.light_dir.z,
                style.ambient,
            ],
            front: style.front,
            back: style.back,
        };
        self.bind_and_push(self.pipelines.surface, &push);
        self.draw_indexed(mirror, grid.offset, index_buffer, count);
        Ok(())
    }

    /// Draws isolines every `every` samples (1 = full wireframe) over a grid surface, in
    /// linear colour `color`. Draw it after the surface: the surface is depth-biased back.
    pub fn draw_wire(
        &mut self,
        mirror: &Mirror,
        grid: SurfaceGrid,
        every: u32,
        color: [f32; 4],
    ) -> GpuResult<()> {
        Self::check_grid(mirror, &grid)?;
        let r = &mut *self.renderer;
        let ib = r
            .grids
            .lines(&r.device, &mut r.uploader, grid.shape, every)?;
        let (index_buffer, count) = (ib.buffer.raw, ib.count);
        let push = WirePush {
            view_proj: self.view_proj(),
            color,
        };
        self.bind_and_push(self.pipelines.wire, &push);
        self.draw_indexed(mirror, grid.offset, index_buffer, count);
        Ok(())
    }

    fn draw_indexed(&self, mirror: &Mirror, offset: usize, index_buffer: vk::Buffer, count: u32) {
        let vb = mirror.slot(self.slot).raw();
        // SAFETY: recording inside a rendering scope; offsets/ranges checked by the caller.
        unsafe {
            let raw = &self.renderer.device.raw;
            raw.cmd_bind_vertex_buffers(self.cmd, 0, &[vb], &[offset as u64 * 4]);
            raw.cmd_bind_index_buffer(self.cmd, index_buffer, 0, vk::IndexType::UINT32);
            raw.cmd_draw_indexed(self.cmd, count, 1, 0, 0, 0);
        }
    }

    /// Draws a wide polyline through the points of `run` in this frame's slot of `mirror`.
    pub fn draw_polyline(
        &mut self,
        mirror: &Mirror,
        run: PointRun,
        style: &PolylineStyle,
    ) -> GpuResult<()> {
        run.check(mirror.len(), 2)?;
        let address = mirror.slot(self.slot).address();
        self.polyline_at(address, run, style);
        Ok(())
    }

    /// Draws a wide polyline through `points`, copied into this frame's transient memory.
    pub fn draw_polyline_immediate(
        &mut self,
        points: &[[f32; 3]],
        style: &PolylineStyle,
    ) -> GpuResult<()> {
        let run = PointRun::packed(0, points.len());
        run.check(points.len() * 3, 2)?;
        let alloc = self.push_transient(points)?;
        self.polyline_at(alloc.address, run, style);
        Ok(())
    }

    fn polyline_at(&mut self, address: vk::DeviceAddress, run: PointRun, style: &PolylineStyle) {
        let push = PolylinePush {
            view_proj: self.view_proj(),
            color: style.color,
            points: address,
            viewport: self.viewport_size(),
            first: run.offset as u32,
            stride: run.stride as u32,
            count: run.count as u32,
            width: style.width,
        };
        self.bind_and_push(self.pipelines.polyline, &push);
        // SAFETY: recording inside a rendering scope; the run was bounds-checked.
        unsafe {
            let raw = &self.renderer.device.raw;
            raw.cmd_set_depth_test_enable(self.cmd, style.depth_test);
            raw.cmd_draw(self.cmd, 6, run.count as u32 - 1, 0, 0);
        }
    }

    /// Draws the points of `run` as screen-space squares, highlighting hovered/selected.
    pub fn draw_points(
        &mut self,
        mirror: &Mirror,
        run: PointRun,
        style: &PointStyle,
    ) -> GpuResult<()> {
        run.check(mirror.len(), 1)?;
        let index = |i: Option<u32>| i.and_then(|i| i32::try_from(i).ok()).unwrap_or(-1);
        let push = PointsPush {
            view_proj: self.view_proj(),
            points: mirror.slot(self.slot).address(),
            viewport: self.viewport_size(),
            first: run.offset as u32,
            stride: run.stride as u32,
            hovered: index(style.hovered),
            selected: index(style.selected),
            size: style.size,
            color: pack_unorm(style.color),
            hovered_color: pack_unorm(style.hovered_color),
            selected_color: pack_unorm(style.selected_color),
        };
        self.bind_and_push(self.pipelines.points, &push);
        // SAFETY: recording inside a rendering scope; the run was bounds-checked.
        unsafe {
            let raw = &self.renderer.device.raw;
            raw.cmd_set_depth_test_enable(self.cmd, style.depth_test);
            raw.cmd_draw(self.cmd, 6, run.count as u32, 0, 0);
        }
        Ok(())
    }

    fn push_transient<T: Pod>(&mut self, data: &[T]) -> GpuResult<TransientAlloc> {
        let r = &mut *self.renderer;
        let slot = &mut r.frames[self.slot];
        slot.transient.push(&r.device, &mut slot.release, data)
    }

    /// Draws a depth-tested coloured line list (pairs of vertices) in world space.
    pub fn draw_lines3d(&mut self, vertices: &[LineVertex]) -> GpuResult<()> {
        if vertices.len() < 2 {
            return Ok(());
        }
        let alloc = self.push_transient(vertices)?;
        let push = Lines3dPush {
            view_proj: self.view_proj(),
        };
        self.bind_and_push(self.pipelines.lines3d, &push);
        self.draw_transient(alloc, (vertices.len() & !1) as u32);
        Ok(())
    }

    /// Draws alpha-blended triangles in pixel coordinates of the current viewport (no depth).
    /// See [`super::font`] for text.
    pub fn draw_overlay(&mut self, vertices: &[OverlayVertex]) -> GpuResult<()> {
        let count = vertices.len() / 3 * 3;
        if count == 0 {
            return Ok(());
        }
        let alloc = self.push_transient(&vertices[..count])?;
        let push = OverlayPush {
            viewport: self.viewport_size(),
        };
        self.bind_and_push(self.pipelines.overlay, &push);
        self.draw_transient(alloc, count as u32);
        Ok(())
    }

    fn draw_transient(&self, alloc: TransientAlloc, count: u32) {
        // SAFETY: recording inside a rendering scope; the data was just written this frame.
        unsafe {
            let raw = &self.renderer.device.raw;
            raw.cmd_bind_vertex_buffers(self.cmd, 0, &[alloc.buffer], &[alloc.offset]);
            raw.cmd_draw(self.cmd, count, 1, 0, 0);
        }
    }
}
