//! Tensor-product Bézier, B-spline and NURBS surfaces: the model and its edits.

use super::curve::{check_elevation, check_insertion, check_restore, replace};
use crate::geom::shape::{greville, insertion_window, shape_kept, span_probes};
use crate::geom::{KnotVector, TensorSurface};
use crate::model::edit::{EditError, KindEdit, Target, check_shape_kept};
use crate::model::points::PointEdit;
use crate::model::{SplineForm, check_surface_samples};
use glam::DVec3;

/// A Bézier or B-spline (NURBS with weights) surface with its sample counts [mu, mv].
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceModel {
    form: SplineForm,
    surface: TensorSurface,
    samples: [usize; 2],
}

impl SurfaceModel {
    /// A Bézier form needs one clamped span on [0, 1] per direction.
    pub fn new(
        form: SplineForm,
        surface: TensorSurface,
        samples: [usize; 2],
    ) -> Result<Self, EditError> {
        check_surface_samples(samples)?;
        if form == SplineForm::Bezier && !is_bezier(&surface) {
            return Err(EditError::new(
                "knots",
                "a Bézier surface has the knot vectors {0^(d+1), 1^(d+1)}",
            ));
        }
        Ok(Self {
            form,
            surface,
            samples,
        })
    }

    #[must_use]
    pub fn form(&self) -> SplineForm {
        self.form
    }

    #[must_use]
    pub fn surface(&self) -> &TensorSurface {
        &self.surface
    }

    #[must_use]
    pub fn samples(&self) -> [usize; 2] {
        self.samples
    }

    /// Mutable geometry for building examples (the demo's teapot placement); edits go through
    /// [`SurfaceEdit`].
    pub fn map_points(&mut self, f: impl Fn(DVec3) -> DVec3) {
        self.surface.map_points(f);
    }
}

fn is_bezier(s: &TensorSurface) -> bool {
    (0..2).all(|dir| s.knots()[dir] == KnotVector::bezier(s.degree()[dir], 0.0, 1.0))
}

/// Edits of a [`SurfaceModel`]. Directions are 0 (u) and 1 (v).
#[derive(Debug, Clone, PartialEq)]
pub enum SurfaceEdit {
    Point(PointEdit<[usize; 2]>),
    /// SurfaceKnotIns in one direction; the shape is unchanged, Bézier becomes B-spline.
    InsertKnot {
        dir: usize,
        t: f64,
        times: usize,
    },
    /// Degree elevation by [bu, bv]; the shape is unchanged, Bézier stays Bézier.
    ElevateDegree {
        by: [usize; 2],
    },
    /// Put back a whole earlier model (see [`super::curve::CurveEdit::Restore`]).
    Restore {
        model: Box<SurfaceModel>,
        shape_kept: bool,
    },
}

impl KindEdit for SurfaceEdit {
    type Model = SurfaceModel;

    fn prepare(&self, m: &SurfaceModel) -> Result<Option<SurfaceModel>, EditError> {
        let s = &m.surface;
        let (surface, form) = match *self {
            SurfaceEdit::Point(p) => return p.validate(s).map(|()| None),
            SurfaceEdit::InsertKnot { dir, t, times } => {
                if dir > 1 {
                    return Err(EditError::new("insert_knot", "the direction is u or v"));
                }
                check_insertion(
                    s.domain()[dir],
                    s.degree()[dir],
                    s.knots()[dir].multiplicity(t),
                    t,
                    times,
                )
                .map_err(|e| in_direction(e, dir))?;
                let refined = s
                    .insert_knot(dir, t, times)
                    .map_err(|e| EditError::new("insert_knot", e.message))?;
                let mut windows = [None; 2];
                windows[dir] = Some(insertion_window(
                    &s.knots()[dir],
                    s.degree()[dir],
                    t,
                    s.domain()[dir],
                ));
                check_surface_kept("insert_knot", s, &refined, windows)?;
                (refined, SplineForm::BSpline)
            }
            SurfaceEdit::ElevateDegree { by } => {
                if by == [0, 0] {
                    return Err(EditError::new(
                        "elevate_degree",
                        "the elevation must be at least 1 in u or v",
                    ));
                }
                for dir in 0..2 {
                    if by[dir] > 0 {
                        check_elevation("elevate_degree", s.degree()[dir], by[dir])
                            .map_err(|e| in_direction(e, dir))?;
                    }
                }
                let windows = [0, 1].map(|dir| (by[dir] > 0).then(|| s.domain()[dir]));
                let elevated = elevated(s, by);
                check_surface_kept("elevate_degree", s, &elevated, windows)?;
                (elevated, m.form)
            }
            SurfaceEdit::Restore { ref model, .. } => {
                check_restore(model.samples == m.samples)?;
                return Ok(Some((**model).clone()));
            }
        };
        Ok(Some(SurfaceModel {
            form,
            surface,
            samples: m.samples,
        }))
    }

    fn apply(&self, m: &mut SurfaceModel) {
        match self {
            SurfaceEdit::Point(p) => p.apply(&mut m.surface),
            SurfaceEdit::InsertKnot { dir, t, times } => {
                let r = m.surface.insert_knot(*dir, *t, *times);
                if replace(&mut m.surface, r) {
                    m.form = SplineForm::BSpline;
                }
            }
            SurfaceEdit::ElevateDegree { by } => m.surface = elevated(&m.surface, *by),
            SurfaceEdit::Restore { model, .. } => *m = (**model).clone(),
        }
    }

    fn inverse(&self, m: &SurfaceModel) -> Self {
        let restore = |shape_kept| SurfaceEdit::Restore {
            model: Box::new(m.clone()),
            shape_kept,
        };
        match self {
            SurfaceEdit::Point(p) => p
                .inverse(&m.surface)
                .map_or(restore(false), SurfaceEdit::Point),
            SurfaceEdit::InsertKnot { .. } | SurfaceEdit::ElevateDegree { .. } => restore(true),
            SurfaceEdit::Restore { shape_kept, .. } => restore(*shape_kept),
        }
    }

    fn target(&self) -> Target {
        match self {
            SurfaceEdit::Point(p) => p.target(),
            _ => Target::Structure,
        }
    }

    fn merge(&self, next: &Self) -> Option<Self> {
        match (self, next) {
            (SurfaceEdit::Point(a), SurfaceEdit::Point(b)) => a.merge(b).map(SurfaceEdit::Point),
            _ => None,
        }
    }
}

/// The surface elevated by `by` per direction (u first).
fn elevated(s: &TensorSurface, by: [usize; 2]) -> TensorSurface {
    let mut out = s.clone();
    for (dir, &b) in by.iter().enumerate() {
        if b > 0 {
            out = out.elevate_degree(dir, b);
        }
    }
    out
}

/// A refinement of `old` (an edit's `field`) that keeps its shape: the surfaces agree on a
/// grid of d+1 parameters per span of each refined direction inside its window (where the
/// refinement can change it) and the Greville abscissae of an unrefined one (where its
/// B-splines are independent, so every line of the net is compared).
fn check_surface_kept(
    field: &'static str,
    old: &TensorSurface,
    new: &TensorSurface,
    windows: [Option<(f64, f64)>; 2],
) -> Result<(), EditError> {
    let at = [0, 1].map(|dir| {
        let (d, knots) = (new.degree()[dir], &new.knots()[dir]);
        match windows[dir] {
            Some(window) => span_probes(knots, d, window),
            None => greville(knots, d, new.count()[dir], new.domain()[dir]),
        }
    });
    shape_kept(old, new, &at).or_else(|change| check_shape_kept(field, "surface", change))
}

fn in_direction(mut e: EditError, dir: usize) -> EditError {
    e.message = format!("{} direction: {}", ["u", "v"][dir], e.message);
    e
}

#[cfg(test)]
mod guard_tests {
    use super::*;

    /// The guard every surface refinement passes through refuses a refined net that moves
    /// the shape, naming the edit's field; the same net unmoved passes.
    #[test]
    fn a_refinement_that_moves_the_shape_is_refused() {
        let points = (0..9)
            .map(|k| DVec3::new((k / 3) as f64, (k % 3) as f64, ((k * 7) % 5) as f64 * 0.3))
            .collect();
        let s = TensorSurface::bezier([3, 3], points, None).unwrap();
        let windows = [Some(s.domain()[0]), None];
        let elevated = s.elevate_degree(0, 1);
        assert_eq!(
            check_surface_kept("elevate_degree", &s, &elevated, windows),
            Ok(())
        );
        let mut moved = elevated;
        let p = moved.points()[4];
        moved.set_point(1, 1, p + DVec3::new(0.0, 0.0, 1e-6));
        let e = check_surface_kept("elevate_degree", &s, &moved, windows).unwrap_err();
        assert_eq!(e.field, "elevate_degree", "{e:?}");
    }
}
