//! Window surface and swapchain: creation from a raw-window-handle window, present-mode
//! choice, recreation on resize / out-of-date / suboptimal, and minimised (zero-size) windows.

use std::sync::Arc;

use ash::vk;
use raw_window_handle::{HasDisplayHandle, HasWindowHandle};

use super::FRAMES_IN_FLIGHT;
use super::attachments::Attachments;
use super::device::Device;
use super::error::{GpuError, GpuResult, VkResultExt, vk_error};
use super::image::create_view;
use super::instance::Instance;
use super::layer::StaticLayer;
use super::target::TargetView;

/// Parameters for [`super::Renderer::create_swapchain`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SwapchainDesc {
    /// Window inner width in physical pixels (used when the surface does not dictate it).
    pub width: u32,
    /// Window inner height in physical pixels.
    pub height: u32,
    /// `true`: FIFO (vsync). `false`: MAILBOX, else IMMEDIATE, else FIFO.
    pub vsync: bool,
    /// MSAA sample count; 0 picks [`super::Renderer::default_samples`].
    pub samples: u32,
}

/// A surface and its swapchain. Destroy with [`super::Renderer::destroy_swapchain`].
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
    /// Whether the images take transfers (then the attachments have a static layer).
    copyable: bool,
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
    #[must_use]
    pub fn extent(&self) -> [u32; 2] {
        [self.extent.width, self.extent.height]
    }

    /// Colour format of the swapchain images.
    #[must_use]
    pub fn format(&self) -> vk::Format {
        self.format.format
    }

    /// Present mode in use.
    #[must_use]
    pub fn present_mode(&self) -> vk::PresentModeKHR {
        self.present_mode
    }

    /// The static layer of the current attachments.
    pub(crate) fn layer_mut(&mut self) -> Option<&mut StaticLayer> {
        self.attachments.as_mut()?.layer.as_mut()
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
            layer: a.layer.is_some(),
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

impl Swapchain {
    /// Creates a surface for `window` and its swapchain (see
    /// [`super::Renderer::create_swapchain`]).
    pub(crate) fn new<W>(
        instance: &Instance,
        device: &Device,
        window: Arc<W>,
        desc: &SwapchainDesc,
    ) -> GpuResult<Self>
    where
        W: HasDisplayHandle + HasWindowHandle + Send + Sync + 'static,
    {
        let surface_fn = instance.surface_fn.as_ref().ok_or_else(|| {
            GpuError::Surface(
                "renderer was created without a display (RendererDesc::display)".into(),
            )
        })?;
        if device.swapchain_fn.is_none() {
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
            ash_window::create_surface(&instance.entry, &instance.raw, display, handle, None)
        }
        .vk("vkCreate*SurfaceKHR")?;
        // SAFETY: valid physical device, queue family and surface.
        let supported = unsafe {
            surface_fn.get_physical_device_surface_support(
                device.physical,
                device.queue_family,
                surface,
            )
        };
        if !matches!(supported, Ok(true)) {
            // SAFETY: the surface is unused.
            unsafe { surface_fn.destroy_surface(surface, None) };
            return Err(GpuError::Surface(format!(
                "{} cannot present to this window",
                device.caps.name
            )));
        }
        let samples = match device.caps.resolve_samples(desc.samples) {
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
            copyable: false,
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
        if let Err(e) = swapchain.rebuild(instance, device, 0) {
            // SAFETY: the swapchain was just created: no frame ever rendered into its images.
            unsafe { swapchain.destroy(instance, device) };
            return Err(e);
        }
        Ok(swapchain)
    }

    /// Rebuilds the swapchain for the current surface size, after waiting for the device to
    /// go idle; `frame_number` is the next frame's (it dates the retired predecessor).
    /// Returns `false` (and leaves no images) when the surface has zero area, i.e. the window
    /// is minimised.
    pub(crate) fn rebuild(
        &mut self,
        instance: &Instance,
        device: &Device,
        frame_number: u64,
    ) -> GpuResult<bool> {
        device.wait_idle()?;
        let (Some(surface_fn), Some(swapchain_fn)) =
            (instance.surface_fn.as_ref(), device.swapchain_fn.as_ref())
        else {
            return Err(GpuError::Surface("no surface support".into()));
        };
        let old_images = self.images.len();
        // SAFETY: the device is idle (waited above), so no frame renders into them.
        unsafe { self.destroy_images(device) };
        let (caps, formats, modes) = self.surface_properties(surface_fn, device)?;
        let Some(extent) = self.extent_for(&caps) else {
            self.extent = vk::Extent2D::default();
            return Ok(false);
        };
        let format = choose_format(&formats)
            .ok_or_else(|| GpuError::Surface("surface reports no formats".into()))?;
        let present_mode = choose_present_mode(&modes, self.vsync);
        let old = self.raw;
        let transfers = vk::ImageUsageFlags::TRANSFER_SRC | vk::ImageUsageFlags::TRANSFER_DST;
        self.copyable = caps.supported_usage_flags.contains(transfers);
        let mut info = swapchain_info(self.surface, &caps, format, extent, present_mode, old);
        if self.copyable {
            info = info.image_usage(vk::ImageUsageFlags::COLOR_ATTACHMENT | transfers);
        }
        // SAFETY: parameters were validated against the surface capabilities above.
        let raw = unsafe { swapchain_fn.create_swapchain(&info, None) }.vk("vkCreateSwapchainKHR");
        if old != vk::SwapchainKHR::null() {
            // Passing it as old_swapchain retired it (even if creation failed); presentation
            // may still use it and its semaphores, so they are destroyed later.
            self.retired.push(Retired {
                raw: old,
                semaphores: std::mem::take(&mut self.render_finished),
                until: frame_number + (FRAMES_IN_FLIGHT + old_images.max(1)) as u64,
            });
            self.raw = vk::SwapchainKHR::null();
        }
        self.raw = raw?;
        self.format = format;
        self.present_mode = present_mode;
        self.extent = extent;
        self.create_images(device, swapchain_fn)?;
        self.stale = false;
        Ok(true)
    }

    /// Capabilities, formats and present modes of the surface.
    fn surface_properties(
        &self,
        surface_fn: &ash::khr::surface::Instance,
        device: &Device,
    ) -> GpuResult<SurfaceProperties> {
        // SAFETY: valid physical device and surface for all three queries.
        unsafe {
            Ok((
                surface_fn
                    .get_physical_device_surface_capabilities(device.physical, self.surface)
                    .vk("vkGetPhysicalDeviceSurfaceCapabilitiesKHR")?,
                surface_fn
                    .get_physical_device_surface_formats(device.physical, self.surface)
                    .vk("vkGetPhysicalDeviceSurfaceFormatsKHR")?,
                surface_fn
                    .get_physical_device_surface_present_modes(device.physical, self.surface)
                    .vk("vkGetPhysicalDeviceSurfacePresentModesKHR")?,
            ))
        }
    }

    /// The image size for the wanted window size, or `None` when either has zero area.
    fn extent_for(&self, caps: &vk::SurfaceCapabilitiesKHR) -> Option<vk::Extent2D> {
        // u32::MAX means "the swapchain decides"; otherwise the surface dictates the size.
        let extent = if caps.current_extent.width != u32::MAX {
            caps.current_extent
        } else {
            vk::Extent2D {
                width: self
                    .wanted
                    .width
                    .clamp(caps.min_image_extent.width, caps.max_image_extent.width),
                height: self
                    .wanted
                    .height
                    .clamp(caps.min_image_extent.height, caps.max_image_extent.height),
            }
        };
        let empty = extent.width == 0
            || extent.height == 0
            || self.wanted.width == 0
            || self.wanted.height == 0;
        (!empty).then_some(extent)
    }

    /// Views, render-finished semaphores and attachments for the new swapchain's images.
    fn create_images(
        &mut self,
        device: &Device,
        swapchain_fn: &ash::khr::swapchain::Device,
    ) -> GpuResult<()> {
        // SAFETY: valid swapchain.
        self.images =
            unsafe { swapchain_fn.get_swapchain_images(self.raw) }.vk("vkGetSwapchainImagesKHR")?;
        for &image in &self.images {
            self.views
                .push(create_view(device, image, self.format.format)?);
        }
        while self.render_finished.len() < self.images.len() {
            // SAFETY: valid device.
            let s = unsafe {
                device
                    .raw
                    .create_semaphore(&vk::SemaphoreCreateInfo::default(), None)
            }
            .vk("vkCreateSemaphore")?;
            self.render_finished.push(s);
        }
        self.attachments = Some(Attachments::new(
            device,
            self.extent,
            self.format.format,
            self.samples,
            self.copyable,
        )?);
        Ok(())
    }

    /// Acquires the next image, signalling `semaphore`. `None` when the swapchain is out of
    /// date (it is marked stale; skip the frame).
    pub(crate) fn acquire(
        &mut self,
        device: &Device,
        semaphore: vk::Semaphore,
    ) -> GpuResult<Option<u32>> {
        let Some(swapchain_fn) = device.swapchain_fn.as_ref() else {
            return Err(GpuError::Surface("device has no VK_KHR_swapchain".into()));
        };
        let limit = u64::try_from(super::WAIT_LIMIT.as_nanos()).unwrap_or(u64::MAX);
        // SAFETY: valid swapchain; the caller's semaphore is unsignalled and not in use (its
        // previous waiter, the slot's last submission, has completed).
        let acquired = unsafe {
            swapchain_fn.acquire_next_image(self.raw, limit, semaphore, vk::Fence::null())
        };
        match acquired {
            Ok((index, suboptimal)) => {
                // Still presentable; rebuild after this frame.
                self.stale |= suboptimal;
                Ok(Some(index))
            }
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => {
                self.stale = true;
                Ok(None)
            }
            Err(result) => Err(vk_error("vkAcquireNextImageKHR", result)),
        }
    }

    /// Presents image `index` once `wait` is signalled; an out-of-date or suboptimal
    /// swapchain is marked for rebuilding.
    pub(crate) fn present(
        &mut self,
        device: &Device,
        index: u32,
        wait: vk::Semaphore,
    ) -> GpuResult<()> {
        let Some(swapchain_fn) = device.swapchain_fn.as_ref() else {
            return Ok(());
        };
        let swapchains = [self.raw];
        let indices = [index];
        let waits = [wait];
        let info = vk::PresentInfoKHR::default()
            .wait_semaphores(&waits)
            .swapchains(&swapchains)
            .image_indices(&indices);
        // SAFETY: the image was acquired this frame and its semaphore is signalled by the
        // frame's submission.
        let result = unsafe { swapchain_fn.queue_present(device.queue, &info) };
        let stale = match result {
            Ok(suboptimal) => suboptimal,
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => true,
            Err(result) => return Err(vk_error("vkQueuePresentKHR", result)),
        };
        self.stale |= stale;
        Ok(())
    }

    /// Destroys retired swapchains whose presents are surely done, given the next frame's
    /// number (`all`: every one, at teardown after the device went idle).
    pub(crate) fn collect_retired(&mut self, device: &Device, frame_number: u64, all: bool) {
        let Some(swapchain_fn) = device.swapchain_fn.as_ref() else {
            return;
        };
        self.retired.retain(|r| {
            if !all && frame_number < r.until {
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
    pub(crate) unsafe fn destroy(mut self, instance: &Instance, device: &Device) {
        self.collect_retired(device, 0, true);
        // SAFETY: the caller guarantees an idle (or lost) device.
        unsafe { self.destroy_images(device) };
        if let Some(f) = device.swapchain_fn.as_ref()
            && self.raw != vk::SwapchainKHR::null()
        {
            // SAFETY: idle device, swapchain destroyed once.
            unsafe { f.destroy_swapchain(self.raw, None) };
        }
        for s in self.render_finished.drain(..) {
            // SAFETY: the device is idle and the swapchain that presented with these
            // semaphores is gone. Present completion itself cannot be observed without
            // VK_EXT_swapchain_maintenance1; this is the teardown order the Vulkan samples use.
            unsafe { device.raw.destroy_semaphore(s, None) };
        }
        if let Some(f) = instance.surface_fn.as_ref() {
            // SAFETY: the swapchain using the surface is gone.
            unsafe { f.destroy_surface(self.surface, None) };
        }
    }
}

type SurfaceProperties = (
    vk::SurfaceCapabilitiesKHR,
    Vec<vk::SurfaceFormatKHR>,
    Vec<vk::PresentModeKHR>,
);

/// The create info of a swapchain on `surface`: one image more than the minimum, opaque
/// composition where supported.
fn swapchain_info(
    surface: vk::SurfaceKHR,
    caps: &vk::SurfaceCapabilitiesKHR,
    format: vk::SurfaceFormatKHR,
    extent: vk::Extent2D,
    present_mode: vk::PresentModeKHR,
    old: vk::SwapchainKHR,
) -> vk::SwapchainCreateInfoKHR<'static> {
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
    vk::SwapchainCreateInfoKHR::default()
        .surface(surface)
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
        .old_swapchain(old)
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
