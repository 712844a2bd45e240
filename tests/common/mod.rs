//! Shared helpers for the GPU tests: a validated lavapipe renderer, a golden-image harness
//! and small synthetic scenes (computed here, independent of `geom`).
#![allow(dead_code)] // each test binary uses a different subset

use std::f32::consts::TAU;
use std::path::PathBuf;

use glam::{Mat4, Vec3};
use prespline::gpu::{
    Camera, GridShape, Pixels, Renderer, RendererDesc, ValidationMode, ValidationSink, vk,
};

/// Renderer on lavapipe (chosen by name among the installed drivers, and checked to be the
/// CPU device llvmpipe) with the validation layer required.
pub fn renderer_with(always_flush: bool) -> (Renderer, ValidationSink) {
    let renderer = Renderer::new(&RendererDesc {
        app_name: "prespline-tests".into(),
        validation: ValidationMode::Required,
        sync_validation: true,
        display: None,
        always_flush,
        device: Some("llvmpipe".into()),
    })
    .unwrap_or_else(|e| panic!("cannot create renderer on lavapipe: {e}"));
    let caps = renderer.caps();
    assert!(
        caps.device_type == vk::PhysicalDeviceType::CPU && caps.name.contains("llvmpipe"),
        "GPU tests must run on lavapipe (llvmpipe, a CPU device), got {} ({:?})",
        caps.name,
        caps.device_type
    );
    let sink = renderer
        .validation_sink()
        .expect("validation is required, so a sink exists");
    (renderer, sink)
}

pub fn renderer() -> (Renderer, ValidationSink) {
    renderer_with(false)
}

/// Drops the renderer (teardown reports leaks through the sink) and fails on any
/// validation error seen during the whole test.
pub fn teardown(renderer: Renderer, sink: ValidationSink) {
    drop(renderer);
    let errors = sink.errors();
    assert!(
        errors.is_empty(),
        "{} validation error(s):\n{}",
        errors.len(),
        errors
            .iter()
            .map(ToString::to_string)
            .collect::<Vec<_>>()
            .join("\n")
    );
}

/// How far a rendering may stray from its golden image. Rasterisation on lavapipe is
/// deterministic for one driver build; the slack only absorbs rounding between builds, so a
/// thin curve or a few control-point markers that go missing must fail.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GoldenTolerance {
    /// A pixel differs when any channel differs by more than this.
    pub channel: u8,
    /// At most this fraction of the pixels may differ.
    pub max_fraction: f64,
    /// No channel of any pixel may differ by more than this: a missing 2-px curve or marker is
    /// few pixels, each far off. One of four MSAA samples flipping on a black/white edge moves
    /// a pixel by 64 at most.
    pub max_channel_diff: u8,
}

/// The tolerance every golden test uses.
pub const GOLDEN: GoldenTolerance = GoldenTolerance {
    channel: 2,
    max_fraction: 0.0005,
    max_channel_diff: 64,
};

/// Per-pixel comparison of two images of the same size.
pub struct ImageDiff {
    /// Pixels with a channel differing by more than the tolerance's `channel`.
    pub differing: usize,
    pub total: usize,
    /// Largest channel difference anywhere.
    pub worst: u8,
    /// Differing pixels magenta over a faded copy of the expected image.
    pub picture: Pixels,
}

impl ImageDiff {
    pub fn fraction(&self) -> f64 {
        self.differing as f64 / self.total.max(1) as f64
    }

    /// Whether the difference is within `tol`; the error says which bound broke.
    pub fn check(&self, tol: &GoldenTolerance) -> Result<(), String> {
        let mut broken = Vec::new();
        if self.fraction() > tol.max_fraction {
            broken.push(format!(
                "{} of {} pixels ({:.3}%) differ by more than {} (allowed {:.3}%)",
                self.differing,
                self.total,
                self.fraction() * 100.0,
                tol.channel,
                tol.max_fraction * 100.0
            ));
        }
        if self.worst > tol.max_channel_diff {
            broken.push(format!(
                "the worst pixel differs by {} (allowed {})",
                self.worst, tol.max_channel_diff
            ));
        }
        if broken.is_empty() {
            Ok(())
        } else {
            Err(broken.join("; "))
        }
    }
}

/// Compares `actual` with `expected` pixel by pixel (`channel` decides which pixels count as
/// differing); `Err` when the sizes differ.
pub fn compare_images(
    expected: &Pixels,
    actual: &Pixels,
    channel: u8,
) -> Result<ImageDiff, String> {
    if (expected.width, expected.height) != (actual.width, actual.height) {
        return Err(format!(
            "size {}x{} differs from the expected {}x{}",
            actual.width, actual.height, expected.width, expected.height
        ));
    }
    let mut picture = Pixels {
        width: actual.width,
        height: actual.height,
        rgba: vec![0; actual.rgba.len()],
    };
    let mut differing = 0usize;
    let mut worst = 0u8;
    for (i, (a, g)) in actual
        .rgba
        .chunks_exact(4)
        .zip(expected.rgba.chunks_exact(4))
        .enumerate()
    {
        let d = a
            .iter()
            .zip(g)
            .map(|(x, y)| x.abs_diff(*y))
            .max()
            .unwrap_or(0);
        worst = worst.max(d);
        let px = &mut picture.rgba[i * 4..i * 4 + 4];
        if d > channel {
            differing += 1;
            px.copy_from_slice(&[255, 0, 255, 255]);
        } else {
            // Faded copy of the expected image for context.
            px.copy_from_slice(&[g[0] / 4, g[1] / 4, g[2] / 4, 255]);
        }
    }
    Ok(ImageDiff {
        differing,
        total: (actual.width * actual.height) as usize,
        worst,
        picture,
    })
}

/// Golden images live in `tests/golden/NAME.png` and are compared within [`GOLDEN`]. On
/// mismatch `NAME-actual.png` and `NAME-diff.png` are written next to the golden (git-ignored).
/// `PRESPLINE_BLESS=1` (re)writes the golden instead of comparing.
pub fn assert_golden(name: &str, actual: &Pixels) {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/golden");
    let golden_path = dir.join(format!("{name}.png"));
    if std::env::var_os("PRESPLINE_BLESS").is_some_and(|v| v == "1") {
        std::fs::create_dir_all(&dir).expect("create tests/golden");
        actual.write_png(&golden_path).expect("write golden");
        eprintln!("blessed {}", golden_path.display());
        return;
    }
    let golden = Pixels::read_png(&golden_path)
        .unwrap_or_else(|e| panic!("{e}\n(run with PRESPLINE_BLESS=1 to create the golden image)"));
    let actual_path = dir.join(format!("{name}-actual.png"));
    let diff_path = dir.join(format!("{name}-diff.png"));
    let outcome = compare_images(&golden, actual, GOLDEN.channel).and_then(|diff| {
        diff.check(&GOLDEN).inspect_err(|_| {
            diff.picture.write_png(&diff_path).expect("write diff");
        })
    });
    if let Err(why) = outcome {
        actual.write_png(&actual_path).expect("write actual");
        panic!(
            "{name}: {why}.\n  actual: {}\n  diff:   {}\n  golden: {}\n\
             re-bless with PRESPLINE_BLESS=1 if the change is intended",
            actual_path.display(),
            diff_path.display(),
            golden_path.display()
        );
    }
    // Stale outputs from an earlier failure would be confusing.
    let _ = std::fs::remove_file(actual_path);
    let _ = std::fs::remove_file(diff_path);
}

/// Whether skips must fail: under `make test` (which exports `PRESPLINE_STRICT=1`) and on CI
/// (`CI` set to anything but "" / "0" / "false").
pub fn strict() -> bool {
    let on = |var: &str| {
        std::env::var(var)
            .is_ok_and(|v| !v.is_empty() && v != "0" && !v.eq_ignore_ascii_case("false"))
    };
    on("PRESPLINE_STRICT") || on("CI")
}

/// Whether a test whose precondition (`available`) is missing may go on: false (skip with a
/// note) outside strict mode, a failure in strict mode.
pub fn precondition(available: bool, what: &str) -> bool {
    if !available {
        assert!(
            !strict(),
            "{what}, and skipping is not allowed under make test or CI (PRESPLINE_STRICT / CI set)"
        );
        eprintln!("skipped: {what}");
    }
    available
}

/// Whether an X display is reachable for windowed tests (`make test` runs them under Xvfb).
pub fn display() -> bool {
    precondition(
        std::env::var_os("DISPLAY").is_some_and(|d| !d.is_empty()),
        "DISPLAY is not set (make test runs this under Xvfb)",
    )
}

/// A scratch directory of its own for one test: `target/tmp/LABEL-PID-N` with a per-process
/// counter, emptied if a stale one exists, removed when dropped (kept when the test fails, for
/// inspection).
pub struct Scratch {
    path: PathBuf,
}

impl Scratch {
    pub fn new(label: &str) -> Self {
        use std::sync::atomic::{AtomicUsize, Ordering};
        static NEXT: AtomicUsize = AtomicUsize::new(0);
        let n = NEXT.fetch_add(1, Ordering::Relaxed);
        Self::at(
            PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
                .join(format!("{label}-{}-{n}", std::process::id())),
        )
    }

    /// The scratch directory `path`, emptied first: a reused process id must not find an
    /// earlier run's results.
    pub fn at(path: PathBuf) -> Self {
        let _ = std::fs::remove_dir_all(&path);
        std::fs::create_dir_all(&path)
            .unwrap_or_else(|e| panic!("cannot create {}: {e}", path.display()));
        Self { path }
    }

    pub fn path(&self) -> &std::path::Path {
        &self.path
    }

    /// `path/name`.
    pub fn join(&self, name: impl AsRef<std::path::Path>) -> PathBuf {
        self.path.join(name)
    }

    /// Writes `text` to a new file `name` in the directory.
    pub fn file(&self, name: &str, text: &str) -> PathBuf {
        let p = self.path.join(name);
        std::fs::write(&p, text).unwrap_or_else(|e| panic!("cannot write {}: {e}", p.display()));
        p
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            let _ = std::fs::remove_dir_all(&self.path);
        }
    }
}

/// At most this many children of one test binary run at once. A binary's tests run on a
/// thread each, and a dozen viewers starting together would share two cores with the Xvfb
/// server and each other (the "Failed to open connection to X server" that once came with it
/// was the server resetting between clients; `make test` runs Xvfb with -noreset). The limit
/// is a wait, not a skip: every child still runs.
const MAX_CHILDREN: usize = 3;

struct ChildSlot;

static RUNNING: std::sync::Mutex<usize> = std::sync::Mutex::new(0);
static FREED: std::sync::Condvar = std::sync::Condvar::new();

impl ChildSlot {
    fn take() -> ChildSlot {
        let poisoned = std::sync::PoisonError::into_inner;
        let mut running = RUNNING.lock().unwrap_or_else(poisoned);
        while *running >= MAX_CHILDREN {
            running = FREED.wait(running).unwrap_or_else(poisoned);
        }
        *running += 1;
        ChildSlot
    }
}

impl Drop for ChildSlot {
    fn drop(&mut self) {
        let mut running = RUNNING
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        *running -= 1;
        FREED.notify_one();
    }
}

/// Runs `command` to completion with its output captured, killing it and failing the test
/// when it runs longer than `limit` (a hung viewer must not hang the suite).
pub fn output_with_timeout(
    command: &mut std::process::Command,
    limit: std::time::Duration,
) -> std::process::Output {
    use std::io::Read;
    use std::process::Stdio;
    let _slot = ChildSlot::take();
    let mut child = command
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("cannot run {command:?}: {e}"));
    let pipe = |mut r: Box<dyn Read + Send>| {
        std::thread::spawn(move || {
            let mut buf = Vec::new();
            let _ = r.read_to_end(&mut buf);
            buf
        })
    };
    let stdout = pipe(Box::new(child.stdout.take().expect("piped")));
    let stderr = pipe(Box::new(child.stderr.take().expect("piped")));
    let start = std::time::Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait for the child") {
            break status;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            let err = String::from_utf8_lossy(&stderr.join().unwrap_or_default()).into_owned();
            panic!("{command:?} did not finish within {limit:?}; stderr:\n{err}");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    std::process::Output {
        status,
        stdout: stdout.join().unwrap_or_default(),
        stderr: stderr.join().unwrap_or_default(),
    }
}

/// A camera looking at the origin from `eye`, z up.
pub fn camera(eye: Vec3, width: u32, height: u32) -> Camera {
    let proj = Mat4::perspective_rh(0.8, width as f32 / height as f32, 0.1, 50.0);
    let view = Mat4::look_at_rh(eye, Vec3::ZERO, Vec3::Z);
    Camera {
        view_proj: proj * view,
        eye,
    }
}

/// An open torus section (so its inside, the back side, is visible) as a grid of
/// (position, normal) vertices with analytic normals.
pub fn torus_section(shape: GridShape, major: f32, minor: f32) -> Vec<f32> {
    let mut out = Vec::with_capacity(shape.vertices() as usize * 6);
    for i in 0..shape.rows {
        let u = 0.8 * TAU * i as f32 / (shape.rows - 1) as f32;
        for j in 0..shape.cols {
            let v = 0.75 * TAU * j as f32 / (shape.cols - 1) as f32;
            let (su, cu) = u.sin_cos();
            let (sv, cv) = v.sin_cos();
            let ring = major + minor * cv;
            out.extend_from_slice(&[ring * cu, ring * su, minor * sv, cv * cu, cv * su, sv]);
        }
    }
    out
}

/// A height field z = h(x, y) over [-1, 1]² with exact normals; `bumps` are
/// (x, y, height, radius) Gaussians.
pub fn height_field(shape: GridShape, bumps: &[(f32, f32, f32, f32)]) -> Vec<f32> {
    let mut out = Vec::with_capacity(shape.vertices() as usize * 6);
    for i in 0..shape.rows {
        let y = -1.0 + 2.0 * i as f32 / (shape.rows - 1) as f32;
        for j in 0..shape.cols {
            let x = -1.0 + 2.0 * j as f32 / (shape.cols - 1) as f32;
            let (mut z, mut dx, mut dy) = (0.0, 0.0, 0.0);
            for &(bx, by, h, r) in bumps {
                let g = h * (-((x - bx).powi(2) + (y - by).powi(2)) / (r * r)).exp();
                z += g;
                dx += g * -2.0 * (x - bx) / (r * r);
                dy += g * -2.0 * (y - by) / (r * r);
            }
            let n = Vec3::new(-dx, -dy, 1.0).normalize();
            out.extend_from_slice(&[x, y, z, n.x, n.y, n.z]);
        }
    }
    out
}

/// A helix of `n` points around the z axis.
pub fn helix(n: usize, radius: f32, turns: f32, z0: f32, z1: f32) -> Vec<f32> {
    let mut out = Vec::with_capacity(n * 3);
    for k in 0..n {
        let t = k as f32 / (n - 1) as f32;
        let a = TAU * turns * t;
        out.extend_from_slice(&[radius * a.cos(), radius * a.sin(), z0 + (z1 - z0) * t]);
    }
    out
}

/// Small deterministic PRNG (xorshift64*), so failures reproduce.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(seed.max(1))
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// Uniform in `lo..hi`.
    pub fn range(&mut self, lo: usize, hi: usize) -> usize {
        lo + (self.next_u64() % (hi - lo) as u64) as usize
    }

    /// Uniform in `[lo, hi)`.
    pub fn f32(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * ((self.next_u64() >> 40) as f32 / (1u64 << 24) as f32)
    }
}

/// An editor over `scene` as the viewer runs one (shading samples, GPU mirrors budgeted),
/// with `map` shown on its surfaces (curvature maps sample second partials).
pub fn editor(
    scene: &prespline::scene::Scene,
    map: Option<prespline::render::maps::SurfaceMap>,
) -> prespline::editor::Editor {
    use prespline::sampling::SampleMode;
    let options = prespline::editor::EditorOptions {
        mode: SampleMode::Render,
        uses: prespline::render::DRAW_USES,
        budget: prespline::sampling::budget::MemoryBudget::machine_default(),
    };
    let mut ed = prespline::editor::Editor::new(scene, options).expect("the scene fits");
    if map.is_some_and(|m| m.needs_curvature()) {
        ed.set_surface_mode(SampleMode::Analysis)
            .expect("the map fits");
        ed.apply_pending();
    }
    ed
}

/// Submits `e` through the editor and hands what it changed to the GPU scene: the route of
/// every edit.
pub fn edit(
    ed: &mut prespline::editor::Editor,
    gs: &mut prespline::render::GpuScene,
    e: prespline::model::Edit,
) -> prespline::editor::Applied {
    ed.submit(e).expect("a valid edit");
    let applied = ed.apply_pending();
    gs.consume(&applied);
    applied
}

/// sRGB byte → linear.
pub fn srgb_to_linear(c: u8) -> f32 {
    let c = f32::from(c) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear → sRGB byte.
pub fn linear_to_srgb(c: f32) -> u8 {
    let c = c.clamp(0.0, 1.0);
    let s = if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0).round() as u8
}

/// What a pixel of overlay text with coverage `a` (0..=255) in colour `color` over the opaque
/// `panel` looks like: the GPU blends in linear space into an sRGB target.
pub fn text_over(panel: [u8; 4], color: [u8; 4], a: u8) -> [u8; 3] {
    let a = f32::from(a) / 255.0;
    std::array::from_fn(|i| {
        let (p, c) = (srgb_to_linear(panel[i]), srgb_to_linear(color[i]));
        linear_to_srgb(p + (c - p) * a)
    })
}

/// Reads `count` characters of overlay text whose first cell's top-left corner is `at`,
/// drawn with `font` at `size` in `color` over the opaque `panel`: each cell is compared with
/// every printable ASCII glyph (and `…`) as the GPU would blend it, and the closest wins. The
/// overlay font is monospace on whole pixels, so this reads what a user sees on the panel.
pub fn read_text(
    px: &Pixels,
    font: &prespline::gpu::font::Font,
    size: prespline::gpu::font::TextSize,
    at: [u32; 2],
    count: usize,
    panel: [u8; 4],
    color: [u8; 4],
) -> String {
    let m = font.metrics(size);
    let candidates: Vec<(char, Vec<u8>)> = (' '..='~')
        .chain(['…'])
        .map(|c| (c, font.glyph_cell(c, size)))
        .collect();
    let mut text = String::new();
    for i in 0..count as u32 {
        let x0 = at[0] + i * m.advance;
        let error = |cell: &[u8]| -> u64 {
            let mut e = 0u64;
            for y in 0..m.cell[1] {
                for x in 0..m.advance {
                    let (gx, gy) = (x0 + x, at[1] + y);
                    if gx >= px.width || gy >= px.height {
                        return u64::MAX;
                    }
                    let want = text_over(panel, color, cell[(y * m.cell[0] + x) as usize]);
                    let got = px.get(gx, gy);
                    e += (0..3)
                        .map(|k| u64::from(want[k].abs_diff(got[k])))
                        .sum::<u64>();
                }
            }
            e
        };
        let best = candidates
            .iter()
            .min_by_key(|(_, cell)| error(cell))
            .map_or('?', |(c, _)| *c);
        text.push(best);
    }
    text
}
