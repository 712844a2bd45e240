//! Descriptive statistics of a set of times: mean, nearest-rank percentiles, "1 % low".

use serde::{Deserialize, Serialize};

/// The meaning of the percentile columns, for footnotes.
pub const PERCENTILE_MEANING: &str =
    "nearest-rank percentiles: at least p % of the frames took no longer";
/// The meaning of "1% low", for footnotes.
pub const LOW_1PCT_MEANING: &str = "mean of the slowest 1 % of the frames (lower is better)";

/// Statistics of a set of times in ms. See the module documentation of
/// [`crate::profile`] for the percentile method and the definition of `low_1pct`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Stats {
    pub count: usize,
    pub mean: f64,
    pub min: f64,
    pub p50: f64,
    pub p90: f64,
    pub p95: f64,
    pub p99: f64,
    pub max: f64,
    /// Mean of the slowest 1 % (at least one value).
    pub low_1pct: f64,
}

impl Stats {
    /// Placeholder for a set with no finite value (`count` 0, everything else 0).
    pub const EMPTY: Stats = Stats {
        count: 0,
        mean: 0.0,
        min: 0.0,
        p50: 0.0,
        p90: 0.0,
        p95: 0.0,
        p99: 0.0,
        max: 0.0,
        low_1pct: 0.0,
    };

    /// `None` when no finite value is given. Non-finite values are dropped: they can only
    /// come from hand-made records, and would make `summary.json` invalid.
    pub fn from_values(values: impl IntoIterator<Item = f64>) -> Option<Stats> {
        let mut sorted: Vec<f64> = values.into_iter().filter(|v| v.is_finite()).collect();
        sorted.sort_by(f64::total_cmp);
        Self::from_sorted(&sorted)
    }

    /// Like [`from_values`](Self::from_values) for values already sorted ascending.
    #[must_use]
    pub fn from_sorted(sorted: &[f64]) -> Option<Stats> {
        let (&min, &max) = (sorted.first()?, sorted.last()?);
        Some(Stats {
            count: sorted.len(),
            mean: sorted.iter().sum::<f64>() / sorted.len() as f64,
            min,
            p50: percentile(sorted, 50.0),
            p90: percentile(sorted, 90.0),
            p95: percentile(sorted, 95.0),
            p99: percentile(sorted, 99.0),
            max,
            low_1pct: slowest_mean(sorted, 0.01),
        })
    }
}

/// Nearest-rank percentile of ascending `sorted` values: the value at 1-based rank
/// `ceil(p/100 · n)`, clamped to `1..=n`. `p` is in percent. NaN for an empty slice.
#[must_use]
pub fn percentile(sorted: &[f64], p: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let n = sorted.len();
    // p·n is exact for the integer percentages used here, so the division is exact whenever
    // the true rank is an integer and `ceil` does not step past it.
    let rank = (p * n as f64 / 100.0).ceil() as usize;
    sorted[rank.clamp(1, n) - 1]
}

/// Mean of the largest `ceil(fraction · n)` (at least one) of ascending `sorted` values.
/// NaN for an empty slice.
#[must_use]
pub fn slowest_mean(sorted: &[f64], fraction: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let n = sorted.len();
    let k = ((fraction * n as f64).ceil() as usize).clamp(1, n);
    sorted[n - k..].iter().sum::<f64>() / k as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_rank_textbook_example() {
        // The worked example of the nearest-rank method (Wikipedia, "Percentile").
        let v = [15.0, 20.0, 35.0, 40.0, 50.0];
        assert_eq!(percentile(&v, 5.0), 15.0);
        assert_eq!(percentile(&v, 30.0), 20.0);
        assert_eq!(percentile(&v, 40.0), 20.0);
        assert_eq!(percentile(&v, 50.0), 35.0);
        assert_eq!(percentile(&v, 100.0), 50.0);
        assert_eq!(percentile(&v, 0.0), 15.0);
    }

    #[test]
    fn percentiles_of_one_to_hundred_are_their_rank() {
        let v: Vec<f64> = (1..=100).map(f64::from).collect();
        let s = Stats::from_sorted(&v).unwrap();
        assert_eq!((s.p50, s.p90, s.p95, s.p99), (50.0, 90.0, 95.0, 99.0));
        assert_eq!((s.min, s.max, s.count), (1.0, 100.0, 100));
        assert_eq!(s.mean, 50.5);
        // Slowest 1 % of 100 values is the single largest.
        assert_eq!(s.low_1pct, 100.0);
    }

    #[test]
    fn one_percent_low_averages_the_slowest_ceil_n_over_100() {
        // 1000 values: the slowest 10 are 991..=1000.
        let v: Vec<f64> = (1..=1000).map(f64::from).collect();
        assert_eq!(slowest_mean(&v, 0.01), 995.5);
        // 101 values: ceil(1.01) = 2 slowest.
        let v: Vec<f64> = (1..=101).map(f64::from).collect();
        assert_eq!(slowest_mean(&v, 0.01), 100.5);
        assert_eq!(percentile(&v, 99.0), 100.0);
    }

    #[test]
    fn unsorted_input_and_single_value() {
        let s = Stats::from_values([3.0, 1.0, 2.0]).unwrap();
        assert_eq!((s.min, s.p50, s.max, s.mean), (1.0, 2.0, 3.0, 2.0));
        let s = Stats::from_values([7.0]).unwrap();
        assert_eq!((s.p50, s.p99, s.low_1pct, s.count), (7.0, 7.0, 7.0, 1));
    }

    #[test]
    fn empty_and_non_finite() {
        assert!(Stats::from_values([]).is_none());
        assert!(Stats::from_values([f64::NAN]).is_none());
        assert!(percentile(&[], 50.0).is_nan());
        let s = Stats::from_values([1.0, f64::INFINITY, 3.0]).unwrap();
        assert_eq!((s.count, s.max), (2, 3.0));
    }
}
