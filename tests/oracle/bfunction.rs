//! Blending functions B: [0,1] → [0,1] for ERBS, with derivatives of any order.
//!
//! * `expo` (expo-rational, the default): B(t) = S_F ∫_0^t φ(s) ds with
//!   φ(s) = exp(-(s-½)²/(s(1-s))). B is computed by composite Gauss–Legendre quadrature on a
//!   geometrically graded mesh towards s = 0 (φ is flat there, every derivative vanishes), using
//!   B(t) = 1 - B(1-t) for t > ½. Derivatives B^(r) = S_F φ^(r-1) come from Taylor arithmetic:
//!   the exponent h(x) = -(s+x-½)²/((s+x)(1-s-x)) = 1 - ¼(1/(s+x) + 1/(1-s-x)) has an exact
//!   Taylor expansion around s, and exp of a series follows from E' = H'E.
//! * `smoothstep` 3t² − 2t³, `smootherstep` 10t³ − 15t⁴ + 6t⁵: polynomials, exact derivatives.
//! * `trigonometric` sin²(πt/2) = (1 − cos πt)/2: B^(r) = (π^r / 2) sin(πt + (r−1)π/2), r ≥ 1.
//! * `rational` t²/(t² + (1−t)²): Taylor-series division of numerator by denominator.

use std::sync::OnceLock;

/// S_F = 1 / ∫_0^1 exp(-(s-½)²/(s(1-s))) ds correctly rounded to f64. mpmath (50 digits) gives
/// 1.6571376797382103033283181259720…; the literal 1.6571376797382105 printed in the design notes
/// is one ulp above the nearest double (relative error 1e-16, harmless).
#[allow(clippy::excessive_precision)]
pub const EXPO_SCALE: f64 = 1.657_137_679_738_210_303_3;

/// The five B-functions a scene may name in `"bfunction"`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BFunction {
    Expo,
    Smoothstep,
    Smootherstep,
    Trigonometric,
    Rational,
}

impl BFunction {
    pub const ALL: [BFunction; 5] = [
        BFunction::Expo,
        BFunction::Smoothstep,
        BFunction::Smootherstep,
        BFunction::Trigonometric,
        BFunction::Rational,
    ];

    pub fn from_name(name: &str) -> Result<Self, String> {
        Ok(match name {
            "expo" => BFunction::Expo,
            "smoothstep" => BFunction::Smoothstep,
            "smootherstep" => BFunction::Smootherstep,
            "trigonometric" => BFunction::Trigonometric,
            "rational" => BFunction::Rational,
            other => return Err(format!("unknown bfunction {other:?}")),
        })
    }

    pub fn name(self) -> &'static str {
        match self {
            BFunction::Expo => "expo",
            BFunction::Smoothstep => "smoothstep",
            BFunction::Smootherstep => "smootherstep",
            BFunction::Trigonometric => "trigonometric",
            BFunction::Rational => "rational",
        }
    }

    /// `[B(t), B'(t), …, B^(n)(t)]` for t ∈ [0, 1].
    pub fn derivatives(self, t: f64, n: usize) -> Vec<f64> {
        match self {
            BFunction::Expo => expo_derivatives(t, n),
            BFunction::Smoothstep => {
                // B = 3t² − 2t³ = t²(3 − 2t); for t > ½ via B(t) = 1 − B(1 − t) (1 − t is exact
                // there), which keeps B(t) accurate to ~1e-16 absolute near t = 1.
                let value = |x: f64| x * x * (3.0 - 2.0 * x);
                let all = [
                    symmetric(t, value),
                    6.0 * t * (1.0 - t),
                    6.0 - 12.0 * t,
                    -12.0,
                ];
                (0..=n)
                    .map(|k| all.get(k).copied().unwrap_or(0.0))
                    .collect()
            }
            BFunction::Smootherstep => {
                // B = t³(10 − 15t + 6t²) and its derivatives in Horner form.
                let value = |x: f64| x * x * x * (10.0 + x * (-15.0 + 6.0 * x));
                let all = [
                    symmetric(t, value),
                    30.0 * t * t * (1.0 - t) * (1.0 - t),
                    60.0 * t * (1.0 - t) * (1.0 - 2.0 * t),
                    60.0 + t * (-360.0 + 360.0 * t),
                    -360.0 + 720.0 * t,
                    720.0,
                ];
                (0..=n)
                    .map(|k| all.get(k).copied().unwrap_or(0.0))
                    .collect()
            }
            BFunction::Trigonometric => {
                let value = |x: f64| (std::f64::consts::FRAC_PI_2 * x).sin().powi(2);
                let (sin, cos) = (std::f64::consts::PI * t).sin_cos();
                let mut out = vec![symmetric(t, value)];
                let mut pi_pow = 0.5; // π^r / 2
                for r in 1..=n {
                    pi_pow *= std::f64::consts::PI;
                    // d^(r-1)/dx^(r-1) sin x at x = πt.
                    let s = match (r - 1) % 4 {
                        0 => sin,
                        1 => cos,
                        2 => -sin,
                        _ => -cos,
                    };
                    out.push(pi_pow * s);
                }
                out
            }
            BFunction::Rational => {
                // N(x) = (t+x)², D(x) = (t+x)² + (1-t-x)² as Taylor polynomials in x.
                let num = [t * t, 2.0 * t, 1.0];
                let den = [t * t + (1.0 - t) * (1.0 - t), 4.0 * t - 2.0, 2.0];
                let mut q = Vec::with_capacity(n + 1);
                for k in 0..=n {
                    let mut acc = num.get(k).copied().unwrap_or(0.0);
                    for j in 1..=k.min(2) {
                        acc -= den[j] * q[k - j];
                    }
                    q.push(acc / den[0]);
                }
                let mut factorial = 1.0;
                for (k, qk) in q.iter_mut().enumerate() {
                    if k > 0 {
                        factorial *= k as f64;
                    }
                    *qk *= factorial;
                }
                q[0] = symmetric(t, |x| x * x / (x * x + (1.0 - x) * (1.0 - x)));
                q
            }
        }
    }
}

/// B(t) from a function accurate (relatively) near 0: itself for t ≤ ½, 1 − B(1 − t) above.
fn symmetric(t: f64, value: impl Fn(f64) -> f64) -> f64 {
    if t <= 0.5 {
        value(t)
    } else {
        1.0 - value(1.0 - t)
    }
}

/// φ(s) = exp(-(s-½)²/(s(1-s))) on (0,1); 0 outside.
pub fn expo_phi(s: f64) -> f64 {
    if s <= 0.0 || s >= 1.0 {
        return 0.0;
    }
    let d = s - 0.5;
    (-(d * d) / (s * (1.0 - s))).exp()
}

/// Gauss–Legendre nodes and weights on [-1, 1] (Newton iteration on P_n, Golub-free classic).
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        // Tricomi's initial guess for the i-th root.
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut derivative = 0.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            // P_n'(x) = n (x P_n − P_{n−1}) / (x² − 1)
            derivative = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let step = p1 / derivative;
            x -= step;
            if step.abs() < 1e-17 {
                break;
            }
        }
        let weight = 2.0 / ((1.0 - x * x) * derivative * derivative);
        out.push((x, weight));
    }
    out
}

fn gauss_rule() -> &'static [(f64, f64)] {
    static RULE: OnceLock<Vec<(f64, f64)>> = OnceLock::new();
    RULE.get_or_init(|| gauss_legendre(24))
}

/// ∫_0^t φ(s) ds for 0 ≤ t ≤ ½, on the graded mesh [t/2^(k+1), t/2^k]. Each piece [a, 2a] keeps
/// the essential singularity at s = 0 at relative distance 3 half-lengths, so the 24-point rule
/// converges like ρ^(-48) with ρ ≈ 3; the neglected [0, a) with a < 1/500 contributes < 1e-50.
pub fn expo_integral_lower(t: f64) -> f64 {
    debug_assert!((0.0..=0.5).contains(&t));
    let rule = gauss_rule();
    let mut sum = 0.0;
    let mut hi = t;
    while hi > 0.002 {
        let lo = 0.5 * hi;
        let (mid, half) = (0.5 * (hi + lo), 0.5 * (hi - lo));
        let mut piece = 0.0;
        for &(x, w) in rule {
            piece += w * expo_phi(mid + half * x);
        }
        sum += half * piece;
        hi = lo;
    }
    sum
}

/// `[B(t), …, B^(n)(t)]` for the expo-rational B-function.
fn expo_derivatives(t: f64, n: usize) -> Vec<f64> {
    let mut out = vec![0.0; n + 1];
    if t <= 0.0 {
        return out;
    }
    if t >= 1.0 {
        out[0] = 1.0;
        return out;
    }
    out[0] = if t <= 0.5 {
        EXPO_SCALE * expo_integral_lower(t)
    } else {
        1.0 - EXPO_SCALE * expo_integral_lower(1.0 - t)
    };
    if n == 0 {
        return out;
    }
    let phi = phi_taylor(t, n - 1);
    let mut factorial = 1.0;
    for r in 1..=n {
        // B^(r) = S_F φ^(r−1) = S_F (r−1)! e_{r−1}
        if r > 1 {
            factorial *= (r - 1) as f64;
        }
        out[r] = EXPO_SCALE * factorial * phi[r - 1];
    }
    out
}

/// Taylor coefficients e_0..e_m of φ(s + x) in x, 0 < s < 1.
pub fn phi_taylor(s: f64, m: usize) -> Vec<f64> {
    let d = s - 0.5;
    let e0 = (-(d * d) / (s * (1.0 - s))).exp();
    let mut e = vec![0.0; m + 1];
    e[0] = e0;
    if e0 == 0.0 {
        // φ underflowed: every derivative is below the subnormal range as well.
        return e;
    }
    // h_j = −¼((−1)^j / s^(j+1) + 1/(1−s)^(j+1)), j ≥ 1.
    let (inv_s, inv_1s) = (1.0 / s, 1.0 / (1.0 - s));
    let mut h = vec![0.0; m + 1];
    let (mut ps, mut p1s) = (inv_s, inv_1s);
    for (j, hj) in h.iter_mut().enumerate().skip(1) {
        ps *= inv_s;
        p1s *= inv_1s;
        let sign = if j % 2 == 0 { 1.0 } else { -1.0 };
        *hj = -0.25 * (sign * ps + p1s);
    }
    for k in 1..=m {
        let mut acc = 0.0;
        for j in 1..=k {
            acc += j as f64 * h[j] * e[k - j];
        }
        e[k] = acc / k as f64;
    }
    e
}
