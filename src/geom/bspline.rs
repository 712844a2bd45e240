//! B-spline curves and NURBS.

use super::basis::hermite_into;
use super::control::{check_points, check_weights, combine_rows};
use super::error::{GeomError, GeomResult};
use super::knots::KnotVector;
use super::point::{Point, homogeneous, rational_curve_derivs};
use super::refine::{HomSpline, curve_knot_ins, degree_elevate};
use glam::{DVec3, DVec4};

/// c(t) = Σ c_i b_{d,i}(t) on [t_d, t_n]; with weights a NURBS curve evaluated in homogeneous
/// coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct BSplineCurve {
    degree: usize,
    knots: KnotVector,
    points: Vec<DVec3>,
    weights: Option<Vec<f64>>,
}

impl BSplineCurve {
    /// Validates degree, knots (n+d+1, non-decreasing, multiplicity ≤ d+1, non-empty domain),
    /// points and weights.
    pub fn new(
        degree: usize,
        knots: Vec<f64>,
        points: Vec<DVec3>,
        weights: Option<Vec<f64>>,
    ) -> GeomResult<Self> {
        check_points(&points)?;
        let knots = KnotVector::for_bspline(knots, degree, points.len())?;
        if let Some(w) = &weights {
            check_weights(w, points.len())?;
        }
        Ok(Self {
            degree,
            knots,
            points,
            weights,
        })
    }

    /// Assembles already-validated parts.
    pub(crate) fn from_parts(
        degree: usize,
        knots: KnotVector,
        points: Vec<DVec3>,
        weights: Option<Vec<f64>>,
    ) -> Self {
        debug_assert_eq!(knots.len(), points.len() + degree + 1);
        Self {
            degree,
            knots,
            points,
            weights,
        }
    }

    #[must_use]
    pub fn degree(&self) -> usize {
        self.degree
    }

    #[must_use]
    pub fn knots(&self) -> &KnotVector {
        &self.knots
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
    pub fn is_rational(&self) -> bool {
        self.weights.is_some()
    }

    /// [t_d, t_n].
    #[must_use]
    pub fn domain(&self) -> (f64, f64) {
        self.knots.domain(self.degree, self.points.len())
    }

    /// FindSpan for this curve.
    #[must_use]
    pub fn find_span(&self, t: f64) -> usize {
        self.knots.find_span(self.degree, self.points.len(), t)
    }

    /// Translates control point `i` (its weight is unchanged).
    pub fn translate_point(&mut self, i: usize, delta: DVec3) {
        self.points[i] += delta;
    }

    /// Sets control point `i` exactly (undo restores values bit for bit).
    pub fn set_point(&mut self, i: usize, p: DVec3) {
        self.points[i] = p;
    }

    /// Replaces every control point by `f(point)` (weights unchanged), e.g. an affine map.
    pub fn map_points(&mut self, f: impl Fn(DVec3) -> DVec3) {
        for p in &mut self.points {
            *p = f(*p);
        }
    }

    /// Replaces all control points (same count), exactly.
    pub fn set_points(&mut self, points: &[DVec3]) {
        self.points.copy_from_slice(points);
    }

    /// The same curve with its parameter mapped affinely so that the domain becomes [a, b]:
    /// knots t ↦ a + (t − t_d)(b − a)/(t_n − t_d), the domain's ends exactly. The k-th
    /// derivative scales by the inverse factor's k-th power; the shape is unchanged.
    pub fn reparametrized(&self, (a, b): (f64, f64)) -> GeomResult<Self> {
        let (d0, d1) = self.domain();
        if !(a.is_finite() && b.is_finite() && a < b) {
            return Err(GeomError::new(
                "interval",
                format!("[{a}, {b}] is not a finite interval with a < b"),
            ));
        }
        let scale = (b - a) / (d1 - d0);
        self.with_knots_mapped(|t| match t {
            t if t == d0 => a,
            t if t == d1 => b,
            t => a + (t - d0) * scale,
        })
    }

    /// The same control points on knots mapped by an increasing `f` (a reparametrisation).
    pub fn with_knots_mapped(&self, f: impl Fn(f64) -> f64) -> GeomResult<Self> {
        let mut c = self.clone();
        c.knots = KnotVector::new(self.knots.iter().map(|&t| f(t)).collect())?;
        Ok(c)
    }

    /// Sets weight `i`, making the curve rational (other weights 1) if it was not.
    pub fn set_weight(&mut self, i: usize, w: f64) {
        let n = self.points.len();
        self.weights.get_or_insert_with(|| vec![1.0; n])[i] = w;
    }

    /// Homogeneous control points (w_i c_i, w_i); weight 1 for polynomial curves.
    #[must_use]
    pub fn homogeneous_points(&self) -> Vec<DVec4> {
        homogeneous(&self.points, self.weights.as_deref())
    }

    /// c(t) by de Boor's algorithm.
    #[must_use]
    pub fn eval(&self, t: f64) -> DVec3 {
        match &self.weights {
            None => de_boor(&self.knots, self.degree, &self.points, t),
            Some(_) => {
                let h = de_boor(&self.knots, self.degree, &self.homogeneous_points(), t);
                h.truncate() / h.w
            }
        }
    }

    /// c(t), c'(t), …, c^(n)(t) through the B-spline-Hermite matrix M_{d,i}(t) (at a knot: the
    /// right limit, as FindSpan gives).
    #[must_use]
    pub fn derivatives(&self, t: f64, n: usize) -> Vec<DVec3> {
        self.one_sided_derivatives(t, n, false)
    }

    /// Limits of c, c', …, c^(n) as the parameter approaches t from the left (`from_left`) or
    /// the right: the polynomial of the span on that side evaluated at t. At an interior knot of
    /// multiplicity m the two differ from order d − m + 1 on in general; elsewhere they agree.
    #[must_use]
    pub fn one_sided_derivatives(&self, t: f64, n: usize, from_left: bool) -> Vec<DVec3> {
        let d = self.degree;
        let (a, b) = self.domain();
        let t = t.clamp(a, b);
        let span = if from_left && t > a {
            // The last span [t_i, t_{i+1}) with t_i < t.
            (self.knots.partition_point(|&k| k < t) - 1).max(d)
        } else {
            self.find_span(t)
        };
        let mut m = vec![0.0; (d + 1) * (d + 1)];
        hermite_into(&self.knots, d, span, t, &mut m);
        let first = span - d;
        match &self.weights {
            None => combine_rows(&m, d, &self.points[first..=span], n),
            Some(_) => {
                let h = self.homogeneous_points();
                let hd = combine_rows(&m, d, &h[first..=span], n);
                let mut out = vec![DVec3::ZERO; n + 1];
                rational_curve_derivs(&hd, &mut out);
                out
            }
        }
    }

    /// The same derivatives by a second, independent route: derivative control points
    /// (CurveDerivCpts, NURBS Book A3.3) evaluated with de Boor's algorithm. Slower; used to
    /// cross-check the Hermite path.
    #[must_use]
    pub fn derivatives_de_boor(&self, t: f64, n: usize) -> Vec<DVec3> {
        match &self.weights {
            None => derivs_by_control_points(&self.knots, self.degree, &self.points, t, n),
            Some(_) => {
                let h = self.homogeneous_points();
                let hd = derivs_by_control_points(&self.knots, self.degree, &h, t, n);
                let mut out = vec![DVec3::ZERO; n + 1];
                rational_curve_derivs(&hd, &mut out);
                out
            }
        }
    }

    /// CurveKnotIns (NURBS Book A5.1, Böhm): inserts `t` `times` times; the curve is unchanged.
    /// `t` must lie in [t_d, t_n) and the final multiplicity may not exceed the degree.
    pub fn insert_knot(&self, t: f64, times: usize) -> GeomResult<Self> {
        let (a, b) = self.domain();
        if !(t >= a && t < b) {
            return Err(GeomError::new(
                "parameter",
                format!("{t} is not in [{a}, {b})"),
            ));
        }
        if times == 0 {
            return Ok(self.clone());
        }
        let p = self.degree;
        let s = self.knots.multiplicity(t);
        if s + times > p {
            return Err(GeomError::new(
                "parameter",
                format!(
                    "inserting {t} {times} times would give multiplicity {} > degree {p}",
                    s + times
                ),
            ));
        }
        let r = curve_knot_ins(&self.homogeneous_spline(), t, times);
        Ok(self.with_homogeneous(KnotVector::new(r.knots)?, r.points))
    }

    /// DegreeElevateCurve (NURBS Book A5.9): the same curve of degree d + `by`; every knot keeps
    /// its continuity (its multiplicity grows by `by`). An unclamped curve comes back clamped
    /// on its domain.
    pub fn elevate_degree(&self, by: usize) -> GeomResult<Self> {
        let e = degree_elevate(&self.homogeneous_spline(), by);
        Ok(self.with_homogeneous(KnotVector::new(e.knots)?, e.points))
    }

    /// Degree, knots and homogeneous control points, for the refinement algorithms.
    pub(crate) fn homogeneous_spline(&self) -> HomSpline {
        HomSpline {
            degree: self.degree,
            knots: self.knots.to_vec(),
            points: self.homogeneous_points(),
        }
    }

    /// Splits at an interior parameter into two curves meeting at c(t); knots are inserted until
    /// t has multiplicity d, then the knot vector is cut with t repeated d+1 times on each side.
    pub fn split(&self, t: f64) -> GeomResult<(Self, Self)> {
        let (a, b) = self.domain();
        if !(t > a && t < b) {
            return Err(GeomError::new(
                "parameter",
                format!("{t} is not inside ({a}, {b})"),
            ));
        }
        let p = self.degree;
        if p == 0 {
            // Piecewise constant: the span holding t is simply cut in two.
            let k = self.find_span(t);
            let u = &self.knots;
            let mut lk = u[..=k].to_vec();
            lk.push(t);
            let mut rk = vec![t];
            rk.extend_from_slice(&u[k + 1..]);
            let q = self.homogeneous_points();
            let left = self.with_homogeneous(KnotVector::new(lk)?, q[..=k].to_vec());
            let right = self.with_homogeneous(KnotVector::new(rk)?, q[k..].to_vec());
            return Ok((left, right));
        }
        let s = self.knots.multiplicity(t);
        let c = if s < p {
            self.insert_knot(t, p - s)?
        } else {
            self.clone()
        };
        let u = &c.knots;
        let Some(first) = u.iter().position(|&x| x == t) else {
            return Err(GeomError::new("parameter", format!("cannot split at {t}")));
        };
        let q = c.homogeneous_points();
        // With multiplicity p the curve interpolates q[first−1]; with p+1 (a jump) the left piece
        // ends with q[first−1] and the right one starts with q[first].
        let mult = c.knots.multiplicity(t);
        let right_start = if mult == p + 1 { first } else { first - 1 };
        let mut lk = u[..first].to_vec();
        lk.extend(std::iter::repeat_n(t, p + 1));
        let mut rk = vec![t; p + 1];
        rk.extend_from_slice(&u[first + mult..]);
        let left = c.with_homogeneous(KnotVector::new(lk)?, q[..first].to_vec());
        let right = c.with_homogeneous(KnotVector::new(rk)?, q[right_start..].to_vec());
        Ok((left, right))
    }

    fn with_homogeneous(&self, knots: KnotVector, q: Vec<DVec4>) -> Self {
        let points = q.iter().map(|h| h.truncate() / h.w).collect();
        let weights = self.is_rational().then(|| q.iter().map(|h| h.w).collect());
        let degree = knots.len() - q.len() - 1;
        Self::from_parts(degree, knots, points, weights)
    }
}

/// de Boor's algorithm on the active control points of span k.
pub fn de_boor<P: Point>(knots: &KnotVector, degree: usize, points: &[P], t: f64) -> P {
    let p = degree;
    let n = points.len();
    let k = knots.find_span(p, n, t);
    let (a, b) = knots.domain(p, n);
    let t = t.clamp(a, b);
    let mut d: Vec<P> = points[k - p..=k].to_vec();
    for r in 1..=p {
        for j in (r..=p).rev() {
            let lo = knots[j + k - p];
            let alpha = (t - lo) / (knots[j + 1 + k - r] - lo);
            d[j] = d[j - 1] * (1.0 - alpha) + d[j] * alpha;
        }
    }
    d[p]
}

/// Derivatives via derivative control points: the k-th derivative curve has degree d−k, knots
/// t_k … t_{m−k} and points (d−k+1)(Q_{i+1} − Q_i)/(t_{i+d+1} − t_{i+k}).
fn derivs_by_control_points<P: Point>(
    knots: &KnotVector,
    degree: usize,
    points: &[P],
    t: f64,
    n: usize,
) -> Vec<P> {
    let mut out = vec![P::default(); n + 1];
    let mut q = points.to_vec();
    for (k, o) in out.iter_mut().enumerate().take(n.min(degree) + 1) {
        if k > 0 {
            let deg = degree - k + 1;
            q = (0..q.len() - 1)
                .map(|i| {
                    let den = knots[i + degree + 1] - knots[i + k];
                    if den == 0.0 {
                        P::default()
                    } else {
                        (q[i + 1] - q[i]) * (deg as f64 / den)
                    }
                })
                .collect();
        }
        let sub =
            KnotVector::new(knots[k..knots.len() - k].to_vec()).expect("sub-vector of valid knots");
        *o = de_boor(&sub, degree - k, &q, t);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lecture_points() -> Vec<DVec3> {
        vec![
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(1.0, 10.0, 0.0),
            DVec3::new(10.0, 10.0, 0.0),
            DVec3::new(10.0, 1.0, 0.0),
        ]
    }

    #[test]
    fn lecture_uniform_cubic_de_boor() {
        let c =
            BSplineCurve::new(3, (0..8).map(f64::from).collect(), lecture_points(), None).unwrap();
        let expect = DVec3::new(79.0 / 18.0, 171.0 / 18.0, 0.0);
        assert!((c.eval(10.0 / 3.0) - expect).length() < 1e-14);
        assert!((c.derivatives(10.0 / 3.0, 0)[0] - expect).length() < 1e-14);
    }

    fn wavy(weights: bool) -> BSplineCurve {
        let pts: Vec<DVec3> = (0..9)
            .map(|i| DVec3::new(i as f64, (i as f64 * 1.3).sin() * 3.0, (i * i) as f64 * 0.1))
            .collect();
        let knots = vec![0., 0., 0., 0., 0.5, 1.5, 1.5, 2.0, 3.0, 4.0, 4.0, 4.0, 4.0];
        let w = weights.then(|| (0..9).map(|i| 0.5 + (i % 3) as f64).collect());
        BSplineCurve::new(3, knots, pts, w).unwrap()
    }

    #[test]
    fn hermite_and_de_boor_paths_agree() {
        for rational in [false, true] {
            let c = wavy(rational);
            for i in 0..=40 {
                let t = 4.0 * i as f64 / 40.0;
                let a = c.derivatives(t, 4);
                let b = c.derivatives_de_boor(t, 4);
                assert!((a[0] - c.eval(t)).length() < 1e-13);
                for r in 0..=4 {
                    let tol = 1e-11 * (1.0 + b[r].length());
                    assert!(
                        (a[r] - b[r]).length() < tol,
                        "t={t} r={r}: {:?} vs {:?}",
                        a[r],
                        b[r]
                    );
                }
            }
        }
    }

    #[test]
    fn elevation_clamps_unclamped_curves_and_keeps_jumps() {
        let pts: Vec<DVec3> = (0..7)
            .map(|i| DVec3::new(i as f64, (i as f64).cos(), 0.3 * i as f64))
            .collect();
        let uniform =
            BSplineCurve::new(3, (0..11).map(f64::from).collect(), pts.clone(), None).unwrap();
        let jump = BSplineCurve::new(
            2,
            vec![0., 0., 0., 1., 2., 2., 2., 3., 4., 4., 4.],
            pts.iter().chain(&pts[..1]).copied().collect(),
            Some(vec![1., 2., 0.5, 1., 1., 3., 1., 1.]),
        )
        .unwrap();
        let constant = BSplineCurve::new(0, vec![0., 1., 2., 3.], pts[..3].to_vec(), None).unwrap();
        for c in [uniform, jump, constant] {
            let (a, b) = c.domain();
            for by in [1, 2] {
                let e = c.elevate_degree(by).unwrap();
                assert_eq!(e.domain(), (a, b));
                assert_eq!(e.knots().multiplicity(a), e.degree() + 1);
                for i in 0..=60 {
                    let x = a + (b - a) * i as f64 / 60.0;
                    let (p, q) = (c.eval(x), e.eval(x));
                    assert!(
                        (p - q).length() < 1e-12 * (1.0 + p.length()),
                        "{x}: {p} {q}"
                    );
                }
            }
        }
    }

    #[test]
    fn knot_insertion_and_split_leave_the_curve_unchanged() {
        for rational in [false, true] {
            let c = wavy(rational);
            for (t, times) in [(0.25, 1), (1.5, 1), (0.5, 2), (2.7, 3), (0.0, 0)] {
                let d = c.insert_knot(t, times).unwrap();
                assert_eq!(d.points().len(), c.points().len() + times);
                for i in 0..=50 {
                    let x = 4.0 * i as f64 / 50.0;
                    assert!(
                        (d.eval(x) - c.eval(x)).length() < 1e-12,
                        "insert {t}×{times} at {x}"
                    );
                }
            }
            for t in [0.3, 1.5, 2.0, 3.99] {
                let (l, r) = c.split(t).unwrap();
                assert_eq!(l.domain(), (0.0, t));
                assert_eq!(r.domain(), (t, 4.0));
                for i in 0..=20 {
                    let x = t * i as f64 / 20.0;
                    assert!((l.eval(x) - c.eval(x)).length() < 1e-12);
                    let y = t + (4.0 - t) * i as f64 / 20.0;
                    assert!((r.eval(y) - c.eval(y)).length() < 1e-12);
                }
            }
            for by in [1, 2, 3] {
                let e = c.elevate_degree(by).unwrap();
                assert_eq!(e.degree(), c.degree() + by);
                // Clamped, 4 distinct interior breakpoints (0.5, 1.5 twice, 2, 3): every knot's
                // multiplicity grows by `by`.
                for (t, m) in [(0.0, 4), (0.5, 1), (1.5, 2), (2.0, 1), (3.0, 1), (4.0, 4)] {
                    assert_eq!(e.knots().multiplicity(t), m + by, "by {by}: knot {t}");
                }
                assert_eq!(e.points().len(), c.points().len() + by * 5);
                for i in 0..=80 {
                    let x = 4.0 * i as f64 / 80.0;
                    let (a, b) = (c.derivatives(x, 2), e.derivatives(x, 2));
                    for r in 0..3 {
                        assert!(
                            (a[r] - b[r]).length() < 1e-11 * (1.0 + a[r].length()),
                            "elevate {by} at {x} r={r}: {:?} vs {:?}",
                            a[r],
                            b[r]
                        );
                    }
                }
            }
            assert!(c.insert_knot(1.5, 2).is_err());
            assert!(c.insert_knot(0.0, 1).is_err());
            assert!(c.split(0.0).is_err());
        }
    }
}
