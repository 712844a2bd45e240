//! IGES curves as exact NURBS, placed: circular arcs (entity 100), composites (102), conic arcs
//! in standard position (104), copious data (106, forms 1–3, 11–13, 63), lines (110), parametric
//! splines (112) and rational B-splines (126). The same code reads model-space curves (placed in
//! millimetres) and parameter-space curves (placed by their own 124 only, z ignored).
//!
//! Each curve keeps how the file's own parameter maps onto the NURBS parameter, because surfaces
//! of revolution (120) and tabulated cylinders (122) are parametrised through the parameter of
//! their generatrix or directrix.

use std::f64::consts::TAU;

use crate::formats::iges::{Entity, Transform};
use crate::geom::analytic::{ArcMap, Frame, NurbsCurve, ellipse_arc};
use glam::DVec3;

use super::fail::{Mapped, geometry, malformed, skip};
use super::reader::{CURVES, MAX_DEPTH, Reader};

/// How the IGES parameter of a curve relates to the parameter of its NURBS form.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum CurveParam {
    /// The same parameter (lines on [0, 1], splines on their breakpoints, B-splines).
    Same,
    /// The IGES parameter is an angle (circular arcs, ellipses by their eccentric angle).
    Arc(ArcMap),
    /// The NURBS form is exact in shape only (parabolas, hyperbolas, copious data).
    Shape,
}

/// One curve as an exact NURBS, with the file's parameter range and its map.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Curve {
    pub nurbs: NurbsCurve,
    pub param: CurveParam,
    /// The IGES parameter range `[start, end]` of the curve.
    pub range: [f64; 2],
}

impl Curve {
    /// IGES parameter → NURBS parameter, `None` where only the shape is known.
    #[must_use]
    pub fn to_nurbs(&self, t: f64) -> Option<f64> {
        match &self.param {
            CurveParam::Same => Some(t),
            CurveParam::Arc(map) => Some(map.angle_to_param(t)),
            CurveParam::Shape => None,
        }
    }
}

/// Applies an affine placement to a curve's control points (exact for rational curves).
pub(crate) fn place_curve(c: &mut NurbsCurve, t: &Transform) {
    if !t.is_identity() {
        for p in &mut c.points {
            *p = DVec3::from_array(t.apply_point(p.to_array()));
        }
    }
}

fn point(e: &Entity, k: usize) -> Mapped<DVec3> {
    Ok(DVec3::new(e.real(k)?, e.real(k + 1)?, e.real(k + 2)?))
}

/// A degree-1 curve through `points` with the parameter of point `k` equal to `k`.
fn polyline(e: &Entity, points: Vec<DVec3>, param: CurveParam) -> Mapped<Curve> {
    if points.len() < 2 {
        return Err(malformed(e, "has fewer than two points"));
    }
    let n = points.len();
    let mut knots = vec![0.0];
    knots.extend((0..n).map(|k| k as f64));
    knots.push((n - 1) as f64);
    Ok(Curve {
        range: [0.0, (n - 1) as f64],
        nurbs: NurbsCurve {
            degree: 1,
            knots,
            weights: vec![1.0; n],
            points,
        },
        param,
    })
}

impl Reader<'_> {
    /// The curve `e` as a chain of NURBS pieces (one, or a composite's members in order), placed
    /// by `e`'s own transformation and then `outer`.
    pub fn curve(&mut self, e: &Entity, outer: &Transform, depth: usize) -> Mapped<Vec<Curve>> {
        if depth > MAX_DEPTH {
            return Err(malformed(e, "nests curves too deeply (a reference loop?)"));
        }
        self.mark(e);
        let place = self.placement(e, outer)?;
        let mut curve = match e.entity_type() {
            102 => return self.composite(e, &place, depth),
            116 => return Ok(Vec::new()),
            100 => arc(e)?,
            104 => conic(e)?,
            106 => copious(e)?,
            110 => line(e)?,
            112 => spline(e)?,
            126 => bspline(e)?,
            130 => {
                return Err(skip(
                    "offset curve (entity 130) in a boundary is not supported",
                ));
            }
            142 => {
                // A curve on a surface used as a plain curve: its model-space curve.
                let c = self.follow_kind(e, 4, &CURVES, "a model-space curve")?;
                return self.curve(c, &place, depth + 1);
            }
            t => {
                return Err(malformed(
                    e,
                    format!("is used as a curve, but entity {t} is not one"),
                ));
            }
        };
        place_curve(&mut curve.nurbs, &place);
        Ok(vec![curve])
    }

    /// Entity 102: the members in order; each is defined in the composite's space.
    fn composite(&mut self, e: &Entity, place: &Transform, depth: usize) -> Mapped<Vec<Curve>> {
        let n = e.count(1)?;
        let mut out = Vec::with_capacity(n);
        for k in 0..n {
            let member = self.follow_kind(e, 2 + k, &CURVES, "a curve")?;
            out.extend(self.curve(member, place, depth + 1)?);
        }
        Ok(out)
    }
}

/// Entity 100: counter-clockwise from the start to the end point in the plane `z = ZT`; the same
/// start and end point make a full circle. The IGES parameter is the angle.
fn arc(e: &Entity) -> Mapped<Curve> {
    let zt = e.real(1)?;
    let (cx, cy) = (e.real(2)?, e.real(3)?);
    let (sx, sy) = (e.real(4)? - cx, e.real(5)? - cy);
    let (ex, ey) = (e.real(6)? - cx, e.real(7)? - cy);
    let radius = sx.hypot(sy);
    if !(radius.is_finite() && radius > 0.0) {
        return Err(malformed(e, "has a zero or non-finite radius"));
    }
    let a0 = sy.atan2(sx);
    let mut a1 = ey.atan2(ex);
    let closing = (ex - sx).hypot(ey - sy) <= 1e-9 * radius;
    if closing {
        a1 = a0 + TAU;
    } else if a1 <= a0 {
        a1 += TAU;
    }
    let frame = Frame {
        origin: DVec3::new(cx, cy, zt),
        x: DVec3::X,
        y: DVec3::Y,
        z: DVec3::Z,
    };
    let (nurbs, map) = geometry(ellipse_arc(&frame, radius, radius, a0, a1), "circular arc")?;
    Ok(Curve {
        nurbs,
        param: CurveParam::Arc(map),
        range: [a0, a1],
    })
}

/// Entity 110: `P1 + t (P2 − P1)`, `t ∈ [0, 1]`.
fn line(e: &Entity) -> Mapped<Curve> {
    let (p1, p2) = (point(e, 1)?, point(e, 4)?);
    if !(p1.is_finite() && p2.is_finite()) {
        return Err(malformed(e, "has a non-finite end point"));
    }
    Ok(Curve {
        nurbs: NurbsCurve {
            degree: 1,
            knots: vec![0.0, 0.0, 1.0, 1.0],
            points: vec![p1, p2],
            weights: vec![1.0, 1.0],
        },
        param: CurveParam::Same,
        range: [0.0, 1.0],
    })
}

/// Entity 106: forms 1/11/63 are (x, y) pairs at a common z, 2/12 triples, 3/13 triples with a
/// vector each (the vectors are not part of the curve).
fn copious(e: &Entity) -> Mapped<Curve> {
    let ip = e.int(1)?;
    let n = e.count(2)?;
    let (first, stride, common_z) = match ip {
        1 => (4, 2, Some(e.real(3)?)),
        2 => (3, 3, None),
        3 => (3, 6, None),
        _ => return Err(malformed(e, format!("has data type {ip}, not 1, 2 or 3"))),
    };
    let values = e.reals(first, n.saturating_mul(stride))?;
    let points = values
        .chunks_exact(stride)
        .map(|c| match (c, common_z) {
            ([x, y, ..], Some(z)) => DVec3::new(*x, *y, z),
            ([x, y, z, ..], None) => DVec3::new(*x, *y, *z),
            _ => DVec3::ZERO,
        })
        .collect();
    polyline(e, points, CurveParam::Shape)
}

/// Entity 112: `N` cubic (or lower) segments, each `A + B s + C s² + D s³` per coordinate in the
/// local parameter `s = t − T(i)`; converted per segment to Bézier form, joined with knots of
/// multiplicity 3 at the breakpoints (exact, C0 between segments as the file allows).
fn spline(e: &Entity) -> Mapped<Curve> {
    let ndim = e.int(3)?;
    let n = e.count(4)?;
    if n == 0 {
        return Err(malformed(e, "has no segments"));
    }
    let breaks = e.reals(5, n + 1)?;
    let coeffs = e.reals(6 + n, n.saturating_mul(12))?;
    let mut points = Vec::with_capacity(3 * n + 1);
    let mut knots = Vec::with_capacity(3 * n + 5);
    for ((seg, pair), k) in coeffs.chunks_exact(12).zip(breaks.windows(2)).zip(0..) {
        let (h, t0) = match pair {
            [a, b] if b > a => (b - a, *a),
            _ => return Err(malformed(e, "has breakpoints that do not increase")),
        };
        let (cx, rest) = seg.split_at(4);
        let (cy, cz) = rest.split_at(4);
        let [x, y, mut z] = [cx, cy, cz].map(|c| power_to_bezier(c, h));
        if ndim == 2 {
            z = [cz.first().copied().unwrap_or_default(); 4];
        }
        let start = usize::from(k > 0);
        let pts = x
            .iter()
            .zip(&y)
            .zip(&z)
            .map(|((x, y), z)| DVec3::new(*x, *y, *z));
        points.extend(pts.skip(start));
        knots.extend(std::iter::repeat_n(t0, if k == 0 { 4 } else { 3 }));
    }
    let end = breaks.last().copied().unwrap_or_default();
    knots.extend([end; 4]);
    let weights = vec![1.0; points.len()];
    let range = [breaks.first().copied().unwrap_or_default(), end];
    Ok(Curve {
        nurbs: NurbsCurve {
            degree: 3,
            knots,
            points,
            weights,
        },
        param: CurveParam::Same,
        range,
    })
}

/// Bézier control values of the cubic `a + b s + c s² + d s³` on `s ∈ [0, h]`.
#[must_use]
pub(crate) fn power_to_bezier(c: &[f64], h: f64) -> [f64; 4] {
    let g = |k: usize| c.get(k).copied().unwrap_or(0.0);
    let (a, b, c2, d) = (g(0), g(1) * h, g(2) * h * h, g(3) * h * h * h);
    [a, a + b / 3.0, a + 2.0 * b / 3.0 + c2 / 3.0, a + b + c2 + d]
}

/// Entity 126: `K + 1` control points of degree `M`, knots `T(−M) … T(N + M)`, weights, points,
/// then the parameter range `[V0, V1]`, which may be a part of the knot domain.
fn bspline(e: &Entity) -> Mapped<Curve> {
    let k = e.count(1)?;
    let m = e.count(2)?;
    if m == 0 || k < m {
        return Err(malformed(e, format!("has upper index {k} and degree {m}")));
    }
    let n_knots = k + m + 2;
    let knots = e.reals(7, n_knots)?;
    let weights = e.reals(7 + n_knots, k + 1)?;
    let xyz = e.reals(8 + n_knots + k, 3 * (k + 1))?;
    let points = xyz
        .chunks_exact(3)
        .map(|c| match c {
            [x, y, z] => DVec3::new(*x, *y, *z),
            _ => DVec3::ZERO,
        })
        .collect();
    let at = 8 + n_knots + k + 3 * (k + 1);
    let (v0, v1) = (e.real(at)?, e.real(at + 1)?);
    let curve = NurbsCurve {
        degree: m,
        knots,
        points,
        weights,
    };
    let domain = curve
        .domain()
        .map_err(|err| malformed(e, format!("is not a valid B-spline: {err}")))?;
    let (a, b) = (v0.max(domain[0]), v1.min(domain[1]));
    let nurbs = if a < b && (a > domain[0] || b < domain[1] || !clamped(&curve)) {
        geometry(curve.segment(a, b), "B-spline curve range")?
    } else {
        curve
    };
    Ok(Curve {
        nurbs,
        param: CurveParam::Same,
        range: [a.min(b), b.max(a)],
    })
}

/// Whether the end knots have full multiplicity, so the end control points are the end points.
#[must_use]
pub(crate) fn clamped(c: &NurbsCurve) -> bool {
    let p = c.degree;
    let first = c.knots.get(..=p);
    let last = c
        .knots
        .len()
        .checked_sub(p + 1)
        .and_then(|s| c.knots.get(s..));
    let flat =
        |s: Option<&[f64]>| s.is_some_and(|s| s.windows(2).all(|w| matches!(w, [a, b] if a == b)));
    flat(first) && flat(last)
}

/// Entity 104 in standard position (IGES 5.3 requires it: `B = D = E = 0` for the central
/// conics, `A = E = 0`-type for parabolas): ellipses by their eccentric angle (exact, with the
/// angle as parameter), parabolas and hyperbolas as exact rational quadratics.
fn conic(e: &Entity) -> Mapped<Curve> {
    let [a, b, c, d, ee, f] = [
        e.real(1)?,
        e.real(2)?,
        e.real(3)?,
        e.real(4)?,
        e.real(5)?,
        e.real(6)?,
    ];
    let zt = e.real(7)?;
    let (s, t) = ([e.real(8)?, e.real(9)?], [e.real(10)?, e.real(11)?]);
    let not_standard = || skip("conic arc (entity 104) not in standard position");
    if b != 0.0 {
        return Err(not_standard());
    }
    if d == 0.0 && ee == 0.0 && a * c > 0.0 && f * a < 0.0 {
        let (ra, rb) = ((-f / a).sqrt(), (-f / c).sqrt());
        let t0 = (s[1] / rb).atan2(s[0] / ra);
        let mut t1 = (t[1] / rb).atan2(t[0] / ra);
        if t1 <= t0 + 1e-12 {
            t1 += TAU;
        }
        let frame = Frame {
            origin: DVec3::new(0.0, 0.0, zt),
            x: DVec3::X,
            y: DVec3::Y,
            z: DVec3::Z,
        };
        let (nurbs, map) = geometry(ellipse_arc(&frame, ra, rb, t0, t1), "ellipse")?;
        return Ok(Curve {
            nurbs,
            param: CurveParam::Arc(map),
            range: [t0, t1],
        });
    }
    if d == 0.0 && ee == 0.0 && a * c < 0.0 && f != 0.0 {
        return hyperbola(e, [a, c, f], s, t, zt);
    }
    parabola(e, [a, c, d, ee, f], s, t, zt).ok_or_else(not_standard)?
}

/// `A x² + C y² + F = 0` with `A C < 0`: with the transverse axis along x, `x = ±a cosh σ`,
/// `y = b sinh σ`; the arc from `σ0` to `σ1` is the rational quadratic with middle weight
/// `cosh((σ1 − σ0)/2)` (the hyperbolic analogue of the circle's `cos(Δ/2)`).
fn hyperbola(e: &Entity, [a, c, f]: [f64; 3], s: [f64; 2], t: [f64; 2], zt: f64) -> Mapped<Curve> {
    let swap = -f / a <= 0.0;
    let (ra, rb) = if swap {
        ((-f / c).sqrt(), (f / a).sqrt())
    } else {
        ((-f / a).sqrt(), (f / c).sqrt())
    };
    let local = |p: [f64; 2]| if swap { [p[1], p[0]] } else { p };
    let (ls, lt) = (local(s), local(t));
    let sign = if ls[0] < 0.0 { -1.0 } else { 1.0 };
    let (s0, s1) = ((ls[1] / rb).asinh(), (lt[1] / rb).asinh());
    let (m, h) = (0.5 * (s0 + s1), 0.5 * (s1 - s0));
    let w = h.cosh();
    let to_world = |x: f64, y: f64| {
        let (x, y) = (sign * ra * x, rb * y);
        if swap {
            DVec3::new(y, x, zt)
        } else {
            DVec3::new(x, y, zt)
        }
    };
    let points = vec![
        to_world(s0.cosh(), s0.sinh()),
        to_world(m.cosh() / w, m.sinh() / w),
        to_world(s1.cosh(), s1.sinh()),
    ];
    if !(points.iter().all(|p| p.is_finite()) && h != 0.0) {
        return Err(malformed(e, "is a degenerate hyperbola arc"));
    }
    Ok(Curve {
        nurbs: NurbsCurve {
            degree: 2,
            knots: vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
            points,
            weights: vec![1.0, w, 1.0],
        },
        param: CurveParam::Shape,
        range: [0.0, 1.0],
    })
}

/// `A x² + E y = 0` (or `C y² + D x = 0`): the arc between the end points is the quadratic Bézier
/// whose middle point is where the end tangents meet.
fn parabola(
    e: &Entity,
    [a, c, d, ee, f]: [f64; 5],
    s: [f64; 2],
    t: [f64; 2],
    zt: f64,
) -> Option<Mapped<Curve>> {
    if f != 0.0 {
        return None;
    }
    // y = k x² along x, or x = k y² along y (then the roles of x and y swap).
    let (k, swap) = if c == 0.0 && d == 0.0 && a != 0.0 && ee != 0.0 {
        (-a / ee, false)
    } else if a == 0.0 && ee == 0.0 && c != 0.0 && d != 0.0 {
        (-c / d, true)
    } else {
        return None;
    };
    let (x0, x1) = if swap { (s[1], t[1]) } else { (s[0], t[0]) };
    let mid = 0.5 * (x0 + x1);
    let pts = [(x0, k * x0 * x0), (mid, k * x0 * x1), (x1, k * x1 * x1)];
    let points = pts
        .iter()
        .map(|&(u, v)| {
            if swap {
                DVec3::new(v, u, zt)
            } else {
                DVec3::new(u, v, zt)
            }
        })
        .collect();
    if x0 == x1 {
        return Some(Err(malformed(e, "is a degenerate parabola arc")));
    }
    Some(Ok(Curve {
        nurbs: NurbsCurve {
            degree: 2,
            knots: vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
            points,
            weights: vec![1.0; 3],
        },
        param: CurveParam::Shape,
        range: [0.0, 1.0],
    }))
}
