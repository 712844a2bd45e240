//! Pre-evaluation data of one ERBS direction at given parameters: the interval of each sample,
//! the blend weights of its two locals with derivatives, and for each local the samples it
//! covers as pieces (two for the local that wraps around a closed direction).

use crate::geom::erbs::{ErbsKnots, blend_weights};
use crate::geom::point::binomial;
use crate::geom::{BFunction, BFunctionKind};
use std::ops::Range;

/// Samples of a level covered by one local: the local is evaluated at param − shift there
/// (shift T where a closed direction wraps). `offset` is where these samples start in the
/// local's own sample list, which runs over its pieces in increasing local parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct Piece {
    pub samples: Range<usize>,
    pub shift: f64,
    pub offset: usize,
}

impl Piece {
    /// The level samples of local samples `local` (clipped to this piece), or `None`.
    #[must_use]
    pub fn level_range(&self, local: &Range<usize>) -> Option<Range<usize>> {
        let lo = local.start.max(self.offset);
        let hi = local.end.min(self.offset + self.samples.len());
        (lo < hi)
            .then(|| self.samples.start + lo - self.offset..self.samples.start + hi - self.offset)
    }
}

#[derive(Debug, Clone)]
pub struct ErbsAxis {
    pub params: Vec<f64>,
    /// Interval of each sample.
    pub spans: Vec<usize>,
    order: usize,
    /// Per sample: W^(0..=g) of the interval's left local (1 − B), then of its right one (B).
    blend: Vec<f64>,
    /// Per local: the samples it covers.
    pieces: Vec<Vec<Piece>>,
    /// The samples of each knot interval met, in order.
    cells: Vec<Cell>,
}

/// The samples of one knot interval and its two active locals (left, then right).
#[derive(Debug, Clone, PartialEq)]
pub struct Cell {
    pub samples: Range<usize>,
    pub locals: [usize; 2],
}

impl ErbsAxis {
    #[must_use]
    pub fn new(knots: &ErbsKnots, bf: BFunctionKind, params: Vec<f64>, order: usize) -> Self {
        let spans: Vec<usize> = params.iter().map(|&t| knots.locate(t)).collect();
        let mut blend = Vec::with_capacity(params.len() * 2 * (order + 1));
        for (&t, &i) in params.iter().zip(&spans) {
            let [left, right] = blend_weights(&bf, knots.interval(i), t, order);
            blend.extend_from_slice(&left);
            blend.extend_from_slice(&right);
        }
        let pieces = pieces(knots, &params, &spans);
        let cells = cells(knots, &spans);
        Self {
            params,
            spans,
            order,
            blend,
            pieces,
            cells,
        }
    }

    /// The same parameters on knots with one more centre inserted strictly inside interval i
    /// (see [`ErbsKnots::insert`]): samples outside that interval keep their weights (their
    /// interval's knots are the same), only those inside are evaluated again.
    #[must_use]
    pub fn refined(&self, knots: &ErbsKnots, bf: BFunctionKind, i: usize) -> Self {
        let g1 = self.order + 1;
        let mut spans = Vec::with_capacity(self.params.len());
        let mut blend = Vec::with_capacity(self.blend.len());
        for (j, &t) in self.params.iter().enumerate() {
            let old = self.spans[j];
            if old == i {
                let s = knots.locate(t);
                let [left, right] = blend_weights(&bf, knots.interval(s), t, self.order);
                blend.extend_from_slice(&left);
                blend.extend_from_slice(&right);
                spans.push(s);
            } else {
                blend.extend_from_slice(&self.blend[2 * g1 * j..2 * g1 * (j + 1)]);
                spans.push(if old > i { old + 1 } else { old });
            }
        }
        let pieces = pieces(knots, &self.params, &spans);
        let cells = cells(knots, &spans);
        Self {
            params: self.params.clone(),
            spans,
            order: self.order,
            blend,
            pieces,
            cells,
        }
    }

    #[must_use]
    pub fn len(&self) -> usize {
        self.params.len()
    }

    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.params.is_empty()
    }

    /// Blend weights W^(0..=g) of local l at sample j (l must be active there).
    #[inline]
    #[must_use]
    pub fn weights(&self, j: usize, l: usize) -> &[f64] {
        let g1 = self.order + 1;
        let side = usize::from(self.spans[j] != l);
        let base = (2 * j + side) * g1;
        &self.blend[base..base + g1]
    }

    /// Number of locals of the direction.
    #[must_use]
    pub fn locals(&self) -> usize {
        self.pieces.len()
    }

    #[must_use]
    pub fn pieces(&self, l: usize) -> &[Piece] {
        &self.pieces[l]
    }

    /// The parameters local l is evaluated at, in its own increasing order.
    #[must_use]
    pub fn local_params(&self, l: usize) -> Vec<f64> {
        self.pieces[l]
            .iter()
            .flat_map(|p| {
                self.params[p.samples.clone()]
                    .iter()
                    .map(move |&t| t - p.shift)
            })
            .collect()
    }

    /// The level sample of each of local l's samples, in its own order.
    #[must_use]
    pub fn local_rows(&self, l: usize) -> Vec<usize> {
        self.pieces[l]
            .iter()
            .flat_map(|p| p.samples.clone())
            .collect()
    }

    /// Local l's own index of level sample j (which it must cover).
    #[must_use]
    pub fn local_index(&self, l: usize, j: usize) -> usize {
        let p = self.pieces[l]
            .iter()
            .find(|p| p.samples.contains(&j))
            .expect("the local covers the sample");
        j - p.samples.start + p.offset
    }

    #[must_use]
    pub fn cells(&self) -> &[Cell] {
        &self.cells
    }

    /// How many samples local l covers.
    #[must_use]
    pub fn local_len(&self, l: usize) -> usize {
        self.pieces[l].iter().map(|p| p.samples.len()).sum()
    }

    /// The samples a refinement inside interval i changes: those strictly inside it, and
    /// those at its two knots as well when the B-function's derivatives up to the sampled
    /// order do not all vanish at 0 and 1 (the expo-rational one's all do).
    #[must_use]
    pub fn touched_by_refinement(
        &self,
        knots: &ErbsKnots,
        i: usize,
        bf: BFunctionKind,
    ) -> Range<usize> {
        let (a, b) = knots.interval(i);
        let mut d = vec![0.0; self.order + 1];
        let flat = [0.0, 1.0].iter().all(|&w| {
            bf.derivatives(w, &mut d);
            d[1..].iter().all(|&x| x == 0.0)
        });
        let (lo, hi) = if flat {
            (
                self.params.partition_point(|&t| t <= a),
                self.params.partition_point(|&t| t < b),
            )
        } else {
            (
                self.params.partition_point(|&t| t < a),
                self.params.partition_point(|&t| t <= b),
            )
        };
        lo..hi.max(lo)
    }
}

/// The runs of samples with one interval, with the interval's two locals.
#[must_use]
fn cells(knots: &ErbsKnots, spans: &[usize]) -> Vec<Cell> {
    let mut cells: Vec<Cell> = Vec::new();
    for (j, &i) in spans.iter().enumerate() {
        match cells.last_mut() {
            Some(c) if c.locals[0] == i => c.samples.end = j + 1,
            _ => cells.push(Cell {
                samples: j..j + 1,
                locals: [i, knots.right(i).0],
            }),
        }
    }
    cells
}

/// For every local, the runs of consecutive samples where it is active with one shift, ordered
/// by local parameter.
#[must_use]
fn pieces(knots: &ErbsKnots, params: &[f64], spans: &[usize]) -> Vec<Vec<Piece>> {
    let n = knots.locals();
    let mut runs: Vec<Vec<(Range<usize>, f64)>> = vec![Vec::new(); n];
    for (j, &i) in spans.iter().enumerate() {
        let (right, shift) = knots.right(i);
        for (l, s) in [(i, 0.0), (right, shift)] {
            match runs[l].last_mut() {
                Some((r, rs)) if r.end == j && *rs == s => r.end += 1,
                _ => runs[l].push((j..j + 1, s)),
            }
        }
    }
    runs.into_iter()
        .map(|mut r| {
            r.sort_by(|a, b| {
                let (ta, tb) = (params[a.0.start] - a.1, params[b.0.start] - b.1);
                ta.total_cmp(&tb)
            });
            let mut offset = 0;
            r.into_iter()
                .map(|(samples, shift)| {
                    let p = Piece {
                        offset,
                        shift,
                        samples,
                    };
                    offset += p.samples.len();
                    p
                })
                .collect()
        })
        .collect()
}

/// Leibniz terms ∂^r(W·c) = Σ_k C(r,k) W^(r−k) c^(k), per output order, as (C(r,k), r−k, k).
#[must_use]
pub fn leibniz_terms(g: usize) -> Vec<Vec<(f64, usize, usize)>> {
    (0..=g)
        .map(|r| (0..=r).map(|k| (binomial(r, k), r - k, k)).collect())
        .collect()
}
