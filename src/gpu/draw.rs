//! What a frame can draw: the draw calls, on top of the frame's recording state.
//!
//! Every draw binds its pipeline and pushes its constants; vertex data comes from this
//! frame's slot of a mirror or from the frame's transient memory.

use ash::vk;

use super::error::{GpuError, GpuResult};
use super::frame::{DrawStats, Frame};
use super::grid::GridStride;
use super::mirror::Mirror;
use super::pipeline::{
    Lines3dPush, MASK_BINDING, MapPush, OverlayPush, PUSH_STAGES, PointsPush, PolylinePush,
    SurfacePush, Which, WirePush,
};
use super::pod::{Pod, bytes_of};
use super::region::{PointRun, SurfaceBatch, SurfaceGrid};
use super::style::{GripGrid, MapStyle, PointStyle, PolylineStyle, SurfaceStyle};
use super::transient::TransientAlloc;
use super::vertex::{LineVertex, OverlayVertex};

/// The pipeline for a batch: `trimmed` when it has a coverage mask (checked against it).
fn masked(batch: &SurfaceBatch, whole: Which, trimmed: Which) -> GpuResult<Which> {
    match batch.mask {
        Some(mask) => mask.check(batch.offsets.len()).map(|()| trimmed),
        None => Ok(whole),
    }
}

/// Packs a linear colour into RGBA8 (for `unpackUnorm4x8` in shaders).
fn pack_unorm(c: [f32; 4]) -> u32 {
    let b = |x: f32| (x.clamp(0.0, 1.0) * 255.0 + 0.5) as u32;
    b(c[0]) | (b(c[1]) << 8) | (b(c[2]) << 16) | (b(c[3]) << 24)
}

impl Frame<'_> {
    fn bind_and_push<T: Pod>(&mut self, pipeline: vk::Pipeline, push: &T) {
        self.ensure_rendering();
        let layout = self.ctx.layout;
        let raw = &self.ctx.device.raw;
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
                self.ctx
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
                self.ctx
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
                self.ctx.device.raw.cmd_bind_index_buffer(
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
    #[must_use]
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
            mask: None,
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
        self.surface_batch(mirror, batch, None, style)
    }

    /// Draws some cells of one surface (the batch's first) as [`Frame::draw_surface_batch`]
    /// draws them: `cells` are (first index, index count) ranges of the strided mesh's
    /// triangle list ([`super::grid::grid_triangles_strided`]), drawn in the order given. The
    /// retained redraw draws a surface's static and dynamic chunks apart with it.
    pub fn draw_surface_cells(
        &mut self,
        mirror: &Mirror,
        batch: &SurfaceBatch,
        cells: &[(u32, u32)],
        style: &SurfaceStyle,
    ) -> GpuResult<()> {
        self.surface_batch(mirror, batch, Some(cells), style)
    }

    fn surface_batch(
        &mut self,
        mirror: &Mirror,
        batch: &SurfaceBatch,
        cells: Option<&[(u32, u32)]>,
        style: &SurfaceStyle,
    ) -> GpuResult<()> {
        let (base, runs) = batch.runs(mirror.len())?;
        let Some(longest) = runs.iter().map(|r| r.1).max() else {
            return Ok(());
        };
        let c = &mut self.ctx;
        let release = &mut c.ring.slots[self.slot].release;
        let key = (batch.shape, batch.stride, longest);
        let ib = c.grids.triangles(c.device, c.uploader, key, release)?;
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
        let cells = check_cells(cells, count, &runs)?;
        let pipeline = self
            .ctx
            .pipeline(masked(batch, Which::Surface, Which::SurfaceTrim)?)?;
        self.bind_and_push(pipeline, &push);
        let instance = self.bind_mask(batch);
        let indices = self.draw_indexed(mirror, base, index_buffer, count, &runs, cells, instance);
        self.stats.surface_triangles += indices / 3;
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
        self.surface_map_batch(mirror, scalars, batch, None, style)
    }

    /// Some cells of one surface coloured by a map: [`Frame::draw_surface_cells`] for
    /// [`Frame::draw_surface_map_batch`].
    pub fn draw_surface_map_cells(
        &mut self,
        mirror: &Mirror,
        scalars: Option<&Mirror>,
        batch: &SurfaceBatch,
        cells: &[(u32, u32)],
        style: MapStyle,
    ) -> GpuResult<()> {
        self.surface_map_batch(mirror, scalars, batch, Some(cells), style)
    }

    fn surface_map_batch(
        &mut self,
        mirror: &Mirror,
        scalars: Option<&Mirror>,
        batch: &SurfaceBatch,
        cells: Option<&[(u32, u32)]>,
        style: MapStyle,
    ) -> GpuResult<()> {
        let (base, runs) = batch.runs(mirror.len())?;
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
        let c = &mut self.ctx;
        let release = &mut c.ring.slots[self.slot].release;
        let key = (batch.shape, batch.stride, longest);
        let ib = c.grids.triangles(c.device, c.uploader, key, release)?;
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
        let cells = check_cells(cells, count, &runs)?;
        let pipeline =
            self.ctx
                .pipeline(masked(batch, Which::SurfaceMap, Which::SurfaceMapTrim)?)?;
        self.bind_and_push(pipeline, &push);
        let scalar_buffer = scalars.slot(self.slot).raw();
        // SAFETY: recording inside a rendering scope; the scalar mirror has VERTEX_BUFFER
        // usage, lives until this slot's fence signals (mirrors are released through the
        // frame), and holds a float for every vertex index the draw reads (checked above).
        unsafe {
            self.ctx
                .device
                .raw
                .cmd_bind_vertex_buffers(self.cmd, 1, &[scalar_buffer], &[0])
        };
        let instance = self.bind_mask(batch);
        let indices = self.draw_indexed(mirror, base, index_buffer, count, &runs, cells, instance);
        self.stats.surface_triangles += indices / 3;
        Ok(())
    }

    /// Binds a masked batch's mask table (instance-rate binding 2) and returns the instance
    /// that selects its entry; 0 for a batch without a mask.
    fn bind_mask(&mut self, batch: &SurfaceBatch) -> u32 {
        let Some(mask) = batch.mask else {
            return 0;
        };
        let buffer = mask.table.slot(self.slot).raw();
        // SAFETY: recording; the table mirror has VERTEX_BUFFER usage and outlives the frame;
        // the bound pipeline reads binding 2 per instance.
        unsafe {
            self.ctx
                .device
                .raw
                .cmd_bind_vertex_buffers(self.cmd, MASK_BINDING, &[buffer], &[0])
        };
        mask.entry
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
            mask: None,
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
        let (base, runs) = batch.runs(mirror.len())?;
        let Some(longest) = runs.iter().map(|r| r.1).max() else {
            return Ok(());
        };
        let c = &mut self.ctx;
        let release = &mut c.ring.slots[self.slot].release;
        let key = (batch.shape, every, batch.stride, longest);
        let ib = c.grids.lines(c.device, c.uploader, key, release)?;
        let (index_buffer, count) = (ib.buffer.raw, ib.count);
        let push = WirePush {
            view_proj: self.view_proj(),
            color,
        };
        let pipeline = self
            .ctx
            .pipeline(masked(batch, Which::Wire, Which::WireTrim)?)?;
        self.bind_and_push(pipeline, &push);
        let instance = self.bind_mask(batch);
        self.draw_indexed(mirror, base, index_buffer, count, &runs, None, instance);
        Ok(())
    }

    /// For each run (vertex offset, surfaces), the first `surfaces · count` indices of
    /// `index_buffer` (copies of one grid's `count`), or with `cells` the given index ranges
    /// of the first run's surface: one `vkCmdDrawMultiIndexedEXT` (per `maxMultiDrawCount`
    /// draws) where supported, else one draw each; one instance, `instance` (a masked
    /// batch's mask entry).
    #[allow(clippy::too_many_arguments)]
    fn draw_indexed(
        &mut self,
        mirror: &Mirror,
        base: u64,
        index_buffer: vk::Buffer,
        count: u32,
        runs: &[(i32, u32)],
        cells: Option<&[(u32, u32)]>,
        instance: u32,
    ) -> u64 {
        self.bind_vertices(mirror.slot(self.slot).raw(), base);
        self.bind_indices(index_buffer);
        // (first index, index count, vertex offset) of every draw.
        let draws: Vec<(u32, u32, i32)> = match cells {
            Some(cells) => cells.iter().map(|&(f, n)| (f, n, runs[0].0)).collect(),
            None => runs.iter().map(|&(v, s)| (0, count * s, v)).collect(),
        };
        let indices = draws.iter().map(|d| u64::from(d.1)).sum::<u64>();
        let device = self.ctx.device;
        match &device.multi_draw {
            Some(multi) => {
                for chunk in draws.chunks(multi.max_count as usize) {
                    let infos: Vec<vk::MultiDrawIndexedInfoEXT> = chunk
                        .iter()
                        .map(|&(first_index, index_count, vertex_offset)| {
                            vk::MultiDrawIndexedInfoEXT {
                                first_index,
                                index_count,
                                vertex_offset,
                            }
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
                            instance,
                            size_of::<vk::MultiDrawIndexedInfoEXT>() as u32,
                            std::ptr::null(),
                        )
                    };
                    self.stats.draws += 1;
                }
            }
            None => {
                for &(first_index, index_count, vertex_offset) in &draws {
                    // SAFETY: recording inside a rendering scope; ranges checked by the caller.
                    unsafe {
                        device.raw.cmd_draw_indexed(
                            self.cmd,
                            index_count,
                            1,
                            first_index,
                            vertex_offset,
                            instance,
                        )
                    };
                    self.stats.draws += 1;
                }
            }
        }
        indices
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
            (self.ctx.eager(Which::ThinLines), 2)
        } else {
            (self.ctx.eager(Which::Polyline), 6)
        };
        self.bind_and_push(pipeline, &push);
        self.set_depth_test(style.depth_test);
        self.draw_vertices(vertex_count(segments, per_segment));
    }

    fn draw_vertices(&mut self, count: u32) {
        // SAFETY: recording inside a rendering scope; vertex data is pulled through device
        // addresses whose ranges the callers checked.
        unsafe { self.ctx.device.raw.cmd_draw(self.cmd, count, 1, 0, 0) };
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
        let large_points = self.ctx.device.caps.large_points;
        let index = |i: Option<u32>| i.and_then(|i| i32::try_from(i).ok()).unwrap_or(-1);
        let grid = GripGrid::words(style.grid);
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
            grid_cols: grid[0],
            grid_rows: grid[1],
            _pad: 0,
        };
        self.bind_and_push(self.ctx.eager(Which::Points), &push);
        self.set_depth_test(style.depth_test);
        self.draw_vertices(vertex_count(run.count, if large_points { 1 } else { 6 }));
        Ok(())
    }

    fn push_transient<T: Pod>(&mut self, data: &[T]) -> GpuResult<TransientAlloc> {
        let slot = &mut self.ctx.ring.slots[self.slot];
        slot.transient
            .push(self.ctx.device, &mut slot.release, data)
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
        self.bind_and_push(self.ctx.eager(Which::Lines3d), &push);
        self.draw_transient(alloc, (vertices.len() & !1) as u32);
        Ok(())
    }

    /// Draws alpha-blended triangles in pixel coordinates of the current viewport (no depth),
    /// in order (later triangles over earlier ones). Text quads come from
    /// [`Frame::font`]'s [`super::font::Font::push_text`].
    pub fn draw_overlay(&mut self, vertices: &[OverlayVertex]) -> GpuResult<()> {
        let count = vertices.len() / 3 * 3;
        if count == 0 {
            return Ok(());
        }
        let alloc = self.push_transient(&vertices[..count])?;
        let push = OverlayPush {
            viewport: self.viewport_size(),
            font: self.ctx.font,
            atlas_width: self.ctx.text.atlas_size()[0],
            _pad: 0,
        };
        self.bind_and_push(self.ctx.eager(Which::Overlay), &push);
        self.draw_transient(alloc, count as u32);
        Ok(())
    }

    fn draw_transient(&mut self, alloc: TransientAlloc, count: u32) {
        self.bind_vertices(alloc.buffer, alloc.offset);
        // SAFETY: recording inside a rendering scope; the data was just written this frame.
        unsafe { self.ctx.device.raw.cmd_draw(self.cmd, count, 1, 0, 0) };
        self.stats.draws += 1;
    }
}

/// Cell ranges must lie in one grid's `count` indices, whole triangles, for a batch of one
/// surface.
fn check_cells<'c>(
    cells: Option<&'c [(u32, u32)]>,
    count: u32,
    runs: &[(i32, u32)],
) -> GpuResult<Option<&'c [(u32, u32)]>> {
    let Some(cells) = cells else {
        return Ok(None);
    };
    let fits = |&(f, n): &(u32, u32)| {
        f % 3 == 0 && n % 3 == 0 && f.checked_add(n).is_some_and(|end| end <= count)
    };
    if runs.len() == 1 && runs[0].1 == 1 && cells.iter().all(fits) {
        Ok(Some(cells))
    } else {
        Err(GpuError::InvalidArgument(format!(
            "cell ranges {cells:?} do not lie in one surface of {count} indices"
        )))
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
