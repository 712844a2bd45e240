//! Mirror buffers under two frames in flight: long random sequences of partial updates,
//! each frame slot receiving exactly the ranges it has not seen yet, must render the same
//! pixels as a fresh mirror holding the final data.

use crate::common;

use std::ops::Range;

use glam::Vec3;
use prespline::gpu::{
    FRAMES_IN_FLIGHT, GridShape, Mirror, OffscreenDesc, OffscreenTarget, Pixels, PointRun,
    PointStyle, PolylineStyle, Renderer, SurfaceGrid, SurfaceStyle,
};

const W: u32 = 160;
const H: u32 = 120;
const SHAPE: GridShape = GridShape { rows: 24, cols: 20 };
const BUMPS: [(f32, f32, f32, f32); 2] = [(-0.3, 0.2, 0.5, 0.5), (0.5, -0.4, -0.3, 0.4)];

/// Renders one frame; first copies `pending[slot]` ranges of `data` into the frame's slot.
fn render(
    r: &mut Renderer,
    target: &mut OffscreenTarget,
    mirror: &mut Mirror,
    pending: &mut [Vec<Range<usize>>],
    data: &[f32],
) {
    let grid = SurfaceGrid {
        offset: 0,
        shape: SHAPE,
    };
    let mut frame = r.begin_offscreen(target).expect("begin");
    let slot = frame.slot();
    {
        let mut w = frame.write_mirror(mirror);
        for range in pending[slot].drain(..) {
            w.write(range.start, &data[range]).expect("write");
        }
    }
    frame.set_camera(common::camera(Vec3::new(0.4, -2.6, 2.2), W, H));
    frame
        .draw_surface(mirror, grid, &SurfaceStyle::default())
        .expect("surface");
    frame
        .draw_wire(mirror, grid, 3, [0.0, 0.0, 0.0, 1.0])
        .expect("wire");
    let (rows, cols) = (SHAPE.rows as usize, SHAPE.cols as usize);
    for col in [0, cols / 2, cols - 1] {
        frame
            .draw_polyline(
                mirror,
                PointRun::grid_column(0, rows, cols, 6, col),
                &PolylineStyle {
                    color: [1.0, 0.3, 0.1, 1.0],
                    width: 2.0,
                    depth_test: true,
                },
            )
            .expect("column");
    }
    frame
        .draw_points(
            mirror,
            PointRun::grid_row(0, cols, 6, rows / 2),
            &PointStyle {
                size: 5.0,
                hovered: Some(3),
                selected: Some(7),
                depth_test: true,
                ..PointStyle::default()
            },
        )
        .expect("points");
    frame.capture();
    frame.finish().expect("finish");
}

/// Moves the vertices of a random rectangle of the grid and returns the float range of the
/// touched rows (what a sampler would mark dirty).
fn random_edit(rng: &mut common::Rng, data: &mut [f32]) -> Range<usize> {
    let (rows, cols) = (SHAPE.rows as usize, SHAPE.cols as usize);
    let i0 = rng.range(0, rows);
    let i1 = rng.range(i0 + 1, (i0 + 6).min(rows) + 1);
    let j0 = rng.range(0, cols);
    let j1 = rng.range(j0 + 1, (j0 + 6).min(cols) + 1);
    let dz = rng.f32(-0.25, 0.25);
    let tilt = Vec3::new(rng.f32(-0.5, 0.5), rng.f32(-0.5, 0.5), 0.0);
    for i in i0..i1 {
        for j in j0..j1 {
            let v = &mut data[(i * cols + j) * 6..][..6];
            v[2] += dz;
            let n = (Vec3::new(v[3], v[4], v[5]) + tilt).normalize();
            v[3..6].copy_from_slice(&n.to_array());
        }
    }
    i0 * cols * 6..i1 * cols * 6
}

/// Runs `frames` frames of random edits. With `drop_slot_update`, the very last edit is
/// (wrongly) given only to the slot rendered next, not to the final frame's slot.
fn incremental_vs_fresh(
    seed: u64,
    frames: usize,
    always_flush: bool,
    drop_slot_update: bool,
) -> (Pixels, Pixels) {
    let (mut r, sink) = common::renderer_with(always_flush);
    let mut target = r
        .create_offscreen(&OffscreenDesc {
            width: W,
            height: H,
            samples: 0,
        })
        .expect("target");
    let mut data = common::height_field(SHAPE, &BUMPS);
    let mut mirror = r.create_mirror("grid", data.len()).expect("mirror");
    r.fill_mirror(&mut mirror, 0, &data).expect("fill");
    let mut pending: Vec<Vec<Range<usize>>> = vec![Vec::new(); FRAMES_IN_FLIGHT];
    let mut rng = common::Rng::new(seed);
    for f in 0..frames {
        let last = f + 1 == frames;
        for _ in 0..rng.range(0, 4) {
            let range = random_edit(&mut rng, &mut data);
            for p in &mut pending {
                p.push(range.clone());
            }
        }
        if last && drop_slot_update {
            // The edit reaches the slot of frame f-1 but not the one of frame f.
            let range = random_edit(&mut rng, &mut data);
            let skipped = r.frame_number() as usize % FRAMES_IN_FLIGHT;
            pending[(skipped + 1) % FRAMES_IN_FLIGHT].push(range);
        }
        render(&mut r, &mut target, &mut mirror, &mut pending, &data);
    }
    let incremental = r.read_pixels(&target).expect("read incremental");

    let mut fresh = r.create_mirror("fresh", data.len()).expect("fresh mirror");
    r.fill_mirror(&mut fresh, 0, &data).expect("fill fresh");
    let mut none = vec![Vec::new(); FRAMES_IN_FLIGHT];
    render(&mut r, &mut target, &mut fresh, &mut none, &data);
    let fresh_pixels = r.read_pixels(&target).expect("read fresh");

    r.destroy_mirror(mirror);
    r.destroy_mirror(fresh);
    r.destroy_offscreen(target).expect("destroy target");
    common::teardown(r, sink);
    (incremental, fresh_pixels)
}

#[test]
fn partial_updates_across_frames_match_fresh_render() {
    for seed in [1, 0xdead_beef, 42] {
        let (incremental, fresh) = incremental_vs_fresh(seed, 60, false, false);
        assert!(
            incremental == fresh,
            "seed {seed}: incremental mirror updates rendered different pixels"
        );
    }
}

#[test]
fn partial_updates_with_forced_flushes_match_fresh_render() {
    // Flushing coherent memory is legal; it runs the atom-aligned flush path under the
    // validation layer, which checks alignment and bounds of every range.
    let (incremental, fresh) = incremental_vs_fresh(7, 40, true, false);
    assert!(
        incremental == fresh,
        "forced-flush path rendered different pixels"
    );
}

#[test]
fn a_slot_missing_an_update_is_detected() {
    // Negative control: the comparison above must be able to fail.
    let (incremental, fresh) = incremental_vs_fresh(3, 10, false, true);
    assert!(incremental != fresh, "a stale slot went unnoticed");
}

/// A split writer refuses overlapping or out-of-range ranges and writes outside its range,
/// each as an error, and its disjoint ranges written on threads give the same pixels as one
/// fill.
#[test]
fn split_writers_fill_disjoint_ranges_and_refuse_the_rest() {
    let (mut r, sink) = common::renderer_with(false);
    let mut target = r
        .create_offscreen(&OffscreenDesc {
            width: W,
            height: H,
            samples: 0,
        })
        .expect("target");
    let data = common::height_field(SHAPE, &BUMPS);
    let mut mirror = r.create_mirror("split", data.len()).expect("mirror");
    for _ in 0..FRAMES_IN_FLIGHT {
        let mut frame = r.begin_offscreen(&mut target).expect("begin");
        {
            let mut w = frame.write_mirror(&mut mirror);
            let n = data.len();
            assert!(w.split(&[0..10, 5..20]).is_err(), "overlapping ranges");
            assert!(w.split(&[0..1, 2..n + 1]).is_err(), "past the end");
            let (a, b) = (n / 3, 2 * n / 3);
            let mut parts = w.split(&[0..a, a..b, b..n]).expect("split");
            assert!(
                parts[0].write(a - 1, &[0.0, 0.0]).is_err(),
                "outside its range"
            );
            std::thread::scope(|s| {
                for part in &mut parts {
                    let data = &data;
                    s.spawn(move || {
                        let range = part.range();
                        part.write(range.start, &data[range]).expect("write");
                    });
                }
            });
        }
        frame.finish().expect("finish");
    }
    let mut none = vec![Vec::new(); FRAMES_IN_FLIGHT];
    render(&mut r, &mut target, &mut mirror, &mut none, &data);
    let split = r.read_pixels(&target).expect("read");
    let mut fresh = r.create_mirror("fresh", data.len()).expect("fresh mirror");
    r.fill_mirror(&mut fresh, 0, &data).expect("fill fresh");
    render(&mut r, &mut target, &mut fresh, &mut none, &data);
    let filled = r.read_pixels(&target).expect("read fresh");
    let diff = common::compare_images(&filled, &split, 0).unwrap();
    assert_eq!(diff.differing, 0, "{} pixels differ", diff.differing);
    r.destroy_mirror(mirror);
    r.destroy_mirror(fresh);
    r.destroy_offscreen(target).expect("destroy target");
    common::teardown(r, sink);
}
