//! The [`Frame`] being recorded: its slot, mirror writes, camera, clear and viewport state,
//! and the end of the frame protocol (end, flush, submit with synchronization2, present).
//! The draw calls are in `draw.rs`; the renderer begins frames.

use ash::vk;

use super::barrier;
use super::device::Device;
use super::error::{GpuError, GpuResult};
use super::font::Font;
use super::grid::GridCache;
use super::mirror::{Mirror, MirrorWriter};
use super::offscreen::OffscreenTarget;
use super::pipeline::{PipelineKey, Pipelines, Which};
use super::shader::Shaders;
use super::slot::{FrameRing, FrameSlot};
use super::style::Camera;
use super::swapchain::Swapchain;
use super::target::TargetView;
use super::upload::Uploader;

/// Clear colour of a frame until [`Frame::set_clear_color`] (linear RGBA).
const DEFAULT_CLEAR: [f32; 4] = [0.02, 0.02, 0.025, 1.0];

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

/// State bound in the frame's command buffer, so draws skip binding it again.
#[derive(Clone, Copy, Default)]
pub(crate) struct Bound {
    pub pipeline: vk::Pipeline,
    pub vertices: Option<(vk::Buffer, u64)>,
    pub indices: vk::Buffer,
    /// `None` until set after the last pipeline bind.
    pub depth_test: Option<bool>,
}

/// The target a frame renders into.
pub(crate) enum FrameTarget<'a> {
    Offscreen(&'a mut OffscreenTarget),
    Swapchain {
        swapchain: &'a mut Swapchain,
        image_index: u32,
    },
}

/// What a frame borrows from its renderer while it records: the device, the frame slots,
/// the index-buffer cache and its uploader, and the fixed drawing state.
pub(crate) struct FrameContext<'a> {
    pub device: &'a Device,
    pub ring: &'a mut FrameRing,
    pub grids: &'a mut GridCache,
    pub uploader: &'a mut Uploader,
    pub layout: vk::PipelineLayout,
    /// The pipelines, built for the target's key on first use ([`FrameContext::pipeline`]).
    pub pipelines: &'a mut Pipelines,
    pub shaders: &'a Shaders,
    pub key: PipelineKey,
    /// Device address of the overlay font's glyph atlas (0: none).
    pub font: vk::DeviceAddress,
    /// The overlay font the atlas was built from (metrics and layout).
    pub text: &'a Font,
    /// Flush host writes even to coherent memory (see `RendererDesc::always_flush`).
    pub always_flush: bool,
}

impl FrameContext<'_> {
    /// Pipeline `which` for this frame's target, built on first use (creating a pipeline
    /// while a command buffer records is allowed: pipelines are not command-buffer state).
    pub(crate) fn pipeline(&mut self, which: Which) -> GpuResult<vk::Pipeline> {
        self.pipelines
            .get(self.device, self.shaders, self.key, which)
    }

    /// A pipeline built with the set when the frame began (lines, points, overlays).
    pub(crate) fn eager(&self, which: Which) -> vk::Pipeline {
        self.pipelines.eager(self.key, which)
    }
}

/// One frame being recorded. Obtained from [`super::Renderer::begin_offscreen`] or
/// [`super::Renderer::begin_swapchain`]; submit with [`Frame::finish`] (dropping an unfinished frame
/// submits it too, ignoring errors).
///
/// Mirror writes for this frame go through [`Frame::write_mirror`], which targets this
/// frame's slot. Rendering (clear included) starts lazily at the first draw, so
/// [`Frame::set_clear_color`] before any draw is free.
pub struct Frame<'a> {
    pub(crate) ctx: FrameContext<'a>,
    pub(crate) target: FrameTarget<'a>,
    pub(crate) view: TargetView,
    pub(crate) slot: usize,
    pub(crate) number: u64,
    pub(crate) cmd: vk::CommandBuffer,
    pub(crate) rendering: bool,
    pub(crate) clear: [f32; 4],
    pub(crate) camera: Camera,
    pub(crate) viewport: vk::Rect2D,
    pub(crate) flushes: Vec<vk::MappedMemoryRange<'static>>,
    pub(crate) finished: bool,
    pub(crate) bound: Bound,
    pub(crate) stats: DrawStats,
    /// Offscreen only: copy the image into the readback buffer at the end of the frame.
    pub(crate) capture: bool,
    /// Rendering starts from the attachments' contents (a restored or saved static layer)
    /// instead of clearing them.
    pub(crate) load: bool,
    /// Store depth at the end of rendering (a static layer will be saved from it); other
    /// frames let the driver discard it.
    pub(crate) keep_depth: bool,
    /// Draws are clipped to this pixel rectangle within the viewport (`None`: the viewport).
    pub(crate) scissor: Option<vk::Rect2D>,
}

impl<'a> Frame<'a> {
    /// A frame on `slot`, whose command buffer was begun and its barriers recorded.
    pub(crate) fn new(
        ctx: FrameContext<'a>,
        target: FrameTarget<'a>,
        view: TargetView,
        slot: usize,
    ) -> Self {
        let cmd = ctx.ring.slots[slot].cmd;
        let number = ctx.ring.number;
        Frame {
            ctx,
            target,
            view,
            slot,
            number,
            cmd,
            rendering: false,
            clear: DEFAULT_CLEAR,
            camera: Camera::default(),
            viewport: vk::Rect2D {
                offset: vk::Offset2D::default(),
                extent: view.extent,
            },
            flushes: Vec::new(),
            finished: false,
            bound: Bound::default(),
            stats: DrawStats::default(),
            capture: false,
            load: false,
            keep_depth: false,
            scissor: None,
        }
    }

    /// The frame slot this frame records into (`0..FRAMES_IN_FLIGHT`): the caller must bring
    /// this slot of each mirror up to date.
    #[must_use]
    pub fn slot(&self) -> usize {
        self.slot
    }

    /// The overlay font whose atlas [`Frame::draw_overlay`] samples: lay text out with it.
    #[must_use]
    pub fn font(&self) -> &'a Font {
        self.ctx.text
    }

    /// Sequential frame number (0 for the renderer's first frame).
    #[must_use]
    pub fn number(&self) -> u64 {
        self.number
    }

    /// MSAA samples per pixel of the target.
    #[must_use]
    pub fn samples(&self) -> u32 {
        self.view.samples.as_raw()
    }

    /// Target size in pixels.
    #[must_use]
    pub fn extent(&self) -> [u32; 2] {
        [self.view.extent.width, self.view.extent.height]
    }

    /// GPU time in milliseconds of the previous frame recorded in this slot (`None` before
    /// the slot's first completion or without timestamp support).
    #[must_use]
    pub fn gpu_time_ms(&self) -> Option<f64> {
        self.ctx.ring.slots[self.slot].gpu_ms
    }

    /// Write access to this frame's slot of `mirror`. Safe by construction: the slot's
    /// previous GPU use has completed (begin waited for its fence).
    pub fn write_mirror<'m>(&'m mut self, mirror: &'m mut Mirror) -> MirrorWriter<'m> {
        let atom = self.ctx.device.caps.non_coherent_atom_size;
        let track = self.ctx.always_flush || mirror.slot(self.slot).buffer.needs_flush();
        mirror.writer(self.slot, atom, track, &mut self.flushes)
    }

    /// Replaces `mirror` by a new one holding `data` in every slot (a layout change, such as
    /// a refined control net). Never waits: see [`Frame::create_mirror`] and
    /// [`Frame::destroy_mirror`].
    pub fn replace_mirror(
        &mut self,
        mirror: &mut Mirror,
        name: &str,
        data: &[f32],
    ) -> GpuResult<()> {
        let fresh = self.create_mirror(name, data)?;
        let old = std::mem::replace(mirror, fresh);
        self.destroy_mirror(old);
        Ok(())
    }

    /// A new mirror holding `data` (at least one float) in every slot. Never waits: the new
    /// buffers have never been used by the GPU, so all their slots may be written now.
    pub fn create_mirror(&mut self, name: &str, data: &[f32]) -> GpuResult<Mirror> {
        let mut fresh = Mirror::new(self.ctx.device, name, data.len().max(1))?;
        // SAFETY: the new buffers have never been used by the GPU.
        let filled = unsafe { fresh.fill(self.ctx.device, 0, data, self.ctx.always_flush) };
        if let Err(e) = filled {
            self.destroy_mirror(fresh);
            return Err(e);
        }
        Ok(fresh)
    }

    /// Writes `data` into slot `slot` of a mirror this frame created and the GPU has not used
    /// yet (any slot may be written then).
    pub(crate) fn write_new_mirror_slot(
        &mut self,
        mirror: &mut Mirror,
        slot: usize,
        data: &[f32],
    ) -> GpuResult<()> {
        let atom = self.ctx.device.caps.non_coherent_atom_size;
        let track = self.ctx.always_flush || mirror.slot(slot).buffer.needs_flush();
        mirror
            .writer(slot, atom, track, &mut self.flushes)
            .write(0, data)
    }

    /// Gives a mirror back; each slot's buffer is released when that slot's fence next
    /// signals (this frame's included), so this never waits.
    pub fn destroy_mirror(&mut self, mirror: Mirror) {
        self.ctx.ring.release_mirror(self.ctx.device, mirror);
    }

    /// Offscreen frames: also copy the finished image into the target's readback buffer, for
    /// [`super::Renderer::read_pixels`]. Frames that are not captured copy nothing (an image read
    /// back every frame costs a full-image copy nobody looks at). No effect on swapchains.
    pub fn capture(&mut self) {
        self.capture = true;
    }

    /// The camera of subsequent 3D draws.
    #[must_use]
    pub fn camera(&self) -> Camera {
        self.camera
    }

    /// The clear colour (linear RGBA).
    #[must_use]
    pub fn clear_color(&self) -> [f32; 4] {
        self.clear
    }

    /// The viewport, `[x, y, width, height]` in pixels.
    #[must_use]
    pub fn viewport(&self) -> [u32; 4] {
        let r = self.viewport;
        [
            r.offset.x as u32,
            r.offset.y as u32,
            r.extent.width,
            r.extent.height,
        ]
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
                self.ctx
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
        self.scissor = None;
        if self.rendering {
            self.apply_viewport();
        }
        Ok(())
    }

    /// Clips later draws to the pixel rectangle `[x, y, width, height]` (origin top-left),
    /// intersected with the viewport; `None` clips to the viewport again.
    pub fn set_scissor(&mut self, rect: Option<[u32; 4]>) {
        let v = self.viewport;
        self.scissor = rect.map(|[x, y, w, h]| {
            let (vx, vy) = (v.offset.x as u32, v.offset.y as u32);
            let x0 = x.clamp(vx, vx + v.extent.width);
            let y0 = y.clamp(vy, vy + v.extent.height);
            let x1 = x.saturating_add(w).clamp(x0, vx + v.extent.width);
            let y1 = y.saturating_add(h).clamp(y0, vy + v.extent.height);
            vk::Rect2D {
                offset: vk::Offset2D {
                    x: x0 as i32,
                    y: y0 as i32,
                },
                extent: vk::Extent2D {
                    width: x1 - x0,
                    height: y1 - y0,
                },
            }
        });
        if self.rendering {
            self.apply_viewport();
        }
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
            let raw = &self.ctx.device.raw;
            raw.cmd_set_viewport(self.cmd, 0, &[viewport]);
            raw.cmd_set_scissor(self.cmd, 0, &[self.scissor.unwrap_or(r)]);
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
        let load_op = if self.load {
            vk::AttachmentLoadOp::LOAD
        } else {
            vk::AttachmentLoadOp::CLEAR
        };
        // Depth is kept only where a static layer will be saved from it.
        let depth_store = if v.layer && self.keep_depth {
            vk::AttachmentStoreOp::STORE
        } else {
            vk::AttachmentStoreOp::DONT_CARE
        };
        let mut color = vk::RenderingAttachmentInfo::default()
            .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
            .load_op(load_op)
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
            .load_op(load_op)
            .store_op(depth_store)
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
        unsafe { self.ctx.device.raw.cmd_begin_rendering(self.cmd, &info) };
        self.rendering = true;
        self.apply_viewport();
    }

    /// Ends recording, flushes this frame's host writes and submits (and presents, for a
    /// swapchain). Returns the frame number.
    pub fn finish(mut self) -> GpuResult<u64> {
        self.finished = true;
        self.finish_inner()?;
        Ok(self.number)
    }

    /// Records the end of the frame, flushes host writes, submits and presents.
    ///
    /// If anything fails before the submission is accepted, the slot stays usable: its fence
    /// is only waited for when a submission will signal it, and a swapchain image's acquire
    /// semaphore, already signalled, is consumed by an empty submission so the slot can
    /// acquire again.
    fn finish_inner(&mut self) -> GpuResult<()> {
        match self.record_and_submit() {
            Ok(()) => {
                self.ctx.ring.number += 1;
                match &mut self.target {
                    FrameTarget::Swapchain {
                        swapchain,
                        image_index,
                    } => {
                        let wait = swapchain.render_finished[*image_index as usize];
                        swapchain.present(self.ctx.device, *image_index, wait)
                    }
                    FrameTarget::Offscreen(_) => Ok(()),
                }
            }
            Err(e) => {
                self.recover_unsubmitted();
                Err(e)
            }
        }
    }

    /// Ends recording and submits; the offscreen image is copied out when captured.
    fn record_and_submit(&mut self) -> GpuResult<()> {
        // Begin rendering even for an empty frame so the clear happens.
        self.ensure_rendering();
        let (cmd, slot, device) = (self.cmd, self.slot, self.ctx.device);
        // SAFETY: `cmd` is recording inside the rendering scope begun above.
        unsafe { device.raw.cmd_end_rendering(cmd) };
        let signal = match &mut self.target {
            FrameTarget::Offscreen(target) => {
                // Until this submission is accepted, no pixels are readable.
                target.last_slot = None;
                if self.capture {
                    // SAFETY: recording outside rendering; the slot's readback buffer is not
                    // read by the host until this submission's fence signals.
                    unsafe { target.record_readback(device, cmd, slot) };
                }
                None
            }
            FrameTarget::Swapchain {
                swapchain,
                image_index,
            } => {
                // SAFETY: recording outside rendering; the image is this frame's.
                unsafe { barrier::record(&device.raw, cmd, &[barrier::to_present(&self.view)]) };
                Some(swapchain.render_finished[*image_index as usize])
            }
        };
        let ring: &mut FrameRing = self.ctx.ring;
        let frame_slot: &mut FrameSlot = &mut ring.slots[slot];
        frame_slot.submit(device, &mut self.flushes, signal, &mut ring.submit_fault)?;
        if let FrameTarget::Offscreen(target) = &mut self.target {
            target.last_slot = self.capture.then_some(slot);
        }
        Ok(())
    }

    /// After a failure before submission: a swapchain frame's acquire semaphore is signalled
    /// and would make the slot's next acquire invalid, so it is consumed, and the swapchain
    /// is rebuilt at the next begin, which releases the image that will not be presented.
    fn recover_unsubmitted(&mut self) {
        let FrameTarget::Swapchain { swapchain, .. } = &mut self.target else {
            return;
        };
        swapchain.stale = true;
        self.ctx.ring.slots[self.slot].consume_acquire(self.ctx.device);
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
