//! Model-space points onto a face's surface: the analytic crate's closed forms for the analytic
//! kinds (angles then carried continuously along the boundary), and a warm-started Newton
//! iteration on the NURBS (The NURBS Book §6.1, eqs. 6.3–6.8) for 128 and 114, falling back to
//! the analytic crate's global inversion when the local one does not land on the surface.

use crate::geom::analytic::{InvertOptions, NewtonOptions, NurbsSurface, ParamBox, invert_nurbs};
use glam::{DVec2, DVec3};

use super::fail::{Mapped, geometry};
use super::surfaces::AnalyticSupport;

/// A foot point: parameters in the inverter's space and the 3D distance to it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Foot {
    pub uv: DVec2,
    pub distance: f64,
}

/// Moves angle `x` by whole turns to the representative nearest `reference`.
#[must_use]
pub(crate) fn nearest_turn(x: f64, reference: f64) -> f64 {
    x + ((reference - x) / std::f64::consts::TAU).round() * std::f64::consts::TAU
}

/// Inverts `p` onto the analytic support over `range`; angular parameters are moved next to
/// `reference` (continuity along a boundary), and a free `u` (axis, pole, apex) takes the
/// reference's.
pub(crate) fn invert_analytic(
    s: &AnalyticSupport,
    p: DVec3,
    range: &ParamBox,
    reference: Option<DVec2>,
) -> Mapped<Foot> {
    let inv = geometry(
        s.surf.invert(p, range, &InvertOptions::default()),
        "boundary point inversion",
    )?;
    let [ang_u, ang_v] = s.surf.angular();
    let mut uv = DVec2::from_array(inv.uv);
    if let Some(r) = reference {
        if inv.u_free {
            uv.x = r.x;
        } else if ang_u {
            uv.x = nearest_turn(uv.x, r.x);
        }
        if ang_v {
            uv.y = nearest_turn(uv.y, r.y);
        }
    }
    Ok(Foot {
        uv,
        distance: inv.distance,
    })
}

/// Inverts `p` onto a NURBS surface, starting from `reference` when given.
pub(crate) fn invert_surface(
    s: &NurbsSurface,
    dom: [[f64; 2]; 2],
    p: DVec3,
    reference: Option<DVec2>,
    scale: f64,
) -> Mapped<Foot> {
    if let Some(start) = reference
        && let Some(foot) = newton(s, dom, p, start, scale)
        && foot.distance <= 1e-6 * scale
    {
        return Ok(foot);
    }
    let opts = NewtonOptions::default();
    let global = geometry(invert_nurbs(s, p, &opts), "boundary point inversion")?;
    let global = Foot {
        uv: DVec2::from_array(global.uv),
        distance: global.distance,
    };
    let local = reference.and_then(|start| newton(s, dom, p, start, scale));
    Ok(match local {
        Some(l) if l.distance <= global.distance * (1.0 + 1e-9) => l,
        _ => global,
    })
}

/// Newton's method on `f(u, v) = |S(u, v) − p|² / 2` from `start`, kept inside the domain;
/// Gauss–Newton where the Hessian is not positive definite.
fn newton(
    s: &NurbsSurface,
    dom: [[f64; 2]; 2],
    p: DVec3,
    start: DVec2,
    scale: f64,
) -> Option<Foot> {
    let clamp = |uv: DVec2| {
        DVec2::new(
            uv.x.clamp(dom[0][0], dom[0][1]),
            uv.y.clamp(dom[1][0], dom[1][1]),
        )
    };
    let mut uv = clamp(start);
    let mut d = s.derivs(uv.x, uv.y).ok()?;
    let span = DVec2::new(dom[0][1] - dom[0][0], dom[1][1] - dom[1][0]);
    for _ in 0..30 {
        let r = d.p - p;
        let g = DVec2::new(d.su.dot(r), d.sv.dot(r));
        let (a, b, c) = (d.su.dot(d.su), d.su.dot(d.sv), d.sv.dot(d.sv));
        let (mut h11, mut h12, mut h22) = (a + d.suu.dot(r), b + d.suv.dot(r), c + d.svv.dot(r));
        if h11 <= 0.0 || h11 * h22 - h12 * h12 <= 0.0 {
            (h11, h12, h22) = (a, b, c);
        }
        let det = h11 * h22 - h12 * h12;
        if !(det.is_finite() && det > 0.0) {
            break;
        }
        let step = DVec2::new(h22 * g.x - h12 * g.y, h11 * g.y - h12 * g.x) / det;
        let next = clamp(uv - step);
        let moved = ((next - uv) / span).abs().max_element();
        let dn = s.derivs(next.x, next.y).ok()?;
        if (dn.p - p).length() > r.length() * (1.0 + 1e-12) + 1e-15 * scale {
            break;
        }
        (uv, d) = (next, dn);
        if moved <= 1e-15 {
            break;
        }
    }
    Some(Foot {
        uv,
        distance: (d.p - p).length(),
    })
}
