//! Window surface and swapchain: creation from a raw-window-handle window, present-mode
//! choice, recreation on resize / out-of-date / suboptimal, and minimised (zero-size) windows.

use std::sync::Arc;

use ash::vk;
use raw_window_handle::{HasDisplayHandle, HasWindowHandle};

use super::FRAMES_IN_FLIGHT;
use super::device::Device;
use super::error::{GpuError, GpuResult, VkResultExt};
use super::frame::TargetView;
use super::image::{Attachments, create_view};
use super::renderer::{Orphan, Renderer};

/// Parameters for [`Renderer::create_swapchain`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SwapchainDesc {
    /// Window inner width in physical pixels (used when the surface does not dictate it).
    pub width: u32,
    /// Window inner height in physical pixels.
    pub height: u32,
    /// `true`: FIFO (vsync). `false`: MAILBOX, else IMMEDIATE, else FIFO.
    pub vsync: bool,
    /// MSAA sample count; 0 picks [`Renderer::default_samples`].
    pub samples: u32,
}

/// A surface and its swapchain. Destroy with [`Renderer::destroy_swapchain`].
///
/// It holds a reference to its window, so the window's handles stay valid for as long as the
/// surface exists.
pub struct Swapchain {
    /// Keeps the window (and so its native handles) alive; dropped after the surface is gone.
    _window: Arc<dyn std::any::Any + Send + Sync>,
    surface: vk::SurfaceKHR,
    pub(crate) raw: vk::SwapchainKHR,
    images: Vec<vk::Image>,
    views: Vec<vk::ImageView>,
    /// One per image: a present waits on the semaphore of the image it shows, so reuse is
    /// safe once that image is acquired again.
    pub(crate) render_finished: Vec<vk::Semaphore>,
    attachments: Option<Attachments>,
    format: vk::SurfaceFormatKHR,
    extent: vk::Extent2D,
    wanted: vk::Extent2D,
    vsync: bool,
    samples: vk::SampleCountFlags,
    present_mode: vk::PresentModeKHR,
    /// Set on resize, out-of-date or suboptimal; the next begin recreates.
    pub(crate) stale: bool,
    /// Swapchains replaced by a rebuild, kept with their semaphores until presentation is
    /// surely done with them (see [`Retired`]).
    retired: Vec<Retired>,
}

/// A swapchain replaced by a rebuild. `vkDeviceWaitIdle` covers queue work but not the
/// presentation engine, which may still wait on the old swapchain's render-finished
/// semaphores or show its images, so they are destroyed only after `until` frames have been
/// submitted: by then every image of the old swapchain has been cycled through by presents
/// that the presentation engine processes in order. (`VK_EXT_swapchain_maintenance1`'s present
/// fences would make this exact; lavapipe 22.3 does not offer it.)
struct Retired {
    raw: vk::SwapchainKHR,
    semaphores: Vec<vk::Semaphore>,
    until: u64,
}

impl Swapchain {
    /// Records a new window size; the swapchain is rebuilt at the next frame. A zero size
    /// (minimised window) makes `begin_swapchain` return `None` until a real size arrives.
    pub fn resize(&mut self, width: u32, height: u32) {
        let wanted = vk::Extent2D { width, height };
        if wanted != self.wanted {
            self.wanted = wanted;
            self.stale = true;
        }
    }

    /// Switches between FIFO and the low-latency modes at the next frame.
    pub fn set_vsync(&mut self, vsync: bool) {
        if vsync != self.vsync {
            self.vsync = vsync;
            self.stale = true;
        }
    }

    /// Current image size (0×0 before the first successful build).
    pub fn extent(&self) -> [u32; 2] {
        [self.extent.width, self.extent.height]
    }

    /// Colour format of the swapchain images.
    pub fn format(&self) -> vk::Format {
        self.format.format
    }

    /// Present mode in use.
    pub fn present_mode(&self) -> vk::PresentModeKHR {
        self.present_mode
    }

    pub(crate) fn view(&self, image_index: u32) -> Option<TargetView> {
        let a = self.attachments.as_ref()?;
        let i = image_index as usize;
        Some(TargetView {
            image: *self.images.get(i)?,
            view: *self.views.get(i)?,
            msaa: a.msaa.as_ref().map(|m| (m.raw, m.view)),
            depth: (a.depth.raw, a.depth.view),
            extent: self.extent,
            format: self.format.format,
            samples: self.samples,
        })
    }

    /// Destroys views and attachments (not the swapchain, surface or semaphores).
    ///
    /// # Safety
    /// The device must be idle (or lost): no frame still renders into these attachments.
    unsafe fn destroy_images(&mut self, device: &Device) {
        for v in self.views.drain(..) {
            // SAFETY: the caller made the device idle.
            unsafe { device.raw.destroy_image_view(v, None) };
        }
        self.images.clear();
        if let Some(a) = self.attachments.take() {
            // SAFETY: as above.
            unsafe { a.destroy(device) };
        }
    }
}

/// Prefers an 8-bit sRGB format so that linear shader output is encoded for display.
pub(crate) fn choose_format(formats: &[vk::SurfaceFormatKHR]) -> Option<vk::SurfaceFormatKHR> {
    let srgb = |f: vk::Format| {
        formats
            .iter()
            .copied()
            .find(|s| s.format == f && s.color_space == vk::ColorSpaceKHR::SRGB_NONLINEAR)
    };
    srgb(vk::Format::B8G8R8A8_SRGB)
        .or_else(|| srgb(vk::Format::R8G8B8A8_SRGB))
        .or_else(|| formats.first().copied())
}

/// FIFO for vsync (always supported); otherwise MAILBOX, IMMEDIATE, FIFO in that order.
pub(crate) fn choose_present_mode(modes: &[vk::PresentModeKHR], vsync: bool) -> vk::PresentModeKHR {
    if vsync {
        return vk::PresentModeKHR::FIFO;
    }
    [vk::PresentModeKHR::MAILBOX, vk::PresentModeKHR::IMMEDIATE]
        .into_iter()
        .find(|m| modes.contains(m))
        .unwrap_or(vk::PresentModeKHR::FIFO)
}

impl Renderer {
    /// Creates a surface for `window` and its swapchain. The renderer must have been created
    /// with `RendererDesc::display` set to the window's display. The swapchain keeps `window`
    /// alive (the surface must not outlive its window).
    pub fn create_swapchain<W>(
        &mut self,
        window: Arc<W>,
        desc: &SwapchainDesc,
    ) -> GpuResult<Swapchain>
    where
        W: HasDisplayHandle + HasWindowHandle + Send + Sync + 'static,
    {
        let surface_fn = self.instance.surface_fn.as_ref().ok_or_else(|| {
            GpuError::Surface(
                "renderer was created without a display (RendererDesc::display)".into(),
            )
        })?;
        if self.device.swapchain_fn.is_none() {
            return Err(GpuError::Surface("device has no VK_KHR_swapchain".into()));
        }
        let display = window
            .display_handle()
            .map_err(|e| GpuError::Surface(e.to_string()))?
            .as_raw();
        let handle = window
            .window_handle()
            .map_err(|e| GpuError::Surface(e.to_string()))?
            .as_raw();
        // SAFETY: the handles come from a live window, which the swapchain keeps alive (it
        // holds the Arc) until after the surface is destroyed.
        let surface = unsafe {
            ash_window::create_surface(
                &self.instance.entry,
                &self.instance.raw,
                display,
                handle,
                None,
            )
        }
        .vk("vkCreate*SurfaceKHR")?;
        // SAFETY: valid physical device, queue family and surface.
        let supported = unsafe {
            surface_fn.get_physical_device_surface_support(
                self.device.physical,
                self.device.queue_family,
                surface,
            )
        };
        if !matches!(supported, Ok(true)) {
            // SAFETY: the surface is unused.
            unsafe { surface_fn.destroy_surface(surface, None) };
            return Err(GpuError::Surface(format!(
                "{} cannot present to this window",
                self.device.caps.name
            )));
        }
        let samples = match self.resolve_samples(desc.samples) {
            Ok(s) => s,
            Err(e) => {
                // SAFETY: the surface is unused.
                unsafe { surface_fn.destroy_surface(surface, None) };
                return Err(e);
            }
        };
        let mut swapchain = Swapchain {
            _window: window,
            surface,
            raw: vk::SwapchainKHR::null(),
            images: Vec::new(),
            views: Vec::new(),
            render_finished: Vec::new(),
            attachments: None,
            format: vk::SurfaceFormatKHR::default(),
            extent: vk::Extent2D::default(),
            wanted: vk::Extent2D {
                width: desc.width,
                height: desc.height,
            },
            vsync: desc.vsync,
            samples,
            present_mode: vk::PresentModeKHR::FIFO,
            stale: true,
            retired: Vec::new(),
        };
        if let Err(e) = self.rebuild_swapchain(&mut swapchain) {
            // SAFETY: the swapchain was just created: no frame ever rendered into its images.
            unsafe { self.destroy_swapchain_now(swapchain) };
            return Err(e);
        }
        Ok(swapchain)
    }

    /// Rebuilds the swapchain for the current surface size. Returns `false` (and leaves no
    /// images) when the surface has zero area, i.e. the window is minimised.
    pub(crate) fn rebuild_swapchain(&mut self, sc: &mut Swapchain) -> GpuResult<bool> {
        self.wait_idle()?;
        let device = &*self.device;
        let (Some(surface_fn), Some(swapchain_fn)) = (
            self.instance.surface_fn.as_ref(),
            device.swapchain_fn.as_ref(),
        ) else {
            return Err(GpuError::Surface("no surface support".into()));
        };
        let old_images = sc.images.len();
        // SAFETY: the device is idle (waited above), so no frame renders into them.
        unsafe { sc.destroy_images(device) };
        // SAFETY: valid physical device and surface for all three queries.
        let (caps, formats, modes) = unsafe {
            (
                surface_fn
                    .get_physical_device_surface_capabilities(device.physical, sc.surface)
                    .vk("vkGetPhysicalDeviceSurfaceCapabilitiesKHR")?,
                surface_fn
                    .get_physical_device_surface_formats(device.physical, sc.surface)
                    .vk("vkGetPhysicalDeviceSurfaceFormatsKHR")?,
                surface_fn
                    .get_physical_device_surface_present_modes(device.physical, sc.surface)
                    .vk("vkGetPhysicalDeviceSurfacePresentModesKHR")?,
            )
        };
        // u32::MAX means "the swapchain decides"; otherwise the surface dictates the size.
        let extent = if caps.current_extent.width != u32::MAX {
            caps.current_extent
        } else {
            vk::Extent2D {
                width: sc
                    .wanted
                    .width
                    .clamp(caps.min_image_extent.width, caps.max_image_extent.width),
                height: sc
                    .wanted
                    .height
                    .clamp(caps.min_image_extent.height, caps.max_image_extent.height),
            }
        };
        if extent.width == 0 || extent.height == 0 || sc.wanted.width == 0 || sc.wanted.height == 0
        {
            sc.extent = vk::Extent2D::default();
            return Ok(false);
        }
        let format = choose_format(&formats)
            .ok_or_else(|| GpuError::Surface("surface reports no formats".into()))?;
        let present_mode = choose_present_mode(&modes, sc.vsync);
        let mut image_count = caps.min_image_count + 1;
        if caps.max_image_count > 0 {
            image_count = image_count.min(caps.max_image_count);
        }
        let composite = [
            vk::CompositeAlphaFlagsKHR::OPAQUE,
            vk::CompositeAlphaFlagsKHR::INHERIT,
            vk::CompositeAlphaFlagsKHR::PRE_MULTIPLIED,
            vk::CompositeAlphaFlagsKHR::POST_MULTIPLIED,
        ]
        .into_iter()
        .find(|c| caps.supported_composite_alpha.contains(*c))
        .unwrap_or(vk::CompositeAlphaFlagsKHR::OPAQUE);
        let old = sc.raw;
        let info = vk::SwapchainCreateInfoKHR::default()
            .surface(sc.surface)
            .min_image_count(image_count)
            .image_format(format.format)
            .image_color_space(format.color_space)
            .image_extent(extent)
            .image_array_layers(1)
            .image_usage(vk::ImageUsageFlags::COLOR_ATTACHMENT)
            .image_sharing_mode(vk::SharingMode::EXCLUSIVE)
            .pre_transform(caps.current_transform)
            .composite_alpha(composite)
            .present_mode(present_mode)
            .clipped(true)
            .old_swapchain(old);
        // SAFETY: parameters were validated against the surface capabilities above.
        let raw = unsafe { swapchain_fn.create_swapchain(&info, None) }.vk("vkCreateSwapchainKHR");
        if old != vk::SwapchainKHR::null() {
            // Passing it as old_swapchain retired it (even if creation failed); presentation
            // may still use it and its semaphores, so they are destroyed later.
            sc.retired.push(Retired {
                raw: old,
                semaphores: std::mem::take(&mut sc.render_finished),
                until: self.frame_number + (FRAMES_IN_FLIGHT + old_images.max(1)) as u64,
            });
            sc.raw = vk::SwapchainKHR::null();
        }
        sc.raw = raw?;
        sc.format = format;
        sc.present_mode = present_mode;
        sc.extent = extent;
        // SAFETY: valid swapchain.
        sc.images =
            unsafe { swapchain_fn.get_swapchain_images(sc.raw) }.vk("vkGetSwapchainImagesKHR")?;
        for &image in &sc.images {
            sc.views.push(create_view(device, image, format.format)?);
        }
        while sc.render_finished.len() < sc.images.len() {
            // SAFETY: valid device.
            let s = unsafe {
                device
                    .raw
                    .create_semaphore(&vk::SemaphoreCreateInfo::default(), None)
            }
            .vk("vkCreateSemaphore")?;
            sc.render_finished.push(s);
        }
        sc.attachments = Some(Attachments::new(device, extent, format.format, sc.samples)?);
        sc.stale = false;
        Ok(true)
    }

    /// Destroys the swapchain and its surface (waits for the GPU first).
    pub fn destroy_swapchain(&mut self, swapchain: Swapchain) -> GpuResult<()> {
        match self.wait_idle() {
            Ok(()) => {
                // SAFETY: the device is idle.
                unsafe { self.destroy_swapchain_now(swapchain) };
                Ok(())
            }
            Err(e) if e.is_device_lost() => {
                // SAFETY: nothing executes on a lost device.
                unsafe { self.destroy_swapchain_now(swapchain) };
                Err(e)
            }
            Err(e) => {
                // Work may still render into its images: keep it until the renderer goes.
                self.orphans.push(Orphan::Swapchain(swapchain));
                Err(e)
            }
        }
    }

    /// Destroys retired swapchains whose presents are surely done (`all`: every one, at
    /// teardown after the device went idle).
    pub(crate) fn collect_retired(&self, sc: &mut Swapchain, all: bool) {
        let device = &*self.device;
        let Some(swapchain_fn) = device.swapchain_fn.as_ref() else {
            return;
        };
        let frame = self.frame_number;
        sc.retired.retain(|r| {
            if !all && frame < r.until {
                return true;
            }
            // SAFETY: `until` frames have been submitted since the swapchain was retired, so the
            // presents that waited on these semaphores and showed its images have been processed
            // (or, at teardown, the device is idle and the surface is about to go).
            unsafe {
                for &s in &r.semaphores {
                    device.raw.destroy_semaphore(s, None);
                }
                swapchain_fn.destroy_swapchain(r.raw, None);
            }
            false
        });
    }

    /// Destroys the swapchain, its retired predecessors, semaphores and surface.
    ///
    /// # Safety
    /// The device must be idle or lost (no frame renders into its images).
    pub(crate) unsafe fn destroy_swapchain_now(&mut self, mut sc: Swapchain) {
        self.collect_retired(&mut sc, true);
        let device = &*self.device;
        // SAFETY: the caller guarantees an idle (or lost) device.
        unsafe { sc.destroy_images(device) };
        if let Some(f) = device.swapchain_fn.as_ref()
            && sc.raw != vk::SwapchainKHR::null()
        {
            // SAFETY: idle device, swapchain destroyed once.
            unsafe { f.destroy_swapchain(sc.raw, None) };
        }
        for s in sc.render_finished.drain(..) {
            // SAFETY: the device is idle and the swapchain that presented with these
            // semaphores is gone. Present completion itself cannot be observed without
            // VK_EXT_swapchain_maintenance1; this is the teardown order the Vulkan samples use.
            unsafe { device.raw.destroy_semaphore(s, None) };
        }
        if let Some(f) = self.instance.surface_fn.as_ref() {
            // SAFETY: the swapchain using the surface is gone.
            unsafe { f.destroy_surface(sc.surface, None) };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn present_mode_preferences() {
        use vk::PresentModeKHR as P;
        assert_eq!(choose_present_mode(&[P::FIFO, P::MAILBOX], true), P::FIFO);
        assert_eq!(
            choose_present_mode(&[P::FIFO, P::MAILBOX, P::IMMEDIATE], false),
            P::MAILBOX
        );
        assert_eq!(
            choose_present_mode(&[P::IMMEDIATE, P::FIFO], false),
            P::IMMEDIATE
        );
        assert_eq!(choose_present_mode(&[P::FIFO], false), P::FIFO);
    }

    #[test]
    fn format_prefers_srgb() {
        let f = |format| vk::SurfaceFormatKHR {
            format,
            color_space: vk::ColorSpaceKHR::SRGB_NONLINEAR,
        };
        let formats = [f(vk::Format::B8G8R8A8_UNORM), f(vk::Format::B8G8R8A8_SRGB)];
        assert_eq!(choose_format(&formats), Some(f(vk::Format::B8G8R8A8_SRGB)));
        assert_eq!(choose_format(&formats[..1]), Some(formats[0]));
        assert_eq!(choose_format(&[]), None);
    }
}
