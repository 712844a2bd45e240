//! Condition scales for comparing samples of refined control nets.
//!
//! After a knot insertion or a degree elevation the same shape is carried by a different f64
//! control net. Rounding every control coordinate (and weight) by a relative ε moves the r-th
//! derivative by up to ε·Σ_i |N_i^(r)(t)|·|P_i|: that, not the derivative's own size, is how
//! well any f64 net, and any backward-stable evaluation of it, can fix the value. Where the
//! derivative is much smaller than the terms that cancel in it (coordinates far from the
//! origin, short spans, high orders, orders above a polynomial piece's original degree after
//! elevation, a weight function that is locally constant), the value-relative measure of
//! [`super::compare`] asks for digits no representation has.
//!
//! Here each (object, derivative order) is measured against its *condition scale*: the largest
//! first-order bound Σ|N^(a)(u)|·|N^(b)(v)|·|w·P| over the object's samples (per coordinate),
//! carried through the quotient rule for rational objects (NURBS Book A4.2/A4.4, with
//! magnitudes). It is never below the value-relative scale of a polynomial object's order, and
//! it is the same quantity for the oracle, the product and both refined nets.
//!
//! ERBS objects (not refined here) are compared by [`compare_output`] unchanged.

use serde_json::Value;

use super::compare::{Mismatch, Report, compare_output};
use super::eval::{
    Basis, Homogeneous, Point3, binomial, homogeneous, project_curve_derivatives,
    project_surface_derivatives,
};
use super::scene::{Object, Scene, Shape};

/// The larger of two numbers, NaN when either is NaN (`f64::max` would drop it).
pub fn nan_max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}

/// `[k][i]` = N_i^(k)(t) for k ≤ n: the basis functions' derivatives, one unit control
/// polygon at a time.
fn basis_table(basis: &Basis, count: usize, t: f64, n: usize) -> Vec<Vec<f64>> {
    let mut table = vec![vec![0.0; count]; n + 1];
    let mut unit = vec![[0.0]; count];
    for i in 0..count {
        unit[i] = [1.0];
        for (k, d) in basis.derivatives(&unit, t, n).into_iter().enumerate() {
            table[k][i] = d[0];
        }
        unit[i] = [0.0];
    }
    table
}

/// Accumulates Σ_i N_i·h_i and Σ_i |N_i|·|h_i| for one derivative order.
fn accumulate(row: &[f64], h: &[Homogeneous]) -> (Homogeneous, Homogeneous) {
    let (mut value, mut bound) = ([0.0; 4], [0.0; 4]);
    for (n, p) in row.iter().zip(h) {
        for c in 0..4 {
            value[c] += n * p[c];
            bound[c] += n.abs() * p[c].abs();
        }
    }
    (value, bound)
}

fn xyz(h: Homogeneous) -> Point3 {
    [h[0], h[1], h[2]]
}

/// Bounds on the Cartesian derivatives C^(k) = (A^(k) − Σ_{i≥1} C(k,i) w^(i) C^(k−i)) / w from
/// bounds `da` on the homogeneous ones (w in slot 3), to first order.
fn project_curve_bounds(a: &[Homogeneous], da: &[Homogeneous]) -> Vec<Point3> {
    let s = project_curve_derivatives(a);
    let w = a[0][3].abs();
    let mut ds: Vec<Point3> = Vec::with_capacity(a.len());
    for k in 0..a.len() {
        let bound = std::array::from_fn(|c| {
            let mut b = da[k][c] + da[0][3] * s[k][c].abs();
            for i in 1..=k {
                b += binomial(k, i) * (da[i][3] * s[k - i][c].abs() + a[i][3].abs() * ds[k - i][c]);
            }
            b / w
        });
        ds.push(bound);
    }
    ds
}

/// The same for surfaces, `[k][l]`: A^(k,l) = Σ_{i≤k, j≤l} C(k,i) C(l,j) w^(i,j) S^(k−i,l−j).
fn project_surface_bounds(a: &[Vec<Homogeneous>], da: &[Vec<Homogeneous>]) -> Vec<Vec<Point3>> {
    let s = project_surface_derivatives(a);
    let n = a.len() - 1;
    let w = a[0][0][3].abs();
    let mut ds = vec![vec![[0.0; 3]; n + 1]; n + 1];
    for k in 0..=n {
        for l in 0..=n {
            ds[k][l] = std::array::from_fn(|c| {
                let mut b = da[k][l][c] + da[0][0][3] * s[k][l][c].abs();
                for i in 0..=k {
                    for j in 0..=l {
                        if i + j == 0 {
                            continue;
                        }
                        let coefficient = binomial(k, i) * binomial(l, j);
                        b += coefficient
                            * (da[i][j][3] * s[k - i][l - j][c].abs()
                                + a[i][j][3].abs() * ds[k - i][l - j][c]);
                    }
                }
                b / w
            });
        }
    }
    ds
}

fn lift(points: &[Point3], weights: Option<&[f64]>) -> Vec<Homogeneous> {
    points
        .iter()
        .enumerate()
        .map(|(i, &p)| homogeneous(p, weights.map_or(1.0, |w| w[i])))
        .collect()
}

/// Per sample (row-major) and order slot (curves r; surfaces a·(n+1)+b), per coordinate: the
/// first-order rounding bound of the value, divided by ε. None for ERBS objects.
pub fn sample_bounds(object: &Object, params: &[Vec<f64>], n: usize) -> Option<Vec<Vec<Point3>>> {
    match &object.shape {
        Shape::Curve {
            basis,
            points,
            weights,
        } => {
            let h = lift(points, weights.as_deref());
            Some(
                params[0]
                    .iter()
                    .map(|&t| {
                        let table = basis_table(basis, h.len(), t, n);
                        let (a, da): (Vec<_>, Vec<_>) =
                            table.iter().map(|row| accumulate(row, &h)).unzip();
                        if weights.is_some() {
                            project_curve_bounds(&a, &da)
                        } else {
                            da.into_iter().map(xyz).collect()
                        }
                    })
                    .collect(),
            )
        }
        Shape::Surface {
            basis,
            points,
            weights,
        } => {
            let h: Vec<Vec<Homogeneous>> = points
                .iter()
                .enumerate()
                .map(|(i, row)| lift(row, weights.as_ref().map(|w| w[i].as_slice())))
                .collect();
            let (nu, nv) = (h.len(), h[0].len());
            let v_tables: Vec<Vec<Vec<f64>>> = params[1]
                .iter()
                .map(|&v| basis_table(&basis[1], nv, v, n))
                .collect();
            let mut out = Vec::with_capacity(params[0].len() * params[1].len());
            for &u in &params[0] {
                let tu = basis_table(&basis[0], nu, u, n);
                // g[a][j] = Σ_i N_i^(a)(u) H_ij, with its bound.
                let (g, dg): (Vec<Vec<Homogeneous>>, Vec<Vec<Homogeneous>>) = tu
                    .iter()
                    .map(|row| {
                        (0..nv)
                            .map(|j| {
                                let column: Vec<Homogeneous> = h.iter().map(|r| r[j]).collect();
                                accumulate(row, &column)
                            })
                            .unzip()
                    })
                    .unzip();
                for tv in &v_tables {
                    let mut a = vec![vec![[0.0; 4]; n + 1]; n + 1];
                    let mut da = vec![vec![[0.0; 4]; n + 1]; n + 1];
                    for ka in 0..=n {
                        for kb in 0..=n {
                            a[ka][kb] = accumulate(&tv[kb], &g[ka]).0;
                            da[ka][kb] = accumulate(&tv[kb], &dg[ka]).1;
                        }
                    }
                    let bounds = if weights.is_some() {
                        project_surface_bounds(&a, &da)
                    } else {
                        da.iter()
                            .map(|row| row.iter().map(|&d| xyz(d)).collect())
                            .collect()
                    };
                    out.push(bounds.into_iter().flatten().collect());
                }
            }
            Some(out)
        }
        Shape::ErbsCurve { .. } | Shape::ErbsSurface { .. } => None,
    }
}

/// Per order slot, the largest bound over the object's samples and coordinates: the
/// condition scale. None for ERBS objects.
pub fn condition_scales(object: &Object, params: &[Vec<f64>], n: usize) -> Option<Vec<f64>> {
    let bounds = sample_bounds(object, params, n)?;
    let slots = bounds.first().map_or(0, Vec::len);
    Some(
        (0..slots)
            .map(|slot| {
                bounds.iter().flat_map(|s| s[slot]).fold(0.0, |m: f64, x| {
                    if x.is_nan() { f64::NAN } else { m.max(x) }
                })
            })
            .collect(),
    )
}

/// The oracle's values of `object` at `params`, `[sample][slot]` as in [`sample_bounds`].
fn oracle_values(object: &Object, params: &[Vec<f64>], n: usize) -> Vec<Vec<Point3>> {
    if object.is_surface() {
        object
            .surface_grid(&params[0], &params[1], n)
            .into_iter()
            .flatten()
            .map(|p| p.into_iter().flatten().collect())
            .collect()
    } else {
        params[0]
            .iter()
            .map(|&t| object.curve_derivatives(t, n))
            .collect()
    }
}

fn numbers(v: &Value) -> Option<Vec<f64>> {
    v.as_array()?.iter().map(Value::as_f64).collect()
}

/// Sample parameters per direction, and values `[sample][slot]`.
type Samples = (Vec<Vec<f64>>, Vec<Vec<Point3>>);

/// One output entry's params and samples as `[sample][slot]`, or why they cannot be read.
fn entry_samples(entry: &Value, surface: bool, n: usize) -> Result<Samples, String> {
    let bad = |what: &str| format!("unreadable {what}");
    let params: Vec<Vec<f64>> = if surface {
        let dirs = entry["params"].as_array().ok_or_else(|| bad("params"))?;
        dirs.iter()
            .map(|d| numbers(d).ok_or_else(|| bad("params")))
            .collect::<Result<_, _>>()?
    } else {
        vec![numbers(&entry["params"]).ok_or_else(|| bad("params"))?]
    };
    let vector = |v: &Value| -> Result<Point3, String> {
        let xs = numbers(v)
            .filter(|x| x.len() == 3)
            .ok_or_else(|| bad("vector"))?;
        Ok([xs[0], xs[1], xs[2]])
    };
    let list = |v: &Value, len: usize| -> Result<Vec<Value>, String> {
        v.as_array()
            .filter(|a| a.len() == len)
            .cloned()
            .ok_or_else(|| bad("samples"))
    };
    let mut samples = Vec::new();
    if surface {
        for row in list(&entry["samples"], params[0].len())? {
            for cell in list(&row, params[1].len())? {
                let mut slots = Vec::with_capacity((n + 1) * (n + 1));
                for by_a in list(&cell, n + 1)? {
                    for value in list(&by_a, n + 1)? {
                        slots.push(vector(&value)?);
                    }
                }
                samples.push(slots);
            }
        }
    } else {
        for row in list(&entry["samples"], params[0].len())? {
            samples.push(
                list(&row, n + 1)?
                    .iter()
                    .map(vector)
                    .collect::<Result<_, _>>()?,
            );
        }
    }
    Ok((params, samples))
}

fn slot_name(surface: bool, n: usize, slot: usize) -> String {
    if surface {
        format!("[{}][{}]", slot / (n + 1), slot % (n + 1))
    } else {
        format!("[{slot}]")
    }
}

/// Which object's samples are compared, and their layout.
struct Layout<'a> {
    name: &'a str,
    surface: bool,
    n: usize,
}

/// Adds |x − y| / scale[slot] for every number of `ours` against `theirs` to `report`.
fn compare_values(
    layout: &Layout,
    theirs: &[Vec<Point3>],
    ours: &[Vec<Point3>],
    scales: &[f64],
    tol: f64,
    report: &mut Report,
) {
    let Layout { name, surface, n } = *layout;
    let mut listed = 0;
    for (s, (x, y)) in theirs.iter().zip(ours).enumerate() {
        for (slot, (xv, yv)) in x.iter().zip(y).enumerate() {
            for k in 0..3 {
                let err = (xv[k] - yv[k]).abs();
                let relative = if err == 0.0 { 0.0 } else { err / scales[slot] };
                report.compared += 1;
                report.max_relative_error =
                    if relative.is_nan() || report.max_relative_error.is_nan() {
                        f64::NAN
                    } else {
                        report.max_relative_error.max(relative)
                    };
                // NaN fails too.
                if relative.is_nan() || relative > tol {
                    report.mismatch_count += 1;
                    if listed < 8 {
                        listed += 1;
                        report.mismatches.push(Mismatch {
                            object: name.to_string(),
                            location: format!(
                                "sample {s} (row-major) order {}[{k}] (condition scale)",
                                slot_name(surface, n, slot)
                            ),
                            product: xv[k],
                            oracle: yv[k],
                            scale: scales[slot],
                        });
                    }
                }
            }
        }
    }
}

/// Keeps only the output entries of the named objects.
fn filter_output(output: &Value, names: &[&str]) -> Value {
    let entries: Vec<Value> = output["objects"]
        .as_array()
        .map(|list| {
            list.iter()
                .filter(|e| e["name"].as_str().is_some_and(|n| names.contains(&n)))
                .cloned()
                .collect()
        })
        .unwrap_or_default();
    serde_json::json!({ "objects": entries })
}

fn merge(into: &mut Report, other: Report) {
    into.problems.extend(other.problems);
    into.mismatches.extend(other.mismatches);
    into.mismatch_count += other.mismatch_count;
    into.compared += other.compared;
    into.max_relative_error =
        if into.max_relative_error.is_nan() || other.max_relative_error.is_nan() {
            f64::NAN
        } else {
            into.max_relative_error.max(other.max_relative_error)
        };
}

/// A `prespline sample` output against the oracle evaluation of `scene`, every Bézier/B-spline
/// object measured against its condition scales (`|x − y| ≤ tol · scale`), ERBS objects by
/// [`compare_output`] with the same `tol`. Names, types, parameters and shapes are checked by
/// [`compare_output`].
pub fn compare_conditioned(scene: &Scene, n: usize, output: &Value, tol: f64) -> Report {
    // Structure, parameters and NaN only: an infinite tolerance passes every finite number.
    let mut report = compare_output(scene, n, output, f64::INFINITY);
    report.compared = 0;
    report.max_relative_error = 0.0;
    if !report.problems.is_empty() {
        return report;
    }
    let (refined, erbs): (Vec<&Object>, Vec<&Object>) = scene
        .objects
        .iter()
        .partition(|o| matches!(o.shape, Shape::Curve { .. } | Shape::Surface { .. }));
    let entries = output["objects"].as_array().cloned().unwrap_or_default();
    for object in refined {
        let entry = entries
            .iter()
            .find(|e| e["name"].as_str() == Some(&object.name))
            .expect("compare_output found it");
        let surface = object.is_surface();
        match entry_samples(entry, surface, n) {
            Err(e) => report.problems.push(format!("{}: {e}", object.name)),
            Ok((params, theirs)) => {
                let scales = condition_scales(object, &params, n).expect("not ERBS");
                let ours = oracle_values(object, &params, n);
                let layout = Layout {
                    name: &object.name,
                    surface,
                    n,
                };
                compare_values(&layout, &theirs, &ours, &scales, tol, &mut report);
            }
        }
    }
    if !erbs.is_empty() {
        let names: Vec<&str> = erbs.iter().map(|o| o.name.as_str()).collect();
        let sub = Scene {
            objects: erbs.into_iter().cloned().collect(),
        };
        merge(
            &mut report,
            compare_output(&sub, n, &filter_output(output, &names), tol),
        );
    }
    report
}

/// Two `prespline sample` outputs of the same shapes, `after` from a refined model: the same
/// names, bit-identical parameters, and every number within `tol` of the larger of the
/// condition scales of `before` and `after` (the oracle's models of the two control nets).
/// Objects without condition scales (ERBS) are held to `tol` of their largest value per order.
pub fn compare_refined_outputs(
    before: &Scene,
    after: &Scene,
    n: usize,
    before_output: &Value,
    after_output: &Value,
    tol: f64,
) -> Report {
    let mut report = Report::default();
    let entry = |output: &Value, name: &str| -> Option<Value> {
        output["objects"]
            .as_array()?
            .iter()
            .find(|e| e["name"].as_str() == Some(name))
            .cloned()
    };
    for (b, a) in before.objects.iter().zip(&after.objects) {
        let surface = b.is_surface();
        let (Some(eb), Some(ea)) = (entry(before_output, &b.name), entry(after_output, &a.name))
        else {
            report
                .problems
                .push(format!("{}: missing from an output", b.name));
            continue;
        };
        let read = |e: &Value| entry_samples(e, surface, n);
        let ((pb, sb), (pa, sa)) = match (read(&eb), read(&ea)) {
            (Ok(x), Ok(y)) => (x, y),
            (Err(e), _) | (_, Err(e)) => {
                report.problems.push(format!("{}: {e}", b.name));
                continue;
            }
        };
        if pb != pa {
            report
                .problems
                .push(format!("{}: parameters changed", b.name));
            continue;
        }
        let scales: Vec<f64> = match (condition_scales(b, &pb, n), condition_scales(a, &pa, n)) {
            (Some(x), Some(y)) => x.iter().zip(&y).map(|(p, q)| p.max(*q)).collect(),
            _ => {
                let slots = sb.first().map_or(0, Vec::len);
                (0..slots)
                    .map(|slot| {
                        sb.iter()
                            .flat_map(|s| s[slot])
                            .fold(0.0, |m, x| nan_max(m, x.abs()))
                    })
                    .collect()
            }
        };
        let layout = Layout {
            name: &b.name,
            surface,
            n,
        };
        compare_values(&layout, &sa, &sb, &scales, tol, &mut report);
    }
    if before.objects.len() != after.objects.len() {
        report.problems.push("object counts differ".into());
    }
    report
}
