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

/// Shorthand for `Result<T, GpuError>`.
pub type GpuResult<T> = Result<T, GpuError>;

/// Attaches the Vulkan entry point name to a raw `VkResult`.
pub(crate) trait VkResultExt<T> {
    fn vk(self, call: &'static str) -> GpuResult<T>;
}

impl<T> VkResultExt<T> for Result<T, vk::Result> {
    fn vk(self, call: &'static str) -> GpuResult<T> {
        self.map_err(|result| GpuError::Vk { call, result })
    }
}
