//! The edits file (docs/scene-format.md): a JSON list parsed into the model's edit vocabulary.
//! Edits are validated in order against the model as the earlier edits leave it, so an edit
//! after a knot insertion addresses the refined control net.

use super::json::*;
use super::{Scene, SceneError};
use crate::model::{Edit, Model, ModelRef, ObjectEdit};
use serde_json::{Map, Value};

/// An edits file: a JSON list whose entries are parsed one at a time, each against its
/// object's model as the edits before it leave it (a refinement renumbers what follows).
#[derive(Debug, Clone)]
pub struct EditList(Vec<Value>);

impl EditList {
    /// The list, checked to be a JSON list; its entries are read by [`EditList::edit`].
    pub fn parse(text: &str) -> Result<Self, SceneError> {
        let v: Value =
            serde_json::from_str(text).map_err(|e| SceneError(format!("invalid JSON: {e}")))?;
        match v {
            Value::Array(list) => Ok(Self(list)),
            v => Err(SceneError(format!(
                "the edits file must be a JSON list of edits, found {}",
                kind(&v)
            ))),
        }
    }

    #[must_use]
    pub fn len(&self) -> usize {
        self.0.len()
    }

    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// Edit `k`: `find` gives the index and current model of the object it names. Returns the
    /// edit and its message prefix ("edit 3 (object 'c')") for a refusal later on.
    pub fn edit<'m>(
        &self,
        k: usize,
        find: impl Fn(&str) -> Option<(usize, ModelRef<'m>)>,
    ) -> Result<(Edit, At), SceneError> {
        let v = &self.0[k];
        let at = At(format!("edit {k}"));
        let obj = v.as_object().ok_or_else(|| {
            SceneError(format!("edit {k}: expected an object, found {}", kind(v)))
        })?;
        let name = as_str(&at, "object", require(&at, obj, "object")?)?;
        let (object, model) =
            find(name).ok_or_else(|| at.err("object", format!("unknown object '{name}'")))?;
        let at = At(format!("edit {k} (object '{name}')"));
        let edit = parse_edit(&at, obj, model)?;
        Ok((Edit { object, edit }, at))
    }
}

/// Parses an edits file against `scene`, validating each edit against the model the edits
/// before it leave (models are copied only for objects that are edited).
pub fn parse_edits(text: &str, scene: &Scene) -> Result<Vec<Edit>, SceneError> {
    let list = EditList::parse(text)?;
    let mut edited: Vec<Option<Model>> = vec![None; scene.objects.len()];
    let mut out = Vec::with_capacity(list.len());
    for k in 0..list.len() {
        let (edit, at) = list.edit(k, |name| {
            let i = scene.find(name)?;
            let m = edited[i].as_ref().unwrap_or(&scene.objects[i].model);
            Some((i, m.as_ref()))
        })?;
        let model =
            edited[edit.object].get_or_insert_with(|| scene.objects[edit.object].model.clone());
        edit.edit
            .prepare(model.as_ref())
            .and_then(|result| model.apply_prepared(&edit.edit, result))
            .map_err(|e| at.err(e.field, e.message))?;
        out.push(edit);
    }
    Ok(out)
}

/// Applies validated edits to the scene's models in order (the `--full` reference path).
pub fn apply_all(scene: &mut Scene, edits: &[Edit]) -> Result<(), SceneError> {
    for (k, e) in edits.iter().enumerate() {
        let o = &mut scene.objects[e.object];
        o.model
            .apply(&e.edit)
            .map_err(|err| SceneError(format!("edit {k} (object '{}'): {err}", o.name)))?;
    }
    Ok(())
}

fn parse_edit(
    at: &At,
    obj: &Map<String, Value>,
    model: ModelRef<'_>,
) -> Result<ObjectEdit, SceneError> {
    if obj.contains_key("to_bspline") {
        return to_bspline(at, obj, model);
    }
    model.kind().read_edit(at, obj)
}

/// `{"object": o, "to_bspline": true}`: a Catmull–Rom or Bézier spline becomes the equivalent
/// `bspline_curve` (later edits address its B-spline control points).
fn to_bspline(
    at: &At,
    obj: &Map<String, Value>,
    model: ModelRef<'_>,
) -> Result<ObjectEdit, SceneError> {
    check_fields(at, obj, &["object", "to_bspline"])?;
    if obj["to_bspline"] != Value::Bool(true) {
        return Err(at.err(
            "to_bspline",
            format!("expected true, found {}", obj["to_bspline"]),
        ));
    }
    let chain = model.to_bspline_curve().ok_or_else(|| {
        at.err(
            "to_bspline",
            format!(
                "only catmull_rom and bezier_spline objects convert to a bspline_curve, not a {}",
                model.type_name()
            ),
        )
    })?;
    Ok(ObjectEdit::Replace(Box::new(chain)))
}
