//! Pre-evaluated tensor-product Bézier, B-spline and NURBS surfaces.

use super::axis::HermiteTable;
use super::dirty::DirtyRegion;
use super::grid::{PartialSet, SampleGrid};
use super::normals::NormalSource;
use super::rational::QuotientRule;
use super::shading::{self, ShadingGrid};
use super::spline_curve::dot;
use crate::geom::TensorSurface;
use crate::geom::point::to_homogeneous;
use glam::{DVec3, DVec4};
use std::ops::Range;

/// A surface with per-direction pre-evaluation data (storage grows with mu + mv, not mu·mv) and
/// its canonical samples.
#[derive(Debug, Clone)]
pub struct SplineSurfaceSampler {
    surface: TensorSurface,
    tables: [HermiteTable; 2],
    grid: SampleGrid,
    /// (a, b) of each slot, cached.
    partials: Vec<(usize, usize)>,
    hom: Option<Vec<DVec4>>,
    rule: QuotientRule,
}

impl SplineSurfaceSampler {
    /// Samples `samples = [mu, mv]` over the domain; `normals` adds unit normals (needs a set with
    /// first partials).
    pub fn new(
        surface: TensorSurface,
        samples: [usize; 2],
        set: PartialSet,
        normals: bool,
    ) -> Self {
        let g = set.max_order();
        let [nu, nv] = surface.count();
        let [du, dv] = surface.degree();
        let [ku, kv] = surface.knots();
        let tables = [
            HermiteTable::new(ku, du, nu, samples[0], g),
            HermiteTable::new(kv, dv, nv, samples[1], g),
        ];
        let grid = SampleGrid::new(samples, set.clone(), normals);
        let partials = set.list();
        let rule = QuotientRule::new(&set);
        let mut s = Self {
            surface,
            tables,
            grid,
            partials,
            hom: None,
            rule,
        };
        s.full();
        s
    }

    pub fn surface(&self) -> &TensorSurface {
        &self.surface
    }

    pub fn grid(&self) -> &SampleGrid {
        &self.grid
    }

    pub fn params(&self) -> [&[f64]; 2] {
        [&self.tables[0].params, &self.tables[1].params]
    }

    pub fn full(&mut self) -> DirtyRegion {
        self.hom = self
            .surface
            .is_rational()
            .then(|| vec![DVec4::ZERO; self.grid.data.len()]);
        let [mu, mv] = self.grid.dims;
        self.rebuild(0..mu, 0..mv)
    }

    /// Exact re-evaluation of a rectangle from the control points, in two passes: first each
    /// sample row against every control column (Q_a = M_u[a]·C), then each sample in the row
    /// (S_ab = Q_a·M_v[b]ᵀ) — (d+1) products per output instead of (d+1)².
    pub fn rebuild(&mut self, rows: Range<usize>, cols: Range<usize>) -> DirtyRegion {
        let nv = self.surface.count()[1];
        if self.fast_shading() && shading::surface_supported(self.surface.degree()) {
            let mut degenerate = Vec::new();
            let [tu, tv] = &self.tables;
            shading::sample_surface(
                tu,
                tv,
                self.surface.points(),
                nv,
                rows.clone(),
                cols.clone(),
                shading_grid(&mut self.grid),
                &mut degenerate,
            );
            self.resolve_degenerate(&degenerate);
            return DirtyRegion::Surface { rows, cols };
        }
        let stride = self.grid.stride();
        let mv = self.grid.dims[1];
        let [tu, tv] = &self.tables;
        let target = Rect {
            rows: rows.clone(),
            cols: cols.clone(),
            origin: (0, 0),
            width: mv,
            stride,
        };
        match &mut self.hom {
            None => two_pass(
                tu,
                tv,
                self.surface.points(),
                nv,
                &self.partials,
                &target,
                &mut self.grid.data,
            ),
            Some(hom) => {
                two_pass(
                    tu,
                    tv,
                    &self.surface.homogeneous_points(),
                    nv,
                    &self.partials,
                    &target,
                    hom,
                );
                for i in rows.clone() {
                    for j in cols.clone() {
                        let base = (i * mv + j) * stride;
                        self.rule.project(
                            &hom[base..base + stride],
                            &mut self.grid.data[base..base + stride],
                        );
                    }
                }
            }
        }
        self.update_normals(rows.clone(), cols.clone());
        DirtyRegion::Surface { rows, cols }
    }

    /// Moves control point (k, l): S_ij += M_u[i][·][k] M_v[j][·][l] Δ over I_k × I_l only.
    pub fn translate_point(&mut self, k: usize, l: usize, delta: DVec3) -> DirtyRegion {
        self.surface.translate_point(k, l, delta);
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
            self.resolve_degenerate(&degenerate);
            return DirtyRegion::Surface { rows, cols };
        }
        match self.surface.weights() {
            None => {
                let (rows, cols) = (self.tables[0].range(k), self.tables[1].range(l));
                let [tu, tv] = &self.tables;
                let stride = self.grid.stride();
                let mv = self.grid.dims[1];
                for i in rows.clone() {
                    let cu = k - tu.first(i);
                    for j in cols.clone() {
                        let cv = l - tv.first(j);
                        let out =
                            &mut self.grid.data[(i * mv + j) * stride..(i * mv + j + 1) * stride];
                        for (p, &(a, b)) in self.partials.iter().enumerate() {
                            let c = tu.row(i, a).map_or(0.0, |r| r[cu])
                                * tv.row(j, b).map_or(0.0, |r| r[cv]);
                            out[p] += delta * c;
                        }
                    }
                }
                self.update_normals(rows.clone(), cols.clone());
                DirtyRegion::Surface { rows, cols }
            }
            Some(w) => {
                let nv = self.surface.count()[1];
                let dh = (delta * w[k * nv + l]).extend(0.0);
                self.add_homogeneous(k, l, dh)
            }
        }
    }

    /// Sets control point (k, l) exactly (samples move by the difference).
    pub fn set_point(&mut self, k: usize, l: usize, p: DVec3) -> DirtyRegion {
        let region = self.translate_point(k, l, p - self.surface.point(k, l));
        self.surface.set_point(k, l, p);
        region
    }

    /// Sets weight (k, l): Δ(w P, w) = (Δw P_kl, Δw) on the touched samples, then re-projects.
    pub fn set_weight(&mut self, k: usize, l: usize, w: f64) -> DirtyRegion {
        let nv = self.surface.count()[1];
        let old = self.surface.weights().map_or(1.0, |ws| ws[k * nv + l]);
        let was_rational = self.surface.is_rational();
        self.surface.set_weight(k, l, w);
        if !was_rational {
            return self.full();
        }
        let dh = to_homogeneous(self.surface.point(k, l), w - old);
        self.add_homogeneous(k, l, dh)
    }

    fn add_homogeneous(&mut self, k: usize, l: usize, dh: DVec4) -> DirtyRegion {
        let (rows, cols) = (self.tables[0].range(k), self.tables[1].range(l));
        let [tu, tv] = &self.tables;
        let stride = self.grid.stride();
        let mv = self.grid.dims[1];
        let hom = self
            .hom
            .as_mut()
            .expect("rational surfaces keep homogeneous samples");
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
        DirtyRegion::Surface { rows, cols }
    }

    /// Whether the `shading` kernels apply: a polynomial surface of degree ≥ 1 both ways on a
    /// `Shading` grid with normals (what the renderer asks for).
    fn fast_shading(&self) -> bool {
        !self.surface.is_rational()
            && self.grid.partials == PartialSet::Shading
            && self.grid.normals.is_some()
            && self.surface.degree().iter().all(|&d| d >= 1)
    }

    fn resolve_degenerate(&mut self, samples: &[(usize, usize)]) {
        let params = [
            self.tables[0].params.as_slice(),
            self.tables[1].params.as_slice(),
        ];
        super::normals::resolve_degenerate(&mut self.grid, samples, params, &self.surface);
    }

    fn update_normals(&mut self, rows: Range<usize>, cols: Range<usize>) {
        let params = [
            self.tables[0].params.as_slice(),
            self.tables[1].params.as_slice(),
        ];
        super::normals::update(&mut self.grid, rows, cols, params, &self.surface);
    }
}

fn shading_grid(grid: &mut SampleGrid) -> ShadingGrid<'_> {
    ShadingGrid {
        data: &mut grid.data,
        normals: Some(grid.normals.as_mut().expect("shading grids keep normals")),
        width: grid.dims[1],
    }
}

/// Where [`two_pass`] writes: samples `rows × cols` (parent indices) of a row-major array of
/// `width` samples per row whose first entry is parent sample `origin`, `stride` values each.
pub(crate) struct Rect {
    pub rows: Range<usize>,
    pub cols: Range<usize>,
    pub origin: (usize, usize),
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
            let base = (li * rect.width + lj) * rect.stride;
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
}
