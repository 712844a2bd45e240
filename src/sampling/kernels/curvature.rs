//! The curvature-map kernels: a control point edit of a polynomial surface on a `Curvature`
//! grid (six partials per sample), with the normals and [K, H] of the touched samples in the
//! same pass, `LANES` samples at a time.

use super::lanes::{LANES, unit_normals_inv};
use crate::geom::surface::regular_normal;
use crate::sampling::curvature::fundamental_forms;
use crate::sampling::grid::SampleGrid;
use crate::sampling::tables::axis::HermiteTable;
use glam::DVec3;
use std::ops::Range;

/// Moves control point (k, l) of a polynomial surface on a `Curvature` grid by `delta`: the six
/// partials of the samples in I_k × I_l gain M_u[a][k]·M_v[b][l]·Δ (the generic update's
/// products in its order), and their normals and [K, H] are recomputed in the same pass.
/// Samples with a degenerate Su × Sv are appended to `degenerate` (normal and curvature left
/// for the caller's fallback). Returns the touched rectangle.
#[must_use]
pub(crate) fn translate(
    tables: [&HermiteTable; 2],
    point: [usize; 2],
    delta: DVec3,
    grid: &mut SampleGrid,
    degenerate: &mut Vec<(usize, usize)>,
) -> (Range<usize>, Range<usize>) {
    let [tu, tv] = tables;
    let [k, l] = point;
    let (rows, cols) = (tu.range(k), tv.range(l));
    // Basis value and first and second derivatives of column k (resp. l) at each sample.
    let coeffs = |t: &HermiteTable, c: usize, j: usize| {
        let col = c - t.first(j);
        let at = |r: usize| t.row(j, r).map_or(0.0, |row| row[col]);
        [at(0), at(1), at(2)]
    };
    let cv: Vec<[f64; 3]> = cols.clone().map(|j| coeffs(tv, l, j)).collect();
    let mv = grid.dims[1];
    let (Some(normals), Some(curv)) = (grid.normals.as_mut(), grid.curvatures.as_mut()) else {
        return (rows, cols);
    };
    let d = delta.to_array();
    for i in rows.clone() {
        let cu = coeffs(tu, k, i);
        let (a, b) = (i * mv + cols.start, i * mv + cols.end);
        let data = grid.data[a * 6..b * 6].as_chunks_mut::<6>().0;
        for (s, cv) in data.iter_mut().zip(&cv) {
            // Δ·(M_u[a] M_v[b]) per partial, component by component: 18 independent
            // multiply-adds the compiler can pair.
            let c = [
                cu[0] * cv[0],
                cu[1] * cv[0],
                cu[0] * cv[1],
                cu[2] * cv[0],
                cu[1] * cv[1],
                cu[0] * cv[2],
            ];
            for (p, &c) in s.iter_mut().zip(&c) {
                let v: &mut [f64; 3] = p.as_mut();
                for x in 0..3 {
                    v[x] += d[x] * c;
                }
            }
        }
        // The row segment is in L1 now: normals and [K, H] LANES samples at a time.
        shape_of(data, &mut normals[a..b], &mut curv[a..b], |jj| {
            degenerate.push((i, cols.start + jj))
        });
    }
    (rows, cols)
}

/// Unit normals (exactly `regular_normal`'s) and [K, H] of `data`'s samples (S, Su, Sv, Suu,
/// Suv, Svv each), LANES at a time so that the square roots and divisions vectorise; reports
/// the index of every sample whose Su × Sv is degenerate (its outputs are left as they were).
pub(crate) fn shape_of(
    data: &[[DVec3; 6]],
    normals: &mut [DVec3],
    curv: &mut [[f64; 2]],
    mut degenerate: impl FnMut(usize),
) {
    const L: usize = LANES;
    let n = data.len();
    if n < L {
        for (jj, s) in data.iter().enumerate() {
            match regular_normal(s[1], s[2]) {
                Some(v) => {
                    normals[jj] = v;
                    curv[jj] = fundamental_forms(&[s[1], s[2], s[3], s[4], s[5]], v);
                }
                None => degenerate(jj),
            }
        }
        return;
    }
    // A ragged end is one more group over the last L samples instead of a scalar tail: a
    // sample computed twice gets the same bits, and only the new ones are reported.
    let starts = (0..n / L)
        .map(|g| g * L)
        .chain((!n.is_multiple_of(L)).then_some(n - L));
    let mut done = 0;
    for start in starts {
        let d: &[[DVec3; 6]; L] = data[start..start + L].try_into().expect("L samples");
        let stage = shape_lanes(d);
        for l in 0..L {
            let j = start + l;
            if stage[5][l] == 0.0 {
                if j >= done {
                    degenerate(j);
                }
                continue;
            }
            normals[j] = DVec3::new(stage[0][l], stage[1][l], stage[2][l]);
            curv[j] = [stage[3][l], stage[4][l]];
        }
        done = start + L;
    }
}

/// Normal (3 rows), K, H and the regular flag of L samples, lane by lane.
#[inline(always)]
#[must_use]
fn shape_lanes(d: &[[DVec3; 6]; LANES]) -> [[f64; LANES]; 6] {
    const L: usize = LANES;
    // Plain loops, not `array::map`: the map was left as an out-of-line call per partial.
    let part = |p: usize| {
        let mut out = [[0.0; L]; 3];
        for (x, o) in out.iter_mut().enumerate() {
            for (l, o) in o.iter_mut().enumerate() {
                *o = d[l][p][x];
            }
        }
        out
    };
    let (u, v) = (part(1), part(2));
    let (nn, ok, inv) = unit_normals_inv::<L>(u, v);
    let dot = |a: &[[f64; L]; 3], b: &[[f64; L]; 3]| -> [f64; L] {
        std::array::from_fn(|l| a[0][l] * b[0][l] + a[1][l] * b[1][l] + a[2][l] * b[2][l])
    };
    let (e, f, gg) = (dot(&u, &u), dot(&u, &v), dot(&v, &v));
    let (ll, m, n2) = (dot(&part(3), &nn), dot(&part(4), &nn), dot(&part(5), &nn));
    // EG − F² = |Su × Sv|², so the normal's reciprocal length squared saves a division.
    let r: [f64; L] = std::array::from_fn(|l| inv[l] * inv[l]);
    // Through memory, so that the caller's stores do not pull the lanes apart (see
    // lanes::normals_of).
    std::hint::black_box([
        nn[0],
        nn[1],
        nn[2],
        std::array::from_fn(|l| (ll[l] * n2[l] - m[l] * m[l]) * r[l]),
        std::array::from_fn(|l| (e[l] * n2[l] - 2.0 * f[l] * m[l] + gg[l] * ll[l]) * (0.5 * r[l])),
        ok,
    ])
}
