//! Bézier, B-spline and NURBS curves: the model and its edits.

use super::curve_sampler::SplineCurveSampler;
use crate::format::{At, SceneError};
use crate::geom::shape::{insertion_window, shape_kept, span_probes};
use crate::geom::{BSplineCurve, GeomError, KnotVector};
use crate::model::Index2;
use crate::model::Kind;
use crate::model::controls::{ControlDisplay, Grip};
use crate::model::edit::{EditError, KindEdit, Target, check_shape_kept};
use crate::model::points::PointEdit;
use crate::model::{MAX_CURVE_SAMPLES, MAX_DEGREE, SplineForm, check_samples};
use crate::sampling::SampleMode;
use crate::sampling::budget::Extent;
use glam::DVec3;
use serde_json::{Map, Value};

/// A Bézier or B-spline (NURBS with weights) curve with its sample count.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveModel {
    form: SplineForm,
    curve: BSplineCurve,
    samples: usize,
}

impl CurveModel {
    /// A Bézier form needs one clamped span on [0, 1] (the file format's Bézier curve).
    pub fn new(form: SplineForm, curve: BSplineCurve, samples: usize) -> Result<Self, EditError> {
        check_samples(samples, MAX_CURVE_SAMPLES)?;
        if form == SplineForm::Bezier
            && *curve.knots() != KnotVector::bezier(curve.degree(), 0.0, 1.0)
        {
            return Err(EditError::new(
                "knots",
                "a Bézier curve has the knot vector {0^(d+1), 1^(d+1)}",
            ));
        }
        Ok(Self {
            form,
            curve,
            samples,
        })
    }

    #[must_use]
    pub fn form(&self) -> SplineForm {
        self.form
    }

    #[must_use]
    pub fn curve(&self) -> &BSplineCurve {
        &self.curve
    }

    #[must_use]
    pub fn samples(&self) -> usize {
        self.samples
    }
}

impl Kind for CurveModel {
    type Edit = CurveEdit;
    type Sampler = SplineCurveSampler;
    const SURFACE: bool = false;
    const LABEL: &'static str = "curve";

    const TYPES: &'static [&'static str] = super::file::CURVE_TYPES;

    fn read(
        ty: &str,
        at: &At,
        obj: &Map<String, Value>,
        common: &[&'static str],
    ) -> Result<Self, SceneError> {
        super::file::read_curve(ty, at, obj, common)
    }

    fn write(&self, out: &mut String) {
        super::file::write_curve(self, out);
    }

    fn read_edit(&self, at: &At, obj: &Map<String, Value>) -> Result<CurveEdit, SceneError> {
        super::file::read_curve_edit(at, obj)
    }

    fn type_name(&self) -> &'static str {
        match self.form {
            SplineForm::Bezier => "bezier_curve",
            SplineForm::BSpline => "bspline_curve",
        }
    }

    fn sample_dims(&self) -> [usize; 2] {
        [self.samples, 1]
    }

    fn domain(&self) -> Vec<(f64, f64)> {
        vec![self.curve.domain()]
    }

    fn sampler(&self, mode: SampleMode) -> SplineCurveSampler {
        SplineCurveSampler::new(self.clone(), mode.layout().0)
    }

    fn derivatives_at(
        &self,
        [u, _]: [f64; 2],
        order: usize,
        _: &[(usize, usize)],
        out: &mut [DVec3],
    ) {
        out.copy_from_slice(&self.curve.derivatives(u, order));
    }

    fn extent(&self) -> Extent {
        let c = &self.curve;
        Extent::polynomial(&[self.samples], &[c.degree()], c.is_rational())
    }

    fn controls(&self) -> ControlDisplay {
        ControlDisplay::polygon(self.curve.points().to_vec())
    }

    fn control_point(&self, point: Index2) -> Option<DVec3> {
        let Index2::One(k) = point else { return None };
        self.curve.points().get(k).copied()
    }

    fn move_edit(&self, grip: Grip, delta: DVec3) -> Option<CurveEdit> {
        let Grip::Point(Index2::One(point)) = grip else {
            return None;
        };
        Some(CurveEdit::Point(PointEdit::Move { point, delta }))
    }

    fn weight(&self, grip: Grip) -> Option<f64> {
        let Grip::Point(Index2::One(k)) = grip else {
            return None;
        };
        self.curve.points().get(k)?;
        Some(self.curve.weights().map_or(1.0, |w| w[k]))
    }

    fn weight_edit(&self, grip: Grip, weight: f64) -> Result<CurveEdit, String> {
        match grip {
            Grip::Point(Index2::One(point)) => {
                Ok(CurveEdit::Point(PointEdit::Weight { point, weight }))
            }
            _ => Err(format!("a {} has no such control point", self.type_name())),
        }
    }
}

/// Edits of a [`CurveModel`].
#[derive(Debug, Clone, PartialEq)]
pub enum CurveEdit {
    Point(PointEdit<usize>),
    /// CurveKnotIns: insert `t` `times` times; the shape is unchanged, a Bézier curve becomes a
    /// B-spline curve.
    InsertKnot {
        t: f64,
        times: usize,
    },
    /// DegreeElevateCurve by `by`; the shape is unchanged, a Bézier curve stays Bézier.
    ElevateDegree {
        by: usize,
    },
    /// Put back a whole earlier model (undo of structural edits, and of a weight that made a
    /// polynomial curve rational). `shape_kept`: the restored model describes the current
    /// shape (undo of a refinement), so samples need not be recomputed.
    Restore {
        model: Box<CurveModel>,
        shape_kept: bool,
    },
}

impl KindEdit for CurveEdit {
    type Model = CurveModel;

    fn prepare(&self, m: &CurveModel) -> Result<Option<CurveModel>, EditError> {
        let c = &m.curve;
        let (curve, form) = match *self {
            CurveEdit::Point(p) => return p.validate(c).map(|()| None),
            CurveEdit::InsertKnot { t, times } => {
                check_insertion(c.domain(), c.degree(), c.knots().multiplicity(t), t, times)?;
                let window = insertion_window(c.knots(), c.degree(), t, c.domain());
                let refined = kept_curve("insert_knot", c, c.insert_knot(t, times), window)?;
                (refined, SplineForm::BSpline)
            }
            CurveEdit::ElevateDegree { by } => {
                check_elevation("elevate_degree", c.degree(), by)?;
                let elevated = kept_curve("elevate_degree", c, c.elevate_degree(by), c.domain())?;
                (elevated, m.form)
            }
            CurveEdit::Restore { ref model, .. } => {
                check_restore(model.samples == m.samples)?;
                return Ok(Some((**model).clone()));
            }
        };
        Ok(Some(CurveModel {
            form,
            curve,
            samples: m.samples,
        }))
    }

    fn apply(&self, m: &mut CurveModel) {
        match self {
            CurveEdit::Point(p) => p.apply(&mut m.curve),
            CurveEdit::InsertKnot { t, times } => {
                let r = m.curve.insert_knot(*t, *times);
                if replace(&mut m.curve, r) {
                    m.form = SplineForm::BSpline;
                }
            }
            CurveEdit::ElevateDegree { by } => {
                let r = m.curve.elevate_degree(*by);
                replace(&mut m.curve, r);
            }
            CurveEdit::Restore { model, .. } => *m = (**model).clone(),
        }
    }

    fn inverse(&self, m: &CurveModel) -> Self {
        let restore = |shape_kept| CurveEdit::Restore {
            model: Box::new(m.clone()),
            shape_kept,
        };
        match self {
            CurveEdit::Point(p) => p.inverse(&m.curve).map_or(restore(false), CurveEdit::Point),
            CurveEdit::InsertKnot { .. } | CurveEdit::ElevateDegree { .. } => restore(true),
            CurveEdit::Restore { shape_kept, .. } => restore(*shape_kept),
        }
    }

    fn target(&self) -> Target {
        match self {
            CurveEdit::Point(p) => p.target(),
            _ => Target::Structure,
        }
    }

    fn merge(&self, next: &Self) -> Option<Self> {
        match (self, next) {
            (CurveEdit::Point(a), CurveEdit::Point(b)) => a.merge(b).map(CurveEdit::Point),
            _ => None,
        }
    }
}

/// A refinement of `old` (an edit's `field`) that keeps its shape: the refined curve agrees
/// with it at d+1 points per span of the refined knots inside `window`, where it can differ.
fn kept_curve(
    field: &'static str,
    old: &BSplineCurve,
    refined: Result<BSplineCurve, GeomError>,
    window: (f64, f64),
) -> Result<BSplineCurve, EditError> {
    let new = refined.map_err(|e| EditError::new(field, e.message))?;
    let at = span_probes(new.knots(), new.degree(), window);
    shape_kept(old, &new, &at).or_else(|change| check_shape_kept(field, "curve", change))?;
    Ok(new)
}

/// Takes a refinement's result. Refining a valid model with validated arguments cannot fail;
/// should it ever, the model stays as it was rather than half-changed.
pub(super) fn replace<T>(slot: &mut T, refined: Result<T, GeomError>) -> bool {
    match refined {
        Ok(v) => {
            *slot = v;
            true
        }
        Err(e) => {
            debug_assert!(false, "validated refinement failed: {e}");
            false
        }
    }
}

pub(super) fn check_restore(same_samples: bool) -> Result<(), EditError> {
    if same_samples {
        Ok(())
    } else {
        Err(EditError::new(
            "samples",
            "a restored model keeps the sample counts",
        ))
    }
}

/// t strictly inside the domain (a, b), times ≥ 1, and the resulting multiplicity ≤ degree.
pub(super) fn check_insertion(
    (a, b): (f64, f64),
    degree: usize,
    multiplicity: usize,
    t: f64,
    times: usize,
) -> Result<(), EditError> {
    if !(t > a && t < b) {
        return Err(EditError::new(
            "insert_knot",
            format!("parameter {t} is not inside the open domain ({a}, {b})"),
        ));
    }
    if times == 0 {
        return Err(EditError::new("times", "must be at least 1"));
    }
    if multiplicity + times > degree {
        return Err(EditError::new(
            "times",
            format!(
                "inserting {t} {times} time(s) gives multiplicity {} there, above the degree {degree}",
                multiplicity + times
            ),
        ));
    }
    Ok(())
}

/// by ≥ 1 and degree + by ≤ MAX_DEGREE.
pub(super) fn check_elevation(
    field: &'static str,
    degree: usize,
    by: usize,
) -> Result<(), EditError> {
    if by == 0 {
        return Err(EditError::new(field, "the elevation must be at least 1"));
    }
    if degree + by > MAX_DEGREE {
        return Err(EditError::new(
            field,
            format!("degree {degree} + {by} exceeds the supported maximum {MAX_DEGREE}"),
        ));
    }
    Ok(())
}
