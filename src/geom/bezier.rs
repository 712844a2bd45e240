//! Bézier curves, polynomial and rational, on a general parameter interval [a, b].

use super::basis::hermite_into;
use super::bspline::BSplineCurve;
use super::control::{check_points, check_weights, combine_rows};
use super::error::{GeomError, GeomResult};
use super::knots::KnotVector;
use super::point::{Point, homogeneous, rational_curve_derivs};
use glam::{DVec3, DVec4};

/// A Bézier curve C(t) = Σ C_i B^n_i((t−a)/(b−a)), t ∈ [a, b]; with weights it is rational and
/// evaluated in homogeneous coordinates (w_i C_i, w_i).
#[derive(Debug, Clone, PartialEq)]
pub struct BezierCurve {
    points: Vec<DVec3>,
    weights: Option<Vec<f64>>,
    interval: (f64, f64),
}

impl BezierCurve {
    /// A polynomial Bézier curve on [0, 1]. At least one point (degree 0 is a constant curve).
    pub fn new(points: Vec<DVec3>) -> GeomResult<Self> {
        check_points(&points)?;
        Ok(Self {
            points,
            weights: None,
            interval: (0.0, 1.0),
        })
    }

    /// A rational Bézier curve on [0, 1]; weights must be positive and finite.
    pub fn rational(points: Vec<DVec3>, weights: Vec<f64>) -> GeomResult<Self> {
        check_points(&points)?;
        check_weights(&weights, points.len())?;
        Ok(Self {
            points,
            weights: Some(weights),
            interval: (0.0, 1.0),
        })
    }

    /// The same curve reparameterised linearly onto [a, b] (lecture 3.1.2: geometry unchanged,
    /// the k-th derivative scales by (b−a)^−k).
    pub fn with_interval(mut self, a: f64, b: f64) -> GeomResult<Self> {
        if !(a.is_finite() && b.is_finite() && a < b) {
            return Err(GeomError::new(
                "interval",
                format!("[{a}, {b}] is not a finite interval with a < b"),
            ));
        }
        self.interval = (a, b);
        Ok(self)
    }

    #[must_use]
    pub fn degree(&self) -> usize {
        self.points.len() - 1
    }

    #[must_use]
    pub fn points(&self) -> &[DVec3] {
        &self.points
    }

    #[must_use]
    pub fn weights(&self) -> Option<&[f64]> {
        self.weights.as_deref()
    }

    #[must_use]
    pub fn interval(&self) -> (f64, f64) {
        self.interval
    }

    #[must_use]
    pub fn is_rational(&self) -> bool {
        self.weights.is_some()
    }

    /// Moves control point `i` by `delta` (weights unchanged).
    pub fn translate_point(&mut self, i: usize, delta: DVec3) {
        self.points[i] += delta;
    }

    /// Replaces all control points (same count), exactly.
    pub fn set_points(&mut self, points: &[DVec3]) {
        assert_eq!(
            points.len(),
            self.points.len(),
            "set_points keeps the degree"
        );
        self.points.copy_from_slice(points);
    }

    /// Replaces every control point by `f(point)` (weights unchanged), e.g. an affine map.
    pub fn map_points(&mut self, f: impl Fn(DVec3) -> DVec3) {
        for p in &mut self.points {
            *p = f(*p);
        }
    }

    /// Homogeneous control points (w_i C_i, w_i); weight 1 for polynomial curves.
    #[must_use]
    pub fn homogeneous_points(&self) -> Vec<DVec4> {
        homogeneous(&self.points, self.weights.as_deref())
    }

    fn local(&self, t: f64) -> f64 {
        let (a, b) = self.interval;
        (t - a) / (b - a)
    }

    /// C(t) by de Casteljau's algorithm (on homogeneous points when rational).
    #[must_use]
    pub fn eval(&self, t: f64) -> DVec3 {
        let s = self.local(t);
        match &self.weights {
            None => de_casteljau(&self.points, s),
            Some(_) => {
                let h = de_casteljau(&self.homogeneous_points(), s);
                h.truncate() / h.w
            }
        }
    }

    /// C(t), C'(t), …, C^(n)(t) through the Bernstein-Hermite matrix (quotient rule if rational).
    #[must_use]
    pub fn derivatives(&self, t: f64, n: usize) -> Vec<DVec3> {
        let d = self.degree();
        let (a, b) = self.interval;
        let knots = KnotVector::bezier(d, a, b);
        let mut m = vec![0.0; (d + 1) * (d + 1)];
        hermite_into(&knots, d, d, t.clamp(a, b), &mut m);
        match &self.weights {
            None => combine_rows(&m, d, &self.points, n),
            Some(_) => {
                let h = combine_rows(&m, d, &self.homogeneous_points(), n);
                let mut out = vec![DVec3::ZERO; n + 1];
                rational_curve_derivs(&h, &mut out);
                out
            }
        }
    }

    /// Subdivision at parameter t (lecture 3.1, de Casteljau): the two pieces on [a, t] and
    /// [t, b], each with its own interval, describing the same curve.
    pub fn subdivide(&self, t: f64) -> GeomResult<(BezierCurve, BezierCurve)> {
        let (a, b) = self.interval;
        if !(t > a && t < b) {
            return Err(GeomError::new(
                "parameter",
                format!("{t} is not inside ({a}, {b})"),
            ));
        }
        let s = self.local(t);
        let (l, r) = split_de_casteljau(&self.homogeneous_points(), s);
        let left = self.with_homogeneous(l, (a, t));
        let right = self.with_homogeneous(r, (t, b));
        Ok((left, right))
    }

    /// Degree elevation by one: the same curve with one more control point,
    /// Q_i = i/(n+1) P_{i−1} + (1 − i/(n+1)) P_i (in homogeneous space when rational).
    #[must_use]
    pub fn elevate_degree(&self) -> BezierCurve {
        let p = self.homogeneous_points();
        let n = p.len() - 1;
        let mut q = Vec::with_capacity(n + 2);
        q.push(p[0]);
        for i in 1..=n {
            let a = i as f64 / (n + 1) as f64;
            q.push(p[i - 1] * a + p[i] * (1.0 - a));
        }
        q.push(p[n]);
        self.with_homogeneous(q, self.interval)
    }

    /// The hodograph C'(t) as a Bézier curve of one degree less (polynomial curves only):
    /// n/(b−a) (P_{i+1} − P_i).
    #[must_use]
    pub fn hodograph(&self) -> Option<BezierCurve> {
        if self.is_rational() || self.points.len() < 2 {
            return None;
        }
        let n = self.degree() as f64;
        let (a, b) = self.interval;
        let pts = self
            .points
            .windows(2)
            .map(|w| (w[1] - w[0]) * (n / (b - a)))
            .collect();
        Some(BezierCurve {
            points: pts,
            weights: None,
            interval: self.interval,
        })
    }

    /// The same curve as a B-spline with the Bézier knot vector {a^(n+1), b^(n+1)}.
    #[must_use]
    pub fn to_bspline(&self) -> BSplineCurve {
        let (a, b) = self.interval;
        let knots = KnotVector::bezier(self.degree(), a, b);
        BSplineCurve::from_parts(
            self.degree(),
            knots,
            self.points.clone(),
            self.weights.clone(),
        )
    }

    fn with_homogeneous(&self, h: Vec<DVec4>, interval: (f64, f64)) -> BezierCurve {
        let rational = self.is_rational();
        let points = h.iter().map(|p| p.truncate() / p.w).collect();
        let weights = rational.then(|| h.iter().map(|p| p.w).collect());
        BezierCurve {
            points,
            weights,
            interval,
        }
    }
}

/// de Casteljau's algorithm: repeated affine combinations C^{k+1}_i = (1−s)C^k_i + s C^k_{i+1}.
pub fn de_casteljau<P: Point>(points: &[P], s: f64) -> P {
    let mut c = points.to_vec();
    let n = c.len();
    for k in 1..n {
        for i in 0..n - k {
            c[i] = c[i] * (1.0 - s) + c[i + 1] * s;
        }
    }
    c[0]
}

/// Both halves of de Casteljau's triangle: the left edge and the right edge.
fn split_de_casteljau<P: Point>(points: &[P], s: f64) -> (Vec<P>, Vec<P>) {
    let mut c = points.to_vec();
    let n = c.len();
    let mut left = Vec::with_capacity(n);
    let mut right = vec![P::default(); n];
    left.push(c[0]);
    right[n - 1] = c[n - 1];
    for k in 1..n {
        for i in 0..n - k {
            c[i] = c[i] * (1.0 - s) + c[i + 1] * s;
        }
        left.push(c[0]);
        right[n - 1 - k] = c[n - 1 - k];
    }
    (left, right)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lecture() -> BezierCurve {
        BezierCurve::new(vec![
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(1.0, 10.0, 0.0),
            DVec3::new(10.0, 10.0, 0.0),
            DVec3::new(10.0, 1.0, 0.0),
        ])
        .unwrap()
    }

    #[test]
    fn lecture_de_casteljau_example() {
        let c = lecture();
        let p = c.eval(1.0 / 3.0);
        assert!((p - DVec3::new(10.0 / 3.0, 7.0, 0.0)).max_abs() < 1e-14);
        let d = c.derivatives(1.0 / 3.0, 1);
        assert!((d[0] - p).max_abs() < 1e-14);
        assert!((d[1] - DVec3::new(12.0, 9.0, 0.0)).max_abs() < 1e-13);
    }

    #[test]
    fn quarter_circle_is_exact() {
        let w = std::f64::consts::FRAC_1_SQRT_2;
        let c = BezierCurve::rational(
            vec![DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y],
            vec![1.0, w, 1.0],
        )
        .unwrap();
        for i in 0..=20 {
            let t = i as f64 / 20.0;
            let d = c.derivatives(t, 2);
            assert!((d[0].length() - 1.0).abs() < 1e-15, "radius at {t}");
            assert!(d[0].dot(d[1]).abs() < 1e-14, "tangent ⟂ radius at {t}");
            assert!((d[0] - c.eval(t)).length() < 1e-15);
        }
    }

    #[test]
    fn subdivision_elevation_and_interval_preserve_the_curve() {
        let w = [1.0, 0.5, 2.0, 1.3];
        let c = BezierCurve::rational(lecture().points().to_vec(), w.to_vec()).unwrap();
        let (l, r) = c.subdivide(0.3).unwrap();
        for i in 0..=10 {
            let t = i as f64 / 10.0;
            let (tl, tr) = (0.3 * t, 0.3 + 0.7 * t);
            assert!((l.eval(tl) - c.eval(tl)).length() < 1e-13);
            assert!((r.eval(tr) - c.eval(tr)).length() < 1e-13);
            let dl = l.derivatives(tl, 2);
            let dc = c.derivatives(tl, 2);
            assert!((dl[2] - dc[2]).length() < 1e-10 * dc[2].length().max(1.0));
        }
        let e = c.elevate_degree();
        assert_eq!(e.degree(), 4);
        let moved = lecture().with_interval(2.0, 5.0).unwrap();
        for i in 0..=10 {
            let t = i as f64 / 10.0;
            assert!((e.eval(t) - c.eval(t)).length() < 1e-13);
            let a = moved.derivatives(2.0 + 3.0 * t, 2);
            let b = lecture().derivatives(t, 2);
            assert!((a[0] - b[0]).length() < 1e-13);
            assert!((a[1] * 3.0 - b[1]).length() < 1e-12);
            assert!((a[2] * 9.0 - b[2]).length() < 1e-11);
        }
        let h = lecture().hodograph().unwrap();
        assert!((h.eval(1.0 / 3.0) - DVec3::new(12.0, 9.0, 0.0)).length() < 1e-13);
    }

    #[test]
    fn bad_input_is_reported() {
        assert_eq!(BezierCurve::new(vec![]).unwrap_err().field, "points");
        let e = BezierCurve::rational(vec![DVec3::ZERO; 2], vec![1.0, -1.0]).unwrap_err();
        assert!(e.message.contains("weight 1 is -1"), "{e}");
        let e = BezierCurve::new(vec![DVec3::new(0.0, f64::NAN, 0.0)]).unwrap_err();
        assert!(e.message.contains("point 0"), "{e}");
    }
}
