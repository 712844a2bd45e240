//! The boundaries of a face as the file gives them, before they are traced into the NURBS
//! parameter space: curves on a parametric surface (142), boundaries (141) and B-rep loops
//! (508 with the edge lists 504). Each picks, per its preference flag, either the
//! parameter-space curves or the model-space curves, and falls back to the other when the
//! preferred one is absent or cannot be used on this surface.

use crate::formats::iges::{Entity, Transform};
use glam::DVec3;

use super::curves::Curve;
use super::fail::{Mapped, malformed, skip};
use super::reader::{CURVES, Reader};

/// Where a boundary curve lives.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Source {
    /// In the surface's IGES parameter space (x, y of the curve).
    Param(Curve),
    /// In model space, placed in millimetres.
    Model(Curve),
}

/// One curve of a loop, in loop order.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Piece {
    pub source: Source,
    /// Traversed from its end to its start.
    pub reversed: bool,
}

/// One loop as the file gives it.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct LoopSource {
    pub pieces: Vec<Piece>,
}

/// The first and last point of a piece in its own space, as traversed.
fn piece_ends(p: &Piece) -> Option<(DVec3, DVec3)> {
    let c = match &p.source {
        Source::Param(c) | Source::Model(c) => &c.nurbs,
    };
    let [lo, hi] = c.domain().ok()?;
    let (a, b) = (c.point(lo).ok()?, c.point(hi).ok()?);
    let flat = |q: DVec3| match p.source {
        Source::Param(_) => q.truncate().extend(0.0),
        Source::Model(_) => q,
    };
    Some(if p.reversed {
        (flat(b), flat(a))
    } else {
        (flat(a), flat(b))
    })
}

impl LoopSource {
    /// Turns pieces written against the chain's direction (a member whose end meets the
    /// previous member) around, so that tracing carries angles and Newton starts along the
    /// actual boundary.
    pub fn orient(&mut self) {
        let ends: Vec<Option<(DVec3, DVec3)>> = self.pieces.iter().map(piece_ends).collect();
        let mut prev_end: Option<DVec3> = None;
        for (k, piece) in self.pieces.iter_mut().enumerate() {
            let Some(Some((s, e))) = ends.get(k).copied() else {
                prev_end = None;
                continue;
            };
            let (s, e) = match prev_end {
                Some(q) if q.distance(e) < q.distance(s) => {
                    piece.reversed = !piece.reversed;
                    (e, s)
                }
                None if k == 0 => {
                    // The first piece: keep it if its end meets the second piece.
                    let next = ends.get(1).copied().flatten();
                    let flip = next.is_some_and(|(ns, ne)| {
                        s.distance(ns).min(s.distance(ne)) < e.distance(ns).min(e.distance(ne))
                    });
                    if flip {
                        piece.reversed = !piece.reversed;
                        (e, s)
                    } else {
                        (s, e)
                    }
                }
                _ => (s, e),
            };
            let _ = s;
            prev_end = Some(e);
        }
    }
}

fn forward(curves: Vec<Curve>, param: bool, reversed: bool) -> Vec<Piece> {
    let wrap = |c| {
        if param {
            Source::Param(c)
        } else {
            Source::Model(c)
        }
    };
    let mut pieces: Vec<Piece> = curves
        .into_iter()
        .map(|c| Piece {
            source: wrap(c),
            reversed,
        })
        .collect();
    if reversed {
        pieces.reverse();
    }
    pieces
}

impl<'a> Reader<'a> {
    /// Entity 142 (IGES 5.3): `CRTN, SPTR, BPTR, CPTR, PREF`. PREF 2 prefers the model-space
    /// curve `CPTR`; 0, 1 and 3 the parameter-space curve `BPTR`; either falls back to the other.
    /// `param_ok` says whether the surface has an IGES parameter space to put `BPTR` in.
    pub fn curve_on_surface(
        &mut self,
        e: &Entity,
        place: &Transform,
        param_ok: bool,
    ) -> Mapped<LoopSource> {
        if e.entity_type() != 142 {
            return Err(malformed(
                e,
                format!(
                    "is used as a boundary, but entity {} is not a 142",
                    e.entity_type()
                ),
            ));
        }
        self.mark(e);
        let bptr = self.kind_optional(e, 3)?;
        let cptr = self.kind_optional(e, 4)?;
        let pref = e.int_or(5, 0)?;
        let use_param = match (bptr.filter(|_| param_ok), cptr) {
            (Some(_), Some(_)) => pref != 2,
            (Some(_), None) => true,
            (None, Some(_)) => false,
            (None, None) => {
                return Err(skip(if bptr.is_some() {
                    "the boundary has only a parameter-space curve, on a surface without a \
                     parameter space"
                } else {
                    "the boundary (142) has neither a parameter-space nor a model-space curve"
                }));
            }
        };
        let pieces = match (use_param, bptr, cptr) {
            (true, Some(b), _) => {
                if let Some(c) = cptr {
                    self.mark_tree(c);
                }
                forward(self.curve(b, &Transform::IDENTITY, 1)?, true, false)
            }
            (_, _, Some(c)) => {
                if let Some(b) = bptr {
                    self.mark_tree(b);
                }
                let own = self.placement(e, place)?;
                forward(self.curve(c, &own, 1)?, false, false)
            }
            _ => Vec::new(),
        };
        Ok(LoopSource { pieces })
    }

    /// Entity 141: `TYPE, PREF, SPTR, N`, then per model curve `CRVPT, SENSE, K, PSCPT(K)`.
    /// PREF 1 prefers model space, 2 parameter space (note: the opposite numbering of 142);
    /// parameter curves are used only when every model curve has them.
    pub fn boundary141(
        &mut self,
        e: &Entity,
        place: &Transform,
        param_ok: bool,
    ) -> Mapped<LoopSource> {
        if e.entity_type() != 141 {
            return Err(malformed(
                e,
                format!(
                    "is used as a boundary, but entity {} is not a 141",
                    e.entity_type()
                ),
            ));
        }
        self.mark(e);
        let (kind, pref) = (e.int(1)?, e.int(2)?);
        let n = e.count(4)?;
        let mut entries = Vec::with_capacity(n);
        let mut k = 5;
        for _ in 0..n {
            let count = e.count(k + 2)?;
            entries.push((k, e.int(k + 1)? == 2, count));
            k += 3 + count;
        }
        let all_param = entries.iter().all(|&(_, _, c)| c > 0);
        let use_param = param_ok && kind == 1 && all_param && pref != 1;
        let own = self.placement(e, place)?;
        let mut pieces = Vec::new();
        for (at, reversed, count) in entries {
            if use_param {
                if let Some(model) = self.follow_optional(e, at)? {
                    self.mark_tree(model);
                }
                for j in 0..count {
                    let c = self.follow_kind(e, at + 3 + j, &CURVES, "a curve")?;
                    pieces.extend(forward(
                        self.curve(c, &Transform::IDENTITY, 1)?,
                        true,
                        false,
                    ));
                }
                if reversed {
                    let start = pieces.len().saturating_sub(count);
                    reverse_tail(&mut pieces, start);
                }
            } else {
                for j in 0..count {
                    let p = self.follow(e, at + 3 + j)?;
                    self.mark_tree(p);
                }
                let c = self.follow_kind(e, at, &CURVES, "a curve")?;
                pieces.extend(forward(self.curve(c, &own, 1)?, false, reversed));
            }
        }
        Ok(LoopSource { pieces })
    }

    /// Entity 508: `N`, then per edge `TYPE, EDGE, NDX, OF, K, (ISOP, CURV) × K`. An edge is
    /// entry `NDX` of an edge list (504: `CURV, SVP, SV, TVP, TV` per edge); TYPE 1 edges are
    /// vertices (degenerate, kept only through their parameter curves). `OF = 0` runs the edge
    /// against its curve.
    pub fn loop508(&mut self, e: &Entity, place: &Transform, param_ok: bool) -> Mapped<LoopSource> {
        if e.entity_type() != 508 {
            return Err(malformed(
                e,
                format!(
                    "is used as a loop, but entity {} is not a 508",
                    e.entity_type()
                ),
            ));
        }
        self.mark(e);
        let n = e.count(1)?;
        let mut pieces = Vec::new();
        let mut k = 2;
        for _ in 0..n {
            let (kind, ndx, of, count) = (e.int(k)?, e.int(k + 2)?, e.int(k + 3)?, e.count(k + 4)?);
            let reversed = of == 0;
            if param_ok && count > 0 {
                if kind == 0 {
                    let list = self.follow(e, k + 1)?;
                    let curve = self.edge_curve(list, ndx)?;
                    self.mark_tree(curve);
                }
                let start = pieces.len();
                for j in 0..count {
                    let c = self.follow_kind(e, k + 6 + 2 * j, &CURVES, "a curve")?;
                    pieces.extend(forward(
                        self.curve(c, &Transform::IDENTITY, 1)?,
                        true,
                        false,
                    ));
                }
                if reversed {
                    reverse_tail(&mut pieces, start);
                }
            } else if kind == 0 {
                for j in 0..count {
                    let p = self.follow(e, k + 6 + 2 * j)?;
                    self.mark_tree(p);
                }
                let list = self.follow(e, k + 1)?;
                let curve = self.edge_curve(list, ndx)?;
                pieces.extend(forward(self.curve(curve, place, 1)?, false, reversed));
            } else {
                let vertex = self.follow(e, k + 1)?;
                self.mark_tree(vertex);
            }
            k += 5 + 2 * count;
        }
        Ok(LoopSource { pieces })
    }

    /// An optional curve pointer, checked to lead to a curve.
    fn kind_optional(&mut self, e: &Entity, k: usize) -> Mapped<Option<&'a Entity>> {
        match e.optional_pointer(k)? {
            None => Ok(None),
            Some(_) => self.follow_kind(e, k, &CURVES, "a curve").map(Some),
        }
    }

    /// The model curve of edge `ndx` (1-based) of edge list `list` (504).
    fn edge_curve(&mut self, list: &Entity, ndx: i64) -> Mapped<&'a Entity> {
        if list.entity_type() != 504 {
            return Err(malformed(list, "is used as an edge list, but is not a 504"));
        }
        let n = list.count(1)?;
        let i = usize::try_from(ndx)
            .ok()
            .filter(|&i| (1..=n).contains(&i))
            .ok_or_else(|| malformed(list, format!("has no edge {ndx} (it has {n})")))?;
        self.follow_kind(list, 2 + 5 * (i - 1), &CURVES, "a curve")
    }
}

/// Reverses the order and direction of `pieces[start..]` (one model edge's parameter curves).
fn reverse_tail(pieces: &mut [Piece], start: usize) {
    if let Some(tail) = pieces.get_mut(start..) {
        tail.reverse();
        for p in tail {
            p.reversed = !p.reversed;
        }
    }
}
