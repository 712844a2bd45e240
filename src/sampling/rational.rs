//! The quotient rule for rational samples, precomputed for a partial set.

use super::grid::PartialSet;
use crate::geom::point::binomial;
use glam::{DVec3, DVec4};

/// Projects homogeneous partials of (w·S, w) to Euclidean partials of S for any downward-closed
/// partial set: ∂^{kl}S = (∂^{kl}(wS) − Σ_{(i,j)≠(0,0)} C(k,i)C(l,j) ∂^{ij}w ∂^{k−i,l−j}S) / w
/// (NURBS Book A4.2/A4.4). The (coefficient, w-slot, S-slot) terms are found once per set.
#[derive(Debug, Clone)]
pub struct QuotientRule {
    terms: Vec<Vec<(f64, usize, usize)>>,
}

impl QuotientRule {
    #[must_use]
    pub fn new(set: &PartialSet) -> Self {
        let list = set.list();
        let slot = |a: usize, b: usize| {
            list.iter()
                .position(|&p| p == (a, b))
                .expect("downward-closed set")
        };
        let terms = list
            .iter()
            .map(|&(k, l)| {
                let mut t = Vec::new();
                for i in 0..=k {
                    for j in 0..=l {
                        if (i, j) != (0, 0) {
                            t.push((
                                binomial(k, i) * binomial(l, j),
                                slot(i, j),
                                slot(k - i, l - j),
                            ));
                        }
                    }
                }
                t
            })
            .collect();
        Self { terms }
    }

    /// `h` and `out` hold one sample's partials in set order.
    #[inline]
    pub fn project(&self, h: &[DVec4], out: &mut [DVec3]) {
        let inv_w = 1.0 / h[0].w;
        for (p, terms) in self.terms.iter().enumerate() {
            let mut v = h[p].truncate();
            for &(c, iw, is) in terms {
                v -= out[is] * (c * h[iw].w);
            }
            out[p] = v * inv_w;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::point::rational_curve_derivs;

    #[test]
    fn matches_the_curve_rule() {
        let h = [
            DVec4::new(1.0, 2.0, 3.0, 0.7),
            DVec4::new(-0.5, 0.3, 1.0, 0.2),
            DVec4::new(0.1, -2.0, 0.4, -0.3),
        ];
        let mut a = [DVec3::ZERO; 3];
        let mut b = [DVec3::ZERO; 3];
        rational_curve_derivs(&h, &mut a);
        QuotientRule::new(&PartialSet::Curve(2)).project(&h, &mut b);
        for r in 0..3 {
            assert!((a[r] - b[r]).length() < 1e-14);
        }
    }
}
