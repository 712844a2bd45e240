//! Trimmed surfaces on lavapipe (validation on): the OBJ specification's trimming examples and
//! a trimmed JSON scene against golden images; the drawn boundary within a pixel of the exact
//! one at a close zoom (10⁵ pixels across the surface); two faces sharing a curved edge
//! without a crack. Each geometric check has a negative control that must fail it.

use crate::common;

use glam::{DMat4, DVec2, DVec3, DVec4};
use prespline::editor::Document;
use prespline::formats::{LoadOptions, SampleDefaults, load, parse_scene};
use prespline::gpu::Pixels;
use prespline::render::offscreen::{Shot, render_document, shot_camera};
use prespline::render::{OrbitCamera, ViewOptions};
use prespline::sampling::budget::MemoryBudget;
use prespline::scene::Scene;
use std::path::Path;

fn data(name: &str) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(name);
    let options = LoadOptions {
        budget: MemoryBudget::machine_default(),
        progress: &prespline::progress::Silent,
        samples: SampleDefaults::default(),
    };
    load(&path, options).unwrap().scene
}

fn shot(width: u32, height: u32, camera: Option<OrbitCamera>, msaa: u32) -> Shot {
    Shot {
        width,
        height,
        camera,
        options: ViewOptions::default(),
        msaa,
    }
}

fn render(scene: &Scene, shot: &Shot) -> Pixels {
    let (mut renderer, sink) = common::renderer();
    let doc = Document::new(scene);
    let pixels = render_document(&mut renderer, &doc, shot).unwrap();
    common::teardown(renderer, sink);
    pixels
}

#[test]
fn the_obj_specification_trimming_examples_render_trimmed() {
    for (file, golden) in [
        (
            "tests/data/obj_spec_trimming_with_holes.obj",
            "trim_obj_holes",
        ),
        (
            "tests/data/obj_spec_special_curve.obj",
            "trim_obj_special_curve",
        ),
        (
            "tests/data/obj_spec_special_points.obj",
            "trim_obj_special_points",
        ),
        ("tests/data/obj_kept_statements.obj", "trim_obj_connected"),
        ("examples/trimmed_surface.json", "trim_json_example"),
    ] {
        let px = render(&data(file), &shot(640, 400, None, 4));
        common::assert_golden(golden, &px);
    }
}

/// A unit plane (x = u, y = v, z = 0) trimmed by a circle of radius `r` about (0.5, 0.5),
/// given as the rational quadratic B-spline.
fn plane_disc(r: f64) -> Scene {
    let c = DVec2::new(0.5, 0.5);
    let mut pts = Vec::new();
    let mut w = Vec::new();
    for k in 0..9 {
        let a = k as f64 * std::f64::consts::FRAC_PI_4;
        let rr = if k % 2 == 0 { r } else { r * 2f64.sqrt() };
        let p = c + rr * DVec2::new(a.cos(), a.sin());
        pts.push(format!("[{:?}, {:?}]", p.x, p.y));
        w.push(if k % 2 == 0 {
            1.0
        } else {
            std::f64::consts::FRAC_1_SQRT_2
        });
    }
    let text = format!(
        r#"{{"objects": [{{"name": "plane", "type": "bspline_surface", "degree": [1, 1],
  "knots": [[0, 0, 1, 1], [0, 0, 1, 1]], "points": [[[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 0]]],
  "samples": [9, 9], "trim": [{{"outer": [{{"bspline": [{}], "degree": 2,
  "knots": [0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1], "weights": {w:?}}}]}}]}}]}}"#,
        pts.join(", ")
    );
    parse_scene(&text).unwrap()
}

/// Pixel centres of a `w × h` image as points of the plane z = 0 seen through `view_proj`.
fn unproject(view_proj: &DMat4, w: u32, h: u32, x: u32, y: u32) -> DVec3 {
    let inv = view_proj.inverse();
    let ndc = DVec2::new(
        2.0 * (f64::from(x) + 0.5) / f64::from(w) - 1.0,
        1.0 - 2.0 * (f64::from(y) + 0.5) / f64::from(h),
    );
    let at = |z: f64| {
        let p = inv * DVec4::new(ndc.x, ndc.y, z, 1.0);
        p.truncate() / p.w
    };
    let (a, b) = (at(0.0), at(1.0));
    a + (b - a) * (-a.z / (b.z - a.z))
}

/// The worst distance, in pixels, from a pixel whose coverage disagrees with the exact disc
/// (inside |p − c| ≤ r_exact) to the exact circle; 0 when every pixel agrees.
fn worst_boundary_error(scene: &Scene, r_exact: f64) -> f64 {
    let (w, h) = (320, 240);
    let eye = "0.8,0.5,0.23,0.8,0.5,0,1";
    let camera = OrbitCamera::parse(eye).unwrap();
    let px = render(scene, &shot(w, h, Some(camera), 1));
    let doc = Document::new(scene);
    let view_proj = camera.view_proj(f64::from(w) / f64::from(h), &doc.bounds());
    let background = px.get(w - 1, 0);
    // The world size of one pixel at the image centre.
    let centre = unproject(&view_proj, w, h, w / 2, h / 2);
    let pixel = centre.distance(unproject(&view_proj, w, h, w / 2 + 1, h / 2));
    assert!(pixel < 2e-5, "not a close zoom: {pixel} per pixel");
    let c = DVec3::new(0.5, 0.5, 0.0);
    let mut worst: f64 = 0.0;
    let mut crossings = 0;
    for y in 0..h {
        for x in 0..w {
            let p = unproject(&view_proj, w, h, x, y);
            let exact = p.distance(c) <= r_exact;
            let drawn = px.get(x, y) != background;
            if exact != drawn {
                worst = worst.max((p.distance(c) - r_exact).abs() / pixel);
            }
            if x > 0 && drawn != (px.get(x - 1, y) != background) {
                crossings += 1;
            }
        }
    }
    assert!(
        crossings >= h / 2,
        "the boundary is not in the picture ({crossings} crossings)"
    );
    worst
}

#[test]
fn the_drawn_boundary_stays_within_a_pixel_of_the_exact_one_at_a_close_zoom() {
    let worst = worst_boundary_error(&plane_disc(0.3), 0.3);
    println!("worst boundary error at 1e-5 per pixel: {worst:.3} px");
    assert!(worst <= 1.0, "boundary off by {worst} pixels");
}

/// Negative control: a trim 3 pixels larger than the exact circle fails the check.
#[test]
fn a_boundary_three_pixels_off_fails_the_zoom_check() {
    let worst = worst_boundary_error(&plane_disc(0.3 + 3e-5), 0.3);
    assert!(worst > 1.0, "a shifted boundary passed: {worst} px");
}

/// Two planes meeting along a curved edge x = 1 + 0.15 sin(πy), y ∈ [0, 1]: the left one
/// (x = u, y = v on [0, 1.5] × [0, 1]) trimmed to its side, the right one (x = u + 0.5) to
/// the other; the edge is the same polyline of 3D points in both. `gap` moves the right
/// face's edge to the right (a negative control).
fn two_faces(gap: f64) -> Scene {
    let edge: Vec<(f64, f64)> = (0..=40)
        .map(|k| {
            let y = f64::from(k) / 40.0;
            (1.0 + 0.15 * (std::f64::consts::PI * y).sin(), y)
        })
        .collect();
    let left: Vec<String> = std::iter::once("[0.0, 0.0]".to_string())
        .chain(edge.iter().map(|(x, y)| format!("[{x:?}, {y:?}]")))
        .chain(["[0.0, 1.0]".to_string(), "[0.0, 0.0]".to_string()])
        .collect();
    let right: Vec<String> = edge
        .iter()
        .map(|(x, y)| format!("[{:?}, {y:?}]", x - 0.5 + gap))
        .chain([
            "[1.5, 1.0]".to_string(),
            "[1.5, 0.0]".to_string(),
            format!("[{:?}, 0.0]", edge[0].0 - 0.5 + gap),
        ])
        .collect();
    let plane = |name: &str, x0: f64, trim: &[String]| {
        format!(
            r#"{{"name": "{name}", "type": "bspline_surface", "degree": [1, 1],
  "knots": [[0, 0, 1.5, 1.5], [0, 0, 1, 1]],
  "points": [[[{x0}, 0, 0], [{x0}, 1, 0]], [[{x1}, 0, 0], [{x1}, 1, 0]]], "samples": [17, 17],
  "color": [0.8, 0.6, 0.3], "trim": [{{"outer": [{{"polyline": [{}]}}]}}]}}"#,
            trim.join(", "),
            x1 = x0 + 1.5
        )
    };
    let text = format!(
        "{{\"objects\": [{}, {}]}}",
        plane("left", 0.0, &left),
        plane("right", 0.5, &right)
    );
    parse_scene(&text).unwrap()
}

/// Background pixels found along the middle of the seam of [`two_faces`] (the shared edge
/// moved by half the `gap` between the faces) at the default view.
fn crack_pixels(scene: &Scene, gap: f64) -> usize {
    let (w, h) = (640, 400);
    let s = shot(w, h, None, 1);
    let px = render(scene, &s);
    let doc = Document::new(scene);
    let camera = shot_camera(&doc, &s);
    let view_proj = camera.view_proj(f64::from(w) / f64::from(h), &doc.bounds());
    let background = px.get(0, 0);
    let mut cracks = 0;
    for k in 1..400 {
        let y = f64::from(k) / 400.0;
        let p = DVec3::new(
            1.0 + 0.5 * gap + 0.15 * (std::f64::consts::PI * y).sin(),
            y,
            0.0,
        );
        let clip = view_proj * p.extend(1.0);
        let ndc = clip.truncate() / clip.w;
        let x = ((ndc.x + 1.0) * 0.5 * f64::from(w)).floor() as u32;
        let row = ((1.0 - ndc.y) * 0.5 * f64::from(h)).floor() as u32;
        if x < w && row < h && px.get(x, row) == background {
            cracks += 1;
        }
    }
    cracks
}

#[test]
fn two_faces_sharing_an_edge_show_no_crack() {
    assert_eq!(crack_pixels(&two_faces(0.0), 0.0), 0);
}

/// Negative control: the right face's edge moved 2 % of the face to the right opens a crack
/// (about 5 pixels, more than the half pixel each face grows by) the check sees.
#[test]
fn a_gap_between_two_faces_is_seen_as_a_crack() {
    assert!(crack_pixels(&two_faces(0.02), 0.02) > 50);
}
