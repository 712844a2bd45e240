//! Point inversion: 3D point → analytic `(u, v)` of an [`AnalyticSurface`].
//!
//! Planes, cylinders, cones, spheres and tori are inverted in closed form:
//! the foot of the perpendicular lies in the meridian plane through the
//! point, so the angle is an `atan2` and the rest is a 2D projection onto a
//! line (cone) or circle (sphere, torus). Where the meridian plane holds two
//! generators (cone across its apex, degenerate torus) both are tried.
//! Revolutions and extrusions reduce to a curve inversion (see `swept`).
//!
//! Angles are unwrapped into the face's range with [`unwrap_angle`].

use std::f64::consts::{PI, TAU};

use glam::DVec3;

use super::error::{Result, clamp, finite_vec};
use super::newton::NewtonOptions;
use super::surface::{AnalyticSurface, ParamBox, SurfaceKind, checked_range};

/// Which side of a 2π range a point on the seam should be given.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Seam {
    /// The range start `u0`.
    #[default]
    Low,
    /// The range end `u1 = u0 + 2π`.
    High,
}

/// Tolerances and hints for [`AnalyticSurface::invert`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InvertOptions {
    /// Angles outside the range by at most this (radians) are clamped into it;
    /// it is also the width of the seam.
    pub angle_tol: f64,
    /// Linear parameters outside the range by at most this are clamped;
    /// candidates closer than this count as equally near (then the one inside
    /// the box wins). In model units.
    pub length_tol: f64,
    /// Side to use for a point on the seam of a 2π range.
    pub seam: Seam,
    /// Settings of the Newton iterations used for revolutions and extrusions.
    pub newton: NewtonOptions,
}

impl Default for InvertOptions {
    fn default() -> Self {
        Self {
            angle_tol: 1e-9,
            length_tol: 1e-9,
            seam: Seam::Low,
            newton: NewtonOptions::default(),
        }
    }
}

/// The result of a point inversion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Inversion {
    /// Parameters of the foot point (analytic, or NURBS for `invert_nurbs`).
    pub uv: [f64; 2],
    /// The surface point at `uv`.
    pub point: DVec3,
    /// `|p − point|`, for the caller to compare with its tolerance.
    pub distance: f64,
    /// Whether `uv` lies in the parameter box (after tolerance clamping).
    pub inside: bool,
    /// Per parameter: the point was on the seam of a 2π range and the
    /// [`Seam`] hint chose the side; the other side is `uv ∓ 2π`.
    pub on_seam: [bool; 2],
    /// `u` is arbitrary (point on the axis, at a pole or at an apex): any `u`
    /// gives the same distance.
    pub u_free: bool,
}

/// One angle placed in `[lo, hi]` (period 2π).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Unwrapped {
    /// The representative chosen.
    pub value: f64,
    /// It lies in `[lo, hi]` (angles within `tol` outside were clamped in).
    pub inside: bool,
    /// Both `value` and `value ± 2π` were within the range: the hint chose.
    pub on_seam: bool,
}

/// Places `angle` in the range `[lo, hi]` modulo 2π.
///
/// If a representative lies within `[lo − tol, hi + tol]` it is clamped into
/// `[lo, hi]`; if two do (a range of ~2π and a point on its seam) `seam`
/// picks one. Otherwise the representative nearest to the range is returned,
/// unclamped, with `inside = false`.
#[must_use]
pub fn unwrap_angle(angle: f64, range: [f64; 2], tol: f64, seam: Seam) -> Unwrapped {
    let [lo, hi] = range;
    let outside = Unwrapped {
        value: angle,
        inside: false,
        on_seam: false,
    };
    if lo.is_nan() || hi.is_nan() || lo > hi || !tol.is_finite() || !angle.is_finite() {
        return outside;
    }
    let k = ((lo - tol - angle) / TAU).ceil();
    let rep = |j: f64| angle + j * TAU;
    let c = rep(k);
    if c <= hi + tol {
        let on_seam = rep(k + 1.0) <= hi + tol;
        let pick = if on_seam && seam == Seam::High {
            rep(k + 1.0)
        } else {
            c
        };
        return Unwrapped {
            value: clamp(pick, lo, hi),
            inside: true,
            on_seam,
        };
    }
    let below = rep(k - 1.0);
    let value = if c - hi <= lo - below { c } else { below };
    Unwrapped {
        value,
        inside: false,
        on_seam: false,
    }
}

/// Places a linear parameter in `[lo, hi]`, clamping if within `tol`.
fn clamp_linear(x: f64, [lo, hi]: [f64; 2], tol: f64) -> (f64, bool) {
    if x >= lo - tol && x <= hi + tol {
        (clamp(x, lo, hi), true)
    } else {
        (x, false)
    }
}

/// A raw foot-point parameter pair before unwrapping.
pub(crate) struct Raw {
    /// `[u, v]`, angles not yet unwrapped.
    pub(crate) uv: [f64; 2],
    /// `u` is arbitrary at this foot.
    pub(crate) u_free: bool,
}

impl AnalyticSurface {
    /// Inverts `p` onto this surface: the foot point's analytic `(u, v)` with
    /// angles unwrapped into `range` (see [`unwrap_angle`]) and the distance.
    ///
    /// The foot is the closest point of the untrimmed surface (for a
    /// revolution/extrusion: with the profile parameter restricted to the
    /// box); `inside` tells whether it lies in the box.
    ///
    /// # Errors
    /// Non-finite point, a non-finite or empty box, or a profile that cannot
    /// be evaluated.
    pub fn invert(&self, p: DVec3, range: &ParamBox, opts: &InvertOptions) -> Result<Inversion> {
        finite_vec(p, "point to invert")?;
        checked_range(range.u, "u")?;
        checked_range(range.v, "v")?;
        let raws = match self.kind() {
            SurfaceKind::Revolution { .. } | SurfaceKind::Extrusion { .. } => {
                vec![self.invert_swept(p, range, opts)?]
            }
            _ => self.closed_form_candidates(p),
        };
        let mut best: Option<Inversion> = None;
        for raw in raws {
            let cand = self.finish(p, raw, range, opts)?;
            best = Some(match best {
                Some(b) if prefer(&b, &cand, opts.length_tol) => b,
                _ => cand,
            });
        }
        best.ok_or(super::error::AnalyticError::InvalidNurbs(
            "no inversion candidate",
        ))
    }

    /// Unwraps/clamps a raw candidate and measures its distance.
    fn finish(
        &self,
        p: DVec3,
        raw: Raw,
        range: &ParamBox,
        opts: &InvertOptions,
    ) -> Result<Inversion> {
        let [ang_u, ang_v] = self.angular();
        let place = |x: f64, r: [f64; 2], angular: bool| {
            if angular {
                let w = unwrap_angle(x, r, opts.angle_tol, opts.seam);
                (w.value, w.inside, w.on_seam)
            } else {
                let (x, inside) = clamp_linear(x, r, opts.length_tol);
                (x, inside, false)
            }
        };
        let [ru, rv] = raw.uv;
        let (u, in_u, seam_u) = place(ru, range.u, ang_u);
        let (v, in_v, seam_v) = place(rv, range.v, ang_v);
        let (uv, inside, on_seam) = ([u, v], in_u && in_v, [seam_u, seam_v]);
        let point = self.point(u, v)?;
        let distance = (p - point).length();
        Ok(Inversion {
            uv,
            point,
            distance,
            inside,
            on_seam,
            u_free: raw.u_free,
        })
    }

    /// Closed-form candidates for plane, cylinder, cone, sphere and torus.
    fn closed_form_candidates(&self, p: DVec3) -> Vec<Raw> {
        let l = self.frame().to_local(p);
        let rho = l.x.hypot(l.y);
        let phi = l.y.atan2(l.x);
        let opposite = phi + PI;
        // On the axis within the rounding noise of the coordinates: u is free.
        let noise = 16.0 * f64::EPSILON * (p.length() + self.frame().origin.length());
        let raw = |u: f64, v: f64, scale: f64| Raw {
            uv: [u, v],
            u_free: rho <= noise + 16.0 * f64::EPSILON * scale,
        };
        match *self.kind() {
            SurfaceKind::Plane => vec![Raw {
                uv: [l.x, l.y],
                u_free: false,
            }],
            SurfaceKind::Cylinder { radius } => vec![raw(phi, l.z, radius)],
            SurfaceKind::Cone { radius, semi_angle } => {
                // Project (±ρ, z) onto the generator (R + v tan α, v).
                let (s, c) = semi_angle.sin_cos();
                let foot = |r: f64| (r - radius) * s * c + l.z * c * c;
                let scale = radius.max(l.z.abs());
                vec![raw(phi, foot(rho), scale), raw(opposite, foot(-rho), scale)]
            }
            SurfaceKind::Sphere { radius } => vec![raw(phi, l.z.atan2(rho), radius)],
            SurfaceKind::Torus { major, minor } => vec![
                raw(phi, l.z.atan2(rho - major), major + minor),
                raw(opposite, l.z.atan2(-rho - major), major + minor),
            ],
            SurfaceKind::Revolution { .. } | SurfaceKind::Extrusion { .. } => Vec::new(),
        }
    }
}

/// Whether the current best `b` should be kept over candidate `c`: strictly
/// nearer, or as near (within `tol`) and inside while `c` is not.
fn prefer(b: &Inversion, c: &Inversion, tol: f64) -> bool {
    if (b.distance - c.distance).abs() <= tol {
        b.inside || !c.inside
    } else {
        b.distance < c.distance || c.distance.is_nan()
    }
}
