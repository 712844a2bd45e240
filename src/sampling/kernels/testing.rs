//! What the kernels' tests share: a small deterministic generator, (Su, Sv) cases for the
//! normals, and the comparison of a fast `Shading` grid with a generic `Square(1)` one.

use crate::geom::point::{Point, nan_max};
use crate::geom::surface::regular_normal;
use crate::sampling::grid::{PartialSet, SampleGrid};
use glam::DVec3;

pub(crate) struct Rng(pub u64);

impl Rng {
    #[must_use]
    pub(crate) fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    #[must_use]
    pub(crate) fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    #[must_use]
    pub(crate) fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.unit()
    }
    #[must_use]
    pub(crate) fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    #[must_use]
    pub(crate) fn vec(&mut self, s: f64) -> DVec3 {
        DVec3::new(self.range(-s, s), self.range(-s, s), self.range(-s, s))
    }
}

/// Largest difference of S, Su, Sv (relative to max(1, |value|)) and of the normals between
/// a `Shading` grid and a `Square(1)` grid of the same surface.
#[must_use]
pub(crate) fn difference(fast: &SampleGrid, generic: &SampleGrid) -> f64 {
    assert_eq!(fast.partials, PartialSet::Shading);
    let n = fast.dims[0] * fast.dims[1];
    let mut worst = 0.0f64;
    for s in 0..n {
        for (p, &(a, b)) in [(0, 0), (1, 0), (0, 1)].iter().enumerate() {
            let x = fast.data[s * 3 + p];
            let y = generic.data[s * 4 + generic.partials.index(a, b).unwrap()];
            let scale = nan_max(x.max_abs(), y.max_abs()).max(1.0);
            worst = nan_max(worst, (x - y).max_abs() / scale);
        }
        let (nf, ng) = (
            &fast.normals.as_ref().unwrap(),
            generic.normals.as_ref().unwrap(),
        );
        worst = nan_max(worst, (nf[s] - ng[s]).max_abs());
    }
    worst
}

/// (Su, Sv) pairs: zero, tiny, huge, NaN and infinite partials, then random ones over 20
/// decades, every third pair nearly parallel (near the regularity threshold).
#[must_use]
pub(crate) fn normal_cases() -> Vec<(DVec3, DVec3)> {
    let mut rng = Rng(99);
    let special = [
        DVec3::ZERO,
        DVec3::X,
        DVec3::new(1e-200, 0.0, 0.0),
        DVec3::new(1e200, 1e200, 0.0),
        DVec3::new(f64::NAN, 0.0, 1.0),
        DVec3::new(f64::INFINITY, 1.0, 0.0),
    ];
    (0..10_000)
        .map(|n| {
            if n < 36 {
                return (special[n / 6], special[n % 6]);
            }
            let su = 10f64.powi(rng.below(20) as i32 - 10);
            let sv = 10f64.powi(rng.below(20) as i32 - 10);
            let u = rng.vec(su);
            let v = match n % 3 {
                0 => u * rng.range(-2.0, 2.0) + rng.vec(1e-12),
                _ => rng.vec(sv),
            };
            (u, v)
        })
        .collect()
}

/// Bit for bit `regular_normal`'s normal, or flagged degenerate exactly where it says so.
pub(crate) fn assert_is_regular_normal(u: DVec3, v: DVec3, n: [f64; 3], ok: bool) {
    match regular_normal(u, v) {
        Some(r) => {
            assert!(ok, "{u} × {v} is regular");
            assert_eq!(r.to_array().map(f64::to_bits), n.map(f64::to_bits));
        }
        None => assert!(!ok, "{u} × {v} is degenerate"),
    }
}
