//! Face surfaces (ISO 10303-42 §4.4.49 ff.): elementary, swept, B-spline, rectangular-trimmed
//! and offset surfaces, read into one type that evaluates, inverts points and becomes its exact
//! rational B-spline form over a parameter box.
//!
//! Parameters. The analytic crate parametrises every kind as ISO 10303-42 does, with angles in
//! radians, so a file's `(u, v)` (a PCURVE's coordinates) reaches the crate's through [`Pre`]:
//! the angle unit's factor, and for a swept conic (a SURFACE_OF_REVOLUTION of a CIRCLE) the
//! conic's arc map, since the crate sweeps a NURBS profile whose parameter is not the angle.
//! Everything below works in the crate's parameters.
//!
//! OFFSET_SURFACE of an elementary surface is again elementary and is drawn exactly: a plane
//! moves along its normal, a cylinder's or sphere's radius and a torus's minor radius grow by
//! the distance, a cone of semi-angle α gets radius `R + d cos α` and origin `C − d sin α Z`
//! (same `(u, v)` in each case, so its PCURVEs still apply). Offsets of other surfaces have no
//! exact NURBS form and are reported as not drawn.

use crate::formats::step::EntityRef;
use crate::geom::analytic::{
    AnalyticSurface, ArcMap, Frame, NurbsCurve, SurfaceKind, line_segment,
};
use glam::{DVec2, DVec3};

use super::attrs::{P, Res, axis1, bad, frame, is, part, unsupported, vector};
use super::curves::{self, Curve, full_arc};
use super::nurbs::{FastSurface, read_bspline_surface};

/// How one file parameter becomes the crate's.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Pre {
    Identity,
    /// An angle in the file's unit: times the factor.
    Scale(f64),
    /// An angle (times the factor) through a whole conic's arc map, continued periodically.
    Arc(f64, ArcMap),
}

impl Pre {
    /// File parameter → crate parameter.
    #[must_use]
    pub(crate) fn apply(&self, x: f64) -> f64 {
        match self {
            Pre::Identity => x,
            Pre::Scale(f) => x * f,
            Pre::Arc(f, map) => {
                let tau = std::f64::consts::TAU;
                let a = x * f;
                let k = (a / tau).floor();
                k * tau + map.angle_to_param(a - k * tau)
            }
        }
    }
}

/// The geometry behind a face.
#[derive(Clone, Debug)]
pub(crate) enum Geometry {
    Analytic(AnalyticSurface),
    Nurbs(NurbsSurface2),
}

/// A B-spline surface with its fast evaluator.
#[derive(Clone, Debug)]
pub(crate) struct NurbsSurface2 {
    pub surface: crate::geom::analytic::NurbsSurface,
    pub fast: FastSurface,
    /// The control net's diagonal, a scale for tolerances.
    pub size: f64,
    /// Sample points `(uv, S(uv))` for the start of a global inversion, made when first needed.
    pub grid: std::cell::OnceCell<Vec<(DVec2, DVec3)>>,
}

/// A face's surface, ready for trimming.
#[derive(Clone, Debug)]
pub(crate) struct Surface {
    /// The entities a PCURVE's `basis_surface` may name for this surface (the face's, and the
    /// basis of a rectangular-trimmed one).
    pub ids: Vec<u64>,
    /// The face geometry's entity type, as in the file.
    pub type_name: String,
    pub geom: Geometry,
    /// File → crate parameters per direction.
    pub pre: [Pre; 2],
    /// The surface's normal is opposite to the crate parametrisation's `S_u × S_v` (a
    /// RECTANGULAR_TRIMMED_SURFACE with one sense reversed).
    pub flip: bool,
    /// RECTANGULAR_TRIMMED_SURFACE limits, in crate parameters.
    pub limits: Option<[[f64; 2]; 2]>,
    /// Periods of the crate parameters (angles: 2π; a closed profile or B-spline direction:
    /// its domain's length).
    pub periods: [Option<f64>; 2],
    /// The crate-parameter range a face may use at most, per direction (`None`: unbounded). A
    /// closed swept profile is stored twice over, so its range is two periods: any window of
    /// one period starting in the first fits.
    pub natural: [Option<[f64; 2]>; 2],
}

/// How deeply surfaces may refer to surfaces (trimmed of offset of …).
const MAX_NESTING: usize = 8;

/// Reads the surface `e`. `rad` converts angles; `extent` is the box `(lo, hi)` of the face's
/// edges, used to bound a swept infinite LINE.
pub(crate) fn read(e: EntityRef<'_>, rad: f64, extent: (DVec3, DVec3)) -> Res<Surface> {
    let mut s = read_inner(e, rad, extent, 0)?;
    s.type_name = e.name().to_owned();
    if is(&e, "B_SPLINE_SURFACE") && e.is_complex() {
        s.type_name = if is(&e, "B_SPLINE_SURFACE_WITH_KNOTS") {
            "B_SPLINE_SURFACE_WITH_KNOTS".into()
        } else {
            "B_SPLINE_SURFACE".into()
        };
    }
    Ok(s)
}

fn read_inner(e: EntityRef<'_>, rad: f64, extent: (DVec3, DVec3), depth: usize) -> Res<Surface> {
    if depth > MAX_NESTING {
        return Err(bad(&e, "surfaces nested too deeply"));
    }
    let analytic =
        |a: crate::geom::analytic::Result<AnalyticSurface>, pre: [Pre; 2]| -> Res<Surface> {
            let a = a.map_err(|x| bad(&e, x.to_string()))?;
            Ok(plain(e.id(), Geometry::Analytic(a), pre))
        };
    let angular = [Pre::Scale(rad), Pre::Identity];
    let both = [Pre::Scale(rad), Pre::Scale(rad)];
    if is(&e, "B_SPLINE_SURFACE") {
        let surface = read_bspline_surface(e)?;
        let fast = FastSurface::new(&surface);
        let size = surface.extent().max(f64::MIN_POSITIVE);
        let g = Geometry::Nurbs(NurbsSurface2 {
            surface,
            fast,
            size,
            grid: std::cell::OnceCell::new(),
        });
        return Ok(plain(e.id(), g, [Pre::Identity, Pre::Identity]));
    }
    let own = part(e, e.name(), 1)?;
    let pos = || -> Res<Frame> { frame(own.p(0, "position")?.ent()?) };
    let len = |i, name| own.p(i, name).and_then(|p| p.f());
    match e.name() {
        "PLANE" => analytic(
            AnalyticSurface::plane(pos()?),
            [Pre::Identity, Pre::Identity],
        ),
        "CYLINDRICAL_SURFACE" => analytic(
            AnalyticSurface::cylinder(pos()?, len(1, "radius")?),
            angular,
        ),
        "CONICAL_SURFACE" => {
            let a = len(2, "semi_angle")? * rad;
            analytic(AnalyticSurface::cone(pos()?, len(1, "radius")?, a), angular)
        }
        "SPHERICAL_SURFACE" => analytic(AnalyticSurface::sphere(pos()?, len(1, "radius")?), both),
        "TOROIDAL_SURFACE" | "DEGENERATE_TOROIDAL_SURFACE" => {
            let (r1, r2) = (len(1, "major_radius")?, len(2, "minor_radius")?);
            analytic(AnalyticSurface::torus(pos()?, r1, r2), both)
        }
        "SURFACE_OF_REVOLUTION" => {
            let (profile, pre) = profile(own.p(0, "swept_curve")?.ent()?, rad, extent)?;
            let (a, d) = axis1(own.p(1, "axis_position")?.ent()?)?;
            analytic(
                AnalyticSurface::revolution(profile, a, d),
                [Pre::Scale(rad), pre],
            )
        }
        "SURFACE_OF_LINEAR_EXTRUSION" => {
            let (profile, pre) = profile(own.p(0, "swept_curve")?.ent()?, rad, extent)?;
            let v = vector(own.p(1, "extrusion_axis")?.ent()?)?;
            analytic(AnalyticSurface::extrusion(profile, v), [pre, Pre::Identity])
        }
        "RECTANGULAR_TRIMMED_SURFACE" => rectangular(e, rad, extent, depth),
        "OFFSET_SURFACE" => offset(e, rad, extent, depth),
        // A surface of another type is valid STEP not drawn yet; anything else is a reference
        // to the wrong kind of entity.
        name if name.contains("SURFACE") => {
            Err(unsupported(&e, "this surface type is not drawn yet"))
        }
        _ => Err(bad(&e, "should be a surface")),
    }
}

/// A surface with no limits and no flip.
#[must_use]
fn plain(id: u64, geom: Geometry, pre: [Pre; 2]) -> Surface {
    let (periods, natural) = shape(&geom);
    Surface {
        ids: vec![id],
        type_name: String::new(),
        geom,
        pre,
        flip: false,
        limits: None,
        periods,
        natural,
    }
}

/// Periods and natural ranges of a surface's crate parameters (see [`Surface::periods`]).
#[must_use]
fn shape(geom: &Geometry) -> ([Option<f64>; 2], [Option<[f64; 2]>; 2]) {
    let tau = Some(std::f64::consts::TAU);
    let half = std::f64::consts::FRAC_PI_2;
    match geom {
        Geometry::Analytic(a) => match a.kind() {
            SurfaceKind::Plane => ([None, None], [None, None]),
            SurfaceKind::Cylinder { .. } | SurfaceKind::Cone { .. } => ([tau, None], [None, None]),
            SurfaceKind::Sphere { .. } => ([tau, None], [None, Some([-half, half])]),
            SurfaceKind::Torus { .. } => ([tau, tau], [None, None]),
            SurfaceKind::Revolution { profile, .. } => (
                [tau, doubled_period(profile)],
                [None, profile.domain().ok()],
            ),
            SurfaceKind::Extrusion { profile, .. } => (
                [doubled_period(profile), None],
                [profile.domain().ok(), None],
            ),
        },
        Geometry::Nurbs(n) => {
            let [u, v] = n.fast.domain();
            (super::invert::nurbs_periods(&n.fast), [Some(u), Some(v)])
        }
    }
}

/// Half the domain of a profile that [`profile`] stored twice (closed), else `None`.
#[must_use]
fn doubled_period(c: &NurbsCurve) -> Option<f64> {
    let [lo, hi] = c.domain().ok()?;
    let mid = 0.5 * (lo + hi);
    let half = c.segment(lo, mid).ok()?;
    (closed_curve(&half).is_some() && closed_curve(c).is_some() && c.knots.contains(&mid))
        .then_some(mid - lo)
}

/// The swept curve of a SURFACE_OF_REVOLUTION / _LINEAR_EXTRUSION as a NURBS profile, and how
/// the file's curve parameter becomes the profile's: a conic is swept whole over `[0, 2π]`
/// (the face's range cuts it), an infinite LINE over its TRIMMED_CURVE range or else over the
/// part of it near the face's edges.
fn profile(c: EntityRef<'_>, rad: f64, extent: (DVec3, DVec3)) -> Res<(NurbsCurve, Pre)> {
    let (curve, pre) = open_profile(c, rad, extent)?;
    match closed_curve(&curve) {
        Some(_) => Ok((
            twice(&curve).ok_or_else(|| bad(&c, "swept curve: bad closed profile"))?,
            pre,
        )),
        None => Ok((curve, pre)),
    }
}

/// A closed clamped curve followed by itself one period on: knots `[a…, inner, b×p, inner +
/// L, (b + L)…]`, points shared at the joint.
#[must_use]
pub(crate) fn twice(c: &NurbsCurve) -> Option<NurbsCurve> {
    let p = c.degree;
    let [lo, hi] = c.domain().ok()?;
    let len = hi - lo;
    let n = c.points.len();
    let mut knots: Vec<f64> = c.knots.get(..n)?.to_vec();
    knots.extend(c.knots.get(1..)?.iter().map(|k| k + len));
    let mut points = c.points.clone();
    points.extend(c.points.get(1..)?.iter().copied());
    let mut weights = c.weights.clone();
    // The copy's first point is the original's last: its weights scale to match it.
    let scale = c.weights.last().copied()? / c.weights.first().copied()?;
    weights.extend(c.weights.get(1..)?.iter().map(|w| w * scale));
    let d = NurbsCurve {
        degree: p,
        knots,
        points,
        weights,
    };
    d.validate().ok()?;
    Some(d)
}

/// The swept curve as read (see [`profile`]).
fn open_profile(c: EntityRef<'_>, rad: f64, extent: (DVec3, DVec3)) -> Res<(NurbsCurve, Pre)> {
    let read = curves::read(c, rad, 0)?;
    let fail = |what: &str| bad(&c, format!("swept curve: {what}"));
    match &read.curve {
        Curve::Nurbs(n) => {
            let curve = match read.trim {
                Some((a, b)) => n
                    .curve
                    .segment(a.min(b), a.max(b))
                    .map_err(|x| fail(&x.to_string()))?,
                None => n.curve.clone(),
            };
            Ok((curve, Pre::Identity))
        }
        Curve::Conic { .. } => {
            let map = full_arc().ok_or_else(|| fail("bad arc"))?;
            let (n, _) = read
                .curve
                .to_nurbs(0.0, std::f64::consts::TAU)
                .ok_or_else(|| fail("bad conic"))?;
            Ok((n, Pre::Arc(rad, map)))
        }
        Curve::Line { p, d } => {
            let (t0, t1) = match read.trim {
                Some((a, b)) => (a.min(b), a.max(b)),
                None => line_range(*p, *d, extent),
            };
            let n = line_segment(*p, *d, t0, t1).map_err(|x| fail(&x.to_string()))?;
            Ok((n, Pre::Identity))
        }
        _ => Err(unsupported(
            &c,
            "swept parabolas and hyperbolas are not drawn yet",
        )),
    }
}

/// The parameters of the line `p + t d` within twice the extent's diagonal of its centre
/// (every point of a face swept from it lies nearer than that to the face's edges).
#[must_use]
fn line_range(p: DVec3, d: DVec3, (lo, hi): (DVec3, DVec3)) -> (f64, f64) {
    let c = 0.5 * (lo + hi);
    let r = (hi - lo).length().max(1e-9 * (c.length() + 1.0)) * 2.0;
    let t = (c - p).dot(d) / d.length_squared();
    let dt = r / d.length();
    (t - dt, t + dt)
}

/// RECTANGULAR_TRIMMED_SURFACE (§4.4.61): the basis with limits; one reversed sense flips the
/// normal.
fn rectangular(e: EntityRef<'_>, rad: f64, extent: (DVec3, DVec3), depth: usize) -> Res<Surface> {
    let own = part(e, "RECTANGULAR_TRIMMED_SURFACE", 1)?;
    let basis_e = own.p(0, "basis_surface")?.ent()?;
    let mut s = read_inner(basis_e, rad, extent, depth + 1)?;
    let lim = |i, name| own.p(i, name).and_then(|p| p.f());
    let (u1, u2, v1, v2) = (lim(1, "u1")?, lim(2, "u2")?, lim(3, "v1")?, lim(4, "v2")?);
    let usense = own.p(5, "usense")?.flag()?;
    let vsense = own.p(6, "vsense")?.flag()?;
    let (pu, pv) = (&s.pre[0], &s.pre[1]);
    let (a, b) = (pu.apply(u1), pu.apply(u2));
    let (c, d) = (pv.apply(v1), pv.apply(v2));
    s.limits = Some([[a.min(b), a.max(b)], [c.min(d), c.max(d)]]);
    s.flip ^= usense != vsense;
    s.ids.push(e.id());
    Ok(s)
}

/// OFFSET_SURFACE (§4.4.62): exact for elementary bases (see the module doc).
fn offset(e: EntityRef<'_>, rad: f64, extent: (DVec3, DVec3), depth: usize) -> Res<Surface> {
    let own = part(e, "OFFSET_SURFACE", 1)?;
    let basis_e = own.p(0, "basis_surface")?.ent()?;
    let d = own.p(1, "distance")?.f()?;
    let mut s = read_inner(basis_e, rad, extent, depth + 1)?;
    let not_drawn = || unsupported(&e, "offset surfaces are not drawn yet");
    let Geometry::Analytic(a) = &s.geom else {
        return Err(not_drawn());
    };
    let f = *a.frame();
    let shifted = |by: DVec3| Frame {
        origin: f.origin + by,
        ..f
    };
    let made = match *a.kind() {
        SurfaceKind::Plane => AnalyticSurface::plane(shifted(d * f.z)),
        SurfaceKind::Cylinder { radius } => AnalyticSurface::cylinder(f, radius + d),
        SurfaceKind::Sphere { radius } => AnalyticSurface::sphere(f, radius + d),
        SurfaceKind::Torus { major, minor } => AnalyticSurface::torus(f, major, minor + d),
        SurfaceKind::Cone { radius, semi_angle } => {
            let (sin, cos) = semi_angle.sin_cos();
            AnalyticSurface::cone(shifted(-d * sin * f.z), radius + d * cos, semi_angle)
        }
        _ => return Err(not_drawn()),
    };
    s.geom = Geometry::Analytic(made.map_err(|_| not_drawn())?);
    s.ids.push(e.id());
    Ok(s)
}

/// A point inverted onto a surface, in crate parameters.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Inv {
    pub uv: DVec2,
    /// Per parameter: the point is on a singular line where this parameter is arbitrary (a
    /// sphere's pole, a cone's apex: `u`).
    pub free: [bool; 2],
    pub distance: f64,
}

impl Surface {
    /// The point at crate parameters `uv`.
    #[must_use]
    pub(crate) fn point(&self, uv: DVec2) -> Option<DVec3> {
        match &self.geom {
            Geometry::Analytic(a) => a.point(uv.x, uv.y).ok(),
            Geometry::Nurbs(n) => n.fast.point(uv.x, uv.y),
        }
    }

    /// The point at a file's parameters (a PCURVE's coordinates).
    #[must_use]
    pub(crate) fn file_point(&self, uv_file: DVec2) -> Option<DVec3> {
        self.point(DVec2::new(
            self.pre[0].apply(uv_file.x),
            self.pre[1].apply(uv_file.y),
        ))
    }
}

/// A profile whose ends meet (to 1e-10 of its size) is closed; its period is its domain.
#[must_use]
fn closed_curve(c: &NurbsCurve) -> Option<f64> {
    let [lo, hi] = c.domain().ok()?;
    let (a, b) = (c.point(lo).ok()?, c.point(hi).ok()?);
    let size = c.points.iter().fold(0.0f64, |m, p| {
        m.max((*p - c.points.first().copied().unwrap_or(*p)).length())
    });
    ((a - b).length() <= 1e-10 * size.max(f64::MIN_POSITIVE)).then_some(hi - lo)
}
