//! Per-frame contexts (one per frame in flight) and the [`Frame`] being recorded: slot,
//! mirror writes, camera, clear and viewport state. Draw calls live in `draw.rs`, the
//! begin/submit protocol in `submit.rs`.

use ash::vk;

use super::device::Device;
use super::draw::{Camera, DrawStats};
use super::error::{GpuError, GpuResult, VkResultExt};
use super::memory::Buffer;
use super::mirror::{Mirror, MirrorWriter};
use super::offscreen::OffscreenTarget;
use super::pipeline::PipelineSet;
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
    /// Whether a submission signalling `fence` is pending. Only such a fence is waited for:
    /// the fence is reset just before submitting, so after a failed submission it would
    /// never signal, and waiting for it would hang the slot forever.
    pub in_flight: bool,
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
            in_flight: false,
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
                // SAFETY: created just above and never used by the GPU.
                unsafe { slot.destroy(device) };
                Err(e)
            }
        }
    }

    /// Waits for the slot's previous submission (if it was submitted), then recycles what it
    /// used. A failed wait leaves everything in place, so a later call may try again.
    pub(crate) fn wait_and_recycle(&mut self, device: &Device) -> GpuResult<()> {
        if self.in_flight {
            device.wait_fence(self.fence)?;
            self.in_flight = false;
            if let Some(t) = self.timer.as_mut() {
                self.gpu_ms = t.read(device).or(self.gpu_ms);
            }
        }
        for b in self.release.drain(..) {
            // SAFETY: released buffers were last used by this slot's previous submission,
            // whose fence was just waited for (or which never happened).
            unsafe { device.destroy_buffer(b) };
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

    /// Destroys everything.
    ///
    /// # Safety
    /// No submitted GPU work that uses these objects may still be pending (the device is idle
    /// or lost, or they were never used).
    pub(crate) unsafe fn destroy(mut self, device: &Device) {
        // SAFETY: the caller guarantees nothing pending uses them (this function's contract).
        unsafe {
            for b in self.release.drain(..) {
                device.destroy_buffer(b);
            }
            if let Some(t) = self.timer.take() {
                t.destroy(device);
            }
            self.transient.destroy(device);
        }
        // SAFETY: idle device; null handles (from a failed `new`) are ignored by Vulkan.
        unsafe {
            device.raw.destroy_semaphore(self.acquire, None);
            device.raw.destroy_fence(self.fence, None);
            device.raw.destroy_command_pool(self.pool, None);
        }
    }
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

/// State bound in the frame's command buffer, so draws skip binding it again.
#[derive(Clone, Copy, Default)]
pub(crate) struct Bound {
    pub pipeline: vk::Pipeline,
    pub vertices: Option<(vk::Buffer, u64)>,
    pub indices: vk::Buffer,
    /// `None` until set after the last pipeline bind.
    pub depth_test: Option<bool>,
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
    pub(crate) bound: Bound,
    pub(crate) stats: DrawStats,
    /// Offscreen only: copy the image into the readback buffer at the end of the frame.
    pub(crate) capture: bool,
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

    /// MSAA samples per pixel of the target.
    pub fn samples(&self) -> u32 {
        self.view.samples.as_raw()
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
        let len = data.len().max(1);
        let mut fresh = Mirror::new(&self.renderer.device, name, len)?;
        let atom = self.renderer.device.caps.non_coherent_atom_size;
        let mut flushes = Vec::new();
        for slot in 0..super::FRAMES_IN_FLIGHT {
            let track = self.renderer.always_flush || fresh.slot(slot).buffer.needs_flush();
            let written = fresh.writer(slot, atom, track, &mut flushes).write(0, data);
            if let Err(e) = written {
                self.renderer.destroy_mirror(fresh);
                return Err(e);
            }
        }
        if let Err(e) = self.renderer.device.flush_ranges(&flushes) {
            self.renderer.destroy_mirror(fresh);
            return Err(e);
        }
        Ok(fresh)
    }

    /// Gives a mirror back; each slot's buffer is released when that slot's fence next
    /// signals (this frame's included), so this never waits.
    pub fn destroy_mirror(&mut self, mirror: Mirror) {
        self.renderer.destroy_mirror(mirror);
    }

    /// Offscreen frames: also copy the finished image into the target's readback buffer, for
    /// [`Renderer::read_pixels`]. Frames that are not captured copy nothing (an image read
    /// back every frame costs a full-image copy nobody looks at). No effect on swapchains.
    pub fn capture(&mut self) {
        self.capture = true;
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
