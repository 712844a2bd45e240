//! What an object kind is: one trait, implemented once per kind in the kind's own module, and
//! the object-safe views of it ([`DynKind`], [`DynEdit`], [`DynSampler`]) through which the
//! registered kinds ([`super::registry`]) are reached without a `match` in every layer.

use super::controls::{ControlDisplay, Grip};
use super::edit::{EditError, KindEdit, Target};
use super::registry::{Model, ModelRef, ObjectEdit, SampledObject};
use super::{Index2, LocalPath};
use crate::format::{At, SceneError};
use crate::sampling::budget::Extent;
use crate::sampling::{DirtyRegion, PartialSet, SampleGrid, SampleMode, Sampler, Tracked};
use glam::DVec3;
use serde_json::{Map, Value};
use std::fmt::Debug;

/// An object kind: its model type (this trait's implementor), its edits and its sampler.
pub trait Kind: Clone + Debug + PartialEq + Sized + 'static {
    type Edit: KindEdit<Model = Self>;
    type Sampler: Sampler<Model = Self, Edit = Self::Edit> + Support + Clone + Debug;

    /// Whether the samples form a surface grid (else a curve).
    const SURFACE: bool;

    /// The kind's name in messages ("curve", "ERBS surface", …).
    const LABEL: &'static str;

    /// The scene-file `type` names this kind reads (docs/scene-format.md).
    const TYPES: &'static [&'static str];

    /// The scene-file `type` of this model.
    fn type_name(&self) -> &'static str;

    /// Reads an object of type `ty` (one of [`Kind::TYPES`]) from its fields; `common` names
    /// the fields every object has, which the scene reads.
    fn read(
        ty: &str,
        at: &At,
        obj: &Map<String, Value>,
        common: &[&'static str],
    ) -> Result<Self, SceneError>;

    /// Writes the kind's own fields, each as `, "name": value` (the scene writes the name,
    /// type, samples and colour).
    fn write(&self, out: &mut String);

    /// Reads an edit of this object (docs/scene-format.md, edits files).
    fn read_edit(&self, at: &At, obj: &Map<String, Value>) -> Result<Self::Edit, SceneError>;

    /// Sample grid dimensions: [m, 1] for curves, [mu, mv] for surfaces.
    fn sample_dims(&self) -> [usize; 2];

    /// Parameter domain per direction (one entry for curves).
    fn domain(&self) -> Vec<(f64, f64)>;

    /// Pre-evaluates and fully samples the model.
    fn sampler(&self, mode: SampleMode) -> Self::Sampler;

    /// The equivalent `bspline_curve` of a kind that is a chain of Bézier segments.
    fn to_bspline_curve(&self) -> Option<Model> {
        None
    }

    /// Exact evaluation by the geometry layer's own evaluators (no pre-evaluation), for the
    /// reference path: at `uv` ([u, 0] on curves) the derivatives up to `order` — curves write
    /// C, C', …; surfaces write the partials `list` names, (a, b) = ∂^(a+b)/∂u^a∂v^b.
    fn derivatives_at(
        &self,
        uv: [f64; 2],
        order: usize,
        list: &[(usize, usize)],
        out: &mut [DVec3],
    );

    /// The parameters where a chain's Bézier segments meet, and whether the chain closes on
    /// itself (its seam is a junction too), for kinds built of segments.
    fn junctions(&self) -> Option<(Vec<f64>, bool)> {
        None
    }

    /// What the memory budget needs to know of the object (samples, degrees, rational, ERBS
    /// locals).
    fn extent(&self) -> Extent;

    /// What is drawn and picked besides the samples: the control polygon or net, or the
    /// polynomial locals of an ERBS object.
    fn controls(&self) -> ControlDisplay;

    /// One point of the control polygon or net, so a drag rewrites one display vertex; `None`
    /// where the kind's display is rebuilt instead.
    fn control_point(&self, _point: Index2) -> Option<DVec3> {
        None
    }

    /// The display of the polynomial locals at or below `local` (kinds with locals).
    fn local_controls(&self, _local: LocalPath<Index2>) -> Option<ControlDisplay> {
        None
    }

    /// The edit that moves a grip by `delta` (`None` for a grip the model does not have).
    fn move_edit(&self, grip: Grip, delta: DVec3) -> Option<Self::Edit>;

    /// The weight of a control point (1 for a polynomial object of a rational kind), `None`
    /// for grips without one.
    fn weight(&self, _grip: Grip) -> Option<f64> {
        None
    }

    /// The edit setting a grip's weight, or why the kind has none.
    fn weight_edit(&self, _grip: Grip, _weight: f64) -> Result<Self::Edit, String> {
        Err(format!(
            "the points of an {} have no weights",
            self.type_name()
        ))
    }
}

/// A [`Kind`] behind a reference, for code that holds a model of any kind.
pub trait DynKind {
    fn type_name(&self) -> &'static str;
    fn is_surface(&self) -> bool;
    fn sample_dims(&self) -> [usize; 2];
    fn domain(&self) -> Vec<(f64, f64)>;
    fn to_model(&self) -> Model;
    fn sampled(&self, mode: SampleMode) -> SampledObject;
    fn to_bspline_curve(&self) -> Option<Model>;
    /// Applies an edit of this kind to the model (another kind's is an error).
    fn apply(&mut self, edit: &ObjectEdit) -> Result<(), EditError>;
    /// Checks an edit of this kind; a structural edit hands back the model it leaves
    /// ([`KindEdit::prepare`]).
    fn prepare(&self, edit: &ObjectEdit) -> Result<Option<Model>, EditError>;
    fn inverse(&self, edit: &ObjectEdit) -> Result<ObjectEdit, EditError>;
    fn controls(&self) -> ControlDisplay;
    fn extent(&self) -> Extent;
    fn write(&self, out: &mut String);
    fn read_edit(&self, at: &At, obj: &Map<String, Value>) -> Result<ObjectEdit, SceneError>;
    fn derivatives_at(
        &self,
        uv: [f64; 2],
        order: usize,
        list: &[(usize, usize)],
        out: &mut [DVec3],
    );
    fn junctions(&self) -> Option<(Vec<f64>, bool)>;
    fn control_point(&self, point: Index2) -> Option<DVec3>;
    fn local_controls(&self, local: LocalPath<Index2>) -> Option<ControlDisplay>;
    fn move_edit(&self, grip: Grip, delta: DVec3) -> Option<ObjectEdit>;
    fn weight(&self, grip: Grip) -> Option<f64>;
    fn weight_edit(&self, grip: Grip, weight: f64) -> Result<ObjectEdit, String>;
}

/// The error for an edit paired with a model of another kind.
#[must_use]
pub fn edit_kind_mismatch(e: &ObjectEdit, model_type: &str) -> EditError {
    EditError::new(
        "object",
        format!("a {} edit does not apply to a {model_type}", e.kind_name()),
    )
}

impl<K> DynKind for K
where
    K: Kind,
    Model: From<K>,
    SampledObject: From<Tracked<K::Sampler>>,
{
    fn type_name(&self) -> &'static str {
        Kind::type_name(self)
    }

    fn is_surface(&self) -> bool {
        K::SURFACE
    }

    fn sample_dims(&self) -> [usize; 2] {
        Kind::sample_dims(self)
    }

    fn domain(&self) -> Vec<(f64, f64)> {
        Kind::domain(self)
    }

    fn to_model(&self) -> Model {
        Model::from(self.clone())
    }

    fn sampled(&self, mode: SampleMode) -> SampledObject {
        SampledObject::from(Tracked::new(self.sampler(mode)))
    }

    fn to_bspline_curve(&self) -> Option<Model> {
        Kind::to_bspline_curve(self)
    }

    fn apply(&mut self, edit: &ObjectEdit) -> Result<(), EditError> {
        let e = K::Edit::from_object(edit)
            .ok_or_else(|| edit_kind_mismatch(edit, Kind::type_name(self)))?;
        e.apply(self);
        Ok(())
    }

    fn prepare(&self, edit: &ObjectEdit) -> Result<Option<Model>, EditError> {
        let after = K::Edit::from_object(edit)
            .ok_or_else(|| edit_kind_mismatch(edit, Kind::type_name(self)))?
            .prepare(self)?;
        Ok(after.map(Model::from))
    }

    fn inverse(&self, edit: &ObjectEdit) -> Result<ObjectEdit, EditError> {
        let e = K::Edit::from_object(edit)
            .ok_or_else(|| edit_kind_mismatch(edit, Kind::type_name(self)))?;
        Ok(e.inverse(self).into_object())
    }

    fn controls(&self) -> ControlDisplay {
        Kind::controls(self)
    }

    fn extent(&self) -> Extent {
        Kind::extent(self)
    }

    fn write(&self, out: &mut String) {
        Kind::write(self, out);
    }

    fn read_edit(&self, at: &At, obj: &Map<String, Value>) -> Result<ObjectEdit, SceneError> {
        Kind::read_edit(self, at, obj).map(KindEdit::into_object)
    }

    fn derivatives_at(
        &self,
        uv: [f64; 2],
        order: usize,
        list: &[(usize, usize)],
        out: &mut [DVec3],
    ) {
        Kind::derivatives_at(self, uv, order, list, out);
    }

    fn junctions(&self) -> Option<(Vec<f64>, bool)> {
        Kind::junctions(self)
    }

    fn control_point(&self, point: Index2) -> Option<DVec3> {
        Kind::control_point(self, point)
    }

    fn local_controls(&self, local: LocalPath<Index2>) -> Option<ControlDisplay> {
        Kind::local_controls(self, local)
    }

    fn move_edit(&self, grip: Grip, delta: DVec3) -> Option<ObjectEdit> {
        Kind::move_edit(self, grip, delta).map(KindEdit::into_object)
    }

    fn weight(&self, grip: Grip) -> Option<f64> {
        Kind::weight(self, grip)
    }

    fn weight_edit(&self, grip: Grip, weight: f64) -> Result<ObjectEdit, String> {
        Kind::weight_edit(self, grip, weight).map(KindEdit::into_object)
    }
}

/// A [`KindEdit`] behind a reference.
pub trait DynEdit {
    /// The kind's name in messages.
    fn kind_label(&self) -> &'static str;
    fn target(&self) -> Target;
    /// This edit followed by `next` as one, when both act on one target and combine.
    fn merge(&self, next: &ObjectEdit) -> Option<ObjectEdit>;
}

impl<E> DynEdit for E
where
    E: KindEdit,
    E::Model: Kind,
{
    fn kind_label(&self) -> &'static str {
        <E::Model as Kind>::LABEL
    }

    fn target(&self) -> Target {
        KindEdit::target(self)
    }

    fn merge(&self, next: &ObjectEdit) -> Option<ObjectEdit> {
        let next = E::from_object(next)?;
        KindEdit::merge(self, next).map(KindEdit::into_object)
    }
}

/// A kind's tracked sampler behind a reference.
pub trait DynSampler {
    fn model(&self) -> ModelRef<'_>;
    fn grid(&self) -> &SampleGrid;
    fn params(&self) -> Vec<&[f64]>;
    fn interval(&self) -> Option<usize>;
    fn set_interval(&mut self, every: Option<usize>);
    /// Applies an edit of the sampler's kind through the delta path. `result` is the model
    /// the edit leaves where [`ObjectEdit::prepare`] computed it against this sampler's model
    /// (a structural edit), and is taken as it is. Without one, the edit is prepared here:
    /// edits arrive validated, and checking again costs a few comparisons and keeps a stale
    /// index (say, after an undone refinement) from ever reaching the kernels.
    fn apply(&mut self, edit: &ObjectEdit, result: Option<Model>)
    -> Result<DirtyRegion, EditError>;
    fn rebuild_touched(&mut self) -> DirtyRegion;
    fn full(&mut self) -> DirtyRegion;
    fn support(&self, target: Target) -> Vec<DirtyRegion>;
}

/// The samples whose values edits of a target can change, known before any is applied: I_k
/// (× I_l on surfaces) of a control point or its weight, an ERBS local's support at any depth,
/// the segments a chain point reaches; the whole grid for a structural target or an index the
/// object does not have. (A first weight that makes a polynomial object rational re-samples it
/// whole once: its values outside the support stay the shape's.) The renderer keeps this out
/// of its static layer for a gesture.
pub trait Support {
    fn support(&self, target: Target) -> Vec<DirtyRegion>;
}

impl<S: Support> Support for Tracked<S> {
    fn support(&self, target: Target) -> Vec<DirtyRegion> {
        self.inner().support(target)
    }
}

impl<S> DynSampler for Tracked<S>
where
    S: Sampler + Support,
    S::Edit: KindEdit<Model = S::Model>,
    S::Model: Kind<Edit = S::Edit> + TryFrom<Model, Error = Model>,
    for<'a> ModelRef<'a>: From<&'a S::Model>,
{
    fn model(&self) -> ModelRef<'_> {
        ModelRef::from(Sampler::model(self))
    }

    fn grid(&self) -> &SampleGrid {
        Sampler::grid(self)
    }

    fn params(&self) -> Vec<&[f64]> {
        Sampler::params(self)
    }

    fn interval(&self) -> Option<usize> {
        self.interval
    }

    fn set_interval(&mut self, every: Option<usize>) {
        self.interval = every;
    }

    fn apply(
        &mut self,
        edit: &ObjectEdit,
        result: Option<Model>,
    ) -> Result<DirtyRegion, EditError> {
        let model = Sampler::model(self);
        let e = <S::Edit as KindEdit>::from_object(edit)
            .ok_or_else(|| edit_kind_mismatch(edit, Kind::type_name(model)))?;
        let after = match result {
            Some(after) => Some(
                S::Model::try_from(after)
                    .map_err(|other| edit_kind_mismatch(edit, other.type_name()))?,
            ),
            None => e.prepare(model)?,
        };
        Ok(Sampler::apply_prepared(self, e, after))
    }

    fn rebuild_touched(&mut self) -> DirtyRegion {
        Tracked::rebuild_touched(self)
    }

    fn full(&mut self) -> DirtyRegion {
        Sampler::full(self)
    }

    fn support(&self, target: Target) -> Vec<DirtyRegion> {
        Support::support(self, target)
    }
}

/// What a sampler keeps per sample, read back from its grid.
pub(super) fn mode_of(grid: &SampleGrid) -> SampleMode {
    match (&grid.partials, grid.normals.is_some()) {
        (PartialSet::Curve(1), _) | (PartialSet::Shading, true) => SampleMode::Render,
        (PartialSet::Curvature, true) => SampleMode::Analysis,
        (p, _) => SampleMode::Derivatives(p.max_order()),
    }
}
