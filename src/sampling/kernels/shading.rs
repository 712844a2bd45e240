//! Fast paths for what the renderer samples: polynomial B-spline surfaces with S, Su, Sv and unit
//! normals (`PartialSet::Shading`), and curves with C, C'.
//!
//! They perform the generic code's multiplications and additions in the generic code's order,
//! except that sums start from their first product instead of from 0 (so the sign of an exact
//! zero may differ); the normal is exactly `regular_normal(Su, Sv)`. Only the loop structure
//! differs:
//! - the widths d+1 ∈ {2, 3, 4} are const generics, so the dot products have fixed trip counts
//!   and run without `Option` row lookups or bounds checks;
//! - `LANES` sample rows are evaluated together: they share every column's v-coefficients, so
//!   each coefficient load feeds `LANES` independent dot products, and lane-minor storage lets
//!   the autovectoriser emit SIMD for them (no `unsafe`, no intrinsics, any target);
//! - the normal is computed in the same pass, while the sample's partials are in L1, instead
//!   of in a second sweep over the grid (25 MB for 512² samples). Samples where Su × Sv
//!   degenerates are only recorded; the caller gives them the model fallback.

use super::lanes::{LANES, Lanes, QCol, fill_q, normals_of, partials, unit_normals};
use crate::sampling::tables::axis::HermiteTable;
use glam::DVec3;
use std::ops::Range;

/// The `Shading` grid a kernel writes: `data[((i - first_row) * width + j) * 3 + p]` with p over
/// S, Su, Sv, and `normals[(i - first_row) * width + j]` when there are normals. `first_row` is
/// 0 for a whole grid, the block's first row for one thread's row block.
pub(crate) struct ShadingGrid<'a> {
    pub data: &'a mut [DVec3],
    pub normals: Option<&'a mut [DVec3]>,
    pub width: usize,
    pub first_row: usize,
}

/// Whether [`sample_surface`] handles degrees `[du, dv]`: 1 to 3 each way. Degree 0 has no
/// first derivative row; higher degrees are rare enough to stay on the generic path.
#[must_use]
pub(crate) fn surface_supported(degree: [usize; 2]) -> bool {
    degree.iter().all(|d| (1..=3).contains(d))
}

/// Samples `rows × cols` of a polynomial surface with control points `pts` (row-major, `nv`
/// per row), tables built for order 1. Samples whose Su × Sv is degenerate are appended to
/// `degenerate` with an unspecified normal.
#[allow(clippy::too_many_arguments)]
pub(crate) fn sample_surface(
    tu: &HermiteTable,
    tv: &HermiteTable,
    pts: &[DVec3],
    nv: usize,
    rows: Range<usize>,
    cols: Range<usize>,
    out: ShadingGrid<'_>,
    degenerate: &mut Vec<(usize, usize)>,
) {
    let rect = Rect {
        tu,
        tv,
        pts,
        nv,
        rows,
        cols,
    };
    match tu.degree() {
        1 => rect.dispatch_v::<2>(out, degenerate),
        2 => rect.dispatch_v::<3>(out, degenerate),
        3 => rect.dispatch_v::<4>(out, degenerate),
        d => panic!("no fast shading path for u-degree {d}"),
    }
}

/// A rectangle of samples to compute.
struct Rect<'a> {
    tu: &'a HermiteTable,
    tv: &'a HermiteTable,
    pts: &'a [DVec3],
    nv: usize,
    rows: Range<usize>,
    cols: Range<usize>,
}

impl Rect<'_> {
    fn dispatch_v<const WU: usize>(&self, out: ShadingGrid<'_>, deg: &mut Vec<(usize, usize)>) {
        match self.tv.degree() {
            1 => self.sample::<WU, 2>(out, deg),
            2 => self.sample::<WU, 3>(out, deg),
            3 => self.sample::<WU, 4>(out, deg),
            d => panic!("no fast shading path for v-degree {d}"),
        }
    }

    fn sample<const WU: usize, const WV: usize>(
        &self,
        out: ShadingGrid<'_>,
        degenerate: &mut Vec<(usize, usize)>,
    ) {
        let (rows, cols, tv) = (self.rows.clone(), self.cols.clone(), self.tv);
        if rows.is_empty() || cols.is_empty() {
            return;
        }
        assert!(self.tu.rows_kept() == 2 && self.tu.degree() + 1 == WU);
        assert!(tv.rows_kept() == 2 && tv.degree() + 1 == WV);
        let c0 = tv.first(cols.start);
        let kernel = Kernel::<WU, WV> {
            tu: self.tu,
            pts: self.pts,
            nv: self.nv,
            c0,
            nc: tv.spans[cols.end - 1] + 1 - c0,
            firsts: cols.clone().map(|j| tv.first(j) - c0).collect(),
            coeffs: &tv.matrix().as_chunks::<WV>().0.as_chunks::<2>().0[cols.clone()],
            cols,
        };
        let mv = out.width;
        let (r0, r1) = (rows.start - out.first_row, rows.end - out.first_row);
        let mut data = out.data[r0 * mv * 3..r1 * mv * 3].chunks_exact_mut(mv * 3);
        let split = rows.start + rows.len() / LANES * LANES;
        match out.normals {
            Some(normals) => {
                let mut normals = normals[r0 * mv..r1 * mv].chunks_exact_mut(mv);
                kernel.rows::<LANES, true>(rows.start..split, &mut data, &mut normals, degenerate);
                kernel.rows::<1, true>(split..rows.end, &mut data, &mut normals, degenerate);
            }
            None => {
                let mut none = std::iter::empty();
                kernel.rows::<LANES, false>(rows.start..split, &mut data, &mut none, degenerate);
                kernel.rows::<1, false>(split..rows.end, &mut data, &mut none, degenerate);
            }
        }
    }
}

/// What every row group of one rectangle shares, for u-width WU and v-width WV.
struct Kernel<'a, const WU: usize, const WV: usize> {
    tu: &'a HermiteTable,
    pts: &'a [DVec3],
    nv: usize,
    cols: Range<usize>,
    /// First control column the rectangle touches, and how many it touches.
    c0: usize,
    nc: usize,
    /// Per output column: the first active control column (relative to `c0`).
    firsts: Vec<usize>,
    /// Per output column: rows 0 and 1 of M_v.
    coeffs: &'a [[[f64; WV]; 2]],
}

impl<const WU: usize, const WV: usize> Kernel<'_, WU, WV> {
    /// Rows `rows` (a multiple of L of them) in groups of L; `data` and `normals` yield the
    /// grid's rows in the same order (`normals` only if N).
    fn rows<'g, const L: usize, const N: bool>(
        &self,
        rows: Range<usize>,
        data: &mut impl Iterator<Item = &'g mut [DVec3]>,
        normals: &mut impl Iterator<Item = &'g mut [DVec3]>,
        degenerate: &mut Vec<(usize, usize)>,
    ) {
        if rows.is_empty() {
            return;
        }
        // The v-coefficients repeated across the lanes once per rectangle, so the hot loop
        // loads them as whole vectors (SSE2 has no broadcast load).
        let coeffs: Vec<[[Lanes<L>; WV]; 2]> = self
            .coeffs
            .iter()
            .map(|cv| cv.map(|row| row.map(|c| Lanes([c; L]))))
            .collect();
        let mut q = vec![[Lanes([0.0; L]); 6]; self.nc];
        // Su, Sv, the normal and 1 where it is regular, of one sample column in lane layout.
        // The normal goes through memory on purpose: computed from registers and stored
        // straight into the rows, LLVM's SLP vectoriser pairs x and y of one lane to suit the
        // stores and leaves the square root and divisions scalar; from and to lane-layout
        // memory they vectorise across the lanes. (With two lanes LLVM forwards through the
        // buffer and pairs x and y again.)
        let mut stage = Box::new([Lanes([0.0; L]); 10]);
        let (j0, j1) = (self.cols.start, self.cols.end);
        for i0 in rows.step_by(L) {
            self.q_of(i0, &mut q);
            let d: [&mut [[DVec3; 3]]; L] = std::array::from_fn(|_| {
                data.next().expect("one grid row per sample row")[j0 * 3..j1 * 3]
                    .as_chunks_mut::<3>()
                    .0
            });
            let n: [&mut [DVec3]; L] = std::array::from_fn(|_| match N {
                true => &mut normals.next().expect("one normal row per sample row")[j0..j1],
                false => &mut [],
            });
            for (jj, (&f, cv)) in self.firsts.iter().zip(&coeffs).enumerate() {
                let win: &[QCol<L>; WV] = q[f..f + WV].try_into().expect("WV columns");
                let s = partials::<WV, L>(win, cv);
                for l in 0..L {
                    d[l][jj] = [
                        DVec3::new(s[0][l], s[1][l], s[2][l]),
                        DVec3::new(s[3][l], s[4][l], s[5][l]),
                        DVec3::new(s[6][l], s[7][l], s[8][l]),
                    ];
                }
                if !N {
                    continue;
                }
                stage[..6].copy_from_slice(&s[3..]);
                normals_staged(&mut stage);
                let v = &*stage;
                for l in 0..L {
                    n[l][jj] = DVec3::new(v[6][l], v[7][l], v[8][l]);
                }
                if v[9].0.contains(&0.0) {
                    let lanes = (0..L).filter(|&l| v[9][l] == 0.0);
                    degenerate.extend(lanes.map(|l| (i0 + l, j0 + jj)));
                }
            }
        }
    }

    /// Q0, Q1 of sample rows i0..i0+L at the rectangle's control columns (two_pass's first
    /// pass, each sum in the same order, from its first product).
    fn q_of<const L: usize>(&self, i0: usize, q: &mut [QCol<L>]) {
        // Per lane: the control rows it reads; per derivative order and k: the lanes' basis
        // values.
        let rows: [[&[DVec3]; WU]; L] = std::array::from_fn(|l| {
            let first = self.tu.first(i0 + l);
            std::array::from_fn(|k| &self.pts[(first + k) * self.nv + self.c0..][..self.nc])
        });
        let m: [[[f64; L]; WU]; 2] = std::array::from_fn(|r| {
            std::array::from_fn(|k| {
                std::array::from_fn(|l| self.tu.row(i0 + l, r).expect("order 0 and 1 rows")[k])
            })
        });
        fill_q::<WU, L, false>(q, |r, k, l| m[r][k][l], |l, k, c| rows[l][k][c]);
    }
}

/// Normals from Su, Sv in `stage[0..6]` into `stage[6..9]`, and 1 in `stage[9]` where regular.
#[inline(always)]
pub(crate) fn normals_staged<const L: usize>(stage: &mut [Lanes<L>; 10]) {
    let (n, ok) = unit_normals(
        [stage[0].0, stage[1].0, stage[2].0],
        [stage[3].0, stage[4].0, stage[5].0],
    );
    stage[6..9].copy_from_slice(&n.map(Lanes));
    stage[9] = Lanes(ok);
}

/// Moves control point (k, l) of a polynomial surface on a `Shading` grid by `delta`: S, Su, Sv
/// of the samples in I_k × I_l gain M_u[a][k]·M_v[b][l]·Δ and get new normals in the same pass.
/// Returns the touched rectangle; degenerate normals are appended as in [`sample_surface`].
#[must_use]
pub(crate) fn translate_surface(
    tables: [&HermiteTable; 2],
    point: [usize; 2],
    delta: DVec3,
    mut out: ShadingGrid<'_>,
    degenerate: &mut Vec<(usize, usize)>,
) -> (Range<usize>, Range<usize>) {
    let [tu, tv] = tables;
    let [k, l] = point;
    let (rows, cols) = (tu.range(k), tv.range(l));
    // The basis values of column k (resp. l) at each touched sample, once instead of per sample.
    let coeffs = |t: &HermiteTable, c: usize, j: usize| {
        let col = c - t.first(j);
        [
            t.row(j, 0).expect("order 0 row")[col],
            t.row(j, 1).expect("order 1 row")[col],
        ]
    };
    let cv: Vec<[f64; 2]> = cols.clone().map(|j| coeffs(tv, l, j)).collect();
    let mv = out.width;
    for i in rows.clone() {
        let cu = coeffs(tu, k, i);
        let row = (i - out.first_row) * mv;
        let (a, b) = (row + cols.start, row + cols.end);
        let data = out.data[a * 3..b * 3].as_chunks_mut::<3>().0;
        let normals = &mut out
            .normals
            .as_deref_mut()
            .expect("shading grids keep normals")[a..b];
        for (s, cv) in data.iter_mut().zip(&cv) {
            s[0] += delta * (cu[0] * cv[0]);
            s[1] += delta * (cu[1] * cv[0]);
            s[2] += delta * (cu[0] * cv[1]);
        }
        // The row segment is in L1 now; its normals go LANES samples at a time.
        normals_of(data, normals, |jj| degenerate.push((i, cols.start + jj)));
    }
    (rows, cols)
}

/// Whether [`sample_curve`] handles a curve of this degree sampled with C, C'.
#[must_use]
pub(crate) fn curve_supported(degree: usize) -> bool {
    (1..=3).contains(&degree)
}

/// C, C' of a polynomial curve at samples `range` into `data[2j..2j+2]`.
pub(crate) fn sample_curve(
    t: &HermiteTable,
    pts: &[DVec3],
    range: Range<usize>,
    data: &mut [DVec3],
) {
    match t.degree() {
        1 => sample_curve_w::<2>(t, pts, range, data),
        2 => sample_curve_w::<3>(t, pts, range, data),
        3 => sample_curve_w::<4>(t, pts, range, data),
        d => panic!("no fast curve path for degree {d}"),
    }
}

fn sample_curve_w<const W: usize>(
    t: &HermiteTable,
    pts: &[DVec3],
    range: Range<usize>,
    data: &mut [DVec3],
) {
    assert!(t.rows_kept() == 2 && t.degree() + 1 == W);
    let coeffs = &t.matrix().as_chunks::<W>().0.as_chunks::<2>().0[range.clone()];
    let spans = &t.spans[range.clone()];
    let out = data[range.start * 2..range.end * 2].as_chunks_mut::<2>().0;
    for ((o, cv), &span) in out.iter_mut().zip(coeffs).zip(spans) {
        let first = span + 1 - W;
        let win: &[DVec3; W] = pts[first..first + W].try_into().expect("W points");
        // From the first product, as in the surface kernel.
        let (mut c, mut d) = (win[0] * cv[0][0], win[0] * cv[1][0]);
        for k in 1..W {
            c += win[k] * cv[0][k];
            d += win[k] * cv[1][k];
        }
        *o = [c, d];
    }
}

/// Moves control point k of a polynomial curve sampled with C, C' (degree ≥ 1) by `delta`.
pub(crate) fn translate_curve(t: &HermiteTable, k: usize, delta: DVec3, data: &mut [DVec3]) {
    let range = t.range(k);
    let w = t.degree() + 1;
    let m = &t.matrix()[range.start * 2 * w..range.end * 2 * w];
    let out = data[range.start * 2..range.end * 2].as_chunks_mut::<2>().0;
    for ((o, cv), &span) in out
        .iter_mut()
        .zip(m.chunks_exact(2 * w))
        .zip(&t.spans[range])
    {
        let col = k + t.degree() - span;
        o[0] += delta * cv[col];
        o[1] += delta * cv[w + col];
    }
}
