//! The sampler trait every object kind implements, drift control on top of it, and a
//! pre-evaluated object of any kind.

use super::chain_curve::ChainCurveSampler;
use super::dirty::DirtyRegion;
use super::erbs_curve::ErbsCurveSampler;
use super::erbs_surface::ErbsSurfaceSampler;
use super::grid::{PartialSet, SampleGrid};
use super::spline_curve::SplineCurveSampler;
use super::spline_surface::SplineSurfaceSampler;
use crate::model::{
    BezierSplineEdit, CatmullRomEdit, EditError, KindEdit, Model, ModelRef, ObjectEdit,
    edit_kind_mismatch,
};

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
    type Edit: KindEdit;

    /// The current model (after every applied edit).
    fn model(&self) -> &<Self::Edit as KindEdit>::Model;

    fn grid(&self) -> &SampleGrid;

    /// Sample parameters per direction.
    fn params(&self) -> Vec<&[f64]>;

    /// Applies a validated edit through the delta path (the model changes with it) and returns
    /// the samples it rewrote.
    fn apply(&mut self, edit: &Self::Edit) -> DirtyRegion;

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
    interval: Option<usize>,
    edits_since_rebuild: usize,
    touched: DirtyRegion,
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
    type Edit = S::Edit;

    fn model(&self) -> &<S::Edit as KindEdit>::Model {
        self.sampler.model()
    }

    fn grid(&self) -> &SampleGrid {
        self.sampler.grid()
    }

    fn params(&self) -> Vec<&[f64]> {
        self.sampler.params()
    }

    fn apply(&mut self, edit: &S::Edit) -> DirtyRegion {
        let region = self.sampler.apply(edit);
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

/// Applies `edit` if it is of the sampler's kind. Edits arrive validated; checking again costs
/// a few comparisons and keeps a stale index (say, after an undone refinement) from ever
/// reaching the kernels.
fn apply_kind<S: Sampler>(
    s: &mut Tracked<S>,
    edit: &ObjectEdit,
    model_type: &str,
) -> Result<DirtyRegion, EditError> {
    let e = S::Edit::from_object(edit).ok_or_else(|| edit_kind_mismatch(edit, model_type))?;
    e.validate(s.model())?;
    Ok(s.apply(e))
}

/// A scene object with pre-evaluation data and its canonical sample grid.
#[derive(Debug, Clone)]
pub enum SampledObject {
    Curve(Tracked<SplineCurveSampler>),
    Surface(Tracked<SplineSurfaceSampler>),
    ErbsCurve(Tracked<ErbsCurveSampler>),
    ErbsSurface(Tracked<ErbsSurfaceSampler>),
    CatmullRom(Tracked<ChainCurveSampler<CatmullRomEdit>>),
    BezierSpline(Tracked<ChainCurveSampler<BezierSplineEdit>>),
}

/// Runs `$body` with `$s` bound to the kind's tracked sampler.
macro_rules! each_sampler {
    ($e:expr, $s:ident => $body:expr) => {
        match $e {
            SampledObject::Curve($s) => $body,
            SampledObject::Surface($s) => $body,
            SampledObject::ErbsCurve($s) => $body,
            SampledObject::ErbsSurface($s) => $body,
            SampledObject::CatmullRom($s) => $body,
            SampledObject::BezierSpline($s) => $body,
        }
    };
}

impl SampledObject {
    /// Pre-evaluates and fully samples `model`.
    pub fn new(model: &Model, mode: SampleMode) -> Self {
        let (order, set, normals) = mode.layout();
        match model {
            Model::Curve(m) => Self::Curve(Tracked::new(SplineCurveSampler::new(m.clone(), order))),
            Model::Surface(m) => Self::Surface(Tracked::new(SplineSurfaceSampler::new(
                m.clone(),
                set,
                normals,
            ))),
            Model::ErbsCurve(m) => {
                Self::ErbsCurve(Tracked::new(ErbsCurveSampler::new(m.clone(), order)))
            }
            Model::ErbsSurface(m) => Self::ErbsSurface(Tracked::new(ErbsSurfaceSampler::new(
                m.clone(),
                set,
                normals,
            ))),
            Model::CatmullRom(m) => {
                Self::CatmullRom(Tracked::new(ChainCurveSampler::new(m.clone(), order)))
            }
            Model::BezierSpline(m) => {
                Self::BezierSpline(Tracked::new(ChainCurveSampler::new(m.clone(), order)))
            }
        }
    }

    /// The sample mode this object was built with.
    pub fn mode(&self) -> SampleMode {
        let grid = self.grid();
        match (&grid.partials, grid.normals.is_some()) {
            (PartialSet::Curve(1), _) | (PartialSet::Shading, true) => SampleMode::Render,
            (PartialSet::Curvature, true) => SampleMode::Analysis,
            (p, _) => SampleMode::Derivatives(p.max_order()),
        }
    }

    /// `None` disables the periodic exact rebuild (to measure raw drift in tests).
    pub fn set_rebuild_interval(&mut self, every: Option<usize>) {
        each_sampler!(self, s => s.interval = every)
    }

    /// The current model by reference (no copy).
    pub fn model(&self) -> ModelRef<'_> {
        match self {
            SampledObject::Curve(s) => ModelRef::Curve(s.model()),
            SampledObject::Surface(s) => ModelRef::Surface(s.model()),
            SampledObject::ErbsCurve(s) => ModelRef::ErbsCurve(s.model()),
            SampledObject::ErbsSurface(s) => ModelRef::ErbsSurface(s.model()),
            SampledObject::CatmullRom(s) => ModelRef::CatmullRom(s.model()),
            SampledObject::BezierSpline(s) => ModelRef::BezierSpline(s.model()),
        }
    }

    pub fn type_name(&self) -> &'static str {
        self.model().type_name()
    }

    pub fn grid(&self) -> &SampleGrid {
        each_sampler!(self, s => s.grid())
    }

    /// Sample parameters per direction.
    pub fn params(&self) -> Vec<&[f64]> {
        each_sampler!(self, s => s.params())
    }

    /// Applies an edit through the delta path; returns the samples it touched (including any
    /// periodic rebuild's). An edit of another kind, or one that does not fit the model, is an
    /// error and changes nothing.
    pub fn apply(&mut self, edit: &ObjectEdit) -> Result<DirtyRegion, EditError> {
        if let ObjectEdit::Replace(model) = edit {
            edit.validate(self.model())?;
            let interval = each_sampler!(self, s => s.interval);
            *self = SampledObject::new(model, self.mode());
            self.set_rebuild_interval(interval);
            let [rows, _] = self.grid().dims;
            return Ok(DirtyRegion::curve(0..rows).union(self.full_region()));
        }
        let name = self.type_name();
        each_sampler!(self, s => apply_kind(s, edit, name))
    }

    /// Every sample.
    fn full_region(&self) -> DirtyRegion {
        let [rows, cols] = self.grid().dims;
        DirtyRegion::surface(0..rows, 0..cols)
    }

    /// Exact re-evaluation of everything touched since the last rebuild (drift reset).
    pub fn rebuild_touched(&mut self) -> DirtyRegion {
        each_sampler!(self, s => s.rebuild_touched())
    }

    /// Full sampling from the pre-evaluated data, as the constructor does.
    pub fn rebuild_all(&mut self) -> DirtyRegion {
        each_sampler!(self, s => s.full())
    }

    /// Samples in the grid (rows × cols).
    pub fn sample_count(&self) -> usize {
        let [a, b] = self.grid().dims;
        a * b
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{BSplineCurve, KnotVector, TensorSurface};
    use crate::model::{CurveEdit, CurveModel, PointEdit, SplineForm, SurfaceEdit, SurfaceModel};
    use glam::DVec3;

    /// A mirror that copies exactly the rows each edit reports, as the GPU mirrors do, must equal
    /// the grid after every edit.
    fn mirror_follows(obj: &mut SampledObject, edits: &[ObjectEdit]) {
        let stride = obj.grid().stride();
        let cols = obj.grid().dims[1];
        let mut mirror = obj.grid().data.clone();
        let bits = |v: &[DVec3]| -> Vec<[u64; 3]> {
            v.iter().map(|p| p.to_array().map(f64::to_bits)).collect()
        };
        for (k, e) in edits.iter().enumerate() {
            let region = obj.apply(e).unwrap();
            let rows = region.rows.start * cols * stride..region.rows.end * cols * stride;
            mirror[rows.clone()].copy_from_slice(&obj.grid().data[rows]);
            assert!(
                bits(&mirror) == bits(&obj.grid().data),
                "after edit {k}, a mirror fed the reported regions differs from the grid"
            );
        }
    }

    fn wiggle(k: usize) -> DVec3 {
        let x = k as f64;
        DVec3::new((x * 0.7).sin(), (x * 1.3).cos(), (x * 0.37).sin()) * 0.123_456_7
    }

    #[test]
    fn apply_reports_what_the_periodic_rebuild_rewrote() {
        // Edits at both ends of a curve and a surface; every 3rd edit rebuilds everything touched
        // since the last rebuild, which rewrites the other end's samples with exact values.
        let n = 12;
        let pts = (0..n).map(|i| DVec3::new(i as f64, 0.0, 0.0)).collect();
        let knots = KnotVector::clamped_uniform(3, n, 0.0, 1.0).into_vec();
        let c = BSplineCurve::new(3, knots.clone(), pts, None).unwrap();
        let m = CurveModel::new(SplineForm::BSpline, c, 200).unwrap();
        for mode in [SampleMode::Render, SampleMode::Derivatives(2)] {
            let mut obj = SampledObject::new(&Model::Curve(m.clone()), mode);
            obj.set_rebuild_interval(Some(3));
            let edits: Vec<ObjectEdit> = (0..40)
                .map(|k| {
                    let point = if k % 2 == 0 { 1 } else { n - 2 };
                    let delta = wiggle(k);
                    CurveEdit::Point(PointEdit::Move { point, delta }).into_object()
                })
                .collect();
            mirror_follows(&mut obj, &edits);
        }
        let pts = (0..n * n)
            .map(|k| DVec3::new((k / n) as f64, (k % n) as f64, 0.0))
            .collect();
        let knots2 = KnotVector::clamped_uniform(2, n, 0.0, 1.0).into_vec();
        let s = TensorSurface::bspline([3, 2], [knots, knots2], [n, n], pts, None).unwrap();
        let m = SurfaceModel::new(SplineForm::BSpline, s, [40, 30]).unwrap();
        for mode in [SampleMode::Render, SampleMode::Derivatives(1)] {
            let mut obj = SampledObject::new(&Model::Surface(m.clone()), mode);
            obj.set_rebuild_interval(Some(3));
            let edits: Vec<ObjectEdit> = (0..40)
                .map(|k| {
                    let point = if k % 2 == 0 { [1, 1] } else { [n - 2, n - 2] };
                    let delta = wiggle(k);
                    SurfaceEdit::Point(PointEdit::Move { point, delta }).into_object()
                })
                .collect();
            mirror_follows(&mut obj, &edits);
        }
    }
}
