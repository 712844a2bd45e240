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

/// Golden images live in `tests/golden/NAME.png`. On mismatch `NAME-actual.png` and
/// `NAME-diff.png` are written next to the golden (git-ignored). `PRESPLINE_BLESS=1`
/// (re)writes the golden instead of comparing.
///
/// A pixel mismatches when any channel differs by more than `tolerance`; the test fails
/// when more than `max_fraction` of the pixels mismatch.
pub fn assert_golden(name: &str, actual: &Pixels, tolerance: u8, max_fraction: f64) {
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
    if (golden.width, golden.height) != (actual.width, actual.height) {
        actual.write_png(&actual_path).expect("write actual");
        panic!(
            "{name}: size {}x{} differs from golden {}x{}; actual written to {}",
            actual.width,
            actual.height,
            golden.width,
            golden.height,
            actual_path.display()
        );
    }
    let mut diff = Pixels {
        width: actual.width,
        height: actual.height,
        rgba: vec![0; actual.rgba.len()],
    };
    let mut bad = 0usize;
    let mut worst = 0u8;
    for (i, (a, g)) in actual
        .rgba
        .chunks_exact(4)
        .zip(golden.rgba.chunks_exact(4))
        .enumerate()
    {
        let d = a
            .iter()
            .zip(g)
            .map(|(x, y)| x.abs_diff(*y))
            .max()
            .unwrap_or(0);
        worst = worst.max(d);
        let px = &mut diff.rgba[i * 4..i * 4 + 4];
        if d > tolerance {
            bad += 1;
            px.copy_from_slice(&[255, 0, 255, 255]);
        } else {
            // Faded copy of the golden for context.
            px.copy_from_slice(&[g[0] / 4, g[1] / 4, g[2] / 4, 255]);
        }
    }
    let total = (actual.width * actual.height) as usize;
    let fraction = bad as f64 / total as f64;
    if fraction > max_fraction {
        actual.write_png(&actual_path).expect("write actual");
        diff.write_png(&diff_path).expect("write diff");
        panic!(
            "{name}: {bad} of {total} pixels ({:.3}%) differ by more than {tolerance} \
             (worst {worst}); allowed {:.3}%.\n  actual: {}\n  diff:   {}\n  golden: {}\n\
             re-bless with PRESPLINE_BLESS=1 if the change is intended",
            fraction * 100.0,
            max_fraction * 100.0,
            actual_path.display(),
            diff_path.display(),
            golden_path.display()
        );
    }
    // Stale outputs from an earlier failure would be confusing.
    let _ = std::fs::remove_file(actual_path);
    let _ = std::fs::remove_file(diff_path);
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
