//! Refinement that keeps the shape: knot insertion (NURBS Book A5.1 CurveKnotIns, A5.3 per
//! surface direction), clamping, and degree elevation (A5.9 DegreeElevateCurve, A5.10 per
//! surface direction).
//!
//! Everything works on homogeneous control points (w·P, w), so rational curves and surfaces
//! refine exactly like polynomial ones; callers project back. Surfaces refine one direction by
//! running the curve algorithm on every line of the net in that direction: the knots and the
//! coefficients are the same for every line.

use super::point::binomial;
use glam::DVec4;

/// A B-spline in homogeneous form: degree, knots (n+d+1) and n homogeneous control points.
#[derive(Debug, Clone, PartialEq)]
pub struct HomSpline {
    pub degree: usize,
    pub knots: Vec<f64>,
    pub points: Vec<DVec4>,
}

impl HomSpline {
    /// [t_d, t_n].
    fn domain(&self) -> (f64, f64) {
        (self.knots[self.degree], self.knots[self.points.len()])
    }
}

/// CurveKnotIns (NURBS Book A5.1, Böhm): inserts `t` `r` times. The caller checks that t lies
/// in the domain and that the resulting multiplicity stays at most the degree.
#[must_use]
pub fn curve_knot_ins(c: &HomSpline, t: f64, r: usize) -> HomSpline {
    if r == 0 {
        return c.clone();
    }
    let p = c.degree;
    let u = &c.knots;
    let pw = &c.points;
    let np = pw.len();
    let k = find_span(u, p, np, t);
    let s = u.iter().filter(|&&x| x == t).count();
    let mut q = vec![DVec4::ZERO; np + r];
    // Unaffected points keep their places (shifted by r after the affected block).
    q[..=k - p].copy_from_slice(&pw[..=k - p]);
    q[k - s + r..np + r].copy_from_slice(&pw[k - s..np]);
    let keep = p + 1 - s;
    let mut rw: Vec<DVec4> = (0..keep).map(|i| pw[k - p + i]).collect();
    let mut l = k - p;
    for j in 1..=r {
        l = k - p + j;
        for i in 0..keep - j {
            let alpha = (t - u[l + i]) / (u[i + k + 1] - u[l + i]);
            rw[i] = rw[i + 1] * alpha + rw[i] * (1.0 - alpha);
        }
        q[l] = rw[0];
        q[k + r - j - s] = rw[keep - j - 1];
    }
    if l + 1 < k - s {
        q[l + 1..k - s].copy_from_slice(&rw[1..k - s - l]);
    }
    let mut knots = Vec::with_capacity(u.len() + r);
    knots.extend_from_slice(&u[..=k]);
    knots.extend(std::iter::repeat_n(t, r));
    knots.extend_from_slice(&u[k + 1..]);
    HomSpline {
        degree: p,
        knots,
        points: q,
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
pub fn clamp(c: &HomSpline) -> HomSpline {
    let start = clamp_start(c);
    let reversed = reverse(&start);
    reverse(&clamp_start(&reversed))
}

fn clamp_start(c: &HomSpline) -> HomSpline {
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
    HomSpline {
        degree: p,
        knots,
        points: c.points[k - p..].to_vec(),
    }
}

/// The curve with its parameter reversed (t ↦ −t): knots negated in reverse order.
fn reverse(c: &HomSpline) -> HomSpline {
    HomSpline {
        degree: c.degree,
        knots: c.knots.iter().rev().map(|&x| -x).collect(),
        points: c.points.iter().rev().copied().collect(),
    }
}

/// Degree elevation by `t` (DegreeElevateCurve): the same curve of degree d+t; every knot's
/// multiplicity grows by t, so the continuity there is kept. Unclamped curves are clamped first;
/// interior knots of multiplicity d+1 (jumps) split the curve into pieces elevated separately.
#[must_use]
pub fn degree_elevate(c: &HomSpline, t: usize) -> HomSpline {
    if t == 0 {
        return c.clone();
    }
    let c = clamp(c);
    let p = c.degree;
    let mut out: Option<HomSpline> = None;
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
fn split_at_jumps(c: &HomSpline) -> Vec<HomSpline> {
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
            pieces.push(HomSpline {
                degree: p,
                knots: c.knots[k0..=j].to_vec(),
                points: c.points[p0..i].to_vec(),
            });
            k0 = i;
            p0 = i;
        }
        i = j + 1;
    }
    pieces.push(HomSpline {
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
fn elevate_bezier(c: &HomSpline, t: usize) -> HomSpline {
    let p = c.degree;
    let ph = p + t;
    let alphas = bezier_alphas(p, t);
    let points = alphas
        .iter()
        .map(|row| {
            row.iter()
                .zip(&c.points)
                .fold(DVec4::ZERO, |acc, (&a, &q)| acc + q * a)
        })
        .collect();
    let (a, b) = (c.knots[0], c.knots[c.knots.len() - 1]);
    let mut knots = vec![a; ph + 1];
    knots.extend(std::iter::repeat_n(b, ph + 1));
    HomSpline {
        degree: ph,
        knots,
        points,
    }
}

/// A5.9 on a clamped curve whose interior knots have multiplicity at most d: Bézier segments
/// are extracted by knot insertion, elevated, and the inserted knots removed again on the fly.
fn degree_elevate_clamped(c: &HomSpline, t: usize) -> HomSpline {
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
    let mut qw = vec![DVec4::ZERO; (n + 1) * (t + 1) + 1];
    qw[0] = pw[0];
    let mut uh = vec![ua; ph + 1];
    let mut bpts: Vec<DVec4> = pw[..=p].to_vec();
    let mut next_bpts = vec![DVec4::ZERO; p.max(1)];
    let mut ebpts = vec![DVec4::ZERO; ph + 1];
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
                .fold(DVec4::ZERO, |acc, j| acc + bpts[j] * bezalfs[i][j]);
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
    HomSpline {
        degree: ph,
        knots: uh,
        points: qw,
    }
}

/// Runs a curve refinement on every line of a `count = [nu, nv]` row-major net along `dir`
/// (0: lines of constant v index, running in u; 1: lines of constant u index). Returns the
/// refined direction's knots and degree, the new count and the new net.
#[must_use]
pub fn refine_net(
    degree: usize,
    knots: &[f64],
    count: [usize; 2],
    net: &[DVec4],
    dir: usize,
    refine: impl Fn(&HomSpline) -> HomSpline,
) -> (HomSpline, [usize; 2], Vec<DVec4>) {
    let [nu, nv] = count;
    let (lines, len) = if dir == 0 { (nv, nu) } else { (nu, nv) };
    let at = |line: usize, i: usize| {
        if dir == 0 {
            i * nv + line
        } else {
            line * nv + i
        }
    };
    let mut refined: Vec<HomSpline> = Vec::with_capacity(lines);
    for line in 0..lines {
        let c = HomSpline {
            degree,
            knots: knots.to_vec(),
            points: (0..len).map(|i| net[at(line, i)]).collect(),
        };
        refined.push(refine(&c));
    }
    let new_len = refined[0].points.len();
    let new_count = if dir == 0 {
        [new_len, nv]
    } else {
        [nu, new_len]
    };
    let mut out = vec![DVec4::ZERO; new_count[0] * new_count[1]];
    for (line, r) in refined.iter().enumerate() {
        for (i, &q) in r.points.iter().enumerate() {
            let idx = if dir == 0 {
                i * new_count[1] + line
            } else {
                line * new_count[1] + i
            };
            out[idx] = q;
        }
    }
    let first = refined.swap_remove(0);
    let shape = HomSpline {
        degree: first.degree,
        knots: first.knots,
        points: Vec::new(),
    };
    (shape, new_count, out)
}
