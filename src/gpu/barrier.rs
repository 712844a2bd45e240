//! synchronization2 image barriers for a frame's attachments.
//!
//! Target images (depth, MSAA colour, the offscreen colour image) are shared by both frame
//! slots. Each frame starts with a barrier from `UNDEFINED` whose source scope covers the
//! previous frame's accesses, which serialises the two slots on those images while leaving
//! host-side work (mirror writes, recording) overlapped with the GPU.

use ash::vk;

use super::image::full_range;
use super::pipeline::DEPTH_FORMAT;
use super::target::TargetView;

/// One image's layout transition with its source and destination scopes.
pub(crate) fn image_barrier(
    image: vk::Image,
    format: vk::Format,
    src: (vk::PipelineStageFlags2, vk::AccessFlags2),
    dst: (vk::PipelineStageFlags2, vk::AccessFlags2),
    layouts: (vk::ImageLayout, vk::ImageLayout),
) -> vk::ImageMemoryBarrier2<'static> {
    vk::ImageMemoryBarrier2::default()
        .src_stage_mask(src.0)
        .src_access_mask(src.1)
        .dst_stage_mask(dst.0)
        .dst_access_mask(dst.1)
        .old_layout(layouts.0)
        .new_layout(layouts.1)
        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .image(image)
        .subresource_range(full_range(format))
}

/// Barriers that discard last frame's contents and make every attachment writable.
pub(crate) fn begin_barriers(
    view: &TargetView,
    swapchain: bool,
) -> Vec<vk::ImageMemoryBarrier2<'static>> {
    use vk::AccessFlags2 as A;
    use vk::PipelineStageFlags2 as S;
    let color_stage = S::COLOR_ATTACHMENT_OUTPUT;
    let color_dst = (
        color_stage,
        A::COLOR_ATTACHMENT_WRITE | A::COLOR_ATTACHMENT_READ,
    );
    let to_color = (
        vk::ImageLayout::UNDEFINED,
        vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
    );
    // A swapchain image comes from the acquire semaphore, waited at COLOR_ATTACHMENT_OUTPUT;
    // the offscreen image was last read by the previous frame's copy.
    let target_src = if swapchain {
        (color_stage, A::NONE)
    } else {
        (color_stage | S::COPY, A::COLOR_ATTACHMENT_WRITE)
    };
    let mut barriers = vec![image_barrier(
        view.image,
        view.format,
        target_src,
        color_dst,
        to_color,
    )];
    if let Some((msaa, _)) = view.msaa {
        barriers.push(image_barrier(
            msaa,
            view.format,
            (color_stage, A::COLOR_ATTACHMENT_WRITE),
            color_dst,
            to_color,
        ));
    }
    let depth_stages = S::EARLY_FRAGMENT_TESTS | S::LATE_FRAGMENT_TESTS;
    barriers.push(image_barrier(
        view.depth.0,
        DEPTH_FORMAT,
        (depth_stages, A::DEPTH_STENCIL_ATTACHMENT_WRITE),
        (
            depth_stages,
            A::DEPTH_STENCIL_ATTACHMENT_READ | A::DEPTH_STENCIL_ATTACHMENT_WRITE,
        ),
        (
            vk::ImageLayout::UNDEFINED,
            vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
        ),
    ));
    barriers
}

/// The barrier that hands a rendered swapchain image to the presentation engine.
pub(crate) fn to_present(view: &TargetView) -> vk::ImageMemoryBarrier2<'static> {
    use vk::AccessFlags2 as A;
    use vk::PipelineStageFlags2 as S;
    image_barrier(
        view.image,
        view.format,
        (S::COLOR_ATTACHMENT_OUTPUT, A::COLOR_ATTACHMENT_WRITE),
        (S::ALL_COMMANDS, A::NONE),
        (
            vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
            vk::ImageLayout::PRESENT_SRC_KHR,
        ),
    )
}

/// Records `barriers` into `cmd`.
///
/// # Safety
/// `cmd` must be recording outside a rendering scope, and the images must be live.
pub(crate) unsafe fn record(
    device: &ash::Device,
    cmd: vk::CommandBuffer,
    barriers: &[vk::ImageMemoryBarrier2<'_>],
) {
    let info = vk::DependencyInfo::default().image_memory_barriers(barriers);
    // SAFETY: the caller guarantees a recording command buffer and live images.
    unsafe { device.cmd_pipeline_barrier2(cmd, &info) };
}
