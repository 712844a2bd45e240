//! STEP analytic surfaces (ISO 10303-42 parametrisations) and their exact
//! rational B-spline forms over a parameter box.

use glam::DVec3;

use super::arc::ArcMap;
use super::error::{AnalyticError, Result, finite, finite_vec, positive};
use super::frame::{Frame, unit};
use super::nurbs::{NurbsCurve, NurbsSurface};

/// The kind and size of an analytic surface. Angles are in radians.
#[derive(Debug, Clone, PartialEq)]
pub enum SurfaceKind {
    /// `S(u,v) = C + uX + vY`.
    Plane,
    /// `S(u,v) = C + R(cos u X + sin u Y) + vZ`.
    Cylinder {
        /// `R > 0`.
        radius: f64,
    },
    /// `S(u,v) = C + (R + v tan α)(cos u X + sin u Y) + vZ`.
    Cone {
        /// `R ≥ 0`, the radius at `v = 0`.
        radius: f64,
        /// `α ∈ (−π/2, π/2)`.
        semi_angle: f64,
    },
    /// `S(u,v) = C + R cos v (cos u X + sin u Y) + R sin v Z`.
    Sphere {
        /// `R > 0`.
        radius: f64,
    },
    /// `S(u,v) = C + (R + r cos v)(cos u X + sin u Y) + r sin v Z` (`r > R`
    /// allowed: the degenerate torus).
    Torus {
        /// `R > 0`.
        major: f64,
        /// `r > 0`.
        minor: f64,
    },
    /// `S(u,v)` = `profile(v)` rotated by `u` about the axis (right hand rule).
    Revolution {
        /// The generatrix, validated.
        profile: NurbsCurve,
        /// A point `A` on the axis.
        axis_point: DVec3,
        /// Unit axis direction `D`.
        axis_dir: DVec3,
    },
    /// `S(u,v) = profile(u) + vV`.
    Extrusion {
        /// The directrix, validated.
        profile: NurbsCurve,
        /// Extrusion vector `V` (its length scales `v`, as in STEP).
        vector: DVec3,
    },
}

/// A validated analytic surface: a frame plus a [`SurfaceKind`].
#[derive(Debug, Clone, PartialEq)]
pub struct AnalyticSurface {
    /// Placement (validated orthonormal).
    frame: Frame,
    /// Kind and sizes (validated).
    kind: SurfaceKind,
}

/// A face's parameter box `[u0, u1] × [v0, v1]` in analytic parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParamBox {
    /// `[u0, u1]`, `u0 < u1`.
    pub u: [f64; 2],
    /// `[v0, v1]`, `v0 < v1`.
    pub v: [f64; 2],
}

/// How one analytic parameter maps to its NURBS parameter.
#[derive(Debug, Clone, PartialEq)]
pub enum AxisMap {
    /// The NURBS parameter is the analytic parameter.
    Identity,
    /// An angle, mapped through the arc's closed-form map.
    Arc(ArcMap),
}

impl AxisMap {
    /// Analytic → NURBS.
    #[must_use]
    pub fn to_nurbs(&self, x: f64) -> f64 {
        match self {
            Self::Identity => x,
            Self::Arc(a) => a.angle_to_param(x),
        }
    }

    /// NURBS → analytic.
    #[must_use]
    pub fn to_analytic(&self, s: f64) -> f64 {
        match self {
            Self::Identity => s,
            Self::Arc(a) => a.param_to_angle(s),
        }
    }
}

/// Analytic `(u, v)` ↔ NURBS `(s, t)` for one converted face, so trim curves
/// given in the analytic parameters can be mapped exactly point by point.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamMap {
    /// Map of the first parameter.
    pub u: AxisMap,
    /// Map of the second parameter.
    pub v: AxisMap,
}

impl ParamMap {
    /// Analytic `[u, v]` → NURBS `[s, t]` (angles clamped to the face's range).
    #[must_use]
    pub fn to_nurbs(&self, uv: [f64; 2]) -> [f64; 2] {
        [self.u.to_nurbs(uv[0]), self.v.to_nurbs(uv[1])]
    }

    /// NURBS `[s, t]` → analytic `[u, v]`.
    #[must_use]
    pub fn to_analytic(&self, st: [f64; 2]) -> [f64; 2] {
        [self.u.to_analytic(st[0]), self.v.to_analytic(st[1])]
    }
}

/// A converted face: the exact NURBS form and its parameter map.
#[derive(Debug, Clone, PartialEq)]
pub struct FaceNurbs {
    /// The rational B-spline surface.
    pub surface: NurbsSurface,
    /// Analytic ↔ NURBS parameters.
    pub map: ParamMap,
}

/// A finite range with `lo < hi`.
pub(crate) fn checked_range(r: [f64; 2], what: &'static str) -> Result<[f64; 2]> {
    let [lo, hi] = r;
    finite(lo, what)?;
    finite(hi, what)?;
    if lo < hi {
        Ok(r)
    } else {
        Err(AnalyticError::EmptyRange { what, lo, hi })
    }
}

/// Degree-1 knots `[lo, lo, hi, hi]` of a straight direction.
fn linear_knots(r: [f64; 2]) -> Vec<f64> {
    vec![r[0], r[0], r[1], r[1]]
}

impl AnalyticSurface {
    /// STEP PLANE.
    ///
    /// # Errors
    /// If the frame is not orthonormal.
    pub fn plane(frame: Frame) -> Result<Self> {
        frame.validate()?;
        Ok(Self {
            frame,
            kind: SurfaceKind::Plane,
        })
    }

    /// STEP CYLINDRICAL_SURFACE.
    ///
    /// # Errors
    /// Bad frame or radius.
    pub fn cylinder(frame: Frame, radius: f64) -> Result<Self> {
        frame.validate()?;
        let radius = positive(radius, "cylinder radius")?;
        Ok(Self {
            frame,
            kind: SurfaceKind::Cylinder { radius },
        })
    }

    /// STEP CONICAL_SURFACE (`R ≥ 0`, `|α| < π/2`; negative α narrows with v).
    ///
    /// # Errors
    /// Bad frame, negative radius, or semi-angle outside (−π/2, π/2).
    pub fn cone(frame: Frame, radius: f64, semi_angle: f64) -> Result<Self> {
        frame.validate()?;
        if finite(radius, "cone radius")? < 0.0 {
            return Err(AnalyticError::NonPositive {
                what: "cone radius",
                value: radius,
            });
        }
        if finite(semi_angle, "cone semi-angle")?.abs() >= std::f64::consts::FRAC_PI_2 {
            return Err(AnalyticError::SemiAngle(semi_angle));
        }
        Ok(Self {
            frame,
            kind: SurfaceKind::Cone { radius, semi_angle },
        })
    }

    /// STEP SPHERICAL_SURFACE.
    ///
    /// # Errors
    /// Bad frame or radius.
    pub fn sphere(frame: Frame, radius: f64) -> Result<Self> {
        frame.validate()?;
        let radius = positive(radius, "sphere radius")?;
        Ok(Self {
            frame,
            kind: SurfaceKind::Sphere { radius },
        })
    }

    /// STEP TOROIDAL_SURFACE (and DEGENERATE_TOROIDAL_SURFACE, `minor > major`).
    ///
    /// # Errors
    /// Bad frame or radii.
    pub fn torus(frame: Frame, major: f64, minor: f64) -> Result<Self> {
        frame.validate()?;
        let major = positive(major, "torus major radius")?;
        let minor = positive(minor, "torus minor radius")?;
        Ok(Self {
            frame,
            kind: SurfaceKind::Torus { major, minor },
        })
    }

    /// STEP SURFACE_OF_REVOLUTION of `profile` about the axis through
    /// `axis_point` along `axis_dir`. The frame is the axis frame (`Z = D`).
    ///
    /// # Errors
    /// Invalid profile, non-finite point, zero axis.
    pub fn revolution(profile: NurbsCurve, axis_point: DVec3, axis_dir: DVec3) -> Result<Self> {
        profile.validate()?;
        let axis_point = finite_vec(axis_point, "revolution axis point")?;
        let axis_dir = unit(axis_dir, "revolution axis")?;
        let frame = Frame::from_axis2_placement(axis_point, Some(axis_dir), None)?;
        Ok(Self {
            frame,
            kind: SurfaceKind::Revolution {
                profile,
                axis_point,
                axis_dir,
            },
        })
    }

    /// STEP SURFACE_OF_LINEAR_EXTRUSION of `profile` along `vector`.
    ///
    /// # Errors
    /// Invalid profile, non-finite or zero vector.
    pub fn extrusion(profile: NurbsCurve, vector: DVec3) -> Result<Self> {
        profile.validate()?;
        let dir = unit(vector, "extrusion vector")?;
        let frame = Frame::from_axis2_placement(DVec3::ZERO, Some(dir), None)?;
        Ok(Self {
            frame,
            kind: SurfaceKind::Extrusion { profile, vector },
        })
    }

    /// The placement frame (for revolution/extrusion: a frame whose `Z` is the
    /// axis/extrusion direction).
    #[must_use]
    pub fn frame(&self) -> &Frame {
        &self.frame
    }

    /// The surface kind and its sizes.
    #[must_use]
    pub fn kind(&self) -> &SurfaceKind {
        &self.kind
    }

    /// Which parameters are angles (and so periodic with period 2π).
    #[must_use]
    pub fn angular(&self) -> [bool; 2] {
        match self.kind {
            SurfaceKind::Plane | SurfaceKind::Extrusion { .. } => [false, false],
            SurfaceKind::Sphere { .. } | SurfaceKind::Torus { .. } => [true, true],
            _ => [true, false],
        }
    }

    /// The analytic formula `S(u, v)` evaluated directly (the reference the
    /// NURBS forms are tested against).
    ///
    /// # Errors
    /// Only if a profile curve cannot be evaluated.
    pub fn point(&self, u: f64, v: f64) -> Result<DVec3> {
        let f = &self.frame;
        let ring = |r: f64, z: f64| f.to_world(r * u.cos(), r * u.sin(), z);
        Ok(match &self.kind {
            SurfaceKind::Plane => f.to_world(u, v, 0.0),
            SurfaceKind::Cylinder { radius } => ring(*radius, v),
            SurfaceKind::Cone { radius, semi_angle } => ring(radius + v * semi_angle.tan(), v),
            SurfaceKind::Sphere { radius } => ring(radius * v.cos(), radius * v.sin()),
            SurfaceKind::Torus { major, minor } => ring(major + minor * v.cos(), minor * v.sin()),
            SurfaceKind::Revolution {
                profile,
                axis_point,
                axis_dir,
            } => rotate(profile.point(v)?, *axis_point, *axis_dir, u.cos(), u.sin()),
            SurfaceKind::Extrusion { profile, vector } => profile.point(u)? + v * *vector,
        })
    }

    /// The exact NURBS form over `range` and its [`ParamMap`].
    ///
    /// Angular directions use the arc of [`ArcMap`] (≤ 90° segments, knots at
    /// the angles); straight directions are degree 1 with knots
    /// `[v0, v0, v1, v1]`; profile directions keep the profile's knots, cut to
    /// the range. Weights of the two directions multiply.
    ///
    /// # Errors
    /// Non-finite or empty ranges, angular sweeps above 2π, sphere `v`
    /// outside `[−π/2, π/2]`, profile ranges outside the profile's domain.
    pub fn to_nurbs(&self, range: &ParamBox) -> Result<FaceNurbs> {
        let u = checked_range(range.u, "u")?;
        let v = checked_range(range.v, "v")?;
        match &self.kind {
            SurfaceKind::Plane => Ok(self.plane_nurbs(u, v)),
            SurfaceKind::Cylinder { radius } => self.ruled_nurbs(u, v, *radius, 0.0),
            SurfaceKind::Cone { radius, semi_angle } => {
                self.ruled_nurbs(u, v, *radius, semi_angle.tan())
            }
            SurfaceKind::Sphere { radius } => {
                let pole = std::f64::consts::FRAC_PI_2 * (1.0 + 1e-12);
                if v[0] < -pole || v[1] > pole {
                    let (dom_lo, dom_hi) = (-pole, pole);
                    return Err(AnalyticError::OutOfDomain {
                        what: "sphere v",
                        lo: v[0],
                        hi: v[1],
                        dom_lo,
                        dom_hi,
                    });
                }
                self.doubly_curved(u, v, 0.0, *radius)
            }
            SurfaceKind::Torus { major, minor } => self.doubly_curved(u, v, *major, *minor),
            SurfaceKind::Revolution {
                profile,
                axis_point,
                axis_dir,
            } => revolution_nurbs(&profile.segment(v[0], v[1])?, *axis_point, *axis_dir, u),
            SurfaceKind::Extrusion { profile, vector } => {
                Ok(extrusion_nurbs(&profile.segment(u[0], u[1])?, *vector, v))
            }
        }
    }

    /// Bilinear patch with the corners `C + uX + vY`.
    fn plane_nurbs(&self, u: [f64; 2], v: [f64; 2]) -> FaceNurbs {
        let f = &self.frame;
        let points = u
            .iter()
            .flat_map(|&a| v.iter().map(move |&b| f.to_world(a, b, 0.0)))
            .collect();
        let surface = NurbsSurface {
            degree: [1, 1],
            knots: [linear_knots(u), linear_knots(v)],
            points,
            weights: vec![1.0; 4],
        };
        FaceNurbs {
            surface,
            map: ParamMap {
                u: AxisMap::Identity,
                v: AxisMap::Identity,
            },
        }
    }

    /// Cylinder (`slope = 0`) and cone (`slope = tan α`): the arc in `u`
    /// times a line in `v`. `(R + v tan α)(x X + y Y) + v Z` is bilinear in the
    /// arc's homogeneous coordinates and in `v`, so the tensor product with
    /// control points at `v0`, `v1` is exact, also across the apex.
    fn ruled_nurbs(&self, u: [f64; 2], v: [f64; 2], radius: f64, slope: f64) -> Result<FaceNurbs> {
        let arc = ArcMap::new(u[0], u[1])?;
        let f = &self.frame;
        let mut points = Vec::new();
        let mut weights = Vec::new();
        for (q, w) in arc.unit_polygon() {
            for z in v {
                let r = radius + z * slope;
                points.push(f.to_world(r * q.x, r * q.y, z));
                weights.push(w);
            }
        }
        let surface = NurbsSurface {
            degree: [2, 1],
            knots: [arc.knot_vector(), linear_knots(v)],
            points,
            weights,
        };
        Ok(FaceNurbs {
            surface,
            map: ParamMap {
                u: AxisMap::Arc(arc),
                v: AxisMap::Identity,
            },
        })
    }

    /// Sphere (`major = 0`) and torus: the `u` arc times the `v` arc, with
    /// `P_ij = C + (R + r x_j)(x_i X + y_i Y) + r y_j Z` and `w_ij = w_i w_j`,
    /// exact because the formula is bilinear in the two homogeneous arcs.
    fn doubly_curved(&self, u: [f64; 2], v: [f64; 2], major: f64, minor: f64) -> Result<FaceNurbs> {
        let (au, av) = (ArcMap::new(u[0], u[1])?, ArcMap::new(v[0], v[1])?);
        let f = &self.frame;
        let pv = av.unit_polygon();
        let mut points = Vec::new();
        let mut weights = Vec::new();
        for (qi, wi) in au.unit_polygon() {
            for &(qj, wj) in &pv {
                let r = major + minor * qj.x;
                points.push(f.to_world(r * qi.x, r * qi.y, minor * qj.y));
                weights.push(wi * wj);
            }
        }
        let surface = NurbsSurface {
            degree: [2, 2],
            knots: [au.knot_vector(), av.knot_vector()],
            points,
            weights,
        };
        Ok(FaceNurbs {
            surface,
            map: ParamMap {
                u: AxisMap::Arc(au),
                v: AxisMap::Arc(av),
            },
        })
    }
}

/// Rodrigues rotation of `p` about the axis `(a, d)` by the angle with
/// cosine `c` and sine `s`; `(c, s)` need not be unit (used on the arc's
/// middle control points), which keeps the map affine in `(c, s)`.
#[must_use]
pub(crate) fn rotate(p: DVec3, a: DVec3, d: DVec3, c: f64, s: f64) -> DVec3 {
    let w = p - a;
    let along = w.dot(d) * d;
    let r = w - along;
    a + along + c * r + s * d.cross(r)
}

/// The NURBS Book §8.5 / A8.1 MakeRevolvedSurf, with the arc of [`ArcMap`]:
/// control point `(i, j)` is profile point `P_j` rotated by the arc's unit
/// polygon point `(x_i, y_i)` (an affine map), weight `w_i · w_j`.
fn revolution_nurbs(profile: &NurbsCurve, a: DVec3, d: DVec3, u: [f64; 2]) -> Result<FaceNurbs> {
    let arc = ArcMap::new(u[0], u[1])?;
    let mut points = Vec::new();
    let mut weights = Vec::new();
    for (q, wi) in arc.unit_polygon() {
        for (&p, &wj) in profile.points.iter().zip(&profile.weights) {
            points.push(rotate(p, a, d, q.x, q.y));
            weights.push(wi * wj);
        }
    }
    let surface = NurbsSurface {
        degree: [2, profile.degree],
        knots: [arc.knot_vector(), profile.knots.clone()],
        points,
        weights,
    };
    Ok(FaceNurbs {
        surface,
        map: ParamMap {
            u: AxisMap::Arc(arc),
            v: AxisMap::Identity,
        },
    })
}

/// Profile (along `u`) times a degree-1 line along `V` (along `v`).
fn extrusion_nurbs(profile: &NurbsCurve, vector: DVec3, v: [f64; 2]) -> FaceNurbs {
    let mut points = Vec::new();
    let mut weights = Vec::new();
    for (&p, &w) in profile.points.iter().zip(&profile.weights) {
        for z in v {
            points.push(p + z * vector);
            weights.push(w);
        }
    }
    let surface = NurbsSurface {
        degree: [profile.degree, 1],
        knots: [profile.knots.clone(), linear_knots(v)],
        points,
        weights,
    };
    FaceNurbs {
        surface,
        map: ParamMap {
            u: AxisMap::Identity,
            v: AxisMap::Identity,
        },
    }
}
