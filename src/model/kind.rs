//! What an object kind is: one trait, implemented once per kind in the kind's own folder. The
//! registered kinds are reached through its object-safe views ([`super::registry`]), without a
//! `match` in every layer.

use super::controls::{ControlDisplay, Grip};
use super::edit::{EditError, KindEdit, Target};
use super::erbs::LocalPath;
use super::index::Index2;
use super::spline::curve::CurveModel;
use crate::fields::{At, ReadCtx, SceneError};
use crate::geom::surface::TensorSurface;
use crate::sampling::budget::Extent;
use crate::sampling::{DirtyRegion, SampleMode, Sampler, Tracked};
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

    /// The scene-file `type` of this model: the kind's one type, unless the model says which
    /// of several it is.
    fn type_name(&self) -> &'static str {
        Self::TYPES[0]
    }

    /// Reads an object of type `ty` (one of [`Kind::TYPES`]) from its fields; `ctx.common`
    /// names the fields every object has, which the scene reads.
    fn read(
        ty: &str,
        at: &At,
        obj: &Map<String, Value>,
        ctx: &ReadCtx<'_>,
    ) -> Result<Self, SceneError>;

    /// Writes the kind's own fields, each as `, "name": value` (the scene writes the name,
    /// type, samples and colour).
    fn write(&self, out: &mut String);

    /// Reads an edit of this object (docs/scene-format.md, edits files).
    fn read_edit(&self, at: &At, obj: &Map<String, Value>) -> Result<Self::Edit, SceneError>;

    /// Sample grid dimensions: [m, 1] for curves, [mu, mv] for surfaces.
    fn sample_dims(&self) -> [usize; 2];

    /// The same geometry with other sample counts (`--samples`): [m, _] for curves, [mu, mv]
    /// for surfaces, checked against the limits.
    fn with_samples(&self, samples: [usize; 2]) -> Result<Self, EditError>;

    /// Parameter domain per direction (one entry for curves).
    fn domain(&self) -> Vec<(f64, f64)>;

    /// The kind's geometry as a tensor-product (rational) B-spline surface, where it is one:
    /// what measures a surface evaluates it thousands of times, through evaluators that do not
    /// allocate ([`TensorSurface::first_partials`]). `None`: [`Kind::derivatives_at`] serves.
    fn tensor(&self) -> Option<&TensorSurface> {
        None
    }

    /// The polynomial degree per direction, where the kind has one (B-spline and Bézier
    /// curves and surfaces); empty otherwise. For `info` and messages.
    fn degrees(&self) -> Vec<usize> {
        Vec::new()
    }

    /// The weights of a rational kind's control points; `None` for a polynomial one. For
    /// messages: a rational derivative divides by the weighted sum, so weights far apart
    /// explain a derivative that overflows.
    fn weights(&self) -> Option<&[f64]> {
        None
    }

    /// Per direction, the parameters where the geometry's pieces meet, ends included (the
    /// distinct knots in the domain): quadrature lines its cells up with them, since the
    /// geometry is smooth only in between. Default: the domain's ends.
    fn breakpoints(&self) -> Vec<Vec<f64>> {
        self.domain().iter().map(|&(a, b)| vec![a, b]).collect()
    }

    /// Pre-evaluates and fully samples the model.
    fn sampler(&self, mode: SampleMode) -> Self::Sampler;

    /// The equivalent `bspline_curve` of a kind that is a chain of Bézier segments.
    fn to_bspline_curve(&self) -> Option<CurveModel> {
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
