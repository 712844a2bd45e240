//! The document: every object of the scene with its name, colour, pre-evaluated samples
//! ([`SampledObject`]) and control display, and what can be read and built from it (handles,
//! bounds, the edits a gesture stands for).

use crate::geom::Bounds;
use crate::geom::trim::{Coverage, Trimmed};
use crate::model::SampledObject;
use crate::model::{
    ControlDisplay, Edit, ErbsCurveEdit, ErbsSurfaceEdit, Grip, Index2, KindEdit, LocalEdit,
    LocalPath, Model, ModelRef, ObjectEdit, each_curve_leaf_of, each_patch_leaf_of,
};
use crate::progress::{ProgressSink, Silent};
use crate::sampling::SampleMode;
use crate::scene::{Scene, SceneObject};
use glam::DVec3;
use std::sync::Arc;

/// One object of the document.
#[derive(Debug, Clone)]
pub struct DocObject {
    pub name: String,
    pub color: Option<[f64; 3]>,
    /// What its file held that prespline does not use, kept through edits for saving.
    pub kept: crate::scene::Carried,
    pub sampled: SampledObject,
    /// What is drawn and picked besides the samples, kept up to date by every apply.
    pub controls: ControlDisplay,
    /// A trimmed surface's trim and which of its samples and cells lie inside: worked out
    /// once, since no edit moves a trim in parameter space nor the sample parameters.
    pub trim: Option<Arc<TrimCoverage>>,
}

/// The most boundary vertices of a trimmed surface [`DocObject::drawn_points`] evaluates.
pub const BOUNDARY_POINTS: usize = 256;

/// A trim with its coverage of an object's sample grid, each sample cell cut into `refine`²
/// mask cells (see [`TrimCoverage::of`]).
#[derive(Debug, Clone, PartialEq)]
pub struct TrimCoverage {
    pub trimmed: Trimmed,
    /// The coverage of the mask grid: the sample grid with every cell cut `refine` times per
    /// direction (its sample `(i·refine, j·refine)` is sample `(i, j)`).
    pub coverage: Coverage,
    /// Mask cells per sample cell and direction, a power of two.
    pub refine: usize,
}

/// The mask's target of segments per boundary cell, on average over the boundary cells: what the
/// fragment shader tests per boundary fragment. A plane drawn from 2 × 2 samples with a hole
/// flattened into thousands of segments would otherwise test all of them at every fragment
/// (seconds a frame on lavapipe). Cells no finer than needed: the half-pixel growth reaches only
/// the segments of the fragment's own cell, so a mask cell smaller than a pixel grows less.
const MASK_SEGMENTS_PER_CELL: f64 = 32.0;
/// The most mask cells per sample cell and direction, and the most mask cells in all.
const MAX_REFINE: usize = 64;
const MAX_MASK_CELLS: usize = 1 << 21;

impl TrimCoverage {
    /// The coverage of a sampled surface's grid by `trimmed`; `None` for a curve or a grid
    /// the coverage cannot take (over 32,768 samples a side, which no sample limit allows).
    /// The mask cells: the sample cells cut in 2, 4, … per direction until the segments per
    /// boundary cell fall to [`MASK_SEGMENTS_PER_CELL`] on average (each cut about halves it: a
    /// flattened curve crosses twice the cells, each holding half its segments).
    #[must_use]
    pub fn of(trimmed: &Trimmed, sampled: &SampledObject) -> Option<Self> {
        let params = sampled.params();
        let [u, v] = params.as_slice() else {
            return None;
        };
        let coarse = Coverage::new(trimmed.regions(), u, v).ok()?;
        let (mu, mv) = coarse.samples();
        let cells = (mu - 1) * (mv - 1);
        let records = coarse.gpu_records();
        let refs: usize = records.iter().map(|r| (r[1] >> 1) as usize).sum();
        let mut refine = 1;
        let mut cost = refs as f64 / records.len().max(1) as f64;
        while cost > MASK_SEGMENTS_PER_CELL
            && refine < MAX_REFINE
            && 2 * refine * (mu - 1) < 32_768
            && 2 * refine * (mv - 1) < 32_768
            && cells * 4 * refine * refine <= MAX_MASK_CELLS
        {
            refine *= 2;
            cost /= 2.0;
        }
        let coverage = if refine == 1 {
            coarse
        } else {
            Coverage::new(trimmed.regions(), &cut(u, refine), &cut(v, refine)).ok()?
        };
        Some(Self {
            trimmed: trimmed.clone(),
            coverage,
            refine,
        })
    }

    /// Whether sample `(i, j)` lies inside the trim.
    #[must_use]
    pub fn sample_inside(&self, i: usize, j: usize) -> bool {
        self.coverage
            .sample_inside(i * self.refine, j * self.refine)
    }
}

/// The uniform parameters `s` with every interval cut into `k`.
fn cut(s: &[f64], k: usize) -> Vec<f64> {
    let (Some(&a), Some(&b)) = (s.first(), s.last()) else {
        return Vec::new();
    };
    let n = (s.len() - 1) * k;
    (0..=n)
        .map(|m| {
            if m == n {
                b
            } else {
                a + (b - a) * m as f64 / n as f64
            }
        })
        .collect()
}

impl DocObject {
    /// Pre-evaluates a scene object in `mode`.
    #[must_use]
    pub fn new(o: &SceneObject, mode: SampleMode) -> Self {
        let sampled = SampledObject::new(&o.model, mode);
        let controls = ControlDisplay::of(sampled.model());
        let trim = o
            .trim
            .as_ref()
            .and_then(|t| TrimCoverage::of(t, &sampled))
            .map(Arc::new);
        Self {
            name: o.name.clone(),
            color: o.color,
            kept: o.kept.clone(),
            sampled,
            controls,
            trim,
        }
    }

    /// Whether sample (i, j) is drawn: inside the trim of a trimmed surface, always otherwise.
    #[must_use]
    pub fn drawn(&self, i: usize, j: usize) -> bool {
        self.trim.as_ref().is_none_or(|t| t.sample_inside(i, j))
    }

    /// Points of what is drawn, for framing and bounds: every `every`-th sample (a trimmed
    /// surface's inside ones), and a trimmed surface's boundary, at most `boundary` (at most
    /// [`BOUNDARY_POINTS`]) of its vertices evaluated on the exact surface (a coarse grid of a
    /// large face, a plane's 2 × 2, can have no sample inside its trim).
    #[must_use]
    pub fn drawn_points(&self, every: usize, boundary: usize) -> Vec<DVec3> {
        let g = self.sampled.grid();
        let [rows, cols] = g.dims;
        let every = every.max(1);
        let Some(t) = &self.trim else {
            return g.data.iter().step_by(g.stride() * every).copied().collect();
        };
        let mut out: Vec<DVec3> = (0..rows * cols)
            .step_by(every)
            .filter(|k| t.sample_inside(k / cols, k % cols))
            .map(|k| g.position(k / cols, k % cols))
            .collect();
        let loops = t.trimmed.regions().loops();
        let vertices: usize = loops.iter().map(|l| l.points().len()).sum();
        let step = vertices.div_ceil(boundary.clamp(1, BOUNDARY_POINTS)).max(1);
        let kind = self.sampled.model().kind();
        for p in loops.iter().flat_map(|l| l.points()).step_by(step) {
            let q = match kind.tensor() {
                Some(t) => t.first_partials(p.x, p.y)[0],
                None => {
                    let mut d = [DVec3::ZERO];
                    kind.derivatives_at([p.x, p.y], 0, &[(0, 0)], &mut d);
                    d[0]
                }
            };
            if q.is_finite() {
                out.push(q);
            }
        }
        out
    }

    /// The scene object it stands for now (every applied edit in).
    #[must_use]
    pub fn to_scene_object(&self) -> SceneObject {
        SceneObject {
            name: self.name.clone(),
            model: self.sampled.model().to_model(),
            color: self.color,
            kept: self.kept.clone(),
            trim: self.trim.as_ref().map(|t| t.trimmed.clone()),
        }
    }
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
    #[must_use]
    pub fn object(&self) -> usize {
        match *self {
            Handle::Point { object, .. } | Handle::LocalPoint { object, .. } => object,
        }
    }

    /// The grip within its object.
    #[must_use]
    pub fn grip(&self) -> Grip {
        match *self {
            Handle::Point { point, .. } => Grip::Point(point),
            Handle::LocalPoint { local, point, .. } => Grip::LocalPoint { local, point },
        }
    }

    /// The handle of `grip` on object `object`.
    #[must_use]
    pub fn of(object: usize, grip: Grip) -> Self {
        match grip {
            Grip::Point(point) => Handle::Point { object, point },
            Grip::LocalPoint { local, point } => Handle::LocalPoint {
                object,
                local,
                point,
            },
        }
    }
}

impl Document {
    /// Pre-evaluates every object of `scene` for drawing.
    #[must_use]
    pub fn new(scene: &Scene) -> Self {
        Self::with_mode(scene, SampleMode::Render)
    }

    /// Pre-evaluates every object of `scene` in `mode` (surfaces and curves alike), the
    /// objects spread over every core ([`crate::parallel`]; the same bits as on one thread).
    #[must_use]
    pub fn with_mode(scene: &Scene, mode: SampleMode) -> Self {
        Self::with_progress(scene, mode, &Silent)
    }

    /// [`Document::with_mode`], counting the samples done into `progress`.
    #[must_use]
    pub fn with_progress(scene: &Scene, mode: SampleMode, progress: &dyn ProgressSink) -> Self {
        let samples: u64 = scene
            .objects
            .iter()
            .map(|o| {
                o.model
                    .sample_dims()
                    .iter()
                    .map(|&m| m as u64)
                    .product::<u64>()
            })
            .sum();
        let progress = progress.start("pre-evaluating", Some(samples), "samples");
        let objects = crate::parallel::map(&scene.objects, |o| {
            let d = DocObject::new(o, mode);
            progress.inc(d.sampled.grid().data.len() as u64 / d.sampled.grid().stride() as u64);
            d
        });
        // Cleared, not left: the load's progress is transient, and an error that follows
        // must stand on its own line.
        drop(progress);
        Self { objects }
    }

    /// The current scene (what Ctrl+S writes).
    pub fn to_scene(&self) -> Scene {
        Scene {
            objects: self
                .objects
                .iter()
                .map(DocObject::to_scene_object)
                .collect(),
        }
    }

    /// Samples every surface in `mode` (second partials with K and H for the curvature maps,
    /// what shading needs otherwise); returns the objects re-sampled, whose every sample
    /// changed (models are kept exactly).
    pub fn set_surface_mode(&mut self, mode: SampleMode) -> Vec<usize> {
        let mut changed = Vec::new();
        for (i, o) in self.objects.iter_mut().enumerate() {
            if o.sampled.model().is_surface() && o.sampled.mode() != mode {
                o.sampled = SampledObject::new(&o.sampled.model().to_model(), mode);
                changed.push(i);
            }
        }
        changed
    }

    /// The weight of a control point (1 for polynomial objects), or `None` for handles that
    /// have no weight (ERBS local points, Catmull–Rom and Bézier spline handles).
    #[must_use]
    pub fn weight_of(&self, handle: Handle) -> Option<f64> {
        let model = self.objects.get(handle.object())?.sampled.model();
        model.kind().weight(handle.grip())
    }

    /// The edit setting a control point's weight (a polynomial object becomes rational), or
    /// why it cannot be set.
    pub fn set_weight(&self, handle: Handle, weight: f64) -> Result<Edit, String> {
        let model = self.objects[handle.object()].sampled.model();
        let edit = model.kind().weight_edit(handle.grip(), weight)?;
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

    /// Bounds of every drawn sample (a trimmed surface's inside ones) and control point.
    #[must_use]
    pub fn bounds(&self) -> Bounds {
        // A pass over every sample of the scene: per object on every core, then merged (a
        // minimum and a maximum, so the order does not matter).
        let each = crate::parallel::map(&self.objects, |o| {
            let mut b = Bounds::EMPTY;
            for p in o.drawn_points(1, BOUNDARY_POINTS) {
                b.include(p);
            }
            for p in o.controls.grip_points() {
                b.include(p);
            }
            b
        });
        each.into_iter().fold(Bounds::EMPTY, |mut all, b| {
            all.merge(&b);
            all
        })
    }

    /// Every pickable control point of object `i` with its position: the points its control
    /// display draws (no sampling: cheap).
    #[must_use]
    pub fn handles(&self, i: usize) -> Vec<(Handle, DVec3)> {
        self.objects[i]
            .controls
            .grips()
            .into_iter()
            .map(|(grip, p)| (Handle::of(i, grip), p))
            .collect()
    }

    /// Every pickable control point of the document.
    #[must_use]
    pub fn all_handles(&self) -> Vec<(Handle, DVec3)> {
        (0..self.objects.len())
            .flat_map(|i| self.handles(i))
            .collect()
    }

    /// The edit that moves a handle by `delta` (`None` if the handle does not fit its object).
    #[must_use]
    pub fn move_handle(&self, handle: Handle, delta: DVec3) -> Option<Edit> {
        let model = self.objects.get(handle.object())?.sampled.model();
        let edit = model.kind().move_edit(handle.grip(), delta)?;
        Some(Edit {
            object: handle.object(),
            edit,
        })
    }

    /// Every control point of the ERBS local at `local`, at any depth.
    #[must_use]
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
    #[must_use]
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
    #[must_use]
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
