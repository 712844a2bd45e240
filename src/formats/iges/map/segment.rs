//! Cutting a NURBS surface to a parameter box with clamped knots: each column of control points
//! is a curve in `u` (and each row one in `v`), and knot insertion acts on them one by one with
//! the same knots, so the analytic crate's curve segmentation does the surface too. The
//! parametrisation is unchanged, so trims given in the file's parameters stay valid.

use crate::geom::analytic::{NurbsCurve, NurbsSurface};
use glam::DVec3;

/// `s` restricted to `[u0, u1] × [v0, v1]` (clamped into its domain), with clamped knots.
/// Returns `s` itself (cloned) when nothing needs cutting.
pub(crate) fn cut_surface(
    s: &NurbsSurface,
    u: [f64; 2],
    v: [f64; 2],
) -> Result<NurbsSurface, String> {
    let dom = s.domain().map_err(|e| e.to_string())?;
    let range = |r: [f64; 2], d: [f64; 2]| {
        let (a, b) = (r[0].max(d[0]), r[1].min(d[1]));
        if a.is_finite() && b.is_finite() && a < b {
            [a, b]
        } else {
            d
        }
    };
    let (u, v) = (range(u, dom[0]), range(v, dom[1]));
    let mut out = s.clone();
    if needs_cut(&out.knots[0], out.degree[0], u, dom[0]) {
        out = cut_u(&out, u)?;
    }
    if needs_cut(&out.knots[1], out.degree[1], v, dom[1]) {
        out = transpose(&cut_u(&transpose(&out), v)?);
    }
    out.validate().map_err(|e| e.to_string())?;
    Ok(out)
}

/// Whether the range is smaller than the domain or the knots are not clamped at its ends.
fn needs_cut(knots: &[f64], p: usize, r: [f64; 2], dom: [f64; 2]) -> bool {
    let clamped_lo = knots
        .get(..=p)
        .is_some_and(|k| k.iter().all(|&x| x == dom[0]));
    let n = knots.len();
    let clamped_hi = knots
        .get(n.saturating_sub(p + 1)..)
        .is_some_and(|k| k.iter().all(|&x| x == dom[1]));
    r[0] > dom[0] || r[1] < dom[1] || !clamped_lo || !clamped_hi
}

/// Cuts the `u` direction to `[a, b]`.
fn cut_u(s: &NurbsSurface, [a, b]: [f64; 2]) -> Result<NurbsSurface, String> {
    let nv = s.knots[1].len().saturating_sub(s.degree[1] + 1);
    let nu = s.knots[0].len().saturating_sub(s.degree[0] + 1);
    let mut columns = Vec::with_capacity(nv);
    for j in 0..nv {
        let pick = |i: usize| i * nv + j;
        let column = NurbsCurve {
            degree: s.degree[0],
            knots: s.knots[0].clone(),
            points: (0..nu)
                .filter_map(|i| s.points.get(pick(i)).copied())
                .collect(),
            weights: (0..nu)
                .filter_map(|i| s.weights.get(pick(i)).copied())
                .collect(),
        };
        columns.push(column.segment(a, b).map_err(|e| e.to_string())?);
    }
    let knots = columns
        .first()
        .map(|c| c.knots.clone())
        .ok_or("the surface has no control points")?;
    let new_nu = columns.first().map_or(0, |c| c.points.len());
    let mut points = vec![DVec3::ZERO; new_nu * nv];
    let mut weights = vec![1.0; new_nu * nv];
    for (j, c) in columns.iter().enumerate() {
        for (i, (p, w)) in c.points.iter().zip(&c.weights).enumerate() {
            if let (Some(ps), Some(ws)) = (points.get_mut(i * nv + j), weights.get_mut(i * nv + j))
            {
                *ps = *p;
                *ws = *w;
            }
        }
    }
    Ok(NurbsSurface {
        degree: s.degree,
        knots: [knots, s.knots[1].clone()],
        points,
        weights,
    })
}

/// The same surface with `u` and `v` exchanged.
fn transpose(s: &NurbsSurface) -> NurbsSurface {
    let nu = s.knots[0].len().saturating_sub(s.degree[0] + 1);
    let nv = s.knots[1].len().saturating_sub(s.degree[1] + 1);
    let mut points = Vec::with_capacity(nu * nv);
    let mut weights = Vec::with_capacity(nu * nv);
    for j in 0..nv {
        for i in 0..nu {
            points.push(s.points.get(i * nv + j).copied().unwrap_or_default());
            weights.push(s.weights.get(i * nv + j).copied().unwrap_or(1.0));
        }
    }
    NurbsSurface {
        degree: [s.degree[1], s.degree[0]],
        knots: [s.knots[1].clone(), s.knots[0].clone()],
        points,
        weights,
    }
}
