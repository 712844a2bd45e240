//! What a frame can draw: the argument types (styles, runs, vertices) and the draw calls.
//!
//! Every draw binds its pipeline and pushes its constants; vertex data comes from this
//! frame's slot of a mirror or from the frame's transient memory.

use ash::vk;
use glam::{Mat4, Vec3};

use super::error::{GpuError, GpuResult};
use super::frame::Frame;
use super::grid::{GridShape, GridStride};
use super::mirror::Mirror;
use super::pipeline::{
    Lines3dPush, MapPush, OverlayPush, PUSH_STAGES, PointsPush, PolylinePush, SurfacePush, WirePush,
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

/// How an analysis map colours surfaces ([`Frame::draw_surface_map_batch`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MapStyle {
    /// Each vertex's scalar through the diverging colour scale over ±`range` (NaN grey).
    Scale { range: f32 },
    /// Reflection lines: `stripes` bands over the height (z from −1 to 1) of the reflected view ray.
    Zebra { stripes: f32 },
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

/// Vertex of [`Frame::draw_overlay`]: pixel position (origin top-left, y down), sRGB-encoded
/// RGBA8 colour (alpha-blended) and where in the built-in font the quad samples.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OverlayVertex {
    /// Pixel coordinates relative to the current viewport.
    pub pos: [f32; 2],
    /// sRGB-encoded colour, straight alpha.
    pub color: [u8; 4],
    /// Font coordinates: `x = 8 · glyph + column`, `y = row`, in font pixels of the glyph
    /// table of [`super::font`] (glyph = character code − 32). The fragment shader keeps the
    /// fragment where that font pixel is lit. [`OverlayVertex::SOLID`] (negative) fills the
    /// whole triangle.
    pub glyph: [f32; 2],
}

impl OverlayVertex {
    /// `glyph` value of untextured (solid) triangles.
    pub const SOLID: [f32; 2] = [-1.0, -1.0];
}

// SAFETY: repr(C), 12 + 4 bytes, no padding, every bit pattern valid.
unsafe impl Pod for LineVertex {}
// SAFETY: repr(C), 8 + 4 + 8 bytes, no padding, every bit pattern valid.
unsafe impl Pod for OverlayVertex {}

const _: () = {
    assert!(size_of::<LineVertex>() == 16);
    assert!(size_of::<OverlayVertex>() == 20);
};

/// Packs a linear colour into RGBA8 (for `unpackUnorm4x8` in shaders).
fn pack_unorm(c: [f32; 4]) -> u32 {
    let b = |x: f32| (x.clamp(0.0, 1.0) * 255.0 + 0.5) as u32;
    b(c[0]) | (b(c[1]) << 8) | (b(c[2]) << 16) | (b(c[3]) << 24)
}

/// What a frame recorded so far: draws and state changes (state already bound is not bound
/// again).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DrawStats {
    /// Draw calls recorded.
    pub draws: u32,
    /// Pipeline binds recorded.
    pub pipeline_binds: u32,
    /// Triangles submitted by surface draws (after level of detail).
    pub surface_triangles: u64,
}

impl Frame<'_> {
    fn bind_and_push<T: Pod>(&mut self, pipeline: vk::Pipeline, push: &T) {
        self.ensure_rendering();
        let layout = self.renderer.pipelines.layout;
        let raw = &self.renderer.device.raw;
        if self.bound.pipeline != pipeline {
            // SAFETY: recording inside a rendering scope; the pipeline matches the target.
            unsafe { raw.cmd_bind_pipeline(self.cmd, vk::PipelineBindPoint::GRAPHICS, pipeline) };
            self.bound.pipeline = pipeline;
            // Dynamic depth-test state is reset per pipeline in our bookkeeping: a pipeline
            // without the dynamic state overrides it.
            self.bound.depth_test = None;
            self.stats.pipeline_binds += 1;
        }
        // SAFETY: recording inside a rendering scope; the push struct fits the layout range.
        unsafe { raw.cmd_push_constants(self.cmd, layout, PUSH_STAGES, 0, bytes_of(push)) };
    }

    fn set_depth_test(&mut self, enable: bool) {
        if self.bound.depth_test != Some(enable) {
            // SAFETY: recording; the bound pipeline has DEPTH_TEST_ENABLE as dynamic state.
            unsafe {
                self.renderer
                    .device
                    .raw
                    .cmd_set_depth_test_enable(self.cmd, enable)
            };
            self.bound.depth_test = Some(enable);
        }
    }

    fn bind_vertices(&mut self, buffer: vk::Buffer, offset: u64) {
        if self.bound.vertices != Some((buffer, offset)) {
            // SAFETY: recording; the buffer has VERTEX_BUFFER usage and outlives the frame.
            unsafe {
                self.renderer
                    .device
                    .raw
                    .cmd_bind_vertex_buffers(self.cmd, 0, &[buffer], &[offset])
            };
            self.bound.vertices = Some((buffer, offset));
        }
    }

    fn bind_indices(&mut self, buffer: vk::Buffer) {
        if self.bound.indices != buffer {
            // SAFETY: recording; cached index buffers live as long as the renderer.
            unsafe {
                self.renderer.device.raw.cmd_bind_index_buffer(
                    self.cmd,
                    buffer,
                    0,
                    vk::IndexType::UINT32,
                )
            };
            self.bound.indices = buffer;
        }
    }

    /// Draws and binds recorded so far in this frame.
    pub fn stats(&self) -> DrawStats {
        self.stats
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

    /// Checks the batch against `mirror`; returns the byte offset to bind the vertices at and
    /// the batch's runs: (vertex offset from there, number of surfaces stored back to back).
    fn batch_runs(mirror: &Mirror, batch: &SurfaceBatch) -> GpuResult<(u64, Vec<(i32, u32)>)> {
        batch.shape.validate()?;
        let per = SurfaceGrid::FLOATS_PER_VERTEX;
        let floats = SurfaceGrid {
            offset: 0,
            shape: batch.shape,
        }
        .floats();
        let residue = batch.offsets.first().map_or(0, |o| o % per);
        let mut runs: Vec<(i32, u32)> = Vec::with_capacity(batch.offsets.len());
        let mut next = None;
        for &offset in batch.offsets {
            let fits = offset
                .checked_add(floats)
                .is_some_and(|end| end <= mirror.len());
            let vertex = i32::try_from((offset - offset % per) / per).ok();
            match vertex {
                Some(v) if fits && offset % per == residue => {
                    match runs.last_mut() {
                        // Right after the previous surface: the same run.
                        Some(run) if next == Some(offset) => run.1 += 1,
                        _ => runs.push((v, 1)),
                    }
                    next = Some(offset + floats);
                }
                _ => {
                    return Err(GpuError::InvalidArgument(format!(
                        "surface grid {}x{} at float {offset} does not fit a mirror of {} \
                         floats (or its offset is not {residue} modulo {per})",
                        batch.shape.rows,
                        batch.shape.cols,
                        mirror.len()
                    )));
                }
            }
        }
        Ok((residue as u64 * 4, runs))
    }

    /// Draws a shaded grid surface from this frame's slot of `mirror`.
    pub fn draw_surface(
        &mut self,
        mirror: &Mirror,
        grid: SurfaceGrid,
        style: &SurfaceStyle,
    ) -> GpuResult<()> {
        let batch = SurfaceBatch {
            shape: grid.shape,
            stride: GridStride::FULL,
            offsets: &[grid.offset],
        };
        self.draw_surface_batch(mirror, &batch, style)
    }

    /// Draws a batch of shaded grid surfaces at the batch's stride (display level of detail,
    /// see [`GridStride`]): the same vertices, fewer triangles, one call.
    pub fn draw_surface_batch(
        &mut self,
        mirror: &Mirror,
        batch: &SurfaceBatch,
        style: &SurfaceStyle,
    ) -> GpuResult<()> {
        let (base, runs) = Self::batch_runs(mirror, batch)?;
        let Some(longest) = runs.iter().map(|r| r.1).max() else {
            return Ok(());
        };
        let r = &mut *self.renderer;
        let release = &mut r.frames[self.slot].release;
        let key = (batch.shape, batch.stride, longest);
        let ib = r
            .grids
            .triangles(&r.device, &mut r.uploader, key, release)?;
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
        self.stats.surface_triangles += u64::from(count / 3) * batch.offsets.len() as u64;
        self.bind_and_push(self.pipelines.surface, &push);
        self.draw_indexed(mirror, base, index_buffer, count, &runs);
        Ok(())
    }

    /// Draws a batch like [`Frame::draw_surface_batch`], coloured by an analysis map.
    ///
    /// The vertex at floats `r + 6v` of `mirror` (`r` the batch's common offset residue, see
    /// [`SurfaceBatch`]) takes its scalar from float `v` of `scalars` (binding 1), so a batch
    /// of surfaces shares one scalar buffer indexed like the vertex buffer. Zebra stripes read
    /// no scalar: with `scalars` `None` the vertex mirror itself is bound there.
    pub fn draw_surface_map_batch(
        &mut self,
        mirror: &Mirror,
        scalars: Option<&Mirror>,
        batch: &SurfaceBatch,
        style: MapStyle,
    ) -> GpuResult<()> {
        let (base, runs) = Self::batch_runs(mirror, batch)?;
        let Some(longest) = runs.iter().map(|r| r.1).max() else {
            return Ok(());
        };
        let scalars = match (scalars, style) {
            (Some(s), _) => s,
            (None, MapStyle::Zebra { .. }) => mirror,
            (None, MapStyle::Scale { .. }) => {
                return Err(GpuError::InvalidArgument(
                    "a colour-scale map needs a scalar mirror".into(),
                ));
            }
        };
        // The last vertex any run reads, against the scalars there are.
        let vertices = batch.shape.vertices() as usize;
        let needed = runs
            .iter()
            .map(|&(first, surfaces)| first as usize + surfaces as usize * vertices)
            .max()
            .unwrap_or(0);
        if scalars.len() < needed {
            return Err(GpuError::InvalidArgument(format!(
                "an analysis map needs a scalar per vertex: {} scalars for {needed} vertices",
                scalars.len()
            )));
        }
        let r = &mut *self.renderer;
        let release = &mut r.frames[self.slot].release;
        let key = (batch.shape, batch.stride, longest);
        let ib = r
            .grids
            .triangles(&r.device, &mut r.uploader, key, release)?;
        let (index_buffer, count) = (ib.buffer.raw, ib.count);
        let eye = self.camera.eye;
        let params = match style {
            MapStyle::Scale { range } => [0.0, 1.0 / range, 0.0, 0.25],
            MapStyle::Zebra { stripes } => [1.0, 0.0, stripes, 0.25],
        };
        let push = MapPush {
            view_proj: self.view_proj(),
            eye: [eye.x, eye.y, eye.z, 0.0],
            params,
        };
        self.stats.surface_triangles += u64::from(count / 3) * batch.offsets.len() as u64;
        self.bind_and_push(self.pipelines.surface_map, &push);
        let scalar_buffer = scalars.slot(self.slot).raw();
        // SAFETY: recording inside a rendering scope; the scalar mirror has VERTEX_BUFFER
        // usage, lives until this slot's fence signals (mirrors are released through the
        // frame), and holds a float for every vertex index the draw reads (checked above).
        unsafe {
            self.renderer
                .device
                .raw
                .cmd_bind_vertex_buffers(self.cmd, 1, &[scalar_buffer], &[0])
        };
        self.draw_indexed(mirror, base, index_buffer, count, &runs);
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
        let batch = SurfaceBatch {
            shape: grid.shape,
            stride: GridStride::FULL,
            offsets: &[grid.offset],
        };
        self.draw_wire_batch(mirror, &batch, every, color)
    }

    /// Isolines over every surface of a batch, on the strided mesh
    /// [`Frame::draw_surface_batch`] draws for it: they lie on its edges (`every` rounds up
    /// to a multiple of the stride).
    pub fn draw_wire_batch(
        &mut self,
        mirror: &Mirror,
        batch: &SurfaceBatch,
        every: u32,
        color: [f32; 4],
    ) -> GpuResult<()> {
        let (base, runs) = Self::batch_runs(mirror, batch)?;
        let Some(longest) = runs.iter().map(|r| r.1).max() else {
            return Ok(());
        };
        let r = &mut *self.renderer;
        let release = &mut r.frames[self.slot].release;
        let key = (batch.shape, every, batch.stride, longest);
        let ib = r.grids.lines(&r.device, &mut r.uploader, key, release)?;
        let (index_buffer, count) = (ib.buffer.raw, ib.count);
        let push = WirePush {
            view_proj: self.view_proj(),
            color,
        };
        self.bind_and_push(self.pipelines.wire, &push);
        self.draw_indexed(mirror, base, index_buffer, count, &runs);
        Ok(())
    }

    /// For each run (vertex offset, surfaces), the first `surfaces · count` indices of
    /// `index_buffer` (copies of one grid's `count`): one `vkCmdDrawMultiIndexedEXT` (per
    /// `maxMultiDrawCount` runs) where supported, else one draw per run.
    fn draw_indexed(
        &mut self,
        mirror: &Mirror,
        base: u64,
        index_buffer: vk::Buffer,
        count: u32,
        runs: &[(i32, u32)],
    ) {
        self.bind_vertices(mirror.slot(self.slot).raw(), base);
        self.bind_indices(index_buffer);
        let device = &*self.renderer.device;
        match &device.multi_draw {
            Some(multi) => {
                for chunk in runs.chunks(multi.max_count as usize) {
                    let infos: Vec<vk::MultiDrawIndexedInfoEXT> = chunk
                        .iter()
                        .map(|&(vertex_offset, surfaces)| vk::MultiDrawIndexedInfoEXT {
                            first_index: 0,
                            index_count: count * surfaces,
                            vertex_offset,
                        })
                        .collect();
                    // SAFETY: recording inside a rendering scope; the extension and its
                    // multiDraw feature are enabled; `infos` holds `chunk.len()` tightly packed
                    // structs (stride = their size) whose index and vertex ranges the caller
                    // checked against the bound buffers.
                    unsafe {
                        (multi.fns.fp().cmd_draw_multi_indexed_ext)(
                            self.cmd,
                            infos.len() as u32,
                            infos.as_ptr(),
                            1,
                            0,
                            size_of::<vk::MultiDrawIndexedInfoEXT>() as u32,
                            std::ptr::null(),
                        )
                    };
                    self.stats.draws += 1;
                }
            }
            None => {
                for &(vertex_offset, surfaces) in runs {
                    // SAFETY: recording inside a rendering scope; ranges checked by the caller.
                    unsafe {
                        device.raw.cmd_draw_indexed(
                            self.cmd,
                            count * surfaces,
                            1,
                            0,
                            vertex_offset,
                            0,
                        )
                    };
                    self.stats.draws += 1;
                }
            }
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
        self.polyline_at(address, run, 0, style);
        Ok(())
    }

    /// Draws every row and every column of a `rows × cols` grid of points as wide lines, in
    /// one draw: a control net. Point `(r, c)` is point `r · cols + c` of `run`, whose count
    /// must be `rows · cols`.
    pub fn draw_net(
        &mut self,
        mirror: &Mirror,
        run: PointRun,
        cols: usize,
        style: &PolylineStyle,
    ) -> GpuResult<()> {
        run.check(mirror.len(), 1)?;
        if cols == 0 || !run.count.is_multiple_of(cols) || u32::try_from(cols).is_err() {
            return Err(GpuError::InvalidArgument(format!(
                "net of {} points is not a whole number of rows of {cols}",
                run.count
            )));
        }
        if net_segments(run.count, cols) == 0 {
            return Ok(());
        }
        let address = mirror.slot(self.slot).address();
        self.polyline_at(address, run, cols as u32, style);
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
        self.polyline_at(alloc.address, run, 0, style);
        Ok(())
    }

    /// One draw of 6 vertices per segment (a quad each). Instancing would say the same more
    /// briefly, but Mesa's draw module runs every instance as a separate draw.
    fn polyline_at(
        &mut self,
        address: vk::DeviceAddress,
        run: PointRun,
        grid_cols: u32,
        style: &PolylineStyle,
    ) {
        let segments = if grid_cols == 0 {
            run.count - 1
        } else {
            net_segments(run.count, grid_cols as usize)
        };
        // One-pixel lines rasterise natively: 2 vertices per segment instead of a quad's 6.
        let thin = style.width <= 1.0;
        let push = PolylinePush {
            view_proj: self.view_proj(),
            color: style.color,
            points: address,
            viewport: self.viewport_size(),
            first: run.offset as u32,
            stride: run.stride as u32,
            count: run.count as u32,
            width: style.width,
            grid_cols,
            thin: u32::from(thin),
        };
        let (pipeline, per_segment) = if thin {
            (self.pipelines.thin_lines, 2)
        } else {
            (self.pipelines.polyline, 6)
        };
        self.bind_and_push(pipeline, &push);
        self.set_depth_test(style.depth_test);
        self.draw_vertices(vertex_count(segments, per_segment));
    }

    fn draw_vertices(&mut self, count: u32) {
        // SAFETY: recording inside a rendering scope; vertex data is pulled through device
        // addresses whose ranges the callers checked.
        unsafe { self.renderer.device.raw.cmd_draw(self.cmd, count, 1, 0, 0) };
        self.stats.draws += 1;
    }

    /// Draws the points of `run` as screen-space squares, highlighting hovered/selected.
    pub fn draw_points(
        &mut self,
        mirror: &Mirror,
        run: PointRun,
        style: &PointStyle,
    ) -> GpuResult<()> {
        run.check(mirror.len(), 1)?;
        let large_points = self.renderer.device.caps.large_points;
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
            quads: u32::from(!large_points),
            _pad: 0,
        };
        self.bind_and_push(self.pipelines.points, &push);
        self.set_depth_test(style.depth_test);
        self.draw_vertices(vertex_count(run.count, if large_points { 1 } else { 6 }));
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
            font: self.renderer.font.as_ref().map_or(0, |f| f.address()),
        };
        self.bind_and_push(self.pipelines.overlay, &push);
        self.draw_transient(alloc, count as u32);
        Ok(())
    }

    fn draw_transient(&mut self, alloc: TransientAlloc, count: u32) {
        self.bind_vertices(alloc.buffer, alloc.offset);
        // SAFETY: recording inside a rendering scope; the data was just written this frame.
        unsafe { self.renderer.device.raw.cmd_draw(self.cmd, count, 1, 0, 0) };
        self.stats.draws += 1;
    }
}

/// Segments of a `count`-point net with `cols` points per row: rows·(cols−1) along the rows,
/// cols·(rows−1) along the columns.
fn net_segments(count: usize, cols: usize) -> usize {
    let rows = count / cols;
    rows * (cols - 1) + cols * rows.saturating_sub(1)
}

/// Vertices of `n` primitives of `per` vertices each. Point runs are bounds-checked to fewer
/// than 2³² floats of at least 3 each, so this fits a `u32` for every checked run up to
/// 715 827 882 quads; larger counts are clamped to whole primitives.
fn vertex_count(n: usize, per: u32) -> u32 {
    u32::try_from(n.saturating_mul(per as usize)).unwrap_or(u32::MAX / per * per)
}
