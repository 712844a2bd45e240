//! Hermite interpolation at a point by a Bézier curve or patch: the Taylor polynomial built
//! from derivatives at a centre, written in Bernstein form on an interval (GMlib's way of
//! making ERBS local curves from a given curve or surface).

use super::super::point::binomial;
use super::super::surface::Partials;
use glam::DVec3;

/// The degree-d Bézier points on [a, b] of P(t) = Σ_r D_r (t − c)^r / r!, where `derivs` holds
/// D_0 … D_d: the polynomial whose derivatives 0..=d at c are the D_r.
///
/// With t = a + h·s: P = Σ_j m_j s^j, m_j = h^j Σ_{r≥j} D_r/r! C(r, j) (a − c)^{r−j}; then
/// Bernstein b_i = Σ_{j≤i} C(i, j)/C(d, j) m_j (NURBS Book eq. 6.x, power to Bernstein).
#[must_use]
pub fn taylor_bezier(derivs: &[DVec3], c: f64, (a, b): (f64, f64)) -> Vec<DVec3> {
    let coeffs: Vec<DVec3> = derivs
        .iter()
        .enumerate()
        .map(|(r, &v)| v / factorial(r))
        .collect();
    bernstein_from_taylor(&coeffs, c, (a, b))
}

/// Taylor coefficients P_r (P = Σ P_r (t − c)^r) to Bernstein points on [a, b].
fn bernstein_from_taylor(coeffs: &[DVec3], c: f64, (a, b): (f64, f64)) -> Vec<DVec3> {
    let d = coeffs.len() - 1;
    let h = b - a;
    let delta = a - c;
    let monomial: Vec<DVec3> = (0..=d)
        .map(|j| {
            let mut acc = DVec3::ZERO;
            for r in j..=d {
                acc += coeffs[r] * (binomial(r, j) * delta.powi((r - j) as i32));
            }
            acc * h.powi(j as i32)
        })
        .collect();
    (0..=d)
        .map(|i| {
            (0..=i).fold(DVec3::ZERO, |acc, j| {
                acc + monomial[j] * (binomial(i, j) / binomial(d, j))
            })
        })
        .collect()
}

/// The (du+1)×(dv+1) Bézier patch (row-major, i along u) on [a, b] × [c, d] whose partials
/// ∂^{a+b} with a ≤ du, b ≤ dv at `centre` equal `partials`' (which must hold those orders).
#[must_use]
pub fn taylor_patch(
    partials: &Partials,
    [du, dv]: [usize; 2],
    centre: (f64, f64),
    [iu, iv]: [(f64, f64); 2],
) -> Vec<DVec3> {
    // In u for each v order, then in v for each u Bernstein index: both maps are linear.
    let by_u: Vec<Vec<DVec3>> = (0..=dv)
        .map(|b| {
            let coeffs: Vec<DVec3> = (0..=du)
                .map(|a| partials.get(a, b) / (factorial(a) * factorial(b)))
                .collect();
            bernstein_from_taylor(&coeffs, centre.0, iu)
        })
        .collect();
    let mut out = vec![DVec3::ZERO; (du + 1) * (dv + 1)];
    for i in 0..=du {
        let column: Vec<DVec3> = (0..=dv).map(|b| by_u[b][i]).collect();
        for (j, p) in bernstein_from_taylor(&column, centre.1, iv)
            .into_iter()
            .enumerate()
        {
            out[i * (dv + 1) + j] = p;
        }
    }
    out
}

fn factorial(r: usize) -> f64 {
    (1..=r).map(|k| k as f64).product()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::BezierCurve;

    #[test]
    fn taylor_bezier_matches_its_derivatives() {
        let derivs = [
            DVec3::new(1.0, 2.0, 3.0),
            DVec3::new(-0.5, 0.25, 4.0),
            DVec3::new(3.0, -1.0, 0.5),
            DVec3::new(0.0, 6.0, -2.0),
        ];
        let (a, b, c) = (0.3, 1.7, 0.9);
        let pts = taylor_bezier(&derivs, c, (a, b));
        let bez = BezierCurve::new(pts).unwrap().with_interval(a, b).unwrap();
        let got = bez.derivatives(c, 3);
        for r in 0..4 {
            assert!((got[r] - derivs[r]).length() < 1e-12, "r={r}: {:?}", got[r]);
        }
    }
}
