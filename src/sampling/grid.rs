//! The canonical f64 sample grid.

use crate::geom::point::{Point, nan_max};
use glam::DVec3;

/// Which derivatives a grid holds per sample. Curves: orders 0..=g. Surfaces: a downward-closed
/// set of partials (a, b) = ∂^{a+b}/∂u^a∂v^b, ordered so that every partial's lower partials come
/// first (the quotient rule for rational surfaces relies on it).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum PartialSet {
    /// c, c', …, c^(g).
    Curve(usize),
    /// All (a, b) with a, b ≤ g, row-major in a — the `prespline sample` layout.
    Square(usize),
    /// S, Su, Sv: what shading needs.
    Shading,
    /// S, Su, Sv, Suu, Suv, Svv: shading and surface curvature (the analysis maps).
    Curvature,
}

impl PartialSet {
    /// The partials in storage order.
    #[must_use]
    pub fn list(&self) -> Vec<(usize, usize)> {
        match *self {
            PartialSet::Curve(g) => (0..=g).map(|r| (r, 0)).collect(),
            PartialSet::Square(g) => (0..=g).flat_map(|a| (0..=g).map(move |b| (a, b))).collect(),
            PartialSet::Shading => vec![(0, 0), (1, 0), (0, 1)],
            PartialSet::Curvature => vec![(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)],
        }
    }

    /// Vectors stored per sample.
    #[must_use]
    pub fn len(&self) -> usize {
        match *self {
            PartialSet::Curve(g) => g + 1,
            PartialSet::Square(g) => (g + 1) * (g + 1),
            PartialSet::Shading => 3,
            PartialSet::Curvature => 6,
        }
    }

    #[must_use]
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Highest order per direction.
    #[must_use]
    pub fn max_order(&self) -> usize {
        match *self {
            PartialSet::Curve(g) | PartialSet::Square(g) => g,
            PartialSet::Shading => 1,
            PartialSet::Curvature => 2,
        }
    }

    /// Storage slot of partial (a, b).
    #[must_use]
    pub fn index(&self, a: usize, b: usize) -> Option<usize> {
        self.list().iter().position(|&p| p == (a, b))
    }
}

/// Samples of one object: `data[(i * cols + j) * stride + p]` is partial p of sample (i, j)
/// (curves: one column). Surfaces built for shading also keep unit normals, and those with
/// second partials ([`PartialSet::Curvature`]) their Gaussian and mean curvature.
#[derive(Debug, Clone, PartialEq)]
pub struct SampleGrid {
    /// [rows, cols]: [m, 1] for curves, [mu, mv] for surfaces.
    pub dims: [usize; 2],
    pub partials: PartialSet,
    pub data: Vec<DVec3>,
    /// Unit normals (surfaces with `Shading`, or `Square(g ≥ 1)` when requested), row-major.
    pub normals: Option<Vec<DVec3>>,
    /// [K, H] per sample, row-major: Gaussian and mean curvature with the normal orientation of
    /// `normals` (`Curvature` grids with normals only).
    pub curvatures: Option<Vec<[f64; 2]>>,
}

impl SampleGrid {
    #[must_use]
    pub fn new(dims: [usize; 2], partials: PartialSet, with_normals: bool) -> Self {
        let n = dims[0] * dims[1];
        let stride = partials.len();
        Self {
            dims,
            data: vec![DVec3::ZERO; n * stride],
            normals: with_normals.then(|| vec![DVec3::Z; n]),
            curvatures: (with_normals && partials == PartialSet::Curvature)
                .then(|| vec![[0.0; 2]; n]),
            partials,
        }
    }

    #[inline]
    #[must_use]
    pub fn stride(&self) -> usize {
        self.partials.len()
    }

    /// All partials of sample (i, j).
    #[inline]
    #[must_use]
    pub fn sample(&self, i: usize, j: usize) -> &[DVec3] {
        let s = self.stride();
        let base = (i * self.dims[1] + j) * s;
        &self.data[base..base + s]
    }

    #[inline]
    pub fn sample_mut(&mut self, i: usize, j: usize) -> &mut [DVec3] {
        let s = self.stride();
        let base = (i * self.dims[1] + j) * s;
        &mut self.data[base..base + s]
    }

    /// Position of sample (i, j).
    #[inline]
    #[must_use]
    pub fn position(&self, i: usize, j: usize) -> DVec3 {
        self.data[(i * self.dims[1] + j) * self.stride()]
    }

    /// Largest |component| over every stored value of partial slot p (its magnitude, for
    /// relative tolerances); NaN when any of them is NaN.
    #[must_use]
    pub fn scale(&self, p: usize) -> f64 {
        self.data
            .iter()
            .skip(p)
            .step_by(self.stride())
            .fold(0.0, |m, v| nan_max(m, v.max_abs()))
    }

    /// Per partial slot, the largest absolute difference to another grid of the same shape
    /// relative to that slot's own magnitude (the larger of the two grids' [`scale`]s, no
    /// floor): each derivative order is held to its own size, however small the object. A
    /// slot that is zero in both grids differs by 0. A NaN anywhere — in either grid, values or
    /// normals — gives +∞, so that no comparison with a tolerance can pass it.
    ///
    /// [`scale`]: SampleGrid::scale
    #[must_use]
    pub fn relative_differences(&self, other: &SampleGrid) -> Vec<f64> {
        assert_eq!(self.dims, other.dims);
        assert_eq!(self.partials, other.partials);
        let s = self.stride();
        (0..s)
            .map(|p| {
                let scale = nan_max(self.scale(p), other.scale(p));
                let diff = self
                    .data
                    .iter()
                    .zip(&other.data)
                    .skip(p)
                    .step_by(s)
                    .fold(0.0f64, |m, (a, b)| nan_max(m, (*a - *b).max_abs()));
                relative(diff, scale)
            })
            .collect()
    }

    /// The largest of [`relative_differences`](SampleGrid::relative_differences) (+∞ on NaN).
    pub fn max_relative_difference(&self, other: &SampleGrid) -> f64 {
        self.relative_differences(other)
            .into_iter()
            .fold(0.0, nan_max)
    }

    /// Largest distance between the unit normals of two grids (0 when neither keeps normals,
    /// +∞ when only one does or on NaN).
    #[must_use]
    pub fn max_normal_difference(&self, other: &SampleGrid) -> f64 {
        match (&self.normals, &other.normals) {
            (None, None) => 0.0,
            (Some(a), Some(b)) if a.len() == b.len() => {
                let d = a
                    .iter()
                    .zip(b)
                    .fold(0.0, |m, (x, y)| nan_max(m, (*x - *y).length()));
                if d.is_nan() { f64::INFINITY } else { d }
            }
            _ => f64::INFINITY,
        }
    }
}

/// `diff / scale`, +∞ for NaN and for any difference of something that is zero.
fn relative(diff: f64, scale: f64) -> f64 {
    if diff.is_nan() || scale.is_nan() {
        f64::INFINITY
    } else if diff == 0.0 {
        0.0
    } else {
        diff / scale
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn curve(values: &[[f64; 3]]) -> SampleGrid {
        let mut g = SampleGrid::new([values.len() / 2, 1], PartialSet::Curve(1), false);
        for (d, v) in g.data.iter_mut().zip(values) {
            *d = DVec3::from_array(*v);
        }
        g
    }

    #[test]
    fn a_nan_is_never_within_tolerance() {
        let a = curve(&[
            [1.0, 2.0, 3.0],
            [0.1, 0.0, 0.0],
            [2.0, 1.0, 0.0],
            [0.2, 0.0, 0.0],
        ]);
        let mut b = a.clone();
        assert_eq!(a.max_relative_difference(&b), 0.0);
        b.data[3].y = f64::NAN;
        assert_eq!(a.max_relative_difference(&b), f64::INFINITY);
        assert_eq!(b.max_relative_difference(&a), f64::INFINITY);
        assert!(b.scale(1).is_nan());
        // NaN in both at the same place is no better.
        assert_eq!(b.max_relative_difference(&b.clone()), f64::INFINITY);
    }

    #[test]
    fn each_derivative_order_is_relative_to_its_own_magnitude() {
        // Positions of size 1000, first derivatives of size 1e-3: an error of 1e-9 in the
        // derivative is 1e-6 of its magnitude, however large the positions are.
        let a = curve(&[
            [1000.0, 0.0, 0.0],
            [1e-3, 0.0, 0.0],
            [0.0, 1000.0, 0.0],
            [0.0, 1e-3, 0.0],
        ]);
        let mut b = a.clone();
        b.data[1].x += 1e-9;
        let rel = a.relative_differences(&b);
        assert_eq!(rel[0], 0.0);
        assert!((rel[1] - 1e-6).abs() < 1e-11, "{rel:?}");
        // A slot that is zero in one grid and not in the other differs relative to the other.
        let zero = curve(&[[1.0, 0.0, 0.0], [0.0; 3], [2.0, 0.0, 0.0], [0.0; 3]]);
        let mut nonzero = zero.clone();
        nonzero.data[1].x = 1e-300;
        assert_eq!(zero.relative_differences(&nonzero)[1], 1.0);
        assert_eq!(zero.relative_differences(&zero.clone())[1], 0.0);
    }

    #[test]
    fn normal_differences_catch_nan() {
        let mut a = SampleGrid::new([2, 2], PartialSet::Shading, true);
        let b = a.clone();
        assert_eq!(a.max_normal_difference(&b), 0.0);
        a.normals.as_mut().unwrap()[3] = DVec3::new(f64::NAN, 0.0, 1.0);
        assert_eq!(a.max_normal_difference(&b), f64::INFINITY);
    }
}
