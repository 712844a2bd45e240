//! Faces: a trimmed surface (144), a bounded surface (143), a B-rep face (510) or a surface on
//! its own (128, 114, 120, 122, bounded 108, 196, 198), each turned into a [`CadFace`] whose trim
//! loops lie in its NURBS parameter space and have been accepted by the trim crate.

use std::f64::consts::PI;

use crate::formats::iges::{Attr, Entity, Transform};
use crate::geom::analytic::{NurbsSurface, ParamBox};
use glam::DVec2;

use super::boundary::LoopSource;
use super::check;
use super::fail::{Mapped, geometry, malformed, skip};
use super::loops::{Repairs, assemble, domain_loop, to_cad};
use super::reader::{CURVES, Reader, SURFACES};
use super::surfaces::{AnalyticSupport, IgesMap, ReadSurface, Support};
use super::trace::{FLATTEN, Target, Traced, Tracer, seam_shift};
use crate::formats::cad::{CadFace, CadLoop};

/// How far an unbounded surface's box reaches past its trims, relative to their extent: enough
/// to hold the exact curves between the coarse samples the box is measured on.
const PAD: f64 = 0.02;

/// The colours of the DE colour numbers 1–8 (IGES 5.3 §2.2.4.4, field 13).
const COLOURS: [[f64; 3]; 8] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [1.0, 1.0, 0.0],
    [1.0, 0.0, 1.0],
    [0.0, 1.0, 1.0],
    [1.0, 1.0, 1.0],
];

/// A face's loops as read: the declared outer loop (if the file gives one) and the others.
pub(crate) struct FaceLoops {
    pub loops: Vec<LoopSource>,
    /// The outer boundary is the surface's whole domain (144 with `N1 = 0`).
    pub whole_domain: bool,
}

/// Everything a face is built from.
pub(crate) struct FaceSpec<'e> {
    pub entity: &'e Entity,
    pub surface: ReadSurface,
    pub loops: FaceLoops,
    pub reversed: bool,
    /// Colour fallback (the surface entity's, the solid's).
    pub fallback_colour: Option<[f64; 3]>,
}

/// Whether parameter-space boundaries can be used on this support.
#[must_use]
pub(crate) fn has_param_space(s: &Support) -> bool {
    match s {
        Support::Nurbs(_) => true,
        Support::Analytic(a) => a.iges != IgesMap::Undefined,
    }
}

impl<'a> Reader<'a> {
    /// The colour of `e` from its DE field 13: a number 1–8 or a 314 colour definition (whose
    /// components are percentages).
    pub fn colour(&mut self, e: &Entity) -> Mapped<Option<[f64; 3]>> {
        match e.directory().colour {
            Attr::Value(n) => Ok(usize::try_from(n)
                .ok()
                .and_then(|n| n.checked_sub(1))
                .and_then(|i| COLOURS.get(i).copied())),
            Attr::Pointer(de) => {
                let c = self.at(e, de)?;
                if c.entity_type() != 314 {
                    return Ok(None);
                }
                let rgb = [c.real(1)?, c.real(2)?, c.real(3)?].map(|x| (x / 100.0).clamp(0.0, 1.0));
                Ok(Some(rgb))
            }
        }
    }

    /// Entity 144: `PTS, N1, N2, PTO, PTI(N2)`.
    pub fn trimmed_surface(&mut self, e: &'a Entity, outer: &Transform) -> Mapped<CadFace> {
        self.mark(e);
        let place = self.placement(e, outer)?;
        let pts = self.follow_kind(e, 1, &SURFACES, "a surface")?;
        let surface = self.surface(pts, &place)?;
        let param_ok = has_param_space(&surface.support);
        let n1 = e.int(2)?;
        let n2 = e.count(3)?;
        let mut loops = Vec::with_capacity(n2 + 1);
        if n1 != 0 {
            let pto = self.follow_kind(e, 4, &[142], "a curve on a surface (142)")?;
            loops.push(self.curve_on_surface(pto, &place, param_ok)?);
        }
        for k in 0..n2 {
            let pti = self.follow_kind(e, 5 + k, &[142], "a curve on a surface (142)")?;
            loops.push(self.curve_on_surface(pti, &place, param_ok)?);
        }
        let fallback_colour = self.colour(pts)?;
        self.face(FaceSpec {
            entity: e,
            surface,
            loops: FaceLoops {
                loops,
                whole_domain: n1 == 0,
            },
            reversed: false,
            fallback_colour,
        })
    }

    /// Entity 143: `TYPE, SPTR, N, BDPT(N)` with 141 boundaries.
    pub fn bounded_surface(&mut self, e: &'a Entity, outer: &Transform) -> Mapped<CadFace> {
        self.mark(e);
        let place = self.placement(e, outer)?;
        let s = self.follow_kind(e, 2, &SURFACES, "a surface")?;
        let surface = self.surface(s, &place)?;
        let param_ok = e.int(1)? == 1 && has_param_space(&surface.support);
        let n = e.count(3)?;
        let mut loops = Vec::with_capacity(n);
        for k in 0..n {
            let b = self.follow_kind(e, 4 + k, &[141], "a boundary (141)")?;
            loops.push(self.boundary141(b, &place, param_ok)?);
        }
        let fallback_colour = self.colour(s)?;
        self.face(FaceSpec {
            entity: e,
            surface,
            loops: FaceLoops {
                loops,
                whole_domain: false,
            },
            reversed: false,
            fallback_colour,
        })
    }

    /// Entity 510: `SURF, N, OF, LOOP(N)` with 508 loops; `reversed` from the shell.
    pub fn brep_face(
        &mut self,
        e: &'a Entity,
        place: &Transform,
        reversed: bool,
        solid_colour: Option<[f64; 3]>,
    ) -> Mapped<CadFace> {
        if e.entity_type() != 510 {
            return Err(malformed(e, "is used as a B-rep face, but is not a 510"));
        }
        self.mark(e);
        let s = self.follow_kind(e, 1, &SURFACES, "a surface")?;
        let surface = self.surface(s, place)?;
        let param_ok = has_param_space(&surface.support);
        let n = e.count(2)?;
        let mut loops = Vec::with_capacity(n);
        for k in 0..n {
            let l = self.follow_kind(e, 4 + k, &[508], "a loop (508)")?;
            loops.push(self.loop508(l, place, param_ok)?);
        }
        let fallback_colour = self.colour(s)?.or(solid_colour);
        self.face(FaceSpec {
            entity: e,
            surface,
            loops: FaceLoops {
                loops,
                whole_domain: false,
            },
            reversed,
            fallback_colour,
        })
    }

    /// A surface drawn on its own: untrimmed over its own range, or, for a bounded plane (108
    /// form 1), within its bounding curve.
    pub fn lone_surface(&mut self, e: &'a Entity, outer: &Transform) -> Mapped<CadFace> {
        let bounded_plane = e.entity_type() == 108 && e.form() == 1;
        let place = self.placement(e, outer)?;
        let surface = self.surface(e, outer)?;
        let mut loops = Vec::new();
        if bounded_plane {
            let c = self.follow_kind(e, 5, &CURVES, "a curve")?;
            let curves = self.curve(c, &place, 1)?;
            loops.push(LoopSource {
                pieces: curves
                    .into_iter()
                    .map(|c| super::boundary::Piece {
                        source: super::boundary::Source::Model(c),
                        reversed: false,
                    })
                    .collect(),
            });
        }
        self.face(FaceSpec {
            entity: e,
            surface,
            loops: FaceLoops {
                loops,
                whole_domain: false,
            },
            reversed: false,
            fallback_colour: None,
        })
    }

    /// Builds the NURBS and the loops of one face.
    fn face(&mut self, mut spec: FaceSpec<'_>) -> Mapped<CadFace> {
        let entity = spec.entity;
        for l in &mut spec.loops.loops {
            l.orient();
        }
        let colour = self.colour(entity)?.or(spec.fallback_colour);
        let name = format!("{}#{}", self.stem, entity.de().0);
        let (surface, traced) = match &spec.surface.support {
            Support::Nurbs(s) => (s.clone(), self.trace_nurbs(s, &spec.loops.loops)?),
            Support::Analytic(a) => self.trace_analytic(a, &spec.loops.loops)?,
        };
        let dom = geometry(surface.domain(), "face surface")?;
        let diagonal = (dom[0][1] - dom[0][0]).hypot(dom[1][1] - dom[1][0]);
        let mut repairs = Repairs::default();
        let mut loops: Vec<CadLoop> = traced
            .into_iter()
            .map(|pieces| CadLoop {
                outer: false,
                pieces: to_cad(assemble(pieces, &surface, diagonal, &mut repairs)),
            })
            .collect();
        if spec.loops.whole_domain && !loops.is_empty() {
            loops.insert(0, domain_loop(dom));
        }
        classify(&surface, &mut loops).map_err(|e| skip(format!("its trim is refused: {e}")))?;
        self.note_repairs(&name, repairs);
        Ok(CadFace {
            name,
            surface_type: format!("entity {}", spec.surface.entity_type),
            surface,
            loops,
            color: colour,
            reversed: spec.reversed,
        })
    }

    fn note_repairs(&mut self, name: &str, r: Repairs) {
        self.repairs.snapped += r.snapped;
        self.repairs.bridged += r.bridged;
        if r.largest > self.repairs.largest {
            self.repairs.largest = r.largest;
            self.largest_gap_face = name.to_owned();
        }
    }

    fn note_distance(&mut self, d: f64, scale: f64) {
        let relative = d / scale.max(f64::MIN_POSITIVE);
        if relative > self.off_surface.0 {
            self.off_surface = (relative, d);
        }
    }

    fn trace_nurbs(&mut self, s: &NurbsSurface, loops: &[LoopSource]) -> Mapped<Vec<Vec<Traced>>> {
        let dom = geometry(s.domain(), "face surface")?;
        let diagonal = (dom[0][1] - dom[0][0]).hypot(dom[1][1] - dom[1][0]);
        let scale = s.extent();
        let mut tracer = Tracer {
            target: Target::Nurbs {
                surface: s,
                dom,
                scale,
            },
            map: None,
            tol: FLATTEN * diagonal,
            max_distance: 0.0,
        };
        let traced = loops
            .iter()
            .map(|l| tracer.trace(l, None))
            .collect::<Mapped<Vec<_>>>()?;
        self.note_distance(tracer.max_distance, scale);
        Ok(traced)
    }

    fn trace_analytic(
        &mut self,
        a: &AnalyticSupport,
        loops: &[LoopSource],
    ) -> Mapped<(NurbsSurface, Vec<Vec<Traced>>)> {
        let mut coarse = Tracer {
            target: Target::Analytic {
                support: a,
                range: search_box(a),
            },
            map: None,
            tol: 0.0,
            max_distance: 0.0,
        };
        let mut starts = Vec::with_capacity(loops.len());
        let (mut lo, mut hi) = (DVec2::INFINITY, DVec2::NEG_INFINITY);
        for l in loops {
            let points = coarse.coarse(l)?;
            let shift = seam_shift(&points, a)?;
            for p in &points {
                lo = lo.min(*p + shift);
                hi = hi.max(*p + shift);
            }
            starts.push(points.first().map(|p| *p + shift));
        }
        let range = face_box(a, lo, hi)?;
        let nurbs = geometry(a.surf.to_nurbs(&range), "analytic surface")?;
        let dom = geometry(nurbs.surface.domain(), "face surface")?;
        let diagonal = (dom[0][1] - dom[0][0]).hypot(dom[1][1] - dom[1][0]);
        let scale = nurbs.surface.extent();
        let mut tracer = Tracer {
            target: Target::Analytic { support: a, range },
            map: Some(nurbs.map.clone()),
            tol: FLATTEN * diagonal,
            max_distance: 0.0,
        };
        let traced = loops
            .iter()
            .zip(starts)
            .map(|(l, start)| tracer.trace(l, start))
            .collect::<Mapped<Vec<_>>>()?;
        self.note_distance(tracer.max_distance.max(coarse.max_distance), scale);
        Ok((nurbs.surface, traced))
    }
}

/// The box model-space points are inverted in before the face's box is known: the fixed ranges,
/// a huge one for unbounded lengths, one turn for unbounded angles.
fn search_box(a: &AnalyticSupport) -> ParamBox {
    let angular = a.surf.angular();
    let side = |k: usize| {
        let fixed = a.fixed.get(k).copied().flatten();
        let is_angle = angular.get(k).copied().unwrap_or(false);
        fixed.unwrap_or(if is_angle { [-PI, PI] } else { [-1e15, 1e15] })
    };
    ParamBox {
        u: side(0),
        v: side(1),
    }
}

/// The face's analytic box: the fixed ranges, or the trims' extent padded by [`PAD`] (at most one
/// turn for angles).
fn face_box(a: &AnalyticSupport, lo: DVec2, hi: DVec2) -> Mapped<ParamBox> {
    let angular = a.surf.angular();
    let side = |k: usize, lo: f64, hi: f64| -> Mapped<[f64; 2]> {
        if let Some(Some(r)) = a.fixed.get(k) {
            return Ok(*r);
        }
        if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
            return Err(skip(
                "an unbounded surface without trim loops cannot be drawn",
            ));
        }
        let pad = PAD * (hi - lo).max(1e-9 * (lo.abs() + hi.abs()).max(1.0));
        let (mut a0, mut a1) = (lo - pad, hi + pad);
        if angular.get(k).copied().unwrap_or(false) && a1 - a0 > 2.0 * PI {
            let mid = 0.5 * (lo + hi);
            (a0, a1) = (mid - PI, mid + PI);
        }
        Ok([a0, a1])
    };
    Ok(ParamBox {
        u: side(0, lo.x, hi.x)?,
        v: side(1, lo.y, hi.y)?,
    })
}

/// Validates the loops with the trim crate and marks the outer ones by nesting.
fn classify(surface: &NurbsSurface, loops: &mut [CadLoop]) -> Result<(), String> {
    let Some(regions) = check::regions(surface, loops)? else {
        return Ok(());
    };
    for (l, r) in loops.iter_mut().zip(regions.loops()) {
        l.outer = r.role() == crate::geom::trim::Role::Outer;
    }
    Ok(())
}
