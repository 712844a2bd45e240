//! The lane toolkit every sampling kernel is built from: `LANES` sample rows evaluated together,
//! one f64 lane per row, stored lane-minor so that the autovectoriser emits SIMD across the
//! rows (no `unsafe`, no intrinsics, any target). A tensor-product kernel forms Q0, Q1 (the u
//! direction applied to the control columns, [`fill_q`]), then S, Su, Sv per sample column
//! ([`partials`]), then unit normals exactly equal to `regular_normal`'s ([`unit_normals`],
//! [`NormalStage`], [`normals_of`]).

use crate::geom::surface::regular_normal;
use glam::DVec3;

/// Sample rows per group: four f64 lanes fill two SSE2 registers (one AVX register). With two,
/// each coefficient load serves too few rows to pay for itself; with eight, a column's
/// accumulators no longer fit the registers and spill.
pub(crate) const LANES: usize = 4;

/// Q0 = M_u[0]·C and Q1 = M_u[1]·C at one control column for L sample rows: x, y, z of Q0, then
/// of Q1, each with one lane per row.
pub(crate) type QCol<const L: usize> = [Lanes<L>; 6];

/// One value for each of L sample rows. Aligned so that SSE2 arithmetic may take its operands
/// straight from memory (legacy SSE memory operands must be 16-byte aligned).
#[derive(Debug, Clone, Copy)]
#[repr(C, align(16))]
pub(crate) struct Lanes<const L: usize>(pub [f64; L]);

impl<const L: usize> std::ops::Index<usize> for Lanes<L> {
    type Output = f64;
    #[inline(always)]
    fn index(&self, l: usize) -> &f64 {
        &self.0[l]
    }
}

impl<const L: usize> std::ops::IndexMut<usize> for Lanes<L> {
    #[inline(always)]
    fn index_mut(&mut self, l: usize) -> &mut f64 {
        &mut self.0[l]
    }
}

impl<const L: usize> std::ops::Add for Lanes<L> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Lanes(std::array::from_fn(|l| self.0[l] + o.0[l]))
    }
}

impl<const L: usize> std::ops::Mul for Lanes<L> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        Lanes(std::array::from_fn(|l| self.0[l] * o.0[l]))
    }
}

/// Q0 = Σ_k M_0k·P_k and Q1 = Σ_k M_1k·P_k (x, y, z of each) at every control column c of `q`,
/// for L sample rows: lane l weights the points `point(l, k, c)`, k < W, by its basis values
/// `basis(r, k, l)` of orders r = 0, 1 (two_pass's first pass, accumulated in registers one
/// column at a time). Each sum runs over k in order; with FROM_ZERO it starts from +0, as the
/// generic code's do, else from its first product, which saves an addition per value and can
/// differ only in the sign of an exact zero.
#[inline(always)]
pub(crate) fn fill_q<const W: usize, const L: usize, const FROM_ZERO: bool>(
    q: &mut [QCol<L>],
    basis: impl Fn(usize, usize, usize) -> f64,
    point: impl Fn(usize, usize, usize) -> DVec3,
) {
    for (c, qc) in q.iter_mut().enumerate() {
        let term = |k: usize, l: usize| {
            let p = point(l, k, c);
            let (a, b) = (basis(0, k, l), basis(1, k, l));
            [p.x * a, p.y * a, p.z * a, p.x * b, p.y * b, p.z * b]
        };
        let mut acc = [Lanes([0.0; L]); 6];
        for l in 0..L {
            for (v, t) in acc.iter_mut().zip(term(0, l)) {
                v[l] = if FROM_ZERO { v[l] + t } else { t };
            }
        }
        for k in 1..W {
            for l in 0..L {
                for (v, t) in acc.iter_mut().zip(term(k, l)) {
                    v[l] += t;
                }
            }
        }
        *qc = acc;
    }
}

/// S, Su, Sv (x, y, z each) of one sample column for L rows.
#[inline(always)]
#[must_use]
pub(crate) fn partials<const W: usize, const L: usize>(
    win: &[QCol<L>; W],
    cv: &[[Lanes<L>; W]; 2],
) -> [Lanes<L>; 9] {
    let [a, b] = cv;
    let mut s = [Lanes([0.0; L]); 9];
    for c in 0..3 {
        // Starting from the first product rather than from 0 saves an addition per value; the
        // only possible difference to the generic path is the sign of an exact zero.
        let (mut p, mut pu, mut pv) = (win[0][c] * a[0], win[0][3 + c] * a[0], win[0][c] * b[0]);
        for k in 1..W {
            p = p + win[k][c] * a[k];
            pu = pu + win[k][3 + c] * a[k];
            pv = pv + win[k][c] * b[k];
        }
        (s[c], s[3 + c], s[6 + c]) = (p, pu, pv);
    }
    s
}

/// `regular_normal` of L lanes of (Su, Sv), spelled out (same operations in the same order) and
/// without branches so that each step is one SIMD operation across the lanes: the normals, and
/// per lane 1 if regular (the normal is exactly `regular_normal`'s) else 0.
#[inline(always)]
#[must_use]
pub(crate) fn unit_normals<const L: usize>(
    u: [[f64; L]; 3],
    v: [[f64; L]; 3],
) -> ([[f64; L]; 3], [f64; L]) {
    let (n, ok, _) = unit_normals_inv(u, v);
    (n, ok)
}

/// [`unit_normals`] with 1/|Su × Sv| per lane, for kernels that need the area element too.
#[inline(always)]
#[must_use]
pub(crate) fn unit_normals_inv<const L: usize>(
    u: [[f64; L]; 3],
    v: [[f64; L]; 3],
) -> ([[f64; L]; 3], [f64; L], [f64; L]) {
    let lanes = |f: &dyn Fn(usize) -> f64| -> [f64; L] { std::array::from_fn(f) };
    let cx = lanes(&|l| u[1][l] * v[2][l] - v[1][l] * u[2][l]);
    let cy = lanes(&|l| u[2][l] * v[0][l] - v[2][l] * u[0][l]);
    let cz = lanes(&|l| u[0][l] * v[1][l] - v[0][l] * u[1][l]);
    let lu = lanes(&|l| u[0][l] * u[0][l] + u[1][l] * u[1][l] + u[2][l] * u[2][l]);
    let lv = lanes(&|l| v[0][l] * v[0][l] + v[1][l] * v[1][l] + v[2][l] * v[2][l]);
    // A plain select, not `f64::max` (whose NaN rule costs two more instructions): they differ
    // only when Su or Sv has a NaN, and then |Su × Sv|² is NaN and the lane is not regular
    // either way, so the flags and normals stay exactly `regular_normal`'s.
    let scale = lanes(&|l| if lu[l] > lv[l] { lu[l] } else { lv[l] });
    let len2 = lanes(&|l| cx[l] * cx[l] + cy[l] * cy[l] + cz[l] * cz[l]);
    let ok = lanes(&|l| {
        let ok = (scale[l] > 0.0) & (len2[l] > 1e-20 * scale[l] * scale[l]) & len2[l].is_finite();
        if ok { 1.0 } else { 0.0 }
    });
    let inv = lanes(&|l| 1.0 / len2[l].sqrt());
    let n = [
        lanes(&|l| cx[l] * inv[l]),
        lanes(&|l| cy[l] * inv[l]),
        lanes(&|l| cz[l] * inv[l]),
    ];
    (n, ok, inv)
}

/// Su, Sv of a block of samples component by component (one array per coordinate), and their
/// unit normals in the same layout. A kernel that computes L samples per lane group stores its
/// lanes here and solves the normals in a loop of their own: over plain arrays the loop
/// vectoriser takes it whole, with packed square roots and divisions. Inside the kernel's lane
/// loop LLVM pairs x and y of one sample for the stores into the grid and leaves every square
/// root and division scalar, four of each per lane group on the one divider.
pub(crate) struct NormalStage {
    /// Ten columns of `len` values: Su x, y, z, Sv x, y, z, normal x, y, z, and 1 where the
    /// normal is regular, else 0.
    buf: Vec<f64>,
    len: usize,
}

impl NormalStage {
    #[must_use]
    pub(crate) fn new(len: usize) -> Self {
        Self {
            buf: vec![0.0; 10 * len],
            len,
        }
    }

    #[must_use]
    fn columns(&mut self) -> [&mut [f64]; 10] {
        let len = self.len;
        let mut rest = self.buf.as_mut_slice();
        std::array::from_fn(|_| {
            let (col, tail) = std::mem::take(&mut rest).split_at_mut(len);
            rest = tail;
            col
        })
    }

    /// The Su, Sv columns as `groups` lane groups of L samples (sample k·L + l is lane l of
    /// group k), for a kernel to store its lanes into. Exactly `groups` long, so that a loop
    /// over as many grid columns indexes them without bounds checks.
    #[inline(always)]
    #[must_use]
    pub(crate) fn inputs<const L: usize>(&mut self, groups: usize) -> [&mut [[f64; L]]; 6] {
        let mut cols = self.columns().into_iter();
        std::array::from_fn(|_| {
            let col = cols.next().expect("six input columns");
            &mut col.as_chunks_mut::<L>().0[..groups]
        })
    }

    /// The normals of every sample (exactly `regular_normal`'s where regular); returns how
    /// many are degenerate.
    #[must_use]
    pub(crate) fn solve(&mut self) -> usize {
        let [ux, uy, uz, vx, vy, vz, nx, ny, nz, ok] = self.columns();
        let mut bad = 0usize;
        let inputs = ux.iter().zip(uy.iter()).zip(uz.iter());
        let inputs = inputs.zip(vx.iter().zip(vy.iter()).zip(vz.iter()));
        let outputs = nx
            .iter_mut()
            .zip(ny.iter_mut())
            .zip(nz.iter_mut().zip(ok.iter_mut()));
        for ((((ux, uy), uz), ((vx, vy), vz)), ((nx, ny), (nz, ok))) in inputs.zip(outputs) {
            let (n, regular) = unit_normals::<1>([[*ux], [*uy], [*uz]], [[*vx], [*vy], [*vz]]);
            (*nx, *ny, *nz, *ok) = (n[0][0], n[1][0], n[2][0], regular[0]);
            bad += (regular[0] == 0.0) as usize;
        }
        bad
    }

    /// The normals' x, y, z columns as `groups` lane groups of L samples, as in
    /// [`Self::inputs`].
    #[inline(always)]
    #[must_use]
    pub(crate) fn normals<const L: usize>(&self, groups: usize) -> [&[[f64; L]]; 3] {
        std::array::from_fn(|c| {
            let col = &self.buf[(6 + c) * self.len..(7 + c) * self.len];
            &col.as_chunks::<L>().0[..groups]
        })
    }

    /// Whether sample k's normal is regular (after [`Self::solve`]).
    #[must_use]
    pub(crate) fn regular(&self, k: usize) -> bool {
        self.buf[9 * self.len + k] != 0.0
    }
}

/// Unit normals of `data`'s samples (S, Su, Sv each) into `normals`, `LANES` at a time so that
/// the square roots and divisions vectorise; reports the index of every degenerate sample.
/// Inlinable into the point edits of other modules, whose row loops it finishes.
#[inline]
pub(crate) fn normals_of(
    data: &[[DVec3; 3]],
    normals: &mut [DVec3],
    mut degenerate: impl FnMut(usize),
) {
    let mut stage = [Lanes([0.0; LANES]); 4];
    let (data4, rest) = data.as_chunks::<LANES>();
    let (normals4, normals_rest) = normals.as_chunks_mut::<LANES>();
    for (g, (d, n)) in data4.iter().zip(normals4).enumerate() {
        let u = [0, 1, 2].map(|c| std::array::from_fn(|l| d[l][1][c]));
        let v = [0, 1, 2].map(|c| std::array::from_fn(|l| d[l][2][c]));
        let (nn, ok) = unit_normals::<LANES>(u, v);
        stage[..3].copy_from_slice(&nn.map(Lanes));
        stage[3] = Lanes(ok);
        // Through memory, so that the stores below do not pull the lanes apart (see `rows`).
        let st = std::hint::black_box(&stage);
        for l in 0..LANES {
            n[l] = DVec3::new(st[0][l], st[1][l], st[2][l]);
            if st[3][l] == 0.0 {
                degenerate(g * LANES + l);
            }
        }
    }
    let base = data4.len() * LANES;
    for (jj, (s, n)) in rest.iter().zip(normals_rest).enumerate() {
        match regular_normal(s[1], s[2]) {
            Some(v) => *n = v,
            None => degenerate(base + jj),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::kernels::testing::{Rng, assert_is_regular_normal, normal_cases};
    use std::array::from_fn;

    /// `fill_q` against the ordered sum it stands for, bit for bit, both ways a sum may start,
    /// with every lane reading its own points and basis values; and where every product is −0,
    /// the sum from +0 is +0 (the generic code's) while the sum from the first product stays −0.
    #[test]
    fn fill_q_is_the_ordered_sum() {
        const W: usize = 3;
        const L: usize = 4;
        let mut rng = Rng(5);
        let m: [[[f64; L]; W]; 2] = from_fn(|_| from_fn(|_| from_fn(|_| rng.range(-1.0, 1.0))));
        // Per control column, lane and k.
        let pts: Vec<[[DVec3; W]; L]> = (0..5)
            .map(|_| from_fn(|_| from_fn(|_| rng.vec(3.0))))
            .collect();
        let basis = |r: usize, k: usize, l: usize| m[r][k][l];
        let point = |l: usize, k: usize, c: usize| pts[c][l][k];
        for from_zero in [false, true] {
            let mut q = vec![[Lanes([f64::NAN; L]); 6]; pts.len()];
            match from_zero {
                true => fill_q::<W, L, true>(&mut q, basis, point),
                false => fill_q::<W, L, false>(&mut q, basis, point),
            }
            for (c, qc) in q.iter().enumerate() {
                for (l, r, x) in (0..L).flat_map(|l| (0..6).map(move |v| (l, v / 3, v % 3))) {
                    let term = |k: usize| pts[c][l][k][x] * m[r][k][l];
                    let mut want = if from_zero { 0.0 + term(0) } else { term(0) };
                    for k in 1..W {
                        want += term(k);
                    }
                    assert_eq!(qc[3 * r + x][l].to_bits(), want.to_bits(), "{from_zero}");
                }
            }
        }
        let minus_zero = |_: usize, _: usize, _: usize| DVec3::splat(-0.0);
        let mut q = [[Lanes([f64::NAN; 1]); 6]];
        fill_q::<W, 1, true>(&mut q, |_, _, _| 1.0, minus_zero);
        assert!(q[0].iter().all(|v| v[0].to_bits() == 0.0f64.to_bits()));
        fill_q::<W, 1, false>(&mut q, |_, _, _| 1.0, minus_zero);
        assert!(q[0].iter().all(|v| v[0].to_bits() == (-0.0f64).to_bits()));
    }

    #[test]
    fn lane_normal_is_regular_normal() {
        for (u, v) in normal_cases() {
            let (n, ok) = unit_normals(u.to_array().map(|c| [c]), v.to_array().map(|c| [c]));
            let ([[x], [y], [z]], [ok]) = (n, ok);
            assert_is_regular_normal(u, v, [x, y, z], ok == 1.0);
        }
    }

    /// The stage's vectorised loop gives `regular_normal`'s normals and flags too, and counts
    /// the degenerate samples.
    #[test]
    fn normal_stage_solves_regular_normals() {
        let cases = normal_cases();
        let groups = cases.len() / LANES;
        let mut stage = NormalStage::new(groups * LANES);
        let inputs = stage.inputs::<LANES>(groups);
        for (k, chunk) in cases.chunks_exact(LANES).enumerate() {
            for (l, (u, v)) in chunk.iter().enumerate() {
                for c in 0..3 {
                    inputs[c][k][l] = u[c];
                    inputs[3 + c][k][l] = v[c];
                }
            }
        }
        let bad = stage.solve();
        let [nx, ny, nz] = stage.normals::<LANES>(groups);
        for (i, (u, v)) in cases.iter().enumerate().take(groups * LANES) {
            let (k, l) = (i / LANES, i % LANES);
            let n = [nx[k][l], ny[k][l], nz[k][l]];
            assert_is_regular_normal(*u, *v, n, stage.regular(i));
        }
        let expected = cases[..groups * LANES]
            .iter()
            .filter(|(u, v)| regular_normal(*u, *v).is_none())
            .count();
        assert!(expected > 10, "the cases include degenerate ones");
        assert_eq!(bad, expected);
    }
}
