//! Pre-evaluated Bézier, B-spline and NURBS curves.

use super::axis::HermiteTable;
use super::dirty::DirtyRegion;
use super::grid::{PartialSet, SampleGrid};
use super::rational::QuotientRule;
use super::shading;
use crate::geom::BSplineCurve;
use crate::geom::point::to_homogeneous;
use glam::{DVec3, DVec4};
use std::ops::Range;

/// A curve with its pre-evaluation data and canonical samples c^(r)(S_j), r ≤ g.
#[derive(Debug, Clone)]
pub struct SplineCurveSampler {
    curve: BSplineCurve,
    table: HermiteTable,
    grid: SampleGrid,
    /// Homogeneous samples of (w·c, w) for rational curves, same layout as the grid.
    hom: Option<Vec<DVec4>>,
    rule: QuotientRule,
}

impl SplineCurveSampler {
    pub fn new(curve: BSplineCurve, samples: usize, order: usize) -> Self {
        let n = curve.points().len();
        let table = HermiteTable::new(curve.knots(), curve.degree(), n, samples, order);
        let set = PartialSet::Curve(order);
        let grid = SampleGrid::new([samples, 1], set.clone(), false);
        let mut s = Self {
            curve,
            table,
            grid,
            hom: None,
            rule: QuotientRule::new(&set),
        };
        s.full();
        s
    }

    pub fn curve(&self) -> &BSplineCurve {
        &self.curve
    }

    pub fn grid(&self) -> &SampleGrid {
        &self.grid
    }

    pub fn params(&self) -> &[f64] {
        &self.table.params
    }

    /// Full sampling from the pre-evaluated matrices: P_j = M_j · c.
    pub fn full(&mut self) -> DirtyRegion {
        self.hom = self
            .curve
            .is_rational()
            .then(|| vec![DVec4::ZERO; self.grid.data.len()]);
        self.rebuild(0..self.table.len())
    }

    /// Exact re-evaluation of samples `range` from the control points (bounds drift).
    pub fn rebuild(&mut self, range: Range<usize>) -> DirtyRegion {
        let g = self.grid.stride();
        match &mut self.hom {
            None if g == 2 && shading::curve_supported(self.curve.degree()) => {
                shading::sample_curve(
                    &self.table,
                    self.curve.points(),
                    range.clone(),
                    &mut self.grid.data,
                );
            }
            None => {
                let pts = self.curve.points();
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
                let h = self.curve.homogeneous_points();
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
        DirtyRegion::Curve(range)
    }

    /// Moves control point k by `delta`: P_j += M_j[·][k]·Δ over I_k only (homogeneous
    /// (w_k Δ, 0) and re-projection for rational curves).
    pub fn translate_point(&mut self, k: usize, delta: DVec3) -> DirtyRegion {
        self.curve.translate_point(k, delta);
        match self.curve.weights() {
            None => {
                self.add_polynomial(k, delta);
                DirtyRegion::Curve(self.table.range(k))
            }
            Some(w) => {
                let dh = (delta * w[k]).extend(0.0);
                self.add_homogeneous(k, dh)
            }
        }
    }

    /// Sets weight k: Δ(w c, w) = (Δw c_k, Δw) through the touched samples.
    pub fn set_weight(&mut self, k: usize, w: f64) -> DirtyRegion {
        let old = self.curve.weights().map_or(1.0, |ws| ws[k]);
        let was_rational = self.curve.is_rational();
        self.curve.set_weight(k, w);
        if !was_rational {
            // Becoming rational needs homogeneous samples everywhere: one full pass.
            return self.full();
        }
        let dw = w - old;
        let dh = to_homogeneous(self.curve.points()[k], dw);
        self.add_homogeneous(k, dh)
    }

    /// Sets control point k exactly: the samples move by the difference, the model takes the
    /// exact value (so undo restores it bit for bit).
    pub fn set_point(&mut self, k: usize, p: DVec3) -> DirtyRegion {
        let region = self.translate_point(k, p - self.curve.points()[k]);
        self.curve.set_point(k, p);
        region
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
        let hom = self
            .hom
            .as_mut()
            .expect("rational curves keep homogeneous samples");
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
        DirtyRegion::Curve(range)
    }
}

/// Σ_k row[k]·p[k].
#[inline]
pub(crate) fn dot<P>(row: &[f64], p: &[P]) -> P
where
    P: Copy + Default + std::ops::Add<Output = P> + std::ops::Mul<f64, Output = P>,
{
    let mut acc = P::default();
    for (c, &q) in row.iter().zip(p) {
        acc = acc + q * *c;
    }
    acc
}
