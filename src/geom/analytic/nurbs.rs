//! Plain-data rational B-splines and a small evaluator.
//!
//! Evaluation runs de Boor's algorithm on homogeneous (4D) control points
//! `(w·P, w)`; first and second derivatives come from de Boor on the
//! derivative control points `p(Q_{i+1} − Q_i)/(u_{i+p+1} − u_{i+1})` of the
//! homogeneous curve (The NURBS Book, eq. 3.8), and are turned into the
//! rational derivatives by the quotient rule of A4.2 (RatCurveDerivs) and
//! A4.4 (RatSurfaceDerivs). De Boor was chosen over A2.3 DersBasisFuns because
//! it is short, obviously correct and never divides by a zero knot span.

use glam::{DVec3, DVec4};

use super::error::{AnalyticError, Result, clamp};

/// A rational B-spline curve (plain data: the caller wraps it in its own type).
#[derive(Debug, Clone, PartialEq)]
pub struct NurbsCurve {
    /// Polynomial degree `p ≥ 1`.
    pub degree: usize,
    /// Non-decreasing knots, `points.len() + degree + 1` of them.
    pub knots: Vec<f64>,
    /// Control points.
    pub points: Vec<DVec3>,
    /// Positive weights, one per control point.
    pub weights: Vec<f64>,
}

/// A tensor-product rational B-spline surface.
///
/// `points` is row-major `[nu][nv]`: control point `(i, j)` is at
/// `i * nv + j`, with `i` running along `u`.
#[derive(Debug, Clone, PartialEq)]
pub struct NurbsSurface {
    /// Degrees `[p_u, p_v]`.
    pub degree: [usize; 2],
    /// Knot vectors `[U, V]`.
    pub knots: [Vec<f64>; 2],
    /// Control net, row-major `[nu][nv]`.
    pub points: Vec<DVec3>,
    /// Weights, same layout as `points`.
    pub weights: Vec<f64>,
}

/// The active part of a control net at one parameter pair.
struct LocalNet {
    /// Knot spans `[k_u, k_v]`.
    span: [usize; 2],
    /// Parameters clamped into the domain.
    uv: [f64; 2],
    /// `(p_u+1)` rows of `(p_v+1)` homogeneous points.
    rows: Vec<Vec<DVec4>>,
}

/// Point and partial derivatives of a surface at one parameter pair.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceDerivs {
    /// `S`
    pub p: DVec3,
    /// `∂S/∂u`
    pub su: DVec3,
    /// `∂S/∂v`
    pub sv: DVec3,
    /// `∂²S/∂u²`
    pub suu: DVec3,
    /// `∂²S/∂u∂v`
    pub suv: DVec3,
    /// `∂²S/∂v²`
    pub svv: DVec3,
}

/// An index that validation should have ruled out (never expected).
const BAD: AnalyticError = AnalyticError::InvalidNurbs("index out of range");

/// Checks one knot vector for `n` control points of degree `p`.
fn check_knots(p: usize, knots: &[f64], n: usize) -> Result<()> {
    if p == 0 {
        return Err(AnalyticError::InvalidNurbs("degree must be at least 1"));
    }
    if n < p + 1 {
        return Err(AnalyticError::InvalidNurbs(
            "fewer than degree+1 control points",
        ));
    }
    if knots.len() != n + p + 1 {
        return Err(AnalyticError::InvalidNurbs(
            "knot count != points + degree + 1",
        ));
    }
    if knots.iter().any(|k| !k.is_finite()) {
        return Err(AnalyticError::NonFinite { what: "knot" });
    }
    if knots.windows(2).any(|w| matches!(w, [a, b] if b < a)) {
        return Err(AnalyticError::InvalidNurbs("knots decrease"));
    }
    let [lo, hi] = domain_of(knots, p, n)?;
    if lo < hi {
        Ok(())
    } else {
        Err(AnalyticError::InvalidNurbs("empty parameter domain"))
    }
}

/// Checks point/weight counts, finiteness and positive weights.
fn check_points(points: &[DVec3], weights: &[f64]) -> Result<()> {
    if points.len() != weights.len() {
        return Err(AnalyticError::InvalidNurbs("weight count != point count"));
    }
    if points.iter().any(|p| !p.is_finite()) {
        return Err(AnalyticError::NonFinite {
            what: "control point",
        });
    }
    if weights.iter().any(|w| !w.is_finite()) {
        return Err(AnalyticError::NonFinite { what: "weight" });
    }
    if weights.iter().any(|&w| w <= 0.0) {
        return Err(AnalyticError::InvalidNurbs("weights must be positive"));
    }
    Ok(())
}

/// `[u_p, u_n]`, the valid parameter interval.
fn domain_of(knots: &[f64], p: usize, n: usize) -> Result<[f64; 2]> {
    Ok([*knots.get(p).ok_or(BAD)?, *knots.get(n).ok_or(BAD)?])
}

/// A2.1 FindSpan: the `k ∈ [p, n−1]` with `u_k ≤ t < u_{k+1}`, using the last
/// non-empty span at the right end. `t` is clamped into the domain first.
pub(crate) fn find_span(knots: &[f64], p: usize, n: usize, t: f64) -> Option<usize> {
    let inner = knots.get(p..n)?;
    let hi = *knots.get(n)?;
    let lo = *inner.first()?;
    let t = clamp(t, lo, hi);
    let below = if t >= hi {
        inner.partition_point(|&k| k < hi)
    } else {
        inner.partition_point(|&k| k <= t)
    };
    (p + below).checked_sub(1)
}

/// De Boor's algorithm on the `p+1` local points of span `k`.
fn de_boor(knots: &[f64], p: usize, k: usize, local: &[DVec4], t: f64) -> Option<DVec4> {
    let mut d = local.get(..=p)?.to_vec();
    let base = k.checked_sub(p)?;
    for r in 1..=p {
        for j in (r..=p).rev() {
            let a = *knots.get(j + base)?;
            let b = *knots.get(j + 1 + k - r)?;
            let alpha = (t - a) / (b - a);
            let prev = *d.get(j - 1)?;
            let cur = d.get_mut(j)?;
            *cur = prev * (1.0 - alpha) + *cur * alpha;
        }
    }
    d.get(p).copied()
}

/// Local control points of the derivative of span `k` (NURBS Book eq. 3.8).
fn derivative_points(knots: &[f64], p: usize, k: usize, local: &[DVec4]) -> Option<Vec<DVec4>> {
    let base = k.checked_sub(p)?;
    let pf = p as f64;
    local
        .windows(2)
        .take(p)
        .enumerate()
        .map(|(i, w)| {
            let den = knots.get(base + i + p + 1)? - knots.get(base + i + 1)?;
            match w {
                [a, b] => Some((*b - *a) * (pf / den)),
                _ => None,
            }
        })
        .collect()
}

/// Homogeneous value, first and second derivative on span `k`.
fn span_derivs(knots: &[f64], p: usize, k: usize, local: &[DVec4], t: f64) -> Option<[DVec4; 3]> {
    let d0 = de_boor(knots, p, k, local, t)?;
    if p == 0 {
        return Some([d0, DVec4::ZERO, DVec4::ZERO]);
    }
    let inner = knots.get(1..knots.len().checked_sub(1)?)?;
    let q1 = derivative_points(knots, p, k, local)?;
    let d1 = de_boor(inner, p - 1, k.checked_sub(1)?, &q1, t)?;
    if p == 1 {
        return Some([d0, d1, DVec4::ZERO]);
    }
    let inner2 = inner.get(1..inner.len().checked_sub(1)?)?;
    let q2 = derivative_points(inner, p - 1, k.checked_sub(1)?, &q1)?;
    let d2 = de_boor(inner2, p - 2, k.checked_sub(2)?, &q2, t)?;
    Some([d0, d1, d2])
}

/// `(w·P, w)`.
pub(crate) fn homogeneous(p: DVec3, w: f64) -> DVec4 {
    (p * w).extend(w)
}

/// A4.2 quotient rule: rational point, first and second derivative.
fn rational(a: [DVec4; 3]) -> [DVec3; 3] {
    let [a0, a1, a2] = a;
    let w = a0.w;
    let c0 = a0.truncate() / w;
    let c1 = (a1.truncate() - a1.w * c0) / w;
    let c2 = (a2.truncate() - 2.0 * a1.w * c1 - a2.w * c0) / w;
    [c0, c1, c2]
}

impl NurbsCurve {
    /// Checks array lengths, knot order, finiteness and positive weights.
    ///
    /// # Errors
    /// [`AnalyticError::InvalidNurbs`] or [`AnalyticError::NonFinite`].
    pub fn validate(&self) -> Result<()> {
        check_knots(self.degree, &self.knots, self.points.len())?;
        check_points(&self.points, &self.weights)
    }

    /// The parameter domain `[u_p, u_n]`.
    ///
    /// # Errors
    /// If the curve is invalid.
    pub fn domain(&self) -> Result<[f64; 2]> {
        self.validate()?;
        domain_of(&self.knots, self.degree, self.points.len())
    }

    /// Point, first and second derivative at `t` (clamped into the domain).
    ///
    /// # Errors
    /// If the curve is invalid.
    pub fn derivs(&self, t: f64) -> Result<[DVec3; 3]> {
        self.validate()?;
        self.derivs_unchecked(t).ok_or(BAD)
    }

    /// Point at `t` (clamped into the domain).
    ///
    /// # Errors
    /// If the curve is invalid.
    pub fn point(&self, t: f64) -> Result<DVec3> {
        Ok(self.derivs(t)?[0])
    }

    /// [`Self::derivs`] for an already validated curve.
    pub(crate) fn derivs_unchecked(&self, t: f64) -> Option<[DVec3; 3]> {
        let (p, n) = (self.degree, self.points.len());
        let k = find_span(&self.knots, p, n, t)?;
        let [lo, hi] = [*self.knots.get(p)?, *self.knots.get(n)?];
        let range = k.checked_sub(p)?..=k;
        let local: Vec<DVec4> = self
            .points
            .get(range.clone())?
            .iter()
            .zip(self.weights.get(range)?)
            .map(|(&q, &w)| homogeneous(q, w))
            .collect();
        Some(rational(span_derivs(
            &self.knots,
            p,
            k,
            &local,
            clamp(t, lo, hi),
        )?))
    }
}

impl NurbsSurface {
    /// Numbers of control points `[nu, nv]` implied by the knot vectors.
    fn counts(&self) -> Result<[usize; 2]> {
        let [pu, pv] = self.degree;
        let [ku, kv] = [&self.knots[0], &self.knots[1]];
        let nu = ku
            .len()
            .checked_sub(pu + 1)
            .ok_or(AnalyticError::InvalidNurbs("too few u knots"))?;
        let nv = kv
            .len()
            .checked_sub(pv + 1)
            .ok_or(AnalyticError::InvalidNurbs("too few v knots"))?;
        Ok([nu, nv])
    }

    /// Checks knot vectors, net size, finiteness and positive weights.
    ///
    /// # Errors
    /// [`AnalyticError::InvalidNurbs`] or [`AnalyticError::NonFinite`].
    pub fn validate(&self) -> Result<()> {
        let [nu, nv] = self.counts()?;
        check_knots(self.degree[0], &self.knots[0], nu)?;
        check_knots(self.degree[1], &self.knots[1], nv)?;
        if nu.checked_mul(nv) != Some(self.points.len()) {
            return Err(AnalyticError::InvalidNurbs("point count != nu * nv"));
        }
        check_points(&self.points, &self.weights)
    }

    /// `[[u_lo, u_hi], [v_lo, v_hi]]`.
    ///
    /// # Errors
    /// If the surface is invalid.
    pub fn domain(&self) -> Result<[[f64; 2]; 2]> {
        self.validate()?;
        let [nu, nv] = self.counts()?;
        Ok([
            domain_of(&self.knots[0], self.degree[0], nu)?,
            domain_of(&self.knots[1], self.degree[1], nv)?,
        ])
    }

    /// Point at `(u, v)` (clamped into the domain).
    ///
    /// # Errors
    /// If the surface is invalid.
    pub fn point(&self, u: f64, v: f64) -> Result<DVec3> {
        Ok(self.derivs(u, v)?.p)
    }

    /// Point and derivatives up to second order at `(u, v)`.
    ///
    /// # Errors
    /// If the surface is invalid.
    pub fn derivs(&self, u: f64, v: f64) -> Result<SurfaceDerivs> {
        self.validate()?;
        self.derivs_unchecked(u, v).ok_or(BAD)
    }

    /// Length of the control net's bounding-box diagonal: the scale for
    /// relative tolerances.
    #[must_use]
    pub fn extent(&self) -> f64 {
        let lo = self.points.iter().fold(DVec3::INFINITY, |a, &b| a.min(b));
        let hi = self
            .points
            .iter()
            .fold(DVec3::NEG_INFINITY, |a, &b| a.max(b));
        (hi - lo).length()
    }

    /// Active control net at `(u, v)`: spans, clamped parameters and the
    /// `(pu+1)` rows of `(pv+1)` homogeneous points.
    fn local_net(&self, u: f64, v: f64) -> Option<LocalNet> {
        let [pu, pv] = self.degree;
        let [ku, kv] = [&self.knots[0], &self.knots[1]];
        let nu = ku.len().checked_sub(pu + 1)?;
        let nv = kv.len().checked_sub(pv + 1)?;
        let (su, sv) = (find_span(ku, pu, nu, u)?, find_span(kv, pv, nv, v)?);
        let u = clamp(u, *ku.get(pu)?, *ku.get(nu)?);
        let v = clamp(v, *kv.get(pv)?, *kv.get(nv)?);
        let mut rows = Vec::with_capacity(pu + 1);
        for i in su.checked_sub(pu)?..=su {
            let start = i * nv + sv.checked_sub(pv)?;
            let range = start..=start + pv;
            let pts = self.points.get(range.clone())?.iter();
            rows.push(
                pts.zip(self.weights.get(range)?)
                    .map(|(&q, &w)| homogeneous(q, w))
                    .collect(),
            );
        }
        Some(LocalNet {
            span: [su, sv],
            uv: [u, v],
            rows,
        })
    }

    /// Point only (cheaper than [`Self::derivs_unchecked`]; used for the
    /// coarse start grid of the Newton inversion).
    pub(crate) fn point_unchecked(&self, u: f64, v: f64) -> Option<DVec3> {
        let [pu, pv] = self.degree;
        let net = self.local_net(u, v)?;
        let [su, sv] = net.span;
        let col: Vec<DVec4> = net
            .rows
            .iter()
            .map(|r| de_boor(&self.knots[1], pv, sv, r, net.uv[1]))
            .collect::<Option<_>>()?;
        let h = de_boor(&self.knots[0], pu, su, &col, net.uv[0])?;
        Some(h.truncate() / h.w)
    }

    /// [`Self::derivs`] for an already validated surface: curve de Boor along
    /// `v` for each active row, then along `u`, then A4.4's quotient rule.
    pub(crate) fn derivs_unchecked(&self, u: f64, v: f64) -> Option<SurfaceDerivs> {
        let [pu, pv] = self.degree;
        let net = self.local_net(u, v)?;
        let [su, sv] = net.span;
        let [u, v] = net.uv;
        // rows[i][b] = ∂^b/∂v^b of row (su − pu + i).
        let rows: Vec<[DVec4; 3]> = net
            .rows
            .iter()
            .map(|r| span_derivs(&self.knots[1], pv, sv, r, v))
            .collect::<Option<_>>()?;
        // a[b] = [∂^0, ∂^1, ∂^2 along u] of the b-th v-derivative.
        let mut a = [[DVec4::ZERO; 3]; 3];
        for (b, slot) in a.iter_mut().enumerate() {
            let col: Vec<DVec4> = rows
                .iter()
                .map(|r| r.get(b).copied())
                .collect::<Option<_>>()?;
            *slot = span_derivs(&self.knots[0], pu, su, &col, u)?;
        }
        let [[a00, a10, a20], [a01, a11, _], [a02, _, _]] = a;
        let w = a00.w;
        let p = a00.truncate() / w;
        let su = (a10.truncate() - a10.w * p) / w;
        let sv = (a01.truncate() - a01.w * p) / w;
        let suu = (a20.truncate() - 2.0 * a10.w * su - a20.w * p) / w;
        let svv = (a02.truncate() - 2.0 * a01.w * sv - a02.w * p) / w;
        let suv = (a11.truncate() - a10.w * sv - a01.w * su - a11.w * p) / w;
        Some(SurfaceDerivs {
            p,
            su,
            sv,
            suu,
            suv,
            svv,
        })
    }
}
