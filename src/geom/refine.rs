//! Refinement that keeps the shape: knot insertion (NURBS Book A5.1 CurveKnotIns, A5.3 per
//! surface direction, A5.4 RefineKnotVectCurve for many knots at once), clamping, and degree
//! elevation (what A5.9 DegreeElevateCurve computes, A5.10 per surface direction, by a stable
//! route: see [`degree_elevate`]).
//!
//! Every new control point is a convex combination of old ones (Böhm's and Oslo's insertion
//! coefficients lie in [0, 1]); nothing here extrapolates, so a refined net is as accurate as
//! the net it came from, whatever the degree and however short the spans.
//! Everything works on homogeneous control points (w·P, w), so rational curves and surfaces
//! refine exactly like polynomial ones; callers project back. Surfaces refine one direction by
//! running the curve algorithm on every line of the net in that direction: the knots and the
//! coefficients are the same for every line.

use super::point::{Point, binomial};
use glam::{DVec3, DVec4};

/// A B-spline's degree, knots (n+d+1) and n control points of any vector type: homogeneous
/// points for rational curves, or packs of several lines of a surface net refined together.
#[derive(Debug, Clone, PartialEq)]
pub struct Spline<P> {
    pub degree: usize,
    pub knots: Vec<f64>,
    pub points: Vec<P>,
}

/// Homogeneous control points (w·P, w).
pub type HomSpline = Spline<DVec4>;

impl<P> Spline<P> {
    /// [t_d, t_n].
    fn domain(&self) -> (f64, f64) {
        (self.knots[self.degree], self.knots[self.points.len()])
    }
}

/// CurveKnotIns (NURBS Book A5.1, Böhm): inserts `t` `r` times. The caller checks that t lies
/// in the domain and that the resulting multiplicity stays at most the degree.
#[must_use]
pub fn curve_knot_ins<P: Point>(c: &Spline<P>, t: f64, r: usize) -> Spline<P> {
    let plan = KnotInsertion::new(&c.knots, c.degree, c.points.len(), t, r);
    let mut points = vec![P::default(); c.points.len() + r];
    plan.apply(&c.points, &mut points, 1);
    Spline {
        degree: c.degree,
        knots: plan.knots,
        points,
    }
}

/// CurveKnotIns split in two: the new knots and the coefficients of the affected points
/// depend on the knots alone, so every line of a surface net (or a whole row of lines at once)
/// reuses them.
#[derive(Debug, Clone, PartialEq)]
pub struct KnotInsertion {
    /// The refined knot vector.
    pub knots: Vec<f64>,
    /// FindSpan of t, t's multiplicity before, the degree and the insertion count.
    k: usize,
    s: usize,
    p: usize,
    r: usize,
    /// Per step j = 1..=r, the α of the points i = 0..keep−j of the affected block.
    alphas: Vec<Vec<f64>>,
}

impl KnotInsertion {
    #[must_use]
    pub fn new(u: &[f64], p: usize, n: usize, t: f64, r: usize) -> Self {
        let k = find_span(u, p, n, t);
        let s = u.iter().filter(|&&x| x == t).count();
        let keep = (p + 1).saturating_sub(s);
        let alphas = (1..=r)
            .map(|j| {
                let l = k - p + j;
                (0..keep.saturating_sub(j))
                    .map(|i| (t - u[l + i]) / (u[i + k + 1] - u[l + i]))
                    .collect()
            })
            .collect();
        let mut knots = Vec::with_capacity(u.len() + r);
        knots.extend_from_slice(&u[..=k]);
        knots.extend(std::iter::repeat_n(t, r));
        knots.extend_from_slice(&u[k + 1..]);
        Self {
            knots,
            k,
            s,
            p,
            r,
            alphas,
        }
    }

    /// Refines `old` (n blocks of `width` values: a point, or a whole row of points) into `new`
    /// (n + r blocks). Unaffected blocks are copied; the affected ones are Böhm's combinations.
    pub fn apply<P: Point>(&self, old: &[P], new: &mut [P], width: usize) {
        let (k, s, p, r) = (self.k, self.s, self.p, self.r);
        let n = old.len() / width;
        let blocks = |a: usize, b: usize| a * width..b * width;
        if r == 0 {
            new.copy_from_slice(old);
            return;
        }
        // Unaffected points keep their places (shifted by r after the affected block).
        new[blocks(0, k - p + 1)].copy_from_slice(&old[blocks(0, k - p + 1)]);
        new[blocks(k - s + r, n + r)].copy_from_slice(&old[blocks(k - s, n)]);
        let keep = p + 1 - s;
        let mut rw: Vec<P> = old[blocks(k - p, k - p + keep)].to_vec();
        let mut l = k - p;
        for (j, alphas) in (1..=r).zip(&self.alphas) {
            l = k - p + j;
            for (i, &alpha) in alphas.iter().enumerate() {
                let (lo, hi) = rw[blocks(i, i + 2)].split_at_mut(width);
                for (a, &b) in lo.iter_mut().zip(hi.iter()) {
                    *a = b * alpha + *a * (1.0 - alpha);
                }
            }
            new[blocks(l, l + 1)].copy_from_slice(&rw[blocks(0, 1)]);
            let last = k + r - j - s;
            new[blocks(last, last + 1)].copy_from_slice(&rw[blocks(keep - j - 1, keep - j)]);
        }
        if l + 1 < k - s {
            new[blocks(l + 1, k - s)].copy_from_slice(&rw[blocks(1, k - s - l)]);
        }
    }
}

/// FindSpan (A2.1) on raw knots: t_k ≤ t < t_{k+1}, d ≤ k ≤ n−1; t_n maps to the last
/// non-empty span.
fn find_span(u: &[f64], p: usize, n: usize, t: f64) -> usize {
    if t >= u[n] {
        let mut i = n - 1;
        while i > p && u[i] == u[i + 1] {
            i -= 1;
        }
        return i;
    }
    let (mut lo, mut hi) = (p, n);
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if t < u[mid] {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    lo
}

/// The same curve on its domain [t_d, t_n] with clamped ends (both end knots of multiplicity
/// d+1): end knots are inserted to multiplicity d, then the knots and points outside the domain
/// are dropped. Clamped curves come back unchanged.
#[must_use]
pub fn clamp<P: Point>(c: &Spline<P>) -> Spline<P> {
    let start = clamp_start(c);
    let reversed = reverse(&start);
    reverse(&clamp_start(&reversed))
}

fn clamp_start<P: Point>(c: &Spline<P>) -> Spline<P> {
    let p = c.degree;
    let (a, _) = c.domain();
    let mult = c.knots.iter().filter(|&&x| x == a).count();
    let first = c.knots.iter().position(|&x| x == a).expect("t_d is a knot");
    if first == 0 && mult == p + 1 {
        return c.clone();
    }
    let (c, mult) = if mult < p {
        (curve_knot_ins(c, a, p - mult), p)
    } else {
        (c.clone(), mult)
    };
    let first = c.knots.iter().position(|&x| x == a).expect("t_d is a knot");
    // Span k = first + mult − 1 (the last knot equal to a); its active points start at k − p.
    let k = first + mult - 1;
    let mut knots = vec![a; p + 1];
    knots.extend_from_slice(&c.knots[first + mult..]);
    Spline {
        degree: p,
        knots,
        points: c.points[k - p..].to_vec(),
    }
}

/// The curve with its parameter reversed (t ↦ −t): knots negated in reverse order.
fn reverse<P: Point>(c: &Spline<P>) -> Spline<P> {
    Spline {
        degree: c.degree,
        knots: c.knots.iter().rev().map(|&x| -x).collect(),
        points: c.points.iter().rev().copied().collect(),
    }
}

/// Degree elevation by `t` (DegreeElevateCurve): the same curve of degree d+t; every knot's
/// multiplicity grows by t, so the continuity there is kept. Unclamped curves are clamped first;
/// interior knots of multiplicity d+1 (jumps) split the curve into pieces elevated separately.
///
/// The NURBS Book's A5.9 removes again, on the fly, the knots its Bézier decomposition
/// inserted, and knot removal extrapolates: beside a short span, or at a high degree, it
/// amplifies rounding without bound (a degree-11 elevation next to a span of 1e-4 moved a curve
/// 3 units across by 5.5). Here every new control point is a convex combination of old ones
/// ([`elevate_once`]), so the elevated net is accurate to a few roundings of the net's size at
/// every degree and knot spacing.
#[must_use]
pub fn degree_elevate<P: Point>(c: &Spline<P>, t: usize) -> Spline<P> {
    if t == 0 {
        return c.clone();
    }
    let pieces = split_at_jumps(&clamp(c));
    join_at_jumps(pieces.iter().map(|piece| elevate_piece(piece, t)))
}

/// DegreeElevateCurve for many curves on one knot vector (the lines of a net, A5.10): the
/// elevation is linear, Q_j = Σ_l E_{j,l} P_l on the clamped points, and E depends on the knots
/// alone, so it is computed once and every line costs d+2 products per new point.
///
/// E comes from [`degree_elevate`] itself, run on unit points: E_{j,l} ≠ 0 only where the new
/// B-spline N'_j has its support inside the old N_l's (on a span outside it N_l vanishes and the
/// N'_j there are independent), which leaves at most d+1 consecutive l for each j. So unit
/// points d+2 apart share a lane without meeting in any new point, and one run of 16 lanes
/// gives E for up to degree 14. Its entries are convex weights (rows sum to 1), like those of
/// the elevation they record: E·P is as stable.
#[derive(Debug, Clone, PartialEq)]
pub struct Elevation {
    /// The elevated degree and knots.
    degree: usize,
    knots: Vec<f64>,
    /// Per new point j: the first clamped point it weighs and the weights.
    rows: Vec<(usize, Vec<f64>)>,
}

impl Elevation {
    /// The elevation by `t` of degree-`degree` curves on `knots` (any count of points).
    #[must_use]
    pub fn new(degree: usize, knots: &[f64], t: usize) -> Self {
        let count = knots.len() - degree - 1;
        let lanes = 4 * LINES;
        let clamped = clamp(&Spline {
            degree,
            knots: knots.to_vec(),
            points: vec![0.0; count],
        })
        .knots;
        let n = clamped.len() - degree - 1;
        // Unit points l ≡ c (mod apart) share lane c.
        let apart = degree + 2;
        let runs: Vec<Spline<Pack>> = (0..apart)
            .step_by(lanes)
            .map(|base| {
                let points = (0..n)
                    .map(|l| {
                        let mut p = Pack::default();
                        if let Some(lane) = (l % apart).checked_sub(base).filter(|&c| c < lanes) {
                            p.0[lane] = 1.0;
                        }
                        p
                    })
                    .collect();
                let unit = Spline {
                    degree,
                    knots: clamped.clone(),
                    points,
                };
                degree_elevate(&unit, t)
            })
            .collect();
        let (q, raised) = (runs[0].degree, &runs[0].knots);
        let rows = (0..runs[0].points.len())
            .map(|j| {
                // The first l with N'_j's support inside N_l's: u_{l+d+1} ≥ û_{j+q+1}.
                let first = clamped.partition_point(|&x| x < raised[j + q + 1]);
                let lo = first.saturating_sub(degree + 1);
                let weights = (lo..(lo + apart).min(n))
                    .map(|l| {
                        let c = l % apart;
                        runs[c / lanes].points[j].0[c % lanes]
                    })
                    .collect();
                (lo, weights)
            })
            .collect();
        Self {
            degree: q,
            knots: runs[0].knots.clone(),
            rows,
        }
    }

    /// The elevated curve of `c`, whose degree and knots are the ones this was made for.
    #[must_use]
    pub fn apply<P: Point>(&self, c: &Spline<P>) -> Spline<P> {
        let c = clamp(c);
        let points = self
            .rows
            .iter()
            .map(|(lo, w)| {
                w.iter()
                    .zip(&c.points[*lo..])
                    .fold(P::default(), |acc, (&w, &p)| acc + p * w)
            })
            .collect();
        Spline {
            degree: self.degree,
            knots: self.knots.clone(),
            points,
        }
    }
}

/// One clamped piece without jumps elevated by t: a Bézier span in one step, a B-spline by t
/// steps of one.
fn elevate_piece<P: Point>(piece: &Spline<P>, t: usize) -> Spline<P> {
    if piece.points.len() == piece.degree + 1 {
        return elevate_bezier(piece, t);
    }
    let mut c = elevate_once(piece);
    for _ in 1..t {
        c = elevate_once(&c);
    }
    c
}

/// Pieces clamped at shared jumps joined again: d+1 copies of each jump, once.
fn join_at_jumps<P: Point>(pieces: impl Iterator<Item = Spline<P>>) -> Spline<P> {
    pieces
        .reduce(|mut acc, e| {
            acc.knots.extend_from_slice(&e.knots[e.degree + 1..]);
            acc.points.extend_from_slice(&e.points);
            acc
        })
        .expect("a curve has at least one piece")
}

/// Pieces between interior knots of multiplicity d+1, each clamped at both ends.
fn split_at_jumps<P: Point>(c: &Spline<P>) -> Vec<Spline<P>> {
    let p = c.degree;
    let n = c.points.len();
    let mut pieces = Vec::new();
    let (mut k0, mut p0) = (0, 0);
    let mut i = p + 1;
    while i < n {
        let mut j = i;
        while j + 1 < c.knots.len() && c.knots[j + 1] == c.knots[i] {
            j += 1;
        }
        if j - i + 1 == p + 1 {
            // Knots i..=j are the jump: the left piece ends with point i−1, the right starts at i.
            pieces.push(Spline {
                degree: p,
                knots: c.knots[k0..=j].to_vec(),
                points: c.points[p0..i].to_vec(),
            });
            k0 = i;
            p0 = i;
        }
        i = j + 1;
    }
    pieces.push(Spline {
        degree: p,
        knots: c.knots[k0..].to_vec(),
        points: c.points[p0..].to_vec(),
    });
    pieces
}

/// Bézier degree-elevation coefficients: Q_i = Σ_j C(p,j)C(t,i−j)/C(p+t,i) P_j.
fn bezier_alphas(p: usize, t: usize) -> Vec<Vec<f64>> {
    let ph = p + t;
    (0..=ph)
        .map(|i| {
            (0..=p)
                .map(|j| {
                    if j <= i && i - j <= t {
                        binomial(p, j) * binomial(t, i - j) / binomial(ph, i)
                    } else {
                        0.0
                    }
                })
                .collect()
        })
        .collect()
}

/// A single Bézier span (d+1 points, clamped knots) elevated by t.
fn elevate_bezier<P: Point>(c: &Spline<P>, t: usize) -> Spline<P> {
    let p = c.degree;
    let ph = p + t;
    let alphas = bezier_alphas(p, t);
    let points = alphas
        .iter()
        .map(|row| {
            row.iter()
                .zip(&c.points)
                .fold(P::default(), |acc, (&a, &q)| acc + q * a)
        })
        .collect();
    let (a, b) = (c.knots[0], c.knots[c.knots.len() - 1]);
    let mut knots = vec![a; ph + 1];
    knots.extend(std::iter::repeat_n(b, ph + 1));
    Spline {
        degree: ph,
        knots,
        points,
    }
}

/// Elevation by one of a clamped curve whose interior knots have multiplicity at most d, by
/// blossoming (Prautzsch and Piper, "A fast algorithm to raise the degree of spline curves",
/// CAGD 8, 1991). The elevated knots û repeat every distinct knot once more. New control point
/// j is the degree-(d+1) blossom at û_{j+1}, …, û_{j+d+1}, the mean of the d+1 degree-d blossoms
/// that leave one of those arguments out. Leaving out û_k with k ≡ r (mod d+1) leaves d
/// consecutive knots of τ_r, û without every (d+1)-th knot from index r on ([`Thinning`]). Each
/// τ_r refines the old knots (a value loses at most one of its m+1 copies), so that blossom is a
/// control point of the curve refined to τ_r (RefineKnotVectCurve, A5.4), and every new point
/// is the mean of one point of each of the d+1 refinements: convex combinations throughout.
fn elevate_once<P: Point>(c: &Spline<P>) -> Spline<P> {
    let p = c.degree;
    let knots = raised_knots(&c.knots);
    let count = knots.len() - (p + 2);
    let share = 1.0 / (p + 1) as f64;
    let mut points = vec![P::default(); count];
    for r in 0..=p {
        let thinning = Thinning::new(&knots, p, r);
        let refined = refine_knot_vect(c, &missing(&c.knots, &thinning.knots));
        debug_assert_eq!(refined.knots, thinning.knots);
        for (j, q) in points.iter_mut().enumerate() {
            *q += refined.points[thinning.point(j)] * share;
        }
    }
    Spline {
        degree: p + 1,
        knots,
        points,
    }
}

/// Every distinct knot once more: the knots of the curve elevated by one.
fn raised_knots(u: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(2 * u.len());
    for (i, &x) in u.iter().enumerate() {
        out.push(x);
        if u.get(i + 1) != Some(&x) {
            out.push(x);
        }
    }
    out
}

/// The knots of `finer` that `coarser` lacks (both sorted, `finer` ⊇ `coarser` as multisets).
fn missing(coarser: &[f64], finer: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(finer.len() - coarser.len());
    let mut next = coarser.iter().peekable();
    for &x in finer {
        if next.peek() == Some(&&x) {
            next.next();
        } else {
            out.push(x);
        }
    }
    out
}

/// τ_r for the elevation by one of a degree-d curve: the raised knots û without those at
/// indices ≡ r (mod d+1), each end topped up to d+1 copies again.
struct Thinning {
    knots: Vec<f64>,
    degree: usize,
    r: usize,
    /// 1 when the thinning dropped two copies of the first knot (r = 0) and one was put back.
    front: usize,
}

impl Thinning {
    fn new(raised: &[f64], degree: usize, r: usize) -> Self {
        let m = degree + 1;
        let front = usize::from(r == 0);
        let mut knots = Vec::with_capacity(raised.len());
        knots.extend(std::iter::repeat_n(raised[0], front));
        knots.extend(
            raised
                .iter()
                .enumerate()
                .filter(|(k, _)| k % m != r)
                .map(|(_, &x)| x),
        );
        let last = raised[raised.len() - 1];
        if knots.iter().rev().take_while(|&&x| x == last).count() == degree {
            knots.push(last);
        }
        Self {
            knots,
            degree,
            r,
            front,
        }
    }

    /// The control point of the curve refined to τ_r whose knots are those of elevated point j,
    /// û_{j+1}, …, û_{j+d+1}, without the one at an index ≡ r (mod d+1).
    fn point(&self, j: usize) -> usize {
        let m = self.degree + 1;
        // The knot left out is û_{j+l}, 1 ≤ l ≤ d+1 (l = 0 below stands for d+1), and the
        // blossom's first knot û_s.
        let l = (self.r + m - j % m) % m;
        let s = if l == 1 { j + 2 } else { j + 1 };
        // Knots before û_s that τ_r dropped: indices i < s with i ≡ r.
        let dropped = (s + self.degree - self.r) / m;
        s - dropped + self.front - 1
    }
}

/// RefineKnotVectCurve (NURBS Book A5.4): inserts the sorted knots `x`, all inside the domain,
/// in one pass from the right. Every new point is a convex combination of two others, so the
/// refinement is stable however short the spans.
fn refine_knot_vect<P: Point>(c: &Spline<P>, x: &[f64]) -> Spline<P> {
    if x.is_empty() {
        return c.clone();
    }
    let (p, u, pw) = (c.degree, &c.knots, &c.points);
    let n = pw.len() - 1;
    let m = n + p + 1;
    let r = x.len() - 1;
    let a = find_span(u, p, n + 1, x[0]);
    let b = find_span(u, p, n + 1, x[r]) + 1;
    let mut qw = vec![P::default(); n + r + 2];
    let mut ubar = vec![0.0; m + r + 2];
    qw[..=a - p].copy_from_slice(&pw[..=a - p]);
    qw[b + r..].copy_from_slice(&pw[b - 1..]);
    ubar[..=a].copy_from_slice(&u[..=a]);
    ubar[b + p + r + 1..].copy_from_slice(&u[b + p..]);
    let mut i = b + p - 1;
    let mut k = b + p + r;
    for &xj in x.iter().rev() {
        while xj <= u[i] && i > a {
            qw[k - p - 1] = pw[i - p - 1];
            ubar[k] = u[i];
            k -= 1;
            i -= 1;
        }
        qw[k - p - 1] = qw[k - p];
        for l in 1..=p {
            let ind = k - p + l;
            let num = ubar[k + l] - xj;
            qw[ind - 1] = if num == 0.0 {
                qw[ind]
            } else {
                let alfa = num / (ubar[k + l] - u[i - p + l]);
                qw[ind - 1] * alfa + qw[ind] * (1.0 - alfa)
            };
        }
        ubar[k] = xj;
        k -= 1;
    }
    Spline {
        degree: p,
        knots: ubar,
        points: qw,
    }
}

/// Lines of a net refined together: their homogeneous coordinates side by side, so every step
/// of a refinement algorithm is one short loop over the lanes (which the compiler vectorises)
/// instead of one call per line.
const LINES: usize = 4;

/// `LINES` homogeneous points, one per line: lanes 4l..4l+4 hold line l's (w·P, w).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pack([f64; 4 * LINES]);

impl Default for Pack {
    fn default() -> Self {
        Pack([0.0; 4 * LINES])
    }
}

impl std::ops::Add for Pack {
    type Output = Pack;
    #[inline(always)]
    fn add(self, o: Pack) -> Pack {
        Pack(std::array::from_fn(|i| self.0[i] + o.0[i]))
    }
}

impl std::ops::Sub for Pack {
    type Output = Pack;
    #[inline(always)]
    fn sub(self, o: Pack) -> Pack {
        Pack(std::array::from_fn(|i| self.0[i] - o.0[i]))
    }
}

impl std::ops::AddAssign for Pack {
    #[inline(always)]
    fn add_assign(&mut self, o: Pack) {
        for (a, b) in self.0.iter_mut().zip(o.0) {
            *a += b;
        }
    }
}

impl std::ops::Mul<f64> for Pack {
    type Output = Pack;
    #[inline(always)]
    fn mul(self, k: f64) -> Pack {
        Pack(self.0.map(|x| x * k))
    }
}

impl Point for Pack {
    fn max_abs(self) -> f64 {
        self.0.iter().fold(0.0, |m, x| m.max(x.abs()))
    }
}

/// A refined net: the refined direction's degree and knots, the new count, and the control
/// points (row-major) with their weights when the net is rational.
#[derive(Debug, Clone, PartialEq)]
pub struct RefinedNet {
    pub degree: usize,
    pub knots: Vec<f64>,
    pub count: [usize; 2],
    pub points: Vec<DVec3>,
    pub weights: Option<Vec<f64>>,
}

/// Runs a curve refinement on every line of a `count = [nu, nv]` row-major net along `dir`
/// (0: the lines of constant v index, running in u; 1: those of constant u index), `LINES`
/// lines at a time, in homogeneous coordinates. The refinement's coefficients depend only on
/// the knots, so all lines come out with the same degree and knots. Only the result is
/// allocated at the net's size: for a large net, fresh pages cost more than the arithmetic.
#[must_use]
pub fn refine_net(
    degree: usize,
    knots: &[f64],
    count: [usize; 2],
    (points, weights): (&[DVec3], Option<&[f64]>),
    dir: usize,
    refine: impl Fn(&Spline<Pack>) -> Spline<Pack>,
) -> RefinedNet {
    let [nu, nv] = count;
    let (lines, len) = if dir == 0 { (nv, nu) } else { (nu, nv) };
    let index = |line: usize, i: usize, cols: usize| {
        if dir == 0 {
            i * cols + line
        } else {
            line * cols + i
        }
    };
    let mut out = RefinedNet {
        degree,
        knots: Vec::new(),
        count,
        points: Vec::new(),
        weights: None,
    };
    let mut input = Spline {
        degree,
        knots: knots.to_vec(),
        points: vec![Pack::default(); len],
    };
    for first in (0..lines).step_by(LINES) {
        let group = first..(first + LINES).min(lines);
        for (i, p) in input.points.iter_mut().enumerate() {
            for (l, line) in group.clone().enumerate() {
                let k = index(line, i, nv);
                let w = weights.map_or(1.0, |w| w[k]);
                let h = (points[k] * w).extend(w);
                p.0[4 * l..4 * l + 4].copy_from_slice(&h.to_array());
            }
        }
        let r = refine(&input);
        if out.points.is_empty() {
            out.count = if dir == 0 {
                [r.points.len(), nv]
            } else {
                [nu, r.points.len()]
            };
            let n = out.count[0] * out.count[1];
            out.points = vec![DVec3::ZERO; n];
            out.weights = weights.map(|_| vec![0.0; n]);
            out.degree = r.degree;
            out.knots = r.knots;
        }
        for (i, p) in r.points.iter().enumerate() {
            for (l, line) in group.clone().enumerate() {
                let k = index(line, i, out.count[1]);
                let h = &p.0[4 * l..4 * l + 4];
                out.points[k] = DVec3::new(h[0], h[1], h[2]) / h[3];
                if let Some(w) = out.weights.as_mut() {
                    w[k] = h[3];
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// de Boor's algorithm on raw knots (FindSpan, then the triangle): an evaluator of its own.
    fn eval(c: &Spline<DVec4>, t: f64) -> DVec3 {
        let p = c.degree;
        let k = find_span(&c.knots, p, c.points.len(), t);
        let mut d = c.points[k - p..=k].to_vec();
        for r in 1..=p {
            for j in (r..=p).rev() {
                let (lo, hi) = (c.knots[j + k - p], c.knots[j + 1 + k - r]);
                let a = (t - lo) / (hi - lo);
                d[j] = d[j] * a + d[j - 1] * (1.0 - a);
            }
        }
        d[p].truncate() / d[p].w
    }

    /// A clamped curve of degree `p` on [0, 1] with interior knots `inner`, wavy points and,
    /// when `rational`, weights between 0.5 and 2.
    fn curve(p: usize, inner: &[f64], rational: bool) -> Spline<DVec4> {
        let mut knots = vec![0.0; p + 1];
        knots.extend_from_slice(inner);
        knots.extend(std::iter::repeat_n(1.0, p + 1));
        let n = knots.len() - p - 1;
        let points = (0..n)
            .map(|i| {
                let x = i as f64;
                let w = if rational {
                    1.25 + 0.75 * (1.7 * x).sin()
                } else {
                    1.0
                };
                (DVec3::new((0.9 * x).sin(), (1.3 * x).cos(), (0.4 * x).sin() * 2.0) * w).extend(w)
            })
            .collect();
        Spline {
            degree: p,
            knots,
            points,
        }
    }

    /// The bounding box of the projected points, grown by `slack` of its diagonal.
    fn bounds(c: &Spline<DVec4>) -> (DVec3, DVec3, f64) {
        let pts = c.points.iter().map(|h| h.truncate() / h.w);
        let (lo, hi) = pts.fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p), hi.max(p))
        });
        (lo, hi, (hi - lo).length())
    }

    /// Largest distance between the two curves at 40 points per span of `b`, over the size.
    fn moved(a: &Spline<DVec4>, b: &Spline<DVec4>) -> f64 {
        let (_, _, size) = bounds(a);
        let mut worst = 0.0f64;
        for w in b.knots.windows(2).filter(|w| w[0] < w[1]) {
            for i in 0..=40 {
                let t = w[0] + (w[1] - w[0]) * i as f64 / 40.0;
                worst = super::super::point::nan_max(worst, (eval(a, t) - eval(b, t)).length());
            }
        }
        worst / size
    }

    #[test]
    fn refine_knot_vect_equals_insertion_one_knot_at_a_time() {
        let c = curve(4, &[0.2, 0.2, 0.5, 0.7], true);
        let x = [0.1, 0.2, 0.2, 0.35, 0.5, 0.5, 0.9, 0.9];
        let all = refine_knot_vect(&c, &x);
        let mut one = c.clone();
        for &t in &x {
            one = curve_knot_ins(&one, t, 1);
        }
        assert_eq!(all.knots, one.knots);
        for (a, b) in all.points.iter().zip(&one.points) {
            assert!((*a - *b).length() < 1e-14, "{a} {b}");
        }
        assert_eq!(refine_knot_vect(&c, &[]), c);
    }

    #[test]
    fn thinned_knots_refine_the_old_ones_and_index_the_blossoms() {
        // Knots of multiplicity 1 to d, the ends d+1.
        let c = curve(3, &[0.25, 0.5, 0.5, 0.75, 0.75, 0.75], false);
        let raised = raised_knots(&c.knots);
        assert_eq!(raised.len(), c.knots.len() + 5);
        for r in 0..=3 {
            let t = Thinning::new(&raised, 3, r);
            assert_eq!(
                missing(&c.knots, &t.knots).len() + c.knots.len(),
                t.knots.len()
            );
            assert_eq!(&t.knots[..4], &[0.0; 4]);
            assert_eq!(&t.knots[t.knots.len() - 4..], &[1.0; 4]);
            let n = t.knots.len() - 4;
            // Point j's knots in τ_r are û_{j+1..=j+4} less the one at an index ≡ r (mod 4).
            for j in 0..raised.len() - 5 {
                let i = t.point(j);
                assert!(i < n, "r {r} j {j}");
                let mut want: Vec<f64> = (j + 1..=j + 4)
                    .filter(|k| k % 4 != r)
                    .map(|k| raised[k])
                    .collect();
                want.truncate(3);
                assert_eq!(&t.knots[i + 1..=i + 3], &want[..], "r {r} j {j}");
            }
        }
    }

    /// The curves: high degrees next to a short span. A5.9's knot removal sent the net
    /// far outside the old one (5.5 on a curve 3 across); convex combinations stay inside it.
    #[test]
    fn elevation_beside_short_spans_stays_inside_the_net_and_on_the_curve() {
        for (p, inner) in [
            (10, vec![0.5, 0.5001]),
            (10, vec![0.0001]),
            (30, vec![0.3, 0.3 + 1e-6, 0.9]),
            (63, vec![1e-6, 0.5]),
        ] {
            for rational in [false, true] {
                let c = curve(p, &inner, rational);
                let (lo, hi, size) = bounds(&c);
                for by in [1, 2, 5] {
                    if p + by > 64 {
                        continue;
                    }
                    let e = degree_elevate(&c, by);
                    assert_eq!(e.degree, p + by);
                    assert_eq!(e.knots.len(), c.knots.len() + by * (inner.len() + 2));
                    for q in e.points.iter().map(|h| h.truncate() / h.w) {
                        let slack = 1e-13 * size;
                        assert!(
                            q.cmpge(lo - slack).all() && q.cmple(hi + slack).all(),
                            "degree {p} + {by}: {q} outside [{lo}, {hi}]"
                        );
                    }
                    let m = moved(&c, &e);
                    assert!(
                        m < 1e-13,
                        "degree {p} + {by} (rational {rational}): moved {m:e}"
                    );
                }
            }
        }
    }

    /// The net form (E computed once) equals elevating each curve, on clamped and unclamped
    /// knots, with jumps, at degrees that need one and several runs of lanes.
    #[test]
    fn the_elevation_matrix_equals_elevating_each_curve() {
        let mut cases = vec![
            curve(3, &[0.25, 0.5, 0.5, 0.5001], true),
            curve(2, &[0.3, 0.3, 0.3, 0.6], false),
            curve(20, &[1e-6, 0.5, 0.7], true),
            curve(40, &[0.5], false),
        ];
        let mut unclamped = curve(4, &[0.2, 0.4, 0.6], true);
        unclamped.knots = (0..unclamped.knots.len()).map(|i| i as f64 * 0.1).collect();
        cases.push(unclamped);
        for c in cases {
            for by in [1, 3] {
                if c.degree + by > 64 {
                    continue;
                }
                let (direct, plan) = (
                    degree_elevate(&c, by),
                    Elevation::new(c.degree, &c.knots, by),
                );
                let net = plan.apply(&c);
                assert_eq!((net.degree, &net.knots), (direct.degree, &direct.knots));
                let (_, _, size) = bounds(&c);
                for (a, b) in net.points.iter().zip(&direct.points) {
                    let d = (a.truncate() / a.w - b.truncate() / b.w).length();
                    assert!(d < 1e-13 * size, "degree {} + {by}: {a} {b}", c.degree);
                }
                for (_, w) in &plan.rows {
                    let sum: f64 = w.iter().sum();
                    assert!((sum - 1.0).abs() < 1e-13 && w.iter().all(|&x| x >= 0.0));
                }
            }
        }
    }

    #[test]
    fn elevation_by_one_equals_the_bezier_elevation_on_one_span() {
        let c = curve(5, &[], true);
        let (a, b) = (elevate_once(&c), elevate_bezier(&c, 1));
        assert_eq!(a.knots, b.knots);
        for (x, y) in a.points.iter().zip(&b.points) {
            assert!((*x - *y).length() < 1e-14, "{x} {y}");
        }
    }
}
