//! Undo and redo of edits through the same delta path.
//!
//! A step is one user gesture (a whole drag, one G/R/S transform). It keeps the edits that made
//! it (redo replays them on the same starting values, so redo is bit-exact) and, for every
//! target it touched, the exact value before the step (undo sets them back, so undo is
//! bit-exact too — inverse matrices would leave rounding behind).

use crate::render::Document;
use crate::sampling::ModelRef;
use crate::scene::{Edit, EditOp, Index2};

#[derive(Debug, Clone, Default)]
pub struct UndoStep {
    pub label: String,
    pub forward: Vec<Edit>,
    pub restore: Vec<Edit>,
}

#[derive(Debug, Default)]
pub struct UndoStack {
    done: Vec<UndoStep>,
    undone: Vec<UndoStep>,
    open: Option<UndoStep>,
}

impl UndoStack {
    /// Opens a step; edits recorded until [`UndoStack::end`] belong to it.
    pub fn begin(&mut self, label: &str) {
        self.end();
        self.open = Some(UndoStep {
            label: label.into(),
            ..UndoStep::default()
        });
    }

    pub fn is_open(&self) -> bool {
        self.open.is_some()
    }

    /// Records `edit` before it is applied: captures the exact prior value of its target the
    /// first time the step touches it. Edits outside an open step form a step of their own.
    pub fn record(&mut self, doc: &Document, edit: &Edit) {
        let single = self.open.is_none();
        if single {
            self.begin("edit");
        }
        let step = self.open.as_mut().expect("a step is open");
        if let Some(restore) = capture(doc, edit) {
            let same_target =
                |e: &Edit| e.object == restore.object && target(&e.op) == target(&restore.op);
            if !step.restore.iter().any(same_target) {
                step.restore.push(restore);
            }
        }
        step.forward.push(edit.clone());
        if single {
            self.end();
        }
    }

    /// Closes the open step (empty steps are dropped); a new step clears the redo list.
    pub fn end(&mut self) {
        if let Some(step) = self.open.take().filter(|s| !s.forward.is_empty()) {
            self.done.push(step);
            self.undone.clear();
        }
    }

    /// Drops the open step without keeping it (after a cancelled gesture was rolled back).
    pub fn discard(&mut self) -> Option<UndoStep> {
        self.open.take()
    }

    /// The edits that undo the last step (exact prior values), or `None`.
    pub fn undo(&mut self) -> Option<(String, Vec<Edit>)> {
        self.end();
        let step = self.done.pop()?;
        let edits = step.restore.iter().rev().cloned().collect();
        let label = step.label.clone();
        self.undone.push(step);
        Some((label, edits))
    }

    /// The edits that redo the last undone step, or `None`.
    pub fn redo(&mut self) -> Option<(String, Vec<Edit>)> {
        self.end();
        let step = self.undone.pop()?;
        let edits = step.forward.clone();
        let label = step.label.clone();
        self.done.push(step);
        Some((label, edits))
    }

    pub fn depth(&self) -> (usize, usize) {
        (self.done.len(), self.undone.len())
    }
}

#[derive(Debug, PartialEq, Eq)]
enum Target {
    Point(Index2),
    Weight(Index2),
    Local(Index2),
}

fn target(op: &EditOp) -> Target {
    match op {
        EditOp::TranslatePoint { point, .. } | EditOp::SetPoint { point, .. } => {
            Target::Point(*point)
        }
        EditOp::SetWeight { point, .. } => Target::Weight(*point),
        EditOp::TransformLocal { local, .. }
        | EditOp::TranslateLocalPoint { local, .. }
        | EditOp::SetLocalPoints { local, .. } => Target::Local(*local),
    }
}

/// The edit that sets `edit`'s target back to its current value.
fn capture(doc: &Document, edit: &Edit) -> Option<Edit> {
    let model = doc.objects.get(edit.object)?.sampled.model();
    let object = edit.object;
    let op = match (&edit.op, model) {
        (EditOp::TranslatePoint { point, .. } | EditOp::SetPoint { point, .. }, m) => {
            EditOp::SetPoint {
                point: *point,
                position: point_of(m, *point)?,
            }
        }
        (EditOp::SetWeight { point, .. }, ModelRef::Curve(c)) => {
            let Index2::One(k) = point else { return None };
            EditOp::SetWeight {
                point: *point,
                weight: c.weights().map_or(1.0, |w| w[*k]),
            }
        }
        (EditOp::SetWeight { point, .. }, ModelRef::Surface(s)) => {
            let Index2::Two(i, j) = point else {
                return None;
            };
            let nv = s.count()[1];
            EditOp::SetWeight {
                point: *point,
                weight: s.weights().map_or(1.0, |w| w[i * nv + j]),
            }
        }
        (
            EditOp::TransformLocal { local, .. }
            | EditOp::TranslateLocalPoint { local, .. }
            | EditOp::SetLocalPoints { local, .. },
            m,
        ) => EditOp::SetLocalPoints {
            local: *local,
            points: local_points(m, *local)?,
        },
        _ => return None,
    };
    Some(Edit { object, op })
}

fn point_of(m: ModelRef<'_>, p: Index2) -> Option<glam::DVec3> {
    match (m, p) {
        (ModelRef::Curve(c), Index2::One(k)) => c.points().get(k).copied(),
        (ModelRef::Surface(s), Index2::Two(i, j)) => Some(s.point(i, j)),
        _ => None,
    }
}

/// Every control point of an ERBS local curve/patch.
pub fn local_points(m: ModelRef<'_>, local: Index2) -> Option<Vec<glam::DVec3>> {
    match (m, local) {
        (ModelRef::ErbsCurve(c), Index2::One(l)) => {
            Some(c.local_curves().get(l)?.points().to_vec())
        }
        (ModelRef::ErbsSurface(s), Index2::Two(k, l)) => {
            Some(s.local_patch(k, l).points().to_vec())
        }
        _ => None,
    }
}
