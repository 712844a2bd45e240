//! Screen-space picking of control points.

use crate::editor::Handle;
use crate::render::{Bounds, OrbitCamera};
use glam::DVec3;

/// Pick radius in pixels.
pub const PICK_RADIUS: f64 = 12.0;

/// A handle projected into the image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projected {
    pub handle: Handle,
    pub world: DVec3,
    pub x: f64,
    pub y: f64,
    /// Depth in [0, 1], smaller is nearer.
    pub depth: f64,
}

/// Projects handles into a `size` image (those behind the eye are dropped).
#[must_use]
pub fn project_all(
    handles: &[(Handle, DVec3)],
    camera: &OrbitCamera,
    bounds: &Bounds,
    size: [f64; 2],
) -> Vec<Projected> {
    handles
        .iter()
        .filter_map(|&(handle, world)| {
            let (x, y, depth) = camera.project(world, size[0], size[1], bounds)?;
            (0.0..=1.0).contains(&depth).then_some(Projected {
                handle,
                world,
                x,
                y,
                depth,
            })
        })
        .collect()
}

/// Screen distance (pixels) within which overlapping handles count as "under the cursor
/// together", so depth decides between them.
const OVERLAP: f64 = 3.0;

/// The handle under the cursor, depth-aware: the handle nearest the cursor on screen (within
/// `radius`), except that among handles practically as near (within a few pixels more) the one
/// nearest the viewer wins — so aiming at a point picks it, and of points drawn on top of each
/// other the front one is picked.
pub fn pick(candidates: &[Projected], cursor: (f64, f64), radius: f64) -> Option<Projected> {
    let dist = |p: &Projected| (p.x - cursor.0).hypot(p.y - cursor.1);
    let nearest = candidates
        .iter()
        .map(dist)
        .filter(|&d| d <= radius)
        .fold(f64::INFINITY, f64::min);
    if !nearest.is_finite() {
        return None;
    }
    candidates
        .iter()
        .filter(|p| dist(p) <= (nearest + OVERLAP).min(radius))
        .min_by(|a, b| {
            a.depth
                .total_cmp(&b.depth)
                .then_with(|| dist(a).total_cmp(&dist(b)))
        })
        .copied()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Index2;

    fn handle(k: usize) -> Handle {
        Handle::Point {
            object: 0,
            point: Index2::One(k),
        }
    }

    #[test]
    fn nearest_in_depth_wins_within_the_radius() {
        let mut b = Bounds::EMPTY;
        b.include(DVec3::splat(-2.0));
        b.include(DVec3::splat(2.0));
        let cam = OrbitCamera {
            target: DVec3::ZERO,
            distance: 10.0,
            yaw: 0.0,
            pitch: 0.0,
            fov_y: 0.7,
        };
        // The eye is at −y; two points on the same line of sight, one nearer.
        let handles = vec![
            (handle(0), DVec3::new(0.0, 1.0, 0.0)),
            (handle(1), DVec3::new(0.0, -1.0, 0.0)),
            (handle(2), DVec3::new(1.5, 0.0, 0.0)),
        ];
        let size = [800.0, 600.0];
        let p = project_all(&handles, &cam, &b, size);
        assert_eq!(p.len(), 3);
        let centre = (p[0].x, p[0].y);
        let hit = pick(&p, centre, PICK_RADIUS).unwrap();
        assert_eq!(hit.handle, handle(1), "the point nearer the eye is picked");
        let side = (p[2].x + 5.0, p[2].y - 3.0);
        assert_eq!(pick(&p, side, PICK_RADIUS).unwrap().handle, handle(2));
        // Aiming exactly at a point picks it even if a nearer one is within the radius.
        let far = vec![
            Projected {
                handle: handle(3),
                world: DVec3::ZERO,
                x: 100.0,
                y: 100.0,
                depth: 0.9,
            },
            Projected {
                handle: handle(4),
                world: DVec3::ZERO,
                x: 109.0,
                y: 100.0,
                depth: 0.1,
            },
        ];
        assert_eq!(
            pick(&far, (100.0, 100.0), PICK_RADIUS).unwrap().handle,
            handle(3)
        );
        assert_eq!(
            pick(&far, (104.0, 100.0), PICK_RADIUS).unwrap().handle,
            handle(4)
        );
        assert!(pick(&p, (5.0, 5.0), PICK_RADIUS).is_none());
    }

    #[test]
    fn points_behind_the_eye_are_not_pickable() {
        let mut b = Bounds::EMPTY;
        b.include(DVec3::splat(-1.0));
        b.include(DVec3::splat(1.0));
        let cam = OrbitCamera {
            target: DVec3::ZERO,
            distance: 5.0,
            yaw: 0.0,
            pitch: 0.0,
            fov_y: 0.7,
        };
        let handles = vec![(handle(0), DVec3::new(0.0, -20.0, 0.0))];
        assert!(project_all(&handles, &cam, &b, [640.0, 480.0]).is_empty());
    }
}
