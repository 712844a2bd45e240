//! Point inversion on surfaces of revolution and linear extrusion, reduced to
//! a Newton inversion on a curve.
//!
//! * Revolution: the foot of `p` lies in `p`'s meridian half-plane, where the
//!   circle swept by `c(v)` shows up as the point `m(v) = (ρ_c(v), z_c(v))`
//!   (distance from and height along the axis). So `v` minimises
//!   `|m(v) − (ρ_p, z_p)|` (Newton on the meridian curve `m`), and `u` is the
//!   angle from `c(v)`'s radial direction to `p`'s, by `atan2`.
//! * Extrusion: `v` enters linearly, so project along `V`: `u` inverts `p`
//!   on the profile projected onto the plane ⟂ `V`, then
//!   `v = (p − c(u))·V / |V|²`.

use glam::DVec3;

use super::error::{AnalyticError, Result, clamp};
use super::invert::{InvertOptions, Raw};
use super::newton::invert_curve;
use super::nurbs::NurbsCurve;
use super::surface::{AnalyticSurface, ParamBox, SurfaceKind};

/// `m(v) = (ρ, z, 0)` and its first two derivatives (ρ'' from the quotient
/// rule on `ρ = |r|`; at `ρ = 0` the one-sided `ρ' = |r'|` is used).
fn meridian(c: [DVec3; 3], a: DVec3, d: DVec3) -> [DVec3; 3] {
    let [c0, c1, c2] = c;
    let w = c0 - a;
    let (z0, z1, z2) = (w.dot(d), c1.dot(d), c2.dot(d));
    let (r0, r1, r2) = (w - z0 * d, c1 - z1 * d, c2 - z2 * d);
    let rho = r0.length();
    let (p1, p2) = if rho > f64::MIN_POSITIVE.sqrt() {
        let p1 = r0.dot(r1) / rho;
        (p1, (r1.dot(r1) + r0.dot(r2) - p1 * p1) / rho)
    } else {
        (r1.length(), 0.0)
    };
    [
        DVec3::new(rho, z0, 0.0),
        DVec3::new(p1, z1, 0.0),
        DVec3::new(p2, z2, 0.0),
    ]
}

/// Size of a profile, for relative tolerances.
fn size(c: &NurbsCurve) -> f64 {
    let lo = c.points.iter().fold(DVec3::INFINITY, |a, &b| a.min(b));
    let hi = c.points.iter().fold(DVec3::NEG_INFINITY, |a, &b| a.max(b));
    (hi - lo).length().max(f64::MIN_POSITIVE)
}

/// Clamps a box side into the profile's domain (the NURBS form does the same).
fn within(dom: [f64; 2], r: [f64; 2]) -> [f64; 2] {
    [clamp(r[0], dom[0], dom[1]), clamp(r[1], dom[0], dom[1])]
}

impl AnalyticSurface {
    /// Raw `(u, v)` of the foot point on a revolution or extrusion.
    pub(crate) fn invert_swept(
        &self,
        p: DVec3,
        range: &ParamBox,
        opts: &InvertOptions,
    ) -> Result<Raw> {
        let fail = || AnalyticError::InvalidNurbs("profile evaluation failed");
        match self.kind() {
            SurfaceKind::Revolution {
                profile,
                axis_point,
                axis_dir,
            } => {
                let (a, d) = (*axis_point, *axis_dir);
                let w = p - a;
                let zp = w.dot(d);
                let rp = w - zp * d;
                let target = DVec3::new(rp.length(), zp, 0.0);
                let scale = size(profile).max(w.length());
                let eps1 = opts.newton.rel_distance * scale;
                let dom = within(profile.domain()?, range.v);
                let f = |t: f64| profile.derivs_unchecked(t).map(|c| meridian(c, a, d));
                let (v, _) =
                    invert_curve(&f, target, profile, dom, eps1, &opts.newton).ok_or_else(fail)?;
                let c = profile.derivs_unchecked(v).ok_or_else(fail)?[0] - a;
                let rc = c - c.dot(d) * d;
                let tiny = 16.0 * f64::EPSILON * (scale + p.length() + a.length());
                let u_free = rc.length() <= tiny || rp.length() <= tiny;
                let u = if u_free {
                    0.0
                } else {
                    rc.cross(rp).dot(d).atan2(rc.dot(rp))
                };
                Ok(Raw { uv: [u, v], u_free })
            }
            SurfaceKind::Extrusion { profile, vector } => {
                let vv = *vector;
                let n = vv / vv.length();
                let flat = |x: DVec3| x - x.dot(n) * n;
                let eps1 = opts.newton.rel_distance * size(profile).max(p.length());
                let dom = within(profile.domain()?, range.u);
                let f = |t: f64| profile.derivs_unchecked(t).map(|c| c.map(flat));
                let (u, _) =
                    invert_curve(&f, flat(p), profile, dom, eps1, &opts.newton).ok_or_else(fail)?;
                let c = profile.derivs_unchecked(u).ok_or_else(fail)?[0];
                Ok(Raw {
                    uv: [u, (p - c).dot(vv) / vv.length_squared()],
                    u_free: false,
                })
            }
            _ => Err(AnalyticError::InvalidNurbs("not a swept surface")),
        }
    }
}
