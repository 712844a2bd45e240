//! Knot insertion and degree elevation as edits: on random curves and surfaces (rational
//! included, clamped and unclamped, Bézier and B-spline) the shape and all its derivatives stay
//! the same, multiplicities and control counts come out as the algorithms promise, the inverse
//! restores the model bit for bit, and the delta path through structural and point edits equals
//! full re-sampling.

use glam::DVec3;
use prespline::geom::{BSplineCurve, KnotVector, TensorSurface};
use prespline::model::SampledObject;
use prespline::model::{
    CurveEdit, CurveModel, KindEdit, Model, ObjectEdit, PointEdit, SplineForm, SurfaceEdit,
    SurfaceModel,
};
use prespline::sampling::{SampleGrid, SampleMode};

struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.unit()
    }
    fn vec(&mut self, r: f64) -> DVec3 {
        DVec3::new(self.range(-r, r), self.range(-r, r), self.range(-r, r))
    }
}

/// Random knots for `n` points of degree `d`: clamped or not, with repeated interior knots.
fn knots(rng: &mut Rng, d: usize, n: usize) -> Vec<f64> {
    loop {
        let mut k: Vec<f64> = (0..n + d + 1).map(|_| rng.range(0.0, 4.0)).collect();
        k.sort_by(f64::total_cmp);
        // Repeat some knots (multiplicity up to d), then clamp half of the vectors.
        for i in 1..k.len() {
            if rng.below(5) == 0 {
                k[i] = k[i - 1];
            }
        }
        if rng.below(2) == 0 {
            let (a, b) = (k[d], k[n]);
            k[..=d].fill(a);
            k[n..].fill(b);
        }
        if KnotVector::for_bspline(k.clone(), d, n).is_ok() && k[d] < k[n] {
            // Keep interior multiplicities at most d so insertion has room.
            let ok = (d + 1..n).all(|i| k[i..].iter().take_while(|&&x| x == k[i]).count() <= d);
            if ok {
                return k;
            }
        }
    }
}

fn random_curve(rng: &mut Rng) -> CurveModel {
    let d = 1 + rng.below(5);
    let n = d + 1 + rng.below(8);
    let bezier = rng.below(4) == 0;
    let (n, k) = if bezier {
        (d + 1, KnotVector::bezier(d, 0.0, 1.0).into_vec())
    } else {
        (n, knots(rng, d, n))
    };
    let pts = (0..n).map(|_| rng.vec(3.0)).collect();
    let w = (rng.below(2) == 0).then(|| (0..n).map(|_| rng.range(0.4, 2.5)).collect());
    let c = BSplineCurve::new(d, k, pts, w).unwrap();
    let form = if bezier {
        SplineForm::Bezier
    } else {
        SplineForm::BSpline
    };
    CurveModel::new(form, c, 60 + rng.below(100)).unwrap()
}

fn random_surface(rng: &mut Rng) -> SurfaceModel {
    let bezier = rng.below(4) == 0;
    let d = [1 + rng.below(4), 1 + rng.below(4)];
    let mut count = [0; 2];
    let mut kn: [Vec<f64>; 2] = Default::default();
    for dir in 0..2 {
        if bezier {
            count[dir] = d[dir] + 1;
            kn[dir] = KnotVector::bezier(d[dir], 0.0, 1.0).into_vec();
        } else {
            count[dir] = d[dir] + 1 + rng.below(5);
            kn[dir] = knots(rng, d[dir], count[dir]);
        }
    }
    let n = count[0] * count[1];
    let pts = (0..n).map(|_| rng.vec(3.0)).collect();
    let w = (rng.below(2) == 0).then(|| (0..n).map(|_| rng.range(0.4, 2.5)).collect());
    let s = if bezier {
        TensorSurface::bezier(count, pts, w).unwrap()
    } else {
        TensorSurface::bspline(d, kn, count, pts, w).unwrap()
    };
    let form = if bezier {
        SplineForm::Bezier
    } else {
        SplineForm::BSpline
    };
    SurfaceModel::new(form, s, [20 + rng.below(20), 20 + rng.below(20)]).unwrap()
}

/// A valid insertion parameter strictly inside the domain with room for `times` more knots.
fn insertion(rng: &mut Rng, knots: &[f64], degree: usize, (a, b): (f64, f64)) -> (f64, usize) {
    loop {
        // Sometimes at an existing interior knot, mostly in between.
        let t = if rng.below(3) == 0 {
            knots[rng.below(knots.len())]
        } else {
            rng.range(a, b)
        };
        let m = knots.iter().filter(|&&x| x == t).count();
        if t > a && t < b && m < degree {
            return (t, 1 + rng.below(degree - m));
        }
    }
}

fn curve_insertion(rng: &mut Rng, m: &CurveModel) -> CurveEdit {
    let c = m.curve();
    let (t, times) = insertion(rng, c.knots(), c.degree(), c.domain());
    CurveEdit::InsertKnot { t, times }
}

fn surface_insertion(rng: &mut Rng, m: &SurfaceModel) -> SurfaceEdit {
    let s = m.surface();
    let dir = rng.below(2);
    let (t, times) = insertion(rng, &s.knots()[dir], s.degree()[dir], s.domain()[dir]);
    SurfaceEdit::InsertKnot { dir, t, times }
}

/// What a representation can resolve of each derivative order: on a span of length h, a
/// degree-d B-spline's r-th derivative amplifies the rounding of its control points by about
/// (d/h)^r, so the r-th derivative is judged relative to max(|its values|, |P|·(d/h)^r).
/// `conditioning[dir]` is d/h for the refined representation in each direction.
fn slot_scales(a: &SampleGrid, b: &SampleGrid, conditioning: [f64; 2]) -> Vec<f64> {
    let s = a.stride();
    let magnitude = |g: &SampleGrid, p: usize| {
        g.data
            .iter()
            .skip(p)
            .step_by(s)
            .map(|v| v.abs().max_element())
            .fold(0.0f64, f64::max)
    };
    let position = magnitude(a, 0).max(magnitude(b, 0));
    a.partials
        .list()
        .iter()
        .enumerate()
        .map(|(p, &(i, j))| {
            let floor = position * conditioning[0].powi(i as i32) * conditioning[1].powi(j as i32);
            magnitude(a, p)
                .max(magnitude(b, p))
                .max(floor)
                .max(f64::MIN_POSITIVE)
        })
        .collect()
}

/// Largest difference per slot relative to its scale ([`slot_scales`]); NaN if any value
/// differs by NaN (glam's `max_element` would drop it, so it is checked first).
fn worst_relative(a: &SampleGrid, b: &SampleGrid, conditioning: [f64; 2]) -> f64 {
    assert_eq!((a.dims, &a.partials), (b.dims, &b.partials));
    let s = a.stride();
    let scales = slot_scales(a, b, conditioning);
    let mut worst = 0.0f64;
    for (p, scale) in scales.iter().enumerate() {
        for (x, y) in a.data.iter().zip(&b.data).skip(p).step_by(s) {
            let d = (*x - *y).abs();
            if d.is_nan() {
                return f64::NAN;
            }
            worst = worst.max(d.max_element() / scale);
        }
    }
    worst
}

/// d/h of a knot vector: degree over the shortest non-empty span inside the domain.
fn conditioning(knots: &[f64], degree: usize, (a, b): (f64, f64)) -> f64 {
    let h = knots
        .windows(2)
        .filter(|w| w[0] >= a && w[1] <= b && w[1] > w[0])
        .map(|w| w[1] - w[0])
        .fold(f64::INFINITY, f64::min);
    degree.max(1) as f64 / h
}

fn curve_conditioning(m: &CurveModel) -> [f64; 2] {
    let c = m.curve();
    [conditioning(c.knots(), c.degree(), c.domain()), 1.0]
}

fn surface_conditioning(m: &SurfaceModel) -> [f64; 2] {
    let s = m.surface();
    [0, 1].map(|d| conditioning(&s.knots()[d], s.degree()[d], s.domain()[d]))
}

#[test]
fn comparison_catches_nan_and_perturbation() {
    let mut rng = Rng(5);
    let m = Model::Curve(random_curve(&mut rng));
    let a = SampledObject::new(&m, SampleMode::Derivatives(2));
    let mut b = a.grid().clone();
    let k = [1.0, 1.0];
    assert_eq!(worst_relative(a.grid(), &b, k), 0.0);
    b.data[7].y *= 1.0 + 1e-9;
    assert!(worst_relative(a.grid(), &b, k) > 1e-12);
    b.data[7].y = f64::NAN;
    assert!(worst_relative(a.grid(), &b, k).is_nan());
}

/// The claim of docs/testing.md and the issue: sampling after a refinement equals sampling before
/// it to about 1e-13, positions and derivatives.
const SHAPE_TOLERANCE: f64 = 1e-13;

#[test]
fn curve_refinement_keeps_shape_and_counts() {
    let mut rng = Rng(0x1234_5678_9abc);
    let mut worst = 0.0f64;
    for case in 0..300 {
        let m = random_curve(&mut rng);
        let before = SampledObject::new(&Model::Curve(m.clone()), SampleMode::Derivatives(3));
        let c = m.curve();
        let edit = if case % 2 == 0 {
            curve_insertion(&mut rng, &m)
        } else {
            CurveEdit::ElevateDegree {
                by: 1 + rng.below(2),
            }
        };
        edit.validate(&m).unwrap();
        let mut after = m.clone();
        edit.apply(&mut after);
        let r = after.curve();
        match edit {
            CurveEdit::InsertKnot { t, times } => {
                assert_eq!(r.points().len(), c.points().len() + times);
                assert_eq!(r.knots().multiplicity(t), c.knots().multiplicity(t) + times);
                assert_eq!(after.form(), SplineForm::BSpline);
            }
            CurveEdit::ElevateDegree { by } => {
                assert_eq!(r.degree(), c.degree() + by);
                let (a, b) = c.domain();
                assert_eq!(r.domain(), (a, b));
                // Every distinct knot inside the domain keeps its continuity: multiplicity + by.
                for x in c.knots().breakpoints(a, b) {
                    let expect = if x == a || x == b {
                        r.degree() + 1
                    } else {
                        c.knots().multiplicity(x) + by
                    };
                    assert_eq!(r.knots().multiplicity(x), expect, "case {case} knot {x}");
                }
                assert_eq!(after.form(), m.form());
            }
            _ => unreachable!(),
        }
        assert_eq!(r.is_rational(), c.is_rational());
        let refined = SampledObject::new(&Model::Curve(after.clone()), SampleMode::Derivatives(3));
        let e = worst_relative(before.grid(), refined.grid(), curve_conditioning(&after));
        assert!(e <= SHAPE_TOLERANCE, "case {case} {edit:?}: {e:e}");
        worst = worst.max(e);
        // The inverse puts the model back bit for bit.
        let inverse = edit.inverse(&m);
        inverse.apply(&mut after);
        assert_eq!(after, m, "case {case}");
    }
    eprintln!("curves: largest relative change after refinement {worst:.2e}");
}

#[test]
fn surface_refinement_keeps_shape_and_counts() {
    let mut rng = Rng(0xfeed_beef_1234);
    let mut worst = 0.0f64;
    for case in 0..120 {
        let m = random_surface(&mut rng);
        let before = SampledObject::new(&Model::Surface(m.clone()), SampleMode::Derivatives(2));
        let s = m.surface();
        let edit = if case % 2 == 0 {
            surface_insertion(&mut rng, &m)
        } else {
            let mut by = [rng.below(2), rng.below(2)];
            by[rng.below(2)] += 1;
            SurfaceEdit::ElevateDegree { by }
        };
        edit.validate(&m).unwrap();
        let mut after = m.clone();
        edit.apply(&mut after);
        let r = after.surface();
        match edit {
            SurfaceEdit::InsertKnot { dir, t, times } => {
                let mut count = s.count();
                count[dir] += times;
                assert_eq!(r.count(), count);
                assert_eq!(
                    r.knots()[dir].multiplicity(t),
                    s.knots()[dir].multiplicity(t) + times
                );
                assert_eq!(
                    r.knots()[1 - dir],
                    s.knots()[1 - dir],
                    "the other direction stays"
                );
            }
            SurfaceEdit::ElevateDegree { by } => {
                assert_eq!(r.degree(), [s.degree()[0] + by[0], s.degree()[1] + by[1]]);
                for (dir, _) in by.iter().enumerate().filter(|(_, b)| **b == 0) {
                    assert_eq!(r.knots()[dir], s.knots()[dir]);
                }
            }
            _ => unreachable!(),
        }
        let refined =
            SampledObject::new(&Model::Surface(after.clone()), SampleMode::Derivatives(2));
        let e = worst_relative(before.grid(), refined.grid(), surface_conditioning(&after));
        assert!(e <= SHAPE_TOLERANCE, "case {case} {edit:?}: {e:e}");
        worst = worst.max(e);
        edit.inverse(&m).apply(&mut after);
        assert_eq!(after, m, "case {case}");
    }
    eprintln!("surfaces: largest relative change after refinement {worst:.2e}");
}

/// Structural and point edits mixed, through the delta path, against full re-sampling of the
/// final model; later point edits address the refined net.
#[test]
fn delta_path_through_refinements_equals_full() {
    let mut rng = Rng(0x0dd_ba11);
    let mut worst = 0.0f64;
    for case in 0..60 {
        let surface = case % 2 == 1;
        let model = if surface {
            Model::Surface(random_surface(&mut rng))
        } else {
            Model::Curve(random_curve(&mut rng))
        };
        for mode in [SampleMode::Derivatives(2), SampleMode::Render] {
            let mut obj = SampledObject::new(&model, mode);
            let mut reference = model.clone();
            for _ in 0..80 {
                let edit: ObjectEdit = match &reference {
                    Model::Curve(m) => {
                        let n = m.curve().points().len();
                        match rng.below(10) {
                            0 => curve_insertion(&mut rng, m).into_object(),
                            1 if m.curve().degree() < 6 => {
                                CurveEdit::ElevateDegree { by: 1 }.into_object()
                            }
                            _ => CurveEdit::Point(PointEdit::Move {
                                point: rng.below(n),
                                delta: rng.vec(0.5),
                            })
                            .into_object(),
                        }
                    }
                    Model::Surface(m) => {
                        let [nu, nv] = m.surface().count();
                        match rng.below(12) {
                            0 if nu * nv < 150 => surface_insertion(&mut rng, m).into_object(),
                            1 if m.surface().degree().iter().all(|&d| d < 5) => {
                                SurfaceEdit::ElevateDegree { by: [0, 1] }.into_object()
                            }
                            _ => SurfaceEdit::Point(PointEdit::Move {
                                point: [rng.below(nu), rng.below(nv)],
                                delta: rng.vec(0.5),
                            })
                            .into_object(),
                        }
                    }
                    _ => unreachable!(),
                };
                obj.apply(&edit).unwrap();
                reference.apply(&edit).unwrap();
            }
            assert_eq!(
                obj.model().to_model(),
                reference,
                "case {case}: models agree"
            );
            let fresh = SampledObject::new(&reference, mode);
            let k = match &reference {
                Model::Curve(m) => curve_conditioning(m),
                Model::Surface(m) => surface_conditioning(m),
                _ => unreachable!(),
            };
            let e = worst_relative(fresh.grid(), obj.grid(), k);
            assert!(e <= SHAPE_TOLERANCE, "case {case} {mode:?}: {e:e}");
            worst = worst.max(e);
        }
    }
    eprintln!("delta through refinements: largest relative difference {worst:.2e}");
}
