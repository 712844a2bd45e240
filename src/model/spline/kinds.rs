//! The spline kinds' entries in the table of kinds: what ties each model to its sampler, its
//! scene-file fields and its control display.

use super::curve::{CurveEdit, CurveModel};
use super::curve_sampler::SplineCurveSampler;
use super::file;
use super::form::SplineForm;
use super::surface::{SurfaceEdit, SurfaceModel};
use super::surface_sampler::SplineSurfaceSampler;
use crate::fields::{At, ReadCtx, SceneError};
use crate::geom::surface::TensorSurface;
use crate::model::controls::{ControlDisplay, Grip};
use crate::model::edit::EditError;
use crate::model::index::Index2;
use crate::model::kind::Kind;
use crate::model::points::PointEdit;
use crate::sampling::SampleMode;
use crate::sampling::budget::Extent;
use glam::DVec3;
use serde_json::{Map, Value};

impl Kind for CurveModel {
    type Edit = CurveEdit;
    type Sampler = SplineCurveSampler;
    const SURFACE: bool = false;
    const LABEL: &'static str = "curve";

    const TYPES: &'static [&'static str] = file::CURVE_TYPES;

    fn read(
        ty: &str,
        at: &At,
        obj: &Map<String, Value>,
        ctx: &ReadCtx<'_>,
    ) -> Result<Self, SceneError> {
        file::read_curve(ty, at, obj, ctx.common)
    }

    fn write(&self, out: &mut String) {
        file::write_curve(self, out);
    }

    fn read_edit(&self, at: &At, obj: &Map<String, Value>) -> Result<CurveEdit, SceneError> {
        file::read_curve_edit(at, obj)
    }

    fn type_name(&self) -> &'static str {
        match self.form() {
            SplineForm::Bezier => "bezier_curve",
            SplineForm::BSpline => "bspline_curve",
        }
    }

    fn sample_dims(&self) -> [usize; 2] {
        [self.samples(), 1]
    }

    fn with_samples(&self, samples: [usize; 2]) -> Result<Self, EditError> {
        Self::new(self.form(), self.curve().clone(), samples[0])
    }

    fn domain(&self) -> Vec<(f64, f64)> {
        vec![self.curve().domain()]
    }

    fn degrees(&self) -> Vec<usize> {
        vec![self.curve().degree()]
    }

    fn weights(&self) -> Option<&[f64]> {
        self.curve().weights()
    }

    fn breakpoints(&self) -> Vec<Vec<f64>> {
        let (a, b) = self.curve().domain();
        vec![distinct_in(self.curve().knots().as_slice(), a, b)]
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
        out.copy_from_slice(&self.curve().derivatives(u, order));
    }

    fn extent(&self) -> Extent {
        let c = self.curve();
        let n = c.points().len();
        Extent::polynomial(&[self.samples()], &[c.degree()], c.is_rational())
            .with_net(n, c.knots().len(), 1, c.is_rational())
            .with_shared_tables(table_key(&[(c.knots(), c.degree(), n, self.samples())]))
    }

    fn controls(&self) -> ControlDisplay {
        ControlDisplay::polygon(self.curve().points().to_vec())
    }

    fn control_point(&self, point: Index2) -> Option<DVec3> {
        let Index2::One(k) = point else { return None };
        self.curve().points().get(k).copied()
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
        self.curve().points().get(k)?;
        Some(self.curve().weights().map_or(1.0, |w| w[k]))
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

impl Kind for SurfaceModel {
    type Edit = SurfaceEdit;
    type Sampler = SplineSurfaceSampler;
    const SURFACE: bool = true;
    const LABEL: &'static str = "surface";

    const TYPES: &'static [&'static str] = file::SURFACE_TYPES;

    fn read(
        ty: &str,
        at: &At,
        obj: &Map<String, Value>,
        ctx: &ReadCtx<'_>,
    ) -> Result<Self, SceneError> {
        file::read_surface(ty, at, obj, ctx.common)
    }

    fn write(&self, out: &mut String) {
        file::write_surface(self, out);
    }

    fn read_edit(&self, at: &At, obj: &Map<String, Value>) -> Result<SurfaceEdit, SceneError> {
        file::read_surface_edit(at, obj)
    }

    fn type_name(&self) -> &'static str {
        match self.form() {
            SplineForm::Bezier => "bezier_surface",
            SplineForm::BSpline => "bspline_surface",
        }
    }

    fn sample_dims(&self) -> [usize; 2] {
        self.samples()
    }

    fn with_samples(&self, samples: [usize; 2]) -> Result<Self, EditError> {
        Self::new(self.form(), self.surface().clone(), samples)
    }

    fn domain(&self) -> Vec<(f64, f64)> {
        self.surface().domain().to_vec()
    }

    fn degrees(&self) -> Vec<usize> {
        self.surface().degree().to_vec()
    }

    fn weights(&self) -> Option<&[f64]> {
        self.surface().weights()
    }

    fn tensor(&self) -> Option<&TensorSurface> {
        Some(self.surface())
    }

    fn breakpoints(&self) -> Vec<Vec<f64>> {
        let s = self.surface();
        (0..2)
            .map(|dir| {
                let (a, b) = s.domain()[dir];
                distinct_in(s.knots()[dir].as_slice(), a, b)
            })
            .collect()
    }

    fn sampler(&self, mode: SampleMode) -> SplineSurfaceSampler {
        let (_, set, normals) = mode.layout();
        SplineSurfaceSampler::new(self.clone(), set, normals)
    }

    fn derivatives_at(
        &self,
        [u, v]: [f64; 2],
        order: usize,
        list: &[(usize, usize)],
        out: &mut [DVec3],
    ) {
        let p = self.surface().derivatives(u, v, order);
        for (slot, &(a, b)) in list.iter().enumerate() {
            out[slot] = p.get(a, b);
        }
    }

    fn extent(&self) -> Extent {
        let s = self.surface();
        let [ku, kv] = s.knots();
        let ([du, dv], [nu, nv], [mu, mv]) = (s.degree(), s.count(), self.samples());
        Extent::polynomial(&self.samples(), &s.degree(), s.is_rational())
            .with_net(s.points().len(), ku.len() + kv.len(), 2, s.is_rational())
            .with_shared_tables(table_key(&[(ku, du, nu, mu), (kv, dv, nv, mv)]))
    }

    fn controls(&self) -> ControlDisplay {
        ControlDisplay::net(self.surface().count(), self.surface().points().to_vec())
    }

    fn control_point(&self, point: Index2) -> Option<DVec3> {
        let Index2::Two(i, j) = point else {
            return None;
        };
        let [rows, cols] = self.surface().count();
        (i < rows && j < cols).then(|| self.surface().point(i, j))
    }

    fn move_edit(&self, grip: Grip, delta: DVec3) -> Option<SurfaceEdit> {
        let Grip::Point(Index2::Two(i, j)) = grip else {
            return None;
        };
        Some(SurfaceEdit::Point(PointEdit::Move {
            point: [i, j],
            delta,
        }))
    }

    fn weight(&self, grip: Grip) -> Option<f64> {
        let Grip::Point(Index2::Two(i, j)) = grip else {
            return None;
        };
        let [rows, cols] = self.surface().count();
        (i < rows && j < cols).then(|| self.surface().weights().map_or(1.0, |w| w[i * cols + j]))
    }

    fn weight_edit(&self, grip: Grip, weight: f64) -> Result<SurfaceEdit, String> {
        match grip {
            Grip::Point(Index2::Two(i, j)) => Ok(SurfaceEdit::Point(PointEdit::Weight {
                point: [i, j],
                weight,
            })),
            _ => Err(format!("a {} has no such control point", self.type_name())),
        }
    }
}

/// What a B-spline object's Hermite tables are built from, hashed: objects with equal keys
/// share their tables (`HermiteTable::shared`), which the memory budget counts once.
fn table_key(directions: &[(&[f64], usize, usize, usize)]) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    for &(knots, degree, count, samples) in directions {
        knots.iter().for_each(|k| k.to_bits().hash(&mut h));
        (degree, count, samples).hash(&mut h);
    }
    h.finish()
}

/// The distinct values of `knots` in [a, b], a and b included.
fn distinct_in(knots: &[f64], a: f64, b: f64) -> Vec<f64> {
    let mut out = vec![a];
    out.extend(knots.iter().copied().filter(|&k| k > a && k < b));
    out.push(b);
    out.dedup();
    out
}
