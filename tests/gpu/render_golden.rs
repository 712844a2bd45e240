//! `prespline render` output against golden images on lavapipe (validation layer required):
//! the teapot shaded, a B-spline surface with its control net, an ERBS curve with its local
//! curves, the NURBS circle, and every display option (normals, Frenet frames, full wireframe,
//! local patches hidden). On mismatch `NAME-actual.png` and `NAME-diff.png` are written next to
//! the golden in `tests/golden/`; `PRESPLINE_BLESS=1` re-blesses. Negative controls show that
//! the comparator fails a rendering with a thin curve or a few control-point markers missing.

use crate::common;

use prespline::editor::Document;
use prespline::formats::parse_scene;
use prespline::gpu::Pixels;
use prespline::render::offscreen::{Shot, render_document};
use prespline::render::{NetMode, OrbitCamera, ViewOptions, Wire};
use prespline::scene::Scene;
use std::path::Path;

fn example(name: &str) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples")
        .join(name);
    prespline::formats::read_json(&path).unwrap()
}

fn render_scene(scene: &Scene, camera: Option<OrbitCamera>, options: ViewOptions) -> Pixels {
    let (mut renderer, sink) = common::renderer();
    let doc = Document::new(scene);
    let shot = Shot {
        width: 640,
        height: 400,
        camera,
        options,
        msaa: 4,
    };
    let pixels = render_document(&mut renderer, &doc, &shot).unwrap();
    common::teardown(renderer, sink);
    pixels
}

fn render(example_name: &str, options: ViewOptions) -> Pixels {
    render_scene(&example(example_name), None, options)
}

#[test]
fn teapot_shaded() {
    let px = render("teapot.json", ViewOptions::default());
    common::assert_golden("teapot", &px);
}

#[test]
fn bspline_surface_with_control_net() {
    let px = render(
        "bspline_surface.json",
        ViewOptions {
            control_nets: NetMode::All,
            wire: Wire::Isolines(8),
            ..ViewOptions::default()
        },
    );
    common::assert_golden("bspline_surface_net", &px);
}

#[test]
fn erbs_curve_with_local_curves() {
    let px = render(
        "erbs_curve.json",
        ViewOptions {
            control_nets: NetMode::All,
            local_curves: true,
            ..ViewOptions::default()
        },
    );
    common::assert_golden("erbs_curve_local", &px);
}

#[test]
fn nurbs_circle() {
    let px = render(
        "nurbs_circle.json",
        ViewOptions {
            control_nets: NetMode::All,
            curvature_comb: true,
            ..ViewOptions::default()
        },
    );
    common::assert_golden("nurbs_circle", &px);
}

#[test]
fn erbs_surface_with_local_patches() {
    let px = render(
        "erbs_surface.json",
        ViewOptions {
            local_curves: true,
            ..ViewOptions::default()
        },
    );
    common::assert_golden("erbs_surface_local", &px);
}

#[test]
fn surface_normals_and_full_wireframe() {
    let px = render(
        "bspline_surface.json",
        ViewOptions {
            wire: Wire::Full,
            normals: true,
            ..ViewOptions::default()
        },
    );
    common::assert_golden("bspline_surface_normals_wire", &px);
}

#[test]
fn curve_with_frenet_frames() {
    // A helix-like curve: its Frenet frames turn around the axis, so a wrong frame shows.
    let px = render(
        "helix.json",
        ViewOptions {
            frenet: true,
            ..ViewOptions::default()
        },
    );
    common::assert_golden("helix_frenet", &px);
}

#[test]
fn erbs_surface_without_local_patches() {
    let options = ViewOptions {
        local_curves: false,
        ..ViewOptions::default()
    };
    let px = render("erbs_surface.json", options);
    common::assert_golden("erbs_surface_no_local", &px);
    // The option has an effect: against the golden with the patches drawn it fails.
    let with_local = golden("erbs_surface_local");
    let diff = common::compare_images(&with_local, &px, common::GOLDEN.channel).unwrap();
    assert!(
        diff.check(&common::GOLDEN).is_err(),
        "hiding the local patches changed nothing"
    );
}

fn golden(name: &str) -> Pixels {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/golden")
        .join(format!("{name}.png"));
    Pixels::read_png(&path).unwrap()
}

/// A camera fixed in the scene (not framing it), so removing an object moves nothing else.
fn fixed_camera() -> Option<OrbitCamera> {
    Some(OrbitCamera::parse("0,-1,9,0,0,0,40").unwrap())
}

/// The circle and a short 2-px curve beside it.
fn circle_and_short_curve(with_short: bool) -> Scene {
    let mut scene = example("nurbs_circle.json");
    if with_short {
        let short = parse_scene(
            r#"{"objects": [{"name": "short", "type": "bezier_curve",
                "points": [[-0.6, -0.3, 0], [0, 0.2, 0], [0.6, -0.3, 0]], "samples": 40,
                "color": [0.3, 0.9, 0.4]}]}"#,
        )
        .unwrap();
        scene.objects.extend(short.objects);
    }
    scene
}

/// Negative control: a rendering that lacks one short thin curve must fail the comparator,
/// while a second rendering of the same scene passes it.
#[test]
fn comparator_fails_a_missing_thin_curve() {
    let expected = render_scene(
        &circle_and_short_curve(true),
        fixed_camera(),
        ViewOptions::default(),
    );
    let again = render_scene(
        &circle_and_short_curve(true),
        fixed_camera(),
        ViewOptions::default(),
    );
    let same = common::compare_images(&expected, &again, common::GOLDEN.channel).unwrap();
    same.check(&common::GOLDEN)
        .expect("the same scene rendered twice must pass");
    let missing = render_scene(
        &circle_and_short_curve(false),
        fixed_camera(),
        ViewOptions::default(),
    );
    let diff = common::compare_images(&expected, &missing, common::GOLDEN.channel).unwrap();
    eprintln!(
        "short curve missing: {} pixels ({:.4}%) differ, worst {}",
        diff.differing,
        diff.fraction() * 100.0,
        diff.worst
    );
    assert!(diff.differing > 0, "the short curve was not drawn at all");
    assert!(
        diff.check(&common::GOLDEN).is_err(),
        "a missing curve passed the golden comparator"
    );
}

/// A straight segment as a degree-1 B-spline through `points` collinear, evenly spaced control
/// points: the curve and its control polygon are the same whatever the count; only the number
/// of control-point markers changes.
fn segment(points: usize) -> Scene {
    let pts: Vec<String> = (0..points)
        .map(|i| {
            let t = i as f64 / (points - 1) as f64;
            format!("[{}, {}, 0]", -2.0 + 4.0 * t, -1.0 + 2.0 * t)
        })
        .collect();
    let mut knots = vec![0.0];
    knots.extend((0..points).map(|i| i as f64 / (points - 1) as f64));
    knots.push(1.0);
    let knots: Vec<String> = knots.iter().map(|k| format!("{k}")).collect();
    parse_scene(&format!(
        r#"{{"objects": [{{"name": "segment", "type": "bspline_curve", "degree": 1,
            "knots": [{}], "points": [{}], "samples": 61}}]}}"#,
        knots.join(", "),
        pts.join(", ")
    ))
    .unwrap()
}

/// Negative control: the same segment with three of its five control-point markers missing
/// must fail the comparator.
#[test]
fn comparator_fails_missing_control_point_markers() {
    let options = ViewOptions {
        control_nets: NetMode::All,
        ..ViewOptions::default()
    };
    let expected = render_scene(&segment(5), fixed_camera(), options);
    let missing = render_scene(&segment(2), fixed_camera(), options);
    let diff = common::compare_images(&expected, &missing, common::GOLDEN.channel).unwrap();
    eprintln!(
        "three markers missing: {} pixels ({:.4}%) differ, worst {}",
        diff.differing,
        diff.fraction() * 100.0,
        diff.worst
    );
    assert!(diff.differing > 0, "the markers were not drawn at all");
    assert!(
        diff.check(&common::GOLDEN).is_err(),
        "missing control-point markers passed the golden comparator"
    );
}

/// The bounds one by one on synthetic changes of a rendering: a 4×4 block far off fails on the
/// cap alone (16 pixels are well under the fraction), rounding-sized changes pass, and a
/// widespread small change fails on the fraction.
#[test]
fn comparator_bounds_each_fail_on_their_own() {
    let expected = golden("nurbs_circle");
    let paint = |f: &dyn Fn(&mut [u8])| {
        let mut p = expected.clone();
        for y in 100..104 {
            for x in 300..304 {
                let i = (y * p.width as usize + x) * 4;
                f(&mut p.rgba[i..i + 3]);
            }
        }
        p
    };
    let check = |actual: &Pixels| {
        common::compare_images(&expected, actual, common::GOLDEN.channel)
            .unwrap()
            .check(&common::GOLDEN)
    };
    let block = paint(&|px| px.iter_mut().for_each(|c| *c = c.wrapping_add(128)));
    let err = check(&block).expect_err("a 4×4 block off by 128 passed");
    assert!(
        err.contains("worst pixel") && !err.contains("pixels ("),
        "{err}"
    );
    let rounding = paint(&|px| px.iter_mut().for_each(|c| *c = c.saturating_add(2)));
    check(&rounding).expect("changes within the channel tolerance must pass");
    let mut everywhere = expected.clone();
    everywhere
        .rgba
        .iter_mut()
        .for_each(|c| *c = c.saturating_add(10));
    let err = check(&everywhere).expect_err("a change of every pixel passed");
    assert!(err.contains("pixels (") && !err.contains("worst"), "{err}");
}

/// Margins of the drawn pixels (those differing from the corner pixel): [left, right, top,
/// bottom] in pixels.
fn margins(px: &Pixels) -> [i64; 4] {
    let bg = px.get(0, 0);
    let (mut x0, mut x1, mut y0, mut y1) = (i64::MAX, i64::MIN, i64::MAX, i64::MIN);
    for y in 0..px.height {
        for x in 0..px.width {
            let c = px.get(x, y);
            if (0..3).any(|k| c[k].abs_diff(bg[k]) > 40) {
                let (x, y) = (i64::from(x), i64::from(y));
                (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
            }
        }
    }
    assert!(x0 <= x1, "something is drawn");
    let (w, h) = (i64::from(px.width), i64::from(px.height));
    [x0, w - 1 - x1, y0, h - 1 - y1]
}

/// The default framing frames the projected bounds: a flat rectangle seen from the default
/// oblique direction for flat scenes fills the image with equal margins left and right and
/// top and bottom (within 3 px: line width and rasterisation). Negative control: the same
/// camera with its target moved a quarter of the rectangle along +y has them clearly unequal.
#[test]
fn default_framing_balances_the_margins_of_a_flat_object() {
    let scene = parse_scene(
        r#"{"objects": [{"name": "frame", "type": "bspline_curve", "degree": 1,
        "knots": [0, 0, 1, 2, 3, 4, 4], "points": [[-3, -1, 0], [3, -1, 0], [3, 1, 0], [-3, 1, 0], [-3, -1, 0]],
        "samples": 200}]}"#,
    )
    .unwrap();
    let [left, right, top, bottom] = margins(&render_scene(&scene, None, ViewOptions::default()));
    assert!((left - right).abs() <= 3, "left {left} right {right}");
    assert!((top - bottom).abs() <= 3, "top {top} bottom {bottom}");
    // 90 % of the tighter direction is filled: 5 % margins on each side of it.
    assert!(
        (left.min(top) - 20).abs() <= 6 || (left - 32).abs() <= 6,
        "margins {left} {right} {top} {bottom}"
    );
    let doc = Document::new(&scene);
    let shot = Shot {
        width: 640,
        height: 400,
        camera: None,
        options: ViewOptions::default(),
        msaa: 4,
    };
    let mut moved = prespline::render::offscreen::shot_camera(&doc, &shot);
    moved.target.y += 0.5;
    let [_, _, top, bottom] = margins(&render_scene(&scene, Some(moved), ViewOptions::default()));
    assert!(
        (top - bottom).abs() > 20,
        "negative control: an off-centre target shows: top {top} bottom {bottom}"
    );
}
