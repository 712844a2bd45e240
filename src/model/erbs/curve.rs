//! The ERBS curve kind: its model and what its edits need of it.

use super::*;
use crate::geom::erbs::{ErbsCurve, LocalCurve};
use crate::geom::shape::{ShapeChange, erbs_knot_probes, erbs_probes, shape_change};
use crate::geom::{BFunctionKind, GeomError};
use crate::model::edit::EditError;
use crate::model::{MAX_CURVE_SAMPLES, check_samples};
use glam::{DMat4, DVec3};
use std::fmt::Debug;

/// An ERBS curve with its sample count.
#[derive(Debug, Clone, PartialEq)]
pub struct ErbsCurveModel {
    curve: ErbsCurve,
    samples: usize,
}

impl ErbsCurveModel {
    pub fn new(curve: ErbsCurve, samples: usize) -> Result<Self, EditError> {
        check_samples(samples, MAX_CURVE_SAMPLES)?;
        Ok(Self { curve, samples })
    }

    #[must_use]
    pub fn curve(&self) -> &ErbsCurve {
        &self.curve
    }

    #[must_use]
    pub fn samples(&self) -> usize {
        self.samples
    }
}

impl ErbsNet for ErbsCurve {
    type Index = usize;
    type Local = LocalCurve;
    type Knot = f64;
    type Degree = usize;
    type Count = usize;
    type Model = ErbsCurveModel;

    fn of(m: &ErbsCurveModel) -> &Self {
        &m.curve
    }

    fn of_mut(m: &mut ErbsCurveModel) -> &mut Self {
        &mut m.curve
    }

    fn in_model(self, m: &ErbsCurveModel) -> ErbsCurveModel {
        ErbsCurveModel {
            curve: self,
            samples: m.samples,
        }
    }

    fn local_at(&self, path: &[usize]) -> Option<&LocalCurve> {
        ErbsCurve::local_at(self, path)
    }

    fn check_path(&self, path: &[usize]) -> Result<(), EditError> {
        let mut level = self;
        for (depth, &l) in path.iter().enumerate() {
            check_count("local", l, level.local_curves().len())
                .map_err(|e| step_error(depth, e))?;
            match (&level.local_curves()[l], depth + 1 < path.len()) {
                (LocalCurve::Erbs(e), true) => level = e,
                (LocalCurve::Spline { .. }, true) => {
                    return Err(EditError::new(
                        "local",
                        format!("step {depth} of the path is a polynomial local: it has no locals"),
                    ));
                }
                _ => {}
            }
        }
        Ok(())
    }

    fn points(local: &LocalCurve) -> Option<&[DVec3]> {
        local.points()
    }

    fn check_point(local: &LocalCurve, p: usize) -> Result<(), EditError> {
        check_count("point", p, local.points().map_or(0, <[DVec3]>::len))
    }

    fn as_erbs(local: &LocalCurve) -> Option<&Self> {
        match local {
            LocalCurve::Erbs(e) => Some(e),
            LocalCurve::Spline { .. } => None,
        }
    }

    fn wrap(e: Self) -> LocalCurve {
        LocalCurve::Erbs(Box::new(e))
    }

    fn transform_local(&mut self, path: &[usize], a: &DMat4) {
        ErbsCurve::transform_local(self, path, a);
    }

    fn translate_local_point(&mut self, path: &[usize], p: usize, d: DVec3) {
        ErbsCurve::translate_local_point(self, path, p, d);
    }

    fn set_local_points(&mut self, path: &[usize], points: &[DVec3]) {
        ErbsCurve::set_local_points(self, path, points);
    }

    fn set_local(&mut self, path: &[usize], local: LocalCurve) {
        ErbsCurve::set_local(self, path, local);
    }

    fn refine(&self, t: f64, degree: Option<usize>) -> Result<Self, GeomError> {
        self.insert_knot(t, degree).map(|(c, _)| c)
    }

    fn build(
        local: &LocalCurve,
        n: usize,
        degree: usize,
        bf: BFunctionKind,
    ) -> Result<Self, GeomError> {
        match local {
            LocalCurve::Spline { curve, .. } => ErbsCurve::from_curve(curve, n, degree, bf, false),
            LocalCurve::Erbs(_) => Err(GeomError::new("to_erbs", "already an ERBS local")),
        }
    }

    fn count_of(side: usize) -> usize {
        side
    }

    fn locals_in(count: usize) -> u128 {
        count as u128
    }

    fn build_size(n: usize, degree: usize) -> (String, u128) {
        (
            format!("{n} local curves of degree {degree}"),
            ErbsCurve::from_curve_bytes(n, degree),
        )
    }

    fn bfunction(&self) -> BFunctionKind {
        ErbsCurve::bfunction(self)
    }

    fn check_degree(d: usize) -> Result<(), EditError> {
        check_max_degree("degree", d)
    }

    const NOUN: &'static str = "curve";
    const LOCAL_NOUN: &'static str = "local curve";

    fn refinement_change(&self, refined: &Self, t: f64) -> ShapeChange {
        let degree = self.local_curves().iter().map(LocalCurve::degree).max();
        let per = degree.unwrap_or(0) + 1;
        let mut at = erbs_probes(self.knots(), per, Some(self.knots().locate(t)));
        at.push(t);
        shape_change(self, refined, &at)
    }

    fn build_change(local: &LocalCurve, built: &Self) -> ShapeChange {
        let at = erbs_knot_probes(built.knots());
        shape_change(local, &Self::wrap(built.clone()), &at)
    }
}
