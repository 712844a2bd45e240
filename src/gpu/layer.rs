//! The retained static layer of a target: one colour and one depth image of the target's size
//! that a frame can save its attachments into mid-frame and a later frame can start from,
//! instead of clearing ([`Frame::save_static_layer`], [`Frame::restore_static_layer`]).
//!
//! The restore is an image copy rather than a full-screen draw: on lavapipe a copy is a row
//! `memcpy`, while a full-screen quad runs the JIT fragment path over every pixel, over 5× the
//! cost before it reads a texel (docs/performance.md, "Copy or full-screen draw").
//!
//! Only single-sampled targets have one: a multisampled depth buffer cannot be resolved into a
//! layer that restores bit for bit, and lavapipe, where redrawing costs most, renders MSAA 1.
//!
//! Synchronization: the layer images stay in `TRANSFER_SRC_OPTIMAL` between uses. A save
//! discards them (`UNDEFINED` → `TRANSFER_DST_OPTIMAL`, after the reads of earlier restores),
//! copies and returns them to `TRANSFER_SRC_OPTIMAL` with its writes made visible to later
//! copies; a restore reads them there. The target's attachments go to the transfer layouts
//! and back around each copy.

use std::sync::atomic::AtomicU64;

use ash::vk;

use super::device::Device;
use super::error::GpuResult;
use super::image::{Image, ImageDesc};
use super::pipeline::DEPTH_FORMAT;

/// What a restore of the static layer copies back.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Restore {
    /// Colour only: where no depth-tested draw of the frame follows (each copied image is a
    /// full-image memcpy on lavapipe, about 0.7 ms at 1280 × 720).
    Color,
    /// Colour and depth, for pixels that depth-tested draws reach.
    ColorAndDepth,
}

/// Distinct for every save of every layer in the process, so a stale token never matches.
pub(crate) static NEXT_TOKEN: AtomicU64 = AtomicU64::new(1);

/// Which of a target's two saves: the surfaces alone, or the surfaces with the lines and
/// points drawn over them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LayerPart {
    Surfaces,
    Lines,
}

/// One saved colour and depth image pair and which save it holds.
pub(crate) struct LayerImages {
    pub color: Image,
    pub depth: Image,
    /// The token of the save the images hold (`None`: never saved).
    pub saved: Option<u64>,
}

impl LayerImages {
    fn new(device: &Device, extent: vk::Extent2D, format: vk::Format) -> GpuResult<Self> {
        // Only copied, but every image gets a view, which needs an attachment usage.
        let copies = vk::ImageUsageFlags::TRANSFER_SRC | vk::ImageUsageFlags::TRANSFER_DST;
        let desc = |name, format, usage| ImageDesc {
            name,
            extent,
            format,
            samples: vk::SampleCountFlags::TYPE_1,
            usage: copies | usage,
        };
        let color = Image::new(
            device,
            &desc(
                "static layer colour",
                format,
                vk::ImageUsageFlags::COLOR_ATTACHMENT,
            ),
        )?;
        let depth = desc(
            "static layer depth",
            DEPTH_FORMAT,
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT,
        );
        match Image::new(device, &depth) {
            Ok(depth) => Ok(Self {
                color,
                depth,
                saved: None,
            }),
            Err(e) => {
                // SAFETY: created just above and never used by the GPU.
                unsafe { color.destroy(device) };
                Err(e)
            }
        }
    }

    /// # Safety
    /// No submitted GPU work that uses the images may still be pending.
    unsafe fn destroy(self, device: &Device) {
        // SAFETY: the caller's guarantee.
        unsafe {
            self.color.destroy(device);
            self.depth.destroy(device);
        }
    }
}

/// A target's static layer: a save of the surfaces and one of the surfaces with the lines.
pub(crate) struct StaticLayer {
    parts: [LayerImages; 2],
}

impl StaticLayer {
    pub(crate) fn new(
        device: &Device,
        extent: vk::Extent2D,
        format: vk::Format,
    ) -> GpuResult<Self> {
        let surfaces = LayerImages::new(device, extent, format)?;
        match LayerImages::new(device, extent, format) {
            Ok(lines) => Ok(Self {
                parts: [surfaces, lines],
            }),
            Err(e) => {
                // SAFETY: created just above and never used by the GPU.
                unsafe { surfaces.destroy(device) };
                Err(e)
            }
        }
    }

    pub(crate) fn part(&mut self, part: LayerPart) -> &mut LayerImages {
        &mut self.parts[part as usize]
    }

    /// # Safety
    /// No submitted GPU work that uses the images may still be pending.
    pub(crate) unsafe fn destroy(self, device: &Device) {
        let [a, b] = self.parts;
        // SAFETY: the caller's guarantee.
        unsafe {
            a.destroy(device);
            b.destroy(device);
        }
    }
}

use vk::AccessFlags2 as A;
use vk::PipelineStageFlags2 as S;

pub(crate) const DEPTH_STAGES: S =
    S::from_raw(S::EARLY_FRAGMENT_TESTS.as_raw() | S::LATE_FRAGMENT_TESTS.as_raw());
pub(crate) const DEPTH_ACCESS: A = A::from_raw(
    A::DEPTH_STENCIL_ATTACHMENT_READ.as_raw() | A::DEPTH_STENCIL_ATTACHMENT_WRITE.as_raw(),
);
pub(crate) const COLOR_ACCESS: A =
    A::from_raw(A::COLOR_ATTACHMENT_READ.as_raw() | A::COLOR_ATTACHMENT_WRITE.as_raw());

/// Copy of the pixel rectangle `[x, y, width, height]` of a single-level image.
pub(crate) fn rect_copy(aspect: vk::ImageAspectFlags, [x, y, w, h]: [u32; 4]) -> vk::ImageCopy {
    let layers = vk::ImageSubresourceLayers {
        aspect_mask: aspect,
        mip_level: 0,
        base_array_layer: 0,
        layer_count: 1,
    };
    let offset = vk::Offset3D {
        x: x as i32,
        y: y as i32,
        z: 0,
    };
    vk::ImageCopy {
        src_subresource: layers,
        src_offset: offset,
        dst_subresource: layers,
        dst_offset: offset,
        extent: vk::Extent3D {
            width: w,
            height: h,
            depth: 1,
        },
    }
}

/// `rect` within an image of `extent` (`None`: the whole image).
pub(crate) fn clamp_rect(rect: Option<[u32; 4]>, extent: vk::Extent2D) -> [u32; 4] {
    let (ew, eh) = (extent.width, extent.height);
    let [x, y, w, h] = rect.unwrap_or([0, 0, ew, eh]);
    let (x0, y0) = (x.min(ew), y.min(eh));
    let (x1, y1) = (x.saturating_add(w).min(ew), y.saturating_add(h).min(eh));
    [x0, y0, x1 - x0, y1 - y0]
}
