//! The scene being viewed and edited: every object pre-evaluated for drawing, plus the control
//! structures (polygons, nets, ERBS local curves and patches) that are drawn and picked.

use super::camera::Bounds;
use super::maps::{SurfaceMap, symmetric_range};
use crate::geom::erbs::{ErbsCurve, ErbsSurface};
use crate::geom::knots::uniform_params;
use crate::geom::{LocalCurve as GeomLocalCurve, LocalPatch as GeomLocalPatch};
use crate::model::{
    BezierSplineEdit, CatmullRomEdit, CurveEdit, Edit, EditError, ErbsCurveEdit, ErbsSurfaceEdit,
    Index2, KindEdit, LocalEdit, LocalPath, Model, ModelRef, ObjectEdit, PointEdit, SurfaceEdit,
};
use crate::sampling::{DirtyRegion, SampleMode, SampledObject};
use crate::scene::{Scene, SceneObject};
use glam::DVec3;

/// Samples per ERBS local curve drawn in its own colour.
pub const LOCAL_CURVE_SAMPLES: usize = 48;
/// Samples per direction of an ERBS local patch drawn as a wire grid.
pub const LOCAL_PATCH_SAMPLES: usize = 9;

/// One object of the document.
#[derive(Debug, Clone)]
pub struct DocObject {
    pub name: String,
    pub color: Option<[f64; 3]>,
    /// What its OBJ source held that prespline does not use, kept through edits for saving.
    pub obj: crate::scene::obj::carried::Carried,
    pub sampled: SampledObject,
}

/// The scene as the viewer holds it.
#[derive(Debug, Clone, Default)]
pub struct Document {
    pub objects: Vec<DocObject>,
}

/// A control point as it can be picked: which object and which point (of a local curve/patch
/// for ERBS objects).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Handle {
    Point {
        object: usize,
        point: Index2,
    },
    LocalPoint {
        object: usize,
        local: LocalPath<Index2>,
        point: Index2,
    },
}

impl Handle {
    pub fn object(&self) -> usize {
        match *self {
            Handle::Point { object, .. } | Handle::LocalPoint { object, .. } => object,
        }
    }
}

/// Control structures of one object, in f64 world coordinates.
#[derive(Debug, Clone, PartialEq)]
pub enum Controls {
    /// Control polygon of a Bézier/B-spline curve.
    Polygon(Vec<DVec3>),
    /// Control net of a tensor surface, row-major.
    Net {
        rows: usize,
        cols: usize,
        points: Vec<DVec3>,
    },
    /// ERBS curve: every polynomial local at any depth (in path order) with its control
    /// points and samples over its support.
    LocalCurves(Vec<LocalCurve>),
    /// ERBS surface: every polynomial local patch at any depth with its control net and a small
    /// grid of samples.
    LocalPatches(Vec<LocalPatch>),
}

#[derive(Debug, Clone, PartialEq)]
pub struct LocalCurve {
    pub path: LocalPath<Index2>,
    pub points: Vec<DVec3>,
    pub samples: Vec<DVec3>,
}

#[derive(Debug, Clone, PartialEq)]
pub struct LocalPatch {
    pub path: LocalPath<Index2>,
    pub net_rows: usize,
    pub net_cols: usize,
    pub points: Vec<DVec3>,
    /// LOCAL_PATCH_SAMPLES² (position, normal) pairs, row-major.
    pub grid: Vec<(DVec3, DVec3)>,
}

impl Document {
    /// Pre-evaluates every object of `scene` for drawing.
    pub fn new(scene: &Scene) -> Self {
        let objects = scene
            .objects
            .iter()
            .map(|o| DocObject {
                name: o.name.clone(),
                color: o.color,
                obj: o.obj.clone(),
                sampled: SampledObject::new(&o.model, SampleMode::Render),
            })
            .collect();
        Self { objects }
    }

    /// The current scene (what Ctrl+S writes).
    pub fn to_scene(&self) -> Scene {
        Scene {
            objects: self
                .objects
                .iter()
                .map(|o| SceneObject {
                    name: o.name.clone(),
                    model: o.sampled.model().to_model(),
                    color: o.color,
                    obj: o.obj.clone(),
                })
                .collect(),
        }
    }

    /// Samples every surface for `map` (second partials with K and H for the curvature maps,
    /// what shading needs otherwise); returns the objects re-sampled, whose every sample
    /// changed (models are kept exactly).
    pub fn set_analysis(&mut self, map: Option<SurfaceMap>) -> Vec<usize> {
        let mode = match map {
            Some(m) if m.needs_curvature() => SampleMode::Analysis,
            _ => SampleMode::Render,
        };
        let mut changed = Vec::new();
        for (i, o) in self.objects.iter_mut().enumerate() {
            if o.sampled.model().is_surface() && o.sampled.mode() != mode {
                o.sampled = SampledObject::new(&o.sampled.model().to_model(), mode);
                changed.push(i);
            }
        }
        changed
    }

    /// The half range of `map`'s colour scale over every surface (see [`symmetric_range`]).
    pub fn map_range(&self, map: SurfaceMap) -> f64 {
        symmetric_range(self.objects.iter().flat_map(|o| {
            o.sampled
                .grid()
                .curvatures
                .iter()
                .flatten()
                .map(move |&kh| map.value(kh))
        }))
    }

    /// The weight of a control point (1 for polynomial objects), or `None` for handles that
    /// have no weight (ERBS local points, Catmull–Rom and Bézier spline handles).
    pub fn weight_of(&self, handle: Handle) -> Option<f64> {
        let model = self.objects.get(handle.object())?.sampled.model();
        match (handle, model) {
            (
                Handle::Point {
                    point: Index2::One(k),
                    ..
                },
                ModelRef::Curve(c),
            ) => Some(c.curve().weights().map_or(1.0, |w| w[k])),
            (
                Handle::Point {
                    point: Index2::Two(i, j),
                    ..
                },
                ModelRef::Surface(s),
            ) => {
                let s = s.surface();
                Some(s.weights().map_or(1.0, |w| w[i * s.count()[1] + j]))
            }
            _ => None,
        }
    }

    /// The edit setting a control point's weight (a polynomial object becomes rational), or
    /// why it cannot be set.
    pub fn set_weight(&self, handle: Handle, weight: f64) -> Result<Edit, String> {
        let model = self.objects[handle.object()].sampled.model();
        let edit: ObjectEdit = match (handle, model) {
            (
                Handle::Point {
                    point: Index2::One(point),
                    ..
                },
                ModelRef::Curve(_),
            ) => CurveEdit::Point(PointEdit::Weight { point, weight }).into_object(),
            (
                Handle::Point {
                    point: Index2::Two(i, j),
                    ..
                },
                ModelRef::Surface(_),
            ) => SurfaceEdit::Point(PointEdit::Weight {
                point: [i, j],
                weight,
            })
            .into_object(),
            (_, ModelRef::CatmullRom(_) | ModelRef::BezierSpline(_)) => {
                return Err(format!(
                    "a {} has no weights: B converts it to a bspline_curve first",
                    model.type_name()
                ));
            }
            _ => {
                return Err(format!(
                    "the points of an {} have no weights",
                    model.type_name()
                ));
            }
        };
        edit.validate(model).map_err(|e| e.to_string())?;
        Ok(Edit {
            object: handle.object(),
            edit,
        })
    }

    /// The edit replacing a Catmull–Rom or Bézier spline by its equivalent `bspline_curve`.
    pub fn to_bspline(&self, object: usize) -> Result<Edit, String> {
        let model = self.objects[object].sampled.model();
        let chain = model.to_bspline_curve().ok_or_else(|| {
            format!(
                "only Catmull–Rom and Bézier splines convert to a bspline_curve (this is a {})",
                model.type_name()
            )
        })?;
        Ok(Edit {
            object,
            edit: ObjectEdit::Replace(Box::new(chain)),
        })
    }

    /// Applies a validated edit through the delta path.
    pub fn apply(&mut self, edit: &Edit) -> Result<DirtyRegion, EditError> {
        self.objects[edit.object].sampled.apply(&edit.edit)
    }

    /// Bounds of every sample and control point.
    pub fn bounds(&self) -> Bounds {
        let mut b = Bounds::EMPTY;
        for (i, o) in self.objects.iter().enumerate() {
            let g = o.sampled.grid();
            for p in g.data.iter().step_by(g.stride()) {
                b.include(*p);
            }
            for h in self.handles(i) {
                b.include(h.1);
            }
        }
        b
    }

    /// Control structures of object `i`.
    pub fn controls(&self, i: usize) -> Controls {
        match self.objects[i].sampled.model() {
            ModelRef::Curve(c) => Controls::Polygon(c.curve().points().to_vec()),
            // The interpolated points.
            ModelRef::CatmullRom(c) => Controls::Polygon(c.spline().points().to_vec()),
            // Bézier points, or the de Boor polygon of splines edited through it (their Bézier
            // points are drawn as an overlay).
            ModelRef::BezierSpline(c) => Controls::Polygon(c.spline().handles()),
            ModelRef::Surface(s) => {
                let s = s.surface();
                let [rows, cols] = s.count();
                Controls::Net {
                    rows,
                    cols,
                    points: s.points().to_vec(),
                }
            }
            ModelRef::ErbsCurve(c) => Controls::LocalCurves(curve_leaves(c.curve(), None)),
            ModelRef::ErbsSurface(s) => Controls::LocalPatches(patch_leaves(s.surface(), None)),
        }
    }

    /// Every pickable control point of object `i` with its position (no sampling: cheap).
    pub fn handles(&self, i: usize) -> Vec<(Handle, DVec3)> {
        let object = i;
        let polygon = |points: Vec<DVec3>| {
            points
                .into_iter()
                .enumerate()
                .map(|(k, q)| {
                    let point = Index2::One(k);
                    (Handle::Point { object, point }, q)
                })
                .collect()
        };
        let local_points = |path: LocalPath<Index2>, pts: &[DVec3], cols: usize| {
            pts.iter()
                .enumerate()
                .map(|(q, &p)| {
                    let point = match q.checked_div(cols) {
                        None => Index2::One(q),
                        Some(a) => Index2::Two(a, q % cols),
                    };
                    (
                        Handle::LocalPoint {
                            object,
                            local: path,
                            point,
                        },
                        p,
                    )
                })
                .collect::<Vec<_>>()
        };
        match self.objects[i].sampled.model() {
            ModelRef::CatmullRom(c) => polygon(c.spline().points().to_vec()),
            ModelRef::BezierSpline(c) => polygon(c.spline().handles()),
            ModelRef::Curve(c) => c
                .curve()
                .points()
                .iter()
                .enumerate()
                .map(|(k, &q)| {
                    (
                        Handle::Point {
                            object,
                            point: Index2::One(k),
                        },
                        q,
                    )
                })
                .collect(),
            ModelRef::Surface(s) => {
                let s = s.surface();
                let cols = s.count()[1];
                s.points()
                    .iter()
                    .enumerate()
                    .map(|(k, &q)| {
                        (
                            Handle::Point {
                                object,
                                point: Index2::Two(k / cols, k % cols),
                            },
                            q,
                        )
                    })
                    .collect()
            }
            ModelRef::ErbsCurve(c) => each_curve_leaf(c.curve(), None)
                .into_iter()
                .flat_map(|(path, l)| local_points(path, l.points().unwrap_or(&[]), 0))
                .collect(),
            ModelRef::ErbsSurface(s) => each_patch_leaf(s.surface(), None)
                .into_iter()
                .flat_map(|(path, p)| match p.net() {
                    Some(([_, nc], pts)) => local_points(path, pts, nc),
                    None => Vec::new(),
                })
                .collect(),
        }
    }

    /// Every pickable control point of the document.
    pub fn all_handles(&self) -> Vec<(Handle, DVec3)> {
        (0..self.objects.len())
            .flat_map(|i| self.handles(i))
            .collect()
    }

    /// The edit that moves a handle by `delta` (`None` if the handle does not fit its object).
    pub fn move_handle(&self, handle: Handle, delta: DVec3) -> Option<Edit> {
        let model = self.objects.get(handle.object())?.sampled.model();
        let edit = match (handle, model) {
            (
                Handle::Point {
                    point: Index2::One(point),
                    ..
                },
                ModelRef::Curve(_),
            ) => CurveEdit::Point(PointEdit::Move { point, delta }).into_object(),
            (
                Handle::Point {
                    point: Index2::One(point),
                    ..
                },
                ModelRef::CatmullRom(_),
            ) => CatmullRomEdit::Point(PointEdit::Move { point, delta }).into_object(),
            (
                Handle::Point {
                    point: Index2::One(point),
                    ..
                },
                ModelRef::BezierSpline(_),
            ) => BezierSplineEdit::Move { point, delta }.into_object(),
            (
                Handle::Point {
                    point: Index2::Two(i, j),
                    ..
                },
                ModelRef::Surface(_),
            ) => SurfaceEdit::Point(PointEdit::Move {
                point: [i, j],
                delta,
            })
            .into_object(),
            (
                Handle::LocalPoint {
                    local,
                    point: Index2::One(point),
                    ..
                },
                ModelRef::ErbsCurve(_),
            ) => ErbsCurveEdit::Local(LocalEdit::MovePoint {
                local: local.to_curve()?,
                point,
                delta,
            })
            .into_object(),
            (
                Handle::LocalPoint {
                    local,
                    point: Index2::Two(a, b),
                    ..
                },
                ModelRef::ErbsSurface(_),
            ) => ErbsSurfaceEdit::Local(LocalEdit::MovePoint {
                local: local.to_surface()?,
                point: [a, b],
                delta,
            })
            .into_object(),
            _ => return None,
        };
        Some(Edit {
            object: handle.object(),
            edit,
        })
    }

    /// Every control point of the ERBS local at `local`, at any depth.
    pub fn local_points(&self, object: usize, local: LocalPath<Index2>) -> Option<Vec<DVec3>> {
        let points: Vec<DVec3> = match self.objects.get(object)?.sampled.model() {
            ModelRef::ErbsCurve(c) => {
                let root = c.curve().local_at(local.to_curve()?.steps())?;
                each_curve_leaf_of(root, local)
                    .into_iter()
                    .flat_map(|(_, l)| l.points().unwrap_or(&[]).to_vec())
                    .collect()
            }
            ModelRef::ErbsSurface(s) => {
                let root = s.surface().local_at(local.to_surface()?.steps())?;
                each_patch_leaf_of(root, local)
                    .into_iter()
                    .flat_map(|(_, p)| p.net().map_or(Vec::new(), |(_, pts)| pts.to_vec()))
                    .collect()
            }
            _ => return None,
        };
        (!points.is_empty()).then_some(points)
    }

    /// The edit that sets the ERBS local at `local` exactly to its state in `origin` mapped
    /// by `matrix` (a transform taken from a gesture's start rather than by increments).
    pub fn set_local_transformed(
        object: usize,
        local: LocalPath<Index2>,
        origin: &Model,
        matrix: &glam::DMat4,
    ) -> Option<Edit> {
        let f = |p: DVec3| matrix.transform_point3(p);
        let edit = match origin {
            Model::ErbsCurve(m) => {
                let path = local.to_curve()?;
                let mut l = m.curve().local_at(path.steps())?.clone();
                l.map_points(&f);
                ErbsCurveEdit::SetLocal {
                    local: path,
                    to: Box::new(l),
                }
                .into_object()
            }
            Model::ErbsSurface(m) => {
                let path = local.to_surface()?;
                let mut p = m.surface().local_at(path.steps())?.clone();
                p.map_points(&f);
                ErbsSurfaceEdit::SetLocal {
                    local: path,
                    to: Box::new(p),
                }
                .into_object()
            }
            _ => return None,
        };
        Some(Edit { object, edit })
    }

    /// The edit that maps an ERBS local curve or patch by the affine `matrix`.
    pub fn transform_local(
        &self,
        object: usize,
        local: LocalPath<Index2>,
        matrix: glam::DMat4,
    ) -> Option<Edit> {
        let edit: ObjectEdit = match self.objects.get(object)?.sampled.model() {
            ModelRef::ErbsCurve(_) => ErbsCurveEdit::Local(LocalEdit::Transform {
                local: local.to_curve()?,
                matrix,
            })
            .into_object(),
            ModelRef::ErbsSurface(_) => ErbsSurfaceEdit::Local(LocalEdit::Transform {
                local: local.to_surface()?,
                matrix,
            })
            .into_object(),
            _ => return None,
        };
        Some(Edit { object, edit })
    }
}

impl Document {
    /// The edit that turns the polynomial local at `local` into an ERBS local with `count`
    /// locals per direction of the local's own degree (so its shape stays), with that degree
    /// for messages. `None` unless the local is a polynomial local of an ERBS object.
    #[must_use]
    pub fn local_to_erbs_edit(
        &self,
        object: usize,
        local: LocalPath<Index2>,
        count: usize,
    ) -> Option<(ObjectEdit, String)> {
        match self.objects.get(object)?.sampled.model() {
            ModelRef::ErbsCurve(m) => {
                let path = local.to_curve()?;
                let l = m.curve().local_at(path.steps())?;
                l.points()?;
                let degree = l.degree();
                let edit = ErbsCurveEdit::ToErbs {
                    local: path,
                    count,
                    degree,
                };
                Some((edit.into_object(), degree.to_string()))
            }
            ModelRef::ErbsSurface(m) => {
                let path = local.to_surface()?;
                let p = m.surface().local_at(path.steps())?;
                p.net()?;
                let degree = p.degree();
                let edit = ErbsSurfaceEdit::ToErbs {
                    local: path,
                    count: [count; 2],
                    degree,
                };
                Some((edit.into_object(), format!("{degree:?}")))
            }
            _ => None,
        }
    }
}

/// Display data of the polynomial locals under one ERBS local.
#[derive(Debug, Clone, PartialEq)]
pub enum LocalControls {
    Curves(Vec<LocalCurve>),
    Patches(Vec<LocalPatch>),
}

impl Document {
    /// Display data of the polynomial locals at or below `local` of object `i` (what an edit of
    /// that local changes), without recomputing the others.
    pub fn local_controls(&self, i: usize, local: LocalPath<Index2>) -> Option<LocalControls> {
        match self.objects[i].sampled.model() {
            ModelRef::ErbsCurve(c) => {
                Some(LocalControls::Curves(curve_leaves(c.curve(), Some(local))))
            }
            ModelRef::ErbsSurface(s) => Some(LocalControls::Patches(patch_leaves(
                s.surface(),
                Some(local),
            ))),
            _ => None,
        }
    }
}

/// Every polynomial local of an ERBS curve at any depth with its path, in depth-first path
/// order; only those at or below `under` if given.
fn each_curve_leaf(
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

fn each_curve_leaf_of(
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

fn each_patch_leaf(
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

fn each_patch_leaf_of(
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

fn curve_leaves(c: &ErbsCurve, under: Option<LocalPath<Index2>>) -> Vec<LocalCurve> {
    each_curve_leaf(c, under)
        .into_iter()
        .map(|(path, l)| {
            let (a, b) = l.domain();
            let samples = uniform_params(a, b, LOCAL_CURVE_SAMPLES)
                .into_iter()
                .map(|t| l.eval(t))
                .collect();
            LocalCurve {
                path,
                points: l.points().unwrap_or(&[]).to_vec(),
                samples,
            }
        })
        .collect()
}

fn patch_leaves(s: &ErbsSurface, under: Option<LocalPatchPath>) -> Vec<LocalPatch> {
    each_patch_leaf(s, under)
        .into_iter()
        .filter_map(|(path, p)| {
            let GeomLocalPatch::Spline { surface, .. } = p else {
                return None;
            };
            let [nr, nc] = surface.count();
            let [(u0, u1), (v0, v1)] = surface.domain();
            let us = uniform_params(u0, u1, LOCAL_PATCH_SAMPLES);
            let vs = uniform_params(v0, v1, LOCAL_PATCH_SAMPLES);
            let grid = us
                .iter()
                .flat_map(|&u| vs.iter().map(move |&v| (u, v)))
                .map(|(u, v)| (surface.eval(u, v), surface.normal(u, v)))
                .collect();
            Some(LocalPatch {
                path,
                net_rows: nr,
                net_cols: nc,
                points: surface.points().to_vec(),
                grid,
            })
        })
        .collect()
}

type LocalPatchPath = LocalPath<Index2>;
