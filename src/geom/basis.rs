//! B-spline basis functions and the B-spline-Hermite matrix.
//!
//! Two independent routes to the same numbers are kept on purpose: the factor-matrix construction
//! of Lakså's paper ([`HermiteMatrix::bspline`]) and the NURBS Book's DersBasisFuns
//! ([`ders_basis_funs`]); tests cross-check them.

use super::knots::KnotVector;

/// The B-spline-Hermite matrix M_{d,i}(t): (d+1)×(d+1), row r holds the r-th derivatives of the
/// d+1 basis functions non-zero on span [t_i, t_{i+1}); column k belongs to control point i−d+k.
/// For a Bézier knot vector it is the Bernstein-Hermite matrix.
#[derive(Debug, Clone, PartialEq)]
pub struct HermiteMatrix {
    degree: usize,
    span: usize,
    m: Vec<f64>,
}

impl HermiteMatrix {
    /// M_{d,i}(t) for `span` i (as returned by FindSpan), built with the paper's factorisation
    /// c(t) = T_1(t)…T_d(t)·c and D^r = d!/(d−r)! · T_1…T_{d−r} T'_{d−r+1}…T'_d.
    #[must_use]
    pub fn bspline(knots: &KnotVector, degree: usize, span: usize, t: f64) -> Self {
        let mut m = vec![0.0; (degree + 1) * (degree + 1)];
        hermite_into(knots, degree, span, t, &mut m);
        Self { degree, span, m }
    }

    /// Bernstein-Hermite matrix for a degree-d Bézier curve on [a, b] at t.
    #[must_use]
    pub fn bernstein(degree: usize, a: f64, b: f64, t: f64) -> Self {
        let knots = KnotVector::bezier(degree, a, b);
        Self::bspline(&knots, degree, degree, t)
    }

    #[must_use]
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// The span index i this matrix was evaluated for; column k multiplies control point i−d+k.
    #[must_use]
    pub fn span(&self) -> usize {
        self.span
    }

    /// Entry (r, k): r-th derivative of the k-th active basis function.
    #[inline]
    #[must_use]
    pub fn get(&self, r: usize, k: usize) -> f64 {
        self.m[r * (self.degree + 1) + k]
    }

    /// Row r: r-th derivatives of the active basis functions.
    #[must_use]
    pub fn row(&self, r: usize) -> &[f64] {
        let w = self.degree + 1;
        &self.m[r * w..(r + 1) * w]
    }

    /// Row-major storage, (d+1)² values.
    #[must_use]
    pub fn as_slice(&self) -> &[f64] {
        &self.m
    }
}

/// Writes M_{d,i}(t) row-major into `out` ((d+1)² values). This is the routine the
/// pre-evaluation engine calls once per sample parameter.
///
/// Row vector b_k holds the degree-k basis functions active on the span; b_k = b_{k−1}·T_k(t)
/// with T_k[j][j] = 1 − w_{k,s}, T_k[j][j+1] = w_{k,s}, s = i−k+1+j and
/// w_{k,s}(t) = (t − t_s)/(t_{s+k} − t_s). Derivatives replace trailing factors by their constant
/// derivatives T'_k (entries ∓δ_{k,s}, δ_{k,s} = 1/(t_{s+k} − t_s)). Every knot interval used
/// contains the non-empty span, so no division by zero can occur.
pub fn hermite_into(knots: &[f64], degree: usize, span: usize, t: f64, out: &mut [f64]) {
    hermite_rows_into(knots, degree, span, t, degree + 1, out);
}

/// The first `rows` rows of M_{d,i}(t) (derivative orders 0..rows), row-major into
/// `out[..rows·(d+1)]`: what pre-evaluation keeps when fewer derivatives are wanted.
pub fn hermite_rows_into(
    knots: &[f64],
    degree: usize,
    span: usize,
    t: f64,
    rows: usize,
    out: &mut [f64],
) {
    let d = degree;
    let w = d + 1;
    debug_assert!(rows <= w && out.len() >= rows * w);
    // Scratch: tri[k*w + j] = b_k[j] (degree-k values), plus two work rows for derivatives.
    let mut stack = [0.0f64; STACK_SCRATCH];
    let mut heap;
    let scratch: &mut [f64] = if w * (w + 2) <= STACK_SCRATCH {
        &mut stack[..w * (w + 2)]
    } else {
        heap = vec![0.0; w * (w + 2)];
        &mut heap
    };
    let (tri, work) = scratch.split_at_mut(w * w);
    let (cur, next) = work.split_at_mut(w);
    tri[0] = 1.0;
    for k in 1..=d {
        let mut carry = 0.0;
        for j in 0..k {
            let s = span + 1 + j - k;
            let wk = (t - knots[s]) / (knots[s + k] - knots[s]);
            let v = tri[(k - 1) * w + j];
            tri[k * w + j] = carry + (1.0 - wk) * v;
            carry = wk * v;
        }
        tri[k * w + k] = carry;
    }
    out[..w].copy_from_slice(&tri[d * w..d * w + w]);
    // Row r: start from b_{d−r} and apply T'_{d−r+1} … T'_d, then scale by d!/(d−r)!.
    for r in 1..rows {
        let base = d - r;
        cur[..=base].copy_from_slice(&tri[base * w..base * w + base + 1]);
        let mut scale = 1.0;
        for k in (base + 1)..=d {
            scale *= k as f64;
            // (v·T'_k)[j] = −δ_{k,s_j}·v_j + δ_{k,s_{j−1}}·v_{j−1}, s_j = i−k+1+j.
            let mut carry = 0.0;
            for j in 0..k {
                let s = span + 1 + j - k;
                let v = cur[j] / (knots[s + k] - knots[s]);
                next[j] = carry - v;
                carry = v;
            }
            next[k] = carry;
            cur[..=k].copy_from_slice(&next[..=k]);
        }
        for j in 0..w {
            out[r * w + j] = scale * cur[j];
        }
        // The basis functions sum to 1, so every derivative row sums to 0. Rounding leaves a
        // residual that locally constant weights (w' = Σ N_k' w_k) turn into noise multiplied
        // into higher derivatives by the quotient rule; make the sum, taken in the order dot
        // products take it, exactly 0 by giving the residual to the last entry.
        let row = &mut out[r * w..(r + 1) * w];
        let partial = row[..w - 1].iter().fold(0.0, |acc, &x| acc + x);
        row[w - 1] = -partial;
    }
}

/// Scratch size (f64s) kept on the stack by [`hermite_into`]; enough for degree 14.
const STACK_SCRATCH: usize = 15 * 17;

/// BasisFuns (NURBS Book A2.2): the d+1 non-vanishing basis functions N_{i−d..=i, d}(t).
#[must_use]
pub fn basis_funs(knots: &[f64], degree: usize, span: usize, t: f64) -> Vec<f64> {
    let mut n = vec![0.0; degree + 1];
    basis_funs_into(knots, degree, span, t, &mut n);
    n
}

/// [`basis_funs`] into `n` (d+1 entries), without allocating: callers that evaluate at many
/// parameters (the shape guard) keep one buffer. A2.2's `left[j]` and `right[j]` are t minus
/// a knot and a knot minus t, read where they are used (the same values bit for bit).
pub fn basis_funs_into(knots: &[f64], degree: usize, span: usize, t: f64, n: &mut [f64]) {
    let left = |j: usize| t - knots[span + 1 - j];
    let right = |j: usize| knots[span + j] - t;
    n[0] = 1.0;
    for j in 1..=degree {
        let mut saved = 0.0;
        for r in 0..j {
            let temp = n[r] / (right(r + 1) + left(j - r));
            n[r] = saved + right(r + 1) * temp;
            saved = left(j - r) * temp;
        }
        n[j] = saved;
    }
}

/// DersBasisFuns (NURBS Book A2.3): `ders[k][j]` is the k-th derivative of N_{i−d+j, d} at t,
/// for k = 0..=n_ders (rows above the degree are zero).
#[must_use]
pub fn ders_basis_funs(
    knots: &[f64],
    degree: usize,
    span: usize,
    t: f64,
    n_ders: usize,
) -> Vec<Vec<f64>> {
    let p = degree;
    let mut ndu = vec![vec![0.0; p + 1]; p + 1];
    let mut left = vec![0.0; p + 1];
    let mut right = vec![0.0; p + 1];
    ndu[0][0] = 1.0;
    for j in 1..=p {
        left[j] = t - knots[span + 1 - j];
        right[j] = knots[span + j] - t;
        let mut saved = 0.0;
        for r in 0..j {
            ndu[j][r] = right[r + 1] + left[j - r];
            let temp = ndu[r][j - 1] / ndu[j][r];
            ndu[r][j] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        ndu[j][j] = saved;
    }
    let mut ders = vec![vec![0.0; p + 1]; n_ders + 1];
    for j in 0..=p {
        ders[0][j] = ndu[j][p];
    }
    let mut a = vec![vec![0.0; p + 1]; 2];
    for r in 0..=p {
        let (mut s1, mut s2) = (0usize, 1usize);
        a[0][0] = 1.0;
        for k in 1..=n_ders.min(p) {
            let mut d = 0.0;
            let rk = r as isize - k as isize;
            let pk = p - k;
            if r >= k {
                a[s2][0] = a[s1][0] / ndu[pk + 1][rk as usize];
                d = a[s2][0] * ndu[rk as usize][pk];
            }
            let j1 = if rk >= -1 { 1 } else { (-rk) as usize };
            let j2 = if r as isize - 1 <= pk as isize {
                k - 1
            } else {
                p - r
            };
            for j in j1..=j2 {
                let idx = (rk + j as isize) as usize;
                a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][idx];
                d += a[s2][j] * ndu[idx][pk];
            }
            if r <= pk {
                a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r];
                d += a[s2][k] * ndu[r][pk];
            }
            ders[k][r] = d;
            std::mem::swap(&mut s1, &mut s2);
        }
    }
    let mut fac = p as f64;
    for k in 1..=n_ders.min(p) {
        for j in 0..=p {
            ders[k][j] *= fac;
        }
        fac *= (p - k) as f64;
    }
    ders
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
    }

    #[test]
    fn bernstein_hermite_cubic_at_one_third() {
        let m = HermiteMatrix::bernstein(3, 0.0, 1.0, 1.0 / 3.0);
        let (u, v) = (1.0 / 3.0, 2.0 / 3.0);
        let expect0 = [v * v * v, 3.0 * u * v * v, 3.0 * u * u * v, u * u * u];
        let expect1 = [
            -3.0 * v * v,
            3.0 * v * v - 6.0 * u * v,
            6.0 * u * v - 3.0 * u * u,
            3.0 * u * u,
        ];
        for k in 0..4 {
            assert!(close(m.get(0, k), expect0[k], 1e-15));
            assert!(close(m.get(1, k), expect1[k], 1e-14));
        }
        // Third derivative of cubic Bernstein polynomials: 6·(−1, 3, −3, 1).
        for (k, e) in [-6.0, 18.0, -18.0, 6.0].iter().enumerate() {
            assert!(close(m.get(3, k), *e, 1e-13));
        }
    }

    #[test]
    fn hermite_equals_ders_basis_funs_on_irregular_knots() {
        let knots = KnotVector::for_bspline(
            vec![0.0, 0.0, 0.0, 0.3, 0.3, 1.1, 2.0, 2.5, 4.0, 4.0, 4.0],
            2,
            8,
        )
        .unwrap();
        for &t in &[0.0, 0.1, 0.3, 0.7, 1.1, 2.2, 3.9, 4.0] {
            let span = knots.find_span(2, 8, t);
            let m = HermiteMatrix::bspline(&knots, 2, span, t);
            let d = ders_basis_funs(&knots, 2, span, t, 2);
            let b = basis_funs(&knots, 2, span, t);
            for r in 0..=2 {
                for k in 0..=2 {
                    assert!(close(m.get(r, k), d[r][k], 1e-13), "t={t} r={r} k={k}");
                }
            }
            for k in 0..=2 {
                assert!(close(m.get(0, k), b[k], 1e-15));
            }
        }
    }

    #[test]
    fn high_degree_partition_of_unity_and_derivative_sums() {
        for degree in [0usize, 1, 5, 10, 16, 18] {
            let n = degree + 7;
            let knots = KnotVector::clamped_uniform(degree, n, -1.0, 3.0);
            for &t in &[-1.0, -0.37, 0.5, 1.999, 3.0] {
                let span = knots.find_span(degree, n, t);
                let m = HermiteMatrix::bspline(&knots, degree, span, t);
                let sum0: f64 = m.row(0).iter().sum();
                assert!(close(sum0, 1.0, 1e-14), "degree {degree} t {t}: {sum0}");
                for r in 1..=degree {
                    let scale: f64 = m.row(r).iter().map(|x| x.abs()).sum();
                    let s: f64 = m.row(r).iter().sum();
                    assert!(
                        s.abs() <= 1e-13 * scale.max(1.0),
                        "degree {degree} r {r}: {s}"
                    );
                }
            }
        }
    }
}
