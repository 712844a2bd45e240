//! Issue 23: one large surface's full pass and exact rebuilds split into row blocks on several
//! threads give the same bits as one thread — B-spline (the fast shading kernel and the generic
//! two-pass path), rational (homogeneous pass and quotient rule) and ERBS.

use glam::DVec3;
use prespline::geom::{BFunctionKind, ErbsSurface, KnotVector, TensorSurface};
use prespline::model::{
    ErbsSurfaceModel, KindEdit, Model, PointEdit, SampledObject, SplineForm, SurfaceEdit,
    SurfaceModel,
};
use prespline::parallel;
use prespline::sampling::SampleMode;

/// Odd sample counts, so the last row block is shorter than the others and not a multiple of
/// the kernels' row groups.
const SAMPLES: [usize; 2] = [259, 253];

fn bspline(weights: bool) -> Model {
    let n = 40;
    let pts = (0..n * n)
        .map(|k| {
            let (i, j) = ((k / n) as f64, (k % n) as f64);
            DVec3::new(i, j, (0.3 * i).sin() * (0.2 * j).cos())
        })
        .collect();
    let w = weights.then(|| {
        (0..n * n)
            .map(|k| 1.0 + 0.5 * ((k % 7) as f64) / 7.0)
            .collect()
    });
    let k = KnotVector::clamped_uniform(3, n, 0.0, 1.0).into_vec();
    let s = TensorSurface::bspline([3, 3], [k.clone(), k], [n, n], pts, w).unwrap();
    Model::Surface(SurfaceModel::new(SplineForm::BSpline, s, SAMPLES).unwrap())
}

fn erbs() -> Model {
    let n = 6;
    let knots: Vec<f64> = std::iter::once(0.0)
        .chain((0..n).map(|i| i as f64))
        .chain(std::iter::once((n - 1) as f64))
        .collect();
    let patches = (0..n * n)
        .map(|p| {
            let (k, l) = (p / n, p % n);
            let pts = (0..16)
                .map(|q| {
                    DVec3::new(
                        k as f64 + (q / 4) as f64 / 3.0,
                        l as f64 + (q % 4) as f64 / 3.0,
                        ((k * l + q) % 5) as f64 * 0.1,
                    )
                })
                .collect();
            TensorSurface::bezier([4, 4], pts, None).unwrap()
        })
        .collect();
    let e = ErbsSurface::new(
        [knots.clone(), knots],
        [n, n],
        patches,
        BFunctionKind::ExpoRational,
    )
    .unwrap();
    Model::ErbsSurface(ErbsSurfaceModel::new(e, SAMPLES).unwrap())
}

/// Every bit of the samples and normals after the constructor's full pass, and again after a
/// point edit followed by an exact rebuild of the whole grid.
fn bits(model: &Model, mode: SampleMode) -> Vec<u64> {
    let mut obj = SampledObject::new(model, mode);
    let mut out = grid_bits(&obj);
    if let Model::Surface(_) = model {
        let edit = SurfaceEdit::Point(PointEdit::Move {
            point: [17, 23],
            delta: DVec3::new(0.1, -0.2, 0.3),
        });
        obj.apply(&edit.into_object()).unwrap();
    }
    obj.rebuild_all();
    out.extend(grid_bits(&obj));
    out
}

fn grid_bits(obj: &SampledObject) -> Vec<u64> {
    let g = obj.grid();
    let normals = g.normals.iter().flatten();
    g.data
        .iter()
        .chain(normals)
        .flat_map(|v| v.to_array())
        .map(f64::to_bits)
        .collect()
}

#[test]
fn one_large_surface_on_n_threads_equals_one_thread_bit_for_bit() {
    // The grid is large enough to be split: otherwise this test compares one thread with itself.
    parallel::set_threads(3);
    let blocks = parallel::row_blocks(0..SAMPLES[0], SAMPLES[1], 4);
    parallel::set_threads(0);
    assert!(
        blocks.len() > 3,
        "{SAMPLES:?} is split into row blocks: {blocks:?}"
    );
    let cases = [
        ("B-spline", bspline(false)),
        ("rational", bspline(true)),
        ("ERBS", erbs()),
    ];
    for (name, model) in &cases {
        for mode in [SampleMode::Render, SampleMode::Analysis] {
            let one = parallel::on_one_thread(|| bits(model, mode));
            for n in [2, 3] {
                parallel::set_threads(n);
                let many = bits(model, mode);
                parallel::set_threads(0);
                assert_eq!(one.len(), many.len(), "{name} {mode:?}");
                assert!(one == many, "{name} {mode:?}: 1 and {n} threads differ");
            }
        }
    }
    // Negative control: one flipped bit, and one pair of swapped row blocks, are seen.
    let one = parallel::on_one_thread(|| bits(&cases[0].1, SampleMode::Render));
    let mut flipped = one.clone();
    flipped[one.len() / 2] ^= 1;
    assert!(one != flipped);
    let row = SAMPLES[1] * 9;
    let mut swapped = one.clone();
    let (a, b) = swapped.split_at_mut(row * 8);
    a[..row * 8].swap_with_slice(&mut b[..row * 8]);
    assert!(one != swapped);
}
