//! What is drawn and picked of an object besides its samples: its control polygon or net, and
//! for ERBS objects every polynomial local curve or patch at any depth with its control points
//! and a few display samples. Kept per object as display vertices with a layout, updated in
//! place by the edits that move them, so a drag rewrites one vertex and not the net.

use super::{Index2, LocalPath, ModelRef, Target};
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
    /// The control display of a model.
    #[must_use]
    pub fn of(model: ModelRef<'_>) -> Self {
        model.kind().controls()
    }

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

    /// Brings the display up to date with `model` after an edit of `target`, rewriting only
    /// what that target moves where the layout allows; says what changed.
    pub fn update(&mut self, model: ModelRef<'_>, target: Target) -> ControlsChange {
        let changed = match target {
            // A weight moves no control point.
            Target::Weight(_) => return ControlsChange::Unchanged,
            Target::Point(p) => self.update_point(model, p),
            Target::Local(l) => self.update_local(model, l),
            Target::Structure => None,
        };
        changed.map_or_else(|| self.refresh(model), ControlsChange::Vertices)
    }

    /// Everything again; `Resized` where the layout changed.
    pub fn refresh(&mut self, model: ModelRef<'_>) -> ControlsChange {
        let new = ControlDisplay::of(model);
        if new.layout == self.layout && new.vertices.len() == self.vertices.len() {
            self.vertices = new.vertices;
            ControlsChange::Vertices(DirtySet::all(self.vertices.len()))
        } else {
            *self = new;
            ControlsChange::Resized
        }
    }

    /// One control point of a polygon or net (a drag must not copy a 10 000-point net).
    fn update_point(&mut self, model: ModelRef<'_>, point: Index2) -> Option<DirtySet> {
        let index = match (&self.layout, point) {
            (ControlLayout::Polygon { count }, Index2::One(k)) if k < *count => k,
            (ControlLayout::Net { rows, cols }, Index2::Two(i, j)) if i < *rows && j < *cols => {
                i * cols + j
            }
            _ => return None,
        };
        let p = model.kind().control_point(point)?;
        self.vertices[index] = p;
        let mut set = DirtySet::default();
        set.insert(index..index + 1);
        Some(set)
    }

    /// The polynomial locals at or below one ERBS local: their display samples and points.
    fn update_local(&mut self, model: ModelRef<'_>, local: LocalPath<Index2>) -> Option<DirtySet> {
        let fresh = model.kind().local_controls(local)?;
        let ((ControlLayout::LocalCurves(old), ControlLayout::LocalCurves(new))
        | (ControlLayout::LocalPatches(old), ControlLayout::LocalPatches(new))) =
            (&self.layout, &fresh.layout)
        else {
            return None;
        };
        let mut set = DirtySet::default();
        for n in new {
            let o = old.iter().find(|o| o.path == n.path)?;
            if (o.rows, o.cols) != (n.rows, n.cols) {
                return None;
            }
            let (s_len, p_len) = (display_samples(&fresh.layout), n.rows * n.cols);
            self.vertices[o.samples..o.samples + s_len]
                .copy_from_slice(&fresh.vertices[n.samples..n.samples + s_len]);
            self.vertices[o.points..o.points + p_len]
                .copy_from_slice(&fresh.vertices[n.points..n.points + p_len]);
            set.insert(o.samples..o.samples + s_len);
            set.insert(o.points..o.points + p_len);
        }
        Some(set)
    }
}

/// Display sample vertices of one local in `layout`.
fn display_samples(layout: &ControlLayout) -> usize {
    match layout {
        ControlLayout::LocalPatches(_) => 2 * LOCAL_PATCH_SAMPLES * LOCAL_PATCH_SAMPLES,
        _ => LOCAL_CURVE_SAMPLES,
    }
}
