//! Scene → GPU: the document being viewed, the orbit camera, per-object mirrors with per-slot
//! dirty tracking, display options and overlays. Used by `prespline render` (offscreen) and the
//! viewer (swapchain).

pub mod analysis;
pub mod camera;
pub mod document;
pub mod gpu_scene;
pub mod lod;
pub mod map_mirror;
pub mod maps;
pub mod offscreen;
pub mod overlays;
pub mod style;

pub use camera::{Bounds, OrbitCamera};
pub use document::{Controls, DocObject, Document, Handle};
pub use gpu_scene::{DrawReport, GpuScene, Highlight, UploadStats};
pub use lod::Lod;
pub use map_mirror::MapView;
pub use style::{NetMode, Palette, ViewOptions, Wire};
