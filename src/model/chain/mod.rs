//! Catmull–Rom splines and Bézier splines with declared continuity: the models and their edits.
//!
//! Both are chains of Bézier segments, which the sampler pre-evaluates as one B-spline (knots of
//! multiplicity d at the junctions); an edit of a user point becomes moves of the few chain
//! points it changes ([`ChainEdit::chain_points`]), each touching only its segments' samples.

pub mod file;
mod kinds;
pub mod sampler;

use crate::geom::{BezierSpline, CatmullRom, GeomError};
use crate::model::edit::{EditError, KindEdit, Target};
use crate::model::points::{PointEdit, check_index, check_vector};
use crate::model::{CurveModel, Index2, MAX_CURVE_SAMPLES, SplineForm, check_samples};
use glam::DVec3;

/// A curve kind pre-evaluated as the B-spline of its Bézier chain.
pub trait ChainModel: Clone + std::fmt::Debug {
    /// The chain as a B-spline curve model with this model's sample count (sampler
    /// construction, conversion to `bspline_curve`).
    fn chain_form(&self) -> CurveModel;
    /// Control point i of that B-spline (junction points shared).
    fn chain_point(&self, i: usize) -> DVec3;
}

/// An edit of a [`ChainModel`] kind.
pub trait ChainEdit: KindEdit<Model: ChainModel> {
    /// Indices of the chain points this edit may change, computed before it is applied.
    fn chain_points(&self, model: &Self::Model) -> Vec<usize>;

    /// Indices of the chain points a move of handle `handle` may change, known before any move
    /// (what a drag of it reaches); none for a handle the model does not have.
    fn handle_points(model: &Self::Model, handle: usize) -> Vec<usize>;
}

fn geom_error(e: GeomError) -> EditError {
    EditError::new(e.field, e.message)
}

/// A Catmull–Rom spline with its sample count.
#[derive(Debug, Clone, PartialEq)]
pub struct CatmullRomModel {
    spline: CatmullRom,
    samples: usize,
}

impl CatmullRomModel {
    pub fn new(spline: CatmullRom, samples: usize) -> Result<Self, EditError> {
        check_samples(samples, MAX_CURVE_SAMPLES)?;
        Ok(Self { spline, samples })
    }

    #[must_use]
    pub fn spline(&self) -> &CatmullRom {
        &self.spline
    }

    #[must_use]
    pub fn samples(&self) -> usize {
        self.samples
    }
}

impl ChainModel for CatmullRomModel {
    fn chain_form(&self) -> CurveModel {
        CurveModel::new(SplineForm::BSpline, self.spline.to_bspline(), self.samples)
            .expect("the sample count was checked")
    }

    fn chain_point(&self, i: usize) -> DVec3 {
        self.spline.bezier_point_at(i)
    }
}

/// Edits of a [`CatmullRomModel`]: moving or setting one interpolated point (no weights: the
/// segments are polynomial).
#[derive(Debug, Clone, PartialEq)]
pub enum CatmullRomEdit {
    Point(PointEdit<usize>),
}

impl CatmullRomEdit {
    fn check(&self, m: &CatmullRomModel) -> Result<(), EditError> {
        let CatmullRomEdit::Point(p) = self;
        let j = p.point();
        check_index("point", j, m.spline.points().len())?;
        let to = match *p {
            PointEdit::Move { delta, .. } => {
                check_vector("delta", delta)?;
                m.spline.points()[j] + delta
            }
            PointEdit::Set { position, .. } => {
                check_vector("position", position)?;
                position
            }
            PointEdit::Weight { .. } => {
                return Err(EditError::new(
                    "weight",
                    "a catmull_rom has no weights (its segments are polynomial; convert it to a bspline_curve first)",
                ));
            }
        };
        m.spline.check_move(j, to).map_err(geom_error)
    }
}

impl KindEdit for CatmullRomEdit {
    type Model = CatmullRomModel;

    /// Point edits apply in place: nothing to prepare but the checks.
    fn prepare(&self, m: &CatmullRomModel) -> Result<Option<CatmullRomModel>, EditError> {
        self.check(m).map(|()| None)
    }

    fn apply(&self, m: &mut CatmullRomModel) {
        let CatmullRomEdit::Point(p) = self;
        let j = p.point();
        match *p {
            PointEdit::Move { delta, .. } => {
                let to = m.spline.points()[j] + delta;
                m.spline.set_point(j, to);
            }
            PointEdit::Set { position, .. } => m.spline.set_point(j, position),
            PointEdit::Weight { .. } => debug_assert!(false, "refused by validate"),
        }
    }

    fn inverse(&self, m: &CatmullRomModel) -> Self {
        let CatmullRomEdit::Point(p) = self;
        let point = p.point();
        CatmullRomEdit::Point(PointEdit::Set {
            point,
            position: m.spline.points()[point],
        })
    }

    fn target(&self) -> Target {
        let CatmullRomEdit::Point(p) = self;
        p.target()
    }

    fn merge(&self, next: &Self) -> Option<Self> {
        let (CatmullRomEdit::Point(a), CatmullRomEdit::Point(b)) = (self, next);
        a.merge(b).map(CatmullRomEdit::Point)
    }
}

impl ChainEdit for CatmullRomEdit {
    fn chain_points(&self, m: &CatmullRomModel) -> Vec<usize> {
        let CatmullRomEdit::Point(p) = self;
        m.spline.bezier_points_of(p.point())
    }

    fn handle_points(m: &CatmullRomModel, handle: usize) -> Vec<usize> {
        if handle < m.spline.points().len() {
            m.spline.bezier_points_of(handle)
        } else {
            Vec::new()
        }
    }
}

/// A Bézier spline with its sample count.
#[derive(Debug, Clone, PartialEq)]
pub struct BezierSplineModel {
    spline: BezierSpline,
    samples: usize,
}

impl BezierSplineModel {
    pub fn new(spline: BezierSpline, samples: usize) -> Result<Self, EditError> {
        check_samples(samples, MAX_CURVE_SAMPLES)?;
        Ok(Self { spline, samples })
    }

    #[must_use]
    pub fn spline(&self) -> &BezierSpline {
        &self.spline
    }

    #[must_use]
    pub fn samples(&self) -> usize {
        self.samples
    }
}

impl ChainModel for BezierSplineModel {
    fn chain_form(&self) -> CurveModel {
        CurveModel::new(SplineForm::BSpline, self.spline.to_bspline(), self.samples)
            .expect("the sample count was checked")
    }

    fn chain_point(&self, i: usize) -> DVec3 {
        self.spline.points()[i]
    }
}

/// Edits of a [`BezierSplineModel`]. `point` is a handle: a Bézier point, or a de Boor point
/// for the splines edited through them (C1 quadratic, C2 cubic).
#[derive(Debug, Clone, PartialEq)]
pub enum BezierSplineEdit {
    /// Moves a handle; the points its continuity ties to it follow
    /// ([`BezierSpline::move_handle`]).
    Move { point: usize, delta: DVec3 },
    /// Sets Bézier points exactly (the undo of a move of handle `point`).
    Set {
        point: usize,
        values: Vec<(usize, DVec3)>,
    },
}

impl BezierSplineEdit {
    #[must_use]
    pub fn point(&self) -> usize {
        match *self {
            BezierSplineEdit::Move { point, .. } | BezierSplineEdit::Set { point, .. } => point,
        }
    }
}

impl BezierSplineEdit {
    fn check(&self, m: &BezierSplineModel) -> Result<(), EditError> {
        let s = &m.spline;
        match self {
            BezierSplineEdit::Move { point, delta } => {
                check_vector("delta", *delta)?;
                s.move_handle(*point, *delta)
                    .map(|_| ())
                    .map_err(geom_error)
            }
            BezierSplineEdit::Set { point, values } => {
                s.check_handle(*point).map_err(geom_error)?;
                for &(i, p) in values {
                    check_index("point", i, s.points().len())?;
                    check_vector("position", p)?;
                }
                Ok(())
            }
        }
    }
}

impl KindEdit for BezierSplineEdit {
    type Model = BezierSplineModel;

    /// Point edits apply in place: nothing to prepare but the checks.
    fn prepare(&self, m: &BezierSplineModel) -> Result<Option<BezierSplineModel>, EditError> {
        self.check(m).map(|()| None)
    }

    fn apply(&self, m: &mut BezierSplineModel) {
        let values = match self {
            BezierSplineEdit::Move { point, delta } => match m.spline.move_handle(*point, *delta) {
                Ok(v) => v,
                Err(e) => {
                    debug_assert!(false, "validated move failed: {e}");
                    return;
                }
            },
            BezierSplineEdit::Set { values, .. } => values.clone(),
        };
        for (i, p) in values {
            m.spline.set_point(i, p);
        }
    }

    fn inverse(&self, m: &BezierSplineModel) -> Self {
        let point = self.point();
        let values = self
            .chain_points(m)
            .into_iter()
            .map(|i| (i, m.spline.points()[i]))
            .collect();
        BezierSplineEdit::Set { point, values }
    }

    fn target(&self) -> Target {
        Target::Point(Index2::One(self.point()))
    }

    fn merge(&self, next: &Self) -> Option<Self> {
        use BezierSplineEdit::*;
        if self.point() != next.point() {
            return None;
        }
        match (self, next) {
            (Move { point, delta: a }, Move { delta: b, .. }) => Some(Move {
                point: *point,
                delta: *a + *b,
            }),
            // A set of handle h covers every point a move of h changes.
            (_, Set { .. }) => Some(next.clone()),
            _ => None,
        }
    }
}

impl ChainEdit for BezierSplineEdit {
    fn chain_points(&self, m: &BezierSplineModel) -> Vec<usize> {
        match self {
            BezierSplineEdit::Move { point, delta } => m
                .spline
                .move_handle(*point, *delta)
                .map(|v| v.into_iter().map(|(i, _)| i).collect())
                .unwrap_or_default(),
            BezierSplineEdit::Set { values, .. } => values.iter().map(|&(i, _)| i).collect(),
        }
    }

    /// The points a move carries depend on the continuity and the handle, not on the move.
    fn handle_points(m: &BezierSplineModel, handle: usize) -> Vec<usize> {
        BezierSplineEdit::Move {
            point: handle,
            delta: DVec3::ONE,
        }
        .chain_points(m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{JoinContinuity, Parametrization};

    #[test]
    fn inverses_restore_bit_for_bit() {
        let pts: Vec<DVec3> = (0..6)
            .map(|i| DVec3::new(i as f64 * 0.7, (i as f64).sin(), 0.1 * i as f64))
            .collect();
        let c = CatmullRom::new(pts, Parametrization::Centripetal, true).unwrap();
        let m = CatmullRomModel::new(c, 100).unwrap();
        let e = CatmullRomEdit::Point(PointEdit::Move {
            point: 2,
            delta: DVec3::new(0.1, 0.2, 0.3),
        });
        e.validate(&m).unwrap();
        let inv = e.inverse(&m);
        let mut after = m.clone();
        e.apply(&mut after);
        assert_ne!(after, m);
        inv.apply(&mut after);
        assert_eq!(after, m);

        let knots = vec![0.0, 1.0, 1.5, 3.0];
        let deboor: Vec<DVec3> = (0..6)
            .map(|i| DVec3::new(i as f64, (i * i % 4) as f64, 0.0))
            .collect();
        let mut kv = vec![0.0; 4];
        kv.extend_from_slice(&[1.0, 1.5]);
        kv.extend([3.0; 4]);
        let mut b = crate::geom::BSplineCurve::new(3, kv, deboor, None).unwrap();
        b = b.insert_knot(1.0, 2).unwrap().insert_knot(1.5, 2).unwrap();
        let s = BezierSpline::new(3, knots, b.points().to_vec(), JoinContinuity::C2).unwrap();
        let m = BezierSplineModel::new(s, 50).unwrap();
        for point in 0..6 {
            let e = BezierSplineEdit::Move {
                point,
                delta: DVec3::new(0.3, 0.1, -0.2),
            };
            let inv = e.inverse(&m);
            let mut after = m.clone();
            e.apply(&mut after);
            assert_ne!(after, m);
            inv.apply(&mut after);
            assert_eq!(after, m);
        }
    }
}
