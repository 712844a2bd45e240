//! The editor floor: the document (objects with their samplers and control displays), undo and
//! redo, and the edit pipeline every change goes through.
//!
//! The route of an edit: the viewer turns a gesture into an [`Edit`](crate::model::Edit) (from
//! the document's handles), [`Editor::submit`] validates it, holds it to the memory budget and
//! records it for undo, [`Editor::apply_pending`] applies the frame's edits through each
//! object's sampler (the delta path) and returns one [`Applied`] report — the sample rows and
//! control vertices rewritten — which the GPU scene copies into its mirrors. Nothing below the
//! editor looks at an edit again.

pub mod applied;
pub mod document;
pub mod pipeline;
pub mod undo;

pub use crate::model::controls::{
    ControlDisplay, ControlLayout, Grip, LOCAL_CURVE_SAMPLES, LOCAL_PATCH_SAMPLES, LocalEntry,
};
pub use applied::{Applied, ControlsChange, ObjectChange};
pub use document::{DocObject, Document, Handle, TrimCoverage};
pub use pipeline::{Editor, EditorOptions, ListRefused, Refused};
