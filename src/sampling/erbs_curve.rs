//! Pre-evaluated ERBS curves: local curves sampled at the parent's parameters, blended by the
//! Leibniz rule.

use super::axis::HermiteTable;
use super::dirty::DirtyRegion;
use super::erbs_axis::{ErbsAxis, leibniz_terms};
use super::grid::{PartialSet, SampleGrid};
use super::object::Sampler;
use crate::geom::knots::KnotVector;
use crate::model::{ErbsCurveEdit, ErbsCurveModel, KindEdit, LocalEdit};
use glam::{DMat4, DVec3};

/// One local curve's pre-evaluation at the parent's parameters in its support: its
/// Bernstein-Hermite rows (with the [t_l, t_{l+2}] chain-rule factors) and its samples c_l^(k).
#[derive(Debug, Clone)]
struct LocalSamples {
    first: usize,
    table: HermiteTable,
    samples: Vec<DVec3>,
}

#[derive(Debug, Clone)]
pub struct ErbsCurveSampler {
    model: ErbsCurveModel,
    axis: ErbsAxis,
    local: Vec<LocalSamples>,
    terms: Vec<Vec<(f64, usize, usize)>>,
    grid: SampleGrid,
}

impl ErbsCurveSampler {
    pub fn new(model: ErbsCurveModel, order: usize) -> Self {
        let curve = model.curve();
        let samples = model.samples();
        let axis = ErbsAxis::new(curve.knots(), curve.bfunction(), samples, order);
        let knots = curve.knots();
        let local = curve
            .local_curves()
            .iter()
            .enumerate()
            .map(|(l, c)| {
                let range = axis.range(l);
                let deg = c.degree();
                let kv = KnotVector::bezier(deg, knots[l], knots[l + 2]);
                let table = HermiteTable::at_params(
                    &kv,
                    deg,
                    deg + 1,
                    axis.params[range.clone()].to_vec(),
                    order,
                );
                LocalSamples {
                    first: range.start,
                    table,
                    samples: vec![DVec3::ZERO; range.len() * (order + 1)],
                }
            })
            .collect();
        let grid = SampleGrid::new([samples, 1], PartialSet::Curve(order), false);
        let mut s = Self {
            model,
            axis,
            local,
            terms: leibniz_terms(order),
            grid,
        };
        s.full();
        s
    }

    /// Exact sampling: every local curve from its control points, then the blend.
    fn sample_all(&mut self) -> DirtyRegion {
        self.grid.data.fill(DVec3::ZERO);
        let g1 = self.grid.stride();
        for l in 0..self.local.len() {
            let pts = self.model.curve().local_curves()[l].points();
            let loc = &mut self.local[l];
            for jl in 0..loc.table.len() {
                for k in 0..g1 {
                    loc.samples[jl * g1 + k] = match loc.table.row(jl, k) {
                        Some(row) => super::spline_curve::dot(row, pts),
                        None => DVec3::ZERO,
                    };
                }
            }
            let delta = loc.samples.clone();
            self.blend_in(l, &delta);
        }
        DirtyRegion::curve(0..self.grid.dims[0])
    }

    /// Affine map of local curve l: Δc = A·c − c on its pre-sampled data (positions as points,
    /// derivatives as vectors), blended into the parent with the Leibniz rule.
    fn transform_local(&mut self, l: usize, a: &DMat4) -> DirtyRegion {
        let g1 = self.grid.stride();
        let loc = &mut self.local[l];
        let mut delta = vec![DVec3::ZERO; loc.samples.len()];
        for (idx, (d, s)) in delta.iter_mut().zip(loc.samples.iter_mut()).enumerate() {
            let moved = if idx % g1 == 0 {
                a.transform_point3(*s)
            } else {
                a.transform_vector3(*s)
            };
            *d = moved - *s;
            *s = moved;
        }
        self.blend_in(l, &delta)
    }

    /// Control point q of local curve l moved by Δ: Δc^(k) = M_l[k][q]·Δ, then the blend.
    fn move_local_point(&mut self, l: usize, q: usize, delta: DVec3) -> DirtyRegion {
        let g1 = self.grid.stride();
        let loc = &mut self.local[l];
        let mut d = vec![DVec3::ZERO; loc.samples.len()];
        for jl in 0..loc.table.len() {
            for k in 0..g1 {
                let c = loc.table.row(jl, k).map_or(0.0, |r| r[q]);
                d[jl * g1 + k] = delta * c;
                loc.samples[jl * g1 + k] += delta * c;
            }
        }
        self.blend_in(l, &d)
    }

    /// P^(r) += Σ_k C(r,k) W_l^(r−k) Δc_l^(k) over the support of local curve l.
    fn blend_in(&mut self, l: usize, delta: &[DVec3]) -> DirtyRegion {
        let g1 = self.grid.stride();
        let loc = &self.local[l];
        let range = self.axis.range(l);
        for j in range.clone() {
            let w = self.axis.weights(j, l);
            let d = &delta[(j - loc.first) * g1..(j - loc.first + 1) * g1];
            let out = &mut self.grid.data[j * g1..(j + 1) * g1];
            for (r, terms) in self.terms.iter().enumerate() {
                let mut acc = DVec3::ZERO;
                for &(c, wi, k) in terms {
                    acc += d[k] * (c * w[wi]);
                }
                out[r] += acc;
            }
        }
        DirtyRegion::curve(range)
    }
}

impl Sampler for ErbsCurveSampler {
    type Edit = ErbsCurveEdit;

    fn model(&self) -> &ErbsCurveModel {
        &self.model
    }

    fn grid(&self) -> &SampleGrid {
        &self.grid
    }

    fn params(&self) -> Vec<&[f64]> {
        vec![&self.axis.params]
    }

    fn apply(&mut self, edit: &ErbsCurveEdit) -> DirtyRegion {
        let ErbsCurveEdit::Local(e) = edit;
        let l = e.local();
        let before = self.model.curve().local_curves()[l].points().to_vec();
        edit.apply(&mut self.model);
        match e {
            LocalEdit::Transform { matrix, .. } => self.transform_local(l, matrix),
            // Samples move by the model's exact change of each point.
            LocalEdit::MovePoint { .. } | LocalEdit::SetPoints { .. } => {
                let after = self.model.curve().local_curves()[l].points().to_vec();
                let mut region = DirtyRegion::NOTHING;
                for (q, (&new, &old)) in after.iter().zip(&before).enumerate() {
                    if new != old {
                        region = region.union(self.move_local_point(l, q, new - old));
                    }
                }
                region
            }
        }
    }

    /// ERBS updates are local anyway: drift control re-samples everything.
    fn rebuild(&mut self, _region: DirtyRegion) -> DirtyRegion {
        self.sample_all()
    }

    fn full(&mut self) -> DirtyRegion {
        self.sample_all()
    }
}
