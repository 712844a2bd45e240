//! Crossing tests: a loop crossing itself or another loop is an error, touching is not.
//!
//! Candidate pairs come from a uniform bucket grid (each segment in every cell it passes within
//! the gap tolerance of, see [`super::grid`]), sorted by x within a cell and swept, so the cost
//! is about linear in the number of segments for loops of tens of thousands of segments.
//!
//! A pair whose segments cross with every endpoint farther than the tolerance from the other
//! segment's line is a crossing. A pair closer than the tolerance is a *contact*, to be judged
//! by its neighbourhood, since CAD faces let loops touch at a vertex: along each loop, the
//! maximal runs of consecutive segments in contact are found; their outer endpoints lie farther
//! than the tolerance from the other loop. For two loops, a run whose two outer endpoints lie on
//! different sides of the other loop (winding number) crosses it. For a loop touching itself, the
//! two runs at a contact cross when their four arms interleave around the contact point.

use std::f64::consts::TAU;

use glam::DVec2;

use super::curve::point_segment_distance;
use super::error::TrimError;
use super::grid::SegGrid;

/// All segments of all loops, numbered loop after loop.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Segments {
    pub ends: Vec<[DVec2; 2]>,
    pub loop_of: Vec<u32>,
    /// First segment id of each loop, and the total at the end.
    pub first: Vec<usize>,
}

impl Segments {
    #[must_use]
    pub(crate) fn new(loops: &[Vec<DVec2>]) -> Self {
        let mut s = Self {
            ends: Vec::new(),
            loop_of: Vec::new(),
            first: vec![0],
        };
        for (l, pts) in loops.iter().enumerate() {
            for (k, &p) in pts.iter().enumerate() {
                let q = pts.get(k + 1).or(pts.first()).copied().unwrap_or(p);
                s.ends.push([p, q]);
                s.loop_of.push(l as u32);
            }
            s.first.push(s.ends.len());
        }
        s
    }

    #[must_use]
    fn loop_len(&self, l: usize) -> usize {
        self.first[l + 1] - self.first[l]
    }

    /// `(loop, index in loop)` of segment `id`.
    #[must_use]
    fn locate(&self, id: usize) -> (usize, usize) {
        let l = self.loop_of[id] as usize;
        (l, id - self.first[l])
    }

    /// Whether `s` and `t` follow each other in one loop (they share an endpoint by construction).
    #[must_use]
    fn adjacent(&self, s: usize, t: usize) -> bool {
        let ((ls, ks), (lt, kt)) = (self.locate(s), self.locate(t));
        let n = self.loop_len(ls);
        ls == lt && ((ks + 1) % n == kt || (kt + 1) % n == ks)
    }
}

/// Two segments closer than the tolerance, and where.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Contact {
    pub s: usize,
    pub t: usize,
    pub at: DVec2,
}

enum Pair {
    Apart,
    Cross(DVec2),
    Touch(DVec2),
}

/// The relation of segments `a`–`b` and `c`–`d` (both longer than `tol`) under tolerance `tol`.
#[must_use]
fn classify(a: DVec2, b: DVec2, c: DVec2, d: DVec2, tol: f64) -> Pair {
    let (ab, cd) = (b - a, d - c);
    let (lab, lcd) = (ab.length(), cd.length());
    let (dc, dd) = (ab.perp_dot(c - a) / lab, ab.perp_dot(d - a) / lab);
    let (da, db) = (cd.perp_dot(a - c) / lcd, cd.perp_dot(b - c) / lcd);
    let straddle = |x: f64, y: f64| (x > 0.0 && y < 0.0) || (x < 0.0 && y > 0.0);
    if straddle(dc, dd) && straddle(da, db) {
        let at = c + cd * (dc / (dc - dd));
        let clear = [dc, dd, da, db].iter().all(|x| x.abs() > tol);
        return if clear {
            Pair::Cross(at)
        } else {
            Pair::Touch(at)
        };
    }
    let candidates = [(c, a, b), (d, a, b), (a, c, d), (b, c, d)];
    let (dist, at) = candidates
        .iter()
        .map(|&(q, e0, e1)| (point_segment_distance(q, e0, e1), q))
        .fold((f64::INFINITY, a), |m, x| if x.0 < m.0 { x } else { m });
    if dist <= tol {
        Pair::Touch(at)
    } else {
        Pair::Apart
    }
}

/// The error for a crossing of segments `s` and `t` at `point`.
#[must_use]
fn crossing_error(segs: &Segments, s: usize, t: usize, point: DVec2) -> TrimError {
    let (ls, lt) = (segs.loop_of[s] as usize, segs.loop_of[t] as usize);
    if ls == lt {
        TrimError::SelfCrossing {
            loop_index: ls,
            point,
        }
    } else {
        TrimError::LoopsCross {
            first: ls.min(lt),
            second: ls.max(lt),
            point,
        }
    }
}

/// Tests every pair of non-adjacent segments sharing a grid cell; the first crossing (in cell
/// order) is the error, the contacts are returned sorted by `(s, t)` without repeats.
pub(crate) fn find_contacts(
    segs: &Segments,
    grid: &SegGrid,
    tol: f64,
) -> Result<Vec<Contact>, TrimError> {
    let mut contacts = Vec::new();
    let mut order: Vec<(f64, f64, usize)> = Vec::new();
    for cell in 0..grid.cell_count() {
        order.clear();
        order.extend(grid.cell(cell).iter().map(|&id| {
            let [a, b] = segs.ends[id as usize];
            (a.x.min(b.x), a.x.max(b.x), id as usize)
        }));
        order.sort_by(|p, q| p.0.total_cmp(&q.0));
        for (k, &(_, x_hi, s)) in order.iter().enumerate() {
            for &(x_lo, _, t) in &order[k + 1..] {
                if x_lo > x_hi + tol {
                    break;
                }
                if segs.adjacent(s, t) {
                    continue;
                }
                let ([a, b], [c, d]) = (segs.ends[s], segs.ends[t]);
                match classify(a, b, c, d, tol) {
                    Pair::Apart => {}
                    Pair::Cross(at) => return Err(crossing_error(segs, s, t, at)),
                    Pair::Touch(at) => contacts.push(Contact {
                        s: s.min(t),
                        t: s.max(t),
                        at,
                    }),
                }
            }
        }
    }
    contacts.sort_by_key(|c| (c.s, c.t));
    contacts.dedup_by_key(|c| (c.s, c.t));
    Ok(contacts)
}

/// Maximal runs of consecutive indices (cyclic modulo `n`) in the sorted, repeat-free `idx`, as
/// `(first, last)`; `None` when the run covers the whole loop.
#[must_use]
fn runs(idx: &[usize], n: usize) -> Option<Vec<(usize, usize)>> {
    if idx.len() >= n {
        return None;
    }
    let mut out: Vec<(usize, usize)> = Vec::new();
    for &k in idx {
        match out.last_mut() {
            Some(run) if run.1 + 1 == k => run.1 = k,
            _ => out.push((k, k)),
        }
    }
    if out.len() > 1 && out[0].0 == 0 && out.last().is_some_and(|r| r.1 + 1 == n) {
        let first_last = out[0].1;
        out.remove(0);
        if let Some(run) = out.last_mut() {
            run.1 = first_last;
        }
    }
    Some(out)
}

/// Index of the run containing `k`.
#[must_use]
fn run_of(runs: &[(usize, usize)], k: usize) -> Option<usize> {
    runs.iter().position(|&(a, b)| {
        if a <= b {
            a <= k && k <= b
        } else {
            k >= a || k <= b
        }
    })
}

/// Judges the contacts (see the module doc). `winding(l, p)` is loop `l`'s winding number at `p`.
pub(crate) fn resolve_contacts(
    segs: &Segments,
    loops: &[Vec<DVec2>],
    contacts: &[Contact],
    winding: impl Fn(usize, DVec2) -> i32,
) -> Result<(), TrimError> {
    let mut grouped: Vec<(usize, usize, Contact)> = contacts
        .iter()
        .map(|c| {
            let (ls, lt) = (segs.loop_of[c.s] as usize, segs.loop_of[c.t] as usize);
            (ls.min(lt), ls.max(lt), *c)
        })
        .collect();
    grouped.sort_by_key(|g| (g.0, g.1));
    for group in grouped.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        let (la, lb) = (group[0].0, group[0].1);
        let cs: Vec<Contact> = group.iter().map(|g| g.2).collect();
        if la == lb {
            self_contacts(segs, &loops[la], la, &cs)?;
        } else {
            pair_contacts(segs, loops, (la, lb), &cs, &winding)?;
            pair_contacts(segs, loops, (lb, la), &cs, &winding)?;
        }
    }
    Ok(())
}

/// Loop `b`'s runs in contact with loop `a`: each must enter and leave on the same side of `a`.
fn pair_contacts(
    segs: &Segments,
    loops: &[Vec<DVec2>],
    (a, b): (usize, usize),
    cs: &[Contact],
    winding: &impl Fn(usize, DVec2) -> i32,
) -> Result<(), TrimError> {
    let on_b = |c: &Contact| {
        if segs.loop_of[c.s] as usize == b {
            c.s
        } else {
            c.t
        }
    };
    let mut idx: Vec<(usize, DVec2)> = cs.iter().map(|c| (segs.locate(on_b(c)).1, c.at)).collect();
    idx.sort_by_key(|x| x.0);
    idx.dedup_by_key(|x| x.0);
    let n = segs.loop_len(b);
    let keys: Vec<usize> = idx.iter().map(|x| x.0).collect();
    let at = idx.first().map_or(DVec2::ZERO, |x| x.1);
    let (first, second) = (a.min(b), a.max(b));
    let Some(runs) = runs(&keys, n) else {
        return Err(TrimError::LoopsOverlap {
            first,
            second,
            point: at,
        });
    };
    let pts = &loops[b];
    for &(k0, k1) in &runs {
        let (enter, leave) = (pts[k0], pts[(k1 + 1) % n]);
        if (winding(a, enter) != 0) != (winding(a, leave) != 0) {
            let point = idx.iter().find(|x| x.0 == k0).map_or(at, |x| x.1);
            return Err(TrimError::LoopsCross {
                first,
                second,
                point,
            });
        }
    }
    Ok(())
}

/// A loop touching itself: at each contact, the two runs must not interleave.
fn self_contacts(
    segs: &Segments,
    pts: &[DVec2],
    l: usize,
    cs: &[Contact],
) -> Result<(), TrimError> {
    let n = pts.len();
    let mut keys: Vec<usize> = cs
        .iter()
        .flat_map(|c| [segs.locate(c.s).1, segs.locate(c.t).1])
        .collect();
    keys.sort_unstable();
    keys.dedup();
    let Some(runs) = runs(&keys, n) else {
        return Ok(());
    };
    let arms = |r: (usize, usize)| (pts[r.0], pts[(r.1 + 1) % n]);
    for c in cs {
        let (Some(rs), Some(rt)) = (
            run_of(&runs, segs.locate(c.s).1),
            run_of(&runs, segs.locate(c.t).1),
        ) else {
            continue;
        };
        if rs != rt && interleave(c.at, arms(runs[rs]), arms(runs[rt])) {
            return Err(TrimError::SelfCrossing {
                loop_index: l,
                point: c.at,
            });
        }
    }
    Ok(())
}

/// Whether the arms `p`→`f.0`, `p`→`f.1` and `p`→`g.0`, `p`→`g.1` alternate around `p`: then
/// the path through `g` passes from one side of the path through `f` to the other.
#[must_use]
fn interleave(p: DVec2, f: (DVec2, DVec2), g: (DVec2, DVec2)) -> bool {
    let base = f.0 - p;
    let angle = |q: DVec2| {
        let v = q - p;
        let a = base.perp_dot(v).atan2(base.dot(v));
        if a < 0.0 { a + TAU } else { a }
    };
    let split = angle(f.1);
    (angle(g.0) < split) != (angle(g.1) < split)
}
