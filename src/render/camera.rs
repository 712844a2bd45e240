//! The orbit camera: a target point, a distance and two angles, z up.

pub use crate::geom::Bounds;
use glam::{DMat4, DVec3, DVec4, Mat4, Vec3};

/// A camera orbiting `target` (z up): `yaw` around z, `pitch` above the xy-plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrbitCamera {
    pub target: DVec3,
    pub distance: f64,
    /// Radians around +z, 0 = looking along +y from −y.
    pub yaw: f64,
    /// Radians above the horizon, clamped short of the poles.
    pub pitch: f64,
    /// Vertical field of view in radians.
    pub fov_y: f64,
}

impl Default for OrbitCamera {
    fn default() -> Self {
        Self {
            target: DVec3::ZERO,
            distance: 10.0,
            yaw: -0.6,
            pitch: 0.45,
            fov_y: 40f64.to_radians(),
        }
    }
}

impl OrbitCamera {
    /// Limit keeping the up vector well-defined.
    pub const MAX_PITCH: f64 = 1.55;

    #[must_use]
    pub fn eye(&self) -> DVec3 {
        self.target + self.direction() * self.distance
    }

    /// Unit vector from the target to the eye.
    #[must_use]
    pub fn direction(&self) -> DVec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        DVec3::new(sy * cp, -cy * cp, sp)
    }

    #[must_use]
    pub fn view(&self) -> DMat4 {
        DMat4::look_at_rh(self.eye(), self.target, DVec3::Z)
    }

    /// Near and far planes that contain a sphere of `radius` around `centre`.
    #[must_use]
    pub fn clip_planes(&self, bounds: &Bounds) -> (f64, f64) {
        let d = (self.eye() - bounds.centre()).length();
        let r = bounds.radius();
        let far = (d + r) * 1.05;
        let near = (d - r).max(far * 1e-4).max(1e-6);
        (near, far)
    }

    /// Projection × view for an image of `aspect` = width / height, depth in [0, 1], y up.
    #[must_use]
    pub fn view_proj(&self, aspect: f64, bounds: &Bounds) -> DMat4 {
        let (near, far) = self.clip_planes(bounds);
        DMat4::perspective_rh(self.fov_y, aspect, near, far) * self.view()
    }

    /// The f32 camera the GPU layer takes.
    #[must_use]
    pub fn gpu(&self, aspect: f64, bounds: &Bounds) -> crate::gpu::Camera {
        crate::gpu::Camera {
            view_proj: to_f32(&self.view_proj(aspect, bounds)),
            eye: self.eye().as_vec3(),
        }
    }

    /// Frames the projected bounds of `points` (inside `bounds`): from the current direction
    /// their projections are centred in the image and fill 90 % of it in the tighter
    /// direction, so a flat object seen at an angle gets equal margins above and below
    /// (centring the bounds' centre, or fitting their sphere, leaves the near side crowded and
    /// the far side empty). Alternates a distance fit (bisection) with moving the target in the
    /// view plane by the projected box's offset; perspective makes each move approximate, so a
    /// few rounds.
    pub fn frame_points(&mut self, points: &[DVec3], bounds: &Bounds, aspect: f64) {
        self.frame_points_in(points, bounds, aspect, Self::WHOLE);
    }

    /// The whole image as an NDC region `[x0, x1, y0, y1]` (y up).
    pub const WHOLE: [f64; 4] = [-1.0, 1.0, -1.0, 1.0];

    /// [`OrbitCamera::frame_points`] into `region`, an NDC rectangle `[x0, x1, y0, y1]` (y up)
    /// of the image: the part that overlays (a performance panel, a status line) leave free.
    /// The projections are centred in it and fill 90 % of it in the tighter direction.
    pub fn frame_points_in(
        &mut self,
        points: &[DVec3],
        bounds: &Bounds,
        aspect: f64,
        region: [f64; 4],
    ) {
        let region = if region[0] < region[1] && region[2] < region[3] {
            region
        } else {
            Self::WHOLE
        };
        self.target = bounds.centre();
        let half = 0.5 * self.fov_y;
        let half_h = (half.tan() * aspect.min(1.0)).atan();
        let shrink = 0.5 * (region[1] - region[0]).min(region[3] - region[2]);
        let safe = bounds.radius() / half_h.min(half).sin() * 1.05 / shrink.max(1e-3);
        if bounds.is_empty() || points.is_empty() {
            self.distance = safe;
            return;
        }
        let centre = [0.5 * (region[0] + region[1]), 0.5 * (region[2] + region[3])];
        for _ in 0..8 {
            self.fit_distance(points, bounds, aspect, safe, region);
            let Some([x0, x1, y0, y1]) = self.projected_box(points, bounds, aspect) else {
                break;
            };
            let (cx, cy) = (0.5 * (x0 + x1) - centre[0], 0.5 * (y0 + y1) - centre[1]);
            if cx.abs().max(cy.abs()) < 1e-5 {
                break;
            }
            let (right, up) = self.basis();
            let h = self.distance * half.tan();
            self.target += right * (cx * h * aspect) + up * (cy * h);
        }
        self.fit_distance(points, bounds, aspect, safe, region);
    }

    /// The NDC box [x0, x1, y0, y1] of `points`; `None` when one is behind the eye.
    fn projected_box(&self, points: &[DVec3], bounds: &Bounds, aspect: f64) -> Option<[f64; 4]> {
        let vp = self.view_proj(aspect, bounds);
        let mut b = [
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        for &p in points {
            let c = vp * p.extend(1.0);
            if c.w <= 0.0 {
                return None;
            }
            let (x, y) = (c.x / c.w, c.y / c.w);
            b = [b[0].min(x), b[1].max(x), b[2].min(y), b[3].max(y)];
        }
        Some(b)
    }

    /// The smallest distance (bisection) at which every point projects inside 90 % of
    /// `region` (about its centre), from the current target and direction; `safe` is a first
    /// upper bound.
    fn fit_distance(
        &mut self,
        points: &[DVec3],
        bounds: &Bounds,
        aspect: f64,
        safe: f64,
        region: [f64; 4],
    ) {
        let (cx, cy) = (0.5 * (region[0] + region[1]), 0.5 * (region[2] + region[3]));
        let (hx, hy) = (
            0.45 * (region[1] - region[0]),
            0.45 * (region[3] - region[2]),
        );
        let fits = |distance: f64| {
            let probe = OrbitCamera { distance, ..*self };
            probe
                .projected_box(points, bounds, aspect)
                .is_some_and(|[x0, x1, y0, y1]| {
                    x0 >= cx - hx && x1 <= cx + hx && y0 >= cy - hy && y1 <= cy + hy
                })
        };
        let mut hi = safe.max(f64::MIN_POSITIVE);
        for _ in 0..60 {
            if fits(hi) {
                break;
            }
            hi *= 2.0;
        }
        let mut lo = 0.0;
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            if fits(mid) { hi = mid } else { lo = mid }
        }
        self.distance = hi;
    }

    /// The default viewing direction for a scene: straight down the normal of a planar scene
    /// that lies in a coordinate plane (a circle must look round), obliquely from above for a
    /// nearly flat (xy) one, where an oblique view would squash everything into a band, and
    /// oblique otherwise.
    #[must_use]
    pub fn default_for(bounds: &Bounds) -> Self {
        if bounds.is_empty() {
            return Self::default();
        }
        let size = bounds.max - bounds.min;
        let largest = size.max_element();
        // Planar: thinner than a rounding error of the scene's size across.
        let planar = |thickness: f64| thickness <= 1e-9 * largest && largest > 0.0;
        if planar(size.z) {
            // Looking down −z with +x right and +y up.
            Self {
                yaw: 0.0,
                pitch: Self::MAX_PITCH,
                ..Self::default()
            }
        } else if planar(size.y) {
            // Looking along +y: +x right, +z up.
            Self {
                yaw: 0.0,
                pitch: 0.0,
                ..Self::default()
            }
        } else if planar(size.x) {
            // Looking along −x from +x: +y right, +z up.
            Self {
                yaw: std::f64::consts::FRAC_PI_2,
                pitch: 0.0,
                ..Self::default()
            }
        } else if size.z <= 0.02 * size.x.max(size.y) {
            Self {
                yaw: -0.25,
                pitch: 1.2,
                ..Self::default()
            }
        } else {
            Self::default()
        }
    }

    /// Turns by pixel drags: `dx`, `dy` in radians.
    pub fn orbit(&mut self, dyaw: f64, dpitch: f64) {
        self.yaw += dyaw;
        self.pitch = (self.pitch + dpitch).clamp(-Self::MAX_PITCH, Self::MAX_PITCH);
    }

    /// Moves target and eye together in the view plane by a world-space offset.
    pub fn pan(&mut self, offset: DVec3) {
        self.target += offset;
    }

    /// Camera right and up vectors in world space.
    #[must_use]
    pub fn basis(&self) -> (DVec3, DVec3) {
        let forward = -self.direction();
        let right = forward.cross(DVec3::Z).try_normalize().unwrap_or(DVec3::X);
        (right, right.cross(forward))
    }

    /// World-space ray through a pixel (origin top-left) of a `width × height` image.
    #[must_use]
    pub fn ray(
        &self,
        px: f64,
        py: f64,
        width: f64,
        height: f64,
        bounds: &Bounds,
    ) -> (DVec3, DVec3) {
        let inv = self.view_proj(width / height, bounds).inverse();
        let ndc_x = 2.0 * px / width - 1.0;
        let ndc_y = 1.0 - 2.0 * py / height;
        let near = inv * DVec4::new(ndc_x, ndc_y, 0.0, 1.0);
        let far = inv * DVec4::new(ndc_x, ndc_y, 1.0, 1.0);
        let (a, b) = (near.truncate() / near.w, far.truncate() / far.w);
        (a, (b - a).normalize())
    }

    /// Pixel position (origin top-left) and depth in [0, 1] of a world point; `None` behind the
    /// eye.
    #[must_use]
    pub fn project(
        &self,
        p: DVec3,
        width: f64,
        height: f64,
        bounds: &Bounds,
    ) -> Option<(f64, f64, f64)> {
        let c = self.view_proj(width / height, bounds) * p.extend(1.0);
        if c.w <= 0.0 {
            return None;
        }
        let n = c.truncate() / c.w;
        Some(((n.x + 1.0) * 0.5 * width, (1.0 - n.y) * 0.5 * height, n.z))
    }

    /// Parses `EX,EY,EZ,TX,TY,TZ[,FOV_DEGREES]` (eye, target, vertical field of view).
    pub fn parse(spec: &str) -> Result<Self, String> {
        let v: Vec<f64> = spec
            .split(',')
            .map(|s| {
                s.trim()
                    .parse::<f64>()
                    .map_err(|_| format!("'{s}' is not a number"))
            })
            .collect::<Result<_, _>>()?;
        if !(v.len() == 6 || v.len() == 7) || v.iter().any(|x| !x.is_finite()) {
            return Err(
                "expected EX,EY,EZ,TX,TY,TZ[,FOV] (eye, target, field of view in degrees)".into(),
            );
        }
        let eye = DVec3::new(v[0], v[1], v[2]);
        let target = DVec3::new(v[3], v[4], v[5]);
        let d = eye - target;
        let distance = d.length();
        if distance == 0.0 {
            return Err("eye and target coincide".into());
        }
        let fov = v.get(6).copied().unwrap_or(40.0);
        if !(1.0..=170.0).contains(&fov) {
            return Err(format!("field of view {fov}° is outside 1..170"));
        }
        let dir = d / distance;
        let pitch = dir
            .z
            .clamp(-1.0, 1.0)
            .asin()
            .clamp(-Self::MAX_PITCH, Self::MAX_PITCH);
        Ok(Self {
            target,
            distance,
            yaw: Self::yaw_of(dir),
            pitch,
            fov_y: fov.to_radians(),
        })
    }

    /// The yaw of a view direction (target to eye). A vertical one has none of its own: +Y is
    /// then up on screen, the limit of tilting the eye towards −Y from above (+X to the right)
    /// or towards +Y from below, so a view straight down continues the views next to it instead
    /// of showing the scene turned half a circle.
    fn yaw_of(dir: DVec3) -> f64 {
        let horizontal = dir.x.hypot(dir.y);
        if horizontal > 1e-9 * dir.z.abs() {
            dir.x.atan2(-dir.y)
        } else if dir.z >= 0.0 {
            0.0
        } else {
            std::f64::consts::PI
        }
    }
}

fn to_f32(m: &DMat4) -> Mat4 {
    Mat4::from_cols_array(&m.to_cols_array().map(|x| x as f32))
}

/// Vec3 from f64 world coordinates.
#[must_use]
pub fn v32(p: DVec3) -> Vec3 {
    p.as_vec3()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scene in a coordinate plane is seen straight down that plane's normal (to within the
    /// pitch limit), with the plane's first axis to the right; a nearly flat one obliquely
    /// from above; others from the default direction. Negative control: a scene 1e-6 thick is
    /// not planar.
    #[test]
    fn planar_scenes_are_seen_down_their_normal() {
        let bounds = |size: DVec3| {
            let mut b = Bounds::EMPTY;
            b.include(DVec3::new(1.0, 2.0, 3.0));
            b.include(DVec3::new(1.0, 2.0, 3.0) + size);
            b
        };
        for (size, normal, right) in [
            (DVec3::new(4.0, 4.0, 0.0), DVec3::Z, DVec3::X),
            (DVec3::new(4.0, 0.0, 4.0), -DVec3::Y, DVec3::X),
            (DVec3::new(0.0, 4.0, 4.0), DVec3::X, DVec3::Y),
        ] {
            let c = OrbitCamera::default_for(&bounds(size));
            assert!(
                c.direction().dot(normal) > 0.999,
                "{size}: {}",
                c.direction()
            );
            assert!(c.basis().0.dot(right) > 0.999, "{size}: {:?}", c.basis());
        }
        let near = OrbitCamera::default_for(&bounds(DVec3::new(4.0, 4.0, 0.05)));
        assert_eq!((near.yaw, near.pitch), (-0.25, 1.2));
        let thick = OrbitCamera::default_for(&bounds(DVec3::new(4.0, 4.0, 4e-6)));
        assert_eq!((thick.yaw, thick.pitch), (-0.25, 1.2));
        let solid = OrbitCamera::default_for(&bounds(DVec3::splat(4.0)));
        assert_eq!(solid, OrbitCamera::default());
    }

    #[test]
    fn parse_round_trips_eye_and_target() {
        let c = OrbitCamera::parse("3,-4,5, 1,1,1, 35").unwrap();
        assert!((c.eye() - DVec3::new(3.0, -4.0, 5.0)).length() < 1e-12);
        assert!((c.target - DVec3::ONE).length() < 1e-12);
        assert!(OrbitCamera::parse("1,2,3").is_err());
        assert!(OrbitCamera::parse("1,2,3,1,2,3").is_err());
    }

    #[test]
    fn project_and_ray_agree() {
        let mut b = Bounds::EMPTY;
        b.include(DVec3::splat(-1.0));
        b.include(DVec3::splat(1.0));
        let mut c = OrbitCamera::default();
        let corners: Vec<DVec3> = (0..8)
            .map(|i| {
                let s = |bit: usize| if i & bit == 0 { -1.0 } else { 1.0 };
                DVec3::new(s(1), s(2), s(4))
            })
            .collect();
        c.frame_points(&corners, &b, 1.5);
        let p = DVec3::new(0.3, -0.2, 0.5);
        let (x, y, z) = c.project(p, 1200.0, 800.0, &b).unwrap();
        assert!((0.0..1.0).contains(&z));
        let (o, d) = c.ray(x, y, 1200.0, 800.0, &b);
        let closest = o + d * (p - o).dot(d);
        assert!((closest - p).length() < 1e-9);
        // Framing keeps every corner inside the image, the box centred with equal margins.
        let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for i in 0..8 {
            let q = DVec3::new(
                if i & 1 == 0 { -1.0 } else { 1.0 },
                if i & 2 == 0 { -1.0 } else { 1.0 },
                if i & 4 == 0 { -1.0 } else { 1.0 },
            );
            let (x, y, _) = c.project(q, 1200.0, 800.0, &b).unwrap();
            assert!(
                (0.0..1200.0).contains(&x) && (0.0..800.0).contains(&y),
                "{q:?} → {x}, {y}"
            );
            (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
        }
        assert!(
            (x0 - (1200.0 - x1)).abs() < 0.5,
            "left {x0} right {}",
            1200.0 - x1
        );
        assert!(
            (y0 - (800.0 - y1)).abs() < 0.5,
            "top {y0} bottom {}",
            800.0 - y1
        );
        // The tighter direction is filled to 90 %.
        assert!(((y1 - y0) / 800.0 - 0.9).abs() < 1e-3 || ((x1 - x0) / 1200.0 - 0.9).abs() < 1e-3);
    }
}
