//! B_SPLINE_CURVE and B_SPLINE_SURFACE (ISO 10303-42 §4.4.27, §4.4.57) read into the analytic
//! crate's plain NURBS types, and a fast evaluator with first derivatives.
//!
//! Knots come from B_SPLINE_*_WITH_KNOTS (distinct values and multiplicities, expanded here) or
//! are generated for the UNIFORM_, QUASI_UNIFORM_ and BEZIER_ subtypes as ISO 10303-42 defines
//! them; weights from RATIONAL_B_SPLINE_* (else 1). Nothing is sized from a number written in
//! the file before it is checked against the lists actually present: the multiplicities must
//! add up to `points + degree + 1` before the knot vector is expanded.

use crate::formats::step::EntityRef;
use crate::formats::step::map::attrs::{at, at_mut};
use crate::geom::analytic::{NurbsCurve, NurbsSurface};
use glam::{DVec3, DVec4};

use super::attrs::{P, Part, Res, bad, is, msg, part, point3};

/// Highest degree accepted (ISO 10303-42 sets none; CAD systems stay far below).
pub(crate) const MAX_DEGREE: usize = 32;

/// A degree attribute, checked.
fn degree(own: &Part<'_>, i: usize, name: &'static str, e: &EntityRef<'_>) -> Res<usize> {
    let d = own.p(i, name)?.integer()?;
    usize::try_from(d)
        .ok()
        .filter(|d| (1..=MAX_DEGREE).contains(d))
        .ok_or_else(|| bad(e, format!("{name} {d} is outside 1..={MAX_DEGREE}")))
}

/// The knot vector of one direction: from multiplicities and knots (WITH_KNOTS) or generated
/// for the uniform, quasi-uniform and Bézier forms.
fn knot_vector(
    e: &EntityRef<'_>,
    explicit: Option<(Vec<i64>, Vec<f64>)>,
    p: usize,
    n: usize,
) -> Res<Vec<f64>> {
    if n < p + 1 {
        return Err(bad(
            e,
            format!("{n} control points are too few for degree {p}"),
        ));
    }
    let count = n + p + 1;
    let Some((mults, values)) = explicit else {
        return generated(e, p, n);
    };
    if mults.len() != values.len() || values.len() < 2 {
        return Err(bad(e, "knot multiplicities and knots differ in number"));
    }
    let mut sum: usize = 0;
    for &m in &mults {
        let m = usize::try_from(m)
            .ok()
            .filter(|m| (1..=p + 1).contains(m))
            .ok_or_else(|| bad(e, format!("knot multiplicity {m} is outside 1..={}", p + 1)))?;
        sum += m;
    }
    if sum != count {
        return Err(bad(
            e,
            format!("multiplicities add up to {sum}, expected points + degree + 1 = {count}"),
        ));
    }
    if values.windows(2).any(|w| matches!(w, [a, b] if b < a)) {
        return Err(bad(e, "knots decrease"));
    }
    let mut knots = Vec::with_capacity(count);
    for (&m, &k) in mults.iter().zip(&values) {
        knots.extend(std::iter::repeat_n(k, usize::try_from(m).unwrap_or(0)));
    }
    Ok(knots)
}

/// Knots of UNIFORM_ (`i − p`), QUASI_UNIFORM_ (clamped, unit spacing) and BEZIER_ (piecewise
/// Bézier: interior knots of multiplicity `p`) B-splines, ISO 10303-42 §4.4.28–4.4.30.
fn generated(e: &EntityRef<'_>, p: usize, n: usize) -> Res<Vec<f64>> {
    let count = n + p + 1;
    let names = e.type_names();
    if names.contains("QUASI_UNIFORM") {
        let inner = n - p;
        let mut k = vec![0.0; p + 1];
        k.extend((1..inner).map(|i| i as f64));
        k.extend(std::iter::repeat_n(inner as f64, p + 1));
        Ok(k)
    } else if names.contains("UNIFORM") {
        Ok((0..count).map(|i| i as f64 - p as f64).collect())
    } else if names.contains("BEZIER") {
        if !(n - 1).is_multiple_of(p) {
            return Err(bad(
                e,
                "a piecewise Bézier needs 1 + k·degree control points",
            ));
        }
        let segments = (n - 1) / p;
        let mut k = vec![0.0; p + 1];
        for s in 1..segments {
            k.extend(std::iter::repeat_n(s as f64, p));
        }
        k.extend(std::iter::repeat_n(segments as f64, p + 1));
        Ok(k)
    } else {
        Err(bad(
            e,
            "B-spline without knots (not WITH_KNOTS, UNIFORM, QUASI_UNIFORM or BEZIER)",
        ))
    }
}

/// Positive finite weights, one per point.
fn check_weights(e: &EntityRef<'_>, w: &[f64], n: usize) -> Res<()> {
    if w.len() != n {
        return Err(bad(
            e,
            format!("{} weights for {n} control points", w.len()),
        ));
    }
    if w.iter().any(|&x| x <= 0.0) {
        return Err(bad(e, "weights must be positive"));
    }
    Ok(())
}

/// B_SPLINE_CURVE and its subtypes (simple or complex instance).
pub(crate) fn read_bspline_curve(e: EntityRef<'_>) -> Res<NurbsCurve> {
    let own = part(e, "B_SPLINE_CURVE", 1)?;
    let p = degree(&own, 0, "degree", &e)?;
    let points: Vec<DVec3> = own
        .p(1, "control_points_list")?
        .ents()?
        .into_iter()
        .map(point3)
        .collect::<Res<_>>()?;
    let n = points.len();
    let explicit = if is(&e, "B_SPLINE_CURVE_WITH_KNOTS") {
        let k = part(e, "B_SPLINE_CURVE_WITH_KNOTS", 6)?;
        let m = k.p(0, "knot_multiplicities")?.ints().map_err(msg)?;
        Some((m, k.p(1, "knots")?.nums()?))
    } else {
        None
    };
    let knots = knot_vector(&e, explicit, p, n)?;
    let weights = if is(&e, "RATIONAL_B_SPLINE_CURVE") {
        let w = part(e, "RATIONAL_B_SPLINE_CURVE", 6)?
            .p(0, "weights_data")?
            .nums()?;
        check_weights(&e, &w, n)?;
        w
    } else {
        vec![1.0; n]
    };
    let c = NurbsCurve {
        degree: p,
        knots,
        points,
        weights,
    };
    c.validate().map_err(|x| bad(&e, x.to_string()))?;
    Ok(c)
}

/// B_SPLINE_SURFACE and its subtypes; control point `(i, j)` (i along u) at `i·nv + j`.
pub(crate) fn read_bspline_surface(e: EntityRef<'_>) -> Res<NurbsSurface> {
    let own = part(e, "B_SPLINE_SURFACE", 1)?;
    let pu = degree(&own, 0, "u_degree", &e)?;
    let pv = degree(&own, 1, "v_degree", &e)?;
    let rows = own.p(2, "control_points_list")?;
    let rows = rows.list().map_err(msg)?;
    let nu = rows.len();
    let mut points = Vec::new();
    let mut nv = None;
    for row in rows.iter() {
        let r = row.ents()?;
        if *nv.get_or_insert(r.len()) != r.len() {
            return Err(bad(&e, "control point rows differ in length"));
        }
        for p in r {
            points.push(point3(p)?);
        }
    }
    let nv = nv.unwrap_or(0);
    let explicit = |i_m, i_k| -> Res<Option<(Vec<i64>, Vec<f64>)>> {
        if !is(&e, "B_SPLINE_SURFACE_WITH_KNOTS") {
            return Ok(None);
        }
        let k = part(e, "B_SPLINE_SURFACE_WITH_KNOTS", 8)?;
        let m = k.p(i_m, "multiplicities")?.ints().map_err(msg)?;
        Ok(Some((m, k.p(i_k, "knots")?.nums()?)))
    };
    let ku = knot_vector(&e, explicit(0, 2)?, pu, nu)?;
    let kv = knot_vector(&e, explicit(1, 3)?, pv, nv)?;
    let weights = if is(&e, "RATIONAL_B_SPLINE_SURFACE") {
        let rows = part(e, "RATIONAL_B_SPLINE_SURFACE", 8)?.p(0, "weights_data")?;
        let mut w = Vec::with_capacity(points.len());
        for row in rows.list().map_err(msg)?.iter() {
            w.extend(row.nums()?);
        }
        check_weights(&e, &w, points.len())?;
        w
    } else {
        vec![1.0; points.len()]
    };
    let s = NurbsSurface {
        degree: [pu, pv],
        knots: [ku, kv],
        points,
        weights,
    };
    s.validate().map_err(|x| bad(&e, x.to_string()))?;
    Ok(s)
}

/// A B-spline surface closed in direction `d` (period `period`) re-parametrised to start at
/// `start`: each line of control points along `d` is a closed curve, stored twice over and cut
/// to `[start, start + period]` by knot insertion (The NURBS Book A5.1), so the surface is the
/// same point set with the same parameters modulo the period. `None` where the lines' weights
/// do not scale alike at the seam (then no common copy exists).
#[must_use]
pub(crate) fn reseat(s: &NurbsSurface, d: usize, start: f64, period: f64) -> Option<NurbsSurface> {
    let [pu, pv] = s.degree;
    let nv = s.knots[1].len().checked_sub(pv + 1)?;
    let nu = s.knots[0].len().checked_sub(pu + 1)?;
    let (count, along) = if d == 0 { (nv, nu) } else { (nu, nv) };
    let index = |line: usize, k: usize| if d == 0 { k * nv + line } else { line * nv + k };
    let mut lines = Vec::with_capacity(count);
    let mut ratio: Option<f64> = None;
    for line in 0..count {
        let idx: Vec<usize> = (0..along).map(|k| index(line, k)).collect();
        let c = NurbsCurve {
            degree: *at(&s.degree, d),
            knots: at(&s.knots, d).clone(),
            points: idx
                .iter()
                .map(|&i| s.points.get(i).copied())
                .collect::<Option<_>>()?,
            weights: idx
                .iter()
                .map(|&i| s.weights.get(i).copied())
                .collect::<Option<_>>()?,
        };
        let r = c.weights.last()? / c.weights.first()?;
        if ratio.is_some_and(|q| (q - r).abs() > 1e-12 * q.abs()) {
            return None;
        }
        ratio = Some(r);
        let lo = *c.knots.get(c.degree)?;
        let twice = super::surface::twice(&c)?;
        let k = ((start - lo) / period).floor();
        let a = start - k * period;
        let cut = twice.segment(a, a + period).ok()?;
        lines.push((cut, k * period));
    }
    let (first, shift) = lines.first()?;
    let knots: Vec<f64> = first.knots.iter().map(|x| x + shift).collect();
    let along = first.points.len();
    let mut points = vec![DVec3::ZERO; count * along];
    let mut weights = vec![0.0; count * along];
    for (line, (c, _)) in lines.iter().enumerate() {
        for k in 0..along {
            let i = if d == 0 {
                k * count + line
            } else {
                line * along + k
            };
            *points.get_mut(i)? = *c.points.get(k)?;
            *weights.get_mut(i)? = *c.weights.get(k)?;
        }
    }
    let mut out = s.clone();
    *at_mut(&mut out.knots, d) = knots;
    out.points = points;
    out.weights = weights;
    out.validate().ok()?;
    Some(out)
}

/// A rational surface prepared for fast evaluation of the point and first partials
/// (homogeneous points, basis functions by The NURBS Book A2.2 on the stack). Used by the
/// Newton inversion and the area quadrature, which evaluate it hundreds of thousands of times.
#[derive(Clone, Debug)]
pub(crate) struct FastSurface {
    degree: [usize; 2],
    knots: [Vec<f64>; 2],
    count: [usize; 2],
    hw: Vec<DVec4>,
}

/// Point and first partial derivatives.
#[derive(Clone, Copy, Debug)]
pub(crate) struct D1 {
    pub p: DVec3,
    pub su: DVec3,
    pub sv: DVec3,
}

impl FastSurface {
    /// Prepares a validated surface.
    #[must_use]
    pub(crate) fn new(s: &NurbsSurface) -> Self {
        let count = [
            s.knots[0].len().saturating_sub(s.degree[0] + 1),
            s.knots[1].len().saturating_sub(s.degree[1] + 1),
        ];
        let hw = s
            .points
            .iter()
            .zip(&s.weights)
            .map(|(p, &w)| (*p * w).extend(w))
            .collect();
        Self {
            degree: s.degree,
            knots: s.knots.clone(),
            count,
            hw,
        }
    }

    /// `[[u0, u1], [v0, v1]]`.
    #[must_use]
    pub(crate) fn domain(&self) -> [[f64; 2]; 2] {
        let d = |k: usize| {
            let (p, n) = (*at(&self.degree, k), *at(&self.count, k));
            let kn = at(&self.knots, k);
            [
                kn.get(p).copied().unwrap_or(0.0),
                kn.get(n).copied().unwrap_or(0.0),
            ]
        };
        [d(0), d(1)]
    }

    /// Point and first partials at `(u, v)` (clamped into the domain).
    #[must_use]
    pub(crate) fn d1(&self, u: f64, v: f64) -> Option<D1> {
        // Basis arrays on the stack, sized for the usual degrees (≤ 11) or the largest.
        if self.degree.iter().all(|&p| p < SMALL) {
            self.d1_with::<SMALL>(u, v)
        } else {
            self.d1_with::<{ MAX_DEGREE + 1 }>(u, v)
        }
    }

    /// The point at `(u, v)` (clamped into the domain), without the partials: the same
    /// basis values and sums as [`FastSurface::d1`]'s point, so the same bits, at about half
    /// the cost (flattening and the bounds search need points only).
    #[must_use]
    pub(crate) fn point(&self, u: f64, v: f64) -> Option<DVec3> {
        let [pu, pv] = self.degree;
        if pu == 0 || pv == 0 {
            return None;
        }
        let (su, u) = span(&self.knots[0], pu, self.count[0], u)?;
        let (sv, v) = span(&self.knots[1], pv, self.count[1], v)?;
        let nu = funs(&self.knots[0], su, u, pu)?;
        let nv = funs(&self.knots[1], sv, v, pv)?;
        let mut a = DVec4::ZERO;
        for (i, n) in nu.iter().take(pu + 1).enumerate() {
            let start = (su - pu + i) * self.count[1] + sv - pv;
            let row = self.hw.get(start..=start + pv)?;
            let mut r = DVec4::ZERO;
            for (h, m) in row.iter().zip(&nv) {
                r += *h * *m;
            }
            a += r * *n;
        }
        Some(a.truncate() / a.w)
    }

    #[must_use]
    fn d1_with<const N: usize>(&self, u: f64, v: f64) -> Option<D1> {
        let (mut nu, mut du, mut nv, mut dv) = ([0.0; N], [0.0; N], [0.0; N], [0.0; N]);
        let su = basis(
            &self.knots[0],
            self.degree[0],
            self.count[0],
            u,
            &mut nu,
            &mut du,
        )?;
        let sv = basis(
            &self.knots[1],
            self.degree[1],
            self.count[1],
            v,
            &mut nv,
            &mut dv,
        )?;
        let [pu, pv] = self.degree;
        let (mut a, mut au, mut av) = (DVec4::ZERO, DVec4::ZERO, DVec4::ZERO);
        for i in 0..=pu {
            let start = (su - pu + i) * self.count[1] + sv - pv;
            let row = self.hw.get(start..=start + pv)?;
            let (mut r, mut rv) = (DVec4::ZERO, DVec4::ZERO);
            for ((h, n), d) in row.iter().zip(&nv).zip(&dv) {
                r += *h * *n;
                rv += *h * *d;
            }
            let (n, d) = (*nu.get(i)?, *du.get(i)?);
            a += r * n;
            au += r * d;
            av += rv * n;
        }
        let p = a.truncate() / a.w;
        Some(D1 {
            p,
            su: (au.truncate() - au.w * p) / a.w,
            sv: (av.truncate() - av.w * p) / a.w,
        })
    }
}

/// Basis array length for degrees below it (the fast path of [`FastSurface::d1`]).
const SMALL: usize = 12;

/// A rational curve prepared for fast evaluation (homogeneous points, A2.2 basis functions on
/// the stack): trim pieces evaluate their curves thousands of times.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct FastCurve {
    degree: usize,
    knots: Vec<f64>,
    hw: Vec<DVec4>,
}

impl FastCurve {
    /// Prepares a validated curve.
    #[must_use]
    pub(crate) fn new(c: &NurbsCurve) -> Self {
        Self {
            degree: c.degree,
            knots: c.knots.clone(),
            hw: c
                .points
                .iter()
                .zip(&c.weights)
                .map(|(p, &w)| (*p * w).extend(w))
                .collect(),
        }
    }

    /// The point at `t` (clamped into the domain).
    #[must_use]
    pub(crate) fn point(&self, t: f64) -> Option<DVec3> {
        let (p, n) = (self.degree, self.hw.len());
        let (span, t) = span(&self.knots, p, n, t)?;
        let f = funs(&self.knots, span, t, p)?;
        let mut a = DVec4::ZERO;
        for (k, h) in self.hw.get(span.checked_sub(p)?..=span)?.iter().enumerate() {
            a += *h * *f.get(k)?;
        }
        Some(a.truncate() / a.w)
    }
}

/// A2.1 FindSpan with `t` clamped into `[u_p, u_n]`: the span index and the clamped `t`.
#[must_use]
fn span(knots: &[f64], p: usize, n: usize, t: f64) -> Option<(usize, f64)> {
    let lo = *knots.get(p)?;
    let hi = *knots.get(n)?;
    if !(t.is_finite() && lo < hi) {
        return None;
    }
    let t = t.clamp(lo, hi);
    let inner = knots.get(p..n)?;
    let below = if t >= hi {
        inner.partition_point(|&k| k < hi)
    } else {
        inner.partition_point(|&k| k <= t)
    };
    // The span lies in [p, n − 1]: at least one knot of `inner` is ≤ t.
    (below >= 1).then_some((p + below - 1, t))
}

/// Basis values `n` and first derivatives `d` of the `p + 1` functions non-zero at `t` (A2.2
/// run to degree `p − 1`, kept, then to `p`; derivatives by eq. 2.7); returns the span and the
/// clamped `t`.
// Fixed-array indices are bounded by `p < N`, checked first.
#[allow(clippy::indexing_slicing)]
#[must_use]
fn basis<const N: usize>(
    knots: &[f64],
    p: usize,
    count: usize,
    t: f64,
    n: &mut [f64; N],
    d: &mut [f64; N],
) -> Option<usize> {
    if p >= N || p == 0 {
        return None;
    }
    let (span, t) = span(knots, p, count, t)?;
    let mut left = [0.0; N];
    let mut right = [0.0; N];
    let mut lower = [0.0; N];
    n[0] = 1.0;
    for j in 1..=p {
        if j == p {
            lower[..p].copy_from_slice(&n[..p]);
        }
        left[j] = t - knots.get((span + 1).checked_sub(j)?)?;
        right[j] = knots.get(span + j)? - t;
        let mut saved = 0.0;
        for r in 0..j {
            let den = right[r + 1] + left[j - r];
            let temp = if den != 0.0 { n[r] / den } else { 0.0 };
            n[r] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        n[j] = saved;
    }
    let pf = p as f64;
    for k in 0..=p {
        let i = span + k - p;
        let l = if k > 0 {
            let den = knots.get(i + p)? - knots.get(i)?;
            if den > 0.0 { lower[k - 1] / den } else { 0.0 }
        } else {
            0.0
        };
        let r = if k < p {
            let den = knots.get(i + p + 1)? - knots.get(i + 1)?;
            if den > 0.0 { lower[k] / den } else { 0.0 }
        } else {
            0.0
        };
        d[k] = pf * (l - r);
    }
    Some(span)
}

/// A2.2 BasisFuns: the `p + 1` degree-`p` functions non-zero on `span` at `t`.
// Fixed-array indices are bounded by `p ≤ MAX_DEGREE`, checked first.
#[allow(clippy::indexing_slicing)]
#[must_use]
fn funs(knots: &[f64], span: usize, t: f64, p: usize) -> Option<[f64; MAX_DEGREE + 1]> {
    if p > MAX_DEGREE {
        return None;
    }
    let mut n = [0.0; MAX_DEGREE + 1];
    let mut left = [0.0; MAX_DEGREE + 1];
    let mut right = [0.0; MAX_DEGREE + 1];
    n[0] = 1.0;
    for j in 1..=p {
        left[j] = t - knots.get((span + 1).checked_sub(j)?)?;
        right[j] = knots.get(span + j)? - t;
        let mut saved = 0.0;
        for r in 0..j {
            let den = right[r + 1] + left[j - r];
            let temp = if den != 0.0 { n[r] / den } else { 0.0 };
            n[r] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        n[j] = saved;
    }
    Some(n)
}
