//! A polynomial ERBS local patch, pre-evaluated as a control net and, per direction, its basis at
//! the parent's samples in its support already multiplied by its ERBS weight (Leibniz): the
//! blended Hermite tables. Its share of the surface is then a tensor product of two tables and
//! a net, like a B-spline surface's, and a change of the patch is a change of the net: nothing
//! per sample is stored beyond the level's own grid.

use super::axis::{HermiteTable, dot};
use super::erbs_axis::ErbsAxis;
use crate::geom::TensorSurface;
use crate::sampling::grid::PartialSet;
use glam::DVec3;
use std::ops::Range;

/// Rows 0 and 1 of a dense basis of width W at one sample: the W functions' values and first
/// derivatives (the dense kernel's input, one per sample row or column).
pub(crate) type DenseRow<const W: usize> = [[f64; W]; 2];

/// Widest dense patch: a single Bézier piece of degree ≤ 3 each way.
pub(crate) const DENSE: usize = 4;

#[derive(Debug, Clone)]
pub(crate) struct SplinePatch {
    /// The local's basis N_a in u and N_b in v at its samples (its own order), orders 0..=g.
    pub tables: Box<[HermiteTable; 2]>,
    /// The net, row-major [u][v].
    pub points: Vec<DVec3>,
    pub count: [usize; 2],
    /// Rows 0 and 1 of the blended bases W_k·N_a and W_l·N_b (Leibniz) padded to width 4, and
    /// the net padded to 4 × 4, when the patch is one Bézier piece of degree ≤ 3 each way on a
    /// `Shading` level: the dense kernels' input.
    pub dense: Option<Box<DensePatch>>,
}

#[derive(Debug, Clone)]
pub(crate) struct DensePatch {
    pub rows: [Vec<DenseRow<DENSE>>; 2],
    pub net: [[DVec3; DENSE]; DENSE],
}

impl SplinePatch {
    /// Pre-evaluates local patch (k, l) of a level with these axes.
    #[must_use]
    pub fn new(
        surface: &TensorSurface,
        axes: &[ErbsAxis; 2],
        kl: [usize; 2],
        set: &PartialSet,
    ) -> Self {
        let g = set.max_order();
        let degree = surface.degree();
        let count = surface.count();
        let tables: Box<[HermiteTable; 2]> = Box::new(std::array::from_fn(|dir| {
            HermiteTable::at_params(
                &surface.knots()[dir],
                degree[dir],
                count[dir],
                axes[dir].local_params(kl[dir]),
                g,
            )
        }));
        let single = (0..2).all(|d| count[d] == degree[d] + 1 && degree[d] < DENSE);
        let dense = (*set == PartialSet::Shading && single).then(|| {
            let rows = std::array::from_fn(|dir| {
                let (axis, local) = (&axes[dir], kl[dir]);
                let at = axis.local_rows(local);
                dense_rows(&tables[dir].blended(|j| axis.weights(at[j], local)))
            });
            Box::new(DensePatch {
                rows,
                net: [[DVec3::ZERO; DENSE]; DENSE],
            })
        });
        let mut p = Self {
            tables,
            points: Vec::new(),
            count,
            dense,
        };
        p.set_points(surface.points());
        p
    }

    /// Whether `surface` has this patch's basis (only its points may differ).
    #[must_use]
    pub fn holds(&self, surface: &TensorSurface) -> bool {
        let [du, dv] = surface.degree();
        let [ku, kv] = surface.knots();
        let [nu, nv] = surface.count();
        !surface.is_rational()
            && self.tables[0].tabulates(ku, du, nu)
            && self.tables[1].tabulates(kv, dv, nv)
    }

    pub fn set_points(&mut self, points: &[DVec3]) {
        self.points.clear();
        self.points.extend_from_slice(points);
        if let Some(d) = &mut self.dense {
            d.net = padded(points, self.count);
        }
    }

    pub fn map_points(&mut self, f: impl Fn(DVec3) -> DVec3) {
        let moved: Vec<DVec3> = self.points.iter().map(|&p| f(p)).collect();
        self.set_points(&moved);
    }

    /// The local samples a change of the net confined to points `a × b` touches.
    #[must_use]
    pub fn touched(&self, a: Range<usize>, b: Range<usize>) -> [Range<usize>; 2] {
        let [tu, tv] = &*self.tables;
        [
            tu.range(a.start).start..tu.range(a.end - 1).end,
            tv.range(b.start).start..tv.range(b.end - 1).end,
        ]
    }
}

/// A net of at most 4 × 4 points padded with zeros (their basis rows are padded with zeros too).
#[must_use]
pub(crate) fn padded(points: &[DVec3], [nu, nv]: [usize; 2]) -> [[DVec3; DENSE]; DENSE] {
    std::array::from_fn(|a| {
        std::array::from_fn(|b| {
            if a < nu && b < nv {
                points[a * nv + b]
            } else {
                DVec3::ZERO
            }
        })
    })
}

/// Rows 0 and 1 of a single-span table, padded to width 4.
#[must_use]
fn dense_rows(t: &HermiteTable) -> Vec<DenseRow<DENSE>> {
    (0..t.len())
        .map(|j| {
            debug_assert_eq!(t.first(j), 0, "one span");
            std::array::from_fn(|r| {
                let row = t.row(j, r).expect("blended tables keep orders 0 and 1");
                std::array::from_fn(|a| row.get(a).copied().unwrap_or(0.0))
            })
        })
        .collect()
}

/// Where a change is written: level samples from `origin` on, `width` per row, `stride` values
/// each.
pub(crate) struct Out<'a> {
    pub data: &'a mut [DVec3],
    pub origin: (usize, usize),
    pub width: usize,
    pub stride: usize,
}

/// For output partial (a, b) of a level: the Leibniz terms C(a,a')C(b,b') Wu^(a−a') Wv^(b−b')
/// s^(a'b') as (C(a,a')C(b,b'), a − a', b − b', slot of (a', b')).
pub(crate) type BlendTerm = (f64, usize, usize, usize);

/// Adds the share of patch (k, l) with net `net` to every partial of the level samples in
/// `rect` it covers (any degree, any partials): the patch's partials in two passes per row
/// (Q_a = M_u[a]·net, then M_v[b]·Q_a), blended with the weights by the Leibniz `terms`. The
/// products and sums are the dense kernels' in another order; for derivatives above the first
/// this one rounds less (the local partials are formed before the weights scale them).
#[allow(clippy::too_many_arguments)]
pub(crate) fn add_share(
    p: &SplinePatch,
    axes: &[ErbsAxis; 2],
    [k, l]: [usize; 2],
    net: &[DVec3],
    rect: &[Range<usize>; 2],
    partials: &[(usize, usize)],
    terms: &[Vec<BlendTerm>],
    out: &mut Out<'_>,
) {
    let [tu, tv] = &*p.tables;
    let nv = p.count[1];
    let max_a = partials.iter().map(|p| p.0).max().unwrap_or(0);
    let mut q = vec![DVec3::ZERO; (max_a + 1) * nv];
    let mut local = vec![DVec3::ZERO; partials.len()];
    let (oi, oj) = out.origin;
    for pu in axes[0].pieces(k) {
        for i in clip(&pu.samples, &rect[0]) {
            let li = i - pu.samples.start + pu.offset;
            let first = tu.first(li);
            let wu = axes[0].weights(i, k);
            for (a, qa) in q.chunks_exact_mut(nv).enumerate() {
                qa.fill(DVec3::ZERO);
                let Some(row) = tu.row(li, a) else {
                    continue;
                };
                for (t, &c) in row.iter().enumerate() {
                    for (o, &x) in qa.iter_mut().zip(&net[(first + t) * nv..][..nv]) {
                        *o += x * c;
                    }
                }
            }
            for pv in axes[1].pieces(l) {
                for j in clip(&pv.samples, &rect[1]) {
                    let lj = j - pv.samples.start + pv.offset;
                    let fv = tv.first(lj);
                    let wv = axes[1].weights(j, l);
                    for (c, &(a, b)) in local.iter_mut().zip(partials) {
                        *c = tv
                            .row(lj, b)
                            .map_or(DVec3::ZERO, |row| dot(row, &q[a * nv + fv..]));
                    }
                    let base = ((i - oi) * out.width + j - oj) * out.stride;
                    for (slot, terms) in terms.iter().enumerate() {
                        let mut acc = DVec3::ZERO;
                        for &(c, ia, ib, s) in terms {
                            acc += local[s] * (c * wu[ia] * wv[ib]);
                        }
                        out.data[base + slot] += acc;
                    }
                }
            }
        }
    }
}

#[must_use]
pub(crate) fn clip(a: &Range<usize>, b: &Range<usize>) -> Range<usize> {
    a.start.max(b.start)..a.end.min(b.end).max(a.start.max(b.start))
}
