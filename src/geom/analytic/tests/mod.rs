//! Tests: shared helpers (each with negative controls) and the test modules.

mod arc_tests;
mod error_tests;
mod invert_tests;
mod nurbs_tests;
mod surface_tests;

use glam::DVec3;

use super::{AnalyticSurface, FaceNurbs, Frame, NurbsCurve, ParamBox};

/// SplitMix64: a tiny deterministic generator so the tests need no crates.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`.
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in `[a, b]`.
    pub fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.unit()
    }

    pub fn vec(&mut self, s: f64) -> DVec3 {
        DVec3::new(self.range(-s, s), self.range(-s, s), self.range(-s, s))
    }

    /// A random placement (location, axis and ref_direction all random).
    pub fn frame(&mut self) -> Frame {
        loop {
            let f = Frame::from_axis2_placement(
                self.vec(5.0),
                Some(self.vec(1.0)),
                Some(self.vec(1.0)),
            );
            if let Ok(f) = f {
                return f;
            }
        }
    }
}

/// NaN-aware: true only if `|a − b| ≤ tol` with everything finite.
pub fn close(a: f64, b: f64, tol: f64) -> bool {
    let e = (a - b).abs();
    e.is_finite() && e <= tol
}

/// NaN-aware vector version of [`close`].
pub fn close_vec(a: DVec3, b: DVec3, tol: f64) -> bool {
    let e = (a - b).length();
    e.is_finite() && e <= tol
}

/// The largest error, NaN if any is NaN (`f64::max` would drop NaNs).
pub fn worst(errs: impl IntoIterator<Item = f64>) -> f64 {
    errs.into_iter().fold(0.0, |m, e| {
        if e.is_nan() || m.is_nan() {
            f64::NAN
        } else {
            m.max(e)
        }
    })
}

/// True only if `err` is a finite number `≤ tol`.
pub fn ok_err(err: f64, tol: f64) -> bool {
    err.is_finite() && err <= tol
}

/// Analytic `(u, v)` samples: the box corners, edge midpoints and random.
pub fn box_samples(rng: &mut Rng, r: &ParamBox, n: usize) -> Vec<[f64; 2]> {
    let [u0, u1] = r.u;
    let [v0, v1] = r.v;
    let mut out = vec![
        [u0, v0],
        [u0, v1],
        [u1, v0],
        [u1, v1],
        [0.5 * (u0 + u1), v0],
        [u0, 0.5 * (v0 + v1)],
    ];
    out.extend((0..n).map(|_| [rng.range(u0, u1), rng.range(v0, v1)]));
    out
}

/// The scale of a surface for relative tolerances: its extent, or the size of
/// its coordinates if larger (a tiny patch far from the origin cannot be
/// computed more accurately than its coordinates' ulps).
pub fn scale(s: &super::NurbsSurface) -> f64 {
    let far = s
        .points
        .iter()
        .fold(0.0, |m: f64, p| m.max(p.abs().max_element()));
    s.extent().max(far)
}

/// Worst `|NURBS(map(u, v)) − S(u, v)|` over the samples, relative to
/// [`scale`]. NaN if anything fails to evaluate.
pub fn surface_deviation(face: &FaceNurbs, s: &AnalyticSurface, samples: &[[f64; 2]]) -> f64 {
    let size = scale(&face.surface);
    worst(samples.iter().map(|&[u, v]| {
        let [a, b] = face.map.to_nurbs([u, v]);
        match (face.surface.point(a, b), s.point(u, v)) {
            (Ok(p), Ok(q)) => (p - q).length() / size,
            _ => f64::NAN,
        }
    }))
}

/// Copies of `face` with the middle control point, then the middle weight,
/// perturbed by `eps` (relative): the negative controls of the exactness test.
pub fn perturbed(face: &FaceNurbs, eps: f64) -> [FaceNurbs; 2] {
    let mid = face.surface.points.len() / 2;
    let size = face.surface.extent();
    let mut a = face.clone();
    if let Some(p) = a.surface.points.get_mut(mid) {
        *p += DVec3::splat(eps * size);
    }
    let mut b = face.clone();
    if let Some(w) = b.surface.weights.get_mut(mid) {
        *w *= 1.0 + eps;
    }
    [a, b]
}

/// A non-uniform rational cubic B-spline profile in the XZ half-plane x > 0.
pub fn bspline_profile() -> NurbsCurve {
    NurbsCurve {
        degree: 3,
        knots: vec![0.0, 0.0, 0.0, 0.0, 0.7, 1.1, 2.5, 3.0, 3.0, 3.0, 3.0],
        points: vec![
            DVec3::new(1.0, 0.0, -1.0),
            DVec3::new(2.0, 0.3, -0.5),
            DVec3::new(1.5, -0.2, 0.4),
            DVec3::new(2.5, 0.1, 1.0),
            DVec3::new(1.2, 0.0, 1.8),
            DVec3::new(0.8, 0.4, 2.6),
            DVec3::new(1.7, 0.0, 3.2),
        ],
        weights: vec![1.0, 0.8, 1.3, 1.0, 0.6, 1.1, 1.0],
    }
}

#[test]
fn helpers_reject_nan_and_out_of_tolerance() {
    assert!(close(1.0, 1.0 + 1e-13, 1e-12));
    assert!(!close(1.0, 1.0 + 1e-11, 1e-12));
    assert!(!close(f64::NAN, f64::NAN, 1.0));
    assert!(!close(1.0, f64::INFINITY, 1e300));
    assert!(close_vec(DVec3::ONE, DVec3::ONE, 0.0));
    assert!(!close_vec(DVec3::ONE, DVec3::new(1.0, f64::NAN, 1.0), 1.0));
    assert!(!close_vec(DVec3::ONE, DVec3::new(1.0, 1.1, 1.0), 0.05));
    assert!(worst([1.0, f64::NAN, 0.5]).is_nan());
    assert!(worst([f64::NAN]).is_nan());
    assert!(close(worst([1.0, 3.0, 2.0]), 3.0, 0.0));
    assert!(!ok_err(f64::NAN, 1.0));
    assert!(!ok_err(2.0, 1.0));
    assert!(ok_err(1.0, 1.0));
}

#[test]
fn deviation_helper_flags_nan_and_perturbation() {
    let s = AnalyticSurface::cylinder(Frame::default(), 2.0).unwrap();
    let r = ParamBox {
        u: [0.0, 3.0],
        v: [-1.0, 1.0],
    };
    let face = s.to_nurbs(&r).unwrap();
    let mut rng = Rng::new(1);
    let samples = box_samples(&mut rng, &r, 50);
    assert!(ok_err(surface_deviation(&face, &s, &samples), 1e-14));
    let mut bad = face.clone();
    bad.surface.points[0].x = f64::NAN;
    assert!(surface_deviation(&bad, &s, &samples).is_nan());
    for p in perturbed(&face, 1e-6) {
        assert!(!ok_err(surface_deviation(&p, &s, &samples), 1e-12));
    }
}
