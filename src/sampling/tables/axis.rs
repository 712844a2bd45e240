//! Pre-evaluation data of one parameter direction of a B-spline (the paper's S, I and M).

use crate::geom::basis::hermite_rows_into;
use crate::geom::knots::{KnotVector, uniform_params};
use crate::geom::point::binomial;
use std::collections::HashMap;
use std::ops::Range;
use std::sync::{Arc, Mutex, OnceLock, PoisonError, Weak};

/// Pre-evaluated basis data for one direction: sample parameters S, the span of each sample,
/// the rows 0..=g of the B-spline-Hermite matrix at each sample, and per control point the index
/// range I of samples it influences.
#[derive(Debug, Clone)]
pub struct HermiteTable {
    /// Sample parameters S (m values, both domain ends included).
    pub params: Vec<f64>,
    /// FindSpan of each sample.
    pub spans: Vec<usize>,
    degree: usize,
    /// Derivative rows kept per sample: min(g, d) + 1 (rows above the degree are zero).
    rows: usize,
    /// Highest derivative order g requested.
    order: usize,
    /// Per sample, `rows × (d+1)` values, row-major.
    m: Vec<f64>,
    /// Per control point k: samples whose span i satisfies i−d ≤ k ≤ i (may be empty).
    ranges: Vec<Range<usize>>,
    /// The knots tabulated, so a refinement can tell whether this direction changed.
    knots: KnotVector,
}

impl HermiteTable {
    /// Pre-evaluates `samples` uniform parameters over the domain of a degree-`degree` B-spline
    /// with `n` control points, keeping derivatives up to order `order`.
    #[must_use]
    pub fn new(knots: &KnotVector, degree: usize, n: usize, samples: usize, order: usize) -> Self {
        let (a, b) = knots.domain(degree, n);
        let params = uniform_params(a, b, samples);
        Self::at_params(knots, degree, n, params, order)
    }

    /// [`HermiteTable::new`], shared with every live object that asked for the same knots,
    /// degree, count, sample count and order. The patches of a CAD model mostly share their
    /// knot vectors (every patch of the Utah teapot has the same two), and a table is never
    /// changed once built (a refinement builds a new one), so sharing saves its memory and its
    /// construction and leaves every value bit for bit what a fresh build gives.
    #[must_use]
    pub fn shared(
        knots: &KnotVector,
        degree: usize,
        n: usize,
        samples: usize,
        order: usize,
    ) -> Arc<Self> {
        let key = TableKey {
            knots: knots.iter().map(|k| k.to_bits()).collect(),
            shape: [degree, n, samples, order],
        };
        let lock = || {
            SHARED
                .get_or_init(Mutex::default)
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
        };
        if let Some(table) = lock().tables.get(&key).and_then(Weak::upgrade) {
            return table;
        }
        // Built outside the lock, so objects pre-evaluated on other cores do not wait; two
        // cores building the same table build equal ones, and the first stored is kept.
        let built = Arc::new(Self::new(knots, degree, n, samples, order));
        let mut shared = lock();
        let table = match shared.tables.get(&key).and_then(Weak::upgrade) {
            Some(table) => table,
            None => {
                shared.tables.insert(key, Arc::downgrade(&built));
                built
            }
        };
        shared.forget_dead();
        table
    }

    /// Pre-evaluation at given parameters (non-decreasing, inside the domain).
    #[must_use]
    pub fn at_params(
        knots: &KnotVector,
        degree: usize,
        n: usize,
        params: Vec<f64>,
        order: usize,
    ) -> Self {
        let w = degree + 1;
        let rows = order.min(degree) + 1;
        let mut m = vec![0.0; params.len() * rows * w];
        let mut spans = Vec::with_capacity(params.len());
        for (&t, out) in params.iter().zip(m.chunks_exact_mut(rows * w)) {
            let span = knots.find_span(degree, n, t);
            hermite_rows_into(knots, degree, span, t, rows, out);
            spans.push(span);
        }
        let ranges = influence_ranges(&spans, degree, n);
        Self {
            params,
            spans,
            degree,
            rows,
            order,
            m,
            ranges,
            knots: knots.clone(),
        }
    }

    /// The table of the same parameters for a new basis (knots, degree, control count), as after
    /// a knot insertion: a sample whose span has the same knot window t_{s−d+1} … t_{s+d} as
    /// before keeps its matrix (the same arithmetic on the same values), so only the samples
    /// near the changed knots are evaluated again.
    #[must_use]
    pub fn refit(&self, knots: &KnotVector, degree: usize, n: usize) -> Self {
        if degree != self.degree {
            return Self::at_params(knots, degree, n, self.params.clone(), self.order);
        }
        let w = degree + 1;
        let per = self.rows * w;
        let mut m = vec![0.0; self.m.len()];
        let mut spans = Vec::with_capacity(self.params.len());
        // M on span s reads the knots t_{s−d+1} … t_{s+d} (and t).
        #[must_use]
        fn window(k: &[f64], s: usize, d: usize) -> &[f64] {
            &k[s + 1 - d..s + d + 1]
        }
        for (j, (&t, out)) in self.params.iter().zip(m.chunks_exact_mut(per)).enumerate() {
            let span = knots.find_span(degree, n, t);
            let old = self.spans[j];
            if window(knots, span, degree) == window(&self.knots, old, degree) {
                out.copy_from_slice(&self.m[j * per..(j + 1) * per]);
            } else {
                hermite_rows_into(knots, degree, span, t, self.rows, out);
            }
            spans.push(span);
        }
        let ranges = influence_ranges(&spans, degree, n);
        Self {
            params: self.params.clone(),
            spans,
            degree,
            rows: self.rows,
            order: self.order,
            m,
            ranges,
            knots: knots.clone(),
        }
    }

    /// The table of W·N_k at the same samples for a weight W given per sample with its
    /// derivatives W^(0..=g), g this table's order: row r is Σ_{s ≤ r} C(r,s) W^(r−s) N^(s)
    /// (Leibniz), kept for every order up to g, above the degree too. This is an ERBS local's
    /// basis blended with its weight, so a local patch blends in by the tensor-product kernels.
    #[must_use]
    pub fn blended<'w>(&self, weight: impl Fn(usize) -> &'w [f64]) -> Self {
        let w = self.degree + 1;
        let rows = self.order + 1;
        let mut m = vec![0.0; self.params.len() * rows * w];
        for (j, out) in m.chunks_exact_mut(rows * w).enumerate() {
            let wj = weight(j);
            for (r, out) in out.chunks_exact_mut(w).enumerate() {
                for s in 0..=r.min(self.rows - 1) {
                    let c = binomial(r, s) * wj[r - s];
                    let src = &self.m[(j * self.rows + s) * w..][..w];
                    for (o, &x) in out.iter_mut().zip(src) {
                        *o += c * x;
                    }
                }
            }
        }
        Self {
            params: self.params.clone(),
            spans: self.spans.clone(),
            degree: self.degree,
            rows,
            order: self.order,
            m,
            ranges: self.ranges.clone(),
            knots: self.knots.clone(),
        }
    }

    /// Whether both tables tabulate the same basis (degree, knots, control count) at the same
    /// parameters.
    #[must_use]
    pub fn same_basis(&self, other: &Self) -> bool {
        self.degree == other.degree
            && self.ranges.len() == other.ranges.len()
            && self.knots == other.knots
            && self.params == other.params
    }

    /// Whether this table is the pre-evaluation of a degree-`degree` B-spline with `n` control
    /// points on `knots`.
    #[must_use]
    pub fn tabulates(&self, knots: &KnotVector, degree: usize, n: usize) -> bool {
        self.degree == degree && self.ranges.len() == n && self.knots == *knots
    }

    #[must_use]
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// Highest derivative order g this table was built for.
    #[must_use]
    pub fn order(&self) -> usize {
        self.order
    }

    #[must_use]
    pub fn len(&self) -> usize {
        self.params.len()
    }

    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.params.is_empty()
    }

    /// Index of the first control point active at sample j (span − d).
    #[inline]
    #[must_use]
    pub fn first(&self, j: usize) -> usize {
        self.spans[j] - self.degree
    }

    /// Row r of M at sample j (the r-th derivatives of the d+1 active basis functions), or
    /// `None` when r exceeds the degree (all zero).
    #[inline]
    #[must_use]
    pub fn row(&self, j: usize, r: usize) -> Option<&[f64]> {
        if r >= self.rows {
            return None;
        }
        let w = self.degree + 1;
        let base = (j * self.rows + r) * w;
        Some(&self.m[base..base + w])
    }

    /// Derivative rows kept per sample (min(g, d) + 1).
    #[inline]
    #[must_use]
    pub fn rows_kept(&self) -> usize {
        self.rows
    }

    /// All of M in storage order, per sample `rows_kept() × (d+1)` values, for kernels that
    /// walk it linearly instead of looking rows up one by one.
    #[inline]
    #[must_use]
    pub fn matrix(&self) -> &[f64] {
        &self.m
    }

    /// Coefficient of control point k in the r-th derivative at sample j (0 if inactive).
    #[inline]
    #[must_use]
    pub fn coeff(&self, j: usize, r: usize, k: usize) -> f64 {
        let first = self.first(j);
        if r >= self.rows || k < first || k > first + self.degree {
            return 0.0;
        }
        self.m[(j * self.rows + r) * (self.degree + 1) + (k - first)]
    }

    /// The samples control point k influences (the paper's I_k).
    #[inline]
    #[must_use]
    pub fn range(&self, k: usize) -> Range<usize> {
        self.ranges[k].clone()
    }

    /// The samples control point k influences, `None` for an index past the control points.
    #[must_use]
    pub fn range_of(&self, k: usize) -> Option<Range<usize>> {
        self.ranges.get(k).cloned()
    }
}

/// I_k for every control point k: spans are non-decreasing in the sample index, so
/// {j : span_j ∈ [k, k+d]} is an interval, found with two monotone cursors.
#[must_use]
fn influence_ranges(spans: &[usize], degree: usize, n: usize) -> Vec<Range<usize>> {
    let mut ranges = Vec::with_capacity(n);
    let (mut lo, mut hi) = (0usize, 0usize);
    for k in 0..n {
        while lo < spans.len() && spans[lo] < k {
            lo += 1;
        }
        hi = hi.max(lo);
        while hi < spans.len() && spans[hi] <= k + degree {
            hi += 1;
        }
        ranges.push(lo..hi);
    }
    ranges
}

/// Σ_k row[k]·p[k]: a row of M (or of a blended table) against the points it weights.
#[inline]
#[must_use]
pub(crate) fn dot<P>(row: &[f64], p: &[P]) -> P
where
    P: Copy + Default + std::ops::Add<Output = P> + std::ops::Mul<f64, Output = P>,
{
    let mut acc = P::default();
    for (c, &q) in row.iter().zip(p) {
        acc = acc + q * *c;
    }
    acc
}

/// What a shared table is built from: the knots' bits and (degree, count, samples, order).
#[derive(Debug, PartialEq, Eq, Hash)]
struct TableKey {
    knots: Vec<u64>,
    shape: [usize; 4],
}

/// The tables [`HermiteTable::shared`] handed out, held weakly: a table lives as long as an
/// object uses it.
#[derive(Default)]
struct SharedTables {
    tables: HashMap<TableKey, Weak<HermiteTable>>,
    /// Entries at the last sweep of dead ones; the next sweep waits until the map doubles, so
    /// sweeping costs O(1) per insertion amortised.
    swept: usize,
}

impl SharedTables {
    fn forget_dead(&mut self) {
        if self.tables.len() >= 2 * self.swept.max(32) {
            self.tables.retain(|_, t| t.strong_count() > 0);
            self.swept = self.tables.len();
        }
    }
}

static SHARED: OnceLock<Mutex<SharedTables>> = OnceLock::new();

#[cfg(test)]
mod tests {
    use super::*;

    /// Equal inputs share one table while it lives; any differing input gets its own; a
    /// table nobody holds is rebuilt, equal to a fresh build.
    #[test]
    fn tables_are_shared_by_equal_inputs_only() {
        // Knots no other test uses, so tables of tests running alongside cannot interfere.
        let knots = KnotVector::clamped_uniform(3, 7, 0.125, 0.9375);
        let a = HermiteTable::shared(&knots, 3, 7, 33, 2);
        let b = HermiteTable::shared(&knots, 3, 7, 33, 2);
        assert!(Arc::ptr_eq(&a, &b), "equal inputs share");
        let moved = KnotVector::clamped_uniform(3, 7, 0.125, 0.9376);
        let differing = [
            HermiteTable::shared(&moved, 3, 7, 33, 2),
            HermiteTable::shared(&knots, 3, 7, 34, 2),
            HermiteTable::shared(&knots, 3, 7, 33, 1),
        ];
        for d in &differing {
            assert!(
                !Arc::ptr_eq(&a, d),
                "a differing input builds its own table"
            );
        }
        let fresh = HermiteTable::new(&knots, 3, 7, 33, 2);
        let same = |t: &HermiteTable| {
            t.params == fresh.params
                && t.spans == fresh.spans
                && t.m
                    .iter()
                    .map(|x| x.to_bits())
                    .eq(fresh.m.iter().map(|x| x.to_bits()))
                && t.ranges == fresh.ranges
        };
        assert!(same(&a));
        assert!(
            !same(&differing[1]),
            "negative control: the comparison sees a difference"
        );
        let weak = Arc::downgrade(&a);
        drop((a, b));
        assert!(weak.upgrade().is_none(), "the cache holds no table alive");
        assert!(same(&HermiteTable::shared(&knots, 3, 7, 33, 2)));
    }

    #[test]
    fn paper_example_ranges_cover_pieces_two_to_five() {
        // Degree 3, 10 control points, knots {0,0,0,0,1,…,6,7,7,7,7}: moving C4 changes pieces
        // 2–5, i.e. parameters in [1, 5].
        let knots = KnotVector::clamped_uniform(3, 10, 0.0, 7.0);
        let t = HermiteTable::new(&knots, 3, 10, 71, 1);
        let r = t.range(4);
        assert_eq!(t.params[r.start], 1.0);
        assert!(t.params[r.end - 1] < 5.0 && t.params[r.end] == 5.0);
        let pieces: std::collections::BTreeSet<usize> =
            r.clone().map(|j| t.spans[j] - 3 + 1).collect();
        assert_eq!(pieces.into_iter().collect::<Vec<_>>(), vec![2, 3, 4, 5]);
        // Outside I_4 the basis function of C4 vanishes; inside it is the matrix entry.
        for j in 0..t.len() {
            let c = t.coeff(j, 0, 4);
            if !r.contains(&j) {
                assert_eq!(c, 0.0);
            }
        }
        assert_eq!(t.range(0), 0..10);
        assert_eq!(t.range(9).end, 71);
    }
}
