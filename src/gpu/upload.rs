//! Synchronous uploads of static data (grid index buffers) into device-local buffers.
//!
//! Static data is created rarely (once per grid shape), so a blocking staging copy on the
//! graphics queue is simpler than threading uploads through the frame's command buffer.

use ash::vk;
use gpu_allocator::MemoryLocation;

use super::device::Device;
use super::error::{GpuError, GpuResult, VkResultExt};
use super::memory::{Buffer, BufferDesc};

#[derive(Default)]
pub(crate) struct Uploader {
    pool: vk::CommandPool,
    fence: vk::Fence,
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
        Ok(Self { pool, fence })
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
        let size = bytes.len() as u64;
        let staging = device.create_buffer(&BufferDesc {
            name: "staging",
            size,
            usage: vk::BufferUsageFlags::TRANSFER_SRC,
            location: MemoryLocation::CpuToGpu,
        })?;
        let result = self.copy_via(device, name, &staging, bytes, usage, dst_stage, dst_access);
        device.destroy_buffer(staging);
        result
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
    ) -> GpuResult<Buffer> {
        let base = staging
            .mapped()
            .ok_or_else(|| GpuError::Internal("staging buffer is not mapped".into()))?;
        // SAFETY: the staging buffer is at least `bytes.len()` long, freshly created, mapped
        // and unaliased.
        unsafe { std::ptr::copy_nonoverlapping(bytes.as_ptr(), base.as_ptr(), bytes.len()) };
        if staging.needs_flush() {
            let atom = device.caps.non_coherent_atom_size;
            device.flush_ranges(&[staging.mapped_range(0..bytes.len() as u64, atom)])?;
        }
        let dst = device.create_buffer(&BufferDesc {
            name,
            size: bytes.len() as u64,
            usage: usage | vk::BufferUsageFlags::TRANSFER_DST,
            location: MemoryLocation::GpuOnly,
        })?;
        if let Err(e) = self.submit_copy(device, staging, &dst, dst_stage, dst_access) {
            // The copy may be in flight if only the wait failed; make sure before freeing.
            let _ = device.wait_idle();
            device.destroy_buffer(dst);
            return Err(e);
        }
        Ok(dst)
    }

    fn submit_copy(
        &mut self,
        device: &Device,
        src: &Buffer,
        dst: &Buffer,
        dst_stage: vk::PipelineStageFlags2,
        dst_access: vk::AccessFlags2,
    ) -> GpuResult<()> {
        let raw = &device.raw;
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(self.pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        // SAFETY: the pool is ours and was reset after the previous upload.
        let cmd =
            unsafe { raw.allocate_command_buffers(&alloc) }.vk("vkAllocateCommandBuffers")?[0];
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
        let result = unsafe {
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
                .and_then(|()| {
                    raw.wait_for_fences(&[self.fence], true, u64::MAX)
                        .vk("vkWaitForFences")
                })
        };
        // SAFETY: the submission (if any) completed, or failed to start; either way the
        // command buffer is no longer pending. Resetting returns it to the pool.
        unsafe {
            let _ = raw.reset_fences(&[self.fence]);
            let _ = raw.reset_command_pool(self.pool, vk::CommandPoolResetFlags::empty());
            raw.free_command_buffers(self.pool, &[cmd]);
        }
        result
    }

    pub(crate) fn destroy(self, device: &Device) {
        // SAFETY: every upload waited for its fence; nothing is pending.
        unsafe {
            device.raw.destroy_fence(self.fence, None);
            device.raw.destroy_command_pool(self.pool, None);
        }
    }
}
