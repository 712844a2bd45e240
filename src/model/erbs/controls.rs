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

/// The display of the given polynomial local curves, in one exactly sized vertex list: per
/// local its [`LOCAL_CURVE_SAMPLES`] samples over its support, then every local's control
/// points (a scene can hold millions of locals, so nothing is built twice).
fn local_curves(leaves: &[(LocalPath<Index2>, &GeomLocalCurve)]) -> ControlDisplay {
    let mut vertices = Vec::with_capacity(curve_display_vertices(leaves.iter().map(|(_, l)| *l)));
    let mut entries = Vec::with_capacity(leaves.len());
    for &(path, l) in leaves {
        entries.push(LocalEntry {
            path,
            samples: vertices.len(),
            points: 0,
            rows: points(l).len(),
            cols: 1,
        });
        let (a, b) = l.domain();
        vertices.extend(
            uniform_params(a, b, LOCAL_CURVE_SAMPLES)
                .into_iter()
                .map(|t| l.eval(t)),
        );
    }
    for (&(_, l), e) in leaves.iter().zip(entries.iter_mut()) {
        e.points = vertices.len();
        vertices.extend_from_slice(points(l));
    }
    ControlDisplay {
        layout: ControlLayout::LocalCurves(entries),
        vertices,
    }
}

/// As [`local_curves`] for local patches: per patch a [`LOCAL_PATCH_SAMPLES`]² grid of
/// (position, normal) pairs, then every patch's net.
fn local_patches(leaves: &[(LocalPath<Index2>, &GeomLocalPatch)]) -> ControlDisplay {
    let mut vertices = Vec::with_capacity(patch_display_vertices(leaves.iter().map(|(_, p)| *p)));
    let mut entries = Vec::with_capacity(leaves.len());
    for &(path, p) in leaves {
        let Some(surface) = spline(p) else { continue };
        let [rows, cols] = surface.count();
        entries.push(LocalEntry {
            path,
            samples: vertices.len(),
            points: 0,
            rows,
            cols,
        });
        let [(u0, u1), (v0, v1)] = surface.domain();
        let vs = uniform_params(v0, v1, LOCAL_PATCH_SAMPLES);
        for u in uniform_params(u0, u1, LOCAL_PATCH_SAMPLES) {
            for &v in &vs {
                vertices.push(surface.eval(u, v));
                vertices.push(surface.normal(u, v));
            }
        }
    }
    let mut e = entries.iter_mut();
    for surface in leaves.iter().filter_map(|(_, p)| spline(p)) {
        let entry = e.next().expect("one entry per spline patch");
        entry.points = vertices.len();
        vertices.extend_from_slice(surface.points());
    }
    ControlDisplay {
        layout: ControlLayout::LocalPatches(entries),
        vertices,
    }
}

fn points(l: &GeomLocalCurve) -> &[DVec3] {
    l.points().unwrap_or(&[])
}

fn spline(p: &GeomLocalPatch) -> Option<&crate::geom::TensorSurface> {
    match p {
        GeomLocalPatch::Spline { surface, .. } => Some(surface),
        GeomLocalPatch::Erbs(_) => None,
    }
}

/// The vertices [`local_curves`] makes for these locals (what the memory budget counts).
fn curve_display_vertices<'a>(leaves: impl Iterator<Item = &'a GeomLocalCurve>) -> usize {
    leaves.map(|l| LOCAL_CURVE_SAMPLES + points(l).len()).sum()
}

/// The vertices [`local_patches`] makes for these patches.
fn patch_display_vertices<'a>(leaves: impl Iterator<Item = &'a GeomLocalPatch>) -> usize {
    leaves
        .filter_map(spline)
        .map(|s| 2 * LOCAL_PATCH_SAMPLES * LOCAL_PATCH_SAMPLES + s.points().len())
        .sum()
}

/// Vertices and host bytes of an ERBS curve's control display, before it is built.
#[must_use]
pub fn curve_display_size(c: &ErbsCurve) -> (usize, u128) {
    let leaves = each_curve_leaf(c, None);
    display_size(
        curve_display_vertices(leaves.iter().map(|(_, l)| *l)),
        leaves.len(),
    )
}

/// Vertices and host bytes of an ERBS surface's control display, before it is built.
#[must_use]
pub fn patch_display_size(s: &ErbsSurface) -> (usize, u128) {
    let leaves = each_patch_leaf(s, None);
    display_size(
        patch_display_vertices(leaves.iter().map(|(_, p)| *p)),
        leaves.len(),
    )
}

/// Host bytes of a display of `vertices` vertices and `entries` locals, and while it is
/// built the list of leaves it is built from.
fn display_size(vertices: usize, entries: usize) -> (usize, u128) {
    let leaf = std::mem::size_of::<(LocalPath<Index2>, &GeomLocalCurve)>();
    let bytes = vertices as u128 * std::mem::size_of::<DVec3>() as u128
        + entries as u128 * (std::mem::size_of::<LocalEntry>() + leaf) as u128;
    (vertices, bytes)
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

/// The display of an ERBS curve's polynomial locals (those at or below `under` if given).
#[must_use]
pub fn curve_controls(c: &ErbsCurve, under: Option<LocalPath<Index2>>) -> ControlDisplay {
    local_curves(&each_curve_leaf(c, under))
}

/// The display of an ERBS surface's polynomial local patches (at or below `under` if given).
#[must_use]
pub fn patch_controls(s: &ErbsSurface, under: Option<LocalPath<Index2>>) -> ControlDisplay {
    local_patches(&each_patch_leaf(s, under))
}
