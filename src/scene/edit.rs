//! Edits: what the `--edits` file, the viewer and undo/redo apply to objects.

use super::json::*;
use super::{Scene, SceneError, Shape};
use glam::{DMat4, DVec3};
use serde_json::Value;

/// A control point or local curve/patch index: one index for curves, two for surfaces.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Index2 {
    One(usize),
    Two(usize, usize),
}

/// One edit of one object (`object` indexes `Scene::objects`).
#[derive(Debug, Clone, PartialEq)]
pub struct Edit {
    pub object: usize,
    pub op: EditOp,
}

/// The edit operations of the DESIGN.md edit format.
#[derive(Debug, Clone, PartialEq)]
pub enum EditOp {
    /// Translate a control point (for rational objects the Cartesian point; its weight stays).
    TranslatePoint { point: Index2, delta: DVec3 },
    /// Set a weight; a polynomial object becomes rational with all other weights 1.
    SetWeight { point: Index2, weight: f64 },
    /// Map every control point of an ERBS local curve/patch by p ↦ (A·[p;1]).xyz (A affine).
    TransformLocal { local: Index2, matrix: DMat4 },
    /// Translate one control point of an ERBS local curve/patch.
    TranslateLocalPoint {
        local: Index2,
        point: Index2,
        delta: DVec3,
    },
    /// Set a control point to an exact position (undo restores the model bit for bit). Not part
    /// of the edits file format.
    SetPoint { point: Index2, position: DVec3 },
    /// Set every control point of an ERBS local curve/patch exactly (undo). Not part of the
    /// edits file format.
    SetLocalPoints { local: Index2, points: Vec<DVec3> },
}

impl EditOp {
    /// Applies the edit to the model (control data). Indices must have been validated.
    pub fn apply_to(&self, shape: &mut Shape) {
        match (self, shape) {
            (
                EditOp::TranslatePoint {
                    point: Index2::One(i),
                    delta,
                },
                Shape::BezierCurve(c) | Shape::BSplineCurve(c),
            ) => c.translate_point(*i, *delta),
            (
                EditOp::TranslatePoint {
                    point: Index2::Two(i, j),
                    delta,
                },
                Shape::BezierSurface(s) | Shape::BSplineSurface(s),
            ) => s.translate_point(*i, *j, *delta),
            (
                EditOp::SetWeight {
                    point: Index2::One(i),
                    weight,
                },
                Shape::BezierCurve(c) | Shape::BSplineCurve(c),
            ) => c.set_weight(*i, *weight),
            (
                EditOp::SetWeight {
                    point: Index2::Two(i, j),
                    weight,
                },
                Shape::BezierSurface(s) | Shape::BSplineSurface(s),
            ) => s.set_weight(*i, *j, *weight),
            (
                EditOp::TransformLocal {
                    local: Index2::One(l),
                    matrix,
                },
                Shape::ErbsCurve(c),
            ) => c.transform_local(*l, matrix),
            (
                EditOp::TransformLocal {
                    local: Index2::Two(k, l),
                    matrix,
                },
                Shape::ErbsSurface(s),
            ) => s.transform_local(*k, *l, matrix),
            (
                EditOp::TranslateLocalPoint {
                    local: Index2::One(l),
                    point: Index2::One(q),
                    delta,
                },
                Shape::ErbsCurve(c),
            ) => c.translate_local_point(*l, *q, *delta),
            (
                EditOp::TranslateLocalPoint {
                    local: Index2::Two(k, l),
                    point: Index2::Two(a, b),
                    delta,
                },
                Shape::ErbsSurface(s),
            ) => s.translate_local_point(*k, *l, *a, *b, *delta),
            (
                EditOp::SetPoint {
                    point: Index2::One(i),
                    position,
                },
                Shape::BezierCurve(c) | Shape::BSplineCurve(c),
            ) => c.set_point(*i, *position),
            (
                EditOp::SetPoint {
                    point: Index2::Two(i, j),
                    position,
                },
                Shape::BezierSurface(s) | Shape::BSplineSurface(s),
            ) => s.set_point(*i, *j, *position),
            (
                EditOp::SetLocalPoints {
                    local: Index2::One(l),
                    points,
                },
                Shape::ErbsCurve(c),
            ) => c.set_local_points(*l, points),
            (
                EditOp::SetLocalPoints {
                    local: Index2::Two(k, l),
                    points,
                },
                Shape::ErbsSurface(s),
            ) => s.set_local_points(*k, *l, points),
            (op, shape) => panic!(
                "edit {op:?} does not fit a {} (validate first)",
                shape.type_name()
            ),
        }
    }
}

/// Parses an edits file (a JSON list) against `scene`, validating object names, kinds and
/// indices. Nothing is applied.
pub fn parse_edits(text: &str, scene: &Scene) -> Result<Vec<Edit>, SceneError> {
    let v: Value =
        serde_json::from_str(text).map_err(|e| SceneError(format!("invalid JSON: {e}")))?;
    let list = v.as_array().ok_or_else(|| {
        SceneError(format!(
            "the edits file must be a JSON list of edits, found {}",
            kind(&v)
        ))
    })?;
    list.iter()
        .enumerate()
        .map(|(k, e)| parse_edit(k, e, scene))
        .collect()
}

fn parse_edit(k: usize, v: &Value, scene: &Scene) -> Result<Edit, SceneError> {
    let at = At(format!("edit {k}"));
    let obj = v
        .as_object()
        .ok_or_else(|| SceneError(format!("edit {k}: expected an object, found {}", kind(v))))?;
    let name = as_str(&at, "object", require(&at, obj, "object")?)?;
    let object = scene
        .find(name)
        .ok_or_else(|| at.err("object", format!("unknown object '{name}'")))?;
    let shape = &scene.objects[object].shape;
    let at = At(format!("edit {k} (object '{name}')"));
    let ty = shape.type_name();
    let has = |f: &str| obj.contains_key(f);
    let op = if has("local") {
        let erbs_dims = match shape {
            Shape::ErbsCurve(_) => 1,
            Shape::ErbsSurface(_) => 2,
            _ => {
                return Err(at.err(
                    "local",
                    format!("a {ty} has no local curves or patches (only ERBS objects do)"),
                ));
            }
        };
        let local = index(&at, "local", require(&at, obj, "local")?, erbs_dims)?;
        check_local(&at, shape, local)?;
        if has("transform") {
            check_fields(&at, obj, &["object", "local", "transform"])?;
            EditOp::TransformLocal {
                local,
                matrix: affine(&at, require(&at, obj, "transform")?)?,
            }
        } else {
            check_fields(&at, obj, &["object", "local", "point", "delta"])?;
            let point = index(&at, "point", require(&at, obj, "point")?, erbs_dims)?;
            check_local_point(&at, shape, local, point)?;
            let delta = as_point(&at, "delta", "delta", require(&at, obj, "delta")?)?;
            EditOp::TranslateLocalPoint {
                local,
                point,
                delta,
            }
        }
    } else {
        let dims = match shape {
            Shape::BezierCurve(_) | Shape::BSplineCurve(_) => 1,
            Shape::BezierSurface(_) | Shape::BSplineSurface(_) => 2,
            Shape::ErbsCurve(_) | Shape::ErbsSurface(_) => {
                return Err(at.err(
                    if has("transform") { "transform" } else { "point" },
                    format!("an {ty} is edited through its local curves: give \"local\" (with \"transform\", or \"point\" and \"delta\")"),
                ));
            }
        };
        let point = index(&at, "point", require(&at, obj, "point")?, dims)?;
        check_point(&at, shape, point)?;
        if has("weight") {
            check_fields(&at, obj, &["object", "point", "weight"])?;
            let w = as_f64(&at, "weight", "weight", require(&at, obj, "weight")?)?;
            if w <= 0.0 {
                return Err(at.err("weight", format!("weight {w} must be positive")));
            }
            EditOp::SetWeight { point, weight: w }
        } else {
            check_fields(&at, obj, &["object", "point", "delta"])?;
            let delta = as_point(&at, "delta", "delta", require(&at, obj, "delta")?)?;
            EditOp::TranslatePoint { point, delta }
        }
    };
    Ok(Edit { object, op })
}

/// `i` (dims = 1) or `[i, j]` (dims = 2).
fn index(at: &At, field: &str, v: &Value, dims: usize) -> Result<Index2, SceneError> {
    if dims == 1 {
        return Ok(Index2::One(as_usize(at, field, "index", v)?));
    }
    match v.as_array() {
        Some(a) if a.len() == 2 => Ok(Index2::Two(
            as_usize(at, field, "index", &a[0])?,
            as_usize(at, field, "index", &a[1])?,
        )),
        _ => Err(at.err(field, format!("expected [i, j] for a surface, found {v}"))),
    }
}

fn out_of_range(at: &At, field: &str, idx: Index2, bounds: Index2) -> SceneError {
    let msg = match (idx, bounds) {
        (Index2::One(i), Index2::One(n)) => format!(
            "index {i} out of range (valid: 0..={})",
            n.saturating_sub(1)
        ),
        (Index2::Two(i, j), Index2::Two(n, m)) => {
            format!(
                "index [{i}, {j}] out of range (valid: [0..={}, 0..={}])",
                n.saturating_sub(1),
                m.saturating_sub(1)
            )
        }
        _ => "index has the wrong number of components".to_string(),
    };
    at.err(field, msg)
}

fn within(idx: Index2, bounds: Index2) -> bool {
    match (idx, bounds) {
        (Index2::One(i), Index2::One(n)) => i < n,
        (Index2::Two(i, j), Index2::Two(n, m)) => i < n && j < m,
        _ => false,
    }
}

fn check_point(at: &At, shape: &Shape, p: Index2) -> Result<(), SceneError> {
    let bounds = match shape {
        Shape::BezierCurve(c) | Shape::BSplineCurve(c) => Index2::One(c.points().len()),
        Shape::BezierSurface(s) | Shape::BSplineSurface(s) => {
            Index2::Two(s.count()[0], s.count()[1])
        }
        _ => unreachable!("ERBS objects are rejected before"),
    };
    if within(p, bounds) {
        Ok(())
    } else {
        Err(out_of_range(at, "point", p, bounds))
    }
}

fn check_local(at: &At, shape: &Shape, l: Index2) -> Result<(), SceneError> {
    let bounds = match shape {
        Shape::ErbsCurve(c) => Index2::One(c.local_curves().len()),
        Shape::ErbsSurface(s) => Index2::Two(s.count()[0], s.count()[1]),
        _ => unreachable!("only ERBS objects get here"),
    };
    if within(l, bounds) {
        Ok(())
    } else {
        Err(out_of_range(at, "local", l, bounds))
    }
}

fn check_local_point(at: &At, shape: &Shape, l: Index2, p: Index2) -> Result<(), SceneError> {
    let bounds = match (shape, l) {
        (Shape::ErbsCurve(c), Index2::One(l)) => Index2::One(c.local_curves()[l].points().len()),
        (Shape::ErbsSurface(s), Index2::Two(k, l)) => {
            let c = s.local_patch(k, l).count();
            Index2::Two(c[0], c[1])
        }
        _ => unreachable!("validated by check_local"),
    };
    if within(p, bounds) {
        Ok(())
    } else {
        Err(out_of_range(at, "point", p, bounds))
    }
}

/// A row-major 4×4 affine matrix (last row 0 0 0 1).
fn affine(at: &At, v: &Value) -> Result<DMat4, SceneError> {
    let rows = as_array(at, "transform", v)?;
    if rows.len() != 4 {
        return Err(at.err(
            "transform",
            format!("expected 4 rows, found {}", rows.len()),
        ));
    }
    let mut m = [[0.0; 4]; 4];
    for (r, row) in rows.iter().enumerate() {
        let vals = as_f64_list(at, "transform", &format!("row {r} entry"), row)?;
        if vals.len() != 4 {
            return Err(at.err(
                "transform",
                format!("row {r} has {} entries, expected 4", vals.len()),
            ));
        }
        m[r].copy_from_slice(&vals);
    }
    if m[3] != [0.0, 0.0, 0.0, 1.0] {
        return Err(at.err(
            "transform",
            format!(
                "not affine: the last row must be [0, 0, 0, 1], found {:?}",
                m[3]
            ),
        ));
    }
    Ok(DMat4::from_cols_array_2d(&m).transpose())
}

/// Applies validated edits to the scene model in order.
pub fn apply_all(scene: &mut Scene, edits: &[Edit]) {
    for e in edits {
        e.op.apply_to(&mut scene.objects[e.object].shape);
    }
}

/// What an edit acts on, for merging: ops on different targets commute.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Target {
    Point(usize, Index2),
    Weight(usize, Index2),
    Local(usize, Index2),
}

fn target(e: &Edit) -> Target {
    match &e.op {
        EditOp::TranslatePoint { point, .. } | EditOp::SetPoint { point, .. } => {
            Target::Point(e.object, *point)
        }
        EditOp::SetWeight { point, .. } => Target::Weight(e.object, *point),
        EditOp::TransformLocal { local, .. }
        | EditOp::TranslateLocalPoint { local, .. }
        | EditOp::SetLocalPoints { local, .. } => Target::Local(e.object, *local),
    }
}

/// Merges the edits of one frame so each touched control point or local patch is updated once:
/// consecutive translations of a point add up, consecutive transforms of a local curve compose
/// (A2·A1), consecutive moves of one local control point add up, and the last weight of a point
/// wins. Edits on different targets commute (a point's position and its weight are independent,
/// as are distinct local curves), so targets are applied in first-touch order; edits on one
/// target keep their order.
pub fn merge_edits(edits: &[Edit]) -> Vec<Edit> {
    let mut groups: Vec<(Target, Vec<Edit>)> = Vec::new();
    for e in edits {
        let key = target(e);
        let group = match groups.iter_mut().find(|(k, _)| *k == key) {
            Some((_, g)) => g,
            None => {
                groups.push((key, Vec::new()));
                &mut groups.last_mut().expect("just pushed").1
            }
        };
        let merged = match (group.last().map(|x| &x.op), &e.op) {
            (
                Some(EditOp::TranslatePoint { point, delta: a }),
                EditOp::TranslatePoint { delta: b, .. },
            ) => Some(EditOp::TranslatePoint {
                point: *point,
                delta: *a + *b,
            }),
            (Some(EditOp::SetWeight { .. }), EditOp::SetWeight { .. }) => Some(e.op.clone()),
            (
                Some(EditOp::TransformLocal { local, matrix: a }),
                EditOp::TransformLocal { matrix: b, .. },
            ) => Some(EditOp::TransformLocal {
                local: *local,
                matrix: *b * *a,
            }),
            (
                Some(EditOp::TranslateLocalPoint {
                    local,
                    point: p,
                    delta: a,
                }),
                EditOp::TranslateLocalPoint {
                    point: q, delta: b, ..
                },
            ) if p == q => Some(EditOp::TranslateLocalPoint {
                local: *local,
                point: *p,
                delta: *a + *b,
            }),
            _ => None,
        };
        match merged {
            Some(op) => group.last_mut().expect("merged with the last edit").op = op,
            None => group.push(e.clone()),
        }
    }
    groups.into_iter().flat_map(|(_, g)| g).collect()
}
