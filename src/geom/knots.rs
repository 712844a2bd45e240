//! Knot vectors: validation, standard constructors, span search and multiplicity.
//!
//! Conventions (docs/scene-format.md): a degree-d B-spline with n control points has n+d+1
//! non-decreasing knots and domain [t_d, t_n]; the parameter t_n belongs to the last non-empty span.

use super::error::{GeomError, GeomResult};
use std::ops::Deref;

/// A validated, non-decreasing sequence of finite knots.
#[derive(Debug, Clone, PartialEq)]
pub struct KnotVector(Vec<f64>);

impl Deref for KnotVector {
    type Target = [f64];
    fn deref(&self) -> &[f64] {
        &self.0
    }
}

impl KnotVector {
    /// Accepts any finite, non-decreasing sequence.
    pub fn new(knots: Vec<f64>) -> GeomResult<Self> {
        for (i, &t) in knots.iter().enumerate() {
            if !t.is_finite() {
                return Err(GeomError::new(
                    "knots",
                    format!("knot {i} is {t}, not a finite number"),
                ));
            }
            if i > 0 && t < knots[i - 1] {
                return Err(GeomError::new(
                    "knots",
                    format!(
                        "knot {i} ({t}) is smaller than knot {} ({}): knots must be non-decreasing",
                        i - 1,
                        knots[i - 1]
                    ),
                ));
            }
        }
        Ok(Self(knots))
    }

    /// Validates `knots` for a B-spline of `degree` with `n` control points: n+d+1 knots, no knot
    /// of multiplicity above d+1 (its basis function would vanish identically), and a non-empty
    /// domain [t_d, t_n].
    pub fn for_bspline(knots: Vec<f64>, degree: usize, n: usize) -> GeomResult<Self> {
        if n <= degree {
            return Err(GeomError::new(
                "degree",
                format!(
                    "degree {degree} needs at least {} control points, got {n}",
                    degree + 1
                ),
            ));
        }
        if knots.len() != n + degree + 1 {
            return Err(GeomError::new(
                "knots",
                format!(
                    "expected {} knots (points + degree + 1 = {n} + {degree} + 1), got {}",
                    n + degree + 1,
                    knots.len()
                ),
            ));
        }
        let kv = Self::new(knots)?;
        let mut start = 0;
        while start < kv.len() {
            let mut end = start;
            while end + 1 < kv.len() && kv[end + 1] == kv[start] {
                end += 1;
            }
            let mult = end - start + 1;
            if mult > degree + 1 {
                return Err(GeomError::new(
                    "knots",
                    format!(
                        "knot value {} at indices {start}..={end} has multiplicity {mult}, more than degree + 1 = {}",
                        kv[start],
                        degree + 1
                    ),
                ));
            }
            start = end + 1;
        }
        if kv[degree] >= kv[n] {
            return Err(GeomError::new(
                "knots",
                format!(
                    "empty domain: knot {degree} ({}) must be smaller than knot {n} ({})",
                    kv[degree], kv[n]
                ),
            ));
        }
        Ok(kv)
    }

    /// Clamped (open) knot vector with uniformly spaced interior knots over [a, b].
    #[must_use]
    pub fn clamped_uniform(degree: usize, n: usize, a: f64, b: f64) -> Self {
        assert!(
            n > degree && a < b,
            "clamped_uniform needs n > degree and a < b"
        );
        let spans = n - degree;
        let mut t = Vec::with_capacity(n + degree + 1);
        t.extend(std::iter::repeat_n(a, degree + 1));
        for i in 1..spans {
            t.push(a + (b - a) * (i as f64 / spans as f64));
        }
        t.extend(std::iter::repeat_n(b, degree + 1));
        Self(t)
    }

    /// Uniform (unclamped) knot vector t_i = a + i·(b−a)/(n+d), i = 0..=n+d.
    #[must_use]
    pub fn uniform(degree: usize, n: usize, a: f64, b: f64) -> Self {
        assert!(n > degree && a < b, "uniform needs n > degree and a < b");
        let last = n + degree;
        Self(
            (0..=last)
                .map(|i| {
                    if i == last {
                        b
                    } else {
                        a + (b - a) * (i as f64 / last as f64)
                    }
                })
                .collect(),
        )
    }

    /// The Bézier knot vector {a^(d+1), b^(d+1)}: a single span on which the B-spline basis is
    /// the Bernstein basis on [a, b].
    #[must_use]
    pub fn bezier(degree: usize, a: f64, b: f64) -> Self {
        let mut t = vec![a; degree + 1];
        t.extend(std::iter::repeat_n(b, degree + 1));
        Self(t)
    }

    #[must_use]
    pub fn as_slice(&self) -> &[f64] {
        &self.0
    }

    #[must_use]
    pub fn into_vec(self) -> Vec<f64> {
        self.0
    }

    /// Parameter domain [t_d, t_n] of a degree-d B-spline with n control points.
    #[must_use]
    pub fn domain(&self, degree: usize, n: usize) -> (f64, f64) {
        (self.0[degree], self.0[n])
    }

    /// FindSpan (NURBS Book A2.1): the index i with t_i ≤ t < t_{i+1}, d ≤ i ≤ n−1. Parameters
    /// at or beyond t_n map to the last non-empty span, parameters below t_d to the first.
    #[must_use]
    pub fn find_span(&self, degree: usize, n: usize, t: f64) -> usize {
        let k = &self.0;
        if t >= k[n] {
            let mut i = n - 1;
            while i > degree && k[i] == k[i + 1] {
                i -= 1;
            }
            return i;
        }
        let t = if t < k[degree] { k[degree] } else { t };
        // Invariant: k[lo] <= t < k[hi].
        let (mut lo, mut hi) = (degree, n);
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if t < k[mid] {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        lo
    }

    /// Number of knots equal to `t`.
    #[must_use]
    pub fn multiplicity(&self, t: f64) -> usize {
        self.0.iter().filter(|&&k| k == t).count()
    }

    /// Distinct knot values in the closed interval [a, b], in increasing order.
    #[must_use]
    pub fn breakpoints(&self, a: f64, b: f64) -> Vec<f64> {
        let mut out: Vec<f64> = Vec::new();
        for &t in &self.0 {
            if t >= a && t <= b && out.last() != Some(&t) {
                out.push(t);
            }
        }
        out
    }
}

/// `m` sample parameters uniformly over [a, b], both ends included exactly
/// (docs/scene-format.md: samples).
#[must_use]
pub fn uniform_params(a: f64, b: f64, m: usize) -> Vec<f64> {
    assert!(
        m >= 2,
        "at least two samples are needed to include both ends"
    );
    let last = m - 1;
    (0..m)
        .map(|j| {
            if j == last {
                b
            } else {
                a + (b - a) * (j as f64 / last as f64)
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn paper() -> KnotVector {
        let t = vec![0., 0., 0., 0., 1., 2., 3., 4., 5., 6., 7., 7., 7., 7.];
        KnotVector::for_bspline(t, 3, 10).unwrap()
    }

    #[test]
    fn find_span_follows_right_continuity_and_clamps_the_end() {
        let k = paper();
        assert_eq!(k.find_span(3, 10, 0.0), 3);
        assert_eq!(k.find_span(3, 10, 0.5), 3);
        assert_eq!(k.find_span(3, 10, 1.0), 4);
        assert_eq!(k.find_span(3, 10, 6.999), 9);
        assert_eq!(k.find_span(3, 10, 7.0), 9);
        assert_eq!(k.find_span(3, 10, 8.0), 9);
        assert_eq!(k.find_span(3, 10, -1.0), 3);
    }

    #[test]
    fn find_span_skips_empty_spans_at_repeated_knots() {
        let k = KnotVector::for_bspline(vec![0., 0., 0., 1., 1., 2., 2., 2.], 2, 5).unwrap();
        assert_eq!(k.find_span(2, 5, 1.0), 4);
        assert_eq!(k.find_span(2, 5, 0.999), 2);
        assert_eq!(k.find_span(2, 5, 2.0), 4);
        // Unclamped end with repeated last interior knot: t_n belongs to the last non-empty span.
        let k = KnotVector::for_bspline(vec![0., 1., 2., 3., 3., 4., 5.], 2, 4).unwrap();
        assert_eq!(k.find_span(2, 4, 3.0), 2);
    }

    #[test]
    fn multiplicity_and_breakpoints() {
        let k = paper();
        assert_eq!(k.multiplicity(0.0), 4);
        assert_eq!(k.multiplicity(3.0), 1);
        assert_eq!(k.multiplicity(3.5), 0);
        assert_eq!(k.breakpoints(0.0, 7.0).len(), 8);
    }

    #[test]
    fn validation_messages_name_the_problem() {
        let e = KnotVector::for_bspline(vec![0., 0., 1., 1.], 1, 3).unwrap_err();
        assert_eq!(e.field, "knots");
        assert!(e.message.contains("expected 5 knots"), "{e}");
        let e = KnotVector::for_bspline(vec![0., 0., 2., 1., 3.], 1, 3).unwrap_err();
        assert!(
            e.message.contains("knot 3 (1) is smaller than knot 2 (2)"),
            "{e}"
        );
        let e = KnotVector::for_bspline(vec![0., 0., f64::NAN, 1., 3.], 1, 3).unwrap_err();
        assert!(e.message.contains("knot 2 is NaN"), "{e}");
        let e = KnotVector::for_bspline(vec![0., 1., 1., 1., 2.], 1, 3).unwrap_err();
        assert!(e.message.contains("multiplicity 3"), "{e}");
        let e = KnotVector::for_bspline(vec![0., 1., 1., 2.], 3, 0).unwrap_err();
        assert_eq!(e.field, "degree");
        let e = KnotVector::for_bspline(vec![0., 1., 1., 1., 1., 2.], 2, 3).unwrap_err();
        assert!(e.message.contains("multiplicity 4"), "{e}");
    }

    #[test]
    fn empty_domain_is_rejected() {
        let e = KnotVector::for_bspline(vec![0., 0., 0., 0., 1., 1.], 2, 3).unwrap_err();
        assert!(e.message.contains("multiplicity 4"), "{e}");
        let e = KnotVector::for_bspline(vec![0., 1., 1., 1., 5.], 2, 2).unwrap_err();
        assert_eq!(e.field, "degree", "{e}");
    }

    #[test]
    fn constructors() {
        let k = KnotVector::clamped_uniform(3, 10, 0.0, 7.0);
        assert_eq!(k.as_slice(), paper().as_slice());
        let k = KnotVector::uniform(3, 4, 0.0, 7.0);
        assert_eq!(k.as_slice(), &[0., 1., 2., 3., 4., 5., 6., 7.]);
        assert_eq!(
            KnotVector::bezier(2, 0.0, 1.0).as_slice(),
            &[0., 0., 0., 1., 1., 1.]
        );
        let p = uniform_params(1.0, 2.0, 5);
        assert_eq!(p, vec![1.0, 1.25, 1.5, 1.75, 2.0]);
    }
}
