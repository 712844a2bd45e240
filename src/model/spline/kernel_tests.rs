//! The shading fast paths of the B-spline samplers against their generic code.
// The fast paths against the generic code: `Square(1)` grids (which hold S, Su, Sv among
//! other partials) and curve orders above 1 never take them.
use crate::geom::point::{Point, nan_max};
use crate::geom::surface::regular_normal;
use crate::geom::{BSplineCurve, TensorSurface};
use crate::model::SplineCurveSampler;
use crate::model::SplineSurfaceSampler;
use crate::model::{CurveEdit, CurveModel, PointEdit, SplineForm, SurfaceEdit, SurfaceModel};
use crate::sampling::grid::PartialSet;
use crate::sampling::kernels::testing::{Rng, difference};
use crate::sampling::{DirtyRegion, Sampler};

/// Clamped knots on [0, 1] with random interior knots, some repeated (up to the degree).
#[must_use]
fn knots(rng: &mut Rng, d: usize, n: usize) -> Vec<f64> {
    let mut interior: Vec<f64> = (0..n - d - 1).map(|_| rng.range(0.05, 0.95)).collect();
    interior.sort_by(f64::total_cmp);
    for i in 1..interior.len() {
        let mult = interior[..i]
            .iter()
            .filter(|&&t| t == interior[i - 1])
            .count();
        if mult < d && rng.below(4) == 0 {
            interior[i] = interior[i - 1];
        }
    }
    let mut k = vec![0.0; d + 1];
    k.extend(interior);
    k.extend(std::iter::repeat_n(1.0, d + 1));
    k
}

#[must_use]
fn surface(rng: &mut Rng, degree: [usize; 2], rational: bool) -> TensorSurface {
    let count = [degree[0] + 1 + rng.below(6), degree[1] + 1 + rng.below(6)];
    let n = count[0] * count[1];
    let pts = (0..n).map(|_| rng.vec(10.0)).collect();
    let weights = rational.then(|| (0..n).map(|_| rng.range(0.3, 3.0)).collect());
    let kn = [
        knots(rng, degree[0], count[0]),
        knots(rng, degree[1], count[1]),
    ];
    TensorSurface::bspline(degree, kn, count, pts, weights).unwrap()
}

#[test]
fn surface_shading_matches_the_generic_path() {
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    let mut worst = 0.0f64;
    for du in 0..=5 {
        for dv in 0..=5 {
            for rational in [false, true] {
                let s = surface(&mut rng, [du, dv], rational);
                let samples = [2 + rng.below(30), 2 + rng.below(30)];
                let m = SurfaceModel::new(SplineForm::BSpline, s, samples).unwrap();
                let mut fast = SplineSurfaceSampler::new(m.clone(), PartialSet::Shading, true);
                let mut generic = SplineSurfaceSampler::new(m, PartialSet::Square(1), true);
                worst = nan_max(worst, difference(fast.grid(), generic.grid()));
                let [nu, nv] = fast.model().surface().count();
                for _ in 0..20 {
                    let point = [rng.below(nu), rng.below(nv)];
                    let edit = if rational && rng.below(3) == 0 {
                        let weight = rng.range(0.3, 3.0);
                        SurfaceEdit::Point(PointEdit::Weight { point, weight })
                    } else {
                        let delta = rng.vec(1.0);
                        SurfaceEdit::Point(PointEdit::Move { point, delta })
                    };
                    assert_eq!(fast.apply(&edit), generic.apply(&edit));
                    worst = nan_max(worst, difference(fast.grid(), generic.grid()));
                }
                let i0 = rng.below(samples[0]);
                let j0 = rng.below(samples[1]);
                let rows = i0..i0 + 1 + rng.below(samples[0] - i0);
                let cols = j0..j0 + 1 + rng.below(samples[1] - j0);
                fast.rebuild(DirtyRegion::surface(rows.clone(), cols.clone()));
                generic.rebuild(DirtyRegion::surface(rows, cols));
                let d = difference(fast.grid(), generic.grid());
                assert!(d < 1e-13, "degree ({du}, {dv}) rational {rational}: {d:e}");
                worst = nan_max(worst, d);
            }
        }
    }
    assert!(worst < 1e-13, "worst {worst:e}");
}

#[test]
fn degenerate_normals_take_the_model_fallback() {
    // Row 0 of the control net collapsed to a point: Sv = 0 along u = 0, so the normals
    // there come from the model's one-sided limit, not from Su × Sv.
    let mut rng = Rng(7);
    for degree in [[1, 1], [2, 3], [3, 3], [3, 2]] {
        let mut s = surface(&mut rng, degree, false);
        let nv = s.count()[1];
        let apex = s.point(0, 0);
        for l in 1..nv {
            s.translate_point(0, l, apex - s.point(0, l));
        }
        let m = SurfaceModel::new(SplineForm::BSpline, s, [9, 13]).unwrap();
        let fast = SplineSurfaceSampler::new(m.clone(), PartialSet::Shading, true);
        let generic = SplineSurfaceSampler::new(m, PartialSet::Square(1), true);
        let g = fast.grid();
        assert!(
            (0..13).all(|j| regular_normal(g.sample(0, j)[1], g.sample(0, j)[2]).is_none()),
            "the edge u = 0 is degenerate"
        );
        assert!(difference(g, generic.grid()) < 1e-13);
    }
}

#[test]
fn curve_fast_path_matches_the_generic_path() {
    let mut rng = Rng(0xdead_beef);
    for d in 0..=5 {
        for rational in [false, true] {
            let n = d + 1 + rng.below(20);
            let pts = (0..n).map(|_| rng.vec(10.0)).collect();
            let weights = rational.then(|| (0..n).map(|_| rng.range(0.3, 3.0)).collect());
            let c = BSplineCurve::new(d, knots(&mut rng, d, n), pts, weights).unwrap();
            let m = 2 + rng.below(200);
            let model = CurveModel::new(SplineForm::BSpline, c, m).unwrap();
            let mut fast = SplineCurveSampler::new(model.clone(), 1);
            let mut generic = SplineCurveSampler::new(model, 2);
            for step in 0..=20 {
                if step > 0 {
                    let (point, delta) = (rng.below(n), rng.vec(1.0));
                    let edit = CurveEdit::Point(PointEdit::Move { point, delta });
                    assert_eq!(fast.apply(&edit), generic.apply(&edit));
                }
                if step == 20 {
                    let a = rng.below(m);
                    let r = a..a + 1 + rng.below(m - a);
                    fast.rebuild(DirtyRegion::curve(r.clone()));
                    generic.rebuild(DirtyRegion::curve(r));
                }
                let (f, g) = (&fast.grid().data, &generic.grid().data);
                for j in 0..m {
                    for r in 0..2 {
                        let (x, y) = (f[j * 2 + r], g[j * 3 + r]);
                        let scale = nan_max(x.max_abs(), y.max_abs()).max(1.0);
                        let e = (x - y).max_abs() / scale;
                        assert!(e < 1e-13, "degree {d} rational {rational}: {e:e}");
                    }
                }
            }
        }
    }
}
