//! Tensor-product Bézier and B-spline surfaces, rational too: partial derivatives, unit normals
//! with a fallback where Su × Sv vanishes, Gaussian and mean curvature.

use super::basis::hermite_into;
use super::bspline::de_boor;
use super::control::{check_points, check_weights};
use super::error::{GeomError, GeomResult};
use super::knots::KnotVector;
use super::point::{Point, binomial, homogeneous, to_homogeneous};
use super::refine::{Elevation, KnotInsertion, Pack, Spline, refine_net};
use glam::{DVec3, DVec4};

/// S(u,v) = Σ_i Σ_j P_ij N_i(u) N_j(v). Control points are row-major, `points[i * nv + j]`, with
/// i along u. A Bézier surface is the special case of Bézier knot vectors on [0,1]².
#[derive(Debug, Clone, PartialEq)]
pub struct TensorSurface {
    degree: [usize; 2],
    knots: [KnotVector; 2],
    count: [usize; 2],
    points: Vec<DVec3>,
    weights: Option<Vec<f64>>,
}

/// Applies a knot insertion to a row-major net of `nv` columns: across rows (direction u,
/// whole rows are the blocks) or within each row (direction v).
fn insert_in_lines<P: Point>(
    plan: &KnotInsertion,
    dir: usize,
    nv: usize,
    old: &[P],
    new: &mut [P],
) {
    if dir == 0 {
        plan.apply(old, new, nv);
    } else {
        let grown = new.len() / (old.len() / nv);
        for (o, n) in old.chunks_exact(nv).zip(new.chunks_exact_mut(grown)) {
            plan.apply(o, n, 1);
        }
    }
}

/// All partial derivatives ∂^{a+b}S/∂u^a∂v^b for a, b ≤ n.
#[derive(Debug, Clone, PartialEq)]
pub struct Partials {
    n: usize,
    values: Vec<DVec3>,
}

impl Partials {
    #[must_use]
    pub fn zeros(n: usize) -> Self {
        Self {
            n,
            values: vec![DVec3::ZERO; (n + 1) * (n + 1)],
        }
    }

    /// Highest order per direction.
    #[must_use]
    pub fn order(&self) -> usize {
        self.n
    }

    #[inline]
    #[must_use]
    pub fn get(&self, a: usize, b: usize) -> DVec3 {
        self.values[a * (self.n + 1) + b]
    }

    #[inline]
    pub fn set(&mut self, a: usize, b: usize, v: DVec3) {
        self.values[a * (self.n + 1) + b] = v;
    }
}

impl TensorSurface {
    /// A B-spline (or NURBS, with weights) surface; `points` row-major with `count = [nu, nv]`.
    pub fn bspline(
        degree: [usize; 2],
        knots: [Vec<f64>; 2],
        count: [usize; 2],
        points: Vec<DVec3>,
        weights: Option<Vec<f64>>,
    ) -> GeomResult<Self> {
        check_grid(count, &points)?;
        let [ku, kv] = knots;
        let ku = KnotVector::for_bspline(ku, degree[0], count[0]).map_err(|e| direction(e, "u"))?;
        let kv = KnotVector::for_bspline(kv, degree[1], count[1]).map_err(|e| direction(e, "v"))?;
        if let Some(w) = &weights {
            check_weights(w, points.len())?;
        }
        Ok(Self {
            degree,
            knots: [ku, kv],
            count,
            points,
            weights,
        })
    }

    /// A Bézier (or rational Bézier) patch of degree (nu−1, nv−1) on [0,1]².
    pub fn bezier(
        count: [usize; 2],
        points: Vec<DVec3>,
        weights: Option<Vec<f64>>,
    ) -> GeomResult<Self> {
        check_grid(count, &points)?;
        if let Some(w) = &weights {
            check_weights(w, points.len())?;
        }
        let degree = [count[0] - 1, count[1] - 1];
        let knots = [
            KnotVector::bezier(degree[0], 0.0, 1.0),
            KnotVector::bezier(degree[1], 0.0, 1.0),
        ];
        Ok(Self {
            degree,
            knots,
            count,
            points,
            weights,
        })
    }

    /// The same Bézier patch with its parameters mapped linearly onto [a, b] × [c, d] (how ERBS
    /// local patches are placed). Only meaningful for Bézier patches.
    pub fn with_bezier_domain(mut self, domain: [(f64, f64); 2]) -> GeomResult<Self> {
        for (dir, (a, b)) in domain.iter().enumerate() {
            if !(a.is_finite() && b.is_finite() && a < b) {
                return Err(GeomError::new(
                    "interval",
                    format!("[{a}, {b}] is not a finite interval with a < b"),
                ));
            }
            self.knots[dir] = KnotVector::bezier(self.degree[dir], *a, *b);
        }
        Ok(self)
    }

    #[must_use]
    pub fn degree(&self) -> [usize; 2] {
        self.degree
    }

    #[must_use]
    pub fn knots(&self) -> &[KnotVector; 2] {
        &self.knots
    }

    /// [nu, nv].
    #[must_use]
    pub fn count(&self) -> [usize; 2] {
        self.count
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

    #[must_use]
    pub fn point(&self, i: usize, j: usize) -> DVec3 {
        self.points[i * self.count[1] + j]
    }

    pub fn translate_point(&mut self, i: usize, j: usize, delta: DVec3) {
        self.points[i * self.count[1] + j] += delta;
    }

    /// Sets control point (i, j) exactly.
    pub fn set_point(&mut self, i: usize, j: usize, p: DVec3) {
        self.points[i * self.count[1] + j] = p;
    }

    /// Replaces all control points (same count), exactly.
    pub fn set_points(&mut self, points: &[DVec3]) {
        assert_eq!(
            points.len(),
            self.points.len(),
            "set_points keeps the net size"
        );
        self.points.copy_from_slice(points);
    }

    /// Replaces every control point by `f(point)` (weights unchanged), e.g. an affine map.
    pub fn map_points(&mut self, f: impl Fn(DVec3) -> DVec3) {
        for p in &mut self.points {
            *p = f(*p);
        }
    }

    /// Sets weight (i, j), making the surface rational (other weights 1) if it was not.
    pub fn set_weight(&mut self, i: usize, j: usize, w: f64) {
        let n = self.points.len();
        let nv = self.count[1];
        self.weights.get_or_insert_with(|| vec![1.0; n])[i * nv + j] = w;
    }

    /// Homogeneous control points (w P, w), row-major.
    #[must_use]
    pub fn homogeneous_points(&self) -> Vec<DVec4> {
        homogeneous(&self.points, self.weights.as_deref())
    }

    /// The same net on knots of direction `dir` mapped by an increasing `f` (a
    /// reparametrisation of that direction).
    pub fn with_knots_mapped(&self, dir: usize, f: impl Fn(f64) -> f64) -> GeomResult<Self> {
        let mut s = self.clone();
        s.knots[dir] = KnotVector::new(self.knots[dir].iter().map(|&t| f(t)).collect())?;
        Ok(s)
    }

    /// Splits at an interior parameter t of direction `dir` into two surfaces meeting along
    /// the isoline there (knots inserted to multiplicity d, then the net cut), exactly as
    /// [`super::BSplineCurve::split`] does for every line of the net.
    pub fn split(&self, dir: usize, t: f64) -> GeomResult<(Self, Self)> {
        let (a, b) = self.domain()[dir];
        if !(t > a && t < b) {
            return Err(GeomError::new(
                "parameter",
                format!("{t} is not inside ({a}, {b})"),
            ));
        }
        let p = self.degree[dir];
        if p == 0 {
            // Piecewise constant in `dir`: the span holding t is cut in two.
            let n = self.count[dir];
            let k = self.knots[dir].find_span(0, n, t);
            let u = &self.knots[dir];
            let mut lk = u[..=k].to_vec();
            lk.push(t);
            let mut rk = vec![t];
            rk.extend_from_slice(&u[k + 1..]);
            let left = self.sliced(dir, 0..k + 1, KnotVector::new(lk)?);
            let right = self.sliced(dir, k..n, KnotVector::new(rk)?);
            return Ok((left, right));
        }
        let s = self.knots[dir].multiplicity(t);
        let c = if s < p {
            self.with_knot(dir, t, p - s)
        } else {
            self.clone()
        };
        let u = &c.knots[dir];
        let Some(first) = u.iter().position(|&x| x == t) else {
            return Err(GeomError::new("parameter", format!("cannot split at {t}")));
        };
        let mult = u.multiplicity(t);
        let right_start = if mult == p + 1 { first } else { first - 1 };
        let mut lk = u[..first].to_vec();
        lk.extend(std::iter::repeat_n(t, p + 1));
        let mut rk = vec![t; p + 1];
        rk.extend_from_slice(&u[first + mult..]);
        let left = c.sliced(dir, 0..first, KnotVector::new(lk)?);
        let right = c.sliced(dir, right_start..c.count[dir], KnotVector::new(rk)?);
        Ok((left, right))
    }

    /// The control points with index in `range` along `dir`, on new knots for that direction.
    fn sliced(&self, dir: usize, range: std::ops::Range<usize>, knots: KnotVector) -> Self {
        let [nu, nv] = self.count;
        let keep = |k: usize| {
            let (i, j) = (k / nv, k % nv);
            range.contains(if dir == 0 { &i } else { &j })
        };
        let points = (0..nu * nv)
            .filter(|&k| keep(k))
            .map(|k| self.points[k])
            .collect();
        let weights = self
            .weights
            .as_ref()
            .map(|w| (0..nu * nv).filter(|&k| keep(k)).map(|k| w[k]).collect());
        let mut count = self.count;
        count[dir] = range.len();
        let mut out = Self {
            degree: self.degree,
            knots: self.knots.clone(),
            count,
            points,
            weights,
        };
        out.knots[dir] = knots;
        out
    }

    /// SurfaceKnotIns (NURBS Book A5.3): inserts `t` `times` times in direction `dir` (0: u,
    /// 1: v) by CurveKnotIns on every line of the net; the surface is unchanged. `t` must lie
    /// in the domain and the final multiplicity may not exceed that direction's degree.
    pub fn insert_knot(&self, dir: usize, t: f64, times: usize) -> GeomResult<Self> {
        let (a, b) = self.domain()[dir];
        if !(t >= a && t < b) {
            return Err(GeomError::new(
                "parameter",
                format!("{t} is not in [{a}, {b})"),
            ));
        }
        let p = self.degree[dir];
        let s = self.knots[dir].multiplicity(t);
        if s + times > p {
            return Err(GeomError::new(
                "parameter",
                format!(
                    "inserting {t} {times} times would give multiplicity {} > degree {p}",
                    s + times
                ),
            ));
        }
        Ok(self.with_knot(dir, t, times))
    }

    /// SurfaceKnotIns without the checks: Böhm's coefficients once, applied to whole rows of
    /// the net (direction u: rows of control points are the blocks) or within each row
    /// (direction v). Polynomial nets refine their points directly, rational ones in
    /// homogeneous coordinates.
    fn with_knot(&self, dir: usize, t: f64, r: usize) -> Self {
        let [nu, nv] = self.count;
        let plan = KnotInsertion::new(&self.knots[dir], self.degree[dir], self.count[dir], t, r);
        let mut count = self.count;
        count[dir] += r;
        let (points, weights) = match &self.weights {
            None => {
                let mut new = vec![DVec3::ZERO; count[0] * count[1]];
                insert_in_lines(&plan, dir, nv, &self.points, &mut new);
                (new, None)
            }
            Some(_) => {
                let mut new = vec![DVec4::ZERO; count[0] * count[1]];
                insert_in_lines(&plan, dir, nv, &self.homogeneous_points(), &mut new);
                let points = new.iter().map(|h| h.truncate() / h.w).collect();
                (points, Some(new.iter().map(|h| h.w).collect()))
            }
        };
        debug_assert_eq!(nu * nv + r * if dir == 0 { nv } else { nu }, points.len());
        let mut knots = self.knots.clone();
        knots[dir] = KnotVector::new(plan.knots).expect("insertion keeps knots sorted");
        Self {
            degree: self.degree,
            knots,
            count,
            points,
            weights,
        }
    }

    /// Degree elevation by `by` in direction `dir` (NURBS Book A5.10: DegreeElevateCurve on
    /// every line of the net). An unclamped direction comes back clamped on its domain.
    #[must_use]
    pub fn elevate_degree(&self, dir: usize, by: usize) -> Self {
        let elevation = Elevation::new(self.degree[dir], &self.knots[dir], by);
        self.refined(dir, |c| elevation.apply(c))
    }

    fn refined(&self, dir: usize, refine: impl Fn(&Spline<Pack>) -> Spline<Pack>) -> Self {
        let r = refine_net(
            self.degree[dir],
            &self.knots[dir],
            self.count,
            (&self.points, self.weights.as_deref()),
            dir,
            refine,
        );
        let mut degree = self.degree;
        let mut knots = self.knots.clone();
        degree[dir] = r.degree;
        knots[dir] = KnotVector::new(r.knots).expect("refinement keeps knots sorted");
        Self {
            degree,
            knots,
            count: r.count,
            points: r.points,
            weights: r.weights,
        }
    }

    /// Parameter domains [(u0, u1), (v0, v1)].
    #[must_use]
    pub fn domain(&self) -> [(f64, f64); 2] {
        [
            self.knots[0].domain(self.degree[0], self.count[0]),
            self.knots[1].domain(self.degree[1], self.count[1]),
        ]
    }

    /// FindSpan in each direction.
    #[must_use]
    pub fn find_spans(&self, u: f64, v: f64) -> [usize; 2] {
        [
            self.knots[0].find_span(self.degree[0], self.count[0], u),
            self.knots[1].find_span(self.degree[1], self.count[1], v),
        ]
    }

    /// ∂^{a+b}S/∂u^a∂v^b for a, b ≤ n, as P = M_u · C · M_vᵀ with the two Hermite matrices
    /// (RatSurfaceDerivs, NURBS Book A4.4, for rational surfaces).
    #[must_use]
    pub fn derivatives(&self, u: f64, v: f64, n: usize) -> Partials {
        let [du, dv] = self.degree;
        let [su, sv] = self.find_spans(u, v);
        let [(u0, u1), (v0, v1)] = self.domain();
        let mut mu = vec![0.0; (du + 1) * (du + 1)];
        let mut mv = vec![0.0; (dv + 1) * (dv + 1)];
        hermite_into(&self.knots[0], du, su, u.clamp(u0, u1), &mut mu);
        hermite_into(&self.knots[1], dv, sv, v.clamp(v0, v1), &mut mv);
        let nv = self.count[1];
        let mut out = Partials::zeros(n);
        match &self.weights {
            None => {
                for a in 0..=n.min(du) {
                    for b in 0..=n.min(dv) {
                        let mut acc = DVec3::ZERO;
                        for k in 0..=du {
                            let row = (su - du + k) * nv + sv - dv;
                            let mut inner = DVec3::ZERO;
                            for l in 0..=dv {
                                inner += self.points[row + l] * mv[b * (dv + 1) + l];
                            }
                            acc += inner * mu[a * (du + 1) + k];
                        }
                        out.set(a, b, acc);
                    }
                }
            }
            Some(w) => {
                let mut hom = vec![DVec4::ZERO; (n + 1) * (n + 1)];
                for a in 0..=n.min(du) {
                    for b in 0..=n.min(dv) {
                        let mut acc = DVec4::ZERO;
                        for k in 0..=du {
                            let row = (su - du + k) * nv + sv - dv;
                            let mut inner = DVec4::ZERO;
                            for l in 0..=dv {
                                let idx = row + l;
                                inner +=
                                    to_homogeneous(self.points[idx], w[idx]) * mv[b * (dv + 1) + l];
                            }
                            acc += inner * mu[a * (du + 1) + k];
                        }
                        hom[a * (n + 1) + b] = acc;
                    }
                }
                rational_surface_derivs(&hom, n, &mut out);
            }
        }
        out
    }

    /// S, S_u and S_v at (u, v) without allocating: BasisFuns (A2.2) of degree d and d − 1 in
    /// stack arrays and N′ = d (N_{i,d−1}/(t_{i+d} − t_i) − N_{i+1,d−1}/(t_{i+d+1} − t_{i+1}))
    /// (A2.3 for one derivative), the quotient rule for rational surfaces. What measures a
    /// surface (areas, bounds) evaluates it thousands of times; degrees above 15 take
    /// [`TensorSurface::derivatives`].
    #[must_use]
    pub fn first_partials(&self, u: f64, v: f64) -> [DVec3; 3] {
        let [du, dv] = self.degree;
        if du > STACK_DEGREE || dv > STACK_DEGREE {
            let p = self.derivatives(u, v, 1);
            return [p.get(0, 0), p.get(1, 0), p.get(0, 1)];
        }
        let [su, sv] = self.find_spans(u, v);
        let [(u0, u1), (v0, v1)] = self.domain();
        let (bu, dbu) = basis_and_derivative(self.knots[0].as_slice(), du, su, u.clamp(u0, u1));
        let (bv, dbv) = basis_and_derivative(self.knots[1].as_slice(), dv, sv, v.clamp(v0, v1));
        let nv = self.count[1];
        let (mut s, mut s_u, mut s_v) = (DVec4::ZERO, DVec4::ZERO, DVec4::ZERO);
        for k in 0..=du {
            let row = (su - du + k) * nv + sv - dv;
            let (mut inner, mut inner_v) = (DVec4::ZERO, DVec4::ZERO);
            for l in 0..=dv {
                let idx = row + l;
                let w = self.weights.as_ref().map_or(1.0, |w| w[idx]);
                let h = to_homogeneous(self.points[idx], w);
                inner += h * bv[l];
                inner_v += h * dbv[l];
            }
            s += inner * bu[k];
            s_u += inner * dbu[k];
            s_v += inner_v * bu[k];
        }
        let p = s.truncate() / s.w;
        [
            p,
            (s_u.truncate() - p * s_u.w) / s.w,
            (s_v.truncate() - p * s_v.w) / s.w,
        ]
    }

    /// [`TensorSurface::first_partials`] at every point of the grid `us` × `vs` (at most
    /// [`GRID_NODES`] each), `out[a * vs.len() + b]` at `(us[a], vs[b])`, the same bits. Where
    /// every node of the grid lies in one knot span per direction (the Gauss nodes of a cell
    /// between breakpoints), the basis functions are found once per row and column and the
    /// control net is contracted with the v basis once per column: 12 basis evaluations and
    /// about a fifth of the multiplications of 36 separate points.
    pub fn first_partials_grid(&self, us: &[f64], vs: &[f64], out: &mut [[DVec3; 3]]) {
        let [du, dv] = self.degree;
        let fallback = |out: &mut [[DVec3; 3]]| {
            for (a, &u) in us.iter().enumerate() {
                for (b, &v) in vs.iter().enumerate() {
                    if let Some(o) = out.get_mut(a * vs.len() + b) {
                        *o = self.first_partials(u, v);
                    }
                }
            }
        };
        if du > STACK_DEGREE
            || dv > STACK_DEGREE
            || us.len() > GRID_NODES
            || vs.len() > GRID_NODES
            || out.len() < us.len() * vs.len()
            || us.is_empty()
            || vs.is_empty()
        {
            return fallback(out);
        }
        let [(u0, u1), (v0, v1)] = self.domain();
        let su = self.knots[0].find_span(du, self.count[0], us[0]);
        let sv = self.knots[1].find_span(dv, self.count[1], vs[0]);
        let same_u = us
            .iter()
            .all(|&u| self.knots[0].find_span(du, self.count[0], u) == su);
        let same_v = vs
            .iter()
            .all(|&v| self.knots[1].find_span(dv, self.count[1], v) == sv);
        if !(same_u && same_v) {
            return fallback(out);
        }
        let nv = self.count[1];
        // Per v node, per row k of the span: Σ_l H_{k,l} N_l(v) and Σ_l H_{k,l} N_l′(v).
        let mut col = [[DVec4::ZERO; STACK_DEGREE + 1]; GRID_NODES];
        let mut col_v = [[DVec4::ZERO; STACK_DEGREE + 1]; GRID_NODES];
        for (b, &v) in vs.iter().enumerate() {
            let (bv, dbv) = basis_and_derivative(self.knots[1].as_slice(), dv, sv, v.clamp(v0, v1));
            for k in 0..=du {
                let row = (su - du + k) * nv + sv - dv;
                let (mut inner, mut inner_v) = (DVec4::ZERO, DVec4::ZERO);
                for l in 0..=dv {
                    let idx = row + l;
                    let w = self.weights.as_ref().map_or(1.0, |w| w[idx]);
                    let h = to_homogeneous(self.points[idx], w);
                    inner += h * bv[l];
                    inner_v += h * dbv[l];
                }
                col[b][k] = inner;
                col_v[b][k] = inner_v;
            }
        }
        for (a, &u) in us.iter().enumerate() {
            let (bu, dbu) = basis_and_derivative(self.knots[0].as_slice(), du, su, u.clamp(u0, u1));
            for b in 0..vs.len() {
                let (mut s, mut s_u, mut s_v) = (DVec4::ZERO, DVec4::ZERO, DVec4::ZERO);
                for k in 0..=du {
                    s += col[b][k] * bu[k];
                    s_u += col[b][k] * dbu[k];
                    s_v += col_v[b][k] * bu[k];
                }
                let p = s.truncate() / s.w;
                out[a * vs.len() + b] = [
                    p,
                    (s_u.truncate() - p * s_u.w) / s.w,
                    (s_v.truncate() - p * s_v.w) / s.w,
                ];
            }
        }
    }

    /// S(u, v) by de Boor's algorithm as a curve of curves (independent of the Hermite path).
    #[must_use]
    pub fn eval(&self, u: f64, v: f64) -> DVec3 {
        let [du, dv] = self.degree;
        let [nu, nv] = self.count;
        let h = self.homogeneous_points();
        let column: Vec<DVec4> = (0..nu)
            .map(|i| de_boor(&self.knots[1], dv, &h[i * nv..(i + 1) * nv], v))
            .collect();
        let p = de_boor(&self.knots[0], du, &column, u);
        p.truncate() / p.w
    }

    /// Unit normal at (u, v), defined everywhere; see [`normal_with_fallback`].
    #[must_use]
    pub fn normal(&self, u: f64, v: f64) -> DVec3 {
        let p = self.derivatives(u, v, 1);
        normal_with_fallback(
            p.get(1, 0),
            p.get(0, 1),
            p.get(1, 1),
            self.domain(),
            u,
            v,
            |u, v| {
                let q = self.derivatives(u, v, 1);
                (q.get(1, 0), q.get(0, 1))
            },
        )
    }

    /// Gaussian and mean curvature (K, H) at (u, v) from the fundamental forms, with the normal
    /// orientation Su × Sv; `None` where the parameterisation is singular.
    #[must_use]
    pub fn curvatures(&self, u: f64, v: f64) -> Option<(f64, f64)> {
        let p = self.derivatives(u, v, 2);
        curvatures_from_partials(&p)
    }
}

/// Degrees up to which [`TensorSurface::first_partials`] works in stack arrays.
const STACK_DEGREE: usize = 15;

/// The most nodes per direction [`TensorSurface::first_partials_grid`] takes at once.
pub const GRID_NODES: usize = 8;

/// The d + 1 basis functions non-zero on `span` at `t` and their first derivatives.
fn basis_and_derivative(
    knots: &[f64],
    d: usize,
    span: usize,
    t: f64,
) -> ([f64; STACK_DEGREE + 1], [f64; STACK_DEGREE + 1]) {
    let mut n = [0.0; STACK_DEGREE + 1];
    let mut dn = [0.0; STACK_DEGREE + 1];
    // The d basis functions of degree d − 1 on the span, N_{span−d+1 ..= span, d−1}: BasisFuns
    // (A2.2) one step short of degree d, kept on the way.
    let mut low = [0.0; STACK_DEGREE + 1];
    n[0] = 1.0;
    for j in 1..=d {
        if j == d {
            low[..d].copy_from_slice(&n[..d]);
        }
        let mut saved = 0.0;
        for r in 0..j {
            let right = knots[span + r + 1] - t;
            let left = t - knots[span + 1 + r - j];
            let temp = n[r] / (right + left);
            n[r] = saved + right * temp;
            saved = left * temp;
        }
        n[j] = saved;
    }
    if d == 0 {
        return (n, dn);
    }
    let df = d as f64;
    for j in 0..=d {
        let i = span - d + j;
        let left = if j >= 1 {
            let den = knots[i + d] - knots[i];
            if den > 0.0 { low[j - 1] / den } else { 0.0 }
        } else {
            0.0
        };
        let right = if j < d {
            let den = knots[i + d + 1] - knots[i + 1];
            if den > 0.0 { low[j] / den } else { 0.0 }
        } else {
            0.0
        };
        dn[j] = df * (left - right);
    }
    (n, dn)
}

/// Gaussian and mean curvature from partials up to order (2, 2) (only Su, Sv, Suu, Suv, Svv
/// are used).
#[must_use]
pub fn curvatures_from_partials(p: &Partials) -> Option<(f64, f64)> {
    let (su, sv) = (p.get(1, 0), p.get(0, 1));
    let n = regular_normal(su, sv)?;
    let (e, f, g) = (su.dot(su), su.dot(sv), sv.dot(sv));
    let (l, m, nn) = (p.get(2, 0).dot(n), p.get(1, 1).dot(n), p.get(0, 2).dot(n));
    let det = e * g - f * f;
    Some((
        (l * nn - m * m) / det,
        (e * nn - 2.0 * f * m + g * l) / (2.0 * det),
    ))
}

/// normalize(Su × Sv), or `None` where the cross product is negligible against |Su|·|Sv| scale
/// (a collapsed edge, a cusp, or a vanishing derivative).
#[must_use]
pub fn regular_normal(su: DVec3, sv: DVec3) -> Option<DVec3> {
    let c = su.cross(sv);
    let scale = su.length_squared().max(sv.length_squared());
    let len2 = c.length_squared();
    if scale > 0.0 && len2 > 1e-20 * scale * scale && len2.is_finite() {
        // One division and three products: the samplers' lane kernels do the same, and a
        // division costs as much as the rest of the normal.
        Some(c * (1.0 / len2.sqrt()))
    } else {
        None
    }
}

/// The normal where Su × Sv vanishes, as a one-sided limit from the inside of the domain.
///
/// 1. If Sv ≈ 0 along an edge u = const (e.g. the teapot's lid top, where a whole patch edge
///    collapses to a point), Sv(u+h, v) ≈ h·Suv, so the normal is ±normalize(Su × Suv) with the
///    sign of the step h towards the interior; symmetrically ±normalize(Suv × Sv) when Su ≈ 0.
/// 2. Otherwise (a corner where both vanish, or parallel partials) the regular normal at points
///    nudged towards the domain centre by 1e-7, 1e-5, 1e-3 of the domain size.
/// 3. As the last resort +Z, so that every sample has a defined unit normal.
pub fn normal_with_fallback(
    su: DVec3,
    sv: DVec3,
    suv: DVec3,
    domain: [(f64, f64); 2],
    u: f64,
    v: f64,
    first_partials: impl Fn(f64, f64) -> (DVec3, DVec3),
) -> DVec3 {
    if let Some(n) = regular_normal(su, sv) {
        return n;
    }
    let [(u0, u1), (v0, v1)] = domain;
    let (uc, vc) = (0.5 * (u0 + u1), 0.5 * (v0 + v1));
    let inward_u = if u <= uc { 1.0 } else { -1.0 };
    let inward_v = if v <= vc { 1.0 } else { -1.0 };
    let (lu, lv) = (su.length(), sv.length());
    let limit = if lv <= 1e-10 * lu {
        regular_normal(su, suv * inward_u)
    } else if lu <= 1e-10 * lv {
        regular_normal(suv * inward_v, sv)
    } else {
        None
    };
    if let Some(n) = limit {
        return n;
    }
    for eps in [1e-7, 1e-5, 1e-3] {
        let (un, vn) = (u + eps * (uc - u), v + eps * (vc - v));
        let (a, b) = first_partials(un, vn);
        if let Some(n) = regular_normal(a, b) {
            return n;
        }
    }
    DVec3::Z
}

/// RatSurfaceDerivs (NURBS Book A4.4) on the full square a, b ≤ n: projects homogeneous partials
/// `hom[a*(n+1)+b]` of (w·S, w) to Euclidean partials of S by the quotient rule.
pub fn rational_surface_derivs(hom: &[DVec4], n: usize, out: &mut Partials) {
    let w = n + 1;
    let wd = |a: usize, b: usize| hom[a * w + b].w;
    for k in 0..=n {
        for l in 0..=n {
            let mut v = hom[k * w + l].truncate();
            for j in 1..=l {
                v -= out.get(k, l - j) * (binomial(l, j) * wd(0, j));
            }
            for i in 1..=k {
                v -= out.get(k - i, l) * (binomial(k, i) * wd(i, 0));
                let mut v2 = DVec3::ZERO;
                for j in 1..=l {
                    v2 += out.get(k - i, l - j) * (binomial(l, j) * wd(i, j));
                }
                v -= v2 * binomial(k, i);
            }
            out.set(k, l, v / wd(0, 0));
        }
    }
}

fn check_grid(count: [usize; 2], points: &[DVec3]) -> GeomResult<()> {
    if count[0] == 0 || count[1] == 0 {
        return Err(GeomError::new(
            "points",
            format!("empty control net ({} × {})", count[0], count[1]),
        ));
    }
    if points.len() != count[0] * count[1] {
        return Err(GeomError::new(
            "points",
            format!(
                "{} points do not form a {} × {} net",
                points.len(),
                count[0],
                count[1]
            ),
        ));
    }
    check_points(points)
}

fn direction(mut e: GeomError, dir: &str) -> GeomError {
    e.message = format!("{dir} direction: {}", e.message);
    e
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A bicubic patch over a saddle-ish net with irregular knots in u.
    fn patch(rational: bool) -> TensorSurface {
        let (nu, nv) = (6, 4);
        let mut pts = Vec::new();
        for i in 0..nu {
            for j in 0..nv {
                let (x, y) = (i as f64, j as f64);
                pts.push(DVec3::new(
                    x,
                    y,
                    0.3 * x * y - 0.2 * x * x + (x + 2.0 * y).sin(),
                ));
            }
        }
        let w = rational.then(|| (0..nu * nv).map(|k| 0.6 + 0.15 * (k % 5) as f64).collect());
        TensorSurface::bspline(
            [3, 2],
            [
                vec![0., 0., 0., 0., 0.7, 1.9, 3., 3., 3., 3.],
                vec![0., 0., 0., 0.5, 1., 1., 1.],
            ],
            [nu, nv],
            pts,
            w,
        )
        .unwrap()
    }

    #[test]
    fn hermite_partials_match_de_boor_and_finite_differences() {
        for rational in [false, true] {
            let s = patch(rational);
            for &(u, v) in &[
                (0.0, 0.0),
                (0.35, 0.2),
                (1.2, 0.77),
                (2.9, 1.0),
                (3.0, 0.45),
            ] {
                let p = s.derivatives(u, v, 2);
                assert!((p.get(0, 0) - s.eval(u, v)).length() < 1e-13);
                let h = 1e-5;
                let (uc, vc) = (u.clamp(h, 3.0 - h), v.clamp(h, 1.0 - h));
                let q = s.derivatives(uc, vc, 2);
                let fu = (s.eval(uc + h, vc) - s.eval(uc - h, vc)) / (2.0 * h);
                let fv = (s.eval(uc, vc + h) - s.eval(uc, vc - h)) / (2.0 * h);
                assert!((fu - q.get(1, 0)).length() < 1e-6 * (1.0 + fu.length()));
                assert!((fv - q.get(0, 1)).length() < 1e-6 * (1.0 + fv.length()));
                let fuv = (s.derivatives(uc, vc + h, 1).get(1, 0)
                    - s.derivatives(uc, vc - h, 1).get(1, 0))
                    / (2.0 * h);
                assert!((fuv - q.get(1, 1)).length() < 1e-6 * (1.0 + fuv.length()));
            }
        }
    }

    #[test]
    fn collapsed_edge_gets_the_limit_normal() {
        // A cap of revolution: the whole u = 0 edge is the pole (0, 0, 1).
        let pole = DVec3::new(0.0, 0.0, 1.0);
        let mut pts = Vec::new();
        for i in 0..4 {
            for j in 0..4 {
                if i == 0 {
                    pts.push(pole);
                } else {
                    // Row 1 lies in the tangent plane z = 1, so the pole is a smooth point.
                    let a = std::f64::consts::FRAC_PI_2 * j as f64 / 3.0;
                    let r = i as f64 / 3.0;
                    let z = if i == 1 { 1.0 } else { 1.0 - 0.3 * r * r };
                    pts.push(DVec3::new(r * a.cos(), r * a.sin(), z));
                }
            }
        }
        let s = TensorSurface::bezier([4, 4], pts, None).unwrap();
        for j in 0..=4 {
            let v = j as f64 / 4.0;
            let n = s.normal(0.0, v);
            assert!((n.length() - 1.0).abs() < 1e-14);
            // The limit normal at the pole of a surface of revolution about z is ±z; orientation
            // must agree with the regular normals next to it.
            let inner = s.normal(1e-4, v);
            assert!(n.dot(inner) > 0.99, "v={v}: {n:?} vs {inner:?}");
            assert!(n.z.abs() > 0.999_999, "{n:?}");
        }
    }

    #[test]
    fn sphere_curvatures() {
        // Rational biquadratic patch: an octant of the unit sphere.
        let r2 = std::f64::consts::FRAC_1_SQRT_2;
        let pts = vec![
            DVec3::new(0., 0., 1.),
            DVec3::new(0., 0., 1.),
            DVec3::new(0., 0., 1.),
            DVec3::new(1., 0., 1.),
            DVec3::new(1., 1., 1.),
            DVec3::new(0., 1., 1.),
            DVec3::new(1., 0., 0.),
            DVec3::new(1., 1., 0.),
            DVec3::new(0., 1., 0.),
        ];
        let w = vec![1., r2, 1., r2, 0.5, r2, 1., r2, 1.];
        let s = TensorSurface::bezier([3, 3], pts, Some(w)).unwrap();
        for &(u, v) in &[(0.3, 0.3), (0.5, 0.9), (0.8, 0.1)] {
            assert!((s.eval(u, v).length() - 1.0).abs() < 1e-14);
            let (k, h) = s.curvatures(u, v).unwrap();
            assert!((k - 1.0).abs() < 1e-10, "K = {k}");
            assert!((h.abs() - 1.0).abs() < 1e-10, "H = {h}");
        }
        // The pole (u = 0) is a collapsed edge: the normal is still ±z.
        assert!(s.normal(0.0, 0.4).z.abs() > 0.999_999);
    }

    #[test]
    fn grid_validation() {
        let e = TensorSurface::bezier([2, 2], vec![DVec3::ZERO; 3], None).unwrap_err();
        assert!(
            e.message.contains("3 points do not form a 2 × 2 net"),
            "{e}"
        );
        let e = TensorSurface::bspline(
            [1, 1],
            [vec![0., 0., 1.], vec![0., 0., 1., 1.]],
            [2, 2],
            vec![DVec3::ZERO; 4],
            None,
        )
        .unwrap_err();
        assert!(e.message.starts_with("u direction"), "{e}");
    }
}

#[cfg(test)]
mod first_partials_tests {
    use super::*;

    /// A bicubic × biquadratic net with uneven knots, rational or not.
    fn surface(rational: bool) -> TensorSurface {
        let (nu, nv) = (6, 5);
        let points = (0..nu * nv)
            .map(|k| {
                let (i, j) = ((k / nv) as f64, (k % nv) as f64);
                DVec3::new(i, j, (1.3 * i).sin() * (0.7 * j).cos())
            })
            .collect();
        let weights = rational.then(|| (0..nu * nv).map(|k| 0.5 + (k % 7) as f64 * 0.25).collect());
        TensorSurface::bspline(
            [3, 2],
            [
                vec![0.0, 0.0, 0.0, 0.0, 0.3, 1.1, 2.0, 2.0, 2.0, 2.0],
                vec![0.0, 0.0, 0.0, 0.2, 0.6, 1.0, 1.0, 1.0],
            ],
            [nu, nv],
            points,
            weights,
        )
        .unwrap()
    }

    /// The allocation-free S, S_u, S_v agree with the Hermite path to rounding, at knots
    /// and ends too; a perturbed weight does not (the comparison can fail).
    #[test]
    fn first_partials_agree_with_the_hermite_path() {
        let close = |a: DVec3, b: DVec3| (a - b).length() <= 1e-12 * (1.0 + b.length());
        for rational in [false, true] {
            let s = surface(rational);
            for k in 0..=40 {
                let (u, v) = (2.0 * k as f64 / 40.0, (k * 7 % 41) as f64 / 40.0);
                let fast = s.first_partials(u, v);
                let p = s.derivatives(u, v, 1);
                for (f, h) in fast
                    .into_iter()
                    .zip([p.get(0, 0), p.get(1, 0), p.get(0, 1)])
                {
                    assert!(close(f, h), "rational {rational} at ({u}, {v}): {f} vs {h}");
                }
            }
        }
        let (mut a, b) = (surface(true), surface(true));
        a.set_weight(2, 2, 1.3);
        let (pa, pb) = (a.first_partials(0.9, 0.5), b.first_partials(0.9, 0.5));
        assert!(!close(pa[1], pb[1]), "a changed weight must change S_u");
    }
}
