//! Validated, classified trim regions and the point query.
//!
//! Building: each loop is assembled ([`super::loops`]), all loops are checked for crossings
//! (`crossings.rs`), then classified by nesting depth (the number of other loops around
//! one of its points that is off every other loop): depth 0 bounds a region, 1 is a hole, 2 an
//! island in that hole, and so on. Loops are normalised so that regions run counter-clockwise and
//! holes clockwise; the winding number (ray casting to +u) is then 1 inside and 0 outside.
//!
//! Point queries use horizontal slabs: every segment is listed in the slabs its v-range meets, so
//! a query only visits the segments of one slab.

use glam::DVec2;

use super::crossings::{Segments, find_contacts, resolve_contacts};
use super::error::TrimError;
use super::grid::{SegGrid, cell_index};
use super::loops::{Limits, LoopInput, Role, Tolerances, bounds, build_polygon, signed_area};

/// Most segments all loops of one surface may have together: keeps every index and count of the
/// acceleration structures well inside 32 bits.
pub const MAX_TOTAL_SEGMENTS: usize = 1 << 26;

/// One normalised loop: a closed polygon (first point not repeated), counter-clockwise for an
/// outer boundary, clockwise for a hole.
#[derive(Clone, Debug, PartialEq)]
pub struct TrimLoop {
    points: Vec<DVec2>,
    depth: usize,
    parent: Option<usize>,
}

impl TrimLoop {
    /// The polygon's vertices; the last connects back to the first.
    #[must_use]
    pub fn points(&self) -> &[DVec2] {
        &self.points
    }

    /// Nesting depth: how many loops enclose this one.
    #[must_use]
    pub fn depth(&self) -> usize {
        self.depth
    }

    /// [`Role::Outer`] at even depth, [`Role::Hole`] at odd depth.
    #[must_use]
    pub fn role(&self) -> Role {
        if self.depth.is_multiple_of(2) {
            Role::Outer
        } else {
            Role::Hole
        }
    }

    /// The innermost loop enclosing this one (for a hole, the outer loop of its region).
    #[must_use]
    pub fn parent(&self) -> Option<usize> {
        self.parent
    }

    /// Signed area: positive for an outer loop, negative for a hole.
    #[must_use]
    pub fn signed_area(&self) -> f64 {
        signed_area(&self.points)
    }
}

/// Segment ids bucketed by horizontal slabs of the bounding box.
#[derive(Clone, Debug, PartialEq)]
struct Slabs {
    v0: f64,
    scale: f64,
    start: Vec<u32>,
    items: Vec<u32>,
}

impl Slabs {
    /// About one slab per segment, fewer when segments are tall (a comb of long vertical edges
    /// would otherwise be listed in every slab): at most about 5 entries per segment in all.
    #[must_use]
    fn new(ends: &[[DVec2; 2]], v0: f64, v1: f64) -> Self {
        let height = v1 - v0;
        let tall: f64 = ends.iter().map(|s| (s[1].y - s[0].y).abs()).sum::<f64>()
            / height.max(f64::MIN_POSITIVE);
        let per_segment = 4.0 / tall.max(1.0);
        let n = ((ends.len() as f64 * per_segment.min(1.0)) as usize).clamp(1, 1 << 16);
        let scale = if v1 > v0 { n as f64 / height } else { 0.0 };
        let mut slabs = Self {
            v0,
            scale,
            start: vec![0; n + 1],
            items: Vec::new(),
        };
        let range =
            |s: &[DVec2; 2]| slabs.slab(s[0].y.min(s[1].y))..=slabs.slab(s[0].y.max(s[1].y));
        let ranges: Vec<_> = ends.iter().map(range).collect();
        for r in &ranges {
            for k in r.clone() {
                slabs.start[k + 1] += 1;
            }
        }
        for k in 1..=n {
            slabs.start[k] += slabs.start[k - 1];
        }
        let mut fill = slabs.start.clone();
        slabs.items = vec![0; slabs.start[n] as usize];
        for (id, r) in ranges.into_iter().enumerate() {
            for k in r {
                slabs.items[fill[k] as usize] = id as u32;
                fill[k] += 1;
            }
        }
        slabs
    }

    /// The slab of `v`: monotone in `v`, so a segment whose v-range contains `v` is listed in it.
    #[must_use]
    fn slab(&self, v: f64) -> usize {
        cell_index((v - self.v0) * self.scale, self.start.len() - 1)
    }

    #[must_use]
    fn at(&self, v: f64) -> &[u32] {
        let k = self.slab(v);
        self.items
            .get(self.start[k] as usize..self.start[k + 1] as usize)
            .unwrap_or(&[])
    }
}

/// Where segment `a`–`b` crosses the horizontal line at `v`, and its direction (+1 upwards):
/// half-open in v, so a chain through a vertex on the line counts once. Every inside test of the
/// module goes through this one function, so they agree exactly.
#[inline]
#[must_use]
pub(crate) fn crossing(a: DVec2, b: DVec2, v: f64) -> Option<(f64, i32)> {
    if (a.y <= v) == (b.y <= v) {
        return None;
    }
    let u = a.x + (v - a.y) * (b.x - a.x) / (b.y - a.y);
    Some((u, if b.y > a.y { 1 } else { -1 }))
}

/// Trimmed domain of one surface: validated, classified, normalised loops with a point query.
#[derive(Clone, Debug, PartialEq)]
pub struct TrimRegions {
    loops: Vec<TrimLoop>,
    domain: [(f64, f64); 2],
    lo: DVec2,
    hi: DVec2,
    segs: Segments,
    slabs: Slabs,
}

impl TrimRegions {
    /// Builds the regions of `inputs` (see the module doc; the rules are in [`super::loops`])
    /// on the parameter `domain` `[(u0, u1), (v0, v1)]`. Loop `k` of the result is input `k`.
    pub fn new(
        inputs: &[LoopInput],
        domain: [(f64, f64); 2],
        tol: &Tolerances,
    ) -> Result<Self, TrimError> {
        let lim = Limits::new(domain, tol)?;
        if inputs.is_empty() {
            return Err(TrimError::NoLoops);
        }
        let mut polys = Vec::with_capacity(inputs.len());
        for (k, input) in inputs.iter().enumerate() {
            polys.push(build_polygon(k, input, &lim)?);
        }
        if polys.iter().map(Vec::len).sum::<usize>() > MAX_TOTAL_SEGMENTS {
            return Err(TrimError::TooManyLoopSegments {
                limit: MAX_TOTAL_SEGMENTS,
            });
        }
        let segs = Segments::new(&polys);
        let (lo, hi) = bounds(&polys.concat());
        let grid = SegGrid::new(&segs.ends, lo, hi, lim.gap);
        let contacts = find_contacts(&segs, &grid, lim.gap)?;
        let slabs = Slabs::new(&segs.ends, lo.y, hi.y);
        let loop_winding = |l: usize, p: DVec2| winding(&segs, &slabs, p, Some(l));
        resolve_contacts(&segs, &polys, &contacts, loop_winding)?;
        let (depths, parents) = nesting(&segs, &slabs, &grid, &polys, lim.gap)?;
        let mut loops = Vec::with_capacity(polys.len());
        for (k, mut points) in polys.into_iter().enumerate() {
            let (depth, parent) = (depths[k], parents[k]);
            check_role(k, inputs[k].role, depth, parent)?;
            if (signed_area(&points) > 0.0) != depth.is_multiple_of(2) {
                points.reverse();
            }
            loops.push(TrimLoop {
                points,
                depth,
                parent,
            });
        }
        let all: Vec<Vec<DVec2>> = loops.iter().map(|l| l.points.clone()).collect();
        let segs = Segments::new(&all);
        let slabs = Slabs::new(&segs.ends, lo.y, hi.y);
        Ok(Self {
            loops,
            domain,
            lo,
            hi,
            segs,
            slabs,
        })
    }

    /// The normalised loops, in input order.
    #[must_use]
    pub fn loops(&self) -> &[TrimLoop] {
        &self.loops
    }

    /// The parameter domain the regions were built on.
    #[must_use]
    pub fn domain(&self) -> [(f64, f64); 2] {
        self.domain
    }

    /// Bounding box of all loops, `(min, max)`.
    #[must_use]
    pub fn bounds(&self) -> (DVec2, DVec2) {
        (self.lo, self.hi)
    }

    /// Parameter-space area of the trimmed domain (exact for the polygons).
    #[must_use]
    pub fn area(&self) -> f64 {
        self.loops.iter().map(TrimLoop::signed_area).sum()
    }

    /// Number of boundary segments over all loops.
    #[must_use]
    pub fn segment_count(&self) -> usize {
        self.segs.ends.len()
    }

    /// Segment `id` (ids run loop after loop, in each loop's order), oriented as its loop.
    #[must_use]
    pub fn segment(&self, id: usize) -> Option<[DVec2; 2]> {
        self.segs.ends.get(id).copied()
    }

    /// Whether `p` is inside the trimmed domain: winding number > 0 with the normalised loops.
    /// A point exactly on the boundary falls by the half-open ray-casting rule: on a left or
    /// bottom edge of the trimmed domain it is inside, on a right or top edge outside (so a
    /// trim equal to the domain's box leaves the last row and column of samples outside).
    #[must_use]
    pub fn contains(&self, p: DVec2) -> bool {
        self.in_bounds(p) && winding(&self.segs, &self.slabs, p, None) > 0
    }

    /// The bounding-box test `contains` starts with (shared with the grid sweep).
    #[must_use]
    pub(crate) fn in_bounds(&self, p: DVec2) -> bool {
        p.cmpge(self.lo).all() && p.cmple(self.hi).all()
    }

    /// All crossings of the horizontal line at `v` with the boundary, `(u, direction)` unsorted,
    /// computed exactly as in [`TrimRegions::contains`].
    pub(crate) fn crossings_at(&self, v: f64, out: &mut Vec<(f64, i32)>) {
        out.clear();
        for &id in self.slabs.at(v) {
            let [a, b] = self.segs.ends[id as usize];
            out.extend(crossing(a, b, v));
        }
    }
}

/// Winding number at `p` of loop `only`, or of all loops (ray casting to +u through the slab).
#[must_use]
fn winding(segs: &Segments, slabs: &Slabs, p: DVec2, only: Option<usize>) -> i32 {
    let mut w = 0;
    for &id in slabs.at(p.y) {
        let id = id as usize;
        if only.is_some_and(|l| segs.loop_of[id] as usize != l) {
            continue;
        }
        let [a, b] = segs.ends[id];
        if let Some((u, dir)) = crossing(a, b, p.y)
            && u > p.x
        {
            w += dir;
        }
    }
    w
}

/// Depth and parent of every loop, from the windings of all loops at one point of each loop
/// that lies farther than `gap` from every other loop (the loops do not cross, so one point
/// decides).
fn nesting(
    segs: &Segments,
    slabs: &Slabs,
    grid: &SegGrid,
    polys: &[Vec<DVec2>],
    gap: f64,
) -> Result<(Vec<usize>, Vec<Option<usize>>), TrimError> {
    let n = polys.len();
    let mut inside: Vec<Vec<usize>> = Vec::with_capacity(n);
    let mut w = vec![0i32; n];
    for (l, pts) in polys.iter().enumerate() {
        let clear = |p: DVec2| {
            grid.near(p).iter().all(|&id| {
                let id = id as usize;
                let [a, b] = segs.ends[id];
                segs.loop_of[id] as usize == l
                    || super::curve::point_segment_distance(p, a, b) > gap
            })
        };
        let Some(&p) = pts.iter().find(|&&p| clear(p)) else {
            let mut others = grid
                .near(pts[0])
                .iter()
                .map(|&id| segs.loop_of[id as usize] as usize);
            let other = others.find(|&m| m != l).unwrap_or(l);
            return Err(TrimError::LoopsOverlap {
                first: l.min(other),
                second: l.max(other),
                point: pts[0],
            });
        };
        // Windings of the loops crossing this slab only: cost independent of the loop count.
        let mut crossed: Vec<usize> = Vec::new();
        for &id in slabs.at(p.y) {
            let [a, b] = segs.ends[id as usize];
            if let Some((u, dir)) = crossing(a, b, p.y)
                && u > p.x
            {
                let m = segs.loop_of[id as usize] as usize;
                w[m] += dir;
                crossed.push(m);
            }
        }
        crossed.sort_unstable();
        crossed.dedup();
        inside.push(
            crossed
                .iter()
                .copied()
                .filter(|&m| m != l && w[m] != 0)
                .collect(),
        );
        crossed.iter().for_each(|&m| w[m] = 0);
    }
    let depths: Vec<usize> = inside.iter().map(Vec::len).collect();
    let parents = inside
        .iter()
        .map(|around| around.iter().copied().max_by_key(|&m| depths[m]))
        .collect();
    Ok((depths, parents))
}

/// A declared role must agree with the nesting.
fn check_role(
    loop_index: usize,
    role: Option<Role>,
    depth: usize,
    parent: Option<usize>,
) -> Result<(), TrimError> {
    match (role, parent) {
        (Some(Role::Hole), None) => Err(TrimError::HoleOutside { loop_index }),
        (Some(Role::Hole), Some(parent)) if depth.is_multiple_of(2) => {
            Err(TrimError::HoleInHole { loop_index, parent })
        }
        (Some(Role::Outer), Some(parent)) if depth % 2 == 1 => {
            Err(TrimError::OuterInOuter { loop_index, parent })
        }
        _ => Ok(()),
    }
}
