//! What a frame renders into, as the frame sees it: the attachments of an offscreen target or
//! of one swapchain image. Both target kinds hand out this plain view, so recording code does
//! not depend on either.

use ash::vk;

/// Attachments of the target of one frame, resolved at begin.
#[derive(Clone, Copy)]
pub(crate) struct TargetView {
    pub image: vk::Image,
    pub view: vk::ImageView,
    pub msaa: Option<(vk::Image, vk::ImageView)>,
    pub depth: (vk::Image, vk::ImageView),
    pub extent: vk::Extent2D,
    pub format: vk::Format,
    pub samples: vk::SampleCountFlags,
    /// The target has a static layer (its depth is stored at the end of rendering).
    pub layer: bool,
}
