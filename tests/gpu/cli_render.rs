//! `prespline render` run the way a user runs it (on lavapipe).

use crate::common;

use std::path::Path;
use std::process::Command;

fn prespline() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_prespline"));
    let icd = "/usr/share/vulkan/icd.d/lvp_icd.x86_64.json";
    c.env("VK_DRIVER_FILES", icd)
        .env("VK_ICD_FILENAMES", icd)
        .env("PRESPLINE_VALIDATION", "required");
    c
}

#[test]
fn renders_a_png_with_edits_and_camera() {
    let scratch = common::Scratch::new("cli-render");
    let dir = scratch.path();
    let edits = dir.join("edits.json");
    std::fs::write(
        &edits,
        r#"[{"object": "bumps", "point": [3, 3], "delta": [0, 0, -2]}]"#,
    )
    .unwrap();
    let out = dir.join("bumps.png");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/bspline_surface.json");
    let r = prespline()
        .arg("render")
        .arg(&scene)
        .arg("--out")
        .arg(&out)
        .args([
            "--size",
            "320x200",
            "--camera",
            "-6,-6,5,0,0,0,45",
            "--net",
            "--wire",
            "4",
        ])
        .arg("--edits")
        .arg(&edits)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(r.status.success(), "{err}");
    assert!(err.contains("wrote") && err.contains("320x200"), "{err}");
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&out).unwrap()));
    let reader = decoder.read_info().unwrap();
    assert_eq!((reader.info().width, reader.info().height), (320, 200));
}

#[test]
fn bad_input_is_one_line() {
    let scratch = common::Scratch::new("cli-render");
    let dir = scratch.path();
    let r = prespline()
        .args(["render", "/nonexistent.json", "--out"])
        .arg(dir.join("x.png"))
        .output()
        .unwrap();
    assert!(!r.status.success());
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("cannot read /nonexistent.json"), "{err}");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/teapot.json");
    for (flag, value, msg) in [
        ("--size", "0x10", "within 1..16384"),
        ("--camera", "1,2,3", "EX,EY,EZ,TX,TY,TZ"),
        ("--wire", "0", "0 draws no isolines: give N ≥ 1"),
    ] {
        let r = prespline()
            .arg("render")
            .arg(&scene)
            .arg("--out")
            .arg(dir.join("x.png"))
            .args([flag, value])
            .output()
            .unwrap();
        assert!(!r.status.success());
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(err.contains(msg), "{flag} {value}: {err}");
    }
    // A sample count the device lacks names the ones it has (lavapipe: 1 or 4).
    let r = prespline()
        .arg("render")
        .arg(&scene)
        .arg("--out")
        .arg(dir.join("x.png"))
        .args(["--size", "64x64", "--msaa", "8"])
        .output()
        .unwrap();
    assert!(!r.status.success());
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("8x MSAA is not supported by")
            && err.contains("renders with 1")
            && err.contains(" or 4 samples"),
        "{err}"
    );
    assert!(!dir.join("x.png").exists());
}

/// `PRESPLINE_VALIDATION=required` (what every test run uses) fails with one line when the
/// Khronos layer is missing, instead of rendering unvalidated; `1` renders without it.
#[test]
fn required_validation_fails_without_the_layer() {
    let scratch = common::Scratch::new("cli-render");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/bezier_curve.json");
    let out = scratch.join("x.png");
    let render = |mode: &str| {
        prespline()
            .env("PRESPLINE_VALIDATION", mode)
            // An empty layer search path: the loader finds no layer at all.
            .env("VK_LAYER_PATH", scratch.path())
            .env_remove("VK_ADD_LAYER_PATH")
            .arg("render")
            .arg(&scene)
            .args(["--size", "64x64", "--out"])
            .arg(&out)
            .output()
            .unwrap()
    };
    let r = render("required");
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(!r.status.success(), "rendered unvalidated: {err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("validation layer") && err.contains("vulkan-validationlayers"),
        "{err}"
    );
    assert!(!out.exists());
    let r = render("1");
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
}

/// The display flags draw what the goldens of `render_golden` show: `--normals --wire 1`,
/// `--frenet` and `--no-local` run the way a user runs them, against the same golden images.
#[test]
fn display_flags_draw_what_the_goldens_show() {
    let scratch = common::Scratch::new("cli-render");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for (example, flags, golden) in [
        (
            "bspline_surface.json",
            &["--normals", "--wire", "1"][..],
            "bspline_surface_normals_wire",
        ),
        ("helix.json", &["--frenet"][..], "helix_frenet"),
        (
            "erbs_surface.json",
            &["--no-local"][..],
            "erbs_surface_no_local",
        ),
    ] {
        let out = scratch.join(format!("{golden}.png"));
        let r = prespline()
            .arg("render")
            .arg(root.join("examples").join(example))
            .args(["--size", "640x400", "--msaa", "4"])
            .args(flags)
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        let expected =
            prespline::gpu::Pixels::read_png(&root.join(format!("tests/golden/{golden}.png")))
                .unwrap();
        let actual = prespline::gpu::Pixels::read_png(&out).unwrap();
        common::compare_images(&expected, &actual, common::GOLDEN.channel)
            .unwrap()
            .check(&common::GOLDEN)
            .unwrap_or_else(|e| panic!("{example} {flags:?} against {golden}: {e}"));
    }
}

/// Centroid (x, y) of the pixels of an image where `channel` clearly dominates.
fn centroid(path: &Path, channel: usize) -> Option<(f64, f64)> {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    let (w, bpp) = (info.width as usize, info.color_type.samples());
    let (mut sx, mut sy, mut n) = (0.0, 0.0, 0.0);
    for (k, px) in buf[..info.buffer_size()].chunks(bpp).enumerate() {
        let c = px[channel] as i32;
        let others = (0..3).filter(|&i| i != channel).map(|i| px[i] as i32);
        if c > 120 && others.clone().all(|o| o * 2 < c) {
            sx += (k % w) as f64;
            sy += (k / w) as f64;
            n += 1.0;
        }
    }
    (n > 0.0).then(|| (sx / n, sy / n))
}

/// A camera straight above, straight below or at an angle keeps the screen the right way
/// round: red marker on +X, green on −X, blue on +Y; +Y is up on screen for the vertical views
/// (+X to the right from above, to the left from below, as a mirror shows it).
#[test]
fn vertical_cameras_keep_plus_y_up() {
    let scratch = common::Scratch::new("cli-render");
    let dir = scratch.path();
    let marker = |name: &str, x: f64, y: f64, color: &str| {
        format!(
            r#"{{"name": "{name}a", "type": "bezier_curve", "points": [[{}, {y}, 0], [{}, {y}, 0]], "samples": 8, "color": {color}}},
               {{"name": "{name}b", "type": "bezier_curve", "points": [[{x}, {}, 0], [{x}, {}, 0]], "samples": 8, "color": {color}}}"#,
            x - 0.4,
            x + 0.4,
            y - 0.4,
            y + 0.4
        )
    };
    let scene = dir.join("markers.json");
    std::fs::write(
        &scene,
        format!(
            r#"{{"objects": [{}, {}, {}]}}"#,
            marker("px", 2.0, 0.0, "[1, 0, 0]"),
            marker("mx", -2.0, 0.0, "[0, 1, 0]"),
            marker("py", 0.0, 2.0, "[0, 0, 1]"),
        ),
    )
    .unwrap();
    // (camera, red right of green, blue above the centre)
    for (camera, red_right, name) in [
        ("0,0,20,0,0,0", true, "above"),
        ("0,0,-20,0,0,0", false, "below"),
        ("0,-12,12,0,0,0", true, "at an angle"),
        ("0,-0.001,20,0,0,0", true, "tilted a little towards -Y"),
    ] {
        let out = dir.join(format!("{name}.png"));
        let r = prespline()
            .arg("render")
            .arg(&scene)
            .arg("--out")
            .arg(&out)
            .args(["--size", "200x200", "--msaa", "1", "--camera", camera])
            .output()
            .unwrap();
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        let red = centroid(&out, 0).expect("red marker visible");
        let green = centroid(&out, 1).expect("green marker visible");
        let blue = centroid(&out, 2).expect("blue marker visible");
        assert_eq!(
            red.0 > green.0,
            red_right,
            "{name}: red {red:?} green {green:?}"
        );
        assert!(
            blue.1 < 100.0 - 20.0,
            "{name}: +Y must be up, blue at {blue:?}"
        );
        assert!((red.1 - green.1).abs() < 10.0, "{name}: X axis level");
    }
}

/// `--out` decides the format by its extension: .jpg/.jpeg write JPEG, .png PNG, anything else
/// is refused in one line and nothing is written.
#[test]
fn the_image_format_follows_the_extension() {
    let scratch = common::Scratch::new("cli-render");
    let dir = scratch.path();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/bezier_curve.json");
    let render = |name: &str| {
        let out = dir.join(name);
        let r = prespline()
            .arg("render")
            .arg(&scene)
            .arg("--out")
            .arg(&out)
            .args(["--size", "96x64"])
            .output()
            .unwrap();
        (r, out)
    };
    for (name, magic) in [
        ("a.jpg", &[0xff, 0xd8, 0xff][..]),
        ("b.JPEG", &[0xff, 0xd8, 0xff][..]),
        ("c.png", &[0x89, b'P', b'N', b'G'][..]),
    ] {
        let (r, out) = render(name);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        let bytes = std::fs::read(&out).unwrap();
        assert!(bytes.starts_with(magic), "{name}: {:x?}", &bytes[..4]);
    }
    for name in ["d.gif", "e", "f.jpg.txt"] {
        let (r, out) = render(name);
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(!r.status.success(), "{name}: {err}");
        assert_eq!(err.lines().count(), 1, "{name}: {err}");
        assert!(
            err.contains("(use .png, .jpg or .jpeg)") || err.contains("needs an extension"),
            "{err}"
        );
        assert!(!out.exists(), "{name} written after refusing");
    }
}

/// The budget's ratio in a `--memory-report` line ("estimate / measured 0.978;"), the scene's
/// estimate alone (the line then gives it with the image's memory too).
fn report_ratio(stderr: &str) -> Option<f64> {
    let line = stderr.lines().find(|l| l.starts_with("memory: estimate"))?;
    let (_, rest) = line.split_once("estimate / measured ")?;
    rest.split(';').next()?.parse().ok()
}

/// Whether an estimate / measured ratio agrees within `tol` (NaN never does).
fn agrees(ratio: f64, tol: f64) -> bool {
    (ratio - 1.0).abs() <= tol
}

/// The tolerance docs/performance.md states for the budget against the resident size.
const RESIDENT_TOLERANCE: f64 = 0.15;

/// Issue 23: the memory budget's estimate of one teapot (32 Bézier patches, where the driver's
/// draw state is most of it) and of a 16 × 16 teapot scene (8192 patches), GPU parts included,
/// agrees with what `render` makes resident within 15 %.
#[test]
fn the_budget_estimate_agrees_with_the_resident_size_on_teapots() {
    use glam::DVec3;
    use prespline::model::Model;
    use prespline::scene::Scene;
    let teapot = prespline::formats::read_json(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/teapot.json"),
    )
    .unwrap();
    let n = 16;
    let mut objects = Vec::new();
    for k in 0..n * n {
        let offset = DVec3::new((k % n) as f64 * 4.0, (k / n) as f64 * 4.0, 0.0);
        for o in &teapot.objects {
            let mut copy = o.clone();
            copy.name = format!("t{k}_{}", o.name);
            if let Model::Surface(s) = &mut copy.model {
                s.map_points(|p| p + offset);
            }
            objects.push(copy);
        }
    }
    let scratch = common::Scratch::new("cli-render-memory");
    let scene = scratch.path().join("teapots256.json");
    prespline::formats::save_json(&Scene { objects }, &scene).unwrap();
    let one = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/teapot.json");
    for scene in [one, scene] {
        let r = prespline()
            .arg("render")
            .arg(&scene)
            .arg("--out")
            .arg(scratch.path().join("t.png"))
            .args(["--size", "64x64", "--memory-report"])
            // The validation layer's own bookkeeping per Vulkan object is not the scene's.
            .env("PRESPLINE_VALIDATION", "0")
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(r.status.success(), "{err}");
        let ratio = report_ratio(&err).unwrap_or(f64::NAN);
        eprintln!("{err}");
        assert!(
            agrees(ratio, RESIDENT_TOLERANCE),
            "{}: estimate / measured {ratio} is not within {RESIDENT_TOLERANCE}: {err}",
            scene.display()
        );
    }
}

#[test]
fn the_resident_comparison_fails_on_a_wrong_estimate() {
    // Negative controls: an estimate 20 % low or high, and an unreadable report, fail it.
    assert!(agrees(0.9, RESIDENT_TOLERANCE));
    assert!(!agrees(0.8, RESIDENT_TOLERANCE));
    assert!(!agrees(1.2, RESIDENT_TOLERANCE));
    assert!(!agrees(f64::NAN, RESIDENT_TOLERANCE));
    let line = "memory: estimate 1 B (1 B); measured 2 B (...); estimate / measured 0.500; \
                with the image's attachments and read-back (1 B, which the budget leaves out) 1.000";
    assert_eq!(report_ratio(line), Some(0.5));
    assert!(!agrees(report_ratio(line).unwrap(), RESIDENT_TOLERANCE));
    assert_eq!(report_ratio("wrote x.png"), None);
}

/// What `render --analysis gaussian` wrote for `scene` with `args`: the image and the
/// document and shot it shows (for projecting samples and placing legends).
fn render_map(
    scene: &Path,
    out: &Path,
    args: &[&str],
) -> (
    prespline::gpu::Pixels,
    prespline::editor::Document,
    prespline::render::offscreen::Shot,
) {
    use prespline::render::ViewOptions;
    use prespline::render::maps::SurfaceMap;
    let r = prespline()
        .arg("render")
        .arg(scene)
        .arg("--out")
        .arg(out)
        .args(["--size", "960x540", "--msaa", "1", "--analysis", "gaussian"])
        .args(args)
        .output()
        .unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let px = prespline::gpu::Pixels::read_png(out).unwrap();
    let loaded = prespline::formats::read_json(scene).unwrap();
    let doc = common::editor(&loaded, Some(SurfaceMap::Gaussian)).into_document();
    let shot = prespline::render::offscreen::Shot {
        width: 960,
        height: 540,
        camera: None,
        options: ViewOptions {
            analysis: Some(SurfaceMap::Gaussian),
            ..ViewOptions::default()
        },
        msaa: 1,
    };
    (px, doc, shot)
}

/// The text of a legend drawn for `scale` at `slot` (named `name`): its title and its three
/// values, as read from the image where [`legend_layout`] puts them.
fn read_legend(
    px: &prespline::gpu::Pixels,
    scale: prespline::render::maps::MapScale,
    name: Option<&str>,
    slot: usize,
) -> (Vec<String>, Vec<String>) {
    use prespline::gpu::font::{Font, TextSize};
    use prespline::render::analysis::PANEL;
    use prespline::render::maps::{LEGEND_TEXT, LegendPlace, SurfaceMap, legend_layout};
    let font = Font::new(1.0);
    let place = LegendPlace {
        name,
        slot,
        width: px.width as f32,
        height: px.height as f32,
    };
    let layout = legend_layout(SurfaceMap::Gaussian, scale, &font, place);
    let texts: Vec<(String, [f32; 2])> =
        std::iter::once(layout.title).chain(layout.labels).collect();
    let want = texts.iter().map(|(t, _)| t.clone()).collect();
    let seen = texts
        .iter()
        .map(|(t, at)| {
            let at = [at[0].round() as u32, at[1].round() as u32];
            common::read_text(
                px,
                &font,
                TextSize::Normal,
                at,
                t.chars().count(),
                PANEL,
                LEGEND_TEXT,
            )
        })
        .collect();
    (want, seen)
}

/// `render --map-range MIN,MAX` fixes the scale: the legend reads MIN, the middle and MAX, and
/// a range far wider than the bumps' curvature leaves them white, where the default
/// (per-object) range colours them and its legend shows the surface's own range.
#[test]
fn render_map_range_min_max_sets_the_legend_and_the_colours() {
    use crate::render_analysis::coloured_fraction_beside;
    use prespline::render::maps::{MapRange, MapScale, SurfaceMap, map_scales};
    let scratch = common::Scratch::new("cli-map-range");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/bspline_surface.json");
    let (px, doc, shot) = render_map(&scene, &scratch.join("default.png"), &[]);
    let own = map_scales(&doc, SurfaceMap::Gaussian, MapRange::PerObject)[0];
    let (want, seen) = read_legend(&px, own, None, 0);
    assert_eq!(seen, want, "default: the surface's own range");
    let coloured = coloured_fraction_beside(&doc, &shot, &px, 0, 1);
    assert!(coloured > 0.3, "default: the bumps show colour: {coloured}");

    let fixed = MapScale {
        low: -50.0,
        high: 50.0,
    };
    let (want, seen) = read_legend(&px, fixed, None, 0);
    assert_ne!(
        seen, want,
        "negative control: the default legend is not the fixed one"
    );
    let (px, doc, shot) = render_map(&scene, &scratch.join("fixed.png"), &["--map-range=-50,50"]);
    let (want, seen) = read_legend(&px, fixed, None, 0);
    assert_eq!(want[1..], ["-50.00", "0", "50.00"]);
    assert_eq!(
        seen, want,
        "--map-range=-50,50: the legend shows the fixed range"
    );
    let coloured = coloured_fraction_beside(&doc, &shot, &px, 0, 1);
    assert!(
        coloured < 0.05,
        "a wide fixed range leaves the bumps white: {coloured}"
    );
}

/// `render --map-range shared` against the default on the bumps beside the teapot: by default
/// each family has its own legend (teapot above, bumps below) and the bumps show colour; shared,
/// one unnamed legend with the teapot-sized range and the bumps go white.
#[test]
fn render_map_range_shared_against_the_default() {
    use crate::render_analysis::{bumps_beside_the_teapot_json, coloured_fraction_beside};
    use prespline::render::maps::{MapRange, SurfaceMap, map_scales};
    let scratch = common::Scratch::new("cli-map-range");
    let scene = scratch.file("mixed.json", &bumps_beside_the_teapot_json());
    let (px, doc, shot) = render_map(&scene, &scratch.join("default.png"), &[]);
    let bumps = doc.objects.len() - 1;
    let own = map_scales(&doc, SurfaceMap::Gaussian, MapRange::PerObject);
    let (want, seen) = read_legend(&px, own[0], Some("teapot"), 1);
    assert_eq!(seen, want, "default: the teapot's legend on top");
    let (want, seen) = read_legend(&px, own[bumps], Some("bumps"), 0);
    assert_eq!(seen, want, "default: the bumps' legend below");
    let coloured = coloured_fraction_beside(&doc, &shot, &px, bumps, 2);
    assert!(coloured > 0.3, "default: the bumps show colour: {coloured}");

    let shared = map_scales(&doc, SurfaceMap::Gaussian, MapRange::Shared)[0];
    let (want, seen) = read_legend(&px, shared, None, 0);
    assert_ne!(seen, want, "negative control: no shared legend by default");
    let (px, doc, shot) = render_map(
        &scene,
        &scratch.join("shared.png"),
        &["--map-range", "shared"],
    );
    let (want, seen) = read_legend(&px, shared, None, 0);
    assert_eq!(seen, want, "shared: one legend with the shared range");
    let coloured = coloured_fraction_beside(&doc, &shot, &px, bumps, 1);
    assert!(coloured < 0.05, "shared: the bumps wash out: {coloured}");
}
