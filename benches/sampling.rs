//! Pre-evaluation benchmarks on the DESIGN.md "Performance model" workload:
//! a bicubic clamped uniform surface with 100×100 control points sampled 512×512 with S, Su, Sv
//! and normals; a cubic curve with 1000 control points sampled 100 000 times with C, C'; edits of
//! one interior point, one boundary point, ten random points, and an ERBS local-patch rotation.
//!
//! `cargo bench --bench sampling` runs criterion and then prints a summary table (full sampling
//! time, M samples/s, µs per edit, samples touched, edit/full ratio) from criterion's estimates.

use criterion::{BenchmarkId, Criterion, Throughput};
use glam::{DMat4, DVec3};
use prespline::geom::{BFunctionKind, BSplineCurve, ErbsSurface, KnotVector, TensorSurface};
use prespline::sampling::{SampleMode, SampledObject};
use prespline::scene::{EditOp, Index2, Samples, Shape};
use std::hint::black_box;
use std::time::Duration;

const SURFACE_SAMPLES: usize = 512;
const CURVE_SAMPLES: usize = 100_000;

fn surface() -> Shape {
    let n = 100;
    let pts = (0..n * n)
        .map(|k| {
            let (i, j) = ((k / n) as f64, (k % n) as f64);
            DVec3::new(i, j, (0.3 * i).sin() * (0.2 * j).cos())
        })
        .collect();
    let k = KnotVector::clamped_uniform(3, n, 0.0, 1.0).into_vec();
    Shape::BSplineSurface(
        TensorSurface::bspline([3, 3], [k.clone(), k], [n, n], pts, None).unwrap(),
    )
}

fn curve() -> Shape {
    let n = 1000;
    let pts = (0..n)
        .map(|i| DVec3::new(i as f64, (0.1 * i as f64).sin(), 0.0))
        .collect();
    Shape::BSplineCurve(
        BSplineCurve::new(
            3,
            KnotVector::clamped_uniform(3, n, 0.0, 1.0).into_vec(),
            pts,
            None,
        )
        .unwrap(),
    )
}

/// 10 × 10 bicubic local patches tiling [0, 10]².
fn erbs_surface() -> Shape {
    let n = 10;
    let knots: Vec<f64> = std::iter::once(0.0)
        .chain((0..n).map(|i| i as f64))
        .chain(std::iter::once((n - 1) as f64))
        .collect();
    let mut patches = Vec::new();
    for k in 0..n {
        for l in 0..n {
            let pts = (0..16)
                .map(|q| {
                    DVec3::new(
                        k as f64 + (q / 4) as f64 / 3.0,
                        l as f64 + (q % 4) as f64 / 3.0,
                        ((k * l + q) % 5) as f64 * 0.1,
                    )
                })
                .collect();
            patches.push(TensorSurface::bezier([4, 4], pts, None).unwrap());
        }
    }
    Shape::ErbsSurface(
        ErbsSurface::new(
            [knots.clone(), knots],
            [n, n],
            patches,
            BFunctionKind::ExpoRational,
        )
        .unwrap(),
    )
}

fn rotation_about(centre: DVec3, angle: f64) -> DMat4 {
    DMat4::from_translation(centre)
        * DMat4::from_rotation_z(angle)
        * DMat4::from_translation(-centre)
}

/// The edit scenarios: (name, object, edit batch).
fn scenarios() -> Vec<(&'static str, &'static str, Vec<EditOp>)> {
    let mv = |i, j| EditOp::TranslatePoint {
        point: Index2::Two(i, j),
        delta: DVec3::new(0.0, 0.0, 1e-3),
    };
    let mut state = 12345u64;
    let mut next = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 33) % 100) as usize
    };
    let ten = (0..10).map(|_| mv(next(), next())).collect();
    vec![
        ("interior point", "surface", vec![mv(50, 50)]),
        ("boundary point", "surface", vec![mv(0, 50)]),
        ("ten random points", "surface", ten),
        (
            "curve point",
            "curve",
            vec![EditOp::TranslatePoint {
                point: Index2::One(500),
                delta: DVec3::new(0.0, 1e-3, 0.0),
            }],
        ),
        (
            "ERBS patch rotation",
            "erbs",
            vec![EditOp::TransformLocal {
                local: Index2::Two(4, 5),
                matrix: rotation_about(DVec3::new(4.5, 5.5, 0.0), 1e-3),
            }],
        ),
    ]
}

fn objects() -> Vec<(&'static str, Shape, Samples)> {
    vec![
        ("surface", surface(), Samples::Surface([SURFACE_SAMPLES; 2])),
        ("curve", curve(), Samples::Curve(CURVE_SAMPLES)),
        (
            "erbs",
            erbs_surface(),
            Samples::Surface([SURFACE_SAMPLES; 2]),
        ),
    ]
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("full");
    g.sample_size(20).measurement_time(Duration::from_secs(4));
    for (name, shape, samples) in objects() {
        let mut obj = SampledObject::new(&shape, samples, SampleMode::Render);
        g.throughput(Throughput::Elements(obj.sample_count() as u64));
        g.bench_function(BenchmarkId::from_parameter(name), |b| {
            b.iter(|| {
                // The same full pass the constructor runs, without re-building the tables.
                black_box(obj.rebuild_all());
            })
        });
    }
    g.finish();

    let mut g = c.benchmark_group("edit");
    g.measurement_time(Duration::from_secs(3));
    let objs = objects();
    for (name, target, batch) in scenarios() {
        let (_, shape, samples) = objs.iter().find(|o| o.0 == target).unwrap();
        let mut obj = SampledObject::new(shape, *samples, SampleMode::Render);
        // Alternate the sign so the object does not wander off over millions of iterations.
        let back: Vec<EditOp> = batch.iter().map(invert).collect();
        let mut flip = false;
        g.bench_function(BenchmarkId::from_parameter(name), |b| {
            b.iter(|| {
                flip = !flip;
                for op in if flip { &batch } else { &back } {
                    black_box(obj.apply(op));
                }
            })
        });
    }
    g.finish();
}

fn invert(op: &EditOp) -> EditOp {
    match op {
        EditOp::TranslatePoint { point, delta } => EditOp::TranslatePoint {
            point: *point,
            delta: -*delta,
        },
        EditOp::TransformLocal { local, matrix } => EditOp::TransformLocal {
            local: *local,
            matrix: matrix.inverse(),
        },
        other => other.clone(),
    }
}

/// Reads criterion's mean estimate (ns) for a benchmark id. Criterion keeps spaces in its
/// directory names (`criterion/edit/interior point/`), so the id is used as it is.
fn mean_ns(group: &str, id: &str) -> Option<f64> {
    let dir = std::env::var("CARGO_TARGET_DIR").unwrap_or_else(|_| "target".into());
    let path = format!("{dir}/criterion/{group}/{id}/new/estimates.json");
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(path).ok()?).ok()?;
    v["mean"]["point_estimate"].as_f64()
}

fn summary() {
    println!("\nSummary (single thread, means of criterion's samples)\n");
    println!("| workload | samples | full sampling | M samples/s |");
    println!("|---|---:|---:|---:|");
    let objs = objects();
    for (name, shape, samples) in &objs {
        let n = SampledObject::new(shape, *samples, SampleMode::Render).sample_count();
        match mean_ns("full", name) {
            Some(ns) => println!(
                "| {name} | {n} | {:.3} ms | {:.1} |",
                ns / 1e6,
                n as f64 / (ns / 1e9) / 1e6
            ),
            None => println!("| {name} | {n} | not measured | |"),
        }
    }
    println!("\n| edit | object | µs per edit batch | samples touched | edit / full |");
    println!("|---|---|---:|---:|---:|");
    for (name, target, batch) in scenarios() {
        let (_, shape, samples) = objs.iter().find(|o| o.0 == target).unwrap();
        let mut obj = SampledObject::new(shape, *samples, SampleMode::Render);
        let touched: usize = batch.iter().map(|op| obj.apply(op).samples()).sum();
        // A row whose estimate is missing still prints, so a broken lookup cannot hide it.
        match (mean_ns("edit", name), mean_ns("full", target)) {
            (Some(e), Some(f)) => println!(
                "| {name} | {target} | {:.2} | {touched} | 1/{:.0} |",
                e / 1e3,
                f / e
            ),
            (Some(e), None) => println!("| {name} | {target} | {:.2} | {touched} | |", e / 1e3),
            _ => println!("| {name} | {target} | not measured | {touched} | |"),
        }
    }
}

fn main() {
    let mut c = Criterion::default().configure_from_args();
    bench(&mut c);
    c.final_summary();
    // `cargo test` runs benches once as smoke tests; only `cargo bench` (which passes --bench)
    // leaves fresh estimates to summarise.
    if std::env::args().any(|a| a == "--bench") {
        summary();
    }
}
