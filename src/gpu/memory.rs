//! Buffers backed by gpu-allocator, and flushing of host-written ranges.
//!
//! Host-visible allocations are aligned to `nonCoherentAtomSize` and padded to a multiple of
//! it, so that any atom-aligned sub-range of a buffer lies inside its own allocation: flushes
//! never touch a neighbour's memory nor run past the end of the `VkDeviceMemory`.

use std::ops::Range;
use std::ptr::NonNull;

use ash::vk;
use gpu_allocator::MemoryLocation;
use gpu_allocator::vulkan::Allocation;

use super::device::Device;
use super::error::{GpuError, GpuResult, VkResultExt};

/// Parameters for [`Device::create_buffer`].
#[derive(Clone, Debug)]
pub struct BufferDesc<'a> {
    /// Debug name (allocator reports, validation messages).
    pub name: &'a str,
    /// Size in bytes; must be > 0.
    pub size: u64,
    /// Vulkan usage. `SHADER_DEVICE_ADDRESS` makes [`Buffer::address`] available.
    pub usage: vk::BufferUsageFlags,
    /// Where the memory lives (`CpuToGpu` and `GpuToCpu` buffers are persistently mapped).
    pub location: MemoryLocation,
}

/// A `VkBuffer` with its memory. Destroy with [`Device::destroy_buffer`] (not on drop).
pub struct Buffer {
    pub(crate) raw: vk::Buffer,
    allocation: Allocation,
    size: u64,
    address: vk::DeviceAddress,
    mapped: Option<NonNull<u8>>,
    coherent: bool,
}

// SAFETY: the mapped pointer is only dereferenced through `&mut self` methods of the owners
// (mirror writer, transient buffer, readback), never shared across threads without `&mut`.
unsafe impl Send for Buffer {}

impl Buffer {
    /// Requested size in bytes.
    #[must_use]
    pub fn size(&self) -> u64 {
        self.size
    }

    /// GPU address (0 unless created with `SHADER_DEVICE_ADDRESS`).
    #[must_use]
    pub fn address(&self) -> vk::DeviceAddress {
        self.address
    }

    /// Persistent mapping, for host-visible buffers.
    pub(crate) fn mapped(&self) -> Option<NonNull<u8>> {
        self.mapped
    }

    /// Whether host writes need an explicit flush (and host reads an invalidate).
    pub(crate) fn needs_flush(&self) -> bool {
        !self.coherent
    }

    /// The `VkMappedMemoryRange` covering byte range `r` of this buffer, widened to atoms.
    pub(crate) fn mapped_range(&self, r: Range<u64>, atom: u64) -> vk::MappedMemoryRange<'static> {
        let (offset, size) = atom_aligned(r, atom, self.allocation.size());
        vk::MappedMemoryRange::default()
            // SAFETY: the handle is only passed to flush/invalidate while the allocation lives.
            .memory(unsafe { self.allocation.memory() })
            .offset(self.allocation.offset() + offset)
            .size(size)
    }
}

/// Widens `r` to multiples of `atom`, clamped to `alloc_size` (itself a multiple of `atom`).
/// Returns `(offset, size)` relative to the allocation.
pub(crate) fn atom_aligned(r: Range<u64>, atom: u64, alloc_size: u64) -> (u64, u64) {
    let start = r.start - r.start % atom;
    let end = r.end.div_ceil(atom).saturating_mul(atom).min(alloc_size);
    (start, end.saturating_sub(start))
}

/// A set of byte ranges written by the host, coalesced as they arrive. Consecutive writes
/// (the common case: rows of a grid, spans of a curve) extend the last range in O(1).
#[derive(Clone, Debug, Default)]
pub(crate) struct DirtyRanges {
    ranges: Vec<Range<u64>>,
}

impl DirtyRanges {
    pub(crate) fn add(&mut self, r: Range<u64>) {
        if r.is_empty() {
            return;
        }
        if let Some(last) = self.ranges.last_mut()
            && r.start <= last.end
            && r.end >= last.start
        {
            last.start = last.start.min(r.start);
            last.end = last.end.max(r.end);
            return;
        }
        self.ranges.push(r);
    }

    /// Sorted, merged ranges; ranges closer than `gap` bytes are joined (one flush per atom).
    pub(crate) fn take_merged(&mut self, gap: u64) -> Vec<Range<u64>> {
        let mut v = std::mem::take(&mut self.ranges);
        v.sort_by_key(|r| r.start);
        let mut out: Vec<Range<u64>> = Vec::with_capacity(v.len());
        for r in v {
            match out.last_mut() {
                Some(last) if r.start <= last.end.saturating_add(gap) => {
                    last.end = last.end.max(r.end)
                }
                _ => out.push(r),
            }
        }
        out
    }

    pub(crate) fn is_empty(&self) -> bool {
        self.ranges.is_empty()
    }
}

fn is_host_visible(location: MemoryLocation) -> bool {
    matches!(
        location,
        MemoryLocation::CpuToGpu | MemoryLocation::GpuToCpu
    )
}

impl Device {
    /// Creates a buffer and binds fresh memory from the allocator.
    pub(crate) fn create_buffer(&self, desc: &BufferDesc<'_>) -> GpuResult<Buffer> {
        if desc.size == 0 {
            return Err(GpuError::InvalidArgument(format!(
                "buffer {:?} has size 0",
                desc.name
            )));
        }
        let info = vk::BufferCreateInfo::default()
            .size(desc.size)
            .usage(desc.usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        // SAFETY: valid device and create info.
        let raw = unsafe { self.raw.create_buffer(&info, None) }.vk("vkCreateBuffer")?;
        // SAFETY: `raw` was just created from this device.
        let mut requirements = unsafe { self.raw.get_buffer_memory_requirements(raw) };
        if is_host_visible(desc.location) {
            let atom = self.caps.non_coherent_atom_size;
            requirements.alignment = requirements.alignment.max(atom);
            requirements.size = requirements.size.div_ceil(atom) * atom;
        }
        let allocation = match self.allocate(desc.name, requirements, desc.location, true) {
            Ok(a) => a,
            Err(e) => {
                // SAFETY: the buffer is unused and has no memory bound.
                unsafe { self.raw.destroy_buffer(raw, None) };
                return Err(e);
            }
        };
        let mut buffer = Buffer {
            raw,
            mapped: allocation.mapped_ptr().map(|p| p.cast()),
            coherent: allocation
                .memory_properties()
                .contains(vk::MemoryPropertyFlags::HOST_COHERENT),
            allocation,
            size: desc.size,
            address: 0,
        };
        // SAFETY: memory comes from a type compatible with `requirements`, at an aligned offset.
        let bound = unsafe {
            self.raw
                .bind_buffer_memory(raw, buffer.allocation.memory(), buffer.allocation.offset())
        };
        if let Err(e) = bound.vk("vkBindBufferMemory") {
            // SAFETY: created just above and never used by the GPU.
            unsafe { self.destroy_buffer(buffer) };
            return Err(e);
        }
        if desc
            .usage
            .contains(vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS)
        {
            // SAFETY: the buffer has the usage flag and bound memory allocated with the
            // device-address flag (allocator created with `buffer_device_address: true`).
            buffer.address = unsafe {
                self.raw
                    .get_buffer_device_address(&vk::BufferDeviceAddressInfo::default().buffer(raw))
            };
        }
        if is_host_visible(desc.location) && buffer.mapped.is_none() {
            // SAFETY: created just above and never used by the GPU.
            unsafe { self.destroy_buffer(buffer) };
            return Err(GpuError::Internal(format!(
                "buffer {:?}: host-visible memory is not mapped",
                desc.name
            )));
        }
        Ok(buffer)
    }

    /// Destroys a buffer and returns its memory.
    ///
    /// # Safety
    /// No submitted GPU work that uses the buffer may still be pending (its fence signalled,
    /// the device is idle, or it was never used).
    pub(crate) unsafe fn destroy_buffer(&self, buffer: Buffer) {
        // SAFETY: the caller guarantees no pending GPU use; the buffer is destroyed once.
        unsafe { self.raw.destroy_buffer(buffer.raw, None) };
        if let Some(a) = self.allocator().as_mut() {
            // A free only fails for a foreign allocation, which cannot happen here.
            let _ = a.free(buffer.allocation);
        }
    }

    /// Waits for `fence` at most [`super::WAIT_LIMIT`] (then [`GpuError::Timeout`]).
    pub(crate) fn wait_fence(&self, fence: vk::Fence) -> GpuResult<()> {
        let limit = u64::try_from(super::WAIT_LIMIT.as_nanos()).unwrap_or(u64::MAX);
        // SAFETY: the fence belongs to this device.
        unsafe { self.raw.wait_for_fences(&[fence], true, limit) }.vk("vkWaitForFences")
    }

    /// Flushes host writes so the device sees them (no-op call list when empty).
    pub(crate) fn flush_ranges(&self, ranges: &[vk::MappedMemoryRange<'_>]) -> GpuResult<()> {
        if ranges.is_empty() {
            return Ok(());
        }
        // SAFETY: ranges refer to live, mapped allocations and are atom-aligned.
        unsafe { self.raw.flush_mapped_memory_ranges(ranges) }.vk("vkFlushMappedMemoryRanges")
    }

    /// Makes device writes visible to host reads of non-coherent memory.
    pub(crate) fn invalidate_ranges(&self, ranges: &[vk::MappedMemoryRange<'_>]) -> GpuResult<()> {
        if ranges.is_empty() {
            return Ok(());
        }
        // SAFETY: as for flush.
        unsafe { self.raw.invalidate_mapped_memory_ranges(ranges) }
            .vk("vkInvalidateMappedMemoryRanges")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atom_alignment_widens_and_clamps() {
        assert_eq!(atom_aligned(0..4, 64, 256), (0, 64));
        assert_eq!(atom_aligned(70..130, 64, 256), (64, 128));
        assert_eq!(atom_aligned(200..256, 64, 256), (192, 64));
        assert_eq!(atom_aligned(250..255, 64, 256), (192, 64));
        assert_eq!(atom_aligned(12..24, 1, 100), (12, 12));
    }

    #[test]
    fn dirty_ranges_coalesce() {
        let mut d = DirtyRanges::default();
        d.add(0..12);
        d.add(12..24);
        d.add(100..112);
        d.add(40..52);
        d.add(5..6);
        assert_eq!(d.take_merged(0), vec![0..24, 40..52, 100..112]);
        assert!(d.is_empty());
        d.add(0..12);
        d.add(40..52);
        assert_eq!(d.take_merged(64), vec![0..52]);
    }
}
