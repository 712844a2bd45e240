//! Synchronous uploads of static data (grid index buffers) into device-local buffers.
//!
//! Static data is created rarely (once per grid shape), so a blocking staging copy on the
//! graphics queue is simpler than threading uploads through the frame's command buffer.

use ash::vk;
use gpu_allocator::MemoryLocation;

use super::device::Device;
use super::error::{GpuError, GpuResult, VkResultExt, vk_error};
use super::memory::{Buffer, BufferDesc};

#[derive(Default)]
pub(crate) struct Uploader {
    pool: vk::CommandPool,
    fence: vk::Fence,
    /// Buffers of an upload whose completion could not be established (the wait failed and
    /// so did waiting for the device): the GPU may still use them, so they are only destroyed
    /// with the uploader, after the renderer's final wait.
    orphans: Vec<Buffer>,
    /// Set when a copy may still be pending on `pool`: the pool and fence are unusable.
    poisoned: bool,
    /// Error-path tests: the next wait for an upload reports this instead of waiting.
    fail_wait: Option<vk::Result>,
}

/// How far an upload got before failing.
enum Failure {
    /// Nothing is pending on the GPU: every resource may be released.
    Idle(GpuError),
    /// The copy may still be running: its resources must outlive it.
    Pending(GpuError),
}

impl Uploader {
    pub(crate) fn new(device: &Device) -> GpuResult<Self> {
        let info = vk::CommandPoolCreateInfo::default()
            .flags(vk::CommandPoolCreateFlags::TRANSIENT)
            .queue_family_index(device.queue_family);
        // SAFETY: valid device and queue family.
        let pool =
            unsafe { device.raw.create_command_pool(&info, None) }.vk("vkCreateCommandPool")?;
        // SAFETY: valid device.
        let fence = match unsafe {
            device
                .raw
                .create_fence(&vk::FenceCreateInfo::default(), None)
        } {
            Ok(f) => f,
            Err(result) => {
                // SAFETY: the pool is unused.
                unsafe { device.raw.destroy_command_pool(pool, None) };
                return Err(GpuError::Vk {
                    call: "vkCreateFence",
                    result,
                });
            }
        };
        Ok(Self {
            pool,
            fence,
            ..Self::default()
        })
    }

    /// Makes the next upload's fence wait report `result` (error-path tests).
    pub(crate) fn fail_next_wait(&mut self, result: vk::Result) {
        self.fail_wait = Some(result);
    }

    /// Creates a device-local buffer holding `bytes`, readable by `dst_stage`/`dst_access`
    /// in any later submission. Blocks until the copy has finished.
    pub(crate) fn upload(
        &mut self,
        device: &Device,
        name: &str,
        bytes: &[u8],
        usage: vk::BufferUsageFlags,
        dst_stage: vk::PipelineStageFlags2,
        dst_access: vk::AccessFlags2,
    ) -> GpuResult<Buffer> {
        if self.poisoned {
            return Err(GpuError::DeviceLost {
                call: "vkDeviceWaitIdle (after an earlier upload failed)",
            });
        }
        let size = bytes.len() as u64;
        let staging = device.create_buffer(&BufferDesc {
            name: "staging",
            size,
            usage: vk::BufferUsageFlags::TRANSFER_SRC,
            location: MemoryLocation::CpuToGpu,
        })?;
        let result = self.copy_via(device, name, &staging, bytes, usage, dst_stage, dst_access);
        match result {
            Ok(dst) => {
                // SAFETY: the copy that read it completed (its fence was waited for).
                unsafe { device.destroy_buffer(staging) };
                Ok(dst)
            }
            Err(Failure::Idle(e)) => {
                // SAFETY: nothing using it is pending (`Failure::Idle`).
                unsafe { device.destroy_buffer(staging) };
                Err(e)
            }
            Err(Failure::Pending(e)) => {
                self.orphans.push(staging);
                Err(e)
            }
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn copy_via(
        &mut self,
        device: &Device,
        name: &str,
        staging: &Buffer,
        bytes: &[u8],
        usage: vk::BufferUsageFlags,
        dst_stage: vk::PipelineStageFlags2,
        dst_access: vk::AccessFlags2,
    ) -> Result<Buffer, Failure> {
        let base = staging
            .mapped()
            .ok_or_else(|| GpuError::Internal("staging buffer is not mapped".into()))
            .map_err(Failure::Idle)?;
        // SAFETY: the staging buffer is at least `bytes.len()` long, freshly created, mapped
        // and unaliased.
        unsafe { std::ptr::copy_nonoverlapping(bytes.as_ptr(), base.as_ptr(), bytes.len()) };
        if staging.needs_flush() {
            let atom = device.caps.non_coherent_atom_size;
            device
                .flush_ranges(&[staging.mapped_range(0..bytes.len() as u64, atom)])
                .map_err(Failure::Idle)?;
        }
        let dst = device
            .create_buffer(&BufferDesc {
                name,
                size: bytes.len() as u64,
                usage: usage | vk::BufferUsageFlags::TRANSFER_DST,
                location: MemoryLocation::GpuOnly,
            })
            .map_err(Failure::Idle)?;
        match self.submit_copy(device, staging, &dst, dst_stage, dst_access) {
            Ok(()) => Ok(dst),
            Err(Failure::Idle(e)) => {
                // SAFETY: nothing using it is pending (`Failure::Idle`).
                unsafe { device.destroy_buffer(dst) };
                Err(Failure::Idle(e))
            }
            Err(Failure::Pending(e)) => {
                self.orphans.push(dst);
                Err(Failure::Pending(e))
            }
        }
    }

    /// Records, submits and waits for the copy. The pool and fence are only reset once
    /// nothing is pending on them: after a failed wait the copy may still be running, so
    /// the device is waited for first, and if that fails too the uploader is poisoned
    /// rather than resetting a pool whose command buffer may be pending.
    fn submit_copy(
        &mut self,
        device: &Device,
        src: &Buffer,
        dst: &Buffer,
        dst_stage: vk::PipelineStageFlags2,
        dst_access: vk::AccessFlags2,
    ) -> Result<(), Failure> {
        let raw = &device.raw;
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(self.pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        // SAFETY: the pool is ours and was reset after the previous upload.
        let cmd = unsafe { raw.allocate_command_buffers(&alloc) }
            .vk("vkAllocateCommandBuffers")
            .map_err(Failure::Idle)?[0];
        let begin = vk::CommandBufferBeginInfo::default()
            .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
        let region = vk::BufferCopy {
            src_offset: 0,
            dst_offset: 0,
            size: dst.size(),
        };
        // The barrier orders the copy before every later submission's reads of `dst`.
        let barrier = [vk::BufferMemoryBarrier2::default()
            .src_stage_mask(vk::PipelineStageFlags2::COPY)
            .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
            .dst_stage_mask(dst_stage)
            .dst_access_mask(dst_access)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .buffer(dst.raw)
            .offset(0)
            .size(vk::WHOLE_SIZE)];
        let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
        let submit = [vk::SubmitInfo2::default().command_buffer_infos(&cmds)];
        // SAFETY: `cmd` is a fresh primary buffer; handles are live; the fence is unsignalled
        // (created so, and reset after each use); the queue is only used from &mut Renderer.
        let submitted = unsafe {
            raw.begin_command_buffer(cmd, &begin)
                .vk("vkBeginCommandBuffer")
                .and_then(|()| {
                    raw.cmd_copy_buffer(cmd, src.raw, dst.raw, &[region]);
                    raw.cmd_pipeline_barrier2(
                        cmd,
                        &vk::DependencyInfo::default().buffer_memory_barriers(&barrier),
                    );
                    raw.end_command_buffer(cmd).vk("vkEndCommandBuffer")
                })
                .and_then(|()| {
                    raw.queue_submit2(device.queue, &submit, self.fence)
                        .vk("vkQueueSubmit2")
                })
        };
        let outcome = match submitted {
            // Nothing was submitted: nothing is pending.
            Err(e) => Err(Failure::Idle(e)),
            Ok(()) => {
                let waited = match self.fail_wait.take() {
                    Some(result) => Err(vk_error("vkWaitForFences", result)),
                    None => device.wait_fence(self.fence),
                };
                match waited {
                    Ok(()) => Ok(()),
                    // The copy may still run; only an idle device proves it finished.
                    Err(e) => match device.wait_idle() {
                        Ok(()) => Err(Failure::Idle(e)),
                        Err(_) => {
                            self.poisoned = true;
                            return Err(Failure::Pending(e));
                        }
                    },
                }
            }
        };
        // SAFETY: nothing submitted from the pool is pending (the submission failed, its fence
        // signalled, or the device went idle), so the fence and pool may be reset and the
        // command buffer freed.
        unsafe {
            let _ = raw.reset_fences(&[self.fence]);
            let _ = raw.reset_command_pool(self.pool, vk::CommandPoolResetFlags::empty());
            raw.free_command_buffers(self.pool, &[cmd]);
        }
        outcome
    }

    /// Destroys the pool, the fence and orphaned buffers.
    ///
    /// # Safety
    /// No submitted GPU work that uses these objects may still be pending (the device is idle
    /// or lost, or they were never used).
    pub(crate) unsafe fn destroy(self, device: &Device) {
        for b in self.orphans {
            // SAFETY: the caller guarantees nothing pending uses them (this function's contract).
            unsafe { device.destroy_buffer(b) };
        }
        // SAFETY: every upload waited for its fence, or the renderer waited for the device
        // (or lost it) before destroying the uploader.
        unsafe {
            device.raw.destroy_fence(self.fence, None);
            device.raw.destroy_command_pool(self.pool, None);
        }
    }
}
