//! The knot-insertion tool: the parameter under the cursor on one curve or surface (on a
//! surface, of the u or v isoparametric line through the point under the cursor), previewed as
//! a marker or an isoline until it is applied. On B-spline objects it inserts a knot
//! (CurveKnotIns); on ERBS objects it refines one ERBS level, the object's own or an ERBS local's
//! nested inside it, with a new Hermite local centred at the parameter.

use super::tools::View;
use crate::editor::Document;
use crate::geom::erbs::{ErbsKnots, LocalCurve, LocalPatch};
use crate::gpu::LineVertex;
use crate::model::{
    CurveEdit, Edit, ErbsCurveEdit, ErbsSurfaceEdit, Index2, KindEdit, LocalPath, ModelRef,
    SurfaceEdit,
};
use crate::sampling::SampleGrid;
use glam::DVec3;

/// How far (pixels) from the object the cursor may be for a parameter to be found.
pub const REFINE_RADIUS: f64 = 40.0;
/// Points of a previewed isoline.
const ISOLINE_POINTS: usize = 96;

/// An insertion being aimed.
#[derive(Debug, Clone, PartialEq)]
pub struct Refine {
    pub object: usize,
    /// 0: u (curves always), 1: v.
    pub dir: usize,
    /// The parameter under the cursor, if the cursor is near the object.
    pub at: Option<f64>,
    /// The ERBS level refined: `None` the object itself, else the ERBS local at this path.
    pub level: Option<LocalPath<Index2>>,
}

impl Refine {
    #[must_use]
    pub fn new(object: usize) -> Self {
        Self {
            object,
            dir: 0,
            at: None,
            level: None,
        }
    }

    /// Refines the ERBS level that owns `selected` (a local of `object`): the local itself when
    /// it is an ERBS local (a detail made with X), else the level it belongs to — its parent
    /// ERBS local, or the object for a top-level local.
    #[must_use]
    pub fn for_local(object: usize, selected: LocalPath<Index2>, doc: &Document) -> Self {
        let is_erbs = match doc.objects[object].sampled.model() {
            ModelRef::ErbsCurve(m) => selected
                .to_curve()
                .and_then(|p| m.curve().local_at(p.steps()))
                .is_some_and(|l| matches!(l, LocalCurve::Erbs(_))),
            ModelRef::ErbsSurface(m) => selected
                .to_surface()
                .and_then(|p| m.surface().local_at(p.steps()))
                .is_some_and(|l| matches!(l, LocalPatch::Erbs(_))),
            _ => false,
        };
        let level = if is_erbs {
            Some(selected)
        } else {
            let steps = selected.steps();
            LocalPath::new(&steps[..steps.len() - 1])
        };
        Self {
            level,
            ..Self::new(object)
        }
    }

    /// Finds the parameter under the cursor: the nearest sample on screen, refined linearly
    /// along the chosen direction between it and its neighbours.
    pub fn aim(&mut self, doc: &Document, view: &View, cursor: (f64, f64)) {
        let o = &doc.objects[self.object];
        let grid = o.sampled.grid();
        let params = o.sampled.params();
        self.at = nearest_sample(grid, view, cursor, REFINE_RADIUS).map(|[i, j]| {
            let dir = self.dir.min(params.len() - 1);
            let index = [i, j][dir];
            let along = |k: usize| if dir == 0 { [k, j] } else { [i, k] };
            let here = grid.position(i, j);
            let mut best = (f64::INFINITY, params[dir][index]);
            for next in [index.wrapping_sub(1), index + 1] {
                if next >= params[dir].len() {
                    continue;
                }
                let [ni, nj] = along(next);
                let (Some(a), Some(b)) = (view.project(here), view.project(grid.position(ni, nj)))
                else {
                    continue;
                };
                let (s, d) = segment_parameter(a, b, cursor);
                if d < best.0 {
                    let (t0, t1) = (params[dir][index], params[dir][next]);
                    best = (d, t0 + (t1 - t0) * s);
                }
            }
            best.1
        });
    }

    /// Whether the object takes knots at all (Catmull–Rom and Bézier splines keep their
    /// segments); the reason, with the way out, when not.
    pub fn supported(&self, doc: &Document) -> Result<(), String> {
        let model = doc.objects[self.object].sampled.model();
        match model {
            ModelRef::Curve(_)
            | ModelRef::Surface(_)
            | ModelRef::ErbsCurve(_)
            | ModelRef::ErbsSurface(_) => Ok(()),
            _ if model.to_bspline_curve().is_some() => Err(format!(
                "a {} keeps its segments: B converts it to a bspline_curve first",
                model.type_name()
            )),
            _ => Err(format!("a {} takes no knots", model.type_name())),
        }
    }

    /// The insertion as an edit, validated against the object (an error is one line).
    pub fn edit(&self, doc: &Document) -> Result<Edit, String> {
        let t = self
            .at
            .ok_or("no parameter under the cursor: aim at the curve or surface")?;
        let model = doc.objects[self.object].sampled.model();
        let edit = match model {
            ModelRef::Curve(_) => CurveEdit::InsertKnot { t, times: 1 }.into_object(),
            ModelRef::Surface(_) => SurfaceEdit::InsertKnot {
                dir: self.dir,
                t,
                times: 1,
            }
            .into_object(),
            ModelRef::ErbsCurve(_) => ErbsCurveEdit::InsertKnot {
                local: self.level.and_then(|p| p.to_curve()),
                at: self.level_parameter(doc, t)?,
                degree: None,
            }
            .into_object(),
            ModelRef::ErbsSurface(_) => ErbsSurfaceEdit::InsertKnot {
                local: self.level.and_then(|p| p.to_surface()),
                at: (self.dir, self.level_parameter(doc, t)?),
                degree: None,
            }
            .into_object(),
            _ => return Err(self.supported(doc).err().unwrap_or_default()),
        };
        edit.validate(model).map_err(|e| e.to_string())?;
        Ok(Edit {
            object: self.object,
            edit,
        })
    }

    /// The refined level's domain in the chosen direction: the object's, or the nested ERBS
    /// local's (its support, in the object's parameter).
    fn level_domain(&self, doc: &Document) -> Option<(f64, f64)> {
        let dir = self.dir;
        match doc.objects[self.object].sampled.model() {
            ModelRef::ErbsCurve(m) => match self.level {
                None => Some(m.curve().domain()),
                Some(p) => m
                    .curve()
                    .local_at(p.to_curve()?.steps())
                    .map(LocalCurve::domain),
            },
            ModelRef::ErbsSurface(m) => match self.level {
                None => Some(m.surface().domain()[dir]),
                Some(p) => m
                    .surface()
                    .local_at(p.to_surface()?.steps())
                    .map(|l| l.domain()[dir]),
            },
            _ => None,
        }
    }

    /// The knots of the refined level in the chosen direction.
    fn level_knots<'a>(&self, doc: &'a Document) -> Option<&'a ErbsKnots> {
        match doc.objects[self.object].sampled.model() {
            ModelRef::ErbsCurve(m) => match self.level {
                None => Some(m.curve().knots()),
                Some(p) => match m.curve().local_at(p.to_curve()?.steps())? {
                    LocalCurve::Erbs(e) => Some(e.knots()),
                    LocalCurve::Spline { .. } => None,
                },
            },
            ModelRef::ErbsSurface(m) => match self.level {
                None => Some(&m.surface().knots()[self.dir]),
                Some(p) => match m.surface().local_at(p.to_surface()?.steps())? {
                    LocalPatch::Erbs(e) => Some(&e.knots()[self.dir]),
                    LocalPatch::Spline { .. } => None,
                },
            },
            _ => None,
        }
    }

    /// The object's parameter `t` in the refined level's parameter: the same number, or one
    /// period off where a closed object's local straddles the seam.
    fn level_parameter(&self, doc: &Document, t: f64) -> Result<f64, String> {
        let Some(path) = self.level else {
            return Ok(t);
        };
        let (a, b) = self
            .level_domain(doc)
            .ok_or("the selected local is gone: select a local again")?;
        let period = match doc.objects[self.object].sampled.model() {
            ModelRef::ErbsCurve(m) => m.curve().knots().period(),
            ModelRef::ErbsSurface(m) => m.surface().knots()[self.dir].period(),
            _ => None,
        };
        let shifts = period.map_or(vec![0.0], |p| vec![0.0, -p, p]);
        shifts
            .into_iter()
            .map(|s| t + s)
            .find(|x| *x > a && *x < b)
            .ok_or_else(|| {
                format!(
                    "{axis} = {t:.4} is outside local {} ({axis} in [{a:.4}, {b:.4}]): aim inside it",
                    path,
                    axis = self.axis_name(doc),
                )
            })
    }

    /// "t" on curves, "u" or "v" on surfaces.
    #[must_use]
    pub fn axis_name(&self, doc: &Document) -> &'static str {
        if doc.objects[self.object].sampled.model().is_surface() {
            ["u", "v"][self.dir]
        } else {
            "t"
        }
    }

    /// Which local the refinement adds, for the status line after it: "local 3" of the level.
    #[must_use]
    pub fn new_local(&self, doc: &Document) -> Option<String> {
        let t = self.level_parameter(doc, self.at?).ok()?;
        let i = self.level_knots(doc)?.locate(t) + 1;
        let what = match (
            doc.objects[self.object].sampled.model().is_surface(),
            self.dir,
        ) {
            (false, _) => format!("local {i}"),
            (true, 0) => format!("row {i} of patches"),
            (true, _) => format!("column {i} of patches"),
        };
        Some(match self.level {
            None => what,
            Some(p) => format!("{what} in local {}", p),
        })
    }

    /// Whether the object is an ERBS object (refinement) rather than a B-spline (knot insertion).
    #[must_use]
    pub fn is_erbs(&self, doc: &Document) -> bool {
        matches!(
            doc.objects[self.object].sampled.model(),
            ModelRef::ErbsCurve(_) | ModelRef::ErbsSurface(_)
        )
    }

    /// The status line while aiming.
    #[must_use]
    pub fn describe(&self, doc: &Document) -> String {
        let o = &doc.objects[self.object];
        let surface = o.sampled.model().is_surface();
        let dir = if surface {
            ["u = ", "v = "][self.dir]
        } else {
            "t = "
        };
        let at = self
            .at
            .map_or("aim at the object".into(), |t| format!("{dir}{t:.6}"));
        let keys = if surface {
            "click or Enter inserts, U/V direction, Esc cancels"
        } else {
            "click or Enter inserts, Esc cancels"
        };
        if !self.is_erbs(doc) {
            return format!("insert knot in {}: {at} ({keys})", o.name);
        }
        let level = self
            .level
            .map_or(String::new(), |p| format!(" local {}", p));
        let at = self
            .at
            .map_or("aim at the object".into(), |t| format!("{dir}{t:.4}"));
        let keys = if surface {
            "click/Enter refines, U/V, Esc"
        } else {
            "click/Enter refines, Esc"
        };
        format!("refine {}{level}: {at} ({keys})", o.name)
    }

    /// The preview: the isoline at the parameter (surfaces; across a nested ERBS level only its
    /// support) or a marker on the curve.
    #[must_use]
    pub fn preview(&self, doc: &Document, scale: f64) -> Vec<LineVertex> {
        let Some(t) = self.at else {
            return Vec::new();
        };
        let polyline: Vec<DVec3> = match doc.objects[self.object].sampled.model() {
            ModelRef::Curve(m) => return marker(&m.curve().derivatives(t, 1), scale),
            ModelRef::ErbsCurve(m) => return marker(&m.curve().derivatives(t, 1), scale),
            ModelRef::Surface(m) => {
                let s = m.surface();
                isoline(self.dir, t, s.domain()[1 - self.dir], |u, v| s.eval(u, v))
            }
            ModelRef::ErbsSurface(m) => {
                let s = m.surface();
                let (a, b) = s.domain()[1 - self.dir];
                let range = match self.level.and_then(|p| p.to_surface()) {
                    Some(p) => s.local_at(p.steps()).map_or((a, b), |l| {
                        let (c, d) = l.domain()[1 - self.dir];
                        (c.max(a), d.min(b))
                    }),
                    None => (a, b),
                };
                isoline(self.dir, t, range, |u, v| s.eval(u, v))
            }
            _ => return Vec::new(),
        };
        polyline
            .windows(2)
            .flat_map(|w| [vertex(w[0]), vertex(w[1])])
            .collect()
    }
}

const PREVIEW_COLOR: [u8; 4] = [255, 170, 40, 255];

fn vertex(p: DVec3) -> LineVertex {
    LineVertex {
        pos: p.as_vec3().to_array(),
        color: PREVIEW_COLOR,
    }
}

/// A cross across the curve at a point, from the point and its first derivative.
fn marker(d: &[DVec3], scale: f64) -> Vec<LineVertex> {
    let tangent = d[1].normalize_or_zero();
    let across = tangent.any_orthonormal_vector();
    let r = 0.03 * scale;
    let other = across.cross(tangent);
    [across, other]
        .into_iter()
        .flat_map(|v| [vertex(d[0] - v * r), vertex(d[0] + v * r)])
        .collect()
}

/// The isoparametric line `dir` = t over `(a, b)` in the other direction.
fn isoline(dir: usize, t: f64, (a, b): (f64, f64), eval: impl Fn(f64, f64) -> DVec3) -> Vec<DVec3> {
    (0..ISOLINE_POINTS)
        .map(|k| {
            let x = a + (b - a) * k as f64 / (ISOLINE_POINTS - 1) as f64;
            if dir == 0 { eval(t, x) } else { eval(x, t) }
        })
        .collect()
}

/// The sample projecting nearest the cursor (within `radius` pixels): a coarse search over
/// every 4th sample, then the neighbourhood of the best one.
fn nearest_sample(
    grid: &SampleGrid,
    view: &View,
    cursor: (f64, f64),
    radius: f64,
) -> Option<[usize; 2]> {
    let [rows, cols] = grid.dims;
    let dist = |i: usize, j: usize| {
        view.project(grid.position(i, j))
            .map_or(f64::INFINITY, |(x, y)| (x - cursor.0).hypot(y - cursor.1))
    };
    let step = 4;
    let mut best = (f64::INFINITY, [0, 0]);
    for i in (0..rows).step_by(step) {
        for j in (0..cols).step_by(step) {
            let d = dist(i, j);
            if d < best.0 {
                best = (d, [i, j]);
            }
        }
    }
    let [ci, cj] = best.1;
    for i in ci.saturating_sub(step)..(ci + step + 1).min(rows) {
        for j in cj.saturating_sub(step)..(cj + step + 1).min(cols) {
            let d = dist(i, j);
            if d < best.0 {
                best = (d, [i, j]);
            }
        }
    }
    (best.0 <= radius).then_some(best.1)
}

/// Where the cursor projects onto the screen segment a–b: (s ∈ [0, 1], distance in pixels).
fn segment_parameter(a: (f64, f64), b: (f64, f64), c: (f64, f64)) -> (f64, f64) {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let len2 = dx * dx + dy * dy;
    let s = if len2 > 0.0 {
        (((c.0 - a.0) * dx + (c.1 - a.1) * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (px, py) = (a.0 + dx * s, a.1 + dy * s);
    (s, (px - c.0).hypot(py - c.1))
}

#[cfg(test)]
mod tests {
    use super::segment_parameter;

    #[test]
    fn segment_parameter_projects_and_clamps() {
        let (s, d) = segment_parameter((0.0, 0.0), (10.0, 0.0), (2.5, 3.0));
        assert_eq!((s, d), (0.25, 3.0));
        assert_eq!(
            segment_parameter((0.0, 0.0), (10.0, 0.0), (-5.0, 0.0)).0,
            0.0
        );
        assert_eq!(
            segment_parameter((1.0, 1.0), (1.0, 1.0), (4.0, 5.0)),
            (0.0, 5.0)
        );
    }
}
