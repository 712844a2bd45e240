//! The registered kinds and the closed sums over them: [`Model`], [`ModelRef`], [`ObjectEdit`]
//! and [`SampledObject`], generated from the one list, `registered_kinds!`, by `kinds!`,
//! and the object-safe views of a kind ([`DynKind`], [`DynEdit`], [`DynSampler`]) through which
//! the sums reach the [`Kind`] implementation inside. What the sums do is written against those
//! views in model/object.rs: nothing there names a kind.

use super::controls::{ControlDisplay, Grip};
use super::edit::{EditError, IntoObject, KindEdit, Target};
use super::erbs::LocalPath;
use super::index::Index2;
use super::kind::{Kind, Support};
use crate::fields::{At, SceneError};
use crate::geom::surface::TensorSurface;
use crate::sampling::budget::Extent;
use crate::sampling::{DirtyRegion, SampleGrid, SampleMode, Sampler, Tracked};
use glam::DVec3;
use serde_json::{Map, Value};

/// The registered kinds: `Variant(model type)` each. A new kind is one folder under model/ and
/// one line here; `kinds!` generates the sums over these and everything reaches a kind
/// through its [`Kind`] implementation.
macro_rules! registered_kinds {
    ($then:ident) => {
        $then! {
            Curve(crate::model::CurveModel),
            Surface(crate::model::SurfaceModel),
            ErbsCurve(crate::model::ErbsCurveModel),
            ErbsSurface(crate::model::ErbsSurfaceModel),
            CatmullRom(crate::model::CatmullRomModel),
            BezierSpline(crate::model::BezierSplineModel),
        }
    };
}

/// Declares the kinds: `Variant(ModelType)` each, once. Generates the four sums over them and
/// the conversions into them; the rest of this module is written against the sums.
macro_rules! kinds {
    ($($v:ident($m:ty)),+ $(,)?) => {
        /// Every object kind with its geometry and sample counts.
        #[derive(Debug, Clone, PartialEq)]
        pub enum Model {
            $($v($m),)+
        }

        /// A borrowed [`Model`] (samplers own their kind's model; this is how others read it).
        #[derive(Debug, Clone, Copy, PartialEq)]
        pub enum ModelRef<'a> {
            $($v(&'a $m),)+
        }

        /// An edit of any kind.
        #[derive(Debug, Clone, PartialEq)]
        pub enum ObjectEdit {
            $($v(<$m as $crate::model::Kind>::Edit),)+
            /// Replace the whole model, possibly by one of another kind with the same sample
            /// counts (conversion of a Catmull–Rom or Bézier spline to its `bspline_curve`, and
            /// its undo).
            Replace(Box<Model>),
        }

        /// A scene object with pre-evaluation data and its canonical sample grid. Boxed: the
        /// kinds' samplers differ in size by hundreds of bytes, and a scene of many small
        /// objects should not pay the largest kind's size for each.
        #[derive(Debug, Clone)]
        pub enum SampledObject {
            $($v(Box<$crate::sampling::Tracked<<$m as $crate::model::Kind>::Sampler>>),)+
        }

        $(
            impl IntoObject for <$m as $crate::model::Kind>::Edit {
                type Object = ObjectEdit;

                fn wrap(self) -> ObjectEdit {
                    ObjectEdit::$v(self)
                }

                fn unwrap(e: &ObjectEdit) -> Option<&Self> {
                    match e {
                        ObjectEdit::$v(x) => Some(x),
                        _ => None,
                    }
                }
            }

            impl From<$m> for Model {
                fn from(m: $m) -> Self {
                    Model::$v(m)
                }
            }

            impl TryFrom<Model> for $m {
                /// The model of another kind, handed back.
                type Error = Model;

                fn try_from(m: Model) -> Result<Self, Model> {
                    match m {
                        Model::$v(m) => Ok(m),
                        other => Err(other),
                    }
                }
            }

            impl<'a> From<&'a $m> for ModelRef<'a> {
                fn from(m: &'a $m) -> Self {
                    ModelRef::$v(m)
                }
            }

            impl From<$crate::sampling::Tracked<<$m as $crate::model::Kind>::Sampler>>
                for SampledObject
            {
                fn from(s: $crate::sampling::Tracked<<$m as $crate::model::Kind>::Sampler>) -> Self {
                    SampledObject::$v(Box::new(s))
                }
            }
        )+

        impl Model {
            /// Reads an object of scene-file type `ty` through the kind that declares it;
            /// `None` for a type no kind declares.
            pub fn read(
                ty: &str,
                at: &$crate::fields::At,
                obj: &serde_json::Map<String, serde_json::Value>,
                ctx: &$crate::fields::ReadCtx<'_>,
            ) -> Option<Result<Model, $crate::fields::SceneError>> {
                use $crate::model::Kind;
                $(
                    if <$m>::TYPES.contains(&ty) {
                        return Some(<$m>::read(ty, at, obj, ctx).map(Model::$v));
                    }
                )+
                None
            }

            /// Every scene-file type, curves first, in registration order.
            #[must_use]
            pub fn types() -> Vec<&'static str> {
                use $crate::model::Kind;
                let mut curves = Vec::new();
                let mut surfaces = Vec::new();
                $(
                    if <$m>::SURFACE {
                        surfaces.extend_from_slice(<$m>::TYPES);
                    } else {
                        curves.extend_from_slice(<$m>::TYPES);
                    }
                )+
                curves.extend(surfaces);
                curves
            }

            /// Whether scene-file type `ty` is a surface kind (`None`: no kind reads it).
            #[must_use]
            pub fn type_is_surface(ty: &str) -> Option<bool> {
                use $crate::model::Kind;
                $(
                    if <$m>::TYPES.contains(&ty) {
                        return Some(<$m>::SURFACE);
                    }
                )+
                None
            }

            /// The model's kind.
            #[must_use]
            pub fn kind(&self) -> &dyn DynKind {
                match self {
                    $(Model::$v(m) => m,)+
                }
            }

            pub(super) fn kind_mut(&mut self) -> &mut dyn DynKind {
                match self {
                    $(Model::$v(m) => m,)+
                }
            }

            #[must_use]
            pub fn as_ref(&self) -> ModelRef<'_> {
                match self {
                    $(Model::$v(m) => ModelRef::$v(m),)+
                }
            }
        }

        impl<'a> ModelRef<'a> {
            /// The model's kind.
            #[must_use]
            pub fn kind(&self) -> &'a dyn DynKind {
                match *self {
                    $(ModelRef::$v(m) => m,)+
                }
            }
        }

        impl ObjectEdit {
            /// The kind's edit inside (`None` for a replacement).
            pub(super) fn as_dyn(&self) -> Option<&dyn DynEdit> {
                match self {
                    $(ObjectEdit::$v(e) => Some(e),)+
                    ObjectEdit::Replace(_) => None,
                }
            }
        }

        impl SampledObject {
            pub(super) fn sampler(&self) -> &dyn DynSampler {
                match self {
                    $(SampledObject::$v(s) => s.as_ref(),)+
                }
            }

            pub(super) fn sampler_mut(&mut self) -> &mut dyn DynSampler {
                match self {
                    $(SampledObject::$v(s) => s.as_mut(),)+
                }
            }
        }
    };
}

registered_kinds!(kinds);

/// A [`Kind`] behind a reference, for code that holds a model of any kind.
pub trait DynKind {
    fn type_name(&self) -> &'static str;
    fn is_surface(&self) -> bool;
    fn sample_dims(&self) -> [usize; 2];
    /// The tensor-product B-spline surface, where the kind is one ([`Kind::tensor`]).
    fn tensor(&self) -> Option<&TensorSurface>;
    /// The degree per direction, where the kind has one ([`Kind::degrees`]).
    fn degrees(&self) -> Vec<usize>;
    /// A rational kind's weights ([`Kind::weights`]).
    fn weights(&self) -> Option<&[f64]>;
    /// Where the geometry's pieces meet, per direction ([`Kind::breakpoints`]).
    fn breakpoints(&self) -> Vec<Vec<f64>>;
    /// The model with other sample counts ([`Kind::with_samples`]).
    fn with_samples(&self, samples: [usize; 2]) -> Result<Model, EditError>;
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
    K::Edit: IntoObject<Object = ObjectEdit>,
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

    fn breakpoints(&self) -> Vec<Vec<f64>> {
        Kind::breakpoints(self)
    }

    fn degrees(&self) -> Vec<usize> {
        Kind::degrees(self)
    }

    fn weights(&self) -> Option<&[f64]> {
        Kind::weights(self)
    }

    fn tensor(&self) -> Option<&TensorSurface> {
        Kind::tensor(self)
    }

    fn with_samples(&self, samples: [usize; 2]) -> Result<Model, EditError> {
        Kind::with_samples(self, samples).map(Model::from)
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
        Kind::to_bspline_curve(self).map(Model::Curve)
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
    /// What preparing it will allocate ([`KindEdit::builds`]).
    fn builds(&self) -> Option<super::edit::Build>;
}

impl<E> DynEdit for E
where
    E: KindEdit + IntoObject<Object = ObjectEdit>,
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

    fn builds(&self) -> Option<super::edit::Build> {
        KindEdit::builds(self)
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

impl<S> DynSampler for Tracked<S>
where
    S: Sampler + Support,
    S::Edit: KindEdit<Model = S::Model> + IntoObject<Object = ObjectEdit>,
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
