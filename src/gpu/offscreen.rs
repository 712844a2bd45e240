//! Offscreen render targets with CPU readback, and PNG helpers.

use std::io::{BufReader, BufWriter};
use std::path::Path;

use ash::vk;
use gpu_allocator::MemoryLocation;

use super::FRAMES_IN_FLIGHT;
use super::attachments::Attachments;
use super::barrier::image_barrier;
use super::device::Device;
use super::error::{GpuError, GpuResult};
use super::image::{Image, ImageDesc};
use super::memory::{Buffer, BufferDesc};
use super::target::TargetView;

/// Colour format of offscreen targets. sRGB, so shaders output linear colour and the PNG
/// bytes read back are display-ready.
pub const OFFSCREEN_FORMAT: vk::Format = vk::Format::R8G8B8A8_SRGB;

/// Parameters for [`super::Renderer::create_offscreen`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OffscreenDesc {
    /// Width in pixels (> 0).
    pub width: u32,
    /// Height in pixels (> 0).
    pub height: u32,
    /// MSAA sample count: 1, 2, 4, 8...; 0 picks [`super::Renderer::default_samples`].
    pub samples: u32,
}

/// An image to render into and read back. Destroy with
/// [`super::Renderer::destroy_offscreen`].
pub struct OffscreenTarget {
    pub(crate) color: Image,
    pub(crate) attachments: Attachments,
    /// One readback buffer per frame slot, so a frame never overwrites one being read.
    pub(crate) readback: Vec<Buffer>,
    pub(crate) extent: vk::Extent2D,
    /// Slot of the last frame rendered here, when that frame was captured (its readback
    /// buffer holds the pixels).
    pub(crate) last_slot: Option<usize>,
}

impl OffscreenTarget {
    /// Creates the colour image, attachments and one readback buffer per frame slot, for a
    /// non-empty `desc` (the renderer checks it) with `samples` resolved from it.
    pub(crate) fn new(
        device: &Device,
        desc: &OffscreenDesc,
        samples: vk::SampleCountFlags,
    ) -> GpuResult<Self> {
        let extent = vk::Extent2D {
            width: desc.width,
            height: desc.height,
        };
        let color = Image::new(
            device,
            &ImageDesc {
                name: "offscreen colour",
                extent,
                format: OFFSCREEN_FORMAT,
                samples: vk::SampleCountFlags::TYPE_1,
                usage: vk::ImageUsageFlags::COLOR_ATTACHMENT
                    | vk::ImageUsageFlags::TRANSFER_SRC
                    | vk::ImageUsageFlags::TRANSFER_DST,
            },
        )?;
        let attachments = match Attachments::new(device, extent, OFFSCREEN_FORMAT, samples, true) {
            Ok(a) => a,
            Err(e) => {
                // SAFETY: created just above and never used by the GPU.
                unsafe { color.destroy(device) };
                return Err(e);
            }
        };
        let mut target = OffscreenTarget {
            color,
            attachments,
            readback: Vec::new(),
            extent,
            last_slot: None,
        };
        let bytes = u64::from(desc.width) * u64::from(desc.height) * 4;
        for _ in 0..FRAMES_IN_FLIGHT {
            let buffer = device.create_buffer(&BufferDesc {
                name: "offscreen readback",
                size: bytes,
                usage: vk::BufferUsageFlags::TRANSFER_DST,
                location: MemoryLocation::GpuToCpu,
            });
            match buffer {
                Ok(b) => target.readback.push(b),
                Err(e) => {
                    // SAFETY: created just above and never used by the GPU.
                    unsafe { target.destroy(device) };
                    return Err(e);
                }
            }
        }
        Ok(target)
    }

    /// The frame slot whose readback buffer holds the last frame rendered here; an error
    /// when that frame was not captured.
    pub(crate) fn captured_slot(&self) -> GpuResult<usize> {
        self.last_slot.ok_or_else(|| {
            GpuError::InvalidArgument(
                "read_pixels: the last frame rendered into this target was not captured \
                 (call Frame::capture before finish)"
                    .into(),
            )
        })
    }

    /// Copies the pixels out of `slot`'s readback buffer. The caller has waited for the
    /// submission that filled it ([`OffscreenTarget::captured_slot`]).
    pub(crate) fn read_back(&self, device: &Device, slot: usize) -> GpuResult<Pixels> {
        let buffer = &self.readback[slot];
        let len = buffer.size() as usize;
        if buffer.needs_flush() {
            let atom = device.caps.non_coherent_atom_size;
            device.invalidate_ranges(&[buffer.mapped_range(0..len as u64, atom)])?;
        }
        let src = buffer
            .mapped()
            .ok_or_else(|| GpuError::Internal("readback buffer is not mapped".into()))?;
        let mut rgba = vec![0u8; len];
        // SAFETY: the buffer is mapped host-readable (GpuToCpu) memory of `len` bytes whose
        // writes completed (fence) and were made host-visible (barrier + invalidate).
        unsafe { std::ptr::copy_nonoverlapping(src.as_ptr(), rgba.as_mut_ptr(), len) };
        Ok(Pixels {
            width: self.extent.width,
            height: self.extent.height,
            rgba,
        })
    }

    /// Size in pixels.
    #[must_use]
    pub fn extent(&self) -> [u32; 2] {
        [self.extent.width, self.extent.height]
    }

    /// MSAA sample count.
    #[must_use]
    pub fn samples(&self) -> u32 {
        self.attachments.samples.as_raw()
    }

    pub(crate) fn view(&self) -> TargetView {
        TargetView {
            image: self.color.raw,
            view: self.color.view,
            msaa: self.attachments.msaa.as_ref().map(|m| (m.raw, m.view)),
            depth: (self.attachments.depth.raw, self.attachments.depth.view),
            extent: self.extent,
            format: OFFSCREEN_FORMAT,
            samples: self.attachments.samples,
            layer: self.attachments.layer.is_some(),
        }
    }

    /// Records the copy of the image into `slot`'s readback buffer and makes it visible to
    /// the host.
    ///
    /// # Safety
    /// `cmd` must be recording outside a rendering scope after this target's frame was drawn,
    /// and the host must not read `slot`'s buffer until the submission's fence signals.
    pub(crate) unsafe fn record_readback(
        &self,
        device: &Device,
        cmd: vk::CommandBuffer,
        slot: usize,
    ) {
        let view = self.view();
        let readback = &self.readback[slot];
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
        // SAFETY: the caller guarantees a recording command buffer outside rendering and no host
        // read of the buffer before the fence.
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

    /// Destroys images and readback buffers.
    ///
    /// # Safety
    /// No submitted GPU work that uses these objects may still be pending (the device is idle
    /// or lost, or they were never used).
    pub(crate) unsafe fn destroy(self, device: &Device) {
        // SAFETY: the caller guarantees nothing pending uses them (this function's contract).
        unsafe {
            self.color.destroy(device);
            self.attachments.destroy(device);
            for b in self.readback {
                device.destroy_buffer(b);
            }
        }
    }
}

/// Tightly packed RGBA8 pixels, rows top to bottom, sRGB-encoded.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Pixels {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height * 4` bytes.
    pub rgba: Vec<u8>,
}

impl Pixels {
    /// The RGBA value at `(x, y)`.
    #[must_use]
    pub fn get(&self, x: u32, y: u32) -> [u8; 4] {
        let i = (y as usize * self.width as usize + x as usize) * 4;
        [
            self.rgba[i],
            self.rgba[i + 1],
            self.rgba[i + 2],
            self.rgba[i + 3],
        ]
    }

    /// Writes an RGBA8 PNG.
    pub fn write_png(&self, path: &Path) -> GpuResult<()> {
        let err = |message: String| GpuError::Image {
            path: path.display().to_string(),
            message,
        };
        let file = std::fs::File::create(path).map_err(|e| err(e.to_string()))?;
        let mut encoder = png::Encoder::new(BufWriter::new(file), self.width, self.height);
        encoder.set_color(png::ColorType::Rgba);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
        // fdeflate's PNG-tuned mode: a 1280 × 720 render in a few milliseconds instead of tens,
        // for files about a fifth larger (renders are flat colours and smooth shading).
        encoder.set_compression(png::Compression::Fast);
        let mut writer = encoder.write_header().map_err(|e| err(e.to_string()))?;
        writer
            .write_image_data(&self.rgba)
            .map_err(|e| err(e.to_string()))?;
        writer.finish().map_err(|e| err(e.to_string()))
    }

    /// Reads an 8-bit RGBA PNG (as written by [`Pixels::write_png`]).
    pub fn read_png(path: &Path) -> GpuResult<Self> {
        let err = |message: String| GpuError::Image {
            path: path.display().to_string(),
            message,
        };
        let file = std::fs::File::open(path).map_err(|e| err(e.to_string()))?;
        let mut reader = png::Decoder::new(BufReader::new(file))
            .read_info()
            .map_err(|e| err(e.to_string()))?;
        let size = reader
            .output_buffer_size()
            .ok_or_else(|| err("image too large".into()))?;
        let mut rgba = vec![0; size];
        let info = reader
            .next_frame(&mut rgba)
            .map_err(|e| err(e.to_string()))?;
        if info.color_type != png::ColorType::Rgba || info.bit_depth != png::BitDepth::Eight {
            return Err(err(format!(
                "expected 8-bit RGBA, found {:?} {:?}",
                info.color_type, info.bit_depth
            )));
        }
        rgba.truncate(info.width as usize * info.height as usize * 4);
        Ok(Self {
            width: info.width,
            height: info.height,
            rgba,
        })
    }
}
