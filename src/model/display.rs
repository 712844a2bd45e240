//! A control display kept up to date with its model: the methods of [`ControlDisplay`] that
//! read a model of any kind (through the registry's views).

use super::controls::{ControlDisplay, ControlLayout, ControlsChange, display_samples};
use super::edit::Target;
use super::erbs::LocalPath;
use super::index::Index2;
use super::registry::ModelRef;
use crate::sampling::DirtySet;

impl ControlDisplay {
    /// The control display of a model.
    #[must_use]
    pub fn of(model: ModelRef<'_>) -> Self {
        model.kind().controls()
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
