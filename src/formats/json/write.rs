//! [`Scene`] → scene file text. Numbers are written in Rust's shortest round-trip form, so
//! loading a saved scene reproduces every control value bit for bit.

use crate::fields::write::{field, json_string, numbers};
use crate::scene::{Scene, SceneObject};
use std::fmt::Write;

/// Serialises a scene in the format of docs/scene-format.md, one object per line.
#[must_use]
pub fn scene_to_json(scene: &Scene) -> String {
    let mut s = String::from("{\"objects\": [\n");
    for (i, o) in scene.objects.iter().enumerate() {
        s.push_str("  ");
        write_object(&mut s, o);
        s.push_str(if i + 1 < scene.objects.len() {
            ",\n"
        } else {
            "\n"
        });
    }
    s.push_str("]}\n");
    s
}

fn write_object(s: &mut String, o: &SceneObject) {
    let _ = write!(
        s,
        "{{\"name\": {}, \"type\": \"{}\"",
        json_string(&o.name),
        o.model.type_name()
    );
    o.model.kind().write(s);
    match o.model.sample_dims() {
        [m, _] if !o.model.is_surface() => field(s, "samples", &m.to_string()),
        [mu, mv] => field(s, "samples", &format!("[{mu}, {mv}]")),
    }
    if let Some(c) = o.color {
        field(s, "color", &numbers(&c));
    }
    if let Some(t) = &o.trim {
        field(s, "trim", &super::trim::trim_json(t.spec()));
    }
    for k in o.kept.iter() {
        field(s, k.key(), &k.to_json());
    }
    s.push('}');
}
