//! The state of one mapping run: the parsed file, the unit, the face name stem, and the set of
//! entities that were read for something drawn (so that everything else can be reported as
//! skipped instead of dropped silently).

use std::collections::HashSet;

use crate::formats::iges::{De, Entity, IgesFile, Transform};

use super::fail::{Fail, Mapped, malformed};
use super::loops::Repairs;

/// How deep references may nest (composites of composites, subfigures in subfigures, …) before
/// the file is taken to loop; real files use two or three levels.
pub(crate) const MAX_DEPTH: usize = 32;

/// Entity types that are surfaces (IGES 5.3), for pointer checks; unsupported ones among them are
/// skipped with a reason when drawn.
pub(crate) const SURFACES: [i32; 13] = [
    108, 114, 118, 120, 122, 128, 140, 190, 192, 194, 196, 198, 143,
];

/// Entity types that are curves (or points, allowed in composites).
pub(crate) const CURVES: [i32; 10] = [100, 102, 104, 106, 110, 112, 116, 126, 130, 142];

pub(crate) struct Reader<'a> {
    pub file: &'a IgesFile,
    /// Millimetres per model unit (IGES 5.3 §2.2.4.3, global parameters 14 and 15).
    pub mm: f64,
    /// File stem or product id, the first part of every face name.
    pub stem: String,
    /// Entities read for a face or used as its attribute.
    pub used: HashSet<De>,
    /// Trim repairs over the whole model, and the face with the largest gap closed.
    pub repairs: Repairs,
    pub largest_gap_face: String,
    /// Largest distance of a model-space boundary from its surface: (relative to the surface's
    /// size, in mm).
    pub off_surface: (f64, f64),
}

impl<'a> Reader<'a> {
    #[must_use]
    pub fn new(file: &'a IgesFile, stem: String) -> Self {
        Self {
            file,
            mm: file.mm_per_unit(),
            stem,
            used: HashSet::new(),
            repairs: Repairs::default(),
            largest_gap_face: String::new(),
            off_surface: (0.0, 0.0),
        }
    }

    /// The uniform scaling from model units to millimetres, applied last.
    #[must_use]
    pub fn unit(&self) -> Transform {
        let s = self.mm;
        Transform {
            matrix: [[s, 0.0, 0.0, 0.0], [0.0, s, 0.0, 0.0], [0.0, 0.0, s, 0.0]],
        }
    }

    /// Marks `e` as read.
    pub fn mark(&mut self, e: &Entity) {
        self.used.insert(e.de());
    }

    /// The entity pointer parameter `k` of `from` points at, marked as read.
    pub fn follow(&mut self, from: &Entity, k: usize) -> Mapped<&'a Entity> {
        let e = self.file.follow(from, k)?;
        self.used.insert(e.de());
        Ok(e)
    }

    /// Like [`Self::follow`], for a pointer that must lead to one of `types` (`what` names them
    /// in the error, which is about `from` and its parameter `k`).
    pub fn follow_kind(
        &mut self,
        from: &Entity,
        k: usize,
        types: &[i32],
        what: &str,
    ) -> Mapped<&'a Entity> {
        let e = self.follow(from, k)?;
        if types.contains(&e.entity_type()) {
            Ok(e)
        } else {
            Err(Fail::Malformed(
                from.param_error(
                    k,
                    format!(
                        "points at {} (entity {}, {}), which is not {what}",
                        e.de(),
                        e.entity_type(),
                        e.type_name()
                    ),
                )
                .to_string(),
            ))
        }
    }

    /// Like [`Self::follow`], with a null pointer meaning none.
    pub fn follow_optional(&mut self, from: &Entity, k: usize) -> Mapped<Option<&'a Entity>> {
        let e = self.file.follow_optional(from, k)?;
        if let Some(e) = e {
            self.used.insert(e.de());
        }
        Ok(e)
    }

    /// The entity numbered `de` (already checked to exist by the parser), marked as read.
    pub fn at(&mut self, from: &Entity, de: De) -> Mapped<&'a Entity> {
        let e = self
            .file
            .entity(de)
            .ok_or_else(|| malformed(from, format!("points at {de}, which does not exist")))?;
        self.used.insert(de);
        Ok(e)
    }

    /// Marks `e` and everything it is made of as read, without converting it: the
    /// representation of a boundary that was not chosen (142 BPTR or CPTR, 141/508 curves).
    pub fn mark_tree(&mut self, e: &Entity) {
        let mut stack = vec![(e.de(), 0)];
        while let Some((de, depth)) = stack.pop() {
            let Some(x) = self.file.entity(de) else {
                continue;
            };
            if !self.used.insert(de) && depth > 0 {
                continue;
            }
            if depth < MAX_DEPTH {
                let parts = super::roots::parts(x).unwrap_or_default();
                stack.extend(parts.into_iter().map(|p| (p, depth + 1)));
                stack.extend(x.directory().transform.map(|t| (t, depth + 1)));
            }
        }
    }

    /// `e`'s own transformation chain (IGES 5.3 entity 124: DE field 7, then the 124s placing
    /// that one) followed by `outer`, the placement of the parent it is read for. Children are
    /// defined in their parent's definition space, so the parent's placement comes last.
    pub fn placement(&mut self, e: &Entity, outer: &Transform) -> Mapped<Transform> {
        let own = self.file.transform(e)?;
        let mut holder = e.directory().transform;
        let mut guard = 0;
        while let Some(de) = holder {
            if !self.used.insert(de) || guard > MAX_DEPTH {
                break;
            }
            guard += 1;
            holder = self.file.entity(de).and_then(|m| m.directory().transform);
        }
        Ok(own.then(*outer))
    }
}
