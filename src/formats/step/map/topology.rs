//! Faces as ISO 10303-42 topology (§5.4) describes them: ADVANCED_FACE / FACE_SURFACE with
//! FACE_OUTER_BOUND / FACE_BOUND (orientation flag), EDGE_LOOP of ORIENTED_EDGE of EDGE_CURVE
//! (same_sense, VERTEX_POINT ends), VERTEX_LOOP (a degenerate loop: a cone's apex, a sphere's
//! pole — dropped, its point kept as a hint), POLY_LOOP (a faceted face's polygon), and the
//! PCURVEs that SURFACE_CURVE / SEAM_CURVE carry as associated geometry.
//!
//! Nothing here needs the surface: parameter ranges are worked out by the trims, which know it.

use crate::formats::step::EntityRef;
use glam::DVec3;

use super::attrs::{P, Res, bad, is, part, point3, unsupported};
use super::curves::{self, Read};

/// One face read from the file.
#[derive(Clone, Debug)]
pub(crate) struct FaceIn<'a> {
    pub entity: EntityRef<'a>,
    pub surface: EntityRef<'a>,
    /// ADVANCED_FACE.same_sense.
    pub same_sense: bool,
    pub loops: Vec<LoopIn>,
    /// Points of the VERTEX_LOOPs, which are dropped as loops.
    pub vertex_points: Vec<DVec3>,
    /// Box of the edges (vertices, conic circles, spline control points): a size scale.
    pub extent: (DVec3, DVec3),
}

/// One bound of a face, in the direction its FACE_BOUND orientation gives.
#[derive(Clone, Debug)]
pub(crate) struct LoopIn {
    /// A FACE_OUTER_BOUND.
    pub outer: bool,
    pub edges: Vec<EdgeUse>,
}

/// One ORIENTED_EDGE of a loop.
#[derive(Clone, Debug)]
pub(crate) struct EdgeUse {
    /// The EDGE_CURVE (or, for a POLY_LOOP side, the loop).
    pub id: u64,
    /// The 3D curve (`None` when the edge geometry is a PCURVE: it is then in `pcurves`).
    pub curve: Option<Read>,
    /// EDGE_CURVE.edge_start / edge_end points.
    pub start: DVec3,
    pub end: DVec3,
    /// Start and end are the same vertex: the edge is a whole closed curve.
    pub closed: bool,
    /// EDGE_CURVE.same_sense.
    pub same_sense: bool,
    /// Traversed from `start` to `end` (ORIENTED_EDGE.orientation, times the bound's).
    pub forward: bool,
    /// 2D curves in a surface's parameter space: `(basis_surface id, curve)`.
    pub pcurves: Vec<(u64, Read)>,
}

/// Reads a face entity (ADVANCED_FACE, FACE_SURFACE; an ORIENTED_FACE is resolved by the
/// caller). `rad` converts angles.
pub(crate) fn read_face<'a>(e: EntityRef<'a>, rad: f64) -> Res<FaceIn<'a>> {
    if !(is(&e, "FACE_SURFACE") || is(&e, "ADVANCED_FACE")) {
        return Err(unsupported(&e, "only faces with a surface are drawn"));
    }
    let own = part(e, "FACE", 1)?;
    let bounds = own.p(0, "bounds")?.ents()?;
    let face_surface = part(e, "FACE_SURFACE", 2)?;
    let surface = face_surface.p(0, "face_geometry")?.ent()?;
    let same_sense = face_surface.p(1, "same_sense")?.flag()?;
    let mut loops = Vec::new();
    let mut vertex_points = Vec::new();
    for b in bounds {
        let fb = part(b, "FACE_BOUND", 1)?;
        let lp = fb.p(0, "bound")?.ent()?;
        let orientation = fb.p(1, "orientation")?.flag()?;
        let outer = is(&b, "FACE_OUTER_BOUND");
        if is(&lp, "VERTEX_LOOP") {
            let v = part(lp, "VERTEX_LOOP", 1)?.p(0, "loop_vertex")?.ent()?;
            vertex_points.push(vertex_point(v)?);
            continue;
        }
        let mut edges = if is(&lp, "EDGE_LOOP") {
            read_edge_loop(lp, rad)?
        } else if is(&lp, "POLY_LOOP") {
            read_poly_loop(lp)?
        } else {
            return Err(unsupported(&lp, "this loop type is not drawn yet"));
        };
        if !orientation {
            edges.reverse();
            edges.iter_mut().for_each(|u| u.forward = !u.forward);
        }
        loops.push(LoopIn { outer, edges });
    }
    let extent = extent(&loops, &vertex_points);
    Ok(FaceIn {
        entity: e,
        surface,
        same_sense,
        loops,
        vertex_points,
        extent,
    })
}

/// VERTEX_POINT's CARTESIAN_POINT.
fn vertex_point(v: EntityRef<'_>) -> Res<DVec3> {
    let g = part(v, "VERTEX_POINT", 1)?.p(0, "vertex_geometry")?.ent()?;
    if !is(&g, "CARTESIAN_POINT") {
        return Err(unsupported(
            &g,
            "vertices on curves or surfaces are not drawn yet",
        ));
    }
    point3(g)
}

/// EDGE_LOOP: its ORIENTED_EDGEs in order.
fn read_edge_loop(lp: EntityRef<'_>, rad: f64) -> Res<Vec<EdgeUse>> {
    let list = part(lp, "EDGE_LOOP", 1)?.p(0, "edge_list")?.ents()?;
    if list.is_empty() {
        return Err(bad(&lp, "edge loop has no edges"));
    }
    let mut out = Vec::with_capacity(list.len());
    for oe in list {
        let (edge, forward) = if is(&oe, "ORIENTED_EDGE") {
            let own = part(oe, "ORIENTED_EDGE", 3)?;
            (
                own.p(0, "edge_element")?.ent()?,
                own.p(1, "orientation")?.flag()?,
            )
        } else {
            (oe, true)
        };
        out.push(read_edge(edge, forward, rad)?);
    }
    Ok(out)
}

/// EDGE_CURVE with its vertices, 3D curve and PCURVEs.
fn read_edge(edge: EntityRef<'_>, forward: bool, rad: f64) -> Res<EdgeUse> {
    if !is(&edge, "EDGE_CURVE") {
        return Err(unsupported(&edge, "only EDGE_CURVE edges are drawn"));
    }
    let e = part(edge, "EDGE", 1)?;
    let (vs, ve) = (e.p(0, "edge_start")?.ent()?, e.p(1, "edge_end")?.ent()?);
    let ec = part(edge, "EDGE_CURVE", 3)?;
    let geom = ec.p(0, "edge_geometry")?.ent()?;
    let same_sense = ec.p(1, "same_sense")?.flag()?;
    let (start, end) = (vertex_point(vs)?, vertex_point(ve)?);
    let mut pcurves = Vec::new();
    let curve = if is(&geom, "PCURVE") {
        pcurves.push(read_pcurve(geom, rad)?);
        None
    } else {
        if is(&geom, "SURFACE_CURVE") {
            let sc = part(geom, "SURFACE_CURVE", 1)?;
            for g in sc.p(1, "associated_geometry")?.ents()? {
                if is(&g, "PCURVE") {
                    pcurves.push(read_pcurve(g, rad)?);
                }
            }
        }
        Some(curves::read(geom, rad, 0)?)
    };
    Ok(EdgeUse {
        id: edge.id(),
        curve,
        start,
        end,
        closed: vs.id() == ve.id(),
        same_sense,
        forward,
        pcurves,
    })
}

/// PCURVE: its basis surface's id and the 2D curve of its DEFINITIONAL_REPRESENTATION.
fn read_pcurve(pc: EntityRef<'_>, rad: f64) -> Res<(u64, Read)> {
    let own = part(pc, "PCURVE", 1)?;
    let surface = own
        .p(0, "basis_surface")?
        .reference()
        .map_err(super::attrs::msg)?;
    let rep = own.p(1, "reference_to_curve")?.ent()?;
    let items = part(rep, "REPRESENTATION", 0)?.p(1, "items")?.ents()?;
    for item in items {
        if is(&item, "CURVE")
            || matches!(
                item.name(),
                "LINE"
                    | "CIRCLE"
                    | "ELLIPSE"
                    | "TRIMMED_CURVE"
                    | "POLYLINE"
                    | "PARABOLA"
                    | "HYPERBOLA"
            )
            || is(&item, "B_SPLINE_CURVE")
        {
            return Ok((surface, curves::read(item, rad, 0)?));
        }
    }
    Err(bad(&rep, "definitional representation holds no curve"))
}

/// POLY_LOOP: straight edges between its points, as lines.
fn read_poly_loop(lp: EntityRef<'_>) -> Res<Vec<EdgeUse>> {
    let pts: Vec<DVec3> = part(lp, "POLY_LOOP", 1)?
        .p(0, "polygon")?
        .ents()?
        .into_iter()
        .map(point3)
        .collect::<Res<_>>()?;
    if pts.len() < 3 {
        return Err(bad(&lp, "a poly loop needs at least 3 points"));
    }
    let n = pts.len();
    let mut out = Vec::with_capacity(n);
    for (i, &a) in pts.iter().enumerate() {
        let b = pts.get((i + 1) % n).copied().unwrap_or(a);
        if a == b {
            continue;
        }
        out.push(EdgeUse {
            id: lp.id(),
            curve: Some(Read {
                curve: curves::Curve::Line { p: a, d: b - a },
                trim: None,
            }),
            start: a,
            end: b,
            closed: false,
            same_sense: true,
            forward: true,
            pcurves: Vec::new(),
        });
    }
    Ok(out)
}

/// Box of everything the loops touch (see [`FaceIn::extent`]).
#[must_use]
fn extent(loops: &[LoopIn], extra: &[DVec3]) -> (DVec3, DVec3) {
    let mut lo = DVec3::INFINITY;
    let mut hi = DVec3::NEG_INFINITY;
    let mut add = |p: DVec3| {
        lo = lo.min(p);
        hi = hi.max(p);
    };
    extra.iter().for_each(|&p| add(p));
    for u in loops.iter().flat_map(|l| &l.edges) {
        add(u.start);
        add(u.end);
        match u.curve.as_ref().map(|r| &r.curve) {
            Some(curves::Curve::Conic { frame, a, b }) => {
                let r = a.max(*b);
                add(frame.origin - DVec3::splat(r));
                add(frame.origin + DVec3::splat(r));
            }
            Some(curves::Curve::Nurbs(n)) => n.curve.points.iter().for_each(|&p| add(p)),
            _ => {}
        }
    }
    if lo.x > hi.x {
        (DVec3::ZERO, DVec3::ZERO)
    } else {
        (lo, hi)
    }
}
