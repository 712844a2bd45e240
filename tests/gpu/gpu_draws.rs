//! What a frame costs in calls (lavapipe, validation on): each polyline, control net, point
//! run and batch of same-shaped surfaces is one draw call; a pipeline already bound is not
//! bound again; an offscreen frame copies its image out only when captured.

use crate::common;

use glam::Vec3;
use prespline::gpu::{
    GridShape, GridStride, OffscreenDesc, PointRun, PointStyle, PolylineStyle, SurfaceBatch,
    SurfaceGrid, SurfaceStyle,
};

#[test]
fn draws_and_binds_are_counted_once() {
    let (mut r, sink) = common::renderer();
    let mut target = r
        .create_offscreen(&OffscreenDesc {
            width: 96,
            height: 64,
            samples: 1,
        })
        .unwrap();
    let shape = GridShape { rows: 9, cols: 9 };
    let one = SurfaceGrid { offset: 0, shape };
    let patch = common::height_field(shape, &[(0.0, 0.0, 0.4, 0.6)]);
    // Four patches back to back, and a polyline of 50 points after them.
    let mut data: Vec<f32> = (0..4).flat_map(|_| patch.iter().copied()).collect();
    let curve_at = data.len();
    data.extend(common::helix(50, 0.8, 2.0, -0.5, 0.5));
    let mut mirror = r.create_mirror("draws", data.len()).unwrap();
    r.fill_mirror(&mut mirror, 0, &data).unwrap();
    let offsets: Vec<usize> = (0..4).map(|k| k * one.floats()).collect();

    let mut frame = r.begin_offscreen(&mut target).unwrap();
    frame.set_camera(common::camera(Vec3::new(0.0, -3.0, 2.0), 96, 64));
    let batch = SurfaceBatch {
        shape,
        stride: GridStride { rows: 2, cols: 2 },
        offsets: &offsets,
        mask: None,
    };
    frame
        .draw_surface_batch(&mirror, &batch, &SurfaceStyle::default())
        .unwrap();
    let after_batch = frame.stats();
    assert_eq!(after_batch.draws, 1, "four patches, one call");
    assert_eq!(after_batch.surface_triangles, 4 * 4 * 4 * 2);
    let curve = PointRun {
        offset: curve_at,
        stride: 3,
        count: 50,
    };
    let style = PolylineStyle::default();
    for _ in 0..3 {
        frame.draw_polyline(&mirror, curve, &style).unwrap();
    }
    let after_lines = frame.stats();
    assert_eq!(
        after_lines.draws, 4,
        "a polyline of 49 segments is one draw"
    );
    assert_eq!(
        after_lines.pipeline_binds, 2,
        "the polyline pipeline is bound once for three polylines"
    );
    // A 9 × 9 net (vertices of the first patch, stride 6): one draw for 144 segments.
    let net = PointRun {
        offset: 0,
        stride: 6,
        count: 81,
    };
    frame.draw_net(&mirror, net, 9, &style).unwrap();
    frame
        .draw_points(&mirror, net, &PointStyle::default())
        .unwrap();
    let end = frame.stats();
    assert_eq!(end.draws, 6);
    assert_eq!(
        end.pipeline_binds, 3,
        "net shares the polyline pipeline; points bind theirs"
    );
    assert!(
        frame.draw_net(&mirror, net, 7, &style).is_err(),
        "81 points are not rows of 7"
    );
    frame.finish().unwrap();
    // Not captured: nothing to read back.
    assert!(r.read_pixels(&target).is_err());

    let mut frame = r.begin_offscreen(&mut target).unwrap();
    frame.set_clear_color([0.2, 0.4, 0.6, 1.0]);
    frame.capture();
    frame.finish().unwrap();
    let px = r.read_pixels(&target).expect("captured frame");
    assert_eq!(px.get(1, 1)[3], 255);
    r.destroy_mirror(mirror);
    r.destroy_offscreen(target).unwrap();
    common::teardown(r, sink);
}
