//! Per-frame contexts: one [`FrameSlot`] per frame in flight (command buffer, fence, acquire
//! semaphore, timer, transient memory, deferred releases) and the [`FrameRing`] that cycles
//! through them. A slot is reused every `FRAMES_IN_FLIGHT` frames, after its fence says the
//! GPU finished the previous use.

use ash::vk;

use super::FRAMES_IN_FLIGHT;
use super::device::Device;
use super::error::{GpuResult, VkResultExt, vk_error};
use super::memory::Buffer;
use super::mirror::Mirror;
use super::timestamp::GpuTimer;
use super::transient::TransientBuffer;

/// Everything one frame slot owns.
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

    /// Ends the command buffer, flushes the frame's host writes (`flushes`, plus this slot's
    /// transient memory) and submits it, signalling the slot's fence. A swapchain frame
    /// (`present`: its image's render-finished semaphore) also waits for the slot's acquire
    /// semaphore and signals `present`. `fault` (a test hook), when set, is taken and
    /// reported instead of submitting.
    pub(crate) fn submit(
        &mut self,
        device: &Device,
        flushes: &mut Vec<vk::MappedMemoryRange<'static>>,
        present: Option<vk::Semaphore>,
        fault: &mut Option<vk::Result>,
    ) -> GpuResult<()> {
        use vk::PipelineStageFlags2 as S;
        let raw = &device.raw;
        if let Some(t) = self.timer.as_mut() {
            t.end(device, self.cmd);
        }
        // SAFETY: `cmd` is recording and every scope opened in it was closed.
        unsafe { raw.end_command_buffer(self.cmd) }.vk("vkEndCommandBuffer")?;

        // Host writes need no barrier before submit (submission makes them visible), but
        // non-coherent memory needs its written ranges flushed first.
        let atom = device.caps.non_coherent_atom_size;
        self.transient.flush_ranges(atom, flushes);
        device.flush_ranges(flushes)?;
        flushes.clear();

        let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(self.cmd)];
        let mut waits = Vec::new();
        let mut signals = Vec::new();
        if let Some(finished) = present {
            waits.push(
                vk::SemaphoreSubmitInfo::default()
                    .semaphore(self.acquire)
                    .stage_mask(S::COLOR_ATTACHMENT_OUTPUT),
            );
            signals.push(
                vk::SemaphoreSubmitInfo::default()
                    .semaphore(finished)
                    .stage_mask(S::ALL_COMMANDS),
            );
        }
        let submit = [vk::SubmitInfo2::default()
            .wait_semaphore_infos(&waits)
            .command_buffer_infos(&cmds)
            .signal_semaphore_infos(&signals)];
        // SAFETY: the slot has no pending submission (begin waited for it, or the last one
        // failed), so its fence is not in use and may be reset.
        unsafe { raw.reset_fences(&[self.fence]) }.vk("vkResetFences")?;
        if let Some(result) = fault.take() {
            return Err(vk_error("vkQueueSubmit2", result));
        }
        // SAFETY: the command buffer is executable, the fence unsignalled and unused, and the
        // queue is only used from `&mut Renderer`.
        unsafe { raw.queue_submit2(device.queue, &submit, self.fence) }.vk("vkQueueSubmit2")?;
        self.in_flight = true;
        Ok(())
    }

    /// Consumes a signalled acquire semaphore with an empty submission that also signals the
    /// slot's fence, so the slot can acquire again. Best effort: it runs only on error paths,
    /// whose error is the one reported.
    pub(crate) fn consume_acquire(&mut self, device: &Device) {
        let waits = [vk::SemaphoreSubmitInfo::default()
            .semaphore(self.acquire)
            .stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)];
        let submit = [vk::SubmitInfo2::default().wait_semaphore_infos(&waits)];
        // SAFETY: no submission using the slot's fence is pending (`in_flight` is false: the
        // slot was waited for at begin and the failed frame never submitted), so it may be
        // reset; the acquire semaphore has a pending signal and no waiter yet.
        let consumed = unsafe {
            device
                .raw
                .reset_fences(&[self.fence])
                .and_then(|()| device.raw.queue_submit2(device.queue, &submit, self.fence))
        };
        self.in_flight = consumed.is_ok();
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

/// The frame slots and the count of frames begun: frame `n` records into slot
/// `n % FRAMES_IN_FLIGHT`.
#[derive(Default)]
pub(crate) struct FrameRing {
    pub slots: Vec<FrameSlot>,
    /// Frames begun so far whose submission was accepted (the next frame's number).
    pub number: u64,
    /// Test hook: the next frame submission fails with this result instead of reaching
    /// the driver (after its fence was reset).
    pub submit_fault: Option<vk::Result>,
}

impl FrameRing {
    /// Waits for the next slot's previous submission and recycles its resources.
    pub(crate) fn next_slot(&mut self, device: &Device) -> GpuResult<usize> {
        let slot = (self.number % FRAMES_IN_FLIGHT as u64) as usize;
        self.slots[slot].wait_and_recycle(device)?;
        Ok(slot)
    }

    /// Waits for every slot's previous submission (nothing the GPU reads is in flight after).
    pub(crate) fn wait_all(&mut self, device: &Device) -> GpuResult<()> {
        for s in &mut self.slots {
            s.wait_and_recycle(device)?;
        }
        Ok(())
    }

    /// Waits for `slot`'s last accepted submission, if one is pending.
    pub(crate) fn wait_slot(&self, device: &Device, slot: usize) -> GpuResult<()> {
        let s = &self.slots[slot];
        // A slot not in flight finished its last accepted submission (it was waited for).
        if s.in_flight {
            device.wait_fence(s.fence)?;
        }
        Ok(())
    }

    /// GPU time (ms) of the most recent frame whose timing is known.
    pub(crate) fn last_gpu_time_ms(&self) -> Option<f64> {
        let prev = (self.number + FRAMES_IN_FLIGHT as u64 - 1) as usize % FRAMES_IN_FLIGHT;
        self.slots
            .get(prev)
            .and_then(|f| f.gpu_ms)
            .or_else(|| self.slots.iter().find_map(|f| f.gpu_ms))
    }

    /// Gives a mirror back: each slot's buffer is released when that slot's fence next
    /// signals, so this never waits.
    pub(crate) fn release_mirror(&mut self, device: &Device, mirror: Mirror) {
        for (i, b) in mirror.slots.into_iter().enumerate() {
            match self.slots.get_mut(i) {
                Some(f) => f.release.push(b.buffer),
                // No slot, so no frame ever used this buffer.
                // SAFETY: a buffer without a frame slot was never bound by a submission.
                None => unsafe { device.destroy_buffer(b.buffer) },
            }
        }
    }

    /// Destroys every slot.
    ///
    /// # Safety
    /// No submitted GPU work that uses the slots' objects may still be pending (the device is
    /// idle or lost).
    pub(crate) unsafe fn destroy(&mut self, device: &Device) {
        for f in std::mem::take(&mut self.slots) {
            // SAFETY: the caller guarantees nothing pending uses them (this function's contract).
            unsafe { f.destroy(device) };
        }
    }
}
