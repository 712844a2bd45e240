//! How things are drawn: the camera and the styles of the draw calls. Colours are linear
//! RGBA `f32`.

use glam::{Mat4, Vec3};

/// Camera for 3D draws.
///
/// `view_proj` maps world space to Vulkan clip space with depth in `[0, 1]` and **y up**
/// (e.g. `Mat4::perspective_rh(..) * Mat4::look_at_rh(..)`): the renderer flips the viewport
/// so that the conventional y-up projection comes out upright.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Projection × view.
    pub view_proj: Mat4,
    /// Camera position in world space (lighting, two-sided shading).
    pub eye: Vec3,
}

impl Default for Camera {
    fn default() -> Self {
        Self {
            view_proj: Mat4::IDENTITY,
            eye: Vec3::new(0.0, 0.0, 1.0),
        }
    }
}

/// Shading of a grid surface. Colours are linear RGBA.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceStyle {
    /// Colour of the side the normals point to.
    pub front: [f32; 4],
    /// Colour of the other side.
    pub back: [f32; 4],
    /// Direction towards the light in world space; zero means a headlight (from the eye).
    pub light_dir: Vec3,
    /// Ambient fraction in `[0, 1]`.
    pub ambient: f32,
    /// Blinn–Phong specular exponent.
    pub shininess: f32,
}

impl Default for SurfaceStyle {
    fn default() -> Self {
        Self {
            front: [0.55, 0.62, 0.80, 1.0],
            back: [0.80, 0.45, 0.35, 1.0],
            light_dir: Vec3::ZERO,
            ambient: 0.15,
            shininess: 48.0,
        }
    }
}

/// How an analysis map colours surfaces ([`super::Frame::draw_surface_map_batch`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MapStyle {
    /// Each vertex's scalar through the diverging colour scale over ±`range` (NaN grey).
    Scale { range: f32 },
    /// Reflection lines: `stripes` bands over the height (z from −1 to 1) of the reflected view ray.
    Zebra { stripes: f32 },
}

/// Wide-line style. Colour is linear RGBA.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PolylineStyle {
    /// Linear RGBA.
    pub color: [f32; 4],
    /// Width in pixels.
    pub width: f32,
    /// Whether the line is hidden behind nearer geometry.
    pub depth_test: bool,
}

impl Default for PolylineStyle {
    fn default() -> Self {
        Self {
            color: [0.9, 0.9, 0.9, 1.0],
            width: 2.0,
            depth_test: true,
        }
    }
}

/// Control-point style. Colours are linear RGBA.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointStyle {
    /// Colour of ordinary points.
    pub color: [f32; 4],
    /// Side of the square in pixels (hovered/selected points are drawn larger).
    pub size: f32,
    /// Index (within the run) of the point under the cursor.
    pub hovered: Option<u32>,
    /// Index (within the run) of the selected point.
    pub selected: Option<u32>,
    /// Colour of the hovered point.
    pub hovered_color: [f32; 4],
    /// Colour of the selected point.
    pub selected_color: [f32; 4],
    /// Whether points are hidden behind nearer geometry.
    pub depth_test: bool,
    /// The run as rows of a control net, thinned on screen (`None`: every point drawn).
    pub grid: Option<GripGrid>,
}

/// A run of points as rows of a `rows × cols` control net whose first row is `first_row`
/// (a run may hold some rows of a larger net), of which only every `every`-th row and column
/// (and the last of each) is drawn, besides the hovered and the selected point: a dense net
/// stays readable and its surface visible.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GripGrid {
    pub rows: u32,
    pub cols: u32,
    pub first_row: u32,
    /// A power of two up to [`GripGrid::MAX_EVERY`].
    pub every: u32,
}

impl GripGrid {
    pub const MAX_EVERY: u32 = 128;

    /// The two push-constant words `points.vert` reads: columns (bits 0–23) with log2 of
    /// `every` (bits 24–31), and the first row (bits 16–31) with the rows (bits 0–15).
    /// `[0, 0]` (every point) when the net does not fit those bits.
    #[must_use]
    pub fn words(grid: Option<Self>) -> [u32; 2] {
        match grid {
            Some(g)
                if g.every > 1
                    && g.every.is_power_of_two()
                    && g.every <= Self::MAX_EVERY
                    && g.cols >= 1
                    && g.cols < 1 << 24
                    && g.rows >= 1
                    && g.rows < 1 << 16
                    && g.first_row < 1 << 16 =>
            {
                [
                    g.cols | (g.every.trailing_zeros() << 24),
                    g.rows | (g.first_row << 16),
                ]
            }
            _ => [0, 0],
        }
    }
}

impl Default for PointStyle {
    fn default() -> Self {
        Self {
            color: [0.95, 0.95, 0.95, 1.0],
            size: 8.0,
            hovered: None,
            selected: None,
            hovered_color: [1.0, 0.8, 0.1, 1.0],
            selected_color: [1.0, 0.2, 0.1, 1.0],
            depth_test: false,
            grid: None,
        }
    }
}
