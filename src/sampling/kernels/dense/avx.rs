//! The dense kernel's groups of four sample rows in explicit AVX, for x86-64 builds that have it
//! (`.cargo/config.toml` builds for the host CPU). The portable kernel computes a column's nine
//! values (S, Su, Sv) with one lane per row and leaves the layout to LLVM, and for a patch edit
//! much of its work only moves data: every old value is gathered as a scalar into its lane,
//! each sum is scattered to four grid rows, and the normals go out to the rows in a loop of
//! their own. Here:
//! - the sums are formed in the grid's own order: per row, one vector of its values 0..4
//!   (S, Su x) and one of 4..8 (Su y, z, Sv x, y), from the row group's Q values transposed
//!   once per group, so a column needs no transpose, and the old values are added as two
//!   whole-vector loads per sample; Sv z stays one lane per row;
//! - Su and Sv of the sums return to lanes through one transpose, into a stage;
//! - the stage's normals are solved in a loop of their own (the square roots and divisions
//!   share one divider, and a short loop overlaps them best), and one transpose gives each
//!   row its normal.
//!
//! Every value is the portable kernel's product and sum, in its order, so the two paths agree
//! bit for bit (`dense`'s tests compare them). That is also why no product and sum is fused
//! into a multiply-add: it would round once where the portable path rounds twice.

use crate::sampling::kernels::lanes::{LANES, QCol};
use crate::sampling::tables::erbs_patch::DenseRow;
use glam::DVec3;
use safe_arch::{
    blend_varying_m256d, cmp_op, cmp_op_mask_m256d, load_f64_splat_m256d, m256d, move_mask_m256d,
    permute2z_m256d, set_splat_m256d, sqrt_m256d, unpack_hi_m256d, unpack_lo_m256d, zeroed_m256d,
};

// A group is one AVX register of f64 lanes.
const _: () = assert!(LANES == 4);

/// All rows `cu` in groups of four, as the portable kernel's row pass does; the last group
/// padded with copies of its last row, their results written to scratch rows and dropped (one
/// padded group costs less than one to three rows one by one). `q_of` gives a group's Q0, Q1
/// at the net columns (the portable kernel's, so the sums below continue its sums); `origin`
/// is the grid index of the pass's first row and column.
pub(super) fn groups<'g, const WU: usize, const WV: usize, const ADD: bool, const N: bool>(
    q_of: impl Fn(&[DenseRow<WU>; LANES]) -> [QCol<LANES>; WV],
    origin: (usize, usize),
    cu: &[DenseRow<WU>],
    cv: &[DenseRow<WV>],
    data: &mut impl Iterator<Item = &'g mut [DVec3]>,
    normals: &mut impl Iterator<Item = &'g mut [DVec3]>,
    degenerate: &mut Vec<(usize, usize)>,
) {
    let nc = cv.len();
    let mut group = Group {
        q_of,
        origin,
        cv,
        mixed: cv
            .iter()
            .map(|[a, b]| std::array::from_fn(|k| m256d::from_array([a[k], a[k], b[k], b[k]])))
            .collect(),
        stage: vec![[zeroed_m256d(); 6]; if N { nc } else { 0 }],
    };
    let mut data_row = || {
        let row = data.next().expect("one grid row per sample row");
        &mut row.as_chunks_mut::<3>().0[..nc]
    };
    let mut normal_row = || match N {
        true => &mut normals.next().expect("one normal row per sample row")[..nc],
        false => &mut [],
    };
    let mut whole = cu.chunks_exact(LANES);
    for (g, rows) in (&mut whole).enumerate() {
        let rows = rows.try_into().expect("LANES rows");
        let d = std::array::from_fn(|_| data_row());
        let n = std::array::from_fn(|_| normal_row());
        group.run::<WU, ADD, N>(rows, d, n, g * LANES, LANES, degenerate);
    }
    let rest = whole.remainder();
    let Some(last) = rest.last() else {
        return;
    };
    let rows = std::array::from_fn(|l| *rest.get(l).unwrap_or(last));
    let pad = LANES - rest.len();
    let mut scratch = vec![[DVec3::ZERO; 3]; pad * nc];
    let mut scratch_normals = vec![DVec3::ZERO; if N { pad * nc } else { 0 }];
    let mut scratch = scratch.chunks_exact_mut(nc.max(1));
    let mut scratch_normals = scratch_normals.chunks_exact_mut(nc.max(1));
    let d = std::array::from_fn(|l| match l < rest.len() {
        true => data_row(),
        false => scratch.next().expect("a scratch row per padding lane"),
    });
    let n = std::array::from_fn(|l| match (l < rest.len(), N) {
        (true, _) => normal_row(),
        (false, true) => scratch_normals
            .next()
            .expect("a scratch row per padding lane"),
        (false, false) => &mut [],
    });
    let first = cu.len() - rest.len();
    group.run::<WU, ADD, N>(&rows, d, n, first, rest.len(), degenerate);
}

/// What the row groups of one pass share.
struct Group<'a, Q, const WV: usize> {
    q_of: Q,
    origin: (usize, usize),
    cv: &'a [DenseRow<WV>],
    /// Per column and net column k: M_v[0][k], M_v[0][k], M_v[1][k], M_v[1][k].
    mixed: Vec<[m256d; WV]>,
    /// Per column: Su x, y, z and Sv x, y, z of the group's four rows.
    stage: Vec<[m256d; 6]>,
}

impl<Q, const WV: usize> Group<'_, Q, WV> {
    /// Four rows, the first being the pass's rectangle row `first`, into the grid row segments
    /// `d` and normal row segments `n`; only the first `valid` lanes report degenerate normals.
    fn run<const WU: usize, const ADD: bool, const N: bool>(
        &mut self,
        rows: &[DenseRow<WU>; LANES],
        d: [&mut [[DVec3; 3]]; LANES],
        n: [&mut [DVec3]; LANES],
        first: usize,
        valid: usize,
        degenerate: &mut Vec<(usize, usize)>,
    ) where
        Q: Fn(&[DenseRow<WU>; LANES]) -> [QCol<LANES>; WV],
    {
        let zero = zeroed_m256d();
        // Resliced to exactly the column count, so that indexing by the column needs no bounds
        // checks.
        let nc = self.cv.len();
        let d = d.map(|row| &mut row[..nc]);
        let q = (self.q_of)(rows).map(|col| col.map(|lanes| m256d::from_array(lanes.0)));
        // Per net column k, each row's Q0 x, y, z, Q1 x (for its grid values 0..4: S, Su x)
        // and Q1 y, z, Q0 x, y (values 4..8: Su y, z, Sv x, y), so that the sums come out in
        // the grid's order and need no transpose; Q0 z (for Sv z) stays one lane per row.
        let q_head: [[m256d; LANES]; WV] =
            std::array::from_fn(|k| transpose([q[k][0], q[k][1], q[k][2], q[k][3]]));
        let q_tail: [[m256d; LANES]; WV] =
            std::array::from_fn(|k| transpose([q[k][4], q[k][5], q[k][0], q[k][1]]));
        for (jj, (c, ab)) in self.cv.iter().zip(&self.mixed).enumerate() {
            // The coefficients broadcast straight from the table, a load each; values 4..8
            // take M_v[0] twice, then M_v[1] twice.
            let a: [m256d; WV] = std::array::from_fn(|k| load_f64_splat_m256d(&c[0][k]));
            let b: [m256d; WV] = std::array::from_fn(|k| load_f64_splat_m256d(&c[1][k]));
            // `lanes::partials`' products and sums, in its order, for each value.
            let mut head: [m256d; LANES] = std::array::from_fn(|l| q_head[0][l] * a[0]);
            let mut tail: [m256d; LANES] = std::array::from_fn(|l| q_tail[0][l] * ab[0]);
            let mut svz = q[0][2] * b[0];
            for k in 1..WV {
                for l in 0..LANES {
                    head[l] += q_head[k][l] * a[k];
                    tail[l] += q_tail[k][l] * ab[k];
                }
                svz += q[k][2] * b[k];
            }
            if ADD {
                svz = m256d::from_array(std::array::from_fn(|l| d[l][jj][2].z)) + svz;
                for l in 0..LANES {
                    let (h, t) = load_sample(&d[l][jj]);
                    (head[l], tail[l]) = (h + head[l], t + tail[l]);
                }
            }
            let last = svz.to_array();
            for l in 0..LANES {
                store_sample(&mut d[l][jj], head[l], tail[l], last[l]);
            }
            if N {
                // Su x is lane 3 of each row's head; the rest of Su, Sv is the tail's transpose.
                let su_x = permute2z_m256d::<0x31>(
                    unpack_hi_m256d(head[0], head[1]),
                    unpack_hi_m256d(head[2], head[3]),
                );
                let [su_y, su_z, sv_x, sv_y] = transpose(tail);
                self.stage[jj] = [su_x, su_y, su_z, sv_x, sv_y, svz];
            }
        }
        if !N {
            return;
        }
        let (r0, c0) = self.origin;
        let i = r0 + first;
        let valid = (1 << valid) - 1;
        let n = n.map(|row| &mut row[..nc]);
        for (jj, [ux, uy, uz, vx, vy, vz]) in self.stage[..nc].iter().enumerate() {
            let (normal, regular) = unit_normals([*ux, *uy, *uz], [*vx, *vy, *vz]);
            let rows = transpose([normal[0], normal[1], normal[2], zero]);
            for l in 0..LANES {
                let [x, y, z, _] = rows[l].to_array();
                n[l][jj] = DVec3::new(x, y, z);
            }
            let bad = !move_mask_m256d(regular) & valid;
            if bad != 0 {
                let lanes = (0..LANES).filter(|&l| bad & (1 << l) != 0);
                degenerate.extend(lanes.map(|l| (i + l, c0 + jj)));
            }
        }
    }
}

/// Row l of the result is lane l of every input.
#[inline(always)]
#[must_use]
fn transpose(r: [m256d; 4]) -> [m256d; 4] {
    let (lo01, hi01) = (unpack_lo_m256d(r[0], r[1]), unpack_hi_m256d(r[0], r[1]));
    let (lo23, hi23) = (unpack_lo_m256d(r[2], r[3]), unpack_hi_m256d(r[2], r[3]));
    [
        permute2z_m256d::<0x20>(lo01, lo23),
        permute2z_m256d::<0x20>(hi01, hi23),
        permute2z_m256d::<0x31>(lo01, lo23),
        permute2z_m256d::<0x31>(hi01, hi23),
    ]
}

/// A sample's grid values 0..4 and 4..8 (LLVM makes each one load).
#[inline(always)]
#[must_use]
fn load_sample(d: &[DVec3; 3]) -> (m256d, m256d) {
    (
        m256d::from_array([d[0].x, d[0].y, d[0].z, d[1].x]),
        m256d::from_array([d[1].y, d[1].z, d[2].x, d[2].y]),
    )
}

/// Stores a sample's nine grid values: 0..4, 4..8 and the last.
#[inline(always)]
fn store_sample(d: &mut [DVec3; 3], head: m256d, tail: m256d, last: f64) {
    let [a0, a1, a2, a3] = head.to_array();
    let [b0, b1, b2, b3] = tail.to_array();
    *d = [
        DVec3::new(a0, a1, a2),
        DVec3::new(a3, b0, b1),
        DVec3::new(b2, b3, last),
    ];
}

/// `lanes::unit_normals` in AVX (the same operations in the same order): the normals, and
/// per lane an all-ones mask where the normal is regular.
#[inline(always)]
#[must_use]
fn unit_normals(u: [m256d; 3], v: [m256d; 3]) -> ([m256d; 3], m256d) {
    let cx = u[1] * v[2] - v[1] * u[2];
    let cy = u[2] * v[0] - v[2] * u[0];
    let cz = u[0] * v[1] - v[0] * u[1];
    let lu = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
    let lv = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    let scale = blend_varying_m256d(
        lv,
        lu,
        cmp_op_mask_m256d::<{ cmp_op!(GreaterThanOrdered) }>(lu, lv),
    );
    let len2 = cx * cx + cy * cy + cz * cz;
    let tiny = set_splat_m256d(1e-20) * scale * scale;
    // Ordered comparisons are false for NaN, as Rust's are.
    let regular = cmp_op_mask_m256d::<{ cmp_op!(GreaterThanOrdered) }>(scale, zeroed_m256d())
        & cmp_op_mask_m256d::<{ cmp_op!(GreaterThanOrdered) }>(len2, tiny)
        & cmp_op_mask_m256d::<{ cmp_op!(LessThanOrdered) }>(len2, set_splat_m256d(f64::INFINITY));
    let inv = set_splat_m256d(1.0) / sqrt_m256d(len2);
    ([cx * inv, cy * inv, cz * inv], regular)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::kernels::testing::{assert_is_regular_normal, normal_cases};

    /// The AVX normals against `regular_normal`, bit for bit, over the kernels' test cases
    /// (zero, tiny, huge, NaN, infinite, near-parallel); a wrong lane order must fail.
    #[test]
    fn avx_normals_are_regular_normals() {
        let cases = normal_cases();
        for chunk in cases.chunks_exact(4) {
            let lanes = |f: &dyn Fn(&(DVec3, DVec3)) -> f64| {
                m256d::from_array(std::array::from_fn(|l| f(&chunk[l])))
            };
            let u = [lanes(&|c| c.0.x), lanes(&|c| c.0.y), lanes(&|c| c.0.z)];
            let v = [lanes(&|c| c.1.x), lanes(&|c| c.1.y), lanes(&|c| c.1.z)];
            let (n, regular) = unit_normals(u, v);
            let regular = move_mask_m256d(regular);
            let n = n.map(|c| c.to_array());
            for (l, (su, sv)) in chunk.iter().enumerate() {
                let got = [n[0][l], n[1][l], n[2][l]];
                assert_is_regular_normal(*su, *sv, got, regular & (1 << l) != 0);
            }
        }
        // The transpose moves lanes into rows (the identity would not).
        let r: [m256d; 4] =
            std::array::from_fn(|i| m256d::from_array(std::array::from_fn(|j| (4 * i + j) as f64)));
        let t = transpose(r).map(|v| v.to_array());
        assert_eq!(t[1], [1.0, 5.0, 9.0, 13.0]);
        assert_ne!(t[1], r[1].to_array());
    }
}
