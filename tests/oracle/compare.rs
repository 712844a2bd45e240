//! Comparison of a `prespline sample` output against the oracle.
//!
//! Error measure: for every number x (product) and y (oracle) of an object's samples,
//!   |x − y| ≤ rel_tol · scale,
//! where scale = max |value| over that object's oracle samples of the same derivative order —
//! per r for curves, per (a, b) for surfaces — with no floor, so a small object is held to its
//! own size. Where a derivative order vanishes identically (above a polynomial's degree) its
//! scale is the object's position magnitude instead, so rounding noise there is measured
//! against the object's size rather than against zero. NaN never passes: a NaN on either side
//! is a mismatch and makes the maximum error NaN. The oracle is evaluated at the product's own
//! parameters; those must equal the contract's formula to within 4 ulp of the domain size.

use serde_json::Value;

use super::eval::Point3;
use super::scene::{Object, Scene};

/// One number that differs by more than the tolerance.
#[derive(Clone, Debug)]
pub struct Mismatch {
    pub object: String,
    /// `params[j]/samples[j][r][k]` or `samples[i][j][a][b][k]`, with the parameters.
    pub location: String,
    pub product: f64,
    pub oracle: f64,
    pub scale: f64,
}

/// Outcome of one comparison.
#[derive(Clone, Debug, Default)]
pub struct Report {
    /// Structural problems (missing objects, wrong shapes, wrong params, non-numbers).
    pub problems: Vec<String>,
    /// The first mismatches (at most `MAX_LISTED` per object).
    pub mismatches: Vec<Mismatch>,
    /// All mismatches, including unlisted ones.
    pub mismatch_count: usize,
    /// Numbers compared.
    pub compared: usize,
    /// max |x − y| / scale over everything compared (NaN when anything compared was NaN).
    pub max_relative_error: f64,
}

/// The larger of two numbers, NaN when either is NaN (`f64::max` returns the other one).
pub fn nan_max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}

/// Per-order scales from per-order maxima of |value|: an order that vanishes identically is
/// measured against the position magnitude (order 0) instead.
fn scales_or_position(maxima: &mut [f64], position: f64) {
    for m in maxima.iter_mut() {
        if *m == 0.0 {
            *m = position;
        }
    }
}

const MAX_LISTED: usize = 8;

impl Report {
    pub fn ok(&self) -> bool {
        self.problems.is_empty() && self.mismatch_count == 0
    }

    /// Human-readable summary of everything that went wrong.
    pub fn describe(&self) -> String {
        let mut s = String::new();
        for p in &self.problems {
            s += &format!("  problem: {p}\n");
        }
        for m in &self.mismatches {
            s += &format!(
                "  {} {}: product {:e}, oracle {:e}, |diff| {:e} = {:.3e} × scale {:e}\n",
                m.object,
                m.location,
                m.product,
                m.oracle,
                (m.product - m.oracle).abs(),
                (m.product - m.oracle).abs() / m.scale,
                m.scale
            );
        }
        if self.mismatch_count > self.mismatches.len() {
            s += &format!("  … {} mismatches in all\n", self.mismatch_count);
        }
        s
    }
}

/// Whether `product` equals the contract's parameter formula, to within 4 ulp of the domain.
fn params_agree(product: f64, oracle: f64, (a, b): (f64, f64)) -> bool {
    let size = a.abs().max(b.abs()).max((b - a).abs());
    (product - oracle).abs() <= 4.0 * f64::EPSILON * size
}

fn parse_params(v: &Value, m: usize) -> Result<Vec<f64>, String> {
    let list = v.as_array().ok_or("params: not an array")?;
    if list.len() != m {
        return Err(format!("params: {} values, scene asks for {m}", list.len()));
    }
    list.iter()
        .map(|x| x.as_f64().ok_or_else(|| "params: not a number".to_string()))
        .collect()
}

/// Compares a parsed `prespline sample` output with the oracle evaluation of `scene` for
/// derivative order `n`.
pub fn compare_output(scene: &Scene, n: usize, product: &Value, rel_tol: f64) -> Report {
    let mut report = Report::default();
    let Some(entries) = product.get("objects").and_then(Value::as_array) else {
        report
            .problems
            .push("output has no \"objects\" array".to_string());
        return report;
    };
    for entry in entries {
        let name = entry.get("name").and_then(Value::as_str).unwrap_or("?");
        if scene.object(name).is_none() {
            report.problems.push(format!("unexpected object {name:?}"));
        }
    }
    for object in &scene.objects {
        let found: Vec<&Value> = entries
            .iter()
            .filter(|e| e.get("name").and_then(Value::as_str) == Some(&object.name))
            .collect();
        match found.as_slice() {
            [entry] => compare_object(object, n, entry, rel_tol, &mut report),
            [] => report
                .problems
                .push(format!("object {:?} missing from the output", object.name)),
            _ => report
                .problems
                .push(format!("object {:?} appears more than once", object.name)),
        }
    }
    report
}

fn compare_object(object: &Object, n: usize, entry: &Value, rel_tol: f64, report: &mut Report) {
    let name = &object.name;
    let problem =
        |report: &mut Report, what: String| report.problems.push(format!("{name}: {what}"));
    if entry.get("type").and_then(Value::as_str) != Some(object.type_name()) {
        problem(
            report,
            format!(
                "type {:?}, expected {:?}",
                entry.get("type"),
                object.type_name()
            ),
        );
        return;
    }
    // Parameters: the product's, checked against the formula.
    let own = object.params();
    let domains = object.domains();
    let params: Vec<Vec<f64>> = if object.is_surface() {
        let dirs = entry.get("params").and_then(Value::as_array);
        match dirs {
            Some(d) if d.len() == 2 => {
                match (
                    parse_params(&d[0], own[0].len()),
                    parse_params(&d[1], own[1].len()),
                ) {
                    (Ok(u), Ok(v)) => vec![u, v],
                    (Err(e), _) | (_, Err(e)) => return problem(report, e),
                }
            }
            _ => return problem(report, "params: expected [[u…], [v…]]".to_string()),
        }
    } else {
        match entry.get("params").map(|p| parse_params(p, own[0].len())) {
            Some(Ok(t)) => vec![t],
            Some(Err(e)) => return problem(report, e),
            None => return problem(report, "no params".to_string()),
        }
    };
    for (dir, (theirs, ours)) in params.iter().zip(&own).enumerate() {
        for (j, (&x, &y)) in theirs.iter().zip(ours).enumerate() {
            if !params_agree(x, y, domains[dir]) {
                problem(
                    report,
                    format!("params[{dir}][{j}] = {x:e}, formula gives {y:e}"),
                );
            }
        }
    }
    let Some(samples) = entry.get("samples") else {
        return problem(report, "no samples".to_string());
    };
    let mut listed = 0;
    let mut check =
        |report: &mut Report, location: String, theirs: &Value, ours: Point3, scale: f64| {
            let Some(list) = theirs.as_array().filter(|l| l.len() == 3) else {
                report
                    .problems
                    .push(format!("{name}: {location}: not a 3-vector"));
                return;
            };
            for k in 0..3 {
                let Some(x) = list[k].as_f64() else {
                    report
                        .problems
                        .push(format!("{name}: {location}[{k}]: not a number"));
                    continue;
                };
                let y = ours[k];
                let err = (x - y).abs();
                report.compared += 1;
                let relative = if err == 0.0 { 0.0 } else { err / scale };
                report.max_relative_error = nan_max(report.max_relative_error, relative);
                if err.is_nan() || err > rel_tol * scale {
                    report.mismatch_count += 1;
                    if listed < MAX_LISTED {
                        listed += 1;
                        report.mismatches.push(Mismatch {
                            object: name.clone(),
                            location: format!("{location}[{k}]"),
                            product: x,
                            oracle: y,
                            scale,
                        });
                    }
                }
            }
        };
    let shape_error = |what: &str| format!("samples: wrong shape at {what}");
    if object.is_surface() {
        let ours = object.surface_grid(&params[0], &params[1], n);
        let mut scales = vec![vec![0.0f64; n + 1]; n + 1];
        for p in ours.iter().flatten() {
            for (a, row) in p.iter().enumerate() {
                for (b, v) in row.iter().enumerate() {
                    for x in v {
                        scales[a][b] = nan_max(scales[a][b], x.abs());
                    }
                }
            }
        }
        let position = scales[0][0];
        scales
            .iter_mut()
            .for_each(|row| scales_or_position(row, position));
        let Some(rows) = samples.as_array().filter(|r| r.len() == ours.len()) else {
            return problem(report, shape_error("[i]"));
        };
        for (i, row) in rows.iter().enumerate() {
            let Some(row) = row.as_array().filter(|r| r.len() == ours[i].len()) else {
                return problem(report, shape_error(&format!("[{i}]")));
            };
            for (j, cell) in row.iter().enumerate() {
                let Some(cell) = cell.as_array().filter(|c| c.len() == n + 1) else {
                    return problem(report, shape_error(&format!("[{i}][{j}]")));
                };
                for (a, by_a) in cell.iter().enumerate() {
                    let Some(by_a) = by_a.as_array().filter(|c| c.len() == n + 1) else {
                        return problem(report, shape_error(&format!("[{i}][{j}][{a}]")));
                    };
                    for (b, value) in by_a.iter().enumerate() {
                        let location = format!(
                            "samples[{i}][{j}][{a}][{b}] (u={:e}, v={:e})",
                            params[0][i], params[1][j]
                        );
                        check(report, location, value, ours[i][j][a][b], scales[a][b]);
                    }
                }
            }
        }
    } else {
        let ours: Vec<Vec<Point3>> = params[0]
            .iter()
            .map(|&t| object.curve_derivatives(t, n))
            .collect();
        let mut scales = vec![0.0f64; n + 1];
        for p in &ours {
            for (r, v) in p.iter().enumerate() {
                for x in v {
                    scales[r] = nan_max(scales[r], x.abs());
                }
            }
        }
        let position = scales[0];
        scales_or_position(&mut scales, position);
        let Some(rows) = samples.as_array().filter(|r| r.len() == ours.len()) else {
            return problem(report, shape_error("[j]"));
        };
        for (j, row) in rows.iter().enumerate() {
            let Some(row) = row.as_array().filter(|r| r.len() == n + 1) else {
                return problem(report, shape_error(&format!("[{j}]")));
            };
            for (r, value) in row.iter().enumerate() {
                let location = format!("samples[{j}][{r}] (t={:e})", params[0][j]);
                check(report, location, value, ours[j][r], scales[r]);
            }
        }
    }
}
