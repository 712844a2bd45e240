//! Boundary curves → curves in the face's NURBS parameter space.
//!
//! * Exact where a closed form exists: parameter-space curves on a 128/114 (the IGES parameters
//!   are the NURBS parameters); model-space curves on a plane (the plane's parameters are an
//!   affine function of the point, so the projected control points give the exact 2D curve);
//!   parameter-space curves on an analytic surface whose IGES map and NURBS map are both affine.
//! * Otherwise a polyline within [`FLATTEN`] × the NURBS domain's diagonal of the exact image,
//!   by adaptive bisection (three probes per piece, at least [`PIECES_PER_SPAN`] pieces per knot
//!   span): through the surface's IGES parameter map for parameter-space curves, through point
//!   inversion for model-space curves (closed form on analytic surfaces, Newton on NURBS).
//!
//! Angles are carried continuously along a loop; a first coarse pass ([`Tracer::coarse`])
//! decides on which side of a periodic surface's seam the loop lies and, for unbounded
//! surfaces (planes, cylinders, cones), how large the parameter box must be.

use crate::geom::analytic::{NurbsCurve, NurbsSurface, ParamBox, ParamMap, SurfaceKind};
use crate::geom::trim::curve::point_segment_distance;
use glam::{DVec2, DVec3};

use super::boundary::{LoopSource, Piece, Source};
use super::curves::Curve;
use super::fail::{Mapped, geometry, skip};
use super::invert::{invert_analytic, invert_surface, nearest_turn};
use super::surfaces::AnalyticSupport;

/// Flattening tolerance, relative to the diagonal of the NURBS parameter domain: ten times below
/// the trim crate's default gap tolerance (1e-6), as it asks.
pub const FLATTEN: f64 = 1e-7;

/// Minimum pieces per knot span before the deviation test, so that a span turning through up
/// to 360° (one Bézier span of a closed 126) is seen in steps of at most 45°.
pub const PIECES_PER_SPAN: usize = 8;

/// Most points one traced curve may have.
const MAX_POINTS: usize = 1 << 18;

/// A curve in the NURBS parameter space.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Traced {
    /// An exact 2D NURBS (z = 0) over `range` (reversed when `range.0 > range.1`).
    Exact {
        curve: NurbsCurve,
        range: (f64, f64),
    },
    /// A polyline.
    Poly(Vec<DVec2>),
}

impl Traced {
    /// First and last point.
    pub fn ends(&self) -> Option<(DVec2, DVec2)> {
        match self {
            Self::Poly(p) => Some((*p.first()?, *p.last()?)),
            Self::Exact { curve, range } => {
                let a = curve.point(range.0).ok()?;
                let b = curve.point(range.1).ok()?;
                Some((a.truncate(), b.truncate()))
            }
        }
    }
}

/// What boundary points are mapped onto.
pub(crate) enum Target<'s> {
    /// A 128/114: inverter space = NURBS space.
    Nurbs {
        surface: &'s NurbsSurface,
        dom: [[f64; 2]; 2],
        scale: f64,
    },
    /// An analytic surface: inverter space = analytic parameters over `range`.
    Analytic {
        support: &'s AnalyticSupport,
        range: ParamBox,
    },
}

pub(crate) struct Tracer<'s> {
    pub target: Target<'s>,
    /// Analytic → NURBS parameters; `None` = identity (NURBS targets, and the coarse pass).
    pub map: Option<ParamMap>,
    /// Flattening tolerance in NURBS parameter units.
    pub tol: f64,
    /// Largest distance of a model-space boundary point from the surface.
    pub max_distance: f64,
}

fn xy(p: DVec3) -> DVec2 {
    p.truncate()
}

/// The curve's parameters to start from: its domain cut at every distinct knot and each span
/// cut into `per_span` pieces, in traversal order.
fn start_params(c: &NurbsCurve, reversed: bool, per_span: usize) -> Mapped<Vec<f64>> {
    let [lo, hi] = geometry(c.domain(), "boundary curve")?;
    let mut knots: Vec<f64> = c
        .knots
        .iter()
        .copied()
        .filter(|&k| k > lo && k < hi)
        .collect();
    knots.dedup();
    let mut ends = vec![lo];
    ends.extend(knots);
    ends.push(hi);
    let mut out = vec![lo];
    for w in ends.windows(2) {
        if let [a, b] = w {
            for k in 1..=per_span {
                out.push(a + (b - a) * k as f64 / per_span as f64);
            }
        }
    }
    if reversed {
        out.reverse();
    }
    Ok(out)
}

fn curve_of(source: &Source) -> &Curve {
    match source {
        Source::Param(c) | Source::Model(c) => c,
    }
}

impl Tracer<'_> {
    /// The point of `source` at `t`: in the inverter's space and in NURBS space.
    fn eval(
        &mut self,
        source: &Source,
        t: f64,
        reference: Option<DVec2>,
    ) -> Mapped<(DVec2, DVec2)> {
        let c = curve_of(source);
        let p = geometry(c.nurbs.point(t), "boundary curve")?;
        let target = match (source, &self.target) {
            (Source::Param(_), Target::Nurbs { .. }) => xy(p),
            (Source::Param(_), Target::Analytic { support, .. }) => {
                support.iges.to_analytic(xy(p)).ok_or_else(|| {
                    skip("a parameter-space boundary on a surface whose parameters are not known")
                })?
            }
            (
                Source::Model(_),
                Target::Nurbs {
                    surface,
                    dom,
                    scale,
                },
            ) => {
                let foot = invert_surface(surface, *dom, p, reference, *scale)?;
                self.max_distance = self.max_distance.max(foot.distance);
                foot.uv
            }
            (Source::Model(_), Target::Analytic { support, range }) => {
                let foot = invert_analytic(support, p, range, reference)?;
                self.max_distance = self.max_distance.max(foot.distance);
                foot.uv
            }
        };
        let fin = match &self.map {
            Some(m) => DVec2::from_array(m.to_nurbs(target.to_array())),
            None => target,
        };
        Ok((target, fin))
    }

    /// Coarse points of a loop in the inverter's space, angles continuous, starting from the
    /// inverter's own choice (angles unwrapped into the entity's range).
    pub fn coarse(&mut self, l: &LoopSource) -> Mapped<Vec<DVec2>> {
        let mut out: Vec<DVec2> = Vec::new();
        for piece in &l.pieces {
            let c = curve_of(&piece.source);
            for t in start_params(&c.nurbs, piece.reversed, 4)? {
                let reference = out.last().copied();
                out.push(self.eval(&piece.source, t, reference)?.0);
            }
        }
        Ok(out)
    }

    /// The loop's pieces in NURBS space, starting the angle continuity at `start`.
    pub fn trace(&mut self, l: &LoopSource, start: Option<DVec2>) -> Mapped<Vec<Traced>> {
        let mut reference = start;
        let mut out = Vec::with_capacity(l.pieces.len());
        for piece in &l.pieces {
            if let Some(exact) = self.exact(piece)? {
                if matches!(self.target, Target::Analytic { .. }) {
                    let c = curve_of(&piece.source);
                    let [lo, hi] = geometry(c.nurbs.domain(), "boundary curve")?;
                    let t_end = if piece.reversed { lo } else { hi };
                    reference = Some(self.eval(&piece.source, t_end, reference)?.0);
                }
                out.push(exact);
                continue;
            }
            let (points, last) = self.adaptive(piece, reference)?;
            reference = Some(last);
            out.push(Traced::Poly(points));
        }
        Ok(out)
    }

    /// The closed-form image of a piece, where there is one.
    fn exact(&self, piece: &Piece) -> Mapped<Option<Traced>> {
        let c = curve_of(&piece.source);
        let map_affine = self.map.as_ref().is_none_or(is_identity);
        let mapped: Option<Vec<DVec3>> = match (&piece.source, &self.target) {
            (Source::Param(_), Target::Nurbs { .. }) => Some(c.nurbs.points.clone()),
            (Source::Param(_), Target::Analytic { support, .. })
                if map_affine && support.iges.is_affine() =>
            {
                c.nurbs
                    .points
                    .iter()
                    .map(|p| support.iges.to_analytic(xy(*p)).map(|q| q.extend(0.0)))
                    .collect()
            }
            (Source::Model(_), Target::Analytic { support, .. })
                if map_affine && matches!(support.surf.kind(), SurfaceKind::Plane) =>
            {
                let f = support.surf.frame();
                let size = f.to_local(DVec3::ZERO).length().max(1.0);
                let local: Vec<DVec3> = c.nurbs.points.iter().map(|&p| f.to_local(p)).collect();
                let off = local.iter().fold(0.0_f64, |m, q| m.max(q.z.abs()));
                (off <= 1e-6 * size.max(extent(&c.nurbs.points)))
                    .then(|| local.iter().map(|q| DVec3::new(q.x, q.y, 0.0)).collect())
            }
            _ => None,
        };
        let Some(points) = mapped else {
            return Ok(None);
        };
        let curve = NurbsCurve {
            degree: c.nurbs.degree,
            knots: c.nurbs.knots.clone(),
            points: points.iter().map(|p| DVec3::new(p.x, p.y, 0.0)).collect(),
            weights: c.nurbs.weights.clone(),
        };
        let [lo, hi] = geometry(curve.domain(), "boundary curve")?;
        let range = if piece.reversed { (hi, lo) } else { (lo, hi) };
        Ok(Some(Traced::Exact { curve, range }))
    }

    /// Adaptive bisection of one piece in NURBS space; returns the polyline and the inverter-space
    /// point of its end (the next piece's continuity reference).
    fn adaptive(&mut self, piece: &Piece, reference: Option<DVec2>) -> Mapped<(Vec<DVec2>, DVec2)> {
        let c = curve_of(&piece.source);
        let ts = start_params(&c.nurbs, piece.reversed, PIECES_PER_SPAN)?;
        let first = *ts.first().ok_or_else(|| skip("empty boundary curve"))?;
        let (mut ta, (mut ga, mut fa)) = (first, self.eval(&piece.source, first, reference)?);
        let mut out = vec![fa];
        for &tb in ts.iter().skip(1) {
            let end = self.eval(&piece.source, tb, Some(ga))?;
            let mut stack = vec![(tb, end)];
            while let Some(&(tb, (gb, fb))) = stack.last() {
                let tm = 0.5 * (ta + tb);
                let (gm, fm) = self.eval(&piece.source, tm, Some(ga))?;
                let mut deviates = point_segment_distance(fm, fa, fb) > self.tol;
                for f in [0.25, 0.75] {
                    let probe = self.eval(&piece.source, ta + (tb - ta) * f, Some(ga))?.1;
                    deviates |= point_segment_distance(probe, fa, fb) > self.tol;
                }
                if deviates && tm != ta && tm != tb {
                    stack.push((tm, (gm, fm)));
                    continue;
                }
                out.push(fb);
                if out.len() > MAX_POINTS {
                    return Err(skip(format!(
                        "a boundary curve needs more than {MAX_POINTS} points to follow within {:e}",
                        self.tol
                    )));
                }
                (ta, ga, fa) = (tb, gb, fb);
                stack.pop();
            }
        }
        Ok((out, ga))
    }
}

/// Whether both axes of the map are identities (planes, extrusion's linear directions).
fn is_identity(m: &ParamMap) -> bool {
    matches!(
        (&m.u, &m.v),
        (
            crate::geom::analytic::AxisMap::Identity,
            crate::geom::analytic::AxisMap::Identity
        )
    )
}

fn extent(points: &[DVec3]) -> f64 {
    let lo = points.iter().fold(DVec3::INFINITY, |a, &b| a.min(b));
    let hi = points.iter().fold(DVec3::NEG_INFINITY, |a, &b| a.max(b));
    (hi - lo).length()
}

/// Where a loop's coarse points sit against the fixed range of each angular parameter: the
/// whole-turn shift that puts them inside, or why none does.
pub(crate) fn seam_shift(points: &[DVec2], support: &AnalyticSupport) -> Mapped<DVec2> {
    let angular = support.surf.angular();
    let mut shift = DVec2::ZERO;
    for axis in 0..2 {
        let (Some(true), Some(Some([lo, hi]))) = (angular.get(axis), support.fixed.get(axis))
        else {
            continue;
        };
        let values = points.iter().map(|p| if axis == 0 { p.x } else { p.y });
        let (min, max) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
        let tol = 1e-6 * (hi - lo);
        let (first, last) = match (points.first(), points.last()) {
            (Some(f), Some(l)) => (f, l),
            _ => continue,
        };
        let gap = if axis == 0 {
            last.x - first.x
        } else {
            last.y - first.y
        };
        if gap.abs() > std::f64::consts::PI {
            return Err(skip(
                "a trim loop winds around a periodic surface without a seam edge",
            ));
        }
        let centre = 0.5 * (min + max);
        let s = nearest_turn(centre, 0.5 * (lo + hi)) - centre;
        if min + s < lo - tol || max + s > hi + tol {
            return Err(skip(format!(
                "a trim loop spans angles [{:.6}, {:.6}], which do not fit the surface's [{lo:.6}, {hi:.6}]",
                min + s,
                max + s
            )));
        }
        if axis == 0 {
            shift.x = s;
        } else {
            shift.y = s;
        }
    }
    Ok(shift)
}
