//! What the sums over the kinds do ([`Model`], [`ModelRef`], [`ObjectEdit`],
//! [`SampledObject`]), written against the object-safe views of the registry, and the edit of
//! one object of a scene with the frame-merging of edits.

use super::edit::{EditError, Target};
use super::registry::{Model, ModelRef, ObjectEdit, SampledObject};
use crate::sampling::{DirtyRegion, PartialSet, SampleGrid, SampleMode};

impl Model {
    /// The scene-file `type` string.
    #[must_use]
    pub fn type_name(&self) -> &'static str {
        self.kind().type_name()
    }

    #[must_use]
    pub fn is_surface(&self) -> bool {
        self.kind().is_surface()
    }

    /// Sample grid dimensions: [m, 1] for curves, [mu, mv] for surfaces.
    #[must_use]
    pub fn sample_dims(&self) -> [usize; 2] {
        self.kind().sample_dims()
    }

    /// Parameter domain per direction (one entry for curves).
    #[must_use]
    pub fn domain(&self) -> Vec<(f64, f64)> {
        self.kind().domain()
    }

    /// Applies a validated edit of this object's kind (a kind mismatch is an error).
    pub fn apply(&mut self, edit: &ObjectEdit) -> Result<(), EditError> {
        self.apply_prepared(edit, None)
    }

    /// Applies an edit prepared against this model ([`ObjectEdit::prepare`]): the model it
    /// leaves where the preparation computed one, else the edit itself.
    pub fn apply_prepared(
        &mut self,
        edit: &ObjectEdit,
        result: Option<Model>,
    ) -> Result<(), EditError> {
        match (edit, result) {
            (_, Some(after)) => {
                *self = after;
                Ok(())
            }
            (ObjectEdit::Replace(new), None) => {
                *self = (**new).clone();
                Ok(())
            }
            (e, None) => self.kind_mut().apply(e),
        }
    }
}

impl<'a> ModelRef<'a> {
    #[must_use]
    pub fn type_name(&self) -> &'static str {
        self.kind().type_name()
    }

    #[must_use]
    pub fn is_surface(&self) -> bool {
        self.kind().is_surface()
    }

    #[must_use]
    pub fn sample_dims(&self) -> [usize; 2] {
        self.kind().sample_dims()
    }

    #[must_use]
    pub fn domain(&self) -> Vec<(f64, f64)> {
        self.kind().domain()
    }

    /// The equivalent B-spline curve (Catmull–Rom and Bézier splines: their Bézier chain), or
    /// `None` for kinds that are not such a chain.
    #[must_use]
    pub fn to_bspline_curve(&self) -> Option<Model> {
        self.kind().to_bspline_curve()
    }

    /// An owned copy.
    #[must_use]
    pub fn to_model(&self) -> Model {
        self.kind().to_model()
    }
}

impl ObjectEdit {
    #[must_use]
    pub fn target(&self) -> Target {
        self.as_dyn().map_or(Target::Structure, |e| e.target())
    }

    /// Whether the edit changes the object's structure (knots, degree, control counts).
    #[must_use]
    pub fn is_structural(&self) -> bool {
        self.target() == Target::Structure
    }

    /// The two as one edit, when they act on one target and combine.
    #[must_use]
    pub fn merge(&self, next: &ObjectEdit) -> Option<ObjectEdit> {
        self.as_dyn()?.merge(next)
    }

    /// What preparing the edit will allocate ([`KindEdit::builds`](super::KindEdit::builds)).
    #[must_use]
    pub fn builds(&self) -> Option<super::edit::Build> {
        self.as_dyn()?.builds()
    }

    /// Checks the edit against a model (of its own kind).
    pub fn validate(&self, model: ModelRef<'_>) -> Result<(), EditError> {
        match self {
            ObjectEdit::Replace(new) => check_replacement(new.as_ref().as_ref(), model),
            e => model.kind().prepare(e).map(|_| ()),
        }
    }

    /// Checks the edit against a model (of its own kind) and computes what applying it takes
    /// ([`KindEdit::prepare`](super::KindEdit::prepare)): the model a structural edit leaves,
    /// computed once, or `None` for an edit applied in place. The budget reads the result,
    /// and [`SampledObject::apply_prepared`] or [`Model::apply_prepared`] takes it.
    pub fn prepare(&self, model: ModelRef<'_>) -> Result<Option<Model>, EditError> {
        match self {
            ObjectEdit::Replace(new) => {
                check_replacement(new.as_ref().as_ref(), model)?;
                Ok(Some((**new).clone()))
            }
            e => model.kind().prepare(e),
        }
    }

    /// The edit restoring `model` as it is before this edit, or an error on a kind mismatch.
    pub fn inverse(&self, model: ModelRef<'_>) -> Result<ObjectEdit, EditError> {
        match self {
            ObjectEdit::Replace(_) => Ok(ObjectEdit::Replace(Box::new(model.to_model()))),
            e => model.kind().inverse(e),
        }
    }

    /// The kind's name for messages: "curve", "ERBS surface", "replacement"…
    #[must_use]
    pub fn kind_name(&self) -> &'static str {
        self.as_dyn().map_or("replacement", |e| e.kind_label())
    }
}

/// A replacement keeps the sample grid (curve or surface, and its counts), so samplers and GPU
/// mirrors keep their size.
fn check_replacement(new: ModelRef<'_>, old: ModelRef<'_>) -> Result<(), EditError> {
    if new.is_surface() == old.is_surface() && new.sample_dims() == old.sample_dims() {
        Ok(())
    } else {
        Err(EditError::new(
            "object",
            format!(
                "a {} with samples {:?} cannot replace a {} with samples {:?}",
                new.type_name(),
                new.sample_dims(),
                old.type_name(),
                old.sample_dims()
            ),
        ))
    }
}

impl SampledObject {
    /// Pre-evaluates and fully samples `model`.
    #[must_use]
    pub fn new(model: &Model, mode: SampleMode) -> Self {
        model.kind().sampled(mode)
    }

    /// The sample mode this object was built with.
    #[must_use]
    pub fn mode(&self) -> SampleMode {
        mode_of(self.grid())
    }

    /// `None` disables the periodic exact rebuild (to measure raw drift in tests).
    pub fn set_rebuild_interval(&mut self, every: Option<usize>) {
        self.sampler_mut().set_interval(every);
    }

    /// The current model by reference (no copy).
    #[must_use]
    pub fn model(&self) -> ModelRef<'_> {
        self.sampler().model()
    }

    #[must_use]
    pub fn type_name(&self) -> &'static str {
        self.model().type_name()
    }

    #[must_use]
    pub fn grid(&self) -> &SampleGrid {
        self.sampler().grid()
    }

    /// The samples whose values edits of `target` can change ([`crate::model::kind::Support`]).
    #[must_use]
    pub fn support(&self, target: Target) -> Vec<DirtyRegion> {
        self.sampler().support(target)
    }

    /// Sample parameters per direction.
    #[must_use]
    pub fn params(&self) -> Vec<&[f64]> {
        self.sampler().params()
    }

    /// Applies an edit through the delta path; returns the samples it touched (including any
    /// periodic rebuild's). An edit of another kind, or one that does not fit the model, is an
    /// error and changes nothing.
    pub fn apply(&mut self, edit: &ObjectEdit) -> Result<DirtyRegion, EditError> {
        self.apply_prepared(edit, None)
    }

    /// [`SampledObject::apply`] of an edit prepared against this object's model
    /// ([`ObjectEdit::prepare`]): `result`, the model a structural edit leaves, is taken as it
    /// is, not computed or checked again.
    pub fn apply_prepared(
        &mut self,
        edit: &ObjectEdit,
        result: Option<Model>,
    ) -> Result<DirtyRegion, EditError> {
        if let ObjectEdit::Replace(model) = edit {
            if result.is_none() {
                edit.validate(self.model())?;
            }
            let interval = self.sampler().interval();
            *self = SampledObject::new(result.as_ref().unwrap_or(model), self.mode());
            self.set_rebuild_interval(interval);
            let [rows, cols] = self.grid().dims;
            return Ok(DirtyRegion::surface(0..rows, 0..cols));
        }
        self.sampler_mut().apply(edit, result)
    }

    /// Exact re-evaluation of everything touched since the last rebuild (drift reset).
    pub fn rebuild_touched(&mut self) -> DirtyRegion {
        self.sampler_mut().rebuild_touched()
    }

    /// Full sampling from the pre-evaluated data, as the constructor does.
    pub fn rebuild_all(&mut self) -> DirtyRegion {
        self.sampler_mut().full()
    }

    /// Samples in the grid (rows × cols).
    #[must_use]
    pub fn sample_count(&self) -> usize {
        let [a, b] = self.grid().dims;
        a * b
    }
}

/// What a sampler keeps per sample, read back from its grid.
fn mode_of(grid: &SampleGrid) -> SampleMode {
    match (&grid.partials, grid.normals.is_some()) {
        (PartialSet::Curve(1), _) | (PartialSet::Shading, true) => SampleMode::Render,
        (PartialSet::Curvature, true) => SampleMode::Analysis,
        (p, _) => SampleMode::Derivatives(p.max_order()),
    }
}

/// One edit of one object (`object` indexes the scene's objects).
#[derive(Debug, Clone, PartialEq)]
pub struct Edit {
    pub object: usize,
    pub edit: ObjectEdit,
}

/// Merges the edits of one frame so each touched target is updated once: consecutive edits of
/// one target combine where their kind says so ([`KindEdit::merge`](super::KindEdit::merge)); edits on different
/// targets commute, so targets are applied in first-touch order while edits on one target keep
/// their order. A structural edit is a barrier: nothing moves across it (indices change there).
#[must_use]
pub fn merge_edits(edits: &[Edit]) -> Vec<Edit> {
    let mut out = Vec::with_capacity(edits.len());
    let mut groups: Vec<((usize, Target), Vec<Edit>)> = Vec::new();
    let flush = |groups: &mut Vec<((usize, Target), Vec<Edit>)>, out: &mut Vec<Edit>| {
        out.extend(groups.drain(..).flat_map(|(_, g)| g));
    };
    for e in edits {
        let target = e.edit.target();
        if target == Target::Structure {
            flush(&mut groups, &mut out);
            out.push(e.clone());
            continue;
        }
        let key = (e.object, target);
        let group = match groups.iter().position(|(k, _)| *k == key) {
            Some(i) => &mut groups[i].1,
            None => {
                groups.push((key, Vec::new()));
                &mut groups.last_mut().expect("just pushed").1
            }
        };
        let merged = group.last().and_then(|last| last.edit.merge(&e.edit));
        match (merged, group.last_mut()) {
            (Some(m), Some(last)) => last.edit = m,
            _ => group.push(e.clone()),
        }
    }
    flush(&mut groups, &mut out);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{BSplineCurve, KnotVector, TensorSurface};
    use crate::model::{
        CurveEdit, CurveModel, KindEdit, PointEdit, SplineForm, SurfaceEdit, SurfaceModel,
    };
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
