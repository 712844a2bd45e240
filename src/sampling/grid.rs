//! The canonical f64 sample grid.

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
    pub fn list(&self) -> Vec<(usize, usize)> {
        match *self {
            PartialSet::Curve(g) => (0..=g).map(|r| (r, 0)).collect(),
            PartialSet::Square(g) => (0..=g).flat_map(|a| (0..=g).map(move |b| (a, b))).collect(),
            PartialSet::Shading => vec![(0, 0), (1, 0), (0, 1)],
            PartialSet::Curvature => vec![(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)],
        }
    }

    /// Vectors stored per sample.
    pub fn len(&self) -> usize {
        match *self {
            PartialSet::Curve(g) => g + 1,
            PartialSet::Square(g) => (g + 1) * (g + 1),
            PartialSet::Shading => 3,
            PartialSet::Curvature => 6,
        }
    }

    pub fn is_empty(&self) -> bool {
        false
    }

    /// Highest order per direction.
    pub fn max_order(&self) -> usize {
        match *self {
            PartialSet::Curve(g) | PartialSet::Square(g) => g,
            PartialSet::Shading => 1,
            PartialSet::Curvature => 2,
        }
    }

    /// Storage slot of partial (a, b).
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
    pub fn stride(&self) -> usize {
        self.partials.len()
    }

    /// All partials of sample (i, j).
    #[inline]
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
    pub fn position(&self, i: usize, j: usize) -> DVec3 {
        self.data[(i * self.dims[1] + j) * self.stride()]
    }

    /// Largest |component| over every stored value of partial slot p (for relative tolerances).
    pub fn scale(&self, p: usize) -> f64 {
        self.data
            .iter()
            .skip(p)
            .step_by(self.stride())
            .fold(0.0, |m, v| m.max(v.abs().max_element()))
    }

    /// Largest absolute difference to another grid of the same shape, per partial slot,
    /// relative to max(1, that slot's scale).
    pub fn max_relative_difference(&self, other: &SampleGrid) -> f64 {
        assert_eq!(self.dims, other.dims);
        assert_eq!(self.partials, other.partials);
        let s = self.stride();
        (0..s)
            .map(|p| {
                let scale = self.scale(p).max(other.scale(p)).max(1.0);
                let diff = self
                    .data
                    .iter()
                    .zip(&other.data)
                    .skip(p)
                    .step_by(s)
                    .fold(0.0f64, |m, (a, b)| m.max((*a - *b).abs().max_element()));
                diff / scale
            })
            .fold(0.0, f64::max)
    }
}
