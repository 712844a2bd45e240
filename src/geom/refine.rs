//! Refinement that keeps the shape: knot insertion (NURBS Book A5.1 CurveKnotIns, A5.3 per
//! surface direction), clamping, and degree elevation (A5.9 DegreeElevateCurve, A5.10 per
//! surface direction).
//!
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
#[must_use]
pub fn degree_elevate<P: Point>(c: &Spline<P>, t: usize) -> Spline<P> {
    if t == 0 {
        return c.clone();
    }
    let c = clamp(c);
    let p = c.degree;
    let mut out: Option<Spline<P>> = None;
    for piece in split_at_jumps(&c) {
        let e = if piece.points.len() == p + 1 {
            elevate_bezier(&piece, t)
        } else {
            degree_elevate_clamped(&piece, t)
        };
        out = Some(match out {
            None => e,
            Some(mut acc) => {
                // Both pieces are clamped at the jump: keep d+t+1 copies of it once.
                acc.knots.extend_from_slice(&e.knots[e.degree + 1..]);
                acc.points.extend_from_slice(&e.points);
                acc
            }
        });
    }
    out.expect("a curve has at least one piece")
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

/// A5.9 on a clamped curve whose interior knots have multiplicity at most d: Bézier segments
/// are extracted by knot insertion, elevated, and the inserted knots removed again on the fly.
fn degree_elevate_clamped<P: Point>(c: &Spline<P>, t: usize) -> Spline<P> {
    let p = c.degree;
    let u = &c.knots;
    let pw = &c.points;
    let n = pw.len() - 1;
    let m = n + p + 1;
    let ph = p + t;
    let ph2 = ph / 2;
    let bezalfs = bezier_alphas(p, t);
    // The book computes half and mirrors; the closed form above gives the same values, and the
    // mirror symmetry is kept exactly by construction of the binomials.
    debug_assert!((ph2 + 1..ph).all(|i| (0..=p).all(|j| bezalfs[i][j] == bezalfs[ph - i][p - j])));
    let mut mh = ph;
    let mut kind = ph + 1;
    let mut r: isize = -1;
    let mut a = p;
    let mut b = p + 1;
    let mut cind = 1;
    let mut ua = u[0];
    let mut qw = vec![P::default(); (n + 1) * (t + 1) + 1];
    qw[0] = pw[0];
    let mut uh = vec![ua; ph + 1];
    let mut bpts: Vec<P> = pw[..=p].to_vec();
    let mut next_bpts = vec![P::default(); p.max(1)];
    let mut ebpts = vec![P::default(); ph + 1];
    let mut alfs = vec![0.0; p.max(1)];
    while b < m {
        let i0 = b;
        while b < m && u[b] == u[b + 1] {
            b += 1;
        }
        let mul = b - i0 + 1;
        mh += mul + t;
        let ub = u[b];
        let oldr = r;
        r = p as isize - mul as isize;
        // Bézier points of the previous and this segment that knot removal keeps.
        let lbz = if oldr > 0 {
            ((oldr + 2) / 2) as usize
        } else {
            1
        };
        let rbz = if r > 0 {
            ph - ((r + 1) / 2) as usize
        } else {
            ph
        };
        if r > 0 {
            // Insert u[b] r times to get the Bézier segment [ua, ub].
            let numer = ub - ua;
            for k in (mul + 1..=p).rev() {
                alfs[k - mul - 1] = numer / (u[a + k] - ua);
            }
            for j in 1..=r as usize {
                let save = r as usize - j;
                let s = mul + j;
                for k in (s..=p).rev() {
                    bpts[k] = bpts[k] * alfs[k - s] + bpts[k - 1] * (1.0 - alfs[k - s]);
                }
                next_bpts[save] = bpts[p];
            }
        }
        for (i, e) in ebpts.iter_mut().enumerate().skip(lbz) {
            *e = (i.saturating_sub(t)..=p.min(i))
                .fold(P::default(), |acc, j| acc + bpts[j] * bezalfs[i][j]);
        }
        if oldr > 1 {
            // Remove the knot u = ua oldr − 1 times.
            let oldr = oldr as usize;
            let den = ub - ua;
            let bet = (ub - uh[kind - 1]) / den;
            // Each removal step widens the window [first, last] by one on both sides.
            for tr in 1..oldr {
                let (first, last) = (kind - 1 - tr, kind - 1 + tr);
                let (mut i, mut j) = (first, last);
                let mut kj = (j - kind + 1) as isize;
                while j - i > tr {
                    if i < cind {
                        let alf = (ub - uh[i]) / (ua - uh[i]);
                        qw[i] = qw[i] * alf + qw[i - 1] * (1.0 - alf);
                    }
                    if j >= lbz {
                        let k = kj as usize;
                        if j - tr <= kind - ph + oldr {
                            let gam = (ub - uh[j - tr]) / den;
                            ebpts[k] = ebpts[k] * gam + ebpts[k + 1] * (1.0 - gam);
                        } else {
                            ebpts[k] = ebpts[k] * bet + ebpts[k + 1] * (1.0 - bet);
                        }
                    }
                    i += 1;
                    j -= 1;
                    kj -= 1;
                }
            }
        }
        if a != p {
            // Load the knot ua.
            for _ in 0..(ph as isize - oldr) {
                uh.push(ua);
                kind += 1;
            }
        }
        for e in &ebpts[lbz..=rbz] {
            qw[cind] = *e;
            cind += 1;
        }
        if b < m {
            let r0 = r.max(0) as usize;
            bpts[..r0].copy_from_slice(&next_bpts[..r0]);
            for j in r0..=p {
                bpts[j] = pw[b - p + j];
            }
            a = b;
            b += 1;
            ua = ub;
        } else {
            uh.extend(std::iter::repeat_n(ub, ph + 1));
        }
    }
    let count = mh - ph;
    qw.truncate(count);
    debug_assert_eq!(uh.len(), count + ph + 1);
    Spline {
        degree: ph,
        knots: uh,
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
