//! One pre-evaluated scene object: the sampler for its kind, edits, and drift control.

use super::dirty::DirtyRegion;
use super::erbs_curve::ErbsCurveSampler;
use super::erbs_surface::ErbsSurfaceSampler;
use super::grid::{PartialSet, SampleGrid};
use super::spline_curve::SplineCurveSampler;
use super::spline_surface::SplineSurfaceSampler;
use crate::geom::{BSplineCurve, ErbsCurve, ErbsSurface, TensorSurface};
use crate::scene::{EditOp, Index2, Samples, Shape};

/// A borrowed view of an object's model.
#[derive(Debug, Clone, Copy)]
pub enum ModelRef<'a> {
    Curve(&'a BSplineCurve),
    ErbsCurve(&'a ErbsCurve),
    Surface(&'a TensorSurface),
    ErbsSurface(&'a ErbsSurface),
}

/// What to keep per sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SampleMode {
    /// Curves c^(0..=g); surfaces every ∂^{a+b}, a, b ≤ g (the `prespline sample` contract).
    Derivatives(usize),
    /// Curves c, c'; surfaces S, Su, Sv and unit normals (what the renderer draws).
    Render,
}

/// Exact rebuild of the touched region after this many incremental edits, so rounding in the
/// delta path stays bounded however long a session runs (≈ µs per edit amortised).
pub const DEFAULT_REBUILD_INTERVAL: usize = 4096;

#[derive(Debug, Clone)]
enum Sampler {
    SplineCurve(SplineCurveSampler),
    ErbsCurve(ErbsCurveSampler),
    SplineSurface(SplineSurfaceSampler),
    ErbsSurface(ErbsSurfaceSampler),
}

/// A scene object with pre-evaluation data and its canonical sample grid.
#[derive(Debug, Clone)]
pub struct SampledObject {
    type_name: &'static str,
    sampler: Sampler,
    rebuild_interval: Option<usize>,
    edits_since_rebuild: usize,
    touched: DirtyRegion,
}

impl SampledObject {
    /// Pre-evaluates and fully samples `shape`.
    pub fn new(shape: &Shape, samples: Samples, mode: SampleMode) -> Self {
        let (curve_order, surface_set, normals) = match mode {
            SampleMode::Derivatives(g) => (g, PartialSet::Square(g), false),
            SampleMode::Render => (1, PartialSet::Shading, true),
        };
        let sampler = match (shape, samples) {
            (Shape::BezierCurve(c) | Shape::BSplineCurve(c), Samples::Curve(m)) => {
                Sampler::SplineCurve(SplineCurveSampler::new(c.clone(), m, curve_order))
            }
            (Shape::ErbsCurve(c), Samples::Curve(m)) => {
                Sampler::ErbsCurve(ErbsCurveSampler::new(c.clone(), m, curve_order))
            }
            (Shape::BezierSurface(s) | Shape::BSplineSurface(s), Samples::Surface(m)) => {
                Sampler::SplineSurface(SplineSurfaceSampler::new(
                    s.clone(),
                    m,
                    surface_set,
                    normals,
                ))
            }
            (Shape::ErbsSurface(s), Samples::Surface(m)) => {
                Sampler::ErbsSurface(ErbsSurfaceSampler::new(s.clone(), m, surface_set, normals))
            }
            (shape, samples) => panic!("{} cannot have {samples:?}", shape.type_name()),
        };
        Self {
            type_name: shape.type_name(),
            sampler,
            rebuild_interval: Some(DEFAULT_REBUILD_INTERVAL),
            edits_since_rebuild: 0,
            touched: DirtyRegion::Nothing,
        }
    }

    /// `None` disables the periodic exact rebuild (to measure raw drift in tests).
    pub fn set_rebuild_interval(&mut self, every: Option<usize>) {
        self.rebuild_interval = every;
    }

    pub fn type_name(&self) -> &'static str {
        self.type_name
    }

    pub fn grid(&self) -> &SampleGrid {
        match &self.sampler {
            Sampler::SplineCurve(s) => s.grid(),
            Sampler::ErbsCurve(s) => s.grid(),
            Sampler::SplineSurface(s) => s.grid(),
            Sampler::ErbsSurface(s) => s.grid(),
        }
    }

    /// Sample parameters per direction.
    pub fn params(&self) -> Vec<&[f64]> {
        match &self.sampler {
            Sampler::SplineCurve(s) => vec![s.params()],
            Sampler::ErbsCurve(s) => vec![s.params()],
            Sampler::SplineSurface(s) => s.params().to_vec(),
            Sampler::ErbsSurface(s) => s.params().to_vec(),
        }
    }

    /// The current model (after every applied edit).
    pub fn shape(&self) -> Shape {
        match &self.sampler {
            Sampler::SplineCurve(s) if self.type_name == "bezier_curve" => {
                Shape::BezierCurve(s.curve().clone())
            }
            Sampler::SplineCurve(s) => Shape::BSplineCurve(s.curve().clone()),
            Sampler::ErbsCurve(s) => Shape::ErbsCurve(s.curve().clone()),
            Sampler::SplineSurface(s) if self.type_name == "bezier_surface" => {
                Shape::BezierSurface(s.surface().clone())
            }
            Sampler::SplineSurface(s) => Shape::BSplineSurface(s.surface().clone()),
            Sampler::ErbsSurface(s) => Shape::ErbsSurface(s.surface().clone()),
        }
    }

    /// The current model by reference (no copy), for drawing control structures and overlays.
    pub fn model(&self) -> ModelRef<'_> {
        match &self.sampler {
            Sampler::SplineCurve(s) => ModelRef::Curve(s.curve()),
            Sampler::ErbsCurve(s) => ModelRef::ErbsCurve(s.curve()),
            Sampler::SplineSurface(s) => ModelRef::Surface(s.surface()),
            Sampler::ErbsSurface(s) => ModelRef::ErbsSurface(s.surface()),
        }
    }

    /// Applies a validated edit through the delta path; returns the samples it touched.
    pub fn apply(&mut self, op: &EditOp) -> DirtyRegion {
        let region = match (&mut self.sampler, op) {
            (
                Sampler::SplineCurve(s),
                EditOp::TranslatePoint {
                    point: Index2::One(k),
                    delta,
                },
            ) => s.translate_point(*k, *delta),
            (
                Sampler::SplineCurve(s),
                EditOp::SetWeight {
                    point: Index2::One(k),
                    weight,
                },
            ) => s.set_weight(*k, *weight),
            (
                Sampler::SplineSurface(s),
                EditOp::TranslatePoint {
                    point: Index2::Two(k, l),
                    delta,
                },
            ) => s.translate_point(*k, *l, *delta),
            (
                Sampler::SplineSurface(s),
                EditOp::SetWeight {
                    point: Index2::Two(k, l),
                    weight,
                },
            ) => s.set_weight(*k, *l, *weight),
            (
                Sampler::ErbsCurve(s),
                EditOp::TransformLocal {
                    local: Index2::One(l),
                    matrix,
                },
            ) => s.transform_local(*l, matrix),
            (
                Sampler::ErbsCurve(s),
                EditOp::TranslateLocalPoint {
                    local: Index2::One(l),
                    point: Index2::One(q),
                    delta,
                },
            ) => s.translate_local_point(*l, *q, *delta),
            (
                Sampler::ErbsSurface(s),
                EditOp::TransformLocal {
                    local: Index2::Two(k, l),
                    matrix,
                },
            ) => s.transform_local(*k, *l, matrix),
            (
                Sampler::ErbsSurface(s),
                EditOp::TranslateLocalPoint {
                    local: Index2::Two(k, l),
                    point: Index2::Two(a, b),
                    delta,
                },
            ) => s.translate_local_point(*k, *l, *a, *b, *delta),
            (
                Sampler::SplineCurve(s),
                EditOp::SetPoint {
                    point: Index2::One(k),
                    position,
                },
            ) => s.set_point(*k, *position),
            (
                Sampler::SplineSurface(s),
                EditOp::SetPoint {
                    point: Index2::Two(k, l),
                    position,
                },
            ) => s.set_point(*k, *l, *position),
            (
                Sampler::ErbsCurve(s),
                EditOp::SetLocalPoints {
                    local: Index2::One(l),
                    points,
                },
            ) => s.set_local_points(*l, points),
            (
                Sampler::ErbsSurface(s),
                EditOp::SetLocalPoints {
                    local: Index2::Two(k, l),
                    points,
                },
            ) => s.set_local_points(*k, *l, points),
            (_, op) => panic!(
                "edit {op:?} does not fit a {} (validate first)",
                self.type_name
            ),
        };
        self.touched =
            std::mem::replace(&mut self.touched, DirtyRegion::Nothing).union(region.clone());
        self.edits_since_rebuild += 1;
        if self
            .rebuild_interval
            .is_some_and(|n| self.edits_since_rebuild >= n)
        {
            self.rebuild_touched();
        }
        region
    }

    /// Exact re-evaluation of everything touched since the last rebuild (drift reset).
    pub fn rebuild_touched(&mut self) -> DirtyRegion {
        let touched = std::mem::replace(&mut self.touched, DirtyRegion::Nothing);
        self.edits_since_rebuild = 0;
        match (&mut self.sampler, touched) {
            (_, DirtyRegion::Nothing) => DirtyRegion::Nothing,
            (Sampler::SplineCurve(s), DirtyRegion::Curve(r)) => s.rebuild(r),
            (Sampler::SplineSurface(s), DirtyRegion::Surface { rows, cols }) => {
                s.rebuild(rows, cols)
            }
            (Sampler::ErbsCurve(s), _) => s.full(),
            (Sampler::ErbsSurface(s), _) => s.rebuild(),
            (_, region) => panic!("region {region:?} does not fit a {}", self.type_name),
        }
    }

    /// Full sampling from the pre-evaluated data, as the constructor does.
    pub fn rebuild_all(&mut self) -> DirtyRegion {
        self.touched = DirtyRegion::Nothing;
        self.edits_since_rebuild = 0;
        match &mut self.sampler {
            Sampler::SplineCurve(s) => s.full(),
            Sampler::ErbsCurve(s) => s.full(),
            Sampler::SplineSurface(s) => s.full(),
            Sampler::ErbsSurface(s) => s.full(),
        }
    }

    /// Samples in the grid (rows × cols).
    pub fn sample_count(&self) -> usize {
        let [a, b] = self.grid().dims;
        a * b
    }
}
