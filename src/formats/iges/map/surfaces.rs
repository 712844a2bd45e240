//! IGES surfaces and what the trims need to know about them: rational B-spline surfaces (128)
//! and parametric spline surfaces (114) are their own NURBS; planes (108, 190), surfaces of
//! revolution (120), tabulated cylinders (122) and the B-rep surfaces 192–198 become the analytic
//! crate's [`AnalyticSurface`], whose exact NURBS form is built once the parameter box is known
//! (from the entity where it has one, from the trim loops where it is unbounded).
//!
//! Every IGES parametrisation is recorded as an [`IgesMap`] to the analytic parameters, so that
//! parameter-space trim curves (142 BPTR, 141 and 508 parameter curves) land where the file
//! means them.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use crate::formats::iges::{Entity, Transform};
use crate::geom::analytic::{AnalyticSurface, Frame, NurbsSurface};
use glam::{DVec2, DVec3};

use super::curves::{Curve, CurveParam, place_curve, power_to_bezier};
use super::fail::{Mapped, geometry, malformed, skip};
use super::reader::{CURVES, Reader};

/// IGES parameters → analytic parameters of the surface (IGES 5.3, each entity's
/// parametrisation; the B-rep surfaces 192–198 measure angles in degrees).
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum IgesMap {
    /// No parameter space is defined (108 planes, 190 form 0): model-space curves only.
    Undefined,
    /// The IGES parameters are the analytic ones (190 form 1: `LOC + u REFDIR + v (N × REFDIR)`).
    Identity,
    /// Entity 120: `(t, θ)` with `t` the generatrix parameter → analytic `(θ, g(t))`.
    Revolution(Curve),
    /// Entity 122: `(u, v) ∈ [0, 1]²`, `u` the normalised directrix parameter → `(g(t), v)`.
    Tabulated(Curve),
    /// Scales per parameter (192: degrees and length; 196: degrees and degrees).
    Scaled([f64; 2]),
    /// Entity 194: `u` in degrees, `v` along the generator; the analytic `v` is the height.
    Cone { cos: f64 },
    /// Entity 198: `(a, b)` in degrees → analytic `(2π − b, a)` (major angle, minor angle), as
    /// OpenCASCADE reads it.
    Torus,
}

impl IgesMap {
    /// The analytic parameters of IGES parameters `p`; `None` where undefined.
    #[must_use]
    pub fn to_analytic(&self, p: DVec2) -> Option<DVec2> {
        let deg = PI / 180.0;
        Some(match self {
            Self::Undefined => return None,
            Self::Identity => p,
            Self::Revolution(g) => DVec2::new(p.y, g.to_nurbs(p.x)?),
            Self::Tabulated(g) => {
                let t = g.range[0] + p.x * (g.range[1] - g.range[0]);
                DVec2::new(g.to_nurbs(t)?, p.y)
            }
            Self::Scaled([su, sv]) => DVec2::new(p.x * su, p.y * sv),
            Self::Cone { cos } => DVec2::new(p.x * deg, p.y * cos),
            Self::Torus => DVec2::new(TAU - p.y * deg, p.x * deg),
        })
    }

    /// Whether `to_analytic` is affine, so mapped control points give the exact curve.
    #[must_use]
    pub fn is_affine(&self) -> bool {
        match self {
            Self::Undefined | Self::Revolution(_) | Self::Tabulated(_) => false,
            Self::Identity | Self::Scaled(_) | Self::Cone { .. } | Self::Torus => true,
        }
    }
}

/// What a face is drawn on.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Support {
    /// 128, 114: the IGES parameters are the NURBS parameters.
    Nurbs(NurbsSurface),
    /// An analytic surface whose NURBS form waits for its parameter box.
    Analytic(Box<AnalyticSupport>),
}

#[derive(Debug, Clone, PartialEq)]
pub(crate) struct AnalyticSupport {
    pub surf: AnalyticSurface,
    pub iges: IgesMap,
    /// Analytic parameter ranges the entity fixes; `None` = unbounded, taken from the trims.
    pub fixed: [Option<[f64; 2]>; 2],
}

/// A surface read for a face: the support and the file's name of its type.
pub(crate) struct ReadSurface {
    pub support: Support,
    pub entity_type: i32,
}

fn dvec(t: &Transform, p: DVec3) -> DVec3 {
    DVec3::from_array(t.apply_point(p.to_array()))
}

fn dir(t: &Transform, v: DVec3) -> DVec3 {
    DVec3::from_array(t.apply_vector(v.to_array()))
}

/// The determinant of the linear part: a mirror (< 0) reverses angles about transformed axes.
#[must_use]
pub(crate) fn det(t: &Transform) -> f64 {
    let [a, b, c] = t.matrix;
    let col = |k: usize| {
        DVec3::new(
            a.get(k).copied().unwrap_or_default(),
            b.get(k).copied().unwrap_or_default(),
            c.get(k).copied().unwrap_or_default(),
        )
    };
    col(0).dot(col(1).cross(col(2)))
}

/// A frame placed by `t`: origin and axes mapped, then re-orthonormalised (IGES 124s are
/// rotations, possibly times the uniform unit scale). Under a mirror the frame stays
/// right-handed, so the surface is the same point set but its parameters run differently: the
/// caller then trusts model-space trims only.
fn placed_frame(t: &Transform, origin: DVec3, z: DVec3, x: Option<DVec3>) -> Mapped<Frame> {
    let z = dir(t, z);
    let x = x.map(|x| dir(t, x));
    geometry(
        Frame::from_axis2_placement(dvec(t, origin), Some(z), x),
        "surface placement",
    )
}

impl Reader<'_> {
    /// The surface `e`, placed by its own transformation and then `outer`.
    pub fn surface(&mut self, e: &Entity, outer: &Transform) -> Mapped<ReadSurface> {
        self.mark(e);
        let place = self.placement(e, outer)?;
        let support = match e.entity_type() {
            128 => Support::Nurbs(bspline_surface(e, &place)?),
            114 => Support::Nurbs(spline_surface(e, &place)?),
            108 => self.plane(e, &place)?,
            120 => self.revolution(e, &place)?,
            122 => self.tabulated(e, &place)?,
            190..=198 => self.brep_surface(e, &place)?,
            140 => return Err(skip("offset surface (entity 140) has no exact NURBS form")),
            118 => return Err(skip("ruled surface (entity 118) is not supported")),
            t => {
                return Err(malformed(
                    e,
                    format!("is used as a surface, but entity {t} is not one"),
                ));
            }
        };
        Ok(ReadSurface {
            support,
            entity_type: e.entity_type(),
        })
    }

    /// Entity 108: `A x + B y + C z = D`; parametrised here by a frame on the plane (IGES gives
    /// it no parameter space), extent from the trims.
    fn plane(&mut self, e: &Entity, place: &Transform) -> Mapped<Support> {
        let n = DVec3::new(e.real(1)?, e.real(2)?, e.real(3)?);
        let d = e.real(4)?;
        let len2 = n.length_squared();
        if !(len2.is_finite() && len2 > 0.0 && d.is_finite()) {
            return Err(malformed(e, "has no valid plane equation"));
        }
        let frame = placed_frame(place, n * (d / len2), n, None)?;
        Ok(Support::Analytic(Box::new(AnalyticSupport {
            surf: geometry(AnalyticSurface::plane(frame), "plane")?,
            iges: IgesMap::Undefined,
            fixed: [None, None],
        })))
    }

    /// Entity 120: the generatrix rotated about the axis line from `SA` to `TA`,
    /// counter-clockwise about the direction from the line's start to its end.
    fn revolution(&mut self, e: &Entity, place: &Transform) -> Mapped<Support> {
        let axis = self.follow_kind(e, 1, &[110], "a line (110)")?;
        let axis = single(self.curve(axis, place, 1)?, e, "axis")?;
        let generatrix = self.follow_kind(e, 2, &CURVES, "a curve")?;
        let profile = single(self.curve(generatrix, place, 1)?, e, "generatrix")?;
        let (sa, ta) = (e.real(3)?, e.real(4)?);
        if !(sa.is_finite() && ta.is_finite() && ta > sa && ta - sa <= TAU * (1.0 + 1e-9)) {
            return Err(malformed(e, format!("has the angle range [{sa}, {ta}]")));
        }
        let (a, b) = match axis.nurbs.points.as_slice() {
            [a, b] => (*a, *b),
            _ => return Err(malformed(e, "has a degenerate axis")),
        };
        let sign = if det(place) < 0.0 { -1.0 } else { 1.0 };
        let surf = geometry(
            AnalyticSurface::revolution(profile.nurbs.clone(), a, (b - a) * sign),
            "surface of revolution",
        )?;
        let v = geometry(profile.nurbs.domain(), "generatrix")?;
        Ok(Support::Analytic(Box::new(AnalyticSupport {
            surf,
            iges: IgesMap::Revolution(profile),
            fixed: [Some([sa, ta.min(sa + TAU)]), Some(v)],
        })))
    }

    /// Entity 122: the directrix swept along `L − C(start)`, `(u, v) ∈ [0, 1]²`.
    fn tabulated(&mut self, e: &Entity, place: &Transform) -> Mapped<Support> {
        let child = self.follow_kind(e, 1, &CURVES, "a curve")?;
        let raw = self.curve(child, &Transform::IDENTITY, 1)?;
        let mut directrix = single(raw, e, "directrix")?;
        let end = DVec3::new(e.real(2)?, e.real(3)?, e.real(4)?);
        let start = geometry(
            directrix.nurbs.point(directrix_start(&directrix)),
            "directrix",
        )?;
        let vector = dir(place, end - start);
        place_curve(&mut directrix.nurbs, place);
        let surf = geometry(
            AnalyticSurface::extrusion(directrix.nurbs.clone(), vector),
            "tabulated cylinder",
        )?;
        let u = geometry(directrix.nurbs.domain(), "directrix")?;
        Ok(Support::Analytic(Box::new(AnalyticSupport {
            surf,
            iges: IgesMap::Tabulated(directrix),
            fixed: [Some(u), Some([0.0, 1.0])],
        })))
    }

    /// Entities 190–198 (IGES 5.3 B-rep surfaces): location (116), axis and reference
    /// direction (123), sizes; form 1 is parametrised, form 0 has model-space trims only.
    fn brep_surface(&mut self, e: &Entity, place: &Transform) -> Mapped<Support> {
        let t = e.entity_type();
        let loc = self.point116(e, 1)?;
        let parametrised = e.form() == 1;
        let (surf, iges, fixed) = match t {
            190 => {
                let z = self.direction(e, 2)?;
                let x = self.optional_direction(e, 3, parametrised)?;
                let frame = placed_frame(place, loc, z, x)?;
                let map = if x.is_some() {
                    IgesMap::Identity
                } else {
                    IgesMap::Undefined
                };
                (AnalyticSurface::plane(frame), map, [None, None])
            }
            192 | 194 => {
                let z = self.direction(e, 2)?;
                let radius = e.real(3)? * place_scale(place);
                let (alpha, ref_k) = if t == 194 {
                    (e.real(4)?.to_radians(), 5)
                } else {
                    (0.0, 4)
                };
                let x = self.optional_direction(e, ref_k, parametrised)?;
                let frame = placed_frame(place, loc, z, x)?;
                if t == 192 {
                    let map = IgesMap::Scaled([PI / 180.0, 1.0]);
                    (AnalyticSurface::cylinder(frame, radius), map, [None, None])
                } else {
                    let map = IgesMap::Cone { cos: alpha.cos() };
                    (
                        AnalyticSurface::cone(frame, radius, alpha),
                        map,
                        [None, None],
                    )
                }
            }
            196 => {
                let radius = e.real(2)? * place_scale(place);
                let z = self
                    .optional_direction(e, 3, parametrised)?
                    .unwrap_or(DVec3::Z);
                let x = self.optional_direction(e, 4, parametrised)?;
                let frame = placed_frame(place, loc, z, x)?;
                let deg = PI / 180.0;
                let full = [Some([0.0, TAU]), Some([-FRAC_PI_2, FRAC_PI_2])];
                let s = AnalyticSurface::sphere(frame, radius);
                (s, IgesMap::Scaled([deg, deg]), full)
            }
            198 => {
                let z = self.direction(e, 2)?;
                let scale = place_scale(place);
                let (major, minor) = (e.real(3)? * scale, e.real(4)? * scale);
                let x = self.optional_direction(e, 5, parametrised)?;
                let frame = placed_frame(place, loc, z, x)?;
                let full = [Some([0.0, TAU]), Some([0.0, TAU])];
                (
                    AnalyticSurface::torus(frame, major, minor),
                    IgesMap::Torus,
                    full,
                )
            }
            _ => return Err(skip(format!("entity {t} is not a B-rep surface type"))),
        };
        let iges = if parametrised && det(place) > 0.0 {
            iges
        } else {
            IgesMap::Undefined
        };
        Ok(Support::Analytic(Box::new(AnalyticSupport {
            surf: geometry(surf, &format!("entity {t}"))?,
            iges,
            fixed,
        })))
    }

    /// A point entity (116) at pointer `k`, in definition space.
    fn point116(&mut self, e: &Entity, k: usize) -> Mapped<DVec3> {
        let p = self.follow_kind(e, k, &[116], "a point (116)")?;
        let own = self.placement(p, &Transform::IDENTITY)?;
        Ok(dvec(&own, DVec3::new(p.real(1)?, p.real(2)?, p.real(3)?)))
    }

    /// A direction entity (123) at pointer `k`.
    fn direction(&mut self, e: &Entity, k: usize) -> Mapped<DVec3> {
        let d = self.follow_kind(e, k, &[123], "a direction (123)")?;
        let own = self.placement(d, &Transform::IDENTITY)?;
        Ok(dir(&own, DVec3::new(d.real(1)?, d.real(2)?, d.real(3)?)))
    }

    fn optional_direction(&mut self, e: &Entity, k: usize, read: bool) -> Mapped<Option<DVec3>> {
        if !read || e.optional_pointer(k)?.is_none() {
            return Ok(None);
        }
        self.direction(e, k).map(Some)
    }
}

/// The uniform scale of a placement (1 for a rotation), to scale radii given as numbers.
fn place_scale(t: &Transform) -> f64 {
    det(t).abs().cbrt()
}

/// The IGES start parameter's NURBS parameter (the domain start where only the shape is known).
fn directrix_start(c: &Curve) -> f64 {
    match c.param {
        CurveParam::Shape => c
            .nurbs
            .knots
            .get(c.nurbs.degree)
            .copied()
            .unwrap_or_default(),
        _ => c.to_nurbs(c.range[0]).unwrap_or_default(),
    }
}

/// The one curve a generatrix or directrix must be.
fn single(mut curves: Vec<Curve>, e: &Entity, what: &str) -> Mapped<Curve> {
    match curves.len() {
        1 => curves.pop().ok_or_else(|| skip(what.to_owned())),
        0 => Err(malformed(e, format!("has an empty {what}"))),
        _ => Err(skip(format!(
            "a composite curve as {what} is not supported"
        ))),
    }
}

/// Entity 128 (IGES 5.3): knots, weights and points with `u` running fastest, then the
/// parameter range `[U0, U1] × [V0, V1]`, which may be part of the knot domain (non-normalised
/// and periodic forms included); the result is cut to that range with clamped knots.
fn bspline_surface(e: &Entity, place: &Transform) -> Mapped<NurbsSurface> {
    let (k1, k2) = (e.count(1)?, e.count(2)?);
    let (m1, m2) = (e.count(3)?, e.count(4)?);
    if m1 == 0 || m2 == 0 || k1 < m1 || k2 < m2 {
        return Err(malformed(
            e,
            format!("has indices {k1}, {k2} and degrees {m1}, {m2}"),
        ));
    }
    let (n1, n2) = (k1 + 1, k2 + 1);
    let (a, b) = (n1 + m1 + 1, n2 + m2 + 1);
    let knots_u = e.reals(10, a)?;
    let knots_v = e.reals(10 + a, b)?;
    let count = n1
        .checked_mul(n2)
        .ok_or_else(|| malformed(e, "has too many points"))?;
    let w_at = 10 + a + b;
    let w = e.reals(w_at, count)?;
    let xyz = e.reals(w_at + count, count.saturating_mul(3))?;
    let mut points = Vec::with_capacity(count);
    let mut weights = Vec::with_capacity(count);
    for i in 0..n1 {
        for j in 0..n2 {
            let idx = j * n1 + i;
            let p = xyz.get(3 * idx..3 * idx + 3).unwrap_or_default();
            let q = match p {
                [x, y, z] => DVec3::new(*x, *y, *z),
                _ => return Err(malformed(e, "has too few control points")),
            };
            points.push(dvec(place, q));
            weights.push(w.get(idx).copied().unwrap_or(1.0));
        }
    }
    let range_at = w_at + 4 * count;
    let u = [e.real(range_at)?, e.real(range_at + 1)?];
    let v = [e.real(range_at + 2)?, e.real(range_at + 3)?];
    let surface = NurbsSurface {
        degree: [m1, m2],
        knots: [knots_u, knots_v],
        points,
        weights,
    };
    surface
        .validate()
        .map_err(|err| malformed(e, format!("is not a valid B-spline surface: {err}")))?;
    super::segment::cut_surface(&surface, u, v).map_err(|err| skip(format!("entity 128: {err}")))
}

/// Entity 114: `M × N` bicubic patches in power form on the breakpoint grid, 48 coefficients
/// each (x, y, z; `s^a t^b` at index `a + 4b`), plus 48 arbitrary values after each `u` row;
/// converted to Bézier patches joined with knots of multiplicity 3 (exact).
fn spline_surface(e: &Entity, place: &Transform) -> Mapped<NurbsSurface> {
    let (m, n) = (e.count(3)?, e.count(4)?);
    if m == 0 || n == 0 {
        return Err(malformed(e, "has no patches"));
    }
    let tu = e.reals(5, m + 1)?;
    let tv = e.reals(6 + m, n + 1)?;
    let first = 7 + m + n;
    // Every patch's 48 coefficients must be there before the net is allocated.
    let needed = m
        .checked_mul(n + 1)
        .and_then(|k| k.checked_mul(48))
        .and_then(|k| k.checked_add(first));
    if needed.is_none_or(|k| k > e.param_count() + 48) {
        return Err(malformed(
            e,
            format!("has too few coefficients for {m} × {n} patches"),
        ));
    }
    let (nu, nv) = (3 * m + 1, 3 * n + 1);
    let mut points = vec![DVec3::ZERO; nu * nv];
    for i in 0..m {
        let hu =
            step(&tu, i).ok_or_else(|| malformed(e, "has u breakpoints that do not increase"))?;
        for j in 0..n {
            let hv = step(&tv, j)
                .ok_or_else(|| malformed(e, "has v breakpoints that do not increase"))?;
            let at = first + (i * (n + 1) + j) * 48;
            let c = e.reals(at, 48)?;
            let patch = bezier_patch(&c, hu, hv);
            for (a, row) in patch.iter().enumerate() {
                for (b, p) in row.iter().enumerate() {
                    if let Some(slot) = points.get_mut((3 * i + a) * nv + 3 * j + b) {
                        *slot = dvec(place, *p);
                    }
                }
            }
        }
    }
    let knots = |t: &[f64]| {
        let mut k = vec![t.first().copied().unwrap_or_default(); 4];
        for x in t.iter().skip(1).take(t.len().saturating_sub(2)) {
            k.extend([*x; 3]);
        }
        k.extend([t.last().copied().unwrap_or_default(); 4]);
        k
    };
    let surface = NurbsSurface {
        degree: [3, 3],
        knots: [knots(&tu), knots(&tv)],
        weights: vec![1.0; points.len()],
        points,
    };
    geometry(surface.validate(), "entity 114")?;
    Ok(surface)
}

fn step(t: &[f64], i: usize) -> Option<f64> {
    let h = t.get(i + 1)? - t.get(i)?;
    (h > 0.0).then_some(h)
}

/// The 4 × 4 Bézier points of one patch from its 48 power coefficients.
fn bezier_patch(c: &[f64], hu: f64, hv: f64) -> [[DVec3; 4]; 4] {
    let mut out = [[DVec3::ZERO; 4]; 4];
    for (axis, coeffs) in c.chunks_exact(16).take(3).enumerate() {
        // Rows in s for each power of t, then columns in t.
        let mut by_t = [[0.0; 4]; 4];
        for (b, row) in by_t.iter_mut().enumerate() {
            let s_poly: Vec<f64> = (0..4)
                .map(|a| coeffs.get(a + 4 * b).copied().unwrap_or(0.0))
                .collect();
            *row = power_to_bezier(&s_poly, hu);
        }
        for (a, col) in out.iter_mut().enumerate() {
            let t_poly: Vec<f64> = by_t
                .iter()
                .map(|r| r.get(a).copied().unwrap_or(0.0))
                .collect();
            let bez = power_to_bezier(&t_poly, hv);
            for (slot, value) in col.iter_mut().zip(bez) {
                match axis {
                    0 => slot.x = value,
                    1 => slot.y = value,
                    _ => slot.z = value,
                }
            }
        }
    }
    out
}
