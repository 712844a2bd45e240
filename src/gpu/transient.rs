//! Per-frame transient ("immediate") vertex memory: a bump allocator over one mapped buffer
//! per frame slot, reset when the slot's fence has signalled. Used for lines3d, the 2D
//! overlay and immediate polylines, whose data is rebuilt every frame.

use ash::vk;
use gpu_allocator::MemoryLocation;

use super::device::Device;
use super::error::{GpuError, GpuResult};
use super::memory::{Buffer, BufferDesc, DirtyRanges};
use super::pod::{Pod, slice_bytes};

const MIN_CAPACITY: u64 = 256 * 1024;

/// Where pushed data ended up.
#[derive(Clone, Copy, Debug)]
pub(crate) struct TransientAlloc {
    pub buffer: vk::Buffer,
    pub offset: u64,
    pub address: vk::DeviceAddress,
}

pub(crate) struct TransientBuffer {
    buffer: Option<Buffer>,
    cursor: u64,
    dirty: DirtyRanges,
    /// Record ranges even on coherent memory (tests exercise the flush path this way).
    always_flush: bool,
}

impl TransientBuffer {
    pub(crate) fn new(always_flush: bool) -> Self {
        Self {
            buffer: None,
            cursor: 0,
            dirty: DirtyRanges::default(),
            always_flush,
        }
    }

    /// Starts a new frame; the previous contents are no longer in use by the GPU.
    pub(crate) fn reset(&mut self) {
        self.cursor = 0;
        self.dirty = DirtyRanges::default();
    }

    /// Copies `data` in, growing into a new buffer when full. A replaced buffer may still be
    /// referenced by draws recorded earlier this frame, so it goes to `release` (destroyed
    /// when this slot's fence next signals) after its written ranges are flushed.
    pub(crate) fn push<T: Pod>(
        &mut self,
        device: &Device,
        release: &mut Vec<Buffer>,
        data: &[T],
    ) -> GpuResult<TransientAlloc> {
        let bytes = slice_bytes(data);
        let len = bytes.len() as u64;
        // 16 covers every vertex format and the float alignment of device-address reads.
        let mut offset = self.cursor.next_multiple_of(16);
        let capacity = self.buffer.as_ref().map_or(0, Buffer::size);
        if offset + len > capacity {
            let new_capacity = (capacity * 2)
                .max(len.next_multiple_of(16))
                .max(MIN_CAPACITY);
            let new = device.create_buffer(&BufferDesc {
                name: "transient vertices",
                size: new_capacity,
                usage: vk::BufferUsageFlags::VERTEX_BUFFER
                    | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS,
                location: MemoryLocation::CpuToGpu,
            })?;
            if let Some(old) = self.buffer.replace(new) {
                let mut ranges = Vec::new();
                self.take_ranges(&old, device.caps.non_coherent_atom_size, &mut ranges);
                release.push(old);
                device.flush_ranges(&ranges)?;
            }
            offset = 0;
        }
        let (buffer, base) = match self.buffer.as_ref().and_then(|b| Some((b, b.mapped()?))) {
            Some(x) => x,
            None => {
                return Err(GpuError::Internal("transient buffer is not mapped".into()));
            }
        };
        // SAFETY: offset + len <= capacity; the region is mapped, unaliased, and unused by
        // the GPU (this slot's fence signalled before the frame began); no overlap.
        unsafe {
            std::ptr::copy_nonoverlapping(
                bytes.as_ptr(),
                base.as_ptr().add(offset as usize),
                bytes.len(),
            )
        };
        self.cursor = offset + len;
        if buffer.needs_flush() || self.always_flush {
            self.dirty.add(offset..offset + len);
        }
        Ok(TransientAlloc {
            buffer: buffer.raw,
            offset,
            address: buffer.address() + offset,
        })
    }

    fn take_ranges(
        &mut self,
        buffer: &Buffer,
        atom: u64,
        out: &mut Vec<vk::MappedMemoryRange<'static>>,
    ) {
        for r in self.dirty.take_merged(atom) {
            out.push(buffer.mapped_range(r, atom));
        }
    }

    /// Appends the flush ranges of this frame's writes to `out`.
    pub(crate) fn flush_ranges(
        &mut self,
        atom: u64,
        out: &mut Vec<vk::MappedMemoryRange<'static>>,
    ) {
        if let Some(buffer) = self.buffer.take() {
            self.take_ranges(&buffer, atom, out);
            self.buffer = Some(buffer);
        }
    }

    /// Destroys the slot's transient buffers.
    ///
    /// # Safety
    /// No submitted GPU work that uses these objects may still be pending (the device is idle
    /// or lost, or they were never used).
    pub(crate) unsafe fn destroy(self, device: &Device) {
        if let Some(b) = self.buffer {
            // SAFETY: the caller guarantees nothing pending uses them (this function's contract).
            unsafe { device.destroy_buffer(b) };
        }
    }
}
