//! Pre-evaluation data of one ERBS direction: sample parameters, the knot interval of each
//! sample, the blend weights with derivatives, and each local curve's sample range.

use crate::geom::BFunctionKind;
use crate::geom::erbs::{blend_weights, erbs_interval};
use crate::geom::knots::uniform_params;
use crate::geom::point::binomial;
use std::ops::Range;

#[derive(Debug, Clone)]
pub struct ErbsAxis {
    pub params: Vec<f64>,
    /// Knot interval i (1 ≤ i ≤ n−1) of each sample.
    pub spans: Vec<usize>,
    order: usize,
    /// Per sample: W^(r) for the left local curve (1 − B) at [0..=g], then the right one (B).
    blend: Vec<f64>,
    /// Per local curve l: the samples in its support, those with interval l or l+1.
    ranges: Vec<Range<usize>>,
}

impl ErbsAxis {
    pub fn new(knots: &[f64], bf: BFunctionKind, samples: usize, order: usize) -> Self {
        let n = knots.len() - 2;
        let params = uniform_params(knots[1], knots[n], samples);
        let spans: Vec<usize> = params.iter().map(|&t| erbs_interval(knots, t)).collect();
        let mut blend = Vec::with_capacity(samples * 2 * (order + 1));
        for (&t, &i) in params.iter().zip(&spans) {
            let [left, right] = blend_weights(&bf, knots, i, t, order);
            blend.extend_from_slice(&left);
            blend.extend_from_slice(&right);
        }
        let ranges = (0..n)
            .map(|l| {
                let start = spans.partition_point(|&i| i < l);
                let end = spans.partition_point(|&i| i <= l + 1);
                start..end
            })
            .collect();
        Self {
            params,
            spans,
            order,
            blend,
            ranges,
        }
    }

    /// Samples in the support of local curve l.
    pub fn range(&self, l: usize) -> Range<usize> {
        self.ranges[l].clone()
    }

    /// Blend weights W_l^(0..=g) of local curve l at sample j (l must be active there).
    #[inline]
    pub fn weights(&self, j: usize, l: usize) -> &[f64] {
        let g1 = self.order + 1;
        let side = if self.spans[j] == l { 1 } else { 0 };
        let base = (2 * j + side) * g1;
        &self.blend[base..base + g1]
    }
}

/// Leibniz terms ∂^r(W·c) = Σ_k C(r,k) W^(r−k) c^(k), per output order, as (C(r,k), r−k, k).
pub fn leibniz_terms(g: usize) -> Vec<Vec<(f64, usize, usize)>> {
    (0..=g)
        .map(|r| (0..=r).map(|k| (binomial(r, k), r - k, k)).collect())
        .collect()
}
