//! Point evaluation with derivatives: Bézier (de Casteljau on hodographs), B-spline (de Boor on
//! local derivative control points), rational projection (quotient rule), tensor-product surfaces
//! as curves of curves, and ERBS blending by the Leibniz rule.
//!
//! Points are fixed-size arrays `[f64; D]`; rational objects use D = 4 homogeneous points
//! (w·x, w·y, w·z, w) and non-rational ones simply carry w = 1, so one code path serves both.

use super::bfunction::BFunction;

/// Homogeneous point (w·x, w·y, w·z, w).
pub type Homogeneous = [f64; 4];
pub type Point3 = [f64; 3];

pub fn add<const D: usize>(a: [f64; D], b: [f64; D]) -> [f64; D] {
    std::array::from_fn(|k| a[k] + b[k])
}

pub fn sub<const D: usize>(a: [f64; D], b: [f64; D]) -> [f64; D] {
    std::array::from_fn(|k| a[k] - b[k])
}

pub fn scale<const D: usize>(s: f64, a: [f64; D]) -> [f64; D] {
    std::array::from_fn(|k| s * a[k])
}

/// (1 − α) a + α b, the affine step of de Casteljau and de Boor.
pub fn lerp<const D: usize>(a: [f64; D], b: [f64; D], alpha: f64) -> [f64; D] {
    std::array::from_fn(|k| (1.0 - alpha) * a[k] + alpha * b[k])
}

/// Binomial coefficient C(n, k) as f64 (exact for the small n used here).
pub fn binomial(n: usize, k: usize) -> f64 {
    if k > n {
        return 0.0;
    }
    let k = k.min(n - k);
    let mut c = 1.0;
    for i in 0..k {
        c = c * (n - i) as f64 / (i + 1) as f64;
    }
    c.round()
}

/// Lift a Cartesian point with weight w to homogeneous coordinates (w·p, w).
pub fn homogeneous(p: Point3, w: f64) -> Homogeneous {
    [w * p[0], w * p[1], w * p[2], w]
}

/// de Casteljau's algorithm: the Bézier curve with control polygon `points` at t ∈ [0,1].
pub fn de_casteljau<const D: usize>(points: &[[f64; D]], t: f64) -> [f64; D] {
    let mut b = points.to_vec();
    for r in 1..b.len() {
        for i in 0..b.len() - r {
            b[i] = lerp(b[i], b[i + 1], t);
        }
    }
    b[0]
}

/// Derivatives 0..=n of a Bézier curve at t. The k-th derivative is the de Casteljau value of the
/// k-th hodograph, whose control points are P^(k)_i = (p−k+1)(P^(k−1)_{i+1} − P^(k−1)_i).
/// Derivatives above the degree are exactly zero.
pub fn bezier_derivatives<const D: usize>(points: &[[f64; D]], t: f64, n: usize) -> Vec<[f64; D]> {
    assert!(!points.is_empty(), "Bézier curve without control points");
    let degree = points.len() - 1;
    let mut out = vec![[0.0; D]; n + 1];
    let mut hodograph = points.to_vec();
    for (k, slot) in out.iter_mut().enumerate().take(degree.min(n) + 1) {
        if k > 0 {
            let factor = (degree - k + 1) as f64;
            for i in 0..hodograph.len() - 1 {
                hodograph[i] = scale(factor, sub(hodograph[i + 1], hodograph[i]));
            }
            hodograph.pop();
        }
        *slot = de_casteljau(&hodograph, t);
    }
    out
}

/// The knot span index i with t ∈ [t_i, t_{i+1}), p ≤ i ≤ n−1, for a degree-p B-spline with n
/// control points. At (or beyond) the domain end t_n the last non-empty span is used; before the
/// domain start the first non-empty span.
pub fn find_span(degree: usize, knots: &[f64], n_points: usize, t: f64) -> usize {
    let (p, n) = (degree, n_points);
    let nonempty = |i: &usize| knots[*i] < knots[*i + 1];
    if t >= knots[n] {
        return (p..n)
            .rev()
            .find(nonempty)
            .expect("B-spline with empty domain");
    }
    match (p..n).rev().find(|&i| knots[i] <= t) {
        Some(i) => i,
        None => (p..n).find(nonempty).expect("B-spline with empty domain"),
    }
}

/// Derivatives 0..=nder of a degree-p B-spline curve at t.
///
/// On the span i (see [`find_span`]) only P_{i−p..=i} matter. Their derivative control points
/// (NURBS Book eq. 3.8, A3.3 `CurveDerivCpts`)
///   P^(k)_j = (p−k+1) (P^(k−1)_{j+1} − P^(k−1)_j) / (t_{j+p+1} − t_{j+k})
/// define the k-th derivative curve, of degree p−k on the knots with k removed at each end; it is
/// evaluated by the de Boor triangle on the same span. All denominators involved contain the
/// non-empty span [t_i, t_{i+1}], so repeated knots (any multiplicity ≤ p+1) are harmless and the
/// values at an interior knot are the right-hand limits.
pub fn bspline_derivatives<const D: usize>(
    degree: usize,
    knots: &[f64],
    points: &[[f64; D]],
    t: f64,
    nder: usize,
) -> Vec<[f64; D]> {
    let p = degree;
    assert_eq!(knots.len(), points.len() + p + 1, "knot vector length");
    let i = find_span(p, knots, points.len(), t);
    let mut out = vec![[0.0; D]; nder + 1];
    let mut cpts: Vec<[f64; D]> = points[i - p..=i].to_vec();
    for (k, slot) in out.iter_mut().enumerate().take(p.min(nder) + 1) {
        if k > 0 {
            let factor = (p - k + 1) as f64;
            for j in 0..=p - k {
                let denominator = knots[i + j + 1] - knots[i - p + j + k];
                cpts[j] = scale(factor / denominator, sub(cpts[j + 1], cpts[j]));
            }
            cpts.pop();
        }
        // de Boor on the derivative curve: degree q = p − k, its knot T_m = t_{m+k}, span i − k.
        let q = p - k;
        let mut d = cpts.clone();
        for r in 1..=q {
            for j in (r..=q).rev() {
                let lo = knots[i - p + k + j];
                let hi = knots[i + 1 + j - r];
                d[j] = lerp(d[j - 1], d[j], (t - lo) / (hi - lo));
            }
        }
        *slot = d[q];
    }
    out
}

/// Parameterisation of one direction of a curve or tensor-product surface.
#[derive(Clone, Debug, PartialEq)]
pub enum Basis {
    /// Bernstein basis on [0, 1]; the degree is the point count minus one.
    Bezier,
    /// B-spline basis of the given degree and knot vector.
    BSpline { degree: usize, knots: Vec<f64> },
}

impl Basis {
    /// Parameter domain for `n_points` control points: [0,1] or [t_d, t_n].
    pub fn domain(&self, n_points: usize) -> (f64, f64) {
        match self {
            Basis::Bezier => (0.0, 1.0),
            Basis::BSpline { degree, knots } => (knots[*degree], knots[n_points]),
        }
    }

    /// Derivatives 0..=n of the curve with control points `points` at t.
    pub fn derivatives<const D: usize>(
        &self,
        points: &[[f64; D]],
        t: f64,
        n: usize,
    ) -> Vec<[f64; D]> {
        match self {
            Basis::Bezier => bezier_derivatives(points, t, n),
            Basis::BSpline { degree, knots } => bspline_derivatives(*degree, knots, points, t, n),
        }
    }
}

/// Cartesian derivatives from homogeneous ones (NURBS Book A4.2 `RatCurveDerivs`):
///   C^(k) = (A^(k) − Σ_{i=1..k} C(k,i) w^(i) C^(k−i)) / w.
pub fn project_curve_derivatives(h: &[Homogeneous]) -> Vec<Point3> {
    let mut out: Vec<Point3> = Vec::with_capacity(h.len());
    for k in 0..h.len() {
        let mut v = [h[k][0], h[k][1], h[k][2]];
        for i in 1..=k {
            v = sub(v, scale(binomial(k, i) * h[i][3], out[k - i]));
        }
        out.push(scale(1.0 / h[0][3], v));
    }
    out
}

/// Cartesian mixed partials from homogeneous ones (NURBS Book A4.4 `RatSurfaceDerivs`);
/// `h[a][b]` = ∂^{a+b}/∂u^a∂v^b of (w·S, w).
pub fn project_surface_derivatives(h: &[Vec<Homogeneous>]) -> Vec<Vec<Point3>> {
    let (na, nb) = (h.len(), h[0].len());
    let w = |a: usize, b: usize| h[a][b][3];
    let mut s = vec![vec![[0.0; 3]; nb]; na];
    for k in 0..na {
        for l in 0..nb {
            let mut v = [h[k][l][0], h[k][l][1], h[k][l][2]];
            for j in 1..=l {
                v = sub(v, scale(binomial(l, j) * w(0, j), s[k][l - j]));
            }
            for i in 1..=k {
                v = sub(v, scale(binomial(k, i) * w(i, 0), s[k - i][l]));
                let mut inner = [0.0; 3];
                for j in 1..=l {
                    inner = add(inner, scale(binomial(l, j) * w(i, j), s[k - i][l - j]));
                }
                v = sub(v, scale(binomial(k, i), inner));
            }
            s[k][l] = scale(1.0 / w(0, 0), v);
        }
    }
    s
}

/// Tensor-product surface as a curve of curves: first, for every control column j, the
/// u-derivatives 0..=n of the u-curve through points[·][j] at u; then, for every order a, the
/// v-derivatives 0..=n of the v-curve through those values at v. Returns `[a][b]`.
pub fn tensor_derivatives<const D: usize>(
    basis_u: &Basis,
    basis_v: &Basis,
    points: &[Vec<[f64; D]>],
    u: f64,
    v: f64,
    n: usize,
) -> Vec<Vec<[f64; D]>> {
    let columns = u_stage(basis_u, points, u, n);
    v_stage(basis_v, &columns, v, n)
}

/// `[a][j]`: ∂^a/∂u^a of the u-curve through column j of `points[i][j]`, at u.
pub fn u_stage<const D: usize>(
    basis_u: &Basis,
    points: &[Vec<[f64; D]>],
    u: f64,
    n: usize,
) -> Vec<Vec<[f64; D]>> {
    let nv = points[0].len();
    let mut out = vec![vec![[0.0; D]; nv]; n + 1];
    for j in 0..nv {
        let column: Vec<[f64; D]> = points.iter().map(|row| row[j]).collect();
        for (a, value) in basis_u.derivatives(&column, u, n).into_iter().enumerate() {
            out[a][j] = value;
        }
    }
    out
}

/// `[a][b]`: v-derivatives 0..=n of each row of `u_values[a][j]` at v.
pub fn v_stage<const D: usize>(
    basis_v: &Basis,
    u_values: &[Vec<[f64; D]>],
    v: f64,
    n: usize,
) -> Vec<Vec<[f64; D]>> {
    u_values
        .iter()
        .map(|row| basis_v.derivatives(row, v, n))
        .collect()
}

/// The ERBS interval i (1 ≤ i ≤ n−1) with t ∈ [t_i, t_{i+1}) for knots t_0..t_{n+1};
/// the domain end t_n (and beyond) belongs to the last interval n−1.
pub fn erbs_interval(knots: &[f64], t: f64) -> usize {
    let n = knots.len() - 2;
    (1..n).rev().find(|&i| knots[i] <= t).unwrap_or(1)
}

/// The blending-weight derivatives on [t_i, t_{i+1}): `(left, right)` with
/// left[r] = d^r/dt^r (1 − B(w)) and right[r] = d^r/dt^r B(w), w = (t − t_i)/(t_{i+1} − t_i).
pub fn erbs_weights(
    bfunction: BFunction,
    knots: &[f64],
    i: usize,
    t: f64,
    n: usize,
) -> (Vec<f64>, Vec<f64>) {
    let length = knots[i + 1] - knots[i];
    let w = (t - knots[i]) / length;
    let b = bfunction.derivatives(w, n);
    let mut right = Vec::with_capacity(n + 1);
    let mut factor = 1.0;
    for (r, br) in b.iter().enumerate() {
        if r > 0 {
            factor /= length;
        }
        right.push(br * factor);
    }
    let left = right
        .iter()
        .enumerate()
        .map(|(r, &x)| if r == 0 { 1.0 - x } else { -x })
        .collect();
    (left, right)
}

/// Derivatives 0..=n (w.r.t. t) of local Bézier curve l, whose parameter [0,1] is mapped
/// linearly onto [t_l, t_{l+2}]: the chain rule contributes (t_{l+2} − t_l)^(−k).
pub fn erbs_local_curve_derivatives(
    knots: &[f64],
    l: usize,
    points: &[Point3],
    t: f64,
    n: usize,
) -> Vec<Point3> {
    let length = knots[l + 2] - knots[l];
    let s = (t - knots[l]) / length;
    let mut d = bezier_derivatives(points, s, n);
    let mut factor = 1.0;
    for (k, dk) in d.iter_mut().enumerate() {
        if k > 0 {
            factor /= length;
        }
        *dk = scale(factor, *dk);
    }
    d
}

/// ERBS curve derivatives 0..=n at t by the Leibniz rule
///   c^(r) = Σ_k C(r,k) [ (1−B)^(k) c_{i−1}^(r−k) + B^(k) c_i^(r−k) ].
pub fn erbs_curve_derivatives(
    bfunction: BFunction,
    knots: &[f64],
    locals: &[Vec<Point3>],
    t: f64,
    n: usize,
) -> Vec<Point3> {
    let i = erbs_interval(knots, t);
    let (left, right) = erbs_weights(bfunction, knots, i, t, n);
    let c_left = erbs_local_curve_derivatives(knots, i - 1, &locals[i - 1], t, n);
    let c_right = erbs_local_curve_derivatives(knots, i, &locals[i], t, n);
    (0..=n)
        .map(|r| {
            let mut v = [0.0; 3];
            for k in 0..=r {
                let c = binomial(r, k);
                v = add(v, scale(c * left[k], c_left[r - k]));
                v = add(v, scale(c * right[k], c_right[r - k]));
            }
            v
        })
        .collect()
}

/// Mixed partials `[α][β]`, 0..=n each, of local Bézier patch (k,l) over
/// [u_k, u_{k+2}] × [v_l, v_{l+2}] (points `[a][b]`, a along u), w.r.t. (u, v).
pub fn erbs_local_patch_derivatives(
    knots: [&[f64]; 2],
    (k, l): (usize, usize),
    points: &[Vec<Point3>],
    (u, v): (f64, f64),
    n: usize,
) -> Vec<Vec<Point3>> {
    let (lu, lv) = (knots[0][k + 2] - knots[0][k], knots[1][l + 2] - knots[1][l]);
    let s = (u - knots[0][k]) / lu;
    let r = (v - knots[1][l]) / lv;
    let mut d = tensor_derivatives(&Basis::Bezier, &Basis::Bezier, points, s, r, n);
    let mut fu = 1.0;
    for (a, row) in d.iter_mut().enumerate() {
        if a > 0 {
            fu /= lu;
        }
        let mut fv = 1.0;
        for (b, x) in row.iter_mut().enumerate() {
            if b > 0 {
                fv /= lv;
            }
            *x = scale(fu * fv, *x);
        }
    }
    d
}

/// ERBS surface mixed partials `[a][b]`, 0..=n each, at (u, v):
///   ∂^{a+b}S = Σ_{k,l} Σ_{α≤a} Σ_{β≤b} C(a,α) C(b,β) B_k^(α)(u) B_l^(β)(v) ∂^{a−α,b−β} s_kl,
/// with k ∈ {i−1, i}, l ∈ {j−1, j} on [u_i, u_{i+1}) × [v_j, v_{j+1}).
pub fn erbs_surface_derivatives(
    bfunction: BFunction,
    knots: [&[f64]; 2],
    locals: &[Vec<Vec<Vec<Point3>>>],
    (u, v): (f64, f64),
    n: usize,
) -> Vec<Vec<Point3>> {
    let i = erbs_interval(knots[0], u);
    let j = erbs_interval(knots[1], v);
    let (ul, ur) = erbs_weights(bfunction, knots[0], i, u, n);
    let (vl, vr) = erbs_weights(bfunction, knots[1], j, v, n);
    let mut out = vec![vec![[0.0; 3]; n + 1]; n + 1];
    for (k, uw) in [(i - 1, &ul), (i, &ur)] {
        for (l, vw) in [(j - 1, &vl), (j, &vr)] {
            let d = erbs_local_patch_derivatives(knots, (k, l), &locals[k][l], (u, v), n);
            for a in 0..=n {
                for b in 0..=n {
                    let mut acc = [0.0; 3];
                    for alpha in 0..=a {
                        for beta in 0..=b {
                            let c = binomial(a, alpha) * binomial(b, beta) * uw[alpha] * vw[beta];
                            acc = add(acc, scale(c, d[a - alpha][b - beta]));
                        }
                    }
                    out[a][b] = add(out[a][b], acc);
                }
            }
        }
    }
    out
}
