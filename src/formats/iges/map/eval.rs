//! A point-and-first-derivatives evaluator for a surface validated once. The analytic crate's
//! public `derivs` validates the whole net on every call (its unchecked evaluator is private to
//! it), which makes the millions of evaluations of an area integral slow; this one checks once
//! and then runs The NURBS Book's A2.2/A2.3 basis functions with first derivatives.

use crate::geom::analytic::{NurbsCurve, NurbsSurface};
use glam::{DVec3, DVec4};

/// A validated surface ready for repeated evaluation.
pub struct Evaluator<'s> {
    s: &'s NurbsSurface,
    n: [usize; 2],
}

/// Span index `k` with `knots[k] <= t < knots[k + 1]` inside `[knots[p], knots[n]]` (the last
/// non-empty span at the right end).
fn span(knots: &[f64], p: usize, n: usize, t: f64) -> Option<usize> {
    let inner = knots.get(p..=n)?;
    let (lo, hi) = (*inner.first()?, *inner.last()?);
    let t = t.clamp(lo, hi);
    let below = if t >= hi {
        inner.partition_point(|&k| k < hi)
    } else {
        inner.partition_point(|&k| k <= t)
    };
    (p + below).checked_sub(1)
}

/// Highest degree evaluated without allocating.
pub const MAX_DEGREE: usize = 15;

type Row = [f64; MAX_DEGREE + 1];

/// The `p + 1` non-zero basis functions at `t` on span `k` and their first derivatives
/// (A2.2, with the first derivative of A2.3 from the degree `p − 1` functions).
fn basis(knots: &[f64], p: usize, k: usize, t: f64) -> Option<(Row, Row)> {
    if p > MAX_DEGREE {
        return None;
    }
    let (mut left, mut right): (Row, Row) = ([0.0; MAX_DEGREE + 1], [0.0; MAX_DEGREE + 1]);
    let mut n: Row = [0.0; MAX_DEGREE + 1];
    let mut lower: Row = [0.0; MAX_DEGREE + 1];
    *n.get_mut(0)? = 1.0;
    for j in 1..=p {
        *left.get_mut(j)? = t - knots.get((k + 1).checked_sub(j)?)?;
        *right.get_mut(j)? = knots.get(k + j)? - t;
        if j == p {
            lower = n;
        }
        let mut saved = 0.0;
        for r in 0..j {
            let den = right.get(r + 1)? + left.get(j - r)?;
            let temp = if den != 0.0 { n.get(r)? / den } else { 0.0 };
            *n.get_mut(r)? = saved + right.get(r + 1)? * temp;
            saved = left.get(j - r)? * temp;
        }
        *n.get_mut(j)? = saved;
    }
    let mut d: Row = [0.0; MAX_DEGREE + 1];
    // N'_{i,p} = p (N_{i,p-1} / (u_{i+p} − u_i) − N_{i+1,p-1} / (u_{i+p+1} − u_{i+1})).
    for r in 0..=p {
        let i = (k + r).checked_sub(p)?;
        let a = if r >= 1 { *lower.get(r - 1)? } else { 0.0 };
        let b = if r < p { *lower.get(r)? } else { 0.0 };
        let da = knots.get(i + p)? - knots.get(i)?;
        let db = knots.get(i + p + 1)? - knots.get(i + 1)?;
        let ta = if da != 0.0 { a / da } else { 0.0 };
        let tb = if db != 0.0 { b / db } else { 0.0 };
        *d.get_mut(r)? = p as f64 * (ta - tb);
    }
    Some((n, d))
}

impl<'s> Evaluator<'s> {
    /// Validates `s` once.
    pub fn new(s: &'s NurbsSurface) -> Result<Self, String> {
        s.validate().map_err(|e| e.to_string())?;
        let n = [
            s.knots[0].len() - s.degree[0] - 1,
            s.knots[1].len() - s.degree[1] - 1,
        ];
        Ok(Self { s, n })
    }

    /// `S`, `S_u`, `S_v` at `(u, v)` (clamped into the domain).
    #[must_use]
    pub fn eval(&self, u: f64, v: f64) -> Option<[DVec3; 3]> {
        let s = self.s;
        let [pu, pv] = s.degree;
        let [nu, nv] = self.n;
        let (ku, kv) = (&s.knots[0], &s.knots[1]);
        let su = span(ku, pu, nu, u)?;
        let sv = span(kv, pv, nv, v)?;
        let u = u.clamp(*ku.get(pu)?, *ku.get(nu)?);
        let v = v.clamp(*kv.get(pv)?, *kv.get(nv)?);
        let (bu, du) = basis(ku, pu, su, u)?;
        let (bv, dv) = basis(kv, pv, sv, v)?;
        let (mut a, mut au, mut av) = (DVec4::ZERO, DVec4::ZERO, DVec4::ZERO);
        for (r, (nu_r, du_r)) in bu.iter().zip(&du).take(pu + 1).enumerate() {
            let i = (su + r).checked_sub(pu)?;
            for (c, (nv_c, dv_c)) in bv.iter().zip(&dv).take(pv + 1).enumerate() {
                let j = (sv + c).checked_sub(pv)?;
                let idx = i * nv + j;
                let w = *s.weights.get(idx)?;
                let h = (*s.points.get(idx)? * w).extend(w);
                a += h * (nu_r * nv_c);
                au += h * (du_r * nv_c);
                av += h * (nu_r * dv_c);
            }
        }
        let p = a.truncate() / a.w;
        let d_u = (au.truncate() - au.w * p) / a.w;
        let d_v = (av.truncate() - av.w * p) / a.w;
        Some([p, d_u, d_v])
    }
}

/// A curve validated once, evaluated by de Boor's algorithm on homogeneous points without
/// allocating (degrees up to [`MAX_DEGREE`]; higher degrees fall back to the analytic crate).
pub struct CurveEvaluator<'c> {
    c: &'c NurbsCurve,
    lo: f64,
    hi: f64,
}

impl<'c> CurveEvaluator<'c> {
    /// Validates `c` once.
    pub fn new(c: &'c NurbsCurve) -> Result<Self, String> {
        let [lo, hi] = c.domain().map_err(|e| e.to_string())?;
        Ok(Self { c, lo, hi })
    }

    /// The parameter domain.
    #[must_use]
    pub fn domain(&self) -> (f64, f64) {
        (self.lo, self.hi)
    }

    /// The point at `t` (clamped into the domain).
    #[must_use]
    pub fn point(&self, t: f64) -> Option<DVec3> {
        let c = self.c;
        let p = c.degree;
        if p > MAX_DEGREE {
            return c.point(t).ok();
        }
        let n = c.points.len();
        let k = span(&c.knots, p, n, t)?;
        let t = t.clamp(self.lo, self.hi);
        let mut d = [DVec4::ZERO; MAX_DEGREE + 1];
        for (j, slot) in d.iter_mut().take(p + 1).enumerate() {
            let i = (k + j).checked_sub(p)?;
            let w = *c.weights.get(i)?;
            *slot = (*c.points.get(i)? * w).extend(w);
        }
        for r in 1..=p {
            for j in (r..=p).rev() {
                let i = (k + j).checked_sub(p)?;
                let a = *c.knots.get(i)?;
                let b = *c.knots.get(i + p + 1 - r)?;
                let alpha = if b > a { (t - a) / (b - a) } else { 0.0 };
                let prev = *d.get(j - 1)?;
                let cur = d.get_mut(j)?;
                *cur = prev * (1.0 - alpha) + *cur * alpha;
            }
        }
        let h = *d.get(p)?;
        Some(h.truncate() / h.w)
    }
}
