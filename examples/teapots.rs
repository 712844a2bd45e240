//! Writes the "64 Utah teapots" benchmark scene: an N × N grid (8 × 8 by default) of copies of
//! `examples/teapot.json` (32 bicubic Bézier patches each, 17 × 17 samples), 4 units apart —
//! 2048 patches and about a million triangles at full resolution.
//!
//! ```sh
//! cargo run --release --example teapots -- 8 teapots64.json
//! prespline bench teapots64.json --scenario drag --frames 120 --warmup 20
//! ```

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use glam::DVec3;
use prespline::model::Model;
use prespline::scene::Scene;

/// Distance between neighbouring teapots (a teapot is about 3 units across its spout/handle).
const SPACING: f64 = 4.0;

fn main() -> ExitCode {
    let mut args = std::env::args().skip(1);
    let n = match args.next().map(|a| a.parse::<usize>()) {
        None => 8,
        Some(Ok(n)) if (1..=64).contains(&n) => n,
        _ => {
            eprintln!("error: usage: teapots [N (1..=64, default 8)] [OUT.json]");
            return ExitCode::FAILURE;
        }
    };
    let out = args.next().map_or_else(
        || PathBuf::from(format!("teapots{}.json", n * n)),
        PathBuf::from,
    );
    let teapot = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/teapot.json");
    let result = prespline::formats::read_json(&teapot)
        .map_err(|e| e.to_string())
        .and_then(|one| prespline::formats::save_json(&grid(&one, n), &out));
    match result {
        Ok(()) => {
            eprintln!("wrote {} ({} teapots)", out.display(), n * n);
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// `n × n` copies of `one`, copy `k` at (k mod n, k div n) · SPACING in x and y, its objects
/// named `t{k}_{name}`.
fn grid(one: &Scene, n: usize) -> Scene {
    let mut objects = Vec::with_capacity(n * n * one.objects.len());
    for k in 0..n * n {
        let offset = DVec3::new((k % n) as f64 * SPACING, (k / n) as f64 * SPACING, 0.0);
        for o in &one.objects {
            let mut copy = o.clone();
            copy.name = format!("t{k}_{}", o.name);
            if let Model::Surface(s) = &mut copy.model {
                s.map_points(|p| p + offset);
            }
            objects.push(copy);
        }
    }
    Scene { objects }
}
