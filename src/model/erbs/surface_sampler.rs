//! Pre-evaluated ERBS surfaces, hierarchically. A polynomial local patch keeps its net and its
//! blended Hermite tables (`erbs_patch`), so over one knot cell the surface is a tensor product
//! of the 2 × 2 active patches' bases on an 8 × 8 net, sampled in one pass, and an edit of a
//! patch is a net delta through its tables over its support. An ERBS local patch is a level of
//! its own, pre-sampled at its parent's parameters: an edit at any depth returns the change of
//! that level's samples over the edited patch's support, and each parent blends it in by the
//! Leibniz rule over the same samples.

use super::edit::apply_keeping_old;
use crate::geom::erbs::{ErbsKnots, ErbsSurface, LocalPatch};
use crate::geom::knots::uniform_params;
use crate::geom::point::binomial;
use crate::model::{
    ErbsEdit, ErbsSurfaceEdit, ErbsSurfaceModel, KindEdit, LocalEdit, Target as EditTarget,
};
use crate::parallel;
use crate::sampling::dirty::DirtyRegion;
use crate::sampling::fallback::{NormalSource, resolve_degenerate};
use crate::sampling::grid::{PartialSet, SampleGrid};
use crate::sampling::kernels::dense::{self, Target};
use crate::sampling::object::Sampler;
use crate::sampling::tables::erbs_axis::ErbsAxis;
use crate::sampling::tables::erbs_patch::{
    self, BlendTerm, DENSE, DenseRow, Out, SplinePatch, add_share, clip,
};
use glam::{DMat4, DVec3};
use std::ops::Range;

/// A change of a level's samples over `rows × cols`, `stride` vectors per sample, row-major
/// (`values` empty at the top level, which only needs where).
#[derive(Debug, Clone)]
pub(crate) struct Patch {
    pub rows: Range<usize>,
    pub cols: Range<usize>,
    pub values: Vec<DVec3>,
    /// Whether a kernel already wrote these samples' unit normals.
    pub normals: bool,
}

/// What reaches the local patch at the end of a path, after the model changed.
pub(crate) enum PatchOp<'a> {
    /// The local was mapped by A (an ERBS local's samples follow A directly); its new state.
    Transform(&'a DMat4, &'a LocalPatch),
    /// The local's new state (points moved, replaced, refined, nested).
    Update(&'a LocalPatch),
}

#[derive(Debug, Clone)]
enum PatchLevel {
    Spline(SplinePatch),
    Erbs(Box<SurfaceLevel>),
}

impl PatchLevel {
    fn new(patch: &LocalPatch, axes: &[ErbsAxis; 2], kl: [usize; 2], set: &PartialSet) -> Self {
        match patch {
            LocalPatch::Spline { surface, .. } => {
                PatchLevel::Spline(SplinePatch::new(surface, axes, kl, set))
            }
            LocalPatch::Erbs(e) => {
                let params = [axes[0].local_params(kl[0]), axes[1].local_params(kl[1])];
                PatchLevel::Erbs(Box::new(SurfaceLevel::new(
                    e,
                    params,
                    set.clone(),
                    false,
                    true,
                )))
            }
        }
    }

    /// Maps the patch by A; an ERBS patch writes the change of its samples into `delta`.
    fn transform(&mut self, a: &DMat4, delta: &mut Vec<DVec3>) {
        match self {
            PatchLevel::Spline(p) => p.map_points(|x| a.transform_point3(x)),
            PatchLevel::Erbs(s) => s.transform_all(a, delta),
        }
    }
}

/// Applies A to every sample (slot 0 as a point, the partials as vectors), writing the change
/// into `delta` (a buffer kept between edits: a fresh one would be page-faulted in every time).
fn transform_samples(samples: &mut [DVec3], a: &DMat4, stride: usize, delta: &mut Vec<DVec3>) {
    delta.clear();
    delta.resize(samples.len(), DVec3::ZERO);
    for (d, s) in delta
        .chunks_exact_mut(stride)
        .zip(samples.chunks_exact_mut(stride))
    {
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
}

/// One knot cell's 2 × 2 patches side by side: width-8 bases and the 8 × 8 net.
struct DenseCell {
    cu: Vec<DenseRow<{ 2 * DENSE }>>,
    cv: Vec<DenseRow<{ 2 * DENSE }>>,
    net: [[DVec3; 2 * DENSE]; 2 * DENSE],
}

/// An ERBS surface pre-evaluated at given parameters per direction.
#[derive(Debug, Clone)]
pub(crate) struct SurfaceLevel {
    axes: [ErbsAxis; 2],
    /// The knots the axes tabulate, so a refresh can tell whether the structure changed.
    knots: [ErbsKnots; 2],
    partials: Vec<(usize, usize)>,
    terms: Vec<Vec<BlendTerm>>,
    /// Row-major [nu][nv].
    patches: Vec<PatchLevel>,
    pub grid: SampleGrid,
    /// Whether a change is returned with its values: a parent level blends them in; the top
    /// level only needs where it changed.
    record: bool,
    /// The partials are S, Su, Sv (drawing): dense patches go through the dense kernels.
    shading: bool,
    /// The change of an ERBS patch's samples, kept between edits.
    scratch: Vec<DVec3>,
    /// Samples whose normal degenerated in a kernel, for the sampler's model fallback.
    pub degenerate: Vec<(usize, usize)>,
}

impl SurfaceLevel {
    /// The level, sampled.
    pub fn new(
        surface: &ErbsSurface,
        params: [Vec<f64>; 2],
        set: PartialSet,
        normals: bool,
        record: bool,
    ) -> Self {
        let mut level = Self::tabulated(surface, params, set, normals, record);
        let [mu, mv] = level.grid.dims;
        level.fill(&[0..mu, 0..mv]);
        level
    }

    /// The level's tables and nets, not sampled yet.
    fn tabulated(
        surface: &ErbsSurface,
        params: [Vec<f64>; 2],
        set: PartialSet,
        normals: bool,
        record: bool,
    ) -> Self {
        let g = set.max_order();
        let [ku, kv] = surface.knots();
        let [pu, pv] = params;
        let dims = [pu.len(), pv.len()];
        let axes = [
            ErbsAxis::new(ku, surface.bfunction(), pu, g),
            ErbsAxis::new(kv, surface.bfunction(), pv, g),
        ];
        let partials = set.list();
        let shading = partials == [(0, 0), (1, 0), (0, 1)];
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
        let nv = surface.count()[1];
        let patches = surface
            .local_patches()
            .iter()
            .enumerate()
            .map(|(idx, p)| PatchLevel::new(p, &axes, [idx / nv, idx % nv], &set))
            .collect();
        Self {
            axes,
            knots: surface.knots().clone(),
            partials,
            terms,
            patches,
            grid: SampleGrid::new(dims, set, normals),
            record,
            shading,
            scratch: Vec::new(),
            degenerate: Vec::new(),
        }
    }

    fn nv(&self) -> usize {
        self.axes[1].locals()
    }

    fn all(&self) -> [Range<usize>; 2] {
        [0..self.grid.dims[0], 0..self.grid.dims[1]]
    }

    /// Whether every local patch is polynomial (no deeper level can drift on its own).
    pub fn is_flat(&self) -> bool {
        self.patches
            .iter()
            .all(|p| matches!(p, PatchLevel::Spline(_)))
    }

    /// Samples `region` again from the patches, knot cell by knot cell.
    pub fn fill(&mut self, region: &[Range<usize>; 2]) -> Patch {
        let mut normals = true;
        let ucells = self.axes[0].cells().to_vec();
        let vcells = self.axes[1].cells().to_vec();
        let done = self.fill_dense_in_parallel(region);
        // `done` has one entry per u-cell with rows in the region.
        let mut bands = done.iter();
        for cu in &ucells {
            let rows = clip(&cu.samples, &region[0]);
            if rows.is_empty() {
                continue;
            }
            let done = bands.next();
            for (m, cv) in vcells.iter().enumerate() {
                let cols = clip(&cv.samples, &region[1]);
                if cols.is_empty() || done.is_some_and(|row| row[m]) {
                    continue;
                }
                normals &= self.fill_cell(cu.locals, cv.locals, [rows.clone(), cols]);
            }
        }
        Patch {
            rows: region[0].clone(),
            cols: region[1].clone(),
            values: Vec::new(),
            normals: normals && self.grid.normals.is_some(),
        }
    }

    /// The dense cells of a large `region` (a full pass of a drawn surface), one band of knot
    /// cells' rows per task on every core; returns per u-cell and v-cell whether it was
    /// written (nothing when the region is small or there is one thread). Each cell is the
    /// same dense pass as in [`Self::fill_cell`] and the degenerate samples are kept in the
    /// same order, so the result is bit for bit that of one thread.
    fn fill_dense_in_parallel(&mut self, region: &[Range<usize>; 2]) -> Vec<Vec<bool>> {
        let bands: Vec<(Range<usize>, [usize; 2])> = self.axes[0]
            .cells()
            .iter()
            .map(|c| (clip(&c.samples, &region[0]), c.locals))
            .filter(|(rows, _)| !rows.is_empty())
            .collect();
        let blocks: Vec<Range<usize>> = bands.iter().map(|b| b.0.clone()).collect();
        let samples = region[0].len() * region[1].len();
        let ascending = blocks.windows(2).all(|w| w[0].end <= w[1].start);
        if !self.shading
            || !ascending
            || blocks.len() < 2
            || samples < parallel::MIN_PARALLEL_SAMPLES
            || parallel::threads() < 2
        {
            return Vec::new();
        }
        let mv = self.grid.dims[1];
        let mut data = std::mem::take(&mut self.grid.data);
        let mut normals = self.grid.normals.take();
        let vcells = self.axes[1].cells();
        let this = &*self;
        let data_parts = parallel::split_rows(&mut data, &blocks, mv * 3);
        let mut normal_parts: Vec<Option<&mut [DVec3]>> = match normals.as_deref_mut() {
            Some(n) => parallel::split_rows(n, &blocks, mv)
                .into_iter()
                .map(Some)
                .collect(),
            None => blocks.iter().map(|_| None).collect(),
        };
        let mut jobs: Vec<_> = bands
            .iter()
            .zip(data_parts)
            .zip(normal_parts.iter_mut())
            .map(|((band, d), n)| (band, d, n.take(), Vec::new(), Vec::new()))
            .collect();
        parallel::for_each_mut(&mut jobs, |(band, data, normals, degenerate, done)| {
            let (rows, ku) = (&band.0, band.1);
            for cv in vcells {
                let cols = clip(&cv.samples, &region[1]);
                let kv = cv.locals;
                let ids = ku.map(|k| kv.map(|l| k * this.nv() + l));
                let rect = [rows.clone(), cols.clone()];
                let cell = match cols.is_empty() {
                    true => None,
                    false => this.dense_cell(ids, ku, kv, &rect),
                };
                done.push(cell.is_some());
                let Some(cell) = cell else { continue };
                let target = Target {
                    data,
                    normals: normals.as_deref_mut(),
                    width: mv,
                    row0: 0,
                    col0: cols.start,
                };
                let first = degenerate.len();
                dense::pass::<{ 2 * DENSE }, { 2 * DENSE }, false>(
                    &cell.cu, &cell.cv, &cell.net, target, degenerate,
                );
                for d in &mut degenerate[first..] {
                    d.0 += rows.start;
                }
            }
        });
        let mut done = Vec::with_capacity(jobs.len());
        for (_, _, _, degenerate, cells) in jobs {
            self.degenerate.extend(degenerate);
            done.push(cells);
        }
        self.grid.data = data;
        self.grid.normals = normals;
        done
    }

    /// One knot cell's samples in `rect`: in one dense pass when its four patches allow,
    /// otherwise as the sum of the four shares. Returns whether the normals were written.
    fn fill_cell(&mut self, ku: [usize; 2], kv: [usize; 2], rect: [Range<usize>; 2]) -> bool {
        let nv = self.nv();
        let ids = ku.map(|k| kv.map(|l| k * nv + l));
        let mv = self.grid.dims[1];
        if let Some(cell) = self.dense_cell(ids, ku, kv, &rect) {
            let target = Target {
                data: &mut self.grid.data,
                normals: self.grid.normals.as_deref_mut(),
                width: mv,
                row0: rect[0].start,
                col0: rect[1].start,
            };
            dense::pass::<{ 2 * DENSE }, { 2 * DENSE }, false>(
                &cell.cu,
                &cell.cv,
                &cell.net,
                target,
                &mut self.degenerate,
            );
            return true;
        }
        let stride = self.partials.len();
        for i in rect[0].clone() {
            self.grid.data[(i * mv + rect[1].start) * stride..(i * mv + rect[1].end) * stride]
                .fill(DVec3::ZERO);
        }
        for idx in ids.into_iter().flatten() {
            match &self.patches[idx] {
                PatchLevel::Spline(p) => {
                    let mut out = Out {
                        data: &mut self.grid.data,
                        origin: (0, 0),
                        width: mv,
                        stride,
                    };
                    let kl = [idx / nv, idx % nv];
                    add_share(
                        p,
                        &self.axes,
                        kl,
                        &p.points,
                        &rect,
                        &self.partials,
                        &self.terms,
                        &mut out,
                    );
                }
                PatchLevel::Erbs(_) => self.blend_patch(idx, &rect),
            }
        }
        false
    }

    /// The cell's patches side by side, when all four are dense, on a `Shading` level, and the
    /// two patches of each row (column) share their u (v) basis — the cell is then a tensor
    /// product.
    fn dense_cell(
        &self,
        ids: [[usize; 2]; 2],
        ku: [usize; 2],
        kv: [usize; 2],
        rect: &[Range<usize>; 2],
    ) -> Option<DenseCell> {
        if !self.shading {
            return None;
        }
        let p = ids.map(|row| {
            row.map(|idx| match &self.patches[idx] {
                PatchLevel::Spline(p) => p.dense.as_ref().map(|d| (p, d)),
                PatchLevel::Erbs(_) => None,
            })
        });
        let p = p.map(|row| row.map(|x| x.ok_or(())));
        let [[Ok(p00), Ok(p01)], [Ok(p10), Ok(p11)]] = p else {
            return None;
        };
        let same =
            |a: &SplinePatch, b: &SplinePatch, dir: usize| a.tables[dir].same_basis(&b.tables[dir]);
        if !(same(p00.0, p01.0, 0)
            && same(p10.0, p11.0, 0)
            && same(p00.0, p10.0, 1)
            && same(p01.0, p11.0, 1))
        {
            return None;
        }
        let [p00, p01, p10, p11] = [p00.1, p01.1, p10.1, p11.1];
        let side = |dir: usize, locals: [usize; 2], halves: [&[DenseRow<DENSE>]; 2]| {
            let r = &rect[dir];
            let first = locals.map(|k| self.axes[dir].local_index(k, r.start));
            r.clone()
                .map(|i| {
                    let t = i - r.start;
                    std::array::from_fn(|o| {
                        std::array::from_fn(|c| {
                            halves[c / DENSE][first[c / DENSE] + t][o][c % DENSE]
                        })
                    })
                })
                .collect::<Vec<DenseRow<{ 2 * DENSE }>>>()
        };
        let cu = side(0, ku, [&p00.rows[0], &p10.rows[0]]);
        let cv = side(1, kv, [&p00.rows[1], &p01.rows[1]]);
        let nets = [[&p00.net, &p01.net], [&p10.net, &p11.net]];
        let net = std::array::from_fn(|a| {
            std::array::from_fn(|b| nets[a / DENSE][b / DENSE][a % DENSE][b % DENSE])
        });
        Some(DenseCell { cu, cv, net })
    }

    /// Blends ERBS patch idx's own samples in whole over the level samples in `rect`.
    fn blend_patch(&mut self, idx: usize, rect: &[Range<usize>; 2]) {
        let PatchLevel::Erbs(child) = &mut self.patches[idx] else {
            return;
        };
        let values = std::mem::take(&mut child.grid.data);
        let all = child.all();
        let record = std::mem::replace(&mut self.record, false);
        self.blend(idx, &values, all, Some(rect));
        self.record = record;
        if let PatchLevel::Erbs(child) = &mut self.patches[idx] {
            child.grid.data = values;
        }
    }

    /// ∂^{ab}P += Σ C(a,a')C(b,b') Wu_k^(a−a') Wv_l^(b−b') Δs^(a'b') for ERBS patch idx's local
    /// samples `local` (rows × cols; `delta` covers exactly them), restricted to level samples
    /// `only` if given. Returns the change of this level's samples, rectangle by rectangle.
    fn blend(
        &mut self,
        idx: usize,
        delta: &[DVec3],
        local: [Range<usize>; 2],
        only: Option<&[Range<usize>; 2]>,
    ) -> Vec<Patch> {
        let nv = self.nv();
        let (k, l) = (idx / nv, idx % nv);
        let stride = self.partials.len();
        let width = local[1].len();
        let mv = self.grid.dims[1];
        let mut out = Vec::new();
        for pu in self.axes[0].pieces(k) {
            let Some(mut rows) = pu.level_range(&local[0]) else {
                continue;
            };
            if let Some(o) = only {
                rows = clip(&rows, &o[0]);
            }
            for pv in self.axes[1].pieces(l) {
                let Some(mut cols) = pv.level_range(&local[1]) else {
                    continue;
                };
                if let Some(o) = only {
                    cols = clip(&cols, &o[1]);
                }
                if rows.is_empty() || cols.is_empty() {
                    continue;
                }
                let n = if self.record {
                    rows.len() * cols.len() * stride
                } else {
                    0
                };
                let mut values = Vec::with_capacity(n);
                let wv: Vec<&[f64]> = cols.clone().map(|j| self.axes[1].weights(j, l)).collect();
                let lj0 = cols.start - pv.samples.start + pv.offset - local[1].start;
                for i in rows.clone() {
                    let wu = self.axes[0].weights(i, k);
                    let li = i - pu.samples.start + pu.offset - local[0].start;
                    let d = &delta
                        [(li * width + lj0) * stride..(li * width + lj0 + cols.len()) * stride];
                    let o = &mut self.grid.data[(i * mv + cols.start) * stride..]
                        [..cols.len() * stride];
                    if self.shading {
                        blend_shading_row(wu, &wv, d, o, self.record.then_some(&mut values));
                        continue;
                    }
                    for ((d, o), wv) in d
                        .chunks_exact(stride)
                        .zip(o.chunks_exact_mut(stride))
                        .zip(&wv)
                    {
                        for (slot, terms) in self.terms.iter().enumerate() {
                            let mut acc = DVec3::ZERO;
                            for &(c, ia, ib, s) in terms {
                                acc += d[s] * (c * wu[ia] * wv[ib]);
                            }
                            o[slot] += acc;
                            if self.record {
                                values.push(acc);
                            }
                        }
                    }
                }
                out.push(Patch {
                    rows: rows.clone(),
                    cols,
                    values,
                    normals: false,
                });
            }
        }
        out
    }

    /// Maps every patch and every sample by A (nested levels only: they keep no normals).
    fn transform_all(&mut self, a: &DMat4, delta: &mut Vec<DVec3>) {
        let stride = self.partials.len();
        for p in &mut self.patches {
            p.transform(a, delta);
        }
        transform_samples(&mut self.grid.data, a, stride, delta);
    }

    /// The level samples the patch at `path` covers, rectangle by rectangle (a path going on
    /// below a polynomial patch: that patch's).
    fn support(&self, path: &[[usize; 2]]) -> Vec<[Range<usize>; 2]> {
        let Some((&[k, l], rest)) = path.split_first() else {
            return Vec::new();
        };
        let Some(patch) = self
            .patches
            .get(k * self.nv() + l)
            .filter(|_| l < self.nv())
        else {
            return Vec::new();
        };
        let own = match (rest.is_empty(), patch) {
            (false, PatchLevel::Erbs(child)) => child.support(rest),
            _ => vec![[0..self.axes[0].local_len(k), 0..self.axes[1].local_len(l)]],
        };
        let mut out = Vec::new();
        for [ru, rv] in &own {
            for pu in self.axes[0].pieces(k) {
                let Some(rows) = pu.level_range(ru) else {
                    continue;
                };
                for pv in self.axes[1].pieces(l) {
                    if let Some(cols) = pv.level_range(rv) {
                        out.push([rows.clone(), cols]);
                    }
                }
            }
        }
        out
    }

    /// Applies `op` to the patch at `path` and returns this level's change.
    pub fn apply(&mut self, path: &[[usize; 2]], op: &PatchOp) -> Vec<Patch> {
        let Some((&[k, l], rest)) = path.split_first() else {
            return Vec::new();
        };
        let idx = k * self.nv() + l;
        if idx >= self.patches.len() {
            return Vec::new();
        }
        if !rest.is_empty() {
            let PatchLevel::Erbs(child) = &mut self.patches[idx] else {
                return Vec::new();
            };
            let changes = child.apply(rest, op);
            return changes
                .into_iter()
                .flat_map(|c| self.blend(idx, &c.values, [c.rows, c.cols], None))
                .collect();
        }
        match (op, &mut self.patches[idx]) {
            (PatchOp::Transform(a, _), PatchLevel::Erbs(child)) => {
                let mut delta = std::mem::take(&mut self.scratch);
                child.transform_all(a, &mut delta);
                let all = child.all();
                let changes = self.blend(idx, &delta, all, None);
                self.scratch = delta;
                changes
            }
            (PatchOp::Transform(_, new) | PatchOp::Update(new), _) => self.update(idx, new),
        }
    }

    /// Patch idx became `new`: a net delta through its tables when only its points moved,
    /// otherwise pre-evaluated again and its support sampled again.
    fn update(&mut self, idx: usize, new: &LocalPatch) -> Vec<Patch> {
        if let (PatchLevel::Spline(p), LocalPatch::Spline { surface, .. }) =
            (&mut self.patches[idx], new)
            && p.holds(surface)
        {
            let delta: Vec<DVec3> = surface
                .points()
                .iter()
                .zip(&p.points)
                .map(|(n, o)| *n - *o)
                .collect();
            p.set_points(surface.points());
            return self.add_net(idx, &delta);
        }
        let nv = self.nv();
        self.patches[idx] =
            PatchLevel::new(new, &self.axes, [idx / nv, idx % nv], &self.grid.partials);
        self.refill_support(idx)
    }

    /// Adds polynomial patch idx's share for a net change `delta` (the points that did not
    /// move bound the samples touched).
    fn add_net(&mut self, idx: usize, delta: &[DVec3]) -> Vec<Patch> {
        let nv = self.nv();
        let kl = [idx / nv, idx % nv];
        let Self {
            axes,
            partials,
            terms,
            patches,
            grid,
            record,
            degenerate,
            ..
        } = self;
        let PatchLevel::Spline(p) = &patches[idx] else {
            return Vec::new();
        };
        let [nun, nvn] = p.count;
        let moved: Vec<(usize, usize)> = (0..nun * nvn)
            .filter(|&q| delta[q] != DVec3::ZERO)
            .map(|q| (q / nvn, q % nvn))
            .collect();
        let (Some(a0), Some(a1)) = (
            moved.iter().map(|m| m.0).min(),
            moved.iter().map(|m| m.0).max(),
        ) else {
            return Vec::new();
        };
        let b0 = moved.iter().map(|m| m.1).min().unwrap_or(0);
        let b1 = moved.iter().map(|m| m.1).max().unwrap_or(0);
        let local = p.touched(a0..a1 + 1, b0..b1 + 1);
        let stride = partials.len();
        let mv = grid.dims[1];
        let mut out = Vec::new();
        for pu in axes[0].pieces(kl[0]) {
            let Some(rows) = pu.level_range(&local[0]) else {
                continue;
            };
            for pv in axes[1].pieces(kl[1]) {
                let Some(cols) = pv.level_range(&local[1]) else {
                    continue;
                };
                let rect = [rows.clone(), cols.clone()];
                let n = rows.len() * cols.len() * stride;
                let mut values = if *record {
                    vec![DVec3::ZERO; n]
                } else {
                    Vec::new()
                };
                let mut normals = false;
                match &p.dense {
                    Some(d) => {
                        let lr = rows.start - pu.samples.start + pu.offset;
                        let lc = cols.start - pv.samples.start + pv.offset;
                        let cu = &d.rows[0][lr..lr + rows.len()];
                        let cv = &d.rows[1][lc..lc + cols.len()];
                        let net = erbs_patch::padded(delta, p.count);
                        if *record {
                            let target = Target {
                                data: &mut values,
                                normals: None,
                                width: cols.len(),
                                row0: 0,
                                col0: 0,
                            };
                            dense::pass::<DENSE, DENSE, false>(cu, cv, &net, target, degenerate);
                        } else {
                            normals = grid.normals.is_some();
                            let target = Target {
                                data: &mut grid.data,
                                normals: grid.normals.as_deref_mut(),
                                width: mv,
                                row0: rows.start,
                                col0: cols.start,
                            };
                            dense::pass::<DENSE, DENSE, true>(cu, cv, &net, target, degenerate);
                        }
                    }
                    None => {
                        let mut o = if *record {
                            Out {
                                data: &mut values,
                                origin: (rows.start, cols.start),
                                width: cols.len(),
                                stride,
                            }
                        } else {
                            Out {
                                data: &mut grid.data,
                                origin: (0, 0),
                                width: mv,
                                stride,
                            }
                        };
                        add_share(p, axes, kl, delta, &rect, partials, terms, &mut o);
                    }
                }
                if *record {
                    add_rect(&mut grid.data, mv, stride, &rect, &values);
                }
                out.push(Patch {
                    rows: rows.clone(),
                    cols,
                    values,
                    normals,
                });
            }
        }
        out
    }

    /// Samples patch idx's support again; a recording level returns the change.
    fn refill_support(&mut self, idx: usize) -> Vec<Patch> {
        let nv = self.nv();
        let (k, l) = (idx / nv, idx % nv);
        let stride = self.partials.len();
        let mv = self.grid.dims[1];
        let rects: Vec<[Range<usize>; 2]> = self.axes[0]
            .pieces(k)
            .iter()
            .flat_map(|pu| {
                self.axes[1]
                    .pieces(l)
                    .iter()
                    .map(|pv| [pu.samples.clone(), pv.samples.clone()])
            })
            .collect();
        let mut out = Vec::new();
        for rect in rects {
            if rect[0].is_empty() || rect[1].is_empty() {
                continue;
            }
            let old = self
                .record
                .then(|| copy_rect(&self.grid.data, mv, stride, &rect));
            let mut patch = self.fill(&rect);
            if let Some(mut old) = old {
                let new = copy_rect(&self.grid.data, mv, stride, &rect);
                for (o, n) in old.iter_mut().zip(new) {
                    *o = n - *o;
                }
                patch.values = old;
            }
            out.push(patch);
        }
        out
    }

    /// After [`ErbsSurface::insert_knot`] in direction `dir` inside interval i: the restricted
    /// patches and the new row or column are pre-evaluated, the others keep theirs, and the
    /// samples of the refined strip are sampled again. Returns the strip.
    pub fn refine(
        &mut self,
        old: &ErbsSurface,
        refined: &ErbsSurface,
        dir: usize,
        i: usize,
    ) -> Patch {
        let strip = self.axes[dir].touched_by_refinement(&old.knots()[dir], i, old.bfunction());
        let (right, _) = old.knots()[dir].right(i);
        self.axes[dir] = self.axes[dir].refined(&refined.knots()[dir], refined.bfunction(), i);
        self.knots = refined.knots().clone();
        let new_right = if right == 0 { 0 } else { right + 1 };
        let rebuilt = [i, i + 1, new_right];
        let [nu, nv] = refined.count();
        let old_nv = old.count()[1];
        let mut old_patches: Vec<Option<PatchLevel>> = std::mem::take(&mut self.patches)
            .into_iter()
            .map(Some)
            .collect();
        let mut patches = Vec::with_capacity(nu * nv);
        for k in 0..nu {
            for l in 0..nv {
                let (a, m) = if dir == 0 { (k, l) } else { (l, k) };
                let kept = if rebuilt.contains(&a) {
                    None
                } else {
                    let old_a = if a > i + 1 { a - 1 } else { a };
                    let (ok, ol) = if dir == 0 { (old_a, m) } else { (m, old_a) };
                    old_patches[ok * old_nv + ol].take()
                };
                patches.push(match kept {
                    Some(p) => p,
                    None => PatchLevel::new(
                        refined.local_patch(k, l),
                        &self.axes,
                        [k, l],
                        &self.grid.partials,
                    ),
                });
            }
        }
        self.patches = patches;
        let [mu, mv] = self.grid.dims;
        let region = if dir == 0 {
            [strip.clone(), 0..mv]
        } else {
            [0..mu, strip.clone()]
        };
        self.fill(&region)
    }

    /// Takes the model's points again at every depth and samples everything again; `None` when
    /// the structure (knots, patch kinds and bases) is not the tabulated one.
    pub fn refresh(&mut self, surface: &ErbsSurface) -> Option<Patch> {
        if !self.refresh_nets(surface) {
            return None;
        }
        let all = self.all();
        Some(self.fill(&all))
    }

    fn refresh_nets(&mut self, surface: &ErbsSurface) -> bool {
        if self.knots != *surface.knots() || self.patches.len() != surface.local_patches().len() {
            return false;
        }
        let nv = self.nv();
        for (idx, new) in surface.local_patches().iter().enumerate() {
            let kept = match (&mut self.patches[idx], new) {
                (PatchLevel::Spline(p), LocalPatch::Spline { surface, .. }) if p.holds(surface) => {
                    p.set_points(surface.points());
                    true
                }
                (PatchLevel::Erbs(child), LocalPatch::Erbs(e)) => child.refresh(e).is_some(),
                _ => false,
            };
            if !kept {
                self.patches[idx] =
                    PatchLevel::new(new, &self.axes, [idx / nv, idx % nv], &self.grid.partials);
            }
        }
        true
    }
}

fn copy_rect(data: &[DVec3], mv: usize, stride: usize, rect: &[Range<usize>; 2]) -> Vec<DVec3> {
    let mut v = Vec::with_capacity(rect[0].len() * rect[1].len() * stride);
    for i in rect[0].clone() {
        v.extend_from_slice(
            &data[(i * mv + rect[1].start) * stride..(i * mv + rect[1].end) * stride],
        );
    }
    v
}

fn add_rect(
    data: &mut [DVec3],
    mv: usize,
    stride: usize,
    rect: &[Range<usize>; 2],
    values: &[DVec3],
) {
    let w = rect[1].len() * stride;
    for (i, v) in rect[0].clone().zip(values.chunks_exact(w)) {
        let o = &mut data[(i * mv + rect[1].start) * stride..][..w];
        for (o, v) in o.iter_mut().zip(v) {
            *o += *v;
        }
    }
}

/// One level row of the blend for S, Su, Sv (Leibniz in each direction with W, W'):
/// ΔS = Wu Wv Δs, ΔSu = Wu' Wv Δs + Wu Wv Δsu, ΔSv = Wu Wv' Δs + Wu Wv Δsv.
#[inline]
fn blend_shading_row(
    wu: &[f64],
    wv: &[&[f64]],
    delta: &[DVec3],
    out: &mut [DVec3],
    mut values: Option<&mut Vec<DVec3>>,
) {
    let (u0, u1) = (wu[0], wu[1]);
    for ((d, o), wv) in delta.chunks_exact(3).zip(out.chunks_exact_mut(3)).zip(wv) {
        let (v0, v1) = (wv[0], wv[1]);
        let w = u0 * v0;
        let s = d[0] * w;
        let su = d[0] * (u1 * v0) + d[1] * w;
        let sv = d[0] * (u0 * v1) + d[2] * w;
        o[0] += s;
        o[1] += su;
        o[2] += sv;
        if let Some(v) = values.as_deref_mut() {
            v.extend_from_slice(&[s, su, sv]);
        }
    }
}

/// A top-level ERBS surface: the level at uniform parameters over its domain (with unit normals
/// when rendering).
#[derive(Debug, Clone)]
pub struct ErbsSurfaceSampler {
    model: ErbsSurfaceModel,
    level: SurfaceLevel,
}

impl ErbsSurfaceSampler {
    #[must_use]
    pub fn new(model: ErbsSurfaceModel, set: PartialSet, normals: bool) -> Self {
        let level = Self::tabulated(&model, set, normals);
        let mut s = Self { model, level };
        s.sample_all();
        s
    }

    fn tabulated(model: &ErbsSurfaceModel, set: PartialSet, normals: bool) -> SurfaceLevel {
        let [(u0, u1), (v0, v1)] = model.surface().domain();
        let [mu, mv] = model.samples();
        let params = [uniform_params(u0, u1, mu), uniform_params(v0, v1, mv)];
        SurfaceLevel::tabulated(model.surface(), params, set, normals, false)
    }

    fn sample_all(&mut self) -> DirtyRegion {
        let all = self.level.all();
        let patch = self.level.fill(&all);
        self.finish(&[patch])
    }

    /// Normals where no kernel wrote them, the model fallback where they degenerated, and the
    /// region changed.
    fn finish(&mut self, changes: &[Patch]) -> DirtyRegion {
        let mut region = DirtyRegion::NOTHING;
        for c in changes {
            if !c.normals {
                self.update_normals(c.rows.clone(), c.cols.clone());
            }
            region = region.union(DirtyRegion::surface(c.rows.clone(), c.cols.clone()));
        }
        let degenerate = std::mem::take(&mut self.level.degenerate);
        if !degenerate.is_empty() {
            let params = [
                self.level.axes[0].params.as_slice(),
                self.level.axes[1].params.as_slice(),
            ];
            resolve_degenerate(
                &mut self.level.grid,
                &degenerate,
                params,
                self.model.surface(),
            );
        }
        region
    }

    fn update_normals(&mut self, rows: Range<usize>, cols: Range<usize>) {
        let params = [
            self.level.axes[0].params.as_slice(),
            self.level.axes[1].params.as_slice(),
        ];
        crate::sampling::normals::update(
            &mut self.level.grid,
            rows,
            cols,
            params,
            self.model.surface(),
        );
    }

    /// The local at `path` changed in the model (by A if given): the level follows.
    fn follow(&mut self, path: &[[usize; 2]], transform: Option<&DMat4>) -> Vec<Patch> {
        let Some(local) = self.model.surface().local_at(path) else {
            return Vec::new();
        };
        let op = match transform {
            Some(a) => PatchOp::Transform(a, local),
            None => PatchOp::Update(local),
        };
        self.level.apply(path, &op)
    }
}

impl Sampler for ErbsSurfaceSampler {
    type Model = ErbsSurfaceModel;
    type Edit = ErbsSurfaceEdit;

    fn model(&self) -> &ErbsSurfaceModel {
        &self.model
    }

    fn grid(&self) -> &SampleGrid {
        &self.level.grid
    }

    fn params(&self) -> Vec<&[f64]> {
        vec![&self.level.axes[0].params, &self.level.axes[1].params]
    }

    fn apply_prepared(
        &mut self,
        edit: &ErbsSurfaceEdit,
        result: Option<ErbsSurfaceModel>,
    ) -> DirtyRegion {
        let changes = match edit {
            ErbsEdit::Local(e) => {
                edit.apply_prepared(&mut self.model, result);
                let transform = match e {
                    LocalEdit::Transform { matrix, .. } => Some(matrix),
                    _ => None,
                };
                self.follow(e.local().steps(), transform)
            }
            ErbsEdit::InsertKnot {
                local: None,
                at: (dir, t),
                ..
            } => {
                let i = self.model.surface().knots()[*dir].locate(*t);
                let old = apply_keeping_old(edit, &mut self.model, result);
                if self.model.surface() == old.surface() {
                    return DirtyRegion::NOTHING;
                }
                vec![
                    self.level
                        .refine(old.surface(), self.model.surface(), *dir, i),
                ]
            }
            ErbsEdit::InsertKnot {
                local: Some(path), ..
            }
            | ErbsEdit::ToErbs { local: path, .. }
            | ErbsEdit::SetLocal { local: path, .. } => {
                edit.apply_prepared(&mut self.model, result);
                self.follow(path.steps(), None)
            }
            ErbsEdit::Restore(_) => {
                edit.apply_prepared(&mut self.model, result);
                return self.full();
            }
        };
        self.finish(&changes)
    }

    /// The region again from the nets (which are the model's); a level with ERBS patches
    /// samples everything again, since their own samples drift too.
    fn rebuild(&mut self, region: DirtyRegion) -> DirtyRegion {
        if region.is_empty() {
            return DirtyRegion::NOTHING;
        }
        if !self.level.is_flat() {
            return self.full();
        }
        let patch = self.level.fill(&[region.rows, region.cols]);
        self.finish(&[patch])
    }

    /// Everything again from the model, reusing the tables when its structure is the
    /// tabulated one.
    fn full(&mut self) -> DirtyRegion {
        match self.level.refresh(self.model.surface()) {
            Some(patch) => self.finish(&[patch]),
            None => {
                let normals = self.level.grid.normals.is_some();
                let set = self.level.grid.partials.clone();
                self.level = Self::tabulated(&self.model, set, normals);
                self.sample_all()
            }
        }
    }
}

impl crate::model::kind::Support for ErbsSurfaceSampler {
    fn support(&self, target: EditTarget) -> Vec<DirtyRegion> {
        let path = match target {
            EditTarget::Local(path) => path.to_surface(),
            _ => None,
        };
        match path {
            Some(p) => self
                .level
                .support(p.steps())
                .into_iter()
                .map(|[rows, cols]| DirtyRegion::surface(rows, cols))
                .collect(),
            None => vec![DirtyRegion::whole(self.level.grid.dims)],
        }
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
