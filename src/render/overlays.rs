//! Analysis overlays drawn as coloured line lists: surface normals, Frenet frames and curvature
//! combs along curves. Computed from the model and the canonical samples each frame they are
//! shown (a few hundred evaluations).

use super::style::{NetMode, ViewOptions};
use crate::editor::Document;
use crate::geom::Handles;
use crate::geom::differential::frenet_frame;
use crate::geom::knots::uniform_params;
use crate::gpu::LineVertex;
use crate::model::{Model, ModelRef};
use glam::DVec3;

/// Frames drawn per curve.
const FRAMES_PER_CURVE: usize = 24;
/// Teeth of a curvature comb.
const COMB_TEETH: usize = 160;
/// Normals per surface direction (at most).
const NORMALS_PER_DIRECTION: usize = 32;

/// All enabled overlays; `scale` is the scene radius (sets line lengths).
pub fn overlay_lines(doc: &Document, opts: &ViewOptions, scale: f64) -> Vec<LineVertex> {
    let mut out = Vec::new();
    for o in &doc.objects {
        if opts.control_nets != NetMode::Off {
            bezier_points_of_deboor_splines(&mut out, o.sampled.model(), scale);
        }
        let grid = o.sampled.grid();
        if let (true, Some(normals)) = (opts.normals, &grid.normals) {
            let [rows, cols] = grid.dims;
            let (si, sj) = (
                rows.div_ceil(NORMALS_PER_DIRECTION).max(1),
                cols.div_ceil(NORMALS_PER_DIRECTION).max(1),
            );
            for i in (0..rows).step_by(si) {
                for j in (0..cols).step_by(sj) {
                    let p = grid.position(i, j);
                    line(
                        &mut out,
                        p,
                        p + normals[i * cols + j] * (0.04 * scale),
                        [40, 220, 230, 255],
                    );
                }
            }
        }
        let (derivs, (a, b)): (Box<dyn Fn(f64) -> Vec<DVec3>>, _) = match o.sampled.model() {
            ModelRef::Curve(c) => (
                Box::new(move |t| c.curve().derivatives(t, 3)),
                c.curve().domain(),
            ),
            ModelRef::ErbsCurve(c) => (
                Box::new(move |t| c.curve().derivatives(t, 3)),
                c.curve().domain(),
            ),
            m @ (ModelRef::CatmullRom(_) | ModelRef::BezierSpline(_)) => {
                let Some(Model::Curve(chain)) = m.to_bspline_curve() else {
                    continue;
                };
                let domain = chain.curve().domain();
                (Box::new(move |t| chain.curve().derivatives(t, 3)), domain)
            }
            _ => continue,
        };
        if opts.frenet {
            let len = 0.05 * scale;
            for t in uniform_params(a, b, FRAMES_PER_CURVE) {
                let d = derivs(t);
                if let Some(f) = frenet_frame(d[1], d[2], d[3]) {
                    line(&mut out, d[0], d[0] + f.tangent * len, [230, 60, 50, 255]);
                    line(&mut out, d[0], d[0] + f.normal * len, [60, 210, 80, 255]);
                    line(&mut out, d[0], d[0] + f.binormal * len, [70, 120, 240, 255]);
                }
            }
        }
        if opts.curvature_comb {
            let ts = uniform_params(a, b, COMB_TEETH);
            let teeth: Vec<(DVec3, DVec3)> = ts
                .iter()
                .map(|&t| {
                    let d = derivs(t);
                    let dir = frenet_frame(d[1], d[2], d[3])
                        .map_or(DVec3::ZERO, |f| -f.normal * f.curvature);
                    (d[0], dir)
                })
                .collect();
            let max = teeth.iter().map(|(_, v)| v.length()).fold(0.0, f64::max);
            if max > 0.0 {
                let k = 0.15 * scale / max;
                let color = [220, 80, 220, 255];
                for (p, v) in &teeth {
                    line(&mut out, *p, *p + *v * k, color);
                }
                for w in teeth.windows(2) {
                    line(&mut out, w[0].0 + w[0].1 * k, w[1].0 + w[1].1 * k, color);
                }
            }
        }
    }
    out
}

/// The Bézier polygon of a spline edited through de Boor points (C1 quadratic, C2 cubic), with
/// a small cross on each Bézier point: the lecture's A-frame picture next to the de Boor
/// polygon the control net shows.
fn bezier_points_of_deboor_splines(out: &mut Vec<LineVertex>, model: ModelRef<'_>, scale: f64) {
    let ModelRef::BezierSpline(s) = model else {
        return;
    };
    let s = s.spline();
    if s.handle_kind() != Handles::DeBoor {
        return;
    }
    let color = [200, 150, 90, 255];
    for w in s.points().windows(2) {
        line(out, w[0], w[1], color);
    }
    let r = 0.006 * scale;
    for &p in s.points() {
        for d in [DVec3::X, DVec3::Y, DVec3::Z] {
            line(out, p - d * r, p + d * r, color);
        }
    }
}

fn line(out: &mut Vec<LineVertex>, a: DVec3, b: DVec3, color: [u8; 4]) {
    out.push(LineVertex {
        pos: a.as_vec3().to_array(),
        color,
    });
    out.push(LineVertex {
        pos: b.as_vec3().to_array(),
        color,
    });
}
