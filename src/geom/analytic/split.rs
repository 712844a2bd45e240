//! Extracting the piece of a NURBS curve over a sub-range, so that surfaces of
//! revolution and extrusion cover exactly the face's parameter box.

use glam::DVec4;

use super::error::{AnalyticError, Result, clamp, finite};
use super::nurbs::{NurbsCurve, find_span, homogeneous};

/// Relative distance below which a cut is snapped onto an existing knot, so
/// that no sliver span of a few ulps is created.
const SNAP: f64 = 4.0 * f64::EPSILON;

/// Boehm single knot insertion (The NURBS Book A5.1 CurveKnotIns with r = 1)
/// on homogeneous points; the curve is unchanged.
fn insert_once(knots: &mut Vec<f64>, pts: &mut Vec<DVec4>, p: usize, t: f64) -> Option<()> {
    let n = pts.len();
    let k = find_span(knots, p, n, t)?;
    let mut out = Vec::with_capacity(n + 1);
    out.extend_from_slice(pts.get(..=k.checked_sub(p)?)?);
    for i in k - p + 1..=k {
        let (ui, uip) = (*knots.get(i)?, *knots.get(i + p)?);
        let alpha = (t - ui) / (uip - ui);
        out.push(*pts.get(i)? * alpha + *pts.get(i - 1)? * (1.0 - alpha));
    }
    out.extend_from_slice(pts.get(k..)?);
    knots.insert(k + 1, t);
    *pts = out;
    Some(())
}

/// Inserts `t` until it has multiplicity at least `p + 1`.
fn saturate(knots: &mut Vec<f64>, pts: &mut Vec<DVec4>, p: usize, t: f64) -> Option<()> {
    let have = knots.iter().filter(|&&k| k == t).count();
    for _ in have..=p {
        insert_once(knots, pts, p, t)?;
    }
    Some(())
}

/// Moves `t` onto a knot closer than [`SNAP`] of the knot vector's scale.
fn snap(knots: &[f64], t: f64, scale: f64) -> f64 {
    knots
        .iter()
        .copied()
        .find(|k| (k - t).abs() <= SNAP * scale)
        .unwrap_or(t)
}

impl NurbsCurve {
    /// The same curve restricted to `[a, b]`, with its parameter unchanged
    /// (so an identity parameter map stays exact).
    ///
    /// Cuts are made by inserting `a` and `b` to full multiplicity (A5.1) and
    /// keeping the control points in between. `a`/`b` outside the domain by
    /// at most 1e-12 of its length are clamped onto it.
    ///
    /// # Errors
    /// Invalid curve, non-finite or empty range, or a range outside the domain.
    pub fn segment(&self, a: f64, b: f64) -> Result<NurbsCurve> {
        let [lo, hi] = self.domain()?;
        finite(a, "curve range start")?;
        finite(b, "curve range end")?;
        let slack = 1e-12 * (hi - lo);
        if a < lo - slack || b > hi + slack {
            let what = "profile";
            return Err(AnalyticError::OutOfDomain {
                what,
                lo: a,
                hi: b,
                dom_lo: lo,
                dom_hi: hi,
            });
        }
        let scale = lo.abs().max(hi.abs()).max(hi - lo);
        let a = snap(&self.knots, clamp(a, lo, hi), scale);
        let b = snap(&self.knots, clamp(b, lo, hi), scale);
        if a >= b {
            return Err(AnalyticError::EmptyRange {
                what: "profile",
                lo: a,
                hi: b,
            });
        }
        self.cut(a, b)
            .ok_or(AnalyticError::InvalidNurbs("segment extraction failed"))
    }

    /// Saturates `a` and `b` (A5.1) and keeps the knots/points between.
    fn cut(&self, a: f64, b: f64) -> Option<NurbsCurve> {
        let p = self.degree;
        let mut knots = self.knots.clone();
        let mut pts: Vec<DVec4> = self
            .points
            .iter()
            .zip(&self.weights)
            .map(|(&q, &w)| homogeneous(q, w))
            .collect();
        saturate(&mut knots, &mut pts, p, a)?;
        saturate(&mut knots, &mut pts, p, b)?;
        let ja = knots.iter().rposition(|&k| k == a)?.checked_sub(p)?;
        let jb = knots.iter().position(|&k| k == b)? + p;
        let knots = knots.get(ja..=jb)?.to_vec();
        let kept = pts.get(ja..=jb.checked_sub(p + 1)?)?;
        Some(NurbsCurve {
            degree: p,
            knots,
            points: kept.iter().map(|h| h.truncate() / h.w).collect(),
            weights: kept.iter().map(|h| h.w).collect(),
        })
    }
}
