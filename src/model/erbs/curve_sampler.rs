//! Pre-evaluated ERBS curves, hierarchically: every local curve is pre-sampled at its parent's
//! parameters in its support (a polynomial local through its Hermite table, an ERBS local as a
//! level of its own), and blended by the Leibniz rule. An edit at any depth returns the change
//! of that level's samples over the edited local's support; each parent blends it in over the
//! same samples, so the cost at every level is what the edit touches.

use super::edit::apply_keeping_old;
use crate::geom::erbs::{ErbsCurve, LocalCurve};
use crate::geom::knots::uniform_params;
use crate::model::{ErbsCurveEdit, ErbsCurveModel, ErbsEdit, KindEdit, LocalEdit, Target};
use crate::sampling::dirty::DirtyRegion;
use crate::sampling::grid::{PartialSet, SampleGrid};
use crate::sampling::object::Sampler;
use crate::sampling::tables::axis::{HermiteTable, dot};
use crate::sampling::tables::erbs_axis::{ErbsAxis, leibniz_terms};
use glam::{DMat4, DVec3};
use std::ops::Range;

/// A change of a level's samples: `values` for samples `start..`, g + 1 vectors each.
#[derive(Debug, Clone)]
pub(crate) struct Block {
    pub start: usize,
    pub values: Vec<DVec3>,
}

/// What reaches a local at the end of a path.
pub(crate) enum LocalOp<'a> {
    Transform(&'a DMat4),
    MovePoint(usize, DVec3),
    /// The local was replaced (restored, refined, rebuilt): pre-evaluate it again.
    Replace(&'a LocalCurve),
}

/// One local curve's pre-evaluation at its support's samples.
#[derive(Debug, Clone)]
enum LocalLevel {
    Spline {
        table: HermiteTable,
        samples: Vec<DVec3>,
    },
    Erbs(Box<CurveLevel>),
}

impl LocalLevel {
    fn new(local: &LocalCurve, params: Vec<f64>, order: usize) -> Self {
        match local {
            LocalCurve::Spline { curve, .. } => {
                let table = HermiteTable::at_params(
                    curve.knots(),
                    curve.degree(),
                    curve.points().len(),
                    params,
                    order,
                );
                let g1 = order + 1;
                let pts = curve.points();
                let mut samples = vec![DVec3::ZERO; table.len() * g1];
                for j in 0..table.len() {
                    let first = table.first(j);
                    for k in 0..g1 {
                        samples[j * g1 + k] = match table.row(j, k) {
                            Some(row) => dot(row, &pts[first..]),
                            None => DVec3::ZERO,
                        };
                    }
                }
                LocalLevel::Spline { table, samples }
            }
            LocalCurve::Erbs(e) => LocalLevel::Erbs(Box::new(CurveLevel::new(e, params, order))),
        }
    }

    fn samples(&self) -> &[DVec3] {
        match self {
            LocalLevel::Spline { samples, .. } => samples,
            LocalLevel::Erbs(c) => &c.grid.data,
        }
    }

    /// Maps every sample by A (positions as points, derivatives as vectors); returns the change.
    fn transform(&mut self, a: &DMat4, g1: usize) -> Vec<DVec3> {
        match self {
            LocalLevel::Spline { samples, .. } => transform_samples(samples, a, g1),
            LocalLevel::Erbs(c) => c.transform_all(a),
        }
    }
}

/// Applies A to samples in place (position slot as a point, the others as vectors) and
/// returns the change.
fn transform_samples(samples: &mut [DVec3], a: &DMat4, g1: usize) -> Vec<DVec3> {
    let mut delta = vec![DVec3::ZERO; samples.len()];
    for (idx, (d, s)) in delta.iter_mut().zip(samples.iter_mut()).enumerate() {
        let moved = if idx % g1 == 0 {
            a.transform_point3(*s)
        } else {
            a.transform_vector3(*s)
        };
        *d = moved - *s;
        *s = moved;
    }
    delta
}

/// An ERBS curve pre-evaluated at given parameters (its own, which are its parent's).
#[derive(Debug, Clone)]
pub(crate) struct CurveLevel {
    axis: ErbsAxis,
    order: usize,
    terms: Vec<Vec<(f64, usize, usize)>>,
    locals: Vec<LocalLevel>,
    pub grid: SampleGrid,
}

impl CurveLevel {
    pub fn new(curve: &ErbsCurve, params: Vec<f64>, order: usize) -> Self {
        let m = params.len();
        let axis = ErbsAxis::new(curve.knots(), curve.bfunction(), params, order);
        let locals = curve
            .local_curves()
            .iter()
            .enumerate()
            .map(|(l, c)| LocalLevel::new(c, axis.local_params(l), order))
            .collect();
        let mut level = Self {
            axis,
            order,
            terms: leibniz_terms(order),
            locals,
            grid: SampleGrid::new([m, 1], PartialSet::Curve(order), false),
        };
        for l in 0..level.locals.len() {
            let values = level.locals[l].samples().to_vec();
            let all = 0..values.len() / (order + 1);
            level.blend(l, &values, all, None);
        }
        level
    }

    /// P^(r) += Σ_k C(r,k) W_l^(r−k) Δc_l^(k) for local samples `local` (whose change is
    /// `delta`, starting at `local.start`), restricted to level samples `only` if given.
    /// Returns the change of this level's samples, piece by piece.
    fn blend(
        &mut self,
        l: usize,
        delta: &[DVec3],
        local: Range<usize>,
        only: Option<&Range<usize>>,
    ) -> Vec<Block> {
        let g1 = self.order + 1;
        let mut blocks = Vec::new();
        for piece in self.axis.pieces(l) {
            let Some(mut rows) = piece.level_range(&local) else {
                continue;
            };
            if let Some(o) = only {
                rows = rows.start.max(o.start)..rows.end.min(o.end);
                if rows.is_empty() {
                    continue;
                }
            }
            let mut values = Vec::with_capacity(rows.len() * g1);
            for j in rows.clone() {
                let w = self.axis.weights(j, l);
                let li = j - piece.samples.start + piece.offset - local.start;
                let d = &delta[li * g1..(li + 1) * g1];
                let out = &mut self.grid.data[j * g1..(j + 1) * g1];
                for (r, terms) in self.terms.iter().enumerate() {
                    let mut acc = DVec3::ZERO;
                    for &(c, wi, k) in terms {
                        acc += d[k] * (c * w[wi]);
                    }
                    out[r] += acc;
                    values.push(acc);
                }
            }
            blocks.push(Block {
                start: rows.start,
                values,
            });
        }
        blocks
    }

    /// Maps the whole level by A: every local and every sample; returns the change.
    fn transform_all(&mut self, a: &DMat4) -> Vec<DVec3> {
        let g1 = self.order + 1;
        for l in &mut self.locals {
            l.transform(a, g1);
        }
        transform_samples(&mut self.grid.data, a, g1)
    }

    /// Applies `op` to the local at `path` and returns this level's change.
    pub fn apply(&mut self, path: &[usize], op: &LocalOp) -> Vec<Block> {
        let g1 = self.order + 1;
        let Some((&l, rest)) = path.split_first() else {
            return Vec::new();
        };
        if !rest.is_empty() {
            let LocalLevel::Erbs(child) = &mut self.locals[l] else {
                return Vec::new();
            };
            let child_blocks = child.apply(rest, op);
            return child_blocks
                .into_iter()
                .flat_map(|b| {
                    let range = b.start..b.start + b.values.len() / g1;
                    self.blend(l, &b.values, range, None)
                })
                .collect();
        }
        match *op {
            LocalOp::Transform(a) => {
                let delta = self.locals[l].transform(a, g1);
                let all = 0..delta.len() / g1;
                self.blend(l, &delta, all, None)
            }
            LocalOp::MovePoint(q, d) => {
                let LocalLevel::Spline { table, samples } = &mut self.locals[l] else {
                    return Vec::new();
                };
                let range = table.range(q);
                let mut delta = Vec::with_capacity(range.len() * g1);
                for j in range.clone() {
                    let col = q - table.first(j);
                    for k in 0..g1 {
                        let c = table.row(j, k).map_or(0.0, |r| r[col]);
                        samples[j * g1 + k] += d * c;
                        delta.push(d * c);
                    }
                }
                self.blend(l, &delta, range, None)
            }
            LocalOp::Replace(local) => {
                let fresh = LocalLevel::new(local, self.axis.local_params(l), self.order);
                let delta: Vec<DVec3> = fresh
                    .samples()
                    .iter()
                    .zip(self.locals[l].samples())
                    .map(|(a, b)| *a - *b)
                    .collect();
                self.locals[l] = fresh;
                let all = 0..delta.len() / g1;
                self.blend(l, &delta, all, None)
            }
        }
    }

    /// The level samples the local at `path` covers, piece by piece (a local whose path goes
    /// on below a polynomial local: that local's).
    fn support(&self, path: &[usize]) -> Vec<Range<usize>> {
        let Some((&l, rest)) = path.split_first() else {
            return Vec::new();
        };
        let Some(local) = self.locals.get(l) else {
            return Vec::new();
        };
        let own = match (rest.is_empty(), local) {
            (false, LocalLevel::Erbs(child)) => child.support(rest),
            _ => std::iter::once(0..self.axis.local_len(l)).collect(),
        };
        own.iter()
            .flat_map(|r| self.axis.pieces(l).iter().filter_map(|p| p.level_range(r)))
            .collect()
    }

    /// After [`ErbsCurve::insert_knot`] inside interval i of this level's curve: the two
    /// restricted locals and the new one are pre-evaluated, the others keep theirs, and the
    /// samples strictly inside the interval are blended again — the only ones that change.
    /// (With a B-function whose derivatives up to the sampled order do not all vanish at 0 and
    /// 1, the higher derivatives at the interval's two knots depend on the neighbours too, so
    /// those samples are blended again as well.)
    pub fn refine(&mut self, old: &ErbsCurve, refined: &ErbsCurve, i: usize) -> Range<usize> {
        let g1 = self.order + 1;
        let inside = self
            .axis
            .touched_by_refinement(old.knots(), i, old.bfunction());
        let (right, _) = old.knots().right(i);
        self.axis = self.axis.refined(refined.knots(), refined.bfunction(), i);
        let new_right = if right == 0 { 0 } else { right + 1 };
        let rebuilt = [i, i + 1, new_right];
        let mut locals: Vec<Option<LocalLevel>> = std::mem::take(&mut self.locals)
            .into_iter()
            .map(Some)
            .collect();
        locals.insert(i + 1, None);
        self.locals = locals
            .into_iter()
            .enumerate()
            .map(|(l, kept)| match kept {
                Some(level) if !rebuilt.contains(&l) => level,
                _ => LocalLevel::new(
                    &refined.local_curves()[l],
                    self.axis.local_params(l),
                    self.order,
                ),
            })
            .collect();
        self.grid.data[inside.start * g1..inside.end * g1].fill(DVec3::ZERO);
        for l in 0..self.locals.len() {
            let values = self.locals[l].samples().to_vec();
            let all = 0..values.len() / g1;
            self.blend(l, &values, all, Some(&inside));
        }
        inside
    }
}

/// A top-level ERBS curve: the level at uniform parameters over its domain.
#[derive(Debug, Clone)]
pub struct ErbsCurveSampler {
    model: ErbsCurveModel,
    level: CurveLevel,
}

impl ErbsCurveSampler {
    #[must_use]
    pub fn new(model: ErbsCurveModel, order: usize) -> Self {
        let level = Self::level(&model, order);
        Self { model, level }
    }

    fn level(model: &ErbsCurveModel, order: usize) -> CurveLevel {
        let (a, b) = model.curve().domain();
        CurveLevel::new(model.curve(), uniform_params(a, b, model.samples()), order)
    }

    fn region(&self, blocks: &[Block]) -> DirtyRegion {
        let g1 = self.level.order + 1;
        blocks.iter().fold(DirtyRegion::NOTHING, |r, b| {
            r.union(DirtyRegion::curve(b.start..b.start + b.values.len() / g1))
        })
    }
}

impl Sampler for ErbsCurveSampler {
    type Model = ErbsCurveModel;
    type Edit = ErbsCurveEdit;

    fn model(&self) -> &ErbsCurveModel {
        &self.model
    }

    fn grid(&self) -> &SampleGrid {
        &self.level.grid
    }

    fn params(&self) -> Vec<&[f64]> {
        vec![&self.level.axis.params]
    }

    fn apply_prepared(
        &mut self,
        edit: &ErbsCurveEdit,
        result: Option<ErbsCurveModel>,
    ) -> DirtyRegion {
        match edit {
            ErbsEdit::Local(e) => {
                let path = e.local();
                let blocks = match e {
                    LocalEdit::Transform { matrix, .. } => {
                        edit.apply_prepared(&mut self.model, result);
                        self.level.apply(path.steps(), &LocalOp::Transform(matrix))
                    }
                    // Samples move by the model's exact change of the point.
                    LocalEdit::MovePoint { point, .. } => {
                        let before = self.point(path.steps(), *point);
                        edit.apply_prepared(&mut self.model, result);
                        let d = self.point(path.steps(), *point) - before;
                        self.level
                            .apply(path.steps(), &LocalOp::MovePoint(*point, d))
                    }
                    LocalEdit::SetPoints { .. } => {
                        edit.apply_prepared(&mut self.model, result);
                        self.replace(path.steps())
                    }
                };
                self.region(&blocks)
            }
            ErbsEdit::InsertKnot {
                local: None, at, ..
            } => {
                let i = self.model.curve().knots().locate(*at);
                let old = apply_keeping_old(edit, &mut self.model, result);
                if self.model.curve() == old.curve() {
                    return DirtyRegion::NOTHING;
                }
                let inside = self.level.refine(old.curve(), self.model.curve(), i);
                DirtyRegion::curve(inside)
            }
            ErbsEdit::InsertKnot {
                local: Some(path), ..
            }
            | ErbsEdit::ToErbs { local: path, .. }
            | ErbsEdit::SetLocal { local: path, .. } => {
                edit.apply_prepared(&mut self.model, result);
                let blocks = self.replace(path.steps());
                self.region(&blocks)
            }
            ErbsEdit::Restore(_) => {
                edit.apply_prepared(&mut self.model, result);
                self.full()
            }
        }
    }

    /// ERBS updates are local anyway: drift control re-samples everything.
    fn rebuild(&mut self, _region: DirtyRegion) -> DirtyRegion {
        self.full()
    }

    fn full(&mut self) -> DirtyRegion {
        self.level = Self::level(&self.model, self.level.order);
        DirtyRegion::curve(0..self.level.axis.len())
    }
}

impl crate::model::kind::Support for ErbsCurveSampler {
    fn support(&self, target: Target) -> Vec<DirtyRegion> {
        let path = match target {
            Target::Local(path) => path.to_curve(),
            _ => None,
        };
        match path {
            Some(p) => self
                .level
                .support(p.steps())
                .into_iter()
                .map(DirtyRegion::curve)
                .collect(),
            None => vec![DirtyRegion::whole(self.level.grid.dims)],
        }
    }
}

impl ErbsCurveSampler {
    fn point(&self, path: &[usize], q: usize) -> DVec3 {
        self.model
            .curve()
            .local_at(path)
            .and_then(LocalCurve::points)
            .map_or(DVec3::ZERO, |p| p[q])
    }

    fn replace(&mut self, path: &[usize]) -> Vec<Block> {
        match self.model.curve().local_at(path) {
            Some(local) => self.level.apply(path, &LocalOp::Replace(local)),
            None => Vec::new(),
        }
    }
}
