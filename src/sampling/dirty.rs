//! What changed since a mirror last saw it.
//!
//! An update reports a [`DirtyRegion`]; the renderer keeps one [`DirtySet`] per frame-in-flight
//! mirror and, before recording frame k, copies exactly the rows in mirror k's set (whole rows
//! of touched rectangles, which are contiguous in memory).

use std::ops::Range;

/// Samples an update touched: a rectangle of sample rows × columns (curves have one column).
/// Empty when nothing changed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DirtyRegion {
    pub rows: Range<usize>,
    pub cols: Range<usize>,
}

impl DirtyRegion {
    pub const NOTHING: DirtyRegion = DirtyRegion {
        rows: 0..0,
        cols: 0..0,
    };

    /// A span of curve samples.
    #[must_use]
    pub fn curve(samples: Range<usize>) -> Self {
        Self::surface(samples, 0..1)
    }

    /// Every sample of a `rows × cols` grid.
    #[must_use]
    pub fn whole([rows, cols]: [usize; 2]) -> Self {
        Self::surface(0..rows, 0..cols)
    }

    /// Whether every sample of `other` is in this region.
    #[must_use]
    pub fn contains(&self, other: &DirtyRegion) -> bool {
        other.is_empty()
            || (self.rows.start <= other.rows.start
                && other.rows.end <= self.rows.end
                && self.cols.start <= other.cols.start
                && other.cols.end <= self.cols.end)
    }

    /// A rectangle of surface samples.
    #[must_use]
    pub fn surface(rows: Range<usize>, cols: Range<usize>) -> Self {
        if rows.is_empty() || cols.is_empty() {
            Self::NOTHING
        } else {
            Self { rows, cols }
        }
    }

    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// Number of samples in the region.
    #[must_use]
    pub fn samples(&self) -> usize {
        self.rows.len() * self.cols.len()
    }

    /// Smallest region containing both.
    #[must_use]
    pub fn union(self, other: DirtyRegion) -> DirtyRegion {
        if self.is_empty() {
            return other;
        }
        if other.is_empty() {
            return self;
        }
        DirtyRegion {
            rows: self.rows.start.min(other.rows.start)..self.rows.end.max(other.rows.end),
            cols: self.cols.start.min(other.cols.start)..self.cols.end.max(other.cols.end),
        }
    }
}

/// A set of disjoint, sorted row ranges; inserting merges overlapping and adjacent ranges so a
/// mirror copies each dirty row once, in as few contiguous runs as possible.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct DirtySet {
    ranges: Vec<Range<usize>>,
}

impl DirtySet {
    /// Everything in 0..n (a fresh mirror).
    #[must_use]
    pub fn all(n: usize) -> Self {
        Self {
            ranges: if n > 0 {
                std::iter::once(0..n).collect()
            } else {
                Vec::new()
            },
        }
    }

    pub fn insert(&mut self, r: Range<usize>) {
        if r.is_empty() {
            return;
        }
        // First range that ends at or after r.start (could merge), last that starts at or
        // before r.end.
        let lo = self.ranges.partition_point(|x| x.end < r.start);
        let hi = self.ranges.partition_point(|x| x.start <= r.end);
        if lo == hi {
            self.ranges.insert(lo, r);
            return;
        }
        let start = r.start.min(self.ranges[lo].start);
        let end = r.end.max(self.ranges[hi - 1].end);
        self.ranges.splice(lo..hi, std::iter::once(start..end));
    }

    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.ranges.is_empty()
    }

    #[must_use]
    pub fn ranges(&self) -> &[Range<usize>] {
        &self.ranges
    }

    /// Rows in the set.
    #[must_use]
    pub fn count(&self) -> usize {
        self.ranges.iter().map(|r| r.len()).sum()
    }

    /// Returns the ranges and leaves the set empty.
    pub fn take(&mut self) -> Vec<Range<usize>> {
        std::mem::take(&mut self.ranges)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dirty_set_merges_overlaps_and_neighbours() {
        let mut s = DirtySet::default();
        s.insert(10..20);
        s.insert(30..40);
        s.insert(0..5);
        assert_eq!(s.ranges(), &[0..5, 10..20, 30..40]);
        s.insert(20..30);
        assert_eq!(s.ranges(), &[0..5, 10..40]);
        s.insert(3..12);
        assert_eq!(s.ranges().len(), 1);
        assert_eq!(s.ranges()[0], 0..40);
        s.insert(50..50);
        assert_eq!(s.count(), 40);
        assert_eq!(s.take().len(), 1);
        assert!(s.is_empty());
    }

    #[test]
    fn dirty_set_matches_a_bitmap_on_random_inserts() {
        let mut state = 0x9e3779b97f4a7c15u64;
        let mut next = |n: u64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % n) as usize
        };
        for _ in 0..200 {
            let mut s = DirtySet::default();
            let mut bits = vec![false; 100];
            for _ in 0..next(12) {
                let a = next(100);
                let b = (a + next(15)).min(100);
                s.insert(a..b);
                bits[a..b].iter_mut().for_each(|x| *x = true);
            }
            let mut from_set = vec![false; 100];
            for r in s.ranges() {
                from_set[r.clone()].iter_mut().for_each(|x| *x = true);
            }
            assert_eq!(bits, from_set);
            for w in s.ranges().windows(2) {
                assert!(
                    w[0].end < w[1].start,
                    "ranges must be disjoint and not adjacent"
                );
            }
        }
    }
}
