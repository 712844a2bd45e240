//! The viewer's overlay text without a window (lavapipe, validation required), read back from
//! the rendered image: the help is opaque over a bright surface and drawn above the analysis
//! legend at 800×600; a long status message shows on two lines keeping its end (read back
//! glyph by glyph); the text reader itself tells different text apart.

mod common;

use prespline::formats::parse_scene;
use prespline::gpu::font::{Font, TextSize};
use prespline::gpu::{OffscreenDesc, OverlayVertex, Pixels, Renderer, ValidationSink};
use prespline::render::analysis::PANEL;
use prespline::render::maps::{LegendPlace, MapScale, SurfaceMap, legend};
use prespline::view::Session;
use prespline::view::hud::{
    HELP_PANEL, STATUS_MARGIN, TEXT, help_overlay, status_lines, status_top,
};

const W: u32 = 800;
const H: u32 = 600;

/// A large flat Bézier surface filling most of the view: bright, shaded, right behind the
/// help.
const WALL: &str = r#"{"objects": [
  {"name": "wall", "type": "bezier_surface",
   "points": [[[-4, -3, 0], [-4, 3, 0]], [[4, -3, 0], [4, 3, 0]]], "samples": [8, 8]}
]}"#;

struct Viewer {
    session: Session,
    renderer: Renderer,
    sink: ValidationSink,
    _dir: common::Scratch,
}

impl Viewer {
    fn new() -> Self {
        let (mut renderer, sink) = common::renderer();
        let dir = common::Scratch::new("view-text");
        let scene = parse_scene(WALL).unwrap();
        let session = Session::open(
            &mut renderer,
            &scene,
            dir.join("wall.json"),
            [W, H],
            prespline::sampling::budget::MemoryBudget::machine_default(),
        )
        .unwrap();
        Viewer {
            session,
            renderer,
            sink,
            _dir: dir,
        }
    }

    /// What the window would show, HUD included, rendered offscreen.
    fn shot(&mut self) -> Pixels {
        let r = &mut self.renderer;
        let mut target = r
            .create_offscreen(&OffscreenDesc {
                width: W,
                height: H,
                samples: 0,
            })
            .unwrap();
        let mut frame = r.begin_offscreen(&mut target).unwrap();
        self.session.upload(&mut frame).unwrap();
        self.session.record(&mut frame, true).unwrap();
        frame.capture();
        frame.finish().unwrap();
        let px = r.read_pixels(&target).unwrap();
        r.destroy_offscreen(target).unwrap();
        px
    }

    fn finish(self) {
        let Viewer {
            session,
            mut renderer,
            sink,
            ..
        } = self;
        session.destroy(&mut renderer);
        common::teardown(renderer, sink);
    }
}

/// Pixel rectangle `[x0, y0, x1, y1)` of the solid quad starting at vertex `first`.
fn quad_rect(v: &[OverlayVertex], first: usize) -> [u32; 4] {
    let (a, b) = (v[first].pos, v[first + 2].pos);
    [a[0] as u32, a[1] as u32, b[0] as u32, b[1] as u32]
}

/// Whether a glyph quad of `v` covers the centre of pixel (x, y).
fn under_glyph(v: &[OverlayVertex], x: u32, y: u32) -> bool {
    let (cx, cy) = (x as f32 + 0.5, y as f32 + 0.5);
    v.chunks_exact(6).any(|q| {
        q[0].glyph != OverlayVertex::SOLID
            && (q[0].pos[0]..q[2].pos[0]).contains(&cx)
            && (q[0].pos[1]..q[2].pos[1]).contains(&cy)
    })
}

/// Pixels of `rect` that no glyph quad of `help` covers and that differ from the help panel.
fn not_panel(px: &Pixels, help: &[OverlayVertex], rect: [u32; 4]) -> (usize, usize) {
    let (mut checked, mut off) = (0, 0);
    for y in rect[1]..rect[3] {
        for x in rect[0]..rect[2] {
            if under_glyph(help, x, y) {
                continue;
            }
            checked += 1;
            if px.get(x, y)[..3] != HELP_PANEL[..3] {
                off += 1;
            }
        }
    }
    (checked, off)
}

fn intersect(a: [u32; 4], b: [u32; 4]) -> [u32; 4] {
    [
        a[0].max(b[0]),
        a[1].max(b[1]),
        a[2].min(b[2]),
        a[3].min(b[3]),
    ]
}

fn luma(p: [u8; 4]) -> u32 {
    (u32::from(p[0]) + u32::from(p[1]) + u32::from(p[2])) / 3
}

#[test]
fn the_help_panel_is_opaque_over_a_bright_surface() {
    let mut v = Viewer::new();
    let font = Font::new(1.0);
    let help = help_overlay(&font, W as f32, H as f32);
    let panel = quad_rect(&help, 0);
    let without = v.shot();
    // The surface really is behind the panel, bright.
    let bright = (panel[1]..panel[3])
        .flat_map(|y| (panel[0]..panel[2]).map(move |x| (x, y)))
        .filter(|&(x, y)| luma(without.get(x, y)) > 100)
        .count();
    assert!(
        bright > 20_000,
        "only {bright} bright pixels behind the help"
    );
    v.session.show_help = true;
    let with = v.shot();
    let (checked, off) = not_panel(&with, &help, panel);
    assert!(checked > 100_000, "{checked}");
    assert_eq!(
        off, 0,
        "{off} of {checked} pixels between the help's glyphs show through"
    );
    // Negative control: the same check on the picture without the help finds the surface.
    let (_, off) = not_panel(&without, &help, panel);
    assert!(off > 20_000, "{off}");
    v.finish();
}

#[test]
fn the_help_is_drawn_above_the_legend_at_800x600() {
    let mut v = Viewer::new();
    v.session.set_map(Some(SurfaceMap::Gaussian));
    let font = Font::new(1.0);
    let help = help_overlay(&font, W as f32, H as f32);
    let place = LegendPlace {
        name: None,
        slot: 0,
        width: W as f32,
        height: H as f32,
    };
    let legend = legend(SurfaceMap::Gaussian, MapScale::symmetric(1.0), &font, place);
    let both = intersect(quad_rect(&help, 0), quad_rect(&legend, 0));
    assert!(
        both[0] + 50 < both[2] && both[1] + 20 < both[3],
        "at 800x600 the help covers the legend: {both:?}"
    );
    let without = v.shot();
    let (_, shown) = not_panel(&without, &help, both);
    assert!(
        shown > 1000,
        "the legend is not where it should be ({shown})"
    );
    v.session.show_help = true;
    let with = v.shot();
    let (checked, off) = not_panel(&with, &help, both);
    assert!(checked > 1000, "{checked}");
    assert_eq!(off, 0, "the legend shows through the help at {off} pixels");
    v.finish();
}

/// The message a user got when saving an ERBS surface to OBJ.
const LONG: &str = "save failed: object 'erbs_surface': cannot be written to OBJ: the expo \
    B-function is not a rational function, so no rational B-spline equals this ERBS \
    (B-functions smoothstep, smootherstep and rational export exactly; or keep it in JSON)";

#[test]
fn a_long_status_shows_on_two_lines_keeping_its_end() {
    let mut v = Viewer::new();
    v.session.set_status(LONG);
    let px = v.shot();
    let font = Font::new(1.0);
    let lines = status_lines(&font, W as f32, LONG);
    assert_eq!(lines.len(), 2, "{lines:?}");
    let top = status_top(&font, H as f32, 2) as u32;
    let line = font.metrics(TextSize::Normal).line_height;
    let mut read = Vec::new();
    for (k, expected) in lines.iter().enumerate() {
        let at = [STATUS_MARGIN as u32, top + k as u32 * line];
        let n = expected.chars().count();
        read.push(common::read_text(
            &px,
            &font,
            TextSize::Normal,
            at,
            n,
            PANEL,
            TEXT,
        ));
    }
    assert_eq!(read, lines);
    assert!(
        read[0].starts_with("save failed: object 'erbs_surface'"),
        "{read:?}"
    );
    assert!(
        read[1].starts_with("… ") && read[1].ends_with("or keep it in JSON)"),
        "{read:?}"
    );
    // Negative control: the reader tells the lines apart (it reads what is there).
    let at = [STATUS_MARGIN as u32, top];
    let n = lines[1].chars().count();
    let other = common::read_text(&px, &font, TextSize::Normal, at, n, PANEL, TEXT);
    assert_ne!(other, lines[1]);
    v.finish();
}
