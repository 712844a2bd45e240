//! Behaviour of the GPU API on lavapipe: colour handling, viewports, strided point runs,
//! transient growth, timestamps, argument checking and leak-free teardown.

use crate::common;

use glam::Vec3;
use prespline::gpu::font::push_rect;
use prespline::gpu::{
    GpuError, GridShape, LineVertex, OffscreenDesc, OverlayVertex, Pixels, PointRun, PolylineStyle,
    Renderer, SurfaceGrid, SurfaceStyle,
};

fn offscreen(r: &mut Renderer, w: u32, h: u32, samples: u32) -> prespline::gpu::OffscreenTarget {
    r.create_offscreen(&OffscreenDesc {
        width: w,
        height: h,
        samples,
    })
    .expect("offscreen target")
}

#[test]
fn overlay_colours_round_trip_through_srgb() {
    let (mut r, sink) = common::renderer();
    let mut target = offscreen(&mut r, 64, 32, 1);
    let mut quads = Vec::new();
    push_rect(&mut quads, 0.0, 0.0, 32.0, 32.0, [200, 100, 30, 255]);
    push_rect(&mut quads, 32.0, 0.0, 32.0, 32.0, [10, 128, 250, 255]);
    let mut frame = r.begin_offscreen(&mut target).expect("begin");
    frame.set_clear_color([0.0, 0.0, 0.0, 1.0]);
    frame.draw_overlay(&quads).expect("overlay");
    frame.capture();
    frame.finish().expect("finish");
    let px = r.read_pixels(&target).expect("read");
    for (x, want) in [(5, [200, 100, 30, 255]), (40, [10, 128, 250, 255])] {
        let got = px.get(x, 16);
        for c in 0..4 {
            assert!(
                got[c].abs_diff(want[c]) <= 1,
                "pixel {x}: {got:?} vs {want:?}"
            );
        }
    }
    r.destroy_offscreen(target).expect("destroy");
    common::teardown(r, sink);
}

#[test]
fn viewport_restricts_drawing_and_late_clear_clears_it() {
    let (mut r, sink) = common::renderer();
    let mut target = offscreen(&mut r, 64, 32, 4);
    let mut quads = Vec::new();
    push_rect(&mut quads, 0.0, 0.0, 1000.0, 1000.0, [255, 255, 255, 255]);
    let mut frame = r.begin_offscreen(&mut target).expect("begin");
    frame.set_clear_color([0.0, 0.0, 0.0, 1.0]);
    frame.draw_overlay(&quads).expect("overlay everywhere");
    // Now clear only the right half to red, mid-frame.
    frame.set_viewport(32, 0, 32, 32).expect("viewport");
    frame.set_clear_color([1.0, 0.0, 0.0, 1.0]);
    assert!(matches!(
        frame.set_viewport(40, 0, 32, 32),
        Err(GpuError::InvalidArgument(_))
    ));
    frame.capture();
    frame.finish().expect("finish");
    let px = r.read_pixels(&target).expect("read");
    assert_eq!(px.get(10, 10), [255, 255, 255, 255]);
    assert_eq!(px.get(50, 10), [255, 0, 0, 255]);
    r.destroy_offscreen(target).expect("destroy");
    common::teardown(r, sink);
}

/// A grid column drawn through a strided run must equal the same points packed, and the
/// same points drawn immediately from transient memory.
#[test]
fn strided_packed_and_immediate_polylines_agree() {
    let (mut r, sink) = common::renderer();
    let (w, h) = (128, 96);
    let mut target = offscreen(&mut r, w, h, 4);
    let shape = GridShape { rows: 30, cols: 12 };
    let surface = common::torus_section(shape, 1.0, 0.4);
    let col = 7;
    let column: Vec<[f32; 3]> = (0..shape.rows as usize)
        .map(|i| {
            let v = &surface[(i * shape.cols as usize + col) * 6..];
            [v[0], v[1], v[2]]
        })
        .collect();
    let packed: Vec<f32> = column.iter().flatten().copied().collect();
    // Put the packed copy at an odd offset to exercise sub-ranges too.
    let mut mirror = r.create_mirror("surface", surface.len()).expect("mirror");
    r.fill_mirror(&mut mirror, 0, &surface).expect("fill");
    let mut packed_mirror = r.create_mirror("packed", packed.len() + 9).expect("mirror");
    r.fill_mirror(&mut packed_mirror, 9, &packed).expect("fill");
    let style = PolylineStyle {
        color: [1.0, 1.0, 0.0, 1.0],
        width: 3.0,
        depth_test: true,
    };
    let cam = common::camera(Vec3::new(2.5, -2.5, 2.0), w, h);
    let mut images: Vec<Pixels> = Vec::new();
    for variant in 0..3 {
        let mut frame = r.begin_offscreen(&mut target).expect("begin");
        frame.set_camera(cam);
        match variant {
            0 => frame.draw_polyline(
                &mirror,
                PointRun::grid_column(0, shape.rows as usize, shape.cols as usize, 6, col),
                &style,
            ),
            1 => frame.draw_polyline(&packed_mirror, PointRun::packed(3, column.len()), &style),
            _ => frame.draw_polyline_immediate(&column, &style),
        }
        .expect("polyline");
        frame.capture();
        frame.finish().expect("finish");
        images.push(r.read_pixels(&target).expect("read"));
    }
    let yellow = images[0]
        .rgba
        .chunks_exact(4)
        .filter(|p| p[0] > 200 && p[1] > 200 && p[2] < 50)
        .count();
    assert!(yellow > 100, "polyline barely visible ({yellow} px)");
    assert!(images[0] == images[1], "strided and packed runs differ");
    assert!(
        images[0] == images[2],
        "mirror and immediate polylines differ"
    );
    r.destroy_mirror(mirror);
    r.destroy_mirror(packed_mirror);
    r.destroy_offscreen(target).expect("destroy");
    common::teardown(r, sink);
}

#[test]
fn bad_arguments_are_errors_not_panics() {
    let (mut r, sink) = common::renderer();
    let invalid = |e: Result<(), GpuError>| matches!(e, Err(GpuError::InvalidArgument(_)));
    assert!(
        r.create_offscreen(&OffscreenDesc {
            width: 0,
            height: 10,
            samples: 1
        })
        .is_err()
    );
    assert!(
        r.create_offscreen(&OffscreenDesc {
            width: 8,
            height: 8,
            samples: 3
        })
        .is_err()
    );
    assert!(r.create_mirror("empty", 0).is_err());
    let mut target = offscreen(&mut r, 32, 32, 1);
    let mut mirror = r.create_mirror("m", 60).expect("mirror");
    assert!(invalid(r.fill_mirror(&mut mirror, 50, &[0.0; 11])));
    r.fill_mirror(&mut mirror, 0, &[0.0; 60]).expect("fill");
    let mut frame = r.begin_offscreen(&mut target).expect("begin");
    assert!(invalid(
        frame.write_mirror(&mut mirror).write(59, &[1.0, 2.0])
    ));
    let style = PolylineStyle::default();
    // 20 points fit exactly; 21 do not; a stride below 3 is rejected; one point is no line.
    frame
        .draw_polyline(&mirror, PointRun::packed(0, 20), &style)
        .expect("exact fit");
    assert!(invalid(frame.draw_polyline(
        &mirror,
        PointRun::packed(0, 21),
        &style
    )));
    let bad_stride = PointRun {
        offset: 0,
        stride: 2,
        count: 4,
    };
    assert!(invalid(frame.draw_polyline(&mirror, bad_stride, &style)));
    assert!(invalid(frame.draw_polyline(
        &mirror,
        PointRun::packed(0, 1),
        &style
    )));
    let grid = SurfaceGrid {
        offset: 0,
        shape: GridShape { rows: 3, cols: 4 },
    };
    assert!(invalid(frame.draw_surface(
        &mirror,
        grid,
        &SurfaceStyle::default()
    )));
    let tiny = SurfaceGrid {
        offset: 0,
        shape: GridShape { rows: 1, cols: 4 },
    };
    assert!(invalid(frame.draw_wire(&mirror, tiny, 1, [1.0; 4])));
    frame.finish().expect("finish");
    r.destroy_mirror(mirror);
    r.destroy_offscreen(target).expect("destroy");
    common::teardown(r, sink);
}

#[test]
fn transient_growth_timestamps_and_teardown() {
    let (mut r, sink) = common::renderer();
    let mut target = offscreen(&mut r, 96, 64, 4);
    let shape = GridShape { rows: 16, cols: 16 };
    let surface = common::height_field(shape, &[(0.0, 0.0, 0.4, 0.5)]);
    let grid = SurfaceGrid { offset: 0, shape };
    let mut mirror = r.create_mirror("surface", surface.len()).expect("mirror");
    r.fill_mirror(&mut mirror, 0, &surface).expect("fill");
    // ~1.6 MB of lines per frame: the 256 KiB transient buffer must grow mid-frame while
    // earlier draws still reference the old one.
    let lines: Vec<LineVertex> = (0..100_000)
        .map(|k| {
            let t = k as f32 * 1e-3;
            LineVertex {
                pos: [t.cos(), t.sin(), (k % 2) as f32 * 0.1],
                color: [255, 128, 0, 255],
            }
        })
        .collect();
    let mut hud: Vec<OverlayVertex> = Vec::new();
    push_rect(&mut hud, 2.0, 2.0, 10.0, 10.0, [0, 255, 0, 255]);
    let mut gpu_times = Vec::new();
    for _ in 0..5 {
        let mut frame = r.begin_offscreen(&mut target).expect("begin");
        gpu_times.push(frame.gpu_time_ms());
        frame.set_camera(common::camera(Vec3::new(0.0, -3.0, 2.0), 96, 64));
        frame
            .draw_surface(&mirror, grid, &SurfaceStyle::default())
            .expect("surface");
        frame.draw_wire(&mirror, grid, 1, [0.0; 4]).expect("wire");
        frame.draw_lines3d(&lines[..1000]).expect("small lines");
        frame.draw_lines3d(&lines).expect("big lines");
        frame.draw_overlay(&hud).expect("hud");
        frame.capture();
        frame.finish().expect("finish");
    }
    let px = r.read_pixels(&target).expect("read");
    assert_eq!(px.get(6, 6), [0, 255, 0, 255], "overlay drawn after growth");
    if r.caps().timestamps() {
        // Slots report the previous use's time: nothing for the first two frames.
        assert_eq!(&gpu_times[..2], &[None, None]);
        assert!(gpu_times[2..].iter().all(|t| t.is_some_and(|ms| ms > 0.0)));
        assert!(r.last_gpu_time_ms().is_some());
    } else {
        assert!(gpu_times.iter().all(Option::is_none));
    }
    r.destroy_mirror(mirror);
    r.destroy_offscreen(target).expect("destroy");
    common::teardown(r, sink);
}

#[test]
fn leaked_resources_are_reported_by_validation() {
    // Negative control for the teardown checks: a mirror that is never destroyed must
    // show up as a validation error when the device is destroyed.
    let (mut r, sink) = common::renderer();
    let mirror = r.create_mirror("leaked", 16).expect("mirror");
    std::mem::forget(mirror);
    drop(r);
    let errors = sink.errors();
    assert!(
        errors
            .iter()
            .any(|m| m.id.contains("VUID-vkDestroyDevice-device-00378")),
        "leak not reported: {errors:?}"
    );
}
