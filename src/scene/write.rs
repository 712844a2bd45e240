//! [`Scene`] → scene file text. Numbers are written in Rust's shortest round-trip form, so
//! loading a saved scene reproduces every control value bit for bit.

use super::{Scene, SceneObject};
use crate::geom::erbs::{ErbsCurve, ErbsSurface, LocalCurve, LocalPatch};
use crate::geom::{BFunctionKind, Parametrization, TensorSurface};
use crate::model::{Model, SplineForm};
use glam::DVec3;
use std::fmt::Write;

/// Serialises a scene in the format of docs/scene-format.md, one object per line.
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
        Model::ErbsCurve(m) => erbs_curve(s, m.curve()),
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
        Model::ErbsSurface(m) => erbs_surface(s, m.surface()),
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
    if !o.obj.is_empty() {
        field(s, "obj", &super::obj::carried::to_json(&o.obj));
    }
    s.push('}');
}

/// The explicit form of an ERBS curve's fields: knots, `closed`, locals (typed where not the
/// original Bézier form), a narrowed `domain` of a local ERBS, the B-function.
fn erbs_curve(s: &mut String, c: &ErbsCurve) {
    let k = c.knots();
    field(s, "knots", &numbers(k.as_slice()));
    if k.is_closed() {
        field(s, "closed", "true");
    }
    if k.domain() != k.full_domain() {
        let (a, b) = k.domain();
        field(s, "domain", &numbers(&[a, b]));
    }
    let local: Vec<String> = c.local_curves().iter().map(local_curve).collect();
    field(s, "local", &format!("[{}]", local.join(", ")));
    bfunction(s, c.bfunction());
}

fn local_curve(l: &LocalCurve) -> String {
    let mut s = String::from("{");
    match l {
        LocalCurve::Spline {
            curve,
            bezier: true,
        } => {
            let _ = write!(s, "\"points\": {}", points(curve.points()));
        }
        LocalCurve::Spline { curve, .. } => {
            let _ = write!(
                s,
                "\"type\": \"bspline_curve\", \"degree\": {}, \"knots\": {}, \"points\": {}",
                curve.degree(),
                numbers(curve.knots()),
                points(curve.points())
            );
        }
        LocalCurve::Erbs(e) => {
            s.push_str("\"type\": \"erbs_curve\"");
            erbs_curve(&mut s, e);
        }
    }
    s.push('}');
    s
}

fn erbs_surface(s: &mut String, e: &ErbsSurface) {
    let [ku, kv] = e.knots();
    field(
        s,
        "knots",
        &format!("[{}, {}]", numbers(ku.as_slice()), numbers(kv.as_slice())),
    );
    if e.closed() != [false, false] {
        let [a, b] = e.closed();
        field(s, "closed", &format!("[{a}, {b}]"));
    }
    if ku.domain() != ku.full_domain() || kv.domain() != kv.full_domain() {
        let [(u0, u1), (v0, v1)] = e.domain();
        field(
            s,
            "domain",
            &format!("[{}, {}]", numbers(&[u0, u1]), numbers(&[v0, v1])),
        );
    }
    let [nu, nv] = e.count();
    let rows: Vec<String> = (0..nu)
        .map(|k| {
            let row: Vec<String> = (0..nv).map(|l| local_patch(e.local_patch(k, l))).collect();
            format!("[{}]", row.join(", "))
        })
        .collect();
    field(s, "local", &format!("[{}]", rows.join(", ")));
    bfunction(s, e.bfunction());
}

fn local_patch(p: &LocalPatch) -> String {
    let mut s = String::from("{");
    match p {
        LocalPatch::Spline {
            surface,
            bezier: true,
        } => {
            let _ = write!(s, "\"points\": {}", point_grid(surface));
        }
        LocalPatch::Spline { surface, .. } => {
            let [du, dv] = surface.degree();
            let [ku, kv] = surface.knots();
            let _ = write!(
                s,
                "\"type\": \"bspline_surface\", \"degree\": [{du}, {dv}], \"knots\": [{}, {}], \"points\": {}",
                numbers(ku),
                numbers(kv),
                point_grid(surface)
            );
        }
        LocalPatch::Erbs(e) => {
            s.push_str("\"type\": \"erbs_surface\"");
            erbs_surface(&mut s, e);
        }
    }
    s.push('}');
    s
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
