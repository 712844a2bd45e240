//! Analysis views rendered on lavapipe (validation layer required): a golden image of every
//! surface map (Gaussian, mean, max and min principal curvature, zebra) on the B-spline surface
//! example, the curvature maps on an exact sphere and cylinder, and continuity badges with an
//! osculating circle on curves. The map's scalar mirrors follow the delta path: after random
//! drags over many frames with two frames in flight (and map changes on the way) the picture
//! equals a fresh upload, and one interior drag copies only its touched rows of the map.
//! `PRESPLINE_BLESS=1` re-blesses the goldens.

use crate::common;

use glam::DVec3;
use prespline::editor::Document;
use prespline::gpu::font::TextSize;
use prespline::gpu::{OffscreenDesc, OffscreenTarget, Pixels, Renderer};
use prespline::model::{Edit, KindEdit, PointEdit, SurfaceEdit};
use prespline::render::analysis::{
    CurveEval, Osculating, PANEL, badge_overlay, osculating_panel_origin, osculating_text,
};
use prespline::render::maps::{MapScale, SurfaceMap};
use prespline::render::offscreen::{Shot, render_document, shot_camera};
use prespline::render::{GpuScene, Highlight, Lod, MapView, ViewOptions};
use prespline::scene::Scene;
use std::path::Path;

fn load(path: &str) -> Scene {
    prespline::formats::read_json(&Path::new(env!("CARGO_MANIFEST_DIR")).join(path)).unwrap()
}

/// `scene` rendered as `prespline render --analysis` does: curvature maps re-sample the
/// surfaces with second partials first.
fn render_with(scene: &Scene, options: ViewOptions) -> Pixels {
    let (mut renderer, sink) = common::renderer();
    let doc = common::editor(scene, options.analysis).into_document();
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

fn map_options(map: SurfaceMap) -> ViewOptions {
    ViewOptions {
        analysis: Some(map),
        ..ViewOptions::default()
    }
}

fn golden_map(scene: &str, label: &str, map: SurfaceMap) -> Pixels {
    let px = render_with(&load(scene), map_options(map));
    common::assert_golden(&format!("analysis_{label}_{}", map.name()), &px);
    px
}

#[test]
fn gaussian_curvature_golden() {
    golden_map(
        "examples/bspline_surface.json",
        "bspline",
        SurfaceMap::Gaussian,
    );
}

#[test]
fn mean_curvature_golden() {
    golden_map("examples/bspline_surface.json", "bspline", SurfaceMap::Mean);
}

#[test]
fn max_principal_curvature_golden() {
    golden_map(
        "examples/bspline_surface.json",
        "bspline",
        SurfaceMap::MaxPrincipal,
    );
}

#[test]
fn min_principal_curvature_golden() {
    golden_map(
        "examples/bspline_surface.json",
        "bspline",
        SurfaceMap::MinPrincipal,
    );
}

#[test]
fn zebra_golden() {
    golden_map(
        "examples/bspline_surface.json",
        "bspline",
        SurfaceMap::Zebra,
    );
}

#[test]
fn sphere_and_cylinder_gaussian_goldens() {
    golden_map("tests/data/sphere.json", "sphere", SurfaceMap::Gaussian);
    golden_map("tests/data/cylinder.json", "cylinder", SurfaceMap::Gaussian);
}

/// Linear value of an sRGB byte.
fn linear(c: u8) -> f32 {
    let x = c as f32 / 255.0;
    if x <= 0.04045 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    }
}

/// The centre pixel's hue class: which of red and blue dominates, or neither (white/grey).
fn centre_tint(px: &Pixels) -> (f32, f32) {
    let (w, h) = (px.width as usize, px.height as usize);
    let i = ((h / 2) * w + w / 2) * 4;
    let [r, _, b] = [0, 1, 2].map(|k| linear(px.rgba[i + k]));
    (r, b)
}

/// The colours mean what the legend says: the sphere's K = 1/r² > 0 is red, its H = −1/r
/// (outward normals) blue, and the cylinder's K = 0 is neutral (red and blue equal).
#[test]
fn map_colours_follow_the_sign() {
    let (r, b) = centre_tint(&render_with(
        &load("tests/data/sphere.json"),
        map_options(SurfaceMap::Gaussian),
    ));
    assert!(r > 2.0 * b, "sphere K should be red: r {r} b {b}");
    let (r, b) = centre_tint(&render_with(
        &load("tests/data/sphere.json"),
        map_options(SurfaceMap::Mean),
    ));
    assert!(b > 2.0 * r, "sphere H should be blue: r {r} b {b}");
    let (r, b) = centre_tint(&render_with(
        &load("tests/data/cylinder.json"),
        map_options(SurfaceMap::Gaussian),
    ));
    assert!(
        (r - b).abs() < 0.02 && r > 0.1,
        "cylinder K should be white: r {r} b {b}"
    );
}

/// Negative control: the same surface under two different maps fails the golden comparator
/// (the scalars reach the picture).
#[test]
fn comparator_tells_the_maps_apart() {
    let scene = load("examples/bspline_surface.json");
    let k = render_with(&scene, map_options(SurfaceMap::Gaussian));
    let h = render_with(&scene, map_options(SurfaceMap::Mean));
    let plain = render_with(&scene, ViewOptions::default());
    for (what, other) in [("mean", &h), ("plain shading", &plain)] {
        let diff = common::compare_images(&k, other, common::GOLDEN.channel).unwrap();
        assert!(
            diff.check(&common::GOLDEN).is_err(),
            "Gaussian map and {what} passed the comparator"
        );
    }
}

#[test]
fn badges_and_osculating_circle_golden() {
    let scene = load("tests/data/badges.json");
    let px = render_with(
        &scene,
        ViewOptions {
            badges: true,
            osculating_at: Some((0, 2.5)),
            ..ViewOptions::default()
        },
    );
    common::assert_golden("analysis_badges", &px);
}

#[test]
fn bezier_spline_and_catmull_rom_badges_golden() {
    for (file, name) in [
        (
            "examples/bezier_spline.json",
            "analysis_badges_bezier_spline",
        ),
        ("examples/catmull_rom.json", "analysis_badges_catmull_rom"),
    ] {
        let px = render_with(
            &load(file),
            ViewOptions {
                badges: true,
                ..ViewOptions::default()
            },
        );
        common::assert_golden(name, &px);
    }
}

/// A fixed-camera shot with `map` on.
fn shot(doc: &Document, map: SurfaceMap) -> Shot {
    let base = Shot {
        width: 400,
        height: 280,
        camera: None,
        options: map_options(map),
        msaa: 1,
    };
    Shot {
        camera: Some(shot_camera(doc, &base)),
        ..base
    }
}

/// Uploads what changed and draws one frame; returns the upload's bytes.
fn frame(
    renderer: &mut Renderer,
    target: &mut OffscreenTarget,
    gs: &mut GpuScene,
    doc: &Document,
    shot: &Shot,
) -> usize {
    let camera = shot_camera(doc, shot);
    let aspect = shot.width as f64 / shot.height as f64;
    let mut frame = renderer.begin_offscreen(target).unwrap();
    let bytes = gs.upload(&mut frame, doc).unwrap().bytes;
    frame.set_camera(camera.gpu(aspect, &doc.bounds()));
    let lod = Lod::new(
        camera.view_proj(aspect, &doc.bounds()),
        [shot.width as f64, shot.height as f64],
        frame.samples(),
    );
    gs.draw(&mut frame, doc, &shot.options, &Highlight::default(), &lod)
        .unwrap();
    frame.capture();
    frame.finish().unwrap();
    bytes
}

fn view(map: SurfaceMap) -> Option<MapView> {
    Some(MapView {
        map,
        scales: vec![MapScale::symmetric(0.5); 2],
    })
}

fn offscreen(renderer: &mut Renderer, shot: &Shot) -> OffscreenTarget {
    renderer
        .create_offscreen(&OffscreenDesc {
            width: shot.width,
            height: shot.height,
            samples: shot.msaa,
        })
        .unwrap()
}

fn surface_move(point: [usize; 2], delta: DVec3) -> Edit {
    Edit {
        object: 0,
        edit: SurfaceEdit::Point(PointEdit::Move { point, delta }).into_object(),
    }
}

#[test]
fn dragging_with_a_map_ends_identical_to_a_fresh_upload() {
    let (mut renderer, sink) = common::renderer();
    let mut ed = common::editor(
        &load("examples/bspline_surface.json"),
        Some(SurfaceMap::Gaussian),
    );
    let [nu, nv] = match ed.doc().objects[0].sampled.model() {
        prespline::model::ModelRef::Surface(s) => s.surface().count(),
        _ => unreachable!("the example is a surface"),
    };
    let s = shot(ed.doc(), SurfaceMap::Mean);
    let mut target = offscreen(&mut renderer, &s);
    let mut gs = GpuScene::new(&mut renderer, ed.doc()).unwrap();
    gs.set_map(view(SurfaceMap::Gaussian));
    let mut rng = common::Rng::new(11);
    for f in 0..40 {
        if f == 20 {
            // A map change mid-way: the scalars are rebuilt, later drags keep them.
            gs.set_map(view(SurfaceMap::Mean));
        }
        for _ in 0..1 + rng.range(0, 3) {
            let p = [rng.range(0, nu), rng.range(0, nv)];
            let d = DVec3::new(0.0, 0.0, 0.6 * f64::from(rng.f32(-1.0, 1.0)));
            let e = surface_move(p, d);
            common::edit(&mut ed, &mut gs, e);
        }
        frame(&mut renderer, &mut target, &mut gs, ed.doc(), &s);
    }
    let incremental = renderer.read_pixels(&target).unwrap();
    gs.destroy(&mut renderer);

    let doc = ed.into_document();
    let mut fresh_gs = GpuScene::new(&mut renderer, &doc).unwrap();
    fresh_gs.set_map(view(SurfaceMap::Mean));
    frame(&mut renderer, &mut target, &mut fresh_gs, &doc, &s);
    let fresh = renderer.read_pixels(&target).unwrap();
    fresh_gs.destroy(&mut renderer);

    renderer.destroy_offscreen(target).unwrap();
    common::teardown(renderer, sink);
    let differing = incremental
        .rgba
        .chunks(4)
        .zip(fresh.rgba.chunks(4))
        .filter(|(a, b)| a != b)
        .count();
    assert_eq!(
        differing, 0,
        "{differing} pixels differ between the dragged map and a fresh one"
    );
}

/// One interior drag with the map on copies the touched sample rows of the vertices and of the
/// map, nothing more: 24 + 4 bytes per touched sample row entry, against 24 with the map off.
#[test]
fn a_drag_copies_only_its_rows_of_the_map() {
    let (mut renderer, sink) = common::renderer();
    let mut bytes = Vec::new();
    for map in [None, Some(SurfaceMap::Gaussian)] {
        let mut ed = common::editor(&load("examples/bspline_surface.json"), map);
        let s = shot(ed.doc(), SurfaceMap::Gaussian);
        let mut target = offscreen(&mut renderer, &s);
        let mut gs = GpuScene::new(&mut renderer, ed.doc()).unwrap();
        gs.set_map(map.and_then(view));
        // The first frame builds the scalars; then both slots are up to date.
        frame(&mut renderer, &mut target, &mut gs, ed.doc(), &s);
        frame(&mut renderer, &mut target, &mut gs, ed.doc(), &s);
        let e = surface_move([1, 1], DVec3::new(0.0, 0.0, 0.4));
        let applied = common::edit(&mut ed, &mut gs, e);
        let region = applied.changes[0].samples[0].clone();
        let doc = ed.doc();
        let copied = frame(&mut renderer, &mut target, &mut gs, doc, &s);
        let cols = doc.objects[0].sampled.grid().dims[1];
        let rows = region.rows.len();
        assert!(rows > 0 && rows < doc.objects[0].sampled.grid().dims[0]);
        // Only the rows: the nets are not drawn, so the control display has no mirror.
        let per_vertex = if map.is_some() { 28 } else { 24 };
        assert_eq!(copied, rows * cols * per_vertex, "map {map:?}");
        bytes.push(copied);
        gs.destroy(&mut renderer);
        renderer.destroy_offscreen(target).unwrap();
    }
    common::teardown(renderer, sink);
    assert!(bytes[1] > bytes[0]);
}

/// Whether every pixel of `rect` is the readout's panel, its magenta text or a blend of the
/// two (within 2 per channel): no badge or other overlay shows on the readout.
fn only_readout(px: &Pixels, rect: [u32; 4]) -> Result<(), String> {
    let blends: Vec<[u8; 3]> = (0..=255u8)
        .map(|a| common::text_over(PANEL, READOUT, a))
        .collect();
    for y in rect[1]..rect[3] {
        for x in rect[0]..rect[2] {
            let p = px.get(x, y);
            let near = blends
                .iter()
                .any(|b| (0..3).all(|k| b[k].abs_diff(p[k]) <= 2));
            if !near {
                return Err(format!("pixel ({x}, {y}) is {p:?}: not the readout"));
            }
        }
    }
    Ok(())
}

/// The readout's text colour (sRGB).
const READOUT: [u8; 4] = [240, 150, 240, 255];

/// `prespline render examples/catmull_rom.json --badges --osculating centripetal@T`, T the
/// first parameter (in steps of 0.05) whose readout lies over a badge: the readout is drawn
/// above it on its opaque panel (it used to read "cur C2 ture").
#[test]
fn the_osculating_readout_is_not_overlapped_by_badges() {
    let scene = load("examples/catmull_rom.json");
    let i = scene
        .objects
        .iter()
        .position(|o| o.name == "centripetal")
        .unwrap();
    let (mut renderer, sink) = common::renderer();
    let doc = Document::new(&scene);
    let shot = Shot {
        width: 1280,
        height: 720,
        camera: None,
        options: ViewOptions::default(),
        msaa: 0,
    };
    let font = renderer.font();
    let (w, h) = (shot.width as f64, shot.height as f64);
    let camera = shot_camera(&doc, &shot);
    let badges = badge_overlay(&doc, font, |p| {
        camera
            .project(p, w, h, &doc.bounds())
            .map(|(x, y, _)| (x, y))
    });
    // Where the readout at t goes, as the renderer places it.
    let readout_rect = |t: f64| {
        let curve = CurveEval::of(doc.objects[i].sampled.model()).unwrap();
        let o = Osculating::at(&curve, t)?;
        let (x, y, _) = camera.project(o.point, w, h, &doc.bounds())?;
        let [tw, th] = font.text_size(&osculating_text("centripetal", &o), TextSize::Normal);
        let [px0, py0] = osculating_panel_origin([tw, th], (x, y), [w as f32, h as f32]);
        Some([
            px0 as u32,
            py0 as u32,
            (px0 + tw + 10.0) as u32,
            (py0 + th + 8.0) as u32,
        ])
    };
    // A badge under the readout (a join of a curve inside its panel).
    let covered = |rect: [u32; 4]| {
        badges.chunks_exact(6).any(|q| {
            let (a, b) = (q[0].pos, q[2].pos);
            a[0] < rect[2] as f32
                && b[0] > rect[0] as f32
                && a[1] < rect[3] as f32
                && b[1] > rect[1] as f32
        })
    };
    let (t, rect) = (1..120)
        .map(|k| k as f64 * 0.05)
        .find_map(|t| readout_rect(t).filter(|&r| covered(r)).map(|r| (t, r)))
        .expect("no badge under any readout: the test shows nothing");
    let options = ViewOptions {
        badges: true,
        osculating_at: Some((i, t)),
        ..ViewOptions::default()
    };
    let px = render_document(&mut renderer, &doc, &Shot { options, ..shot }).unwrap();
    let magenta = (rect[1]..rect[3])
        .flat_map(|y| (rect[0]..rect[2]).map(move |x| (x, y)))
        .filter(|&(x, y)| px.get(x, y)[..3] == READOUT[..3])
        .count();
    assert!(
        magenta > 200,
        "the readout is not there ({magenta} text pixels)"
    );
    only_readout(&px, rect).unwrap_or_else(|e| {
        px.write_png(&std::env::temp_dir().join("readout-actual.png"))
            .unwrap();
        panic!("{e}")
    });
    // Negative control: a badge-coloured square on the panel is found.
    let mut bad = px.clone();
    for y in rect[1] + 2..rect[1] + 6 {
        for x in rect[0] + 2..rect[0] + 6 {
            let at = ((y * bad.width + x) * 4) as usize;
            bad.rgba[at..at + 3].copy_from_slice(&[235, 190, 60]);
        }
    }
    assert!(only_readout(&bad, rect).is_err());
    common::teardown(renderer, sink);
}

/// A B-spline curve whose interior knot has multiplicity degree + 1 is two pieces (C⁻¹, the
/// "gap" badge): no line may bridge them. Degree 1 over (−3,0) (−1,0) | (1,2) (3,2), seen from
/// straight above: the pieces are drawn, the diagonal between (−1,0) and (1,2) stays empty.
/// Each piece reaches its end at the gap (the one-sided limits (−1,0) and (1,2)) even where no
/// sample does: with 5 samples the last one left of the knot is at x = −2, and with 4 neither
/// piece has a sample at the knot. The negative control is the same points with a simple
/// interior knot, one polyline through all four, whose diagonal the same probes must see.
#[test]
fn curves_with_a_gap_are_drawn_apart() {
    use prespline::render::analysis::curve_pieces;
    use prespline::render::camera::OrbitCamera;
    let scene = |knots: &str, samples: usize| {
        prespline::formats::parse_scene(&format!(
            r#"{{"objects": [{{"name": "c", "type": "bspline_curve", "degree": 1, "knots": {knots},
            "points": [[-3, 0, 0], [-1, 0, 0], [1, 2, 0], [3, 2, 0]], "samples": {samples}, "color": [1, 1, 1]}}]}}"#
        ))
        .unwrap()
    };
    let camera = OrbitCamera::parse("0,1,20,0,1,0").unwrap();
    let ink = |scene: &Scene| {
        let doc = common::editor(scene, None).into_document();
        let sampled = &doc.objects[0].sampled;
        let pieces: Vec<_> = curve_pieces(sampled.model(), sampled.params()[0])
            .into_iter()
            .map(|p| p.samples)
            .collect();
        let (w, h) = (400u32, 400u32);
        let (mut renderer, sink) = common::renderer();
        let shot = Shot {
            width: w,
            height: h,
            camera: Some(camera),
            options: ViewOptions::default(),
            msaa: 1,
        };
        let px = render_document(&mut renderer, &doc, &shot).unwrap();
        common::teardown(renderer, sink);
        let background = px.get(0, 0);
        // Pixels in a 9×9 window around the projection of `p` that differ from the background.
        let lit = |p: DVec3| {
            let (x, y, _) = camera
                .project(p, w as f64, h as f64, &doc.bounds())
                .unwrap();
            let (x, y) = (x.round() as i64, y.round() as i64);
            let mut n = 0;
            for yy in y - 4..=y + 4 {
                for xx in x - 4..=x + 4 {
                    let c = px.get(xx as u32, yy as u32);
                    n += usize::from((0..3).any(|k| c[k].abs_diff(background[k]) > 40));
                }
            }
            n
        };
        let pieces_lit = [DVec3::new(-2.0, 0.0, 0.0), DVec3::new(2.0, 2.0, 0.0)].map(lit);
        let ends_lit = [DVec3::new(-1.2, 0.0, 0.0), DVec3::new(1.2, 2.0, 0.0)].map(lit);
        let bridge_lit = [0.3, 0.5, 0.7].map(|s| lit(DVec3::new(-1.0 + 2.0 * s, 2.0 * s, 0.0)));
        (pieces, pieces_lit, ends_lit, bridge_lit)
    };
    for (samples, want) in [(41, [0..20, 20..41]), (5, [0..2, 2..5]), (4, [0..2, 2..4])] {
        let (pieces, pieces_lit, ends_lit, bridge_lit) = ink(&scene("[0, 0, 1, 1, 2, 2]", samples));
        assert_eq!(
            pieces, want,
            "{samples} samples: a sample at the gap starts the right piece"
        );
        assert!(
            pieces_lit.iter().all(|&n| n > 0),
            "{samples} samples: both pieces drawn: {pieces_lit:?}"
        );
        assert!(
            ends_lit.iter().all(|&n| n > 0),
            "{samples} samples: each piece reaches the gap: {ends_lit:?}"
        );
        assert_eq!(
            bridge_lit,
            [0, 0, 0],
            "{samples} samples: nothing bridges the gap"
        );
    }
    let (pieces, pieces_lit, ends_lit, bridge_lit) = ink(&scene("[0, 0, 1, 2, 3, 3]", 41));
    assert_eq!((pieces.len(), pieces.first()), (1, Some(&(0..41))));
    assert!(
        pieces_lit.iter().chain(&ends_lit).all(|&n| n > 0),
        "{pieces_lit:?} {ends_lit:?}"
    );
    assert!(
        bridge_lit.iter().all(|&n| n > 0),
        "negative control: the probes see a drawn diagonal: {bridge_lit:?}"
    );
}

/// The bumpy B-spline surface (moved to the left) next to the 32 teapot patches, Gaussian map.
pub(crate) fn bumps_beside_the_teapot() -> Scene {
    prespline::formats::parse_scene(&bumps_beside_the_teapot_json()).unwrap()
}

/// [`bumps_beside_the_teapot`] as a scene file's text.
pub(crate) fn bumps_beside_the_teapot_json() -> String {
    let read = |p: &str| -> serde_json::Value {
        let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(p));
        serde_json::from_str(&text.unwrap()).unwrap()
    };
    let mut scene = read("examples/teapot.json");
    let mut bumps = read("examples/bspline_surface.json")["objects"][0].clone();
    for row in bumps["points"].as_array_mut().unwrap() {
        for p in row.as_array_mut().unwrap() {
            p[0] = serde_json::json!(p[0].as_f64().unwrap() - 9.0);
        }
    }
    scene["objects"].as_array_mut().unwrap().push(bumps);
    scene.to_string()
}

/// The fraction of object `i`'s samples whose pixel is clearly coloured (not white or grey),
/// leaving out those under the legends (bottom right, at most two stacked).
fn coloured_fraction(doc: &Document, shot: &Shot, px: &Pixels, i: usize) -> f64 {
    coloured_fraction_beside(doc, shot, px, i, 2)
}

/// [`coloured_fraction`] beside `slots` stacked legends.
pub(crate) fn coloured_fraction_beside(
    doc: &Document,
    shot: &Shot,
    px: &Pixels,
    i: usize,
    slots: usize,
) -> f64 {
    let camera = shot_camera(doc, shot);
    let (w, h) = (shot.width as f64, shot.height as f64);
    let grid = doc.objects[i].sampled.grid();
    let stride = grid.stride();
    let (mut seen, mut coloured) = (0usize, 0usize);
    for k in 0..grid.dims[0] * grid.dims[1] {
        let Some((x, y, _)) = camera.project(grid.data[k * stride], w, h, &doc.bounds()) else {
            continue;
        };
        let legends = x >= w - 340.0 && y >= h - 64.0 - slots as f64 * 96.0;
        if x < 0.0 || y < 0.0 || x >= w || y >= h || legends {
            continue;
        }
        let c = px.get(x as u32, y as u32);
        let (hi, lo) = (c[..3].iter().max().unwrap(), c[..3].iter().min().unwrap());
        seen += 1;
        coloured += usize::from(hi - lo > 40);
    }
    assert!(seen > 100, "object {i} is in the picture");
    coloured as f64 / seen as f64
}

/// In a mixed scene each surface gets its own colour scale by default: the gently curved bumps
/// (|K| ≲ 0.7) beside the teapot (|K| up to ~60) still show red and blue. The negative control
/// is the shared scale, which the teapot sets, so the bumps go almost white.
#[test]
fn per_object_ranges_colour_every_surface_in_a_mixed_scene() {
    use prespline::render::maps::{MapRange, map_scales};
    let scene = bumps_beside_the_teapot();
    let doc = common::editor(&scene, Some(SurfaceMap::Gaussian)).into_document();
    let bumps = doc.objects.len() - 1;
    let render = |range: MapRange| {
        let shot = Shot {
            width: 960,
            height: 540,
            camera: None,
            options: ViewOptions {
                analysis: Some(SurfaceMap::Gaussian),
                map_range: range,
                ..ViewOptions::default()
            },
            msaa: 1,
        };
        let (mut renderer, sink) = common::renderer();
        let px = render_document(&mut renderer, &doc, &shot).unwrap();
        common::teardown(renderer, sink);
        let fractions = [0, bumps].map(|i| coloured_fraction(&doc, &shot, &px, i));
        (fractions, px)
    };
    // The scales themselves: the bumps' own range is the one it gets alone, the teapot's
    // patches (teapot_00 … teapot_31) share one.
    let own = map_scales(&doc, SurfaceMap::Gaussian, MapRange::PerObject);
    let alone = common::editor(
        &load("examples/bspline_surface.json"),
        Some(SurfaceMap::Gaussian),
    )
    .into_document();
    let alone = map_scales(&alone, SurfaceMap::Gaussian, MapRange::PerObject)[0];
    // Equal up to the rounding of the curvature after the move by −9 in x.
    assert!((own[bumps].high - alone.high).abs() <= 1e-12 * alone.high);
    assert_eq!(own[bumps].low, -own[bumps].high);
    assert!(
        own[..bumps].iter().all(|s| *s == own[0]),
        "one scale for the teapot"
    );
    let shared = map_scales(&doc, SurfaceMap::Gaussian, MapRange::Shared);
    assert!(
        shared[bumps].high > 20.0 * own[bumps].high,
        "{shared:?} vs {own:?}"
    );

    let ([teapot, bumpy], px) = render(MapRange::PerObject);
    if std::env::var_os("PRESPLINE_KEEP").is_some() {
        px.write_png(Path::new("/tmp/mixed-per-object.png"))
            .unwrap();
    }
    assert!(teapot > 0.05, "teapot coloured: {teapot}");
    assert!(bumpy > 0.3, "per-object: the bumps show colour: {bumpy}");
    let ([teapot, bumpy], px) = render(MapRange::Shared);
    if std::env::var_os("PRESPLINE_KEEP").is_some() {
        px.write_png(Path::new("/tmp/mixed-shared.png")).unwrap();
    }
    assert!(teapot > 0.05, "teapot coloured: {teapot}");
    assert!(
        bumpy < 0.05,
        "negative control, shared scale: the bumps wash out: {bumpy}"
    );
}

/// Six copies of the bumpy B-spline surface named as Blender names separate objects
/// (`Surface.001` … `Surface.006`), two rows of three a clear gap apart, their heights scaled
/// by 1/8, 1/4, … 4 (so their curvatures differ by orders of magnitude).
fn six_separate_surfaces() -> Scene {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/bspline_surface.json"),
    );
    let bumps: serde_json::Value = serde_json::from_str(&text.unwrap()).unwrap();
    let bumps = &bumps["objects"][0];
    let objects: Vec<serde_json::Value> = (0..6)
        .map(|k| {
            let mut o = bumps.clone();
            o["name"] = serde_json::json!(format!("Surface.{:03}", k + 1));
            let (dx, dy) = (8.0 * (k % 3) as f64 - 8.0, 8.0 * (k / 3) as f64 - 4.0);
            let height = 2f64.powi(k - 3);
            for row in o["points"].as_array_mut().unwrap() {
                for p in row.as_array_mut().unwrap() {
                    let [x, y, z] = [0, 1, 2].map(|c| p[c].as_f64().unwrap());
                    *p = serde_json::json!([x + dx, y + dy, z * height]);
                }
            }
            o
        })
        .collect();
    let scene = serde_json::json!({ "objects": objects });
    prespline::formats::parse_scene(&scene.to_string()).unwrap()
}

/// Separate surfaces whose names differ only in a trailing number (Blender's `Surface.001` …)
/// are not one model: each gets its own colour scale and shows colour, the flattest too. The
/// negative control is the shared scale, under which the flattest goes white.
#[test]
fn separate_surfaces_with_numbered_names_get_their_own_ranges() {
    use prespline::render::maps::{MapRange, map_scales, surface_families};
    let doc = common::editor(&six_separate_surfaces(), Some(SurfaceMap::Gaussian)).into_document();
    let families = surface_families(&doc);
    let names: Vec<&str> = families.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(
        names,
        [
            "Surface.001",
            "Surface.002",
            "Surface.003",
            "Surface.004",
            "Surface.005",
            "Surface.006"
        ]
    );
    let own = map_scales(&doc, SurfaceMap::Gaussian, MapRange::PerObject);
    assert!(
        own.windows(2).all(|w| w[1].high > 1.5 * w[0].high),
        "each its own range, growing with the height: {own:?}"
    );
    // From straight above, the scene left of the legends' column.
    let camera = prespline::render::camera::OrbitCamera::parse("5,0,40,5,0,0").unwrap();
    let render = |range: MapRange| {
        let shot = Shot {
            width: 1200,
            height: 900,
            camera: Some(camera),
            options: ViewOptions {
                analysis: Some(SurfaceMap::Gaussian),
                map_range: range,
                ..ViewOptions::default()
            },
            msaa: 1,
        };
        let (mut renderer, sink) = common::renderer();
        let px = render_document(&mut renderer, &doc, &shot).unwrap();
        common::teardown(renderer, sink);
        if std::env::var_os("PRESPLINE_KEEP").is_some() {
            px.write_png(&std::env::temp_dir().join(format!("six-{range:?}.png")))
                .unwrap();
        }
        let slots = if range == MapRange::PerObject { 6 } else { 1 };
        (0..6)
            .map(|i| coloured_fraction_beside(&doc, &shot, &px, i, slots))
            .collect::<Vec<_>>()
    };
    let coloured = render(MapRange::PerObject);
    assert!(
        coloured.iter().all(|&f| f > 0.15),
        "every surface shows colour: {coloured:?}"
    );
    let shared = render(MapRange::Shared);
    assert!(
        shared[0] < 0.05,
        "negative control, shared scale: the flattest washes out: {shared:?}"
    );
}

/// Where the legends of a still image do not all fit, a note above them says how many
/// families and surfaces have none: 6 separate surfaces at 800 × 400 show 3 legends and
/// "+3 more: 3 surfaces without a legend". The negative control reads the same place with
/// the shared scale (one legend, no note).
#[test]
fn legends_that_do_not_fit_are_counted_in_a_note() {
    use prespline::gpu::font::Font;
    use prespline::render::maps::{
        LEGEND_TEXT, LegendPlace, MapRange, legend_layout, legend_note_height, legend_note_layout,
        legend_note_text, map_scales,
    };
    use prespline::render::offscreen::legends_shown;
    let doc = common::editor(&six_separate_surfaces(), Some(SurfaceMap::Gaussian)).into_document();
    let font = Font::new(1.0);
    let (w, h) = (800u32, 400u32);
    let shown = legends_shown(6, h as f32, legend_note_height(&font));
    assert_eq!(shown, 3);
    let note = legend_note_text(3, 3);
    assert_eq!(note, "+3 more: 3 surfaces without a legend");
    let place = |name, slot| LegendPlace {
        name,
        slot,
        width: w as f32,
        height: h as f32,
    };
    let (_, at) = legend_note_layout(&note, &font, place(None, shown));
    let read = |range: MapRange| {
        let shot = Shot {
            width: w,
            height: h,
            camera: None,
            options: ViewOptions {
                analysis: Some(SurfaceMap::Gaussian),
                map_range: range,
                ..ViewOptions::default()
            },
            msaa: 1,
        };
        let (mut renderer, sink) = common::renderer();
        let px = render_document(&mut renderer, &doc, &shot).unwrap();
        common::teardown(renderer, sink);
        let text = |(s, at): (&str, [f32; 2])| {
            let at = [at[0].round() as u32, at[1].round() as u32];
            common::read_text(
                &px,
                &font,
                TextSize::Normal,
                at,
                s.chars().count(),
                PANEL,
                LEGEND_TEXT,
            )
        };
        // The legends shown are the first three families', the first on top.
        let scales = map_scales(&doc, SurfaceMap::Gaussian, MapRange::PerObject);
        let titles: Vec<[String; 2]> = (0..3)
            .map(|k| {
                let name = format!("Surface.{:03}", k + 1);
                let slot = 2 - k;
                let place = LegendPlace {
                    name: Some(&name),
                    slot,
                    width: w as f32,
                    height: h as f32,
                };
                let layout = legend_layout(SurfaceMap::Gaussian, scales[k], &font, place);
                let (title, at) = layout.title;
                [text((&title, at)), title]
            })
            .collect();
        (text((&note, at)), titles)
    };
    let (seen, titles) = read(MapRange::PerObject);
    assert_eq!(seen, note, "the note names what has no legend");
    for [seen, want] in titles {
        assert_eq!(
            seen, want,
            "the first three families' legends, top to bottom"
        );
    }
    let (seen, _) = read(MapRange::Shared);
    assert_ne!(seen, note, "negative control: one shared legend, no note");
}
