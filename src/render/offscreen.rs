//! Headless rendering of a document into pixels (`prespline render`, golden-image tests).

use super::camera::OrbitCamera;
use super::document::Document;
use super::gpu_scene::{GpuScene, Highlight};
use super::lod::Lod;
use super::overlays::overlay_lines;
use super::style::{Palette, ViewOptions};
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
    frame.set_clear_color(Palette::default().background);
    frame.set_camera(camera.gpu(aspect, &bounds));
    let viewport = [shot.width as f64, shot.height as f64];
    let lod = Lod::new(camera.view_proj(aspect, &bounds), viewport, frame.samples());
    scene.draw(&mut frame, doc, &shot.options, &Highlight::default(), &lod)?;
    let lines = overlay_lines(doc, &shot.options, bounds.radius());
    if !lines.is_empty() {
        frame.draw_lines3d(&lines)?;
    }
    frame.capture();
    frame.finish()?;
    Ok(())
}
