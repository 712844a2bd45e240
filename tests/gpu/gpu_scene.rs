//! Offscreen rendering of a synthetic scene through real Vulkan (lavapipe), compared with a
//! golden image, with the validation layer watching.

use crate::common;

use glam::Vec3;
use prespline::gpu::font::{TextSize, push_rect};
use prespline::gpu::{
    GridShape, LineVertex, OffscreenDesc, PointRun, PointStyle, PolylineStyle, SurfaceGrid,
    SurfaceStyle,
};

const W: u32 = 320;
const H: u32 = 240;

#[test]
fn synthetic_scene_matches_golden() {
    let (mut r, sink) = common::renderer();
    let shape = GridShape { rows: 40, cols: 24 };
    let surface = common::torus_section(shape, 1.0, 0.4);
    let helix = common::helix(160, 1.55, 2.5, -0.7, 0.7);
    let controls: Vec<f32> = (0..8)
        .flat_map(|k| {
            let a = k as f32 * 0.8;
            [1.8 * a.cos(), 1.8 * a.sin(), 0.9]
        })
        .collect();

    // One mirror holding everything, at different offsets.
    let grid = SurfaceGrid { offset: 0, shape };
    let helix_at = grid.floats();
    let controls_at = helix_at + helix.len();
    let len = controls_at + controls.len();
    let mut mirror = r.create_mirror("scene", len).expect("mirror");
    let mut all = surface.clone();
    all.extend_from_slice(&helix);
    all.extend_from_slice(&controls);
    r.fill_mirror(&mut mirror, 0, &all).expect("fill");

    let mut target = r
        .create_offscreen(&OffscreenDesc {
            width: W,
            height: H,
            samples: 4,
        })
        .expect("target");
    assert_eq!(target.samples(), 4);

    // Normals at every 6th sample as a lines3d overlay.
    let mut normals = Vec::new();
    for v in surface.chunks_exact(6).step_by(6) {
        let p = Vec3::new(v[0], v[1], v[2]);
        let n = Vec3::new(v[3], v[4], v[5]);
        normals.push(LineVertex {
            pos: p.into(),
            color: [40, 200, 90, 255],
        });
        normals.push(LineVertex {
            pos: (p + 0.2 * n).into(),
            color: [40, 200, 90, 255],
        });
    }
    let mut hud = Vec::new();
    let font = r.font();
    let [tw, th] = font.text_size("prespline 0.1", TextSize::Normal);
    push_rect(&mut hud, 4.0, 4.0, tw + 8.0, th + 8.0, [0, 0, 0, 160]);
    font.push_text(
        &mut hud,
        "prespline 0.1",
        8.0,
        8.0,
        TextSize::Normal,
        [255, 230, 120, 255],
    );

    let mut frame = r.begin_offscreen(&mut target).expect("begin");
    frame.set_clear_color([0.05, 0.05, 0.07, 1.0]);
    frame.set_camera(common::camera(Vec3::new(3.4, -3.0, 2.6), W, H));
    frame
        .draw_surface(&mirror, grid, &SurfaceStyle::default())
        .expect("surface");
    frame
        .draw_wire(&mirror, grid, 4, [0.05, 0.05, 0.1, 1.0])
        .expect("isolines");
    // A surface column as a polyline straight from the surface vertices (stride = row).
    let column = PointRun::grid_column(0, shape.rows as usize, shape.cols as usize, 6, 5);
    frame
        .draw_polyline(
            &mirror,
            column,
            &PolylineStyle {
                color: [0.9, 0.2, 0.9, 1.0],
                width: 3.0,
                depth_test: true,
            },
        )
        .expect("column");
    frame
        .draw_polyline(
            &mirror,
            PointRun::packed(helix_at / 3, helix.len() / 3),
            &PolylineStyle {
                color: [0.2, 0.8, 1.0, 1.0],
                width: 2.5,
                depth_test: true,
            },
        )
        .expect("helix");
    let control_run = PointRun::packed(controls_at / 3, controls.len() / 3);
    frame
        .draw_polyline(
            &mirror,
            control_run,
            &PolylineStyle {
                color: [0.6, 0.6, 0.6, 1.0],
                width: 1.5,
                depth_test: false,
            },
        )
        .expect("control polygon");
    frame
        .draw_points(
            &mirror,
            control_run,
            &PointStyle {
                size: 9.0,
                hovered: Some(2),
                selected: Some(5),
                ..PointStyle::default()
            },
        )
        .expect("points");
    frame.draw_lines3d(&normals).expect("normals");
    frame.draw_overlay(&hud).expect("hud");
    frame.capture();
    frame.finish().expect("finish");

    let pixels = r.read_pixels(&target).expect("read");
    // The clear colour survives in a corner; the scene covers a good part of the image.
    assert_eq!(pixels.get(W - 1, H - 1)[..3], [63, 63, 75]);
    let lit = pixels
        .rgba
        .chunks_exact(4)
        .filter(|p| p[..3] != [63, 63, 75])
        .count();
    assert!(lit > (W * H / 6) as usize, "only {lit} pixels drawn");
    common::assert_golden("scene", &pixels);

    r.destroy_mirror(mirror);
    r.destroy_offscreen(target).expect("destroy target");
    common::teardown(r, sink);
}
