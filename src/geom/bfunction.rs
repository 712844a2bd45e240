//! B-functions: the smooth monotone maps B: [0,1] → [0,1] (B(0)=0, B(1)=1, B(1−t)=1−B(t)) that
//! blend neighbouring local curves in an ERBS. The expo-rational one is the default; the others are
//! the alternatives of the paper's family (polynomial, trigonometric, rational).

use std::sync::LazyLock;

/// A B-function with derivatives.
pub trait BFunction {
    /// Writes B(t), B'(t), …, B^(n)(t) into `out[0..=n]`, n = `out.len() − 1`. Outside [0,1] the
    /// function is constant (0 below, 1 above) and every derivative is 0.
    fn derivatives(&self, t: f64, out: &mut [f64]);

    /// B(t).
    fn value(&self, t: f64) -> f64 {
        let mut v = [0.0];
        self.derivatives(t, &mut v);
        v[0]
    }
}

/// The B-functions a scene can name (`"bfunction"` field); `ExpoRational` is the default.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub enum BFunctionKind {
    /// B(t) = S_F ∫_0^t exp(−(s−½)²/(s(1−s))) ds — C^∞ with all derivatives 0 at both ends.
    #[default]
    ExpoRational,
    /// 3t² − 2t³ (the incomplete-beta B-function of order 2; C¹ blending).
    Smoothstep,
    /// 10t³ − 15t⁴ + 6t⁵ (order 3; C² blending).
    Smootherstep,
    /// sin²(πt/2).
    Trigonometric,
    /// t² / (t² + (1−t)²).
    Rational,
}

impl BFunctionKind {
    /// Every kind, in the order they are documented.
    pub const ALL: [BFunctionKind; 5] = [
        Self::ExpoRational,
        Self::Smoothstep,
        Self::Smootherstep,
        Self::Trigonometric,
        Self::Rational,
    ];

    /// The name used in scene files.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::ExpoRational => "expo",
            Self::Smoothstep => "smoothstep",
            Self::Smootherstep => "smootherstep",
            Self::Trigonometric => "trigonometric",
            Self::Rational => "rational",
        }
    }

    /// Parses a scene-file name.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }
}

impl BFunction for BFunctionKind {
    fn derivatives(&self, t: f64, out: &mut [f64]) {
        if out.is_empty() {
            return;
        }
        if t <= 0.0 || t >= 1.0 || t.is_nan() {
            let at_end = t >= 1.0;
            // Polynomial, trigonometric and rational kinds keep their one-sided derivatives at the
            // closed ends; beyond them everything is constant.
            if (t == 0.0 || t == 1.0) && *self != Self::ExpoRational {
                return closed_form(*self, t, out);
            }
            out.fill(0.0);
            out[0] = if at_end { 1.0 } else { 0.0 };
            return;
        }
        match self {
            Self::ExpoRational => expo_rational(t, out),
            _ => closed_form(*self, t, out),
        }
    }
}

/// Derivatives of the polynomial, trigonometric and rational B-functions on [0, 1].
fn closed_form(kind: BFunctionKind, t: f64, out: &mut [f64]) {
    match kind {
        BFunctionKind::Smoothstep => polynomial(&[0.0, 0.0, 3.0, -2.0], t, out),
        BFunctionKind::Smootherstep => polynomial(&[0.0, 0.0, 0.0, 10.0, -15.0, 6.0], t, out),
        BFunctionKind::Trigonometric => {
            // sin²(πt/2) = (1 − cos πt)/2; d^k/dt^k cos(πt) = π^k cos(πt + kπ/2).
            let pi = std::f64::consts::PI;
            out[0] = 0.5 * (1.0 - (pi * t).cos());
            let mut pk = 1.0;
            for (k, o) in out.iter_mut().enumerate().skip(1) {
                pk *= pi;
                *o = -0.5 * pk * (pi * t + k as f64 * std::f64::consts::FRAC_PI_2).cos();
            }
        }
        BFunctionKind::Rational => {
            // B = p/q, p = t², q = t² + (1−t)² = 2t² − 2t + 1; quotient rule
            // B^(k) = (p^(k) − Σ_{i=1..k} C(k,i) q^(i) B^(k−i)) / q.
            let p = [t * t, 2.0 * t, 2.0];
            let q = [2.0 * t * t - 2.0 * t + 1.0, 4.0 * t - 2.0, 4.0];
            for k in 0..out.len() {
                let mut v = if k < 3 { p[k] } else { 0.0 };
                for i in 1..=k.min(2) {
                    v -= super::point::binomial(k, i) * q[i] * out[k - i];
                }
                out[k] = v / q[0];
            }
        }
        BFunctionKind::ExpoRational => unreachable!("expo-rational has no polynomial closed form"),
    }
}

/// Derivatives of the polynomial Σ c_i t^i.
fn polynomial(coeffs: &[f64], t: f64, out: &mut [f64]) {
    for (k, o) in out.iter_mut().enumerate() {
        // d^k/dt^k t^i = i!/(i−k)! t^(i−k); Horner over the surviving terms.
        let mut v = 0.0;
        for i in (k..coeffs.len()).rev() {
            let mut f = 1.0;
            for j in (i - k + 1)..=i {
                f *= j as f64;
            }
            v = v * t + coeffs[i] * f;
        }
        *o = v;
    }
}

/// S_F = 1 / ∫_0^1 exp(−(s−½)²/(s(1−s))) ds, to f64 precision. (Computed with 50-digit
/// quadrature: 1.657137679738210303328…; the original design notes printed the 16th digit as
/// …105.)
pub const EXPO_RATIONAL_SCALE: f64 = 1.657_137_679_738_210_3;

/// φ(s) = exp(g(s)), g(s) = −(s−½)²/(s(1−s)) = 1 − ¼(1/s + 1/(1−s)).
#[inline]
fn expo_phi(s: f64) -> f64 {
    (1.0 - 0.25 * (1.0 / s + 1.0 / (1.0 - s))).exp()
}

fn expo_rational(t: f64, out: &mut [f64]) {
    out[0] = expo_integral(t);
    if out.len() == 1 {
        return;
    }
    let phi = expo_phi(t);
    if phi == 0.0 {
        // Underflow: φ and all its derivatives are below the smallest f64 here; computing the
        // derivative polynomial would risk 0·∞.
        out[1..].fill(0.0);
        return;
    }
    // g^(k)(t) = −¼ k! ((−1)^k / t^(k+1) + 1/(1−t)^(k+1)), k ≥ 1.
    let n = out.len() - 1;
    let mut g = vec![0.0; n + 1];
    let (mut fact, mut it, mut iu) = (1.0, 1.0 / t, 1.0 / (1.0 - t));
    let (ti, ui) = (it, iu);
    for (k, gk) in g.iter_mut().enumerate().skip(1) {
        fact *= k as f64;
        it *= ti;
        iu *= ui;
        let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
        *gk = -0.25 * fact * (sign * it + iu);
    }
    // φ' = g'φ ⇒ φ^(m+1) = Σ_{j=0..m} C(m,j) g^(j+1) φ^(m−j).
    let mut phis = vec![0.0; n];
    phis[0] = phi;
    for m in 0..n.saturating_sub(1) {
        let mut v = 0.0;
        for j in 0..=m {
            v += super::point::binomial(m, j) * g[j + 1] * phis[m - j];
        }
        phis[m + 1] = v;
    }
    for k in 1..=n {
        out[k] = EXPO_RATIONAL_SCALE * phis[k - 1];
    }
}

/// B(t) for the expo-rational B-function, absolute error ≈ 1e-16 and relative error ≈ 1e-15
/// wherever B(t) > 1e-25.
///
/// By symmetry only t ≤ ½ is integrated. The flat tail near 0 is integrated after the
/// substitution u = 1/s, u = 1/t + 4x, which turns φ(s)ds into e^{−x}·(smooth factor)dx with the
/// e^{−1/(4t)} magnitude factored out (relative accuracy in the tail); [t0, t] uses plain
/// Gauss–Legendre panels where φ is well resolved.
fn expo_integral(t: f64) -> f64 {
    if t > 0.5 {
        return 1.0 - expo_integral(1.0 - t);
    }
    const T0: f64 = 0.1;
    let raw = if t <= T0 {
        expo_tail(t)
    } else {
        let panels = ((t - T0) / 0.1).ceil().max(1.0) as usize;
        let h = (t - T0) / panels as f64;
        let mut sum = *EXPO_TAIL_T0;
        for p in 0..panels {
            let a = T0 + h * p as f64;
            let b = if p + 1 == panels { t } else { a + h };
            sum += gauss_legendre(a, b, expo_phi);
        }
        sum
    };
    EXPO_RATIONAL_SCALE * raw
}

static EXPO_TAIL_T0: LazyLock<f64> = LazyLock::new(|| expo_tail(0.1));

/// ∫_0^t φ(s) ds for t ≤ 0.1 via s = 1/(1/t + 4x).
fn expo_tail(t: f64) -> f64 {
    let big_u = 1.0 / t;
    // φ(1/u)/u² = exp(¾ − u/4 − 1/(4(u−1)))/u², valid for u > 1; with u = U + 4x and the factor
    // e^{−U/4} taken out the integrand is 4·exp(¾ − x − 1/(4(U+4x−1)))/(U+4x)².
    let f = |x: f64| {
        let u = big_u + 4.0 * x;
        4.0 * (0.75 - x - 0.25 / (u - 1.0)).exp() / (u * u)
    };
    const EDGES: [f64; 7] = [0.0, 1.0, 2.5, 5.0, 10.0, 20.0, 40.0];
    let sum: f64 = EDGES
        .windows(2)
        .map(|e| gauss_legendre(e[0], e[1], f))
        .sum();
    (-0.25 * big_u).exp() * sum
}

/// 20-point Gauss–Legendre rule on [a, b].
fn gauss_legendre(a: f64, b: f64, f: impl Fn(f64) -> f64) -> f64 {
    let (nodes, weights) = &*GAUSS_LEGENDRE_20;
    let half = 0.5 * (b - a);
    let mid = 0.5 * (a + b);
    let mut s = 0.0;
    for (x, w) in nodes.iter().zip(weights) {
        s += w * f(mid + half * x);
    }
    s * half
}

/// Nodes and weights of the 20-point Gauss–Legendre rule on [−1, 1], by Newton iteration on
/// P_20 (converges to machine precision from the Chebyshev-like initial guesses).
static GAUSS_LEGENDRE_20: LazyLock<([f64; 20], [f64; 20])> = LazyLock::new(|| {
    const N: usize = 20;
    let mut x = [0.0; N];
    let mut w = [0.0; N];
    for i in 0..N / 2 {
        let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (N as f64 + 0.5)).cos();
        let mut dp = 0.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, z);
            for k in 2..=N {
                let p2 = ((2 * k - 1) as f64 * z * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            dp = N as f64 * (z * p1 - p0) / (z * z - 1.0);
            let dz = p1 / dp;
            z -= dz;
            if dz.abs() < 1e-17 {
                break;
            }
        }
        x[i] = -z;
        x[N - 1 - i] = z;
        let wi = 2.0 / ((1.0 - z * z) * dp * dp);
        w[i] = wi;
        w[N - 1 - i] = wi;
    }
    (x, w)
});

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expo_rational_normalisation_and_symmetry() {
        let b = BFunctionKind::ExpoRational;
        assert_eq!(b.value(0.0), 0.0);
        assert_eq!(b.value(1.0), 1.0);
        assert!(
            (b.value(0.5) - 0.5).abs() <= 2.0 * f64::EPSILON,
            "{}",
            b.value(0.5) - 0.5
        );
        // B(1) computed through the integral, not the clamp.
        assert!((b.value(1.0 - 1e-15) - 1.0).abs() < 1e-15);
        let one = EXPO_RATIONAL_SCALE * 2.0 * expo_integral_raw_half();
        assert!((one - 1.0).abs() <= 4.0 * f64::EPSILON, "{one}");
        for i in 1..100 {
            let t = i as f64 / 100.0;
            assert!(
                (b.value(t) + b.value(1.0 - t) - 1.0).abs() <= 2.0 * f64::EPSILON,
                "t={t}"
            );
        }
    }

    fn expo_integral_raw_half() -> f64 {
        expo_integral(0.5) / EXPO_RATIONAL_SCALE
    }

    #[test]
    fn derivatives_match_finite_differences() {
        for kind in BFunctionKind::ALL {
            for &t in &[0.05, 0.2, 0.37, 0.5, 0.81, 0.97] {
                let mut d = [0.0; 6];
                kind.derivatives(t, &mut d);
                let h = 1e-4;
                for k in 0..5 {
                    let mut p = [0.0; 6];
                    let mut m = [0.0; 6];
                    let mut p2 = [0.0; 6];
                    let mut m2 = [0.0; 6];
                    kind.derivatives(t + h, &mut p);
                    kind.derivatives(t - h, &mut m);
                    kind.derivatives(t + 2.0 * h, &mut p2);
                    kind.derivatives(t - 2.0 * h, &mut m2);
                    // Fourth-order central difference of the k-th derivative.
                    let fd = (-p2[k] + 8.0 * p[k] - 8.0 * m[k] + m2[k]) / (12.0 * h);
                    let scale = d[k + 1].abs().max(d[k].abs()).max(1.0);
                    assert!(
                        (fd - d[k + 1]).abs() <= 1e-6 * scale,
                        "{kind:?} t={t} order {}: {fd} vs {}",
                        k + 1,
                        d[k + 1]
                    );
                }
            }
        }
    }

    #[test]
    fn b_function_family_properties() {
        for kind in BFunctionKind::ALL {
            assert_eq!(BFunctionKind::from_name(kind.name()), Some(kind));
            assert!(kind.value(0.0).abs() < 1e-16, "{kind:?}");
            assert!((kind.value(1.0) - 1.0).abs() < 1e-15, "{kind:?}");
            let mut prev = 0.0;
            for i in 1..=64 {
                let t = i as f64 / 64.0;
                let v = kind.value(t);
                assert!(v >= prev, "{kind:?} is not monotone at {t}");
                assert!(
                    (v + kind.value(1.0 - t) - 1.0).abs() < 1e-15,
                    "{kind:?} symmetry"
                );
                prev = v;
            }
        }
    }

    #[test]
    fn gauss_legendre_integrates_polynomials_exactly() {
        let v = gauss_legendre(-1.0, 2.0, |x| x.powi(39) - 3.0 * x.powi(8));
        let exact = (2f64.powi(40) - 1.0) / 40.0 - 3.0 * (2f64.powi(9) + 1.0) / 9.0;
        // x^39 amplifies node rounding by ~39: a few ulps relative is machine precision here.
        assert!((v - exact).abs() <= 1e-14 * exact.abs(), "{v} vs {exact}");
        let low = gauss_legendre(0.0, 1.0, |x| 5.0 * x.powi(4));
        assert!((low - 1.0).abs() <= 4.0 * f64::EPSILON, "{low}");
        let (_, w) = &*GAUSS_LEGENDRE_20;
        assert!((w.iter().sum::<f64>() - 2.0).abs() <= 4.0 * f64::EPSILON);
    }
}
