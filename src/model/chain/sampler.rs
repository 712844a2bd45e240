//! Pre-evaluated Catmull–Rom and Bézier splines: the B-spline of their Bézier chain (knots of
//! multiplicity d at the junctions) in a [`SplineCurveSampler`], fed one control point at a time.

use crate::model::spline::curve_sampler::SplineCurveSampler;
use crate::model::{ChainEdit, ChainModel, CurveEdit, Index2, PointEdit, Target};
use crate::sampling::dirty::{DirtyRegion, DirtySet};
use crate::sampling::grid::SampleGrid;
use crate::sampling::object::Sampler;

/// A chain kind's model and the pre-evaluation of its B-spline form. The B-spline's control
/// points are always the model's chain points, bit for bit.
#[derive(Debug, Clone)]
pub struct ChainCurveSampler<E: ChainEdit> {
    model: E::Model,
    chain: SplineCurveSampler,
}

impl<E: ChainEdit> ChainCurveSampler<E> {
    pub fn new(model: E::Model, order: usize) -> Self {
        let chain = SplineCurveSampler::new(model.chain_form(), order);
        Self { model, chain }
    }
}

impl<E: ChainEdit> Sampler for ChainCurveSampler<E> {
    type Model = E::Model;
    type Edit = E;

    fn model(&self) -> &E::Model {
        &self.model
    }

    fn grid(&self) -> &SampleGrid {
        self.chain.grid()
    }

    fn params(&self) -> Vec<&[f64]> {
        self.chain.params()
    }

    /// The chain points the edit changes, each as an exact `Set` through the B-spline delta
    /// path: only the samples of the segments around them are touched (a Catmull–Rom point:
    /// at most 4 segments).
    fn apply_prepared(&mut self, edit: &E, result: Option<E::Model>) -> DirtyRegion {
        let touched = edit.chain_points(&self.model);
        edit.apply_prepared(&mut self.model, result);
        let mut region = DirtyRegion::NOTHING;
        for point in touched {
            let position = self.model.chain_point(point);
            let now = self.chain.model().curve().points()[point];
            if position.to_array().map(f64::to_bits) == now.to_array().map(f64::to_bits) {
                continue;
            }
            let set = CurveEdit::Point(PointEdit::Set { point, position });
            region = region.union(self.chain.apply(&set));
        }
        region
    }

    fn rebuild(&mut self, region: DirtyRegion) -> DirtyRegion {
        self.chain.rebuild(region)
    }

    fn full(&mut self) -> DirtyRegion {
        self.chain.full()
    }
}

impl<E: ChainEdit> crate::model::kind::Support for ChainCurveSampler<E> {
    /// The segments around every chain point a move of the handle reaches, as disjoint runs
    /// (a closed Catmull–Rom spline's first point reaches both ends).
    fn support(&self, target: Target) -> Vec<DirtyRegion> {
        let Target::Point(Index2::One(handle)) = target else {
            return vec![DirtyRegion::whole(self.grid().dims)];
        };
        let mut runs = DirtySet::default();
        for point in E::handle_points(&self.model, handle) {
            for r in self.chain.support(Target::Point(Index2::One(point))) {
                runs.insert(r.rows);
            }
        }
        runs.ranges()
            .iter()
            .map(|r| DirtyRegion::curve(r.clone()))
            .collect()
    }
}
