//! The [`Renderer`]: owns the instance, device, pipelines, frame slots and caches.

use std::mem::ManuallyDrop;

use ash::vk;
use raw_window_handle::RawDisplayHandle;

use super::FRAMES_IN_FLIGHT;
use super::device::{Device, DeviceCaps};
use super::error::{GpuError, GpuResult};
use super::frame::FrameSlot;
use super::grid::GridCache;
use super::instance::{Instance, InstanceDesc, ValidationMode};
use super::memory::Buffer;
use super::mirror::Mirror;
use super::offscreen::OffscreenTarget;
use super::pipeline::Pipelines;
use super::pod::slice_bytes;
use super::shader::Shaders;
use super::swapchain::Swapchain;
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
pub(crate) enum Orphan {
    Target(OffscreenTarget),
    Swapchain(Swapchain),
}

/// The GPU renderer. See the [module docs](super) for the frame protocol.
///
/// Resources it hands out (mirrors, targets, swapchains) must be given back through the
/// matching `destroy_*` method before the renderer is dropped; the validation layer reports
/// anything left over as a leak.
pub struct Renderer {
    pub(crate) frames: Vec<FrameSlot>,
    pub(crate) frame_number: u64,
    pub(crate) pipelines: Pipelines,
    pub(crate) shaders: Shaders,
    pub(crate) grids: GridCache,
    pub(crate) uploader: Uploader,
    /// The HUD font's glyph rows in device memory (read by `overlay.frag` through its address).
    pub(crate) font: Option<Buffer>,
    pub(crate) always_flush: bool,
    /// A failure to report at the next matching call (error-path tests).
    pub(crate) fault: Option<Fault>,
    /// Objects whose GPU use could not be shown to have ended when they were given back;
    /// destroyed after the final wait in `Drop`.
    pub(crate) orphans: Vec<Orphan>,
    // Dropped by hand, in order, after everything above (see `Drop`).
    pub(crate) device: ManuallyDrop<Device>,
    pub(crate) instance: ManuallyDrop<Instance>,
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
            frames: Vec::new(),
            frame_number: 0,
            pipelines: Pipelines::default(),
            shaders: Shaders::default(),
            grids: GridCache::default(),
            uploader: Uploader::default(),
            font: None,
            always_flush: desc.always_flush,
            fault: None,
            orphans: Vec::new(),
            device: ManuallyDrop::new(device),
            instance: ManuallyDrop::new(instance),
        };
        renderer.shaders = Shaders::new(&renderer.device)?;
        renderer.pipelines = Pipelines::new(&renderer.device)?;
        renderer.uploader = Uploader::new(&renderer.device)?;
        renderer.font = Some(renderer.uploader.upload(
            &renderer.device,
            "font",
            slice_bytes(&super::font::glyph_rows()),
            vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS,
            vk::PipelineStageFlags2::FRAGMENT_SHADER,
            vk::AccessFlags2::SHADER_STORAGE_READ,
        )?);
        for _ in 0..FRAMES_IN_FLIGHT {
            let slot = FrameSlot::new(&renderer.device, desc.always_flush)?;
            renderer.frames.push(slot);
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
        self.frame_number
    }

    /// GPU time (ms) of the most recent frame whose timing is known.
    pub fn last_gpu_time_ms(&self) -> Option<f64> {
        let prev = (self.frame_number + FRAMES_IN_FLIGHT as u64 - 1) as usize % FRAMES_IN_FLIGHT;
        self.frames
            .get(prev)
            .and_then(|f| f.gpu_ms)
            .or_else(|| self.frames.iter().find_map(|f| f.gpu_ms))
    }

    /// Makes the next matching call fail with `fault` instead of reaching the driver. For
    /// tests of error paths (a submission that fails, a wait that fails): the renderer must
    /// report the error, never hang, and stay usable where the error allows.
    #[doc(hidden)]
    pub fn inject_fault(&mut self, fault: Fault) {
        match fault {
            Fault::Submit(_) => self.fault = Some(fault),
            Fault::UploadWait(result) => self.uploader.fail_next_wait(result),
        }
    }

    /// Blocks until the GPU has finished all submitted work.
    pub fn wait_idle(&self) -> GpuResult<()> {
        self.device.wait_idle()
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
        for f in &mut self.frames {
            f.wait_and_recycle(&self.device)?;
        }
        let atom = self.device.caps.non_coherent_atom_size;
        let mut flushes = Vec::new();
        for slot in 0..FRAMES_IN_FLIGHT {
            let track = self.always_flush || mirror.slot(slot).buffer.needs_flush();
            let mut w = mirror.writer(slot, atom, track, &mut flushes);
            w.write(offset, data)?;
        }
        self.device.flush_ranges(&flushes)
    }

    /// Destroys a mirror. Each slot's buffer is released when that slot's fence next
    /// signals, so this never waits.
    pub fn destroy_mirror(&mut self, mirror: Mirror) {
        for (i, b) in mirror.slots.into_iter().enumerate() {
            match self.frames.get_mut(i) {
                Some(f) => f.release.push(b.buffer),
                // No slot, so no frame ever used this buffer.
                // SAFETY: a buffer without a frame slot was never bound by a submission.
                None => unsafe { self.device.destroy_buffer(b.buffer) },
            }
        }
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
            unsafe {
                match orphan {
                    Orphan::Target(t) => t.destroy(&self.device),
                    Orphan::Swapchain(s) => self.destroy_swapchain_now(s),
                }
            }
        }
        let device = &*self.device;
        // SAFETY: the device is idle or lost, so no GPU work uses any of these objects.
        unsafe {
            for f in std::mem::take(&mut self.frames) {
                f.destroy(device);
            }
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
