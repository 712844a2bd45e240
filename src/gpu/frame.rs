//! Per-frame contexts (one per frame in flight) and the [`Frame`] recording API.

use ash::vk;
use glam::{Mat4, Vec3};

use super::device::Device;
use super::error::{GpuError, GpuResult, VkResultExt};
use super::grid::GridShape;
use super::memory::Buffer;
use super::mirror::{Mirror, MirrorWriter};
use super::offscreen::OffscreenTarget;
use super::pipeline::{
    Lines3dPush, OverlayPush, PUSH_STAGES, PipelineSet, PointsPush, PolylinePush, SurfacePush,
    WirePush,
};
use super::pod::{Pod, bytes_of};
use super::renderer::Renderer;
use super::swapchain::Swapchain;
use super::timestamp::GpuTimer;
use super::transient::TransientBuffer;

/// Everything one frame slot owns. The slot is reused every `FRAMES_IN_FLIGHT` frames, after
/// its fence says the GPU finished the previous use.
pub(crate) struct FrameSlot {
    pool: vk::CommandPool,
    pub cmd: vk::CommandBuffer,
    pub fence: vk::Fence,
    /// Signalled by `vkAcquireNextImageKHR`, waited by this slot's submission.
    pub acquire: vk::Semaphore,
    pub timer: Option<GpuTimer>,
    /// Buffers to destroy once this slot's fence next signals.
    pub release: Vec<Buffer>,
    pub transient: TransientBuffer,
    /// GPU time of the previous use of this slot.
    pub gpu_ms: Option<f64>,
}

impl FrameSlot {
    pub(crate) fn new(device: &Device, always_flush: bool) -> GpuResult<Self> {
        let raw = &device.raw;
        let mut slot = Self {
            pool: vk::CommandPool::null(),
            cmd: vk::CommandBuffer::null(),
            fence: vk::Fence::null(),
            acquire: vk::Semaphore::null(),
            timer: None,
            release: Vec::new(),
            transient: TransientBuffer::new(always_flush),
            gpu_ms: None,
        };
        let result = (|| {
            let info = vk::CommandPoolCreateInfo::default()
                .flags(vk::CommandPoolCreateFlags::TRANSIENT)
                .queue_family_index(device.queue_family);
            // SAFETY: valid device and create infos for each object below.
            unsafe {
                slot.pool = raw
                    .create_command_pool(&info, None)
                    .vk("vkCreateCommandPool")?;
                let alloc = vk::CommandBufferAllocateInfo::default()
                    .command_pool(slot.pool)
                    .level(vk::CommandBufferLevel::PRIMARY)
                    .command_buffer_count(1);
                slot.cmd = raw
                    .allocate_command_buffers(&alloc)
                    .vk("vkAllocateCommandBuffers")?[0];
                // Signalled, so the first wait on a fresh slot returns at once.
                let fence = vk::FenceCreateInfo::default().flags(vk::FenceCreateFlags::SIGNALED);
                slot.fence = raw.create_fence(&fence, None).vk("vkCreateFence")?;
                slot.acquire = raw
                    .create_semaphore(&vk::SemaphoreCreateInfo::default(), None)
                    .vk("vkCreateSemaphore")?;
            }
            slot.timer = GpuTimer::new(device)?;
            Ok(())
        })();
        match result {
            Ok(()) => Ok(slot),
            Err(e) => {
                slot.destroy(device);
                Err(e)
            }
        }
    }

    /// Waits for the slot's previous submission, then recycles what it used.
    pub(crate) fn wait_and_recycle(&mut self, device: &Device) -> GpuResult<()> {
        // SAFETY: the fence belongs to this device.
        unsafe { device.raw.wait_for_fences(&[self.fence], true, u64::MAX) }
            .vk("vkWaitForFences")?;
        if let Some(t) = self.timer.as_mut() {
            self.gpu_ms = t.read(device).or(self.gpu_ms);
        }
        for b in self.release.drain(..) {
            device.destroy_buffer(b);
        }
        self.transient.reset();
        Ok(())
    }

    /// Resets the command pool and begins the command buffer.
    pub(crate) fn begin_commands(&mut self, device: &Device) -> GpuResult<()> {
        // SAFETY: the fence has signalled, so the command buffer is not pending.
        unsafe {
            device
                .raw
                .reset_command_pool(self.pool, vk::CommandPoolResetFlags::empty())
                .vk("vkResetCommandPool")?;
            let begin = vk::CommandBufferBeginInfo::default()
                .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            device
                .raw
                .begin_command_buffer(self.cmd, &begin)
                .vk("vkBeginCommandBuffer")?;
        }
        if let Some(t) = self.timer.as_mut() {
            t.begin(device, self.cmd);
        }
        Ok(())
    }

    /// Destroys everything; the caller waited for the device to be idle.
    pub(crate) fn destroy(mut self, device: &Device) {
        for b in self.release.drain(..) {
            device.destroy_buffer(b);
        }
        if let Some(t) = self.timer.take() {
            t.destroy(device);
        }
        self.transient.destroy(device);
        // SAFETY: idle device; null handles (from a failed `new`) are ignored by Vulkan.
        unsafe {
            device.raw.destroy_semaphore(self.acquire, None);
            device.raw.destroy_fence(self.fence, None);
            device.raw.destroy_command_pool(self.pool, None);
        }
    }
}

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

/// Attachments of the target of one frame, resolved at begin.
#[derive(Clone, Copy)]
pub(crate) struct TargetView {
    pub image: vk::Image,
    pub view: vk::ImageView,
    pub msaa: Option<(vk::Image, vk::ImageView)>,
    pub depth: (vk::Image, vk::ImageView),
    pub extent: vk::Extent2D,
    pub format: vk::Format,
    pub samples: vk::SampleCountFlags,
}

pub(crate) enum FrameTarget<'a> {
    Offscreen(&'a mut OffscreenTarget),
    Swapchain {
        swapchain: &'a mut Swapchain,
        image_index: u32,
    },
}

/// One frame being recorded. Obtained from [`Renderer::begin_offscreen`] or
/// [`Renderer::begin_swapchain`]; submit with [`Frame::finish`] (dropping an unfinished frame
/// submits it too, ignoring errors).
///
/// Mirror writes for this frame go through [`Frame::write_mirror`], which targets this
/// frame's slot. Rendering (clear included) starts lazily at the first draw, so
/// [`Frame::set_clear_color`] before any draw is free.
pub struct Frame<'a> {
    pub(crate) renderer: &'a mut Renderer,
    pub(crate) target: FrameTarget<'a>,
    pub(crate) view: TargetView,
    pub(crate) slot: usize,
    pub(crate) number: u64,
    pub(crate) cmd: vk::CommandBuffer,
    pub(crate) pipelines: PipelineSet,
    pub(crate) rendering: bool,
    pub(crate) clear: [f32; 4],
    pub(crate) camera: Camera,
    pub(crate) viewport: vk::Rect2D,
    pub(crate) flushes: Vec<vk::MappedMemoryRange<'static>>,
    pub(crate) finished: bool,
}

impl<'a> Frame<'a> {
    /// The frame slot this frame records into (`0..FRAMES_IN_FLIGHT`): the caller must bring
    /// this slot of each mirror up to date.
    pub fn slot(&self) -> usize {
        self.slot
    }

    /// Sequential frame number (0 for the renderer's first frame).
    pub fn number(&self) -> u64 {
        self.number
    }

    /// Target size in pixels.
    pub fn extent(&self) -> [u32; 2] {
        [self.view.extent.width, self.view.extent.height]
    }

    /// GPU time in milliseconds of the previous frame recorded in this slot (`None` before
    /// the slot's first completion or without timestamp support).
    pub fn gpu_time_ms(&self) -> Option<f64> {
        self.renderer.frames[self.slot].gpu_ms
    }

    /// Write access to this frame's slot of `mirror`. Safe by construction: the slot's
    /// previous GPU use has completed (begin waited for its fence).
    pub fn write_mirror<'m>(&'m mut self, mirror: &'m mut Mirror) -> MirrorWriter<'m> {
        let atom = self.renderer.device.caps.non_coherent_atom_size;
        let track = self.renderer.always_flush || mirror.slot(self.slot).buffer.needs_flush();
        mirror.writer(self.slot, atom, track, &mut self.flushes)
    }

    /// Sets the camera used by subsequent 3D draws.
    pub fn set_camera(&mut self, camera: Camera) {
        self.camera = camera;
    }

    /// Sets the clear colour (linear RGBA). Before the first draw it becomes the load-op
    /// clear; afterwards it clears colour and depth of the current viewport immediately.
    pub fn set_clear_color(&mut self, color: [f32; 4]) {
        self.clear = color;
        if self.rendering {
            let attachments = [
                vk::ClearAttachment {
                    aspect_mask: vk::ImageAspectFlags::COLOR,
                    color_attachment: 0,
                    clear_value: vk::ClearValue {
                        color: vk::ClearColorValue { float32: color },
                    },
                },
                vk::ClearAttachment {
                    aspect_mask: vk::ImageAspectFlags::DEPTH,
                    color_attachment: 0,
                    clear_value: vk::ClearValue {
                        depth_stencil: vk::ClearDepthStencilValue {
                            depth: 1.0,
                            stencil: 0,
                        },
                    },
                },
            ];
            let rect = [vk::ClearRect {
                rect: self.viewport,
                base_array_layer: 0,
                layer_count: 1,
            }];
            // SAFETY: inside a rendering scope with these attachments; rect within the target.
            unsafe {
                self.renderer
                    .device
                    .raw
                    .cmd_clear_attachments(self.cmd, &attachments, &rect)
            };
        }
    }

    /// Restricts drawing to a pixel rectangle (origin top-left). Defaults to the whole target.
    pub fn set_viewport(&mut self, x: u32, y: u32, width: u32, height: u32) -> GpuResult<()> {
        let e = self.view.extent;
        if width == 0
            || height == 0
            || x.checked_add(width).is_none_or(|r| r > e.width)
            || y.checked_add(height).is_none_or(|b| b > e.height)
        {
            return Err(GpuError::InvalidArgument(format!(
                "viewport {x},{y} {width}x{height} outside target {}x{}",
                e.width, e.height
            )));
        }
        self.viewport = vk::Rect2D {
            offset: vk::Offset2D {
                x: x as i32,
                y: y as i32,
            },
            extent: vk::Extent2D { width, height },
        };
        if self.rendering {
            self.apply_viewport();
        }
        Ok(())
    }

    fn apply_viewport(&self) {
        let r = self.viewport;
        // Negative height flips y so that y-up projections come out upright.
        let viewport = vk::Viewport {
            x: r.offset.x as f32,
            y: (r.offset.y as u32 + r.extent.height) as f32,
            width: r.extent.width as f32,
            height: -(r.extent.height as f32),
            min_depth: 0.0,
            max_depth: 1.0,
        };
        // SAFETY: recording command buffer; values validated in `set_viewport`.
        unsafe {
            let raw = &self.renderer.device.raw;
            raw.cmd_set_viewport(self.cmd, 0, &[viewport]);
            raw.cmd_set_scissor(self.cmd, 0, &[r]);
        }
    }

    /// Begins dynamic rendering (with the clears) if not begun yet.
    pub(crate) fn ensure_rendering(&mut self) {
        if self.rendering {
            return;
        }
        let v = &self.view;
        let clear_color = vk::ClearValue {
            color: vk::ClearColorValue {
                float32: self.clear,
            },
        };
        let mut color = vk::RenderingAttachmentInfo::default()
            .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .clear_value(clear_color);
        color = match v.msaa {
            // Only the resolved image is kept; the multisampled one is discarded.
            Some((_, msaa_view)) => color
                .image_view(msaa_view)
                .store_op(vk::AttachmentStoreOp::DONT_CARE)
                .resolve_mode(vk::ResolveModeFlags::AVERAGE)
                .resolve_image_view(v.view)
                .resolve_image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL),
            None => color
                .image_view(v.view)
                .store_op(vk::AttachmentStoreOp::STORE),
        };
        let colors = [color];
        let depth = vk::RenderingAttachmentInfo::default()
            .image_view(v.depth.1)
            .image_layout(vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(vk::AttachmentStoreOp::DONT_CARE)
            .clear_value(vk::ClearValue {
                depth_stencil: vk::ClearDepthStencilValue {
                    depth: 1.0,
                    stencil: 0,
                },
            });
        let info = vk::RenderingInfo::default()
            .render_area(vk::Rect2D {
                offset: vk::Offset2D::default(),
                extent: v.extent,
            })
            .layer_count(1)
            .color_attachments(&colors)
            .depth_attachment(&depth);
        // SAFETY: recording command buffer; attachments were transitioned at begin.
        unsafe {
            self.renderer
                .device
                .raw
                .cmd_begin_rendering(self.cmd, &info)
        };
        self.rendering = true;
        self.apply_viewport();
    }

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

    fn push_transient<T: Pod>(
        &mut self,
        data: &[T],
    ) -> GpuResult<super::transient::TransientAlloc> {
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

    fn draw_transient(&self, alloc: super::transient::TransientAlloc, count: u32) {
        // SAFETY: recording inside a rendering scope; the data was just written this frame.
        unsafe {
            let raw = &self.renderer.device.raw;
            raw.cmd_bind_vertex_buffers(self.cmd, 0, &[alloc.buffer], &[alloc.offset]);
            raw.cmd_draw(self.cmd, count, 1, 0, 0);
        }
    }

    /// Ends recording, flushes this frame's host writes and submits (and presents, for a
    /// swapchain). Returns the frame number.
    pub fn finish(mut self) -> GpuResult<u64> {
        self.finished = true;
        self.finish_inner()?;
        Ok(self.number)
    }
}

impl Drop for Frame<'_> {
    fn drop(&mut self) {
        if !self.finished {
            self.finished = true;
            if let Err(e) = self.finish_inner() {
                eprintln!("prespline: frame dropped without finish() failed to submit: {e}");
            }
        }
    }
}
