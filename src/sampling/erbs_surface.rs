//! Pre-evaluated ERBS surfaces: local patches sampled on their support sub-grids at the parent's
//! parameters, blended by the Leibniz rule in both directions.

use super::axis::HermiteTable;
use super::dirty::DirtyRegion;
use super::erbs_axis::ErbsAxis;
use super::grid::{PartialSet, SampleGrid};
use super::normals::NormalSource;
use super::object::Sampler;
use super::shading::{self, ShadingGrid};
use super::spline_surface::{Rect, two_pass};
use crate::geom::ErbsSurface;
use crate::geom::knots::KnotVector;
use crate::geom::point::binomial;
use crate::model::{ErbsSurfaceEdit, ErbsSurfaceModel, KindEdit, LocalEdit};
use glam::{DMat4, DVec3};
use std::ops::Range;

/// One local patch's pre-evaluation on its support rows × cols: Bernstein-Hermite tables per
/// direction and the patch's own partials there.
#[derive(Debug, Clone)]
struct LocalPatch {
    rows: Range<usize>,
    cols: Range<usize>,
    tables: [HermiteTable; 2],
    samples: Vec<DVec3>,
}

/// For output partial (a, b): Σ over (a', b') ≤ (a, b) of C(a,a')C(b,b') Wu^(a−a') Wv^(b−b') s^(a'b').
type BlendTerm = (f64, usize, usize, usize);

#[derive(Debug, Clone)]
pub struct ErbsSurfaceSampler {
    model: ErbsSurfaceModel,
    axes: [ErbsAxis; 2],
    partials: Vec<(usize, usize)>,
    terms: Vec<Vec<BlendTerm>>,
    patches: Vec<LocalPatch>,
    grid: SampleGrid,
    /// Reused buffer for an edit's change of one patch's samples: a fresh allocation of that
    /// size is mapped and zeroed by the kernel on every edit.
    scratch: Vec<DVec3>,
}

impl ErbsSurfaceSampler {
    pub fn new(model: ErbsSurfaceModel, set: PartialSet, normals: bool) -> Self {
        let g = set.max_order();
        let surface = model.surface();
        let samples = model.samples();
        let [ku, kv] = surface.knots();
        let axes = [
            ErbsAxis::new(ku, surface.bfunction(), samples[0], g),
            ErbsAxis::new(kv, surface.bfunction(), samples[1], g),
        ];
        let partials = set.list();
        let slot = |a: usize, b: usize| {
            partials
                .iter()
                .position(|&p| p == (a, b))
                .expect("downward closed")
        };
        let terms = partials
            .iter()
            .map(|&(a, b)| {
                let mut t = Vec::new();
                for a2 in 0..=a {
                    for b2 in 0..=b {
                        t.push((
                            binomial(a, a2) * binomial(b, b2),
                            a - a2,
                            b - b2,
                            slot(a2, b2),
                        ));
                    }
                }
                t
            })
            .collect();
        let [nu, nv] = surface.count();
        let stride = set.len();
        let mut patches = Vec::with_capacity(nu * nv);
        for k in 0..nu {
            for l in 0..nv {
                let p = surface.local_patch(k, l);
                let [da, db] = p.degree();
                let (rows, cols) = (axes[0].range(k), axes[1].range(l));
                let tu = HermiteTable::at_params(
                    &KnotVector::bezier(da, ku[k], ku[k + 2]),
                    da,
                    da + 1,
                    axes[0].params[rows.clone()].to_vec(),
                    g,
                );
                let tv = HermiteTable::at_params(
                    &KnotVector::bezier(db, kv[l], kv[l + 2]),
                    db,
                    db + 1,
                    axes[1].params[cols.clone()].to_vec(),
                    g,
                );
                let n = rows.len() * cols.len() * stride;
                patches.push(LocalPatch {
                    rows,
                    cols,
                    tables: [tu, tv],
                    samples: vec![DVec3::ZERO; n],
                });
            }
        }
        let grid = SampleGrid::new(samples, set, normals);
        let mut s = Self {
            model,
            axes,
            partials,
            terms,
            patches,
            grid,
            scratch: Vec::new(),
        };
        s.full();
        s
    }

    /// Exact sampling: every local patch from its control points (two passes on its sub-grid),
    /// then the blend.
    fn sample_all(&mut self) -> DirtyRegion {
        self.grid.data.fill(DVec3::ZERO);
        for idx in 0..self.patches.len() {
            self.sample_patch(idx);
            // The patch's samples are the whole delta; lent out instead of cloned.
            let delta = std::mem::take(&mut self.patches[idx].samples);
            self.blend_in(idx, &delta);
            self.patches[idx].samples = delta;
        }
        let [mu, mv] = self.grid.dims;
        self.update_normals(0..mu, 0..mv);
        DirtyRegion::surface(0..mu, 0..mv)
    }

    fn sample_patch(&mut self, idx: usize) {
        let surface = self.model.surface();
        let nv = surface.count()[1];
        let patch = surface.local_patch(idx / nv, idx % nv);
        let p = &mut self.patches[idx];
        let [tu, tv] = &p.tables;
        if self.grid.partials == PartialSet::Shading
            && shading::surface_supported([tu.degree(), tv.degree()])
        {
            let out = ShadingGrid {
                data: &mut p.samples,
                normals: None,
                width: p.cols.len(),
            };
            let (rows, cols) = (0..p.rows.len(), 0..p.cols.len());
            let nv = patch.count()[1];
            shading::sample_surface(tu, tv, patch.points(), nv, rows, cols, out, &mut Vec::new());
            return;
        }
        let rect = Rect {
            rows: p.rows.clone(),
            cols: p.cols.clone(),
            origin: (p.rows.start, p.cols.start),
            width: p.cols.len(),
            stride: self.partials.len(),
        };
        two_pass(
            &p.tables[0],
            &p.tables[1],
            patch.points(),
            patch.count()[1],
            &self.partials,
            &rect,
            &mut p.samples,
        );
    }

    /// Affine map of local patch (k, l): Δs = A·s − s on its pre-sampled partials (positions as
    /// points, derivatives as vectors), blended into the parent.
    fn transform_local(&mut self, idx: usize, a: &DMat4) -> DirtyRegion {
        let stride = self.partials.len();
        let p = &mut self.patches[idx];
        let mut delta = std::mem::take(&mut self.scratch);
        delta.resize(p.samples.len(), DVec3::ZERO);
        let samples = p.samples.chunks_exact_mut(stride);
        for (d, s) in delta.chunks_exact_mut(stride).zip(samples) {
            for (q, (d, s)) in d.iter_mut().zip(s).enumerate() {
                let moved = if q == 0 {
                    a.transform_point3(*s)
                } else {
                    a.transform_vector3(*s)
                };
                *d = moved - *s;
                *s = moved;
            }
        }
        let region = self.finish(idx, &delta);
        self.scratch = delta;
        region
    }

    /// Control point (qa, qb) of local patch `idx` moved by Δ: Δs^(ab) = Mu[a][qa] Mv[b][qb] Δ.
    fn move_local_point(&mut self, idx: usize, qa: usize, qb: usize, delta: DVec3) -> DirtyRegion {
        let stride = self.partials.len();
        let p = &mut self.patches[idx];
        let width = p.cols.len();
        let mut d = std::mem::take(&mut self.scratch);
        d.resize(p.samples.len(), DVec3::ZERO);
        for li in 0..p.rows.len() {
            for lj in 0..width {
                let base = (li * width + lj) * stride;
                for (slot, &(a, b)) in self.partials.iter().enumerate() {
                    let c = p.tables[0].row(li, a).map_or(0.0, |r| r[qa])
                        * p.tables[1].row(lj, b).map_or(0.0, |r| r[qb]);
                    d[base + slot] = delta * c;
                    p.samples[base + slot] += delta * c;
                }
            }
        }
        let region = self.finish(idx, &d);
        self.scratch = d;
        region
    }

    fn finish(&mut self, idx: usize, delta: &[DVec3]) -> DirtyRegion {
        let region = self.blend_in(idx, delta);
        let (rows, cols) = (
            self.patches[idx].rows.clone(),
            self.patches[idx].cols.clone(),
        );
        self.update_normals(rows, cols);
        region
    }

    /// ∂^{ab}P += Σ C(a,a')C(b,b') Wu_k^(a−a') Wv_l^(b−b') Δs^(a'b') over the patch's support.
    fn blend_in(&mut self, idx: usize, delta: &[DVec3]) -> DirtyRegion {
        let nv = self.model.surface().count()[1];
        let (k, l) = (idx / nv, idx % nv);
        let p = &self.patches[idx];
        let stride = self.partials.len();
        let mv = self.grid.dims[1];
        let width = p.cols.len();
        if self.grid.partials == PartialSet::Shading {
            // The Leibniz terms of S, Su, Sv written out (the generic loop below with its
            // terms in the same order, up to the sign of an exact zero): no per-sample term
            // lists and slices.
            let wv: Vec<[f64; 2]> = p
                .cols
                .clone()
                .map(|j| {
                    let w = self.axes[1].weights(j, l);
                    [w[0], w[1]]
                })
                .collect();
            for (i, d) in p.rows.clone().zip(delta.chunks_exact(width * 3)) {
                let wu = self.axes[0].weights(i, k);
                let (wu0, wu1) = (wu[0], wu[1]);
                let out =
                    &mut self.grid.data[(i * mv + p.cols.start) * 3..(i * mv + p.cols.end) * 3];
                let (out, d) = (out.as_chunks_mut::<3>().0, d.as_chunks::<3>().0);
                for ((o, d), &[wv0, wv1]) in out.iter_mut().zip(d).zip(&wv) {
                    let w00 = wu0 * wv0;
                    o[0] += d[0] * w00;
                    o[1] += d[0] * (wu1 * wv0) + d[1] * w00;
                    o[2] += d[0] * (wu0 * wv1) + d[2] * w00;
                }
            }
            return DirtyRegion::surface(p.rows.clone(), p.cols.clone());
        }
        for i in p.rows.clone() {
            let wu = self.axes[0].weights(i, k);
            for j in p.cols.clone() {
                let wv = self.axes[1].weights(j, l);
                let d =
                    &delta[((i - p.rows.start) * width + (j - p.cols.start)) * stride..][..stride];
                let out = &mut self.grid.data[(i * mv + j) * stride..][..stride];
                for (slot, terms) in self.terms.iter().enumerate() {
                    let mut acc = DVec3::ZERO;
                    for &(c, ia, ib, s) in terms {
                        acc += d[s] * (c * wu[ia] * wv[ib]);
                    }
                    out[slot] += acc;
                }
            }
        }
        DirtyRegion::surface(p.rows.clone(), p.cols.clone())
    }

    fn update_normals(&mut self, rows: Range<usize>, cols: Range<usize>) {
        let params = [
            self.axes[0].params.as_slice(),
            self.axes[1].params.as_slice(),
        ];
        super::normals::update(&mut self.grid, rows, cols, params, self.model.surface());
    }
}

impl Sampler for ErbsSurfaceSampler {
    type Edit = ErbsSurfaceEdit;

    fn model(&self) -> &ErbsSurfaceModel {
        &self.model
    }

    fn grid(&self) -> &SampleGrid {
        &self.grid
    }

    fn params(&self) -> Vec<&[f64]> {
        vec![&self.axes[0].params, &self.axes[1].params]
    }

    fn apply(&mut self, edit: &ErbsSurfaceEdit) -> DirtyRegion {
        let ErbsSurfaceEdit::Local(e) = edit;
        let [k, l] = e.local();
        let nb = self.model.surface().local_patch(k, l).count()[1];
        let idx = k * self.model.surface().count()[1] + l;
        let before = self.model.surface().local_patch(k, l).points().to_vec();
        edit.apply(&mut self.model);
        match e {
            LocalEdit::Transform { matrix, .. } => self.transform_local(idx, matrix),
            // Samples move by the model's exact change of each point.
            LocalEdit::MovePoint { .. } | LocalEdit::SetPoints { .. } => {
                let after = self.model.surface().local_patch(k, l).points().to_vec();
                let mut region = DirtyRegion::NOTHING;
                for (q, (&new, &old)) in after.iter().zip(&before).enumerate() {
                    if new != old {
                        region =
                            region.union(self.move_local_point(idx, q / nb, q % nb, new - old));
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

impl NormalSource for ErbsSurface {
    fn first_partials(&self, u: f64, v: f64) -> (DVec3, DVec3, DVec3) {
        let p = self.derivatives(u, v, 1);
        (p.get(1, 0), p.get(0, 1), p.get(1, 1))
    }

    fn domain(&self) -> [(f64, f64); 2] {
        ErbsSurface::domain(self)
    }
}
