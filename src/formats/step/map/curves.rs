//! ISO 10303-42 curves (§4.4.19 ff.) in one evaluable form, 3D and 2D alike (a 2D curve of a
//! parameter space has `z = 0`).
//!
//! LINE, CIRCLE, ELLIPSE, PARABOLA, HYPERBOLA, B_SPLINE_CURVE (with knots, uniform,
//! quasi-uniform, Bézier, rational), POLYLINE (a degree-1 B-spline through its points, parameter
//! `i` at point `i` as §4.4.34 defines it), TRIMMED_CURVE (basis and trims), and the 3D curve of
//! SURFACE_CURVE / SEAM_CURVE / INTERSECTION_CURVE. Conic parameters are angles, converted to
//! radians here. Each curve evaluates, inverts a point on it (closed form for the conics and
//! lines, sampling plus golden-section refinement for splines), and gives its exact rational
//! B-spline form over a range where one exists.

use crate::formats::step::{EntityRef, Value};
use crate::geom::analytic::{ArcMap, AxisMap, Frame, NurbsCurve, ellipse_arc, line_segment};
use glam::DVec3;

use super::attrs::{P, Res, bad, frame, frame2, is, part, point3, unsupported, vector};
use super::nurbs::{FastCurve, read_bspline_curve};

/// How deeply curves may refer to curves (TRIMMED_CURVE of a SURFACE_CURVE of …).
pub(crate) const MAX_NESTING: usize = 16;

/// An evaluable curve. Conic parameters are radians.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Curve {
    /// `P + t·D` (D keeps the VECTOR's magnitude).
    Line { p: DVec3, d: DVec3 },
    /// `C + a cos t X + b sin t Y`: CIRCLE (`a = b`) and ELLIPSE.
    Conic { frame: Frame, a: f64, b: f64 },
    /// `C + f (t² X + 2t Y)`.
    Parabola { frame: Frame, f: f64 },
    /// `C + a cosh t X + b sinh t Y`.
    Hyperbola { frame: Frame, a: f64, b: f64 },
    /// B-splines and polylines, with a fast evaluator.
    Nurbs(Box<Spline>),
}

/// A B-spline curve and its fast evaluator.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Spline {
    pub curve: NurbsCurve,
    fast: FastCurve,
    domain: (f64, f64),
}

impl Spline {
    /// Wraps a validated curve.
    #[must_use]
    pub(crate) fn new(curve: NurbsCurve) -> Box<Self> {
        let fast = FastCurve::new(&curve);
        let domain = curve.domain().map_or((0.0, 0.0), |[a, b]| (a, b));
        Box::new(Self {
            curve,
            fast,
            domain,
        })
    }
}

/// A curve read from the file, with the range a TRIMMED_CURVE gives it (`t0 > t1`: backwards).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Read {
    pub curve: Curve,
    pub trim: Option<(f64, f64)>,
}

/// Reads the curve `e`; `rad` converts the context's angle unit to radians.
pub(crate) fn read(e: EntityRef<'_>, rad: f64, depth: usize) -> Res<Read> {
    if depth > MAX_NESTING {
        return Err(bad(&e, "curves nested too deeply"));
    }
    let plain = |curve| Ok(Read { curve, trim: None });
    if is(&e, "B_SPLINE_CURVE") {
        return plain(Curve::Nurbs(Spline::new(read_bspline_curve(e)?)));
    }
    match e.name() {
        "LINE" => {
            let own = part(e, "LINE", 1)?;
            let p = point3(own.p(0, "pnt")?.ent()?)?;
            plain(Curve::Line {
                p,
                d: vector(own.p(1, "dir")?.ent()?)?,
            })
        }
        "CIRCLE" | "ELLIPSE" | "PARABOLA" | "HYPERBOLA" => plain(conic(e)?),
        "POLYLINE" => plain(Curve::Nurbs(Spline::new(polyline(e)?))),
        "TRIMMED_CURVE" => trimmed(e, rad, depth),
        "SURFACE_CURVE" | "SEAM_CURVE" | "INTERSECTION_CURVE" | "BOUNDED_SURFACE_CURVE" => {
            let c = part(e, "SURFACE_CURVE", 1)?.p(0, "curve_3d")?.ent()?;
            read(c, rad, depth + 1)
        }
        name if name.contains("CURVE") || name.contains("CLOTHOID") => {
            Err(unsupported(&e, "this curve type is not drawn yet"))
        }
        _ => Err(bad(&e, "should be a curve")),
    }
}

/// CIRCLE, ELLIPSE, PARABOLA, HYPERBOLA: a placement (3D or 2D) and sizes.
fn conic(e: EntityRef<'_>) -> Res<Curve> {
    let own = part(e, e.name(), 1)?;
    let pos = own.p(0, "position")?.ent()?;
    let frame = if is(&pos, "AXIS2_PLACEMENT_2D") {
        let (c, x, y) = frame2(pos)?;
        Frame {
            origin: c.extend(0.0),
            x: x.extend(0.0),
            y: y.extend(0.0),
            z: DVec3::Z,
        }
    } else {
        frame(pos)?
    };
    let size = |i, name| -> Res<f64> {
        let r = own.p(i, name)?.f()?;
        if r > 0.0 {
            Ok(r)
        } else {
            Err(bad(&e, format!("{name} must be positive")))
        }
    };
    Ok(match e.name() {
        "CIRCLE" => {
            let r = size(1, "radius")?;
            Curve::Conic { frame, a: r, b: r }
        }
        "ELLIPSE" => Curve::Conic {
            frame,
            a: size(1, "semi_axis_1")?,
            b: size(2, "semi_axis_2")?,
        },
        "PARABOLA" => Curve::Parabola {
            frame,
            f: own.p(1, "focal_dist")?.f()?,
        },
        _ => Curve::Hyperbola {
            frame,
            a: size(1, "semi_axis")?,
            b: size(2, "semi_imag_axis")?,
        },
    })
}

/// POLYLINE as a degree-1 B-spline with knots `0, 0, 1, …, n−2, n−1, n−1`.
fn polyline(e: EntityRef<'_>) -> Res<NurbsCurve> {
    let pts = part(e, "POLYLINE", 1)?.p(0, "points")?.ents()?;
    let points: Vec<DVec3> = pts.into_iter().map(point3).collect::<Res<_>>()?;
    if points.len() < 2 {
        return Err(bad(&e, "a polyline needs at least 2 points"));
    }
    let n = points.len();
    let mut knots = vec![0.0];
    knots.extend((0..n).map(|i| i as f64));
    knots.push((n - 1) as f64);
    Ok(NurbsCurve {
        degree: 1,
        knots,
        weights: vec![1.0; n],
        points,
    })
}

/// TRIMMED_CURVE (§4.4.44): the basis and the range between the trims, by parameter where one
/// is given, else by inverting the trimming point. `sense_agreement = .F.` runs backwards.
fn trimmed(e: EntityRef<'_>, rad: f64, depth: usize) -> Res<Read> {
    let own = part(e, "TRIMMED_CURVE", 1)?;
    let basis = read(own.p(0, "basis_curve")?.ent()?, rad, depth + 1)?;
    let is_conic = matches!(basis.curve, Curve::Conic { .. });
    let scale = if is_conic { rad } else { 1.0 };
    let trim = |i, name| -> Res<f64> {
        let list = own.p(i, name)?;
        let items = list.list().map_err(super::attrs::msg)?;
        let mut point = None;
        for item in items.iter() {
            match item.value() {
                Value::Typed(_, v) => return Ok(v.f()? * scale),
                Value::Real(_) | Value::Int(_) => return Ok(item.f()? * scale),
                Value::Ref(_) => point = Some(point3(item.ent()?)?),
                _ => {}
            }
        }
        let p = point.ok_or_else(|| bad(&e, format!("{name} has no point or parameter")))?;
        Ok(basis.curve.invert(p))
    };
    let (t1, mut t2) = (trim(1, "trim_1")?, trim(2, "trim_2")?);
    let forward = own.p(3, "sense_agreement")?.flag()?;
    if let Some(period) = basis.curve.period() {
        t2 = wrap_after(t1, t2, period, forward);
    }
    Ok(Read {
        curve: basis.curve,
        trim: Some((t1, t2)),
    })
}

/// `t2` moved by whole periods so that `t1 → t2` runs forward (`t2 ∈ (t1, t1 + P]`) or
/// backward (`t2 ∈ [t1 − P, t1)`); equal ends mean the whole period.
#[must_use]
pub(crate) fn wrap_after(t1: f64, t2: f64, period: f64, forward: bool) -> f64 {
    let k = ((t2 - t1) / period).floor();
    let mut t = t2 - k * period; // in [t1, t1 + P)
    let eps = 1e-12 * period.max(t1.abs());
    if forward {
        if t - t1 <= eps {
            t += period;
        }
    } else {
        t -= period;
        if t1 - t <= eps {
            t -= period;
        }
    }
    t
}

impl Curve {
    /// The point at `t`.
    #[must_use]
    pub(crate) fn eval(&self, t: f64) -> DVec3 {
        match self {
            Curve::Line { p, d } => *p + t * *d,
            Curve::Conic { frame, a, b } => frame.to_world(a * t.cos(), b * t.sin(), 0.0),
            Curve::Parabola { frame, f } => frame.to_world(f * t * t, 2.0 * f * t, 0.0),
            Curve::Hyperbola { frame, a, b } => frame.to_world(a * t.cosh(), b * t.sinh(), 0.0),
            Curve::Nurbs(c) => c.fast.point(t).unwrap_or(DVec3::NAN),
        }
    }

    /// The period of a closed parametrisation (conics: 2π).
    #[must_use]
    pub(crate) fn period(&self) -> Option<f64> {
        match self {
            Curve::Conic { .. } => Some(std::f64::consts::TAU),
            _ => None,
        }
    }

    /// The parameter domain (lines and open conics: unbounded).
    #[must_use]
    pub(crate) fn domain(&self) -> (f64, f64) {
        match self {
            Curve::Nurbs(c) => c.domain,
            _ => (f64::NEG_INFINITY, f64::INFINITY),
        }
    }

    /// Distinct interior knots (where a spline may bend sharply), for sampling densities.
    #[must_use]
    pub(crate) fn breaks(&self) -> Vec<f64> {
        match self {
            Curve::Nurbs(c) => {
                let (lo, hi) = self.domain();
                let mut k: Vec<f64> = c
                    .curve
                    .knots
                    .iter()
                    .copied()
                    .filter(|&t| t > lo && t < hi)
                    .collect();
                k.dedup();
                k
            }
            _ => Vec::new(),
        }
    }

    /// The parameter of `p` (a point on the curve, up to the file's tolerance).
    #[must_use]
    pub(crate) fn invert(&self, p: DVec3) -> f64 {
        match self {
            Curve::Line { p: o, d } => (p - *o).dot(*d) / d.length_squared(),
            Curve::Conic { frame, a, b } => {
                let l = frame.to_local(p);
                (l.y / b).atan2(l.x / a)
            }
            Curve::Parabola { frame, f } => frame.to_local(p).y / (2.0 * f),
            Curve::Hyperbola { frame, b, .. } => (frame.to_local(p).y / b).asinh(),
            Curve::Nurbs(_) => {
                let (lo, hi) = self.domain();
                // Vertices sit at the ends of their spline almost always: check those first.
                let (a, b) = (self.eval(lo), self.eval(hi));
                let scale = (a - b).length().max(a.length()).max(1.0);
                if (a - p).length() <= 1e-12 * scale {
                    return lo;
                }
                if (b - p).length() <= 1e-12 * scale {
                    return hi;
                }
                invert_sampled(|t| self.eval(t), lo, hi, &self.breaks(), p)
            }
        }
    }

    /// The exact rational B-spline of the curve over `t0 < t1`, and how its parameter relates
    /// to `t` (identity, or the arc map of a conic); `None` for parabolas and hyperbolas, which
    /// are sampled instead.
    #[must_use]
    pub(crate) fn to_nurbs(&self, t0: f64, t1: f64) -> Option<(NurbsCurve, AxisMap)> {
        match self {
            Curve::Line { p, d } => Some((line_segment(*p, *d, t0, t1).ok()?, AxisMap::Identity)),
            Curve::Conic { frame, a, b } => {
                let (c, map) = ellipse_arc(frame, *a, *b, t0, t1).ok()?;
                Some((c, AxisMap::Arc(map)))
            }
            Curve::Nurbs(c) => {
                let (lo, hi) = self.domain();
                let s = c.curve.segment(t0.max(lo), t1.min(hi)).ok()?;
                Some((s, AxisMap::Identity))
            }
            _ => None,
        }
    }
}

/// The arc map of a whole conic, `[0, 2π]` (used where a conic profile is swept).
#[must_use]
pub(crate) fn full_arc() -> Option<ArcMap> {
    ArcMap::new(0.0, std::f64::consts::TAU).ok()
}

/// Samples per span for the start of a sampled inversion, and the most samples in all.
const INVERT_PER_SPAN: usize = 8;
const INVERT_MAX: usize = 4096;

/// The parameter in `[lo, hi]` nearest to `p`: the best of a sampling with
/// [`INVERT_PER_SPAN`] samples per span between `breaks`, refined by golden-section search on
/// the bracket around it (to ~1e-13 of the bracket).
#[must_use]
pub(crate) fn invert_sampled(
    f: impl Fn(f64) -> DVec3,
    lo: f64,
    hi: f64,
    breaks: &[f64],
    p: DVec3,
) -> f64 {
    let spans = breaks.len() + 1;
    let n = (spans * INVERT_PER_SPAN).clamp(16, INVERT_MAX);
    let at = |i: usize| lo + (hi - lo) * (i as f64 / n as f64);
    let dist = |t: f64| (f(t) - p).length_squared();
    let mut best = (0, f64::INFINITY);
    for i in 0..=n {
        let d = dist(at(i));
        if d < best.1 {
            best = (i, d);
        }
    }
    let (mut a, mut b) = (at(best.0.saturating_sub(1)), at((best.0 + 1).min(n)));
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
    let (mut fc, mut fd) = (dist(c), dist(d));
    for _ in 0..80 {
        if fc < fd {
            (b, d, fd) = (d, c, fc);
            c = b - g * (b - a);
            fc = dist(c);
        } else {
            (a, c, fc) = (c, d, fd);
            d = a + g * (b - a);
            fd = dist(d);
        }
    }
    let t = 0.5 * (a + b);
    // The ends of the domain are exact candidates (a vertex at the start of a spline).
    [lo, t, hi]
        .into_iter()
        .min_by(|x, y| dist(*x).total_cmp(&dist(*y)))
        .unwrap_or(t)
}
