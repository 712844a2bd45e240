//! The control display of ERBS objects: every polynomial local curve or patch at any depth with
//! its control points and a few display samples.

use crate::geom::erbs::{ErbsCurve, ErbsSurface};
use crate::geom::knots::uniform_params;
use crate::geom::{LocalCurve as GeomLocalCurve, LocalPatch as GeomLocalPatch};
use crate::model::controls::{
    ControlDisplay, ControlLayout, LOCAL_CURVE_SAMPLES, LOCAL_PATCH_SAMPLES, LocalEntry,
};
use crate::model::{Index2, LocalPath};
use glam::DVec3;

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
pub fn each_curve_leaf(
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

#[must_use]
pub fn each_curve_leaf_of(
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

pub fn each_patch_leaf(
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

#[must_use]
pub fn each_patch_leaf_of(
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

/// The display of an ERBS curve's polynomial locals (those at or below `under` if given).
#[must_use]
pub fn curve_controls(c: &ErbsCurve, under: Option<LocalPath<Index2>>) -> ControlDisplay {
    local_curves(&curve_leaves(c, under))
}

/// The display of an ERBS surface's polynomial local patches (at or below `under` if given).
#[must_use]
pub fn patch_controls(s: &ErbsSurface, under: Option<LocalPath<Index2>>) -> ControlDisplay {
    local_patches(&patch_leaves(s, under))
}
