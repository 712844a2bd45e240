//! Offscreen render targets with CPU readback, and PNG helpers.

use std::io::{BufReader, BufWriter};
use std::path::Path;

use ash::vk;
use gpu_allocator::MemoryLocation;

use super::FRAMES_IN_FLIGHT;
use super::device::Device;
use super::error::{GpuError, GpuResult};
use super::frame::TargetView;
use super::image::{Attachments, Image, ImageDesc};
use super::memory::{Buffer, BufferDesc};
use super::renderer::{Orphan, Renderer};

/// Colour format of offscreen targets. sRGB, so shaders output linear colour and the PNG
/// bytes read back are display-ready.
pub const OFFSCREEN_FORMAT: vk::Format = vk::Format::R8G8B8A8_SRGB;

/// Parameters for [`Renderer::create_offscreen`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OffscreenDesc {
    /// Width in pixels (> 0).
    pub width: u32,
    /// Height in pixels (> 0).
    pub height: u32,
    /// MSAA sample count: 1, 2, 4, 8...; 0 picks [`Renderer::default_samples`].
    pub samples: u32,
}

/// An image to render into and read back. Destroy with [`Renderer::destroy_offscreen`].
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
    /// Size in pixels.
    pub fn extent(&self) -> [u32; 2] {
        [self.extent.width, self.extent.height]
    }

    /// MSAA sample count.
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

impl Renderer {
    /// The MSAA sample count used when a target asks for 0, chosen per device type by
    /// measurement (docs/performance.md, "Frames"): 1 on CPU rasterisers (lavapipe), where 4×
    /// multisampling multiplies the cost of every triangle's rasterisation and of the resolve,
    /// and 4 on GPUs, where it is cheap. Falls back to 1 where 4 is not supported.
    pub fn default_samples(&self) -> u32 {
        let preferred = match self.device.caps.device_type {
            vk::PhysicalDeviceType::CPU => 1,
            _ => 4,
        };
        if self.device.caps.supports_samples(preferred) {
            preferred
        } else {
            1
        }
    }

    pub(crate) fn resolve_samples(&self, requested: u32) -> GpuResult<vk::SampleCountFlags> {
        let n = if requested == 0 {
            self.default_samples()
        } else {
            requested
        };
        if !n.is_power_of_two() || !self.device.caps.supports_samples(n) {
            return Err(GpuError::InvalidArgument(format!(
                "{n}x MSAA is not supported by {}",
                self.device.caps.name
            )));
        }
        Ok(vk::SampleCountFlags::from_raw(n))
    }

    /// Creates an offscreen target.
    pub fn create_offscreen(&mut self, desc: &OffscreenDesc) -> GpuResult<OffscreenTarget> {
        if desc.width == 0 || desc.height == 0 {
            return Err(GpuError::InvalidArgument(format!(
                "offscreen target {}x{} is empty",
                desc.width, desc.height
            )));
        }
        let samples = self.resolve_samples(desc.samples)?;
        let device = &*self.device;
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
                usage: vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC,
            },
        )?;
        let attachments = match Attachments::new(device, extent, OFFSCREEN_FORMAT, samples) {
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

    /// Waits for the last frame rendered into `target` and returns its pixels. That frame
    /// must have been captured ([`super::Frame::capture`]).
    pub fn read_pixels(&mut self, target: &OffscreenTarget) -> GpuResult<Pixels> {
        let slot = target.last_slot.ok_or_else(|| {
            GpuError::InvalidArgument(
                "read_pixels: the last frame rendered into this target was not captured \
                 (call Frame::capture before finish)"
                    .into(),
            )
        })?;
        let device = &*self.device;
        // A slot not in flight finished its last accepted submission (it was waited for).
        if self.frames[slot].in_flight {
            device.wait_fence(self.frames[slot].fence)?;
        }
        let buffer = &target.readback[slot];
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
            width: target.extent.width,
            height: target.extent.height,
            rgba,
        })
    }

    /// Destroys an offscreen target, after waiting for the GPU to finish with it. If that
    /// wait fails for another reason than a lost device (work may still run), the target is
    /// kept until the renderer is dropped and the error returned.
    pub fn destroy_offscreen(&mut self, target: OffscreenTarget) -> GpuResult<()> {
        match self.wait_idle() {
            Ok(()) => {
                // SAFETY: the device is idle.
                unsafe { target.destroy(&self.device) };
                Ok(())
            }
            Err(e) if e.is_device_lost() => {
                // SAFETY: nothing executes on a lost device; its objects may be destroyed.
                unsafe { target.destroy(&self.device) };
                Err(e)
            }
            Err(e) => {
                self.orphans.push(Orphan::Target(target));
                Err(e)
            }
        }
    }
}
