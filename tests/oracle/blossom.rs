//! Knot insertion and degree elevation by blossoming (polar forms), written from the contract
//! only and sharing nothing with the product's Böhm insertion (NURBS Book A5.1/A5.3) or its
//! Bézier-decomposition elevation (A5.9/A5.10).
//!
//! The polynomial piece of a degree-p B-spline on a non-empty span [t_s, t_{s+1}) has a unique
//! blossom f_s(u_1, …, u_p): symmetric, multi-affine, and equal to the piece on its diagonal.
//! It is evaluated by a de Boor triangle that uses a different argument on each level. Two
//! facts do all the work:
//!
//! * (de Boor–Ramshaw) control point j of a spline on knots t is f_s(t_{j+1}, …, t_{j+p}) for
//!   every non-empty span s that P_j's basis function covers. A refined knot vector t' describes
//!   the same pieces, so its control points are the same blossoms at the refined arguments:
//!   Q_k = f_s(t'_{k+1}, …, t'_{k+p}), s any original span under a non-empty refined span in
//!   k..=k+p.
//! * Degree elevation by e: a polynomial of degree p is also one of degree p + e, whose blossom
//!   is the symmetric average of f over the C(p+e, p) ways of choosing p of the p + e arguments.
//!
//! Rational objects are refined in homogeneous coordinates (w·P, w), so `D` is 3 or 4.
//!
//! Blossoms at knots a few spans away from the span extrapolate (affine weights outside
//! [0, 1]), which amplifies rounding; so the triangle runs in double-double arithmetic
//! (Dekker/Knuth error-free sums and FMA products, about 106 bits) and rounds once at the end.
//! The refined nets are then correct to about an ulp, well below what the product is held to.

/// Largest degree the contract allows after elevation.
pub const MAX_DEGREE: usize = 64;

/// A degree-p B-spline with n control points and n + p + 1 knots.
#[derive(Clone, Debug, PartialEq)]
pub struct Spline<const D: usize> {
    pub degree: usize,
    pub knots: Vec<f64>,
    pub points: Vec<[f64; D]>,
}

impl<const D: usize> Spline<D> {
    /// A Bézier curve as the B-spline on [0, 0, …, 1, 1] (each end p + 1 times).
    pub fn bezier(points: &[[f64; D]]) -> Spline<D> {
        let p = points.len() - 1;
        let mut knots = vec![0.0; p + 1];
        knots.extend(std::iter::repeat_n(1.0, p + 1));
        Spline {
            degree: p,
            knots,
            points: points.to_vec(),
        }
    }

    /// The parameter domain [t_p, t_n].
    pub fn domain(&self) -> (f64, f64) {
        (self.knots[self.degree], self.knots[self.points.len()])
    }

    /// How often `t` occurs in the knot vector.
    pub fn multiplicity(&self, t: f64) -> usize {
        self.knots.iter().filter(|&&k| k == t).count()
    }

    /// The original span whose piece covers x ∈ [t_p, t_n): the largest s in p..n with t_s ≤ x
    /// (then t_{s+1} > x, so the span is non-empty).
    fn span_of(&self, x: f64) -> usize {
        let (p, n) = (self.degree, self.points.len());
        (p..n)
            .rev()
            .find(|&s| self.knots[s] <= x)
            .expect("parameter below the domain")
    }

    /// The blossom f_s(args) of the piece on the non-empty span s (p arguments). Level r of
    /// the de Boor triangle uses args[r − 1]:
    ///   d_j^r = d_{j−1}^{r−1} + α (d_j^{r−1} − d_{j−1}^{r−1}),  α = (u_r − t_j)/(t_{j+p+1−r} − t_j),
    /// for s−p+r ≤ j ≤ s.
    pub fn blossom(&self, span: usize, args: &[f64]) -> [f64; D] {
        self.blossom_dd(span, args).map(Dd::round)
    }

    fn blossom_dd(&self, span: usize, args: &[f64]) -> [Dd; D] {
        let p = self.degree;
        assert_eq!(args.len(), p, "a degree-{p} blossom takes {p} arguments");
        assert!(self.knots[span] < self.knots[span + 1], "empty span {span}");
        let t = &self.knots;
        let mut d: Vec<[Dd; D]> = self.points[span - p..=span]
            .iter()
            .map(|x| x.map(Dd::from))
            .collect();
        for (r, &u) in (1..=p).zip(args) {
            // d[m] holds d_{span−p+m}; update from the top so d[m−1] is still level r − 1.
            for m in (r..=p).rev() {
                let j = span - p + m;
                let (lo, hi) = (t[j], t[j + p + 1 - r]);
                let alpha = Dd::difference(u, lo).div(Dd::difference(hi, lo));
                d[m] =
                    std::array::from_fn(|k| d[m - 1][k].add(alpha.mul(d[m][k].sub(d[m - 1][k]))));
            }
        }
        d[p]
    }

    /// The blossom of the same piece seen as a polynomial of degree p + e (p + e arguments):
    /// the mean of f_s over every choice of p of the arguments, C(p + e, p) terms.
    pub fn elevated_blossom(&self, span: usize, args: &[f64]) -> [f64; D] {
        self.elevated_blossom_dd(span, args).map(Dd::round)
    }

    fn elevated_blossom_dd(&self, span: usize, args: &[f64]) -> [Dd; D] {
        let p = self.degree;
        assert!(args.len() >= p);
        let mut sum = [Dd::from(0.0); D];
        let mut terms = 0usize;
        let mut chosen = Vec::with_capacity(p);
        for_each_subset(args, p, 0, &mut chosen, &mut |subset| {
            let f = self.blossom_dd(span, subset);
            for k in 0..D {
                sum[k] = sum[k].add(f[k]);
            }
            terms += 1;
        });
        let count = Dd::from(terms as f64);
        sum.map(|x| x.div(count))
    }

    /// The same as [`Self::elevated_blossom`] by one-at-a-time elevation,
    ///   F_{q+1}(u_1..u_{q+1}) = (1/(q+1)) Σ_i F_q(u_1..û_i..u_{q+1}),
    /// applied e times. Costs (p+e)!/p! evaluations; a cross-check for small cases.
    pub fn elevated_blossom_recursive(&self, span: usize, args: &[f64]) -> [f64; D] {
        if args.len() == self.degree {
            return self.blossom(span, args);
        }
        let q = args.len();
        let mut sum = [0.0; D];
        for i in 0..q {
            let rest: Vec<f64> = args
                .iter()
                .enumerate()
                .filter(|&(k, _)| k != i)
                .map(|(_, &u)| u)
                .collect();
            let f = self.elevated_blossom_recursive(span, &rest);
            for k in 0..D {
                sum[k] += f[k];
            }
        }
        sum.map(|x| x / q as f64)
    }

    /// Control points of this spline's shape, raised to degree `degree` (≥ p), on `knots`,
    /// a refinement of this spline's knots: Q_k = F_s(t'_{k+1}, …, t'_{k+degree}). A control
    /// point whose support misses the domain does not shape the curve; it keeps the original
    /// point with the same knot arguments (the ends of an unclamped curve).
    fn points_on(&self, degree: usize, knots: &[f64]) -> Vec<[f64; D]> {
        let q = degree;
        let n_new = knots.len() - q - 1;
        let (a, b) = self.domain();
        (0..n_new)
            .map(|k| {
                let args = &knots[k + 1..=k + q];
                // Any of these spans gives the same point; the middle one extrapolates least.
                let spans: Vec<usize> = (k..=k + q)
                    .filter(|&s| knots[s] < knots[s + 1] && knots[s] >= a && knots[s + 1] <= b)
                    .collect();
                match spans.get(spans.len() / 2) {
                    Some(&s) => self.elevated_blossom(self.span_of(knots[s]), args),
                    None => {
                        assert_eq!(q, self.degree, "an elevated net lies within the domain");
                        let p = self.degree;
                        (0..self.points.len())
                            .find(|&j| self.knots[j + 1..=j + p] == *args)
                            .map(|j| self.points[j])
                            .expect("a control point outside the domain has an original twin")
                    }
                }
            })
            .collect()
    }

    /// Knot insertion: `t` inserted `times` times; the same curve on the refined knot vector.
    pub fn insert_knot(&self, t: f64, times: usize) -> Result<Spline<D>, String> {
        let (a, b) = self.domain();
        if !(t.is_finite() && a < t && t < b) {
            return Err(format!(
                "insert_knot: {t} is not inside the open domain ({a}, {b})"
            ));
        }
        if times == 0 {
            return Err("times: must be at least 1".into());
        }
        let multiplicity = self.multiplicity(t) + times;
        if multiplicity > self.degree {
            return Err(format!(
                "times: multiplicity {multiplicity} at {t} is above the degree {}",
                self.degree
            ));
        }
        let at = self.knots.iter().take_while(|&&k| k <= t).count();
        let mut knots = self.knots[..at].to_vec();
        knots.extend(std::iter::repeat_n(t, times));
        knots.extend_from_slice(&self.knots[at..]);
        let points = self.points_on(self.degree, &knots);
        Ok(Spline {
            degree: self.degree,
            knots,
            points,
        })
    }

    /// Degree elevation by e ≥ 0 (e = 0 only clamps): the same curve of degree p + e on the
    /// domain [a, b] clamped (a and b p + e + 1 times, knots outside dropped), every interior
    /// knot's multiplicity grown by e. Where C(p + e, p) is large, e single steps instead.
    pub fn elevate(&self, e: usize) -> Result<Spline<D>, String> {
        let q = self.degree + e;
        if q > MAX_DEGREE {
            return Err(format!(
                "elevate_degree: degree {} + {e} is above {MAX_DEGREE}",
                self.degree
            ));
        }
        if e > 1 && binomial(q, e) > 5000.0 {
            return (0..e).try_fold(self.clone(), |s, _| s.elevate(1));
        }
        let (a, b) = self.domain();
        let mut knots = vec![a; q + 1];
        let interior: Vec<f64> = self
            .knots
            .iter()
            .copied()
            .filter(|&k| a < k && k < b)
            .collect();
        for (i, &k) in interior.iter().enumerate() {
            knots.push(k);
            if i + 1 == interior.len() || interior[i + 1] != k {
                knots.extend(std::iter::repeat_n(k, e));
            }
        }
        knots.extend(std::iter::repeat_n(b, q + 1));
        let points = self.points_on(q, &knots);
        Ok(Spline {
            degree: q,
            knots,
            points,
        })
    }
}

/// A double-double number hi + lo, |lo| ≤ ulp(hi)/2 (Dekker 1971; Knuth TAOCP 4.2.2).
#[derive(Clone, Copy, Debug)]
struct Dd {
    hi: f64,
    lo: f64,
}

impl From<f64> for Dd {
    fn from(x: f64) -> Dd {
        Dd { hi: x, lo: 0.0 }
    }
}

/// a + b = s + e exactly (Knuth's TwoSum).
fn two_sum(a: f64, b: f64) -> Dd {
    let s = a + b;
    let bb = s - a;
    Dd {
        hi: s,
        lo: (a - (s - bb)) + (b - bb),
    }
}

/// a · b = p + e exactly (FMA).
fn two_product(a: f64, b: f64) -> Dd {
    let p = a * b;
    Dd {
        hi: p,
        lo: a.mul_add(b, -p),
    }
}

impl Dd {
    /// a − b, exact.
    fn difference(a: f64, b: f64) -> Dd {
        two_sum(a, -b)
    }

    fn normalise(hi: f64, lo: f64) -> Dd {
        let s = hi + lo;
        Dd {
            hi: s,
            lo: lo - (s - hi),
        }
    }

    fn add(self, o: Dd) -> Dd {
        let s = two_sum(self.hi, o.hi);
        let t = two_sum(self.lo, o.lo);
        let u = Dd::normalise(s.hi, s.lo + t.hi);
        Dd::normalise(u.hi, u.lo + t.lo)
    }

    fn neg(self) -> Dd {
        Dd {
            hi: -self.hi,
            lo: -self.lo,
        }
    }

    fn sub(self, o: Dd) -> Dd {
        self.add(o.neg())
    }

    fn mul(self, o: Dd) -> Dd {
        let p = two_product(self.hi, o.hi);
        Dd::normalise(p.hi, p.lo + (self.hi * o.lo + self.lo * o.hi))
    }

    fn div(self, o: Dd) -> Dd {
        let q1 = self.hi / o.hi;
        let r = self.sub(o.mul(Dd::from(q1)));
        let q2 = r.hi / o.hi;
        let r = r.sub(o.mul(Dd::from(q2)));
        let q3 = r.hi / o.hi;
        Dd::normalise(q1, q2).add(Dd::from(q3))
    }

    fn round(self) -> f64 {
        self.hi + self.lo
    }
}

/// C(n, k) as f64.
fn binomial(n: usize, k: usize) -> f64 {
    (0..k.min(n - k)).fold(1.0, |c, i| c * (n - i) as f64 / (i + 1) as f64)
}

/// Calls `f` with every `size`-element subsequence of `items[from..]` appended to `chosen`.
fn for_each_subset(
    items: &[f64],
    size: usize,
    from: usize,
    chosen: &mut Vec<f64>,
    f: &mut dyn FnMut(&[f64]),
) {
    if chosen.len() == size {
        f(chosen);
        return;
    }
    let needed = size - chosen.len();
    for i in from..=items.len() - needed {
        chosen.push(items[i]);
        for_each_subset(items, size, i + 1, chosen, f);
        chosen.pop();
    }
}
