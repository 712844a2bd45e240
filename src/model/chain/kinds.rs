//! The chain kinds' entries in the table of kinds: what ties each model to its sampler (the
//! B-spline of its Bézier chain), its scene-file fields and its control polygon.

use super::file;
use super::sampler::ChainCurveSampler;
use super::{BezierSplineEdit, BezierSplineModel, CatmullRomEdit, CatmullRomModel, ChainModel};
use crate::fields::{At, ReadCtx, SceneError};
use crate::model::controls::{ControlDisplay, Grip};
use crate::model::edit::EditError;
use crate::model::index::Index2;
use crate::model::kind::Kind;
use crate::model::points::PointEdit;
use crate::model::spline::curve::CurveModel;
use crate::sampling::SampleMode;
use crate::sampling::budget::Extent;
use glam::DVec3;
use serde_json::{Map, Value};

/// `impl Kind` for a chain kind: the entries both share (one sample direction, the chain's
/// B-spline for sampling, derivatives and conversion, no weights), the kind's file readers
/// and writer named by `file`, and its own entries (junctions, extent, polygon, moves).
macro_rules! chain_kind {
    (
        $model:ty, $edit:ty, $label:literal, $ty:literal,
        file: ($read:ident, $write:ident, $read_edit:ident),
        { $($own:tt)* }
    ) => {
        impl Kind for $model {
            type Edit = $edit;
            type Sampler = ChainCurveSampler<$edit>;
            const SURFACE: bool = false;
            const LABEL: &'static str = $label;
            const TYPES: &'static [&'static str] = &[$ty];

            fn read(
                _: &str,
                at: &At,
                obj: &Map<String, Value>,
                ctx: &ReadCtx<'_>,
            ) -> Result<Self, SceneError> {
                file::$read(at, obj, ctx.common)
            }

            fn write(&self, out: &mut String) {
                file::$write(self, out);
            }

            fn read_edit(&self, at: &At, obj: &Map<String, Value>) -> Result<$edit, SceneError> {
                file::$read_edit(at, obj)
            }

            fn sample_dims(&self) -> [usize; 2] {
                [self.samples(), 1]
            }

            fn with_samples(&self, samples: [usize; 2]) -> Result<Self, EditError> {
                Self::new(self.spline().clone(), samples[0])
            }

            fn domain(&self) -> Vec<(f64, f64)> {
                vec![self.spline().domain()]
            }

            fn sampler(&self, mode: SampleMode) -> Self::Sampler {
                ChainCurveSampler::new(self.clone(), mode.layout().0)
            }

            fn to_bspline_curve(&self) -> Option<CurveModel> {
                Some(self.chain_form())
            }

            fn derivatives_at(
                &self,
                [u, _]: [f64; 2],
                order: usize,
                _: &[(usize, usize)],
                out: &mut [DVec3],
            ) {
                out.copy_from_slice(&self.chain_form().curve().derivatives(u, order));
            }

            fn weight_edit(&self, _grip: Grip, _weight: f64) -> Result<Self::Edit, String> {
                Err(format!(
                    "a {} has no weights: B converts it to a bspline_curve first",
                    self.type_name()
                ))
            }

            $($own)*
        }
    };
}

chain_kind!(
    CatmullRomModel, CatmullRomEdit, "Catmull–Rom", "catmull_rom",
    file: (read_catmull_rom, write_catmull_rom, read_catmull_rom_edit),
    {
        fn junctions(&self) -> Option<(Vec<f64>, bool)> {
            Some((self.spline().breakpoints(), self.spline().closed()))
        }

        /// Cubic segments.
        fn extent(&self) -> Extent {
            chain_extent(self.samples(), 3, self.spline().points().len())
        }

        /// The interpolated points.
        fn controls(&self) -> ControlDisplay {
            ControlDisplay::polygon(self.spline().points().to_vec())
        }

        fn move_edit(&self, grip: Grip, delta: DVec3) -> Option<CatmullRomEdit> {
            let Grip::Point(Index2::One(point)) = grip else {
                return None;
            };
            Some(CatmullRomEdit::Point(PointEdit::Move { point, delta }))
        }
    }
);

chain_kind!(
    BezierSplineModel, BezierSplineEdit, "Bézier spline", "bezier_spline",
    file: (read_bezier_spline, write_bezier_spline, read_bezier_spline_edit),
    {
        fn junctions(&self) -> Option<(Vec<f64>, bool)> {
            Some((self.spline().knots().to_vec(), false))
        }

        fn extent(&self) -> Extent {
            let s = self.spline();
            chain_extent(self.samples(), s.degree(), s.handles().len())
        }

        /// Bézier points, or the de Boor polygon of splines edited through it (their Bézier
        /// points are drawn as an overlay).
        fn controls(&self) -> ControlDisplay {
            ControlDisplay::polygon(self.spline().handles())
        }

        fn move_edit(&self, grip: Grip, delta: DVec3) -> Option<BezierSplineEdit> {
            let Grip::Point(Index2::One(point)) = grip else {
                return None;
            };
            Some(BezierSplineEdit::Move { point, delta })
        }
    }
);

/// A chain of degree-`degree` Bézier segments through `handles` user points: the sampler
/// pre-evaluates the chain's B-spline, about `degree` chain points per handle, besides the
/// handles the model and the display keep.
fn chain_extent(samples: usize, degree: usize, handles: usize) -> Extent {
    let chain = Extent::polynomial(&[samples], &[degree], false).with_net(
        degree.max(1) * handles,
        (degree.max(1) + 1) * handles,
        1,
        false,
    );
    let (vertices, bytes) = (handles, chain.control_bytes + 2 * 24 * handles as u128);
    chain.with_controls(vertices, bytes)
}
