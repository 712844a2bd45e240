//! Graphics pipelines for dynamic rendering, built per (colour format, sample count).
//!
//! All pipelines share one layout: no descriptor sets, one 128-byte push-constant range
//! (the guaranteed minimum) visible to both stages. Vertex data comes from vertex buffers, or
//! for polylines/points from buffer device addresses in the push constants.

use std::collections::HashMap;
use std::mem::offset_of;

use ash::vk;

use super::device::Device;
use super::error::{GpuResult, VkResultExt};
use super::pod::Pod;
use super::shader::{ShaderId, Shaders};

/// Depth attachment format of every target.
pub const DEPTH_FORMAT: vk::Format = vk::Format::D32_SFLOAT;
/// Size of the single push-constant range.
pub(crate) const PUSH_SIZE: u32 = 128;
pub(crate) const PUSH_STAGES: vk::ShaderStageFlags = vk::ShaderStageFlags::from_raw(
    vk::ShaderStageFlags::VERTEX.as_raw() | vk::ShaderStageFlags::FRAGMENT.as_raw(),
);

/// Push constants of `surface.vert`/`surface.frag` (std430 layout mirrored by `repr(C)`).
#[repr(C)]
#[derive(Clone, Copy)]
pub(crate) struct SurfacePush {
    pub view_proj: [f32; 16],
    pub eye: [f32; 4],
    pub light: [f32; 4],
    pub front: [f32; 4],
    pub back: [f32; 4],
}

/// Push constants of `map.vert`/`map.frag` (analysis maps on surfaces).
#[repr(C)]
#[derive(Clone, Copy)]
pub(crate) struct MapPush {
    pub view_proj: [f32; 16],
    pub eye: [f32; 4],
    pub params: [f32; 4],
}

/// Push constants of `wire.vert` + `flat.frag`.
#[repr(C)]
#[derive(Clone, Copy)]
pub(crate) struct WirePush {
    pub view_proj: [f32; 16],
    pub color: [f32; 4],
}

/// Push constants of `polyline.vert` + `flat.frag`.
#[repr(C)]
#[derive(Clone, Copy)]
pub(crate) struct PolylinePush {
    pub view_proj: [f32; 16],
    pub color: [f32; 4],
    pub points: u64,
    pub viewport: [f32; 2],
    pub first: u32,
    pub stride: u32,
    pub count: u32,
    pub width: f32,
    /// 0: one polyline through the run; n > 0: a control net of rows of n points.
    pub grid_cols: u32,
    /// 1: one-pixel lines (line list, 2 vertices per segment); 0: wide quads (6 per segment).
    pub thin: u32,
}

/// Push constants of `points.vert`.
#[repr(C)]
#[derive(Clone, Copy)]
pub(crate) struct PointsPush {
    pub view_proj: [f32; 16],
    pub points: u64,
    pub viewport: [f32; 2],
    pub first: u32,
    pub stride: u32,
    pub hovered: i32,
    pub selected: i32,
    pub size: f32,
    pub color: u32,
    pub hovered_color: u32,
    pub selected_color: u32,
    /// 1: one quad (6 vertices) per point; 0: one point primitive per point (`largePoints`).
    pub quads: u32,
    /// [`super::style::GripGrid::words`].
    pub grid_cols: u32,
    pub grid_rows: u32,
    pub _pad: u32,
}

/// Push constants of `lines3d.vert`.
#[repr(C)]
#[derive(Clone, Copy)]
pub(crate) struct Lines3dPush {
    pub view_proj: [f32; 16],
}

/// Push constants of `overlay.vert` + `overlay.frag`.
#[repr(C)]
#[derive(Clone, Copy)]
pub(crate) struct OverlayPush {
    pub viewport: [f32; 2],
    /// Device address of the glyph atlas (one coverage byte per texel, row-major).
    pub font: u64,
    /// Atlas width in texels (bytes per row).
    pub atlas_width: u32,
    pub _pad: u32,
}

// SAFETY: all push structs are repr(C) with fields laid out without padding (the size and
// offset assertions below, which are also the std430 offsets of the GLSL blocks).
unsafe impl Pod for SurfacePush {}
// SAFETY: see above.
unsafe impl Pod for MapPush {}
// SAFETY: see above.
unsafe impl Pod for WirePush {}
// SAFETY: see above.
unsafe impl Pod for PolylinePush {}
// SAFETY: see above.
unsafe impl Pod for PointsPush {}
// SAFETY: see above.
unsafe impl Pod for Lines3dPush {}
// SAFETY: see above.
unsafe impl Pod for OverlayPush {}

const _: () = {
    assert!(size_of::<SurfacePush>() == 128);
    assert!(size_of::<MapPush>() == 96);
    assert!(offset_of!(MapPush, params) == 80);
    assert!(size_of::<WirePush>() == 80);
    assert!(size_of::<PolylinePush>() == 120);
    assert!(size_of::<PointsPush>() == 128);
    assert!(offset_of!(PointsPush, quads) == 112);
    assert!(offset_of!(PointsPush, grid_cols) == 116);
    assert!(offset_of!(PolylinePush, thin) == 116);
    assert!(size_of::<Lines3dPush>() == 64);
    assert!(size_of::<OverlayPush>() == 24);
    assert!(offset_of!(OverlayPush, font) == 8);
    assert!(offset_of!(OverlayPush, atlas_width) == 16);
    assert!(offset_of!(PolylinePush, grid_cols) == 112);
    // std430 offsets of the blocks in surface.*, polyline.vert and points.vert.
    assert!(offset_of!(SurfacePush, eye) == 64);
    assert!(offset_of!(SurfacePush, back) == 112);
    assert!(offset_of!(PolylinePush, color) == 64);
    assert!(offset_of!(PolylinePush, points) == 80);
    assert!(offset_of!(PolylinePush, viewport) == 88);
    assert!(offset_of!(PolylinePush, width) == 108);
    assert!(offset_of!(PointsPush, points) == 64);
    assert!(offset_of!(PointsPush, viewport) == 72);
    assert!(offset_of!(PointsPush, hovered) == 88);
    assert!(offset_of!(PointsPush, selected_color) == 108);
};

/// Identifies a pipeline set: everything about a target that pipelines bake in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) struct PipelineKey {
    pub color_format: vk::Format,
    pub samples: vk::SampleCountFlags,
}

/// The pipelines of a set, one per primitive kind. Those the infallible draws use (lines,
/// points, overlays) are built with the set; the others on first use, so that a scene of
/// curves compiles no surface pipeline and one of trimmed faces no untrimmed one (lavapipe
/// compiles each to machine code: milliseconds and megabytes apiece).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Which {
    Surface,
    Wire,
    Polyline,
    /// `polyline.vert` as a line list: one-pixel lines and nets, 2 vertices per segment.
    ThinLines,
    Points,
    Lines3d,
    Overlay,
    /// Surfaces coloured by an analysis map (a second vertex stream of one scalar each).
    SurfaceMap,
    /// The surface, map and wire pipelines of trimmed surfaces: a third, instance-rate
    /// stream names the object's coverage mask, which every fragment is tested against.
    SurfaceTrim,
    SurfaceMapTrim,
    WireTrim,
}

impl Which {
    /// Every pipeline, in the order of [`set_specs`].
    const ALL: [Which; SET_SIZE] = [
        Which::Surface,
        Which::Wire,
        Which::Polyline,
        Which::Points,
        Which::ThinLines,
        Which::Lines3d,
        Which::Overlay,
        Which::SurfaceMap,
        Which::SurfaceTrim,
        Which::SurfaceMapTrim,
        Which::WireTrim,
    ];

    /// Built with the set: the pipelines of draws that cannot fail.
    fn eager(self) -> bool {
        matches!(
            self,
            Which::Polyline | Which::ThinLines | Which::Points | Which::Lines3d | Which::Overlay
        )
    }

    fn index(self) -> usize {
        Self::ALL.iter().position(|&w| w == self).unwrap_or(0)
    }
}

/// The pipelines built so far for one [`PipelineKey`] (null: not yet).
type PipelineSet = [vk::Pipeline; SET_SIZE];

/// The shared layout and the pipelines built so far, per target.
#[derive(Default)]
pub(crate) struct Pipelines {
    pub layout: vk::PipelineLayout,
    sets: HashMap<PipelineKey, PipelineSet>,
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Depth {
    /// Test and write, pushed back by a depth bias so overlays on the surface win.
    Biased,
    /// Test (less-or-equal) and write.
    On,
    /// Test enable set per draw (`vkCmdSetDepthTestEnable`).
    Dynamic,
    Off,
}

struct Spec<'a> {
    vs: ShaderId,
    fs: ShaderId,
    bindings: &'a [vk::VertexInputBindingDescription],
    attributes: &'a [vk::VertexInputAttributeDescription],
    topology: vk::PrimitiveTopology,
    depth: Depth,
    blend: bool,
}

fn binding(stride: u32) -> [vk::VertexInputBindingDescription; 1] {
    [vk::VertexInputBindingDescription {
        binding: 0,
        stride,
        input_rate: vk::VertexInputRate::VERTEX,
    }]
}

fn attribute(
    location: u32,
    format: vk::Format,
    offset: u32,
) -> vk::VertexInputAttributeDescription {
    vk::VertexInputAttributeDescription {
        location,
        binding: 0,
        format,
        offset,
    }
}

impl Pipelines {
    pub(crate) fn new(device: &Device) -> GpuResult<Self> {
        let ranges = [vk::PushConstantRange {
            stage_flags: PUSH_STAGES,
            offset: 0,
            size: PUSH_SIZE,
        }];
        let info = vk::PipelineLayoutCreateInfo::default().push_constant_ranges(&ranges);
        // SAFETY: valid device and create info.
        let layout = unsafe { device.raw.create_pipeline_layout(&info, None) }
            .vk("vkCreatePipelineLayout")?;
        Ok(Self {
            layout,
            sets: HashMap::new(),
        })
    }

    /// Builds the eager pipelines of `key`'s set if they are not there (a new swapchain
    /// format, say): a frame's infallible draws use them.
    pub(crate) fn prepare(
        &mut self,
        device: &Device,
        shaders: &Shaders,
        key: PipelineKey,
    ) -> GpuResult<()> {
        for w in Which::ALL.into_iter().filter(|w| w.eager()) {
            self.get(device, shaders, key, w)?;
        }
        Ok(())
    }

    /// Pipeline `which` for `key`, built on first use.
    pub(crate) fn get(
        &mut self,
        device: &Device,
        shaders: &Shaders,
        key: PipelineKey,
        which: Which,
    ) -> GpuResult<vk::Pipeline> {
        let set = self
            .sets
            .entry(key)
            .or_insert([vk::Pipeline::null(); SET_SIZE]);
        let slot = &mut set[which.index()];
        if *slot == vk::Pipeline::null() {
            let inputs = VertexInputs::new();
            let specs = set_specs(&inputs, device.caps.large_points);
            *slot = build_one(device, shaders, self.layout, key, &specs[which.index()])?;
        }
        Ok(*slot)
    }

    /// A pipeline [`Pipelines::prepare`] built for `key`; null if it was not called.
    #[must_use]
    pub(crate) fn eager(&self, key: PipelineKey, which: Which) -> vk::Pipeline {
        debug_assert!(which.eager());
        self.sets
            .get(&key)
            .map_or(vk::Pipeline::null(), |s| s[which.index()])
    }

    /// Destroys every pipeline and the layout.
    ///
    /// # Safety
    /// No submitted GPU work that uses these objects may still be pending (the device is idle
    /// or lost, or they were never used).
    pub(crate) unsafe fn destroy(self, device: &Device) {
        for p in self.sets.into_values().flatten() {
            if p != vk::Pipeline::null() {
                // SAFETY: the renderer waited for the GPU before destroying pipelines.
                unsafe { device.raw.destroy_pipeline(p, None) };
            }
        }
        // SAFETY: no pipeline using the layout remains.
        unsafe { device.raw.destroy_pipeline_layout(self.layout, None) };
    }
}

/// The vertex buffer layouts of the pipelines that read vertex buffers (polylines and points
/// pull theirs through device addresses instead).
struct VertexInputs {
    /// Surface vertices: position and normal, 6 floats.
    surface: [vk::VertexInputBindingDescription; 1],
    surface_attrs: [vk::VertexInputAttributeDescription; 2],
    /// Analysis maps: the surface vertices plus one f32 per vertex from a second buffer.
    map: [vk::VertexInputBindingDescription; 2],
    map_attrs: [vk::VertexInputAttributeDescription; 3],
    /// The trimmed variants: the same, plus one `uvec4` per instance (binding 2, location 4)
    /// naming the object's coverage mask (see `shaders/trim.glsl`).
    surface_trim: [vk::VertexInputBindingDescription; 2],
    surface_trim_attrs: [vk::VertexInputAttributeDescription; 3],
    map_trim: [vk::VertexInputBindingDescription; 3],
    map_trim_attrs: [vk::VertexInputAttributeDescription; 4],
    wire_trim_attrs: [vk::VertexInputAttributeDescription; 2],
    /// `LineVertex`: position and RGBA8 colour.
    lines: [vk::VertexInputBindingDescription; 1],
    lines_attrs: [vk::VertexInputAttributeDescription; 2],
    /// `OverlayVertex`: pixel position, RGBA8 colour, font coordinates.
    overlay: [vk::VertexInputBindingDescription; 1],
    overlay_attrs: [vk::VertexInputAttributeDescription; 3],
}

impl VertexInputs {
    fn new() -> Self {
        use vk::Format as F;
        let surface = binding(24);
        let surface_attrs = [
            attribute(0, F::R32G32B32_SFLOAT, 0),
            attribute(1, F::R32G32B32_SFLOAT, 12),
        ];
        let scalar = vk::VertexInputBindingDescription {
            binding: 1,
            stride: 4,
            input_rate: vk::VertexInputRate::VERTEX,
        };
        let scalar_attr = vk::VertexInputAttributeDescription {
            location: 2,
            binding: 1,
            format: F::R32_SFLOAT,
            offset: 0,
        };
        let mask = vk::VertexInputBindingDescription {
            binding: MASK_BINDING,
            stride: 16,
            input_rate: vk::VertexInputRate::INSTANCE,
        };
        let mask_attr = vk::VertexInputAttributeDescription {
            location: 4,
            binding: MASK_BINDING,
            format: F::R32G32B32A32_UINT,
            offset: 0,
        };
        Self {
            surface,
            surface_attrs,
            map: [surface[0], scalar],
            map_attrs: [surface_attrs[0], surface_attrs[1], scalar_attr],
            surface_trim: [surface[0], mask],
            surface_trim_attrs: [surface_attrs[0], surface_attrs[1], mask_attr],
            map_trim: [surface[0], scalar, mask],
            map_trim_attrs: [surface_attrs[0], surface_attrs[1], scalar_attr, mask_attr],
            wire_trim_attrs: [surface_attrs[0], mask_attr],
            lines: binding(16),
            lines_attrs: [
                attribute(0, F::R32G32B32_SFLOAT, 0),
                attribute(1, F::R8G8B8A8_UNORM, 12),
            ],
            overlay: binding(20),
            overlay_attrs: [
                attribute(0, F::R32G32_SFLOAT, 0),
                attribute(1, F::R8G8B8A8_UNORM, 8),
                attribute(2, F::R32G32_SFLOAT, 12),
            ],
        }
    }
}

/// The vertex binding of the coverage-mask stream of trimmed pipelines.
pub(crate) const MASK_BINDING: u32 = 2;

/// The pipelines of a set, in the order of [`set_specs`].
const SET_SIZE: usize = 11;

/// What each pipeline of a set is made of, in the order of [`Which::ALL`]:
/// surface, wire, polyline, points, thin lines, 3D lines, overlay, surface map, and the
/// trimmed surface, surface map and wire.
fn set_specs(inputs: &VertexInputs, large_points: bool) -> [Spec<'_>; SET_SIZE] {
    let tri = vk::PrimitiveTopology::TRIANGLE_LIST;
    let lines = vk::PrimitiveTopology::LINE_LIST;
    // Polylines and points pull their vertices through buffer device addresses.
    let pulled = |vs, fs, topology| Spec {
        vs,
        fs,
        bindings: &[],
        attributes: &[],
        topology,
        depth: Depth::Dynamic,
        blend: false,
    };
    [
        Spec {
            vs: ShaderId::SurfaceVert,
            fs: ShaderId::SurfaceFrag,
            bindings: &inputs.surface,
            attributes: &inputs.surface_attrs,
            topology: tri,
            depth: Depth::Biased,
            blend: false,
        },
        Spec {
            vs: ShaderId::WireVert,
            fs: ShaderId::FlatFrag,
            bindings: &inputs.surface,
            attributes: &inputs.surface_attrs[..1],
            topology: lines,
            depth: Depth::On,
            blend: false,
        },
        pulled(ShaderId::PolylineVert, ShaderId::FlatFrag, tri),
        // Large point primitives: a sixth of the vertex work of quads.
        pulled(
            ShaderId::PointsVert,
            ShaderId::PointsFrag,
            if large_points {
                vk::PrimitiveTopology::POINT_LIST
            } else {
                tri
            },
        ),
        pulled(ShaderId::PolylineVert, ShaderId::FlatFrag, lines),
        Spec {
            vs: ShaderId::Lines3dVert,
            fs: ShaderId::ColorFrag,
            bindings: &inputs.lines,
            attributes: &inputs.lines_attrs,
            topology: lines,
            depth: Depth::On,
            blend: false,
        },
        Spec {
            vs: ShaderId::OverlayVert,
            fs: ShaderId::OverlayFrag,
            bindings: &inputs.overlay,
            attributes: &inputs.overlay_attrs,
            topology: tri,
            depth: Depth::Off,
            blend: true,
        },
        Spec {
            vs: ShaderId::MapVert,
            fs: ShaderId::MapFrag,
            bindings: &inputs.map,
            attributes: &inputs.map_attrs,
            topology: tri,
            depth: Depth::Biased,
            blend: false,
        },
        Spec {
            vs: ShaderId::SurfaceTrimVert,
            fs: ShaderId::SurfaceTrimFrag,
            bindings: &inputs.surface_trim,
            attributes: &inputs.surface_trim_attrs,
            topology: tri,
            depth: Depth::Biased,
            blend: false,
        },
        Spec {
            vs: ShaderId::MapTrimVert,
            fs: ShaderId::MapTrimFrag,
            bindings: &inputs.map_trim,
            attributes: &inputs.map_trim_attrs,
            topology: tri,
            depth: Depth::Biased,
            blend: false,
        },
        Spec {
            vs: ShaderId::WireTrimVert,
            fs: ShaderId::FlatTrimFrag,
            bindings: &inputs.surface_trim,
            attributes: &inputs.wire_trim_attrs,
            topology: lines,
            depth: Depth::On,
            blend: false,
        },
    ]
}

fn build_one(
    device: &Device,
    shaders: &Shaders,
    layout: vk::PipelineLayout,
    key: PipelineKey,
    spec: &Spec<'_>,
) -> GpuResult<vk::Pipeline> {
    let stages = [
        vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::VERTEX)
            .module(shaders.get(spec.vs))
            .name(c"main"),
        vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::FRAGMENT)
            .module(shaders.get(spec.fs))
            .name(c"main"),
    ];
    let vertex_input = vk::PipelineVertexInputStateCreateInfo::default()
        .vertex_binding_descriptions(spec.bindings)
        .vertex_attribute_descriptions(spec.attributes);
    let input_assembly =
        vk::PipelineInputAssemblyStateCreateInfo::default().topology(spec.topology);
    let viewport = vk::PipelineViewportStateCreateInfo::default()
        .viewport_count(1)
        .scissor_count(1);
    let raster = rasterization(spec.depth);
    let multisample =
        vk::PipelineMultisampleStateCreateInfo::default().rasterization_samples(key.samples);
    let depth_on = spec.depth != Depth::Off;
    let depth = vk::PipelineDepthStencilStateCreateInfo::default()
        .depth_test_enable(depth_on)
        .depth_write_enable(depth_on)
        .depth_compare_op(vk::CompareOp::LESS_OR_EQUAL);
    let blend_attachments = [blend_attachment(spec.blend)];
    let blend = vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend_attachments);
    let dynamic =
        vk::PipelineDynamicStateCreateInfo::default().dynamic_states(dynamic_states(spec.depth));
    let color_formats = [key.color_format];
    let mut rendering = vk::PipelineRenderingCreateInfo::default()
        .color_attachment_formats(&color_formats)
        .depth_attachment_format(DEPTH_FORMAT);
    let info = vk::GraphicsPipelineCreateInfo::default()
        .stages(&stages)
        .vertex_input_state(&vertex_input)
        .input_assembly_state(&input_assembly)
        .viewport_state(&viewport)
        .rasterization_state(&raster)
        .multisample_state(&multisample)
        .depth_stencil_state(&depth)
        .color_blend_state(&blend)
        .dynamic_state(&dynamic)
        .layout(layout)
        .push_next(&mut rendering);
    // SAFETY: all state structs outlive the call; shaders match the layout's push range.
    let result = unsafe {
        device
            .raw
            .create_graphics_pipelines(vk::PipelineCache::null(), &[info], None)
    };
    match result {
        Ok(p) => Ok(p[0]),
        Err((_, e)) => Err(e).vk("vkCreateGraphicsPipelines"),
    }
}

/// Filled polygons, no culling; surfaces ([`Depth::Biased`]) pushed back in depth.
fn rasterization(depth: Depth) -> vk::PipelineRasterizationStateCreateInfo<'static> {
    let raster = vk::PipelineRasterizationStateCreateInfo::default()
        .polygon_mode(vk::PolygonMode::FILL)
        .cull_mode(vk::CullModeFlags::NONE)
        .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
        .line_width(1.0);
    if depth != Depth::Biased {
        return raster;
    }
    // Push filled surfaces back by a couple of depth units plus a slope term, so lines lying
    // exactly on the surface (isolines, wireframe, curves on it) pass LESS_OR_EQUAL.
    raster
        .depth_bias_enable(true)
        .depth_bias_constant_factor(2.0)
        .depth_bias_slope_factor(1.5)
}

/// Straight-alpha "over" blending when `blend`, else plain writes.
fn blend_attachment(blend: bool) -> vk::PipelineColorBlendAttachmentState {
    let plain = vk::PipelineColorBlendAttachmentState::default()
        .color_write_mask(vk::ColorComponentFlags::RGBA);
    if !blend {
        return plain;
    }
    plain
        .blend_enable(true)
        .src_color_blend_factor(vk::BlendFactor::SRC_ALPHA)
        .dst_color_blend_factor(vk::BlendFactor::ONE_MINUS_SRC_ALPHA)
        .color_blend_op(vk::BlendOp::ADD)
        .src_alpha_blend_factor(vk::BlendFactor::ONE)
        .dst_alpha_blend_factor(vk::BlendFactor::ONE_MINUS_SRC_ALPHA)
        .alpha_blend_op(vk::BlendOp::ADD)
}

/// Viewport and scissor are always dynamic; the depth test too for [`Depth::Dynamic`].
fn dynamic_states(depth: Depth) -> &'static [vk::DynamicState] {
    if depth == Depth::Dynamic {
        &[
            vk::DynamicState::VIEWPORT,
            vk::DynamicState::SCISSOR,
            vk::DynamicState::DEPTH_TEST_ENABLE,
        ]
    } else {
        &[vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR]
    }
}
