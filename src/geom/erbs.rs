//! ERBS (expo-rational B-spline) curves and tensor-product surfaces of blending type with Bézier
//! local curves and patches (DESIGN.md conventions).
//!
//! Curve with n local curves and knots t_0 … t_{n+1} (t_0 = t_1, t_n = t_{n+1}, strictly
//! increasing in between), domain [t_1, t_n]. On [t_i, t_{i+1}):
//! c(t) = (1 − B(w)) c_{i−1}(t) + B(w) c_i(t), w = (t − t_i)/(t_{i+1} − t_i), and local curve l
//! lives on [t_l, t_{l+2}]. Derivatives by the full Leibniz rule
//! c^(r) = Σ_k C(r,k) [W_{i−1}^(r−k) c_{i−1}^(k) + W_i^(r−k) c_i^(k)] — not the paper's printed
//! update loop, which drops the product-rule terms.

use super::bezier::BezierCurve;
use super::bfunction::{BFunction, BFunctionKind};
use super::error::{GeomError, GeomResult};
use super::point::binomial;
use super::surface::{Partials, TensorSurface};
use glam::{DMat4, DVec3};

/// An ERBS curve of blending type.
#[derive(Debug, Clone, PartialEq)]
pub struct ErbsCurve {
    knots: Vec<f64>,
    local: Vec<BezierCurve>,
    bfunction: BFunctionKind,
}

/// An ERBS tensor-product surface: s(u,v) = Σ_k Σ_l s_kl(u,v) B_k(u) B_l(v).
#[derive(Debug, Clone, PartialEq)]
pub struct ErbsSurface {
    knots: [Vec<f64>; 2],
    count: [usize; 2],
    local: Vec<TensorSurface>,
    bfunction: BFunctionKind,
}

/// Validates an ERBS knot vector for `n` local curves: n+2 finite knots, t_0 = t_1,
/// t_n = t_{n+1}, strictly increasing t_1 < … < t_n.
pub fn check_erbs_knots(knots: &[f64], n: usize) -> GeomResult<()> {
    if n < 2 {
        return Err(GeomError::new(
            "local",
            format!("an ERBS needs at least 2 local curves, got {n}"),
        ));
    }
    if knots.len() != n + 2 {
        return Err(GeomError::new(
            "knots",
            format!(
                "expected {} knots (local curves + 2 = {n} + 2), got {}",
                n + 2,
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
    }
    if knots[0] != knots[1] {
        return Err(GeomError::new(
            "knots",
            format!("knot 0 ({}) must equal knot 1 ({})", knots[0], knots[1]),
        ));
    }
    if knots[n] != knots[n + 1] {
        return Err(GeomError::new(
            "knots",
            format!(
                "knot {} ({}) must equal knot {n} ({})",
                n + 1,
                knots[n + 1],
                knots[n]
            ),
        ));
    }
    for i in 2..=n {
        if knots[i] <= knots[i - 1] {
            return Err(GeomError::new(
                "knots",
                format!(
                    "knot {i} ({}) must be greater than knot {} ({}): interior ERBS knots are strictly increasing",
                    knots[i],
                    i - 1,
                    knots[i - 1]
                ),
            ));
        }
    }
    Ok(())
}

/// The interval index i (1 ≤ i ≤ n−1) with t_i ≤ t < t_{i+1}; t ≥ t_n maps to the last one.
pub fn erbs_interval(knots: &[f64], t: f64) -> usize {
    let n = knots.len() - 2;
    let mut i = 1;
    while i < n - 1 && t >= knots[i + 1] {
        i += 1;
    }
    i
}

/// Blend weights and their derivatives with respect to the parameter on interval i:
/// `out[0][r]` for local curve i−1 (1 − B) and `out[1][r]` for local curve i (B), r = 0..=n.
pub fn blend_weights(
    bf: &impl BFunction,
    knots: &[f64],
    i: usize,
    t: f64,
    n: usize,
) -> [Vec<f64>; 2] {
    let (a, b) = (knots[i], knots[i + 1]);
    let delta = 1.0 / (b - a);
    let w = ((t - a) * delta).clamp(0.0, 1.0);
    let mut bd = vec![0.0; n + 1];
    bf.derivatives(w, &mut bd);
    let mut scale = 1.0;
    for v in bd.iter_mut() {
        *v *= scale;
        scale *= delta;
    }
    let left = bd
        .iter()
        .enumerate()
        .map(|(r, &v)| if r == 0 { 1.0 - v } else { -v })
        .collect();
    [left, bd]
}

impl ErbsCurve {
    /// `local[l]` is given on any interval; it is re-placed onto [t_l, t_{l+2}].
    pub fn new(
        knots: Vec<f64>,
        local: Vec<BezierCurve>,
        bfunction: BFunctionKind,
    ) -> GeomResult<Self> {
        check_erbs_knots(&knots, local.len())?;
        let local = local
            .into_iter()
            .enumerate()
            .map(|(l, c)| c.with_interval(knots[l], knots[l + 2]))
            .collect::<GeomResult<_>>()?;
        Ok(Self {
            knots,
            local,
            bfunction,
        })
    }

    pub fn knots(&self) -> &[f64] {
        &self.knots
    }

    pub fn local_curves(&self) -> &[BezierCurve] {
        &self.local
    }

    pub fn bfunction(&self) -> BFunctionKind {
        self.bfunction
    }

    /// [t_1, t_n].
    pub fn domain(&self) -> (f64, f64) {
        (self.knots[1], self.knots[self.local.len()])
    }

    /// Maps every control point of local curve l by p ↦ (A·[p;1]).xyz.
    pub fn transform_local(&mut self, l: usize, a: &DMat4) {
        self.local[l].map_points(|p| a.transform_point3(p));
    }

    /// Sets every control point of local curve l exactly.
    pub fn set_local_points(&mut self, l: usize, points: &[DVec3]) {
        self.local[l].set_points(points);
    }

    /// Translates control point q of local curve l.
    pub fn translate_local_point(&mut self, l: usize, q: usize, delta: DVec3) {
        self.local[l].translate_point(q, delta);
    }

    /// c(t), c'(t), …, c^(n)(t).
    pub fn derivatives(&self, t: f64, n: usize) -> Vec<DVec3> {
        let (a, b) = self.domain();
        let t = t.clamp(a, b);
        let i = erbs_interval(&self.knots, t);
        let w = blend_weights(&self.bfunction, &self.knots, i, t, n);
        let mut out = vec![DVec3::ZERO; n + 1];
        for (side, l) in [i - 1, i].into_iter().enumerate() {
            let c = self.local[l].derivatives(t, n);
            for (r, o) in out.iter_mut().enumerate() {
                for k in 0..=r {
                    *o += c[k] * (binomial(r, k) * w[side][r - k]);
                }
            }
        }
        out
    }

    pub fn eval(&self, t: f64) -> DVec3 {
        self.derivatives(t, 0)[0]
    }
}

impl ErbsSurface {
    /// `local` is row-major [nu][nv] Bézier patches (any domain; they are re-placed onto
    /// [u_k, u_{k+2}] × [v_l, v_{l+2}]).
    pub fn new(
        knots: [Vec<f64>; 2],
        count: [usize; 2],
        local: Vec<TensorSurface>,
        bfunction: BFunctionKind,
    ) -> GeomResult<Self> {
        check_erbs_knots(&knots[0], count[0]).map_err(|e| direction(e, "u"))?;
        check_erbs_knots(&knots[1], count[1]).map_err(|e| direction(e, "v"))?;
        if local.len() != count[0] * count[1] {
            return Err(GeomError::new(
                "local",
                format!(
                    "{} local patches do not form a {} × {} grid",
                    local.len(),
                    count[0],
                    count[1]
                ),
            ));
        }
        let nv = count[1];
        let local = local
            .into_iter()
            .enumerate()
            .map(|(idx, s)| {
                let (k, l) = (idx / nv, idx % nv);
                s.with_bezier_domain([
                    (knots[0][k], knots[0][k + 2]),
                    (knots[1][l], knots[1][l + 2]),
                ])
            })
            .collect::<GeomResult<_>>()?;
        Ok(Self {
            knots,
            count,
            local,
            bfunction,
        })
    }

    pub fn knots(&self) -> &[Vec<f64>; 2] {
        &self.knots
    }

    /// [nu, nv] local patches.
    pub fn count(&self) -> [usize; 2] {
        self.count
    }

    pub fn local_patch(&self, k: usize, l: usize) -> &TensorSurface {
        &self.local[k * self.count[1] + l]
    }

    pub fn local_patches(&self) -> &[TensorSurface] {
        &self.local
    }

    pub fn bfunction(&self) -> BFunctionKind {
        self.bfunction
    }

    pub fn domain(&self) -> [(f64, f64); 2] {
        [
            (self.knots[0][1], self.knots[0][self.count[0]]),
            (self.knots[1][1], self.knots[1][self.count[1]]),
        ]
    }

    /// Maps every control point of local patch (k, l) by p ↦ (A·[p;1]).xyz.
    pub fn transform_local(&mut self, k: usize, l: usize, a: &DMat4) {
        let nv = self.count[1];
        self.local[k * nv + l].map_points(|p| a.transform_point3(p));
    }

    /// Sets every control point of local patch (k, l) exactly (row-major).
    pub fn set_local_points(&mut self, k: usize, l: usize, points: &[DVec3]) {
        let nv = self.count[1];
        self.local[k * nv + l].set_points(points);
    }

    /// Translates control point (a, b) of local patch (k, l).
    pub fn translate_local_point(&mut self, k: usize, l: usize, a: usize, b: usize, delta: DVec3) {
        let nv = self.count[1];
        self.local[k * nv + l].translate_point(a, b, delta);
    }

    /// ∂^{a+b}s/∂u^a∂v^b for a, b ≤ n by the Leibniz rule in both directions.
    pub fn derivatives(&self, u: f64, v: f64, n: usize) -> Partials {
        let [(u0, u1), (v0, v1)] = self.domain();
        let (u, v) = (u.clamp(u0, u1), v.clamp(v0, v1));
        let i = erbs_interval(&self.knots[0], u);
        let j = erbs_interval(&self.knots[1], v);
        let wu = blend_weights(&self.bfunction, &self.knots[0], i, u, n);
        let wv = blend_weights(&self.bfunction, &self.knots[1], j, v, n);
        let mut out = Partials::zeros(n);
        for (su, k) in [i - 1, i].into_iter().enumerate() {
            for (sv, l) in [j - 1, j].into_iter().enumerate() {
                let s = self.local_patch(k, l).derivatives(u, v, n);
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

    pub fn eval(&self, u: f64, v: f64) -> DVec3 {
        self.derivatives(u, v, 0).get(0, 0)
    }
}

fn direction(mut e: GeomError, dir: &str) -> GeomError {
    e.message = format!("{dir} direction: {}", e.message);
    e
}

#[cfg(test)]
mod tests {
    use super::*;

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
                let t = c.knots()[l + 1];
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
        let c = |k: Vec<f64>| check_erbs_knots(&k, 3).unwrap_err().message;
        assert!(c(vec![0., 0., 1., 2.]).contains("expected 5 knots"));
        assert!(c(vec![0., 0.5, 1., 2., 2.]).contains("knot 0 (0) must equal knot 1 (0.5)"));
        assert!(c(vec![0., 0., 1., 2., 3.]).contains("knot 4 (3) must equal knot 3 (2)"));
        assert!(c(vec![0., 0., 0., 2., 2.]).contains("strictly increasing"));
        assert!(
            check_erbs_knots(&[0., 0., 1.], 1)
                .unwrap_err()
                .message
                .contains("at least 2")
        );
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
                let (u, v) = (s.knots()[0][k + 1], s.knots()[1][l + 1]);
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
                assert!(
                    (fu - p.get(a + 1, b)).length() < 1e-5 * (1.0 + fu.length()),
                    "u a={a} b={b}"
                );
                assert!(
                    (fv - p.get(a, b + 1)).length() < 1e-5 * (1.0 + fv.length()),
                    "v a={a} b={b}"
                );
            }
        }
    }
}
