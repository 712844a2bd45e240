//! The CPU phases of a frame and a fixed per-phase container.

use serde::{Deserialize, Serialize};
use std::fmt;
use std::ops::{Index, IndexMut};

/// A CPU phase of a frame, in the order a frame normally runs them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Phase {
    /// Event handling or scripted input, turned into edits.
    Input,
    /// Applying edits to the sample grids: the CPU cost of an edit.
    Delta,
    /// Copying dirty ranges into the GPU mirror buffers.
    Upload,
    /// Command recording.
    Record,
    /// Queue submission.
    Submit,
    /// Present, including waits for the swapchain image and frame fence.
    Present,
}

impl Phase {
    pub const COUNT: usize = 6;
    pub const ALL: [Phase; Phase::COUNT] = [
        Phase::Input,
        Phase::Delta,
        Phase::Upload,
        Phase::Record,
        Phase::Submit,
        Phase::Present,
    ];

    /// Short lowercase name, as used in file columns and keys.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Phase::Input => "input",
            Phase::Delta => "delta",
            Phase::Upload => "upload",
            Phase::Record => "record",
            Phase::Submit => "submit",
            Phase::Present => "present",
        }
    }
}

impl Phase {
    /// What the phase measures, in a few words, for the footnotes of `summary.txt` and the
    /// plots.
    #[must_use]
    pub const fn meaning(self) -> &'static str {
        match self {
            Phase::Input => "events turned into edits",
            Phase::Delta => "edits applied to the samples",
            Phase::Upload => "dirty ranges copied to the GPU",
            Phase::Record => "command recording",
            Phase::Submit => "queue submission",
            Phase::Present => "wait for the swapchain image or frame slot (the GPU or rasteriser)",
        }
    }
}

/// The meaning of "other" (see [`FrameRecord::other_ms`](super::FrameRecord::other_ms)), next
/// to [`Phase::meaning`].
pub const OTHER_MEANING: &str = "frame time in no phase (idle or not instrumented)";
/// The meaning of the GPU time, for footnotes.
pub const GPU_MEANING: &str = "GPU execution time (timestamp queries)";

impl fmt::Display for Phase {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// One value per phase. Named fields (rather than an array) so that JSON has readable keys in
/// phase order; index it with a [`Phase`].
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct PhaseMap<T> {
    pub input: T,
    pub delta: T,
    pub upload: T,
    pub record: T,
    pub submit: T,
    pub present: T,
}

impl<T> PhaseMap<T> {
    pub fn from_fn(mut f: impl FnMut(Phase) -> T) -> Self {
        PhaseMap {
            input: f(Phase::Input),
            delta: f(Phase::Delta),
            upload: f(Phase::Upload),
            record: f(Phase::Record),
            submit: f(Phase::Submit),
            present: f(Phase::Present),
        }
    }

    /// `(phase, value)` in phase order.
    pub fn iter(&self) -> impl Iterator<Item = (Phase, &T)> {
        Phase::ALL.into_iter().map(move |p| (p, &self[p]))
    }
}

impl<T> Index<Phase> for PhaseMap<T> {
    type Output = T;
    fn index(&self, phase: Phase) -> &T {
        match phase {
            Phase::Input => &self.input,
            Phase::Delta => &self.delta,
            Phase::Upload => &self.upload,
            Phase::Record => &self.record,
            Phase::Submit => &self.submit,
            Phase::Present => &self.present,
        }
    }
}

impl<T> IndexMut<Phase> for PhaseMap<T> {
    fn index_mut(&mut self, phase: Phase) -> &mut T {
        match phase {
            Phase::Input => &mut self.input,
            Phase::Delta => &mut self.delta,
            Phase::Upload => &mut self.upload,
            Phase::Record => &mut self.record,
            Phase::Submit => &mut self.submit,
            Phase::Present => &mut self.present,
        }
    }
}
