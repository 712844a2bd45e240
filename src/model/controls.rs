//! What is drawn and picked of an object besides its samples: its control polygon or net, and
//! for ERBS objects every polynomial local curve or patch at any depth with its control points
//! and a few display samples. Kept per object as display vertices with a layout, updated in
//! place by the edits that move them, so a drag rewrites one vertex and not the net.

use super::erbs::LocalPath;
use super::index::Index2;
use crate::sampling::DirtySet;
use glam::DVec3;

/// Samples per ERBS local curve drawn in its own colour.
pub const LOCAL_CURVE_SAMPLES: usize = 48;
/// Samples per direction of an ERBS local patch drawn as a wire grid.
pub const LOCAL_PATCH_SAMPLES: usize = 9;

/// What happened to one object's control display.
#[derive(Debug, Clone, Default, PartialEq)]
pub enum ControlsChange {
    #[default]
    Unchanged,
    /// These display vertices were rewritten in place (the layout is the same).
    Vertices(DirtySet),
    /// The layout changed (a refinement, an undone one, a conversion): take it all again.
    Resized,
}

impl ControlsChange {
    /// Both changes as one.
    pub fn join(&mut self, other: ControlsChange) {
        *self = match (std::mem::take(self), other) {
            (ControlsChange::Resized, _) | (_, ControlsChange::Resized) => ControlsChange::Resized,
            (ControlsChange::Unchanged, x) | (x, ControlsChange::Unchanged) => x,
            (ControlsChange::Vertices(mut a), ControlsChange::Vertices(b)) => {
                b.ranges().iter().for_each(|r| a.insert(r.clone()));
                ControlsChange::Vertices(a)
            }
        };
    }
}

/// A control point as it is picked, within its object: a point of the control polygon or net,
/// or a point of a polynomial ERBS local at any depth.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Grip {
    Point(Index2),
    LocalPoint {
        local: LocalPath<Index2>,
        point: Index2,
    },
}

/// Where one polynomial ERBS local's display vertices sit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LocalEntry {
    pub path: LocalPath<Index2>,
    /// First display sample: [`LOCAL_CURVE_SAMPLES`] positions (curves), or
    /// [`LOCAL_PATCH_SAMPLES`]² (position, normal) pairs row-major (patches).
    pub samples: usize,
    /// First control point.
    pub points: usize,
    /// Control points (curves), or net rows (patches).
    pub rows: usize,
    /// 1 (curves), or net columns (patches).
    pub cols: usize,
}

/// How an object's display vertices are laid out.
#[derive(Debug, Clone, PartialEq)]
pub enum ControlLayout {
    /// Control polygon of a curve.
    Polygon { count: usize },
    /// Control net of a tensor surface, row-major.
    Net { rows: usize, cols: usize },
    /// ERBS curve: every polynomial local at any depth, in path order; all display samples
    /// first, then all control points.
    LocalCurves(Vec<LocalEntry>),
    /// ERBS surface: every polynomial local patch at any depth, likewise.
    LocalPatches(Vec<LocalEntry>),
}

/// An object's control display: a layout and its vertices (f64 world coordinates).
#[derive(Debug, Clone, PartialEq)]
pub struct ControlDisplay {
    pub layout: ControlLayout,
    pub vertices: Vec<DVec3>,
}

impl ControlDisplay {
    /// A control polygon.
    #[must_use]
    pub fn polygon(points: Vec<DVec3>) -> Self {
        ControlDisplay {
            layout: ControlLayout::Polygon {
                count: points.len(),
            },
            vertices: points,
        }
    }

    /// A row-major control net.
    #[must_use]
    pub fn net([rows, cols]: [usize; 2], points: Vec<DVec3>) -> Self {
        ControlDisplay {
            layout: ControlLayout::Net { rows, cols },
            vertices: points,
        }
    }

    /// Every pickable point with its position: the display's own control points, so what is
    /// drawn is what is picked.
    #[must_use]
    pub fn grips(&self) -> Vec<(Grip, DVec3)> {
        let v = &self.vertices;
        match &self.layout {
            ControlLayout::Polygon { count } => (0..*count)
                .map(|k| (Grip::Point(Index2::One(k)), v[k]))
                .collect(),
            ControlLayout::Net { rows, cols } => (0..rows * cols)
                .map(|k| (Grip::Point(Index2::Two(k / cols, k % cols)), v[k]))
                .collect(),
            ControlLayout::LocalCurves(entries) | ControlLayout::LocalPatches(entries) => entries
                .iter()
                .flat_map(|e| {
                    (0..e.rows * e.cols).map(move |q| {
                        let point = if matches!(self.layout, ControlLayout::LocalCurves(_)) {
                            Index2::One(q)
                        } else {
                            Index2::Two(q / e.cols, q % e.cols)
                        };
                        let grip = Grip::LocalPoint {
                            local: e.path,
                            point,
                        };
                        (grip, v[e.points + q])
                    })
                })
                .collect(),
        }
    }
}

impl ControlDisplay {
    /// The positions of [`ControlDisplay::grips`], in the same order, without building the
    /// grips (a net can have millions of points; bounds need only where they are).
    pub fn grip_points(&self) -> impl Iterator<Item = DVec3> + '_ {
        let ranges: Box<dyn Iterator<Item = std::ops::Range<usize>> + '_> = match &self.layout {
            ControlLayout::Polygon { count } => Box::new(std::iter::once(0..*count)),
            ControlLayout::Net { rows, cols } => Box::new(std::iter::once(0..rows * cols)),
            ControlLayout::LocalCurves(entries) | ControlLayout::LocalPatches(entries) => {
                Box::new(entries.iter().map(|e| e.points..e.points + e.rows * e.cols))
            }
        };
        ranges.flat_map(|r| self.vertices[r].iter().copied())
    }
}

/// Display sample vertices of one local in `layout`.
pub(super) fn display_samples(layout: &ControlLayout) -> usize {
    match layout {
        ControlLayout::LocalPatches(_) => 2 * LOCAL_PATCH_SAMPLES * LOCAL_PATCH_SAMPLES,
        _ => LOCAL_CURVE_SAMPLES,
    }
}
