//! Point inversion onto a face's surface, and where a surface's parametrisation is periodic or
//! singular.
//!
//! Elementary surfaces use the analytic crate's closed-form inversion. Swept surfaces use
//! Newton on the profile from a nearby point's parameters (the meridian of a revolution, the
//! profile projected along an extrusion), else the crate's global inversion. B-spline surfaces
//! use Gauss–Newton (The NURBS Book §6.1 with the first-order normal equations, which converge
//! quadratically for a point on the surface) started from a nearby point of the same edge —
//! running on across the seam of a closed direction instead of clamping — and for the first
//! point of a loop, or when the local iteration stops on the domain's edge far from the point,
//! a global start: the nearest points of a grid over every knot span (made once per surface),
//! then the analytic crate's finer search if those do not land on the surface.

use crate::formats::step::map::attrs::at;
use crate::geom::analytic::{InvertOptions, NewtonOptions, ParamBox, SurfaceKind, invert_nurbs};
use glam::{DVec2, DVec3};

use super::nurbs::{D1, FastSurface};
use super::surface::{Geometry, Inv, NurbsSurface2, Surface};

/// A line of the parameter plane where one parameter is arbitrary: `param[dir] == at`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Pole {
    /// The parameter that is constant along the line (1 for a sphere's poles `v = ±π/2`).
    pub dir: usize,
    pub at: f64,
}

/// Relative size below which a partial derivative counts as zero (a pole).
const DEGENERATE: f64 = 1e-9;

impl Surface {
    /// Inverts `p`; `hint` is a nearby parameter pair (the previous point of an edge) that a
    /// B-spline inversion starts from.
    #[must_use]
    pub(crate) fn invert(&self, p: DVec3, hint: Option<DVec2>) -> Option<Inv> {
        match &self.geom {
            Geometry::Analytic(a) => {
                let pi = std::f64::consts::PI;
                let half = std::f64::consts::FRAC_PI_2;
                let (u, v) = match a.kind() {
                    SurfaceKind::Sphere { .. } => ([-pi, pi], [-half, half]),
                    SurfaceKind::Torus { .. } => ([-pi, pi], [-pi, pi]),
                    SurfaceKind::Revolution { profile, .. } => ([-pi, pi], profile.domain().ok()?),
                    SurfaceKind::Extrusion { profile, .. } => (profile.domain().ok()?, [-1.0, 1.0]),
                    _ => ([-pi, pi], [-1.0, 1.0]),
                };
                if let Some(local) = hint.and_then(|h| swept_local(a, p, h)) {
                    return Some(local);
                }
                let opts = InvertOptions::default();
                let inv = a.invert(p, &ParamBox { u, v }, &opts).ok()?;
                Some(Inv {
                    uv: DVec2::from(inv.uv),
                    free: [inv.u_free, false],
                    distance: inv.distance,
                })
            }
            Geometry::Nurbs(n) => invert_bspline(n, p, hint, self.periods),
        }
    }

    /// The singular lines of the parametrisation (see [`Pole`]).
    #[must_use]
    pub(crate) fn poles(&self) -> Vec<Pole> {
        match &self.geom {
            Geometry::Analytic(a) => match *a.kind() {
                SurfaceKind::Sphere { .. } => {
                    let h = std::f64::consts::FRAC_PI_2;
                    vec![Pole { dir: 1, at: -h }, Pole { dir: 1, at: h }]
                }
                SurfaceKind::Cone { radius, semi_angle } if semi_angle != 0.0 => {
                    vec![Pole {
                        dir: 1,
                        at: -radius / semi_angle.tan(),
                    }]
                }
                SurfaceKind::Torus { major, minor } if minor > major => {
                    let v = (-major / minor).acos();
                    vec![Pole { dir: 1, at: v }, Pole { dir: 1, at: -v }]
                }
                SurfaceKind::Revolution {
                    ref profile,
                    axis_point,
                    axis_dir,
                } => {
                    let Ok([lo, hi]) = profile.domain() else {
                        return Vec::new();
                    };
                    let size = profile_size(profile);
                    [lo, hi]
                        .into_iter()
                        .filter(|&t| {
                            profile.point(t).is_ok_and(|q| {
                                let w = q - axis_point;
                                (w - w.dot(axis_dir) * axis_dir).length() <= DEGENERATE * size
                            })
                        })
                        .map(|at| Pole { dir: 1, at })
                        .collect()
                }
                _ => Vec::new(),
            },
            Geometry::Nurbs(n) => nurbs_poles(&n.fast),
        }
    }
}

/// Newton on the profile of a swept surface from the hint's profile parameter (the analytic
/// crate's reduction: a revolution's meridian curve `(ρ(v), z(v))` against the point's, an
/// extrusion's profile projected along the extrusion); `None` if it does not converge onto
/// the surface (to 1e-4 of the profile's size), so that the global inversion runs.
#[must_use]
fn swept_local(a: &crate::geom::analytic::AnalyticSurface, p: DVec3, hint: DVec2) -> Option<Inv> {
    match a.kind() {
        SurfaceKind::Revolution {
            profile,
            axis_point,
            axis_dir,
        } => {
            let (ax, d) = (*axis_point, *axis_dir);
            let w = p - ax;
            let zp = w.dot(d);
            let rp = w - zp * d;
            let target = DVec3::new(rp.length(), zp, 0.0);
            let meridian = |t: f64| -> Option<[DVec3; 3]> {
                let [c0, c1, c2] = profile.derivs(t).ok()?;
                let r0 = c0 - ax - (c0 - ax).dot(d) * d;
                let (r1, r2) = (c1 - c1.dot(d) * d, c2 - c2.dot(d) * d);
                let rho = r0.length();
                let (p1, p2) = if rho > 1e-300 {
                    let p1 = r0.dot(r1) / rho;
                    (p1, (r1.dot(r1) + r0.dot(r2) - p1 * p1) / rho)
                } else {
                    (r1.length(), 0.0)
                };
                let z = |x: DVec3, v: f64| DVec3::new(x.length(), v, 0.0);
                Some([
                    z(r0, (c0 - ax).dot(d)),
                    DVec3::new(p1, c1.dot(d), 0.0),
                    DVec3::new(p2, c2.dot(d), 0.0),
                ])
            };
            let v = curve_newton(&meridian, target, hint.y, profile)?;
            let c = profile.point(v).ok()? - ax;
            let rc = c - c.dot(d) * d;
            let size = profile_size(profile);
            let free = rc.length() <= DEGENERATE * size || rp.length() <= DEGENERATE * size;
            let u = if free {
                hint.x
            } else {
                rc.cross(rp).dot(d).atan2(rc.dot(rp))
            };
            let q = a.point(u, v).ok()?;
            let distance = (q - p).length();
            (distance <= 1e-4 * size).then_some(Inv {
                uv: DVec2::new(u, v),
                free: [free, false],
                distance,
            })
        }
        SurfaceKind::Extrusion { profile, vector } => {
            let n = vector.normalize();
            let flat = |x: DVec3| x - x.dot(n) * n;
            let f = |t: f64| profile.derivs(t).ok().map(|c| c.map(flat));
            let u = curve_newton(&f, flat(p), hint.x, profile)?;
            let c = profile.point(u).ok()?;
            let v = (p - c).dot(*vector) / vector.length_squared();
            let distance = (c + v * *vector - p).length();
            (distance <= 1e-4 * profile_size(profile)).then_some(Inv {
                uv: DVec2::new(u, v),
                free: [false, false],
                distance,
            })
        }
        _ => None,
    }
}

/// Newton on `min |f(t) − target|` from `t0` (value, first and second derivative of `f`),
/// iterates clamped to the profile's domain; `None` unless the steps shrink to 1e-13 of it.
#[must_use]
fn curve_newton(
    f: &dyn Fn(f64) -> Option<[DVec3; 3]>,
    target: DVec3,
    t0: f64,
    profile: &crate::geom::analytic::NurbsCurve,
) -> Option<f64> {
    let [lo, hi] = profile.domain().ok()?;
    let mut t = t0.clamp(lo, hi);
    for _ in 0..30 {
        let [c0, c1, c2] = f(t)?;
        let r = c0 - target;
        let g = r.dot(c1);
        let h = c1.dot(c1) + r.dot(c2);
        if h <= 0.0 {
            return None;
        }
        let next = (t - g / h).clamp(lo, hi);
        let step = (next - t).abs();
        t = next;
        if step <= 1e-13 * (hi - lo) {
            return Some(t);
        }
    }
    None
}

/// The size of a profile's control polygon.
#[must_use]
fn profile_size(c: &crate::geom::analytic::NurbsCurve) -> f64 {
    let lo = c.points.iter().fold(DVec3::INFINITY, |a, &b| a.min(b));
    let hi = c.points.iter().fold(DVec3::NEG_INFINITY, |a, &b| a.max(b));
    (hi - lo).length().max(f64::MIN_POSITIVE)
}

/// Gauss–Newton from `hint`, checked against the global inversion (see the module doc): a
/// local foot is kept when the iteration converged to a foot (the error orthogonal to the
/// surface, or on the domain's edge) within the files' tolerances, or, farther, when it
/// converged at all: a point of an edge next to the previous one has its foot next to the
/// previous foot, however far the edge strays from the surface.
#[must_use]
fn invert_bspline(
    n: &NurbsSurface2,
    p: DVec3,
    hint: Option<DVec2>,
    periods: [Option<f64>; 2],
) -> Option<Inv> {
    let size = n.size;
    let local = hint.and_then(|h| newton(&n.fast, p, h, periods));
    let best = match local {
        Some(r) if r.1 <= 1e-3 * size || (r.2 && !on_edge(&n.fast, r.0, periods)) => {
            (r.0, r.1, Some(r.3))
        }
        _ => {
            let global = global(n, p, periods)?;
            match local {
                Some(l) if l.1 <= global.1 => (l.0, l.1, Some(l.3)),
                _ => global,
            }
        }
    };
    let d = match best.2 {
        Some(d) => d,
        None => {
            let w = wrap(&n.fast, best.0, periods);
            n.fast.d1(w.x, w.y)?
        }
    };
    let scale = d.su.length().max(d.sv.length()).max(f64::MIN_POSITIVE);
    Some(Inv {
        uv: best.0,
        free: [
            d.su.length() <= DEGENERATE * scale,
            d.sv.length() <= DEGENERATE * scale,
        ],
        distance: best.1,
    })
}

/// Samples per knot span, and at most per direction, of the start grid of a global inversion.
const GRID_PER_SPAN: usize = 4;
const GRID_MAX: usize = 64;

/// A global inversion: Newton from the nearest few points of a grid over every knot span
/// (made once per surface), and the analytic crate's inversion (a finer search) when none of
/// them lands on the surface.
#[must_use]
fn global(
    n: &NurbsSurface2,
    p: DVec3,
    periods: [Option<f64>; 2],
) -> Option<(DVec2, f64, Option<D1>)> {
    let grid = n.grid.get_or_init(|| start_grid(&n.fast, &n.surface.knots));
    let mut near: Vec<(f64, DVec2)> = grid
        .iter()
        .map(|(uv, q)| ((*q - p).length_squared(), *uv))
        .collect();
    let k = near.len().min(3);
    if k > 0 {
        near.select_nth_unstable_by(k - 1, |a, b| a.0.total_cmp(&b.0));
    }
    let mut best: Option<(DVec2, f64, Option<D1>)> = None;
    for &(_, start) in near.iter().take(k) {
        if let Some(r) = newton(&n.fast, p, start, periods)
            && best.is_none_or(|b| r.1 < b.1)
        {
            best = Some((r.0, r.1, Some(r.3)));
        }
    }
    if best.is_some_and(|b| b.1 <= 1e-6 * n.size) {
        return best;
    }
    let g = invert_nurbs(&n.surface, p, &NewtonOptions::default()).ok()?;
    let refined = newton(&n.fast, p, DVec2::from(g.uv), periods)
        .map_or((DVec2::from(g.uv), g.distance, None), |r| {
            (r.0, r.1, Some(r.3))
        });
    Some(match best {
        Some(b) if b.1 <= refined.1 => b,
        _ => refined,
    })
}

/// Parameters and points of a grid with [`GRID_PER_SPAN`] intervals per knot span.
#[must_use]
fn start_grid(s: &FastSurface, knots: &[Vec<f64>; 2]) -> Vec<(DVec2, DVec3)> {
    let dom = s.domain();
    let axis = |d: usize| -> Vec<f64> {
        let [lo, hi] = *at(&dom, d);
        let mut b: Vec<f64> = at(knots, d)
            .iter()
            .copied()
            .filter(|&k| k > lo && k < hi)
            .collect();
        b.dedup();
        let per = (GRID_MAX / (b.len() + 1)).clamp(1, GRID_PER_SPAN);
        let mut ends = vec![lo];
        ends.extend(b);
        ends.push(hi);
        let mut out: Vec<f64> = Vec::with_capacity(ends.len() * per);
        for w in ends.windows(2) {
            if let [a, b] = *w {
                out.extend((0..per).map(|i| a + (b - a) * (i as f64 / per as f64)));
            }
        }
        out.push(hi);
        out
    };
    let (us, vs) = (axis(0), axis(1));
    let mut out = Vec::with_capacity(us.len() * vs.len());
    for &u in &us {
        for &v in &vs {
            if let Some(d) = s.d1(u, v) {
                out.push((DVec2::new(u, v), d.p));
            }
        }
    }
    out
}

/// Gauss–Newton on `|S(u, v) − p|²` from `start`, steps halved while they do not reduce the
/// distance, iterates clamped to the domain; a singular normal matrix (a pole) falls back to
/// steps along the non-degenerate direction. Returns the foot, its distance, whether it
/// converged, and the point and partials there (callers need them, and evaluating them again
/// was a fifth of a STEP part's load).
#[must_use]
fn newton(
    s: &FastSurface,
    p: DVec3,
    start: DVec2,
    periods: [Option<f64>; 2],
) -> Option<(DVec2, f64, bool, D1)> {
    let [du, dv] = s.domain();
    // Closed directions run on across the seam (evaluated one period back); others clamp.
    let clamp = |q: DVec2| {
        DVec2::new(
            if periods[0].is_some() {
                q.x
            } else {
                q.x.clamp(du[0], du[1])
            },
            if periods[1].is_some() {
                q.y
            } else {
                q.y.clamp(dv[0], dv[1])
            },
        )
    };
    let at = |q: DVec2| {
        let w = wrap(s, q, periods);
        s.d1(w.x, w.y)
    };
    let mut uv = clamp(start);
    let mut d = at(uv)?;
    let mut dist = (d.p - p).length();
    let mut converged = false;
    for _ in 0..20 {
        let r = d.p - p;
        let (a, b, c) = (d.su.dot(d.su), d.su.dot(d.sv), d.sv.dot(d.sv));
        let (gu, gv) = (d.su.dot(r), d.sv.dot(r));
        let det = a * c - b * b;
        let step = if det > 1e-12 * a * c && det > 0.0 {
            DVec2::new((c * gu - b * gv) / det, (a * gv - b * gu) / det)
        } else if a >= c && a > 0.0 {
            DVec2::new(gu / a, 0.0)
        } else if c > 0.0 {
            DVec2::new(0.0, gv / c)
        } else {
            break;
        };
        // A step below 1e-10 of the domain moves the foot far less than any trim tolerance.
        let tiny =
            |q: DVec2| q.x.abs() <= 1e-10 * (du[1] - du[0]) && q.y.abs() <= 1e-10 * (dv[1] - dv[0]);
        if tiny(step) {
            converged = true;
            break;
        }
        let mut lambda = 1.0;
        let mut moved = None;
        for _ in 0..12 {
            let next = clamp(uv - lambda * step);
            let e = at(next)?;
            let nd = (e.p - p).length();
            if nd < dist || (nd <= dist && next != uv) {
                moved = Some((next, e, nd));
                break;
            }
            lambda *= 0.5;
        }
        let Some((next, e, nd)) = moved else {
            converged = true;
            break;
        };
        let shift = next - uv;
        (uv, d, dist) = (next, e, nd);
        if tiny(shift) {
            converged = true;
            break;
        }
        let r = d.p - p;
        let cosine = |t: DVec3| t.dot(r).abs() / (t.length() * r.length()).max(f64::MIN_POSITIVE);
        if r.length() <= 1e-15 * (d.p.length() + 1.0)
            || (cosine(d.su) < 1e-9 && cosine(d.sv) < 1e-9)
        {
            converged = true;
            break;
        }
    }
    Some((uv, dist, converged, d))
}

/// `q` moved by whole periods into the domain in the closed directions.
#[must_use]
fn wrap(s: &FastSurface, q: DVec2, periods: [Option<f64>; 2]) -> DVec2 {
    let [du, dv] = s.domain();
    let w = |x: f64, lo: f64, p: Option<f64>| match p {
        Some(p) if p > 0.0 => lo + (x - lo).rem_euclid(p),
        _ => x,
    };
    DVec2::new(w(q.x, du[0], periods[0]), w(q.y, dv[0], periods[1]))
}

/// Whether `q` lies on the edge of the domain in a direction that is not closed.
#[must_use]
fn on_edge(s: &FastSurface, q: DVec2, periods: [Option<f64>; 2]) -> bool {
    let [du, dv] = s.domain();
    let at = |x: f64, r: [f64; 2], p: Option<f64>| {
        p.is_none()
            && ((x - r[0]).abs() <= 1e-12 * (r[1] - r[0])
                || (x - r[1]).abs() <= 1e-12 * (r[1] - r[0]))
    };
    at(q.x, du, periods[0]) || at(q.y, dv, periods[1])
}

/// Directions in which a B-spline surface closes on itself (its ends coincide along the whole
/// boundary, sampled at 9 points, to 1e-9 of its size); the period is the domain's length.
#[must_use]
pub(crate) fn nurbs_periods(s: &FastSurface) -> [Option<f64>; 2] {
    let dom = s.domain();
    let size = extent(s);
    let closed = |dir: usize| -> Option<f64> {
        let (along, across) = (*at(&dom, dir), *at(&dom, 1 - dir));
        for k in 0..9 {
            let t = across[0] + (across[1] - across[0]) * (k as f64 / 8.0);
            let at = |x: f64| if dir == 0 { s.d1(x, t) } else { s.d1(t, x) };
            let (a, b) = (at(along[0])?.p, at(along[1])?.p);
            if (a - b).length() > DEGENERATE * size {
                return None;
            }
        }
        Some(along[1] - along[0])
    };
    [closed(0), closed(1)]
}

/// Boundary lines of a B-spline surface that collapse to a point (a pole of a spherical patch).
#[must_use]
pub(crate) fn nurbs_poles(s: &FastSurface) -> Vec<Pole> {
    let dom = s.domain();
    let size = extent(s);
    let mut out = Vec::new();
    for dir in 0..2 {
        for &at in at(&dom, dir) {
            let across = *crate::formats::step::map::attrs::at(&dom, 1 - dir);
            let at_t = |t: f64| if dir == 0 { s.d1(at, t) } else { s.d1(t, at) };
            let Some(first) = at_t(across[0]) else {
                continue;
            };
            let collapsed = (1..=8).all(|k| {
                let t = across[0] + (across[1] - across[0]) * (k as f64 / 8.0);
                at_t(t).is_some_and(|q| (q.p - first.p).length() <= DEGENERATE * size)
            });
            if collapsed {
                out.push(Pole { dir, at });
            }
        }
    }
    out
}

/// The diagonal of a B-spline surface's sampled box (a scale for relative tolerances).
#[must_use]
fn extent(s: &FastSurface) -> f64 {
    let [du, dv] = s.domain();
    let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for i in 0..=8 {
        for j in 0..=8 {
            let u = du[0] + (du[1] - du[0]) * (i as f64 / 8.0);
            let v = dv[0] + (dv[1] - dv[0]) * (j as f64 / 8.0);
            if let Some(d) = s.d1(u, v) {
                lo = lo.min(d.p);
                hi = hi.max(d.p);
            }
        }
    }
    (hi - lo).length().max(f64::MIN_POSITIVE)
}
