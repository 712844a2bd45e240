//! Which entities are faces to draw, and how often. IGES marks dependence in the status field,
//! but writers set it inconsistently, so the pointers decide (as the brief asks): an entity is a
//! root when no geometry entity points at it — a 128 under a 144 is drawn once, trimmed.
//! Associativity groups (402) do not make their members dependent: a group lists faces, it does
//! not consume them. Subfigure instances (408) draw their definition's (308) faces once per
//! instance, placed, and solids (186) their shells' faces (514, 510), as OpenCASCADE counts.

use std::collections::HashSet;

use crate::formats::iges::{De, Entity, IgesError, IgesFile, Transform};

use super::fail::{Fail, Mapped, malformed, skip};
use super::reader::{MAX_DEPTH, Reader};
use crate::formats::cad::CadFace;

/// Every pointer parameter of `e` that makes its target part of `e` (IGES 5.3 parameter lists).
pub(crate) fn parts(e: &Entity) -> Result<Vec<De>, IgesError> {
    let opt = |k: usize| e.optional_pointer(k);
    let list = |first: usize, n: usize| -> Result<Vec<De>, IgesError> {
        let mut out = Vec::with_capacity(n);
        for k in first..first + n {
            out.extend(e.optional_pointer(k)?);
        }
        Ok(out)
    };
    let mut out: Vec<De> = Vec::new();
    match e.entity_type() {
        102 => out = list(2, e.count(1)?)?,
        108 => out.extend(opt(5)?),
        120 => out = list(1, 2)?,
        122 => out.extend(opt(1)?),
        140 => out.extend(opt(5)?),
        141 => {
            out.extend(opt(3)?);
            let mut k = 5;
            for _ in 0..e.count(4)? {
                out.extend(opt(k)?);
                let n = e.count(k + 2)?;
                out.extend(list(k + 3, n)?);
                k += 3 + n;
            }
        }
        142 => out = list(2, 3)?,
        143 => {
            out.extend(opt(2)?);
            out.extend(list(4, e.count(3)?)?);
        }
        144 => {
            out.extend(opt(1)?);
            out.extend(opt(4)?);
            out.extend(list(5, e.count(3)?)?);
        }
        186 => {
            out.extend(opt(1)?);
            let n = e.count(3)?;
            for k in 0..n {
                out.extend(opt(4 + 2 * k)?);
            }
        }
        190 => out = list(1, 3.min(e.param_count()))?,
        192 | 198 => {
            out = list(1, 2)?;
            out.extend(opt(if e.entity_type() == 192 { 4 } else { 5 })?);
        }
        194 => {
            out = list(1, 2)?;
            out.extend(opt(5)?);
        }
        196 => {
            out.extend(opt(1)?);
            out.extend(opt(3)?);
            out.extend(opt(4)?);
        }
        308 => out = list(4, e.count(3)?)?,
        408 => out.extend(opt(1)?),
        402 if e.form() == 9 => out = list(3, e.count(1)? + e.count(2)?)?,
        504 => {
            for k in 0..e.count(1)? {
                out.extend(opt(2 + 5 * k)?);
                out.extend(opt(3 + 5 * k)?);
                out.extend(opt(5 + 5 * k)?);
            }
        }
        508 => {
            let mut k = 2;
            for _ in 0..e.count(1)? {
                out.extend(opt(k + 1)?);
                let n = e.count(k + 4)?;
                for j in 0..n {
                    out.extend(opt(k + 6 + 2 * j)?);
                }
                k += 5 + 2 * n;
            }
        }
        510 => {
            out.extend(opt(1)?);
            out.extend(list(4, e.count(2)?)?);
        }
        514 => {
            for k in 0..e.count(1)? {
                out.extend(opt(2 + 2 * k)?);
            }
        }
        _ => {}
    }
    Ok(out)
}

/// Entities some other entity is made of.
pub(crate) fn referenced(file: &IgesFile) -> Result<HashSet<De>, IgesError> {
    let mut set = HashSet::new();
    for e in file.entities() {
        set.extend(parts(e)?);
    }
    Ok(set)
}

/// One face produced, or one face that could not be, with its entity.
pub(crate) enum Outcome {
    Face(CadFace),
    Skipped { entity_type: i32, reason: String },
}

fn record(out: &mut Vec<Outcome>, e: &Entity, result: Mapped<CadFace>) -> Mapped<()> {
    match result {
        Ok(face) => out.push(Outcome::Face(face)),
        Err(Fail::Skip(reason)) => out.push(Outcome::Skipped {
            entity_type: e.entity_type(),
            reason,
        }),
        Err(f @ Fail::Malformed(_)) => return Err(f),
    }
    Ok(())
}

impl<'a> Reader<'a> {
    /// The faces of root `e` placed by `outer` (instances and solids give several).
    pub fn root(
        &mut self,
        e: &'a Entity,
        outer: &Transform,
        depth: usize,
        out: &mut Vec<Outcome>,
    ) -> Mapped<()> {
        if depth > MAX_DEPTH {
            return Err(malformed(
                e,
                "nests subfigures too deeply (a reference loop?)",
            ));
        }
        let result = match e.entity_type() {
            144 => self.trimmed_surface(e, outer),
            143 => self.bounded_surface(e, outer),
            186 => return self.solid(e, outer, out),
            514 => {
                let place = self.placement(e, outer)?;
                return self.shell(e, &place, true, None, out);
            }
            510 => {
                let place = self.placement(e, outer)?;
                self.brep_face(e, &place, false, None)
            }
            408 => return self.instance(e, outer, depth, out),
            108 if e.form() != 1 => Err(skip(
                "an unbounded plane (108 form 0 or -1) outside a trimmed surface has no extent",
            )),
            190..=194 => Err(skip(
                "an unbounded B-rep surface outside a face has no extent",
            )),
            402 if e.form() == 9 => Err(skip(
                "single-parent associativity (402 form 9, planes with holes) is not supported",
            )),
            108 | 114 | 118 | 120 | 122 | 128 | 140 | 196 | 198 => self.lone_surface(e, outer),
            _ => return Ok(()),
        };
        if matches!(result, Err(Fail::Skip(_))) {
            self.mark(e);
        }
        record(out, e, result)
    }

    /// Entity 408: the 308 it instantiates, scaled by `S`, moved by `(X, Y, Z)`, then placed by
    /// the 408's own transformation.
    fn instance(
        &mut self,
        e: &'a Entity,
        outer: &Transform,
        depth: usize,
        out: &mut Vec<Outcome>,
    ) -> Mapped<()> {
        self.mark(e);
        let def = self.follow(e, 1)?;
        if def.entity_type() != 308 {
            return Err(malformed(
                e,
                "does not point at a subfigure definition (308)",
            ));
        }
        let (x, y, z) = (e.real(2)?, e.real(3)?, e.real(4)?);
        let s = e.real_or(5, 1.0)?;
        let s = if s == 0.0 { 1.0 } else { s };
        let local = Transform {
            matrix: [[s, 0.0, 0.0, x], [0.0, s, 0.0, y], [0.0, 0.0, s, z]],
        };
        let place = local.then(self.placement(e, outer)?);
        let n = def.count(3)?;
        for k in 0..n {
            let member = self.follow(def, 4 + k)?;
            self.root(member, &place, depth + 1, out)?;
        }
        Ok(())
    }

    /// Entity 186: `SHELL, SOF, NVOID, (VOID, VOF) × NVOID`.
    fn solid(&mut self, e: &'a Entity, outer: &Transform, out: &mut Vec<Outcome>) -> Mapped<()> {
        self.mark(e);
        let place = self.placement(e, outer)?;
        let colour = self.colour(e)?;
        let shell = self.follow_kind(e, 1, &[514], "a shell (514)")?;
        let sof = e.int(2)? != 0;
        let shell_place = self.placement(shell, &place)?;
        self.shell(shell, &shell_place, sof, colour, out)?;
        for k in 0..e.count(3)? {
            let void = self.follow_kind(e, 4 + 2 * k, &[514], "a shell (514)")?;
            let vof = e.int(5 + 2 * k)? != 0;
            let void_place = self.placement(void, &place)?;
            self.shell(void, &void_place, vof, colour, out)?;
        }
        Ok(())
    }

    /// Entity 514: `N, (FACE, OF) × N`; a face's `OF = 0` (or a reversed shell) flips its side.
    fn shell(
        &mut self,
        e: &'a Entity,
        place: &Transform,
        agrees: bool,
        colour: Option<[f64; 3]>,
        out: &mut Vec<Outcome>,
    ) -> Mapped<()> {
        if e.entity_type() != 514 {
            return Err(malformed(e, "is used as a shell, but is not a 514"));
        }
        self.mark(e);
        let colour = self.colour(e)?.or(colour);
        for k in 0..e.count(1)? {
            let face = self.follow_kind(e, 2 + 2 * k, &[510], "a face (510)")?;
            let of = e.int(3 + 2 * k)? != 0;
            let result = self.brep_face(face, place, of != agrees, colour);
            record(out, face, result)?;
        }
        Ok(())
    }
}
