//! Headless rendering of a document into pixels (`prespline render`, golden-image tests).

use super::analysis::{CurveEval, Osculating, badge_overlay, osculating_lines, osculating_overlay};
use super::camera::OrbitCamera;
use super::gpu_scene::{GpuScene, Highlight};
use super::lod::Lod;
use super::map_mirror::MapView;
use super::maps::legend;
use super::overlays::overlay_lines;
use super::style::{Palette, ViewOptions};
use crate::editor::Document;
use crate::gpu::{GpuResult, OffscreenDesc, Pixels, Renderer};

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
pub fn shot_camera(doc: &Document, shot: &Shot) -> OrbitCamera {
    shot.camera.unwrap_or_else(|| {
        let bounds = doc.bounds();
        let mut c = OrbitCamera::default_for(&bounds);
        c.frame(&bounds, shot.width as f64 / shot.height as f64);
        c
    })
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
        range: super::maps::map_range(doc, map),
    });
    scene.set_map(map);
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
    if let Some(m) = map {
        overlay.extend(legend(m.map, m.range, font, size[0], size[1]));
    }
    overlay.extend(readout);
    if !overlay.is_empty() {
        frame.draw_overlay(&overlay)?;
    }
    frame.capture();
    frame.finish()?;
    Ok(())
}
