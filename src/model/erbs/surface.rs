//! The ERBS surface kind: its model and what its edits need of it.

use super::*;
use crate::geom::erbs::{ErbsSurface, LocalPatch};
use crate::geom::shape::{ShapeChange, erbs_knot_probes, erbs_probes, shape_change};
use crate::geom::{BFunctionKind, GeomError};
use crate::model::check_surface_samples;
use crate::model::edit::EditError;
use glam::{DMat4, DVec3};
use std::fmt::Debug;

/// An ERBS surface with its sample counts [mu, mv].
#[derive(Debug, Clone, PartialEq)]
pub struct ErbsSurfaceModel {
    surface: ErbsSurface,
    samples: [usize; 2],
}

impl ErbsSurfaceModel {
    pub fn new(surface: ErbsSurface, samples: [usize; 2]) -> Result<Self, EditError> {
        check_surface_samples(samples)?;
        Ok(Self { surface, samples })
    }

    #[must_use]
    pub fn surface(&self) -> &ErbsSurface {
        &self.surface
    }

    #[must_use]
    pub fn samples(&self) -> [usize; 2] {
        self.samples
    }
}

impl ErbsNet for ErbsSurface {
    type Index = [usize; 2];
    type Local = LocalPatch;
    type Knot = (usize, f64);
    type Degree = [usize; 2];
    type Count = [usize; 2];
    type Model = ErbsSurfaceModel;

    fn of(m: &ErbsSurfaceModel) -> &Self {
        &m.surface
    }

    fn of_mut(m: &mut ErbsSurfaceModel) -> &mut Self {
        &mut m.surface
    }

    fn in_model(self, m: &ErbsSurfaceModel) -> ErbsSurfaceModel {
        ErbsSurfaceModel {
            surface: self,
            samples: m.samples,
        }
    }

    fn local_at(&self, path: &[[usize; 2]]) -> Option<&LocalPatch> {
        ErbsSurface::local_at(self, path)
    }

    fn check_path(&self, path: &[[usize; 2]]) -> Result<(), EditError> {
        let mut level = self;
        for (depth, &[k, l]) in path.iter().enumerate() {
            check_pair("local", [k, l], level.count()).map_err(|e| step_error(depth, e))?;
            match (level.local_patch(k, l), depth + 1 < path.len()) {
                (LocalPatch::Erbs(e), true) => level = e,
                (LocalPatch::Spline { .. }, true) => {
                    return Err(EditError::new(
                        "local",
                        format!("step {depth} of the path is a polynomial patch: it has no locals"),
                    ));
                }
                _ => {}
            }
        }
        Ok(())
    }

    fn points(local: &LocalPatch) -> Option<&[DVec3]> {
        local.net().map(|(_, p)| p)
    }

    fn check_point(local: &LocalPatch, p: [usize; 2]) -> Result<(), EditError> {
        check_pair("point", p, local.net().map_or([0, 0], |(c, _)| c))
    }

    fn as_erbs(local: &LocalPatch) -> Option<&Self> {
        match local {
            LocalPatch::Erbs(e) => Some(e),
            LocalPatch::Spline { .. } => None,
        }
    }

    fn wrap(e: Self) -> LocalPatch {
        LocalPatch::Erbs(Box::new(e))
    }

    fn transform_local(&mut self, path: &[[usize; 2]], a: &DMat4) {
        ErbsSurface::transform_local(self, path, a);
    }

    fn translate_local_point(&mut self, path: &[[usize; 2]], p: [usize; 2], d: DVec3) {
        ErbsSurface::translate_local_point(self, path, p, d);
    }

    fn set_local_points(&mut self, path: &[[usize; 2]], points: &[DVec3]) {
        ErbsSurface::set_local_points(self, path, points);
    }

    fn set_local(&mut self, path: &[[usize; 2]], local: LocalPatch) {
        ErbsSurface::set_local(self, path, local);
    }

    fn refine(
        &self,
        (dir, t): (usize, f64),
        degree: Option<[usize; 2]>,
    ) -> Result<Self, GeomError> {
        if dir > 1 {
            return Err(GeomError::new("insert_knot", "the direction is u or v"));
        }
        self.insert_knot(dir, t, degree).map(|(s, _)| s)
    }

    fn build(
        local: &LocalPatch,
        count: [usize; 2],
        degree: [usize; 2],
        bf: BFunctionKind,
    ) -> Result<Self, GeomError> {
        match local {
            LocalPatch::Spline { surface, .. } => {
                ErbsSurface::from_surface(surface, count, degree, bf, [false, false])
            }
            LocalPatch::Erbs(_) => Err(GeomError::new("to_erbs", "already an ERBS local")),
        }
    }

    fn count_of(side: usize) -> [usize; 2] {
        [side, side]
    }

    fn locals_in(count: [usize; 2]) -> u128 {
        count[0] as u128 * count[1] as u128
    }

    fn build_size(count: [usize; 2], degree: [usize; 2]) -> (String, u128) {
        (
            format!(
                "{}×{} local patches of degree [{}, {}]",
                count[0], count[1], degree[0], degree[1]
            ),
            ErbsSurface::from_surface_bytes(count, degree),
        )
    }

    fn bfunction(&self) -> BFunctionKind {
        ErbsSurface::bfunction(self)
    }

    fn check_degree([du, dv]: [usize; 2]) -> Result<(), EditError> {
        check_max_degree("degree", du.max(dv))
    }

    const NOUN: &'static str = "surface";
    const LOCAL_NOUN: &'static str = "local patch";

    /// On a grid: the knots and two parameters inside each interval beside the refined one in
    /// its direction, against every knot of the other, and the line u = t (or v = t) there too
    /// (the new patches interpolate at their knot crossings). Fewer probes than a curve gets:
    /// an ERBS surface point costs a few microseconds, and a misplaced restriction of a row of
    /// patches shows all along it.
    fn refinement_change(&self, refined: &Self, (dir, t): (usize, f64)) -> ShapeChange {
        let knots = self.knots();
        let mut beside = [0, 1].map(|d| erbs_probes(&knots[d], 0, None));
        beside[dir] = erbs_probes(&knots[dir], 2, Some(knots[dir].locate(t)));
        let mut line = [0, 1].map(|d| erbs_knot_probes(&knots[d]));
        line[dir] = vec![t];
        shape_change(self, refined, &beside).worse(shape_change(self, refined, &line))
    }

    fn build_change(local: &LocalPatch, built: &Self) -> ShapeChange {
        let at = built.knots().each_ref().map(erbs_knot_probes);
        shape_change(local, &Self::wrap(built.clone()), &at)
    }
}
