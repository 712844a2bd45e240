//! Device-local images with one view: colour targets, MSAA colour and depth attachments.

use ash::vk;
use gpu_allocator::MemoryLocation;
use gpu_allocator::vulkan::Allocation;

use super::device::Device;
use super::error::{GpuResult, VkResultExt};
use super::pipeline::DEPTH_FORMAT;

/// Parameters for [`Image::new`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct ImageDesc<'a> {
    pub name: &'a str,
    pub extent: vk::Extent2D,
    pub format: vk::Format,
    pub samples: vk::SampleCountFlags,
    pub usage: vk::ImageUsageFlags,
}

/// A 2D image, its memory and a view covering it. Destroy with [`Image::destroy`].
pub(crate) struct Image {
    pub raw: vk::Image,
    pub view: vk::ImageView,
    allocation: Allocation,
}

pub(crate) fn aspect_of(format: vk::Format) -> vk::ImageAspectFlags {
    if format == DEPTH_FORMAT {
        vk::ImageAspectFlags::DEPTH
    } else {
        vk::ImageAspectFlags::COLOR
    }
}

/// A subresource range covering the single mip level and layer of an image of `format`.
pub(crate) fn full_range(format: vk::Format) -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange {
        aspect_mask: aspect_of(format),
        base_mip_level: 0,
        level_count: 1,
        base_array_layer: 0,
        layer_count: 1,
    }
}

/// A view of the whole single-level image.
pub(crate) fn create_view(
    device: &Device,
    image: vk::Image,
    format: vk::Format,
) -> GpuResult<vk::ImageView> {
    let info = vk::ImageViewCreateInfo::default()
        .image(image)
        .view_type(vk::ImageViewType::TYPE_2D)
        .format(format)
        .subresource_range(full_range(format));
    // SAFETY: `image` is a live 2D image of `format` with one level and layer.
    unsafe { device.raw.create_image_view(&info, None) }.vk("vkCreateImageView")
}

impl Image {
    pub(crate) fn new(device: &Device, desc: &ImageDesc<'_>) -> GpuResult<Self> {
        let info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(desc.format)
            .extent(vk::Extent3D {
                width: desc.extent.width,
                height: desc.extent.height,
                depth: 1,
            })
            .mip_levels(1)
            .array_layers(1)
            .samples(desc.samples)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(desc.usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        // SAFETY: valid device and create info (extent checked non-zero by callers).
        let raw = unsafe { device.raw.create_image(&info, None) }.vk("vkCreateImage")?;
        // SAFETY: `raw` was just created from this device.
        let requirements = unsafe { device.raw.get_image_memory_requirements(raw) };
        let allocation =
            match device.allocate(desc.name, requirements, MemoryLocation::GpuOnly, false) {
                Ok(a) => a,
                Err(e) => {
                    // SAFETY: the image is unused and has no memory bound.
                    unsafe { device.raw.destroy_image(raw, None) };
                    return Err(e);
                }
            };
        let mut image = Self {
            raw,
            view: vk::ImageView::null(),
            allocation,
        };
        // SAFETY: memory type and offset satisfy `requirements`.
        let bound = unsafe {
            device
                .raw
                .bind_image_memory(raw, image.allocation.memory(), image.allocation.offset())
        };
        if let Err(e) = bound.vk("vkBindImageMemory") {
            // SAFETY: created just above and never used by the GPU.
            unsafe { image.destroy(device) };
            return Err(e);
        }
        match create_view(device, raw, desc.format) {
            Ok(view) => image.view = view,
            Err(e) => {
                // SAFETY: created just above and never used by the GPU.
                unsafe { image.destroy(device) };
                return Err(e);
            }
        }
        Ok(image)
    }

    /// Destroys view, image and memory.
    ///
    /// # Safety
    /// No submitted GPU work that uses these objects may still be pending (the device is idle
    /// or lost, or they were never used).
    pub(crate) unsafe fn destroy(self, device: &Device) {
        if self.view != vk::ImageView::null() {
            // SAFETY: no pending GPU use (caller's guarantee); destroyed once.
            unsafe { device.raw.destroy_image_view(self.view, None) };
        }
        // SAFETY: as above.
        unsafe { device.raw.destroy_image(self.raw, None) };
        if let Some(a) = device.allocator().as_mut() {
            let _ = a.free(self.allocation);
        }
    }
}
