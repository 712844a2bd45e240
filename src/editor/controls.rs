//! What is drawn and picked of an object besides its samples: its control polygon or net, and
//! for ERBS objects every polynomial local curve or patch at any depth with its control points
//! and a few display samples. Kept per object as display vertices with a layout, updated in
//! place by the edits that move them, so a drag rewrites one vertex and not the net.

use crate::geom::erbs::{ErbsCurve, ErbsSurface};
use crate::geom::knots::uniform_params;
use crate::geom::{LocalCurve as GeomLocalCurve, LocalPatch as GeomLocalPatch};
use crate::model::{Index2, LocalPath, ModelRef, Target};
use crate::sampling::DirtySet;
use glam::DVec3;

use super::applied::ControlsChange;

/// Samples per ERBS local curve drawn in its own colour.
pub const LOCAL_CURVE_SAMPLES: usize = 48;
/// Samples per direction of an ERBS local patch drawn as a wire grid.
pub const LOCAL_PATCH_SAMPLES: usize = 9;

/// Where one polynomial ERBS local's display vertices sit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LocalEntry {
    pub path: LocalPath<Index2>,
    /// First display sample: [`LOCAL_CURVE_SAMPLES`] positions (curves), or
    /// [`LOCAL_PATCH_SAMPLES`]² (position, normal) pairs row-major (patches).
    pub samples: usize,
    /// First control point.
    pub points: usize,
    /// Control points (curves), or net rows (patches).
    pub rows: usize,
    /// 1 (curves), or net columns (patches).
    pub cols: usize,
}

/// How an object's display vertices are laid out.
#[derive(Debug, Clone, PartialEq)]
pub enum ControlLayout {
    /// Control polygon of a curve.
    Polygon { count: usize },
    /// Control net of a tensor surface, row-major.
    Net { rows: usize, cols: usize },
    /// ERBS curve: every polynomial local at any depth, in path order; all display samples
    /// first, then all control points.
    LocalCurves(Vec<LocalEntry>),
    /// ERBS surface: every polynomial local patch at any depth, likewise.
    LocalPatches(Vec<LocalEntry>),
}

/// An object's control display: a layout and its vertices (f64 world coordinates).
#[derive(Debug, Clone, PartialEq)]
pub struct ControlDisplay {
    pub layout: ControlLayout,
    pub vertices: Vec<DVec3>,
}

impl ControlDisplay {
    /// The control display of a model.
    #[must_use]
    pub fn of(model: ModelRef<'_>) -> Self {
        match model {
            ModelRef::Curve(c) => polygon(c.curve().points().to_vec()),
            // The interpolated points.
            ModelRef::CatmullRom(c) => polygon(c.spline().points().to_vec()),
            // Bézier points, or the de Boor polygon of splines edited through it (their Bézier
            // points are drawn as an overlay).
            ModelRef::BezierSpline(c) => polygon(c.spline().handles()),
            ModelRef::Surface(s) => {
                let s = s.surface();
                let [rows, cols] = s.count();
                ControlDisplay {
                    layout: ControlLayout::Net { rows, cols },
                    vertices: s.points().to_vec(),
                }
            }
            ModelRef::ErbsCurve(c) => local_curves(&curve_leaves(c.curve(), None)),
            ModelRef::ErbsSurface(s) => local_patches(&patch_leaves(s.surface(), None)),
        }
    }

    /// Brings the display up to date with `model` after an edit of `target`, rewriting only
    /// what that target moves where the layout allows; says what changed.
    pub fn update(&mut self, model: ModelRef<'_>, target: Target) -> ControlsChange {
        let changed = match target {
            // A weight moves no control point.
            Target::Weight(_) => return ControlsChange::Unchanged,
            Target::Point(p) => self.update_point(model, p),
            Target::Local(l) => self.update_local(model, l),
            Target::Structure => None,
        };
        changed.map_or_else(|| self.refresh(model), ControlsChange::Vertices)
    }

    /// Everything again; `Resized` where the layout changed.
    pub fn refresh(&mut self, model: ModelRef<'_>) -> ControlsChange {
        let new = ControlDisplay::of(model);
        if new.layout == self.layout && new.vertices.len() == self.vertices.len() {
            self.vertices = new.vertices;
            ControlsChange::Vertices(DirtySet::all(self.vertices.len()))
        } else {
            *self = new;
            ControlsChange::Resized
        }
    }

    /// One control point of a polygon or net (a drag must not copy a 10 000-point net).
    fn update_point(&mut self, model: ModelRef<'_>, point: Index2) -> Option<DirtySet> {
        let (index, p) = match (&self.layout, model, point) {
            (ControlLayout::Polygon { count }, ModelRef::Curve(c), Index2::One(k))
                if k < *count =>
            {
                (k, c.curve().points()[k])
            }
            (ControlLayout::Net { rows, cols }, ModelRef::Surface(s), Index2::Two(i, j))
                if i < *rows && j < *cols =>
            {
                (i * cols + j, s.surface().point(i, j))
            }
            _ => return None,
        };
        self.vertices[index] = p;
        let mut set = DirtySet::default();
        set.insert(index..index + 1);
        Some(set)
    }

    /// The polynomial locals at or below one ERBS local: their display samples and points.
    fn update_local(&mut self, model: ModelRef<'_>, local: LocalPath<Index2>) -> Option<DirtySet> {
        let fresh = match model {
            ModelRef::ErbsCurve(c) => local_curves(&curve_leaves(c.curve(), Some(local))),
            ModelRef::ErbsSurface(s) => local_patches(&patch_leaves(s.surface(), Some(local))),
            _ => return None,
        };
        let ((ControlLayout::LocalCurves(old), ControlLayout::LocalCurves(new))
        | (ControlLayout::LocalPatches(old), ControlLayout::LocalPatches(new))) =
            (&self.layout, &fresh.layout)
        else {
            return None;
        };
        let mut set = DirtySet::default();
        for n in new {
            let o = old.iter().find(|o| o.path == n.path)?;
            if (o.rows, o.cols) != (n.rows, n.cols) {
                return None;
            }
            let (s_len, p_len) = (display_samples(&fresh.layout), n.rows * n.cols);
            self.vertices[o.samples..o.samples + s_len]
                .copy_from_slice(&fresh.vertices[n.samples..n.samples + s_len]);
            self.vertices[o.points..o.points + p_len]
                .copy_from_slice(&fresh.vertices[n.points..n.points + p_len]);
            set.insert(o.samples..o.samples + s_len);
            set.insert(o.points..o.points + p_len);
        }
        Some(set)
    }
}

/// Display sample vertices of one local in `layout`.
fn display_samples(layout: &ControlLayout) -> usize {
    match layout {
        ControlLayout::LocalPatches(_) => 2 * LOCAL_PATCH_SAMPLES * LOCAL_PATCH_SAMPLES,
        _ => LOCAL_CURVE_SAMPLES,
    }
}

fn polygon(points: Vec<DVec3>) -> ControlDisplay {
    ControlDisplay {
        layout: ControlLayout::Polygon {
            count: points.len(),
        },
        vertices: points,
    }
}

/// One polynomial local curve's display: its path, control points and samples over its support.
struct LocalCurveDisplay {
    path: LocalPath<Index2>,
    points: Vec<DVec3>,
    samples: Vec<DVec3>,
}

/// One polynomial local patch's display: its path, net and (position, normal) grid.
struct LocalPatchDisplay {
    path: LocalPath<Index2>,
    rows: usize,
    cols: usize,
    points: Vec<DVec3>,
    grid: Vec<(DVec3, DVec3)>,
}

fn local_curves(locals: &[LocalCurveDisplay]) -> ControlDisplay {
    let mut vertices = Vec::new();
    let mut entries = Vec::with_capacity(locals.len());
    for l in locals {
        entries.push(LocalEntry {
            path: l.path,
            samples: vertices.len(),
            points: 0,
            rows: l.points.len(),
            cols: 1,
        });
        vertices.extend_from_slice(&l.samples);
    }
    for (l, e) in locals.iter().zip(entries.iter_mut()) {
        e.points = vertices.len();
        vertices.extend_from_slice(&l.points);
    }
    ControlDisplay {
        layout: ControlLayout::LocalCurves(entries),
        vertices,
    }
}

fn local_patches(patches: &[LocalPatchDisplay]) -> ControlDisplay {
    let mut vertices = Vec::new();
    let mut entries = Vec::with_capacity(patches.len());
    for p in patches {
        entries.push(LocalEntry {
            path: p.path,
            samples: vertices.len(),
            points: 0,
            rows: p.rows,
            cols: p.cols,
        });
        for &(pos, n) in &p.grid {
            vertices.push(pos);
            vertices.push(n);
        }
    }
    for (p, e) in patches.iter().zip(entries.iter_mut()) {
        e.points = vertices.len();
        vertices.extend_from_slice(&p.points);
    }
    ControlDisplay {
        layout: ControlLayout::LocalPatches(entries),
        vertices,
    }
}

/// Every polynomial local of an ERBS curve at any depth with its path, in depth-first path
/// order; only those at or below `under` if given.
pub(super) fn each_curve_leaf(
    c: &ErbsCurve,
    under: Option<LocalPath<Index2>>,
) -> Vec<(LocalPath<Index2>, &GeomLocalCurve)> {
    let mut out = Vec::new();
    for (l, local) in c.local_curves().iter().enumerate() {
        let path = LocalPath::top(Index2::One(l));
        collect_curve_leaves(local, path, under, &mut out);
    }
    out
}

pub(super) fn each_curve_leaf_of(
    root: &GeomLocalCurve,
    path: LocalPath<Index2>,
) -> Vec<(LocalPath<Index2>, &GeomLocalCurve)> {
    let mut out = Vec::new();
    collect_curve_leaves(root, path, None, &mut out);
    out
}

fn collect_curve_leaves<'a>(
    local: &'a GeomLocalCurve,
    path: LocalPath<Index2>,
    under: Option<LocalPath<Index2>>,
    out: &mut Vec<(LocalPath<Index2>, &'a GeomLocalCurve)>,
) {
    match local {
        GeomLocalCurve::Spline { .. } => {
            if under.is_none_or(|u| path.starts_with(&u)) {
                out.push((path, local));
            }
        }
        GeomLocalCurve::Erbs(e) => {
            for (l, child) in e.local_curves().iter().enumerate() {
                if let Some(p) = path.child(Index2::One(l)) {
                    collect_curve_leaves(child, p, under, out);
                }
            }
        }
    }
}

pub(super) fn each_patch_leaf(
    s: &ErbsSurface,
    under: Option<LocalPath<Index2>>,
) -> Vec<(LocalPath<Index2>, &GeomLocalPatch)> {
    let mut out = Vec::new();
    let nv = s.count()[1];
    for (idx, p) in s.local_patches().iter().enumerate() {
        let path = LocalPath::top(Index2::Two(idx / nv, idx % nv));
        collect_patch_leaves(p, path, under, &mut out);
    }
    out
}

pub(super) fn each_patch_leaf_of(
    root: &GeomLocalPatch,
    path: LocalPath<Index2>,
) -> Vec<(LocalPath<Index2>, &GeomLocalPatch)> {
    let mut out = Vec::new();
    collect_patch_leaves(root, path, None, &mut out);
    out
}

fn collect_patch_leaves<'a>(
    patch: &'a GeomLocalPatch,
    path: LocalPath<Index2>,
    under: Option<LocalPath<Index2>>,
    out: &mut Vec<(LocalPath<Index2>, &'a GeomLocalPatch)>,
) {
    match patch {
        GeomLocalPatch::Spline { .. } => {
            if under.is_none_or(|u| path.starts_with(&u)) {
                out.push((path, patch));
            }
        }
        GeomLocalPatch::Erbs(e) => {
            let nv = e.count()[1];
            for (idx, child) in e.local_patches().iter().enumerate() {
                if let Some(p) = path.child(Index2::Two(idx / nv, idx % nv)) {
                    collect_patch_leaves(child, p, under, out);
                }
            }
        }
    }
}

fn curve_leaves(c: &ErbsCurve, under: Option<LocalPath<Index2>>) -> Vec<LocalCurveDisplay> {
    each_curve_leaf(c, under)
        .into_iter()
        .map(|(path, l)| {
            let (a, b) = l.domain();
            let samples = uniform_params(a, b, LOCAL_CURVE_SAMPLES)
                .into_iter()
                .map(|t| l.eval(t))
                .collect();
            LocalCurveDisplay {
                path,
                points: l.points().unwrap_or(&[]).to_vec(),
                samples,
            }
        })
        .collect()
}

fn patch_leaves(s: &ErbsSurface, under: Option<LocalPath<Index2>>) -> Vec<LocalPatchDisplay> {
    each_patch_leaf(s, under)
        .into_iter()
        .filter_map(|(path, p)| {
            let GeomLocalPatch::Spline { surface, .. } = p else {
                return None;
            };
            let [rows, cols] = surface.count();
            let [(u0, u1), (v0, v1)] = surface.domain();
            let us = uniform_params(u0, u1, LOCAL_PATCH_SAMPLES);
            let vs = uniform_params(v0, v1, LOCAL_PATCH_SAMPLES);
            let grid = us
                .iter()
                .flat_map(|&u| vs.iter().map(move |&v| (u, v)))
                .map(|(u, v)| (surface.eval(u, v), surface.normal(u, v)))
                .collect();
            Some(LocalPatchDisplay {
                path,
                rows,
                cols,
                points: surface.points().to_vec(),
                grid,
            })
        })
        .collect()
}
