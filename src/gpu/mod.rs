//! The spline-agnostic GPU layer: an ash (Vulkan 1.3) renderer with persistently mapped
//! mirror buffers, dynamic rendering, synchronization2 and two frames in flight.
//!
//! Nothing here knows what a spline is: it draws grids of (position, normal) vertices,
//! runs of points, line lists and 2D triangles from f32 buffers the caller fills.
//!
//! # Frame protocol
//!
//! ```no_run
//! use prespline::gpu::*;
//! # fn demo() -> Result<(), GpuError> {
//! let mut renderer = Renderer::new(&RendererDesc::default())?;
//! let mut target = renderer.create_offscreen(&OffscreenDesc { width: 640, height: 480, samples: 0 })?;
//! let shape = GridShape { rows: 64, cols: 64 };
//! let grid = SurfaceGrid { offset: 0, shape };
//! let mut mirror = renderer.create_mirror("surface", grid.floats())?;
//! renderer.fill_mirror(&mut mirror, 0, &vec![0.0; grid.floats()])?; // initial contents
//!
//! let mut frame = renderer.begin_offscreen(&mut target)?; // waits for this slot's fence
//! {
//!     // Bring *this slot* up to date: copy what changed since the slot was last written.
//!     let mut w = frame.write_mirror(&mut mirror);
//!     w.put_vertex(0, [0.0f32, 0.0, 0.0, 0.0, 0.0, 1.0]);
//! } // dropping the writer hands its ranges to the frame (flushed before submit if needed)
//! frame.set_camera(Camera::default());
//! frame.draw_surface(&mirror, grid, &SurfaceStyle::default())?;
//! frame.draw_wire(&mirror, grid, 8, [0.0, 0.0, 0.0, 1.0])?;
//! frame.capture(); // copy the image out for read_pixels (frames copy nothing by default)
//! frame.finish()?;
//! let pixels = renderer.read_pixels(&target)?;
//! # renderer.destroy_mirror(mirror);
//! # renderer.destroy_offscreen(target)?;
//! # let _ = pixels; Ok(()) }
//! ```
//!
//! * [`Renderer::begin_offscreen`] / [`Renderer::begin_swapchain`] pick slot
//!   `frame_number % FRAMES_IN_FLIGHT`, wait for its fence, read its GPU timestamps, release
//!   its deferred resources and start its command buffer. Only after that may the caller
//!   write that slot of its mirrors, through [`Frame::write_mirror`]; each slot must receive
//!   every change made since *it* was last written (keep per-slot dirty ranges).
//! * Draw calls record into the frame; rendering begins lazily with the clear.
//! * [`Frame::finish`] ends recording, flushes non-coherent host writes (aligned to
//!   `nonCoherentAtomSize`), submits with `vkQueueSubmit2`, presents for swapchains. If it
//!   fails, the slot stays usable (see the README's "Errors and failure injection").
//!
//! Mapped memory is never read: mirrors expose only writes (it may be write-combined).
//!
//! # Conventions
//!
//! * `Camera::view_proj` is y-up with depth in `[0, 1]` (`glam::Mat4::perspective_rh`); the
//!   viewport is flipped so images come out upright.
//! * Colours in styles are linear RGBA `f32`; vertex colours (`LineVertex`,
//!   `OverlayVertex`) are sRGB-encoded RGBA8. Targets are sRGB formats.
//! * Mirror offsets/strides are in f32 elements. A surface vertex is 6 floats (position,
//!   normal); a curve point is 3 floats.
//!
//! # Destruction
//!
//! Mirrors, targets and swapchains are destroyed explicitly through the renderer
//! (`destroy_*`); dropping the renderer destroys everything else. With validation on,
//! anything leaked is reported by the layer at teardown.

mod attachments;
mod barrier;
mod device;
mod draw;
mod error;
pub mod font;
mod frame;
mod frame_layer;
mod grid;
mod image;
mod instance;
mod layer;
mod mask;
mod memory;
mod mirror;
mod offscreen;
mod pipeline;
mod pod;
mod region;
mod renderer;
mod shader;
mod slot;
mod style;
mod swapchain;
mod target;
mod timestamp;
mod transient;
mod upload;
mod validation;
mod vertex;

/// Frames the CPU may record ahead of the GPU; also the number of slots of every mirror.
pub const FRAMES_IN_FLIGHT: usize = 2;

/// The longest the renderer waits for the GPU (a fence) before reporting
/// [`GpuError::Timeout`] instead of hanging: far beyond any frame, even in software.
pub const WAIT_LIMIT: std::time::Duration = std::time::Duration::from_secs(30);

pub use ash::vk;
pub use device::{Device, DeviceCaps, GPU_ENV};
pub use error::{GpuError, GpuResult};
pub use frame::{DrawStats, Frame};
pub use grid::{
    GridShape, GridStride, RUN_VERTICES, grid_lines, grid_lines_strided, grid_triangles,
    grid_triangles_strided,
};
pub use instance::{ValidationMode, force_driver_files};
pub use layer::{LayerPart, Restore};
pub use mask::{MaskSet, MaskWords};
pub use memory::{Buffer, BufferDesc};
pub use mirror::{Mirror, MirrorBuffer, MirrorWriter, RangeWriter};
pub use offscreen::{OFFSCREEN_FORMAT, OffscreenDesc, OffscreenTarget, Pixels};
pub use pipeline::DEPTH_FORMAT;
pub use region::{MaskRef, PointRun, SurfaceBatch, SurfaceGrid};
pub use renderer::{Fault, Renderer, RendererDesc};
pub use style::{Camera, GripGrid, MapStyle, PointStyle, PolylineStyle, SurfaceStyle};
pub use swapchain::{Swapchain, SwapchainDesc};
pub use validation::{Severity, ValidationMessage, ValidationSink};
pub use vertex::{LineVertex, OverlayVertex};

/// ICD manifest of Mesa's lavapipe (software Vulkan) on Debian/Ubuntu, used by tests.
pub const LAVAPIPE_ICD: &str = "/usr/share/vulkan/icd.d/lvp_icd.x86_64.json";
