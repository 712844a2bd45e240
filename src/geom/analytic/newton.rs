//! Newton point inversion (The NURBS Book §6.1, eqs. 6.3–6.8) on curves and
//! NURBS surfaces, started from a coarse sampling of every knot span.
//!
//! Beyond §6.1, for robustness:
//! * the sample density grows with the control polygon's length, and the
//!   starts are the nearest *local minima* of the sampled distance (one per
//!   basin), not just the nearest samples;
//! * a step is halved until it reduces the distance (or, at a foot off the
//!   surface where the distance is flat to rounding, the gradient);
//! * a singular or non-descending Jacobian (a pole, `S_u = 0`) falls back to
//!   Gauss–Newton and then to per-direction steps;
//! * on a domain edge the step pushes against, the edge's 1D Newton step is
//!   taken instead of the stalled projected step.
//!
//! The result is still a local minimum: on folded or self-intersecting
//! surfaces it can miss the global one, which its distance reveals.

use glam::DVec3;

use super::error::{AnalyticError, Result, clamp, finite_vec};
use super::invert::Inversion;
use super::nurbs::{NurbsCurve, NurbsSurface, SurfaceDerivs};

/// Settings for the Newton inversions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonOptions {
    /// ε1 of §6.1 (point coincidence and step size), relative to the size of
    /// the curve/surface.
    pub rel_distance: f64,
    /// ε2 of §6.1 (zero cosine between the error vector and the tangents).
    pub cosine: f64,
    /// Iteration cap per start.
    pub max_iter: usize,
    /// Samples per knot span for the coarse start (≥ 1).
    pub samples_per_span: usize,
    /// How many of the nearest local minima of the sampled distance are
    /// refined by Newton.
    pub starts: usize,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        Self {
            rel_distance: 1e-15,
            cosine: 1e-13,
            max_iter: 50,
            samples_per_span: 6,
            starts: 3,
        }
    }
}

/// Halvings of a step before giving up on it.
const MAX_HALVINGS: usize = 30;

/// Step acceptance: the distance drops, or (near a foot off the surface,
/// where the distance is flat to within its rounding) it stays the same to
/// 1e-10 relative while the gradient `S'·r` drops. Distance alone would stop
/// ~1e-9 short in the parameter.
fn better(dist_new: f64, dist: f64, grad_new: f64, grad: f64) -> bool {
    dist_new < dist || (dist_new <= dist * (1.0 + 1e-10) && grad_new < grad)
}

/// The distinct knot values inside `dom`, with its ends: the span breaks.
fn breaks(knots: &[f64], [lo, hi]: [f64; 2]) -> Vec<f64> {
    let mut b: Vec<f64> = vec![lo];
    b.extend(knots.iter().copied().filter(|&k| k > lo && k < hi));
    b.push(hi);
    b.dedup();
    b
}

/// Coarse sample parameters: every span between [`breaks`] split into
/// `per_span` pieces.
fn samples(knots: &[f64], dom: [f64; 2], per_span: usize) -> Vec<f64> {
    let per = per_span.max(1);
    let b = breaks(knots, dom);
    let mut out = Vec::with_capacity(b.len() * per);
    for w in b.windows(2) {
        if let [a, b] = *w {
            out.extend((0..per).map(|i| a + (b - a) * (i as f64 / per as f64)));
        }
    }
    out.push(dom[1]);
    out
}

/// Samples per span: at least `base`, and enough that a control polygon of
/// length `len` spread over the spans is sampled about every 1/16 of the
/// `extent` (capped at 64), so long thin faces (a wide cone, a sheared
/// extrusion) get a start in every basin.
fn density(len: f64, extent: f64, knots: &[f64], dom: [f64; 2], base: usize) -> usize {
    let spans = breaks(knots, dom).len().saturating_sub(1).max(1) as f64;
    let want = (16.0 * len / (extent * spans)).ceil();
    if want.is_finite() && want > 0.0 {
        (want.min(64.0) as usize).max(base)
    } else {
        base
    }
}

/// Length of a control polygon.
fn polygon_len<'a>(pts: impl Iterator<Item = &'a DVec3> + Clone) -> f64 {
    pts.clone()
        .zip(pts.skip(1))
        .map(|(a, b)| (*b - *a).length())
        .sum()
}

/// The `n` best local minima of distances sampled on a `rows × cols` grid
/// (row-major; a curve is one row): a grid point counts if no 8-neighbour is
/// nearer. Distinct minima lie in distinct Newton basins, so this finds the
/// foot on folded surfaces (a cone across its apex, a profile projected along
/// a nearly tangent extrusion) where the `n` nearest samples may all sit on
/// the wrong sheet.
fn local_minima<T: Copy>(scored: &[(f64, T)], rows: usize, cols: usize, n: usize) -> Vec<T> {
    let at = |i: usize, j: usize| scored.get(i * cols + j).map(|s| s.0);
    let mut minima: Vec<(f64, T)> = Vec::new();
    for i in 0..rows {
        for j in 0..cols {
            let Some(&(d, t)) = scored.get(i * cols + j) else {
                continue;
            };
            let mut lowest = true;
            for (di, dj) in [
                (0, 1),
                (2, 1),
                (1, 0),
                (1, 2),
                (0, 0),
                (0, 2),
                (2, 0),
                (2, 2),
            ] {
                let (Some(a), Some(b)) = ((i + di).checked_sub(1), (j + dj).checked_sub(1)) else {
                    continue;
                };
                if a < rows && b < cols && at(a, b).is_some_and(|o| o < d) {
                    lowest = false;
                }
            }
            if lowest {
                minima.push((d, t));
            }
        }
    }
    minima.sort_by(|a, b| a.0.total_cmp(&b.0));
    minima.into_iter().take(n.max(1)).map(|(_, t)| t).collect()
}

/// Inverts `target` on the curve `f` (value, first, second derivative) over
/// `dom`: coarse samples at `knots`' spans, then eq. 6.3 Newton from the best
/// starts. Returns `(t, distance)`.
pub(crate) fn invert_curve(
    f: &dyn Fn(f64) -> Option<[DVec3; 3]>,
    target: DVec3,
    profile: &NurbsCurve,
    dom: [f64; 2],
    eps1: f64,
    opts: &NewtonOptions,
) -> Option<(f64, f64)> {
    let lo = profile
        .points
        .iter()
        .fold(DVec3::INFINITY, |a, &b| a.min(b));
    let hi = profile
        .points
        .iter()
        .fold(DVec3::NEG_INFINITY, |a, &b| a.max(b));
    let len = polygon_len(profile.points.iter());
    let per = density(
        len,
        (hi - lo).length(),
        &profile.knots,
        dom,
        opts.samples_per_span,
    );
    let mut scored = Vec::new();
    for t in samples(&profile.knots, dom, per) {
        scored.push(((f(t)?[0] - target).length(), t));
    }
    local_minima(&scored, 1, scored.len(), opts.starts)
        .into_iter()
        .filter_map(|t0| newton_curve(f, target, dom, t0, eps1, opts))
        .min_by(|a, b| a.1.total_cmp(&b.1))
}

/// Eq. 6.3 Newton on one curve from `t0`, clamped to `dom`, with the §6.1
/// stopping tests (ε1 on distance and step, ε2 on the cosine).
fn newton_curve(
    f: &dyn Fn(f64) -> Option<[DVec3; 3]>,
    target: DVec3,
    [lo, hi]: [f64; 2],
    t0: f64,
    eps1: f64,
    opts: &NewtonOptions,
) -> Option<(f64, f64)> {
    let mut t = t0;
    let [mut c, mut d1, mut d2] = f(t)?;
    for _ in 0..opts.max_iter {
        let r = c - target;
        let dist = r.length();
        let speed = d1.length();
        if dist <= eps1 || speed == 0.0 || d1.dot(r).abs() <= opts.cosine * speed * dist {
            break;
        }
        let g = d1.dot(r);
        let h = d2.dot(r) + speed * speed;
        let step = if h > 0.0 {
            -g / h
        } else {
            -g / (speed * speed)
        };
        let mut accepted = None;
        let mut lambda = 1.0;
        for _ in 0..MAX_HALVINGS {
            let tn = clamp(t + lambda * step, lo, hi);
            let e = f(tn)?;
            let rn = e[0] - target;
            if better(rn.length(), dist, e[1].dot(rn).abs(), g.abs()) {
                accepted = Some((tn, e));
                break;
            }
            lambda *= 0.5;
        }
        let Some((tn, e)) = accepted else { break };
        let moved = ((tn - t) * speed).abs();
        (t, [c, d1, d2]) = (tn, e);
        if moved <= eps1 {
            break;
        }
    }
    Some((t, (c - target).length()))
}

/// Solves the 2×2 system `m x = k`, `None` if (nearly) singular.
fn solve2([[a, b], [c, d]]: [[f64; 2]; 2], [k0, k1]: [f64; 2]) -> Option<[f64; 2]> {
    let det = a * d - b * c;
    let scale = (a * d).abs().max((b * c).abs());
    if !det.is_finite() || det.abs() <= 1e-14 * scale || det == 0.0 {
        return None;
    }
    Some([(k0 * d - b * k1) / det, (a * k1 - c * k0) / det])
}

/// 1D Newton step `−g / (|S'|² + r·S'')`, Gauss–Newton if not convex.
fn one_dir(g: f64, speed2: f64, curv: f64) -> f64 {
    let h = speed2 + curv;
    if h > 0.0 {
        -g / h
    } else if speed2 > 0.0 {
        -g / speed2
    } else {
        0.0
    }
}

/// Whether moving `x` by `step` leaves `[lo, hi]` from its boundary.
fn pushes_out(x: f64, [lo, hi]: [f64; 2], step: f64) -> bool {
    (x <= lo && step < 0.0) || (x >= hi && step > 0.0)
}

/// The §6.1 Newton step (eq. 6.6–6.7), falling back to Gauss–Newton and then
/// to independent steps when the Jacobian is singular or not a descent. On a
/// domain edge that the step pushes against, the edge's own 1D Newton step
/// is taken instead (a projected step would stall there); `None` when no
/// step can leave the current point (a corner or edge minimum).
fn surface_step(d: &SurfaceDerivs, r: DVec3, uv: [f64; 2], dom: [[f64; 2]; 2]) -> Option<[f64; 2]> {
    let (uu, uv_, vv) = (d.su.dot(d.su), d.su.dot(d.sv), d.sv.dot(d.sv));
    let g = [d.su.dot(r), d.sv.dot(r)];
    let rhs = [-g[0], -g[1]];
    let newton = [
        [uu + r.dot(d.suu), uv_ + r.dot(d.suv)],
        [uv_ + r.dot(d.suv), vv + r.dot(d.svv)],
    ];
    let descent = |s: &[f64; 2]| s[0] * g[0] + s[1] * g[1] < 0.0;
    let step = solve2(newton, rhs)
        .filter(descent)
        .or_else(|| solve2([[uu, uv_], [uv_, vv]], rhs).filter(descent))
        .unwrap_or([one_dir(g[0], uu, 0.0), one_dir(g[1], vv, 0.0)]);
    let [[u0, u1], [v0, v1]] = dom;
    let blocked_u = pushes_out(uv[0], [u0, u1], step[0]);
    let blocked_v = pushes_out(uv[1], [v0, v1], step[1]);
    let edge =
        |t: f64, x: f64, range: [f64; 2]| (t != 0.0 && !pushes_out(x, range, t)).then_some(t);
    match (blocked_u, blocked_v) {
        (false, false) => Some(step),
        (true, true) => None,
        (true, false) => edge(one_dir(g[1], vv, r.dot(d.svv)), uv[1], [v0, v1]).map(|t| [0.0, t]),
        (false, true) => edge(one_dir(g[0], uu, r.dot(d.suu)), uv[0], [u0, u1]).map(|t| [t, 0.0]),
    }
}

/// Eqs. 6.6–6.8 Newton on a validated surface from `start`, clamped to
/// `dom`, with the §6.1 stopping tests.
fn newton_surface(
    s: &NurbsSurface,
    target: DVec3,
    dom: [[f64; 2]; 2],
    start: [f64; 2],
    eps1: f64,
    opts: &NewtonOptions,
) -> Option<([f64; 2], f64)> {
    let [[u0, u1], [v0, v1]] = dom;
    let mut uv = start;
    let mut d = s.derivs_unchecked(uv[0], uv[1])?;
    let cos_ok = |t: DVec3, r: DVec3, dist: f64| t.dot(r).abs() <= opts.cosine * t.length() * dist;
    for _ in 0..opts.max_iter {
        let r = d.p - target;
        let dist = r.length();
        if dist <= eps1 || (cos_ok(d.su, r, dist) && cos_ok(d.sv, r, dist)) {
            break;
        }
        let Some(step) = surface_step(&d, r, uv, dom) else {
            break;
        };
        let grad = d.su.dot(r).hypot(d.sv.dot(r));
        let mut accepted = None;
        let mut lambda = 1.0;
        for _ in 0..MAX_HALVINGS {
            let un = clamp(uv[0] + lambda * step[0], u0, u1);
            let vn = clamp(uv[1] + lambda * step[1], v0, v1);
            let e = s.derivs_unchecked(un, vn)?;
            let rn = e.p - target;
            if better(rn.length(), dist, e.su.dot(rn).hypot(e.sv.dot(rn)), grad) {
                accepted = Some(([un, vn], e));
                break;
            }
            lambda *= 0.5;
        }
        let Some((next, e)) = accepted else { break };
        let moved = ((next[0] - uv[0]) * d.su + (next[1] - uv[1]) * d.sv).length();
        (uv, d) = (next, e);
        if moved <= eps1 {
            break;
        }
    }
    Some((uv, (d.p - target).length()))
}

/// [`density`] along `u` and `v` from the longest row/column of the net.
fn net_density(s: &NurbsSurface, base: usize) -> Result<[usize; 2]> {
    let [du, dv] = s.domain()?;
    let nv = s.knots[1].len().saturating_sub(s.degree[1] + 1).max(1);
    let rows: Vec<&[DVec3]> = s.points.chunks(nv).collect();
    let along_v = rows
        .iter()
        .map(|r| polygon_len(r.iter()))
        .fold(0.0, f64::max);
    let along_u = (0..nv)
        .map(|j| polygon_len(rows.iter().filter_map(move |r| r.get(j))))
        .fold(0.0, f64::max);
    let extent = s.extent();
    Ok([
        density(along_u, extent, &s.knots[0], du, base),
        density(along_v, extent, &s.knots[1], dv, base),
    ])
}

/// Newton point inversion on a NURBS surface (The NURBS Book §6.1): a coarse
/// grid over every knot span picks the starts, iterates are clamped to the
/// domain, convergence is tested on distance (ε1), cosines (ε2) and step
/// length. `uv` of the result is in the surface's own parameters; `inside` is
/// always true; `u_free` flags a degenerate `S_u` (a pole) at the foot.
///
/// # Errors
/// Invalid surface or non-finite point.
pub fn invert_nurbs(surface: &NurbsSurface, p: DVec3, opts: &NewtonOptions) -> Result<Inversion> {
    finite_vec(p, "point to invert")?;
    let dom = surface.domain()?;
    let [du, dv] = dom;
    let eps1 = opts.rel_distance * surface.extent().max(f64::MIN_POSITIVE);
    let fail = AnalyticError::InvalidNurbs("evaluation failed");
    let [per_u, per_v] = net_density(surface, opts.samples_per_span)?;
    let us = samples(&surface.knots[0], du, per_u);
    let vs = samples(&surface.knots[1], dv, per_v);
    let mut scored = Vec::with_capacity(us.len() * vs.len());
    for &u in &us {
        for &v in &vs {
            let q = surface.point_unchecked(u, v).ok_or_else(|| fail.clone())?;
            scored.push(((q - p).length(), [u, v]));
        }
    }
    let (uv, distance) = local_minima(&scored, us.len(), vs.len(), opts.starts)
        .into_iter()
        .filter_map(|st| newton_surface(surface, p, dom, st, eps1, opts))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .ok_or_else(|| fail.clone())?;
    let d = surface.derivs_unchecked(uv[0], uv[1]).ok_or(fail)?;
    Ok(Inversion {
        uv,
        point: d.p,
        distance,
        inside: true,
        on_seam: [false, false],
        u_free: d.su.length() <= 1e-12 * d.sv.length().max(eps1),
    })
}
