//! The object model and its edit vocabulary: what an object is (geometry together with its
//! sample counts, one type per kind) and every change that can be made to it.
//!
//! This layer sits between `geom` and both `scene` (files, names) and `sampling`
//! (pre-evaluation): the scene parser produces these models and edits, the samplers consume
//! them, the viewer's undo inverts them and the GPU mirrors read what they change. Each kind has
//! its own model and edit type ([`CurveModel`]/[`CurveEdit`], …) implementing [`KindEdit`];
//! [`Model`] and [`ObjectEdit`] are the closed sums over the kinds, and pairing a model with an
//! edit of another kind is an error value, never a panic.

mod curve;
mod edit;
mod erbs;
mod points;
mod splines;
mod surface;

pub use curve::{CurveEdit, CurveModel};
pub use edit::{Edit, EditError, KindEdit, ObjectEdit, Target, edit_kind_mismatch, merge_edits};
pub use erbs::{
    ErbsCurveEdit, ErbsCurveModel, ErbsEdit, ErbsNet, ErbsSurfaceEdit, ErbsSurfaceModel, LocalEdit,
    LocalPath,
};
pub use points::{PointEdit, PointNet};
pub use splines::{
    BezierSplineEdit, BezierSplineModel, CatmullRomEdit, CatmullRomModel, ChainEdit, ChainModel,
};
pub use surface::{SurfaceEdit, SurfaceModel};

/// Largest polynomial degree per direction (files, degree elevation). Evaluation works for any
/// degree; this bounds memory (pre-evaluated matrices grow with (d+1)²) and rejects nonsense.
pub const MAX_DEGREE: usize = 64;
/// Largest sample count per curve.
pub const MAX_CURVE_SAMPLES: usize = 10_000_000;
/// Largest sample count of a surface (mu · mv).
pub const MAX_SURFACE_SAMPLES: usize = 1 << 24;

/// A control point or local curve/patch index: one index for curves, two for surfaces.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Index2 {
    One(usize),
    Two(usize, usize),
}

/// "3" or "[1, 2]", as messages and the file format write an index.
impl std::fmt::Display for Index2 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Index2::One(k) => write!(f, "{k}"),
            Index2::Two(a, b) => write!(f, "[{a}, {b}]"),
        }
    }
}

/// How a polynomial-basis object is written: as a Bézier object (one span on [0, 1]) or as a
/// B-spline. Both are evaluated as B-splines; knot insertion turns a Bézier object into a
/// B-spline object.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SplineForm {
    Bezier,
    BSpline,
}

/// Every object kind with its geometry and sample counts.
#[derive(Debug, Clone, PartialEq)]
pub enum Model {
    Curve(CurveModel),
    Surface(SurfaceModel),
    ErbsCurve(ErbsCurveModel),
    ErbsSurface(ErbsSurfaceModel),
    CatmullRom(CatmullRomModel),
    BezierSpline(BezierSplineModel),
}

/// A borrowed [`Model`] (samplers own their kind's model; this is how others read it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ModelRef<'a> {
    Curve(&'a CurveModel),
    Surface(&'a SurfaceModel),
    ErbsCurve(&'a ErbsCurveModel),
    ErbsSurface(&'a ErbsSurfaceModel),
    CatmullRom(&'a CatmullRomModel),
    BezierSpline(&'a BezierSplineModel),
}

impl Model {
    #[must_use]
    pub fn as_ref(&self) -> ModelRef<'_> {
        match self {
            Model::Curve(m) => ModelRef::Curve(m),
            Model::Surface(m) => ModelRef::Surface(m),
            Model::ErbsCurve(m) => ModelRef::ErbsCurve(m),
            Model::ErbsSurface(m) => ModelRef::ErbsSurface(m),
            Model::CatmullRom(m) => ModelRef::CatmullRom(m),
            Model::BezierSpline(m) => ModelRef::BezierSpline(m),
        }
    }

    /// The scene-file `type` string.
    pub fn type_name(&self) -> &'static str {
        self.as_ref().type_name()
    }

    pub fn is_surface(&self) -> bool {
        self.as_ref().is_surface()
    }

    /// Sample grid dimensions: [m, 1] for curves, [mu, mv] for surfaces.
    pub fn sample_dims(&self) -> [usize; 2] {
        self.as_ref().sample_dims()
    }

    /// Parameter domain per direction (one entry for curves).
    pub fn domain(&self) -> Vec<(f64, f64)> {
        self.as_ref().domain()
    }

    /// Applies a validated edit of this object's kind (a kind mismatch is an error).
    pub fn apply(&mut self, edit: &ObjectEdit) -> Result<(), EditError> {
        edit::apply_to_model(self, edit)
    }
}

impl<'a> ModelRef<'a> {
    pub fn type_name(&self) -> &'static str {
        match self {
            ModelRef::Curve(m) => match m.form() {
                SplineForm::Bezier => "bezier_curve",
                SplineForm::BSpline => "bspline_curve",
            },
            ModelRef::Surface(m) => match m.form() {
                SplineForm::Bezier => "bezier_surface",
                SplineForm::BSpline => "bspline_surface",
            },
            ModelRef::ErbsCurve(_) => "erbs_curve",
            ModelRef::ErbsSurface(_) => "erbs_surface",
            ModelRef::CatmullRom(_) => "catmull_rom",
            ModelRef::BezierSpline(_) => "bezier_spline",
        }
    }

    pub fn is_surface(&self) -> bool {
        matches!(self, ModelRef::Surface(_) | ModelRef::ErbsSurface(_))
    }

    pub fn sample_dims(&self) -> [usize; 2] {
        match self {
            ModelRef::Curve(m) => [m.samples(), 1],
            ModelRef::ErbsCurve(m) => [m.samples(), 1],
            ModelRef::CatmullRom(m) => [m.samples(), 1],
            ModelRef::BezierSpline(m) => [m.samples(), 1],
            ModelRef::Surface(m) => m.samples(),
            ModelRef::ErbsSurface(m) => m.samples(),
        }
    }

    pub fn domain(&self) -> Vec<(f64, f64)> {
        match self {
            ModelRef::Curve(m) => vec![m.curve().domain()],
            ModelRef::ErbsCurve(m) => vec![m.curve().domain()],
            ModelRef::CatmullRom(m) => vec![m.spline().domain()],
            ModelRef::BezierSpline(m) => vec![m.spline().domain()],
            ModelRef::Surface(m) => m.surface().domain().to_vec(),
            ModelRef::ErbsSurface(m) => m.surface().domain().to_vec(),
        }
    }

    /// The equivalent B-spline curve (Catmull–Rom and Bézier splines: their Bézier chain), or
    /// `None` for kinds that are not such a chain.
    #[must_use]
    pub fn to_bspline_curve(&self) -> Option<Model> {
        match *self {
            ModelRef::CatmullRom(m) => Some(Model::Curve(m.chain_form())),
            ModelRef::BezierSpline(m) => Some(Model::Curve(m.chain_form())),
            _ => None,
        }
    }

    /// An owned copy.
    #[must_use]
    pub fn to_model(&self) -> Model {
        match *self {
            ModelRef::Curve(m) => Model::Curve(m.clone()),
            ModelRef::Surface(m) => Model::Surface(m.clone()),
            ModelRef::ErbsCurve(m) => Model::ErbsCurve(m.clone()),
            ModelRef::ErbsSurface(m) => Model::ErbsSurface(m.clone()),
            ModelRef::CatmullRom(m) => Model::CatmullRom(m.clone()),
            ModelRef::BezierSpline(m) => Model::BezierSpline(m.clone()),
        }
    }
}

/// Checks a sample count: at least 2 (both ends are sampled), at most `max`.
pub fn check_samples(m: usize, max: usize) -> Result<(), EditError> {
    if m < 2 {
        return Err(EditError::new(
            "samples",
            format!("{m} samples: at least 2 are needed (both ends are sampled)"),
        ));
    }
    if m > max {
        return Err(EditError::new(
            "samples",
            format!("{m} samples exceed the limit of {max}"),
        ));
    }
    Ok(())
}

/// Checks surface sample counts [mu, mv].
pub fn check_surface_samples([mu, mv]: [usize; 2]) -> Result<(), EditError> {
    check_samples(mu, MAX_SURFACE_SAMPLES)?;
    check_samples(mv, MAX_SURFACE_SAMPLES)?;
    if mu.saturating_mul(mv) > MAX_SURFACE_SAMPLES {
        return Err(EditError::new(
            "samples",
            format!("{mu} × {mv} samples exceed the limit of {MAX_SURFACE_SAMPLES}"),
        ));
    }
    Ok(())
}
