//! Scene model (parsed from `serde_json::Value` per the scene contract of
//! docs/scene-format.md), edits applied to the model, and the `prespline sample` output shape.

use serde_json::{Map, Value, json};

use super::bfunction::BFunction;
use super::blossom::Spline;
use super::eval::{
    self, Basis, Homogeneous, Point3, erbs_curve_derivatives, erbs_surface_derivatives,
    homogeneous, project_curve_derivatives, project_surface_derivatives,
};

/// The geometry of one scene object.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// `bezier_curve` (basis Bézier) or `bspline_curve` (basis B-spline).
    Curve {
        basis: Basis,
        points: Vec<Point3>,
        weights: Option<Vec<f64>>,
    },
    /// `bezier_surface` or `bspline_surface`; `points[i][j]`, i along u.
    Surface {
        basis: [Basis; 2],
        points: Vec<Vec<Point3>>,
        weights: Option<Vec<Vec<f64>>>,
    },
    /// `erbs_curve`: knots t_0..t_{n+1}, n local Bézier curves.
    ErbsCurve {
        knots: Vec<f64>,
        locals: Vec<Vec<Point3>>,
        bfunction: Option<BFunction>,
    },
    /// `erbs_surface`: knots per direction, `locals[k][l]` Bézier patches with points `[a][b]`.
    ErbsSurface {
        knots: [Vec<f64>; 2],
        locals: Vec<Vec<Vec<Vec<Point3>>>>,
        bfunction: Option<BFunction>,
    },
}

/// One named object with its sample counts (one entry for curves, two for surfaces).
#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    pub name: String,
    pub shape: Shape,
    pub samples: Vec<usize>,
}

#[derive(Clone, Debug, PartialEq, Default)]
pub struct Scene {
    pub objects: Vec<Object>,
}

/// Sample parameters: m ≥ 2 values t_j = a + (b − a)·(j/(m−1)) for j < m−1 and t_{m−1} = b exactly.
pub fn sample_params(a: f64, b: f64, m: usize) -> Vec<f64> {
    assert!(m >= 2, "at least two samples");
    (0..m)
        .map(|j| {
            if j == m - 1 {
                b
            } else {
                a + (b - a) * (j as f64 / (m - 1) as f64)
            }
        })
        .collect()
}

// ---------------------------------------------------------------------------------------------
// Parsing
// ---------------------------------------------------------------------------------------------

type Fields<'a> = &'a Map<String, Value>;

fn field<'a>(obj: Fields<'a>, name: &str, ctx: &str) -> Result<&'a Value, String> {
    obj.get(name)
        .ok_or_else(|| format!("{ctx}: missing field {name:?}"))
}

fn number(v: &Value, ctx: &str) -> Result<f64, String> {
    let x = v
        .as_f64()
        .ok_or_else(|| format!("{ctx}: expected a number"))?;
    if x.is_finite() {
        Ok(x)
    } else {
        Err(format!("{ctx}: not finite"))
    }
}

fn count(v: &Value, ctx: &str) -> Result<usize, String> {
    v.as_u64()
        .map(|x| x as usize)
        .ok_or_else(|| format!("{ctx}: expected a non-negative integer"))
}

fn array<'a>(v: &'a Value, ctx: &str) -> Result<&'a Vec<Value>, String> {
    v.as_array()
        .ok_or_else(|| format!("{ctx}: expected an array"))
}

fn numbers(v: &Value, ctx: &str) -> Result<Vec<f64>, String> {
    array(v, ctx)?
        .iter()
        .enumerate()
        .map(|(i, x)| number(x, &format!("{ctx}[{i}]")))
        .collect()
}

fn point(v: &Value, ctx: &str) -> Result<Point3, String> {
    let xs = numbers(v, ctx)?;
    if xs.len() != 3 {
        return Err(format!("{ctx}: expected 3 coordinates"));
    }
    Ok([xs[0], xs[1], xs[2]])
}

fn point_list(v: &Value, ctx: &str) -> Result<Vec<Point3>, String> {
    let list: Vec<Point3> = array(v, ctx)?
        .iter()
        .enumerate()
        .map(|(i, p)| point(p, &format!("{ctx}[{i}]")))
        .collect::<Result<_, _>>()?;
    if list.is_empty() {
        return Err(format!("{ctx}: no points"));
    }
    Ok(list)
}

fn point_grid(v: &Value, ctx: &str) -> Result<Vec<Vec<Point3>>, String> {
    let grid: Vec<Vec<Point3>> = array(v, ctx)?
        .iter()
        .enumerate()
        .map(|(i, row)| point_list(row, &format!("{ctx}[{i}]")))
        .collect::<Result<_, _>>()?;
    if grid.is_empty() || grid.iter().any(|row| row.len() != grid[0].len()) {
        return Err(format!("{ctx}: not a non-empty rectangular grid"));
    }
    Ok(grid)
}

fn weight_grid(v: &Value, rows: usize, cols: usize, ctx: &str) -> Result<Vec<Vec<f64>>, String> {
    let grid: Vec<Vec<f64>> = array(v, ctx)?
        .iter()
        .enumerate()
        .map(|(i, row)| numbers(row, &format!("{ctx}[{i}]")))
        .collect::<Result<_, _>>()?;
    if grid.len() != rows || grid.iter().any(|r| r.len() != cols) {
        return Err(format!("{ctx}: expected {rows}×{cols} weights"));
    }
    Ok(grid)
}

fn check_bspline_knots(degree: usize, knots: &[f64], n: usize, ctx: &str) -> Result<(), String> {
    if degree >= n {
        return Err(format!("{ctx}: degree {degree} ≥ point count {n}"));
    }
    if knots.len() != n + degree + 1 {
        return Err(format!("{ctx}: expected {} knots", n + degree + 1));
    }
    if knots.windows(2).any(|w| w[0] > w[1]) {
        return Err(format!("{ctx}: knots decreasing"));
    }
    if knots[degree] >= knots[n] {
        return Err(format!("{ctx}: empty domain"));
    }
    Ok(())
}

fn check_erbs_knots(knots: &[f64], n: usize, ctx: &str) -> Result<(), String> {
    if n < 2 {
        return Err(format!("{ctx}: need at least 2 local curves"));
    }
    if knots.len() != n + 2 {
        return Err(format!("{ctx}: expected {} knots", n + 2));
    }
    if knots[0] != knots[1] || knots[n] != knots[n + 1] {
        return Err(format!("{ctx}: end knots must be doubled"));
    }
    if knots[1..=n].windows(2).any(|w| w[0] >= w[1]) {
        return Err(format!("{ctx}: interior knots not strictly increasing"));
    }
    Ok(())
}

fn samples_field(v: &Value, dims: usize, ctx: &str) -> Result<Vec<usize>, String> {
    let s = if dims == 1 {
        vec![count(v, ctx)?]
    } else {
        let list = array(v, ctx)?;
        if list.len() != 2 {
            return Err(format!("{ctx}: expected [mu, mv]"));
        }
        vec![count(&list[0], ctx)?, count(&list[1], ctx)?]
    };
    if s.iter().any(|&m| m < 2) {
        return Err(format!("{ctx}: at least 2 samples per direction"));
    }
    Ok(s)
}

fn bfunction_field(obj: Fields, ctx: &str) -> Result<Option<BFunction>, String> {
    match obj.get("bfunction") {
        None => Ok(None),
        Some(v) => {
            let name = v
                .as_str()
                .ok_or_else(|| format!("{ctx}.bfunction: expected a string"))?;
            BFunction::from_name(name).map(Some)
        }
    }
}

impl Object {
    /// Parses one object of the scene contract; unknown fields are rejected.
    pub fn from_json(v: &Value) -> Result<Object, String> {
        let obj = v.as_object().ok_or("object: expected a JSON object")?;
        let name = field(obj, "name", "object")?
            .as_str()
            .ok_or("object.name: expected a string")?
            .to_string();
        let ctx = name.clone();
        let ty = field(obj, "type", &ctx)?
            .as_str()
            .ok_or_else(|| format!("{ctx}.type: expected a string"))?;
        let allowed: &[&str] = match ty {
            "bezier_curve" | "bezier_surface" => &["points", "weights", "samples"],
            "bspline_curve" | "bspline_surface" => {
                &["degree", "knots", "points", "weights", "samples"]
            }
            "erbs_curve" | "erbs_surface" => &["knots", "local", "bfunction", "samples"],
            other => return Err(format!("{ctx}: unknown type {other:?}")),
        };
        if let Some(extra) = obj
            .keys()
            .find(|k| *k != "name" && *k != "type" && !allowed.contains(&k.as_str()))
        {
            return Err(format!("{ctx}: unknown field {extra:?}"));
        }
        let is_surface = ty.ends_with("_surface");
        let samples = samples_field(
            field(obj, "samples", &ctx)?,
            if is_surface { 2 } else { 1 },
            &format!("{ctx}.samples"),
        )?;
        let shape = match ty {
            "bezier_curve" | "bspline_curve" => {
                let points = point_list(field(obj, "points", &ctx)?, &format!("{ctx}.points"))?;
                let basis = if ty == "bezier_curve" {
                    Basis::Bezier
                } else {
                    let degree = count(field(obj, "degree", &ctx)?, &format!("{ctx}.degree"))?;
                    let knots = numbers(field(obj, "knots", &ctx)?, &format!("{ctx}.knots"))?;
                    check_bspline_knots(degree, &knots, points.len(), &format!("{ctx}.knots"))?;
                    Basis::BSpline { degree, knots }
                };
                let weights = match obj.get("weights") {
                    None => None,
                    Some(w) => {
                        let w = numbers(w, &format!("{ctx}.weights"))?;
                        if w.len() != points.len() {
                            return Err(format!("{ctx}.weights: expected {}", points.len()));
                        }
                        Some(w)
                    }
                };
                Shape::Curve {
                    basis,
                    points,
                    weights,
                }
            }
            "bezier_surface" | "bspline_surface" => {
                let points = point_grid(field(obj, "points", &ctx)?, &format!("{ctx}.points"))?;
                let (nu, nv) = (points.len(), points[0].len());
                let basis = if ty == "bezier_surface" {
                    [Basis::Bezier, Basis::Bezier]
                } else {
                    let degree = array(field(obj, "degree", &ctx)?, &format!("{ctx}.degree"))?;
                    let knots = array(field(obj, "knots", &ctx)?, &format!("{ctx}.knots"))?;
                    if degree.len() != 2 || knots.len() != 2 {
                        return Err(format!("{ctx}: degree and knots need two directions"));
                    }
                    let mut bases = Vec::new();
                    for (dir, n) in [(0, nu), (1, nv)] {
                        let d = count(&degree[dir], &format!("{ctx}.degree[{dir}]"))?;
                        let k = numbers(&knots[dir], &format!("{ctx}.knots[{dir}]"))?;
                        check_bspline_knots(d, &k, n, &format!("{ctx}.knots[{dir}]"))?;
                        bases.push(Basis::BSpline {
                            degree: d,
                            knots: k,
                        });
                    }
                    let v = bases.pop().unwrap();
                    let u = bases.pop().unwrap();
                    [u, v]
                };
                let weights = match obj.get("weights") {
                    None => None,
                    Some(w) => Some(weight_grid(w, nu, nv, &format!("{ctx}.weights"))?),
                };
                Shape::Surface {
                    basis,
                    points,
                    weights,
                }
            }
            "erbs_curve" => {
                let locals: Vec<Vec<Point3>> = array(field(obj, "local", &ctx)?, &ctx)?
                    .iter()
                    .enumerate()
                    .map(|(l, local)| {
                        let lctx = format!("{ctx}.local[{l}]");
                        let lo = local
                            .as_object()
                            .ok_or(format!("{lctx}: expected object"))?;
                        if lo.keys().any(|k| k != "points") {
                            return Err(format!("{lctx}: unknown field"));
                        }
                        point_list(field(lo, "points", &lctx)?, &format!("{lctx}.points"))
                    })
                    .collect::<Result<_, _>>()?;
                let knots = numbers(field(obj, "knots", &ctx)?, &format!("{ctx}.knots"))?;
                check_erbs_knots(&knots, locals.len(), &format!("{ctx}.knots"))?;
                Shape::ErbsCurve {
                    knots,
                    locals,
                    bfunction: bfunction_field(obj, &ctx)?,
                }
            }
            "erbs_surface" => {
                let rows = array(field(obj, "local", &ctx)?, &ctx)?;
                let mut locals = Vec::new();
                for (k, row) in rows.iter().enumerate() {
                    let mut out_row = Vec::new();
                    for (l, local) in array(row, &ctx)?.iter().enumerate() {
                        let lctx = format!("{ctx}.local[{k}][{l}]");
                        let lo = local
                            .as_object()
                            .ok_or(format!("{lctx}: expected object"))?;
                        if lo.keys().any(|k| k != "points") {
                            return Err(format!("{lctx}: unknown field"));
                        }
                        out_row.push(point_grid(
                            field(lo, "points", &lctx)?,
                            &format!("{lctx}.points"),
                        )?);
                    }
                    locals.push(out_row);
                }
                if locals.is_empty() || locals.iter().any(|r| r.len() != locals[0].len()) {
                    return Err(format!("{ctx}.local: not a rectangular grid"));
                }
                let knots = array(field(obj, "knots", &ctx)?, &format!("{ctx}.knots"))?;
                if knots.len() != 2 {
                    return Err(format!("{ctx}.knots: need two directions"));
                }
                let ku = numbers(&knots[0], &format!("{ctx}.knots[0]"))?;
                let kv = numbers(&knots[1], &format!("{ctx}.knots[1]"))?;
                check_erbs_knots(&ku, locals.len(), &format!("{ctx}.knots[0]"))?;
                check_erbs_knots(&kv, locals[0].len(), &format!("{ctx}.knots[1]"))?;
                Shape::ErbsSurface {
                    knots: [ku, kv],
                    locals,
                    bfunction: bfunction_field(obj, &ctx)?,
                }
            }
            _ => unreachable!(),
        };
        Ok(Object {
            name,
            shape,
            samples,
        })
    }

    /// The scene-contract JSON of this object.
    pub fn to_json(&self) -> Value {
        let mut m = Map::new();
        m.insert("name".into(), json!(self.name));
        m.insert("type".into(), json!(self.type_name()));
        let samples = if self.samples.len() == 1 {
            json!(self.samples[0])
        } else {
            json!(self.samples)
        };
        match &self.shape {
            Shape::Curve {
                basis,
                points,
                weights,
            } => {
                if let Basis::BSpline { degree, knots } = basis {
                    m.insert("degree".into(), json!(degree));
                    m.insert("knots".into(), json!(knots));
                }
                m.insert("points".into(), json!(points));
                if let Some(w) = weights {
                    m.insert("weights".into(), json!(w));
                }
            }
            Shape::Surface {
                basis,
                points,
                weights,
            } => {
                if let [
                    Basis::BSpline {
                        degree: du,
                        knots: ku,
                    },
                    Basis::BSpline {
                        degree: dv,
                        knots: kv,
                    },
                ] = basis
                {
                    m.insert("degree".into(), json!([du, dv]));
                    m.insert("knots".into(), json!([ku, kv]));
                }
                m.insert("points".into(), json!(points));
                if let Some(w) = weights {
                    m.insert("weights".into(), json!(w));
                }
            }
            Shape::ErbsCurve {
                knots,
                locals,
                bfunction,
            } => {
                m.insert("knots".into(), json!(knots));
                let locals: Vec<Value> = locals.iter().map(|p| json!({ "points": p })).collect();
                m.insert("local".into(), json!(locals));
                if let Some(b) = bfunction {
                    m.insert("bfunction".into(), json!(b.name()));
                }
            }
            Shape::ErbsSurface {
                knots,
                locals,
                bfunction,
            } => {
                m.insert("knots".into(), json!(knots));
                let locals: Vec<Vec<Value>> = locals
                    .iter()
                    .map(|row| row.iter().map(|p| json!({ "points": p })).collect())
                    .collect();
                m.insert("local".into(), json!(locals));
                if let Some(b) = bfunction {
                    m.insert("bfunction".into(), json!(b.name()));
                }
            }
        }
        m.insert("samples".into(), samples);
        Value::Object(m)
    }

    pub fn type_name(&self) -> &'static str {
        match &self.shape {
            Shape::Curve {
                basis: Basis::Bezier,
                ..
            } => "bezier_curve",
            Shape::Curve { .. } => "bspline_curve",
            Shape::Surface {
                basis: [Basis::Bezier, _],
                ..
            } => "bezier_surface",
            Shape::Surface { .. } => "bspline_surface",
            Shape::ErbsCurve { .. } => "erbs_curve",
            Shape::ErbsSurface { .. } => "erbs_surface",
        }
    }

    pub fn is_surface(&self) -> bool {
        matches!(
            self.shape,
            Shape::Surface { .. } | Shape::ErbsSurface { .. }
        )
    }

    /// Parameter domain per direction.
    pub fn domains(&self) -> Vec<(f64, f64)> {
        match &self.shape {
            Shape::Curve { basis, points, .. } => vec![basis.domain(points.len())],
            Shape::Surface { basis, points, .. } => vec![
                basis[0].domain(points.len()),
                basis[1].domain(points[0].len()),
            ],
            Shape::ErbsCurve { knots, .. } => vec![(knots[1], knots[knots.len() - 2])],
            Shape::ErbsSurface { knots, .. } => {
                knots.iter().map(|k| (k[1], k[k.len() - 2])).collect()
            }
        }
    }

    /// The oracle's own sample parameters per direction.
    pub fn params(&self) -> Vec<Vec<f64>> {
        self.domains()
            .iter()
            .zip(&self.samples)
            .map(|(&(a, b), &m)| sample_params(a, b, m))
            .collect()
    }

    /// Curve derivatives 0..=n at t (panics for surfaces).
    pub fn curve_derivatives(&self, t: f64, n: usize) -> Vec<Point3> {
        match &self.shape {
            Shape::Curve {
                basis,
                points,
                weights,
            } => {
                let h = lift_curve(points, weights.as_deref());
                project_curve_derivatives(&basis.derivatives(&h, t, n))
            }
            Shape::ErbsCurve {
                knots,
                locals,
                bfunction,
            } => erbs_curve_derivatives(bfunction.unwrap_or(BFunction::Expo), knots, locals, t, n),
            _ => panic!("{} is not a curve", self.name),
        }
    }

    /// Surface mixed partials `[a][b]`, 0..=n each, at (u, v) (panics for curves).
    pub fn surface_derivatives(&self, u: f64, v: f64, n: usize) -> Vec<Vec<Point3>> {
        self.surface_grid(&[u], &[v], n).remove(0).remove(0)
    }

    /// Surface mixed partials on the grid `us × vs`: `[i][j][a][b]`.
    pub fn surface_grid(&self, us: &[f64], vs: &[f64], n: usize) -> Vec<Vec<Vec<Vec<Point3>>>> {
        match &self.shape {
            Shape::Surface {
                basis,
                points,
                weights,
            } => {
                let h = lift_surface(points, weights.as_ref());
                us.iter()
                    .map(|&u| {
                        let columns = eval::u_stage(&basis[0], &h, u, n);
                        vs.iter()
                            .map(|&v| {
                                let hd = eval::v_stage(&basis[1], &columns, v, n);
                                project_surface_derivatives(&hd)
                            })
                            .collect()
                    })
                    .collect()
            }
            Shape::ErbsSurface {
                knots,
                locals,
                bfunction,
            } => {
                let b = bfunction.unwrap_or(BFunction::Expo);
                us.iter()
                    .map(|&u| {
                        vs.iter()
                            .map(|&v| {
                                erbs_surface_derivatives(
                                    b,
                                    [&knots[0], &knots[1]],
                                    locals,
                                    (u, v),
                                    n,
                                )
                            })
                            .collect()
                    })
                    .collect()
            }
            _ => panic!("{} is not a surface", self.name),
        }
    }

    /// `samples` in the contract shape at the given parameters: curves `[m][n+1][3]`,
    /// surfaces `[mu][mv][n+1][n+1][3]`.
    pub fn samples_json(&self, params: &[Vec<f64>], n: usize) -> Value {
        if self.is_surface() {
            json!(self.surface_grid(&params[0], &params[1], n))
        } else {
            let rows: Vec<Vec<Point3>> = params[0]
                .iter()
                .map(|&t| self.curve_derivatives(t, n))
                .collect();
            json!(rows)
        }
    }

    /// One entry of the `prespline sample` output, at the oracle's own parameters.
    pub fn sample_json(&self, n: usize) -> Value {
        let params = self.params();
        self.sample_json_at(&params, n)
    }

    /// One entry of the `prespline sample` output at the given parameters.
    pub fn sample_json_at(&self, params: &[Vec<f64>], n: usize) -> Value {
        let params_json = if self.is_surface() {
            json!(params)
        } else {
            json!(params[0])
        };
        json!({
            "name": self.name,
            "type": self.type_name(),
            "params": params_json,
            "samples": self.samples_json(params, n),
        })
    }

    /// Control-point bounding-box size (max |coordinate| over all points), for scaling deltas.
    pub fn magnitude(&self) -> f64 {
        let mut m: f64 = 0.0;
        let mut see = |p: &Point3| {
            for x in p {
                m = m.max(x.abs());
            }
        };
        match &self.shape {
            Shape::Curve { points, .. } => points.iter().for_each(&mut see),
            Shape::Surface { points, .. } => points.iter().flatten().for_each(&mut see),
            Shape::ErbsCurve { locals, .. } => locals.iter().flatten().for_each(&mut see),
            Shape::ErbsSurface { locals, .. } => locals
                .iter()
                .flatten()
                .flatten()
                .flatten()
                .for_each(&mut see),
        }
        m
    }
}

fn lift_curve(points: &[Point3], weights: Option<&[f64]>) -> Vec<Homogeneous> {
    points
        .iter()
        .enumerate()
        .map(|(i, &p)| homogeneous(p, weights.map_or(1.0, |w| w[i])))
        .collect()
}

fn lift_surface(points: &[Vec<Point3>], weights: Option<&Vec<Vec<f64>>>) -> Vec<Vec<Homogeneous>> {
    points
        .iter()
        .enumerate()
        .map(|(i, row)| {
            row.iter()
                .enumerate()
                .map(|(j, &p)| homogeneous(p, weights.map_or(1.0, |w| w[i][j])))
                .collect()
        })
        .collect()
}

impl Scene {
    pub fn from_json(v: &Value) -> Result<Scene, String> {
        let top = v.as_object().ok_or("scene: expected a JSON object")?;
        if let Some(k) = top.keys().find(|k| *k != "objects") {
            return Err(format!("scene: unknown field {k:?}"));
        }
        let objects = array(field(top, "objects", "scene")?, "scene.objects")?
            .iter()
            .map(Object::from_json)
            .collect::<Result<Vec<_>, _>>()?;
        for (i, o) in objects.iter().enumerate() {
            if objects[..i].iter().any(|p| p.name == o.name) {
                return Err(format!("{}: duplicate name", o.name));
            }
        }
        Ok(Scene { objects })
    }

    pub fn to_json(&self) -> Value {
        json!({ "objects": self.objects.iter().map(Object::to_json).collect::<Vec<_>>() })
    }

    /// The full `prespline sample` output for derivative order n at the oracle's parameters.
    pub fn sample_json(&self, n: usize) -> Value {
        json!({ "objects": self.objects.iter().map(|o| o.sample_json(n)).collect::<Vec<_>>() })
    }

    pub fn object(&self, name: &str) -> Option<&Object> {
        self.objects.iter().find(|o| o.name == name)
    }

    fn object_mut(&mut self, name: &str) -> Result<&mut Object, String> {
        self.objects
            .iter_mut()
            .find(|o| o.name == name)
            .ok_or_else(|| format!("edit: unknown object {name:?}"))
    }
}

// ---------------------------------------------------------------------------------------------
// Edits
// ---------------------------------------------------------------------------------------------

/// A control-point or local-curve index: `i` for curves, `[i, j]` for surfaces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Index {
    One(usize),
    Two(usize, usize),
}

impl Index {
    fn from_json(v: &Value, ctx: &str) -> Result<Index, String> {
        if let Some(i) = v.as_u64() {
            return Ok(Index::One(i as usize));
        }
        let list = array(v, ctx)?;
        if list.len() != 2 {
            return Err(format!("{ctx}: expected i or [i, j]"));
        }
        Ok(Index::Two(count(&list[0], ctx)?, count(&list[1], ctx)?))
    }

    fn to_json(self) -> Value {
        match self {
            Index::One(i) => json!(i),
            Index::Two(i, j) => json!([i, j]),
        }
    }
}

/// One edit of the `--edits` contract.
#[derive(Clone, Debug, PartialEq)]
pub enum Edit {
    /// Translate control point `point` (Cartesian; a weight stays).
    PointDelta {
        object: String,
        point: Index,
        delta: Point3,
    },
    /// Set a weight; a non-rational object first becomes rational with all weights 1.
    Weight {
        object: String,
        point: Index,
        weight: f64,
    },
    /// p ↦ (A·[p;1]).xyz for every control point of an ERBS local curve/patch (A row-major).
    LocalTransform {
        object: String,
        local: Index,
        matrix: [[f64; 4]; 4],
    },
    /// Translate one control point of an ERBS local curve/patch.
    LocalPointDelta {
        object: String,
        local: Index,
        point: Index,
        delta: Point3,
    },
    /// Insert the knot `t` `times` times (`None`: the field is omitted, meaning 1); `direction`
    /// is `None` for curves (`"insert_knot": t`), 0/1 for a surface's u/v (`{"u": t}`).
    InsertKnot {
        object: String,
        direction: Option<usize>,
        t: f64,
        times: Option<usize>,
    },
    /// Raise the degree, keeping the shape.
    ElevateDegree { object: String, by: Elevation },
}

/// The amount of an `elevate_degree` edit, as written.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Elevation {
    /// `"elevate_degree": e` on a curve.
    Curve(usize),
    /// `"elevate_degree": {"u": a, "v": b}` on a surface; an omitted direction means 0.
    Surface { u: Option<usize>, v: Option<usize> },
}

impl Elevation {
    /// Per-direction amounts: one entry for curves, [u, v] for surfaces.
    pub fn amounts(self) -> Vec<usize> {
        match self {
            Elevation::Curve(e) => vec![e],
            Elevation::Surface { u, v } => vec![u.unwrap_or(0), v.unwrap_or(0)],
        }
    }
}

impl Edit {
    pub fn from_json(v: &Value) -> Result<Edit, String> {
        let o = v.as_object().ok_or("edit: expected a JSON object")?;
        let object = field(o, "object", "edit")?
            .as_str()
            .ok_or("edit.object: expected a string")?
            .to_string();
        let ctx = format!("edit on {object}");
        let has = |k: &str| o.contains_key(k);
        let keys: Vec<&str> = o.keys().map(String::as_str).collect();
        let only = |allowed: &[&str]| -> Result<(), String> {
            match keys.iter().find(|k| !allowed.contains(k)) {
                Some(k) => Err(format!("{ctx}: unexpected field {k:?}")),
                None => Ok(()),
            }
        };
        if has("insert_knot") {
            only(&["object", "insert_knot", "times"])?;
            let at = &o["insert_knot"];
            let kctx = format!("{ctx}.insert_knot");
            let (direction, t) = match at.as_object() {
                Some(dirs) if dirs.len() == 1 => {
                    let (key, value) = dirs.iter().next().unwrap();
                    let dir = match key.as_str() {
                        "u" => 0,
                        "v" => 1,
                        _ => return Err(format!("{kctx}: expected {{\"u\": t}} or {{\"v\": t}}")),
                    };
                    (Some(dir), number(value, &kctx)?)
                }
                Some(_) => return Err(format!("{kctx}: expected one direction")),
                None => (None, number(at, &kctx)?),
            };
            let times = match o.get("times") {
                None => None,
                Some(v) => Some(count(v, &format!("{ctx}.times"))?),
            };
            return Ok(Edit::InsertKnot {
                object,
                direction,
                t,
                times,
            });
        }
        if has("elevate_degree") {
            only(&["object", "elevate_degree"])?;
            let by = &o["elevate_degree"];
            let ectx = format!("{ctx}.elevate_degree");
            let by = match by.as_object() {
                Some(dirs) => {
                    if let Some(k) = dirs.keys().find(|k| *k != "u" && *k != "v") {
                        return Err(format!("{ectx}: unexpected direction {k:?}"));
                    }
                    let amount = |k: &str| dirs.get(k).map(|v| count(v, &ectx)).transpose();
                    Elevation::Surface {
                        u: amount("u")?,
                        v: amount("v")?,
                    }
                }
                None => Elevation::Curve(count(by, &ectx)?),
            };
            return Ok(Edit::ElevateDegree { object, by });
        }
        if has("local") {
            let local = Index::from_json(&o["local"], &format!("{ctx}.local"))?;
            if has("transform") {
                only(&["object", "local", "transform"])?;
                let rows = array(&o["transform"], &ctx)?;
                if rows.len() != 4 {
                    return Err(format!("{ctx}.transform: expected 4 rows"));
                }
                let mut matrix = [[0.0; 4]; 4];
                for (r, row) in rows.iter().enumerate() {
                    let xs = numbers(row, &format!("{ctx}.transform[{r}]"))?;
                    if xs.len() != 4 {
                        return Err(format!("{ctx}.transform[{r}]: expected 4 numbers"));
                    }
                    matrix[r].copy_from_slice(&xs);
                }
                Ok(Edit::LocalTransform {
                    object,
                    local,
                    matrix,
                })
            } else {
                only(&["object", "local", "point", "delta"])?;
                Ok(Edit::LocalPointDelta {
                    object,
                    local,
                    point: Index::from_json(field(o, "point", &ctx)?, &ctx)?,
                    delta: point(field(o, "delta", &ctx)?, &format!("{ctx}.delta"))?,
                })
            }
        } else if has("weight") {
            only(&["object", "point", "weight"])?;
            Ok(Edit::Weight {
                object,
                point: Index::from_json(field(o, "point", &ctx)?, &ctx)?,
                weight: number(&o["weight"], &format!("{ctx}.weight"))?,
            })
        } else {
            only(&["object", "point", "delta"])?;
            Ok(Edit::PointDelta {
                object,
                point: Index::from_json(field(o, "point", &ctx)?, &ctx)?,
                delta: point(field(o, "delta", &ctx)?, &format!("{ctx}.delta"))?,
            })
        }
    }

    pub fn to_json(&self) -> Value {
        match self {
            Edit::PointDelta {
                object,
                point,
                delta,
            } => json!({"object": object, "point": point.to_json(), "delta": delta}),
            Edit::Weight {
                object,
                point,
                weight,
            } => json!({"object": object, "point": point.to_json(), "weight": weight}),
            Edit::LocalTransform {
                object,
                local,
                matrix,
            } => json!({"object": object, "local": local.to_json(), "transform": matrix}),
            Edit::LocalPointDelta {
                object,
                local,
                point,
                delta,
            } => json!({
                "object": object, "local": local.to_json(), "point": point.to_json(), "delta": delta
            }),
            Edit::InsertKnot {
                object,
                direction,
                t,
                times,
            } => {
                let at = match direction {
                    None => json!(t),
                    Some(0) => json!({ "u": t }),
                    Some(_) => json!({ "v": t }),
                };
                let mut m = Map::new();
                m.insert("object".into(), json!(object));
                m.insert("insert_knot".into(), at);
                if let Some(k) = times {
                    m.insert("times".into(), json!(k));
                }
                Value::Object(m)
            }
            Edit::ElevateDegree { object, by } => {
                let by = match by {
                    Elevation::Curve(e) => json!(e),
                    Elevation::Surface { u, v } => {
                        let mut m = Map::new();
                        if let Some(a) = u {
                            m.insert("u".into(), json!(a));
                        }
                        if let Some(b) = v {
                            m.insert("v".into(), json!(b));
                        }
                        Value::Object(m)
                    }
                };
                json!({"object": object, "elevate_degree": by})
            }
        }
    }

    pub fn object(&self) -> &str {
        match self {
            Edit::PointDelta { object, .. }
            | Edit::Weight { object, .. }
            | Edit::LocalTransform { object, .. }
            | Edit::LocalPointDelta { object, .. }
            | Edit::InsertKnot { object, .. }
            | Edit::ElevateDegree { object, .. } => object,
        }
    }

    /// Applies this edit to the model.
    pub fn apply(&self, scene: &mut Scene) -> Result<(), String> {
        let obj = scene.object_mut(self.object())?;
        let ctx = format!("edit on {}", obj.name);
        let bad = || format!("{ctx}: index out of range or wrong kind of object");
        match (self, &mut obj.shape) {
            (
                Edit::InsertKnot {
                    direction,
                    t,
                    times,
                    ..
                },
                shape,
            ) => {
                let refinement = Refinement::Insert {
                    t: *t,
                    times: times.unwrap_or(1),
                };
                refine(shape, *direction, refinement).map_err(|e| format!("{ctx}: {e}"))?;
            }
            (Edit::ElevateDegree { by, .. }, shape) => {
                let amounts = by.amounts();
                if amounts.iter().all(|&e| e == 0) {
                    return Err(format!("{ctx}: elevate_degree: must be at least 1"));
                }
                let directions: Vec<Option<usize>> = match by {
                    Elevation::Curve(_) => vec![None],
                    Elevation::Surface { .. } => vec![Some(0), Some(1)],
                };
                // Both directions or neither: refine a copy.
                let mut refined = shape.clone();
                for (direction, e) in directions.into_iter().zip(amounts) {
                    if e > 0 || direction.is_none() {
                        refine(&mut refined, direction, Refinement::Elevate(e))
                            .map_err(|e| format!("{ctx}: {e}"))?;
                    }
                }
                *shape = refined;
            }
            (Edit::PointDelta { point, delta, .. }, Shape::Curve { points, .. }) => {
                let Index::One(i) = *point else {
                    return Err(bad());
                };
                let p = points.get_mut(i).ok_or_else(bad)?;
                *p = eval::add(*p, *delta);
            }
            (Edit::PointDelta { point, delta, .. }, Shape::Surface { points, .. }) => {
                let Index::Two(i, j) = *point else {
                    return Err(bad());
                };
                let p = points
                    .get_mut(i)
                    .and_then(|r| r.get_mut(j))
                    .ok_or_else(bad)?;
                *p = eval::add(*p, *delta);
            }
            (
                Edit::Weight { point, weight, .. },
                Shape::Curve {
                    points, weights, ..
                },
            ) => {
                let Index::One(i) = *point else {
                    return Err(bad());
                };
                if i >= points.len() {
                    return Err(bad());
                }
                weights.get_or_insert_with(|| vec![1.0; points.len()])[i] = *weight;
            }
            (
                Edit::Weight { point, weight, .. },
                Shape::Surface {
                    points, weights, ..
                },
            ) => {
                let Index::Two(i, j) = *point else {
                    return Err(bad());
                };
                if i >= points.len() || j >= points[0].len() {
                    return Err(bad());
                }
                weights.get_or_insert_with(|| vec![vec![1.0; points[0].len()]; points.len()])[i]
                    [j] = *weight;
            }
            (Edit::LocalTransform { local, matrix, .. }, Shape::ErbsCurve { locals, .. }) => {
                let Index::One(l) = *local else {
                    return Err(bad());
                };
                let pts = locals.get_mut(l).ok_or_else(bad)?;
                pts.iter_mut().for_each(|p| *p = affine(matrix, *p));
            }
            (Edit::LocalTransform { local, matrix, .. }, Shape::ErbsSurface { locals, .. }) => {
                let Index::Two(k, l) = *local else {
                    return Err(bad());
                };
                let grid = locals
                    .get_mut(k)
                    .and_then(|r| r.get_mut(l))
                    .ok_or_else(bad)?;
                grid.iter_mut()
                    .flatten()
                    .for_each(|p| *p = affine(matrix, *p));
            }
            (
                Edit::LocalPointDelta {
                    local,
                    point,
                    delta,
                    ..
                },
                Shape::ErbsCurve { locals, .. },
            ) => {
                let (Index::One(l), Index::One(i)) = (*local, *point) else {
                    return Err(bad());
                };
                let p = locals
                    .get_mut(l)
                    .and_then(|c| c.get_mut(i))
                    .ok_or_else(bad)?;
                *p = eval::add(*p, *delta);
            }
            (
                Edit::LocalPointDelta {
                    local,
                    point,
                    delta,
                    ..
                },
                Shape::ErbsSurface { locals, .. },
            ) => {
                let (Index::Two(k, l), Index::Two(a, b)) = (*local, *point) else {
                    return Err(bad());
                };
                let p = locals
                    .get_mut(k)
                    .and_then(|r| r.get_mut(l))
                    .and_then(|g| g.get_mut(a))
                    .and_then(|r| r.get_mut(b))
                    .ok_or_else(bad)?;
                *p = eval::add(*p, *delta);
            }
            _ => return Err(bad()),
        }
        Ok(())
    }
}

/// A structural edit of one direction.
#[derive(Clone, Copy, Debug)]
enum Refinement {
    Insert { t: f64, times: usize },
    Elevate(usize),
}

impl Refinement {
    fn apply<const D: usize>(self, spline: &Spline<D>) -> Result<Spline<D>, String> {
        match self {
            Refinement::Insert { t, times } => spline.insert_knot(t, times),
            Refinement::Elevate(0) => Err("elevate_degree: must be at least 1".into()),
            Refinement::Elevate(e) => spline.elevate(e),
        }
    }
}

/// The basis after refining: a Bézier direction stays Bézier only under elevation.
fn refined_basis<const D: usize>(was: &Basis, r: Refinement, spline: &Spline<D>) -> Basis {
    match (was, r) {
        (Basis::Bezier, Refinement::Elevate(_)) => Basis::Bezier,
        _ => Basis::BSpline {
            degree: spline.degree,
            knots: spline.knots.clone(),
        },
    }
}

/// A refined basis and its control polygons (or grid rows).
type Refined<const D: usize> = (Basis, Vec<Vec<[f64; D]>>);

/// Refines every control polygon in `lines` (all on `basis`); returns the new basis and lines.
fn refine_lines<const D: usize>(
    basis: &Basis,
    lines: &[Vec<[f64; D]>],
    r: Refinement,
) -> Result<Refined<D>, String> {
    let mut out = Vec::with_capacity(lines.len());
    let mut new_basis = None;
    for line in lines {
        let spline = match basis {
            Basis::Bezier => Spline::bezier(line),
            Basis::BSpline { degree, knots } => Spline {
                degree: *degree,
                knots: knots.clone(),
                points: line.clone(),
            },
        };
        let refined = r.apply(&spline)?;
        new_basis.get_or_insert_with(|| refined_basis(basis, r, &refined));
        out.push(refined.points);
    }
    Ok((new_basis.expect("at least one control polygon"), out))
}

fn transpose<T: Copy>(grid: &[Vec<T>]) -> Vec<Vec<T>> {
    (0..grid[0].len())
        .map(|j| grid.iter().map(|row| row[j]).collect())
        .collect()
}

/// Refines a grid of control points along `dir` (0: u, i.e. every column; 1: v, every row).
fn refine_grid<const D: usize>(
    basis: &Basis,
    grid: &[Vec<[f64; D]>],
    dir: usize,
    r: Refinement,
) -> Result<Refined<D>, String> {
    if dir == 0 {
        let (b, columns) = refine_lines(basis, &transpose(grid), r)?;
        Ok((b, transpose(&columns)))
    } else {
        refine_lines(basis, grid, r)
    }
}

fn project(h: Homogeneous) -> (Point3, f64) {
    ([h[0] / h[3], h[1] / h[3], h[2] / h[3]], h[3])
}

/// Applies a structural edit to `shape` (`direction`: None for curves, Some(0/1) for u/v).
/// Rational shapes are refined in homogeneous coordinates.
fn refine(shape: &mut Shape, direction: Option<usize>, r: Refinement) -> Result<(), String> {
    let field = match r {
        Refinement::Insert { .. } => "insert_knot",
        Refinement::Elevate(_) => "elevate_degree",
    };
    match (shape, direction) {
        (
            Shape::Curve {
                basis,
                points,
                weights,
            },
            None,
        ) => {
            if let Some(w) = weights {
                let (b, mut lines) = refine_lines(basis, &[lift_curve(points, Some(w))], r)?;
                let (p, w): (Vec<Point3>, Vec<f64>) =
                    lines.remove(0).into_iter().map(project).unzip();
                (*basis, *points, *weights) = (b, p, Some(w));
            } else {
                let (b, mut lines) = refine_lines(basis, std::slice::from_ref(points), r)?;
                (*basis, *points) = (b, lines.remove(0));
            }
            Ok(())
        }
        (
            Shape::Surface {
                basis,
                points,
                weights,
            },
            Some(dir),
        ) => {
            let new_basis = if weights.is_some() {
                let (b, grid) =
                    refine_grid(&basis[dir], &lift_surface(points, weights.as_ref()), dir, r)?;
                let (p, w): (Vec<Vec<Point3>>, Vec<Vec<f64>>) = grid
                    .into_iter()
                    .map(|row| row.into_iter().map(project).unzip())
                    .unzip();
                (*points, *weights) = (p, Some(w));
                b
            } else {
                let (b, grid) = refine_grid(&basis[dir], points, dir, r)?;
                *points = grid;
                b
            };
            basis[dir] = new_basis;
            // A Bézier surface refined by insertion in one direction is a B-spline surface in both.
            if matches!(basis[dir], Basis::BSpline { .. }) {
                let counts = [points.len(), points[0].len()];
                for (other, n) in counts.into_iter().enumerate() {
                    if basis[other] == Basis::Bezier {
                        let clamped = Spline::<3>::bezier(&vec![[0.0; 3]; n]);
                        basis[other] = Basis::BSpline {
                            degree: clamped.degree,
                            knots: clamped.knots,
                        };
                    }
                }
            }
            Ok(())
        }
        (Shape::Curve { .. }, Some(_)) => {
            Err(format!("{field}: a curve takes a number, not a direction"))
        }
        (Shape::Surface { .. }, None) => Err(format!(
            "{field}: a surface needs a direction {{\"u\": …}} or {{\"v\": …}}"
        )),
        (Shape::ErbsCurve { .. } | Shape::ErbsSurface { .. }, _) => {
            Err(format!("{field}: ERBS objects are not refined this way"))
        }
    }
}

/// (A·[p;1]).xyz for a row-major 4×4 matrix A.
pub fn affine(a: &[[f64; 4]; 4], p: Point3) -> Point3 {
    std::array::from_fn(|r| a[r][0] * p[0] + a[r][1] * p[1] + a[r][2] * p[2] + a[r][3])
}

/// Parses an edit list (`--edits` file content).
pub fn parse_edits(v: &Value) -> Result<Vec<Edit>, String> {
    array(v, "edits")?.iter().map(Edit::from_json).collect()
}

/// Applies the edits in order to the model.
pub fn apply_edits(scene: &mut Scene, edits: &[Edit]) -> Result<(), String> {
    edits.iter().try_for_each(|e| e.apply(scene))
}
