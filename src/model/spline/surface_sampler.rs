//! Pre-evaluated tensor-product Bézier, B-spline and NURBS surfaces.

use super::curve_sampler::PointState;
use crate::geom::TensorSurface;
use crate::model::{Index2, KindEdit, SurfaceEdit, SurfaceModel, Target};
use crate::parallel;
use crate::sampling::dirty::DirtyRegion;
use crate::sampling::fallback::{NormalSource, resolve_degenerate};
use crate::sampling::grid::{PartialSet, SampleGrid};
use crate::sampling::kernels::curvature;
use crate::sampling::kernels::lanes::LANES;
use crate::sampling::kernels::shading::{self, ShadingGrid};
use crate::sampling::object::Sampler;
use crate::sampling::rational::QuotientRule;
use crate::sampling::tables::axis::{HermiteTable, dot};
use glam::{DVec3, DVec4};
use std::ops::Range;
use std::sync::Arc;

/// A surface with per-direction pre-evaluation data (storage grows with mu + mv, not mu·mv) and
/// its canonical samples.
#[derive(Debug, Clone)]
pub struct SplineSurfaceSampler {
    model: SurfaceModel,
    tables: [Arc<HermiteTable>; 2],
    grid: SampleGrid,
    /// (a, b) of each slot, cached.
    partials: Vec<(usize, usize)>,
    hom: Option<Vec<DVec4>>,
    rule: QuotientRule,
}

impl SplineSurfaceSampler {
    /// Samples `samples = [mu, mv]` over the domain; `normals` adds unit normals (needs a set with
    /// first partials).
    #[must_use]
    pub fn new(model: SurfaceModel, set: PartialSet, normals: bool) -> Self {
        let g = set.max_order();
        let samples = model.samples();
        let surface = model.surface();
        let [nu, nv] = surface.count();
        let [du, dv] = surface.degree();
        let [ku, kv] = surface.knots();
        let tables = [
            HermiteTable::shared(ku, du, nu, samples[0], g),
            HermiteTable::shared(kv, dv, nv, samples[1], g),
        ];
        let grid = SampleGrid::new(samples, set.clone(), normals);
        let partials = set.list();
        let rule = QuotientRule::new(&set);
        let mut s = Self {
            model,
            tables,
            grid,
            partials,
            hom: None,
            rule,
        };
        s.full();
        s
    }

    fn surface(&self) -> &TensorSurface {
        self.model.surface()
    }

    /// Exact re-evaluation of a rectangle from the control points, in two passes: first each
    /// sample row against every control column (Q_a = M_u[a]·C), then each sample in the row
    /// (S_ab = Q_a·M_v[b]ᵀ) — (d+1) products per output instead of (d+1)².
    ///
    /// Large rectangles (a full pass, a periodic exact rebuild of a wide region) are split into
    /// row blocks on every core ([`crate::parallel::row_blocks`]); each sample is computed by the
    /// same code whichever block holds it, so the result is bit for bit that of one thread.
    fn rebuild_rect(&mut self, rows: Range<usize>, cols: Range<usize>) -> DirtyRegion {
        let surface = self.model.surface();
        let nv = surface.count()[1];
        let [tu, tv] = &self.tables;
        if self.fast_shading() && shading::surface_supported(surface.degree()) {
            let pts = surface.points();
            let blocks = parallel::row_blocks(rows.clone(), cols.len(), LANES);
            let grid = shading_grid(&mut self.grid);
            let width = grid.width;
            let normals = grid.normals.expect("shading grids keep normals");
            let mut jobs: Vec<_> = parallel::split_rows(grid.data, &blocks, width * 3)
                .into_iter()
                .zip(parallel::split_rows(normals, &blocks, width))
                .zip(&blocks)
                .map(|((data, normals), block)| (block.clone(), data, normals, Vec::new()))
                .collect();
            parallel::for_each_mut(&mut jobs, |(block, data, normals, degenerate)| {
                let out = ShadingGrid {
                    data,
                    normals: Some(normals),
                    width,
                    first_row: block.start,
                };
                shading::sample_surface(
                    tu,
                    tv,
                    pts,
                    nv,
                    block.clone(),
                    cols.clone(),
                    out,
                    degenerate,
                );
            });
            let degenerate: Vec<_> = jobs.into_iter().flat_map(|job| job.3).collect();
            let params = params(&self.tables);
            resolve_degenerate(&mut self.grid, &degenerate, params, surface);
            return DirtyRegion::surface(rows, cols);
        }
        let stride = self.grid.stride();
        let mv = self.grid.dims[1];
        let blocks = parallel::row_blocks(rows.clone(), cols.len(), 1);
        let block_rect = |block: &Range<usize>| Rect {
            rows: block.clone(),
            cols: cols.clone(),
            origin: (0, 0),
            first_row: block.start,
            width: mv,
            stride,
        };
        let row_len = mv * stride;
        let partials = &self.partials;
        match &mut self.hom {
            None => {
                let pts = surface.points();
                let mut jobs: Vec<_> = blocks
                    .iter()
                    .zip(parallel::split_rows(&mut self.grid.data, &blocks, row_len))
                    .collect();
                parallel::for_each_mut(&mut jobs, |(block, out)| {
                    two_pass(tu, tv, pts, nv, partials, &block_rect(block), out);
                });
            }
            Some(hom) => {
                let pts = surface.homogeneous_points();
                let rule = &self.rule;
                let mut jobs: Vec<_> = blocks
                    .iter()
                    .zip(parallel::split_rows(hom, &blocks, row_len))
                    .zip(parallel::split_rows(&mut self.grid.data, &blocks, row_len))
                    .collect();
                parallel::for_each_mut(&mut jobs, |((block, hom), out)| {
                    two_pass(tu, tv, &pts, nv, partials, &block_rect(block), hom);
                    for i in (*block).clone() {
                        for j in cols.clone() {
                            let base = ((i - block.start) * mv + j) * stride;
                            rule.project(&hom[base..base + stride], &mut out[base..base + stride]);
                        }
                    }
                });
            }
        }
        self.update_normals(rows.clone(), cols.clone());
        DirtyRegion::surface(rows, cols)
    }

    /// A control point edit: S_ij += M_u[i][·][k] M_v[j][·][l] Δ over I_k × I_l only, Δ the
    /// change of point (k, l) (homogeneous and re-projected for rational surfaces).
    fn edit_point(&mut self, edit: &SurfaceEdit, [k, l]: [usize; 2]) -> DirtyRegion {
        let before = PointState::of(self.surface(), [k, l]);
        edit.apply(&mut self.model);
        let after = PointState::of(self.surface(), [k, l]);
        match (before.weight, after.weight) {
            (None, None) => self.add_polynomial(k, l, after.position - before.position),
            (Some(_), Some(_)) => {
                let dh = before.homogeneous_change(&after);
                self.add_homogeneous(k, l, dh)
            }
            _ => self.full(),
        }
    }

    fn add_polynomial(&mut self, k: usize, l: usize, delta: DVec3) -> DirtyRegion {
        if self.fast_shading() {
            let mut degenerate = Vec::new();
            let [tu, tv] = &self.tables;
            let (rows, cols) = shading::translate_surface(
                [tu, tv],
                [k, l],
                delta,
                shading_grid(&mut self.grid),
                &mut degenerate,
            );
            let params = params(&self.tables);
            resolve_degenerate(&mut self.grid, &degenerate, params, self.model.surface());
            return DirtyRegion::surface(rows, cols);
        }
        if self.grid.curvatures.is_some() {
            // Curvature maps: the six partials, normals and [K, H] in one pass.
            let mut degenerate = Vec::new();
            let [tu, tv] = &self.tables;
            let (rows, cols) =
                curvature::translate([tu, tv], [k, l], delta, &mut self.grid, &mut degenerate);
            let params = params(&self.tables);
            resolve_degenerate(&mut self.grid, &degenerate, params, self.model.surface());
            return DirtyRegion::surface(rows, cols);
        }
        let (rows, cols) = (self.tables[0].range(k), self.tables[1].range(l));
        let [tu, tv] = &self.tables;
        let stride = self.grid.stride();
        let mv = self.grid.dims[1];
        for i in rows.clone() {
            let cu = k - tu.first(i);
            for j in cols.clone() {
                let cv = l - tv.first(j);
                let out = &mut self.grid.data[(i * mv + j) * stride..(i * mv + j + 1) * stride];
                for (p, &(a, b)) in self.partials.iter().enumerate() {
                    let c =
                        tu.row(i, a).map_or(0.0, |r| r[cu]) * tv.row(j, b).map_or(0.0, |r| r[cv]);
                    out[p] += delta * c;
                }
            }
        }
        self.update_normals(rows.clone(), cols.clone());
        DirtyRegion::surface(rows, cols)
    }

    /// After a change of knots or degree: new Hermite tables at the same parameters in the
    /// directions whose basis changed; the other direction's table is reused. The shape (and
    /// so every sample) is unchanged.
    fn retabulate(&mut self) {
        let s = self.model.surface();
        for dir in 0..2 {
            let t = &self.tables[dir];
            if !t.tabulates(&s.knots()[dir], s.degree()[dir], s.count()[dir]) {
                self.tables[dir] =
                    Arc::new(t.refit(&s.knots()[dir], s.degree()[dir], s.count()[dir]));
            }
        }
    }

    fn add_homogeneous(&mut self, k: usize, l: usize, dh: DVec4) -> DirtyRegion {
        let (rows, cols) = (self.tables[0].range(k), self.tables[1].range(l));
        let [tu, tv] = &self.tables;
        let stride = self.grid.stride();
        let mv = self.grid.dims[1];
        let Some(hom) = self.hom.as_mut() else {
            return self.full();
        };
        for i in rows.clone() {
            let cu = k - tu.first(i);
            for j in cols.clone() {
                let cv = l - tv.first(j);
                let base = (i * mv + j) * stride;
                for (p, &(a, b)) in self.partials.iter().enumerate() {
                    let c =
                        tu.row(i, a).map_or(0.0, |r| r[cu]) * tv.row(j, b).map_or(0.0, |r| r[cv]);
                    hom[base + p] += dh * c;
                }
                self.rule.project(
                    &hom[base..base + stride],
                    &mut self.grid.data[base..base + stride],
                );
            }
        }
        self.update_normals(rows.clone(), cols.clone());
        DirtyRegion::surface(rows, cols)
    }

    /// Whether the `shading` kernels apply: a polynomial surface of degree ≥ 1 both ways on a
    /// `Shading` grid with normals (what the renderer asks for).
    fn fast_shading(&self) -> bool {
        let s = self.model.surface();
        !s.is_rational()
            && self.grid.partials == PartialSet::Shading
            && self.grid.normals.is_some()
            && s.degree().iter().all(|&d| d >= 1)
    }

    fn update_normals(&mut self, rows: Range<usize>, cols: Range<usize>) {
        let params = params(&self.tables);
        crate::sampling::normals::update(&mut self.grid, rows, cols, params, self.model.surface());
    }
}

impl Sampler for SplineSurfaceSampler {
    type Model = SurfaceModel;
    type Edit = SurfaceEdit;

    fn model(&self) -> &SurfaceModel {
        &self.model
    }

    fn grid(&self) -> &SampleGrid {
        &self.grid
    }

    fn params(&self) -> Vec<&[f64]> {
        vec![&self.tables[0].params, &self.tables[1].params]
    }

    fn apply_prepared(&mut self, edit: &SurfaceEdit, result: Option<SurfaceModel>) -> DirtyRegion {
        match edit {
            SurfaceEdit::Point(p) => self.edit_point(edit, p.point()),
            SurfaceEdit::InsertKnot { .. } | SurfaceEdit::ElevateDegree { .. } => {
                edit.apply_prepared(&mut self.model, result);
                self.retabulate();
                DirtyRegion::NOTHING
            }
            SurfaceEdit::Restore { model, shape_kept } => {
                let rational = self.surface().is_rational();
                self.model = result.unwrap_or_else(|| (**model).clone());
                self.retabulate();
                if *shape_kept && rational == self.surface().is_rational() {
                    DirtyRegion::NOTHING
                } else {
                    self.full()
                }
            }
        }
    }

    fn rebuild(&mut self, region: DirtyRegion) -> DirtyRegion {
        self.rebuild_rect(region.rows, region.cols)
    }

    fn full(&mut self) -> DirtyRegion {
        self.hom = self
            .surface()
            .is_rational()
            .then(|| vec![DVec4::ZERO; self.grid.data.len()]);
        let [mu, mv] = self.grid.dims;
        self.rebuild_rect(0..mu, 0..mv)
    }
}

impl crate::model::kind::Support for SplineSurfaceSampler {
    fn support(&self, target: Target) -> Vec<DirtyRegion> {
        let rect = match target {
            Target::Point(Index2::Two(k, l)) | Target::Weight(Index2::Two(k, l)) => {
                self.tables[0].range_of(k).zip(self.tables[1].range_of(l))
            }
            _ => None,
        };
        vec![rect.map_or_else(
            || DirtyRegion::whole(self.grid.dims),
            |(rows, cols)| DirtyRegion::surface(rows, cols),
        )]
    }
}

/// The sample parameters of both directions.
#[must_use]
fn params(tables: &[Arc<HermiteTable>; 2]) -> [&[f64]; 2] {
    [tables[0].params.as_slice(), tables[1].params.as_slice()]
}

fn shading_grid(grid: &mut SampleGrid) -> ShadingGrid<'_> {
    ShadingGrid {
        data: &mut grid.data,
        normals: Some(grid.normals.as_mut().expect("shading grids keep normals")),
        width: grid.dims[1],
        first_row: 0,
    }
}

/// Where [`two_pass`] writes: samples `rows × cols` (parent indices) of a row-major array of
/// `width` samples per row whose first entry is parent sample `origin` shifted by `first_row`
/// rows (0 for a whole array, a block's first row for one thread's row block), `stride` values
/// each.
pub(crate) struct Rect {
    pub rows: Range<usize>,
    pub cols: Range<usize>,
    pub origin: (usize, usize),
    pub first_row: usize,
    pub width: usize,
    pub stride: usize,
}

/// Tensor-product sampling of a rectangle in two passes: first each sample row against every
/// control column (Q_a = M_u[a]·C), then each sample of the row (S_ab = Q_a·M_v[b]ᵀ) —
/// (d+1) products per output instead of (d+1)². The tables may index their samples from an
/// offset (`origin`), as ERBS local patches do.
pub(crate) fn two_pass<P>(
    tu: &HermiteTable,
    tv: &HermiteTable,
    pts: &[P],
    nv: usize,
    partials: &[(usize, usize)],
    rect: &Rect,
    out: &mut [P],
) where
    P: Copy + Default + std::ops::Add<Output = P> + std::ops::Mul<f64, Output = P>,
{
    let max_a = partials.iter().map(|p| p.0).max().unwrap_or(0);
    let mut q = vec![P::default(); (max_a + 1) * nv];
    let (oi, oj) = rect.origin;
    for i in rect.rows.clone() {
        let li = i - oi;
        let first = tu.first(li);
        for a in 0..=max_a {
            let qa = &mut q[a * nv..(a + 1) * nv];
            qa.fill(P::default());
            if let Some(row) = tu.row(li, a) {
                for (k, &c) in row.iter().enumerate() {
                    let src = &pts[(first + k) * nv..(first + k + 1) * nv];
                    for (o, &p) in qa.iter_mut().zip(src) {
                        *o = *o + p * c;
                    }
                }
            }
        }
        for j in rect.cols.clone() {
            let lj = j - oj;
            let first = tv.first(lj);
            let base = ((li - rect.first_row) * rect.width + lj) * rect.stride;
            for (p, &(a, b)) in partials.iter().enumerate() {
                out[base + p] = match tv.row(lj, b) {
                    Some(row) => dot(row, &q[a * nv + first..]),
                    None => P::default(),
                };
            }
        }
    }
}

impl NormalSource for TensorSurface {
    fn first_partials(&self, u: f64, v: f64) -> (DVec3, DVec3, DVec3) {
        let p = self.derivatives(u, v, 1);
        (p.get(1, 0), p.get(0, 1), p.get(1, 1))
    }

    fn domain(&self) -> [(f64, f64); 2] {
        TensorSurface::domain(self)
    }

    /// The curvature a small step towards the domain centre, where Su × Sv no longer vanishes
    /// (poles of a sphere, collapsed edges): 1e-3, then 1e-2 of the domain size. Closer in, the
    /// fundamental forms' determinant vanishes quadratically and rounding dominates.
    fn curvature_near(&self, u: f64, v: f64) -> Option<[f64; 2]> {
        let [(u0, u1), (v0, v1)] = TensorSurface::domain(self);
        let (uc, vc) = (0.5 * (u0 + u1), 0.5 * (v0 + v1));
        [1e-3, 1e-2].into_iter().find_map(|eps| {
            let (un, vn) = (u + eps * (uc - u), v + eps * (vc - v));
            self.curvatures(un, vn).map(|(k, h)| [k, h])
        })
    }
}
