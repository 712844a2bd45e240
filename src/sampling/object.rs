//! The sampler trait every object kind implements, and drift control on top of it.

use super::dirty::DirtyRegion;
use super::grid::{PartialSet, SampleGrid};

/// What to keep per sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SampleMode {
    /// Curves c^(0..=g); surfaces every ∂^{a+b}, a, b ≤ g (the `prespline sample` contract).
    Derivatives(usize),
    /// Curves c, c'; surfaces S, Su, Sv and unit normals (what the renderer draws).
    Render,
    /// As `Render`, and surfaces also Suu, Suv, Svv with Gaussian and mean curvature per
    /// sample (the analysis colour maps, updated by the delta path like the positions).
    Analysis,
}

impl SampleMode {
    /// Highest curve derivative order, the surface partial set, and whether surfaces keep unit
    /// normals.
    #[must_use]
    pub fn layout(self) -> (usize, PartialSet, bool) {
        match self {
            SampleMode::Derivatives(g) => (g, PartialSet::Square(g), false),
            SampleMode::Render => (1, PartialSet::Shading, true),
            SampleMode::Analysis => (1, PartialSet::Curvature, true),
        }
    }
}

/// The pre-evaluation of one object kind: its model, its samples, and the delta path for the
/// kind's edits.
pub trait Sampler {
    /// The kind's model.
    type Model;
    /// The kind's edits.
    type Edit;

    /// The current model (after every applied edit).
    fn model(&self) -> &Self::Model;

    fn grid(&self) -> &SampleGrid;

    /// Sample parameters per direction.
    fn params(&self) -> Vec<&[f64]>;

    /// Applies a validated edit through the delta path (the model changes with it) and returns
    /// the samples it rewrote.
    fn apply(&mut self, edit: &Self::Edit) -> DirtyRegion {
        self.apply_prepared(edit, None)
    }

    /// [`Sampler::apply`], taking `result`, the model the edit leaves, where checking the edit
    /// computed it (a structural edit's refinement), instead of computing it again.
    fn apply_prepared(&mut self, edit: &Self::Edit, result: Option<Self::Model>) -> DirtyRegion;

    /// Exact re-evaluation of (at least) `region` from the model, bounding the rounding the
    /// delta path accumulates; returns the samples it rewrote.
    fn rebuild(&mut self, region: DirtyRegion) -> DirtyRegion;

    /// Full sampling from the pre-evaluated data.
    fn full(&mut self) -> DirtyRegion;
}

/// Exact rebuild of the touched region after this many incremental edits, so rounding in the
/// delta path stays bounded however long a session runs (≈ µs per edit amortised).
pub const DEFAULT_REBUILD_INTERVAL: usize = 4096;

/// A sampler whose region touched by edits is rebuilt exactly every `interval` edits. The
/// region [`Sampler::apply`] returns includes the rebuild's, so mirrors never miss a sample.
#[derive(Debug, Clone)]
pub struct Tracked<S> {
    sampler: S,
    /// `None` disables the periodic rebuild (to measure raw drift in tests).
    pub interval: Option<usize>,
    edits_since_rebuild: usize,
    touched: DirtyRegion,
}

impl<S> Tracked<S> {
    /// The sampler inside, for queries that do not change it.
    #[must_use]
    pub fn inner(&self) -> &S {
        &self.sampler
    }
}

impl<S: Sampler> Tracked<S> {
    pub fn new(sampler: S) -> Self {
        Self {
            sampler,
            interval: Some(DEFAULT_REBUILD_INTERVAL),
            edits_since_rebuild: 0,
            touched: DirtyRegion::NOTHING,
        }
    }

    /// Exact re-evaluation of everything touched since the last rebuild (drift reset).
    pub fn rebuild_touched(&mut self) -> DirtyRegion {
        let touched = std::mem::replace(&mut self.touched, DirtyRegion::NOTHING);
        self.edits_since_rebuild = 0;
        if touched.is_empty() {
            return DirtyRegion::NOTHING;
        }
        self.sampler.rebuild(touched)
    }
}

impl<S: Sampler> Sampler for Tracked<S> {
    type Model = S::Model;
    type Edit = S::Edit;

    fn model(&self) -> &S::Model {
        self.sampler.model()
    }

    fn grid(&self) -> &SampleGrid {
        self.sampler.grid()
    }

    fn params(&self) -> Vec<&[f64]> {
        self.sampler.params()
    }

    fn apply_prepared(&mut self, edit: &S::Edit, result: Option<S::Model>) -> DirtyRegion {
        let region = self.sampler.apply_prepared(edit, result);
        self.touched =
            std::mem::replace(&mut self.touched, DirtyRegion::NOTHING).union(region.clone());
        self.edits_since_rebuild += 1;
        if self.interval.is_some_and(|n| self.edits_since_rebuild >= n) {
            region.union(self.rebuild_touched())
        } else {
            region
        }
    }

    fn rebuild(&mut self, region: DirtyRegion) -> DirtyRegion {
        self.sampler.rebuild(region)
    }

    fn full(&mut self) -> DirtyRegion {
        self.touched = DirtyRegion::NOTHING;
        self.edits_since_rebuild = 0;
        self.sampler.full()
    }
}
