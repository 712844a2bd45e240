//! Bézier, B-spline and NURBS curves: the model and its edits.

use crate::geom::shape::{insertion_window, shape_kept, span_probes};
use crate::geom::{BSplineCurve, GeomError, KnotVector};
use crate::model::edit::{EditError, KindEdit, Target, check_shape_kept};
use crate::model::points::PointEdit;
use crate::model::{MAX_CURVE_SAMPLES, MAX_DEGREE, SplineForm, check_samples};

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

#[cfg(test)]
mod guard_tests {
    use super::*;
    use glam::DVec3;

    /// The guard every B-spline curve refinement passes through (`prepare` takes its result
    /// from `kept_curve`) refuses a refined net that moves the shape, in one error naming the
    /// edit's field; the same net unmoved passes.
    #[test]
    fn a_refinement_that_moves_the_shape_is_refused() {
        let c = BSplineCurve::new(
            3,
            vec![0.0, 0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0, 1.0],
            vec![
                DVec3::ZERO,
                DVec3::new(1.0, 2.0, 0.0),
                DVec3::new(2.0, -1.0, 1.0),
                DVec3::new(3.0, 1.0, 0.0),
                DVec3::new(4.0, 0.0, 0.0),
            ],
            None,
        )
        .unwrap();
        let elevated = c.elevate_degree(1).unwrap();
        assert!(kept_curve("elevate_degree", &c, Ok(elevated.clone()), c.domain()).is_ok());
        let mut moved = elevated;
        let p = moved.points()[3];
        moved.set_point(3, p + DVec3::new(0.0, 1e-6, 0.0));
        let e = kept_curve("elevate_degree", &c, Ok(moved), c.domain()).unwrap_err();
        assert_eq!(e.field, "elevate_degree", "{e:?}");
        let inserted = c.insert_knot(0.25, 1).unwrap();
        let window = insertion_window(c.knots(), c.degree(), 0.25, c.domain());
        assert!(kept_curve("insert_knot", &c, Ok(inserted.clone()), window).is_ok());
        let mut moved = inserted;
        let p = moved.points()[1];
        moved.set_point(1, p * (1.0 + 1e-7));
        assert!(kept_curve("insert_knot", &c, Ok(moved), window).is_err());
    }
}
