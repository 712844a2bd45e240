//! Mirror buffers: per-frame-in-flight, persistently mapped, write-only copies of f32 data.
//!
//! The canonical data (e.g. a sample grid) lives in ordinary memory. Each frame slot has its
//! own [`MirrorBuffer`]; before recording frame *k* the caller copies into slot *k* whatever
//! changed since that slot was last written (see [`super::Frame::write_mirror`]). A slot is
//! only ever written after the fence of its previous submission has signalled, which
//! [`super::Renderer::begin_offscreen`]/[`super::Renderer::begin_swapchain`] guarantee.
//!
//! The mapping may be write-combined (uncached) memory on discrete GPUs, where reads are
//! extremely slow, so this API offers no way to read it back.

use std::ops::Range;
use std::ptr::NonNull;

use ash::vk;
use gpu_allocator::MemoryLocation;

use super::FRAMES_IN_FLIGHT;
use super::device::Device;
use super::error::{GpuError, GpuResult};
use super::memory::{Buffer, BufferDesc, DirtyRanges};

/// One persistently mapped `CpuToGpu` buffer of `len` f32s, usable as a vertex buffer and
/// through its device address.
pub struct MirrorBuffer {
    pub(crate) buffer: Buffer,
    ptr: NonNull<f32>,
    len: usize,
}

impl MirrorBuffer {
    pub(crate) fn new(device: &Device, name: &str, len: usize) -> GpuResult<Self> {
        let size = (len as u64)
            .checked_mul(4)
            .filter(|&s| s > 0)
            .ok_or_else(|| {
                GpuError::InvalidArgument(format!("mirror {name:?}: bad length {len}"))
            })?;
        let buffer = device.create_buffer(&BufferDesc {
            name,
            size,
            usage: vk::BufferUsageFlags::VERTEX_BUFFER
                | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS,
            location: MemoryLocation::CpuToGpu,
        })?;
        let ptr = buffer
            .mapped()
            .map(NonNull::cast::<f32>)
            .filter(|p| p.as_ptr().is_aligned());
        match ptr {
            Some(ptr) => Ok(Self { buffer, ptr, len }),
            None => {
                // SAFETY: created just above and never used by the GPU.
                unsafe { device.destroy_buffer(buffer) };
                Err(GpuError::Internal(format!(
                    "mirror {name:?}: mapping is missing or misaligned"
                )))
            }
        }
    }

    /// Length in f32 elements.
    #[must_use]
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the buffer holds no elements (never true: creation rejects length 0).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The Vulkan buffer handle.
    #[must_use]
    pub fn raw(&self) -> vk::Buffer {
        self.buffer.raw
    }

    /// GPU address of element 0.
    #[must_use]
    pub fn address(&self) -> vk::DeviceAddress {
        self.buffer.address()
    }
}

// SAFETY: `ptr` points into the mapping owned by `buffer` (itself Send); moving the owner to
// another thread moves the only handle through which the mapping is written.
unsafe impl Send for MirrorBuffer {}

/// A mirrored f32 array: one [`MirrorBuffer`] per frame in flight. Create with
/// [`super::Renderer::create_mirror`], destroy with [`super::Renderer::destroy_mirror`].
pub struct Mirror {
    pub(crate) slots: Vec<MirrorBuffer>,
    len: usize,
}

impl Mirror {
    pub(crate) fn new(device: &Device, name: &str, len: usize) -> GpuResult<Self> {
        let mut slots = Vec::with_capacity(FRAMES_IN_FLIGHT);
        for i in 0..FRAMES_IN_FLIGHT {
            match MirrorBuffer::new(device, &format!("{name}[{i}]"), len) {
                Ok(b) => slots.push(b),
                Err(e) => {
                    for b in slots {
                        // SAFETY: created just above and never used by the GPU.
                        unsafe { device.destroy_buffer(b.buffer) };
                    }
                    return Err(e);
                }
            }
        }
        Ok(Self { slots, len })
    }

    /// Length in f32 elements (the same for every slot).
    #[must_use]
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the mirror holds no elements (never true: creation rejects length 0).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The buffer of frame slot `slot`.
    #[must_use]
    pub fn slot(&self, slot: usize) -> &MirrorBuffer {
        &self.slots[slot % FRAMES_IN_FLIGHT]
    }

    /// Writes `data` at `offset` into every slot and flushes what needs flushing.
    ///
    /// # Safety
    /// No pending GPU work may use any slot of this mirror (every frame slot was waited for,
    /// or the mirror was never used).
    pub(crate) unsafe fn fill(
        &mut self,
        device: &Device,
        offset: usize,
        data: &[f32],
        always_flush: bool,
    ) -> GpuResult<()> {
        let atom = device.caps.non_coherent_atom_size;
        let mut flushes = Vec::new();
        for slot in 0..FRAMES_IN_FLIGHT {
            let track = always_flush || self.slot(slot).buffer.needs_flush();
            self.writer(slot, atom, track, &mut flushes)
                .write(offset, data)?;
        }
        device.flush_ranges(&flushes)
    }

    /// A writer for slot `slot` that appends the flush ranges it produces to `flushes`.
    pub(crate) fn writer<'a>(
        &'a mut self,
        slot: usize,
        atom: u64,
        track: bool,
        flushes: &'a mut Vec<vk::MappedMemoryRange<'static>>,
    ) -> MirrorWriter<'a> {
        let buf = &mut self.slots[slot % FRAMES_IN_FLIGHT];
        MirrorWriter {
            ptr: buf.ptr,
            len: buf.len,
            buffer: &buf.buffer,
            dirty: DirtyRanges::default(),
            track,
            atom,
            flushes,
        }
    }
}

/// Write-only access to one slot of a [`Mirror`]. Values go straight into mapped memory with
/// `ptr::write`; no reference to that memory is ever formed. When the memory is not
/// host-coherent, the written byte ranges are recorded and, when the writer is dropped,
/// handed to the frame, which flushes them (atom-aligned) before submitting.
pub struct MirrorWriter<'a> {
    ptr: NonNull<f32>,
    len: usize,
    buffer: &'a Buffer,
    dirty: DirtyRanges,
    track: bool,
    atom: u64,
    flushes: &'a mut Vec<vk::MappedMemoryRange<'static>>,
}

impl MirrorWriter<'_> {
    /// Length of the slot in f32 elements.
    #[must_use]
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the slot holds no elements.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    fn mark(&mut self, start: usize, count: usize) {
        if self.track {
            self.dirty.add(start as u64 * 4..(start + count) as u64 * 4);
        }
    }

    /// Copies `data` to elements `offset..offset + data.len()`.
    pub fn write(&mut self, offset: usize, data: &[f32]) -> GpuResult<()> {
        let end = offset.checked_add(data.len()).filter(|&e| e <= self.len);
        if end.is_none() {
            return Err(GpuError::InvalidArgument(format!(
                "mirror write of {} elements at {offset} exceeds length {}",
                data.len(),
                self.len
            )));
        }
        // SAFETY: bounds checked above; the destination is mapped memory owned by this slot,
        // not aliased by any Rust reference, and not read by the GPU (the slot's fence has
        // signalled, see module docs). Source and destination cannot overlap.
        unsafe {
            std::ptr::copy_nonoverlapping(data.as_ptr(), self.ptr.as_ptr().add(offset), data.len())
        };
        self.mark(offset, data.len());
        Ok(())
    }

    /// Writes one element.
    ///
    /// # Panics
    /// If `index >= self.len()` (like slice indexing).
    pub fn put(&mut self, index: usize, value: f32) {
        assert!(
            index < self.len,
            "mirror index {index} out of range {}",
            self.len
        );
        // SAFETY: in bounds; write-only access to unaliased mapped memory (see `write`).
        unsafe { self.ptr.as_ptr().add(index).write(value) };
        self.mark(index, 1);
    }

    /// Writes vertex `index` of an array of `N`-float vertices: elements `index*N .. index*N+N`.
    ///
    /// # Panics
    /// If the vertex lies outside the slot (like slice indexing).
    pub fn put_vertex<const N: usize>(&mut self, index: usize, value: [f32; N]) {
        if N == 0 {
            return;
        }
        assert!(
            index < self.len / N,
            "mirror vertex {index} (x{N}) out of range {}",
            self.len
        );
        let start = index * N;
        // SAFETY: in bounds; f32 alignment suffices for [f32; N]; write-only access to
        // unaliased mapped memory (see `write`).
        unsafe { self.ptr.as_ptr().add(start).cast::<[f32; N]>().write(value) };
        self.mark(start, N);
    }
}

impl MirrorWriter<'_> {
    /// Splits the slot into writers of the given element ranges, which must be in increasing
    /// order, disjoint and inside the slot, so they can be filled on several threads at once
    /// (a scene's initial upload). The ranges count as written.
    pub fn split(&mut self, ranges: &[Range<usize>]) -> GpuResult<Vec<RangeWriter<'_>>> {
        let mut end = 0;
        for r in ranges {
            if r.start < end || r.start > r.end || r.end > self.len {
                return Err(GpuError::InvalidArgument(format!(
                    "mirror split at {r:?} overlaps an earlier range or exceeds length {}",
                    self.len
                )));
            }
            end = r.end;
        }
        for r in ranges {
            self.mark(r.start, r.len());
        }
        Ok(ranges
            .iter()
            .map(|r| RangeWriter {
                ptr: self.ptr,
                range: r.clone(),
                _writer: std::marker::PhantomData,
            })
            .collect())
    }
}

/// Write-only access to one element range of a mirror slot ([`MirrorWriter::split`]); the
/// ranges of one split are disjoint, so each may be written on its own thread.
pub struct RangeWriter<'a> {
    ptr: NonNull<f32>,
    range: Range<usize>,
    /// The split borrows its writer mutably for as long as any range writer lives.
    _writer: std::marker::PhantomData<&'a mut ()>,
}

// SAFETY: a range writer only writes its own range of the mapping, disjoint from every other
// writer's of the same split, and the mutable borrow of the slot's writer keeps anything else
// from writing the slot meanwhile.
unsafe impl Send for RangeWriter<'_> {}

impl RangeWriter<'_> {
    /// The element range this writer may write.
    #[must_use]
    pub fn range(&self) -> Range<usize> {
        self.range.clone()
    }

    /// Copies `data` to elements `offset..offset + data.len()`, which must lie inside the
    /// writer's range.
    pub fn write(&mut self, offset: usize, data: &[f32]) -> GpuResult<()> {
        let end = offset.checked_add(data.len());
        if offset < self.range.start || end.is_none_or(|e| e > self.range.end) {
            return Err(GpuError::InvalidArgument(format!(
                "mirror write of {} elements at {offset} outside the range {:?}",
                data.len(),
                self.range
            )));
        }
        // SAFETY: inside this writer's range (checked above), which lies inside the slot
        // (checked by `split`), is written by no one else, is not read by the GPU (the slot's
        // fence has signalled, see the module docs) and has no Rust reference to it.
        unsafe {
            std::ptr::copy_nonoverlapping(data.as_ptr(), self.ptr.as_ptr().add(offset), data.len())
        };
        Ok(())
    }
}

impl Drop for MirrorWriter<'_> {
    fn drop(&mut self) {
        if self.dirty.is_empty() {
            return;
        }
        // Ranges within one atom of each other share a flush anyway; join them.
        for r in self.dirty.take_merged(self.atom) {
            self.flushes.push(self.buffer.mapped_range(r, self.atom));
        }
    }
}
