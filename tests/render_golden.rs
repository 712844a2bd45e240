//! `prespline render` output against golden images on lavapipe (validation layer required):
//! the teapot shaded, a B-spline surface with its control net, an ERBS curve with its local
//! curves, and the NURBS circle. On mismatch `NAME-actual.png` and `NAME-diff.png` are written
//! next to the golden in `tests/golden/`; `PRESPLINE_BLESS=1` re-blesses.

mod common;

use prespline::render::offscreen::{Shot, render_document};
use prespline::render::{Document, NetMode, ViewOptions, Wire};
use prespline::scene::Scene;
use std::path::Path;

fn render(example: &str, options: ViewOptions) -> prespline::gpu::Pixels {
    let (mut renderer, sink) = common::renderer();
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples")
        .join(example);
    let doc = Document::new(&Scene::load(&path).unwrap());
    let shot = Shot {
        width: 640,
        height: 400,
        camera: None,
        options,
        msaa: 4,
    };
    let pixels = render_document(&mut renderer, &doc, &shot).unwrap();
    common::teardown(renderer, sink);
    pixels
}

/// Per-channel tolerance and mismatching-pixel fraction: rasterisation on lavapipe is
/// deterministic; the slack only absorbs rounding differences between driver builds.
const TOLERANCE: u8 = 2;
const MAX_FRACTION: f64 = 0.002;

#[test]
fn teapot_shaded() {
    let px = render("teapot.json", ViewOptions::default());
    common::assert_golden("teapot", &px, TOLERANCE, MAX_FRACTION);
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
    common::assert_golden("bspline_surface_net", &px, TOLERANCE, MAX_FRACTION);
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
    common::assert_golden("erbs_curve_local", &px, TOLERANCE, MAX_FRACTION);
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
    common::assert_golden("nurbs_circle", &px, TOLERANCE, MAX_FRACTION);
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
    common::assert_golden("erbs_surface_local", &px, TOLERANCE, MAX_FRACTION);
}
