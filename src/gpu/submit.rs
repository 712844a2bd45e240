//! The frame protocol: begin (wait for the slot, acquire, transition), finish (end, flush,
//! submit with synchronization2, present).
//!
//! Target images (depth, MSAA colour, the offscreen colour image) are shared by both frame
//! slots. Each frame starts with a barrier from `UNDEFINED` whose source scope covers the
//! previous frame's accesses, which serialises the two slots on those images while leaving
//! host-side work (mirror writes, recording) overlapped with the GPU.

use ash::vk;

use super::FRAMES_IN_FLIGHT;
use super::draw::Camera;
use super::error::{GpuError, GpuResult, VkResultExt, vk_error};
use super::frame::{Frame, FrameTarget, TargetView};
use super::image::full_range;
use super::offscreen::OffscreenTarget;
use super::pipeline::{DEPTH_FORMAT, PipelineKey, PipelineSet};
use super::renderer::{Fault, Renderer};
use super::swapchain::Swapchain;

const DEFAULT_CLEAR: [f32; 4] = [0.02, 0.02, 0.025, 1.0];

fn image_barrier(
    image: vk::Image,
    format: vk::Format,
    src: (vk::PipelineStageFlags2, vk::AccessFlags2),
    dst: (vk::PipelineStageFlags2, vk::AccessFlags2),
    layouts: (vk::ImageLayout, vk::ImageLayout),
) -> vk::ImageMemoryBarrier2<'static> {
    vk::ImageMemoryBarrier2::default()
        .src_stage_mask(src.0)
        .src_access_mask(src.1)
        .dst_stage_mask(dst.0)
        .dst_access_mask(dst.1)
        .old_layout(layouts.0)
        .new_layout(layouts.1)
        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .image(image)
        .subresource_range(full_range(format))
}

/// Barriers that discard last frame's contents and make every attachment writable.
fn begin_barriers(view: &TargetView, swapchain: bool) -> Vec<vk::ImageMemoryBarrier2<'static>> {
    use vk::AccessFlags2 as A;
    use vk::PipelineStageFlags2 as S;
    let color_stage = S::COLOR_ATTACHMENT_OUTPUT;
    let color_dst = (
        color_stage,
        A::COLOR_ATTACHMENT_WRITE | A::COLOR_ATTACHMENT_READ,
    );
    let to_color = (
        vk::ImageLayout::UNDEFINED,
        vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
    );
    // A swapchain image comes from the acquire semaphore, waited at COLOR_ATTACHMENT_OUTPUT;
    // the offscreen image was last read by the previous frame's copy.
    let target_src = if swapchain {
        (color_stage, A::NONE)
    } else {
        (color_stage | S::COPY, A::COLOR_ATTACHMENT_WRITE)
    };
    let mut barriers = vec![image_barrier(
        view.image,
        view.format,
        target_src,
        color_dst,
        to_color,
    )];
    if let Some((msaa, _)) = view.msaa {
        barriers.push(image_barrier(
            msaa,
            view.format,
            (color_stage, A::COLOR_ATTACHMENT_WRITE),
            color_dst,
            to_color,
        ));
    }
    let depth_stages = S::EARLY_FRAGMENT_TESTS | S::LATE_FRAGMENT_TESTS;
    barriers.push(image_barrier(
        view.depth.0,
        DEPTH_FORMAT,
        (depth_stages, A::DEPTH_STENCIL_ATTACHMENT_WRITE),
        (
            depth_stages,
            A::DEPTH_STENCIL_ATTACHMENT_READ | A::DEPTH_STENCIL_ATTACHMENT_WRITE,
        ),
        (
            vk::ImageLayout::UNDEFINED,
            vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
        ),
    ));
    barriers
}

fn pipeline_key(view: &TargetView) -> PipelineKey {
    PipelineKey {
        color_format: view.format,
        samples: view.samples,
    }
}

impl Renderer {
    /// Begins a frame rendering into `target`. Waits for the slot's previous use.
    pub fn begin_offscreen<'a>(
        &'a mut self,
        target: &'a mut OffscreenTarget,
    ) -> GpuResult<Frame<'a>> {
        let slot = self.next_slot()?;
        let view = target.view();
        self.start(FrameTarget::Offscreen(target), view, slot)
    }

    /// Begins a frame on the next swapchain image. Returns `None` when there is nothing to
    /// draw to right now (window minimised, or the swapchain just went out of date); simply
    /// try again next frame.
    pub fn begin_swapchain<'a>(
        &'a mut self,
        swapchain: &'a mut Swapchain,
    ) -> GpuResult<Option<Frame<'a>>> {
        self.collect_retired(swapchain, false);
        if swapchain.stale && !self.rebuild_swapchain(swapchain)? {
            return Ok(None);
        }
        // Build the pipelines before acquiring: once an image is acquired, the frame must be
        // submitted, or the slot's acquire semaphore stays signalled.
        if let Some(view) = swapchain.view(0) {
            self.pipelines
                .get(&self.device, &self.shaders, pipeline_key(&view))?;
        }
        let slot = self.next_slot()?;
        let Some(swapchain_fn) = self.device.swapchain_fn.as_ref() else {
            return Err(GpuError::Surface("device has no VK_KHR_swapchain".into()));
        };
        let acquire = self.frames[slot].acquire;
        let limit = u64::try_from(super::WAIT_LIMIT.as_nanos()).unwrap_or(u64::MAX);
        // SAFETY: valid swapchain; the slot's acquire semaphore is unsignalled and not in use
        // (its previous waiter, this slot's last submission, has completed).
        let acquired = unsafe {
            swapchain_fn.acquire_next_image(swapchain.raw, limit, acquire, vk::Fence::null())
        };
        let image_index = match acquired {
            Ok((index, suboptimal)) => {
                // Still presentable; rebuild after this frame.
                swapchain.stale |= suboptimal;
                index
            }
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => {
                swapchain.stale = true;
                return Ok(None);
            }
            Err(result) => return Err(vk_error("vkAcquireNextImageKHR", result)),
        };
        // From here on the acquire semaphore is signalled: every way out must consume it.
        let Some(view) = swapchain.view(image_index) else {
            swapchain.stale = true;
            self.consume_acquire(slot);
            return Err(GpuError::Surface(format!(
                "acquired image {image_index} does not exist"
            )));
        };
        let pipelines = match self.prepare(view, slot, true) {
            Ok(p) => p,
            Err(e) => {
                swapchain.stale = true;
                self.consume_acquire(slot);
                return Err(e);
            }
        };
        let target = FrameTarget::Swapchain {
            swapchain,
            image_index,
        };
        Ok(Some(self.frame(target, view, slot, pipelines)))
    }

    /// Consumes a signalled acquire semaphore of `slot` with an empty submission that also
    /// signals the slot's fence, so the slot can acquire again. Best effort: it runs only on
    /// error paths, whose error is the one reported.
    pub(crate) fn consume_acquire(&mut self, slot: usize) {
        let device = &*self.device;
        let frame_slot = &mut self.frames[slot];
        let waits = [vk::SemaphoreSubmitInfo::default()
            .semaphore(frame_slot.acquire)
            .stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)];
        let submit = [vk::SubmitInfo2::default().wait_semaphore_infos(&waits)];
        // SAFETY: no submission using the slot's fence is pending (`in_flight` is false: the
        // slot was waited for at begin and the failed frame never submitted), so it may be
        // reset; the acquire semaphore has a pending signal and no waiter yet.
        let consumed = unsafe {
            device.raw.reset_fences(&[frame_slot.fence]).and_then(|()| {
                device
                    .raw
                    .queue_submit2(device.queue, &submit, frame_slot.fence)
            })
        };
        frame_slot.in_flight = consumed.is_ok();
    }

    /// Waits for the next slot's previous submission and recycles its resources.
    fn next_slot(&mut self) -> GpuResult<usize> {
        let slot = (self.frame_number % FRAMES_IN_FLIGHT as u64) as usize;
        self.frames[slot].wait_and_recycle(&self.device)?;
        Ok(slot)
    }

    fn start<'a>(
        &'a mut self,
        target: FrameTarget<'a>,
        view: TargetView,
        slot: usize,
    ) -> GpuResult<Frame<'a>> {
        let swapchain = matches!(target, FrameTarget::Swapchain { .. });
        let pipelines = self.prepare(view, slot, swapchain)?;
        Ok(self.frame(target, view, slot, pipelines))
    }

    /// The fallible part of starting a frame: pipelines for the target, the slot's command
    /// buffer begun, the attachments' barriers recorded.
    fn prepare(
        &mut self,
        view: TargetView,
        slot: usize,
        swapchain: bool,
    ) -> GpuResult<PipelineSet> {
        let pipelines = *self
            .pipelines
            .get(&self.device, &self.shaders, pipeline_key(&view))?;
        let frame_slot = &mut self.frames[slot];
        frame_slot.begin_commands(&self.device)?;
        let cmd = frame_slot.cmd;
        let barriers = begin_barriers(&view, swapchain);
        // SAFETY: `cmd` is recording; images are live and owned by the target.
        unsafe {
            self.device.raw.cmd_pipeline_barrier2(
                cmd,
                &vk::DependencyInfo::default().image_memory_barriers(&barriers),
            )
        };
        Ok(pipelines)
    }

    fn frame<'a>(
        &'a mut self,
        target: FrameTarget<'a>,
        view: TargetView,
        slot: usize,
        pipelines: PipelineSet,
    ) -> Frame<'a> {
        let cmd = self.frames[slot].cmd;
        let number = self.frame_number;
        Frame {
            renderer: self,
            target,
            view,
            slot,
            number,
            cmd,
            pipelines,
            rendering: false,
            clear: DEFAULT_CLEAR,
            camera: Camera::default(),
            viewport: vk::Rect2D {
                offset: vk::Offset2D::default(),
                extent: view.extent,
            },
            flushes: Vec::new(),
            finished: false,
            bound: Default::default(),
            stats: Default::default(),
            capture: false,
        }
    }
}

/// What a successful submission leaves to do: present a swapchain image.
struct Submitted {
    present: Option<(vk::SwapchainKHR, u32, vk::Semaphore)>,
}

impl Frame<'_> {
    /// Records the end of the frame, flushes host writes, submits and presents.
    ///
    /// If anything fails before the submission is accepted, the slot stays usable: its fence
    /// is only waited for when a submission will signal it, and a swapchain image's acquire
    /// semaphore, already signalled, is consumed by an empty submission so the slot can
    /// acquire again.
    pub(crate) fn finish_inner(&mut self) -> GpuResult<()> {
        match self.record_and_submit() {
            Ok(submitted) => {
                self.renderer.frame_number += 1;
                self.present(submitted)
            }
            Err(e) => {
                self.recover_unsubmitted();
                Err(e)
            }
        }
    }

    /// Ends recording and submits; the offscreen image is copied out when captured.
    fn record_and_submit(&mut self) -> GpuResult<Submitted> {
        // Begin rendering even for an empty frame so the clear happens.
        self.ensure_rendering();
        let cmd = self.cmd;
        let slot = self.slot;
        let view = self.view;
        let capture = self.capture;
        let renderer = &mut *self.renderer;
        let device = &*renderer.device;
        let raw = &device.raw;
        use vk::AccessFlags2 as A;
        use vk::PipelineStageFlags2 as S;
        // SAFETY: `cmd` is recording inside the rendering scope begun above.
        unsafe { raw.cmd_end_rendering(cmd) };
        match &mut self.target {
            FrameTarget::Offscreen(target) => {
                // Until this submission is accepted, no pixels are readable.
                target.last_slot = None;
                if capture {
                    record_readback(device, cmd, &view, &target.readback[slot]);
                }
            }
            FrameTarget::Swapchain { .. } => {
                let to_present = [image_barrier(
                    view.image,
                    view.format,
                    (S::COLOR_ATTACHMENT_OUTPUT, A::COLOR_ATTACHMENT_WRITE),
                    (S::ALL_COMMANDS, A::NONE),
                    (
                        vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
                        vk::ImageLayout::PRESENT_SRC_KHR,
                    ),
                )];
                // SAFETY: recording outside rendering; the image is this frame's.
                unsafe {
                    raw.cmd_pipeline_barrier2(
                        cmd,
                        &vk::DependencyInfo::default().image_memory_barriers(&to_present),
                    )
                };
            }
        }
        let frame_slot = &mut renderer.frames[slot];
        if let Some(t) = frame_slot.timer.as_mut() {
            t.end(device, cmd);
        }
        // SAFETY: `cmd` is recording and every scope opened in it was closed.
        unsafe { raw.end_command_buffer(cmd) }.vk("vkEndCommandBuffer")?;

        // Host writes need no barrier before submit (submission makes them visible), but
        // non-coherent memory needs its written ranges flushed first.
        let atom = device.caps.non_coherent_atom_size;
        frame_slot.transient.flush_ranges(atom, &mut self.flushes);
        device.flush_ranges(&self.flushes)?;
        self.flushes.clear();

        let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
        let mut waits = Vec::new();
        let mut signals = Vec::new();
        let mut present = None;
        if let FrameTarget::Swapchain {
            swapchain,
            image_index,
        } = &self.target
        {
            waits.push(
                vk::SemaphoreSubmitInfo::default()
                    .semaphore(frame_slot.acquire)
                    .stage_mask(S::COLOR_ATTACHMENT_OUTPUT),
            );
            let finished = swapchain.render_finished[*image_index as usize];
            signals.push(
                vk::SemaphoreSubmitInfo::default()
                    .semaphore(finished)
                    .stage_mask(S::ALL_COMMANDS),
            );
            present = Some((swapchain.raw, *image_index, finished));
        }
        let submit = [vk::SubmitInfo2::default()
            .wait_semaphore_infos(&waits)
            .command_buffer_infos(&cmds)
            .signal_semaphore_infos(&signals)];
        // SAFETY: the slot has no pending submission (begin waited for it, or the last one
        // failed), so its fence is not in use and may be reset.
        unsafe { raw.reset_fences(&[frame_slot.fence]) }.vk("vkResetFences")?;
        if let Some(Fault::Submit(result)) = renderer.fault.take() {
            return Err(vk_error("vkQueueSubmit2", result));
        }
        // SAFETY: the command buffer is executable, the fence unsignalled and unused, and the
        // queue is only used from `&mut Renderer`.
        unsafe { raw.queue_submit2(device.queue, &submit, frame_slot.fence) }
            .vk("vkQueueSubmit2")?;
        frame_slot.in_flight = true;
        if let FrameTarget::Offscreen(target) = &mut self.target {
            target.last_slot = capture.then_some(slot);
        }
        Ok(Submitted { present })
    }

    fn present(&mut self, submitted: Submitted) -> GpuResult<()> {
        let device = &*self.renderer.device;
        let (Some((swapchain_raw, index, wait)), Some(swapchain_fn)) =
            (submitted.present, device.swapchain_fn.as_ref())
        else {
            return Ok(());
        };
        let swapchains = [swapchain_raw];
        let indices = [index];
        let waits = [wait];
        let info = vk::PresentInfoKHR::default()
            .wait_semaphores(&waits)
            .swapchains(&swapchains)
            .image_indices(&indices);
        // SAFETY: the image was acquired this frame and its semaphore is signalled by the
        // submission above.
        let result = unsafe { swapchain_fn.queue_present(device.queue, &info) };
        let stale = match result {
            Ok(suboptimal) => suboptimal,
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => true,
            Err(result) => return Err(vk_error("vkQueuePresentKHR", result)),
        };
        if let FrameTarget::Swapchain { swapchain, .. } = &mut self.target {
            swapchain.stale |= stale;
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
        self.renderer.consume_acquire(self.slot);
    }
}

/// Copies the offscreen image into `readback` and makes it visible to the host.
fn record_readback(
    device: &super::device::Device,
    cmd: vk::CommandBuffer,
    view: &TargetView,
    readback: &super::memory::Buffer,
) {
    use vk::AccessFlags2 as A;
    use vk::PipelineStageFlags2 as S;
    let raw = &device.raw;
    let to_src = [image_barrier(
        view.image,
        view.format,
        (S::COLOR_ATTACHMENT_OUTPUT, A::COLOR_ATTACHMENT_WRITE),
        (S::COPY, A::TRANSFER_READ),
        (
            vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
        ),
    )];
    let region = vk::BufferImageCopy {
        buffer_offset: 0,
        buffer_row_length: 0,
        buffer_image_height: 0,
        image_subresource: vk::ImageSubresourceLayers {
            aspect_mask: vk::ImageAspectFlags::COLOR,
            mip_level: 0,
            base_array_layer: 0,
            layer_count: 1,
        },
        image_offset: vk::Offset3D::default(),
        image_extent: vk::Extent3D {
            width: view.extent.width,
            height: view.extent.height,
            depth: 1,
        },
    };
    let to_host = [vk::BufferMemoryBarrier2::default()
        .src_stage_mask(S::COPY)
        .src_access_mask(A::TRANSFER_WRITE)
        .dst_stage_mask(S::HOST)
        .dst_access_mask(A::HOST_READ)
        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .buffer(readback.raw)
        .offset(0)
        .size(vk::WHOLE_SIZE)];
    // SAFETY: recording outside rendering; the slot's readback buffer is not read by the host
    // until this submission's fence signals.
    unsafe {
        raw.cmd_pipeline_barrier2(
            cmd,
            &vk::DependencyInfo::default().image_memory_barriers(&to_src),
        );
        raw.cmd_copy_image_to_buffer(
            cmd,
            view.image,
            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
            readback.raw,
            &[region],
        );
        raw.cmd_pipeline_barrier2(
            cmd,
            &vk::DependencyInfo::default().buffer_memory_barriers(&to_host),
        );
    }
}
