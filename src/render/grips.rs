//! Dense control nets thinned on screen. A 100 × 100 net seen whole puts 10,000 grips a few
//! pixels apart over its surface; drawn so, the surface disappears behind them. Only every
//! k-th row and column of grips is drawn (and the last of each, so the net's corners and
//! edges show), k the smallest power of two that keeps the drawn grips [`GAP_IN_POINTS`] point
//! sizes apart; the hovered and the selected grip are always drawn, and every net line is.
//! Picking still reaches every point. k depends on the view only (kept while the camera
//! stands, so a drag never changes it), which keeps a retained frame equal to a full one.

use crate::gpu::Camera;
use glam::{DVec3, Vec4};

/// Drawn grips stand at least this many point sizes apart (median over the net).
pub const GAP_IN_POINTS: f64 = 3.0;
/// Neighbour pairs measured per net at most.
const PAIRS: usize = 1024;

/// Every how many rows and columns of the `rows × cols` net `vertices` (row-major) grips are
/// drawn in `viewport` through `camera` with grips `point_size` pixels wide: a power of two
/// up to [`crate::gpu::GripGrid::MAX_EVERY`], 1 for a net whose grips already stand apart
/// (or that is not in front of the camera).
#[must_use]
pub fn grip_every(
    vertices: &[DVec3],
    [rows, cols]: [usize; 2],
    camera: &Camera,
    viewport: [u32; 4],
    point_size: f32,
) -> u32 {
    let n = (rows * cols).min(vertices.len());
    if n < 2 || cols == 0 {
        return 1;
    }
    let half = [f64::from(viewport[2]) / 2.0, f64::from(viewport[3]) / 2.0];
    let screen = |p: DVec3| {
        let c = camera.view_proj * Vec4::new(p.x as f32, p.y as f32, p.z as f32, 1.0);
        (c.w > 1e-6 && c.is_finite()).then(|| {
            [
                f64::from(c.x / c.w) * half[0],
                f64::from(c.y / c.w) * half[1],
            ]
        })
    };
    let step = (n / (PAIRS / 2)).max(1);
    let mut gaps = Vec::with_capacity(PAIRS);
    for k in (0..n).step_by(step) {
        let (i, j) = (k / cols, k % cols);
        let Some(a) = screen(vertices[k]) else {
            continue;
        };
        let neighbours = [
            (j + 1 < cols).then_some(k + 1),
            (i + 1 < rows).then_some(k + cols),
        ];
        for b in neighbours.into_iter().flatten().filter(|&b| b < n) {
            if let Some(b) = screen(vertices[b]) {
                gaps.push((a[0] - b[0]).hypot(a[1] - b[1]));
            }
        }
    }
    if gaps.is_empty() {
        return 1;
    }
    let mid = gaps.len() / 2;
    let (_, &mut median, _) = gaps.select_nth_unstable_by(mid, f64::total_cmp);
    let want = GAP_IN_POINTS * f64::from(point_size.max(1.0));
    let mut every = 1;
    while every < crate::gpu::GripGrid::MAX_EVERY && median * f64::from(every) < want {
        every *= 2;
    }
    every
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Mat4;

    /// A flat `n × n` net of spacing `h` in the plane z = 0, seen from straight above by an
    /// orthographic camera mapping x, y ∈ [−1, 1] onto a 1000 × 1000 viewport.
    fn case(n: usize, h: f64) -> (Vec<DVec3>, Camera, [u32; 4]) {
        let vertices = (0..n * n)
            .map(|k| DVec3::new((k % n) as f64 * h, (k / n) as f64 * h, 0.0))
            .collect();
        let camera = Camera {
            view_proj: Mat4::IDENTITY,
            ..Camera::default()
        };
        (vertices, camera, [0, 0, 1000, 1000])
    }

    /// Grips 10 pixels apart with 8-pixel points need every 4th row and column (40 pixels ≥
    /// 24); 30 pixels apart, all; and the count doubles as the spacing halves.
    #[test]
    fn every_keeps_drawn_grips_three_point_sizes_apart() {
        let px = 2.0 / 1000.0;
        for (gap_px, want) in [(30.0, 1), (10.0, 4), (5.0, 8), (2.5, 16), (0.01, 128)] {
            let (v, camera, viewport) = case(50, gap_px * px);
            assert_eq!(
                grip_every(&v, [50, 50], &camera, viewport, 8.0),
                want,
                "{gap_px} px"
            );
        }
        // Negative control: the point size counts (4-pixel points at 10 pixels: every 2nd).
        let (v, camera, viewport) = case(50, 10.0 * px);
        assert_eq!(grip_every(&v, [50, 50], &camera, viewport, 4.0), 2);
    }

    /// A net behind the camera, empty or of one point is drawn whole.
    #[test]
    fn nets_that_cannot_be_measured_are_drawn_whole() {
        let (mut v, camera, viewport) = case(10, 1e-6);
        assert_eq!(grip_every(&v, [10, 10], &camera, viewport, 8.0), 128);
        let behind = Camera {
            view_proj: Mat4::from_cols(Vec4::X, Vec4::Y, Vec4::Z, Vec4::new(0.0, 0.0, 0.0, -1.0)),
            ..camera
        };
        assert_eq!(grip_every(&v, [10, 10], &behind, viewport, 8.0), 1);
        v.truncate(1);
        assert_eq!(grip_every(&v, [1, 1], &camera, viewport, 8.0), 1);
        assert_eq!(grip_every(&[], [0, 0], &camera, viewport, 8.0), 1);
    }
}
