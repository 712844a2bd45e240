//! Exact rational quadratic arcs whose knots sit at the segment angles, and
//! the closed-form maps between angle and NURBS parameter.
//!
//! # Segment rule: at most 90°
//! A sweep `Δ` is split into `n = ⌈|Δ| / 90°⌉` equal segments (full circle:
//! 4), as in The NURBS Book A7.1 MakeNurbsCircle. 90° rather than 120° keeps
//! the middle weight `cos(φ/2) ≥ 0.707` (vs 0.5), so the parametrisation is
//! closer to arc length (speed ratio ≤ 2 instead of 4), the control polygon
//! hugs the arc (bounding boxes and convex-hull culling are tighter) and the
//! tessellator's parameter-uniform sampling wastes fewer points, at the cost
//! of one extra segment for sweeps between 240° and 360°.
//!
//! # Parameter map
//! Knots are the segment boundary angles `a_k` themselves, so the NURBS
//! parameter equals the angle at every knot. Inside a segment of sweep `φ`
//! (half-sweep `h = φ/2`) with local parameter `s = (t − a_k)/φ ∈ [0, 1]`,
//! weights `1, cos h, 1`, control points `e^{i a_k}`, `e^{i(a_k+h)}/cos h`,
//! `e^{i a_{k+1}}`, the homogeneous numerator in complex form is
//! `(1−s)² + 2s(1−s)·cos h·e^{ih}/cos h + s²e^{2ih} = ((1−s) + s e^{ih})²`
//! (rotated by `a_k`), and the denominator is `|(1−s) + s e^{ih}|²`. So the
//! point is `e^{i·2·arg((1−s) + s e^{ih})}`, i.e. the angle `α` from `a_k` obeys
//!
//! `tan(α/2) = s sin h / ((1 − s) + s cos h)`.
//!
//! Solving for `s` with `γ = α/2` gives the cancellation-free inverse
//! `s = sin γ / (sin γ + sin(h − γ))` (both terms ≥ 0 on the segment).
//!
//! # Orientation
//! A reversed range (`θ1 < θ0`) is supported: the NURBS parameter is then
//! `t = −θ` (knots at the negated angles, still increasing), which is the
//! forward arc with `Y` negated.

use std::f64::consts::{FRAC_PI_2, TAU};

use glam::{DVec2, DVec3};

use super::error::{AnalyticError, Result, clamp, finite, finite_vec, positive};
use super::frame::Frame;
use super::nurbs::NurbsCurve;

/// Sweeps may exceed 2π by this relative amount (rounding of `θ0 + 2π`).
const SWEEP_SLACK: f64 = 1e-12;

/// The angle ↔ parameter map of one arc and its unit-circle control polygon.
#[derive(Debug, Clone, PartialEq)]
pub struct ArcMap {
    /// Segment boundaries in parameter units (`sign · angle`), increasing.
    breaks: Vec<f64>,
    /// `+1` for `θ1 > θ0`, `−1` for a reversed arc.
    sign: f64,
}

impl ArcMap {
    /// The map for angles `theta0 → theta1` (radians, `0 < |θ1 − θ0| ≤ 2π`).
    ///
    /// # Errors
    /// Non-finite angles, an empty range, or a sweep above 2π.
    pub fn new(theta0: f64, theta1: f64) -> Result<Self> {
        finite(theta0, "start angle")?;
        finite(theta1, "end angle")?;
        let sweep = (theta1 - theta0).abs();
        if !sweep.is_finite() {
            return Err(AnalyticError::NonFinite {
                what: "angle sweep",
            });
        }
        if sweep > TAU * (1.0 + SWEEP_SLACK) {
            return Err(AnalyticError::SweepTooLarge {
                what: "angle",
                sweep,
            });
        }
        let sign = if theta1 >= theta0 { 1.0 } else { -1.0 };
        let (a0, a1) = (sign * theta0, sign * theta1);
        // ceil with slack so that an exact 90° multiple is not split further.
        let n = ((sweep / FRAC_PI_2) * (1.0 - SWEEP_SLACK)).ceil().max(1.0) as usize;
        let mut breaks: Vec<f64> = (0..n)
            .map(|k| a0 + (a1 - a0) * (k as f64 / n as f64))
            .collect();
        breaks.push(a1);
        if breaks.windows(2).any(|w| matches!(w, [a, b] if b <= a)) {
            return Err(AnalyticError::EmptyRange {
                what: "angle",
                lo: theta0,
                hi: theta1,
            });
        }
        Ok(Self { breaks, sign })
    }

    /// Number of rational quadratic segments.
    #[must_use]
    pub fn segments(&self) -> usize {
        self.breaks.len().saturating_sub(1)
    }

    /// Segment boundaries in NURBS parameter units (equal to the angles, or
    /// their negatives for a reversed arc).
    #[must_use]
    pub fn breakpoints(&self) -> &[f64] {
        &self.breaks
    }

    /// `+1.0` for an increasing angle range, `−1.0` for a reversed one.
    #[must_use]
    pub fn sign(&self) -> f64 {
        self.sign
    }

    /// The NURBS parameter domain `[t0, t1]`.
    #[must_use]
    pub fn domain(&self) -> [f64; 2] {
        let first = self.breaks.first().copied().unwrap_or(0.0);
        [first, self.breaks.last().copied().unwrap_or(first)]
    }

    /// The clamped quadratic knot vector `[a0,a0,a0, a1,a1, …, an,an,an]`.
    #[must_use]
    pub fn knot_vector(&self) -> Vec<f64> {
        let mut k = Vec::with_capacity(2 * self.breaks.len() + 2);
        for (i, &b) in self.breaks.iter().enumerate() {
            let copies = if i == 0 || i + 1 == self.breaks.len() {
                3
            } else {
                2
            };
            k.extend(std::iter::repeat_n(b, copies));
        }
        k
    }

    /// Unit-circle control points `(x, y)` (meaning `x·X + y·Y`) and weights,
    /// `2n + 1` of them (A7.1: ends on the circle, middles at the tangent
    /// intersections `e^{i m}/cos h` with weight `cos h`).
    #[must_use]
    pub fn unit_polygon(&self) -> Vec<(DVec2, f64)> {
        let on = |a: f64| DVec2::new(a.cos(), self.sign * a.sin());
        let mut out = Vec::with_capacity(2 * self.breaks.len());
        if let Some(&a) = self.breaks.first() {
            out.push((on(a), 1.0));
        }
        for w in self.breaks.windows(2) {
            if let [a, b] = *w {
                let h = 0.5 * (b - a);
                let c = h.cos();
                out.push((on(a + h) / c, c));
                out.push((on(b), 1.0));
            }
        }
        out
    }

    /// Segment `(start, end)` containing parameter `t` (clamped): the last
    /// segment whose start is `≤ t`.
    fn segment_of(&self, t: f64) -> (f64, f64) {
        let n = self.segments().max(1);
        let k = self.breaks.partition_point(|&b| b <= t).clamp(1, n) - 1;
        let a = self.breaks.get(k).copied().unwrap_or(t);
        (a, self.breaks.get(k + 1).copied().unwrap_or(a))
    }

    /// Angle (radians) → NURBS parameter, in closed form; angles outside the
    /// arc's range are clamped to its ends. Exact at the knots, monotone.
    #[must_use]
    pub fn angle_to_param(&self, theta: f64) -> f64 {
        let [lo, hi] = self.domain();
        let psi = clamp(self.sign * theta, lo, hi);
        let (a, b) = self.segment_of(psi);
        let h = 0.5 * (b - a);
        let g = clamp(0.5 * (psi - a), 0.0, h);
        let (sg, sr) = (g.sin(), (h - g).sin());
        if sr <= 0.0 {
            return b;
        }
        let s = sg / (sg + sr);
        clamp(a + s * (b - a), a, b)
    }

    /// NURBS parameter → angle (radians), in closed form via
    /// `tan(α/2) = s sin h / ((1−s) + s cos h)`; clamped, exact at knots.
    #[must_use]
    pub fn param_to_angle(&self, t: f64) -> f64 {
        let [lo, hi] = self.domain();
        let t = clamp(t, lo, hi);
        let (a, b) = self.segment_of(t);
        let s = (t - a) / (b - a);
        let psi = if s >= 1.0 {
            b
        } else {
            let h = 0.5 * (b - a);
            let g = (s * h.sin()).atan2((1.0 - s) + s * h.cos());
            clamp(a + 2.0 * g, a, b)
        };
        self.sign * psi
    }
}

/// Builds the curve `C + rx·x(θ)·X + ry·y(θ)·Y` over the arc.
fn scaled_arc(frame: &Frame, rx: f64, ry: f64, map: &ArcMap) -> NurbsCurve {
    let (points, weights) = map
        .unit_polygon()
        .into_iter()
        .map(|(q, w)| (frame.to_world(rx * q.x, ry * q.y, 0.0), w))
        .unzip();
    NurbsCurve {
        degree: 2,
        knots: map.knot_vector(),
        points,
        weights,
    }
}

/// STEP CIRCLE `C + R(cos θ X + sin θ Y)` over `[θ0, θ1]` as an exact
/// rational quadratic (A7.1 MakeNurbsCircle, knots at the segment angles).
///
/// # Errors
/// Bad frame, non-positive radius, or a bad angle range (see [`ArcMap::new`]).
pub fn circle_arc(
    frame: &Frame,
    radius: f64,
    theta0: f64,
    theta1: f64,
) -> Result<(NurbsCurve, ArcMap)> {
    ellipse_arc(frame, radius, radius, theta0, theta1)
}

/// STEP ELLIPSE `C + a cos θ X + b sin θ Y` over `[θ0, θ1]`: the affine image
/// of the unit circle, so it shares the circle's weights, knots and map (θ is
/// the eccentric angle, exactly as STEP parametrises it).
///
/// # Errors
/// Bad frame, non-positive semi-axis, or a bad angle range.
pub fn ellipse_arc(
    frame: &Frame,
    semi_x: f64,
    semi_y: f64,
    theta0: f64,
    theta1: f64,
) -> Result<(NurbsCurve, ArcMap)> {
    frame.validate()?;
    positive(semi_x, "ellipse semi-axis 1")?;
    positive(semi_y, "ellipse semi-axis 2")?;
    let map = ArcMap::new(theta0, theta1)?;
    Ok((scaled_arc(frame, semi_x, semi_y, &map), map))
}

/// STEP LINE `P + t·V` over `[t0, t1]` as a degree-1 NURBS whose parameter is
/// `t` itself (knots `[t0, t0, t1, t1]`); `V` keeps its magnitude, as in STEP.
///
/// # Errors
/// Non-finite input, zero direction, or `t1 ≤ t0`.
pub fn line_segment(point: DVec3, direction: DVec3, t0: f64, t1: f64) -> Result<NurbsCurve> {
    finite_vec(point, "line point")?;
    finite_vec(direction, "line direction")?;
    if direction.length_squared() == 0.0 {
        return Err(AnalyticError::ZeroVector {
            what: "line direction",
        });
    }
    finite(t0, "line start")?;
    finite(t1, "line end")?;
    if t1 <= t0 {
        return Err(AnalyticError::EmptyRange {
            what: "line",
            lo: t0,
            hi: t1,
        });
    }
    Ok(NurbsCurve {
        degree: 1,
        knots: vec![t0, t0, t1, t1],
        points: vec![point + t0 * direction, point + t1 * direction],
        weights: vec![1.0, 1.0],
    })
}
