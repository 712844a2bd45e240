//! The ERBS kinds' entries in the table of kinds: what ties each model to its sampler, its
//! scene-file fields and its control display (every polynomial local at any depth).

use super::controls::{curve_controls, curve_display_size, patch_controls, patch_display_size};
use super::curve_sampler::ErbsCurveSampler;
use super::file;
use super::surface_sampler::ErbsSurfaceSampler;
use super::{
    ErbsCurveEdit, ErbsCurveModel, ErbsSurfaceEdit, ErbsSurfaceModel, LocalEdit, LocalPath,
};
use crate::fields::{At, ReadCtx, SceneError};
use crate::geom::{ErbsCurve, ErbsSurface};
use crate::model::controls::{ControlDisplay, Grip};
use crate::model::edit::EditError;
use crate::model::index::Index2;
use crate::model::kind::Kind;
use crate::sampling::SampleMode;
use crate::sampling::budget::Extent;
use glam::DVec3;
use serde_json::{Map, Value};

impl Kind for ErbsCurveModel {
    type Edit = ErbsCurveEdit;
    type Sampler = ErbsCurveSampler;
    const SURFACE: bool = false;
    const LABEL: &'static str = "ERBS curve";

    const TYPES: &'static [&'static str] = &["erbs_curve"];

    fn read(
        _: &str,
        at: &At,
        obj: &Map<String, Value>,
        ctx: &ReadCtx<'_>,
    ) -> Result<Self, SceneError> {
        file::read_curve(at, obj, ctx)
    }

    fn write(&self, out: &mut String) {
        file::write_erbs_curve(out, self.curve());
    }

    fn read_edit(&self, at: &At, obj: &Map<String, Value>) -> Result<ErbsCurveEdit, SceneError> {
        file::read_curve_edit(at, obj)
    }

    fn sample_dims(&self) -> [usize; 2] {
        [self.samples(), 1]
    }

    fn with_samples(&self, samples: [usize; 2]) -> Result<Self, EditError> {
        Self::new(self.curve().clone(), samples[0])
    }

    fn domain(&self) -> Vec<(f64, f64)> {
        vec![self.curve().domain()]
    }

    fn sampler(&self, mode: SampleMode) -> ErbsCurveSampler {
        ErbsCurveSampler::new(self.clone(), mode.layout().0)
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
        let (vertices, display) = curve_display_size(c);
        let extent = Extent::erbs_curve(c, self.samples());
        // The sampler's copy of the model: its locals with their points.
        let model = ErbsCurve::from_curve_bytes(c.local_curves().len(), extent.degree[0]);
        extent.with_controls(vertices, display + model)
    }

    fn controls(&self) -> ControlDisplay {
        curve_controls(self.curve(), None)
    }

    fn local_controls(&self, local: LocalPath<Index2>) -> Option<ControlDisplay> {
        Some(curve_controls(self.curve(), Some(local)))
    }

    fn move_edit(&self, grip: Grip, delta: DVec3) -> Option<ErbsCurveEdit> {
        let Grip::LocalPoint {
            local,
            point: Index2::One(point),
        } = grip
        else {
            return None;
        };
        Some(ErbsCurveEdit::Local(LocalEdit::MovePoint {
            local: local.to_curve()?,
            point,
            delta,
        }))
    }
}

impl Kind for ErbsSurfaceModel {
    type Edit = ErbsSurfaceEdit;
    type Sampler = ErbsSurfaceSampler;
    const SURFACE: bool = true;
    const LABEL: &'static str = "ERBS surface";

    const TYPES: &'static [&'static str] = &["erbs_surface"];

    fn read(
        _: &str,
        at: &At,
        obj: &Map<String, Value>,
        ctx: &ReadCtx<'_>,
    ) -> Result<Self, SceneError> {
        file::read_surface(at, obj, ctx)
    }

    fn write(&self, out: &mut String) {
        file::write_erbs_surface(out, self.surface());
    }

    fn read_edit(&self, at: &At, obj: &Map<String, Value>) -> Result<ErbsSurfaceEdit, SceneError> {
        file::read_surface_edit(at, obj)
    }

    fn sample_dims(&self) -> [usize; 2] {
        self.samples()
    }

    fn with_samples(&self, samples: [usize; 2]) -> Result<Self, EditError> {
        Self::new(self.surface().clone(), samples)
    }

    fn domain(&self) -> Vec<(f64, f64)> {
        self.surface().domain().to_vec()
    }

    fn sampler(&self, mode: SampleMode) -> ErbsSurfaceSampler {
        let (_, set, normals) = mode.layout();
        ErbsSurfaceSampler::new(self.clone(), set, normals)
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
        let (vertices, display) = patch_display_size(s);
        let extent = Extent::erbs_surface(s, self.samples());
        let model =
            ErbsSurface::from_surface_bytes(s.count(), [extent.degree[0], extent.degree[1]]);
        extent.with_controls(vertices, display + model)
    }

    fn controls(&self) -> ControlDisplay {
        patch_controls(self.surface(), None)
    }

    fn local_controls(&self, local: LocalPath<Index2>) -> Option<ControlDisplay> {
        Some(patch_controls(self.surface(), Some(local)))
    }

    fn move_edit(&self, grip: Grip, delta: DVec3) -> Option<ErbsSurfaceEdit> {
        let Grip::LocalPoint {
            local,
            point: Index2::Two(a, b),
        } = grip
        else {
            return None;
        };
        Some(ErbsSurfaceEdit::Local(LocalEdit::MovePoint {
            local: local.to_surface()?,
            point: [a, b],
            delta,
        }))
    }
}
