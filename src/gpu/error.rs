//! The error type of the GPU layer.

use ash::vk;

/// Everything that can go wrong in [`crate::gpu`]. Runtime failures (driver, memory, window
/// system) always come back as a `GpuError`, never as a panic.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    /// The Vulkan loader library could not be opened or is unusable.
    #[error(
        "no Vulkan loader found ({0}): install libvulkan1 and mesa-vulkan-drivers \
         (apt-get install libvulkan1 mesa-vulkan-drivers)"
    )]
    NoLoader(String),
    /// The loader works but no driver (ICD) offers a usable device.
    #[error(
        "no Vulkan driver found{0}: install libvulkan1 and mesa-vulkan-drivers \
         (apt-get install libvulkan1 mesa-vulkan-drivers)"
    )]
    NoDriver(String),
    /// Devices exist, but none has what the renderer needs (Vulkan 1.3, a graphics queue, ...).
    #[error("no suitable GPU: {0}")]
    NoSuitableDevice(String),
    /// Validation was required but `VK_LAYER_KHRONOS_validation` is not installed.
    #[error(
        "Vulkan validation layer requested but not installed \
         (apt-get install vulkan-validationlayers)"
    )]
    NoValidationLayer,
    /// The device was lost (driver reset, crash, or hang recovery): nothing submitted since
    /// completes, and the renderer cannot continue.
    #[error(
        "the GPU device was lost during {call} (driver reset or crash); rendering cannot continue"
    )]
    DeviceLost {
        /// The Vulkan entry point that reported it.
        call: &'static str,
    },
    /// The GPU did not finish work within the renderer's wait limit ([`super::WAIT_LIMIT`]).
    #[error("the GPU did not finish within {seconds} s ({call}); it may be hung")]
    Timeout {
        /// The Vulkan entry point that waited.
        call: &'static str,
        /// The limit in seconds.
        seconds: u64,
    },
    /// A Vulkan call returned an error code.
    #[error("{call} failed: {result}")]
    Vk {
        /// The Vulkan entry point, e.g. `"vkCreateBuffer"`.
        call: &'static str,
        /// The code it returned.
        result: vk::Result,
    },
    /// gpu-allocator could not satisfy an allocation.
    #[error("GPU memory allocation failed: {0}")]
    Alloc(#[from] gpu_allocator::AllocationError),
    /// A caller-supplied value is out of range (buffer bounds, grid shape, sizes).
    #[error("invalid argument: {0}")]
    InvalidArgument(String),
    /// The validation layer reported errors (see [`super::Renderer::check_validation`]).
    #[error("{0}")]
    Validation(String),
    /// An internal invariant did not hold (a bug in this module).
    #[error("internal error: {0}")]
    Internal(String),
    /// The window system could not give us a surface.
    #[error("window surface: {0}")]
    Surface(String),
    /// Writing an image file failed.
    #[error("cannot write image {path}: {message}")]
    Image {
        /// File that was being written.
        path: String,
        /// What went wrong.
        message: String,
    },
}

impl GpuError {
    /// Whether the error means the device is gone (every later call fails too).
    #[must_use]
    pub fn is_device_lost(&self) -> bool {
        matches!(self, GpuError::DeviceLost { .. })
    }
}

/// Shorthand for `Result<T, GpuError>`.
pub type GpuResult<T> = Result<T, GpuError>;

/// Attaches the Vulkan entry point name to a raw `VkResult`.
pub(crate) trait VkResultExt<T> {
    fn vk(self, call: &'static str) -> GpuResult<T>;
}

impl<T> VkResultExt<T> for Result<T, vk::Result> {
    fn vk(self, call: &'static str) -> GpuResult<T> {
        self.map_err(|result| vk_error(call, result))
    }
}

/// The error for `result` returned by `call`: device loss and timeouts get their own variants.
pub(crate) fn vk_error(call: &'static str, result: vk::Result) -> GpuError {
    match result {
        vk::Result::ERROR_DEVICE_LOST => GpuError::DeviceLost { call },
        vk::Result::TIMEOUT => GpuError::Timeout {
            call,
            seconds: super::WAIT_LIMIT.as_secs(),
        },
        result => GpuError::Vk { call, result },
    }
}
