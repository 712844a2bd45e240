//! ERBS curves: local curves of any kind, blended; built from a curve, refined locally.

use super::super::bezier::BezierCurve;
use super::super::bfunction::BFunctionKind;
use super::super::bspline::BSplineCurve;
use super::super::error::{GeomError, GeomResult};
use super::super::point::binomial;
use super::{ErbsKnots, MAX_NESTING, blend_weights, taylor_bezier};
use glam::{DMat4, DVec3};

/// A local curve, placed: its parameter is the parent's and its domain the local's support.
#[derive(Debug, Clone, PartialEq)]
pub enum LocalCurve {
    /// A polynomial Bézier (`bezier`: one span, written as its points) or B-spline curve.
    Spline { curve: BSplineCurve, bezier: bool },
    /// An ERBS curve with its own locals.
    Erbs(Box<ErbsCurve>),
}

impl LocalCurve {
    /// A polynomial Bézier local from its points (placed later, onto its support).
    pub fn bezier(points: Vec<DVec3>) -> GeomResult<Self> {
        Ok(LocalCurve::Spline {
            curve: BezierCurve::new(points)?.to_bspline(),
            bezier: true,
        })
    }

    /// The parameter interval the local covers (its support once placed).
    #[must_use]
    pub fn domain(&self) -> (f64, f64) {
        match self {
            LocalCurve::Spline { curve, .. } => curve.domain(),
            LocalCurve::Erbs(e) => e.domain(),
        }
    }

    /// c(t), c'(t), …, c^(n)(t) in the parent's parameter.
    #[must_use]
    pub fn derivatives(&self, t: f64, n: usize) -> Vec<DVec3> {
        match self {
            LocalCurve::Spline { curve, .. } => curve.derivatives(t, n),
            LocalCurve::Erbs(e) => e.derivatives(t, n),
        }
    }

    #[must_use]
    pub fn eval(&self, t: f64) -> DVec3 {
        self.derivatives(t, 0)[0]
    }

    /// Its own control points (none for an ERBS local: those live in its locals).
    #[must_use]
    pub fn points(&self) -> Option<&[DVec3]> {
        match self {
            LocalCurve::Spline { curve, .. } => Some(curve.points()),
            LocalCurve::Erbs(_) => None,
        }
    }

    /// The degree of a polynomial local; of an ERBS local, the largest of its locals'.
    pub fn degree(&self) -> usize {
        match self {
            LocalCurve::Spline { curve, .. } => curve.degree(),
            LocalCurve::Erbs(e) => e.local.iter().map(LocalCurve::degree).max().unwrap_or(0),
        }
    }

    /// ERBS levels below this local (0 for a polynomial one).
    #[must_use]
    pub fn depth(&self) -> usize {
        match self {
            LocalCurve::Spline { .. } => 0,
            LocalCurve::Erbs(e) => e.depth(),
        }
    }

    pub fn is_rational(&self) -> bool {
        match self {
            LocalCurve::Spline { curve, .. } => curve.is_rational(),
            LocalCurve::Erbs(e) => e.local.iter().any(LocalCurve::is_rational),
        }
    }

    /// Every control point, at any depth, mapped by `f` (affine maps commute with the blend:
    /// the B-functions form a partition of unity).
    pub fn map_points(&mut self, f: &impl Fn(DVec3) -> DVec3) {
        match self {
            LocalCurve::Spline { curve, .. } => curve.map_points(f),
            LocalCurve::Erbs(e) => e.local.iter_mut().for_each(|l| l.map_points(f)),
        }
    }

    /// The same local with its parameter mapped affinely so that its domain becomes [a, b].
    pub fn placed(self, (a, b): (f64, f64)) -> GeomResult<Self> {
        let (d0, d1) = self.domain();
        if (d0, d1) == (a, b) {
            return Ok(self);
        }
        if !(a.is_finite() && b.is_finite() && a < b) {
            return Err(GeomError::new(
                "interval",
                format!("[{a}, {b}] is not a finite interval with a < b"),
            ));
        }
        let scale = (b - a) / (d1 - d0);
        // One function for every knot at every depth, with the old ends sent exactly to the
        // new ones, so nested supports and domains stay equal where they were equal.
        let f = move |t: f64| match t {
            t if t == d0 => a,
            t if t == d1 => b,
            t => a + (t - d0) * scale,
        };
        self.mapped(&f)
    }

    fn mapped(self, f: &impl Fn(f64) -> f64) -> GeomResult<Self> {
        Ok(match self {
            LocalCurve::Spline { curve, bezier } => LocalCurve::Spline {
                curve: curve.with_knots_mapped(f)?,
                bezier,
            },
            LocalCurve::Erbs(mut e) => {
                e.knots.map(f);
                e.local = e
                    .local
                    .into_iter()
                    .map(|l| l.mapped(f))
                    .collect::<GeomResult<_>>()?;
                LocalCurve::Erbs(e)
            }
        })
    }

    /// The same function on the shorter interval [a, b] ⊆ domain, exactly: a polynomial local
    /// is split (Bézier subdivision by knot insertion), an ERBS local keeps its knots and
    /// narrows its domain.
    pub fn restricted(&self, (a, b): (f64, f64)) -> GeomResult<Self> {
        let (d0, d1) = self.domain();
        match self {
            LocalCurve::Spline { curve, bezier } => {
                let mut c = curve.clone();
                if a > d0 {
                    c = c.split(a)?.1;
                }
                if b < d1 {
                    c = c.split(b)?.0;
                }
                Ok(LocalCurve::Spline {
                    curve: c,
                    bezier: *bezier,
                })
            }
            LocalCurve::Erbs(e) => {
                let mut e = e.clone();
                e.knots = e.knots.with_domain((a.max(d0), b.min(d1)))?;
                Ok(LocalCurve::Erbs(e))
            }
        }
    }
}

/// An ERBS curve of blending type.
#[derive(Debug, Clone, PartialEq)]
pub struct ErbsCurve {
    knots: ErbsKnots,
    local: Vec<LocalCurve>,
    bfunction: BFunctionKind,
}

impl ErbsCurve {
    /// An open ERBS curve with Bézier locals, each given on any interval and placed onto
    /// [t_l, t_{l+2}].
    pub fn new(
        knots: Vec<f64>,
        local: Vec<BezierCurve>,
        bfunction: BFunctionKind,
    ) -> GeomResult<Self> {
        let knots = ErbsKnots::open(knots, local.len())?;
        let local = local
            .iter()
            .map(|c| {
                if c.is_rational() {
                    return Err(rational_local());
                }
                LocalCurve::bezier(c.points().to_vec())
            })
            .collect::<GeomResult<_>>()?;
        Self::with_locals(knots, local, bfunction)
    }

    /// An ERBS curve from its knots and locals of any kind; each local is placed onto its
    /// support. Locals must be polynomial and nested at most [`MAX_NESTING`] deep.
    pub fn with_locals(
        knots: ErbsKnots,
        local: Vec<LocalCurve>,
        bfunction: BFunctionKind,
    ) -> GeomResult<Self> {
        if local.len() != knots.locals() {
            return Err(GeomError::new(
                "local",
                format!(
                    "{} local curves for knots that hold {}",
                    local.len(),
                    knots.locals()
                ),
            ));
        }
        let local: Vec<LocalCurve> = local
            .into_iter()
            .enumerate()
            .map(|(l, c)| {
                if c.is_rational() {
                    return Err(rational_local());
                }
                c.placed(knots.support(l))
            })
            .collect::<GeomResult<_>>()?;
        let c = Self {
            knots,
            local,
            bfunction,
        };
        if c.depth() > MAX_NESTING {
            return Err(GeomError::new(
                "local",
                format!(
                    "ERBS locals are nested {} levels deep; at most {MAX_NESTING} are supported",
                    c.depth()
                ),
            ));
        }
        Ok(c)
    }

    /// GMlib's construction: n locals on uniform knots over the source's domain, local l the
    /// source's degree-d Taylor polynomial at its centre in Bernstein form on its support
    /// (derivatives of rational sources by the quotient rule).
    pub fn from_curve(
        source: &BSplineCurve,
        n: usize,
        degree: usize,
        bfunction: BFunctionKind,
        closed: bool,
    ) -> GeomResult<Self> {
        let (a, b) = source.domain();
        let knots = ErbsKnots::uniform(a, b, n, closed)?;
        let local = (0..n)
            .map(|l| {
                let c = knots.centre(l);
                let support = knots.support(l);
                hermite_local(&source.derivatives(c, degree), c, support)
            })
            .collect::<GeomResult<_>>()?;
        Self::with_locals(knots, local, bfunction)
    }

    /// Bytes [`ErbsCurve::from_curve`] allocates for `n` locals of degree `degree`, from the
    /// types it builds: per local the enum, d + 1 points and 2(d + 1) knots, plus the ERBS knot
    /// vector. Saturates; for the memory budget before anything is built.
    #[must_use]
    pub fn from_curve_bytes(n: usize, degree: usize) -> u128 {
        let d1 = degree as u128 + 1;
        let per_local = std::mem::size_of::<LocalCurve>() as u128
            + d1 * std::mem::size_of::<DVec3>() as u128
            + 2 * d1 * std::mem::size_of::<f64>() as u128;
        n as u128 * (per_local + std::mem::size_of::<f64>() as u128)
    }

    #[must_use]
    pub fn knots(&self) -> &ErbsKnots {
        &self.knots
    }

    #[must_use]
    pub fn local_curves(&self) -> &[LocalCurve] {
        &self.local
    }

    #[must_use]
    pub fn bfunction(&self) -> BFunctionKind {
        self.bfunction
    }

    #[must_use]
    pub fn domain(&self) -> (f64, f64) {
        self.knots.domain()
    }

    #[must_use]
    pub fn is_closed(&self) -> bool {
        self.knots.is_closed()
    }

    /// ERBS levels inside this curve's locals (1 when every local is polynomial).
    pub fn depth(&self) -> usize {
        1 + self.local.iter().map(LocalCurve::depth).max().unwrap_or(0)
    }

    /// The local at `path` (indices descending through ERBS locals).
    #[must_use]
    pub fn local_at(&self, path: &[usize]) -> Option<&LocalCurve> {
        let (&first, rest) = path.split_first()?;
        let l = self.local.get(first)?;
        match (rest.is_empty(), l) {
            (true, _) => Some(l),
            (false, LocalCurve::Erbs(e)) => e.local_at(rest),
            (false, LocalCurve::Spline { .. }) => None,
        }
    }

    fn local_at_mut(&mut self, path: &[usize]) -> Option<&mut LocalCurve> {
        let (&first, rest) = path.split_first()?;
        let l = self.local.get_mut(first)?;
        if rest.is_empty() {
            return Some(l);
        }
        match l {
            LocalCurve::Erbs(e) => e.local_at_mut(rest),
            LocalCurve::Spline { .. } => None,
        }
    }

    /// Maps every control point of the local at `path` by p ↦ (A·[p;1]).xyz.
    pub fn transform_local(&mut self, path: &[usize], a: &DMat4) {
        if let Some(l) = self.local_at_mut(path) {
            l.map_points(&|p| a.transform_point3(p));
        }
    }

    /// Translates control point q of the polynomial local at `path`.
    pub fn translate_local_point(&mut self, path: &[usize], q: usize, delta: DVec3) {
        if let Some(LocalCurve::Spline { curve, .. }) = self.local_at_mut(path) {
            curve.translate_point(q, delta);
        }
    }

    /// Sets every control point of the polynomial local at `path` exactly.
    pub fn set_local_points(&mut self, path: &[usize], points: &[DVec3]) {
        if let Some(LocalCurve::Spline { curve, .. }) = self.local_at_mut(path) {
            curve.set_points(points);
        }
    }

    /// Replaces the local at `path` (already placed on its support).
    pub fn set_local(&mut self, path: &[usize], local: LocalCurve) {
        if let Some(l) = self.local_at_mut(path) {
            *l = local;
        }
    }

    /// Local refinement at t, strictly inside interval i = [c_i, c_{i+1}]: the two locals
    /// whose supports contain t keep their shape, restricted exactly to [c_{i−1}, t] and
    /// [t, c_{i+2}]; a new local i + 1 on [c_i, c_{i+1}] is the degree-d Bézier matching this
    /// curve's derivatives 0..=d at t (d defaults to the larger degree of its neighbours). Every
    /// old knot keeps its value and derivatives; the curve changes only inside (c_i, c_{i+1}).
    /// Returns the refined curve and the new local's index.
    pub fn insert_knot(&self, t: f64, degree: Option<usize>) -> GeomResult<(Self, usize)> {
        let (knots, i) = self.knots.insert(t)?;
        let (right, shift) = self.knots.right(i);
        let d = degree.unwrap_or_else(|| self.local[i].degree().max(self.local[right].degree()));
        let new = hermite_local(&self.derivatives(t, d), t, self.knots.interval(i))?;
        let mut local = self.local.clone();
        local[i] = self.local[i].restricted((self.knots.support(i).0, t))?;
        local[right] = self.local[right].restricted((t - shift, self.knots.support(right).1))?;
        local.insert(i + 1, new);
        let refined = Self {
            knots,
            local,
            bfunction: self.bfunction,
        };
        Ok((refined, i + 1))
    }

    /// c(t), c'(t), …, c^(n)(t).
    #[must_use]
    pub fn derivatives(&self, t: f64, n: usize) -> Vec<DVec3> {
        let (a, b) = self.domain();
        let t = t.clamp(a, b);
        let i = self.knots.locate(t);
        let w = blend_weights(&self.bfunction, self.knots.interval(i), t, n);
        let (right, shift) = self.knots.right(i);
        let mut out = vec![DVec3::ZERO; n + 1];
        for (side, (l, s)) in [(i, 0.0), (right, shift)].into_iter().enumerate() {
            let c = self.local[l].derivatives(t - s, n);
            for (r, o) in out.iter_mut().enumerate() {
                for k in 0..=r {
                    *o += c[k] * (binomial(r, k) * w[side][r - k]);
                }
            }
        }
        out
    }

    #[must_use]
    pub fn eval(&self, t: f64) -> DVec3 {
        self.derivatives(t, 0)[0]
    }
}

/// The Bézier local matching `derivs` (orders 0..=d) at `centre`, on `support`.
fn hermite_local(derivs: &[DVec3], centre: f64, support: (f64, f64)) -> GeomResult<LocalCurve> {
    let points = taylor_bezier(derivs, centre, support);
    Ok(LocalCurve::Spline {
        curve: BezierCurve::new(points)?
            .with_interval(support.0, support.1)?
            .to_bspline(),
        bezier: true,
    })
}

fn rational_local() -> GeomError {
    GeomError::new(
        "local",
        "rational local curves are not supported: local curves and patches must be polynomial",
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::KnotVector;

    fn curve(bf: BFunctionKind) -> ErbsCurve {
        let local = (0..4)
            .map(|l| {
                let x = l as f64;
                BezierCurve::new(vec![
                    DVec3::new(x - 0.5, 0.2 * x, 0.0),
                    DVec3::new(x, 1.0 + x * 0.1, 0.5),
                    DVec3::new(x + 0.6, -0.3, 0.2 * x),
                ])
                .unwrap()
            })
            .collect();
        ErbsCurve::new(vec![0.0, 0.0, 1.0, 2.5, 3.0, 3.0], local, bf).unwrap()
    }

    #[test]
    fn interpolates_local_curves_at_knots() {
        for bf in BFunctionKind::ALL {
            let c = curve(bf);
            for l in 0..4 {
                let t = c.knots().centre(l);
                let a = c.eval(t);
                let b = c.local_curves()[l].eval(t);
                assert!((a - b).length() < 1e-14, "{bf:?} l={l}");
            }
        }
    }

    #[test]
    fn derivatives_match_finite_differences() {
        for bf in BFunctionKind::ALL {
            let c = curve(bf);
            for &t in &[0.1, 0.5, 1.3, 2.0, 2.7, 2.9] {
                let d = c.derivatives(t, 4);
                let h = 1e-5;
                let p = c.derivatives(t + h, 4);
                let m = c.derivatives(t - h, 4);
                for r in 0..4 {
                    let fd = (p[r] - m[r]) / (2.0 * h);
                    let tol = 1e-5 * (1.0 + d[r + 1].length());
                    assert!(
                        (fd - d[r + 1]).length() < tol,
                        "{bf:?} t={t} r={}: {fd:?} vs {:?}",
                        r + 1,
                        d[r + 1]
                    );
                }
            }
        }
    }

    #[test]
    fn knot_validation() {
        let c = |k: Vec<f64>| ErbsKnots::open(k, 3).unwrap_err().message;
        assert!(c(vec![0., 0., 1., 2.]).contains("expected 5 knots"));
        assert!(c(vec![0., 0.5, 1., 2., 2.]).contains("knot 0 (0) must equal knot 1 (0.5)"));
        assert!(c(vec![0., 0., 1., 2., 3.]).contains("knot 4 (3) must equal knot 3 (2)"));
        assert!(c(vec![0., 0., 0., 2., 2.]).contains("strictly increasing"));
        assert!(
            ErbsKnots::open(vec![0., 0., 1.], 1)
                .unwrap_err()
                .message
                .contains("at least 2")
        );
    }

    fn source() -> BSplineCurve {
        let pts = (0..7)
            .map(|i| DVec3::new(i as f64, (i as f64 * 0.9).sin() * 2.0, 0.1 * (i * i) as f64))
            .collect();
        let knots = KnotVector::clamped_uniform(3, 7, -1.0, 2.0).into_vec();
        BSplineCurve::new(3, knots, pts, Some(vec![1.0, 2.0, 0.5, 1.0, 1.5, 1.0, 0.7])).unwrap()
    }

    #[test]
    fn construction_matches_the_source_at_every_knot() {
        for closed in [false, true] {
            let s = source();
            let e = ErbsCurve::from_curve(&s, 6, 3, BFunctionKind::ExpoRational, closed).unwrap();
            assert_eq!(e.domain(), s.domain());
            for l in 0..6 {
                let c = e.knots().centre(l);
                let (a, b) = (e.derivatives(c, 3), s.derivatives(c, 3));
                for r in 0..=3 {
                    assert!(
                        (a[r] - b[r]).length() < 1e-9 * (1.0 + b[r].length()),
                        "closed {closed} l={l} r={r}: {:?} vs {:?}",
                        a[r],
                        b[r]
                    );
                }
            }
        }
    }

    #[test]
    fn refinement_keeps_old_knots_and_changes_only_its_interval() {
        for closed in [false, true] {
            let e = ErbsCurve::from_curve(&source(), 5, 3, BFunctionKind::ExpoRational, closed)
                .unwrap();
            let last = e.knots().intervals() - 1;
            for i in [0, 1, last] {
                let (lo, hi) = e.knots().interval(i);
                let t = lo + 0.37 * (hi - lo);
                let (r, new) = e.insert_knot(t, None).unwrap();
                assert_eq!(new, i + 1);
                assert_eq!(r.local_curves().len(), 6);
                assert_eq!(r.knots().centre(new), t);
                let want = e.derivatives(t, 3);
                let got = r.derivatives(t, 3);
                for k in 0..=3 {
                    assert!((want[k] - got[k]).length() < 1e-9 * (1.0 + want[k].length()));
                }
                let (a, b) = e.domain();
                for j in 0..=200 {
                    let x = a + (b - a) * j as f64 / 200.0;
                    let inside = x > lo && x < hi;
                    let (p, q) = (e.derivatives(x, 2), r.derivatives(x, 2));
                    if !inside {
                        for k in 0..=2 {
                            assert!(
                                (p[k] - q[k]).length() < 1e-10 * (1.0 + p[k].length()),
                                "closed {closed} i={i} x={x} k={k}"
                            );
                        }
                    }
                }
            }
        }
    }
}
