//! The ERBS surface kernel: S, Su, Sv and unit normals of a rectangle of samples from a *dense*
//! basis, one whose every function is active at every sample of the rectangle. That is a Bézier
//! local patch blended with its ERBS weight (width d+1 padded to 4), and also the 2×2 local
//! patches active over one knot cell side by side (width 8 each way): over a cell the ERBS
//! surface is a tensor product on an 8 × 8 net, so a sample costs one pass instead of four.
//!
//! The lane layout is the toolkit's ([`super::lanes`]): L sample rows share each column's
//! v-coefficients, held lane-minor so that the autovectoriser emits SIMD across the rows. The normals of a row group
//! are solved after its columns, through a [`NormalStage`]. Where the build has AVX, groups of
//! four rows take the same steps in explicit AVX instead ([`avx`]).

#[cfg(all(target_arch = "x86_64", target_feature = "avx"))]
mod avx;

use super::lanes::{LANES, Lanes, NormalStage, QCol, fill_q, partials, unit_normals};
use crate::sampling::tables::erbs_patch::DenseRow;
use glam::DVec3;

/// Where a pass writes: `rows` consecutive grid rows from `row0`, columns from `col0`, of a
/// row-major grid of S, Su, Sv per sample with `width` samples per row, and the unit normals
/// when `normals` is given.
pub(crate) struct Target<'a> {
    pub data: &'a mut [DVec3],
    pub normals: Option<&'a mut [DVec3]>,
    pub width: usize,
    pub row0: usize,
    pub col0: usize,
}

/// S, Su, Sv of Σ_a Σ_b U_a(u_i) V_b(v_j) P_ab for `cu.len()` rows × `cv.len()` columns, stored
/// into `out` or, if ADD, added to what is there; unit normals of the result when `out` keeps
/// normals. Samples whose Su × Sv degenerates are appended to `degenerate` (grid indices) with
/// an unspecified normal, for the caller's model fallback.
pub(crate) fn pass<const WU: usize, const WV: usize, const ADD: bool>(
    cu: &[DenseRow<WU>],
    cv: &[DenseRow<WV>],
    net: &[[DVec3; WV]; WU],
    out: Target<'_>,
    degenerate: &mut Vec<(usize, usize)>,
) {
    run::<WU, WV, ADD>(cu, cv, net, out, degenerate, false);
}

/// [`pass`], on the portable kernel alone if `portable` (the tests compare the two paths).
fn run<const WU: usize, const WV: usize, const ADD: bool>(
    cu: &[DenseRow<WU>],
    cv: &[DenseRow<WV>],
    net: &[[DVec3; WV]; WU],
    out: Target<'_>,
    degenerate: &mut Vec<(usize, usize)>,
    portable: bool,
) {
    let (nr, nc) = (cu.len(), cv.len());
    if nr == 0 || nc == 0 {
        return;
    }
    let pass = Pass {
        net,
        origin: (out.row0, out.col0),
        portable,
    };
    pass.run::<ADD>(cu, cv, out, degenerate);
}

struct Pass<'a, const WU: usize, const WV: usize> {
    net: &'a [[DVec3; WV]; WU],
    origin: (usize, usize),
    /// Whether groups of rows keep to the portable kernel where the build has AVX.
    #[cfg_attr(
        not(all(target_arch = "x86_64", target_feature = "avx")),
        allow(dead_code)
    )]
    portable: bool,
}

impl<const WU: usize, const WV: usize> Pass<'_, WU, WV> {
    /// The row pass over `cu.len()` rows × `cv.len()` columns into `out`.
    fn run<const ADD: bool>(
        &self,
        cu: &[DenseRow<WU>],
        cv: &[DenseRow<WV>],
        out: Target<'_>,
        degenerate: &mut Vec<(usize, usize)>,
    ) {
        let nr = cu.len();
        let nc = cv.len();
        let w = out.width;
        let (r0, c0) = (out.row0, out.col0);
        let mut data = out.data[r0 * w * 3..(r0 + nr) * w * 3]
            .chunks_exact_mut(w * 3)
            .map(|r| &mut r[c0 * 3..(c0 + nc) * 3]);
        match out.normals {
            Some(normals) => {
                let mut normals = normals[r0 * w..(r0 + nr) * w]
                    .chunks_exact_mut(w)
                    .map(|r| &mut r[c0..c0 + nc]);
                self.groups::<ADD, true>(cu, cv, &mut data, &mut normals, degenerate);
            }
            None => {
                let none = &mut std::iter::empty();
                self.groups::<ADD, false>(cu, cv, &mut data, none, degenerate);
            }
        }
    }

    /// The rows in groups of `LANES`: in explicit AVX where the build has it (the last group
    /// padded), else through the portable kernel (the rows past the last whole group one by
    /// one).
    fn groups<'g, const ADD: bool, const N: bool>(
        &self,
        cu: &[DenseRow<WU>],
        cv: &[DenseRow<WV>],
        data: &mut impl Iterator<Item = &'g mut [DVec3]>,
        normals: &mut impl Iterator<Item = &'g mut [DVec3]>,
        degenerate: &mut Vec<(usize, usize)>,
    ) {
        #[cfg(all(target_arch = "x86_64", target_feature = "avx"))]
        if !self.portable {
            let q_of = |rows: &[DenseRow<WU>; LANES]| self.q_of::<LANES>(rows);
            avx::groups::<WU, WV, ADD, N>(q_of, self.origin, cu, cv, data, normals, degenerate);
            return;
        }
        let split = cu.len() / LANES * LANES;
        self.rows::<LANES, ADD, N>(0, &cu[..split], cv, data, normals, degenerate);
        self.rows::<1, ADD, N>(split, &cu[split..], cv, data, normals, degenerate);
    }

    /// Rows `cu` (a multiple of L of them, the first being rectangle row `first`) in groups of
    /// L; `data` and `normals` yield the rows' grid segments in the same order.
    fn rows<'g, const L: usize, const ADD: bool, const N: bool>(
        &self,
        first: usize,
        cu: &[DenseRow<WU>],
        cv: &[DenseRow<WV>],
        data: &mut impl Iterator<Item = &'g mut [DVec3]>,
        normals: &mut impl Iterator<Item = &'g mut [DVec3]>,
        degenerate: &mut Vec<(usize, usize)>,
    ) {
        if cu.is_empty() {
            return;
        }
        // The v-coefficients repeated across the lanes once per rectangle, so the hot loop
        // loads them as whole vectors.
        let coeffs: Vec<[[Lanes<L>; WV]; 2]> = cv
            .iter()
            .map(|c| c.map(|row| row.map(|x| Lanes([x; L]))))
            .collect();
        let (r0, c0) = self.origin;
        let nc = coeffs.len();
        // Over a 4-wide net (a patch edit) the column loop is short and the normals' square
        // roots and divisions bound it, so they are solved afterwards through a stage, packed.
        // Over an 8-wide net (a knot cell of the full pass) the column loop's products are
        // twice as many and hide the scalar ones LLVM makes in the loop, while the stage's
        // loop of its own would not overlap them.
        let staged = N && WV <= 4;
        let mut stage = NormalStage::new(if staged { nc * L } else { 0 });
        for (g, rows) in cu.chunks_exact(L).enumerate() {
            let q = self.q_of::<L>(rows);
            // The rows and stage columns resliced to exactly `nc`, so that indexing them by
            // the column needs no bounds check.
            let d: [&mut [[DVec3; 3]]; L] = std::array::from_fn(|_| {
                let row = data.next().expect("one grid row per sample row");
                &mut row.as_chunks_mut::<3>().0[..nc]
            });
            let mut st = stage.inputs::<L>(if staged { nc } else { 0 });
            // Staged normals go out to their rows after the columns.
            let n: [&mut [DVec3]; L] = std::array::from_fn(|_| {
                if N && !staged {
                    &mut normals.next().expect("one normal row per sample row")[..nc]
                } else {
                    &mut []
                }
            });
            let i = r0 + first + g * L;
            for (jj, cv) in coeffs.iter().enumerate() {
                let mut s = partials::<WV, L>(&q, cv);
                if ADD {
                    // The old values gathered into lanes first, then one vector sum per
                    // component: added lane by lane in place, LLVM extracted every lane,
                    // added it scalar and spilled it (two stores per value).
                    let old: [Lanes<L>; 9] = std::array::from_fn(|k| {
                        Lanes(std::array::from_fn(|l| d[l][jj][k / 3][k % 3]))
                    });
                    for (s, o) in s.iter_mut().zip(old) {
                        *s = *s + o;
                    }
                }
                for l in 0..L {
                    d[l][jj] = [
                        DVec3::new(s[0][l], s[1][l], s[2][l]),
                        DVec3::new(s[3][l], s[4][l], s[5][l]),
                        DVec3::new(s[6][l], s[7][l], s[8][l]),
                    ];
                }
                if staged {
                    for (col, lanes) in st.iter_mut().zip(&s[3..]) {
                        col[jj] = lanes.0;
                    }
                } else if N {
                    let (nn, ok) =
                        unit_normals::<L>([s[3].0, s[4].0, s[5].0], [s[6].0, s[7].0, s[8].0]);
                    for l in 0..L {
                        n[l][jj] = DVec3::new(nn[0][l], nn[1][l], nn[2][l]);
                    }
                    // The flags are 1 or 0: one product tells whether any lane is degenerate.
                    if ok.iter().product::<f64>() == 0.0 {
                        let lanes = (0..L).filter(|&l| ok[l] == 0.0);
                        degenerate.extend(lanes.map(|l| (i + l, c0 + jj)));
                    }
                }
            }
            if !staged {
                continue;
            }
            // The group's normals in one vectorised loop, then out to the grid rows.
            let bad = stage.solve();
            let n: [&mut [DVec3]; L] = std::array::from_fn(|_| {
                let row = normals.next().expect("one normal row per sample row");
                &mut row[..nc]
            });
            let [nx, ny, nz] = stage.normals::<L>(nc);
            for (jj, ((x, y), z)) in nx.iter().zip(ny).zip(nz).enumerate() {
                for l in 0..L {
                    n[l][jj] = DVec3::new(x[l], y[l], z[l]);
                }
            }
            if bad > 0 {
                for jj in 0..nc {
                    let lanes = (0..L).filter(|&l| !stage.regular(jj * L + l));
                    degenerate.extend(lanes.map(|l| (i + l, c0 + jj)));
                }
            }
        }
    }

    /// Q0 = Σ_a U_a P_ab and Q1 = Σ_a U'_a P_ab at every net column b, for L sample rows
    /// (each sum from +0).
    #[inline(always)]
    #[must_use]
    fn q_of<const L: usize>(&self, rows: &[DenseRow<WU>]) -> [QCol<L>; WV] {
        let mut q = [[Lanes([0.0; L]); 6]; WV];
        fill_q::<WU, L, true>(&mut q, |r, a, l| rows[l][r][a], |_, a, b| self.net[a][b]);
        q
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The kernel against the definition, sample by sample, for a random dense basis and net,
    /// storing and adding, with and without normals; and a perturbed net must be told apart.
    /// On the portable path a 3-wide net takes the staged normals, an 8-wide one the normals in
    /// the column loop; the AVX path, where the build has it, must give the same bits.
    #[test]
    fn dense_pass_is_the_tensor_product() {
        // Row counts with no, one and three rows past the last whole group of four, and one
        // with no whole group at all.
        for nr in [8, 7, 9, 3] {
            tensor_product::<4, 3>(nr);
            tensor_product::<4, 8>(nr);
        }
    }

    /// Exact comparison (NaN-aware: equal bits).
    #[must_use]
    fn bits(v: &[DVec3]) -> Vec<[u64; 3]> {
        v.iter().map(|p| p.to_array().map(f64::to_bits)).collect()
    }

    fn tensor_product<const WU: usize, const WV: usize>(nr: usize) {
        let mut state = 7u64;
        let mut rnd = move || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1);
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let (nc, width) = (5, 9);
        let cu: Vec<DenseRow<WU>> = (0..nr)
            .map(|_| std::array::from_fn(|_| std::array::from_fn(|_| rnd())))
            .collect();
        let cv: Vec<DenseRow<WV>> = (0..nc)
            .map(|_| std::array::from_fn(|_| std::array::from_fn(|_| rnd())))
            .collect();
        let net: [[DVec3; WV]; WU] =
            std::array::from_fn(|_| std::array::from_fn(|_| DVec3::new(rnd(), rnd(), rnd())));
        let expect = |i: usize, j: usize, ru: usize, rv: usize| {
            let mut s = DVec3::ZERO;
            for (a, row) in net.iter().enumerate() {
                for (b, p) in row.iter().enumerate() {
                    s += *p * (cu[i][ru][a] * cv[j][rv][b]);
                }
            }
            s
        };
        let (row0, col0) = (2, 3);
        let base = DVec3::new(1.0, -2.0, 0.5);
        let check = |data: &[DVec3], add: bool, net_ok: bool| -> f64 {
            let mut worst = 0.0f64;
            for i in 0..nr {
                for j in 0..nc {
                    let k = ((row0 + i) * width + col0 + j) * 3;
                    for (p, (ru, rv)) in [(0, 0), (1, 0), (0, 1)].into_iter().enumerate() {
                        let want = expect(i, j, ru, rv) + if add { base } else { DVec3::ZERO };
                        let e = (data[k + p] - want).abs().max_element();
                        worst = if e.is_nan() {
                            f64::INFINITY
                        } else {
                            worst.max(e)
                        };
                    }
                }
            }
            assert!(net_ok || worst > 1e-3, "a perturbed net must fail");
            worst
        };
        // A 12-row grid filled with `base`, the pass run on it with normals: (S, Su, Sv per
        // sample, normals, degenerate indices). The portable path must give the same bits.
        let run = |net: &[[DVec3; WV]; WU], base: DVec3, add: bool| {
            let runs: [_; 2] = std::array::from_fn(|portable| {
                let mut data = vec![base; 12 * width * 3];
                let mut normals = vec![DVec3::ZERO; 12 * width];
                let mut degenerate = Vec::new();
                let target = Target {
                    data: &mut data,
                    normals: Some(&mut normals),
                    width,
                    row0,
                    col0,
                };
                let (dg, portable) = (&mut degenerate, portable == 1);
                match add {
                    true => run::<WU, WV, true>(&cu, &cv, net, target, dg, portable),
                    false => run::<WU, WV, false>(&cu, &cv, net, target, dg, portable),
                }
                (data, normals, degenerate)
            });
            let [mut fast, mut portable] = runs;
            assert_eq!(
                bits(&fast.0),
                bits(&portable.0),
                "S, Su, Sv of the two paths"
            );
            assert_eq!(bits(&fast.1), bits(&portable.1), "normals of the two paths");
            // The order of the degenerate samples is unspecified.
            fast.2.sort_unstable();
            portable.2.sort_unstable();
            assert_eq!(fast.2, portable.2, "degenerate samples of the two paths");
            fast
        };
        for add in [false, true] {
            let (data, normals, degenerate) = run(&net, base, add);
            assert!(check(&data, add, true) < 1e-15);
            for i in 0..nr {
                for j in 0..nc {
                    let g = (row0 + i) * width + col0 + j;
                    let n = crate::geom::surface::regular_normal(data[g * 3 + 1], data[g * 3 + 2]);
                    match n {
                        Some(n) => assert_eq!(normals[g], n),
                        None => assert!(degenerate.contains(&(row0 + i, col0 + j))),
                    }
                }
            }
            // Outside the rectangle nothing moved.
            assert_eq!(data[0], base);
            assert_eq!(normals[0], DVec3::ZERO);
            let mut bad = net;
            bad[1][2].y += 0.5;
            let mut other = vec![base; 12 * width * 3];
            let t = Target {
                data: &mut other,
                normals: None,
                width,
                row0,
                col0,
            };
            pass::<WU, WV, false>(&cu, &cv, &bad, t, &mut Vec::new());
            check(&other, false, false);
        }
        // A zero net: Su = Sv = 0 at every sample, so each must be reported degenerate, once,
        // at its grid index (the lane groups and the ragged last row alike).
        let (_, _, mut degenerate) = run(&[[DVec3::ZERO; WV]; WU], DVec3::ZERO, true);
        degenerate.sort_unstable();
        let all: Vec<_> = (row0..row0 + nr)
            .flat_map(|i| (col0..col0 + nc).map(move |j| (i, j)))
            .collect();
        assert_eq!(degenerate, all);
    }
}
