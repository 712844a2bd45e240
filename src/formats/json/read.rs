//! Scene file → [`Scene`], validating everything with one-line errors.

use super::super::context::{LoadContext, SampleDefaults};
use crate::fields::ReadCtx;
use crate::fields::json::*;
use crate::geom::trim::Trimmed;
use crate::model::Model;
use crate::model::file::opt;
use crate::scene::{Carried, Scene, SceneError, SceneNames, SceneObject};
use serde::Deserialize;
use serde_json::{Map, Value};
use std::collections::HashMap;

/// Parses and validates scene JSON text.
///
/// The objects are streamed: each one is read into a small `Value`, validated into its model and
/// dropped before the next, so that a large scene never holds a `Value` tree of the whole file
/// (which took more time to build and free than the parsing itself, and four times the memory
/// of the models).
pub fn parse_scene(text: &str, ctx: &LoadContext<'_>) -> Result<Scene, SceneError> {
    if !text.trim_start().starts_with('{') {
        // Not an object (or not JSON): the whole-value path words the message.
        return parse_scene_value(text);
    }
    let failed = std::cell::RefCell::new(None);
    let mut de = serde_json::Deserializer::from_str(text);
    let parsed = serde::de::Deserializer::deserialize_map(
        &mut de,
        SceneVisitor {
            failed: &failed,
            ctx,
        },
    )
    .and_then(|objects| de.end().map(|()| objects));
    match (parsed, failed.into_inner()) {
        (_, Some(e)) => Err(e),
        (Ok(objects), None) => {
            check_kept(&objects)?;
            Ok(Scene { objects })
        }
        (Err(e), None) => Err(SceneError(format!("invalid JSON: {e}"))),
    }
}

/// The scene text through one `Value` tree: only for text that is not a JSON object, whose
/// message this words.
fn parse_scene_value(text: &str) -> Result<Scene, SceneError> {
    let v: Value =
        serde_json::from_str(text).map_err(|e| SceneError(format!("invalid JSON: {e}")))?;
    Err(SceneError(format!(
        "the scene must be a JSON object {{\"objects\": [...]}}, found {}",
        kind(&v)
    )))
}

/// A scene error raised inside the streaming deserializer: kept here and handed to serde as an
/// empty custom error, so that it reaches the user as it was worded, not with serde's position.
type Failed<'a> = &'a std::cell::RefCell<Option<SceneError>>;

fn fail<E: serde::de::Error>(failed: Failed<'_>, e: SceneError) -> E {
    failed.replace(Some(e));
    E::custom("")
}

/// The top-level `{"objects": [...]}`.
struct SceneVisitor<'a> {
    failed: Failed<'a>,
    ctx: &'a LoadContext<'a>,
}

impl<'de> serde::de::Visitor<'de> for SceneVisitor<'_> {
    type Value = Vec<SceneObject>;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("a scene object {\"objects\": [...]}")
    }

    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
        let at = At("scene".into());
        let mut objects = None;
        while let Some(key) = map.next_key::<String>()? {
            match key.as_str() {
                "objects" if objects.is_some() => {
                    return Err(fail(self.failed, at.err("objects", "given twice")));
                }
                "objects" => {
                    objects = Some(map.next_value_seed(ObjectsSeed {
                        failed: self.failed,
                        ctx: self.ctx,
                    })?);
                }
                _ => {
                    return Err(fail(
                        self.failed,
                        SceneError(format!(
                            "scene: unknown field '{key}' (expected one of: objects)"
                        )),
                    ));
                }
            }
        }
        objects.ok_or_else(|| fail(self.failed, at.err("objects", "missing")))
    }
}

/// The `objects` array, parsed one object at a time.
struct ObjectsSeed<'a> {
    failed: Failed<'a>,
    ctx: &'a LoadContext<'a>,
}

impl<'de> serde::de::DeserializeSeed<'de> for ObjectsSeed<'_> {
    type Value = Vec<SceneObject>;

    fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
        // Any JSON value: an array is streamed, anything else is refused with its kind.
        let v = d.deserialize_any(self)?;
        Ok(v)
    }
}

impl<'de> serde::de::Visitor<'de> for ObjectsSeed<'_> {
    type Value = Vec<SceneObject>;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("an array of objects")
    }

    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
        let mut objects: Vec<SceneObject> = Vec::with_capacity(seq.size_hint().unwrap_or(0));
        // Name → index, so that uniqueness costs one hash per object, not a scan of all before
        // it.
        let mut names: HashMap<String, usize> = HashMap::new();
        let progress = self.ctx.progress.start("parsing", None, "objects");
        let fields = ObjectFields::of(self.ctx);
        while let Some(item) = seq.next_element::<Value>()? {
            progress.inc(1);
            let i = objects.len();
            let obj = parse_object(i, &item, &fields).map_err(|e| fail(self.failed, e))?;
            if let Some(j) = names.insert(obj.name.clone(), i) {
                return Err(fail(
                    self.failed,
                    SceneError(format!(
                        "object '{}' (objects[{i}]): field 'name': duplicate name, already used by objects[{j}]",
                        obj.name
                    )),
                ));
            }
            objects.push(obj);
        }
        // Cleared, not left: the load's progress is transient, and an error that follows
        // must stand on its own line.
        drop(progress);
        Ok(objects)
    }

    fn visit_map<A: serde::de::MapAccess<'de>>(self, map: A) -> Result<Self::Value, A::Error> {
        let v = Value::deserialize(serde::de::value::MapAccessDeserializer::new(map))?;
        Err(self.wrong_kind(&v))
    }

    fn visit_bool<E: serde::de::Error>(self, b: bool) -> Result<Self::Value, E> {
        Err(self.wrong_kind(&Value::Bool(b)))
    }

    fn visit_i64<E: serde::de::Error>(self, x: i64) -> Result<Self::Value, E> {
        Err(self.wrong_kind(&Value::from(x)))
    }

    fn visit_u64<E: serde::de::Error>(self, x: u64) -> Result<Self::Value, E> {
        Err(self.wrong_kind(&Value::from(x)))
    }

    fn visit_f64<E: serde::de::Error>(self, x: f64) -> Result<Self::Value, E> {
        Err(self.wrong_kind(&Value::from(x)))
    }

    fn visit_str<E: serde::de::Error>(self, x: &str) -> Result<Self::Value, E> {
        Err(self.wrong_kind(&Value::from(x)))
    }

    fn visit_unit<E: serde::de::Error>(self) -> Result<Self::Value, E> {
        Err(self.wrong_kind(&Value::Null))
    }
}

impl ObjectsSeed<'_> {
    fn wrong_kind<E: serde::de::Error>(&self, v: &Value) -> E {
        let at = At("scene".into());
        fail(self.failed, as_array(&at, "objects", v).unwrap_err())
    }
}

/// What each object's file kept that names other objects (OBJ's `con`) names them rightly.
fn check_kept(objects: &[SceneObject]) -> Result<(), SceneError> {
    let names = SceneNames { objects };
    for (i, o) in objects.iter().enumerate() {
        for k in o.kept.iter() {
            k.check_scene(&names, i)
                .map_err(|e| At(format!("object '{}' (objects[{i}])", o.name)).err(k.key(), e))?;
        }
    }
    Ok(())
}

/// Fields every object has besides its geometry.
const OBJECT_FIELDS: [&str; 5] = ["name", "type", "samples", "color", "trim"];

/// The fields every object may have: [`OBJECT_FIELDS`] and each format's kept field.
struct ObjectFields<'a> {
    common: Vec<&'static str>,
    ctx: &'a LoadContext<'a>,
}

impl<'a> ObjectFields<'a> {
    fn of(ctx: &'a LoadContext<'a>) -> Self {
        let mut common = OBJECT_FIELDS.to_vec();
        common.extend(ctx.formats.iter().filter_map(|f| f.kept_key()));
        Self { common, ctx }
    }
}

fn parse_object(i: usize, v: &Value, fields: &ObjectFields<'_>) -> Result<SceneObject, SceneError> {
    let defaults = fields.ctx.samples;
    let at = At(format!("objects[{i}]"));
    let obj = v.as_object().ok_or_else(|| {
        SceneError(format!(
            "objects[{i}]: expected an object, found {}",
            kind(v)
        ))
    })?;
    let name = as_str(&at, "name", require(&at, obj, "name")?)?;
    if name.is_empty() {
        return Err(at.err("name", "empty name"));
    }
    let at = At(format!("object '{name}' (objects[{i}])"));
    let ty = as_str(&at, "type", require(&at, obj, "type")?)?;
    let with_default;
    let obj = match default_samples(ty, obj, defaults) {
        Some(samples) => {
            let mut o = obj.clone();
            o.insert("samples".into(), samples);
            with_default = o;
            &with_default
        }
        None => obj,
    };
    let ctx = ReadCtx {
        common: &fields.common,
        budget: fields.ctx.budget,
    };
    let model = Model::read(ty, &at, obj, &ctx).unwrap_or_else(|| {
        Err(at.err(
            "type",
            format!(
                "unknown type '{ty}' (expected one of: {}){}",
                Model::types().join(", "),
                type_hint(ty)
            ),
        ))
    })?;
    let color = opt(obj, "color").map(|c| parse_color(&at, c)).transpose()?;
    let mut kept = Carried::default();
    for format in fields.ctx.formats {
        if let Some(v) = format.kept_key().and_then(|key| opt(obj, key)) {
            kept.set(format.read_kept(&at, v, model.is_surface())?);
        }
    }
    let trim = opt(obj, "trim")
        .map(|v| read_trimmed(&at, v, &model))
        .transpose()?;
    Ok(SceneObject {
        name: name.to_string(),
        model,
        color,
        kept,
        trim,
    })
}

/// A surface's `trim`, validated against its parameter domain.
fn read_trimmed(at: &At, v: &Value, model: &Model) -> Result<Trimmed, SceneError> {
    if !model.is_surface() {
        return Err(at.err("trim", "only surfaces have trims"));
    }
    let spec = super::trim::read_trim(at, v)?;
    let d = model.domain();
    let domain = [d[0], d.get(1).copied().unwrap_or(d[0])];
    Trimmed::new(spec, domain).map_err(|e| at.err("trim", e))
}

/// The sample count `defaults` give an object of type `ty` that has none of its own.
fn default_samples(ty: &str, obj: &Map<String, Value>, defaults: SampleDefaults) -> Option<Value> {
    if obj.contains_key("samples") {
        return None;
    }
    match Model::type_is_surface(ty)? {
        true => defaults.surface.map(|[u, v]| Value::from(vec![u, v])),
        false => defaults.curve.map(Value::from),
    }
}

fn parse_color(at: &At, v: &Value) -> Result<[f64; 3], SceneError> {
    let p = as_point(at, "color", "color", v)?;
    if !p.cmpge(glam::DVec3::ZERO).all() || !p.cmple(glam::DVec3::ONE).all() {
        return Err(at.err(
            "color",
            format!("components must lie in [0, 1], found {:?}", p.to_array()),
        ));
    }
    Ok(p.to_array())
}

/// What a user who wrote another program's type name meant: NURBS are the B-spline kinds with
/// `weights`, and rational Béziers the Bézier kinds with them.
fn type_hint(ty: &str) -> &'static str {
    let t = ty.to_ascii_lowercase();
    let surface = t.contains("surf") || t.contains("patch");
    if t.contains("nurbs") || t.contains("rational") {
        if surface {
            "; a NURBS surface is a bspline_surface with \"weights\""
        } else {
            "; a NURBS curve is a bspline_curve with \"weights\""
        }
    } else {
        ""
    }
}
