//! Pre-evaluated ERBS surfaces, hierarchically: every local patch is pre-sampled on its support
//! sub-grid at its parent's parameters (a polynomial patch in two passes, an ERBS patch as a
//! level of its own), and blended by the Leibniz rule in both directions. An edit at any depth
//! returns the change of that level's samples over the edited patch's support; each parent
//! blends it in over the same samples.

use super::axis::HermiteTable;
use super::dirty::DirtyRegion;
use super::erbs_axis::{ErbsAxis, Piece};
use super::grid::{PartialSet, SampleGrid};
use super::normals::NormalSource;
use super::object::Sampler;
use super::shading::{self, ShadingGrid};
use super::spline_surface::{Rect, two_pass};
use crate::geom::erbs::{ErbsSurface, LocalPatch};
use crate::geom::knots::uniform_params;
use crate::geom::point::binomial;
use crate::model::{ErbsEdit, ErbsSurfaceEdit, ErbsSurfaceModel, KindEdit, LocalEdit};
use glam::{DMat4, DVec3};
use std::ops::Range;

/// A change of a level's samples over `rows × cols`, `stride` vectors per sample, row-major.
#[derive(Debug, Clone)]
pub(crate) struct Patch {
    pub rows: Range<usize>,
    pub cols: Range<usize>,
    pub values: Vec<DVec3>,
}

/// What reaches a local patch at the end of a path.
pub(crate) enum PatchOp<'a> {
    Transform(&'a DMat4),
    MovePoint([usize; 2], DVec3),
    Replace(&'a LocalPatch),
}

/// One local patch's pre-evaluation on its support sub-grid (local rows × local cols).
#[derive(Debug, Clone)]
enum PatchLevel {
    Spline {
        tables: Box<[HermiteTable; 2]>,
        samples: Vec<DVec3>,
    },
    Erbs(Box<SurfaceLevel>),
}

impl PatchLevel {
    fn new(patch: &LocalPatch, params: [Vec<f64>; 2], set: &PartialSet) -> Self {
        let g = set.max_order();
        match patch {
            LocalPatch::Spline { surface, .. } => {
                let [ku, kv] = surface.knots();
                let [du, dv] = surface.degree();
                let [nu, nv] = surface.count();
                let [pu, pv] = params;
                let tables = [
                    HermiteTable::at_params(ku, du, nu, pu, g),
                    HermiteTable::at_params(kv, dv, nv, pv, g),
                ];
                let (rows, cols) = (tables[0].len(), tables[1].len());
                let mut samples = vec![DVec3::ZERO; rows * cols * set.len()];
                sample_spline(&tables, surface.points(), nv, set, &mut samples);
                PatchLevel::Spline {
                    tables: Box::new(tables),
                    samples,
                }
            }
            LocalPatch::Erbs(e) => PatchLevel::Erbs(Box::new(SurfaceLevel::new(
                e,
                params,
                set.clone(),
                false,
                true,
            ))),
        }
    }

    fn samples(&self) -> &[DVec3] {
        match self {
            PatchLevel::Spline { samples, .. } => samples,
            PatchLevel::Erbs(s) => &s.grid.data,
        }
    }

    fn samples_mut(&mut self) -> &mut Vec<DVec3> {
        match self {
            PatchLevel::Spline { samples, .. } => samples,
            PatchLevel::Erbs(s) => &mut s.grid.data,
        }
    }

    /// Applies A to the samples, writing their change into `delta` (resized to fit).
    fn transform(&mut self, a: &DMat4, stride: usize, delta: &mut Vec<DVec3>) {
        match self {
            PatchLevel::Spline { samples, .. } => transform_samples(samples, a, stride, delta),
            PatchLevel::Erbs(s) => s.transform_all(a, delta),
        }
    }
}

/// Samples a polynomial patch on its tables' sub-grid: the shading kernel for S, Su, Sv of
/// degrees 1..=3, the generic two passes otherwise.
fn sample_spline(
    tables: &[HermiteTable; 2],
    points: &[DVec3],
    nv: usize,
    set: &PartialSet,
    out: &mut [DVec3],
) {
    let [tu, tv] = tables;
    let (rows, cols) = (tu.len(), tv.len());
    if *set == PartialSet::Shading && shading::surface_supported([tu.degree(), tv.degree()]) {
        let grid = ShadingGrid {
            data: out,
            normals: None,
            width: cols,
        };
        shading::sample_surface(tu, tv, points, nv, 0..rows, 0..cols, grid, &mut Vec::new());
        return;
    }
    let rect = Rect {
        rows: 0..rows,
        cols: 0..cols,
        origin: (0, 0),
        width: cols,
        stride: set.len(),
    };
    two_pass(tu, tv, points, nv, &set.list(), &rect, out);
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

/// Where a blend takes a patch's change from.
enum Delta<'a> {
    /// The change, local rows × cols.
    Values(&'a [DVec3]),
    /// The patch's samples, to be transformed by A as they are blended (each exactly once:
    /// the pieces of a support partition its local samples).
    Transform(&'a mut [DVec3], &'a DMat4),
}

/// For output partial (a, b): Σ over (a', b') ≤ (a, b) of C(a,a')C(b,b') Wu^(a−a') Wv^(b−b') s^(a'b').
type BlendTerm = (f64, usize, usize, usize);

/// An ERBS surface pre-evaluated at given parameters per direction.
#[derive(Debug, Clone)]
pub(crate) struct SurfaceLevel {
    axes: [ErbsAxis; 2],
    partials: Vec<(usize, usize)>,
    terms: Vec<Vec<BlendTerm>>,
    /// Row-major [nu][nv].
    patches: Vec<PatchLevel>,
    pub grid: SampleGrid,
    /// Whether a change is returned with its values: a parent level blends them in; the top
    /// level only needs where it changed.
    record: bool,
    /// The partials are S, Su, Sv (drawing): the blend runs a fixed kernel.
    shading: bool,
    /// The change of the edited patch's samples, kept between edits.
    scratch: Vec<DVec3>,
}

impl SurfaceLevel {
    pub fn new(
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
        let [nu, nv] = surface.count();
        let patches = (0..nu * nv)
            .map(|idx| {
                let (k, l) = (idx / nv, idx % nv);
                PatchLevel::new(
                    surface.local_patch(k, l),
                    [axes[0].local_params(k), axes[1].local_params(l)],
                    &set,
                )
            })
            .collect();
        let mut level = Self {
            axes,
            partials,
            terms,
            patches,
            grid: SampleGrid::new(dims, set, normals),
            record: false,
            shading,
            scratch: Vec::new(),
        };
        for idx in 0..level.patches.len() {
            level.blend_patch(idx, None);
        }
        level.record = record;
        level
    }

    /// Blends patch idx's own samples in whole (restricted to level rows `only` if given).
    fn blend_patch(&mut self, idx: usize, only: Option<&[Range<usize>; 2]>) {
        let values = std::mem::take(self.patches[idx].samples_mut());
        let all = self.local_dims(idx);
        let record = std::mem::replace(&mut self.record, false);
        self.blend(
            idx,
            &mut Delta::Values(&values),
            [0..all[0], 0..all[1]],
            only,
        );
        self.record = record;
        *self.patches[idx].samples_mut() = values;
    }

    fn nv(&self) -> usize {
        self.axes[1].locals()
    }

    /// Local sub-grid size of patch idx: [local rows, local cols].
    fn local_dims(&self, idx: usize) -> [usize; 2] {
        let nv = self.nv();
        [
            self.axes[0].local_len(idx / nv),
            self.axes[1].local_len(idx % nv),
        ]
    }

    /// ∂^{ab}P += Σ C(a,a')C(b,b') Wu_k^(a−a') Wv_l^(b−b') Δs^(a'b') for the patch's local
    /// samples `local` (rows × cols; `delta` covers exactly them), restricted to level rows
    /// `only` if given. Returns the change of this level's samples, rectangle by rectangle.
    fn blend(
        &mut self,
        idx: usize,
        source: &mut Delta,
        local: [Range<usize>; 2],
        only: Option<&[Range<usize>; 2]>,
    ) -> Vec<Patch> {
        let nv = self.nv();
        let (k, l) = (idx / nv, idx % nv);
        let stride = self.partials.len();
        let width = local[1].len();
        let mv = self.grid.dims[1];
        let mut out = Vec::new();
        let mut row = Vec::new();
        let upieces: Vec<Piece> = self.axes[0].pieces(k).to_vec();
        let vpieces: Vec<Piece> = self.axes[1].pieces(l).to_vec();
        for pu in &upieces {
            let Some(mut rows) = pu.level_range(&local[0]) else {
                continue;
            };
            if let Some(o) = only {
                rows = rows.start.max(o[0].start)..rows.end.min(o[0].end);
            }
            for pv in &vpieces {
                let Some(mut cols) = pv.level_range(&local[1]) else {
                    continue;
                };
                if let Some(o) = only {
                    cols = cols.start.max(o[1].start)..cols.end.min(o[1].end);
                }
                if rows.is_empty() || cols.is_empty() {
                    continue;
                }
                let rows = rows.clone();
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
                    let span =
                        (li * width + lj0) * stride..(li * width + lj0 + cols.len()) * stride;
                    let d = match source {
                        Delta::Values(delta) => &delta[span],
                        Delta::Transform(samples, a) => {
                            transform_samples(&mut samples[span], a, stride, &mut row);
                            &row
                        }
                    };
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
                out.push(Patch { rows, cols, values });
            }
        }
        out
    }

    fn transform_all(&mut self, a: &DMat4, delta: &mut Vec<DVec3>) {
        let stride = self.partials.len();
        for p in &mut self.patches {
            p.transform(a, stride, delta);
        }
        transform_samples(&mut self.grid.data, a, stride, delta);
    }

    /// Applies `op` to the patch at `path` and returns this level's change.
    pub fn apply(&mut self, path: &[[usize; 2]], op: &PatchOp) -> Vec<Patch> {
        let stride = self.partials.len();
        let Some((&[k, l], rest)) = path.split_first() else {
            return Vec::new();
        };
        let idx = k * self.nv() + l;
        if !rest.is_empty() {
            let PatchLevel::Erbs(child) = &mut self.patches[idx] else {
                return Vec::new();
            };
            let changes = child.apply(rest, op);
            return changes
                .into_iter()
                .flat_map(|c| {
                    self.blend(idx, &mut Delta::Values(&c.values), [c.rows, c.cols], None)
                })
                .collect();
        }
        let dims = self.local_dims(idx);
        let all = [0..dims[0], 0..dims[1]];
        match *op {
            PatchOp::Transform(a) => {
                if let PatchLevel::Spline { samples, .. } = &mut self.patches[idx] {
                    // A row at a time, straight into the blend: the patch's change never
                    // goes through memory as a whole.
                    let mut samples = std::mem::take(samples);
                    let changes =
                        self.blend(idx, &mut Delta::Transform(&mut samples, a), all, None);
                    *self.patches[idx].samples_mut() = samples;
                    return changes;
                }
                let mut delta = std::mem::take(&mut self.scratch);
                self.patches[idx].transform(a, stride, &mut delta);
                let changes = self.blend(idx, &mut Delta::Values(&delta), all, None);
                self.scratch = delta;
                changes
            }
            PatchOp::MovePoint([qa, qb], d) => {
                let PatchLevel::Spline {
                    tables, samples, ..
                } = &mut self.patches[idx]
                else {
                    return Vec::new();
                };
                let (rows, cols) = (tables[0].range(qa), tables[1].range(qb));
                let width = dims[1];
                let mut delta = Vec::with_capacity(rows.len() * cols.len() * stride);
                for li in rows.clone() {
                    for lj in cols.clone() {
                        let base = (li * width + lj) * stride;
                        for (slot, &(a, b)) in self.partials.iter().enumerate() {
                            let c = coefficient(&tables[0], li, a, qa)
                                * coefficient(&tables[1], lj, b, qb);
                            samples[base + slot] += d * c;
                            delta.push(d * c);
                        }
                    }
                }
                self.blend(idx, &mut Delta::Values(&delta), [rows, cols], None)
            }
            PatchOp::Replace(patch) => {
                let nv = self.nv();
                let params = [
                    self.axes[0].local_params(idx / nv),
                    self.axes[1].local_params(idx % nv),
                ];
                let fresh = PatchLevel::new(patch, params, &self.grid.partials);
                let delta: Vec<DVec3> = fresh
                    .samples()
                    .iter()
                    .zip(self.patches[idx].samples())
                    .map(|(a, b)| *a - *b)
                    .collect();
                self.patches[idx] = fresh;
                self.blend(idx, &mut Delta::Values(&delta), all, None)
            }
        }
    }

    /// After [`ErbsSurface::insert_knot`] in direction `dir` inside interval i: the restricted
    /// patches and the new row or column are pre-evaluated, the others keep theirs, and the
    /// samples of the refined strip are blended again. Returns the strip.
    pub fn refine(
        &mut self,
        old: &ErbsSurface,
        refined: &ErbsSurface,
        dir: usize,
        i: usize,
    ) -> [Range<usize>; 2] {
        let stride = self.partials.len();
        let strip = self.axes[dir].touched_by_refinement(&old.knots()[dir], i, old.bfunction());
        let (right, _) = old.knots()[dir].right(i);
        self.axes[dir] = self.axes[dir].refined(&refined.knots()[dir], refined.bfunction(), i);
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
                        [self.axes[0].local_params(k), self.axes[1].local_params(l)],
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
        for i in region[0].clone() {
            self.grid.data[(i * mv + region[1].start) * stride..(i * mv + region[1].end) * stride]
                .fill(DVec3::ZERO);
        }
        for idx in 0..self.patches.len() {
            self.blend_patch(idx, Some(&region));
        }
        region
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

/// M[li][order][q] of a table, 0 when q is not active there or the order is above the degree.
#[inline]
fn coefficient(t: &HermiteTable, j: usize, order: usize, q: usize) -> f64 {
    let first = t.first(j);
    if q < first || q > first + t.degree() {
        return 0.0;
    }
    t.row(j, order).map_or(0.0, |r| r[q - first])
}

/// A top-level ERBS surface: the level at uniform parameters over its domain (with unit normals
/// when rendering).
#[derive(Debug, Clone)]
pub struct ErbsSurfaceSampler {
    model: ErbsSurfaceModel,
    level: SurfaceLevel,
}

impl ErbsSurfaceSampler {
    pub fn new(model: ErbsSurfaceModel, set: PartialSet, normals: bool) -> Self {
        let level = Self::level(&model, set, normals);
        let mut s = Self { model, level };
        let [mu, mv] = s.level.grid.dims;
        s.update_normals(0..mu, 0..mv);
        s
    }

    fn level(model: &ErbsSurfaceModel, set: PartialSet, normals: bool) -> SurfaceLevel {
        let [(u0, u1), (v0, v1)] = model.surface().domain();
        let [mu, mv] = model.samples();
        let params = [uniform_params(u0, u1, mu), uniform_params(v0, v1, mv)];
        SurfaceLevel::new(model.surface(), params, set, normals, false)
    }

    fn finish(&mut self, changes: &[Patch]) -> DirtyRegion {
        let mut region = DirtyRegion::NOTHING;
        for c in changes {
            self.update_normals(c.rows.clone(), c.cols.clone());
            region = region.union(DirtyRegion::surface(c.rows.clone(), c.cols.clone()));
        }
        region
    }

    fn update_normals(&mut self, rows: Range<usize>, cols: Range<usize>) {
        let params = [
            self.level.axes[0].params.as_slice(),
            self.level.axes[1].params.as_slice(),
        ];
        super::normals::update(
            &mut self.level.grid,
            rows,
            cols,
            params,
            self.model.surface(),
        );
    }

    fn point(&self, path: &[[usize; 2]], [a, b]: [usize; 2]) -> DVec3 {
        match self.model.surface().local_at(path) {
            Some(LocalPatch::Spline { surface, .. }) => surface.point(a, b),
            _ => DVec3::ZERO,
        }
    }

    fn replace(&mut self, path: &[[usize; 2]]) -> Vec<Patch> {
        match self.model.surface().local_at(path) {
            Some(p) => self.level.apply(path, &PatchOp::Replace(p)),
            None => Vec::new(),
        }
    }
}

impl Sampler for ErbsSurfaceSampler {
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

    fn apply(&mut self, edit: &ErbsSurfaceEdit) -> DirtyRegion {
        let changes = match edit {
            ErbsEdit::Local(e) => {
                let path = e.local();
                match e {
                    LocalEdit::Transform { matrix, .. } => {
                        edit.apply(&mut self.model);
                        self.level.apply(path.steps(), &PatchOp::Transform(matrix))
                    }
                    LocalEdit::MovePoint { point, .. } => {
                        let before = self.point(path.steps(), *point);
                        edit.apply(&mut self.model);
                        let d = self.point(path.steps(), *point) - before;
                        self.level
                            .apply(path.steps(), &PatchOp::MovePoint(*point, d))
                    }
                    LocalEdit::SetPoints { .. } => {
                        edit.apply(&mut self.model);
                        self.replace(path.steps())
                    }
                }
            }
            ErbsEdit::InsertKnot {
                local: None,
                at: (dir, t),
                ..
            } => {
                let old = self.model.surface().clone();
                let i = old.knots()[*dir].locate(*t);
                edit.apply(&mut self.model);
                if self.model.surface() == &old {
                    return DirtyRegion::NOTHING;
                }
                let [rows, cols] = self.level.refine(&old, self.model.surface(), *dir, i);
                vec![Patch {
                    rows,
                    cols,
                    values: Vec::new(),
                }]
            }
            ErbsEdit::InsertKnot {
                local: Some(path), ..
            }
            | ErbsEdit::ToErbs { local: path, .. }
            | ErbsEdit::SetLocal { local: path, .. } => {
                edit.apply(&mut self.model);
                self.replace(path.steps())
            }
            ErbsEdit::Restore(_) => {
                edit.apply(&mut self.model);
                return self.full();
            }
        };
        self.finish(&changes)
    }

    /// ERBS updates are local anyway: drift control re-samples everything.
    fn rebuild(&mut self, _region: DirtyRegion) -> DirtyRegion {
        self.full()
    }

    fn full(&mut self) -> DirtyRegion {
        let normals = self.level.grid.normals.is_some();
        self.level = Self::level(&self.model, self.level.grid.partials.clone(), normals);
        let [mu, mv] = self.level.grid.dims;
        self.update_normals(0..mu, 0..mv);
        DirtyRegion::surface(0..mu, 0..mv)
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
