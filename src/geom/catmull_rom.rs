//! Catmull–Rom splines (lecture 3.2): interpolating cubic Bézier splines whose tangents are
//! estimated from the neighbouring points, with the uniform, centripetal and chordal knot
//! sequences and open or closed point lists.
//!
//! Segment s joins P_s and P_{s+1} and is written over the global parameter [s, s+1], so the
//! domain is [0, k+1] for k+2 points (open) and [0, n] for n points (closed) whatever the knot
//! sequence: the knots only shape the tangents. Uniform knots give exactly the lecture's
//! construction, a C1 curve; with centripetal or chordal knots each segment is the same cubic
//! as over its knot interval, reparameterised affinely, so the curve is C1 in the knot
//! parameter and G1 (one tangent direction, lengths in the ratio of the intervals) in s.

use super::bspline::BSplineCurve;
use super::error::{GeomError, GeomResult};
use glam::DVec3;

/// How the knot intervals Δ_s = t_{s+1} − t_s follow the points: Δ_s = |P_{s+1} − P_s|^α.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Parametrization {
    /// α = 0: Δ_s = 1, the lecture's construction.
    #[default]
    Uniform,
    /// α = ½: no cusps or self-intersections within a segment (Yuksel, Schaefer, Keyser 2011).
    Centripetal,
    /// α = 1: intervals as long as the chords.
    Chordal,
}

impl Parametrization {
    pub const ALL: [Parametrization; 3] = [
        Parametrization::Uniform,
        Parametrization::Centripetal,
        Parametrization::Chordal,
    ];

    /// The scene-file name.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Parametrization::Uniform => "uniform",
            Parametrization::Centripetal => "centripetal",
            Parametrization::Chordal => "chordal",
        }
    }

    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|p| p.name() == name)
    }

    /// Δ for a chord of length `len`.
    fn interval(self, len: f64) -> f64 {
        match self {
            Parametrization::Uniform => 1.0,
            Parametrization::Centripetal => len.sqrt(),
            Parametrization::Chordal => len,
        }
    }
}

/// A Catmull–Rom spline through `points`.
#[derive(Debug, Clone, PartialEq)]
pub struct CatmullRom {
    points: Vec<DVec3>,
    parametrization: Parametrization,
    closed: bool,
}

impl CatmullRom {
    /// At least 2 points (3 when closed), finite; with centripetal or chordal knots consecutive
    /// points must differ (a zero-length interval has no tangent).
    pub fn new(
        points: Vec<DVec3>,
        parametrization: Parametrization,
        closed: bool,
    ) -> GeomResult<Self> {
        let min = if closed { 3 } else { 2 };
        if points.len() < min {
            return Err(GeomError::new(
                "points",
                format!(
                    "a{} Catmull–Rom spline needs at least {min} points, got {}",
                    if closed { " closed" } else { "n open" },
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
        let c = Self {
            points,
            parametrization,
            closed,
        };
        for s in 0..c.segments() {
            c.check_segment(s)?;
        }
        Ok(c)
    }

    #[must_use]
    pub fn points(&self) -> &[DVec3] {
        &self.points
    }

    #[must_use]
    pub fn parametrization(&self) -> Parametrization {
        self.parametrization
    }

    #[must_use]
    pub fn closed(&self) -> bool {
        self.closed
    }

    /// Number of cubic segments: one per pair of consecutive points (and the closing pair).
    #[must_use]
    pub fn segments(&self) -> usize {
        if self.closed {
            self.points.len()
        } else {
            self.points.len() - 1
        }
    }

    /// [0, segments].
    #[must_use]
    pub fn domain(&self) -> (f64, f64) {
        (0.0, self.segments() as f64)
    }

    /// Point j, cyclically for closed splines.
    fn p(&self, j: isize) -> DVec3 {
        let n = self.points.len() as isize;
        self.points[j.rem_euclid(n) as usize]
    }

    /// The error for a segment whose knot interval would vanish.
    fn check_segment(&self, s: usize) -> GeomResult<()> {
        if self.parametrization == Parametrization::Uniform {
            return Ok(());
        }
        let d = self.delta(s);
        if d > 0.0 && d.is_finite() {
            return Ok(());
        }
        let n = self.points.len();
        Err(GeomError::new(
            "points",
            format!(
                "points {s} and {} coincide: {} knots need distinct consecutive points",
                (s + 1) % n,
                self.parametrization.name()
            ),
        ))
    }

    /// Whether moving point j to `to` keeps every knot interval non-zero.
    pub fn check_move(&self, j: usize, to: DVec3) -> GeomResult<()> {
        let mut moved = self.clone();
        moved.points[j] = to;
        let n = self.segments();
        let segs = [j as isize - 1, j as isize];
        for s in segs {
            if self.closed || (0..n as isize).contains(&s) {
                moved.check_segment(s.rem_euclid(n as isize) as usize)?;
            }
        }
        Ok(())
    }

    /// Knot interval Δ_s of segment s.
    fn delta(&self, s: usize) -> f64 {
        let s = s as isize;
        self.parametrization
            .interval((self.p(s + 1) - self.p(s)).length())
    }

    /// Δ_s times the tangent m_j (derivative in the knot parameter) at the start (`end` false)
    /// or end of segment s, where j = s or s+1: the vector whose third is the Bézier leg.
    fn scaled_tangent(&self, s: usize, j: isize) -> DVec3 {
        let n = self.points.len() as isize;
        let open_end = !self.closed && (j == 0 || j == n - 1);
        if self.parametrization == Parametrization::Uniform {
            // The lecture: T_j = ½(P_{j+1} − P_{j−1}), T_0 = ½(P_1 − P_0), T_last = ½(P_last − P_{last−1}).
            return if open_end && j == 0 {
                (self.p(1) - self.p(0)) * 0.5
            } else if open_end {
                (self.p(n - 1) - self.p(n - 2)) * 0.5
            } else {
                (self.p(j + 1) - self.p(j - 1)) * 0.5
            };
        }
        let ds = self.delta(s);
        if open_end {
            // The uniform end tangent, scaled to the end interval: the same Bézier leg.
            return if j == 0 {
                (self.p(1) - self.p(0)) * 0.5
            } else {
                (self.p(n - 1) - self.p(n - 2)) * 0.5
            };
        }
        // Barry–Goldman: m_j = (P_j − P_{j−1})/Δ_{j−1} − (P_{j+1} − P_{j−1})/(Δ_{j−1} + Δ_j)
        // + (P_{j+1} − P_j)/Δ_j, the derivative of the pyramid's cubic at t_j.
        let nseg = self.segments() as isize;
        let (a, b) = (
            self.delta((j - 1).rem_euclid(nseg) as usize),
            self.delta(j.rem_euclid(nseg) as usize),
        );
        let (p0, p1, p2) = (self.p(j - 1), self.p(j), self.p(j + 1));
        let m = (p1 - p0) / a - (p2 - p0) / (a + b) + (p2 - p1) / b;
        m * ds
    }

    /// Bézier point q (0..=3) of segment s: C_0 = P_s, C_1 = P_s + T_s/3, C_2 = P_{s+1} −
    /// T_{s+1}/3, C_3 = P_{s+1} (T scaled by the segment's interval).
    #[must_use]
    pub fn bezier_point(&self, s: usize, q: usize) -> DVec3 {
        let j = s as isize;
        match q {
            0 => self.p(j),
            1 => self.p(j) + self.scaled_tangent(s, j) / 3.0,
            2 => self.p(j + 1) - self.scaled_tangent(s, j + 1) / 3.0,
            _ => self.p(j + 1),
        }
    }

    /// All 3·segments + 1 Bézier points, junctions shared (closed: the last equals the first).
    #[must_use]
    pub fn bezier_points(&self) -> Vec<DVec3> {
        let mut out = Vec::with_capacity(3 * self.segments() + 1);
        for s in 0..self.segments() {
            for q in 0..3 {
                out.push(self.bezier_point(s, q));
            }
        }
        out.push(self.bezier_point(self.segments() - 1, 3));
        out
    }

    /// Bézier point `i` of [`bezier_points`](Self::bezier_points).
    #[must_use]
    pub fn bezier_point_at(&self, i: usize) -> DVec3 {
        let n = self.segments();
        if i == 3 * n {
            self.bezier_point(n - 1, 3)
        } else {
            self.bezier_point(i / 3, i % 3)
        }
    }

    /// Indices of the Bézier points that moving point j can change: those of segments
    /// j−2 … j+1 (cyclically when closed), at most 4 segments; for a closed spline both copies
    /// of the first point.
    #[must_use]
    pub fn bezier_points_of(&self, j: usize) -> Vec<usize> {
        let n = self.segments() as isize;
        let mut out = Vec::with_capacity(14);
        for s in (j as isize - 2)..=(j as isize + 1) {
            if !self.closed && !(0..n).contains(&s) {
                continue;
            }
            let s = s.rem_euclid(n) as usize;
            for q in 0..=3 {
                out.push(3 * s + q);
            }
        }
        if self.closed && (out.contains(&0) || out.contains(&(3 * n as usize))) {
            out.push(0);
            out.push(3 * n as usize);
        }
        out.sort_unstable();
        out.dedup();
        out
    }

    /// Sets point j (callers check [`check_move`](Self::check_move) first).
    pub fn set_point(&mut self, j: usize, p: DVec3) {
        self.points[j] = p;
    }

    /// The spline as a cubic B-spline with triple interior knots at 1, 2, … (its Bézier form).
    #[must_use]
    pub fn to_bspline(&self) -> BSplineCurve {
        bezier_chain_bspline(3, &self.breakpoints(), self.bezier_points())
    }

    /// Segment boundaries 0, 1, …, segments.
    #[must_use]
    pub fn breakpoints(&self) -> Vec<f64> {
        (0..=self.segments()).map(|s| s as f64).collect()
    }
}

/// A chain of degree-d Bézier segments over `breaks` (strictly increasing) sharing their
/// junction points, as a B-spline with knots of multiplicity d at the junctions.
#[must_use]
pub fn bezier_chain_bspline(degree: usize, breaks: &[f64], points: Vec<DVec3>) -> BSplineCurve {
    let k = breaks.len() - 1;
    debug_assert_eq!(points.len(), k * degree + 1);
    let mut knots = vec![breaks[0]; degree + 1];
    for &t in &breaks[1..k] {
        knots.extend(std::iter::repeat_n(t, degree));
    }
    knots.extend(std::iter::repeat_n(breaks[k], degree + 1));
    BSplineCurve::new(degree, knots, points, None).expect("a Bézier chain is a valid B-spline")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pts() -> Vec<DVec3> {
        vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 2.0, 0.0),
            DVec3::new(3.0, 2.5, 1.0),
            DVec3::new(4.0, 0.0, 0.5),
            DVec3::new(6.0, 0.5, 0.0),
        ]
    }

    #[test]
    fn every_parametrization_interpolates_and_has_one_tangent_direction() {
        for closed in [false, true] {
            for par in Parametrization::ALL {
                let c = CatmullRom::new(pts(), par, closed).unwrap();
                let b = c.to_bspline();
                for j in 0..c.segments() {
                    assert_eq!(b.eval(j as f64), c.points()[j]);
                }
                for s in 1..c.segments() {
                    let l = c.bezier_point(s - 1, 3) - c.bezier_point(s - 1, 2);
                    let r = c.bezier_point(s, 1) - c.bezier_point(s, 0);
                    assert!(l.cross(r).length() <= 1e-12 * l.length() * r.length());
                    assert!(l.dot(r) > 0.0);
                }
            }
        }
    }

    #[test]
    fn moving_a_point_changes_only_the_listed_bezier_points() {
        for closed in [false, true] {
            for par in Parametrization::ALL {
                let c = CatmullRom::new(pts(), par, closed).unwrap();
                for j in 0..c.points().len() {
                    let mut m = c.clone();
                    m.set_point(j, c.points()[j] + DVec3::new(0.3, -0.2, 0.1));
                    let (a, b) = (c.bezier_points(), m.bezier_points());
                    let listed = c.bezier_points_of(j);
                    for i in 0..a.len() {
                        if a[i] != b[i] {
                            assert!(listed.contains(&i), "{par:?} closed {closed}: {j} → {i}");
                        }
                    }
                    assert!(listed.len() <= 14);
                }
            }
        }
    }

    #[test]
    fn coincident_points_are_refused_for_centripetal_knots() {
        let mut p = pts();
        p[2] = p[1];
        assert!(CatmullRom::new(p.clone(), Parametrization::Uniform, false).is_ok());
        let e = CatmullRom::new(p, Parametrization::Centripetal, false).unwrap_err();
        assert!(e.message.contains("points 1 and 2 coincide"), "{e}");
    }
}
