//! ERBS curves and surfaces as B-splines, for export to formats without ERBS (OBJ).
//!
//! On an interval [t_i, t_{i+1}] an ERBS curve is (1 − B(w))·c_{i−1} + B(w)·c_i with w the
//! interval's own linear parameter. When B is a polynomial (smoothstep, smootherstep) or a
//! rational function (rational: w²/(w² + (1−w)²)) and the local curves are Bézier curves, every
//! piece is a polynomial (rational) Bézier curve: restrict both locals to the interval (de
//! Casteljau), raise them to a common degree, multiply by the Bernstein forms of the blend
//! numerators and add. The pieces join at the knots into a B-spline whose interior knots have
//! multiplicity equal to its degree. Surfaces do the same per direction. The expo-rational and
//! trigonometric B-functions are not rational functions, so no rational B-spline equals them.

use crate::geom::point::binomial;
use crate::geom::{
    BFunctionKind, BSplineCurve, ErbsCurve, ErbsSurface, LocalCurve, LocalPatch, TensorSurface,
};
use crate::scene::MAX_DEGREE;
use glam::{DVec3, DVec4};

/// 1 − B and B as Bernstein polynomials over their common denominator: N_left / D and
/// N_right / D with D = N_left + N_right (D ≡ 1 for polynomial B-functions).
struct Blend {
    left: &'static [f64],
    right: &'static [f64],
    rational: bool,
}

impl Blend {
    fn of(kind: BFunctionKind) -> Result<Blend, String> {
        match kind {
            // 3w² − 2w³ = B_2 + B_3 (cubic Bernstein).
            BFunctionKind::Smoothstep => Ok(Blend {
                left: &[1.0, 1.0, 0.0, 0.0],
                right: &[0.0, 0.0, 1.0, 1.0],
                rational: false,
            }),
            // 10w³ − 15w⁴ + 6w⁵ = B_3 + B_4 + B_5 (quintic Bernstein).
            BFunctionKind::Smootherstep => Ok(Blend {
                left: &[1.0, 1.0, 1.0, 0.0, 0.0, 0.0],
                right: &[0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
                rational: false,
            }),
            // w² / (w² + (1−w)²): numerators (1−w)² = B_0 and w² = B_2 (quadratic).
            BFunctionKind::Rational => Ok(Blend {
                left: &[1.0, 0.0, 0.0],
                right: &[0.0, 0.0, 1.0],
                rational: true,
            }),
            BFunctionKind::ExpoRational | BFunctionKind::Trigonometric => Err(format!(
                "cannot be written to OBJ: the {} B-function is not a rational function, so no rational B-spline equals this ERBS (B-functions smoothstep, smootherstep and rational export exactly; or keep it in JSON)",
                kind.name()
            )),
        }
    }

    fn degree(&self) -> usize {
        self.left.len() - 1
    }
}

fn exact_form_only() -> String {
    "cannot be written to OBJ: the exact B-spline form covers open ERBS objects whose locals are Bézier curves or patches (not closed ones, nor B-spline or ERBS locals); keep it in JSON".into()
}

/// The exact B-spline (NURBS for the rational B-function) form of an ERBS curve.
pub fn curve_to_bspline(c: &ErbsCurve) -> Result<BSplineCurve, String> {
    let blend = Blend::of(c.bfunction())?;
    let k = c.knots();
    if k.is_closed() || k.domain() != k.full_domain() {
        return Err(exact_form_only());
    }
    let local = c
        .local_curves()
        .iter()
        .map(|l| match l {
            LocalCurve::Spline {
                curve,
                bezier: true,
            } => Ok(curve.points()),
            _ => Err(exact_form_only()),
        })
        .collect::<Result<Vec<_>, _>>()?;
    let d = local.iter().map(|p| p.len() - 1).max().unwrap_or(0);
    let p = degree(d, &blend)?;
    let t = k.as_slice();
    let n = local.len();
    let hom = |l: usize| -> Vec<DVec4> { local[l].iter().map(|q| q.extend(1.0)).collect() };
    let mut points: Vec<DVec4> = Vec::with_capacity((n - 1) * p + 1);
    for i in 1..n {
        let mut piece = vec![DVec4::ZERO; p + 1];
        for (side, weights) in [blend.left, blend.right].into_iter().enumerate() {
            let l = i - 1 + side;
            let (s0, s1) = sub_interval(t, l, i);
            let q = product(&elevate(&part(&hom(l), s0, s1), d), weights);
            piece.iter_mut().zip(q).for_each(|(a, b)| *a += b);
        }
        // Neighbouring pieces meet in c(t_i): keep the left piece's end.
        points.extend_from_slice(if i == 1 { &piece } else { &piece[1..] });
    }
    let (points, weights) = project(points, blend.rational);
    BSplineCurve::new(p, knots(t, n, p), points, weights).map_err(|e| e.to_string())
}

/// The exact tensor-product B-spline (NURBS for the rational B-function) form of an ERBS
/// surface.
pub fn surface_to_bspline(s: &ErbsSurface) -> Result<TensorSurface, String> {
    let blend = Blend::of(s.bfunction())?;
    let [cu, cv] = s.count();
    if s.closed() != [false, false] || s.knots().iter().any(|k| k.domain() != k.full_domain()) {
        return Err(exact_form_only());
    }
    let patches = s
        .local_patches()
        .iter()
        .map(|p| match p {
            LocalPatch::Spline {
                surface,
                bezier: true,
            } => Ok(surface),
            _ => Err(exact_form_only()),
        })
        .collect::<Result<Vec<_>, _>>()?;
    let [ku, kv] = s.knots();
    let (ku, kv) = (ku.as_slice(), kv.as_slice());
    let [du, dv] = [0, 1].map(|d| patches.iter().map(|q| q.degree()[d]).max().unwrap_or(0));
    let (pu, pv) = (degree(du, &blend)?, degree(dv, &blend)?);
    let (nu, nv) = ((cu - 1) * pu + 1, (cv - 1) * pv + 1);
    let mut net = vec![DVec4::ZERO; nu * nv];
    let sides = [blend.left, blend.right];
    for i in 1..cu {
        for j in 1..cv {
            let mut cell = Grid::zeros(pu + 1, pv + 1);
            for (a, bu) in sides.into_iter().enumerate() {
                for (b, bv) in sides.into_iter().enumerate() {
                    let (k, l) = (i - 1 + a, j - 1 + b);
                    let (u0, u1) = sub_interval(ku, k, i);
                    let (v0, v1) = sub_interval(kv, l, j);
                    let g = Grid::of(patches[k * cv + l])
                        .map_columns(|col| product(&elevate(&part(col, u0, u1), du), bu))
                        .map_rows(|row| product(&elevate(&part(row, v0, v1), dv), bv));
                    cell.add(&g);
                }
            }
            for r in 0..=pu {
                for c in 0..=pv {
                    let (gi, gj) = ((i - 1) * pu + r, (j - 1) * pv + c);
                    if (r > 0 || i == 1) && (c > 0 || j == 1) {
                        net[gi * nv + gj] = cell.at(r, c);
                    }
                }
            }
        }
    }
    let (points, weights) = project(net, blend.rational);
    TensorSurface::bspline(
        [pu, pv],
        [knots(ku, cu, pu), knots(kv, cv, pv)],
        [nu, nv],
        points,
        weights,
    )
    .map_err(|e| e.to_string())
}

fn degree(local: usize, blend: &Blend) -> Result<usize, String> {
    let p = local + blend.degree();
    if p > MAX_DEGREE {
        return Err(format!(
            "cannot be written to OBJ: its exact B-spline form has degree {p}, above the supported maximum {MAX_DEGREE}"
        ));
    }
    Ok(p)
}

/// Where interval [t_i, t_{i+1}] lies in local l's parameter [t_l, t_{l+2}] → [0, 1]; for the
/// two locals alive there one end is exactly 0 or 1.
fn sub_interval(t: &[f64], l: usize, i: usize) -> (f64, f64) {
    let (lo, hi) = (t[l], t[l + 2]);
    ((t[i] - lo) / (hi - lo), (t[i + 1] - lo) / (hi - lo))
}

/// ERBS knots t_1 … t_n as B-spline knots: ends p + 1 times, interior knots p times.
fn knots(t: &[f64], n: usize, p: usize) -> Vec<f64> {
    let mut k = vec![t[1]; p + 1];
    for &x in &t[2..n] {
        k.extend(std::iter::repeat_n(x, p));
    }
    k.extend(std::iter::repeat_n(t[n], p + 1));
    k
}

/// Homogeneous points → points and weights (polynomial blends have weight ≡ 1: dropped).
fn project(h: Vec<DVec4>, rational: bool) -> (Vec<DVec3>, Option<Vec<f64>>) {
    if rational {
        let points = h.iter().map(|q| q.truncate() / q.w).collect();
        (points, Some(h.iter().map(|q| q.w).collect()))
    } else {
        (h.iter().map(|q| q.truncate()).collect(), None)
    }
}

/// The Bernstein coefficients of f·g (degrees add): (f·g)_k = Σ_j f_j g_{k−j}
/// C(p,j) C(q,k−j) / C(p+q,k).
fn product(f: &[DVec4], g: &[f64]) -> Vec<DVec4> {
    let (p, q) = (f.len() - 1, g.len() - 1);
    let mut out = vec![DVec4::ZERO; p + q + 1];
    for (j, &fj) in f.iter().enumerate() {
        for (k, &gk) in g.iter().enumerate().filter(|(_, g)| **g != 0.0) {
            out[j + k] += fj * (gk * binomial(p, j) * binomial(q, k) / binomial(p + q, j + k));
        }
    }
    out
}

/// Degree elevation to `degree` (multiplication by 1 = Σ Bernstein polynomials).
fn elevate(f: &[DVec4], degree: usize) -> Vec<DVec4> {
    let p = f.len() - 1;
    if p == degree {
        f.to_vec()
    } else {
        product(f, &vec![1.0; degree - p + 1])
    }
}

/// The Bézier coefficients of f restricted to [s0, s1] (one of them 0 or 1), by de Casteljau.
fn part(f: &[DVec4], s0: f64, s1: f64) -> Vec<DVec4> {
    let f = if s0 > 0.0 { split(f, s0).1 } else { f.to_vec() };
    if s1 < 1.0 {
        // [s0, 1] was mapped onto [0, 1].
        split(&f, (s1 - s0) / (1.0 - s0)).0
    } else {
        f
    }
}

/// de Casteljau subdivision at s: the coefficients on [0, s] and on [s, 1].
fn split(f: &[DVec4], s: f64) -> (Vec<DVec4>, Vec<DVec4>) {
    let mut c = f.to_vec();
    let n = c.len();
    let mut left = Vec::with_capacity(n);
    let mut right = Vec::with_capacity(n);
    for r in 0..n {
        left.push(c[0]);
        right.push(c[n - 1 - r]);
        for k in 0..n - 1 - r {
            c[k] = c[k] * (1.0 - s) + c[k + 1] * s;
        }
    }
    right.reverse();
    (left, right)
}

/// A row-major net of homogeneous points (rows along u).
struct Grid {
    rows: usize,
    cols: usize,
    pts: Vec<DVec4>,
}

impl Grid {
    fn zeros(rows: usize, cols: usize) -> Self {
        Self {
            rows,
            cols,
            pts: vec![DVec4::ZERO; rows * cols],
        }
    }

    fn of(s: &TensorSurface) -> Self {
        let [rows, cols] = s.count();
        Self {
            rows,
            cols,
            pts: s.homogeneous_points(),
        }
    }

    fn at(&self, r: usize, c: usize) -> DVec4 {
        self.pts[r * self.cols + c]
    }

    fn add(&mut self, o: &Grid) {
        self.pts.iter_mut().zip(&o.pts).for_each(|(a, b)| *a += *b);
    }

    fn map_rows(&self, f: impl Fn(&[DVec4]) -> Vec<DVec4>) -> Grid {
        let rows: Vec<Vec<DVec4>> = self.pts.chunks(self.cols).map(f).collect();
        let cols = rows[0].len();
        Grid {
            rows: self.rows,
            cols,
            pts: rows.concat(),
        }
    }

    fn map_columns(&self, f: impl Fn(&[DVec4]) -> Vec<DVec4>) -> Grid {
        let cols: Vec<Vec<DVec4>> = (0..self.cols)
            .map(|c| f(&(0..self.rows).map(|r| self.at(r, c)).collect::<Vec<_>>()))
            .collect();
        let rows = cols[0].len();
        let pts = (0..rows)
            .flat_map(|r| cols.iter().map(move |col| col[r]))
            .collect();
        Grid {
            rows,
            cols: self.cols,
            pts,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_and_product_reproduce_the_polynomials() {
        let f: Vec<DVec4> = [1.0, -2.0, 5.0, 0.5]
            .iter()
            .map(|&x| DVec4::new(x, 0.0, 0.0, 1.0))
            .collect();
        let eval = |c: &[DVec4], s: f64| crate::geom::bezier::de_casteljau(c, s).x;
        let (l, r) = split(&f, 0.3);
        assert!((eval(&l, 0.5) - eval(&f, 0.15)).abs() < 1e-14);
        assert!((eval(&r, 0.5) - eval(&f, 0.65)).abs() < 1e-14);
        let g = [0.0, 0.0, 1.0, 1.0]; // smoothstep
        let fg = product(&f, &g);
        for s in [0.0, 0.2, 0.7, 1.0] {
            let b = 3.0 * s * s - 2.0 * s * s * s;
            assert!((eval(&fg, s) - eval(&f, s) * b).abs() < 1e-14);
        }
        let e = elevate(&f, 6);
        assert_eq!(e.len(), 7);
        assert!((eval(&e, 0.4) - eval(&f, 0.4)).abs() < 1e-14);
    }
}
