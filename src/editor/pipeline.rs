//! The edit pipeline: every change of the document goes through [`Editor::submit`] (validate,
//! hold to the memory budget, prepare structural results once, record for undo) and comes back
//! from [`Editor::apply_pending`] as one [`Applied`] report (the samples and controls it
//! rewrote). The viewer, `prespline render`, `sample` and `bench` all drive this one type.

use super::applied::Applied;
use super::document::Document;
use super::undo::{UndoStack, UndoStep};
use crate::model::{Build, Edit, EditError, Model, merge_edits};
use crate::sampling::budget::{Extent, MemoryBudget, Uses, check_extents};
use crate::sampling::{DirtyRegion, SampleMode};
use crate::scene::{EditList, Scene, SceneError};
use std::time::Instant;

/// Why a submitted edit was not taken; nothing changed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Refused {
    /// It does not fit its object (an index out of range, a NaN, a degree past the limit…).
    #[error("{0}")]
    Invalid(#[from] EditError),
    /// Its result would not fit the memory budget (the estimate, one line).
    #[error("{0}")]
    OverBudget(String),
}

/// Why an edits file was not applied: an edit in it (with its position and object), or the
/// memory budget.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ListRefused {
    #[error("{0}")]
    Edit(SceneError),
    #[error("{0}")]
    OverBudget(String),
}

/// How an editor pre-evaluates and what it may take.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EditorOptions {
    /// What is kept per sample (the renderer's shading data, or derivatives for `sample`).
    pub mode: SampleMode,
    /// What the command does with the samples besides keeping them (GPU mirrors, JSON text).
    pub uses: Uses,
    /// What pre-evaluation may take; edits that would grow past it are refused.
    pub budget: MemoryBudget,
}

/// The document with its undo history and this frame's queued edits.
pub struct Editor {
    doc: Document,
    undo: UndoStack,
    pending: Vec<Edit>,
    /// What was applied and not yet handed out (structural edits apply when submitted).
    applied: Applied,
    options: EditorOptions,
    /// Merge a frame's edits per target before applying them (off: apply each as it came).
    pub merge: bool,
    /// What tools without pre-evaluation do on an edit: re-sample every edited object from
    /// scratch and rewrite all of it (`prespline bench --naive`).
    pub naive: bool,
}

impl Editor {
    /// Pre-evaluates `scene` after checking that it fits the budget (one line naming the
    /// object otherwise).
    pub fn new(scene: &Scene, options: EditorOptions) -> Result<Self, String> {
        scene.check_budget(options.mode, options.uses, &options.budget)?;
        Ok(Self {
            doc: Document::with_mode(scene, options.mode),
            undo: UndoStack::default(),
            pending: Vec::new(),
            applied: Applied::default(),
            options,
            merge: true,
            naive: false,
        })
    }

    #[must_use]
    pub fn doc(&self) -> &Document {
        &self.doc
    }

    #[must_use]
    pub fn options(&self) -> &EditorOptions {
        &self.options
    }

    /// The current scene (what a save writes), with every queued edit applied first.
    pub fn to_scene(&mut self) -> Scene {
        self.flush();
        self.doc.to_scene()
    }

    /// What pre-evaluation may take from now on.
    pub fn set_budget(&mut self, budget: MemoryBudget) {
        self.options.budget = budget;
    }

    /// Opens an undo step: the edits submitted until [`Editor::end`] undo as one.
    pub fn begin(&mut self, label: &str) {
        self.undo.begin(label);
    }

    pub fn end(&mut self) {
        self.undo.end();
    }

    /// Undo steps done and undone.
    #[must_use]
    pub fn undo_depth(&self) -> (usize, usize) {
        self.undo.depth()
    }

    /// Submits one edit: validated against the object it names, held to the memory budget
    /// when it grows the object, recorded for undo, and queued for this frame. A structural
    /// edit is prepared once (the refined model) and applied at once, after what was queued
    /// before it: undo must capture the model each edit sees, and the edits after a refinement
    /// address the refined net. An error is one line and changes nothing.
    pub fn submit(&mut self, edit: Edit) -> Result<(), Refused> {
        let Some(o) = self.doc.objects.get(edit.object) else {
            return Err(Refused::Invalid(EditError::new(
                "object",
                format!("there is no object {}", edit.object),
            )));
        };
        if !edit.edit.is_structural() {
            edit.edit.validate(o.sampled.model())?;
            self.undo.record(&self.doc, &edit);
            self.pending.push(edit);
            return Ok(());
        }
        self.flush();
        if let Some(b) = edit.edit.builds() {
            self.options
                .budget
                .check_build(&b.what, b.bytes)
                .map_err(|e| Refused::Invalid(EditError::new(b.field, e)))?;
            self.check_build_peak(edit.object, &b)?;
        }
        let model = self.doc.objects[edit.object].sampled.model();
        let result = edit.edit.prepare(model)?;
        let grown = match &result {
            Some(after) => after.kind().extent(),
            // Put back in place (one ERBS local): grown as applying it grows it.
            None => {
                let mut grown = model.to_model();
                grown.apply(&edit.edit)?;
                grown.kind().extent()
            }
        };
        let mut extents = self.extents();
        extents[edit.object].1 = grown;
        let o = &self.options;
        check_extents(&extents, o.mode, o.uses, &o.budget).map_err(Refused::OverBudget)?;
        self.undo.record(&self.doc, &edit);
        self.apply_now(&edit, result);
        Ok(())
    }

    /// Holds an edit that builds from a count to the budget before it builds anything, at its
    /// peak: the scene with the grown object, the object it replaces (alive until the new one
    /// is in place) and the prepared structure being handed to the object's sampler (one more
    /// copy of what it builds, [`Build::bytes`]); the grown scene is extrapolated from the same
    /// edit with two small counts ([`Build::proxies`]), which cost next to nothing. A proxy that
    /// cannot be prepared leaves the check to the real edit (its own error, or the check of
    /// the extents it leaves).
    fn check_build_peak(&self, object: usize, b: &Build) -> Result<(), Refused> {
        let model = self.doc.objects[object].sampled.model();
        let o = &self.options;
        let unlimited = MemoryBudget::from_flag(Some(u64::MAX));
        let mut points = Vec::with_capacity(b.proxies.len());
        for (locals, proxy) in &b.proxies {
            let Ok(Some(after)) = proxy.prepare(model) else {
                return Ok(());
            };
            let mut extents = self.extents();
            let old = std::mem::replace(&mut extents[object].1, after.kind().extent());
            extents.push((extents[object].0, old));
            let Ok(bytes) = check_extents(&extents, o.mode, o.uses, &unlimited) else {
                return Ok(());
            };
            points.push((*locals as f64, bytes as f64));
        }
        let [(n0, b0), (n1, b1)] = points[..] else {
            return Ok(());
        };
        if n1 <= n0 || b.locals as f64 <= n1 {
            return Ok(());
        }
        let grown = b1 + ((b1 - b0) / (n1 - n0)).max(0.0) * (b.locals as f64 - n1);
        let need = grown + b.bytes as f64;
        o.budget
            .check_build(
                format_args!("{} (with the scene and the object they replace)", b.what),
                need as u128,
            )
            .map_err(|e| Refused::Invalid(EditError::new(b.field, e)))
    }

    /// Submits every edit of an edits file in order, each parsed against its object as the
    /// edits before it leave it, and applies them.
    pub fn submit_list(&mut self, list: &EditList) -> Result<(), ListRefused> {
        for k in 0..list.len() {
            let doc = &self.doc;
            let (edit, at) = list
                .edit(k, |name| {
                    let i = doc.objects.iter().position(|o| o.name == name)?;
                    Some((i, doc.objects[i].sampled.model()))
                })
                .map_err(ListRefused::Edit)?;
            self.submit(edit).map_err(|r| match r {
                Refused::Invalid(e) => ListRefused::Edit(at.err(e.field, e.message)),
                Refused::OverBudget(m) => ListRefused::OverBudget(m),
            })?;
            // The next edit is parsed against the model this one leaves.
            self.flush();
        }
        Ok(())
    }

    /// Applies the queued edits (merged per target) through the delta path and hands out
    /// everything applied since the last call, structural edits included.
    pub fn apply_pending(&mut self) -> Applied {
        self.flush();
        std::mem::take(&mut self.applied)
    }

    /// Applies the queued edits now (so the document shows them), keeping the report for the
    /// next [`Editor::apply_pending`].
    pub fn apply_queued(&mut self) {
        self.flush();
    }

    /// Applies the queued edits into the held report.
    fn flush(&mut self) {
        if self.pending.is_empty() {
            return;
        }
        let start = Instant::now();
        // One edit per frame (a drag) is the common case: nothing to merge.
        let edits = if self.merge && self.pending.len() > 1 {
            let merged = merge_edits(&self.pending);
            self.pending.clear();
            merged
        } else {
            std::mem::take(&mut self.pending)
        };
        let mut report = Applied {
            edits: edits.len(),
            ..Applied::default()
        };
        let mut edited = Vec::new();
        for e in &edits {
            // Validated when submitted; a stale edit (an undo racing a refinement) is dropped
            // by the sampler's own check rather than reaching the kernels.
            self.apply_one(e, None, &mut report, &mut edited);
        }
        self.finish(report, &edited, start);
    }

    /// Applies one structural edit now with the model its preparation computed (`result`),
    /// into the held report.
    fn apply_now(&mut self, edit: &Edit, result: Option<Model>) {
        let start = Instant::now();
        let mut report = Applied {
            edits: 1,
            ..Applied::default()
        };
        let mut edited = Vec::new();
        self.apply_one(edit, result, &mut report, &mut edited);
        self.finish(report, &edited, start);
    }

    /// Applies one edit through its object's delta path and records what it rewrote; a naive
    /// editor only notes the object in `edited`, to re-sample it whole.
    fn apply_one(
        &mut self,
        e: &Edit,
        result: Option<Model>,
        report: &mut Applied,
        edited: &mut Vec<usize>,
    ) {
        let o = &mut self.doc.objects[e.object];
        let Ok(region) = o.sampled.apply_prepared(&e.edit, result) else {
            return;
        };
        if self.naive {
            if !edited.contains(&e.object) {
                edited.push(e.object);
            }
            return;
        }
        let controls = o.controls.update(o.sampled.model(), e.edit.target());
        report.record(e.object, region, controls);
    }

    /// Re-samples the `edited` objects of a naive editor whole, and keeps the report.
    fn finish(&mut self, mut report: Applied, edited: &[usize], start: Instant) {
        for &i in edited {
            let o = &mut self.doc.objects[i];
            let region = o.sampled.rebuild_all();
            let controls = o.controls.refresh(o.sampled.model());
            report.record(i, region, controls);
        }
        report.micros = start.elapsed().as_secs_f64() * 1e6;
        self.applied.extend(report);
    }

    /// The memory budget's estimate of the document as it stands, in bytes (what
    /// `render --memory-report` sets against the resident size).
    #[must_use]
    pub fn estimated_bytes(&self) -> u64 {
        let unlimited = MemoryBudget::from_flag(Some(u64::MAX));
        let o = &self.options;
        check_extents(&self.extents(), o.mode, o.uses, &unlimited).unwrap_or(u64::MAX)
    }

    /// Every object's name and budget extent, read from the models in place.
    fn extents(&self) -> Vec<(&str, Extent)> {
        self.doc
            .objects
            .iter()
            .map(|o| (o.name.as_str(), o.sampled.model().kind().extent()))
            .collect()
    }

    /// Undoes the last step (exact prior values); its label, or `None` with nothing to undo.
    pub fn undo(&mut self) -> Option<String> {
        let (label, edits) = self.undo.undo()?;
        self.pending.extend(edits);
        self.flush();
        Some(label)
    }

    /// Redoes the last undone step; its label, or `None`.
    pub fn redo(&mut self) -> Option<String> {
        let (label, edits) = self.undo.redo()?;
        self.pending.extend(edits);
        self.flush();
        Some(label)
    }

    /// Drops the open step and puts back what it changed (a cancelled gesture).
    pub fn cancel_step(&mut self) -> Option<UndoStep> {
        let step = self.undo.discard()?;
        // Exact prior values: queued after any pending increments of this gesture.
        self.pending.extend(step.restore.iter().rev().cloned());
        Some(step)
    }

    /// Samples every surface in `mode` (a curvature map needs second partials): held to the
    /// budget first; every sample of a re-sampled surface is reported rewritten.
    pub fn set_surface_mode(&mut self, mode: SampleMode) -> Result<(), String> {
        self.flush();
        if mode == SampleMode::Analysis && self.options.mode != SampleMode::Analysis {
            check_extents(
                &self.extents(),
                mode,
                self.options.uses,
                &self.options.budget,
            )?;
        }
        self.options.mode = mode;
        for i in self.doc.set_surface_mode(mode) {
            let [rows, cols] = self.doc.objects[i].sampled.grid().dims;
            self.applied.record(
                i,
                DirtyRegion::surface(0..rows, 0..cols),
                super::applied::ControlsChange::Unchanged,
            );
        }
        Ok(())
    }

    /// The document, for a command that is done editing.
    #[must_use]
    pub fn into_document(mut self) -> Document {
        self.flush();
        self.doc
    }

    /// Every object sampled from scratch from its current model, as a fresh document would be
    /// (the `sample --full` reference path).
    pub fn resample_all(&mut self) {
        self.flush();
        let mode = self.options.mode;
        for (i, o) in self.doc.objects.iter_mut().enumerate() {
            *o = super::document::DocObject::new(&o.to_scene_object(), mode);
            let [rows, cols] = o.sampled.grid().dims;
            self.applied.record(
                i,
                DirtyRegion::surface(0..rows, 0..cols),
                super::applied::ControlsChange::Resized,
            );
        }
    }

    /// Exact re-evaluation of everything edited since the last rebuild, in every object.
    pub fn rebuild_touched(&mut self) {
        self.flush();
        for (i, o) in self.doc.objects.iter_mut().enumerate() {
            let region = o.sampled.rebuild_touched();
            if !region.is_empty() {
                self.applied
                    .record(i, region, super::applied::ControlsChange::Unchanged);
            }
        }
    }
}
