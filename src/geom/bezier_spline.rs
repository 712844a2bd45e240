//! Bézier splines: segments joined with C0/C1/C2 continuity on intervals of unequal length, and
//! the Catmull–Rom interpolating spline (lecture 3.2).

use super::bezier::BezierCurve;
use super::bspline::BSplineCurve;
use super::error::{GeomError, GeomResult};
use super::knots::KnotVector;
use glam::DVec3;

/// Parametric continuity order of a join.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Continuity {
    C0,
    C1,
    C2,
}

/// The first control points Q_0 … Q_k (k = 0, 1, 2 for C0, C1, C2) of a degree-`degree`
/// segment on an interval of length Δ1 that follows `prev` (degree n, length Δ0) with the given
/// continuity. From matching derivatives at the join:
/// Q_0 = P_n;
/// Q_1 = Q_0 + (n Δ1)/(m Δ0) (P_n − P_{n−1});
/// Q_2 = 2Q_1 − Q_0 + (n(n−1) Δ1²)/(m(m−1) Δ0²) (P_n − 2P_{n−1} + P_{n−2}).
/// For equal degrees this is the lecture's Q_2 = Q_1 + (Δ1/Δ0)(Q_1 − (P_{n−1} + (Δ1/Δ0)(P_{n−1} − P_{n−2}))).
pub fn join_points(
    prev: &BezierCurve,
    degree: usize,
    next_len: f64,
    c: Continuity,
) -> GeomResult<Vec<DVec3>> {
    let p = prev.points();
    let n = prev.degree();
    let k = c as usize;
    if prev.is_rational() {
        return Err(GeomError::new(
            "points",
            "continuity joins are defined here for polynomial segments",
        ));
    }
    if n < k || degree < k.max(1) {
        return Err(GeomError::new(
            "degree",
            format!("C{k} joins need degree ≥ {k} on both sides"),
        ));
    }
    if !(next_len.is_finite() && next_len > 0.0) {
        return Err(GeomError::new(
            "interval",
            format!("interval length {next_len} must be positive"),
        ));
    }
    let (a, b) = prev.interval();
    let r = next_len / (b - a);
    let m = degree as f64;
    let nf = n as f64;
    let mut q = vec![p[n]];
    if k >= 1 {
        q.push(q[0] + (p[n] - p[n - 1]) * (nf * r / m));
    }
    if k >= 2 {
        let second = p[n] - p[n - 1] * 2.0 + p[n - 2];
        q.push(q[1] * 2.0 - q[0] + second * (nf * (nf - 1.0) * r * r / (m * (m - 1.0))));
    }
    Ok(q)
}

/// Builds the segment that follows `prev` on [b, b + next_len]: the first control points from
/// [`join_points`], the remaining ones from `free`.
pub fn extend(
    prev: &BezierCurve,
    next_len: f64,
    c: Continuity,
    free: &[DVec3],
) -> GeomResult<BezierCurve> {
    let k = c as usize;
    let degree = k + free.len();
    let mut pts = join_points(prev, degree, next_len, c)?;
    pts.extend_from_slice(free);
    let (_, b) = prev.interval();
    BezierCurve::new(pts)?.with_interval(b, b + next_len)
}

/// Catmull–Rom spline through `points` at parameters `params` (uniform 0, 1, 2, … if `None`):
/// cubic Bézier segments with tangents m_j = (P_{j+1} − P_{j−1})/(t_{j+1} − t_{j−1}) inside,
/// m_0 = ½(P_1 − P_0)/Δ_0 and m_last likewise at the ends (the lecture's end tangents), and
/// inner points C_1 = P_j + Δ_j m_j / 3, C_2 = P_{j+1} − Δ_j m_{j+1} / 3. The result is C1.
pub fn catmull_rom(points: &[DVec3], params: Option<&[f64]>) -> GeomResult<Vec<BezierCurve>> {
    let k = points.len();
    if k < 2 {
        return Err(GeomError::new(
            "points",
            "a Catmull–Rom spline needs at least 2 points",
        ));
    }
    let t: Vec<f64> = match params {
        Some(p) if p.len() == k => p.to_vec(),
        Some(p) => {
            return Err(GeomError::new(
                "params",
                format!("{} parameters for {k} points", p.len()),
            ));
        }
        None => (0..k).map(|j| j as f64).collect(),
    };
    KnotVector::new(t.clone())?;
    if t.windows(2).any(|w| w[1] <= w[0]) {
        return Err(GeomError::new(
            "params",
            "parameters must be strictly increasing",
        ));
    }
    let tangent = |j: usize| -> DVec3 {
        if j == 0 {
            (points[1] - points[0]) * (0.5 / (t[1] - t[0]))
        } else if j == k - 1 {
            (points[k - 1] - points[k - 2]) * (0.5 / (t[k - 1] - t[k - 2]))
        } else {
            (points[j + 1] - points[j - 1]) / (t[j + 1] - t[j - 1])
        }
    };
    (0..k - 1)
        .map(|j| {
            let d = t[j + 1] - t[j];
            let pts = vec![
                points[j],
                points[j] + tangent(j) * (d / 3.0),
                points[j + 1] - tangent(j + 1) * (d / 3.0),
                points[j + 1],
            ];
            BezierCurve::new(pts)?.with_interval(t[j], t[j + 1])
        })
        .collect()
}

/// A C0 chain of polynomial Bézier segments of equal degree as one B-spline (interior
/// breakpoints with multiplicity = degree), so it can be pre-evaluated like any B-spline.
pub fn to_bspline(segments: &[BezierCurve]) -> GeomResult<BSplineCurve> {
    let first = segments
        .first()
        .ok_or_else(|| GeomError::new("segments", "no segments"))?;
    let d = first.degree();
    let mut knots = vec![first.interval().0; d + 1];
    let mut pts = vec![first.points()[0]];
    for (s, seg) in segments.iter().enumerate() {
        if seg.degree() != d || seg.is_rational() {
            return Err(GeomError::new(
                "segments",
                format!("segment {s} is not polynomial of degree {d}"),
            ));
        }
        if s > 0 {
            let prev = &segments[s - 1];
            if prev.interval().1 != seg.interval().0 || prev.points()[d] != seg.points()[0] {
                return Err(GeomError::new(
                    "segments",
                    format!("segment {s} does not continue segment {}", s - 1),
                ));
            }
            knots.extend(std::iter::repeat_n(seg.interval().0, d));
        }
        pts.extend_from_slice(&seg.points()[1..]);
    }
    knots.extend(std::iter::repeat_n(
        segments[segments.len() - 1].interval().1,
        d + 1,
    ));
    BSplineCurve::new(d, knots, pts, None)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seg() -> BezierCurve {
        BezierCurve::new(vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 2.0, 0.0),
            DVec3::new(3.0, 2.5, 1.0),
            DVec3::new(4.0, 0.0, 0.5),
        ])
        .unwrap()
        .with_interval(0.0, 2.0)
        .unwrap()
    }

    #[test]
    fn joins_match_derivatives_with_unequal_intervals() {
        let prev = seg();
        for c in [Continuity::C0, Continuity::C1, Continuity::C2] {
            let next = extend(&prev, 0.7, c, &[DVec3::new(5.0, -1.0, 0.0); 2]).unwrap();
            let a = prev.derivatives(2.0, 2);
            let b = next.derivatives(2.0, 2);
            for r in 0..=(c as usize) {
                assert!(
                    (a[r] - b[r]).length() < 1e-12 * (1.0 + a[r].length()),
                    "{c:?} r={r}"
                );
            }
            if c < Continuity::C2 {
                assert!(
                    (a[2] - b[2]).length() > 1e-3,
                    "{c:?} should not be C2 by accident"
                );
            }
        }
    }

    #[test]
    fn lecture_c2_formula_agrees_for_equal_degrees() {
        let prev = seg();
        let q = join_points(&prev, 3, 0.7, Continuity::C2).unwrap();
        let p = prev.points();
        let r = 0.7 / 2.0;
        let lecture = q[1] + (q[1] - (p[2] + (p[2] - p[1]) * r)) * r;
        assert!((q[2] - lecture).length() < 1e-13);
    }

    #[test]
    fn catmull_rom_interpolates_and_is_c1() {
        let pts: Vec<DVec3> = (0..6)
            .map(|i| DVec3::new(i as f64, ((i * i) % 5) as f64, 0.0))
            .collect();
        for params in [None, Some(&[0.0, 0.5, 2.0, 2.2, 4.0, 5.0][..])] {
            let segs = catmull_rom(&pts, params).unwrap();
            for (j, s) in segs.iter().enumerate() {
                let (a, b) = s.interval();
                assert!((s.eval(a) - pts[j]).length() < 1e-14);
                assert!((s.eval(b) - pts[j + 1]).length() < 1e-14);
                if j > 0 {
                    let l = segs[j - 1].derivatives(a, 1)[1];
                    let r = s.derivatives(a, 1)[1];
                    assert!((l - r).length() < 1e-12);
                }
            }
            let bs = to_bspline(&segs).unwrap();
            for s in &segs {
                let (a, b) = s.interval();
                let t = 0.3 * a + 0.7 * b;
                assert!((bs.eval(t) - s.eval(t)).length() < 1e-13);
            }
        }
    }
}
