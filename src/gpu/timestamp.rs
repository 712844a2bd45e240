//! GPU frame timing with a two-entry timestamp query pool per frame slot.
//!
//! Results are read when the slot comes round again (its fence has signalled), so reading
//! never stalls; the time returned by a frame is that of the previous use of its slot.

use ash::vk;

use super::device::Device;
use super::error::{GpuResult, VkResultExt};

pub(crate) struct GpuTimer {
    pool: vk::QueryPool,
    /// Whether the last submission of this slot wrote both queries.
    written: bool,
    period_ns: f64,
    valid_mask: u64,
}

impl GpuTimer {
    /// `None` when the queue has no timestamp support.
    pub(crate) fn new(device: &Device) -> GpuResult<Option<Self>> {
        let caps = &device.caps;
        if !caps.timestamps() {
            return Ok(None);
        }
        let info = vk::QueryPoolCreateInfo::default()
            .query_type(vk::QueryType::TIMESTAMP)
            .query_count(2);
        // SAFETY: valid device and create info.
        let pool = unsafe { device.raw.create_query_pool(&info, None) }.vk("vkCreateQueryPool")?;
        let valid_mask = if caps.timestamp_valid_bits >= 64 {
            u64::MAX
        } else {
            (1u64 << caps.timestamp_valid_bits) - 1
        };
        Ok(Some(Self {
            pool,
            written: false,
            period_ns: caps.timestamp_period_ns,
            valid_mask,
        }))
    }

    /// Records the reset and the start stamp; must be outside a rendering scope.
    pub(crate) fn begin(&mut self, device: &Device, cmd: vk::CommandBuffer) {
        // SAFETY: `cmd` is recording; queries are not in use by pending work (fence waited).
        unsafe {
            device.raw.cmd_reset_query_pool(cmd, self.pool, 0, 2);
            device.raw.cmd_write_timestamp2(
                cmd,
                vk::PipelineStageFlags2::TOP_OF_PIPE,
                self.pool,
                0,
            );
        }
    }

    /// Records the end stamp.
    pub(crate) fn end(&mut self, device: &Device, cmd: vk::CommandBuffer) {
        // SAFETY: `cmd` is recording and query 1 was reset in `begin`.
        unsafe {
            device.raw.cmd_write_timestamp2(
                cmd,
                vk::PipelineStageFlags2::ALL_COMMANDS,
                self.pool,
                1,
            );
        }
        self.written = true;
    }

    /// GPU milliseconds of the last completed submission of this slot, if any. Call only
    /// after the slot's fence has signalled.
    pub(crate) fn read(&mut self, device: &Device) -> Option<f64> {
        if !std::mem::take(&mut self.written) {
            return None;
        }
        let mut stamps = [0u64; 2];
        // SAFETY: both queries were written by a submission whose fence has signalled.
        let ok = unsafe {
            device.raw.get_query_pool_results(
                self.pool,
                0,
                &mut stamps,
                vk::QueryResultFlags::TYPE_64,
            )
        };
        ok.ok()?;
        let ticks = (stamps[1] & self.valid_mask).wrapping_sub(stamps[0] & self.valid_mask)
            & self.valid_mask;
        Some(ticks as f64 * self.period_ns * 1e-6)
    }

    /// Destroys the query pool.
    ///
    /// # Safety
    /// No submitted GPU work that uses these objects may still be pending (the device is idle
    /// or lost, or they were never used).
    pub(crate) unsafe fn destroy(self, device: &Device) {
        // SAFETY: no pending GPU use (renderer waited for idle).
        unsafe { device.raw.destroy_query_pool(self.pool, None) };
    }
}
