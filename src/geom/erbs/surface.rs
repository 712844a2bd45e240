//! ERBS tensor-product surfaces: s(u,v) = Σ_k Σ_l s_kl(u,v) B_k(u) B_l(v) with local patches
//! of any kind; built from a surface, refined by a row or column of new patches.

use super::super::bfunction::BFunctionKind;
use super::super::error::{GeomError, GeomResult};
use super::super::point::binomial;
use super::super::surface::{Partials, TensorSurface};
use super::{ErbsKnots, MAX_NESTING, blend_weights, taylor_patch};
use glam::{DMat4, DVec3};

/// A local patch, placed: its parameters are the parent's, its domain the patch's support.
#[derive(Debug, Clone, PartialEq)]
pub enum LocalPatch {
    /// A polynomial Bézier (`bezier`: one span each way, written as its points) or B-spline
    /// surface.
    Spline {
        surface: TensorSurface,
        bezier: bool,
    },
    /// An ERBS surface with its own local patches.
    Erbs(Box<ErbsSurface>),
}

impl LocalPatch {
    /// A polynomial Bézier patch from its row-major net (placed later, onto its support).
    pub fn bezier(count: [usize; 2], points: Vec<DVec3>) -> GeomResult<Self> {
        Ok(LocalPatch::Spline {
            surface: TensorSurface::bezier(count, points, None)?,
            bezier: true,
        })
    }

    #[must_use]
    pub fn domain(&self) -> [(f64, f64); 2] {
        match self {
            LocalPatch::Spline { surface, .. } => surface.domain(),
            LocalPatch::Erbs(e) => e.domain(),
        }
    }

    /// ∂^{a+b}/∂u^a∂v^b for a, b ≤ n in the parent's parameters.
    #[must_use]
    pub fn derivatives(&self, u: f64, v: f64, n: usize) -> Partials {
        match self {
            LocalPatch::Spline { surface, .. } => surface.derivatives(u, v, n),
            LocalPatch::Erbs(e) => e.derivatives(u, v, n),
        }
    }

    #[must_use]
    pub fn eval(&self, u: f64, v: f64) -> DVec3 {
        self.derivatives(u, v, 0).get(0, 0)
    }

    /// Its own control net, row-major, and its size (none for an ERBS patch).
    #[must_use]
    pub fn net(&self) -> Option<([usize; 2], &[DVec3])> {
        match self {
            LocalPatch::Spline { surface, .. } => Some((surface.count(), surface.points())),
            LocalPatch::Erbs(_) => None,
        }
    }

    /// Degrees per direction; of an ERBS patch, the largest of its patches'.
    pub fn degree(&self) -> [usize; 2] {
        match self {
            LocalPatch::Spline { surface, .. } => surface.degree(),
            LocalPatch::Erbs(e) => e
                .local
                .iter()
                .map(LocalPatch::degree)
                .fold([0, 0], |m, d| [m[0].max(d[0]), m[1].max(d[1])]),
        }
    }

    #[must_use]
    pub fn depth(&self) -> usize {
        match self {
            LocalPatch::Spline { .. } => 0,
            LocalPatch::Erbs(e) => e.depth(),
        }
    }

    pub fn is_rational(&self) -> bool {
        match self {
            LocalPatch::Spline { surface, .. } => surface.is_rational(),
            LocalPatch::Erbs(e) => e.local.iter().any(LocalPatch::is_rational),
        }
    }

    /// Every control point at any depth mapped by `f`.
    pub fn map_points(&mut self, f: &impl Fn(DVec3) -> DVec3) {
        match self {
            LocalPatch::Spline { surface, .. } => surface.map_points(f),
            LocalPatch::Erbs(e) => e.local.iter_mut().for_each(|l| l.map_points(f)),
        }
    }

    /// The same patch with its parameters mapped affinely so that its domain becomes `to`.
    pub fn placed(self, to: [(f64, f64); 2]) -> GeomResult<Self> {
        let from = self.domain();
        if from == to {
            return Ok(self);
        }
        let mut maps = Vec::with_capacity(2);
        for dir in 0..2 {
            let ((d0, d1), (a, b)) = (from[dir], to[dir]);
            if !(a.is_finite() && b.is_finite() && a < b) {
                return Err(GeomError::new(
                    "interval",
                    format!("[{a}, {b}] is not a finite interval with a < b"),
                ));
            }
            let scale = (b - a) / (d1 - d0);
            maps.push(move |t: f64| match t {
                t if t == d0 => a,
                t if t == d1 => b,
                t => a + (t - d0) * scale,
            });
        }
        self.mapped(&maps[0], &maps[1])
    }

    fn mapped(self, fu: &impl Fn(f64) -> f64, fv: &impl Fn(f64) -> f64) -> GeomResult<Self> {
        Ok(match self {
            LocalPatch::Spline { surface, bezier } => LocalPatch::Spline {
                surface: surface.with_knots_mapped(0, fu)?.with_knots_mapped(1, fv)?,
                bezier,
            },
            LocalPatch::Erbs(mut e) => {
                e.knots[0].map(fu);
                e.knots[1].map(fv);
                e.local = e
                    .local
                    .into_iter()
                    .map(|l| l.mapped(fu, fv))
                    .collect::<GeomResult<_>>()?;
                LocalPatch::Erbs(e)
            }
        })
    }

    /// The same function on [a, b] ⊆ the domain in direction `dir`, exactly: a polynomial
    /// patch is split, an ERBS patch narrows its domain.
    pub fn restricted(&self, dir: usize, (a, b): (f64, f64)) -> GeomResult<Self> {
        let (d0, d1) = self.domain()[dir];
        match self {
            LocalPatch::Spline { surface, bezier } => {
                let mut s = surface.clone();
                if a > d0 {
                    s = s.split(dir, a)?.1;
                }
                if b < d1 {
                    s = s.split(dir, b)?.0;
                }
                Ok(LocalPatch::Spline {
                    surface: s,
                    bezier: *bezier,
                })
            }
            LocalPatch::Erbs(e) => {
                let mut e = e.clone();
                e.knots[dir] = e.knots[dir].clone().with_domain((a.max(d0), b.min(d1)))?;
                Ok(LocalPatch::Erbs(e))
            }
        }
    }
}

/// An ERBS tensor-product surface.
#[derive(Debug, Clone, PartialEq)]
pub struct ErbsSurface {
    knots: [ErbsKnots; 2],
    local: Vec<LocalPatch>,
    bfunction: BFunctionKind,
}

impl ErbsSurface {
    /// An open ERBS surface with Bézier patches, row-major [nu][nv], each placed onto
    /// [u_k, u_{k+2}] × [v_l, v_{l+2}].
    pub fn new(
        knots: [Vec<f64>; 2],
        count: [usize; 2],
        local: Vec<TensorSurface>,
        bfunction: BFunctionKind,
    ) -> GeomResult<Self> {
        let [ku, kv] = knots;
        let knots = [
            ErbsKnots::open_patches(ku, count[0]).map_err(|e| direction(e, "u"))?,
            ErbsKnots::open_patches(kv, count[1]).map_err(|e| direction(e, "v"))?,
        ];
        let local = local
            .into_iter()
            .map(|s| {
                if s.is_rational() {
                    return Err(rational_patch());
                }
                Ok(LocalPatch::Spline {
                    surface: s,
                    bezier: true,
                })
            })
            .collect::<GeomResult<_>>()?;
        Self::with_locals(knots, local, bfunction)
    }

    /// An ERBS surface from knots per direction and patches of any kind, row-major; each patch
    /// is placed onto its support.
    pub fn with_locals(
        knots: [ErbsKnots; 2],
        local: Vec<LocalPatch>,
        bfunction: BFunctionKind,
    ) -> GeomResult<Self> {
        let [nu, nv] = [knots[0].locals(), knots[1].locals()];
        if local.len() != nu * nv {
            return Err(GeomError::new(
                "local",
                format!(
                    "{} local patches do not form a {nu} × {nv} grid",
                    local.len()
                ),
            ));
        }
        let local = local
            .into_iter()
            .enumerate()
            .map(|(idx, p)| {
                if p.is_rational() {
                    return Err(rational_patch());
                }
                let (k, l) = (idx / nv, idx % nv);
                p.placed([knots[0].support(k), knots[1].support(l)])
            })
            .collect::<GeomResult<_>>()?;
        let s = Self {
            knots,
            local,
            bfunction,
        };
        if s.depth() > MAX_NESTING {
            return Err(GeomError::new(
                "local",
                format!(
                    "ERBS local patches are nested {} levels deep; at most {MAX_NESTING} are supported",
                    s.depth()
                ),
            ));
        }
        Ok(s)
    }

    /// GMlib's construction: [nu, nv] patches on uniform knots over the source's domain, patch
    /// (k, l) the source's Taylor polynomial of degree [du, dv] at its knot crossing in
    /// Bernstein form on its support.
    pub fn from_surface(
        source: &TensorSurface,
        count: [usize; 2],
        degree: [usize; 2],
        bfunction: BFunctionKind,
        closed: [bool; 2],
    ) -> GeomResult<Self> {
        let dom = source.domain();
        let knots = [
            ErbsKnots::uniform_patches(dom[0].0, dom[0].1, count[0], closed[0])
                .map_err(|e| direction(e, "u"))?,
            ErbsKnots::uniform_patches(dom[1].0, dom[1].1, count[1], closed[1])
                .map_err(|e| direction(e, "v"))?,
        ];
        let n = degree[0].max(degree[1]);
        let mut local = Vec::with_capacity(count[0] * count[1]);
        for k in 0..count[0] {
            for l in 0..count[1] {
                let centre = (knots[0].centre(k), knots[1].centre(l));
                let support = [knots[0].support(k), knots[1].support(l)];
                let partials = source.derivatives(centre.0, centre.1, n);
                local.push(hermite_patch(&partials, degree, centre, support)?);
            }
        }
        Self::with_locals(knots, local, bfunction)
    }

    /// Bytes [`ErbsSurface::from_surface`] allocates for `count` patches of degree `degree`,
    /// from the types it builds: per patch the enum, (du + 1)(dv + 1) points and 2(du + 1) +
    /// 2(dv + 1) knots, plus the two ERBS knot vectors. Saturates; for the memory budget before
    /// anything is built.
    #[must_use]
    pub fn from_surface_bytes(count: [usize; 2], degree: [usize; 2]) -> u128 {
        let [d1u, d1v] = degree.map(|d| d as u128 + 1);
        let f64_bytes = std::mem::size_of::<f64>() as u128;
        let per_patch = std::mem::size_of::<LocalPatch>() as u128
            + d1u * d1v * std::mem::size_of::<DVec3>() as u128
            + 2 * (d1u + d1v) * f64_bytes;
        let patches = count[0] as u128 * count[1] as u128;
        patches.saturating_mul(per_patch) + (count[0] as u128 + count[1] as u128) * f64_bytes
    }

    #[must_use]
    pub fn knots(&self) -> &[ErbsKnots; 2] {
        &self.knots
    }

    /// [nu, nv] local patches.
    #[must_use]
    pub fn count(&self) -> [usize; 2] {
        [self.knots[0].locals(), self.knots[1].locals()]
    }

    #[must_use]
    pub fn local_patch(&self, k: usize, l: usize) -> &LocalPatch {
        &self.local[k * self.count()[1] + l]
    }

    #[must_use]
    pub fn local_patches(&self) -> &[LocalPatch] {
        &self.local
    }

    #[must_use]
    pub fn bfunction(&self) -> BFunctionKind {
        self.bfunction
    }

    #[must_use]
    pub fn domain(&self) -> [(f64, f64); 2] {
        [self.knots[0].domain(), self.knots[1].domain()]
    }

    #[must_use]
    pub fn closed(&self) -> [bool; 2] {
        [self.knots[0].is_closed(), self.knots[1].is_closed()]
    }

    pub fn depth(&self) -> usize {
        1 + self.local.iter().map(LocalPatch::depth).max().unwrap_or(0)
    }

    /// The patch at `path` (index pairs descending through ERBS patches).
    #[must_use]
    pub fn local_at(&self, path: &[[usize; 2]]) -> Option<&LocalPatch> {
        let (&[k, l], rest) = path.split_first()?;
        let [nu, nv] = self.count();
        if k >= nu || l >= nv {
            return None;
        }
        let p = &self.local[k * nv + l];
        match (rest.is_empty(), p) {
            (true, _) => Some(p),
            (false, LocalPatch::Erbs(e)) => e.local_at(rest),
            (false, LocalPatch::Spline { .. }) => None,
        }
    }

    fn local_at_mut(&mut self, path: &[[usize; 2]]) -> Option<&mut LocalPatch> {
        let (&[k, l], rest) = path.split_first()?;
        let [nu, nv] = self.count();
        if k >= nu || l >= nv {
            return None;
        }
        let p = &mut self.local[k * nv + l];
        if rest.is_empty() {
            return Some(p);
        }
        match p {
            LocalPatch::Erbs(e) => e.local_at_mut(rest),
            LocalPatch::Spline { .. } => None,
        }
    }

    /// Maps every control point of the patch at `path` by p ↦ (A·[p;1]).xyz.
    pub fn transform_local(&mut self, path: &[[usize; 2]], a: &DMat4) {
        if let Some(p) = self.local_at_mut(path) {
            p.map_points(&|x| a.transform_point3(x));
        }
    }

    /// Translates control point [a, b] of the polynomial patch at `path`.
    pub fn translate_local_point(&mut self, path: &[[usize; 2]], [a, b]: [usize; 2], d: DVec3) {
        if let Some(LocalPatch::Spline { surface, .. }) = self.local_at_mut(path) {
            surface.translate_point(a, b, d);
        }
    }

    /// Sets every control point of the polynomial patch at `path` exactly (row-major).
    pub fn set_local_points(&mut self, path: &[[usize; 2]], points: &[DVec3]) {
        if let Some(LocalPatch::Spline { surface, .. }) = self.local_at_mut(path) {
            surface.set_points(points);
        }
    }

    /// Replaces the patch at `path` (already placed on its support).
    pub fn set_local(&mut self, path: &[[usize; 2]], patch: LocalPatch) {
        if let Some(p) = self.local_at_mut(path) {
            *p = patch;
        }
    }

    /// Local refinement at t in direction `dir`, strictly inside interval i: the patches
    /// whose supports contain t keep their shape, restricted exactly; a new row (u) or column
    /// (v) of patches i + 1 Hermite-interpolates the surface at its knot crossings, to degree
    /// `degree` (default: the larger degree of its two neighbours, per direction). Returns the
    /// refined surface and the new row's or column's index.
    pub fn insert_knot(
        &self,
        dir: usize,
        t: f64,
        degree: Option<[usize; 2]>,
    ) -> GeomResult<(Self, usize)> {
        let (new_knots, i) = self.knots[dir].insert(t)?;
        let (right, shift) = self.knots[dir].right(i);
        let [nu, nv] = self.count();
        let other = 1 - dir;
        let at = |a: usize, m: usize| if dir == 0 { a * nv + m } else { m * nv + a };
        let lines = self.count()[other];
        let mut rows: Vec<Vec<LocalPatch>> = Vec::with_capacity(self.count()[dir] + 1);
        for a in 0..self.count()[dir] {
            rows.push((0..lines).map(|m| self.local[at(a, m)].clone()).collect());
        }
        let mut inserted = Vec::with_capacity(lines);
        for m in 0..lines {
            let (left_p, right_p) = (&self.local[at(i, m)], &self.local[at(right, m)]);
            let d = degree.unwrap_or_else(|| {
                let (x, y) = (left_p.degree(), right_p.degree());
                [x[0].max(y[0]), x[1].max(y[1])]
            });
            let cm = self.knots[other].centre(m);
            let centre = if dir == 0 { (t, cm) } else { (cm, t) };
            let sup_dir = self.knots[dir].interval(i);
            let sup_other = self.knots[other].support(m);
            let support = if dir == 0 {
                [sup_dir, sup_other]
            } else {
                [sup_other, sup_dir]
            };
            let partials = self.derivatives(centre.0, centre.1, d[0].max(d[1]));
            inserted.push(hermite_patch(&partials, d, centre, support)?);
            rows[i][m] = left_p.restricted(dir, (self.knots[dir].support(i).0, t))?;
            rows[right][m] =
                right_p.restricted(dir, (t - shift, self.knots[dir].support(right).1))?;
        }
        rows.insert(i + 1, inserted);
        let mut count = [nu, nv];
        count[dir] += 1;
        let mut local = Vec::with_capacity(count[0] * count[1]);
        for k in 0..count[0] {
            for l in 0..count[1] {
                let (a, m) = if dir == 0 { (k, l) } else { (l, k) };
                local.push(rows[a][m].clone());
            }
        }
        let mut knots = self.knots.clone();
        knots[dir] = new_knots;
        Ok((
            Self {
                knots,
                local,
                bfunction: self.bfunction,
            },
            i + 1,
        ))
    }

    /// ∂^{a+b}s/∂u^a∂v^b for a, b ≤ n by the Leibniz rule in both directions.
    #[must_use]
    pub fn derivatives(&self, u: f64, v: f64, n: usize) -> Partials {
        let [(u0, u1), (v0, v1)] = self.domain();
        let (u, v) = (u.clamp(u0, u1), v.clamp(v0, v1));
        let [ku, kv] = &self.knots;
        let (i, j) = (ku.locate(u), kv.locate(v));
        let wu = blend_weights(&self.bfunction, ku.interval(i), u, n);
        let wv = blend_weights(&self.bfunction, kv.interval(j), v, n);
        let nv = self.count()[1];
        let mut out = Partials::zeros(n);
        for (su, (k, sk)) in [(i, 0.0), ku.right(i)].into_iter().enumerate() {
            for (sv, (l, sl)) in [(j, 0.0), kv.right(j)].into_iter().enumerate() {
                let s = self.local[k * nv + l].derivatives(u - sk, v - sl, n);
                for a in 0..=n {
                    for b in 0..=n {
                        let mut acc = out.get(a, b);
                        for a2 in 0..=a {
                            for b2 in 0..=b {
                                let c = binomial(a, a2)
                                    * binomial(b, b2)
                                    * wu[su][a - a2]
                                    * wv[sv][b - b2];
                                acc += s.get(a2, b2) * c;
                            }
                        }
                        out.set(a, b, acc);
                    }
                }
            }
        }
        out
    }

    #[must_use]
    pub fn eval(&self, u: f64, v: f64) -> DVec3 {
        self.derivatives(u, v, 0).get(0, 0)
    }
}

/// The Bézier patch matching `partials` (a ≤ du, b ≤ dv) at `centre`, on `support`.
fn hermite_patch(
    partials: &Partials,
    degree: [usize; 2],
    centre: (f64, f64),
    support: [(f64, f64); 2],
) -> GeomResult<LocalPatch> {
    let points = taylor_patch(partials, degree, centre, support);
    let surface = TensorSurface::bezier([degree[0] + 1, degree[1] + 1], points, None)?
        .with_bezier_domain(support)?;
    Ok(LocalPatch::Spline {
        surface,
        bezier: true,
    })
}

fn rational_patch() -> GeomError {
    GeomError::new(
        "local",
        "rational local patches are not supported: local curves and patches must be polynomial",
    )
}

fn direction(mut e: GeomError, dir: &str) -> GeomError {
    e.message = format!("{dir} direction: {}", e.message);
    e
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::KnotVector;

    fn source() -> TensorSurface {
        let n = [6, 5];
        let pts = (0..n[0] * n[1])
            .map(|k| {
                let (i, j) = ((k / n[1]) as f64, (k % n[1]) as f64);
                DVec3::new(i, j, (0.7 * i).sin() * (0.5 * j).cos())
            })
            .collect();
        let knots = [
            KnotVector::clamped_uniform(3, n[0], 0.0, 2.0).into_vec(),
            KnotVector::clamped_uniform(2, n[1], -1.0, 1.0).into_vec(),
        ];
        TensorSurface::bspline([3, 2], knots, n, pts, None).unwrap()
    }

    #[test]
    fn surface_interpolates_local_patches_and_has_consistent_partials() {
        let mut local = Vec::new();
        for k in 0..3 {
            for l in 0..4 {
                let mut pts = Vec::new();
                for a in 0..3 {
                    for b in 0..2 {
                        pts.push(DVec3::new(
                            k as f64 + a as f64 * 0.5,
                            l as f64 + b as f64 * 0.7,
                            ((k + l + a * b) % 3) as f64,
                        ));
                    }
                }
                local.push(TensorSurface::bezier([3, 2], pts, None).unwrap());
            }
        }
        let s = ErbsSurface::new(
            [vec![0., 0., 1., 2., 2.], vec![0., 0., 0.5, 1.5, 3., 3.]],
            [3, 4],
            local,
            BFunctionKind::ExpoRational,
        )
        .unwrap();
        for k in 0..3 {
            for l in 0..4 {
                let (u, v) = (s.knots()[0].centre(k), s.knots()[1].centre(l));
                assert!((s.eval(u, v) - s.local_patch(k, l).eval(u, v)).length() < 1e-14);
            }
        }
        let (u, v, h) = (0.7, 1.1, 1e-5);
        let p = s.derivatives(u, v, 2);
        let pu = s.derivatives(u + h, v, 2);
        let mu = s.derivatives(u - h, v, 2);
        let pv = s.derivatives(u, v + h, 2);
        let mv = s.derivatives(u, v - h, 2);
        for a in 0..2 {
            for b in 0..2 {
                let fu = (pu.get(a, b) - mu.get(a, b)) / (2.0 * h);
                let fv = (pv.get(a, b) - mv.get(a, b)) / (2.0 * h);
                assert!((fu - p.get(a + 1, b)).length() < 1e-5 * (1.0 + fu.length()));
                assert!((fv - p.get(a, b + 1)).length() < 1e-5 * (1.0 + fv.length()));
            }
        }
    }

    #[test]
    fn construction_and_refinement_hermite_interpolate_at_crossings() {
        let src = source();
        for closed in [[false, false], [true, false], [false, true]] {
            let e = ErbsSurface::from_surface(
                &src,
                [4, 3],
                [3, 2],
                BFunctionKind::ExpoRational,
                closed,
            )
            .unwrap();
            for k in 0..4 {
                for l in 0..3 {
                    let (u, v) = (e.knots()[0].centre(k), e.knots()[1].centre(l));
                    let (a, b) = (e.derivatives(u, v, 2), src.derivatives(u, v, 2));
                    for x in 0..=2 {
                        for y in 0..=2 {
                            let (p, q) = (a.get(x, y), b.get(x, y));
                            assert!(
                                (p - q).length() < 1e-9 * (1.0 + q.length()),
                                "{closed:?} ({k},{l}) ∂{x}{y}: {p:?} vs {q:?}"
                            );
                        }
                    }
                }
            }
            for dir in 0..2 {
                let (lo, hi) = e.knots()[dir].interval(1);
                let t = lo + 0.4 * (hi - lo);
                let (r, new) = e.insert_knot(dir, t, None).unwrap();
                assert_eq!(new, 2);
                let mut count = e.count();
                count[dir] += 1;
                assert_eq!(r.count(), count);
                let other = 1 - dir;
                for m in 0..e.count()[other] {
                    let c = e.knots()[other].centre(m);
                    let (u, v) = if dir == 0 { (t, c) } else { (c, t) };
                    let (a, b) = (r.derivatives(u, v, 2), e.derivatives(u, v, 2));
                    for x in 0..=2 {
                        for y in 0..=2 {
                            let (p, q) = (a.get(x, y), b.get(x, y));
                            assert!((p - q).length() < 1e-9 * (1.0 + q.length()));
                        }
                    }
                }
                // Outside the refined interval in `dir`, nothing changes.
                let [(u0, u1), (v0, v1)] = e.domain();
                for s in 0..=20 {
                    for w in 0..=20 {
                        let u = u0 + (u1 - u0) * s as f64 / 20.0;
                        let v = v0 + (v1 - v0) * w as f64 / 20.0;
                        let x = if dir == 0 { u } else { v };
                        if x > lo && x < hi {
                            continue;
                        }
                        let (p, q) = (e.eval(u, v), r.eval(u, v));
                        assert!((p - q).length() < 1e-10 * (1.0 + p.length()), "({u}, {v})");
                    }
                }
            }
        }
    }
}
