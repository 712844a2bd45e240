//! The [`Renderer`]: owns the instance, device, pipelines, frame slots and caches, and
//! composes them: it creates and destroys targets, swapchains and mirrors, and begins frames
//! (waits for the slot, acquires, transitions the attachments).

use std::mem::ManuallyDrop;
use std::sync::Arc;

use ash::vk;
use raw_window_handle::{HasDisplayHandle, HasWindowHandle, RawDisplayHandle};

use super::FRAMES_IN_FLIGHT;
use super::barrier;
use super::device::{Device, DeviceCaps};
use super::error::{GpuError, GpuResult};
use super::font::Font;
use super::frame::{Frame, FrameContext, FrameTarget};
use super::grid::GridCache;
use super::instance::{Instance, InstanceDesc, ValidationMode};
use super::memory::Buffer;
use super::mirror::Mirror;
use super::offscreen::OFFSCREEN_FORMAT;
use super::offscreen::{OffscreenDesc, OffscreenTarget, Pixels};
use super::pipeline::{PipelineKey, Pipelines, Which};
use super::shader::Shaders;
use super::slot::{FrameRing, FrameSlot};
use super::swapchain::{Swapchain, SwapchainDesc};
use super::target::TargetView;
use super::upload::Uploader;
use super::validation::ValidationSink;

/// Parameters for [`Renderer::new`].
#[derive(Clone, Debug, Default)]
pub struct RendererDesc {
    /// Application name reported to the driver.
    pub app_name: String,
    /// Validation layer policy (tests use [`ValidationMode::Required`]).
    pub validation: ValidationMode,
    /// Also enable synchronization validation (slow; for tests).
    pub sync_validation: bool,
    /// Display that swapchains will be created for; `None` for offscreen-only use.
    pub display: Option<RawDisplayHandle>,
    /// Flush host writes even when memory is coherent. Only useful to exercise the
    /// non-coherent path (under validation) on drivers whose memory is all coherent.
    pub always_flush: bool,
    /// The device to use: the first whose name contains this (case-insensitive), e.g.
    /// `"llvmpipe"` for Mesa's software rasteriser among several installed drivers. `None`
    /// follows `PRESPLINE_GPU`, else prefers discrete > integrated > virtual > CPU.
    pub device: Option<String>,
}

/// A failure a test makes the renderer report instead of calling Vulkan, to exercise error
/// paths that real drivers rarely take ([`Renderer::inject_fault`]).
#[doc(hidden)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fault {
    /// The next `vkQueueSubmit2` of a frame returns this result (after its fence was reset).
    Submit(vk::Result),
    /// The next static upload's `vkWaitForFences` returns this result after a successful
    /// submission (the copy may still be running).
    UploadWait(vk::Result),
}

/// A resource given back while the GPU might still use it (a wait for it failed).
enum Orphan {
    Target(OffscreenTarget),
    Swapchain(Swapchain),
}

/// The GPU renderer. See the [module docs](super) for the frame protocol.
///
/// Resources it hands out (mirrors, targets, swapchains) must be given back through the
/// matching `destroy_*` method before the renderer is dropped; the validation layer reports
/// anything left over as a leak.
pub struct Renderer {
    frames: FrameRing,
    pipelines: Pipelines,
    shaders: Shaders,
    grids: GridCache,
    uploader: Uploader,
    /// The overlay font (metrics, layout) and its glyph atlas in device memory (read by
    /// `overlay.frag` through its address).
    text: Font,
    font: Option<Buffer>,
    always_flush: bool,
    /// Objects whose GPU use could not be shown to have ended when they were given back;
    /// destroyed after the final wait in `Drop`.
    orphans: Vec<Orphan>,
    // Dropped by hand, in order, after everything above (see `Drop`).
    device: ManuallyDrop<Device>,
    instance: ManuallyDrop<Instance>,
}

impl Renderer {
    /// Creates instance, device, pipelines layout, shaders and frame slots.
    pub fn new(desc: &RendererDesc) -> GpuResult<Self> {
        let instance = Instance::new(&InstanceDesc {
            app_name: if desc.app_name.is_empty() {
                "prespline".into()
            } else {
                desc.app_name.clone()
            },
            validation: desc.validation,
            sync_validation: desc.sync_validation,
            display: desc.display,
        })?;
        let device = match Device::new(&instance, desc.device.as_deref()) {
            Ok(d) => d,
            Err(e) => {
                // SAFETY: nothing was created from the instance (the device failed).
                unsafe { instance.destroy() };
                return Err(e);
            }
        };
        // From here on, Drop cleans up whatever was created.
        let mut renderer = Self {
            frames: FrameRing::default(),
            pipelines: Pipelines::default(),
            shaders: Shaders::default(),
            grids: GridCache::default(),
            uploader: Uploader::default(),
            text: Font::new(1.0),
            font: None,
            always_flush: desc.always_flush,
            orphans: Vec::new(),
            device: ManuallyDrop::new(device),
            instance: ManuallyDrop::new(instance),
        };
        renderer.shaders = Shaders::new(&renderer.device)?;
        renderer.pipelines = Pipelines::new(&renderer.device)?;
        renderer.uploader = Uploader::new(&renderer.device)?;
        renderer.font = Some(upload_atlas(
            &renderer.device,
            &mut renderer.uploader,
            &renderer.text,
        )?);
        for _ in 0..FRAMES_IN_FLIGHT {
            let slot = FrameSlot::new(&renderer.device, desc.always_flush)?;
            renderer.frames.slots.push(slot);
        }
        Ok(renderer)
    }

    /// What the chosen device can do (name, timestamps, MSAA, ...).
    pub fn caps(&self) -> &DeviceCaps {
        self.device.caps()
    }

    /// The device, for callers that need raw Vulkan access.
    pub fn device(&self) -> &Device {
        &self.device
    }

    /// The validation message sink, when validation is on. Keep a clone to inspect messages
    /// emitted during teardown (leak reports) after the renderer is dropped.
    pub fn validation_sink(&self) -> Option<ValidationSink> {
        self.instance.validation_sink()
    }

    /// Number of frames begun so far (the next frame's number).
    pub fn frame_number(&self) -> u64 {
        self.frames.number
    }

    /// GPU time (ms) of the most recent frame whose timing is known.
    pub fn last_gpu_time_ms(&self) -> Option<f64> {
        self.frames.last_gpu_time_ms()
    }

    /// Makes the next matching call fail with `fault` instead of reaching the driver. For
    /// tests of error paths (a submission that fails, a wait that fails): the renderer must
    /// report the error, never hang, and stay usable where the error allows.
    #[doc(hidden)]
    pub fn inject_fault(&mut self, fault: Fault) {
        match fault {
            Fault::Submit(result) => self.frames.submit_fault = Some(result),
            Fault::UploadWait(result) => self.uploader.fail_next_wait(result),
        }
    }

    /// Blocks until the GPU has finished all submitted work.
    pub fn wait_idle(&self) -> GpuResult<()> {
        self.device.wait_idle()
    }

    /// The overlay font: lay text out with it (see [`Frame::font`]).
    pub fn font(&self) -> &Font {
        &self.text
    }

    /// Rebuilds the overlay font for a window scale factor (physical pixels per logical
    /// pixel; 1 headless). Waits for the frames in flight when the atlas changes.
    pub fn set_text_scale(&mut self, scale_factor: f32) -> GpuResult<()> {
        let text = Font::new(scale_factor);
        if text.scale_factor() == self.text.scale_factor() {
            return Ok(());
        }
        let atlas = upload_atlas(&self.device, &mut self.uploader, &text)?;
        self.frames.wait_all(&self.device)?;
        if let Some(old) = self.font.replace(atlas) {
            // SAFETY: every frame slot was waited for: no submission reads the old atlas.
            unsafe { self.device.destroy_buffer(old) };
        }
        self.text = text;
        Ok(())
    }

    /// Creates a mirrored array of `len` f32s (one buffer per frame in flight). Its contents
    /// are undefined until written: use [`Renderer::fill_mirror`] or per-frame writes.
    pub fn create_mirror(&mut self, name: &str, len: usize) -> GpuResult<Mirror> {
        Mirror::new(&self.device, name, len)
    }

    /// Writes `data` at `offset` into **every** slot of `mirror`, waiting first for all
    /// frames in flight. For initial contents and wholesale replacement; per-frame updates
    /// should use [`super::Frame::write_mirror`] instead, which never waits.
    pub fn fill_mirror(
        &mut self,
        mirror: &mut Mirror,
        offset: usize,
        data: &[f32],
    ) -> GpuResult<()> {
        self.frames.wait_all(&self.device)?;
        // SAFETY: every frame slot was just waited for, so no GPU work uses the mirror.
        unsafe { mirror.fill(&self.device, offset, data, self.always_flush) }
    }

    /// Destroys a mirror. Each slot's buffer is released when that slot's fence next
    /// signals, so this never waits.
    pub fn destroy_mirror(&mut self, mirror: Mirror) {
        self.frames.release_mirror(&self.device, mirror);
    }

    /// Fails with a clear message when the validation layer recorded errors (handy in tests
    /// before teardown; leak reports arrive only during drop).
    pub fn check_validation(&self) -> GpuResult<()> {
        let Some(sink) = self.validation_sink() else {
            return Ok(());
        };
        let errors = sink.errors();
        if errors.is_empty() {
            Ok(())
        } else {
            let text: Vec<String> = errors.iter().map(ToString::to_string).collect();
            Err(GpuError::Validation(format!(
                "{} validation error(s):\n{}",
                errors.len(),
                text.join("\n")
            )))
        }
    }

    /// The MSAA sample count used when a target asks for 0 ([`DeviceCaps::default_samples`]:
    /// 1 on CPU rasterisers such as lavapipe, 4 on GPUs).
    pub fn default_samples(&self) -> u32 {
        self.device.caps.default_samples()
    }

    /// Creates an offscreen target.
    pub fn create_offscreen(&mut self, desc: &OffscreenDesc) -> GpuResult<OffscreenTarget> {
        if desc.width == 0 || desc.height == 0 {
            return Err(GpuError::InvalidArgument(format!(
                "offscreen target {}x{} is empty",
                desc.width, desc.height
            )));
        }
        let samples = self.device.caps.resolve_samples(desc.samples)?;
        OffscreenTarget::new(&self.device, desc, samples)
    }

    /// Builds ahead the pipelines an offscreen frame of `samples` MSAA samples draws shaded
    /// surfaces with (untrimmed and trimmed) and those every frame needs, so that a caller
    /// can compile them on a second thread while it loads a scene (lavapipe compiles each
    /// pipeline to machine code: milliseconds apiece).
    pub fn warm_offscreen(&mut self, samples: u32) -> GpuResult<()> {
        let key = PipelineKey {
            color_format: OFFSCREEN_FORMAT,
            samples: self.device.caps.resolve_samples(samples)?,
        };
        self.pipelines.prepare(&self.device, &self.shaders, key)?;
        for which in [Which::Surface, Which::SurfaceTrim] {
            self.pipelines
                .get(&self.device, &self.shaders, key, which)?;
        }
        Ok(())
    }

    /// Waits for the last frame rendered into `target` and returns its pixels. That frame
    /// must have been captured ([`Frame::capture`]).
    pub fn read_pixels(&mut self, target: &OffscreenTarget) -> GpuResult<Pixels> {
        let slot = target.captured_slot()?;
        self.frames.wait_slot(&self.device, slot)?;
        target.read_back(&self.device, slot)
    }

    /// Destroys an offscreen target, after waiting for the GPU to finish with it. If that
    /// wait fails for another reason than a lost device (work may still run), the target is
    /// kept until the renderer is dropped and the error returned.
    pub fn destroy_offscreen(&mut self, target: OffscreenTarget) -> GpuResult<()> {
        self.destroy_when_idle(Orphan::Target(target))
    }

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
        Swapchain::new(&self.instance, &self.device, window, desc)
    }

    /// Destroys the swapchain and its surface (waits for the GPU first).
    pub fn destroy_swapchain(&mut self, swapchain: Swapchain) -> GpuResult<()> {
        self.destroy_when_idle(Orphan::Swapchain(swapchain))
    }

    /// Destroys `orphan` once the device is idle. A lost device executes nothing, so its
    /// objects go at once (and the error is returned); if the wait fails otherwise, work may
    /// still use it, so it is kept until the renderer is dropped.
    fn destroy_when_idle(&mut self, orphan: Orphan) -> GpuResult<()> {
        let waited = self.wait_idle();
        match waited {
            Err(e) if !e.is_device_lost() => {
                self.orphans.push(orphan);
                Err(e)
            }
            _ => {
                // SAFETY: the device is idle or lost, so no GPU work uses the object.
                unsafe { self.destroy_orphan(orphan) };
                waited
            }
        }
    }

    /// # Safety
    /// The device must be idle or lost.
    unsafe fn destroy_orphan(&self, orphan: Orphan) {
        // SAFETY: the caller guarantees an idle or lost device.
        unsafe {
            match orphan {
                Orphan::Target(t) => t.destroy(&self.device),
                Orphan::Swapchain(s) => s.destroy(&self.instance, &self.device),
            }
        }
    }

    /// Begins a frame rendering into `target`. Waits for the slot's previous use.
    pub fn begin_offscreen<'a>(
        &'a mut self,
        target: &'a mut OffscreenTarget,
    ) -> GpuResult<Frame<'a>> {
        let slot = self.frames.next_slot(&self.device)?;
        let view = target.view();
        let key = self.prepare(view, slot, false)?;
        Ok(Frame::new(
            self.frame_context(key),
            FrameTarget::Offscreen(target),
            view,
            slot,
        ))
    }

    /// Begins a frame on the next swapchain image. Returns `None` when there is nothing to
    /// draw to right now (window minimised, or the swapchain just went out of date); simply
    /// try again next frame.
    pub fn begin_swapchain<'a>(
        &'a mut self,
        swapchain: &'a mut Swapchain,
    ) -> GpuResult<Option<Frame<'a>>> {
        swapchain.collect_retired(&self.device, self.frames.number, false);
        if swapchain.stale
            && !swapchain.rebuild(&self.instance, &self.device, self.frames.number)?
        {
            return Ok(None);
        }
        // Build the pipelines before acquiring: once an image is acquired, the frame must be
        // submitted, or the slot's acquire semaphore stays signalled.
        if let Some(view) = swapchain.view(0) {
            self.pipelines
                .prepare(&self.device, &self.shaders, pipeline_key(&view))?;
        }
        let slot = self.frames.next_slot(&self.device)?;
        let acquire = self.frames.slots[slot].acquire;
        let Some(image_index) = swapchain.acquire(&self.device, acquire)? else {
            return Ok(None);
        };
        // From here on the acquire semaphore is signalled: every way out must consume it.
        let prepared = match swapchain.view(image_index) {
            Some(view) => self.prepare(view, slot, true).map(|p| (view, p)),
            None => Err(GpuError::Surface(format!(
                "acquired image {image_index} does not exist"
            ))),
        };
        let (view, key) = match prepared {
            Ok(p) => p,
            Err(e) => {
                swapchain.stale = true;
                self.frames.slots[slot].consume_acquire(&self.device);
                return Err(e);
            }
        };
        let target = FrameTarget::Swapchain {
            swapchain,
            image_index,
        };
        Ok(Some(Frame::new(
            self.frame_context(key),
            target,
            view,
            slot,
        )))
    }

    /// The fallible part of starting a frame: pipelines for the target, the slot's command
    /// buffer begun, the attachments' barriers recorded.
    fn prepare(
        &mut self,
        view: TargetView,
        slot: usize,
        swapchain: bool,
    ) -> GpuResult<PipelineKey> {
        let key = pipeline_key(&view);
        self.pipelines.prepare(&self.device, &self.shaders, key)?;
        let frame_slot: &mut FrameSlot = &mut self.frames.slots[slot];
        frame_slot.begin_commands(&self.device)?;
        let barriers = barrier::begin_barriers(&view, swapchain);
        // SAFETY: the slot's command buffer is recording (begun above, outside rendering);
        // the images are live and owned by the target.
        unsafe { barrier::record(&self.device.raw, frame_slot.cmd, &barriers) };
        Ok(key)
    }

    /// What a frame borrows from the renderer while it records.
    fn frame_context(&mut self, key: PipelineKey) -> FrameContext<'_> {
        FrameContext {
            device: &self.device,
            ring: &mut self.frames,
            grids: &mut self.grids,
            uploader: &mut self.uploader,
            layout: self.pipelines.layout,
            pipelines: &mut self.pipelines,
            shaders: &self.shaders,
            key,
            font: self.font.as_ref().map_or(0, |f| f.address()),
            text: &self.text,
            always_flush: self.always_flush,
        }
    }
}

impl Drop for Renderer {
    fn drop(&mut self) {
        match self.device.wait_idle() {
            // Idle, or lost (nothing executes on a lost device): everything may go.
            Ok(()) => {}
            Err(e) if e.is_device_lost() => {}
            // The GPU may still be running our work: destroying it would be undefined
            // behaviour, so everything is leaked instead (the process is usually ending).
            Err(_) => return,
        }
        for orphan in std::mem::take(&mut self.orphans) {
            // SAFETY: the device is idle or lost, so no GPU work uses them.
            unsafe { self.destroy_orphan(orphan) };
        }
        let device = &*self.device;
        // SAFETY: the device is idle or lost, so no GPU work uses any of these objects.
        unsafe {
            self.frames.destroy(device);
            std::mem::take(&mut self.grids).destroy(device);
            std::mem::take(&mut self.uploader).destroy(device);
            if let Some(font) = self.font.take() {
                device.destroy_buffer(font);
            }
            std::mem::take(&mut self.pipelines).destroy(device);
            std::mem::take(&mut self.shaders).destroy(device);
        }
        // SAFETY: `device` and `instance` are taken exactly once, here, and never used again;
        // every child object was destroyed above (or by the caller via destroy_*), and the
        // device is idle or lost.
        unsafe {
            let device = ManuallyDrop::take(&mut self.device);
            let instance = ManuallyDrop::take(&mut self.instance);
            device.destroy();
            instance.destroy();
        }
    }
}

/// Everything about a target that its pipelines bake in.
fn pipeline_key(view: &TargetView) -> PipelineKey {
    PipelineKey {
        color_format: view.format,
        samples: view.samples,
    }
}

/// The glyph atlas of `text` in device memory, padded to whole 32-bit words (the shader reads
/// words).
fn upload_atlas(device: &Device, uploader: &mut Uploader, text: &Font) -> GpuResult<Buffer> {
    let mut bytes = text.atlas().to_vec();
    bytes.resize(bytes.len().next_multiple_of(4).max(4), 0);
    uploader.upload(
        device,
        "glyph atlas",
        &bytes,
        vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS,
        vk::PipelineStageFlags2::FRAGMENT_SHADER,
        vk::AccessFlags2::SHADER_STORAGE_READ,
    )
}
