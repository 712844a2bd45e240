//! Arc segment rule, the closed-form angle ↔ parameter maps, and the exact
//! circle/ellipse/line curves.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use glam::DVec3;

use super::super::{ArcMap, Frame, circle_arc, ellipse_arc, line_segment};
use super::{Rng, close, close_vec, ok_err, worst};

/// Ranges covering small/large sweeps, offsets and reversed arcs.
fn ranges(rng: &mut Rng) -> Vec<(f64, f64)> {
    let mut r = vec![
        (0.0, TAU),
        (-PI, PI),
        (0.3, 0.3 + 1e-6),
        (1.0, 1.0 + FRAC_PI_2),
        (2.0, -1.0),
        (7.0, 7.0 - TAU),
    ];
    for _ in 0..40 {
        let a = rng.range(-10.0, 10.0);
        let sweep = rng.range(-TAU, TAU);
        r.push((a, a + sweep));
    }
    r
}

#[test]
fn segment_count_rule() {
    let n = |a: f64, b: f64| ArcMap::new(a, b).unwrap().segments();
    assert_eq!(n(0.0, FRAC_PI_2), 1);
    assert_eq!(n(0.0, FRAC_PI_2 * (1.0 + 1e-9)), 2);
    assert_eq!(n(0.0, PI), 2);
    assert_eq!(n(0.0, 1.5 * PI), 3);
    assert_eq!(n(0.0, TAU), 4);
    assert_eq!(n(1.0, 1.0 + 1e-9), 1);
    assert_eq!(n(0.0, -TAU), 4);
    // Negative control: the rule is not "one segment per 120°".
    assert_ne!(n(0.0, TAU), 3);
}

#[test]
fn knots_sit_at_segment_angles() {
    let mut rng = Rng::new(7);
    for (a, b) in ranges(&mut rng) {
        let m = ArcMap::new(a, b).unwrap();
        let n = m.segments();
        for (k, &t) in m.breakpoints().iter().enumerate() {
            let angle = a + (b - a) * k as f64 / n as f64;
            assert!(
                close(m.sign() * t, angle, 1e-14 * (1.0 + angle.abs())),
                "{a} {b} {k}"
            );
            // Exact (not approximately) consistent at the knots.
            assert_eq!(m.param_to_angle(t), m.sign() * t);
            assert_eq!(m.angle_to_param(m.sign() * t), t);
        }
        let kv = m.knot_vector();
        assert_eq!(kv.len(), 2 * n + 4);
        assert!(kv.windows(2).all(|w| w[0] <= w[1]));
        assert_eq!(kv[0], m.domain()[0]);
        assert_eq!(kv[kv.len() - 1], m.domain()[1]);
        assert_eq!(m.param_to_angle(m.domain()[1]), b);
        assert_eq!(m.param_to_angle(m.domain()[0]), a);
    }
}

#[test]
fn round_trip_is_exact_to_1e14() {
    let mut rng = Rng::new(11);
    let mut errs = Vec::new();
    for (a, b) in ranges(&mut rng) {
        let m = ArcMap::new(a, b).unwrap();
        let [lo, hi] = m.domain();
        for _ in 0..200 {
            let t = rng.range(lo, hi);
            errs.push((m.angle_to_param(m.param_to_angle(t)) - t).abs());
            let th = m.param_to_angle(t);
            errs.push((m.param_to_angle(m.angle_to_param(th)) - th).abs());
        }
    }
    let e = worst(errs);
    assert!(ok_err(e, 1e-14), "round trip error {e:e}");
}

#[test]
fn maps_are_monotone() {
    let mut rng = Rng::new(3);
    for (a, b) in ranges(&mut rng) {
        let m = ArcMap::new(a, b).unwrap();
        let [lo, hi] = m.domain();
        let n = 4000;
        let ts: Vec<f64> = (0..=n)
            .map(|i| lo + (hi - lo) * i as f64 / n as f64)
            .collect();
        let th: Vec<f64> = ts.iter().map(|&t| m.sign() * m.param_to_angle(t)).collect();
        assert!(
            th.windows(2).all(|w| w[0] <= w[1]),
            "param_to_angle not monotone {a} {b}"
        );
        let back: Vec<f64> = th.iter().map(|&x| m.angle_to_param(m.sign() * x)).collect();
        assert!(
            back.windows(2).all(|w| w[0] <= w[1]),
            "angle_to_param not monotone {a} {b}"
        );
    }
    // Negative control: the check does catch a decreasing sequence.
    assert!(![0.0, 1.0, 0.5].windows(2).all(|w| w[0] <= w[1]));
}

#[test]
fn half_angle_formula_matches_the_curve() {
    // Verifies tan(α/2) = s sin(φ/2) / ((1−s) + s cos(φ/2)) against atan2 of
    // evaluated NURBS points, on single segments of several sweeps.
    for phi in [1e-6, 0.3, 1.0, FRAC_PI_2] {
        let (c, m) = circle_arc(&Frame::default(), 1.0, 0.0, phi).unwrap();
        assert_eq!(m.segments(), 1);
        assert!(close(c.weights[1], (0.5 * phi).cos(), 1e-16));
        let h = 0.5 * phi;
        for i in 0..=100 {
            let s = i as f64 / 100.0;
            let p = c.point(s * phi).unwrap();
            let alpha = p.y.atan2(p.x);
            let rhs = s * h.sin() / ((1.0 - s) + s * h.cos());
            assert!(close((0.5 * alpha).tan(), rhs, 1e-15), "phi {phi} s {s}");
            assert!(close(
                m.param_to_angle(s * phi),
                alpha,
                2e-16 * (1.0 + phi) + 1e-16
            ));
            assert!(close(p.length(), 1.0, 4e-16));
        }
        // Negative control: the uniform map α = sφ is wrong inside.
        let p = c.point(0.25 * phi).unwrap();
        assert!(!close(p.y.atan2(p.x), 0.25 * phi, 1e-12 * phi) || phi < 1e-3);
    }
}

#[test]
fn circle_and_ellipse_match_step_formulas() {
    let mut rng = Rng::new(5);
    let mut errs = Vec::new();
    for (a, b) in ranges(&mut rng) {
        let f = rng.frame();
        let (ra, rb) = (rng.range(0.1, 10.0), rng.range(0.1, 10.0));
        let (e, m) = ellipse_arc(&f, ra, rb, a, b).unwrap();
        let (c, mc) = circle_arc(&f, ra, a, b).unwrap();
        assert_eq!(m, mc);
        for _ in 0..50 {
            let th = a + (b - a) * rng.unit();
            let want = f.to_world(ra * th.cos(), rb * th.sin(), 0.0);
            errs.push((e.point(m.angle_to_param(th)).unwrap() - want).length() / ra.max(rb));
            let want = f.to_world(ra * th.cos(), ra * th.sin(), 0.0);
            errs.push((c.point(m.angle_to_param(th)).unwrap() - want).length() / ra);
        }
        // Negative control: moving the middle weight breaks exactness.
        let mut bad = e.clone();
        bad.weights[1] *= 1.0 + 1e-3;
        let th = m.param_to_angle(0.75 * m.breakpoints()[0] + 0.25 * m.breakpoints()[1]);
        let want = f.to_world(ra * th.cos(), rb * th.sin(), 0.0);
        let got = bad.point(m.angle_to_param(th)).unwrap();
        assert!(!close_vec(got, want, 1e-12 * ra.max(rb)));
    }
    let e = worst(errs);
    assert!(ok_err(e, 1e-14), "circle/ellipse error {e:e}");
}

#[test]
fn line_keeps_its_parameter() {
    let p = DVec3::new(1.0, 2.0, 3.0);
    let d = DVec3::new(0.5, -1.0, 2.0);
    let l = line_segment(p, d, -2.0, 3.5).unwrap();
    for t in [-2.0, -1.0, 0.0, 1.7, 3.5] {
        assert!(close_vec(l.point(t).unwrap(), p + t * d, 1e-15 * 8.0));
    }
    assert!(!close_vec(l.point(1.0).unwrap(), p + 1.1 * d, 1e-3));
}
