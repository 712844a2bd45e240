//! Hierarchical ERBS, independently: constructed (`from`), nested, closed and refined ERBS curves
//! and surfaces, written from the definitions and docs/scene-format.md only.
//!
//! Differences from the product on purpose:
//!
//! * A local keeps the parameter it was given and is reached through an affine map from the
//!   parent's parameter (chain rule per level), instead of being re-placed into the parent's
//!   parameter at every depth.
//! * Refinement never splits a local: restricting a local to a shorter support does not change
//!   it as a function, so the oracle only records the new knot and evaluates the old local.
//! * The Hermite (Taylor) local's Bernstein points come from the polar form of the Taylor
//!   polynomial, b_i = P[a^{d−i}, b^i] with (t − c)^r ↦ e_r(x_1 − c, …, x_d − c)/C(d, r), not
//!   from a power-to-Bernstein conversion.

use serde_json::{Map, Value, json};

use super::bfunction::BFunction;
use super::eval::{Basis, Point3, add, binomial, scale, tensor_derivatives};
use super::scene::Object;

/// One parameter direction: knots, open or closed, and the window actually used.
#[derive(Clone, Debug)]
pub struct Dir {
    pub knots: Vec<f64>,
    pub closed: bool,
    pub window: (f64, f64),
}

impl Dir {
    fn new(knots: Vec<f64>, closed: bool) -> Dir {
        let window = if closed {
            (knots[0], *knots.last().unwrap())
        } else {
            (knots[1], knots[knots.len() - 2])
        };
        Dir {
            knots,
            closed,
            window,
        }
    }

    /// Uniform knots over [a, b] for n locals (open: t_1 = a … t_n = b; closed: k_0 = a … k_n = b).
    fn uniform(a: f64, b: f64, n: usize, closed: bool) -> Dir {
        let steps = if closed { n } else { n - 1 };
        let at = |i: usize| {
            if i == steps {
                b
            } else {
                a + (b - a) * (i as f64 / steps as f64)
            }
        };
        let mut k: Vec<f64> = (0..=steps).map(at).collect();
        if !closed {
            k.insert(0, a);
            k.push(b);
        }
        Dir::new(k, closed)
    }

    pub fn locals(&self) -> usize {
        self.knots.len() - if self.closed { 1 } else { 2 }
    }

    /// Centre of local l (for closed knots, l = n is the period's end).
    pub fn centre(&self, l: usize) -> f64 {
        self.knots[if self.closed { l } else { l + 1 }]
    }

    fn period(&self) -> f64 {
        self.knots[self.knots.len() - 1] - self.knots[0]
    }

    fn intervals(&self) -> usize {
        self.locals() - usize::from(!self.closed)
    }

    /// Support of local l, unwrapped.
    pub fn support(&self, l: usize) -> (f64, f64) {
        if !self.closed {
            return (self.knots[l], self.knots[l + 2]);
        }
        let n = self.locals();
        let lo = if l == 0 {
            self.knots[n - 1] - self.period()
        } else {
            self.knots[l - 1]
        };
        (lo, self.knots[l + 1])
    }

    /// The interval [c_i, c_{i+1}] holding t: interior knots belong to the right, the end to
    /// the last interval.
    fn interval_of(&self, t: f64) -> usize {
        (1..self.intervals())
            .rev()
            .find(|&i| self.centre(i) <= t)
            .unwrap_or(0)
    }

    /// The local blended with weight B on interval i and the shift of its parameter.
    fn right(&self, i: usize) -> (usize, f64) {
        if self.closed && i + 1 == self.locals() {
            (0, self.period())
        } else {
            (i + 1, 0.0)
        }
    }

    /// (1 − B)^(r) and B^(r), r = 0..=n, in the parameter, on interval i.
    fn weights(&self, bf: BFunction, i: usize, t: f64, n: usize) -> [Vec<f64>; 2] {
        let (a, b) = (self.centre(i), self.centre(i + 1));
        let h = b - a;
        let bd = bf.derivatives(((t - a) / h).clamp(0.0, 1.0), n);
        let right: Vec<f64> = bd
            .iter()
            .enumerate()
            .map(|(r, x)| x / h.powi(r as i32))
            .collect();
        let left = right
            .iter()
            .enumerate()
            .map(|(r, &x)| if r == 0 { 1.0 - x } else { -x })
            .collect();
        [left, right]
    }

    /// The knots with t inserted (strictly inside the window and between two centres), and the
    /// interval i it fell in.
    fn insert(&self, t: f64) -> Result<(Dir, usize), String> {
        if !(t > self.window.0 && t < self.window.1) {
            return Err(format!("{t} outside the open window {:?}", self.window));
        }
        let i = self.interval_of(t);
        if t == self.centre(i) || t == self.centre(i + 1) {
            return Err(format!("{t} is a knot"));
        }
        let mut d = self.clone();
        d.knots.insert(if self.closed { i + 1 } else { i + 2 }, t);
        Ok((d, i))
    }
}

/// Parent parameter ↦ own parameter: `from` (the support) onto `to` (the local's own domain).
#[derive(Clone, Copy, Debug)]
pub struct Place {
    pub from: (f64, f64),
    pub to: (f64, f64),
}

impl Place {
    fn slope(&self) -> f64 {
        (self.to.1 - self.to.0) / (self.from.1 - self.from.0)
    }
    fn map(&self, t: f64) -> f64 {
        self.to.0 + (t - self.from.0) * self.slope()
    }
    fn unmap(&self, s: f64) -> f64 {
        self.from.0 + (s - self.to.0) / self.slope()
    }
}

/// A local curve's own geometry.
#[derive(Clone, Debug)]
pub enum CurveKind {
    Bezier(Vec<Point3>),
    BSpline {
        degree: usize,
        knots: Vec<f64>,
        points: Vec<Point3>,
    },
    Erbs(Box<Curve>),
}

#[derive(Clone, Debug)]
pub struct LocalCurve {
    pub kind: CurveKind,
    pub place: Place,
}

impl LocalCurve {
    fn own_domain(kind: &CurveKind) -> (f64, f64) {
        match kind {
            CurveKind::Bezier(_) => (0.0, 1.0),
            CurveKind::BSpline {
                degree,
                knots,
                points,
            } => (knots[*degree], knots[points.len()]),
            CurveKind::Erbs(e) => e.dir.window,
        }
    }

    fn derivatives(&self, t: f64, n: usize) -> Vec<Point3> {
        let s = self.place.map(t);
        let mut d = match &self.kind {
            CurveKind::Bezier(p) => Basis::Bezier.derivatives(p, s, n),
            CurveKind::BSpline {
                degree,
                knots,
                points,
            } => Basis::BSpline {
                degree: *degree,
                knots: knots.clone(),
            }
            .derivatives(points, s, n),
            CurveKind::Erbs(e) => e.derivatives(s, n),
        };
        let k = self.place.slope();
        for (r, x) in d.iter_mut().enumerate() {
            *x = scale(k.powi(r as i32), *x);
        }
        d
    }

    fn degree(&self) -> usize {
        match &self.kind {
            CurveKind::Bezier(p) => p.len() - 1,
            CurveKind::BSpline { degree, .. } => *degree,
            CurveKind::Erbs(e) => e.locals.iter().map(LocalCurve::degree).max().unwrap(),
        }
    }
}

/// An ERBS curve: knots, locals, B-function.
#[derive(Clone, Debug)]
pub struct Curve {
    pub dir: Dir,
    pub locals: Vec<LocalCurve>,
    pub bf: BFunction,
}

impl Curve {
    /// c, c', …, c^(n) at t (clamped to the window), by the Leibniz rule.
    pub fn derivatives(&self, t: f64, n: usize) -> Vec<Point3> {
        let t = t.clamp(self.dir.window.0, self.dir.window.1);
        let i = self.dir.interval_of(t);
        let w = self.dir.weights(self.bf, i, t, n);
        let (r, shift) = self.dir.right(i);
        let mut out = vec![[0.0; 3]; n + 1];
        for (side, (l, s)) in [(i, 0.0), (r, shift)].into_iter().enumerate() {
            let c = self.locals[l].derivatives(t - s, n);
            for (k, o) in out.iter_mut().enumerate() {
                for j in 0..=k {
                    *o = add(*o, scale(binomial(k, j) * w[side][k - j], c[j]));
                }
            }
        }
        out
    }

    /// Local refinement at t (the issue's §2): returns the refined curve and the new index.
    pub fn insert_knot(&self, t: f64, degree: Option<usize>) -> Result<(Curve, usize), String> {
        let (dir, i) = self.dir.insert(t)?;
        let (r, _) = self.dir.right(i);
        let d = degree.unwrap_or_else(|| self.locals[i].degree().max(self.locals[r].degree()));
        let support = (self.dir.centre(i), self.dir.centre(i + 1));
        let new = hermite_curve(&self.derivatives(t, d), t, support);
        let mut locals = self.locals.clone();
        locals.insert(i + 1, new);
        Ok((
            Curve {
                dir,
                locals,
                bf: self.bf,
            },
            i + 1,
        ))
    }

    /// The ERBS local at `path` (empty: this curve).
    pub fn nested(&self, path: &[usize]) -> &Curve {
        match path.split_first() {
            None => self,
            Some((&l, rest)) => match &self.locals[l].kind {
                CurveKind::Erbs(e) => e.nested(rest),
                k => panic!("step {l} is a polynomial local: {k:?}"),
            },
        }
    }

    /// This curve's parameter of the parameter `s` of the ERBS local at `path`.
    pub fn outer_parameter(&self, path: &[usize], s: f64) -> f64 {
        match path.split_first() {
            None => s,
            Some((&l, rest)) => {
                let CurveKind::Erbs(e) = &self.locals[l].kind else {
                    panic!("step {l} is a polynomial local")
                };
                self.locals[l].place.unmap(e.outer_parameter(rest, s))
            }
        }
    }

    /// Refinement of the ERBS local at `path` at `t` in this curve's parameter: the local's
    /// own refinement at its own parameter, its placement unchanged.
    pub fn insert_knot_at(
        &self,
        path: &[usize],
        t: f64,
        degree: Option<usize>,
    ) -> Result<Curve, String> {
        let Some((&l, rest)) = path.split_first() else {
            return Ok(self.insert_knot(t, degree)?.0);
        };
        let mut out = self.clone();
        let local = &mut out.locals[l];
        let CurveKind::Erbs(e) = &local.kind else {
            return Err(format!("step {l} is a polynomial local"));
        };
        let inner = e.insert_knot_at(rest, local.place.map(t), degree)?;
        local.kind = CurveKind::Erbs(Box::new(inner));
        Ok(out)
    }
}

/// The polar form of (t − c)^r of degree d at the multiset {a × (d − i), b × i}, i.e.
/// e_r(a − c, …, b − c)/C(d, r).
fn polar_power(d: usize, r: usize, i: usize, (a, b): (f64, f64), c: f64) -> f64 {
    let (alpha, beta) = (a - c, b - c);
    let mut e = 0.0;
    for j in 0..=r.min(i) {
        if r - j <= d - i {
            e += binomial(d - i, r - j)
                * binomial(i, j)
                * alpha.powi((r - j) as i32)
                * beta.powi(j as i32);
        }
    }
    e / binomial(d, r)
}

fn factorial(r: usize) -> f64 {
    (1..=r).map(|k| k as f64).product()
}

/// The Bézier local on `support` whose derivatives 0..=d at c are `derivs`.
pub fn hermite_curve(derivs: &[Point3], c: f64, support: (f64, f64)) -> LocalCurve {
    let d = derivs.len() - 1;
    let points = (0..=d)
        .map(|i| {
            (0..=d).fold([0.0; 3], |acc, r| {
                add(
                    acc,
                    scale(polar_power(d, r, i, support, c) / factorial(r), derivs[r]),
                )
            })
        })
        .collect();
    LocalCurve {
        kind: CurveKind::Bezier(points),
        place: Place {
            from: support,
            to: (0.0, 1.0),
        },
    }
}

/// A local patch's own geometry (`points[a][b]`, a along u).
#[derive(Clone, Debug)]
pub enum PatchKind {
    Tensor {
        basis: [Basis; 2],
        points: Vec<Vec<Point3>>,
    },
    Erbs(Box<Surface>),
}

#[derive(Clone, Debug)]
pub struct LocalPatch {
    pub kind: PatchKind,
    pub place: [Place; 2],
}

impl LocalPatch {
    fn own_domain(kind: &PatchKind) -> [(f64, f64); 2] {
        match kind {
            PatchKind::Tensor { basis, points } => [
                basis[0].domain(points.len()),
                basis[1].domain(points[0].len()),
            ],
            PatchKind::Erbs(e) => [e.dirs[0].window, e.dirs[1].window],
        }
    }

    fn derivatives(&self, u: f64, v: f64, n: usize) -> Vec<Vec<Point3>> {
        let (s, r) = (self.place[0].map(u), self.place[1].map(v));
        let mut d = match &self.kind {
            PatchKind::Tensor { basis, points } => {
                tensor_derivatives(&basis[0], &basis[1], points, s, r, n)
            }
            PatchKind::Erbs(e) => e.derivatives(s, r, n),
        };
        let (ku, kv) = (self.place[0].slope(), self.place[1].slope());
        for (a, row) in d.iter_mut().enumerate() {
            for (b, x) in row.iter_mut().enumerate() {
                *x = scale(ku.powi(a as i32) * kv.powi(b as i32), *x);
            }
        }
        d
    }

    fn degree(&self) -> [usize; 2] {
        let deg = |b: &Basis, count: usize| match b {
            Basis::Bezier => count - 1,
            Basis::BSpline { degree, .. } => *degree,
        };
        match &self.kind {
            PatchKind::Tensor { basis, points } => [
                deg(&basis[0], points.len()),
                deg(&basis[1], points[0].len()),
            ],
            PatchKind::Erbs(e) => e.locals.iter().fold([0, 0], |m, p| {
                let d = p.degree();
                [m[0].max(d[0]), m[1].max(d[1])]
            }),
        }
    }
}

/// An ERBS surface; `locals` row-major [k][l] with k along u.
#[derive(Clone, Debug)]
pub struct Surface {
    pub dirs: [Dir; 2],
    pub locals: Vec<LocalPatch>,
    pub bf: BFunction,
}

impl Surface {
    pub fn count(&self) -> [usize; 2] {
        [self.dirs[0].locals(), self.dirs[1].locals()]
    }

    /// ∂^{a+b}S for a, b ≤ n at (u, v) (clamped to the window).
    pub fn derivatives(&self, u: f64, v: f64, n: usize) -> Vec<Vec<Point3>> {
        let u = u.clamp(self.dirs[0].window.0, self.dirs[0].window.1);
        let v = v.clamp(self.dirs[1].window.0, self.dirs[1].window.1);
        let (i, j) = (self.dirs[0].interval_of(u), self.dirs[1].interval_of(v));
        let wu = self.dirs[0].weights(self.bf, i, u, n);
        let wv = self.dirs[1].weights(self.bf, j, v, n);
        let (ri, su) = self.dirs[0].right(i);
        let (rj, sv) = self.dirs[1].right(j);
        let nv = self.count()[1];
        let mut out = vec![vec![[0.0; 3]; n + 1]; n + 1];
        for (a_side, (k, du)) in [(i, 0.0), (ri, su)].into_iter().enumerate() {
            for (b_side, (l, dv)) in [(j, 0.0), (rj, sv)].into_iter().enumerate() {
                let p = self.locals[k * nv + l].derivatives(u - du, v - dv, n);
                for a in 0..=n {
                    for b in 0..=n {
                        for x in 0..=a {
                            for y in 0..=b {
                                let c =
                                    binomial(a, x) * binomial(b, y) * wu[a_side][x] * wv[b_side][y];
                                out[a][b] = add(out[a][b], scale(c, p[a - x][b - y]));
                            }
                        }
                    }
                }
            }
        }
        out
    }

    /// Refinement in direction `dir` (0 = u): a new row (u) or column (v) of Hermite patches.
    pub fn insert_knot(
        &self,
        dir: usize,
        t: f64,
        degree: Option<[usize; 2]>,
    ) -> Result<(Surface, usize), String> {
        let (new_dir, i) = self.dirs[dir].insert(t)?;
        let (r, _) = self.dirs[dir].right(i);
        let other = 1 - dir;
        let count = self.count();
        let at = |a: usize, m: usize| {
            if dir == 0 {
                a * count[1] + m
            } else {
                m * count[1] + a
            }
        };
        let mut new = Vec::new();
        for m in 0..count[other] {
            let (lp, rp) = (&self.locals[at(i, m)], &self.locals[at(r, m)]);
            let d = degree.unwrap_or_else(|| {
                let (x, y) = (lp.degree(), rp.degree());
                [x[0].max(y[0]), x[1].max(y[1])]
            });
            let cm = self.dirs[other].centre(m);
            let mut centre = [0.0; 2];
            centre[dir] = t;
            centre[other] = cm;
            let mut support = [(0.0, 0.0); 2];
            support[dir] = (self.dirs[dir].centre(i), self.dirs[dir].centre(i + 1));
            support[other] = self.dirs[other].support(m);
            let partials = self.derivatives(centre[0], centre[1], d[0].max(d[1]));
            new.push(hermite_patch(&partials, d, (centre[0], centre[1]), support));
        }
        let mut dirs = self.dirs.clone();
        dirs[dir] = new_dir;
        let mut grown = count;
        grown[dir] += 1;
        let mut locals = Vec::with_capacity(grown[0] * grown[1]);
        for k in 0..grown[0] {
            for l in 0..grown[1] {
                let (a, m) = if dir == 0 { (k, l) } else { (l, k) };
                locals.push(match a {
                    a if a == i + 1 => new[m].clone(),
                    a if a > i + 1 => self.locals[at(a - 1, m)].clone(),
                    a => self.locals[at(a, m)].clone(),
                });
            }
        }
        Ok((
            Surface {
                dirs,
                locals,
                bf: self.bf,
            },
            i + 1,
        ))
    }

    fn local_index(&self, [k, l]: [usize; 2]) -> usize {
        k * self.count()[1] + l
    }

    /// The ERBS local at `path` (empty: this surface).
    pub fn nested(&self, path: &[[usize; 2]]) -> &Surface {
        match path.split_first() {
            None => self,
            Some((&kl, rest)) => match &self.locals[self.local_index(kl)].kind {
                PatchKind::Erbs(e) => e.nested(rest),
                _ => panic!("step {kl:?} is a polynomial local"),
            },
        }
    }

    /// This surface's parameter in direction `dir` of the parameter `s` of the ERBS local at
    /// `path`.
    pub fn outer_parameter(&self, path: &[[usize; 2]], dir: usize, s: f64) -> f64 {
        match path.split_first() {
            None => s,
            Some((&kl, rest)) => {
                let local = &self.locals[self.local_index(kl)];
                let PatchKind::Erbs(e) = &local.kind else {
                    panic!("step {kl:?} is a polynomial local")
                };
                local.place[dir].unmap(e.outer_parameter(rest, dir, s))
            }
        }
    }

    /// Refinement in direction `dir` of the ERBS local at `path`, `t` in this surface's
    /// parameter.
    pub fn insert_knot_at(
        &self,
        path: &[[usize; 2]],
        dir: usize,
        t: f64,
        degree: Option<[usize; 2]>,
    ) -> Result<Surface, String> {
        let Some((&kl, rest)) = path.split_first() else {
            return Ok(self.insert_knot(dir, t, degree)?.0);
        };
        let mut out = self.clone();
        let at = out.local_index(kl);
        let local = &mut out.locals[at];
        let PatchKind::Erbs(e) = &local.kind else {
            return Err(format!("step {kl:?} is a polynomial local"));
        };
        let inner = e.insert_knot_at(rest, dir, local.place[dir].map(t), degree)?;
        local.kind = PatchKind::Erbs(Box::new(inner));
        Ok(out)
    }
}

/// The Bézier patch on `support` whose partials a ≤ du, b ≤ dv at `centre` are `partials`.
pub fn hermite_patch(
    partials: &[Vec<Point3>],
    [du, dv]: [usize; 2],
    (cu, cv): (f64, f64),
    support: [(f64, f64); 2],
) -> LocalPatch {
    let points = (0..=du)
        .map(|i| {
            (0..=dv)
                .map(|j| {
                    let mut p = [0.0; 3];
                    for (a, row) in partials.iter().enumerate().take(du + 1) {
                        for (b, &d) in row.iter().enumerate().take(dv + 1) {
                            let c = polar_power(du, a, i, support[0], cu)
                                * polar_power(dv, b, j, support[1], cv)
                                / (factorial(a) * factorial(b));
                            p = add(p, scale(c, d));
                        }
                    }
                    p
                })
                .collect()
        })
        .collect();
    LocalPatch {
        kind: PatchKind::Tensor {
            basis: [Basis::Bezier, Basis::Bezier],
            points,
        },
        place: [
            Place {
                from: support[0],
                to: (0.0, 1.0),
            },
            Place {
                from: support[1],
                to: (0.0, 1.0),
            },
        ],
    }
}

// ---------------------------------------------------------------------------------------------
// Scene JSON (only what the tests write; the product's parser is the one that validates).

fn num(v: &Value) -> f64 {
    v.as_f64().expect("number")
}

fn nums(v: &Value) -> Vec<f64> {
    v.as_array().expect("list").iter().map(num).collect()
}

fn point(v: &Value) -> Point3 {
    let x = nums(v);
    [x[0], x[1], x[2]]
}

fn points(v: &Value) -> Vec<Point3> {
    v.as_array().expect("list").iter().map(point).collect()
}

fn grid(v: &Value) -> Vec<Vec<Point3>> {
    v.as_array().expect("rows").iter().map(points).collect()
}

fn bf_of(obj: &Map<String, Value>) -> BFunction {
    obj.get("bfunction")
        .map(|v| BFunction::from_name(v.as_str().unwrap()).unwrap())
        .unwrap_or(BFunction::Expo)
}

/// A source body (`from`) as an oracle object (the existing evaluator, rational included).
fn source_object(src: &Value, samples: Value) -> Object {
    let mut o = src.as_object().expect("source").clone();
    o.insert("name".into(), json!("source"));
    o.insert("samples".into(), samples);
    Object::from_json(&Value::Object(o)).expect("valid source")
}

/// The source's domain per direction.
fn source_domains(o: &Object) -> Vec<(f64, f64)> {
    o.domains()
}

impl Curve {
    /// An `erbs_curve` body (object or local entry): explicit or `from`.
    pub fn from_json(v: &Value) -> Curve {
        let obj = v.as_object().expect("erbs_curve body");
        let bf = bf_of(obj);
        let closed = obj.get("closed").and_then(Value::as_bool).unwrap_or(false);
        if let Some(src) = obj.get("from") {
            let source = source_object(src, json!(2));
            let (a, b) = source_domains(&source)[0];
            let n = obj["local_curves"].as_u64().unwrap() as usize;
            let d = obj["local_degree"].as_u64().unwrap() as usize;
            let dir = Dir::uniform(a, b, n, closed);
            let locals = (0..n)
                .map(|l| {
                    let c = dir.centre(l);
                    hermite_curve(&source.curve_derivatives(c, d), c, dir.support(l))
                })
                .collect();
            return Curve { dir, locals, bf };
        }
        let mut dir = Dir::new(nums(&obj["knots"]), closed);
        if let Some(w) = obj.get("domain") {
            let w = nums(w);
            dir.window = (w[0], w[1]);
        }
        let locals = obj["local"]
            .as_array()
            .unwrap()
            .iter()
            .enumerate()
            .map(|(l, e)| {
                let kind = curve_kind(e);
                let to = LocalCurve::own_domain(&kind);
                LocalCurve {
                    kind,
                    place: Place {
                        from: dir.support(l),
                        to,
                    },
                }
            })
            .collect();
        Curve { dir, locals, bf }
    }
}

fn curve_kind(e: &Value) -> CurveKind {
    let o = e.as_object().expect("local entry");
    match o
        .get("type")
        .and_then(Value::as_str)
        .unwrap_or("bezier_curve")
    {
        "bezier_curve" => CurveKind::Bezier(points(&o["points"])),
        "bspline_curve" => CurveKind::BSpline {
            degree: o["degree"].as_u64().unwrap() as usize,
            knots: nums(&o["knots"]),
            points: points(&o["points"]),
        },
        "erbs_curve" => CurveKind::Erbs(Box::new(Curve::from_json(e))),
        t => panic!("local type {t}"),
    }
}

impl Surface {
    /// An `erbs_surface` body (object or local entry): explicit or `from`.
    pub fn from_json(v: &Value) -> Surface {
        let obj = v.as_object().expect("erbs_surface body");
        let bf = bf_of(obj);
        let closed = match obj.get("closed") {
            Some(c) => {
                let c = c.as_array().unwrap();
                [c[0].as_bool().unwrap(), c[1].as_bool().unwrap()]
            }
            None => [false, false],
        };
        if let Some(src) = obj.get("from") {
            let source = source_object(src, json!([2, 2]));
            let dom = source_domains(&source);
            let pair = |f: &str| {
                let x = obj[f].as_array().unwrap();
                [
                    x[0].as_u64().unwrap() as usize,
                    x[1].as_u64().unwrap() as usize,
                ]
            };
            let (count, degree) = (pair("local_patches"), pair("local_degree"));
            let dirs = [
                Dir::uniform(dom[0].0, dom[0].1, count[0], closed[0]),
                Dir::uniform(dom[1].0, dom[1].1, count[1], closed[1]),
            ];
            let mut locals = Vec::new();
            for k in 0..count[0] {
                for l in 0..count[1] {
                    let c = (dirs[0].centre(k), dirs[1].centre(l));
                    let partials = source.surface_derivatives(c.0, c.1, degree[0].max(degree[1]));
                    locals.push(hermite_patch(
                        &partials,
                        degree,
                        c,
                        [dirs[0].support(k), dirs[1].support(l)],
                    ));
                }
            }
            return Surface { dirs, locals, bf };
        }
        let knots = obj["knots"].as_array().unwrap();
        let mut dirs = [
            Dir::new(nums(&knots[0]), closed[0]),
            Dir::new(nums(&knots[1]), closed[1]),
        ];
        if let Some(w) = obj.get("domain") {
            let w = w.as_array().unwrap();
            for d in 0..2 {
                let x = nums(&w[d]);
                dirs[d].window = (x[0], x[1]);
            }
        }
        let mut locals = Vec::new();
        for (k, row) in obj["local"].as_array().unwrap().iter().enumerate() {
            for (l, e) in row.as_array().unwrap().iter().enumerate() {
                let kind = patch_kind(e);
                let to = LocalPatch::own_domain(&kind);
                locals.push(LocalPatch {
                    kind,
                    place: [
                        Place {
                            from: dirs[0].support(k),
                            to: to[0],
                        },
                        Place {
                            from: dirs[1].support(l),
                            to: to[1],
                        },
                    ],
                });
            }
        }
        Surface { dirs, locals, bf }
    }
}

fn patch_kind(e: &Value) -> PatchKind {
    let o = e.as_object().expect("local entry");
    match o
        .get("type")
        .and_then(Value::as_str)
        .unwrap_or("bezier_surface")
    {
        "bezier_surface" => PatchKind::Tensor {
            basis: [Basis::Bezier, Basis::Bezier],
            points: grid(&o["points"]),
        },
        "bspline_surface" => {
            let deg = o["degree"].as_array().unwrap();
            let knots = o["knots"].as_array().unwrap();
            let basis = |d: usize| Basis::BSpline {
                degree: deg[d].as_u64().unwrap() as usize,
                knots: nums(&knots[d]),
            };
            PatchKind::Tensor {
                basis: [basis(0), basis(1)],
                points: grid(&o["points"]),
            }
        }
        "erbs_surface" => PatchKind::Erbs(Box::new(Surface::from_json(e))),
        t => panic!("local type {t}"),
    }
}
