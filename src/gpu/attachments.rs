//! The attachments a target renders into besides its final colour image: the multisampled
//! colour image, the depth buffer and the static layer.

use ash::vk;

use super::device::Device;
use super::error::GpuResult;
use super::image::{Image, ImageDesc};
use super::layer::StaticLayer;
use super::pipeline::DEPTH_FORMAT;

/// The per-target attachments besides the final colour image: the multisampled colour image
/// (resolved into the final one) when MSAA is on, and the depth buffer. Shared by both frames
/// in flight; the layout transition at the start of each frame orders them (see `frame.rs`).
pub(crate) struct Attachments {
    pub msaa: Option<Image>,
    pub depth: Image,
    pub samples: vk::SampleCountFlags,
    /// The retained static layer (single-sampled targets whose colour image can be copied).
    pub layer: Option<StaticLayer>,
}

impl Attachments {
    pub(crate) fn new(
        device: &Device,
        extent: vk::Extent2D,
        color_format: vk::Format,
        samples: vk::SampleCountFlags,
        copyable: bool,
    ) -> GpuResult<Self> {
        let with_layer = copyable && samples == vk::SampleCountFlags::TYPE_1;
        let msaa = if samples != vk::SampleCountFlags::TYPE_1 {
            Some(Image::new(
                device,
                &ImageDesc {
                    name: "msaa colour",
                    extent,
                    format: color_format,
                    samples,
                    usage: vk::ImageUsageFlags::COLOR_ATTACHMENT
                        | vk::ImageUsageFlags::TRANSIENT_ATTACHMENT,
                },
            )?)
        } else {
            None
        };
        let depth = Image::new(
            device,
            &ImageDesc {
                name: "depth",
                extent,
                format: DEPTH_FORMAT,
                samples,
                usage: if with_layer {
                    vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT
                        | vk::ImageUsageFlags::TRANSFER_SRC
                        | vk::ImageUsageFlags::TRANSFER_DST
                } else {
                    vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT
                        | vk::ImageUsageFlags::TRANSIENT_ATTACHMENT
                },
            },
        );
        let layer = match depth {
            Ok(_) if with_layer => Some(StaticLayer::new(device, extent, color_format)),
            _ => None,
        };
        match (depth, layer) {
            (Ok(depth), Some(Err(e))) => {
                // SAFETY: created just above and never used by the GPU.
                unsafe {
                    depth.destroy(device);
                    if let Some(m) = msaa {
                        m.destroy(device);
                    }
                }
                Err(e)
            }
            (Ok(depth), layer) => Ok(Self {
                msaa,
                depth,
                samples,
                layer: layer.and_then(Result::ok),
            }),
            (Err(e), _) => {
                if let Some(m) = msaa {
                    // SAFETY: created just above and never used by the GPU.
                    unsafe { m.destroy(device) };
                }
                Err(e)
            }
        }
    }

    /// Destroys the depth and MSAA attachments.
    ///
    /// # Safety
    /// No submitted GPU work that uses these objects may still be pending (the device is idle
    /// or lost, or they were never used).
    pub(crate) unsafe fn destroy(self, device: &Device) {
        // SAFETY: the caller guarantees nothing pending uses them (this function's contract).
        unsafe {
            if let Some(m) = self.msaa {
                m.destroy(device);
            }
            self.depth.destroy(device);
            if let Some(l) = self.layer {
                l.destroy(device);
            }
        }
    }
}
