//! Retained redraw: during a gesture, what it cannot change is drawn once into the target's
//! static layer; each frame restores it and draws only the dynamic set.
//!
//! Why a retained frame equals a full redraw bit for bit (MSAA 1): surfaces are opaque and
//! drawn with depth test LESS_OR_EQUAL, so a pixel ends up with the *last* of the fragments of
//! least depth, in draw order. The full order is P (surfaces before the dragged one), O (the
//! dragged surface, its cells row by row), Q (surfaces after it); then lines and points (L),
//! then overlays, drawn in every frame in both modes.
//! - The layer holds P, O's static cells and Q in that order; the dynamic cells D are drawn
//!   after it. Against P, D comes later in both orders, so ties go to D in both.
//! - Against Q, D comes *earlier* in the full order: a Q fragment tying D must win. So every
//!   frame also draws again, clipped to the screen rectangle of D's fragments, each Q surface
//!   whose screen rectangle meets it, in order. Inside the rectangle every Q fragment is then
//!   drawn after D (ties go to Q, as in full) and after the other Q fragments it follows in
//!   full order (drawing a fragment again over its own result changes nothing); outside it
//!   D draws nothing and the layer is the full redraw's image.
//! - O's static and dynamic cells share their edge vertices bit for bit, so the rasteriser's
//!   fill rule gives each pixel of a shared edge to one triangle only: they meet at a tie
//!   only where the surface folds onto itself with equal depth, the one case this leaves to
//!   draw order within O.
//!
//! Lines and points: the layer has two saves, the surfaces above (S) and S with all of L drawn
//! over it (SL). Let R be a pixel rectangle holding the dynamic cells' fragments and those of
//! every line or point through a control vertex that moves, both as drawn now and as SL holds
//! them. Outside R no fragment differs from the full redraw's, so SL is its image there. Inside
//! R a frame copies S back and draws the surfaces as above, then every line and point draw that
//! reaches R in full order, clipped to R: a full redraw of R. (A draw left out has no fragment
//! in R; of the dragged surface's net only rows and columns that reach R are drawn, which
//! changes no pixel because its segments are one colour and its points still follow them in
//! order.) Points are drawn without depth test, so order matters between every line and point
//! draw: that is why R is redrawn in full order and not only the moving parts.

use super::lod::Lod;
use super::map_mirror::MapView;
use super::style::ViewOptions;
use crate::editor::{ControlLayout, LOCAL_CURVE_SAMPLES, LOCAL_PATCH_SAMPLES};
use crate::gpu::{Camera, GridShape, GridStride};
use crate::model::{Index2, Target};
use crate::sampling::{DirtyRegion, DirtySet, SampleGrid};
use glam::{DVec3, Vec4};
use std::ops::Range;

/// How frames are drawn while a gesture runs (`--redraw`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Redraw {
    /// From the static layer, drawing only what the gesture moves.
    #[default]
    Retained,
    /// Every object, every frame (the reference).
    Full,
}

impl Redraw {
    /// Parses `retained` or `full`.
    pub fn parse(s: &str) -> Result<Self, String> {
        match s {
            "retained" => Ok(Self::Retained),
            "full" => Ok(Self::Full),
            _ => Err(format!("--redraw takes retained or full, not {s:?}")),
        }
    }

    /// The option's value.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Retained => "retained",
            Self::Full => "full",
        }
    }
}

/// A gesture in progress: what moves, known before it does.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gesture {
    pub object: usize,
    pub target: Target,
}

/// Samples per chunk side, in the cells of the drawn (strided) mesh.
pub const CHUNK: usize = 32;

/// Everything a static layer's pixels depend on besides the samples (which
/// [`super::GpuScene::consume`] watches): when any differs, the layer is stale.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct LayerKey {
    pub camera: Camera,
    pub clear: [f32; 4],
    pub viewport: [u32; 4],
    pub extent: [u32; 2],
    pub opts: ViewOptions,
    pub lod: Option<Lod>,
    pub map: Option<MapView>,
    /// Whether the curvature map's scalars were built (before, plain shading stands in).
    pub scalars: bool,
    pub objects: usize,
    /// The gesture the layer leaves out.
    pub gesture: Gesture,
    /// Hovered and selected handles and locals: they colour and size points and nets drawn
    /// in the layer.
    pub highlight: super::style::Highlight,
    /// The stride the dragged surface is drawn at (frozen for the gesture).
    pub stride: Option<GridStride>,
}

/// The dragged surface's triangles split into the dynamic chunks and the rest, as index ranges
/// (first, count) of its strided triangle list, in draw order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SplitCells {
    pub dynamic: Vec<(u32, u32)>,
    pub fixed: Vec<(u32, u32)>,
    /// Sample rectangles (rows, cols) of the dynamic chunks, for their screen bounds.
    pub chunks: Vec<[Range<usize>; 2]>,
}

/// The rows (or columns) the strided mesh draws: `0, step, 2·step, …` and the last.
fn drawn_lines(n: usize, step: usize) -> Vec<usize> {
    let mut v: Vec<usize> = (0..n).step_by(step.max(1)).collect();
    if n > 0 && v.last() != Some(&(n - 1)) {
        v.push(n - 1);
    }
    v
}

/// Cells (between consecutive drawn lines `lines`) that contain a sample of `samples`.
fn cells_of(lines: &[usize], samples: &Range<usize>) -> Option<Range<usize>> {
    if samples.is_empty() || lines.len() < 2 {
        return None;
    }
    let cells = lines.len() - 1;
    let lo = (0..cells).find(|&i| lines[i + 1] >= samples.start)?;
    let hi = (0..cells).rev().find(|&i| lines[i] < samples.end)?;
    (lo <= hi).then_some(lo..hi + 1)
}

/// Splits a `shape` surface drawn at `stride` into the chunks that contain samples of
/// `support` and the rest. `drop_one` leaves the first dynamic chunk out of the dynamic set
/// (a negative control for tests: its old pixels stay in the layer).
#[must_use]
pub fn split_cells(
    shape: GridShape,
    stride: GridStride,
    support: &[DirtyRegion],
    drop_one: bool,
) -> SplitCells {
    let stride = stride.normalized();
    let rows = drawn_lines(shape.rows as usize, stride.rows as usize);
    let cols = drawn_lines(shape.cols as usize, stride.cols as usize);
    let (nr, nc) = (rows.len().saturating_sub(1), cols.len().saturating_sub(1));
    let (kr, kc) = (nr.div_ceil(CHUNK), nc.div_ceil(CHUNK));
    let mut marked = vec![false; kr * kc];
    for region in support {
        let (Some(r), Some(c)) = (cells_of(&rows, &region.rows), cells_of(&cols, &region.cols))
        else {
            continue;
        };
        for i in r.start / CHUNK..=(r.end - 1) / CHUNK {
            for j in c.start / CHUNK..=(c.end - 1) / CHUNK {
                marked[i * kc + j] = true;
            }
        }
    }
    if drop_one && let Some(first) = marked.iter().position(|&m| m) {
        marked[first] = false;
    }
    let mut split = SplitCells::default();
    for i in 0..kr {
        for j in 0..kc {
            if marked[i * kc + j] {
                let (r0, r1) = (i * CHUNK, ((i + 1) * CHUNK).min(nr));
                let (c0, c1) = (j * CHUNK, ((j + 1) * CHUNK).min(nc));
                split
                    .chunks
                    .push([rows[r0]..rows[r1] + 1, cols[c0]..cols[c1] + 1]);
            }
        }
    }
    for cell_row in 0..nr {
        let i = cell_row / CHUNK;
        for j in 0..kc {
            let (c0, c1) = (j * CHUNK, ((j + 1) * CHUNK).min(nc));
            let first = ((cell_row * nc + c0) * 6) as u32;
            let count = ((c1 - c0) * 6) as u32;
            let list = if marked[i * kc + j] {
                &mut split.dynamic
            } else {
                &mut split.fixed
            };
            match list.last_mut() {
                Some(last) if last.0 + last.1 == first => last.1 += count,
                _ => list.push((first, count)),
            }
        }
    }
    split
}

/// World-space bounds of the samples of `grid` in `rects` (all of it for `None`).
#[must_use]
pub fn sample_bounds(grid: &SampleGrid, rects: Option<&[[Range<usize>; 2]]>) -> Option<[DVec3; 2]> {
    let [rows, cols] = grid.dims;
    let stride = grid.stride();
    let whole = [[0..rows, 0..cols]];
    let rects = rects.unwrap_or(&whole);
    let mut b: Option<[DVec3; 2]> = None;
    for [r, c] in rects {
        for i in r.start..r.end.min(rows) {
            for j in c.start..c.end.min(cols) {
                let p = grid.data[(i * cols + j) * stride];
                b = Some(match b {
                    Some([lo, hi]) => [lo.min(p), hi.max(p)],
                    None => [p, p],
                });
            }
        }
    }
    b
}

/// The pixel rectangle `[x, y, width, height]` of `viewport` that a box's projection can
/// touch, with a margin for rasterisation; the whole viewport when the box reaches behind the
/// eye or is not finite.
#[must_use]
pub fn screen_rect(camera: &Camera, bounds: [DVec3; 2], viewport: [u32; 4]) -> [u32; 4] {
    screen_rect_with(camera, bounds, viewport, 2.0)
}

/// [`screen_rect`] with a margin of `margin` pixels (for lines and points drawn wider than a
/// pixel around their vertices).
#[must_use]
pub fn screen_rect_with(
    camera: &Camera,
    bounds: [DVec3; 2],
    viewport: [u32; 4],
    margin: f32,
) -> [u32; 4] {
    let [lo, hi] = bounds;
    let mut ndc_lo = [f32::INFINITY; 2];
    let mut ndc_hi = [f32::NEG_INFINITY; 2];
    for k in 0..8 {
        let p = DVec3::new(
            if k & 1 == 0 { lo.x } else { hi.x },
            if k & 2 == 0 { lo.y } else { hi.y },
            if k & 4 == 0 { lo.z } else { hi.z },
        )
        .as_vec3();
        let c = camera.view_proj * Vec4::new(p.x, p.y, p.z, 1.0);
        // Also catches a NaN w (every comparison with NaN is false).
        if c.w.partial_cmp(&1e-6) != Some(std::cmp::Ordering::Greater) || !c.is_finite() {
            return viewport;
        }
        for a in 0..2 {
            let v = c[a] / c.w;
            ndc_lo[a] = ndc_lo[a].min(v);
            ndc_hi[a] = ndc_hi[a].max(v);
        }
    }
    let [vx, vy, vw, vh] = viewport;
    let (w, h) = (vw as f32, vh as f32);
    let margin = margin.max(2.0);
    // y grows downwards on screen: NDC y = 1 is the top row.
    let x0 = (ndc_lo[0] + 1.0) * 0.5 * w - margin;
    let x1 = (ndc_hi[0] + 1.0) * 0.5 * w + margin;
    let y0 = (1.0 - ndc_hi[1]) * 0.5 * h - margin;
    let y1 = (1.0 - ndc_lo[1]) * 0.5 * h + margin;
    let clamp = |v: f32, max: u32| v.floor().clamp(0.0, max as f32) as u32;
    let (x0, x1) = (clamp(x0, vw), clamp(x1.ceil(), vw));
    let (y0, y1) = (clamp(y0, vh), clamp(y1.ceil(), vh));
    [vx + x0, vy + y0, x1 - x0, y1 - y0]
}

/// Whether two pixel rectangles share a pixel.
#[must_use]
pub fn overlaps(a: [u32; 4], b: [u32; 4]) -> bool {
    a[0] < b[0] + b[2] && b[0] < a[0] + a[2] && a[1] < b[1] + b[3] && b[1] < a[1] + a[3]
}

/// The smallest pixel rectangle holding both (an empty one adds nothing).
#[must_use]
pub fn union_rect(a: [u32; 4], b: [u32; 4]) -> [u32; 4] {
    if a[2] == 0 || a[3] == 0 {
        return b;
    }
    if b[2] == 0 || b[3] == 0 {
        return a;
    }
    let (x0, y0) = (a[0].min(b[0]), a[1].min(b[1]));
    let x1 = (a[0] + a[2]).max(b[0] + b[2]);
    let y1 = (a[1] + a[3]).max(b[1] + b[3]);
    [x0, y0, x1 - x0, y1 - y0]
}

/// The control display vertices a gesture on `target` rewrites, as far as the layout tells
/// before it does (an edit that rewrites others makes the layer stale; see
/// [`super::GpuScene::consume`]).
#[must_use]
pub fn moving_vertices(layout: &ControlLayout, target: Target) -> DirtySet {
    let mut set = DirtySet::default();
    match (layout, target) {
        (ControlLayout::Polygon { count }, Target::Point(Index2::One(k))) if k < *count => {
            set.insert(k..k + 1);
        }
        (ControlLayout::Net { rows, cols }, Target::Point(Index2::Two(i, j)))
            if i < *rows && j < *cols =>
        {
            set.insert(i * cols + j..i * cols + j + 1);
        }
        (
            ControlLayout::LocalCurves(entries) | ControlLayout::LocalPatches(entries),
            Target::Local(local),
        ) => {
            for e in entries.iter().filter(|e| e.path.starts_with(&local)) {
                set.insert(e.samples..e.samples + entry_samples(layout));
                set.insert(e.points..e.points + e.rows * e.cols);
            }
        }
        _ => {}
    }
    set
}

/// Display sample vertices of one ERBS local (patches store a normal after each position).
fn entry_samples(layout: &ControlLayout) -> usize {
    match layout {
        ControlLayout::LocalPatches(_) => 2 * LOCAL_PATCH_SAMPLES * LOCAL_PATCH_SAMPLES,
        _ => LOCAL_CURVE_SAMPLES,
    }
}

/// The vertices of every line and point drawn through a vertex of `moving`: its neighbours
/// in the polygon or net, the whole local for ERBS locals (their wires, nets and points).
#[must_use]
pub fn touched_vertices(layout: &ControlLayout, moving: &DirtySet) -> DirtySet {
    let mut set = DirtySet::default();
    let hit = |r: &Range<usize>| {
        moving
            .ranges()
            .iter()
            .any(|m| m.start < r.end && r.start < m.end)
    };
    match layout {
        ControlLayout::Polygon { count } => {
            for m in moving.ranges() {
                set.insert(m.start.saturating_sub(1)..(m.end + 1).min(*count));
            }
        }
        ControlLayout::Net { rows, cols } => {
            for k in moving.ranges().iter().flat_map(|m| m.clone()) {
                let (i, j) = (k / cols, k % cols);
                set.insert(k..k + 1);
                if i > 0 {
                    set.insert(k - cols..k - cols + 1);
                }
                if i + 1 < *rows {
                    set.insert(k + cols..k + cols + 1);
                }
                if j > 0 {
                    set.insert(k - 1..k);
                }
                if j + 1 < *cols {
                    set.insert(k + 1..k + 2);
                }
            }
        }
        ControlLayout::LocalCurves(entries) | ControlLayout::LocalPatches(entries) => {
            for e in entries {
                let samples = e.samples..e.samples + entry_samples(layout);
                let points = e.points..e.points + e.rows * e.cols;
                if hit(&samples) || hit(&points) {
                    set.insert(samples);
                    set.insert(points);
                }
            }
        }
    }
    set
}

/// Whether `set` holds every index of `r`.
#[must_use]
pub fn covers(set: &DirtySet, r: &Range<usize>) -> bool {
    r.is_empty()
        || set
            .ranges()
            .iter()
            .any(|s| s.start <= r.start && r.end <= s.end)
}

/// World-space bounds of `vertices` at the indices of `set` (patch normals among them only
/// make the box larger).
#[must_use]
pub fn vertex_bounds(vertices: &[DVec3], set: &DirtySet) -> Option<[DVec3; 2]> {
    let mut b: Option<[DVec3; 2]> = None;
    for r in set.ranges() {
        for &p in vertices.get(r.clone()).unwrap_or(&[]) {
            b = Some(match b {
                Some([lo, hi]) => [lo.min(p), hi.max(p)],
                None => [p, p],
            });
        }
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_support_marks_the_chunks_it_reaches_and_the_rest_stays_static() {
        let shape = GridShape {
            rows: 100,
            cols: 70,
        };
        let support = [DirtyRegion::surface(40..50, 10..12)];
        let s = split_cells(shape, GridStride::FULL, &support, false);
        // Rows 40..50 are cells 39..49: chunk row 1; columns 10..12: cells 9..11, chunk 0.
        assert_eq!(s.chunks, vec![[32..65, 0..33]]);
        let count = |v: &[(u32, u32)]| v.iter().map(|r| r.1).sum::<u32>();
        assert_eq!(count(&s.dynamic), 32 * 32 * 6);
        assert_eq!(count(&s.dynamic) + count(&s.fixed), 99 * 69 * 6);
        // A sample on a chunk boundary belongs to the cells on both sides.
        let edge = split_cells(
            shape,
            GridStride::FULL,
            &[DirtyRegion::surface(32..33, 0..1)],
            false,
        );
        assert_eq!(edge.chunks.len(), 2);
        let none = split_cells(shape, GridStride::FULL, &support, true);
        assert!(none.dynamic.is_empty());
    }

    #[test]
    fn strided_cells_cover_the_support() {
        let shape = GridShape { rows: 10, cols: 10 };
        let stride = GridStride { rows: 4, cols: 4 };
        // Drawn rows 0, 4, 8, 9: sample 9 lies in cell 2 only.
        let s = split_cells(shape, stride, &[DirtyRegion::surface(9..10, 0..1)], false);
        assert_eq!(s.chunks, vec![[0..10, 0..10]]);
        assert_eq!(s.dynamic, vec![(0, 9 * 6)]);
    }

    #[test]
    fn screen_rects_contain_the_projection() {
        let camera = Camera {
            view_proj: glam::Mat4::IDENTITY,
            eye: glam::Vec3::ZERO,
        };
        let r = screen_rect(
            &camera,
            [DVec3::new(-0.5, 0.0, 0.1), DVec3::new(0.0, 0.5, 0.2)],
            [0, 0, 100, 100],
        );
        assert_eq!(r, [23, 23, 29, 29]);
        assert!(overlaps(r, [50, 50, 10, 10]));
        assert!(!overlaps(r, [52, 0, 10, 100]));
    }

    #[test]
    fn a_moving_net_point_touches_its_four_neighbours_only() {
        let layout = ControlLayout::Net { rows: 3, cols: 4 };
        let moving = moving_vertices(&layout, Target::Point(Index2::Two(1, 0)));
        assert_eq!(moving.ranges().to_vec(), vec![4..5]);
        let touched = touched_vertices(&layout, &moving);
        // (0,0), (1,0), (1,1), (2,0): no left neighbour on column 0.
        assert_eq!(touched.ranges(), &[0..1, 4..6, 8..9]);
        assert!(covers(&touched, &(4..6)));
        assert!(!covers(&touched, &(3..5)));
        let polygon = ControlLayout::Polygon { count: 5 };
        let m = moving_vertices(&polygon, Target::Point(Index2::One(4)));
        assert_eq!(touched_vertices(&polygon, &m).ranges().to_vec(), vec![3..5]);
        // A weight moves no control point.
        assert!(moving_vertices(&polygon, Target::Weight(Index2::One(4))).is_empty());
    }

    #[test]
    fn rectangles_join_and_an_empty_one_adds_nothing() {
        assert_eq!(union_rect([0, 0, 0, 0], [5, 6, 7, 8]), [5, 6, 7, 8]);
        assert_eq!(union_rect([1, 2, 3, 4], [5, 6, 7, 8]), [1, 2, 11, 12]);
        let bounds = vertex_bounds(
            &[DVec3::ZERO, DVec3::ONE, DVec3::splat(-3.0)],
            &DirtySet::all(2),
        );
        assert_eq!(bounds, Some([DVec3::ZERO, DVec3::ONE]));
    }
}
