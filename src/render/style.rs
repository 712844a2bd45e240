//! What is shown and in which colours.

use crate::editor::Handle;
use crate::model::{Index2, LocalPath};

/// Surface wireframe overlay.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Wire {
    Off,
    /// Isoparametric lines every k samples (boundary included).
    Isolines(u32),
    /// Every sample row and column.
    Full,
}

/// Which objects show their control polygons, nets and points.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NetMode {
    Off,
    /// The selected object and the one under the cursor.
    Focused,
    All,
}

impl NetMode {
    /// Next mode for the toggle key: All → Focused → Off → All.
    #[must_use]
    pub fn next(self) -> Self {
        match self {
            NetMode::All => NetMode::Focused,
            NetMode::Focused => NetMode::Off,
            NetMode::Off => NetMode::All,
        }
    }
}

/// The display toggles of the viewer and `prespline render`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewOptions {
    /// Control polygons, control nets and control points.
    pub control_nets: NetMode,
    /// ERBS local curves and patches in their own colour.
    pub local_curves: bool,
    pub wire: Wire,
    /// Surface normals as short lines.
    pub normals: bool,
    /// Frenet frames along curves.
    pub frenet: bool,
    /// Curvature combs along curves.
    pub curvature_comb: bool,
    /// Continuity badges at curve junctions and multiple knots.
    pub badges: bool,
    /// A colour map (or zebra stripes) on surfaces, with its legend.
    pub analysis: Option<super::maps::SurfaceMap>,
    /// How the map's colour scale is chosen: per surface (the default), shared or fixed.
    pub map_range: super::maps::MapRange,
    /// The osculating circle of curve object `.0` at parameter `.1` (`render --osculating`;
    /// the viewer follows the cursor instead).
    pub osculating_at: Option<(usize, f64)>,
    /// Curve width in pixels.
    pub curve_width: f32,
    /// Control point size in pixels.
    pub point_size: f32,
    /// Display level of detail: draw strided subsets of dense surface grids (see
    /// [`super::lod`]). Off draws every sample.
    pub lod: bool,
}

impl Default for ViewOptions {
    fn default() -> Self {
        Self {
            control_nets: NetMode::Off,
            local_curves: true,
            wire: Wire::Off,
            normals: false,
            frenet: false,
            curvature_comb: false,
            badges: false,
            analysis: None,
            map_range: super::maps::MapRange::PerObject,
            osculating_at: None,
            curve_width: 2.5,
            point_size: 8.0,
            lod: true,
        }
    }
}

/// Colours (linear RGBA).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Palette {
    pub background: [f32; 4],
    pub wire: [f32; 4],
    pub net: [f32; 4],
    pub point: [f32; 4],
    /// ERBS local curves and patches (green, as in the paper's Figure 3).
    pub local: [f32; 4],
    pub selected_local: [f32; 4],
    surface: [f32; 3],
    objects: [[f32; 3]; 6],
}

impl Default for Palette {
    fn default() -> Self {
        Self {
            background: [0.018, 0.02, 0.026, 1.0],
            wire: [0.02, 0.02, 0.025, 1.0],
            net: [0.35, 0.37, 0.42, 1.0],
            point: [0.9, 0.9, 0.92, 1.0],
            local: [0.08, 0.6, 0.12, 1.0],
            selected_local: [1.0, 0.45, 0.05, 1.0],
            surface: [0.55, 0.62, 0.80],
            objects: [
                [0.85, 0.85, 0.90],
                [0.80, 0.45, 0.20],
                [0.30, 0.65, 0.45],
                [0.75, 0.25, 0.30],
                [0.65, 0.55, 0.80],
                [0.85, 0.75, 0.25],
            ],
        }
    }
}

impl Palette {
    /// Colour of object `i`: the scene's `color` if given, else a palette entry.
    #[must_use]
    pub fn object(&self, i: usize, color: Option<[f64; 3]>) -> [f32; 4] {
        let c = color
            .map(|c| c.map(|x| x as f32))
            .unwrap_or(self.objects[i % self.objects.len()]);
        [c[0], c[1], c[2], 1.0]
    }

    /// Colour of a surface: the scene's `color` if given, else one neutral colour for every
    /// surface (models made of many patches, like the teapot, should not look like a quilt).
    #[must_use]
    pub fn surface(&self, color: Option<[f64; 3]>) -> [f32; 4] {
        let c = color.map(|c| c.map(|x| x as f32)).unwrap_or(self.surface);
        [c[0], c[1], c[2], 1.0]
    }

    /// Back faces (the side Su × Sv points away from): a warmer, slightly darker version of the
    /// front, so orientation is visible without making one-sided models look garish.
    #[must_use]
    pub fn back_of(&self, c: [f32; 4]) -> [f32; 4] {
        let warm = [0.85, 0.55, 0.35];
        [
            0.9 * (0.6 * c[0] + 0.4 * warm[0]),
            0.9 * (0.6 * c[1] + 0.4 * warm[1]),
            0.9 * (0.6 * c[2] + 0.4 * warm[2]),
            1.0,
        ]
    }
}

/// Which handle the cursor is over and which one is selected (for highlighting).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Highlight {
    pub hovered: Option<Handle>,
    pub selected: Option<Handle>,
    /// A selected ERBS local curve/patch (drawn emphasised).
    pub selected_local: Option<(usize, LocalPath<Index2>)>,
    /// The object under the cursor (its controls show in [`NetMode::Focused`]).
    pub hovered_object: Option<usize>,
}

impl Highlight {
    /// Whether object `i` is selected or under the cursor.
    #[must_use]
    pub fn focuses(&self, i: usize) -> bool {
        self.hovered.is_some_and(|h| h.object() == i)
            || self.selected.is_some_and(|h| h.object() == i)
            || self.selected_local.is_some_and(|(o, _)| o == i)
            || self.hovered_object == Some(i)
    }
}
