//! SPIR-V modules compiled by `build.rs` from `shaders/` and embedded in the binary.

use std::io::Cursor;

use ash::vk;

use super::device::Device;
use super::error::{GpuError, GpuResult, VkResultExt};

macro_rules! spirv {
    ($name:literal) => {
        include_bytes!(concat!(env!("OUT_DIR"), "/", $name, ".spv")).as_slice()
    };
}

/// Every shader the renderer uses; the discriminant indexes [`Shaders`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum ShaderId {
    SurfaceVert,
    SurfaceFrag,
    WireVert,
    FlatFrag,
    PolylineVert,
    PointsVert,
    PointsFrag,
    Lines3dVert,
    OverlayVert,
    ColorFrag,
    OverlayFrag,
    MapVert,
    MapFrag,
    /// The trimmed variants: the same bodies with a coverage-mask test (shaders/trim.glsl).
    SurfaceTrimVert,
    SurfaceTrimFrag,
    MapTrimVert,
    MapTrimFrag,
    WireTrimVert,
    FlatTrimFrag,
}

const SOURCES: [(ShaderId, &str, &[u8]); 19] = [
    (
        ShaderId::SurfaceVert,
        "surface.vert",
        spirv!("surface.vert"),
    ),
    (
        ShaderId::SurfaceFrag,
        "surface.frag",
        spirv!("surface.frag"),
    ),
    (ShaderId::WireVert, "wire.vert", spirv!("wire.vert")),
    (ShaderId::FlatFrag, "flat.frag", spirv!("flat.frag")),
    (
        ShaderId::PolylineVert,
        "polyline.vert",
        spirv!("polyline.vert"),
    ),
    (ShaderId::PointsVert, "points.vert", spirv!("points.vert")),
    (ShaderId::PointsFrag, "points.frag", spirv!("points.frag")),
    (
        ShaderId::Lines3dVert,
        "lines3d.vert",
        spirv!("lines3d.vert"),
    ),
    (
        ShaderId::OverlayVert,
        "overlay.vert",
        spirv!("overlay.vert"),
    ),
    (ShaderId::ColorFrag, "color.frag", spirv!("color.frag")),
    (
        ShaderId::OverlayFrag,
        "overlay.frag",
        spirv!("overlay.frag"),
    ),
    (ShaderId::MapVert, "map.vert", spirv!("map.vert")),
    (ShaderId::MapFrag, "map.frag", spirv!("map.frag")),
    (
        ShaderId::SurfaceTrimVert,
        "surface_trim.vert",
        spirv!("surface_trim.vert"),
    ),
    (
        ShaderId::SurfaceTrimFrag,
        "surface_trim.frag",
        spirv!("surface_trim.frag"),
    ),
    (
        ShaderId::MapTrimVert,
        "map_trim.vert",
        spirv!("map_trim.vert"),
    ),
    (
        ShaderId::MapTrimFrag,
        "map_trim.frag",
        spirv!("map_trim.frag"),
    ),
    (
        ShaderId::WireTrimVert,
        "wire_trim.vert",
        spirv!("wire_trim.vert"),
    ),
    (
        ShaderId::FlatTrimFrag,
        "flat_trim.frag",
        spirv!("flat_trim.frag"),
    ),
];

/// The shader modules, created once; pipelines for new target formats are built from them.
#[derive(Default)]
pub(crate) struct Shaders {
    modules: Vec<vk::ShaderModule>,
}

impl Shaders {
    pub(crate) fn new(device: &Device) -> GpuResult<Self> {
        let mut shaders = Self {
            modules: Vec::with_capacity(SOURCES.len()),
        };
        for (i, (id, name, bytes)) in SOURCES.iter().enumerate() {
            debug_assert_eq!(*id as usize, i);
            match create_module(device, name, bytes) {
                Ok(m) => shaders.modules.push(m),
                Err(e) => {
                    // SAFETY: no pipeline was built from these modules yet.
                    unsafe { shaders.destroy(device) };
                    return Err(e);
                }
            }
        }
        Ok(shaders)
    }

    pub(crate) fn get(&self, id: ShaderId) -> vk::ShaderModule {
        self.modules[id as usize]
    }

    /// Destroys the modules (pipelines keep their own copies of the code).
    ///
    /// # Safety
    /// No submitted GPU work that uses these objects may still be pending (the device is idle
    /// or lost, or they were never used).
    pub(crate) unsafe fn destroy(self, device: &Device) {
        for m in self.modules {
            // SAFETY: pipelines built from the module keep their own copy; modules are unused.
            unsafe { device.raw.destroy_shader_module(m, None) };
        }
    }
}

fn create_module(device: &Device, name: &str, bytes: &[u8]) -> GpuResult<vk::ShaderModule> {
    // read_spv copies into u32 words, so the embedded bytes need no particular alignment.
    let words = ash::util::read_spv(&mut Cursor::new(bytes))
        .map_err(|e| GpuError::InvalidArgument(format!("embedded shader {name}: {e}")))?;
    let info = vk::ShaderModuleCreateInfo::default().code(&words);
    // SAFETY: the words are SPIR-V produced by glslang for Vulkan 1.3 in build.rs.
    unsafe { device.raw.create_shader_module(&info, None) }.vk("vkCreateShaderModule")
}
