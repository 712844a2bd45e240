//! A frame's commands on its target's static layer ([`StaticLayer`]): announce, save and
//! restore, whole or within a rectangle. The layer's images and their synchronization are in
//! `layer.rs`.

use ash::vk;
use std::sync::atomic::Ordering;
use vk::AccessFlags2 as A;
use vk::ImageLayout as L;
use vk::PipelineStageFlags2 as S;

use super::barrier::{self, image_barrier};
use super::error::GpuResult;
use super::frame::{Frame, FrameTarget};
use super::layer::{
    COLOR_ACCESS, DEPTH_ACCESS, DEPTH_STAGES, LayerImages, LayerPart, NEXT_TOKEN, Restore,
    StaticLayer, clamp_rect, rect_copy,
};
use super::pipeline::DEPTH_FORMAT;

impl Frame<'_> {
    /// The layer of this frame's target (`None` for multisampled targets and swapchains whose
    /// images cannot be copied).
    fn static_layer(&mut self) -> Option<&mut StaticLayer> {
        match &mut self.target {
            FrameTarget::Offscreen(t) => t.attachments.layer.as_mut(),
            FrameTarget::Swapchain { swapchain, .. } => swapchain.layer_mut(),
        }
    }

    fn layer(&mut self, part: LayerPart) -> Option<&mut LayerImages> {
        self.static_layer().map(|l| l.part(part))
    }

    /// Whether this frame's target has a static layer.
    pub fn has_static_layer(&mut self) -> bool {
        self.static_layer().is_some()
    }

    /// Announces a [`Frame::save_static_layer`] before the frame's first draw, so rendering
    /// stores its depth (other frames let the driver discard it).
    pub fn keep_depth(&mut self) {
        if !self.rendering {
            self.keep_depth = true;
        }
    }

    /// Saves what was drawn so far (colour and depth) into `part` of the target's static
    /// layer and goes on drawing over it. Returns the save's token for
    /// [`Frame::restore_static_layer`]; `None` when the target has no layer, or rendering
    /// began without [`Frame::keep_depth`] (nothing is recorded then).
    pub fn save_static_layer(&mut self, part: LayerPart) -> GpuResult<Option<u64>> {
        let (view, cmd) = (self.view, self.cmd);
        if !self.keep_depth {
            return Ok(None);
        }
        let Some(layer) = self.layer(part) else {
            return Ok(None);
        };
        let (lc, ld) = (layer.color.raw, layer.depth.raw);
        // The clear and the draws so far must land in the attachments first.
        self.ensure_rendering();
        let raw = &self.ctx.device.raw;
        // SAFETY: `cmd` is recording inside the rendering scope begun above.
        unsafe { raw.cmd_end_rendering(cmd) };
        self.rendering = false;
        let to_src = [
            image_barrier(
                view.image,
                view.format,
                (S::COLOR_ATTACHMENT_OUTPUT, A::COLOR_ATTACHMENT_WRITE),
                (S::COPY, A::TRANSFER_READ),
                (L::COLOR_ATTACHMENT_OPTIMAL, L::TRANSFER_SRC_OPTIMAL),
            ),
            image_barrier(
                view.depth.0,
                DEPTH_FORMAT,
                (DEPTH_STAGES, A::DEPTH_STENCIL_ATTACHMENT_WRITE),
                (S::COPY, A::TRANSFER_READ),
                (L::DEPTH_STENCIL_ATTACHMENT_OPTIMAL, L::TRANSFER_SRC_OPTIMAL),
            ),
            // Earlier restores read the layer: they finish before it is overwritten.
            image_barrier(
                lc,
                view.format,
                (S::COPY, A::NONE),
                (S::COPY, A::TRANSFER_WRITE),
                (L::UNDEFINED, L::TRANSFER_DST_OPTIMAL),
            ),
            image_barrier(
                ld,
                DEPTH_FORMAT,
                (S::COPY, A::NONE),
                (S::COPY, A::TRANSFER_WRITE),
                (L::UNDEFINED, L::TRANSFER_DST_OPTIMAL),
            ),
        ];
        let back = [
            image_barrier(
                view.image,
                view.format,
                (S::COPY, A::NONE),
                (S::COLOR_ATTACHMENT_OUTPUT, COLOR_ACCESS),
                (L::TRANSFER_SRC_OPTIMAL, L::COLOR_ATTACHMENT_OPTIMAL),
            ),
            image_barrier(
                view.depth.0,
                DEPTH_FORMAT,
                (S::COPY, A::NONE),
                (DEPTH_STAGES, DEPTH_ACCESS),
                (L::TRANSFER_SRC_OPTIMAL, L::DEPTH_STENCIL_ATTACHMENT_OPTIMAL),
            ),
            image_barrier(
                lc,
                view.format,
                (S::COPY, A::TRANSFER_WRITE),
                (S::COPY, A::TRANSFER_READ),
                (L::TRANSFER_DST_OPTIMAL, L::TRANSFER_SRC_OPTIMAL),
            ),
            image_barrier(
                ld,
                DEPTH_FORMAT,
                (S::COPY, A::TRANSFER_WRITE),
                (S::COPY, A::TRANSFER_READ),
                (L::TRANSFER_DST_OPTIMAL, L::TRANSFER_SRC_OPTIMAL),
            ),
        ];
        let whole = clamp_rect(None, view.extent);
        let color_copy = [rect_copy(vk::ImageAspectFlags::COLOR, whole)];
        let depth_copy = [rect_copy(vk::ImageAspectFlags::DEPTH, whole)];
        // SAFETY: recording outside a rendering scope; the target's attachments and the layer
        // (same size and formats, TRANSFER usages) are live for this frame; the barriers put
        // every image in the layout its copy names.
        unsafe {
            barrier::record(raw, cmd, &to_src);
            raw.cmd_copy_image(
                cmd,
                view.image,
                L::TRANSFER_SRC_OPTIMAL,
                lc,
                L::TRANSFER_DST_OPTIMAL,
                &color_copy,
            );
            raw.cmd_copy_image(
                cmd,
                view.depth.0,
                L::TRANSFER_SRC_OPTIMAL,
                ld,
                L::TRANSFER_DST_OPTIMAL,
                &depth_copy,
            );
            barrier::record(raw, cmd, &back);
        }
        self.load = true;
        self.bound = Default::default();
        let token = NEXT_TOKEN.fetch_add(1, Ordering::Relaxed);
        if let Some(layer) = self.layer(part) {
            layer.saved = Some(token);
        }
        Ok(Some(token))
    }

    /// Copies `rect` (`None`: all) of `part` of the static layer, saved with `token`, into
    /// the frame's colour, and with [`Restore::ColorAndDepth`] its depth: one
    /// `vkCmdCopyImage` each. Before the first draw it starts the frame from the layer instead
    /// of clearing; later it replaces what was drawn in `rect`. Returns `false`, recording
    /// nothing, when the part holds another save (or none, or the target has no layer).
    ///
    /// Depth left out keeps whatever the attachment held, undefined at a frame's start: only
    /// for pixels no depth-tested draw of the frame reaches.
    pub fn restore_static_layer(
        &mut self,
        part: LayerPart,
        token: u64,
        rect: Option<[u32; 4]>,
        what: Restore,
    ) -> GpuResult<bool> {
        let (view, cmd) = (self.view, self.cmd);
        let Some(layer) = self.layer(part).filter(|l| l.saved == Some(token)) else {
            return Ok(false);
        };
        let (lc, ld) = (layer.color.raw, layer.depth.raw);
        let rect = clamp_rect(rect, view.extent);
        if rect[2] == 0 || rect[3] == 0 {
            return Ok(true);
        }
        if self.rendering {
            let raw = &self.ctx.device.raw;
            // SAFETY: `cmd` is recording inside the rendering scope the flag says is open.
            unsafe { raw.cmd_end_rendering(cmd) };
            self.rendering = false;
        }
        // Earlier draws (or begin's layout transition) finish their attachment reads and
        // writes before the copy overwrites the pixels.
        let to_dst = [
            image_barrier(
                view.image,
                view.format,
                (S::COLOR_ATTACHMENT_OUTPUT, A::COLOR_ATTACHMENT_WRITE),
                (S::COPY, A::TRANSFER_WRITE),
                (L::COLOR_ATTACHMENT_OPTIMAL, L::TRANSFER_DST_OPTIMAL),
            ),
            image_barrier(
                view.depth.0,
                DEPTH_FORMAT,
                (DEPTH_STAGES, A::DEPTH_STENCIL_ATTACHMENT_WRITE),
                (S::COPY, A::TRANSFER_WRITE),
                (L::DEPTH_STENCIL_ATTACHMENT_OPTIMAL, L::TRANSFER_DST_OPTIMAL),
            ),
        ];
        let back = [
            image_barrier(
                view.image,
                view.format,
                (S::COPY, A::TRANSFER_WRITE),
                (S::COLOR_ATTACHMENT_OUTPUT, COLOR_ACCESS),
                (L::TRANSFER_DST_OPTIMAL, L::COLOR_ATTACHMENT_OPTIMAL),
            ),
            image_barrier(
                view.depth.0,
                DEPTH_FORMAT,
                (S::COPY, A::TRANSFER_WRITE),
                (DEPTH_STAGES, DEPTH_ACCESS),
                (L::TRANSFER_DST_OPTIMAL, L::DEPTH_STENCIL_ATTACHMENT_OPTIMAL),
            ),
        ];
        let color_copy = [rect_copy(vk::ImageAspectFlags::COLOR, rect)];
        let depth_copy = [rect_copy(vk::ImageAspectFlags::DEPTH, rect)];
        let images = match what {
            Restore::Color => 1,
            Restore::ColorAndDepth => 2,
        };
        let raw = &self.ctx.device.raw;
        // SAFETY: recording outside a rendering scope (ended above); the layer part holds a
        // save of this target (same size and formats) in TRANSFER_SRC_OPTIMAL, made visible to
        // copies by the save's closing barrier; `rect` lies inside both images; the barriers
        // cover exactly the images copied into.
        unsafe {
            barrier::record(raw, cmd, &to_dst[..images]);
            raw.cmd_copy_image(
                cmd,
                lc,
                L::TRANSFER_SRC_OPTIMAL,
                view.image,
                L::TRANSFER_DST_OPTIMAL,
                &color_copy,
            );
            if what == Restore::ColorAndDepth {
                raw.cmd_copy_image(
                    cmd,
                    ld,
                    L::TRANSFER_SRC_OPTIMAL,
                    view.depth.0,
                    L::TRANSFER_DST_OPTIMAL,
                    &depth_copy,
                );
            }
            barrier::record(raw, cmd, &back[..images]);
        }
        self.load = true;
        self.bound = Default::default();
        Ok(true)
    }
}
