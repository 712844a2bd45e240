//! What changed since a mirror last saw it.
//!
//! An update reports a [`DirtyRegion`]; the renderer keeps one [`DirtySet`] per frame-in-flight
//! mirror and, before recording frame k, copies exactly the rows in mirror k's set.

use std::ops::Range;

/// Samples an update touched: a span of curve samples, or a rectangle of surface samples.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum DirtyRegion {
    Nothing,
    Curve(Range<usize>),
    Surface {
        rows: Range<usize>,
        cols: Range<usize>,
    },
}

impl DirtyRegion {
    /// Number of samples in the region.
    pub fn samples(&self) -> usize {
        match self {
            DirtyRegion::Nothing => 0,
            DirtyRegion::Curve(r) => r.len(),
            DirtyRegion::Surface { rows, cols } => rows.len() * cols.len(),
        }
    }

    /// Rows a mirror must re-copy: whole rows of a touched rectangle (contiguous in memory),
    /// samples of a curve.
    pub fn rows(&self) -> Range<usize> {
        match self {
            DirtyRegion::Nothing => 0..0,
            DirtyRegion::Curve(r) => r.clone(),
            DirtyRegion::Surface { rows, .. } => rows.clone(),
        }
    }

    /// Smallest region containing both.
    pub fn union(self, other: DirtyRegion) -> DirtyRegion {
        use DirtyRegion::*;
        match (self, other) {
            (Nothing, r) | (r, Nothing) => r,
            (Curve(a), Curve(b)) => Curve(a.start.min(b.start)..a.end.max(b.end)),
            (Surface { rows: r1, cols: c1 }, Surface { rows: r2, cols: c2 }) => Surface {
                rows: r1.start.min(r2.start)..r1.end.max(r2.end),
                cols: c1.start.min(c2.start)..c1.end.max(c2.end),
            },
            (a, b) => panic!("cannot unite {a:?} and {b:?}: different object kinds"),
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

    pub fn is_empty(&self) -> bool {
        self.ranges.is_empty()
    }

    pub fn ranges(&self) -> &[Range<usize>] {
        &self.ranges
    }

    /// Rows in the set.
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
