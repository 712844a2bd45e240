//! Bézier splines with a declared continuity (lecture 3.2): k segments of degree d over knots
//! t_0 < … < t_k (intervals h_j = t_{j+1} − t_j may differ), k·d + 1 Bézier points with each
//! junction J = j·d shared, and the edits that keep the continuity, as drawing programs do.
//!
//! How a move of one handle spreads (the lecture's conditions at junction J with
//! r = h_j / h_{j−1}):
//! - **C0**: a junction carries its two neighbours (d ≥ 2), an end point its one neighbour;
//!   any other point moves alone.
//! - **C1** (d ≥ 3): as C0, and moving the neighbour on one side of a junction puts the
//!   neighbour on the other side at its mirror: P_{J+1} = P_J + r (P_J − P_{J−1}), or
//!   P_{J−1} = P_J − (P_{J+1} − P_J)/r.
//! - **G1** (d ≥ 3): as C0, and moving the neighbour on one side turns the other neighbour to
//!   the opposite direction from P_J, keeping that neighbour's distance to P_J (each handle keeps
//!   its length, the tangent direction follows the moved one). A move that would put a
//!   neighbour onto its junction is refused (no tangent direction).
//! - **C2** (d ≥ 5): as C1 with two points on each side: a junction carries J ± 1 and J ± 2,
//!   and moving J + 1 or J + 2 re-solves J − 1, J − 2 from the C1 and C2 conditions
//!   (and the other way round).
//! - **De Boor editing** where neighbouring junctions share constrained points: C1 quadratic
//!   (the lecture's quadratic B-spline construction: the handles are the end points and the
//!   inner points, each junction the h-weighted mean of its neighbours) and C2 cubic (the A-frame
//!   construction: the handles are the k + 3 de Boor points, the Bézier points follow from the
//!   lecture's formulas). C2 of degree 4 and G1 of degree 2 are refused.

use super::bspline::BSplineCurve;
use super::catmull_rom::bezier_chain_bspline;
use super::error::{GeomError, GeomResult};
use glam::DVec3;

/// The continuity a Bézier spline declares and keeps while edited.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JoinContinuity {
    C0,
    G1,
    C1,
    C2,
}

impl JoinContinuity {
    pub const ALL: [JoinContinuity; 4] = [
        JoinContinuity::C0,
        JoinContinuity::G1,
        JoinContinuity::C1,
        JoinContinuity::C2,
    ];

    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            JoinContinuity::C0 => "C0",
            JoinContinuity::G1 => "G1",
            JoinContinuity::C1 => "C1",
            JoinContinuity::C2 => "C2",
        }
    }

    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|c| c.name() == name)
    }

    /// Points tied on each side of a junction.
    fn tied(self) -> usize {
        match self {
            JoinContinuity::C0 => 0,
            JoinContinuity::G1 | JoinContinuity::C1 => 1,
            JoinContinuity::C2 => 2,
        }
    }
}

/// What the handles of a spline are.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Handles {
    /// Every Bézier point.
    Bezier,
    /// De Boor points of the equivalent B-spline (C1 quadratic, C2 cubic).
    DeBoor,
}

/// A Bézier spline with declared continuity.
#[derive(Debug, Clone, PartialEq)]
pub struct BezierSpline {
    degree: usize,
    knots: Vec<f64>,
    points: Vec<DVec3>,
    continuity: JoinContinuity,
}

/// Relative tolerance of the continuity check of given points (files are written with every
/// bit, so a spline built by the formulas passes by ~6 orders of magnitude).
const CHECK_TOLERANCE: f64 = 1e-9;

impl BezierSpline {
    /// Validates the degree for the continuity, the knots (finite, strictly increasing, at
    /// least 2), k·d + 1 finite points, and the continuity at every junction (the error names
    /// the first junction that breaks it).
    pub fn new(
        degree: usize,
        knots: Vec<f64>,
        points: Vec<DVec3>,
        continuity: JoinContinuity,
    ) -> GeomResult<Self> {
        check_degree(degree, continuity)?;
        if knots.len() < 2 {
            return Err(GeomError::new(
                "knots",
                format!(
                    "a Bézier spline needs at least 2 knots (one segment), got {}",
                    knots.len()
                ),
            ));
        }
        for (i, &t) in knots.iter().enumerate() {
            if !t.is_finite() {
                return Err(GeomError::new(
                    "knots",
                    format!("knot {i} is {t}, not a finite number"),
                ));
            }
            if i > 0 && t <= knots[i - 1] {
                return Err(GeomError::new(
                    "knots",
                    format!(
                        "knot {i} ({t}) is not above knot {} ({}): the knots of a Bézier spline are strictly increasing",
                        i - 1,
                        knots[i - 1]
                    ),
                ));
            }
        }
        let k = knots.len() - 1;
        if points.len() != k * degree + 1 {
            return Err(GeomError::new(
                "points",
                format!(
                    "{k} segment(s) of degree {degree} need k·d + 1 = {} points, got {}",
                    k * degree + 1,
                    points.len()
                ),
            ));
        }
        if let Some(i) = points.iter().position(|p| !p.is_finite()) {
            return Err(GeomError::new(
                "points",
                format!("point {i} is not finite: {:?}", points[i].to_array()),
            ));
        }
        let s = Self {
            degree,
            knots,
            points,
            continuity,
        };
        for j in 1..k {
            if let Some(why) = s.junction_error(j) {
                return Err(GeomError::new("points", why));
            }
        }
        Ok(s)
    }

    #[must_use]
    pub fn degree(&self) -> usize {
        self.degree
    }

    #[must_use]
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }

    #[must_use]
    pub fn points(&self) -> &[DVec3] {
        &self.points
    }

    #[must_use]
    pub fn continuity(&self) -> JoinContinuity {
        self.continuity
    }

    /// Number of segments k.
    #[must_use]
    pub fn segments(&self) -> usize {
        self.knots.len() - 1
    }

    #[must_use]
    pub fn domain(&self) -> (f64, f64) {
        (self.knots[0], self.knots[self.segments()])
    }

    /// Interval length h_j; 0 outside the segments (the clamped ends of the A-frame formulas).
    fn h(&self, j: isize) -> f64 {
        if j < 0 || j >= self.segments() as isize {
            0.0
        } else {
            let j = j as usize;
            self.knots[j + 1] - self.knots[j]
        }
    }

    /// The spline as a degree-d B-spline with knots of multiplicity d at the junctions.
    #[must_use]
    pub fn to_bspline(&self) -> BSplineCurve {
        bezier_chain_bspline(self.degree, &self.knots, self.points.clone())
    }

    /// Why junction j (1 ≤ j < k) breaks the declared continuity, if it does.
    #[must_use]
    pub fn junction_error(&self, j: usize) -> Option<String> {
        let d = self.degree;
        let jj = j * d;
        let p = &self.points;
        let scale = self
            .points
            .iter()
            .fold(1.0f64, |m, q| m.max(q.abs().max_element()));
        let tol = CHECK_TOLERANCE * scale;
        let at = format!("junction {j} (t = {}, point {jj})", self.knots[j]);
        let r = self.h(j as isize) / self.h(j as isize - 1);
        match self.continuity {
            JoinContinuity::C0 => None,
            JoinContinuity::G1 => {
                let (a, b) = (p[jj] - p[jj - 1], p[jj + 1] - p[jj]);
                if a.length() <= tol || b.length() <= tol {
                    return Some(format!(
                        "{at} is declared G1 but a neighbouring point lies on the junction (no tangent direction)"
                    ));
                }
                let sin = a.cross(b).length() / (a.length() * b.length());
                if sin > CHECK_TOLERANCE || a.dot(b) <= 0.0 {
                    return Some(format!(
                        "{at} is declared G1 but points {}, {jj}, {} are not collinear in order (angle {:.3e} rad)",
                        jj - 1,
                        jj + 1,
                        a.angle_between(b)
                    ));
                }
                None
            }
            JoinContinuity::C1 | JoinContinuity::C2 => {
                let expect = p[jj] + (p[jj] - p[jj - 1]) * r;
                let off = (p[jj + 1] - expect).length();
                if off > tol {
                    return Some(format!(
                        "{at} is declared C1 but point {} is {off:.3e} from P{jj} + (h{j}/h{})·(P{jj} − P{}) (interval ratio {r})",
                        jj + 1,
                        j - 1,
                        jj - 1
                    ));
                }
                if self.continuity == JoinContinuity::C2 {
                    let expect2 =
                        p[jj + 1] * 2.0 - p[jj] + (p[jj] - p[jj - 1] * 2.0 + p[jj - 2]) * (r * r);
                    let off = (p[jj + 2] - expect2).length();
                    if off > tol {
                        return Some(format!(
                            "{at} is declared C2 but point {} is {off:.3e} from where equal second derivatives put it (interval ratio {r})",
                            jj + 2
                        ));
                    }
                }
                None
            }
        }
    }

    /// Whether the handles are the Bézier points or de Boor points.
    #[must_use]
    pub fn handle_kind(&self) -> Handles {
        match (self.continuity, self.degree) {
            (JoinContinuity::C1, 2) | (JoinContinuity::C2, 3) => Handles::DeBoor,
            _ => Handles::Bezier,
        }
    }

    /// Number of handles.
    #[must_use]
    pub fn handle_count(&self) -> usize {
        let k = self.segments();
        match (self.handle_kind(), self.degree) {
            (Handles::Bezier, _) => self.points.len(),
            (Handles::DeBoor, 2) => k + 2,
            (Handles::DeBoor, _) => k + 3,
        }
    }

    /// The handle positions: Bézier points, or de Boor points (C1 quadratic: P_0, the inner
    /// points, P_2k; C2 cubic: the A-frame points D_0 = P_0, D_1 = P_1, D_{s+2} = P_{3s+2} +
    /// (h_{s+1}/h_s)(P_{3s+2} − P_{3s+1}), D_{k+2} = P_{3k}).
    #[must_use]
    pub fn handles(&self) -> Vec<DVec3> {
        (0..self.handle_count()).map(|i| self.handle(i)).collect()
    }

    /// Handle i's position.
    #[must_use]
    pub fn handle(&self, i: usize) -> DVec3 {
        let k = self.segments();
        let p = &self.points;
        match (self.handle_kind(), self.degree) {
            (Handles::Bezier, _) => p[i],
            (Handles::DeBoor, 2) => match i {
                0 => p[0],
                i if i == k + 1 => p[2 * k],
                i => p[2 * i - 1],
            },
            (Handles::DeBoor, _) => match i {
                0 => p[0],
                1 => p[1],
                i if i == k + 2 => p[3 * k],
                i => {
                    let s = i - 2;
                    let r = self.h(s as isize + 1) / self.h(s as isize);
                    p[3 * s + 2] + (p[3 * s + 2] - p[3 * s + 1]) * r
                }
            },
        }
    }

    /// Checks a handle index.
    pub fn check_handle(&self, i: usize) -> GeomResult<()> {
        let n = self.handle_count();
        if i < n {
            return Ok(());
        }
        let what = match self.handle_kind() {
            Handles::Bezier => "Bézier point",
            Handles::DeBoor => "de Boor point",
        };
        Err(GeomError::new(
            "point",
            format!(
                "{what} index {i} out of range (valid: 0..={}; a {} Bézier spline of degree {} is edited through {n} {what}s)",
                n - 1,
                self.continuity.name(),
                self.degree,
            ),
        ))
    }

    /// The Bézier points that moving handle `i` by `delta` changes, with their new values:
    /// the continuity-keeping expansion described in the module documentation.
    pub fn move_handle(&self, i: usize, delta: DVec3) -> GeomResult<Vec<(usize, DVec3)>> {
        self.check_handle(i)?;
        match self.handle_kind() {
            Handles::DeBoor => Ok(self
                .deboor_weights(i)
                .into_iter()
                .map(|(m, w)| (m, self.points[m] + delta * w))
                .collect()),
            Handles::Bezier => self.move_bezier(i, delta),
        }
    }

    /// Bézier-point editing (C0, G1, C1 with d ≥ 3, C2 with d ≥ 5).
    fn move_bezier(&self, i: usize, delta: DVec3) -> GeomResult<Vec<(usize, DVec3)>> {
        let d = self.degree;
        let last = self.points.len() - 1;
        let c = self.continuity.tied();
        let mut out = vec![(i, self.points[i] + delta)];
        let carry = |out: &mut Vec<(usize, DVec3)>, m: usize| {
            if m <= last && m != i {
                out.push((m, self.points[m] + delta));
            }
        };
        if i.is_multiple_of(d) {
            // A junction carries its tied neighbours, an end its one neighbour (one at least
            // when d ≥ 2, so the tangent directions at a corner stay as they were).
            let ends = usize::from(d >= 2);
            let reach = if i == 0 || i == last {
                ends
            } else {
                c.max(ends)
            };
            for a in 1..=reach {
                carry(&mut out, i + a);
                if let Some(m) = i.checked_sub(a) {
                    carry(&mut out, m);
                }
            }
            return Ok(out);
        }
        // A tied point of an interior junction: the junction within c of it.
        let (junction, side) = if i % d <= c {
            (i - i % d, 1isize)
        } else if d - i % d <= c {
            (i + (d - i % d), -1)
        } else {
            return Ok(out);
        };
        if junction == 0 || junction == last {
            return Ok(out);
        }
        let moved = |m: usize| {
            if m == i {
                self.points[m] + delta
            } else {
                self.points[m]
            }
        };
        let j = junction / d;
        let pj = self.points[junction];
        // Ratio of the other side's interval to the moved side's.
        let (h_this, h_other) = if side > 0 {
            (self.h(j as isize), self.h(j as isize - 1))
        } else {
            (self.h(j as isize - 1), self.h(j as isize))
        };
        let q = h_other / h_this;
        let at = |a: usize| -> usize { if side > 0 { junction + a } else { junction - a } };
        let mirror = |a: usize| -> usize { if side > 0 { junction - a } else { junction + a } };
        match self.continuity {
            JoinContinuity::C0 => {}
            JoinContinuity::G1 => {
                let leg = moved(at(1)) - pj;
                let len = leg.length();
                if len <= 0.0 || !len.is_finite() {
                    return Err(GeomError::new(
                        "delta",
                        format!(
                            "the move puts point {} onto junction {j} (point {junction}): a G1 junction needs a tangent direction",
                            at(1)
                        ),
                    ));
                }
                let keep = (self.points[mirror(1)] - pj).length();
                out.push((mirror(1), pj - leg * (keep / len)));
            }
            JoinContinuity::C1 | JoinContinuity::C2 => {
                // Derivatives at the junction from the moved side, matched on the other side:
                // first differences scale by q, second differences by q².
                let d1 = moved(at(1)) - pj;
                let m1 = pj - d1 * q;
                out.push((mirror(1), m1));
                if c == 2 {
                    let d2 = moved(at(2)) - moved(at(1)) * 2.0 + pj;
                    out.push((mirror(2), d2 * (q * q) - pj + m1 * 2.0));
                }
            }
        }
        Ok(out)
    }

    /// How de Boor point i enters the Bézier points: (index, weight) for every Bézier point it
    /// changes (the lecture's quadratic and cubic B-spline constructions are linear in the de
    /// Boor points).
    fn deboor_weights(&self, i: usize) -> Vec<(usize, f64)> {
        let k = self.segments() as isize;
        let h = |j: isize| self.h(j);
        let mut out = Vec::new();
        if self.degree == 2 {
            // D_0 = P_0, D_{k+1} = P_2k, D_{s+1} = P_{2s+1}; P_{2j} = (h_j P_{2j−1} +
            // h_{j−1} P_{2j+1}) / (h_{j−1} + h_j) at interior junctions.
            if i == 0 {
                return vec![(0, 1.0)];
            }
            if i as isize == k + 1 {
                return vec![(2 * k as usize, 1.0)];
            }
            let s = i as isize - 1;
            out.push((2 * s as usize + 1, 1.0));
            if s >= 1 {
                out.push((2 * s as usize, h(s - 1) / (h(s - 1) + h(s))));
            }
            if s < k - 1 {
                out.push((2 * s as usize + 2, h(s + 1) / (h(s) + h(s + 1))));
            }
            return out;
        }
        // Cubic (A-frame): inner points of segment s on D_{s+1} D_{s+2},
        // C^s_1 = ((h_s + h_{s+1}) D_{s+1} + h_{s−1} D_{s+2}) / Σ,
        // C^s_2 = (h_{s+1} D_{s+1} + (h_{s−1} + h_s) D_{s+2}) / Σ, Σ = h_{s−1} + h_s + h_{s+1};
        // junctions P_{3s} = (h_s C^{s−1}_2 + h_{s−1} C^s_1) / (h_{s−1} + h_s); P_0 = D_0,
        // P_3k = D_{k+2}.
        let i = i as isize;
        let inner = |s: isize| -> (f64, f64) {
            let sum = h(s - 1) + h(s) + h(s + 1);
            if i == s + 1 {
                ((h(s) + h(s + 1)) / sum, h(s + 1) / sum)
            } else if i == s + 2 {
                (h(s - 1) / sum, (h(s - 1) + h(s)) / sum)
            } else {
                (0.0, 0.0)
            }
        };
        if i == 0 {
            out.push((0, 1.0));
        }
        if i == k + 2 {
            out.push((3 * k as usize, 1.0));
        }
        for s in (i - 2).max(0)..=(i - 1).min(k - 1) {
            let (c1, c2) = inner(s);
            out.push((3 * s as usize + 1, c1));
            out.push((3 * s as usize + 2, c2));
        }
        for s in (i - 2).max(1)..=i.min(k - 1) {
            let w = (h(s) * inner(s - 1).1 + h(s - 1) * inner(s).0) / (h(s - 1) + h(s));
            out.push((3 * s as usize, w));
        }
        out.retain(|&(_, w)| w != 0.0);
        out.sort_by_key(|&(m, _)| m);
        out
    }

    /// Sets Bézier point m (edits go through [`move_handle`](Self::move_handle); this is how
    /// their results and exact undo values are written).
    pub fn set_point(&mut self, m: usize, p: DVec3) {
        self.points[m] = p;
    }
}

/// The degrees a continuity can be kept at.
fn check_degree(d: usize, c: JoinContinuity) -> GeomResult<()> {
    let why = match (c, d) {
        (_, 0) => "degree 0 has no curve to join",
        (JoinContinuity::C1, 1) => "C1 needs degree ≥ 2",
        (JoinContinuity::G1, 1 | 2) => {
            "G1 needs degree ≥ 3 (a quadratic's one inner point would be tied to both junctions; use C1 for quadratics)"
        }
        (JoinContinuity::C2, 1 | 2) => "C2 needs degree ≥ 3",
        (JoinContinuity::C2, 4) => {
            "C2 is kept for degree 3 (de Boor points) and degree ≥ 5 (Bézier points); degree 4 is not supported"
        }
        _ => return Ok(()),
    };
    Err(GeomError::new(
        "degree",
        format!("degree {d} with continuity {}: {why}", c.name()),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::bezier_spline::{Continuity, extend};
    use crate::geom::{BSplineCurve, BezierCurve};

    /// A C2 cubic spline from de Boor points by the B-spline itself (knot insertion to
    /// multiplicity 3), independent of the A-frame formulas.
    fn c2_cubic(knots: &[f64], deboor: &[DVec3]) -> BezierSpline {
        let k = knots.len() - 1;
        let mut kv = vec![knots[0]; 4];
        kv.extend_from_slice(&knots[1..k]);
        kv.extend(std::iter::repeat_n(knots[k], 4));
        let mut b = BSplineCurve::new(3, kv, deboor.to_vec(), None).unwrap();
        for &t in &knots[1..k] {
            b = b.insert_knot(t, 2).unwrap();
        }
        BezierSpline::new(3, knots.to_vec(), b.points().to_vec(), JoinContinuity::C2).unwrap()
    }

    fn deboor() -> Vec<DVec3> {
        (0..7)
            .map(|i| DVec3::new(i as f64, ((i * i) % 5) as f64, (i % 3) as f64))
            .collect()
    }

    const KNOTS: [f64; 5] = [0.0, 0.5, 2.0, 2.25, 4.0];

    #[test]
    fn a_frame_points_are_the_de_boor_points() {
        let s = c2_cubic(&KNOTS, &deboor());
        for (a, b) in s.handles().iter().zip(deboor()) {
            assert!((*a - b).length() < 1e-13, "{a} {b}");
        }
    }

    #[test]
    fn moving_a_de_boor_point_is_the_b_spline_with_that_point_moved() {
        let delta = DVec3::new(0.3, -0.7, 0.2);
        for i in 0..7 {
            let s = c2_cubic(&KNOTS, &deboor());
            let mut moved = s.clone();
            for (m, p) in s.move_handle(i, delta).unwrap() {
                moved.set_point(m, p);
            }
            let mut d = deboor();
            d[i] += delta;
            let expect = c2_cubic(&KNOTS, &d);
            for (a, b) in moved.points().iter().zip(expect.points()) {
                assert!((*a - *b).length() < 1e-13, "de Boor {i}: {a} {b}");
            }
        }
    }

    #[test]
    fn mirrors_keep_c1_and_c2_with_unequal_intervals() {
        // Degree 5, C2: build by the join formulas of bezier_spline.rs.
        let seg = BezierCurve::new(
            (0..6)
                .map(|i| DVec3::new(i as f64, (i * i) as f64 * 0.1, 0.0))
                .collect(),
        )
        .unwrap();
        let next = extend(&seg, 0.4, Continuity::C2, &[DVec3::ONE; 3]).unwrap();
        let mut pts = seg.points().to_vec();
        pts.extend_from_slice(&next.points()[1..]);
        let s = BezierSpline::new(5, vec![0.0, 1.0, 1.4], pts, JoinContinuity::C2).unwrap();
        for i in 0..=10 {
            let mut m = s.clone();
            for (idx, p) in s.move_handle(i, DVec3::new(0.1, 0.2, -0.3)).unwrap() {
                m.set_point(idx, p);
            }
            assert_eq!(m.junction_error(1), None, "handle {i}");
        }
    }

    #[test]
    fn degrees_that_cannot_keep_their_continuity_are_refused() {
        let e = BezierSpline::new(4, vec![0.0, 1.0], vec![DVec3::ZERO; 5], JoinContinuity::C2)
            .unwrap_err();
        assert_eq!(e.field, "degree");
        let e = BezierSpline::new(2, vec![0.0, 1.0], vec![DVec3::ZERO; 3], JoinContinuity::G1)
            .unwrap_err();
        assert!(e.message.contains("G1 needs degree ≥ 3"), "{e}");
    }
}
