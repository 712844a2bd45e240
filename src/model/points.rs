//! Control-point edits, the same for every net of points and weights (curve polygons with one
//! index, surface nets with two).

use super::Index2;
use super::edit::{EditError, Target};
use crate::geom::{BSplineCurve, TensorSurface};
use glam::DVec3;

/// A net of control points with optional weights, addressed by `I`.
pub trait PointNet<I> {
    /// An error naming the valid range when `i` is outside the net.
    fn check_index(&self, i: I) -> Result<(), EditError>;
    fn point(&self, i: I) -> DVec3;
    fn set_point(&mut self, i: I, p: DVec3);
    /// The weight, or `None` for a polynomial net.
    fn weight(&self, i: I) -> Option<f64>;
    /// Sets a weight; a polynomial net becomes rational with all other weights 1.
    fn set_weight(&mut self, i: I, w: f64);
}

/// An edit of one control point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PointEdit<I> {
    /// Translate the point (for rational nets the Cartesian point; its weight stays).
    Move { point: I, delta: DVec3 },
    /// Set the point exactly (undo restores values bit for bit).
    Set { point: I, position: DVec3 },
    /// Set the weight.
    Weight { point: I, weight: f64 },
}

impl<I: Copy + PartialEq + Into<Index2>> PointEdit<I> {
    pub fn point(&self) -> I {
        match *self {
            PointEdit::Move { point, .. }
            | PointEdit::Set { point, .. }
            | PointEdit::Weight { point, .. } => point,
        }
    }

    pub fn validate(&self, net: &impl PointNet<I>) -> Result<(), EditError> {
        net.check_index(self.point())?;
        match *self {
            PointEdit::Move { delta, .. } => check_vector("delta", delta),
            PointEdit::Set { position, .. } => check_vector("position", position),
            PointEdit::Weight { weight, .. } => check_weight(weight),
        }
    }

    pub fn apply(&self, net: &mut impl PointNet<I>) {
        match *self {
            PointEdit::Move { point, delta } => net.set_point(point, net.point(point) + delta),
            PointEdit::Set { point, position } => net.set_point(point, position),
            PointEdit::Weight { point, weight } => net.set_weight(point, weight),
        }
    }

    /// The edit setting the target back; `None` when only the whole model can say what it
    /// was (a weight of a polynomial net, which becomes rational).
    #[must_use]
    pub fn inverse(&self, net: &impl PointNet<I>) -> Option<Self> {
        Some(match *self {
            PointEdit::Move { point, .. } | PointEdit::Set { point, .. } => PointEdit::Set {
                point,
                position: net.point(point),
            },
            PointEdit::Weight { point, .. } => PointEdit::Weight {
                point,
                weight: net.weight(point)?,
            },
        })
    }

    pub fn target(&self) -> Target {
        match *self {
            PointEdit::Move { point, .. } | PointEdit::Set { point, .. } => {
                Target::Point(point.into())
            }
            PointEdit::Weight { point, .. } => Target::Weight(point.into()),
        }
    }

    /// Consecutive moves of one point add up, a set point absorbs later moves, the last set
    /// point or weight wins.
    #[must_use]
    pub fn merge(&self, next: &Self) -> Option<Self> {
        use PointEdit::*;
        if self.point() != next.point() {
            return None;
        }
        match (*self, *next) {
            (Move { point, delta: a }, Move { delta: b, .. }) => Some(Move {
                point,
                delta: a + b,
            }),
            (Set { point, position }, Move { delta, .. }) => Some(Set {
                point,
                position: position + delta,
            }),
            (Set { .. } | Move { .. }, Set { .. }) | (Weight { .. }, Weight { .. }) => Some(*next),
            _ => None,
        }
    }
}

impl From<usize> for Index2 {
    fn from(i: usize) -> Self {
        Index2::One(i)
    }
}

impl From<[usize; 2]> for Index2 {
    fn from([i, j]: [usize; 2]) -> Self {
        Index2::Two(i, j)
    }
}

impl PointNet<usize> for BSplineCurve {
    fn check_index(&self, i: usize) -> Result<(), EditError> {
        check_index("point", i, self.points().len())
    }

    fn point(&self, i: usize) -> DVec3 {
        self.points()[i]
    }

    fn set_point(&mut self, i: usize, p: DVec3) {
        BSplineCurve::set_point(self, i, p);
    }

    fn weight(&self, i: usize) -> Option<f64> {
        self.weights().map(|w| w[i])
    }

    fn set_weight(&mut self, i: usize, w: f64) {
        BSplineCurve::set_weight(self, i, w);
    }
}

impl PointNet<[usize; 2]> for TensorSurface {
    fn check_index(&self, [i, j]: [usize; 2]) -> Result<(), EditError> {
        let [nu, nv] = self.count();
        if i < nu && j < nv {
            return Ok(());
        }
        Err(EditError::new(
            "point",
            format!(
                "index [{i}, {j}] out of range (valid: [0..={}, 0..={}])",
                nu - 1,
                nv - 1
            ),
        ))
    }

    fn point(&self, [i, j]: [usize; 2]) -> DVec3 {
        TensorSurface::point(self, i, j)
    }

    fn set_point(&mut self, [i, j]: [usize; 2], p: DVec3) {
        TensorSurface::set_point(self, i, j, p);
    }

    fn weight(&self, [i, j]: [usize; 2]) -> Option<f64> {
        self.weights().map(|w| w[i * self.count()[1] + j])
    }

    fn set_weight(&mut self, [i, j]: [usize; 2], w: f64) {
        TensorSurface::set_weight(self, i, j, w);
    }
}

pub(super) fn check_index(field: &'static str, i: usize, n: usize) -> Result<(), EditError> {
    if i < n {
        Ok(())
    } else {
        Err(EditError::new(
            field,
            format!(
                "index {i} out of range (valid: 0..={})",
                n.saturating_sub(1)
            ),
        ))
    }
}

pub(super) fn check_vector(field: &'static str, v: DVec3) -> Result<(), EditError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(EditError::new(
            field,
            format!("{:?} is not a finite vector", v.to_array()),
        ))
    }
}

fn check_weight(w: f64) -> Result<(), EditError> {
    if w.is_finite() && w > 0.0 {
        Ok(())
    } else {
        Err(EditError::new(
            "weight",
            format!("weight {w} must be positive and finite"),
        ))
    }
}
