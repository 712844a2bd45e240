//! The knot-insertion tool: the parameter under the cursor on one curve or surface (on a
//! surface, of the u or v isoparametric line through the point under the cursor), previewed as
//! a marker or an isoline until it is applied.

use super::tools::View;
use crate::gpu::LineVertex;
use crate::model::{CurveEdit, Edit, KindEdit, ModelRef, SurfaceEdit};
use crate::render::Document;
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
}

impl Refine {
    pub fn new(object: usize) -> Self {
        Self {
            object,
            dir: 0,
            at: None,
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
            ModelRef::CatmullRom(_) | ModelRef::BezierSpline(_) => {
                return Err(format!(
                    "a {} keeps its segments: B converts it to a bspline_curve first",
                    model.type_name()
                ));
            }
            _ => return Err("ERBS objects are not refined by B-spline knot insertion".into()),
        };
        edit.validate(model).map_err(|e| e.to_string())?;
        Ok(Edit {
            object: self.object,
            edit,
        })
    }

    /// The status line while aiming.
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
        format!("insert knot in {}: {at} ({keys})", o.name)
    }

    /// The preview: the isoline at the parameter (surfaces) or a marker on the curve.
    pub fn preview(&self, doc: &Document, scale: f64) -> Vec<LineVertex> {
        let Some(t) = self.at else {
            return Vec::new();
        };
        let color = [255, 170, 40, 255];
        let mut out = Vec::new();
        let mut line = |a: DVec3, b: DVec3| {
            for p in [a, b] {
                out.push(LineVertex {
                    pos: p.as_vec3().to_array(),
                    color,
                });
            }
        };
        match doc.objects[self.object].sampled.model() {
            ModelRef::Curve(m) => {
                let d = m.curve().derivatives(t, 1);
                let tangent = d[1].normalize_or_zero();
                let across = tangent.any_orthonormal_vector();
                let r = 0.03 * scale;
                line(d[0] - across * r, d[0] + across * r);
                line(
                    d[0] - across.cross(tangent) * r,
                    d[0] + across.cross(tangent) * r,
                );
            }
            ModelRef::Surface(m) => {
                let s = m.surface();
                let (a, b) = s.domain()[1 - self.dir];
                let at = |x: f64| {
                    if self.dir == 0 {
                        s.eval(t, x)
                    } else {
                        s.eval(x, t)
                    }
                };
                let pts: Vec<DVec3> = (0..ISOLINE_POINTS)
                    .map(|k| at(a + (b - a) * k as f64 / (ISOLINE_POINTS - 1) as f64))
                    .collect();
                for w in pts.windows(2) {
                    line(w[0], w[1]);
                }
            }
            _ => {}
        }
        out
    }
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
