//! Undo and redo of edits through the same delta path.
//!
//! A step is one user gesture (a whole drag, one G/R/S transform). It keeps the edits that made
//! it (redo replays them on the same starting values, so redo is bit-exact) and, for every
//! target it touched, the exact value before the step (undo sets them back, so undo is
//! bit-exact too — inverse matrices would leave rounding behind).

use super::document::Document;
use crate::model::{Edit, Target};

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

    #[must_use]
    pub fn is_open(&self) -> bool {
        self.open.is_some()
    }

    /// Records `edit` just before it is applied to `doc`: keeps the exact prior state of its
    /// target the first time the step touches it (every structural edit keeps the whole prior
    /// model). Edits outside an open step form a step of their own.
    pub fn record(&mut self, doc: &Document, edit: &Edit) {
        let single = self.open.is_none();
        if single {
            self.begin("edit");
        }
        let step = self.open.get_or_insert_with(UndoStep::default);
        let target = edit.edit.target();
        let known = target != Target::Structure && restored(&step.restore, edit.object, target);
        if !known
            && let Some(o) = doc.objects.get(edit.object)
            && let Ok(inverse) = edit.edit.inverse(o.sampled.model())
        {
            step.restore.push(Edit {
                object: edit.object,
                edit: inverse,
            });
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

    #[must_use]
    pub fn depth(&self) -> (usize, usize) {
        (self.done.len(), self.undone.len())
    }
}

/// Whether `restores` (a step's restore edits in the order recorded) already puts `key`'s target
/// back: a restore of the same target after the object's last structural restore. Indices
/// before a structural edit address another net, so the search stops there.
fn restored(restores: &[Edit], object: usize, target: Target) -> bool {
    for r in restores.iter().rev().filter(|r| r.object == object) {
        let t = r.edit.target();
        if t == Target::Structure {
            return false;
        }
        if t == target {
            return true;
        }
    }
    false
}
