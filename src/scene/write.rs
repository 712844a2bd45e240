//! [`Scene`] → scene file text. Numbers are written in Rust's shortest round-trip form, so
//! loading a saved scene reproduces every control value bit for bit.

use super::{Scene, SceneObject};
use crate::geom::{BFunctionKind, Parametrization, TensorSurface};
use crate::model::{Model, SplineForm};
use glam::DVec3;
use std::fmt::Write;

/// Serialises a scene in the DESIGN.md format, one object per line.
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
    match &o.model {
        Model::Curve(m) if m.form() == SplineForm::Bezier => {
            let c = m.curve();
            field(s, "points", &points(c.points()));
            if let Some(w) = c.weights() {
                field(s, "weights", &numbers(w));
            }
        }
        Model::Curve(m) => {
            let c = m.curve();
            field(s, "degree", &c.degree().to_string());
            field(s, "knots", &numbers(c.knots()));
            field(s, "points", &points(c.points()));
            if let Some(w) = c.weights() {
                field(s, "weights", &numbers(w));
            }
        }
        Model::ErbsCurve(m) => {
            let c = m.curve();
            field(s, "knots", &numbers(c.knots()));
            let local: Vec<String> = c
                .local_curves()
                .iter()
                .map(|l| format!("{{\"points\": {}}}", points(l.points())))
                .collect();
            field(s, "local", &format!("[{}]", local.join(", ")));
            bfunction(s, c.bfunction());
        }
        Model::Surface(m) if m.form() == SplineForm::Bezier => {
            let p = m.surface();
            field(s, "points", &point_grid(p));
            weights(s, p);
        }
        Model::Surface(m) => {
            let p = m.surface();
            let [du, dv] = p.degree();
            field(s, "degree", &format!("[{du}, {dv}]"));
            let [ku, kv] = p.knots();
            field(s, "knots", &format!("[{}, {}]", numbers(ku), numbers(kv)));
            field(s, "points", &point_grid(p));
            weights(s, p);
        }
        Model::ErbsSurface(m) => {
            let e = m.surface();
            let [ku, kv] = e.knots();
            field(s, "knots", &format!("[{}, {}]", numbers(ku), numbers(kv)));
            let [nu, nv] = e.count();
            let rows: Vec<String> = (0..nu)
                .map(|k| {
                    let row: Vec<String> = (0..nv)
                        .map(|l| format!("{{\"points\": {}}}", point_grid(e.local_patch(k, l))))
                        .collect();
                    format!("[{}]", row.join(", "))
                })
                .collect();
            field(s, "local", &format!("[{}]", rows.join(", ")));
            bfunction(s, e.bfunction());
        }
        Model::CatmullRom(m) => {
            let c = m.spline();
            field(s, "points", &points(c.points()));
            if c.parametrization() != Parametrization::Uniform {
                field(
                    s,
                    "parametrization",
                    &format!("\"{}\"", c.parametrization().name()),
                );
            }
            if c.closed() {
                field(s, "closed", "true");
            }
        }
        Model::BezierSpline(m) => {
            let c = m.spline();
            field(s, "degree", &c.degree().to_string());
            field(s, "knots", &numbers(c.knots()));
            field(s, "points", &points(c.points()));
            field(s, "continuity", &format!("\"{}\"", c.continuity().name()));
        }
    }
    match o.model.sample_dims() {
        [m, _] if !o.model.is_surface() => field(s, "samples", &m.to_string()),
        [mu, mv] => field(s, "samples", &format!("[{mu}, {mv}]")),
    }
    if let Some(c) = o.color {
        field(s, "color", &numbers(&c));
    }
    s.push('}');
}

fn field(s: &mut String, name: &str, value: &str) {
    let _ = write!(s, ", \"{name}\": {value}");
}

fn bfunction(s: &mut String, b: BFunctionKind) {
    if b != BFunctionKind::default() {
        field(s, "bfunction", &format!("\"{}\"", b.name()));
    }
}

fn weights(s: &mut String, p: &TensorSurface) {
    if let Some(w) = p.weights() {
        let nv = p.count()[1];
        let rows: Vec<String> = w.chunks(nv).map(numbers).collect();
        field(s, "weights", &format!("[{}]", rows.join(", ")));
    }
}

/// Shortest round-trip decimal (Rust's `{:?}` for f64 never loses bits; exponents for extremes).
pub fn number(x: f64) -> String {
    format!("{x:?}")
}

fn numbers(v: &[f64]) -> String {
    let items: Vec<String> = v.iter().map(|&x| number(x)).collect();
    format!("[{}]", items.join(", "))
}

fn points(p: &[DVec3]) -> String {
    let items: Vec<String> = p.iter().map(|q| numbers(&q.to_array())).collect();
    format!("[{}]", items.join(", "))
}

fn point_grid(p: &TensorSurface) -> String {
    let nv = p.count()[1];
    let rows: Vec<String> = p.points().chunks(nv).map(points).collect();
    format!("[{}]", rows.join(", "))
}

fn json_string(s: &str) -> String {
    serde_json::to_string(s).expect("strings always serialise")
}
