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
use super::error::{GpuError, GpuResult, VkResultExt};
use super::frame::{Frame, FrameTarget, TargetView};
use super::image::full_range;
use super::offscreen::OffscreenTarget;
use super::pipeline::{DEPTH_FORMAT, PipelineKey};
use super::renderer::Renderer;
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
        // SAFETY: valid swapchain; the slot's acquire semaphore is unsignalled and not in use
        // (its previous waiter, this slot's last submission, has completed).
        let acquired = unsafe {
            swapchain_fn.acquire_next_image(swapchain.raw, u64::MAX, acquire, vk::Fence::null())
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
            Err(result) => {
                return Err(GpuError::Vk {
                    call: "vkAcquireNextImageKHR",
                    result,
                });
            }
        };
        let Some(view) = swapchain.view(image_index) else {
            return Err(GpuError::Surface(format!(
                "acquired image {image_index} does not exist"
            )));
        };
        let target = FrameTarget::Swapchain {
            swapchain,
            image_index,
        };
        self.start(target, view, slot).map(Some)
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
        let pipelines = *self
            .pipelines
            .get(&self.device, &self.shaders, pipeline_key(&view))?;
        let frame_slot = &mut self.frames[slot];
        frame_slot.begin_commands(&self.device)?;
        let cmd = frame_slot.cmd;
        let barriers = begin_barriers(&view, matches!(target, FrameTarget::Swapchain { .. }));
        // SAFETY: `cmd` is recording; images are live and owned by the target.
        unsafe {
            self.device.raw.cmd_pipeline_barrier2(
                cmd,
                &vk::DependencyInfo::default().image_memory_barriers(&barriers),
            )
        };
        let number = self.frame_number;
        Ok(Frame {
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
        })
    }
}

impl Frame<'_> {
    /// Records the end of the frame, flushes host writes, submits and presents.
    pub(crate) fn finish_inner(&mut self) -> GpuResult<()> {
        // Begin rendering even for an empty frame so the clear happens.
        self.ensure_rendering();
        let cmd = self.cmd;
        let slot = self.slot;
        let view = self.view;
        let renderer = &mut *self.renderer;
        let device = &*renderer.device;
        let raw = &device.raw;
        use vk::AccessFlags2 as A;
        use vk::PipelineStageFlags2 as S;
        // SAFETY: `cmd` is recording inside the rendering scope begun above.
        unsafe { raw.cmd_end_rendering(cmd) };
        let capture = self.capture;
        match &mut self.target {
            FrameTarget::Offscreen(target) if !capture => {
                // Nothing to copy; the next frame's begin barrier orders its writes after ours.
                // Older captured pixels no longer show what the target holds.
                target.last_slot = None;
            }
            FrameTarget::Offscreen(target) => {
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
                let readback = &target.readback[slot];
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
                // SAFETY: recording outside rendering; the readback buffer of this slot is
                // not read by the host until this submission's fence signals.
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
                target.last_slot = Some(slot);
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
        // SAFETY: the fence is signalled and unused (waited at begin); resetting it only now
        // means an error anywhere above leaves it signalled, so the slot never deadlocks.
        unsafe {
            raw.reset_fences(&[frame_slot.fence]).vk("vkResetFences")?;
            raw.queue_submit2(device.queue, &submit, frame_slot.fence)
                .vk("vkQueueSubmit2")?;
        }
        renderer.frame_number += 1;

        if let (Some((swapchain_raw, index, wait)), Some(swapchain_fn)) =
            (present, device.swapchain_fn.as_ref())
        {
            let swapchains = [swapchain_raw];
            let indices = [index];
            let waits = [wait];
            let info = vk::PresentInfoKHR::default()
                .wait_semaphores(&waits)
                .swapchains(&swapchains)
                .image_indices(&indices);
            // SAFETY: the image was acquired this frame and its semaphore is signalled by
            // the submission above.
            let result = unsafe { swapchain_fn.queue_present(device.queue, &info) };
            let stale = match result {
                Ok(suboptimal) => suboptimal,
                Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => true,
                Err(result) => {
                    return Err(GpuError::Vk {
                        call: "vkQueuePresentKHR",
                        result,
                    });
                }
            };
            if let FrameTarget::Swapchain { swapchain, .. } = &mut self.target {
                swapchain.stale |= stale;
            }
        }
        Ok(())
    }
}
