//! Pre-evaluation benchmarks on the reference workload (docs/performance.md):
//! a bicubic clamped uniform surface with 100×100 control points sampled 512×512 with S, Su, Sv
//! and normals; a cubic curve with 1000 control points sampled 100 000 times with C, C'; edits of
//! one interior point, one boundary point, ten random points, and an ERBS local-patch rotation;
//! structural edits of the surface (knot insertion, degree elevation), each with its undo;
//! the interior point edit with the curvature map off (S, Su, Sv, normals) and on (also Suu,
//! Suv, Svv and K, H per sample).
//!
//! `cargo bench --bench sampling` runs criterion and then prints a summary table (full sampling
//! time, M samples/s, µs per edit, samples touched, edit/full ratio) from criterion's estimates.
//! `BENCH_THREADS=N` runs the full passes on N threads (default: every core).

use criterion::{BenchmarkId, Criterion, Throughput};
use glam::{DMat4, DVec3};
use prespline::geom::{BFunctionKind, BSplineCurve, ErbsSurface, KnotVector, TensorSurface};
use prespline::model::SampledObject;
use prespline::model::{
    CurveEdit, CurveModel, ErbsSurfaceEdit, ErbsSurfaceModel, KindEdit, LocalEdit, LocalPath,
    Model, ObjectEdit, PointEdit, SplineForm, SurfaceEdit, SurfaceModel,
};
use prespline::sampling::SampleMode;
use std::hint::black_box;
use std::time::{Duration, Instant};

const SURFACE_SAMPLES: usize = 512;
const CURVE_SAMPLES: usize = 100_000;

fn surface() -> Model {
    let n = 100;
    let pts = (0..n * n)
        .map(|k| {
            let (i, j) = ((k / n) as f64, (k % n) as f64);
            DVec3::new(i, j, (0.3 * i).sin() * (0.2 * j).cos())
        })
        .collect();
    let k = KnotVector::clamped_uniform(3, n, 0.0, 1.0).into_vec();
    let s = TensorSurface::bspline([3, 3], [k.clone(), k], [n, n], pts, None).unwrap();
    Model::Surface(SurfaceModel::new(SplineForm::BSpline, s, [SURFACE_SAMPLES; 2]).unwrap())
}

fn curve() -> Model {
    let n = 1000;
    let pts = (0..n)
        .map(|i| DVec3::new(i as f64, (0.1 * i as f64).sin(), 0.0))
        .collect();
    let k = KnotVector::clamped_uniform(3, n, 0.0, 1.0).into_vec();
    let c = BSplineCurve::new(3, k, pts, None).unwrap();
    Model::Curve(CurveModel::new(SplineForm::BSpline, c, CURVE_SAMPLES).unwrap())
}

/// 10 × 10 bicubic local patches tiling [0, 10]².
fn erbs_surface() -> Model {
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
    let e = ErbsSurface::new(
        [knots.clone(), knots],
        [n, n],
        patches,
        BFunctionKind::ExpoRational,
    )
    .unwrap();
    Model::ErbsSurface(ErbsSurfaceModel::new(e, [SURFACE_SAMPLES; 2]).unwrap())
}

fn rotation_about(centre: DVec3, angle: f64) -> DMat4 {
    DMat4::from_translation(centre)
        * DMat4::from_rotation_z(angle)
        * DMat4::from_translation(-centre)
}

/// The edit scenarios: (name, object, edit batch). Batches repeat as they are.
fn scenarios() -> Vec<(&'static str, &'static str, Vec<ObjectEdit>)> {
    let mv = |i, j| {
        SurfaceEdit::Point(PointEdit::Move {
            point: [i, j],
            delta: DVec3::new(0.0, 0.0, 1e-3),
        })
        .into_object()
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
            vec![
                CurveEdit::Point(PointEdit::Move {
                    point: 500,
                    delta: DVec3::new(0.0, 1e-3, 0.0),
                })
                .into_object(),
            ],
        ),
        (
            "ERBS patch rotation",
            "erbs",
            vec![
                ErbsSurfaceEdit::Local(LocalEdit::Transform {
                    local: LocalPath::top([4, 5]),
                    matrix: rotation_about(DVec3::new(4.5, 5.5, 0.0), 1e-3),
                })
                .into_object(),
            ],
        ),
    ]
}

/// Structural edits of the surface: (name, edit). Each is timed alone; its undo runs between
/// iterations, untimed, so every iteration refines the same 100 × 100 net.
fn structural() -> Vec<(&'static str, SurfaceEdit)> {
    vec![
        (
            "insert u knot",
            SurfaceEdit::InsertKnot {
                dir: 0,
                t: 0.5037,
                times: 1,
            },
        ),
        (
            "insert v knot",
            SurfaceEdit::InsertKnot {
                dir: 1,
                t: 0.5037,
                times: 1,
            },
        ),
        (
            "elevate u degree",
            SurfaceEdit::ElevateDegree { by: [1, 0] },
        ),
    ]
}

fn objects() -> Vec<(&'static str, Model)> {
    vec![
        ("surface", surface()),
        ("curve", curve()),
        ("erbs", erbs_surface()),
    ]
}

fn bench(c: &mut Criterion) {
    // `BENCH_THREADS=1 cargo bench --bench sampling -- full/` measures one thread (default: all).
    if let Some(n) = std::env::var("BENCH_THREADS")
        .ok()
        .and_then(|n| n.parse().ok())
    {
        prespline::parallel::set_threads(n);
    }
    let mut g = c.benchmark_group("full");
    g.sample_size(20).measurement_time(Duration::from_secs(4));
    for (name, model) in objects() {
        let mut obj = SampledObject::new(&model, SampleMode::Render);
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
        let (_, model) = objs.iter().find(|o| o.0 == target).unwrap();
        let mut obj = SampledObject::new(model, SampleMode::Render);
        g.bench_function(BenchmarkId::from_parameter(name), |b| {
            b.iter(|| {
                for e in &batch {
                    black_box(obj.apply(e).expect("the bench's edits fit their objects"));
                }
            })
        });
    }
    g.finish();

    // The same edit with the analysis map off and on (the budget: on ≤ 2 × off).
    let mut g = c.benchmark_group("analysis");
    g.measurement_time(Duration::from_secs(3));
    let (_, _, batch) = &scenarios()[0];
    for (id, mode) in MAP_MODES {
        let mut obj = SampledObject::new(&surface(), mode);
        g.bench_function(BenchmarkId::from_parameter(id), |b| {
            b.iter(|| {
                for e in batch {
                    black_box(obj.apply(e).expect("the bench's edits fit their objects"));
                }
            })
        });
    }
    g.finish();

    let mut g = c.benchmark_group("edit");
    g.measurement_time(Duration::from_secs(3));
    let surface = surface();
    let Model::Surface(model) = &surface else {
        unreachable!("the surface workload is a B-spline surface")
    };
    let mut obj = SampledObject::new(&surface, SampleMode::Render);
    for (name, edit) in structural() {
        let undo = edit.inverse(model).into_object();
        let edit = edit.into_object();
        g.bench_function(BenchmarkId::from_parameter(name), |b| {
            b.iter_custom(|iters| {
                let mut timed = Duration::ZERO;
                for _ in 0..iters {
                    let start = Instant::now();
                    black_box(obj.apply(&edit).expect("valid refinement"));
                    timed += start.elapsed();
                    obj.apply(&undo).expect("valid undo");
                }
                timed
            })
        });
    }
    g.finish();
}

/// ERBS structure, on the reference surface: building an ERBS surface of 10 × 10 bicubic
/// local patches from the 100 × 100 B-spline surface (Taylor patches at the knot crossings),
/// alone and with its 512² pre-evaluation; and a local refinement (a u knot in the middle of
/// an interval of the bench's ERBS surface), timed alone with its undo run untimed.
fn erbs_structure(c: &mut Criterion) {
    let mut g = c.benchmark_group("erbs");
    g.sample_size(20).measurement_time(Duration::from_secs(4));
    let Model::Surface(source) = surface() else {
        unreachable!("the surface workload is a B-spline surface")
    };
    let build = || {
        ErbsSurface::from_surface(
            source.surface(),
            [10, 10],
            [3, 3],
            BFunctionKind::ExpoRational,
            [false, false],
        )
        .expect("a valid construction")
    };
    g.bench_function(ERBS_STRUCTURE[0], |b| b.iter(|| black_box(build())));
    g.bench_function(ERBS_STRUCTURE[1], |b| {
        b.iter(|| {
            let model = ErbsSurfaceModel::new(build(), [SURFACE_SAMPLES; 2]).unwrap();
            black_box(SampledObject::new(
                &Model::ErbsSurface(model),
                SampleMode::Render,
            ))
        })
    });
    let erbs = erbs_surface();
    let Model::ErbsSurface(model) = &erbs else {
        unreachable!("the ERBS workload is an ERBS surface")
    };
    let edit = ErbsSurfaceEdit::InsertKnot {
        local: None,
        at: (0, 4.37),
        degree: None,
    };
    let undo = edit.inverse(model).into_object();
    let edit = edit.into_object();
    let mut obj = SampledObject::new(&erbs, SampleMode::Render);
    g.bench_function(ERBS_STRUCTURE[2], |b| {
        b.iter_custom(|iters| {
            let mut timed = Duration::ZERO;
            for _ in 0..iters {
                let start = Instant::now();
                black_box(obj.apply(&edit).expect("valid refinement"));
                timed += start.elapsed();
                obj.apply(&undo).expect("valid undo");
            }
            timed
        })
    });
    g.finish();
}

const ERBS_STRUCTURE: [&str; 3] = [
    "construct 10x10 from 100x100",
    "construct and pre-evaluate 512x512",
    "refine u knot",
];

fn erbs_summary() {
    println!(
        "
| ERBS structure (512² samples) | ms |"
    );
    println!("|---|---:|");
    for id in ERBS_STRUCTURE {
        match mean_ns("erbs", id) {
            Some(ns) => println!("| {id} | {:.3} |", ns / 1e6),
            None => println!("| {id} | not measured |"),
        }
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
    for (name, model) in &objs {
        let n = SampledObject::new(model, SampleMode::Render).sample_count();
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
        let (_, model) = objs.iter().find(|o| o.0 == target).unwrap();
        let mut obj = SampledObject::new(model, SampleMode::Render);
        let touched: usize = batch
            .iter()
            .map(|e| obj.apply(e).map_or(0, |r| r.samples()))
            .sum();
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

/// The curvature map's sample modes, by benchmark id.
const MAP_MODES: [(&str, SampleMode); 2] = [
    ("interior point, map off", SampleMode::Render),
    ("interior point, map on", SampleMode::Analysis),
];

fn analysis_summary() {
    println!("\n| edit (100 × 100 surface, 512² samples) | µs | samples touched |");
    println!("|---|---:|---:|");
    let (_, _, batch) = &scenarios()[0];
    for (id, mode) in MAP_MODES {
        let mut obj = SampledObject::new(&surface(), mode);
        let touched = obj.apply(&batch[0]).map_or(0, |r| r.samples());
        match mean_ns("analysis", id) {
            Some(ns) => println!("| {id} | {:.2} | {touched} |", ns / 1e3),
            None => println!("| {id} | not measured | {touched} |"),
        }
    }
    if let (Some(off), Some(on)) = (
        mean_ns("analysis", MAP_MODES[0].0),
        mean_ns("analysis", MAP_MODES[1].0),
    ) {
        println!("\nmap on / map off: {:.2}× (criterion means)", on / off);
    }
    paired_map_ratio();
}

/// The map's cost ratio measured in pairs: the two criterion groups run seconds apart, and on
/// a shared host their ratio moves with whatever else runs. Here each round times a block of
/// edits with the map off and then on, so both see the same load, and the median of the
/// per-round ratios is reported with its spread.
fn paired_map_ratio() {
    const ROUNDS: usize = 41;
    const EDITS: usize = 400;
    let (_, _, batch) = &scenarios()[0];
    let mut objs = MAP_MODES.map(|(_, mode)| SampledObject::new(&surface(), mode));
    let block = |obj: &mut SampledObject| {
        let start = Instant::now();
        for _ in 0..EDITS {
            for e in batch {
                black_box(obj.apply(e).expect("the bench's edits fit their objects"));
            }
        }
        start.elapsed().as_secs_f64()
    };
    for obj in &mut objs {
        block(obj);
    }
    let mut ratios: Vec<f64> = (0..ROUNDS)
        .map(|_| {
            let [off, on] = &mut objs;
            let off = block(off);
            block(on) / off
        })
        .collect();
    ratios.sort_by(f64::total_cmp);
    println!(
        "map on / map off, paired: median {:.2}× over {ROUNDS} rounds of {EDITS} edits \
         (quartiles {:.2}–{:.2}×, range {:.2}–{:.2}×)",
        ratios[ROUNDS / 2],
        ratios[ROUNDS / 4],
        ratios[3 * ROUNDS / 4],
        ratios[0],
        ratios[ROUNDS - 1]
    );
}

fn structural_summary() {
    println!("\n| structural edit (100 × 100 surface, 512² samples) | µs |");
    println!("|---|---:|");
    for (name, _) in structural() {
        match mean_ns("edit", name) {
            Some(ns) => println!("| {name} | {:.1} |", ns / 1e3),
            None => println!("| {name} | not measured |"),
        }
    }
}

fn main() {
    let mut c = Criterion::default().configure_from_args();
    bench(&mut c);
    erbs_structure(&mut c);
    c.final_summary();
    // `cargo test` runs benches once as smoke tests; only `cargo bench` (which passes --bench)
    // leaves fresh estimates to summarise.
    if std::env::args().any(|a| a == "--bench") {
        summary();
        analysis_summary();
        structural_summary();
        erbs_summary();
    }
}
