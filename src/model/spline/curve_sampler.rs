//! Pre-evaluated Bézier, B-spline and NURBS curves.

use crate::geom::BSplineCurve;
use crate::geom::point::to_homogeneous;
use crate::model::{CurveEdit, CurveModel, Index2, KindEdit, PointNet, Target};
use crate::sampling::dirty::DirtyRegion;
use crate::sampling::grid::{PartialSet, SampleGrid};
use crate::sampling::kernels::shading;
use crate::sampling::object::Sampler;
use crate::sampling::rational::QuotientRule;
use crate::sampling::tables::axis::{HermiteTable, dot};
use glam::{DVec3, DVec4};
use std::ops::Range;
use std::sync::Arc;

/// A curve with its pre-evaluation data and canonical samples c^(r)(S_j), r ≤ g.
#[derive(Debug, Clone)]
pub struct SplineCurveSampler {
    model: CurveModel,
    table: Arc<HermiteTable>,
    grid: SampleGrid,
    /// Homogeneous samples of (w·c, w) for rational curves, same layout as the grid.
    hom: Option<Vec<DVec4>>,
    rule: QuotientRule,
}

impl SplineCurveSampler {
    #[must_use]
    pub fn new(model: CurveModel, order: usize) -> Self {
        let curve = model.curve();
        let n = curve.points().len();
        let table = HermiteTable::shared(curve.knots(), curve.degree(), n, model.samples(), order);
        let set = PartialSet::Curve(order);
        let grid = SampleGrid::new([model.samples(), 1], set.clone(), false);
        let mut s = Self {
            model,
            table,
            grid,
            hom: None,
            rule: QuotientRule::new(&set),
        };
        s.full();
        s
    }

    fn curve(&self) -> &BSplineCurve {
        self.model.curve()
    }

    /// Exact re-evaluation of samples `range` from the control points (bounds drift).
    fn rebuild_range(&mut self, range: Range<usize>) -> DirtyRegion {
        let g = self.grid.stride();
        let curve = self.model.curve();
        match &mut self.hom {
            None if g == 2 && shading::curve_supported(curve.degree()) => {
                shading::sample_curve(
                    &self.table,
                    curve.points(),
                    range.clone(),
                    &mut self.grid.data,
                );
            }
            None => {
                let pts = curve.points();
                for j in range.clone() {
                    let first = self.table.first(j);
                    for r in 0..g {
                        self.grid.data[j * g + r] = match self.table.row(j, r) {
                            Some(row) => dot(row, &pts[first..]),
                            None => DVec3::ZERO,
                        };
                    }
                }
            }
            Some(hom) => {
                let h = curve.homogeneous_points();
                for j in range.clone() {
                    let first = self.table.first(j);
                    for r in 0..g {
                        hom[j * g + r] = match self.table.row(j, r) {
                            Some(row) => dot(row, &h[first..]),
                            None => DVec4::ZERO,
                        };
                    }
                    self.rule.project(
                        &hom[j * g..(j + 1) * g],
                        &mut self.grid.data[j * g..(j + 1) * g],
                    );
                }
            }
        }
        DirtyRegion::curve(range)
    }

    /// A control point edit: P_j += M_j[·][k]·Δ over I_k only, Δ the change of point k
    /// (homogeneous (Δ(w c), Δw) and re-projection for rational curves).
    fn edit_point(&mut self, edit: &CurveEdit, k: usize) -> DirtyRegion {
        let before = PointState::of(self.curve(), k);
        edit.apply(&mut self.model);
        let after = PointState::of(self.curve(), k);
        match (before.weight, after.weight) {
            (None, None) => {
                self.add_polynomial(k, after.position - before.position);
                DirtyRegion::curve(self.table.range(k))
            }
            (Some(_), Some(_)) => {
                let dh = before.homogeneous_change(&after);
                self.add_homogeneous(k, dh)
            }
            // Becoming rational (or polynomial) needs homogeneous samples everywhere.
            _ => self.full(),
        }
    }

    /// After a change of knots or degree: a new Hermite table at the same parameters. The
    /// shape (and so every sample) is unchanged.
    fn retabulate(&mut self) {
        let c = self.model.curve();
        self.table = Arc::new(self.table.refit(c.knots(), c.degree(), c.points().len()));
    }

    fn add_polynomial(&mut self, k: usize, delta: DVec3) {
        let g = self.grid.stride();
        if g == 2 && self.table.degree() >= 1 {
            shading::translate_curve(&self.table, k, delta, &mut self.grid.data);
            return;
        }
        let rows = g.min(self.table.degree() + 1);
        for j in self.table.range(k) {
            let col = k - self.table.first(j);
            for r in 0..rows {
                let c = self.table.row(j, r).expect("r ≤ degree")[col];
                self.grid.data[j * g + r] += delta * c;
            }
        }
    }

    fn add_homogeneous(&mut self, k: usize, dh: DVec4) -> DirtyRegion {
        let g = self.grid.stride();
        let rows = g.min(self.table.degree() + 1);
        let Some(hom) = self.hom.as_mut() else {
            return self.full();
        };
        let range = self.table.range(k);
        for j in range.clone() {
            let col = k - self.table.first(j);
            for r in 0..rows {
                let c = self.table.row(j, r).expect("r ≤ degree")[col];
                hom[j * g + r] += dh * c;
            }
            self.rule.project(
                &hom[j * g..(j + 1) * g],
                &mut self.grid.data[j * g..(j + 1) * g],
            );
        }
        DirtyRegion::curve(range)
    }
}

impl Sampler for SplineCurveSampler {
    type Model = CurveModel;
    type Edit = CurveEdit;

    fn model(&self) -> &CurveModel {
        &self.model
    }

    fn grid(&self) -> &SampleGrid {
        &self.grid
    }

    fn params(&self) -> Vec<&[f64]> {
        vec![&self.table.params]
    }

    fn apply_prepared(&mut self, edit: &CurveEdit, result: Option<CurveModel>) -> DirtyRegion {
        match edit {
            CurveEdit::Point(p) => self.edit_point(edit, p.point()),
            CurveEdit::InsertKnot { .. } | CurveEdit::ElevateDegree { .. } => {
                edit.apply_prepared(&mut self.model, result);
                self.retabulate();
                DirtyRegion::NOTHING
            }
            CurveEdit::Restore { model, shape_kept } => {
                let rational = self.curve().is_rational();
                self.model = result.unwrap_or_else(|| (**model).clone());
                self.retabulate();
                if *shape_kept && rational == self.curve().is_rational() {
                    DirtyRegion::NOTHING
                } else {
                    self.full()
                }
            }
        }
    }

    fn rebuild(&mut self, region: DirtyRegion) -> DirtyRegion {
        self.rebuild_range(region.rows)
    }

    /// Full sampling from the pre-evaluated matrices: P_j = M_j · c.
    fn full(&mut self) -> DirtyRegion {
        self.hom = self
            .curve()
            .is_rational()
            .then(|| vec![DVec4::ZERO; self.grid.data.len()]);
        self.rebuild_range(0..self.table.len())
    }
}

impl crate::model::kind::Support for SplineCurveSampler {
    fn support(&self, target: Target) -> Vec<DirtyRegion> {
        let range = match target {
            Target::Point(Index2::One(k)) | Target::Weight(Index2::One(k)) => {
                self.table.range_of(k)
            }
            _ => None,
        };
        vec![range.map_or_else(|| DirtyRegion::whole(self.grid.dims), DirtyRegion::curve)]
    }
}

/// One control point as an edit sees it, before or after.
pub(crate) struct PointState {
    pub position: DVec3,
    pub weight: Option<f64>,
}

impl PointState {
    pub fn of<I>(net: &impl PointNet<I>, i: I) -> Self
    where
        I: Copy,
    {
        Self {
            position: net.point(i),
            weight: net.weight(i),
        }
    }

    /// Δ(w·p, w) of a rational point. A point edit changes the position or the weight, never
    /// both, so each case is formed without cancellation: (w Δp, 0) or (Δw p, Δw).
    pub fn homogeneous_change(&self, after: &PointState) -> DVec4 {
        let (w0, w1) = (self.weight.unwrap_or(1.0), after.weight.unwrap_or(1.0));
        if w0 == w1 {
            ((after.position - self.position) * w0).extend(0.0)
        } else {
            to_homogeneous(after.position, w1 - w0)
        }
    }
}
