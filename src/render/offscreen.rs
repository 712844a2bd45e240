//! Headless rendering of a document into pixels (`prespline render`, golden-image tests).

use super::analysis::{CurveEval, Osculating, badge_overlay, osculating_lines, osculating_overlay};
use super::camera::OrbitCamera;
use super::gpu_scene::GpuScene;
use super::lod::Lod;
use super::map_mirror::MapView;
use super::maps::{
    LEGEND_STEP, LegendPlace, MapRange, MapScale, legend, legend_note, legend_note_height,
    legend_note_text, map_scales, surface_families,
};
use super::overlays::overlay_lines;
use super::style::Highlight;
use super::style::{Palette, ViewOptions};
use crate::editor::Document;
use crate::gpu::{GpuResult, OffscreenDesc, Pixels, Renderer};
use glam::DVec3;

/// One offscreen image.
#[derive(Debug, Clone)]
pub struct Shot {
    pub width: u32,
    pub height: u32,
    /// `None` frames the whole document from the default direction.
    pub camera: Option<OrbitCamera>,
    pub options: ViewOptions,
    /// MSAA samples (0 = the renderer's default).
    pub msaa: u32,
}

/// The camera a shot uses: the given one, or the default direction framing the document.
#[must_use]
pub fn shot_camera(doc: &Document, shot: &Shot) -> OrbitCamera {
    shot.camera.unwrap_or_else(|| {
        let bounds = doc.bounds();
        let mut c = OrbitCamera::default_for(&bounds);
        let nets = shot.options.control_nets != super::style::NetMode::Off;
        c.frame_points(
            &framing_points(doc, |_| nets),
            &bounds,
            shot.width as f64 / shot.height as f64,
        );
        c
    })
}

/// What the default framing fits: the drawn samples (a trimmed surface's inside ones), and the control points of the objects
/// whose nets are drawn (`nets(i)`; hidden ones, such as ERBS local patches' points above a
/// surface, would leave an empty band), every k-th of them so that at most about 8192 are
/// projected per fitting step.
#[must_use]
pub fn framing_points(doc: &Document, nets: impl Fn(usize) -> bool) -> Vec<DVec3> {
    const MAX: usize = 8192;
    let count = |i: usize| {
        let g = doc.objects[i].sampled.grid();
        g.dims[0] * g.dims[1]
    };
    let samples: usize = (0..doc.objects.len()).map(count).sum();
    let handles: Vec<DVec3> = (0..doc.objects.len())
        .filter(|&i| nets(i))
        .flat_map(|i| doc.objects[i].controls.grip_points())
        .collect();
    let every = (samples + handles.len()).div_ceil(MAX).max(1);
    let mut points: Vec<DVec3> = handles.into_iter().step_by(every).collect();
    // The trimmed surfaces' boundary points share the same allowance (a CAD model has
    // hundreds of faces, each with thousands of boundary vertices).
    let trimmed = doc.objects.iter().filter(|o| o.trim.is_some()).count();
    let boundary = (MAX / trimmed.max(1)).max(16);
    for o in &doc.objects {
        points.extend(o.drawn_points(every, boundary));
    }
    points
}

/// Renders `doc` into an image and reads it back.
pub fn render_document(renderer: &mut Renderer, doc: &Document, shot: &Shot) -> GpuResult<Pixels> {
    let mut target = renderer.create_offscreen(&OffscreenDesc {
        width: shot.width,
        height: shot.height,
        samples: shot.msaa,
    })?;
    let mut scene = match GpuScene::new(renderer, doc) {
        Ok(s) => s,
        Err(e) => {
            renderer.destroy_offscreen(target)?;
            return Err(e);
        }
    };
    let result = record(renderer, &mut target, &mut scene, doc, shot)
        .and_then(|()| renderer.read_pixels(&target));
    scene.destroy(renderer);
    renderer.destroy_offscreen(target)?;
    result
}

fn record(
    renderer: &mut Renderer,
    target: &mut crate::gpu::OffscreenTarget,
    scene: &mut GpuScene,
    doc: &Document,
    shot: &Shot,
) -> GpuResult<()> {
    let bounds = doc.bounds();
    let camera = shot_camera(doc, shot);
    let aspect = shot.width as f64 / shot.height as f64;
    let mut frame = renderer.begin_offscreen(target)?;
    let map = shot.options.analysis.map(|map| MapView {
        map,
        scales: map_scales(doc, map, shot.options.map_range),
    });
    scene.set_map(map.clone());
    scene.upload(&mut frame, doc)?;
    frame.set_clear_color(Palette::default().background);
    frame.set_camera(camera.gpu(aspect, &bounds));
    let viewport = [shot.width as f64, shot.height as f64];
    let lod = Lod::new(camera.view_proj(aspect, &bounds), viewport, frame.samples());
    scene.draw(&mut frame, doc, &shot.options, &Highlight::default(), &lod)?;
    let mut lines = overlay_lines(doc, &shot.options, bounds.radius());
    let (w, h) = (shot.width as f64, shot.height as f64);
    let project = |p| camera.project(p, w, h, &bounds).map(|(x, y, _)| (x, y));
    let font = frame.font();
    let size = [w as f32, h as f32];
    // Back to front: badges, legend, then the osculating readout, which no badge covers.
    let mut overlay = Vec::new();
    let mut readout = Vec::new();
    if let Some((i, t)) = shot.options.osculating_at
        && let Some(o) = doc.objects.get(i).and_then(|o| {
            let curve = CurveEval::of(o.sampled.model())?;
            Osculating::at(&curve, t)
        })
    {
        lines.extend(osculating_lines(&o));
        if let Some(at) = project(o.point) {
            readout = osculating_overlay(&doc.objects[i].name, &o, font, at, size);
        }
    }
    if !lines.is_empty() {
        frame.draw_lines3d(&lines)?;
    }
    if shot.options.badges {
        overlay.extend(badge_overlay(doc, font, project));
    }
    if let Some(m) = &map {
        overlay.extend(legends(doc, m, shot.options.map_range, font, size));
    }
    overlay.extend(readout);
    if !overlay.is_empty() {
        frame.draw_overlay(&overlay)?;
    }
    frame.capture();
    frame.finish()?;
    Ok(())
}

/// The legends of a still image: one per surface family ([`surface_families`]), named, when
/// each has its own scale (as many as fit, top to bottom in scene order, and above them a note
/// of how many families and surfaces had no room); one for all of them otherwise.
fn legends(
    doc: &Document,
    view: &MapView,
    range: MapRange,
    font: &crate::gpu::font::Font,
    [width, height]: [f32; 2],
) -> Vec<crate::gpu::OverlayVertex> {
    let families = surface_families(doc);
    let place = |name, slot| LegendPlace {
        name,
        slot,
        width,
        height,
    };
    let own = range == MapRange::PerObject && view.map.needs_curvature() && families.len() > 1;
    if !own {
        let first = families.first().map_or(0, |(_, m)| m[0]);
        let scale = view.scales.get(first).copied();
        let scale = scale.unwrap_or(MapScale::symmetric(1.0));
        return legend(view.map, scale, font, place(None, 0));
    }
    let groups = legend_groups(doc, &families, &view.scales);
    let shown = legends_shown(groups.len(), height, legend_note_height(font));
    let mut v: Vec<_> = groups[..shown]
        .iter()
        .enumerate()
        .flat_map(|(k, (name, scale, _))| {
            legend(view.map, *scale, font, place(Some(name), shown - 1 - k))
        })
        .collect();
    if shown < groups.len() {
        let hidden = &groups[shown..];
        let surfaces = hidden.iter().map(|(_, _, n)| n).sum();
        let note = legend_note_text(hidden.len(), surfaces);
        v.extend(legend_note(&note, font, place(None, shown)));
    }
    v
}

/// The families' legends with one scale merged into one, in scene order: a legend per range
/// shown, named by its one family, or by the first and last surface of its families with
/// their count (`t0_teapot_00 … t63_teapot_31 (2,048 surfaces)`). Ranges within a millionth
/// of each other are the same range: the legend shows four digits, and copies of one model
/// placed apart differ in the last bits of their curvature.
#[must_use]
pub fn legend_groups(
    doc: &Document,
    families: &[(String, Vec<usize>)],
    scales: &[MapScale],
) -> Vec<(String, MapScale, usize)> {
    let same = |a: MapScale, b: MapScale| {
        let close = |x: f64, y: f64| (x - y).abs() <= 1e-6 * x.abs().max(y.abs());
        close(a.low, b.low) && close(a.high, b.high)
    };
    // (scale, family indices) in the order each range first appears.
    let mut groups: Vec<(MapScale, Vec<usize>)> = Vec::new();
    for (k, (_, members)) in families.iter().enumerate() {
        let scale = scales[members[0]];
        match groups.iter_mut().find(|(s, _)| same(*s, scale)) {
            Some((_, ks)) => ks.push(k),
            None => groups.push((scale, vec![k])),
        }
    }
    groups
        .into_iter()
        .map(|(scale, ks)| {
            let surfaces: usize = ks.iter().map(|&k| families[k].1.len()).sum();
            let name = match ks.as_slice() {
                [one] => families[*one].0.clone(),
                [first, .., last] => {
                    let a = &doc.objects[families[*first].1[0]].name;
                    let b = &doc.objects[*families[*last].1.last().unwrap_or(&0)].name;
                    format!("{a} … {b} ({} surfaces)", thousands(surfaces))
                }
                [] => String::new(),
            };
            (name, scale, surfaces)
        })
        .collect()
}

/// `2048` as `2,048`.
fn thousands(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (k, c) in digits.chars().enumerate() {
        if k > 0 && (digits.len() - k).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// How many of `families` legends a still image `height` pixels high shows: all that fit
/// (at least one); when some do not, as many as leave room for the note (`note` pixels high)
/// saying so above them.
#[must_use]
pub fn legends_shown(families: usize, height: f32, note: f32) -> usize {
    let room = height - 64.0;
    let fit = ((room / LEGEND_STEP).floor().max(1.0) as usize).min(families);
    if fit == families {
        return fit;
    }
    ((room - note) / LEGEND_STEP).floor().max(0.0) as usize
}
