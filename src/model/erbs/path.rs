//! Paths to ERBS locals at any depth.

use crate::geom::erbs::MAX_NESTING;
use crate::model::Index2;
use std::fmt::Debug;
use std::hash::Hash;

/// The path to a local curve or patch: one index (curves) or index pair (surfaces) per ERBS
/// level, from the object's own locals down. At most [`MAX_NESTING`] steps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct LocalPath<I> {
    len: u8,
    steps: [I; MAX_NESTING],
}

/// "2 → [1, 0]": the steps from the object's own locals down.
impl<I: Copy + std::fmt::Display> std::fmt::Display for LocalPath<I> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        for (k, step) in self.steps[..usize::from(self.len)].iter().enumerate() {
            if k > 0 {
                f.write_str(" → ")?;
            }
            write!(f, "{step}")?;
        }
        Ok(())
    }
}

impl<I: Copy + Default> LocalPath<I> {
    /// `None` for an empty or too long path.
    pub fn new(steps: &[I]) -> Option<Self> {
        if steps.is_empty() || steps.len() > MAX_NESTING {
            return None;
        }
        let mut s = [I::default(); MAX_NESTING];
        s[..steps.len()].copy_from_slice(steps);
        Some(Self {
            len: steps.len() as u8,
            steps: s,
        })
    }

    /// A top-level local.
    pub fn top(i: I) -> Self {
        Self::new(&[i]).expect("one step")
    }

    pub fn steps(&self) -> &[I] {
        &self.steps[..self.len as usize]
    }

    /// The path one level deeper.
    pub fn child(&self, i: I) -> Option<Self> {
        let mut v = self.steps().to_vec();
        v.push(i);
        Self::new(&v)
    }

    /// Whether this path is `prefix` or lies below it.
    pub fn starts_with(&self, prefix: &LocalPath<I>) -> bool
    where
        I: PartialEq,
    {
        self.steps().starts_with(prefix.steps())
    }

    /// The same path with index pairs for both kinds (what [`Target`] compares).
    pub fn key(&self) -> LocalPath<Index2>
    where
        I: Into<Index2>,
    {
        LocalPath {
            len: self.len,
            steps: self.steps.map(Into::into),
        }
    }
}

impl LocalPath<Index2> {
    /// The curve form of a path of single indices.
    #[must_use]
    pub fn to_curve(&self) -> Option<LocalPath<usize>> {
        let steps: Option<Vec<usize>> = self
            .steps()
            .iter()
            .map(|i| match *i {
                Index2::One(k) => Some(k),
                Index2::Two(..) => None,
            })
            .collect();
        LocalPath::new(&steps?)
    }

    /// The surface form of a path of index pairs.
    #[must_use]
    pub fn to_surface(&self) -> Option<LocalPath<[usize; 2]>> {
        let steps: Option<Vec<[usize; 2]>> = self
            .steps()
            .iter()
            .map(|i| match *i {
                Index2::Two(k, l) => Some([k, l]),
                Index2::One(_) => None,
            })
            .collect();
        LocalPath::new(&steps?)
    }
}

impl Default for Index2 {
    fn default() -> Self {
        Index2::One(0)
    }
}
